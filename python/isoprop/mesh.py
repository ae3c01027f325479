# SPDX-License-Identifier: BSD-3-Clause
"""Triangles copied out of a libisoprop mesh into numpy arrays."""
import ctypes

import numpy as np

NORMAL_SCALE = 32767.0  # ip_normal_unpack(), include/isoprop/mesh.h


def _view(pointer, dtype, first, count):
    """`count` values of numpy type `dtype` from index `first` of the C array at `pointer`,
    as a numpy array over the C memory (no copy: valid only while that memory is)."""
    size = np.dtype(dtype).itemsize
    address = ctypes.addressof(pointer.contents) + first * size
    return np.frombuffer((ctypes.c_char * (count * size)).from_address(address), dtype)


def soup_faces(triangles):
    """Faces of a triangle soup: triangle t is vertices 3t, 3t + 1, 3t + 2 (int32, or int64
    when there are 2^31 vertices or more)."""
    dtype = np.int32 if 3 * triangles < 2 ** 31 else np.int64
    return np.arange(3 * triangles, dtype=dtype).reshape(triangles, 3)


class Mesh:
    """Triangles as a soup, in world units (sample (i, j, k) sits at (i, j, k) * spacing).

    vertices: float32 (3T, 3), x y z of each triangle's 3 corners in turn;
    normals:  float32 (3T, 3), unit normals at the corners (from the data's gradient, pointing
              toward lower values);
    faces:    int32 (T, 3), the corners of triangle t: 3t, 3t + 1, 3t + 2;
    stats:    a dict with the keys of isorender --stats (docs/python.md)."""

    def __init__(self, vertices, normals, stats=None):
        self.vertices, self.normals, self.stats = vertices, normals, stats
        self.faces = soup_faces(len(vertices) // 3)

    @property
    def triangle_count(self):
        return len(self.faces)

    @property
    def triangles(self):
        """The vertices as float32 (T, 3, 3): triangle, corner, axis (a view, no copy)."""
        return self.vertices.reshape(-1, 3, 3)

    def __len__(self):
        return self.triangle_count

    def __repr__(self):
        return "<isoprop.Mesh %d triangles>" % self.triangle_count


class Step(Mesh):
    """One step of a progressive extraction: the triangles it added (a Mesh of its own),
    `first_triangle` (how many the steps before added), `counts` (this step's rays, seeds,
    cells, triangles, deferred, retired, nodes), `rays` and `rays_total` (cast so far, and one per pixel),
    `done` (every pixel has had its ray) and `stats` (the run so far)."""

    def __init__(self, vertices, normals, stats, first_triangle, counts):
        super().__init__(vertices, normals, stats)
        self.first_triangle, self.counts = first_triangle, counts
        self.rays, self.rays_total, self.done = stats["rays"], stats["rays_total"], stats["done"]

    def __repr__(self):
        return "<isoprop.Step %d new triangles, %d of %d rays>" % (
            self.triangle_count, self.rays, self.rays_total)


def copy_triangles(mesh, first, count):
    """Triangles [first, first + count) of an ip_mesh as (vertices, normals) float32 arrays."""
    if count == 0:
        empty = np.empty((0, 3), dtype=np.float32)
        return empty, empty.copy()
    positions = _view(mesh.positions, np.float32, 9 * first, 9 * count).copy()
    packed = _view(mesh.normals, np.int16, 9 * first, 9 * count)
    # as ip_normal_unpack(): the integer as a float, divided by 32767 in float arithmetic
    normals = np.divide(packed, np.float32(NORMAL_SCALE), dtype=np.float32)
    return positions.reshape(-1, 3), normals.reshape(-1, 3)

# SPDX-License-Identifier: BSD-3-Clause
"""Triangles copied out of a libisoprop mesh into numpy arrays."""
import ctypes

import numpy as np

from . import _structs as S
from ._library import lib

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
    """Triangles as a soup, in the volume's physical space (docs/meshes.md, "Space"), as
    isorender --mesh writes them: sample (i, j, k) sits at origin + D (i, j, k) * spacing, D
    the file's axis directions; or, extracted with space="grid", at (i, j, k) * spacing.

    vertices: float32 (3T, 3), x y z of each triangle's 3 corners in turn;
    normals:  float32 (3T, 3), unit normals at the corners (from the data's gradient, pointing
              toward lower values), turned by D like the vertices;
    faces:    int32 (T, 3), the corners of triangle t: 3t, 3t + 1, 3t + 2;
    space:    the space's name, as a mesh file names it: "RAS", "LAS" or "LPS" where the
              brick file names one, "volume" where it names none, "grid" for space="grid";
    stats:    a dict with the keys of isorender --stats (docs/python.md)."""

    def __init__(self, vertices, normals, stats=None, space=None):
        self.vertices, self.normals, self.stats, self.space = vertices, normals, stats, space
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

    def __init__(self, vertices, normals, stats, first_triangle, counts, space=None):
        super().__init__(vertices, normals, stats, space)
        self.first_triangle, self.counts = first_triangle, counts
        self.rays, self.rays_total, self.done = stats["rays"], stats["rays_total"], stats["done"]

    def __repr__(self):
        return "<isoprop.Step %d new triangles, %d of %d rays>" % (
            self.triangle_count, self.rays, self.rays_total)


def copy_in_space(mesh, first, count, orientation):
    """As copy_triangles(), moved into the physical space of `orientation` (an S.Orientation)
    by the library's own ip_mesh_to_physical(), so that the numbers are those isorender --mesh
    writes; None (or the identity) copies them as they are."""
    if orientation is None or count == 0 or lib.ip_orientation_is_identity(ctypes.byref(orientation)):
        return copy_triangles(mesh, first, count)
    moved = S.Mesh()
    lib.ip_mesh_init(ctypes.byref(moved))
    try:
        if lib.ip_mesh_append_mesh(ctypes.byref(moved), ctypes.byref(mesh), first, count) != 0:
            raise MemoryError("isoprop: no memory for a copy of %d triangles" % count)
        lib.ip_mesh_to_physical(ctypes.byref(moved), ctypes.byref(orientation))
        return copy_triangles(moved, 0, count)
    finally:
        lib.ip_mesh_free(ctypes.byref(moved))


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

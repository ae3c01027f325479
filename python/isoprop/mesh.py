# SPDX-License-Identifier: BSD-3-Clause
"""Triangles copied out of a libisoprop mesh into numpy arrays; a Mesh's welded form, area,
volume, files (through the library's writers) and other libraries' meshes."""
import ctypes
import os
from collections import namedtuple
from typing import Any, Dict, List, Optional, Union

import numpy as np

from . import _structs as S
from ._library import lib
from .errors import ArgumentError, Error, check, new_error

NORMAL_SCALE = 32767.0  # ip_normal_unpack(), include/isoprop/mesh.h
IP_ERR_NOMEM = -2  # include/isoprop/status.h


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


Welded = namedtuple("Welded", "points faces normals dropped")
Welded.__doc__ = """A mesh with shared vertices (Mesh.welded()): points float32 (V, 3), each
position once, numbered in the order of first appearance in the soup; faces int32 (F, 3)
(int64 past 2^31 - 1 points) indexing points, in the soup's order and winding; normals float32
(V, 3), the average of the normals of each point's corners, unit; dropped: how many degenerate
soup triangles (two corners at one position) were left out (0 when they were kept)."""

IMPORT_HINTS = {"pyvista": "pip install pyvista (no Debian package)",
                "trimesh": "Debian: apt-get install python3-trimesh, or pip install trimesh"}


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
    stats:    a dict with the keys of isorender --stats (docs/python.md).

    The same triangles with shared vertices (computed on first use, then kept): points,
    point_normals and indices (welded(): the library's ip_mesh_weld(), as isorender --mesh
    writes them). `faces` stays the soup's, so that vertices[faces] is always the triangles.
    area(), volume(), write() (PLY, STL, OBJ, glTF), to_pyvista() and to_trimesh()."""

    def __init__(self, vertices, normals, stats=None, space=None):
        self.vertices, self.normals, self.stats, self.space = vertices, normals, stats, space
        self.faces = soup_faces(len(vertices) // 3)
        self._welded: Dict[bool, Welded] = {}

    def welded(self, allow_degenerate: bool = False) -> Welded:
        """The triangles with shared vertices (a Welded: points, faces, normals, dropped):
        corners at the same position (bit for bit) become one point. allow_degenerate=False
        (as isorender --mesh) leaves out the triangles with two corners at one position, which
        have no area; True keeps them (faces with a repeated index), so that there are as many
        faces as triangles. Computed once per choice and kept (the arrays are shared)."""
        key = bool(allow_degenerate)
        if key not in self._welded:
            self._welded[key] = weld(self.vertices, self.normals, key)
        return self._welded[key]

    @property
    def points(self) -> np.ndarray:
        """float32 (V, 3): each distinct vertex position once (welded().points)."""
        return self.welded().points

    @property
    def point_normals(self) -> np.ndarray:
        """float32 (V, 3): the unit normal at each point (welded().normals)."""
        return self.welded().normals

    @property
    def indices(self) -> np.ndarray:
        """int32 (F, 3): the triangles as indices into points, degenerate ones left out
        (welded().faces)."""
        return self.welded().faces

    def area(self) -> float:
        """The surface's area: the sum of its triangles' areas, in the mesh's units squared
        (the spacing's units; float64 sums)."""
        t = self.triangles.astype(np.float64)
        cross = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
        return 0.5 * float(np.sqrt(np.einsum("ij,ij->i", cross, cross)).sum())

    def volume(self) -> float:
        """The volume the surface encloses, by the divergence theorem: the sum over triangles
        (a, b, c) of a . (b x c) / 6, in the mesh's units cubed. Triangles are counter-clockwise
        seen from lower values, so the volume of higher values inside a closed surface is
        positive (negative where the surface encloses lower values). For an open surface (one
        that runs out of the volume: extracted surfaces end at the volume's faces) the sum
        depends on where the origin is and is not the volume of anything; close it first (pad
        the array with a value below the level, say)."""
        t = self.triangles.astype(np.float64)
        return float(np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6.0)

    def write(self, path: Union[str, bytes, "os.PathLike[str]"], force: bool = False,
              weld: bool = True) -> None:
        """Writes the mesh in the format its name ends in (.ply, .stl, .obj or .glb, ignoring
        case), as isorender --mesh does, with the library's writers: welded (shared vertices,
        degenerate triangles left out) unless weld=False (--no-weld: 3 vertices a triangle; STL
        is always one). The file names the mesh's space (self.space), and is written
        atomically. Raises isoprop.Error (status IP_ERR_EXISTS) when the file exists and force
        is False, ArgumentError for another extension, isoprop.Error for a failed write."""
        write_mesh(self, path, force, weld)

    def to_pyvista(self) -> Any:
        """The welded mesh as a pyvista.PolyData (points, triangles, "Normals" point data).
        Raises ImportError naming the package when pyvista is not installed."""
        pv = _require("pyvista")
        w = self.welded()
        cells = np.empty((len(w.faces), 4), dtype=np.int64)
        cells[:, 0] = 3
        cells[:, 1:] = w.faces
        poly = pv.PolyData(w.points, cells.ravel())
        poly.point_data["Normals"] = w.normals
        return poly

    def to_trimesh(self) -> Any:
        """The welded mesh as a trimesh.Trimesh (vertices, faces, vertex_normals, process=False
        so that it keeps them as they are). Raises ImportError naming the package when trimesh
        is not installed."""
        trimesh = _require("trimesh")
        w = self.welded()
        return trimesh.Trimesh(vertices=w.points, faces=w.faces, vertex_normals=w.normals,
                               process=False)

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

    def decimate(self, ratio: float, error: Optional[float] = None) -> "Mesh":
        """A simplified copy (isorender --decimate): the mesh welded, then about `ratio`
        (0 < ratio < 1) of its triangles kept by edge collapses (the library's
        ip_indexed_mesh_decimate(), with meshoptimizer), as far as the error stays within
        `error` (the mesh's units; None: 1 % of its size). Vertices on the rim of an open
        surface stay. Returned as a soup like this one, with stats["decimate"]: ratio,
        triangles_before, triangles_after and error (the error reached, meshoptimizer's
        estimate of the distance to the original surface). Fewer triangles would pass the
        bound where triangles_after is above ratio x triangles_before. Raises ArgumentError for
        a bad ratio or error, isoprop.Error where meshoptimizer is missing."""
        return decimate_mesh(self, ratio, error)
    # ---- measuring and cleaning (docs/meshes.md, "Measuring" and "Cleaning"): on the welded
    # mesh, by the library's ip_indexed_mesh_* functions, as isorender --measure ----

    @property
    def bbox(self) -> np.ndarray:
        """float64 (2, 3): the least and greatest coordinate on each axis (zeros when empty)."""
        return _measured(self).bbox

    def measure(self) -> Dict[str, Any]:
        """The figures isorender --stats gives as "surface", as a dict: triangles and vertices
        (welded), area, volume (signed; for an open surface it depends on the origin),
        closed (every edge in exactly two triangles), components, removed_components (0),
        largest (the component of the greatest area: triangles, area, volume) and bbox
        (min, max)."""
        m = _measured(self)
        best = int(np.argmax(m.area)) if len(m.area) else 0
        empty = not len(m.area)
        return {"triangles": len(m.welded.faces), "vertices": len(m.welded.points),
                "area": m.total_area, "volume": m.total_volume, "closed": m.closed,
                "components": len(m.area), "removed_components": 0,
                "largest": {"triangles": 0 if empty else int(m.triangles[best]),
                            "area": 0.0 if empty else float(m.area[best]),
                            "volume": 0.0 if empty else float(m.volume[best])},
                "bbox": {"min": m.bbox[0].tolist(), "max": m.bbox[1].tolist()}}

    def components(self) -> List["Mesh"]:
        """The connected components (triangles joined by a shared vertex, once welded), each a
        Mesh of its triangles (degenerate ones left out), in the order of their first
        triangle."""
        m = _measured(self)
        return [self._subset(m, m.labels == c) for c in range(len(m.area))]

    def largest(self) -> "Mesh":
        """The component of the greatest area (the first of equals), as isorender --largest."""
        return self.clean(largest=True)

    def clean(self, min_area: float = 0.0, largest: bool = False) -> "Mesh":
        """A Mesh of the components of an area of min_area or more (--min-area), only the
        largest with largest=True (--largest); degenerate triangles are left out. Raises
        ArgumentError for a negative or NaN min_area."""
        if not min_area >= 0:
            raise ArgumentError("isoprop: min_area %r is not an area of 0 or more" % (min_area,))
        m = _measured(self)
        keep = m.area >= min_area
        if largest and len(m.area):
            keep &= np.arange(len(m.area)) == int(np.argmax(m.area))
        return self._subset(m, keep[m.labels])

    def _subset(self, m: "_Measures", faces: np.ndarray) -> "Mesh":
        """A Mesh of the soup's triangles whose welded faces `faces` (a mask) marks."""
        t = m.soup_triangles[faces]
        corners = (3 * t[:, None] + np.arange(3)).ravel()
        return Mesh(self.vertices[corners], self.normals[corners], space=self.space)


_Measures = namedtuple("_Measures", "welded labels triangles area volume total_area total_volume "
                       "closed bbox soup_triangles")


def _borrowed_indexed(w: Welded, indices: np.ndarray) -> S.IndexedMesh:
    """An ip_indexed_mesh over a Welded's points and `indices` (uint32, C-contiguous), for the
    library to read (no normals: the measures do not read them)."""
    m = S.IndexedMesh()
    m.positions = w.points.ctypes.data_as(ctypes.POINTER(ctypes.c_float))
    m.indices = indices.ctypes.data_as(ctypes.POINTER(ctypes.c_uint32))
    m.vertex_count, m.triangle_count = len(w.points), len(w.faces)
    return m


def _measured(mesh: Mesh) -> _Measures:
    """The welded mesh's measures and components, by the library; computed once and kept."""
    if getattr(mesh, "_measures", None) is not None:
        return mesh._measures
    w = mesh.welded()
    indices = np.ascontiguousarray(w.faces, dtype=np.uint32)
    points = np.ascontiguousarray(w.points, dtype=np.float32)
    w = w._replace(points=points)
    c = _borrowed_indexed(w, indices)
    labels = np.zeros(len(w.faces), np.uint32)
    count, boundary, nonmanifold = ctypes.c_uint64(), ctypes.c_uint64(), ctypes.c_uint64()
    u32 = ctypes.POINTER(ctypes.c_uint32)
    for st in (lib.ip_indexed_mesh_components(ctypes.byref(c), labels.ctypes.data_as(u32),
                                              ctypes.byref(count)),
               lib.ip_indexed_mesh_edges(ctypes.byref(c), ctypes.byref(boundary),
                                         ctypes.byref(nonmanifold))):
        if st != 0:
            raise MemoryError("isoprop: no memory to measure %d triangles" % len(w.faces))
    n = count.value
    tris, area, volume = np.zeros(n, np.uint64), np.zeros(n), np.zeros(n)
    f64 = ctypes.POINTER(ctypes.c_double)
    lib.ip_indexed_mesh_component_measures(
        ctypes.byref(c), labels.ctypes.data_as(u32), n,
        tris.ctypes.data_as(ctypes.POINTER(ctypes.c_uint64)), area.ctypes.data_as(f64),
        volume.ctypes.data_as(f64))
    lo, hi = (ctypes.c_double * 3)(), (ctypes.c_double * 3)()
    lib.ip_indexed_mesh_bounds(ctypes.byref(c), lo, hi)
    t = mesh.triangles
    # the welded faces are the soup's triangles without two corners at one position, in order
    same = (t[:, 0] == t[:, 1]).all(1) | (t[:, 1] == t[:, 2]).all(1) | (t[:, 0] == t[:, 2]).all(1)
    mesh._measures = _Measures(
        w, labels.astype(np.int64), tris, area, volume,
        float(lib.ip_indexed_mesh_area(ctypes.byref(c))),
        float(lib.ip_indexed_mesh_volume(ctypes.byref(c))),
        len(w.faces) > 0 and boundary.value == 0 and nonmanifold.value == 0,
        np.array([list(lo), list(hi)]), np.flatnonzero(~same))
    return mesh._measures


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


def _require(name: str) -> Any:
    """The module `name`, or ImportError saying how to install it."""
    import importlib
    try:
        return importlib.import_module(name)
    except ImportError as e:
        raise ImportError("isoprop: this needs the package %s, which is not installed (%s)"
                          % (name, IMPORT_HINTS[name]), name=name) from e


def pack_normals(normals: np.ndarray) -> np.ndarray:
    """float32 unit normals as int16, as ip_normal_pack() (include/isoprop/mesh.h): times
    32767, clamped, rounded half away from zero; NaN as 0."""
    s = np.multiply(normals, np.float32(NORMAL_SCALE), dtype=np.float32)
    np.clip(s, -NORMAL_SCALE, NORMAL_SCALE, out=s)
    s[np.isnan(s)] = 0
    s += np.where(s < 0, np.float32(-0.5), np.float32(0.5))
    return s.astype(np.int16)


def _borrowed_soup(vertices: np.ndarray, packed: np.ndarray) -> S.Mesh:
    """An ip_mesh over numpy's memory (C-contiguous float32 positions and int16 normals, 3 a
    triangle): for the library to read, never to free or grow."""
    m = S.Mesh()
    m.positions = vertices.ctypes.data_as(ctypes.POINTER(ctypes.c_float))
    m.normals = packed.ctypes.data_as(ctypes.POINTER(ctypes.c_int16))
    m.triangle_count = m.capacity = m.populated = len(vertices) // 3
    return m


def _unit(normals: np.ndarray) -> np.ndarray:
    """The rows of float32 `normals` scaled to length 1 (zero rows stay zero), in place."""
    length = np.sqrt(np.einsum("ij,ij->i", normals, normals))
    length[length == 0] = 1
    normals /= length[:, None]
    return normals


def _weld_status(st: int, triangles: int) -> None:
    """Raises for a failed ip_mesh_weld(): MemoryError, or isoprop.Error."""
    if st == IP_ERR_NOMEM:
        raise MemoryError("isoprop: no memory to weld %d triangles" % triangles)
    if st != 0:
        raise Error(st, "isoprop: welding %d triangles: more than 2^32 - 2 distinct vertices"
                    % triangles)


def weld_c(mesh: S.Mesh, keep_degenerate: bool) -> Welded:
    """An ip_mesh (the library's or borrowed) welded by the library, as numpy arrays."""
    out = S.IndexedMesh()
    fn = lib.ip_mesh_weld_keep_degenerate if keep_degenerate else lib.ip_mesh_weld
    _weld_status(fn(ctypes.byref(mesh), ctypes.byref(out)), mesh.triangle_count)
    try:
        return indexed_arrays(out)
    finally:
        lib.ip_indexed_mesh_free(ctypes.byref(out))


def indexed_arrays(out: S.IndexedMesh, reverse: bool = False, take: bool = False) -> Welded:
    """The library's ip_indexed_mesh `out` as numpy arrays; with `reverse`, points and normals
    z, y, x (an array's axis order), in the same one copy; with `take`, faces are out's own
    indices, no copy, whose memory they then own (out.indices becomes NULL), where they fit
    int32. out stays the caller's."""
    nv, nf = out.vertex_count, out.triangle_count
    order = slice(None, None, -1 if reverse else 1)
    points = np.empty((nv, 3), np.float32)
    normals = np.empty((nv, 3), np.float32)
    if nv:
        points[:] = _view(out.positions, np.float32, 0, 3 * nv).reshape(-1, 3)[:, order]
        np.divide(_view(out.normals, np.int16, 0, 3 * nv).reshape(-1, 3)[:, order],
                  np.float32(NORMAL_SCALE), out=normals)
    dtype = np.int32 if nv < 2 ** 31 else np.int64
    if take and nf and dtype == np.int32:
        faces = take_c(out.indices, np.int32, 3 * nf).reshape(-1, 3)
        out.indices = None
    else:
        faces = (_view(out.indices, np.uint32, 0, 3 * nf).astype(dtype).reshape(-1, 3) if nf
                 else np.empty((0, 3), dtype))
    return Welded(points, faces, _unit(normals), int(out.dropped_triangles))


class _Freed:
    """Frees (libc's free()) the memory at `address` when the last array over it goes."""

    def __init__(self, address: int) -> None:
        self.address = address

    def __del__(self) -> None:
        free_c(self.address)


def take_c(pointer: Any, dtype: Any, count: int) -> np.ndarray:
    """A numpy array over `count` values of `dtype` at the C array `pointer`, which the
    library allocated for its caller to free(): the array (and its views) own it from now on,
    no copy. count > 0."""
    address = ctypes.cast(pointer, ctypes.c_void_p).value
    buffer = (ctypes.c_char * (count * np.dtype(dtype).itemsize)).from_address(address)
    buffer._freed = _Freed(address)  # freed with the buffer, which every view keeps
    return np.frombuffer(buffer, dtype)


def free_c(pointer: Any) -> None:
    """Releases an array the library allocated for its caller to free() (libc's)."""
    global _libc
    if _libc is None:
        _libc = ctypes.CDLL(None)
        _libc.free.argtypes = [ctypes.c_void_p]
        _libc.free.restype = None
    _libc.free(pointer if isinstance(pointer, int) else ctypes.cast(pointer, ctypes.c_void_p))


_libc = None


def weld(vertices: np.ndarray, normals: np.ndarray, keep_degenerate: bool = False) -> Welded:
    """A soup (float32 (3T, 3) vertices and normals) welded by the library (ip_mesh_weld(), or
    ip_mesh_weld_keep_degenerate() when keep_degenerate)."""
    v = np.ascontiguousarray(vertices, dtype=np.float32)
    packed = pack_normals(np.ascontiguousarray(normals, dtype=np.float32))
    return weld_c(_borrowed_soup(v, packed), keep_degenerate)


def _space_name(space: Optional[str]) -> Optional[bytes]:
    return space.encode() if space else None


def write_mesh(mesh: Mesh, path: Any, force: bool, weld_it: bool) -> None:
    """Mesh.write(): the library's ip_indexed_mesh_write_in() or ip_mesh_write_in()."""
    from . import _check as C
    C.path("path", path)
    force = C.flag("force", force)
    weld_it = C.flag("weld", weld_it)
    encoded = os.fsencode(path)
    if lib.ip_mesh_format_of(encoded) is None:
        raise ArgumentError("path: %r: not a mesh file name (.ply, .stl, .obj or .glb)" % (path,))
    err = new_error()
    v = np.ascontiguousarray(mesh.vertices, dtype=np.float32)
    packed = pack_normals(np.ascontiguousarray(mesh.normals, dtype=np.float32))
    if not weld_it:
        st = lib.ip_mesh_write_in(ctypes.byref(_borrowed_soup(v, packed)), encoded,
                                  _space_name(mesh.space), int(force), ctypes.byref(err))
        check(st, err)
        return
    out = S.IndexedMesh()  # welded here by the library, so the file is isorender's, byte for byte
    _weld_status(lib.ip_mesh_weld(ctypes.byref(_borrowed_soup(v, packed)), ctypes.byref(out)),
                 len(v) // 3)
    try:
        st = lib.ip_indexed_mesh_write_in(ctypes.byref(out), encoded, _space_name(mesh.space),
                                          int(force), ctypes.byref(err))
    finally:
        lib.ip_indexed_mesh_free(ctypes.byref(out))
    check(st, err)


def decimate_mesh(mesh: Mesh, ratio: Any, error: Any) -> Mesh:
    """Mesh.decimate(): welded, simplified by the library, repeated back into a soup."""
    from . import _check as C
    ratio = C.number("ratio", ratio)
    if not 0 < ratio < 1:
        raise ArgumentError("ratio: %r is not a share of the triangles to keep, in (0, 1)"
                            % ratio)
    bound = 0.0 if error is None else C.positive("error", error)
    v = np.ascontiguousarray(mesh.vertices, dtype=np.float32)
    packed = pack_normals(np.ascontiguousarray(mesh.normals, dtype=np.float32))
    out, err, reached = S.IndexedMesh(), new_error(), ctypes.c_double()
    soup = _borrowed_soup(v, packed)
    _weld_status(lib.ip_mesh_weld(ctypes.byref(soup), ctypes.byref(out)), soup.triangle_count)
    try:
        before = int(out.triangle_count)
        if before:
            check(lib.ip_indexed_mesh_decimate(ctypes.byref(out), ratio, bound,
                                               ctypes.byref(reached), ctypes.byref(err)), err)
        welded = indexed_arrays(out)
    finally:
        lib.ip_indexed_mesh_free(ctypes.byref(out))
    stats = dict(mesh.stats or {})
    stats["decimate"] = {"ratio": ratio, "triangles_before": before,
                         "triangles_after": len(welded.faces), "error": reached.value}
    corners = welded.faces.reshape(-1)
    return Mesh(welded.points[corners], welded.normals[corners], stats, mesh.space)

# SPDX-License-Identifier: BSD-3-Clause
"""One call from an array: marching_cubes() (scikit-image's signature and conventions) and
contour() (the view-dependent surface of an array or a brick file), both over a File."""
import math
import os
from typing import Any, Optional, Sequence, Tuple, Union

import numpy as np

from . import _check as C
from .array import open_array
from .errors import ArgumentError
from .mesh import Mesh
from .volume import open as open_file

# dtypes a brick file holds; others are converted (_as_volume())
STORED = (np.uint8, np.uint16, np.int16, np.float32)
DIRECTIONS = ("descent", "ascent")
AXES = "axis 0, 1, 2"

PathLike = Union[str, bytes, "os.PathLike[str]"]


def _as_volume(name: str, volume: Any) -> np.ndarray:
    """`volume` as a 3-D numpy array of a dtype a brick file holds: bool as uint8, int8 as
    int16, any other number type as float32 (which rounds integers past 2^24 and float64)."""
    a = np.asarray(volume)
    if a.ndim != 3:
        raise ArgumentError("%s: must be a 3-D array, not %d-D (shape %s)" % (name, a.ndim,
                                                                             a.shape))
    if min(a.shape) < 2:
        raise ArgumentError("%s: shape %s: at least 2 samples along each axis" % (name, a.shape))
    if a.dtype == np.bool_:
        return a.astype(np.uint8)
    if a.dtype == np.int8:
        return a.astype(np.int16)
    if any(a.dtype == np.dtype(t) for t in STORED):
        return a
    if a.dtype.kind not in "uif":
        raise TypeError("%s: must hold numbers, not %s" % (name, a.dtype))
    return a.astype(np.float32)


def _axis_spacing(spacing: Any) -> Tuple[float, float, float]:
    """spacing (axis 0, 1, 2): three positive finite numbers."""
    out = [C.number("spacing", v, axis) for v, axis in
           zip(C.numbers_of("spacing", spacing, 3, AXES), ("axis 0", "axis 1", "axis 2"))]
    for s, axis in zip(out, range(3)):
        if not (s > 0 and math.isfinite(s)):
            raise ArgumentError("spacing: axis %d: %r is not a positive finite number" % (axis, s))
    return out[0], out[1], out[2]


def _level(level: Any, value_range: Tuple[float, float]) -> float:
    """The isovalue: the midpoint of the data's range `value_range` (min, max) for None;
    ValueError naming `level` when it is NaN or outside [min, max], as scikit-image."""
    lo, hi = float(value_range[0]), float(value_range[1])
    if level is None:
        return 0.5 * (lo + hi)
    value = C.number("level", level)
    if not lo <= value <= hi:
        raise ArgumentError("level: %r is outside the data's range, %g .. %g" % (value, lo, hi))
    return value


def marching_cubes(volume: Any, level: Optional[float] = None, *,
                   spacing: Sequence[float] = (1.0, 1.0, 1.0),
                   gradient_direction: str = "descent", allow_degenerate: bool = True,
                   threads: int = 0
                   ) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The isosurface `level` of the 3-D array `volume`, every cell of it, as scikit-image's
    skimage.measure.marching_cubes() returns it: (verts, faces, normals, values).

    volume: any 3-D array of numbers (uint8, uint16, int16 and float32 as they are; bool as
    uint8, int8 as int16, others as float32). level: the midpoint of the data's range when None;
    ValueError naming `level` when NaN or outside [min, max]. spacing: the distance between
    samples along axis 0, 1, 2 of the array (scikit-image's order). gradient_direction:
    "descent" (the object holds the higher values) or "ascent" (the lower), which sets the
    faces' winding as scikit-image does. allow_degenerate: keep the triangles with two corners
    at one position (the surface through a sample), so that the face count is the one of
    classic marching cubes (VTK's); False leaves them out. threads: 0 for every core.

    verts: float32 (V, 3), axis 0, 1, 2 of the array times spacing, each vertex once (shared by
    the faces that meet there); faces: int32 (F, 3) indices into verts, counter-clockwise seen
    from the higher values for "descent", from the lower for "ascent"; normals: float32 (V, 3)
    unit, toward lower values (minus the data's gradient; either direction); values: float32
    (V,), the larger of the two samples at the ends of the grid edge each vertex lies on (its
    sample where it sits on one): as scikit-image's, the data's maximum near the vertex.
    Raises RuntimeError when there is no surface at `level` (as scikit-image)."""
    a = _as_volume("volume", volume)
    sp = _axis_spacing(spacing)
    gradient_direction = C.choice("gradient_direction", gradient_direction, DIRECTIONS)
    allow_degenerate = C.flag("allow_degenerate", allow_degenerate)
    threads = C.whole("threads", threads, 0, C.MAX_VIEW_THREADS)
    with open_array(a, spacing=tuple(sp[::-1])) as f:
        # the range from the store's summaries, which opening it works out: no pass over `a`
        iso = _level(level, f.value_range_stored)
        welded = f._full_welded(iso, threads, allow_degenerate)
    if welded is None:
        raise RuntimeError("marching_cubes: no surface at level %r" % iso)
    w, values = welded
    # x, y, z (the file's) is axis 2, 1, 0 of the array: a reflection, so the faces, which are
    # counter-clockwise from lower values in x, y, z, are so from higher values in axis order
    # (_full_welded() gives the points and normals in axis order)
    faces = w.faces if gradient_direction == "descent" else np.ascontiguousarray(w.faces[:, ::-1])
    return w.points, faces, w.normals, values


def contour(volume_or_path: Union[PathLike, Any], level: float, *, view: Optional[str] = None,
            camera: Any = None, size: Sequence[int] = (800, 600),
            spacing: Optional[Sequence[float]] = None, stored: bool = False,
            **options: Any) -> Mesh:
    """The view-dependent isosurface `level` (File.extract()'s progressive route: the
    triangles the rays of a `size` image seen from `view` or `camera` reach) of an array or a
    brick file, as a Mesh.

    volume_or_path: a path to a brick file (its spacing, space and rescale; `level` in its
    units, or stored=True) or a 3-D array (converted as marching_cubes() does; spacing along
    its axis 0, 1, 2, default 1). The Mesh is File.extract()'s: vertices x, y, z, which for an
    array are its axis 2, 1, 0 (mesh.vertices[:, ::-1] is axis order), normals toward lower
    values. Other keywords are File.extract()'s (rays, time_limit, threads, lod, pixel_error,
    occlusion, cull, space, ...), except full (marching_cubes() or File.extract(full=True))."""
    if "full" in options:
        raise ArgumentError("full: contour() is the view-dependent surface; for every cell use "
                            "marching_cubes() or File.extract(full=True)")
    if isinstance(volume_or_path, (str, bytes, os.PathLike)):
        if spacing is not None:
            raise ArgumentError("spacing: a brick file has its own (only for an array)")
        with open_file(volume_or_path) as f:
            return f.extract(level, stored=stored, view=view, camera=camera, size=size,
                             **options)
    a = _as_volume("volume_or_path", volume_or_path)
    sp = _axis_spacing((1.0, 1.0, 1.0) if spacing is None else spacing)
    with open_array(a, spacing=tuple(sp[::-1])) as f:
        return f.extract(level, stored=stored, view=view, camera=camera, size=size, **options)


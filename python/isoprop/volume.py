# SPDX-License-Identifier: BSD-3-Clause
"""isoprop.open(): a brick file, and extraction from it, full or progressive."""
import ctypes
import os
import threading
import warnings
from collections import namedtuple
from typing import Any, Callable, Dict, Iterator, Mapping, Optional, Tuple, Union

import numpy as np

from . import _structs as S
from ._library import lib
from . import _check as C
from .bricking import DTYPES
from .errors import ArgumentError, check, new_error
from .mesh import Mesh, Step, copy_in_space, free_c, indexed_arrays, take_c
from .stats import counts_dict, run_stats

Level = namedtuple("Level", "level dims bricks value_range")
Level.__doc__ = """One level of the pyramid: level k samples the volume at every 2^k-th sample;
dims and bricks along x, y, z; value_range (min, max) of its samples, in the file's units
where it has a rescale."""

Rescale = namedtuple("Rescale", "slope intercept unit")
Rescale.__doc__ = """What a file's stored sample values stand for: value = stored * slope +
intercept, in unit ("HU" for a DICOM CT; "" when the input named none)."""

DEFAULT_SIZE = (1600, 1200)  # isorender's
PathLike = Union[str, bytes, "os.PathLike[str]", "os.PathLike[bytes]"]
# a camera: isorender's --camera text or a dict of eye, target, up (and fov)
CameraLike = Union[None, str, Mapping[str, Any]]
VIEW_FOV = 30.0  # degrees: the field of view of the named views (isorender --view)
# views and cameras are in the file's physical space (isoprop/camera.h, "Views in physical
# space"); the engine takes their world counterparts


SPACES = ("physical", "grid")  # extract(space=...): docs/meshes.md, "Space"

BUSY = "isoprop.File: another call is running on this File (one thread at a time)"


class _Args:
    """The checked keywords of an extraction (or of File.camera()): each as the library takes
    it. Raises TypeError or isoprop.ArgumentError naming the first bad one, before any work."""

    def __init__(self, view=None, camera=None, size=DEFAULT_SIZE, threads=0, cutoff=None,
                 foldback=None, lod=True, pixel_error=1.0, occlusion=True, prefetch=True,
                 cull=False, cache_mb=None):
        self.camera = C.camera(camera)
        self.view = C.view(view, camera)
        self.size = C.size(size)
        self.threads = C.whole("threads", threads, 0, C.MAX_VIEW_THREADS)
        self.cutoff = C.degrees("cutoff", cutoff, 0, True)
        self.foldback = C.degrees("foldback", foldback, 0, False)
        self.lod = C.flag("lod", lod)
        self.pixel_error = C.positive("pixel_error", pixel_error)
        self.occlusion = C.flag("occlusion", occlusion)
        self.prefetch = C.prefetch(prefetch)
        self.cull = C.flag("cull", cull)
        self.cache_mb = C.cache_mb(cache_mb)

    def engine_options(self):
        o = S.EngineOptions()
        lib.ip_engine_options_default(ctypes.byref(o))
        if self.cutoff is not None:
            o.cutoff_degrees = self.cutoff
        if self.foldback is not None:
            o.foldback_degrees = self.foldback
        o.threads, o.lod, o.pixel_error = self.threads, int(self.lod), self.pixel_error
        o.occlusion = int(self.occlusion)
        # prefetch: True (on) or False (off), or "always" (isorender --prefetch always)
        o.prefetch = (S.PREFETCH_ALWAYS if self.prefetch == "always"
                      else S.PREFETCH_ON if self.prefetch else S.PREFETCH_OFF)
        o.cull = int(self.cull)
        return o


def _camera_from(camera, size):
    """An ip_camera from "ex,ey,ez,tx,ty,tz,ux,uy,uz,fov" (isorender --camera) or a dict with
    eye, target, up (the file's physical units) and fov (degrees, default 30), both as
    _check.camera() gives them; ArgumentError when the library refuses it."""
    c, err = S.Camera(), new_error()
    c.width, c.height = size
    if isinstance(camera, str):
        if lib.ip_camera_parse(camera.encode(), ctypes.byref(c), ctypes.byref(err)) != 0:
            raise ArgumentError('camera: %r is not "ex,ey,ez,tx,ty,tz,ux,uy,uz,fov" (physical '
                                "units, degrees)" % camera)
    else:
        c.eye[:], c.target[:], c.up[:] = camera["eye"], camera["target"], camera["up"]
        c.fov_y = camera.get("fov", VIEW_FOV)
    if lib.ip_camera_check(ctypes.byref(c), ctypes.byref(err)) != 0:
        raise ArgumentError(err.message.decode("utf-8", "replace"))  # "camera: ..."
    return c


class _Run:
    """One extraction's engine and figures; its engine (if any) is freed by destroy().
    rays and time_limit (None: no limit) and rays_per_step (None: 1, 2, 4, ...) say how a
    progressive run steps (_advance())."""

    def __init__(self, f, iso, full, camera, options, rays=None, time_limit=None,
                 rays_per_step=None, space="physical"):
        """iso: (value in the file's units, stored value, whether it was given stored), as
        File._isovalue() settles it. space: where the triangles go, the file's physical space
        or the grid (index x spacing)."""
        self.path, self.summary_bytes = f.path, f._summary_bytes
        self.orientation = f._orientation if space == "physical" else None
        self.space = f._space if space == "physical" else "grid"
        (self.iso, self.iso_stored, stored), self.rescale = iso, f.rescale
        self.full, self.camera, self.options = full, camera, options
        self.physical = f._physical(camera)  # the camera the statistics report
        self.engine, self.wall_seconds, self.warnings = None, 0.0, []
        self.limit = rays if rays is not None else C.MAX_COUNT
        self.time_limit, self.rays_per_step, self.target = time_limit, rays_per_step, 1
        lo, hi = f.value_range_stored
        v = float(np.float32(self.iso_stored))  # the isovalue as the engine takes it
        if not (lo < v <= hi):
            given, (a, b) = ((self.iso_stored, (lo, hi)) if stored or not f.rescale
                             else (self.iso, f.value_range))
            unit = " " + f.rescale.unit if f.rescale and f.rescale.unit and not stored else ""
            reversed_ = bool(f.rescale) and f.rescale.slope < 0 and not stored
            rule = ("at least the minimum and below the maximum" if reversed_
                    else "above the minimum and at most the maximum")
            text = ("iso %g%s is outside the value range of %s, %g .. %g%s: there is no "
                    "surface (an isovalue must be %s)"
                    % (given, " (stored)" if stored else "", f.path, a, b, unit, rule))
            self.warnings.append(text)
            warnings.warn(text, RuntimeWarning, stacklevel=4)

    def done(self):
        return bool(self.full) or bool(self.engine and lib.ip_engine_done(self.engine))

    def destroy(self):
        if self.engine:
            lib.ip_engine_destroy(self.engine)
            self.engine = None


class _Call:
    """`with _Call(f):` around every use of a File's store, cache or engines. One call at a
    time: a second one, from another thread or from inside the first (on_step), raises
    RuntimeError at once rather than wait. The lock is what makes releasing the GIL in the
    library's calls safe: no other call can free the cache or an engine under one."""

    def __init__(self, f):
        self.f = f

    def __enter__(self):
        if not self.f._lock.acquire(blocking=False):
            raise RuntimeError(BUSY)
        try:
            self.f._reap()
        except BaseException:
            self.f._lock.release()
            raise

    def __exit__(self, *exc):
        try:
            self.f._reap()
        finally:
            self.f._lock.release()


class File:
    """An open brick file (isoprop.open()). Attributes: path, dims (x, y, z samples), shape
    (z, y, x, as a numpy array of the volume), dtype (numpy), spacing (x, y, z world units),
    origin and directions (where sample (0, 0, 0) is and the unit direction of each sample
    axis in the file's physical space; a mesh's vertices are origin + D (i, j, k) * spacing),
    space (the anatomical space the file names, "RAS", "LAS" or "LPS", or None), rescale (a
    Rescale: what the stored values stand for, as isoinfo shows it; None when the file has
    none), value_range (min, max; in the file's units where it has a rescale),
    value_range_stored (the same as stored values), levels (a tuple of Level, level 0 first),
    brick_size, subblock_size, file_bytes, format_version. Isovalues are in the file's units
    (stored=True: stored values). One call at a time: a call (extract(), a step of
    extract_steps(), close()) made while another is running on the same File, from another
    thread or from an on_step callback, raises RuntimeError; it never waits, and never
    crashes. close() (or a with block) frees it, and so does garbage collection."""

    def __init__(self, path: PathLike) -> None:
        self._init_state()
        C.path("path", path)
        err, store = new_error(), ctypes.c_void_p()
        check(lib.ip_store_open(os.fsencode(path), ctypes.byref(store), ctypes.byref(err)), err)
        self._adopt(store)

    def _init_state(self, array=None):
        """The state of a File with no store yet; `array`: the numpy array a store in memory
        (isoprop.open_array()) reads, kept referenced until the store is closed."""
        self._lock, self._orphans = threading.Lock(), []
        self._store, self._cache, self._cache_budget, self._runs = None, None, 0, set()
        self._array = array

    def _adopt(self, store):
        """Takes the open store `store` (a brick file's or an array's) and reads its layout."""
        self._store = store
        l = lib.ip_store_layout(store).contents
        self.path = lib.ip_store_path(store).decode()
        self.dims = tuple(l.dims)
        self.shape = self.dims[::-1]
        self.dtype = np.dtype(DTYPES[l.type])
        self.spacing = tuple(l.spacing)
        self.space = lib.ip_space_name(l.orientation.space).decode() or None
        self._rescale = S.Rescale.from_buffer_copy(l.rescale)  # for the library's conversions
        self.rescale = (Rescale(l.rescale.slope, l.rescale.intercept, l.rescale.unit.decode())
                        if l.rescale.present else None)
        self.value_range_stored = (l.value_min, l.value_max)
        self.value_range = self._values(l.value_min, l.value_max)
        self.levels = tuple(
            Level(k, tuple(lv.dims), tuple(lv.bricks), self._values(lv.value_min, lv.value_max))
            for k, lv in ((k, l.levels[k]) for k in range(l.level_count)))
        self.format_version = l.format_version
        self.brick_size, self.subblock_size = l.brick_edge, l.subblock_edge
        self.file_bytes = l.file_size
        self._orientation = S.Orientation.from_buffer_copy(l.orientation)
        self.origin = tuple(l.orientation.origin)
        self.directions = tuple(tuple(d) for d in l.orientation.directions)
        self._space = lib.ip_mesh_space_of(ctypes.byref(self._orientation)).decode()
        self._summary_bytes = lib.ip_store_summary_memory(store)
        lo, hi = (ctypes.c_double * 3)(), (ctypes.c_double * 3)()
        lib.ip_layout_world_box(ctypes.byref(l), lo, hi)
        self.world_box = (tuple(lo), tuple(hi))

    def _values(self, lo, hi):
        """The stored range lo .. hi in the file's units, lowest first."""
        a, b = (lib.ip_rescale_to_value(ctypes.byref(self._rescale), v) for v in (lo, hi))
        return (a, b) if a <= b else (b, a)

    def _isovalue(self, iso, stored):
        """(value in the file's units, stored value the engine extracts, stored) of a checked
        `iso` given in the file's units, or as a stored value with stored=True: one from the
        other through the library's ip_rescale_to_stored() / _to_value()."""
        stored = C.flag("stored", stored)
        r = ctypes.byref(self._rescale)
        value, raw = ((lib.ip_rescale_to_value(r, iso), iso) if stored
                      else (iso, lib.ip_rescale_to_stored(r, iso)))
        C.isovalue(raw)  # the stored value too must be a finite float32
        return value, raw, stored

    # -- life time ------------------------------------------------------------------------
    def close(self) -> None:
        """Frees the engines of unfinished extract_steps() runs, the cache and the store.
        Raises RuntimeError, closing nothing, while another call on this File is running (the
        File stays usable; close it once that call has returned)."""
        with _Call(self):
            self._close()

    def _close(self):
        for run in list(self._runs):
            run.destroy()
        self._runs.clear()
        if self._cache:
            lib.ip_cache_destroy(self._cache)
            self._cache = None
        if self._store:
            lib.ip_store_close(self._store)
            self._store = None
        self._array = None  # the store that read it is gone

    def __enter__(self) -> "File":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def __del__(self):
        # no call can be running: a running call holds a reference to the File
        if getattr(self, "_store", None) is not None and lib is not None and \
                self._lock.acquire(blocking=False):
            try:
                self._close()
            finally:
                self._lock.release()

    def __repr__(self) -> str:
        return "<isoprop.File %s %s %s>" % (self.path, "x".join(map(str, self.dims)),
                                            self.dtype.name)

    def _reap(self):
        """Frees the engines of extract_steps() runs that ended while another call held the
        File (_drop()); under the lock."""
        while self._orphans:
            self._end(self._orphans.pop())

    def _drop(self, run):
        """Frees `run` (an extract_steps() run that has ended) now, or, when another call is
        running (a generator closed from another thread, or collected during a call), when
        that call ends."""
        self._orphans.append(run)
        if self._lock.acquire(blocking=False):
            try:
                self._reap()
            finally:
                self._lock.release()

    def _open_store(self):
        if not self._store:
            raise ValueError("%s: the file is closed" % self.path)
        return self._store

    def _cache_for(self, cache_mb):
        """The brick cache, kept from one extraction to the next (warm); `cache_mb` other than
        the current budget makes a new one (None: keep it, or the default budget)."""
        store = self._open_store()
        budget = lib.ip_cache_default_budget() if cache_mb is None else cache_mb << 20
        if self._cache and (cache_mb is None or budget == self._cache_budget):
            return self._cache
        if self._runs:
            raise ValueError("%s: cache_mb cannot change while an extract_steps() run is open"
                             % self.path)
        if self._cache:
            lib.ip_cache_destroy(self._cache)
            self._cache = None
        err, cache = new_error(), ctypes.c_void_p()
        check(lib.ip_cache_create(store, budget, ctypes.byref(cache), ctypes.byref(err)), err)
        self._cache, self._cache_budget = cache, budget
        return cache

    def camera(self, view: Optional[str] = None, camera: CameraLike = None,
               size: Tuple[int, int] = DEFAULT_SIZE) -> Dict[str, Any]:
        """The camera an extraction uses, as a dict (eye, target, up, fov, width, height) in the
        file's physical space, as camera= takes it. Touches nothing of the File but its box:
        callable at any time, from any thread."""
        c = self._physical(self._camera(_Args(view=view, camera=camera, size=size)))
        return {"eye": tuple(c.eye), "target": tuple(c.target), "up": tuple(c.up),
                "fov": c.fov_y, "width": c.width, "height": c.height}

    def _physical(self, world):
        """The physical camera of a world camera."""
        c = S.Camera()
        lib.ip_camera_to_physical(ctypes.byref(self._orientation), ctypes.byref(world),
                                  ctypes.byref(c))
        return c

    def _camera(self, a):
        """The world camera (what the engine takes) of a's camera or view, both physical."""
        self._open_store()
        if a.camera is not None:
            c = _camera_from(a.camera, a.size)
            lib.ip_camera_to_world(ctypes.byref(self._orientation), ctypes.byref(c),
                                   ctypes.byref(c))
            return c
        c, err = S.Camera(), new_error()
        lo, hi = ((ctypes.c_double * 3)(*b) for b in self.world_box)
        view = a.view.encode() if a.view is not None else None
        st = lib.ip_camera_fit_view(ctypes.byref(self._orientation), lo, hi, view, VIEW_FOV,
                                    a.size[0], a.size[1], ctypes.byref(c), ctypes.byref(err))
        if st != 0:  # an anatomical view in a file without a space: an argument of the call
            raise ArgumentError("view: %s: %s" % (self.path,
                                                  err.message.decode("utf-8", "replace")))
        return c

    # -- extraction -----------------------------------------------------------------------
    def extract(self, iso: float, *, stored: bool = False, view: Optional[str] = None,
                camera: CameraLike = None, size: Tuple[int, int] = DEFAULT_SIZE,
                rays: Optional[int] = None, full: Union[bool, str] = False,
                time_limit: Optional[float] = None, threads: int = 0,
                cutoff: Optional[float] = None, foldback: Optional[float] = None,
                lod: bool = True, pixel_error: float = 1.0, occlusion: bool = True,
                prefetch: Union[bool, str] = True, cull: bool = False,
                cache_mb: Optional[int] = None,
                on_step: Optional[Callable[[Step], Any]] = None,
                space: str = "physical", cap: bool = False) -> Mesh:
        """Extracts the isosurface `iso` and returns a Mesh (vertices, normals, faces, stats).
        `iso` is in the file's units where it has a rescale (self.rescale: HU for a DICOM CT),
        else a stored value; stored=True takes it as a stored sample value (isorender
        --iso-stored). The stats give both ("iso", "iso_stored") with a rescale.

        Progressive (the default), as isorender: rays in the paper's order for the image of
        `size` (width, height) pixels seen from `view` (the side the eye is on, in the file's
        physical space: anterior posterior left right superior inferior in a file with an
        anatomical space, +x -x +y -y +z -z along its physical axes; None: anterior, or -y in a
        file without a space) or `camera` (a dict eye/target/up/fov or isorender's --camera
        text, in physical units), until every
        pixel has had its ray, `rays` rays or `time_limit` seconds. full=True triangulates
        every active cell instead (isorender --full; the view does not matter); full="lod"
        every active cell at the view's adaptive resolution, each level's cells within its
        distance band (isorender --full-lod: what the progressive mesh with lod on draws once
        every pixel has had its ray; needs lod on). threads (0:
        every core), cutoff and foldback (degrees), lod, pixel_error, occlusion, prefetch (True,
        False or "always") and cull are isorender's options (cull off by default here: the mesh
        is the product, not an image of it); cache_mb the brick cache's budget (the cache stays warm
        between calls). on_step(step), if given, sees each step (as extract_steps() yields);
        it runs inside the call, so calling this File from it raises RuntimeError.
        space: "physical" (the default) gives the vertices in the file's physical space, as
        isorender --mesh writes them; "grid" as sample index x spacing from 0 (the Mesh's
        `space` names which). cap=True (with full=True, isorender --cap) closes the surface where
        it leaves the volume's box: each face's region above the isovalue, triangulated from the
        same samples, its rim the surface's boundary vertices, so that the welded mesh is closed.
        Every argument is checked first (TypeError, or isoprop.ArgumentError, a ValueError,
        naming it). Raises isoprop.Error for a file that cannot be read, RuntimeError when
        another call on this File is running."""
        iso = self._isovalue(C.isovalue(iso), stored)
        a = _Args(view=view, camera=camera, size=size, threads=threads, cutoff=cutoff,
                  foldback=foldback, lod=lod, pixel_error=pixel_error, occlusion=occlusion,
                  prefetch=prefetch, cull=cull, cache_mb=cache_mb)
        rays = C.count_or_none("rays", rays, 0)
        time_limit = C.seconds_or_none("time_limit", time_limit)
        C.callable_or_none("on_step", on_step)
        full = C.full(full)
        space = C.choice("space", space, SPACES)
        cap = C.flag("cap", cap)
        if cap and full is not True:
            raise ArgumentError("cap: closes the whole surface at the volume's faces: it needs "
                                "full=True")
        if full:
            given = [n for n, v in (("rays", rays), ("time_limit", time_limit),
                                    ("on_step", on_step)) if v is not None]
            if given:
                raise ArgumentError("%s: not with full=%r, which extracts everything (no rays, "
                                    "time_limit or on_step)" % (given[0], full))
            if full == "lod" and not a.lod:
                raise ArgumentError('full: "lod" is the full extraction at adaptive resolution: '
                                    "not with lod=False (full=True is that)")
            with _Call(self):
                return self._extract_full(iso, full, a, space, cap)
        with _Call(self):
            run = self._begin(iso, a, rays, time_limit, None, space)
            try:
                while True:
                    step = self._advance(run)
                    if step is None:
                        break
                    if on_step is not None:
                        on_step(self._step(run, *step))
                mesh = lib.ip_engine_mesh(run.engine).contents
                vertices, normals = copy_in_space(mesh, 0, mesh.triangle_count, run.orientation)
                return Mesh(vertices, normals, self._stats(run), run.space)
            finally:
                self._end(run)

    def extract_steps(self, iso: float, *, stored: bool = False,
                      rays_per_step: Optional[int] = None, rays: Optional[int] = None,
                      time_limit: Optional[float] = None, view: Optional[str] = None,
                      camera: CameraLike = None, size: Tuple[int, int] = DEFAULT_SIZE,
                      threads: int = 0, cutoff: Optional[float] = None,
                      foldback: Optional[float] = None, lod: bool = True,
                      pixel_error: float = 1.0, occlusion: bool = True,
                      prefetch: Union[bool, str] = True, cull: bool = False,
                      cache_mb: Optional[int] = None,
                      space: str = "physical") -> Iterator[Step]:
        """Progressive extraction as a generator: yields a Step (the step's new triangles, its
        counts, the run's statistics so far) after each step of the engine, until every pixel
        has had its ray, `rays` rays or `time_limit` seconds. Steps cast `rays_per_step` rays
        each (None: 1, 2, 4, ... as isorender does, so that the first images come at once).
        Other keywords as extract(), checked here, before the first step. Closing the
        generator (or leaving its loop) frees the engine; the triangles of all steps, in
        order, are those of one extract() of the same rays on one thread. Each step is one
        call on the File (RuntimeError while another is running); between steps the File is
        free for other calls."""
        iso = self._isovalue(C.isovalue(iso), stored)
        a = _Args(view=view, camera=camera, size=size, threads=threads, cutoff=cutoff,
                  foldback=foldback, lod=lod, pixel_error=pixel_error, occlusion=occlusion,
                  prefetch=prefetch, cull=cull, cache_mb=cache_mb)
        rays_per_step = C.count_or_none("rays_per_step", rays_per_step, 1)
        rays = C.count_or_none("rays", rays, 0)
        time_limit = C.seconds_or_none("time_limit", time_limit)
        space = C.choice("space", space, SPACES)
        return self._steps(iso, a, rays, time_limit, rays_per_step, space)

    def _steps(self, iso, a, rays, time_limit, rays_per_step, space):
        run = None
        try:
            while True:
                with _Call(self):
                    if run is None:
                        run = self._begin(iso, a, rays, time_limit, rays_per_step, space)
                    step = self._advance(run)
                    if step is None:
                        return
                    step = self._step(run, *step)
                yield step
        finally:
            if run is not None:
                self._drop(run)

    def _begin(self, iso, a, rays, time_limit, rays_per_step, space):
        cam = self._camera(a)
        options = a.engine_options()
        cache = self._cache_for(a.cache_mb)
        run = _Run(self, iso, False, cam, options, rays, time_limit, rays_per_step, space)
        err, engine = new_error(), ctypes.c_void_p()
        check(lib.ip_engine_create(cache, ctypes.byref(options), ctypes.byref(engine),
                                   ctypes.byref(err)), err)
        run.engine = engine
        self._runs.add(run)
        try:  # the view's set-up counts in its time, as in isorender
            start = lib.ip_now_seconds()
            st = lib.ip_engine_begin(engine, ctypes.byref(cam), run.iso_stored,
                                     ctypes.byref(err))
            run.wall_seconds = lib.ip_now_seconds() - start
            check(st, err)
        except BaseException:
            self._end(run)
            raise
        return run

    def _end(self, run):
        run.destroy()
        self._runs.discard(run)

    def _advance(self, run):
        """One step of the engine as isorender takes it: returns (first new triangle, how many,
        counts of the step), or None once every pixel has had its ray, the rays are cast or
        the time is up. Under the lock."""
        if not run.engine:
            raise ValueError("%s: the file was closed during the extraction" % self.path)
        if lib.ip_engine_done(run.engine):
            return None
        err, counts, total = new_error(), S.EngineCounts(), S.EngineCounts()
        lib.ip_engine_totals(run.engine, ctypes.byref(total))
        if total.rays >= run.limit:
            return None
        left = run.time_limit - run.wall_seconds if run.time_limit is not None else 0.0
        if run.time_limit is not None and left <= 0:
            return None
        if run.rays_per_step is None:
            batch = min(run.target, run.limit) - total.rays
        else:
            batch = min(run.rays_per_step, run.limit - total.rays)
        first = lib.ip_engine_mesh(run.engine).contents.triangle_count
        start = lib.ip_now_seconds()
        st = lib.ip_engine_step(run.engine, batch, left, ctypes.byref(counts), ctypes.byref(err))
        run.wall_seconds += lib.ip_now_seconds() - start
        check(st, err)
        now = lib.ip_engine_mesh(run.engine).contents.triangle_count
        run.target *= 2
        return first, now - first, counts

    def _step(self, run, first, count, counts):
        vertices, normals = copy_in_space(lib.ip_engine_mesh(run.engine).contents, first, count,
                                          run.orientation)
        return Step(vertices, normals, self._stats(run), first, counts_dict(counts), run.space)

    def _stats(self, run, counts=None):
        if counts is None:
            counts = S.EngineCounts()
            lib.ip_engine_totals(run.engine, ctypes.byref(counts))
        return run_stats(run, counts, self._cache)

    def _extract_full(self, iso, full, a, space, cap=False):
        cam = self._camera(a)
        options = a.engine_options()
        cache = self._cache_for(a.cache_mb)
        run = _Run(self, iso, full, cam, options, space=space)
        mesh, counts, err = S.Mesh(), S.EngineCounts(), new_error()
        lib.ip_mesh_init(ctypes.byref(mesh))
        try:
            start = lib.ip_now_seconds()
            if full == "lod":
                st = lib.ip_extract_full_lod(cache, run.iso_stored, ctypes.byref(cam),
                                             options.pixel_error,
                                             a.threads, None, 0, ctypes.byref(mesh),
                                             ctypes.byref(counts), ctypes.byref(err))
            else:
                st = lib.ip_extract_full(cache, run.iso_stored, 0, a.threads, ctypes.byref(mesh),
                                         ctypes.byref(counts), ctypes.byref(err))
                if st == 0 and cap:
                    st = lib.ip_extract_cap(cache, run.iso_stored, 0, ctypes.byref(mesh),
                                            ctypes.byref(err))
            run.wall_seconds = lib.ip_now_seconds() - start
            check(st, err)
            vertices, normals = copy_in_space(mesh, 0, mesh.triangle_count, run.orientation)
        finally:
            lib.ip_mesh_free(ctypes.byref(mesh))
        return Mesh(vertices, normals, self._stats(run, counts), run.space)

    def _full_welded(self, iso_stored, threads, keep_degenerate):
        """marching_cubes()'s route: every active cell at full resolution (isorender --full) of
        the stored isovalue `iso_stored`, in grid space (sample index x spacing), welded by the
        library as it extracts (ip_extract_full_indexed()), so that no soup is made. Returns a
        Welded whose points and normals are z, y, x (an array's axis order) and its values
        (float32, per vertex: the larger sample at the ends of its edge), or None when there is
        no surface."""
        a = _Args(threads=threads)
        with _Call(self):
            cache = self._cache_for(a.cache_mb)
            out, counts, err = S.IndexedMesh(), S.EngineCounts(), new_error()
            values = ctypes.POINTER(ctypes.c_float)()
            try:
                check(lib.ip_extract_full_indexed(cache, float(iso_stored), 0, a.threads,
                                                  int(bool(keep_degenerate)), ctypes.byref(out),
                                                  ctypes.byref(values), ctypes.byref(counts),
                                                  ctypes.byref(err)), err)
                if not out.triangle_count:
                    return None
                welded = indexed_arrays(out, reverse=True, take=True)
                mine = take_c(values, np.float32, out.vertex_count)
                values = None  # the array owns it now
                return welded, mine
            finally:
                lib.ip_indexed_mesh_free(ctypes.byref(out))
                if values:
                    free_c(values)


def open(path: PathLike) -> File:  # noqa: A001 (isoprop.open, as the module's API names it)
    """Opens the brick file at `path` (verifying its header and summaries) and returns a
    File. Raises isoprop.Error naming the file when it is missing, not a brick file or
    corrupt; TypeError or isoprop.ArgumentError for a `path` that is no path."""
    return File(path)

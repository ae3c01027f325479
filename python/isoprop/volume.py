"""isoprop.open(): a brick file, and extraction from it, full or progressive."""
import ctypes
import os
import warnings
from collections import namedtuple

import numpy as np

from . import _structs as S
from ._library import lib
from .bricking import DTYPES
from .errors import check, new_error
from .mesh import Mesh, Step, copy_triangles
from .stats import counts_dict, run_stats

Level = namedtuple("Level", "level dims bricks value_range")
Level.__doc__ = """One level of the pyramid: level k samples the volume at every 2^k-th sample;
dims and bricks along x, y, z; value_range (min, max) of its samples."""

DEFAULT_SIZE = (1600, 1200)  # isorender's
VIEW_FOV = 30.0  # degrees: the field of view of the named views (isorender --view)


def _engine_options(threads, cutoff, foldback, lod, pixel_error, occlusion, prefetch,
                    cull=False):
    o = S.EngineOptions()
    lib.ip_engine_options_default(ctypes.byref(o))
    if cutoff is not None:
        o.cutoff_degrees = cutoff
    if foldback is not None:
        o.foldback_degrees = foldback
    o.threads, o.lod, o.pixel_error = threads, int(bool(lod)), pixel_error
    o.occlusion = int(bool(occlusion))
    # prefetch: True (on) or False (off), or "always" (isorender --prefetch always)
    if isinstance(prefetch, str) and prefetch != "always":
        raise ValueError('prefetch: True, False or "always", not %r' % prefetch)
    o.prefetch = (S.PREFETCH_ALWAYS if prefetch == "always"
                  else S.PREFETCH_ON if prefetch else S.PREFETCH_OFF)
    o.cull = int(bool(cull))
    return o


def _camera_from(camera, size):
    """An ip_camera from "ex,ey,ez,tx,ty,tz,ux,uy,uz,fov" (isorender --camera) or a dict with
    eye, target, up (world units) and fov (degrees, default 30)."""
    c, err = S.Camera(), new_error()
    c.width, c.height = size
    if isinstance(camera, str):
        check(lib.ip_camera_parse(camera.encode(), ctypes.byref(c), ctypes.byref(err)), err)
    else:
        c.eye[:], c.target[:], c.up[:] = (
            [float(v) for v in camera[k]] for k in ("eye", "target", "up"))
        c.fov_y = float(camera.get("fov", VIEW_FOV))
    check(lib.ip_camera_check(ctypes.byref(c), ctypes.byref(err)), err)
    return c


class _Run:
    """One extraction's engine and figures; its engine (if any) is freed by destroy()."""

    def __init__(self, f, iso, full, camera, options):
        self.path, self.summary_bytes = f.path, f._summary_bytes
        self.iso, self.full, self.camera, self.options = iso, full, camera, options
        self.engine, self.wall_seconds, self.warnings = None, 0.0, []
        lo, hi = f.value_range
        v = float(np.float32(iso))  # the isovalue as the engine takes it
        if not (lo < v <= hi):
            text = ("iso %g is outside the value range of %s, %g .. %g: there is no surface (an "
                    "isovalue must be above the minimum and at most the maximum)"
                    % (iso, f.path, lo, hi))
            self.warnings.append(text)
            warnings.warn(text, RuntimeWarning, stacklevel=4)

    def done(self):
        return bool(self.full) or bool(self.engine and lib.ip_engine_done(self.engine))

    def destroy(self):
        if self.engine:
            lib.ip_engine_destroy(self.engine)
            self.engine = None


class File:
    """An open brick file (isoprop.open()). Attributes: path, dims (x, y, z samples), shape
    (z, y, x, as a numpy array of the volume), dtype (numpy), spacing (x, y, z world units),
    value_range (min, max), levels (a tuple of Level, level 0 first), brick_size,
    subblock_size, file_bytes. One thread at a time may use it; close() (or a with block)
    frees it, and so does garbage collection."""

    def __init__(self, path):
        self._store, self._cache, self._cache_budget, self._runs = None, None, 0, set()
        err, store = new_error(), ctypes.c_void_p()
        check(lib.ip_store_open(os.fsencode(path), ctypes.byref(store), ctypes.byref(err)), err)
        self._store = store
        l = lib.ip_store_layout(store).contents
        self.path = lib.ip_store_path(store).decode()
        self.dims = tuple(l.dims)
        self.shape = self.dims[::-1]
        self.dtype = np.dtype(DTYPES[l.type])
        self.spacing = tuple(l.spacing)
        self.value_range = (l.value_min, l.value_max)
        self.levels = tuple(
            Level(k, tuple(lv.dims), tuple(lv.bricks), (lv.value_min, lv.value_max))
            for k, lv in ((k, l.levels[k]) for k in range(l.level_count)))
        self.brick_size, self.subblock_size = l.brick_edge, l.subblock_edge
        self.file_bytes = l.file_size
        self._summary_bytes = lib.ip_store_summary_memory(store)
        lo, hi = (ctypes.c_double * 3)(), (ctypes.c_double * 3)()
        lib.ip_layout_world_box(ctypes.byref(l), lo, hi)
        self.world_box = (tuple(lo), tuple(hi))

    # -- life time ------------------------------------------------------------------------
    def close(self):
        """Frees the engines of unfinished extract_steps() runs, the cache and the store."""
        for run in list(self._runs):
            run.destroy()
        self._runs.clear()
        if self._cache:
            lib.ip_cache_destroy(self._cache)
            self._cache = None
        if self._store:
            lib.ip_store_close(self._store)
            self._store = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        if getattr(self, "_store", None) is not None and lib is not None:
            self.close()

    def __repr__(self):
        return "<isoprop.File %s %s %s>" % (self.path, "x".join(map(str, self.dims)),
                                            self.dtype.name)

    def _open_store(self):
        if not self._store:
            raise ValueError("%s: the file is closed" % self.path)
        return self._store

    def _cache_for(self, cache_mb):
        """The brick cache, kept from one extraction to the next (warm); `cache_mb` other than
        the current budget makes a new one (None: keep it, or the default budget)."""
        store = self._open_store()
        budget = lib.ip_cache_default_budget() if cache_mb is None else int(cache_mb) << 20
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

    def camera(self, view="-y", camera=None, size=DEFAULT_SIZE):
        """The camera an extraction uses, as a dict (eye, target, up, fov, width, height)."""
        c = self._camera(view, camera, size)
        return {"eye": tuple(c.eye), "target": tuple(c.target), "up": tuple(c.up),
                "fov": c.fov_y, "width": c.width, "height": c.height}

    def _camera(self, view, camera, size):
        self._open_store()
        w, h = (int(v) for v in size)
        if camera is not None:
            return _camera_from(camera, (w, h))
        c, err = S.Camera(), new_error()
        lo, hi = ((ctypes.c_double * 3)(*b) for b in self.world_box)
        check(lib.ip_camera_fit_axis(lo, hi, view.encode(), VIEW_FOV, w, h, ctypes.byref(c),
                                     ctypes.byref(err)), err)
        return c

    # -- extraction -----------------------------------------------------------------------
    def extract(self, iso, *, view="-y", camera=None, size=DEFAULT_SIZE, rays=None, full=False,
                time_limit=None, threads=0, cutoff=None, foldback=None, lod=True,
                pixel_error=1.0, occlusion=True, prefetch=True, cull=False, cache_mb=None,
                on_step=None):
        """Extracts the isosurface `iso` and returns a Mesh (vertices, normals, faces, stats).

        Progressive (the default), as isorender: rays in the paper's order for the image of
        `size` (width, height) pixels seen from `view` (+x -x +y -y +z -z: the side the eye is
        on) or `camera` (a dict eye/target/up/fov or isorender's --camera text), until every
        pixel has had its ray, `rays` rays or `time_limit` seconds. full=True triangulates
        every active cell instead (isorender --full; the view does not matter); full="lod"
        every active cell at the view's adaptive resolution, each level's cells within its
        distance band (isorender --full-lod: what the progressive mesh with lod on draws once
        every pixel has had its ray; needs lod on). threads (0:
        every core), cutoff and foldback (degrees), lod, pixel_error, occlusion, prefetch (True,
        False or "always") and cull are isorender's options (cull off by default here: the mesh
        is the product, not an image of it); cache_mb the brick cache's budget (the cache stays warm
        between calls). on_step(step), if given, sees each step (as extract_steps() yields).
        Raises isoprop.Error for a file that cannot be read."""
        kw = dict(view=view, camera=camera, size=size, threads=threads, cutoff=cutoff,
                  foldback=foldback, lod=lod, pixel_error=pixel_error, occlusion=occlusion,
                  prefetch=prefetch, cull=cull, cache_mb=cache_mb)
        if full not in (False, True, "lod"):
            raise ValueError('full: False, True or "lod", not %r' % (full,))
        if full:
            if rays is not None or time_limit is not None or on_step is not None:
                raise ValueError("full=True extracts everything: no rays, time_limit or on_step")
            if full == "lod" and not lod:
                raise ValueError('full="lod" is the full extraction at adaptive resolution: '
                                 "not with lod=False (full=True is that)")
            return self._extract_full(iso, full, **kw)
        run = self._begin(iso, **kw)
        try:
            for first, count, counts in self._steps(run, rays, time_limit, None):
                if on_step is not None:
                    on_step(self._step(run, first, count, counts))
            mesh = lib.ip_engine_mesh(run.engine).contents
            vertices, normals = copy_triangles(mesh, 0, mesh.triangle_count)
            return Mesh(vertices, normals, self._stats(run))
        finally:
            self._end(run)

    def extract_steps(self, iso, *, rays_per_step=None, rays=None, time_limit=None, **kw):
        """Progressive extraction as a generator: yields a Step (the step's new triangles, its
        counts, the run's statistics so far) after each step of the engine, until every pixel
        has had its ray, `rays` rays or `time_limit` seconds. Steps cast `rays_per_step` rays
        each (None: 1, 2, 4, ... as isorender does, so that the first images come at once).
        Other keywords as extract(). Closing the generator (or leaving its loop) frees the
        engine; the triangles of all steps, in order, are those of one extract() of the same
        rays on one thread."""
        if rays_per_step is not None and rays_per_step < 1:
            raise ValueError("rays_per_step %r: must be at least 1" % (rays_per_step,))
        run = self._begin(iso, **kw)
        try:
            for first, count, counts in self._steps(run, rays, time_limit, rays_per_step):
                yield self._step(run, first, count, counts)
        finally:
            self._end(run)

    def _begin(self, iso, view="-y", camera=None, size=DEFAULT_SIZE, threads=0, cutoff=None,
               foldback=None, lod=True, pixel_error=1.0, occlusion=True, prefetch=True,
               cull=False, cache_mb=None):
        cam = self._camera(view, camera, size)
        options = _engine_options(threads, cutoff, foldback, lod, pixel_error, occlusion,
                                  prefetch, cull)
        cache = self._cache_for(cache_mb)
        run = _Run(self, iso, False, cam, options)
        err, engine = new_error(), ctypes.c_void_p()
        check(lib.ip_engine_create(cache, ctypes.byref(options), ctypes.byref(engine),
                                   ctypes.byref(err)), err)
        run.engine = engine
        self._runs.add(run)
        try:  # the view's set-up counts in its time, as in isorender
            start = lib.ip_now_seconds()
            st = lib.ip_engine_begin(engine, ctypes.byref(cam), float(iso), ctypes.byref(err))
            run.wall_seconds = lib.ip_now_seconds() - start
            check(st, err)
        except BaseException:
            self._end(run)
            raise
        return run

    def _end(self, run):
        run.destroy()
        self._runs.discard(run)

    def _steps(self, run, rays, time_limit, rays_per_step):
        """Steps the engine as isorender does; yields (first new triangle, how many, counts of
        the step) after each."""
        limit = rays if rays is not None else 2 ** 64 - 1
        target, err, counts, total = 1, new_error(), S.EngineCounts(), S.EngineCounts()
        while run.engine and not lib.ip_engine_done(run.engine):
            lib.ip_engine_totals(run.engine, ctypes.byref(total))
            if total.rays >= limit:
                break
            left = time_limit - run.wall_seconds if time_limit is not None else 0.0
            if time_limit is not None and left <= 0:
                break
            if rays_per_step is None:
                batch = min(target, limit) - total.rays
            else:
                batch = min(rays_per_step, limit - total.rays)
            first = lib.ip_engine_mesh(run.engine).contents.triangle_count
            start = lib.ip_now_seconds()
            st = lib.ip_engine_step(run.engine, batch, left, ctypes.byref(counts),
                                    ctypes.byref(err))
            run.wall_seconds += lib.ip_now_seconds() - start
            check(st, err)
            now = lib.ip_engine_mesh(run.engine).contents.triangle_count
            yield first, now - first, counts
            target *= 2
        if not run.engine:
            raise ValueError("%s: the file was closed during the extraction" % self.path)

    def _step(self, run, first, count, counts):
        vertices, normals = copy_triangles(lib.ip_engine_mesh(run.engine).contents, first, count)
        return Step(vertices, normals, self._stats(run), first, counts_dict(counts))

    def _stats(self, run, counts=None):
        if counts is None:
            counts = S.EngineCounts()
            lib.ip_engine_totals(run.engine, ctypes.byref(counts))
        return run_stats(run, counts, self._cache)

    def _extract_full(self, iso, full, view, camera, size, threads, cache_mb, **engine_kw):
        cam = self._camera(view, camera, size)
        options = _engine_options(threads, **engine_kw)
        cache = self._cache_for(cache_mb)
        run = _Run(self, iso, full, cam, options)
        mesh, counts, err = S.Mesh(), S.EngineCounts(), new_error()
        lib.ip_mesh_init(ctypes.byref(mesh))
        try:
            start = lib.ip_now_seconds()
            if full == "lod":
                st = lib.ip_extract_full_lod(cache, float(iso), ctypes.byref(cam),
                                             options.pixel_error, threads, None, 0,
                                             ctypes.byref(mesh), ctypes.byref(counts),
                                             ctypes.byref(err))
            else:
                st = lib.ip_extract_full(cache, float(iso), 0, threads, ctypes.byref(mesh),
                                         ctypes.byref(counts), ctypes.byref(err))
            run.wall_seconds = lib.ip_now_seconds() - start
            check(st, err)
            vertices, normals = copy_triangles(mesh, 0, mesh.triangle_count)
        finally:
            lib.ip_mesh_free(ctypes.byref(mesh))
        return Mesh(vertices, normals, self._stats(run, counts))


def open(path):  # noqa: A001 (isoprop.open, as the module's API names it)
    """Opens the brick file at `path` (verifying its header and summaries) and returns a
    File. Raises isoprop.Error naming the file when it is missing, not a brick file or
    corrupt."""
    return File(path)

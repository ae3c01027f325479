# SPDX-License-Identifier: BSD-3-Clause
"""Every argument of every public function is checked before any work: a bad one raises
TypeError (wrong type) or isoprop.ArgumentError (out of range: a ValueError and an
isoprop.Error) whose message starts with the argument's name; nothing is written, no cache is
made. Values at the limits are accepted. The limits are the programs' (isorender, isobrick)."""
import math
import os
import unittest

import support  # first: it skips (status 77) when numpy is absent
import numpy as np
import isoprop

ISO = 1000.5
SIZE = (32, 24)
NAN, INF = float("nan"), float("inf")
V = TypeError   # shorthands for the table
R = isoprop.ArgumentError
CAMERA = {"eye": (24, -80, 30), "target": (24, 20, 26), "up": (0, 0, 1)}

# (keywords of File.extract(), the exception, the name its message starts with)
EXTRACT = [
    # the cases
    (dict(size=(2 ** 32 + 64, 48)), R, "size: width 4294967360 is not within 1 .. 16384"),
    (dict(size=(-5, -5)), R, "size: width -5"),
    (dict(size=(0, 10)), R, "size: width 0"),
    (dict(size=(10, 0)), R, "size: height 0"),
    (dict(size=(100000, 100000)), R, "size: width 100000"),
    (dict(size=(16385, 1)), R, "size: width"),
    (dict(size=(64,)), R, "size"),
    (dict(size=(64, 48, 1)), R, "size"),
    (dict(size=(64.0, 48)), V, "size: width"),
    (dict(size=(64, True)), V, "size: height"),
    (dict(size="64x48"), V, "size"),
    (dict(size=64), V, "size"),
    (dict(cache_mb=-1), R, "cache_mb"),
    (dict(cache_mb=0), R, "cache_mb"),
    (dict(cache_mb=2 ** 30 + 1), R, "cache_mb"),
    (dict(cache_mb=512.0), V, "cache_mb"),
    (dict(threads=-1), R, "threads"),
    (dict(threads=65), R, "threads"),
    (dict(threads=2 ** 32), R, "threads"),
    (dict(threads=1.5), V, "threads"),
    (dict(threads="4"), V, "threads"),
    (dict(rays=-1), R, "rays"),
    (dict(rays=2 ** 64), R, "rays"),
    (dict(rays=10.0), V, "rays"),
    (dict(time_limit=-1), R, "time_limit"),
    (dict(time_limit=0), R, "time_limit"),
    (dict(time_limit=NAN), R, "time_limit"),
    (dict(time_limit=INF), R, "time_limit"),
    (dict(time_limit="1"), V, "time_limit"),
    (dict(iso=NAN), R, "iso"),
    (dict(iso=INF), R, "iso"),
    (dict(iso=-INF), R, "iso"),
    (dict(iso=1e39), R, "iso"),  # no float32
    (dict(iso="600"), V, "iso"),
    (dict(iso=None), V, "iso"),
    (dict(iso=True), V, "iso"),
    (dict(iso=NAN, full=True), R, "iso"),
    (dict(iso=NAN, full="lod"), R, "iso"),
    (dict(view="+w"), R, "view"),
    (dict(view="x"), R, "view"),
    (dict(view="anterior"), R, "view"),  # the phantom names no anatomical space
    (dict(view=3), V, "view"),
    (dict(camera=5), V, "camera"),
    (dict(camera=["1,2"]), V, "camera"),
    (dict(camera="1,2,3"), R, "camera"),
    (dict(camera="24,-80,30,24,20,26,0,0,1,200"), R, "camera"),  # fov
    (dict(camera="24,-80,30,24,-80,30,0,0,1,30"), R, "camera"),  # eye = target
    (dict(camera=dict(CAMERA, eye=(1, 1))), R, "camera['eye']"),
    (dict(camera=dict(CAMERA, target=(1, NAN, 1))), R, "camera['target']"),
    (dict(camera=dict(CAMERA, up="z")), V, "camera['up']"),
    (dict(camera=dict(CAMERA, up=(0, 0, 0))), R, "camera"),
    (dict(camera=dict(CAMERA, up=(0, 25, -1))), R, "camera"),  # parallel to the view
    (dict(camera=dict(CAMERA, eye=(24, 20, 26))), R, "camera"),
    (dict(camera=dict(CAMERA, fov=0)), R, "camera['fov']"),
    (dict(camera=dict(CAMERA, fov=180)), R, "camera['fov']"),
    (dict(camera=dict(CAMERA, fov=NAN)), R, "camera['fov']"),
    (dict(camera=dict(CAMERA, fovy=30)), R, "camera"),
    (dict(camera={"eye": (1, 1, 1), "target": (0, 0, 0)}), R, "camera"),
    (dict(cutoff=0), R, "cutoff"),
    (dict(cutoff=-1), R, "cutoff"),
    (dict(cutoff=181), R, "cutoff"),
    (dict(cutoff=NAN), R, "cutoff"),
    (dict(cutoff="2"), V, "cutoff"),
    (dict(foldback=-0.1), R, "foldback"),
    (dict(foldback=181), R, "foldback"),
    (dict(foldback=INF), R, "foldback"),
    (dict(pixel_error=0), R, "pixel_error"),
    (dict(pixel_error=-1), R, "pixel_error"),
    (dict(pixel_error=NAN), R, "pixel_error"),
    (dict(pixel_error=None), V, "pixel_error"),
    (dict(lod="yes"), V, "lod"),
    (dict(lod=2), V, "lod"),
    (dict(lod=None), V, "lod"),
    (dict(occlusion="off"), V, "occlusion"),
    (dict(cull=0.5), V, "cull"),
    (dict(prefetch="off"), R, "prefetch"),
    (dict(prefetch=None), V, "prefetch"),
    (dict(full="yes"), R, "full"),
    (dict(full=None), V, "full"),
    (dict(full=2), V, "full"),
    (dict(full="lod", lod=False), R, "full"),
    (dict(full=True, rays=10), R, "rays"),
    (dict(full=True, time_limit=1.0), R, "time_limit"),
    (dict(full=True, on_step=print), R, "on_step"),
    (dict(on_step=3), V, "on_step"),
]

# (keywords of File.extract_steps() beyond extract()'s, the exception, the name)
STEPS = [
    (dict(rays_per_step=0), R, "rays_per_step"),
    (dict(rays_per_step=-1), R, "rays_per_step"),
    (dict(rays_per_step=2 ** 64), R, "rays_per_step"),
    (dict(rays_per_step=1.5), V, "rays_per_step"),
    (dict(rays=-1), R, "rays"),
    (dict(time_limit=NAN), R, "time_limit"),
    (dict(size=(0, 10)), R, "size"),
    (dict(iso=NAN), R, "iso"),
    (dict(threads=-1), R, "threads"),
]

# (keywords of isoprop.brick() with an array (a) or a file (f) as source, ...)
BRICK = [
    ("a", dict(hc=99), R, "hc: level 99 is not within 1 .. 12"),
    ("a", dict(hc=0), R, "hc"),
    ("a", dict(hc=-1), R, "hc"),
    ("a", dict(hc=2.5), V, "hc"),
    ("a", dict(hc="9"), V, "hc"),
    ("a", dict(mem_mb=-1), R, "mem_mb"),
    ("a", dict(mem_mb=2 ** 40 + 1), R, "mem_mb"),
    ("a", dict(mem_mb=1.5), V, "mem_mb"),
    ("a", dict(threads=-1), R, "threads"),
    ("a", dict(threads=257), R, "threads"),
    ("a", dict(threads=None), V, "threads"),
    ("a", dict(spacing=(1, 1)), R, "spacing"),
    ("a", dict(spacing=(1, 1, 1, 1)), R, "spacing"),
    ("a", dict(spacing=1.0), V, "spacing"),
    ("a", dict(spacing="1,1,1"), V, "spacing"),
    ("a", dict(spacing=(1, 1, 0)), R, "spacing"),
    ("a", dict(spacing=(1, -1, 1)), R, "spacing"),
    ("a", dict(spacing=(1, NAN, 1)), R, "spacing"),
    ("a", dict(spacing=(1e-12, 1, 1)), R, "spacing"),  # the library's bounds
    ("a", dict(spacing=(1, 1, 2000)), R, "spacing"),  # the library's ratio
    ("a", dict(brick_size=3), R, "brick_size"),
    ("a", dict(brick_size=1), R, "brick_size"),
    ("a", dict(brick_size=512), R, "brick_size"),
    ("a", dict(brick_size=32.0), V, "brick_size"),
    ("a", dict(subblock_size=0), R, "subblock_size"),
    ("a", dict(subblock_size=6), R, "subblock_size"),
    ("a", dict(brick_size=8, subblock_size=16), R, "subblock_size"),
    ("a", dict(force="no"), V, "force"),
    ("a", dict(force=None), V, "force"),
    ("a", dict(progress=1), V, "progress"),
    ("a", dict(dims=(8, 8, 8)), R, "dims"),
    ("a", dict(dtype="uint8"), R, "dtype"),
    ("a", dict(endian="little"), R, "endian"),
    ("f", dict(dims=(1, 8, 8)), R, "dims: x 1"),
    ("f", dict(dims=(8, 8, 2 ** 31)), R, "dims: z"),
    ("f", dict(dims=(8, 8)), R, "dims"),
    ("f", dict(dims=(8.0, 8, 8)), V, "dims"),
    ("f", dict(dims="8x8x8"), V, "dims"),
    ("f", dict(dtype="float64"), V, "dtype"),
    ("f", dict(dtype="nonsense"), V, "dtype"),
    ("f", dict(dtype=5), V, "dtype"),
    ("f", dict(endian="middle"), R, "endian"),
    ("f", dict(endian=1), V, "endian"),
    ("f", dict(hc=13), R, "hc"),
    ("f", dict(threads=-1), R, "threads"),
]

# (source, out, the exception, the name)
BRICK_PATHS = [
    (5, "x.ibv", V, "source"),
    (None, "x.ibv", V, "source"),
    ([[1, 2], [3]], "x.ibv", V, "source"),
    (np.zeros((4, 4, 4)), "x.ibv", V, "source"),  # float64
    (np.zeros((4, 4), np.uint8), "x.ibv", R, "source"),
    (np.zeros((4, 1, 4), np.uint8), "x.ibv", R, "source"),
    ("", "x.ibv", R, "source"),
    ("a\0b.raw", "x.ibv", R, "source"),
    ("RAW", 5, V, "out"),
    ("RAW", None, V, "out"),
    ("RAW", "", R, "out"),
    ("RAW", "x\0.ibv", R, "out"),
    (np.zeros((4, 4, 4), np.uint8), b"", R, "out"),
]


class Arguments(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.ibv = support.phantom((48, 40, 36), "uint16", "1,1,1.5")
        cls.raw = support.generate("shepp-logan", (16, 16, 16), "uint8")
        cls.array = np.fromfile(cls.raw, dtype=np.uint8).reshape(16, 16, 16)

    def assert_refused(self, call, exception, name):
        with self.assertRaises(exception) as caught:
            call()
        e = caught.exception
        self.assertTrue(str(e).startswith(name), "%r does not start with %r" % (str(e), name))
        if exception is R:  # an out-of-range value: a ValueError and an isoprop.Error
            self.assertIsInstance(e, ValueError)
            self.assertIsInstance(e, isoprop.Error)
            self.assertLess(e.status, 0)
        return e

    def test_extract(self):
        """Each bad keyword of extract(), progressive and full: refused before any work (no
        cache made, no run left)."""
        f = isoprop.open(self.ibv)
        try:
            for kw, exception, name in EXTRACT:
                kw = dict(kw)
                iso = kw.pop("iso", ISO)
                kw.setdefault("size", SIZE)
                for full in ((kw.pop("full"),) if "full" in kw else (False, True)):
                    with self.subTest(kw=kw, full=full):
                        self.assert_refused(lambda: f.extract(iso, full=full, **kw), exception,
                                            name)
            self.assertIsNone(f._cache, "a refused call made the cache")
            self.assertFalse(f._runs)
        finally:
            f.close()

    def test_extract_steps_and_camera(self):
        """extract_steps() checks when called, before its first step; camera() likewise."""
        with isoprop.open(self.ibv) as f:
            for kw, exception, name in STEPS:
                kw = dict(kw)
                iso = kw.pop("iso", ISO)
                with self.subTest(kw=kw):
                    self.assert_refused(lambda: f.extract_steps(iso, **kw), exception, name)
            with self.assertRaises(TypeError):  # extract()'s, but not a progressive run's
                f.extract_steps(ISO, full=True)
            for kw, exception, name in EXTRACT:
                if set(kw) <= {"view", "camera", "size"}:
                    with self.subTest(camera=kw):
                        self.assert_refused(lambda: f.camera(**kw), exception, name)
            self.assertIsNone(f._cache)

    def test_brick(self):
        """Each bad keyword of brick(), from an array and from a file: nothing is written."""
        before = sorted(os.listdir(support.WORK))
        out = support.work("refused.ibv")
        for source, kw, exception, name in BRICK:
            src = self.array if source == "a" else self.raw
            with self.subTest(source=source, kw=kw):
                self.assert_refused(lambda: isoprop.brick(src, out, **kw), exception, name)
        for source, target, exception, name in BRICK_PATHS:
            src = self.raw if isinstance(source, str) and source == "RAW" else source
            dst = support.work(target) if isinstance(target, str) and target else target
            with self.subTest(source=source, out=target):
                self.assert_refused(lambda: isoprop.brick(src, dst), exception, name)
        self.assertEqual(sorted(os.listdir(support.WORK)), before, "a refused brick() wrote")

    def test_whole_messages(self):
        """The messages in full, for the values that once misled (a camera message for a zero
        size, "out of memory" for a huge one, a ctypes message for a short spacing, an empty
        mesh for a NaN isovalue, a scratch file's name for a missing output folder)."""
        with isoprop.open(self.ibv) as f:
            for size, text in (((0, 10), "size: width 0 is not within 1 .. 16384 pixels"),
                               ((100000, 100000), "size: width 100000 is not within 1 .. 16384 "
                                                  "pixels")):
                with self.assertRaises(isoprop.ArgumentError) as caught:
                    f.extract(ISO, size=size)
                self.assertEqual(str(caught.exception),
                                 text + " (16384: the largest image side the engine renders)")
            with self.assertRaises(isoprop.ArgumentError) as caught:
                f.extract(NAN)
            self.assertEqual(str(caught.exception), "iso: nan is not finite")
        with self.assertRaises(isoprop.ArgumentError) as caught:
            isoprop.brick(self.array, support.work("x.ibv"), spacing=(1, 1))
        self.assertEqual(str(caught.exception),
                         "spacing: 2 values given, 3 needed (x, y, z: positive finite numbers)")
        with self.assertRaises(FileNotFoundError) as caught:
            isoprop.brick(self.array, support.work("nodir/x.ibv"))
        self.assertEqual(caught.exception.strerror, "out: the output's folder %s does not exist"
                         % support.work("nodir"))

    def test_open(self):
        for path, exception, name in ((5, V, "path"), (None, V, "path"), ("", R, "path"),
                                      ("a\0b.ibv", R, "path"), (b"", R, "path")):
            with self.subTest(path=path):
                self.assert_refused(lambda: isoprop.open(path), exception, name)

    def test_accepted_at_the_limits(self):
        """Values at the limits, numpy numbers and 0/1 for flags pass as before."""
        with isoprop.open(self.ibv) as f:
            for kw in (dict(size=(1, 1)), dict(size=(16384, 1), rays=100),
                       dict(size=(np.int64(32), np.uint16(24))), dict(size=np.array([32, 24])),
                       dict(threads=64, rays=64), dict(threads=np.int32(1)), dict(rays=0),
                       dict(cache_mb=1), dict(cache_mb=np.int64(64)), dict(time_limit=1e-9),
                       dict(cutoff=180, foldback=0), dict(cutoff=1e-3, foldback=180),
                       dict(pixel_error=1e-6, rays=64),
                       dict(lod=0, occlusion=1, cull=np.bool_(True)),
                       dict(prefetch=0), dict(prefetch="always"),
                       dict(camera=dict(CAMERA, fov=179.5, width=1, height=2)),
                       dict(camera="24,-80,30,24,20,26,0,0,1,35", view=None)):
                with self.subTest(kw=kw):
                    mesh = f.extract(np.float32(ISO), **dict({"size": SIZE}, **kw))
                    self.assertIsInstance(mesh, isoprop.Mesh)
            self.assertEqual(f.extract(ISO, size=SIZE, rays=0).stats["rays"], 0)
            self.assertEqual(len(f.extract(1000, full=1, threads=0)),
                             len(f.extract(1000.0, full=True)))
            self.assertEqual(f.camera(size=(16384, 16384))["width"], 16384)
            self.assertTrue(math.isfinite(f.extract(ISO, size=SIZE, rays=8).stats["iso"]))
            steps = list(f.extract_steps(ISO, size=(4, 4), rays_per_step=2 ** 64 - 1))
            self.assertEqual(len(steps), 1)
        for kw in (dict(hc=1), dict(hc=12), dict(hc=True), dict(hc=False), dict(hc=np.int8(3)),
                   dict(mem_mb=0, threads=256), dict(brick_size=2, subblock_size=1),
                   dict(brick_size=256, subblock_size=256), dict(spacing=(1e-3, 1e-3, 1)),
                   dict(spacing=np.array([0.5, 1.0, 2.0])), dict(force=1)):
            with self.subTest(kw=kw):
                report = isoprop.brick(self.array, support.work("limits.ibv"),
                                       **dict({"force": True}, **kw))
                self.assertGreater(report["file_bytes"], 0)
        isoprop.brick(self.raw, support.work("limits.ibv"), dims=(16, 16, 16), dtype="uint8",
                      endian="big", force=True)


if __name__ == "__main__":
    support.main()

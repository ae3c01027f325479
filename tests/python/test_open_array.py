# SPDX-License-Identifier: BSD-3-Clause
"""isoprop.open_array(): a numpy array extracted without a brick file gives the triangles of
the brick file of the same array (full and progressive), a strided view those of its
contiguous copy; the File holds the array until it is closed; bad input is refused naming
the argument."""
import gc
import unittest
import weakref

import support  # first: it skips (status 77) when numpy is absent
import numpy as np
import isoprop


def volume(shape=(30, 34, 38), dtype=np.uint16):
    """A smooth test volume (z, y, x): a ball with ripples, over most of dtype's range."""
    z, y, x = np.meshgrid(*(np.linspace(-1, 1, n) for n in shape), indexing="ij")
    v = 1 - np.sqrt(x * x + 1.3 * y * y + 0.8 * z * z) + 0.05 * np.sin(9 * x) * np.cos(7 * z)
    v = np.clip(v, 0, 1)
    if np.dtype(dtype).kind == "f":
        return v.astype(dtype)
    return (v * np.iinfo(dtype).max * 0.9).astype(dtype)


def sorted_triangles(mesh):
    """The mesh's triangles as rows of 9 floats, sorted: a set, whatever their order."""
    t = np.asarray(mesh.vertices, dtype=np.float32).reshape(-1, 9)
    return t[np.lexsort(t.T[::-1])]


class OpenArray(unittest.TestCase):
    def test_same_as_brick_file(self):
        for dtype, iso in ((np.uint16, 20000.5), (np.float32, 0.35), (np.uint8, 100.5),
                           (np.int16, 9000.5)):
            a = volume(dtype=dtype)
            ibv = support.work("same_%s.ibv" % np.dtype(dtype).name)
            isoprop.brick(a, ibv, spacing=(1, 1.5, 2), force=True)
            with isoprop.open(ibv) as f, isoprop.open_array(a, (1, 1.5, 2)) as g:
                self.assertEqual(g.path, "array")
                self.assertEqual((g.dims, g.shape, g.dtype), (f.dims, f.shape, f.dtype))
                self.assertEqual(g.levels, f.levels)
                self.assertEqual(g.value_range, f.value_range)
                self.assertEqual(g.world_box, f.world_box)
                mf, mg = f.extract(iso, full=True), g.extract(iso, full=True)
                self.assertGreater(mf.triangle_count, 100)
                self.assertEqual(mg.triangle_count, mf.triangle_count)
                np.testing.assert_array_equal(sorted_triangles(mg), sorted_triangles(mf))
                # a progressive view, one thread: the same triangles in the same order
                pf = f.extract(iso, view="-y", size=(96, 72), threads=1)
                pg = g.extract(iso, view="-y", size=(96, 72), threads=1)
                self.assertGreater(pg.triangle_count, 0)
                np.testing.assert_array_equal(pg.vertices, pf.vertices)
                steps = list(g.extract_steps(iso, view="+x", size=(64, 48), rays_per_step=512))
                self.assertTrue(steps[-1].done)

    def test_strided_view(self):
        big = volume((40, 44, 60), np.int16)
        view = big[3:35:1, ::-1, 4:56:2]  # y backwards, every other x: no copy
        self.assertFalse(view.flags.c_contiguous)
        flat = np.ascontiguousarray(view)
        with isoprop.open_array(view) as g, isoprop.open_array(flat) as h:
            mg, mh = g.extract(9000.5, full=True), h.extract(9000.5, full=True)
            self.assertGreater(mh.triangle_count, 100)
            np.testing.assert_array_equal(mg.vertices, mh.vertices)
        # broadcast along z (stride 0), and one value broadcast everywhere (all strides 0)
        with isoprop.open_array(np.broadcast_to(flat[5], flat.shape)) as b:
            self.assertEqual(b.value_range, (float(flat[5].min()), float(flat[5].max())))
        with isoprop.open_array(np.broadcast_to(np.int16(7), (5, 6, 7))) as b:
            self.assertEqual(b.value_range, (7.0, 7.0))
        swapped = flat.astype(flat.dtype.newbyteorder(">"))  # copied once into host order
        with isoprop.open_array(swapped) as s:
            np.testing.assert_array_equal(s.extract(9000.5, full=True).vertices, mh.vertices)

    def test_origin_rescale_name(self):
        a = volume(dtype=np.int16)
        with isoprop.open_array(a, (0.5, 0.5, 1), origin=(10, 20, 30), rescale=(1, -1024, "HU"),
                                name="ct") as g:
            self.assertEqual(g.path, "ct")
            self.assertEqual(g.origin, (10.0, 20.0, 30.0))
            self.assertEqual(g.rescale, isoprop.Rescale(1.0, -1024.0, "HU"))
            self.assertEqual(g.value_range[0], g.value_range_stored[0] - 1024)
            m = g.extract(9000.5 - 1024, full=True)
            self.assertGreater(m.triangle_count, 100)
            self.assertGreaterEqual(m.vertices[:, 0].min(), 10.0)

    def test_array_outlives_store(self):
        a = volume(dtype=np.float32)
        ref = weakref.ref(a)
        g = isoprop.open_array(a)
        del a
        gc.collect()
        self.assertIsNotNone(ref(), "the File must hold the array while open")
        self.assertGreater(g.extract(0.35, full=True).triangle_count, 100)
        g.close()
        gc.collect()
        self.assertIsNone(ref(), "closed, the File must let the array go")

    def test_refused(self):
        good = volume((4, 4, 4), np.float32)
        for bad, error, text in (
                ([[[1, 2], [3, 4]]] * 2, TypeError, "volume: must be a numpy array"),
                (good.astype(np.float64), TypeError, "volume: an array of dtype float64"),
                (good[0], isoprop.ArgumentError, "volume: an array of shape (4, 4)"),
                (good[:1], isoprop.ArgumentError, "each dimension must be within 2")):
            with self.assertRaises(error) as c:
                isoprop.open_array(bad)
            self.assertIn(text, str(c.exception))
        with self.assertRaises(isoprop.ArgumentError) as c:
            isoprop.open_array(good, (1, 0, 1))
        self.assertIn("spacing: y 0.0 is not positive", str(c.exception))
        with self.assertRaises(TypeError) as c:
            isoprop.open_array(good, name=3)
        self.assertIn("name:", str(c.exception))
        nan = good.copy()
        nan[2, 1, 3] = np.nan
        with self.assertRaises(isoprop.Error) as c:
            isoprop.open_array(nan, name="scan")
        self.assertIn("scan: float32 sample at (x,y,z) = (3,1,2) is NaN", str(c.exception))


if __name__ == "__main__":
    support.main()

# SPDX-License-Identifier: BSD-3-Clause
"""isoprop.brick(): from a numpy array (z, y, x) the same brick file as from the raw file of the
same samples; every sample type; overrides for a plain raw file; errors leave no output and no
scratch file; progress and cancelling."""
import os
import unittest

import support  # first: it skips (status 77) when numpy is absent
import numpy as np
import isoprop


DIMS = (23, 18, 13)  # x, y, z: all different, so that a transposed axis shows


listing = support.listing


class Brick(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.raw, cls.array = support.generated_uint16("shepp-logan", DIMS)

    def brick_both(self, name, **kw):
        """Bricks the raw file and the array with the same options; returns both paths."""
        from_file, from_array = support.work(name + "-file.ibv"), support.work(name + "-array.ibv")
        isoprop.brick(self.raw, from_file, force=True, **kw)
        report = isoprop.brick(self.array, from_array, force=True, **kw)
        self.assertEqual(report["input_bytes"], self.array.nbytes)
        self.assertEqual(report["file_bytes"], os.path.getsize(from_array))
        return from_file, from_array

    def test_array_equals_raw_file(self):
        a, b = self.brick_both("same", brick_size=8, spacing=(0.5, 1.0, 2.0))
        with open(a, "rb") as fa, open(b, "rb") as fb:
            self.assertEqual(fa.read(), fb.read(), "the two brick files differ")
        with isoprop.open(a) as f, isoprop.open(b) as g:
            self.assertEqual(f.dims, DIMS)
            self.assertEqual(g.shape, self.array.shape)
            self.assertEqual(g.spacing, (0.5, 1.0, 2.0))
            self.assertEqual(g.value_range, (self.array.min(), self.array.max()))
            mf, mg = f.extract(1000.5, full=True), g.extract(1000.5, full=True)
            self.assertGreater(len(mf), 0)
            np.testing.assert_array_equal(mf.vertices, mg.vertices)
            np.testing.assert_array_equal(mf.normals, mg.normals)

    def test_views_and_byte_orders(self):
        """A big-endian or non-contiguous array gives the same samples."""
        ref = support.work("ref.ibv")
        isoprop.brick(self.array, ref, brick_size=8)
        big = support.work("big.ibv")
        isoprop.brick(self.array.astype(">u2"), big, brick_size=8)
        strided = support.work("strided.ibv")
        isoprop.brick(np.asfortranarray(self.array), strided, brick_size=8)
        for other in (big, strided):
            with open(ref, "rb") as fa, open(other, "rb") as fb:
                self.assertEqual(fa.read(), fb.read(), other)

    def test_every_sample_type(self):
        rng = np.random.default_rng(1)
        for dtype in (np.uint8, np.uint16, np.int16, np.float32):
            a = (rng.random((9, 11, 10)) * 100 - (50 if dtype in (np.int16, np.float32) else 0))
            a = a.astype(dtype)
            out = support.work("type-%s.ibv" % np.dtype(dtype).name)
            isoprop.brick(a, out, brick_size=4, subblock_size=4)
            with isoprop.open(out) as f:
                self.assertEqual(f.dtype, np.dtype(dtype))
                self.assertEqual(f.dims, (10, 11, 9))
                self.assertEqual(f.value_range, (float(a.min()), float(a.max())))

    def test_plain_raw_with_overrides(self):
        plain = support.work("samples.bin")
        self.array.astype(">u2").tofile(plain)
        out = support.work("plain.ibv")
        isoprop.brick(plain, out, dims=DIMS, dtype="uint16", endian="big", brick_size=8)
        ref = support.work("plain-ref.ibv")
        isoprop.brick(self.raw, ref, brick_size=8)
        with open(out, "rb") as fa, open(ref, "rb") as fb:
            self.assertEqual(fa.read(), fb.read())
        with self.assertRaises(isoprop.Error) as caught:  # no dims: the name does not say them
            isoprop.brick(plain, support.work("plain2.ibv"))
        self.assertIn(plain, str(caught.exception))

    def test_bad_arrays(self):
        before = listing()
        with self.assertRaises(TypeError):
            isoprop.brick(np.zeros((4, 4, 4)), support.work("f64.ibv"))  # float64
        with self.assertRaises(ValueError):
            isoprop.brick(np.zeros((4, 4), np.uint8), support.work("2d.ibv"))
        with self.assertRaises(ValueError):
            isoprop.brick(np.zeros((4, 1, 4), np.uint8), support.work("thin.ibv"))
        with self.assertRaises(ValueError):
            isoprop.brick(np.zeros((4, 4, 4), np.uint8), support.work("x.ibv"), dims=(4, 4, 4))
        nan = np.zeros((4, 4, 4), np.float32)
        nan[1, 2, 3] = np.nan
        with self.assertRaises(isoprop.Error) as caught:
            isoprop.brick(nan, support.work("nan.ibv"))
        self.assertIn("array", str(caught.exception))
        self.assertNotIn(".raw", str(caught.exception))  # names the array, not the scratch file
        self.assertEqual(listing(), before, "an error left a file behind")

    def test_existing_output_and_force(self):
        out = support.work("exists.ibv")
        isoprop.brick(self.array, out, brick_size=8)
        before = listing()
        with self.assertRaises(isoprop.Error) as caught:
            isoprop.brick(self.array, out, brick_size=8)
        self.assertEqual(caught.exception.status, -8)  # IP_ERR_EXISTS
        self.assertIn(out, str(caught.exception))
        self.assertEqual(listing(), before)
        isoprop.brick(self.array, out, brick_size=8, force=True)
        self.assertEqual(listing(), before)

    def test_progress_and_cancel(self):
        seen = []
        isoprop.brick(self.array, support.work("progress.ibv"),
                      progress=lambda done, total: seen.append((done, total)))
        self.assertTrue(seen)
        self.assertEqual(seen[-1][1], self.array.nbytes)
        before = listing()
        out = support.work("cancelled.ibv")
        with self.assertRaises(isoprop.Error) as caught:
            isoprop.brick(self.array, out, progress=lambda done, total: True)
        self.assertEqual(caught.exception.status, -11)  # IP_ERR_CANCELLED
        self.assertEqual(listing(), before)

        def interrupt(done, total):
            raise KeyboardInterrupt

        with self.assertRaises(KeyboardInterrupt):  # Ctrl-C cancels cleanly too
            isoprop.brick(self.array, out, progress=interrupt)
        self.assertEqual(listing(), before)


@unittest.skipUnless(os.path.exists(os.path.join(support.BIN, "tests", "make_zarr")),
                     "a build without the Zarr reader (IP_ZARR off)")
class OmeZarr(unittest.TestCase):
    """OME-Zarr images (make_zarr): channel=, time= and scale= pick the volume, as isobrick's
    --channel, --time and --scale do; refused on other inputs."""

    @classmethod
    def setUpClass(cls):
        cls.raw = support.generate("shepp-logan", (45, 38, 27), "int16")
        cls.dir = support.work("zarr")
        support.tool("tests/make_zarr", cls.raw, "45x38x27", cls.dir)

    def test_channel_and_scale(self):
        ome = os.path.join(self.dir, "ome05.zarr")
        with self.assertRaisesRegex(isoprop.Error, "pick a volume with --time and --channel"):
            isoprop.brick(ome, support.work("none.ibv"))
        self.assertFalse(os.path.exists(support.work("none.ibv")))
        out = support.work("c2.ibv")
        isoprop.brick(ome, out, channel=2, brick_size=8, force=True)
        raw = support.work("raw.ibv")
        isoprop.brick(self.raw, raw, spacing=(0.5, 0.5, 1.25), brick_size=8, force=True)
        a, b = support.isoinfo(out), support.isoinfo(raw)
        for key in ("dims", "spacing", "value_min", "value_max"):
            self.assertEqual(a[key], b[key], key)
        self.assertEqual(a["origin"], [2.5, -5, 0])
        half = support.work("half.ibv")
        isoprop.brick(ome, half, channel=2, scale=1, force=True)
        self.assertEqual(support.isoinfo(half)["dims"], [23, 19, 14])

    def test_refused(self):
        with self.assertRaisesRegex(isoprop.Error, "not an OME-Zarr image"):
            isoprop.brick(self.raw, support.work("t.ibv"), time=0)
        with self.assertRaises(TypeError):
            isoprop.brick(self.raw, support.work("t.ibv"), channel="1")


class DicomFolder(unittest.TestCase):
    """A DICOM folder as scanners write it (make_dicom): several series picked by series=, a
    gantry tilt resampled or refused (correct_tilt=), as isobrick does."""

    @classmethod
    def setUpClass(cls):
        cls.dir = support.work("dicom")
        os.makedirs(cls.dir, exist_ok=True)
        support.tool("tests/make_dicom", cls.dir)
        listing = support.tool("isobrick", os.path.join(cls.dir, "scanner"), "--list-series")
        cls.uids = [line.split()[0] for line in listing.splitlines()
                    if line and line[0].isdigit()]

    def test_series_picked(self):
        self.assertEqual(len(self.uids), 2, self.uids)
        scanner = os.path.join(self.dir, "scanner")
        with self.assertRaisesRegex(isoprop.Error, "series"):
            isoprop.brick(scanner, support.work("several.ibv"))
        self.assertFalse(os.path.exists(support.work("several.ibv")))
        for k, uid in enumerate(self.uids):
            out = support.work("series%d.ibv" % k)
            isoprop.brick(scanner, out, series=uid, force=True)
            self.assertEqual(support.isoinfo(out)["dims"][2] > 0, True)
        # the series alone and picked from the scanner's folder give the same file
        alone = support.work("alone.ibv")
        isoprop.brick(os.path.join(self.dir, "series"), alone, force=True)
        picked = [support.work("series%d.ibv" % k) for k in range(2)]
        same = [open(alone, "rb").read() == open(p, "rb").read() for p in picked]
        self.assertEqual(sorted(same), [False, True])

    def test_tilt(self):
        tilted = os.path.join(self.dir, "tilted")
        with self.assertRaisesRegex(isoprop.Error, "tilt"):
            isoprop.brick(tilted, support.work("refused.ibv"), correct_tilt=False)
        self.assertFalse(os.path.exists(support.work("refused.ibv")))
        isoprop.brick(tilted, support.work("tilted.ibv"), force=True)
        self.assertTrue(os.path.exists(support.work("tilted.ibv")))

    def test_bad_arguments(self):
        with self.assertRaises(TypeError):
            isoprop.brick(self.dir, support.work("x.ibv"), series=1)
        with self.assertRaises(isoprop.ArgumentError):
            isoprop.brick(self.dir, support.work("x.ibv"), series="")
        with self.assertRaises(isoprop.ArgumentError):
            isoprop.brick(np.zeros((2, 2, 2), np.uint8), support.work("x.ibv"), series="1.2")
        with self.assertRaises(TypeError):
            isoprop.brick(self.dir, support.work("x.ibv"), correct_tilt="no")


@unittest.skipUnless(os.path.exists(os.path.join(support.BIN, "tests/make_hdf5")),
                     "built without HDF5 (IP_HDF5=OFF)")
class Hdf5File(unittest.TestCase):
    """An HDF5 file with two 3-D datasets (make_hdf5): dataset= picks one, as isobrick
    --dataset does; without it the file is refused naming both."""

    @classmethod
    def setUpClass(cls):
        cls.dir = support.work("hdf5")
        os.makedirs(cls.dir, exist_ok=True)
        support.tool("isogen", "sphere", "--dims", "20x18x16", "--type", "uint16", "-o",
                     cls.dir + "/", "--quiet")
        support.tool("tests/make_hdf5", os.path.join(cls.dir, "sphere_20x18x16_uint16.raw"),
                     cls.dir)

    def test_dataset_picked(self):
        two = os.path.join(self.dir, "two.h5")
        with self.assertRaisesRegex(isoprop.Error, "2 3-D datasets: pick one with --dataset: /a"):
            isoprop.brick(two, support.work("several.ibv"))
        self.assertFalse(os.path.exists(support.work("several.ibv")))
        raw = support.work("h5_raw.ibv")
        isoprop.brick(os.path.join(self.dir, "sphere_20x18x16_uint16.raw"), raw, force=True)
        picked = support.work("h5_picked.ibv")
        isoprop.brick(two, picked, dataset="/b/c", force=True)
        self.assertEqual(open(raw, "rb").read(), open(picked, "rb").read())
        with self.assertRaises(TypeError):
            isoprop.brick(two, support.work("x.ibv"), dataset=3)
        with self.assertRaises(isoprop.ArgumentError):
            isoprop.brick(np.zeros((2, 2, 2), np.uint8), support.work("x.ibv"), dataset="/a")


if __name__ == "__main__":
    support.main()

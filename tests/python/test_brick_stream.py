# SPDX-License-Identifier: BSD-3-Clause
"""isoprop.brick() from array-likes, streamed slab by slab into the bricker through the
library's plane source (ip_input_desc_from_planes()), with no scratch file and no whole copy:
a numpy memmap and a minimal object with only shape, dtype and __getitem__ give the brick file
of the raw file; each plane is asked for once, in slabs the bricker's plan holds; an exception
of the slicing is re-raised with nothing written; a NaN is named; progress can cancel."""
import os
import unittest

import support  # first: it skips (status 77) when numpy is absent
import numpy as np
import isoprop

DIMS = (40, 36, 70)  # x, y, z: several layers of 8^3 bricks


class Counted:
    """An array-like with only shape, dtype and slicing, counting the bytes asked for."""

    def __init__(self, array, fail_at=None):
        self.array, self.fail_at = array, fail_at
        self.shape, self.dtype = array.shape, array.dtype
        self.bytes, self.largest, self.slices = 0, 0, []

    def __getitem__(self, key):
        if not isinstance(key, slice):
            raise TypeError("only slices: %r" % (key,))
        if self.fail_at is not None and key.start <= self.fail_at < key.stop:
            raise KeyError("plane %d is gone" % self.fail_at)
        slab = self.array[key].copy()
        self.bytes += slab.nbytes
        self.largest = max(self.largest, slab.nbytes)
        self.slices.append((key.start, key.stop))
        return slab


class BrickStream(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.raw, cls.array = support.generated_uint16("gyroid", DIMS)
        cls.ref = support.work("ref.ibv")
        isoprop.brick(cls.raw, cls.ref, brick_size=8, force=True)
        with open(cls.ref, "rb") as f:
            cls.ref_bytes = f.read()

    def same_as_ref(self, path):
        with open(path, "rb") as f:
            self.assertEqual(f.read(), self.ref_bytes, "%s differs from the raw file's" % path)

    def test_memmap(self):
        for mode in ("r", "r+", "c"):
            mapped = np.memmap(self.raw, dtype="<u2", mode=mode, shape=DIMS[::-1])
            out = support.work("memmap-%s.ibv" % mode)
            report = isoprop.brick(mapped, out, brick_size=8, force=True)
            self.assertEqual(report["input_bytes"], mapped.nbytes)
            self.same_as_ref(out)
            self.assertEqual(int(mapped[35, 20, 10]), int(self.array[35, 20, 10]))
            del mapped

    def test_minimal_array_like(self):
        for threads, mem_mb in ((1, 0), (2, 16)):
            source = Counted(self.array.astype(">u2"))  # big-endian: converted to the host's
            out = support.work("counted.ibv")
            report = isoprop.brick(source, out, brick_size=8, threads=threads, mem_mb=mem_mb,
                                   force=True)
            self.same_as_ref(out)
            self.assertEqual(source.bytes, self.array.nbytes)  # every plane once, no more
            starts = [a for a, _ in source.slices]
            ends = [b for _, b in source.slices]
            self.assertEqual(starts, [0] + ends[:-1])  # in order, no gap
            self.assertEqual(ends[-1], DIMS[2])
            self.assertGreater(len(source.slices), 1)  # slab by slab, not the whole array
            self.assertLessEqual(source.largest, report["memory_planned"])

    def test_slicing_error_is_reraised(self):
        source = Counted(self.array, fail_at=50)
        out = support.work("failed.ibv")
        before = support.listing()
        with self.assertRaises(KeyError) as caught:
            isoprop.brick(source, out, brick_size=8)
        self.assertIn("plane 50 is gone", str(caught.exception))
        self.assertEqual(support.listing(), before)  # no output, no scratch file
        self.assertFalse(os.path.exists(out))

    def test_wrong_slab_shape(self):
        class Short(Counted):
            def __getitem__(self, key):
                return Counted.__getitem__(self, key)[:, :-1]
        with self.assertRaises(ValueError) as caught:
            isoprop.brick(Short(self.array), support.work("short.ibv"))
        self.assertIn("source: slicing [0:", str(caught.exception))
        self.assertFalse(os.path.exists(support.work("short.ibv")))

    def test_nan_named(self):
        values = self.array.astype(np.float32)
        values[33, 2, 1] = np.nan
        with self.assertRaises(isoprop.Error) as caught:
            isoprop.brick(Counted(values), support.work("nan.ibv"))
        self.assertEqual(str(caught.exception),
                         "array: float32 sample at (x,y,z) = (1,2,33) is NaN")

    def test_cancel_and_interrupt(self):
        for raised in (None, KeyboardInterrupt):
            seen = []

            def progress(done, total):
                seen.append(done)
                if raised:
                    raise raised()
                return True
            source = Counted(self.array)
            out = support.work("cancelled.ibv")
            with self.assertRaises(KeyboardInterrupt if raised else isoprop.Error):
                isoprop.brick(source, out, brick_size=8, progress=progress)
            self.assertEqual(len(seen), 1)
            self.assertLess(source.bytes, self.array.nbytes)  # stopped early
            self.assertFalse(os.path.exists(out))


if __name__ == "__main__":
    support.main()

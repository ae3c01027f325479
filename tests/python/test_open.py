# SPDX-License-Identifier: BSD-3-Clause
"""isoprop.open(): the file's attributes against isoinfo --json; errors for missing and corrupt
files; closing."""
import gc
import unittest

import support  # first: it skips (status 77) when numpy is absent
import numpy as np
import isoprop


class Open(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.ibv = support.phantom((40, 33, 27), "int16", "0.5,0.75,1.25")
        cls.info = support.isoinfo(cls.ibv)

    def test_attributes_equal_isoinfo(self):
        i = self.info
        with isoprop.open(self.ibv) as f:
            self.assertEqual(f.path, i["file"])
            self.assertEqual(list(f.dims), i["dims"])
            self.assertEqual(f.shape, tuple(i["dims"][::-1]))
            self.assertEqual(f.dtype, np.dtype(i["type"]))
            self.assertEqual(list(f.spacing), i["spacing"])
            self.assertEqual(f.value_range, (i["value_min"], i["value_max"]))
            self.assertEqual((f.brick_size, f.subblock_size), (i["brick_size"], i["subblock_size"]))
            self.assertEqual(f.file_bytes, i["bytes_file"])
            self.assertEqual(len(f.levels), i["levels"])
            for level, info in zip(f.levels, i["level_info"]):
                self.assertEqual(level.level, info["level"])
                self.assertEqual(list(level.dims), info["dims"])
                self.assertEqual(list(level.bricks), info["bricks"])
                self.assertEqual(level.value_range, (info["value_min"], info["value_max"]))
            hi = tuple((d - 1) * s for d, s in zip(f.dims, f.spacing))
            self.assertEqual(f.world_box, ((0.0, 0.0, 0.0), hi))

    def test_missing_file_raises_with_its_path(self):
        path = support.work("no-such.ibv")
        with self.assertRaises(isoprop.Error) as caught:
            isoprop.open(path)
        self.assertIn(path, str(caught.exception))
        self.assertEqual(caught.exception.status, -1)  # IP_ERR_IO
        self.assertIsInstance(caught.exception, RuntimeError)

    def test_corrupt_file_raises_with_its_path(self):
        with open(self.ibv, "rb") as f:
            data = bytearray(f.read())
        bad = support.work("bad-header.ibv")
        data[8] ^= 0xFF  # the format version, covered by the header's checksum
        with open(bad, "wb") as f:
            f.write(data)
        with self.assertRaises(isoprop.Error) as caught:
            isoprop.open(bad)
        self.assertTrue(str(caught.exception).startswith(bad), str(caught.exception))
        self.assertLess(caught.exception.status, 0)
        self.assertTrue(caught.exception.status_name)
        short = support.work("short.ibv")
        with open(short, "wb") as f:
            f.write(data[:100])
        with self.assertRaises(isoprop.Error) as caught:
            isoprop.open(short)
        self.assertIn(short, str(caught.exception))

    def test_not_a_brick_file(self):
        raw = support.generate("sphere", (8, 8, 8), "uint8")
        with self.assertRaises(isoprop.Error) as caught:
            isoprop.open(raw)
        self.assertIn(raw, str(caught.exception))

    def test_closed_file_refuses_work(self):
        f = isoprop.open(self.ibv)
        f.close()
        f.close()  # twice is fine
        with self.assertRaises(ValueError):
            f.extract(100.5, full=True)
        g = isoprop.open(self.ibv)
        steps = g.extract_steps(100.5, size=(32, 24), rays_per_step=16)
        next(steps)
        del g  # the generator keeps the file; freeing both must not crash
        del steps
        gc.collect()


if __name__ == "__main__":
    support.main()

# SPDX-License-Identifier: BSD-3-Clause
"""The rescale from Python: a DICOM CT's brick file (Hounsfield units = stored - 1024) opened
shows its rescale and value ranges as isoinfo --json does; extract(-500) and
extract(524, stored=True) give the same triangles, and their statistics as isorender --stats
writes them (iso, iso_stored, rescale); brick(rescale=...) sets or drops a rescale; a file
without one reads as before."""
import json
import os
import unittest
import warnings

import support  # first: it skips (status 77) when numpy is absent
import numpy as np
import isoprop


class Units(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        support.tool(os.path.join("tests", "make_dicom"), support.WORK, "--air")
        cls.series = support.work("series")
        cls.raw = support.work("volume_40x36x13_int16.raw")
        cls.ct = support.work("ct.ibv")
        support.tool("isobrick", cls.series, "-o", cls.ct, "--brick-size", "8", "--quiet")
        cls.info = support.isoinfo(cls.ct)

    def test_the_rescale_and_ranges_as_isoinfo_shows_them(self):
        i = self.info
        with isoprop.open(self.ct) as f:
            self.assertEqual(f.rescale, isoprop.Rescale(1.0, -1024.0, "HU"))
            self.assertEqual(f.rescale._asdict(), i["rescale"])
            self.assertEqual(f.format_version, i["format_version"])
            self.assertEqual(f.format_version, 3)
            self.assertEqual(f.value_range, (i["value_min"], i["value_max"]))
            self.assertEqual(f.value_range_stored, (i["value_min_stored"], i["value_max_stored"]))
            self.assertEqual(f.value_range[0], -1000.0)
            for level, info in zip(f.levels, i["level_info"]):
                self.assertEqual(level.value_range, (info["value_min"], info["value_max"]))

    def test_iso_in_hu_equals_the_stored_value(self):
        with isoprop.open(self.ct) as f:
            for full in (True, False):
                a = f.extract(-500, full=full, threads=1, size=(64, 48))
                b = f.extract(524, stored=True, full=full, threads=1, size=(64, 48))
                self.assertGreater(len(a.faces), 100)
                self.assertTrue(np.array_equal(a.vertices, b.vertices), "full=%r" % full)
                self.assertTrue(np.array_equal(a.normals, b.normals), "full=%r" % full)
                for s in (a.stats, b.stats):
                    self.assertEqual(s["iso"], -500.0)
                    self.assertEqual(s["iso_stored"], 524.0)
                    self.assertEqual(s["rescale"], {"slope": 1.0, "intercept": -1024.0,
                                                    "unit": "HU"})
                # another surface where the value is taken as stored: -500 is below them all
                with self.assertWarns(RuntimeWarning) as caught:
                    c = f.extract(-500, stored=True, full=full, threads=1, size=(64, 48))
                self.assertEqual(len(c.faces), 0)
                self.assertIn("iso -500 (stored) is outside the value range", str(caught.warning))
            steps = list(f.extract_steps(200, threads=1, size=(64, 48)))
            stored = list(f.extract_steps(1224, stored=True, threads=1, size=(64, 48)))
            grid = list(f.extract_steps(1224, stored=True, threads=1, size=(64, 48),
                                        space="grid"))
            self.assertEqual(len(steps), len(stored))
            self.assertEqual(len(steps), len(grid))
            self.assertTrue(all(np.array_equal(x.vertices, y.vertices)
                                for x, y in zip(steps, stored)))
            # the grid's vertices are the physical ones less the origin (LPS, axes unturned)
            self.assertEqual((steps[-1].space, grid[-1].space), ("LPS", "grid"))
            self.assertTrue(all(np.allclose(x.vertices - np.array(f.origin), y.vertices,
                                            atol=1e-4) for x, y in zip(steps, grid)))
            self.assertEqual(steps[-1].stats["iso_stored"], 1224.0)

    def test_stats_as_isorender_writes_them(self):
        stats = support.work("full.json")
        support.tool("isorender", self.ct, "--iso", "-500", "--full", "--threads", "1",
                     "--size", "64x48", "--software", "-o", support.work("full.png"),
                     "--stats", stats, "--quiet", "--force")
        with open(stats) as j:
            written = json.load(j)
        with isoprop.open(self.ct) as f:
            mesh = f.extract(-500, full=True, threads=1, size=(64, 48))
        for key in ("iso", "iso_stored", "rescale", "triangles", "cells"):
            self.assertEqual(mesh.stats[key], written[key], key)
        # the keys in isorender's order: iso, then iso_stored and rescale, then the rest
        keys = list(mesh.stats)
        self.assertEqual(keys[keys.index("iso"):keys.index("iso") + 4],
                         ["iso", "iso_stored", "rescale", "mode"])

    def test_brick_sets_and_drops_a_rescale(self):
        scaled, dropped = support.work("scaled.ibv"), support.work("dropped.ibv")
        isoprop.brick(self.raw, scaled, dims=(40, 36, 13), dtype="int16", brick_size=8,
                      spacing=(0.8, 0.7, 2.5), rescale=(0.5, -3.25, "mg/ml"), force=True)
        isoprop.brick(self.series, dropped, brick_size=8, rescale=False, force=True)
        with isoprop.open(scaled) as f, isoprop.open(dropped) as g, isoprop.open(self.ct) as ct:
            self.assertEqual(f.rescale, isoprop.Rescale(0.5, -3.25, "mg/ml"))
            self.assertEqual(support.isoinfo(scaled)["rescale"], f.rescale._asdict())
            self.assertIsNone(g.rescale)
            self.assertEqual(g.format_version, 2)
            self.assertEqual(g.value_range, g.value_range_stored)
            # stored 524 everywhere; on the grid, since the raw volume has no physical space
            want = ct.extract(-500, full=True, threads=1, space="grid").vertices
            for mesh in (f.extract(258.75, full=True, threads=1, space="grid"),
                         g.extract(524, full=True, threads=1, space="grid"),
                         ct.extract(524, stored=True, full=True, threads=1, space="grid")):
                self.assertEqual(mesh.space, "grid")
                self.assertTrue(np.array_equal(mesh.vertices, want))
            # the series' own physical space (LPS) whichever way the isovalue is given
            self.assertTrue(np.array_equal(g.extract(524, full=True, threads=1).vertices,
                                           ct.extract(-500, full=True, threads=1).vertices))
            self.assertNotIn("iso_stored", g.extract(524, full=True).stats)
            self.assertNotIn("rescale", g.extract(524, full=True).stats)
        array = np.zeros((4, 5, 6), np.int16)
        array[1:3, 1:4, 1:5] = 100
        out = support.work("array.ibv")
        isoprop.brick(array, out, rescale=(2, -3), force=True)
        with isoprop.open(out) as f:
            self.assertEqual(f.rescale, isoprop.Rescale(2.0, -3.0, ""))
            self.assertEqual(f.value_range, (-3.0, 197.0))

    def test_negative_slope_range_rule(self):
        """With a negative slope the units run against the stored values: the maximum in units
        is the stored minimum, which has no surface, and the warning says the rule that way."""
        out = support.work("flipped.ibv")
        isoprop.brick(self.series, out, brick_size=8, rescale=(-1, 1024, "negHU"), force=True)
        with isoprop.open(out) as f:
            lo, hi = f.value_range
            self.assertLess(lo, hi)
            with self.assertWarns(RuntimeWarning) as caught:
                f.extract(hi, full=True, threads=1)
            self.assertIn("at least the minimum and below the maximum", str(caught.warning))
            with warnings.catch_warnings():
                warnings.simplefilter("error")
                self.assertGreater(len(f.extract(lo, full=True, threads=1)), 0)

    def test_bad_arguments(self):
        out = support.work("bad.ibv")
        for bad, kind, text in (((0, 1), isoprop.ArgumentError, "slope 0 is not a finite"),
                                ((1, float("nan")), isoprop.ArgumentError, "intercept"),
                                ((1, 2, "\u00b5g"), isoprop.ArgumentError, "not printable"),
                                ((1, 2, "a" * 16), isoprop.ArgumentError, "longer than 15"),
                                ((1,), TypeError, "(slope, intercept[, unit])"),
                                ("HU", TypeError, "(slope, intercept[, unit])"),
                                ((1, 2, 3), TypeError, "the unit must be a str")):
            with self.assertRaises(kind) as caught:
                isoprop.brick(self.raw, out, dims=(40, 36, 13), dtype="int16", rescale=bad)
            self.assertIn(text, str(caught.exception))
        self.assertFalse(os.path.exists(out))
        with isoprop.open(self.ct) as f:
            with self.assertRaises(TypeError):
                f.extract(-500, stored="yes", full=True)
            with self.assertRaises(isoprop.ArgumentError):
                f.extract(1e39, stored=True, full=True)  # beyond float32


if __name__ == "__main__":
    support.main()

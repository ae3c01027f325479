# SPDX-License-Identifier: BSD-3-Clause
"""Views and cameras in the file's physical space: one object stored in several orders
(make_orders: NIfTI in RAS, LAS and LAI order, a DICOM series in LPS) gives the same cameras
(in its own space's coordinates) and the same surface, as isorender does (tests/tools/orders.sh)."""
import itertools
import unittest

import support  # first: it skips (status 77) when numpy is absent
import numpy as np
import isoprop

ISO = 0.5
SIZE = (96, 80)
ORDERS = ("ras", "las", "lai", "dicom")
LPS = np.array([-1.0, -1.0, 1.0])  # RAS coordinates to LPS ones, and back


def same_points(a, b, tolerance=1e-4):
    """Whether every point of a has one of b within the tolerance (and as many of each)."""
    a, b = np.unique(a, axis=0), np.unique(b, axis=0)
    if len(a) != len(b):
        return False
    size = 100 * tolerance
    grid = {}
    for p in b:
        grid.setdefault(tuple((p // size).astype(int)), []).append(p)
    for p in a:
        key = (p // size).astype(int)
        if not any(np.all(np.abs(q - p) <= tolerance)
                   for step in itertools.product((-1, 0, 1), repeat=3)
                   for q in grid.get(tuple(key + step), [])):
            return False
    return True


class Views(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        support.tool("tests/make_orders", support.WORK)
        cls.files = {}
        for name in ORDERS:
            source = support.work("series" if name == "dicom" else name + ".nii")
            ibv = support.work(name + ".ibv")
            support.tool("isobrick", source, "-o", ibv, "--brick-size", "8", "--quiet", "--force")
            cls.files[name] = isoprop.open(ibv)

    @classmethod
    def tearDownClass(cls):
        for f in cls.files.values():
            f.close()

    def camera(self, name, **kw):
        c = self.files[name].camera(size=SIZE, **kw)
        to_ras = LPS if name == "dicom" else np.ones(3)
        return {k: np.array(c[k]) * to_ras for k in ("eye", "target", "up")}

    def test_spaces(self):
        self.assertEqual([self.files[n].space for n in ORDERS], ["RAS", "RAS", "RAS", "LPS"])

    def test_the_same_camera_from_every_order(self):
        for view in (None, "anterior", "left", "superior", "+x", "-z"):
            ras = self.camera("ras", view=view)
            for name in ORDERS[1:]:
                if name == "dicom" and view in ("+x", "-z"):
                    continue  # the file's own axes: LPS's +x is left
                with self.subTest(view=view, order=name):
                    got = self.camera(name, view=view)
                    for k in ras:
                        np.testing.assert_allclose(got[k], ras[k], atol=1e-9)

    def test_named_views(self):
        ras = self.camera("ras")
        # the default is anterior: the eye in front of the face (RAS +y), up superior
        self.assertGreater(ras["eye"][1], ras["target"][1])
        np.testing.assert_allclose(ras["up"], [0, 0, 1])
        pairs = ((("ras", "right"), ("ras", "+x")), (("dicom", "left"), ("dicom", "+x")),
                 (("dicom", "anterior"), ("dicom", "-y")), (("ras", "inferior"), ("ras", "-z")))
        for (n1, v1), (n2, v2) in pairs:
            with self.subTest(views=(n1, v1, n2, v2)):
                c1, c2 = self.files[n1].camera(view=v1), self.files[n2].camera(view=v2)
                for k in ("eye", "target"):
                    np.testing.assert_allclose(c1[k], c2[k], atol=1e-9)
        up = self.camera("ras", view="superior")["up"]
        np.testing.assert_allclose(up, [0, 1, 0], atol=1e-12)  # anterior

    def test_camera_is_physical(self):
        """camera= takes what camera() gives (physical units): the same run either way."""
        for name in ("las", "dicom"):
            f = self.files[name]
            given = f.camera(view="left", size=SIZE)
            a = f.extract(ISO, view="left", size=SIZE, threads=1)
            b = f.extract(ISO, camera=given, size=SIZE, threads=1)
            with self.subTest(order=name):
                self.assertEqual(len(a), len(b))
                np.testing.assert_array_equal(a.vertices, b.vertices)
                np.testing.assert_allclose(b.stats["camera"]["eye"], given["eye"], atol=1e-9)
                np.testing.assert_allclose(a.stats["camera"]["eye"], given["eye"], atol=1e-9)

    def test_the_same_surface_from_every_order(self):
        """The meshes, in each file's physical space (LPS turned to RAS), have the same vertices
        and as many triangles."""
        meshes = {n: self.files[n].extract(ISO, full=True) for n in ORDERS}
        ras = meshes["ras"].vertices.astype(np.float64)
        self.assertGreater(len(ras), 0)
        self.assertEqual([meshes[n].space for n in ORDERS], ["RAS", "RAS", "RAS", "LPS"])
        for name in ORDERS[1:]:
            got = meshes[name].vertices.astype(np.float64)
            if name == "dicom":
                got = got * LPS
            with self.subTest(order=name):
                self.assertEqual(len(meshes[name]), len(meshes["ras"]))
                self.assertTrue(same_points(got, ras))


if __name__ == "__main__":
    support.main()

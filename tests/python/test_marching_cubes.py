# SPDX-License-Identifier: BSD-3-Clause
"""isoprop.marching_cubes() as a drop-in for scikit-image's: shapes and dtypes, welded vertices,
the same positions as the brick file's full extraction in axis order with spacing per axis,
winding and normals for both gradient directions, degenerate triangles kept or dropped, the
level's checks; against skimage.measure.marching_cubes when it is installed. And contour()."""
import unittest

import support  # first: it skips (status 77) when numpy is absent
import numpy as np
import isoprop

SHAPE = (14, 19, 23)          # axis 0, 1, 2: not cubic
SPACING = (1.5, 0.75, 1.25)   # per axis, unequal
CENTRE = (6.3, 9.1, 10.4)     # in samples, off every symmetry
LEVEL = 50.3


def ball():
    """A bright ellipsoid (values 100 at the centre, falling by 10 a unit of distance), float32:
    the surface at LEVEL is closed, well inside the array."""
    i, j, k = np.meshgrid(*(np.arange(n, dtype=np.float64) for n in SHAPE), indexing="ij")
    d = np.sqrt((i - CENTRE[0]) ** 2 + ((j - CENTRE[1]) * 0.8) ** 2 + ((k - CENTRE[2]) * 0.9) ** 2)
    return (100.0 - 10.0 * d).astype(np.float32)


def sorted_rows(a, *others):
    """a's rows in lexicographic order, and `others` reordered the same way."""
    order = np.lexsort(a.T[::-1])
    return (a[order],) + tuple(o[order] for o in others)


def degenerate(faces):
    return (faces[:, 0] == faces[:, 1]) | (faces[:, 1] == faces[:, 2]) | (faces[:, 0] == faces[:, 2])


def face_normals(verts, faces):
    t = verts[faces].astype(np.float64)
    return np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])


class MarchingCubes(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.volume = ball()
        cls.result = isoprop.marching_cubes(cls.volume, LEVEL, spacing=SPACING)

    def test_shapes_and_dtypes(self):
        verts, faces, normals, values = self.result
        self.assertGreater(len(faces), 100)
        self.assertEqual(verts.shape, (len(verts), 3))
        self.assertEqual(faces.shape, (len(faces), 3))
        self.assertEqual(normals.shape, verts.shape)
        self.assertEqual(values.shape, (len(verts),))
        for a, dtype in ((verts, np.float32), (faces, np.int32), (normals, np.float32),
                         (values, np.float32)):
            self.assertEqual(a.dtype, dtype)
        self.assertEqual(faces.min(), 0)
        self.assertEqual(faces.max(), len(verts) - 1)  # every vertex used
        np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-5)

    def test_welded(self):
        """Each position once, and every edge of the closed surface in exactly two faces."""
        verts, faces, _, _ = self.result
        self.assertEqual(len(np.unique(verts, axis=0)), len(verts))
        good = faces[~degenerate(faces)]
        edges = np.sort(np.concatenate([good[:, [0, 1]], good[:, [1, 2]], good[:, [2, 0]]]), 1)
        _, counts = np.unique(edges, axis=0, return_counts=True)
        self.assertEqual(set(counts.tolist()), {2})

    def test_full_extraction_in_axis_order(self):
        """verts are the brick file's full extraction (x, y, z = axis 2, 1, 0), reordered."""
        ibv = support.work("ball.ibv")
        isoprop.brick(self.volume, ibv, spacing=SPACING[::-1], force=True)
        with isoprop.open(ibv) as f:
            mesh = f.extract(LEVEL, full=True, space="grid")
        want = np.unique(mesh.vertices[:, ::-1], axis=0)
        np.testing.assert_array_equal(np.unique(self.result[0], axis=0), want)
        self.assertEqual(len(self.result[1]), len(mesh))  # degenerate triangles kept

    def test_spacing_per_axis(self):
        """Each axis scales by its own spacing, and only it."""
        verts, faces = isoprop.marching_cubes(self.volume, LEVEL)[:2]
        np.testing.assert_allclose(sorted_rows(verts * np.float32(SPACING))[0],
                                   sorted_rows(self.result[0])[0], rtol=1e-6, atol=1e-5)
        self.assertEqual(len(faces), len(self.result[1]))
        # the centre of the surface is the ball's, in axis order times spacing
        np.testing.assert_allclose(self.result[0].mean(0), np.multiply(CENTRE, SPACING), atol=0.1)

    def test_winding_and_normals(self):
        """descent: faces counter-clockwise seen from the higher values (outside the ball is
        lower: their right-hand normals point in), ascent the other way; normals toward lower
        values (out) in both."""
        verts, faces, normals, _ = self.result
        centre = verts.mean(0)
        good = faces[~degenerate(faces)]
        outward = verts[good].mean(1) - centre
        self.assertTrue(((face_normals(verts, good) * outward).sum(1) < 0).all())
        self.assertTrue(((normals * (verts - centre)).sum(1) > 0).all())
        v2, f2, n2, _ = isoprop.marching_cubes(self.volume, LEVEL, spacing=SPACING,
                                               gradient_direction="ascent")
        np.testing.assert_array_equal(v2, verts)
        np.testing.assert_array_equal(n2, normals)
        np.testing.assert_array_equal(f2, faces[:, ::-1])

    def test_degenerate(self):
        """A level equal to samples makes triangles with two corners at one vertex: kept with
        allow_degenerate (as classic marching cubes counts them), dropped without."""
        volume = np.rint(self.volume)  # LEVEL 50 now equals some samples exactly
        keep = isoprop.marching_cubes(volume, 50.0, spacing=SPACING)
        drop = isoprop.marching_cubes(volume, 50.0, spacing=SPACING, allow_degenerate=False)
        n = int(degenerate(keep[1]).sum())
        self.assertGreater(n, 0)
        self.assertEqual(int(degenerate(drop[1]).sum()), 0)
        self.assertEqual(len(drop[1]), len(keep[1]) - n)
        # the same triangles, corner for corner (the vertices' numbering may differ)
        np.testing.assert_array_equal(drop[0][drop[1]], keep[0][keep[1][~degenerate(keep[1])]])

    def test_values(self):
        """values: the larger sample at the ends of each vertex's edge, at least the level."""
        verts, _, _, values = self.result
        self.assertTrue((values >= LEVEL - 1e-4).all())
        self.assertTrue((values <= self.volume.max()).all())
        index = verts / np.float32(SPACING)
        lo = np.floor(index + 1e-4).astype(int)
        self.assertTrue((values >= self.volume[lo[:, 0], lo[:, 1], lo[:, 2]] - 1e-3).all())

    def test_level(self):
        """Default: the middle of the data's range; NaN and outside it: ValueError naming level."""
        mid = 0.5 * (float(self.volume.min()) + float(self.volume.max()))
        a = isoprop.marching_cubes(self.volume)
        b = isoprop.marching_cubes(self.volume, mid)
        np.testing.assert_array_equal(a[0], b[0])
        for bad in (float("nan"), float(self.volume.max()) + 1, float(self.volume.min()) - 1):
            with self.assertRaisesRegex(ValueError, "^level: "):
                isoprop.marching_cubes(self.volume, bad)

    def test_arguments(self):
        with self.assertRaisesRegex(ValueError, "^volume: must be a 3-D array"):
            isoprop.marching_cubes(np.zeros((4, 4)), 0.5)
        with self.assertRaisesRegex(ValueError, "^spacing: axis 1"):
            isoprop.marching_cubes(self.volume, LEVEL, spacing=(1, 0, 1))
        with self.assertRaisesRegex(ValueError, "^gradient_direction"):
            isoprop.marching_cubes(self.volume, LEVEL, gradient_direction="up")

    def test_dtypes(self):
        """Integer, boolean and float64 arrays give the same surface as float32 of the same
        values."""
        small = (self.volume > 40).astype(np.uint8) * 200
        want = isoprop.marching_cubes(small.astype(np.float32), 100.0)
        for dtype in (np.uint8, np.int16, np.int32, np.float64):
            got = isoprop.marching_cubes(small.astype(dtype), 100.0)
            np.testing.assert_array_equal(sorted_rows(got[0])[0], sorted_rows(want[0])[0])
            self.assertEqual(len(got[1]), len(want[1]))
        got = isoprop.marching_cubes(self.volume > 40, 0.5)
        self.assertEqual(len(got[1]), len(want[1]))

    def test_against_scikit_image(self):
        """Where scikit-image is installed: the same vertices (as sets, to float rounding) and
        winding sense; the same face count once degenerate faces are left out (its Lewiner
        tables split some cells' polygons along other diagonals, so the faces differ)."""
        try:
            from skimage.measure import marching_cubes as sk
        except ImportError:
            self.skipTest("scikit-image is not installed (Debian: python3-skimage)")
        for direction in ("descent", "ascent"):
            verts, faces, normals, _ = isoprop.marching_cubes(
                self.volume, LEVEL, spacing=SPACING, gradient_direction=direction,
                allow_degenerate=False)
            sv, sf, sn, _ = sk(self.volume, LEVEL, spacing=SPACING, gradient_direction=direction,
                               allow_degenerate=False)
            self.assertEqual(len(faces), len(sf))
            self.assertEqual(len(verts), len(sv))
            np.testing.assert_allclose(sorted_rows(verts)[0], sorted_rows(sv)[0], atol=1e-4)
            mine = np.sign((face_normals(verts, faces) * verts[faces].mean(1)).sum(1)).mean()
            theirs = np.sign((face_normals(sv, sf) * sv[sf].mean(1)).sum(1)).mean()
            self.assertEqual(np.sign(mine - 0), np.sign(theirs - 0))
            centre = sv.mean(0)
            self.assertTrue(((sn * (sv - centre)).sum(1) > 0).all())  # both point out


class Contour(unittest.TestCase):
    def test_array_and_path(self):
        """contour() of an array is File.extract()'s progressive mesh of the same brick file;
        of a path likewise."""
        volume = ball()
        ibv = support.work("contour.ibv")
        isoprop.brick(volume, ibv, spacing=SPACING[::-1], force=True)
        with isoprop.open(ibv) as f:
            want = f.extract(LEVEL, view="+x", size=(64, 48), threads=1)
        got = isoprop.contour(volume, LEVEL, spacing=SPACING, view="+x", size=(64, 48), threads=1)
        self.assertIsInstance(got, isoprop.Mesh)
        self.assertGreater(len(got), 0)
        np.testing.assert_array_equal(got.vertices, want.vertices)
        again = isoprop.contour(ibv, LEVEL, view="+x", size=(64, 48), threads=1)
        np.testing.assert_array_equal(again.vertices, want.vertices)
        with self.assertRaisesRegex(ValueError, "^spacing: "):
            isoprop.contour(ibv, LEVEL, spacing=(1, 1, 1))
        with self.assertRaisesRegex(ValueError, "^full: "):
            isoprop.contour(volume, LEVEL, full=True)


if __name__ == "__main__":
    support.main()

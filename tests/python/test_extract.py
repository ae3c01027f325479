# SPDX-License-Identifier: BSD-3-Clause
"""File.extract() and extract_steps() against isorender: full extraction triangle for triangle
as isorender --full --mesh writes them, a progressive run on one thread likewise, the
statistics' keys against isorender --stats, steps against one run, errors."""
import json
import os
import unittest
import warnings

import support  # first: it skips (status 77) when numpy is absent
import numpy as np
import isoprop


ISO = 1000.5
SIZE = (64, 48)
# Keys of isorender --stats that the module leaves out: they come from rasterizing the run's
# mesh into the image (the renderer, which isoprop's Python module does not load).
RENDER_ONLY = {"final_pixel_pct", "visible_triangles", "overdraw"}


def key_paths(d, prefix=""):
    """Every key of a nested dict as "a.b.c" (the first element of lists of dicts included)."""
    out = set()
    for k, v in d.items():
        out.add(prefix + k)
        if isinstance(v, dict):
            out |= key_paths(v, prefix + k + ".")
        elif isinstance(v, list) and v and isinstance(v[0], dict):
            out |= key_paths(v[0], prefix + k + "[].")
    return out


class Extract(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.ibv = support.phantom((48, 40, 36), "uint16", "1,1,1.5")
        cls.f = isoprop.open(cls.ibv)

    @classmethod
    def tearDownClass(cls):
        cls.f.close()

    def isorender(self, name, *args):
        """isorender on the phantom (software rasterizer, one thread); returns its mesh (PLY)
        and its --stats JSON."""
        ply, stats = support.work(name + ".ply"), support.work(name + ".json")
        support.tool("isorender", self.ibv, "--iso", ISO, "--size", "%dx%d" % SIZE,
                     "--threads", "1", "--software", "-o", support.work(name + ".png"),
                     "--mesh", ply, "--no-weld", "--stats", stats, "--quiet", "--force", *args)
        with open(stats) as s:
            return support.read_ply(ply), json.load(s)

    def assert_same_triangles(self, mesh, ply):
        vertices, normals, faces = ply
        self.assertGreater(len(mesh), 0)
        self.assertEqual(len(mesh), len(faces))
        np.testing.assert_array_equal(mesh.vertices, vertices)
        np.testing.assert_array_equal(mesh.normals, normals)
        np.testing.assert_array_equal(mesh.faces, faces)
        self.assertEqual(mesh.vertices.dtype, np.float32)
        self.assertEqual(mesh.normals.dtype, np.float32)

    def assert_same_keys(self, ours, theirs):
        """The stats have isorender's keys, less those of RENDER_ONLY it wrote (not
        final_pixel_pct with --full); and the same counts."""
        # "surface" (isorender --stats with --full) is Mesh.measure()'s in Python
        theirs_keys = {k for k in key_paths(theirs) if k.split(".")[0] != "surface"}
        ours_keys = key_paths(ours)
        self.assertEqual(ours_keys - theirs_keys, set())
        self.assertEqual(theirs_keys - ours_keys, RENDER_ONLY & set(theirs))
        self.assertIn("overdraw", theirs)
        for k in ("mode", "width", "height", "rays", "rays_total", "done", "seeds", "cells",
                  "triangles", "threads", "lod", "pixel_error", "iso", "warnings"):
            self.assertEqual(ours[k], theirs[k], k)
        for k in ("eye", "target", "up"):  # isorender prints 9 digits
            np.testing.assert_allclose(ours["camera"][k], theirs["camera"][k], rtol=1e-8)
        self.assertAlmostEqual(ours["camera"]["fov"], theirs["camera"]["fov"])
        self.assertEqual(ours["cache"]["bricks_total"], theirs["cache"]["bricks_total"])

    def test_full_equals_isorender_full(self):
        ply, stats = self.isorender("full", "--full")
        for threads in (1, 0):  # brick order whatever the threads
            mesh = self.f.extract(ISO, full=True, size=SIZE, threads=threads)
            self.assert_same_triangles(mesh, ply)
        mesh = self.f.extract(ISO, full=True, size=SIZE, threads=1)
        self.assert_same_keys(mesh.stats, stats)
        self.assertEqual(mesh.stats["triangles"], len(mesh))

    def test_full_lod_equals_isorender_full_lod(self):
        """full="lod" is isorender --full-lod: the view's levels, each level's cells in its
        distance band; at a 4-pixel error the phantom's far side comes from a coarser level,
        so there are fewer triangles than in the full extraction."""
        ply, stats = self.isorender("full-lod", "--full-lod", "--view", "+x", "--pixel-error", "4")
        self.assertEqual(stats["mode"], "full-lod")
        for threads in (1, 0):
            mesh = self.f.extract(ISO, full="lod", view="+x", size=SIZE, threads=threads,
                                  pixel_error=4)
            self.assert_same_triangles(mesh, ply)
        mesh = self.f.extract(ISO, full="lod", view="+x", size=SIZE, threads=1, pixel_error=4)
        self.assert_same_keys(mesh.stats, stats)
        whole = self.f.extract(ISO, full=True, size=SIZE)
        self.assertLess(len(mesh), len(whole))
        with self.assertRaises(ValueError):
            self.f.extract(ISO, full="lod", lod=False, size=SIZE)
        with self.assertRaises(ValueError):
            self.f.extract(ISO, full="yes", size=SIZE)

    def test_progressive_equals_isorender_on_one_thread(self):
        ply, stats = self.isorender("progressive", "--view", "+x")
        mesh = self.f.extract(ISO, view="+x", size=SIZE, threads=1)
        self.assert_same_triangles(mesh, ply)
        self.assert_same_keys(mesh.stats, stats)
        self.assertTrue(mesh.stats["done"])
        self.assertEqual(mesh.stats["rays"], SIZE[0] * SIZE[1])

    def test_prefetch_always_and_off_same_triangles(self):
        """prefetch="always" (isorender --prefetch always) and prefetch=False extract the same
        triangles on one thread; the statistics say whether a reader ran."""
        always = self.f.extract(ISO, view="+x", size=SIZE, threads=1, prefetch="always")
        off = self.f.extract(ISO, view="+x", size=SIZE, threads=1, prefetch=False)
        self.assertTrue(always.stats["prefetch"])
        self.assertFalse(off.stats["prefetch"])
        self.assertEqual(always.stats["prefetch_mode"], "always")
        self.assertEqual(off.stats["prefetch_mode"], "off")
        self.assertEqual(always.faces.tolist(), off.faces.tolist())
        self.assertEqual(always.vertices.tolist(), off.vertices.tolist())
        with self.assertRaises(ValueError):
            self.f.extract(ISO, view="+x", size=SIZE, threads=1, prefetch="off")

    def test_cull_equals_isorender_cull_on(self):
        """cull=True keeps what isorender --mesh --cull on keeps, and fewer triangles than the
        default, which keeps them all; the counts add up."""
        ply, stats = self.isorender("culled", "--view", "+x", "--cull", "on")
        self.assertTrue(stats["cull"])
        mesh = self.f.extract(ISO, view="+x", size=SIZE, threads=1, cull=True)
        self.assert_same_triangles(mesh, ply)
        self.assertTrue(mesh.stats["cull"])
        self.assertEqual(mesh.stats["culled_triangles"], stats["culled_triangles"])
        whole = self.f.extract(ISO, view="+x", size=SIZE, threads=1)
        self.assertFalse(whole.stats["cull"])
        self.assertEqual(whole.stats["culled_triangles"], 0)
        self.assertGreater(mesh.stats["culled_triangles"], 0)
        self.assertEqual(len(mesh) + mesh.stats["culled_triangles"], len(whole))

    def test_camera_text_and_dict(self):
        text = "24,-80,30,24,20,26,0,0,1,35"
        ply, _ = self.isorender("camera", "--camera", text)
        as_dict = {"eye": (24, -80, 30), "target": (24, 20, 26), "up": (0, 0, 1), "fov": 35}
        for camera in (text, as_dict):
            self.assert_same_triangles(
                self.f.extract(ISO, camera=camera, size=SIZE, threads=1), ply)
        self.assertEqual(self.f.camera(camera=as_dict, size=SIZE)["eye"], (24.0, -80.0, 30.0))
        with self.assertRaises(isoprop.Error):
            self.f.extract(ISO, camera={"eye": (1, 1, 1), "target": (1, 1, 1), "up": (0, 0, 1)})
        with self.assertRaises(isoprop.Error):
            self.f.extract(ISO, view="+w")

    def test_steps_concatenated_equal_one_run(self):
        for rays in (1000, None):
            one = self.f.extract(ISO, view="-z", size=SIZE, rays=rays, threads=1)
            steps = list(self.f.extract_steps(ISO, view="-z", size=SIZE, rays=rays, threads=1,
                                              rays_per_step=37))
            expect = rays or SIZE[0] * SIZE[1]
            self.assertEqual(len(steps), -(-expect // 37))
            self.assertEqual(steps[-1].rays, expect)
            self.assertEqual(steps[-1].done, rays is None)
            self.assertEqual(sum(s.counts["rays"] for s in steps), expect)
            self.assertEqual([s.first_triangle for s in steps],
                             list(np.cumsum([0] + [len(s) for s in steps[:-1]])))
            np.testing.assert_array_equal(np.concatenate([s.vertices for s in steps]),
                                          one.vertices)
            np.testing.assert_array_equal(np.concatenate([s.normals for s in steps]),
                                          one.normals)
            self.assertEqual(steps[-1].stats["triangles"], len(one))
        seen = []
        mesh = self.f.extract(ISO, view="-z", size=SIZE, threads=1, on_step=seen.append)
        self.assertEqual([s.rays for s in seen][:3], [1, 2, 4])  # 1, 2, 4, ... rays a step
        np.testing.assert_array_equal(np.concatenate([s.vertices for s in seen]), mesh.vertices)

    def test_unfinished_steps_free_their_engine(self):
        steps = self.f.extract_steps(ISO, size=SIZE, rays_per_step=100)
        first = next(steps)
        self.assertEqual(first.rays, 100)
        self.assertFalse(first.done)
        steps.close()
        self.assertFalse(self.f._runs)
        # a time limit ends the run early, and the warm cache is kept between calls
        mesh = self.f.extract(ISO, size=(1600, 1200), time_limit=0.001)
        self.assertLess(mesh.stats["rays"], 1600 * 1200)

    def test_iso_outside_the_range_warns(self):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            mesh = self.f.extract(1e6, size=SIZE)
        self.assertEqual(len(mesh), 0)
        self.assertEqual(mesh.vertices.shape, (0, 3))
        self.assertEqual(len(mesh.stats["warnings"]), 1)
        self.assertIn(self.ibv, mesh.stats["warnings"][0])
        self.assertTrue(any(issubclass(w.category, RuntimeWarning) for w in caught))

    def test_corrupt_payload_raises_with_its_path(self):
        sections = dict(line.split(" ", 1) for line in support.tool(
            os.path.join("tests", "corrupt"), "info", self.ibv).splitlines())
        offset, size = (int(v) for v in sections["data"].split())
        with open(self.ibv, "rb") as f:
            data = bytearray(f.read())
        data[offset:offset + size] = bytes(b ^ 0x5A for b in data[offset:offset + size])
        bad = support.work("bad-payload.ibv")
        with open(bad, "wb") as f:
            f.write(data)
        with isoprop.open(bad) as g:  # the summaries are intact
            for full in (True, False):
                with self.assertRaises(isoprop.Error) as caught:
                    g.extract(ISO, full=full, size=SIZE)
                self.assertTrue(str(caught.exception).startswith(bad), str(caught.exception))
                self.assertEqual(caught.exception.status, -6)  # IP_ERR_CHECKSUM
            self.assertFalse(g._runs)


class Space(unittest.TestCase):
    """Vertices in the file's physical space, as isorender --mesh writes them, or in the grid
    (index x spacing) with space="grid", as --mesh-grid; the Mesh names which."""

    @classmethod
    def setUpClass(cls):
        raw = support.generate("sphere", (24, 20, 16), "uint8")
        nhdr = support.work("turned.nhdr")
        with open(nhdr, "w") as h:  # x along +y, y along -x; spacings 0.5, 0.5, 2
            h.write("NRRD0004\ntype: uint8\ndimension: 3\nsizes: 24 20 16\n"
                    "space: left-posterior-superior\n"
                    "space directions: (0,0.5,0) (-0.5,0,0) (0,0,2)\n"
                    "space origin: (10,-20,30.5)\nendian: little\nencoding: raw\n"
                    "data file: %s\n" % os.path.basename(raw))
        cls.ibv = support.work("turned.ibv")
        support.tool("isobrick", nhdr, "-o", cls.ibv, "--brick-size", "8", "--quiet")
        cls.f = isoprop.open(cls.ibv)

    @classmethod
    def tearDownClass(cls):
        cls.f.close()

    def isorender_mesh(self, name, *args):
        ply = support.work(name + ".ply")
        support.tool("isorender", self.ibv, "--iso", 128, "--full", "--threads", "1",
                     "--software", "-o", support.work(name + ".png"), "--mesh", ply,
                     "--no-weld", "--quiet", "--force", *args)
        return support.read_ply(ply)

    def test_file_orientation(self):
        self.assertEqual(self.f.origin, (10.0, -20.0, 30.5))
        self.assertEqual(self.f.directions, ((0.0, 1.0, 0.0), (-1.0, 0.0, 0.0), (0.0, 0.0, 1.0)))

    def test_physical_by_default(self):
        mesh = self.f.extract(128, full=True, threads=1)
        self.assertEqual(mesh.space, "LPS")
        vertices, normals, _ = self.isorender_mesh("physical")
        self.assertGreater(len(mesh), 0)
        np.testing.assert_array_equal(mesh.vertices, vertices)
        np.testing.assert_array_equal(mesh.normals, normals)

    def test_grid(self):
        grid = self.f.extract(128, full=True, threads=1, space="grid")
        self.assertEqual(grid.space, "grid")
        vertices, normals, _ = self.isorender_mesh("grid", "--mesh-grid")
        np.testing.assert_array_equal(grid.vertices, vertices)
        np.testing.assert_array_equal(grid.normals, normals)
        # physical = origin + D * grid: (10 - y, -20 + x, 30.5 + z)
        physical = self.f.extract(128, full=True, threads=1)
        g = grid.vertices.astype(np.float64)
        want = np.stack([10 - g[:, 1], -20 + g[:, 0], 30.5 + g[:, 2]], axis=1)
        np.testing.assert_allclose(physical.vertices, want, atol=1e-4)

    def test_progressive_and_steps(self):
        mesh = self.f.extract(128, view="-y", size=(48, 32), threads=1)
        vertices, _, _ = self.isorender_mesh_view()
        self.assertEqual(mesh.space, "LPS")
        np.testing.assert_array_equal(mesh.vertices, vertices)
        steps = list(self.f.extract_steps(128, view="-y", size=(48, 32), threads=1))
        self.assertTrue(all(s.space == "LPS" for s in steps))
        np.testing.assert_array_equal(np.concatenate([s.vertices for s in steps]), vertices)

    def isorender_mesh_view(self):
        ply = support.work("view.ply")
        support.tool("isorender", self.ibv, "--iso", 128, "--size", "48x32", "--threads", "1",
                     "--view", "-y", "--software", "-o", support.work("view.png"), "--mesh", ply,
                     "--no-weld", "--quiet", "--force")
        return support.read_ply(ply)

    def test_bad_space(self):
        with self.assertRaises(isoprop.ArgumentError):
            self.f.extract(128, space="index")
        with self.assertRaises(TypeError):
            self.f.extract(128, space=1)


class SampleVolume(unittest.TestCase):
    """A real volume of ../shared/data, bricked from a numpy array in Python, against
    isorender --full on the brick file isobrick makes of the raw file."""

    def test_tooth_full_from_an_array_equals_isorender(self):
        raw = os.path.join(os.environ.get("IP_SHARED_DATA", ""),
                           "tooth_103x94x161_uint8.raw")
        if not os.path.isfile(raw):
            print("skipped in part: %s is absent (the real volumes of ../shared/data)" % raw)
            return
        ibv, ply = support.work("tooth.ibv"), support.work("tooth.ply")
        support.tool("isobrick", raw, "-o", ibv, "--quiet")
        support.tool("isorender", ibv, "--iso", "120.5", "--full", "--software", "--size",
                     "64x48", "-o", support.work("tooth.png"), "--mesh", ply, "--no-weld", "--quiet")
        vertices, normals, faces = support.read_ply(ply)
        array = np.fromfile(raw, dtype=np.uint8).reshape(161, 94, 103)
        isoprop.brick(array, support.work("tooth-array.ibv"))
        with isoprop.open(support.work("tooth-array.ibv")) as f:
            mesh = f.extract(120.5, full=True)
        self.assertGreater(len(mesh), 100000)
        np.testing.assert_array_equal(mesh.vertices, vertices)
        np.testing.assert_array_equal(mesh.normals, normals)
        np.testing.assert_array_equal(mesh.faces, faces)


if __name__ == "__main__":
    support.main()

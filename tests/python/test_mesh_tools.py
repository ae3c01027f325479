# SPDX-License-Identifier: BSD-3-Clause
"""Mesh's tools: the welded form (points, indices, point_normals), area() and volume() of a
sphere, write() in every format read back (and byte for byte isorender --mesh's), and
to_pyvista() / to_trimesh() without those packages."""
import importlib
import json
import os
import struct
import subprocess
import sys
import unittest

import support  # first: it skips (status 77) when numpy is absent
import numpy as np
import isoprop

N = 40
RADIUS = 14.0            # samples
CENTRE = (19.3, 20.1, 18.7)
SPACING = (0.5, 0.5, 0.5)


def sphere():
    """RADIUS - distance from CENTRE (float32, shape (z, y, x)): the surface at 0 is a sphere
    of radius RADIUS samples, higher values inside."""
    z, y, x = np.meshgrid(*(np.arange(N, dtype=np.float64),) * 3, indexing="ij")
    d = np.sqrt((x - CENTRE[0]) ** 2 + (y - CENTRE[1]) ** 2 + (z - CENTRE[2]) ** 2)
    return (RADIUS - d).astype(np.float32)


def optional(name):
    """The module `name`, or None where it is not installed."""
    try:
        return importlib.import_module(name)
    except ImportError:
        return None


def read_obj(path):
    v, vn, f = [], [], []
    with open(path) as h:
        for line in h:
            p = line.split()
            if p and p[0] == "v":
                v.append([float(t) for t in p[1:4]])
            elif p and p[0] == "vn":
                vn.append([float(t) for t in p[1:4]])
            elif p and p[0] == "f":
                f.append([int(t.split("//")[0]) - 1 for t in p[1:4]])
    return np.array(v), np.array(vn), np.array(f)


def read_stl(path):
    with open(path, "rb") as h:
        data = h.read()
    (count,) = struct.unpack_from("<I", data, 80)
    rec = np.frombuffer(data, dtype=np.dtype([("n", "<f4", 3), ("p", "<f4", (3, 3)),
                                              ("a", "<u2")]), count=count, offset=84)
    assert len(data) == 84 + 50 * count
    return rec["p"]


def read_glb(path):
    """Positions and indices of a .glb's one primitive."""
    with open(path, "rb") as h:
        data = h.read()
    magic, version, length = struct.unpack_from("<4sII", data, 0)
    assert magic == b"glTF" and version == 2 and length == len(data)
    jlen, _ = struct.unpack_from("<I4s", data, 12)
    doc = json.loads(data[20:20 + jlen])
    blen, _ = struct.unpack_from("<I4s", data, 20 + jlen)
    binary = data[28 + jlen:28 + jlen + blen]

    def accessor(i, dtype, width):
        a = doc["accessors"][i]
        view = doc["bufferViews"][a["bufferView"]]
        start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
        per = 3 if a["type"] == "VEC3" else 1
        return np.frombuffer(binary, dtype=dtype, count=a["count"] * per,
                             offset=start).reshape(-1, width)

    prim = doc["meshes"][0]["primitives"][0]
    return accessor(prim["attributes"]["POSITION"], "<f4", 3), accessor(prim["indices"], "<u4", 3)


def open_edges(mesh):
    """(edges in one triangle, edges in more than two) of the welded mesh."""
    f = mesh.indices
    e = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    _, uses = np.unique(e, axis=0, return_counts=True)
    return int((uses == 1).sum()), int((uses > 2).sum())


class MeshTools(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.ibv = support.work("sphere.ibv")
        isoprop.brick(sphere(), cls.ibv, spacing=SPACING, force=True)
        with isoprop.open(cls.ibv) as f:
            cls.mesh = f.extract(0.0, full=True)
            cls.open_mesh = f.extract(RADIUS - 19.0, full=True)  # runs out of the volume

    def test_welded(self):
        m = self.mesh
        self.assertEqual(m.faces.shape, (len(m), 3))  # the soup's, as before
        np.testing.assert_array_equal(m.vertices[m.faces].reshape(-1, 3), m.vertices)
        self.assertEqual(m.indices.dtype, np.int32)
        self.assertEqual(m.points.dtype, np.float32)
        self.assertEqual(len(np.unique(m.points, axis=0)), len(m.points))
        self.assertLess(len(m.points), len(m.vertices) // 2)
        w = m.welded()
        self.assertIs(m.welded(), w)  # kept
        kept = m.welded(allow_degenerate=True)
        f = kept.faces
        proper = (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])
        np.testing.assert_array_equal(m.points[m.indices], m.triangles[proper])
        self.assertEqual(len(kept.faces), len(m))
        self.assertEqual(len(w.faces) + w.dropped, len(m))
        np.testing.assert_array_equal(kept.points[kept.faces], m.triangles)
        np.testing.assert_allclose(np.linalg.norm(m.point_normals, axis=1), 1.0, atol=1e-5)

    def test_area_and_volume(self):
        r = RADIUS * SPACING[0]
        self.assertAlmostEqual(self.mesh.area() / (4 * np.pi * r * r), 1.0, delta=0.01)
        self.assertAlmostEqual(self.mesh.volume() / (4 / 3 * np.pi * r ** 3), 1.0, delta=0.01)
        # the volume does not depend on where the origin is, for a closed surface
        shifted = isoprop.Mesh(self.mesh.vertices + np.float32(7.0), self.mesh.normals)
        self.assertAlmostEqual(shifted.volume(), self.mesh.volume(), delta=1e-3)
        # the same surface seen inside out (lower values inside) has the opposite sign
        flipped = isoprop.Mesh(self.mesh.triangles[:, ::-1].reshape(-1, 3), self.mesh.normals)
        self.assertAlmostEqual(flipped.volume(), -self.mesh.volume(), delta=1e-3)

    def test_write_formats(self):
        m = self.mesh
        w = m.welded()
        for name in ("s.ply", "s.obj", "s.stl", "s.glb"):
            m.write(support.work(name))
        v, n, f = support.read_ply(support.work("s.ply"))
        np.testing.assert_array_equal(v, w.points)
        np.testing.assert_array_equal(f, w.faces)
        np.testing.assert_allclose(n, w.normals, atol=1e-4)
        v, n, f = read_obj(support.work("s.obj"))
        np.testing.assert_allclose(v, w.points, rtol=1e-6, atol=1e-6)
        np.testing.assert_array_equal(f, w.faces)
        np.testing.assert_array_equal(read_stl(support.work("s.stl")), w.points[w.faces])
        v, f = read_glb(support.work("s.glb"))
        np.testing.assert_array_equal(v, w.points)
        np.testing.assert_array_equal(f, w.faces)
        m.write(support.work("soup.ply"), weld=False)
        v, n, f = support.read_ply(support.work("soup.ply"))
        np.testing.assert_array_equal(v, m.vertices)
        np.testing.assert_array_equal(n, m.normals)
        np.testing.assert_array_equal(f, m.faces)

    def test_write_as_isorender(self):
        """The welded PLY is isorender --full --mesh's, byte for byte."""
        ply = support.work("isorender.ply")
        support.tool("isorender", self.ibv, "--iso", "0", "--full", "--size", "32x24",
                     "--software", "-o", support.work("i.png"), "--mesh", ply, "--quiet",
                     "--force")
        self.mesh.write(support.work("python.ply"))
        with open(ply, "rb") as a, open(support.work("python.ply"), "rb") as b:
            self.assertEqual(a.read(), b.read())

    def test_write_errors(self):
        path = support.work("twice.ply")
        self.mesh.write(path)
        with self.assertRaisesRegex(isoprop.Error, "exists"):
            self.mesh.write(path)
        self.mesh.write(path, force=True)
        with self.assertRaisesRegex(ValueError, "^path: "):
            self.mesh.write(support.work("s.vtk"))
        self.assertFalse(os.path.exists(support.work("s.vtk")))

    def test_open_surface(self):
        """An open surface (the sphere cut by the volume's faces) has an area but its
        'volume' changes with the origin."""
        m = self.open_mesh
        self.assertGreater(m.area(), 0)
        shifted = isoprop.Mesh(m.vertices + np.float32(5.0), m.normals)
        self.assertGreater(abs(shifted.volume() - m.volume()), 1.0)

    def test_cap_and_decimate(self):
        """extract(full=True, cap=True) closes the cut sphere at the volume's faces around the
        ball's part inside the box; decimate() keeps about its share of the triangles, the
        closedness, the rim of an open surface and about the volume; bad arguments raise."""
        with isoprop.open(self.ibv) as f:
            capped = f.extract(RADIUS - 19.0, full=True, cap=True)
            with self.assertRaisesRegex(ValueError, "^cap: .*full=True"):
                f.extract(0.0, cap=True)
        self.assertEqual(open_edges(capped), (0, 0))
        # the ball of radius 19 samples inside the box [0, N - 1]^3: exact along x
        t = (np.arange(2000) + 0.5) * (N - 1) / 2000
        y, z = np.meshgrid(t - CENTRE[1], t - CENTRE[2])
        h = np.sqrt(np.clip(19.0 ** 2 - y * y - z * z, 0, None))
        length = np.clip(CENTRE[0] + h, 0, N - 1) - np.clip(CENTRE[0] - h, 0, N - 1)
        exact = length.sum() * ((N - 1) / 2000) ** 2 * SPACING[0] ** 3
        self.assertAlmostEqual(capped.volume() / exact, 1.0, delta=0.01)

        d = self.mesh.decimate(0.1)
        s = d.stats["decimate"]
        self.assertEqual(s["triangles_before"], len(self.mesh.indices))
        self.assertEqual(s["triangles_after"], len(d))
        self.assertLessEqual(len(d), 0.1 * s["triangles_before"])
        self.assertGreater(s["error"], 0)
        self.assertEqual(open_edges(d), (0, 0))
        self.assertAlmostEqual(d.volume() / self.mesh.volume(), 1.0, delta=0.03)
        rim = open_edges(self.open_mesh)[0]
        self.assertGreater(rim, 0)
        self.assertEqual(open_edges(self.open_mesh.decimate(0.2))[0], rim)
        for bad in (0, 1, 1.5, float("nan")):
            with self.assertRaisesRegex(ValueError, "^ratio: "):
                self.mesh.decimate(bad)
        with self.assertRaisesRegex(ValueError, "^error: "):
            self.mesh.decimate(0.5, error=-1.0)

    def test_other_libraries_absent(self):
        """to_pyvista() and to_trimesh() without the package: ImportError naming it and how to
        install it (run where they are not importable: a child python that blocks them)."""
        code = ("import sys; sys.modules['pyvista'] = None; sys.modules['trimesh'] = None\n"
                "import numpy as np, isoprop\n"
                "m = isoprop.Mesh(np.zeros((3, 3), np.float32), np.zeros((3, 3), np.float32))\n"
                "for call, name, hint in ((m.to_pyvista, 'pyvista', 'pip install pyvista'),\n"
                "                         (m.to_trimesh, 'trimesh', 'python3-trimesh')):\n"
                "    try:\n"
                "        call()\n"
                "    except ImportError as e:\n"
                "        assert name in str(e) and hint in str(e) and e.name == name, str(e)\n"
                "    else:\n"
                "        raise SystemExit(name + ': no ImportError')\n"
                "print('ok')\n")
        p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                           env=support.python_env())
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertEqual(p.stdout.strip(), "ok")

    def test_other_libraries(self):
        """Where pyvista or trimesh is installed: the same points and faces."""
        trimesh, pyvista = optional("trimesh"), optional("pyvista")
        if trimesh is not None:
            t = self.mesh.to_trimesh()
            np.testing.assert_array_equal(t.vertices, self.mesh.points)
            np.testing.assert_array_equal(t.faces, self.mesh.indices)
        if pyvista is not None:
            p = self.mesh.to_pyvista()
            np.testing.assert_array_equal(p.points, self.mesh.points)
            self.assertEqual(p.n_cells, len(self.mesh.indices))
        if trimesh is None and pyvista is None:
            self.skipTest("neither trimesh nor pyvista is installed")

    def test_measure(self):
        """measure(): the library's figures, those of area() and volume(), and isorender
        --stats' "surface" (same keys, same numbers)."""
        m = self.mesh.measure()
        self.assertTrue(m["closed"])
        self.assertEqual(m["components"], 1)
        self.assertAlmostEqual(m["area"], self.mesh.area(), delta=1e-6 * m["area"])
        self.assertAlmostEqual(m["volume"], self.mesh.volume(), delta=1e-6 * m["volume"])
        self.assertEqual(m["largest"]["triangles"], m["triangles"])
        np.testing.assert_array_equal(self.mesh.bbox[0], self.mesh.points.min(0))
        np.testing.assert_array_equal(self.mesh.bbox[1], self.mesh.points.max(0))
        self.assertFalse(self.open_mesh.measure()["closed"])
        stats = support.work("measure.json")
        support.tool("isorender", self.ibv, "--iso", "0", "--full", "--size", "32x24",
                     "--software", "-o", support.work("m.png"), "--stats", stats, "--quiet",
                     "--force")
        with open(stats) as f:
            theirs = json.load(f)["surface"]
        self.assertEqual(set(theirs), set(m))
        for k in ("triangles", "vertices", "components", "closed"):
            self.assertEqual(theirs[k], m[k], k)
        for k in ("area", "volume"):
            self.assertAlmostEqual(theirs[k], m[k], delta=1e-7 * abs(m[k]))

    def test_components_and_cleaning(self):
        """Two spheres (the second moved far off, half as large): two components; largest()
        is the first, clean(min_area) drops the small one, components() gives both."""
        big = self.mesh
        small_v = (big.vertices - big.bbox.mean(0).astype(np.float32)) * np.float32(0.5) + \
            np.float32(100.0)
        both = isoprop.Mesh(np.concatenate([small_v, big.vertices]),
                            np.concatenate([big.normals, big.normals]))
        m = both.measure()
        self.assertEqual(m["components"], 2)
        parts = both.components()
        self.assertEqual(len(parts), 2)
        self.assertAlmostEqual(parts[0].area(), big.area() / 4, delta=1e-3 * big.area())
        self.assertEqual(sum(len(p) for p in parts), m["triangles"])
        largest = both.largest()
        self.assertEqual(len(largest), len(big.indices))
        np.testing.assert_array_equal(largest.points, big.points)
        self.assertEqual(m["largest"]["triangles"], len(largest))
        self.assertEqual(len(both.clean(min_area=big.area() / 2)), len(big.indices))
        self.assertEqual(both.clean(min_area=0).measure()["components"], 2)
        self.assertEqual(len(both.clean(min_area=10 * big.area())), 0)
        for bad in (-1.0, float("nan")):
            with self.assertRaises(ValueError):
                both.clean(min_area=bad)


if __name__ == "__main__":
    support.main()

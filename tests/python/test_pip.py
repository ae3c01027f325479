# SPDX-License-Identifier: BSD-3-Clause
"""Installing the package with pip, offline, as a user would (docs/python.md, "Installing"):
the committed source tree, cloned, installed into a venv made with --system-site-packages
(pip install --no-build-isolation --no-index .), imports from another folder with a clean
environment (no PYTHONPATH, no ISOPROP_LIBRARY) and loads the libisoprop inside the package,
whose extraction matches the build's, and the module's tests of arrays, marching_cubes and
streaming and the docs' examples pass with it; `pip wheel` gives a wheel holding libisoprop.

Skipped (77) where the source tree is not a git checkout, where Debian's venv or pip is
missing (tools/setup.sh installs them), and in the sanitizer builds (the package is built
without them: the plain build covers it)."""
import os
import shutil
import subprocess
import sys
import unittest
import zipfile

import support  # first: it skips (status 77) when numpy is absent
import numpy as np
import isoprop

SOURCE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))

# Run by the venv's interpreter in another folder: bricks a cube, extracts it whole, prints
# the library's path and the triangle count.
CHILD = r"""
import sys
import numpy as np
import isoprop
a = np.zeros((20, 22, 24), np.uint16)
a[4:15, 5:17, 6:19] = 1000
isoprop.brick(a, sys.argv[1], brick_size=8)
with isoprop.open(sys.argv[1]) as f:
    print(isoprop.library_path)
    print(f.extract(500, full=True).triangle_count)
"""


# Run again by the venv's interpreter, which finds isoprop in the venv only (support.py checks
# that the library loaded is IP_EXPECT_LIBRARY's)
IN_VENV = ("test_marching_cubes.py", "test_open_array.py", "test_brick_stream.py", "test_docs.py")


def skip(why):
    print("skipped: " + why)
    sys.exit(77)


def run(args, **kw):
    p = subprocess.run(args, capture_output=True, text=True, **kw)
    if p.returncode != 0:
        raise AssertionError("%s: exit %d:\n%s%s" % (" ".join(args), p.returncode, p.stdout,
                                                     p.stderr))
    return p.stdout


def clean_env(**extra):
    """An environment without PYTHONPATH, ISOPROP_LIBRARY or a preloaded sanitizer: a user's."""
    env = {"PATH": "/usr/bin:/bin", "HOME": support.WORK, "LANG": "C.UTF-8",
           "ISOPROP_BUILD_JOBS": "2", "PIP_NO_INPUT": "1", "PIP_DISABLE_PIP_VERSION_CHECK": "1"}
    env.update(extra)
    return env


class Pip(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.clone = support.work("isoprop")
        head = run(["git", "-C", SOURCE, "rev-parse", "HEAD"]).strip()
        run(["git", "clone", "--quiet", "--no-checkout", SOURCE, cls.clone])
        run(["git", "-C", cls.clone, "checkout", "--quiet", head])
        cls.venv = support.work("venv")
        run([sys.executable, "-m", "venv", "--system-site-packages", cls.venv])
        cls.pip = [os.path.join(cls.venv, "bin", "python"), "-m", "pip"]

    def test_install_import_extract_and_wheel(self):
        run(self.pip + ["install", "--no-build-isolation", "--no-index", "."], cwd=self.clone,
            env=clean_env())
        elsewhere = support.work("elsewhere")
        os.makedirs(elsewhere)
        out = run([os.path.join(self.venv, "bin", "python"), "-c", CHILD,
                   os.path.join(elsewhere, "cube.ibv")], cwd=elsewhere, env=clean_env())
        path, triangles = out.split()
        site = run([os.path.join(self.venv, "bin", "python"), "-c",
                    "import sysconfig; print(sysconfig.get_paths()['platlib'])"],
                   env=clean_env()).strip()
        self.assertEqual(os.path.dirname(path), os.path.join(site, "isoprop"))
        self.assertTrue(os.path.basename(path).startswith("libisoprop.so."))
        # the same extraction as the build tree's module
        a = np.zeros((20, 22, 24), np.uint16)
        a[4:15, 5:17, 6:19] = 1000
        here = support.work("cube.ibv")
        isoprop.brick(a, here, brick_size=8)
        with isoprop.open(here) as f:
            self.assertEqual(int(triangles), f.extract(500, full=True).triangle_count)
        self.assertGreater(int(triangles), 0)

        # the module's own tests and the docs' examples pass with the installed package
        here_tests = os.path.dirname(os.path.abspath(__file__))
        for test in IN_VENV:
            run([os.path.join(self.venv, "bin", "python"), os.path.join(here_tests, test)],
                cwd=elsewhere, env=clean_env(IP_BIN=support.BIN, IP_EXPECT_LIBRARY=path,
                                             IP_TEST_TMP=support.work("tests")))
        wheels = support.work("wheels")
        run(self.pip + ["wheel", "--no-build-isolation", "--no-index", "--no-deps", "-w",
                        wheels, "."], cwd=self.clone, env=clean_env())
        built = [w for w in os.listdir(wheels) if w.startswith("isoprop-")]
        self.assertEqual(len(built), 1, os.listdir(wheels))
        self.assertIn("linux_", built[0])  # a platform wheel: it holds compiled code
        names = zipfile.ZipFile(os.path.join(wheels, built[0])).namelist()
        for name in ("isoprop/__init__.py", "isoprop/_config.py", "isoprop/py.typed",
                     "isoprop/libisoprop.so.0", "isoprop/libisoprop_input.so.0"):
            self.assertIn(name, names)


def main():
    if os.environ.get("IP_ASAN_RUNTIME"):
        skip("the pip-built package has no sanitizer: tested in the plain build")
    if shutil.which("git") is None or subprocess.run(
            ["git", "-C", SOURCE, "rev-parse", "HEAD"], capture_output=True).returncode != 0:
        skip("the source tree %s is not a git checkout (the test clones it)" % SOURCE)
    for module in ("venv", "ensurepip", "pip", "setuptools", "wheel"):
        if subprocess.run([sys.executable, "-c", "import " + module],
                          capture_output=True).returncode != 0:
            skip("%s has no %s (Debian: apt-get install python3-venv python3-pip "
                 "python3-setuptools python3-wheel)" % (sys.executable, module))
    support.main()


if __name__ == "__main__":
    main()

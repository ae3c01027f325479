# SPDX-License-Identifier: BSD-3-Clause
"""Where the module finds libisoprop: installed with cmake --install into a prefix, it loads
the prefix's library (relative to itself); ISOPROP_LIBRARY overrides, and a wrong one fails
at import with a message that names the variable."""
import os
import subprocess
import sys
import unittest

import support  # first: it skips (status 77) when numpy is absent
import isoprop


def python(code, **env):
    """Runs `code` in a fresh interpreter (this one) with `env` added, in the scratch folder
    (ctest runs the tests in build/python, where `import` would find the build's package)."""
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=support.WORK,
                          env=support.python_env(**env))


class Install(unittest.TestCase):
    def test_build_tree_loads_the_builds_library(self):
        self.assertTrue(os.path.samefile(os.path.dirname(isoprop.library_path), support.BIN))

    def test_installed_package_finds_the_prefixs_library(self):
        prefix = support.work("prefix")
        subprocess.run([os.environ["IP_CMAKE"], "--install", support.BIN, "--prefix", prefix],
                       check=True, capture_output=True)
        packages = os.path.join(prefix, os.environ["IP_PYTHON_INSTALL_DIR"])
        p = python("import isoprop; print(isoprop.library_path); print(isoprop.__version__)",
                   PYTHONPATH=packages)
        self.assertEqual(p.returncode, 0, p.stderr)
        path, version = p.stdout.split()
        self.assertEqual(os.path.dirname(os.path.dirname(path)), prefix)  # PREFIX/lib/...
        self.assertTrue(os.path.exists(path))
        self.assertEqual(version, isoprop.__version__)
        self.assertTrue(os.path.isfile(os.path.join(packages, "isoprop", "_config.py")))

    def test_install_says_where_the_module_went(self):
        """Prefix /usr (staged with DESTDIR): the module lands where Debian's /usr/bin/python3
        looks; another prefix: the install says which PYTHONPATH to set."""
        stage = support.work("stage")
        p = subprocess.run([os.environ["IP_CMAKE"], "--install", support.BIN, "--prefix", "/usr",
                            "--component", "Unspecified"], capture_output=True, text=True,
                           env=dict(os.environ, DESTDIR=stage))
        self.assertEqual(p.returncode, 0, p.stderr)
        packages = "/usr/" + os.environ["IP_PYTHON_INSTALL_DIR"]
        self.assertIn("Python module: %s%s/isoprop (on the path of Debian's python3)"
                      % (stage, packages), p.stdout)
        self.assertTrue(os.path.isfile(stage + packages + "/isoprop/__init__.py"))
        self.assertTrue(os.path.isfile(stage + packages + "/isoprop/py.typed"))
        if os.path.exists("/usr/bin/python3"):
            path = subprocess.run(["/usr/bin/python3", "-c", "import sys; print(sys.path)"],
                                  capture_output=True, text=True, env={}).stdout
            self.assertIn(repr(packages), path)
        prefix = support.work("elsewhere")
        p = subprocess.run([os.environ["IP_CMAKE"], "--install", support.BIN, "--prefix", prefix,
                            "--component", "Unspecified"], capture_output=True, text=True)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertIn("to import it: export PYTHONPATH=%s/%s"
                      % (prefix, os.environ["IP_PYTHON_INSTALL_DIR"]), p.stdout)

    def test_environment_variable_overrides(self):
        p = python("import isoprop; print(isoprop.library_path)",
                   ISOPROP_LIBRARY=isoprop.library_path)
        self.assertEqual(p.stdout.strip(), isoprop.library_path, p.stderr)
        missing = support.work("no-such/libisoprop.so")
        p = python("import isoprop", ISOPROP_LIBRARY=missing)
        self.assertNotEqual(p.returncode, 0)
        self.assertIn("ISOPROP_LIBRARY", p.stderr)
        self.assertIn(missing, p.stderr)


if __name__ == "__main__":
    support.main()

# SPDX-License-Identifier: BSD-3-Clause
"""Builds the Python package isoprop with its shared libraries inside it (pyproject.toml holds
the metadata; docs/python.md, "Installing"):

    pip install --no-build-isolation --no-index .    (or: pip wheel --no-build-isolation ...)

CMake builds libisoprop.so and libisoprop_input.so (the TIFF and DICOM readers libisoprop
loads from its own folder) and nothing else (IP_BUILD_TOOLS=OFF, IP_BUILD_TESTS=OFF), in
build-python/; they are copied into the package under their sonames, beside a _config.py that
names libisoprop relative to the package, so `import isoprop` needs no environment variable.
ISOPROP_BUILD_JOBS sets the build's parallel jobs (default: every core), CMAKE the cmake
program."""
import os
import re
import shutil
import subprocess

from setuptools import Distribution, setup
from setuptools.command.build_py import build_py

ROOT = os.path.dirname(os.path.abspath(__file__))


def version_parts():
    with open(os.path.join(ROOT, "include", "isoprop", "version.h")) as f:
        text = f.read()
    return [re.search(r"#define IP_VERSION_%s +(\d+)" % part, text).group(1)
            for part in ("MAJOR", "MINOR", "PATCH")]


class BuildWithLibrary(build_py):
    """build_py, then the shared libraries built with CMake, into the package."""

    def run(self):
        super().run()
        cmake = os.environ.get("CMAKE", "cmake")
        jobs = os.environ.get("ISOPROP_BUILD_JOBS") or str(os.cpu_count() or 1)
        tree = os.path.abspath(os.path.join(self.get_finalized_command("build").build_temp,
                                            "cmake"))
        subprocess.run([cmake, "-S", ROOT, "-B", tree, "-DCMAKE_BUILD_TYPE=Release",
                        "-DIP_BUILD_TOOLS=OFF", "-DIP_BUILD_TESTS=OFF", "-DIP_WERROR=OFF"],
                       check=True, stdout=subprocess.DEVNULL)
        subprocess.run([cmake, "--build", tree, "-j", jobs, "--target", "isoprop_shared",
                        "isoprop_input_shared"], check=True, stdout=subprocess.DEVNULL)
        package = os.path.join(self.build_lib, "isoprop")
        major = version_parts()[0]
        for name in ("libisoprop.so.", "libisoprop_input.so."):
            shutil.copyfile(os.path.join(tree, name + major), os.path.join(package, name + major))
        with open(os.path.join(package, "_config.py"), "w") as f:
            f.write("# Written by setup.py: libisoprop, relative to this folder.\n"
                    'LIBRARY = "libisoprop.so.%s"\nSONAME = "libisoprop.so.%s"\n' % (major, major))


class BinaryDistribution(Distribution):
    """The package holds compiled libraries: a platform wheel, installed in platlib."""

    def has_ext_modules(self):
        return True


setup(version=".".join(version_parts()), cmdclass={"build_py": BuildWithLibrary},
      distclass=BinaryDistribution, options={"build": {"build_base": "build-python"}})

# SPDX-License-Identifier: BSD-3-Clause
"""Shared by the Python tests: the build's programs, a scratch folder, PLY reading.

Environment (set by ctest, python/CMakeLists.txt): PYTHONPATH holds build/python, IP_BIN the
build folder, IP_TEST_TMP the scratch space. The scratch folder is removed when the test
passes and kept, for diagnosis, when it fails."""
import json
import os
import shutil
import subprocess
import sys
import threading
import unittest

try:
    import numpy as np
except ImportError:
    print("skipped: numpy is not installed (Debian: apt-get install python3-numpy)")
    sys.exit(77)


# test_pip.py runs some tests again with the package a venv installed: they must load its library
if os.environ.get("IP_EXPECT_LIBRARY"):
    import isoprop as _isoprop
    if _isoprop.library_path != os.environ["IP_EXPECT_LIBRARY"]:
        raise SystemExit("isoprop loaded %s, not the installed %s" % (
            _isoprop.library_path, os.environ["IP_EXPECT_LIBRARY"]))

# run.sh preloads the sanitizer's runtime for this interpreter in the AddressSanitizer build;
# the programs run below carry their own (python_env() gives it back to child interpreters).
PRELOAD = os.environ.pop("LD_PRELOAD", None)
BIN = os.environ.get("IP_BIN", os.path.join(os.path.dirname(__file__), "../../build"))
NAME = os.path.splitext(os.path.basename(sys.argv[0]))[0]
WORK = os.path.join(os.environ.get("IP_TEST_TMP", "/tmp/isoprop-test"), "python_" + NAME)


def tool(program, *args):
    """Runs build/PROGRAM with args; returns its stdout; fails the test on a non-zero exit."""
    p = subprocess.run([os.path.join(BIN, program)] + [str(a) for a in args],
                       capture_output=True, text=True)
    if p.returncode != 0:
        raise AssertionError("%s %s: exit %d: %s" % (program, " ".join(map(str, args)),
                                                     p.returncode, p.stderr.strip()))
    return p.stdout


def python_env(**extra):
    """The environment for a child python3 that imports isoprop: this one's, plus `extra`."""
    env = dict(os.environ, **extra)
    if PRELOAD:
        env["LD_PRELOAD"] = PRELOAD
    return env


def work(name):
    """A path in the test's scratch folder."""
    return os.path.join(WORK, name)


def generate(field, dims, dtype):
    """isogen FIELD into the scratch folder; returns the raw file's path."""
    return tool("isogen", field, "--dims", "x".join(map(str, dims)), "--type", dtype, "-o",
                WORK + "/", "--force").strip()


def generated_uint16(field, dims):
    """isogen FIELD as uint16 into the scratch folder: (the raw file's path, its samples as a
    numpy array of shape (z, y, x))."""
    raw = generate(field, dims, "uint16")
    return raw, np.fromfile(raw, dtype="<u2").reshape(tuple(dims)[::-1])


def listing():
    """The scratch folder's names, sorted."""
    return sorted(os.listdir(WORK))


def run_threads(work, count, timeout=120):
    """Runs work(k) on `count` threads at once, k = 0 .. count-1; returns the repr of each
    exception that escaped a thread (an empty list when none did)."""
    errors = []

    def guarded(k):
        try:
            work(k)
        except BaseException as e:  # noqa: B902: returned to the caller
            errors.append(repr(e))

    workers = [threading.Thread(target=guarded, args=(k,)) for k in range(count)]
    for w in workers:
        w.start()
    for w in workers:
        w.join(timeout)
    return errors


def phantom(dims, dtype, spacing, name="phantom.ibv"):
    """The Shepp-Logan phantom of `dims` and `dtype`, bricked (8^3 bricks, `spacing`) into the
    scratch folder; returns the brick file's path."""
    raw = generate("shepp-logan", dims, dtype)
    ibv = work(name)
    tool("isobrick", raw, "-o", ibv, "--brick-size", "8", "--spacing", spacing, "--quiet")
    return ibv


def isoinfo(path):
    return json.loads(tool("isoinfo", path, "--json"))


def read_ply(path):
    """A binary little-endian PLY as isorender --mesh writes it: float32 (N, 3) positions,
    float32 (N, 3) normals, int32 (M, 3) faces."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().split("\n")
    assert header[1] == "format binary_little_endian 1.0", header[1]
    counts = {line.split()[1]: int(line.split()[2]) for line in header
              if line.startswith("element ")}
    n, m = counts["vertex"], counts["face"]
    vertices = np.frombuffer(data, dtype="<f4", count=6 * n, offset=end).reshape(n, 6)
    faces = np.frombuffer(data, dtype=np.dtype([("k", "u1"), ("v", "<i4", 3)]), count=m,
                          offset=end + 24 * n)
    assert (faces["k"] == 3).all()
    return vertices[:, :3], vertices[:, 3:], faces["v"]


def main():
    """Runs the test case(s) of the calling module in a fresh scratch folder."""
    shutil.rmtree(WORK, ignore_errors=True)
    os.makedirs(WORK)
    result = unittest.main(module="__main__", exit=False, verbosity=2).result
    if result.wasSuccessful():
        shutil.rmtree(WORK, ignore_errors=True)
        sys.exit(0)
    print("%s: scratch files kept in %s" % (NAME, WORK), file=sys.stderr)
    sys.exit(1)

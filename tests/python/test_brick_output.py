# SPDX-License-Identifier: BSD-3-Clause
"""isoprop.brick()'s output path when it cannot be written: a missing folder, a file size cap
(RLIMIT_FSIZE, no root needed) and, when run as root, a full disk (a small tmpfs). Each error
names the output path the caller gave and leaves nothing behind (an array is streamed into the
bricker, with no scratch copy): FileNotFoundError naming the folder before any work when the
output's folder does not exist, isoprop.Error when the library's output cannot be written."""
import errno
import json
import os
import subprocess
import sys
import unittest

import support  # first: it skips (status 77) when numpy is absent
import numpy as np
import isoprop

# Run in a child interpreter so that the cap stays there: bricks the array in ARRAY.npy to
# OUT under a file size cap of CAP bytes (SIGXFSZ ignored, so that a write past it fails with
# EFBIG), from the array or from the raw file RAW; prints what was raised as JSON.
CHILD = r"""
import json, os, resource, signal, sys
import numpy as np
import isoprop
array, out, cap, raw = np.load(sys.argv[1]), sys.argv[2], int(sys.argv[3]), sys.argv[4]
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, (cap, cap))
try:
    if raw:
        isoprop.brick(raw, out, dims=array.shape[::-1], dtype=array.dtype)
    else:
        isoprop.brick(array, out)
    print(json.dumps(None))
except Exception as e:
    print(json.dumps({"type": type(e).__name__, "text": str(e), "os": isinstance(e, OSError),
                      "errno": getattr(e, "errno", None), "filename": getattr(e, "filename", None),
                      "library": isinstance(e, isoprop.Error)}))
"""


def listing(folder):
    return sorted(os.listdir(folder))


def noise(shape):
    """Random uint16 samples over the whole range: they do not compress, so the brick file
    (with its pyramid) is larger than the samples."""
    return np.random.default_rng(7).integers(0, 65536, shape, dtype=np.uint16)


class BrickOutput(unittest.TestCase):
    def assert_names_out(self, text, out):
        self.assertIn(out, text)
        self.assertNotIn(".isoprop-", text)  # the scratch file's name

    def test_missing_folder(self):
        array = noise((6, 7, 8))
        out = os.path.join("no-such-folder", "x.ibv")  # relative, as a user would write it
        before = listing(support.WORK)
        cwd = os.getcwd()
        os.chdir(support.WORK)
        try:
            raw = "noise_8x7x6_uint16.raw"
            array.tofile(raw)
            for source in (array, raw):
                with self.assertRaises(FileNotFoundError) as caught:
                    isoprop.brick(source, out)
                self.assertEqual(caught.exception.filename, out)
                self.assertEqual(caught.exception.errno, errno.ENOENT)
                self.assert_names_out(str(caught.exception), out)
                self.assertIn("the output's folder %s does not exist"
                              % os.path.join(support.WORK, "no-such-folder"),
                              str(caught.exception))
                self.assertIsNone(caught.exception.__cause__)
            os.unlink(raw)
        finally:
            os.chdir(cwd)
        self.assertEqual(listing(support.WORK), before)

    def child(self, array, out, cap, raw=""):
        saved = support.work("child-array.npy")
        np.save(saved, array)
        try:
            p = subprocess.run([sys.executable, "-c", CHILD, saved, out, str(cap), raw],
                               capture_output=True, text=True, env=support.python_env())
        finally:
            os.unlink(saved)
        self.assertEqual(p.returncode, 0, p.stderr)
        return json.loads(p.stdout)

    def test_file_size_cap(self):
        """Under RLIMIT_FSIZE: the brick file past the cap (isoprop.Error naming out), from an
        array (no scratch copy: nothing else is written) and from a file."""
        folder = support.work("capped")
        os.makedirs(folder)
        array = noise((24, 24, 24))
        ref = os.path.join(folder, "ref.ibv")
        isoprop.brick(array, ref)
        size = os.path.getsize(ref)
        os.unlink(ref)
        self.assertGreater(size, array.nbytes + 256)
        out = os.path.join(folder, "x.ibv")
        raw = os.path.join(folder, "noise.raw")

        cap = size // 2  # the brick file does not fit
        got = self.child(array, out, cap)
        self.assertTrue(got and got["library"], got)
        self.assert_names_out(got["text"], out)
        self.assertIn("File too large", got["text"])
        self.assertEqual(listing(folder), [])

        array.tofile(raw)
        got = self.child(array, out, cap, raw)
        self.assertTrue(got and got["library"], got)
        self.assert_names_out(got["text"], out)
        self.assertEqual(listing(folder), ["noise.raw"])

    def test_full_disk(self):
        """A 64 KiB tmpfs (mounting one needs root: skipped otherwise): the brick file of an
        array that does not fit (isoprop.Error naming out)."""
        if os.geteuid() != 0:
            print("skipped in part: mounting a small tmpfs (a full disk) needs root")
            return
        folder = support.work("full")
        os.makedirs(folder)
        p = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", folder],
                           capture_output=True, text=True)
        if p.returncode != 0:
            print("skipped in part: cannot mount a tmpfs here: %s" % p.stderr.strip())
            return
        try:
            out = os.path.join(folder, "x.ibv")
            with self.assertRaises(isoprop.Error) as caught:
                isoprop.brick(noise((40, 40, 40)), out)  # 128000 bytes, no scratch copy
            self.assert_names_out(str(caught.exception), out)
            self.assertIn("No space left", str(caught.exception))
            self.assertEqual(listing(folder), [])
        finally:
            subprocess.run(["umount", folder], check=True)


if __name__ == "__main__":
    support.main()

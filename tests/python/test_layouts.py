# SPDX-License-Identifier: BSD-3-Clause
"""The ctypes mirrors of python/isoprop/_structs.py against the C compiler: the size of every
mirrored struct, the offset of every field and the value of every mirrored constant, as
tests/helpers/struct_layouts.c prints them."""
import ctypes
import os
import subprocess
import unittest

import support  # first: it skips (status 77) when numpy is absent
from isoprop import _structs


class Layouts(unittest.TestCase):
    def test_every_mirror_matches_the_headers(self):
        out = subprocess.run([os.path.join(support.BIN, "tests", "struct_layouts")], check=True,
                             capture_output=True, text=True).stdout
        lines = dict(line.split() for line in out.splitlines())
        c = {k: v for k, v in lines.items() if not k.startswith("#")}
        constants = {k[1:]: int(v) for k, v in lines.items() if k.startswith("#")}
        checked = 0
        for name, mirror in _structs.MIRRORS.items():
            self.assertEqual(ctypes.sizeof(mirror), int(c[name]), "sizeof(%s)" % name)
            for field, _ in mirror._fields_:
                self.assertEqual(getattr(mirror, field).offset, int(c[name + "." + field]),
                                 "offsetof(%s, %s)" % (name, field))
                checked += 1
        # every field the helper prints is mirrored (a new C field fails here too)
        self.assertEqual(checked, sum(1 for k in c if "." in k))
        self.assertEqual(set(_structs.MIRRORS), {k for k in c if "." not in k})
        # every constant the helper prints is mirrored, with its value
        self.assertEqual(_structs.CONSTANTS, constants)


if __name__ == "__main__":
    support.main()

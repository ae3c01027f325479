# SPDX-License-Identifier: BSD-3-Clause
"""Writes every second sample of a uint16 raw volume along each axis (NAME_XxYxZ_uint16.raw in
OUT_FOLDER), for tests/tools/measure.sh: a small copy of a real CT scan."""
import re
import sys

import numpy as np

path, folder = sys.argv[1], sys.argv[2]
x, y, z = (int(v) for v in re.search(r"_(\d+)x(\d+)x(\d+)_uint16\.raw$", path).groups())
data = np.fromfile(path, dtype="<u2").reshape(z, y, x)[::2, ::2, ::2]
name = "%s/head_%dx%dx%d_uint16.raw" % (folder, data.shape[2], data.shape[1], data.shape[0])
data.tofile(name)
print(name)

#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Out-of-core bricking from Python: isoprop.brick() of a numpy memmap (streamed slab by slab
into the bricker, docs/python.md) next to isobrick on the same raw file, each in a fresh
process with the same memory limit; prints a table of wall time and peak RSS (ru_maxrss).

    PYTHONPATH=build/python /usr/bin/python3 tools/bench/bench_python_brick.py \
        [--bin build] [--dims 1024x1024x1024] [--mem-mb 256] [--runs 1] [--dir /tmp]

Generates DIR/gyroid_XxYxZ_uint16.raw with isogen (2 GiB for the default dims), bricks it
--runs times each way (interleaved) into DIR, and deletes the raw and brick files at the end.
Needs numpy and a built tree (isogen, isobrick, build/python)."""
import argparse
import filecmp
import os
import statistics
import subprocess
import sys
import time

# Run in a fresh interpreter: bricks the memmap; prints seconds and ru_maxrss (KiB).
CHILD = r"""
import resource, sys, time
import numpy as np
import isoprop
raw, out, x, y, z, mem = sys.argv[1:7]
a = np.memmap(raw, dtype="<u2", mode="r", shape=(int(z), int(y), int(x)))
t = time.perf_counter()
isoprop.brick(a, out, mem_mb=int(mem), force=True)
print(time.perf_counter() - t, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)
"""


def child_peak_kib(pid):
    """Waits for `pid`; returns (status, its ru_maxrss in KiB)."""
    _, status, usage = os.wait4(pid, 0)
    return status, usage.ru_maxrss


def run_python(raw, out, dims, mem_mb):
    p = subprocess.run([sys.executable, "-c", CHILD, raw, out] + [str(d) for d in dims] +
                       [str(mem_mb)], capture_output=True, text=True, check=True)
    seconds, rss = p.stdout.split()
    return float(seconds), int(rss)


def run_isobrick(bin_dir, raw, out, mem_mb):
    t = time.perf_counter()
    p = subprocess.Popen([os.path.join(bin_dir, "isobrick"), raw, "-o", out, "--mem-mb",
                          str(mem_mb), "--force", "--quiet"])
    status, rss = child_peak_kib(p.pid)
    if status != 0:
        raise SystemExit("isobrick failed (status %d)" % status)
    return time.perf_counter() - t, rss


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default="build")
    ap.add_argument("--dims", default="1024x1024x1024")
    ap.add_argument("--mem-mb", type=int, default=256)
    ap.add_argument("--runs", type=int, default=1)
    ap.add_argument("--dir", default="/tmp")
    args = ap.parse_args()
    dims = [int(d) for d in args.dims.split("x")]
    raw = subprocess.run([os.path.join(args.bin, "isogen"), "gyroid", "--dims", args.dims,
                          "--type", "uint16", "-o", args.dir + "/", "--force"],
                         capture_output=True, text=True, check=True).stdout.strip().split("\n")[-1]
    outs = [os.path.join(args.dir, "bench-python-brick-%s.ibv" % w) for w in ("py", "cli")]
    rows = []
    try:
        for _ in range(args.runs):
            rows.append(("isoprop.brick(np.memmap)",) + run_python(raw, outs[0], dims,
                                                                   args.mem_mb))
            rows.append(("isobrick RAW",) + run_isobrick(args.bin, raw, outs[1], args.mem_mb))
        same = filecmp.cmp(outs[0], outs[1], shallow=False)
    finally:
        for path in outs + [raw]:
            if os.path.exists(path):
                os.unlink(path)
    gib = dims[0] * dims[1] * dims[2] * 2 / 2**30
    print("input: %s uint16 (%.2f GiB), --mem-mb %d, %d run(s) each; brick files identical: %s"
          % (args.dims, gib, args.mem_mb, args.runs, "yes" if same else "NO"))
    print("%-26s %10s %14s" % ("how", "seconds", "peak RSS MiB"))
    for how, seconds, rss in rows:
        print("%-26s %10.2f %14.0f" % (how, seconds, rss / 1024))
    if args.runs > 1:
        for how in dict.fromkeys(r[0] for r in rows):
            mine = [r for r in rows if r[0] == how]
            print("%-26s %10.2f %14.0f" % ("median " + how.split("(")[0].split()[0],
                                           statistics.median(r[1] for r in mine),
                                           statistics.median(r[2] for r in mine) / 1024))


if __name__ == "__main__":
    main()

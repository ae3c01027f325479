#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# Extraction from a numpy array: isoprop.open_array() + extract(iso, full=True) against the
# brick-file route (isoprop.brick() to a scratch file, open(), extract()) on the same array.
# Prints one Markdown table. Not a test: numbers depend on the machine.
#
#   tools/bench/bench_array.sh [RAW] [ISO] [BUILD_DIR]
#       (defaults: ../shared/data/ct_head_visible_woman_512x512x234_uint16.raw, 600.5, build)
#
# Each run is a fresh python3 process (PYTHON, default /usr/bin/python3: one with numpy) that loads the raw file into an array (np.fromfile,
# from the page cache: it is read once first), then takes one route; "route s" is the wall
# time of the route alone (from the array to the mesh), "process s" that of the whole
# process (interpreter, import, loading the array). RUNS (default 3) runs of each route,
# interleaved; medians. The brick file goes to a scratch folder beside BUILD_DIR.
set -eu
raw=${1:-../shared/data/ct_head_visible_woman_512x512x234_uint16.raw}
iso=${2:-600.5}
build=${3:-build}
runs=${RUNS:-3}
py=${PYTHON:-/usr/bin/python3} # a python3 with numpy (Debian's)
scratch=$(mktemp -d "${build}/bench_array.XXXXXX")
trap 'rm -rf "$scratch"' EXIT
cat "$raw" >/dev/null
name=$(basename "$raw" .raw)
dims=$(echo "$name" | sed -E 's/.*_([0-9]+)x([0-9]+)x([0-9]+)_([a-z0-9]+)$/\3 \2 \1 \4/')
cat >"$scratch/run.py" <<'PY'
import sys, time
import numpy as np
import isoprop
route, raw, iso, z, y, x, dtype, out = sys.argv[1:]
a = np.fromfile(raw, dtype="<" + {"uint8": "u1", "uint16": "u2", "int16": "i2",
                                  "float32": "f4"}[dtype]).reshape(int(z), int(y), int(x))
t0 = time.perf_counter()
if route == "array":
    with isoprop.open_array(a) as f:
        m = f.extract(float(iso), full=True)
else:
    isoprop.brick(a, out, force=True)
    with isoprop.open(out) as f:
        m = f.extract(float(iso), full=True)
print(time.perf_counter() - t0, m.triangle_count)
PY
export PYTHONPATH="$build/python${PYTHONPATH:+:$PYTHONPATH}"
for i in $(seq "$runs"); do
    for route in array file; do
        t0=$(date +%s.%N)
        set -- $("$py" "$scratch/run.py" "$route" "$raw" "$iso" $dims "$scratch/v.ibv")
        t1=$(date +%s.%N)
        echo "$route $1 $(echo "$t1 - $t0" | bc) $2" >>"$scratch/times"
    done
done
echo "| route | route s (median) | process s (median) | triangles |"
echo "| --- | --- | --- | --- |"
# the median of column $2 of the lines of route $1
median() {
    grep "^$1 " "$scratch/times" | cut -d' ' -f"$2" | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'
}
for route in array file; do
    label="open_array + extract"
    [ "$route" = file ] && label="brick + open + extract"
    printf "| %s | %.3f | %.3f | %s |\n" "$label" "$(median $route 2)" "$(median $route 3)" \
        "$(grep "^$route " "$scratch/times" | head -1 | cut -d' ' -f4)"
done

#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# Occlusion-aware propagation against the paper's propagation (isorender --occlusion on|off)
# on the Visible Woman head at 1600x1200 (results in docs/notes/performance-notebook.md, part 6).
# Prints a Markdown table per case: medians over REPEAT interleaved runs of the time to 85 %
# and 99.5 % final pixels and to all rays, warm (isorender --warm) and fresh (a new process,
# the brick file in the page cache), with the triangles extracted by then and the overdraw
# (triangles extracted / triangles owning a pixel of the final image).
#
#   tools/bench/bench_occlusion.sh [BUILD_DIR] [WORK_DIR]
#   defaults: build, /tmp/bench_occlusion; environment: RAW (the 512x512x234 head), REPEAT (5),
#   CASES ("skin bone")
#
# Times come from isorender's --progress CSV (checkpoints at doubling ray counts, clock started
# at ip_engine_begin); "t [p]" is the first checkpoint at or past the share and the one before
# it (the share was reached between the two). Not a test: it only measures and prints.
set -eu
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-build}
work=${2:-/tmp/bench_occlusion}
raw=${RAW:-$root/../shared/data/ct_head_visible_woman_512x512x234_uint16.raw}
repeat=${REPEAT:-5}
cases=${CASES:-skin bone}
mkdir -p "$work"
[ -f "$work/head.ibv" ] || "$build/isobrick" "$raw" -o "$work/head.ibv" --quiet
for i in $(seq "$repeat"); do
    for c in $cases; do
        case $c in
        skin) args="--iso 600.5 --view -y" ;;
        bone) args="--iso 1224.5 --view -x" ;;
        esac
        for mode in warm fresh; do
            for occlusion in on off; do
                warm=""
                [ "$mode" = warm ] && warm=--warm
                # shellcheck disable=SC2086
                "$build/isorender" "$work/head.ibv" $args --size 1600x1200 --software --force \
                    --quiet $warm --occlusion "$occlusion" -o "$work/$c.png" \
                    --progress "$work/$c-$mode-$occlusion-$i.csv" \
                    --stats "$work/$c-$mode-$occlusion-$i.json"
            done
        done
    done
done
python3 - "$work" "$repeat" $cases <<'PY'
import json, statistics, sys
work, repeat, cases = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
def rows(path):
    with open(path) as f:
        next(f)
        return [[float(v) for v in line.split(",")] for line in f if line.strip()]
def point(r, pct):
    for i, row in enumerate(r):
        if row[5] >= pct:
            return row, (r[i - 1][0] if i else 0.0)
med = statistics.median
for c in cases:
    print("\n%s\n" % c)
    print("| run | 85 % (s) | triangles (K) | overdraw | 99.5 % (s) | triangles (K) | overdraw "
          "| all rays (s) | triangles (K) | visible (K) | overdraw |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for mode in ("warm", "fresh"):
        for occ in ("on", "off"):
            runs = [rows("%s/%s-%s-%s-%d.csv" % (work, c, mode, occ, i + 1)) for i in range(repeat)]
            cells = []
            for pct in (85, 99.5):
                p = [point(r, pct) for r in runs]
                cells.append("%.3f [%.3f]" % (med(x[0][0] for x in p), med(x[1] for x in p)))
                cells.append("%.0f" % (med(x[0][4] for x in p) / 1e3))
                cells.append("%.2f" % med(x[0][7] for x in p))
            last = [r[-1] for r in runs]
            cells += ["%.3f" % med(x[0] for x in last), "%.0f" % (med(x[4] for x in last) / 1e3),
                      "%.0f" % (med(x[6] for x in last) / 1e3), "%.2f" % med(x[7] for x in last)]
            print("| %s, occlusion %s | %s |" % (mode, occ, " | ".join(cells)))
    for mode in ("warm", "fresh"):
        for occ in ("on", "off"):
            t = [rows("%s/%s-%s-%s-%d.csv" % (work, c, mode, occ, i + 1))[-1][0]
                 for i in range(repeat)]
            print("%s%s, occlusion %s: all rays %.3f-%.3f s" % ("\n" if mode == "warm" and occ == "on"
                                                                 else "", mode, occ, min(t), max(t)))
PY

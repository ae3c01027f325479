#!/bin/bash
# SPDX-License-Identifier: BSD-3-Clause
# Two builds of isorender side by side on one brick file: time to 85 % and 99.5 % final pixels
# and to all rays, from a fresh process and warm (--warm), in interleaved runs (old fresh, old
# warm, new fresh, new warm, ...); prints the medians with [min-max] and the triangles
# extracted by 99.5 %. The page cache is left as it is (run once beforehand to warm it).
#
#   tools/bench/bench_compare.sh OLD_BUILD NEW_BUILD FILE.ibv ISO VIEW [RUNS] [WxH]
#
# e.g. tools/bench/bench_compare.sh /tmp/old/build build head.ibv 600.5 -y 5 1600x1200
# Uses the software rasterizer (--software); what is timed is the engine's own clock.
set -eu
if [ $# -lt 5 ]; then
    sed -n '3,10p' "$0" | sed 's/^# \{0,1\}//' >&2
    exit 2
fi
old=$1 new=$2 file=$3 iso=$4 view=$5 runs=${6:-5} size=${7:-1600x1200}
for b in "$old" "$new"; do
    [ -x "$b/isorender" ] || { echo "bench_compare: $b/isorender is missing" >&2; exit 1; }
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for i in $(seq "$runs"); do
    for v in old new; do
        bin=$old
        [ "$v" = new ] && bin=$new
        for mode in fresh warm; do
            extra=""
            [ "$mode" = warm ] && extra=--warm
            "$bin/isorender" "$file" --iso "$iso" --view "$view" --size "$size" --software \
                $extra -o "$work/$v.png" --progress "$work/$v-$mode-$i.csv" --force --quiet
        done
    done
done
python3 - "$work" "$runs" "$old" "$new" <<'PY'
import csv, statistics, sys
work, runs, builds = sys.argv[1], int(sys.argv[2]), {'old': sys.argv[3], 'new': sys.argv[4]}
def first(rows, pct, key):
    return next(float(r[key]) for r in rows if float(r['final_pixel_pct']) >= pct)
def cell(v):
    return '%.3f [%.3f-%.3f]' % (statistics.median(v), min(v), max(v))
print('| build | run | 85 % (s) | 99.5 % (s) | all rays (s) | triangles by 99.5 % |')
print('| --- | --- | ---: | ---: | ---: | ---: |')
for v in ('old', 'new'):
    for mode in ('fresh', 'warm'):
        rows = [list(csv.DictReader(open('%s/%s-%s-%d.csv' % (work, v, mode, i))))
                for i in range(1, runs + 1)]
        print('| %s (%s) | %s | %s | %s | %s | %d |' % (
            v, builds[v], mode, cell([first(r, 85, 'time_s') for r in rows]),
            cell([first(r, 99.5, 'time_s') for r in rows]),
            cell([float(r[-1]['time_s']) for r in rows]),
            statistics.median([first(r, 99.5, 'triangles') for r in rows])))
PY

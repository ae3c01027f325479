#!/bin/bash
# SPDX-License-Identifier: BSD-3-Clause
# The floor under the 99.5 % targets, beside the engine and Flying Edges in one run: per round,
# VTK's Flying Edges (first Update() in its process and again), isorender to 99.5 % final
# pixels from a fresh process and warm (--warm), and bench_floor (marching cubes over only the
# cells that own a pixel of the final image: its run 0 in a fresh process, and warm; then the
# same over the cells the engine extracts by the warm run's 99.5 % checkpoint, the walked
# floor; and those cells through the engine's own extraction with the coverage, warm), for
# the skin (600.5, -y) and the bone (1224.5, -x) at 1600x1200. Rounds interleave; prints the
# medians with [min-max]. The page cache is left as it is (warm: run once beforehand).
#
#   tools/bench/bench_floor.sh BUILD FILE.ibv RAW [RUNS] [THREADS]
#
# e.g. tools/bench/bench_floor.sh build /tmp/head.ibv ../shared/data/ct_head_visible_woman_512x512x234_uint16.raw 5
# RAW is the volume FILE.ibv was bricked from (bench_vtk.py reads it). THREADS (default 2) is
# the engine's and the floor's; VTK uses every core. Needs python3-vtk9, as bench_engine.sh.
set -eu
if [ $# -lt 3 ]; then
    sed -n '3,15p' "$0" | sed 's/^# \{0,1\}//' >&2
    exit 2
fi
build=$1 file=$2 raw=$3 runs=${4:-5} threads=${5:-2}
root=$(cd "$(dirname "$0")/../.." && pwd)
for p in isorender bench_floor; do
    [ -x "$build/$p" ] || { echo "bench_floor: $build/$p is missing" >&2; exit 1; }
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
surfaces="skin:600.5:-y bone:1224.5:-x"
for i in $(seq "$runs"); do
    /usr/bin/python3 "$root/tools/bench/bench_vtk.py" extract "$raw" 600.5 1224.5 \
        >"$work/vtk-$i.jsonl"
    for s in $surfaces; do
        IFS=: read -r name iso view <<<"$s"
        for mode in fresh warm; do
            extra=""
            [ "$mode" = warm ] && extra=--warm
            "$build/isorender" "$file" --iso "$iso" --view "$view" --size 1600x1200 --software \
                --threads "$threads" $extra -o "$work/$name.png" \
                --progress "$work/$name-$mode-$i.csv" --force --quiet
        done
        "$build/bench_floor" "$file" "$iso" "$view" 1600x1200 "$threads" 20 >"$work/$name-floor-$i.txt"
        rays=$(awk -F, 'NR > 1 && $6 >= 99.5 { print $2; exit }' "$work/$name-warm-$i.csv")
        "$build/bench_floor" "$file" "$iso" "$view" 1600x1200 "$threads" 20 "$rays" \
            >"$work/$name-walked-$i.txt"
        "$build/bench_floor" "$file" "$iso" "$view" 1600x1200 "$threads" 20 "$rays" cover \
            >"$work/$name-cover-$i.txt"
    done
done
python3 - "$work" "$runs" "$threads" <<'PY'
import csv, json, re, statistics, sys
work, runs, threads = sys.argv[1], int(sys.argv[2]), sys.argv[3]
def cell(v):
    return '%.4f [%.4f-%.4f]' % (statistics.median(v), min(v), max(v))
def at(path, pct, key='time_s'):
    rows = list(csv.DictReader(open(path)))
    return next(float(r[key]) for r in rows if float(r['final_pixel_pct']) >= pct)
print('| %s threads | Flying Edges first / again | 99.5 %% fresh | 99.5 %% warm | floor fresh '
      '(run 0) | floor warm | floor warm / FE again | walked floor fresh | walked floor warm | '
      'walked warm / FE again | walked + coverage warm | cells owning a pixel | cells extracted '
      'by 99.5 %% |' % threads)
print('| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |')
def floor(name, kind):
    r0, rw = [], []
    for i in range(1, runs + 1):
        text = open('%s/%s-%s-%d.txt' % (work, name, kind, i)).read()
        r0.append(float(re.search(r'run 0: ([0-9.]+) s', text).group(1)))
        rw.append(float(re.search(r'median ([0-9.]+) s', text).group(1)))
    return r0, rw
for name, iso in (('skin', 600.5), ('bone', 1224.5)):
    fe = {1: [], 2: []}
    for i in range(1, runs + 1):
        for line in open('%s/vtk-%d.jsonl' % (work, i)):
            j = json.loads(line)
            if j['filter'] == 'flying_edges' and j['iso'] == iso:
                fe[j['call']].append(j['update_s'])
    fresh = [at('%s/%s-fresh-%d.csv' % (work, name, i), 99.5) for i in range(1, runs + 1)]
    warm = [at('%s/%s-warm-%d.csv' % (work, name, i), 99.5) for i in range(1, runs + 1)]
    f0, fw = floor(name, 'floor')
    w0, ww = floor(name, 'walked')
    c0, cw = floor(name, 'cover')
    cells = re.search(r'from (\d+) cells', open('%s/%s-floor-1.txt' % (work, name)).read()).group(1)
    extracted = statistics.median(
        [at('%s/%s-warm-%d.csv' % (work, name, i), 99.5, 'cells') for i in range(1, runs + 1)])
    fe2 = statistics.median(fe[2])
    print('| %s | %.4f / %.4f | %s | %s | %s | %s | %.2f | %s | %s | %.2f | %s | %s | %d |' % (
        name, statistics.median(fe[1]), fe2, cell(fresh), cell(warm), cell(f0), cell(fw),
        statistics.median(fw) / fe2, cell(w0), cell(ww), statistics.median(ww) / fe2, cell(cw),
        cells, extracted))
PY

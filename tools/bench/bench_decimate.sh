#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# What --decimate and --cap add to a full extraction written as a mesh: the Visible Woman
# head's skin (isorender --iso 600.5 --full --mesh OUT.ply, welded PLY, software rasterizer,
# 320x240) as it is, with --decimate 0.1 and with --cap. RUNS (3) interleaved rounds of fresh
# processes, a warm page cache; prints the median wall time of each (/usr/bin/time), its
# ratio to the plain run, and the mesh file's triangles and the error --decimate reports (its
# --stats). Not a test.
#
#   tools/bench/bench_decimate.sh [BUILD_DIR]
#
# Bricks ../shared/data/ct_head_visible_woman_512x512x234_uint16.raw into a temporary folder
# first. Environment: RUNS (3), THREADS (0: every core).
set -eu
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-build}
case $build in /*) ;; *) build=$root/$build ;; esac
runs=${RUNS:-3}
threads=${THREADS:-0}
head=$root/../shared/data/ct_head_visible_woman_512x512x234_uint16.raw
for p in isobrick isorender; do
    [ -x "$build/$p" ] || { echo "bench_decimate: $build/$p is missing" >&2; exit 1; }
done
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$build/isobrick" "$head" -o "$tmp/head.ibv" --quiet
echo "# bench_decimate $(date -u '+%Y-%m-%d %H:%M UTC'): head 512x512x234 uint16, iso 600.5, --full --mesh"
echo "machine: $(nproc) cores, $(awk '/MemTotal/ { printf "%.1f GiB RAM", $2 / 1048576 }' /proc/meminfo)"
echo
set -- plain "" decimate "--decimate 0.1" cap "--cap"
names="plain decimate cap"
one() { # one NAME OPTIONS: a fresh process; appends its wall seconds to $tmp/NAME.times
    /usr/bin/time -f %e -o "$tmp/$1.t" "$build/isorender" "$tmp/head.ibv" --iso 600.5 --full \
        --threads "$threads" --size 320x240 --software -o "$tmp/$1.png" --mesh "$tmp/$1.ply" \
        --stats "$tmp/$1.json" --force --quiet $2
    cat "$tmp/$1.t" >>"$tmp/$1.times"
}
"$build/isorender" "$tmp/head.ibv" --iso 600.5 --full --size 32x24 --software -o "$tmp/w.png" \
    --force --quiet # the page cache warm
i=0
while [ "$i" -lt "$runs" ]; do
    one plain ""
    one decimate "--decimate 0.1"
    one cap "--cap"
    i=$((i + 1))
done
median() { sort -n "$1" | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
base=$(median "$tmp/plain.times")
faces() { grep -a -m1 '^element face' "$1" | awk '{ print $3 }'; }
echo "| run | median wall s ($runs runs) | vs plain | mesh triangles | --decimate error |"
echo "| --- | ---: | ---: | ---: | ---: |"
for n in $names; do
    m=$(median "$tmp/$n.times")
    err=$(python3 -c 'import json, sys; d = json.load(open(sys.argv[1])).get("decimate"); print("%.4g" % d["error"] if d else "-")' "$tmp/$n.json")
    awk -v n="$n" -v m="$m" -v b="$base" -v f="$(faces "$tmp/$n.ply")" -v e="$err" \
        'BEGIN { printf "| %s | %.2f | %+.0f %% | %d | %s |\n", n, m, 100 * (m - b) / b, f, e }'
done

#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# The viewer on volumes far larger than its cache: isoview driven by a script under a virtual X
# server, on the Visible Woman head upsampled 4x and 6x (the brick files tools/bench/bench_big.sh
# makes in DIR: x4.ibv, x6.ibv), cold (page cache dropped first) and warm. Prints a Markdown table
# (results in docs/isoview.md, "Viewing a volume far larger than the cache"):
#
#   per view (the median over the orbit's 25 views, the opening one and 24 steps): time to the first frame after the change,
#   to 85 % and 99.5 % of the final pixels on the screen, to complete refinement; the mean
#   time per view to complete (the orbit's wall time / 24); frames a second while refining and
#   while dragging; peak RSS; against the targets.
#
#   tools/bench/bench_view.sh DIR [BUILD_DIR]
#
# The orbit: 24 steps, each `orbit 15 0` (a full turn in all), `zoom 1.08` in the first 12 and
# `zoom 1/1.08` in the last 12 (in to 2.5x and back out), then `wait done`; the skin (600.5) in a
# 1280x960 window seen from -y. The drag: `drag 90 0 3` (a quarter turn over 3 seconds, a step
# every frame, as a mouse drag), warm. Then (LONG=1, the default) 100 views of an orbit on the
# first volume, its resident size sampled every second. Environment: SCALES ("4 6"), CACHE_MB
# ("256 512": per scale), RENDERER (auto), REPEAT (1: runs of each kind, medians reported), SIZE
# (1280x960), LONG (1).
# Each isoview writes --stats, read with python3. Not a test.
set -eu
if [ $# -lt 1 ]; then
    sed -n '3,22p' "$0" | sed 's/^# \{0,1\}//' >&2
    exit 2
fi
root=$(cd "$(dirname "$0")/../.." && pwd)
dir=$(cd "$1" && pwd)
build=${2:-build}
case $build in /*) ;; *) build=$root/$build ;; esac
scales=${SCALES:-4 6}
caches=${CACHE_MB:-256 512}
renderer=${RENDERER:-auto}
repeat=${REPEAT:-1}
size=${SIZE:-1280x960}
[ -x "$build/isoview" ] || { echo "bench_view: $build/isoview is missing" >&2; exit 1; }
command -v xvfb-run >/dev/null || { echo "bench_view: xvfb-run is missing (apt-get install xvfb)" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

{
    for i in $(seq 24); do
        echo "orbit 15 0"
        if [ "$i" -le 12 ]; then echo "zoom 1.08"; else echo "zoom 0.925925925925926"; fi
        echo "wait done"
    done
    echo quit
} >"$tmp/orbit.txt"
printf 'wait done\ndrag 90 0 3\nwait done\nquit\n' >"$tmp/drag.txt"

cold_note="page cache dropped before each cold run"
drop_caches() {
    sync
    echo 3 2>/dev/null >/proc/sys/vm/drop_caches ||
        cold_note="page cache NOT dropped (not allowed here): cold runs are only fresh processes"
}

# run NAME FILE CACHE_MB SCRIPT: one isoview under xvfb-run, its statistics in $tmp/NAME.json
run() {
    xvfb-run -a -s "-screen 0 1600x1200x24" "$build/isoview" "$2" --iso 600.5 --size "$size" \
        --cache-mb "$3" --renderer "$renderer" --script "$4" --stats "$tmp/$1.json" --force \
        --quiet --exit-after 900
}

# row LABEL TARGET_S TARGET_MIB JSON...: one table row, the medians of the runs' figures
row() {
    python3 - "$@" <<'EOF'
import json, statistics, sys
label, target_s, target_mib = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
runs = [json.load(open(p)) for p in sys.argv[4:]]
def med(values):
    values = [v for v in values if v is not None]
    return statistics.median(values) if values else float("nan")
def per_run(d):
    views = [v for v in d["views"] if not v["moving"]]
    done = [v for v in views if v["complete_s"] is not None]
    wall = d["fps"]["seconds"]
    refining = sum(v["view_frames"] for v in done) / max(1e-9, sum(v["complete_s"] for v in done))
    return {
        "first": d["views_median"]["first_frame_s"], "p85": d["views_median"]["final_85_s"],
        "p995": d["views_median"]["final_995_s"], "complete": d["views_median"]["complete_s"],
        "mean": wall / max(1, len(views)), "fps": refining,
        "rss": d["memory"]["rss_peak_bytes"] / 1048576, "renderer": d["renderer"],
        "mesh": d["memory"]["engine_mesh_bytes"] / 1048576,
        "misses": d["cache"]["misses"],
    }
rows = [per_run(d) for d in runs]
m = {k: med([r[k] for r in rows]) for k in rows[0] if k != "renderer"}
ok = "met" if m["mean"] <= target_s and m["rss"] <= target_mib else "missed"
print(f"| {label} | {rows[0]['renderer']} | {m['first']:.3f} | {m['p85']:.3f} | {m['p995']:.3f} | "
      f"{m['complete']:.3f} | **{m['mean']:.3f}** | {m['fps']:.1f} | {m['rss']:.0f} | "
      f"{m['mesh']:.0f} | {m['misses']:.0f} | <= {target_s} s, <= {target_mib:.0f} MiB: {ok} |")
EOF
}

drag_row() {
    python3 - "$@" <<'EOF'
import json, statistics, sys
runs = [json.load(open(p)) for p in sys.argv[2:]]
fps = statistics.median(d["fps_moving"] for d in runs)
first = statistics.median(min(v["first_frame_s"] for v in d["views"] if v["moving"] and v["first_frame_s"] is not None) for d in runs)
moving = statistics.median(sum(1 for v in d["views"] if v["moving"]) for d in runs)
print(f"| {sys.argv[1]} | {fps:.1f} | {moving:.0f} | {first:.3f} |")
EOF
}

echo "# bench_view $(date -u '+%Y-%m-%d %H:%M UTC')"
echo
echo "machine: $(nproc) cores, $(awk '/MemTotal/ { printf "%.1f GiB RAM", $2 / 1048576 }' /proc/meminfo);" \
    "isoview: $build; window $size; renderer $renderer"
echo
echo "| volume, cache | renderer | first frame (s) | 85 % (s) | 99.5 % (s) | complete (s) | mean per view (s) | fps refining | peak RSS (MiB) | engine mesh (MiB) | cache misses | target |"
echo "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |"
set -- $caches
for k in $scales; do
    cache=$1
    [ $# -gt 1 ] && shift
    ibv=$dir/x$k.ibv
    [ -f "$ibv" ] || { echo "bench_view: $ibv is missing: run tools/bench/bench_big.sh $dir first" >&2; exit 1; }
    case $k in 4) ts=1.0 tm=640 ;; 6) ts=1.5 tm=1024 ;; *) ts=1.5 tm=1024 ;; esac
    cold="" warm=""
    for r in $(seq "$repeat"); do
        drop_caches
        run "x$k-cold-$r" "$ibv" "$cache" "$tmp/orbit.txt"
        cold="$cold $tmp/x$k-cold-$r.json"
        run "x$k-warm-$r" "$ibv" "$cache" "$tmp/orbit.txt"
        warm="$warm $tmp/x$k-warm-$r.json"
    done
    # shellcheck disable=SC2086 # lists of files
    row "x$k, $cache MiB, cold" "$ts" "$tm" $cold
    # shellcheck disable=SC2086
    row "x$k, $cache MiB, warm" "$ts" "$tm" $warm
done
echo
echo "Dragging (\`drag 90 0 3\` after the first view, warm): frames a second while the camera moves," \
    "the passes it started and the median time to the first frame of each."
echo
echo "| volume | fps dragging | passes | first frame (s) |"
echo "| --- | ---: | ---: | ---: |"
set -- $caches
for k in $scales; do
    cache=$1
    [ $# -gt 1 ] && shift
    drag=""
    for r in $(seq "$repeat"); do
        run "x$k-drag-$r" "$dir/x$k.ibv" "$cache" "$tmp/drag.txt"
        drag="$drag $tmp/x$k-drag-$r.json"
    done
    # shellcheck disable=SC2086
    drag_row "x$k" $drag
done
# Memory over a long orbit: 100 steps of `orbit 15 0` (four turns and more), the first scale's
# volume and cache, the process's resident size sampled every second from /proc.
if [ "${LONG:-1}" = 1 ]; then
    set -- $scales
    k=$1
    set -- $caches
    cache=$1
    { for i in $(seq 100); do printf 'orbit 15 0\nwait done\n'; done; echo quit; } >"$tmp/long.txt"
    xvfb-run -a -s "-screen 0 1600x1200x24" "$build/isoview" "$dir/x$k.ibv" --iso 600.5 \
        --size "$size" --cache-mb "$cache" --renderer "$renderer" --script "$tmp/long.txt" \
        --stats "$tmp/long.json" --force --quiet --exit-after 1800 &
    runner=$!
    : >"$tmp/rss.txt"
    while kill -0 "$runner" 2>/dev/null; do
        pid=$(pgrep -n -f "isoview $dir/x$k.ibv" || true)
        [ -n "$pid" ] && awk '/VmRSS/ { print $2 }' "/proc/$pid/status" 2>/dev/null >>"$tmp/rss.txt"
        sleep 1
    done
    wait "$runner" || true
    echo
    echo "Memory over 100 views (x$k, \`--cache-mb $cache\`, \`orbit 15 0\` + \`wait done\` each):" \
        "resident size (MiB) by tenths of the run, and the statistics' peak and breakdown at the end."
    echo
    python3 - "$tmp/rss.txt" "$tmp/long.json" <<'EOF'
import json, sys
rss = [int(x) / 1024 for x in open(sys.argv[1]) if x.strip()]
d = json.load(open(sys.argv[2]))
m = d["memory"]
tenths = [max(rss[len(rss) * i // 10:max(len(rss) * (i + 1) // 10, len(rss) * i // 10 + 1)]) for i in range(10)] if rss else []
print("| tenth | " + " | ".join(str(i + 1) for i in range(len(tenths))) + " |")
print("| --- |" + " ---: |" * len(tenths))
print("| peak RSS in it (MiB) | " + " | ".join(f"{v:.0f}" for v in tenths) + " |")
print()
print("| at the end (MiB) | cache (peak) | summaries | engine mesh | workers | visited | coverage | canvas | GPU mesh | RSS (peak) |")
print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
f = lambda k: m[k] / 1048576
print(f"| {len(d['views'])} views | {f('cache_bytes'):.0f} ({f('cache_peak_bytes'):.0f}) | {f('summaries_bytes'):.0f} | "
      f"{f('engine_mesh_bytes'):.0f} | {f('engine_workers_bytes'):.0f} | {f('visited_bytes'):.0f} | "
      f"{f('coverage_bytes'):.0f} | {f('canvas_bytes'):.0f} | {f('gpu_mesh_bytes'):.0f} | "
      f"{f('rss_bytes'):.0f} ({f('rss_peak_bytes'):.0f}) |")
EOF
fi
echo
echo "($cold_note. Mean per view: the wall time from the first frame to the last over the" \
    "25 views, the opening view and the 24 steps; the medians are over the same 25.)"

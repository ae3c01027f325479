#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# Out of core for real: the Visible Woman head upsampled 4x (2048x2048x936 uint16, 7.3 GiB)
# and 6x (3072x3072x1404 uint16, 24.7 GiB, more than this machine's RAM), each bricked once
# with a capped working memory and viewed cold with a 512 MiB brick cache. Prints Markdown
# tables (results in docs/benchmarks.md):
#
#   1. bricking: seconds, MB/s of raw input, peak RSS against --mem-mb, compression ratio,
#      beside `lz4 -1` on one core over the same raw file (both from a cold page cache);
#   2. cold views: time to the first image (the first ray's checkpoint), 85 % and 99.5 % final
#      pixels, all rays, peak RSS, bricks touched, bytes read from the disk, per volume;
#   3. the targets.
#
#   tools/bench/bench_big.sh DIR [BUILD_DIR]
#
# DIR holds the big files: each raw volume and brick file is made there once (isogen
# --upsample K, isobrick --mem-mb) when missing, and reused afterwards; the script removes
# nothing it did not make (only its own temporary files). DIR must not be inside the
# repository. BUILD_DIR defaults to `build`.
# Environment: REPEAT (cold views per volume, median reported: 3), SCALES ("4 6"), MEM_MB
# (isobrick's --mem-mb: 1024), CACHE_MB (isorender's --cache-mb: 512), REBRICK (1: brick again
# even if the brick file is there, to measure bricking), LZ4 (1: time `lz4 -1` too).
#
# Cold means `sync; echo 3 > /proc/sys/vm/drop_caches` before each run (root only; without
# it the runs are only fresh processes, and the output says so). Views use the software
# rasterizer (--software), so that no GPU driver is read from disk or competes for the cores;
# engine times come from isorender's --progress CSV (its clock starts at ip_engine_begin),
# process figures from /usr/bin/time (elapsed, peak RSS, blocks read: the getrusage count of
# reads that went to the device, which includes the program's own libraries). Not a test.
set -eu
if [ $# -lt 1 ]; then
    sed -n '3,28p' "$0" | sed 's/^# \{0,1\}//' >&2
    exit 2
fi
root=$(cd "$(dirname "$0")/../.." && pwd)
dir=$1
build=${2:-build}
case $build in /*) ;; *) build=$root/$build ;; esac
repeat=${REPEAT:-3}
scales=${SCALES:-4 6}
mem_mb=${MEM_MB:-1024}
cache_mb=${CACHE_MB:-512}
rebrick=${REBRICK:-0}
do_lz4=${LZ4:-1}
raw=$root/../shared/data/ct_head_visible_woman_512x512x234_uint16.raw
py=/usr/bin/python3
[ -f "$raw" ] || { echo "bench_big: $raw is missing" >&2; exit 1; }
for p in isobrick isorender isogen; do
    [ -x "$build/$p" ] || { echo "bench_big: $build/$p is missing: run tools/setup.sh build" >&2; exit 1; }
done
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)
case $dir/ in "$root"/*) echo "bench_big: $dir is inside the repository; name a folder outside it" >&2; exit 2 ;; esac
if [ "$do_lz4" = 1 ] && ! command -v lz4 >/dev/null; then
    if [ "$(id -u)" = 0 ]; then
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq lz4 >/dev/null 2>&1 ||
            { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq lz4 >/dev/null; }
    else
        echo "bench_big: lz4 is missing (apt-get install lz4), or run with LZ4=0" >&2
        exit 1
    fi
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

cold_note="page cache dropped before each cold run"
drop_caches() {
    sync
    echo 3 2>/dev/null >/proc/sys/vm/drop_caches ||
        cold_note="page cache NOT dropped (not allowed here): cold runs are only fresh processes"
}
mib() { awk -v k="$1" 'BEGIN { printf "%.0f", k / 1024 }'; }

echo "# bench_big $(date -u '+%Y-%m-%d %H:%M UTC')"
echo
echo "machine: $(nproc) cores, $(awk '/MemTotal/ { printf "%.1f GiB RAM", $2 / 1048576 }' /proc/meminfo)," \
    "disk of $dir: $(df -h "$dir" | awk 'NR == 2 { print $1 ", " $4 " free" }'), read-ahead" \
    "$(cat /sys/block/"$(basename "$(df "$dir" | awk 'NR == 2 { print $1 }')")"/queue/read_ahead_kb 2>/dev/null || echo '?') KiB;" \
    "isoprop: $build"
echo

# --- the volumes, made once -------------------------------------------------------------------
for k in $scales; do
    x=$((512 * k)) z=$((234 * k))
    big=$dir/ct_head_visible_woman_x${k}_${x}x${x}x${z}_uint16.raw
    if [ ! -f "$big" ]; then
        echo "making $big (isogen --upsample $k)" >&2
        "$build/isogen" --upsample "$k" "$raw" -o "$dir/" --quiet >/dev/null
    fi
done

# --- 1. bricking --------------------------------------------------------------------------------
echo "## Bricking (--mem-mb $mem_mb, cold page cache)"
echo
echo "| volume | raw size | isobrick (s) | MB/s | peak RSS (MiB) | ratio | lz4 -1, one core (s) | MB/s | isobrick / lz4 -1 |"
echo "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
for k in $scales; do
    x=$((512 * k)) z=$((234 * k))
    big=$dir/ct_head_visible_woman_x${k}_${x}x${x}x${z}_uint16.raw
    ibv=$dir/x$k.ibv
    log=$dir/x$k.brick.txt
    bytes=$(stat -c %s "$big")
    if [ "$rebrick" = 1 ] || [ ! -f "$ibv" ] || [ ! -f "$log" ] || [ "$build/isobrick" -nt "$ibv" ]; then
        drop_caches
        if ! /usr/bin/time -f "%e %M" -o "$log" "$build/isobrick" "$big" -o "$ibv" \
            --mem-mb "$mem_mb" --force --quiet 2>"$tmp/brick.err"; then
            echo "| x$k | $(awk -v b="$bytes" 'BEGIN { printf "%.1f GiB", b / 1073741824 }') | failed: $(grep -v '^Command exited' "$tmp/brick.err" | head -1) | | | | | | |"
            rm -f "$log"
            continue
        fi
        lz=""
        if [ "$do_lz4" = 1 ]; then
            drop_caches
            lz=$( { /usr/bin/time -f "%e" lz4 -1 -q -c "$big" >/dev/null; } 2>&1 | tail -1)
        fi
        echo "$lz" >>"$log"
    fi
    set -- $(head -1 "$log")
    secs=$1 rss=$2
    lz=$(sed -n 2p "$log")
    ratio=$(awk -v r="$bytes" -v c="$(stat -c %s "$ibv")" 'BEGIN { printf "%.2f", r / c }')
    mbs=$(awk -v b="$bytes" -v s="$secs" 'BEGIN { printf "%.0f", b / s / 1e6 }')
    if [ -n "$lz" ]; then
        lzs=$(awk -v b="$bytes" -v s="$lz" 'BEGIN { printf "%.0f", b / s / 1e6 }')
        rel=$(awk -v a="$secs" -v b="$lz" 'BEGIN { printf "%.2fx", b / a }')
    else
        lz="-" lzs="-" rel="-"
    fi
    echo "| x$k | $(awk -v b="$bytes" 'BEGIN { printf "%.1f GiB", b / 1073741824 }') | $secs | $mbs | $(mib "$rss") | $ratio | $lz | $lzs | $rel |"
    echo "$k $rss" >>"$tmp/brick_rss"
done
echo
echo "(\`isobrick / lz4 -1\` > 1 means isobrick is faster. A brick file is reused while it is newer" \
    "than isobrick; its row then repeats the measurement logged when it was made.)"
echo

# --- 2. cold views ---------------------------------------------------------------------------
echo "## Cold views (--cache-mb $cache_mb, exact: --pixel-error 1, skin 600.5, view -y, 1600x1200, software rasterizer)"
echo
viewed=""
for k in $scales; do
    ibv=$dir/x$k.ibv
    [ -f "$dir/x$k.brick.txt" ] || continue
    viewed="$viewed $k"
    i=1
    while [ $i -le "$repeat" ]; do
        drop_caches
        /usr/bin/time -f "%e %M %I" -o "$tmp/x$k-$i.time" "$build/isorender" "$ibv" --iso 600.5 \
            --view -y --size 1600x1200 --cache-mb "$cache_mb" --software --force --quiet \
            -o "$tmp/x$k.png" --progress "$tmp/x$k-$i.csv" --stats "$tmp/x$k-$i.json"
        i=$((i + 1))
    done
done
echo "$cold_note."
echo
$py - "$tmp" "$repeat" "$viewed" <<'PY'
import json, statistics, sys
tmp, repeat, scales = sys.argv[1], int(sys.argv[2]), sys.argv[3].split()
def rows(p):
    with open(p) as f:
        next(f)
        return [[float(v) for v in l.split(",")] for l in f if l.strip()]
def first(r, pct):
    return next((x[0] for x in r if x[5] >= pct), float("nan"))
def cell(v, fmt="%.3f"):
    return (fmt + " [" + fmt + "-" + fmt + "]") % (statistics.median(v), min(v), max(v))
print("| volume | first image (s) | 85 % (s) | 99.5 % (s) | all rays (s) | process (s) | peak RSS (MiB) | bricks touched | read from disk (MiB) | engine waited on bricks: decode (s) |")
print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
out = {}
for k in scales:
    runs = range(1, repeat + 1)
    r = [rows("%s/x%s-%d.csv" % (tmp, k, i)) for i in runs]
    j = [json.load(open("%s/x%s-%d.json" % (tmp, k, i))) for i in runs]
    t = [open("%s/x%s-%d.time" % (tmp, k, i)).read().split() for i in runs]
    c = [x["cache"] for x in j]
    p995 = [first(x, 99.5) for x in r]
    rss = [float(x[1]) / 1024 for x in t]
    out[k] = (statistics.median(p995), statistics.median(rss))
    print("| x%s | %s | %s | %s | %s | %s | %s | %d of %d | %s | %s |" % (
        k, cell([x[0][0] for x in r]), cell([first(x, 85) for x in r]), cell(p995),
        cell([x[-1][0] for x in r]), cell([float(x[0]) for x in t], "%.2f"),
        cell(rss, "%.0f"), c[0]["bricks_touched"], c[0]["bricks_total"],
        cell([float(x[2]) * 512 / 1048576 for x in t], "%.0f"),
        cell([x["decode_seconds"] for x in c])))
with open(tmp + "/views", "w") as f:
    for k, (t, m) in out.items():
        f.write("%s %f %f\n" % (k, t, m))
PY
echo
echo "(medians [min-max] of $repeat runs; first image: the checkpoint after the first ray; read from" \
    "disk: getrusage's blocks read by the process, libraries included; decode: the cache's" \
    "decode_seconds, summed over threads.)"
echo

# --- 3. targets -------------------------------------------------------------------------------
echo "## Targets"
echo
echo "| target | measured | bound | result |"
echo "| --- | ---: | ---: | --- |"
verdict() { awk -v m="$1" -v b="$2" 'BEGIN { print (m <= b ? "**met**" : sprintf("**missed** (%.2fx the bound)", m / b)) }'; }
while read -r k t m; do
    case $k in
    4) tb=1.0 rb=0.7 ;;
    6) tb=1.5 rb=0.8 ;;
    *) continue ;;
    esac
    echo "| x$k cold, 99.5 % final pixels <= $tb s | $(printf %.3f "$t") s | $tb s | $(verdict "$t" "$tb") |"
    g=$(awk -v m="$m" 'BEGIN { printf "%.3f", m / 1024 }')
    echo "| x$k cold, peak RSS <= $rb GiB | $g GiB | $rb GiB | $(verdict "$g" "$rb") |"
done <"$tmp/views"
while read -r k rss; do
    [ "$k" = 6 ] || continue
    g=$(awk -v m="$rss" 'BEGIN { printf "%.3f", m / 1048576 }')
    echo "| x6 bricking with --mem-mb 1024: peak RSS <= 1.2 GiB | $g GiB | 1.2 GiB | $(verdict "$g" 1.2) |"
done <"$tmp/brick_rss"

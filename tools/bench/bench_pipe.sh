#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# A volume larger than the free disk, bricked from a pipe: the head upsampled SCALE times (8:
# 4096x4096x1872 uint16, 62.8 GB) by isogen on standard output, bricked by isobrick from
# standard input with --mem-mb MEM_MB (1536: a layer of 33 planes of 4096x4096 uint16 needs
# 1476 MiB, so 512 is refused), so that the raw volume never touches the disk; then
# viewed once from a cold page cache (isorender --iso 600.5, view -y, 1600x1200, software
# rasterizer, --cache-mb 512). Prints the bricking throughput (MB/s of raw bytes), the brick
# file's size, the peak RSS of both processes (/usr/bin/time -v), and the cold view's time to
# 99.5 % of the final pixels and its peak RSS. Not a test.
#
#   tools/bench/bench_pipe.sh OUT.ibv [BUILD_DIR]
#
# OUT.ibv (outside the repository) is replaced. Cold means `sync; echo 3 >
# /proc/sys/vm/drop_caches` before the view (root only; otherwise the output says so).
# Environment: SCALE (8), MEM_MB (1536), CACHE_MB (512).
set -eu
if [ $# -lt 1 ]; then
    sed -n '3,16p' "$0" | sed 's/^# \{0,1\}//' >&2
    exit 2
fi
root=$(cd "$(dirname "$0")/../.." && pwd)
out=$1
build=${2:-build}
case $build in /*) ;; *) build=$root/$build ;; esac
scale=${SCALE:-8}
mem_mb=${MEM_MB:-1536}
cache_mb=${CACHE_MB:-512}
head=$root/../shared/data/ct_head_visible_woman_512x512x234_uint16.raw
for p in isobrick isogen isorender; do
    [ -x "$build/$p" ] || { echo "bench_pipe: $build/$p is missing" >&2; exit 1; }
done
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
x=$((512 * scale)) z=$((234 * scale))
bytes=$((x * x * z * 2))
echo "# bench_pipe $(date -u '+%Y-%m-%d %H:%M UTC'): head x$scale, ${x}x${x}x${z} uint16, $bytes bytes"
echo "machine: $(nproc) cores, $(awk '/MemTotal/ { printf "%.1f GiB RAM", $2 / 1048576 }' /proc/meminfo);" \
    "free on $(dirname "$out"): $(df -h "$(dirname "$out")" | awk 'NR == 2 { print $4 }')"
echo
start=$(date +%s.%N)
/usr/bin/time -v -o "$tmp/gen.time" "$build/isogen" --upsample "$scale" "$head" -o - --quiet |
    /usr/bin/time -v -o "$tmp/brick.time" "$build/isobrick" - --dims "${x}x${x}x${z}" \
        --type uint16 -o "$out" --mem-mb "$mem_mb" --force >"$tmp/brick.out"
end=$(date +%s.%N)
kib() { awk -F': ' '/Maximum resident set size/ { print $2 }' "$1"; }
secs=$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.1f", b - a }')
size=$(stat -c %s "$out")
echo "| bricking from the pipe | seconds | MB/s of raw bytes | brick file | ratio | isogen peak RSS | isobrick peak RSS |"
echo "| --- | ---: | ---: | ---: | ---: | ---: | ---: |"
awk -v s="$secs" -v b="$bytes" -v f="$size" -v g="$(kib "$tmp/gen.time")" \
    -v i="$(kib "$tmp/brick.time")" -v m="$mem_mb" 'BEGIN {
    printf "| --mem-mb %d | %.1f | %.0f | %.2f GiB (%.0f bytes) | %.2f | %.0f MiB | %.0f MiB |\n",
        m, s, b / s / 1e6, f / 1073741824, f, b / f, g / 1024, i / 1024 }'
echo
sed 's/^/    /' "$tmp/brick.out"
echo
note="page cache dropped"
sync
echo 3 2>/dev/null >/proc/sys/vm/drop_caches || note="page cache NOT dropped (not allowed here)"
/usr/bin/time -v -o "$tmp/view.time" "$build/isorender" "$out" --iso 600.5 --view -y \
    --size 1600x1200 --cache-mb "$cache_mb" --software --force --quiet -o "$tmp/view.png" \
    --progress "$tmp/view.csv" --stats "$tmp/view.json"
p995=$(awk -F, 'NR > 1 && $6 >= 99.5 { print $1; exit }' "$tmp/view.csv")
last=$(tail -1 "$tmp/view.csv" | cut -d, -f1)
echo "| cold view ($note) | 99.5 % of final pixels (s) | all rays (s) | peak RSS |"
echo "| --- | ---: | ---: | ---: |"
awk -v p="$p995" -v l="$last" -v r="$(kib "$tmp/view.time")" -v c="$cache_mb" 'BEGIN {
    printf "| --cache-mb %d | %.2f | %.2f | %.0f MiB |\n", c, p, l, r / 1024 }'

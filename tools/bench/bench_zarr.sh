#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# Bricking from Zarr against bricking from raw: the same 16-bit volume (the Visible Woman head
# of the data folder, enlarged K times with isogen --upsample; K = 1 keeps it) as a raw file and
# as a Zarr v2 array (blosc lz4, byte shuffle, 64^3 chunks, written by tests/helpers/make_zarr),
# each bricked RUNS times (default 3) with the default threads and --mem-mb MEM_MB (default
# 2048); prints the median wall time, the ratio, the peak RSS and the working memory planned.
# Not a test: numbers depend on the machine.
#
#   tools/bench/bench_zarr.sh [K] [DATA_DIR] [BUILD_DIR]   (defaults: 2, ../shared/data, build)
set -eu
k=${1:-2}
data=${2:-../shared/data}
build=${3:-build}
runs=${RUNS:-3}
mem_mb=${MEM_MB:-2048}
head=$data/ct_head_visible_woman_512x512x234_uint16.raw
[ -f "$head" ] || { echo "bench_zarr: $head not found" >&2; exit 77; }
work=$(mktemp -d "${TMPDIR:-/tmp}/bench_zarr.XXXXXX")
trap 'rm -rf "$work"' EXIT
dims=$((512 * k))x$((512 * k))x$((234 * k))
raw=$work/head_${dims}_uint16.raw
if [ "$k" = 1 ]; then
    cp "$head" "$raw"
else
    "$build/isogen" --upsample "$k" "$head" -o "$raw" --quiet
fi
"$build/tests/make_zarr" "$raw" "$dims" "$work/head.zarr" --bench
# zarr's uint16 array is read as uint16: the brick files must be equal
median() { sort -n | awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}'; }
measure() { # INPUT OUT: median seconds, then the last run's peak RSS and plan
    for i in $(seq "$runs"); do
        cat "$1" >/dev/null 2>&1 || find "$1" -type f -exec cat {} + >/dev/null
        start=$(date +%s.%N)
        "$build/isobrick" "$1" -o "$2" --force --mem-mb "$mem_mb" >"$work/summary"
        end=$(date +%s.%N)
        printf '%.3f\n' "$(echo "$end - $start" | bc)"
    done | median
}
t_raw=$(measure "$raw" "$work/raw.ibv")
rss_raw=$(grep "peak RSS" "$work/summary" | sed 's/^ *peak RSS *//')
t_zarr=$(measure "$work/head.zarr" "$work/zarr.ibv")
rss_zarr=$(grep "peak RSS" "$work/summary" | sed 's/^ *peak RSS *//')
cmp -s "$work/raw.ibv" "$work/zarr.ibv" || { echo "bench_zarr: the brick files differ" >&2; exit 1; }
zarr_bytes=$(du -sb "$work/head.zarr" | cut -f1)
echo "| input ($dims uint16, $(nproc) cores) | bytes | isobrick s (median of $runs) | vs raw | peak RSS (planned) |"
echo "| --- | ---: | ---: | ---: | --- |"
echo "| raw | $(stat -c %s "$raw") | $t_raw | 1.00 | $rss_raw |"
echo "| Zarr v2 blosc lz4 64^3 | $zarr_bytes | $t_zarr | $(printf '%.2f' "$(echo "scale=4; $t_zarr / $t_raw" | bc)") | $rss_zarr |"

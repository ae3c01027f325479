#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# HDF5 input against raw: the head upsampled 2x (1024x1024x468 uint16, 936 MiB) bricked from
# the raw file and from an HDF5 file of the same samples (chunks of 64^3, gzip level 4, written
# by the test helper make_hdf5), RUNS times each in turn (default 3), each from a cold page
# cache where the script may drop it (root). Prints a Markdown table: the median seconds, MB/s
# of raw bytes, peak RSS, and HDF5's time over raw's (the target is at most 3x). The two brick
# files must be equal, byte for byte. Not a test.
#
#   tools/bench/bench_hdf5.sh DIR [BUILD_DIR]
#
# DIR (outside the repository) holds the raw and HDF5 files, made once and reused; BUILD_DIR
# defaults to build and must have been configured with HDF5 (tests/make_hdf5). MEM_MB:
# isobrick's --mem-mb (default 1024).
set -eu
if [ $# -lt 1 ]; then
    sed -n '3,15p' "$0" | sed 's/^# \{0,1\}//' >&2
    exit 2
fi
root=$(cd "$(dirname "$0")/../.." && pwd)
dir=$1
build=${2:-build}
case $build in /*) ;; *) build=$root/$build ;; esac
runs=${RUNS:-3}
mem_mb=${MEM_MB:-1024}
head=$root/../shared/data/ct_head_visible_woman_512x512x234_uint16.raw
for p in isobrick isogen tests/make_hdf5; do
    [ -x "$build/$p" ] || { echo "bench_hdf5: $build/$p is missing (a build with IP_HDF5=ON)" >&2; exit 1; }
done
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)
raw=$dir/ct_head_visible_woman_x2_1024x1024x468_uint16.raw
h5=$dir/head_x2_gzip_chunks64.h5
[ -f "$raw" ] || "$build/isogen" --upsample 2 "$head" -o "$dir/" --quiet
[ -f "$h5" ] || "$build/tests/make_hdf5" --chunked 64 "$raw" "$h5"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cold() {
    sync
    if [ "$(id -u)" = 0 ]; then echo 3 >/proc/sys/vm/drop_caches; fi
}
# one run: INPUT NAME -> seconds and peak RSS (KiB) appended to $tmp/NAME
run() {
    cold
    /usr/bin/time -f "%e %M" -o "$tmp/time" "$build/isobrick" "$1" -o "$tmp/$2.ibv" --force \
        --quiet --mem-mb "$mem_mb"
    cat "$tmp/time" >>"$tmp/$2"
}
i=0
while [ "$i" -lt "$runs" ]; do
    run "$raw" raw
    run "$h5" hdf5
    i=$((i + 1))
done
cmp -s "$tmp/raw.ibv" "$tmp/hdf5.ibv" || { echo "bench_hdf5: the brick files differ" >&2; exit 1; }
median() { sort -n | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
bytes=$(stat -c %s "$raw")
raw_s=$(cut -d' ' -f1 "$tmp/raw" | median)
h5_s=$(cut -d' ' -f1 "$tmp/hdf5" | median)
echo "| input | file size | isobrick (s) | MB/s of raw bytes | peak RSS (MiB) | / raw |"
echo "| --- | ---: | ---: | ---: | ---: | ---: |"
for name in raw hdf5; do
    f=$raw
    [ "$name" = hdf5 ] && f=$h5
    s=$(cut -d' ' -f1 "$tmp/$name" | median)
    rss=$(cut -d' ' -f2 "$tmp/$name" | median)
    awk -v n="$name" -v size="$(stat -c %s "$f")" -v s="$s" -v b="$bytes" -v r="$rss" \
        -v base="$raw_s" 'BEGIN { printf "| %s | %.0f MiB | %.2f | %.0f | %.0f | %.2fx |\n",
            n, size / 1048576, s, b / s / 1e6, r / 1024, s / base }'
done
echo
echo "(median of $runs runs each, taken in turn; HDF5/raw = $(awk -v a="$h5_s" -v b="$raw_s" 'BEGIN { printf "%.2f", a / b }')x; target <= 3x)"

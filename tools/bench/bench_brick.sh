#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# Bricking benchmark: for each volume in the data folder, the brick file against whole-file
# lz4 -1 and zstd -1. Prints one Markdown table. Not a test: numbers depend on the machine.
#
#   tools/bench/bench_brick.sh [--speed-only] [DATA_DIR] [BUILD_DIR] [EXTRA.raw ...]
#                                                  (defaults: ../shared/data, build)
#
# Every input is read once first so that all columns are measured from the page cache.
# "ratio" is input bytes / brick file bytes (the file also holds the pyramid levels and the
# summaries); "L0 ratio" is input bytes / level-0 payload bytes, the figure comparable with
# lz4 and zstd of the raw file.
#
# A second table puts bricking speed beside `lz4 -1` on one core (taskset -c 0) on the same
# raw file, for the data folder's volumes of 64 MiB or more and the EXTRA files: the medians of
# RUNS (default 5) runs taken in turn, each as the wall time of the whole process. isobrick runs
# with its default threads and --mem-mb MEM_MB (default 1024); peak RSS is its own report.
# --speed-only prints that table alone.
set -eu
speed_only=0
if [ "${1:-}" = "--speed-only" ]; then
    speed_only=1
    shift
fi
data=${1:-../shared/data}
build=${2:-build}
shift $(($# < 2 ? $# : 2))
extra="$*" # file names without spaces
runs=${RUNS:-5}
mem_mb=${MEM_MB:-1024}
for p in isobrick isoinfo; do
    [ -x "$build/$p" ] || { echo "bench_brick: $build/$p is missing: run tools/setup.sh build" >&2; exit 1; }
done
command -v lz4 >/dev/null && command -v zstd >/dev/null ||
    { echo "bench_brick: needs the lz4 and zstd programs (apt-get install lz4 zstd)" >&2; exit 1; }
[ -d "$data" ] || { echo "bench_brick: no data folder $data" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

now() { date +%s.%N; }
mbps() { awk -v b="$1" -v t="$2" 'BEGIN { printf "%.0f", b / t / 1e6 }'; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", a / b }'; }

# tool_row NAME CMD: ratio and MB/s of "CMD < file | wc -c"
tool_cols() {
    t0=$(now)
    bytes=$($1 <"$2" | wc -c)
    t1=$(now)
    echo "$(ratio "$3" "$bytes") | $(mbps "$3" "$(awk -v a="$t0" -v b="$t1" 'BEGIN{print b-a}')")"
}

median() { sort -n | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
elapsed() { awk -v a="$1" -v b="$2" 'BEGIN { print b - a }'; }

# speed_row FILE: isobrick and lz4 -1 (one core) in turn, RUNS times each, medians.
speed_row() {
    raw=$1
    size=$(stat -c %s "$raw")
    cat "$raw" >/dev/null
    : >"$tmp/brick_s"
    : >"$tmp/lz4_s"
    i=0
    while [ "$i" -lt "$runs" ]; do
        t0=$(now)
        "$build/isobrick" "$raw" -o "$tmp/s.ibv" --force --mem-mb "$mem_mb" >"$tmp/out"
        t1=$(now)
        taskset -c 0 lz4 -1 -c "$raw" >/dev/null
        t2=$(now)
        elapsed "$t0" "$t1" >>"$tmp/brick_s"
        elapsed "$t1" "$t2" >>"$tmp/lz4_s"
        i=$((i + 1))
    done
    brick=$(mbps "$size" "$(median <"$tmp/brick_s")")
    lz4=$(mbps "$size" "$(median <"$tmp/lz4_s")")
    rss=$(awk '/^  peak RSS/ { v = $3; if ($4 == "GiB") v *= 1024; if ($4 == "KiB") v /= 1024; printf "%.0f", v }' "$tmp/out")
    file=$(stat -c %s "$tmp/s.ibv")
    printf '| %s | %.1f | %s | %s | %s | %s | %s | %s |\n' "$(basename "$raw" .raw)" \
        "$(awk -v s="$size" 'BEGIN{print s/1048576}')" "$brick" "$lz4" "$(ratio "$brick" "$lz4")" \
        "$(ratio "$size" "$file")" "$mem_mb" "$rss"
}

echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
echo
if [ "$speed_only" = 0 ]; then
echo "| volume | input MiB | bricks | file MiB | ratio | L0 ratio | bricking MB/s | peak RSS MiB | lz4 -1 ratio | lz4 -1 MB/s | zstd -1 ratio | zstd -1 MB/s |"
echo "| --- | ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
for raw in "$data"/*.raw; do
    name=$(basename "$raw" .raw)
    size=$(stat -c %s "$raw")
    cat "$raw" >/dev/null
    lz4_cols=$(tool_cols "lz4 -1 -c" "$raw" "$size")
    zstd_cols=$(tool_cols "zstd -1 -c -T1" "$raw" "$size")
    for variant in "32" "64" "32 --hc"; do
        set -- $variant
        edge=$1
        shift
        "$build/isobrick" "$raw" -o "$tmp/v.ibv" --brick-size "$edge" --force "$@" >"$tmp/out"
        secs=$(awk '/^  time/ { print $2 }' "$tmp/out")
        rss=$(awk '/^  peak RSS/ { v = $3; if ($4 == "GiB") v *= 1024; if ($4 == "KiB") v /= 1024; printf "%.0f", v }' "$tmp/out")
        "$build/isoinfo" --json "$tmp/v.ibv" >"$tmp/json"
        file=$(sed 's/.*"bytes_file": \([0-9]*\).*/\1/' "$tmp/json")
        level0=$(sed 's/.*"level": 0[^}]*"bytes_payload": \([0-9]*\).*/\1/' "$tmp/json")
        label="$edge${1:+ hc}"
        printf '| %s | %.1f | %s | %.1f | %s | %s | %s | %s | %s | %s |\n' "$name" \
            "$(awk -v s="$size" 'BEGIN{print s/1048576}')" "$label" \
            "$(awk -v s="$file" 'BEGIN{print s/1048576}')" "$(ratio "$size" "$file")" \
            "$(ratio "$size" "$level0")" "$(mbps "$size" "$secs")" "$rss" "$lz4_cols" "$zstd_cols"
    done
done
echo
fi
echo "| volume | input MiB | isobrick MB/s | lz4 -1 (1 core) MB/s | speed / lz4 | file ratio | --mem-mb | peak RSS MiB |"
echo "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
for raw in "$data"/*.raw; do
    [ "$(stat -c %s "$raw")" -ge $((64 << 20)) ] && speed_row "$raw"
done
for raw in $extra; do
    speed_row "$raw"
done

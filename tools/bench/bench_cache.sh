#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# Brick-cache benchmark: decode throughput (ours against LZ4 and XXH64 alone), hit latency,
# and random and sequential runs under several budgets; then `lz4 -b1` on the raw input, for
# LZ4's own figure on the whole file. Prints Markdown. Not a test: numbers depend on the machine.
#
#   tools/bench/bench_cache.sh [BRICK_FILE_OR_RAW] [BUILD_DIR] [bench_cache options...]
#
# Defaults: ../shared/data/ct_head_visible_woman_512x512x234_uint16.raw and build. A raw input
# is bricked first (isobrick, default options) into a temporary .ibv; a .ibv is used as it is
# (and then there is no raw file for lz4 -b1). Options after BUILD_DIR go to bench_cache, e.g.
# --budgets 16,64 --threads 1 --quick. Skips, with a message and exit status 0, when the input
# is missing. Results are in docs/cache.md.
set -eu
input=${1:-../shared/data/ct_head_visible_woman_512x512x234_uint16.raw}
build=${2:-build}
[ $# -gt 2 ] && shift 2 || set --
if [ ! -f "$input" ]; then
    echo "bench_cache: skipped: no input file $input"
    exit 0
fi
for p in isobrick bench_cache; do
    [ -x "$build/$p" ] || { echo "bench_cache: $build/$p is missing: build first (cmake --build $build)" >&2; exit 1; }
done

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

echo "# Brick cache benchmark"
echo
echo "- machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(awk '/MemTotal/ { printf "%.0f GiB", $2 / 1048576 }' /proc/meminfo) RAM"
# Other processes share the cores: the load and the kernel's CPU pressure ("some": the share
# of time runnable tasks waited for a core) say how much, before and after.
load() { echo "$(uptime | sed 's/.*load average/load average/')$( [ -r /proc/pressure/cpu ] && echo "; CPU pressure: $(head -1 /proc/pressure/cpu)")"; }
echo "- load before: $(load)"

case $input in
*.ibv)
    ibv=$input
    raw=
    ;;
*)
    raw=$input
    ibv=$tmp/input.ibv
    "$build/isobrick" "$raw" -o "$ibv" --quiet
    echo "- input: $raw, bricked with \`isobrick\` (default options) into a temporary file of $(stat -c %s "$ibv") bytes"
    ;;
esac
[ -n "$raw" ] || echo "- input: $ibv"
echo "- command: $build/bench_cache $ibv${*:+ $*}"
echo

stall() { sed -n 's/^some .*total=\([0-9]*\).*/\1/p' /proc/pressure/cpu 2>/dev/null || true; }
stall0=$(stall)
start=$(date +%s.%N)
"$build/bench_cache" "$ibv" "$@"
end=$(date +%s.%N)
stall1=$(stall)

echo "### lz4 -b1 on the whole raw file"
echo
if [ -z "$raw" ]; then
    echo "No raw file (the input is a brick file): skipped."
elif ! command -v lz4 >/dev/null; then
    echo "The lz4 program is missing (apt-get install lz4): skipped."
else
    # lz4 reports compression, then decompression speed in MB/s (10^6 bytes), on one core,
    # over independent 4 MiB blocks of the raw samples (no filters).
    line=$(lz4 -b1 "$raw" 2>&1 | tr '\r' '\n' | grep 'MB/s ,' | tail -1)
    echo "| file | input bytes | lz4 -1 bytes | ratio | compression MB/s | decompression MB/s, one core |"
    echo "| --- | ---: | ---: | ---: | ---: | ---: |"
    echo "$line" | sed -n "s#.*: *\([0-9]*\) *-> *\([0-9]*\) *(\([0-9.]*\)), *\([0-9.]*\) MB/s *, *\([0-9.]*\) MB/s.*#| $(basename "$raw") | \1 | \2 | \3 | \4 | \5 |#p"
fi
echo
echo "- bench_cache wall time: $(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.1f s", b - a }')"
if [ -n "$stall0" ] && [ -n "$stall1" ]; then
    # "some" CPU pressure: time during which at least one runnable task waited for a core
    # (ours or another process's); near 0 % means bench_cache had the cores it asked for.
    echo "- CPU pressure during bench_cache: $(awk -v a="$stall0" -v b="$stall1" -v s="$start" -v e="$end" \
        'BEGIN { printf "%.1f s of waiting for a core (%.1f %% of the run)", (b - a) / 1e6, (b - a) / 1e4 / (e - s) }')"
fi
echo "- load after: $(load)"

# SPDX-License-Identifier: BSD-3-Clause
# Bounded memory: every brick of a 1 GiB volume read through a 32 MiB cache keeps the
# process's peak RSS under budget + summaries + 64 MiB, whatever the file's size.
. "$(dirname "$0")/lib.sh"

if [ -n "${IP_SANITIZE:-}" ]; then
    echo "cache_memory: skipped: peak RSS is not meaningful under sanitizers (${IP_SANITIZE})"
    exit 77
fi
"$bin/isogen" gyroid --dims 1024x1024x512 --type uint16 -o "$work/" --quiet
raw=gyroid_1024x1024x512_uint16.raw
check "the input is 1 GiB" test "$(stat -c %s "$raw")" = 1073741824
"$bin/isobrick" "$raw" -o big.ibv --quiet
rm -f "$raw"
file_bytes=$(stat -c %s big.ibv)
check "the brick file is larger than the slack under test" test "$file_bytes" -gt $((256 << 20))
run_capture "$bin/isoinfo" --verify big.ibv --cache-mb 32 --stats stats.json
check "reading every brick succeeds" test "$rc" = 0
budget=$(json_number budget_bytes stats.json)
summary=$(json_number summary_bytes stats.json)
peak=$(json_number peak_rss_bytes stats.json)
touched=$(json_number bricks_touched stats.json)
total=$(json_number bricks_total stats.json)
resident_peak=$(json_number resident_peak_bytes stats.json)
limit=$((budget + summary + (64 << 20)))
echo "cache_memory: file $((file_bytes >> 20)) MiB, budget $((budget >> 20)) MiB, summaries $((summary >> 20)) MiB, peak RSS $((peak >> 20)) MiB, limit $((limit >> 20)) MiB"
check "budget is 32 MiB" test "$budget" = $((32 << 20))
check "every brick was read" test "$touched" = "$total"
check "decoded bricks stayed within the budget" test "$resident_peak" -le "$budget"
check "peak RSS $peak <= budget + summaries + 64 MiB = $limit" test "$peak" -le "$limit"
check "the stats table was printed" grep -q "cache statistics" "$work/.out"
finish

# SPDX-License-Identifier: BSD-3-Clause
# isoinfo --histogram end to end (text and JSON: keys, counts that sum to the level's samples,
# whole-value bins, option errors), and --verify's progress bar, forced on a pipe.
. "$(dirname "$0")/lib.sh"

"$bin/isogen" gyroid --dims 40x30x20 --type uint16 -o "$work/" --quiet
"$bin/isobrick" gyroid_40x30x20_uint16.raw -o g.ibv --brick-size 8 --subblock-size 4 \
    --threads 2 --quiet
check "the brick file exists" test -s g.ibv

# --- JSON: keys and counts, at every level (one Python run checks a level: `checks`) ---
checks='
import json, sys
h = json.load(open(sys.argv[1]))["histogram"]
level, bins_max = int(sys.argv[2]), int(sys.argv[3])
keys = {"level", "dims", "type", "samples", "unbinned", "subblocks", "bricks_read",
        "bricks_constant", "seconds", "value_min", "value_max", "bins"}
bins = h["bins"]
problems = [what for what, good in [
    ("keys " + str(sorted(set(h))), set(h) == keys),
    ("bin keys", all(set(b) == {"lo", "hi", "count", "active_subblocks"} for b in bins)),
    ("level", h["level"] == level),
    ("counts sum to the samples, the product of dims",
     sum(b["count"] for b in bins) == h["samples"] == h["dims"][0] * h["dims"][1] * h["dims"][2]),
    ("bin count", 1 <= len(bins) <= bins_max),
    ("contiguous edges", all(a["hi"] == b["lo"] for a, b in zip(bins, bins[1:]))),
    ("first edge", bins[0]["lo"] == h["value_min"]),
    ("whole-value bins", all(b["hi"] - b["lo"] == int(b["hi"] - b["lo"]) >= 1 for b in bins)),
    ("active sub-blocks", max(b["active_subblocks"] for b in bins) > 0 or h["subblocks"] < 2),
] if not good]
print(" ".join(problems) or "ok")
'
"$bin/isoinfo" g.ibv --json >info.json
levels=$(python3 -c 'import json,sys; j=json.load(open(sys.argv[1])); print(j["levels"], j["bricks"])' info.json)
bricks=${levels#* }
levels=${levels% *}
check "the file has several levels ($levels)" test "$levels" -ge 2
for level in $(seq 0 $((levels - 1))); do
    run_capture "$bin/isoinfo" g.ibv --histogram --json --level "$level" --bins 20
    check "--histogram --json --level $level succeeds (got $rc: $err)" test "$rc" = 0
    printf '%s\n' "$out" >h.json
    result=$(python3 -c "$checks" h.json "$level" 20)
    check "level $level: $result" test "$result" = ok
done
run_capture "$bin/isoinfo" g.ibv --histogram --json
printf '%s\n' "$out" >h0.json
result=$(python3 -c "$checks" h0.json 0 64)
check "the default: level 0 of a small file, 64 bins at most: $result" test "$result" = ok
check "level 0 has 24000 samples" grep -q '"samples": 24000,' h0.json
nbins=$(grep -o '"lo":' h0.json | wc -l)

# --- text: a header line and one row per bin, the same counts ---
run_capture "$bin/isoinfo" g.ibv --histogram --level 0
check "--histogram succeeds" test "$rc" = 0
check "the text names the level" grep -q "histogram of level 0" "$work/.out"
rows=$(grep -cE '^ +[-0-9.e+]+ +[-0-9.e+]+ +[0-9]+ +#* +[0-9]+$' "$work/.out")
check "one row per bin ($rows, $nbins)" test "$rows" = "$nbins"
sum=$(grep -E '^ +[-0-9.e+]+ +[-0-9.e+]+ +[0-9]+ ' "$work/.out" | awk '{s += $3} END {print s}')
check "the text's counts sum to 24000 ($sum)" test "$sum" = 24000

# --- option errors: exit 2, one line ---
expect_error 2 "--bins '0'" "$bin/isoinfo" g.ibv --histogram --bins 0
expect_error 2 "--bins 'x'" "$bin/isoinfo" g.ibv --histogram --bins x
expect_error 2 "--bins '65537'" "$bin/isoinfo" g.ibv --histogram --bins 65537
expect_error 2 "past the pyramid" "$bin/isoinfo" g.ibv --histogram --level "$levels"
expect_error 2 "--level '-1'" "$bin/isoinfo" g.ibv --histogram --level -1
expect_error 2 "go with --histogram" "$bin/isoinfo" g.ibv --bins 8
expect_error 1 "missing.ibv" "$bin/isoinfo" missing.ibv --histogram

# --- --verify's progress bar: none on a pipe, forced with ISOINFO_PROGRESS=1, none with --json ---
run_capture "$bin/isoinfo" g.ibv --verify
check "no bar on a pipe" test "$(printf '%s' "$err" | grep -c 'bricks.*MB/s')" = 0
run_capture env ISOINFO_PROGRESS=1 "$bin/isoinfo" g.ibv --verify
check "forced bar succeeds" test "$rc" = 0
check "the forced bar ends at 100% of $bricks bricks" \
    grep -qF "100.0% $bricks/$bricks bricks" "$work/.err"
check "the bar redraws in place" grep -q $'\r' "$work/.err"
check "the verified line stands on a line of its own" grep -q '^isoinfo: g.ibv: verified' "$work/.err"
run_capture env ISOINFO_PROGRESS=1 "$bin/isoinfo" g.ibv --verify --json
check "no bar with --json" test "$(printf '%s' "$err" | grep -c 'bricks.*MB/s')" = 0

finish

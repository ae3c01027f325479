# SPDX-License-Identifier: BSD-3-Clause
# isorender --strip: the progress strip holds the real image of the run at each of its points,
# side by side over a band of labels; bad --strip options are refused before any work.
. "$(dirname "$0")/lib.sh"

compare=$bin/tests/png_compare
"$bin/isogen" gyroid --dims 40x40x40 --type uint8 -o "$work/" --quiet
"$bin/isobrick" gyroid_40x40x40_uint8.raw -o g.ibv --brick-size 8 --quiet

# png_size FILE: "WIDTHxHEIGHT" from the PNG's header (IHDR: two big-endian 32-bit numbers)
png_size() {
    od -An -tu1 -j16 -N8 "$1" | awk '{ printf "%dx%d", (($1 * 256 + $2) * 256 + $3) * 256 + $4,
                                                     (($5 * 256 + $6) * 256 + $7) * 256 + $8 }'
}
# drawn FILE X: the pixels of the 96x72 frame at column X of FILE that are not background
# (differ from the empty image's)
drawn() {
    "$compare" "$1" empty.png --crop "$2,0,96,72" --max-pct 100 |
        sed -n 's/.*, \([0-9]*\) pixels (.*/\1/p'
}
view="--camera 90,-55,80,19.5,19.5,19.5,0,0,1,30 --size 96x72 --lod off"

# shellcheck disable=SC2086 # $view is a list of options
run_capture "$bin/isorender" g.ibv --iso 127.5 $view --software -o final.png \
    --strip s.png --strip-at 0.1%,2,100% --progress p.csv
check "a run with --strip succeeds" test "$rc" = 0
check "the summary names the strip and its frames" \
    sh -c 'printf "%s" "$0" | grep -q "strip  *s.png: 0.1% (.*) 2% (.*) 100% ("' "$out"
# three 96x72 frames 4 pixels apart: 296 wide; 72 + a band of 24 below for the labels
check "the strip is 296x96 ($(png_size s.png))" test "$(png_size s.png)" = 296x96
check "its last frame is the final image" "$compare" s.png final.png --crop 200,0,96,72
check "its first frame is not" sh -c '! "$0" s.png final.png --crop 0,0,96,72 >/dev/null' \
    "$compare"
# shellcheck disable=SC2086
"$bin/isorender" g.ibv --iso 300 $view --software -o empty.png --quiet 2>/dev/null
first=$(drawn s.png 0) middle=$(drawn s.png 100) last=$(drawn s.png 200)
check "the frames draw more and more ($first < $middle < $last pixels)" \
    test "${first:-0}" -gt 0 -a "${first:-0}" -lt "${middle:-0}" -a "${middle:-0}" -lt "${last:-0}"
check "the band holds the labels" sh -c '! "$0" s.png empty.png --crop 0,72,96,24 >/dev/null' \
    "$compare"
# the strip's points do not change the progress file's checkpoints (one per doubling)
# shellcheck disable=SC2086
"$bin/isorender" g.ibv --iso 127.5 $view --software -o plain.png --progress plain.csv --quiet
check "the same checkpoints with and without --strip" \
    test "$(cut -d, -f2 p.csv)" = "$(cut -d, -f2 plain.csv)"
check "the same final image with and without --strip" cmp -s final.png plain.png

# the default points (0.01%, 0.1%, 1%, 100%), with the renderer of the image (OpenGL where
# there is one): the last frame is that image, whichever renderer drew them
# shellcheck disable=SC2086
run_capture env ${preload:+LD_PRELOAD=$preload} "$bin/isorender" g.ibv --iso 127.5 $view \
    -o gl.png --strip gl-strip.png --quiet
check "a run with the default points succeeds" test "$rc" = 0
check "4 frames by default ($(png_size gl-strip.png))" test "$(png_size gl-strip.png)" = 396x96
check "the last frame is the image" "$compare" gl-strip.png gl.png --crop 300,0,96,72

# bad options: exit 2, one line, nothing written
expect_error 2 "--strip-at needs --strip" "$bin/isorender" g.ibv --iso 127.5 --strip-at 1,100
expect_error 2 "'0' is not a percentage" "$bin/isorender" g.ibv --iso 127.5 --strip x.png \
    --strip-at 0,100
expect_error 2 "'101%' is not a percentage" "$bin/isorender" g.ibv --iso 127.5 --strip x.png \
    --strip-at 1,101%
expect_error 2 "'abc' is not a percentage" "$bin/isorender" g.ibv --iso 127.5 --strip x.png \
    --strip-at 1,abc
expect_error 2 "'' is not a percentage" "$bin/isorender" g.ibv --iso 127.5 --strip x.png \
    --strip-at 1,,100
expect_error 2 "must increase" "$bin/isorender" g.ibv --iso 127.5 --strip x.png --strip-at 5,1
expect_error 2 "more than 8 frames" "$bin/isorender" g.ibv --iso 127.5 --strip x.png \
    --strip-at 1,2,3,4,5,6,7,8,9
expect_error 2 "no --full, --rays or --time" "$bin/isorender" g.ibv --iso 127.5 --strip x.png \
    --full
expect_error 2 "no --full, --rays or --time" "$bin/isorender" g.ibv --iso 127.5 --strip x.png \
    --rays 10
expect_error 2 "no --full, --rays or --time" "$bin/isorender" g.ibv --iso 127.5 --strip x.png \
    --time 1
expect_error 2 "over 65536" "$bin/isorender" g.ibv --iso 127.5 --strip x.png --size 16384x8 \
    --strip-at 10,20,30,40,100
expect_error 1 "x.png" "$bin/isorender" g.ibv --iso 127.5 -o x.png --strip x.png
check "a refused run writes nothing" test ! -e x.png -a ! -e isorender.png
finish

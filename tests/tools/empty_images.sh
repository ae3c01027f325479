# SPDX-License-Identifier: BSD-3-Clause
# No silently empty or wrong image: a spacing outside the bounds that render correctly is
# refused by isobrick (flags and headers alike) and by isorender and isoview (brick files
# written before the bounds existed); spacings at the bounds render the same picture as
# spacing 1; an isovalue outside the file's value range gives a one-line warning (exit 0, the
# image is legitimately empty) and a "warnings" entry in isorender's --stats JSON.
. "$(dirname "$0")/lib.sh"

compare=$bin/tests/png_compare
"$bin/isogen" sphere --dims 48x40x36 --type uint8 -o "$work/" --quiet
raw=sphere_48x40x36_uint8.raw
"$bin/isobrick" "$raw" -o s.ibv --brick-size 8 --quiet

# --- isobrick refuses what cannot be rendered, saying the range and another unit ---
expect_error 1 "$raw: spacing 1e-12 along x" "$bin/isobrick" "$raw" -o t.ibv \
    --spacing 1e-12,1e-12,1e-12
check "the message gives the range" sh -c 'printf "%s" "$0" | grep -q "1e-09 to 1e+06"' "$err"
check "and suggests another unit" sh -c 'printf "%s" "$0" | grep -q "micrometres"' "$err"
expect_error 1 "kilometres" "$bin/isobrick" "$raw" -o t.ibv --spacing 1,1,2e6
expect_error 1 "1000 times" "$bin/isobrick" "$raw" -o t.ibv --spacing 1,1,5000
printf 'NRRD0004\ntype: uchar\ndimension: 3\nsizes: 48 40 36\nspacings: 1e-12 1e-12 1e-12\nencoding: raw\ndata file: %s\n' \
    "$raw" >tiny.nhdr
expect_error 1 "tiny.nhdr: spacing 1e-12" "$bin/isobrick" tiny.nhdr -o t.ibv
check "no brick file after a refused spacing" test ! -e t.ibv

# --- the bounds themselves render right: the picture of spacing 1, scaled ---
picture() { # picture FILE NAME: progressive (exact) and full, software
    "$bin/isorender" "$1" --iso 100.5 --size 160x120 --software --lod off --quiet -o "$2-p.png"
    "$bin/isorender" "$1" --iso 100.5 --size 160x120 --software --full --quiet -o "$2-f.png"
}
picture s.ibv one
for s in 1e-9 1e-6 1e6; do
    run_capture "$bin/isobrick" "$raw" -o "s$s.ibv" --brick-size 8 --spacing "$s,$s,$s" --quiet
    check "spacing $s is accepted (got $rc: $err)" test "$rc" = 0
    picture "s$s.ibv" "s$s"
    for mode in p f; do
        line=$("$compare" one-p.png "s$s-$mode.png" --level 2 --max-pct 0.1)
        check "spacing $s ($mode) draws the picture of spacing 1: $line" test $? = 0
    done
done
"$bin/isobrick" "$raw" -o ratio.ibv --brick-size 8 --spacing 1,1,0.001 --quiet
"$bin/isorender" ratio.ibv --iso 100.5 --size 160x120 --software --lod off --view +z --quiet \
    -o ratio-p.png
"$bin/isorender" ratio.ibv --iso 100.5 --size 160x120 --software --full --view +z --quiet \
    -o ratio-f.png
"$bin/isorender" ratio.ibv --iso 1e9 --size 160x120 --software --full --view +z --quiet \
    -o ratio-none.png 2>/dev/null
line=$("$compare" ratio-p.png ratio-f.png --level 2 --max-pct 0)
check "a ratio of 1000: progressive equals full: $line" test $? = 0
check "and the surface shows" sh -c '! "$0" "$1" "$2" --level 2 --max-pct 1 >/dev/null' \
    "$compare" ratio-f.png ratio-none.png

# --- isorender and isoview refuse a brick file whose spacing is outside the bounds ---
for bad in 1e-12,1e-12,1e-12 1e7,1e7,1e7 1,1,5000; do
    "$bin/tests/respace" s.ibv "bad.ibv" "$bad"
    expect_error 1 "bad.ibv: spacing" "$bin/isorender" bad.ibv --iso 100.5 -o bad.png --stats bad.json
    expect_error 1 "bad.ibv: spacing" "$bin/isoview" bad.ibv --iso 100.5
    rm -f bad.ibv
done
check "no image or stats from a refused brick file" sh -c '[ ! -e bad.png ] && [ ! -e bad.json ]'

# --- an isovalue outside the value range: a warning, exit 0, an empty image ---
range=$("$bin/isoinfo" s.ibv --json | sed 's/.*"value_min": \([0-9.e+-]*\), "value_max": \([0-9.e+-]*\).*/\1 \2/')
min=${range% *}
max=${range#* }
for iso in 1000 "$min" -5; do
    run_capture "$bin/isorender" s.ibv --iso "$iso" --size 160x120 --software -o "w$iso.png" \
        --stats "w$iso.json" --quiet
    check "--iso $iso (range $min .. $max): exit 0 (got $rc)" test "$rc" = 0
    check "--iso $iso: one warning line ($err)" sh -c \
        '[ "$(printf "%s\n" "$0" | grep -c .)" = 1 ] && printf "%s" "$0" | grep -q "isorender: warning: --iso .*value range of s.ibv"' "$err"
    check "--iso $iso: the image is written" test -s "w$iso.png"
    check "--iso $iso: the stats carry the warning" grep -q '"warnings": \["--iso .*value range' "w$iso.json"
done
run_capture "$bin/isorender" s.ibv --iso 100.5 --size 160x120 --software -o in.png \
    --stats in.json --quiet
check "an isovalue inside the range: no warning ($err)" test -z "$err"
check "and an empty warnings array" grep -q '"warnings": \[\]' in.json
for key in cache file iso mode camera rays triangles time final_pixel_pct; do
    check "the stats keep \"$key\"" grep -q "\"$key\":" in.json
done

# isoview warns the same way, before its window opens
if command -v xvfb-run >/dev/null 2>&1; then
    # (display numbers from 200: away from the other window tests running at the same time)
    in_xvfb 200 640x480x24 "$bin/isoview" s.ibv --iso 1000 --size 160x120 --exit-after 0.5 --quiet
    check "isoview --iso 1000: exit 0 (got $rc)" test "$rc" = 0
    check "isoview --iso 1000: one warning line" sh -c \
        '[ "$(printf "%s\n" "$0" | grep -c .)" = 1 ] && printf "%s" "$0" | grep -q "isoview: warning: --iso 1000 is outside the value range"' \
        "$err"
else
    echo "empty_images: isoview part skipped: xvfb-run is missing (Debian package xvfb)"
fi
finish

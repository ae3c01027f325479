# SPDX-License-Identifier: BSD-3-Clause
# Clipping planes (--clip): the engine neither seeds nor propagates beyond them, so that the
# progressive image of every ray equals the clipped full extraction's; the triangles lie on
# the kept side (within a cell's diagonal: cells are kept or dropped whole); a plane that keeps
# nothing gives an empty image and exit 0; fewer bricks are read than without the plane; bad
# planes are usage errors (exit 2).
. "$(dirname "$0")/lib.sh"

compare=$bin/tests/png_compare
"$bin/isogen" sphere --dims 48x40x36 --type uint8 -o "$work/" --quiet
"$bin/isobrick" sphere_48x40x36_uint8.raw -o s.ibv --brick-size 8 --quiet
render() { # render NAME ARGS...: software, 160x120, one thread, no reading ahead
    name=$1
    shift
    "$bin/isorender" s.ibv --iso 100.5 --size 160x120 --software --threads 1 --prefetch off \
        --quiet -o "$name.png" "$@"
}

# --- progressive (every ray, lod off) equals full, for axis shortcuts and general planes ---
i=0
for spec in "--clip x=24" "--clip -x=20" "--clip 0,0,1,-20" "--clip y=18 --clip -z=25" \
    "--clip 1,1,1,-60"; do
    i=$((i + 1))
    # shellcheck disable=SC2086 # the spec is several words on purpose
    render "p$i" --lod off $spec --mesh "p$i.obj"
    # shellcheck disable=SC2086
    render "f$i" --full $spec --mesh "f$i.obj"
    line=$("$compare" "p$i.png" "f$i.png" --level 2 --max-pct 0)
    check "$spec: progressive equals full: $line" test $? = 0
done
render whole --full --mesh whole.obj
line=$("$compare" whole.png f1.png --level 2 --max-pct 1)
check "the cut changes the picture: $line" test $? != 0

# --- every vertex within a cell's diagonal (sqrt 3, spacing 1) of the kept side ---
kept_side() { # kept_side OBJ A B C D: the least A*x + B*y + C*z + D over the vertices
    awk -v a="$2" -v b="$3" -v c="$4" -v d="$5" '
        $1 == "v" { s = a * $2 + b * $3 + c * $4 + d; if (n++ == 0 || s < m) m = s }
        END { if (n == 0) print "none"; else printf "%.4f\n", m }' "$1"
}
at_least() { # at_least DESC OBJ A B C D LIMIT: the least is at least LIMIT
    least=$(kept_side "$2" "$3" "$4" "$5" "$6")
    check "$1 (least $least)" awk -v m="$least" -v l="$7" 'BEGIN { exit !(m != "none" && m >= l) }'
}
at_least "x=24: progressive vertices have x >= 24 - 1.733" p1.obj 1 0 0 -24 -1.733
at_least "x=24: full vertices have x >= 24 - 1.733" f1.obj 1 0 0 -24 -1.733
at_least "1,1,1,-60: vertices within a cell (1.733 * |n|) of the kept side" p5.obj 1 1 1 -60 -3.0
least=$(kept_side whole.obj 1 0 0 -24)
check "without the plane the surface reaches far beyond it (least $least)" \
    awk -v m="$least" 'BEGIN { exit !(m < -10) }'

# --- a plane that keeps nothing: an empty image, exit 0 ---
"$bin/isorender" s.ibv --iso 1e9 --size 160x120 --software --quiet -o none.png 2>/dev/null
run_capture render gone --clip x=1000 --stats gone.json
check "keeping nothing exits 0 (got $rc: $err)" test "$rc" = 0
line=$("$compare" gone.png none.png --level 0 --max-pct 0)
check "keeping nothing draws the background only: $line" test $? = 0
check "and no triangles" grep -q '"triangles": 0,' gone.json

# --- fewer bricks touched (deterministic with one thread and no reading ahead) ---
touched() { grep -o '"bricks_touched": [0-9]*' "$1" | head -1 | sed 's/.* //'; }
render a --lod off --stats a.json
render b --lod off --stats b.json --clip x=30
render b2 --lod off --stats b2.json --clip x=30
na=$(touched a.json) nb=$(touched b.json) nb2=$(touched b2.json)
check "the clipped run touches fewer bricks ($nb < $na)" test "$nb" -lt "$na"
check "the same count on a second run ($nb = $nb2)" test "$nb" = "$nb2"
render c --full --stats c.json
render d --full --stats d.json --clip x=30
nc=$(touched c.json) nd=$(touched d.json)
check "full extraction too touches fewer bricks ($nd < $nc)" test "$nd" -lt "$nc"
check "--stats records the planes" grep -q '"clip": \[\[1, 0, 0, -30\]\]' b.json
check "--stats records no plane as []" grep -q '"clip": \[\]' a.json

# --- bad planes: exit 2, one line ---
for spec in w=3 x= x=abc "1,2,3" "1,2,3,4,5" "0,0,0,1" "1,,2,3" "1,2,3,4," "" "=4" "-x" nan,0,0,1; do
    expect_error 2 "bad --clip" "$bin/isorender" s.ibv --iso 100.5 -o bad.png --clip "$spec"
done
expect_error 2 "at most 6 --clip" "$bin/isorender" s.ibv --iso 100.5 -o bad.png --clip x=1 \
    --clip x=2 --clip x=3 --clip x=4 --clip x=5 --clip x=6 --clip x=7
expect_error 2 "bad --clip" "$bin/isoview" s.ibv --iso 100.5 --clip y
expect_error 2 "option '--clip' needs a value" "$bin/isorender" s.ibv --iso 100.5 -o bad.png --clip
check "no image after a bad plane" test ! -e bad.png

finish

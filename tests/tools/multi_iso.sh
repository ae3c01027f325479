# SPDX-License-Identifier: BSD-3-Clause
# isorender with several --iso: each surface extracted by its own run, drawn together with its
# own colour and opacity. On nested spheres (isogen sphere: the isosurface c is the sphere of
# radius 1 - c), the images are checked against the single-surface images: opaque, the outer
# surface hides the inner one; translucent, it is blended over it (png_over computes that
# image from the two single-surface images and the empty one).
. "$(dirname "$0")/lib.sh"

compare=$bin/tests/png_compare
over=$bin/tests/png_over
"$bin/isogen" sphere --dims 40x40x40 --type uint8 -o "$work/" --quiet
"$bin/isobrick" sphere_40x40x40_uint8.raw -o s.ibv --brick-size 8 --quiet
outer='#d9a38c' inner='#8fb3d9'
render() { "$bin/isorender" s.ibv --size 120x90 --software --quiet --azimuth 20 --elevation 15 "$@"; }
same() { # same DESCRIPTION A B [png_compare options]: A and B agree
    sd_desc=$1 sd_a=$2 sd_b=$3
    shift 3
    check "$sd_desc" "$compare" "$sd_a" "$sd_b" "$@"
}
count() { # count A B LEVEL: the pixels of A and B that differ by more than LEVEL
    "$compare" "$1" "$2" --level "$3" --max-pct 100 | sed -n 's/.*, \([0-9]*\) pixels (.*/\1/p'
}
differ() { # differ DESCRIPTION A B: more than 5 % of the pixels differ by more than 8 levels
    check "$1" sh -c '! "$0" "$1" "$2" --level 8 --max-pct 5 >/dev/null' "$compare" "$2" "$3"
}

# bad values: exit 2, one line, nothing written
expect_error 2 "--opacity '0'" render --iso 60 --opacity 0
expect_error 2 "--opacity '1.5'" render --iso 60 --opacity 1.5
expect_error 2 "--opacity 'abc'" render --iso 60 --opacity abc
expect_error 2 "--opacity '1e-50' is not a number in (0, 1]" render --iso 60 --opacity 1e-50
expect_error 2 "--iso given 5 times" render --iso 10 --iso 20 --iso 30 --iso 40 --iso 50
expect_error 2 "--iso 60 is given twice" render --iso 60 --iso 180 --iso 60.0
expect_error 2 "3 --color and 0 --opacity for 2 --iso" render --iso 60 --iso 180 \
    --color '#ff0000' --color '#00ff00' --color '#0000ff'
expect_error 2 "0 --color and 2 --opacity for 1 --iso" render --iso 60 --opacity 0.5 --opacity 1
expect_error 2 "--color '2,0,0'" render --iso 60 --iso 180 --color '#ff0000' --color 2,0,0
check "a refused run writes nothing" test ! -e isorender.png

# the single surfaces, and the empty image (an isovalue above the maximum, 246)
render --iso 60 --color "$outer" -o outer.png
render --iso 180 --color "$inner" -o inner.png
render --iso 250 -o empty.png 2>/dev/null
differ "the outer surface shows (the test can fail)" outer.png empty.png
differ "the inner surface differs from the outer" inner.png outer.png

# opaque: the outer surface hides the inner one, whatever the order of --iso
render --iso 60 --iso 180 --color "$outer" --color "$inner" -o opaque.png
same "two opaque nested surfaces: the outer one alone shows" opaque.png outer.png
render --iso 180 --iso 60 --color "$inner" --color "$outer" -o opaque2.png
same "in either order" opaque2.png outer.png
# a second surface with no triangles leaves the single surface's image (the new drawing path
# gives the old one's image)
render --iso 60 --iso 250 --color "$outer" -o lone.png 2>/dev/null
same "a surface with no triangles adds nothing" lone.png outer.png

# translucent outer surface: a * outer + (1 - a) * what lies under it, where it is drawn
render --iso 60 --iso 180 --color "$outer" --color "$inner" --opacity 0.4 -o glass.png \
    --stats glass.json --progress glass.csv
"$over" outer.png inner.png empty.png 0.4 expect.png
same "the translucent surface is blended over the inner one" glass.png expect.png --level 1
differ "and differs from the outer surface alone" glass.png outer.png
differ "and from the inner one alone" glass.png inner.png
# the inner surface shows only through the outer one: the glass image differs from the outer
# surface over the background exactly where the inner surface is drawn
"$over" outer.png empty.png empty.png 0.4 over_empty.png
inner_px=$(count inner.png empty.png 0) seen_px=$(count glass.png over_empty.png 1)
check "the inner surface shows where drawn ($seen_px of $inner_px pixels)" \
    test "${seen_px:-0}" -gt $((${inner_px:-0} * 9 / 10)) -a "${seen_px:-0}" -le "${inner_px:-0}"
# a translucent surface alone is blended over the background
render --iso 60 --color "$outer" --opacity 0.4 -o alone.png
same "a translucent surface alone: over the background" alone.png over_empty.png --level 1
# both translucent: blended in --iso order, each over the image so far; the inner (second)
# one last, wherever it is drawn (no opaque surface is in front of it)
render --iso 60 --iso 180 --color "$outer" --color "$inner" --opacity 0.4 --opacity 0.7 -o both.png
"$over" inner.png over_empty.png empty.png 0.7 expect_both.png
same "two translucent surfaces: blended in --iso order" both.png expect_both.png --level 2

# --stats: the top level is the first surface's; "surfaces" has one entry a surface
check "--stats: surfaces, each with its counts" python3 -c '
import json, sys
d = json.load(open("glass.json"))
s = d["surfaces"]
assert [x["iso"] for x in s] == [60, 180], s
assert [x["opacity"] for x in s] == [0.4, 1], s
assert [x["color"] for x in s] == ["#d9a38c", "#8fb3d9"], s
for x in s:
    for k in ("rays", "seeds", "cells", "triangles", "done", "visible_triangles",
              "final_pixel_pct", "extraction_wall_s"):
        assert k in x, k
    assert x["triangles"] > 0 and x["done"], x
assert d["iso"] == 60 and d["triangles"] == s[0]["triangles"], d
assert d["warnings"] == []
'
check "--progress: an iso column, the rows of 60 then of 180" sh -c '
    head -1 glass.csv | grep -q "^time_s,rays,seeds,cells,triangles,final_pixel_pct,visible_triangles,overdraw,iso$" &&
    test "$(tail -n +2 glass.csv | cut -d, -f9 | uniq | tr "\n" " ")" = "60 180 "'
render --iso 60 --iso 120 --iso 180 -o palette.png --stats palette.json
check "surfaces without --color take the palette" python3 -c '
import json
s = json.load(open("palette.json"))["surfaces"]
assert [x["color"] for x in s] == ["#ede3c9", "#8fb3d9", "#e0a370"], s'
# one --iso: no "surfaces", no iso column
render --iso 60 -o one.png --stats one.json --progress one.csv
check "one --iso: no surfaces in --stats" sh -c '! grep -q surfaces one.json'
check "one --iso: the columns as before" sh -c \
    'head -1 one.csv | grep -q "^time_s,rays,seeds,cells,triangles,final_pixel_pct,visible_triangles,overdraw$"'

# the range warning applies to each isovalue
run_capture render --iso -5 --iso 60 --iso 300 -o w.png --stats w.json
check "two warnings, for -5 and 300" sh -c 'printf "%s\n" "$0" | grep -c "warning: --iso \(-5\|300\) is outside" | grep -qx 2' "$err"
check "both in --stats" python3 -c '
import json
assert len(json.load(open("w.json"))["warnings"]) == 2'

# --mesh: one file a surface, the isovalue before the extension
render --iso 60 --iso 180 -o m.png --mesh m.ply 2>/dev/null
check "--mesh m.ply writes m_iso60.ply and m_iso180.ply" test -s m_iso60.ply -a -s m_iso180.ply -a ! -e m.ply
expect_error 1 "m_iso60.ply" render --iso 60 --iso 180 -o m2.png --mesh m.ply
: >taken_iso180.ply
expect_error 1 "taken_iso180.ply" render --iso 60 --iso 180 -o t.png --mesh taken.ply
check "and then nothing is written" test ! -e t.png -a ! -e taken_iso60.ply
# the summary: each surface's counts and extraction times, then the image's one rendering time
run_capture "$bin/isorender" s.ibv --size 120x90 --software --iso 60 --iso 180 -o sum.png
check "the summary gives each surface" \
    test "$(printf '%s\n' "$out" | grep -c '^  surface [12]     iso \(60\|180\)$')" = 2
check "... and the rendering once, not per surface" \
    test "$(printf '%s\n' "$out" | grep -c '^  rendering     [0-9.]* s (software), the surfaces together$')" = 1 \
    -a "$(printf '%s\n' "$out" | grep -c '; rendering')" = 0
expect_error 2 "--mesh m.xyz: the name must end in" render --iso 60 --iso 180 -o x.png --mesh m.xyz
# isovalues that "%g" would both write as 100 keep the digits that tell them apart
render --iso 100.0001 --iso 100.0002 --iso 0.1 -o n.png --mesh n.ply 2>/dev/null
check "--mesh names 100.0001, 100.0002 and 0.1 apart" \
    test -s n_iso100.0001.ply -a -s n_iso100.0002.ply -a -s n_iso0.1.ply

# --full: the whole surfaces, the same picture
render --iso 60 --iso 180 --color "$outer" --color "$inner" --opacity 0.4 --full -o full.png
render --iso 60 --iso 180 --color "$outer" --color "$inner" --opacity 0.4 --lod off -o prog.png
same "--full draws what a progressive run draws" full.png prog.png --level 1 --max-pct 0.5

# the strip and the turntable take every surface
render --iso 60 --iso 180 --opacity 0.4 --lod off -o s.png --strip strip.png --strip-at 50,100
render --iso 60 --iso 180 --opacity 0.4 --lod off -o plain.png
same "the strip's last frame is the image" strip.png plain.png --crop 124,0,120,90
render --iso 60 --iso 180 --opacity 0.4 --lod off --turntable 2 -o frames
same "the turntable's first frame is the image" frames/frame_000.png plain.png

# OpenGL draws the same (where OpenGL is available)
"$bin/isorender" s.ibv --size 120x90 --quiet --azimuth 20 --elevation 15 --iso 60 --iso 180 \
    --color "$outer" --color "$inner" --opacity 0.4 -o gl.png --stats gl.json --renderer opengl
if grep -q '"renderer": "opengl"' gl.json; then
    same "OpenGL and software agree" gl.png glass.png --level 3 --max-pct 2
else
    echo "multi_iso: no headless OpenGL here; the OpenGL comparison is skipped"
fi
finish

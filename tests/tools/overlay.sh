# SPDX-License-Identifier: BSD-3-Clause
# isorender --axes and --scale-bar: the overlays change only their corners, the scale bar is
# as long as the projection makes its length at the target's depth, and the triad follows the
# camera. --verbose says where each was drawn and what it shows.
. "$(dirname "$0")/lib.sh"

compare=$bin/tests/png_compare
pixel=$bin/tests/png_pixel
"$bin/isogen" shepp-logan --dims 40x40x40 --type uint8 -o "$work/" --quiet
"$bin/isobrick" shepp-logan_40x40x40_uint8.raw -o c.ibv --brick-size 8 --quiet
# an eye 100 world units from the volume's centre (19.5, 19.5, 19.5) on -y, fov 30 degrees
camera=19.5,-80.5,19.5,19.5,19.5,19.5,0,0,1,30
render() { "$bin/isorender" c.ibv --iso 60 --size 320x240 --full --quiet --force "$@"; }

expect_error 2 "--scale-unit needs --scale-bar" render --scale-unit mm -o x.png
check "a refused run writes nothing" test ! -e x.png
# an overlay is drawn whole or not at all: the triad needs 63x62 pixels (before any work);
# the scale bar's label is known only once the view is, so a bar that does not fit ends the
# run with nothing written
expect_error 2 "--axes: the triad needs an image of at least 63x62 pixels, not 16x16" \
    render --size 16x16 --axes -o x.png
expect_error 2 "not 62x62" render --size 62x62 --axes --software -o x.png
check "a refused --axes writes nothing" test ! -e x.png
render --size 63x62 --axes --software -o small.png
check "63x62 takes the triad" test -s small.png
expect_error 1 "c.ibv: --scale-bar: \"10 units\" and its bar need 48x19 pixels in the corner, more than the 40x40 image has" \
    render --size 40x40 --scale-bar --software -o x.png
check "a scale bar that does not fit writes nothing" test ! -e x.png

# box WORD TEXT: the "x0,y0 to x1,y1" after WORD in TEXT, as "x0 y0 x1 y1"
box() { printf '%s\n' "$2" | sed -n "s/.*$1 \([0-9]*\),\([0-9]*\) to \([0-9]*\),\([0-9]*\).*/\1 \2 \3 \4/p"; }
# inside BBOX_LINE X0 Y0 X1 Y1: png_compare's "bbox X Y W H" lies within [X0, X1) x [Y0, Y1)
inside() {
    printf '%s\n' "$1" | awk -v x0="$2" -v y0="$3" -v x1="$4" -v y1="$5" \
        '/^bbox/ { found = 1; ok = $2 >= x0 && $3 >= y0 && $2 + $4 <= x1 && $3 + $5 <= y1 }
         END { exit !(found && ok) }'
}

for renderer in --software opengl; do
    case $renderer in
    opengl)
        render --camera $camera --stats gl.json --renderer opengl -o probe.png
        if ! grep -q '"renderer": "opengl"' gl.json; then
            echo "overlay: no headless OpenGL here; the overlays are tested in software only"
            continue
        fi
        set -- --aa 4
        ;;
    *) set -- --software ;;
    esac
    render --camera $camera "$@" -o plain.png
    run_capture render --camera $camera "$@" --axes -v -o axes.png
    axes_box=$(box "axes: box" "$err")
    run_capture render --camera $camera "$@" --scale-bar -v -o bar.png
    bar_line=$err
    bar_box=$(box "; box" "$bar_line")
    check "$renderer: the boxes are reported ($axes_box; $bar_box)" \
        test -n "$axes_box" -a -n "$bar_box"
    # shellcheck disable=SC2086 # the boxes are four numbers each
    check "$renderer: --axes changes its bottom-left box only" \
        inside "$("$compare" plain.png axes.png --bbox | sed -n 2p)" $axes_box
    # shellcheck disable=SC2086
    check "$renderer: --scale-bar changes its bottom-right box only" \
        inside "$("$compare" plain.png bar.png --bbox | sed -n 2p)" $bar_box
    check "$renderer: the overlays change pixels (the test can fail)" \
        sh -c '! "$0" plain.png axes.png >/dev/null && ! "$0" plain.png bar.png >/dev/null' \
        "$compare"
    set -- $axes_box
    check "$renderer: the triad is in the bottom-left corner" test "$3" -le 160 -a "$2" -ge 120
done

# The scale bar for this camera: a pixel spans 2 * 100 * tan(15 deg) / 240 world units at the
# target's depth; at most a quarter of the width (80 pixels, 17.9 units): 10 units
run_capture render --camera $camera --software --scale-bar -v --stats s.json -o bar.png
expected=$(awk 'BEGIN { p = 200 * sin(15 * atan2(0, -1) / 180) / cos(15 * atan2(0, -1) / 180) / 240
                        printf "%.6f %.3f", p, 10 / p }')
set -- $expected
check "the scale bar is 10 units, $2 pixels of $1 ($err)" \
    sh -c 'printf "%s" "$0" | grep -qF "scale bar: 10 units = $1 pixels"' "$err" "$2"
check "--stats has the scale bar" grep -q '"scale_bar": {"length": 10, "unit": "units"' s.json
# the image's bar: its bottom row lit over round(pixels) columns, not one more on either side
bar_at=$(box "; bar" "$err")
set -- $bar_at
row=$(($4 - 1))
rounded=$(awk -v p="$(printf '%s' "$expected" | cut -d' ' -f2)" 'BEGIN { printf "%d", p + 0.5 }')
check "the bar is $rounded pixels long (from $1 to $3)" test $(($3 - $1)) = "$rounded"
lit() { "$pixel" bar.png "$1,$row" | awk '{ exit !($1 > 200 && $2 > 200 && $3 > 200) }'; }
check "the bar's first column is lit" lit "$1"
check "the bar's last column is lit" lit $(($3 - 1))
if lit $(($1 - 1)) || lit "$3"; then bad "the bar is longer than $rounded pixels"; else ok; fi
# --zoom 2 doubles every length on screen: 5 units for a bar of the same quarter width
run_capture render --camera $camera --software --scale-bar --zoom 2 -v -o zoom.png
check "--zoom 2: 10 units would be twice as long, 5 fit ($err)" \
    sh -c 'printf "%s" "$0" | grep -q "scale bar: 5 units = "' "$err"
run_capture render --camera $camera --software --scale-bar --scale-unit mm -v -o mm.png
check "--scale-unit names the unit" sh -c 'printf "%s" "$0" | grep -q "scale bar: 10 mm = "' "$err"
# a unit the font has no glyphs for (UTF-8 "um" with a micro sign) is drawn with '?'
render --camera $camera --software --scale-bar --scale-unit "$(printf '\302\265m')" -o micro.png
render --camera $camera --software --scale-bar --scale-unit '??m' -o qm.png
check "a non-ASCII unit draws as ?" "$compare" micro.png qm.png

# The triad follows the camera: from -y, x points right; turned by 180 degrees, left
direction() { printf '%s\n' "$1" | sed -n "s/.* $2 \([-+][0-9.]*\),\([-+][0-9.]*\),.*/\1 \2/p"; }
run_capture render --view -y --software --axes -v -o a0.png
front=$err
run_capture render --view -y --azimuth 180 --software --axes -v -o a180.png
back=$err
check "from -y, x points right, z up ($front)" \
    test "$(direction "$front" x)" = "+1.0000 +0.0000" -a "$(direction "$front" z)" = "+0.0000 -1.0000"
check "--azimuth 180 mirrors x ($back)" \
    test "$(direction "$back" x)" = "-1.0000 +0.0000" -a "$(direction "$back" z)" = "+0.0000 -1.0000"
check "the mirrored triads differ in the image" sh -c '! "$0" a0.png a180.png >/dev/null' "$compare"
# --elevation 90 looks down: y points up in the image, x still right
run_capture render --view -y --elevation 90 --software --axes -v -o up.png
check "--elevation 90: y up, x right ($err)" \
    test "$(direction "$err" y)" = "+0.0000 -1.0000" -a "$(direction "$err" x)" = "+1.0000 +0.0000"

# every turntable frame gets the overlays: frame 1 of 2 is the view turned half round
"$bin/isorender" c.ibv --iso 60 --size 160x120 --full --software --turntable 2 --axes -v \
    -o frames >/dev/null 2>frames.err
check "each frame has its triad" test "$(grep -c 'axes: box' frames.err)" = 2
check "frame 1 of 2 mirrors x" \
    test "$(direction "$(sed -n '/axes: box/p' frames.err | sed -n 2p)" x)" = "-1.0000 +0.0000"

# a file in a named space (LPS), its sample x along physical +y and y along physical -x: the
# triad shows the physical axes, labelled L, P, S; the scale bar's unit is mm
cat >turned.nhdr <<NHDR
NRRD0004
type: uint8
dimension: 3
sizes: 40 40 40
space: left-posterior-superior
space directions: (0,1,0) (-1,0,0) (0,0,1)
endian: little
encoding: raw
data file: shepp-logan_40x40x40_uint8.raw
NHDR
"$bin/isobrick" turned.nhdr -o t.ibv --brick-size 8 --quiet
run_capture "$bin/isorender" t.ibv --iso 60 --size 320x240 --full --quiet --software --view left \
    --axes --scale-bar -v -o t.png
# the views are in physical space: from the left (physical +x, L), L is toward the eye, P
# right, S up, whichever way the samples are stored
check "LPS, from the left: L toward the eye, P right, S up ($err)" \
    test "$(direction "$err" L)" != "" -a "$(direction "$err" P)" = "+1.0000 +0.0000" \
    -a "$(direction "$err" S)" = "+0.0000 -1.0000"
check "LPS: L along the view" sh -c 'printf "%s" "$0" | grep -qF " L +0.0000,+0.0000,+1.0000"' "$err"
check "LPS: the unit is mm" sh -c 'printf "%s" "$0" | grep -q "scale bar: [0-9.]* mm = "' "$err"
# --view -y: the eye on the physical -y side (anterior, in LPS): L right, P away, S up; the
# same as --view anterior, the default in a file with a space
run_capture "$bin/isorender" t.ibv --iso 60 --size 320x240 --full --quiet --software --view -y \
    --axes -v -o ty.png
check "LPS, from -y: L right, S up ($err)" \
    test "$(direction "$err" L)" = "+1.0000 +0.0000" -a "$(direction "$err" S)" = "+0.0000 -1.0000"
check "LPS, from -y: P away from the eye" \
    sh -c 'printf "%s" "$0" | grep -qF " P +0.0000,+0.0000,-1.0000"' "$err"
run_capture "$bin/isorender" t.ibv --iso 60 --size 320x240 --full --quiet --software --axes \
    -o tdefault.png
check "LPS: the default view is anterior, -y" cmp -s ty.png tdefault.png
finish

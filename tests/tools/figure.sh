# SPDX-License-Identifier: BSD-3-Clause
# isorender's figure options: --azimuth, --elevation and --zoom turn and magnify the view,
# --color and --background colour the image, --turntable writes the frames of a full turn
# (and an MP4 through ffmpeg when it is installed). Bad values are refused before any work.
. "$(dirname "$0")/lib.sh"

compare=$bin/tests/png_compare
pixel=$bin/tests/png_pixel
# a cube whose content differs along x and y, so that each side shows a different picture
"$bin/isogen" shepp-logan --dims 40x40x40 --type uint8 -o "$work/" --quiet
"$bin/isobrick" shepp-logan_40x40x40_uint8.raw -o c.ibv --brick-size 8 --quiet
render() { "$bin/isorender" c.ibv --iso 60 --size 120x90 --software --quiet "$@"; }
same() { # same DESCRIPTION A B [png_compare options]: A and B agree
    sd_desc=$1 sd_a=$2 sd_b=$3
    shift 3
    check "$sd_desc" "$compare" "$sd_a" "$sd_b" "$@"
}

# bad values: exit 2, one line, nothing written
expect_error 2 "--zoom '0'" render --zoom 0
expect_error 2 "--zoom '-2'" render --zoom -2
expect_error 2 "--azimuth 'abc'" render --azimuth abc
expect_error 2 "--elevation 'nan'" render --elevation nan
expect_error 2 "--color '2,0,0'" render --color 2,0,0
expect_error 2 "--color '#12345g'" render --color '#12345g'
expect_error 2 "--color '0.5,0.5'" render --color 0.5,0.5
expect_error 2 "--background 'red'" render --background red
expect_error 2 "--background '#000000:'" render --background '#000000:'
expect_error 2 "--turntable '0' is not a frame count (1 to 100000)" render --turntable 0
expect_error 2 "--turntable 'x' is not a frame count (1 to 100000)" render --turntable x
expect_error 2 "--turntable '100001' is not a frame count (1 to 100000)" render --turntable 100001
expect_error 2 "--mp4 needs --turntable" render --mp4 t.mp4
expect_error 2 "no --mesh" render --turntable 3 --mesh m.ply
check "a refused run writes nothing" test ! -e isorender.png -a ! -e turntable -a ! -e m.ply

# the turns, exactly (--full: the same mesh for every view, so only the camera differs)
render --full --view -y -o y.png
render --full --view -y --azimuth 360 -o y360.png
render --full --view +x -o x.png
render --full --view -y --azimuth 90 -o y90.png
render --full --view -y --azimuth -90 -o ym90.png
render --full --view -x -o mx.png
render --full --view +z -o z.png
render --full --view -y --elevation 90 -o yup.png
same "--azimuth 360 is no turn" y360.png y.png --level 1 --max-pct 0.1
check "the sides differ (the test can fail)" sh -c '! "$0" y.png x.png --max-pct 5 >/dev/null' "$compare"
same "-y turned by --azimuth 90 looks from +x" y90.png x.png --level 1 --max-pct 0.1
same "-y turned by --azimuth -90 looks from -x" ym90.png mx.png --level 1 --max-pct 0.1
same "-y raised by --elevation 90 looks from +z" yup.png z.png --level 1 --max-pct 0.1
# progressive: the extraction follows the turned camera
render --view -y --azimuth 90 --lod off -o p90.png
render --view +x --lod off -o px.png
same "a progressive run follows the turn" p90.png px.png --level 1 --max-pct 0.1

# --zoom 2 narrows the field of view: the image is the central half of the unzoomed one at
# twice the size (the same rays); a solid background, since a gradient spans the image
render --full --view -y --background '#000000' --size 240x180 -o big.png
render --full --view -y --background '#000000' --zoom 2 -o zoom.png
same "--zoom 2 shows the central half, twice as large" big.png zoom.png --crop 60,45,120,90 \
    --level 1 --max-pct 0.1
check "--zoom changes the picture" sh -c '! "$0" y.png zoom.png --max-pct 5 >/dev/null' "$compare"

# colours: a solid background fills the corners; a gradient goes from the top row's colour
# to the bottom row's (row y shows mix(top, bottom, (y + 0.5) / height)); the surface colour
# shows where the surface faces the eye (there: colour * 0.92 + 0.12 highlight, clamped)
render --view -y --background '#204080' -o solid.png
check "the solid background in the top-left corner" test "$("$pixel" solid.png 0,0)" = "32 64 128 255"
check "the solid background in the bottom-right corner" test "$("$pixel" solid.png -1,-1)" = "32 64 128 255"
render --view -y --background '1,0,0:0,0,1' -o gradient.png
check "the gradient's top row is the top colour" test "$("$pixel" gradient.png 0,0)" = "254 0 1 255"
check "the gradient's bottom row is the bottom colour" test "$("$pixel" gradient.png -1,-1)" = "1 0 254 255"
check "the gradient's middle" test "$("$pixel" gradient.png 5,45)" = "126 0 129 255"
render --view -y --color '#00ff00' -o green.png
render --view -y -o ivory.png
check "the default background is unchanged" test "$("$pixel" ivory.png 0,0)" = "61 69 86 255"
green=$("$pixel" green.png 60,45) # the centre: surface that faces the eye
ivory=$("$pixel" ivory.png 60,45)
check "the surface is green ($green)" sh -c 'set -- $0; [ "$2" = 255 ] && [ "$1" -lt 40 ] && [ "$3" -lt 40 ]' "$green"
check "the default surface is ivory ($ivory)" sh -c 'set -- $0; [ "$1" -gt "$2" ] && [ "$2" -gt "$3" ] && [ "$3" -gt 180 ]' "$ivory"

# OpenGL draws the same colours as the software rasterizer (where OpenGL is available)
"$bin/isorender" c.ibv --iso 60 --size 120x90 --quiet --full --color '0.2,0.5,0.9' \
    --background '#ffe0c0:#102030' --azimuth 30 --elevation 20 -o gl.png --stats gl.json \
    --renderer opengl
render --full --color '0.2,0.5,0.9' --background '#ffe0c0:#102030' --azimuth 30 --elevation 20 \
    -o sw.png
if grep -q '"renderer": "opengl"' gl.json; then
    same "OpenGL and software agree with colours" gl.png sw.png --level 3 --max-pct 2
    # the turntable draws all its frames with one renderer: each frame is the image a run
    # of its own gives
    gl() { "$bin/isorender" c.ibv --iso 60 --size 120x90 --quiet --full --elevation 20 "$@"; }
    run_capture gl --turntable 3 --azimuth 30 -o glframes
    check "an OpenGL --turntable succeeds ($err)" test "$rc" = 0
    for f in 0 1 2; do
        gl --azimuth $((30 + 120 * f)) -o gl$f.png
        same "OpenGL turntable frame $f is its own run's image" glframes/frame_00$f.png gl$f.png \
            --level 1 --max-pct 0.1
    done
else
    echo "figure: no headless OpenGL here; the OpenGL comparison is skipped"
fi

# the turntable: N complete frames, the eye turned 360 / N degrees more each time
run_capture render --view -y --turntable 4 -o frames --lod off
check "--turntable succeeds" test "$rc" = 0
check "--turntable 4 writes 4 frames" test "$(ls frames | tr '\n' ' ')" = \
    "frame_000.png frame_001.png frame_002.png frame_003.png "
render --view -y --lod off -o plain.png
same "frame 0 is the plain image" frames/frame_000.png plain.png
render --view -y --azimuth 90 --lod off -o turned.png
same "frame 1 is the image turned by 90 degrees" frames/frame_001.png turned.png
expect_error 1 "exists" render --view -y --turntable 4 -o frames --lod off
run_capture render --full --view -y --turntable 2 -o frames --force --azimuth 90
check "--turntable --full --force succeeds" test "$rc" = 0
same "a full turntable's frame 0 is its azimuth's image" frames/frame_000.png y90.png
same "and frame 1 is half a turn further" frames/frame_001.png ym90.png --level 1 --max-pct 0.1
check "the folder keeps the older frames" test -e frames/frame_003.png
# --full-lod: the levels follow the eye, so each frame has its own full extraction, and it is
# the image of that frame's progressive run (a 4-pixel error: two levels in use)
render --view -y --pixel-error 4 --full-lod --stats lod.json -o lod.png
check "a 4-pixel error uses level 1" sh -c '! grep -q "\"level\": 1, \"bricks_touched\": 0," lod.json'
run_capture render --view -y --turntable 3 --pixel-error 4 --full-lod -o lodfull
check "--turntable --full-lod succeeds" test "$rc" = 0
run_capture render --view -y --turntable 3 --pixel-error 4 -o lodprog
for f in 0 1 2; do
    check "--full-lod turntable frame $f is the progressive frame" \
        cmp -s lodfull/frame_00$f.png lodprog/frame_00$f.png
done
: >afile
expect_error 1 "not a folder" render --turntable 2 -o afile

# the MP4: without ffmpeg, refused before any work, in one line, exit 1, nothing written
mkdir -p nobin
expect_error 1 "t.mp4: --mp4 needs ffmpeg, which is not on the PATH" env PATH="$work/nobin" \
    "$bin/isorender" c.ibv --iso 60 --size 120x90 --software --quiet --turntable 2 -o nf --mp4 t.mp4
check "and nothing is written" test ! -e nf -a ! -e t.mp4
# an ffmpeg that fails: the run fails as a whole, leaving no MP4, no frame and not the folder
# it made (its outputs are a set: all or none)
printf '#!/bin/sh\nexit 3\n' >nobin/ffmpeg
chmod +x nobin/ffmpeg
run_capture env PATH="$work/nobin" "$bin/isorender" c.ibv --iso 60 --size 120x90 --software \
    --quiet --turntable 2 -o nf --mp4 t.mp4 --force
check "a failing ffmpeg: exit 1, no MP4" sh -c '[ "$0" = 1 ] && [ ! -e t.mp4 ] && [ ! -e t.mp4.partial ]' "$rc"
check "... and no frames, nor the folder the run made" test ! -e nf
mkdir kept && : >kept/other.txt
run_capture env PATH="$work/nobin" "$bin/isorender" c.ibv --iso 60 --size 120x90 --software \
    --quiet --turntable 2 -o kept --mp4 t.mp4 --force
check "a folder that was there stays, with what it held, without the frames" \
    sh -c '[ "$0" = 1 ] && [ -e kept/other.txt ] && [ ! -e kept/frame_000.png ]' "$rc"
if command -v ffmpeg >/dev/null; then
    run_capture render --turntable 4 -o mf --mp4 t.mp4
    check "ffmpeg encodes the MP4" test "$rc" = 0
    check "the MP4 is an ISO media file" sh -c 'head -c 8 t.mp4 | tail -c 4 | grep -q ftyp'
else
    echo "figure: ffmpeg is not installed; the MP4 encoding is not tested"
fi
finish

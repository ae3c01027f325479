# SPDX-License-Identifier: BSD-3-Clause
# isorender --aa N: OpenGL multisampling. Silhouettes get intermediate colours, so the image
# comes closer to a 4 times larger one shrunk by a box filter; the rest of the image stays.
# Bad values are refused before any work.
. "$(dirname "$0")/lib.sh"

compare=$bin/tests/png_compare
# a black sphere on white: its silhouette is the only strong edge of the image
"$bin/isogen" sphere --dims 32x32x32 --type uint8 -o "$work/" --quiet
"$bin/isobrick" sphere_32x32x32_uint8.raw -o s.ibv --brick-size 8 --quiet
render() {
    "$bin/isorender" s.ibv --iso 128 --quiet --full --lod off --color 0,0,0 \
        --background '#ffffff' "$@"
}

expect_error 2 "--aa '0' is not a sample count (1 to 16)" render --aa 0 -o x.png
expect_error 2 "--aa '17' is not a sample count (1 to 16)" render --aa 17 -o x.png
expect_error 2 "--aa 'four' is not a sample count (1 to 16)" render --aa four -o x.png
expect_error 2 "--aa '-4' is not a sample count (1 to 16)" render --aa -4 -o x.png
expect_error 2 "--aa is OpenGL's" render --aa 4 --software -o x.png
check "a refused run writes nothing" test ! -e x.png

render --size 120x90 --aa 1 --renderer opengl -o one.png --stats one.json
if ! grep -q '"renderer": "opengl"' one.json; then
    echo "antialias: no headless OpenGL here; --aa is not tested further"
    finish
fi
render --size 120x90 --aa 4 -o four.png --stats four.json
check "--aa draws with OpenGL, --renderer auto or not" grep -q '"renderer": "opengl"' four.json
# auto (the default) without --aa: software where OpenGL is itself software (llvmpipe), which
# the window tests see (tests/tools/isoview.sh); here one of the two, the image alike
render --size 120x90 -o auto.png --stats auto.json
check "auto draws with one of the renderers" grep -q '"renderer": "\(software\|opengl\)"' auto.json
check "auto's image is --aa 1's" "$compare" auto.png one.png --level 3 --max-pct 2
render --size 480x360 --aa 1 -o big.png
render --size 120x90 --software -o sw.png

# --aa 1 is the image without anti-aliasing, the software rasterizer's within the GL tolerance
check "--aa 1 matches the software image" "$compare" one.png sw.png --level 3 --max-pct 2
# --aa 4: the silhouette changes, nothing else (the sphere's edge is under 2 % of the pixels)
check "--aa 4 changes the silhouette" sh -c "! '$compare' one.png four.png --level 16"
check "--aa 4 keeps the rest" "$compare" one.png four.png --level 3 --max-pct 2
# and comes closer to the large image box-filtered to the same size
d1=$("$compare" one.png big.png --box 4)
d4=$("$compare" four.png big.png --box 4)
check "--aa 4 is closer to the filtered large image ($d4 < $d1)" \
    awk -v a="$d4" -v b="$d1" 'BEGIN { exit !(a < 0.75 * b) }'
finish

# SPDX-License-Identifier: BSD-3-Clause
# isorender --measure, --largest, --min-area and --stats' "surface": a sphere's area and volume
# within 1 % of 4 pi r^2 and 4/3 pi r^3 (r from its bounding box), the Shepp-Logan phantom's
# components, the cleaning written to the file, STL without degenerate triangles, the
# progressive run's warning and the bad command lines. Where VTK is importable and the shared
# CT head is there, the figures against VTK's on every second sample of the head.
here=$(cd "$(dirname "$0")" && pwd) # before lib.sh moves to the scratch folder
. "$here/lib.sh"

# surface KEY FILE: a member of --stats' "surface" (largest.KEY for the largest's)
surface() {
    python3 -c 'import json, sys
s = json.load(open(sys.argv[2]))["surface"]
for k in sys.argv[1].split("."):
    s = s[k]
print(str(s).lower())' "$1" "$2"
}

"$bin/isogen" sphere --dims 64x64x64 -o "$work/" --quiet
"$bin/isobrick" sphere_64x64x64_uint16.raw -o s.ibv --quiet
run_capture "$bin/isorender" s.ibv --iso 2000 --full --size 64x64 --software --measure \
    --stats s.json --mesh s.ply -o s.png
check "a sphere measured" test "$rc" = 0 -a -z "$err"
check "the summary's lines" sh -c 'printf "%s" "$0" | grep -q "^  surface  .*area .*(closed)$" &&
    printf "%s" "$0" | grep -q "^  components    1; largest"' "$out"
check "closed, one component" test "$(surface closed s.json)/$(surface components s.json)" = true/1
check "area and volume within 1 % of the sphere's" python3 -c 'import json, math, sys
s = json.load(open(sys.argv[1]))["surface"]
r = sum(h - l for h, l in zip(s["bbox"]["max"], s["bbox"]["min"])) / 6
a, v = 4 * math.pi * r * r, 4 / 3 * math.pi * r ** 3
sys.exit(not (abs(s["area"] / a - 1) < 0.01 and abs(s["volume"] / v - 1) < 0.01 and r > 15))' s.json
check "the file holds the triangles measured" sh -c \
    '"$0" --topology s.ply | grep -q "faces $1 "' "$bin/tests/ply_triangles" "$(surface triangles s.json)"

"$bin/isogen" shepp-logan --dims 64x64x64 --type uint8 -o "$work/" --quiet
"$bin/isobrick" shepp-logan_64x64x64_uint8.raw -o p.ibv --brick-size 16 --quiet
render() { run_capture "$bin/isorender" p.ibv --iso 20.5 --size 80x60 --software --full "$@"; }
render --stats all.json --mesh all.ply -o all.png
check "the phantom's outline: 4 components" test "$(surface components all.json)" = 4
render --largest --stats big.json --mesh big.ply -o big.png
check "--largest: one component left, 3 removed" test \
    "$(surface components big.json)/$(surface removed_components big.json)" = 1/3
check "--largest keeps the largest's triangles" test \
    "$(surface triangles big.json)" = "$(surface largest.triangles all.json)"
check "the file holds them" sh -c '"$0" --topology big.ply | grep -q "faces $1 "' \
    "$bin/tests/ply_triangles" "$(surface triangles big.json)"
check "--largest: the image is the extracted surface's" cmp -s all.png big.png
# just under the largest's area (printed to 9 digits), far over the others'
cut=$(python3 -c 'import sys; print(float(sys.argv[1]) * 0.999)' "$(surface largest.area all.json)")
render --min-area "$cut" --stats cut.json -o cut.png
check "--min-area at the largest's area keeps it alone" test \
    "$(surface components cut.json)/$(surface triangles cut.json)" = "1/$(surface triangles big.json)"
render --min-area 0 --measure -o zero.png
check "--min-area 0 keeps everything" sh -c 'printf "%s" "$0" | grep -q "^  components    4;"' "$out"

render --mesh all.stl -o stl.png
check "STL: as many triangles as the welded mesh (no degenerate one)" test \
    "$(( ($(stat -c %s all.stl) - 84) / 50 ))" = "$(surface triangles all.json)"

run_capture "$bin/isorender" p.ibv --iso 20.5 --size 80x60 --software --measure --stats prog.json \
    -o prog.png
check "a progressive run's figures: a warning" sh -c 'printf "%s" "$0" | grep -q "warning: the surface.s figures are for the part this view extracted"' "$err"
check "... in --stats' warnings" grep -q '"warnings": \[[^]]*figures are for the part' prog.json

for bad in -1 nan x inf ""; do
    expect_error 2 "--min-area '$bad' is not an area of 0 or more" "$bin/isorender" p.ibv \
        --iso 20.5 --full --min-area "$bad" --mesh x.ply -o x.png
done
expect_error 2 "need --mesh, --measure or --stats" "$bin/isorender" p.ibv --iso 20.5 --full --largest -o x.png
expect_error 2 "no --no-weld" "$bin/isorender" p.ibv --iso 20.5 --full --largest --no-weld --mesh x.ply -o x.png
expect_error 2 "no --measure" "$bin/isorender" p.ibv --iso 20.5 --measure --turntable 2 -o frames/
check "nothing written after a usage error" test ! -e x.ply -a ! -e x.png -a ! -e frames

# Against VTK (where importable) on every second sample of the CT head (its skin at 600.5).
head="${IP_SHARED_DATA:-}/ct_head_visible_woman_512x512x234_uint16.raw"
vtk_python=""
for p in python3 /usr/bin/python3; do
    if "$p" -c "import vtk, numpy" 2>/dev/null; then vtk_python=$p; break; fi
done
if [ -n "$vtk_python" ] && [ -e "$head" ]; then
    small=$("$vtk_python" "$here/measure_subsample.py" "$head" "$work")
    "$bin/isobrick" "$small" -o head.ibv --quiet
    run_capture "$bin/isorender" head.ibv --iso 600.5 --full --size 64x64 --software \
        --stats head.json --mesh head.ply -o head.png
    check "the head measured" test "$rc" = 0
    "$bin/isorender" head.ibv --iso 600.5 --full --size 64x64 --software --largest \
        --stats head_big.json -o head_big.png --quiet
    set -- $("$vtk_python" "$here/measure_vtk.py" head.ply)
    check "area within 0.5 % of vtkMassProperties' ($(surface area head.json) vs $1)" \
        python3 -c 'import sys; sys.exit(not abs(float(sys.argv[1]) / float(sys.argv[2]) - 1) < 0.005)' \
        "$(surface area head.json)" "$1"
    check "components: VTK's regions ($(surface components head.json) vs $2)" \
        test "$(surface components head.json)" = "$2"
    check "--largest: VTK's largest region ($(surface triangles head_big.json) vs $3)" \
        test "$(surface triangles head_big.json)" = "$3"
else
    echo "measure: VTK or the CT head not found: its comparison skipped"
fi
finish

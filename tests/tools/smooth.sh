# SPDX-License-Identifier: BSD-3-Clause
# isorender --smooth N: Taubin smoothing of the mesh file. The Shepp-Logan phantom is piecewise
# constant, so its surfaces terrace (here the head's outline, at 20.5): smoothing keeps the
# counts and the closed topology, makes neighbouring triangles' normals closer and barely
# changes the enclosed volume; the image is the extracted surface's, unchanged. Bad counts and
# --no-weld are usage errors.
. "$(dirname "$0")/lib.sh"

"$bin/isogen" shepp-logan --dims 64x64x64 --type uint8 -o "$work/" --quiet
"$bin/isobrick" shepp-logan_64x64x64_uint8.raw -o p.ibv --brick-size 16 --quiet
render() { run_capture "$bin/isorender" p.ibv --iso 20.5 --size 80x60 --software --full "$@"; }
topology() { "$bin/tests/ply_triangles" --topology "$1"; }
shape() { "$bin/tests/ply_triangles" --shape "$1"; }
# field NAME LINE: the number after NAME in a line of ply_triangles
field() { printf '%s\n' "$2" | sed -n "s/.*$1 \([-0-9.e+]*\).*/\1/p"; }

render --mesh plain.ply -o plain.png
check "without --smooth" test "$rc" = 0
render --smooth 10 --mesh smooth.ply -o smooth.png
check "--smooth 10 succeeds" test "$rc" = 0 -a -z "$err"
check "the summary says the mesh is smoothed" sh -c 'printf "%s" "$0" | grep -q "mesh  *smooth.ply: .*(shared), smoothed"' "$out"
before=$(topology plain.ply) after=$(topology smooth.ply)
check "the same vertex, edge and face counts ($before; $after)" test "$before" = "$after"
check "closed before and after" test "$(field open "$after")" = 0
check "the positions changed" sh -c '! cmp -s "$0" "$1"' plain.ply smooth.ply
check "the image is the extracted surface's" cmp -s plain.png smooth.png
s0=$(shape plain.ply) s1=$(shape smooth.ply)
a0=$(field normal_angle "$s0") a1=$(field normal_angle "$s1")
v0=$(field volume "$s0") v1=$(field volume "$s1")
check "neighbouring normals closer: $a0 -> $a1 degrees" awk -v a="$a0" -v b="$a1" 'BEGIN { exit !(b < 0.5 * a) }'
check "the volume changes by less than 1 %: $v0 -> $v1" awk -v a="$v0" -v b="$v1" 'BEGIN { d = (b - a) / a; exit !(d < 0.01 && d > -0.01) }'
render --smooth 0 --mesh zero.ply -o zero.png
check "--smooth 0 changes nothing" cmp -s plain.ply zero.ply

render --smooth 10 --mesh smooth.stl -o stl.png
check "--smooth with STL" test "$rc" = 0
render --mesh plain.stl -o stl2.png
check "the STL holds as many triangles, moved" sh -c \
    'test "$(stat -c %s "$0")" = "$(stat -c %s "$1")" && ! cmp -s "$0" "$1"' smooth.stl plain.stl

for bad in -1 x 1.5 ""; do
    expect_error 2 "--smooth '$bad' is not an iteration count (0 to 100000)" "$bin/isorender" p.ibv --iso 20.5 --full --smooth "$bad" --mesh x.ply -o x.png
done
expect_error 2 "--no-weld" "$bin/isorender" p.ibv --iso 20.5 --full --smooth 5 --no-weld --mesh x.ply -o x.png
expect_error 2 "needs --mesh" "$bin/isorender" p.ibv --iso 20.5 --full --smooth 5 -o x.png
check "nothing written after a usage error" test ! -e x.ply -a ! -e x.png
finish

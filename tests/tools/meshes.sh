# SPDX-License-Identifier: BSD-3-Clause
# isorender's mesh files: shared vertices by default (--weld) or not (--no-weld), the same
# triangles either way; a fully extracted sphere comes out closed, a progressive run's mesh
# open (and a note says so); binary glTF.
. "$(dirname "$0")/lib.sh"

"$bin/isogen" sphere --dims 40x44x36 --type uint8 -o "$work/" --quiet
"$bin/isobrick" sphere_40x44x36_uint8.raw -o s.ibv --brick-size 8 --quiet
render() { run_capture "$bin/isorender" s.ibv --iso 100.5 --size 80x60 --software "$@"; }
topology() { "$bin/tests/ply_triangles" --topology "$1"; }
# field NAME TOPOLOGY: the number after NAME in a topology line
field() { printf '%s\n' "$2" | sed -n "s/.*$1 \([0-9]*\).*/\1/p"; }

render --full --mesh w.ply -o w.png --stats w.json
check "--full --mesh succeeds" test "$rc" = 0
check "no note about open meshes with --full" test -z "$err"
check "the summary gives the mesh's vertices" sh -c 'printf "%s" "$0" | grep -q "mesh  *w.ply: [0-9]* triangles, [0-9]* vertices (shared)"' "$out"
t=$(topology w.ply)
v=$(field vertices "$t") e=$(field edges "$t") f=$(field faces "$t")
check "the welded sphere is closed ($t)" test "$(field open "$t")" = 0 -a "$(field repeated "$t")" = 0
check "every edge in two triangles ($e edges, $f faces)" test $((2 * e)) = $((3 * f))
check "V - E + F = 2 ($v - $e + $f)" test $((v - e + f)) = 2

render --full --weld --mesh w2.ply -o w2.png
check "--weld is the default" cmp -s w.ply w2.ply
render --full --no-weld --mesh u.ply -o u.png
check "--no-weld succeeds" test "$rc" = 0
t=$(topology u.ply)
triangles=$(json_number triangles w.json)
check "--no-weld: 3 vertices for each of the $triangles triangles ($t)" \
    test "$(field vertices "$t")" = $((3 * triangles)) -a "$(field faces "$t")" = "$triangles"
"$bin/tests/ply_triangles" w.ply >w.txt
"$bin/tests/ply_triangles" u.ply >u.txt
check "welded and not, the same triangles in the same order" cmp -s w.txt u.txt
check "as many as extracted" test "$(grep -c . u.txt)" = "$triangles"
check "the welded file is smaller" test "$(stat -c %s w.ply)" -lt "$(stat -c %s u.ply)"
expect_error 2 "--no-weld" "$bin/isorender" s.ibv --iso 100.5 --weld --no-weld --mesh x.ply -o x.png

# a progressive run keeps what the view needed: open behind, and a note says so
render --mesh p.ply -o p.png
check "progressive --mesh succeeds" test "$rc" = 0
check "a note says the mesh is open and --full closes it" sh -c \
    'printf "%s\n" "$0" | grep -c . | grep -qx 1 && printf "%s" "$0" | grep -q "note: p.ply .*--full"' "$err"
t=$(topology p.ply)
check "the progressive mesh is open ($t)" test "$(field open "$t")" -gt 0
render --mesh q.ply -o q.png --quiet
check "--quiet: no note" test -z "$err"

# binary glTF: the container's header, and its length is the file's
render --full --mesh g.glb -o g.png
check "--mesh .glb succeeds" test "$rc" = 0
check "the glTF magic and version 2" test "$(od -An -tx1 -N8 g.glb | tr -d ' ')" = 676c544602000000
check "the header's length is the file's" test "$(od -An -tu4 -j8 -N4 g.glb | tr -d ' ')" = "$(stat -c %s g.glb)"
check "positions, normals and indices" sh -c 'head -c 2000 g.glb | grep -q "\"indices\":2" && head -c 2000 g.glb | grep -q "\"NORMAL\":1"'
render --full --no-weld --mesh n.glb -o n.png
check "--no-weld glTF has no indices" sh -c '! head -c 2000 n.glb | grep -q "\"indices\""'
expect_error 2 ".glb" "$bin/isorender" s.ibv --iso 100.5 --mesh x.gltf -o x.png
check "nothing written for an unknown format" test ! -e x.gltf -a ! -e x.png
finish

# Physical space end to end: a NRRD header with a space, a space origin and turned space
# directions bricks to a file whose isoinfo shows them (the spacing being the vectors'
# lengths), and a header that names nothing bricks to the identity.
. "$(dirname "$0")/lib.sh"

"$bin/isogen" sphere --dims 24x20x16 -o "$work/" --quiet
raw=$(ls sphere_24x20x16_*.raw)
type=${raw##*_}
type=${type%.raw}
# x and y turned 90 degrees about z (x runs along +y, y along -x), spacings 0.5, 0.5, 2
cat >turned.nhdr <<NHDR
NRRD0004
type: $type
dimension: 3
sizes: 24 20 16
space: left-posterior-superior
space directions: (0,0.5,0) (-0.5,0,0) (0,0,2)
space origin: (10,-20,30.5)
endian: little
encoding: raw
data file: $raw
NHDR
run_capture "$bin/isobrick" turned.nhdr -o turned.ibv --brick-size 8 --threads 2
check "the turned NRRD bricks ($err)" test "$rc" = 0
run_capture "$bin/isoinfo" --json turned.ibv
check "isoinfo --json: the spacing is the vectors' lengths" grep -qF '"spacing": [0.5, 0.5, 2]' "$work/.out"
check "isoinfo --json: origin, directions and space" \
    grep -qF '"origin": [10, -20, 30.5], "directions": [[0, 1, 0], [-1, 0, 0], [0, 0, 1]], "space": "LPS"' \
    "$work/.out"
run_capture "$bin/isoinfo" turned.ibv
check "isoinfo: the origin line" grep -qF "origin        10, -20, 30.5 (LPS space)" "$work/.out"
check "isoinfo: the directions line" \
    grep -qF "directions    x (0, 1, 0), y (-1, 0, 0), z (0, 0, 1)" "$work/.out"
check "the turned file verifies" "$bin/isoinfo" --verify turned.ibv

# the same samples without a space: identity, no space named
sed '/^space/d; s/^dimension: 3/dimension: 3\nspacings: 0.5 0.5 2/' turned.nhdr >plain.nhdr
run_capture "$bin/isobrick" plain.nhdr -o plain.ibv --brick-size 8 --threads 2
check "the plain NRRD bricks ($err)" test "$rc" = 0
run_capture "$bin/isoinfo" --json plain.ibv
check "no space: identity" \
    grep -qF '"origin": [0, 0, 0], "directions": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "space": null' \
    "$work/.out"

# the mesh in physical space: the plain file's vertices moved by origin + D * p
for name in turned plain; do
    run_capture "$bin/isorender" "$name.ibv" --iso 128 --full --threads 1 --size 64x48 \
        -o "$name.png" --mesh "$name.ply" --no-weld
    check "isorender --full --mesh on $name ($err)" test "$rc" = 0
    "$bin/tests/ply_triangles" "$name.ply" >"$name.txt"
done
check "a surface was extracted" test -s plain.txt
check "the same image either way" cmp -s turned.png plain.png
check "turned vertices = (10 - y, -20 + x, 30.5 + z) of the plain ones" python3 -c '
import sys
a = [l.split() for l in open("plain.txt")]
b = [l.split() for l in open("turned.txt")]
assert len(a) == len(b) > 0, (len(a), len(b))
worst = 0.0
for ta, tb in zip(a, b):
    for i in range(0, 9, 3):
        x, y, z = (float.fromhex(v) for v in ta[i:i + 3])
        want = (10 - y, -20 + x, 30.5 + z)
        got = [float.fromhex(v) for v in tb[i:i + 3]]
        worst = max(worst, max(abs(g - w) for g, w in zip(got, want)))
assert worst < 1e-4, worst
'

# a sheared grid has no orthonormal frame: the identity, and the vectors' lengths as spacing
sed 's/^space directions:.*/space directions: (0.5,0.5,0) (0,0.5,0) (0,0,2)/' turned.nhdr >sheared.nhdr
run_capture "$bin/isobrick" sheared.nhdr -o sheared.ibv --brick-size 8 --threads 2
check "the sheared NRRD bricks ($err)" test "$rc" = 0
run_capture "$bin/isoinfo" --json sheared.ibv
check "sheared: identity directions" \
    grep -qF '"directions": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "space": "LPS"' "$work/.out"
finish

# SPDX-License-Identifier: BSD-3-Clause
# Physical space end to end: a NRRD header with a space, a space origin and turned space
# directions bricks to a file whose isoinfo shows them (the spacing being the vectors'
# lengths), and a header that names nothing bricks to the identity. The same turn written as
# a NIfTI sform (pixdim left at 1: the sform's column lengths are the spacing) and as a
# MetaImage TransformMatrix and Offset, and a NIfTI qform (a half turn about z, qfac -1),
# give the origin, directions and space isoinfo shows and the mesh's physical vertices. The
# views are the physical space's: the turned file's front is the plain file's side.
. "$(dirname "$0")/lib.sh"
match="python3 $(dirname "$0")/mesh_match.py"

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
# the same samples, turned in physical space: the same surface, each cell triangulated in the
# physical frame (the turned file's quadrilaterals split the other way where the turn says)
check "turned vertices = (10 - y, -20 + x, 30.5 + z) of the plain ones" \
    $match plain.txt turned.txt "(10 - y, -20 + x, 30.5 + z)" --vertices
check "as many triangles either way" test "$(wc -l <plain.txt)" = "$(wc -l <turned.txt)"
# the turned file's default view, anterior (LPS: physical -y, world -x), sees what the plain
# file's -x view sees, shaded across those quadrilaterals otherwise in places
"$bin/isorender" plain.ibv --iso 128 --full --threads 1 --size 64x48 --view -x -o side.png \
    --quiet
check "the turned file's front is the plain file's side" \
    "$bin/tests/png_compare" turned.png side.png --level 12 --max-pct 0.5

# the file names its space: the file's (LPS), "volume" for one that names none, "grid" for
# --mesh-grid, whose vertices are the plain ones (index x spacing from 0) whatever the space
check "the turned mesh names its space" grep -aq '^comment space LPS$' turned.ply
check "the plain mesh names the volume's own axes" grep -aq '^comment space volume$' plain.ply
run_capture "$bin/isorender" turned.ibv --iso 128 --full --threads 1 --size 64x48 \
    -o grid.png --mesh grid.ply --no-weld --mesh-grid
check "isorender --mesh-grid ($err)" test "$rc" = 0
check "the grid mesh says so" grep -aq '^comment space grid$' grid.ply
"$bin/tests/ply_triangles" grid.ply >grid.txt
# (the same vertices: the turned file's cells are split along its physical frame's diagonals)
check "--mesh-grid: the plain file's vertices" $match plain.txt grid.txt --vertices
check "--mesh-grid: as many triangles" test "$(wc -l <grid.txt)" = "$(wc -l <plain.txt)"
for ext in obj stl glb; do
    "$bin/isorender" turned.ibv --iso 128 --full --threads 1 --size 64x48 -o m.png -f \
        --mesh "turned.$ext" --quiet
done
check "OBJ names the space" grep -q '^# space LPS$' turned.obj
check "STL's header names the space" sh -c 'head -c 80 turned.stl | grep -aq "space LPS"'
check "glTF's asset extras name the space" grep -aqF '"extras":{"space":"LPS"}' turned.glb
expect_error 2 "needs --mesh" "$bin/isorender" turned.ibv --iso 128 --mesh-grid -o x.png

# nifti NAME PIXDIM(3) QFAC QFORM_CODE QUATERN(3) QOFFSET(3) SFORM_CODE SROW(12): a NIfTI-1 file
# of the sphere's samples, written field by field (offsets of the NIfTI-1 header)
nifti() {
    python3 - "$raw" "$type" "$@" <<'PY'
import struct, sys
raw, kind, name = sys.argv[1:4]
v = [float(x) for x in sys.argv[4:]]
pixdim, qfac, qcode = v[0:3], v[3], int(v[4])
quatern, qoffset, scode, srow = v[5:8], v[8:11], int(v[11]), v[12:24]
datatype, bits = {"uint8": (2, 8), "uint16": (512, 16)}[kind]
h = bytearray(352)
struct.pack_into("<i", h, 0, 348)
struct.pack_into("<8h", h, 40, 3, 24, 20, 16, 1, 1, 1, 1)
struct.pack_into("<2h", h, 70, datatype, bits)
struct.pack_into("<4f", h, 76, qfac, *pixdim)
struct.pack_into("<f", h, 108, 352)
h[123] = 2
struct.pack_into("<2h", h, 252, qcode, scode)
struct.pack_into("<6f", h, 256, *quatern, *qoffset)
struct.pack_into("<12f", h, 280, *srow)
h[344:348] = b"n+1\0"
with open(name, "wb") as f:
    f.write(h + open(raw, "rb").read())
PY
}
# the turn: srow_x = (0, -0.5, 0, 10), srow_y = (0.5, 0, 0, -20), srow_z = (0, 0, 2, 30.5)
nifti sform.nii 1 1 1 1 0 0 0 0 0 0 0 2 0 -0.5 0 10 0.5 0 0 -20 0 0 2 30.5
# a half turn about z (quaternion b, c, d = 0, 0, 1), the third axis flipped by qfac -1
nifti qform.nii 0.5 0.5 2 -1 1 0 0 1 1 2 3 0 9 9 9 9 9 9 9 9 9 9 9 9
cat >turned.mhd <<MHD
ObjectType = Image
NDims = 3
BinaryData = True
BinaryDataByteOrderMSB = False
TransformMatrix = 0 1 0 -1 0 0 0 0 1
Offset = 10 -20 30.5
AnatomicalOrientation = RAI
ElementSpacing = 0.5 0.5 2
DimSize = 24 20 16
ElementType = MET_$(test "$type" = uint8 && echo UCHAR || echo USHORT)
ElementDataFile = $raw
MHD
for name in sform qform mhd; do
    input=$name.nii
    test "$name" = mhd && input=turned.mhd
    run_capture "$bin/isobrick" "$input" -o "$name.ibv" --brick-size 8 --threads 2
    check "$input bricks ($err)" test "$rc" = 0
    run_capture "$bin/isoinfo" --json "$name.ibv"
    check "isoinfo --json on $name: the spacing" grep -qF '"spacing": [0.5, 0.5, 2]' "$work/.out"
    case $name in
    sform) want='"origin": [10, -20, 30.5], "directions": [[0, 1, 0], [-1, 0, 0], [0, 0, 1]], "space": "RAS"' ;;
    qform) want='"origin": [1, 2, 3], "directions": [[-1, 0, 0], [0, -1, 0], [0, 0, -1]], "space": "RAS"' ;;
    mhd) want='"origin": [10, -20, 30.5], "directions": [[0, 1, 0], [-1, 0, 0], [0, 0, 1]], "space": null' ;;
    esac
    check "isoinfo --json on $name: origin, directions and space" grep -qF "$want" "$work/.out"
    run_capture "$bin/isorender" "$name.ibv" --iso 128 --full --threads 1 --size 64x48 \
        -o "$name.png" --mesh "$name.ply" --no-weld
    check "isorender --full --mesh on $name ($err)" test "$rc" = 0
    "$bin/tests/ply_triangles" "$name.ply" >"$name.txt"
done
run_capture "$bin/isoinfo" sform.ibv
check "isoinfo: the NIfTI origin line" grep -qF "origin        10, -20, 30.5 (RAS space)" "$work/.out"
check "isoinfo: the NIfTI directions line" \
    grep -qF "directions    x (0, 1, 0), y (-1, 0, 0), z (0, 0, 1)" "$work/.out"
# moved: compares the vertices of plain.txt moved by the expression with those of the file
moved() { $match plain.txt "$1" "$2" --vertices; }
check "NIfTI sform vertices = (10 - y, -20 + x, 30.5 + z)" moved sform.txt '(10 - y, -20 + x, 30.5 + z)'
check "NIfTI qform vertices = (1 - x, 2 - y, 3 - z)" moved qform.txt '(1 - x, 2 - y, 3 - z)'
check "MetaImage vertices = (10 - y, -20 + x, 30.5 + z)" moved mhd.txt '(10 - y, -20 + x, 30.5 + z)'

# a sheared grid has no orthonormal frame: the identity, and the vectors' lengths as spacing
sed 's/^space directions:.*/space directions: (0.5,0.5,0) (0,0.5,0) (0,0,2)/' turned.nhdr >sheared.nhdr
run_capture "$bin/isobrick" sheared.nhdr -o sheared.ibv --brick-size 8 --threads 2
check "the sheared NRRD bricks ($err)" test "$rc" = 0
run_capture "$bin/isoinfo" --json sheared.ibv
check "sheared: identity directions" \
    grep -qF '"directions": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "space": "LPS"' "$work/.out"
finish

# SPDX-License-Identifier: BSD-3-Clause
# DICOM series end to end: isobrick bricks a series written by the tests (shuffled file order,
# transfer syntaxes by turns: explicit and implicit VR little endian, explicit VR big endian,
# RLE) to the same samples as the raw volume it was made from, reports and keeps the rescale (a
# CT's: Hounsfield units, as the raw volume bricked with --rescale 1,-1024,HU), and refuses a
# broken series in one line naming it.
. "$(dirname "$0")/lib.sh"

"$bin/tests/make_dicom" "$work" || { bad "make_dicom writes the series"; finish; }
raw=volume_40x36x13_int16.raw

run_capture "$bin/isobrick" series -o dicom.ibv --brick-size 8 --threads 2
check "isobrick bricks the series folder ($err)" test "$rc" = 0
check "the summary reports the rescale" grep -qF "stored x 1 - 1024" "$work/.out"
run_capture "$bin/isobrick" "$raw" -o plain.ibv --brick-size 8 --threads 2 --spacing 0.8,0.7,2.5
check "isobrick bricks the raw volume" test "$rc" = 0
check "no rescale for raw input" sh -c '! grep -q rescale "$0"' "$work/.out"
run_capture "$bin/isobrick" "$raw" -o raw.ibv --brick-size 8 --threads 2 --spacing 0.8,0.7,2.5 \
    --rescale 1,-1024,HU
check "isobrick bricks the raw volume with the CT's rescale" test "$rc" = 0

run_capture "$bin/isobrick" series/ --quiet
check "a folder's default output is bricks/FOLDER.ibv" test -s bricks/series.ibv

# the same dims, type, spacing, value range and rescale; the file name and the physical space
# aside, the same description
"$bin/isoinfo" --json dicom.ibv >dicom_space.json
strip_space() { sed 's/"file": "[^"]*", //; s/"origin": .*"space": [^,]*, //' "$1"; }
"$bin/isoinfo" --json raw.ibv >raw_space.json
strip_space dicom_space.json >dicom.json
strip_space raw_space.json >raw.json
check "isoinfo describes both alike" cmp -s dicom.json raw.json
# the first slice by position is at (-12.5, 30, -40), rows along x, columns along y: LPS
check "the origin is the first slice's position" \
    grep -qF '"origin": [-12.5, 30, -40], "directions": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "space": "LPS"' \
    dicom_space.json
check "raw input has no physical space" \
    grep -qF '"origin": [0, 0, 0], "directions": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "space": null' \
    raw_space.json
check "the series keeps its rescale" grep -qF \
    '"rescale": {"slope": 1, "intercept": -1024, "unit": "HU"}' dicom.json
check "the spacing comes from the headers" grep -q '"spacing": \[0.8000.*, 0.6999.*, 2.5\]' dicom.json
check "isoinfo --verify passes" "$bin/isoinfo" --verify dicom.ibv

# the same samples: every cell's triangles, extracted in one thread, byte for byte
# (the series' mesh lies in its LPS space: the raw volume's moved by the origin); 476.5 HU is
# the stored value 1500.5
for f in dicom raw; do
    "$bin/isorender" "$f.ibv" --iso 476.5 --full --threads 1 --software --size 64x48 \
        --mesh "$f.ply" -o "$f.png" --quiet --no-weld
    "$bin/tests/ply_triangles" "$f.ply" >"$f.txt"
done
"$bin/isorender" plain.ibv --iso 1500.5 --full --threads 1 --software --size 64x48 \
    -o plain.png --quiet
check "476.5 HU draws what the stored value 1500.5 draws without a rescale" \
    cmp -s dicom.png plain.png
check "a surface was extracted" test -s dicom.txt
check "the same triangles from the series as from the raw volume, moved" python3 -c '
a = [l.split() for l in open("raw.txt")]
b = [l.split() for l in open("dicom.txt")]
assert len(a) == len(b) > 0, (len(a), len(b))
origin = (-12.5, 30, -40)
for ta, tb in zip(a, b):
    for i in range(9):
        want = float.fromhex(ta[i]) + origin[i % 3]
        assert abs(float.fromhex(tb[i]) - want) < 1e-4, (ta, tb)
'
check "the same image" cmp -s dicom.png raw.png

# broken series: exit 1, one line naming the folder or file, no output
cp -r series gap
rm gap/IM0005.dcm
expect_error 1 "a slice is missing between" "$bin/isobrick" gap -o gap.ibv
check "the gap message names the folder" sh -c 'printf "%s" "$0" | grep -q "gap:"' "$err"
check "no output after a missing slice" test ! -e gap.ibv
mkdir empty
expect_error 1 "empty: the folder holds no files" "$bin/isobrick" empty -o empty.ibv
cp -r series stranger
echo "scanned on Tuesday" >stranger/notes.txt
expect_error 1 "stranger/notes.txt: not a DICOM file" "$bin/isobrick" stranger -o s.ibv
check "no output after a stranger" test ! -e s.ibv

finish

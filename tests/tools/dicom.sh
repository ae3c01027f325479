# SPDX-License-Identifier: BSD-3-Clause
# DICOM series end to end: isobrick bricks a series written by the tests (shuffled file order,
# transfer syntaxes by turns: explicit and implicit VR little endian, explicit VR big endian,
# RLE) to the same samples as the raw volume it was made from, reports and keeps the rescale (a
# CT's: Hounsfield units, as the raw volume bricked with --rescale 1,-1024,HU), and refuses a
# broken series in one line naming it. A folder as scanners write it (a DIRFILE, a report and
# a presentation state beside two series in subfolders, one with a gantry tilt): the objects
# skipped and counted, the series listed, refused without a pick, picked; the tilted series
# resampled so that its surface lies where the ball it images is, or refused when asked; a
# slice missing refused, or resampled when asked.
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

# a slice missing: refused naming the option, resampled with it
expect_error 1 "gap: a slice is missing between IM0003.dcm (at -30 mm) and IM0007.dcm (at -25 mm): 5 mm apart, 2.0 times the slice spacing 2.5 mm (isobrick --even-spacing resamples them onto an even grid)" \
    "$bin/isobrick" gap -o gap.ibv
expect_error 1 "$raw: a gantry tilt or slice spacing choice was given, but this is not a folder of DICOM files" \
    "$bin/isobrick" "$raw" --even-spacing -o notdicom.ibv
expect_error 1 "$raw: a DICOM series was asked for, but this is not a folder of DICOM files" \
    "$bin/isobrick" "$raw" --series 1.2 -o notdicom.ibv
run_capture "$bin/isobrick" gap -o gap.ibv --even-spacing --quiet
check "--even-spacing bricks the series with a slice missing" test "$rc" = 0
"$bin/isoinfo" --json gap.ibv >gap.json 2>/dev/null
check "... on the full 13 planes, 2.5 mm apart" grep -q '"dims": \[40, 36, 13\].*"spacing": \[0.8[0-9]*, 0.69*[0-9]*, 2.5\]' gap.json

# a folder as a scanner writes it
ls bricks >bricks_before.txt
run_capture "$bin/isobrick" scanner --list-series
check "--list-series exits 0" test "$rc" = 0
check "--list-series counts the series and the objects skipped" \
    grep -qxF "scanner: 2 series, 3 DICOM objects that are not images skipped" "$work/.out"
check "--list-series gives UID, description, modality, slices, size and spacing" grep -qxF \
    '1.2.826.0.1.3680043.2.1125.1.1  "Head"  CT  13 slices  40x36x13 int16  spacing 0.8,0.7,2.5 mm' \
    "$work/.out"
check "--list-series says the tilt" grep -qxF \
    '1.2.826.0.1.3680043.2.1125.1.3  "Tilted head"  CT  13 slices  40x50x13 int16  spacing 0.8,0.7,2.36 mm  gantry tilt 18.5 degrees: resampled' \
    "$work/.out"
check "--list-series writes nothing" sh -c 'ls bricks | cmp -s - bricks_before.txt'
expect_error 1 "scanner: the folder holds 2 series: pick one by its UID (isobrick --series UID): 1.2.826.0.1.3680043.2.1125.1.1 \"Head\" CT 13 slices; 1.2.826.0.1.3680043.2.1125.1.3 \"Tilted head\" CT 13 slices" \
    "$bin/isobrick" scanner -o several.ibv
check "no output without a pick" test ! -e several.ibv
run_capture "$bin/isobrick" scanner --series 1.2.826.0.1.3680043.2.1125.1.1 -o picked.ibv \
    --brick-size 8 --threads 2
check "--series picks the series ($err)" test "$rc" = 0
check "the summary counts the objects skipped" \
    grep -qF "skipped     3 DICOM objects that are not images (by SOP class)" "$work/.out"
"$bin/isoinfo" --json picked.ibv | sed 's/"file": "[^"]*", //' >picked.json
sed 's/"file": "[^"]*", //' dicom_space.json >series.json
check "the series picked is the series alone" cmp -s picked.json series.json

# the tilted series: resampled by default, its surface where the ball is (centre -> mm, LPS;
# the iso value 1600 bounds a sphere of radius 10 mm), within half a voxel
run_capture "$bin/isobrick" scanner --series 1.2.826.0.1.3680043.2.1125.1.3 -o tilted.ibv \
    --brick-size 8 --threads 2
check "a prefix of one UID picks it ($err)" test "$rc" = 0
check "the summary says the tilt and the resampling" grep -qF \
    "resampled   gantry tilt of 18.5 degrees: the sheared slices resampled onto a regular 40x50x13 grid" \
    "$work/.out"
check "the resampled series keeps its rescale" sh -c \
    '"$0" --json tilted.ibv | grep -qF "\"rescale\": {\"slope\": 1, \"intercept\": -1024, \"unit\": \"HU\"}"' \
    "$bin/isoinfo"
"$bin/isorender" tilted.ibv --iso-stored 1600.5 --full --threads 1 --software --size 64x48 \
    --mesh tilted.ply -o tilted.png --quiet --no-weld
"$bin/tests/ply_triangles" tilted.ply >tilted.txt
check "the tilted ball's surface lies where the ball is" python3 -c '
import math
v = [float.fromhex(x) for l in open("tilted.txt") for x in l.split()[:9]]
p = [v[i:i + 3] for i in range(0, len(v), 3)]
assert len(p) > 300, len(p)
centre, radius, half = (3.1, 37.5, -25.84), 10.0, (0.4, 0.35, 1.18)
for a in range(3):
    lo, hi = min(q[a] for q in p), max(q[a] for q in p)
    assert abs((lo + hi) / 2 - centre[a]) < half[a], (a, lo, hi)
    assert abs((hi - lo) / 2 - radius) < half[a], (a, lo, hi)
r = [math.dist(q, centre) for q in p]
assert max(abs(x - radius) for x in r) < 0.35, (min(r), max(r))
'
expect_error 1 "tilted: gantry tilt: the slices stack 18.5 degrees off their normal" \
    "$bin/isobrick" tilted --no-correct-tilt -o refused.ibv
check "the refusal names --correct-tilt" sh -c 'printf "%s" "$0" | grep -qF -- "--correct-tilt"' "$err"
check "no output after a refused tilt" test ! -e refused.ibv
expect_error 2 "--correct-tilt and --no-correct-tilt" \
    "$bin/isobrick" tilted --correct-tilt --no-correct-tilt -o both.ibv

finish

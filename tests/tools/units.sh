# SPDX-License-Identifier: BSD-3-Clause
# The rescale end to end: a DICOM CT series (Hounsfield units = stored - 1024) bricks to a
# version 3 file that keeps its rescale; isoinfo shows it (text, --json, --histogram in HU);
# isorender takes --iso in HU and --iso-stored as a stored value, the two giving the very same
# triangles and image, and --stats writes both; the same volume bricked raw (no rescale) gives
# the same surface at the stored value and a version 2 file whose --stats and isoinfo keys are
# as before; isobrick --rescale sets or drops a rescale; isoview and isowall take --iso alike.
. "$(dirname "$0")/lib.sh"

"$bin/tests/make_dicom" "$work" --air || { bad "make_dicom --air writes the series"; finish; }
raw=volume_40x36x13_int16.raw
run_capture "$bin/isobrick" series -o ct.ibv --brick-size 8 --threads 2
check "isobrick bricks the CT series ($err)" test "$rc" = 0
check "isobrick says the rescale is kept and --iso is in HU" grep -qF \
    "rescale     HU = stored x 1 - 1024, kept: --iso in HU, --iso-stored in stored values" \
    "$work/.out"
"$bin/isobrick" "$raw" -o raw.ibv --brick-size 8 --threads 2 --spacing 0.8,0.7,2.5 --quiet

# --- isoinfo: the rescale, and the values in HU beside the stored ones ---
run_capture "$bin/isoinfo" ct.ibv
check "isoinfo: format version 3" grep -qF "format        version 3" "$work/.out"
check "isoinfo: the value range in HU, the stored one beside it ($out)" grep -qF \
    "value range   -1000 .. 933 HU (stored 24 .. 1957)" "$work/.out"
check "isoinfo: the rescale line" grep -qF "rescale       HU = stored x 1 - 1024" "$work/.out"
"$bin/isoinfo" --json ct.ibv >ct.json
check "isoinfo --json: the rescale" grep -qF \
    '"rescale": {"slope": 1, "intercept": -1024, "unit": "HU"}' ct.json
check "isoinfo --json: the values in HU, the stored ones beside them" grep -qF \
    '"value_min": -1000, "value_max": 933, "value_min_stored": 24, "value_max_stored": 1957' \
    ct.json
check "isoinfo --json: the levels' values in HU" grep -qF \
    '"level": 0, "dims": [40, 36, 13], "bricks": [5, 5, 2], "bytes_payload"' ct.json
check "isoinfo --json: level 0's values in HU" sh -c \
    'grep -o "\"level\": 0,[^}]*}" "$0" | grep -qF "\"value_min\": -1000, \"value_max\": 933"' \
    ct.json
"$bin/isoinfo" --json raw.ibv >raw.json
check "a file without a rescale: version 2, rescale null, values as stored" grep -qF \
    '"value_min": 24, "value_max": 1957, "rescale": null' raw.json
check "a file without a rescale: format version 2" grep -qF '"format_version": 2' raw.json
check "isoinfo --verify passes on version 3" "$bin/isoinfo" --verify ct.ibv

# --histogram: the bins' edges in HU (the stored ones beside them in JSON)
run_capture "$bin/isoinfo" ct.ibv --histogram --bins 4 --level 0
check "--histogram: bins over the range in HU ($out)" grep -qF \
    "4 bins over -1000 .. 936 HU (stored 24 .. 1960)" "$work/.out"
check "--histogram: the first bin from -1000 HU" sh -c \
    'grep -E "^ +-1000 +-516 " "$0" >/dev/null' "$work/.out"
"$bin/isoinfo" ct.ibv --histogram --bins 4 --level 0 --json >hist.json
check "--histogram --json: edges in HU, stored beside" grep -qF \
    '{"lo": -1000, "hi": -516, "lo_stored": 24, "hi_stored": 508' hist.json
"$bin/isoinfo" raw.ibv --histogram --bins 4 --level 0 --json >hist_raw.json
check "--histogram --json without a rescale: the stored edges, no stored keys" sh -c \
    'grep -qF "{\"lo\": 24, \"hi\": 508, \"count\"" "$0" && ! grep -q _stored "$0"' \
    hist_raw.json
check "both histograms count alike" test "$(sed 's/.*"bins"//' hist.json | grep -o '"count": [0-9]*')" = \
    "$(sed 's/.*"bins"//' hist_raw.json | grep -o '"count": [0-9]*')"

# --- isorender: --iso -500 (HU) is --iso-stored 524, triangle for triangle ---
render() { "$bin/isorender" "$@" --size 96x72 --software --threads 1 --quiet --force; }
for mode in progressive full; do
    flag=""
    [ "$mode" = full ] && flag=--full
    render ct.ibv --iso -500 $flag --mesh "hu_$mode.ply" -o "hu_$mode.png" --stats "hu_$mode.json"
    render ct.ibv --iso-stored 524 $flag --mesh "st_$mode.ply" -o "st_$mode.png" \
        --stats "st_$mode.json"
    render raw.ibv --iso 524 $flag -o "raw_$mode.png" --stats "raw_$mode.json"
    "$bin/tests/ply_triangles" "hu_$mode.ply" >"hu_$mode.txt"
    check "$mode: a surface at -500 HU" test "$(wc -l <"hu_$mode.txt")" -gt 100
    check "$mode: --iso -500 and --iso-stored 524 write the same mesh" \
        cmp -s "hu_$mode.ply" "st_$mode.ply"
    check "$mode: and the same image" cmp -s "hu_$mode.png" "st_$mode.png"
    check "$mode: the raw volume at stored 524 draws that image" cmp -s "hu_$mode.png" \
        "raw_$mode.png"
    for f in "hu_$mode.json" "st_$mode.json"; do
        check "$f: iso in HU, iso_stored, the rescale" grep -qF \
            '"iso": -500, "iso_stored": 524, "rescale": {"slope": 1, "intercept": -1024, "unit": "HU"}, "mode"' \
            "$f"
    done
    check "$mode: the same counts either way" test \
        "$(json_number triangles "hu_$mode.json")" = "$(json_number triangles "st_$mode.json")"
    check "$mode: without a rescale, --stats as before (no iso_stored, no rescale)" sh -c \
        'grep -qF "\"iso\": 524, \"mode\"" "$0" && ! grep -q "iso_stored\|rescale" "$0"' \
        "raw_$mode.json"
done
# --iso -500 on the stored values would be another surface: below every value, none
run_capture "$bin/isorender" ct.ibv --iso-stored -500 --size 32x24 --software -q -f -o no.png
check "--iso-stored -500 is below the stored values: warned in stored values ($err)" \
    sh -c 'printf "%s" "$0" | grep -qF -- "--iso-stored -500 is outside the value range of ct.ibv, 24 .. 1957:"' "$err"
run_capture "$bin/isorender" ct.ibv --iso 3000 --size 32x24 --software -q -f -o no.png
check "--iso 3000 HU: warned in HU ($err)" sh -c \
    'printf "%s" "$0" | grep -qF -- "--iso 3000 is outside the value range of ct.ibv, -1000 .. 933 HU:"' "$err"
# the summary says the unit
run_capture "$bin/isorender" ct.ibv --iso -500 --size 32x24 --software -f -o s.png
check "the summary gives iso -500 HU" grep -qF "ct.ibv: iso -500 HU, progressive, 32x24" \
    "$work/.out"

# several surfaces: each in HU, each with its stored value
render ct.ibv --iso -500 --iso 200 -o two.png --stats two.json
check "several --iso: each surface's iso and iso_stored" sh -c \
    'grep -qF "{\"iso\": -500, \"iso_stored\": 524, \"color\"" "$0" &&
     grep -qF "{\"iso\": 200, \"iso_stored\": 1224, \"color\"" "$0"' two.json
render ct.ibv --iso-stored 524 --iso-stored 1224 -o two_stored.png
check "several --iso-stored: the same image" cmp -s two.png two_stored.png

# --iso and --iso-stored do not mix; --iso-stored needs a number
expect_error 2 "--iso and --iso-stored do not mix" "$bin/isorender" ct.ibv --iso -500 \
    --iso-stored 524
expect_error 2 "--iso-stored 'bone' is not a number" "$bin/isorender" ct.ibv --iso-stored bone
expect_error 2 "--iso V is required (or --iso-stored V)" "$bin/isorender" ct.ibv
check "no image after usage errors" test ! -e isorender.png

# --- isobrick --rescale: sets one on raw input, drops one with none ---
"$bin/isobrick" "$raw" -o raw_hu.ibv --brick-size 8 --threads 2 --spacing 0.8,0.7,2.5 \
    --rescale 1,-1024,HU --quiet
render raw_hu.ibv --iso -500 -o raw_hu.png
check "--rescale 1,-1024,HU on the raw volume: --iso -500 draws the CT's image" \
    cmp -s raw_hu.png hu_progressive.png
"$bin/isoinfo" --json raw_hu.ibv >raw_hu.json
check "--rescale: kept in the file" grep -qF \
    '"rescale": {"slope": 1, "intercept": -1024, "unit": "HU"}' raw_hu.json
"$bin/isobrick" series -o dropped.ibv --brick-size 8 --threads 2 --rescale none --quiet
"$bin/isoinfo" --json dropped.ibv >dropped.json
check "--rescale none: version 2, no rescale" grep -qF '"format_version": 2' dropped.json
check "--rescale none: rescale null" grep -qF '"rescale": null' dropped.json
"$bin/isobrick" series -o pet.ibv --brick-size 8 --threads 2 --rescale 0.5,-3.25 --quiet
"$bin/isoinfo" --json pet.ibv >pet.json
check "--rescale without a unit: unit \"\"" grep -qF \
    '"rescale": {"slope": 0.5, "intercept": -3.25, "unit": ""}' pet.json
render pet.ibv --iso 258.75 -o pet.png --stats pet_stats.json # (258.75 + 3.25) / 0.5 = 524
check "slope 0.5: --iso 258.75 is stored 524" cmp -s pet.png hu_progressive.png
check "slope 0.5: iso_stored 524" grep -qF '"iso": 258.75, "iso_stored": 524,' pet_stats.json
"$bin/isobrick" series -o flipped.ibv --brick-size 8 --threads 2 --rescale -1,1024,negHU --quiet
render flipped.ibv --iso 500 --mesh flipped.ply -o flipped.png
check "a negative slope: --iso 500 is stored 524, the same triangles" \
    cmp -s flipped.ply hu_progressive.ply
run_capture "$bin/isoinfo" flipped.ibv
check "a negative slope: the range lowest first ($out)" grep -qF \
    "value range   -933 .. 1000 negHU (stored 24 .. 1957)" "$work/.out"
# a negative slope turns the rule around: stored 24 (1000 negHU) has no surface, 1957 (-933) has
run_capture render flipped.ibv --iso 1000 -o edge_hi.png
check "a negative slope: the maximum warns, with the rule turned around ($err)" \
    grep -qF "(an isovalue must be at least the minimum and below the maximum)" "$work/.err"
run_capture render flipped.ibv --iso -933 -o edge_lo.png
check "a negative slope: the minimum does not warn ($err)" sh -c '! grep -q warning "$0"' \
    "$work/.err"
expect_error 2 "--rescale '1' is not SLOPE,INTERCEPT[,UNIT] or none" "$bin/isobrick" "$raw" \
    --rescale 1 -o bad.ibv
expect_error 2 "slope 0 is not a finite number other than 0" "$bin/isobrick" "$raw" \
    --rescale 0,5 -o bad.ibv
expect_error 2 "the unit is longer than 15 characters" "$bin/isobrick" "$raw" \
    --rescale 1,0,Hounsfield-units -o bad.ibv
expect_error 2 "unit holds a character that is not printable ASCII" "$bin/isobrick" "$raw" \
    --rescale "$(printf '1,0,H\tU')" -o bad.ibv
check "no output after bad --rescale" test ! -e bad.ibv

# --- isowall takes --iso in HU too (where the build has it and mpirun runs) ---
if [ -x "$bin/isowall" ] && command -v mpirun >/dev/null 2>&1; then
    case "${IP_SANITIZE:-}" in # OpenMPI's unloaded components: as wall.sh, no leak checking
    *address*) export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" ;;
    esac
    run_capture timeout 300 mpirun --oversubscribe --allow-run-as-root -np 2 "$bin/isowall" \
        ct.ibv --iso -500 --wall 2x1 --tile 48x72 -o wall.png --stats wall.json --quiet
    check "isowall --iso -500 runs ($rc: $err)" test "$rc" = 0
    check "isowall --iso -500: isorender's image at --iso-stored 524" "$bin/tests/png_compare" \
        wall.png st_progressive.png --level 0 --max-pct 0.01
    check "isowall --stats: iso, iso_stored, rescale" sh -c \
        'grep -qF "\"iso\": -500," "$0" && grep -qF "\"iso_stored\": 524," "$0" &&
         grep -qF "\"rescale\": {\"slope\": 1, \"intercept\": -1024, \"unit\": \"HU\"}" "$0"' \
        wall.json
fi

# --- isoview: --iso in HU or --iso-stored, and the script's iso and iso-stored alike ---
if command -v xvfb-run >/dev/null 2>&1; then
    view() { in_xvfb 130 320x240x24 "$bin/isoview" ct.ibv --size 160x120 --lod off "$@"; }
    same_image() { check "$1" "$bin/tests/png_compare" "$2" "$3" --level 2 --max-pct 0.2; }
    "$bin/isorender" ct.ibv --iso 200 --size 160x120 --lod off -o r200.png --quiet
    "$bin/isorender" ct.ibv --iso -500 --size 160x120 --lod off -o r500.png --quiet
    printf 'overlay off\nwait done\nscreenshot a1.png\niso -500\nwait done\nscreenshot b1.png\nquit\n' \
        >walk1.txt
    view --iso-stored 1224 --script walk1.txt --stats view1.json
    check "isoview --iso-stored 1224, then iso -500 ($rc: $err)" test "$rc" = 0
    sed 's/^iso -500$/iso-stored 524/; s/1\.png/2.png/' walk1.txt >walk2.txt
    view --iso 200 --script walk2.txt --stats view2.json
    check "isoview --iso 200, then iso-stored 524 ($rc: $err)" test "$rc" = 0
    same_image "isoview --iso-stored 1224 shows isorender --iso 200" a1.png r200.png
    same_image "isoview --iso 200 shows it too" a2.png r200.png
    same_image "the script's iso -500 shows isorender --iso -500" b1.png r500.png
    same_image "the script's iso-stored 524 shows it too" b2.png r500.png
    for f in view1.json view2.json; do
        check "$f: the last isovalue in HU, its stored value, the rescale" grep -qF \
            '"iso": -500, "iso_stored": 524, "rescale": {"slope": 1, "intercept": -1024, "unit": "HU"}' \
            "$f"
    done
fi

finish

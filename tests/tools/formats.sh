# SPDX-License-Identifier: BSD-3-Clause
# TIFF and NIfTI input end to end: a raw volume written again as a multi-page TIFF, a folder of
# TIFF files, a NIfTI-1 .nii.gz and a big-endian NIfTI-2 .nii (tests/helpers/make_formats.c)
# bricks to the same file as the raw volume itself: the same samples, and the same spacing,
# read from ImageJ's calibration and from pixdim (and for the NIfTI files their scl_slope 2 and
# scl_inter -10, as isobrick --rescale 2,-10 gives the raw volume). The brick file stores no
# source name, so equal samples, spacing and rescale make equal files. Then the usual
# breakages, one line each.
. "$(dirname "$0")/lib.sh"

"$bin/isogen" shepp-logan --dims 45x38x27 --type int16 -o "$work/" --quiet
raw=shepp-logan_45x38x27_int16.raw
mkdir formats
check "make_formats writes the files" "$bin/tests/make_formats" "$raw" formats 0.5,1.25

run_capture "$bin/isobrick" "$raw" -o raw.ibv --brick-size 8 --threads 2 --spacing 0.5,0.5,1.25
check "the raw volume bricks" test "$rc" = 0
run_capture "$bin/isobrick" "$raw" -o raw_scaled.ibv --brick-size 8 --threads 2 \
    --spacing 0.5,0.5,1.25 --rescale 2,-10
check "the raw volume bricks with the NIfTI files' rescale" test "$rc" = 0
for input in formats/stack.tif formats/slices formats/volume.nii.gz formats/volume_be.nii; do
    name=$(basename "$input" | tr . _)
    run_capture "$bin/isobrick" "$input" -o "$name.ibv" --brick-size 8 --threads 2
    check "$input bricks ($err)" test "$rc" = 0
    case $input in
    *.nii*)
        check "$input: the scaling is reported and kept" grep -qF \
            "rescale     value = stored x 2 - 10, kept: --iso in rescaled values, --iso-stored in stored values" \
            "$work/.out"
        check "$input bricks to the raw volume's file with its rescale" \
            cmp -s raw_scaled.ibv "$name.ibv"
        ;;
    *)
        check "$input: no scaling to report" sh -c '! grep -q rescale "$0"' "$work/.out"
        check "$input bricks to the raw volume's file" cmp -s raw.ibv "$name.ibv"
        ;;
    esac
    check "$input verifies" "$bin/isoinfo" --verify "$name.ibv"
done
run_capture "$bin/isoinfo" --json volume_nii_gz.ibv
check "isoinfo --json: the NIfTI's rescale, no unit" grep -qF \
    '"rescale": {"slope": 2, "intercept": -10, "unit": ""}' "$work/.out"
run_capture "$bin/isoinfo" --json stack_tif.ibv
check "spacing from ImageJ" grep -q '"spacing": \[0.5, 0.5, 1.25\]' "$work/.out"

# the same extraction from each: one mesh, byte for byte (the NIfTI's isovalue in its rescaled
# values, 2 x 0.5 - 10 = -9, or as the stored value 0.5)
for run in "raw --iso 0.5" "stack_tif --iso 0.5" "volume_be_nii --iso -9" \
    "volume_nii_gz --iso-stored 0.5"; do
    set -- $run
    run_capture "$bin/isorender" "$1.ibv" "$2" "$3" --full --threads 1 --size 64x64 \
        -o "$1.png" --mesh "$1.ply"
    check "isorender --full on $1" test "$rc" = 0
done
check "the TIFF's mesh is the raw volume's" cmp -s raw.ply stack_tif.ply
check "the NIfTI's mesh at -9 is the raw volume's at 0.5" cmp -s raw.ply volume_be_nii.ply
check "the NIfTI's mesh at stored 0.5 is the raw volume's" cmp -s raw.ply volume_nii_gz.ply

# --- breakages: one line naming the file, exit 1, no output ---
mv formats/slices/slice7.tif formats/slice7.tif
expect_error 1 "formats/slices: slice 7 is missing" "$bin/isobrick" formats/slices -o gap.ibv
check "no output after a missing slice" test ! -e gap.ibv
"$bin/tests/make_formats" sphere_doesnotexist_4x4x4_uint8.raw formats 1,1 2>/dev/null
check "make_formats fails on a missing input" test $? = 1
head -c 1000 formats/volume_be.nii >formats/cut.nii
expect_error 1 "formats/cut.nii: data size" "$bin/isobrick" formats/cut.nii -o cut.ibv
check "no output after a truncated NIfTI" test ! -e cut.ibv
printf 'II*\000' >formats/notreally.tif
expect_error 1 "formats/notreally.tif: not a readable TIFF" "$bin/isobrick" formats/notreally.tif \
    -o bad.ibv
expect_error 1 "differ from the TIFF's" "$bin/isobrick" formats/stack.tif --dims 45x38x26 \
    -o bad.ibv
check "no output after bad TIFFs" test ! -e bad.ibv

# --- a volume where a brick file is wanted: say to brick it, with the command ---
for input in formats/volume.nii.gz formats/stack.tif "$raw"; do
    expect_error 1 "$input: " "$bin/isorender" "$input" --iso 0.5 -o v.png
    check "isorender $input: names the command" \
        sh -c 'printf "%s" "$0" | grep -qF "not a brick file: brick it first (isobrick $1)"' "$err" "$input"
    expect_error 1 "brick it first (isobrick $input)" "$bin/isoinfo" "$input"
done
check "and writes nothing" test ! -e v.png
# the default output is named for the input's stem: both parts of .nii.gz go
run_capture "$bin/isobrick" formats/volume.nii.gz --brick-size 8 --quiet
check "isobrick volume.nii.gz writes bricks/volume.ibv ($err)" test "$rc" = 0 -a -e bricks/volume.ibv
check "... not bricks/volume.nii.ibv" test ! -e bricks/volume.nii.ibv
# images are PNG, and named so
expect_error 2 "-o v.jpg: images are written as PNG: name it .png" "$bin/isorender" raw.ibv \
    --iso 0.5 -o v.jpg
expect_error 2 "--strip s.gif: images are written as PNG" "$bin/isorender" raw.ibv --iso 0.5 \
    -o v.png --strip s.gif
check "no image under another name" test ! -e v.jpg -a ! -e v.png
run_capture "$bin/isorender" raw.ibv --iso 0.5 -o V.PNG --quiet
check "a .PNG name is a PNG name ($err)" test "$rc" = 0 -a -e V.PNG
finish

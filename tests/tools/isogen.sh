#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# End-to-end test of isogen: output names, -o forms, --force, bad command lines, sizes, upsampling.
set -u

isogen="$(cd "${IP_BIN:-.}" 2>/dev/null && pwd)/isogen"
if [ ! -x "$isogen" ]; then
    echo "isogen: ${IP_BIN:-.}/isogen is not built; skipping"
    exit 77
fi
work="${IP_TEST_TMP:-/tmp/isoprop-test}/isogen_sh"
rm -rf "$work" && mkdir -p "$work" || exit 1

passed=0
failed=0

# check DESCRIPTION COMMAND...: counts a pass when COMMAND succeeds.
check() {
    local what="$1"
    shift
    if "$@"; then
        passed=$((passed + 1))
    else
        failed=$((failed + 1))
        echo "FAIL: $what"
    fi
}

# run ARGS...: runs isogen in $work, keeping its exit status, stdout and stderr.
run() {
    (cd "$work" && "$isogen" "$@") >"$work/stdout" 2>"$work/stderr"
    status=$?
}

out() { cat "$work/stdout"; }
size_of() { stat -c %s "$1" 2>/dev/null || echo missing; }
lines_of() { wc -l <"$1" | tr -d ' '; }
# one_error: stderr is exactly one line starting "isogen: ".
one_error() { [ "$(lines_of "$work/stderr")" = 1 ] && grep -q '^isogen: ' "$work/stderr"; }

# --- generation: names and sizes ---
run sphere --dims 8x6x4 --type uint8
check "default name: exit 0" [ "$status" = 0 ]
check "default name: stdout is the path" [ "$(out)" = "sphere_8x6x4_uint8.raw" ]
check "default name: size" [ "$(size_of "$work/sphere_8x6x4_uint8.raw")" = 192 ]
check "summary: one line on stderr" [ "$(lines_of "$work/stderr")" = 1 ]
check "summary: has MB/s" grep -q 'MB/s' "$work/stderr"

run gyroid
check "defaults 128^3 uint16" [ "$(size_of "$work/gyroid_128x128x128_uint16.raw")" = 4194304 ]

i=0
for type in uint8 uint16 int16 float32; do
    i=$((i + 1))
    run shepp-logan --dims 10x9x8 --type "$type"
    expect=$((10 * 9 * 8 * (i == 1 ? 1 : i == 4 ? 4 : 2)))
    check "size of $type" [ "$(size_of "$work/shepp-logan_10x9x8_$type.raw")" = "$expect" ]
done
run marschner-lobb --dims=7x7x7 --type=float32
check "--opt=value form" [ "$(out)" = "marschner-lobb_7x7x7_float32.raw" ]

# --- -o forms ---
mkdir -p "$work/folder"
run gyroid --dims 16x16x16 -o folder/
check "-o dir/: path" [ "$(out)" = "folder/gyroid_16x16x16_uint16.raw" ]
check "-o dir/: size" [ "$(size_of "$work/folder/gyroid_16x16x16_uint16.raw")" = 8192 ]
run sphere --dims 16x16x16 -o folder
check "-o existing dir: path" [ "$(out)" = "folder/sphere_16x16x16_uint16.raw" ]
check "-o existing dir: file" [ -f "$work/folder/sphere_16x16x16_uint16.raw" ]
run sphere --dims 5x5x5 --type float32 -o custom.bin
check "-o file: path" [ "$(out)" = "custom.bin" ]
check "-o file: size" [ "$(size_of "$work/custom.bin")" = 500 ]

# --- existing output and --force ---
printf keep >"$work/keep.raw"
run sphere --dims 4x4x4 -o keep.raw
check "existing: exit 1" [ "$status" = 1 ]
check "existing: one-line error" one_error
check "existing: names the file" grep -q 'keep.raw' "$work/stderr"
check "existing: untouched" [ "$(cat "$work/keep.raw")" = keep ]
run sphere --dims 4x4x4 -o keep.raw --force
check "--force: exit 0" [ "$status" = 0 ]
check "--force: replaced" [ "$(size_of "$work/keep.raw")" = 128 ]

run sphere --dims 4x4x4 -o missing_folder/x.raw
check "missing folder: exit 1" [ "$status" = 1 ]
check "missing folder: one-line error" one_error
check "missing folder: names the path" grep -q 'missing_folder/x.raw' "$work/stderr"
check "missing folder: nothing created" [ ! -e "$work/missing_folder" ]

# --- determinism and noise ---
run shepp-logan --dims 20x20x20 --noise 0.05 --seed 9 -o n1.raw
run shepp-logan --dims 20x20x20 --noise 0.05 --seed 9 -o n2.raw
run shepp-logan --dims 20x20x20 --noise 0.05 --seed 10 -o n3.raw
run shepp-logan --dims 20x20x20 -o n0.raw
check "same seed, same bytes" cmp -s "$work/n1.raw" "$work/n2.raw"
check "other seed, other bytes" bash -c "! cmp -s '$work/n1.raw' '$work/n3.raw'"
check "noise changes the volume" bash -c "! cmp -s '$work/n1.raw' '$work/n0.raw'"

run sphere --dims 4x4x4 -o quiet.raw --quiet
check "--quiet: exit 0" [ "$status" = 0 ]
check "--quiet: nothing on stdout" [ ! -s "$work/stdout" ]
check "--quiet: nothing on stderr" [ ! -s "$work/stderr" ]

# --- command-line errors: exit 2, one line ---
for args in "cube" "" "sphere --dims 1x4x4" "sphere --dims 4x4" "sphere --type int64" \
    "sphere --noise -1" "sphere --seed x" "sphere --bogus" "sphere --dims" "sphere gyroid" \
    "sphere --endian big" "--upsample 0 in.raw" "--upsample 2" "--upsample 2 a.raw --noise 1"; do
    # shellcheck disable=SC2086
    run $args
    check "'$args': exit 2" [ "$status" = 2 ]
    check "'$args': one-line error" one_error
done
run --help
check "--help: exit 0" [ "$status" = 0 ]
check "--help: usage" grep -q '^usage: isogen' "$work/stdout"

# --- upsampling ---
run marschner-lobb --dims 6x5x4 --type uint16
run --upsample 2 marschner-lobb_6x5x4_uint16.raw
check "upsample: exit 0" [ "$status" = 0 ]
check "upsample: name" [ "$(out)" = "marschner-lobb_x2_12x10x8_uint16.raw" ]
check "upsample: size" [ "$(size_of "$work/marschner-lobb_x2_12x10x8_uint16.raw")" = 1920 ]
run --upsample 1 marschner-lobb_6x5x4_uint16.raw -o copy.raw
check "upsample x1: identical" cmp -s "$work/copy.raw" "$work/marschner-lobb_6x5x4_uint16.raw"
run --upsample 2 marschner-lobb_6x5x4_uint16.raw
check "upsample existing: exit 1" [ "$status" = 1 ]

cp "$work/marschner-lobb_6x5x4_uint16.raw" "$work/plain.bin"
run --upsample 3 plain.bin --dims 6x5x4 --type uint16 -o folder/
check "upsample overrides: name" [ "$(out)" = "folder/plain_x3_18x15x12_uint16.raw" ]
check "upsample overrides: size" [ "$(size_of "$work/folder/plain_x3_18x15x12_uint16.raw")" = 6480 ]
dd if="$work/plain.bin" of="$work/swapped.bin" conv=swab status=none
run --upsample 1 swapped.bin --dims 6x5x4 --type uint16 --endian big -o unswapped.raw
check "upsample big-endian input" cmp -s "$work/unswapped.raw" "$work/plain.bin"

# Headers: a detached NRRD header and a MetaImage header over the same samples.
printf '%s\n' NRRD0004 'type: unsigned short' 'dimension: 3' 'sizes: 6 5 4' 'encoding: raw' \
    'endian: little' 'data file: plain.bin' >"$work/head.nhdr"
run --upsample 3 head.nhdr
check "upsample NRRD: name" [ "$(out)" = "head_x3_18x15x12_uint16.raw" ]
check "upsample NRRD: same samples" cmp -s "$work/head_x3_18x15x12_uint16.raw" \
    "$work/folder/plain_x3_18x15x12_uint16.raw"
printf '%s\n' 'ObjectType = Image' 'NDims = 3' 'DimSize = 6 5 4' 'ElementType = MET_USHORT' \
    'ElementDataFile = plain.bin' >"$work/meta.mhd"
run --upsample 3 meta.mhd
check "upsample MetaImage: name" [ "$(out)" = "meta_x3_18x15x12_uint16.raw" ]
check "upsample MetaImage: same samples" cmp -s "$work/meta_x3_18x15x12_uint16.raw" \
    "$work/folder/plain_x3_18x15x12_uint16.raw"

run --upsample 2 no_such_input.raw
check "upsample missing input: exit 1" [ "$status" = 1 ]
check "upsample missing input: one-line error" one_error

echo "isogen: $passed passed, $failed failed"
# the scratch folder goes when the test passes, stays for diagnosis when it fails
if [ "$failed" = 0 ]; then rm -rf "$work"; else echo "isogen: scratch files kept in $work" >&2; fi
[ "$failed" = 0 ]

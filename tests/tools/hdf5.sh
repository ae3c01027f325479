# SPDX-License-Identifier: BSD-3-Clause
# HDF5 input end to end (docs/input.md, "HDF5"): a volume's samples written by libhdf5
# (tests/helpers/make_hdf5.c) as a contiguous dataset, a chunked one with shuffle + gzip and
# partial chunks at every edge, int32 (chunked + gzip) and big-endian float64, each brick to the
# same file as the raw volume of the same samples (the brick file stores no source name), with
# the spacing of element_size_um or spacing; the same value range (isoinfo --json) and the same
# triangles (isorender --full). --dataset picks one of several 3-D datasets, without it the file
# is refused listing them; bad input: one line naming the file, exit 1, no output. Skipped where
# the build reads no HDF5 (IP_HDF5=OFF: no make_hdf5).
. "$(dirname "$0")/lib.sh"

[ -x "$bin/tests/make_hdf5" ] || { echo "hdf5: built without HDF5 (IP_HDF5=OFF): skipped"; exit 77; }
"$bin/isogen" shepp-logan --dims 45x38x27 --type uint16 -o "$work/" --quiet
raw=shepp-logan_45x38x27_uint16.raw
mkdir h5
check "make_hdf5 writes the files" "$bin/tests/make_hdf5" "$raw" h5
float=h5/volume_45x38x27_float32.raw

brick() { # brick INPUT OUT [options]
    input=$1 output=$2
    shift 2
    run_capture "$bin/isobrick" "$input" -o "$output" --brick-size 8 --threads 2 --quiet "$@"
    check "$input bricks ($err)" test "$rc" = 0
}
brick "$raw" raw.ibv --spacing 0.5,0.5,1.25
brick "$float" float.ibv --spacing 0.5,0.5,1.25
brick h5/contiguous.h5 contiguous.ibv
brick h5/chunked.h5 chunked.ibv
brick h5/int32.h5 int32.ibv
brick h5/float64.h5 float64.ibv
brick h5/two.h5 two_b.ibv --dataset /b/c --spacing 0.5,0.5,1.25
brick h5/two.h5 two_a.ibv --dataset /a
check "contiguous uint16 (element_size_um) bricks to the raw volume's file" cmp -s raw.ibv contiguous.ibv
check "chunked + gzip uint16 (spacing) bricks to the raw volume's file" cmp -s raw.ibv chunked.ibv
check "--dataset /b/c (big-endian, chunked) bricks to the raw volume's file" cmp -s raw.ibv two_b.ibv
check "int32 bricks to the float32 raw volume's file" cmp -s float.ibv int32.ibv
check "big-endian float64 bricks to the float32 raw volume's file" cmp -s float.ibv float64.ibv
check "--dataset /a is another volume" sh -c '! cmp -s raw.ibv two_a.ibv'

# the same values and the same surface, as the programs report them
for f in raw chunked float64 two_a; do
    "$bin/isoinfo" --json "$f.ibv" >"$f.json"
    "$bin/isorender" "$f.ibv" --iso 500.5 --full --threads 1 --size 64x64 --software --quiet \
        -o "$f.png" --stats "$f.stats.json" 2>/dev/null
done
range() { grep -o '"value_min": [-0-9.e+]*, "value_max": [-0-9.e+]*, "rescale"' "$1"; }
check "the raw volume's value range is 0 to 4095" test "$(range raw.json)" = '"value_min": 0, "value_max": 4095, "rescale"'
check "the same from chunked HDF5" test "$(range chunked.json)" = "$(range raw.json)"
check "the same from float64 HDF5" test "$(range float64.json)" = "$(range raw.json)"
check "--dataset /a: the samples + 1000" \
    test "$(range two_a.json)" = '"value_min": 1000, "value_max": 5095, "rescale"'
check "spacing from element_size_um" grep -q '"spacing": \[0.5, 0.5, 1.25\]' chunked.json
tri_raw=$(json_number triangles raw.stats.json)
check "isorender --full draws triangles ($tri_raw)" test "${tri_raw:-0}" -gt 0
check "the same triangles from chunked HDF5" test "$(json_number triangles chunked.stats.json)" = "$tri_raw"
check "the same triangles from float64 HDF5" test "$(json_number triangles float64.stats.json)" = "$tri_raw"

# detected by its signature under any name, and by .hdf5 / .he5
cp h5/chunked.h5 h5/chunked.data
cp h5/chunked.h5 h5/chunked.hdf5
brick h5/chunked.data signature.ibv
brick h5/chunked.hdf5 hdf5_ext.ibv
check "an HDF5 file without the extension is read by its signature" cmp -s raw.ibv signature.ibv
check ".hdf5 reads" cmp -s raw.ibv hdf5_ext.ibv

# --- refusals: one line naming the file, exit 1 (2: the command line), no output ---
expect_error 1 "h5/two.h5: 2 3-D datasets: pick one with --dataset: /a (z,y,x 27x38x45, uint16), /b/c (z,y,x 27x38x45, uint16)" \
    "$bin/isobrick" h5/two.h5 -o bad.ibv
expect_error 1 "h5/two.h5: no dataset /nope in the file (its 3-D datasets: /a" \
    "$bin/isobrick" h5/two.h5 --dataset /nope -o bad.ibv
expect_error 1 "h5/two.h5: dataset /image has 2 dimensions, not 3" \
    "$bin/isobrick" h5/two.h5 --dataset /image -o bad.ibv
expect_error 1 "h5/flat.h5: the HDF5 file holds no 3-D dataset" "$bin/isobrick" h5/flat.h5 -o bad.ibv
expect_error 1 "h5/int64.h5: dataset /volume holds signed 64-bit integers" \
    "$bin/isobrick" h5/int64.h5 -o bad.ibv
expect_error 1 "h5/truncated.h5: not a readable HDF5 file (truncated file" \
    "$bin/isobrick" h5/truncated.h5 -o bad.ibv
# (the damage spans two chunks of the last layer: either may be named, inflated on two threads)
expect_error 1 "h5/damaged.h5: dataset /data/volume: the gzip chunk at (z,y,x) = (25,16," \
    "$bin/isobrick" h5/damaged.h5 -o bad.ibv
check "... does not inflate ($err)" sh -c 'printf "%s" "$0" | grep -q "does not inflate (zlib error"' "$err"
expect_error 1 "$raw: an HDF5 dataset was asked for, but this is not an HDF5 file" \
    "$bin/isobrick" "$raw" --dataset /volume -o bad.ibv
expect_error 1 "h5/chunked.h5: an HDF5 file says its dims, type and byte order" \
    "$bin/isobrick" h5/chunked.h5 --type uint8 -o bad.ibv
printf 'not HDF5 at all' >h5/fake.h5
expect_error 1 "h5/fake.h5: not a readable HDF5 file" "$bin/isobrick" h5/fake.h5 -o bad.ibv
mkfifo h5/fifo.h5
expect_error 1 "h5/fifo.h5: not a regular file" "$bin/isobrick" h5/fifo.h5 -o bad.ibv
check "no output after any refusal" test ! -e bad.ibv
check "and no HDF5 error stack printed" sh -c '! grep -q "HDF5-DIAG" "$0"' "$work/.err"
finish

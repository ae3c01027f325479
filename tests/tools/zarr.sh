# SPDX-License-Identifier: BSD-3-Clause
# Zarr v2, Zarr v3 and OME-Zarr input end to end (tests/helpers/make_zarr.c writes every
# variant from one raw volume): each brick file equals the raw volume's, OME-Zarr's scale and
# translation become spacing and origin, --scale/--time/--channel pick the right samples, and
# every breakage gives one line naming the file, exit 1 and no output.
. "$(dirname "$0")/lib.sh"

"$bin/isogen" shepp-logan --dims 45x38x27 --type int16 -o "$work/" --quiet
raw=shepp-logan_45x38x27_int16.raw
check "make_zarr writes the variants" "$bin/tests/make_zarr" "$raw" 45x38x27 z

brick() { # INPUT OUT [options]: isobrick into OUT, status in $rc
    in=$1 out=$2
    shift 2
    run_capture "$bin/isobrick" "$in" -o "$out" --brick-size 8 --threads 2 "$@"
}
brick "$raw" raw.ibv
check "the raw volume bricks" test "$rc" = 0
for v in v2_blosc_lz4 v2_blosc_zstd_be v2_zlib v2_gzip_be v2_zstd v2_lz4 v2_none_be v3_blosc \
    v3_gzip_crc_be v3_zstd_v2keys v3_sharded v3_sharded_blosc; do
    brick "z/$v.zarr" "$v.ibv"
    check "$v bricks ($err)" test "$rc" = 0
    check "$v bricks to the raw volume's file" cmp -s raw.ibv "$v.ibv"
done

# chunks all of the fill value (the background, -1024) are left out by the writer: the
# fill value stands for them, as for a shard left out or a shard's empty inner chunk
check "the writer left chunks out" test "$(ls z/v2_blosc_lz4.zarr | wc -l)" -lt 120
check "and whole shards" test "$(find z/v3_sharded.zarr/c -type f | wc -l)" -lt 18

# OME-Zarr 0.5 (v3, sharded, c z y x; z in millimeter, converted to x's micrometer)
brick z/ome05.zarr ome05.ibv --channel 2
check "OME-Zarr 0.5 --channel 2 bricks ($err)" test "$rc" = 0
brick "$raw" raw_spaced.ibv --spacing 0.5,0.5,1.25
same_but_origin() { # A.ibv B.ibv: isoinfo --json alike but for the origin
    "$bin/isoinfo" --json "$1" | sed 's/"origin": \[[^]]*\]//; s/"file": "[^"]*"//' >a.json &&
        "$bin/isoinfo" --json "$2" | sed 's/"origin": \[[^]]*\]//; s/"file": "[^"]*"//' >b.json &&
        cmp -s a.json b.json
}
check "OME-Zarr 0.5: the scale is the spacing, the samples the raw volume's" \
    same_but_origin raw_spaced.ibv ome05.ibv
brick z/ome05.zarr ome05_c0.ibv --channel 0
check "--channel 0 is another volume" sh -c '! cmp -s ome05.ibv ome05_c0.ibv'
run_capture "$bin/isoinfo" --json ome05_c0.ibv
check "channel 0 holds only 7s" grep -q '"value_min": 7, "value_max": 7' "$work/.out"
# OME-Zarr 0.4 (v2, t c z y x), translation as origin; scale 1 is every other sample
brick z/ome04.zarr ome04.ibv --time 1 --channel 2
check "OME-Zarr 0.4 --time 1 --channel 2 bricks ($err)" test "$rc" = 0
check "the summary names the scale, time, channel and unit" grep -qF \
    "ome-zarr    scale 0 of 2, time 1, channel 2; spacing 0.5,0.5,1.25 and origin in um" \
    "$work/.out"
run_capture "$bin/isoinfo" --json ome04.ibv
check "OME-Zarr 0.4: spacing from the scale" grep -q '"spacing": \[0.5, 0.5, 1.25\]' "$work/.out"
check "OME-Zarr 0.4: origin from the translation" grep -q '\[2.5, -5, 10\]' "$work/.out"
brick z/ome04.zarr ome04_s1.ibv --time 1 --channel 2 --scale 1
brick z/half_23x19x14_int16.raw half_spaced.ibv --spacing 1,1,2.5
check "--scale 1 reads the second scale's samples and spacing" \
    same_but_origin half_spaced.ibv ome04_s1.ibv

# --- refusals: one line naming the file, exit 1 (2 for a bad choice), no output ---
expect_fail() { # STATUS PATTERN INPUT [options]
    want=$1 pattern=$2 in=$3
    shift 3
    rm -f out.ibv
    brick "$in" out.ibv "$@"
    check "$in $*: status $want ($rc: $err)" test "$rc" = "$want"
    check "$in: the message says '$pattern'" grep -q -- "$pattern" "$work/.err"
    check "$in: one line" test "$(wc -l <"$work/.err")" = 1
    check "$in: no output" test ! -e out.ibv
}
expect_fail 1 "ome04.zarr: a 5-D image (t=2, c=3, z=27, y=38, x=45): pick a volume" z/ome04.zarr
expect_fail 1 "channel 3 asked for, but the image has 3" z/ome05.zarr --channel 3
expect_fail 1 "scale 2 asked for, but the image has 2" z/ome05.zarr --channel 0 --scale 2
expect_fail 1 "not an OME-Zarr image" "$raw" --time 0
expect_fail 1 "a Zarr array, not an OME-Zarr image" z/v3_blosc.zarr --scale 0
cp -r z/v2_zlib.zarr bad && printf '{"zarr_format": 2, "shape": [27' >bad/.zarray
expect_fail 1 "bad/.zarray: not JSON" bad
rm -rf bad && cp -r z/v2_zlib.zarr bad
sed -i 's/"filters": null/"filters": [{"id": "delta"}]/' bad/.zarray
expect_fail 1 "filter 'delta' is not read" bad
rm -rf bad && cp -r z/v2_zlib.zarr bad && sed -i 's/"C"/"F"/' bad/.zarray
expect_fail 1 'order "F"' bad
rm -rf bad && cp -r z/v2_zlib.zarr bad && sed -i 's/"<i2"/"<i8"/' bad/.zarray
expect_fail 1 "data type <i8 is not read" bad
rm -rf bad && cp -r z/v2_zlib.zarr bad && sed -i 's/"zlib"/"bz2"/' bad/.zarray
expect_fail 1 "compressor 'bz2' is not read" bad
rm -rf bad && cp -r z/v2_zlib.zarr bad && sed -i 's/\[16, 8, 32\]/[16, 8, 31]/' bad/.zarray
expect_fail 1 "zlib: decodes to more than" bad
rm -rf bad && cp -r z/v2_blosc_lz4.zarr bad && truncate -s 40 bad/1.1.1
expect_fail 1 "bad/1.1.1: blosc" bad
rm -rf bad && cp -r z/v2_lz4.zarr bad && truncate -s 100 bad/3.2.2
expect_fail 1 "bad/3.2.2: lz4" bad
rm -rf bad && cp -r z/v3_gzip_crc_be.zarr bad && printf 'X' | dd of=bad/c.1.1.1 bs=1 seek=20 conv=notrunc 2>/dev/null
expect_fail 1 "bad/c.1.1.1: crc32c: checksum mismatch" bad
rm -rf bad && cp -r z/v3_sharded.zarr bad && truncate -s 100 bad/c/0/1/1
expect_fail 1 "bad/c/0/1/1: shard of 100 bytes, under its" bad
rm -rf bad && cp -r z/v3_blosc.zarr bad && sed -i 's/"blosc"/"bz2"/' bad/zarr.json
expect_fail 1 "codec 'bz2' is not read" bad
finish

# SPDX-License-Identifier: BSD-3-Clause
# isobrick and isoinfo end to end: bad input, atomic output, verification, JSON keys.
. "$(dirname "$0")/lib.sh"

# A small real input: 40x30x20 uint16 from a generator, named by convention.
"$bin/isogen" sphere --dims 40x30x20 --type uint16 -o "$work/" --quiet
raw=sphere_40x30x20_uint16.raw
check "isogen wrote $raw" test -s "$raw"

# --- good runs ---
run_capture "$bin/isobrick" "$raw" -o good.ibv --brick-size 8 --threads 2
check "isobrick succeeds" test "$rc" = 0
check "summary names the output" grep -q "wrote good.ibv" "$work/.out"
check "summary has the ratio" grep -q "ratio" "$work/.out"
check "summary has the peak RSS" grep -q "peak RSS" "$work/.out"
run_capture "$bin/isoinfo" --verify good.ibv
check "verify passes on a good file" test "$rc" = 0
run_capture "$bin/isoinfo" --json good.ibv
for key in dims type spacing brick_size levels bricks bricks_constant bytes_raw bytes_file \
           compression_ratio value_min value_max; do
    check "isoinfo --json has \"$key\"" grep -q "\"$key\":" "$work/.out"
done
check "json dims" grep -q '"dims": \[40, 30, 20\]' "$work/.out"
check "json type" grep -q '"type": "uint16"' "$work/.out"
check "json brick size" grep -q '"brick_size": 8' "$work/.out"
check "json raw bytes" grep -q '"bytes_raw": 48000' "$work/.out"

# default output folder bricks/
run_capture "$bin/isobrick" "$raw" --quiet
check "default output bricks/NAME.ibv" test -s bricks/sphere_40x30x20_uint16.ibv
check "quiet prints nothing" test -z "$out$err"

# --- --verbose: the plan, a line a chunk of planes, a line a level, the filter choices ---
run_capture "$bin/isobrick" "$raw" -o plain.ibv --brick-size 8 --threads 2
check "no details (nor a bar, on a pipe) without --verbose" test "$rc" = 0 -a -z "$err"
run_capture "$bin/isobrick" "$raw" -o verbose.ibv --brick-size 8 --threads 2 -v
check "-v succeeds" test "$rc" = 0
check "-v keeps the summary on stdout" grep -q "wrote verbose.ibv" "$work/.out"
check "-v: the input line" sh -c 'printf "%s" "$0" | grep -q "^isobrick: input: .*40x30x20 uint16"' "$err"
check "-v: the plan line" sh -c 'printf "%s" "$0" | grep -q "^isobrick: plan: verbose.ibv, brick size 8"' "$err"
# 20 planes in chunks of B + 1 = 9 planes, then 8: planes 0-8, 9-16, 17-19
chunks=$(printf '%s\n' "$err" | grep '^isobrick: chunk:' | sed 's/.*planes \([0-9]*-[0-9]*\) of 20.*/\1/' | tr '\n' ' ')
check "-v: a line a chunk of planes ($chunks)" test "$chunks" = "0-8 9-16 17-19 "
levels=$(sed -n 's/.* in \([0-9]*\) levels.*/\1/p' "$work/.out")
check "-v: a line a level ($levels levels)" \
    test "$(printf '%s\n' "$err" | grep -c '^isobrick: level [0-9]*: ')" = "$levels"
check "-v: level 0 has 5x4x3 bricks" \
    sh -c 'printf "%s" "$0" | grep -q "^isobrick: level 0: 40x30x20 samples, 5x4x3 = 60 bricks"' "$err"
# the levels' LZ4 bricks add up to the filter summary's count
lz4=$(printf '%s\n' "$err" | sed -n 's/.* constant, \([0-9]*\) LZ4,.*/\1/p' | awk '{ n += $1 } END { print n }')
check "-v: the filter choices cover the $lz4 LZ4 bricks" \
    sh -c 'printf "%s" "$0" | grep -q "^isobrick: filters chosen for $1 LZ4 bricks: "' "$err" "$lz4"
check "-v: the phases" sh -c 'printf "%s" "$0" | grep -q "^isobrick: phases: read "' "$err"
check "-v writes the same file" cmp good.ibv verbose.ibv
# reads: direct where the planes suit O_DIRECT (8 KiB planes; buffered where the file system
# refuses it), buffered behind a 352-byte header, and the same file either way
"$bin/isogen" sphere --dims 64x64x40 --type uint16 -o "$work/" --quiet
aligned=sphere_64x64x40_uint16.raw
run_capture "$bin/isobrick" "$aligned" -o direct.ibv --brick-size 8 --threads 2 -v
check "-v: the phases say how the input was read" sh -c 'printf "%s" "$0" |
    grep -Eq "^isobrick: phases: read [0-9.]+ s \((direct|buffered), overlapped\), encode "' "$err"
{ head -c 352 /dev/zero; cat "$aligned"; } > skewed.dat
printf 'NDims = 3\nDimSize = 64 64 40\nElementType = MET_USHORT\nHeaderSize = 352\nElementDataFile = skewed.dat\n' > skewed.mhd
run_capture "$bin/isobrick" skewed.mhd -o skewed.ibv --brick-size 8 --threads 2
check "a 352-byte header: buffered reads" grep -q "phases .* (buffered, overlapped), " "$work/.out"
check "direct and buffered reads write the same file" cmp direct.ibv skewed.ibv
run_capture "$bin/isobrick" "$raw" -o q.ibv --brick-size 8 -q
check "-q prints nothing" test "$rc" = 0 -a -z "$out$err"
expect_error 2 "--quiet and --verbose" "$bin/isobrick" "$raw" -o qv.ibv -q -v
check "-q -v writes nothing" test ! -e qv.ibv
# the bar: none on a pipe (above), forced with ISOBRICK_PROGRESS=1, none with -q
run_capture env ISOBRICK_PROGRESS=1 "$bin/isobrick" "$raw" -o bar.ibv --brick-size 8
check "ISOBRICK_PROGRESS=1 draws the bar to 20/20 planes" \
    sh -c 'printf "%s" "$0" | grep -q "100.0% 20/20 planes"' "$err"
run_capture env ISOBRICK_PROGRESS=1 "$bin/isobrick" "$raw" -o bar.ibv --brick-size 8 -qf
check "no bar with -q" test -z "$err"

# --- bad input: one line naming the file and the problem, non-zero exit, no output ---
head -c 47999 "$raw" >short_40x30x20_uint16.raw
expect_error 1 "short_40x30x20_uint16.raw" "$bin/isobrick" short_40x30x20_uint16.raw -o short.ibv
check "size error states the sizes" sh -c 'printf "%s" "$0" | grep -q 47999' "$err"
check "no output after a size error" test ! -e short.ibv
cp "$raw" weird_40x30x20_uint64.raw
expect_error 1 "uint64" "$bin/isobrick" weird_40x30x20_uint64.raw -o weird.ibv
check "no output after an unknown type" test ! -e weird.ibv
head -c 2400 "$raw" >flat_40x30x1_uint16.raw
expect_error 1 "flat_40x30x1_uint16.raw" "$bin/isobrick" flat_40x30x1_uint16.raw -o flat.ibv
check "no output after a dimension under 2" test ! -e flat.ibv
printf 'NRRD0004\ntype: ushort\ndimension: 3\nsizes: 40 30\n\n' >bad.nrrd
expect_error 1 "bad.nrrd" "$bin/isobrick" bad.nrrd -o badnrrd.ibv
check "no output after an unreadable header" test ! -e badnrrd.ibv
expect_error 1 "nothere.raw" "$bin/isobrick" nothere.raw -o nothere.ibv
expect_error 2 "--dims" "$bin/isobrick" "$raw" --dims 40x30 -o x.ibv
expect_error 2 "unknown" "$bin/isobrick" "$raw" --frobnicate
expect_error 2 "--brick-size '12' is not a power of two" "$bin/isobrick" "$raw" --brick-size 12 -o b12.ibv
expect_error 2 "--mem-mb '0' is not a size in MiB (1 to 1099511627776)" "$bin/isobrick" "$raw" \
    --mem-mb 0 -o m0.ibv
expect_error 2 "--mem-mb 'lots' is not a size in MiB" "$bin/isobrick" "$raw" --mem-mb lots -o m0.ibv
check "no output after a bad brick size" test ! -e b12.ibv

# --- existing output: kept without --force, replaced with it ---
cp good.ibv keep.ibv
expect_error 1 "exists" "$bin/isobrick" "$raw" -o keep.ibv --quiet
check "existing output untouched" cmp -s good.ibv keep.ibv
run_capture "$bin/isobrick" "$raw" -o keep.ibv --quiet --force --brick-size 4 --subblock-size 4
check "--force replaces" test "$rc" = 0
check "--force wrote the new file" sh -c '! cmp -s good.ibv keep.ibv'

# --- memory cap ---
expect_error 1 "MiB" "$bin/isobrick" "$raw" -o capped.ibv --mem-mb 1 --brick-size 256
check "no output when the memory cap is too small" test ! -e capped.ibv
# The cap holds for the whole run, counted in bytes: a 180 MiB input bricked under a 64 MiB cap
# peaks below the cap plus the program's own 16 MiB (libraries, stacks); the working memory is
# a few brick slabs of 768x768 planes, not the volume.
if [ -z "${IP_SANITIZE:-}" ]; then
    "$bin/isogen" gyroid --dims 768x768x160 --type uint16 -o "$work/" --quiet
    run_capture "$bin/isobrick" gyroid_768x768x160_uint16.raw -o capped.ibv --mem-mb 64
    check "bricking under --mem-mb 64 succeeds" test "$rc" = 0
    peak=$(awk '/^  peak RSS/ { v = $3; u = $4 } END {
        m = u == "GiB" ? 1073741824 : u == "MiB" ? 1048576 : u == "KiB" ? 1024 : 1
        printf "%.0f", v * m }' "$work/.out")
    check "peak RSS $peak <= 64 MiB + 16 MiB" test "$peak" -le $(((64 + 16) << 20))
    run_capture "$bin/isoinfo" --verify capped.ibv
    check "the capped run's file verifies" test "$rc" = 0
    rm -f gyroid_768x768x160_uint16.raw capped.ibv
fi

# --- a failed write (file size limit, as when the disk fills): nothing is left ---
"$bin/isogen" gyroid --dims 96x96x96 --type uint16 -o "$work/" --quiet
run_capture sh -c "trap '' XFSZ; ulimit -f 64; exec \"$bin/isobrick\" gyroid_96x96x96_uint16.raw -o full.ibv"
check "a write failure is an error" test "$rc" != 0
check "a write failure names the output" sh -c 'printf "%s" "$0" | grep -q full.ibv' "$err"
check "a write failure leaves no output" test ! -e full.ibv
check "a write failure leaves no temporary" sh -c '! ls -a | grep -q "\.tmp"'

# --- killed mid-run: no output, nothing half-written ---
"$bin/isogen" gyroid --dims 400x400x400 --type uint16 -o "$work/" --quiet
big=gyroid_400x400x400_uint16.raw
timeout -s KILL 0.3 "$bin/isobrick" "$big" -o killed.ibv --quiet --threads 1
rc=$?
if [ "$rc" = 137 ]; then
    check "a killed run leaves no output" test ! -e killed.ibv
else
    check "a run that finished is whole" "$bin/isoinfo" --verify killed.ibv
fi
"$bin/isobrick" "$big" -o interrupted.ibv --quiet --threads 1 2>"$work/.err" &
pid=$!
signal_when_ready INT 0.3 "$pid"
wait "$pid"
rc=$?
if [ "$rc" != 0 ]; then
    check "an interrupted run leaves no output" test ! -e interrupted.ibv
    check "an interrupted run says so" grep -q "cancelled" "$work/.err"
else
    check "a run that finished is whole" "$bin/isoinfo" --verify interrupted.ibv
fi
check "no temporary files remain" sh -c '! ls -a | grep -q -e "\.tmp" -e spill'
rm -f "$big"

# --- damaged brick files ---
size=$(stat -c %s good.ibv)
head -c $((size - 100)) good.ibv >truncated.ibv
expect_error 1 "truncated.ibv" "$bin/isoinfo" --verify truncated.ibv
check "truncation is named" grep -q "truncated" "$work/.err"
head -c 100 good.ibv >stub.ibv
expect_error 1 "too short" "$bin/isoinfo" stub.ibv
# flip one bit inside the first brick payload (just after the 256-byte header)
cp good.ibv flipped.ibv
printf '\001' | dd of=flipped.ibv bs=1 seek=300 conv=notrunc 2>/dev/null
byte=$(od -An -tu1 -j300 -N1 good.ibv | tr -d ' ')
newbyte=$(( byte ^ 1 ))
printf "$(printf '\\%03o' "$newbyte")" | dd of=flipped.ibv bs=1 seek=300 conv=notrunc 2>/dev/null
check "the flipped file differs by one byte" test "$(cmp -l good.ibv flipped.ibv | wc -l)" = 1
run_capture "$bin/isoinfo" flipped.ibv
check "a payload flip passes the open checks" test "$rc" = 0
expect_error 1 "brick" "$bin/isoinfo" --verify flipped.ibv
check "verify names the checksum" grep -q "checksum mismatch" "$work/.err"
# a flip in the summary section fails on open
cp good.ibv summary.ibv
printf 'Z' | dd of=summary.ibv bs=1 seek=$((size - 10)) conv=notrunc 2>/dev/null
expect_error 1 "summary section checksum" "$bin/isoinfo" summary.ibv
cp good.ibv header.ibv
printf 'Z' | dd of=header.ibv bs=1 seek=20 conv=notrunc 2>/dev/null
expect_error 1 "header checksum" "$bin/isoinfo" header.ibv
finish

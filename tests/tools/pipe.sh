# SPDX-License-Identifier: BSD-3-Clause
# A volume from a pipe (docs/input.md, "From a pipe"): isogen -o - writes the samples on
# standard output, isobrick - reads them with --dims and --type, and the brick file is the one
# bricking the raw file gives (the brick file stores no source name), also when the pipe hands
# the bytes over in pieces and for an upsampled volume. A pipe that ends early or runs past the
# dims is refused in one line, exit 1, no output; so is an output that is the file standard
# input reads.
. "$(dirname "$0")/lib.sh"

"$bin/isogen" shepp-logan --dims 45x38x27 --type uint16 -o "$work/" --quiet
raw=shepp-logan_45x38x27_uint16.raw
opts="--dims 45x38x27 --type uint16 --brick-size 8 --threads 2 --spacing 0.5,0.5,1.25"
run_capture "$bin/isobrick" "$raw" -o raw.ibv --brick-size 8 --threads 2 --spacing 0.5,0.5,1.25
check "the raw file bricks ($err)" test "$rc" = 0

"$bin/isogen" shepp-logan --dims 45x38x27 --type uint16 -o - 2>isogen.err | cmp -s - "$raw"
check "isogen -o - writes the raw file's bytes on stdout" test $? = 0
check "... its summary on stderr" grep -q "isogen: wrote 92340 bytes" isogen.err
check "... and no file named -" test ! -e ./-

"$bin/isogen" shepp-logan --dims 45x38x27 --type uint16 -o - |
    "$bin/isobrick" - $opts -o pipe.ibv >pipe.out 2>pipe.err
check "isogen -o - | isobrick - ($(cat pipe.err))" test $? = 0
check "... bricks to the raw file's brick file" cmp -s raw.ibv pipe.ibv
check "... and reports the input as for a file" grep -q "input       90.2 KiB (92340 bytes)" pipe.out

# the bytes in pieces, with pauses between them: short reads
{ head -c 1001 "$raw"; sleep 0.2; tail -c +1002 "$raw" | head -c 40000; sleep 0.2
  tail -c +41002 "$raw"; } | "$bin/isobrick" - $opts -o pieces.ibv --quiet
check "a pipe that delivers in pieces bricks the same" cmp -s raw.ibv pieces.ibv

# upsampled on the fly, as for a volume larger than the disk
"$bin/isogen" --upsample 2 "$raw" -o "$work/" --quiet
"$bin/isobrick" shepp-logan_x2_90x76x54_uint16.raw -o up_file.ibv --quiet
"$bin/isogen" --upsample 2 "$raw" -o - --quiet |
    "$bin/isobrick" - --dims 90x76x54 --type uint16 -o up_pipe.ibv --quiet
check "isogen --upsample 2 -o - | isobrick - bricks as the upsampled file" cmp -s up_file.ibv up_pipe.ibv

# big-endian samples through the pipe
"$bin/isogen" --upsample 1 "$raw" -o - --quiet | dd conv=swab status=none |
    "$bin/isobrick" - $opts --endian big -o big.ibv --quiet
check "--endian big from a pipe" cmp -s raw.ibv big.ibv

# --- refusals ---
expect_error 1 "stdin: ended after 50000 of 92340 bytes" \
    sh -c 'head -c 50000 "$0" | "$1" - $2 -o short.ibv' "$raw" "$bin/isobrick" "$opts"
check "no output after a pipe that ends early" test ! -e short.ibv
expect_error 1 "stdin: longer than the 45x38x27 x 2 = 92340 bytes of the dims" \
    sh -c 'cat "$0" "$0" | "$1" - $2 -o long.ibv' "$raw" "$bin/isobrick" "$opts"
check "no output after a pipe longer than the dims" test ! -e long.ibv
expect_error 1 "stdin: ended after 0 of 92340 bytes" \
    sh -c '"$1" - $2 -o empty.ibv </dev/null' "$raw" "$bin/isobrick" "$opts"
expect_error 1 "stdin: raw samples from standard input need --dims and --type" \
    sh -c '"$0" - -o nodims.ibv <"$1"' "$bin/isobrick" "$raw"
expect_error 2 "reading standard input ('-') needs -o OUT.ibv" \
    sh -c '"$0" - --dims 45x38x27 --type uint16 <"$1"' "$bin/isobrick" "$raw"
expect_error 1 "-: an HDF5 dataset was asked for, but this is not an HDF5 file" \
    sh -c '"$0" - --dims 45x38x27 --type uint16 --dataset /v -o ds.ibv <"$1"' "$bin/isobrick" "$raw"
cp raw.ibv victim.ibv
expect_error 1 "victim.ibv: is the same file as the input /dev/stdin; refusing to write over it" \
    sh -c '"$0" - --dims 45x38x27 --type uint16 -o victim.ibv --force <victim.ibv' "$bin/isobrick"
check "the file standard input reads is kept" cmp -s raw.ibv victim.ibv
check "no output after any refusal" test ! -e empty.ibv -a ! -e nodims.ibv -a ! -e ds.ibv
if command -v script >/dev/null; then
    script -qec "'$bin/isogen' sphere --dims 8x8x8 -o -" /dev/null >tty.out 2>&1
    check "isogen -o - refuses a terminal" grep -q "isogen: -o -: standard output is a terminal" tty.out
fi
finish

# SPDX-License-Identifier: BSD-3-Clause
# A FIFO (or another file that is not regular) named as an input never hangs a program: each
# is refused at once with one line naming it. Every run is under `timeout 10`, so that a hang
# fails the test (exit 124) instead of blocking it.
. "$(dirname "$0")/lib.sh"

"$bin/isogen" sphere --dims 12x10x8 --type uint8 -o "$work/" --quiet
"$bin/isobrick" sphere_12x10x8_uint8.raw -o s.ibv --quiet
mkfifo f.ibv f_12x10x8_uint8.raw f.raw f.nrrd f.nhdr f.mhd script.txt data.raw

# brick files
expect_error 1 "f.ibv" timeout 10 "$bin/isoinfo" f.ibv
expect_error 1 "f.ibv" timeout 10 "$bin/isoinfo" f.ibv --verify
expect_error 1 "f.ibv" timeout 10 "$bin/isorender" f.ibv --iso 100.5 -o x.png
expect_error 1 "f.ibv" timeout 10 "$bin/isoview" f.ibv --iso 100.5
check "the brick-file FIFOs give the same reason" grep -q "not a regular file" "$work/.err"

# isobrick's inputs: raw by name, raw with flags, headers, detached data files
expect_error 1 "not a regular file" timeout 10 "$bin/isobrick" f_12x10x8_uint8.raw -o a.ibv
expect_error 1 "not a regular file" timeout 10 "$bin/isobrick" f.raw --dims 12x10x8 \
    --type uint8 -o a.ibv
expect_error 1 "f.nrrd: not a regular file" timeout 10 "$bin/isobrick" f.nrrd -o a.ibv
expect_error 1 "f.nhdr: not a regular file" timeout 10 "$bin/isobrick" f.nhdr -o a.ibv
expect_error 1 "f.mhd: not a regular file" timeout 10 "$bin/isobrick" f.mhd -o a.ibv
printf 'NRRD0004\ntype: uchar\ndimension: 3\nsizes: 12 10 8\nencoding: raw\ndata file: data.raw\n' \
    >detached.nhdr
expect_error 1 "data file data.raw: not a regular file" timeout 10 "$bin/isobrick" \
    detached.nhdr -o a.ibv
printf 'ObjectType = Image\nNDims = 3\nDimSize = 12 10 8\nElementType = MET_UCHAR\nElementDataFile = data.raw\n' \
    >detached.mhd
expect_error 1 "not a regular file" timeout 10 "$bin/isobrick" detached.mhd -o a.ibv
check "no brick file after FIFO inputs" test ! -e a.ibv

# isogen --upsample INPUT
expect_error 1 "not a regular file" timeout 10 "$bin/isogen" --upsample 2 f_12x10x8_uint8.raw
expect_error 1 "f.nrrd: not a regular file" timeout 10 "$bin/isogen" --upsample 2 f.nrrd
expect_error 1 "data file data.raw: not a regular file" timeout 10 "$bin/isogen" --upsample 2 \
    detached.nhdr
check "no upsampled volume after FIFO inputs" sh -c '! ls | grep -q "_x2_"'

# isoview --script
expect_error 1 "script.txt" timeout 10 "$bin/isoview" s.ibv --iso 100.5 --script script.txt

# a device is not a volume either, nor is a directory a brick file
expect_error 1 "/dev/zero" timeout 10 "$bin/isobrick" /dev/zero --dims 12x10x8 --type uint8 \
    -o a.ibv
expect_error 1 "/dev/zero" timeout 10 "$bin/isorender" /dev/zero --iso 1 -o x.png
mkdir dir.ibv
expect_error 1 "directory" timeout 10 "$bin/isoinfo" dir.ibv
check "no image after FIFO inputs" test ! -e x.png
finish

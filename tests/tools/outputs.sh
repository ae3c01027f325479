# SPDX-License-Identifier: BSD-3-Clause
# Outputs of every program: --force never clobbers an input or a device, no two outputs of a
# run coincide, only regular files are replaced, every output (isorender's --stats JSON and
# --progress CSV included) respects --force and appears only when complete. Each refusal is
# one line naming the file, a non-zero exit, and no output at all (checked before any work).
. "$(dirname "$0")/lib.sh"

"$bin/isogen" sphere --dims 24x20x18 --type uint8 -o "$work/" --quiet
raw=sphere_24x20x18_uint8.raw
"$bin/isobrick" "$raw" -o F.ibv --brick-size 8 --quiet
cp F.ibv F.orig
cp "$raw" raw.orig
mkfifo fifo
render="$bin/isorender F.ibv --iso 100.5 --size 32x24 --software --quiet"

intact() { cmp -s F.ibv F.orig && cmp -s "$raw" raw.orig; }
none_of() { for f in "$@"; do [ ! -e "$f" ] || return 1; done; }

# --- isorender: an output that is the input, however spelled ---
for opt in --mesh --stats --progress; do
    expect_error 1 "F.ibv" $render $opt F.ibv --force
    check "isorender $opt F.ibv --force leaves the brick file intact" intact
done
# (an image must be named .png: -o F.ibv is a usage error before any file is looked at)
expect_error 2 "-o F.ibv: images are written as PNG" $render -o F.ibv --force
ln F.ibv same.png
expect_error 1 "same file as the input" $render -o same.png --force
check "isorender -o (the input under a .png name) --force leaves the brick file intact" intact
expect_error 1 "same file as the input" $render --stats ./F.ibv --force -o a.png
expect_error 1 "same file as the input" $render --stats "$work/../$(basename "$work")/F.ibv" --force -o a.png
ln F.ibv hard.png
expect_error 1 "same file as the input" $render -o hard.png --force
ln -s F.ibv soft.ibv
expect_error 1 "same file as the input" $render --mesh soft.ibv --force
check "the brick file is intact after every attempt" intact
check "and none of them wrote an image" none_of a.png

# --- isorender: two outputs of one run ---
expect_error 1 "X.png" $render --mesh X.png -o X.png
check "no PLY named .png, no image" none_of X.png
expect_error 1 "same file as the output" $render --mesh ./X.png -o X.png
expect_error 1 "same file as the output" $render --stats "$work/X.json" -o X.png --progress X.json
check "nothing written" none_of X.png X.json

# --- isorender: only regular files are replaced ---
for opt in --mesh --stats --progress; do
    expect_error 1 "not a regular file" $render $opt /dev/null --force
    expect_error 1 "a FIFO" timeout 10 $render $opt fifo --force
done
ln -s /dev/null null.png
mkfifo fifo.png
expect_error 1 "not a regular file" $render -o null.png --force
expect_error 1 "a FIFO" timeout 10 $render -o fifo.png --force
check "/dev/null is still a character device" test -c /dev/null
check "the FIFO is still a FIFO" test -p fifo
mkdir folder.png
expect_error 1 "a directory" $render -o folder.png --force
expect_error 1 "cannot write in folder" $render -o a.png --stats missing/a.json
check "no image when a later output cannot be written" none_of a.png

# --- isorender: --stats and --progress respect --force and are written whole ---
printf 'keep' >old.json
printf 'keep' >old.csv
expect_error 1 "old.json: exists" $render -o b.png --stats old.json
expect_error 1 "old.csv: exists" $render -o b.png --progress old.csv
check "existing stats untouched" test "$(cat old.json)" = keep
check "existing progress untouched" test "$(cat old.csv)" = keep
check "and no image was written" none_of b.png
run_capture $render -o b.png --stats old.json --progress old.csv --force
check "--force replaces them (got $rc: $err)" test "$rc" = 0
check "the stats are JSON" grep -q '^{"cache": {' old.json
check "the progress is CSV" test "$(head -1 old.csv | cut -d, -f1-6)" = "time_s,rays,seeds,cells,triangles,final_pixel_pct"
check "no temporary files remain" sh -c '! ls -a | grep -q "\.tmp"'

# --- isobrick ---
expect_error 1 "$raw" "$bin/isobrick" "$raw" -o "$raw" --force
expect_error 1 "same file as the input" "$bin/isobrick" "$raw" -o "./$raw" --force
check "the raw input is intact" intact
printf 'NRRD0004\ntype: uchar\ndimension: 3\nsizes: 24 20 18\nencoding: raw\ndata file: %s\n' \
    "$raw" >head.nhdr
expect_error 1 "$raw" "$bin/isobrick" head.nhdr -o "$raw" --force
expect_error 1 "head.nhdr" "$bin/isobrick" head.nhdr -o head.nhdr --force
check "the detached data file is intact" intact
expect_error 1 "not a regular file" "$bin/isobrick" "$raw" -o /dev/null --force
expect_error 1 "a FIFO" timeout 10 "$bin/isobrick" "$raw" -o fifo --force
check "/dev/null is still a character device" test -c /dev/null
check "the FIFO is still a FIFO" test -p fifo
expect_error 1 "exists" "$bin/isobrick" "$raw" -o F.ibv
check "an existing brick file is kept without --force" intact

# --- isogen ---
expect_error 1 "$raw" "$bin/isogen" --upsample 1 "$raw" -o "$raw" --force
expect_error 1 "$raw" "$bin/isogen" --upsample 2 head.nhdr -o "$raw" --force
check "isogen leaves its input intact" intact
expect_error 1 "not a regular file" "$bin/isogen" sphere --dims 4x4x4 -o /dev/null --force
expect_error 1 "a FIFO" timeout 10 "$bin/isogen" sphere --dims 4x4x4 -o fifo --force
check "the FIFO is still a FIFO" test -p fifo

# --- isoinfo --stats: --force, the input, devices ---
expect_error 1 "F.ibv" "$bin/isoinfo" F.ibv --stats F.ibv --force
check "isoinfo --stats F.ibv leaves the brick file intact" intact
expect_error 1 "old.json: exists" "$bin/isoinfo" F.ibv --stats old.json
run_capture "$bin/isoinfo" F.ibv --stats old.json --force
check "isoinfo --stats --force replaces (got $rc: $err)" test "$rc" = 0
check "with the cache statistics" grep -q '"budget_bytes"' old.json
expect_error 1 "not a regular file" "$bin/isoinfo" F.ibv --stats /dev/null --force

# --- isoview: checked before any window opens (no display needed) ---
view="$bin/isoview F.ibv --iso 100.5"
expect_error 1 "F.ibv" $view --stats F.ibv --force
expect_error 1 "F.ibv" $view --screenshot-at 1 F.ibv --force
expect_error 1 "same file as the output" $view --stats v.json --screenshot-at 1 ./v.json
printf 'screenshot ./F.ibv\n' >shot.txt
expect_error 1 "F.ibv" $view --script shot.txt --force
printf 'screenshot s.png\nscreenshot s.png\n' >twice.txt
expect_error 1 "s.png" $view --script twice.txt
expect_error 1 "old.json: exists" $view --stats old.json
expect_error 1 "not a regular file" $view --stats /dev/null --force
check "isoview leaves the brick file intact" intact
check "and writes nothing" none_of v.json s.png
finish

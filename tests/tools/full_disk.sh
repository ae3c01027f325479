# SPDX-License-Identifier: BSD-3-Clause
# A full or failing disk under every program's outputs (tests/helpers/fault_io.c, preloaded):
# a run whose disk fills up, or whose fsync, link or rename fails, at any point (before its
# first output, inside one, between two, at the last one's commit) fails with one line naming
# the output and the error, exit 1, and leaves none of its outputs and no temporary file: a
# run's outputs are a set, all of them or none.
. "$(dirname "$0")/lib.sh"

shim=$bin/tests/libfault_io.so
# faulty VAR=VALUE... COMMAND...: COMMAND with the shim and the fault settings given
faulty() {
    set -- env LD_PRELOAD="$shim" "$@"
    run_capture "$@"
}
# leaves_only FILE...: the folder holds exactly these files (hidden ones included)
# (.out, .err and .xvfb-status are the test's own: run_capture's and in_xvfb's)
leaves_only() {
    [ "$(ls -A | grep -v -x -e .out -e .err -e .xvfb-status | sort | tr '\n' ' ')" = \
        "$(printf '%s\n' "$@" | sort | tr '\n' ' ')" ]
}
# failed_cleanly WHAT TEXT FILE...: exit 1, one line on stderr holding TEXT, and the folder
# holds only FILE...
failed_cleanly() {
    what=$1 text=$2
    shift 2
    lines=$(printf '%s\n' "$err" | grep -c .)
    check "$what: exit 1 (got $rc)" test "$rc" = 1
    check "$what: one line naming the file and the error ($err)" \
        sh -c '[ "$0" = 1 ] && printf "%s" "$1" | grep -qF -- "$2"' "$lines" "$err" "$text"
    check "$what: none of the outputs, no temporary file ($(ls -A | tr '\n' ' '))" leaves_only "$@"
}

"$bin/isogen" sphere --dims 40x40x40 --type uint8 -o "$work/" --quiet
raw=sphere_40x40x40_uint8.raw
"$bin/isobrick" "$raw" -o s.ibv --brick-size 8 --quiet

# The shim interposes write, pwrite, fsync, rename and linkat; where something else comes first
# and it cannot, the test says so and is skipped.
mkdir probe
faulty IP_FAULT_BYTES=0 "$bin/isogen" sphere --dims 8x8x8 --type uint8 -o probe/ --quiet
if [ "$rc" = 0 ]; then
    echo "SKIP: the fault shim cannot interpose the programs' writes here"
    exit 77
fi
rm -rf probe

# --- isogen: one output ---
faulty IP_FAULT_BYTES=30000 "$bin/isogen" sphere --dims 40x40x30 --type uint8 -o "$work/" --quiet
failed_cleanly "isogen, disk full inside the volume" "sphere_40x40x30_uint8.raw: write failed: No space left on device" "$raw" s.ibv
faulty IP_FAULT_CALL=fsync IP_FAULT_ERRNO=EIO "$bin/isogen" sphere --dims 40x40x30 --type uint8 -o "$work/" --quiet
failed_cleanly "isogen, fsync fails" "fsync failed: Input/output error" "$raw" s.ibv

# --- isobrick: one output, written in parts by several threads ---
size=$(stat -c %s s.ibv)
for budget in 0 $((size / 2)) $((size - 1)); do
    faulty IP_FAULT_BYTES=$budget "$bin/isobrick" "$raw" -o b.ibv --brick-size 8 --quiet
    failed_cleanly "isobrick, disk full after $budget of $size bytes" "b.ibv" "$raw" s.ibv
    check "... and it says the disk is full" sh -c 'printf "%s" "$0" | grep -q "No space left on device"' "$err"
done
for call in fsync linkat; do
    faulty IP_FAULT_CALL=$call IP_FAULT_ERRNO=EIO "$bin/isobrick" "$raw" -o b.ibv --brick-size 8 --quiet
    failed_cleanly "isobrick, $call fails" "b.ibv" "$raw" s.ibv
done

# --- isoinfo --stats ---
faulty IP_FAULT_BYTES=10 "$bin/isoinfo" s.ibv --stats v.json
failed_cleanly "isoinfo --stats, disk full" "v.json: write failed: No space left on device" "$raw" s.ibv

# --- isorender: five outputs, written in this order ---
outputs="i.png st.png m.ply p.csv r.json"
# (one thread: the same mesh every run; the CSV and the JSON hold times, whose digits vary)
render="$bin/isorender s.ibv --iso 128.5 --size 160x120 --software --quiet --threads 1 -o i.png
        --strip st.png --mesh m.ply --progress p.csv --stats r.json"
$render
check "a run with room writes all five" test -s i.png -a -s st.png -a -s m.ply -a -s p.csv -a -s r.json
# a byte in the middle of each output, in the order written: its start and half its size (a
# margin for the few digits the times of the CSV and the JSON may gain or lose)
start=0
middles=""
for f in $outputs; do
    size=$(stat -c %s "$f")
    middles="$middles $((start + size / 2))"
    start=$((start + size))
done
rm -f $outputs
k=0
for f in $outputs; do
    k=$((k + 1))
    budget=$(echo $middles | cut -d' ' -f$k)
    faulty IP_FAULT_BYTES=$budget $render
    failed_cleanly "isorender, disk full inside output $k ($f)" "$f: write failed: No space left on device" "$raw" s.ibv
    faulty IP_FAULT_CALL=linkat IP_FAULT_NTH=$k IP_FAULT_ERRNO=EIO $render
    failed_cleanly "isorender, output $k ($f) cannot be linked into place" "$f: cannot create: Input/output error" "$raw" s.ibv
    faulty IP_FAULT_CALL=fsync IP_FAULT_NTH=$k IP_FAULT_ERRNO=EIO $render
    failed_cleanly "isorender, output $k ($f) cannot be made durable" "$f: fsync failed: Input/output error" "$raw" s.ibv
done
# with --force and the outputs there before: the failed run takes away the new files it had
# put in place (whose old versions it had replaced) and leaves the others as they were
# (docs/reliability.md)
$render
mkdir old && cp $outputs old/
faulty IP_FAULT_CALL=rename IP_FAULT_NTH=3 IP_FAULT_ERRNO=EIO $render --force
check "isorender --force, the third rename fails: exit 1 ($err)" test "$rc" = 1
check "... the two outputs it had replaced are gone" test ! -e i.png -a ! -e st.png
check "... the three it had not reached are the old ones" \
    sh -c 'cmp -s m.ply old/m.ply && cmp -s p.csv old/p.csv && cmp -s r.json old/r.json'
check "... and no temporary file is left" leaves_only "$raw" s.ibv old m.ply p.csv r.json
rm -rf old m.ply p.csv r.json

# --- isorender --turntable: frames in a folder it makes ---
frame=$( "$bin/isorender" s.ibv --iso 128.5 --size 160x120 --software --quiet -o one.png && stat -c %s one.png)
rm -f one.png
faulty IP_FAULT_BYTES=$((frame + frame / 2)) "$bin/isorender" s.ibv --iso 128.5 --size 160x120 \
    --software --quiet --turntable 3 -o tt
failed_cleanly "isorender --turntable, disk full at the second frame" "tt/frame_" "$raw" s.ibv
check "... which said the disk is full" sh -c 'printf "%s" "$0" | grep -q "No space left on device"' "$err"

# --- isoview: a screenshot and --stats, each refused in one line when the disk fails ---
if command -v xvfb-run >/dev/null 2>&1; then
    printf 'wait done\nscreenshot shot.png\nquit\n' >view.txt
    view() { # view VAR=VALUE...: isoview on the script with the shim and the faults given
        in_xvfb 170 640x480x24 env LD_PRELOAD="$shim${preload:+ $preload}" "$@" \
            "$bin/isoview" s.ibv --iso 128.5 --size 160x120 --stats v.json --script view.txt \
            --quiet
    }
    view IP_FAULT_CALL=linkat IP_FAULT_NTH=1 IP_FAULT_ERRNO=EIO
    check "isoview, the screenshot cannot be linked: exit 1 ($rc: $err)" test "$rc" = 1
    check "... one line naming it" sh -c 'printf "%s" "$0" | grep -q "shot.png: cannot create: Input/output error"' "$err"
    check "... no screenshot, no statistics, no temporary file" leaves_only "$raw" s.ibv view.txt
    view IP_FAULT_CALL=linkat IP_FAULT_NTH=2 IP_FAULT_ERRNO=EIO
    check "isoview, --stats cannot be linked: exit 1 ($rc: $err)" test "$rc" = 1
    check "... one line naming it" sh -c 'printf "%s" "$0" | grep -q "v.json: cannot create: Input/output error"' "$err"
    check "... no statistics (the screenshot, a step of the session, stays)" \
        leaves_only "$raw" s.ibv view.txt shot.png
    rm -f shot.png view.txt
else
    echo "full_disk: isoview part skipped: xvfb-run is missing (Debian package xvfb)"
fi

# --- isowall: the image on rank 0, then the statistics; tiles on their owners ---
if command -v mpirun >/dev/null 2>&1 && [ -x "$bin/isowall" ]; then
    wall() {
        run_capture timeout 300 mpirun --oversubscribe --allow-run-as-root -np 2 \
            -x LD_PRELOAD="$shim" -x IP_FAULT_CALL="$1" -x IP_FAULT_NTH="$2" -x IP_FAULT_ERRNO=EIO \
            "$bin/isowall" s.ibv --iso 128.5 --wall 2x1 --tile 80x60 --quiet --timeout 0 "${@:3}"
    }
    wall linkat 2 -o w.png --stats w.json
    check "isowall, the statistics cannot be linked: exit non-zero ($rc)" test "$rc" != 0
    check "... it says so, naming the file" sh -c 'printf "%s" "$0" | grep -q "w.json: cannot create: Input/output error"' "$err"
    check "... and the image it had written is gone" leaves_only "$raw" s.ibv
    mkdir tiles
    wall linkat 2 --tiles-dir tiles --stats w.json
    check "isowall --tiles-dir, the statistics cannot be linked: exit non-zero ($rc)" test "$rc" != 0
    check "... no tile is left" test -z "$(ls -A tiles)"
    rmdir tiles
else
    echo "full_disk: isowall part skipped: no mpirun or no isowall"
fi
finish

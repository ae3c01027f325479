# SPDX-License-Identifier: BSD-3-Clause
# isowall, the display wall's parallel renderer, on 4 MPI processes (oversubscribed): the
# wall's image, dynamic and --static, and the tiles of --tiles-dir equal isorender's software
# image of the same camera and total size (>= 99.99 % identical pixels); the statistics have
# one record per process whose units add up to the work units and rays to the pixels, fewer of
# them stolen than taken (with --static: each tile's units on its owner, none stolen); bad
# --wall, --tile, --unit and --timeout values are usage errors (exit 2). The watchdog: a process
# stopped (SIGSTOP) in the middle of a wall with --timeout 3 ends the job within 30 s, non-zero,
# with one line naming it (process 2, named by process 0; process 0, named by process 1), and
# nothing is left running; a process that computes for longer than --timeout 1 without a message
# does not end it. Registered only where the build found MPI; skipped when mpirun is missing.
. "$(dirname "$0")/lib.sh"

if ! command -v mpirun >/dev/null 2>&1; then
    echo "SKIP: mpirun is not installed (tools/setup.sh installs OpenMPI)"
    exit 77
fi
compare=$bin/tests/png_compare
# Under AddressSanitizer, leak checking is off in the MPI processes: OpenMPI unloads its
# components at MPI_Finalize, so LeakSanitizer cannot name the frames of what they kept (an
# "unknown module"), and no suppression can match them. Memory errors are still caught, and the
# library calls isowall makes (ip_engine_set_region(), ip_raster_mesh_part()) are leak-checked
# by test_engine.
case "${IP_SANITIZE:-}" in
*address*)
    echo "note: leak checking off in the MPI processes (OpenMPI's unloaded components)"
    # (last, so that it wins over a detect_leaks=1 the caller gave, as tools/setup.sh does)
    export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
    ;;
esac
wall() { # wall ARGS...: isowall on 4 processes over g.ibv, 3x2 tiles of 160x120
    timeout 300 mpirun --oversubscribe --allow-run-as-root -np 4 \
        "$bin/isowall" g.ibv --iso 0.5 --wall 3x2 --tile 160x120 --quiet "$@"
}

"$bin/isogen" gyroid --dims 64x64x64 --type float32 -o "$work/" --quiet
"$bin/isobrick" gyroid_64x64x64_float32.raw -o g.ibv --brick-size 16 --quiet
"$bin/isorender" g.ibv --iso 0.5 --size 480x240 --software --azimuth 20 --elevation 15 \
    --quiet -o ref.png

# --- dynamic: the image, the statistics ---
run_capture wall --azimuth 20 --elevation 15 -o dyn.png --stats dyn.json --coarse coarse.png
check "dynamic run exits 0 (got $rc: $err)" test "$rc" = 0
line=$("$compare" dyn.png ref.png --max-pct 0.01)
check "dynamic wall equals isorender's image: $line" test $? = 0
line=$("$compare" coarse.png ref.png --max-pct 100)
check "the coarse pass's image has the wall's size: $line" test $? = 0
for key in '"iso": 0.5' '"width": 480' '"height": 240' '"wall": \[3, 2\]' '"tile": \[160, 120\]' \
    '"processes": 4' '"static": false' '"balance": ' '"coarse_s": ' '"bytes_sent": ' \
    '"rank": 3' '"busy_s": ' '"idle_s": ' '"stolen": '; do
    check "dyn.json has $key" grep -q "$key" dyn.json
done
ranks() { grep -c '"rank": ' "$1"; }
check "one record per process ($(ranks dyn.json))" test "$(ranks dyn.json)" = 4
sum() { # sum FILE KEY: the KEY values of the per-process records, added
    grep '"rank": ' "$1" | grep -o "\"$2\": [0-9.]*" | awk '{ s += $2 } END { printf "%.0f\n", s }'
}
top() { grep -o "^  \"$2\": [0-9.]*" "$1" | awk '{ print $2 }'; }
regions=$(top dyn.json regions)
check "units add up to 2 passes x $regions regions ($(sum dyn.json units))" \
    test "$(sum dyn.json units)" = $((2 * regions))
check "rays add up to the 115200 pixels ($(sum dyn.json rays))" test "$(sum dyn.json rays)" = 115200
check "more regions than processes ($regions)" test "$regions" -gt 16
# every share starts non-empty (more blocks of 4 regions than processes), so the first unit a
# process takes is from its own share: each stole fewer units than it took
over=$(grep '"rank": ' dyn.json | sed 's/.*"units": \([0-9]*\).*"stolen": \([0-9]*\).*/\1 \2/' |
    awk '$2 >= $1 { n++ } END { print n + 0 }')
check "every process stole fewer units than it took ($over did not)" test "$over" = 0
busy=$(grep '"rank": ' dyn.json | grep -c '"units": [1-9]')
check "every process took units ($busy of 4)" test "$busy" = 4

# --- static: one tile's regions per process, the same image (and no watchdog: --timeout 0) ---
run_capture wall --azimuth 20 --elevation 15 --static -o static.png --stats static.json --timeout 0
check "static run exits 0 (got $rc: $err)" test "$rc" = 0
line=$("$compare" static.png ref.png --max-pct 0.01)
check "static wall equals isorender's image: $line" test $? = 0
check "static.json says static" grep -q '"static": true' static.json
check "static rays add up to the pixels" test "$(sum static.json rays)" = 115200
check "static: no units stolen ($(sum static.json stolen))" test "$(sum static.json stolen)" = 0
# tiles 0-5 on 4 processes: processes 0 and 1 own two tiles, 2 and 3 one; per_tile: the units
# of one tile, 2 passes x its 64 regions
units=$(grep '"rank": ' static.json | grep -o '"units": [0-9]*' | awk '{ printf "%s ", $2 }')
per_tile=$((2 * regions / 6))
check "static: each process took its tiles' units ($units)" \
    test "$units" = "$((2 * per_tile)) $((2 * per_tile)) $per_tile $per_tile "

# --- one PNG per display tile, written by the tile's owner ---
run_capture wall --azimuth 20 --elevation 15 --tiles-dir tiles --unit 32x24
check "--tiles-dir run exits 0 (got $rc: $err)" test "$rc" = 0
for c in 0 1 2; do
    for r in 0 1; do
        line=$("$compare" ref.png "tiles/tile_${c}_$r.png" --crop $((c * 160)),$((r * 120)),160,120 \
            --max-pct 0.01)
        check "tile $c,$r equals its part of isorender's image: $line" test $? = 0
    done
done

# --- a bad brick file: one line from isowall (mpirun adds its own), exit 1, no image ---
echo garbage >bad.ibv
run_capture timeout 300 mpirun --oversubscribe --allow-run-as-root -np 4 "$bin/isowall" bad.ibv \
    --iso 0.5 --wall 3x2 --tile 160x120 -o bad.png
lines=$(printf '%s\n' "$err" | grep -c '^isowall: bad.ibv: ')
check "a bad brick file: exit 1, one line naming it (got $rc, $lines lines)" \
    test "$rc" = 1 -a "$lines" = 1
check "a bad brick file: no image" test ! -e bad.png

# --- the watchdog ---
# stop_rank K: a wall of 3x2 tiles of 640x480 with --timeout 3, whose process K is stopped
# (SIGSTOP) as soon as it has written its process id (ISOWALL_PID_DIR: once its watchdog runs,
# before its first collective call, so the wall cannot end without it); sets rc, err, took
# (seconds from the stop to the end of mpirun) and left (processes of the wall still there
# afterwards, then continued and killed)
stop_rank() {
    pids=$work/pids_$1
    mkdir -p "$pids"
    ISOWALL_PID_DIR=$pids timeout 60 mpirun --oversubscribe --allow-run-as-root -np 4 \
        "$bin/isowall" g.ibv --iso 0.5 --wall 3x2 --tile 640x480 --timeout 3 --quiet \
        -o "stop_$1.png" >"$work/.out" 2>"$work/.err" &
    job=$!
    i=0
    while [ ! -s "$pids/rank_$1.pid" ] && [ "$i" -lt 1200 ] && kill -0 "$job" 2>/dev/null; do
        sleep 0.05
        i=$((i + 1))
    done
    stopped=$(cat "$pids/rank_$1.pid" 2>/dev/null)
    [ -n "$stopped" ] && kill -STOP "$stopped"
    t0=$(date +%s.%N)
    wait "$job"
    rc=$?
    took=$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
    err=$(cat "$work/.err")
    left=0
    for f in "$pids"/rank_*.pid; do
        p=$(cat "$f" 2>/dev/null) || continue
        if kill -0 "$p" 2>/dev/null && grep -q isowall "/proc/$p/cmdline" 2>/dev/null; then
            left=$((left + 1))
            kill -CONT "$p" 2>/dev/null
            kill -KILL "$p" 2>/dev/null
        fi
    done
}
for k in 2 0; do
    namer=$((k == 0 ? 1 : 0))
    stop_rank $k
    echo "process $k stopped: the wall ended $took s later, exit $rc"
    check "process $k stopped: found its process id" test -n "$stopped"
    check "process $k stopped: a non-zero exit, not the safety net's (got $rc)" \
        test "$rc" != 0 -a "$rc" != 124
    check "process $k stopped: the wall ended within 30 s of the stop ($took s)" \
        awk -v t="$took" 'BEGIN { exit !(t < 30) }'
    named=$(printf '%s\n' "$err" | grep -c "^isowall: rank $k sent nothing for [0-9.]* s (rank $namer was ")
    lines=$(printf '%s\n' "$err" | grep -c '^isowall: ')
    check "process $k stopped: one line naming it, from process $namer ($named of $lines: $err)" \
        test "$named" = 1 -a "$lines" = 1
    check "process $k stopped: nothing left running ($left)" test "$left" = 0
done
# process 0 alone casts the one unit of the second pass, then draws the one tile and writes the
# 2048x2048 image, while the others wait for it (--static, a 1x1 wall, one unit a pass): it
# sends nothing on the wall's communicator for longer than the timeout (here 2-3 s; the line
# below says how long on this run), and the wall ends as usual
run_capture timeout 300 mpirun --oversubscribe --allow-run-as-root -np 4 "$bin/isowall" g.ibv \
    --iso 0.5 --wall 1x1 --tile 2048x2048 --unit 2048x2048 --static --timeout 1 --quiet \
    -o slow.png --stats slow.json
check "a process busy for longer than --timeout 1: exit 0 (got $rc: $err)" test "$rc" = 0
quiet=$(awk -v c="$(top slow.json coarse_s)" -v e="$(top slow.json extraction_s)" \
    -v t="$(top slow.json time_s)" 'BEGIN { printf "%.1f s, then %.1f s", e - c, t - e }')
echo "process 0 sent nothing for $quiet (the second pass; the tile and the image), --timeout 1"

# --- bad values: usage errors before MPI starts ---
expect_error 2 "--wall '0x2'" "$bin/isowall" g.ibv --iso 0.5 --wall 0x2 --tile 160x120
expect_error 2 "--wall '3'" "$bin/isowall" g.ibv --iso 0.5 --wall 3 --tile 160x120
expect_error 2 "--tile '160x0'" "$bin/isowall" g.ibv --iso 0.5 --wall 3x2 --tile 160x0
expect_error 2 "--tile 'abc'" "$bin/isowall" g.ibv --iso 0.5 --wall 3x2 --tile abc
expect_error 2 "--unit 200x10 is larger" "$bin/isowall" g.ibv --iso 0.5 --wall 3x2 \
    --tile 160x120 --unit 200x10
expect_error 2 "--wall CxR and --tile WxH are required" "$bin/isowall" g.ibv --iso 0.5 --wall 3x2
expect_error 2 "--size is isorender's" "$bin/isowall" g.ibv --iso 0.5 --wall 3x2 --tile 8x8 \
    --size 16x16
expect_error 2 "--timeout '-1' is not seconds" "$bin/isowall" g.ibv --iso 0.5 --wall 3x2 \
    --tile 160x120 --timeout -1
expect_error 2 "--timeout 'soon' is not seconds" "$bin/isowall" g.ibv --iso 0.5 --wall 3x2 \
    --tile 160x120 --timeout soon
expect_error 2 "larger than 65536" "$bin/isowall" g.ibv --iso 0.5 --wall 200x1 --tile 400x8

# random views (tools/dev/soak_exact.sh with SOAK_WALL=on): 12 cases on the generated volumes, 3 of
# them also on a display wall of random tiles and processes (2 with adaptive resolution, 1 with
# two clipping planes), whose image must equal the full extraction's byte for byte
soak=$(cd "$(dirname "$0")/../../tools/dev" && pwd)/soak_exact.sh
run_capture env SOAK_DATA= SOAK_WALL=on sh "$soak" "$bin" 12 13 "$work/soak"
check "12 random views, 3 on a wall: every image equals the full extraction's ($rc)" \
    test "$rc" = 0
walls=$(grep -c "| isowall --wall" "$work/soak/cases" || true)
check "$walls of them on a wall" test "$walls" = 3
run_capture env SOAK_DATA= SOAK_WALL=maybe sh "$soak" "$bin" 2 5 "$work/soak"
check "a bad SOAK_WALL exits 2 ($rc)" test "$rc" = 2
finish

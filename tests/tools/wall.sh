# isowall, the display wall's parallel renderer, on 4 MPI processes (oversubscribed): the
# wall's image, dynamic and --static, and the tiles of --tiles-dir equal isorender's software
# image of the same camera and total size (>= 99.99 % identical pixels); the statistics have
# one record per process whose units add up to the work units and rays to the pixels, fewer of
# them stolen than taken (with --static: each tile's units on its owner, none stolen); bad
# --wall, --tile and --unit values are usage errors (exit 2). Registered only where the build
# found MPI; skipped when mpirun is missing.
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

# --- static: one tile's regions per process, the same image ---
run_capture wall --azimuth 20 --elevation 15 --static -o static.png --stats static.json
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

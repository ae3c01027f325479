#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# The display wall's bad case (docs/scale-out.md): isowall on the Visible Woman head (skin
# 600.5) on a 6x4 wall whose camera puts the whole head inside one display tile, with the
# regions of each tile on the process that owns it (--static, one copy per projector, the
# paper's wall) against dynamic shares with stealing, at 2, 4 and 8 processes, and one
# process for the total work; then a 6x4 wall of 1280x1024 tiles (31 Mpixel) with the whole
# head in view, to show that it completes. Processes beyond the cores are oversubscribed, so
# compare the CPU-busy seconds (busy_s), not the wall time. Prints Markdown tables; the JSON
# of every run stays in WORK_DIR.
#
#   tools/bench/bench_wall.sh WORK_DIR [BUILD_DIR] [RAW_FILE]
#   defaults: build ../shared/data/ct_head_visible_woman_512x512x234_uint16.raw
#   IP_WALL_TILE (default 1280x1024): the tile of the bad case; IP_WALL_REPEATS (default 5):
#   runs of each case, the one of median balance shown, with the range of balance;
#   IP_WALL_MPIRUN_ARGS: more mpirun options (default --mca osc sm --bind-to
#   core:overload-allowed, see docs/scale-out.md); IP_WALL_BIG_PROCESSES (default 4): the
#   processes of the 31-Mpixel run
set -eu
work=${1:?usage: tools/bench/bench_wall.sh WORK_DIR [BUILD_DIR] [RAW_FILE]}
build=${2:-build}
raw=${3:-../shared/data/ct_head_visible_woman_512x512x234_uint16.raw}
tile=${IP_WALL_TILE:-1280x1024}
repeats=${IP_WALL_REPEATS:-5}
mpi_args=${IP_WALL_MPIRUN_ARGS:---mca osc sm --bind-to core:overload-allowed}
[ -f "$raw" ] || { echo "bench_wall: $raw is missing" >&2; exit 1; }
for p in isobrick isowall; do
    [ -x "$build/$p" ] || { echo "bench_wall: $build/$p is missing (isowall needs MPI: tools/setup.sh)" >&2; exit 1; }
done
command -v mpirun >/dev/null || { echo "bench_wall: mpirun is missing (tools/setup.sh)" >&2; exit 1; }
mkdir -p "$work"
ibv=$work/head.ibv
[ -f "$ibv" ] || "$build/isobrick" "$raw" -o "$ibv" --quiet
iso=600.5

# wall NP JSON ARGS...: isowall on NP processes; prints the wall seconds mpirun took
wall() {
    np=$1 json=$2
    shift 2
    start=$(date +%s.%N)
    # shellcheck disable=SC2086 # mpi_args is several words on purpose
    mpirun --oversubscribe --allow-run-as-root -np "$np" $mpi_args "$build/isowall" "$ibv" \
        --iso "$iso" --wall 6x4 --quiet --force --stats "$json" "$@"
    echo "$(date +%s.%N) $start" | awk '{ printf "%.2f\n", $1 - $2 }'
}
top() { grep -o "^  \"$2\": [-0-9.e]*" "$1" | awk '{ print $2 }'; }

# The bad case's camera: the -y view of the whole volume (isorender's, from a tiny wall of the
# same aspect), moved 1 / zoom times farther along the view and panned so that the volume's
# centre projects onto the centre of tile (2, 1), left of and above the wall's centre.
tw=${tile%x*} th=${tile#*x}
wall 1 "$work/fit.json" --tile "$((tw / 16))x$((th / 16))" -o "$work/fit.png" >/dev/null
camera=$(grep -o '"camera": \[[^]]*\]' "$work/fit.json" | tr -d '[]"a-z:' | tr ',' ' ')
zoom=0.3
cam=$(echo "$camera" | awk -v z="$zoom" -v tw="$tw" -v th="$th" '{
    d = ($5 - $2) / z                  # the eye is on -y, looking along +y
    pix = 2 * d * sin($10 * atan2(0, -1) / 360) / cos($10 * atan2(0, -1) / 360) / (4 * th)
    dx = tw / 2 * pix; dz = -th / 2 * pix
    printf "%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,0,0,1,%g", $4 + dx, $5 - d, $6 + dz, $4 + dx, $5, $6 + dz, $10 }')
echo "bench_wall: head skin $iso, wall 6x4 of $tile, camera $cam (the head in tile 2,1)"
echo "bench_wall: mpirun --oversubscribe -np N $mpi_args isowall head.ibv --iso $iso --wall 6x4 --tile $tile --camera $cam [--static]; $(nproc) cores"

# one case, repeated; keeps the run of median balance as NAME.json, prints its wall seconds
case_run() {
    name=$1 np=$2
    shift 2
    : >"$work/$name.runs"
    r=0
    while [ "$r" -lt "$repeats" ]; do
        r=$((r + 1))
        secs=$(wall "$np" "$work/$name.$r.json" --tile "$tile" --camera "$cam" -o "$work/$name.png" "$@")
        echo "$(top "$work/$name.$r.json" balance) $r $secs" >>"$work/$name.runs"
    done
    median=$(sort -n "$work/$name.runs" | awk -v n="$repeats" 'NR == int((n + 1) / 2) { print $2, $3 }')
    cp "$work/$name.${median% *}.json" "$work/$name.json"
    echo "${median#* }"
}
secs1=$(case_run one 1)
busy1=$(top "$work/one.json" busy_s)
tri1=$(top "$work/one.json" triangles)
echo
echo "| processes | mode | balance (max/mean busy) | balance over $repeats runs | sum busy_s | max busy_s | work / 1 process | triangles / 1 process | bytes sent | wall s |"
echo "|---|---|---|---|---|---|---|---|---|---|"
row() { # row JSON NP MODE SECONDS
    range=$(sort -n "${1%.json}.runs" | awk 'NR == 1 { lo = $1 } { hi = $1 } END { printf "%.3f-%.3f", lo, hi }')
    awk -v b="$(top "$1" balance)" -v s="$(top "$1" busy_s)" -v m="$(top "$1" max_busy_s)" \
        -v range="$range" \
        -v t="$(top "$1" triangles)" -v bytes="$(top "$1" bytes_sent)" -v b1="$busy1" \
        -v t1="$tri1" -v np="$2" -v mode="$3" -v secs="$4" 'BEGIN {
        printf "| %d | %s | %.3f | %s | %.3f | %.3f | %.2f | %.2f | %.1f MB | %s |\n",
               np, mode, b, range, s, m, s / b1, t / t1, bytes / 1e6, secs }'
}
row "$work/one.json" 1 "one process" "$secs1"
for np in 2 4 8; do
    secs=$(case_run "static$np" "$np" --static)
    row "$work/static$np.json" "$np" static "$secs"
    secs=$(case_run "dynamic$np" "$np")
    row "$work/dynamic$np.json" "$np" dynamic "$secs"
done
echo
printf 'units stolen (dynamic, summed over the processes, of %s):' "$(top "$work/one.json" units)"
for np in 2 4 8; do
    printf ' %s at %d' "$(grep -o '"stolen": [0-9]*' "$work/dynamic$np.json" | awk '{ s += $2 } END { print s + 0 }')" "$np"
done
echo

# the whole head on a 31-Mpixel wall
echo
np=${IP_WALL_BIG_PROCESSES:-4}
secs=$(wall "$np" "$work/big.json" --tile 1280x1024 -o "$work/big.png")
echo "6x4 wall of 1280x1024 tiles ($(top "$work/big.json" width)x$(top "$work/big.json" height)), whole head, $np processes, dynamic:"
echo "  wall $secs s, balance $(top "$work/big.json" balance), sum busy_s $(top "$work/big.json" busy_s), coarse pass done at $(top "$work/big.json" coarse_s) s,"
echo "  triangles $(top "$work/big.json" triangles), bytes sent $(top "$work/big.json" bytes_sent), peak RSS per process (MB):" \
    "$(grep -o '"peak_rss_mb": [0-9.]*' "$work/big.json" | awk '{ printf "%s ", $2 }')"

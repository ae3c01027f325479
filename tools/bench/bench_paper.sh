#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# Reproduces the paper's Tables 1 and 2 (Liu, Finkelstein, Li) on the Visible Woman head:
# skin 600.5 from the front (--view -y) and bone 1224.5 from the side (--view -x), 1600x1200,
# cut-off 1.81 degrees; progressive extraction cold (a fresh process, page cache dropped when
# allowed) and warm (the same process after one untimed run), beside the full extraction.
# Prints Markdown tables and writes a plot (PNG, with gnuplot) and the raw CSV/JSON files.
#
# Every run is repeated ROUNDS times (default 5), the rounds interleaved (each round runs every
# surface and mode once); times are medians [min-max] over the rounds, the other columns come
# from the first round (they differ between rounds by a few triangles at most, on several
# threads), and OUT_DIR keeps the first round's CSV and JSON files and its warm images.
#
#   [ROUNDS=N] tools/bench/bench_paper.sh [RAW_FILE] [BUILD_DIR] [OUT_DIR]
#   defaults: ../shared/data/ct_head_visible_woman_512x512x234_uint16.raw build docs/results
set -eu
raw=${1:-../shared/data/ct_head_visible_woman_512x512x234_uint16.raw}
build=${2:-build}
out=${3:-docs/results}
rounds=${ROUNDS:-5}
case $rounds in '' | *[!0-9]* | 0) echo "bench_paper: ROUNDS must be a positive integer" >&2; exit 2 ;; esac
[ -f "$raw" ] || { echo "bench_paper: $raw is missing" >&2; exit 1; }
for p in isobrick isorender; do
    [ -x "$build/$p" ] || { echo "bench_paper: $build/$p is missing: run tools/setup.sh build" >&2; exit 1; }
done
if ! command -v gnuplot >/dev/null; then
    if [ "$(id -u)" = 0 ]; then
        apt-get install -y -qq gnuplot-nox >/dev/null
    else
        echo "bench_paper: gnuplot is missing (apt-get install gnuplot-nox)" >&2
        exit 1
    fi
fi
mkdir -p "$out"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
ibv=$tmp/head.ibv
"$build/isobrick" "$raw" -o "$ibv" --quiet

drop_caches() {
    sync
    if echo 3 2>/dev/null >/proc/sys/vm/drop_caches; then cold_note="page cache dropped"; else cold_note="page cache not dropped (not allowed here)"; fi
}

# render NAME ISO VIEW MODE ROUND: MODE is cold, warm, full-cold or full-warm; the outputs go
# to $tmp/ROUND/
render() {
    name=$1 iso=$2 view=$3 mode=$4 dir=$tmp/$5
    mkdir -p "$dir"
    set -- --iso "$iso" --view "$view" --size 1600x1200 --cutoff 1.81 --force --quiet \
        -o "$dir/$name-$mode.png" --stats "$dir/$name-$mode.json"
    case $mode in
    cold) drop_caches; "$build/isorender" "$ibv" "$@" --progress "$dir/$name-$mode.csv" ;;
    warm) "$build/isorender" "$ibv" "$@" --progress "$dir/$name-$mode.csv" --warm ;;
    full-cold) drop_caches; "$build/isorender" "$ibv" "$@" --full ;;
    full-warm) "$build/isorender" "$ibv" "$@" --full --warm ;;
    esac
}

json() { sed "s/.*\"$2\": \([0-9.e+-]*\).*/\1/" "$1"; }

# json_key KEY FILE: json FILE KEY (the file last, for over_rounds)
json_key() { json "$2" "$1"; }

# point_time PCT CSV: the time of the first checkpoint at or above PCT final pixels
point_time() { awk -F, -v p="$1" 'NR > 1 && $6 + 0 >= p { print $1; exit }' "$2"; }

# point_rest CSV PCT: that checkpoint's triangles (K) | rays (K) | final pixels (%)
point_rest() {
    awk -F, -v p="$2" 'NR > 1 && $6 + 0 >= p { printf "%.0f | %.1f | %.1f", $5 / 1000, $2 / 1000, $6; exit }' "$1"
}

# stat: the numbers on standard input (one a line) as "median [min-max]", FORMAT each
stat() {
    sort -g | awk -v f="$1" '{ v[NR] = $1 } END {
        m = NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2
        if (NR == 1) printf f, m; else printf f " [" f "-" f "]", m, v[1], v[NR] }'
}

# over_rounds FILE COMMAND...: the output of COMMAND... with round r's FILE as its last
# argument, for every round in turn
over_rounds() {
    f=$1
    shift
    r=1
    while [ "$r" -le "$rounds" ]; do "$@" "$tmp/$r/$f"; r=$((r + 1)); done
}

r=1
while [ "$r" -le "$rounds" ]; do
    for surface in "skin 600.5 -y" "bone 1224.5 -x"; do
        set -- $surface
        for mode in cold warm full-cold full-warm; do render "$1" "$2" "$3" "$mode" "$r"; done
    done
    r=$((r + 1))
done
cp "$tmp"/1/*.csv "$tmp"/1/*.json "$tmp"/1/*-warm.png "$out"/

echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //');" \
    "$rounds rounds, interleaved: times are medians [min-max]"
for surface in "skin 600.5 -y" "bone 1224.5 -x"; do
    set -- $surface
    name=$1 iso=$2 view=$3
    echo
    echo "### $name (iso $iso, view $view): $cold_note for the cold runs"
    echo
    echo "| run | point | time (s) | triangles (K) | rays (K) | final pixels (%) |"
    echo "| --- | --- | ---: | ---: | ---: | ---: |"
    for mode in cold warm; do
        for p in "A (>= 85 %) 85" "B (>= 99.5 %) 99.5" "C (all rays) 100"; do
            pct=${p##* }
            t=$(over_rounds "$name-$mode.csv" point_time "$pct" | stat %.3f)
            echo "| $mode | ${p% *} | $t | $(point_rest "$tmp/1/$name-$mode.csv" "$pct") |"
        done
    done
    for mode in full-cold full-warm; do
        t=$(over_rounds "$name-$mode.json" json_key extraction_wall_s | stat %.3f)
        printf '| %s | every active cell | %s | %.0f | - | - |\n' "$mode" "$t" \
            "$(awk -v t="$(json "$tmp/1/$name-$mode.json" triangles)" 'BEGIN{print t/1000}')"
    done
    echo
    echo "CPU time by phase, summed over the threads (medians over the rounds):"
    echo
    echo "| run | intersection (s) | propagation (s) | marching cubes (s) | rendering (s) | seeds | cells |"
    echo "| --- | ---: | ---: | ---: | ---: | ---: | ---: |"
    for mode in cold warm full-cold; do
        j=$name-$mode.json
        printf '| %s | %s | %s | %s | %s | %s | %s |\n' "$mode" \
            "$(over_rounds "$j" json_key intersection_s | stat %.3f | cut -d' ' -f1)" \
            "$(over_rounds "$j" json_key propagation_s | stat %.3f | cut -d' ' -f1)" \
            "$(over_rounds "$j" json_key extraction_s | stat %.3f | cut -d' ' -f1)" \
            "$(over_rounds "$j" json_key rendering_s | stat %.3f | cut -d' ' -f1)" \
            "$(json "$tmp/1/$j" seeds)" "$(json "$tmp/1/$j" cells)"
    done
done

gnuplot <<GP
set terminal pngcairo size 1200,500 font ",11"
set output "$out/progress.png"
set multiplot layout 1,2
do for [s in "skin bone"] {
    set title s." (warm): final pixels and triangles over time"
    set xlabel "elapsed time (s)"
    set ylabel "final pixels (%)"
    set y2label "triangles (K)"
    set yrange [0:100]
    set y2range [0:*]
    set ytics nomirror
    set y2tics
    set key bottom right
    set datafile separator ","
    plot "$out/".s."-warm.csv" using 1:6 skip 1 with linespoints title "final pixels", \
         "$out/".s."-warm.csv" using 1:(\$5/1000) skip 1 axes x1y2 with linespoints title "triangles"
}
unset multiplot
GP
echo
echo "plot: $out/progress.png"

#!/bin/sh
# Reproduces the paper's Tables 1 and 2 (Liu, Finkelstein, Li) on the Visible Woman head:
# skin 600.5 from the front (--view -y) and bone 1224.5 from the side (--view -x), 1600x1200,
# cut-off 1.81 degrees; progressive extraction cold (a fresh process, page cache dropped when
# allowed) and warm (the same process after one untimed run), beside the full extraction.
# Prints Markdown tables and writes a plot (PNG, with gnuplot) and the raw CSV/JSON files.
#
#   tools/bench_paper.sh [RAW_FILE] [BUILD_DIR] [OUT_DIR]
#   defaults: ../shared/data/ct_head_visible_woman_512x512x234_uint16.raw build docs/results
set -eu
raw=${1:-../shared/data/ct_head_visible_woman_512x512x234_uint16.raw}
build=${2:-build}
out=${3:-docs/results}
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

# render NAME ISO VIEW MODE: MODE is cold, warm, full-cold or full-warm
render() {
    name=$1 iso=$2 view=$3 mode=$4
    set -- --iso "$iso" --view "$view" --size 1600x1200 --cutoff 1.81 --force --quiet \
        -o "$out/$name-$mode.png" --stats "$out/$name-$mode.json"
    case $mode in
    cold) drop_caches; "$build/isorender" "$ibv" "$@" --progress "$out/$name-$mode.csv" ;;
    warm) "$build/isorender" "$ibv" "$@" --progress "$out/$name-$mode.csv" --warm ;;
    full-cold) drop_caches; "$build/isorender" "$ibv" "$@" --full ;;
    full-warm) "$build/isorender" "$ibv" "$@" --full --warm ;;
    esac
}

json() { sed "s/.*\"$2\": \([0-9.e+-]*\).*/\1/" "$1"; }

# point CSV PCT: the first checkpoint at or above PCT final pixels: time,triangles,rays,pct
point() {
    awk -F, -v p="$2" 'NR > 1 && $6 + 0 >= p { printf "%.2f | %.0f | %.1f | %.1f", $1, $5 / 1000, $2 / 1000, $6; exit }' "$1"
}

echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
for surface in "skin 600.5 -y" "bone 1224.5 -x"; do
    set -- $surface
    name=$1 iso=$2 view=$3
    for mode in cold warm full-cold full-warm; do render "$name" "$iso" "$view" "$mode"; done
    echo
    echo "### $name (iso $iso, view $view): $cold_note for the cold runs"
    echo
    echo "| run | point | time (s) | triangles (K) | rays (K) | final pixels (%) |"
    echo "| --- | --- | ---: | ---: | ---: | ---: |"
    for mode in cold warm; do
        csv=$out/$name-$mode.csv
        echo "| $mode | A (>= 85 %) | $(point "$csv" 85) |"
        echo "| $mode | B (>= 99.5 %) | $(point "$csv" 99.5) |"
        echo "| $mode | C (all rays) | $(point "$csv" 100) |"
    done
    for mode in full-cold full-warm; do
        j=$out/$name-$mode.json
        printf '| %s | every active cell | %.2f | %.0f | - | - |\n' "$mode" \
            "$(json "$j" extraction_wall_s)" "$(awk -v t="$(json "$j" triangles)" 'BEGIN{print t/1000}')"
    done
    echo
    echo "| run | intersection (s) | propagation (s) | marching cubes (s) | rendering (s) | seeds | cells |"
    echo "| --- | ---: | ---: | ---: | ---: | ---: | ---: |"
    for mode in cold warm full-cold; do
        j=$out/$name-$mode.json
        printf '| %s | %.3f | %.3f | %.3f | %.3f | %s | %s |\n' "$mode" "$(json "$j" intersection_s)" \
            "$(json "$j" propagation_s)" "$(json "$j" extraction_s)" "$(json "$j" rendering_s)" \
            "$(json "$j" seeds)" "$(json "$j" cells)"
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

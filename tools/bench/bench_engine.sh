#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# The engine's performance against its peers, in one run on one machine (results in
# docs/benchmarks.md). Prints one Markdown table per part:
#
#   1. the paper's case: the Visible Woman head, skin 600.5 (-y) and bone 1224.5 (-x), 1600x1200,
#      cut-off 1.81: time to 85 % and 99.5 % final pixels and to all rays, cold, fresh (a new
#      process, page cache warm) and warm, and the overdraw, beside
#      isorender --full and VTK's vtkFlyingEdges3D / vtkMarchingCubes (filter Update() only)
#      and VTK's rendering of the Flying Edges output at 1600x1200 offscreen; the targets as
#      ratios to Flying Edges in the same run, the overdraw's floor (the triangles that
#      show at all, counted at 6400x4800), the marching cubes floor (bench_floor: only the
#      cells that own a pixel of the final image, triangulated alone) and the walked floor
#      (bench_floor RAYS: the cells the engine extracts by the warm 99.5 %, triangulated alone);
#   2. out of core: the head upsampled 4x (2048x2048x936 uint16, 7.3 GiB), bricked once, viewed
#      with a 512 MiB cache: time to first image and to 99.5 %, peak RSS, bricks touched, hit
#      rate; beside it the peak memory of VTK Flying Edges on the same raw file (if it fits);
#   3. display scaling: 512x512, 1600x1200, 3840x2160 (skin, warm);
#   4. threads: --threads 1 against every core, progressive (all rays) and --full;
#   5. profiles (perf record) of the engine: progressive, --full, and the out-of-core view.
#
#   tools/bench/bench_engine.sh [BUILD_DIR] [WORK_DIR]
#   defaults: build, /tmp/bench_engine (raw CSV/JSON/PNG/perf files are kept there)
#   environment: RAW (the 512x512x234 head), BIG_DIR (where the x4 volume and its brick file
#   are, or are made: /work/big), REPEAT (runs per measurement, median reported: 5),
#   PLOTS (where the PNG plots go: docs/performance), MAX_LOAD (1.5), MAX_WAIT (s, 180),
#   PROFILE (1: run part 5), PARTS (which parts to run: "1 2 3 4 5"), REPORT (1: measure
#   nothing, print the tables and draw the plots again from the files in WORK_DIR)
#
# Cold runs are fresh processes after `sync; echo 3 > /proc/sys/vm/drop_caches` (when allowed);
# warm runs use isorender --warm (one untimed extraction first, in the same process). Engine
# times come from isorender's --progress CSV (checkpoints at doubling ray counts, clock started
# at ip_engine_begin) and --stats JSON. Not a test: it only measures and prints.
set -eu
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-build}
work=${2:-/tmp/bench_engine}
raw=${RAW:-$root/../shared/data/ct_head_visible_woman_512x512x234_uint16.raw}
big_dir=${BIG_DIR:-/work/big}
big_raw=$big_dir/ct_head_visible_woman_x4_2048x2048x936_uint16.raw
big_ibv=$big_dir/ct_x4.ibv
repeat=${REPEAT:-5}
plots=${PLOTS:-$root/docs/performance}
max_load=${MAX_LOAD:-1.5}
max_wait=${MAX_WAIT:-180}
parts=${PARTS:-1 2 3 4 5}
report_only=${REPORT:-0}
[ "${PROFILE:-1}" = 1 ] || parts=$(echo "$parts" | sed 's/5//')
py=/usr/bin/python3
case $build in /*) ;; *) build=$root/$build ;; esac
[ -f "$raw" ] || { echo "bench_engine: $raw is missing" >&2; exit 1; }
for p in isobrick isorender isogen bench_floor; do
    [ -x "$build/$p" ] || { echo "bench_engine: $build/$p is missing: run tools/setup.sh build" >&2; exit 1; }
done

# --- what it needs: gnuplot, VTK for Python, Xvfb (VTK renders through GLX), perf ------------
need=""
command -v gnuplot >/dev/null || need="$need gnuplot-nox"
[ -x $py ] && $py -c 'import vtk, numpy' 2>/dev/null || need="$need python3-vtk9 python3-numpy"
command -v xvfb-run >/dev/null || need="$need xvfb xauth"
command -v perf >/dev/null || need="$need linux-perf"
if [ -n "$need" ]; then
    if [ "$(id -u)" = 0 ]; then
        echo "bench_engine: installing$need" >&2
        export DEBIAN_FRONTEND=noninteractive
        apt-get install -y -qq $need >/dev/null 2>&1 || { apt-get update -qq && apt-get install -y -qq $need >/dev/null; }
    else
        echo "bench_engine: missing Debian packages:$need (run as root, or install them)" >&2
        exit 1
    fi
fi

mkdir -p "$work" "$plots"
cd "$work"

# --- helpers -------------------------------------------------------------------------------
cat >h.py <<'PY'
import json, statistics, sys
def rows(path):
    with open(path) as f:
        next(f)
        return [[float(v) for v in line.split(",")] for line in f if line.strip()]
def get(path, *keys):
    d = json.load(open(path))
    for k in keys:
        d = d[int(k)] if isinstance(d, list) else d[k]
    return d
def point(path, pct):
    """first checkpoint at or above pct: time, previous checkpoint's time, rays, triangles"""
    r = rows(path)
    for i, row in enumerate(r):
        if row[5] >= pct:
            return row[0], (r[i - 1][0] if i else 0.0), row[1], row[4], row[5]
    return None
cmd, args = sys.argv[1], sys.argv[2:]
if cmd == "get":
    print(get(*args))
elif cmd == "point":            # CSV PCT -> "time [prev]" rays(K) triangles(K)
    p = point(args[0], float(args[1]))
    print("- | - | -" if p is None else
          "%.3f [%.3f] | %.1f | %.0f" % (p[0], p[1], p[2] / 1e3, p[3] / 1e3))
elif cmd == "t":                # CSV PCT -> time of the first checkpoint at or above PCT
    p = point(args[0], float(args[1]))
    print("nan" if p is None else "%.6f" % p[0])
elif cmd == "last":             # CSV -> all-rays time, triangles(K)
    r = rows(args[0])[-1]
    print("%.3f | %.0f" % (r[0], r[4] / 1e3))
elif cmd == "median-csv":       # CSV... -> the file whose last checkpoint time is the median
    f = sorted(args, key=lambda p: rows(p)[-1][0])
    print(f[(len(f) - 1) // 2])
elif cmd == "median-json":      # KEY.PATH JSON... -> the file whose value is the median
    keys = args[0].split(".")
    f = sorted(args[1:], key=lambda p: float(get(p, *keys)))
    print(f[(len(f) - 1) // 2])
elif cmd == "range":            # PCT CSV... -> min-max time to PCT
    t = [point(p, float(args[0]))[0] for p in args[1:]]
    print("%.3f-%.3f" % (min(t), max(t)))
elif cmd == "vtk":              # JSONL FIELD [key=value...] -> median of FIELD over matching lines
    vals = []
    for line in open(args[0]):
        d = json.loads(line)
        if all(str(d.get(k)) == v for k, v in (a.split("=", 1) for a in args[2:])):
            vals.append(float(d[args[1]]))
    print("%.6g" % statistics.median(vals) if vals else "nan")
elif cmd == "pointm":           # PCT CSV... -> medians: "time [prev] | rays(K) | triangles(K)"
    ps = [point(p, float(args[0])) for p in args[1:]]
    m = lambda i: statistics.median(p[i] for p in ps)
    ml = lambda i: statistics.median_low(p[i] for p in ps)
    print("%.3f [%.3f] | %.1f | %.0f" % (m(0), m(1), ml(2) / 1e3, ml(3) / 1e3))
elif cmd == "lastm":            # CSV... -> medians: "all-rays time | triangles(K)"
    r = [rows(p)[-1] for p in args]
    print("%.3f | %.0f" % (statistics.median(x[0] for x in r),
                           statistics.median_low(x[4] for x in r) / 1e3))
elif cmd == "jmed":             # KEY.PATH JSON... -> median (low: an actual value)
    print(statistics.median_low(float(get(p, *args[0].split("."))) for p in args[1:]))
elif cmd == "timemed":          # TIME... -> median of column 1 (elapsed s) and 2 (max RSS KiB)
    v = [open(p).read().split() for p in args]
    print("%.2f %.0f" % (statistics.median(float(x[0]) for x in v),
                         statistics.median(float(x[1]) for x in v)))
elif cmd == "tstats":           # PCT CSV... -> median min max of the time to PCT
    t = [point(p, float(args[0]))[0] for p in args[1:]]
    print("%.6f %.6f %.6f" % (statistics.median(t), min(t), max(t)))
elif cmd == "jstats":           # KEY.PATH JSON... -> median min max
    t = [float(get(p, *args[0].split("."))) for p in args[1:]]
    print("%.6f %.6f %.6f" % (statistics.median(t), min(t), max(t)))
elif cmd == "odstats":          # PCT CSV... -> median min max of the overdraw at the first
    # checkpoint at or above PCT (column 8 of the progress CSV)
    t = []
    for p in args[1:]:
        r = rows(p)
        t.append(next(row[7] for row in r if row[5] >= float(args[0])))
    print("%.6f %.6f %.6f" % (statistics.median(t), min(t), max(t)))
elif cmd == "calc":             # a Python expression over numbers
    print(eval(args[0], {"__builtins__": {}}, {"min": min, "max": max, "int": int, "round": round}))
PY
h() { $py "$work/h.py" "$@"; }
calc() { h calc "$1"; }

cold_note="page cache not dropped"
drop_caches() {
    sync
    if echo 3 2>/dev/null >/proc/sys/vm/drop_caches; then
        cold_note="page cache dropped before each cold run"
    else
        cold_note="page cache NOT dropped (not allowed here): cold runs are only fresh processes"
    fi
}

# busy: cores kept busy by every process over the next 5 s (from /proc/stat), while this script
# only sleeps, i.e. the load of other processes now (the 1-minute load average still holds the
# previous part's own work).
busy() {
    a=$(awk '/^cpu / { print $2 + $3 + $4 + $7 + $8, $2 + $3 + $4 + $5 + $6 + $7 + $8 }' /proc/stat)
    sleep 5
    b=$(awk '/^cpu / { print $2 + $3 + $4 + $7 + $8, $2 + $3 + $4 + $5 + $6 + $7 + $8 }' /proc/stat)
    echo "$a $b" | awk -v n="$(nproc)" '{ printf "%.2f", n * ($3 - $1) / ($4 - $2) }'
}

# wait_load PART: waits (up to MAX_WAIT s) until other processes keep less than MAX_LOAD / 3
# cores busy (0.5 by default) and the 1-minute load average is below MAX_LOAD, or at least the
# former, then prints `uptime`'s load averages and that figure.
wait_load() {
    part_no=$(echo "$1" | cut -d: -f1)
    if [ "$report_only" = 1 ]; then
        cat "part$part_no.before"
        return 0
    fi
    waited=0
    while :; do
        now_busy=$(busy)
        calm=$(awk -v b="$now_busy" -v m="$max_load" '{ print (b < m / 3) + (b < m / 3 && $1 < m) }' /proc/loadavg)
        [ "$calm" = 2 ] && break
        [ "$calm" = 1 ] && [ "$waited" -ge 60 ] && break
        [ "$waited" -ge "$max_wait" ] && break
        sleep 10
        waited=$((waited + 15))
    done
    {
        echo
        echo "## Part $1"
        echo
        echo "uptime before the part: $(uptime | sed 's/^ *//; s/,  *[0-9]* user.*load/, load/')" \
            "(waited ${waited} s); other processes kept $now_busy of $(nproc) cores busy just before."
    } >"part$part_no.before"
    cat "part$part_no.before"
    cpu_marks
    part_m0=$marks
}

# iso RUN NAME FILE [isorender options...]: one isorender process; writes NAME.json/.csv/.png
# and NAME.time ("elapsed_s max_rss_kb" of the whole process, /usr/bin/time).
iso_run() { # (variables prefixed with ir_: the shell has no local variables)
    ir_name=$1 ir_file=$2
    shift 2
    /usr/bin/time -f "%e %M" -o "$ir_name.time" "$build/isorender" "$ir_file" "$@" --force \
        --quiet -o "$ir_name.png" --stats "$ir_name.json"
}

# stat3 "MEDIAN MIN MAX" -> "median [min-max]"
stat3() { echo "$1" | awk '{ printf "%.3f [%.3f-%.3f]", $1, $2, $3 }'; }
med() { echo "$1" | cut -d' ' -f1; }
fmt_k() { awk -v v="$1" 'BEGIN { printf "%.0f", v / 1000 }'; }
verdict() { # verdict MEASURED BOUND -> "met (x% under)" / "missed by x (y times the bound)"
    awk -v m="$1" -v b="$2" 'BEGIN {
        if (m < b) printf "**met**: %.3g s under the bound (%.0f %% of it)", b - m, 100 * m / b;
        else printf "**missed** by %.3g s (%.1fx the bound)", m - b, m / b }'
}

if [ "$report_only" = 1 ]; then
    cat header.txt
else
{
echo "# bench_engine $(date -u '+%Y-%m-%d %H:%M UTC')"
echo
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')," \
    "$(awk '/MemTotal/ { printf "%.1f GiB RAM", $2 / 1048576 }' /proc/meminfo), Linux $(uname -r)"
src_dir=$(sed -n 's/^CMAKE_HOME_DIRECTORY:INTERNAL=//p' "$build/CMakeCache.txt" 2>/dev/null)
if git -C "${src_dir:-/nonexistent}" rev-parse --short HEAD >/dev/null 2>&1; then
    src_note="git $(git -C "$src_dir" rev-parse --short HEAD)$(git -C "$src_dir" diff --quiet HEAD -- src include CMakeLists.txt || echo ', engine sources modified')"
else
    src_note="not a git checkout"
fi
echo "isoprop: $build, built from $src_dir ($src_note)," \
    "$(sed -n 's/^CMAKE_BUILD_TYPE:STRING=//p' "$build/CMakeCache.txt" 2>/dev/null)," \
    "library flags: $(sed -n 's/^C_FLAGS = //p' "$build/CMakeFiles/isoprop.dir/flags.make" 2>/dev/null | sed 's/ -W[^ ]*//g')," \
    "isorender of $(date -u -r "$build/isorender" '+%Y-%m-%d %H:%M UTC')"
echo "VTK: $($py -c 'import vtk; s = vtk.vtkSMPTools; print(vtk.vtkVersion.GetVTKVersion(), "SMP backend", s.GetBackend(), "threads", s.GetEstimatedNumberOfThreads())')"
echo "repeats: $repeat runs per measurement, interleaved; tables give medians"
} >header.txt
cat header.txt
fi

head_ibv=$work/head.ibv
if [ "$report_only" != 1 ] &&
    ! { [ -f "$head_ibv" ] && [ "$head_ibv" -nt "$raw" ] && [ "$head_ibv" -nt "$build/isobrick" ]; }; then
    "$build/isobrick" "$raw" -o "$head_ibv" --quiet --force
fi

# ============================== part 1: the paper's case =====================================
part1() {
wait_load "1: the paper's case (Visible Woman head, 1600x1200, cut-off 1.81)"
if measuring; then
    # every repeat runs everything once, interleaved, so that a disturbance hits all sides alike
    : >vtk-extract.jsonl
    : >vtk-render.jsonl
    i=1
    while [ $i -le "$repeat" ]; do
        for s in "skin 600.5 -y" "bone 1224.5 -x"; do
            set -- $s
            name=$1 iso=$2 view=$3
            common="--iso $iso --view $view --size 1600x1200 --cutoff 1.81"
            drop_caches
            iso_run "$name-cold-$i" "$head_ibv" $common --progress "$name-cold-$i.csv"
            iso_run "$name-warm-$i" "$head_ibv" $common --progress "$name-warm-$i.csv" --warm
            iso_run "$name-fresh-$i" "$head_ibv" $common --progress "$name-fresh-$i.csv"
            drop_caches
            iso_run "$name-full-cold-$i" "$head_ibv" $common --full
            iso_run "$name-full-warm-$i" "$head_ibv" $common --full --warm
            # the floor: only the cells that own a pixel of the final image (part 21)
            "$build/bench_floor" "$head_ibv" "$iso" "$view" 1600x1200 "$(getconf _NPROCESSORS_ONLN)" 20 \
                >"$name-floor-$i.txt"
            # the walked floor: the cells the engine extracts by the warm 99.5 % (part 27)
            rays=$(awk -F, 'NR > 1 && $6 >= 99.5 { print $2; exit }' "$name-warm-$i.csv")
            "$build/bench_floor" "$head_ibv" "$iso" "$view" 1600x1200 "$(getconf _NPROCESSORS_ONLN)" 20 \
                "$rays" >"$name-walked-$i.txt"
        done
        $py "$root/tools/bench/bench_vtk.py" extract "$raw" 600.5 1224.5 >>vtk-extract.jsonl
        for s in "600.5 -y" "1224.5 -x"; do
            xvfb-run -a -s "-screen 0 1920x1200x24" $py "$root/tools/bench/bench_vtk.py" render "$raw" $s 1600x1200 >>vtk-render.jsonl
        done
        i=$((i + 1))
    done
    # The floor of the overdraw: the triangles of the full surface that show at all, counted as
    # those owning a pixel at 4x the resolution in each direction (same camera), against those
    # owning a pixel at 1600x1200. Extracting exactly the visible triangles gives this ratio.
    for s in "skin 600.5 -y" "bone 1224.5 -x"; do
        set -- $s
        "$build/isorender" "$head_ibv" --iso $2 --view $3 --size 6400x4800 --full --software \
            --force --quiet -o "$1-full-6400.png" --stats "$1-full-6400.json"
    done
    echo "$cold_note" >cold_note.txt
fi
cold_note=$(cat cold_note.txt)
echo "cold: $cold_note. Times in seconds from ip_engine_begin (isorender's clock); a time" \
    "[in brackets] is the previous checkpoint: the threshold was crossed between the two" \
    "(checkpoints at 1, 2, 4, 8, ... rays). Every figure: the median of $repeat runs, the runs" \
    "of all rows interleaved (rays and triangles: the lower median)."
: >bars.dat
for s in "skin 600.5 -y" "bone 1224.5 -x"; do
    set -- $s
    name=$1 iso=$2 view=$3
    # the plots draw the run with the median all-rays time
    warm=$(h median-csv "$name"-warm-?.csv)
    cp "$warm" "$name-warm.csv"
    cp "$(h median-csv "$name"-cold-?.csv)" "$name-cold.csv"
    fe=$(h vtk vtk-extract.jsonl update_s filter=flying_edges call=1 iso="$iso")
    fe2=$(h vtk vtk-extract.jsonl update_s filter=flying_edges call=2 iso="$iso")
    mc=$(h vtk vtk-extract.jsonl update_s filter=marching_cubes iso="$iso")
    fe_tri=$(h vtk vtk-extract.jsonl triangles filter=flying_edges iso="$iso")
    mc_tri=$(h vtk vtk-extract.jsonl triangles filter=marching_cubes iso="$iso")
    r1=$(h vtk vtk-render.jsonl first_render_s iso="$iso")
    r2=$(h vtk vtk-render.jsonl second_render_s iso="$iso")
    echo
    echo "### $name (iso $iso, view $view), 1600x1200"
    echo
    echo "| run | 85 % final pixels (s) | rays (K) | triangles (K) | 99.5 % (s) | rays (K) | triangles (K) | all rays / complete (s) | triangles (K) |"
    echo "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
    for m in cold fresh warm; do
        echo "| isoprop progressive, $m | $(h pointm 85 "$name"-$m-?.csv) | $(h pointm 99.5 "$name"-$m-?.csv) | $(h lastm "$name"-$m-?.csv) |"
    done
    for m in cold warm; do
        printf '| isoprop --full, %s | | | | | | | %.3f | %s |\n' $m \
            "$(h jmed time.extraction_wall_s "$name"-full-$m-*.json)" "$(fmt_k "$(h jmed triangles "$name"-full-$m-*.json)")"
    done
    echo "| VTK vtkFlyingEdges3D, Update(), first call in the process | | | | | | | $(printf %.3f "$fe") | $(fmt_k "$fe_tri") |"
    echo "| VTK vtkFlyingEdges3D, Update() again (warm) | | | | | | | $(printf %.3f "$fe2") | $(fmt_k "$fe_tri") |"
    echo "| VTK vtkMarchingCubes, Update() | | | | | | | $(printf %.3f "$mc") | $(fmt_k "$mc_tri") |"
    echo "| VTK rendering of the Flying Edges mesh: first Render() | | | | | | | $(printf %.3f "$r1") | $(fmt_k "$fe_tri") |"
    echo "| VTK rendering: second Render() | | | | | | | $(printf %.3f "$r2") | |"
    echo
    echo "Ranges over the $repeat runs: 99.5 % warm $(h range 99.5 "$name"-warm-?.csv) s," \
        "cold $(h range 99.5 "$name"-cold-?.csv) s; --full warm $(h jstats time.extraction_wall_s "$name"-full-warm-*.json | awk '{printf "%.3f-%.3f", $2, $3}') s." \
        "isorender's own rendering of the final mesh (OpenGL through EGL, llvmpipe), warm:" \
        "$(h jstats time.rendering_s "$name"-warm-?.json | awk '{printf "%.3f", $1}') s. The whole" \
        "isorender process, cold (elapsed, peak RSS): $(h timemed "$name"-cold-?.time | awk '{printf "%.2f s, %.0f MiB", $1, $2 / 1024}')."
    echo
    # the targets: warm against Flying Edges called again, fresh against its first call
    echo "| target ($name) | measured: median [min-max] of $repeat runs | bound: from the medians above | result (medians) |"
    echo "| --- | ---: | ---: | --- |"
    st=$(h tstats 99.5 "$name"-warm-?.csv)
    bound=$(calc "0.15 * $fe2")
    echo "| 99.5 % final pixels, warm <= 0.15x Flying Edges' Update() (again) | $(stat3 "$st") s | $(printf %.3f "$bound") s | $(verdict "$(med "$st")" "$bound") |"
    st=$(h tstats 100 "$name"-warm-?.csv)
    bound=$(calc "1.5 * $fe2")
    echo "| all rays, warm <= 1.5x Flying Edges' Update() (again) | $(stat3 "$st") s | $(printf %.3f "$bound") s | $(verdict "$(med "$st")" "$bound") |"
    st=$(h tstats 99.5 "$name"-fresh-?.csv)
    bound=$(calc "0.4 * $fe")
    echo "| 99.5 % final pixels, fresh process (page cache warm) <= 0.4x Flying Edges' first Update() | $(stat3 "$st") s | $(printf %.3f "$bound") s | $(verdict "$(med "$st")" "$bound") |"
    st=$(h odstats 99.5 "$name"-warm-?.csv)
    echo "| overdraw at 99.5 %, warm <= 1.3 | $(echo "$st" | awk '{ printf "%.2f [%.2f-%.2f]", $1, $2, $3 }') | 1.3 | $(awk -v m="$(med "$st")" 'BEGIN { print (m <= 1.3 ? "**met**" : "**missed**") }') |"
    v1600=$(h jmed visible_triangles "$name"-full-warm-*.json)
    v6400=$(h get "$name-full-6400.json" visible_triangles)
    echo
    echo "Overdraw floor ($name): of the full surface's $(fmt_k "$(h jmed triangles "$name"-full-warm-*.json)") K triangles," \
        "$(fmt_k "$v1600") K own a pixel at 1600x1200 and $(fmt_k "$v6400") K at 6400x4800 (the same camera):" \
        "keeping exactly the triangles that show at all would give an overdraw of about" \
        "$(calc "round($v6400 / $v1600, 2)") (the floor without culling, which drops most of those holding no" \
        "pixel centre); the warm run kept $(calc "round($(med "$st") * $v1600 / $v6400, 2)")x" \
        "the triangles that show at all by 99.5 %."
    echo
    fw=$(for f in "$name"-floor-?.txt; do sed -n 's/^median \([0-9.]*\) s.*/\1/p' "$f"; done | sort -g)
    f0=$(for f in "$name"-floor-?.txt; do sed -n 's/^run 0: \([0-9.]*\) s.*/\1/p' "$f"; done | sort -g)
    fw_med=$(echo "$fw" | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }')
    f0_med=$(echo "$f0" | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }')
    echo "Marching cubes floor ($name, \`bench_floor\`): the $(sed -n 's/.* from \([0-9]*\) cells$/\1/p' "$name"-floor-1.txt)" \
        "cells whose triangles own a pixel of the final image, triangulated alone (no rays, no" \
        "propagation, no coverage), as an oracle that knew them would: warm $(printf %.4f "$fw_med") s" \
        "[$(echo "$fw" | head -1)-$(echo "$fw" | tail -1)], $(calc "round($fw_med / $fe2, 2)")x Flying Edges again" \
        "(the warm target: 0.15x); a fresh process's first run $(printf %.4f "$f0_med") s," \
        "$(calc "round($f0_med / $fe, 2)")x Flying Edges' first call (the fresh target: 0.4x). Medians of" \
        "$repeat processes, each a median of 20 warm runs."
    if [ -s "$name-walked-1.txt" ]; then
        ww=$(for f in "$name"-walked-?.txt; do sed -n 's/^median \([0-9.]*\) s.*/\1/p' "$f"; done | sort -g)
        w0=$(for f in "$name"-walked-?.txt; do sed -n 's/^run 0: \([0-9.]*\) s.*/\1/p' "$f"; done | sort -g)
        ww_med=$(echo "$ww" | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }')
        w0_med=$(echo "$w0" | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }')
        echo
        echo "Walked floor ($name, \`bench_floor ... RAYS\`, part 27): the$(sed -n 's/^engine, [0-9]* rays: \([0-9]*\) cells.*/ \1/p' "$name"-walked-1.txt)" \
            "cells the engine extracts by the warm run's 99.5 % checkpoint, triangulated alone (normals only" \
            "for those owning a pixel): warm $(printf %.4f "$ww_med") s [$(echo "$ww" | head -1)-$(echo "$ww" | tail -1)]," \
            "$(calc "round($ww_med / $fe2, 2)")x Flying Edges again; a fresh process's first run" \
            "$(printf %.4f "$w0_med") s, $(calc "round($w0_med / $fe, 2)")x Flying Edges' first call."
    fi
    echo
    # bar chart data: name, 85 %, 99.5 %, all rays (warm), --full warm, FE, MC, FE + first render
    echo "$name $(med "$(h tstats 85 "$name"-warm-?.csv)") $(med "$(h tstats 99.5 "$name"-warm-?.csv)") $(med "$(h tstats 100 "$name"-warm-?.csv)") $(h jmed time.extraction_wall_s "$name"-full-warm-*.json) $fe2 $mc $(calc "$fe2 + $r1")" >>bars.dat
done
gnuplot <<GP
set terminal pngcairo size 1000,600 font ",11"
set output "$plots/vs_vtk.png"
set title "Visible Woman head, 1600x1200, warm (medians): isoprop progressive vs full extraction vs VTK"
set style data histograms
set style histogram clustered gap 1
set style fill solid 0.85 border -1
set boxwidth 0.9
set logscale y
set ylabel "seconds (log scale)"
set yrange [0.005:*]
set key outside below horizontal maxrows 2
set grid ytics
plot "$work/bars.dat" using 2:xtic(1) title "isoprop 85 % final pixels", \
     "" using 3 title "isoprop 99.5 %", \
     "" using 4 title "isoprop all rays", \
     "" using 5 title "isoprop --full", \
     "" using 6 title "VTK Flying Edges (Update, warm)", \
     "" using 7 title "VTK Marching Cubes (Update)", \
     "" using 8 title "VTK Flying Edges (warm) + first Render()"
set output "$plots/paper_case.png"
unset logscale y
set style data linespoints
set logscale x
set xrange [0.001:*]
set yrange [0:100]
set xlabel "elapsed time (s, log scale)"
set ylabel "final pixels (%)"
set key inside bottom right
set datafile separator ","
set title "Visible Woman head, 1600x1200: final pixels over time (the median run; checkpoints at doubling ray counts)"
plot "$work/skin-warm.csv" using 1:6 skip 1 title "skin, warm", \
     "$work/skin-cold.csv" using 1:6 skip 1 title "skin, cold", \
     "$work/bone-warm.csv" using 1:6 skip 1 title "bone, warm", \
     "$work/bone-cold.csv" using 1:6 skip 1 title "bone, cold"
GP
echo
echo "plots: $plots/vs_vtk.png, $plots/paper_case.png"
}

# prepare_big: the x4 volume and its brick file (sets big_ibv, brick_note)
prepare_big() {
    if [ ! -f "$big_raw" ]; then
        mkdir -p "$big_dir"
        "$build/isogen" --upsample 4 "$raw" -o "$big_dir/" --quiet
    fi
    # a brick file older than this build's isobrick may hold an older encoding: brick it again, once,
    # into WORK_DIR (the shared one is left alone)
    if [ ! -f "$big_ibv" ] || [ "$big_ibv" -ot "$build/isobrick" ]; then
        big_ibv=$work/ct_x4.ibv
        if [ ! -f "$big_ibv" ] || [ "$big_ibv" -ot "$build/isobrick" ]; then
            /usr/bin/time -f %e -o "$work/isobrick.time" "$build/isobrick" "$big_raw" -o "$big_ibv" --quiet --force
            brick_note="bricked by this run with $build/isobrick in $(cat "$work/isobrick.time") s"
        fi
    fi
}

# ============================== part 2: out of core ==========================================
part2() {
measuring && prepare_big
wait_load "2: out of core (head x4, 2048x2048x936 uint16, 512 MiB cache)"
measuring && echo "brick file: $big_ibv ($(calc "round($(stat -c %s "$big_ibv") / 2**20)") MiB${brick_note:+; $brick_note})" >brick_note.txt
cat brick_note.txt
if measuring; then
    bigopts="--iso 600.5 --view -y --size 1600x1200 --cache-mb 512"
    i=1
    while [ $i -le "$repeat" ]; do
        drop_caches
        iso_run big-cold-$i "$big_ibv" $bigopts --progress big-cold-$i.csv
        drop_caches
        iso_run big-pe2-cold-$i "$big_ibv" $bigopts --progress big-pe2-cold-$i.csv --pixel-error 2
        i=$((i + 1))
    done
    drop_caches
    iso_run big-first "$big_ibv" $bigopts --rays 1
    iso_run big-warm "$big_ibv" $bigopts --progress big-warm.csv --warm
fi
for n in big-cold big-pe2-cold; do # the plot draws the run with the median all-rays time
    cp "$(h median-csv $n-?.csv)" "$n.csv"
done
echo "skin 600.5, view -y, 1600x1200, --cache-mb 512; $cold_note. Cold rows: medians of" \
    "$repeat runs (99.5 % over them: $(h range 99.5 big-cold-?.csv) s, with --pixel-error 2:" \
    "$(h range 99.5 big-pe2-cold-?.csv) s); warm: 1 run (its cache counters include the untimed pass). Times from" \
    "ip_engine_begin; [brackets]: the previous checkpoint. First image: the first checkpoint" \
    "(1 ray). Peak RSS: stats peak_rss_bytes (the whole process, final rendering included)."
echo
echo "| run | first image (s) | 85 % (s) | rays (K) | triangles (K) | 99.5 % (s) | rays (K) | triangles (K) | all rays (s) | triangles (K) | peak RSS (MiB) | bricks touched / total | level-0 bricks touched / total | cache hit rate | process wall (s) |"
echo "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
for r in "cold big-cold-?" "warm big-warm" "cold, --pixel-error 2 big-pe2-cold-?"; do
    label=${r% *} n=${r##* }
    printf '| %s | %.3f | %s | %s | %s | %.0f | %.0f / %s | %.0f / %s | %.2f %% | %s |\n' "$label" \
        "$(med "$(h tstats 0 $n.csv)")" "$(h pointm 85 $n.csv)" "$(h pointm 99.5 $n.csv)" "$(h lastm $n.csv)" \
        "$(calc "$(h jmed cache.peak_rss_bytes $n.json) / 1048576")" \
        "$(h jmed cache.bricks_touched $n.json)" "$(h get big-warm.json cache bricks_total)" \
        "$(h jmed cache.levels.0.bricks_touched $n.json)" "$(h get big-warm.json cache levels 0 bricks_total)" \
        "$(calc "100 * $(h jmed cache.hit_rate $n.json)")" "$(h timemed $n.time | cut -d' ' -f1)"
done
echo
echo "A fresh process after dropping the page cache, casting 1 ray and writing its PNG" \
    "(isorender --rays 1): $(cut -d' ' -f1 big-first.time) s wall, of which" \
    "$(printf %.3f "$(h get big-first.json time extraction_wall_s)") s extraction and" \
    "$(printf %.3f "$(h get big-first.json time rendering_s)") s rendering;" \
    "peak RSS $(awk '{printf "%.0f", $2/1024}' big-first.time) MiB."
echo "Cold run memory (medians): mesh $(fmt_k "$(h jmed triangles big-cold-?.json)") K triangles," \
    "cache resident peak $(calc "round($(h jmed cache.resident_peak_bytes big-cold-?.json) / 1048576)") MiB," \
    "summaries $(calc "round($(h get big-cold-1.json cache summary_bytes) / 1048576)") MiB (read once at open)."
# VTK Flying Edges' peak memory on the raw file, when it fits
bytes=$(stat -c %s "$big_raw" 2>/dev/null || echo 0)
measuring && awk '/MemAvailable/ { printf "%.0f\n", $2 * 1024 }' /proc/meminfo >avail.txt
avail=$(cat avail.txt)
head_tri=$(h vtk vtk-extract.jsonl triangles filter=flying_edges call=1 iso=600.5 2>/dev/null || echo 800000)
[ "$head_tri" = nan ] && head_tri=800000
# input + Flying Edges' one byte per x-edge (about one per sample) + 16x the head's mesh at ~64 B
estimate=$(calc "int($bytes * 1.5 + 16 * $head_tri * 64)")
echo
echo "| VTK vtkFlyingEdges3D on the raw x4 file | value |"
echo "| --- | ---: |"
echo "| estimate (input + 1 byte per sample + 16x the head's mesh) | $(calc "round($estimate / 2**30, 1)") GiB |"
echo "| memory available before the run | $(calc "round($avail / 2**30, 1)") GiB |"
if [ "$bytes" = 0 ]; then
    echo "| skipped | the raw x4 file is not there |"
elif [ "$estimate" -gt $((18 << 30)) ] || [ "$estimate" -gt $((avail - (2 << 30))) ]; then
    echo "| skipped | the estimate exceeds 18 GiB or what is available less 2 GiB |"
else
    measuring && /usr/bin/time -f "%e %M" -o vtk-big.time $py "$root/tools/bench/bench_vtk.py" memory "$big_raw" 600.5 >vtk-big.json
    echo "| read (numpy.fromfile) | $(printf %.1f "$(h get vtk-big.json read_s)") s |"
    echo "| Flying Edges Update() | $(printf %.2f "$(h get vtk-big.json update_s)") s |"
    echo "| triangles | $(fmt_k "$(h get vtk-big.json triangles)") K |"
    echo "| RSS after reading the volume | $(calc "round($(h get vtk-big.json rss_after_read_bytes) / 2**30, 2)") GiB |"
    echo "| peak RSS (getrusage) | $(calc "round($(h get vtk-big.json peak_rss_bytes) / 2**30, 2)") GiB |"
    echo "| peak RSS (/usr/bin/time) | $(awk '{printf "%.2f", $2 / 1048576}' vtk-big.time) GiB |"
fi
echo
echo "| target (out of core, cold) | measured: median [min-max] of $repeat runs | bound | result (median) |"
echo "| --- | ---: | ---: | --- |"
for n in big-cold big-pe2-cold; do
    st=$(h jstats cache.peak_rss_bytes $n-?.json | awk '{ printf "%.6f %.6f %.6f", $1 / 2^30, $2 / 2^30, $3 / 2^30 }')
    rss=$(med "$st")
    t995=$(h tstats 99.5 $n-?.csv)
    label=""; [ $n = big-pe2-cold ] && label=", --pixel-error 2"
    echo "| peak RSS < 1 GiB$label | $(stat3 "$st") GiB | 1 GiB | $(awk -v m="$rss" 'BEGIN { if (m < 1) printf "**met** (%.0f %% of it)", 100 * m; else printf "**missed** by %.2f GiB (%.1fx)", m - 1, m }') |"
    echo "| 99.5 % final pixels within 2 s$label | $(stat3 "$t995") s | 2 s | $(verdict "$(med "$t995")" 2) |"
done
gnuplot <<GP
set terminal pngcairo size 900,520 font ",11"
set output "$plots/out_of_core.png"
set title "Head x4 (7.3 GiB), 512 MiB cache, 1600x1200: final pixels over time"
set datafile separator ","
set style data linespoints
set logscale x
set xlabel "elapsed time (s, log scale)"
set ylabel "final pixels (%)"
set yrange [0:100]
set key inside bottom right
plot "$work/big-cold.csv" using 1:6 skip 1 title "cold", \
     "$work/big-warm.csv" using 1:6 skip 1 title "warm", \
     "$work/big-pe2-cold.csv" using 1:6 skip 1 title "cold, --pixel-error 2"
GP
echo
echo "plot: $plots/out_of_core.png"
}

# ============================== part 3: display scaling ======================================
part3() {
wait_load "3: display scaling (skin 600.5, -y, warm)"
if measuring; then
    i=1
    while [ $i -le "$repeat" ]; do # interleaved
        for size in 512x512 1600x1200; do
            iso_run "scale-$size-$i" "$head_ibv" --iso 600.5 --view -y --size "$size" --warm \
                --progress "scale-$size-$i.csv"
        done
        i=$((i + 1))
    done
    # the largest display once, unless its run (warm pass + timed pass) would exceed 3 minutes
    est=$(calc "round(2 * 8294400 / 1920000 * $(h t scale-1600x1200-1.csv 100), 1)")
    if [ "$(calc "int($est > 180)")" = 1 ]; then
        echo "3840x2160 skipped: estimated $est s"
    else
        iso_run scale-3840x2160-1 "$head_ibv" --iso 600.5 --view -y --size 3840x2160 --warm \
            --progress scale-3840x2160-1.csv
    fi
fi
for size in 512x512 1600x1200 3840x2160; do
    [ -f "scale-$size-1.csv" ] && cp "$(h median-csv scale-"$size"-*.csv)" "scale-$size.csv"
done
echo "skin 600.5, view -y, warm (isorender --warm), medians of $repeat runs, interleaved (1 run at 3840x2160)."
echo
echo "| display | pixels (rays) | 85 % final pixels (s) | rays (K) | triangles (K) | 99.5 % (s) | rays (K) | triangles (K) | all rays (s) | triangles (K) |"
echo "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
for size in 512x512 1600x1200 3840x2160; do
    [ -f "scale-$size.csv" ] || continue
    echo "| $size | $(calc "${size%x*} * ${size#*x}") | $(h pointm 85 scale-$size-?.csv) | $(h pointm 99.5 scale-$size-?.csv) | $(h lastm scale-$size-?.csv) |"
done
tm() { med "$(h tstats "$2" scale-"$1"-?.csv)"; } # median time of size $1 to $2 %
ratio() { calc "round($(tm "$2" "$3") / $(tm "$1" "$3"), 2)"; }
echo
echo "From 512x512 to 1600x1200 (7.3x the pixels): 85 % point x$(ratio 512x512 1600x1200 85)," \
    "99.5 % point x$(ratio 512x512 1600x1200 99.5), all rays x$(ratio 512x512 1600x1200 100)."
if [ -f scale-3840x2160.csv ]; then
    echo "From 1600x1200 to 3840x2160 (4.3x the pixels): 85 % x$(ratio 1600x1200 3840x2160 85)," \
        "99.5 % x$(ratio 1600x1200 3840x2160 99.5), all rays x$(ratio 1600x1200 3840x2160 100)."
fi
gnuplot <<GP
set terminal pngcairo size 900,520 font ",11"
set output "$plots/display_scaling.png"
set title "Skin (600.5), warm: final pixels over time for three display sizes (median runs)"
set datafile separator ","
set style data linespoints
set logscale x
set xlabel "elapsed time (s, log scale)"
set ylabel "final pixels (%)"
set yrange [0:100]
set key inside bottom right
plot "$work/scale-512x512.csv" using 1:6 skip 1 title "512x512", \
     "$work/scale-1600x1200.csv" using 1:6 skip 1 title "1600x1200", \
     "$work/scale-3840x2160.csv" using 1:6 skip 1 title "3840x2160"
GP
echo
echo "plot: $plots/display_scaling.png"
}

# ============================== part 4: threads ==============================================
part4() {
cores=$(nproc)
wait_load "4: threads (1 against $cores, warm, 1600x1200)"
if measuring; then
    i=1
    while [ $i -le "$repeat" ]; do # interleaved: 1 thread, then all, for each surface and repeat
        for s in "skin 600.5 -y" "bone 1224.5 -x"; do
            set -- $s
            name=$1 iso=$2 view=$3
            for t in 1 "$cores"; do
                iso_run "thr-$name-p$t-$i" "$head_ibv" --iso "$iso" --view "$view" --threads "$t" --warm --progress "thr-$name-p$t-$i.csv"
                iso_run "thr-$name-f$t-$i" "$head_ibv" --iso "$iso" --view "$view" --threads "$t" --warm --full
            done
        done
        i=$((i + 1))
    done
fi
echo "warm, $repeat runs each (interleaved); progressive: time to all rays (extraction wall time);" \
    "--full: extraction wall time. Speed-up = 1-thread time / $cores-thread time."
echo
echo "| surface | run | 1 thread (s): median [min-max] | $cores threads (s): median [min-max] | speed-up (medians) | 99.5 % with 1 / $cores threads (s, medians) |"
echo "| --- | --- | ---: | ---: | ---: | ---: |"
for name in skin bone; do
    for m in p f; do
        a=$(h jstats time.extraction_wall_s thr-$name-${m}1-*.json)
        b=$(h jstats time.extraction_wall_s thr-$name-$m$cores-*.json)
        extra="-"
        [ $m = p ] && extra="$(med "$(h tstats 99.5 thr-$name-p1-*.csv)" | awk '{printf "%.3f", $1}') / $(med "$(h tstats 99.5 thr-$name-p$cores-*.csv)" | awk '{printf "%.3f", $1}')"
        label="progressive, all rays"; [ $m = f ] && label="--full"
        printf '| %s | %s | %s | %s | %.2fx | %s |\n' $name "$label" "$(stat3 "$a")" "$(stat3 "$b")" "$(calc "$(med "$a") / $(med "$b")")" "$extra"
    done
done
}

# ============================== part 5: profiles =============================================
profile() { # profile NAME COMMAND...: flat profile, the 15 hottest symbols
    pr_name=$1
    shift
    measuring && perf record -F 999 -q -o "perf-$pr_name.data" -- "$@" >/dev/null 2>&1
    echo
    echo "\`perf report --no-children --sort dso,symbol\`, $pr_name:"
    echo
    echo '```'
    perf report -i "perf-$pr_name.data" --no-children --sort dso,symbol --stdio 2>/dev/null |
        grep -v '^#' | grep -v '^$' | head -15 | sed 's/[ -]*$//; s/   */  /g'
    echo '```'
}
# inclusive shares (DWARF call graphs) of the engine's phases in one progressive run
phases() {
    measuring && perf record -F 499 --call-graph dwarf,16384 -q -o perf-phases.data -- "$@" >/dev/null 2>&1
    echo
    echo "Inclusive shares of the whole process (\`perf record -F 499 --call-graph dwarf\`," \
        "\`perf report --children --sort symbol -g none\`), skin progressive, all rays:"
    echo
    echo "| function | what it is | inclusive % | self % |"
    echo "| --- | --- | ---: | ---: |"
    perf report -i perf-phases.data --children --sort symbol -g none --stdio 2>/dev/null |
        awk '
        BEGIN {
            d["work"] = "worker threads (seeding + propagation)"
            d["ip__seed_find"] = "ray seeding (octree walk, cell tests)"
            d["walk_cells"] = "seeding: the cells of active sub-blocks"
            d["ip__sampler_cell_values"] = "seeding: 8 corner samples per cell"
            d["classify_cell"] = "seeding: ray against the cell triangles"
            d["ip__propagate"] = "propagation (with extraction)"
            d["ip__extract_cell"] = "marching cubes of one cell, mesh append"
            d["ip__sampler_cell_case"] = "the 8 corners of a cell and its case"
            d["ip__coverage_add"] = "triangles into the coverage, and their cull test"
            d["ip__sampler_cell_normals"] = "24 neighbours and gradients of a kept cell, its normals"
            d["ip_now_seconds"] = "clock_gettime for the phase times"
            d["ip_cache_pin_brick"] = "brick cache (decode on a miss)"
            d["render_image"] = "isorender: final OpenGL image"
            d["final_pixels"] = "isorender: final-pixel accounting"
            d["ip_png_write"] = "isorender: PNG"
        }
        $3 == "[.]" && ($4 in d) && !seen[$4]++ {
            printf "| %s | %s | %s | %s |\n", $4, d[$4], $1, $2
        }'
}
part5() {
measuring && prepare_big
wait_load "5: profiles (perf record -F 999, whole isorender process)"
phases "$build/isorender" "$head_ibv" --iso 600.5 --view -y --force --quiet -o perf-skin.png
profile skin-progressive "$build/isorender" "$head_ibv" --iso 600.5 --view -y --force --quiet -o perf-skin.png
profile skin-full "$build/isorender" "$head_ibv" --iso 600.5 --view -y --full --force --quiet -o perf-full.png
measuring && drop_caches
profile big-cold "$build/isorender" "$big_ibv" --iso 600.5 --view -y --cache-mb 512 --force --quiet -o perf-big.png
}

# cpu_marks: sets marks="wall_s all_busy_s children_cpu_s steal_s": the machine's busy CPU seconds (/proc/stat)
# and the CPU seconds of this script's finished children (the shell's `times`)
cpu_marks() {
    busy_j=$(awk '/^cpu / { print $2 + $3 + $4 + $7 + $8 }' /proc/stat)
    steal_j=$(awk '/^cpu / { print $9 }' /proc/stat)
    times >"$work/times.txt" # not in $( ): a subshell would report its own children
    kids=$(sed -n 2p "$work/times.txt" | awk '{ s = 0; for (i = 1; i <= 2; i++) { split($i, a, "m"); s += a[1] * 60 + a[2] } print s }')
    marks="$(date +%s.%N) $(calc "$busy_j / $(getconf CLK_TCK)") $kids $(calc "$steal_j / $(getconf CLK_TCK)")"
}
measuring() { [ "$report_only" != 1 ]; }
for p in $parts; do
    part$p
    if measuring; then
        cpu_marks
        m1=$marks
        {
            echo
            echo "$part_m0 $m1" | awk '{ w = $5 - $1; o = ($6 - $2) - ($7 - $3); if (o < 0) o = 0
                printf "Part took %.0f s after the wait; other processes (and the kernel) used %.0f CPU s meanwhile, %.2f cores on average; the hypervisor stole %.1f CPU s.\n", w, o, o / w, $8 - $4 }'
            echo "uptime after the part: $(uptime | sed 's/^ *//; s/,  *[0-9]* user.*load/, load/')"
        } >"part$p.after"
    fi
    cat "part$p.after"
done

#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# Measuring and cleaning's cost (docs/meshes.md, "Measuring"): isorender --full --mesh of the
# Visible Woman head's skin (--iso 600.5) alone, and with --measure --largest (the welded
# mesh's area, volume, edges, components, then the largest kept), in fresh processes, the two
# interleaved, REPEAT times each; the table gives the medians. Where VTK is importable, its
# area, region count and largest region of the same (uncleaned) PLY follow.
# usage: tools/bench/bench_mesh.sh [BUILD [WORK]]   (RAW, REPEAT, SIZE override)
set -eu
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-build}
work=${2:-/tmp/bench_mesh}
raw=${RAW:-$root/../shared/data/ct_head_visible_woman_512x512x234_uint16.raw}
repeat=${REPEAT:-3}
size=${SIZE:-640x480}
case $build in /*) ;; *) build=$root/$build ;; esac
[ -f "$raw" ] || { echo "bench_mesh: $raw is missing" >&2; exit 1; }
for p in isobrick isorender; do
    [ -x "$build/$p" ] || { echo "bench_mesh: $build/$p is missing" >&2; exit 1; }
done
mkdir -p "$work"
cd "$work"
if ! { [ -f head.ibv ] && [ head.ibv -nt "$raw" ] && [ head.ibv -nt "$build/isobrick" ]; }; then
    "$build/isobrick" "$raw" -o head.ibv --quiet --force
fi
now() { date +%s.%N; }
# one run: its wall time in seconds on stdout
timed() {
    t0=$(now)
    "$build/isorender" head.ibv --iso 600.5 --full --size "$size" -o out.png --quiet --force "$@"
    t1=$(now)
    echo "$t1 - $t0" | bc -l
}
: >plain.txt
: >measured.txt
i=0
while [ "$i" -lt "$repeat" ]; do
    timed --mesh plain.ply >>plain.txt
    timed --mesh clean.ply --measure --largest >>measured.txt
    i=$((i + 1))
done
median() { sort -n "$1" | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
p=$(median plain.txt) m=$(median measured.txt)
echo "isorender head.ibv --iso 600.5 --full --size $size, median of $repeat interleaved runs"
printf '%-44s %10s\n' "run" "wall s"
printf '%-44s %10.3f\n' "--mesh out.ply" "$p"
printf '%-44s %10.3f\n' "--mesh out.ply --measure --largest" "$m"
printf '%-44s %9.1f%%\n' "added" "$(echo "100 * ($m - $p) / $p" | bc -l)"
# the figures (untimed: --stats also rasters the mesh for its pixel counts)
"$build/isorender" head.ibv --iso 600.5 --full --size "$size" -o out.png --quiet --force \
    --stats all.json
"$build/isorender" head.ibv --iso 600.5 --full --size "$size" -o out.png --quiet --force \
    --largest --stats clean.json
py=/usr/bin/python3
python3 - all.json clean.json <<'PY'
import json, sys
a, c = (json.load(open(p))["surface"] for p in sys.argv[1:3])
print("surface: %d triangles, %d vertices, area %.6g, volume %.6g, closed %s, %d components"
      % (a["triangles"], a["vertices"], a["area"], a["volume"], a["closed"], a["components"]))
print("largest: %d triangles, area %.6g, volume %.6g; --largest wrote %d triangles"
      % (a["largest"]["triangles"], a["largest"]["area"], a["largest"]["volume"],
         c["triangles"]))
PY
if [ -x $py ] && $py -c 'import vtk' 2>/dev/null; then
    set -- $($py "$root/tests/tools/measure_vtk.py" plain.ply)
    echo "VTK $($py -c 'import vtk; print(vtk.vtkVersion.GetVTKVersion())'): vtkMassProperties area $1," \
        "vtkPolyDataConnectivityFilter $2 regions, the largest $3 triangles"
fi

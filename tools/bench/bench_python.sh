#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# One call from an array: isoprop.marching_cubes against skimage.measure.marching_cubes and
# VTK's vtkFlyingEdges3D, each in a fresh process per run (tools/bench/bench_python.py), RUNS
# (default 3) interleaved runs, medians of the call's wall time (the array is read before the
# clock starts), face counts; then where isoprop's time goes (its steps, one run). Prints a
# Markdown table. Not a test: numbers depend on the machine.
#
#   tools/bench/bench_python.sh [RAW] [ISO] [BUILD_DIR]
#        (defaults: ../shared/data/ct_head_visible_woman_512x512x234_uint16.raw, 600.5, build)
#
# Needs /usr/bin/python3 with numpy, python3-skimage and python3-vtk9 (a column is left out,
# with a note, when its package is missing).
set -eu
raw=${1:-../shared/data/ct_head_visible_woman_512x512x234_uint16.raw}
iso=${2:-600.5}
build=${3:-build}
runs=${RUNS:-3}
py=/usr/bin/python3
here=$(dirname "$0")
[ -f "$raw" ] || { echo "bench_python: no volume $raw" >&2; exit 1; }
[ -f "$build/python/isoprop/__init__.py" ] || { echo "bench_python: $build/python/isoprop is missing: build first" >&2; exit 1; }
PYTHONPATH=$build/python
export PYTHONPATH
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

tools="isoprop"
$py -c 'import skimage' 2>/dev/null && tools="$tools skimage" || echo "note: no scikit-image (apt-get install python3-skimage)" >&2
$py -c 'import vtk' 2>/dev/null && tools="$tools vtk" || echo "note: no VTK (apt-get install python3-vtk9)" >&2
cat "$raw" >/dev/null
i=0
while [ $i -lt "$runs" ]; do
    for t in $tools; do
        $py "$here/bench_python.py" "$t" "$raw" "$iso" >>"$tmp/$t.jsonl"
    done
    i=$((i + 1))
done

field() { $py -c 'import json, sys; print(json.loads(sys.stdin.readline())[sys.argv[1]])' "$1"; }
median() { $py -c 'import json, statistics, sys; print("%.3f" % statistics.median(json.loads(l)["seconds"] for l in sys.stdin))'; }

echo "$(basename "$raw"), iso $iso: median of $runs runs, each a fresh process; $(nproc) cores"
echo
echo "| call | seconds | faces |"
echo "|---|---:|---:|"
names="isoprop:isoprop.marching_cubes skimage:skimage.measure.marching_cubes vtk:vtkFlyingEdges3D"
for t in $tools; do
    for n in $names; do
        [ "${n%%:*}" = "$t" ] && label=${n#*:}
    done
    echo "| $label | $(median <"$tmp/$t.jsonl") | $(head -1 "$tmp/$t.jsonl" | field faces) |"
done
echo
echo "isoprop.marching_cubes, step by step (seconds, one run): $($py "$here/bench_python.py" profile "$raw" "$iso" | field seconds)"

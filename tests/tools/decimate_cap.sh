# SPDX-License-Identifier: BSD-3-Clause
# isorender --decimate RATIO and --cap. A ball given as a smooth field (radius minus distance,
# float32, level 0) cut by a corner of the volume: --full --cap closes it (every edge in two
# triangles) around the part of the ball inside the box, whose volume it encloses within 1 %
# (computed here; and by VTK's vtkMassProperties where python3 imports vtk); --decimate keeps
# about RATIO of the triangles, the rim of the open surface and the closedness of the capped
# one, and reports what it did in --stats. Bad ratios, --cap without --full or with --clip,
# and --decimate without --mesh are usage errors.
. "$(dirname "$0")/lib.sh"

# ball NAME CX CY CZ R: the field's raw volume, 32^3 float32, spacing 1
ball() {
    python3 - "$@" <<'PY'
import math, struct, sys
name, cx, cy, cz, r = sys.argv[1], *map(float, sys.argv[2:])
n = 32
values = [r - math.sqrt((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2)
          for z in range(n) for y in range(n) for x in range(n)]
with open("%s_32x32x32_float32.raw" % name, "wb") as f:
    f.write(struct.pack("<%df" % len(values), *values))
PY
}
# in_box CX CY CZ R: the volume of the ball within [0, 31]^3 (exact along x, midpoints on y, z)
in_box() {
    python3 - "$@" <<'PY'
import math, sys
cx, cy, cz, r = map(float, sys.argv[1:])
n, l = 600, 31.0
h, total = l / n, 0.0
for i in range(n):
    y = (i + 0.5) * h - cy
    for j in range(n):
        z = (j + 0.5) * h - cz
        r2 = r * r - y * y - z * z
        if r2 > 0:
            total += max(0.0, min(cx + math.sqrt(r2), l) - max(cx - math.sqrt(r2), 0.0))
print("%.6f" % (total * h * h))
PY
}
topology() { "$bin/tests/ply_triangles" --topology "$1"; }
shape() { "$bin/tests/ply_triangles" --shape "$1"; }
field() { printf '%s\n' "$2" | sed -n "s/.*$1 \([-0-9.e+]*\).*/\1/p"; }
render() { run_capture "$bin/isorender" b.ibv --iso 0 --size 80x60 --software "$@"; }

ball corner -3 -4 15.5 14
"$bin/isobrick" corner_32x32x32_float32.raw -o b.ibv --brick-size 16 --quiet

# --cap: closed, the volume inside the box
render --full --mesh open.ply -o open.png
check "without --cap" test "$rc" = 0
check "the surface is open at the box" test "$(field open "$(topology open.ply)")" -gt 0
render --full --cap --mesh capped.ply -o capped.png -v
check "--full --cap succeeds" test "$rc" = 0
check "-v says how many triangles the cap has" sh -c 'printf "%s" "$0" | grep -q "cap: [0-9]* triangles"' "$err"
t=$(topology capped.ply)
check "capped: every edge in two triangles ($t)" test "$(field open "$t")" = 0 -a "$(field repeated "$t")" = 0
volume=$(field volume "$(shape capped.ply)") exact=$(in_box -3 -4 15.5 14)
check "capped volume $volume within 1 % of the ball inside the box, $exact" \
    awk -v a="$volume" -v b="$exact" 'BEGIN { d = (a - b) / b; exit !(d < 0.01 && d > -0.01) }'
check "the image shows the cap" sh -c '! cmp -s "$0" "$1"' open.png capped.png
vtk_python=
for p in python3 /usr/bin/python3; do
    if "$p" -c 'import vtk' 2>/dev/null; then vtk_python=$p; break; fi
done
if [ -n "$vtk_python" ]; then
    vtk_volume=$("$vtk_python" -c '
import sys, vtk
r = vtk.vtkPLYReader(); r.SetFileName(sys.argv[1])
m = vtk.vtkMassProperties(); m.SetInputConnection(r.GetOutputPort()); m.Update()
print("%.6f" % m.GetVolume())' capped.ply)
    check "VTK's vtkMassProperties: $vtk_volume, within 1 % of $exact" \
        awk -v a="$vtk_volume" -v b="$exact" 'BEGIN { d = (a - b) / b; exit !(d < 0.01 && d > -0.01) }'
else
    echo "skip: python3 does not import vtk (python3-vtk9)"
fi

# --decimate: the share kept, the rim kept, closed stays closed
render --full --mesh open_d.ply --decimate 0.2 --stats d.json -o d.png
check "--decimate 0.2 succeeds" test "$rc" = 0
before=$(topology open.ply) after=$(topology open_d.ply)
check "the open surface keeps its rim ($before; $after)" test "$(field open "$before")" = "$(field open "$after")"
check "fewer faces ($before; $after)" test "$(field faces "$after")" -lt "$(field faces "$before")"
check "--stats has the decimate block" python3 -c '
import json, sys
d = json.load(open(sys.argv[1]))["decimate"]
assert d["ratio"] == 0.2 and d["triangles_after"] < d["triangles_before"] and d["error"] > 0, d
assert d["error_bound"] is None, d' d.json
check "the summary says so" sh -c 'printf "%s" "$0" | grep -q "mesh  *open_d.ply: .*decimated"' "$out"
check "the image is the extracted surface's" cmp -s open.png d.png

"$bin/isogen" sphere --dims 48x48x48 --type uint8 -o "$work/" --quiet
"$bin/isobrick" sphere_48x48x48_uint8.raw -o s.ibv --brick-size 16 --quiet
run_capture "$bin/isorender" s.ibv --iso 127.5 --size 80x60 --software --full --mesh s.ply -o s.png
run_capture "$bin/isorender" s.ibv --iso 127.5 --size 80x60 --software --full --mesh s_d.ply \
    --decimate 0.1 --stats s.json -v -o s_d.png
check "--decimate 0.1 of a sphere succeeds" test "$rc" = 0
check "-v reports the error" sh -c 'printf "%s" "$0" | grep -q "decimate: s_d.ply: [0-9]* -> [0-9]* triangles, [0-9]* vertices, error [0-9.]"' "$err"
b=$(field faces "$(topology s.ply)") a=$(field faces "$(topology s_d.ply)")
check "about a tenth of the faces ($b -> $a)" awk -v b="$b" -v a="$a" 'BEGIN { exit !(a <= b / 10 && a > b / 20) }'
check "still closed" test "$(field open "$(topology s_d.ply)")" = 0
check "the volume within 3 %" awk -v a="$(field volume "$(shape s_d.ply)")" -v b="$(field volume "$(shape s.ply)")" \
    'BEGIN { d = (a - b) / b; exit !(d < 0.03 && d > -0.03) }'
run_capture "$bin/isorender" s.ibv --iso 127.5 --size 80x60 --software --full --mesh s_t.ply \
    --decimate 0.01 --decimate-error 0.001 -o s_t.png
check "a tight bound: a warning, the best result kept" sh -c 'printf "%s" "$0" | grep -q "warning: s_t.ply: --decimate 0.01 stops at"' "$err"
check "... and a file" test "$rc" = 0 -a -s s_t.ply
render --full --cap --mesh capped_d.stl --decimate 0.3 -o cd.png
check "capped and decimated STL" test "$rc" = 0 -a -s capped_d.stl

# bad input
for bad in 0 1 1.5 -0.2 nan inf x; do
    expect_error 2 "--decimate '$bad' is not a share" "$bin/isorender" b.ibv --iso 0 --full --mesh x.ply --decimate "$bad"
done
expect_error 2 "--decimate-error 'nan' is not a length" "$bin/isorender" b.ibv --iso 0 --full --mesh x.ply --decimate 0.5 --decimate-error nan
expect_error 2 "--decimate-error bounds --decimate" "$bin/isorender" b.ibv --iso 0 --full --mesh x.ply --decimate-error 1
expect_error 2 "--decimate simplifies the mesh file: it needs --mesh" "$bin/isorender" b.ibv --iso 0 --full --decimate 0.5
expect_error 2 "--decimate needs shared vertices" "$bin/isorender" b.ibv --iso 0 --full --mesh x.ply --no-weld --decimate 0.5
expect_error 2 "--cap closes the whole surface: it needs --full" "$bin/isorender" b.ibv --iso 0 --cap --mesh x.ply
expect_error 2 "--cap closes the whole surface: it needs --full" "$bin/isorender" b.ibv --iso 0 --full-lod --cap
expect_error 2 "not with --clip" "$bin/isorender" b.ibv --iso 0 --full --cap --clip x=10
check "no partial output" test ! -e x.ply -a ! -e isorender.png -a ! -e x.png
finish

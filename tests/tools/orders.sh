# SPDX-License-Identifier: BSD-3-Clause
# One physical object stored in four sample orders (tests/helpers/make_orders.c: NIfTI in RAS
# order, in LAS order, a reflection, and in LAI order, a half turn, each sform adjusted; a DICOM
# series, LPS, its slices from head to foot) looks, meshes and counts the same from each:
# isorender's images of each anatomical view (the default one too, anterior) are byte for byte
# the same, with the axis triad and turned by --azimuth too; --view +x is the file's own
# physical axis (right in RAS, left in LPS); --full meshes are the same triangles (LPS turned to
# RAS for the DICOM one) within 1e-4 mm, wound the same way; --stats counts the same cells,
# triangles and visible triangles; --clip (millimetres) and --clip-index (sample indices), and a
# --camera in millimetres, cut and frame it alike. Anatomical views are refused, in one line,
# for a file without a space. isoview's window and isowall's wall show the same picture for the
# mirrored order as isorender for the first (where xvfb-run and mpirun are found).
. "$(dirname "$0")/lib.sh"
match="python3 $(dirname "$0")/mesh_match.py"
compare=$bin/tests/png_compare

"$bin/tests/make_orders" "$work"
orders="ras las lai dicom"
for o in $orders; do
    input=$o.nii
    test "$o" = dicom && input=series
    run_capture "$bin/isobrick" "$input" -o "$o.ibv" --brick-size 8 --threads 2
    check "$input bricks ($err)" test "$rc" = 0
done
check "the DICOM series is in LPS" sh -c '"$0/isoinfo" --json dicom.ibv | grep -qF "\"space\": \"LPS\""' \
    "$bin"

# render NAME OUT ARGS...: isorender's software image of NAME.ibv at iso 0.5
render() {
    r_name=$1 r_out=$2
    shift 2
    run_capture "$bin/isorender" "$r_name.ibv" --iso 0.5 --size 160x120 --software --quiet \
        -o "$r_out" "$@"
    check "isorender $r_name $* ($err)" test "$rc" = 0
}
# same_as_ras DESCRIPTION SUFFIX: NAME-SUFFIX.png of every order is ras-SUFFIX.png, byte for byte
same_as_ras() {
    for o in las lai dicom; do
        check "$1: $o as ras" cmp -s "ras-$2.png" "$o-$2.png"
    done
}

# --- the views: anatomical, the default, turned, with the axis triad ---
for view in anterior posterior left right superior inferior; do
    for o in $orders; do render "$o" "$o-$view.png" --view "$view"; done
    same_as_ras "--view $view" "$view"
done
views=$(for v in anterior posterior left right superior inferior; do md5sum <"ras-$v.png"; done)
check "the six views are six images" test "$(printf '%s\n' "$views" | sort -u | wc -l)" = 6
for o in $orders; do render "$o" "$o-default.png"; done
same_as_ras "the default view" default
check "the default view is anterior" cmp -s ras-default.png ras-anterior.png
for o in $orders; do
    render "$o" "$o-turned.png" --view left --azimuth 30 --elevation 20 --scale-bar
    render "$o" "$o-figure.png" --view left --azimuth 30 --elevation 20 --axes -v
    echo "$err" >"$o-axes.txt"
done
same_as_ras "--azimuth, --elevation and --scale-bar" turned
for o in las lai; do
    check "--axes: $o as ras" cmp -s ras-figure.png "$o-figure.png"
done
# the triad shows the file's own axes: R, A, S in the NIfTI files, L, P, S (the opposite ways
# in the image for the first two) in the DICOM series
arm() { sed -n "s/.* $2 \([-+][0-9.]*\),\([-+][0-9.]*\),\([-+][0-9.]*\).*/\1 \2 \3/p" "$1"; }
negated() { echo "$1" | awk '{ for (i = 1; i <= 3; i++) printf "%s%+.4f", (i > 1 ? " " : ""), -$i; print "" }'; }
check "--axes: the R arm is drawn ($(arm ras-axes.txt R))" \
    test -n "$(arm ras-axes.txt R)"
check "--axes: L is -R" test "$(arm dicom-axes.txt L)" = "$(negated "$(arm ras-axes.txt R)")"
check "--axes: P is -A" test "$(arm dicom-axes.txt P)" = "$(negated "$(arm ras-axes.txt A)")"
check "--axes: S is S" test "$(arm dicom-axes.txt S)" = "$(arm ras-axes.txt S)"
# the file's own axes: +x is right in RAS, left in LPS; -y anterior in LPS
render ras ras-x.png --view +x
render dicom dicom-x.png --view +x
render dicom dicom-y.png --view -y
check "RAS: --view +x is right" cmp -s ras-x.png ras-right.png
check "LPS: --view +x is left" cmp -s dicom-x.png ras-left.png
check "LPS: --view -y is anterior" cmp -s dicom-y.png ras-anterior.png
# the progressive image (every ray cast) is the full extraction's, and both threads' counts
for o in $orders; do render "$o" "$o-full.png" --full --view anterior; done
check "progressive and full images agree" cmp -s ras-full.png ras-anterior.png
same_as_ras "--full" full

# --- the meshes: the same triangles in physical space, within 1e-4 mm, wound alike ---
for o in $orders; do
    run_capture "$bin/isorender" "$o.ibv" --iso 0.5 --full --size 160x120 --software --quiet \
        -o "$o-mesh.png" --mesh "$o.ply" --no-weld --stats "$o.json"
    check "isorender --full --mesh on $o ($err)" test "$rc" = 0
    "$bin/tests/ply_triangles" "$o.ply" >"$o.txt"
done
check "a surface was extracted ($(wc -l <ras.txt) triangles)" test "$(wc -l <ras.txt)" -gt 1000
for o in las lai; do
    check "$o: the same triangles as ras" $match ras.txt "$o.txt"
done
check "dicom: the same triangles as ras, LPS (-x, -y, z)" $match ras.txt dicom.txt "(-x, -y, z)"
for o in $orders; do
    run_capture "$bin/isorender" "$o.ibv" --iso 0.5 --full --quiet -o "$o-w.png" --mesh "$o-w.ply" \
        --size 160x120 --software
    "$bin/tests/ply_triangles" --shape "$o-w.ply" | sed 's/ normal_angle.*//' >"$o.shape"
done
for o in las lai dicom; do
    check "$o: the welded mesh encloses the same volume, outward ($(cat "$o.shape"))" \
        python3 -c 'import sys
a, b = (open(f).read().split() for f in sys.argv[1:3])
assert float(a[1]) > 0 and abs(float(a[1]) - float(b[1])) < 1e-3 * float(a[1]), (a, b)
assert abs(float(a[3]) - float(b[3])) < 1e-3 * float(a[3]), (a, b)' ras.shape "$o.shape"
done

# --- the statistics: the same surface counts ---
for key in cells triangles visible_triangles; do
    want=$(json_number "$key" ras.json)
    for o in las lai dicom; do
        check "--stats $key: $o $(json_number "$key" "$o.json"), ras $want" \
            test "$(json_number "$key" "$o.json")" = "$want"
    done
done
check "--stats reports the camera in the file's space (LPS: -y toward the eye)" \
    sh -c 'grep -q "\"eye\": \[-0.5, -" dicom.json && grep -q "\"eye\": \[0.5, [0-9]" ras.json'

# --- clipping planes in millimetres and in sample indices; a camera in millimetres ---
# anterior of A = -52 mm (LPS: P <= 52); then the upper half by index (k >= 8 of 17, z up in
# ras, las and dicom, down in lai)
render ras ras-clip.png --view left --clip y=-52 --clip-index z=8
render las las-clip.png --view left --clip y=-52 --clip-index z=8
render lai lai-clip.png --view left --clip y=-52 --clip-index -z=8
render dicom dicom-clip.png --view left --clip -y=52 --clip-index z=8
same_as_ras "--clip and --clip-index" clip
check "the planes cut" sh -c '! cmp -s ras-clip.png ras-left.png'
camera=30,-85,25,0.5,-50,0,0,0,1,40
render ras ras-camera.png --camera "$camera"
render las las-camera.png --camera "$camera"
render lai lai-camera.png --camera "$camera"
render dicom dicom-camera.png --camera -30,85,25,-0.5,50,0,0,0,1,40
same_as_ras "--camera in millimetres" camera

# --- a file without a space: the axes only ---
"$bin/isogen" sphere --dims 20x20x20 -o "$work/" --quiet
"$bin/isobrick" sphere_20x20x20_uint16.raw -o plain.ibv --quiet
expect_error 1 "plain.ibv: view 'anterior' needs a file with an anatomical space" \
    "$bin/isorender" plain.ibv --iso 30000 -o no.png --view anterior
check "no image was written" test ! -e no.png
expect_error 2 "--view 'front' is not a view" "$bin/isorender" plain.ibv --iso 30000 --view front

# --- isoview's window: the mirrored order shows what isorender draws of the first ---
if command -v xvfb-run >/dev/null 2>&1; then
    # (the script's orbit turns as a drag does: isorender's --azimuth the other way)
    render ras ras-orbit.png --view left --azimuth -30 --elevation 10
    cat >walk.txt <<EOF
wait done
overlay off
screenshot window.png
view left
wait done
screenshot window-left.png
orbit 30 10
wait done
screenshot window-orbit.png
quit
EOF
    for renderer in software opengl; do
        rm -f window*.png
        in_xvfb 140 1024x768x24 "$bin/isoview" las.ibv --iso 0.5 --size 160x120 \
            --renderer "$renderer" --script walk.txt --exit-after 60
        check "isoview --renderer $renderer on las exits 0 ($err)" test "$rc" = 0
        # the software canvas is isorender's rasterizer; OpenGL may differ on a few pixels
        exact="--max-pct 0"
        test "$renderer" = opengl && exact="--level 2 --max-pct 0.5"
        check "isoview ($renderer): the default view of las is ras's anterior" \
            "$compare" window.png ras-anterior.png $exact
        check "isoview ($renderer): view left" "$compare" window-left.png ras-left.png $exact
        check "isoview ($renderer): an orbit turns the shown image's way" \
            "$compare" window-orbit.png ras-orbit.png $exact
    done
else
    echo "orders: isoview's window not checked: xvfb-run is missing"
fi

# --- isowall's wall and tiles: the mirrored order, tiles where the physical view has them ---
if [ -x "$bin/isowall" ] && command -v mpirun >/dev/null 2>&1; then
    case "${IP_SANITIZE:-}" in *address*) export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" ;; esac
    render ras ras-wall.png --view left --size 160x120
    mkdir tiles
    run_capture timeout 300 mpirun --oversubscribe --allow-run-as-root -np 2 "$bin/isowall" \
        las.ibv --iso 0.5 --wall 2x1 --tile 80x120 --view left --quiet -o wall.png
    check "isowall on las exits 0 ($err)" test "$rc" = 0
    check "isowall: the wall is isorender's image" "$compare" wall.png ras-wall.png --max-pct 0.01
    run_capture timeout 300 mpirun --oversubscribe --allow-run-as-root -np 2 "$bin/isowall" \
        las.ibv --iso 0.5 --wall 2x1 --tile 80x120 --view left --quiet --tiles-dir tiles
    check "isowall --tiles-dir on las exits 0 ($err)" test "$rc" = 0
    check "tile 0 is the image's left half" "$compare" ras-wall.png tiles/tile_0_0.png \
        --crop 0,0,80,120 --max-pct 0.01
    check "tile 1 is the image's right half" "$compare" ras-wall.png tiles/tile_1_0.png \
        --crop 80,0,80,120 --max-pct 0.01
else
    echo "orders: isowall not checked: no isowall or no mpirun"
fi
finish

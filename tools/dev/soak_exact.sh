#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# Soaks the engine's guarantee: once every ray has been cast, the progressive image equals the
# full extraction's: --full with adaptive resolution off, --full-lod (each level's cells in its
# distance band) with it on. Runs CASES random cases over generated volumes and the sample
# volumes of ../shared/data (those present): a random volume, isovalue, side, azimuth,
# elevation, zoom, image size, thread count and cut-off, occlusion and culling on or off,
# adaptive resolution on or off (with a pixel error of 1, 2 or 4), in one case of four one or
# two clipping planes through the volume's middle (--clip), in one case of four a second
# isovalue (a second surface, each extracted by its own run; the first surface translucent in
# half of those, --opacity), and in one case of four a brick cache of 1 MiB (--cache-mb 1, far
# less than a view needs: bricks are evicted and read again while it is extracted). Each case
# renders the progressive run and the full extraction with the same options through the
# software rasterizer and compares the two PNG files byte for byte. With SOAK_WALL=on, one
# case of six with one surface also renders the view with isowall (the display wall's
# renderer: a random wall of 1 to 3 x 1 to 3 tiles on 2 or 3 MPI processes, the image cut to
# whole tiles) and compares its image with the full extraction's. Prints a line per failing
# case (the command lines that reproduce it), a total, and exits 1 on any difference. Not a
# test: the test suite checks fixed cases; this looks for the rare one, for as long as it is
# given.
#
#   [SOAK_DATA=DIR] [SOAK_LOD=mixed|on|off] [SOAK_CLIP=on|off] [SOAK_MULTI=on|off]
#       [SOAK_CACHE=on|off] [SOAK_WALL=on|off] tools/dev/soak_exact.sh [BUILD_DIR] [CASES] [SEED]
#       [WORK_DIR]
#   defaults: build 200 1 (a temporary folder, removed at the end); SOAK_DATA, the folder of
#   the sample volumes: ../shared/data (empty: the generated volumes alone); SOAK_LOD, whether
#   cases run with adaptive resolution: mixed (one in two, the default), on or off (every
#   case); SOAK_CLIP, whether one case in four has clipping planes (on, the default, or off);
#   SOAK_MULTI, whether one case in four has a second surface, and SOAK_CACHE, whether one in
#   four has a 1 MiB cache (each on, the default, or off); SOAK_WALL, whether some cases also
#   run isowall (off, the default, or on: needs mpirun and BUILD/isowall; it changes only the
#   image size of the cases it picks). Each later draw comes after the earlier ones: with
#   SOAK_LOD=off SOAK_CLIP=off SOAK_MULTI=off SOAK_CACHE=off the cases are those this tool drew
#   before it knew any of them; with SOAK_MULTI=off SOAK_CACHE=off, those it drew before the
#   second surface; with SOAK_CACHE=off, those it drew before the small cache.
set -eu
build=${1:-build}
cases=${2:-200}
seed=${3:-1}
for p in isogen isobrick isoinfo isorender; do
    [ -x "$build/$p" ] || { echo "soak_exact: $build/$p is missing: run tools/setup.sh build" >&2; exit 2; }
done
case $cases$seed in *[!0-9]*) echo "soak_exact: CASES and SEED are whole numbers" >&2; exit 2 ;; esac
lod_mode=${SOAK_LOD:-mixed}
case $lod_mode in mixed | on | off) ;; *) echo "soak_exact: SOAK_LOD is mixed, on or off" >&2; exit 2 ;; esac
clip_mode=${SOAK_CLIP:-on}
case $clip_mode in on | off) ;; *) echo "soak_exact: SOAK_CLIP is on or off" >&2; exit 2 ;; esac
multi_mode=${SOAK_MULTI:-on}
case $multi_mode in on | off) ;; *) echo "soak_exact: SOAK_MULTI is on or off" >&2; exit 2 ;; esac
cache_mode=${SOAK_CACHE:-on}
case $cache_mode in on | off) ;; *) echo "soak_exact: SOAK_CACHE is on or off" >&2; exit 2 ;; esac
wall_mode=${SOAK_WALL:-off}
case $wall_mode in on | off) ;; *) echo "soak_exact: SOAK_WALL is on or off" >&2; exit 2 ;; esac
if [ "$wall_mode" = on ]; then
    command -v mpirun >/dev/null 2>&1 || { echo "soak_exact: SOAK_WALL=on needs mpirun (OpenMPI)" >&2; exit 2; }
    [ -x "$build/isowall" ] || { echo "soak_exact: SOAK_WALL=on needs $build/isowall (a build with MPI)" >&2; exit 2; }
fi
if [ -n "${4:-}" ]; then
    work=$4
    mkdir -p "$work"
else
    work=$(mktemp -d)
    trap 'rm -rf "$work"' EXIT
fi
data=${SOAK_DATA-$(dirname "$0")/../../../shared/data}

# the volumes: NAME FILE.ibv LOW HIGH X Y Z (the value range and the world box's size, as
# isoinfo reports them: (samples - 1) x spacing along each axis)
: >"$work/volumes"
add_volume() { # add_volume NAME INPUT [isobrick options...]
    name=$1 input=$2
    shift 2
    "$build/isobrick" "$input" -o "$work/$name.ibv" --force --quiet "$@"
    "$build/isoinfo" "$work/$name.ibv" >"$work/info"
    range=$(sed -n 's/^  value range *\([-0-9.e+]*\) \.\. \([-0-9.e+]*\)$/\1 \2/p' "$work/info")
    box=$(awk '/^  dims / { x = $2; y = $4; z = $6 }
        /^  spacing / { gsub(",", ""); printf "%.9g %.9g %.9g", (x - 1) * $2, (y - 1) * $3, (z - 1) * $4 }' \
        "$work/info")
    echo "$name $work/$name.ibv $range $box" >>"$work/volumes"
}
"$build/isogen" gyroid --dims 96x80x72 --noise 0.02 -o "$work/" --force --quiet
add_volume gyroid "$work/gyroid_96x80x72_uint16.raw" --brick-size 16
"$build/isogen" marschner-lobb --dims 64x64x64 --type float32 -o "$work/" --force --quiet
add_volume lobb "$work/marschner-lobb_64x64x64_float32.raw" --brick-size 8
for f in neghip_66x66x66_uint8 tooth_103x94x161_uint8 engine_256x256x128_uint8 \
    hydrogen_density_64x64x64_float32 ct_head_visible_woman_512x512x234_uint16; do
    if [ -n "$data" ] && [ -f "$data/$f.raw" ]; then add_volume "${f%%_*}" "$data/$f.raw"; fi
done
volumes=$(grep -c . "$work/volumes")
echo "soak_exact: $cases cases, seed $seed, over $volumes volumes: $(cut -d' ' -f1 "$work/volumes" | tr '\n' ' ')"

: >"$work/cases"
failed=0
i=0
while [ "$i" -lt "$cases" ]; do
    # one case's options, drawn from (seed, i)
    set -- $(awk -v s="$seed" -v i="$i" -v n="$volumes" -v lod_mode="$lod_mode" -v clip_mode="$clip_mode" -v multi_mode="$multi_mode" -v wall_mode="$wall_mode" -v cache_mode="$cache_mode" -v box="$(cut -d' ' -f5-7 "$work/volumes" | tr '\n' ' ')" 'BEGIN {
        srand(s * 100003 + i)
        split("+x -x +y -y +z -z", side, " ")
        split("1 2 3", threads, " ")
        volume = int(rand() * n) + 1
        fraction = 0.03 + 0.6 * rand()
        view = side[int(rand() * 6) + 1]
        azimuth = rand() * 360 - 180
        elevation = rand() * 160 - 80
        zoom = rand() < 0.3 ? 1 + rand() * 3 : 1
        big = rand() < 0.1 # one case in ten at 800x600 to 1600x1200
        width = (big ? 800 : 64) + int(rand() * (big ? 800 : 500))
        height = (big ? 600 : 48) + int(rand() * (big ? 600 : 400))
        thread_count = threads[int(rand() * 3) + 1]
        cutoff = rand() < 0.2 ? 0.5 + rand() * 8 : 1.81
        occlusion = rand() < 0.8 ? "on" : "off"
        cull = rand() < 0.6 ? "on" : "off"
        # drawn last, so that the draws above stay those of every earlier version of the tool
        lod = lod_mode == "on" || (lod_mode == "mixed" && rand() < 0.5) ? "on" : "off"
        pixel_error = lod == "on" ? 2 ^ int(rand() * 3) : 1
        # clipping planes, drawn after everything else: each through a point of the middle of
        # the box of the volume (X Y Z), along an axis or in a random direction; "none" for none
        split(box, b, " ")
        planes = clip_mode == "on" && rand() < 0.25 ? 1 + int(rand() * 2) : 0
        clip = ""
        for (p = 0; p < planes; p++) {
            if (rand() < 0.5) {
                axis = int(rand() * 3)
                nx = axis == 0; ny = axis == 1; nz = axis == 2
                if (rand() < 0.5) { nx = -nx; ny = -ny; nz = -nz }
            } else {
                do { nx = 2 * rand() - 1; ny = 2 * rand() - 1; nz = 2 * rand() - 1
                     l = sqrt(nx * nx + ny * ny + nz * nz) } while (l < 0.1 || l > 1)
                nx /= l; ny /= l; nz /= l
            }
            px = b[3 * volume - 2] * (0.2 + 0.6 * rand())
            py = b[3 * volume - 1] * (0.2 + 0.6 * rand())
            pz = b[3 * volume] * (0.2 + 0.6 * rand())
            clip = clip sprintf("%s%.4f,%.4f,%.4f,%.4f", p ? ":" : "", nx, ny, nz,
                -(nx * px + ny * py + nz * pz))
        }
        # a second surface, drawn after the planes: the fraction of the range at its isovalue (-1:
        # none), and the opacity of the first surface
        second = multi_mode == "on" && rand() < 0.25 ? 0.03 + 0.6 * rand() : -1
        opacity = second >= 0 && rand() < 0.5 ? 0.3 + 0.6 * rand() : 1
        # a display wall, drawn last (one surface only): tiles across and down, processes;
        # the image is cut to whole tiles
        wall = wall_mode == "on" && second < 0 && rand() < 1 / 6
        columns = wall ? 1 + int(rand() * 3) : 1
        rows = wall ? 1 + int(rand() * 3) : 1
        processes = wall ? 2 + int(rand() * 2) : 0
        if (wall) { width -= width % columns; height -= height % rows }
        # a brick cache of 1 MiB, drawn last
        small = cache_mode == "on" && rand() < 0.25
        printf "%d %.4f %s %.1f %.1f %.2f %dx%d %s %.2f %s %s %s %d %s %.4f %.2f %d %d %d %d\n",
            volume, fraction, view, azimuth, elevation, zoom, width, height, thread_count, cutoff,
            occlusion, cull, lod, pixel_error, planes ? clip : "none", second, opacity, columns,
            rows, processes, small }')
    line=$(sed -n "${1}p" "$work/volumes" | cut -d' ' -f1-4)
    set -- $line "$@"
    name=$1 ibv=$2 low=$3 high=$4 fraction=$6 second=${19} opacity=${20}
    columns=${21} rows=${22} processes=${23} small=${24}
    iso=$(awk -v l="$low" -v h="$high" -v f="$fraction" 'BEGIN { printf "%.6g", l + f * (h - l) }')
    opts="--iso $iso --view $7 --azimuth $8 --elevation $9 --zoom ${10} --size ${11} --threads ${12} --cutoff ${13} --lod ${16} --occlusion ${14} --cull ${15} --software --force --quiet"
    # the view's options alone, for isowall
    view="--iso $iso --view $7 --azimuth $8 --elevation $9 --zoom ${10} --cutoff ${13} --lod ${16} --occlusion ${14} --cull ${15}"
    if [ "${18}" != none ]; then
        for plane in $(echo "${18}" | tr ':' ' '); do
            opts="$opts --clip $plane"
            view="$view --clip $plane"
        done
    fi
    if [ "$second" != -1.0000 ]; then
        iso2=$(awk -v l="$low" -v h="$high" -v f="$second" 'BEGIN { printf "%.6g", l + f * (h - l) }')
        opts="$opts --iso $iso2"
        [ "$opacity" = 1.00 ] || opts="$opts --opacity $opacity"
    fi
    full=--full
    if [ "${16}" = on ]; then
        opts="$opts --pixel-error ${17}"
        view="$view --pixel-error ${17}"
        full=--full-lod
    fi
    if [ "$small" = 1 ]; then
        opts="$opts --cache-mb 1"
        view="$view --cache-mb 1"
    fi
    wall=""
    if [ "$processes" != 0 ]; then
        size=${11}
        wall="--wall ${columns}x${rows} --tile $((${size%x*} / columns))x$((${size#*x} / rows))"
    fi
    # what was run, for whoever reads WORK_DIR after
    echo "$name $opts${wall:+ | isowall $wall on $processes processes}" >>"$work/cases"
    # shellcheck disable=SC2086 # opts is a list of words
    if ! "$build/isorender" "$ibv" $opts -o "$work/p.png" 2>"$work/p.err" ||
        ! "$build/isorender" "$ibv" $opts $full -o "$work/f.png" 2>"$work/f.err"; then
        failed=$((failed + 1))
        echo "case $i ($name): isorender failed: $(cat "$work/p.err" "$work/f.err" | head -1)"
        echo "  $build/isorender $ibv $opts -o p.png"
    elif ! cmp -s "$work/p.png" "$work/f.png"; then
        failed=$((failed + 1))
        echo "case $i ($name): the progressive image differs from the full extraction's"
        echo "  $build/isorender $ibv $opts -o p.png"
        echo "  $build/isorender $ibv $opts $full -o f.png"
    elif [ -n "$wall" ] && ! timeout 300 mpirun --oversubscribe --allow-run-as-root -np "$processes" \
        "$build/isowall" "$ibv" $view $wall --threads 1 --force --quiet -o "$work/w.png" \
        >"$work/w.err" 2>&1; then
        failed=$((failed + 1))
        echo "case $i ($name): isowall failed: $(grep -v '^$' "$work/w.err" | head -1)"
        echo "  mpirun -np $processes $build/isowall $ibv $view $wall --threads 1 -o w.png"
    elif [ -n "$wall" ] && ! cmp -s "$work/w.png" "$work/f.png"; then
        failed=$((failed + 1))
        echo "case $i ($name): the display wall's image differs from the full extraction's"
        echo "  mpirun -np $processes $build/isowall $ibv $view $wall --threads 1 -o w.png"
        echo "  $build/isorender $ibv $opts $full -o f.png"
    fi
    i=$((i + 1))
done
echo "soak_exact: $failed of $cases cases failed"
[ "$failed" = 0 ]

#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# Checks that two builds give byte-identical outputs: the brick files isobrick writes, and the
# PNG images and PLY meshes isorender writes, progressive (one thread: a deterministic triangle
# order) and full, with and without adaptive resolution, over several brick edges and views, on
# the sample volumes of ../shared/data (those present) and on generated ones. For refactors that
# must not change a triangle. Prints one line per case and a total; exits 1 on any difference.
#
#   tools/dev/check_identical.sh [--quick] OLD NEW [WORK_DIR]
#
# OLD and NEW are build folders (holding isogen, isobrick, isorender) or git revisions: a
# revision is checked out into WORK_DIR and built there first. NEW defaults to the current
# build folder `build`. WORK_DIR (default: a temporary folder, removed at the end) receives the
# outputs; nothing is written elsewhere. --quick: fewer cases (one view, one brick edge).
#
#   tools/dev/check_identical.sh HEAD~1 build          # this change against the commit before it
set -eu
quick=0
[ "${1:-}" = --quick ] && { quick=1; shift; }
[ $# -ge 1 ] || { echo "usage: tools/dev/check_identical.sh [--quick] OLD [NEW] [WORK_DIR]" >&2; exit 2; }
old=$1
new=${2:-build}
root=$(cd "$(dirname "$0")/../.." && pwd)
data=${IP_SHARED_DATA:-$root/../shared/data}
keep=0
if [ -n "${3:-}" ]; then
    work=$3
    keep=1
    mkdir -p "$work"
else
    work=$(mktemp -d)
fi
cleanup() {
    for s in "$work/src-old" "$work/src-new"; do
        [ -d "$s" ] && git -C "$root" worktree remove --force "$s" 2>/dev/null || true
    done
    [ "$keep" = 1 ] || rm -rf "$work"
}
trap cleanup EXIT

# build_of REF NAME: echoes a build folder for REF (a folder already, or a revision to build)
build_of() {
    if [ -x "$1/isorender" ]; then
        (cd "$1" && pwd)
        return
    fi
    src=$work/src-$2
    rm -rf "$src"
    git -C "$root" worktree add --detach -f "$src" "$1" >/dev/null 2>&1 ||
        { echo "check_identical: $1 is neither a build folder nor a revision" >&2; exit 2; }
    cmake -S "$src" -B "$src/build" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
    cmake --build "$src/build" -j "$(nproc)" --target isogen isobrick isorender >/dev/null
    echo "$src/build"
}
old_bin=$(build_of "$old" old)
new_bin=$(build_of "$new" new)

cases=0
differ=0
# same WHAT FILE: compares the two builds' copies of one output
same() {
    cases=$((cases + 1))
    if cmp -s "$work/old/$2" "$work/new/$2"; then
        echo "same      $1"
    else
        differ=$((differ + 1))
        echo "DIFFERENT $1 ($2)"
    fi
}

# run SIDE PROGRAM ARGS...: runs a program of one side's build inside that side's folder
run() {
    side=$1 prog=$2
    shift 2
    bin=$old_bin
    [ "$side" = new ] && bin=$new_bin
    (cd "$work/$side" && "$bin/$prog" "$@") >/dev/null 2>"$work/$side/.err" ||
        { echo "check_identical: $side $prog $* failed: $(cat "$work/$side/.err")" >&2; exit 1; }
}

both() {
    run old "$@"
    run new "$@"
}

mkdir -p "$work/old" "$work/new"
# volume NAME RAW: the sample volumes found, plus generated ones that need nothing outside
volumes=""
for v in neghip_66x66x66_uint8 tooth_103x94x161_uint8 hydrogen_density_64x64x64_float32 \
         ct_head_visible_woman_512x512x234_uint16; do
    [ -f "$data/$v.raw" ] && volumes="$volumes $data/$v.raw"
done
[ "$quick" = 1 ] && volumes=$(echo $volumes | cut -d' ' -f1-2)
both isogen gyroid --dims 70x61x53 --type uint16 -o gyroid_70x61x53_uint16.raw --force --quiet
both isogen shepp-logan --dims 96x96x96 --type uint8 -o shepp_96x96x96_uint8.raw --force --quiet
same "isogen gyroid" gyroid_70x61x53_uint16.raw
same "isogen shepp-logan" shepp_96x96x96_uint8.raw
volumes="$volumes $work/new/gyroid_70x61x53_uint16.raw $work/new/shepp_96x96x96_uint8.raw"

iso_of() {
    case $1 in
    neghip*) echo 40.5 ;;
    tooth*) echo 120.5 ;;
    hydrogen*) echo 0.1 ;;
    ct_head*) echo 600.5 ;;
    gyroid*) echo 32768.5 ;;
    shepp*) echo 60.5 ;;
    esac
}

edges="32 8 4"
views="-y +x -z"
if [ "$quick" = 1 ]; then
    edges=32
    views=-y
fi
for raw in $volumes; do
    name=$(basename "$raw" .raw)
    iso=$(iso_of "$name")
    size=400x300
    case $name in ct_head*) size=800x600 ;; esac
    for edge in $edges; do
        case $name in ct_head*) [ "$edge" = 32 ] || continue ;; esac
        ibv=$name.b$edge.ibv
        both isobrick "$raw" -o "$ibv" --brick-size "$edge" --subblock-size $((edge / 4 > 0 ? edge / 4 : 1)) --force --quiet
        same "isobrick $name B=$edge" "$ibv"
        for view in $views; do
            for mode in progressive full; do
                for lod in on off; do
                    [ "$mode" = full ] && [ "$lod" = off ] && continue
                    out=$name.b$edge.$view.$mode.lod$lod
                    set -- "$ibv" --iso "$iso" --view "$view" --size "$size" --lod "$lod" \
                        -o "$out.png" --mesh "$out.ply" --force --quiet
                    if [ "$mode" = full ]; then set -- "$@" --full; else set -- "$@" --threads 1; fi
                    both isorender "$@"
                    same "isorender $out png" "$out.png"
                    same "isorender $out ply" "$out.ply"
                done
            done
        done
    done
done
echo "check_identical: $cases outputs compared, $differ different"
[ "$differ" = 0 ]

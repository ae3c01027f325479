#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# isoprop set-up: installs the Debian packages the project needs (only those missing),
# configures and builds, then runs one job.
#
#   tools/setup.sh demo    build, then generate, brick, describe and render the default volume
#                          (a gyroid): its image, its progress strip and the full extraction
#   tools/setup.sh test    build, then run the whole test suite: a -Werror build, a Debug build
#                          (internal assertions on) under AddressSanitizer +
#                          UndefinedBehaviorSanitizer (with the fuzzers), and
#                          the threaded tests under ThreadSanitizer; the final summary lists,
#                          per build, the tests that were skipped (whole or in part) and why
#   tools/setup.sh build   build only (into build/)
set -eu

job=${1:-demo}
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
jobs=$(nproc 2>/dev/null || echo 2)

# Debian packages: compiler and build tools, the libraries, clang for the sanitizer and fuzzer
# builds and clang-format for tools/dev/check_format.sh, and the lz4/zstd programs the benchmark
# compares against; GLFW and stb_easy_font for the viewer, and a virtual X server (xvfb-run) for
# its test; python3 and numpy for the Python module (docs/python.md), which every build puts in
# build/python, and venv, pip, setuptools and wheel to install it with pip offline (its test
# tests/python/test_pip.py); GDCM for DICOM series input, libtiff for TIFF input and libhdf5 (serial)
# for HDF5 input; help2man for the man
# pages; OpenMPI (mpirun and its headers) for isowall, the display wall's parallel renderer
# (docs/scale-out.md); meshoptimizer for simplifying meshes (isorender --decimate).
packages="build-essential cmake pkg-config liblz4-dev libxxhash-dev zlib1g-dev clang clang-format
          lz4 zstd libegl-dev libepoxy-dev libpng-dev libblosc-dev libcjson-dev libzstd-dev libegl-mesa0 libgl1-mesa-dri
          libglfw3-dev libstb-dev xvfb xauth python3 python3-numpy python3-venv python3-pip
          python3-setuptools python3-wheel git libgdcm-dev libtiff-dev libhdf5-dev
          help2man openmpi-bin libopenmpi-dev libmeshoptimizer-dev"

install_missing() {
    missing=""
    for p in $packages; do
        if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
            missing="$missing $p"
        fi
    done
    [ -z "$missing" ] && return 0
    if [ "$(id -u)" != 0 ]; then
        echo "setup: missing Debian packages:$missing (run as root, or install them)" >&2
        exit 1
    fi
    echo "setup: installing$missing"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends $missing >/dev/null
}

# configure_and_build DIR [cmake options...]: a RelWithDebInfo build (-O3, NDEBUG) unless the
# options name another -DCMAKE_BUILD_TYPE
configure_and_build() {
    dir=$1
    shift
    case " $* " in
    *" -DCMAKE_BUILD_TYPE="*) type="" ;;
    *) type=-DCMAKE_BUILD_TYPE=RelWithDebInfo ;;
    esac
    # shellcheck disable=SC2086 # $type is one option or none
    cmake -S . -B "$dir" $type "$@" >/dev/null
    cmake --build "$dir" -j "$jobs" -- --no-print-directory >/dev/null
}

# The demo's volume: a gyroid, one connected surface with many handles (four periods across
# 128^3 samples), most of it hidden behind its front; seen from above the front right corner
# (world units are voxels, 0 .. 127).
demo_view="--iso 2047.5 --camera 283,-221,232,63.5,63.5,57,0,0,1,30"

# json_count FILE KEY: the first "KEY": N of a statistics file
json_count() {
    sed -n "s/.*\"$2\": *\([0-9]*\).*/\1/p" "$1" | head -1
}

demo() {
    configure_and_build build
    build/isogen gyroid --dims 128x128x128 --type uint16 -o bricks/ --force --quiet
    build/isobrick bricks/gyroid_128x128x128_uint16.raw -o bricks/gyroid.ibv --force
    build/isoinfo bricks/gyroid.ibv
    # shellcheck disable=SC2086 # $demo_view is a list of options
    build/isorender bricks/gyroid.ibv $demo_view --size 800x600 -o bricks/gyroid.png \
        --stats bricks/gyroid.json --force
    # the progress strip: the image as the first rays had extracted it, then with every ray
    # shellcheck disable=SC2086
    build/isorender bricks/gyroid.ibv $demo_view --size 360x270 -o bricks/gyroid-360.png \
        --strip bricks/gyroid-strip.png --progress bricks/gyroid-progress.csv --force --quiet
    # the whole isosurface, for comparison: the same picture, more triangles
    # shellcheck disable=SC2086
    build/isorender bricks/gyroid.ibv $demo_view --size 800x600 --full \
        -o bricks/gyroid-full.png --stats bricks/gyroid-full.json --force --quiet
    echo "view-dependent: $(json_count bricks/gyroid.json triangles) triangles for the view;" \
        "the whole isosurface has $(json_count bricks/gyroid-full.json triangles)" \
        "(its picture: bricks/gyroid-full.png)"
    echo "image: bricks/gyroid.png, progress strip: bricks/gyroid-strip.png," \
        "statistics: bricks/gyroid.json, progress: bricks/gyroid-progress.csv"
}

# run_ctest DIR ENV [ctest arguments...]: runs ctest in DIR with the environment assignments
# ENV (may be empty), showing its output as it comes and keeping it in DIR/ctest.log; returns
# ctest's status.
run_ctest() {
    dir=$1 envs=$2
    shift 2
    # shellcheck disable=SC2086 # ENV is a list of assignments
    { (cd "$dir" && env $envs ctest "$@"); echo $? >"$dir/ctest.status"; } 2>&1 |
        tee "$dir/ctest.log"
    return "$(cat "$dir/ctest.status")"
}

# skip_report DIR: what the last ctest run in DIR skipped, one line each: the tests that did
# not run (skipped with status 77, or not run at all) with the reason they printed, then the
# parts of passing tests that they say they skipped (e.g. the volumes of ../shared/data).
skip_report() {
    dir=$1
    log=$dir/Testing/Temporary/LastTest.log
    [ -f "$dir/ctest.log" ] && [ -f "$log" ] || { echo "    (no ctest log)"; return 0; }
    whole=$(sed -n 's/^[[:space:]]*[0-9][0-9]* - \(.*\) (\(Skipped\|Not Run\))$/\1|\2/p' \
        "$dir/ctest.log")
    awk -v whole="$whole" '
        BEGIN {
            n = split(whole, list, "\n")
            for (i = 1; i <= n; i++) if (split(list[i], f, "|") == 2) how[f[1]] = f[2]
        }
        /^[0-9]+\/[0-9]+ Test: / { name = $0; sub(/^[0-9]+\/[0-9]+ Test: /, "", name); next }
        /^Output:$/ { inside = 1; last = ""; why = ""; getline; next }
        /^<end of output>$/ {
            inside = 0
            if (name in how) {
                print "    " name ": " (how[name] == "Skipped" ? "skipped" : "not run") ": " \
                      (why != "" ? why : last != "" ? last : "(no reason printed)")
                done[name] = 1
            }
            next
        }
        inside && NF { last = $0; if (tolower($0) ~ /skip/ && why == "") why = $0 }
        # (the status lines of libFuzzer, such as "#74238 REDUCE ... byteskip", are no reasons)
        inside && tolower($0) ~ /skip/ && $0 !~ /^#[0-9]|# Uses:/ && !(name in how) {
            print "    " name " (passed), in part: " $0
        }
        END {
            for (t in how) if (!(t in done)) print "    " t ": " tolower(how[t]) " (no output)"
        }' "$log"
}

run_tests() {
    status=0
    skips=$(mktemp)
    echo "== build with -Werror (gcc) and run the suite"
    configure_and_build build -DIP_WERROR=ON
    run_ctest build "" --output-on-failure -j "$jobs" || status=1
    { echo "  build (gcc, -Werror):"; skip_report build; } >>"$skips"
    # a Debug build (-O1, no NDEBUG): the internal assertions (IP_ASSERT) are checked here
    echo "== AddressSanitizer + UndefinedBehaviorSanitizer (clang, Debug), fuzzers included"
    CC=clang CXX=clang++ configure_and_build build-asan -DCMAKE_BUILD_TYPE=Debug -DIP_WERROR=ON \
        -DIP_SANITIZE=address,undefined -DIP_FUZZ=ON
    # intercept_tls_get_addr=0: LeakSanitizer's walk of the dynamic TLS blocks it tracks met
    # a bogus one (and crashed, "Tracer caught signal 11") at the exit of isobrick after the
    # dlopen'd input component refused a tilted DICOM series (tool_dicom); leaks are still
    # found through the heap, the stacks and static TLS
    run_ctest build-asan "ASAN_OPTIONS=detect_leaks=1:intercept_tls_get_addr=0" \
        --output-on-failure -j "$jobs" || status=1
    { echo "  build-asan (clang, ASan + UBSan):"; skip_report build-asan; } >>"$skips"
    echo "== ThreadSanitizer (clang): the threaded tests"
    CC=clang CXX=clang++ configure_and_build build-tsan -DIP_WERROR=ON -DIP_SANITIZE=thread
    run_ctest build-tsan "IP_SKIP_SHARED_DATA=1" --output-on-failure -L threads -j "$jobs" ||
        status=1
    { echo "  build-tsan (clang, TSan, threaded tests only):"; skip_report build-tsan; } >>"$skips"
    echo "== skipped tests, per build (whole tests, then parts of passing ones)"
    awk '
        /^  [^ ]/ { if (header != "" && !any) print "    none"; print; header = $0; any = 0; next }
        { any = 1; print }
        END { if (header != "" && !any) print "    none" }' "$skips"
    rm -f "$skips"
    if [ "$status" = 0 ]; then echo "setup: all test runs passed"; else echo "setup: FAILED"; fi
    return "$status"
}

install_missing
case "$job" in
demo) demo ;;
test) run_tests ;;
build) configure_and_build build ;;
*) echo "usage: tools/setup.sh [demo|test|build]" >&2; exit 2 ;;
esac

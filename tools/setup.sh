#!/bin/sh
# isoprop set-up: installs the Debian packages the project needs (only those missing),
# configures and builds, then runs one job.
#
#   tools/setup.sh demo    build, then generate, brick, describe and render the default volume
#   tools/setup.sh test    build, then run the whole test suite: a -Werror build, a build under
#                          AddressSanitizer + UndefinedBehaviorSanitizer (with the fuzzers), and
#                          the threaded tests under ThreadSanitizer
#   tools/setup.sh build   build only (into build/)
set -eu

job=${1:-demo}
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
jobs=$(nproc 2>/dev/null || echo 2)

# Debian packages: compiler and build tools, the libraries, clang for the sanitizer and fuzzer
# builds, and the lz4/zstd programs the benchmark compares against; GLFW and stb_easy_font for
# the viewer, and a virtual X server (xvfb-run) for its test.
packages="build-essential cmake pkg-config liblz4-dev libxxhash-dev zlib1g-dev clang lz4 zstd
          libegl-dev libepoxy-dev libpng-dev libegl-mesa0 libgl1-mesa-dri
          libglfw3-dev libstb-dev xvfb xauth"

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

# configure_and_build DIR [cmake options...]
configure_and_build() {
    dir=$1
    shift
    cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo "$@" >/dev/null
    cmake --build "$dir" -j "$jobs" -- --no-print-directory >/dev/null
}

demo() {
    configure_and_build build
    volume=bricks/shepp-logan_128x128x128_uint16.raw
    build/isogen shepp-logan --dims 128x128x128 --type uint16 -o bricks/ --force --quiet
    build/isobrick "$volume" -o bricks/shepp-logan.ibv --force
    build/isoinfo bricks/shepp-logan.ibv
    build/isorender bricks/shepp-logan.ibv --iso 1000.5 --view -y --size 800x600 \
        -o bricks/shepp-logan.png --stats bricks/shepp-logan.json --force
    echo "image: bricks/shepp-logan.png, statistics: bricks/shepp-logan.json"
}

run_tests() {
    status=0
    echo "== build with -Werror (gcc) and run the suite"
    configure_and_build build -DIP_WERROR=ON
    (cd build && ctest --output-on-failure -j "$jobs") || status=1
    echo "== AddressSanitizer + UndefinedBehaviorSanitizer (clang), fuzzers included"
    CC=clang configure_and_build build-asan -DIP_WERROR=ON -DIP_SANITIZE=address,undefined \
        -DIP_FUZZ=ON
    (cd build-asan && ASAN_OPTIONS=detect_leaks=1 ctest --output-on-failure -j "$jobs") ||
        status=1
    echo "== ThreadSanitizer (clang): the threaded tests"
    CC=clang configure_and_build build-tsan -DIP_WERROR=ON -DIP_SANITIZE=thread
    (cd build-tsan && IP_SKIP_SHARED_DATA=1 ctest --output-on-failure -L threads -j "$jobs") ||
        status=1
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

#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# Runs one Python test: run.sh PYTHON3 TEST.py, PYTHON3 being a python3 with numpy that CMake
# found (python/CMakeLists.txt), or empty when there is none (the test is skipped).
# In the AddressSanitizer build the library needs the sanitizer's runtime loaded before it,
# and the interpreter's own memory at exit is no leak of ours.
py=$1
test=$2
if [ -z "$py" ]; then
    echo "skipped: no python3 with numpy was found (Debian: apt-get install python3 python3-numpy)"
    exit 77
fi
if [ -n "${IP_TSAN:-}" ]; then
    echo "skipped: the Python module is not tested under ThreadSanitizer (an uninstrumented interpreter)"
    exit 77
fi
if [ -n "${IP_ASAN_RUNTIME:-}" ]; then
    LD_PRELOAD=$IP_ASAN_RUNTIME
    ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0
    export LD_PRELOAD ASAN_OPTIONS
fi
exec "$py" "$test"

#!/bin/bash
# SPDX-License-Identifier: BSD-3-Clause
# The lean core: libisoprop.so links only lz4, xxhash, zlib, libm and the C library (threads
# and dlopen are in it; libdl and libpthread where an older C library keeps them apart), at most
# 12 libraries in all as ldd lists them; the image-format libraries (libtiff, GDCM, the C++
# runtime) are linked by libisoprop_input.so alone.
#   lean_core.sh libisoprop.so libisoprop_input.so
set -u
core=$1
component=$2
failed=0
allowed='^(linux-vdso|ld-linux[-a-z0-9_]*|liblz4|libxxhash|libz|libm|libc|libdl|libpthread)\.so'
listed=$(ldd "$core" | awk '{ print $1 }' | sed 's|.*/||')
count=$(printf '%s\n' "$listed" | grep -c .)
if [ "$count" -gt 12 ]; then
    echo "lean_core: $core lists $count libraries in ldd, more than 12"
    failed=1
fi
while read -r name; do
    if ! printf '%s\n' "$name" | grep -Eq "$allowed"; then
        echo "lean_core: $core links $name, which is not lz4, xxhash, zlib, libm or the C library"
        failed=1
    fi
done <<<"$listed"
for needed in libtiff libgdcmMSFF libstdc++; do
    if ! ldd "$component" | grep -q "$needed"; then
        echo "lean_core: $component does not link $needed: the readers are not where they belong"
        failed=1
    fi
done
if ldd "$component" | grep -q 'libisoprop\.so'; then
    echo "lean_core: $component links libisoprop.so; it carries its own private copy instead"
    failed=1
fi
if [ "$failed" = 0 ]; then
    echo "lean_core: libisoprop.so lists $count libraries:" $listed
fi
exit "$failed"

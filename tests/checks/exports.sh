#!/bin/bash
# SPDX-License-Identifier: BSD-3-Clause
# A shared library exports exactly its public API: every function declared with IP_API in its
# public headers, and nothing else (no internal ip__ symbol, nothing without the ip_ prefix, no
# function of another library's headers).
#   exports.sh LIBRARY.so HEADER...   (libisoprop.so: include/isoprop/*.h but render.h and
#                                      input_formats.h; libisoprop_render.so: render.h;
#                                      libisoprop_input.so: input_formats.h)
set -u
lib=$1
shift
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
# (less the __start_SECTION / __stop_SECTION bounds the linker defines for the coverage sections
# of a fuzzer build, -fsanitize=fuzzer-no-link: no code of ours)
nm -D --defined-only "$lib" | awk 'NF == 3 && $3 !~ /^__(start|stop)___sancov_/ { print $3 }' |
    sort -u >"$dir/exported"
# the name of each IP_API declaration: the identifier before the first '('
grep -h '^IP_API ' "$@" | sed 's/(.*//; s/.*[ *]//' | sort -u >"$dir/declared"
failed=0
while read -r s; do
    echo "exports: $lib exports $s, which no public header declares with IP_API"
    failed=1
done < <(comm -23 "$dir/exported" "$dir/declared")
while read -r s; do
    echo "exports: $s is declared with IP_API but $lib does not export it"
    failed=1
done < <(comm -13 "$dir/exported" "$dir/declared")
if [ "$failed" = 0 ]; then
    echo "exports: $(wc -l <"$dir/exported") public functions exported, no internal symbol"
fi
exit "$failed"

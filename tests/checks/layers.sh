#!/bin/bash
# SPDX-License-Identifier: BSD-3-Clause
# The layering of the library, checked on its object files: a stage (a folder of src/) may call
# only functions defined in itself or in the stages it uses, directly or through another
# (CMakeLists.txt, src/README.md). Arguments, one per stage, earlier stages first:
#   STAGE|USED,STAGES|OBJECT:OBJECT:...
# Exit 0 when every call goes in the allowed direction; otherwise one line per wrong call.
set -u
declare -A uses closure
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
stages=()
for arg in "$@"; do
    IFS='|' read -r stage used objects <<<"$arg"
    stages+=("$stage")
    uses[$stage]=${used//,/ }
    IFS=':' read -r -a files <<<"$objects"
    if [ "${#files[@]}" = 0 ]; then
        echo "layers: stage $stage has no object files" >&2
        exit 1
    fi
    nm --defined-only -g "${files[@]}" | awk 'NF == 3 && $3 ~ /^ip_/ { print $3 }' |
        sort -u >"$dir/$stage.defined"
    nm -u "${files[@]}" | awk '$NF ~ /^ip_/ { print $NF }' | sort -u >"$dir/$stage.called"
done
failed=0
for stage in "${stages[@]}"; do
    allowed="$stage"
    for u in ${uses[$stage]}; do
        allowed="$allowed $u ${closure[$u]:-}"
    done
    closure[$stage]="${allowed#"$stage"}"
    sort -u $(for a in $allowed; do echo "$dir/$a.defined"; done) >"$dir/allowed"
    while read -r symbol; do
        owner=$(grep -lx -- "$symbol" "$dir"/*.defined | sed 's|.*/||; s|\.defined$||' | head -1)
        echo "layers: src/$stage calls $symbol of src/${owner:-?}, which it may not use" \
             "(it uses:${closure[$stage]:- nothing})"
        failed=1
    done < <(comm -23 "$dir/$stage.called" "$dir/allowed")
done
if [ "$failed" = 0 ]; then
    echo "layers: ${#stages[@]} stages, every call in the allowed direction"
fi
exit "$failed"

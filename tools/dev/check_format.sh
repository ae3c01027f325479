#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# Checks that the C sources follow .clang-format: runs `clang-format --dry-run --Werror` over
# every *.c and *.h of src/, tools/, tests/, include/ and docs/ and the *.cpp of src/ (tracked
# or new, not ignored) and exits 1 when any would change, listing each difference as
# clang-format reports it. Changes nothing. clang-format is Debian's package clang-format
# (tools/setup.sh installs it).
#
#   tools/dev/check_format.sh            check the whole tree
#   tools/dev/check_format.sh FILE...    check these files only
#   tools/dev/check_format.sh --summary  one line per file that would change, with its line count
set -eu
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
command -v clang-format >/dev/null 2>&1 || {
    echo "check_format: clang-format is missing (apt-get install clang-format)" >&2
    exit 2
}
summary=0
[ "${1:-}" = --summary ] && { summary=1; shift; }
list=$(mktemp)
trap 'rm -f "$list"' EXIT
if [ $# -gt 0 ]; then
    printf '%s\n' "$@" >"$list"
else
    git ls-files --cached --others --exclude-standard -- 'src/*.[ch]' 'src/*.cpp' 'tools/*.[ch]' \
        'tests/*.[ch]' 'include/*.[ch]' 'docs/*.[ch]' | sort -u >"$list"
fi
failed=0 files=0 lines=0
while IFS= read -r f; do
    [ -f "$f" ] || continue
    if [ "$summary" = 1 ]; then
        n=$(clang-format --style=file "$f" | diff "$f" - | grep -c '^<' || true)
        if [ "$n" -gt 0 ]; then
            echo "$f: $n lines"
            files=$((files + 1)) lines=$((lines + n)) failed=1
        fi
    elif ! clang-format --style=file --dry-run --Werror "$f"; then
        failed=1
    fi
done <"$list"
if [ "$summary" = 1 ]; then
    echo "check_format: $files of $(wc -l <"$list") files would change, $lines lines"
elif [ "$failed" = 1 ]; then
    echo "check_format: some files differ from .clang-format (see above)" >&2
fi
exit "$failed"

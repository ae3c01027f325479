# SPDX-License-Identifier: BSD-3-Clause
# The man pages (made from each program's --help by help2man, when the build found it) and
# the bash completion script: each program completes its own options, and files.
src=$(cd "$(dirname "$0")/../.." && pwd) # before lib.sh's cd
. "$(dirname "$0")/lib.sh"

if [ -d "$bin/man" ]; then
    for program in isobrick isoinfo isogen isorender isoview; do
        check "$bin/man/$program.1 exists" test -s "$bin/man/$program.1"
        check "$program.1 mentions --version" grep -q -- 'version' "$bin/man/$program.1"
        # the NAME line says what the program does, not just its name again
        check "$program.1 has a NAME line with a description" \
            sh -c 'sed -n "/^\.SH NAME/{n;p;}" "$0" | grep -Eq "^$1 \\\\- [a-z]" && \
                   ! sed -n "/^\.SH NAME/{n;p;}" "$0" | grep -Eq "^$1 \\\\- $1\$"' \
            "$bin/man/$program.1" "$program"
    done
    if [ -x "$bin/isowall" ]; then # built where MPI was found
        check "isowall.1 exists, with --wall and --tile" \
            sh -c 'grep -q -- "-wall" "$0" && grep -q -- "-tile" "$0"' "$bin/man/isowall.1"
    fi
    check "isorender.1 mentions --iso and --stats" \
        sh -c 'grep -q -- "-iso" "$0" && grep -q -- "-stats" "$0"' "$bin/man/isorender.1"
else
    echo "SKIP: no man pages (help2man was not found when the build was configured)"
fi

complete_words() { # PROGRAM WORD: what completing WORD after PROGRAM offers
    PATH="$bin:$PATH" bash -c '. "$0"; COMP_WORDS=("$1" "$2"); COMP_CWORD=1
        _isoprop_complete "$1" "$2" "$1"; printf "%s\n" "${COMPREPLY[@]}"' \
        "$src/tools/completion/isoprop.bash" "$1" "$2"
}
registered=$(bash -c '. "$0"; complete -p isorender' "$src/tools/completion/isoprop.bash")
check "the script registers isorender ($registered)" \
    test "$registered" = "complete -F _isoprop_complete isorender"
check "isorender --mes completes to --mesh and --mesh-grid" \
    test "$(complete_words isorender --mes | tr '\n' ' ')" = "--mesh --mesh-grid "
check "isobrick --sub completes to --subblock-size" \
    test "$(complete_words isobrick --sub)" = "--subblock-size"
check "isobrick --data completes to --dataset (HDF5)" \
    test "$(complete_words isobrick --data)" = "--dataset"
if [ -x "$bin/isowall" ]; then
    check "isowall --sta completes to --static and --stats" \
        test "$(complete_words isowall --sta | tr '\n' ' ')" = "--static --stats "
fi
touch completion_probe.ibv
check "a file name completes" test "$(complete_words isorender completion_pr)" = "completion_probe.ibv"
finish

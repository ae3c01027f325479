# SPDX-License-Identifier: BSD-3-Clause
# Bash completion for the isoprop programs (isobrick, isogen, isoinfo, isorender, isoview, isowall).
# The option names come from the program's own --help, so that they follow its options;
# after an option that takes a file, and for the positional argument, files are offered.
_isoprop_complete() {
    local cur=${COMP_WORDS[COMP_CWORD]}
    if [[ $cur == -* ]]; then
        local names
        names=$("$1" --help 2>/dev/null | grep -oE -- '(^|[ ,])--?[a-zA-Z][a-zA-Z0-9-]*' |
            sed 's/^[ ,]*//' | sort -u)
        mapfile -t COMPREPLY < <(compgen -W "$names" -- "$cur")
    else
        compopt -o filenames 2>/dev/null
        mapfile -t COMPREPLY < <(compgen -f -- "$cur")
    fi
}
complete -F _isoprop_complete isobrick isogen isoinfo isorender isoview isowall

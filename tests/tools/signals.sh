# SPDX-License-Identifier: BSD-3-Clause
# Ctrl-C and SIGTERM: isorender, isobrick, isoinfo --verify (and isoview, when a virtual X
# server is at hand) stop cleanly, write no output, say so in one line and then end as
# killed by the signal: shell status 130 for SIGINT, 143 for SIGTERM. Each run is long
# enough (several seconds at least) for the signal to land in the middle of its work.
. "$(dirname "$0")/lib.sh"

none_of() { for f in "$@"; do [ ! -e "$f" ] || return 1; done; }

# interrupt SIGNAL AFTER COMMAND...: runs COMMAND, sends it SIGNAL AFTER seconds after it has
# installed its handler, and keeps its status (as the shell reports it) in $rc and its stderr
# in $err.
interrupt() {
    sig=$1 after=$2
    shift 2
    "$@" >"$work/.out" 2>"$work/.err" &
    pid=$!
    signal_when_ready "$sig" "$after" "$pid"
    wait "$pid"
    rc=$?
    err=$(cat "$work/.err")
}

# one_line TEXT: stderr is exactly one line and holds TEXT
one_line() { [ "$(printf '%s\n' "$err" | grep -c .)" = 1 ] && printf '%s' "$err" | grep -qF -- "$1"; }

"$bin/isogen" gyroid --dims 200x200x200 --type uint8 -o "$work/" --quiet
"$bin/isobrick" gyroid_200x200x200_uint8.raw -o g.ibv --quiet

# isorender: a progressive run of 12 million rays on one thread takes well over 10 s
long_render="$bin/isorender g.ibv --iso 128.5 --size 4000x3000 --lod off --threads 1 --quiet"
interrupt INT 1 $long_render -o r.png --mesh r.ply --stats r.json --progress r.csv
check "isorender ends as killed by SIGINT (status $rc, want 130)" test "$rc" = 130
check "isorender writes no output" none_of r.png r.ply r.json r.csv
check "isorender says it was cancelled in one line ($err)" one_line "cancelled; no output written"
interrupt TERM 1 $long_render -o r.png --stats r.json
check "isorender ends as killed by SIGTERM (status $rc, want 143)" test "$rc" = 143
check "isorender writes no output" none_of r.png r.json
# the same from a job in the background, signalled with kill
$long_render -o r.png --stats r.json 2>"$work/.err" &
pid=$!
signal_when_ready INT 1 "$pid"
wait "$pid"
rc=$?
check "a background isorender killed with SIGINT ends with 130 (got $rc)" test "$rc" = 130
check "and writes no output" none_of r.png r.json
# --full cannot stop inside its extraction, but writes nothing after it either
interrupt INT 1 "$bin/isorender" g.ibv --iso 128.5 --size 4000x3000 --full --threads 1 \
    --quiet -o f.png --stats f.json
check "isorender --full ends as killed by SIGINT (status $rc, want 130)" test "$rc" = 130
check "isorender --full writes no output" none_of f.png f.json

# isobrick: LZ4 high compression on one thread takes seconds for 16 MiB
"$bin/isogen" gyroid --dims 256x256x128 --type uint16 -o "$work/" --quiet
interrupt INT 0.5 "$bin/isobrick" gyroid_256x256x128_uint16.raw -o b.ibv --hc 12 --threads 1 \
    --quiet
check "isobrick ends as killed by SIGINT (status $rc, want 130)" test "$rc" = 130
check "isobrick leaves no output" none_of b.ibv
check "isobrick says it was cancelled in one line ($err)" one_line "cancelled; no output written"
interrupt TERM 0.5 "$bin/isobrick" gyroid_256x256x128_uint16.raw -o b.ibv --hc 12 --threads 1 \
    --quiet
check "isobrick ends as killed by SIGTERM (status $rc, want 143)" test "$rc" = 143
check "isobrick leaves no output" none_of b.ibv
check "no temporary files remain" sh -c '! ls -a | grep -q -e "\.tmp" -e spill'

# isoinfo --verify: 4-cell bricks make a long verification (about 600,000 bricks: 1 s on one
# core of a 2-core machine, the signal 0.1 s after the handlers are in place)
"$bin/isogen" gyroid --dims 320x320x320 --type uint8 -o "$work/" --quiet
"$bin/isobrick" gyroid_320x320x320_uint8.raw -o v.ibv --brick-size 4 --subblock-size 4 --quiet
rm -f gyroid_320x320x320_uint8.raw
interrupt INT 0.1 "$bin/isoinfo" v.ibv --verify --cache-mb 1 --stats v.json
check "isoinfo --verify ends as killed by SIGINT (status $rc, want 130)" test "$rc" = 130
check "isoinfo --verify writes no --stats" none_of v.json
check "isoinfo says the verification was cancelled in one line ($err)" \
    one_line "verification cancelled"
interrupt TERM 0.1 "$bin/isoinfo" v.ibv --verify --cache-mb 1 --stats v.json
check "isoinfo --verify ends as killed by SIGTERM (status $rc, want 143)" test "$rc" = 143
check "isoinfo --verify writes no --stats" none_of v.json

# isoview: in a virtual X server, when there is one
if command -v xvfb-run >/dev/null 2>&1; then
    # ($preload, from lib.sh, keeps Mesa's driver loaded under AddressSanitizer)
    printf 'wait 60\nscreenshot late.png\nquit\n' >late.txt
    # (display numbers from 150, away from isoview.sh's, which start at 99)
    in_xvfb 150 640x480x24 timeout --preserve-status -s INT 3 \
        "$bin/isoview" g.ibv --iso 128.5 --size 320x240 --stats view.json --script late.txt --quiet
    check "isoview ends as killed by SIGINT (status $rc, want 130: $err)" test "$rc" = 130
    check "isoview writes no --stats and no screenshot" none_of view.json late.png
else
    echo "signals: isoview part skipped: xvfb-run is missing (Debian package xvfb)"
fi
finish

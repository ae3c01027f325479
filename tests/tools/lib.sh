# SPDX-License-Identifier: BSD-3-Clause
# Helpers for the end-to-end tests of the programs. Source it; call finish at the end.
# IP_BIN: folder with the programs; IP_TEST_TMP: scratch space; IP_SHARED_DATA: real volumes.
# The scratch folder $work is removed when the test passes or skips (exit 0 or 77) and kept,
# for diagnosis, when it fails.
set -u
passed=0
failed=0
test_name=$(basename "$0" .sh)
bin=${IP_BIN:?IP_BIN must name the build folder}
work=${IP_TEST_TMP:-/tmp/isoprop-test}/tool_$test_name
rm -rf "$work"
mkdir -p "$work"
cd "$work" || exit 1

remove_work_on_success() {
    status=$?
    if [ "$status" = 0 ] || [ "$status" = 77 ]; then
        cd / && rm -rf "$work"
    else
        echo "$test_name: scratch files kept in $work" >&2
    fi
}
trap remove_work_on_success EXIT

ok() { passed=$((passed + 1)); }
bad() { failed=$((failed + 1)); echo "FAIL: $*" >&2; }

# check DESCRIPTION COMMAND...: passes when COMMAND succeeds.
check() {
    desc=$1
    shift
    if "$@"; then ok; else bad "$desc"; fi
}

# in_xvfb FIRST_DISPLAY SCREEN COMMAND...: runs COMMAND in a virtual X server (xvfb-run,
# display numbers from FIRST_DISPLAY, screen WxHxD) with $preload (Mesa's driver kept loaded
# under AddressSanitizer), under `timeout 300`; stdout in $out, stderr in $err, and in $rc the
# status of COMMAND itself, kept in a file: xvfb-run's own status also reflects its clean-up,
# which can fail when another test's server starts or stops at the same time.
# json_number KEY FILE: the number after "KEY": in a JSON file (the last such on the first line
# that holds one; the programs write their stats on one line).
json_number() { sed -n "s/.*\"$1\": *\([-0-9.e+]*\).*/\1/p" "$2" | head -1; }

in_xvfb() {
    ix_first=$1 ix_screen=$2
    shift 2
    rm -f "$work/.xvfb-status"
    timeout 300 xvfb-run -a -n "$ix_first" -s "-screen 0 $ix_screen" \
        env ${preload:+LD_PRELOAD=$preload} sh -c '"$@"; echo $? >"$0"' "$work/.xvfb-status" \
        "$@" >"$work/.out" 2>"$work/.err"
    ix_status=$?
    rc=$(cat "$work/.xvfb-status" 2>/dev/null || echo "none (xvfb-run status $ix_status)")
    out=$(cat "$work/.out")
    err=$(grep -v '^xvfb-run: error: problem while cleaning up' "$work/.err")
}

# signal_when_ready SIGNAL AFTER PID: waits (up to 60 s) until process PID has a handler for
# SIGNAL (INT or TERM: its SigCgt mask in /proc), then AFTER seconds more, and sends it the
# signal. A signal sent before the program installs its handlers (a slow start under the
# sanitizers, on a loaded machine) would end it by the default action, without its message.
signal_when_ready() {
    case $1 in INT) swr_bit=2 ;; TERM) swr_bit=16384 ;; *) swr_bit=0 ;; esac
    swr_i=0
    while [ "$swr_bit" != 0 ] && [ "$swr_i" -lt 600 ] && kill -0 "$3" 2>/dev/null; do
        swr_mask=$(sed -n 's/^SigCgt:[[:space:]]*//p' "/proc/$3/status" 2>/dev/null)
        swr_low=${swr_mask#????????} # the low 32 bits: the standard signals
        [ -n "$swr_low" ] && [ $((0x$swr_low & swr_bit)) != 0 ] && break
        sleep 0.1
        swr_i=$((swr_i + 1))
    done
    sleep "$2"
    kill -s "$1" "$3" 2>/dev/null
}

# run_capture COMMAND...: runs it, keeps stdout in $out, stderr in $err, status in $rc.
run_capture() {
    "$@" >"$work/.out" 2>"$work/.err"
    rc=$?
    out=$(cat "$work/.out")
    err=$(cat "$work/.err")
}

# expect_error CODE TEXT COMMAND...: the command exits with CODE and prints one line on stderr
# that contains TEXT.
expect_error() {
    code=$1
    text=$2
    shift 2
    run_capture "$@"
    lines=$(printf '%s\n' "$err" | grep -c .)
    if [ "$rc" = "$code" ] && [ "$lines" = 1 ] && printf '%s' "$err" | grep -qF -- "$text"; then
        ok
    else
        bad "expected exit $code and one line with '$text' from: $* (got $rc: $err)"
    fi
}

# The isoview tests' windows: under AddressSanitizer, Mesa unloads its driver when the
# window's display closes, and LeakSanitizer cannot then name the few bytes the driver still
# held (frames in an "unknown module", which no suppression matches). Preloading the driver
# keeps it loaded to the end, so they stay reachable from its globals; leaks of isoprop's own
# code are still reported. $preload: the driver to preload, or empty.
preload=""
case "${IP_SANITIZE:-}" in
*address*)
    for f in /usr/lib/*/dri/swrast_dri.so /usr/lib/dri/swrast_dri.so; do
        if [ -e "$f" ]; then preload=$f; break; fi
    done
    ;;
esac

finish() {
    echo "$test_name: $passed passed, $failed failed"
    [ "$failed" = 0 ]
    exit $?
}

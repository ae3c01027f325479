# SPDX-License-Identifier: BSD-3-Clause
# Small things every program shares: --version (the one version of include/isoprop/version.h),
# messages that say what is wrong with --size and --dims, and isorender's time line saying
# that its parts are CPU seconds summed over the threads.
header=$(cd "$(dirname "$0")/../../include/isoprop" && pwd)/version.h # before lib.sh's cd
. "$(dirname "$0")/lib.sh"

part() { sed -n "s/^#define IP_VERSION_$1 \([0-9]*\)$/\1/p" "$header"; }
version="$(part MAJOR).$(part MINOR).$(part PATCH)"
check "version.h holds a version ($version)" sh -c 'printf "%s" "$0" | grep -qE "^[0-9]+\.[0-9]+\.[0-9]+$"' "$version"
for program in isobrick isoinfo isogen isorender isoview; do
    run_capture "$bin/$program" --version
    check "$program --version exits 0 (got $rc)" test "$rc" = 0
    check "$program --version prints '$program $version' (got '$out')" test "$out" = "$program $version"
    check "$program --version prints nothing on stderr" test -z "$err"
    check "$program --help mentions --version" sh -c '"$0" --help | grep -q -- --version' "$bin/$program"
done
check "CMake took the same version" grep -q "^CMAKE_PROJECT_VERSION:STATIC=$version$" "$bin/CMakeCache.txt"

"$bin/isogen" sphere --dims 24x20x18 --type uint8 -o "$work/" --quiet
"$bin/isobrick" sphere_24x20x18_uint8.raw -o s.ibv --brick-size 8 --quiet

# --size: the limit is named, not "is not WxH"
for program in isorender isoview; do
    expect_error 2 "16384" "$bin/$program" s.ibv --iso 100.5 --size 20000x20000
    expect_error 2 "the width, 20000 pixels" "$bin/$program" s.ibv --iso 100.5 --size 20000x10
    expect_error 2 "the height, 0 pixels" "$bin/$program" s.ibv --iso 100.5 --size 10x0
    expect_error 2 "is not WxH" "$bin/$program" s.ibv --iso 100.5 --size 12
done
check "no image after --size errors" test ! -e isorender.png

# --dims: a zero (or a 1) is named, as is a dimension that is too large
expect_error 2 "the dimension along x is 0; each must be at least 2" \
    "$bin/isobrick" sphere_24x20x18_uint8.raw --dims 0x94x161 -o x.ibv
expect_error 2 "the dimension along y is 1" "$bin/isobrick" sphere_24x20x18_uint8.raw \
    --dims 24x1x18 -o x.ibv
expect_error 2 "the dimension along z is too large (at most 2147483647)" \
    "$bin/isobrick" sphere_24x20x18_uint8.raw --dims 24x20x3000000000 -o x.ibv
expect_error 2 "is not XxYxZ" "$bin/isobrick" sphere_24x20x18_uint8.raw --dims 24x20 -o x.ibv
expect_error 2 "the dimension along x is 0" "$bin/isogen" sphere --dims 0x4x4
expect_error 2 "the dimension along z is 0" "$bin/isogen" --upsample 2 \
    sphere_24x20x18_uint8.raw --dims 24x20x0
check "no output after --dims errors" sh -c '[ ! -e x.ibv ] && ! ls | grep -q _x2_'

# getopt_long forms: --name=value equals --name value, clustered letters, -oFILE, "--", and
# unambiguous prefixes of long names
run_capture "$bin/isorender" s.ibv --iso 100.5 --size 32x24 --software -q -o eq1.png
run_capture "$bin/isorender" s.ibv --iso=100.5 --size=32x24 --software -qoeq2.png
check "--iso=V and -qoFILE run (got $rc: $err)" test "$rc" = 0
check "--iso=100.5 renders what --iso 100.5 does" cmp -s eq1.png eq2.png
run_capture "$bin/isorender" s.ibv --iso 100.5 --size 32x24 --software -qf -o eq2.png
check "clustered -qf (quiet, force) replaces the image silently (got $rc: $err)" \
    sh -c '[ "$0" = 0 ] && [ -z "$1" ]' "$rc" "$out"
run_capture "$bin/isorender" --iso 100.5 --size 32x24 --softw -q -o eq3.png -- s.ibv
check "-- ends the options; --softw is --software (got $rc: $err)" cmp -s eq1.png eq3.png
cp s.ibv ./-s.ibv
run_capture "$bin/isoinfo" --json -- -s.ibv
check "after --, a file named like an option is the file (got $rc: $err)" test "$rc" = 0
expect_error 2 "ambiguous option '--s'" "$bin/isorender" s.ibv --iso 1 --s 1
expect_error 2 "unknown option '-z'" "$bin/isorender" s.ibv --iso 1 -qz
expect_error 2 "'--mesh' needs a value" "$bin/isorender" s.ibv --iso 1 --mesh
expect_error 2 "more than one file" "$bin/isorender" s.ibv s.ibv --iso 1

# every bad value is a usage error: exit 2 and one line, before any file is opened
for bad in "--view front" "--camera 0,0,0,0,0,0,0,0,1,30" "--iso x" "--size a" "--rays 0" \
    "--time -1" "--threads 0" "--lod maybe" "--occlusion 2" "--cache-mb 0" "--cutoff x" \
    "--pixel-error 0" "--azimuth x" "--zoom 0" "--bogus"; do
    for program in isorender isoview; do
        # shellcheck disable=SC2086 # the option and its value are two words
        expect_error 2 "${bad%% *}" "$bin/$program" missing.ibv --iso 1 $bad
    done
done
for bad in "--color zz" "--background q" "--strip-at 200" "--turntable 0"; do
    # shellcheck disable=SC2086
    expect_error 2 "${bad%% *}" "$bin/isorender" missing.ibv --iso 1 $bad
done
for bad in "--type foo" "--endian mid" "--brick-size 3" "--subblock-size 0" "--hc 99" \
    "--threads 0" "--mem-mb 0" "--spacing 1,2" "--dims 1x2"; do
    # shellcheck disable=SC2086
    expect_error 2 "${bad%% *}" "$bin/isobrick" missing.raw -o y.ibv $bad
done
expect_error 2 "sub-block edge 16 is larger than the brick edge 8" "$bin/isobrick" missing.raw \
    --brick-size 8 --subblock-size 16
for bad in "--bins 0" "--level x" "--cache-mb x"; do
    # shellcheck disable=SC2086
    expect_error 2 "${bad%% *}" "$bin/isoinfo" missing.ibv --histogram $bad
done
for bad in "--type x" "--noise -1" "--seed x" "--upsample 0" "--dims 3"; do
    # shellcheck disable=SC2086
    expect_error 2 "${bad%% *}" "$bin/isogen" sphere -o z.raw $bad
done
expect_error 2 "unknown field" "$bin/isogen" bogus

# "-" is standard output for --stats and --progress: stdout then holds that output alone
keys='import json, sys; d = json.load(sys.stdin); missing = [k for k in sys.argv[1:] if k not in d]; sys.exit(1 if missing else 0)'
"$bin/isorender" s.ibv --iso 100.5 --size 32x24 --software -f -o d.png --stats - >stats.out 2>summary.err
check "isorender --stats - writes its JSON to stdout" \
    sh -c 'python3 -c "$0" cache rays triangles time camera <stats.out' "$keys"
check "isorender's summary then goes to stderr" grep -q "^  triangles" summary.err
"$bin/isorender" s.ibv --iso 100.5 --size 32x24 --software -f -q -o d.png --progress - >progress.out
check "isorender --progress - writes the CSV to stdout" \
    sh -c 'head -1 progress.out | grep -q "^time_s,rays,seeds,cells,triangles" && [ $(wc -l <progress.out) -gt 1 ]'
"$bin/isoinfo" s.ibv --verify --stats - >info.out 2>/dev/null
check "isoinfo --verify --stats - writes only the JSON to stdout" \
    sh -c 'python3 -c "$0" cache <info.out' "$keys"
check "no file named - was written" test ! -e ./-
expect_error 1 "standard output named for 2 outputs" "$bin/isorender" s.ibv --iso 100.5 \
    --stats - --progress - -o d.png -f

# isorender's progress bar: none on a pipe, forced with ISORENDER_PROGRESS=1, none with -q;
# --verbose prints each step's counts
run_capture "$bin/isorender" s.ibv --iso 100.5 --size 32x24 --software -f -o d.png
check "no bar on a pipe" test "$(printf '%s' "$err" | grep -c 'rays.*triangles ETA')" = 0
run_capture env ISORENDER_PROGRESS=1 "$bin/isorender" s.ibv --iso 100.5 --size 32x24 --software -f -o d.png
check "ISORENDER_PROGRESS=1 draws the bar to 768/768 rays" \
    sh -c 'printf "%s" "$0" | tr "\r" "\n" | grep -qE "100.0% 768/768 rays [0-9]+ triangles ETA"' "$err"
run_capture env ISORENDER_PROGRESS=1 "$bin/isorender" s.ibv --iso 100.5 --size 32x24 --software -qf -o d.png
check "no bar with --quiet" test -z "$err"
run_capture "$bin/isorender" s.ibv --iso 100.5 --size 32x24 --software -qvf -o d.png
check "--verbose prints each step's counts" \
    sh -c 'printf "%s\n" "$0" | grep -qE "^isorender: step: 768 rays \([0-9]+ retired\), [0-9]+ seeds, [0-9]+ cells, [0-9]+ triangles"' "$err"

# the time line: parts in CPU seconds summed over the threads, numbers kept
run_capture "$bin/isorender" s.ibv --iso 100.5 --size 64x48 --software --threads 2 -o t.png
check "isorender succeeds (got $rc: $err)" test "$rc" = 0
check "the time line says CPU seconds summed over 2 threads" \
    grep -qE "^  time +[0-9.]+ s extraction \(wall\); CPU s summed over 2 threads: intersection [0-9.]+, propagation [0-9.]+, marching cubes [0-9.]+; rendering [0-9.]+ s \(software\)$" \
    "$work/.out"
check "--help explains it" sh -c '"$0" --help | grep -q "CPU seconds"' "$bin/isorender"
finish

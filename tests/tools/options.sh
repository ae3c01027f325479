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

# the time line: parts in CPU seconds summed over the threads, numbers kept
run_capture "$bin/isorender" s.ibv --iso 100.5 --size 64x48 --software --threads 2 -o t.png
check "isorender succeeds (got $rc: $err)" test "$rc" = 0
check "the time line says CPU seconds summed over 2 threads" \
    grep -qE "^  time +[0-9.]+ s extraction \(wall\); CPU s summed over 2 threads: intersection [0-9.]+, propagation [0-9.]+, marching cubes [0-9.]+; rendering [0-9.]+ s \(software\)$" \
    "$work/.out"
check "--help explains it" sh -c '"$0" --help | grep -q "CPU seconds"' "$bin/isorender"
finish

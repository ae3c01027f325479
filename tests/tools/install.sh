# SPDX-License-Identifier: BSD-3-Clause
# The installed library as an embedder meets it: `cmake --install` of this build into scratch
# prefixes; docs/examples/extract.c built with pkg-config against the core component alone
# (no render.h, no libisoprop_render) and with CMake's find_package(isoprop) (shared, static,
# and the render component); its triangles equal isorender's, byte for byte; nothing
# graphical is linked; the installed programs and .pc files work from a moved prefix; the
# core links no image-format library, and the installed programs read TIFF through the input
# component beside it, or fail naming it when it is missing.
# Under the sanitizers (IP_SANITIZE) the library's objects need the sanitizer runtime, so the
# embedder's programs are built with the same compiler (IP_CC) and -fsanitize flags.
. "$(dirname "$0")/lib.sh"

source_dir=$(cd "$(dirname "$0")/../.." && pwd)
example=$source_dir/docs/examples/extract.c
cmake=${IP_CMAKE:-cmake}
cc=${IP_CC:-cc}
if ! command -v "$cmake" >/dev/null; then
    echo "install: skipped: cmake is missing (Debian package cmake)"
    exit 77
fi
flags=(-std=c11 -Wall -Wextra -Werror)
if [ -n "${IP_SANITIZE:-}" ]; then
    flags+=("-fsanitize=$IP_SANITIZE" -fno-omit-frame-pointer)
fi
graphical='lib(EGL|GL|GLX|GLdispatch|OpenGL|png[0-9]*|epoxy|X11|glfw)\.so'

# links_nothing_graphical FILE: ldd names no graphics library
links_nothing_graphical() { ! ldd "$1" | grep -Eq "$graphical"; }

# --- the core component alone: headers but render.h, libisoprop, isoprop.pc ---
core=$work/core
run_capture "$cmake" --install "$bin" --prefix "$core" --component core
check "cmake --install --component core succeeds ($err)" test "$rc" = 0
check "core: isoprop/isoprop.h installed" test -f "$core/include/isoprop/isoprop.h"
check "core: no render.h" test ! -e "$core/include/isoprop/render.h"
check "core: no libisoprop_render" test -z "$(find "$core" -name 'libisoprop_render*')"
core_pc() { PKG_CONFIG_PATH=$core/lib/pkgconfig pkg-config "$@" isoprop; }
core_lib=$(core_pc --variable=libdir)
run_capture "$cc" "${flags[@]}" "$example" -o extract $(core_pc --cflags --libs) \
    -Wl,-rpath,"$core_lib"
check "the example builds with pkg-config against the core alone ($err)" test "$rc" = 0
check "libisoprop.so has a SONAME" sh -c "readelf -d '$core_lib/libisoprop.so' | grep -q 'SONAME.*libisoprop.so.0'"
check "libisoprop.so links nothing graphical" links_nothing_graphical "$core_lib/libisoprop.so"
check "the example links nothing graphical" links_nothing_graphical extract
check "the example uses the installed libisoprop" sh -c "ldd extract | grep -q '$core_lib/libisoprop.so'"
check "core: libisoprop.so links no image-format library" \
    sh -c "! ldd '$core_lib/libisoprop.so' | grep -Eq 'libtiff|libgdcm|libstdc\+\+'"
check "core: no libisoprop_input" test -z "$(find "$core" -name 'libisoprop_input*')"

# --- a volume, and the example against isorender ---
"$bin/isogen" sphere --dims 48x40x36 --type uint8 -o "$work/" --quiet
"$bin/isobrick" sphere_48x40x36_uint8.raw -o s.ibv --brick-size 8 --quiet
run_capture ./extract s.ibv 128.5 --full --mesh full.ply
check "the example extracts fully ($err)" test "$rc" = 0
check "it prints its triangles" grep -Eq '^[1-9][0-9]* triangles \(full\)' "$work/.out"
"$bin/isorender" s.ibv --iso 128.5 --full --no-weld --mesh full_isorender.ply -o full.png --quiet
check "full extraction: the example's mesh is isorender --full's, byte for byte" \
    cmp full.ply full_isorender.ply
# progressive: one thread casts the rays in exactly the sequential order
run_capture ./extract s.ibv 128.5 --threads 1 --size 160x120 --mesh view.ply
check "the example extracts progressively ($err)" test "$rc" = 0
"$bin/isorender" s.ibv --iso 128.5 --threads 1 --size 160x120 --no-weld --mesh view_isorender.ply \
    -o view.png --quiet
check "progressive, one thread: the example's mesh is isorender's, byte for byte" \
    cmp view.ply view_isorender.ply
expect_error 1 "nothing.ibv" ./extract nothing.ibv 1
expect_error 2 "ISO must be a number" ./extract s.ibv one

# --- everything, and a CMake project using find_package(isoprop) ---
full=$work/prefix
run_capture "$cmake" --install "$bin" --prefix "$full"
check "cmake --install succeeds ($err)" test "$rc" = 0
for f in include/isoprop/render.h lib/cmake/isoprop/isopropConfig.cmake \
         lib/cmake/isoprop/isopropConfigVersion.cmake lib/pkgconfig/isoprop.pc \
         lib/pkgconfig/isoprop-render.pc lib/libisoprop.a lib/libisoprop_render.a bin/isorender \
         lib/libisoprop_input.so.0 lib/pkgconfig/isoprop-input.pc include/isoprop/input_formats.h \
         lib/cmake/isoprop/isopropInputTargets.cmake; do
    check "installed $f" test -e "$full/$f"
done
check "libisoprop_render.so links EGL and libpng (what the check above looks for)" \
    sh -c "ldd '$full/lib/libisoprop_render.so' | grep -q libEGL && ldd '$full/lib/libisoprop_render.so' | grep -q libpng"
mkdir project
cp "$example" project/
cat >project/draw.c <<'EOF'
/* the render component: a 2x2 image from the shading's background, as PNG */
#include <stdio.h>

#include "isoprop/isoprop.h"
#include "isoprop/render.h"

int main(int argc, char **argv)
{
    ip_shading s;
    ip_shading_default(&s);
    uint8_t rgba[16];
    for (int i = 0; i < 16; i++)
        rgba[i] = i % 4 == 3 ? 255 : (uint8_t)(255 * s.background_top[i % 4]);
    ip_error err;
    if (argc != 2 || ip_png_write(argv[1], rgba, 2, 2, 0, &err) != IP_OK) {
        fprintf(stderr, "draw: %s\n", argc == 2 ? err.message : "usage: draw OUT.png");
        return 1;
    }
    printf("isoprop %s\n", ip_version());
    return 0;
}
EOF
cat >project/CMakeLists.txt <<EOF
cmake_minimum_required(VERSION 3.18)
project(uses_isoprop C)
set(CMAKE_C_STANDARD 11)
find_package(isoprop 0.2 REQUIRED COMPONENTS render)
add_executable(extract_shared extract.c)
target_link_libraries(extract_shared PRIVATE isoprop::isoprop)
add_executable(extract_static extract.c)
target_link_libraries(extract_static PRIVATE isoprop::isoprop_static)
add_executable(draw draw.c)
target_link_libraries(draw PRIVATE isoprop::render)
EOF
cmake_flags="${flags[*]}"
run_capture "$cmake" -S project -B project/build -DCMAKE_PREFIX_PATH="$full" \
    -DCMAKE_C_COMPILER="$cc" -DCMAKE_C_FLAGS="$cmake_flags" -DCMAKE_BUILD_TYPE=Release
check "find_package(isoprop 0.2 COMPONENTS render) configures ($err)" test "$rc" = 0
run_capture "$cmake" --build project/build
check "the CMake project builds ($out $err)" test "$rc" = 0
for program in extract_shared extract_static; do
    rm -f "$program.ply"
    project/build/$program s.ibv 128.5 --full --mesh "$program.ply" >/dev/null
    check "$program: the same triangles as isorender --full" cmp "$program.ply" full_isorender.ply
    check "$program links nothing graphical" links_nothing_graphical project/build/$program
done
check "extract_static needs no libisoprop.so" \
    sh -c "! ldd project/build/extract_static | grep -q libisoprop"
run_capture project/build/draw drawn.png
check "the render component draws ($err)" test "$rc" = 0 -a -s drawn.png
sed 's/COMPONENTS render/COMPONENTS render nosuch/' project/CMakeLists.txt >project/CMakeLists.new
mv project/CMakeLists.new project/CMakeLists.txt
run_capture "$cmake" -S project -B project/build_nosuch -DCMAKE_PREFIX_PATH="$full" \
    -DCMAKE_C_COMPILER="$cc" -DCMAKE_C_FLAGS="$cmake_flags"
check "a component that does not exist fails find_package" test "$rc" != 0

# --- a moved prefix: the programs' RUNPATH and the .pc files are relative ---
mv "$full" "$work/moved"
run_capture "$work/moved/bin/isorender" --version
check "the installed isorender runs from a moved prefix ($err)" test "$rc" = 0
check "... with the installed libraries" \
    sh -c "ldd '$work/moved/bin/isorender' | grep -q '$work/moved/bin/../lib/libisoprop_render.so'"
moved_pc() { PKG_CONFIG_PATH=$work/moved/lib/pkgconfig pkg-config "$@"; }
run_capture "$cc" "${flags[@]}" project/draw.c -o draw_pc $(moved_pc --cflags --libs isoprop-render) \
    -Wl,-rpath,"$(moved_pc --variable=libdir isoprop)"
check "draw builds with pkg-config isoprop-render from the moved prefix ($err)" test "$rc" = 0
check "... and runs" ./draw_pc drawn_pc.png

# --- the input component, loaded by libisoprop.so from its own folder ---
mkdir formats
"$bin/isogen" sphere --dims 24x20x12 --type uint8 -o "$work/" --quiet
"$bin/tests/make_formats" sphere_24x20x12_uint8.raw formats 1,1,1 >/dev/null
run_capture "$work/moved/bin/isobrick" formats/stack.tif -o tif.ibv --quiet
check "the installed isobrick reads a TIFF through libisoprop_input ($err)" test "$rc" = 0
check "... which the programs do not link" \
    sh -c "! ldd '$work/moved/bin/isobrick' | grep -q libisoprop_input"
rm "$work"/moved/lib/libisoprop_input.so*
expect_error 1 "formats/stack.tif: TIFF, DICOM, HDF5 and Zarr need the input component libisoprop_input.so.0" \
    "$work/moved/bin/isobrick" formats/stack.tif -o tif2.ibv --quiet
check "... and writes nothing" test ! -e tif2.ibv
run_capture "$work/moved/bin/isobrick" sphere_24x20x12_uint8.raw -o raw.ibv --quiet
check "without it, raw volumes still brick ($err)" test "$rc" = 0

finish

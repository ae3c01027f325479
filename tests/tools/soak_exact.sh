# SPDX-License-Identifier: BSD-3-Clause
# The exact-image guarantee over random views (tools/dev/soak_exact.sh): 24 cases on the generated
# volumes, a fixed seed, each progressive image against the full extraction's, byte for byte
# (--full's, or --full-lod's for the cases with adaptive resolution: about half), some with
# clipping planes, some with a second surface, some with a 1 MiB brick cache; a bad case count,
# SOAK_LOD, SOAK_CLIP, SOAK_MULTI or SOAK_CACHE is a usage error (exit 2).
. "$(dirname "$0")/lib.sh"

soak=$(cd "$(dirname "$0")/../../tools/dev" && pwd)/soak_exact.sh
run_capture env SOAK_DATA= sh "$soak" "$bin" 24 5 "$work/soak"
check "24 random views: every progressive image equals the full extraction's ($rc)" \
    test "$rc" = 0
check "it says so" sh -c 'printf "%s" "$0" | grep -q "0 of 24 cases failed"' "$out"
check "over the generated volumes alone" \
    sh -c 'printf "%s" "$0" | grep -q "over 2 volumes: gyroid lobb"' "$out"
lod_cases=$(grep -c -- "--lod on" "$work/soak/cases" || true)
check "with adaptive resolution in $lod_cases of them" test "$lod_cases" -ge 6
clip_cases=$(grep -c -- "--clip" "$work/soak/cases" || true)
check "with clipping planes in $clip_cases of them" test "$clip_cases" -ge 2
multi_cases=$(grep -c -- "--iso [^ ]* .*--iso " "$work/soak/cases" || true)
check "with a second surface in $multi_cases of them" test "$multi_cases" -ge 2
small_cases=$(grep -c -- "--cache-mb 1" "$work/soak/cases" || true)
check "with a 1 MiB cache in $small_cases of them" test "$small_cases" -ge 3
run_capture env SOAK_DATA= sh "$soak" "$bin" 2x 5 "$work/soak"
check "a bad case count exits 2 ($rc)" test "$rc" = 2
run_capture env SOAK_DATA= SOAK_LOD=maybe sh "$soak" "$bin" 2 5 "$work/soak"
check "a bad SOAK_LOD exits 2 ($rc)" test "$rc" = 2
run_capture env SOAK_DATA= SOAK_CLIP=maybe sh "$soak" "$bin" 2 5 "$work/soak"
check "a bad SOAK_CLIP exits 2 ($rc)" test "$rc" = 2
run_capture env SOAK_DATA= SOAK_MULTI=maybe sh "$soak" "$bin" 2 5 "$work/soak"
check "a bad SOAK_MULTI exits 2 ($rc)" test "$rc" = 2
run_capture env SOAK_DATA= SOAK_CACHE=maybe sh "$soak" "$bin" 2 5 "$work/soak"
check "a bad SOAK_CACHE exits 2 ($rc)" test "$rc" = 2

finish

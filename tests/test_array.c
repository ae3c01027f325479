/* SPDX-License-Identifier: BSD-3-Clause */
/* The growable-array helper (src/common/array.c). */
#include <stdint.h>

#include "array.h"
#include "check.h"

static void test_capacity(void)
{
    /* doubling from `first`, or from the current capacity */
    CHECK_EQ(ip__array_capacity(0, 1, 64, 8, IP_ARRAY_DOUBLE), 64);
    CHECK_EQ(ip__array_capacity(0, 65, 64, 8, IP_ARRAY_DOUBLE), 128);
    CHECK_EQ(ip__array_capacity(64, 65, 8, 8, IP_ARRAY_DOUBLE), 128);
    CHECK_EQ(ip__array_capacity(64, 1000, 8, 8, IP_ARRAY_DOUBLE), 1024);
    /* enough already: unchanged, even below `first` */
    CHECK_EQ(ip__array_capacity(64, 64, 256, 8, IP_ARRAY_DOUBLE), 64);
    CHECK_EQ(ip__array_capacity(10, 3, 256, 8, IP_ARRAY_DOUBLE), 10);
    /* growth by half: 1024, 1536, 2304, 3456 */
    CHECK_EQ(ip__array_capacity(0, 1000, 1024, 36, IP_ARRAY_HALF), 1024);
    CHECK_EQ(ip__array_capacity(1024, 1025, 1024, 36, IP_ARRAY_HALF), 1536);
    CHECK_EQ(ip__array_capacity(1024, 3000, 1024, 36, IP_ARRAY_HALF), 3456);
    /* a first capacity of 0 or 1 still grows */
    CHECK_EQ(ip__array_capacity(0, 5, 0, 1, IP_ARRAY_DOUBLE), 8);
    CHECK_EQ(ip__array_capacity(1, 2, 0, 1, IP_ARRAY_HALF), 2);
    /* overflow of the byte size: 0 */
    CHECK_EQ(ip__array_capacity(0, SIZE_MAX / 8 + 1, 64, 8, IP_ARRAY_DOUBLE), 0);
    /* the largest possible request gets the limit itself, not a wrapped doubling */
    CHECK_EQ(ip__array_capacity(0, (uint64_t)SIZE_MAX, 64, 1, IP_ARRAY_DOUBLE), (uint64_t)SIZE_MAX);
    /* near the limit the capacity stops at it rather than wrapping */
    uint64_t limit = SIZE_MAX / 16;
    uint64_t near = ip__array_capacity(limit / 2 + 1, limit - 1, 64, 16, IP_ARRAY_DOUBLE);
    CHECK_GE(near, limit - 1);
    CHECK_LE(near, limit);
}

static void test_resize_and_reserve(void)
{
    int *a = NULL;
    uint64_t cap = 0;
    CHECK_EQ(ip__array_reserve(&a, &cap, 1, sizeof *a, 4), IP_OK);
    REQUIRE(a != NULL);
    CHECK_EQ(cap, 4);
    for (int i = 0; i < 4; i++)
        a[i] = i * 7;
    int *before = a;
    CHECK_EQ(ip__array_reserve(&a, &cap, 4, sizeof *a, 4), IP_OK); /* enough: nothing moves */
    CHECK_EQ(a, before);
    CHECK_EQ(cap, 4);
    CHECK_EQ(ip__array_reserve(&a, &cap, 5, sizeof *a, 4), IP_OK);
    CHECK_EQ(cap, 8);
    int kept = 1;
    for (int i = 0; i < 4; i++)
        kept &= a[i] == i * 7;
    CHECK(kept);
    for (int i = 4; i < 8; i++)
        a[i] = -i; /* all of the new room is writable (ASan would tell) */
    CHECK_EQ(ip__array_reserve(&a, &cap, 100, sizeof *a, 4), IP_OK);
    CHECK_EQ(cap, 128);
    CHECK_EQ(a[7], -7);
    CHECK_EQ(a[0], 0);
    CHECK_EQ(a[3], 21);

    /* a request that overflows fails and leaves the array and capacity alone */
    int *same = a;
    CHECK_EQ(ip__array_reserve(&a, &cap, UINT64_MAX / 2, sizeof *a, 4), IP_ERR_NOMEM);
    CHECK_EQ(a, same);
    CHECK_EQ(cap, 128);
    CHECK_EQ(a[7], -7);
    CHECK_EQ(ip__array_resize(&a, UINT64_MAX / 2, sizeof *a), IP_ERR_NOMEM);
    CHECK_EQ(a, same);

    /* resize may shrink, keeping the front */
    CHECK_EQ(ip__array_resize(&a, 2, sizeof *a), IP_OK);
    CHECK_EQ(a[0], 0);
    CHECK_EQ(a[1], 7);
    free(a);

    /* arrays of pointers and of structs, through the same helper */
    struct pair {
        double x;
        char c;
    } *p = NULL;
    uint64_t pcap = 0;
    CHECK_EQ(ip__array_reserve(&p, &pcap, 3, sizeof *p, 2), IP_OK);
    CHECK_EQ(pcap, 4);
    p[3] = (struct pair){1.5, 'z'};
    CHECK_EQ(p[3].x, 1.5);
    CHECK_EQ(p[3].c, 'z');
    free(p);
}

static const test_case cases[] = {
    TEST_CASE(test_capacity),
    TEST_CASE(test_resize_and_reserve),
};

int main(int argc, char **argv)
{
    return RUN_CASES(argc, argv, cases, "test_array");
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* The cache's LRU heap (src/store/lru_heap.c): smallest key first, parking, room. */
#include <stdint.h>

#include "check.h"
#include "lru_heap.h"

static uint64_t next_random(uint64_t *state)
{
    *state = *state * 6364136223846793005ull + 1442695040888963407ull;
    return *state >> 33;
}

static void test_order(void)
{
    ip_lru_heap h = {0};
    int values[1000];
    uint64_t state = 42;
    CHECK_EQ(ip__lru_heap_reserve(&h, 1000), IP_OK);
    CHECK_GE(h.capacity, 1000);
    for (int i = 0; i < 1000; i++) {
        values[i] = i;
        ip__lru_heap_push(&h, next_random(&state) % 300, &values[i]); /* with repeats */
    }
    CHECK_EQ(h.count, 1000);
    uint64_t last = 0;
    int sorted = 1, seen[1000] = {0}, all_once = 1;
    for (int i = 0; i < 1000; i++) {
        ip_lru_item it = ip__lru_heap_pop(&h);
        sorted &= it.key >= last;
        last = it.key;
        seen[*(int *)it.value]++;
    }
    for (int i = 0; i < 1000; i++)
        all_once &= seen[i] == 1;
    CHECK(sorted);
    CHECK(all_once);
    CHECK_EQ(h.count, 0);
    ip__lru_heap_free(&h);
    CHECK_EQ(h.items, NULL);
    CHECK_EQ(h.parked, NULL);
    CHECK_EQ(h.capacity, 0);
}

static void test_park(void)
{
    ip_lru_heap h = {0};
    int v[5] = {0, 1, 2, 3, 4};
    CHECK_EQ(ip__lru_heap_reserve(&h, 5), IP_OK);
    for (int i = 0; i < 5; i++)
        ip__lru_heap_push(&h, (uint64_t)(10 - i), &v[i]); /* keys 10, 9, 8, 7, 6 */
    /* pop the two smallest and set them aside: the next pop is the third smallest */
    ip_lru_item a = ip__lru_heap_pop(&h), b = ip__lru_heap_pop(&h);
    CHECK_EQ(a.key, 6);
    CHECK_EQ(a.value, &v[4]);
    CHECK_EQ(b.key, 7);
    CHECK_EQ(b.value, &v[3]);
    ip__lru_heap_park(&h, a);
    ip__lru_heap_park(&h, b);
    CHECK_EQ(h.count, 3);
    CHECK_EQ(h.parked_count, 2);
    CHECK_EQ(ip__lru_heap_pop(&h).key, 8);
    ip__lru_heap_unpark(&h);
    CHECK_EQ(h.count, 4);
    CHECK_EQ(h.parked_count, 0);
    CHECK_EQ(ip__lru_heap_pop(&h).key, 6);
    CHECK_EQ(ip__lru_heap_pop(&h).key, 7);
    CHECK_EQ(ip__lru_heap_pop(&h).key, 9);
    CHECK_EQ(ip__lru_heap_pop(&h).key, 10);
    CHECK_EQ(h.count, 0);
    ip__lru_heap_free(&h);
}

static void test_reserve(void)
{
    ip_lru_heap h = {0};
    CHECK_EQ(ip__lru_heap_reserve(&h, 1), IP_OK);
    CHECK_EQ(h.capacity, 64); /* the first room */
    CHECK_EQ(ip__lru_heap_reserve(&h, 64), IP_OK);
    CHECK_EQ(h.capacity, 64);
    CHECK_EQ(ip__lru_heap_reserve(&h, 65), IP_OK);
    CHECK_EQ(h.capacity, 128);
    int x = 0;
    for (int i = 0; i < 128; i++)
        ip__lru_heap_push(&h, (uint64_t)i, &x);
    for (int i = 0; i < 128; i++)
        ip__lru_heap_park(&h, ip__lru_heap_pop(&h)); /* parking holds every item at once */
    CHECK_EQ(h.count, 0);
    CHECK_EQ(h.parked_count, 128);
    ip__lru_heap_unpark(&h);
    if (CHECK_EQ(h.count, 128))
        CHECK_EQ(ip__lru_heap_pop(&h).key, 0);
    CHECK_EQ(ip__lru_heap_reserve(&h, UINT64_MAX), IP_ERR_NOMEM);
    CHECK_EQ(h.capacity, 128);
    ip__lru_heap_free(&h);
}

static const test_case cases[] = {
    TEST_CASE(test_order),
    TEST_CASE(test_park),
    TEST_CASE(test_reserve),
};

int main(int argc, char **argv)
{
    return RUN_CASES(argc, argv, cases, "test_lru_heap");
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* The cache's LRU min-heap. */
#include <stdlib.h>

#include "array.h"
#include "internal.h"
#include "lru_heap.h"

void ip__lru_heap_free(ip_lru_heap *h)
{
    free(h->items);
    free(h->parked);
    *h = (ip_lru_heap){0};
}

ip_status ip__lru_heap_reserve(ip_lru_heap *h, uint64_t count)
{
    if (count <= h->capacity)
        return IP_OK;
    uint64_t cap = ip__array_capacity(h->capacity, count, 64, sizeof *h->items, IP_ARRAY_DOUBLE);
    ip_status st = cap ? ip__array_resize(&h->items, cap, sizeof *h->items) : IP_ERR_NOMEM;
    if (st == IP_OK)
        st = ip__array_resize(&h->parked, cap, sizeof *h->parked);
    if (st == IP_OK)
        h->capacity = cap;
    return st;
}

static void sift_up(ip_lru_item *items, uint64_t i)
{
    ip_lru_item item = items[i];
    while (i > 0 && items[(i - 1) / 2].key > item.key) {
        items[i] = items[(i - 1) / 2];
        i = (i - 1) / 2;
    }
    items[i] = item;
}

static void sift_down(ip_lru_item *items, uint64_t n, uint64_t i)
{
    ip_lru_item item = items[i];
    for (;;) {
        uint64_t child = 2 * i + 1;
        if (child >= n)
            break;
        if (child + 1 < n && items[child + 1].key < items[child].key)
            child++;
        if (items[child].key >= item.key)
            break;
        items[i] = items[child];
        i = child;
    }
    items[i] = item;
}

void ip__lru_heap_push(ip_lru_heap *h, uint64_t key, void *value)
{
    IP_ASSERT(h->count < h->capacity); /* the room ip__lru_heap_reserve() made */
    h->items[h->count] = (ip_lru_item){key, value};
    sift_up(h->items, h->count++);
}

ip_lru_item ip__lru_heap_pop(ip_lru_heap *h)
{
    IP_ASSERT(h->count > 0);
    ip_lru_item top = h->items[0];
    h->items[0] = h->items[--h->count];
    if (h->count > 0)
        sift_down(h->items, h->count, 0);
    return top;
}

void ip__lru_heap_park(ip_lru_heap *h, ip_lru_item item)
{
    IP_ASSERT(h->parked_count < h->capacity);
    h->parked[h->parked_count++] = item;
}

void ip__lru_heap_unpark(ip_lru_heap *h)
{
    for (uint64_t i = 0; i < h->parked_count; i++)
        ip__lru_heap_push(h, h->parked[i].key, h->parked[i].value);
    h->parked_count = 0;
}

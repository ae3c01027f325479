/* SPDX-License-Identifier: BSD-3-Clause */
/* The cache's LRU order: a binary min-heap of (key, value) items, with room to set items aside
 * while popping. Internal to the store stage. Not thread-safe: the cache calls it under its
 * eviction lock. */
#ifndef ISOPROP_LRU_HEAP_H
#define ISOPROP_LRU_HEAP_H

#include <stdint.h>

#include "isoprop/status.h"

typedef struct ip_lru_item {
    uint64_t key; /* smallest first: the cache's last-pin tick */
    void *value;  /* not owned */
} ip_lru_item;

typedef struct ip_lru_heap {
    ip_lru_item *items;                     /* the heap, items[0] the smallest key */
    ip_lru_item *parked;                    /* items set aside by ip__lru_heap_park() */
    uint64_t count, parked_count, capacity; /* capacity: of items and of parked alike */
} ip_lru_heap;

/* An empty heap is all zeros; this frees its arrays (not the values) and zeroes it. */
void ip__lru_heap_free(ip_lru_heap *h);

/*! ip__lru_heap_reserve() : room for `count` items in the heap and as many parked ones, so that
 *  pushing and parking up to that many cannot fail.
 *  @return : IP_OK, or IP_ERR_NOMEM with the heap unchanged (its room maybe larger). */
ip_status ip__lru_heap_reserve(ip_lru_heap *h, uint64_t count);

/* Adds an item; the room was made by ip__lru_heap_reserve(). O(log n). */
void ip__lru_heap_push(ip_lru_heap *h, uint64_t key, void *value);

/* Removes and returns the item of the smallest key; the heap must not be empty. Of equal keys
 * any one may come first. O(log n). */
ip_lru_item ip__lru_heap_pop(ip_lru_heap *h);

/* Sets a popped item aside, out of the heap, until ip__lru_heap_unpark(). */
void ip__lru_heap_park(ip_lru_heap *h, ip_lru_item item);

/* Pushes back every parked item, in the order they were parked. */
void ip__lru_heap_unpark(ip_lru_heap *h);

#endif

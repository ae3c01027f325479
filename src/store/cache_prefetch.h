/* SPDX-License-Identifier: BSD-3-Clause */
/* Loading bricks into the cache ahead of their first pin, for a background reader (the
 * engine's, src/engine/prefetch.c). Internal to the library.
 *
 * A brick loaded ahead is read, checked and decoded exactly as a miss would, then published
 * unpinned: a later ip_cache_pin_brick() finds it as a hit (counted in `prefetch_hits` at its
 * first pin), and a pin that asks for it while it is being loaded waits for that load (as for
 * another thread's miss). A load ahead never goes over the budget, never evicts a pinned brick,
 * and evicts only bricks last pinned before a tick the caller names (for the engine: before
 * the current view began), never one loaded ahead and not pinned since; when that leaves no
 * room it loads nothing and says so. A load ahead that fails (read, checksum, decode) caches
 * nothing and is not counted in `errors`: the brick's first pin reads it again and reports the
 * error itself, with the same message a run without loading ahead gives.
 *
 * Threads: every function may be called from any thread, at the same time as any function of
 * cache.h. */
#ifndef ISOPROP_CACHE_PREFETCH_H
#define ISOPROP_CACHE_PREFETCH_H

#include <stdint.h>

#include "isoprop/cache.h"

typedef enum ip__prefetch_outcome {
    IP__PREFETCH_LOADED,  /* read, decoded and resident now */
    IP__PREFETCH_PRESENT, /* resident already, or being loaded by another thread */
    IP__PREFETCH_FULL,    /* no room without evicting a brick pinned since `below` */
    IP__PREFETCH_FAILED   /* the read or the decode failed; nothing cached */
} ip__prefetch_outcome;

/* Loads brick `g` ahead, evicting (least recently used first) only unpinned bricks whose last
 * pin or load came before tick `below`; blocks for the read and the decode. */
ip__prefetch_outcome ip__cache_prefetch_brick(ip_cache *cache, uint64_t g, uint64_t below);

/* Pins brick `g` only when it is resident (a hit, counted as one): 1 and *b filled, or 0, with
 * nothing read, loaded or waited for (a brick being loaded by another thread is not resident
 * yet). For tests that may give up where data is missing, such as the engine's beam tests:
 * they must not make a view read bricks that its rays and propagation never need. */
int ip__cache_pin_resident(ip_cache *cache, uint64_t g, ip_brick *b);

/* The earliest tick a pin made from now on gets: bricks pinned after this call have ticks
 * >= the value, those pinned before have smaller ones. */
uint64_t ip__cache_tick_now(const ip_cache *cache);

/* Bricks loaded ahead that are resident and have not been pinned since. */
uint64_t ip__cache_prefetch_unused(const ip_cache *cache);

#endif

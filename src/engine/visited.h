/* The set of cells already extracted, one bit per cell, stored per brick and allocated only
 * for the bricks propagation reaches, so its memory follows the surface, not the volume.
 * Thread-safe: bits are set with atomic operations and a brick's bitmap is published with a
 * compare-and-swap. Internal. */
#ifndef ISOPROP_VISITED_H
#define ISOPROP_VISITED_H

#include <stdatomic.h>
#include <stdint.h>

#include "format.h"

typedef struct ip_visited {
    const ip_layout *layout;
    _Atomic(atomic_uint_fast64_t *) *bitmaps; /* one per brick of every level, or NULL */
    uint64_t words_per_brick;
    unsigned edge_shift;        /* log2 of the brick edge (a power of two) */
    atomic_uint_fast64_t bytes; /* allocated bitmap bytes */
} ip_visited;

ip_status ip__visited_init(ip_visited *v, const ip_layout *layout);
void ip__visited_free(ip_visited *v);

/* Forgets every cell (frees the bitmaps). Not to be called while other threads use the set. */
void ip__visited_clear(ip_visited *v);

/* Marks cell `cell` of `level`; returns 1 if it was already marked, 0 if this call marked it,
 * -1 when out of memory. */
int ip__visited_mark(ip_visited *v, uint32_t level, const uint32_t cell[3]);

/* 1 when the cell is marked. */
int ip__visited_test(const ip_visited *v, uint32_t level, const uint32_t cell[3]);

#endif

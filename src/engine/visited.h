/* SPDX-License-Identifier: BSD-3-Clause */
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
    uint64_t *holders; /* the bricks that have a bitmap, holders[0 .. holder_count) (in the
                          order published; an entry is written just after its count is taken) */
    atomic_uint_fast64_t holder_count;
    uint64_t words_per_brick;
    uint64_t cells_per_brick;     /* B^3: the cells' bits, then one per sub-block, then one */
    uint64_t subblocks_per_brick; /* per cell group (IP_CELL_GROUP^3 cells): see "Settled" */
    unsigned edge_shift;          /* log2 of the brick edge (a power of two) */
} ip_visited;

ip_status ip__visited_init(ip_visited *v, const ip_layout *layout);
void ip__visited_free(ip_visited *v);

/* Forgets every cell (frees the bitmaps, visiting only the bricks that have one). Not to be
 * called while other threads use the set. */
void ip__visited_clear(ip_visited *v);

/* Marks cell `cell` of `level`; returns 1 if it was already marked, 0 if this call marked it,
 * -1 when out of memory. */
int ip__visited_mark(ip_visited *v, uint32_t level, const uint32_t cell[3]);

/* 1 when the cell is marked. */
int ip__visited_test(const ip_visited *v, uint32_t level, const uint32_t cell[3]);

/* The bitmap of the brick holding cell `cell` of `level` (ip__visited_bitmap()). */
atomic_uint_fast64_t *ip__visited_cell_bitmap(const ip_visited *v, uint32_t level,
                                              const uint32_t cell[3]);

/* Settled parts: the beam tests' record of sub-blocks and cell groups every active cell of
 * which (that the clipping planes keep) is marked, so that later tests pass over them. Part
 * `part` of a brick is sub-block `part` (index within the brick, x fastest) below
 * subblocks_per_brick, else cell group part - subblocks_per_brick (likewise, over the brick's
 * B / IP_CELL_GROUP groups a side); a bit of each after the cells' bits of the brick's bitmap,
 * which once set stays set until ip__visited_clear(). Marks part `part` of the brick of
 * global index `brick`; 0, or -1 when out of memory. */
int ip__visited_mark_part(ip_visited *v, uint64_t brick, uint64_t part);

/* For tests and marks of many cells of one brick (ip__visited_test_in(), ip__visited_mark_in()):
 * the bitmap of the brick of global index `brick`, NULL while none of its cells is marked (a
 * bitmap published after this call is not seen, so a cell marked meanwhile may read as
 * unmarked). */
static inline atomic_uint_fast64_t *ip__visited_bitmap(const ip_visited *v, uint64_t brick)
{
    return atomic_load_explicit(&v->bitmaps[brick], memory_order_acquire);
}

/* The bit of `cell` (level coordinates) in its brick's bitmap: the brick's cells x fastest. */
static inline uint64_t ip__visited_cell_bit(const ip_visited *v, const uint32_t cell[3])
{
    unsigned shift = v->edge_shift;
    uint32_t mask = (UINT32_C(1) << shift) - 1;
    return (cell[0] & mask) + ((uint64_t)(cell[1] & mask) << shift) +
           ((uint64_t)(cell[2] & mask) << (2 * shift));
}

/* 1 when `cell` (of the level and brick whose bitmap is `m`, from ip__visited_bitmap()) is
 * marked. */
static inline int ip__visited_test_in(const ip_visited *v, const atomic_uint_fast64_t *m,
                                      const uint32_t cell[3])
{
    if (!m)
        return 0;
    uint64_t bit = ip__visited_cell_bit(v, cell);
    return (atomic_load_explicit(&m[bit >> 6], memory_order_relaxed) >> (bit & 63)) & 1;
}

/* Marks `cell` (of the level and brick whose bitmap is `m`, not NULL); returns 1 if it was
 * already marked, 0 if this call marked it: ip__visited_mark() without finding the bitmap. */
static inline int ip__visited_mark_in(const ip_visited *v, atomic_uint_fast64_t *m,
                                      const uint32_t cell[3])
{
    uint64_t bit = ip__visited_cell_bit(v, cell);
    uint_fast64_t mask = (uint_fast64_t)1 << (bit & 63);
    return (atomic_fetch_or(&m[bit >> 6], mask) & mask) != 0;
}

/* 1 when part `part` of the brick whose bitmap is `m` (ip__visited_bitmap()) is marked
 * settled (ip__visited_mark_part()). */
static inline int ip__visited_part_in(const ip_visited *v, const atomic_uint_fast64_t *m,
                                      uint64_t part)
{
    if (!m)
        return 0;
    uint64_t bit = v->cells_per_brick + part;
    return (atomic_load_explicit(&m[bit >> 6], memory_order_relaxed) >> (bit & 63)) & 1;
}

#endif

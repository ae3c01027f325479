/* SPDX-License-Identifier: BSD-3-Clause */
/* A sparse, concurrent bit set over the cells of every level. */
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "isoprop/cache.h"
#include "visited.h"

ip_status ip__visited_init(ip_visited *v, const ip_layout *layout)
{
    memset(v, 0, sizeof *v);
    v->layout = layout;
    uint64_t b = layout->brick_edge, per = b / layout->subblock_edge;
    uint64_t groups = (b + IP_CELL_GROUP - 1) / IP_CELL_GROUP;
    v->cells_per_brick = b * b * b;
    v->subblocks_per_brick = per * per * per;
    v->words_per_brick = (b * b * b + per * per * per + groups * groups * groups + 63) / 64;
    v->edge_shift = ip__ceil_log2(b);
    v->bitmaps = calloc(layout->brick_count, sizeof *v->bitmaps);
    v->holders = malloc(layout->brick_count * sizeof *v->holders);
    atomic_init(&v->holder_count, 0);
    if (v->bitmaps && v->holders)
        return IP_OK;
    ip__visited_free(v);
    return IP_ERR_NOMEM;
}

void ip__visited_clear(ip_visited *v)
{
    uint64_t n = atomic_load(&v->holder_count);
    IP_ASSERT(n == 0 || n <= v->layout->brick_count);
    for (uint64_t i = 0; i < n; i++) {
        uint64_t g = v->holders[i];
        /* each holder once, with its bitmap: freed here, so a second listing would find none */
        IP_ASSERT(g < v->layout->brick_count && atomic_load(&v->bitmaps[g]) != NULL);
        free(atomic_load(&v->bitmaps[g]));
        atomic_store(&v->bitmaps[g], NULL);
    }
    atomic_store(&v->holder_count, 0);
}

void ip__visited_free(ip_visited *v)
{
    ip__visited_clear(v); /* nothing to visit when the arrays are missing: no holders yet */
    free(v->bitmaps);
    free(v->holders);
    v->bitmaps = NULL;
    v->holders = NULL;
}

/* The global index of the brick holding a cell. */
static uint64_t brick_of(const ip_visited *v, uint32_t level, const uint32_t cell[3])
{
    uint32_t brick[3];
    IP_ASSERT(level < v->layout->level_count);
    for (int a = 0; a < 3; a++) {
        IP_ASSERT(cell[a] < v->layout->levels[level].dims[a] - 1);
        brick[a] = cell[a] >> v->edge_shift;
    }
    return ip_brick_global_index(v->layout, level, brick);
}

/* Brick g's bitmap, allocated and published first if it has none; NULL when out of memory. */
static atomic_uint_fast64_t *brick_bitmap(ip_visited *v, uint64_t g)
{
    IP_ASSERT(g < v->layout->brick_count);
    atomic_uint_fast64_t *m = atomic_load_explicit(&v->bitmaps[g], memory_order_acquire);
    if (!m) {
        atomic_uint_fast64_t *fresh = calloc(v->words_per_brick, sizeof *fresh);
        if (!fresh)
            return NULL;
        atomic_uint_fast64_t *expected = NULL;
        if (atomic_compare_exchange_strong(&v->bitmaps[g], &expected, fresh)) {
            m = fresh;
            uint64_t holder = atomic_fetch_add(&v->holder_count, 1);
            IP_ASSERT(holder < v->layout->brick_count); /* each brick once: room for all */
            v->holders[holder] = g;
        } else {
            free(fresh); /* another thread published first */
            m = expected;
        }
    }
    return m;
}

int ip__visited_mark(ip_visited *v, uint32_t level, const uint32_t cell[3])
{
    atomic_uint_fast64_t *m = brick_bitmap(v, brick_of(v, level, cell));
    return m ? ip__visited_mark_in(v, m, cell) : -1;
}

int ip__visited_mark_part(ip_visited *v, uint64_t brick, uint64_t part)
{
    uint64_t edge = v->layout->brick_edge, groups = (edge + IP_CELL_GROUP - 1) / IP_CELL_GROUP;
    IP_ASSERT(part < v->subblocks_per_brick + groups * groups * groups); /* its bit's room */
    atomic_uint_fast64_t *m = brick_bitmap(v, brick);
    if (!m)
        return -1;
    uint64_t bit = v->cells_per_brick + part;
    atomic_fetch_or(&m[bit >> 6], (uint_fast64_t)1 << (bit & 63));
    return 0;
}

int ip__visited_test(const ip_visited *v, uint32_t level, const uint32_t cell[3])
{
    return ip__visited_test_in(v, ip__visited_cell_bitmap(v, level, cell), cell);
}

atomic_uint_fast64_t *ip__visited_cell_bitmap(const ip_visited *v, uint32_t level,
                                              const uint32_t cell[3])
{
    return ip__visited_bitmap(v, brick_of(v, level, cell));
}

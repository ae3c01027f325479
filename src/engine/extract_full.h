/* SPDX-License-Identifier: BSD-3-Clause */
/* What the full extractions share (extract_full.c: the soup; extract_indexed.c: welded as it
 * goes): the bricks their workers take, and the cells of a sub-block. Internal. */
#ifndef ISOPROP_EXTRACT_FULL_H
#define ISOPROP_EXTRACT_FULL_H

#include <stdatomic.h>
#include <stdint.h>

#include "isoprop/store.h"
#include "sampler.h"

/* The next brick of level `lv` whose range holds `iso` that a worker takes from the shared
 * counter *next: its level-local index in *i. Returns 0 when none is left. */
static inline int ip__next_active_brick(const ip_store *store, const ip_level_layout *lv,
                                        atomic_uint_fast64_t *next, float iso, uint64_t *i)
{
    for (;;) {
        *i = atomic_fetch_add(next, 1);
        if (*i >= lv->brick_count)
            return 0;
        float range[2];
        ip_store_brick_range(store, lv->first_brick + *i, range);
        if (ip__range_active(range[0], range[1], iso))
            return 1;
    }
}

/* The cells lo .. hi - 1 (level coordinates) of sub-block `i` (x fastest; `per` sub-blocks of
 * `se` cells along each edge) of the brick whose samples start at `origin`, `extent` along
 * each axis. */
static inline void ip__subblock_cells(uint32_t i, uint32_t per, uint32_t se,
                                      const uint32_t origin[3], const uint32_t extent[3],
                                      uint32_t lo[3], uint32_t hi[3])
{
    uint32_t sb[3] = {i % per, (i / per) % per, i / (per * per)};
    for (int a = 0; a < 3; a++) {
        lo[a] = origin[a] + se * sb[a];
        hi[a] = lo[a] + se < origin[a] + extent[a] - 1 ? lo[a] + se : origin[a] + extent[a] - 1;
    }
}

#endif

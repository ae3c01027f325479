/* SPDX-License-Identifier: BSD-3-Clause */
/* The ray order handed out to the engine's workers: ranges of positions claimed without a
 * lock, batches of rays, the step's budget. */
#include <stdatomic.h>
#include "engine_state.h"
#include "internal.h"

#define RANGE_MIN 16   /* positions of the ray order a worker claims at once, at the start... */
#define RANGE_MAX 1024 /* ...and at most, later: 1/256 of the positions already handed out */
#define RETIRED_PER_BATCH 4096 /* rays of blocks a batch may retire at once, at most */

int ip__engine_take_budget(ip_engine *e, uint64_t rays)
{
    if (!e->step_limited)
        return 1;
    uint64_t left = atomic_load(&e->step_rays_left);
    do {
        if (left < rays)
            return 0;
    } while (!atomic_compare_exchange_weak(&e->step_rays_left, &left, left - rays));
    return 1;
}

/* Gives the worker a range of the order to walk: the earliest one left unfinished by a step,
 * else the next unclaimed one. Ranges start small, so that the first rays (the coarsest levels)
 * keep their order closely, and grow with the position to at most RANGE_MAX. Returns 0 once
 * every position has been claimed. */
static int claim_range(ip_engine *e, ip_engine_worker *w)
{
    if (atomic_load(&e->leftovers_waiting) > 0) {
        pthread_mutex_lock(&e->leftover_lock);
        unsigned first = 0;
        for (unsigned i = 1; i < e->leftover_count; i++)
            if (e->leftovers[i].start < e->leftovers[first].start)
                first = i;
        int found = e->leftover_count > 0;
        if (found) {
            /* an unwalked rest of a range within the order (ip__engine_leave_range()) */
            IP_ASSERT(e->leftovers[first].start < e->leftovers[first].end &&
                      e->leftovers[first].end <= e->order_cells);
            ip__ray_order_seek(&w->order, e->leftovers[first].start);
            w->range_end = e->leftovers[first].end;
            e->leftovers[first] = e->leftovers[--e->leftover_count];
            atomic_store(&e->leftovers_waiting, e->leftover_count);
        }
        pthread_mutex_unlock(&e->leftover_lock);
        if (found)
            return w->holding = 1;
    }
    uint64_t start = atomic_load(&e->next_position), length;
    do {
        if (start >= e->order_cells)
            return 0;
        length = start / 256 < RANGE_MIN   ? RANGE_MIN
                 : start / 256 > RANGE_MAX ? RANGE_MAX
                                           : start / 256;
        if (length >= BLOCK_CELLS) /* ends on a block's edge, so that later ranges hold whole
                                      blocks (ip__engine_take_block()) */
            length +=
                (BLOCK_CELLS - (start + length + BLOCK_CELLS - e->block_phase) % BLOCK_CELLS) %
                BLOCK_CELLS;
    } while (!atomic_compare_exchange_weak(&e->next_position, &start, start + length));
    ip__ray_order_seek(&w->order, start);
    w->range_end = e->order_cells - start < length ? e->order_cells : start + length;
    IP_ASSERT(start < w->range_end && w->range_end <= e->order_cells);
    return w->holding = 1;
}

void ip__engine_leave_range(ip_engine *e, ip_engine_worker *w)
{
    uint64_t position = ip__ray_order_position(&w->order);
    if (w->holding && position < w->range_end) {
        IP_ASSERT(w->range_end <= e->order_cells);
        pthread_mutex_lock(&e->leftover_lock);
        IP_ASSERT(e->leftover_count < e->threads); /* one range a worker at a time */
        e->leftovers[e->leftover_count++] = (ip_order_range){position, w->range_end};
        atomic_store(&e->leftovers_waiting, e->leftover_count);
        pthread_mutex_unlock(&e->leftover_lock);
    }
    w->holding = 0;
}

uint64_t ip__engine_take_rays(ip_engine *e, ip_engine_worker *w, ip_order_ray *rays,
                              unsigned *count)
{
    *count = 0;
    if (atomic_load_explicit(&e->step_stopped, memory_order_relaxed) ||
        (e->step_deadline > 0 && ip_now_seconds() >= e->step_deadline))
        return 0;
    uint64_t want = e->step_batch;
    if (e->step_limited) { /* take the batch's share of the budget first */
        uint64_t left = atomic_load(&e->step_rays_left);
        do {
            if (left == 0)
                return 0;
            want = left < e->step_batch ? left : e->step_batch;
        } while (!atomic_compare_exchange_weak(&e->step_rays_left, &left, left - want));
    }
    unsigned n = 0;
    uint64_t retired = 0; /* rays of blocks passed over at once */
    while (n < want && retired < RETIRED_PER_BATCH && (w->holding || claim_range(e, w))) {
        unsigned block, walk;
        if (ip__engine_take_block(e, w, rays + n, RAY_ROOM - n, (unsigned)(want - n), &block,
                                  &walk)) {
            retired += block;
            n += walk;
        } else if (ip__ray_order_next_before(&w->order, w->range_end, &rays[n].x, &rays[n].y)) {
            rays[n].x += e->region_x; /* the image's pixel (see ip_engine_set_region()) */
            rays[n].y += e->region_y;
            rays[n].level = ip__ray_order_level(&w->order);
            rays[n].tested = 0;
            n++;
        } else
            w->holding = 0;
    }
    IP_ASSERT(n <= RAY_ROOM);
    if (e->step_limited && n < want) /* the order ran out: give the rest of the share back */
        atomic_fetch_add(&e->step_rays_left, want - n);
    atomic_fetch_add(&e->rays_taken, n + retired);
    *count = n;
    return n + retired;
}

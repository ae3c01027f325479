/* SPDX-License-Identifier: BSD-3-Clause */
/* A propagation's queue of cells, nearest first, in buckets of view depth. */
#include <stdlib.h>
#include <string.h>

#include "array.h"
#include "depth_queue.h"
#include "internal.h"

#define NONE UINT32_MAX

void ip__depth_queue_init(ip_depth_queue *q)
{
    memset(q, 0, sizeof *q);
    q->free = NONE;
    for (unsigned b = 0; b < IP_DEPTH_BUCKETS; b++)
        q->head[b] = NONE;
    q->first = IP_DEPTH_BUCKETS;
    q->last = 0;
    q->scale = 1.0;
}

void ip__depth_queue_free(ip_depth_queue *q)
{
    free(q->slots);
    ip__depth_queue_init(q);
}

void ip__depth_queue_start(ip_depth_queue *q, double around, double width)
{
    IP_ASSERT(width > 0);
    for (uint32_t b = q->first; b <= q->last && b < IP_DEPTH_BUCKETS; b++)
        q->head[b] = NONE; /* what a propagation that stopped early left */
    q->first = IP_DEPTH_BUCKETS;
    q->last = 0;
    q->count = 0;
    q->used = 0;
    q->free = NONE;
    q->scale = 1.0 / width;
    q->base = around - 0.25 * IP_DEPTH_BUCKETS * width;
}

/* The bucket of view depth `depth`, clamped to the range. */
static uint32_t bucket_of(const ip_depth_queue *q, double depth)
{
    double b = (depth - q->base) * q->scale;
    IP_ASSERT(b == b); /* not a NaN: a bucket, near or far */
    return b <= 0 ? 0 : b >= IP_DEPTH_BUCKETS - 1 ? IP_DEPTH_BUCKETS - 1 : (uint32_t)b;
}

/* A slot for one more cell: a free one, else a new one. NONE when out of memory. */
static uint32_t new_slot(ip_depth_queue *q)
{
    if (q->free != NONE) {
        uint32_t s = q->free;
        q->free = q->slots[s].next;
        return s;
    }
    if (q->used == NONE || ip__array_reserve(&q->slots, &q->capacity, (uint64_t)q->used + 1,
                                             sizeof *q->slots, 4096) != IP_OK)
        return NONE;
    return q->used++;
}

ip_status ip__depth_queue_push(ip_depth_queue *q, const ip_queued_cell *cell, double depth)
{
    uint32_t s = new_slot(q);
    if (s == NONE)
        return IP_ERR_NOMEM;
    uint32_t b = bucket_of(q, depth);
    IP_ASSERT(s < q->used && b < IP_DEPTH_BUCKETS);
    q->slots[s] = (ip_depth_slot){*cell, q->head[b]};
    q->head[b] = s;
    q->first = b < q->first ? b : q->first;
    q->last = b > q->last ? b : q->last;
    q->count++;
    return IP_OK;
}

/* Takes the newest cell of bucket b (not empty) into *cell. */
static void take(ip_depth_queue *q, uint32_t b, ip_queued_cell *cell)
{
    uint32_t s = q->head[b];
    IP_ASSERT(q->count > 0 && q->first <= b && b <= q->last && s < q->used);
    *cell = q->slots[s].cell;
    q->head[b] = q->slots[s].next;
    q->slots[s].next = q->free;
    q->free = s;
    q->count--;
}

int ip__depth_queue_pop(ip_depth_queue *q, ip_queued_cell *cell)
{
    if (q->count == 0)
        return 0;
    while (q->head[q->first] == NONE) {
        IP_ASSERT(q->first < q->last); /* a cell is queued: some bucket up to last holds it */
        q->first++;
    }
    take(q, q->first, cell); /* the nearest: no bucket before first holds a cell */
    return 1;
}

unsigned ip__depth_queue_take_far(ip_depth_queue *q, ip_queued_cell *out, unsigned max)
{
    unsigned n = 0;
    while (n < max && q->count > 0) {
        while (q->head[q->last] == NONE) {
            IP_ASSERT(q->last > q->first); /* a cell is queued: some bucket from first holds it */
            q->last--;
        }
        take(q, q->last, &out[n++]);
    }
    return n;
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* A propagation's queue of cells, nearest to the eye first: buckets of view depth. Internal.
 *
 * Propagation that takes the nearest queued cell first extracts the surface in front before
 * the surface behind it, so that by the time a hidden cell comes up the coverage buffer more
 * often holds what hides it, and the cell is deferred rather than extracted (coverage.c). The
 * order is that of buckets of `width` world units of depth; within a bucket, the newest cell
 * first. Depths beyond the buckets' range share the first or the last. Slots of cells taken
 * are used again, so the memory is that of the most cells queued at once. */
#ifndef ISOPROP_DEPTH_QUEUE_H
#define ISOPROP_DEPTH_QUEUE_H

#include <stdint.h>

#include "isoprop/status.h"

#define IP_DEPTH_BUCKETS 1024

typedef struct ip_queued_cell {
    uint32_t cell[3];
    float max_versine; /* 1 - cos of the largest angle to the seed's ray among the cell's
                        * predecessors (angles compare as their versines, without atan2) */
} ip_queued_cell;

typedef struct ip_depth_slot {
    ip_queued_cell cell;
    uint32_t next; /* the next slot in its bucket, or on the free list */
} ip_depth_slot;

typedef struct ip_depth_queue {
    ip_depth_slot *slots;
    uint64_t capacity;               /* slots allocated */
    uint32_t used;                   /* slots ever handed out */
    uint32_t free;                   /* the first free slot (UINT32_MAX: none) */
    uint32_t head[IP_DEPTH_BUCKETS]; /* per bucket: its newest slot (UINT32_MAX: empty) */
    uint32_t first, last;            /* no bucket outside [first, last] holds a cell */
    uint64_t count;                  /* cells queued */
    double base, scale;              /* a depth's bucket: (depth - base) * scale */
} ip_depth_queue;

/* An empty queue; nothing allocated yet. */
void ip__depth_queue_init(ip_depth_queue *q);
void ip__depth_queue_free(ip_depth_queue *q);

/* Empties the queue and sets its buckets: `width` world units of depth each (> 0), the
 * depth `around` a quarter of the way into their range. */
void ip__depth_queue_start(ip_depth_queue *q, double around, double width);

/* Queues `cell` at view depth `depth`. @return IP_OK or IP_ERR_NOMEM. */
ip_status ip__depth_queue_push(ip_depth_queue *q, const ip_queued_cell *cell, double depth);

/* Takes a cell of the nearest bucket that holds one into *cell: 1, or 0 when empty. */
int ip__depth_queue_pop(ip_depth_queue *q, ip_queued_cell *cell);

/* Takes up to `max` cells from the farthest buckets into out[]; returns how many. */
unsigned ip__depth_queue_take_far(ip_depth_queue *q, ip_queued_cell *out, unsigned max);

#endif

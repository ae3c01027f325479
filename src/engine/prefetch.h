/* SPDX-License-Identifier: BSD-3-Clause */
/* The engine's background reader: one thread per engine that reads and decodes into the cache
 * the bricks the next rays of the progressive order will seed in, and their neighbours across
 * brick faces, where propagation goes next, so that the workers find them resident instead of
 * waiting for the disk and the decoder. Internal.
 *
 * What it loads: it walks its own copy of the view's ray order from the first position no
 * worker has claimed yet, at most IP__PREFETCH_AHEAD positions ahead of the workers, over the
 * coarse levels only (those whose cells are at least 2^IP__PREFETCH_SKIP_LEVELS pixels
 * across: the rays of the finer levels fall between them and cross the same bricks). For each
 * ray it finds from the summaries alone the first IP__PREFETCH_RAY_BRICKS bricks, over the
 * view's pyramid levels (the level-of-detail bands), where the ray crosses a sub-block whose
 * range holds the isovalue (ip__seed_ray_bricks()), then the face neighbours of those bricks
 * whose range holds it. Each brick is planned once per view.
 *
 * How: the kernel is asked for the payloads of the planned bricks up to the device's
 * read-ahead size ahead of the brick being loaded (read_ahead_kb of the block device holding
 * the file, IP__PREFETCH_DEFAULT_WINDOW where it cannot be found), so that the disk works
 * while the brick before is decoded; each brick is then loaded with
 * ip__cache_prefetch_brick() (cache_prefetch.h: within the budget, evicting only bricks not
 * pinned since the view began).
 *
 * When it stops: the plan is done; 4 batches of the plan in a row loaded nothing (the view's
 * bricks are resident, as in a warm cache: planning would only take a core from the workers,
 * who load what they still miss themselves); the cache has no room left for it (the budget is
 * full of bricks of this view, or pinned: it stays idle until the next view); the engine is
 * cancelled; or the engine pauses it (a new view, destroy). It runs between steps too.
 *
 * Threads: the functions are called by the engine's driving thread only; the reader thread
 * reads the view only between resume and pause, and writes nothing but the cache. */
#ifndef ISOPROP_PREFETCH_H
#define ISOPROP_PREFETCH_H

#include <stdatomic.h>
#include <stdint.h>

#include "isoprop/cache.h"
#include "isoprop/camera.h"
#include "isoprop/layout.h"
#include "clip.h"
#include "ray_order.h"

#define IP__PREFETCH_AHEAD 4096                /* ray order positions ahead of the workers */
#define IP__PREFETCH_SKIP_LEVELS 4             /* the finest ray order levels not planned */
#define IP__PREFETCH_RAY_BRICKS 2              /* bricks planned per ray */
#define IP__PREFETCH_DEFAULT_WINDOW (1u << 20) /* bytes of payload asked for ahead */

typedef struct ip__prefetcher ip__prefetcher;

/* What the reader plans from: the view of ip_engine_begin(), copied by ip__prefetcher_begin(). */
typedef struct ip__prefetch_view {
    ip_camera camera;
    ip_camera_basis basis;
    float iso;
    uint32_t levels_used;
    const double *lod_distance;  /* D[0 .. levels_used], copied */
    const double *band_widening; /* per level, as the rays widen its band (lod.h), copied */
    ip_ray_order order;          /* the view's order at position 0 */
    uint64_t order_cells;
    const atomic_uint_fast64_t *claimed; /* the first position no worker has claimed */
    const atomic_int *cancel;            /* the engine's cancel flag */
    ip_clip clip; /* the engine's planes: bricks wholly beyond one are not read ahead */
    uint32_t region_x, region_y; /* the image pixel of the order's pixel (0, 0) */
    int load_all; /* load every planned brick, those the page cache holds too: the workers are
                     idle (ip_engine_read_ahead()) */
} ip__prefetch_view;

/* Starts the reader thread (signals blocked), idle until ip__prefetcher_resume(). With
 * `leave_in_memory` it loads only the planned bricks whose payload the page cache does not
 * hold (ip_store_brick_in_memory() is not 1), for when it would take a core from the workers:
 * decoding such a brick costs a worker no more than it costs the reader, and the reader's
 * would be lost when no ray needs the brick. *out is the caller's, released with
 * ip__prefetcher_destroy(). @return IP_OK or IP_ERR_NOMEM. */
ip_status ip__prefetcher_create(ip_cache *cache, int leave_in_memory, ip__prefetcher **out);

/* Pauses, stops and joins the thread, frees everything; NULL is a no-op. */
void ip__prefetcher_destroy(ip__prefetcher *p);

/* Stops the reader at its next brick and returns once it is idle (it finishes the brick it is
 * loading: one read and decode at most). */
void ip__prefetcher_pause(ip__prefetcher *p);

/* A new view, while paused: forgets the plan of the previous one. */
void ip__prefetcher_begin(ip__prefetcher *p, const ip__prefetch_view *view);

/* Lets the reader work on the current view (at each step; a no-op once it has stopped). */
void ip__prefetcher_resume(ip__prefetcher *p);

#endif

/* SPDX-License-Identifier: BSD-3-Clause */
/* The progressive engine's state, shared by the files that make it up (internal): the engine
 * and its workers (engine.c: lifecycle, views, steps), the ray order handed out to the workers
 * (handout.c), a pixel's ray (cast.c), rays retired in bulk by screen tiles (retire.c) and
 * idle workers helping others' propagations (share.c). */
#ifndef ISOPROP_ENGINE_STATE_H
#define ISOPROP_ENGINE_STATE_H

#include <pthread.h>
#include <stdatomic.h>

#include "coverage.h"
#include "isoprop/engine.h"
#include "pool.h"
#include "prefetch.h"
#include "propagate.h"
#include "ray_order.h"
#include "seed.h"

#define RAY_BATCH 16      /* rays a worker takes at once: small, so the order stays progressive */
#define DEPTH_MARGIN 1e-5 /* relative: float rounding of vertices (as coverage.c's boxes) */
#define TILE_SHIFT 3      /* bulk retirement: tiles of 8 x 8 pixels */
/* The Z-order levels' aligned blocks of 4^BLOCK_LOG4 cells are taken at once, their pixels
 * that ip__engine_retire() would retire passed over (ip__engine_take_block()). */
#define BLOCK_LOG4 3
#define BLOCK_CELLS (1u << 2 * BLOCK_LOG4)
#define RAY_ROOM (RAY_BATCH + BLOCK_CELLS) /* a batch's rays, a block's overfill included */

/* A worker's tools for one pyramid level: pinned bricks, seeding state, propagation queue. */
typedef struct ip_level_tools {
    int ready;
    ip_sampler sampler;
    ip_seeder seeder;
    ip_propagator propagator;
} ip_level_tools;

/* Positions [start, end) of the ray order (ray_order.h) that no worker has walked yet. */
typedef struct ip_order_range {
    uint64_t start, end;
} ip_order_range;

/* One worker's private state: its tools per level, its triangles, and its range of the ray
 * order with an iterator over it. */
typedef struct ip_engine_worker {
    ip_engine *engine;
    ip_ray_order order;
    uint64_t range_end;
    int holding; /* a range: the iterator's position up to range_end */
    ip_level_tools level[IP_MAX_LEVELS];
    ip_mesh mesh;
    ip_engine_counts counts;
    ip_status status;
    uint32_t failed_level;
} ip_engine_worker;

/* A screen tile of bulk retirement (see ip__engine_retire()). */
typedef struct ip_engine_tile {
    atomic_uint depth;   /* a float's bits: the rays of its pixels whose solid entry is no
                            deeper need no walk (0: none known; +infinity: every ray) */
    atomic_uint from;    /* a float's bits: a view depth short of which its rays find nothing
                            new (0: none known) */
    atomic_uchar tested; /* 1 + the last ray-order level (from tile_from) it was tested in */
    atomic_uint cells;   /* the engine's cells_done when it was tested last */
} ip_engine_tile;

/* Cells a propagation handed out (ip_share): a part of its queue, for the ray `dir`. */
typedef struct ip_shared_cells {
    uint32_t level;
    unsigned count;
    double dir[3];
    ip_queued_cell cells[IP_SHARE_CELLS];
} ip_shared_cells;

#define SHARED_MAX 16 /* parts of queues waiting at most */

/* A ray of the order: its pixel and the order's level it belongs to; with `tested`, its tile was
 * consulted already (ip__engine_retire()) and the ray is to be walked from view depth `from`. */
typedef struct ip_order_ray {
    uint32_t x, y, level;
    int tested;
    double from;
} ip_order_ray;

struct ip_engine {
    ip_cache *cache;
    ip_engine_options options;
    unsigned threads;
    ip_engine_worker *workers;
    ip__pool *pool;             /* runs the workers of every step; started at create */
    ip__prefetcher *prefetcher; /* with options.prefetch: the background reader */
    ip_visited visited;
    ip_coverage coverage; /* with options.occlusion: what extracted surface hides */
    ip_mesh mesh;
    pthread_mutex_t mesh_lock; /* workers append their buffers to `mesh` during a step */
    ip_camera camera;
    ip_camera_basis basis;
    float iso;
    int begun;
    int reusable; /* with options.reuse: the mesh is that of the view begun last, every step of
                     it successful, no region set (reuse.c) */
    uint32_t levels_used;                   /* levels 0 .. levels_used - 1 have a distance band */
    double lod_distance[IP_MAX_LEVELS + 1]; /* D[k]; D[levels_used] = infinity */
    double cell_reach[IP_MAX_LEVELS];       /* a level-k cell's extent along the view (world) */
    double band_widening[IP_MAX_LEVELS];    /* how far a level-k cell may reach past its band
                                               (world; ip__lod_band_widening()) */
    /* With occlusion: bulk retirement of the rays of 8 x 8 tiles (ip__engine_retire()) */
    ip_engine_tile *tiles;
    unsigned char *reached; /* per tile: some active brick may show in it (reach_view()) */
    size_t tile_capacity;
    uint32_t tiles_x, tiles_y;
    uint32_t tile_from;   /* the first ray-order level whose rays test their tile: the first
                           of the order's local levels (start_order()) */
    uint32_t block_phase; /* the position of tile_from's first cell, modulo BLOCK_CELLS */
    /* The ray order is handed out in ranges of positions: a worker claims the next range
     * with one atomic add (or takes a range another worker left unfinished at the end of a
     * step, the earliest first) and walks it with its own iterator, so no lock is held while
     * the order is computed. */
    ip_ray_order order; /* the view's order, copied into each worker's iterator */
    uint64_t order_cells;
    atomic_uint_fast64_t next_position; /* the first position no worker has claimed */
    atomic_uint_fast64_t ahead_claimed; /* ip_engine_read_ahead(): 0, no worker walks it */
    atomic_uint_fast64_t rays_taken;    /* pixels handed out since begin (or set_region) */
    uint64_t ray_target;                /* the pixels of the order to cast: done at rays_taken */
    atomic_uint cells_done;             /* cells extracted since begin, as workers publish them */
    uint32_t region_x, region_y;        /* the order's pixel (0, 0) in the image */
    pthread_mutex_t leftover_lock;
    ip_order_range *leftovers; /* at most one per worker (each holds one range at a time) */
    unsigned leftover_count;
    atomic_uint leftovers_waiting;       /* leftover_count, readable without the lock */
    int step_limited;                    /* the step has a ray budget */
    unsigned step_batch;                 /* rays a worker takes at once in this step */
    atomic_uint_fast64_t step_rays_left; /* rays the current step may still hand out */
    atomic_int step_stopped;             /* a worker failed: the others take no more rays */
    double step_deadline;                /* 0: none */
    ip_engine_counts totals;
    atomic_int cancel;
    /* Parts of long propagations' queues, for the workers left without rays in a step
     * (ip__engine_help()): a stack of SHARED_MAX under share_lock, with the workers waiting for it
     * (`hungry`, read by the propagations) and those that may still add to it (`working`). */
    pthread_mutex_t share_lock;
    pthread_cond_t share_wake;
    ip_shared_cells *shared;
    unsigned shared_count;
    unsigned working;
    atomic_int hungry;
    atomic_uint share_news; /* bumped under share_lock when waiters should look again (spun on) */
};

/* handout.c */

/* Takes `rays` of the step's budget when the step has one; 0 when it has fewer left. */
int ip__engine_take_budget(ip_engine *e, uint64_t rays);

/* Takes up to RAY_BATCH pixels of the order for this step from the worker's ranges (up to
 * RAY_ROOM when the rays of a block overfill it): those to walk or retire one by one into
 * rays[0 .. *count), and the rays of blocks retired at once; returns how many pixels in all
 * (0: none left for this step). */
uint64_t ip__engine_take_rays(ip_engine *e, ip_engine_worker *w, ip_order_ray *rays,
                              unsigned *count);

/* Hands the unwalked rest of the worker's range back for a later step. */
void ip__engine_leave_range(ip_engine *e, ip_engine_worker *w);

/* retire.c */

/* 1 when ray r may be retired without a walk (counted), with occlusion: tile_retires() in the
 * Z-order levels, before them only a tile no active brick shows in. Otherwise 0, with *from
 * where its walk may start (0: at the eye). */
int ip__engine_retire(ip_engine_worker *w, const ip_order_ray *r, double *from);

/* When the worker's iterator stands at an aligned block of BLOCK_CELLS positions of the Z-order
 * levels, within its range: the block's pixels whose tile retires them (tile_retires(), which tests
 * a tile where ip__engine_retire() would: at its first ray that it does not retire) are counted as
 * retired, their number in *count, and the others, when there are at most `space`, go to rays[0 ..
 * *walk), to be walked; the iterator moves past the block, and 1 is returned. The step's budget
 * pays for the retired rays and those to walk beyond `share` (the batch's share of it left). 0, and
 * nothing done but tests of tiles, where the iterator stands at no such block, more than `space`
 * pixels are left, or the budget cannot pay. */
int ip__engine_take_block(ip_engine *e, ip_engine_worker *w, ip_order_ray *rays, unsigned space,
                          unsigned share, unsigned *count, unsigned *walk);

/* cast.c */

/* Casts the ray of pixel (x, y) from view depth `from` (0: the eye), one distance band after
 * the other, front to back, up to the pixel's solid coverage: extracts its seed and the cells
 * it nearly hit before it, propagating from each not extracted yet. Why the image stays exact
 * with the stop and the start: cast.c. */
ip_status ip__engine_cast_ray(ip_engine_worker *w, uint32_t x, uint32_t y, double from);

/* reuse.c */

/* With options.reuse, at ip_engine_begin() of a view at the isovalue of the one before, once the
 * view, its bands, the coverage and the workers' samplers are set up: keeps the mesh's cells that
 * belong to the new view (engine.h, "Reuse"), marks them extracted and records them in the
 * coverage; adds them to the totals. @return IP_OK or IP_ERR_NOMEM. */
ip_status ip__engine_keep(ip_engine *e);

/* share.c */

/* ip_share's give(): keeps a part of a propagation's queue for a worker without rays, and
 * wakes one. 0 when SHARED_MAX parts wait already. */
int ip__engine_give_cells(void *user, uint32_t level, const ip_queued_cell *cells, unsigned count,
                          const double dir[3]);

/* A worker whose step has no rays left for it propagates from the parts of queues other workers
 * hand out (ip__engine_give_cells()) until none is left and no worker may hand out more: the step
 * ends with every queued cell extracted, as when one worker propagated it all. */
void ip__engine_help(ip_engine *e, ip_engine_worker *w);

#endif

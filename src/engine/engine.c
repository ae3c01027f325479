/* The progressive engine: ray order, seeding, propagation on worker threads, step budgets,
 * cancellation. */
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "beam.h"
#include "coverage.h"
#include "internal.h"
#include "isoprop/engine.h"
#include "pool.h"
#include "prefetch.h"
#include "ray_order.h"
#include "propagate.h"
#include "reach.h"
#include "seed.h"
#include "vec3.h"

#define RAY_BATCH 16   /* rays a worker takes at once: small, so the order stays progressive */
#define RANGE_MIN 16   /* positions of the ray order a worker claims at once, at the start... */
#define RANGE_MAX 1024 /* ...and at most, later: 1/256 of the positions already handed out */
#define LOCAL_LEVELS 3 /* ray order: the finest levels cast in Z-order (start_order()) */
#define FLUSH_TRIANGLES 16384 /* a worker's buffer moves to the engine's mesh past this size */
#define DEPTH_MARGIN 1e-5     /* relative: float rounding of vertices (as coverage.c's boxes) */
#define TILE_SHIFT 3          /* bulk retirement: tiles of 8 x 8 pixels */
/* A tile is tested again in a later Z-order level only once the cells extracted have grown by
 * this fraction since its last test (tile_retires()). */
#define RETEST_GROWTH 0.1
#define TILE_SLACK (1.0 / 64) /* pixels added around a tile's pixel centres for its beam */
/* The Z-order levels' aligned blocks of 4^BLOCK_LOG4 cells are taken at once, their pixels
 * that retire() would retire passed over (take_block()). */
#define BLOCK_LOG4 3
#define BLOCK_CELLS (1u << 2 * BLOCK_LOG4)

/* A worker's tools for one pyramid level: pinned bricks, seeding state, propagation queue. */
typedef struct level_tools {
    int ready;
    ip_sampler sampler;
    ip_seeder seeder;
    ip_propagator propagator;
} level_tools;

/* Positions [start, end) of the ray order (ray_order.h) that no worker has walked yet. */
typedef struct order_range {
    uint64_t start, end;
} order_range;

/* One worker's private state: its tools per level, its triangles, and its range of the ray
 * order with an iterator over it. */
typedef struct worker {
    ip_engine *engine;
    ip_ray_order order;
    uint64_t range_end;
    int holding; /* a range: the iterator's position up to range_end */
    level_tools level[IP_MAX_LEVELS];
    ip_mesh mesh;
    ip_engine_counts counts;
    ip_status status;
    uint32_t failed_level;
} worker;

/* A screen tile of bulk retirement (see retire()). */
typedef struct tile {
    atomic_uint depth;   /* a float's bits: the rays of its pixels whose solid entry is no
                            deeper need no walk (0: none known; +infinity: every ray) */
    atomic_uint from;    /* a float's bits: a view depth short of which its rays find nothing
                            new (0: none known) */
    atomic_uchar tested; /* 1 + the last ray-order level (from tile_from) it was tested in */
    atomic_uint cells;   /* the engine's cells_done when it was tested last */
} tile;

/* Cells a propagation handed out (ip_share): a part of its queue, for the ray `dir`. */
typedef struct shared_cells {
    uint32_t level;
    unsigned count;
    double dir[3];
    ip_queued_cell cells[IP_SHARE_CELLS];
} shared_cells;

#define SHARED_MAX 16 /* parts of queues waiting at most */

/* A ray of the order: its pixel and the order's level it belongs to; with `tested`, its tile
 * was consulted already (retire()) and the ray is to be walked from view depth `from`. */
typedef struct order_ray {
    uint32_t x, y, level;
    int tested;
    double from;
} order_ray;

struct ip_engine {
    ip_cache *cache;
    ip_engine_options options;
    unsigned threads;
    worker *workers;
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
    uint32_t levels_used;                   /* levels 0 .. levels_used - 1 have a distance band */
    double lod_distance[IP_MAX_LEVELS + 1]; /* D[k]; D[levels_used] = infinity */
    double cell_reach[IP_MAX_LEVELS];       /* a level-k cell's extent along the view (world) */
    /* With occlusion: bulk retirement of the rays of 8 x 8 pixel tiles (see retire()). */
    tile *tiles;
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
    atomic_uint_fast64_t rays_taken;    /* pixels handed out since begin (or set_region) */
    uint64_t ray_target;                /* the pixels of the order to cast: done at rays_taken */
    atomic_uint cells_done;             /* cells extracted since begin, as workers publish them */
    uint32_t region_x, region_y;        /* the order's pixel (0, 0) in the image */
    pthread_mutex_t leftover_lock;
    order_range *leftovers; /* at most one per worker (each holds one range at a time) */
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
     * (help()): a stack of SHARED_MAX under share_lock, with the workers waiting for it
     * (`hungry`, read by the propagations) and those that may still add to it (`working`). */
    pthread_mutex_t share_lock;
    pthread_cond_t share_wake;
    shared_cells *shared;
    unsigned shared_count;
    unsigned working;
    atomic_int hungry;
};

void ip_engine_options_default(ip_engine_options *o)
{
    o->cutoff_degrees = IP_DEFAULT_CUTOFF_DEGREES;
    o->foldback_degrees = IP_DEFAULT_FOLDBACK_DEGREES;
    o->threads = 0;
    o->lod = 1;
    o->pixel_error = 1.0;
    o->cell_ids = 0;
    o->occlusion = 1;
    o->prefetch = 1;
    o->clip_count = 0;
}

/* The brick file an engine extracts from, which its messages name. */
static const char *path_of(const ip_cache *cache)
{
    return ip_store_path(ip_cache_store(cache));
}

ip_status ip_engine_create(ip_cache *cache, const ip_engine_options *options, ip_engine **out,
                           ip_error *err)
{
    if (!(options->cutoff_degrees > 0 && options->cutoff_degrees <= 180) ||
        !(options->foldback_degrees >= 0 && options->foldback_degrees <= 180))
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "cut-off %g and fold-back %g must be in degrees, "
                        "0 < cut-off <= 180, 0 <= fold-back <= 180",
                        options->cutoff_degrees, options->foldback_degrees);
    if (options->lod && !(options->pixel_error > 0 && isfinite(options->pixel_error)))
        return ip__fail(err, IP_ERR_ARGUMENT, "the pixel error %g must be positive",
                        options->pixel_error);
    if (!ip__clip_valid(options->clip, options->clip_count))
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "clipping planes: %u given (at most %d), each with a finite, non-zero "
                        "normal and a finite offset",
                        options->clip_count, IP_MAX_CLIP_PLANES);
    ip_engine *e = calloc(1, sizeof *e);
    if (!e)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory for an engine", path_of(cache));
    e->cache = cache;
    e->options = *options;
    e->threads = ip_thread_count(options->threads);
    atomic_init(&e->cancel, 0);
    atomic_init(&e->next_position, 0);
    atomic_init(&e->rays_taken, 0);
    atomic_init(&e->leftovers_waiting, 0);
    atomic_init(&e->step_rays_left, 0);
    atomic_init(&e->step_stopped, 0);
    pthread_mutex_init(&e->leftover_lock, NULL);
    pthread_mutex_init(&e->mesh_lock, NULL);
    pthread_mutex_init(&e->share_lock, NULL);
    pthread_cond_init(&e->share_wake, NULL);
    atomic_init(&e->hungry, 0);
    ip_mesh_init(&e->mesh);
    e->mesh.with_cells = options->cell_ids != 0;
    e->workers = calloc(e->threads, sizeof *e->workers);
    e->leftovers = calloc(e->threads, sizeof *e->leftovers);
    e->shared = malloc(SHARED_MAX * sizeof *e->shared);
    ip_status st = e->workers && e->leftovers && e->shared
                       ? ip__visited_init(&e->visited, ip_store_layout(ip_cache_store(cache)))
                       : IP_ERR_NOMEM;
    if (st == IP_OK)
        st = ip__pool_create(e->threads, &e->pool, NULL);
    if (st == IP_OK && options->prefetch)
        st = ip__prefetcher_create(cache, &e->prefetcher);
    for (unsigned t = 0; st == IP_OK && t < e->threads; t++) {
        e->workers[t].engine = e;
        ip_mesh_init(&e->workers[t].mesh);
        e->workers[t].mesh.with_cells = e->mesh.with_cells;
    }
    if (st != IP_OK) {
        ip_engine_destroy(e);
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory for an engine", path_of(cache));
    }
    *out = e;
    return IP_OK;
}

void ip_engine_destroy(ip_engine *e)
{
    if (!e)
        return;
    ip__prefetcher_destroy(e->prefetcher); /* first: it reads the view */
    ip__pool_destroy(e->pool);
    for (unsigned t = 0; e->workers && t < e->threads; t++) {
        for (uint32_t k = 0; k < IP_MAX_LEVELS; k++) {
            level_tools *lt = &e->workers[t].level[k];
            if (!lt->ready)
                continue;
            ip__propagator_free(&lt->propagator);
            ip__sampler_free(&lt->sampler);
        }
        ip_mesh_free(&e->workers[t].mesh);
    }
    free(e->workers);
    free(e->leftovers);
    free(e->tiles);
    free(e->reached);
    ip__visited_free(&e->visited);
    ip__coverage_free(&e->coverage);
    ip_mesh_free(&e->mesh);
    pthread_mutex_destroy(&e->leftover_lock);
    pthread_mutex_destroy(&e->mesh_lock);
    pthread_mutex_destroy(&e->share_lock);
    pthread_cond_destroy(&e->share_wake);
    free(e->shared);
    free(e);
}

/* D[k]: beyond it a level-k cell (2^k level-0 cells across, at the largest spacing)
 * projects to at most pixel_error pixels. Levels whose D lies beyond the volume's farthest
 * corner are not used. */
static void set_lod_distances(ip_engine *e)
{
    const ip_layout *l = ip_store_layout(ip_cache_store(e->cache));
    double spacing = fmax(l->spacing[0], fmax(l->spacing[1], l->spacing[2]));
    double pixels_per_radian = 0.5 * e->camera.height / e->basis.tan_half_y;
    double far = 0;
    for (int k = 0; k < 8; k++) {
        double corner[3], v[3];
        for (int a = 0; a < 3; a++)
            corner[a] = (k >> a & 1) ? (l->dims[a] - 1) * l->spacing[a] : 0;
        ip__vec3_sub(corner, e->camera.eye, v);
        far = fmax(far, ip__vec3_length(v));
    }
    e->lod_distance[0] = 0;
    e->levels_used = 1;
    for (uint32_t k = 1; e->options.lod && k < l->level_count; k++) {
        double d = (double)(1u << k) * spacing * pixels_per_radian / e->options.pixel_error;
        if (d >= far)
            break;
        e->lod_distance[k] = d;
        e->levels_used = k + 1;
    }
    e->lod_distance[e->levels_used] = INFINITY;
}

double ip_engine_lod_distance(const ip_engine *e, uint32_t level)
{
    return level < e->levels_used ? e->lod_distance[level] : INFINITY;
}

/* The ray order of a width x height image (the view's, or a region's), from its first pixel.
 * The finest levels (cells of at most 2^LOCAL_LEVELS pixels a side, most of the rays) are
 * cast in Z-order: consecutive rays then cross the same bricks and sub-blocks while they are
 * still in the processor's caches. The image is nearly complete by then, so the coarser
 * levels, which make it, keep their spread-out order. Those levels' rays also test their
 * tiles (retire()). */
static void start_order(ip_engine *e, uint32_t width, uint32_t height)
{
    ip__ray_order_init(&e->order, width, height);
    uint32_t last = ip__ray_order_last_level(&e->order);
    e->tile_from = last > LOCAL_LEVELS ? last - LOCAL_LEVELS : 0;
    ip__ray_order_set_local_from(&e->order, e->tile_from);
    e->block_phase = ip__ray_order_level_position(&e->order, e->tile_from) % BLOCK_CELLS;
}

/* Hands the reader (paused) the view and the order the workers are about to walk. */
static void begin_prefetch(ip_engine *e)
{
    if (!e->prefetcher)
        return;
    ip__prefetch_view view = {e->camera,       e->basis,
                              e->iso,          e->levels_used,
                              e->lod_distance, e->order,
                              e->order_cells,  &e->next_position,
                              &e->cancel,      {e->options.clip, e->options.clip_count},
                              e->region_x,     e->region_y};
    ip__prefetcher_begin(e->prefetcher, &view);
}

/* ip_share's give(): keeps a part of a propagation's queue for a worker without rays, and
 * wakes one. 0 when SHARED_MAX parts wait already. */
static int give_cells(void *user, uint32_t level, const ip_queued_cell *cells, unsigned count,
                      const double dir[3])
{
    ip_engine *e = user;
    pthread_mutex_lock(&e->share_lock);
    int room = e->shared_count < SHARED_MAX && count <= IP_SHARE_CELLS;
    if (room) {
        shared_cells *c = &e->shared[e->shared_count++];
        c->level = level;
        c->count = count;
        memcpy(c->dir, dir, sizeof c->dir);
        memcpy(c->cells, cells, count * sizeof *cells);
        pthread_cond_signal(&e->share_wake);
    }
    pthread_mutex_unlock(&e->share_lock);
    return room;
}

/* A worker whose step has no rays left for it propagates from the parts of queues other
 * workers hand out (give_cells()) until none is left and no worker may hand out more: the
 * step ends with every queued cell extracted, as when one worker propagated it all. */
static void help(ip_engine *e, worker *w)
{
    pthread_mutex_lock(&e->share_lock);
    e->working--;
    while (w->status == IP_OK) {
        if (e->shared_count > 0) {
            shared_cells c = e->shared[--e->shared_count];
            e->working++;
            pthread_mutex_unlock(&e->share_lock);
            w->status = ip__propagate_queued(&w->level[c.level].propagator, c.cells, c.count, c.dir,
                                             &w->counts);
            if (w->status != IP_OK)
                w->failed_level = c.level;
            pthread_mutex_lock(&e->share_lock);
            e->working--;
            continue;
        }
        if (e->working == 0)
            break;
        atomic_fetch_add(&e->hungry, 1);
        pthread_cond_wait(&e->share_wake, &e->share_lock);
        atomic_fetch_sub(&e->hungry, 1);
    }
    pthread_cond_broadcast(&e->share_wake); /* the others may wait for working to reach 0 */
    pthread_mutex_unlock(&e->share_lock);
}

/* One worker's share of the occlusion state to start over (a job of the engine's pool): its
 * part of the coverage buffer and of the tiles. */
static void clear_view(void *user, unsigned index)
{
    ip_engine *e = user;
    ip__coverage_clear(&e->coverage, index, e->threads);
    size_t tiles = (size_t)e->tiles_x * e->tiles_y;
    for (size_t t = tiles * index / e->threads; t < tiles * (index + 1) / e->threads; t++) {
        /* a tile no active brick shows in: settled with no bound (reach_view()) */
        atomic_init(&e->tiles[t].depth, e->reached[t] ? 0 : ip__float_bits(INFINITY));
        atomic_init(&e->tiles[t].from, 0);
        atomic_init(&e->tiles[t].tested, 0);
        atomic_init(&e->tiles[t].cells, 0);
    }
}

/* The tiles that some brick holding the isovalue (at a level the view uses) may show in
 * (ip__reach_tiles()). The others are settled from the start with no bound (clear_view()): no
 * ray of theirs can meet an active cell, so none is walked (cast_ray()) and no beam is tested
 * for them; and no triangle can show there, so the coverage keeps no entries for them
 * (ip__coverage_reach()): they are neither cleared nor, in a fresh process, touched at all. */
static void reach_view(ip_engine *e)
{
    ip__reach_tiles(ip_cache_store(e->cache), e->iso, e->levels_used, &e->basis, &e->camera,
                    TILE_SHIFT, e->tiles_x, e->tiles_y, e->reached);
    ip__coverage_reach(&e->coverage, e->reached, TILE_SHIFT, e->tiles_x);
}

ip_status ip_engine_begin(ip_engine *e, const ip_camera *camera, float iso, ip_error *err)
{
    ip_status st = ip_camera_check(camera, err);
    if (st != IP_OK)
        return st;
    if (!isfinite(iso))
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: the isovalue must be finite", path_of(e->cache));
    if (e->prefetcher) /* it reads the view about to change */
        ip__prefetcher_pause(e->prefetcher);
    ip__visited_clear(&e->visited);
    ip_mesh_clear(&e->mesh);
    e->shared_count = 0; /* what a cancelled or failed step left */
    e->camera = *camera;
    ip_camera_basis_of(&e->camera, &e->basis);
    e->iso = iso;
    memset(&e->totals, 0, sizeof e->totals);
    start_order(e, camera->width, camera->height);
    e->order_cells = ip__ray_order_cells(&e->order);
    e->ray_target = ip__ray_order_count(&e->order);
    e->region_x = e->region_y = 0;
    atomic_store(&e->next_position, 0);
    atomic_store(&e->rays_taken, 0);
    atomic_store(&e->cells_done, 0);
    e->leftover_count = 0;
    atomic_store(&e->leftovers_waiting, 0);
    set_lod_distances(e);
    const ip_layout *layout = ip_store_layout(ip_cache_store(e->cache));
    for (uint32_t k = 0; k < e->levels_used; k++) {
        e->cell_reach[k] = 0;
        for (int a = 0; a < 3; a++)
            e->cell_reach[k] += layout->spacing[a] * (double)(1u << k) * fabs(e->basis.forward[a]);
    }
    if (e->options.occlusion) {
        double lo[3], hi[3];
        ip_layout_world_box(layout, lo, hi);
        e->tiles_x = (camera->width + (1u << TILE_SHIFT) - 1) >> TILE_SHIFT;
        e->tiles_y = (camera->height + (1u << TILE_SHIFT) - 1) >> TILE_SHIFT;
        size_t tiles = (size_t)e->tiles_x * e->tiles_y;
        if (tiles > e->tile_capacity) {
            free(e->tiles);
            free(e->reached);
            e->tiles = malloc(tiles * sizeof *e->tiles);
            e->reached = malloc(tiles);
            e->tile_capacity = e->tiles && e->reached ? tiles : 0;
        }
        if (!e->tile_capacity || ip__coverage_prepare(&e->coverage, camera, lo, hi) != IP_OK)
            return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", path_of(e->cache));
        reach_view(e);
        ip__pool_run(e->pool, e->threads, clear_view, e);
    }
    double pixel_angle = 2.0 * e->basis.tan_half_y / camera->height;
    for (unsigned t = 0; t < e->threads; t++) {
        worker *w = &e->workers[t];
        ip_mesh_clear(&w->mesh);
        w->order = e->order;
        w->holding = 0;
        for (uint32_t k = 0; k < e->levels_used; k++) {
            level_tools *lt = &w->level[k];
            if (!lt->ready) {
                if (ip__sampler_init(&lt->sampler, e->cache, k) != IP_OK)
                    return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", path_of(e->cache));
                lt->ready = 1;
            }
            ip__sampler_release(&lt->sampler);
            lt->sampler.status = IP_OK;
            ip__seeder_init(&lt->seeder, &lt->sampler, iso, pixel_angle);
            lt->seeder.clip = (ip_clip){e->options.clip, e->options.clip_count};
            ip__propagator_free(&lt->propagator);
            if (ip__propagator_init(&lt->propagator, &lt->sampler, &e->visited, &w->mesh,
                                    &e->camera, iso, &e->options, e->lod_distance[k],
                                    e->lod_distance[k + 1],
                                    e->options.occlusion ? &e->coverage : NULL) != IP_OK)
                return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", path_of(e->cache));
            if (e->threads > 1)
                lt->propagator.share = (ip_share){&e->hungry, give_cells, e};
        }
    }
    atomic_store(&e->cancel, 0);
    e->begun = 1;
    begin_prefetch(e);
    return IP_OK;
}

ip_status ip_engine_set_region(ip_engine *e, uint32_t x, uint32_t y, uint32_t width,
                               uint32_t height, uint64_t first_ray, uint64_t ray_count,
                               ip_error *err)
{
    if (!e->begun)
        return ip__fail(err, IP_ERR_ARGUMENT, "ip_engine_set_region() before ip_engine_begin()");
    if (width == 0 || height == 0 || x >= e->camera.width || y >= e->camera.height ||
        width > e->camera.width - x || height > e->camera.height - y)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "region %ux%u at (%u, %u) is not a non-empty part of the %ux%u image",
                        width, height, x, y, e->camera.width, e->camera.height);
    uint64_t pixels = (uint64_t)width * height;
    if (first_ray > pixels || ray_count > pixels - first_ray)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "rays %llu + %llu are more than the region's %llu pixels",
                        (unsigned long long)first_ray, (unsigned long long)ray_count,
                        (unsigned long long)pixels);
    if (e->prefetcher) /* it reads the order about to change */
        ip__prefetcher_pause(e->prefetcher);
    start_order(e, width, height);
    /* the positions of rays [first_ray, first_ray + ray_count) of the region's order */
    ip_ray_order walk = e->order;
    uint32_t px, py;
    for (uint64_t i = 0; i < first_ray; i++)
        ip__ray_order_next(&walk, &px, &py);
    uint64_t start = ip__ray_order_position(&walk);
    for (uint64_t i = 0; i < ray_count; i++)
        ip__ray_order_next(&walk, &px, &py);
    e->order_cells = ray_count > 0 ? ip__ray_order_position(&walk) : start;
    e->ray_target = ray_count;
    e->region_x = x;
    e->region_y = y;
    atomic_store(&e->next_position, start);
    atomic_store(&e->rays_taken, 0);
    pthread_mutex_lock(&e->leftover_lock);
    e->leftover_count = 0;
    atomic_store(&e->leftovers_waiting, 0);
    pthread_mutex_unlock(&e->leftover_lock);
    for (unsigned t = 0; t < e->threads; t++) {
        e->workers[t].order = e->order;
        e->workers[t].holding = 0;
        for (uint32_t k = 0; k < e->levels_used; k++) { /* propagate within the rectangle */
            double *window = e->workers[t].level[k].propagator.window;
            window[0] = x;
            window[1] = y;
            window[2] = (double)x + width;
            window[3] = (double)y + height;
        }
    }
    begin_prefetch(e);
    return IP_OK;
}

void ip_engine_cancel(ip_engine *e)
{
    atomic_store(&e->cancel, 1);
}

int ip_engine_done(const ip_engine *e)
{
    return e->begun && atomic_load(&((ip_engine *)e)->rays_taken) == e->ray_target;
}

static void add_counts(ip_engine_counts *to, const ip_engine_counts *from)
{
    to->rays += from->rays;
    to->seeds += from->seeds;
    to->cells += from->cells;
    to->triangles += from->triangles;
    to->intersection_seconds += from->intersection_seconds;
    to->propagation_seconds += from->propagation_seconds;
    to->extraction_seconds += from->extraction_seconds;
    to->rendering_seconds += from->rendering_seconds;
    to->deferred += from->deferred;
    to->retired += from->retired;
    to->nodes += from->nodes;
}

/* Extracts one cell without propagating from it. */
static ip_status extract_one(worker *w, level_tools *lt, const uint32_t cell[3])
{
    unsigned mc;
    ip_status st = IP_OK;
    double t0 = ip_now_seconds();
    int n = ip__extract_cell(&lt->sampler, &w->mesh, cell, w->engine->iso, &mc, &st);
    w->counts.extraction_seconds += ip_now_seconds() - t0;
    if (n < 0)
        return st;
    w->counts.cells++;
    w->counts.triangles += (uint64_t)n;
    return IP_OK;
}

/* The view depth (world units) beyond which no cell can show at pixel (x, y) any more: the
 * solid coverage entry (coverage.h) widened by DEPTH_MARGIN; +infinity without occlusion or
 * where nothing covers the pixel solidly yet. */
static double stop_depth(const ip_engine *e, uint32_t x, uint32_t y)
{
    if (!e->options.occlusion)
        return INFINITY;
    return ip__coverage_solid(&e->coverage, x, y) / (1.0 - DEPTH_MARGIN);
}

/* Casts the ray of pixel (x, y), one distance band (pyramid level) after the other, front to
 * back: extracts its seed, and the cells it nearly hit before it, propagating from each that
 * was not extracted yet.
 *
 * With occlusion the walk stops where the solid coverage entry of the pixel (coverage.h) says
 * nothing further can show: at t = (z + reach) / cos, z the entry widened by DEPTH_MARGIN,
 * reach a cell's extent along the view, cos the cosine between the ray and the view. Why the
 * image stays exact. The entry z means: an extracted triangle T, kept in the mesh, holds the
 * pixel centre by IP_COVERAGE_SOLID_MARGIN (1/128 pixel) or more from each of its edges and
 * has its vertices no deeper than z. The rasterizer moves a vertex by at most sqrt(2) / 512
 * pixel (0.0028) when it snaps it, and an affine map moving the corners of T that little
 * moves no point of T more, so T still holds the centre after snapping (the disc of the
 * margin around it lies in T, the snapped disc's boundary stays within 0.0028 pixel of the
 * circle, so it still winds around the centre: any margin above 0.0028 pixel would do, and
 * 1/128 is 2.8 times that); the depth it is drawn with
 * there interpolates 1 / depth between its vertices, so is at most z. A cell the walk enters
 * at t holds the ray's point at view depth t * cos, so its box reaches no nearer than
 * t * cos - reach; a cell entered beyond the stop has its box, and so every vertex of its
 * triangles, deeper than the entry by more than the margin (which covers the rounding of
 * vertices to floats), and any of its triangles is drawn at the pixel, if at all, deeper than
 * T, which beats it in either mesh. Nothing there can be the full extraction's triangle at this
 * pixel, nor change the extracted mesh's image there. The walk is otherwise the same: the
 * cells of a ray are entered front to back (the boxes of disjoint nodes cut disjoint spans of
 * the ray), so the shortened walk meets exactly the cells of the full walk up to the stop, in
 * the same order, and extracts the same ones of them, near misses (the cells it passes within
 * 1/64 pixel of a triangle edge, extracted alone) and seed alike. Rays may then find nothing
 * where they would have found a hidden seed; propagation from such a seed only ever saved other
 * rays work. Entries only decrease and each is backed by a triangle already in a worker's mesh,
 * so a stale read only stops the walk later. The edge of the solid margin matters: the plain
 * coverage entry also counts centres on a triangle's edge, where snapping may uncover a
 * silhouette and show the surface behind, which this ray must then still find.
 *
 * The walk starts at view depth `from` (t = from / cos), where its tile's beam was found
 * settled short of it (test_tile()): every active cell the ray could enter before is extracted
 * already, and would only end the walk there (a cell hit squarely) or be passed over. Walking
 * on from `from` then finds what the full walk finds past it and at most more cells behind an
 * extracted one, all of the true surface: each is extracted or propagated from as a walk would
 * (the image stays exact: a pixel's own first-hit cell is either extracted already or found). */
static ip_status cast_ray(worker *w, uint32_t x, uint32_t y, double from)
{
    ip_engine *e = w->engine;
    double dir[3];
    uint32_t cells[IP_SEED_MAX_CELLS][3];
    w->counts.rays++;
    if (e->options.occlusion &&
        !e->reached[(size_t)(y >> TILE_SHIFT) * e->tiles_x + (x >> TILE_SHIFT)])
        return IP_OK; /* no active brick shows in its tile (reach_view()): nothing to find */
    ip_camera_pixel_ray(&e->basis, &e->camera, x + 0.5, y + 0.5, dir);
    double z = stop_depth(e, x, y), cos = ip__vec3_dot(dir, e->basis.forward);
    for (uint32_t k = 0; k < e->levels_used; k++) {
        level_tools *lt = &w->level[k];
        unsigned count;
        int seed_index;
        double t_max = e->lod_distance[k + 1], stop = (z + e->cell_reach[k]) / cos;
        t_max = stop < t_max ? stop : t_max;
        if (t_max < e->lod_distance[k])
            return IP_OK;
        double t_min = from / cos > e->lod_distance[k] ? from / cos : e->lod_distance[k];
        if (t_min > t_max)
            continue;
        uint64_t nodes = lt->seeder.nodes;
        int found = ip__seed_find(&lt->seeder, e->camera.eye, dir, t_min, t_max, cells, &count,
                                  &seed_index);
        w->counts.nodes += lt->seeder.nodes - nodes;
        if (found < 0) {
            w->failed_level = k;
            return lt->sampler.status;
        }
        for (unsigned i = 0; i < count; i++) {
            int was = ip__visited_mark(&e->visited, k, cells[i]);
            if (was < 0)
                return IP_ERR_NOMEM;
            if (was)
                continue;
            ip_status st;
            if ((int)i == seed_index) { /* the seed: propagate from it */
                w->counts.seeds++;
                st = ip__propagate(&lt->propagator, cells[i], dir, &w->counts);
            } else { /* a rounding case: its own triangles only, for the pixel's sake */
                st = extract_one(w, lt, cells[i]);
            }
            if (st != IP_OK) {
                w->failed_level = k;
                return st;
            }
        }
        if (found)
            return IP_OK;
    }
    return IP_OK;
}

/* The tile of image pixel (x, y). */
static tile *pixel_tile(ip_engine *e, uint32_t x, uint32_t y)
{
    return &e->tiles[(size_t)(y >> TILE_SHIFT) * e->tiles_x + (x >> TILE_SHIFT)];
}

/* Raises a tile's bound `bound` to `bits` (a float's bits): either bound holds. */
static void raise_bound(atomic_uint *bound, unsigned bits)
{
    unsigned old = atomic_load_explicit(bound, memory_order_relaxed);
    while (bits > old && !atomic_compare_exchange_weak_explicit(
                             bound, &old, bits, memory_order_relaxed, memory_order_relaxed))
        ;
}

/* The bits of the largest float no larger than v * (1 - 1e-12) (v > 0), else 0. */
static unsigned float_below(double v)
{
    v *= 1.0 - 1e-12;
    float f = (float)v;
    f = (double)f > v ? nextafterf(f, 0.0f) : f;
    return f > 0 ? ip__float_bits(f) : 0;
}

/* Tests tile (tx, ty): which of its rays can still extract something. Let D be the deepest
 * solid coverage entry (coverage.h) among its pixels, +infinity when none is covered solidly
 * (a tile outside the surface's image, whose rays must then find nothing anywhere). The beam of
 * its pixel centres (widened by TILE_SLACK) is tested against the octree down to the cells, at
 * every level, up to D's stop (cast_ray()) plus a cell's reach along the view
 * (ip__beam_settled()). Where every active cell there is extracted, the rays of the tile whose
 * solid entry is no deeper than D would find only extracted cells, now or later (entries only
 * decrease and cells stay extracted), and do nothing: their walks can be left out (the tile's
 * `depth` is raised to D), and the mesh is the one the walks would leave. Where some may not
 * be, the test learns the depth short of which the beam is settled: the rays whose stop lies
 * short of it are left out in the same way (a lower `depth`), and the tile's other rays need
 * not look short of it (its `from`): the cells there are extracted or inactive. */
static void test_tile(worker *w, uint32_t tx, uint32_t ty, tile *t)
{
    ip_engine *e = w->engine;
    uint32_t x0 = tx << TILE_SHIFT, y0 = ty << TILE_SHIFT;
    uint32_t x1 = x0 + (1u << TILE_SHIFT), y1 = y0 + (1u << TILE_SHIFT);
    x1 = x1 < e->camera.width ? x1 : e->camera.width;
    y1 = y1 < e->camera.height ? y1 : e->camera.height;
    double deepest = 0; /* over the pixels covered solidly; +infinity when none is */
    for (uint32_t y = y0; y < y1; y++)
        for (uint32_t x = x0; x < x1; x++) {
            double z = ip__coverage_solid(&e->coverage, x, y);
            deepest = z < INFINITY && z > deepest ? z : deepest;
        }
    deepest = deepest > 0 ? deepest : INFINITY;
    double stop = deepest / (1.0 - DEPTH_MARGIN); /* as stop_depth() */
    double corner[4][3];
    double cx[4] = {x0 + 0.5 - TILE_SLACK, x1 - 0.5 + TILE_SLACK, x1 - 0.5 + TILE_SLACK,
                    x0 + 0.5 - TILE_SLACK};
    double cy[4] = {y0 + 0.5 - TILE_SLACK, y0 + 0.5 - TILE_SLACK, y1 - 0.5 + TILE_SLACK,
                    y1 - 0.5 + TILE_SLACK};
    for (int i = 0; i < 4; i++)
        ip_camera_pixel_ray(&e->basis, &e->camera, cx[i], cy[i], corner[i]);
    int whole = 1;
    double from = INFINITY; /* every level's beam is settled short of it */
    /* what an earlier test found settled stays so: the beam need not look there again */
    double known = ip__float_of_bits(atomic_load_explicit(&t->from, memory_order_relaxed));
    for (uint32_t k = 0; k < e->levels_used; k++) {
        ip_beam beam;
        double to;
        ip__beam_init(&beam, e->camera.eye, e->basis.forward, corner, stop + e->cell_reach[k]);
        beam.min_depth = known;
        if (!ip__beam_settled(&w->level[k].seeder, &e->visited, &beam, &to)) {
            whole = 0;
            stop = to - e->cell_reach[k] < stop ? to - e->cell_reach[k] : stop;
        }
        from = to < from ? to : from;
    }
    raise_bound(&t->depth, whole ? ip__float_bits((float)deepest) /* exact */
                                 : float_below(stop * (1.0 - DEPTH_MARGIN)));
    if (from < INFINITY)
        raise_bound(&t->from, float_below(from));
}

/* 1 when the ray of image pixel (x, y) is retired by its tile as it stands: its solid entry is
 * no deeper than the depth its tile was found settled at (`settled`, a float's bits). A tile
 * settled with no bound (+infinity) retires every ray, and the coverage is not read. */
static int pixel_settled(const ip_engine *e, uint32_t x, uint32_t y, unsigned settled)
{
    if (settled == ip__float_bits(INFINITY))
        return 1;
    float z = (float)ip__coverage_solid(&e->coverage, x, y); /* a float's value: exact */
    return z <= ip__float_of_bits(settled);
}

/* 1 when the ray of image pixel (x, y), of the order's Z-order level `level`, is retired by
 * its tile: its solid coverage entry is no deeper than one its tile was found settled at
 * (test_tile()), +infinity included. A tile is tested by the first ray of the Z-order levels
 * (ray_order.h) that it does not retire, and again by the first such ray of a later level once
 * the cells extracted have grown by RETEST_GROWTH since; what it was found settled at stays so.
 * (Testing it again in every level changed a bound in 1 test of 6 on the head, whose surface
 * is 99.6 % final by the first Z-order level, and retired few more rays: it cost more than the
 * walks it saved. Where the first test comes before the surface is, the next level's finds
 * it.) Otherwise 0, with *from the view depth short of which the ray can find nothing new (0
 * when none is known). Counts nothing. */
static int tile_retires(worker *w, uint32_t x, uint32_t y, uint32_t level, double *from)
{
    ip_engine *e = w->engine;
    tile *t = pixel_tile(e, x, y);
    if (pixel_settled(e, x, y, atomic_load_explicit(&t->depth, memory_order_relaxed)))
        return 1;
    unsigned char pass = (unsigned char)(level - e->tile_from + 1), was;
    unsigned cells = atomic_load_explicit(&e->cells_done, memory_order_relaxed);
    if ((was = atomic_load_explicit(&t->tested, memory_order_relaxed)) < pass &&
        (was == 0 ||
         cells > atomic_load_explicit(&t->cells, memory_order_relaxed) * (1.0 + RETEST_GROWTH))) {
        atomic_store_explicit(&t->tested, pass, memory_order_relaxed);
        atomic_store_explicit(&t->cells, cells, memory_order_relaxed);
        test_tile(w, x >> TILE_SHIFT, y >> TILE_SHIFT, t);
        if (pixel_settled(e, x, y, atomic_load_explicit(&t->depth, memory_order_relaxed)))
            return 1;
    }
    *from = ip__float_of_bits(atomic_load_explicit(&t->from, memory_order_relaxed));
    return 0;
}

/* 1 when ray r may be retired without a walk (counted): tile_retires(), in the Z-order
 * levels, with occlusion. Otherwise 0, with *from where its walk may start (0: at the eye). */
static int retire(worker *w, const order_ray *r, double *from)
{
    ip_engine *e = w->engine;
    *from = r->tested ? r->from : 0;
    if (r->tested || !e->options.occlusion || r->level < e->tile_from ||
        !tile_retires(w, r->x, r->y, r->level, from))
        return 0;
    w->counts.rays++;
    w->counts.retired++;
    return 1;
}

#define RETIRED_PER_BATCH 4096             /* rays of blocks a batch may retire at once, at most */
#define RAY_ROOM (RAY_BATCH + BLOCK_CELLS) /* a batch's rays, a block's overfill included */

/* Takes `rays` of the step's budget when the step has one; 0 when it has fewer left. */
static int take_budget(ip_engine *e, uint64_t rays)
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

/* When the worker's iterator stands at such a block, within its range: the block's pixels
 * whose tile retires them (tile_retires(), which tests a tile where retire() would: at its
 * first ray that it does not retire) are counted as retired, their number in
 * *count, and the others, when there are at most `space`, go to rays[0 .. *walk), to be
 * walked; the iterator moves past the block, and 1 is returned. The step's budget pays for the
 * retired rays and those to walk beyond `share` (the batch's share of it left). 0, and nothing
 * done but tests of tiles, where the iterator stands at no such block, more than `space`
 * pixels are left, or the budget cannot pay. */
static int take_block(ip_engine *e, worker *w, order_ray *rays, unsigned space, unsigned share,
                      unsigned *count, unsigned *walk)
{
    if (!e->options.occlusion || ip__ray_order_position(&w->order) + BLOCK_CELLS > w->range_end)
        return 0;
    uint32_t xs[BLOCK_CELLS], ys[BLOCK_CELLS];
    unsigned n, left = 0;
    if (!ip__ray_order_block(&w->order, BLOCK_LOG4, xs, ys, &n)) /* only in tile_from on */
        return 0;
    uint32_t level = ip__ray_order_level(&w->order);
    for (unsigned i = 0; i < n; i++) {
        uint32_t x = xs[i] + e->region_x, y = ys[i] + e->region_y;
        double from;
        if (tile_retires(w, x, y, level, &from))
            continue;
        if (left == space)
            return 0;
        rays[left++] = (order_ray){x, y, level, 1, from};
    }
    if (!take_budget(e, n - left + (left > share ? left - share : 0)))
        return 0;
    ip__ray_order_skip_block(&w->order, BLOCK_LOG4, n);
    w->counts.rays += n - left;
    w->counts.retired += n - left;
    *count = n - left;
    *walk = left;
    return 1;
}

/* Gives the worker a range of the order to walk: the earliest one left unfinished by a step,
 * else the next unclaimed one. Ranges start small, so that the first rays (the coarsest levels)
 * keep their order closely, and grow with the position to at most RANGE_MAX. Returns 0 once
 * every position has been claimed. */
static int claim_range(ip_engine *e, worker *w)
{
    if (atomic_load(&e->leftovers_waiting) > 0) {
        pthread_mutex_lock(&e->leftover_lock);
        unsigned first = 0;
        for (unsigned i = 1; i < e->leftover_count; i++)
            if (e->leftovers[i].start < e->leftovers[first].start)
                first = i;
        int found = e->leftover_count > 0;
        if (found) {
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
                                      blocks (take_block()) */
            length +=
                (BLOCK_CELLS - (start + length + BLOCK_CELLS - e->block_phase) % BLOCK_CELLS) %
                BLOCK_CELLS;
    } while (!atomic_compare_exchange_weak(&e->next_position, &start, start + length));
    ip__ray_order_seek(&w->order, start);
    w->range_end = e->order_cells - start < length ? e->order_cells : start + length;
    return w->holding = 1;
}

/* Hands the unwalked rest of the worker's range back for a later step. */
static void leave_range(ip_engine *e, worker *w)
{
    uint64_t position = ip__ray_order_position(&w->order);
    if (w->holding && position < w->range_end) {
        pthread_mutex_lock(&e->leftover_lock);
        e->leftovers[e->leftover_count++] = (order_range){position, w->range_end};
        atomic_store(&e->leftovers_waiting, e->leftover_count);
        pthread_mutex_unlock(&e->leftover_lock);
    }
    w->holding = 0;
}

/* Takes up to RAY_BATCH pixels of the order for this step from the worker's ranges (up to
 * RAY_ROOM when the rays of a block overfill it): those to walk or retire one by one into
 * rays[0 .. *count), and the rays of blocks retired at once; returns how many pixels in all
 * (0: none left for this step). */
static uint64_t take_rays(ip_engine *e, worker *w, order_ray *rays, unsigned *count)
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
        if (take_block(e, w, rays + n, RAY_ROOM - n, (unsigned)(want - n), &block, &walk)) {
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
    if (e->step_limited && n < want) /* the order ran out: give the rest of the share back */
        atomic_fetch_add(&e->step_rays_left, want - n);
    atomic_fetch_add(&e->rays_taken, n + retired);
    *count = n;
    return n + retired;
}

/* Moves the worker's triangles to the engine's mesh. */
static ip_status flush_triangles(worker *w)
{
    ip_engine *e = w->engine;
    pthread_mutex_lock(&e->mesh_lock);
    ip_status st = ip_mesh_append_mesh(&e->mesh, &w->mesh, 0, w->mesh.triangle_count);
    pthread_mutex_unlock(&e->mesh_lock);
    ip_mesh_clear(&w->mesh);
    return st;
}

/* Adds the cells the worker extracted since *published (of its step's counts) to the engine's
 * cells_done, which decides when tiles are tested again (tile_retires()). */
static void publish_cells(ip_engine *e, const worker *w, uint64_t *published)
{
    if (w->counts.cells != *published)
        atomic_fetch_add_explicit(&e->cells_done, (unsigned)(w->counts.cells - *published),
                                  memory_order_relaxed);
    *published = w->counts.cells;
}

/* One worker's share of a step (a job of the engine's pool): batches of rays until the step's
 * budget, the order or the time runs out, or a worker fails. */
static void work(void *user, unsigned index)
{
    ip_engine *e = user;
    worker *w = &e->workers[index];
    order_ray rays[RAY_ROOM];
    unsigned n;
    uint64_t published = 0; /* of w->counts.cells, in e->cells_done */
    while (w->status == IP_OK && take_rays(e, w, rays, &n) > 0) {
        /* The clock is read once per batch: seeding is the batch's time less what
         * propagation and extraction measured of it. */
        double t0 = ip_now_seconds();
        double inner = w->counts.propagation_seconds + w->counts.extraction_seconds;
        for (unsigned i = 0; i < n && w->status == IP_OK; i++) {
            if (atomic_load_explicit(&e->cancel, memory_order_relaxed)) {
                w->status = IP_ERR_CANCELLED;
                break;
            }
            double from;
            if (!retire(w, &rays[i], &from))
                w->status = cast_ray(w, rays[i].x, rays[i].y, from);
        }
        double seeding = ip_now_seconds() - t0 -
                         (w->counts.propagation_seconds + w->counts.extraction_seconds - inner);
        w->counts.intersection_seconds += seeding > 0 ? seeding : 0;
        publish_cells(e, w, &published);
        if (w->mesh.triangle_count >= FLUSH_TRIANGLES && flush_triangles(w) != IP_OK &&
            w->status == IP_OK)
            w->status = IP_ERR_NOMEM;
    }
    help(e, w);
    publish_cells(e, w, &published);
    if (flush_triangles(w) != IP_OK && w->status == IP_OK)
        w->status = IP_ERR_NOMEM;
    if (w->status != IP_OK) /* the step fails: the other workers take no more rays */
        atomic_store(&e->step_stopped, 1);
    leave_range(e, w);
    for (uint32_t k = 0; k < e->levels_used; k++) /* let the cache evict freely between steps */
        ip__sampler_release(&w->level[k].sampler);
}

ip_status ip_engine_step(ip_engine *e, uint64_t max_rays, double max_seconds,
                         ip_engine_counts *counts, ip_error *err)
{
    if (!e->begun)
        return ip__fail(err, IP_ERR_ARGUMENT, "ip_engine_step() before ip_engine_begin()");
    if (atomic_load(&e->cancel))
        return ip__fail(err, IP_ERR_CANCELLED, "%s: extraction cancelled", path_of(e->cache));
    e->step_limited = max_rays != 0;
    atomic_store(&e->step_rays_left, max_rays);
    atomic_store(&e->step_stopped, 0);
    e->step_deadline = max_seconds > 0 ? ip_now_seconds() + max_seconds : 0;
    /* A small step shares its rays between the threads (each ray may propagate a large part
     * of the surface): a batch of ceil(rays / threads), one thread per ray at most. Every
     * worker runs: those left without rays help the others' propagations (help()). */
    unsigned threads = e->threads, batch_threads = threads;
    e->step_batch = RAY_BATCH;
    if (max_rays && max_rays < (uint64_t)threads * RAY_BATCH) {
        batch_threads = max_rays < threads ? (unsigned)max_rays : threads;
        e->step_batch = (unsigned)((max_rays + batch_threads - 1) / batch_threads);
    }
    e->working = threads;
    for (unsigned t = 0; t < threads; t++) {
        worker *w = &e->workers[t];
        memset(&w->counts, 0, sizeof w->counts);
        w->status = IP_OK;
        w->mesh.triangle_count = 0;
    }
    if (e->prefetcher) /* it keeps reading ahead between steps */
        ip__prefetcher_resume(e->prefetcher);
    ip__pool_run(e->pool, threads, work, e);
    ip_engine_counts c;
    memset(&c, 0, sizeof c);
    ip_status st = IP_OK;
    for (unsigned t = 0; t < threads; t++) {
        worker *w = &e->workers[t];
        add_counts(&c, &w->counts);
        if (st == IP_OK && w->status != IP_OK) {
            st = w->status;
            if (st == IP_ERR_CANCELLED)
                ip__fail(err, st, "%s: extraction cancelled", path_of(e->cache));
            else if (st == IP_ERR_NOMEM)
                ip__fail(err, st, "%s: out of memory", path_of(e->cache));
            else if (err)
                *err = w->level[w->failed_level].sampler.error;
        }
    }
    add_counts(&e->totals, &c);
    if (counts)
        *counts = c;
    return st;
}

const ip_mesh *ip_engine_mesh(const ip_engine *e)
{
    return &e->mesh;
}

void ip_engine_totals(const ip_engine *e, ip_engine_counts *counts)
{
    *counts = e->totals;
}

void ip_engine_add_rendering_time(ip_engine *e, double seconds)
{
    e->totals.rendering_seconds += seconds;
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* The progressive engine: its life, views and regions, and steps run by the workers on the pool
 * (the ray hand-out, a ray's walk, bulk retirement and shared propagation have files of their
 * own: engine_state.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "engine_state.h"
#include "internal.h"
#include "lod.h"
#include "reach.h"
#include "sized.h"
#include "vec3.h"

#define LOCAL_LEVELS 3        /* ray order: the finest levels cast in Z-order (start_order()) */
#define FLUSH_TRIANGLES 16384 /* a worker's buffer moves to the engine's mesh past this size */

void ip_engine_options_default(ip_engine_options *o)
{
    memset(o, 0, sizeof *o);
    o->size = sizeof *o;
    o->cutoff_degrees = IP_DEFAULT_CUTOFF_DEGREES;
    o->foldback_degrees = IP_DEFAULT_FOLDBACK_DEGREES;
    o->threads = 0;
    o->lod = 1;
    o->pixel_error = 1.0;
    o->cell_ids = 0;
    o->occlusion = 1;
    o->prefetch = IP_PREFETCH_ON;
    o->cull = 1;
    o->clip_count = 0;
    o->reuse = 0;
}

/* The brick file an engine extracts from, which its messages name. */
static const char *path_of(const ip_cache *cache)
{
    return ip_store_path(ip_cache_store(cache));
}

ip_status ip_engine_create(ip_cache *cache, const ip_engine_options *given, ip_engine **out,
                           ip_error *err)
{
    ip_engine_options taken;
    ip_engine_options_default(&taken);
    ip_status st = ip__sized_in(&taken, sizeof taken, given,
                                IP__SIZE_UPTO(ip_engine_options, reuse), "engine options", err);
    if (st != IP_OK)
        return st;
    const ip_engine_options *options = &taken;
    if (!(options->cutoff_degrees > 0 && options->cutoff_degrees <= 180) ||
        !(options->foldback_degrees >= 0 && options->foldback_degrees <= 180))
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "cut-off %g and fold-back %g must be in degrees, "
                        "0 < cut-off <= 180, 0 <= fold-back <= 180",
                        options->cutoff_degrees, options->foldback_degrees);
    if (options->lod && !(options->pixel_error > 0 && isfinite(options->pixel_error)))
        return ip__fail(err, IP_ERR_ARGUMENT, "the pixel error %g must be positive",
                        options->pixel_error);
    if (options->prefetch < IP_PREFETCH_OFF || options->prefetch > IP_PREFETCH_ALWAYS)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "prefetch %d: must be IP_PREFETCH_OFF, IP_PREFETCH_ON or "
                        "IP_PREFETCH_ALWAYS (0, 1, 2)",
                        options->prefetch);
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
    atomic_init(&e->ahead_claimed, 0);
    atomic_init(&e->rays_taken, 0);
    atomic_init(&e->leftovers_waiting, 0);
    atomic_init(&e->step_rays_left, 0);
    atomic_init(&e->step_stopped, 0);
    pthread_mutex_init(&e->leftover_lock, NULL);
    pthread_mutex_init(&e->mesh_lock, NULL);
    pthread_mutex_init(&e->share_lock, NULL);
    pthread_cond_init(&e->share_wake, NULL);
    atomic_init(&e->hungry, 0);
    atomic_init(&e->share_news, 0);
    ip_mesh_init(&e->mesh);
    e->mesh.with_cells = options->cell_ids != 0 || options->reuse != 0;
    e->workers = calloc(e->threads, sizeof *e->workers);
    e->leftovers = calloc(e->threads, sizeof *e->leftovers);
    e->shared = malloc(SHARED_MAX * sizeof *e->shared);
    st = e->workers && e->leftovers && e->shared
             ? ip__visited_init(&e->visited, ip_store_layout(ip_cache_store(cache)))
             : IP_ERR_NOMEM;
    if (st == IP_OK)
        st = ip__pool_create(e->threads, &e->pool, NULL);
    /* IP_PREFETCH_ON: the reader leaves the bricks already in memory to the workers when they
     * have every core (ip__prefetcher_create()) */
    if (st == IP_OK && options->prefetch != IP_PREFETCH_OFF)
        st = ip__prefetcher_create(
            cache, options->prefetch == IP_PREFETCH_ON && e->threads >= ip_thread_count(0),
            &e->prefetcher);
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
            ip_level_tools *lt = &e->workers[t].level[k];
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

/* The distance bands of the view's levels (lod.h). */
static void set_lod_distances(ip_engine *e)
{
    const ip_layout *l = ip_store_layout(ip_cache_store(e->cache));
    e->levels_used =
        ip__lod_distances(l, &e->camera, e->options.lod, e->options.pixel_error, e->lod_distance);
}

double ip_engine_lod_distance(const ip_engine *e, uint32_t level)
{
    return level < e->levels_used ? e->lod_distance[level] : INFINITY;
}

/* The ray order of a width x height image (the view's, or a region's), from its first pixel.
 * The finest levels (cells of at most 2^LOCAL_LEVELS pixels a side, most of the rays) are
 * cast in Z-order: consecutive rays then cross the same bricks and sub-blocks while they are
 * still in the processor's caches, and every other one is walked backward, so that a level
 * starts on the bricks the one before ended on (ray_order.h; on the head upsampled 4x with a
 * 256 MiB cache, half the brick cache's misses of a view). The image is nearly complete by
 * then, so the coarser
 * levels, which make it, keep their spread-out order. Those levels' rays also test their
 * tiles (ip__engine_retire()). */
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
    ip__prefetch_view view = {e->camera,
                              e->basis,
                              e->iso,
                              e->levels_used,
                              e->lod_distance,
                              e->band_widening,
                              e->order,
                              e->order_cells,
                              &e->next_position,
                              &e->cancel,
                              {e->options.clip, e->options.clip_count},
                              e->region_x,
                              e->region_y,
                              0};
    ip__prefetcher_begin(e->prefetcher, &view);
}

ip_status ip_engine_read_ahead(ip_engine *e, const ip_camera *camera, ip_error *err)
{
    ip_status st = ip_camera_check(camera, err);
    if (st != IP_OK)
        return st;
    if (!e->begun || !ip_engine_done(e))
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "ip_engine_read_ahead(): the engine's view is not done yet");
    if (!e->prefetcher)
        return IP_OK;
    /* the predicted view's bands and order, as ip_engine_begin() would set them */
    const ip_layout *layout = ip_store_layout(ip_cache_store(e->cache));
    double distance[IP_MAX_LEVELS + 1], widening[IP_MAX_LEVELS];
    uint32_t levels =
        ip__lod_distances(layout, camera, e->options.lod, e->options.pixel_error, distance);
    for (uint32_t k = 0; k < levels; k++)
        widening[k] = ip__lod_band_widening(layout, k, levels);
    ip_ray_order order; /* as start_order() makes it */
    ip__ray_order_init(&order, camera->width, camera->height);
    uint32_t last = ip__ray_order_last_level(&order);
    ip__ray_order_set_local_from(&order, last > LOCAL_LEVELS ? last - LOCAL_LEVELS : 0);
    ip_camera_basis basis;
    ip_camera_basis_of(camera, &basis);
    atomic_store(&e->ahead_claimed, 0); /* no worker walks it: the reader plans its first rays */
    ip__prefetch_view view = {*camera,
                              basis,
                              e->iso,
                              levels,
                              distance,
                              widening,
                              order,
                              ip__ray_order_cells(&order),
                              &e->ahead_claimed,
                              &e->cancel,
                              {e->options.clip, e->options.clip_count},
                              0,
                              0,
                              1}; /* the workers are idle: every planned brick */
    ip__prefetcher_pause(e->prefetcher);
    ip__prefetcher_begin(e->prefetcher, &view);
    ip__prefetcher_resume(e->prefetcher);
    return IP_OK;
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
 * (ip__reach_tiles()). The others are settled from the start with no bound (clear_view()): no ray
 * of theirs can meet an active cell, so none is walked (ip__engine_retire()) and no beam is
 * tested for them; and no triangle can show there, so the coverage keeps no entries for them
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
    /* the view before's mesh stays for reuse (reuse.c) until the new view is set up */
    int keep = e->options.reuse && e->options.occlusion && e->begun && e->reusable &&
               iso == e->iso && e->mesh.with_cells;
    e->reusable = 0;
    ip__visited_clear(&e->visited);
    if (!keep)
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
        e->band_widening[k] = ip__lod_band_widening(layout, k, e->levels_used);
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
        ip_engine_worker *w = &e->workers[t];
        ip_mesh_clear(&w->mesh);
        w->order = e->order;
        w->holding = 0;
        for (uint32_t k = 0; k < e->levels_used; k++) {
            ip_level_tools *lt = &w->level[k];
            if (!lt->ready) {
                if (ip__sampler_init(&lt->sampler, e->cache, k) != IP_OK)
                    return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", path_of(e->cache));
                lt->ready = 1;
            }
            ip__sampler_release(&lt->sampler);
            lt->sampler.status = IP_OK;
            ip__seeder_init(&lt->seeder, &lt->sampler, iso, pixel_angle);
            ip__seeder_band(&lt->seeder, e->lod_distance[k], e->lod_distance[k + 1]);
            lt->seeder.clip = (ip_clip){e->options.clip, e->options.clip_count};
            ip__propagator_free(&lt->propagator);
            if (ip__propagator_init(&lt->propagator, &lt->sampler, &e->visited, &w->mesh,
                                    &e->camera, iso, &e->options, e->lod_distance[k],
                                    e->lod_distance[k + 1],
                                    e->options.occlusion ? &e->coverage : NULL) != IP_OK)
                return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", path_of(e->cache));
            if (e->threads > 1)
                lt->propagator.share = (ip_share){&e->hungry, ip__engine_give_cells, e};
        }
    }
    if (keep && ip__engine_keep(e) != IP_OK) {
        ip_mesh_clear(&e->mesh);
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", path_of(e->cache));
    }
    atomic_store(&e->cancel, 0);
    e->begun = 1;
    e->reusable = 1;
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
    e->reusable = 0; /* a region's mesh is not the view's */
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
    to->culled += from->culled;
    to->kept += from->kept;
}

/* Moves the worker's triangles, if it holds any, to the engine's mesh. */
static ip_status flush_triangles(ip_engine_worker *w)
{
    ip_engine *e = w->engine;
    if (w->mesh.triangle_count == 0)
        return IP_OK; /* not even the lock to take */
    pthread_mutex_lock(&e->mesh_lock);
    ip_status st = ip_mesh_append_mesh(&e->mesh, &w->mesh, 0, w->mesh.triangle_count);
    pthread_mutex_unlock(&e->mesh_lock);
    ip_mesh_clear(&w->mesh);
    return st;
}

/* Adds the cells the worker extracted since *published (of its step's counts) to the engine's
 * cells_done, which decides when tiles are tested again (tile_retires()). */
static void publish_cells(ip_engine *e, const ip_engine_worker *w, uint64_t *published)
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
    ip_engine_worker *w = &e->workers[index];
    ip_order_ray rays[RAY_ROOM];
    unsigned n;
    uint64_t published = 0; /* of w->counts.cells, in e->cells_done */
    while (w->status == IP_OK && ip__engine_take_rays(e, w, rays, &n) > 0) {
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
            if (!ip__engine_retire(w, &rays[i], &from))
                w->status = ip__engine_cast_ray(w, rays[i].x, rays[i].y, from);
        }
        double seeding = ip_now_seconds() - t0 -
                         (w->counts.propagation_seconds + w->counts.extraction_seconds - inner);
        w->counts.intersection_seconds += seeding > 0 ? seeding : 0;
        publish_cells(e, w, &published);
        if (w->mesh.triangle_count >= FLUSH_TRIANGLES && flush_triangles(w) != IP_OK &&
            w->status == IP_OK)
            w->status = IP_ERR_NOMEM;
    }
    /* Out of rays: the triangles go to the mesh before helping, while the other workers may
     * still propagate, rather than after, when the step waits for the last of them. */
    if (flush_triangles(w) != IP_OK && w->status == IP_OK)
        w->status = IP_ERR_NOMEM;
    ip__engine_help(e, w);
    publish_cells(e, w, &published);
    if (flush_triangles(w) != IP_OK && w->status == IP_OK)
        w->status = IP_ERR_NOMEM;
    if (w->status != IP_OK) /* the step fails: the other workers take no more rays */
        atomic_store(&e->step_stopped, 1);
    ip__engine_leave_range(e, w);
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
     * of the surface): a batch of ceil(rays / threads), one ray when there are fewer rays than
     * threads. Every worker runs: those left without rays help the others' propagations
     * (ip__engine_help()). */
    unsigned threads = e->threads;
    e->step_batch = RAY_BATCH;
    if (max_rays && max_rays < (uint64_t)threads * RAY_BATCH)
        e->step_batch = (unsigned)((max_rays + threads - 1) / threads);
    e->working = threads;
    for (unsigned t = 0; t < threads; t++) {
        ip_engine_worker *w = &e->workers[t];
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
        ip_engine_worker *w = &e->workers[t];
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
    if (st != IP_OK)
        e->reusable = 0;
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

/* The bytes of a mesh's arrays as allocated. */
static uint64_t mesh_bytes(const ip_mesh *m)
{
    return m->capacity *
           (9 * sizeof(float) + 9 * sizeof(int16_t) + (m->with_cells ? sizeof(uint64_t) : 0));
}

void ip_engine_memory_of(const ip_engine *e, ip_engine_memory *m)
{
    memset(m, 0, sizeof *m);
    m->mesh = mesh_bytes(&e->mesh);
    for (unsigned t = 0; t < e->threads; t++) {
        const ip_engine_worker *w = &e->workers[t];
        m->workers += mesh_bytes(&w->mesh);
        for (uint32_t k = 0; k < IP_MAX_LEVELS; k++)
            if (w->level[k].ready)
                m->workers += w->level[k].propagator.queue.capacity * sizeof(ip_depth_slot);
    }
    const ip_visited *v = &e->visited;
    uint64_t bricks = v->layout ? v->layout->brick_count : 0;
    m->visited = atomic_load(&((ip_visited *)v)->holder_count) * v->words_per_brick * 8 +
                 bricks * (sizeof *v->bitmaps + sizeof *v->holders);
    m->coverage =
        e->coverage.capacity * 2 * sizeof(atomic_uint) + e->tile_capacity * (sizeof *e->tiles + 1);
    m->total = m->mesh + m->workers + m->visited + m->coverage;
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* Full extraction: every active cell of a level, brick by brick, skipping by summaries; and at
 * a view's adaptive resolution, each level's cells of its distance band (lod.h). */
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "array.h"
#include "clip.h"
#include "extract_full.h"
#include "internal.h"
#include "isoprop/engine.h"
#include "lod.h"
#include "pool.h"
#include "propagate.h"

/* The cells a full extraction takes by distance: with `banded`, those whose centre lies in
 * [near, far) from `eye` (lod.h); else all. */
typedef struct full_band {
    int banded;
    double near, far, widen; /* widen: ip__lod_band_widening() */
    double eye[3];
} full_band;

/* 0 when no cell of the brick whose samples start at `origin` (extent samples along each axis,
 * the sampler's level) can lie in the band: its world box lies wholly nearer than
 * near - widen or farther than far + widen from the eye. */
static int brick_may_be_in_band(const ip_sampler *s, const full_band *band,
                                const uint32_t origin[3], const uint32_t extent[3])
{
    if (!band->banded)
        return 1;
    double lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = s->world[a][origin[a]];
        hi[a] = s->world[a][origin[a] + extent[a] - 1];
    }
    return !ip__lod_box_outside(lo, hi, band->eye, band->near - band->widen,
                                band->far + band->widen);
}

/* Triangulates the active cells of one brick that `clip` keeps (and `band` takes),
 * sub-block by sub-block. */
static ip_status extract_brick(ip_sampler *s, ip_mesh *mesh, float iso, const ip_clip *clip,
                               const full_band *band, uint64_t g, ip_engine_counts *c)
{
    const ip_layout *l = s->layout;
    const float *ranges = ip_store_subblock_ranges(ip_cache_store(s->cache), g);
    uint32_t level, brick[3], origin[3], extent[3];
    ip_brick_coords(l, g, &level, brick);
    ip_brick_extent(l, level, brick, origin, extent);
    uint32_t per = l->brick_edge / l->subblock_edge, se = l->subblock_edge;
    ip_status st = IP_OK;
    ip_cell_output out = {mesh, NULL, 0, 0}; /* every triangle, none culled */
    if (!brick_may_be_in_band(s, band, origin, extent))
        return st;
    for (uint32_t i = 0; i < per * per * per && st == IP_OK; i++) {
        if (!ip__range_active(ranges[2 * i], ranges[2 * i + 1], iso))
            continue;
        uint32_t lo[3], hi[3];
        ip__subblock_cells(i, per, se, origin, extent, lo, hi);
        int side = ip__clip_keeps_samples(clip, l, level, lo, hi);
        if (side == IP__CLIP_DROPS)
            continue;
        for (uint32_t z = lo[2]; z < hi[2] && st == IP_OK; z++)
            for (uint32_t y = lo[1]; y < hi[1] && st == IP_OK; y++)
                for (uint32_t x = lo[0]; x < hi[0]; x++) {
                    uint32_t cell[3] = {x, y, z}, far[3] = {x + 1, y + 1, z + 1};
                    if ((side == IP__CLIP_STRADDLES &&
                         !ip__clip_keeps_samples(clip, l, level, cell, far)) ||
                        (band->banded &&
                         !ip__lod_cell_in_band(s, cell, band->eye, band->near, band->far)))
                        continue;
                    unsigned mc;
                    int n = ip__extract_cell(s, &out, cell, iso, &mc, &c->culled, &st);
                    if (n < 0)
                        break;
                    if (mc != 0 && mc != 255)
                        c->cells++;
                    c->triangles += (uint64_t)n;
                }
    }
    return st;
}

/* A worker of the full extraction: it takes bricks in order from a shared counter and
 * remembers where each brick's triangles start in its own mesh. */
typedef struct full_worker {
    ip_cache *cache;
    float iso;
    uint32_t level;
    ip_clip clip;
    full_band band;
    atomic_uint_fast64_t *next; /* next level-local brick to take */
    ip_sampler sampler;
    ip_mesh mesh;
    uint64_t *brick_of; /* per chunk of this worker: the brick */
    uint64_t *start_of; /* per chunk: its first triangle in mesh */
    uint64_t chunks, capacity;
    ip_engine_counts counts;
    ip_status status;
} full_worker;

static void full_work(void *user, unsigned index)
{
    full_worker *w = (full_worker *)user + index;
    const ip_store *store = ip_cache_store(w->cache);
    const ip_level_layout *lv = &ip_store_layout(store)->levels[w->level];
    double start = ip_now_seconds();
    for (uint64_t i; w->status == IP_OK && ip__next_active_brick(store, lv, w->next, w->iso, &i);) {
        if (!ip__clip_keeps_brick(&w->clip, ip_store_layout(store), lv->first_brick + i))
            continue;
        if (w->chunks == w->capacity) {
            uint64_t cap = ip__array_capacity(w->capacity, w->chunks + 1, 256, sizeof(uint64_t),
                                              IP_ARRAY_DOUBLE);
            if (!cap || ip__array_resize(&w->brick_of, cap, sizeof(uint64_t)) != IP_OK ||
                ip__array_resize(&w->start_of, cap, sizeof(uint64_t)) != IP_OK) {
                w->status = IP_ERR_NOMEM;
                break;
            }
            w->capacity = cap;
        }
        w->brick_of[w->chunks] = i;
        w->start_of[w->chunks++] = w->mesh.triangle_count;
        w->status = extract_brick(&w->sampler, &w->mesh, w->iso, &w->clip, &w->band,
                                  lv->first_brick + i, &w->counts);
        ip__sampler_release(&w->sampler); /* a brick at a time */
    }
    w->counts.extraction_seconds = ip_now_seconds() - start;
}

/* Appends every worker's triangles to `mesh` in brick order. */
static ip_status merge_in_brick_order(full_worker *w, unsigned threads, ip_mesh *mesh)
{
    uint64_t *cursor = calloc(threads, sizeof *cursor);
    if (!cursor)
        return IP_ERR_NOMEM;
    ip_status st = IP_OK;
    for (;;) {
        unsigned best = threads;
        for (unsigned t = 0; t < threads; t++)
            if (cursor[t] < w[t].chunks &&
                (best == threads || w[t].brick_of[cursor[t]] < w[best].brick_of[cursor[best]]))
                best = t;
        if (best == threads || st != IP_OK)
            break;
        full_worker *b = &w[best];
        uint64_t first = b->start_of[cursor[best]];
        uint64_t end =
            cursor[best] + 1 < b->chunks ? b->start_of[cursor[best] + 1] : b->mesh.triangle_count;
        st = ip_mesh_append_mesh(mesh, &b->mesh, first, end - first);
        cursor[best]++;
    }
    free(cursor);
    return st;
}

ip_status ip_extract_full(ip_cache *cache, float iso, uint32_t level, unsigned threads,
                          ip_mesh *mesh, ip_engine_counts *counts, ip_error *err)
{
    return ip_extract_full_clipped(cache, iso, level, threads, NULL, 0, mesh, counts, err);
}

static ip_status check_planes(const ip_clip_plane *clip, unsigned clip_count, ip_error *err)
{
    if (ip__clip_valid(clip, clip_count))
        return IP_OK;
    return ip__fail(err, IP_ERR_ARGUMENT,
                    "clipping planes: %u given (at most %d), each with a finite, non-zero "
                    "normal and a finite offset",
                    clip_count, IP_MAX_CLIP_PLANES);
}

/* The full extraction of one level's cells that the planes keep and `band` takes, appended
 * to `mesh` in brick order; the cells, triangles and time added to *total. */
static ip_status extract_level(ip_cache *cache, float iso, uint32_t level, unsigned threads,
                               const ip_clip_plane *clip, unsigned clip_count,
                               const full_band *band, ip_mesh *mesh, ip_engine_counts *total,
                               ip_error *err)
{
    const char *path = ip_store_path(ip_cache_store(cache));
    threads = ip_thread_count(threads);
    full_worker *w = calloc(threads, sizeof *w);
    if (!w)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", path);
    atomic_uint_fast64_t next;
    atomic_init(&next, 0);
    ip_status st = IP_OK;
    for (unsigned t = 0; t < threads; t++) {
        w[t] = (full_worker){.cache = cache,
                             .iso = iso,
                             .level = level,
                             .clip = {clip, clip_count},
                             .band = *band,
                             .next = &next};
        ip_mesh_init(&w[t].mesh);
        w[t].mesh.with_cells = mesh->with_cells;
        if (ip__sampler_init(&w[t].sampler, cache, level) != IP_OK && st == IP_OK)
            st = ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", path);
    }
    ip__pool *pool = NULL;
    if (st == IP_OK)
        st = ip__pool_create(threads, &pool, NULL);
    if (st == IP_OK)
        ip__pool_run(pool, threads, full_work, w);
    else
        ip__fail(err, st, "out of memory");
    ip__pool_destroy(pool);
    ip_engine_counts c;
    memset(&c, 0, sizeof c);
    for (unsigned t = 0; t < threads; t++) {
        c.cells += w[t].counts.cells;
        c.triangles += w[t].counts.triangles;
        c.extraction_seconds += w[t].counts.extraction_seconds;
        if (st == IP_OK && w[t].status != IP_OK) {
            st = w[t].status;
            if (st == IP_ERR_NOMEM)
                ip__fail(err, st, "%s: out of memory", path);
            else if (err)
                *err = w[t].sampler.error;
        }
    }
    if (st == IP_OK && merge_in_brick_order(w, threads, mesh) != IP_OK)
        st = ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", path);
    for (unsigned t = 0; t < threads; t++) {
        ip__sampler_free(&w[t].sampler);
        ip_mesh_free(&w[t].mesh);
        free(w[t].brick_of);
        free(w[t].start_of);
    }
    free(w);
    total->cells += c.cells;
    total->triangles += c.triangles;
    total->extraction_seconds += c.extraction_seconds;
    return st;
}

ip_status ip_extract_full_clipped(ip_cache *cache, float iso, uint32_t level, unsigned threads,
                                  const ip_clip_plane *clip, unsigned clip_count, ip_mesh *mesh,
                                  ip_engine_counts *counts, ip_error *err)
{
    const ip_layout *l = ip_store_layout(ip_cache_store(cache));
    if (level >= l->level_count)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: level %u does not exist",
                        ip_store_path(ip_cache_store(cache)), level);
    if (check_planes(clip, clip_count, err) != IP_OK)
        return IP_ERR_ARGUMENT;
    static const full_band every = {0, 0.0, INFINITY, 0.0, {0, 0, 0}};
    ip_engine_counts c;
    memset(&c, 0, sizeof c);
    ip_status st =
        extract_level(cache, iso, level, threads, clip, clip_count, &every, mesh, &c, err);
    if (counts)
        *counts = c;
    return st;
}

ip_status ip_extract_full_lod(ip_cache *cache, float iso, const ip_camera *camera,
                              double pixel_error, unsigned threads, const ip_clip_plane *clip,
                              unsigned clip_count, ip_mesh *mesh, ip_engine_counts *counts,
                              ip_error *err)
{
    const ip_layout *l = ip_store_layout(ip_cache_store(cache));
    if (!(pixel_error > 0 && isfinite(pixel_error)))
        return ip__fail(err, IP_ERR_ARGUMENT, "pixel error %g: not a positive number", pixel_error);
    if (ip_camera_check(camera, err) != IP_OK)
        return IP_ERR_ARGUMENT;
    if (check_planes(clip, clip_count, err) != IP_OK)
        return IP_ERR_ARGUMENT;
    double D[IP_MAX_LEVELS + 1];
    uint32_t levels = ip__lod_distances(l, camera, 1, pixel_error, D);
    ip_engine_counts c;
    memset(&c, 0, sizeof c);
    ip_status st = IP_OK;
    for (uint32_t k = 0; k < levels && st == IP_OK; k++) {
        full_band band = {levels > 1,
                          D[k],
                          D[k + 1],
                          ip__lod_band_widening(l, k, levels),
                          {camera->eye[0], camera->eye[1], camera->eye[2]}};
        st = extract_level(cache, iso, k, threads, clip, clip_count, &band, mesh, &c, err);
    }
    if (counts)
        *counts = c;
    return st;
}

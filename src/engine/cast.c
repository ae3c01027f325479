/* SPDX-License-Identifier: BSD-3-Clause */
/* A pixel's ray: the walk through each distance band's octree, its seed and propagation. */
#include <math.h>

#include "engine_state.h"
#include "internal.h"
#include "vec3.h"

/* Extracts one cell without propagating from it, into what its propagations extract into. */
static ip_status extract_one(ip_engine_worker *w, ip_level_tools *lt, const uint32_t cell[3])
{
    unsigned mc;
    ip_status st = IP_OK;
    double t0 = ip_now_seconds();
    int n = ip__extract_cell(&lt->sampler, &lt->propagator.out, cell, w->engine->iso, &mc,
                             &w->counts.culled, &st);
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

/* The ray of pixel (x, y) (engine_state.h), from view depth `from` (t = from / cos; 0: from the
 * eye). With occlusion the walk stops where the solid coverage entry of the pixel (coverage.h)
 * says nothing further can show: at t = (z + reach) / cos, z the entry widened by DEPTH_MARGIN,
 * reach a cell's extent along the view, cos the cosine between the ray and the view. `from` is
 * where its tile's beam was found settled short of (test_tile() in retire.c): every active cell
 * the ray could enter before is extracted already. With adaptive resolution each level is walked
 * over its band (lod.h) widened by half a cell's diagonal, passing over the cells of other bands
 * as the seeder is told (ip__seeder_band()), and each next level only up to where a walk
 * stopped, the far side of the cell it stopped in. Cells the walk meets are extracted: the seed
 * with its propagation, the near misses and the cells beside the ray within its reach (seed.h)
 * alone. Why the image stays exact: docs/design.md, E7-E11 (the stop, the same walk up to it,
 * races on the coverage, the settled start) and E13 (the levels together). */
ip_status ip__engine_cast_ray(ip_engine_worker *w, uint32_t x, uint32_t y, double from)
{
    ip_engine *e = w->engine;
    double dir[3];
    uint32_t cells[IP_SEED_MAX_CELLS][3];
    w->counts.rays++;
    ip_camera_pixel_ray(&e->basis, &e->camera, x + 0.5, y + 0.5, dir);
    double z = stop_depth(e, x, y), cos = ip__vec3_dot(dir, e->basis.forward);
    double nearest = INFINITY; /* where a level's walk stopped: beyond, no level need look */
    for (uint32_t k = 0; k < e->levels_used; k++) {
        ip_level_tools *lt = &w->level[k];
        unsigned count;
        int seed_index;
        /* The level's band (lod.h) widened by ip__lod_band_widening(): every point of a cell
         * of the band lies within that distance range of the eye, and so at t within it. */
        double band_lo = e->lod_distance[k] - e->band_widening[k],
               band_hi = e->lod_distance[k + 1] + e->band_widening[k];
        double t_max = band_hi, stop = (z + e->cell_reach[k]) / cos;
        t_max = stop < t_max ? stop : t_max;
        t_max = nearest < t_max ? nearest : t_max;
        double t_min = from / cos > band_lo ? from / cos : band_lo;
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
        nearest = lt->seeder.hit_t < nearest ? lt->seeder.hit_t : nearest;
    }
    return IP_OK;
}

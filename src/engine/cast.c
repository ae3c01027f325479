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

/* The ray of pixel (x, y) (engine_state.h). With occlusion the walk stops where the solid coverage
 * entry of the pixel (coverage.h) says nothing further can show: at t = (z + reach) / cos, z the
 * entry widened by DEPTH_MARGIN, reach a cell's extent along the view, cos the cosine between the
 * ray and the view. Why the image stays exact. The entry z means: an extracted triangle T, kept in
 * the mesh, holds the pixel centre by IP_COVERAGE_SOLID_MARGIN (1/128 pixel) or more from each of
 * its edges and has its vertices no deeper than z. The rasterizer moves a vertex by at most sqrt(2)
 * / 512 pixel (0.0028) when it snaps it, and an affine map moving the corners of T that little
 * moves no point of T more, so T still holds the centre after snapping (the disc of the margin
 * around it lies in T, the snapped disc's boundary stays within 0.0028 pixel of the circle, so it
 * still winds around the centre: any margin above 0.0028 pixel would do, and 1/128 is 2.8 times
 * that); the depth it is drawn with there interpolates 1 / depth between its vertices, so is at
 * most z. A cell the walk enters at t holds the ray's point at view depth t * cos, so its box
 * reaches no nearer than t * cos - reach; a cell entered beyond the stop has its box, and so every
 * vertex of its triangles, deeper than the entry by more than the margin (which covers the rounding
 * of vertices to floats), and any of its triangles is drawn at the pixel, if at all, deeper than T,
 * which beats it in either mesh. Nothing there can be the full extraction's triangle at this pixel,
 * nor change the extracted mesh's image there. The walk is otherwise the same: the cells of a ray
 * are entered front to back (the boxes of disjoint nodes cut disjoint spans of the ray), so the
 * shortened walk meets exactly the cells of the full walk up to the stop, in the same order, and
 * extracts the same ones of them, near misses (the cells it passes within 1/64 pixel of a triangle
 * edge, extracted alone, those beside it within its reach included: seed.h) and seed alike.
 * Rays may then find nothing where they would have found a hidden seed; propagation from such a
 * seed only ever saved other rays work. Each entry is backed by a triangle already in a
 * worker's mesh (one may rise when two threads lower it at once, coverage.h), so a stale or
 * risen read only stops the walk later. The edge of the solid margin
 * matters: the plain coverage entry also counts centres on a triangle's edge, where snapping may
 * uncover a silhouette and show the surface behind, which this ray must then still find.
 *
 * The walk starts at view depth `from` (t = from / cos), where its tile's beam was found settled
 * short of it (test_tile() in retire.c): every active cell the ray could enter before is extracted
 * already, and would only end the walk there (a cell hit squarely) or be passed over. Walking on
 * from `from` then finds what the full walk finds past it and at most more cells behind an
 * extracted one, all of the true surface: each is extracted or propagated from as a walk would
 * (the image stays exact: a pixel's own first-hit cell is either extracted already or found).
 *
 * With adaptive resolution the surface is that of each level's cells within its distance band
 * (lod.h). The ray walks each level over the band widened by half a cell's diagonal, where
 * every point of a band's cell lies, passing over the cells of other bands as the seeder is
 * told (ip__seeder_band()), and each next level only up to where a walk stopped, the far side
 * of the cell it stopped in: the nearest first-hit cell of any level lies within that, so the
 * argument above holds for the levels together. */
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

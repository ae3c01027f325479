/* SPDX-License-Identifier: BSD-3-Clause */
/* Rays retired in bulk: screen tiles of 8 x 8 pixels tested as beams against the octree, and
 * the Z-order blocks of rays they retire at once (docs/occlusion.md). */
#include <math.h>

#include "beam.h"
#include "engine_state.h"
#include "internal.h"

/* A tile is tested again in a later Z-order level only once the cells extracted have grown by
 * this fraction since its last test (tile_retires()). */
#define RETEST_GROWTH 0.1
#define TILE_SLACK (1.0 / 64) /* pixels added around a tile's pixel centres for its beam */

/* The tile of image pixel (x, y). */
static ip_engine_tile *pixel_tile(ip_engine *e, uint32_t x, uint32_t y)
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
 * every level, up to D's stop (ip__engine_cast_ray()) plus a cell's reach along the view
 * (ip__beam_settled()). Where every active cell there is extracted, the rays of the tile whose
 * solid entry is no deeper than D would find only extracted cells, now or later (cells stay
 * extracted; a ray whose entry reads deeper than D when it comes, as two writers racing may leave
 * it (coverage.h), is simply not left out), and do nothing: their walks can be left out (the tile's
 * `depth` is raised to D), and the mesh is the one the walks would leave. Where some may not be,
 * the test learns the depth short of which the beam is settled: the rays whose stop lies short of
 * it are left out in the same way (a lower `depth`), and the tile's other rays need not look short
 * of it (its `from`): the cells there are extracted or inactive. */
static void test_tile(ip_engine_worker *w, uint32_t tx, uint32_t ty, ip_engine_tile *t)
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
static int tile_retires(ip_engine_worker *w, uint32_t x, uint32_t y, uint32_t level, double *from)
{
    ip_engine *e = w->engine;
    ip_engine_tile *t = pixel_tile(e, x, y);
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

int ip__engine_retire(ip_engine_worker *w, const ip_order_ray *r, double *from)
{
    ip_engine *e = w->engine;
    *from = r->tested ? r->from : 0;
    if (r->tested || !e->options.occlusion)
        return 0;
    /* Before the Z-order levels only a tile settled with no bound retires a ray: one no active
     * brick shows in (clear_view()). */
    if (r->level < e->tile_from
            ? atomic_load_explicit(&pixel_tile(e, r->x, r->y)->depth, memory_order_relaxed) !=
                  ip__float_bits(INFINITY)
            : !tile_retires(w, r->x, r->y, r->level, from))
        return 0;
    w->counts.rays++;
    w->counts.retired++;
    return 1;
}

int ip__engine_take_block(ip_engine *e, ip_engine_worker *w, ip_order_ray *rays, unsigned space,
                          unsigned share, unsigned *count, unsigned *walk)
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
        rays[left++] = (ip_order_ray){x, y, level, 1, from};
    }
    if (!ip__engine_take_budget(e, n - left + (left > share ? left - share : 0)))
        return 0;
    ip__ray_order_skip_block(&w->order, BLOCK_LOG4, n);
    w->counts.rays += n - left;
    w->counts.retired += n - left;
    *count = n - left;
    *walk = left;
    return 1;
}

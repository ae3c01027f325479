/* SPDX-License-Identifier: BSD-3-Clause */
/* Screen tiles that the bricks holding the isovalue may show in. */
#include <math.h>
#include <string.h>

#include "format.h"
#include "reach.h"
#include "sampler.h"

/* The tiles [t[0], t[1]] x [t[2], t[3]] (whole numbers, never NaN: fmax() and fmin() drop a NaN
 * end) holding a pixel centre within a pixel of the bounding rectangle of the image of the
 * world box [lo, hi]: every tile when a corner of the box is not in front of the eye; none when
 * t[0] > t[1] or t[2] > t[3]. */
static void box_tiles(const ip_camera_basis *basis, const ip_camera *camera, const double lo[3],
                      const double hi[3], unsigned shift, uint32_t tiles_x, uint32_t tiles_y,
                      double t[4])
{
    double min_x = INFINITY, max_x = -INFINITY, min_y = INFINITY, max_y = -INFINITY;
    for (int c = 0; c < 8; c++) {
        double p[3] = {c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]};
        double x, y, depth;
        if (!ip_camera_project(basis, camera, p, &x, &y, &depth)) {
            min_x = min_y = -INFINITY;
            max_x = max_y = INFINITY;
            break;
        }
        min_x = x < min_x ? x : min_x;
        max_x = x > max_x ? x : max_x;
        min_y = y < min_y ? y : min_y;
        max_y = y > max_y ? y : max_y;
    }
    /* pixel x's centre x + 0.5 within [min - 1, max + 1]: x in [min - 1.5, max + 0.5] */
    double side = (double)(1u << shift);
    t[0] = fmax(floor((min_x - 1.5) / side), 0);
    t[1] = fmin(floor((max_x + 0.5) / side), tiles_x - 1.0);
    t[2] = fmax(floor((min_y - 1.5) / side), 0);
    t[3] = fmin(floor((max_y + 0.5) / side), tiles_y - 1.0);
}

void ip__reach_box(const ip_camera_basis *basis, const ip_camera *camera, const double lo[3],
                   const double hi[3], unsigned shift, uint32_t tiles_x, uint32_t tiles_y,
                   unsigned char *reached)
{
    double t[4];
    box_tiles(basis, camera, lo, hi, shift, tiles_x, tiles_y, t);
    if (t[0] > t[1]) /* left or right of the image */
        return;
    for (double ty = t[2]; ty <= t[3]; ty++)
        memset(reached + (size_t)ty * tiles_x + (size_t)t[0], 1, (size_t)(t[1] - t[0]) + 1);
}

/* What ip__reach_tiles() walks the octree of one level with. */
typedef struct reach_walk {
    const ip_store *store;
    const ip_layout *layout;
    float iso;
    uint32_t level;
    const ip_camera_basis *basis;
    const ip_camera *camera;
    unsigned shift;
    uint32_t tiles_x, tiles_y;
    unsigned char *reached;
} reach_walk;

/* The world box of the walk's level that octree node `node` of `depth` spans (0: a brick, from
 * its first sample to its last; above, the boxes of its bricks within one), cells of 2^level
 * samples' spacing from sample 0, as the seeder sees them. */
static void node_box(const reach_walk *w, uint32_t depth, const uint32_t node[3], double lo[3],
                     double hi[3])
{
    const ip_layout *l = w->layout;
    const uint32_t *bricks = l->levels[w->level].bricks;
    uint32_t first[3], last[3], origin[3], extent[3];
    for (int a = 0; a < 3; a++) {
        first[a] = node[a] << depth;
        uint32_t end = (node[a] + 1) << depth;
        last[a] = (end < bricks[a] ? end : bricks[a]) - 1;
    }
    ip_brick_extent(l, w->level, first, origin, extent);
    for (int a = 0; a < 3; a++)
        lo[a] = origin[a] * l->spacing[a] * (double)(1u << w->level);
    if (depth > 0) /* a brick is its own first and last */
        ip_brick_extent(l, w->level, last, origin, extent);
    for (int a = 0; a < 3; a++)
        hi[a] = (origin[a] + extent[a] - 1.0) * l->spacing[a] * (double)(1u << w->level);
}

/* Marks the tiles brick b of the walk's level may show in, if its range holds the isovalue. */
static void reach_brick(const reach_walk *w, const uint32_t b[3])
{
    float range[2];
    ip_store_brick_range(w->store, ip_brick_global_index(w->layout, w->level, b), range);
    if (!ip__range_active(range[0], range[1], w->iso))
        return;
    double lo[3], hi[3];
    node_box(w, 0, b, lo, hi);
    ip__reach_box(w->basis, w->camera, lo, hi, w->shift, w->tiles_x, w->tiles_y, w->reached);
}

/* 1 when marking the bricks of node `node` of `depth` (>= 1) would mark no tile not marked yet:
 * the tiles of its box hold every tile of each brick's box, and they are all marked, or none of
 * them is in the image. */
static int reached_already(const reach_walk *w, uint32_t depth, const uint32_t node[3])
{
    double lo[3], hi[3], t[4];
    node_box(w, depth, node, lo, hi);
    box_tiles(w->basis, w->camera, lo, hi, w->shift, w->tiles_x, w->tiles_y, t);
    if (t[0] > t[1] || t[2] > t[3])
        return 1;
    for (double ty = t[2]; ty <= t[3]; ty++) {
        const unsigned char *row = w->reached + (size_t)ty * w->tiles_x;
        for (double tx = t[0]; tx <= t[1]; tx++)
            if (!row[(size_t)tx])
                return 0;
    }
    return 1;
}

/* The bricks under octree node `node` of `depth` (0: a brick) whose range holds the isovalue.
 * A node's range is the union of its children's, so the nodes that do not hold it hold no such
 * brick, and are passed over with all their bricks; so are the nodes whose tiles are all
 * marked already (reached_already()). */
static void reach_node(const reach_walk *w, uint32_t depth, const uint32_t node[3])
{
    if (depth == 0) {
        reach_brick(w, node);
        return;
    }
    const float *range = ip_store_node_range(w->store, w->level, depth, node);
    if (!ip__range_active(range[0], range[1], w->iso) || reached_already(w, depth, node))
        return;
    uint32_t grid[3];
    ip__octree_grid(w->layout, w->level, depth - 1, grid);
    for (unsigned c = 0; c < 8; c++) {
        uint32_t child[3] = {2 * node[0] + (c & 1), 2 * node[1] + (c >> 1 & 1),
                             2 * node[2] + (c >> 2 & 1)};
        if (child[0] < grid[0] && child[1] < grid[1] && child[2] < grid[2])
            reach_node(w, depth - 1, child);
    }
}

void ip__reach_tiles(const ip_store *store, float iso, uint32_t levels,
                     const ip_camera_basis *basis, const ip_camera *camera, unsigned shift,
                     uint32_t tiles_x, uint32_t tiles_y, unsigned char *reached)
{
    memset(reached, 0, (size_t)tiles_x * tiles_y);
    const ip_layout *l = ip_store_layout(store);
    for (uint32_t k = 0; k < levels; k++) {
        static const uint32_t root[3] = {0, 0, 0};
        reach_walk w = {store, l, iso, k, basis, camera, shift, tiles_x, tiles_y, reached};
        reach_node(&w, l->levels[k].octree_depth, root);
    }
}

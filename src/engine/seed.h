/* SPDX-License-Identifier: BSD-3-Clause */
/* Ray seeding: the first cell along a ray whose marching-cubes triangles the ray hits. Internal. */
#ifndef ISOPROP_SEED_H
#define ISOPROP_SEED_H

#include "isoprop/store.h"
#include "clip.h"
#include "sampler.h"

/* Octree depths above the bricks: at most 30, as a level has fewer than 2^31 / 2 bricks along
 * an axis (ip__layout_init() bounds the dimensions and the brick edge). */
#define IP_SEED_MAX_DEPTH 31

/* The walk down the octree skips empty space in long rays; a DDA over the bricks costs less
 * for a stretch of up to this many bricks (the head's every ray, at 16 x 16 x 8 bricks). */
#define IP_SEED_SHORT_WALK 32.0

typedef struct ip_seeder {
    ip_sampler *sampler;
    const ip_store *store;
    const ip_layout *layout;
    uint32_t level;
    float iso;
    double scale[3];       /* world units per level cell along each axis (uniform part) */
    uint64_t cells_tested; /* active cells whose triangles were tested against a ray */
    uint64_t cells_read;   /* cells whose 8 corners were read (to find their case) */
    uint64_t nodes; /* octree nodes (bricks included), sub-blocks and cells that rays entered */
    int use_group_ranges; /* 1 (the default): pass over the cells of inactive cell groups */
    double short_walk;    /* bricks: a stretch of a ray no longer (in its longest axis) is walked
                          over the bricks by a DDA rather than down the octree (the default
                          IP_SEED_SHORT_WALK; the same cells are found either way) */
    uint32_t (*found)[3]; /* the cells of the current ray (see ip__seed_find) */
    unsigned found_count;
    int seed_index;       /* position in found of the first cell the ray is inside, or -1 */
    double margin;        /* IP_SEED_MARGIN_PIXELS as an angle, radians */
    double thick;         /* IP_SEED_REACH_PIXELS as an angle, radians */
    double reach[3];      /* the current ray's reach (IP_SEED_REACH_PIXELS), index units per axis */
    double within[3];     /* reach / |the ray's direction| per axis: the reach in t units */
    double within_most;   /* the largest of them */
    uint64_t near_tested; /* active cells the rays passed close to, without entering, tested */
    /* where the ray leaves the cell it stopped in (walk_cells()); +infinity after an
     * ip__seed_find() that stopped in none */
    double hit_t;
    /* With adaptive resolution (banded), only the cells of the level's distance band
     * [band_near, band_far) are the view's (lod.h): the walk passes over the others as if
     * they were inactive (ip__seeder_band()). */
    int banded;
    double band_near, band_far;
    /* Per octree depth of the level (0: the bricks): the node grid and the range of its
     * node (0, 0, 0), the others following x fastest. */
    uint32_t grid[IP_SEED_MAX_DEPTH + 1][3];
    const float *ranges[IP_SEED_MAX_DEPTH + 1];
    uint64_t first_brick; /* global index of the level's brick (0, 0, 0) */
    ip_clip clip; /* nodes and cells wholly beyond a plane are passed over (none after init) */
} ip_seeder;

/* The pieces of the octree that the ray walk (seed.c) and the beam test (beam.c) both descend.
 * Index space: cell (i, j, k) of the seeder's level is the box [i, i+1] x [j, j+1] x [k, k+1]. */

/* Index box of octree node `node` at `depth` (depth 0: a brick). */
static inline void ip__seeder_node_box(const ip_seeder *s, uint32_t depth, const uint32_t node[3],
                                       double lo[3], double hi[3])
{
    const ip_level_layout *lv = &s->layout->levels[s->level];
    for (int k = 0; k < 3; k++) {
        uint64_t span = (uint64_t)s->layout->brick_edge << depth;
        uint64_t a = node[k] * span, b = a + span, cells = lv->dims[k] - 1;
        lo[k] = (double)a;
        hi[k] = (double)(b < cells ? b : cells);
    }
}

/* 1 when the summary range (min, max) of node `node` at `depth`, which the level has, holds
 * the iso-value. */
static inline int ip__seeder_node_active(const ip_seeder *s, uint32_t depth, const uint32_t node[3])
{
    const uint32_t *grid = s->grid[depth];
    uint64_t i = node[0] + (uint64_t)grid[0] * (node[1] + (uint64_t)grid[1] * node[2]);
    const float *range = s->ranges[depth] + 2 * i;
    return ip__range_active(range[0], range[1], s->iso);
}

/* Child c (0..7: bit k is the upper half along axis k) of node `node` at `depth` (> 0), in
 * ch: 1 when the level has it and its summary range holds the iso-value, else 0. */
static inline int ip__seeder_active_child(const ip_seeder *s, uint32_t depth,
                                          const uint32_t node[3], int c, uint32_t ch[3])
{
    const uint32_t *grid = s->grid[depth - 1];
    for (int k = 0; k < 3; k++)
        ch[k] = 2 * node[k] + ((c >> k) & 1);
    if (ch[0] >= grid[0] || ch[1] >= grid[1] || ch[2] >= grid[2])
        return 0;
    return ip__seeder_node_active(s, depth - 1, ch);
}

/* ip__seeder_node_box() as level coordinates: the node's cells are [first, last). */
static inline void ip__seeder_node_cells(const ip_seeder *s, uint32_t depth, const uint32_t node[3],
                                         uint32_t first[3], uint32_t last[3])
{
    double lo[3], hi[3];
    ip__seeder_node_box(s, depth, node, lo, hi);
    for (int k = 0; k < 3; k++) {
        first[k] = (uint32_t)lo[k];
        last[k] = (uint32_t)hi[k];
    }
}

/* 1 unless the clipping planes drop every cell of node `node` at `depth`. */
static inline int ip__seeder_node_kept(const ip_seeder *s, uint32_t depth, const uint32_t node[3])
{
    if (s->clip.count == 0)
        return 1;
    uint32_t first[3], last[3];
    ip__seeder_node_cells(s, depth, node, first, last);
    return ip__clip_keeps_samples(&s->clip, s->layout, s->level, first, last);
}

/* Brick `b` (brick coordinates of the seeder's level): its first sample and extent (as
 * ip_brick_extent()), in subblocks[] the sub-blocks along each axis that hold cells, and, as
 * the return value, the summary's min/max pairs of its sub-blocks (x fastest, brick_edge /
 * subblock_edge a side; owned by the store). */
static inline const float *ip__seeder_brick(const ip_seeder *s, const uint32_t b[3],
                                            uint32_t origin[3], uint32_t extent[3],
                                            uint32_t subblocks[3])
{
    const ip_layout *l = s->layout;
    ip_brick_extent(l, s->level, b, origin, extent);
    const uint32_t *bricks = s->grid[0];
    uint64_t g = s->first_brick + b[0] + (uint64_t)bricks[0] * (b[1] + (uint64_t)bricks[1] * b[2]);
    for (int k = 0; k < 3; k++)
        subblocks[k] = (extent[k] - 1 + l->subblock_edge - 1) / l->subblock_edge;
    return ip_store_subblock_ranges(s->store, g);
}

/* The cells [lo, hi) of sub-block `at` of the brick whose first sample is `origin` and extent
 * `extent` (ip__seeder_brick()). */
static inline void ip__seeder_subblock_cells(const ip_seeder *s, const uint32_t origin[3],
                                             const uint32_t extent[3], const uint32_t at[3],
                                             uint32_t lo[3], uint32_t hi[3])
{
    uint32_t se = s->layout->subblock_edge;
    for (int k = 0; k < 3; k++) {
        uint32_t last = origin[k] + extent[k] - 1; /* one past the brick's last cell */
        lo[k] = origin[k] + se * at[k];
        hi[k] = lo[k] + se < last ? lo[k] + se : last;
    }
}

/* A ray whose pixel centre lies within this distance of a triangle's projected edge extracts
 * the cell and goes on to the first triangle it clearly hits: a rasteriser (which snaps
 * vertices to 1/256 pixel) may decide either way there. Far larger than that rounding, far
 * smaller than a pixel. */
#define IP_SEED_MARGIN_PIXELS (1.0 / 64.0)
#define IP_SEED_MAX_CELLS 64

/* A ray also tests the active cells it passes within this distance of without entering them
 * (its reach): the rasteriser's snapping moves a triangle's edge by up to sqrt(2) / 512 pixel
 * (0.0028), so it may show at a pixel a triangle whose cell the pixel's ray runs just beside,
 * a triangle no cell the ray enters holds. Those it passes within the margin of are near
 * misses (extracted alone, never the seed). The reach is the angle it subtends at the image
 * centre (where a pixel subtends the widest angle) times the ray's farthest distance within a
 * cell of the volume, along each axis in index units (a box around the ray, wider than the
 * round reach it stands for): 2.8 times the snapping anywhere along the ray. A cell a pixel
 * may show that way lies within the snapping of its ray, inside the slack of a tile's beam
 * (retire.c, 1/64 pixel): a retired ray's tile has it extracted already. */
#define IP_SEED_REACH_PIXELS (1.0 / 128.0)

/* `pixel_angle`: the angle one pixel subtends at the image centre (radians). */
void ip__seeder_init(ip_seeder *s, ip_sampler *sampler, float iso, double pixel_angle);

/* Restricts the walks to the cells of the level's distance band [near, far) (lod.h), as
 * propagation is: 0 and +infinity (a view of one level) walk every cell. */
void ip__seeder_band(ip_seeder *s, double near, double far);

/* Casts the ray eye + t * dir (world units, dir of unit length, t_min <= t <= t_max) through
 * the octree of the seeder's level, front to back (a stretch of up to s->short_walk bricks
 * over the bricks by a DDA). The seed is the first cell with a triangle
 * the ray passes inside. Fills cells[0 .. *count) (room for IP_SEED_MAX_CELLS) with every cell
 * the ray passed inside or within the margin of, in order, up to the first it passes inside by
 * more than the margin (where it stops); *seed_index is the seed's position there, or -1.
 * The other cells are where a rasteriser may show a triangle at this pixel after rounding:
 * among them the cells the ray passes beside within its reach (IP_SEED_REACH_PIXELS) without
 * entering them, up to the cell it stops in, wherever they come in the list.
 * @return 1 when there is a seed, 0 when not (the cells are near misses only, possibly none),
 * -1 when a brick could not be read (see the sampler's status). s->hit_t then says where the
 * ray leaves the cell the walk stopped in (+infinity when it stopped in none). Cells outside
 * the seeder's band (ip__seeder_band()) are passed over, neither found nor stopped in. */
int ip__seed_find(ip_seeder *s, const double eye[3], const double dir[3], double t_min,
                  double t_max, uint32_t cells[][3], unsigned *count, int *seed_index);

/* The bricks of pyramid level `level` that the ray eye + t * dir (world units, t_min <= t <=
 * t_max) would seed in, front to back, up to `max` of them: those whose range holds `iso`, that
 * `planes` keep, and where the ray crosses a sub-block whose range holds it. From the summaries
 * alone (no brick is read); for reading bricks ahead of the rays. @return how many were
 * written to bricks. */
unsigned ip__seed_ray_bricks(const ip_store *store, uint32_t level, float iso,
                             const ip_clip *planes, const double eye[3], const double dir[3],
                             double t_min, double t_max, uint64_t *bricks, unsigned max);

#endif

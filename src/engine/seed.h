/* Ray seeding: the first cell along a ray whose marching-cubes triangles the ray hits. Internal. */
#ifndef ISOPROP_SEED_H
#define ISOPROP_SEED_H

#include "isoprop/store.h"
#include "clip.h"
#include "sampler.h"

/* Octree depths above the bricks: at most 30, as a level has fewer than 2^31 / 2 bricks along
 * an axis (ip__layout_init() bounds the dimensions and the brick edge). */
#define IP_SEED_MAX_DEPTH 31

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
    uint32_t (*found)[3]; /* the cells of the current ray (see ip__seed_find) */
    unsigned found_count;
    int seed_index; /* position in found of the first cell the ray is inside, or -1 */
    double margin;  /* IP_SEED_MARGIN_PIXELS as an angle, radians */
    /* Per octree depth of the level (0: the bricks): the node grid and the range of its
     * node (0, 0, 0), the others following x fastest. */
    uint32_t grid[IP_SEED_MAX_DEPTH + 1][3];
    const float *ranges[IP_SEED_MAX_DEPTH + 1];
    uint64_t first_brick; /* global index of the level's brick (0, 0, 0) */
    ip_clip clip; /* nodes and cells wholly beyond a plane are passed over (none after init) */
} ip_seeder;

/* A ray whose pixel centre lies within this distance of a triangle's projected edge extracts
 * the cell and goes on to the first triangle it clearly hits: a rasteriser (which snaps
 * vertices to 1/256 pixel) may decide either way there. Far larger than that rounding, far
 * smaller than a pixel. */
#define IP_SEED_MARGIN_PIXELS (1.0 / 64.0)
#define IP_SEED_MAX_CELLS 64

/* `pixel_angle`: the angle one pixel subtends at the image centre (radians). */
void ip__seeder_init(ip_seeder *s, ip_sampler *sampler, float iso, double pixel_angle);

/* Casts the ray eye + t * dir (world units, dir of unit length, t_min <= t <= t_max) through
 * the octree of the seeder's level, front to back. The seed is the first cell with a triangle
 * the ray passes inside. Fills cells[0 .. *count) (room for IP_SEED_MAX_CELLS) with every cell
 * the ray passed inside or within the margin of, in order, up to the first it passes inside by
 * more than the margin (where it stops); *seed_index is the seed's position there, or -1.
 * The other cells are where a rasteriser may show a triangle at this pixel after rounding.
 * @return 1 when there is a seed, 0 when not (the cells are near misses only, possibly none),
 * -1 when a brick could not be read (see the sampler's status). */
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

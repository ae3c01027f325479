/* Reading samples and cells of one level through the brick cache. Internal.
 *
 * A sampler keeps a few bricks pinned (the ones it read last), so that the samples of a cell
 * and of its neighbourhood, which may straddle brick faces, are read without a cache lookup
 * each. One sampler per thread. */
#ifndef ISOPROP_SAMPLER_H
#define ISOPROP_SAMPLER_H

#include <stdint.h>

#include "isoprop/cache.h"
#include "isoprop/mc.h"

#define IP_SAMPLER_SLOTS 8

typedef struct ip_sampler {
    ip_cache *cache;
    const ip_layout *layout;
    uint32_t level;
    uint32_t dims[3];         /* the level's samples */
    double *world[3];         /* world coordinate of each level sample along each axis */
    ip_brick held[IP_SAMPLER_SLOTS];
    int used[IP_SAMPLER_SLOTS];
    unsigned next_victim;
    ip_status status;         /* the first failure, IP_OK until then */
    ip_error error;
} ip_sampler;

/* Prepares a sampler over `level` of the cache's store. @return IP_OK or IP_ERR_NOMEM. */
ip_status ip_sampler_init(ip_sampler *s, ip_cache *cache, uint32_t level);

/* Unpins every brick and frees the sampler's tables. */
void ip_sampler_free(ip_sampler *s);

/* Unpins every brick (the sampler stays usable). */
void ip_sampler_release(ip_sampler *s);

/* The brick holding cell `cell` (level coordinates), pinned by the sampler; NULL after a
 * failure (s->status and s->error say which brick). */
const ip_brick *ip_sampler_cell_brick(ip_sampler *s, const uint32_t cell[3]);

/* The 8 corner values of `cell`, in marching-cubes corner order. Returns 0 after a failure. */
int ip_sampler_cell_values(ip_sampler *s, const uint32_t cell[3], float values[8]);

/* World origin and size of `cell`. */
void ip_sampler_cell_box(const ip_sampler *s, const uint32_t cell[3], float origin[3],
                         float size[3]);

/* Triangulates `cell` with gradient normals: writes up to IP_MC_MAX_VERTICES vertices and the
 * marching-cubes case. Returns the number of triangles, or -1 after a failure. */
int ip_sampler_triangulate(ip_sampler *s, const uint32_t cell[3], float iso,
                           ip_mc_vertex *out, unsigned *mc_case);

/* 1 when the range [lo, hi] (over cell corners) may hold an active cell for `iso`: some corner
 * >= iso and some corner < iso. */
static inline int ip_range_active(float lo, float hi, float iso)
{
    return lo < iso && hi >= iso;
}

#endif

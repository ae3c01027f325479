/* Ray seeding: the first cell along a ray whose marching-cubes triangles the ray hits. Internal. */
#ifndef ISOPROP_SEED_H
#define ISOPROP_SEED_H

#include "isoprop/store.h"
#include "sampler.h"

typedef struct ip_seeder {
    ip_sampler *sampler;
    const ip_store *store;
    const ip_layout *layout;
    uint32_t level;
    float iso;
    double scale[3];     /* world units per level cell along each axis (uniform part) */
    uint64_t cells_tested; /* active cells whose triangles were tested against a ray */
} ip_seeder;

void ip_seeder_init(ip_seeder *s, ip_sampler *sampler, float iso);

/* Casts the ray eye + t * dir (world units, dir of unit length, t >= 0) through the octree.
 * @return 1 and the seed cell (level coordinates), 0 when the ray meets no triangle, -1 when
 * a brick could not be read (see the sampler's status). */
int ip_seed_find(ip_seeder *s, const double eye[3], const double dir[3], uint32_t cell[3]);

#endif

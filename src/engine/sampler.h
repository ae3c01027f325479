/* SPDX-License-Identifier: BSD-3-Clause */
/* Reading samples and cells of one level through the brick cache. Internal.
 *
 * A sampler keeps a few bricks pinned (the ones it read last), so that the samples of a cell
 * and of its neighbourhood, which may straddle brick faces, are read without a cache lookup
 * each. One sampler per thread. */
#ifndef ISOPROP_SAMPLER_H
#define ISOPROP_SAMPLER_H

#include <stddef.h>
#include <stdint.h>

#include "isoprop/cache.h"
#include "mc.h"

#define IP_SAMPLER_SLOTS 8

typedef struct ip_sampler {
    ip_cache *cache;
    const ip_layout *layout;
    uint32_t level;
    uint32_t dims[3]; /* the level's samples */
    double *world[3]; /* world coordinate of each level sample along each axis */
    /* per axis and sample: 1 / the world distance between the samples either side of it
     * (clamped at the volume's faces), 0 where that is 0: a central difference's factor */
    double *inverse_span[3];
    ip_brick held[IP_SAMPLER_SLOTS];
    int used[IP_SAMPLER_SLOTS];
    unsigned next_victim;
    unsigned last;       /* the slot returned last: the first one tried for a cell */
    unsigned edge_shift; /* log2 of the brick edge: brick coordinates without a divide */
    ip_status status;    /* the first failure, IP_OK until then */
    ip_error error;
    /* the triangle table in the volume's canonical frame (mc.h, "Frames"): the table's own
     * rows, or own_rows (allocated) where the frame turns them */
    const int8_t (*mc_rows)[16];
    int8_t (*own_rows)[16];
} ip_sampler;

/* Prepares a sampler over `level` of the cache's store. @return IP_OK or IP_ERR_NOMEM. */
ip_status ip__sampler_init(ip_sampler *s, ip_cache *cache, uint32_t level);

/* Unpins every brick and frees the sampler's tables. */
void ip__sampler_free(ip_sampler *s);

/* Unpins every brick (the sampler stays usable). */
void ip__sampler_release(ip_sampler *s);

/* The brick holding cell `cell` (level coordinates), pinned by the sampler; NULL after a
 * failure (s->status and s->error say which brick). */
const ip_brick *ip__sampler_cell_brick(ip_sampler *s, const uint32_t cell[3]);

/* ip__sampler_cell_brick() for a brick the cache already holds: NULL, with nothing read and
 * no failure recorded, when it does not. */
const ip_brick *ip__sampler_resident_cell_brick(ip_sampler *s, const uint32_t cell[3]);

/* The 8 corner values of `cell`, in marching-cubes corner order. Returns 0 after a failure. */
int ip__sampler_cell_values(ip_sampler *s, const uint32_t cell[3], float values[8]);

/* out[i] = sample first + offsets[i] of a native array of `type`, as a float (exact, as
 * ip_sample_get()). The switch on the type is taken once per call rather than once per
 * sample, and inlined with a constant count the loops unroll: the samplers' hot paths read
 * 8 (a cell) or 24 (its gradient neighbours) samples at a time. */
static inline void ip__samples_gather(const void *samples, ip_type type, size_t first,
                                      const ptrdiff_t *offsets, int count, float *out)
{
#define IP_GATHER_AS(T)                          \
    do {                                         \
        const T *p = (const T *)samples + first; \
        for (int i = 0; i < count; i++)          \
            out[i] = (float)p[offsets[i]];       \
        return;                                  \
    } while (0)
    switch (type) {
    case IP_UINT8: IP_GATHER_AS(uint8_t);
    case IP_UINT16: IP_GATHER_AS(uint16_t);
    case IP_INT16: IP_GATHER_AS(int16_t);
    case IP_FLOAT32: IP_GATHER_AS(float);
    }
#undef IP_GATHER_AS
    for (int i = 0; i < count; i++) /* not a type: as ip_sample_get() */
        out[i] = 0.0f;
}

/* Offsets of a cell's 8 corners from its corner 0 in brick `b`, in marching-cubes corner
 * order (the same for every cell of the brick). */
static inline void ip__corner_offsets(const ip_brick *b, ptrdiff_t offsets[8])
{
    ptrdiff_t row = (ptrdiff_t)b->extent[0], slice = row * (ptrdiff_t)b->extent[1];
    for (int c = 0; c < 8; c++)
        offsets[c] = (c & 1) + ((c >> 1) & 1) * row + ((c >> 2) & 1) * slice;
}

/* Index in brick `b` of sample `p` (level coordinates), which the brick must hold. */
static inline size_t ip__sample_index(const ip_brick *b, const uint32_t p[3])
{
    size_t x = p[0] - b->origin[0], y = p[1] - b->origin[1], z = p[2] - b->origin[2];
    return x + (size_t)b->extent[0] * (y + (size_t)b->extent[1] * z);
}

/* The 8 corner values of `cell`, which brick `b` holds, with the brick's corner offsets:
 * ip__sampler_cell_values() without the brick lookup, for loops over the cells of one brick. */
static inline void ip__cell_values(const ip_brick *b, ip_type type, const ptrdiff_t offsets[8],
                                   const uint32_t cell[3], float values[8])
{
    ip__samples_gather(b->samples, type, ip__sample_index(b, cell), offsets, 8, values);
}

/* World positions of `cell`'s low and high corners (0 and 7), each coordinate the grid's own,
 * so that neighbouring cells get the same bits for their shared corners. */
void ip__sampler_cell_box(const ip_sampler *s, const uint32_t cell[3], float lo[3], float hi[3]);

/* The centre of `cell`'s world box, in double (world units): the point propagation orders
 * cells by and the distance bands of adaptive resolution are decided at (lod.h). */
static inline void ip__sampler_cell_centre(const ip_sampler *s, const uint32_t cell[3],
                                           double centre[3])
{
    for (int a = 0; a < 3; a++)
        centre[a] = 0.5 * (s->world[a][cell[a]] + s->world[a][cell[a] + 1]);
}

/* A cell in two parts, for a caller that may not need its normals (the gradients are most of
 * the work): its corner values and marching-cubes case (returns 1, or -1 after a failure);
 * then, for an active case, the gradient normals at its edge crossings from those values, as
 * ip__mc_cell_edge_normals() gives them (the mask of crossed edges, or -1 after a failure).
 * The case first: most cells of an active sub-block are not active, and need neither the
 * gradient neighbours nor the divisions. The vertices are ip__mc_cell_edge_points()', and
 * lo, hi the cell's box as ip__sampler_cell_box() gives it (both take it from the caller, who
 * works it out once). */
int ip__sampler_cell_case(ip_sampler *s, const uint32_t cell[3], float iso, float values[8],
                          unsigned *mc_case);
int ip__sampler_cell_normals(ip_sampler *s, const uint32_t cell[3], const float values[8],
                             unsigned mc_case, float iso, const float lo[3], const float hi[3],
                             float normals[12][3]);

/* 1 when the range [lo, hi] (over cell corners) may hold an active cell for `iso`: some corner
 * >= iso and some corner < iso. */
static inline int ip__range_active(float lo, float hi, float iso)
{
    return lo < iso && hi >= iso;
}

#endif

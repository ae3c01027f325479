/* SPDX-License-Identifier: BSD-3-Clause */
/* The pyramid of coarser levels (subsampling a plane) and the summaries above the bricks (the
 * octree, the levels' value ranges), shared by the bricker and the store of a volume in memory. */
#include <math.h>
#include <string.h>

#include "internal.h"
#include "pyramid.h"
#include "summary.h"

/* One copy per sample, by sample width, so that the compiler turns it into plain loads and
 * stores. */
#define DEFINE_SUBSAMPLE(T, NAME)                                                          \
    static void NAME(const ip__plane_source *src, const uint32_t *x_index,                 \
                     const uint32_t *y_index, uint32_t width, uint32_t height, T *dst)     \
    {                                                                                      \
        for (uint32_t y = 0; y < height; y++) {                                            \
            const unsigned char *row = src->plane + (ptrdiff_t)y_index[y] * src->y_stride; \
            for (uint32_t x = 0; x < width; x++) {                                         \
                T v;                                                                       \
                memcpy(&v, row + (ptrdiff_t)x_index[x] * src->x_stride, sizeof v);         \
                *dst++ = v;                                                                \
            }                                                                              \
        }                                                                                  \
    }

DEFINE_SUBSAMPLE(uint8_t, subsample_8)
DEFINE_SUBSAMPLE(uint16_t, subsample_16)
DEFINE_SUBSAMPLE(uint32_t, subsample_32)

void ip__subsample_plane(const ip__plane_source *src, const uint32_t *x_index,
                         const uint32_t *y_index, uint32_t width, uint32_t height, void *dst)
{
    if (src->sample_size == 1)
        subsample_8(src, x_index, y_index, width, height, dst);
    else if (src->sample_size == 2)
        subsample_16(src, x_index, y_index, width, height, dst);
    else
        subsample_32(src, x_index, y_index, width, height, dst);
}

/* ip__octree_walk() visitor: stores each node's range, read back for the next depth. */
static int store_node(void *nodes, uint32_t level, uint32_t depth, const uint32_t node[3],
                      uint64_t node_index, const float range[2])
{
    (void)level, (void)depth, (void)node;
    memcpy((float *)nodes + 2 * node_index, range, 2 * sizeof(float));
    return 0;
}

void ip__octree_build(const ip_layout *l, const float *brick_ranges, float *nodes)
{
    ip__octree_walk(l, brick_ranges, nodes, store_node, nodes);
}

void ip__level_value_ranges(ip_layout *l, const float *brick_ranges)
{
    for (uint32_t k = 0; k < l->level_count; k++) {
        ip_level_layout *lv = &l->levels[k];
        lv->value_min = INFINITY;
        lv->value_max = -INFINITY;
        for (uint64_t i = 0; i < lv->brick_count; i++) {
            lv->value_min = fminf(lv->value_min, brick_ranges[2 * (lv->first_brick + i)]);
            lv->value_max = fmaxf(lv->value_max, brick_ranges[2 * (lv->first_brick + i) + 1]);
        }
    }
    l->value_min = l->levels[0].value_min;
    l->value_max = l->levels[0].value_max;
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* The pyramid of coarser levels and the summaries above the bricks, as the bricker builds them
 * and a store of samples in memory builds them too. Internal. */
#ifndef ISOPROP_PYRAMID_H
#define ISOPROP_PYRAMID_H

#include <stddef.h>
#include <stdint.h>

#include "isoprop/layout.h"

/* Where one level-0 plane lies and how a coarser level samples it: row y of the plane starts
 * at plane + y * y_stride, its sample x at x * x_stride (bytes); the level's
 * sample (x, y) is the plane's (x_index[x], y_index[y]) (ip_level_sample_index()). */
typedef struct ip__plane_source {
    const unsigned char *plane;
    ptrdiff_t x_stride, y_stride; /* may be negative */
    size_t sample_size;           /* 1, 2 or 4 */
} ip__plane_source;

/* Subsamples a level-0 plane into `dst`, a plane of a level `width` x `height` samples (x
 * fastest, contiguous): a copy per sample, by sample width. */
void ip__subsample_plane(const ip__plane_source *src, const uint32_t *x_index,
                         const uint32_t *y_index, uint32_t width, uint32_t height, void *dst);

/* Fills every octree node's range (2 floats per ip__octree_node_index(), `nodes` holding
 * 2 * node_count floats) from the brick ranges: the octree a brick file stores. */
void ip__octree_build(const ip_layout *l, const float *brick_ranges, float *nodes);

/* Each level's value_min and value_max (the union of its bricks' ranges) and the layout's
 * (level 0's), from the brick ranges. */
void ip__level_value_ranges(ip_layout *l, const float *brick_ranges);

#endif

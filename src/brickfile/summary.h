/* SPDX-License-Identifier: BSD-3-Clause */
/* Min/max summaries of a brick and its sub-blocks, over cell corners. Internal. */
#ifndef ISOPROP_SUMMARY_H
#define ISOPROP_SUMMARY_H

#include <stdint.h>

#include "isoprop/layout.h"
#include "isoprop/volume.h"

/* Range of the samples in the inclusive box [lo, hi] of a brick of `extent` samples. */
void ip__box_range(const void *samples, ip_type type, const uint32_t extent[3],
                   const uint32_t lo[3], const uint32_t hi[3], float *min, float *max);

/* The brick's range and the ranges of its (B/s)^3 sub-blocks, x fastest. A sub-block covers
 * cells [c*s, (c+1)*s) clipped to the brick, so samples [c*s, min((c+1)*s, extent-1)]; one
 * with no cells (an edge brick) gets the empty range [+inf, -inf], which contains no value.
 * `ranges` receives 2 floats per sub-block (min, max). */
void ip__summarise_brick(const void *samples, ip_type type, const uint32_t extent[3],
                         uint32_t brick_edge, uint32_t subblock_edge, float brick_range[2],
                         float *ranges);

/* One layer of bricks of an integer level (not float32) where it lies: row y of the layer's
 * slice z starts at planes[z] + y * row_bytes, for y < dims[1] and z < depth. */
typedef struct ip__layer_rows {
    const unsigned char *const *planes;
    size_t row_bytes;
    ip_type type;
    uint32_t dims[2];   /* the level's width and height in samples */
    uint32_t depth;     /* slices of the layer: the z extent of its bricks */
    uint32_t bricks[2]; /* bricks of the layer along x and y */
    uint32_t brick_edge, subblock_edge;
} ip__layer_rows;

/* Bytes of scratch ip__summarise_brick_row() needs for a level `width` samples wide. */
size_t ip__brick_row_scratch_bytes(uint32_t width, ip_type type);

/* The sub-block ranges of brick row `by` of a layer, the same as ip__summarise_brick() gives
 * each of its bricks: each (y, z) band of sub-blocks is reduced over full-width rows (read in
 * order, three at a time, each slice of the band once) into a row of minima and a row of
 * maxima in `scratch` (ip__brick_row_scratch_bytes()), then each sub-block reduces its stretch
 * of them. Brick (bx, by) of the layer gets its ranges at layer_ranges + 2 * (by * bricks[0] +
 * bx) * (B/s)^3, in the order of ip__summarise_brick(). */
void ip__summarise_brick_row(const ip__layer_rows *layer, uint32_t by, void *scratch,
                             float *layer_ranges);

/* The union of `count` ranges (2 floats each): a brick's range from its sub-blocks'. */
void ip__union_range(const float *ranges, size_t count, float range[2]);

/* Called by ip__octree_walk() once per node with the union of its children's ranges, as
 * read at that moment; a nonzero return stops the walk and is returned by it. */
typedef int (*ip_octree_node_fn)(void *user, uint32_t level, uint32_t depth, const uint32_t node[3],
                                 uint64_t node_index, const float range[2]);

/*! ip__octree_walk() : visits every node of the min/max octree (docs/format.md) level by level,
 *  depth 1 first, z slowest and x fastest within a depth, and passes `visit` the union of the
 *  ranges of the node's up-to-8 children: bricks at depth 1 (`brick_ranges`, 2 floats per
 *  global brick index), nodes of depth - 1 deeper (`node_ranges`, 2 floats per
 *  ip__octree_node_index()). `node_ranges` is read only after the visits of the depth below, so
 *  a visitor that writes each range there builds the octree (the bricker), and one that
 *  compares checks a stored one (the store). Empty nodes get [+inf, -inf].
 *  @return : 0, or the first nonzero value `visit` returned. */
int ip__octree_walk(const ip_layout *l, const float *brick_ranges, const float *node_ranges,
                    ip_octree_node_fn visit, void *user);

#endif

/* Min/max summaries of a brick and its sub-blocks, over cell corners. Internal. */
#ifndef ISOPROP_SUMMARY_H
#define ISOPROP_SUMMARY_H

#include <stdint.h>

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

#endif

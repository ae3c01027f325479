/* SPDX-License-Identifier: BSD-3-Clause */
/* Clipping planes: which boxes of the volume the planes keep (isoprop/engine.h, ip_clip_plane).
 * Internal. */
#ifndef ISOPROP_CLIP_H
#define ISOPROP_CLIP_H

#include <stdint.h>

#include "isoprop/engine.h"
#include "isoprop/layout.h"

/* A set of planes, borrowed from the caller (the engine's options, ip_extract_full_clipped()'s
 * argument); count 0 keeps everything. */
typedef struct ip_clip {
    const ip_clip_plane *planes;
    unsigned count;
} ip_clip;

/* 1 when the planes are usable: at most IP_MAX_CLIP_PLANES, finite, normals not zero. */
int ip__clip_valid(const ip_clip_plane *planes, unsigned count);

/* Where the world box [lo, hi] lies: IP__CLIP_DROPS when wholly beyond one of the planes,
 * IP__CLIP_KEEPS_ALL when wholly on the kept side of every plane (always, with no planes), else
 * IP__CLIP_STRADDLES. Nonzero means kept; callers test the cells of a straddling box one by one
 * and skip that test inside a box kept whole. */
enum {
    IP__CLIP_DROPS = 0,
    IP__CLIP_STRADDLES = 1,
    IP__CLIP_KEEPS_ALL = 2
};
int ip__clip_keeps_box(const ip_clip *c, const double lo[3], const double hi[3]);

/* ip__clip_keeps_box() of the box between samples `first` and `last` of pyramid level `level`
 * (level sample coordinates, first <= last): a node, brick, sub-block or cell. The corners are
 * the samples' world positions, as the sampler computes them, so that a node is dropped only
 * when every cell in it is. */
int ip__clip_keeps_samples(const ip_clip *c, const ip_layout *l, uint32_t level,
                           const uint32_t first[3], const uint32_t last[3]);

/* ip__clip_keeps_samples() of brick `g` (global index), its + face layer included. */
int ip__clip_keeps_brick(const ip_clip *c, const ip_layout *l, uint64_t g);

#endif

/* SPDX-License-Identifier: BSD-3-Clause */
/* Clipping planes: a box is dropped when it lies wholly beyond one plane. */
#include <math.h>

#include "clip.h"

int ip__clip_valid(const ip_clip_plane *planes, unsigned count)
{
    if (count > IP_MAX_CLIP_PLANES || (count > 0 && !planes))
        return 0;
    for (unsigned i = 0; i < count; i++) {
        const double *n = planes[i].normal;
        if (!isfinite(n[0]) || !isfinite(n[1]) || !isfinite(n[2]) || !isfinite(planes[i].offset) ||
            (n[0] == 0 && n[1] == 0 && n[2] == 0))
            return 0;
    }
    return 1;
}

int ip__clip_keeps_box(const ip_clip *c, const double lo[3], const double hi[3])
{
    int side = IP__CLIP_KEEPS_ALL;
    for (unsigned i = 0; i < c->count; i++) {
        const ip_clip_plane *p = &c->planes[i];
        /* the plane's largest and smallest values over the box: each at one corner */
        double most = p->offset, least = p->offset;
        for (int k = 0; k < 3; k++) {
            most += p->normal[k] * (p->normal[k] > 0 ? hi[k] : lo[k]);
            least += p->normal[k] * (p->normal[k] > 0 ? lo[k] : hi[k]);
        }
        if (most < 0)
            return IP__CLIP_DROPS;
        if (least < 0)
            side = IP__CLIP_STRADDLES;
    }
    return side;
}

int ip__clip_keeps_samples(const ip_clip *c, const ip_layout *l, uint32_t level,
                           const uint32_t first[3], const uint32_t last[3])
{
    if (c->count == 0)
        return IP__CLIP_KEEPS_ALL;
    double lo[3], hi[3];
    for (int k = 0; k < 3; k++) {
        lo[k] = ip_level_sample_index(l->dims[k], level, first[k]) * l->spacing[k];
        hi[k] = ip_level_sample_index(l->dims[k], level, last[k]) * l->spacing[k];
    }
    return ip__clip_keeps_box(c, lo, hi);
}

int ip__clip_keeps_brick(const ip_clip *c, const ip_layout *l, uint64_t g)
{
    if (c->count == 0)
        return IP__CLIP_KEEPS_ALL;
    uint32_t level, b[3], origin[3], extent[3], last[3];
    ip_brick_coords(l, g, &level, b);
    ip_brick_extent(l, level, b, origin, extent);
    for (int k = 0; k < 3; k++)
        last[k] = origin[k] + extent[k] - 1;
    return ip__clip_keeps_samples(c, l, level, origin, last);
}

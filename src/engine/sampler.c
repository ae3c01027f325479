/* SPDX-License-Identifier: BSD-3-Clause */
/* Samples, cells and their triangulation for one level, read through the brick cache. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cache_prefetch.h"
#include "internal.h"
#include "sampler.h"

ip_status ip__sampler_init(ip_sampler *s, ip_cache *cache, uint32_t level)
{
    memset(s, 0, sizeof *s);
    s->cache = cache;
    s->layout = ip_store_layout(ip_cache_store(cache));
    s->level = level;
    s->edge_shift = ip__ceil_log2(s->layout->brick_edge); /* a power of two */
    s->mc_rows = ip__mc_triangle_table;
    ip_mc_frame frame;
    if (!ip__mc_frame_of(&s->layout->orientation, &frame)) {
        s->own_rows = malloc(256 * sizeof *s->own_rows);
        if (!s->own_rows)
            return IP_ERR_NOMEM;
        ip__mc_frame_rows(&frame, s->own_rows);
        s->mc_rows = (const int8_t(*)[16])s->own_rows;
    }
    for (int a = 0; a < 3; a++) {
        uint32_t n = s->dims[a] = s->layout->levels[level].dims[a];
        s->world[a] = malloc(n * sizeof(double));
        s->inverse_span[a] = malloc(n * sizeof(double));
        if (!s->world[a] || !s->inverse_span[a]) {
            ip__sampler_free(s);
            return IP_ERR_NOMEM;
        }
        for (uint32_t i = 0; i < n; i++)
            s->world[a][i] =
                ip_level_sample_index(s->layout->dims[a], level, i) * s->layout->spacing[a];
        for (uint32_t i = 0; i < n; i++) {
            double d = s->world[a][i + 1 < n ? i + 1 : i] - s->world[a][i > 0 ? i - 1 : 0];
            s->inverse_span[a][i] = d > 0 ? 1.0 / d : 0.0;
        }
    }
    return IP_OK;
}

void ip__sampler_release(ip_sampler *s)
{
    for (int i = 0; i < IP_SAMPLER_SLOTS; i++)
        if (s->used[i]) {
            ip_cache_unpin_brick(s->cache, &s->held[i]);
            s->used[i] = 0;
        }
}

void ip__sampler_free(ip_sampler *s)
{
    if (s->cache)
        ip__sampler_release(s);
    for (int a = 0; a < 3; a++) {
        free(s->world[a]);
        free(s->inverse_span[a]);
        s->world[a] = NULL;
        s->inverse_span[a] = NULL;
    }
    free(s->own_rows);
    s->own_rows = NULL;
    s->mc_rows = ip__mc_triangle_table;
}

/* The brick at `brick` (brick coordinates), pinned in a slot; with `resident_only`, NULL
 * when the cache does not hold it (nothing is read, s->status stays as it was). */
static const ip_brick *pinned_brick(ip_sampler *s, const uint32_t brick[3], int resident_only)
{
    uint64_t g = ip_brick_global_index(s->layout, s->level, brick);
    for (unsigned i = 0; i < IP_SAMPLER_SLOTS; i++)
        if (s->used[i] && s->held[i].index == g) {
            s->last = i;
            return &s->held[i];
        }
    if (s->status != IP_OK)
        return NULL;
    ip_brick got;
    if (resident_only && !ip__cache_pin_resident(s->cache, g, &got))
        return NULL;
    unsigned v = s->next_victim;
    s->next_victim = (v + 1) % IP_SAMPLER_SLOTS;
    if (s->used[v]) {
        ip_cache_unpin_brick(s->cache, &s->held[v]);
        s->used[v] = 0;
    }
    if (resident_only) {
        s->held[v] = got;
    } else {
        ip_status st = ip_cache_pin_brick(s->cache, g, &s->held[v], &s->error);
        if (st != IP_OK) {
            s->status = st;
            return NULL;
        }
    }
    s->used[v] = 1;
    s->last = v;
    return &s->held[v];
}

static const ip_brick *brick_at(ip_sampler *s, const uint32_t brick[3])
{
    return pinned_brick(s, brick, 0);
}

const ip_brick *ip__sampler_cell_brick(ip_sampler *s, const uint32_t cell[3])
{
    /* Cells come in runs within one brick (a sub-block, a propagation front): the brick of
     * the last lookup is tested first, without the global index and the scan of the slots.
     * A brick's cells are origin .. origin + B - 1 (the unsigned difference wraps below). */
    const ip_brick *last = &s->held[s->last];
    uint32_t edge = s->layout->brick_edge;
    if (s->used[s->last] && cell[0] - last->origin[0] < edge && cell[1] - last->origin[1] < edge &&
        cell[2] - last->origin[2] < edge)
        return last;
    uint32_t b[3];
    for (int a = 0; a < 3; a++)
        b[a] = cell[a] >> s->edge_shift;
    return brick_at(s, b);
}

const ip_brick *ip__sampler_resident_cell_brick(ip_sampler *s, const uint32_t cell[3])
{
    uint32_t b[3];
    for (int a = 0; a < 3; a++)
        b[a] = cell[a] >> s->edge_shift;
    return pinned_brick(s, b, 1);
}

int ip__sampler_cell_values(ip_sampler *s, const uint32_t cell[3], float values[8])
{
    const ip_brick *b = ip__sampler_cell_brick(s, cell);
    if (!b)
        return 0;
    ptrdiff_t corners[8];
    ip__corner_offsets(b, corners);
    ip__cell_values(b, s->layout->type, corners, cell, values);
    return 1;
}

void ip__sampler_cell_box(const ip_sampler *s, const uint32_t cell[3], float lo[3], float hi[3])
{
    for (int a = 0; a < 3; a++) {
        lo[a] = (float)s->world[a][cell[a]];
        hi[a] = (float)s->world[a][cell[a] + 1];
    }
}

/* Sample p of the level, clamped to the volume; any brick holding it will do (neighbouring
 * bricks share their face layers): `near`, a pinned brick, when it holds it, else the one
 * whose cells it starts. Returns 0 after a failure. */
static int sample_at(ip_sampler *s, const ip_brick *near, const int64_t p[3], float *out)
{
    uint32_t q[3], brick[3];
    int held = 1;
    for (int a = 0; a < 3; a++) {
        q[a] = (uint32_t)(p[a] < 0 ? 0 : p[a] >= s->dims[a] ? s->dims[a] - 1 : p[a]);
        held &= q[a] - near->origin[a] < near->extent[a];
        uint32_t cells = s->dims[a] - 1;
        brick[a] = (q[a] < cells ? q[a] : cells - 1) >> s->edge_shift;
    }
    const ip_brick *b = held ? near : brick_at(s, brick);
    if (!b)
        return 0;
    *out = ip_sample_get(b->samples, s->layout->type, ip__sample_index(b, q));
    return 1;
}

/* The sample next to corner c of `cell` outwards along axis a (one below the cell where the
 * corner is on its low side, one above where it is on its high side), clamped to the volume:
 * with the corner across the cell it gives the central difference of the corner's gradient.
 * Gathered as out[3 * c + a]: from the cell's brick when it holds all 24 (one typed read).
 * A cell on a face of its brick (about one in six) reads those the brick holds the same way,
 * and only the others, beyond that face, sample by sample from whichever brick holds each.
 * Returns 0 after a failure. */
static int gradient_neighbours(ip_sampler *s, const uint32_t cell[3], const ip_brick *b,
                               float out[24])
{
    ptrdiff_t stride[3] = {1, (ptrdiff_t)b->extent[0],
                           (ptrdiff_t)b->extent[0] * (ptrdiff_t)b->extent[1]};
    ptrdiff_t step[2][3]; /* to the sample below (0) or above (1) along each axis */
    int held[2][3];       /* whether the brick holds it */
    int inside = 1;
    for (int a = 0; a < 3; a++) {
        /* clamped at the volume's faces: the corner itself, which the brick holds */
        int low = cell[a] > 0, high = cell[a] + 2 < s->dims[a];
        step[0][a] = low ? -stride[a] : 0;
        step[1][a] = high ? stride[a] : 0;
        held[0][a] = !low || cell[a] > b->origin[a];
        held[1][a] = !high || cell[a] + 2 < b->origin[a] + b->extent[a];
        inside &= held[0][a] & held[1][a];
    }
    ptrdiff_t corners[8], offsets[24];
    ip__corner_offsets(b, corners);
    for (int c = 0; c < 8; c++)
        for (int a = 0; a < 3; a++)
            offsets[3 * c + a] = corners[c] + step[(c >> a) & 1][a];
    size_t first = ip__sample_index(b, cell);
    if (inside) {
        ip__samples_gather(b->samples, s->layout->type, first, offsets, 24, out);
        return 1;
    }
    /* The brick's own first: a brick read below may take the slot of `b` (the slot then
     * describes the new brick, which sample_at() checks like any other). */
    for (int c = 0; c < 8; c++)
        for (int a = 0; a < 3; a++)
            if (held[(c >> a) & 1][a])
                out[3 * c + a] =
                    ip_sample_get(b->samples, s->layout->type, first + (size_t)offsets[3 * c + a]);
    for (int c = 0; c < 8; c++)
        for (int a = 0; a < 3; a++) {
            int h = (c >> a) & 1;
            if (held[h][a])
                continue;
            int64_t p[3] = {(int64_t)cell[0] + (c & 1), (int64_t)cell[1] + ((c >> 1) & 1),
                            (int64_t)cell[2] + ((c >> 2) & 1)};
            p[a] += h ? 1 : -1;
            if (!sample_at(s, b, p, &out[3 * c + a]))
                return 0;
        }
    return 1;
}

int ip__sampler_cell_case(ip_sampler *s, const uint32_t cell[3], float iso, float values[8],
                          unsigned *mc_case)
{
    const ip_brick *b = ip__sampler_cell_brick(s, cell);
    if (!b)
        return -1;
    ptrdiff_t corners[8];
    ip__corner_offsets(b, corners);
    ip__cell_values(b, s->layout->type, corners, cell, values);
    *mc_case = ip__mc_case(values, iso);
    return 1;
}

int ip__sampler_cell_normals(ip_sampler *s, const uint32_t cell[3], const float values[8],
                             unsigned mc_case, float iso, const float lo[3], const float hi[3],
                             float normals[12][3])
{
    float outer[24], gradients[8][3];
    const ip_brick *b = ip__sampler_cell_brick(s, cell);
    if (!b || !gradient_neighbours(s, cell, b, outer))
        return -1;
    double inverse[2][3]; /* per axis, 1 / the span around the cell's low and high corners */
    for (int a = 0; a < 3; a++)
        for (int h = 0; h < 2; h++)
            inverse[h][a] = s->inverse_span[a][cell[a] + h];
    for (int c = 0; c < 8; c++)
        for (int a = 0; a < 3; a++) {
            int h = (c >> a) & 1;
            float across = values[c ^ (1 << a)];
            float vh = h ? outer[3 * c + a] : across, vl = h ? across : outer[3 * c + a];
            gradients[c][a] = (float)((double)(vh - vl) * inverse[h][a]);
        }
    return (int)ip__mc_cell_edge_normals(values, mc_case, (const float(*)[3])gradients, iso, lo, hi,
                                         normals);
}

/* Samples, cells and their triangulation for one level, read through the brick cache. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "sampler.h"

ip_status ip_sampler_init(ip_sampler *s, ip_cache *cache, uint32_t level)
{
    memset(s, 0, sizeof *s);
    s->cache = cache;
    s->layout = ip_store_layout(ip_cache_store(cache));
    s->level = level;
    for (int a = 0; a < 3; a++) {
        s->dims[a] = s->layout->levels[level].dims[a];
        s->world[a] = malloc(s->dims[a] * sizeof(double));
        if (!s->world[a]) {
            ip_sampler_free(s);
            return IP_ERR_NOMEM;
        }
        for (uint32_t i = 0; i < s->dims[a]; i++)
            s->world[a][i] =
                ip_level_sample_index(s->layout->dims[a], level, i) * s->layout->spacing[a];
    }
    return IP_OK;
}

void ip_sampler_release(ip_sampler *s)
{
    for (int i = 0; i < IP_SAMPLER_SLOTS; i++)
        if (s->used[i]) {
            ip_cache_unpin_brick(s->cache, &s->held[i]);
            s->used[i] = 0;
        }
}

void ip_sampler_free(ip_sampler *s)
{
    if (s->cache)
        ip_sampler_release(s);
    for (int a = 0; a < 3; a++) {
        free(s->world[a]);
        s->world[a] = NULL;
    }
}

static const ip_brick *brick_at(ip_sampler *s, const uint32_t brick[3])
{
    uint64_t g = ip_brick_global_index(s->layout, s->level, brick);
    for (int i = 0; i < IP_SAMPLER_SLOTS; i++)
        if (s->used[i] && s->held[i].index == g)
            return &s->held[i];
    if (s->status != IP_OK)
        return NULL;
    unsigned v = s->next_victim;
    s->next_victim = (v + 1) % IP_SAMPLER_SLOTS;
    if (s->used[v]) {
        ip_cache_unpin_brick(s->cache, &s->held[v]);
        s->used[v] = 0;
    }
    ip_status st = ip_cache_pin_brick(s->cache, g, &s->held[v], &s->error);
    if (st != IP_OK) {
        s->status = st;
        return NULL;
    }
    s->used[v] = 1;
    return &s->held[v];
}

const ip_brick *ip_sampler_cell_brick(ip_sampler *s, const uint32_t cell[3])
{
    uint32_t b[3];
    for (int a = 0; a < 3; a++)
        b[a] = cell[a] / s->layout->brick_edge;
    return brick_at(s, b);
}

static float brick_sample(const ip_brick *b, ip_type type, uint32_t x, uint32_t y, uint32_t z)
{
    return ip_sample_get(b->samples, type,
                         x + (size_t)b->extent[0] * (y + (size_t)b->extent[1] * z));
}

int ip_sampler_cell_values(ip_sampler *s, const uint32_t cell[3], float values[8])
{
    const ip_brick *b = ip_sampler_cell_brick(s, cell);
    if (!b)
        return 0;
    uint32_t x = cell[0] - b->origin[0], y = cell[1] - b->origin[1], z = cell[2] - b->origin[2];
    for (int c = 0; c < 8; c++)
        values[c] = brick_sample(b, s->layout->type, x + (c & 1), y + ((c >> 1) & 1),
                                 z + ((c >> 2) & 1));
    return 1;
}

void ip_sampler_cell_box(const ip_sampler *s, const uint32_t cell[3], float origin[3],
                         float size[3])
{
    for (int a = 0; a < 3; a++) {
        origin[a] = (float)s->world[a][cell[a]];
        size[a] = (float)(s->world[a][cell[a] + 1] - s->world[a][cell[a]]);
    }
}

/* Sample (x, y, z) of the level, clamped to the volume; any brick holding it will do. */
static float sample_at(ip_sampler *s, int64_t x, int64_t y, int64_t z, int *ok)
{
    int64_t p[3] = {x, y, z};
    uint32_t q[3], brick[3];
    for (int a = 0; a < 3; a++) {
        q[a] = (uint32_t)(p[a] < 0 ? 0 : p[a] >= s->dims[a] ? s->dims[a] - 1 : p[a]);
        uint32_t cells = s->dims[a] - 1;
        brick[a] = (q[a] < cells ? q[a] : cells - 1) / s->layout->brick_edge;
    }
    const ip_brick *b = brick_at(s, brick);
    if (!b) {
        *ok = 0;
        return 0.0f;
    }
    return brick_sample(b, s->layout->type, q[0] - b->origin[0], q[1] - b->origin[1],
                        q[2] - b->origin[2]);
}

/* The 4x4x4 samples around a cell (cell - 1 .. cell + 2, clamped), x fastest. The fast path
 * reads them from the cell's own brick when they all lie in it. */
static int neighbourhood(ip_sampler *s, const uint32_t cell[3], float v[64])
{
    const ip_brick *b = ip_sampler_cell_brick(s, cell);
    if (!b)
        return 0;
    int inside = 1;
    for (int a = 0; a < 3; a++)
        inside &= cell[a] >= b->origin[a] + 1 && cell[a] + 2 < b->origin[a] + b->extent[a];
    if (inside) {
        uint32_t x0 = cell[0] - 1 - b->origin[0], y0 = cell[1] - 1 - b->origin[1],
                 z0 = cell[2] - 1 - b->origin[2];
        for (uint32_t k = 0, i = 0; k < 4; k++)
            for (uint32_t j = 0; j < 4; j++)
                for (uint32_t h = 0; h < 4; h++, i++)
                    v[i] = brick_sample(b, s->layout->type, x0 + h, y0 + j, z0 + k);
        return 1;
    }
    int ok = 1;
    for (int k = 0, i = 0; k < 4; k++)
        for (int j = 0; j < 4; j++)
            for (int h = 0; h < 4; h++, i++)
                v[i] = sample_at(s, (int64_t)cell[0] - 1 + h, (int64_t)cell[1] - 1 + j,
                                 (int64_t)cell[2] - 1 + k, &ok);
    return ok;
}

/* World distance between the samples either side of sample i (clamped) along axis a, and
 * which neighbours those are, for a central (or one-sided) difference. */
static double span(const ip_sampler *s, int a, int64_t i, int *lo, int *hi)
{
    int64_t last = s->dims[a] - 1;
    int64_t l = i > 0 ? i - 1 : 0, h = i < last ? i + 1 : last;
    *lo = (int)(l - i);
    *hi = (int)(h - i);
    return s->world[a][h] - s->world[a][l];
}

int ip_sampler_triangulate(ip_sampler *s, const uint32_t cell[3], float iso, ip_mc_vertex *out,
                           unsigned *mc_case)
{
    float v[64], values[8], gradients[8][3], origin[3], size[3];
    if (!neighbourhood(s, cell, v))
        return -1;
    for (int c = 0; c < 8; c++) {
        int cx = 1 + (c & 1), cy = 1 + ((c >> 1) & 1), cz = 1 + ((c >> 2) & 1);
        int at[3] = {cx, cy, cz};
        values[c] = v[cx + 4 * (cy + 4 * cz)];
        for (int a = 0; a < 3; a++) {
            int lo, hi;
            double d = span(s, a, (int64_t)cell[a] + at[a] - 1, &lo, &hi);
            int step = a == 0 ? 1 : a == 1 ? 4 : 16;
            float vh = v[cx + 4 * (cy + 4 * cz) + hi * step];
            float vl = v[cx + 4 * (cy + 4 * cz) + lo * step];
            gradients[c][a] = d > 0 ? (float)((vh - vl) / d) : 0.0f;
        }
    }
    *mc_case = ip_mc_case(values, iso);
    if (*mc_case == 0 || *mc_case == 255)
        return 0;
    ip_sampler_cell_box(s, cell, origin, size);
    return ip_mc_triangulate_cell(values, (const float(*)[3])gradients, iso, origin, size, out);
}

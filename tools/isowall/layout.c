/* SPDX-License-Identifier: BSD-3-Clause */
/* The wall's screen regions and the tiles a mesh reaches. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "isowall.h"

/* Cell (cx, cy) of the i-th step of the ordered-dither order over a 2^levels square grid: the
 * lowest base-4 digit of i picks the quadrant, the next the sub-quadrant, and so on, taken in
 * the order (low, low), (high, high), (high, low), (low, high), so that any prefix of the
 * order is spread over the grid (the ray order's coarse levels, over regions). */
static void dither_cell(uint64_t i, uint32_t levels, uint32_t *cx, uint32_t *cy)
{
    static const uint8_t dx[4] = {0, 1, 1, 0}, dy[4] = {0, 1, 0, 1};
    *cx = *cy = 0;
    for (uint32_t s = 0; s < levels; s++) {
        unsigned digit = (unsigned)(i >> 2 * s) & 3u;
        *cx |= (uint32_t)dx[digit] << (levels - 1 - s);
        *cy |= (uint32_t)dy[digit] << (levels - 1 - s);
    }
}

int wall_layout_regions(wall_layout *w, uint32_t unit_w, uint32_t unit_h)
{
    uint32_t per_x = (w->tile_w + unit_w - 1) / unit_w, per_y = (w->tile_h + unit_h - 1) / unit_h;
    uint32_t grid_x = per_x * w->cols, grid_y = per_y * w->rows, levels = 0;
    while ((1u << levels) < grid_x || (1u << levels) < grid_y)
        levels++;
    w->region_count = grid_x * grid_y;
    w->regions = malloc((size_t)w->region_count * sizeof *w->regions);
    if (!w->regions)
        return -1;
    uint32_t n = 0;
    for (uint64_t i = 0; n < w->region_count && i < (uint64_t)1 << 2 * levels; i++) {
        uint32_t gx, gy;
        dither_cell(i, levels, &gx, &gy);
        if (gx >= grid_x || gy >= grid_y)
            continue;
        uint32_t col = gx / per_x, row = gy / per_y, ux = gx % per_x, uy = gy % per_y;
        wall_region *r = &w->regions[n++];
        r->x = col * w->tile_w + ux * unit_w;
        r->y = row * w->tile_h + uy * unit_h;
        r->width = ux + 1 < per_x ? unit_w : w->tile_w - ux * unit_w;
        r->height = uy + 1 < per_y ? unit_h : w->tile_h - uy * unit_h;
        r->tile = row * w->cols + col;
        r->gx = gx, r->gy = gy;
    }
    return 0;
}

/* The Z-order key of grid cell (x, y): their bits interleaved, x's in the even places. */
static uint64_t z_key(uint32_t x, uint32_t y)
{
    uint64_t key = 0;
    for (unsigned b = 0; b < 32; b++)
        key |= (uint64_t)(x >> b & 1u) << 2 * b | (uint64_t)(y >> b & 1u) << (2 * b + 1);
    return key;
}

typedef struct keyed {
    uint64_t key;
    uint32_t region;
} keyed;

static int compare_key(const void *a, const void *b)
{
    const keyed *x = a, *y = b;
    return (x->key > y->key) - (x->key < y->key);
}

int wall_spatial_order(const wall_layout *w, uint32_t *order)
{
    keyed *k = malloc((size_t)w->region_count * sizeof *k);
    if (!k)
        return -1;
    for (uint32_t i = 0; i < w->region_count; i++) {
        k[i] = (keyed){z_key(w->regions[i].gx, w->regions[i].gy), i};
    }
    qsort(k, w->region_count, sizeof *k, compare_key);
    for (uint32_t i = 0; i < w->region_count; i++)
        order[i] = k[i].region;
    free(k);
    return 0;
}

uint64_t wall_coarse_rays(const wall_region *r)
{
    uint64_t pixels = (uint64_t)r->width * r->height;
    return (pixels + 63) / 64;
}

void wall_touched_tiles(const wall_layout *w, const ip_mesh *mesh, uint8_t *touched)
{
    ip_camera_basis basis;
    ip_camera_basis_of(&w->camera, &basis);
    memset(touched, 0, w->tile_count);
    double width = w->camera.width, height = w->camera.height;
    for (uint64_t t = 0; t < mesh->triangle_count; t++) {
        double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
        int behind = 0;
        for (int k = 0; k < 3; k++) {
            const float *p = mesh->positions + 9 * t + 3 * k;
            double world[3] = {p[0], p[1], p[2]}, px, py, depth;
            if (!ip_camera_project(&basis, &w->camera, world, &px, &py, &depth)) {
                behind = 1;
                break;
            }
            x0 = fmin(x0, px), x1 = fmax(x1, px), y0 = fmin(y0, py), y1 = fmax(y1, py);
        }
        if (behind) { /* it may reach anywhere once clipped: every tile */
            memset(touched, 1, w->tile_count);
            return;
        }
        /* the pixels whose centres the bounds may hold, one pixel of margin for the snapping */
        if (x1 < -1 || y1 < -1 || x0 > width + 1 || y0 > height + 1)
            continue;
        double cx0 = fmax(0, floor(x0) - 1), cx1 = fmin(width - 1, floor(x1) + 1);
        double cy0 = fmax(0, floor(y0) - 1), cy1 = fmin(height - 1, floor(y1) + 1);
        for (uint32_t row = (uint32_t)cy0 / w->tile_h; row <= (uint32_t)cy1 / w->tile_h; row++)
            for (uint32_t col = (uint32_t)cx0 / w->tile_w; col <= (uint32_t)cx1 / w->tile_w; col++)
                touched[row * w->cols + col] = 1;
    }
}

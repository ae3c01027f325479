/* SPDX-License-Identifier: BSD-3-Clause */
/* The canvas: the software rasterizer's image of a growing mesh, kept from frame to frame so
 * that each frame draws only the triangles added since the last and shades only the pixels
 * they changed. */
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "pool.h"
#include "raster_core.h"

/* Rows are drawn in bands of whole multiples of this many rows, one band per thread. */
#define BAND_ROWS 8

struct ip_canvas {
    ip__pool *pool;
    unsigned bands;         /* the pool's threads: one band of rows each */
    uint32_t width, height; /* of the image, pixels */
    size_t capacity;        /* pixels the buffers hold */
    double *inverse_depth;  /* the raster target's buffers, width * height each */
    uint32_t *index;
    float *normal;
    uint8_t *dirty; /* 1 where a fragment was written since the last shading */
    uint8_t *rgba;
    ip_camera camera;
    ip_camera_basis basis;
    ip_raster_view view;
    ip_shading shading;
    int begun;
    uint64_t triangles; /* added since begin */
    /* the current call's work, read by the jobs */
    const ip_mesh *mesh;
    uint64_t first, count;
    uint32_t band_rows[IP_MAX_THREADS][2]; /* per band: the first and last + 1 row shaded */
};

ip_status ip_canvas_create(unsigned threads, ip_canvas **out, ip_error *err)
{
    *out = NULL;
    ip_canvas *c = calloc(1, sizeof *c);
    if (!c)
        return ip__fail(err, IP_ERR_NOMEM, "canvas: out of memory");
    ip_status st = ip__pool_create(ip_thread_count(threads), &c->pool, err);
    if (st != IP_OK) {
        free(c);
        return st;
    }
    c->bands = ip__pool_threads(c->pool);
    ip_shading_default(&c->shading);
    *out = c;
    return IP_OK;
}

static void free_buffers(ip_canvas *c)
{
    free(c->inverse_depth);
    free(c->index);
    free(c->normal);
    free(c->dirty);
    free(c->rgba);
    c->inverse_depth = NULL;
    c->index = NULL;
    c->normal = NULL;
    c->dirty = NULL;
    c->rgba = NULL;
    c->capacity = 0;
}

void ip_canvas_destroy(ip_canvas *c)
{
    if (!c)
        return;
    ip__pool_destroy(c->pool);
    free_buffers(c);
    free(c);
}

static ip_status reserve_pixels(ip_canvas *c, size_t pixels, ip_error *err)
{
    if (pixels <= c->capacity)
        return IP_OK;
    free_buffers(c);
    c->inverse_depth = malloc(pixels * sizeof *c->inverse_depth);
    c->index = malloc(pixels * sizeof *c->index);
    c->normal = malloc(pixels * 3 * sizeof *c->normal);
    c->dirty = malloc(pixels);
    c->rgba = malloc(pixels * 4);
    if (!c->inverse_depth || !c->index || !c->normal || !c->dirty || !c->rgba) {
        free_buffers(c);
        return ip__fail(err, IP_ERR_NOMEM, "canvas: out of memory for a %zu-pixel image", pixels);
    }
    c->capacity = pixels;
    return IP_OK;
}

/* Band b's rows [*y0, *y1): whole multiples of BAND_ROWS, split evenly. */
static void band_of(const ip_canvas *c, unsigned b, uint32_t *y0, uint32_t *y1)
{
    uint32_t blocks = (c->height + BAND_ROWS - 1) / BAND_ROWS;
    uint32_t first = (uint32_t)((uint64_t)blocks * b / c->bands) * BAND_ROWS;
    uint32_t last = (uint32_t)((uint64_t)blocks * (b + 1) / c->bands) * BAND_ROWS;
    *y0 = first < c->height ? first : c->height;
    *y1 = last < c->height ? last : c->height;
}

/* The raster target of band b: the canvas's buffers from its first row on. */
static ip_raster_target band_target(ip_canvas *c, unsigned b)
{
    uint32_t y0, y1;
    band_of(c, b, &y0, &y1);
    size_t at = (size_t)y0 * c->width;
    ip_raster_target t = {
        c->width,           y1 - y0,      0, y0, c->inverse_depth + at, c->index + at,
        c->normal + 3 * at, c->dirty + at};
    return t;
}

/* Job: band b clears its rows to the background (every pixel to be shaded). */
static void clear_band(void *user, unsigned b)
{
    ip_canvas *c = user;
    ip_raster_target t = band_target(c, b);
    size_t pixels = (size_t)t.width * t.height;
    for (size_t i = 0; i < pixels; i++) {
        t.inverse_depth[i] = 0;
        t.index[i] = UINT32_MAX;
    }
    memset(t.dirty, 1, pixels);
}

ip_status ip_canvas_begin(ip_canvas *c, const ip_camera *camera, const ip_shading *shading,
                          const double lo[3], const double hi[3], ip_error *err)
{
    ip_status st = ip_camera_check(camera, err);
    if (st == IP_OK)
        st = ip_render_check_box(lo, hi, err);
    ip_shading taken;
    if (st == IP_OK)
        st = ip__shading_take(shading, &taken, err);
    if (st != IP_OK)
        return st;
    if (camera->width > 65536 || camera->height > 65536)
        return ip__fail(err, IP_ERR_ARGUMENT, "canvas: image %ux%u is larger than 65536x65536",
                        camera->width, camera->height);
    c->begun = 0;
    st = reserve_pixels(c, (size_t)camera->width * camera->height, err);
    if (st != IP_OK)
        return st;
    c->width = camera->width;
    c->height = camera->height;
    c->camera = *camera;
    ip_camera_basis_of(camera, &c->basis);
    ip__raster_setup_view(&c->view, camera, lo, hi);
    c->shading = taken;
    c->triangles = 0;
    ip__pool_run(c->pool, c->bands, clear_band, c);
    c->begun = 1;
    return IP_OK;
}

/* Job: band b draws the call's triangles that reach its rows. */
static void draw_band(void *user, unsigned b)
{
    ip_canvas *c = user;
    ip_raster_target t = band_target(c, b);
    if (t.height)
        ip__raster_range(&t, &c->view, c->mesh, c->first, c->count, (uint32_t)c->first);
}

/* Job: the call's triangles over the whole image, on one thread. */
static void draw_all(void *user, unsigned job)
{
    ip_canvas *c = user;
    (void)job;
    ip_raster_target t = {c->width,         c->height, 0,         0,
                          c->inverse_depth, c->index,  c->normal, c->dirty};
    ip__raster_range(&t, &c->view, c->mesh, c->first, c->count, (uint32_t)c->first);
}

ip_status ip_canvas_add(ip_canvas *c, const ip_mesh *mesh, uint64_t first, ip_error *err)
{
    if (!c->begun)
        return ip__fail(err, IP_ERR_ARGUMENT, "canvas: ip_canvas_add() before ip_canvas_begin()");
    if (first != c->triangles || first > mesh->triangle_count)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "canvas: triangles from %llu added, but it holds %llu and the mesh %llu",
                        (unsigned long long)first, (unsigned long long)c->triangles,
                        (unsigned long long)mesh->triangle_count);
    if (mesh->triangle_count >= UINT32_MAX)
        return ip__fail(err, IP_ERR_ARGUMENT, "canvas: %llu triangles are too many",
                        (unsigned long long)mesh->triangle_count);
    uint64_t count = mesh->triangle_count - first;
    if (count == 0)
        return IP_OK;
    c->mesh = mesh;
    c->first = first;
    c->count = count;
    /* a few triangles are not worth waking the other threads for */
    ip__pool_run(c->pool, count < 64 ? 1 : c->bands, count < 64 ? draw_all : draw_band, c);
    c->mesh = NULL;
    c->triangles = mesh->triangle_count;
    return IP_OK;
}

/* Job: band b shades the pixels written since the last shading and records the rows it
 * changed. */
static void shade_band(void *user, unsigned b)
{
    ip_canvas *c = user;
    uint32_t y0, y1, first = UINT32_MAX, last = 0;
    band_of(c, b, &y0, &y1);
    for (uint32_t y = y0; y < y1; y++) {
        size_t row = (size_t)y * c->width;
        uint8_t *dirty = c->dirty + row, *end = dirty + c->width;
        uint8_t background[4];
        int have_background = 0;
        for (uint8_t *d = memchr(dirty, 1, c->width); d; d = memchr(d, 1, (size_t)(end - d))) {
            size_t x = (size_t)(d - dirty), pixel = row + x;
            uint8_t *out = c->rgba + 4 * pixel;
            *d++ = 0;
            first = y < first ? y : first;
            last = y + 1;
            if (c->index[pixel] == UINT32_MAX) {
                if (!have_background)
                    ip__raster_background(&c->shading, y, c->height, background);
                have_background = 1;
                memcpy(out, background, 4);
            } else {
                double ray[3], value[3]; /* |n . -ray| = |n . ray| */
                ip_camera_pixel_ray(&c->basis, &c->camera, (double)x + 0.5, (double)y + 0.5, ray);
                ip__raster_shade(&c->shading, c->shading.surface, c->normal + 3 * pixel, ray,
                                 value);
                for (int k = 0; k < 3; k++)
                    out[k] = ip__raster_unorm8(value[k]);
                out[3] = 255;
            }
            if (d == end)
                break;
        }
    }
    c->band_rows[b][0] = first;
    c->band_rows[b][1] = last;
}

const uint8_t *ip_canvas_shade(ip_canvas *c, uint32_t rows[2])
{
    uint32_t first = UINT32_MAX, last = 0;
    if (c->begun) {
        ip__pool_run(c->pool, c->bands, shade_band, c);
        for (unsigned b = 0; b < c->bands; b++) {
            first = c->band_rows[b][0] < first ? c->band_rows[b][0] : first;
            last = c->band_rows[b][1] > last ? c->band_rows[b][1] : last;
        }
    }
    if (rows) {
        rows[0] = first < last ? first : 0;
        rows[1] = first < last ? last : 0;
    }
    return c->begun ? c->rgba : NULL;
}

const uint32_t *ip_canvas_triangle_index(const ip_canvas *c)
{
    return c->begun ? c->index : NULL;
}

uint64_t ip_canvas_triangle_count(const ip_canvas *c)
{
    return c->triangles;
}

size_t ip_canvas_memory(const ip_canvas *c)
{
    return c->capacity *
           (sizeof *c->inverse_depth + sizeof *c->index + 3 * sizeof *c->normal + 1 + 4);
}

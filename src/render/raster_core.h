/* SPDX-License-Identifier: BSD-3-Clause */
/* The software rasterizer's core, shared by the one-off images (raster.c) and the canvas that
 * draws a growing mesh frame after frame (canvas.c). Internal. */
#ifndef ISOPROP_RASTER_CORE_H
#define ISOPROP_RASTER_CORE_H

#include <stdint.h>

#include "isoprop/render.h"

/* A vertex in view space: x right, y up, z the depth along the view direction (world units);
 * the normal stays in world space. */
typedef struct view_vertex {
    double p[3];
    double n[3];
} view_vertex;

/* What a camera and the volume's box give every triangle: the basis, the near and far planes
 * and the guard band. */
typedef struct ip_raster_view {
    ip_camera_basis basis;
    double eye[3];
    double near_plane, far_plane;
    double guard_x, guard_y; /* the guard band as bounds on x / z and y / z */
    double width, height;
} ip_raster_view;

/* The buffers of a part of the camera's image (rows of `width` pixels, top row first). */
typedef struct ip_raster_target {
    uint32_t width, height; /* of the part drawn */
    uint32_t x, y;          /* its top-left pixel in the camera's image */
    double *inverse_depth;  /* 1 / view depth of the nearest surface; 0 where empty */
    uint32_t *index;
    float *normal;  /* 3 per pixel, or NULL when no image is wanted */
    uint8_t *dirty; /* NULL, or a byte per pixel set to 1 where a fragment is written */
} ip_raster_target;

/* The view of `camera` with near and far planes from the box [lo, hi] (checked). */
void ip__raster_setup_view(ip_raster_view *v, const ip_camera *camera, const double lo[3],
                           const double hi[3]);

/* Rasterizes triangles [first, first + count) of `mesh` into t, numbered from `first_index` on:
 * the nearest fragment wins each pixel, on equal depth the one drawn first. */
void ip__raster_range(ip_raster_target *t, const ip_raster_view *view, const ip_mesh *mesh,
                      uint64_t first, uint64_t count, uint32_t first_index);

/* A channel value in [0, 1] (clamped) as 8 bits, round(255 * v). */
uint8_t ip__raster_unorm8(double v);

/* The caller's shading (a sized struct: include/isoprop/status.h; NULL: ip_shading_default())
 * as the library's own, checked as ip_shading_check() does. */
ip_status ip__shading_take(const ip_shading *given, ip_shading *taken, ip_error *err);

/* The background of image row `row` of `height` rows. */
void ip__raster_background(const ip_shading *s, uint32_t row, uint32_t height, uint8_t out[4]);

/* The shaded colour of a surface of colour `colour`, before rounding. n: the interpolated
 * normal (any length); v: the unit vector toward the eye. */
void ip__raster_shade(const ip_shading *s, const float colour[3], const float n[3],
                      const double v[3], double out[3]);

#endif

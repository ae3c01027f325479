/* SPDX-License-Identifier: BSD-3-Clause */
/* The software reference rasterizer: exact coverage, depth and shading of a mesh, no GPU. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "isoprop/render.h"
#include "raster_core.h"
#include "sized.h"
#include "vec3.h"

/* Vertices snap to 1/256 pixel, as GPUs do; edge functions are then exact 64-bit integers, so
 * two triangles sharing an edge agree on every pixel centre. Clipping to a guard band keeps
 * snapped coordinates within 2^20 pixels of the image, so products of coordinate differences
 * stay below 2^60. */
enum {
    SUBPIXEL_BITS = 8,
    MAX_SIDE = 65536,
    MAX_POLYGON = 9,
    PLANE_COUNT = 6
};
#define SUBPIXEL ((int64_t)1 << SUBPIXEL_BITS)
#define GUARD_PIXELS 1048576.0

void ip_shading_default(ip_shading *s)
{
    static const ip_shading defaults = {
        .surface = {0.93f, 0.89f, 0.79f},
        .ambient = 0.12f,
        .diffuse = 0.80f,
        .specular = 0.12f,
        .shininess = 32.0f,
        .background_top = {0.24f, 0.27f, 0.34f},
        .background_bottom = {0.08f, 0.09f, 0.13f},
    };
    *s = defaults;
    s->size = sizeof *s;
}

/* Whether every channel of the colour is in [0, 1] (NaN is not). */
static int is_unit_colour(const float c[3])
{
    for (int i = 0; i < 3; i++)
        if (!(c[i] >= 0.0f && c[i] <= 1.0f))
            return 0;
    return 1;
}

ip_status ip_shading_check(const ip_shading *given, ip_error *err)
{
    ip_shading taken;
    return ip__shading_take(given, &taken, err);
}

/* The checks of ip_shading_check() on the library's own copy. */
static ip_status check_shading(const ip_shading *s, ip_error *err)
{
    if (!is_unit_colour(s->surface) || !is_unit_colour(s->background_top) ||
        !is_unit_colour(s->background_bottom))
        return ip__fail(err, IP_ERR_ARGUMENT, "shading: a colour channel is outside [0, 1]");
    if (!(s->ambient >= 0.0f && s->diffuse >= 0.0f && s->specular >= 0.0f) ||
        !isfinite(s->ambient) || !isfinite(s->diffuse) || !isfinite(s->specular) ||
        !(s->shininess > 0.0f) || !isfinite(s->shininess))
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "shading: ambient, diffuse and specular must be finite and >= 0, "
                        "shininess finite and > 0");
    return IP_OK;
}

ip_status ip__shading_take(const ip_shading *given, ip_shading *taken, ip_error *err)
{
    ip_shading_default(taken);
    if (!given)
        return IP_OK;
    ip_status st = ip__sized_in(taken, sizeof *taken, given,
                                IP__SIZE_UPTO(ip_shading, background_bottom), "shading", err);
    return st == IP_OK ? check_shading(taken, err) : st;
}

uint8_t ip__raster_unorm8(double v)
{
    v = v < 0.0 ? 0.0 : v > 1.0 ? 1.0 : v;
    return (uint8_t)floor(v * 255.0 + 0.5);
}

void ip__raster_background(const ip_shading *s, uint32_t row, uint32_t height, uint8_t out[4])
{
    double t = (row + 0.5) / height;
    for (int i = 0; i < 3; i++)
        out[i] = ip__raster_unorm8(s->background_top[i] +
                                   t * (s->background_bottom[i] - (double)s->background_top[i]));
    out[3] = 255;
}

/* The shaded colour of a surface of colour `colour`, before rounding. n: the interpolated
 * normal (any length); v: the unit vector toward the eye. */
void ip__raster_shade(const ip_shading *s, const float colour[3], const float n[3],
                      const double v[3], double out[3])
{
    const double normal[3] = {n[0], n[1], n[2]};
    double len = ip__vec3_length(normal);
    double c = 1.0;
    if (len > 1e-12)
        c = fmin(1.0, fabs(ip__vec3_dot(normal, v)) / len);
    double light = s->ambient + s->diffuse * c, highlight = s->specular * pow(c, s->shininess);
    for (int i = 0; i < 3; i++)
        out[i] = colour[i] * light + highlight;
}

void ip__raster_setup_view(ip_raster_view *v, const ip_camera *c, const double lo[3],
                           const double hi[3])
{
    ip_camera_basis_of(c, &v->basis);
    memcpy(v->eye, c->eye, sizeof v->eye);
    ip_camera_depth_range(c, lo, hi, &v->near_plane, &v->far_plane);
    v->width = c->width;
    v->height = c->height;
    double side = c->width > c->height ? c->width : c->height;
    v->guard_x = GUARD_PIXELS / side * v->basis.tan_half_x;
    v->guard_y = GUARD_PIXELS / side * v->basis.tan_half_y;
}

static void to_view(const ip_raster_view *v, const float *p, const int16_t *n, view_vertex *out)
{
    double d[3] = {p[0] - v->eye[0], p[1] - v->eye[1], p[2] - v->eye[2]};
    const double *r = v->basis.right, *u = v->basis.up, *f = v->basis.forward;
    out->p[0] = ip__vec3_dot(d, r);
    out->p[1] = ip__vec3_dot(d, u);
    out->p[2] = ip__vec3_dot(d, f);
    for (int i = 0; i < 3; i++)
        out->n[i] = ip_normal_unpack(n[i]);
}

/* Signed distance-like value of a vertex to clip plane k; inside when >= 0. */
static double plane_value(const ip_raster_view *v, int k, const view_vertex *a)
{
    const double *p = a->p;
    switch (k) {
    case 0: return p[2] - v->near_plane;
    case 1: return v->far_plane - p[2];
    case 2: return p[0] + v->guard_x * p[2];
    case 3: return v->guard_x * p[2] - p[0];
    case 4: return p[1] + v->guard_y * p[2];
    default: return v->guard_y * p[2] - p[1];
    }
}

/* The point where edge (a, b) crosses plane k. Computed from the inside end toward the
 * outside one, so both triangles sharing the edge get the same point. */
static view_vertex crossing(const view_vertex *a, double da, const view_vertex *b, double db)
{
    if (da < 0) {
        const view_vertex *t = a;
        double dt = da;
        a = b, da = db, b = t, db = dt;
    }
    double t = da / (da - db);
    view_vertex out;
    for (int i = 0; i < 3; i++) {
        out.p[i] = a->p[i] + t * (b->p[i] - a->p[i]);
        out.n[i] = a->n[i] + t * (b->n[i] - a->n[i]);
    }
    return out;
}

/* Sutherland-Hodgman against one plane; returns the new vertex count. */
static int clip_polygon(const ip_raster_view *v, int k, const view_vertex *in, int count,
                        view_vertex *out)
{
    int n = 0;
    for (int i = 0; i < count; i++) {
        const view_vertex *a = &in[i], *b = &in[(i + 1) % count];
        double da = plane_value(v, k, a), db = plane_value(v, k, b);
        if (da >= 0)
            out[n++] = *a;
        if ((da >= 0) != (db >= 0))
            out[n++] = crossing(a, da, b, db);
    }
    return n;
}

typedef struct screen_vertex {
    int64_t x, y;         /* pixels * SUBPIXEL, top-left origin */
    double inverse_depth; /* 1 / view depth */
    const double *n;
} screen_vertex;

static void to_screen(const ip_raster_view *v, const view_vertex *a, screen_vertex *s)
{
    double iz = 1.0 / a->p[2];
    double px = (a->p[0] * iz / v->basis.tan_half_x + 1.0) * 0.5 * v->width;
    double py = (1.0 - a->p[1] * iz / v->basis.tan_half_y) * 0.5 * v->height;
    s->x = (int64_t)floor(px * SUBPIXEL + 0.5);
    s->y = (int64_t)floor(py * SUBPIXEL + 0.5);
    s->inverse_depth = iz;
    s->n = a->n;
}

static int64_t floor_div(int64_t a, int64_t b)
{
    int64_t q = a / b;
    return q * b > a ? q - 1 : q;
}

/* One edge function E(P) = (b - a) x (P - a), positive inside, stepped per pixel. */
typedef struct edge {
    int64_t value;  /* at the current pixel centre, minus the fill-rule bias */
    int64_t step_x; /* change per pixel to the right */
    int64_t step_y; /* change per pixel down */
    int64_t bias;   /* 0 on a top or left edge, 1 otherwise */
} edge;

static edge make_edge(const screen_vertex *a, const screen_vertex *b, int64_t px, int64_t py)
{
    int64_t dx = b->x - a->x, dy = b->y - a->y;
    edge e;
    /* with the winding made clockwise on screen (y down), a top edge runs left to right and
     * a left edge runs upward */
    e.bias = (dy == 0 && dx > 0) || dy < 0 ? 0 : 1;
    e.value = dx * (py - a->y) - dy * (px - a->x) - e.bias;
    e.step_x = -dy * SUBPIXEL;
    e.step_y = dx * SUBPIXEL;
    return e;
}

static void write_fragment(ip_raster_target *t, size_t pixel, const screen_vertex v[3],
                           const int64_t w[3], double inverse_area, uint32_t index)
{
    double q[3], inverse_depth = 0;
    for (int i = 0; i < 3; i++) {
        q[i] = (double)w[i] * inverse_area * v[i].inverse_depth;
        inverse_depth += q[i];
    }
    if (!(inverse_depth > t->inverse_depth[pixel]))
        return;
    t->inverse_depth[pixel] = inverse_depth;
    t->index[pixel] = index;
    if (t->dirty)
        t->dirty[pixel] = 1;
    if (!t->normal)
        return;
    for (int k = 0; k < 3; k++)
        t->normal[3 * pixel + k] =
            (float)((q[0] * v[0].n[k] + q[1] * v[1].n[k] + q[2] * v[2].n[k]) / inverse_depth);
}

static void scan_triangle(ip_raster_target *t, const screen_vertex v[3], int64_t area,
                          uint32_t index)
{
    int64_t min_x = v[0].x, max_x = v[0].x, min_y = v[0].y, max_y = v[0].y;
    for (int i = 1; i < 3; i++) {
        min_x = v[i].x < min_x ? v[i].x : min_x;
        max_x = v[i].x > max_x ? v[i].x : max_x;
        min_y = v[i].y < min_y ? v[i].y : min_y;
        max_y = v[i].y > max_y ? v[i].y : max_y;
    }
    const int64_t half = SUBPIXEL / 2;
    /* the pixels whose centre x * SUBPIXEL + half lies within the bounding box */
    int64_t x0 = floor_div(min_x - half + SUBPIXEL - 1, SUBPIXEL);
    int64_t x1 = floor_div(max_x - half, SUBPIXEL);
    int64_t y0 = floor_div(min_y - half + SUBPIXEL - 1, SUBPIXEL);
    int64_t y1 = floor_div(max_y - half, SUBPIXEL);
    int64_t left = t->x, top = t->y, right = left + t->width - 1, bottom = top + t->height - 1;
    x0 = x0 < left ? left : x0;
    y0 = y0 < top ? top : y0;
    x1 = x1 > right ? right : x1;
    y1 = y1 > bottom ? bottom : y1;
    if (x0 > x1 || y0 > y1)
        return;
    int64_t px = x0 * SUBPIXEL + half, py = y0 * SUBPIXEL + half;
    double inverse_area = 1.0 / (double)area;
    /* edge i is opposite vertex i, so its value is vertex i's barycentric weight * area */
    edge e[3] = {make_edge(&v[1], &v[2], px, py), make_edge(&v[2], &v[0], px, py),
                 make_edge(&v[0], &v[1], px, py)};
    for (int64_t y = y0; y <= y1; y++) {
        int64_t r[3] = {e[0].value, e[1].value, e[2].value};
        for (int64_t x = x0; x <= x1; x++) {
            if ((r[0] | r[1] | r[2]) >= 0) {
                int64_t w[3] = {r[0] + e[0].bias, r[1] + e[1].bias, r[2] + e[2].bias};
                write_fragment(t, (size_t)(y - top) * t->width + (size_t)(x - left), v, w,
                               inverse_area, index);
            }
            for (int i = 0; i < 3; i++)
                r[i] += e[i].step_x;
        }
        for (int i = 0; i < 3; i++)
            e[i].value += e[i].step_y;
    }
}

static void raster_triangle(ip_raster_target *t, const ip_raster_view *view, const view_vertex *a,
                            const view_vertex *b, const view_vertex *c, uint32_t index)
{
    screen_vertex v[3];
    to_screen(view, a, &v[0]);
    to_screen(view, b, &v[1]);
    to_screen(view, c, &v[2]);
    int64_t area = (v[1].x - v[0].x) * (v[2].y - v[0].y) - (v[1].y - v[0].y) * (v[2].x - v[0].x);
    if (area == 0)
        return;
    if (area < 0) {
        screen_vertex s = v[1];
        v[1] = v[2];
        v[2] = s;
        area = -area;
    }
    scan_triangle(t, v, area, index);
}

/* Clips the triangle where it leaves the view volume or the guard band, then rasterizes the
 * pieces. Returns without work when the triangle lies outside one plane entirely. */
static void clip_and_raster(ip_raster_target *t, const ip_raster_view *view,
                            const view_vertex tri[3], uint32_t index)
{
    unsigned outside_all = (1u << PLANE_COUNT) - 1, outside_any = 0;
    for (int i = 0; i < 3; i++) {
        if (!isfinite(tri[i].p[0]) || !isfinite(tri[i].p[1]) || !isfinite(tri[i].p[2]))
            return;
        unsigned mask = 0;
        for (int k = 0; k < PLANE_COUNT; k++)
            mask |= (plane_value(view, k, &tri[i]) < 0 ? 1u : 0u) << k;
        outside_all &= mask;
        outside_any |= mask;
    }
    if (outside_all)
        return;
    if (!outside_any) {
        raster_triangle(t, view, &tri[0], &tri[1], &tri[2], index);
        return;
    }
    view_vertex poly[2][MAX_POLYGON];
    int count = 3, cur = 0;
    memcpy(poly[0], tri, 3 * sizeof *tri);
    for (int k = 0; k < PLANE_COUNT && count >= 3; k++) {
        if (!(outside_any & (1u << k)))
            continue;
        count = clip_polygon(view, k, poly[cur], count, poly[1 - cur]);
        cur = 1 - cur;
    }
    for (int i = 1; i + 1 < count; i++)
        raster_triangle(t, view, &poly[cur][0], &poly[cur][i], &poly[cur][i + 1], index);
}

/* The buffers of an image's surfaces, all of one part of the camera's image: one target for the
 * opaque surfaces together (triangles numbered across them in surface order), one for each
 * translucent one; first[i] is surface i's first triangle number in its target. One mesh is
 * one opaque surface. */
typedef struct surface_targets {
    ip_raster_target opaque;
    ip_raster_target layer[IP_MAX_SURFACES]; /* of the translucent surfaces */
    uint32_t first[IP_MAX_SURFACES];
} surface_targets;

static int is_opaque(const ip_surface *f)
{
    return f->opacity >= 1.0f;
}

/* The surface the opaque target's triangle `index` belongs to. */
static size_t opaque_surface_of(const surface_targets *st, const ip_surface *surfaces, size_t count,
                                uint32_t index)
{
    size_t found = 0;
    for (size_t i = 0; i < count; i++)
        if (is_opaque(&surfaces[i]) && st->first[i] <= index)
            found = i;
    return found;
}

/* The pixel's colour: the nearest opaque surface (or the background), then each translucent
 * surface whose nearest fragment is at least as near, blended over it in surface order. */
static void shade_surfaces_pixel(const surface_targets *st, const ip_surface *surfaces,
                                 size_t count, const ip_shading *s, const double ray[3],
                                 size_t pixel, uint8_t out[4])
{
    const ip_raster_target *o = &st->opaque;
    double value[3];
    if (o->index[pixel] != UINT32_MAX) {
        const ip_surface *f = &surfaces[opaque_surface_of(st, surfaces, count, o->index[pixel])];
        ip__raster_shade(s, f->colour, o->normal + 3 * pixel, ray, value);
        for (int k = 0; k < 3; k++)
            out[k] = ip__raster_unorm8(value[k]);
    }
    for (size_t i = 0; i < count; i++) {
        const ip_raster_target *t = &st->layer[i];
        if (is_opaque(&surfaces[i]) || t->index[pixel] == UINT32_MAX ||
            t->inverse_depth[pixel] < o->inverse_depth[pixel])
            continue;
        double a = surfaces[i].opacity;
        ip__raster_shade(s, surfaces[i].colour, t->normal + 3 * pixel, ray, value);
        for (int k = 0; k < 3; k++)
            out[k] = ip__raster_unorm8(a * fmin(1.0, fmax(0.0, value[k])) +
                                       (1.0 - a) * (out[k] / 255.0));
    }
}

/* Whether a surface shows at the pixel. */
static int is_covered(const surface_targets *st, const ip_surface *surfaces, size_t count,
                      size_t pixel)
{
    if (st->opaque.index[pixel] != UINT32_MAX)
        return 1;
    for (size_t i = 0; i < count; i++)
        if (!is_opaque(&surfaces[i]) && st->layer[i].index[pixel] != UINT32_MAX)
            return 1;
    return 0;
}

/* Shades the part of the image the targets hold into rgba (its width * height * 4 bytes): each
 * pixel the background of its row of the whole image, then the surfaces that show there. */
static void shade_image(const surface_targets *st, const ip_surface *surfaces, size_t count,
                        const ip_camera *camera, const ip_shading *s, uint8_t *rgba)
{
    const ip_raster_target *t = &st->opaque;
    ip_camera_basis basis;
    ip_camera_basis_of(camera, &basis);
    for (uint32_t y = 0; y < t->height; y++) {
        uint8_t background[4];
        ip__raster_background(s, t->y + y, camera->height, background);
        for (uint32_t x = 0; x < t->width; x++) {
            size_t pixel = (size_t)y * t->width + x;
            uint8_t *out = rgba + 4 * pixel;
            memcpy(out, background, 4);
            if (!is_covered(st, surfaces, count, pixel))
                continue;
            double ray[3]; /* |n . -ray| = |n . ray| */
            ip_camera_pixel_ray(&basis, camera, (double)t->x + x + 0.5, (double)t->y + y + 0.5,
                                ray);
            shade_surfaces_pixel(st, surfaces, count, s, ray, pixel, out);
        }
    }
}

ip_status ip_render_check_box(const double lo[3], const double hi[3], ip_error *err)
{
    for (int i = 0; i < 3; i++)
        if (!isfinite(lo[i]) || !isfinite(hi[i]) || lo[i] > hi[i])
            return ip__fail(err, IP_ERR_ARGUMENT,
                            "render: box [%g,%g,%g]-[%g,%g,%g] is not a "
                            "finite box with lo <= hi",
                            lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
    return IP_OK;
}

static ip_status check_arguments(const ip_mesh *mesh, const ip_camera *camera, const double lo[3],
                                 const double hi[3], ip_error *err)
{
    ip_status st = ip_camera_check(camera, err);
    if (st == IP_OK)
        st = ip_render_check_box(lo, hi, err);
    if (st != IP_OK)
        return st;
    if (camera->width > MAX_SIDE || camera->height > MAX_SIDE)
        return ip__fail(err, IP_ERR_ARGUMENT, "raster: image %ux%u is larger than %dx%d",
                        camera->width, camera->height, MAX_SIDE, MAX_SIDE);
    if (mesh->triangle_count >= UINT32_MAX)
        return ip__fail(err, IP_ERR_ARGUMENT, "raster: %llu triangles are too many",
                        (unsigned long long)mesh->triangle_count);
    return IP_OK;
}

/* The working buffers of the part [x, x + width) x [y, y + height) of the image; the caller's
 * triangle_index and inverse_depth (either may be NULL) are used where given. */
static ip_status allocate_target(ip_raster_target *t, uint32_t x, uint32_t y, uint32_t width,
                                 uint32_t height, uint32_t *triangle_index, double *inverse_depth,
                                 int with_normals, ip_error *err)
{
    size_t pixels = (size_t)width * height;
    memset(t, 0, sizeof *t);
    t->x = x;
    t->y = y;
    t->width = width;
    t->height = height;
    t->inverse_depth = inverse_depth ? inverse_depth : malloc(pixels * sizeof *t->inverse_depth);
    t->index = triangle_index ? triangle_index : malloc(pixels * sizeof *t->index);
    t->normal = with_normals ? malloc(pixels * 3 * sizeof *t->normal) : NULL;
    if (!t->inverse_depth || !t->index || (with_normals && !t->normal))
        return ip__fail(err, IP_ERR_NOMEM, "raster: out of memory for a %ux%u image", width,
                        height);
    for (size_t i = 0; i < pixels; i++) {
        t->index[i] = UINT32_MAX;
        t->inverse_depth[i] = 0;
    }
    return IP_OK;
}

static void free_target(ip_raster_target *t, const uint32_t *triangle_index,
                        const double *inverse_depth)
{
    if (t->inverse_depth != inverse_depth)
        free(t->inverse_depth);
    if (t->index != triangle_index)
        free(t->index);
    free(t->normal);
}

void ip__raster_range(ip_raster_target *t, const ip_raster_view *view, const ip_mesh *mesh,
                      uint64_t first, uint64_t count, uint32_t first_index)
{
    for (uint64_t i = first; i < first + count; i++) {
        view_vertex tri[3];
        for (int k = 0; k < 3; k++)
            to_view(view, mesh->positions + 9 * i + 3 * k, mesh->normals + 9 * i + 3 * k, &tri[k]);
        clip_and_raster(t, view, tri, first_index + (uint32_t)(i - first));
    }
}

/* Rasterizes every triangle of `mesh` into t, numbered from `first_index` on. */
static void raster_triangles(ip_raster_target *t, const ip_raster_view *view, const ip_mesh *mesh,
                             uint32_t first_index)
{
    ip__raster_range(t, view, mesh, 0, mesh->triangle_count, first_index);
}

static ip_status raster_part(const ip_mesh *mesh, const ip_camera *camera,
                             const ip_shading *shading, const double lo[3], const double hi[3],
                             uint32_t x, uint32_t y, uint32_t width, uint32_t height,
                             uint32_t *triangle_index, double *inverse_depth, uint8_t *rgba,
                             ip_error *err);

ip_status ip_raster_mesh(const ip_mesh *mesh, const ip_camera *camera, const double lo[3],
                         const double hi[3], uint32_t *triangle_index, uint8_t *rgba, ip_error *err)
{
    return ip_raster_mesh_shaded(mesh, camera, NULL, lo, hi, triangle_index, rgba, err);
}

ip_status ip_raster_mesh_shaded(const ip_mesh *mesh, const ip_camera *camera,
                                const ip_shading *shading, const double lo[3], const double hi[3],
                                uint32_t *triangle_index, uint8_t *rgba, ip_error *err)
{
    ip_status st = check_arguments(mesh, camera, lo, hi, err);
    if (st != IP_OK)
        return st;
    return raster_part(mesh, camera, shading, lo, hi, 0, 0, camera->width, camera->height,
                       triangle_index, NULL, rgba, err);
}

ip_status ip_raster_mesh_part(const ip_mesh *mesh, const ip_camera *camera,
                              const ip_shading *shading, const double lo[3], const double hi[3],
                              uint32_t x, uint32_t y, uint32_t width, uint32_t height,
                              double *inverse_depth, uint8_t *rgba, ip_error *err)
{
    ip_status st = check_arguments(mesh, camera, lo, hi, err);
    if (st != IP_OK)
        return st;
    if (width == 0 || height == 0 || x >= camera->width || y >= camera->height ||
        width > camera->width - x || height > camera->height - y)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "raster: part %ux%u at (%u, %u) is not a non-empty part of the %ux%u "
                        "image",
                        width, height, x, y, camera->width, camera->height);
    return raster_part(mesh, camera, shading, lo, hi, x, y, width, height, NULL, inverse_depth,
                       rgba, err);
}

/* Draws the part [x, x + width) x [y, y + height) of the camera's image (checked). */
static ip_status raster_part(const ip_mesh *mesh, const ip_camera *camera,
                             const ip_shading *shading, const double lo[3], const double hi[3],
                             uint32_t x, uint32_t y, uint32_t width, uint32_t height,
                             uint32_t *triangle_index, double *inverse_depth, uint8_t *rgba,
                             ip_error *err)
{
    ip_shading s;
    ip_status st = ip__shading_take(shading, &s, err);
    if (st != IP_OK)
        return st;
    surface_targets targets; /* the mesh as one opaque surface */
    ip_raster_target *target = &targets.opaque;
    targets.first[0] = 0;
    st = allocate_target(target, x, y, width, height, triangle_index, inverse_depth, rgba != NULL,
                         err);
    if (st == IP_OK) {
        ip_raster_view view;
        ip__raster_setup_view(&view, camera, lo, hi);
        raster_triangles(target, &view, mesh, 0);
        if (rgba) {
            ip_surface one = {mesh, {0, 0, 0}, 1.0f};
            memcpy(one.colour, s.surface, sizeof one.colour);
            shade_image(&targets, &one, 1, camera, &s, rgba);
        }
    }
    free_target(target, triangle_index, inverse_depth);
    return st;
}

/* ---- several surfaces ---- */

ip_status ip_surfaces_check(const ip_surface *surfaces, size_t count, ip_error *err)
{
    if (count < 1 || count > IP_MAX_SURFACES || !surfaces)
        return ip__fail(err, IP_ERR_ARGUMENT, "surfaces: %zu of them (1 to %d)", count,
                        IP_MAX_SURFACES);
    for (size_t i = 0; i < count; i++) {
        const ip_surface *f = &surfaces[i];
        if (!f->mesh)
            return ip__fail(err, IP_ERR_ARGUMENT, "surface %zu: no mesh", i);
        if (!is_unit_colour(f->colour))
            return ip__fail(err, IP_ERR_ARGUMENT, "surface %zu: a colour channel is outside [0, 1]",
                            i);
        if (!(f->opacity > 0.0f && f->opacity <= 1.0f))
            return ip__fail(err, IP_ERR_ARGUMENT, "surface %zu: opacity %g is not in (0, 1]", i,
                            (double)f->opacity);
    }
    return IP_OK;
}

static ip_status check_surfaces(const ip_surface *surfaces, size_t count, const ip_camera *camera,
                                const double lo[3], const double hi[3], ip_error *err)
{
    ip_status st = ip_surfaces_check(surfaces, count, err);
    uint64_t opaque = 0;
    for (size_t i = 0; st == IP_OK && i < count; i++) {
        st = check_arguments(surfaces[i].mesh, camera, lo, hi, err);
        opaque += is_opaque(&surfaces[i]) ? surfaces[i].mesh->triangle_count : 0;
    }
    if (st == IP_OK && opaque >= UINT32_MAX)
        return ip__fail(err, IP_ERR_ARGUMENT, "raster: %llu opaque triangles are too many",
                        (unsigned long long)opaque);
    return st;
}

ip_status ip_raster_surfaces(const ip_surface *surfaces, size_t count, const ip_camera *camera,
                             const ip_shading *shading, const double lo[3], const double hi[3],
                             uint8_t *rgba, ip_error *err)
{
    ip_shading s;
    ip_status st = ip__shading_take(shading, &s, err);
    if (st == IP_OK)
        st = check_surfaces(surfaces, count, camera, lo, hi, err);
    if (st != IP_OK)
        return st;
    if (!rgba)
        return ip__fail(err, IP_ERR_ARGUMENT, "raster: no image to draw the surfaces into");
    surface_targets *targets = calloc(1, sizeof *targets);
    if (!targets)
        return ip__fail(err, IP_ERR_NOMEM, "raster: out of memory");
    ip_raster_view view;
    ip__raster_setup_view(&view, camera, lo, hi);
    st = allocate_target(&targets->opaque, 0, 0, camera->width, camera->height, NULL, NULL, 1, err);
    uint32_t next = 0;
    for (size_t i = 0; st == IP_OK && i < count; i++) {
        const ip_surface *f = &surfaces[i];
        if (is_opaque(f)) {
            targets->first[i] = next;
            raster_triangles(&targets->opaque, &view, f->mesh, next);
            next += (uint32_t)f->mesh->triangle_count;
            continue;
        }
        st = allocate_target(&targets->layer[i], 0, 0, camera->width, camera->height, NULL, NULL, 1,
                             err);
        if (st == IP_OK)
            raster_triangles(&targets->layer[i], &view, f->mesh, 0);
    }
    if (st == IP_OK)
        shade_image(targets, surfaces, count, camera, &s, rgba);
    free_target(&targets->opaque, NULL, NULL);
    for (size_t i = 0; i < count; i++)
        free_target(&targets->layer[i], NULL, NULL);
    free(targets);
    return st;
}

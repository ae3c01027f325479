/* SPDX-License-Identifier: BSD-3-Clause */
/* The coverage depth buffer: what extracted surface already hides, for occlusion-aware
 * propagation.
 *
 * Why deferring hidden cells keeps the image exact. The image (ip_raster_mesh()) shows at each
 * pixel centre the nearest triangle there. Every pixel's own ray still extracts its first-hit
 * cell, the seed, whatever the coverage says: the test below only keeps propagation from
 * queueing a cell, never stops a ray. So once every pixel has had its ray, each pixel centre
 * holds its first-hit triangle, as in the full extraction, and no extracted triangle is
 * nearer there (all are triangles of the full surface). A deferred cell is therefore never
 * needed at a pixel centre unless some ray seeds it, and then that ray extracts it.
 *
 * The test is conservative besides, so that deferring costs no pixel even mid-way: a cell is
 * deferred only when, at every pixel centre its box may cover, surface already extracted (and
 * kept: the mesh only grows) is strictly nearer than the box's nearest point; its triangles
 * could never win such a pixel. To that end:
 *  - a recorded depth is the largest view depth of its triangle's vertices (the triangle's
 *    depth anywhere is no larger), rounded up to a float;
 *  - a triangle records the pixel centres inside its exact projection or on its edges (within
 *    EDGE_TOLERANCE pixels, for rounding), so that a centre on an edge two triangles share is
 *    recorded by both: either depth bounds the one the rasterizer shows there. It records
 *    only when it lies wholly between the near and far planes the renderers clip at;
 *  - a box's pixel centres are those within BOX_MARGIN pixels of the bounding rectangle of its
 *    corners' projections (more than the rasterizer's 1/256-pixel vertex snapping moves a
 *    triangle of the box), its nearest depth is its nearest corner's (depth is linear) less a
 *    relative BOX_DEPTH_MARGIN for the float rounding of vertices;
 *  - a box not wholly in front of the near plane (crossing it, or behind the eye), or whose
 *    projection holds no pixel centre or more than IP_COVERAGE_MAX_PIXELS, is never hidden.
 * One approximation is left: where a triangle's edge is a silhouette, the rasterizer's
 * snapping may leave uncovered a pixel centre within 1/256 pixel of the exact edge, which the
 * buffer counts as covered. A cell whose surface shows only at such a centre may be deferred
 * until that pixel's own ray seeds it; the final image is unaffected. (Requiring centres to
 * lie 1/256 pixel inside every edge instead leaves the centres on shared edges uncovered: on
 * the head that kept a third of the deferrals from happening.) */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "coverage.h"
#include "internal.h"
#include "vec3.h"

#define EDGE_TOLERANCE 1e-7      /* pixels */
#define BOX_MARGIN (1.0 / 64)    /* pixels */
#define BOX_DEPTH_MARGIN 1e-5    /* relative */
#define NEAR_MARGIN (1.0 + 1e-6) /* relative to the near plane */

ip_status ip__coverage_prepare(ip_coverage *c, const ip_camera *camera, const double lo[3],
                               const double hi[3])
{
    uint32_t tiles_x = (camera->width + IP_COVERAGE_TILE - 1) >> IP_COVERAGE_TILE_SHIFT,
             tiles_y = (camera->height + IP_COVERAGE_TILE - 1) >> IP_COVERAGE_TILE_SHIFT;
    size_t n = (size_t)tiles_x * tiles_y << 2 * IP_COVERAGE_TILE_SHIFT;
    if (n > c->capacity) {
        free(c->depth);
        free(c->solid);
        c->depth = malloc(n * sizeof *c->depth);
        c->solid = malloc(n * sizeof *c->solid);
        c->capacity = c->depth && c->solid ? n : 0;
        if (!c->capacity) {
            ip__coverage_free(c);
            return IP_ERR_NOMEM;
        }
    }
    c->camera = *camera;
    ip_camera_basis_of(camera, &c->basis);
    ip_camera_depth_range(camera, lo, hi, &c->near_plane, &c->far_plane);
    c->width = camera->width;
    c->tiles_x = tiles_x;
    c->height = camera->height;
    ip__image_axes_of(&c->basis, c->width, c->height, &c->axes);
    c->reached = NULL;
    return IP_OK;
}

void ip__coverage_reach(ip_coverage *c, const unsigned char *reached, unsigned shift,
                        uint32_t tiles_x)
{
    IP_ASSERT(!reached || shift >= IP_COVERAGE_TILE_SHIFT);
    c->reached = reached;
    c->reached_shift = shift;
    c->reached_x = tiles_x;
}

/* 1 when pixel (x, y)'s entries are kept (ip__coverage_reach()). */
static inline int kept(const ip_coverage *c, int64_t x, int64_t y)
{
    return !c->reached || c->reached[(size_t)(y >> c->reached_shift) * c->reached_x +
                                     (size_t)(x >> c->reached_shift)];
}

void ip__coverage_clear(ip_coverage *c, unsigned part, unsigned parts)
{
    uint32_t tiles_y = (c->height + IP_COVERAGE_TILE - 1) >> IP_COVERAGE_TILE_SHIFT;
    uint32_t first = (uint32_t)((uint64_t)tiles_y * part / parts),
             end = (uint32_t)((uint64_t)tiles_y * (part + 1) / parts);
    unsigned bits = ip__float_bits(INFINITY);
    for (uint32_t ty = first; ty < end; ty++)
        for (uint32_t tx = 0; tx < c->tiles_x; tx++) {
            if (!kept(c, (int64_t)tx << IP_COVERAGE_TILE_SHIFT,
                      (int64_t)ty << IP_COVERAGE_TILE_SHIFT)) /* the whole layout tile */
                continue;
            size_t at = ip__coverage_index(c, (uint64_t)tx << IP_COVERAGE_TILE_SHIFT,
                                           (uint64_t)ty << IP_COVERAGE_TILE_SHIFT);
            for (size_t i = at; i < at + IP_COVERAGE_TILE * IP_COVERAGE_TILE; i++) {
                atomic_init(&c->depth[i], bits);
                atomic_init(&c->solid[i], bits);
            }
        }
}

ip_status ip__coverage_reset(ip_coverage *c, const ip_camera *camera, const double lo[3],
                             const double hi[3])
{
    ip_status st = ip__coverage_prepare(c, camera, lo, hi);
    if (st == IP_OK)
        ip__coverage_clear(c, 0, 1);
    return st;
}

void ip__coverage_free(ip_coverage *c)
{
    free(c->depth);
    free(c->solid);
    c->depth = NULL;
    c->solid = NULL;
    c->capacity = 0;
}

/* Image position (pixels) and view depth of world point p. */
static void project(const ip_coverage *c, const double p[3], double *x, double *y, double *z)
{
    double v[3];
    ip__vec3_sub(p, c->camera.eye, v);
    *z = ip__vec3_dot(v, c->basis.forward);
    double r = 1.0 / *z;
    *x = ip__vec3_dot(v, c->axes.to_x) * r + c->axes.centre_x;
    *y = ip__vec3_dot(v, c->axes.to_y) * r + c->axes.centre_y;
}

static double min3(double a, double b, double c)
{
    double m = a < b ? a : b;
    return m < c ? m : c;
}

static double max3(double a, double b, double c)
{
    double m = a > b ? a : b;
    return m > c ? m : c;
}

/* The pixel centres (x + 0.5) within [lo - margin, hi + margin], clamped to [0, side); none
 * when either end is NaN. Rounded through integers, not ceil() and floor(), which are calls on
 * the x86-64 baseline: both ends are first clamped to [-1, side], where that changes nothing
 * the clamp to [0, side) would not. */
static int centre_range(double lo, double hi, double margin, uint32_t side, int64_t *first,
                        int64_t *last)
{
    double a = lo - 0.5 - margin, b = hi - 0.5 + margin;
    if (!(a <= b) || !(a <= side) || !(b >= -1.0))
        return 0; /* NaN, or nothing of [0, side) */
    a = a < -1.0 ? -1.0 : a;
    b = b > side ? (double)side : b;
    int64_t ia = (int64_t)a, ib = (int64_t)b; /* toward zero */
    ia += (double)ia < a;                     /* ceil(a) */
    ib -= (double)ib > b;                     /* floor(b) */
    ia = ia < 0 ? 0 : ia;
    ib = ib > (int64_t)side - 1 ? (int64_t)side - 1 : ib;
    if (ia > ib)
        return 0;
    *first = ia;
    *last = ib;
    return 1;
}

/* Lowers an entry to `bits` (a non-negative float's bits, so integer order is float order).
 * A plain store, not a compare-and-swap loop: two threads lowering one entry at once may leave
 * the larger of their two depths, never a depth no triangle recorded. Every entry stays what
 * coverage.h says (a depth some extracted triangle has there, or farther): a lost lowering
 * only defers fewer cells and retires fewer rays. */
static void lower(atomic_uint *entry, unsigned bits)
{
    if (bits < atomic_load_explicit(entry, memory_order_relaxed))
        atomic_store_explicit(entry, bits, memory_order_relaxed);
}

/* Records one triangle, its corners projected: image x, y (pixels) and view depth z. Returns
 * 0 when it can be drawn at no pixel centre (ip__coverage_add()), else 1. Inlined into its one
 * caller, whose per-cell values then stay in registers: 0.9 % fewer instructions per view. */
static IP_ALWAYS_INLINE int add_projected(ip_coverage *c, const double *x, const double *y,
                                          const double *z)
{
    double zmax = 0;
    for (int k = 0; k < 3; k++) {
        if (!(z[k] >= c->near_plane * NEAR_MARGIN && z[k] <= c->far_plane))
            return 1; /* clipped by the renderers, or behind the eye */
        zmax = z[k] > zmax ? z[k] : zmax;
    }
    /* Most triangles are smaller than a pixel: the pixel centres of the bounding rectangle
     * (widened by the show margin) first, and nothing more when it holds none. */
    int64_t x0, x1, y0, y1;
    if (!centre_range(min3(x[0], x[1], x[2]), max3(x[0], x[1], x[2]), IP_COVERAGE_SHOW_MARGIN,
                      c->width, &x0, &x1) ||
        !centre_range(min3(y[0], y[1], y[2]), max3(y[0], y[1], y[2]), IP_COVERAGE_SHOW_MARGIN,
                      c->height, &y0, &y1))
        return 0;
    if ((x1 - x0 + 1) * (y1 - y0 + 1) > IP_COVERAGE_MAX_PIXELS)
        return 1;
    double area = (x[1] - x[0]) * (y[2] - y[0]) - (y[1] - y[0]) * (x[2] - x[0]);
    if (!(fabs(area) > 1e-9))
        return 1;
    int o1 = area < 0 ? 2 : 1, o2 = 3 - o1; /* counter-clockwise: inside is left of every edge */
    double vx[3] = {x[0], x[o1], x[o2]}, vy[3] = {y[0], y[o1], y[o2]};
    /* e_i, the edge function at a centre, is its distance inside edge i times the edge's
     * length: `need` admits centres on the edge (within rounding), `inner` those the solid
     * margin inside it, `show` those within the show margin outside it */
    double ex[3], ey[3], need[3], inner[3], show[3];
    for (int i = 0; i < 3; i++) {
        int j = i == 2 ? 0 : i + 1;
        ex[i] = vx[j] - vx[i];
        ey[i] = vy[j] - vy[i];
        need[i] = -EDGE_TOLERANCE * (fabs(ex[i]) + fabs(ey[i])); /* >= the edge's length */
        double length = sqrt(ex[i] * ex[i] + ey[i] * ey[i]);
        inner[i] = IP_COVERAGE_SOLID_MARGIN * length;
        show[i] = -IP_COVERAGE_SHOW_MARGIN * length;
    }
    /* the next float above zmax (a positive finite float: its bits plus one) */
    unsigned bits = ip__float_bits((float)zmax) + 1;
    int shows = 0;
    /* whether the pixels' entries are kept: once for a rectangle within one kept tile (most
     * are), else pixel by pixel (-1) */
    int all_kept = !c->reached ? 1
                   : (x0 ^ x1) >> c->reached_shift || (y0 ^ y1) >> c->reached_shift
                       ? -1
                       : kept(c, x0, y0);
    for (int64_t py = y0; py <= y1; py++) {
        double cy = py + 0.5;
        for (int64_t px = x0; px <= x1; px++) {
            double cx = px + 0.5;
            double e0 = ex[0] * (cy - vy[0]) - ey[0] * (cx - vx[0]);
            double e1 = ex[1] * (cy - vy[1]) - ey[1] * (cx - vx[1]);
            double e2 = ex[2] * (cy - vy[2]) - ey[2] * (cx - vx[2]);
            if (!(e0 >= show[0] && e1 >= show[1] && e2 >= show[2]))
                continue;
            shows = 1;
            if (all_kept == 0 || (all_kept < 0 && !kept(c, px, py)))
                continue; /* not expected: a caller's triangles stay in kept tiles */
            if (e0 >= need[0] && e1 >= need[1] && e2 >= need[2]) {
                size_t at = ip__coverage_index(c, (uint64_t)px, (uint64_t)py);
                lower(&c->depth[at], bits);
                if (e0 >= inner[0] && e1 >= inner[1] && e2 >= inner[2])
                    lower(&c->solid[at], bits);
            }
        }
    }
    return shows;
}

uint32_t ip__coverage_add_indexed(ip_coverage *c, const float points[][3], const int8_t *corners,
                                  unsigned count)
{
    double px[32], py[32], pz[32];
    uint32_t projected = 0, shows = 0;
    for (unsigned t = 0; t < count; t++) {
        double x[3], y[3], z[3];
        for (int k = 0; k < 3; k++) {
            unsigned i = (unsigned)corners[3 * t + k];
            IP_ASSERT(i < 32);
            if (!(projected >> i & 1)) {
                double p[3] = {points[i][0], points[i][1], points[i][2]};
                project(c, p, &px[i], &py[i], &pz[i]);
                projected |= UINT32_C(1) << i;
            }
            x[k] = px[i];
            y[k] = py[i];
            z[k] = pz[i];
        }
        shows |= (uint32_t)add_projected(c, x, y, z) << t;
    }
    return shows;
}

uint32_t ip__coverage_add(ip_coverage *c, const float *positions, unsigned count)
{
    static const int8_t corners[3] = {0, 1, 2};
    uint32_t shows = 0;
    for (unsigned t = 0; t < count; t++)
        shows |= ip__coverage_add_indexed(c, (const float(*)[3])(positions + 9 * t), corners, 1)
                 << t;
    return shows;
}

int ip__coverage_hides(const ip_coverage *c, const double lo[3], const double hi[3])
{
    double centre[3], v[3];
    for (int a = 0; a < 3; a++)
        centre[a] = 0.5 * (lo[a] + hi[a]);
    ip__vec3_sub(centre, c->camera.eye, v);
    double zc = ip__vec3_dot(v, c->basis.forward);
    if (!(zc > 0.0))
        return 0; /* nor is its nearest point beyond the near plane: never hidden */
    double xc, yc;
    ip__image_position(&c->axes, v, zc, &xc, &yc);
    return ip__coverage_hides_seen(c, lo, hi, zc, xc, yc);
}

int ip__coverage_hides_seen(const ip_coverage *c, const double lo[3], const double hi[3], double zc,
                            double xc, double yc)
{
    /* The nearest depth first (depth is linear: the centre's less the half extents along the
     * view), then the entry under the centre: most boxes tested are in view, and fail there
     * without the projection of the 8 corners. */
    double reach = 0;
    for (int a = 0; a < 3; a++)
        reach += 0.5 * (hi[a] - lo[a]) * fabs(c->basis.forward[a]);
    double zmin = zc - reach;
    if (!(zmin >= c->near_plane * NEAR_MARGIN))
        return 0; /* crosses the near plane or lies behind the eye: never deferred */
    double limit = zmin * (1.0 - BOX_DEPTH_MARGIN);
    float f = (float)limit;
    unsigned bits = ip__float_bits(f);
    if ((double)f > limit) /* the float below (f > 0: one less in its bits) */
        bits--;
    if (xc >= 0 && xc < c->width && yc >= 0 && yc < c->height &&
        (!kept(c, (int64_t)xc, (int64_t)yc) ||
         atomic_load_explicit(&c->depth[ip__coverage_index(c, (uint64_t)xc, (uint64_t)yc)],
                              memory_order_relaxed) >= bits))
        return 0;
    /* The corners' projections: each of (v . to_x, v . to_y, depth), v from the eye, is the
     * low corner's plus the steps along the axes where the corner is high (the rounding this
     * differs by is far below BOX_MARGIN). */
    double v0[3], step[3][3], sum[8][3];
    ip__vec3_sub(lo, c->camera.eye, v0);
    sum[0][0] = ip__vec3_dot(v0, c->axes.to_x);
    sum[0][1] = ip__vec3_dot(v0, c->axes.to_y);
    sum[0][2] = ip__vec3_dot(v0, c->basis.forward);
    for (int a = 0; a < 3; a++) {
        double d = hi[a] - lo[a];
        step[a][0] = d * c->axes.to_x[a];
        step[a][1] = d * c->axes.to_y[a];
        step[a][2] = d * c->basis.forward[a];
    }
    for (int k = 1; k < 8; k++) {
        int a = k & 1 ? 0 : k & 2 ? 1 : 2, from = k & ~(1 << a); /* k less its lowest bit */
        for (int i = 0; i < 3; i++)
            sum[k][i] = sum[from][i] + step[a][i];
    }
    double min_x = INFINITY, max_x = -INFINITY, min_y = INFINITY, max_y = -INFINITY;
    for (int k = 0; k < 8; k++) {
        double r = 1.0 / sum[k][2];
        double x = sum[k][0] * r + c->axes.centre_x, y = sum[k][1] * r + c->axes.centre_y;
        min_x = x < min_x ? x : min_x;
        max_x = x > max_x ? x : max_x;
        min_y = y < min_y ? y : min_y;
        max_y = y > max_y ? y : max_y;
    }
    int64_t x0, x1, y0, y1;
    if (!centre_range(min_x, max_x, BOX_MARGIN, c->width, &x0, &x1) ||
        !centre_range(min_y, max_y, BOX_MARGIN, c->height, &y0, &y1) ||
        (x1 - x0 + 1) * (y1 - y0 + 1) > IP_COVERAGE_MAX_PIXELS)
        return 0;
    for (int64_t py = y0; py <= y1; py++)
        for (int64_t px = x0; px <= x1; px++)
            if (!kept(c, px, py) ||
                atomic_load_explicit(&c->depth[ip__coverage_index(c, (uint64_t)px, (uint64_t)py)],
                                     memory_order_relaxed) >= bits)
                return 0;
    return 1;
}

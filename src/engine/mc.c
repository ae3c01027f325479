/* SPDX-License-Identifier: BSD-3-Clause */
/* Marching cubes: the case of a cell, its triangles, and the ray test that seeding relies on. */
#include <float.h>
#include <math.h>
#include <stddef.h>

#include "internal.h"
#include "mc.h"
#include "vec3.h"

/* The external definition of the inline one in isoprop/mc.h (C11 6.7.4). */
extern unsigned ip__mc_case(const float corner_values[8], float iso);
extern unsigned ip__mc_crossed_faces(unsigned mc_case);

/* Where the surface crosses the edge from v0 (low corner) to v1, as a fraction of the edge.
 * Always measured from the low corner, so the cells sharing an edge compute the same bits. */
static float edge_fraction(float v0, float v1, float iso)
{
    float t = (iso - v0) / (v1 - v0);
    /* Rounding can step just past an end, and two infinite samples give NaN: clamp both. */
    if (!(t >= 0.0f))
        t = 0.0f;
    if (t > 1.0f)
        t = 1.0f;
    return t;
}

/* The point at fraction t along `edge` of the cell whose corners are lo and hi. Each coordinate
 * comes from the edge's own ends, so every cell sharing the edge computes the same bits (which is
 * what lets vertices be welded by exact position): across the edge the corner's coordinate
 * itself, along it lo + t * (hi - lo), and exactly lo or hi at t = 0 or 1 (lo + (hi - lo) need
 * not round to hi), so that a vertex on a corner equals the neighbours' vertices there. */
static void edge_position(unsigned edge, float t, const float lo[3], const float hi[3],
                          float out[3])
{
    unsigned low = ip__mc_edge_corners[edge][0];
    unsigned axis = edge >> 2;
    for (unsigned a = 0; a < 3; a++)
        out[a] = (low >> a) & 1u ? hi[a] : lo[a];
    if (t >= 1.0f)
        out[axis] = hi[axis];
    else if (t > 0.0f)
        out[axis] = lo[axis] + t * (hi[axis] - lo[axis]);
}

/* Writes -g / |g| to out; returns 0 (out untouched) when g has no usable direction. */
static int store_negated_unit(const float g[3], float out[3])
{
    float length = sqrtf(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    if (!(length > 0.0f && length <= FLT_MAX))
        return 0;
    float scale = -1.0f / length;
    for (unsigned a = 0; a < 3; a++)
        out[a] = g[a] * scale;
    return 1;
}

/* Gradient of the cell's trilinear interpolant at fraction t along `edge`: along each other
 * axis it is the linear blend of the differences across the cell at the edge's two ends. */
static void trilinear_gradient(const float values[8], unsigned edge, float t,
                               const float inverse_size[3], float out[3])
{
    unsigned c0 = ip__mc_edge_corners[edge][0];
    unsigned c1 = ip__mc_edge_corners[edge][1];
    for (unsigned a = 0; a < 3; a++) {
        unsigned bit = 1u << a;
        float d0 = values[c0 | bit] - values[c0 & ~bit];
        float d1 = values[c1 | bit] - values[c1 & ~bit];
        out[a] = (d0 + t * (d1 - d0)) * inverse_size[a];
    }
}

static void edge_normal(const float values[8], const float gradients[8][3], float iso,
                        unsigned edge, float t, const float inverse_size[3], float out[3])
{
    unsigned c0 = ip__mc_edge_corners[edge][0];
    unsigned c1 = ip__mc_edge_corners[edge][1];
    float g[3];
    if (gradients) {
        for (unsigned a = 0; a < 3; a++)
            g[a] = gradients[c0][a] + t * (gradients[c1][a] - gradients[c0][a]);
        if (store_negated_unit(g, out))
            return;
    }
    trilinear_gradient(values, edge, t, inverse_size, g);
    if (store_negated_unit(g, out))
        return;
    /* Only infinite samples get here: the edge itself still says which way is out. */
    unsigned axis = edge >> 2;
    out[0] = out[1] = out[2] = 0.0f;
    out[axis] = values[c0] >= iso ? 1.0f : -1.0f;
}

int ip__mc_triangulate_cell(const float values[8], const float gradients[8][3], float iso,
                            const float lo[3], const float hi[3], ip_mc_vertex *out)
{
    /* Each crossing is shared by up to 4 triangles of the cell: computed once. */
    float points[12][3], normals[12][3];
    unsigned mc_case = ip__mc_case(values, iso);
    if (!ip__mc_cell_edge_points(values, mc_case, iso, lo, hi, points))
        return 0;
    ip__mc_cell_edge_normals(values, mc_case, gradients, iso, lo, hi, normals);
    const int8_t *row = ip__mc_triangle_table[mc_case];
    int count = ip__mc_triangle_count[mc_case];
    for (int i = 0; i < 3 * count; i++)
        for (unsigned a = 0; a < 3; a++) {
            out[i].position[a] = points[row[i]][a];
            out[i].normal[a] = normals[row[i]][a];
        }
    return count;
}

unsigned ip__mc_cell_edge_points(const float values[8], unsigned mc_case, float iso,
                                 const float lo[3], const float hi[3], float points[12][3])
{
    unsigned crossed = ip__mc_edge_table[mc_case & 0xFFu];
    for (unsigned left = crossed; left; left &= left - 1) {
        unsigned e = ip__lowest_bit(left);
        float t = edge_fraction(values[ip__mc_edge_corners[e][0]],
                                values[ip__mc_edge_corners[e][1]], iso);
        edge_position(e, t, lo, hi, points[e]);
    }
    return crossed;
}

unsigned ip__mc_cell_edge_normals(const float values[8], unsigned mc_case,
                                  const float gradients[8][3], float iso, const float lo[3],
                                  const float hi[3], float normals[12][3])
{
    unsigned crossed = ip__mc_edge_table[mc_case & 0xFFu];
    const float inverse_size[3] = {1.0f / (hi[0] - lo[0]), 1.0f / (hi[1] - lo[1]),
                                   1.0f / (hi[2] - lo[2])};
    for (unsigned left = crossed; left; left &= left - 1) {
        unsigned e = ip__lowest_bit(left);
        float t = edge_fraction(values[ip__mc_edge_corners[e][0]],
                                values[ip__mc_edge_corners[e][1]], iso);
        edge_normal(values, gradients, iso, e, t, inverse_size, normals[e]);
    }
    return crossed;
}

/* Moller-Trumbore, accepting both sides and the triangle's edges; 1 and *t on a hit at t >= 0.
 * Double precision keeps thin triangles (vertices near a corner) from losing hits. */
static int ray_hits_triangle(const double o[3], const double d[3], const double a[3],
                             const double b[3], const double c[3], double *t)
{
    double e1[3], e2[3], p[3], s[3], q[3];
    ip__vec3_sub(b, a, e1);
    ip__vec3_sub(c, a, e2);
    ip__vec3_cross(d, e2, p);
    double det = ip__vec3_dot(e1, p);
    if (det == 0.0) /* the ray runs in the triangle's plane, or the triangle has no area */
        return 0;
    double inv = 1.0 / det;
    ip__vec3_sub(o, a, s);
    double u = ip__vec3_dot(s, p) * inv;
    if (u < 0.0 || u > 1.0)
        return 0;
    ip__vec3_cross(s, e1, q);
    double v = ip__vec3_dot(d, q) * inv;
    if (v < 0.0 || u + v > 1.0)
        return 0;
    double hit = ip__vec3_dot(e2, q) * inv;
    if (!(hit >= 0.0))
        return 0;
    *t = hit;
    return 1;
}

int ip__mc_ray_hits_cell(const float values[8], float iso, const float lo[3], const float hi[3],
                         const float ray_origin[3], const float ray_dir[3], float *t_hit)
{
    unsigned mc_case = ip__mc_case(values, iso);
    unsigned crossed = ip__mc_edge_table[mc_case];
    if (crossed == 0)
        return 0;
    double at_edge[12][3];
    for (unsigned e = 0; e < 12; e++) {
        if (!(crossed >> e & 1u))
            continue;
        float t = edge_fraction(values[ip__mc_edge_corners[e][0]],
                                values[ip__mc_edge_corners[e][1]], iso);
        float p[3];
        edge_position(e, t, lo, hi, p);
        for (unsigned a = 0; a < 3; a++)
            at_edge[e][a] = p[a];
    }
    double o[3] = {ray_origin[0], ray_origin[1], ray_origin[2]};
    double d[3] = {ray_dir[0], ray_dir[1], ray_dir[2]};
    const int8_t *row = ip__mc_triangle_table[mc_case];
    int hit = 0;
    double nearest = 0.0;
    for (int i = 0; i < 3 * ip__mc_triangle_count[mc_case]; i += 3) {
        double t;
        if (ray_hits_triangle(o, d, at_edge[row[i]], at_edge[row[i + 1]], at_edge[row[i + 2]],
                              &t) &&
            (!hit || t < nearest)) {
            nearest = t;
            hit = 1;
        }
    }
    if (hit && t_hit)
        *t_hit = (float)nearest;
    return hit;
}

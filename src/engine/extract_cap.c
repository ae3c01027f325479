/* SPDX-License-Identifier: BSD-3-Clause */
/* The cap: the volume's box faces where the surface leaves the box, triangulated so that the
 * surface and the cap together are closed. On each face, every cell side is cut by marching
 * squares: its part above the isovalue (corners >= iso and the crossings on its sides) is a
 * convex polygon, fanned. The crossings are those the cell's marching cubes uses
 * (ip__mc_cell_edge_points() with the cell's own box), so the cap's rim has the same bits as
 * the surface's boundary vertices and welding by position joins them. On a side whose inside
 * corners are diagonally opposite, the two corners are cut off separately, as the marching
 * cubes tables separate them (mc.h, "Ambiguity"), so that the cap's rim runs along the same
 * segments as the surface's. */
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "isoprop/engine.h"
#include "sampler.h"

/* Appends triangle (a, b, c) with the face's outward normal, wound counter-clockwise seen
 * from outside (along the normal: axis `axis`, direction `sign`). */
static ip_status add_triangle(ip_mesh *mesh, const float *a, const float *b, const float *c,
                              unsigned axis, int sign)
{
    float p[9], n[9];
    unsigned u = (axis + 1) % 3, v = (axis + 2) % 3;
    double cross = ((double)b[u] - a[u]) * ((double)c[v] - a[v]) -
                   ((double)b[v] - a[v]) * ((double)c[u] - a[u]);
    const float *second = b, *third = c;
    if ((cross < 0) != (sign < 0)) {
        second = c;
        third = b;
    }
    memcpy(p, a, 3 * sizeof *p);
    memcpy(p + 3, second, 3 * sizeof *p);
    memcpy(p + 6, third, 3 * sizeof *p);
    for (int k = 0; k < 9; k++)
        n[k] = (unsigned)k % 3 == axis ? (float)sign : 0.0f;
    uint64_t cell = 0;
    return ip_mesh_append_float_normals(mesh, p, n, &cell, 1);
}

/* The cell's edge joining corners c0 and c1 (either order). */
static unsigned edge_of(unsigned c0, unsigned c1)
{
    for (unsigned e = 0; e < 12; e++)
        if ((ip__mc_edge_corners[e][0] == c0 && ip__mc_edge_corners[e][1] == c1) ||
            (ip__mc_edge_corners[e][0] == c1 && ip__mc_edge_corners[e][1] == c0))
            return e;
    return 0;
}

/* Caps the side of a cell on face (axis, high) of the box. */
static ip_status cap_side(ip_mesh *mesh, const float values[8], float iso, const float lo[3],
                          const float hi[3], unsigned axis, unsigned high)
{
    unsigned u = (axis + 1) % 3, v = (axis + 2) % 3;
    unsigned corner[4]; /* the side's corners in order around it */
    const unsigned du[4] = {0, 1, 1, 0}, dv[4] = {0, 0, 1, 1};
    for (int k = 0; k < 4; k++)
        corner[k] = high << axis | du[k] << u | dv[k] << v;
    unsigned inside = 0;
    for (int k = 0; k < 4; k++)
        inside |= (values[corner[k]] >= iso) << k;
    if (!inside)
        return IP_OK;
    float points[12][3], at[4][3];
    ip__mc_cell_edge_points(values, ip__mc_case(values, iso), iso, lo, hi, points);
    for (int k = 0; k < 4; k++)
        for (unsigned a = 0; a < 3; a++)
            at[k][a] = (corner[k] >> a) & 1u ? hi[a] : lo[a];
    int sign = high ? 1 : -1;
    ip_status st = IP_OK;
    if (inside == 5 || inside == 10) { /* diagonal: each inside corner cut off alone */
        for (int k = inside == 5 ? 0 : 1; k < 4 && st == IP_OK; k += 2)
            st = add_triangle(mesh, at[k], points[edge_of(corner[k], corner[(k + 1) % 4])],
                              points[edge_of(corner[k], corner[(k + 3) % 4])], axis, sign);
        return st;
    }
    const float *polygon[8];
    int n = 0;
    for (int k = 0; k < 4; k++) {
        int next = (k + 1) % 4;
        if (inside >> k & 1)
            polygon[n++] = at[k];
        if ((inside >> k & 1) != (inside >> next & 1))
            polygon[n++] = points[edge_of(corner[k], corner[next])];
    }
    for (int i = 1; i + 1 < n && st == IP_OK; i++)
        st = add_triangle(mesh, polygon[0], polygon[i], polygon[i + 1], axis, sign);
    return st;
}

/* Caps face (axis, high) of the level's box: each cell along it. */
static ip_status cap_face(ip_sampler *s, float iso, unsigned axis, unsigned high, ip_mesh *mesh)
{
    unsigned u = (axis + 1) % 3, v = (axis + 2) % 3;
    uint32_t cell[3];
    cell[axis] = high ? s->dims[axis] - 2 : 0;
    for (cell[v] = 0; cell[v] + 1 < s->dims[v]; cell[v]++)
        for (cell[u] = 0; cell[u] + 1 < s->dims[u]; cell[u]++) {
            float values[8], lo[3], hi[3];
            if (!ip__sampler_cell_values(s, cell, values))
                return s->status;
            ip__sampler_cell_box(s, cell, lo, hi);
            ip_status st = cap_side(mesh, values, iso, lo, hi, axis, high);
            if (st != IP_OK)
                return st;
        }
    return IP_OK;
}

ip_status ip_extract_cap(ip_cache *cache, float iso, uint32_t level, ip_mesh *mesh, ip_error *err)
{
    if (!cache || !mesh)
        return ip__fail(err, IP_ERR_ARGUMENT, "ip_extract_cap: cache and mesh are required");
    const ip_layout *l = ip_store_layout(ip_cache_store(cache));
    if (level >= l->level_count)
        return ip__fail(err, IP_ERR_ARGUMENT, "ip_extract_cap: no level %u (the file has %u)",
                        level, l->level_count);
    ip_sampler s;
    if (ip__sampler_init(&s, cache, level) != IP_OK)
        return ip__fail(err, IP_ERR_NOMEM, "ip_extract_cap: no memory for a sampler");
    ip_status st = IP_OK;
    if (s.dims[0] >= 2 && s.dims[1] >= 2 && s.dims[2] >= 2)
        for (unsigned f = 0; f < 6 && st == IP_OK; f++)
            st = cap_face(&s, iso, f / 2, f % 2, mesh);
    if (st == IP_ERR_NOMEM)
        ip__fail(err, st, "ip_extract_cap: no memory for the cap's triangles");
    else if (st != IP_OK && err)
        *err = s.error;
    ip__sampler_free(&s);
    return st;
}

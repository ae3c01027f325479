/* SPDX-License-Identifier: BSD-3-Clause */
/* Taubin smoothing of a welded mesh: each iteration moves every vertex toward the average of
 * its neighbours (factor lambda > 0), then away from it (factor mu < -lambda). The first step
 * alone, repeated, is Laplacian smoothing, which shrinks a closed surface toward a point; the
 * second step undoes the shrinking of the surface's broad shape while the ripples (terraces of
 * nearly binary data) stay damped, since they pass the first step far less than they pass
 * the second. Neighbours come from the triangles' edges, in a compressed sparse row table
 * (an offset per vertex, then its distinct neighbours), so memory is O(vertices + edges). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "isoprop/mesh.h"

/* The vertices' neighbours: those of vertex v are neighbours[first[v] .. first[v + 1]). */
typedef struct adjacency {
    uint64_t *first;      /* vertex_count + 1 */
    uint32_t *neighbours; /* each undirected edge twice, once from each end */
    unsigned char *fixed; /* per vertex: 1 on an edge that is not in exactly two triangles */
} adjacency;

static void adjacency_free(adjacency *a)
{
    free(a->first);
    free(a->neighbours);
    free(a->fixed);
}

static void sort_u32(uint32_t *v, uint64_t n)
{
    for (uint64_t i = 1; i < n; i++) { /* lists are short: a vertex has about 6 neighbours */
        uint32_t x = v[i];
        uint64_t j = i;
        for (; j > 0 && v[j - 1] > x; j--)
            v[j] = v[j - 1];
        v[j] = x;
    }
}

/* Lists, for every vertex, the other two corners of each of its triangles (a neighbour along
 * an edge in two triangles appears twice). */
static ip_status list_corners(const ip_indexed_mesh *m, adjacency *a)
{
    uint64_t v_count = m->vertex_count;
    a->first = calloc(v_count + 2, sizeof *a->first);
    a->neighbours = malloc((6 * m->triangle_count + 1) * sizeof *a->neighbours);
    a->fixed = calloc(v_count + 1, 1);
    if (!a->first || !a->neighbours || !a->fixed)
        return IP_ERR_NOMEM;
    for (uint64_t i = 0; i < 3 * m->triangle_count; i++)
        a->first[m->indices[i] + 2] += 2;
    for (uint64_t v = 0; v < v_count; v++) /* first[v + 2]: where v + 1's list starts */
        a->first[v + 2] += a->first[v + 1];
    for (uint64_t t = 0; t < m->triangle_count; t++) {
        const uint32_t *c = m->indices + 3 * t;
        for (int k = 0; k < 3; k++) {
            uint64_t *next = &a->first[c[k] + 1];
            a->neighbours[(*next)++] = c[(k + 1) % 3];
            a->neighbours[(*next)++] = c[(k + 2) % 3];
        }
    }
    return IP_OK; /* first[v] is now where v's list starts, first[v + 1] where it ends */
}

/* Sorts each vertex's list, keeps each neighbour once and marks the vertex fixed where a
 * neighbour does not appear exactly twice (a boundary or a non-manifold edge). */
static void distinct_neighbours(const ip_indexed_mesh *m, adjacency *a)
{
    uint64_t out = 0, start = 0;
    for (uint64_t v = 0; v < m->vertex_count; v++) {
        uint64_t end = a->first[v + 1];
        uint32_t *list = a->neighbours + start;
        sort_u32(list, end - start);
        a->first[v] = out;
        for (uint64_t i = 0; i < end - start;) {
            uint64_t j = i;
            while (j < end - start && list[j] == list[i])
                j++;
            a->fixed[v] |= j - i != 2;
            a->neighbours[out++] = list[i];
            i = j;
        }
        start = end;
    }
    a->first[m->vertex_count] = out;
}

static ip_status build_adjacency(const ip_indexed_mesh *m, adjacency *a)
{
    memset(a, 0, sizeof *a);
    ip_status st = list_corners(m, a);
    if (st != IP_OK)
        return st;
    distinct_neighbours(m, a);
    return IP_OK;
}

/* One step: every free vertex p becomes p + factor * (average of its neighbours - p), all
 * from the positions before the step (`scratch` holds the new ones meanwhile). */
static void smoothing_step(ip_indexed_mesh *m, const adjacency *a, double factor, float *scratch)
{
    for (uint64_t v = 0; v < m->vertex_count; v++) {
        const float *p = m->positions + 3 * v;
        uint64_t begin = a->first[v], end = a->first[v + 1];
        for (int k = 0; k < 3; k++)
            scratch[3 * v + (uint64_t)k] = p[k];
        if (a->fixed[v] || begin == end)
            continue;
        double sum[3] = {0, 0, 0};
        for (uint64_t i = begin; i < end; i++)
            for (int k = 0; k < 3; k++)
                sum[k] += m->positions[3 * (uint64_t)a->neighbours[i] + (uint64_t)k];
        for (int k = 0; k < 3; k++)
            scratch[3 * v + (uint64_t)k] =
                (float)(p[k] + factor * (sum[k] / (double)(end - begin) - p[k]));
    }
    memcpy(m->positions, scratch, 3 * m->vertex_count * sizeof(float));
}

/* Each vertex's normal: the sum of its triangles' normals weighted by their areas (the
 * cross product of two edges), normalised; the old one where that sum vanishes. */
static void recompute_normals(ip_indexed_mesh *m, float *sums)
{
    memset(sums, 0, 3 * m->vertex_count * sizeof *sums);
    for (uint64_t t = 0; t < m->triangle_count; t++) {
        const uint32_t *c = m->indices + 3 * t;
        const float *p0 = m->positions + 3 * (uint64_t)c[0],
                    *p1 = m->positions + 3 * (uint64_t)c[1],
                    *p2 = m->positions + 3 * (uint64_t)c[2];
        float e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
        float e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
        float n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                      e1[0] * e2[1] - e1[1] * e2[0]};
        for (int j = 0; j < 3; j++)
            for (int k = 0; k < 3; k++)
                sums[3 * (uint64_t)c[j] + (uint64_t)k] += n[k];
    }
    for (uint64_t v = 0; v < m->vertex_count; v++) {
        const float *s = sums + 3 * v;
        float length = sqrtf(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
        if (length > 0.0f && isfinite(length))
            for (int k = 0; k < 3; k++)
                m->normals[3 * v + (uint64_t)k] = ip_normal_pack(s[k] / length);
    }
}

ip_status ip_indexed_mesh_smooth_taubin(ip_indexed_mesh *mesh, unsigned iterations, double lambda,
                                        double mu, ip_error *err)
{
    if (!(lambda > 0.0 && lambda <= 1.0) || !(mu >= -1.0 && mu <= 0.0))
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "Taubin smoothing: lambda %g must be in (0, 1] and mu %g in [-1, 0]",
                        lambda, mu);
    if (iterations == 0 || mesh->vertex_count == 0)
        return IP_OK;
    adjacency a;
    float *scratch = malloc(3 * mesh->vertex_count * sizeof *scratch);
    ip_status st = scratch ? build_adjacency(mesh, &a) : IP_ERR_NOMEM;
    if (st == IP_OK) {
        for (unsigned i = 0; i < iterations; i++) {
            smoothing_step(mesh, &a, lambda, scratch);
            if (mu != 0.0)
                smoothing_step(mesh, &a, mu, scratch);
        }
        recompute_normals(mesh, scratch);
    }
    if (scratch)
        adjacency_free(&a);
    free(scratch);
    if (st != IP_OK)
        return ip__fail(err, st, "Taubin smoothing: no memory for the adjacency of %llu vertices",
                        (unsigned long long)mesh->vertex_count);
    return IP_OK;
}

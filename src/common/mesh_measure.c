/* SPDX-License-Identifier: BSD-3-Clause */
/* Measures of a welded mesh: area, enclosed volume (the divergence theorem), bounds, and
 * whether it is closed (every edge in exactly two triangles). All sums in double precision. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "isoprop/mesh.h"

/* The corners of triangle t as doubles. */
static void corners(const ip_indexed_mesh *m, uint64_t t, double p[3][3])
{
    for (int c = 0; c < 3; c++) {
        const float *v = m->positions + 3 * (uint64_t)m->indices[3 * t + c];
        for (int k = 0; k < 3; k++)
            p[c][k] = v[k];
    }
}

void ip__triangle_measure(const ip_indexed_mesh *m, uint64_t t, double *area, double *volume)
{
    double p[3][3];
    corners(m, t, p);
    double u[3], v[3];
    for (int k = 0; k < 3; k++) {
        u[k] = p[1][k] - p[0][k];
        v[k] = p[2][k] - p[0][k];
    }
    double c[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    *area = 0.5 * sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    /* p0 . (p1 x p2) / 6: the signed volume of the tetrahedron from the origin */
    double x[3] = {p[1][1] * p[2][2] - p[1][2] * p[2][1], p[1][2] * p[2][0] - p[1][0] * p[2][2],
                   p[1][0] * p[2][1] - p[1][1] * p[2][0]};
    *volume = (p[0][0] * x[0] + p[0][1] * x[1] + p[0][2] * x[2]) / 6.0;
}

/* The sums of the triangles' areas and signed volumes. */
static void sums(const ip_indexed_mesh *mesh, double *area, double *volume)
{
    *area = *volume = 0;
    for (uint64_t t = 0; t < mesh->triangle_count; t++) {
        double a, v;
        ip__triangle_measure(mesh, t, &a, &v);
        *area += a;
        *volume += v;
    }
}

double ip_indexed_mesh_area(const ip_indexed_mesh *mesh)
{
    double area, volume;
    sums(mesh, &area, &volume);
    return area;
}

double ip_indexed_mesh_volume(const ip_indexed_mesh *mesh)
{
    double area, volume;
    sums(mesh, &area, &volume);
    return volume;
}

void ip_indexed_mesh_bounds(const ip_indexed_mesh *mesh, double lo[3], double hi[3])
{
    for (int k = 0; k < 3; k++) {
        lo[k] = mesh->vertex_count ? INFINITY : 0;
        hi[k] = mesh->vertex_count ? -INFINITY : 0;
    }
    for (uint64_t i = 0; i < mesh->vertex_count; i++)
        for (int k = 0; k < 3; k++) {
            double x = mesh->positions[3 * i + k];
            lo[k] = x < lo[k] ? x : lo[k];
            hi[k] = x > hi[k] ? x : hi[k];
        }
}

static int compare_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* Sorts a vertex's few edge ends (insertion sort; qsort for a crowded vertex), then counts the
 * runs of one (boundary) and of more than two (non-manifold). */
static void count_runs(uint32_t *ends, uint64_t n, uint64_t *boundary, uint64_t *nonmanifold)
{
    if (n > 16) {
        qsort(ends, n, sizeof *ends, compare_u32);
    } else {
        for (uint64_t i = 1; i < n; i++)
            for (uint64_t j = i; j > 0 && ends[j - 1] > ends[j]; j--) {
                uint32_t s = ends[j];
                ends[j] = ends[j - 1];
                ends[j - 1] = s;
            }
    }
    for (uint64_t i = 0; i < n;) {
        uint64_t j = i + 1;
        while (j < n && ends[j] == ends[i])
            j++;
        *boundary += j - i == 1;
        *nonmanifold += j - i > 2;
        i = j;
    }
}

ip_status ip_indexed_mesh_edges(const ip_indexed_mesh *mesh, uint64_t *boundary,
                                uint64_t *nonmanifold)
{
    *boundary = *nonmanifold = 0;
    uint64_t v = mesh->vertex_count, t = mesh->triangle_count;
    if (t > SIZE_MAX / (3 * sizeof(uint32_t)) || v >= SIZE_MAX / sizeof(uint64_t) - 1)
        return IP_ERR_NOMEM;
    /* each edge under its lower vertex, holding the higher one (a counting sort by the lower) */
    uint64_t *start = calloc(v + 1, sizeof *start);
    uint32_t *ends = malloc((t ? 3 * t : 1) * sizeof *ends);
    if (!start || !ends) {
        free(start);
        free(ends);
        return IP_ERR_NOMEM;
    }
    for (int pass = 0; pass < 2; pass++) {
        for (uint64_t i = 0; i < t; i++)
            for (int c = 0; c < 3; c++) {
                uint32_t a = mesh->indices[3 * i + c], b = mesh->indices[3 * i + (c + 1) % 3];
                if (a == b)
                    continue; /* a repeated vertex is no edge */
                uint32_t low = a < b ? a : b, high = a < b ? b : a;
                if (pass == 0)
                    start[low + 1]++;
                else
                    ends[start[low]++] = high;
            }
        if (pass == 0)
            for (uint64_t i = 0; i < v; i++)
                start[i + 1] += start[i];
        else /* start[i] has moved to the end of vertex i's edges, the start of i + 1's */
            memmove(start + 1, start, v * sizeof *start), start[0] = 0;
    }
    for (uint64_t i = 0; i < v; i++)
        count_runs(ends + start[i], start[i + 1] - start[i], boundary, nonmanifold);
    free(start);
    free(ends);
    return IP_OK;
}

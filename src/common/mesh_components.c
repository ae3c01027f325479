/* SPDX-License-Identifier: BSD-3-Clause */
/* Connected components of a welded mesh (triangles joined by a shared vertex: union-find over
 * the vertices), their areas and volumes, and the cleaning that keeps some of them. */
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "isoprop/mesh.h"

/* The root of vertex v's set, halving the path on the way. */
static uint32_t find_root(uint32_t *parent, uint32_t v)
{
    while (parent[v] != v) {
        parent[v] = parent[parent[v]];
        v = parent[v];
    }
    return v;
}

/* Joins the sets of a and b under the lower root. */
static void join(uint32_t *parent, uint32_t a, uint32_t b)
{
    a = find_root(parent, a);
    b = find_root(parent, b);
    if (a < b)
        parent[b] = a;
    else
        parent[a] = b;
}

ip_status ip_indexed_mesh_components(const ip_indexed_mesh *mesh, uint32_t *labels, uint64_t *count)
{
    *count = 0;
    uint64_t v = mesh->vertex_count;
    uint32_t *parent = malloc((v ? v : 1) * sizeof *parent);
    if (!parent)
        return IP_ERR_NOMEM;
    for (uint64_t i = 0; i < v; i++)
        parent[i] = (uint32_t)i;
    const uint32_t *ix = mesh->indices;
    for (uint64_t t = 0; t < mesh->triangle_count; t++) {
        join(parent, ix[3 * t], ix[3 * t + 1]);
        join(parent, ix[3 * t], ix[3 * t + 2]);
    }
    for (uint64_t t = 0; t < mesh->triangle_count; t++)
        labels[t] = find_root(parent, ix[3 * t]);
    /* each root's component, numbered in the order of its first triangle */
    uint32_t *number = malloc((v ? v : 1) * sizeof *number);
    if (!number) {
        free(parent);
        return IP_ERR_NOMEM;
    }
    memset(number, 0xff, (v ? v : 1) * sizeof *number);
    for (uint64_t t = 0; t < mesh->triangle_count; t++) {
        uint32_t r = labels[t];
        if (number[r] == UINT32_MAX)
            number[r] = (uint32_t)(*count)++;
        labels[t] = number[r];
    }
    free(number);
    free(parent);
    return IP_OK;
}

void ip_indexed_mesh_component_measures(const ip_indexed_mesh *mesh, const uint32_t *labels,
                                        uint64_t count, uint64_t *triangles, double *area,
                                        double *volume)
{
    for (uint64_t c = 0; c < count; c++) {
        if (triangles)
            triangles[c] = 0;
        if (area)
            area[c] = 0;
        if (volume)
            volume[c] = 0;
    }
    for (uint64_t t = 0; t < mesh->triangle_count; t++) {
        double a, v;
        ip__triangle_measure(mesh, t, &a, &v);
        if (triangles)
            triangles[labels[t]]++;
        if (area)
            area[labels[t]] += a;
        if (volume)
            volume[labels[t]] += v;
    }
}

ip_status ip_indexed_mesh_keep_triangles(ip_indexed_mesh *mesh, const uint8_t *keep)
{
    uint64_t v = mesh->vertex_count;
    uint32_t *remap = malloc((v ? v : 1) * sizeof *remap);
    if (!remap)
        return IP_ERR_NOMEM;
    memset(remap, 0xff, (v ? v : 1) * sizeof *remap);
    uint32_t *ix = mesh->indices;
    uint64_t kept = 0;
    for (uint64_t t = 0; t < mesh->triangle_count; t++) {
        if (!keep[t])
            continue;
        for (int c = 0; c < 3; c++)
            remap[ix[3 * t + c]] = 0; /* used */
        memmove(ix + 3 * kept++, ix + 3 * t, 3 * sizeof *ix);
    }
    /* the used vertices keep their order */
    uint64_t used = 0;
    for (uint64_t i = 0; i < v; i++) {
        if (remap[i] == UINT32_MAX)
            continue;
        remap[i] = (uint32_t)used;
        memmove(mesh->positions + 3 * used, mesh->positions + 3 * i, 3 * sizeof(float));
        memmove(mesh->normals + 3 * used, mesh->normals + 3 * i, 3 * sizeof(int16_t));
        used++;
    }
    for (uint64_t i = 0; i < 3 * kept; i++)
        ix[i] = remap[ix[i]];
    free(remap);
    mesh->triangle_count = kept;
    mesh->vertex_count = used;
    return IP_OK;
}

/* The triangles to keep: those of the components that pass (largest: only the one of the
 * greatest area, the first of equals; and an area of min_area or more). */
static void mark_kept(const ip_indexed_mesh *mesh, const uint32_t *labels, const double *area,
                      uint64_t count, int largest, double min_area, uint8_t *keep,
                      uint64_t *removed)
{
    uint64_t best = 0;
    for (uint64_t c = 1; c < count; c++)
        best = area[c] > area[best] ? c : best;
    *removed = 0;
    for (uint64_t c = 0; c < count; c++)
        if ((largest && c != best) || !(area[c] >= min_area))
            (*removed)++;
    for (uint64_t t = 0; t < mesh->triangle_count; t++) {
        uint32_t c = labels[t];
        keep[t] = !((largest && c != best) || !(area[c] >= min_area));
    }
}

ip_status ip_indexed_mesh_clean(ip_indexed_mesh *mesh, int largest, double min_area,
                                uint64_t *removed)
{
    uint64_t dummy;
    removed = removed ? removed : &dummy;
    *removed = 0;
    if (!(min_area >= 0))
        return IP_ERR_ARGUMENT;
    uint64_t t = mesh->triangle_count, count;
    uint32_t *labels = malloc((t ? t : 1) * sizeof *labels);
    uint8_t *keep = malloc(t ? t : 1);
    if (!labels || !keep) {
        free(labels);
        free(keep);
        return IP_ERR_NOMEM;
    }
    ip_status st = ip_indexed_mesh_components(mesh, labels, &count);
    double *area = st == IP_OK ? malloc((count ? count : 1) * sizeof *area) : NULL;
    if (st == IP_OK && !area)
        st = IP_ERR_NOMEM;
    if (st == IP_OK) {
        ip_indexed_mesh_component_measures(mesh, labels, count, NULL, area, NULL);
        mark_kept(mesh, labels, area, count, largest, min_area, keep, removed);
        st = *removed ? ip_indexed_mesh_keep_triangles(mesh, keep) : IP_OK;
    }
    free(area);
    free(labels);
    free(keep);
    return st;
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* Vertex welding: a triangle soup to an indexed mesh, joining corners at exactly one position.
 * Marching cubes computes a vertex shared by neighbouring cells with the same bits in each
 * (src/engine/mc.h), so no tolerance is needed, and none is used: a tolerance could join
 * distinct vertices of thin triangles and tear the surface it means to close. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "array.h"
#include "internal.h"
#include "isoprop/mesh.h"

#define EMPTY_SLOT UINT32_MAX
#define MAX_VERTICES (UINT64_C(0xffffffff) - 1) /* an index is a uint32; one value marks empty */

/* The welding in progress: the vertices so far and a hash table of them by position. */
typedef struct welder {
    ip_indexed_mesh *out;
    float *normal_sums; /* 3 per vertex */
    uint64_t capacity;  /* vertices allocated */
    uint32_t *slots;    /* open addressing, linear probing: a vertex index or EMPTY_SLOT */
    uint64_t slot_mask; /* slot count - 1, a power of two */
} welder;

void ip_indexed_mesh_init(ip_indexed_mesh *m)
{
    memset(m, 0, sizeof *m);
}

void ip_indexed_mesh_free(ip_indexed_mesh *m)
{
    free(m->positions);
    free(m->normals);
    free(m->indices);
    ip_indexed_mesh_init(m);
}

/* The position p with -0 as +0 (adding +0 does that and changes no other value), so that the
 * bits compare as the values do. */
static void canonical_position(const float p[3], float out[3])
{
    for (int k = 0; k < 3; k++)
        out[k] = p[k] + 0.0f;
}

static uint64_t position_hash(const float p[3])
{
    uint32_t bits[3];
    memcpy(bits, p, sizeof bits);
    uint64_t h = bits[0];
    h = (h * UINT64_C(0x9e3779b97f4a7c15)) ^ bits[1];
    h = (h * UINT64_C(0x9e3779b97f4a7c15)) ^ bits[2];
    h *= UINT64_C(0xd6e8feb86659fd93);
    return h ^ (h >> 32);
}

/* Puts every vertex into a table of `slot_count` slots (a power of two), replacing the old one. */
static ip_status rehash(welder *w, uint64_t slot_count)
{
    uint32_t *slots = malloc(slot_count * sizeof *slots);
    if (!slots)
        return IP_ERR_NOMEM;
    memset(slots, 0xff, slot_count * sizeof *slots); /* EMPTY_SLOT */
    for (uint64_t v = 0; v < w->out->vertex_count; v++) {
        uint64_t i = position_hash(w->out->positions + 3 * v) & (slot_count - 1);
        while (slots[i] != EMPTY_SLOT)
            i = (i + 1) & (slot_count - 1);
        slots[i] = (uint32_t)v;
    }
    free(w->slots);
    w->slots = slots;
    w->slot_mask = slot_count - 1;
    return IP_OK;
}

/* Appends a vertex at p (canonical) with the first corner normal n. */
static ip_status add_vertex(welder *w, const float p[3], const int16_t n[3])
{
    ip_indexed_mesh *m = w->out;
    if (m->vertex_count == MAX_VERTICES)
        return IP_ERR_ARGUMENT;
    if (m->vertex_count == w->capacity) {
        uint64_t cap = ip__array_capacity(w->capacity, m->vertex_count + 1, 1024, 3 * sizeof(float),
                                          IP_ARRAY_HALF);
        /* the arrays that grew keep their contents when a later one cannot */
        ip_status st = cap ? ip__array_resize(&m->positions, cap, 3 * sizeof(float)) : IP_ERR_NOMEM;
        if (st == IP_OK)
            st = ip__array_resize(&m->normals, cap, 3 * sizeof(int16_t));
        if (st == IP_OK)
            st = ip__array_resize(&w->normal_sums, cap, 3 * sizeof(float));
        if (st != IP_OK)
            return st;
        w->capacity = cap;
    }
    uint64_t v = m->vertex_count++;
    memcpy(m->positions + 3 * v, p, 3 * sizeof(float));
    memcpy(m->normals + 3 * v, n, 3 * sizeof(int16_t));
    for (int k = 0; k < 3; k++)
        w->normal_sums[3 * v + k] = 0.0f;
    return IP_OK;
}

/* The slot of the vertex at p (canonical), or the empty slot where it belongs. */
static uint64_t find_slot(const welder *w, const float p[3])
{
    uint64_t i = position_hash(p) & w->slot_mask;
    while (w->slots[i] != EMPTY_SLOT &&
           memcmp(w->out->positions + 3 * (uint64_t)w->slots[i], p, 3 * sizeof(float)) != 0)
        i = (i + 1) & w->slot_mask;
    return i;
}

/* The vertex at p (canonical), added with normal n when new; its normal sum gains n. */
static ip_status vertex_at(welder *w, const float p[3], const int16_t n[3], uint32_t *index)
{
    uint64_t i = find_slot(w, p);
    uint32_t v = w->slots[i];
    if (v == EMPTY_SLOT) {
        ip_status st = add_vertex(w, p, n);
        if (st != IP_OK)
            return st;
        v = w->slots[i] = (uint32_t)(w->out->vertex_count - 1);
        /* at most half full, for short probes */
        if (2 * w->out->vertex_count > w->slot_mask + 1 &&
            (st = rehash(w, 2 * (w->slot_mask + 1))) != IP_OK)
            return st;
    }
    *index = v;
    for (int k = 0; k < 3; k++)
        w->normal_sums[3 * (uint64_t)v + k] += ip_normal_unpack(n[k]);
    return IP_OK;
}

/* Each vertex's normal: its corners' average, normalised; the first corner's where they
 * cancel out. */
static void finish_normals(welder *w)
{
    ip_indexed_mesh *m = w->out;
    for (uint64_t v = 0; v < m->vertex_count; v++) {
        const float *s = w->normal_sums + 3 * v;
        float length = sqrtf(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
        if (length > 0.0f)
            for (int k = 0; k < 3; k++)
                m->normals[3 * v + k] = ip_normal_pack(s[k] / length);
    }
}

/* Whether two of the triangle's canonical corners are at one position. */
static int degenerate(const float c[9])
{
    return memcmp(c, c + 3, 3 * sizeof(float)) == 0 ||
           memcmp(c + 3, c + 6, 3 * sizeof(float)) == 0 || memcmp(c, c + 6, 3 * sizeof(float)) == 0;
}

/* Welds every triangle of `mesh`; those with two corners at one position are left out and
 * counted, unless `keep_degenerate`. */
static ip_status weld_triangles(welder *w, const ip_mesh *mesh, int keep_degenerate)
{
    ip_indexed_mesh *m = w->out;
    for (uint64_t t = 0; t < mesh->triangle_count; t++) {
        float c[9];
        for (int k = 0; k < 3; k++)
            canonical_position(mesh->positions + 9 * t + 3 * k, c + 3 * k);
        if (!keep_degenerate && degenerate(c)) {
            m->dropped_triangles++;
            continue;
        }
        uint32_t *index = m->indices + 3 * m->triangle_count;
        for (int k = 0; k < 3; k++) {
            ip_status st = vertex_at(w, c + 3 * k, mesh->normals + 9 * t + 3 * k, &index[k]);
            if (st != IP_OK)
                return st;
        }
        m->triangle_count++;
    }
    finish_normals(w);
    return IP_OK;
}

static ip_status weld(const ip_mesh *mesh, ip_indexed_mesh *out, int keep_degenerate)
{
    ip_indexed_mesh_init(out);
    welder w = {out, NULL, 0, NULL, 0};
    /* a closed surface has about half as many vertices as triangles: the table starts a
     * quarter full for it, and grows if it must */
    uint64_t slot_count = 1024;
    while (slot_count < 2 * mesh->triangle_count)
        slot_count *= 2;
    ip_status st = mesh->triangle_count > SIZE_MAX / (3 * sizeof(uint32_t)) ? IP_ERR_NOMEM : IP_OK;
    if (st == IP_OK && mesh->triangle_count > 0 &&
        !(out->indices = malloc(mesh->triangle_count * 3 * sizeof(uint32_t))))
        st = IP_ERR_NOMEM;
    if (st == IP_OK)
        st = rehash(&w, slot_count);
    if (st == IP_OK)
        st = weld_triangles(&w, mesh, keep_degenerate);
    free(w.slots);
    free(w.normal_sums);
    if (st != IP_OK) {
        ip_indexed_mesh_free(out);
        return st;
    }
    /* give back the slack of growth; a failure to shrink leaves the larger arrays */
    if (out->vertex_count > 0) {
        (void)ip__array_resize(&out->positions, out->vertex_count, 3 * sizeof(float));
        (void)ip__array_resize(&out->normals, out->vertex_count, 3 * sizeof(int16_t));
    }
    if (out->triangle_count > 0)
        (void)ip__array_resize(&out->indices, out->triangle_count, 3 * sizeof(uint32_t));
    return IP_OK;
}

ip_status ip_mesh_weld(const ip_mesh *mesh, ip_indexed_mesh *out)
{
    return weld(mesh, out, 0);
}

ip_status ip_mesh_weld_keep_degenerate(const ip_mesh *mesh, ip_indexed_mesh *out)
{
    return weld(mesh, out, 1);
}

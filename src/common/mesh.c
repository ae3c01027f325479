/* SPDX-License-Identifier: BSD-3-Clause */
/* Triangle soups: growth and append (the file formats: mesh_write.c). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "array.h"
#include "internal.h"
#include "isoprop/mesh.h"

void ip_mesh_init(ip_mesh *m)
{
    memset(m, 0, sizeof *m);
}

void ip_mesh_init_with_cells(ip_mesh *m)
{
    ip_mesh_init(m);
    m->with_cells = 1;
}

void ip_mesh_free(ip_mesh *m)
{
    int with_cells = m->with_cells;
    free(m->positions);
    free(m->normals);
    free(m->cells);
    ip_mesh_init(m);
    m->with_cells = with_cells;
}

void ip_mesh_clear(ip_mesh *m)
{
    m->triangle_count = 0;
}

ip_status ip_mesh_reserve(ip_mesh *m, uint64_t triangles)
{
    if (triangles <= m->capacity)
        return IP_OK;
    /* Growth by half (not doubling) keeps the slack small for meshes of millions of triangles.
     * glibc moves a block it has mapped by remapping its pages; one it keeps on its heap (as it
     * does for large blocks once a large mapped block has been freed) is copied, which
     * docs/notes/performance-notebook.md part 23 measured at no cost worth arrays mapped by hand. */
    uint64_t cap =
        ip__array_capacity(m->capacity, triangles, 1024, 9 * sizeof(float), IP_ARRAY_HALF);
    /* Moved arrays hold their triangles; what was populated past them may not have moved. */
    m->populated = m->populated < m->triangle_count ? m->populated : m->triangle_count;
    /* the arrays that grew keep the old contents when a later one cannot */
    ip_status st = cap ? ip__array_resize(&m->positions, cap, 9 * sizeof(float)) : IP_ERR_NOMEM;
    if (st == IP_OK)
        st = ip__array_resize(&m->normals, cap, 9 * sizeof(int16_t));
    if (st == IP_OK && m->with_cells)
        st = ip__array_resize(&m->cells, cap, sizeof(uint64_t));
    if (st == IP_OK)
        m->capacity = cap;
    return st;
}

#define POPULATE_TRIANGLES 16384 /* the arrays are populated this many triangles ahead */

/* Populates the arrays' pages from m->populated up to the next multiple of POPULATE_TRIANGLES
 * past `new_count` (or the capacity). Appends are small (a cell's triangles), so this is one
 * system call per POPULATE_TRIANGLES triangles instead of a page fault per page written
 * (internal.h). The mark outlives ip_mesh_clear(): a mesh filled again (the engine's buffers,
 * every few thousand triangles; its mesh, every view) does not ask for its pages again, which
 * would walk them all for nothing. */
static void populate_ahead(ip_mesh *m, uint64_t new_count)
{
    uint64_t after = (new_count + POPULATE_TRIANGLES - 1) / POPULATE_TRIANGLES * POPULATE_TRIANGLES;
    after = after < m->capacity ? after : m->capacity;
    uint64_t before = m->populated;
    if (after <= before)
        return;
    ip__memory_populate(m->positions + 9 * before, (after - before) * 9 * sizeof(float));
    ip__memory_populate(m->normals + 9 * before, (after - before) * 9 * sizeof(int16_t));
    if (m->with_cells)
        ip__memory_populate(m->cells + before, (after - before) * sizeof(uint64_t));
    m->populated = after;
}

ip_status ip_mesh_append(ip_mesh *m, const float *positions, const int16_t *normals,
                         const uint64_t *cells, uint64_t count)
{
    if (count == 0)
        return IP_OK; /* the arrays of an empty mesh may be NULL */
    ip_status st = ip_mesh_reserve(m, m->triangle_count + count);
    if (st != IP_OK)
        return st;
    populate_ahead(m, m->triangle_count + count);
    memcpy(m->positions + 9 * m->triangle_count, positions, count * 9 * sizeof(float));
    memcpy(m->normals + 9 * m->triangle_count, normals, count * 9 * sizeof(int16_t));
    if (m->with_cells)
        memcpy(m->cells + m->triangle_count, cells, count * sizeof(uint64_t));
    m->triangle_count += count;
    return IP_OK;
}

ip_status ip_mesh_append_float_normals(ip_mesh *m, const float *positions, const float *normals,
                                       const uint64_t *cells, uint64_t count)
{
    enum {
        PART = 256
    };
    int16_t packed[9 * PART];
    for (uint64_t done = 0; done < count; done += PART) {
        uint64_t n = count - done < PART ? count - done : PART;
        for (uint64_t i = 0; i < 9 * n; i++)
            packed[i] = ip_normal_pack(normals[9 * done + i]);
        ip_status st =
            ip_mesh_append(m, positions + 9 * done, packed, cells ? cells + done : NULL, n);
        if (st != IP_OK)
            return st;
    }
    return IP_OK;
}

ip_status ip_mesh_append_mesh(ip_mesh *m, const ip_mesh *from, uint64_t first, uint64_t count)
{
    if (first > from->triangle_count || count > from->triangle_count - first ||
        (m->with_cells && count && !from->with_cells))
        return IP_ERR_ARGUMENT;
    if (count == 0)
        return IP_OK;
    return ip_mesh_append(m, from->positions + 9 * first, from->normals + 9 * first,
                          m->with_cells ? from->cells + first : NULL, count);
}

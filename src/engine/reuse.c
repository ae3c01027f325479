/* SPDX-License-Identifier: BSD-3-Clause */
/* Reuse across views (engine.h, "Reuse"): what a new view keeps of the mesh of the view before.
 *
 * The mesh holds whole cells, each as one run of triangles with its cell id (extracted cells
 * append their triangles at once; with culling, whole_cells keeps all of a cell's triangles when
 * one may show). A run is kept in three passes, in place:
 *   1. its level is used by the new view and its centre lies in that level's band (lod.h, the
 *      rule of the full extraction at adaptive resolution), and one of its triangles may be drawn
 *      at a pixel centre of the new image (ip__coverage_add(), which records it);
 *   2. the coverage of all those does not certainly hide the cell's box (ip__coverage_hides());
 *   3. the coverage is cleared and the runs left are recorded again, so that every entry is
 *      backed by a triangle kept in the mesh (cast.c's argument for stopping rays needs that),
 *      and their cells are marked extracted.
 * A cell dropped is simply not extracted yet: a ray or a propagation that needs it extracts it
 * again. A cell kept is whole and of the new view's surface, so the image once every ray has
 * been cast is the one without reuse. Pass 2 drops nothing another kept cell needs: the
 * coverage's nearest entries at a hidden cell's pixels come from triangles nearer than its box,
 * and the nearest of those belong to cells that are not hidden, which pass 3 records again. */
#include <math.h>
#include <string.h>

#include "engine_state.h"
#include "internal.h"
#include "lod.h"

#define CELL_ID_BITS 58 /* ip_cell_id(): the level above them, the linear index below */

/* Triangles [*start, *end) are the run of one cell, from `from` on. */
static void next_run(const ip_mesh *m, uint64_t from, uint64_t *end)
{
    uint64_t id = m->cells[from], i = from + 1;
    while (i < m->triangle_count && m->cells[i] == id)
        i++;
    *end = i;
}

/* The cell of id `id`: its level and its coordinates; 0 when the level is not used. */
static int cell_of(const ip_engine *e, uint64_t id, uint32_t *level, uint32_t cell[3])
{
    *level = (uint32_t)(id >> CELL_ID_BITS);
    if (*level >= e->levels_used)
        return 0;
    const ip_layout *l = ip_store_layout(ip_cache_store(e->cache));
    const ip_level_layout *lv = &l->levels[*level];
    uint64_t linear = id & (((uint64_t)1 << CELL_ID_BITS) - 1);
    uint64_t cx = lv->dims[0] - 1, cy = lv->dims[1] - 1;
    cell[0] = (uint32_t)(linear % cx);
    cell[1] = (uint32_t)(linear / cx % cy);
    cell[2] = (uint32_t)(linear / cx / cy);
    return cell[2] < lv->dims[2] - 1;
}

/* Moves triangles [from, from + count) of the mesh to position `to` (to <= from). */
static void move_run(ip_mesh *m, uint64_t to, uint64_t from, uint64_t count)
{
    if (to == from)
        return;
    memmove(m->positions + 9 * to, m->positions + 9 * from, 9 * count * sizeof *m->positions);
    memmove(m->normals + 9 * to, m->normals + 9 * from, 9 * count * sizeof *m->normals);
    memmove(m->cells + to, m->cells + from, count * sizeof *m->cells);
}

/* Pass 1: the runs of the new view's surface that may show in its image, recorded in the
 * coverage. */
static void keep_in_view(ip_engine *e)
{
    ip_mesh *m = &e->mesh;
    uint64_t kept = 0, end;
    for (uint64_t start = 0; start < m->triangle_count; start = end) {
        next_run(m, start, &end);
        uint32_t level, cell[3];
        if (!cell_of(e, m->cells[start], &level, cell) || end - start > 32)
            continue;
        const ip_sampler *s = &e->workers[0].level[level].sampler;
        double distance = ip__lod_cell_distance(s, cell, e->camera.eye);
        if (!ip__lod_in_band(distance, e->lod_distance[level], e->lod_distance[level + 1]))
            continue;
        if (!ip__coverage_add(&e->coverage, m->positions + 9 * start, (unsigned)(end - start)))
            continue; /* drawn at no pixel centre of the new image */
        move_run(m, kept, start, end - start);
        kept += end - start;
    }
    m->triangle_count = kept;
}

/* Pass 2: the runs whose cell the coverage does not certainly hide. */
static void keep_unhidden(ip_engine *e)
{
    ip_mesh *m = &e->mesh;
    uint64_t kept = 0, end;
    for (uint64_t start = 0; start < m->triangle_count; start = end) {
        next_run(m, start, &end);
        uint32_t level, cell[3];
        (void)cell_of(e, m->cells[start], &level, cell);
        float lo[3], hi[3];
        ip__sampler_cell_box(&e->workers[0].level[level].sampler, cell, lo, hi);
        const double box_lo[3] = {lo[0], lo[1], lo[2]}, box_hi[3] = {hi[0], hi[1], hi[2]};
        if (ip__coverage_hides(&e->coverage, box_lo, box_hi))
            continue;
        move_run(m, kept, start, end - start);
        kept += end - start;
    }
    m->triangle_count = kept;
}

/* Job of the engine's pool: part `index` of the coverage made unknown. */
static void clear_coverage(void *user, unsigned index)
{
    ip_engine *e = user;
    ip__coverage_clear(&e->coverage, index, e->threads);
}

ip_status ip__engine_keep(ip_engine *e)
{
    ip_mesh *m = &e->mesh;
    if (!m->with_cells || !e->options.occlusion)
        return IP_OK;
    keep_in_view(e);
    keep_unhidden(e);
    ip__pool_run(e->pool, e->threads, clear_coverage, e);
    uint64_t cells = 0, end;
    for (uint64_t start = 0; start < m->triangle_count; start = end) {
        next_run(m, start, &end);
        uint32_t level, cell[3];
        (void)cell_of(e, m->cells[start], &level, cell);
        (void)ip__coverage_add(&e->coverage, m->positions + 9 * start, (unsigned)(end - start));
        if (ip__visited_mark(&e->visited, level, cell) < 0)
            return IP_ERR_NOMEM;
        cells++;
    }
    e->totals.triangles += m->triangle_count;
    e->totals.cells += cells;
    e->totals.kept += m->triangle_count;
    return IP_OK;
}

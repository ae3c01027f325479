/* Full extraction: every active cell of a level, brick by brick, skipping by summaries. */
#include <string.h>

#include "internal.h"
#include "isoprop/engine.h"
#include "propagate.h"

/* Triangulates the active cells of one brick, sub-block by sub-block. */
static ip_status extract_brick(ip_sampler *s, ip_mesh *mesh, float iso, uint64_t g,
                               ip_engine_counts *c)
{
    const ip_layout *l = s->layout;
    const float *ranges = ip_store_subblock_ranges(ip_cache_store(s->cache), g);
    uint32_t level, brick[3], origin[3], extent[3];
    ip_brick_coords(l, g, &level, brick);
    ip_brick_extent(l, level, brick, origin, extent);
    uint32_t per = l->brick_edge / l->subblock_edge, se = l->subblock_edge;
    ip_status st = IP_OK;
    for (uint32_t i = 0; i < per * per * per && st == IP_OK; i++) {
        if (!ip_range_active(ranges[2 * i], ranges[2 * i + 1], iso))
            continue;
        uint32_t sb[3] = {i % per, (i / per) % per, i / (per * per)}, lo[3], hi[3];
        for (int a = 0; a < 3; a++) {
            lo[a] = origin[a] + se * sb[a];
            hi[a] = lo[a] + se < origin[a] + extent[a] - 1 ? lo[a] + se : origin[a] + extent[a] - 1;
        }
        for (uint32_t z = lo[2]; z < hi[2] && st == IP_OK; z++)
            for (uint32_t y = lo[1]; y < hi[1] && st == IP_OK; y++)
                for (uint32_t x = lo[0]; x < hi[0]; x++) {
                    uint32_t cell[3] = {x, y, z};
                    unsigned mc;
                    int n = ip_extract_cell(s, mesh, cell, iso, &mc, &st);
                    if (n < 0)
                        break;
                    if (mc != 0 && mc != 255)
                        c->cells++;
                    c->triangles += (uint64_t)n;
                }
    }
    return st;
}

ip_status ip_extract_full(ip_cache *cache, float iso, uint32_t level, ip_mesh *mesh,
                          ip_engine_counts *counts, ip_error *err)
{
    const ip_store *store = ip_cache_store(cache);
    const ip_layout *l = ip_store_layout(store);
    if (level >= l->level_count)
        return ip_fail(err, IP_ERR_ARGUMENT, "level %u does not exist", level);
    ip_sampler s;
    if (ip_sampler_init(&s, cache, level) != IP_OK)
        return ip_fail(err, IP_ERR_NOMEM, "out of memory");
    ip_engine_counts c;
    memset(&c, 0, sizeof c);
    double start = ip_now_seconds();
    ip_status st = IP_OK;
    const ip_level_layout *lv = &l->levels[level];
    for (uint64_t i = 0; i < lv->brick_count && st == IP_OK; i++) {
        float range[2];
        ip_store_brick_range(store, lv->first_brick + i, range);
        if (ip_range_active(range[0], range[1], iso))
            st = extract_brick(&s, mesh, iso, lv->first_brick + i, &c);
        ip_sampler_release(&s); /* a brick at a time: only its neighbours stay pinned briefly */
    }
    c.extraction_seconds = ip_now_seconds() - start;
    if (st != IP_OK) {
        if (st == IP_ERR_NOMEM)
            ip_fail(err, st, "out of memory");
        else if (err)
            *err = s.error;
    }
    ip_sampler_free(&s);
    if (counts)
        *counts = c;
    return st;
}

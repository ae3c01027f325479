/* SPDX-License-Identifier: BSD-3-Clause */
/* isorender's extraction, progressive (with checkpoints) or full, of every surface. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "isorender.h"

static int add_checkpoint(run *r, double start)
{
    ip_engine_counts t;
    ip_engine_totals(r->engine, &t);
    checkpoint *grown = realloc(r->checkpoints, (r->checkpoint_count + 1) * sizeof *grown);
    if (!grown)
        return -1;
    r->checkpoints = grown;
    r->checkpoints[r->checkpoint_count++] =
        (checkpoint){ip_now_seconds() - start, t.rays, t.seeds, t.cells, t.triangles, 0, 0};
    return 0;
}

/* After each step: the bar (rays done of those asked for, triangles so far) and, with
 * --verbose, the step's counts on a line of their own. */
static void step_report(const run *r, tool_progress *bar, uint64_t limit)
{
    ip_engine_counts t;
    ip_engine_totals(r->engine, &t);
    uint64_t pixels = (uint64_t)r->camera.width * r->camera.height;
    uint64_t total = limit < pixels ? limit : pixels;
    char detail[48];
    snprintf(detail, sizeof detail, "%llu triangles", (unsigned long long)t.triangles);
    tool_progress_draw(bar, ip_engine_done(r->engine) ? total : t.rays, total, "rays", detail);
    if (r->o.common.verbose) {
        tool_progress_end(bar);
        fprintf(
            stderr,
            "isorender: step: %llu rays (%llu retired), %llu seeds, %llu cells, %llu triangles, "
            "%.3f s\n",
            (unsigned long long)t.rays, (unsigned long long)t.retired, (unsigned long long)t.seeds,
            (unsigned long long)t.cells, (unsigned long long)t.triangles,
            tool_progress_elapsed(bar));
    }
}

int create_engine(run *r, ip_error *err)
{
    if (r->engine)
        return 0;
    ip_engine_options eo;
    tool_engine_options(&r->o.common, &eo);
    if (ip_engine_create(r->cache, &eo, &r->engine, err) != IP_OK)
        return -1;
    tool_signals_cancel_engine(r->engine);
    return 0;
}

/* Casts rays until done, the ray count or the time limit, checkpointing as the count doubles. */
static int extract_progressive(run *r, ip_error *err)
{
    if (create_engine(r, err) != 0)
        return -1;
    if (r->o.warm) { /* the same work once, untimed: the bricks it needs stay in the cache */
        if (ip_engine_begin(r->engine, &r->camera, (float)r->o.common.iso_stored, err) != IP_OK ||
            ip_engine_step(r->engine, r->o.common.rays, r->o.common.time_limit, NULL, err) != IP_OK)
            return -1;
    }
    strip_plan_rays(r);
    double start = ip_now_seconds(); /* a view's time counts its set-up (the coverage buffer) */
    if (ip_engine_begin(r->engine, &r->camera, (float)r->o.common.iso_stored, err) != IP_OK)
        return -1;
    uint64_t target = 1, limit = r->o.common.rays ? r->o.common.rays : UINT64_MAX;
    tool_progress bar;
    tool_progress_start(&bar, !r->o.common.quiet, "ISORENDER_PROGRESS");
    /* ip_engine_begin() clears a cancel: a signal before it is seen through the flag */
    while (!ip_engine_done(r->engine) && !tool_signal_caught()) {
        ip_engine_counts t;
        ip_engine_totals(r->engine, &t);
        if (t.rays >= limit)
            break;
        double left =
            r->o.common.time_limit > 0 ? r->o.common.time_limit - (ip_now_seconds() - start) : 0;
        if (r->o.common.time_limit > 0 && left <= 0)
            break;
        uint64_t next = target < limit ? target : limit, stop = strip_stop(r, t.rays, next);
        if (ip_engine_step(r->engine, stop - t.rays, left, NULL, err) != IP_OK) {
            tool_progress_end(&bar);
            return -1;
        }
        step_report(r, &bar, limit);
        strip_record(r);
        if (stop < next && !ip_engine_done(r->engine))
            continue; /* a frame of the strip, between two checkpoints */
        if (add_checkpoint(r, start) != 0) {
            tool_progress_end(&bar);
            return -1;
        }
        target *= 2;
    }
    tool_progress_end(&bar);
    r->extraction_wall = ip_now_seconds() - start;
    ip_engine_totals(r->engine, &r->totals);
    r->mesh = ip_engine_mesh(r->engine);
    return 0;
}

/* --full (level 0) or --full-lod (the view's levels, each in its band) into r->full_mesh. */
static ip_status full_extraction(run *r, ip_engine_counts *counts, ip_error *err)
{
    return tool_full_extraction(r->cache, r->o.common.iso_stored, r->o.full, &r->camera,
                                &r->o.common, &r->full_mesh, counts, err);
}

int extract_full(run *r, ip_error *err)
{
    ip_mesh_init(&r->full_mesh);
    if (r->o.warm) {
        if (full_extraction(r, NULL, err) != IP_OK)
            return -1;
        ip_mesh_clear(&r->full_mesh);
    }
    double start = ip_now_seconds();
    if (full_extraction(r, &r->totals, err) != IP_OK || cap_surface(r, err) != 0)
        return -1;
    r->extraction_wall = ip_now_seconds() - start;
    r->mesh = &r->full_mesh;
    return 0;
}

int extract_surfaces(run *r, ip_error *err)
{
    for (size_t i = 0; i <= r->other_count; i++) {
        run *s = surface_run(r, i);
        if (i && tool_signal_caught()) { /* the later surfaces have no mesh: stop here */
            err->code = IP_ERR_CANCELLED;
            snprintf(err->message, sizeof err->message, "cancelled");
            return -1;
        }
        share_view(r, s);
        if ((s->o.full ? extract_full(s, err) : extract_progressive(s, err)) != 0)
            return -1;
    }
    return 0;
}

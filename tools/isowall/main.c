/* SPDX-License-Identifier: BSD-3-Clause */
/* isowall: the run on every MPI process: extraction of the work units, the composite, the
 * outputs and the statistics (see isowall.h). */
#include <errno.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "composite.h"
#include "isoprop/cache.h"
#include "isoprop/engine.h"
#include "isoprop/store.h"
#include "watch.h"

/* What one rank did, gathered on rank 0 for --stats (doubles, so one MPI type carries it). */
enum {
    REC_BUSY,
    REC_IDLE,
    REC_UNITS,
    REC_RAYS,
    REC_SEEDS,
    REC_CELLS,
    REC_TRIANGLES,
    REC_BYTES,
    REC_RSS_MB,
    REC_STOLEN,
    REC_COUNT
};

typedef struct wall_run {
    wall_options o;
    tool_outputs outputs; /* the files this process wrote: kept only when every process's run
                             succeeded (tool_outputs.h) */
    int rank, ranks;
    ip_store *store;
    ip_cache *cache;
    ip_engine *engine;
    tool_space space; /* the file's physical space: the view, the planes, the image */
    wall_layout layout;
    double *cost;   /* per region: CPU seconds of its first pass (summed over the ranks) */
    int *taker;     /* dynamic: per region, the rank that took its first pass */
    uint32_t *list; /* dynamic: the current pass's regions, each rank's share contiguous */
    double *weight; /* dynamic: prefix sums of the list's expected costs (region_count + 1) */
    MPI_Win counter_window; /* dynamic: per pass, one share word per rank on rank 0 */
    uint64_t *counters;     /* rank 0's (NULL elsewhere) */
    uint64_t *words;        /* dynamic: room for every rank's share word, for a steal */
    int window_made;
    double busy, idle; /* CPU seconds on units; wall seconds waiting for work */
    uint64_t units, bytes_sent, stolen;
    wall_composite composite;
    uint8_t *image; /* rank 0, one image: the wall's colours */
    double start, coarse_seconds, extraction_seconds, total_seconds;
    const char *program;
} wall_run;

/* "the first pass" or "the second pass", for the watchdog's line. */
static const char *pass_name(int pass)
{
    return pass ? "the second pass" : "the first pass";
}

/* The rank that takes unit u of a pass under --static: the owner of the unit's tile. */
static int tile_owner(uint32_t tile, int ranks)
{
    return (int)(tile % (uint32_t)ranks);
}

/* The owner of every tile when the composite goes to rank 0's one image. */
static int rank_zero(uint32_t tile, int ranks)
{
    (void)tile, (void)ranks;
    return 0;
}

/* Whether every rank succeeded (ok != 0 on each); every rank must call it. */
static int all_ok(int ok)
{
    MPI_Allreduce(MPI_IN_PLACE, &ok, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    return ok;
}

/* Prints the error of the first rank that failed, once for the whole job. */
static int report_first_failure(const wall_run *r, int failed, const ip_error *err)
{
    int first = failed ? r->rank : r->ranks;
    MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (first == r->rank)
        tool_fail(r->program, err);
    return first < r->ranks;
}

/* The camera over the whole wall, as isorender makes it for --size C*W x R*H. */
static int setup_layout(wall_run *r, ip_error *err)
{
    wall_layout *w = &r->layout;
    tool_space_of(r->store, &r->space);
    memcpy(w->lo, r->space.lo, sizeof w->lo);
    memcpy(w->hi, r->space.hi, sizeof w->hi);
    tool_space_clip(&r->space, &r->o.common);
    w->cols = r->o.cols;
    w->rows = r->o.rows;
    w->tile_w = r->o.tile_w;
    w->tile_h = r->o.tile_h;
    w->tile_count = w->cols * w->rows;
    if (tool_space_camera(&r->space, r->o.common.camera, r->o.common.view, r->o.common.width,
                          r->o.common.height, &w->camera, err) != 0)
        return -1;
    tool_apply_orbit(&r->o.orbit, &r->space, &w->camera);
    if (wall_layout_regions(w, r->o.unit_w, r->o.unit_h) != 0) {
        err->code = IP_ERR_NOMEM;
        snprintf(err->message, sizeof err->message, "out of memory for the regions");
        return -1;
    }
    return 0;
}

/* ---- dynamic units: a share of the list per rank, stolen from when a rank's own runs out ----
 *
 * Each pass has a list of the regions in which every rank's share is a contiguous run (the first
 * pass: patches of 2 x 2 neighbouring regions spread over the wall; the second: the regions the
 * rank took in the first pass, whose surface it has, by expected cost, most first). Rank 0's
 * window holds, per pass and rank, one 64-bit word: the positions [lo, hi) of the list still
 * unclaimed in that rank's share, lo in the low 32 bits. A rank takes its share's next position
 * with one atomic add of 1 (lo >= hi: the share is spent); then it steals the far half (by
 * expected cost) of the share with the most left, under an exclusive lock of the window, and the
 * stolen run becomes its own share (which others may steal from in turn). A rank's regions stay
 * neighbours or ones it has already seen, so its visited set and cache serve them, and the last
 * units taken are small. */

/* A share word: the unclaimed list positions [lo, hi), lo in the low 32 bits. */
static uint64_t share_word(uint64_t lo, uint64_t hi)
{
    return lo | hi << 32;
}

/* One atomic fetch-and-op on word `slot` of rank 0's window; returns the word before it. */
static uint64_t word_op(wall_run *r, int slot, uint64_t value, MPI_Op op)
{
    uint64_t got;
    MPI_Win_lock(MPI_LOCK_SHARED, 0, 0, r->counter_window);
    MPI_Fetch_and_op(&value, &got, MPI_UINT64_T, 0, slot, op, r->counter_window);
    MPI_Win_unlock(0, r->counter_window);
    r->bytes_sent += sizeof value;
    return got;
}

/* Steals from another rank's share of the pass: the far half of the one with the most expected
 * cost left, and the rest of the stolen run becomes this rank's share, all under an exclusive
 * lock of the window (so no other rank takes from the shares meanwhile). Returns the list
 * position of the first unit taken, or -1 when every share is spent. */
static int64_t steal(wall_run *r, int pass)
{
    int base = pass * r->ranks;
    const double *w = r->weight;
    uint64_t *words = r->words;
    MPI_Win_lock(MPI_LOCK_EXCLUSIVE, 0, 0, r->counter_window);
    for (int k = 0; k < r->ranks; k++)
        MPI_Fetch_and_op(NULL, &words[k], MPI_UINT64_T, 0, base + k, MPI_NO_OP, r->counter_window);
    MPI_Win_flush(0, r->counter_window);
    r->bytes_sent += (uint64_t)r->ranks * sizeof *words;
    int victim = -1;
    double most = 0;
    for (int k = 0; k < r->ranks; k++) {
        uint32_t lo = (uint32_t)words[k], hi = (uint32_t)(words[k] >> 32);
        if (k != r->rank && lo < hi && (victim < 0 || w[hi] - w[lo] > most))
            victim = k, most = w[hi] - w[lo];
    }
    int64_t at = -1;
    if (victim >= 0) {
        uint32_t lo = (uint32_t)words[victim], hi = (uint32_t)(words[victim] >> 32), cut = hi - 1;
        while (cut > lo + 1 && w[hi] - w[cut] < most / 2)
            cut--;
        uint64_t theirs = share_word(lo, cut), mine = share_word(cut + 1, hi), old;
        MPI_Fetch_and_op(&theirs, &old, MPI_UINT64_T, 0, base + victim, MPI_REPLACE,
                         r->counter_window);
        MPI_Fetch_and_op(&mine, &old, MPI_UINT64_T, 0, base + r->rank, MPI_REPLACE,
                         r->counter_window);
        r->bytes_sent += 2 * sizeof mine;
        at = cut;
    }
    MPI_Win_unlock(0, r->counter_window);
    return at;
}

/* --static: the next region from *cursor on whose tile this rank owns, or -1 when the pass is
 * done. */
static int64_t next_static(const wall_run *r, int64_t *cursor)
{
    int64_t count = r->layout.region_count;
    while (*cursor < count && tile_owner(r->layout.regions[*cursor].tile, r->ranks) != r->rank)
        (*cursor)++;
    return *cursor < count ? (*cursor)++ : -1;
}

/* Dynamic: the next region of this rank's share of the pass, else a stolen one (*stealing is
 * set from the first steal on: every later unit of the pass is from a stolen run). Returns the
 * region's index, or -1 when the pass is done. */
static int64_t next_dynamic(wall_run *r, int pass, int *stealing)
{
    double wait = MPI_Wtime();
    wall_watch_stage("taking a unit of %s from the window of shares on rank 0", pass_name(pass));
    uint64_t mine = word_op(r, pass * r->ranks + r->rank, 1, MPI_SUM);
    int64_t at = (uint32_t)mine < (uint32_t)(mine >> 32) ? (int64_t)(uint32_t)mine : -1;
    if (at < 0)
        wall_watch_stage("stealing a unit of %s under an exclusive lock of the window of "
                         "shares on rank 0",
                         pass_name(pass));
    if (at < 0 && (at = steal(r, pass)) >= 0)
        *stealing = 1;
    r->idle += MPI_Wtime() - wait;
    if (at < 0)
        return -1;
    r->stolen += *stealing;
    return (int64_t)r->list[at];
}

/* Rank 0 sets every rank's share of the pass's list: rank k's is [bounds[k], bounds[k + 1]). */
static void set_shares(wall_run *r, int pass, const uint32_t *bounds)
{
    if (r->rank != 0)
        return;
    MPI_Win_lock(MPI_LOCK_EXCLUSIVE, 0, 0, r->counter_window);
    for (int k = 0; k < r->ranks; k++)
        r->counters[pass * r->ranks + k] = share_word(bounds[k], bounds[k + 1]);
    MPI_Win_unlock(0, r->counter_window);
}

/* Casts the rays of one pass over the units this rank takes. */
static int run_pass(wall_run *r, int pass, ip_error *err)
{
    int64_t cursor = 0, u;
    int stealing = 0;
    while ((u = r->o.is_static ? next_static(r, &cursor) : next_dynamic(r, pass, &stealing)) >= 0) {
        const wall_region *g = &r->layout.regions[u];
        uint64_t pixels = (uint64_t)g->width * g->height, coarse = wall_coarse_rays(g);
        uint64_t first = pass ? coarse : 0, count = pass ? pixels - coarse : coarse;
        double start = wall_cpu_seconds();
        wall_watch_stage("casting the rays of region %lld in %s", (long long)u, pass_name(pass));
        if (count > 0) {
            if (ip_engine_set_region(r->engine, g->x, g->y, g->width, g->height, first, count,
                                     err) != IP_OK)
                return -1;
            while (!ip_engine_done(r->engine))
                if (ip_engine_step(r->engine, 0, 0, NULL, err) != IP_OK)
                    return -1;
        }
        double spent = wall_cpu_seconds() - start;
        r->busy += spent;
        if (pass == 0) {
            r->cost[u] = spent;
            r->taker[u] = r->rank;
        }
        r->units++;
    }
    return 0;
}

typedef struct costed {
    int taker;
    double cost;
    uint32_t region;
} costed;

/* qsort() order of the second pass's list: by taker, then most expected cost first, then by
 * region (so that every rank sorts to the same list). */
static int compare_cost(const void *a, const void *b)
{
    const costed *x = a, *y = b;
    if (x->taker != y->taker)
        return x->taker < y->taker ? -1 : 1;
    if (x->cost != y->cost)
        return x->cost > y->cost ? -1 : 1;
    return (x->region > y->region) - (x->region < y->region);
}

/* Every rank computes the same list and prefix sums of its weights (cost + 1e-9 s, so that a
 * unit never weighs 0), and rank 0 sets the shares; bounds: ranks + 1 entries. */
static void set_list(wall_run *r, int pass, const costed *order, uint32_t *bounds)
{
    uint32_t n = r->layout.region_count;
    r->weight[0] = 0;
    for (uint32_t i = 0; i < n; i++) {
        r->list[i] = order[i].region;
        r->weight[i + 1] = r->weight[i] + order[i].cost + 1e-9;
    }
    set_shares(r, pass, bounds);
}

/* The first pass's list: the regions in a Z order over the wall's grid of regions, dealt out
 * in blocks of 2 x 2 neighbours, block b to rank b % ranks, so that each rank's share is a
 * contiguous run of the list made of small patches spread over the whole wall (the surface is
 * not known yet: where it lies in one patch of the wall, every share has some of it). Returns
 * 0, or -1 when out of memory. */
static int first_list(wall_run *r)
{
    enum {
        BLOCK = 4
    };
    uint32_t n = r->layout.region_count, blocks = (n + BLOCK - 1) / BLOCK;
    costed *order = malloc(n * sizeof *order);
    uint32_t *bounds = malloc(((size_t)r->ranks + 1) * sizeof *bounds);
    int ok = order && bounds && wall_spatial_order(&r->layout, r->list) == 0;
    if (ok) {
        uint32_t at = 0;
        for (int k = 0; k < r->ranks; k++) {
            bounds[k] = at;
            for (uint32_t b = (uint32_t)k; b < blocks; b += (uint32_t)r->ranks)
                for (uint32_t i = b * BLOCK; i < n && i < (b + 1) * BLOCK; i++)
                    order[at++] = (costed){0, 1.0, r->list[i]};
        }
        bounds[r->ranks] = at;
        set_list(r, 0, order, bounds);
    }
    free(order);
    free(bounds);
    return ok ? 0 : -1;
}

/* qsort() order of doubles, ascending. */
static int compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* What each region's second pass is expected to cost (CPU seconds, into expect[]), from what
 * its first pass cost: twice that, plus its remaining rays at half the wall's typical cost of
 * a first-pass ray (the median over the regions). Rays through empty space dominate the second
 * pass, the surface the first (a rule of thumb from the head of docs/scale-out.md). Returns 0, or
 * -1 when out of memory. */
static int expected_second(const wall_run *r, double *expect)
{
    uint32_t n = r->layout.region_count;
    double *per_ray = malloc(n * sizeof *per_ray);
    if (!per_ray)
        return -1;
    for (uint32_t i = 0; i < n; i++)
        per_ray[i] = r->cost[i] / (double)wall_coarse_rays(&r->layout.regions[i]);
    qsort(per_ray, n, sizeof *per_ray, compare_double);
    double typical = per_ray[n / 2];
    free(per_ray);
    for (uint32_t i = 0; i < n; i++) {
        const wall_region *g = &r->layout.regions[i];
        uint64_t rest = (uint64_t)g->width * g->height - wall_coarse_rays(g);
        expect[i] = 2 * r->cost[i] + (double)rest * typical / 2;
    }
    return 0;
}

/* After the first pass: every rank learns what each region's coarse rays cost and which rank
 * cast them. In the second pass each rank's share is the regions it took in the first, so their
 * surface is already in its mesh and visited set, by expected cost, most first (longest
 * processing time first), so that the units stolen last, from the far ends, are cheap. Every
 * rank computes the same order. Returns 0, or -1 when out of memory. */
static int order_second_pass(wall_run *r)
{
    uint32_t n = r->layout.region_count;
    double wait = MPI_Wtime();
    wall_watch_stage("exchanging the costs of the first pass's units");
    MPI_Allreduce(MPI_IN_PLACE, r->cost, (int)n, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    MPI_Allreduce(MPI_IN_PLACE, r->taker, (int)n, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    r->idle += MPI_Wtime() - wait;
    r->bytes_sent += (uint64_t)n * (sizeof *r->cost + sizeof *r->taker);
    double start = wall_cpu_seconds();
    costed *order = malloc(n * sizeof *order);
    uint32_t *bounds = calloc((size_t)r->ranks + 1, sizeof *bounds);
    double *expect = malloc(n * sizeof *expect);
    int ok = order && bounds && expect && expected_second(r, expect) == 0;
    if (ok) {
        for (uint32_t i = 0; i < n; i++) {
            int t = r->taker[i] >= 0 && r->taker[i] < r->ranks ? r->taker[i] : 0;
            order[i] = (costed){t, expect[i], i};
            bounds[t + 1]++;
        }
        for (int k = 0; k < r->ranks; k++)
            bounds[k + 1] += bounds[k];
        qsort(order, n, sizeof *order, compare_cost);
        set_list(r, 1, order, bounds);
    }
    free(order);
    free(bounds);
    free(expect);
    r->busy += wall_cpu_seconds() - start;
    return ok ? 0 : -1;
}

/* The column, in the wall shown, of the world camera's tile column `col`: the other end of
 * the wall where the space mirrors (the image shown is the physical view, tool_space.h). */
static uint32_t shown_column(const wall_run *r, uint32_t col)
{
    return r->space.mirror ? r->layout.cols - 1 - col : col;
}

/* Rank 0's wall image receives each tile, where the wall shows it. */
static int keep_in_image(uint32_t t, const uint8_t *rgba, void *user, ip_error *err)
{
    (void)err;
    wall_run *r = user;
    const wall_layout *w = &r->layout;
    size_t x0 = (size_t)shown_column(r, t % w->cols) * w->tile_w,
           y0 = (size_t)(t / w->cols) * w->tile_h;
    for (uint32_t y = 0; y < w->tile_h; y++) {
        uint8_t *to = r->image + 4 * ((y0 + y) * w->camera.width + x0);
        memcpy(to, rgba + 4 * (size_t)y * w->tile_w, 4 * (size_t)w->tile_w);
    }
    tool_space_show(&r->space, r->image + 4 * (y0 * w->camera.width + x0), w->tile_w, w->tile_h,
                    w->camera.width);
    return 0;
}

/* --tiles-dir: the owner writes its tile as DIR/tile_COL_ROW.png. */
static int write_tile(uint32_t t, const uint8_t *rgba, void *user, ip_error *err)
{
    wall_run *r = user;
    const wall_layout *w = &r->layout;
    char path[4096];
    snprintf(path, sizeof path, "%s/tile_%u_%u.png", r->o.tiles_dir, shown_column(r, t % w->cols),
             t / w->cols);
    wall_watch_stage("writing %s", path);
    uint8_t *shown = NULL; /* the tile as the wall shows it, where that is another */
    if (r->space.mirror) {
        size_t bytes = (size_t)w->tile_w * w->tile_h * 4;
        if (!(shown = malloc(bytes))) {
            err->code = IP_ERR_NOMEM;
            snprintf(err->message, sizeof err->message, "%.900s: out of memory", path);
            return -1;
        }
        memcpy(shown, rgba, bytes);
        tool_space_show(&r->space, shown, w->tile_w, w->tile_h, w->tile_w);
    }
    ip_status st =
        ip_png_write(path, shown ? shown : rgba, w->tile_w, w->tile_h, r->o.common.force, err);
    free(shown);
    if (st != IP_OK)
        return -1;
    if (tool_outputs_add_or_error(&r->outputs, path, err) != 0)
        return -1;
    return 0;
}

/* Composites the ranks' meshes as they are now into rank 0's image (tiles_dir NULL) or the
 * tile files. A failure aborts the job (ranks may be waiting on this one). */
static void composite(wall_run *r, int to_tiles)
{
    ip_error err;
    ip_error_clear(&err);
    r->composite.owner_of = to_tiles ? tile_owner : rank_zero;
    if (wall_composite_run(&r->composite, ip_engine_mesh(r->engine),
                           to_tiles ? write_tile : keep_in_image, r, &err) != 0) {
        tool_fail(r->program, &err);
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
}

/* Rank 0 writes the image; all ranks learn whether it worked. */
static int write_image(wall_run *r, const char *path)
{
    int ok = 1;
    wall_watch_stage(r->rank == 0 ? "writing %s" : "waiting for rank 0 to write %s", path);
    if (r->rank == 0) {
        ip_error err;
        ip_error_clear(&err);
        if (ip_png_write(path, r->image, r->layout.camera.width, r->layout.camera.height,
                         r->o.common.force, &err) != IP_OK) {
            tool_fail(r->program, &err);
            ok = 0;
        } else if (tool_outputs_add(&r->outputs, path) != 0) {
            fprintf(stderr, "%s: %s: out of memory\n", r->program, path);
            ok = 0;
        }
    }
    MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
    return ok ? 0 : -1;
}

/* Both passes, with the coarse composite between them when asked for. */
static int extract(wall_run *r)
{
    ip_error err;
    ip_error_clear(&err);
    double wait = MPI_Wtime();
    wall_watch_stage("at the barrier before the first pass");
    MPI_Barrier(MPI_COMM_WORLD);
    r->start = MPI_Wtime();
    r->idle += r->start - wait;
    for (int pass = 0; pass < 2; pass++) {
        int failed = run_pass(r, pass, &err) != 0;
        wall_watch_stage("waiting for every process to end %s", pass_name(pass));
        if (report_first_failure(r, failed, &err))
            return -1;
        wait = MPI_Wtime();
        wall_watch_stage("at the barrier after %s", pass_name(pass));
        MPI_Barrier(MPI_COMM_WORLD); /* the pass is done on every rank */
        r->idle += MPI_Wtime() - wait;
        if (pass == 0) {
            r->coarse_seconds = MPI_Wtime() - r->start;
            if (!r->o.is_static) {
                if (!all_ok(order_second_pass(r) == 0)) {
                    if (r->rank == 0)
                        fprintf(stderr, "%s: out of memory for the second pass\n", r->program);
                    return -1;
                }
                wall_watch_stage("at the barrier after the second pass's shares were set");
                MPI_Barrier(MPI_COMM_WORLD); /* the shares are set */
            }
            if (r->o.coarse) {
                composite(r, 0);
                if (write_image(r, r->o.coarse) != 0)
                    return -1;
            }
        }
    }
    r->extraction_seconds = MPI_Wtime() - r->start;
    composite(r, r->o.tiles_dir != NULL);
    if (!r->o.tiles_dir && write_image(r, r->o.out) != 0)
        return -1;
    r->total_seconds = MPI_Wtime() - r->start;
    return 0;
}

/* ---- statistics ---- */

typedef struct stats_view {
    const wall_run *r;
    const double *records; /* REC_COUNT per rank */
} stats_view;

/* The sum, the largest value, and the largest busy_s over the mean (1 when nobody was busy)
 * of one field of the ranks' records. */
static double sum_of(const stats_view *v, int field)
{
    double s = 0;
    for (int k = 0; k < v->r->ranks; k++)
        s += v->records[k * REC_COUNT + field];
    return s;
}

static double max_of(const stats_view *v, int field)
{
    double m = 0;
    for (int k = 0; k < v->r->ranks; k++)
        m = v->records[k * REC_COUNT + field] > m ? v->records[k * REC_COUNT + field] : m;
    return m;
}

static double balance_of(const stats_view *v)
{
    double mean = sum_of(v, REC_BUSY) / v->r->ranks;
    return mean > 0 ? max_of(v, REC_BUSY) / mean : 1.0;
}

/* Prints --stats' JSON (tool_write_text_file()'s fill; user: the stats_view). */
static void fill_stats(FILE *out, void *user)
{
    const stats_view *v = user;
    const wall_run *r = v->r;
    const wall_layout *w = &r->layout;
    ip_camera physical; /* the camera as the file's space states it */
    tool_space_physical(&r->space, &w->camera, &physical);
    const ip_camera *c = &physical;
    fprintf(out, "{\n  \"program\": \"isowall\",\n  \"file\": ");
    tool_json_string(out, r->o.file);
    fprintf(out, ",\n  \"iso\": %.9g", r->o.common.iso_value);
    if (r->o.common.rescale && r->o.common.rescale->present) {
        fprintf(out, ",\n  \"iso_stored\": %.9g,\n  \"rescale\": ", r->o.common.iso_stored);
        tool_write_rescale_json(out, r->o.common.rescale);
    }
    fprintf(out,
            ",\n  \"width\": %u,\n  \"height\": %u,\n"
            "  \"wall\": [%u, %u],\n  \"tile\": [%u, %u],\n  \"unit\": [%u, %u],\n"
            "  \"camera\": [%.9g, %.9g, %.9g, %.9g, %.9g, %.9g, %.9g, %.9g, %.9g, %.9g],\n"
            "  \"processes\": %d,\n  \"static\": %s,\n  \"regions\": %u,\n  \"passes\": 2,\n"
            "  \"units\": %.0f,\n  \"rays\": %.0f,\n  \"seeds\": %.0f,\n  \"cells\": %.0f,\n"
            "  \"triangles\": %.0f,\n  \"bytes_sent\": %.0f,\n  \"tiles_drawn\": %llu,\n"
            "  \"busy_s\": %.6f,\n  \"max_busy_s\": %.6f,\n  \"balance\": %.4f,\n"
            "  \"coarse_s\": %.6f,\n  \"extraction_s\": %.6f,\n  \"time_s\": %.6f,\n"
            "  \"threads\": %u,\n  \"lod\": %s,\n  \"occlusion\": %s,\n  \"prefetch\": %s,\n"
            "  \"ranks\": [",
            c->width, c->height, w->cols, w->rows, w->tile_w, w->tile_h, r->o.unit_w, r->o.unit_h,
            c->eye[0], c->eye[1], c->eye[2], c->target[0], c->target[1], c->target[2], c->up[0],
            c->up[1], c->up[2], c->fov_y, r->ranks, r->o.is_static ? "true" : "false",
            w->region_count, sum_of(v, REC_UNITS), sum_of(v, REC_RAYS), sum_of(v, REC_SEEDS),
            sum_of(v, REC_CELLS), sum_of(v, REC_TRIANGLES), sum_of(v, REC_BYTES),
            (unsigned long long)r->composite.tiles_drawn, sum_of(v, REC_BUSY), max_of(v, REC_BUSY),
            balance_of(v), r->coarse_seconds, r->extraction_seconds, r->total_seconds,
            r->o.common.threads, r->o.common.lod ? "true" : "false",
            r->o.common.occlusion ? "true" : "false", r->o.common.prefetch ? "true" : "false");
    for (int k = 0; k < r->ranks; k++) {
        const double *x = v->records + k * REC_COUNT;
        fprintf(out,
                "%s\n    {\"rank\": %d, \"busy_s\": %.6f, \"idle_s\": %.6f, \"units\": %.0f, "
                "\"rays\": %.0f, \"seeds\": %.0f, \"cells\": %.0f, \"triangles\": %.0f, "
                "\"bytes_sent\": %.0f, \"peak_rss_mb\": %.1f, \"stolen\": %.0f}",
                k ? "," : "", k, x[REC_BUSY], x[REC_IDLE], x[REC_UNITS], x[REC_RAYS], x[REC_SEEDS],
                x[REC_CELLS], x[REC_TRIANGLES], x[REC_BYTES], x[REC_RSS_MB], x[REC_STOLEN]);
    }
    fprintf(out, "\n  ]\n}\n");
}

/* Gathers every rank's record on rank 0, which prints the summary and writes --stats. */
static int report(wall_run *r)
{
    ip_engine_counts t;
    ip_engine_totals(r->engine, &t);
    struct rusage usage;
    getrusage(RUSAGE_SELF, &usage);
    double mine[REC_COUNT] = {
        [REC_BUSY] = r->busy + r->composite.busy_seconds,
        [REC_IDLE] = r->idle + r->composite.idle_seconds,
        [REC_UNITS] = (double)r->units,
        [REC_RAYS] = (double)t.rays,
        [REC_SEEDS] = (double)t.seeds,
        [REC_CELLS] = (double)t.cells,
        [REC_TRIANGLES] = (double)t.triangles,
        [REC_BYTES] = (double)(r->bytes_sent + r->composite.bytes_sent),
        [REC_RSS_MB] = (double)usage.ru_maxrss / 1024.0,
        [REC_STOLEN] = (double)r->stolen,
    };
    double *all = r->rank == 0 ? malloc(sizeof mine * (size_t)r->ranks) : NULL;
    if (r->rank == 0 && !all) {
        fprintf(stderr, "%s: out of memory\n", r->program);
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    wall_watch_stage("gathering the statistics on rank 0");
    MPI_Gather(mine, REC_COUNT, MPI_DOUBLE, all, REC_COUNT, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    int ok = 1;
    if (r->rank == 0) {
        stats_view v = {r, all};
        if (!r->o.common.quiet)
            printf("%s: wall %ux%u of %ux%u (%.1f Mpixel), %d processes, %s: %.0f rays, %.0f "
                   "triangles, busy %.3f s (max %.3f s, balance %.3f), %.3f s\n",
                   r->o.file, r->layout.cols, r->layout.rows, r->layout.tile_w, r->layout.tile_h,
                   r->layout.camera.width * (double)r->layout.camera.height / 1e6, r->ranks,
                   r->o.is_static ? "static" : "dynamic", sum_of(&v, REC_RAYS),
                   sum_of(&v, REC_TRIANGLES), sum_of(&v, REC_BUSY), max_of(&v, REC_BUSY),
                   balance_of(&v), r->total_seconds);
        if (r->o.common.stats && (tool_write_text_file(r->program, r->o.common.stats,
                                                       r->o.common.force, fill_stats, &v) != 0 ||
                                  tool_outputs_add(&r->outputs, r->o.common.stats) != 0))
            ok = 0;
        free(all);
    }
    wall_watch_stage("waiting for rank 0 to write the statistics");
    MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
    return ok ? 0 : 1;
}

/* ---- set-up ---- */

/* Rank 0 checks the outputs (and makes --tiles-dir); every rank opens the file, its cache and
 * engine. Returns 0, or 1 once the first failure has been reported. */
static int open_run(wall_run *r)
{
    ip_error err;
    ip_error_clear(&err);
    int ok = 1;
    if (r->rank == 0) {
        wall_watch_stage("checking the outputs");
        const char *inputs[] = {r->o.file};
        const char *outputs[] = {r->o.out, r->o.coarse, r->o.common.stats};
        ok = tool_check_paths(r->program, inputs, 1, outputs, 3, r->o.common.force) == 0;
        if (ok && r->o.tiles_dir && mkdir(r->o.tiles_dir, 0777) != 0 && errno != EEXIST) {
            fprintf(stderr, "%s: %s: %s\n", r->program, r->o.tiles_dir, strerror(errno));
            ok = 0;
        }
    }
    wall_watch_stage("waiting for every process at the start (rank 0 checks the outputs)");
    if (!all_ok(ok))
        return 1;
    wall_watch_stage("opening the brick file");
    int failed = ip_store_open(r->o.file, &r->store, &err) != IP_OK;
    if (!failed)
        tool_settle_iso(&r->o.common, ip_store_layout(r->store));
    if (!failed)
        failed = ip_cache_create(r->store, r->o.common.cache_bytes, &r->cache, &err) != IP_OK ||
                 setup_layout(r, &err) != 0;
    if (!failed) {
        ip_engine_options eo;
        tool_engine_options(&r->o.common, &eo);
        failed = ip_engine_create(r->cache, &eo, &r->engine, &err) != IP_OK ||
                 ip_engine_begin(r->engine, &r->layout.camera, (float)r->o.common.iso_stored,
                                 &err) != IP_OK;
    }
    wall_watch_stage("waiting for every process to open the brick file");
    if (report_first_failure(r, failed, &err))
        return 1;
    if (r->rank == 0)
        tool_warn_iso_range(r->program, r->store, &r->o.common, NULL, 0);
    size_t bytes = r->rank == 0 ? 2 * (size_t)r->ranks * sizeof(uint64_t) : 0;
    wall_watch_stage("making the window of shares with every process");
    /* an MPI whose one-sided component cannot work beside the watchdog's thread (OpenMPI 4's
     * osc pt2pt under MPI_THREAD_MULTIPLE) fails here: said once, not as MPI's fatal error */
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
    int made = MPI_Win_allocate((MPI_Aint)bytes, sizeof(uint64_t), MPI_INFO_NULL, MPI_COMM_WORLD,
                                &r->counters, &r->counter_window);
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_ARE_FATAL);
    r->window_made = made == MPI_SUCCESS;
    if (!all_ok(r->window_made)) {
        char why[MPI_MAX_ERROR_STRING] = "on another process";
        int length = 0;
        if (!r->window_made)
            MPI_Error_string(made, why, &length);
        if (r->rank == 0)
            fprintf(stderr, "%s: MPI cannot make the window of shares (%s)%s\n", r->program, why,
                    r->o.timeout > 0 ? " beside the watchdog's thread (MPI_THREAD_MULTIPLE, "
                                       "which OpenMPI 4's osc pt2pt refuses): try --timeout 0, "
                                       "no watchdog"
                                     : "");
        return 1;
    }
    size_t pixels = (size_t)r->layout.camera.width * r->layout.camera.height;
    uint32_t n = r->layout.region_count;
    r->cost = calloc(n, sizeof *r->cost);
    r->taker = malloc(n * sizeof *r->taker);
    r->list = malloc(n * sizeof *r->list);
    r->weight = malloc(((size_t)n + 1) * sizeof *r->weight);
    r->words = malloc((size_t)r->ranks * sizeof *r->words);
    int ok_regions = r->cost && r->taker && r->list && r->weight && r->words;
    if (ok_regions) {
        for (uint32_t i = 0; i < n; i++)
            r->taker[i] = -1;
        ok_regions = first_list(r) == 0;
    }
    if (!ok_regions)
        fprintf(stderr, "%s: out of memory for the regions\n", r->program);
    wall_watch_stage("waiting for every process to lay out the regions");
    if (!all_ok(ok_regions))
        return 1;
    int need_image = !r->o.tiles_dir || r->o.coarse;
    if (r->rank == 0 && need_image && !(r->image = malloc(4 * pixels)))
        fprintf(stderr, "%s: out of memory for the %ux%u image\n", r->program,
                r->layout.camera.width, r->layout.camera.height);
    wall_watch_stage("waiting for rank 0 to make room for the image");
    if (!all_ok(r->rank != 0 || !need_image || r->image != NULL))
        return 1;
    r->composite = (wall_composite){&r->layout, &r->o.shading, r->rank, r->ranks, NULL, 0, 0, 0, 0};
    return 0;
}

/* Frees what open_run() made, as far as it got. */
static void close_run(wall_run *r)
{
    wall_watch_stage("freeing the window of shares with every process");
    if (r->window_made)
        MPI_Win_free(&r->counter_window);
    ip_engine_destroy(r->engine);
    ip_cache_destroy(r->cache);
    ip_store_close(r->store);
    free(r->layout.regions);
    free(r->cost);
    free(r->taker);
    free(r->list);
    free(r->weight);
    free(r->words);
    free(r->image);
}

/* Before MPI starts, every process parses the command line; only the first of the job prints
 * what is wrong with it. */
static int parse_quietly_off_rank_zero(int argc, char **argv, wall_options *o)
{
    const char *rank = getenv("OMPI_COMM_WORLD_RANK");
    if (!rank)
        rank = getenv("PMI_RANK");
    int saved = -1;
    if (rank && strcmp(rank, "0") != 0) {
        fflush(stderr);
        saved = dup(2);
        FILE *null = fopen("/dev/null", "w");
        if (null) {
            dup2(fileno(null), 2);
            fclose(null);
        }
    }
    int rc = wall_parse_args(argc, argv, o);
    if (saved >= 0) {
        fflush(stderr);
        dup2(saved, 2);
        close(saved);
    }
    return rc;
}

/* With ISOWALL_PID_DIR=DIR in the environment, each process writes its process id into
 * DIR/rank_K.pid (K: its rank) once its watchdog runs, so that a script can find, signal or
 * trace one rank (the test of the watchdog stops one). Written under another name, then
 * renamed: a reader never sees a part of it. */
static void write_pid_file(int rank)
{
    const char *dir = getenv("ISOWALL_PID_DIR");
    if (!dir || !*dir)
        return;
    char path[4096], part[4200];
    snprintf(path, sizeof path, "%s/rank_%d.pid", dir, rank);
    snprintf(part, sizeof part, "%s.part", path);
    FILE *f = fopen(part, "w");
    int ok = f && fprintf(f, "%ld\n", (long)getpid()) > 0;
    ok = f && fclose(f) == 0 && ok && rename(part, path) == 0;
    if (!ok)
        fprintf(stderr, "isowall: warning: ISOWALL_PID_DIR: cannot write %s: %s\n", path,
                strerror(errno));
}

int main(int argc, char **argv)
{
    wall_run r;
    memset(&r, 0, sizeof r);
    r.program = "isowall";
    int rc = parse_quietly_off_rank_zero(argc, argv, &r.o);
    if (rc)
        return rc;
    /* the watchdog's thread calls MPI beside the main thread; without it, only the main
     * thread does (the engine's threads never do) */
    int watch = r.o.timeout > 0, provided;
    MPI_Init_thread(&argc, &argv, watch ? MPI_THREAD_MULTIPLE : MPI_THREAD_FUNNELED, &provided);
    MPI_Comm_rank(MPI_COMM_WORLD, &r.rank);
    MPI_Comm_size(MPI_COMM_WORLD, &r.ranks);
    if (watch) { /* the lowest level any process got, so that all decide alike */
        MPI_Allreduce(MPI_IN_PLACE, &provided, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
        if (provided < MPI_THREAD_MULTIPLE) {
            if (r.rank == 0)
                fprintf(stderr,
                        "%s: warning: this MPI gives no MPI_THREAD_MULTIPLE: no watchdog "
                        "(--timeout), a process that stops answering hangs the wall\n",
                        r.program);
            watch = 0;
        }
    }
    if (watch)
        wall_watch_start(r.program, r.o.timeout);
    write_pid_file(r.rank);
    rc = open_run(&r);
    if (rc == 0)
        rc = extract(&r) == 0 ? report(&r) : 1;
    /* the outputs of all the processes are one set: a failure anywhere removes them all */
    if (!all_ok(rc == 0)) /* every process calls it */
        tool_outputs_discard(&r.outputs);
    tool_outputs_end(&r.outputs, r.program, r.o.file, rc);
    close_run(&r);
    wall_watch_stop();
    MPI_Finalize();
    return rc;
}

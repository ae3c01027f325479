/* SPDX-License-Identifier: BSD-3-Clause */
/* isoview's record of each pass for --stats: when the change came, when its first frame was
 * shown, when 85 % and 99.5 % of the final pixels were on the screen and when refinement was
 * complete. A pixel is final from the first frame that had drawn the triangle the finished
 * image shows there (the mesh only grows during a pass, and the nearest triangle wins, the
 * earlier one on equal depth), as isorender's --progress counts it. */
#include <stdlib.h>
#include <string.h>

#include "isoview.h"

/* Appends to a growable array of `size`-byte items; returns 0, or -1 when out of memory. */
static int grow(void **items, size_t *capacity, size_t count, size_t size)
{
    if (count < *capacity)
        return 0;
    size_t more = *capacity ? 2 * *capacity : 64;
    void *bigger = realloc(*items, more * size);
    if (!bigger)
        return -1;
    *items = bigger;
    *capacity = more;
    return 0;
}

static pass_record *current(viewer *v)
{
    return v->record_count && !v->pass_recorded ? &v->records[v->record_count - 1] : NULL;
}

/* The pass ends unfinished (a new change came first, or the window closed). */
static void record_abandon(viewer *v)
{
    pass_record *r = current(v);
    if (!r)
        return;
    ip_engine_counts t;
    ip_engine_totals(v->engine, &t);
    r->triangles = t.triangles;
    r->rays = t.rays;
    r->kept = t.kept;
    v->pass_recorded = 1;
}

int record_begin(viewer *v)
{
    record_abandon(v);
    if (grow((void **)&v->records, &v->record_capacity, v->record_count, sizeof *v->records)) {
        set_error(&v->err, IP_ERR_NOMEM, "out of memory");
        return -1;
    }
    pass_record *r = &v->records[v->record_count++];
    memset(r, 0, sizeof *r);
    r->start = ip_now_seconds() - v->start;
    r->first_frame = r->complete = r->final_85 = r->final_995 = -1;
    r->moving = v->engine == v->coarse && v->coarse;
    v->frame_count = 0;
    v->pass_recorded = 0;
    return 0;
}

/* The frame of the pass that first had drawn triangle i. */
static size_t frame_of(const viewer *v, uint32_t i)
{
    size_t lo = 0, hi = v->frame_count - 1;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (v->marks[mid].triangles > i)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

/* The times to 85 % and 99.5 % of the final pixels from the finished image's triangle ids. */
static void final_times(viewer *v, pass_record *r, const uint32_t *index)
{
    size_t n = (size_t)v->camera.width * v->camera.height;
    uint64_t *shown = calloc(v->frame_count, sizeof *shown);
    if (!shown)
        return;
    uint64_t covered = 0;
    for (size_t p = 0; p < n; p++)
        if (index[p] != UINT32_MAX) {
            covered++;
            shown[frame_of(v, index[p])]++;
        }
    uint64_t running = 0;
    for (size_t f = 0; f < v->frame_count; f++) {
        running += shown[f];
        double pct = covered ? 100.0 * (double)running / (double)covered : 100.0;
        if (r->final_85 < 0 && pct >= 85.0)
            r->final_85 = v->marks[f].time;
        if (r->final_995 < 0 && pct >= 99.5)
            r->final_995 = v->marks[f].time;
    }
    free(shown);
}

/* The finished image's triangle ids: the canvas's, or the software rasterizer's of the mesh
 * shown (OpenGL), measured only for --stats. */
static void measure_final(viewer *v, pass_record *r)
{
    const ip_mesh *mesh = shown_mesh(v);
    if (v->canvas && v->canvas_mesh == mesh &&
        ip_canvas_triangle_count(v->canvas) == mesh->triangle_count) {
        final_times(v, r, ip_canvas_triangle_index(v->canvas));
        return;
    }
    if (!v->o.common.stats)
        return;
    uint32_t *index = malloc((size_t)v->camera.width * v->camera.height * sizeof *index);
    if (index && ip_raster_mesh(mesh, &v->camera, v->lo, v->hi, index, NULL, NULL) == IP_OK)
        final_times(v, r, index);
    free(index);
}

void record_frame(viewer *v, double end)
{
    pass_record *r = current(v);
    if (!r)
        return;
    double t = end - v->start - r->start;
    if (grow((void **)&v->marks, &v->frame_capacity, v->frame_count, sizeof *v->marks) == 0) {
        frame_mark *m = &v->marks[v->frame_count++];
        m->time = t;
        m->triangles = v->canvas ? ip_canvas_triangle_count(v->canvas) : v->uploaded;
    }
    r->frames++;
    if (r->first_frame < 0)
        r->first_frame = t;
    if (!v->paused && refinement_complete(v) && !v->restart) {
        r->complete = t;
        ip_engine_counts c;
        if (v->full_shown)
            c = v->full_counts;
        else
            ip_engine_totals(v->engine, &c);
        r->triangles = c.triangles;
        r->rays = c.rays;
        r->kept = c.kept;
        if (v->frame_count == r->frames) /* every frame of the pass is in the log */
            measure_final(v, r);
        v->pass_recorded = 1;
    }
}

void record_end(viewer *v)
{
    record_abandon(v);
}

void record_free(viewer *v)
{
    free(v->records);
    free(v->marks);
}

/* The median of the non-negative values[0 .. n) (sorted in place); -1 when there are none. */
static double median(double *values, size_t n)
{
    size_t m = 0;
    for (size_t i = 0; i < n; i++)
        if (values[i] >= 0)
            values[m++] = values[i];
    if (!m)
        return -1;
    for (size_t i = 1; i < m; i++) /* insertion sort: a few hundred passes at most */
        for (size_t j = i; j > 0 && values[j - 1] > values[j]; j--) {
            double t = values[j];
            values[j] = values[j - 1];
            values[j - 1] = t;
        }
    return m % 2 ? values[m / 2] : 0.5 * (values[m / 2 - 1] + values[m / 2]);
}

static void json_seconds(FILE *f, const char *key, double value)
{
    if (value >= 0)
        fprintf(f, "\"%s\": %.6f", key, value);
    else
        fprintf(f, "\"%s\": null", key);
}

void record_json(FILE *f, const viewer *v)
{
    fprintf(f, ", \"views\": [");
    double *column[4];
    for (int k = 0; k < 4; k++)
        column[k] = calloc(v->record_count + 1, sizeof **column);
    for (size_t i = 0; i < v->record_count; i++) {
        const pass_record *r = &v->records[i];
        fprintf(f, "%s{\"start_s\": %.6f, ", i ? ", " : "", r->start);
        const double at[4] = {r->first_frame, r->final_85, r->final_995, r->complete};
        const char *keys[4] = {"first_frame_s", "final_85_s", "final_995_s", "complete_s"};
        for (int k = 0; k < 4; k++) {
            json_seconds(f, keys[k], at[k]);
            fprintf(f, ", ");
            if (column[k])
                column[k][i] = r->moving ? -1 : at[k];
        }
        fprintf(f,
                "\"view_frames\": %llu, \"view_triangles\": %llu, \"view_kept\": %llu, "
                "\"view_rays\": %llu, \"moving\": %s}",
                (unsigned long long)r->frames, (unsigned long long)r->triangles,
                (unsigned long long)r->kept, (unsigned long long)r->rays,
                r->moving ? "true" : "false");
    }
    fprintf(f, "], \"views_median\": {");
    const char *keys[4] = {"first_frame_s", "final_85_s", "final_995_s", "complete_s"};
    for (int k = 0; k < 4; k++) {
        json_seconds(f, keys[k], column[k] ? median(column[k], v->record_count) : -1);
        fprintf(f, k < 3 ? ", " : "}");
        free(column[k]);
    }
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* isorender --measure, --largest, --min-area: the welded mesh's figures and cleaning
 * (docs/meshes.md, "Measuring" and "Cleaning"). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "isorender.h"

int parse_min_area(const char *program, const tool_option *option, const char *const *values,
                   void *base)
{
    options *o = base;
    double a;
    (void)option;
    if (tool_parse_double(values[0], &a) != 0 || !(a >= 0) || !isfinite(a))
        return tool_usage_error(program, "--min-area '%s' is not an area of 0 or more", values[0]);
    o->min_area = a;
    o->min_area_given = 1;
    return 0;
}

int check_measure_options(const options *o)
{
    int cleaning = o->largest || o->min_area_given;
    if (o->turntable && (o->measure || cleaning))
        return tool_usage_error("isorender", "--turntable writes frames only: no --measure, "
                                             "--largest or --min-area");
    if (!cleaning)
        return 0;
    if (!o->mesh && !o->measure && !o->common.stats)
        return tool_usage_error("isorender", "--largest and --min-area clean the mesh written "
                                             "or measured: they need --mesh, --measure or --stats");
    if (o->no_weld)
        return tool_usage_error("isorender", "--largest and --min-area need shared vertices: "
                                             "no --no-weld");
    return 0;
}

int measuring(const run *r)
{
    /* --stats alone measures the whole surface only: a progressive run's figures, which are for
     * what the view saw, come when asked for (with their warning) */
    const options *o = &r->o;
    return o->measure || (o->common.stats && (o->full || o->largest || o->min_area_given));
}

/* The figures of the welded mesh: area, volume, edges, bounds and components. */
static ip_status measure(const ip_indexed_mesh *m, surface_figures *f)
{
    memset(f, 0, sizeof *f);
    f->triangles = m->triangle_count;
    f->vertices = m->vertex_count;
    f->area = ip_indexed_mesh_area(m);
    f->volume = ip_indexed_mesh_volume(m);
    ip_indexed_mesh_bounds(m, f->lo, f->hi);
    uint64_t boundary, nonmanifold, count;
    ip_status st = ip_indexed_mesh_edges(m, &boundary, &nonmanifold);
    if (st != IP_OK)
        return st;
    f->closed = m->triangle_count > 0 && boundary == 0 && nonmanifold == 0;
    uint32_t *labels = malloc((m->triangle_count ? m->triangle_count : 1) * sizeof *labels);
    if (!labels)
        return IP_ERR_NOMEM;
    st = ip_indexed_mesh_components(m, labels, &count);
    uint64_t *tris = st == IP_OK ? malloc((count ? count : 1) * sizeof *tris) : NULL;
    double *area = st == IP_OK ? malloc((count ? count : 1) * sizeof *area) : NULL;
    double *volume = st == IP_OK ? malloc((count ? count : 1) * sizeof *volume) : NULL;
    if (st == IP_OK && (!tris || !area || !volume))
        st = IP_ERR_NOMEM;
    if (st == IP_OK) {
        ip_indexed_mesh_component_measures(m, labels, count, tris, area, volume);
        uint64_t best = 0;
        for (uint64_t c = 1; c < count; c++)
            best = area[c] > area[best] ? c : best;
        f->components = count;
        if (count) {
            f->largest_triangles = tris[best];
            f->largest_area = area[best];
            f->largest_volume = volume[best];
        }
        f->known = 1;
    }
    free(labels);
    free(tris);
    free(area);
    free(volume);
    return st;
}

/* The name the messages give the mesh: its file, or the volume's when none is written. */
static const char *mesh_name(const run *r)
{
    return r->o.mesh ? r->o.mesh : r->o.file;
}

int clean_and_measure(run *r, ip_indexed_mesh *welded)
{
    ip_status st = IP_OK;
    uint64_t removed = 0;
    if (r->o.largest || r->o.min_area > 0)
        st = ip_indexed_mesh_clean(welded, r->o.largest, r->o.min_area, &removed);
    if (st == IP_OK && measuring(r))
        st = measure(welded, &r->figures);
    r->figures.removed = removed;
    if (st != IP_OK) {
        fprintf(stderr, "isorender: %s: cannot clean or measure %llu triangles (%s)\n",
                mesh_name(r), (unsigned long long)welded->triangle_count, ip_status_message(st));
        return 1;
    }
    if (measuring(r) && !r->o.full) {
        snprintf(r->measure_warning, sizeof r->measure_warning,
                 "the surface's figures are for the part this view extracted (a progressive "
                 "run's mesh is open behind): --full measures the whole surface");
        fprintf(stderr, "isorender: warning: %s\n", r->measure_warning);
    }
    return 0;
}

int measure_unwritten(run *r, const ip_mesh *physical)
{
    ip_indexed_mesh welded;
    ip_status st = ip_mesh_weld(physical, &welded);
    if (st != IP_OK) {
        fprintf(stderr, "isorender: %s: cannot weld %llu triangles (%s)\n", mesh_name(r),
                (unsigned long long)physical->triangle_count, ip_status_message(st));
        return 1;
    }
    int rc = clean_and_measure(r, &welded);
    ip_indexed_mesh_free(&welded);
    return rc;
}

static void json_xyz(FILE *f, const double v[3])
{
    fprintf(f, "[%.9g, %.9g, %.9g]", v[0], v[1], v[2]);
}

void json_surface(FILE *f, const run *r)
{
    const surface_figures *s = &r->figures;
    if (!s->known)
        return;
    fprintf(f,
            ", \"surface\": {\"triangles\": %llu, \"vertices\": %llu, \"area\": %.9g, "
            "\"volume\": %.9g, \"closed\": %s, \"components\": %llu, \"removed_components\": "
            "%llu, \"largest\": {\"triangles\": %llu, \"area\": %.9g, \"volume\": %.9g}, "
            "\"bbox\": {\"min\": ",
            (unsigned long long)s->triangles, (unsigned long long)s->vertices, s->area, s->volume,
            s->closed ? "true" : "false", (unsigned long long)s->components,
            (unsigned long long)s->removed, (unsigned long long)s->largest_triangles,
            s->largest_area, s->largest_volume);
    json_xyz(f, s->lo);
    fprintf(f, ", \"max\": ");
    json_xyz(f, s->hi);
    fprintf(f, "}}");
}

void print_measure(FILE *out, const run *r)
{
    const surface_figures *s = &r->figures;
    if (!r->o.measure || !s->known)
        return;
    fprintf(out, "  surface       %llu triangles, %llu vertices, area %.6g, volume %.6g (%s)\n",
            (unsigned long long)s->triangles, (unsigned long long)s->vertices, s->area, s->volume,
            s->closed ? "closed" : "open: the volume depends on the origin");
    fprintf(out, "  components    %llu", (unsigned long long)s->components);
    if (s->removed)
        fprintf(out, " (%llu removed)", (unsigned long long)s->removed);
    fprintf(out, "; largest %llu triangles, area %.6g, volume %.6g\n",
            (unsigned long long)s->largest_triangles, s->largest_area, s->largest_volume);
    fprintf(out, "  bbox          [%.6g, %.6g, %.6g] to [%.6g, %.6g, %.6g]\n", s->lo[0], s->lo[1],
            s->lo[2], s->hi[0], s->hi[1], s->hi[2]);
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* isorender's figures: final pixels, overdraw, --progress's CSV, --stats' JSON, the summary. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "isorender.h"

/* The first checkpoint whose mesh holds triangle i (checkpoint_count when none). */
static size_t checkpoint_of(const run *r, uint64_t i)
{
    size_t lo = 0, hi = r->checkpoint_count;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (r->checkpoints[mid].triangles > i)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

int final_pixels(run *r, ip_error *err)
{
    double start = ip_now_seconds();
    size_t n = (size_t)r->camera.width * r->camera.height;
    uint32_t *index = malloc(n * sizeof *index);
    if (!index)
        return -1;
    if (ip_raster_mesh(r->mesh, &r->camera, r->lo, r->hi, index, NULL, err) != IP_OK) {
        free(index);
        return -1;
    }
    uint64_t covered = 0;
    for (size_t c = 0; c < r->checkpoint_count; c++)
        r->checkpoints[c].final_pct = 0;
    uint64_t *shown = calloc(r->checkpoint_count + 1, sizeof *shown);
    uint64_t *owners = calloc(r->checkpoint_count + 1, sizeof *owners);
    uint8_t *owns = calloc(r->mesh->triangle_count / 8 + 1, 1); /* a bit per triangle */
    if (!shown || !owners || !owns) {
        free(shown);
        free(owners);
        free(owns);
        free(index);
        return -1;
    }
    r->visible_triangles = 0;
    for (size_t p = 0; p < n; p++) {
        uint32_t i = index[p];
        if (i == UINT32_MAX)
            continue;
        covered++;
        size_t c = checkpoint_of(r, i);
        shown[c]++;
        if (!(owns[i / 8] & (1u << (i % 8)))) {
            owns[i / 8] |= (uint8_t)(1u << (i % 8));
            owners[c]++;
            r->visible_triangles++;
        }
    }
    uint64_t running = 0, visible = 0;
    for (size_t c = 0; c < r->checkpoint_count; c++) {
        running += shown[c];
        visible += owners[c];
        r->checkpoints[c].final_pct = covered ? 100.0 * (double)running / (double)covered : 100.0;
        r->checkpoints[c].visible = visible;
    }
    r->owners_known = 1;
    free(shown);
    free(owners);
    free(owns);
    free(index);
    r->progress_render_seconds = ip_now_seconds() - start;
    return 0;
}

/* Triangles extracted per visible triangle; 0 when none is visible. */
static double overdraw(uint64_t triangles, uint64_t visible)
{
    return visible ? (double)triangles / (double)visible : 0.0;
}

void progress_csv(FILE *f, void *user)
{
    const run *r = user;
    /* the columns scripts read come first, unchanged; later ones are appended: with several
     * surfaces, the isovalue, each surface's rows after the previous one's */
    fprintf(f, "time_s,rays,seeds,cells,triangles,final_pixel_pct,visible_triangles,overdraw%s\n",
            r->other_count ? ",iso" : "");
    for (size_t i = 0; i <= r->other_count; i++) {
        const run *s = surface_run_c(r, i);
        for (size_t c = 0; c < s->checkpoint_count; c++) {
            const checkpoint *k = &s->checkpoints[c];
            fprintf(f, "%.6f,%llu,%llu,%llu,%llu,%.4f,%llu,%.4f", k->time,
                    (unsigned long long)k->rays, (unsigned long long)k->seeds,
                    (unsigned long long)k->cells, (unsigned long long)k->triangles, k->final_pct,
                    (unsigned long long)k->visible, overdraw(k->triangles, k->visible));
            if (r->other_count)
                fprintf(f, ",%.9g", s->o.common.iso_value);
            fprintf(f, "\n");
        }
    }
}

/* A run's "final_pixel_pct" (with checkpoints) and "visible_triangles" and "overdraw" (with
 * the triangles' owners known), as JSON members. */
static void json_quality(FILE *f, const run *r)
{
    if (r->checkpoint_count)
        fprintf(f, ", \"final_pixel_pct\": %.4f",
                r->checkpoints[r->checkpoint_count - 1].final_pct);
    if (r->owners_known)
        fprintf(f, ", \"visible_triangles\": %llu, \"overdraw\": %.4f",
                (unsigned long long)r->visible_triangles,
                overdraw(r->mesh->triangle_count, r->visible_triangles));
}

/* "surfaces": each surface's isovalue, colour, opacity, counts and mesh file. */
static void json_surfaces(FILE *f, const run *r)
{
    ip_mesh views[TOOL_MAX_ISOS];
    fprintf(f, ", \"surfaces\": [");
    for (size_t i = 0; i <= r->other_count; i++) {
        const run *s = surface_run_c(r, i);
        const ip_engine_counts *t = &s->totals;
        ip_surface look;
        surface_of(r, i, NULL, views, &look);
        fprintf(f, "%s{\"iso\": %.9g", i ? ", " : "", s->o.common.iso_value);
        if (s->o.common.rescale && s->o.common.rescale->present)
            fprintf(f, ", \"iso_stored\": %.9g", s->o.common.iso_stored);
        fprintf(f,
                ", \"color\": \"#%02x%02x%02x\", \"opacity\": %g, "
                "\"rays\": %llu, \"done\": %s, \"seeds\": %llu, \"cells\": %llu, "
                "\"triangles\": %llu, \"extraction_wall_s\": %.6f",
                (unsigned)lround(255 * look.colour[0]), (unsigned)lround(255 * look.colour[1]),
                (unsigned)lround(255 * look.colour[2]), (double)look.opacity,
                (unsigned long long)t->rays,
                s->o.full || (s->engine && ip_engine_done(s->engine)) ? "true" : "false",
                (unsigned long long)t->seeds, (unsigned long long)t->cells,
                (unsigned long long)t->triangles, s->extraction_wall);
        json_quality(f, s);
        if (!s->o.full)
            fprintf(f, ", \"deferred_cells\": %llu", (unsigned long long)t->deferred);
        if (s->o.mesh) {
            fprintf(f, ", \"mesh\": ");
            tool_json_string(f, s->o.mesh);
        }
        json_surface(f, s);
        fprintf(f, "}");
    }
    fprintf(f, "]");
}

void json_counts(FILE *f, void *user)
{
    const run *r = user;
    ip_camera physical; /* the camera as the file's space states it */
    tool_space_physical(&r->space, &r->camera, &physical);
    const tool_run_json j = {r->o.file,
                             r->o.common.iso_value,
                             r->o.full,
                             &physical,
                             r->renderer_name ? r->renderer_name : "none",
                             &r->o.common,
                             r->o.warm,
                             r->o.full || (r->engine && ip_engine_done(r->engine)),
                             &r->totals,
                             r->totals.rendering_seconds,
                             r->extraction_wall,
                             r->progress_render_seconds,
                             r->o.common.iso_stored,
                             r->o.common.rescale};
    tool_write_run_json(f, &j);
    json_quality(f, r);
    json_decimate(f, r);
    if (r->o.scale_bar) {
        fprintf(f, ", \"scale_bar\": {\"length\": %.17g, \"unit\": ", r->bar.length);
        tool_json_string(f, scale_unit(r));
        fprintf(f, ", \"pixel_size\": %.17g, \"pixels\": %.17g}", r->bar.pixel_size, r->bar.pixels);
    }
    if (!r->o.full) {
        fprintf(f,
                ", \"occlusion\": %s, \"deferred_cells\": %llu, \"retired_rays\": %llu, "
                "\"ray_nodes\": %llu, \"prefetch\": %s, \"prefetch_mode\": \"%s\", \"cull\": %s, "
                "\"culled_triangles\": %llu",
                r->o.common.occlusion ? "true" : "false", (unsigned long long)r->totals.deferred,
                (unsigned long long)r->totals.retired, (unsigned long long)r->totals.nodes,
                r->o.common.prefetch ? "true" : "false", tool_prefetch_name(r->o.common.prefetch),
                r->o.common.occlusion && r->o.common.cull ? "true" : "false",
                (unsigned long long)r->totals.culled);
    }
    fprintf(f, ", \"warnings\": [");
    size_t written = 0;
    for (size_t i = 0; i <= r->other_count; i++) {
        const run *s = surface_run_c(r, i);
        if (!s->warning[0])
            continue;
        fprintf(f, "%s", written++ ? ", " : "");
        tool_json_string(f, s->warning);
    }
    if (r->measure_warning[0]) { /* the same for every surface of the run: once */
        fprintf(f, "%s", written ? ", " : "");
        tool_json_string(f, r->measure_warning);
    }
    fprintf(f, "]");
    json_surface(f, r);
    if (r->other_count)
        json_surfaces(f, r);
}

/* The summary's lines of surface run s (r: the first surface's, which knows the renderer and
 * the image's rendering time: with several surfaces, given once after them). */
static void print_counts(FILE *out, const run *s, const run *r)
{
    const ip_engine_counts *t = &s->totals;
    fprintf(out, "  rays          %llu of %llu", (unsigned long long)t->rays,
            (unsigned long long)r->camera.width * r->camera.height);
    if (!s->o.full)
        fprintf(out, " (%llu retired without a walk; %llu nodes walked)",
                (unsigned long long)t->retired, (unsigned long long)t->nodes);
    fprintf(out, "\n");
    fprintf(out, "  seeds         %llu\n", (unsigned long long)t->seeds);
    fprintf(out, "  cells         %llu\n", (unsigned long long)t->cells);
    fprintf(out, "  triangles     %llu\n", (unsigned long long)t->triangles);
    if (s->owners_known)
        fprintf(out, "  visible       %llu triangles own a pixel: overdraw %.2f\n",
                (unsigned long long)s->visible_triangles,
                overdraw(s->mesh->triangle_count, s->visible_triangles));
    fprintf(out,
            "  time          %.3f s extraction (wall); CPU s summed over %u threads: "
            "intersection %.3f, propagation %.3f, marching cubes %.3f",
            s->extraction_wall, ip_thread_count(s->o.common.threads), t->intersection_seconds,
            t->propagation_seconds, t->extraction_seconds);
    if (!r->other_count)
        fprintf(out, "; rendering %.3f s (%s)", t->rendering_seconds, r->renderer_name);
    fprintf(out, "\n");
}

void print_summary(FILE *out, const run *r)
{
    if (!r->other_count) {
        char unit[IP_RESCALE_UNIT_MAX + 1];
        fprintf(out, "%s: iso %g%s, %s, %ux%u\n", r->o.file, r->o.common.iso_value,
                tool_unit_suffix(r->o.common.rescale, unit, sizeof unit),
                r->o.full ? "full extraction" : "progressive", r->camera.width, r->camera.height);
        print_counts(out, r, r);
    } else {
        fprintf(out, "%s: %zu surfaces, %s, %ux%u\n", r->o.file, r->other_count + 1,
                r->o.full ? "full extraction" : "progressive", r->camera.width, r->camera.height);
        for (size_t i = 0; i <= r->other_count; i++) {
            char iso[32];
            iso_text(surface_run_c(r, i)->o.common.iso_value, iso, sizeof iso);
            fprintf(out, "  surface %zu     iso %s\n", i + 1, iso);
            print_counts(out, surface_run_c(r, i), r);
        }
        fprintf(out, "  rendering     %.3f s (%s), the surfaces together\n",
                r->totals.rendering_seconds, r->renderer_name);
    }
    fprintf(out, "  image         %s\n", r->o.out);
    for (size_t i = 0; i <= r->other_count; i++) {
        const run *s = surface_run_c(r, i);
        if (s->o.mesh)
            fprintf(out, "  mesh          %s: %llu triangles, %llu vertices%s%s%s\n", s->o.mesh,
                    (unsigned long long)s->mesh_triangles, (unsigned long long)s->mesh_vertices,
                    s->mesh_vertices < 3 * s->mesh->triangle_count ? " (shared)" : "",
                    s->o.smooth ? ", smoothed" : "", s->decimated ? ", decimated" : "");
    }
    for (size_t i = 0; i <= r->other_count; i++)
        print_measure(out, surface_run_c(r, i));
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* What the programs print and write: JSON, byte counts, cache statistics, --stats files. */
#include <math.h>
#include <stdio.h>

#include "tool_common.h"

void tool_json_string(FILE *out, const char *text)
{
    fputc('"', out);
    for (const unsigned char *p = (const unsigned char *)text; *p; p++) {
        if (*p == '"' || *p == '\\')
            fprintf(out, "\\%c", *p);
        else if (*p < 0x20)
            fprintf(out, "\\u%04x", *p);
        else
            fputc(*p, out);
    }
    fputc('"', out);
}

void tool_print_rescale(FILE *out, const ip_input_desc *desc)
{
    if (!desc->has_rescale)
        return;
    double intercept = desc->rescale_intercept;
    fprintf(out,
            "  rescale     values stand for stored x %g %c %g; samples and iso values are in "
            "stored units\n",
            desc->rescale_slope, intercept < 0 ? '-' : '+', fabs(intercept));
}

const char *tool_format_bytes(char *buf, size_t size, double bytes)
{
    static const char *units[] = {"B", "KiB", "MiB", "GiB", "TiB"};
    int u = 0;
    while (bytes >= 1024.0 && u < 4) {
        bytes /= 1024.0;
        u++;
    }
    snprintf(buf, size, u == 0 ? "%.0f %s" : "%.1f %s", bytes, units[u]);
    return buf;
}

static double hit_rate(const ip_cache_stats *s)
{
    uint64_t all = s->hits + s->misses;
    return all ? (double)s->hits / (double)all : 0.0;
}

void tool_print_cache_table(FILE *out, const ip_cache_stats *s, uint64_t summary_bytes)
{
    char a[32], b[32], c[32], d[32], e[32];
    fprintf(out, "cache statistics\n");
    fprintf(out, "  budget          %s\n", tool_format_bytes(a, sizeof a, (double)s->budget_bytes));
    fprintf(out, "  resident        %s now, %s at peak, %llu bricks\n",
            tool_format_bytes(b, sizeof b, (double)s->resident_bytes),
            tool_format_bytes(c, sizeof c, (double)s->resident_peak_bytes),
            (unsigned long long)s->resident_bricks);
    fprintf(out, "  pins            %llu hits, %llu misses (hit rate %.1f %%), %llu evictions\n",
            (unsigned long long)s->hits, (unsigned long long)s->misses, 100.0 * hit_rate(s),
            (unsigned long long)s->evictions);
    fprintf(out, "  decoded         %s from %s in %.3f s\n",
            tool_format_bytes(d, sizeof d, (double)s->bytes_decompressed),
            tool_format_bytes(e, sizeof e, (double)s->bytes_read), s->decode_seconds);
    fprintf(out, "  read ahead      %llu bricks, %llu of them pinned later; waited %.3f s\n",
            (unsigned long long)s->prefetched, (unsigned long long)s->prefetch_hits,
            s->wait_seconds);
    fprintf(out, "  from the disk   %s\n",
            tool_format_bytes(a, sizeof a, (double)s->bytes_read_disk));
    fprintf(out, "  bricks touched  %llu of %llu", (unsigned long long)s->bricks_touched,
            (unsigned long long)s->bricks_total);
    for (uint32_t k = 0; k < s->levels; k++)
        fprintf(out, "%s L%u %llu/%llu", k ? "," : " (", k,
                (unsigned long long)s->level[k].bricks_touched,
                (unsigned long long)s->level[k].bricks_total);
    fprintf(out, "%s\n", s->levels ? ")" : "");
    if (s->over_budget_pins || s->errors)
        fprintf(out,
                "  warnings        %llu loads over budget (all resident bricks pinned), "
                "%llu bad bricks\n",
                (unsigned long long)s->over_budget_pins, (unsigned long long)s->errors);
    fprintf(out, "  summaries       %s\n", tool_format_bytes(a, sizeof a, (double)summary_bytes));
    fprintf(out, "  peak RSS        %s\n",
            tool_format_bytes(b, sizeof b, (double)ip_peak_rss_bytes()));
}

void tool_write_cache_json(FILE *out, const ip_cache_stats *s, uint64_t summary_bytes)
{
    fprintf(out,
            "\"budget_bytes\": %llu, \"resident_bytes\": %llu, "
            "\"resident_peak_bytes\": %llu, \"resident_bricks\": %llu, ",
            (unsigned long long)s->budget_bytes, (unsigned long long)s->resident_bytes,
            (unsigned long long)s->resident_peak_bytes, (unsigned long long)s->resident_bricks);
    fprintf(out,
            "\"hits\": %llu, \"misses\": %llu, \"evictions\": %llu, \"waits\": %llu, "
            "\"hit_rate\": %.6f, ",
            (unsigned long long)s->hits, (unsigned long long)s->misses,
            (unsigned long long)s->evictions, (unsigned long long)s->waits, hit_rate(s));
    fprintf(out, "\"bytes_decompressed\": %llu, \"bytes_read\": %llu, \"decode_seconds\": %.6f, ",
            (unsigned long long)s->bytes_decompressed, (unsigned long long)s->bytes_read,
            s->decode_seconds);
    fprintf(out, "\"over_budget_pins\": %llu, \"pinned_bytes\": %llu, \"errors\": %llu, ",
            (unsigned long long)s->over_budget_pins, (unsigned long long)s->pinned_bytes,
            (unsigned long long)s->errors);
    fprintf(out,
            "\"prefetched\": %llu, \"prefetch_hits\": %llu, \"bytes_read_disk\": %llu, "
            "\"wait_seconds\": %.6f, ",
            (unsigned long long)s->prefetched, (unsigned long long)s->prefetch_hits,
            (unsigned long long)s->bytes_read_disk, s->wait_seconds);
    fprintf(out, "\"bricks_touched\": %llu, \"bricks_total\": %llu, \"levels\": [",
            (unsigned long long)s->bricks_touched, (unsigned long long)s->bricks_total);
    for (uint32_t k = 0; k < s->levels; k++)
        fprintf(out,
                "%s{\"level\": %u, \"bricks_touched\": %llu, \"bricks_total\": %llu, "
                "\"misses\": %llu}",
                k ? ", " : "", k, (unsigned long long)s->level[k].bricks_touched,
                (unsigned long long)s->level[k].bricks_total,
                (unsigned long long)s->level[k].misses);
    fprintf(out, "], \"summary_bytes\": %llu, \"peak_rss_bytes\": %llu",
            (unsigned long long)summary_bytes, (unsigned long long)ip_peak_rss_bytes());
}

typedef struct stats_json {
    const ip_cache_stats *stats;
    uint64_t summary_bytes;
    void (*extra)(FILE *out, void *user);
    void *user;
} stats_json;

static void fill_stats(FILE *out, void *user)
{
    const stats_json *j = user;
    fprintf(out, "{\"cache\": {");
    tool_write_cache_json(out, j->stats, j->summary_bytes);
    fprintf(out, "}");
    if (j->extra) {
        fprintf(out, ", ");
        j->extra(out, j->user);
    }
    fprintf(out, "}\n");
}

int tool_write_stats_file(const char *program, const char *path, int force, const ip_cache_stats *s,
                          uint64_t summary_bytes, void (*extra)(FILE *out, void *user), void *user)
{
    stats_json j = {s, summary_bytes, extra, user};
    return tool_write_text_file(program, path, force, fill_stats, &j);
}

/* "clip": [[A, B, C, D], ...]: each plane keeps A*x + B*y + C*z + D >= 0 (the file's physical
 * units, --clip-index planes turned there too). */
static void write_clip_json(FILE *f, const tool_view_options *o)
{
    fprintf(f, ", \"clip\": [");
    for (unsigned i = 0; i < o->clip_count; i++) {
        const ip_clip_plane *c = &o->clip_physical[i];
        fprintf(f, "%s[%.9g, %.9g, %.9g, %.9g]", i ? ", " : "", c->normal[0], c->normal[1],
                c->normal[2], c->offset);
    }
    fprintf(f, "]");
}

void tool_write_run_json(FILE *f, const tool_run_json *j)
{
    const ip_camera *c = j->camera;
    const tool_view_options *o = j->options;
    const ip_engine_counts *t = j->counts;
    fprintf(f, "\"file\": ");
    tool_json_string(f, j->file);
    fprintf(f,
            ", \"iso\": %.9g, \"mode\": \"%s\", \"width\": %u, \"height\": %u, "
            "\"renderer\": \"%s\"",
            j->iso,
            j->full == TOOL_FULL_LOD ? "full-lod"
            : j->full == TOOL_FULL   ? "full"
                                     : "progressive",
            c->width, c->height, j->renderer);
    fprintf(f,
            ", \"camera\": {\"eye\": [%.9g, %.9g, %.9g], \"target\": [%.9g, %.9g, %.9g], "
            "\"up\": [%.9g, %.9g, %.9g], \"fov\": %.9g}",
            c->eye[0], c->eye[1], c->eye[2], c->target[0], c->target[1], c->target[2], c->up[0],
            c->up[1], c->up[2], c->fov_y);
    fprintf(f, ", \"lod\": %s, \"pixel_error\": %.9g", o->lod ? "true" : "false", o->pixel_error);
    fprintf(f, ", \"warm\": %s, \"threads\": %u", j->warm ? "true" : "false",
            ip_thread_count(o->threads));
    fprintf(f, ", \"cutoff_degrees\": %.9g, \"foldback_degrees\": %.9g", o->cutoff, o->foldback);
    write_clip_json(f, o);
    fprintf(f,
            ", \"rays\": %llu, \"rays_total\": %llu, \"done\": %s, \"seeds\": %llu, "
            "\"cells\": %llu, \"triangles\": %llu",
            (unsigned long long)t->rays, (unsigned long long)c->width * c->height,
            j->done ? "true" : "false", (unsigned long long)t->seeds, (unsigned long long)t->cells,
            (unsigned long long)t->triangles);
    fprintf(f,
            ", \"time\": {\"intersection_s\": %.6f, \"propagation_s\": %.6f, "
            "\"extraction_s\": %.6f, \"rendering_s\": %.6f, \"extraction_wall_s\": %.6f, "
            "\"progress_render_s\": %.6f}",
            t->intersection_seconds, t->propagation_seconds, t->extraction_seconds,
            j->rendering_seconds, j->extraction_wall_seconds, j->progress_render_seconds);
}

int tool_warn_iso_range(const char *program, const ip_store *store, double iso, char *warning,
                        size_t warning_size)
{
    const ip_layout *l = ip_store_layout(store);
    if (warning && warning_size)
        warning[0] = '\0';
    float v = (float)iso; /* the isovalue as the engine takes it */
    if (v > l->value_min && v <= l->value_max)
        return 0;
    char text[512];
    snprintf(text, sizeof text,
             "--iso %g is outside the value range of %s, %g .. %g: there "
             "is no surface (an isovalue must be above the minimum and at most the maximum)",
             iso, ip_store_path(store), (double)l->value_min, (double)l->value_max);
    fprintf(stderr, "%s: warning: %s\n", program, text);
    if (warning && warning_size)
        snprintf(warning, warning_size, "%s", text);
    return 1;
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* What the programs print and write: JSON, byte counts, cache statistics, --stats files. */
#include <math.h>
#include <stdio.h>
#include <string.h>

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

const char *tool_rescale_text(char *buf, size_t size, const ip_rescale *r)
{
    snprintf(buf, size, "%s = stored x %g %c %g", r->unit[0] ? r->unit : "value", r->slope,
             r->intercept < 0 ? '-' : '+', fabs(r->intercept));
    return buf;
}

void tool_print_rescale(FILE *out, const ip_input_desc *desc)
{
    if (!desc->has_rescale)
        return;
    ip_rescale r = {1, desc->rescale_slope, desc->rescale_intercept, ""};
    memcpy(r.unit, desc->rescale_unit, sizeof r.unit);
    r.unit[sizeof r.unit - 1] = '\0';
    char text[96];
    fprintf(out, "  rescale     %s, kept: --iso in %s, --iso-stored in stored values\n",
            tool_rescale_text(text, sizeof text, &r), r.unit[0] ? r.unit : "rescaled values");
}

void tool_value_range(const ip_rescale *r, double lo, double hi, double out[2])
{
    double a = ip_rescale_to_value(r, lo), b = ip_rescale_to_value(r, hi);
    out[0] = a <= b ? a : b;
    out[1] = a <= b ? b : a;
}

const char *tool_unit_suffix(const ip_rescale *r, char *buf, size_t size)
{
    snprintf(buf, size, "%s%s", r && r->present && r->unit[0] ? " " : "",
             r && r->present ? r->unit : "");
    return buf;
}

void tool_write_rescale_json(FILE *out, const ip_rescale *r)
{
    if (!r || !r->present) {
        fprintf(out, "null");
        return;
    }
    fprintf(out, "{\"slope\": %.17g, \"intercept\": %.17g, \"unit\": ", r->slope, r->intercept);
    tool_json_string(out, r->unit);
    fprintf(out, "}");
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
    fprintf(f, ", \"iso\": %.9g", j->iso);
    if (j->rescale && j->rescale->present) {
        fprintf(f, ", \"iso_stored\": %.9g, \"rescale\": ", j->iso_stored);
        tool_write_rescale_json(f, j->rescale);
    }
    fprintf(f, ", \"mode\": \"%s\", \"width\": %u, \"height\": %u, \"renderer\": \"%s\"",
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

int tool_warn_iso_range(const char *program, const ip_store *store, const tool_view_options *o,
                        char *warning, size_t warning_size)
{
    const ip_layout *l = ip_store_layout(store);
    if (warning && warning_size)
        warning[0] = '\0';
    float v = (float)o->iso_stored; /* the isovalue as the engine takes it */
    if (v > l->value_min && v <= l->value_max)
        return 0;
    const ip_rescale *r = o->iso_given_stored ? NULL : o->rescale; /* the range as given */
    double range[2];
    char unit[IP_RESCALE_UNIT_MAX + 1], text[512];
    tool_value_range(r, l->value_min, l->value_max, range);
    int reversed = r && r->present && r->slope < 0; /* units run against the stored values */
    snprintf(text, sizeof text,
             "--iso%s %g is outside the value range of %s, %g .. %g%s: there "
             "is no surface (an isovalue must be %s)",
             o->iso_given_stored ? "-stored" : "", o->iso, ip_store_path(store), range[0], range[1],
             tool_unit_suffix(r, unit, sizeof unit),
             reversed ? "at least the minimum and below the maximum"
                      : "above the minimum and at most the maximum");
    fprintf(stderr, "%s: warning: %s\n", program, text);
    if (warning && warning_size)
        snprintf(warning, warning_size, "%s", text);
    return 1;
}

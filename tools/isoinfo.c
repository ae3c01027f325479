/* SPDX-License-Identifier: BSD-3-Clause */
/* isoinfo: describe a brick file (.ibv), as text or JSON, and verify it. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "isoprop/cache.h"
#include "isoprop/histogram.h"
#include "isoprop/layout.h"
#include "isoprop/store.h"
#include "isoprop/system.h"
#include "tool_common.h"

static const char usage[] =
    "usage: isoinfo FILE.ibv [--json] [--verify] [--histogram [--bins N] [--level K]]\n"
    "               [--cache-mb N] [--stats FILE.json] [--force]\n"
    "Prints the header, levels, brick counts, compression ratio, value range and summary size.\n"
    "  --json     print the same as one JSON object\n"
    "  --verify   check every checksum, decode every brick and compare it with its summaries;\n"
    "             exits 1 and names the first bad brick; reads through the brick cache and\n"
    "             prints its statistics on exit; a progress bar on stderr when it is a\n"
    "             terminal (not with --json; ISOINFO_PROGRESS=1 forces it, for tests)\n"
    "  --histogram      print the histogram of the sample values instead, to choose an\n"
    "                   isovalue: per bin its samples and the sub-blocks an isovalue at its\n"
    "                   lower edge would cross (docs/isoinfo.md)\n"
    "  --bins N         bins over the value range, 1 .. 65536 (default 64; whole values per\n"
    "                   bin for integer types, so there may be fewer)\n"
    "  --level K        the pyramid level counted (0: every sample; default: the finest level\n"
    "                   of at most 16 M samples)\n"
    "  --cache-mb N     brick cache budget in MiB (default 512, or a quarter of RAM if less)\n"
    "  --stats FILE     write the cache statistics as JSON (a \"cache\" object), complete or\n"
    "                   not at all\n"
    "  --force          replace an existing --stats file (a regular file; never the input)\n"
    "  --version        print the version and exit\n"
    "Ctrl-C stops --verify cleanly: no --stats is written, and isoinfo ends as killed by the\n"
    "signal.\n";

typedef struct file_facts {
    uint64_t constant, compressed, raw, payload_bytes, raw_bytes;
    uint64_t level_payload[IP_MAX_LEVELS];
} file_facts;

static void gather_facts(const ip_store *s, file_facts *f)
{
    const ip_layout *l = ip_store_layout(s);
    memset(f, 0, sizeof *f);
    for (uint64_t g = 0; g < l->brick_count; g++) {
        ip_brick_entry e;
        ip_store_brick_entry(s, g, &e);
        f->constant += e.encoding == IP_BRICK_CONSTANT;
        f->raw += e.encoding == IP_BRICK_RAW;
        f->compressed += e.encoding == IP_BRICK_LZ4;
        f->payload_bytes += e.stored_size;
    }
    for (uint32_t k = 0; k < l->level_count; k++)
        for (uint64_t i = 0; i < l->levels[k].brick_count; i++) {
            ip_brick_entry e;
            ip_store_brick_entry(s, l->levels[k].first_brick + i, &e);
            f->level_payload[k] += e.stored_size;
        }
    f->raw_bytes = (uint64_t)l->dims[0] * l->dims[1] * l->dims[2] * ip_type_size(l->type);
}

/* Origin, directions and space, as three lines of the text report. */
static void print_orientation_text(const ip_orientation *o)
{
    const char *space = ip_space_name(o->space);
    printf("  origin        %g, %g, %g (%s space)\n", o->origin[0], o->origin[1], o->origin[2],
           space[0] ? space : "unnamed");
    printf("  directions    x (%g, %g, %g), y (%g, %g, %g), z (%g, %g, %g)\n", o->directions[0][0],
           o->directions[0][1], o->directions[0][2], o->directions[1][0], o->directions[1][1],
           o->directions[1][2], o->directions[2][0], o->directions[2][1], o->directions[2][2]);
}

/* "origin": [x, y, z], "directions": [[x axis], [y axis], [z axis]], "space": "LPS" or null */
static void print_orientation_json(const ip_orientation *o)
{
    const char *space = ip_space_name(o->space);
    printf(", \"origin\": [%.17g, %.17g, %.17g]", o->origin[0], o->origin[1], o->origin[2]);
    printf(", \"directions\": [");
    for (int a = 0; a < 3; a++)
        printf("%s[%.17g, %.17g, %.17g]", a ? ", " : "", o->directions[a][0], o->directions[a][1],
               o->directions[a][2]);
    printf("]");
    if (space[0])
        printf(", \"space\": \"%s\"", space);
    else
        printf(", \"space\": null");
}

/* The value range line, and with a rescale its line: the range in the file's units, the stored
 * one beside it. */
static void print_values_text(const ip_layout *l)
{
    const ip_rescale *r = &l->rescale;
    if (!r->present) {
        printf("  value range   %g .. %g\n", (double)l->value_min, (double)l->value_max);
        return;
    }
    double range[2];
    char unit[IP_RESCALE_UNIT_MAX + 1], text[96];
    tool_value_range(r, l->value_min, l->value_max, range);
    printf("  value range   %g .. %g%s (stored %g .. %g)\n", range[0], range[1],
           tool_unit_suffix(r, unit, sizeof unit), (double)l->value_min, (double)l->value_max);
    printf("  rescale       %s\n", tool_rescale_text(text, sizeof text, r));
}

static void print_text(const ip_store *s, const file_facts *f)
{
    const ip_layout *l = ip_store_layout(s);
    char a[32], b[32], c[32];
    printf("%s\n", ip_store_path(s));
    printf("  format        version %u\n", l->format_version);
    printf("  dims          %u x %u x %u samples, %s\n", l->dims[0], l->dims[1], l->dims[2],
           ip_type_name(l->type));
    printf("  spacing       %g, %g, %g\n", l->spacing[0], l->spacing[1], l->spacing[2]);
    print_orientation_text(&l->orientation);
    print_values_text(l);
    printf("  bricks        %u^3 cells, sub-blocks %u^3 cells\n", l->brick_edge, l->subblock_edge);
    printf("  brick count   %llu: %llu constant, %llu compressed, %llu raw\n",
           (unsigned long long)l->brick_count, (unsigned long long)f->constant,
           (unsigned long long)f->compressed, (unsigned long long)f->raw);
    printf("  size          %s raw, %s file, ratio %.2fx\n",
           tool_format_bytes(a, sizeof a, (double)f->raw_bytes),
           tool_format_bytes(b, sizeof b, (double)l->file_size),
           (double)f->raw_bytes / (double)l->file_size);
    printf("  summary       %s (%llu bytes at offset %llu)\n",
           tool_format_bytes(c, sizeof c, (double)l->summary_size),
           (unsigned long long)l->summary_size, (unsigned long long)l->summary_offset);
    printf("  levels        %u\n", l->level_count);
    for (uint32_t k = 0; k < l->level_count; k++) {
        const ip_level_layout *lv = &l->levels[k];
        char p[32];
        double range[2];
        tool_value_range(&l->rescale, lv->value_min, lv->value_max, range);
        printf("    %2u: %u x %u x %u samples, %u x %u x %u bricks, %s payload, values %g .. %g\n",
               k, lv->dims[0], lv->dims[1], lv->dims[2], lv->bricks[0], lv->bricks[1],
               lv->bricks[2], tool_format_bytes(p, sizeof p, (double)f->level_payload[k]), range[0],
               range[1]);
    }
}

/* "value_min", "value_max" (in the file's units), with a rescale "value_min_stored",
 * "value_max_stored" and always "rescale" (null without one). */
static void print_values_json(const ip_layout *l)
{
    double range[2];
    tool_value_range(&l->rescale, l->value_min, l->value_max, range);
    printf(", \"value_min\": %.9g, \"value_max\": %.9g", range[0], range[1]);
    if (l->rescale.present)
        printf(", \"value_min_stored\": %.9g, \"value_max_stored\": %.9g", (double)l->value_min,
               (double)l->value_max);
    printf(", \"rescale\": ");
    tool_write_rescale_json(stdout, &l->rescale);
}

static void print_json(const ip_store *s, const file_facts *f)
{
    const ip_layout *l = ip_store_layout(s);
    printf("{\"file\": ");
    tool_json_string(stdout, ip_store_path(s));
    printf(", \"format_version\": %u", l->format_version);
    printf(", \"dims\": [%u, %u, %u]", l->dims[0], l->dims[1], l->dims[2]);
    printf(", \"type\": \"%s\"", ip_type_name(l->type));
    printf(", \"spacing\": [%.17g, %.17g, %.17g]", l->spacing[0], l->spacing[1], l->spacing[2]);
    print_orientation_json(&l->orientation);
    printf(", \"brick_size\": %u, \"subblock_size\": %u", l->brick_edge, l->subblock_edge);
    printf(", \"levels\": %u", l->level_count);
    printf(", \"bricks\": %llu, \"bricks_constant\": %llu, \"bricks_compressed\": %llu, "
           "\"bricks_raw\": %llu",
           (unsigned long long)l->brick_count, (unsigned long long)f->constant,
           (unsigned long long)f->compressed, (unsigned long long)f->raw);
    printf(", \"bytes_raw\": %llu, \"bytes_file\": %llu, \"bytes_payload\": %llu, "
           "\"bytes_summary\": %llu",
           (unsigned long long)f->raw_bytes, (unsigned long long)l->file_size,
           (unsigned long long)f->payload_bytes, (unsigned long long)l->summary_size);
    printf(", \"compression_ratio\": %.4f", (double)f->raw_bytes / (double)l->file_size);
    print_values_json(l);
    printf(", \"level_info\": [");
    for (uint32_t k = 0; k < l->level_count; k++) {
        const ip_level_layout *lv = &l->levels[k];
        double range[2];
        tool_value_range(&l->rescale, lv->value_min, lv->value_max, range);
        printf("%s{\"level\": %u, \"dims\": [%u, %u, %u], \"bricks\": [%u, %u, %u], "
               "\"bytes_payload\": %llu, \"value_min\": %.9g, \"value_max\": %.9g}",
               k ? ", " : "", k, lv->dims[0], lv->dims[1], lv->dims[2], lv->bricks[0],
               lv->bricks[1], lv->bricks[2], (unsigned long long)f->level_payload[k], range[0],
               range[1]);
    }
    printf("]}\n");
}

/* --verify's bar: bricks, and the decoded bytes' rate */
static void progress_draw(tool_progress *bar, uint64_t done, uint64_t total, uint64_t bytes)
{
    char rate[32];
    double elapsed = tool_progress_elapsed(bar);
    snprintf(rate, sizeof rate, "%7.1f MB/s", elapsed > 0 ? (double)bytes / elapsed / 1e6 : 0);
    tool_progress_draw(bar, done, total, "bricks", rate);
}

/* Reads every brick through the cache, checking checksums and summaries, then the octree. */
static int verify(const ip_store *s, ip_cache *cache, int quiet)
{
    const ip_layout *l = ip_store_layout(s);
    ip_error err;
    ip_error_clear(&err);
    tool_progress bar;
    uint64_t bytes = 0; /* decoded samples so far */
    tool_progress_start(&bar, !quiet, "ISOINFO_PROGRESS");
    int rc = 0;
    for (uint64_t g = 0; rc == 0 && g < l->brick_count; g++) {
        progress_draw(&bar, g, l->brick_count, bytes);
        if (tool_signal_caught()) {
            tool_progress_end(&bar);
            fprintf(stderr, "isoinfo: %s: verification cancelled after %llu of %llu bricks\n",
                    ip_store_path(s), (unsigned long long)g, (unsigned long long)l->brick_count);
            return 1;
        }
        ip_brick b;
        if (ip_cache_pin_brick(cache, g, &b, &err) != IP_OK)
            rc = -1;
        else if (ip_store_check_summary(s, g, b.samples, &err) != IP_OK)
            rc = -2;
        if (rc != -1)
            ip_cache_unpin_brick(cache, &b);
        bytes += ip_store_brick_samples(s, g) * ip_type_size(l->type);
    }
    if (rc == 0)
        progress_draw(&bar, l->brick_count, l->brick_count, bytes);
    tool_progress_end(&bar);
    if (rc != 0)
        return tool_fail("isoinfo", &err);
    if (ip_store_verify_octree(s, &err) != IP_OK)
        return tool_fail("isoinfo", &err);
    if (!quiet)
        fprintf(stderr, "isoinfo: %s: verified %llu bricks, their summaries and the octree\n",
                ip_store_path(s), (unsigned long long)l->brick_count);
    return 0;
}

/* The histogram as a table: each bin's range (in the file's units where it has a rescale),
 * count, a bar of # (logarithmic, so that the small bins of tissue show next to the huge one of
 * air: log(1 + count), the fullest bin 40 wide) and its active sub-blocks. */
static void print_histogram_text(const ip_store *s, const ip_histogram *h, double seconds)
{
    const ip_layout *l = ip_store_layout(s);
    const ip_rescale *r = &l->rescale;
    const uint32_t *d = l->levels[h->level].dims;
    char unit[IP_RESCALE_UNIT_MAX + 1], stored[96] = "";
    tool_unit_suffix(r, unit, sizeof unit);
    if (r->present)
        snprintf(stored, sizeof stored, " (stored %g .. %g)", h->lo, h->hi);
    uint64_t most = 1;
    for (uint32_t b = 0; b < h->bin_count; b++)
        most = h->bins[b].count > most ? h->bins[b].count : most;
    printf("%s: histogram of level %u of %u (%u x %u x %u = %llu samples, %s), %.3f s\n",
           ip_store_path(s), h->level, l->level_count - 1, d[0], d[1], d[2],
           (unsigned long long)h->samples, ip_type_name(l->type), seconds);
    printf("  %u bins over %g .. %g%s%s; a bin holds %s; active: sub-blocks (of %llu)\n"
           "  an isovalue at lo would cross\n",
           h->bin_count, ip_rescale_to_value(r, h->lo), ip_rescale_to_value(r, h->hi), unit, stored,
           r->slope < 0 ? "hi < v <= lo (a negative rescale slope)" : "lo <= v < hi",
           (unsigned long long)h->subblocks);
    printf("  %12s %12s %12s  %-40s %10s\n", "lo", "hi", "count", "", "active");
    for (uint32_t b = 0; b < h->bin_count; b++) {
        const ip_histogram_bin *bin = &h->bins[b];
        int fill = (int)(log1p((double)bin->count) / log1p((double)most) * 40 + 0.5);
        printf("  %12g %12g %12llu  %-40.*s %10llu\n", ip_rescale_to_value(r, bin->lo),
               ip_rescale_to_value(r, bin->hi), (unsigned long long)bin->count, fill,
               "########################################",
               (unsigned long long)bin->active_subblocks);
    }
    if (h->unbinned)
        printf("  %llu samples are NaN and in no bin\n", (unsigned long long)h->unbinned);
}

static void print_histogram_json(const ip_store *s, const ip_histogram *h, double seconds)
{
    const ip_layout *l = ip_store_layout(s);
    const uint32_t *d = l->levels[h->level].dims;
    printf("{\"file\": ");
    tool_json_string(stdout, ip_store_path(s));
    printf(", \"histogram\": {\"level\": %u, \"dims\": [%u, %u, %u], \"type\": \"%s\"", h->level,
           d[0], d[1], d[2], ip_type_name(l->type));
    printf(", \"samples\": %llu, \"unbinned\": %llu, \"subblocks\": %llu",
           (unsigned long long)h->samples, (unsigned long long)h->unbinned,
           (unsigned long long)h->subblocks);
    printf(", \"bricks_read\": %llu, \"bricks_constant\": %llu, \"seconds\": %.6f",
           (unsigned long long)h->bricks_read, (unsigned long long)h->bricks_constant, seconds);
    const ip_rescale *r = &l->rescale;
    if (r->present)
        print_values_json(l);
    else
        printf(", \"value_min\": %.9g, \"value_max\": %.9g", (double)l->value_min,
               (double)l->value_max);
    printf(", \"bins\": [");
    for (uint32_t b = 0; b < h->bin_count; b++) {
        const ip_histogram_bin *bin = &h->bins[b];
        printf("%s{\"lo\": %.17g, \"hi\": %.17g", b ? ", " : "", ip_rescale_to_value(r, bin->lo),
               ip_rescale_to_value(r, bin->hi));
        if (r->present)
            printf(", \"lo_stored\": %.17g, \"hi_stored\": %.17g", bin->lo, bin->hi);
        printf(", \"count\": %llu, \"active_subblocks\": %llu}", (unsigned long long)bin->count,
               (unsigned long long)bin->active_subblocks);
    }
    printf("]}}\n");
}

/* --histogram: the level asked for (or the default), counted and printed. */
static int histogram(const ip_store *s, int64_t level, uint32_t bins, int json)
{
    const ip_layout *l = ip_store_layout(s);
    if (level >= (int64_t)l->level_count)
        return tool_usage_error("isoinfo",
                                "--level %lld is past the pyramid of %s (levels 0 .. %u)",
                                (long long)level, ip_store_path(s), l->level_count - 1);
    uint32_t k =
        level >= 0 ? (uint32_t)level : ip_histogram_default_level(l, IP_HISTOGRAM_DEFAULT_SAMPLES);
    ip_histogram *h;
    ip_error err;
    ip_error_clear(&err);
    double start = ip_now_seconds();
    if (ip_histogram_compute(s, k, bins, &h, &err) != IP_OK)
        return tool_fail("isoinfo", &err);
    double seconds = ip_now_seconds() - start;
    if (json)
        print_histogram_json(s, h, seconds);
    else
        print_histogram_text(s, h, seconds);
    ip_histogram_free(h);
    return 0;
}

/* The command line of isoinfo (tool_parse_command_line()). */
typedef struct info_options {
    const char *stats_path;
    int json, check, force, histogram;
    uint32_t bins;
    int64_t level;   /* -1: the default */
    uint64_t budget; /* bytes */
} info_options;

static int parse_bins(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    uint64_t n;
    if (tool_parse_u64(v[0], &n) != 0 || n < 1 || n > IP_HISTOGRAM_MAX_BINS)
        return tool_usage_error(p, "--bins '%s' is not within 1 .. %u", v[0],
                                IP_HISTOGRAM_MAX_BINS);
    *(uint32_t *)((char *)base + opt->offset) = (uint32_t)n;
    return 0;
}

static int parse_level(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    uint64_t n;
    if (tool_parse_u64(v[0], &n) != 0 || n >= IP_MAX_LEVELS)
        return tool_usage_error(p, "--level '%s' is not a level (0 .. %u)", v[0],
                                IP_MAX_LEVELS - 1);
    *(int64_t *)((char *)base + opt->offset) = (int64_t)n;
    return 0;
}

#define INFO_FIELD(member) offsetof(info_options, member)
static const tool_option info_table[] = {
    {"--json", NULL, 0, INFO_FIELD(json), NULL, NULL, NULL},
    {"--verify", NULL, 0, INFO_FIELD(check), NULL, NULL, NULL},
    {"--histogram", NULL, 0, INFO_FIELD(histogram), NULL, NULL, NULL},
    {"--bins", NULL, 1, INFO_FIELD(bins), parse_bins, NULL, NULL},
    {"--level", NULL, 1, INFO_FIELD(level), parse_level, NULL, NULL},
    {"--force", "-f", 0, INFO_FIELD(force), NULL, NULL, NULL},
    {"--stats", NULL, 1, INFO_FIELD(stats_path), NULL, NULL, NULL},
    {"--cache-mb", NULL, 1, INFO_FIELD(budget), tool_option_cache_mb, NULL, NULL},
};

int main(int argc, char **argv)
{
    const char *path = NULL;
    info_options o = {NULL, 0, 0, 0, 0, 0, -1, ip_cache_default_budget()};
    tool_option_table table = {info_table, sizeof info_table / sizeof info_table[0], &o};
    tool_command_line c = {"isoinfo", usage, &table, 1, &path, "file"};
    if (tool_parse_command_line(&c, argc, argv) != 0)
        return 2;
    if (!path)
        return tool_usage_error("isoinfo", "no file");
    if ((o.bins || o.level >= 0) && !o.histogram)
        return tool_usage_error("isoinfo", "--bins and --level go with --histogram");
    const char *stats_path = o.stats_path;
    int json = o.json, check = o.check, force = o.force;
    uint64_t budget = o.budget;
    const char *inputs[] = {path}, *outputs[] = {stats_path};
    if (tool_check_paths("isoinfo", inputs, 1, outputs, 1, force) != 0)
        return 1;
    if (check)
        tool_signals_catch(); /* --verify reads every brick: Ctrl-C stops it cleanly */
    ip_store *store;
    ip_error err;
    ip_error_clear(&err);
    if (ip_store_open(path, &store, &err) != IP_OK)
        return tool_fail("isoinfo", &err);
    ip_cache *cache;
    if (ip_cache_create(store, budget, &cache, &err) != IP_OK) {
        ip_store_close(store);
        return tool_fail("isoinfo", &err);
    }
    file_facts facts;
    gather_facts(store, &facts);
    int rc = check ? verify(store, cache, json) : 0;
    int said = rc != 0 && tool_signal_caught(); /* verify() said it was cancelled */
    tool_outputs written = {0};
    ip_cache_stats stats;
    ip_cache_get_stats(cache, &stats);
    uint64_t summary_bytes = ip_store_summary_memory(store);
    int report = !tool_is_stdout(stats_path); /* --stats -: stdout holds the statistics alone */
    if (check && !json && report)
        tool_print_cache_table(stdout, &stats, summary_bytes);
    if (rc == 0 && tool_signal_caught())
        rc = 1; /* the last brick was checked, but the run was interrupted: no output */
    if (rc == 0 && stats_path &&
        (tool_write_stats_file("isoinfo", stats_path, force, &stats, summary_bytes, NULL, NULL) !=
             0 ||
         tool_outputs_add(&written, stats_path) != 0))
        rc = 1;
    if (rc == 0)
        tool_outputs_complete(&written);
    if (rc != 0 || !report)
        ; /* nothing more on stdout */
    else if (o.histogram)
        rc = histogram(store, o.level, o.bins ? o.bins : IP_HISTOGRAM_DEFAULT_BINS, json);
    else {
        if (json)
            print_json(store, &facts);
        else
            print_text(store, &facts);
    }
    ip_cache_destroy(cache);
    ip_store_close(store);
    return tool_outputs_end(&written, "isoinfo", said ? NULL : path, rc);
}

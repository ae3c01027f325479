/* isoinfo: describe a brick file (.ibv), as text or JSON, and verify it. */
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "isoprop/cache.h"
#include "isoprop/layout.h"
#include "isoprop/store.h"
#include "tool_common.h"

static const char usage[] =
    "usage: isoinfo FILE.ibv [--json] [--verify] [--cache-mb N] [--stats FILE.json] [--force]\n"
    "Prints the header, levels, brick counts, compression ratio, value range and summary size.\n"
    "  --json     print the same as one JSON object\n"
    "  --verify   check every checksum, decode every brick and compare it with its summaries;\n"
    "             exits 1 and names the first bad brick; reads through the brick cache and\n"
    "             prints its statistics on exit\n"
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

static void print_text(const ip_store *s, const file_facts *f)
{
    const ip_layout *l = ip_store_layout(s);
    char a[32], b[32], c[32];
    printf("%s\n", ip_store_path(s));
    printf("  format        version %u\n", IP_FORMAT_VERSION);
    printf("  dims          %u x %u x %u samples, %s\n", l->dims[0], l->dims[1], l->dims[2],
           ip_type_name(l->type));
    printf("  spacing       %g, %g, %g\n", l->spacing[0], l->spacing[1], l->spacing[2]);
    printf("  value range   %g .. %g\n", (double)l->value_min, (double)l->value_max);
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
        printf("    %2u: %u x %u x %u samples, %u x %u x %u bricks, %s payload, values %g .. %g\n",
               k, lv->dims[0], lv->dims[1], lv->dims[2], lv->bricks[0], lv->bricks[1],
               lv->bricks[2], tool_format_bytes(p, sizeof p, (double)f->level_payload[k]),
               (double)lv->value_min, (double)lv->value_max);
    }
}

static void print_json(const ip_store *s, const file_facts *f)
{
    const ip_layout *l = ip_store_layout(s);
    printf("{\"file\": ");
    tool_json_string(stdout, ip_store_path(s));
    printf(", \"format_version\": %u", IP_FORMAT_VERSION);
    printf(", \"dims\": [%u, %u, %u]", l->dims[0], l->dims[1], l->dims[2]);
    printf(", \"type\": \"%s\"", ip_type_name(l->type));
    printf(", \"spacing\": [%.17g, %.17g, %.17g]", l->spacing[0], l->spacing[1], l->spacing[2]);
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
    printf(", \"value_min\": %.9g, \"value_max\": %.9g", (double)l->value_min,
           (double)l->value_max);
    printf(", \"level_info\": [");
    for (uint32_t k = 0; k < l->level_count; k++) {
        const ip_level_layout *lv = &l->levels[k];
        printf("%s{\"level\": %u, \"dims\": [%u, %u, %u], \"bricks\": [%u, %u, %u], "
               "\"bytes_payload\": %llu, \"value_min\": %.9g, \"value_max\": %.9g}",
               k ? ", " : "", k, lv->dims[0], lv->dims[1], lv->dims[2], lv->bricks[0],
               lv->bricks[1], lv->bricks[2], (unsigned long long)f->level_payload[k],
               (double)lv->value_min, (double)lv->value_max);
    }
    printf("]}\n");
}

/* Reads every brick through the cache, checking checksums and summaries, then the octree. */
static int verify(const ip_store *s, ip_cache *cache, int quiet)
{
    const ip_layout *l = ip_store_layout(s);
    ip_error err;
    ip_error_clear(&err);
    for (uint64_t g = 0; g < l->brick_count; g++) {
        if (tool_signal_caught()) {
            fprintf(stderr, "isoinfo: %s: verification cancelled after %llu of %llu bricks\n",
                    ip_store_path(s), (unsigned long long)g, (unsigned long long)l->brick_count);
            return 1;
        }
        ip_brick b;
        if (ip_cache_pin_brick(cache, g, &b, &err) != IP_OK)
            return tool_fail("isoinfo", &err);
        ip_status st = ip_store_check_summary(s, g, b.samples, &err);
        ip_cache_unpin_brick(cache, &b);
        if (st != IP_OK)
            return tool_fail("isoinfo", &err);
    }
    if (ip_store_verify_octree(s, &err) != IP_OK)
        return tool_fail("isoinfo", &err);
    if (!quiet)
        fprintf(stderr, "isoinfo: %s: verified %llu bricks, their summaries and the octree\n",
                ip_store_path(s), (unsigned long long)l->brick_count);
    return 0;
}

/* The command line of isoinfo (tool_parse_command_line()). */
typedef struct info_options {
    const char *stats_path;
    int json, check, force;
    uint64_t budget; /* bytes */
} info_options;

#define INFO_FIELD(member) offsetof(info_options, member)
static const tool_option info_table[] = {
    {"--json", NULL, 0, INFO_FIELD(json), NULL, NULL, NULL},
    {"--verify", NULL, 0, INFO_FIELD(check), NULL, NULL, NULL},
    {"--force", NULL, 0, INFO_FIELD(force), NULL, NULL, NULL},
    {"--stats", NULL, 1, INFO_FIELD(stats_path), NULL, NULL, NULL},
    {"--cache-mb", NULL, 1, INFO_FIELD(budget), tool_option_cache_mb, NULL, NULL},
};

int main(int argc, char **argv)
{
    const char *path = NULL;
    info_options o = {NULL, 0, 0, 0, ip_cache_default_budget()};
    tool_option_table table = {info_table, sizeof info_table / sizeof info_table[0], &o};
    tool_command_line c = {"isoinfo", usage, &table, 1, &path, "file"};
    if (tool_parse_command_line(&c, argc, argv) != 0)
        return 2;
    if (!path)
        return tool_usage_error("isoinfo", "no file");
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
    ip_cache_stats stats;
    ip_cache_get_stats(cache, &stats);
    uint64_t summary_bytes = ip_store_summary_memory(store);
    if (check && !json)
        tool_print_cache_table(stdout, &stats, summary_bytes);
    if (rc == 0 && tool_signal_caught())
        rc = 1; /* the last brick was checked, but the run was interrupted: no output */
    if (stats_path && !tool_signal_caught() &&
        tool_write_stats_file("isoinfo", stats_path, force, &stats, summary_bytes, NULL, NULL) != 0)
        rc = 1;
    if (rc == 0) {
        if (json)
            print_json(store, &facts);
        else
            print_text(store, &facts);
    }
    ip_cache_destroy(cache);
    ip_store_close(store);
    tool_signals_reraise();
    return rc;
}

/* isobrick: brick a raw, NRRD or MetaImage volume into a brick file (.ibv), once. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "isoprop/bricker.h"
#include "isoprop/input.h"
#include "tool_common.h"

static const char usage[] =
    "usage: isobrick INPUT [-o OUT.ibv] [options]\n"
    "Bricks INPUT (NAME_XxYxZ_TYPE.raw, any raw file with --dims/--type, .nrrd, .nhdr, .mhd)\n"
    "into an LZ4-compressed brick file with min/max summaries and a level-of-detail pyramid.\n"
    "  -o OUT.ibv          output (default: bricks/NAME.ibv)\n"
    "  --dims XxYxZ        samples along x, y, z (raw input)\n"
    "  --type T            uint8, uint16, int16 or float32 (raw input)\n"
    "  --endian E          little (default) or big\n"
    "  --spacing X,Y,Z     world units between samples (default 1,1,1)\n"
    "  --brick-size B      cells per brick edge, a power of two (default 32)\n"
    "  --subblock-size S   cells per sub-block edge, a power of two <= B (default 8)\n"
    "  --hc [LEVEL]        LZ4 high compression (level 1-12, default 9) instead of fast\n"
    "  --threads N         compression threads (default: all cores)\n"
    "  --mem-mb N          cap on working memory in MiB (default: none)\n"
    "  --force             replace OUT if it exists (a regular file; never the input)\n"
    "  --quiet             no progress bar and no summary\n"
    "  --version           print the version and exit\n"
    "Ctrl-C cancels cleanly: no output is left, and isobrick ends as killed by the signal.\n";

typedef struct progress_state {
    int show;
    double start, last;
} progress_state;

static int report_progress(void *user, uint64_t done, uint64_t total)
{
    progress_state *p = user;
    if (p->show) {
        struct timespec ts;
        clock_gettime(CLOCK_MONOTONIC, &ts);
        double now = (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
        if (now - p->last >= 0.2 || done == total) {
            double elapsed = now - p->start, rate = elapsed > 0 ? (double)done / elapsed : 0;
            double eta = rate > 0 ? (double)(total - done) / rate : 0;
            int width = 30, fill = total ? (int)((double)done / (double)total * width) : width;
            fprintf(stderr, "\r[%-*.*s] %5.1f%% %7.1f MB/s ETA %4.0fs", width, fill,
                    "##############################", total ? 100.0 * (double)done / (double)total : 100.0,
                    rate / 1e6, eta);
            if (done == total)
                fputc('\n', stderr);
            p->last = now;
        }
    }
    return tool_signal_caught() != 0; /* SIGINT/SIGTERM: a clean cancel */
}

typedef struct options {
    const char *input, *output;
    ip_input_overrides overrides;
    ip_bricker_options brick;
    int quiet;
} options;

static int parse_args(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    ip_bricker_options_default(&o->brick);
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        uint64_t n;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(usage, stdout);
            exit(0);
        } else if (!strcmp(a, "--version")) {
            tool_print_version("isobrick");
            exit(0);
        } else if (!strcmp(a, "-o") && v) {
            o->output = v, i++;
        } else if (!strcmp(a, "--dims") && v) {
            if (tool_parse_dims("isobrick", "--dims", v, o->overrides.dims) != 0)
                return 2;
            o->overrides.has_dims = 1, i++;
        } else if (!strcmp(a, "--type") && v) {
            if (ip_type_parse(v, &o->overrides.type) != IP_OK)
                return tool_usage_error("isobrick", "unknown type '%s'", v);
            o->overrides.has_type = 1, i++;
        } else if (!strcmp(a, "--endian") && v) {
            if (strcmp(v, "big") && strcmp(v, "little"))
                return tool_usage_error("isobrick", "--endian must be big or little");
            o->overrides.big_endian = !strcmp(v, "big");
            o->overrides.has_endian = 1, i++;
        } else if (!strcmp(a, "--spacing") && v) {
            if (tool_parse_double3(v, o->overrides.spacing) != 0 ||
                !(o->overrides.spacing[0] > 0 && o->overrides.spacing[1] > 0 &&
                  o->overrides.spacing[2] > 0))
                return tool_usage_error("isobrick", "--spacing '%s' is not three positive "
                                        "numbers", v);
            o->overrides.has_spacing = 1, i++;
        } else if (!strcmp(a, "--brick-size") && v) {
            if (tool_parse_u64(v, &n) != 0 || n > 256)
                return tool_usage_error("isobrick", "bad --brick-size '%s'", v);
            o->brick.brick_edge = (uint32_t)n, i++;
        } else if (!strcmp(a, "--subblock-size") && v) {
            if (tool_parse_u64(v, &n) != 0 || n > 256)
                return tool_usage_error("isobrick", "bad --subblock-size '%s'", v);
            o->brick.subblock_edge = (uint32_t)n, i++;
        } else if (!strcmp(a, "--hc")) {
            o->brick.lz4_level = IP_LZ4_HC_DEFAULT;
            if (v && tool_parse_u64(v, &n) == 0) {
                if (n < 1 || n > 12)
                    return tool_usage_error("isobrick", "--hc level must be 1-12");
                o->brick.lz4_level = (int)n, i++;
            }
        } else if (!strcmp(a, "--threads") && v) {
            if (tool_parse_u64(v, &n) != 0 || n < 1 || n > 256)
                return tool_usage_error("isobrick", "--threads must be 1-256");
            o->brick.threads = (unsigned)n, i++;
        } else if (!strcmp(a, "--mem-mb") && v) {
            if (tool_parse_u64(v, &n) != 0 || n < 1 || n > (1ull << 40))
                return tool_usage_error("isobrick", "bad --mem-mb '%s'", v);
            o->brick.memory_limit = n << 20, i++;
        } else if (!strcmp(a, "--force")) {
            o->brick.force = 1;
        } else if (!strcmp(a, "--quiet") || !strcmp(a, "-q")) {
            o->quiet = 1;
        } else if (a[0] == '-' && a[1] != '\0') {
            return tool_usage_error("isobrick", "unknown or incomplete option '%s'", a);
        } else if (!o->input) {
            o->input = a;
        } else {
            return tool_usage_error("isobrick", "more than one input ('%s')", a);
        }
    }
    if (!o->input)
        return tool_usage_error("isobrick", "no input file");
    return 0;
}

/* bricks/NAME.ibv, NAME being the input's file name without its extension. */
static int default_output(const char *input, char *out, size_t size)
{
    const char *base = strrchr(input, '/');
    base = base ? base + 1 : input;
    const char *dot = strrchr(base, '.');
    int len = dot && dot != base ? (int)(dot - base) : (int)strlen(base);
    if (mkdir("bricks", 0777) != 0 && errno != EEXIST)
        return -1;
    return snprintf(out, size, "bricks/%.*s.ibv", len, base) < (int)size ? 0 : -1;
}

static void print_summary(const ip_bricker_report *r, const char *out)
{
    char in_b[32], file_b[32], rss_b[32];
    printf("wrote %s\n", out);
    printf("  input       %s (%llu bytes)\n", tool_format_bytes(in_b, sizeof in_b, (double)r->input_bytes),
           (unsigned long long)r->input_bytes);
    printf("  file        %s (%llu bytes)\n", tool_format_bytes(file_b, sizeof file_b, (double)r->file_bytes),
           (unsigned long long)r->file_bytes);
    printf("  ratio       %.2fx\n", r->file_bytes ? (double)r->input_bytes / (double)r->file_bytes : 0.0);
    printf("  bricks      %llu in %u levels: %llu constant, %llu compressed, %llu raw\n",
           (unsigned long long)r->bricks, r->levels, (unsigned long long)r->bricks_constant,
           (unsigned long long)r->bricks_compressed, (unsigned long long)r->bricks_raw);
    printf("  time        %.2f s, %.1f MB/s on %u threads\n", r->seconds,
           r->seconds > 0 ? (double)r->input_bytes / r->seconds / 1e6 : 0.0, r->threads);
    printf("  peak RSS    %s (working memory planned: %s)\n",
           tool_format_bytes(rss_b, sizeof rss_b, (double)r->peak_rss),
           tool_format_bytes(in_b, sizeof in_b, (double)r->memory_planned));
}

int main(int argc, char **argv)
{
    options o;
    int rc = parse_args(argc, argv, &o);
    if (rc)
        return rc;
    ip_error err;
    ip_error_clear(&err);
    ip_input_desc desc;
    if (ip_input_describe(o.input, &o.overrides, &desc, &err) != IP_OK)
        return tool_fail("isobrick", &err);
    char out[IP_PATH_MAX];
    if (o.output)
        snprintf(out, sizeof out, "%s", o.output);
    else if (default_output(o.input, out, sizeof out) != 0) {
        fprintf(stderr, "isobrick: cannot create the folder bricks/ for the output\n");
        return 1;
    }
    /* the input, its detached data file (NRRD, MetaImage) and the output, before any work */
    const char *inputs[] = {desc.path, desc.data_path}, *outputs[] = {out};
    if (tool_check_paths("isobrick", inputs, 2, outputs, 1, o.brick.force) != 0)
        return 1;
    tool_signals_catch();
    progress_state progress = {!o.quiet && isatty(STDERR_FILENO), 0, 0};
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    progress.start = (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
    o.brick.progress = report_progress;
    o.brick.progress_user = &progress;
    ip_bricker_report report;
    if (ip_bricker_run(&desc, out, &o.brick, &report, &err) != IP_OK) {
        if (progress.show)
            fputc('\n', stderr);
        rc = tool_fail("isobrick", &err);
        tool_signals_reraise(); /* cancelled by a signal: end as killed by it */
        return rc;
    }
    if (!o.quiet)
        print_summary(&report, out);
    return 0;
}

/* Helpers shared by the programs. */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "isoprop/engine.h"
#include "tool_common.h"

int tool_fail(const char *program, const ip_error *err)
{
    fprintf(stderr, "%s: %s\n", program,
            err->message[0] ? err->message : ip_status_message(err->code));
    return 1;
}

int tool_usage_error(const char *program, const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, "%s: ", program);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fprintf(stderr, " (see %s --help)\n", program);
    return 2;
}

int tool_parse_u64(const char *text, uint64_t *out)
{
    char *end;
    if (!text || *text < '0' || *text > '9')
        return -1;
    errno = 0;
    unsigned long long v = strtoull(text, &end, 10);
    if (errno || *end)
        return -1;
    *out = v;
    return 0;
}

int tool_parse_double(const char *text, double *out)
{
    char *end;
    if (!text || !*text)
        return -1;
    errno = 0;
    double v = strtod(text, &end);
    if (errno || *end || !isfinite(v))
        return -1;
    *out = v;
    return 0;
}

int tool_parse_double3(const char *text, double out[3])
{
    char buf[256];
    char *save = NULL;
    if (!text || strlen(text) >= sizeof buf)
        return -1;
    strcpy(buf, text);
    char *tok = strtok_r(buf, ",", &save);
    for (int i = 0; i < 3; i++) {
        if (!tok || tool_parse_double(tok, &out[i]) != 0)
            return -1;
        tok = strtok_r(NULL, ",", &save);
    }
    return tok ? -1 : 0;
}

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

#include <unistd.h>

/* Peak resident set of this process (VmHWM), in bytes; 0 when unknown. */
static uint64_t peak_rss(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    uint64_t kib = 0;
    while (f && fgets(line, sizeof line, f))
        if (strncmp(line, "VmHWM:", 6) == 0)
            kib = strtoull(line + 6, NULL, 10);
    if (f)
        fclose(f);
    return kib * 1024u;
}

int tool_parse_cache_mb(const char *text, uint64_t *bytes)
{
    uint64_t mb;
    if (tool_parse_u64(text, &mb) != 0 || mb < 1 || mb > (1ull << 30))
        return -1;
    *bytes = mb << 20;
    return 0;
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
    fprintf(out, "  bricks touched  %llu of %llu", (unsigned long long)s->bricks_touched,
            (unsigned long long)s->bricks_total);
    for (uint32_t k = 0; k < s->levels; k++)
        fprintf(out, "%s L%u %llu/%llu", k ? "," : " (", k,
                (unsigned long long)s->level[k].bricks_touched,
                (unsigned long long)s->level[k].bricks_total);
    fprintf(out, "%s\n", s->levels ? ")" : "");
    if (s->over_budget_pins || s->errors)
        fprintf(out, "  warnings        %llu loads over budget (all resident bricks pinned), "
                     "%llu bad bricks\n",
                (unsigned long long)s->over_budget_pins, (unsigned long long)s->errors);
    fprintf(out, "  summaries       %s\n", tool_format_bytes(a, sizeof a, (double)summary_bytes));
    fprintf(out, "  peak RSS        %s\n", tool_format_bytes(b, sizeof b, (double)peak_rss()));
}

void tool_write_cache_json(FILE *out, const ip_cache_stats *s, uint64_t summary_bytes)
{
    fprintf(out, "\"budget_bytes\": %llu, \"resident_bytes\": %llu, "
                 "\"resident_peak_bytes\": %llu, \"resident_bricks\": %llu, ",
            (unsigned long long)s->budget_bytes, (unsigned long long)s->resident_bytes,
            (unsigned long long)s->resident_peak_bytes, (unsigned long long)s->resident_bricks);
    fprintf(out, "\"hits\": %llu, \"misses\": %llu, \"evictions\": %llu, \"waits\": %llu, "
                 "\"hit_rate\": %.6f, ",
            (unsigned long long)s->hits, (unsigned long long)s->misses,
            (unsigned long long)s->evictions, (unsigned long long)s->waits, hit_rate(s));
    fprintf(out, "\"bytes_decompressed\": %llu, \"bytes_read\": %llu, \"decode_seconds\": %.6f, ",
            (unsigned long long)s->bytes_decompressed, (unsigned long long)s->bytes_read,
            s->decode_seconds);
    fprintf(out, "\"over_budget_pins\": %llu, \"pinned_bytes\": %llu, \"errors\": %llu, ",
            (unsigned long long)s->over_budget_pins, (unsigned long long)s->pinned_bytes,
            (unsigned long long)s->errors);
    fprintf(out, "\"bricks_touched\": %llu, \"bricks_total\": %llu, \"levels\": [",
            (unsigned long long)s->bricks_touched, (unsigned long long)s->bricks_total);
    for (uint32_t k = 0; k < s->levels; k++)
        fprintf(out, "%s{\"level\": %u, \"bricks_touched\": %llu, \"bricks_total\": %llu, "
                     "\"misses\": %llu}",
                k ? ", " : "", k, (unsigned long long)s->level[k].bricks_touched,
                (unsigned long long)s->level[k].bricks_total,
                (unsigned long long)s->level[k].misses);
    fprintf(out, "], \"summary_bytes\": %llu, \"peak_rss_bytes\": %llu",
            (unsigned long long)summary_bytes, (unsigned long long)peak_rss());
}

int tool_write_stats_file(const char *program, const char *path, const ip_cache_stats *s,
                          uint64_t summary_bytes, void (*extra)(FILE *out, void *user),
                          void *user)
{
    char temp[4200];
    snprintf(temp, sizeof temp, "%s.tmp.%ld", path, (long)getpid());
    FILE *out = fopen(temp, "w");
    if (!out) {
        fprintf(stderr, "%s: %s: cannot write: %s\n", program, path, strerror(errno));
        return -1;
    }
    fprintf(out, "{\"cache\": {");
    tool_write_cache_json(out, s, summary_bytes);
    fprintf(out, "}");
    if (extra) {
        fprintf(out, ", ");
        extra(out, user);
    }
    fprintf(out, "}\n");
    int failed = ferror(out);
    failed |= fclose(out) != 0;
    if (failed || rename(temp, path) != 0) {
        fprintf(stderr, "%s: %s: cannot write: %s\n", program, path, strerror(errno));
        unlink(temp);
        return -1;
    }
    return 0;
}

void tool_view_options_default(tool_view_options *o, uint32_t width, uint32_t height)
{
    memset(o, 0, sizeof *o);
    o->view = "-y";
    o->width = width;
    o->height = height;
    o->cutoff = IP_DEFAULT_CUTOFF_DEGREES;
    o->foldback = IP_DEFAULT_FOLDBACK_DEGREES;
    o->lod = 1;
    o->pixel_error = 1.0;
    o->cache_bytes = ip_cache_default_budget();
}

void tool_engine_options(const tool_view_options *o, ip_engine_options *eo)
{
    ip_engine_options_default(eo);
    eo->cutoff_degrees = o->cutoff;
    eo->foldback_degrees = o->foldback;
    eo->threads = o->threads;
    eo->lod = o->lod;
    eo->pixel_error = o->pixel_error;
}

static int parse_size(const char *text, uint32_t *w, uint32_t *h)
{
    unsigned long a, b;
    char x, extra;
    if (sscanf(text, "%lu%c%lu%c", &a, &x, &b, &extra) != 3 || (x != 'x' && x != 'X') || a < 1 ||
        b < 1 || a > 16384 || b > 16384)
        return -1;
    *w = (uint32_t)a;
    *h = (uint32_t)b;
    return 0;
}

/* The value of one shared option; returns 0, or 2 after a usage error. */
static int parse_view_value(const char *p, const char *a, const char *v, tool_view_options *o)
{
    if (!strcmp(a, "--iso")) {
        if (tool_parse_double(v, &o->iso) != 0)
            return tool_usage_error(p, "--iso '%s' is not a number", v);
        o->has_iso = 1;
    } else if (!strcmp(a, "--size")) {
        if (parse_size(v, &o->width, &o->height) != 0)
            return tool_usage_error(p, "--size '%s' is not WxH", v);
    } else if (!strcmp(a, "--view")) {
        o->view = v;
    } else if (!strcmp(a, "--camera")) {
        o->camera = v;
    } else if (!strcmp(a, "--rays")) {
        if (tool_parse_u64(v, &o->rays) != 0 || o->rays == 0)
            return tool_usage_error(p, "--rays '%s' is not a positive count", v);
    } else if (!strcmp(a, "--time")) {
        if (tool_parse_double(v, &o->time_limit) != 0 || o->time_limit <= 0)
            return tool_usage_error(p, "--time '%s' is not positive seconds", v);
    } else if (!strcmp(a, "--cutoff")) {
        if (tool_parse_double(v, &o->cutoff) != 0)
            return tool_usage_error(p, "--cutoff '%s' is not a number", v);
    } else if (!strcmp(a, "--foldback")) {
        if (tool_parse_double(v, &o->foldback) != 0)
            return tool_usage_error(p, "--foldback '%s' is not a number", v);
    } else if (!strcmp(a, "--threads")) {
        uint64_t n;
        if (tool_parse_u64(v, &n) != 0 || n < 1 || n > 64)
            return tool_usage_error(p, "--threads must be 1-64");
        o->threads = (unsigned)n;
    } else if (!strcmp(a, "--lod")) {
        if (strcmp(v, "on") && strcmp(v, "off"))
            return tool_usage_error(p, "--lod must be on or off");
        o->lod = !strcmp(v, "on");
    } else if (!strcmp(a, "--pixel-error")) {
        if (tool_parse_double(v, &o->pixel_error) != 0 || o->pixel_error <= 0)
            return tool_usage_error(p, "--pixel-error '%s' is not positive", v);
    } else { /* --cache-mb */
        if (tool_parse_cache_mb(v, &o->cache_bytes) != 0)
            return tool_usage_error(p, "bad --cache-mb '%s'", v);
    }
    return 0;
}

int tool_parse_view_option(const char *program, int argc, char **argv, int *i,
                           tool_view_options *o)
{
    static const char *const names[] = {"--iso", "--size", "--view", "--camera", "--rays",
                                        "--time", "--cutoff", "--foldback", "--threads",
                                        "--lod", "--pixel-error", "--cache-mb"};
    const char *a = argv[*i];
    if (*i + 1 >= argc)
        return 0;
    for (size_t k = 0; k < sizeof names / sizeof names[0]; k++)
        if (!strcmp(a, names[k])) {
            if (parse_view_value(program, a, argv[*i + 1], o) != 0)
                return 2;
            *i += 1;
            return 1;
        }
    return 0;
}

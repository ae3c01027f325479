/* Helpers shared by the programs. */
#include <ctype.h>
#include <errno.h>
#include <getopt.h>
#include <limits.h>
#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <signal.h>
#include <stddef.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "isoprop/engine.h"
#include "isoprop/output.h"
#include "isoprop/version.h"
#include "isoprop/volume.h"
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

int tool_parse_bounded(const char *program, const char *option, const char *text, uint64_t least,
                       uint64_t most, const char *what, uint64_t *out)
{
    uint64_t v;
    if (tool_parse_u64(text, &v) != 0 || v < least || v > most)
        return tool_usage_error(program, "%s '%s' is not %s (%llu to %llu)", option, text, what,
                                (unsigned long long)least, (unsigned long long)most);
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

/* Reads text as n whole numbers joined by 'x' or 'X' ("1600x1200", "512x512x234") into
 * value[] (one too large for them reads as ULLONG_MAX). Returns 0, or -1 when it is not that. */
static int scan_whole_numbers(const char *text, int n, unsigned long long *value)
{
    const char *p = text;
    for (int k = 0; k < n; k++) {
        char *end;
        if (!isdigit((unsigned char)*p))
            return -1;
        errno = 0;
        value[k] = strtoull(p, &end, 10);
        if (errno == ERANGE)
            value[k] = ULLONG_MAX;
        p = end;
        if (k + 1 < n) {
            if (*p != 'x' && *p != 'X')
                return -1;
            p++;
        }
    }
    return *p == '\0' ? 0 : -1;
}

int tool_parse_dims(const char *program, const char *option, const char *text, uint32_t dims[3])
{
    static const char axes[3] = {'x', 'y', 'z'};
    unsigned long long value[3];
    if (scan_whole_numbers(text, 3, value) != 0)
        return tool_usage_error(program,
                                "%s '%s' is not XxYxZ (three whole numbers, e.g. "
                                "512x512x234)",
                                option, text);
    for (int k = 0; k < 3; k++) {
        if (value[k] < 2)
            return tool_usage_error(program,
                                    "%s '%s': the dimension along %c is %llu; each "
                                    "must be at least 2",
                                    option, text, axes[k], value[k]);
        if (value[k] >= (1ull << 31))
            return tool_usage_error(program,
                                    "%s '%s': the dimension along %c is too large "
                                    "(at most %llu)",
                                    option, text, axes[k], (1ull << 31) - 1);
    }
    for (int k = 0; k < 3; k++)
        dims[k] = (uint32_t)value[k];
    return 0;
}

void tool_print_version(const char *program)
{
    printf("%s %s\n", program, ip_version());
}

/* An input must be there and be a regular file: a FIFO would block the open or the reads,
 * a device would never end. stat() does not open, so it never blocks. */
static int check_input(const char *program, const char *path)
{
    struct stat st;
    if (stat(path, &st) != 0) {
        fprintf(stderr, "%s: %s: cannot open: %s\n", program, path, strerror(errno));
        return 1;
    }
    if (S_ISDIR(st.st_mode)) {
        fprintf(stderr, "%s: %s: is a directory, not a file\n", program, path);
        return 1;
    }
    if (!S_ISREG(st.st_mode)) {
        fprintf(stderr, "%s: %s: not a regular file (%s)\n", program, path,
                S_ISFIFO(st.st_mode)   ? "a FIFO"
                : S_ISCHR(st.st_mode)  ? "a character device"
                : S_ISBLK(st.st_mode)  ? "a block device"
                : S_ISSOCK(st.st_mode) ? "a socket"
                                       : "not a plain file");
        return 1;
    }
    return 0;
}

/* The folder an output goes into must be there and writable, so that a run with several
 * outputs does not write the first ones and then fail on a later one. */
static int check_output_folder(const char *program, const char *path)
{
    char folder[4096];
    const char *slash = strrchr(path, '/');
    if (!slash)
        snprintf(folder, sizeof folder, ".");
    else if (slash == path)
        snprintf(folder, sizeof folder, "/");
    else
        snprintf(folder, sizeof folder, "%.*s", (int)(slash - path), path);
    struct stat st;
    if (stat(folder, &st) != 0 || !S_ISDIR(st.st_mode) || access(folder, W_OK | X_OK) != 0) {
        int e = errno;
        fprintf(stderr, "%s: %s: cannot write in folder %s: %s\n", program, path, folder,
                stat(folder, &st) == 0 && !S_ISDIR(st.st_mode) ? "not a directory" : strerror(e));
        return 1;
    }
    return 0;
}

int tool_is_stdout(const char *path)
{
    return path && strcmp(path, "-") == 0;
}

/* At most one output may be standard output ("-"): two would run together there. */
static int check_stdout_outputs(const char *program, const char *const *outputs, size_t count)
{
    size_t named = 0;
    for (size_t o = 0; o < count; o++)
        named += tool_is_stdout(outputs[o]);
    if (named > 1) {
        fprintf(stderr, "%s: -: standard output named for %zu outputs; at most one may go there\n",
                program, named);
        return 1;
    }
    return 0;
}

int tool_check_paths(const char *program, const char *const *inputs, size_t input_count,
                     const char *const *outputs, size_t output_count, int force)
{
    ip_error err;
    for (size_t i = 0; i < input_count; i++)
        if (inputs[i] && check_input(program, inputs[i]) != 0)
            return 1;
    if (check_stdout_outputs(program, outputs, output_count) != 0)
        return 1;
    for (size_t o = 0; o < output_count; o++) {
        if (!outputs[o] || tool_is_stdout(outputs[o]))
            continue;
        for (size_t i = 0; i < input_count; i++)
            if (inputs[i] && ip_output_not_input(outputs[o], inputs[i], &err) != IP_OK)
                return tool_fail(program, &err);
        for (size_t k = 0; k < o; k++)
            if (outputs[k] && !tool_is_stdout(outputs[k]) &&
                ip_path_same_file(outputs[o], outputs[k])) {
                if (strcmp(outputs[o], outputs[k]) == 0)
                    fprintf(stderr,
                            "%s: %s: named for two outputs; each output needs a file "
                            "of its own\n",
                            program, outputs[o]);
                else
                    fprintf(stderr,
                            "%s: %s: is the same file as the output %s; each output "
                            "needs a file of its own\n",
                            program, outputs[o], outputs[k]);
                return 1;
            }
        if (ip_output_check(outputs[o], force, &err) != IP_OK)
            return tool_fail(program, &err);
        if (check_output_folder(program, outputs[o]) != 0)
            return 1;
    }
    return 0;
}

int tool_write_text_file(const char *program, const char *path, int force,
                         void (*fill)(FILE *out, void *user), void *user)
{
    char *text = NULL;
    size_t size = 0;
    FILE *out = open_memstream(&text, &size);
    if (!out) {
        fprintf(stderr, "%s: %s: out of memory\n", program, path);
        return -1;
    }
    fill(out, user);
    int failed = ferror(out);
    failed |= fclose(out) != 0;
    if (failed) {
        fprintf(stderr, "%s: %s: out of memory\n", program, path);
        free(text);
        return -1;
    }
    if (tool_is_stdout(path)) {
        failed = fwrite(text, 1, size, stdout) != size || fflush(stdout) != 0;
        free(text);
        if (failed)
            fprintf(stderr, "%s: standard output: %s\n", program, strerror(errno));
        return failed ? -1 : 0;
    }
    ip_error err;
    ip_status st = ip_output_write(path, text, size, force, &err);
    free(text);
    if (st != IP_OK) {
        tool_fail(program, &err);
        return -1;
    }
    return 0;
}

/* ---- signals ---- */

static volatile sig_atomic_t signal_caught;
static _Atomic(ip_engine *) signal_engine;
static atomic_int signal_handlers_running;

static void on_signal(int sig)
{
    int saved = errno;
    atomic_fetch_add(&signal_handlers_running, 1);
    if (!signal_caught)
        signal_caught = sig;
    ip_engine *engine = atomic_load(&signal_engine);
    if (engine)
        ip_engine_cancel(engine); /* an atomic store: async-signal-safe */
    atomic_fetch_sub(&signal_handlers_running, 1);
    errno = saved;
}

void tool_signals_catch(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
}

int tool_signal_caught(void)
{
    return signal_caught;
}

void tool_signals_cancel_engine(ip_engine *engine)
{
    atomic_store(&signal_engine, engine);
    /* a handler running on another thread may have read the old engine: wait it out */
    while (atomic_load(&signal_handlers_running) != 0)
        sched_yield();
}

void tool_signals_reraise(void)
{
    int sig = signal_caught;
    if (!sig)
        return;
    tool_signals_cancel_engine(NULL);
    fflush(stdout);
    fflush(stderr);
    signal(sig, SIG_DFL);
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, sig);
    pthread_sigmask(SIG_UNBLOCK, &set, NULL);
    raise(sig);
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

void tool_progress_start(tool_progress *p, int wanted, const char *force_variable)
{
    const char *force = getenv(force_variable);
    p->show = wanted && ((force && strcmp(force, "1") == 0) || isatty(STDERR_FILENO));
    p->drawn = 0;
    p->start = p->last = ip_now_seconds();
}

double tool_progress_elapsed(const tool_progress *p)
{
    return ip_now_seconds() - p->start;
}

void tool_progress_draw(tool_progress *p, uint64_t done, uint64_t total, const char *unit,
                        const char *detail)
{
    double now = ip_now_seconds();
    if (!p->show || (done < total && now - p->last < 0.2))
        return;
    double elapsed = now - p->start, fraction = total ? (double)done / (double)total : 1;
    if (fraction > 1)
        fraction = 1;
    double eta = fraction > 0 ? elapsed * (1 - fraction) / fraction : 0;
    int width = 30, fill = (int)(fraction * width);
    fprintf(stderr, "\r[%-*.*s] %5.1f%% %llu/%llu %s %s ETA %4.0fs", width, fill,
            "##############################", 100 * fraction, (unsigned long long)done,
            (unsigned long long)total, unit, detail, eta);
    p->drawn = 1;
    p->last = now;
}

void tool_progress_end(tool_progress *p)
{
    if (p->drawn)
        fputc('\n', stderr);
    p->drawn = 0;
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
    o->occlusion = 1;
    o->prefetch = IP_PREFETCH_ON;
    o->cull = -1;
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
    eo->occlusion = o->occlusion;
    eo->prefetch = o->prefetch;
    eo->cull = o->cull > 0;
    eo->clip_count = o->clip_count;
    memcpy(eo->clip, o->clip, sizeof eo->clip);
}

/* An axis shortcut: "x=40", "-z=2.5". Returns 0, or -1 when `text` is not one. */
static int parse_clip_axis(const char *text, ip_clip_plane *plane)
{
    double sign = 1.0;
    if (text[0] == '-') {
        sign = -1.0;
        text++;
    }
    const char *axes = "xyz", *at = text[0] ? strchr(axes, tolower((unsigned char)text[0])) : NULL;
    double value;
    if (!at || text[1] != '=' || tool_parse_double(text + 2, &value) != 0)
        return -1;
    memset(plane, 0, sizeof *plane);
    plane->normal[at - axes] = sign; /* sign * (x - value) >= 0 */
    plane->offset = -sign * value;
    return 0;
}

int tool_parse_clip(const char *text, ip_clip_plane *plane)
{
    if (strchr(text, '='))
        return parse_clip_axis(text, plane);
    double v[4];
    char rest[256];
    if (strlen(text) >= sizeof rest)
        return -1;
    strcpy(rest, text);
    char *save = NULL, *item = strtok_r(rest, ",", &save);
    int n = 0;
    for (; item && n < 4; item = strtok_r(NULL, ",", &save))
        if (tool_parse_double(item, &v[n++]) != 0)
            return -1;
    if (n != 4 || item || strchr(text, ',') == text || strstr(text, ",,") ||
        text[strlen(text) - 1] == ',')
        return -1;
    if (v[0] == 0 && v[1] == 0 && v[2] == 0)
        return -1;
    *plane = (ip_clip_plane){{v[0], v[1], v[2]}, v[3]};
    return 0;
}

#define MAX_IMAGE_SIDE 16384 /* pixels; OpenGL's common maximum renderbuffer size */

int tool_parse_pair(const char *program, const char *option, const char *text, uint32_t max,
                    const char *form, const char *const sides[2], const char *unit, uint32_t *a,
                    uint32_t *b)
{
    unsigned long long side[2];
    if (scan_whole_numbers(text, 2, side) != 0)
        return tool_usage_error(program, "%s '%s' is not %s", option, text, form);
    for (int k = 0; k < 2; k++)
        if (side[k] < 1 || side[k] > max)
            return tool_usage_error(program, "%s '%s': the %s, %llu %s, is not within 1 .. %u",
                                    option, text, sides[k], side[k], unit, max);
    *a = (uint32_t)side[0];
    *b = (uint32_t)side[1];
    return 0;
}

/* ---- option parsers ---- */

static int parse_double_option(const char *p, const tool_option *opt, const char *value, void *base,
                               int positive)
{
    double *out = (double *)(void *)((char *)base + opt->offset);
    if (tool_parse_double(value, out) != 0 || (positive && *out <= 0))
        return tool_usage_error(p, "%s '%s' %s", opt->name, value, opt->problem);
    return 0;
}

int tool_option_number(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    return parse_double_option(p, opt, v[0], base, 0);
}

int tool_option_positive(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    return parse_double_option(p, opt, v[0], base, 1);
}

int tool_option_background(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    ip_shading *s = (ip_shading *)((char *)base + opt->offset);
    if (tool_parse_background(v[0], s->background_top, s->background_bottom) != 0)
        return tool_usage_error(p,
                                "%s '%s' is not a colour (R,G,B or #rrggbb) or TOP:BOTTOM, two "
                                "of them",
                                opt->name, v[0]);
    return 0;
}

int tool_parse_threads(const char *program, const char *text, unsigned max, unsigned *threads)
{
    uint64_t n;
    if (tool_parse_u64(text, &n) != 0 || n < 1 || n > max)
        return tool_usage_error(program, "--threads must be 1-%u", max);
    *threads = (unsigned)n;
    return 0;
}

/* ---- the shared options (base: the tool_view_options) ---- */

static int parse_iso(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    tool_view_options *o = base;
    if (tool_option_number(p, opt, v, base) != 0)
        return 2;
    if (o->iso_count < TOOL_MAX_ISOS)
        o->isos[o->iso_count] = o->iso;
    o->iso_count++;
    return 0;
}

static int parse_size_option(const char *p, const tool_option *opt, const char *const *v,
                             void *base)
{
    tool_view_options *o = base;
    (void)opt;
    static const char *const sides[2] = {"width", "height"};
    return tool_parse_pair(p, "--size", v[0], MAX_IMAGE_SIDE, "WxH (e.g. 1600x1200)", sides,
                           "pixels", &o->width, &o->height);
}

static int parse_rays(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    tool_view_options *o = base;
    (void)opt;
    if (tool_parse_u64(v[0], &o->rays) != 0 || o->rays == 0)
        return tool_usage_error(p, "--rays '%s' is not a positive count", v[0]);
    return 0;
}

static int parse_view_threads(const char *p, const tool_option *opt, const char *const *v,
                              void *base)
{
    (void)opt;
    return tool_parse_threads(p, v[0], 64, &((tool_view_options *)base)->threads);
}

/* An on|off switch: *out = 1 or 0. */
static int parse_on_off(const char *p, const char *value, int *out, const char *option)
{
    if (strcmp(value, "on") && strcmp(value, "off"))
        return tool_usage_error(p, "%s must be on or off", option);
    *out = !strcmp(value, "on");
    return 0;
}

int tool_option_on_off(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    return parse_on_off(p, v[0], (int *)(void *)((char *)base + opt->offset), opt->name);
}

int tool_option_renderer(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    static const char *const names[3] = {"auto", "opengl", "software"};
    for (int i = 0; i < 3; i++)
        if (!strcmp(v[0], names[i])) {
            *(int *)(void *)((char *)base + opt->offset) = i; /* TOOL_RENDERER_* */
            return 0;
        }
    return tool_usage_error(p, "--renderer '%s': must be auto, opengl or software", v[0]);
}

static int parse_lod(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    (void)opt;
    return parse_on_off(p, v[0], &((tool_view_options *)base)->lod, "--lod");
}

static int parse_occlusion(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    (void)opt;
    return parse_on_off(p, v[0], &((tool_view_options *)base)->occlusion, "--occlusion");
}

/* --prefetch's names, indexed by the modes IP_PREFETCH_OFF, _ON and _ALWAYS (0, 1, 2). */
static const char *const prefetch_names[3] = {"off", "on", "always"};

const char *tool_prefetch_name(int mode)
{
    return mode >= 0 && mode < 3 ? prefetch_names[mode] : "unknown";
}

static int parse_prefetch(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    (void)opt;
    for (int i = 0; i < 3; i++)
        if (!strcmp(v[0], prefetch_names[i])) {
            ((tool_view_options *)base)->prefetch = i;
            return 0;
        }
    return tool_usage_error(p, "--prefetch must be on, off or always");
}

static int parse_cull(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    (void)opt;
    return parse_on_off(p, v[0], &((tool_view_options *)base)->cull, "--cull");
}

int tool_option_cache_mb(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    if (tool_parse_cache_mb(v[0], (uint64_t *)((char *)base + opt->offset)) != 0)
        return tool_usage_error(p, "bad --cache-mb '%s'", v[0]);
    return 0;
}

static int parse_clip_option(const char *p, const tool_option *opt, const char *const *v,
                             void *base)
{
    (void)opt;
    tool_view_options *o = base;
    if (o->clip_count == IP_MAX_CLIP_PLANES)
        return tool_usage_error(p, "at most %d --clip planes", IP_MAX_CLIP_PLANES);
    if (tool_parse_clip(v[0], &o->clip[o->clip_count]) != 0)
        return tool_usage_error(p, "bad --clip '%s' (x=V, -x=V, y=V, ... or A,B,C,D)", v[0]);
    o->clip_count++;
    return 0;
}

/* --view and --camera are checked as they are parsed, so that a bad one is a usage error
 * (exit 2) before any file is opened; the library's own check says what is wrong. */
static int parse_view(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    static const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    ip_camera probe;
    ip_error err;
    (void)opt;
    if (ip_camera_fit_axis(lo, hi, v[0], 30.0, 1, 1, &probe, &err) != IP_OK)
        return tool_usage_error(p, "--view '%s' is not an axis (+x -x +y -y +z -z)", v[0]);
    ((tool_view_options *)base)->view = v[0];
    return 0;
}

static int parse_camera(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    ip_camera probe;
    ip_error err;
    (void)opt;
    memset(&probe, 0, sizeof probe);
    probe.width = probe.height = 1;
    if (ip_camera_parse(v[0], &probe, &err) != IP_OK || ip_camera_check(&probe, &err) != IP_OK)
        return tool_usage_error(p, "--camera '%s': %s", v[0], err.message);
    ((tool_view_options *)base)->camera = v[0];
    return 0;
}

#define VIEW_FIELD(member) offsetof(tool_view_options, member)

static const tool_option view_options[] = {
    {"--iso", NULL, 1, VIEW_FIELD(iso), parse_iso, "is not a number", NULL},
    {"--size", NULL, 1, 0, parse_size_option, NULL, NULL},
    {"--view", NULL, 1, VIEW_FIELD(view), parse_view, NULL, NULL},
    {"--camera", NULL, 1, VIEW_FIELD(camera), parse_camera, NULL, NULL},
    {"--rays", NULL, 1, 0, parse_rays, NULL, NULL},
    {"--time", NULL, 1, VIEW_FIELD(time_limit), tool_option_positive, "is not positive seconds",
     NULL},
    {"--cutoff", NULL, 1, VIEW_FIELD(cutoff), tool_option_number, "is not a number", NULL},
    {"--foldback", NULL, 1, VIEW_FIELD(foldback), tool_option_number, "is not a number", NULL},
    {"--threads", NULL, 1, 0, parse_view_threads, NULL, NULL},
    {"--lod", NULL, 1, 0, parse_lod, NULL, NULL},
    {"--pixel-error", NULL, 1, VIEW_FIELD(pixel_error), tool_option_positive, "is not positive",
     NULL},
    {"--occlusion", NULL, 1, 0, parse_occlusion, NULL, NULL},
    {"--prefetch", NULL, 1, 0, parse_prefetch, NULL, NULL},
    {"--cull", NULL, 1, 0, parse_cull, NULL, NULL},
    {"--clip", NULL, 1, 0, parse_clip_option, NULL, NULL},
    {"--cache-mb", NULL, 1, VIEW_FIELD(cache_bytes), tool_option_cache_mb, NULL, NULL},
    {"--stats", NULL, 1, VIEW_FIELD(stats), NULL, NULL, NULL},
    {"--force", "-f", 0, VIEW_FIELD(force), NULL, NULL, NULL},
    {"--quiet", "-q", 0, VIEW_FIELD(quiet), NULL, NULL, NULL},
};

tool_option_table tool_view_option_table(tool_view_options *o)
{
    return (tool_option_table){view_options, sizeof view_options / sizeof view_options[0], o};
}

int tool_is_u64(const char *text)
{
    uint64_t ignored;
    return tool_parse_u64(text, &ignored) == 0;
}

/* ---- figure options ---- */

void tool_orbit_options_default(tool_orbit_options *o)
{
    o->azimuth = 0.0;
    o->elevation = 0.0;
    o->zoom = 1.0;
}

void tool_apply_orbit(const tool_orbit_options *o, ip_camera *camera)
{
    /* ip_camera_orbit() turns the scene: a positive turn to the right moves the eye left */
    if (o->azimuth != 0.0 || o->elevation != 0.0)
        ip_camera_orbit(camera, -o->azimuth, o->elevation);
    if (o->zoom != 1.0) {
        double half = camera->fov_y * M_PI / 360.0;
        camera->fov_y = atan(tan(half) / o->zoom) * 360.0 / M_PI;
    }
}

/* One hexadecimal digit's value, or -1. */
static int hex_digit(char c)
{
    if (c >= '0' && c <= '9')
        return c - '0';
    c = (char)tolower((unsigned char)c);
    return c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1;
}

int tool_camera_of(const char *camera_text, const char *axis, uint32_t width, uint32_t height,
                   const double lo[3], const double hi[3], ip_camera *camera, ip_error *err)
{
    ip_camera c = {.width = width, .height = height};
    if (camera_text) {
        if (ip_camera_parse(camera_text, &c, err) != IP_OK || ip_camera_check(&c, err) != IP_OK)
            return -1;
    } else if (ip_camera_fit_axis(lo, hi, axis, 30.0, width, height, &c, err) != IP_OK) {
        return -1;
    }
    *camera = c;
    return 0;
}

int tool_parse_colour(const char *text, float rgb[3])
{
    if (text[0] == '#') {
        if (strlen(text) != 7)
            return -1;
        for (int i = 0; i < 3; i++) {
            int hi = hex_digit(text[1 + 2 * i]), lo = hex_digit(text[2 + 2 * i]);
            if (hi < 0 || lo < 0)
                return -1;
            rgb[i] = (float)(hi * 16 + lo) / 255.0f;
        }
        return 0;
    }
    double v[3];
    if (tool_parse_double3(text, v) != 0)
        return -1;
    for (int i = 0; i < 3; i++) {
        if (!(v[i] >= 0.0 && v[i] <= 1.0))
            return -1;
        rgb[i] = (float)v[i];
    }
    return 0;
}

int tool_parse_background(const char *text, float top[3], float bottom[3])
{
    const char *colon = strchr(text, ':');
    if (!colon)
        return tool_parse_colour(text, top) != 0 || tool_parse_colour(text, bottom) != 0 ? -1 : 0;
    char first[64];
    size_t len = (size_t)(colon - text);
    if (len >= sizeof first)
        return -1;
    memcpy(first, text, len);
    first[len] = 0;
    return tool_parse_colour(first, top) != 0 || tool_parse_colour(colon + 1, bottom) != 0 ? -1 : 0;
}

/* ---- the command-line engine: getopt_long over the tables ----
 *
 * Every row becomes a struct option (its long name without the dashes) and, when its name or
 * alias is a single letter ("-o", "-q"), a letter of the short-option string, so that
 * "--iso=V", "--iso V", "-oFILE", "-o FILE", clustered letters ("-qf"), "--" and unambiguous
 * prefixes of long names ("--mes" for --mesh) all work as getopt_long makes them. A row's
 * getopt_long value is ROW_VALUE + its index in the flattened list of rows. */

#define ROW_VALUE 0x1000
#define HELP_VALUE 0x0fff
#define VERSION_VALUE 0x0ffe

typedef struct option_row {
    const tool_option *option;
    void *base;
} option_row;

typedef struct getopt_tables {
    option_row *rows;
    struct option *longs;
    char shorts[128];
    size_t count;
} getopt_tables;

static int is_short_name(const char *name)
{
    return name && name[0] == '-' && name[1] && name[1] != '-' && !name[2];
}

static void add_short(getopt_tables *g, const char *name, int has_value)
{
    size_t n = strlen(g->shorts);
    if (n + 3 >= sizeof g->shorts)
        return;
    g->shorts[n++] = name[1];
    if (has_value)
        g->shorts[n++] = ':';
    g->shorts[n] = '\0';
}

/* Builds the getopt_long tables; returns 0, or -1 when out of memory. */
static int build_getopt_tables(const tool_command_line *c, getopt_tables *g)
{
    size_t count = 0;
    for (size_t t = 0; t < c->table_count; t++)
        count += c->tables[t].count;
    g->rows = calloc(count ? count : 1, sizeof *g->rows);
    g->longs = calloc(count + 3, sizeof *g->longs);
    if (!g->rows || !g->longs)
        return -1;
    strcpy(g->shorts, ":h"); /* ':': a missing value is reported as such, not as unknown */
    size_t l = 0;
    for (size_t t = 0; t < c->table_count; t++)
        for (size_t k = 0; k < c->tables[t].count; k++) {
            const tool_option *opt = &c->tables[t].options[k];
            int has_value = opt->values >= 1; /* an optional value is taken by hand */
            g->rows[g->count] = (option_row){opt, c->tables[t].base};
            const char *names[2] = {opt->name, opt->alias};
            for (int n = 0; n < 2; n++) {
                if (is_short_name(names[n]))
                    add_short(g, names[n], has_value);
                else if (names[n] && names[n][0] == '-' && names[n][1] == '-')
                    g->longs[l++] =
                        (struct option){names[n] + 2, has_value ? required_argument : no_argument,
                                        NULL, ROW_VALUE + (int)g->count};
            }
            g->count++;
        }
    g->longs[l++] = (struct option){"help", no_argument, NULL, HELP_VALUE};
    g->longs[l++] = (struct option){"version", no_argument, NULL, VERSION_VALUE};
    return 0;
}

/* The row whose short name or alias is `letter`, or -1. */
static int short_row(const getopt_tables *g, int letter)
{
    for (size_t r = 0; r < g->count; r++) {
        const tool_option *opt = g->rows[r].option;
        if ((is_short_name(opt->name) && opt->name[1] == letter) ||
            (is_short_name(opt->alias) && opt->alias[1] == letter))
            return (int)r;
    }
    return -1;
}

/* Takes a row's values (getopt_long's optarg, then what follows in argv for a second or an
 * optional value) and applies them. Returns 0, or 2 after a usage error. */
static int take_row(const tool_command_line *c, const option_row *row, int argc, char **argv)
{
    const tool_option *opt = row->option;
    const char *values[2] = {NULL, NULL};
    if (opt->values >= 1)
        values[0] = optarg;
    if (opt->values == 2) {
        if (optind >= argc)
            return tool_usage_error(c->program, "%s needs %d values", opt->name, opt->values);
        values[1] = argv[optind++];
    }
    if (opt->values == TOOL_OPTIONAL_VALUE && optind < argc && opt->accepts(argv[optind]))
        values[0] = argv[optind++];
    char *field = (char *)row->base + opt->offset;
    if (opt->parse)
        return opt->parse(c->program, opt, values, row->base);
    if (opt->values == 0)
        *(int *)(void *)field = 1;
    else
        *(const char **)(void *)field = values[0];
    return 0;
}

/* The usage error for getopt_long's '?' or ':' on argv[optind - 1]. */
static int getopt_error(const tool_command_line *c, int result, char **argv)
{
    const char *arg = argv[optind - 1];
    if (result == ':')
        return tool_usage_error(c->program, "option '%s' needs a value", arg);
    if (optopt && arg[0] == '-' && arg[1] != '-')
        return tool_usage_error(c->program, "unknown option '-%c' (in '%s')", optopt, arg);
    return tool_usage_error(c->program, "unknown or ambiguous option '%s'", arg);
}

static int parse_getopt(const tool_command_line *c, const getopt_tables *g, int argc, char **argv)
{
    opterr = 0;
    optind = 0; /* start afresh, even when called twice */
    for (;;) {
        int result = getopt_long(argc, argv, g->shorts, g->longs, NULL);
        if (result == -1)
            break;
        if (result == HELP_VALUE || result == 'h') {
            fputs(c->usage, stdout);
            exit(0);
        }
        if (result == VERSION_VALUE) {
            tool_print_version(c->program);
            exit(0);
        }
        if (result == '?' || result == ':')
            return getopt_error(c, result, argv);
        int r = result >= ROW_VALUE ? result - ROW_VALUE : short_row(g, result);
        if (r < 0)
            return tool_usage_error(c->program, "unknown option '%s'", argv[optind - 1]);
        if (take_row(c, &g->rows[r], argc, argv) != 0)
            return 2;
    }
    for (int i = optind; i < argc; i++) {
        if (c->positional && !*c->positional)
            *c->positional = argv[i];
        else
            return tool_usage_error(c->program, "more than one %s ('%s')", c->positional_name,
                                    argv[i]);
    }
    return 0;
}

int tool_parse_command_line(const tool_command_line *c, int argc, char **argv)
{
    getopt_tables g;
    memset(&g, 0, sizeof g);
    int rc = build_getopt_tables(c, &g) == 0 ? parse_getopt(c, &g, argc, argv) : -1;
    free(g.rows);
    free(g.longs);
    if (rc < 0) {
        fprintf(stderr, "%s: out of memory\n", c->program);
        return 2;
    }
    return rc;
}

int tool_parse_view_command_line(const char *program, const char *usage, tool_view_options *o,
                                 const tool_option *own, size_t own_count, void *own_base,
                                 const char **file, int argc, char **argv)
{
    const tool_option_table tables[] = {tool_view_option_table(o), {own, own_count, own_base}};
    const tool_command_line line = {program, usage, tables, 2, file, "file"};
    int rc = tool_parse_command_line(&line, argc, argv);
    if (rc)
        return rc;
    if (!*file)
        return tool_usage_error(program, "no brick file");
    if (!o->iso_count)
        return tool_usage_error(program, "--iso V is required");
    return 0;
}

/* "clip": [[A, B, C, D], ...]: each plane keeps A*x + B*y + C*z + D >= 0 (world units). */
static void write_clip_json(FILE *f, const tool_view_options *o)
{
    fprintf(f, ", \"clip\": [");
    for (unsigned i = 0; i < o->clip_count; i++) {
        const ip_clip_plane *c = &o->clip[i];
        fprintf(f, "%s[%.9g, %.9g, %.9g, %.9g]", i ? ", " : "", c->normal[0], c->normal[1],
                c->normal[2], c->offset);
    }
    fprintf(f, "]");
}

ip_status tool_full_extraction(ip_cache *cache, double iso, int mode, const ip_camera *camera,
                               const tool_view_options *o, ip_mesh *mesh, ip_engine_counts *counts,
                               ip_error *err)
{
    if (mode == TOOL_FULL_LOD)
        return ip_extract_full_lod(cache, (float)iso, camera, o->pixel_error, o->threads, o->clip,
                                   o->clip_count, mesh, counts, err);
    return ip_extract_full_clipped(cache, (float)iso, 0, o->threads, o->clip, o->clip_count, mesh,
                                   counts, err);
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

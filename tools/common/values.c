/* SPDX-License-Identifier: BSD-3-Clause */
/* The programs' option values: numbers, dimensions, pairs, counts; and their errors. */
#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "isoprop/version.h"
#include "tool_common.h"

int tool_fail(const char *program, const ip_error *err)
{
    fprintf(stderr, "%s: %s\n", program,
            err->message[0] ? err->message : ip_status_message(err->code));
    return 1;
}

int tool_is_png_name(const char *path)
{
    size_t n = strlen(path);
    return n > 4 && strcasecmp(path + n - 4, ".png") == 0;
}

int tool_check_png_name(const char *program, const char *option, const char *path)
{
    if (!path || tool_is_png_name(path))
        return 0;
    return tool_usage_error(program, "%s %s: images are written as PNG: name it .png", option,
                            path);
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

void tool_print_version(const char *program)
{
    printf("%s %s\n", program, ip_version());
}

int tool_parse_cache_mb(const char *text, uint64_t *bytes)
{
    uint64_t mb;
    if (tool_parse_u64(text, &mb) != 0 || mb < 1 || mb > (1ull << 30))
        return -1;
    *bytes = mb << 20;
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

int tool_is_u64(const char *text)
{
    uint64_t ignored;
    return tool_parse_u64(text, &ignored) == 0;
}

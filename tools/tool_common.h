/* Helpers shared by the programs (not part of the library): option values, errors, JSON. */
#ifndef ISOPROP_TOOL_COMMON_H
#define ISOPROP_TOOL_COMMON_H

#include <stdint.h>
#include <stdio.h>

#include "isoprop/status.h"

/* Prints "PROGRAM: message" on stderr and returns exit code 1 (2 for usage errors). */
int tool_fail(const char *program, const ip_error *err);
int tool_usage_error(const char *program, const char *fmt, ...);

/* Parses a non-negative integer option value; returns 0 on success, -1 on bad text. */
int tool_parse_u64(const char *text, uint64_t *out);
/* Parses a finite double; returns 0 on success, -1 on bad text. */
int tool_parse_double(const char *text, double *out);
/* Parses "a,b,c" into three finite doubles; returns 0 on success. */
int tool_parse_double3(const char *text, double out[3]);

/* Writes `text` as a JSON string literal (with quotes and escapes). */
void tool_json_string(FILE *out, const char *text);

/* Formats a byte count as "12.3 MiB" into buf. */
const char *tool_format_bytes(char *buf, size_t size, double bytes);

#endif

#include "isoprop/cache.h"
#include "isoprop/engine.h"

/* Parses --cache-mb's value into bytes; returns 0 on success. */
int tool_parse_cache_mb(const char *text, uint64_t *bytes);

/* The options isorender and isoview share: what to extract, from where, and how. */
typedef struct tool_view_options {
    double iso;
    int has_iso;
    uint32_t width, height;     /* pixels */
    const char *view, *camera;  /* --view AXIS, --camera E,T,U,FOV (NULL: none) */
    uint64_t rays;              /* 0: every pixel */
    double time_limit;          /* seconds; 0: none */
    double cutoff, foldback;    /* degrees */
    unsigned threads;           /* 0: every core */
    int lod;
    double pixel_error;
    uint64_t cache_bytes;
} tool_view_options;

/* The defaults: view -y, the paper's angles, lod on with a 1-pixel error, every core, the
 * default cache budget, an image of width x height. */
void tool_view_options_default(tool_view_options *o, uint32_t width, uint32_t height);

/* The engine options the shared options ask for. */
void tool_engine_options(const tool_view_options *o, ip_engine_options *eo);

/* Takes argv[*i] (with its value, argv[*i + 1]) when it is one of the shared options,
 * advancing *i past what it took. Returns 1 when taken, 0 when it is not a shared option
 * (or its value is missing), or 2 after printing a usage error for a bad value. */
int tool_parse_view_option(const char *program, int argc, char **argv, int *i,
                           tool_view_options *o);

/* Prints the cache statistics as a short human-readable table (on exit of every tool that
 * reads bricks). `summary_bytes` is the size of the file's summary section. */
void tool_print_cache_table(FILE *out, const ip_cache_stats *s, uint64_t summary_bytes);

/* Writes the "cache" object's members (without braces) as JSON. */
void tool_write_cache_json(FILE *out, const ip_cache_stats *s, uint64_t summary_bytes);

/* Writes {"cache": {...}} plus, when extra is not NULL, the members that extra(out, user)
 * prints (each preceded by ", "), to `path` via a temporary file and a rename.
 * Returns 0, or -1 after printing "PROGRAM: path: reason" on stderr. */
int tool_write_stats_file(const char *program, const char *path, const ip_cache_stats *s,
                          uint64_t summary_bytes, void (*extra)(FILE *out, void *user),
                          void *user);

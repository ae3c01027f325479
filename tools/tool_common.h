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

/* Parses --cache-mb's value into bytes; returns 0 on success. */
int tool_parse_cache_mb(const char *text, uint64_t *bytes);

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

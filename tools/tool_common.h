/* Helpers shared by the programs (not part of the library): option values, errors, JSON. */
#ifndef ISOPROP_TOOL_COMMON_H
#define ISOPROP_TOOL_COMMON_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "isoprop/engine.h"
#include "isoprop/status.h"
#include "isoprop/store.h"
#include "isoprop/system.h"

/* Prints "PROGRAM: message" on stderr and returns exit code 1 (2 for usage errors). */
int tool_fail(const char *program, const ip_error *err);
int tool_usage_error(const char *program, const char *fmt, ...);

/* Parses a non-negative integer option value; returns 0 on success, -1 on bad text. */
int tool_parse_u64(const char *text, uint64_t *out);
/* Parses a finite double; returns 0 on success, -1 on bad text. */
int tool_parse_double(const char *text, double *out);
/* Parses "a,b,c" into three finite doubles; returns 0 on success. */
int tool_parse_double3(const char *text, double out[3]);

/* Parses the value of a dims option ("XxYxZ", each 2 .. 2^31 - 1). Returns 0, or 2 after a
 * usage error that says what is wrong (not three numbers, a dimension that is zero or under 2,
 * one too large). */
int tool_parse_dims(const char *program, const char *option, const char *text,
                    uint32_t dims[3]);

/* Handles --version: prints "PROGRAM VERSION" (the library's, isoprop/version.h) on stdout. */
void tool_print_version(const char *program);

/* Checks every file of a run before any work, so that a bad one fails the run at once:
 * each input (NULL entries are skipped) exists and is a regular file (a FIFO or a device is
 * refused, never opened); no output is an input (the same file by device and inode, however
 * spelled); no two outputs are the same file; each output may be written (absent, or a
 * regular file and `force`; a directory, device or FIFO is refused even with force; see
 * isoprop/output.h). Returns 0, or 1 after printing one line "PROGRAM: path: problem". */
int tool_check_paths(const char *program, const char *const *inputs, size_t input_count,
                     const char *const *outputs, size_t output_count, int force);

/* Writes what fill(out, user) prints as the whole file at `path`, all-or-nothing (nothing is
 * left at path on failure; an existing file is replaced only with `force`, and only when it
 * is a regular file). Returns 0, or -1 after printing "PROGRAM: path: reason" on stderr. */
int tool_write_text_file(const char *program, const char *path, int force,
                         void (*fill)(FILE *out, void *user), void *user);

/* Ctrl-C and SIGTERM. tool_signals_catch() installs handlers that only record the signal
 * (and cancel the engine named by tool_signals_cancel_engine(), an atomic store), so that the
 * program can stop cleanly, write no output and then end as killed by that signal, with
 * tool_signals_reraise() (shell status 130 for SIGINT, 143 for SIGTERM). */
void tool_signals_catch(void);
/* The signal caught so far (SIGINT or SIGTERM), or 0. */
int tool_signal_caught(void);
/* The engine a signal cancels from now on (NULL: none). Before an engine is destroyed, call
 * with NULL: it returns once no handler can still be using the old one. */
void tool_signals_cancel_engine(ip_engine *engine);
/* When a signal was caught: flushes stdout and stderr, restores the default action and
 * raises the signal again (the process ends there). Returns when none was caught. */
void tool_signals_reraise(void);

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
 * prints (preceded by ", "), to `path` with tool_write_text_file() (all-or-nothing; an
 * existing file is replaced only with `force`).
 * Returns 0, or -1 after printing "PROGRAM: path: reason" on stderr. */
int tool_write_stats_file(const char *program, const char *path, int force,
                          const ip_cache_stats *s, uint64_t summary_bytes,
                          void (*extra)(FILE *out, void *user), void *user);

/* Warns (one line on stderr, "PROGRAM: warning: ...") when `iso` cannot cross the file's
 * value range (a cell is active when min < iso <= max), so that the image is legitimately
 * empty. `warning` (may be NULL) receives the warning's text, "" when none. Returns 1 when it
 * warned, else 0. */
int tool_warn_iso_range(const char *program, const ip_store *store, double iso, char *warning,
                        size_t warning_size);

/* SPDX-License-Identifier: BSD-3-Clause */
/* What the programs print and write: JSON, byte counts, cache statistics, --stats files. */
#ifndef ISOPROP_TOOL_REPORT_H
#define ISOPROP_TOOL_REPORT_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "isoprop/cache.h"
#include "isoprop/camera.h"
#include "isoprop/engine.h"
#include "isoprop/input.h"
#include "isoprop/store.h"
#include "tool_options.h"

/* Writes `text` as a JSON string literal (with quotes and escapes). */
void tool_json_string(FILE *out, const char *text);

/* Formats a byte count as "12.3 MiB" into buf. */
const char *tool_format_bytes(char *buf, size_t size, double bytes);

/* When the input says its values stand for stored x slope + intercept (DICOM rescale, NIfTI
 * scl_slope/scl_inter), prints that on `out` as an indented summary line, with the unit that
 * isovalues are then given in (--iso-stored takes stored values). Prints nothing otherwise. */
void tool_print_rescale(FILE *out, const ip_input_desc *desc);

/* `r` as text: "HU = stored x 1 - 1024" ("value = ..." without a unit), into buf. */
const char *tool_rescale_text(char *buf, size_t size, const ip_rescale *r);

/* The stored range lo .. hi in r's units, lowest first (a negative slope swaps the ends). */
void tool_value_range(const ip_rescale *r, double lo, double hi, double out[2]);

/* " HU" (a space, then r's unit), or "" when r has no rescale or no unit: after a value. */
const char *tool_unit_suffix(const ip_rescale *r, char *buf, size_t size);

/* Writes r as the JSON value {"slope": S, "intercept": I, "unit": U}, or null when r (may be
 * NULL) has no rescale. */
void tool_write_rescale_json(FILE *out, const ip_rescale *r);

/* Prints the cache statistics as a short human-readable table (on exit of every tool that
 * reads bricks). `summary_bytes` is the size of the file's summary section. */
void tool_print_cache_table(FILE *out, const ip_cache_stats *s, uint64_t summary_bytes);

/* Writes the "cache" object's members (without braces) as JSON. */
void tool_write_cache_json(FILE *out, const ip_cache_stats *s, uint64_t summary_bytes);

/* What isorender and isoview write about a run in --stats (members after "cache"). */
typedef struct tool_run_json {
    const char *file;
    double iso;              /* in the file's units: options->iso_value, or isoview's value */
    int full;                /* TOOL_PROGRESSIVE, TOOL_FULL or TOOL_FULL_LOD */
    const ip_camera *camera; /* in the file's physical space (tool_space_physical()) */
    const char *renderer;    /* "opengl", "software", "none" */
    const tool_view_options *options;
    int warm, done;
    const ip_engine_counts *counts;
    double rendering_seconds, extraction_wall_seconds, progress_render_seconds;
    double iso_stored;         /* the stored value extracted */
    const ip_rescale *rescale; /* the file's (may be NULL) */
} tool_run_json;

/* Writes the run's members ("file" .. "time"; without braces) as JSON; with a rescale, after
 * "iso" (in the file's units), "iso_stored" and "rescale". */
void tool_write_run_json(FILE *out, const tool_run_json *j);

/* Writes {"cache": {...}} plus, when extra is not NULL, the members that extra(out, user)
 * prints (preceded by ", "), to `path` with tool_write_text_file() (all-or-nothing; an
 * existing file is replaced only with `force`).
 * Returns 0, or -1 after printing "PROGRAM: path: reason" on stderr. */
int tool_write_stats_file(const char *program, const char *path, int force, const ip_cache_stats *s,
                          uint64_t summary_bytes, void (*extra)(FILE *out, void *user), void *user);

/* Warns (one line on stderr, "PROGRAM: warning: ...") when o's isovalue (settled:
 * tool_settle_iso()) cannot cross the file's value range (a cell is active when
 * min < stored iso <= max), so that the image is legitimately empty; the message gives the
 * value and the range as given (in the file's units, or stored with --iso-stored). `warning`
 * (may be NULL) receives the warning's text, "" when none. Returns 1 when it warned, else 0. */
int tool_warn_iso_range(const char *program, const ip_store *store, const tool_view_options *o,
                        char *warning, size_t warning_size);

#endif

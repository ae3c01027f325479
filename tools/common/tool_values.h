/* SPDX-License-Identifier: BSD-3-Clause */
/* The programs' option values (numbers, dimensions, pairs, counts) and their errors. */
#ifndef ISOPROP_TOOL_VALUES_H
#define ISOPROP_TOOL_VALUES_H

#include <stddef.h>
#include <stdint.h>

#include "isoprop/status.h"

/* Prints "PROGRAM: message" on stderr and returns exit code 1 (2 for usage errors). */
int tool_fail(const char *program, const ip_error *err);
int tool_usage_error(const char *program, const char *fmt, ...);

/* Whether `path` names a PNG image by its extension (.png, any case): the only image format the
 * programs write, so that no other name is given PNG bytes. */
int tool_is_png_name(const char *path);

/* The usage error (exit 2) for an image option whose file is not named .png; 0 when it is (or
 * when path is NULL). */
int tool_check_png_name(const char *program, const char *option, const char *path);

/* Parses a non-negative integer option value; returns 0 on success, -1 on bad text. */
int tool_parse_u64(const char *text, uint64_t *out);
/* Parses the value of `option` as an integer from `least` to `most`, into *out. Returns 0, or
 * 2 after the usage error "OPTION 'TEXT' is not WHAT (LEAST to MOST)". */
int tool_parse_bounded(const char *program, const char *option, const char *text, uint64_t least,
                       uint64_t most, const char *what, uint64_t *out);
/* Parses a finite double; returns 0 on success, -1 on bad text. */
int tool_parse_double(const char *text, double *out);
/* Parses "a,b,c" into three finite doubles; returns 0 on success. */
int tool_parse_double3(const char *text, double out[3]);

/* Parses the value of a dims option ("XxYxZ", each 2 .. 2^31 - 1). Returns 0, or 2 after a
 * usage error that says what is wrong (not three numbers, a dimension that is zero or under 2,
 * one too large). */
int tool_parse_dims(const char *program, const char *option, const char *text, uint32_t dims[3]);

/* Parses the value of a two-number option ("AxB", each 1 .. max; x or X between): `form` says
 * what it should be in the usage error ("WxH (e.g. 1600x1200)"), sides[] and `unit` name the
 * numbers in the one about their range ("the height, 0 pixels, is not within 1 .. 16384").
 * Returns 0, or 2 after that usage error. */
int tool_parse_pair(const char *program, const char *option, const char *text, uint32_t max,
                    const char *form, const char *const sides[2], const char *unit, uint32_t *a,
                    uint32_t *b);

/* Handles --version: prints "PROGRAM VERSION" (the library's, isoprop/version.h) on stdout. */
void tool_print_version(const char *program);

/* Parses --cache-mb's value into bytes; returns 0 on success. */
int tool_parse_cache_mb(const char *text, uint64_t *bytes);

/* Parses --threads N: 1 .. max, else "--threads must be 1-MAX". Returns 0, or 2 after the
 * usage error. */
int tool_parse_threads(const char *program, const char *text, unsigned max, unsigned *threads);

/* Whether `text` is a non-negative integer (tool_parse_u64() succeeds): for `accepts`. */
int tool_is_u64(const char *text);

#endif

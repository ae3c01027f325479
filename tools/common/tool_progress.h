/* SPDX-License-Identifier: BSD-3-Clause */
/* The programs' progress bar on stderr. */
#ifndef ISOPROP_TOOL_PROGRESS_H
#define ISOPROP_TOOL_PROGRESS_H

#include <stdint.h>

/* A progress bar on stderr (isoinfo --verify, isorender): shown when stderr is a terminal, or
 * always when the environment variable `force_variable` is "1" (for tests, whose stderr is a
 * pipe); drawn at most five times a second and at the end, as
 * "[####      ]  40.0% DONE/TOTAL UNIT DETAIL ETA Ns" on one line that it redraws. */
typedef struct tool_progress {
    int show, drawn;
    double start, last; /* seconds */
} tool_progress;

/* Starts the clock; the bar shows only when `wanted` (not --quiet, not --json). */
void tool_progress_start(tool_progress *p, int wanted, const char *force_variable);
/* Draws done of total UNIT (e.g. "bricks"), then `detail` (may be ""). */
void tool_progress_draw(tool_progress *p, uint64_t done, uint64_t total, const char *unit,
                        const char *detail);
/* Seconds since tool_progress_start(). */
double tool_progress_elapsed(const tool_progress *p);
/* Ends the bar's line, so that what follows starts on a line of its own. */
void tool_progress_end(tool_progress *p);

#endif

/* SPDX-License-Identifier: BSD-3-Clause */
/* The outputs of one run, as a set: all of them or none. */
#ifndef ISOPROP_TOOL_OUTPUTS_H
#define ISOPROP_TOOL_OUTPUTS_H

#include <stddef.h>

#include "isoprop/status.h"

/* The outputs a run has written so far. Each output file is all-or-nothing by itself
 * (isoprop/output.h); the set makes the run so: a run that fails, or that a signal stops
 * before its last output is written, removes the ones it wrote, so that it leaves none of its
 * outputs. A signal that comes once every output is written changes nothing: the run ends as
 * it would have, with exit status 0, and says so (tool_outputs_end()). Zero-initialise. */
typedef struct tool_outputs {
    char **paths; /* written by this run, in order */
    size_t count, capacity;
    char *folder; /* a folder this run made for its outputs (--turntable), removed with them
                     when it is then empty */
    int complete; /* every output is written */
} tool_outputs;

/* Records `path`, just written whole by this run ("-", standard output, is not a file and is
 * not recorded). Returns 0; -1 when there is no memory to record it, after removing the file
 * (the run then fails, and must leave nothing). */
int tool_outputs_add(tool_outputs *o, const char *path);

/* tool_outputs_add(), with the error (IP_ERR_NOMEM, naming `path`) in *err when it fails, for
 * a caller that reports an ip_error. Returns 0 or -1. */
int tool_outputs_add_or_error(tool_outputs *o, const char *path, ip_error *err);

/* Records the folder this run made for its outputs. Returns 0 or -1 (no memory). */
int tool_outputs_made_folder(tool_outputs *o, const char *path);

/* Marks the set complete: every output of the run is written. */
void tool_outputs_complete(tool_outputs *o);

/* Removes every output recorded, last first, and the folder the run made if it is then empty.
 * Returns how many files were removed. */
size_t tool_outputs_discard(tool_outputs *o);

/* The end of a run that wrote outputs, under one rule for every program: a run that failed
 * (rc != 0) removes what it wrote; a run stopped by SIGINT or SIGTERM before its outputs were
 * complete removes what it wrote, says "PROGRAM: WHAT: cancelled; no output written" (WHAT
 * NULL: the program has said so itself) and ends as killed by the signal (this call does not
 * return); a signal that came once they were complete is reported in one line ("PROGRAM:
 * every output was written before SIGINT; ending normally") and the run ends with `rc` (0).
 * Returns the exit status. Frees the set. */
int tool_outputs_end(tool_outputs *o, const char *program, const char *what, int rc);

#endif

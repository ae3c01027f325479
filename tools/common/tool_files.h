/* SPDX-License-Identifier: BSD-3-Clause */
/* The programs' files: checked before any work; text outputs written all-or-nothing. */
#ifndef ISOPROP_TOOL_FILES_H
#define ISOPROP_TOOL_FILES_H

#include <stddef.h>
#include <stdio.h>

/* Checks every file of a run before any work, so that a bad one fails the run at once: each input
 * (NULL entries are skipped) exists and is a regular file (a FIFO or a device is refused, never
 * opened); no output is an input (the same file by device and inode, however spelled); no two
 * outputs are the same file; each output may be written (absent, or a regular file and `force`; a
 * directory, device or FIFO is refused even with force; see isoprop/output.h). An output "-" is
 * standard output, which at most one output may be. Returns 0, or 1 after printing one line
 * "PROGRAM: path: problem". */
int tool_check_paths(const char *program, const char *const *inputs, size_t input_count,
                     const char *const *outputs, size_t output_count, int force);

/* Whether an output's path is "-", standard output (--stats -, --progress -). */
int tool_is_stdout(const char *path);

/* Writes what fill(out, user) prints as the whole file at `path`, all-or-nothing (nothing is
 * left at path on failure; an existing file is replaced only with `force`, and only when it
 * is a regular file). A path of "-" is standard output: the text is written there whole, at
 * once, but what has been written to stdout cannot be taken back when a later output fails.
 * Returns 0, or -1 after printing "PROGRAM: path: reason" on stderr. */
int tool_write_text_file(const char *program, const char *path, int force,
                         void (*fill)(FILE *out, void *user), void *user);

#endif

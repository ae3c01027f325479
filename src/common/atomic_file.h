/* SPDX-License-Identifier: BSD-3-Clause */
/* Atomic output files: all-or-nothing creation of a file at a path.
 *
 * The bytes go to an unnamed file (O_TMPFILE) in the destination's folder, or, where the file
 * system lacks O_TMPFILE, to a hidden temporary name there. ip__atomic_commit() fsyncs it and
 * gives it its final name in one step (link without --force, so an existing file is never
 * clobbered; link then rename with --force), then fsyncs the folder. Until then nothing exists
 * under the final name; a crash, a signal or an error leaves no partial output behind (with
 * O_TMPFILE, not even a temporary file). The public face of these rules is
 * isoprop/output.h. Internal to the library.
 */
#ifndef ISOPROP_ATOMIC_FILE_H
#define ISOPROP_ATOMIC_FILE_H

#include <stddef.h>
#include <stdint.h>

#include "isoprop/volume.h"
#include "isoprop/status.h"

typedef struct ip_atomic_file {
    int fd;                      /* write here (pwrite or write) */
    int force;                   /* replace an existing file at commit */
    int named;                   /* 1 when the fallback temporary name is in use */
    char path[IP_PATH_MAX];      /* the final name */
    char temp_path[IP_PATH_MAX]; /* the fallback temporary name, when named */
} ip_atomic_file;

/* Starts an output at `path`. Without force, an existing path fails at once (IP_ERR_EXISTS);
 * a path that exists and is not a regular file (a directory, device, FIFO or socket, or a link
 * to one) fails even with force (IP_ERR_ARGUMENT): only regular files are ever replaced. The
 * commit checks both again, just before the file gets its name. */
ip_status ip__atomic_create(ip_atomic_file *file, const char *path, int force, ip_error *err);

/* Makes the output durable and visible under its final name; closes it either way. */
ip_status ip__atomic_commit(ip_atomic_file *file, ip_error *err);

/* Discards the output; nothing remains. Safe after a failed commit and on a zeroed struct
 * whose fd is -1. */
void ip__atomic_abort(ip_atomic_file *file);

/* Writes all `size` bytes at `offset` (retrying short writes); names `path` in the error. */
ip_status ip__pwrite_all(int fd, const void *data, size_t size, uint64_t offset, const char *path,
                         ip_error *err);

/* Writes all `size` bytes: at `offset` with ip__pwrite_all(), or (stream != 0: a pipe, standard
 * output) in order with write(), retrying short writes; names `path` in the error. */
ip_status ip__write_at(int fd, int stream, const void *data, size_t size, uint64_t offset,
                       const char *path, ip_error *err);

/* Reads exactly `size` bytes at `offset`; a short read is IP_ERR_IO naming `path`. */
ip_status ip__pread_all(int fd, void *data, size_t size, uint64_t offset, const char *path,
                        ip_error *err);

#endif

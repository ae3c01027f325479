/* SPDX-License-Identifier: BSD-3-Clause */
/* isoprop: the rules every output file follows, and whole files written all-or-nothing.
 *
 * Every file the library writes (brick files, raw volumes, PNG images, PLY meshes, and the
 * buffers given to ip_output_write()) appears under its name only when complete: the bytes go
 * to an unnamed or hidden temporary file in the destination's folder, which is then linked or
 * renamed into place (see src/common/atomic_file.h). Three rules hold for all of them:
 *
 *   - without `force`, an existing file is never replaced (IP_ERR_EXISTS);
 *   - only regular files are ever replaced: an existing directory, device, FIFO or socket at
 *     the output path is refused even with `force` (IP_ERR_ARGUMENT);
 *   - a writer that reads an input refuses an output that is that input (the same file by
 *     device and inode, however the path is spelled).
 *
 * Programs check their whole lists of inputs and outputs up front with these functions, so
 * that a run fails before doing any work.
 */
#ifndef ISOPROP_OUTPUT_H
#define ISOPROP_OUTPUT_H

#include <stddef.h>

#include "isoprop/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- Experimental (IP_EXPERIMENTAL) ----
 * Declared only where IP_EXPERIMENTAL is defined before the include (docs/api.md,
 * "Stability"): calls for advanced uses that may change in a minor version, as the
 * programs use them. Exported all the same. */
#ifdef IP_EXPERIMENTAL

/*! ip_output_check() : whether `path` may be written as an output now: IP_OK when nothing
 *  exists there, or when a regular file (or a symbolic link to one: the link is replaced, not
 *  its target) exists and `force` is set. Touches nothing. Reentrant.
 *  @return IP_OK; IP_ERR_EXISTS when a file exists and force is 0; IP_ERR_ARGUMENT when the
 *  path exists and is not a regular file (directory, device, FIFO, socket), force or not;
 *  IP_ERR_IO when it cannot be examined. err->message names the path. */
IP_API ip_status ip_output_check(const char *path, int force, ip_error *err);

/*! ip_path_same_file() : 1 when paths `a` and `b` name the same file: the same device and
 *  inode when both exist, else the same canonical spelling (the real path of the folder plus
 *  the base name, so "x.png", "./x.png" and "dir/../x.png" agree before x.png exists); 0
 *  otherwise. Touches nothing. Reentrant. */
IP_API int ip_path_same_file(const char *a, const char *b);

/*! ip_output_not_input() : refuses an output that is an input.
 *  @return IP_OK when `output_path` and `input_path` are different files (ip_path_same_file()),
 *  else IP_ERR_ARGUMENT with a message naming both. */
IP_API ip_status ip_output_not_input(const char *output_path, const char *input_path,
                                     ip_error *err);

/*! ip_output_write() : writes `size` bytes from `data` as the whole file at `path`,
 *  all-or-nothing (durable and visible only when complete; nothing is left on failure),
 *  following the rules above. The caller keeps `data`. Reentrant.
 *  @return IP_OK, IP_ERR_EXISTS, IP_ERR_ARGUMENT (not a regular file, path too long) or
 *  IP_ERR_IO, with err->message naming the path. */
IP_API ip_status ip_output_write(const char *path, const void *data, size_t size, int force,
                                 ip_error *err);

#endif /* IP_EXPERIMENTAL */

#ifdef __cplusplus
}
#endif
#endif

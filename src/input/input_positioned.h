/* SPDX-License-Identifier: BSD-3-Clause */
/* Positioned reads of uncompressed input (and telling standard input, which has none), for callers that read planes from several threads
 * (the bricker) and ask the kernel to read ahead. Internal. */
#ifndef ISOPROP_INPUT_POSITIONED_H
#define ISOPROP_INPUT_POSITIONED_H

#include <stdint.h>

#include "isoprop/input.h"

/*! ip__input_is_stdin() : 1 when `path` (a desc's path or data_path) is "-": standard input,
 *  which is read once, in order (never positioned). */
int ip__input_is_stdin(const char *path);

/*! ip__input_positioned() : nonzero when the reader's data can be read at any plane
 *  (uncompressed data); gzip streams are read in order only, with ip_input_read_planes(). */
int ip__input_positioned(const ip_input_reader *reader);

/*! ip__input_direct_open() : opens the reader's data file a second time with O_DIRECT, so that
 *  ip__input_read_planes_at() reads past the page cache where it can (not thread-safe: call it
 *  before the reads). Only raw data whose offset and plane size are multiples of the file
 *  system's alignment qualify. Where they do not, or the file system refuses O_DIRECT (at the
 *  open or at the first read), the reads stay buffered without a word. @return nonzero when
 *  direct reads are on. */
int ip__input_direct_open(ip_input_reader *reader);

/*! ip__input_read_planes_at() : reads `count` planes from plane `z` into `dst` (count x plane
 *  bytes, caller-owned), converted to host byte order and checked as ip_input_read_planes()
 *  does; does not move the reader's position. After ip__input_direct_open() the bytes are read
 *  with O_DIRECT when dst, the file offset and the length meet the file system's alignment
 *  (statx STATX_DIOALIGN, else 4096), through the page cache otherwise; *direct_bytes (may be
 *  NULL) gets the count read directly. Thread-safe: several threads may read distinct planes of
 *  one reader at once. @return IP_OK, IP_ERR_IO, IP_ERR_INPUT (a float32 sample that is not
 *  finite), or IP_ERR_ARGUMENT (planes out of range, or a gzip reader). */
ip_status ip__input_read_planes_at(const ip_input_reader *reader, uint32_t z, uint32_t count,
                                   void *dst, uint64_t *direct_bytes, ip_error *err);

/*! ip__input_prefetch() : asks the kernel to start reading planes [z, z + count) into the page
 *  cache (posix_fadvise WILLNEED) and returns at once; planes past the end are ignored, and so
 *  is the whole call for a gzip reader and while reads are direct. The pages are the kernel's
 *  cache, not the process's memory. Thread-safe. */
void ip__input_prefetch(const ip_input_reader *reader, uint32_t z, uint32_t count);

#endif

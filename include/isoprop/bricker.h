/* SPDX-License-Identifier: BSD-3-Clause */
/* isoprop: bricking a raw volume into a brick file, streaming, with bounded memory.
 *
 * The input is read once, plane by plane. Each pyramid level keeps one slab of B+1 planes;
 * when a slab is full its layer of bricks is summarised and compressed on all threads (the
 * calling one and helpers started once per run, joined before ip_bricker_run() returns) and
 * appended to an unnamed spill file. Where the memory limit has room for B more level-0
 * planes, a thread reads the next chunk of planes meanwhile; raw data whose planes suit the
 * file system's direct I/O are read with O_DIRECT, past the page cache. At the end the
 * payloads are copied into the output in Morton order, followed by the summary section and the
 * header. The output appears under its name only when complete (see docs/format.md and
 * src/common/atomic_file.h).
 */
#ifndef ISOPROP_BRICKER_H
#define ISOPROP_BRICKER_H

#include <stdint.h>

#include "isoprop/input.h"
#include "isoprop/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Returns nonzero to cancel the run (e.g. after Ctrl-C). Called from the calling thread. */
typedef int (*ip_progress_fn)(void *user, uint64_t done_bytes, uint64_t total_bytes);

/* Compression effort: IP_LZ4_FAST is LZ4's default; 1..12 are LZ4HC levels. */
#define IP_LZ4_FAST 0
#define IP_LZ4_HC_DEFAULT 9

typedef struct ip_bricker_options {
    uint32_t size; /* bytes of the struct as the caller compiled it (IP_SIZED); see status.h */
    uint32_t brick_edge;     /* B, cells per brick edge; default IP_DEFAULT_BRICK_EDGE */
    uint32_t subblock_edge;  /* s, cells per sub-block edge; default IP_DEFAULT_SUBBLOCK_EDGE */
    int lz4_level;           /* IP_LZ4_FAST (default) or an LZ4HC level 1..12 */
    unsigned threads;        /* compression threads; 0 = every online core */
    uint64_t memory_limit;   /* bytes of working memory allowed; 0 = no limit */
    int force;               /* replace an existing output */
    ip_progress_fn progress; /* may be NULL */
    void *progress_user;
} ip_bricker_options;

typedef struct ip_bricker_report {
    uint64_t input_bytes; /* dims x type size */
    uint64_t file_bytes;  /* size of the brick file written */
    uint64_t bricks;      /* all levels */
    uint64_t bricks_constant, bricks_compressed, bricks_raw;
    uint32_t levels;
    unsigned threads;
    double seconds;          /* wall time of the whole run */
    uint64_t memory_planned; /* working memory the run reserved for itself, bytes */
    uint64_t peak_rss;       /* the process's peak resident set at the end (VmHWM), bytes */
    /* Where the wall time went, seconds: reading the input and subsampling the pyramid;
     * summarising, filtering, compressing, checksumming and spilling the bricks; putting the
     * payloads in order and writing the summary. */
    double seconds_read, seconds_encode, seconds_write;
    /* Input bytes read with O_DIRECT, past the page cache: raw data whose offset and plane size
     * suit the file system's direct I/O; 0 when every read was buffered. */
    uint64_t bytes_direct;
    /* Nonzero when a thread read each next chunk of planes while the last one was encoded (the
     * plan had room for a second chunk of level-0 planes); seconds_read then counts only the
     * reading the encoding did not hide. */
    int read_overlap;
    uint64_t reserved[8]; /* zero: room for later fields at the same size (status.h) */
} ip_bricker_report;

/*! ip_bricker_options_default() : fills `options` with the defaults above. */
IP_API void ip_bricker_options_default(ip_bricker_options *options);

/*! ip_bricker_memory_needed() : working memory (bytes) a run with `options` needs for `input`:
 *  what its reader holds (input->reader_bytes: a Zarr row of chunks) and the plan with a
 *  second chunk of level-0 planes (read while the one before is encoded) when the input has
 *  more than one layer of level-0 bricks and options->memory_limit is 0 or has room for it,
 *  else the smallest plan.
 *  @return IP_OK, or an error for options the layout rejects. */
IP_API ip_status ip_bricker_memory_needed(const ip_input_desc *input,
                                          const ip_bricker_options *options, uint64_t *bytes,
                                          ip_error *err);

/*! ip_bricker_run() : bricks `input` into a new brick file at `out_path`. The input's rescale
 *  (has_rescale: slope, intercept, unit) goes into the file, which is then of format version
 *  3 (else 2). On any failure,
 *  cancellation included, nothing is left at out_path (an existing file there is untouched).
 *  Follows the output rules of isoprop/output.h: out_path is never the input file or its
 *  data file (however spelled), and only a regular file is ever replaced (with force).
 *  `report` (may be NULL) is filled on success.
 *  @return IP_OK, IP_ERR_EXISTS, IP_ERR_LIMIT (memory_limit too small: the message says how
 *  much is needed), IP_ERR_INPUT, IP_ERR_IO, IP_ERR_NOMEM or IP_ERR_CANCELLED;
 *  IP_ERR_ARGUMENT when out_path is the input (or its data file) or exists as something other
 *  than a regular file, an argument is NULL, or the rescale is invalid (ip_rescale_check());
 *  IP_ERR_UNSUPPORTED for a spacing outside the
 *  bounds of ip_spacing_check(). */
IP_API ip_status ip_bricker_run(const ip_input_desc *input, const char *out_path,
                                const ip_bricker_options *options, ip_bricker_report *report,
                                ip_error *err);

#ifdef __cplusplus
}
#endif
#endif

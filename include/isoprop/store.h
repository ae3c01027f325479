/* SPDX-License-Identifier: BSD-3-Clause */
/* isoprop: a brick file opened for reading.
 *
 * ip_store_open() reads the header and the summary section once, into memory the store owns,
 * and validates them (ip__format_parse_header(), ip__format_parse_summary()): after that every
 * summary (level table, brick and sub-block ranges, octree nodes) is available without
 * touching the file again, and stays as verified whatever happens to the file. Reading a brick
 * reads its payload with pread() into the caller's scratch, verifies its checksum there and
 * decodes those same bytes. So a file that changes while open (truncated, rewritten in place)
 * gives a clear error naming the brick (IP_ERR_IO for a short read, IP_ERR_CHECKSUM for other
 * bytes), never a signal and never unverified samples. Nothing of the file is mapped.
 * A store is immutable after opening: every function here is safe to call from many threads
 * at once.
 */
#ifndef ISOPROP_STORE_H
#define ISOPROP_STORE_H

#include <stddef.h>
#include <stdint.h>

#include "isoprop/layout.h"
#include "isoprop/orientation.h"
#include "isoprop/status.h"
#include "isoprop/volume.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ip_store ip_store;

/*! ip_store_open() : opens and validates the brick file at `path`. *out is owned by the
 *  caller and released with ip_store_close().
 *  @return IP_OK, IP_ERR_IO, IP_ERR_FORMAT, IP_ERR_CHECKSUM, IP_ERR_UNSUPPORTED or
 *  IP_ERR_NOMEM, with err->message naming the file and the problem. */
IP_API ip_status ip_store_open(const char *path, ip_store **out, ip_error *err);

/*! ip_store_close() : unmaps and frees the store (NULL is allowed). No brick pointer or
 *  summary pointer obtained from it may be used afterwards. */
IP_API void ip_store_close(ip_store *store);

/*! ip_store_layout() : the file's layout (dims, type, levels, offsets); owned by the store. */
IP_API const ip_layout *ip_store_layout(const ip_store *store);

/*! ip_store_path() : the path the store was opened with. */
IP_API const char *ip_store_path(const ip_store *store);

/*! ip_store_summary_memory() : bytes the store holds in memory for the summaries (directory,
 *  brick, sub-block and node ranges; the sub-block ranges of constant bricks are shared, so
 *  this is usually well under the file's summary section). */
IP_API uint64_t ip_store_summary_memory(const ip_store *store);

/*! ip_store_check_summary() : recomputes the range and sub-block ranges of brick `g` from its
 *  decoded `samples` (as ip_store_read_brick() or the cache give them) and compares them with
 *  the summary section. @return IP_OK, or IP_ERR_CORRUPT naming the brick. */
IP_API ip_status ip_store_check_summary(const ip_store *store, uint64_t g, const void *samples,
                                        ip_error *err);

/*! ip_store_verify_brick() : ip_store_read_brick() (same buffers), then recomputes the brick's range and
 *  sub-block ranges from the decoded samples and compares them with the summary section.
 *  @return IP_OK, or IP_ERR_CHECKSUM / IP_ERR_CORRUPT naming the brick. */
IP_API ip_status ip_store_verify_brick(const ip_store *store, uint64_t g, void *dst, void *work,
                                       ip_error *err);

/*! ip_store_verify_octree() : recomputes every octree node from the brick ranges and compares.
 *  @return IP_OK or IP_ERR_CORRUPT naming the first wrong node. */
IP_API ip_status ip_store_verify_octree(const ip_store *store, ip_error *err);

/* ---- Experimental (IP_EXPERIMENTAL) ----
 * Declared only where IP_EXPERIMENTAL is defined before the include (docs/api.md,
 * "Stability"): calls for advanced uses that may change in a minor version, as the
 * programs use them. Exported all the same. */
#ifdef IP_EXPERIMENTAL

/*! ip_store_brick_entry() : directory entry of global brick `g` (< brick_count). */
IP_API void ip_store_brick_entry(const ip_store *store, uint64_t g, ip_brick_entry *entry);

/*! ip_store_brick_range() : min and max over the corners of every cell of brick `g`. */
IP_API void ip_store_brick_range(const ip_store *store, uint64_t g, float range[2]);

/*! ip_store_subblock_ranges() : the (B/s)^3 sub-block ranges of brick `g`, 2 floats each
 *  (min, max; x fastest); an empty sub-block is [+inf, -inf]. Owned by the store. */
IP_API const float *ip_store_subblock_ranges(const ip_store *store, uint64_t g);

/*! ip_store_node_range() : range of octree node `node` at `depth` (1..octree_depth) of
 *  `level`; depth 0 is the brick itself. Owned by the store. */
IP_API const float *ip_store_node_range(const ip_store *store, uint32_t level, uint32_t depth,
                                        const uint32_t node[3]);

/*! ip_store_brick_samples() : number of samples of brick `g` (its extent's product). */
IP_API uint64_t ip_store_brick_samples(const ip_store *store, uint64_t g);

/*! ip_store_read_work_size() : bytes of scratch ip_store_read_brick() needs, for any brick of
 *  this file (its largest payload plus the codec's scratch for the largest brick). */
IP_API size_t ip_store_read_work_size(const ip_store *store);

/*! ip_store_read_brick() : reads brick `g`'s payload, verifies its checksum and decodes it into
 *  `dst` (ip_store_brick_samples() samples of the file's type, host byte order, x fastest; the
 *  extent is ip_brick_extent()). `work` is scratch of ip_store_read_work_size() bytes. Both
 *  buffers are the caller's. A constant brick reads nothing.
 *  @return IP_OK; IP_ERR_CHECKSUM or IP_ERR_CORRUPT naming the brick, its level and
 *  coordinates; IP_ERR_IO when the read fails or the file ends before the payload (it shrank
 *  since it was opened: the message gives both sizes). */
IP_API ip_status ip_store_read_brick(const ip_store *store, uint64_t g, void *dst, void *work,
                                     ip_error *err);

/*! ip_store_prefetch_brick() : asks the kernel to start reading brick `g`'s payload into the
 *  page cache in the background (posix_fadvise WILLNEED); returns at once, waits for nothing.
 *  A hint: a later ip_store_read_brick() finds the bytes in memory instead of stalling. */
IP_API void ip_store_prefetch_brick(const ip_store *store, uint64_t g);

/*! ip_store_brick_in_memory() : whether brick `g`'s payload (g < the brick count) can be read
 *  without waiting for the disk: 1 when the kernel holds it in the page cache (or the brick
 *  has no payload), 0 when a read would wait for the device, -1 when the kernel or the file
 *  system cannot tell (reads that may not wait, RWF_NOWAIT, are not supported). Probes a few
 *  bytes of the payload (a read of one byte each), reads nothing else and changes nothing. A
 *  hint: the answer may be stale the moment it is given. Thread-safe. */
IP_API int ip_store_brick_in_memory(const ip_store *store, uint64_t g);

/* ---- A volume in memory (experimental) ----
 * ip_store_open_memory() opens a store on samples the caller holds in memory (a numpy array,
 * a buffer of its own) instead of a brick file: the same layout, brick and sub-block ranges
 * and octree as the brick file of those samples would hold (bit for bit), so the cache and
 * the engine run on it unchanged and extract the same triangles. Level 0 bricks are gathered
 * from the caller's samples on each read (ip_store_read_brick(), a strided copy into the
 * caller's buffer); the coarser levels of the pyramid (about 1/7 of the samples) are built
 * once at open and held by the store (ip_store_held_samples()). Nothing is written to disk
 * and no whole copy of the samples is made. */

/* The caller's volume: an options-like sized struct (status.h; initialise it with
 * IP_SIZED(ip_memory_volume) or ip_memory_volume_default()). */
typedef struct ip_memory_volume {
    uint32_t size;
    uint32_t dims[3];   /* samples along x, y, z; each >= 2 */
    ip_type type;       /* IP_UINT8, IP_UINT16, IP_INT16 or IP_FLOAT32, host byte order */
    int64_t strides[3]; /* bytes from a sample to its next along x, y, z (any sign; 0 allowed
                           for a volume constant along that axis); all three 0: contiguous,
                           x fastest */
    double spacing[3];  /* world units between samples; all three 0: 1, 1, 1 */
    ip_orientation orientation; /* as ip_input_desc's; all-zero directions: the
                                   unit axes (origin and space kept) */
    ip_rescale rescale;         /* what the values stand for, as a brick file keeps it;
                                   present 0: none */
    uint32_t brick_edge;        /* B; 0: IP_DEFAULT_BRICK_EDGE (as the bricker's) */
    uint32_t subblock_edge;     /* s; 0: IP_DEFAULT_SUBBLOCK_EDGE */
    uint32_t threads;           /* threads building the pyramid and summaries at open
                                   (ip_thread_count()); 0: every core */
    const char *name;           /* what messages and ip_store_path() call the volume; NULL:
                                   "array" */
} ip_memory_volume;

/*! ip_memory_volume_default() : zeros, size set, name "array". */
IP_API void ip_memory_volume_default(ip_memory_volume *volume);

/*! ip_store_open_memory() : opens a store on `samples`, the address of sample (0,0,0) of the
 *  volume `volume` describes. The samples stay the caller's: they must stay alive and
 *  unchanged until ip_store_close() (a store only reads them; a change is not seen by the
 *  summaries, so extraction would then be wrong where they changed, which
 *  ip_store_verify_brick() detects). float32 samples must be finite: the first NaN or
 *  infinite one is named and refused. `*out` is the caller's, released with ip_store_close().
 *  On a memory store, ip_store_read_brick() gathers the brick (level 0 from the samples,
 *  coarser levels from the store's pyramid) and cannot fail, leaving `work` unused (whose
 *  ip_store_read_work_size() is a token 64 bytes);
 *  the directory entries (ip_store_brick_entry()) have no offset, payload or checksum (offset,
 *  stored_size and checksum 0; encoding IP_BRICK_CONSTANT for a brick whose samples all equal
 *  one value, else IP_BRICK_RAW); ip_store_verify_brick() recomputes the summaries of a brick
 *  from the samples now (IP_ERR_CORRUPT when they changed since open); the layout's file
 *  figures (data and summary offsets and sizes, checksum, file_size) are 0;
 *  ip_store_prefetch_brick() does nothing and ip_store_brick_in_memory() is 1.
 *  @return IP_OK; IP_ERR_ARGUMENT (a NULL pointer, dims under 2, an unsupported type, a bad
 *  brick or sub-block edge, orientation or rescale), IP_ERR_UNSUPPORTED (a spacing outside
 *  ip_spacing_check()'s bounds), IP_ERR_INPUT (a NaN or infinite float32 sample) or
 *  IP_ERR_NOMEM, the message starting with the volume's name. */
IP_API ip_status ip_store_open_memory(const void *samples, const ip_memory_volume *volume,
                                      ip_store **out, ip_error *err);

/*! ip_store_held_samples() : bytes of samples the store holds in memory: the coarser levels of
 *  a memory store's pyramid; 0 for a brick file (its samples are read on demand). Not part
 *  of ip_store_summary_memory(). */
IP_API uint64_t ip_store_held_samples(const ip_store *store);

#endif /* IP_EXPERIMENTAL */

#ifdef __cplusplus
}
#endif
#endif

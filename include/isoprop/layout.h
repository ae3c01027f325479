/* SPDX-License-Identifier: BSD-3-Clause */
/* isoprop: the shape of a brick file: its levels, bricks and directory entries.
 *
 * docs/format.md specifies every byte. In short: a 256-byte header, then the brick payloads
 * (Morton order within each level, level 0 first), then the summary section (4096-aligned):
 * the level table, the brick directory, per-brick and per-sub-block min/max, and the min/max
 * octree above the bricks of every level. ip_store_layout() gives an open file's layout; the
 * functions here locate bricks in it. Pure functions, thread-safe.
 */
#ifndef ISOPROP_LAYOUT_H
#define ISOPROP_LAYOUT_H

#include <stddef.h>
#include <stdint.h>

#include "isoprop/orientation.h"
#include "isoprop/status.h"
#include "isoprop/volume.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The newest format version this build reads. It writes version 3 for a volume with a
 * rescale (ip_rescale), version 2 for one without, as 2 has it (docs/format.md). */
#define IP_FORMAT_VERSION 3u
#define IP_HEADER_SIZE 256u
#define IP_MAGIC "\x89IBV\r\n\x1a\n" /* 8 bytes */
#define IP_MAX_LEVELS 32
#define IP_LEVEL_ENTRY_SIZE 64u
#define IP_DIRECTORY_ENTRY_SIZE 24u
#define IP_RANGE_SIZE 8u           /* float32 min, float32 max */
#define IP_RESCALE_RECORD_SIZE 64u /* version 3: the rescale, first in the summary section */
#define IP_SUMMARY_ALIGN 4096u
#define IP_DEFAULT_BRICK_EDGE 32u
#define IP_DEFAULT_SUBBLOCK_EDGE 8u
#define IP_MAX_BRICK_EDGE 256u

/* How a brick's payload is stored (directory entry byte 12). */
typedef enum ip_brick_encoding {
    IP_BRICK_CONSTANT = 0, /* no payload: every sample equals the brick's min (== max) */
    IP_BRICK_RAW = 1,      /* the samples, little-endian, x fastest */
    IP_BRICK_LZ4 = 2       /* one LZ4 block of the filtered samples */
} ip_brick_encoding;

/* Reversible filters applied before LZ4 (directory entry byte 13). At most one predictor
 * (DELTA or MED) is set; encoding applies the predictor, then SHUFFLE. Predictions work on the
 * samples as unsigned integers of their width, residuals wrap and are zigzag-mapped so that
 * small negative and positive residuals both become small numbers. */
enum {
    IP_FILTER_DELTA = 1,   /* residual from the previous sample in storage order */
    IP_FILTER_SHUFFLE = 2, /* byte planes: all first bytes, then all second bytes, ... */
    IP_FILTER_MED = 4      /* residual from the median edge predictor within each z slice */
};

/* One level of the pyramid: level k samples the volume at every 2^k-th sample. */
typedef struct ip_level_layout {
    uint32_t dims[3];      /* samples along each axis: ceil((d - 1) / 2^k) + 1 */
    uint32_t bricks[3];    /* bricks along each axis: ceil((dims - 1) / B) */
    uint64_t first_brick;  /* global index of brick (0,0,0) of this level */
    uint64_t brick_count;  /* bricks[0] * bricks[1] * bricks[2] */
    uint32_t octree_depth; /* octree levels above the bricks (0 when one brick) */
    uint64_t first_node;   /* index of this level's first octree node in the node array */
    uint64_t node_count;   /* octree nodes of this level, all depths */
    float value_min, value_max;
} ip_level_layout;

/* Everything about a brick file except its payload bytes. */
typedef struct ip_layout {
    uint32_t dims[3];
    ip_type type;
    double spacing[3];
    ip_orientation orientation; /* origin, directions and space of the volume in its source
                                   file's physical space (format version 2; identity for 1) */
    uint32_t brick_edge;        /* B: cells per brick edge, a power of two in [2, 256] */
    uint32_t subblock_edge;     /* s: cells per sub-block edge, a power of two dividing B */
    uint32_t level_count;
    float value_min, value_max;
    uint64_t brick_count; /* all levels */
    uint64_t node_count;  /* octree nodes, all levels */
    uint64_t data_offset, data_size;
    uint64_t summary_offset, summary_size;
    uint64_t summary_checksum;
    uint64_t file_size;
    ip_level_layout levels[IP_MAX_LEVELS];
    uint32_t format_version; /* the file's format version (an opened file's own: 1, 2 or 3);
                                the version this build writes for a layout made to write */
    ip_rescale rescale;      /* what the stored values stand for (format version 3; none for
                                1 and 2) */
} ip_layout;

/* A brick directory entry (24 bytes on disk). */
typedef struct ip_brick_entry {
    uint64_t offset;      /* absolute file offset of the payload */
    uint32_t stored_size; /* payload bytes (0 for a constant brick) */
    uint8_t encoding;     /* ip_brick_encoding */
    uint8_t filters;      /* IP_FILTER_* bits (0 unless LZ4) */
    uint64_t checksum;    /* XXH64 (seed 0) of the payload; 0 for a constant brick */
} ip_brick_entry;

/*! ip_layout_world_box() : the volume's world-space box: lo = 0, hi = (dims - 1) * spacing
 *  along each axis (world units). */
IP_API void ip_layout_world_box(const ip_layout *layout, double lo[3], double hi[3]);

/* ---- Experimental (IP_EXPERIMENTAL) ----
 * Declared only where IP_EXPERIMENTAL is defined before the include (docs/api.md,
 * "Stability"): calls for advanced uses that may change in a minor version, as the
 * programs use them. Exported all the same. */
#ifdef IP_EXPERIMENTAL

/*! ip_layout_subblocks_per_brick() : (B / s)^3. */
IP_API uint32_t ip_layout_subblocks_per_brick(const ip_layout *layout);

/*! ip_level_sample_index() : the level-0 sample index along an axis of size `dim` that level
 *  `level`'s sample `i` takes: min(i * 2^level, dim - 1). */
IP_API uint32_t ip_level_sample_index(uint32_t dim, uint32_t level, uint32_t i);

/*! ip_brick_extent() : samples along each axis of brick (bx,by,bz) of `level`, including its
 *  + face layer: min(B, cells - b*B) + 1. Writes origin (first sample, level coordinates). */
IP_API void ip_brick_extent(const ip_layout *layout, uint32_t level, const uint32_t brick[3],
                            uint32_t origin[3], uint32_t extent[3]);

/*! ip_brick_global_index() : directory index of brick (bx,by,bz) of `level`. */
IP_API uint64_t ip_brick_global_index(const ip_layout *layout, uint32_t level,
                                      const uint32_t brick[3]);

/*! ip_brick_coords() : inverse of ip_brick_global_index(); fills level and brick. */
IP_API void ip_brick_coords(const ip_layout *layout, uint64_t global, uint32_t *level,
                            uint32_t brick[3]);

#endif /* IP_EXPERIMENTAL */

#ifdef __cplusplus
}
#endif
#endif

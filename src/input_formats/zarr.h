/* SPDX-License-Identifier: BSD-3-Clause */
/* Internal to the input component: Zarr v2 and v3 arrays and OME-Zarr images (docs/input.md,
 * "Zarr"). zarr_meta.c reads the metadata (cJSON) into a zarr_array; zarr_codec.c decodes a
 * chunk or a shard's inner chunk (blosc, zlib/gzip, zstd, lz4, crc32c); input_zarr.c is the
 * describe function and the plane source, which decodes one z-row of chunks at a time on every
 * core. */
#ifndef ISOPROP_ZARR_H
#define ISOPROP_ZARR_H

#include <stddef.h>
#include <stdint.h>

#include "input_source.h"

#define ZARR_MAX_DIMS 5
#define ZARR_MAX_CODECS 4

/* The bytes-to-bytes codecs of a chunk, applied in this order when writing (decoded last to
 * first). ZARR_LZ4 is numcodecs' LZ4: a 4-byte little-endian size, then an LZ4 block. */
typedef enum zarr_codec_id {
    ZARR_BLOSC,
    ZARR_ZLIB, /* a zlib stream (v2 "zlib") */
    ZARR_GZIP, /* a gzip stream (v2 "gzip", v3 "gzip") */
    ZARR_ZSTD,
    ZARR_LZ4,
    ZARR_CRC32C /* v3: 4 bytes of CRC-32C (little-endian) after the data */
} zarr_codec_id;

/* A chain of codecs: the chunk's samples in `big_endian` order, then `count` codecs: at most
 * one compressor, and (v3) crc32c after it. */
typedef struct zarr_chain {
    int big_endian;
    uint32_t count;
    zarr_codec_id codecs[ZARR_MAX_CODECS];
} zarr_chain;

/* One array, the dimensions slowest first (C order). */
typedef struct zarr_array {
    char folder[IP_PATH_MAX]; /* the array's folder */
    int version;              /* 2 or 3 */
    uint32_t ndim;
    uint64_t shape[ZARR_MAX_DIMS];
    uint64_t chunk[ZARR_MAX_DIMS]; /* the chunk (v3 sharded: the shard) shape */
    char kind;                     /* 'u', 'i' or 'f' */
    uint32_t item;                 /* bytes of a stored sample: 1, 2 or 4 */
    ip_type type;                  /* the type read into: int8 as int16, 32-bit ints as float32 */
    double fill;                   /* the fill value of missing chunks */
    char separator;                /* between a key's indices: '.' or '/' */
    int key_prefix;                /* v3 default encoding: keys start "c" + separator */
    zarr_chain chain;              /* a chunk's codecs (sharded: the inner chunks') */
    int sharded;                   /* v3 sharding_indexed */
    uint64_t inner[ZARR_MAX_DIMS]; /* sharded: the inner chunk shape */
    zarr_chain index_chain;        /* sharded: the index's codecs (bytes, crc32c only) */
    int index_at_start;            /* sharded: the index starts the shard (else ends it) */
} zarr_array;

/* What the describe function found beyond the array: the axes and the chosen 3-D volume. */
typedef struct zarr_pick {
    int axis[ZARR_MAX_DIMS];    /* per array dim: 'x', 'y', 'z', 't', 'c' */
    uint64_t at[ZARR_MAX_DIMS]; /* index along the dims that are not x, y, z (t, c, 1s) */
} zarr_pick;

/*! zarr_read_array() : reads the array metadata of the folder `folder` (.zarray, or zarr.json
 *  of node_type array) into *a. IP_ERR_INPUT naming the metadata file and the problem. */
ip_status ip__zarr_read_array(const char *folder, zarr_array *a, ip_error *err);

/* An OME-Zarr image's choice (isobrick --scale, --time, --channel) and what it gives. */
typedef struct zarr_ome {
    char array[IP_PATH_MAX]; /* the chosen scale's array folder */
    uint32_t scales;         /* scales in the multiscale */
    int axis[ZARR_MAX_DIMS]; /* per dim: 'x', 'y', 'z', 't', 'c' */
    uint32_t ndim;
    double spacing[3], origin[3]; /* x, y, z; in `unit` */
    char unit[32];                /* the spatial axes' unit ("" when none) */
} zarr_ome;

/*! ip__zarr_read_ome() : 1 in *is_ome when `folder` is an OME-Zarr image (multiscales in .zattrs
 *  or in zarr.json's attributes.ome), then reads scale `scale` into *o. IP_ERR_INPUT naming the
 *  file and the problem (a scale that is not there names the count). */
ip_status ip__zarr_read_ome(const char *folder, uint32_t scale, int *is_ome, zarr_ome *o,
                            ip_error *err);

/*! ip__zarr_read_text() : the text of the metadata file `path` into *out (NUL-terminated, the
 *  caller's to free); *missing 1 (and *out NULL) when it does not exist. IP_ERR_IO when it
 *  cannot be read, IP_ERR_INPUT when it is not a regular file or is over 16 MiB. */
ip_status ip__zarr_read_text(const char *path, char **out, int *missing, ip_error *err);

/*! ip__zarr_shown() : `text` from a metadata file as it may go into a one-line message: at
 *  most size - 1 characters, control characters as '?', "?" for NULL. Returns buf. */
const char *ip__zarr_shown(const char *text, char *buf, size_t size);

/*! ip__zarr_unit_symbol() : an OME length unit ("micrometer") as its symbol ("um") into out;
 *  another unit as it is, cut to size - 1 characters. */
void ip__zarr_unit_symbol(const char *unit, char *out, size_t size);

/* ---- chunks (zarr_codec.c) ---- */

/*! ip__zarr_decode() : decodes `size` bytes of `src` through `chain` into exactly `out_bytes`
 *  bytes at dst (samples still in the chain's byte order). Returns 0, or -1 with what is
 *  wrong in `why` ("blosc: does not decode", "crc32c: checksum mismatch", "zstd: decodes to
 *  100 bytes, not the chunk's 512"). */
int ip__zarr_decode(const zarr_chain *chain, const unsigned char *src, size_t size,
                    unsigned char *dst, size_t out_bytes, char *why, size_t why_size);

/*! ip__crc32c() : CRC-32C (Castagnoli, reflected, polynomial 0x82F63B78) of data. */
uint32_t ip__crc32c(const unsigned char *data, size_t size);

/*! ip__zarr_parse_array() : the array metadata from the JSON text `text` (of the file `name`,
 *  for messages; version 2: .zarray, 3: zarr.json) into *a (whose folder the caller sets). */
ip_status ip__zarr_parse_array(const char *name, const char *text, int version, zarr_array *a,
                               ip_error *err);

#endif

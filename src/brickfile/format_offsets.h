/* SPDX-License-Identifier: BSD-3-Clause */
/* isoprop internal: every byte offset of the brick file's fixed-size records, named once.
 *
 * docs/format.md is the specification; these names are its tables ("Header", "Rescale
 * record", "Level table entry", "Directory entry"), used by the encoders and the parser of format.c alike and by the
 * tests that corrupt one field. Offsets are in bytes from the start of the record; a field of
 * three values (dims, spacing, bricks) holds them x, y, z at its offset + i * the value's size.
 * The _Static_asserts below tie the names to the record sizes of isoprop/layout.h, so that a
 * field cannot be moved without the layout failing to compile.
 */
#ifndef ISOPROP_FORMAT_OFFSETS_H
#define ISOPROP_FORMAT_OFFSETS_H

#include "isoprop/layout.h"

/* Header (IP_HEADER_SIZE = 256 bytes) */
enum {
    IP_HDR_MAGIC = 0,              /* 8 bytes, IP_MAGIC */
    IP_HDR_MAGIC_SIZE = 8,         /* bytes of the magic */
    IP_HDR_VERSION = 8,            /* u32 */
    IP_HDR_HEADER_SIZE = 12,       /* u32 */
    IP_HDR_DIMS = 16,              /* u32 x 3 */
    IP_HDR_TYPE = 28,              /* u32 */
    IP_HDR_SPACING = 32,           /* f64 x 3 */
    IP_HDR_BRICK_EDGE = 56,        /* u32, B */
    IP_HDR_SUBBLOCK_EDGE = 60,     /* u32, s */
    IP_HDR_LEVEL_COUNT = 64,       /* u32 */
    IP_HDR_FLAGS = 68,             /* u32, 0 */
    IP_HDR_VALUE_MIN = 72,         /* f32 */
    IP_HDR_VALUE_MAX = 76,         /* f32 */
    IP_HDR_BRICK_COUNT = 80,       /* u64 */
    IP_HDR_NODE_COUNT = 88,        /* u64 */
    IP_HDR_DATA_OFFSET = 96,       /* u64 */
    IP_HDR_DATA_SIZE = 104,        /* u64 */
    IP_HDR_SUMMARY_OFFSET = 112,   /* u64 */
    IP_HDR_SUMMARY_SIZE = 120,     /* u64 */
    IP_HDR_SUMMARY_CHECKSUM = 128, /* u64 */
    IP_HDR_FILE_SIZE = 136,        /* u64 */
    IP_HDR_ORIGIN = 144,           /* f64 x 3 (version 2) */
    IP_HDR_DIRECTIONS = 168,       /* f64 x 9: x axis direction, then y, then z (version 2) */
    IP_HDR_SPACE = 240,            /* u32, ip_space (version 2) */
    IP_HDR_RESERVED = 244,         /* zero bytes up to IP_HDR_CHECKSUM */
    IP_HDR_RESERVED_V1 = 144,      /* version 1: zero bytes from here up to IP_HDR_CHECKSUM */
    IP_HDR_CHECKSUM = 248          /* u64, XXH64 of bytes [0, IP_HDR_CHECKSUM) */
};

/* Level table entry (IP_LEVEL_ENTRY_SIZE = 64 bytes) */
enum {
    IP_LVL_DIMS = 0,          /* u32 x 3 */
    IP_LVL_BRICKS = 12,       /* u32 x 3 */
    IP_LVL_FIRST_BRICK = 24,  /* u64 */
    IP_LVL_OCTREE_DEPTH = 32, /* u32 */
    IP_LVL_RESERVED_A = 36,   /* u32, 0 */
    IP_LVL_FIRST_NODE = 40,   /* u64 */
    IP_LVL_VALUE_MIN = 48,    /* f32 */
    IP_LVL_VALUE_MAX = 52,    /* f32 */
    IP_LVL_RESERVED_B = 56    /* u64, 0 */
};

/* Directory entry (IP_DIRECTORY_ENTRY_SIZE = 24 bytes) */
enum {
    IP_DIR_OFFSET = 0,        /* u64 */
    IP_DIR_STORED_SIZE = 8,   /* u32 */
    IP_DIR_ENCODING = 12,     /* u8 */
    IP_DIR_FILTERS = 13,      /* u8 */
    IP_DIR_RESERVED = 14,     /* u8 x 2, 0 */
    IP_DIR_RESERVED_SIZE = 2, /* bytes reserved */
    IP_DIR_CHECKSUM = 16      /* u64 */
};

/* Rescale record (IP_RESCALE_RECORD_SIZE = 64 bytes; version 3, first in the summary) */
enum {
    IP_RSC_SLOPE = 0,          /* f64 */
    IP_RSC_INTERCEPT = 8,      /* f64 */
    IP_RSC_UNIT = 16,          /* IP_RESCALE_UNIT_MAX bytes: printable ASCII, NUL-padded */
    IP_RSC_RESERVED = 32,      /* zero bytes up to IP_RESCALE_RECORD_SIZE */
    IP_RSC_RESERVED_SIZE = 32, /* bytes reserved */
};

/* The version a file without a rescale is written as (3 adds the rescale record). */
#define IP_FORMAT_VERSION_PLAIN 2u

/* Range (IP_RANGE_SIZE = 8 bytes) */
enum {
    IP_RANGE_MIN = 0, /* f32 */
    IP_RANGE_MAX = 4  /* f32 */
};

/* The record sizes (docs/format.md), and each record exactly filled by its fields. */
_Static_assert(IP_HEADER_SIZE == 256, "the header is 256 bytes");
_Static_assert(IP_LEVEL_ENTRY_SIZE == 64, "a level table entry is 64 bytes");
_Static_assert(IP_DIRECTORY_ENTRY_SIZE == 24, "a directory entry is 24 bytes");
_Static_assert(IP_RANGE_SIZE == 8, "a range is 8 bytes");
_Static_assert(IP_SUMMARY_ALIGN == 4096, "the summary starts on a 4096-byte page");
_Static_assert(sizeof(IP_MAGIC) - 1 == IP_HDR_MAGIC_SIZE, "the magic is 8 bytes");

_Static_assert(IP_HDR_MAGIC + IP_HDR_MAGIC_SIZE == IP_HDR_VERSION, "header: magic, version");
_Static_assert(IP_HDR_VERSION + 4 == IP_HDR_HEADER_SIZE, "header: version, header size");
_Static_assert(IP_HDR_HEADER_SIZE + 4 == IP_HDR_DIMS, "header: header size, dims");
_Static_assert(IP_HDR_DIMS + 3 * 4 == IP_HDR_TYPE, "header: dims, type");
_Static_assert(IP_HDR_TYPE + 4 == IP_HDR_SPACING, "header: type, spacing");
_Static_assert(IP_HDR_SPACING + 3 * 8 == IP_HDR_BRICK_EDGE, "header: spacing, B");
_Static_assert(IP_HDR_BRICK_EDGE + 4 == IP_HDR_SUBBLOCK_EDGE, "header: B, s");
_Static_assert(IP_HDR_SUBBLOCK_EDGE + 4 == IP_HDR_LEVEL_COUNT, "header: s, level count");
_Static_assert(IP_HDR_LEVEL_COUNT + 4 == IP_HDR_FLAGS, "header: level count, flags");
_Static_assert(IP_HDR_FLAGS + 4 == IP_HDR_VALUE_MIN, "header: flags, value min");
_Static_assert(IP_HDR_VALUE_MIN + 4 == IP_HDR_VALUE_MAX, "header: value min, max");
_Static_assert(IP_HDR_VALUE_MAX + 4 == IP_HDR_BRICK_COUNT, "header: value max, brick count");
_Static_assert(IP_HDR_BRICK_COUNT + 8 == IP_HDR_NODE_COUNT, "header: brick, node count");
_Static_assert(IP_HDR_NODE_COUNT + 8 == IP_HDR_DATA_OFFSET, "header: node count, data");
_Static_assert(IP_HDR_DATA_OFFSET + 8 == IP_HDR_DATA_SIZE, "header: data offset, size");
_Static_assert(IP_HDR_DATA_SIZE + 8 == IP_HDR_SUMMARY_OFFSET, "header: data, summary");
_Static_assert(IP_HDR_SUMMARY_OFFSET + 8 == IP_HDR_SUMMARY_SIZE, "header: summary offset, size");
_Static_assert(IP_HDR_SUMMARY_SIZE + 8 == IP_HDR_SUMMARY_CHECKSUM, "header: summary checksum");
_Static_assert(IP_HDR_SUMMARY_CHECKSUM + 8 == IP_HDR_FILE_SIZE, "header: file size");
_Static_assert(IP_HDR_FILE_SIZE + 8 == IP_HDR_ORIGIN, "header: file size, origin");
_Static_assert(IP_HDR_ORIGIN + 3 * 8 == IP_HDR_DIRECTIONS, "header: origin, directions");
_Static_assert(IP_HDR_DIRECTIONS + 9 * 8 == IP_HDR_SPACE, "header: directions, space");
_Static_assert(IP_HDR_SPACE + 4 == IP_HDR_RESERVED, "header: space, reserved");
_Static_assert(IP_HDR_RESERVED + 4 == IP_HDR_CHECKSUM, "header: 4 reserved bytes");
_Static_assert(IP_HDR_RESERVED_V1 == IP_HDR_ORIGIN, "header: version 1 reserves from 144");
_Static_assert(IP_HDR_CHECKSUM + 8 == IP_HEADER_SIZE, "header: the checksum ends it");

_Static_assert(IP_LVL_DIMS + 3 * 4 == IP_LVL_BRICKS, "level entry: dims, bricks");
_Static_assert(IP_LVL_BRICKS + 3 * 4 == IP_LVL_FIRST_BRICK, "level entry: bricks, first brick");
_Static_assert(IP_LVL_FIRST_BRICK + 8 == IP_LVL_OCTREE_DEPTH, "level entry: octree depth");
_Static_assert(IP_LVL_OCTREE_DEPTH + 4 == IP_LVL_RESERVED_A, "level entry: reserved u32");
_Static_assert(IP_LVL_RESERVED_A + 4 == IP_LVL_FIRST_NODE, "level entry: first node");
_Static_assert(IP_LVL_FIRST_NODE + 8 == IP_LVL_VALUE_MIN, "level entry: value min");
_Static_assert(IP_LVL_VALUE_MIN + 4 == IP_LVL_VALUE_MAX, "level entry: value max");
_Static_assert(IP_LVL_VALUE_MAX + 4 == IP_LVL_RESERVED_B, "level entry: reserved u64");
_Static_assert(IP_LVL_RESERVED_B + 8 == IP_LEVEL_ENTRY_SIZE, "level entry: 64 bytes");

_Static_assert(IP_DIR_OFFSET + 8 == IP_DIR_STORED_SIZE, "directory entry: offset, size");
_Static_assert(IP_DIR_STORED_SIZE + 4 == IP_DIR_ENCODING, "directory entry: encoding");
_Static_assert(IP_DIR_ENCODING + 1 == IP_DIR_FILTERS, "directory entry: filters");
_Static_assert(IP_DIR_FILTERS + 1 == IP_DIR_RESERVED, "directory entry: reserved");
_Static_assert(IP_DIR_RESERVED + IP_DIR_RESERVED_SIZE == IP_DIR_CHECKSUM,
               "directory entry: checksum");
_Static_assert(IP_DIR_CHECKSUM + 8 == IP_DIRECTORY_ENTRY_SIZE, "directory entry: 24 bytes");

_Static_assert(IP_RESCALE_RECORD_SIZE == 64, "the rescale record is 64 bytes");
_Static_assert(IP_RSC_SLOPE + 8 == IP_RSC_INTERCEPT, "rescale: slope, intercept");
_Static_assert(IP_RSC_INTERCEPT + 8 == IP_RSC_UNIT, "rescale: intercept, unit");
_Static_assert(IP_RSC_UNIT + IP_RESCALE_UNIT_MAX == IP_RSC_RESERVED, "rescale: unit, reserved");
_Static_assert(IP_RSC_RESERVED + IP_RSC_RESERVED_SIZE == IP_RESCALE_RECORD_SIZE,
               "rescale: 64 bytes");
_Static_assert(IP_RESCALE_RECORD_SIZE % 8 == 0, "the level table after it stays 8-aligned");

_Static_assert(IP_RANGE_MAX + 4 == IP_RANGE_SIZE, "range: min, max");

#endif

/* SPDX-License-Identifier: BSD-3-Clause */
/* isoprop internal: the brick file's header and summary section, encoded and parsed.
 *
 * This module computes the layout from the volume's shape (the public part of it is
 * isoprop/layout.h), encodes the header and summary, and parses and validates them from
 * untrusted bytes. It does no I/O.
 */
#ifndef ISOPROP_FORMAT_H
#define ISOPROP_FORMAT_H

#include <stddef.h>
#include <stdint.h>

#include "isoprop/layout.h"
#include "isoprop/status.h"
#include "isoprop/volume.h"

/*! ip__layout_init() : computes levels, brick counts and node counts for a volume of `dims`
 *  samples of `type` with brick edge `brick_edge` and sub-block edge `subblock_edge` (cells).
 *  Leaves offsets, sizes and value ranges zero. @return IP_OK or IP_ERR_ARGUMENT. */
ip_status ip__layout_init(ip_layout *layout, const uint32_t dims[3], ip_type type,
                          const double spacing[3], uint32_t brick_edge, uint32_t subblock_edge,
                          ip_error *err);

/*! ip__layout_summary_size() : bytes of the summary section implied by the layout. */
uint64_t ip__layout_summary_size(const ip_layout *layout);

/*! ip__layout_set_rescale() : gives the layout `rescale` (NULL or one not present: none), the
 *  format version that holds it (3 with a rescale, else IP_FORMAT_VERSION_PLAIN) and the
 *  summary size that version implies. The caller has checked the rescale. */
void ip__layout_set_rescale(ip_layout *layout, const ip_rescale *rescale);

/*! ip__brick_face_neighbours() : the global indices of the bricks of brick `g`'s level that
 *  share a face with it (up to 6: fewer at the level's boundary), into out; @return how many. */
unsigned ip__brick_face_neighbours(const ip_layout *layout, uint64_t g, uint64_t out[6]);

/*! ip__octree_grid() : node grid size of `level` at octree depth `depth` (1..octree_depth):
 *  ceil(bricks / 2^depth). Depth 0 is the brick grid itself. */
void ip__octree_grid(const ip_layout *layout, uint32_t level, uint32_t depth, uint32_t grid[3]);

/*! ip__octree_node_index() : index into the node range array of node `node` at `depth`
 *  (1..octree_depth) of `level`. */
uint64_t ip__octree_node_index(const ip_layout *layout, uint32_t level, uint32_t depth,
                               const uint32_t node[3]);

/*! ip__morton_order() : fills order[0 .. level brick_count) with the level-local brick indices
 *  (x fastest) sorted by the Morton code of their coordinates: the order payloads are stored in.
 *  `order` is owned by the caller. @return IP_OK or IP_ERR_NOMEM. */
ip_status ip__morton_order(const ip_layout *layout, uint32_t level, uint64_t *order);

/* Offsets of the arrays inside the summary section, relative to its start. */
typedef struct ip_summary_offsets {
    uint64_t level_table, directory, brick_ranges, subblock_ranges, nodes, end;
} ip_summary_offsets;

/*! ip__summary_offsets_of() : the derived positions of the summary arrays. */
void ip__summary_offsets_of(const ip_layout *layout, ip_summary_offsets *out);

/*! ip__format_header_encode() : writes the 256-byte header of `layout` (with its checksum) to `out`. */
void ip__format_header_encode(const ip_layout *layout, unsigned char out[IP_HEADER_SIZE]);

/*! ip__format_rescale_encode() : writes the 64-byte rescale record of a version 3 layout. */
void ip__format_rescale_encode(const ip_layout *layout, unsigned char out[IP_RESCALE_RECORD_SIZE]);

/*! ip__format_level_table_encode() : writes level_count * 64 bytes of level table to `out`. */
void ip__format_level_table_encode(const ip_layout *layout, unsigned char *out);

/*! ip__format_entry_encode() / _decode() : one 24-byte directory entry. */
void ip__format_entry_encode(const ip_brick_entry *entry,
                             unsigned char out[IP_DIRECTORY_ENTRY_SIZE]);
void ip__format_entry_decode(const unsigned char in[IP_DIRECTORY_ENTRY_SIZE],
                             ip_brick_entry *entry);

enum {
    IP_PARSE_SKIP_CHECKSUMS = 1 /* for fuzzing the structure checks behind the checksums */
};

/*! ip__format_parse_header() : parses and validates the 256-byte header of a brick file of
 *  `file_size` bytes: magic, version, header checksum, the layout its dims, B and s imply, and
 *  the section offsets against the size. Fills *layout (value ranges of the levels come with
 *  the summary). `name` is used in messages. Safe on arbitrary bytes.
 *  @return IP_OK, IP_ERR_FORMAT, IP_ERR_CHECKSUM or IP_ERR_UNSUPPORTED. */
ip_status ip__format_parse_header(const unsigned char header[IP_HEADER_SIZE], uint64_t file_size,
                                  const char *name, unsigned flags, ip_layout *layout,
                                  ip_error *err);

/*! ip__format_parse_summary() : validates the rest of the metadata of a file whose header
 *  ip__format_parse_header() accepted into *layout: `gap` holds the padding between the data
 *  section and the summary section (summary_offset - data_offset - data_size bytes, which must
 *  be zero), `summary` the summary section (summary_size bytes): its checksum, the level table
 *  against the layout, every directory entry (encodings, sizes, offsets inside the data
 *  section, reserved bytes zero) and every brick range. Sets the levels' value ranges.
 *  Touches no payload byte. Safe on arbitrary bytes.
 *  @return IP_OK, IP_ERR_FORMAT or IP_ERR_CHECKSUM. */
ip_status ip__format_parse_summary(ip_layout *layout, const unsigned char *gap,
                                   const unsigned char *summary, const char *name, unsigned flags,
                                   ip_error *err);

/*! ip__format_check_summary() : ip__format_parse_summary() for a reader that holds only the
 *  start of the summary section, `head` (its bytes up to the sub-block ranges: level table,
 *  directory and brick ranges), and computed the whole section's checksum itself
 *  (ip__format_checksum() of the summary_size bytes, in `checksum`). */
ip_status ip__format_check_summary(ip_layout *layout, const unsigned char *gap,
                                   const unsigned char *head, uint64_t checksum, const char *name,
                                   unsigned flags, ip_error *err);

/*! ip__format_parse() : ip__format_parse_header() then ip__format_parse_summary() on a whole
 *  brick file image (`file`, `size` bytes) held in memory.
 *  @return IP_OK and *layout filled, or IP_ERR_FORMAT / IP_ERR_CHECKSUM / IP_ERR_UNSUPPORTED. */
ip_status ip__format_parse(const unsigned char *file, uint64_t size, const char *name,
                           unsigned flags, ip_layout *layout, ip_error *err);

/*! ip__format_checksum() : XXH64 (seed 0) of `size` bytes, the checksum used throughout. */
uint64_t ip__format_checksum(const void *data, size_t size);

#endif

/* SPDX-License-Identifier: BSD-3-Clause */
/* The brick file layout: derived geometry, header and summary encoding, validation. */
#include <math.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>
#include <xxhash.h>

#include "internal.h"
#include "format.h"
#include "input_source.h"
#include "format_offsets.h"

uint64_t ip__format_checksum(const void *data, size_t size)
{
    return (uint64_t)XXH64(data, size, 0);
}

static int is_power_of_two(uint32_t v)
{
    return v != 0 && (v & (v - 1)) == 0;
}

static uint32_t ceil_div(uint64_t a, uint64_t b)
{
    return (uint32_t)((a + b - 1) / b);
}

uint32_t ip_level_sample_index(uint32_t dim, uint32_t level, uint32_t i)
{
    uint64_t s = (uint64_t)i << level;
    return s < dim - 1 ? (uint32_t)s : dim - 1;
}

static void level_shape(const ip_layout *layout, uint32_t k, ip_level_layout *lv)
{
    uint32_t deepest = 0;
    for (int a = 0; a < 3; a++) {
        uint64_t cells = layout->dims[a] - 1u;
        uint32_t level_cells = (uint32_t)((cells + (1ull << k) - 1) >> k);
        lv->dims[a] = level_cells + 1;
        lv->bricks[a] = ceil_div(level_cells, layout->brick_edge);
        uint32_t depth = ip__ceil_log2(lv->bricks[a]);
        if (depth > deepest)
            deepest = depth;
    }
    lv->brick_count = (uint64_t)lv->bricks[0] * lv->bricks[1] * lv->bricks[2];
    lv->octree_depth = deepest;
    lv->node_count = 0;
    for (uint32_t j = 1; j <= deepest; j++) {
        uint64_t n = 1;
        for (int a = 0; a < 3; a++)
            n *= ceil_div(lv->bricks[a], 1ull << j);
        lv->node_count += n;
    }
}

ip_status ip__layout_init(ip_layout *layout, const uint32_t dims[3], ip_type type,
                          const double spacing[3], uint32_t brick_edge, uint32_t subblock_edge,
                          ip_error *err)
{
    memset(layout, 0, sizeof *layout);
    layout->format_version = IP_FORMAT_VERSION_PLAIN;
    ip_rescale_identity(&layout->rescale);
    for (int a = 0; a < 3; a++) {
        if (dims[a] < 2 || dims[a] >= (1u << 31))
            return ip__fail(err, IP_ERR_ARGUMENT, "dimension %u along %c is outside [2, 2^31)",
                            dims[a], "xyz"[a]);
        if (!(spacing[a] > 0.0) || !isfinite(spacing[a]))
            return ip__fail(err, IP_ERR_ARGUMENT, "spacing %g along %c is not positive", spacing[a],
                            "xyz"[a]);
    }
    if (ip_type_size(type) == 0)
        return ip__fail(err, IP_ERR_ARGUMENT, "unknown sample type %d", (int)type);
    if (!is_power_of_two(brick_edge) || brick_edge < 2 || brick_edge > IP_MAX_BRICK_EDGE)
        return ip__fail(err, IP_ERR_ARGUMENT, "brick edge %u is not a power of two in [2, %u]",
                        brick_edge, IP_MAX_BRICK_EDGE);
    if (!is_power_of_two(subblock_edge) || subblock_edge > brick_edge)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "sub-block edge %u is not a power of two no larger than the brick edge %u",
                        subblock_edge, brick_edge);
    memcpy(layout->dims, dims, sizeof layout->dims);
    memcpy(layout->spacing, spacing, sizeof layout->spacing);
    ip_orientation_identity(&layout->orientation);
    layout->type = type;
    layout->brick_edge = brick_edge;
    layout->subblock_edge = subblock_edge;
    for (uint32_t k = 0;; k++) {
        if (k >= IP_MAX_LEVELS)
            return ip__fail(err, IP_ERR_ARGUMENT, "too many levels");
        ip_level_layout *lv = &layout->levels[k];
        level_shape(layout, k, lv);
        lv->first_brick = layout->brick_count;
        lv->first_node = layout->node_count;
        layout->brick_count += lv->brick_count;
        layout->node_count += lv->node_count;
        layout->level_count = k + 1;
        if (lv->brick_count == 1)
            break;
    }
    layout->data_offset = IP_HEADER_SIZE;
    layout->summary_size = ip__layout_summary_size(layout);
    return IP_OK;
}

uint32_t ip_layout_subblocks_per_brick(const ip_layout *layout)
{
    uint32_t n = layout->brick_edge / layout->subblock_edge;
    return n * n * n;
}

void ip_layout_world_box(const ip_layout *layout, double lo[3], double hi[3])
{
    for (int a = 0; a < 3; a++) {
        lo[a] = 0;
        hi[a] = (layout->dims[a] - 1) * layout->spacing[a];
    }
}

void ip__summary_offsets_of(const ip_layout *layout, ip_summary_offsets *out)
{
    out->level_table = layout->format_version >= 3 ? IP_RESCALE_RECORD_SIZE : 0;
    out->directory = out->level_table + (uint64_t)layout->level_count * IP_LEVEL_ENTRY_SIZE;
    out->brick_ranges = out->directory + layout->brick_count * IP_DIRECTORY_ENTRY_SIZE;
    out->subblock_ranges = out->brick_ranges + layout->brick_count * IP_RANGE_SIZE;
    out->nodes = out->subblock_ranges +
                 layout->brick_count * ip_layout_subblocks_per_brick(layout) * IP_RANGE_SIZE;
    out->end = out->nodes + layout->node_count * IP_RANGE_SIZE;
}

uint64_t ip__layout_summary_size(const ip_layout *layout)
{
    ip_summary_offsets o;
    ip__summary_offsets_of(layout, &o);
    return o.end;
}

void ip__layout_set_rescale(ip_layout *layout, const ip_rescale *rescale)
{
    if (rescale && rescale->present)
        layout->rescale = *rescale;
    else
        ip_rescale_identity(&layout->rescale);
    layout->format_version = layout->rescale.present ? 3u : IP_FORMAT_VERSION_PLAIN;
    layout->summary_size = ip__layout_summary_size(layout);
}

void ip_brick_extent(const ip_layout *layout, uint32_t level, const uint32_t brick[3],
                     uint32_t origin[3], uint32_t extent[3])
{
    const ip_level_layout *lv = &layout->levels[level];
    for (int a = 0; a < 3; a++) {
        uint32_t first = brick[a] * layout->brick_edge;
        uint32_t cells = lv->dims[a] - 1 - first;
        if (cells > layout->brick_edge)
            cells = layout->brick_edge;
        origin[a] = first;
        extent[a] = cells + 1;
    }
}

uint64_t ip_brick_global_index(const ip_layout *layout, uint32_t level, const uint32_t brick[3])
{
    const ip_level_layout *lv = &layout->levels[level];
    return lv->first_brick + brick[0] +
           (uint64_t)lv->bricks[0] * (brick[1] + (uint64_t)lv->bricks[1] * brick[2]);
}

void ip_brick_coords(const ip_layout *layout, uint64_t global, uint32_t *level, uint32_t brick[3])
{
    uint32_t k = 0;
    while (k + 1 < layout->level_count && global >= layout->levels[k + 1].first_brick)
        k++;
    const ip_level_layout *lv = &layout->levels[k];
    uint64_t local = global - lv->first_brick;
    *level = k;
    brick[0] = (uint32_t)(local % lv->bricks[0]);
    local /= lv->bricks[0];
    brick[1] = (uint32_t)(local % lv->bricks[1]);
    brick[2] = (uint32_t)(local / lv->bricks[1]);
}

unsigned ip__brick_face_neighbours(const ip_layout *layout, uint64_t g, uint64_t out[6])
{
    uint32_t level, b[3];
    unsigned count = 0;
    ip_brick_coords(layout, g, &level, b);
    const uint32_t *grid = layout->levels[level].bricks;
    for (int f = 0; f < 6; f++) {
        uint32_t n[3] = {b[0], b[1], b[2]};
        int axis = f / 2;
        if (f % 2 == 0 ? n[axis] == 0 : n[axis] + 1 >= grid[axis])
            continue;
        n[axis] += f % 2 == 0 ? (uint32_t)-1 : 1u;
        out[count++] = ip_brick_global_index(layout, level, n);
    }
    return count;
}

void ip__octree_grid(const ip_layout *layout, uint32_t level, uint32_t depth, uint32_t grid[3])
{
    IP_ASSERT(level < layout->level_count && depth < 32);
    for (int a = 0; a < 3; a++)
        grid[a] = ceil_div(layout->levels[level].bricks[a], 1ull << depth);
}

uint64_t ip__octree_node_index(const ip_layout *layout, uint32_t level, uint32_t depth,
                               const uint32_t node[3])
{
    IP_ASSERT(level < layout->level_count);
    IP_ASSERT(depth >= 1 && depth <= layout->levels[level].octree_depth);
    uint64_t index = layout->levels[level].first_node;
    uint32_t grid[3];
    for (uint32_t j = 1; j < depth; j++) {
        ip__octree_grid(layout, level, j, grid);
        index += (uint64_t)grid[0] * grid[1] * grid[2];
    }
    ip__octree_grid(layout, level, depth, grid);
    IP_ASSERT(node[0] < grid[0] && node[1] < grid[1] && node[2] < grid[2]);
    return index + node[0] + (uint64_t)grid[0] * (node[1] + (uint64_t)grid[1] * node[2]);
}

static uint64_t spread_bits(uint32_t v)
{
    uint64_t x = v & 0x1fffff;
    x = (x | x << 32) & 0x1f00000000ffffull;
    x = (x | x << 16) & 0x1f0000ff0000ffull;
    x = (x | x << 8) & 0x100f00f00f00f00full;
    x = (x | x << 4) & 0x10c30c30c30c30c3ull;
    x = (x | x << 2) & 0x1249249249249249ull;
    return x;
}

typedef struct morton_key {
    uint64_t code;
    uint64_t index;
} morton_key;

static int compare_morton(const void *a, const void *b)
{
    const morton_key *x = a, *y = b;
    return (x->code > y->code) - (x->code < y->code);
}

ip_status ip__morton_order(const ip_layout *layout, uint32_t level, uint64_t *order)
{
    IP_ASSERT(level < layout->level_count && order != NULL);
    const ip_level_layout *lv = &layout->levels[level];
    morton_key *keys = malloc(lv->brick_count * sizeof *keys);
    if (!keys)
        return IP_ERR_NOMEM;
    uint64_t i = 0;
    for (uint32_t z = 0; z < lv->bricks[2]; z++)
        for (uint32_t y = 0; y < lv->bricks[1]; y++)
            for (uint32_t x = 0; x < lv->bricks[0]; x++, i++) {
                keys[i].code = spread_bits(x) | spread_bits(y) << 1 | spread_bits(z) << 2;
                keys[i].index = i;
            }
    qsort(keys, lv->brick_count, sizeof *keys, compare_morton);
    for (i = 0; i < lv->brick_count; i++)
        order[i] = keys[i].index;
    free(keys);
    return IP_OK;
}

/* ---- encoding ---- */

void ip__format_header_encode(const ip_layout *layout, unsigned char out[IP_HEADER_SIZE])
{
    memset(out, 0, IP_HEADER_SIZE);
    memcpy(out + IP_HDR_MAGIC, IP_MAGIC, IP_HDR_MAGIC_SIZE);
    ip__store_u32le(out + IP_HDR_VERSION, layout->format_version);
    ip__store_u32le(out + IP_HDR_HEADER_SIZE, IP_HEADER_SIZE);
    for (int a = 0; a < 3; a++) {
        ip__store_u32le(out + IP_HDR_DIMS + 4 * a, layout->dims[a]);
        ip__store_f64le(out + IP_HDR_SPACING + 8 * a, layout->spacing[a]);
    }
    ip__store_u32le(out + IP_HDR_TYPE, (uint32_t)layout->type);
    ip__store_u32le(out + IP_HDR_BRICK_EDGE, layout->brick_edge);
    ip__store_u32le(out + IP_HDR_SUBBLOCK_EDGE, layout->subblock_edge);
    ip__store_u32le(out + IP_HDR_LEVEL_COUNT, layout->level_count);
    ip__store_u32le(out + IP_HDR_FLAGS, 0);
    ip__store_f32le(out + IP_HDR_VALUE_MIN, layout->value_min);
    ip__store_f32le(out + IP_HDR_VALUE_MAX, layout->value_max);
    ip__store_u64le(out + IP_HDR_BRICK_COUNT, layout->brick_count);
    ip__store_u64le(out + IP_HDR_NODE_COUNT, layout->node_count);
    ip__store_u64le(out + IP_HDR_DATA_OFFSET, layout->data_offset);
    ip__store_u64le(out + IP_HDR_DATA_SIZE, layout->data_size);
    ip__store_u64le(out + IP_HDR_SUMMARY_OFFSET, layout->summary_offset);
    ip__store_u64le(out + IP_HDR_SUMMARY_SIZE, layout->summary_size);
    ip__store_u64le(out + IP_HDR_SUMMARY_CHECKSUM, layout->summary_checksum);
    ip__store_u64le(out + IP_HDR_FILE_SIZE, layout->file_size);
    const ip_orientation *o = &layout->orientation;
    for (int a = 0; a < 3; a++) {
        ip__store_f64le(out + IP_HDR_ORIGIN + 8 * a, o->origin[a]);
        for (int c = 0; c < 3; c++)
            ip__store_f64le(out + IP_HDR_DIRECTIONS + 8 * (3 * a + c), o->directions[a][c]);
    }
    ip__store_u32le(out + IP_HDR_SPACE, (uint32_t)o->space);
    ip__store_u64le(out + IP_HDR_CHECKSUM, ip__format_checksum(out, IP_HDR_CHECKSUM));
}

void ip__format_rescale_encode(const ip_layout *layout, unsigned char out[IP_RESCALE_RECORD_SIZE])
{
    IP_ASSERT(layout->format_version >= 3 && layout->rescale.present);
    memset(out, 0, IP_RESCALE_RECORD_SIZE);
    ip__store_f64le(out + IP_RSC_SLOPE, layout->rescale.slope);
    ip__store_f64le(out + IP_RSC_INTERCEPT, layout->rescale.intercept);
    memcpy(out + IP_RSC_UNIT, layout->rescale.unit,
           strnlen(layout->rescale.unit, IP_RESCALE_UNIT_MAX));
}

void ip__format_level_table_encode(const ip_layout *layout, unsigned char *out)
{
    IP_ASSERT(layout->level_count >= 1 && layout->level_count <= IP_MAX_LEVELS);
    for (uint32_t k = 0; k < layout->level_count; k++) {
        const ip_level_layout *lv = &layout->levels[k];
        unsigned char *e = out + (size_t)k * IP_LEVEL_ENTRY_SIZE;
        memset(e, 0, IP_LEVEL_ENTRY_SIZE);
        for (int a = 0; a < 3; a++) {
            ip__store_u32le(e + IP_LVL_DIMS + 4 * a, lv->dims[a]);
            ip__store_u32le(e + IP_LVL_BRICKS + 4 * a, lv->bricks[a]);
        }
        ip__store_u64le(e + IP_LVL_FIRST_BRICK, lv->first_brick);
        ip__store_u32le(e + IP_LVL_OCTREE_DEPTH, lv->octree_depth);
        ip__store_u64le(e + IP_LVL_FIRST_NODE, lv->first_node);
        ip__store_f32le(e + IP_LVL_VALUE_MIN, lv->value_min);
        ip__store_f32le(e + IP_LVL_VALUE_MAX, lv->value_max);
    }
}

void ip__format_entry_encode(const ip_brick_entry *entry,
                             unsigned char out[IP_DIRECTORY_ENTRY_SIZE])
{
    IP_ASSERT(entry->encoding <= IP_BRICK_LZ4);
    IP_ASSERT(entry->encoding == IP_BRICK_LZ4 || entry->filters == 0);
    ip__store_u64le(out + IP_DIR_OFFSET, entry->offset);
    ip__store_u32le(out + IP_DIR_STORED_SIZE, entry->stored_size);
    out[IP_DIR_ENCODING] = entry->encoding;
    out[IP_DIR_FILTERS] = entry->filters;
    memset(out + IP_DIR_RESERVED, 0, IP_DIR_RESERVED_SIZE);
    ip__store_u64le(out + IP_DIR_CHECKSUM, entry->checksum);
}

void ip__format_entry_decode(const unsigned char in[IP_DIRECTORY_ENTRY_SIZE], ip_brick_entry *entry)
{
    entry->offset = ip__load_u64le(in + IP_DIR_OFFSET);
    entry->stored_size = ip__load_u32le(in + IP_DIR_STORED_SIZE);
    entry->encoding = in[IP_DIR_ENCODING];
    entry->filters = in[IP_DIR_FILTERS];
    entry->checksum = ip__load_u64le(in + IP_DIR_CHECKSUM);
}

/* ---- parsing ---- */

/* Version 2's origin, directions and space; version 1 has none (identity) and its bytes are
 * reserved. The reserved bytes that remain are zero either way. */
static ip_status parse_orientation(const unsigned char *h, uint32_t version, const char *name,
                                   ip_layout *layout, ip_error *err)
{
    int reserved_from = version == 1 ? IP_HDR_RESERVED_V1 : IP_HDR_RESERVED;
    for (int i = reserved_from; i < IP_HDR_CHECKSUM; i++)
        if (h[i] != 0)
            return ip__fail(err, IP_ERR_FORMAT, "%s: reserved header byte %d is not zero", name, i);
    ip_orientation *o = &layout->orientation;
    ip_orientation_identity(o);
    if (version == 1)
        return IP_OK;
    for (int a = 0; a < 3; a++) {
        o->origin[a] = ip__load_f64le(h + IP_HDR_ORIGIN + 8 * a);
        for (int c = 0; c < 3; c++)
            o->directions[a][c] = ip__load_f64le(h + IP_HDR_DIRECTIONS + 8 * (3 * a + c));
    }
    uint32_t space = ip__load_u32le(h + IP_HDR_SPACE);
    if (space > IP_SPACE_LPS)
        return ip__fail(err, IP_ERR_FORMAT, "%s: unknown space %u", name, space);
    o->space = (ip_space)space;
    ip_error why;
    if (ip_orientation_check(o, NULL, &why) != IP_OK)
        return ip__fail(err, IP_ERR_FORMAT, "%s: %s", name, why.message);
    return IP_OK;
}

/* What a file that is not a brick file holds, when it is one of the volumes the bricker reads
 * (by its first `size` bytes and its name), or NULL: for a message that says to brick it. */
static const char *volume_kind(const unsigned char *h, size_t size, const char *name)
{
    if (size >= 132 && memcmp(h + 128, "DICM", 4) == 0)
        return "a DICOM file";
    if (size >= 4 && (memcmp(h, "II*", 4) == 0 || memcmp(h, "MM\0*", 4) == 0 ||
                      memcmp(h, "II+", 4) == 0 || memcmp(h, "MM\0+", 4) == 0))
        return "a TIFF file";
    if (size >= 4 && memcmp(h, "NRRD", 4) == 0)
        return "an NRRD volume";
    if (size >= 4 && (ip__load_u32le(h) == 348 || ip__load_u32le(h) == 540 ||
                      ip__load_u32le(h) == 0x5c010000u || ip__load_u32le(h) == 0x1c020000u))
        return "a NIfTI volume";
    return ip__input_format_named(name); /* else by its name */
}

/* Fails for a file that is not a brick file: saying to brick it first when it is a volume. */
static ip_status not_a_brick_file(const unsigned char *h, size_t size, const char *name,
                                  const char *why, ip_error *err)
{
    const char *kind = volume_kind(h, size, name);
    if (kind)
        return ip__fail(err, IP_ERR_FORMAT,
                        "%s: %s, not a brick file: brick it first (isobrick %s)", name, kind, name);
    return ip__fail(err, IP_ERR_FORMAT, "%s: %s", name, why);
}

static ip_status parse_header(const unsigned char *h, const char *name, unsigned flags,
                              ip_layout *layout, ip_error *err)
{
    if (memcmp(h + IP_HDR_MAGIC, IP_MAGIC, IP_HDR_MAGIC_SIZE) != 0)
        return not_a_brick_file(h, IP_HEADER_SIZE, name, "not a brick file (bad magic)", err);
    uint32_t version = ip__load_u32le(h + IP_HDR_VERSION);
    if (version < 1 || version > IP_FORMAT_VERSION)
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "%s: format version %u is not supported (this "
                        "build reads versions 1 to %u)",
                        name, version, IP_FORMAT_VERSION);
    if (ip__load_u32le(h + IP_HDR_HEADER_SIZE) != IP_HEADER_SIZE)
        return ip__fail(err, IP_ERR_FORMAT, "%s: header size %u is not %u", name,
                        ip__load_u32le(h + IP_HDR_HEADER_SIZE), IP_HEADER_SIZE);
    if (!(flags & IP_PARSE_SKIP_CHECKSUMS) &&
        ip__load_u64le(h + IP_HDR_CHECKSUM) != ip__format_checksum(h, IP_HDR_CHECKSUM))
        return ip__fail(err, IP_ERR_CHECKSUM, "%s: header checksum mismatch", name);
    uint32_t dims[3];
    double spacing[3];
    for (int a = 0; a < 3; a++) {
        dims[a] = ip__load_u32le(h + IP_HDR_DIMS + 4 * a);
        spacing[a] = ip__load_f64le(h + IP_HDR_SPACING + 8 * a);
    }
    uint32_t type = ip__load_u32le(h + IP_HDR_TYPE);
    if (type >= IP_TYPE_COUNT)
        return ip__fail(err, IP_ERR_FORMAT, "%s: unknown sample type %u", name, type);
    if (ip__load_u32le(h + IP_HDR_FLAGS) != 0)
        return ip__fail(err, IP_ERR_UNSUPPORTED, "%s: unknown header flags 0x%x", name,
                        ip__load_u32le(h + IP_HDR_FLAGS));
    ip_error why;
    if (ip__layout_init(layout, dims, (ip_type)type, spacing, ip__load_u32le(h + IP_HDR_BRICK_EDGE),
                        ip__load_u32le(h + IP_HDR_SUBBLOCK_EDGE), &why) != IP_OK)
        return ip__fail(err, IP_ERR_FORMAT, "%s: %s", name, why.message);
    /* a spacing nothing downstream renders correctly (a file from before the bounds, or a
     * hostile one): refused here, so that no reader of the library reaches the engine with it */
    ip_status st = ip_spacing_check(spacing, name, err);
    if (st != IP_OK)
        return st;
    layout->format_version = version;
    layout->summary_size = ip__layout_summary_size(layout); /* version 3's holds the rescale */
    if ((st = parse_orientation(h, version, name, layout, err)) != IP_OK)
        return st;
    if (ip__load_u32le(h + IP_HDR_LEVEL_COUNT) != layout->level_count ||
        ip__load_u64le(h + IP_HDR_BRICK_COUNT) != layout->brick_count ||
        ip__load_u64le(h + IP_HDR_NODE_COUNT) != layout->node_count)
        return ip__fail(err, IP_ERR_FORMAT,
                        "%s: level, brick or node counts disagree with the dimensions", name);
    layout->value_min = ip__load_f32le(h + IP_HDR_VALUE_MIN);
    layout->value_max = ip__load_f32le(h + IP_HDR_VALUE_MAX);
    layout->data_offset = ip__load_u64le(h + IP_HDR_DATA_OFFSET);
    layout->data_size = ip__load_u64le(h + IP_HDR_DATA_SIZE);
    layout->summary_offset = ip__load_u64le(h + IP_HDR_SUMMARY_OFFSET);
    layout->summary_checksum = ip__load_u64le(h + IP_HDR_SUMMARY_CHECKSUM);
    layout->file_size = ip__load_u64le(h + IP_HDR_FILE_SIZE);
    if (ip__load_u64le(h + IP_HDR_SUMMARY_SIZE) != layout->summary_size)
        return ip__fail(err, IP_ERR_FORMAT, "%s: summary size %llu is not the expected %llu", name,
                        (unsigned long long)ip__load_u64le(h + IP_HDR_SUMMARY_SIZE),
                        (unsigned long long)layout->summary_size);
    return IP_OK;
}

static ip_status check_sections(const ip_layout *l, uint64_t size, const char *name, ip_error *err)
{
    if (l->file_size != size)
        return ip__fail(err, IP_ERR_FORMAT,
                        "%s: file is %llu bytes but its header says %llu "
                        "(truncated or extended)",
                        name, (unsigned long long)size, (unsigned long long)l->file_size);
    if (l->data_offset != IP_HEADER_SIZE || l->data_size > size ||
        l->summary_offset % IP_SUMMARY_ALIGN != 0 ||
        l->summary_offset < l->data_offset + l->data_size ||
        l->summary_offset - (l->data_offset + l->data_size) >= IP_SUMMARY_ALIGN ||
        l->summary_offset > size || size - l->summary_offset != l->summary_size)
        return ip__fail(err, IP_ERR_FORMAT, "%s: section offsets are inconsistent", name);
    return IP_OK;
}

/* Version 3's rescale record, first in the summary section: a valid rescale, its unit
 * NUL-padded, its reserved bytes zero. */
static ip_status parse_rescale(const unsigned char *r, const char *name, ip_layout *layout,
                               ip_error *err)
{
    ip_rescale *out = &layout->rescale;
    ip_rescale_identity(out);
    if (layout->format_version < 3)
        return IP_OK;
    for (int i = 0; i < IP_RSC_RESERVED_SIZE; i++)
        if (r[IP_RSC_RESERVED + i] != 0)
            return ip__fail(err, IP_ERR_FORMAT, "%s: reserved byte %d of the rescale is not zero",
                            name, IP_RSC_RESERVED + i);
    const unsigned char *unit = r + IP_RSC_UNIT;
    size_t n = 0;
    while (n < IP_RESCALE_UNIT_MAX && unit[n] != 0)
        n++;
    for (size_t i = n; i < IP_RESCALE_UNIT_MAX; i++)
        if (unit[i] != 0)
            return ip__fail(err, IP_ERR_FORMAT, "%s: the rescale's unit is not NUL-padded", name);
    ip_rescale found = {1, ip__load_f64le(r + IP_RSC_SLOPE), ip__load_f64le(r + IP_RSC_INTERCEPT),
                        ""};
    if (n == IP_RESCALE_UNIT_MAX)
        return ip__fail(err, IP_ERR_FORMAT, "%s: the rescale's unit is not NUL-terminated", name);
    memcpy(found.unit, unit, n);
    ip_error why;
    if (ip_rescale_check(&found, NULL, &why) != IP_OK)
        return ip__fail(err, IP_ERR_FORMAT, "%s: %s", name, why.message);
    *out = found;
    return IP_OK;
}

static int range_ok(float lo, float hi)
{
    return isfinite(lo) && isfinite(hi) && lo <= hi;
}

static ip_status check_level_table(const ip_layout *l, const unsigned char *table, const char *name,
                                   ip_layout *out, ip_error *err)
{
    for (uint32_t k = 0; k < l->level_count; k++) {
        const unsigned char *e = table + (size_t)k * IP_LEVEL_ENTRY_SIZE;
        const ip_level_layout *lv = &l->levels[k];
        int same = ip__load_u64le(e + IP_LVL_FIRST_BRICK) == lv->first_brick &&
                   ip__load_u32le(e + IP_LVL_OCTREE_DEPTH) == lv->octree_depth &&
                   ip__load_u64le(e + IP_LVL_FIRST_NODE) == lv->first_node &&
                   ip__load_u32le(e + IP_LVL_RESERVED_A) == 0 &&
                   ip__load_u64le(e + IP_LVL_RESERVED_B) == 0;
        for (int a = 0; a < 3; a++)
            same = same && ip__load_u32le(e + IP_LVL_DIMS + 4 * a) == lv->dims[a] &&
                   ip__load_u32le(e + IP_LVL_BRICKS + 4 * a) == lv->bricks[a];
        if (!same)
            return ip__fail(err, IP_ERR_FORMAT,
                            "%s: level %u of the level table disagrees with "
                            "the header",
                            name, k);
        out->levels[k].value_min = ip__load_f32le(e + IP_LVL_VALUE_MIN);
        out->levels[k].value_max = ip__load_f32le(e + IP_LVL_VALUE_MAX);
        if (!range_ok(out->levels[k].value_min, out->levels[k].value_max))
            return ip__fail(err, IP_ERR_FORMAT, "%s: level %u has an invalid value range", name, k);
    }
    if (!range_ok(l->value_min, l->value_max) || l->value_min != out->levels[0].value_min ||
        l->value_max != out->levels[0].value_max)
        return ip__fail(err, IP_ERR_FORMAT, "%s: the value range is invalid", name);
    return IP_OK;
}

/* `reserved`: the entry's reserved bytes or'ed together. */
static ip_status check_entry(const ip_layout *l, uint64_t g, const ip_brick_entry *e,
                             unsigned reserved, float lo, float hi, const char *name, ip_error *err)
{
    uint32_t level, brick[3], origin[3], extent[3];
    ip_brick_coords(l, g, &level, brick);
    ip_brick_extent(l, level, brick, origin, extent);
    uint64_t raw = (uint64_t)extent[0] * extent[1] * extent[2] * ip_type_size(l->type);
    const char *why = NULL;
    if (!range_ok(lo, hi))
        why = "an invalid value range";
    else if (reserved)
        why = "non-zero reserved bytes";
    else if (e->encoding == IP_BRICK_CONSTANT) {
        if (e->stored_size != 0 || e->filters != 0 || e->checksum != 0 || lo != hi)
            why = "an inconsistent constant entry";
        else if (!ip_type_holds(l->type, lo))
            why = "a constant value its sample type cannot hold";
    } else if (e->encoding == IP_BRICK_RAW) {
        if (e->stored_size != raw || e->filters != 0)
            why = "a raw payload of the wrong size";
    } else if (e->encoding == IP_BRICK_LZ4) {
        if (e->stored_size == 0 || e->stored_size > raw + raw / 255 + 16 || (e->filters & ~7u) ||
            (e->filters & 5u) == 5u)
            why = "an LZ4 payload of impossible size or unknown filters";
    } else
        why = "an unknown encoding";
    if (!why && e->stored_size != 0 &&
        (e->offset < l->data_offset || e->offset > l->data_offset + l->data_size ||
         e->stored_size > l->data_offset + l->data_size - e->offset))
        why = "a payload outside the data section";
    if (why)
        return ip__fail(err, IP_ERR_FORMAT, "%s: brick %llu (level %u, %u,%u,%u) has %s", name,
                        (unsigned long long)g, level, brick[0], brick[1], brick[2], why);
    return IP_OK;
}

ip_status ip__format_parse_header(const unsigned char header[IP_HEADER_SIZE], uint64_t file_size,
                                  const char *name, unsigned flags, ip_layout *layout,
                                  ip_error *err)
{
    if (file_size < IP_HEADER_SIZE) {
        char why[96];
        snprintf(why, sizeof why, "%llu bytes is too short for a brick file",
                 (unsigned long long)file_size);
        return not_a_brick_file(header, (size_t)file_size, name, why, err);
    }
    ip_status st = parse_header(header, name, flags, layout, err);
    return st == IP_OK ? check_sections(layout, file_size, name, err) : st;
}

ip_status ip__format_check_summary(ip_layout *layout, const unsigned char *gap,
                                   const unsigned char *head, uint64_t checksum, const char *name,
                                   unsigned flags, ip_error *err)
{
    uint64_t gap_size = layout->summary_offset - (layout->data_offset + layout->data_size);
    for (uint64_t i = 0; i < gap_size; i++)
        if (gap[i] != 0)
            return ip__fail(err, IP_ERR_FORMAT,
                            "%s: byte %llu, in the padding before the "
                            "summary section, is not zero",
                            name,
                            (unsigned long long)(layout->data_offset + layout->data_size + i));
    if (!(flags & IP_PARSE_SKIP_CHECKSUMS) && checksum != layout->summary_checksum)
        return ip__fail(err, IP_ERR_CHECKSUM, "%s: summary section checksum mismatch", name);
    ip_summary_offsets o;
    ip__summary_offsets_of(layout, &o);
    ip_status st = parse_rescale(head, name, layout, err);
    if (st == IP_OK)
        st = check_level_table(layout, head + o.level_table, name, layout, err);
    if (st != IP_OK)
        return st;
    for (uint64_t g = 0; g < layout->brick_count; g++) {
        const unsigned char *d = head + o.directory + g * IP_DIRECTORY_ENTRY_SIZE;
        const unsigned char *r = head + o.brick_ranges + g * IP_RANGE_SIZE;
        ip_brick_entry e;
        ip__format_entry_decode(d, &e);
        st = check_entry(layout, g, &e, d[IP_DIR_RESERVED] | d[IP_DIR_RESERVED + 1],
                         ip__load_f32le(r + IP_RANGE_MIN), ip__load_f32le(r + IP_RANGE_MAX), name,
                         err);
        if (st != IP_OK)
            return st;
    }
    return IP_OK;
}

ip_status ip__format_parse_summary(ip_layout *layout, const unsigned char *gap,
                                   const unsigned char *summary, const char *name, unsigned flags,
                                   ip_error *err)
{
    uint64_t checksum = flags & IP_PARSE_SKIP_CHECKSUMS
                            ? layout->summary_checksum
                            : ip__format_checksum(summary, layout->summary_size);
    return ip__format_check_summary(layout, gap, summary, checksum, name, flags, err);
}

ip_status ip__format_parse(const unsigned char *file, uint64_t size, const char *name,
                           unsigned flags, ip_layout *layout, ip_error *err)
{
    ip_status st = ip__format_parse_header(file, size, name, flags, layout, err);
    if (st != IP_OK)
        return st;
    return ip__format_parse_summary(layout, file + layout->data_offset + layout->data_size,
                                    file + layout->summary_offset, name, flags, err);
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* The brick file format (src/brickfile/format.c) on its own, in memory: the layout derived from
 * odd dimensions and brick edges against the formulas of docs/format.md, brick coordinates and
 * extents, the octree numbering, the Morton order, header and directory entry round trips
 * through the named offsets (format_offsets.h), and every validation of the parser: each
 * header field, reserved byte, level table field and directory entry field made wrong on its
 * own (the checksums resealed, so that the check behind them is the one reached) is refused
 * with its code and a message naming the file. Version 3's rescale record round trips and is
 * validated alike, and files of versions 1 and 2 (no rescale) still read, with none. */
#include <math.h>

#include "check.h"
#include "format.h"
#include "format_offsets.h"
#include "internal.h"

#define NAME "memory.ibv"

static uint32_t ceil_div_u64(uint64_t a, uint64_t b)
{
    return (uint32_t)((a + b - 1) / b);
}

/* The layout of docs/format.md "Levels", "Bricks" and "Octree nodes", computed again here. */
static void check_layout_against_spec(const uint32_t dims[3], uint32_t B, uint32_t s)
{
    const double spacing[3] = {1, 2, 0.5};
    ip_layout l;
    ip_error err;
    char what[96];
    snprintf(what, sizeof what, "%ux%ux%u B=%u s=%u", dims[0], dims[1], dims[2], B, s);
    REQUIRE(ip__layout_init(&l, dims, IP_INT16, spacing, B, s, &err) == IP_OK);
    uint64_t bricks_total = 0, nodes_total = 0;
    uint32_t k = 0;
    for (;; k++) {
        REQUIRE(k < IP_MAX_LEVELS);
        uint64_t bricks = 1;
        uint32_t depth = 0;
        for (int a = 0; a < 3; a++) {
            uint32_t n = ceil_div_u64(dims[a] - 1, 1ull << k) + 1;
            uint32_t nb = ceil_div_u64(n - 1, B);
            CHECK_MSG(l.levels[k].dims[a] == n, "%s: level %u dims[%d] %u, wanted %u", what, k, a,
                      l.levels[k].dims[a], n);
            CHECK_MSG(l.levels[k].bricks[a] == nb, "%s: level %u bricks[%d]", what, k, a);
            bricks *= nb;
            uint32_t d = 0;
            while ((1u << d) < nb)
                d++;
            if (d > depth)
                depth = d;
        }
        uint64_t nodes = 0;
        for (uint32_t j = 1; j <= depth; j++) {
            uint64_t n = 1;
            for (int a = 0; a < 3; a++)
                n *= ceil_div_u64(l.levels[k].bricks[a], 1ull << j);
            nodes += n;
        }
        CHECK_MSG(l.levels[k].brick_count == bricks, "%s: level %u brick count", what, k);
        CHECK_MSG(l.levels[k].first_brick == bricks_total, "%s: level %u first brick", what, k);
        CHECK_MSG(l.levels[k].octree_depth == depth, "%s: level %u depth", what, k);
        CHECK_MSG(l.levels[k].node_count == nodes, "%s: level %u nodes", what, k);
        CHECK_MSG(l.levels[k].first_node == nodes_total, "%s: level %u first node", what, k);
        bricks_total += bricks;
        nodes_total += nodes;
        if (bricks == 1)
            break;
    }
    CHECK_MSG(l.level_count == k + 1, "%s: %u levels, wanted %u", what, l.level_count, k + 1);
    CHECK_EQ(l.brick_count, bricks_total);
    CHECK_EQ(l.node_count, nodes_total);
    CHECK_EQ(l.data_offset, IP_HEADER_SIZE);
    uint64_t P = B / s;
    CHECK_MSG(l.summary_size ==
                  l.level_count * 64ull + bricks_total * (24 + 8 + 8 * P * P * P) + nodes_total * 8,
              "%s: summary size", what);
    CHECK_EQ(ip_layout_subblocks_per_brick(&l), P * P * P);

    /* every brick: coordinates and global index agree, extents tile the level's cells */
    for (uint32_t lv = 0; lv < l.level_count; lv++) {
        uint64_t cells_x = 0;
        for (uint32_t bx = 0; bx < l.levels[lv].bricks[0]; bx++) {
            uint32_t b[3] = {bx, l.levels[lv].bricks[1] - 1, 0}, o[3], ext[3];
            ip_brick_extent(&l, lv, b, o, ext);
            CHECK_EQ(o[0], bx * B);
            CHECK_GE(ext[0], 2);
            CHECK_LE(ext[0], B + 1);
            cells_x += ext[0] - 1;
        }
        CHECK_MSG(cells_x == l.levels[lv].dims[0] - 1, "%s: level %u bricks cover x", what, lv);
    }
    for (uint64_t g = 0; g < l.brick_count; g++) {
        uint32_t level, b[3];
        ip_brick_coords(&l, g, &level, b);
        CHECK_MSG(ip_brick_global_index(&l, level, b) == g, "%s: brick %llu", what,
                  (unsigned long long)g);
    }
    /* octree nodes: depth by depth, each level's nodes numbered exactly once */
    for (uint32_t lv = 0; lv < l.level_count; lv++) {
        const ip_level_layout *L = &l.levels[lv];
        uint64_t expect = L->first_node;
        for (uint32_t j = 1; j <= L->octree_depth; j++) {
            uint32_t grid[3];
            ip__octree_grid(&l, lv, j, grid);
            for (int a = 0; a < 3; a++)
                CHECK_EQ(grid[a], ceil_div_u64(L->bricks[a], 1ull << j));
            for (uint32_t z = 0; z < grid[2]; z++)
                for (uint32_t y = 0; y < grid[1]; y++)
                    for (uint32_t x = 0; x < grid[0]; x++) {
                        uint32_t node[3] = {x, y, z};
                        CHECK_EQ(ip__octree_node_index(&l, lv, j, node), expect);
                        expect++;
                    }
            if (j == L->octree_depth) {
                CHECK_EQ(grid[0], 1);
                CHECK_EQ(grid[1], 1);
                CHECK_EQ(grid[2], 1);
            }
        }
        CHECK_MSG(expect == L->first_node + L->node_count, "%s: level %u node numbering", what, lv);
        /* Morton order: a permutation, by increasing interleaved code */
        uint64_t *order = malloc(L->brick_count * sizeof *order);
        char *seen = calloc(L->brick_count, 1);
        REQUIRE(order && seen && ip__morton_order(&l, lv, order) == IP_OK);
        uint64_t last = 0;
        int ok = 1;
        for (uint64_t i = 0; i < L->brick_count; i++) {
            uint64_t idx = order[i];
            ok &= idx < L->brick_count && !seen[idx];
            if (idx >= L->brick_count)
                break;
            seen[idx] = 1;
            uint32_t c[3] = {(uint32_t)(idx % L->bricks[0]),
                             (uint32_t)(idx / L->bricks[0] % L->bricks[1]),
                             (uint32_t)(idx / L->bricks[0] / L->bricks[1])};
            uint64_t code = 0;
            for (int bit = 0; bit < 21; bit++)
                for (int a = 0; a < 3; a++)
                    code |= (uint64_t)((c[a] >> bit) & 1) << (3 * bit + a);
            ok &= i == 0 || code > last;
            last = code;
        }
        CHECK_MSG(ok, "%s: level %u Morton order", what, lv);
        free(order);
        free(seen);
    }
}

static void test_layouts(void)
{
    static const uint32_t shapes[][3] = {{2, 2, 2},   {3, 2, 2},  {21, 18, 19},  {33, 33, 33},
                                         {100, 7, 2}, {65, 2, 9}, {257, 3, 130}, {5, 300, 17}};
    static const uint32_t edges[][2] = {{2, 1}, {2, 2}, {4, 2}, {8, 8}, {16, 4}, {32, 8}};
    for (size_t i = 0; i < sizeof shapes / sizeof shapes[0]; i++)
        for (size_t j = 0; j < sizeof edges / sizeof edges[0]; j++)
            check_layout_against_spec(shapes[i], edges[j][0], edges[j][1]);

    /* the smallest volume: one level, one brick, no nodes */
    ip_layout l;
    ip_error err;
    const uint32_t two[3] = {2, 2, 2};
    const double one[3] = {1, 1, 1};
    REQUIRE(ip__layout_init(&l, two, IP_UINT8, one, 32, 8, &err) == IP_OK);
    CHECK_EQ(l.level_count, 1);
    CHECK_EQ(l.brick_count, 1);
    CHECK_EQ(l.node_count, 0);
    uint32_t b[3] = {0, 0, 0}, o[3], e[3];
    ip_brick_extent(&l, 0, b, o, e);
    CHECK_EQ(e[0], 2);
    CHECK_EQ(e[1], 2);
    CHECK_EQ(e[2], 2);
}

static void layout_refused(const uint32_t dims[3], ip_type type, const double spacing[3],
                           uint32_t B, uint32_t s, const char *text)
{
    ip_layout l;
    ip_error err;
    ip_status st = ip__layout_init(&l, dims, type, spacing, B, s, &err);
    CHECK_MSG(st == IP_ERR_ARGUMENT, "%s: status %d", text, (int)st);
    if (st != IP_OK)
        CHECK_CONTAINS(err.message, text);
}

static void test_layout_arguments(void)
{
    const uint32_t dims[3] = {10, 11, 12}, one[3] = {10, 1, 12}, huge[3] = {10, 11, 1u << 31};
    const double sp[3] = {1, 1, 1}, zero[3] = {1, 0, 1}, nan[3] = {NAN, 1, 1};
    const double inf[3] = {1, 1, INFINITY};
    layout_refused(one, IP_UINT8, sp, 8, 4, "dimension 1 along y");
    layout_refused(huge, IP_UINT8, sp, 8, 4, "along z is outside [2, 2^31)");
    layout_refused(dims, IP_UINT8, zero, 8, 4, "spacing 0 along y");
    layout_refused(dims, IP_UINT8, nan, 8, 4, "along x is not positive");
    layout_refused(dims, IP_UINT8, inf, 8, 4, "along z is not positive");
    layout_refused(dims, (ip_type)IP_TYPE_COUNT, sp, 8, 4, "unknown sample type");
    layout_refused(dims, IP_UINT8, sp, 1, 1, "brick edge 1");
    layout_refused(dims, IP_UINT8, sp, 12, 4, "brick edge 12");
    layout_refused(dims, IP_UINT8, sp, 512, 4, "brick edge 512");
    layout_refused(dims, IP_UINT8, sp, 8, 3, "sub-block edge 3");
    layout_refused(dims, IP_UINT8, sp, 8, 16, "sub-block edge 16");
    layout_refused(dims, IP_UINT8, sp, 8, 0, "sub-block edge 0");
}

/* ---- a whole, valid file in memory: every brick constant (no payload) but one raw ---- */

typedef struct image {
    ip_layout layout;
    unsigned char *bytes;
    uint64_t size;
    ip_summary_offsets o;
} image;

/* Recomputes the summary checksum (into the header) and the header checksum. */
static void reseal(image *m)
{
    unsigned char *h = m->bytes;
    uint64_t so = ip__load_u64le(h + IP_HDR_SUMMARY_OFFSET);
    uint64_t ss = ip__load_u64le(h + IP_HDR_SUMMARY_SIZE);
    if (so + ss <= m->size)
        ip__store_u64le(h + IP_HDR_SUMMARY_CHECKSUM, ip__format_checksum(h + so, ss));
    ip__store_u64le(h + IP_HDR_CHECKSUM, ip__format_checksum(h, IP_HDR_CHECKSUM));
}

/* A small file image: format version 2 as this build writes it when `rescale` is NULL (as
 * version 2 builds wrote it: no rescale record), version 3 with the rescale otherwise. */
static void make_image_with(image *m, const ip_rescale *rescale)
{
    const uint32_t dims[3] = {13, 9, 6};
    const double spacing[3] = {0.5, 0.25, 2};
    ip_error err;
    REQUIRE(ip__layout_init(&m->layout, dims, IP_UINT16, spacing, 4, 2, &err) == IP_OK);
    ip_layout *l = &m->layout;
    ip__layout_set_rescale(l, rescale);
    /* x and y turned 30 degrees about z, z reversed: a frame of the other handedness */
    const ip_orientation turned = {
        {10, -20, 5.5},
        {{0.8660254037844387, 0.5, 0}, {-0.5, 0.8660254037844387, 0}, {0, 0, -1}},
        IP_SPACE_LPS};
    l->orientation = turned;
    /* brick 0 is raw (its samples all 5 but for one 9), every other brick constant 5 */
    uint32_t b0[3] = {0, 0, 0}, origin[3], extent[3];
    ip_brick_extent(l, 0, b0, origin, extent);
    uint32_t raw = extent[0] * extent[1] * extent[2] * 2;
    l->data_size = raw;
    l->summary_offset =
        (IP_HEADER_SIZE + raw + IP_SUMMARY_ALIGN - 1) / IP_SUMMARY_ALIGN * IP_SUMMARY_ALIGN;
    l->file_size = l->summary_offset + l->summary_size;
    l->value_min = 5;
    l->value_max = 9;
    for (uint32_t k = 0; k < l->level_count; k++) {
        l->levels[k].value_min = 5;
        l->levels[k].value_max = 9;
    }
    m->size = l->file_size;
    m->bytes = calloc(1, m->size);
    REQUIRE(m->bytes != NULL);
    unsigned char *payload = m->bytes + IP_HEADER_SIZE;
    for (uint32_t i = 0; i < raw / 2; i++) {
        payload[2 * i] = i == 3 ? 9 : 5;
        payload[2 * i + 1] = 0;
    }
    unsigned char *summary = m->bytes + l->summary_offset;
    ip__summary_offsets_of(l, &m->o);
    if (l->format_version >= 3)
        ip__format_rescale_encode(l, summary);
    ip__format_level_table_encode(l, summary + m->o.level_table);
    uint32_t P3 = ip_layout_subblocks_per_brick(l);
    for (uint64_t g = 0; g < l->brick_count; g++) {
        ip_brick_entry e = {0, 0, IP_BRICK_CONSTANT, 0, 0};
        if (g == 0)
            e = (ip_brick_entry){IP_HEADER_SIZE, raw, IP_BRICK_RAW, 0,
                                 ip__format_checksum(payload, raw)};
        ip__format_entry_encode(&e, summary + m->o.directory + g * IP_DIRECTORY_ENTRY_SIZE);
        unsigned char *r = summary + m->o.brick_ranges + g * IP_RANGE_SIZE;
        ip__store_f32le(r + IP_RANGE_MIN, 5);
        ip__store_f32le(r + IP_RANGE_MAX, g == 0 ? 9 : 5);
        for (uint32_t i = 0; i < P3; i++) {
            unsigned char *sr = summary + m->o.subblock_ranges + (g * P3 + i) * IP_RANGE_SIZE;
            ip__store_f32le(sr + IP_RANGE_MIN, 5);
            ip__store_f32le(sr + IP_RANGE_MAX, 5);
        }
    }
    for (uint64_t n = 0; n < l->node_count; n++) {
        ip__store_f32le(summary + m->o.nodes + n * IP_RANGE_SIZE + IP_RANGE_MIN, 5);
        ip__store_f32le(summary + m->o.nodes + n * IP_RANGE_SIZE + IP_RANGE_MAX, 9);
    }
    ip__format_header_encode(l, m->bytes);
    reseal(m);
}

static void make_image(image *m)
{
    make_image_with(m, NULL);
}

/* A CT's rescale: Hounsfield units = stored - 1024. */
static const ip_rescale ct_rescale = {1, 1.0, -1024.0, "HU"};

static ip_status parse(const image *m, ip_layout *out, ip_error *err)
{
    return ip__format_parse(m->bytes, m->size, NAME, 0, out, err);
}

static void test_header_round_trip(void)
{
    image m;
    make_image(&m);
    const ip_layout *l = &m.layout;
    const unsigned char *h = m.bytes;
    /* the named offsets hold the fields of docs/format.md */
    CHECK_MEM_EQ(h + IP_HDR_MAGIC, "\x89IBV\r\n\x1a\n", 8);
    CHECK_EQ(ip__load_u32le(h + IP_HDR_VERSION), 2);
    CHECK_EQ(ip__load_u32le(h + IP_HDR_HEADER_SIZE), 256);
    CHECK_EQ(ip__load_u32le(h + IP_HDR_DIMS), 13);
    CHECK_EQ(ip__load_u32le(h + IP_HDR_DIMS + 4), 9);
    CHECK_EQ(ip__load_u32le(h + IP_HDR_DIMS + 8), 6);
    CHECK_EQ(ip__load_u32le(h + IP_HDR_TYPE), IP_UINT16);
    double sp;
    uint64_t bits = ip__load_u64le(h + IP_HDR_SPACING + 8);
    memcpy(&sp, &bits, 8);
    CHECK_EQ(sp, 0.25);
    CHECK_EQ(ip__load_u32le(h + IP_HDR_BRICK_EDGE), 4);
    CHECK_EQ(ip__load_u32le(h + IP_HDR_SUBBLOCK_EDGE), 2);
    CHECK_EQ(ip__load_u32le(h + IP_HDR_LEVEL_COUNT), l->level_count);
    CHECK_EQ(ip__load_u32le(h + IP_HDR_FLAGS), 0);
    CHECK_EQ(ip__load_f32le(h + IP_HDR_VALUE_MIN), 5);
    CHECK_EQ(ip__load_f32le(h + IP_HDR_VALUE_MAX), 9);
    CHECK_EQ(ip__load_u64le(h + IP_HDR_BRICK_COUNT), l->brick_count);
    CHECK_EQ(ip__load_u64le(h + IP_HDR_NODE_COUNT), l->node_count);
    CHECK_EQ(ip__load_u64le(h + IP_HDR_DATA_OFFSET), 256);
    CHECK_EQ(ip__load_u64le(h + IP_HDR_DATA_SIZE), l->data_size);
    CHECK_EQ(ip__load_u64le(h + IP_HDR_SUMMARY_OFFSET), l->summary_offset);
    CHECK_EQ(ip__load_u64le(h + IP_HDR_SUMMARY_SIZE), l->summary_size);
    CHECK_EQ(ip__load_u64le(h + IP_HDR_FILE_SIZE), m.size);
    CHECK_EQ(ip__load_f64le(h + IP_HDR_ORIGIN), 10);
    CHECK_EQ(ip__load_f64le(h + IP_HDR_ORIGIN + 8), -20);
    CHECK_EQ(ip__load_f64le(h + IP_HDR_ORIGIN + 16), 5.5);
    CHECK_EQ(ip__load_f64le(h + IP_HDR_DIRECTIONS + 8), 0.5);      /* x direction, y component */
    CHECK_EQ(ip__load_f64le(h + IP_HDR_DIRECTIONS + 3 * 8), -0.5); /* y direction, x component */
    CHECK_EQ(ip__load_f64le(h + IP_HDR_DIRECTIONS + 8 * 8), -1);   /* z direction, z component */
    CHECK_EQ(ip__load_u32le(h + IP_HDR_SPACE), IP_SPACE_LPS);
    for (int i = IP_HDR_RESERVED; i < IP_HDR_CHECKSUM; i++)
        CHECK_EQ(h[i], 0);
    CHECK_EQ(ip__load_u64le(h + IP_HDR_CHECKSUM), ip__format_checksum(h, 248));

    ip_layout parsed;
    ip_error err;
    REQUIRE(parse(&m, &parsed, &err) == IP_OK);
    CHECK_MEM_EQ(parsed.dims, l->dims, sizeof l->dims);
    CHECK_MEM_EQ(parsed.spacing, l->spacing, sizeof l->spacing);
    CHECK_MEM_EQ(&parsed.orientation, &l->orientation, sizeof l->orientation);
    CHECK_EQ(parsed.type, l->type);
    CHECK_EQ(parsed.brick_edge, 4);
    CHECK_EQ(parsed.subblock_edge, 2);
    CHECK_EQ(parsed.level_count, l->level_count);
    CHECK_EQ(parsed.brick_count, l->brick_count);
    CHECK_EQ(parsed.node_count, l->node_count);
    CHECK_EQ(parsed.value_min, 5);
    CHECK_EQ(parsed.value_max, 9);
    CHECK_EQ(parsed.data_offset, 256);
    CHECK_EQ(parsed.data_size, l->data_size);
    CHECK_EQ(parsed.summary_offset, l->summary_offset);
    CHECK_EQ(parsed.summary_size, l->summary_size);
    CHECK_EQ(parsed.file_size, m.size);
    CHECK_EQ(parsed.summary_checksum, ip__load_u64le(h + IP_HDR_SUMMARY_CHECKSUM));
    for (uint32_t k = 0; k < l->level_count; k++) {
        CHECK_MEM_EQ(parsed.levels[k].dims, l->levels[k].dims, sizeof l->levels[k].dims);
        CHECK_EQ(parsed.levels[k].first_brick, l->levels[k].first_brick);
        CHECK_EQ(parsed.levels[k].value_min, 5);
        CHECK_EQ(parsed.levels[k].value_max, 9);
    }
    /* re-encoding the parsed layout gives the same header bytes */
    unsigned char again[IP_HEADER_SIZE];
    ip__format_header_encode(&parsed, again);
    CHECK_MEM_EQ(again, h, IP_HEADER_SIZE);
    free(m.bytes);
}

static void test_entry_round_trip(void)
{
    ip_brick_entry e = {0x0102030405060708ull, 0xA0B0C0D0u, IP_BRICK_LZ4, 6, 0x1122334455667788ull},
                   back;
    unsigned char d[IP_DIRECTORY_ENTRY_SIZE];
    memset(d, 0xFF, sizeof d);
    ip__format_entry_encode(&e, d);
    CHECK_EQ(ip__load_u64le(d + IP_DIR_OFFSET), e.offset);
    CHECK_EQ(ip__load_u32le(d + IP_DIR_STORED_SIZE), e.stored_size);
    CHECK_EQ(d[IP_DIR_ENCODING], IP_BRICK_LZ4);
    CHECK_EQ(d[IP_DIR_FILTERS], 6);
    CHECK_EQ(d[IP_DIR_RESERVED], 0);
    CHECK_EQ(d[IP_DIR_RESERVED + 1], 0);
    CHECK_EQ(ip__load_u64le(d + IP_DIR_CHECKSUM), e.checksum);
    ip__format_entry_decode(d, &back);
    CHECK_EQ(back.offset, e.offset);
    CHECK_EQ(back.stored_size, e.stored_size);
    CHECK_EQ(back.encoding, e.encoding);
    CHECK_EQ(back.filters, e.filters);
    CHECK_EQ(back.checksum, e.checksum);
}

/* Parsing the image after `change` (then resealed unless `keep_checksums`) fails with `code`
 * and a message naming the file and holding `text`; the image is restored afterwards. */
typedef void (*change_fn)(image *m, uint64_t arg);

static void refused(image *m, change_fn change, uint64_t arg, int reseal_after, ip_status code,
                    const char *text)
{
    unsigned char *saved = malloc(m->size);
    REQUIRE(saved != NULL);
    memcpy(saved, m->bytes, m->size);
    uint64_t size = m->size;
    change(m, arg);
    if (reseal_after)
        reseal(m);
    ip_layout l;
    ip_error err;
    ip_status st = ip__format_parse(m->bytes, m->size, NAME, 0, &l, &err);
    CHECK_MSG(st == code, "%s (%llu): status %d, wanted %d (%s)", text, (unsigned long long)arg,
              (int)st, (int)code, st != IP_OK ? err.message : "");
    if (st != IP_OK) {
        CHECK_CONTAINS(err.message, NAME);
        CHECK_CONTAINS(err.message, text);
    }
    m->size = size;
    memcpy(m->bytes, saved, m->size);
    free(saved);
}

static void set_u32(image *m, uint64_t packed)
{
    ip__store_u32le(m->bytes + (packed >> 32), (uint32_t)packed);
}

static void set_u64_field(image *m, uint64_t offset, uint64_t v)
{
    ip__store_u64le(m->bytes + offset, v);
}

static uint64_t at(uint64_t offset, uint32_t value)
{
    return offset << 32 | value;
}

static void flip_byte(image *m, uint64_t offset)
{
    m->bytes[offset] ^= 0x40;
}

/* Writes v as the header f64 at `offset`. */
static void set_f64_at(image *m, uint64_t offset, double v)
{
    ip__store_f64le(m->bytes + offset, v);
}

static void set_origin_y(image *m, uint64_t bits)
{
    double v;
    memcpy(&v, &bits, 8);
    set_f64_at(m, IP_HDR_ORIGIN + 8, v);
}

/* the z direction's z component (-1 in make_image) */
static void set_direction_zz(image *m, uint64_t bits)
{
    double v;
    memcpy(&v, &bits, 8);
    set_f64_at(m, IP_HDR_DIRECTIONS + 8 * 8, v);
}

/* the y direction made the x direction: unit length, not perpendicular */
static void copy_x_direction_to_y(image *m, uint64_t unused)
{
    (void)unused;
    memcpy(m->bytes + IP_HDR_DIRECTIONS + 24, m->bytes + IP_HDR_DIRECTIONS, 24);
}

/* The header as format version 1 wrote it: version 1, bytes 144-247 zero. */
static void make_version_1(image *m, uint64_t unused)
{
    (void)unused;
    ip__store_u32le(m->bytes + IP_HDR_VERSION, 1);
    memset(m->bytes + IP_HDR_RESERVED_V1, 0, IP_HDR_CHECKSUM - IP_HDR_RESERVED_V1);
}

static void make_version_1_poke(image *m, uint64_t offset)
{
    make_version_1(m, 0);
    m->bytes[offset] = 1;
}

static void set_spacing_y(image *m, uint64_t bits)
{
    double v;
    memcpy(&v, &bits, 8);
    ip__store_f64le(m->bytes + IP_HDR_SPACING + 8, v);
}

static uint64_t double_bits(double v)
{
    uint64_t bits;
    memcpy(&bits, &v, 8);
    return bits;
}

static void add_to_brick_count(image *m, uint64_t n)
{
    set_u64_field(m, IP_HDR_BRICK_COUNT, m->layout.brick_count + n);
}

static void add_to_node_count(image *m, uint64_t n)
{
    set_u64_field(m, IP_HDR_NODE_COUNT, m->layout.node_count + n);
}

static void add_to_summary_size(image *m, uint64_t n)
{
    set_u64_field(m, IP_HDR_SUMMARY_SIZE, m->layout.summary_size + n);
}

static void add_to_file_size(image *m, uint64_t n)
{
    set_u64_field(m, IP_HDR_FILE_SIZE, m->size + n);
}

static void set_data_offset(image *m, uint64_t v)
{
    set_u64_field(m, IP_HDR_DATA_OFFSET, v);
}

static void add_to_summary_offset(image *m, uint64_t n)
{
    set_u64_field(m, IP_HDR_SUMMARY_OFFSET, m->layout.summary_offset + n);
}

static void set_value_max(image *m, uint64_t bits)
{
    float v;
    uint32_t b = (uint32_t)bits;
    memcpy(&v, &b, 4);
    ip__store_f32le(m->bytes + IP_HDR_VALUE_MAX, v);
}

static void shorten(image *m, uint64_t n)
{
    m->size -= n;
}

static void test_header_refusals(void)
{
    image m;
    make_image(&m);
    ip_layout l;
    ip_error err;
    REQUIRE(parse(&m, &l, &err) == IP_OK);

    for (uint64_t i = 0; i < IP_HDR_MAGIC_SIZE; i++)
        refused(&m, flip_byte, IP_HDR_MAGIC + i, 1, IP_ERR_FORMAT, "bad magic");
    refused(&m, set_u32, at(IP_HDR_VERSION, 4), 1, IP_ERR_UNSUPPORTED, "format version 4");
    refused(&m, set_u32, at(IP_HDR_VERSION, 0), 1, IP_ERR_UNSUPPORTED, "format version 0");
    refused(&m, set_u32, at(IP_HDR_HEADER_SIZE, 255), 1, IP_ERR_FORMAT, "header size 255");
    /* any header byte changed without resealing: the header checksum */
    for (uint64_t i = IP_HDR_DIMS; i < IP_HDR_CHECKSUM + 8; i += 7)
        refused(&m, flip_byte, i, 0, IP_ERR_CHECKSUM, "header checksum mismatch");
    refused(&m, set_u32, at(IP_HDR_TYPE, IP_TYPE_COUNT), 1, IP_ERR_FORMAT, "unknown sample type");
    refused(&m, set_u32, at(IP_HDR_FLAGS, 1), 1, IP_ERR_UNSUPPORTED, "unknown header flags");
    refused(&m, set_u32, at(IP_HDR_DIMS, 1), 1, IP_ERR_FORMAT, "dimension 1 along x");
    refused(&m, set_u32, at(IP_HDR_DIMS + 8, 1u << 31), 1, IP_ERR_FORMAT, "along z is outside");
    refused(&m, set_u32, at(IP_HDR_BRICK_EDGE, 6), 1, IP_ERR_FORMAT, "brick edge 6");
    refused(&m, set_u32, at(IP_HDR_BRICK_EDGE, 512), 1, IP_ERR_FORMAT, "brick edge 512");
    refused(&m, set_u32, at(IP_HDR_SUBBLOCK_EDGE, 8), 1, IP_ERR_FORMAT, "sub-block edge 8");
    refused(&m, set_spacing_y, double_bits(0), 1, IP_ERR_FORMAT, "spacing 0 along y");
    refused(&m, set_spacing_y, double_bits(-1), 1, IP_ERR_FORMAT, "along y is not positive");
    refused(&m, set_spacing_y, double_bits(NAN), 1, IP_ERR_FORMAT, "along y is not positive");
    refused(&m, set_spacing_y, double_bits(1e7), 1, IP_ERR_UNSUPPORTED,
            "outside the range that renders correctly");
    refused(&m, set_spacing_y, double_bits(1e-3), 1, IP_ERR_UNSUPPORTED, "times");
    for (uint64_t i = IP_HDR_RESERVED; i < IP_HDR_CHECKSUM; i++) {
        char text[64];
        snprintf(text, sizeof text, "reserved header byte %llu is not zero", (unsigned long long)i);
        refused(&m, flip_byte, i, 1, IP_ERR_FORMAT, text);
    }
    /* version 2's orientation: finite, orthonormal, a known space */
    refused(&m, set_origin_y, double_bits(NAN), 1, IP_ERR_FORMAT, "origin nan along y");
    refused(&m, set_origin_y, double_bits(INFINITY), 1, IP_ERR_FORMAT, "along y is not finite");
    refused(&m, set_direction_zz, double_bits(NAN), 1, IP_ERR_FORMAT, "z direction is not finite");
    refused(&m, set_direction_zz, double_bits(-1.01), 1, IP_ERR_FORMAT,
            "z direction is not a unit vector");
    refused(&m, set_direction_zz, double_bits(0), 1, IP_ERR_FORMAT, "not a unit vector");
    refused(&m, copy_x_direction_to_y, 0, 1, IP_ERR_FORMAT,
            "x and y directions are not perpendicular");
    refused(&m, set_u32, at(IP_HDR_SPACE, IP_SPACE_LPS + 1), 1, IP_ERR_FORMAT, "unknown space 4");
    /* version 1: the same bytes are reserved, and must be zero */
    for (uint64_t i = IP_HDR_RESERVED_V1; i < IP_HDR_CHECKSUM; i++) {
        char text[64];
        snprintf(text, sizeof text, "reserved header byte %llu is not zero", (unsigned long long)i);
        refused(&m, make_version_1_poke, i, 1, IP_ERR_FORMAT, text);
    }
    refused(&m, set_u32, at(IP_HDR_LEVEL_COUNT, m.layout.level_count + 1), 1, IP_ERR_FORMAT,
            "counts disagree with the dimensions");
    refused(&m, add_to_brick_count, 1, 1, IP_ERR_FORMAT, "counts disagree");
    refused(&m, add_to_node_count, 1, 1, IP_ERR_FORMAT, "counts disagree");
    refused(&m, add_to_summary_size, 8, 1, IP_ERR_FORMAT, "summary size");
    refused(&m, add_to_file_size, 1, 1, IP_ERR_FORMAT, "truncated or extended");
    refused(&m, shorten, 1, 1, IP_ERR_FORMAT, "truncated or extended");
    refused(&m, shorten, m.size - 255, 0, IP_ERR_FORMAT, "too short for a brick file");
    refused(&m, set_data_offset, IP_HEADER_SIZE + 8, 1, IP_ERR_FORMAT, "section offsets");
    refused(&m, add_to_summary_offset, 8, 1, IP_ERR_FORMAT, "section offsets");
    refused(&m, add_to_summary_offset, IP_SUMMARY_ALIGN, 1, IP_ERR_FORMAT, "section offsets");
    /* the header's value range must be level 0's */
    float eight = 8;
    uint32_t eight_bits;
    memcpy(&eight_bits, &eight, 4);
    refused(&m, set_value_max, eight_bits, 1, IP_ERR_FORMAT, "the value range is invalid");

    /* with IP_PARSE_SKIP_CHECKSUMS a wrong header checksum passes */
    m.bytes[IP_HDR_CHECKSUM] ^= 1;
    CHECK_EQ(ip__format_parse(m.bytes, m.size, NAME, IP_PARSE_SKIP_CHECKSUMS, &l, &err), IP_OK);
    CHECK_EQ(ip__format_parse(m.bytes, m.size, NAME, 0, &l, &err), IP_ERR_CHECKSUM);
    free(m.bytes);
}

/* ---- the summary section ---- */

static unsigned char *summary_of(image *m)
{
    return m->bytes + m->layout.summary_offset;
}

static void set_level_u32(image *m, uint64_t packed)
{
    ip__store_u32le(summary_of(m) + m->o.level_table + (packed >> 32), (uint32_t)packed);
}

static void set_level_u64(image *m, uint64_t offset)
{
    ip__store_u64le(summary_of(m) + m->o.level_table + offset,
                    ip__load_u64le(summary_of(m) + m->o.level_table + offset) + 1);
}

static void set_level_nan(image *m, uint64_t offset)
{
    ip__store_f32le(summary_of(m) + m->o.level_table + offset, NAN);
}

/* arg: brick g << 8 | field offset in the directory entry; the byte is or'ed with 0x10 */
static void poke_entry_byte(image *m, uint64_t arg)
{
    summary_of(m)[m->o.directory + (arg >> 8) * IP_DIRECTORY_ENTRY_SIZE + (arg & 0xFF)] ^= 0x10;
}

static void set_entry_encoding(image *m, uint64_t arg)
{
    summary_of(m)[m->o.directory + (arg >> 8) * IP_DIRECTORY_ENTRY_SIZE + IP_DIR_ENCODING] =
        (unsigned char)(arg & 0xFF);
}

static void set_entry_filters(image *m, uint64_t arg)
{
    summary_of(m)[m->o.directory + (arg >> 8) * IP_DIRECTORY_ENTRY_SIZE + IP_DIR_FILTERS] =
        (unsigned char)(arg & 0xFF);
}

static void set_entry_offset(image *m, uint64_t offset)
{
    ip__store_u64le(summary_of(m) + m->o.directory + IP_DIR_OFFSET, offset);
}

static void set_entry_size(image *m, uint64_t arg)
{
    ip__store_u32le(summary_of(m) + m->o.directory + (arg >> 32) * IP_DIRECTORY_ENTRY_SIZE +
                        IP_DIR_STORED_SIZE,
                    (uint32_t)arg);
}

static void set_brick_max(image *m, uint64_t arg)
{
    float v;
    uint32_t bits = (uint32_t)arg;
    memcpy(&v, &bits, 4);
    ip__store_f32le(summary_of(m) + m->o.brick_ranges + (arg >> 32) * IP_RANGE_SIZE + IP_RANGE_MAX,
                    v);
}

static void gap_byte(image *m, uint64_t i)
{
    m->bytes[IP_HEADER_SIZE + m->layout.data_size + i] = 1;
}

static void summary_byte(image *m, uint64_t i)
{
    summary_of(m)[i] ^= 0x01;
}

static uint64_t f32_bits(float v)
{
    uint32_t bits;
    memcpy(&bits, &v, 4);
    return bits;
}

/* A version 1 header (no orientation) still opens, as the identity with zero origin. */
static void test_version_1(void)
{
    image m;
    make_image(&m);
    ip_layout l, identity;
    ip_error err;
    REQUIRE(parse(&m, &l, &err) == IP_OK);
    CHECK_EQ(l.format_version, IP_FORMAT_VERSION_PLAIN); /* the file's own version is kept */
    CHECK(!l.rescale.present);
    make_version_1(&m, 0);
    reseal(&m);
    REQUIRE(parse(&m, &l, &err) == IP_OK);
    CHECK_EQ(l.format_version, 1);
    ip_orientation_identity(&identity.orientation);
    CHECK_MEM_EQ(&l.orientation, &identity.orientation, sizeof l.orientation);
    CHECK(ip_orientation_is_identity(&l.orientation));
    CHECK_EQ(l.orientation.space, IP_SPACE_UNKNOWN);
    CHECK_EQ(l.dims[0], 13);
    CHECK_EQ(l.spacing[1], 0.25);
    CHECK(!l.rescale.present); /* no rescale: the identity */
    CHECK_EQ(l.rescale.slope, 1.0);
    CHECK_EQ(l.rescale.intercept, 0.0);
    CHECK_STR_EQ(l.rescale.unit, "");
    free(m.bytes);
}

/* Version 3: the rescale record first in the summary section, the level table after it; the
 * header as version 2's but for its version. A file without a rescale is still written as
 * version 2, byte for byte as before (no record), and reads with no rescale. */
static void test_rescale_round_trip(void)
{
    image plain, m;
    make_image(&plain);
    make_image_with(&m, &ct_rescale);
    const unsigned char *h = m.bytes, *summary = m.bytes + m.layout.summary_offset;
    CHECK_EQ(ip__load_u32le(plain.bytes + IP_HDR_VERSION), 2);
    CHECK_EQ(plain.o.level_table, 0);
    CHECK_EQ(ip__load_u32le(h + IP_HDR_VERSION), 3);
    CHECK_EQ(m.o.level_table, IP_RESCALE_RECORD_SIZE);
    CHECK_EQ(m.layout.summary_size, plain.layout.summary_size + IP_RESCALE_RECORD_SIZE);
    CHECK_EQ(ip__load_f64le(summary + IP_RSC_SLOPE), 1.0);
    CHECK_EQ(ip__load_f64le(summary + IP_RSC_INTERCEPT), -1024.0);
    CHECK_MEM_EQ(summary + IP_RSC_UNIT, "HU\0\0\0\0\0\0\0\0\0\0\0\0\0\0", IP_RESCALE_UNIT_MAX);
    for (int i = IP_RSC_RESERVED; i < (int)IP_RESCALE_RECORD_SIZE; i++)
        CHECK_EQ(summary[i], 0);
    /* the same level table, directory and ranges, 64 bytes later */
    CHECK_MEM_EQ(summary + IP_RESCALE_RECORD_SIZE, plain.bytes + plain.layout.summary_offset,
                 plain.layout.summary_size);

    ip_layout parsed, parsed_plain;
    ip_error err;
    REQUIRE(parse(&m, &parsed, &err) == IP_OK);
    CHECK_EQ(parsed.format_version, 3);
    CHECK(parsed.rescale.present);
    CHECK_EQ(parsed.rescale.slope, 1.0);
    CHECK_EQ(parsed.rescale.intercept, -1024.0);
    CHECK_STR_EQ(parsed.rescale.unit, "HU");
    CHECK_EQ(parsed.levels[0].value_max, 9);
    unsigned char again[IP_HEADER_SIZE];
    ip__format_header_encode(&parsed, again);
    CHECK_MEM_EQ(again, h, IP_HEADER_SIZE);
    REQUIRE(parse(&plain, &parsed_plain, &err) == IP_OK);
    CHECK_EQ(parsed_plain.format_version, 2);
    CHECK(!parsed_plain.rescale.present);
    CHECK_EQ(parsed_plain.rescale.slope, 1.0);
    /* a negative slope and a unit of every printable character but NUL's room are kept */
    const ip_rescale odd = {1, -0.5, 3.25, "mg/ml ~!@#$%^&*"};
    free(m.bytes);
    make_image_with(&m, &odd);
    REQUIRE(parse(&m, &parsed, &err) == IP_OK);
    CHECK_EQ(parsed.rescale.slope, -0.5);
    CHECK_EQ(parsed.rescale.intercept, 3.25);
    CHECK_STR_EQ(parsed.rescale.unit, "mg/ml ~!@#$%^&*");
    free(m.bytes);
    free(plain.bytes);
}

static void set_rescale_f64(image *m, uint64_t packed)
{
    uint64_t bits = packed & 0xffffffffu;
    double v = bits == 1 ? NAN : bits == 2 ? INFINITY : 0.0; /* 1: NaN, 2: inf, else 0 */
    ip__store_f64le(summary_of(m) + (packed >> 32), v);
}

static void set_rescale_byte(image *m, uint64_t packed)
{
    summary_of(m)[packed >> 32] = (unsigned char)packed;
}

static void fill_unit(image *m, uint64_t c)
{
    memset(summary_of(m) + IP_RSC_UNIT, (int)c, IP_RESCALE_UNIT_MAX);
}

/* Every field of the rescale record made wrong on its own, and versions that disagree with
 * the summary's size. */
static void test_rescale_refusals(void)
{
    image m, plain;
    make_image_with(&m, &ct_rescale);
    make_image(&plain);
    refused(&m, set_rescale_f64, at(IP_RSC_SLOPE, 0), 1, IP_ERR_FORMAT,
            "rescale slope 0 is not a finite number other than 0");
    refused(&m, set_rescale_f64, at(IP_RSC_SLOPE, 1), 1, IP_ERR_FORMAT, "slope nan");
    refused(&m, set_rescale_f64, at(IP_RSC_SLOPE, 2), 1, IP_ERR_FORMAT, "slope inf");
    refused(&m, set_rescale_f64, at(IP_RSC_INTERCEPT, 1), 1, IP_ERR_FORMAT,
            "rescale intercept nan is not finite");
    refused(&m, set_rescale_f64, at(IP_RSC_INTERCEPT, 2), 1, IP_ERR_FORMAT, "intercept inf");
    refused(&m, set_rescale_byte, at(IP_RSC_UNIT + 1, 0x01), 1, IP_ERR_FORMAT,
            "not printable ASCII");
    refused(&m, set_rescale_byte, at(IP_RSC_UNIT + 1, 0x80), 1, IP_ERR_FORMAT,
            "not printable ASCII");
    refused(&m, set_rescale_byte, at(IP_RSC_UNIT + 5, 'x'), 1, IP_ERR_FORMAT, "not NUL-padded");
    refused(&m, fill_unit, 'x', 1, IP_ERR_FORMAT, "not NUL-terminated");
    for (int i = IP_RSC_RESERVED; i < (int)IP_RESCALE_RECORD_SIZE; i++) {
        char text[64];
        snprintf(text, sizeof text, "reserved byte %d of the rescale is not zero", i);
        refused(&m, set_rescale_byte, at((uint64_t)i, 1), 1, IP_ERR_FORMAT, text);
    }
    refused(&m, summary_byte, IP_RSC_UNIT, 0, IP_ERR_CHECKSUM, "summary section checksum");
    /* the version says whether the record is there: the summary's size then disagrees */
    refused(&m, set_u32, at(IP_HDR_VERSION, 2), 1, IP_ERR_FORMAT, "summary size");
    refused(&plain, set_u32, at(IP_HDR_VERSION, 3), 1, IP_ERR_FORMAT, "summary size");
    free(m.bytes);
    free(plain.bytes);
}

static void test_summary_refusals(void)
{
    image m;
    make_image(&m);
    uint64_t last = m.layout.brick_count - 1, raw = m.layout.data_size;
    for (uint32_t k = 0; k < m.layout.level_count; k++) {
        uint64_t e = (uint64_t)k * IP_LEVEL_ENTRY_SIZE;
        char text[64];
        snprintf(text, sizeof text, "level %u of the level table disagrees", k);
        refused(&m, set_level_u32, at(e + IP_LVL_DIMS + 4, 99), 1, IP_ERR_FORMAT, text);
        refused(&m, set_level_u32, at(e + IP_LVL_BRICKS + 8, 99), 1, IP_ERR_FORMAT, text);
        refused(&m, set_level_u64, e + IP_LVL_FIRST_BRICK, 1, IP_ERR_FORMAT, text);
        refused(&m, set_level_u32, at(e + IP_LVL_OCTREE_DEPTH, 9), 1, IP_ERR_FORMAT, text);
        refused(&m, set_level_u32, at(e + IP_LVL_RESERVED_A, 1), 1, IP_ERR_FORMAT, text);
        refused(&m, set_level_u64, e + IP_LVL_FIRST_NODE, 1, IP_ERR_FORMAT, text);
        refused(&m, set_level_u64, e + IP_LVL_RESERVED_B, 1, IP_ERR_FORMAT, text);
        snprintf(text, sizeof text, "level %u has an invalid value range", k);
        refused(&m, set_level_nan, e + IP_LVL_VALUE_MIN, 1, IP_ERR_FORMAT, text);
        refused(&m, set_level_nan, e + IP_LVL_VALUE_MAX, 1, IP_ERR_FORMAT, text);
    }
    for (uint64_t g = 0; g <= last; g += last) {
        for (uint64_t i = 0; i < IP_DIR_RESERVED_SIZE; i++)
            refused(&m, poke_entry_byte, g << 8 | (IP_DIR_RESERVED + i), 1, IP_ERR_FORMAT,
                    "non-zero reserved bytes");
        refused(&m, set_entry_encoding, g << 8 | 3, 1, IP_ERR_FORMAT, "an unknown encoding");
        refused(&m, set_brick_max, g << 32 | f32_bits(NAN), 1, IP_ERR_FORMAT,
                "an invalid value range");
        refused(&m, set_brick_max, g << 32 | f32_bits(1), 1, IP_ERR_FORMAT,
                "an invalid value range");
    }
    /* a constant brick: no payload, no filters, no checksum, equal range ends */
    refused(&m, set_entry_size, last << 32 | 4, 1, IP_ERR_FORMAT, "inconsistent constant");
    refused(&m, set_entry_filters, last << 8 | 1, 1, IP_ERR_FORMAT, "inconsistent constant");
    refused(&m, poke_entry_byte, last << 8 | IP_DIR_CHECKSUM, 1, IP_ERR_FORMAT,
            "inconsistent constant");
    refused(&m, set_brick_max, last << 32 | f32_bits(6), 1, IP_ERR_FORMAT, "inconsistent constant");
    refused(&m, set_brick_max, last << 32 | f32_bits(5.5f), 0, IP_ERR_CHECKSUM,
            "summary section checksum mismatch");
    /* a raw brick: exact size, no filters */
    refused(&m, set_entry_size, 0ull << 32 | (raw - 2), 1, IP_ERR_FORMAT,
            "a raw payload of the wrong size");
    refused(&m, set_entry_filters, 0 << 8 | 2, 1, IP_ERR_FORMAT, "a raw payload of the wrong");
    /* LZ4: a size within LZ4's bound and known filters, one predictor at most */
    refused(&m, set_entry_encoding, 0 << 8 | IP_BRICK_LZ4, 0, IP_ERR_CHECKSUM, "summary");
    ip_layout l;
    ip_error err;
    set_entry_encoding(&m, 0 << 8 | IP_BRICK_LZ4);
    reseal(&m);
    CHECK_EQ(parse(&m, &l, &err), IP_OK); /* a raw-sized LZ4 block is a possible size */
    refused(&m, set_entry_size, 0ull << 32 | 0, 1, IP_ERR_FORMAT, "an LZ4 payload of impossible");
    refused(&m, set_entry_size, 0ull << 32 | (raw + raw / 255 + 17), 1, IP_ERR_FORMAT,
            "an LZ4 payload of impossible");
    refused(&m, set_entry_filters, 0 << 8 | 5, 1, IP_ERR_FORMAT, "unknown filters");
    refused(&m, set_entry_filters, 0 << 8 | 8, 1, IP_ERR_FORMAT, "unknown filters");
    set_entry_encoding(&m, 0 << 8 | IP_BRICK_RAW);
    reseal(&m);
    REQUIRE(parse(&m, &l, &err) == IP_OK);
    /* the payload inside the data section */
    refused(&m, set_entry_offset, IP_HEADER_SIZE - 1, 1, IP_ERR_FORMAT,
            "a payload outside the data section");
    refused(&m, set_entry_offset, IP_HEADER_SIZE + 1, 1, IP_ERR_FORMAT,
            "a payload outside the data section");
    /* padding before the summary, and the summary checksum over every array */
    uint64_t gap = m.layout.summary_offset - IP_HEADER_SIZE - m.layout.data_size;
    REQUIRE(gap > 0);
    refused(&m, gap_byte, 0, 1, IP_ERR_FORMAT, "in the padding before the summary section");
    refused(&m, gap_byte, gap - 1, 1, IP_ERR_FORMAT, "is not zero");
    const uint64_t arrays[] = {m.o.level_table,     m.o.directory, m.o.brick_ranges,
                               m.o.subblock_ranges, m.o.nodes,     m.o.end - 1};
    for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; i++)
        refused(&m, summary_byte, arrays[i], 0, IP_ERR_CHECKSUM,
                "summary section checksum mismatch");
    free(m.bytes);
}

/* The parser on every truncation and on random bytes: refused, never out of bounds. */
static void test_truncations(void)
{
    image m;
    make_image(&m);
    int bad = 0;
    for (uint64_t size = 0; size < m.size; size += size < 300 ? 1 : 97) {
        unsigned char *copy = malloc(size ? size : 1);
        REQUIRE(copy != NULL);
        memcpy(copy, m.bytes, size);
        ip_layout l;
        ip_error err;
        if (ip__format_parse(copy, size, NAME, 0, &l, &err) != IP_ERR_FORMAT)
            bad++;
        free(copy);
    }
    CHECK_MSG(bad == 0, "%d truncations not refused as malformed", bad);
    free(m.bytes);
}

static const test_case cases[] = {
    TEST_CASE(test_layouts),
    TEST_CASE(test_layout_arguments),
    TEST_CASE(test_header_round_trip),
    TEST_CASE(test_entry_round_trip),
    TEST_CASE(test_header_refusals),
    TEST_CASE(test_version_1),
    TEST_CASE(test_summary_refusals),
    TEST_CASE(test_truncations),
    TEST_CASE(test_rescale_round_trip),
    TEST_CASE(test_rescale_refusals),
};

int main(int argc, char **argv)
{
    return RUN_CASES(argc, argv, cases, "test_format");
}

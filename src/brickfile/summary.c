/* SPDX-License-Identifier: BSD-3-Clause */
/* Min/max summaries of bricks and sub-blocks. */
#include <math.h>

#include "format.h"
#include "internal.h"
#include "summary.h"

#define BOX_RANGE(T)                                                                 \
    do {                                                                             \
        const T *s = samples;                                                        \
        T lo_v = s[lo[0] + (size_t)extent[0] * (lo[1] + (size_t)extent[1] * lo[2])]; \
        T hi_v = lo_v;                                                               \
        for (uint32_t z = lo[2]; z <= hi[2]; z++)                                    \
            for (uint32_t y = lo[1]; y <= hi[1]; y++) {                              \
                const T *row = s + (size_t)extent[0] * (y + (size_t)extent[1] * z);  \
                for (uint32_t x = lo[0]; x <= hi[0]; x++) {                          \
                    T v = row[x];                                                    \
                    lo_v = v < lo_v ? v : lo_v;                                      \
                    hi_v = v > hi_v ? v : hi_v;                                      \
                }                                                                    \
            }                                                                        \
        *min = (float)lo_v;                                                          \
        *max = (float)hi_v;                                                          \
    } while (0)

void ip__box_range(const void *samples, ip_type type, const uint32_t extent[3],
                   const uint32_t lo[3], const uint32_t hi[3], float *min, float *max)
{
    switch (type) {
    case IP_UINT8: BOX_RANGE(uint8_t); break;
    case IP_UINT16: BOX_RANGE(uint16_t); break;
    case IP_INT16: BOX_RANGE(int16_t); break;
    case IP_FLOAT32: BOX_RANGE(float); break;
    }
}

/* The brick's range: the non-empty sub-blocks cover every sample of the brick, so their union
 * is its range. */
void ip__union_range(const float *ranges, size_t count, float brick_range[2])
{
    brick_range[0] = INFINITY;
    brick_range[1] = -INFINITY;
    for (size_t j = 0; j < count; j++) {
        brick_range[0] = fminf(brick_range[0], ranges[2 * j]);
        brick_range[1] = fmaxf(brick_range[1], ranges[2 * j + 1]);
    }
}

static void check_shape(const uint32_t extent[3], uint32_t brick_edge, uint32_t subblock_edge)
{
    IP_ASSERT(subblock_edge >= 1 && subblock_edge <= brick_edge && brick_edge % subblock_edge == 0);
    for (int a = 0; a < 3; a++)
        IP_ASSERT(extent[a] >= 2 && extent[a] <= brick_edge + 1);
    (void)extent, (void)brick_edge, (void)subblock_edge;
}

/* ---- a brick row of a layer, band by band ---- */

/* uint16 samples are reduced as int16 shifted by 32768 (same order), so that SSE2's signed
 * 16-bit min and max apply; the other types as they are. */
#define KEEP(v) (v)
#define SHIFT_U16(v) ((int16_t)((int32_t)(v)-32768))
#define UNSHIFT_U16(v) ((int32_t)(v) + 32768)

/* Reduces full-width rows sample by sample into lo and hi: up to three rows per pass, so that
 * the two accumulator rows are loaded and stored once per three rows read. `init` sets lo and
 * hi from the rows instead of merging into them. */
#define DEFINE_ROWS3(T, A, IN, NAME)                                                             \
    static void NAME(A *restrict lo, A *restrict hi, const T *restrict r0, const T *restrict r1, \
                     const T *restrict r2, uint32_t width, int init)                             \
    {                                                                                            \
        if (init) {                                                                              \
            for (uint32_t x = 0; x < width; x++) {                                               \
                A a = (A)IN(r0[x]), b = (A)IN(r1[x]), c = (A)IN(r2[x]);                          \
                A mn = a < b ? a : b, mx = a > b ? a : b;                                        \
                lo[x] = c < mn ? c : mn;                                                         \
                hi[x] = c > mx ? c : mx;                                                         \
            }                                                                                    \
            return;                                                                              \
        }                                                                                        \
        for (uint32_t x = 0; x < width; x++) {                                                   \
            A a = (A)IN(r0[x]), b = (A)IN(r1[x]), c = (A)IN(r2[x]);                              \
            A mn = a < b ? a : b, mx = a > b ? a : b;                                            \
            mn = c < mn ? c : mn;                                                                \
            mx = c > mx ? c : mx;                                                                \
            lo[x] = mn < lo[x] ? mn : lo[x];                                                     \
            hi[x] = mx > hi[x] ? mx : hi[x];                                                     \
        }                                                                                        \
    }

DEFINE_ROWS3(uint8_t, uint8_t, KEEP, rows3_u8)
DEFINE_ROWS3(uint16_t, int16_t, SHIFT_U16, rows3_u16)
DEFINE_ROWS3(int16_t, int16_t, KEEP, rows3_i16)

/* lo = min(lo, lo2), hi = max(hi, hi2) sample by sample. */
#define DEFINE_MERGE(A, NAME)                                                                      \
    static void NAME(A *restrict lo, A *restrict hi, const A *restrict lo2, const A *restrict hi2, \
                     uint32_t width)                                                               \
    {                                                                                              \
        for (uint32_t x = 0; x < width; x++) {                                                     \
            lo[x] = lo2[x] < lo[x] ? lo2[x] : lo[x];                                               \
            hi[x] = hi2[x] > hi[x] ? hi2[x] : hi[x];                                               \
        }                                                                                          \
    }

DEFINE_MERGE(uint8_t, merge_u8)
DEFINE_MERGE(int16_t, merge_i16)

/* Rows [y0, y1] of a slice reduced into lo and hi, three at a time (a last group of one or two
 * repeats a row). */
#define DEFINE_SLICE_BAND(T, A, ROWS3, NAME)                                                  \
    static void NAME(A *lo, A *hi, const unsigned char *slice, size_t row_bytes, uint32_t y0, \
                     uint32_t y1, uint32_t width, int init)                                   \
    {                                                                                         \
        for (uint32_t y = y0; y <= y1; y += 3, init = 0) {                                    \
            uint32_t y_b = y + 1 <= y1 ? y + 1 : y1, y_c = y + 2 <= y1 ? y + 2 : y1;          \
            ROWS3(lo, hi, (const T *)(slice + y * row_bytes),                                 \
                  (const T *)(slice + y_b * row_bytes), (const T *)(slice + y_c * row_bytes), \
                  width, init);                                                               \
        }                                                                                     \
    }

DEFINE_SLICE_BAND(uint8_t, uint8_t, rows3_u8, slice_band_u8)
DEFINE_SLICE_BAND(uint16_t, int16_t, rows3_u16, slice_band_u16)
DEFINE_SLICE_BAND(int16_t, int16_t, rows3_i16, slice_band_i16)

/* Brick row `by` band by band, y bands outer: band (cy, cz) reduces rows [y0, y1] of slices
 * [z0, z1] into lo/hi, then each sub-block of each brick of the row takes its stretch of them.
 * Slice z1 is reduced on its own (into lo2/hi2) and merged, and starts band cz + 1 as it is:
 * each slice of the band is read once. */
#define DEFINE_BRICK_ROW(A, SLICE, MERGE, OUT, NAME)                                            \
    static void NAME(const ip__layer_rows *v, uint32_t by, A *rows, float *ranges)              \
    {                                                                                           \
        uint32_t s = v->subblock_edge, per = v->brick_edge / s, w = v->dims[0];                 \
        size_t sub = (size_t)per * per * per;                                                   \
        A *lo = rows, *hi = rows + w, *lo2 = rows + 2 * (size_t)w, *hi2 = rows + 3 * (size_t)w; \
        for (uint32_t cy = 0; cy < per; cy++) {                                                 \
            uint32_t y0 = by * v->brick_edge + cy * s;                                          \
            uint32_t y1 = y0 + s < v->dims[1] - 1 ? y0 + s : v->dims[1] - 1;                    \
            int carried = 0; /* lo2/hi2 hold slice z0 of this band */                           \
            for (uint32_t cz = 0; cz < per; cz++) {                                             \
                uint32_t z0 = cz * s, z1 = z0 + s < v->depth - 1 ? z0 + s : v->depth - 1;       \
                int empty = y0 >= v->dims[1] - 1 || z0 >= v->depth - 1;                         \
                if (!empty) {                                                                   \
                    if (carried) {                                                              \
                        A *t = lo;                                                              \
                        lo = lo2, lo2 = t, t = hi, hi = hi2, hi2 = t;                           \
                    } else {                                                                    \
                        SLICE(lo, hi, v->planes[z0], v->row_bytes, y0, y1, w, 1);               \
                    }                                                                           \
                    for (uint32_t z = z0 + 1; z < z1; z++)                                      \
                        SLICE(lo, hi, v->planes[z], v->row_bytes, y0, y1, w, 0);                \
                    SLICE(lo2, hi2, v->planes[z1], v->row_bytes, y0, y1, w, 1);                 \
                    MERGE(lo, hi, lo2, hi2, w);                                                 \
                    carried = 1;                                                                \
                }                                                                               \
                for (uint32_t bx = 0; bx < v->bricks[0]; bx++) {                                \
                    float *r = ranges + 2 * ((by * (size_t)v->bricks[0] + bx) * sub +           \
                                             ((size_t)cz * per + cy) * per);                    \
                    for (uint32_t cx = 0; cx < per; cx++) {                                     \
                        uint32_t x0 = bx * v->brick_edge + cx * s;                              \
                        uint32_t x1 = x0 + s < w - 1 ? x0 + s : w - 1;                          \
                        if (empty || x0 >= w - 1) {                                             \
                            r[2 * cx] = INFINITY;                                               \
                            r[2 * cx + 1] = -INFINITY;                                          \
                            continue;                                                           \
                        }                                                                       \
                        A mn = lo[x0], mx = hi[x0];                                             \
                        for (uint32_t x = x0 + 1; x <= x1; x++) {                               \
                            mn = lo[x] < mn ? lo[x] : mn;                                       \
                            mx = hi[x] > mx ? hi[x] : mx;                                       \
                        }                                                                       \
                        r[2 * cx] = (float)OUT(mn);                                             \
                        r[2 * cx + 1] = (float)OUT(mx);                                         \
                    }                                                                           \
                }                                                                               \
            }                                                                                   \
        }                                                                                       \
    }

DEFINE_BRICK_ROW(uint8_t, slice_band_u8, merge_u8, KEEP, brick_row_u8)
DEFINE_BRICK_ROW(int16_t, slice_band_u16, merge_i16, UNSHIFT_U16, brick_row_u16)
DEFINE_BRICK_ROW(int16_t, slice_band_i16, merge_i16, KEEP, brick_row_i16)

size_t ip__brick_row_scratch_bytes(uint32_t width, ip_type type)
{
    return 4 * (size_t)width * ip_type_size(type);
}

void ip__summarise_brick_row(const ip__layer_rows *layer, uint32_t by, void *scratch,
                             float *layer_ranges)
{
    IP_ASSERT(layer->type != IP_FLOAT32 && layer->depth >= 2 && layer->dims[0] >= 2);
    switch (layer->type) {
    case IP_UINT8: brick_row_u8(layer, by, scratch, layer_ranges); break;
    case IP_UINT16: brick_row_u16(layer, by, scratch, layer_ranges); break;
    case IP_INT16: brick_row_i16(layer, by, scratch, layer_ranges); break;
    case IP_FLOAT32: break;
    }
}

/* The sub-block ranges, one box at a time: float32 keeps this order of comparisons, so that
 * which of -0 and +0 a range holds does not change. */
static void box_ranges(const void *samples, ip_type type, const uint32_t extent[3],
                       uint32_t subblock_edge, uint32_t per_axis, float *ranges)
{
    uint32_t last[3] = {extent[0] - 1, extent[1] - 1, extent[2] - 1};
    size_t i = 0;
    for (uint32_t bz = 0; bz < per_axis; bz++)
        for (uint32_t by = 0; by < per_axis; by++)
            for (uint32_t bx = 0; bx < per_axis; bx++, i++) {
                uint32_t c[3] = {bx, by, bz}, lo[3], hi[3];
                int empty = 0;
                for (int a = 0; a < 3; a++) {
                    lo[a] = c[a] * subblock_edge;
                    hi[a] = lo[a] + subblock_edge;
                    if (lo[a] >= last[a])
                        empty = 1;
                    if (hi[a] > last[a])
                        hi[a] = last[a];
                }
                if (empty) {
                    ranges[2 * i] = INFINITY;
                    ranges[2 * i + 1] = -INFINITY;
                } else {
                    ip__box_range(samples, type, extent, lo, hi, &ranges[2 * i],
                                  &ranges[2 * i + 1]);
                }
            }
}

void ip__summarise_brick(const void *samples, ip_type type, const uint32_t extent[3],
                         uint32_t brick_edge, uint32_t subblock_edge, float brick_range[2],
                         float *ranges)
{
    check_shape(extent, brick_edge, subblock_edge);
    uint32_t per_axis = brick_edge / subblock_edge;
    if (type == IP_FLOAT32) {
        box_ranges(samples, type, extent, subblock_edge, per_axis, ranges);
        ip__union_range(ranges, (size_t)per_axis * per_axis * per_axis, brick_range);
        return;
    }
    /* an integer brick is a layer of one brick: its row 0 */
    const unsigned char *planes[IP_MAX_BRICK_EDGE + 1];
    size_t row_bytes = (size_t)extent[0] * ip_type_size(type);
    for (uint32_t z = 0; z < extent[2]; z++)
        planes[z] = (const unsigned char *)samples + (size_t)z * extent[1] * row_bytes;
    ip__layer_rows layer = {planes,    row_bytes, type,       {extent[0], extent[1]},
                            extent[2], {1, 1},    brick_edge, subblock_edge};
    /* ip__brick_row_scratch_bytes(extent[0], type): 4 rows of at most 2-byte samples */
    int16_t scratch[4 * (IP_MAX_BRICK_EDGE + 1)];
    IP_ASSERT(ip__brick_row_scratch_bytes(extent[0], type) <= sizeof scratch);
    ip__summarise_brick_row(&layer, 0, scratch, ranges);
    ip__union_range(ranges, (size_t)per_axis * per_axis * per_axis, brick_range);
}

/* The union of the ranges of the children of `node` at `depth` of `level`. */
static void node_range(const ip_layout *l, uint32_t level, uint32_t depth, const uint32_t node[3],
                       const uint32_t child_grid[3], const float *brick_ranges,
                       const float *node_ranges, float range[2])
{
    range[0] = INFINITY;
    range[1] = -INFINITY;
    for (int c = 0; c < 8; c++) {
        uint32_t ch[3] = {2 * node[0] + (c & 1), 2 * node[1] + ((c >> 1) & 1),
                          2 * node[2] + ((c >> 2) & 1)};
        if (ch[0] >= child_grid[0] || ch[1] >= child_grid[1] || ch[2] >= child_grid[2])
            continue;
        const float *r = depth == 1
                             ? &brick_ranges[2 * ip_brick_global_index(l, level, ch)]
                             : &node_ranges[2 * ip__octree_node_index(l, level, depth - 1, ch)];
        range[0] = fminf(range[0], r[0]);
        range[1] = fmaxf(range[1], r[1]);
    }
}

int ip__octree_walk(const ip_layout *l, const float *brick_ranges, const float *node_ranges,
                    ip_octree_node_fn visit, void *user)
{
    for (uint32_t k = 0; k < l->level_count; k++) {
        for (uint32_t depth = 1; depth <= l->levels[k].octree_depth; depth++) {
            uint32_t grid[3], child_grid[3];
            ip__octree_grid(l, k, depth, grid);
            ip__octree_grid(l, k, depth - 1, child_grid);
            for (uint32_t z = 0; z < grid[2]; z++)
                for (uint32_t y = 0; y < grid[1]; y++)
                    for (uint32_t x = 0; x < grid[0]; x++) {
                        uint32_t node[3] = {x, y, z};
                        float range[2];
                        node_range(l, k, depth, node, child_grid, brick_ranges, node_ranges, range);
                        int stop = visit(user, k, depth, node,
                                         ip__octree_node_index(l, k, depth, node), range);
                        if (stop)
                            return stop;
                    }
        }
    }
    return 0;
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* isoprop: the progressive order in which rays are cast over the screen.
 *
 * Every pixel of a width x height image is visited exactly once, coarse to fine, so that any
 * prefix of the order is spread evenly over the screen and extraction can stop at any time with a
 * usable result.
 *
 * Levels. Level k cuts the screen into a 2^k x 2^k grid of cells, a quadtree split: along x the
 * cell boundaries are floor(i * width / 2^k), i = 0..2^k, and likewise along y. Level k casts one
 * ray through the centre pixel of every cell, (floor((x0 + x1) / 2), floor((y0 + y1) / 2)) for a
 * cell covering columns [x0, x1) and rows [y0, y1). So ray 0 is the screen's centre pixel
 * (width / 2, height / 2), rays 1-4 are the centres of the 4 quadrants, the next 16 the centres
 * of the 16 sub-quadrants, and so on (fewer where a tiny image repeats a centre).
 * An axis stops splitting once its cells are one pixel wide, after ceil(log2(side)) levels, so a
 * 4096 x 1 image takes 12 levels of 2^k x 1 cells, not 4096 x 4096 cells. Empty cells (sides
 * that are not powers of two) and centres already cast at a coarser level are skipped. At the
 * last level every cell is at most one pixel, so every pixel is reached within the levels and
 * none is left for an extra pass.
 *
 * Within a level the cells are taken in ordered-dither (Bayer) order: the lowest two bits of
 * the position in the level choose the quadrant, the next two the sub-quadrant, and so on, with
 * the quadrants taken in the order (low x, low y), (high x, high y), (high x, low y),
 * (low x, high y). Consecutive rays therefore land far apart, and the first quarter of a level
 * is a regular lattice of every other cell, the first half a checkerboard.
 *
 * Local levels (optional, ip__ray_order_set_local_from()): from a chosen level on, the same
 * digits choose the finest split first instead of the coarsest, so that a level is walked in
 * Z-order: consecutive rays land in neighbouring cells, and a ray caster finds the data of the
 * ray before still in its caches. Every other local level, from the second, is walked
 * backward (its positions from the last to the first: each base-4 digit d read as 3 - d, each
 * single-axis bit b as 1 - b), so that it starts where the level before ended: the data a level
 * touched last, still in a least-recently-used cache, is what the next one needs first, and a
 * working set a little larger than the cache is read about once per two levels instead of once
 * per level. A level holds the same pixels either way; only their order within the level
 * changes, and the coarser levels keep their spread.
 *
 * Spread (asserted by tests/test_ray_order.c): after the first 4^k rays, levels 0..k-1 are
 * complete, so every pixel is within ceil(S / 2^k) pixels of a cast ray along each axis
 * (chessboard distance), S = max(width, height); for a square power-of-two image of side W that
 * is W / 2^k, and sqrt(2) * W / 2^k in Euclidean distance. Once level k is complete, every pixel
 * is within half a level-k cell of a cast ray along each axis.
 *
 * Cost: O(1) memory (the iterator is a struct of about 2 KiB, no allocation). The order
 * examines the cells of every level, about 3 per pixel (at most about 5, for sides just above a
 * power of two), each in amortised O(1) time. Each axis's spans and coarser centres of the cells
 * seen lately are remembered (IP__RAY_ORDER_MEMO slots per axis, by the cell's low bits; kept
 * across seeks within a level): in the Z-order of local levels a cell's column and row come
 * back many times in a row.
 * Thread safety: an iterator is used by one thread at a time; separate iterators are independent.
 */
#ifndef ISOPROP_RAY_ORDER_H
#define ISOPROP_RAY_ORDER_H

#include <stdint.h>

#include "isoprop/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#define IP_RAY_ORDER_MAX_SIDE (1u << 30) /* largest width or height accepted */

#define IP__RAY_ORDER_MEMO 64 /* cells of the current level remembered per axis: a power of two */

/* One axis's cells of the current level seen lately, in slot cell % IP__RAY_ORDER_MEMO. */
typedef struct ip__ray_order_memo {
    uint32_t cell[IP__RAY_ORDER_MEMO];    /* the cell in the slot; UINT32_MAX: none */
    uint32_t first[IP__RAY_ORDER_MEMO];   /* its pixels [first, end) along the axis */
    uint32_t end[IP__RAY_ORDER_MEMO];     /* (first == end: an empty cell) */
    uint32_t centres[IP__RAY_ORDER_MEMO]; /* cells of at most 2 pixels: the coarser levels whose
                                             cell along this axis had the same centre, as bits;
                                             0 for wider cells */
} ip__ray_order_memo;

/* The iterator. Owned by the caller (usually on its stack); its fields are private. */
typedef struct ip_ray_order {
    uint32_t width, height;
    uint32_t x_levels, y_levels; /* levels until a cell is at most one pixel along x, y */
    uint32_t level;              /* the level being walked (that of the last pixel returned) */
    uint64_t next_cell;          /* the position in the level of the next cell to examine */
    uint64_t level_base;         /* cells of the levels before `level` */
    uint32_t cell_x, cell_y;     /* that cell's column and row among the level's cells */
    uint64_t emitted;            /* pixels returned since init or reset */
    uint32_t local_from;         /* the first level walked in Z-order (UINT32_MAX: none) */
    ip__ray_order_memo memo[2];  /* x, y: cells of `level` seen lately */
} ip_ray_order;

/*! ip__ray_order_init() : prepares `order` to walk a width x height image from the beginning.
 *  width and height are in pixels, each in [1, IP_RAY_ORDER_MAX_SIDE].
 *  @return IP_OK, or IP_ERR_ARGUMENT for a NULL order or a side out of range (order untouched). */
ip_status ip__ray_order_init(ip_ray_order *order, uint32_t width, uint32_t height);

/*! ip__ray_order_next() : the next pixel of the order, x in [0, width), y in [0, height), with
 *  (0, 0) the first pixel of the first row (the axes' direction does not matter to the order).
 *  @return 1 and *x, *y set; or 0 once every pixel has been returned (and on every later call,
 *  until a reset), leaving *x and *y untouched. */
int ip__ray_order_next(ip_ray_order *order, uint32_t *x, uint32_t *y);

/*! ip__ray_order_count() : the number of pixels the order visits, width * height. */
uint64_t ip__ray_order_count(const ip_ray_order *order);

/*! ip__ray_order_emitted() : how many pixels next() has returned since init or the last reset. */
uint64_t ip__ray_order_emitted(const ip_ray_order *order);

/*! ip__ray_order_level() : the level of the pixel next() returned last (0 for the centre, k for
 *  the centres of the 4^k level-k cells); 0 before the first call. After the last pixel of level
 *  k, every pixel is within half a level-k cell of a cast ray along each axis. */
uint32_t ip__ray_order_level(const ip_ray_order *order);

/*! ip__ray_order_set_local_from() : walks level `level` and every finer level in Z-order (see
 *  "Local levels" above); UINT32_MAX, the default after init, walks every level in Bayer
 *  order. Call it before the first next() or after a reset; reset keeps the choice. */
void ip__ray_order_set_local_from(ip_ray_order *order, uint32_t level);

/*! ip__ray_order_last_level() : the finest level, whose cells are at most one pixel. */
uint32_t ip__ray_order_last_level(const ip_ray_order *order);

/* Cells. The order examines the cells of every level in turn, empty ones and those whose centre
 * was cast before included; cell i of that sequence is its *position*. The positions cut the
 * order into ranges that separate iterators can walk at once (one per thread), each from
 * ip__ray_order_seek() up to a bound given to ip__ray_order_next_before(): walking the ranges
 * [0, a), [a, b), ... [z, cells) one after the other returns exactly the pixels of next(), in
 * the same order. */

/*! ip__ray_order_cells() : the number of positions, over every level (>= width * height). */
uint64_t ip__ray_order_cells(const ip_ray_order *order);

/*! ip__ray_order_level_position() : the position of the first cell of `level`
 *  (ip__ray_order_cells() for a level past the last). */
uint64_t ip__ray_order_level_position(const ip_ray_order *order, uint32_t level);

/*! ip__ray_order_position() : the position of the next cell the iterator examines
 *  (ip__ray_order_cells() once it is done). */
uint64_t ip__ray_order_position(const ip_ray_order *order);

/*! ip__ray_order_seek() : moves the iterator to position `position` (at most
 *  ip__ray_order_cells()), in O(levels) time; emitted() is not changed. */
void ip__ray_order_seek(ip_ray_order *order, uint64_t position);

/*! ip__ray_order_next_before() : next(), but only from cells before position `end`: returns 0,
 *  with the iterator at `end` (or done), when no cell before `end` has a pixel left. */
int ip__ray_order_next_before(ip_ray_order *order, uint64_t end, uint32_t *x, uint32_t *y);

/* Blocks. In a local level the positions [m 4^k, (m + 1) 4^k) are the cells of one aligned
 * square of 2^k x 2^k cells (k up to the level's splits of the shorter axis), so a caller that
 * can account for all the pixels of such a square at once may move past it in one step. */

#define IP__RAY_ORDER_BLOCK_MAX 4 /* the largest k: blocks of at most 256 cells */

/*! ip__ray_order_block() : when the iterator stands at the first cell of an aligned block of
 *  4^k cells (k <= IP__RAY_ORDER_BLOCK_MAX) of a local level, the pixels next() would return
 *  from the block, in xs[0 .. *count), ys[0 .. *count) (4^k entries each at most, in another
 *  order than next()'s), and 1; else 0, nothing written. Does not move the iterator. */
int ip__ray_order_block(ip_ray_order *order, uint32_t k, uint32_t *xs, uint32_t *ys,
                        unsigned *count);

/*! ip__ray_order_skip_block() : moves past the block that ip__ray_order_block() described,
 *  its `count` pixels counted as returned (emitted()); the next pixel is the first after it. */
void ip__ray_order_skip_block(ip_ray_order *order, uint32_t k, unsigned count);

/*! ip__ray_order_reset() : starts the same order again from its first pixel. */
void ip__ray_order_reset(ip_ray_order *order);

#ifdef __cplusplus
}
#endif
#endif

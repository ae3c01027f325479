/* SPDX-License-Identifier: BSD-3-Clause */
/* Progressive ray order: a breadth-first quadtree over the screen, Bayer order within a level. */
#include "ray_order.h"

#include <string.h>

/* Levels needed until a side is cut into cells of at most one pixel: ceil(log2(side)). */
static uint32_t levels_for(uint32_t side)
{
    uint32_t levels = 0;
    while (((uint64_t)1 << levels) < side)
        levels++;
    return levels;
}

static uint32_t min_u32(uint32_t a, uint32_t b)
{
    return a < b ? a : b;
}

ip_status ip__ray_order_init(ip_ray_order *order, uint32_t width, uint32_t height)
{
    if (!order || width < 1 || height < 1 || width > IP_RAY_ORDER_MAX_SIDE ||
        height > IP_RAY_ORDER_MAX_SIDE)
        return IP_ERR_ARGUMENT;
    order->width = width;
    order->height = height;
    order->x_levels = levels_for(width);
    order->y_levels = levels_for(height);
    order->local_from = UINT32_MAX;
    ip__ray_order_reset(order);
    return IP_OK;
}

void ip__ray_order_set_local_from(ip_ray_order *order, uint32_t level)
{
    order->local_from = level;
}

uint32_t ip__ray_order_last_level(const ip_ray_order *order)
{
    return order->x_levels > order->y_levels ? order->x_levels : order->y_levels;
}

uint32_t ip__ray_order_level(const ip_ray_order *order)
{
    /* Once the order is done, level has moved one past the last. */
    uint32_t last = order->x_levels > order->y_levels ? order->x_levels : order->y_levels;
    return min_u32(order->level, last);
}

/* Empties the memo of both axes: their cells belong to the level just left. */
static void forget_cells(ip_ray_order *order)
{
    memset(order->memo[0].cell, 0xff, sizeof order->memo[0].cell);
    memset(order->memo[1].cell, 0xff, sizeof order->memo[1].cell);
}

void ip__ray_order_reset(ip_ray_order *order)
{
    forget_cells(order);
    order->level = 0;
    order->next_cell = 0;
    order->level_base = 0;
    order->cell_x = order->cell_y = 0;
    order->emitted = 0;
}

/* The cells of level `level`. */
static uint64_t level_cells(const ip_ray_order *order, uint32_t level)
{
    return (uint64_t)1 << (min_u32(level, order->x_levels) + min_u32(level, order->y_levels));
}

uint64_t ip__ray_order_level_position(const ip_ray_order *order, uint32_t level)
{
    uint64_t cells = 0;
    for (uint32_t k = 0; k < level && k <= ip__ray_order_last_level(order); k++)
        cells += level_cells(order, k);
    return cells;
}

uint64_t ip__ray_order_cells(const ip_ray_order *order)
{
    return ip__ray_order_level_position(order, ip__ray_order_last_level(order) + 1);
}

uint64_t ip__ray_order_position(const ip_ray_order *order)
{
    return order->level_base + order->next_cell;
}

uint64_t ip__ray_order_count(const ip_ray_order *order)
{
    return (uint64_t)order->width * order->height;
}

uint64_t ip__ray_order_emitted(const ip_ray_order *order)
{
    return order->emitted;
}

/* 1 when the current level is a local level walked backward: every other local level, from
 * the second, runs its Z-order from the end, so that it starts where the level before ended. */
static uint32_t backward(const ip_ray_order *order)
{
    return order->level >= order->local_from && ((order->level - order->local_from) & 1u);
}

static void set_bit(uint32_t *v, uint32_t bit, uint32_t value)
{
    *v = (*v & ~(1u << bit)) | value << bit;
}

/* Steps to the next cell of the level in Bayer order, keeping the cell's coordinates in step
 * with its position so that no cell is decoded from scratch (amortised O(1) per cell).
 *
 * Split s of the level (0 = coarsest) sets bit n - 1 - s of the cell index along each axis that
 * splits there (n being that axis's splits at this level), and is driven by the next low bits of
 * the position: a base-4 digit while both axes split, mapped so that 0, 1, 2, 3 visit
 * (low, low), (high, high), (high, low), (low, high); then one bit per split of the axis that
 * goes on. Counting up the position is a carry running from the coarsest split to finer ones. */
static void next_cell(ip_ray_order *order, uint32_t nx, uint32_t ny)
{
    static const uint8_t digit_x[4] = {0, 1, 1, 0};
    uint64_t position = ++order->next_cell;
    uint32_t both = min_u32(nx, ny), s = 0;
    int local = order->level >= order->local_from; /* finest split first: Z-order */
    uint32_t back = backward(order);
    for (; s < both; s++) {
        uint32_t digit = (uint32_t)(position >> 2 * s) & 3u;
        set_bit(&order->cell_x, local ? s : nx - 1 - s, digit_x[digit]);
        set_bit(&order->cell_y, local ? s : ny - 1 - s, (digit & 1u) ^ back);
        if (digit != 0)
            return;
    }
    uint32_t *cell = nx > both ? &order->cell_x : &order->cell_y;
    uint32_t splits = nx > both ? nx : ny;
    for (; s < splits; s++) {
        uint32_t bit = (uint32_t)(position >> (both + s)) & 1u;
        set_bit(cell, local ? s : splits - 1 - s, bit ^ back);
        if (bit)
            return;
    }
}

/* The pixel span [*first, *end) of cell `cell` when a side is cut into 2^splits cells. The
 * boundaries floor(i * side / 2^splits) of a level are among those of every finer level, so a
 * cell's span is the union of its children's. */
static void cell_span(uint32_t side, uint32_t splits, uint32_t cell, uint32_t *first, uint32_t *end)
{
    *first = (uint32_t)(((uint64_t)cell * side) >> splits);
    *end = (uint32_t)(((uint64_t)(cell + 1) * side) >> splits);
}

/* The coarser levels j < level at which pixel p, the centre of cell `cell` (cut into `splits`),
 * was already the centre of its enclosing cell along one axis that stops after `axis_levels`.
 *
 * Why the walk up can stop early: a cell's centre is the last pixel of its left child or the
 * first of its right child, and the split between the children is a boundary at every finer
 * level. So if p is the centre of a coarser cell, it is the first or last pixel of every cell
 * below that one on the way down to p's own. Once p is neither, no coarser cell can have it as
 * centre; on average the walk visits a couple of levels. */
static uint32_t centre_levels(uint32_t side, uint32_t axis_levels, uint32_t level, uint32_t splits,
                              uint32_t cell, uint32_t p)
{
    uint32_t found = 0;
    /* Levels at which this axis no longer splits kept this very cell. */
    for (uint32_t j = axis_levels; j < level; j++)
        found |= 1u << j;
    for (uint32_t up = 1; up <= splits; up++) {
        uint32_t first, end;
        cell_span(side, splits - up, cell >> up, &first, &end);
        if ((first + end) >> 1 == p)
            found |= 1u << (splits - up);
        if (p != first && p != end - 1)
            break;
    }
    return found;
}

/* The memo slot of cell `cell` of the current level along `axis` (0: x, 1: y), which the axis
 * cuts into 2^splits cells, filled by fill_slot() unless it holds the cell already: its span
 * and, for a cell of at most 2 pixels, the coarser levels whose cell had the same centre (a
 * centre cast before is the first or last pixel of this cell along both axes, see
 * centre_levels(), which needs cells at most 2 pixels wide). */
static void fill_slot(ip_ray_order *order, unsigned axis, uint32_t splits, uint32_t cell,
                      unsigned slot)
{
    ip__ray_order_memo *m = &order->memo[axis];
    uint32_t side = axis ? order->height : order->width, first, end;
    uint32_t axis_levels = axis ? order->y_levels : order->x_levels;
    cell_span(side, splits, cell, &first, &end);
    m->cell[slot] = cell;
    m->first[slot] = first;
    m->end[slot] = end;
    m->centres[slot] =
        end > first && end - first <= 2
            ? centre_levels(side, axis_levels, order->level, splits, cell, (first + end) >> 1)
            : 0;
}

static inline unsigned memo_slot(ip_ray_order *order, unsigned axis, uint32_t splits, uint32_t cell)
{
    unsigned slot = cell & (IP__RAY_ORDER_MEMO - 1);
    if (order->memo[axis].cell[slot] != cell)
        fill_slot(order, axis, splits, cell, slot);
    return slot;
}

/* The cell at `position` of the current level, decoded from scratch: every digit that
 * next_cell() sets on its way there. */
static void decode_cell(ip_ray_order *order, uint64_t position)
{
    static const uint8_t digit_x[4] = {0, 1, 1, 0};
    uint32_t nx = min_u32(order->level, order->x_levels),
             ny = min_u32(order->level, order->y_levels);
    uint32_t both = min_u32(nx, ny), s = 0;
    int local = order->level >= order->local_from;
    uint32_t back = backward(order);
    order->cell_x = order->cell_y = 0;
    for (; s < both; s++) {
        uint32_t digit = (uint32_t)(position >> 2 * s) & 3u;
        set_bit(&order->cell_x, local ? s : nx - 1 - s, digit_x[digit]);
        set_bit(&order->cell_y, local ? s : ny - 1 - s, (digit & 1u) ^ back);
    }
    uint32_t *cell = nx > both ? &order->cell_x : &order->cell_y;
    uint32_t splits = nx > both ? nx : ny;
    for (; s < splits; s++)
        set_bit(cell, local ? s : splits - 1 - s, ((uint32_t)(position >> (both + s)) & 1u) ^ back);
}

void ip__ray_order_seek(ip_ray_order *order, uint64_t position)
{
    uint32_t last_level = ip__ray_order_last_level(order), was = order->level;
    order->level = 0;
    order->level_base = 0;
    while (order->level <= last_level &&
           position - order->level_base >= level_cells(order, order->level)) {
        order->level_base += level_cells(order, order->level);
        order->level++;
    }
    order->next_cell = position - order->level_base;
    if (order->level != was) /* the memo holds cells of the level it was filled in */
        forget_cells(order);
    if (order->level <= last_level)
        decode_cell(order, order->next_cell);
    else
        order->cell_x = order->cell_y = 0;
}

int ip__ray_order_block(ip_ray_order *order, uint32_t k, uint32_t *xs, uint32_t *ys,
                        unsigned *count)
{
    uint32_t level = order->level;
    if (k > IP__RAY_ORDER_BLOCK_MAX || level > ip__ray_order_last_level(order) ||
        level < order->local_from)
        return 0;
    uint32_t nx = min_u32(level, order->x_levels), ny = min_u32(level, order->y_levels);
    uint64_t size = (uint64_t)1 << 2 * k;
    if (k > min_u32(nx, ny) || order->next_cell % size != 0 ||
        order->next_cell + size > (uint64_t)1 << (nx + ny))
        return 0;
    /* the block's low k bits of each cell index run through every value (local levels set
     * bit s of each index from digit s of the position) */
    uint32_t side = 1u << k, cx0 = order->cell_x & ~(side - 1), cy0 = order->cell_y & ~(side - 1);
    unsigned sx[1u << IP__RAY_ORDER_BLOCK_MAX], sy[1u << IP__RAY_ORDER_BLOCK_MAX];
    for (uint32_t i = 0; i < side; i++) {
        sx[i] = memo_slot(order, 0, nx, cx0 + i);
        sy[i] = memo_slot(order, 1, ny, cy0 + i);
    }
    const ip__ray_order_memo *mx = &order->memo[0], *my = &order->memo[1];
    unsigned n = 0;
    for (uint32_t j = 0; j < side; j++) {
        if (my->first[sy[j]] == my->end[sy[j]])
            continue;
        uint32_t y = (my->first[sy[j]] + my->end[sy[j]]) >> 1, centres = my->centres[sy[j]];
        for (uint32_t i = 0; i < side; i++)
            if (mx->first[sx[i]] != mx->end[sx[i]] && !(mx->centres[sx[i]] & centres)) {
                xs[n] = (mx->first[sx[i]] + mx->end[sx[i]]) >> 1;
                ys[n++] = y;
            }
    }
    *count = n;
    return 1;
}

void ip__ray_order_skip_block(ip_ray_order *order, uint32_t k, unsigned count)
{
    uint32_t nx = min_u32(order->level, order->x_levels),
             ny = min_u32(order->level, order->y_levels);
    order->next_cell += (uint64_t)1 << 2 * k;
    order->emitted += count;
    if (order->next_cell < (uint64_t)1 << (nx + ny))
        decode_cell(order, order->next_cell);
}

int ip__ray_order_next(ip_ray_order *order, uint32_t *x, uint32_t *y)
{
    return ip__ray_order_next_before(order, UINT64_MAX, x, y);
}

int ip__ray_order_next_before(ip_ray_order *order, uint64_t end, uint32_t *x, uint32_t *y)
{
    uint32_t last_level = order->x_levels > order->y_levels ? order->x_levels : order->y_levels;
    while (order->level <= last_level) {
        uint32_t level = order->level;
        uint32_t nx = min_u32(level, order->x_levels), ny = min_u32(level, order->y_levels);
        uint64_t level_end = (uint64_t)1 << (nx + ny), cells = level_end;
        if (end <= order->level_base)
            cells = 0;
        else if (end - order->level_base < level_end)
            cells = end - order->level_base;
        const ip__ray_order_memo *mx = &order->memo[0], *my = &order->memo[1];
        while (order->next_cell < cells) {
            uint32_t cx = order->cell_x, cy = order->cell_y;
            next_cell(order, nx, ny);
            unsigned sx = memo_slot(order, 0, nx, cx);
            if (mx->first[sx] == mx->end[sx])
                continue; /* an empty cell: the side is not a power of two */
            unsigned sy = memo_slot(order, 1, ny, cy);
            if (my->first[sy] == my->end[sy])
                continue;
            /* cast at a coarser level where both axes had this centre at the same level */
            if (mx->centres[sx] & my->centres[sy])
                continue;
            *x = (mx->first[sx] + mx->end[sx]) >> 1;
            *y = (my->first[sy] + my->end[sy]) >> 1;
            order->emitted++;
            return 1;
        }
        if (order->next_cell < level_end)
            return 0; /* stopped at `end` */
        order->level++;
        order->level_base += cells;
        order->next_cell = 0;
        forget_cells(order);
        if (order->level <= last_level)
            decode_cell(order, 0); /* (0, 0), or the far corner of a backward level */
    }
    return 0;
}

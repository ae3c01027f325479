/* Progressive ray order: a breadth-first quadtree over the screen, Bayer order within a level. */
#include "ray_order.h"

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

void ip__ray_order_reset(ip_ray_order *order)
{
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

uint64_t ip__ray_order_cells(const ip_ray_order *order)
{
    uint64_t cells = 0;
    for (uint32_t k = 0; k <= ip__ray_order_last_level(order); k++)
        cells += level_cells(order, k);
    return cells;
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
    static const uint8_t digit_x[4] = {0, 1, 1, 0}, digit_y[4] = {0, 1, 0, 1};
    uint64_t position = ++order->next_cell;
    uint32_t both = min_u32(nx, ny), s = 0;
    int local = order->level >= order->local_from; /* finest split first: Z-order */
    for (; s < both; s++) {
        uint32_t digit = (uint32_t)(position >> 2 * s) & 3u;
        set_bit(&order->cell_x, local ? s : nx - 1 - s, digit_x[digit]);
        set_bit(&order->cell_y, local ? s : ny - 1 - s, digit_y[digit]);
        if (digit != 0)
            return;
    }
    uint32_t *cell = nx > both ? &order->cell_x : &order->cell_y;
    uint32_t splits = nx > both ? nx : ny;
    for (; s < splits; s++) {
        uint32_t bit = (uint32_t)(position >> (both + s)) & 1u;
        set_bit(cell, local ? s : splits - 1 - s, bit);
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

/* Whether pixel (px, py), the centre of cell (cx, cy) of the current level, was cast already. */
static int cast_before(const ip_ray_order *order, uint32_t nx, uint32_t ny, uint32_t cx,
                       uint32_t cy, uint32_t px, uint32_t py)
{
    uint32_t level = order->level;
    uint32_t in_x = centre_levels(order->width, order->x_levels, level, nx, cx, px);
    if (in_x == 0)
        return 0;
    return (in_x & centre_levels(order->height, order->y_levels, level, ny, cy, py)) != 0;
}

/* The cell at `position` of the current level, decoded from scratch: every digit that
 * next_cell() sets on its way there. */
static void decode_cell(ip_ray_order *order, uint64_t position)
{
    static const uint8_t digit_x[4] = {0, 1, 1, 0}, digit_y[4] = {0, 1, 0, 1};
    uint32_t nx = min_u32(order->level, order->x_levels),
             ny = min_u32(order->level, order->y_levels);
    uint32_t both = min_u32(nx, ny), s = 0;
    int local = order->level >= order->local_from;
    order->cell_x = order->cell_y = 0;
    for (; s < both; s++) {
        uint32_t digit = (uint32_t)(position >> 2 * s) & 3u;
        set_bit(&order->cell_x, local ? s : nx - 1 - s, digit_x[digit]);
        set_bit(&order->cell_y, local ? s : ny - 1 - s, digit_y[digit]);
    }
    uint32_t *cell = nx > both ? &order->cell_x : &order->cell_y;
    uint32_t splits = nx > both ? nx : ny;
    for (; s < splits; s++)
        set_bit(cell, local ? s : splits - 1 - s, (uint32_t)(position >> (both + s)) & 1u);
}

void ip__ray_order_seek(ip_ray_order *order, uint64_t position)
{
    uint32_t last_level = ip__ray_order_last_level(order);
    order->level = 0;
    order->level_base = 0;
    while (order->level <= last_level &&
           position - order->level_base >= level_cells(order, order->level)) {
        order->level_base += level_cells(order, order->level);
        order->level++;
    }
    order->next_cell = position - order->level_base;
    if (order->level <= last_level)
        decode_cell(order, order->next_cell);
    else
        order->cell_x = order->cell_y = 0;
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
        while (order->next_cell < cells) {
            uint32_t cx = order->cell_x, cy = order->cell_y, x0, x1, y0, y1;
            next_cell(order, nx, ny);
            cell_span(order->width, nx, cx, &x0, &x1);
            cell_span(order->height, ny, cy, &y0, &y1);
            if (x0 == x1 || y0 == y1)
                continue; /* an empty cell: the side is not a power of two */
            uint32_t px = (x0 + x1) >> 1, py = (y0 + y1) >> 1;
            /* A centre cast before is the first or last pixel of this cell along both axes (see
             * centre_levels), which needs cells at most 2 pixels wide. */
            if (x1 - x0 <= 2 && y1 - y0 <= 2 && cast_before(order, nx, ny, cx, cy, px, py))
                continue;
            *x = px;
            *y = py;
            order->emitted++;
            return 1;
        }
        if (order->next_cell < level_end)
            return 0; /* stopped at `end` */
        order->level++;
        order->level_base += cells;
        order->next_cell = 0;
        order->cell_x = order->cell_y = 0;
    }
    return 0;
}

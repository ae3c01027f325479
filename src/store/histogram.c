/* SPDX-License-Identifier: BSD-3-Clause */
/* The histogram of one level's samples, and the sub-blocks each bin edge would cross. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "isoprop/histogram.h"

/* Distinct values of the integer types (uint8, uint16, int16): counted in a table first. */
#define VALUE_TABLE_SIZE 65536u
#define VALUE_TABLE_OFFSET 32768 /* int16's -32768 at index 0 */

uint32_t ip_histogram_default_level(const ip_layout *l, uint64_t max_samples)
{
    for (uint32_t k = 0; k < l->level_count; k++) {
        const uint32_t *d = l->levels[k].dims;
        if ((uint64_t)d[0] * d[1] * d[2] <= max_samples)
            return k;
    }
    return l->level_count ? l->level_count - 1 : 0;
}

/* Bin edges: count bins of `width` from lo; integer types get whole widths. */
static void plan_bins(const ip_layout *l, uint32_t requested, ip_histogram *h, double *width)
{
    double vmin = l->value_min, vmax = l->value_max;
    h->lo = vmin;
    h->hi = vmax;
    if (l->type != IP_FLOAT32) {
        double values = vmax - vmin + 1;
        *width = ceil(values / requested);
        h->bin_count = (uint32_t)ceil(values / *width);
        h->hi = vmin + *width * h->bin_count;
    } else if (vmax > vmin) {
        *width = (vmax - vmin) / requested;
        h->bin_count = requested;
    } else {
        *width = 0;
        h->bin_count = 1;
    }
    for (uint32_t i = 0; i < h->bin_count; i++) {
        h->bins[i].lo = vmin + *width * i;
        h->bins[i].hi = i + 1 == h->bin_count ? h->hi : vmin + *width * (i + 1);
    }
}

/* The bin of `v`, or bin_count for NaN. */
static uint32_t bin_of(const ip_histogram *h, double width, double v)
{
    if (v != v)
        return h->bin_count;
    if (width <= 0 || v <= h->lo)
        return 0;
    double i = floor((v - h->lo) / width);
    return i >= h->bin_count ? h->bin_count - 1 : (uint32_t)i;
}

/* The samples a brick owns: its extent less the + face layer, except on the volume's last
 * face, where no neighbour holds them. */
static void owned_samples(const ip_layout *l, uint32_t level, const uint32_t brick[3],
                          const uint32_t extent[3], uint32_t owned[3])
{
    for (int a = 0; a < 3; a++)
        owned[a] = extent[a] - 1 + (brick[a] + 1 == l->levels[level].bricks[a]);
}

/* Adds the owned samples of a decoded brick: integer types to the value table, float32 to the
 * bins (NaN to unbinned). */
static void count_brick(const ip_layout *l, const void *samples, const uint32_t extent[3],
                        const uint32_t owned[3], uint64_t *table, ip_histogram *h, double width)
{
    for (uint32_t z = 0; z < owned[2]; z++)
        for (uint32_t y = 0; y < owned[1]; y++) {
            size_t row = ((size_t)z * extent[1] + y) * extent[0];
            switch (l->type) {
            case IP_UINT8: {
                const uint8_t *p = (const uint8_t *)samples + row;
                for (uint32_t x = 0; x < owned[0]; x++)
                    table[p[x]]++;
                break;
            }
            case IP_UINT16: {
                const uint16_t *p = (const uint16_t *)samples + row;
                for (uint32_t x = 0; x < owned[0]; x++)
                    table[p[x]]++;
                break;
            }
            case IP_INT16: {
                const int16_t *p = (const int16_t *)samples + row;
                for (uint32_t x = 0; x < owned[0]; x++)
                    table[p[x] + VALUE_TABLE_OFFSET]++;
                break;
            }
            case IP_FLOAT32: {
                const float *p = (const float *)samples + row;
                for (uint32_t x = 0; x < owned[0]; x++) {
                    uint32_t i = bin_of(h, width, p[x]);
                    if (i < h->bin_count)
                        h->bins[i].count++;
                    else
                        h->unbinned++;
                }
                break;
            }
            }
        }
}

/* Moves the value table's counts into the bins (integer types). */
static void fold_table(const ip_layout *l, const uint64_t *table, ip_histogram *h, double width)
{
    int32_t first = l->type == IP_INT16 ? -VALUE_TABLE_OFFSET : 0;
    for (uint32_t i = 0; i < VALUE_TABLE_SIZE; i++)
        if (table[i])
            h->bins[bin_of(h, width, (double)(first + (int32_t)i))].count += table[i];
}

/* The first bin whose lower edge is > v (bin_count when none). */
static uint32_t first_edge_above(const ip_histogram *h, double v)
{
    uint32_t a = 0, b = h->bin_count;
    while (a < b) {
        uint32_t m = a + (b - a) / 2;
        if (h->bins[m].lo > v)
            b = m;
        else
            a = m + 1;
    }
    return a;
}

/* Counts, per bin, the level's sub-blocks with min < lo <= max, from the summaries: each
 * sub-block adds one to a run of bins, through a difference array. */
static ip_status count_active(const ip_store *s, uint32_t level, ip_histogram *h, ip_error *err)
{
    const ip_layout *l = ip_store_layout(s);
    const ip_level_layout *lv = &l->levels[level];
    uint32_t per_brick = ip_layout_subblocks_per_brick(l);
    int64_t *diff = calloc((size_t)h->bin_count + 1, sizeof *diff);
    if (!diff)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory for the histogram", ip_store_path(s));
    for (uint64_t g = lv->first_brick; g < lv->first_brick + lv->brick_count; g++) {
        const float *r = ip_store_subblock_ranges(s, g);
        for (uint32_t i = 0; i < per_brick; i++) {
            float lo = r[2 * i], hi = r[2 * i + 1];
            if (!(lo <= hi))
                continue; /* empty: no cells */
            h->subblocks++;
            if (lo == hi)
                continue;
            uint32_t a = first_edge_above(h, lo), b = first_edge_above(h, hi);
            diff[a]++;
            diff[b]--;
        }
    }
    int64_t run = 0;
    for (uint32_t i = 0; i < h->bin_count; i++) {
        run += diff[i];
        h->bins[i].active_subblocks = (uint64_t)run;
    }
    free(diff);
    return IP_OK;
}

static int compare_offsets(const void *a, const void *b)
{
    const uint64_t *x = a, *y = b;
    return x[0] < y[0] ? -1 : x[0] > y[0];
}

/* The level's bricks in the order of their payloads in the file (pairs offset, g): reading
 * them so streams the level front to back. */
static uint64_t *bricks_in_file_order(const ip_store *s, const ip_level_layout *lv)
{
    uint64_t *order = malloc(lv->brick_count * 2 * sizeof *order);
    if (!order)
        return NULL;
    for (uint64_t i = 0; i < lv->brick_count; i++) {
        ip_brick_entry e;
        ip_store_brick_entry(s, lv->first_brick + i, &e);
        order[2 * i] = e.offset;
        order[2 * i + 1] = lv->first_brick + i;
    }
    qsort(order, lv->brick_count, 2 * sizeof *order, compare_offsets);
    return order;
}

/* Reads (or, constant, looks up) every brick of the level and counts its owned samples. */
static ip_status count_samples(const ip_store *s, uint32_t level, ip_histogram *h, double width,
                               ip_error *err)
{
    const ip_layout *l = ip_store_layout(s);
    const ip_level_layout *lv = &l->levels[level];
    size_t edge = (size_t)l->brick_edge + 1;
    void *samples = malloc(edge * edge * edge * ip_type_size(l->type));
    void *work = malloc(ip_store_read_work_size(s));
    uint64_t *table = l->type != IP_FLOAT32 ? calloc(VALUE_TABLE_SIZE, sizeof *table) : NULL;
    uint64_t *order = bricks_in_file_order(s, lv);
    ip_status st = IP_OK;
    if (!samples || !work || !order || (l->type != IP_FLOAT32 && !table))
        st = ip__fail(err, IP_ERR_NOMEM, "%s: out of memory for the histogram", ip_store_path(s));
    for (uint64_t i = 0; st == IP_OK && i < lv->brick_count; i++) {
        uint64_t g = order[2 * i + 1];
        uint32_t k, brick[3], origin[3], extent[3], owned[3];
        ip_brick_coords(l, g, &k, brick);
        ip_brick_extent(l, level, brick, origin, extent);
        owned_samples(l, level, brick, extent, owned);
        ip_brick_entry e;
        ip_store_brick_entry(s, g, &e);
        if (e.encoding == IP_BRICK_CONSTANT) {
            float range[2];
            ip_store_brick_range(s, g, range);
            uint32_t b = bin_of(h, width, range[0]);
            uint64_t n = (uint64_t)owned[0] * owned[1] * owned[2];
            if (b < h->bin_count)
                h->bins[b].count += n;
            else
                h->unbinned += n;
            h->bricks_constant++;
            continue;
        }
        if (i + 8 < lv->brick_count)
            ip_store_prefetch_brick(s, order[2 * (i + 8) + 1]);
        st = ip_store_read_brick(s, g, samples, work, err);
        if (st == IP_OK) {
            count_brick(l, samples, extent, owned, table, h, width);
            h->bricks_read++;
        }
    }
    if (st == IP_OK && table)
        fold_table(l, table, h, width);
    free(order);
    free(table);
    free(work);
    free(samples);
    return st;
}

static ip_status check_arguments(const ip_store *s, uint32_t level, uint32_t bins, ip_error *err)
{
    const ip_layout *l = ip_store_layout(s);
    if (level >= l->level_count)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: level %u is past the pyramid (levels 0 .. %u)",
                        ip_store_path(s), level, l->level_count - 1);
    if (bins < 1 || bins > IP_HISTOGRAM_MAX_BINS)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: %u bins is not within 1 .. %u", ip_store_path(s),
                        bins, IP_HISTOGRAM_MAX_BINS);
    if (!isfinite(l->value_min) || !isfinite(l->value_max))
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "%s: the value range %g .. %g is not finite: no histogram",
                        ip_store_path(s), (double)l->value_min, (double)l->value_max);
    return IP_OK;
}

ip_status ip_histogram_compute(const ip_store *s, uint32_t level, uint32_t bins, ip_histogram **out,
                               ip_error *err)
{
    ip_status st = check_arguments(s, level, bins, err);
    if (st != IP_OK)
        return st;
    const ip_layout *l = ip_store_layout(s);
    ip_histogram *h = calloc(1, sizeof *h);
    if (h)
        h->bins = calloc(bins, sizeof *h->bins);
    if (!h || !h->bins) {
        ip_histogram_free(h);
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory for the histogram", ip_store_path(s));
    }
    const uint32_t *d = l->levels[level].dims;
    h->level = level;
    h->samples = (uint64_t)d[0] * d[1] * d[2];
    double width;
    plan_bins(l, bins, h, &width);
    st = count_samples(s, level, h, width, err);
    if (st == IP_OK)
        st = count_active(s, level, h, err);
    if (st != IP_OK) {
        ip_histogram_free(h);
        return st;
    }
    *out = h;
    return IP_OK;
}

void ip_histogram_free(ip_histogram *h)
{
    if (h) {
        free(h->bins);
        free(h);
    }
}

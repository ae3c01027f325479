/* SPDX-License-Identifier: BSD-3-Clause */
/* DICOM input: the geometry of one series (dicom_folder.h). Its slices sorted along their
 * normal, the steps between them (none repeated; even, or resampled when asked), a gantry
 * tilt (slices that stack off their normal, each shifted in its plane: resampled by default),
 * the regular grid the series is read on, and the resampling of the slices onto it, one plane
 * at a time from at most two slices. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dicom_folder.h"
#include "internal.h"

/* Slices closer together than this share a position (mm, and a fraction of the median
 * spacing); a step over MISSING_STEP median spacings is a missing slice; steps may differ from
 * the median by UNEVEN_TOLERANCE of it (positions are written with a few decimals). */
#define DUPLICATE_MM 1e-4
#define DUPLICATE_FRACTION 0.01
#define MISSING_STEP 1.5
#define UNEVEN_TOLERANCE 0.01
/* Slices whose in-plane offsets from the first stay under this fraction of a pixel (or under
 * TILT_MM without a pixel spacing) stack along their normal: the rest is rounding. */
#define TILT_PIXELS 0.05
#define TILT_MM 0.01
/* A resampled grid may be at most this many times the slices' own along each axis. */
#define GRID_GROWTH 4
/* Fractions of a sample closer than this to a whole one are that sample. */
#define SNAP 1e-6

static double dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

void ip__dicom_grid_free(dicom_grid *g)
{
    free(g->offsets);
    g->offsets = NULL;
}

/* x along the rows (ImageOrientationPatient's first vector), y along the columns (made
 * perpendicular to x: the files agree only to a tolerance), z their cross product; the
 * origin the first slice's position (LPS). */
static void frame(const dicom_slice *first, ip_orientation *o)
{
    double *x = o->directions[0], *y = o->directions[1], *z = o->directions[2];
    ip_orientation_identity(o);
    memcpy(o->origin, first->position, sizeof o->origin);
    o->space = IP_SPACE_LPS;
    memcpy(x, first->orientation, 3 * sizeof *x);
    memcpy(y, first->orientation + 3, 3 * sizeof *y);
    double n = sqrt(dot(x, x));
    for (int c = 0; c < 3; c++)
        x[c] /= n;
    double along = dot(x, y);
    for (int c = 0; c < 3; c++)
        y[c] -= along * x[c];
    n = sqrt(dot(y, y)); /* the slices' orientation was checked near unit length */
    for (int c = 0; c < 3; c++)
        y[c] /= n;
    z[0] = x[1] * y[2] - x[2] * y[1];
    z[1] = x[2] * y[0] - x[0] * y[2];
    z[2] = x[0] * y[1] - x[1] * y[0];
}

static int by_position(const void *a, const void *b)
{
    double pa = ((const dicom_slice *)a)->along, pb = ((const dicom_slice *)b)->along;
    return (pa > pb) - (pa < pb);
}

static int by_value(const void *a, const void *b)
{
    double pa = *(const double *)a, pb = *(const double *)b;
    return (pa > pb) - (pa < pb);
}

/* The steps between neighbouring slices (sorted): their median and smallest. */
static ip_status step_stats(const dicom_series *s, double *median, double *least, ip_error *err)
{
    double *steps = malloc((size_t)(s->count - 1) * sizeof *steps);
    if (!steps)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory ordering the slices", s->folder);
    for (uint64_t i = 0; i + 1 < s->count; i++)
        steps[i] = s->slices[i + 1].along - s->slices[i].along;
    qsort(steps, (size_t)(s->count - 1), sizeof *steps, by_value);
    *median = steps[(s->count - 1) / 2];
    *least = steps[0];
    free(steps);
    return IP_OK;
}

/* The first uneven step (a slice missing: over MISSING_STEP medians; else over
 * UNEVEN_TOLERANCE off the median), refused naming the choice that resamples; a repeated
 * slice refused in any case. *uneven 1 when there is one and `uneven` resamples it. */
static ip_status check_steps(const dicom_series *s, double median, ip_regrid uneven, int *is_uneven,
                             ip_error *err)
{
    static const char *const option = "isobrick --even-spacing resamples them onto an even grid";
    *is_uneven = 0;
    for (uint64_t i = 0; i + 1 < s->count; i++) {
        const dicom_slice *a = &s->slices[i], *b = &s->slices[i + 1];
        double step = b->along - a->along;
        if (step < DUPLICATE_MM || step < DUPLICATE_FRACTION * median)
            return ip__fail(err, IP_ERR_INPUT,
                            "%s: %s and %s are at the same position (%g mm along the slice "
                            "normal): a slice repeated",
                            s->folder, a->name, b->name, a->along);
        if (fabs(step - median) <= UNEVEN_TOLERANCE * median || *is_uneven)
            continue;
        if (uneven == IP_REGRID_RESAMPLE) {
            *is_uneven = 1;
            continue;
        }
        if (step > MISSING_STEP * median)
            return ip__fail(err, IP_ERR_INPUT,
                            "%s: a slice is missing between %s (at %g mm) and %s (at %g mm): %g "
                            "mm apart, %.1f times the slice spacing %g mm (%s)",
                            s->folder, a->name, a->along, b->name, b->along, step, step / median,
                            median, option);
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: uneven slice spacing: %s (at %g mm) and %s (at %g mm) are %g mm "
                        "apart, the others %g mm (%s)",
                        s->folder, a->name, a->along, b->name, b->along, step, median, option);
    }
    return IP_OK;
}

/* Each slice's in-plane offset from the first into g->offsets; g->tilt_degrees and *tilted
 * (offsets past TILT_PIXELS of a pixel). */
static ip_status find_tilt(const dicom_series *s, const ip_orientation *o, dicom_grid *g,
                           int *tilted, ip_error *err)
{
    const dicom_slice *first = &s->slices[0], *last = &s->slices[s->count - 1];
    g->offsets = malloc((size_t)s->count * 2 * sizeof *g->offsets);
    if (!g->offsets)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory placing the slices", s->folder);
    *tilted = 0;
    for (uint64_t i = 0; i < s->count; i++) {
        double d[3];
        for (int c = 0; c < 3; c++)
            d[c] = s->slices[i].position[c] - first->position[c];
        for (int a = 0; a < 2; a++) {
            double offset = dot(d, o->directions[a]);
            double limit =
                first->has_pixel_spacing ? TILT_PIXELS * first->pixel_spacing[1 - a] : TILT_MM;
            g->offsets[2 * i + a] = offset;
            *tilted |= fabs(offset) > limit;
        }
    }
    double *end = &g->offsets[2 * (s->count - 1)];
    g->tilt_degrees =
        *tilted ? atan2(hypot(end[0], end[1]), last->along - first->along) * 180 / M_PI : 0;
    return IP_OK;
}

/* A tilt refused: as asked, or without a pixel spacing to resample by. */
static ip_status refuse_tilt(const dicom_series *s, const dicom_grid *g, const char *why,
                             ip_error *err)
{
    const double *end = &g->offsets[2 * (s->count - 1)];
    double steps = (double)(s->count - 1);
    return ip__fail(err, IP_ERR_INPUT,
                    "%s: gantry tilt: the slices stack %.3g degrees off their normal, shifted "
                    "(%.3g, %.3g) mm a slice along their rows and columns: %s",
                    s->folder, g->tilt_degrees, end[0] / steps, end[1] / steps, why);
}

/* The planes along the normal: one a slice, or (uneven) as many as the smallest step needs,
 * evenly from the first slice to the last. */
static void plan_planes(const dicom_series *s, double least, dicom_grid *g)
{
    double extent = s->slices[s->count - 1].along - s->slices[0].along;
    double planes = (double)s->count;
    if (g->resampled & IP_RESAMPLED_UNEVEN)
        planes = ceil(extent / least - SNAP) + 1;
    g->dims[2] = planes < 4.0 * GRID_GROWTH * (double)s->count ? (uint32_t)planes : UINT32_MAX;
    g->spacing[2] = extent / (planes - 1);
}

/* The grid's extent along in-plane axis a (0 rows, 1 columns): from the first slice's samples,
 * whole samples out to cover every slice, its offsets considered. */
static void plan_axis(const dicom_series *s, dicom_grid *g, int a, uint32_t samples)
{
    double step = g->spacing[a], low = 0, high = 0;
    for (uint64_t i = 0; i < s->count; i++) {
        double offset = g->offsets[2 * i + a];
        low = offset < low ? offset : low;
        high = offset > high ? offset : high;
    }
    g->start[a] = step * floor(low / step + SNAP);
    double end = high + (samples - 1) * step;
    double count = ceil((end - g->start[a]) / step - SNAP) + 1;
    g->dims[a] = count < (double)GRID_GROWTH * samples + 1 ? (uint32_t)count : UINT32_MAX;
}

/* The resampled grid (g->resampled set): its size, spacing and origin. */
static ip_status plan_resampled(const dicom_series *s, double least, dicom_grid *g, ip_error *err)
{
    const dicom_slice *first = &s->slices[0];
    uint32_t own[3] = {first->columns, first->rows, (uint32_t)s->count};
    plan_planes(s, least, g);
    if (!(g->resampled & IP_RESAMPLED_TILT))
        memset(g->offsets, 0, (size_t)s->count * 2 * sizeof *g->offsets); /* rounding only */
    plan_axis(s, g, 0, first->columns);
    plan_axis(s, g, 1, first->rows);
    for (int a = 0; a < 3; a++)
        if (g->dims[a] > (uint64_t)GRID_GROWTH * own[a])
            return ip__fail(err, IP_ERR_INPUT,
                            "%s: %s: the regular grid would take %s%u samples along %c, over %d "
                            "times the slices' %u: not resampled (are the positions right?)",
                            s->folder,
                            g->resampled & IP_RESAMPLED_TILT ? "gantry tilt" : "uneven spacing",
                            g->dims[a] == UINT32_MAX ? "over " : "",
                            g->dims[a] == UINT32_MAX ? GRID_GROWTH * own[a] : g->dims[a], "xyz"[a],
                            GRID_GROWTH, own[a]);
    for (int c = 0; c < 3; c++)
        g->orientation.origin[c] += g->start[0] * g->orientation.directions[0][c] +
                                    g->start[1] * g->orientation.directions[1][c];
    return IP_OK;
}

/* Positions and orientations that are numbers (a DS value may read as "nan" or "inf"). */
static ip_status check_finite(const dicom_series *s, ip_error *err)
{
    for (uint64_t i = 0; i < s->count; i++) {
        const dicom_slice *slice = &s->slices[i];
        int finite = 1;
        for (int c = 0; c < 6; c++)
            finite &= isfinite(slice->orientation[c]) && (c >= 3 || isfinite(slice->position[c]));
        if (!finite)
            return ip__fail(err, IP_ERR_INPUT,
                            "%s/%s: Image Position (Patient) or Image Orientation (Patient) is "
                            "not finite",
                            s->folder, slice->name);
    }
    return IP_OK;
}

ip_status ip__dicom_grid_plan(dicom_series *s, ip_regrid tilt, ip_regrid uneven, dicom_grid *g,
                              ip_error *err)
{
    double median = 0, least = 0;
    int is_uneven = 0, tilted = 0;
    ip_status st;
    memset(g, 0, sizeof *g);
    if (s->count < 2)
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: the folder holds one DICOM slice (%s): a volume needs 2 or more",
                        s->folder, s->slices[0].name);
    if ((st = check_finite(s, err)) != IP_OK)
        return st;
    frame(&s->slices[0], &g->orientation);
    for (uint64_t i = 0; i < s->count; i++)
        s->slices[i].along = dot(s->slices[i].position, g->orientation.directions[2]);
    qsort(s->slices, (size_t)s->count, sizeof *s->slices, by_position);
    const dicom_slice *first = &s->slices[0];
    memcpy(g->orientation.origin, first->position, sizeof g->orientation.origin);
    if ((st = step_stats(s, &median, &least, err)) != IP_OK ||
        (st = check_steps(s, median, uneven, &is_uneven, err)) != IP_OK ||
        (st = find_tilt(s, &g->orientation, g, &tilted, err)) != IP_OK)
        return st;
    if (tilted && tilt == IP_REGRID_REFUSE)
        return refuse_tilt(s, g,
                           "refused as asked (isobrick --correct-tilt resamples them onto a "
                           "regular grid)",
                           err);
    if (tilted && !first->has_pixel_spacing)
        return refuse_tilt(s, g, "the series lacks Pixel Spacing (0028,0030) to resample them by",
                           err);
    g->resampled = (tilted ? IP_RESAMPLED_TILT : 0) | (is_uneven ? IP_RESAMPLED_UNEVEN : 0);
    g->spacing[0] = first->has_pixel_spacing ? first->pixel_spacing[1] : 1;
    g->spacing[1] = first->has_pixel_spacing ? first->pixel_spacing[0] : 1;
    if (g->resampled)
        return plan_resampled(s, least, g, err);
    g->dims[0] = first->columns;
    g->dims[1] = first->rows;
    g->dims[2] = (uint32_t)s->count;
    g->spacing[2] = (s->slices[s->count - 1].along - first->along) / (double)(s->count - 1);
    return IP_OK;
}

/* ---- resampling ---- */

ip_status ip__dicom_resampler_init(dicom_resampler *r, const dicom_series *s, const dicom_grid *g,
                                   ip_error *err)
{
    const dicom_slice *first = &s->slices[0];
    size_t bytes = (size_t)first->columns * first->rows * ip_type_size(first->type);
    memset(r, 0, sizeof *r);
    r->s = s;
    r->g = g;
    r->slot_of[0] = r->slot_of[1] = UINT64_MAX;
    r->slot[0] = malloc(bytes);
    r->slot[1] = malloc(bytes);
    if (!r->slot[0] || !r->slot[1])
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory resampling the slices", s->folder);
    return IP_OK;
}

void ip__dicom_resampler_free(dicom_resampler *r)
{
    free(r->slot[0]);
    free(r->slot[1]);
    r->slot[0] = r->slot[1] = NULL;
}

static double sample_at(const unsigned char *src, ip_type type, size_t i)
{
    switch (type) {
    case IP_UINT8: return src[i];
    case IP_UINT16: return ((const uint16_t *)(const void *)src)[i];
    case IP_INT16: return ((const int16_t *)(const void *)src)[i];
    default: return 0; /* DICOM input has no other type */
    }
}

/* v rounded to the nearest sample of `type` (within its range: v lies between samples). */
static void store_at(unsigned char *dst, ip_type type, size_t i, double v)
{
    double lo = type == IP_INT16 ? -32768.0 : 0.0, hi = type == IP_UINT8 ? 255.0 : 65535.0;
    v = floor(v + 0.5);
    v = v < lo ? lo : v > (type == IP_INT16 ? 32767.0 : hi) ? (type == IP_INT16 ? 32767.0 : hi) : v;
    if (type == IP_UINT8)
        dst[i] = (unsigned char)v;
    else if (type == IP_UINT16)
        ((uint16_t *)(void *)dst)[i] = (uint16_t)v;
    else
        ((int16_t *)(void *)dst)[i] = (int16_t)v;
}

/* Slice `index` into a slot (decoding it unless held), keeping slice `keep`; the slot's
 * samples into *out. The first slice's lowest sample becomes the background. */
static ip_status hold(dicom_resampler *r, uint64_t index, uint64_t keep, dicom_decode_fn decode,
                      void *user, const unsigned char **out, ip_error *err)
{
    for (int k = 0; k < 2; k++)
        if (r->slot_of[k] == index) {
            *out = r->slot[k];
            return IP_OK;
        }
    int k = keep != UINT64_MAX && r->slot_of[0] == keep ? 1 : 0;
    r->slot_of[k] = UINT64_MAX;
    ip_status st = decode(user, index, r->slot[k], err);
    if (st != IP_OK)
        return st;
    r->slot_of[k] = index;
    *out = r->slot[k];
    if (index == 0) {
        const dicom_slice *first = &r->s->slices[0];
        size_t n = (size_t)first->columns * first->rows;
        r->background = sample_at(r->slot[k], first->type, 0);
        for (size_t i = 1; i < n; i++) {
            double v = sample_at(r->slot[k], first->type, i);
            r->background = v < r->background ? v : r->background;
        }
    }
    return IP_OK;
}

/* Where a slice is sampled for the grid's samples: grid sample (i, j) falls on the slice's
 * (i + whole[0] + part[0], j + whole[1] + part[1]). */
typedef struct placement {
    const unsigned char *samples;
    long whole[2];
    double part[2];
    double weight;
} placement;

static void place(const dicom_resampler *r, uint64_t index, double weight, placement *p)
{
    for (int a = 0; a < 2; a++) {
        double at = (r->g->start[a] - r->g->offsets[2 * index + a]) / r->g->spacing[a];
        double whole = floor(at + SNAP);
        p->whole[a] = (long)whole;
        p->part[a] = at - whole < SNAP ? 0 : at - whole;
    }
    p->weight = weight;
}

/* Bilinear sample of slice p at grid sample (i, j); outside the slice, the background. */
static double bilinear(const dicom_resampler *r, const placement *p, long i, long j)
{
    const dicom_slice *first = &r->s->slices[0];
    long w = (long)first->columns, h = (long)first->rows;
    double sum = 0;
    for (int dy = 0; dy < 2; dy++)
        for (int dx = 0; dx < 2; dx++) {
            double f = (dx ? p->part[0] : 1 - p->part[0]) * (dy ? p->part[1] : 1 - p->part[1]);
            if (f == 0)
                continue;
            long x = i + p->whole[0] + dx, y = j + p->whole[1] + dy;
            sum += f * (x >= 0 && x < w && y >= 0 && y < h
                            ? sample_at(p->samples, first->type, (size_t)y * (size_t)w + (size_t)x)
                            : r->background);
        }
    return sum;
}

ip_status ip__dicom_resample_plane(dicom_resampler *r, uint32_t z, void *dst,
                                   dicom_decode_fn decode, void *user, ip_error *err)
{
    const dicom_series *s = r->s;
    const dicom_grid *g = r->g;
    uint64_t k = z;
    double t = 0;
    if (g->resampled & IP_RESAMPLED_UNEVEN) {
        double a = s->slices[0].along + z * g->spacing[2];
        while (r->next + 2 < s->count && s->slices[r->next + 1].along <= a)
            r->next++;
        k = r->next;
        t = (a - s->slices[k].along) / (s->slices[k + 1].along - s->slices[k].along);
        t = t < SNAP ? 0 : t > 1 - SNAP ? 1 : t;
        if (t == 1)
            k++, t = 0;
    }
    placement p[2];
    int used = t > 0 ? 2 : 1;
    ip_status st = hold(r, k, used == 2 ? k + 1 : UINT64_MAX, decode, user, &p[0].samples, err);
    if (st == IP_OK && used == 2)
        st = hold(r, k + 1, k, decode, user, &p[1].samples, err);
    if (st != IP_OK)
        return st;
    place(r, k, 1 - t, &p[0]);
    if (used == 2)
        place(r, k + 1, t, &p[1]);
    ip_type type = s->slices[0].type;
    for (uint32_t j = 0; j < g->dims[1]; j++)
        for (uint32_t i = 0; i < g->dims[0]; i++) {
            double v = 0;
            for (int q = 0; q < used; q++)
                v += p[q].weight * bilinear(r, &p[q], i, j);
            store_at(dst, type, (size_t)j * g->dims[0] + i, v);
        }
    return IP_OK;
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* DICOM input: a folder (its subfolders included) holding one or more series of single-frame
 * DICOM files, one file a z-plane. The files' headers and pixels are read through
 * dicom_gdcm.h; which files count and the series they make are dicom_folder.c's, the geometry
 * (order along the slice normal, steps, a gantry tilt, the regular grid and the resampling
 * onto it) dicom_grid.c's. Here: one file's fields (type, spacing, position, rescale) and the
 * slices alike, the description, the list of a folder's series, and the source of the
 * planes. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dicom_check.h"
#include "dicom_folder.h"
#include "dicom_gdcm.h"
#include "internal.h"
#include "readers.h"
#include "text_header.h"

/* Row and column directions must be unit vectors at right angles, to this tolerance. */
#define ORIENTATION_TOLERANCE 1e-3

/* ---- one file's header ---- */

/* `value` as a message shows it: control characters (a value may hold any byte) as '?', so
 * that every message stays one line. Returns out. */
static const char *shown(const char *value, char out[IP_DICOM_VALUE_MAX])
{
    size_t i = 0;
    for (; value[i] && i + 1 < IP_DICOM_VALUE_MAX; i++)
        out[i] = (unsigned char)value[i] < 0x20 || value[i] == 0x7F ? '?' : value[i];
    out[i] = '\0';
    return out;
}

const char *ip__dicom_shown(const char *value, char out[IP_DICOM_VALUE_MAX])
{
    return shown(value, out);
}

/* The numbers of a '\'-separated value; *count as ip__text_parse_double_list. */
static int parse_numbers(const char *value, double *out, int max, int *count)
{
    char text[IP_DICOM_VALUE_MAX];
    snprintf(text, sizeof text, "%s", value);
    for (char *c = text; *c; c++)
        if (*c == '\\')
            *c = ' ';
    return ip__text_parse_double_list(text, out, max, count);
}

static const char *const field_names[IP_DICOM_FIELD_COUNT] = {
    [IP_DICOM_TRANSFER_SYNTAX] = "Transfer Syntax UID (0002,0010)",
    [IP_DICOM_SERIES_UID] = "Series Instance UID (0020,000E)",
    [IP_DICOM_MODALITY] = "Modality (0008,0060)",
    [IP_DICOM_SERIES_DESCRIPTION] = "Series Description (0008,103E)",
    [IP_DICOM_POSITION] = "Image Position (Patient) (0020,0032)",
    [IP_DICOM_ORIENTATION] = "Image Orientation (Patient) (0020,0037)",
    [IP_DICOM_SAMPLES_PER_PIXEL] = "Samples per Pixel (0028,0002)",
    [IP_DICOM_PHOTOMETRIC] = "Photometric Interpretation (0028,0004)",
    [IP_DICOM_FRAMES] = "Number of Frames (0028,0008)",
    [IP_DICOM_ROWS] = "Rows (0028,0010)",
    [IP_DICOM_COLUMNS] = "Columns (0028,0011)",
    [IP_DICOM_PIXEL_SPACING] = "Pixel Spacing (0028,0030)",
    [IP_DICOM_BITS_ALLOCATED] = "Bits Allocated (0028,0100)",
    [IP_DICOM_BITS_STORED] = "Bits Stored (0028,0101)",
    [IP_DICOM_HIGH_BIT] = "High Bit (0028,0102)",
    [IP_DICOM_PIXEL_REPRESENTATION] = "Pixel Representation (0028,0103)",
    [IP_DICOM_RESCALE_INTERCEPT] = "Rescale Intercept (0028,1052)",
    [IP_DICOM_RESCALE_SLOPE] = "Rescale Slope (0028,1053)",
    [IP_DICOM_RESCALE_TYPE] = "Rescale Type (0028,1054)",
};

/* `count` numbers of field `f` into out (`fallback` for each when the field is absent and
 * `fallback` is not NaN). */
static ip_status field_numbers(const char *path, const ip_dicom_header *h, ip_dicom_field f,
                               double *out, int count, double fallback, ip_error *err)
{
    int got = 0;
    const char *value = h->value[f];
    char text[IP_DICOM_VALUE_MAX];
    if (value[0] == '\0' && !isnan(fallback)) {
        for (int i = 0; i < count; i++)
            out[i] = fallback;
        return IP_OK;
    }
    if (value[0] == '\0')
        return ip__fail(err, IP_ERR_INPUT, "%s: lacks %s", path, field_names[f]);
    if (parse_numbers(value, out, count, &got) != 0 || got != count)
        return ip__fail(err, IP_ERR_INPUT, "%s: bad %s '%.80s' (%d number%s expected)", path,
                        field_names[f], shown(value, text), count, count == 1 ? "" : "s");
    return IP_OK;
}

/* Whole numbers 0 .. 65535 (the fields read this way are 16-bit). */
static ip_status field_count(const char *path, const ip_dicom_header *h, ip_dicom_field f,
                             double fallback, uint32_t *out, ip_error *err)
{
    double value;
    char text[IP_DICOM_VALUE_MAX];
    *out = 0;
    ip_status st = field_numbers(path, h, f, &value, 1, fallback, err);
    if (st != IP_OK)
        return st;
    if (value != floor(value) || value < 0 || value > 65535)
        return ip__fail(err, IP_ERR_INPUT, "%s: bad %s '%.80s'", path, field_names[f],
                        shown(h->value[f], text));
    *out = (uint32_t)value;
    return IP_OK;
}

static ip_status check_syntax(const char *path, const ip_dicom_header *h, ip_error *err)
{
    char text[IP_DICOM_VALUE_MAX];
    const char *uid = shown(h->value[IP_DICOM_TRANSFER_SYNTAX], text);
    if (uid[0] == '\0')
        return ip__fail(err, IP_ERR_INPUT, "%s: lacks %s", path,
                        field_names[IP_DICOM_TRANSFER_SYNTAX]);
    if (!h->syntax_known)
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "%s: unknown transfer syntax %.80s: its pixel data cannot be decoded", path,
                        uid);
    if (!h->syntax_decodable)
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "%s: unsupported transfer syntax %.80s (%s): no decoder for it", path, uid,
                        h->syntax_name);
    return IP_OK;
}

/* One grey value a pixel, not inverted, one frame a file. */
static ip_status check_pixels(const char *path, const ip_dicom_header *h, ip_error *err)
{
    uint32_t samples, frames;
    char text[IP_DICOM_VALUE_MAX];
    const char *photometric = h->value[IP_DICOM_PHOTOMETRIC];
    ip_status st;
    if ((st = field_count(path, h, IP_DICOM_SAMPLES_PER_PIXEL, 1, &samples, err)) != IP_OK ||
        (st = field_count(path, h, IP_DICOM_FRAMES, 1, &frames, err)) != IP_OK)
        return st;
    if (samples != 1)
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "%s: %u samples a pixel (colour): only grey images are supported", path,
                        samples);
    if (strcmp(photometric, "MONOCHROME1") == 0)
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "%s: MONOCHROME1 (white is the lowest value) is not supported, only "
                        "MONOCHROME2",
                        path);
    if (photometric[0] != '\0' && strcmp(photometric, "MONOCHROME2") != 0)
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "%s: photometric interpretation %.40s is not supported, only MONOCHROME2",
                        path, shown(photometric, text));
    if (frames > 1)
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "%s: %u frames in one file: only single-frame files are supported", path,
                        frames);
    return IP_OK;
}

/* 8-bit unsigned, 16-bit unsigned or signed, and where the bits lie (Bits Stored, High Bit). */
static ip_status read_type(const char *path, const ip_dicom_header *h, dicom_slice *slice,
                           ip_error *err)
{
    uint32_t bits, stored, representation, high;
    ip_type *out = &slice->type;
    ip_status st;
    if ((st = field_count(path, h, IP_DICOM_BITS_ALLOCATED, NAN, &bits, err)) != IP_OK ||
        (st = field_count(path, h, IP_DICOM_BITS_STORED, bits, &stored, err)) != IP_OK ||
        (st = field_count(path, h, IP_DICOM_HIGH_BIT, stored ? stored - 1.0 : 0, &high, err)) !=
            IP_OK ||
        (st = field_count(path, h, IP_DICOM_PIXEL_REPRESENTATION, 0, &representation, err)) !=
            IP_OK)
        return st;
    if (bits == 8 && representation == 0)
        *out = IP_UINT8;
    else if (bits == 16)
        *out = representation ? IP_INT16 : IP_UINT16;
    else
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "%s: %u-bit %s samples are not supported (only 8-bit unsigned, 16-bit "
                        "unsigned or signed)",
                        path, bits, representation ? "signed" : "unsigned");
    if (stored == 0 || stored > bits)
        return ip__fail(err, IP_ERR_INPUT, "%s: %u bits stored in %u-bit samples", path, stored,
                        bits);
    if (high >= bits || high + 1 < stored)
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: High Bit %u does not hold %u bits stored in %u-bit samples", path,
                        high, stored, bits);
    slice->bits_stored = stored;
    slice->high_bit = high;
    return IP_OK;
}

static double dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static ip_status check_orientation(const char *path, const double o[6], ip_error *err)
{
    if (fabs(dot(o, o) - 1) > ORIENTATION_TOLERANCE ||
        fabs(dot(o + 3, o + 3) - 1) > ORIENTATION_TOLERANCE ||
        fabs(dot(o, o + 3)) > ORIENTATION_TOLERANCE)
        return ip__fail(err, IP_ERR_INPUT, "%s: %s is not two unit vectors at right angles", path,
                        field_names[IP_DICOM_ORIENTATION]);
    return IP_OK;
}

/* The unit of the rescaled values: the Rescale Type when it names one (1 to
 * IP_RESCALE_UNIT_MAX - 1 printable characters, other than US, "unspecified"), else "HU" for
 * a CT (whose rescale gives Hounsfield units), else "" (unknown). */
static void rescale_unit(const ip_dicom_header *h, char unit[IP_RESCALE_UNIT_MAX])
{
    const char *type = h->value[IP_DICOM_RESCALE_TYPE];
    size_t n = strlen(type);
    int usable = n > 0 && n < IP_RESCALE_UNIT_MAX && strcmp(type, "US") != 0;
    for (size_t i = 0; usable && i < n; i++)
        usable = type[i] >= 0x20 && type[i] <= 0x7e;
    if (usable)
        memcpy(unit, type, n + 1); /* n < IP_RESCALE_UNIT_MAX */
    else
        snprintf(unit, IP_RESCALE_UNIT_MAX, "%s",
                 strcmp(h->value[IP_DICOM_MODALITY], "CT") == 0 ? "HU" : "");
}

/* The geometry, type and rescale of one file (its header h), each checked on its own. */
ip_status ip__dicom_read_slice(const char *path, const ip_dicom_header *h, dicom_slice *slice,
                               ip_error *err)
{
    ip_status st;
    slice->has_pixel_spacing = h->value[IP_DICOM_PIXEL_SPACING][0] != '\0';
    if ((st = check_syntax(path, h, err)) != IP_OK || (st = check_pixels(path, h, err)) != IP_OK ||
        (st = read_type(path, h, slice, err)) != IP_OK ||
        (st = field_count(path, h, IP_DICOM_COLUMNS, NAN, &slice->columns, err)) != IP_OK ||
        (st = field_count(path, h, IP_DICOM_ROWS, NAN, &slice->rows, err)) != IP_OK ||
        (slice->has_pixel_spacing &&
         (st = field_numbers(path, h, IP_DICOM_PIXEL_SPACING, slice->pixel_spacing, 2, NAN, err)) !=
             IP_OK) ||
        (st = field_numbers(path, h, IP_DICOM_POSITION, slice->position, 3, NAN, err)) != IP_OK ||
        (st = field_numbers(path, h, IP_DICOM_ORIENTATION, slice->orientation, 6, NAN, err)) !=
            IP_OK ||
        (st = check_orientation(path, slice->orientation, err)) != IP_OK ||
        (st = field_numbers(path, h, IP_DICOM_RESCALE_SLOPE, &slice->slope, 1, 1, err)) != IP_OK)
        return st;
    st = field_numbers(path, h, IP_DICOM_RESCALE_INTERCEPT, &slice->intercept, 1, 0, err);
    rescale_unit(h, slice->unit);
    return st;
}
/* ---- the slices together ---- */

static int same_numbers(const double *a, const double *b, int count, double tolerance)
{
    for (int i = 0; i < count; i++)
        if (fabs(a[i] - b[i]) > tolerance)
            return 0;
    return 1;
}

/* What differs between `slice` and the first, or NULL when they are alike. */
static const char *difference(const dicom_slice *first, const dicom_slice *slice)
{
    if (slice->columns != first->columns || slice->rows != first->rows)
        return "a different size (rows, columns)";
    if (slice->type != first->type)
        return "a different sample type";
    if (slice->bits_stored != first->bits_stored || slice->high_bit != first->high_bit)
        return "a different bit layout (Bits Stored, High Bit)";
    if (slice->has_pixel_spacing != first->has_pixel_spacing ||
        (first->has_pixel_spacing &&
         !same_numbers(slice->pixel_spacing, first->pixel_spacing, 2, 1e-4)))
        return "a different pixel spacing";
    if (!same_numbers(slice->orientation, first->orientation, 6, ORIENTATION_TOLERANCE))
        return "a different orientation";
    if (slice->slope != first->slope || slice->intercept != first->intercept ||
        strcmp(slice->unit, first->unit) != 0)
        return "a different rescale";
    return NULL;
}

/* Slices alike: size, type, bit layout, pixel spacing, orientation, rescale (one volume, one
 * rescale). */
ip_status ip__dicom_check_alike(const dicom_series *s, ip_error *err)
{
    const dicom_slice *first = &s->slices[0];
    for (uint64_t i = 1; i < s->count; i++) {
        const dicom_slice *slice = &s->slices[i];
        const char *what = difference(first, slice);
        if (!what)
            continue;
        char path[IP_PATH_MAX];
        snprintf(path, sizeof path, "%s/%s", s->folder, slice->name);
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: mixed series: %s than %s (%ux%u %s, the first %ux%u %s)", path, what,
                        first->name, slice->columns, slice->rows, ip_type_name(slice->type),
                        first->columns, first->rows, ip_type_name(first->type));
    }
    return IP_OK;
}

/* A folder read, one series picked, its grid planned: what both describing and reading do. */
typedef struct dicom_read {
    dicom_folder folder;
    uint32_t picked;
    dicom_series series;
    dicom_grid grid;
} dicom_read;

static void read_free(dicom_read *r)
{
    ip__dicom_grid_free(&r->grid);
    free(r->series.slices);
    r->series.slices = NULL;
    ip__dicom_folder_free(&r->folder);
}

/* Scans `path`, picks the series `wanted` names (NULL: the one there is) and plans its grid
 * as `tilt` and `uneven` say. The caller frees r (also on failure). */
static ip_status read_series(const char *path, const char *wanted, ip_regrid tilt, ip_regrid uneven,
                             dicom_read *r, ip_error *err)
{
    ip_status st;
    memset(r, 0, sizeof *r);
    if ((st = ip__dicom_folder_scan(&r->folder, path, err)) != IP_OK ||
        (st = ip__dicom_folder_pick(&r->folder, wanted, &r->picked, err)) != IP_OK ||
        (st = ip__dicom_series_of(&r->folder, r->picked, &r->series, err)) != IP_OK)
        return st;
    return ip__dicom_grid_plan(&r->series, tilt, uneven, &r->grid, err);
}

/* ---- describing ---- */

/* `text` into out[size], cut to fit. */
static void copy_text(char *out, size_t size, const char *text)
{
    size_t n = strnlen(text, size - 1);
    memcpy(out, text, n);
    out[n] = '\0';
}

static void fill_desc(const dicom_read *r, const ip_input_overrides *overrides, ip_input_desc *desc,
                      ip_text_found *found)
{
    const dicom_slice *first = &r->series.slices[0];
    const dicom_grid *g = &r->grid;
    desc->encoding = IP_ENCODING_DICOM;
    desc->big_endian = 0; /* planes arrive in the host's order */
    desc->type = first->type;
    found->has_type = 1;
    found->has_dims = 1;
    for (int a = 0; a < 3; a++)
        found->dims[a] = g->dims[a];
    if (!ip__text_overridden(BY_SPACING, overrides))
        memcpy(desc->spacing, g->spacing, sizeof desc->spacing);
    desc->orientation = g->orientation;
    /* the identity without a unit says nothing worth keeping */
    desc->has_rescale = first->slope != 1.0 || first->intercept != 0.0 || first->unit[0] != '\0';
    desc->rescale_slope = first->slope;
    desc->rescale_intercept = first->intercept;
    memcpy(desc->rescale_unit, first->unit, sizeof desc->rescale_unit);
    copy_text(desc->series_uid, sizeof desc->series_uid, r->folder.series[r->picked].uid);
    desc->series_count = r->folder.series_count;
    desc->skipped_objects =
        (uint32_t)(r->folder.skipped < UINT32_MAX ? r->folder.skipped : UINT32_MAX);
    desc->source_slices = (uint32_t)r->series.count;
    desc->resampled = g->resampled;
    desc->tilt_degrees = g->tilt_degrees;
}

ip_status ip__dicom_describe(const char *path, const ip_input_overrides *overrides,
                             ip_input_desc *desc, ip_text_found *found, ip_error *err)
{
    dicom_read r;
    const char *wanted = overrides ? overrides->series : NULL;
    ip_regrid tilt = overrides ? overrides->tilt : IP_REGRID_DEFAULT;
    ip_regrid uneven = overrides ? overrides->uneven : IP_REGRID_DEFAULT;
    if ((unsigned)tilt > IP_REGRID_REFUSE || (unsigned)uneven > IP_REGRID_REFUSE)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: unknown ip_regrid %d in the overrides", path,
                        (unsigned)tilt > IP_REGRID_REFUSE ? (int)tilt : (int)uneven);
    ip_status st = read_series(path, wanted, tilt, uneven, &r, err);
    if (st == IP_OK && !r.series.slices[0].has_pixel_spacing &&
        !ip__text_overridden(BY_SPACING, overrides))
        st = ip__fail(err, IP_ERR_INPUT,
                      "%s: the series lacks Pixel Spacing (0028,0030) (give the spacing instead)",
                      path);
    if (st == IP_OK)
        fill_desc(&r, overrides, desc, found);
    read_free(&r);
    return st;
}

/* ---- listing ---- */

/* Series `index` of r->folder as an entry of the list: its grid as read by default, else its
 * problem and the grid it would be resampled onto when there is one. */
static void list_entry(dicom_read *r, uint32_t index, ip_dicom_series_info *out)
{
    const dicom_group *group = &r->folder.series[index];
    ip_error err;
    memset(out, 0, sizeof *out);
    copy_text(out->uid, sizeof out->uid, group->uid);
    copy_text(out->description, sizeof out->description, group->description);
    copy_text(out->modality, sizeof out->modality, group->modality);
    out->slices = (uint32_t)(group->files < UINT32_MAX ? group->files : UINT32_MAX);
    ip_status st = ip__dicom_series_of(&r->folder, index, &r->series, &err);
    if (st == IP_OK) {
        const dicom_slice *first = &r->series.slices[0];
        out->dims[0] = first->columns, out->dims[1] = first->rows, out->dims[2] = out->slices;
        out->type = first->type;
        st = ip__dicom_grid_plan(&r->series, IP_REGRID_DEFAULT, IP_REGRID_DEFAULT, &r->grid, &err);
        if (st != IP_OK) {
            ip__dicom_grid_free(&r->grid);
            copy_text(out->problem, sizeof out->problem, err.message);
            st = ip__dicom_grid_plan(&r->series, IP_REGRID_RESAMPLE, IP_REGRID_RESAMPLE, &r->grid,
                                     &err);
        }
    } else {
        copy_text(out->problem, sizeof out->problem, err.message);
    }
    if (st == IP_OK) {
        memcpy(out->dims, r->grid.dims, sizeof out->dims);
        memcpy(out->spacing, r->grid.spacing, sizeof out->spacing);
        out->resampled = r->grid.resampled;
        out->tilt_degrees = r->grid.tilt_degrees;
    }
    ip__dicom_grid_free(&r->grid);
    free(r->series.slices);
    r->series.slices = NULL;
}

ip_status ip__dicom_list(const char *folder, ip_dicom_series_info **out, uint32_t *count,
                         uint32_t *skipped, ip_error *err)
{
    dicom_read r;
    memset(&r, 0, sizeof r);
    ip_status st = ip__dicom_folder_scan(&r.folder, folder, err);
    ip_dicom_series_info *list = NULL;
    if (st == IP_OK && r.folder.series_count > 0 &&
        !(list = calloc(r.folder.series_count, sizeof *list)))
        st = ip__fail(err, IP_ERR_NOMEM, "%s: out of memory listing its series", folder);
    for (uint32_t i = 0; st == IP_OK && i < r.folder.series_count; i++)
        list_entry(&r, i, &list[i]);
    if (st == IP_OK) {
        *out = list;
        *count = r.folder.series_count;
        if (skipped)
            *skipped = (uint32_t)(r.folder.skipped < UINT32_MAX ? r.folder.skipped : UINT32_MAX);
    }
    read_free(&r);
    return st;
}

/* ---- the plane source ---- */

typedef struct dicom_source {
    char folder[IP_PATH_MAX];
    dicom_read read;
    dicom_resampler resampler;
    uint64_t slice_bytes;
} dicom_source;

/* The series must still be the one described: the same size, and samples of the same size
 * (a type override may read uint16 as int16, not as another size). */
static ip_status check_described(const dicom_source *src, const ip_input_desc *desc, ip_error *err)
{
    const dicom_slice *first = &src->read.series.slices[0];
    const uint32_t *dims = src->read.grid.dims;
    if (desc->dims[0] != dims[0] || desc->dims[1] != dims[1] || desc->dims[2] != dims[2] ||
        ip_type_size(desc->type) != ip_type_size(first->type))
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: the series holds %ux%ux%u %s samples, not the %ux%ux%u %s "
                        "described",
                        desc->path, dims[0], dims[1], dims[2], ip_type_name(first->type),
                        desc->dims[0], desc->dims[1], desc->dims[2], ip_type_name(desc->type));
    return IP_OK;
}

/* Reads the headers again: the description (a plain value, ip_input_desc) has no room for the
 * slices' order, and the second reading checks that the folder still holds the series
 * described (check_described()). Each header is read up to the pixel data only. The series is
 * the one described (by its UID), on the grid described: resampled as it was then, or not. */
static ip_status dicom_open(const ip_input_desc *desc, void **state, ip_error *err)
{
    dicom_source *src = calloc(1, sizeof *src);
    *state = src;
    if (!src)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory opening the series", desc->path);
    snprintf(src->folder, sizeof src->folder, "%s", desc->data_path);
    ip_regrid how = desc->resampled ? IP_REGRID_RESAMPLE : IP_REGRID_REFUSE;
    ip_status st = read_series(src->folder, desc->series_uid, how, how, &src->read, err);
    if (st != IP_OK || (st = check_described(src, desc, err)) != IP_OK)
        return st;
    const dicom_slice *first = &src->read.series.slices[0];
    src->slice_bytes = (uint64_t)first->columns * first->rows * ip_type_size(first->type);
    if (src->read.grid.resampled)
        return ip__dicom_resampler_init(&src->resampler, &src->read.series, &src->read.grid, err);
    return IP_OK;
}

/* Slice `index` (by position) decoded into dst, its file checked again first. */
static ip_status decode_slice(void *state, uint64_t index, void *dst, ip_error *err)
{
    dicom_source *src = state;
    const dicom_slice *slice = &src->read.series.slices[index];
    char path[IP_PATH_MAX], why[160];
    ip_dicom_image image;
    if (snprintf(path, sizeof path, "%s/%s", src->folder, slice->name) >= (int)sizeof path)
        return ip__fail(err, IP_ERR_INPUT, "%s: path too long", src->folder);
    /* checked again: the file may have changed since it was described */
    if (ip__dicom_check_file(path, why, sizeof why) != 0 ||
        ip__dicom_decode(path, dst, (size_t)src->slice_bytes, &image, why, sizeof why) != 0)
        return ip__fail(err, IP_ERR_INPUT, "%s: %s", path, why);
    if (image.columns != slice->columns || image.rows != slice->rows || image.frames != 1 ||
        image.samples_per_pixel != 1 || image.bytes != src->slice_bytes ||
        image.bits_allocated != 8 * ip_type_size(slice->type))
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: decodes to %ux%u pixels of %u bits, not the %ux%u of %zu bits its "
                        "header gave: the file changed?",
                        path, image.columns, image.rows, image.bits_allocated, slice->columns,
                        slice->rows, 8 * ip_type_size(slice->type));
    return IP_OK;
}

static ip_status dicom_read_plane(void *state, uint32_t z, void *dst, ip_error *err)
{
    dicom_source *src = state;
    if (src->read.grid.resampled)
        return ip__dicom_resample_plane(&src->resampler, z, dst, decode_slice, src, err);
    return decode_slice(src, z, dst, err);
}

static void dicom_close(void *state)
{
    dicom_source *src = state;
    if (!src)
        return;
    ip__dicom_resampler_free(&src->resampler);
    read_free(&src->read);
    free(src);
}

const ip__plane_source ip__dicom_source = {dicom_open, dicom_read_plane, dicom_close};

/* SPDX-License-Identifier: BSD-3-Clause */
/* DICOM input: a folder holding one series of single-frame DICOM files, one file a z-plane.
 * The files' headers and pixels are read through dicom_gdcm.h; everything else is here:
 * which files count, one series, slices alike, their order along the slice normal, an even
 * slice spacing (no slice missing or repeated), the type, spacing and rescale. */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "array.h"
#include "dicom_check.h"
#include "dicom_gdcm.h"
#include "readers.h"
#include "internal.h"

/* Slices closer together than this share a position (mm, and a fraction of the median
 * spacing); a step over MISSING_STEP median spacings is a missing slice; steps may differ from
 * the median by UNEVEN_TOLERANCE of it (positions are written with a few decimals). */
#define DUPLICATE_MM 1e-4
#define DUPLICATE_FRACTION 0.01
#define MISSING_STEP 1.5
#define UNEVEN_TOLERANCE 0.01
/* Row and column directions must be unit vectors at right angles, to this tolerance. */
#define ORIENTATION_TOLERANCE 1e-3

/* One file of the folder, as its header describes it. */
typedef struct dicom_slice {
    char name[256]; /* within the folder */
    char series[IP_DICOM_VALUE_MAX];
    uint32_t columns, rows;
    ip_type type;
    uint32_t bits_stored, high_bit; /* where the samples' bits lie in each pixel */
    int has_pixel_spacing;
    double pixel_spacing[2]; /* between rows (y), between columns (x); mm */
    double position[3], orientation[6];
    double slope, intercept;
    char unit[IP_RESCALE_UNIT_MAX]; /* of the rescaled values (rescale_unit()) */
    double along;                   /* position along the slice normal, mm */
} dicom_slice;

/* The slices of a folder: sorted by name while read, by position once checked. */
typedef struct dicom_series {
    const char *folder;
    dicom_slice *slices;
    uint64_t count, capacity;
} dicom_series;

static void series_free(dicom_series *s)
{
    free(s->slices);
    s->slices = NULL;
    s->count = s->capacity = 0;
}

/* folder/name into out; the caller has checked that the folder path leaves room. */
static void slice_path(const dicom_series *s, const dicom_slice *slice, char out[IP_PATH_MAX])
{
    snprintf(out, IP_PATH_MAX, "%.*s/%s", IP_PATH_MAX - 258, s->folder, slice->name);
}

/* ---- which files ---- */

/* Hidden files and the DICOMDIR index (a DICOM file without an image) are not slices. */
static int skipped_name(const char *name)
{
    return name[0] == '.' || strcmp(name, "DICOMDIR") == 0;
}

static int by_name(const void *a, const void *b)
{
    return strcmp(((const dicom_slice *)a)->name, ((const dicom_slice *)b)->name);
}

static ip_status add_name(dicom_series *s, const char *name, ip_error *err)
{
    if (ip__array_reserve(&s->slices, &s->capacity, s->count + 1, sizeof *s->slices, 64) != IP_OK)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory listing the folder", s->folder);
    dicom_slice *slice = &s->slices[s->count++];
    memset(slice, 0, sizeof *slice);
    snprintf(slice->name, sizeof slice->name, "%s", name);
    return IP_OK;
}

/* The folder's regular, visible files, by name. */
static ip_status list_files(dicom_series *s, ip_error *err)
{
    if (strlen(s->folder) > IP_PATH_MAX - 258)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: folder path too long", s->folder);
    DIR *dir = opendir(s->folder);
    if (!dir)
        return ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot open the folder", s->folder);
    ip_status st = IP_OK;
    struct dirent *entry;
    while (st == IP_OK && (entry = readdir(dir)) != NULL) {
        char full[IP_PATH_MAX];
        struct stat info;
        if (skipped_name(entry->d_name))
            continue;
        snprintf(full, sizeof full, "%s/%s", s->folder, entry->d_name);
        if (stat(full, &info) == 0 && S_ISREG(info.st_mode))
            st = add_name(s, entry->d_name, err);
    }
    closedir(dir);
    if (st == IP_OK && s->count == 0)
        st = ip__fail(err, IP_ERR_INPUT, "%s: the folder holds no DICOM files", s->folder);
    if (st == IP_OK)
        qsort(s->slices, (size_t)s->count, sizeof *s->slices, by_name);
    return st;
}

/* A file of a series folder must be DICOM Part 10: "DICM" after the 128-byte preamble. */
static ip_status check_magic(const char *path, ip_error *err)
{
    unsigned char head[132];
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot open", path);
    ssize_t got = pread(fd, head, sizeof head, 0);
    close(fd);
    if (got != (ssize_t)sizeof head || memcmp(head + 128, "DICM", 4) != 0)
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: not a DICOM file (no \"DICM\" at byte 128), in a folder of a DICOM "
                        "series",
                        path);
    return IP_OK;
}

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
    [IP_DICOM_MODALITY] = "Modality (0008,0060)",
    [IP_DICOM_SERIES_UID] = "Series Instance UID (0020,000E)",
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

/* The geometry, type and rescale of one file, each checked on its own. */
static ip_status read_slice(const dicom_series *s, dicom_slice *slice, ip_error *err)
{
    char path[IP_PATH_MAX], why[160];
    ip_dicom_header *h = malloc(sizeof *h);
    ip_status st;
    slice_path(s, slice, path);
    if (!h)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory reading its header", path);
    if ((st = check_magic(path, err)) != IP_OK)
        goto done;
    /* the structure first: the DICOM library stops the process on some malformed files */
    if (ip__dicom_check_file(path, why, sizeof why) != 0 ||
        ip__dicom_read_header(path, h, why, sizeof why) != 0) {
        st = ip__fail(err, IP_ERR_INPUT, "%s: %s", path, why);
        goto done;
    }
    snprintf(slice->series, sizeof slice->series, "%s", h->value[IP_DICOM_SERIES_UID]);
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
        goto done;
    st = field_numbers(path, h, IP_DICOM_RESCALE_INTERCEPT, &slice->intercept, 1, 0, err);
    rescale_unit(h, slice->unit);
done:
    free(h);
    return st;
}

/* ---- the slices together ---- */

/* Every file of one series: otherwise the count of series and their UIDs. */
static ip_status check_one_series(const dicom_series *s, ip_error *err)
{
    char list[600] = "", text[IP_DICOM_VALUE_MAX];
    size_t used = 0;
    uint64_t series = 0;
    for (uint64_t i = 0; i < s->count; i++) {
        uint64_t j = 0;
        while (j < i && strcmp(s->slices[j].series, s->slices[i].series) != 0)
            j++;
        if (j < i)
            continue; /* a series seen before */
        if (++series <= 4 && used < sizeof list)
            used += (size_t)snprintf(
                list + used, sizeof list - used, "%s%s", series > 1 ? ", " : "",
                s->slices[i].series[0] ? shown(s->slices[i].series, text) : "(none)");
    }
    if (series > 1)
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: the folder mixes %llu series (UIDs %s%s): it must hold one", s->folder,
                        (unsigned long long)series, list, series > 4 ? ", ..." : "");
    return IP_OK;
}

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
static ip_status check_alike(const dicom_series *s, ip_error *err)
{
    const dicom_slice *first = &s->slices[0];
    for (uint64_t i = 1; i < s->count; i++) {
        const dicom_slice *slice = &s->slices[i];
        const char *what = difference(first, slice);
        if (!what)
            continue;
        char path[IP_PATH_MAX];
        slice_path(s, slice, path);
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: mixed series: %s than %s (%ux%u %s, the first %ux%u %s)", path, what,
                        first->name, slice->columns, slice->rows, ip_type_name(slice->type),
                        first->columns, first->rows, ip_type_name(first->type));
    }
    return IP_OK;
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

/* Sorts the slices along the normal of their plane (row direction x column direction). */
static void sort_by_position(dicom_series *s)
{
    const double *o = s->slices[0].orientation;
    double normal[3] = {o[1] * o[5] - o[2] * o[4], o[2] * o[3] - o[0] * o[5],
                        o[0] * o[4] - o[1] * o[3]};
    for (uint64_t i = 0; i < s->count; i++)
        s->slices[i].along = dot(s->slices[i].position, normal);
    qsort(s->slices, (size_t)s->count, sizeof *s->slices, by_position);
}

/* The median distance between neighbouring slices (sorted). */
static ip_status median_step(const dicom_series *s, double *out, ip_error *err)
{
    double *steps = malloc((size_t)(s->count - 1) * sizeof *steps);
    if (!steps)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory ordering the slices", s->folder);
    for (uint64_t i = 0; i + 1 < s->count; i++)
        steps[i] = s->slices[i + 1].along - s->slices[i].along;
    qsort(steps, (size_t)(s->count - 1), sizeof *steps, by_value);
    *out = steps[(s->count - 1) / 2];
    free(steps);
    return IP_OK;
}

/* Neighbours `i` and `i + 1`, `step` mm apart, against the median step. */
static ip_status check_step(const dicom_series *s, uint64_t i, double step, double median,
                            ip_error *err)
{
    const dicom_slice *a = &s->slices[i], *b = &s->slices[i + 1];
    if (step < DUPLICATE_MM || step < DUPLICATE_FRACTION * median)
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: %s and %s are at the same position (%g mm along the slice normal): "
                        "a slice repeated",
                        s->folder, a->name, b->name, a->along);
    if (step > MISSING_STEP * median)
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: a slice is missing between %s (at %g mm) and %s (at %g mm): %g mm "
                        "apart, %.1f times the slice spacing %g mm",
                        s->folder, a->name, a->along, b->name, b->along, step, step / median,
                        median);
    if (fabs(step - median) > UNEVEN_TOLERANCE * median)
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: uneven slice spacing: %s (at %g mm) and %s (at %g mm) are %g mm "
                        "apart, the others %g mm",
                        s->folder, a->name, a->along, b->name, b->along, step, median);
    return IP_OK;
}

/* Even steps, none missing, none repeated; *spacing the mean step. */
static ip_status check_steps(const dicom_series *s, double *spacing, ip_error *err)
{
    double median = 0;
    ip_status st;
    if (s->count < 2)
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: the folder holds one DICOM slice (%s): a volume needs 2 or more",
                        s->folder, s->slices[0].name);
    if ((st = median_step(s, &median, err)) != IP_OK)
        return st;
    for (uint64_t i = 0; i + 1 < s->count; i++)
        if ((st = check_step(s, i, s->slices[i + 1].along - s->slices[i].along, median, err)) !=
            IP_OK)
            return st;
    *spacing = (s->slices[s->count - 1].along - s->slices[0].along) / (double)(s->count - 1);
    return IP_OK;
}

/* Lists, reads and checks the series in `folder`, its slices sorted by position; *spacing_z
 * the distance between them. The caller frees the series (also on failure). */
static ip_status scan_series(const char *folder, dicom_series *s, double *spacing_z, ip_error *err)
{
    ip_status st;
    memset(s, 0, sizeof *s);
    s->folder = folder;
    if ((st = list_files(s, err)) != IP_OK)
        return st;
    for (uint64_t i = 0; i < s->count; i++)
        if ((st = read_slice(s, &s->slices[i], err)) != IP_OK)
            return st;
    if ((st = check_one_series(s, err)) != IP_OK || (st = check_alike(s, err)) != IP_OK)
        return st;
    sort_by_position(s);
    return check_steps(s, spacing_z, err);
}

/* ---- describing ---- */

/* x along the rows (ImageOrientationPatient's first vector), y along the columns (made
 * perpendicular to x: the files agree only to ORIENTATION_TOLERANCE), z their cross product,
 * the way the slices were sorted; the origin is the first slice's ImagePositionPatient. */
static void fill_orientation(const dicom_slice *first, ip_orientation *o)
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
    n = sqrt(dot(y, y)); /* check_orientation keeps it near 1 */
    for (int c = 0; c < 3; c++)
        y[c] /= n;
    z[0] = x[1] * y[2] - x[2] * y[1];
    z[1] = x[2] * y[0] - x[0] * y[2];
    z[2] = x[0] * y[1] - x[1] * y[0];
}

static void fill_desc(const dicom_series *s, double spacing_z, const ip_input_overrides *overrides,
                      ip_input_desc *desc, ip_text_found *found)
{
    const dicom_slice *first = &s->slices[0];
    desc->encoding = IP_ENCODING_DICOM;
    desc->big_endian = 0; /* planes arrive in the host's order */
    desc->type = first->type;
    found->has_type = 1;
    found->has_dims = 1;
    found->dims[0] = first->columns;
    found->dims[1] = first->rows;
    found->dims[2] = s->count;
    if (!ip__text_overridden(BY_SPACING, overrides)) {
        desc->spacing[0] = first->pixel_spacing[1];
        desc->spacing[1] = first->pixel_spacing[0];
        desc->spacing[2] = spacing_z;
    }
    fill_orientation(first, &desc->orientation);
    /* the identity without a unit says nothing worth keeping */
    desc->has_rescale = first->slope != 1.0 || first->intercept != 0.0 || first->unit[0] != '\0';
    desc->rescale_slope = first->slope;
    desc->rescale_intercept = first->intercept;
    memcpy(desc->rescale_unit, first->unit, sizeof desc->rescale_unit);
}

ip_status ip__dicom_describe(const char *path, const ip_input_overrides *overrides,
                             ip_input_desc *desc, ip_text_found *found, ip_error *err)
{
    dicom_series s;
    double spacing_z = 0;
    ip_status st = scan_series(path, &s, &spacing_z, err);
    if (st == IP_OK && !s.slices[0].has_pixel_spacing &&
        !ip__text_overridden(BY_SPACING, overrides))
        st = ip__fail(err, IP_ERR_INPUT, "%s: the series lacks %s (give the spacing instead)", path,
                      field_names[IP_DICOM_PIXEL_SPACING]);
    if (st == IP_OK)
        fill_desc(&s, spacing_z, overrides, desc, found);
    series_free(&s);
    return st;
}

/* ---- the plane source ---- */

typedef struct dicom_source {
    char folder[IP_PATH_MAX];
    dicom_series series;
    uint64_t plane_bytes;
} dicom_source;

/* The series must still be the one described: the same size, and samples of the same size
 * (a type override may read uint16 as int16, not as another size). */
static ip_status check_described(const dicom_source *src, const ip_input_desc *desc, ip_error *err)
{
    const dicom_slice *first = &src->series.slices[0];
    if (desc->dims[0] != first->columns || desc->dims[1] != first->rows ||
        desc->dims[2] != src->series.count || ip_type_size(desc->type) != ip_type_size(first->type))
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: the series holds %ux%ux%llu %s samples, not the %ux%ux%u %s "
                        "described",
                        desc->path, first->columns, first->rows,
                        (unsigned long long)src->series.count, ip_type_name(first->type),
                        desc->dims[0], desc->dims[1], desc->dims[2], ip_type_name(desc->type));
    return IP_OK;
}

/* Reads the headers again: the description (a plain value, ip_input_desc) has no room for the
 * slices' order, and the second reading checks that the folder still holds the series
 * described (check_described()). Each header is read up to the pixel data only. */
static ip_status dicom_open(const ip_input_desc *desc, void **state, ip_error *err)
{
    double spacing_z;
    dicom_source *src = calloc(1, sizeof *src);
    *state = src;
    if (!src)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory opening the series", desc->path);
    snprintf(src->folder, sizeof src->folder, "%s", desc->data_path);
    ip_status st = scan_series(src->folder, &src->series, &spacing_z, err);
    if (st != IP_OK)
        return st;
    src->plane_bytes = (uint64_t)desc->dims[0] * desc->dims[1] * ip_type_size(desc->type);
    return check_described(src, desc, err);
}

static ip_status dicom_read_plane(void *state, uint32_t z, void *dst, ip_error *err)
{
    dicom_source *src = state;
    const dicom_slice *slice = &src->series.slices[z];
    char path[IP_PATH_MAX], why[160];
    ip_dicom_image image;
    slice_path(&src->series, slice, path);
    /* checked again: the file may have changed since it was described */
    if (ip__dicom_check_file(path, why, sizeof why) != 0 ||
        ip__dicom_decode(path, dst, (size_t)src->plane_bytes, &image, why, sizeof why) != 0)
        return ip__fail(err, IP_ERR_INPUT, "%s: %s", path, why);
    if (image.columns != slice->columns || image.rows != slice->rows || image.frames != 1 ||
        image.samples_per_pixel != 1 || image.bytes != src->plane_bytes ||
        image.bits_allocated != 8 * ip_type_size(slice->type))
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: decodes to %ux%u pixels of %u bits, not the %ux%u of %zu bits its "
                        "header gave: the file changed?",
                        path, image.columns, image.rows, image.bits_allocated, slice->columns,
                        slice->rows, 8 * ip_type_size(slice->type));
    return IP_OK;
}

static void dicom_close(void *state)
{
    dicom_source *src = state;
    if (!src)
        return;
    series_free(&src->series);
    free(src);
}

const ip__plane_source ip__dicom_source = {dicom_open, dicom_read_plane, dicom_close};

/* SPDX-License-Identifier: BSD-3-Clause */
/* Describing an input volume: format dispatch, the NAME_XxYxZ_TYPE.raw convention, overrides,
 * the checks made before any sample is read. */
#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "input_headers.h"
#include "input_positioned.h"
#include "input_source.h"
#include "internal.h"
#include "sized.h"
#include "isoprop/input.h"

/* Dims at or above this are refused, as ip_dims_parse() refuses them, so that every volume
 * a header or a name describes could also be described on the command line. */
#define IP_INPUT_DIM_LIMIT (UINT64_C(1) << 31)

typedef enum input_kind {
    INPUT_RAW,
    INPUT_NRRD,
    INPUT_MHD,
    INPUT_TIFF,
    INPUT_NIFTI,
    INPUT_HDF5
} input_kind;

static const char axis_names[3] = {'x', 'y', 'z'};

static int has_suffix(const char *text, const char *suffix)
{
    size_t n = strlen(text), m = strlen(suffix);
    return n >= m && strcasecmp(text + n - m, suffix) == 0;
}

static const char *base_name(const char *path)
{
    const char *slash = strrchr(path, '/');
    return slash ? slash + 1 : path;
}

/* The extension decides the format: a raw file's bytes cannot be told from anything else. */
static input_kind kind_of(const char *path)
{
    if (has_suffix(path, ".nrrd") || has_suffix(path, ".nhdr"))
        return INPUT_NRRD;
    if (has_suffix(path, ".mhd") || has_suffix(path, ".mha"))
        return INPUT_MHD;
    if (has_suffix(path, ".tif") || has_suffix(path, ".tiff"))
        return INPUT_TIFF;
    if (has_suffix(path, ".nii") || has_suffix(path, ".nii.gz"))
        return INPUT_NIFTI;
    if (has_suffix(path, ".h5") || has_suffix(path, ".hdf5") || has_suffix(path, ".he5"))
        return INPUT_HDF5;
    return INPUT_RAW;
}

const char *ip__input_format_named(const char *path)
{
    switch (kind_of(path)) {
    case INPUT_NRRD: return "an NRRD volume";
    case INPUT_MHD: return "a MetaImage volume";
    case INPUT_TIFF: return "a TIFF file";
    case INPUT_NIFTI: return "a NIfTI volume";
    case INPUT_HDF5: return "an HDF5 file";
    case INPUT_RAW: break;
    }
    return has_suffix(path, ".raw") ? "a raw volume" : NULL;
}

int ip__input_is_stdin(const char *path)
{
    return strcmp(path, "-") == 0;
}

ip_status ip__input_open_regular(const char *path, int *fd, ip_error *err)
{
    struct stat st;
    *fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (*fd < 0)
        return ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot open", path);
    if (fstat(*fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(*fd);
        *fd = -1;
        return ip__fail(err, IP_ERR_INPUT, "%s: not a regular file", path);
    }
    return IP_OK;
}

/* The input component's readers, by the format they read. */
typedef enum component_reader {
    READ_DICOM,
    READ_TIFF,
    READ_HDF5
} component_reader;

/* Describes `path` with one of the input component's readers. */
static ip_status describe_by_component(component_reader which, const char *path,
                                       const ip_input_overrides *overrides, ip_input_desc *desc,
                                       ip_text_found *found, ip_error *err)
{
    const ip__input_formats *formats;
    ip_status st = ip__input_formats_load(path, &formats, err);
    if (st != IP_OK)
        return st;
    ip__describe_fn describe = which == READ_TIFF   ? formats->tiff_describe
                               : which == READ_HDF5 ? formats->hdf5_describe
                                                    : formats->dicom_describe;
    return describe(path, overrides, desc, found, err);
}

/* 1 when the regular file `path` holds the HDF5 signature where a file may start it: at byte
 * 0, or after a user block of 512, 1024 or 2048 bytes. */
static int hdf5_signature(const char *path)
{
    static const unsigned char magic[8] = {0x89, 'H', 'D', 'F', '\r', '\n', 0x1a, '\n'};
    unsigned char head[8];
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC), found = 0;
    struct stat st;
    if (fd < 0)
        return 0;
    if (fstat(fd, &st) == 0 && S_ISREG(st.st_mode))
        for (off_t at = 0; !found && at <= 2048; at = at ? at * 2 : 512)
            found = pread(fd, head, sizeof head, at) == (ssize_t)sizeof head &&
                    memcmp(head, magic, sizeof magic) == 0;
    close(fd);
    return found;
}

/* ---- folders: a DICOM series or numbered TIFF files ---- */

/* Subfolders deeper than this are not searched for a first file (dicom_folder.c reads as
 * deep). */
#define FOLDER_DEPTH 16

static int visible_folder(const struct dirent *entry)
{
    return entry->d_name[0] != '.';
}

/* The alphabetically first visible regular file of the folder `path` into out, else the first
 * such file of its subfolders (taken in name order, not following links to folders); 0, or -1
 * when there is none. */
static int first_file_in(const char *path, int depth, char out[IP_PATH_MAX])
{
    DIR *dir = opendir(path);
    if (!dir)
        return -1;
    char best[256] = "";
    struct dirent *entry;
    while ((entry = readdir(dir)) != NULL) {
        struct stat st;
        char full[IP_PATH_MAX];
        if (entry->d_name[0] == '.' || (best[0] && strcmp(entry->d_name, best) >= 0))
            continue;
        if (snprintf(full, sizeof full, "%s/%s", path, entry->d_name) >= (int)sizeof full ||
            stat(full, &st) != 0 || !S_ISREG(st.st_mode))
            continue;
        snprintf(best, sizeof best, "%s", entry->d_name);
    }
    closedir(dir);
    if (best[0]) {
        snprintf(out, IP_PATH_MAX, "%s/%s", path, best);
        return 0;
    }
    struct dirent **names = NULL;
    int n = depth < FOLDER_DEPTH ? scandir(path, &names, visible_folder, alphasort) : -1,
        found = -1;
    for (int i = 0; i < n; i++) {
        struct stat st;
        char full[IP_PATH_MAX];
        if (found != 0 &&
            snprintf(full, sizeof full, "%s/%s", path, names[i]->d_name) < (int)sizeof full &&
            lstat(full, &st) == 0 && S_ISDIR(st.st_mode))
            found = first_file_in(full, depth + 1, out);
        free(names[i]);
    }
    free(names);
    return found;
}

/* The folder's first file (first_file_in()); IP_ERR_INPUT when there is none. */
static ip_status first_file_of(const char *path, char out[IP_PATH_MAX], ip_error *err)
{
    DIR *dir = opendir(path);
    if (!dir)
        return ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot open the folder", path);
    closedir(dir);
    if (first_file_in(path, 0, out) != 0)
        return ip__fail(err, IP_ERR_INPUT, "%s: the folder holds no files", path);
    return IP_OK;
}

/* A folder holding .zarray, .zattrs, .zgroup or zarr.json is a Zarr array or an OME-Zarr
 * image (the input component's Zarr reader). */
static int is_zarr_folder(const char *path)
{
    static const char *const names[] = {".zarray", ".zattrs", ".zgroup", "zarr.json"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        char full[IP_PATH_MAX + 16];
        struct stat st;
        snprintf(full, sizeof full, "%s/%s", path, names[i]);
        if (stat(full, &st) == 0 && S_ISREG(st.st_mode))
            return 1;
    }
    return 0;
}

/* A folder is a DICOM series when its first file has the DICOM preamble's "DICM" at byte
 * 128, numbered TIFF files when it starts as a TIFF ("II*\0", "MM\0*", or BigTIFF's 43). */
static ip_status describe_folder(const char *path, const ip_input_overrides *overrides,
                                 ip_input_desc *desc, ip_text_found *found, ip_error *err)
{
    char first[IP_PATH_MAX];
    unsigned char head[132];
    if (is_zarr_folder(path)) {
        const ip__input_formats *formats;
        ip_status zs = ip__input_formats_load(path, &formats, err);
        return zs != IP_OK ? zs : formats->zarr_describe(path, overrides, desc, found, err);
    }
    ip_status st = first_file_of(path, first, err);
    if (st != IP_OK)
        return st;
    int fd = open(first, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot open", first);
    ssize_t got = pread(fd, head, sizeof head, 0);
    close(fd);
    int dicom = got == (ssize_t)sizeof head && memcmp(head + 128, "DICM", 4) == 0;
    int tiff =
        got >= 4 &&
        ((head[0] == 'I' && head[1] == 'I' && (head[2] == 42 || head[2] == 43) && head[3] == 0) ||
         (head[0] == 'M' && head[1] == 'M' && head[2] == 0 && (head[3] == 42 || head[3] == 43)));
    if (dicom || tiff)
        return describe_by_component(tiff ? READ_TIFF : READ_DICOM, path, overrides, desc, found,
                                     err);
    return ip__fail(err, IP_ERR_INPUT,
                    "%s: a folder of neither DICOM nor TIFF files (its first file %s is "
                    "neither)",
                    path, first);
}

/* ---- the raw naming convention ---- */

/* 1 when text[0..len) is exactly DIGITS x DIGITS x DIGITS. */
static int looks_like_dims(const char *text, size_t len)
{
    int digits = 0, separators = 0;
    for (size_t i = 0; i < len; i++) {
        if (isdigit((unsigned char)text[i])) {
            digits++;
        } else if ((text[i] == 'x' || text[i] == 'X') && digits > 0 && separators < 2) {
            separators++;
            digits = 0;
        } else {
            return 0;
        }
    }
    return separators == 2 && digits > 0;
}

/* Parses a field that looks_like_dims() accepted; values too large for 64 bits saturate so
 * that the range check in validate_dims() reports them. */
static void parse_dims_field(const char *text, uint64_t dims[3])
{
    const char *p = text;
    for (int axis = 0; axis < 3; axis++) {
        uint64_t v = 0;
        for (; isdigit((unsigned char)*p); p++)
            v = v > UINT64_MAX / 16 ? UINT64_MAX : v * 10 + (uint64_t)(*p - '0');
        dims[axis] = v;
        p++; /* the 'x' */
    }
}

/* Takes dims and type from a base name NAME_XxYxZ_TYPE.raw (NAME may hold underscores; the
 * last two fields count). A name that does not follow the convention gives nothing; one that
 * does but names an unknown type is an error unless the type is overridden. */
static ip_status describe_from_name(const char *path, const ip_input_overrides *overrides,
                                    ip_input_desc *desc, ip_text_found *found, ip_error *err)
{
    const char *base = base_name(path);
    size_t len = strlen(base);
    if (!has_suffix(base, ".raw"))
        return IP_OK;
    len -= 4;
    const char *type_sep = memrchr(base, '_', len);
    if (!type_sep)
        return IP_OK;
    size_t dims_end = (size_t)(type_sep - base);
    const char *dims_sep = memrchr(base, '_', dims_end);
    size_t dims_start = dims_sep ? (size_t)(dims_sep - base) + 1 : 0;
    if (!looks_like_dims(base + dims_start, dims_end - dims_start))
        return IP_OK;

    if (!(overrides && overrides->has_dims)) {
        parse_dims_field(base + dims_start, found->dims);
        found->has_dims = 1;
    }
    if (!(overrides && overrides->has_type)) {
        char type_text[64];
        size_t type_len = len - dims_end - 1;
        if (type_len >= sizeof type_text)
            return ip__fail(err, IP_ERR_INPUT,
                            "%s: unknown type '%.*s' in the file name (use uint8, uint16, int16 "
                            "or float32)",
                            path, (int)type_len, type_sep + 1);
        memcpy(type_text, type_sep + 1, type_len);
        type_text[type_len] = '\0';
        if (ip_type_parse(type_text, &desc->type) != IP_OK)
            return ip__fail(err, IP_ERR_INPUT,
                            "%s: unknown type '%s' in the file name (use uint8, uint16, int16 "
                            "or float32)",
                            path, type_text);
        found->has_type = 1;
    }
    return IP_OK;
}

/* ---- overrides and checks ---- */

static void set_defaults(ip_input_desc *desc, const char *path)
{
    memset(desc, 0, sizeof *desc);
    snprintf(desc->path, sizeof desc->path, "%s", path);
    snprintf(desc->data_path, sizeof desc->data_path, "%s", path);
    desc->type = IP_UINT8;
    desc->encoding = IP_ENCODING_RAW;
    for (int axis = 0; axis < 3; axis++)
        desc->spacing[axis] = 1.0;
    desc->rescale_slope = 1.0;
    ip_orientation_identity(&desc->orientation);
}

static ip_status apply_overrides(const ip_input_overrides *overrides, ip_input_desc *desc,
                                 ip_text_found *found, ip_error *err)
{
    if (!overrides)
        return IP_OK;
    if (overrides->has_dims) {
        for (int axis = 0; axis < 3; axis++)
            found->dims[axis] = overrides->dims[axis];
        found->has_dims = 1;
    }
    if (overrides->has_type) {
        if (ip_type_size(overrides->type) == 0)
            return ip__fail(err, IP_ERR_ARGUMENT, "%s: unknown type %d in the overrides",
                            desc->path, (int)overrides->type);
        desc->type = overrides->type;
        found->has_type = 1;
    }
    if (overrides->has_endian)
        desc->big_endian = overrides->big_endian ? 1 : 0;
    if (overrides->has_spacing) {
        for (int axis = 0; axis < 3; axis++)
            desc->spacing[axis] = overrides->spacing[axis];
    }
    return IP_OK;
}

static ip_status validate_dims(ip_input_desc *desc, const ip_text_found *found, ip_error *err)
{
    for (int axis = 0; axis < 3; axis++) {
        uint64_t n = found->dims[axis];
        if (n < 2)
            return ip__fail(err, IP_ERR_INPUT, "%s: dimension %llu along %c is under 2", desc->path,
                            (unsigned long long)n, axis_names[axis]);
        if (n >= IP_INPUT_DIM_LIMIT)
            return ip__fail(err, IP_ERR_INPUT,
                            "%s: dimension %llu along %c is too large (the limit is %llu)",
                            desc->path, (unsigned long long)n, axis_names[axis],
                            (unsigned long long)(IP_INPUT_DIM_LIMIT - 1));
        desc->dims[axis] = (uint32_t)n;
    }
    return IP_OK;
}

static ip_status validate_spacing(const ip_input_desc *desc, ip_error *err)
{
    for (int axis = 0; axis < 3; axis++) {
        double s = desc->spacing[axis];
        if (!isfinite(s) || s <= 0.0)
            return ip__fail(err, IP_ERR_INPUT, "%s: spacing %g along %c is not a positive number",
                            desc->path, s, axis_names[axis]);
    }
    /* a positive spacing can still be one that nothing downstream renders correctly */
    return ip_spacing_check(desc->spacing, desc->path, err);
}

/* dims x type size in bytes; a product past 63 bits (file offsets are signed) is an error. */
static ip_status data_bytes(const ip_input_desc *desc, uint64_t *out, ip_error *err)
{
    const uint64_t limit = (uint64_t)INT64_MAX;
    uint64_t bytes = ip_type_size(desc->type);
    for (int axis = 0; axis < 3; axis++) {
        if (bytes > limit / desc->dims[axis])
            return ip__fail(err, IP_ERR_INPUT,
                            "%s: %ux%ux%u samples of %s are more than 2^63 bytes", desc->path,
                            desc->dims[0], desc->dims[1], desc->dims[2], ip_type_name(desc->type));
        bytes *= desc->dims[axis];
    }
    *out = bytes;
    return IP_OK;
}

/* Names the data file in messages: the path alone, or the header and then its data file. */
static void data_label(const ip_input_desc *desc, char *out, size_t size)
{
    if (strcmp(desc->path, desc->data_path) == 0)
        snprintf(out, size, "%s", desc->path);
    else
        snprintf(out, size, "%s: data file %s", desc->path, desc->data_path);
}

static ip_status size_mismatch(const ip_input_desc *desc, const char *label, uint64_t file_size,
                               uint64_t bytes, ip_error *err)
{
    size_t sample = ip_type_size(desc->type);
    const char *unit = sample == 1 ? "byte" : "bytes";
    if (desc->data_offset == 0)
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: file size %llu bytes does not equal %ux%ux%u x %zu %s = %llu bytes",
                        label, (unsigned long long)file_size, desc->dims[0], desc->dims[1],
                        desc->dims[2], sample, unit, (unsigned long long)bytes);
    return ip__fail(err, IP_ERR_INPUT,
                    "%s: data size %llu bytes (file size %llu - offset %llu) does not equal "
                    "%ux%ux%u x %zu %s = %llu bytes",
                    label, (unsigned long long)(file_size - desc->data_offset),
                    (unsigned long long)file_size, (unsigned long long)desc->data_offset,
                    desc->dims[0], desc->dims[1], desc->dims[2], sample, unit,
                    (unsigned long long)bytes);
}

/* Opens the data file (so that a missing or unreadable one is caught now), places data that
 * sit at the end of the file, and checks the size of raw data exactly. Gzip data cannot be
 * measured without inflating them; the reader checks their length. */
static ip_status check_data_file(ip_input_desc *desc, int data_at_end, uint64_t bytes,
                                 ip_error *err)
{
    char label[2 * IP_PATH_MAX + 16];
    struct stat st;
    if (ip__encoding_is_planes(desc->encoding))
        return IP_OK; /* a plane source checks each plane's file as it reads it */
    if (ip__input_is_stdin(desc->data_path))
        return IP_OK; /* a pipe's length is known at its end: the reader checks it */
    data_label(desc, label, sizeof label);
    /* O_NONBLOCK: naming a FIFO must fail below, not hang waiting for a writer. */
    int fd = open(desc->data_path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot open", label);
    int stat_failed = fstat(fd, &st) != 0;
    int stat_errno = errno;
    close(fd);
    if (stat_failed)
        return ip__fail_errno(err, IP_ERR_IO, stat_errno, "%s: cannot stat", label);
    if (!S_ISREG(st.st_mode))
        return ip__fail(err, IP_ERR_INPUT, "%s: not a regular file", label);
    uint64_t file_size = (uint64_t)st.st_size;

    if (data_at_end) {
        if (file_size < bytes)
            return ip__fail(err, IP_ERR_INPUT,
                            "%s: file size %llu bytes is under the %ux%ux%u x %zu = %llu bytes "
                            "of data",
                            label, (unsigned long long)file_size, desc->dims[0], desc->dims[1],
                            desc->dims[2], ip_type_size(desc->type), (unsigned long long)bytes);
        desc->data_offset = file_size - bytes;
        return IP_OK;
    }
    if (desc->encoding == IP_ENCODING_GZIP) {
        if (desc->data_offset >= file_size)
            return ip__fail(err, IP_ERR_INPUT,
                            "%s: no gzip data: the data offset %llu is at or past the end of "
                            "the file (%llu bytes)",
                            label, (unsigned long long)desc->data_offset,
                            (unsigned long long)file_size);
        return IP_OK;
    }
    if (desc->data_offset > file_size)
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: the data offset %llu is past the end of the file (%llu bytes)", label,
                        (unsigned long long)desc->data_offset, (unsigned long long)file_size);
    if (file_size - desc->data_offset != bytes)
        return size_mismatch(desc, label, file_size, bytes, err);
    return IP_OK;
}

/* Only a raw file gets here without dims or type: the header parsers report their missing
 * fields themselves. */
static ip_status require_layout(const ip_input_desc *desc, const ip_text_found *found,
                                ip_error *err)
{
    if (found->has_dims && found->has_type)
        return IP_OK;
    if (ip__input_is_stdin(desc->path))
        return ip__fail(err, IP_ERR_INPUT,
                        "stdin: raw samples from standard input need --dims and --type");
    return ip__fail(err, IP_ERR_INPUT,
                    "%s: cannot tell dims and type: name it NAME_XxYxZ_TYPE.raw or pass --dims "
                    "and --type",
                    desc->path);
}

static ip_status read_layout(const char *path, const ip_input_overrides *overrides,
                             ip_input_desc *desc, ip_text_found *found, ip_error *err)
{
    struct stat st;
    const ip_text_format *format = NULL;
    ip__describe_fn describe = NULL;
    if (ip__input_is_stdin(path)) /* raw samples: dims and type from the overrides */
        return isatty(STDIN_FILENO) ? ip__fail(err, IP_ERR_INPUT,
                                               "stdin: a terminal, not a volume: pipe the samples "
                                               "in (or name a file)")
                                    : IP_OK;
    switch (kind_of(path)) {
    case INPUT_NRRD: format = &ip__nrrd_format; break;
    case INPUT_MHD: format = &ip__mhd_format; break;
    case INPUT_TIFF: return describe_by_component(READ_TIFF, path, overrides, desc, found, err);
    case INPUT_NIFTI: describe = ip__nifti_describe; break;
    case INPUT_HDF5: return describe_by_component(READ_HDF5, path, overrides, desc, found, err);
    case INPUT_RAW: break;
    }
    if (format)
        return ip__text_read_header(format, path, overrides, desc, found, err);
    if (describe)
        return describe(path, overrides, desc, found, err);
    /* A mistyped path should say so, not complain about the name. */
    if (stat(path, &st) != 0)
        return ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot open", path);
    if (S_ISDIR(st.st_mode) && !has_suffix(path, ".raw"))
        return describe_folder(path, overrides, desc, found, err);
    /* raw data have no signature: a name ending in .raw is raw whatever its bytes */
    if (!has_suffix(path, ".raw") && hdf5_signature(path))
        return describe_by_component(READ_HDF5, path, overrides, desc, found, err);
    return describe_from_name(path, overrides, desc, found, err);
}

/* A series is picked, and a tilt or uneven spacing is resampled or refused, in a DICOM folder
 * only: asked of another input, the choice is refused rather than ignored. */
static ip_status check_dicom_choices(const ip_input_overrides *overrides, const ip_input_desc *desc,
                                     ip_error *err)
{
    if (overrides && desc->encoding != IP_ENCODING_ZARR &&
        (overrides->has_scale || overrides->has_time || overrides->has_channel))
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "%s: --scale, --time or --channel was given, but this is not an OME-Zarr "
                        "image",
                        desc->path);
    if (!overrides || desc->encoding == IP_ENCODING_DICOM)
        return IP_OK;
    if (overrides->series)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "%s: a DICOM series was asked for, but this is not a folder of DICOM "
                        "files",
                        desc->path);
    if (overrides->tilt != IP_REGRID_DEFAULT || overrides->uneven != IP_REGRID_DEFAULT)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "%s: a gantry tilt or slice spacing choice was given, but this is not a "
                        "folder of DICOM files",
                        desc->path);
    return IP_OK;
}

/* A dataset is picked in an HDF5 file only. */
static ip_status check_hdf5_choices(const ip_input_overrides *overrides, const ip_input_desc *desc,
                                    ip_error *err)
{
    if (!overrides || !overrides->dataset || desc->encoding == IP_ENCODING_HDF5)
        return IP_OK;
    return ip__fail(err, IP_ERR_ARGUMENT,
                    "%s: an HDF5 dataset was asked for, but this is not an HDF5 file", desc->path);
}

ip_status ip_dicom_list_series(const char *folder, ip_dicom_series_info **out, uint32_t *count,
                               uint32_t *skipped, ip_error *err)
{
    const ip__input_formats *formats;
    if (!folder || !out || !count)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "ip_dicom_list_series: folder, out and count are "
                        "required");
    *out = NULL;
    *count = 0;
    if (folder[0] == '\0' || strlen(folder) >= IP_PATH_MAX)
        return ip__fail(err, IP_ERR_ARGUMENT, "%.64s: path is empty or too long", folder);
    ip_status st = ip__input_formats_load(folder, &formats, err);
    if (st != IP_OK)
        return st;
    return formats->dicom_list(folder, out, count, skipped, err);
}

ip_status ip_input_describe(const char *path, const ip_input_overrides *given, ip_input_desc *out,
                            ip_error *err)
{
    ip_text_found found;
    ip_input_desc desc;
    ip_status status;
    uint64_t bytes = 0;
    if (!path || !out)
        return ip__fail(err, IP_ERR_ARGUMENT, "ip_input_describe: path and out are required");
    if (path[0] == '\0' || strlen(path) >= IP_PATH_MAX)
        return ip__fail(err, IP_ERR_ARGUMENT, "%.64s: path is empty or too long", path);
    ip_input_overrides taken = {0};
    const ip_input_overrides *overrides = NULL;
    if (given) {
        if ((status = ip__sized_in(&taken, sizeof taken, given,
                                   IP__SIZE_UPTO(ip_input_overrides, spacing), "input overrides",
                                   err)) != IP_OK)
            return status;
        overrides = &taken;
    }
    memset(&found, 0, sizeof found);
    set_defaults(&desc, path);
    if ((status = read_layout(path, overrides, &desc, &found, err)) != IP_OK ||
        (status = check_dicom_choices(overrides, &desc, err)) != IP_OK ||
        (status = check_hdf5_choices(overrides, &desc, err)) != IP_OK ||
        (status = apply_overrides(overrides, &desc, &found, err)) != IP_OK ||
        (status = require_layout(&desc, &found, err)) != IP_OK ||
        (status = validate_dims(&desc, &found, err)) != IP_OK ||
        (status = validate_spacing(&desc, err)) != IP_OK ||
        (status = data_bytes(&desc, &bytes, err)) != IP_OK ||
        (status = check_data_file(&desc, found.data_at_end, bytes, err)) != IP_OK)
        return status;
    *out = desc;
    return IP_OK;
}

ip_status ip_input_desc_from_planes(ip_input_desc *desc, const char *name, const uint32_t dims[3],
                                    ip_type type, const double spacing[3], ip_plane_source_fn fn,
                                    void *user, ip_error *err)
{
    if (!desc || !name || !dims || !fn)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "ip_input_desc_from_planes: desc, name, dims and fn are required");
    if (name[0] == '\0' || strlen(name) >= IP_PATH_MAX)
        return ip__fail(err, IP_ERR_ARGUMENT, "%.64s: the name is empty or too long", name);
    for (int axis = 0; axis < 3; axis++)
        if (dims[axis] < 2 || dims[axis] > INT32_MAX)
            return ip__fail(err, IP_ERR_ARGUMENT, "%s: dimension %c is %u, not within 2 .. %d",
                            name, "xyz"[axis], dims[axis], INT32_MAX);
    if (ip_type_size(type) == 0)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: unknown type %d", name, (int)type);
    if (spacing) {
        ip_status st = ip_spacing_check(spacing, name, err);
        if (st != IP_OK)
            return st;
    }
    set_defaults(desc, name);
    for (int axis = 0; axis < 3; axis++) {
        desc->dims[axis] = dims[axis];
        if (spacing)
            desc->spacing[axis] = spacing[axis];
    }
    desc->type = type;
    desc->big_endian = !ip__host_little_endian();
    desc->encoding = IP_ENCODING_CALLBACK;
    desc->plane_source = fn;
    desc->plane_user = user;
    return IP_OK;
}

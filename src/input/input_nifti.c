/* SPDX-License-Identifier: BSD-3-Clause */
/* NIfTI-1 and NIfTI-2 input: one file holding the header and the samples (magic "n+1" or
 * "n+2"; .nii, or .nii.gz compressed as a whole), in either byte order. The header gives the
 * dims (3D, or 4D and up with every further dimension 1), the sample type, the spacing
 * (|pixdim[1..3]|, in the file's unit, xyzt_units), where the samples start (vox_offset) and a
 * scaling (scl_slope, scl_inter), kept as the volume's rescale (with no unit: NIfTI names none
 * for the values), never applied to the samples. The samples are then read as
 * raw data from vox_offset, or as a gzip stream whose first vox_offset bytes are skipped.
 * The orientation comes from the sform when sform_code > 0, else from the qform when
 * qform_code > 0 (RAS space); the samples keep their storage order either way. The standard
 * ranks neither form above the other (the qform for scanner coordinates, the sform for a
 * standard space); this reader prefers the sform. The sform makes no use of pixdim, so when
 * it gives the orientation its columns' lengths are the spacing. */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include "input_source.h"
#include "internal.h"

#define NIFTI1_HEADER_BYTES 348
#define NIFTI2_HEADER_BYTES 540

/* The fields of either version that are used, in host form. */
typedef struct nifti_header {
    int version; /* 1 or 2 */
    int header_bytes;
    int big_endian;
    int64_t dim[8];
    int datatype;
    double pixdim[8];
    double vox_offset;
    double slope, intercept;
    int qform_code, sform_code;
    double quatern[3]; /* b, c, d */
    double qoffset[3];
    double srow[3][4]; /* srow_x, srow_y, srow_z */
} nifti_header;

/* ---- loads in the file's byte order ---- */

static uint64_t load_uint(const unsigned char *p, int bytes, int big_endian)
{
    uint64_t v = 0;
    for (int i = 0; i < bytes; i++)
        v |= (uint64_t)p[big_endian ? bytes - 1 - i : i] << (8 * i);
    return v;
}

static int64_t load_i16(const unsigned char *p, int big_endian)
{
    return (int16_t)load_uint(p, 2, big_endian);
}

static int64_t load_i64(const unsigned char *p, int big_endian)
{
    return (int64_t)load_uint(p, 8, big_endian);
}

static double load_f32(const unsigned char *p, int big_endian)
{
    uint32_t bits = (uint32_t)load_uint(p, 4, big_endian);
    float v;
    memcpy(&v, &bits, sizeof v);
    return v;
}

static double load_f64(const unsigned char *p, int big_endian)
{
    uint64_t bits = load_uint(p, 8, big_endian);
    double v;
    memcpy(&v, &bits, sizeof v);
    return v;
}

/* ---- the two header layouts ---- */

static void parse_nifti1(const unsigned char *h, nifti_header *n)
{
    int be = n->big_endian;
    for (int i = 0; i < 8; i++) {
        n->dim[i] = load_i16(h + 40 + 2 * i, be);
        n->pixdim[i] = load_f32(h + 76 + 4 * i, be);
    }
    n->datatype = (int)load_i16(h + 70, be);
    n->vox_offset = load_f32(h + 108, be);
    n->slope = load_f32(h + 112, be);
    n->intercept = load_f32(h + 116, be);
    n->qform_code = (int)load_i16(h + 252, be);
    n->sform_code = (int)load_i16(h + 254, be);
    for (int i = 0; i < 3; i++) {
        n->quatern[i] = load_f32(h + 256 + 4 * i, be);
        n->qoffset[i] = load_f32(h + 268 + 4 * i, be);
        for (int j = 0; j < 4; j++)
            n->srow[i][j] = load_f32(h + 280 + 16 * i + 4 * j, be);
    }
}

static void parse_nifti2(const unsigned char *h, nifti_header *n)
{
    int be = n->big_endian;
    n->datatype = (int)load_i16(h + 12, be);
    for (int i = 0; i < 8; i++) {
        n->dim[i] = load_i64(h + 16 + 8 * i, be);
        n->pixdim[i] = load_f64(h + 104 + 8 * i, be);
    }
    n->vox_offset = (double)load_i64(h + 168, be);
    n->slope = load_f64(h + 176, be);
    n->intercept = load_f64(h + 184, be);
    n->qform_code = (int)(int32_t)load_uint(h + 344, 4, be);
    n->sform_code = (int)(int32_t)load_uint(h + 348, 4, be);
    for (int i = 0; i < 3; i++) {
        n->quatern[i] = load_f64(h + 352 + 8 * i, be);
        n->qoffset[i] = load_f64(h + 376 + 8 * i, be);
        for (int j = 0; j < 4; j++)
            n->srow[i][j] = load_f64(h + 400 + 32 * i + 8 * j, be);
    }
}

/* The version and byte order from sizeof_hdr, the first 4 bytes: 348 or 540 in one order. */
static ip_status find_version(const char *path, const unsigned char *h, nifti_header *n,
                              ip_error *err)
{
    for (int be = 0; be < 2; be++) {
        uint64_t size = load_uint(h, 4, be);
        if (size == NIFTI1_HEADER_BYTES || size == NIFTI2_HEADER_BYTES) {
            n->big_endian = be;
            n->header_bytes = (int)size;
            n->version = size == NIFTI1_HEADER_BYTES ? 1 : 2;
            return IP_OK;
        }
    }
    return ip__fail(err, IP_ERR_INPUT,
                    "%s: not a NIfTI file (its first 4 bytes, the header size, are neither 348 "
                    "nor 540 in either byte order)",
                    path);
}

static ip_status check_magic(const char *path, const unsigned char *h, const nifti_header *n,
                             ip_error *err)
{
    const unsigned char *magic = n->version == 1 ? h + 344 : h + 4;
    char single = n->version == 1 ? '1' : '2';
    if (magic[0] == 'n' && magic[1] == '+' && magic[2] == single && magic[3] == '\0')
        return IP_OK;
    if (magic[0] == 'n' && magic[1] == 'i' && magic[2] == single && magic[3] == '\0')
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "%s: a NIfTI-%d header of a .hdr/.img pair (magic 'ni%c'); only "
                        "single files (magic 'n+%c', .nii) are supported",
                        path, n->version, single, single);
    return ip__fail(err, IP_ERR_INPUT, "%s: bad NIfTI-%d magic (bytes %d..%d are not 'n+%c\\0')",
                    path, n->version, n->version == 1 ? 344 : 4, n->version == 1 ? 347 : 7, single);
}

/* Reads the header of `path`, through zlib so that a compressed file reads the same;
 * *compressed is 1 for a gzip file. */
static ip_status read_header(const char *path, nifti_header *n, int *compressed, ip_error *err)
{
    unsigned char h[NIFTI2_HEADER_BYTES];
    int fd;
    ip_status st = ip__input_open_regular(path, &fd, err);
    if (st != IP_OK)
        return st;
    *compressed = pread(fd, h, 2, 0) == 2 && h[0] == 0x1f && h[1] == 0x8b;
    gzFile gz = gzdopen(fd, "rb");
    if (!gz) {
        close(fd);
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", path);
    }
    int got = gzread(gz, h, sizeof h);
    gzclose(gz); /* closes fd too */
    if (got < 0)
        return ip__fail(err, IP_ERR_INPUT, "%s: the gzip data do not inflate", path);
    memset(n, 0, sizeof *n);
    ip_status status =
        got >= 4
            ? find_version(path, h, n, err)
            : ip__fail(err, IP_ERR_INPUT, "%s: %d bytes are too few for a NIfTI header", path, got);
    if (status != IP_OK)
        return status;
    if (got < n->header_bytes)
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: truncated: %d bytes, under the %d of a NIfTI-%d header", path, got,
                        n->header_bytes, n->version);
    if ((status = check_magic(path, h, n, err)) != IP_OK)
        return status;
    (n->version == 1 ? parse_nifti1 : parse_nifti2)(h, n);
    return IP_OK;
}

/* ---- what the header says ---- */

static const char *datatype_name(int datatype)
{
    static const struct {
        int code;
        const char *name;
    } names[] = {{1, "binary"},    {2, "uint8"},       {4, "int16"},         {8, "int32"},
                 {16, "float32"},  {32, "complex64"},  {64, "float64"},      {128, "RGB24"},
                 {256, "int8"},    {512, "uint16"},    {768, "uint32"},      {1024, "int64"},
                 {1280, "uint64"}, {1536, "float128"}, {1792, "complex128"}, {2048, "complex256"},
                 {2304, "RGBA32"}};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (names[i].code == datatype)
            return names[i].name;
    return "unknown";
}

static ip_status sample_type(const char *path, int datatype, ip_type *type, ip_error *err)
{
    switch (datatype) {
    case 2: *type = IP_UINT8; return IP_OK;
    case 4: *type = IP_INT16; return IP_OK;
    case 512: *type = IP_UINT16; return IP_OK;
    case 16: *type = IP_FLOAT32; return IP_OK;
    }
    return ip__fail(err, IP_ERR_UNSUPPORTED,
                    "%s: NIfTI datatype %d (%s) is not supported (uint8, int16, uint16 and "
                    "float32 are)",
                    path, datatype, datatype_name(datatype));
}

/* dim[0] dimensions, of which the first three are the volume's and any further must be 1. */
static ip_status volume_dims(const char *path, const nifti_header *n, ip_text_found *found,
                             ip_error *err)
{
    int64_t rank = n->dim[0];
    if (rank < 3 || rank > 7)
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "%s: dim[0] = %lld: only 3D volumes are supported (dim[0] 3, or more "
                        "with every further dimension 1)",
                        path, (long long)rank);
    for (int i = 4; i <= rank; i++)
        if (n->dim[i] != 1)
            return ip__fail(err, IP_ERR_UNSUPPORTED,
                            "%s: a %lldD image (dim[%d] = %lld): only one 3D volume is "
                            "supported",
                            path, (long long)rank, i, (long long)n->dim[i]);
    for (int axis = 0; axis < 3; axis++) {
        if (n->dim[axis + 1] < 1)
            return ip__fail(err, IP_ERR_INPUT, "%s: dim[%d] = %lld is not a size", path, axis + 1,
                            (long long)n->dim[axis + 1]);
        found->dims[axis] = (uint64_t)n->dim[axis + 1];
    }
    found->has_dims = 1;
    return IP_OK;
}

static ip_status check_offset(const char *path, const nifti_header *n, ip_error *err)
{
    double offset = n->vox_offset;
    if (!isfinite(offset) || offset != floor(offset) || offset < n->header_bytes || offset > 0x1p62)
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: vox_offset %g is not a byte offset past the %d-byte header", path,
                        offset, n->header_bytes);
    return IP_OK;
}

/* scl_slope 0 (or not a number) means no scaling; slope 1 and intercept 0 change nothing. The
 * values' unit stays "" (set_defaults()). */
static void report_rescale(const nifti_header *n, ip_input_desc *desc)
{
    if (!isfinite(n->slope) || n->slope == 0.0 || !isfinite(n->intercept))
        return;
    if (n->slope == 1.0 && n->intercept == 0.0)
        return;
    desc->has_rescale = 1;
    desc->rescale_slope = n->slope;
    desc->rescale_intercept = n->intercept;
}

/* The sform's columns over their lengths, which go to `spacing`; 0 when they are not an
 * orthonormal frame. */
static int sform_orientation(const nifti_header *n, ip_orientation *o, double spacing[3])
{
    double directions[3][3];
    for (int a = 0; a < 3; a++) {
        o->origin[a] = n->srow[a][3];
        for (int c = 0; c < 3; c++)
            directions[a][c] = n->srow[c][a];
        spacing[a] =
            sqrt(directions[a][0] * directions[a][0] + directions[a][1] * directions[a][1] +
                 directions[a][2] * directions[a][2]);
    }
    return ip__orientation_frame(o, directions);
}

/* The rotation of the quaternion (b, c, d; a = sqrt(1 - b^2 - c^2 - d^2)), its third column
 * times qfac = pixdim[0] (-1 or, for any other value, 1). */
static int qform_orientation(const nifti_header *n, ip_orientation *o)
{
    double b = n->quatern[0], c = n->quatern[1], d = n->quatern[2];
    double aa = 1.0 - (b * b + c * c + d * d);
    double a = aa > 0.0 ? sqrt(aa) : 0.0;
    double qfac = n->pixdim[0] == -1.0 ? -1.0 : 1.0;
    double r[3][3] = {{a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)},
                      {2 * (b * c + a * d), a * a + c * c - b * b - d * d, 2 * (c * d - a * b)},
                      {2 * (b * d - a * c), 2 * (c * d + a * b), a * a + d * d - c * c - b * b}};
    double directions[3][3];
    for (int axis = 0; axis < 3; axis++) {
        o->origin[axis] = n->qoffset[axis];
        for (int row = 0; row < 3; row++)
            directions[axis][row] = r[row][axis] * (axis == 2 ? qfac : 1.0);
    }
    return ip__orientation_frame(o, directions);
}

/* The sform when it is set and a frame, else the qform when it is set and a frame, else the
 * identity (no space). The spacing is |pixdim[1..3]|, or the sform's when it is used. */
static void fill_orientation(const nifti_header *n, ip_orientation *o, double spacing[3])
{
    ip_orientation framed;
    double sform_spacing[3];
    ip_orientation_identity(o);
    ip_orientation_identity(&framed);
    framed.space = IP_SPACE_RAS;
    for (int axis = 0; axis < 3; axis++)
        spacing[axis] = fabs(n->pixdim[axis + 1]);
    if (n->sform_code > 0 && sform_orientation(n, &framed, sform_spacing)) {
        *o = framed;
        memcpy(spacing, sform_spacing, sizeof sform_spacing);
    } else if (n->qform_code > 0 && qform_orientation(n, &framed)) {
        *o = framed;
    }
}

ip_status ip__nifti_describe(const char *path, const ip_input_overrides *overrides,
                             ip_input_desc *desc, ip_text_found *found, ip_error *err)
{
    nifti_header n;
    int compressed = 0;
    ip_status status = read_header(path, &n, &compressed, err);
    if (status != IP_OK)
        return status;
    if (!ip__text_overridden(BY_DIMS, overrides) &&
        (status = volume_dims(path, &n, found, err)) != IP_OK)
        return status;
    if (!ip__text_overridden(BY_TYPE, overrides)) {
        if ((status = sample_type(path, n.datatype, &desc->type, err)) != IP_OK)
            return status;
        found->has_type = 1;
    }
    double spacing[3];
    fill_orientation(&n, &desc->orientation, spacing);
    if (!ip__text_overridden(BY_SPACING, overrides))
        memcpy(desc->spacing, spacing, sizeof spacing);
    if ((status = check_offset(path, &n, err)) != IP_OK)
        return status;
    desc->big_endian = n.big_endian;
    desc->encoding = compressed ? IP_ENCODING_GZIP : IP_ENCODING_RAW;
    desc->data_offset = compressed ? 0 : (uint64_t)n.vox_offset;
    desc->stream_skip = compressed ? (uint64_t)n.vox_offset : 0;
    report_rescale(&n, desc);
    return IP_OK;
}

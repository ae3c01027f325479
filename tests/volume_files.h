/* SPDX-License-Identifier: BSD-3-Clause */
/* Writing small test volumes as TIFF (libtiff's writing API: a multi-page file or one file a
 * plane) and as NIfTI-1/2 (the header by hand, .nii or .nii.gz through zlib), from samples in
 * the host's byte order; and reading a volume back whole through ip_input. For the tests of
 * the TIFF and NIfTI readers and the helper program make_formats. */
#ifndef ISOPROP_TEST_VOLUME_FILES_H
#define ISOPROP_TEST_VOLUME_FILES_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <tiffio.h>
#include <zlib.h>

#include "isoprop/input.h"
#include "isoprop/volume.h"

/* How a TIFF is written. */
typedef struct tiff_style {
    uint16_t compression;    /* COMPRESSION_NONE, _LZW, _ADOBE_DEFLATE, _PACKBITS */
    uint32_t rows_per_strip; /* 0: the whole page in one strip */
    uint32_t tile;           /* > 0: tiles of tile x tile samples (a multiple of 16) */
    double imagej_spacing;   /* > 0: an ImageJ description with this spacing= (z) ... */
    double pixel_size;       /* ... and X/YResolution 1 / pixel_size */
} tiff_style;

static inline void tiff_set_layout(TIFF *t, ip_type type, uint32_t width, uint32_t height,
                                   const tiff_style *style)
{
    static const uint16_t bits[] = {8, 16, 16, 32};
    static const uint16_t formats[] = {SAMPLEFORMAT_UINT, SAMPLEFORMAT_UINT, SAMPLEFORMAT_INT,
                                       SAMPLEFORMAT_IEEEFP};
    TIFFSetField(t, TIFFTAG_IMAGEWIDTH, width);
    TIFFSetField(t, TIFFTAG_IMAGELENGTH, height);
    TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, bits[type]);
    TIFFSetField(t, TIFFTAG_SAMPLEFORMAT, formats[type]);
    TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, 1);
    TIFFSetField(t, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_MINISBLACK);
    TIFFSetField(t, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
    TIFFSetField(t, TIFFTAG_COMPRESSION, style->compression);
    if (style->tile) {
        TIFFSetField(t, TIFFTAG_TILEWIDTH, style->tile);
        TIFFSetField(t, TIFFTAG_TILELENGTH, style->tile);
    } else {
        TIFFSetField(t, TIFFTAG_ROWSPERSTRIP,
                     style->rows_per_strip ? style->rows_per_strip : height);
    }
}

static inline void tiff_set_imagej(TIFF *t, uint32_t pages, const tiff_style *style)
{
    char text[256];
    if (style->imagej_spacing <= 0)
        return;
    snprintf(text, sizeof text, "ImageJ=1.54f\nimages=%u\nslices=%u\nunit=micron\nspacing=%g\n",
             pages, pages, style->imagej_spacing);
    TIFFSetField(t, TIFFTAG_IMAGEDESCRIPTION, text);
    TIFFSetField(t, TIFFTAG_XRESOLUTION, (float)(1.0 / style->pixel_size));
    TIFFSetField(t, TIFFTAG_YRESOLUTION, (float)(1.0 / style->pixel_size));
    TIFFSetField(t, TIFFTAG_RESOLUTIONUNIT, RESUNIT_NONE);
}

/* Writes one page of width x height samples (host order) in tiles. */
static inline int tiff_write_tiles(TIFF *t, const unsigned char *plane, size_t sample,
                                   uint32_t width, uint32_t height, uint32_t tile)
{
    unsigned char *buf = malloc((size_t)tile * tile * sample);
    int ok = buf != NULL;
    for (uint32_t y = 0; ok && y < height; y += tile)
        for (uint32_t x = 0; ok && x < width; x += tile) {
            memset(buf, 0, (size_t)tile * tile * sample);
            for (uint32_t r = 0; r < tile && y + r < height; r++) {
                uint32_t cols = width - x < tile ? width - x : tile;
                memcpy(buf + (size_t)r * tile * sample,
                       plane + ((size_t)(y + r) * width + x) * sample, cols * sample);
            }
            ok = TIFFWriteTile(t, buf, x, y, 0, 0) >= 0;
        }
    free(buf);
    return ok;
}

/*! write_tiff() : writes `pages` pages of width x height samples of `type` (host order, page
 *  after page) to `path`. Returns 0, or -1 when libtiff fails. */
static inline int write_tiff(const char *path, ip_type type, uint32_t width, uint32_t height,
                             uint32_t pages, const void *samples, const tiff_style *style)
{
    size_t sample = ip_type_size(type), row = (size_t)width * sample;
    const unsigned char *p = samples;
    TIFF *t = TIFFOpen(path, "w");
    if (!t)
        return -1;
    int ok = 1;
    for (uint32_t z = 0; ok && z < pages; z++) {
        const unsigned char *plane = p + (size_t)z * height * row;
        tiff_set_layout(t, type, width, height, style);
        if (z == 0)
            tiff_set_imagej(t, pages, style);
        if (pages > 1) {
            TIFFSetField(t, TIFFTAG_SUBFILETYPE, FILETYPE_PAGE);
            TIFFSetField(t, TIFFTAG_PAGENUMBER, z, pages);
        }
        if (style->tile)
            ok = tiff_write_tiles(t, plane, sample, width, height, style->tile);
        for (uint32_t y = 0; ok && !style->tile && y < height; y++)
            ok = TIFFWriteScanline(t, (void *)(plane + y * row), y, 0) == 1;
        ok = ok && TIFFWriteDirectory(t);
    }
    TIFFClose(t);
    return ok ? 0 : -1;
}

/*! write_tiff_folder() : writes each z-plane to its own file `folder`/`prefix`N.tif, N from
 *  `first` on, without leading zeros (so that only a natural sort orders them). */
static inline int write_tiff_folder(const char *folder, const char *prefix, uint32_t first,
                                    ip_type type, const uint32_t dims[3], const void *samples,
                                    const tiff_style *style)
{
    size_t plane = (size_t)dims[0] * dims[1] * ip_type_size(type);
    for (uint32_t z = 0; z < dims[2]; z++) {
        char path[4096];
        if (snprintf(path, sizeof path, "%s/%s%u.tif", folder, prefix, first + z) >=
                (int)sizeof path ||
            write_tiff(path, type, dims[0], dims[1], 1, (const unsigned char *)samples + z * plane,
                       style) != 0)
            return -1;
    }
    return 0;
}

/* ---- NIfTI ---- */

/* How a NIfTI file is written: version 1 or 2, byte order, compression, and the header
 * fields the tests vary. */
typedef struct nifti_style {
    int version;
    int big_endian;
    int gzip;
    int16_t datatype; /* 0: that of the type */
    int64_t dim[8];   /* dim[0] 0: 3 and the volume's dims */
    double pixdim[3];
    double slope, intercept;
    int64_t vox_offset; /* 0: right after the header and its 4 extension bytes */
    /* where the samples lie; all 0 (the default) writes neither form */
    double qfac; /* pixdim[0] */
    int qform_code, sform_code;
    double quatern[3]; /* quatern_b, _c, _d */
    double qoffset[3];
    double srow[3][4]; /* srow_x, srow_y, srow_z */
} nifti_style;

static inline void nifti_put(unsigned char *p, uint64_t v, int bytes, int big_endian)
{
    for (int i = 0; i < bytes; i++)
        p[big_endian ? bytes - 1 - i : i] = (unsigned char)(v >> (8 * i));
}

static inline void nifti_put_f32(unsigned char *p, double v, int big_endian)
{
    float f = (float)v;
    uint32_t bits;
    memcpy(&bits, &f, 4);
    nifti_put(p, bits, 4, big_endian);
}

static inline void nifti_put_f64(unsigned char *p, double v, int big_endian)
{
    uint64_t bits;
    memcpy(&bits, &v, 8);
    nifti_put(p, bits, 8, big_endian);
}

static inline int16_t nifti_datatype(ip_type type)
{
    static const int16_t codes[] = {2, 512, 4, 16};
    return codes[type];
}

/* The qform and sform fields of s: version 1 has float32 values and int16 codes, version 2
 * float64 values and int32 codes; in both, quatern_b .. _d, qoffset_x .. _z and srow_x .. _z
 * follow each other. */
static inline void nifti_put_forms(unsigned char *h, const nifti_style *s, int v1)
{
    int be = s->big_endian, code = v1 ? 2 : 4;
    size_t real = v1 ? 4 : 8, codes = v1 ? 252 : 344, quatern = v1 ? 256 : 352;
    void (*put_real)(unsigned char *, double, int) = v1 ? nifti_put_f32 : nifti_put_f64;
    put_real(h + (v1 ? 76 : 104), s->qfac, be);
    nifti_put(h + codes, (uint32_t)s->qform_code, code, be);
    nifti_put(h + codes + code, (uint32_t)s->sform_code, code, be);
    for (int i = 0; i < 3; i++) {
        put_real(h + quatern + real * i, s->quatern[i], be);
        put_real(h + quatern + real * (3 + i), s->qoffset[i], be);
        for (int j = 0; j < 4; j++)
            put_real(h + quatern + real * (6 + 4 * i + j), s->srow[i][j], be);
    }
}

/* The header (348 or 540 bytes) into h, zeroed first; returns its size. */
static inline size_t nifti_header(unsigned char *h, ip_type type, const uint32_t dims[3],
                                  const nifti_style *s)
{
    int be = s->big_endian, v1 = s->version == 1;
    int64_t dim[8] = {3, dims[0], dims[1], dims[2], 1, 1, 1, 1};
    if (s->dim[0])
        memcpy(dim, s->dim, sizeof dim);
    size_t size = v1 ? 348 : 540;
    int64_t offset = s->vox_offset ? s->vox_offset : (int64_t)size + 4;
    int16_t datatype = s->datatype ? s->datatype : nifti_datatype(type);
    memset(h, 0, 540);
    nifti_put(h, size, 4, be);
    if (v1) {
        for (int i = 0; i < 8; i++)
            nifti_put(h + 40 + 2 * i, (uint64_t)dim[i], 2, be);
        nifti_put(h + 70, (uint16_t)datatype, 2, be);
        nifti_put(h + 72, 8 * ip_type_size(type), 2, be);
        for (int i = 0; i < 3; i++)
            nifti_put_f32(h + 80 + 4 * i, s->pixdim[i], be);
        nifti_put_f32(h + 108, (double)offset, be);
        nifti_put_f32(h + 112, s->slope, be);
        nifti_put_f32(h + 116, s->intercept, be);
        h[123] = 2; /* millimetres */
        memcpy(h + 344, "n+1", 4);
    } else {
        memcpy(h + 4, "n+2\0\r\n\032\n", 8);
        nifti_put(h + 12, (uint16_t)datatype, 2, be);
        nifti_put(h + 14, 8 * ip_type_size(type), 2, be);
        for (int i = 0; i < 8; i++)
            nifti_put(h + 16 + 8 * i, (uint64_t)dim[i], 8, be);
        for (int i = 0; i < 3; i++)
            nifti_put_f64(h + 112 + 8 * i, s->pixdim[i], be);
        nifti_put(h + 168, (uint64_t)offset, 8, be);
        nifti_put_f64(h + 176, s->slope, be);
        nifti_put_f64(h + 184, s->intercept, be);
        nifti_put(h + 500, 2, 4, be);
    }
    nifti_put_forms(h, s, v1);
    return size;
}

/*! write_nifti() : the header, zeros up to vox_offset, then the samples (host order, put in
 *  the file's byte order), all gzip-compressed when s->gzip. Returns 0 or -1. */
static inline int write_nifti(const char *path, ip_type type, const uint32_t dims[3],
                              const void *samples, const nifti_style *s)
{
    unsigned char h[540];
    size_t header = nifti_header(h, type, dims, s);
    size_t offset = s->vox_offset ? (size_t)s->vox_offset : header + 4;
    size_t sample = ip_type_size(type);
    size_t bytes = (size_t)dims[0] * dims[1] * dims[2] * sample;
    size_t total = offset + bytes > header ? offset + bytes : header;
    unsigned char *file = calloc(1, total);
    if (!file)
        return -1;
    unsigned char *data = file + offset;
    memcpy(data, samples, bytes);
    int host_be = *(const unsigned char *)&(const uint16_t){1} == 0;
    for (size_t i = 0; s->big_endian != host_be && sample > 1 && i < bytes; i += sample)
        for (size_t k = 0; k < sample / 2; k++) {
            unsigned char c = data[i + k];
            data[i + k] = data[i + sample - 1 - k];
            data[i + sample - 1 - k] = c;
        }
    memcpy(file, h, header); /* over the samples when vox_offset is too small (a bad file) */
    int ok;
    if (s->gzip) {
        gzFile gz = gzopen(path, "wb");
        ok = gz && gzwrite(gz, file, (unsigned)total) == (int)total;
        ok = gz && gzclose(gz) == Z_OK && ok;
    } else {
        FILE *f = fopen(path, "wb");
        ok = f && fwrite(file, 1, total, f) == total;
        ok = f && fclose(f) == 0 && ok;
    }
    free(file);
    return ok ? 0 : -1;
}

/* ---- reading back ---- */

/*! read_volume() : all samples of `desc` (host order) through ip_input, two planes a call;
 *  NULL with err filled on failure; free() the result. */
static inline void *read_volume(const ip_input_desc *desc, ip_error *err)
{
    size_t plane = (size_t)desc->dims[0] * desc->dims[1] * ip_type_size(desc->type);
    unsigned char *all = malloc(plane * desc->dims[2]);
    ip_input_reader *reader = NULL;
    if (!all || ip_input_open(desc, &reader, err) != IP_OK) {
        free(all);
        return NULL;
    }
    for (uint32_t z = 0; z < desc->dims[2]; z += 2) {
        uint32_t count = desc->dims[2] - z < 2 ? 1 : 2;
        if (ip_input_read_planes(reader, all + z * plane, count, err) != IP_OK) {
            free(all);
            all = NULL;
            break;
        }
    }
    ip_input_close(reader);
    return all;
}

#endif

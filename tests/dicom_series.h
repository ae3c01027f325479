/* SPDX-License-Identifier: BSD-3-Clause */
/* DICOM series written by the tests, byte by byte: single-frame Part 10 files (128-byte
 * preamble, "DICM", the group 0002 meta header in explicit VR little endian with its group
 * length, then the data set), one file a z-plane of a volume, in explicit or implicit VR little
 * endian or explicit VR big endian, uncompressed or RLE Lossless, or deflated explicit VR
 * little endian. */
#ifndef ISOPROP_TEST_DICOM_SERIES_H
#define ISOPROP_TEST_DICOM_SERIES_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#include "check.h"
#include "isoprop/volume.h"

#define TEST_DICOM_EXPLICIT_LE "1.2.840.10008.1.2.1"
#define TEST_DICOM_IMPLICIT_LE "1.2.840.10008.1.2"
#define TEST_DICOM_EXPLICIT_BE "1.2.840.10008.1.2.2"
#define TEST_DICOM_RLE "1.2.840.10008.1.2.5"
#define TEST_DICOM_DEFLATE "1.2.840.10008.1.2.1.99"
#define TEST_DICOM_CT_STORAGE "1.2.840.10008.5.1.4.1.1.2"
/* SOP classes of objects that are not images */
#define TEST_DICOM_DIRECTORY "1.2.840.10008.1.3.10"              /* Media Storage Directory */
#define TEST_DICOM_BASIC_TEXT_SR "1.2.840.10008.5.1.4.1.1.88.11" /* Basic Text SR */
#define TEST_DICOM_GRAYSCALE_PS "1.2.840.10008.5.1.4.1.1.11.1"   /* Grayscale Softcopy PS */

/* What the files of a series say. */
typedef struct test_dicom_series {
    uint32_t dims[3];         /* columns (x), rows (y), slices (z) */
    ip_type type;             /* IP_UINT8, IP_UINT16 or IP_INT16 */
    unsigned bits_allocated;  /* 0: the type's */
    double pixel_spacing[2];  /* between rows (y), between columns (x) */
    double origin_z, step_z;  /* slice z lies at origin_z + z * step_z along the normal */
    int rescale;              /* 1: write slope and intercept */
    double slope, intercept;  /* Rescale Slope and Intercept */
    const char *rescale_type; /* Rescale Type (0028,1054), with rescale; NULL: none */
    const char *modality;     /* Modality (0008,0060); NULL: CT, "": none */
    const char *series_uid;   /* Series Instance UID */
    const char *syntax;       /* Transfer Syntax UID (NULL: one by slice, see below) */
    const char *photometric;  /* NULL: MONOCHROME2 */
    int no_position;          /* 1: leave out Image Position (Patient) */
    int sequences;            /* 1: add a Referenced Image Sequence and an Icon Image Sequence */
    int overlay;              /* 1: add an overlay plane (group 6000) of the image's size */
    /* the geometry of scanners (all zero: slices stacked along z, evenly) */
    double shift[2];         /* slice z lies z * shift mm further along x and y: a gantry
                                tilt (the rows run along x, the columns along y) */
    const double *z_at;      /* NULL, or where each slice lies along z (origin_z, step_z
                                unused): uneven spacing */
    const char *description; /* NULL, or a Series Description */
} test_dicom_series;

/* A series of `dims`, spacing 0.7 (y) x 0.8 (x) x 2.5 mm, rescale 1 x stored - 1024. */
static inline test_dicom_series test_dicom_default(uint32_t nx, uint32_t ny, uint32_t nz,
                                                   ip_type type)
{
    test_dicom_series s;
    memset(&s, 0, sizeof s);
    s.dims[0] = nx, s.dims[1] = ny, s.dims[2] = nz;
    s.type = type;
    s.pixel_spacing[0] = 0.7, s.pixel_spacing[1] = 0.8;
    s.origin_z = -40.0, s.step_z = 2.5;
    s.rescale = 1, s.slope = 1.0, s.intercept = -1024.0;
    s.series_uid = "1.2.826.0.1.3680043.2.1125.1.1";
    return s;
}

typedef struct test_bytes {
    unsigned char *data;
    size_t size, capacity;
    int big_endian, implicit; /* how the data set is encoded */
} test_bytes;

static inline void test_bytes_put(test_bytes *b, const void *data, size_t size)
{
    if (b->size + size > b->capacity) {
        b->capacity = 2 * (b->size + size) + 256;
        b->data = realloc(b->data, b->capacity);
        REQUIRE(b->data != NULL);
    }
    memcpy(b->data + b->size, data, size);
    b->size += size;
}

static inline void test_bytes_uint(test_bytes *b, uint32_t value, int bytes)
{
    unsigned char out[4];
    for (int i = 0; i < bytes; i++)
        out[b->big_endian ? bytes - 1 - i : i] = (unsigned char)(value >> (8 * i));
    test_bytes_put(b, out, (size_t)bytes);
}

/* One element: tag, VR (explicit syntaxes), length, value padded to an even length (UI with a
 * NUL, text with a space, binary data with a zero). */
static inline void test_dicom_element(test_bytes *b, uint16_t group, uint16_t element,
                                      const char *vr, const void *value, size_t size)
{
    int long_form = strcmp(vr, "OB") == 0 || strcmp(vr, "OW") == 0;
    size_t padded = size + (size & 1);
    test_bytes_uint(b, group, 2);
    test_bytes_uint(b, element, 2);
    if (b->implicit) {
        test_bytes_uint(b, (uint32_t)padded, 4);
    } else {
        test_bytes_put(b, vr, 2);
        if (long_form) {
            test_bytes_uint(b, 0, 2);
            test_bytes_uint(b, (uint32_t)padded, 4);
        } else {
            test_bytes_uint(b, (uint32_t)padded, 2);
        }
    }
    test_bytes_put(b, value, size);
    if (size & 1)
        test_bytes_put(b, strcmp(vr, "UI") == 0 || long_form ? "\0" : " ", 1);
}

static inline void test_dicom_text(test_bytes *b, uint16_t group, uint16_t element, const char *vr,
                                   const char *text)
{
    test_dicom_element(b, group, element, vr, text, strlen(text));
}

static inline void test_dicom_us(test_bytes *b, uint16_t group, uint16_t element, unsigned value)
{
    test_bytes v = {0};
    v.big_endian = b->big_endian;
    test_bytes_uint(&v, value, 2);
    test_dicom_element(b, group, element, "US", v.data, 2);
    free(v.data);
}

/* The meta header of an object of SOP class `sop_class`, always explicit VR little endian,
 * with its group length first. */
static inline void test_dicom_meta_of(test_bytes *out, const char *sop_class, const char *instance,
                                      const char *syntax)
{
    test_bytes g = {0};
    test_dicom_element(&g, 0x0002, 0x0001, "OB", "\0\1", 2);
    test_dicom_text(&g, 0x0002, 0x0002, "UI", sop_class);
    test_dicom_text(&g, 0x0002, 0x0003, "UI", instance);
    test_dicom_text(&g, 0x0002, 0x0010, "UI", syntax);
    test_dicom_text(&g, 0x0002, 0x0012, "UI", "1.2.826.0.1.3680043.2.1125.9");
    unsigned char length[4] = {(unsigned char)g.size, (unsigned char)(g.size >> 8),
                               (unsigned char)(g.size >> 16), (unsigned char)(g.size >> 24)};
    test_bytes_put(out, "\2\0\0\0UL\4\0", 8);
    test_bytes_put(out, length, 4);
    test_bytes_put(out, g.data, g.size);
    free(g.data);
}

/* The meta header of a CT image. */
static inline void test_dicom_meta(test_bytes *out, const char *instance, const char *syntax)
{
    test_dicom_meta_of(out, TEST_DICOM_CT_STORAGE, instance, syntax);
}

/* One RLE segment (PackBits, literal runs only) of `count` bytes taken every `stride` bytes. */
static inline void test_rle_segment(test_bytes *out, const unsigned char *bytes, size_t count,
                                    size_t stride)
{
    for (size_t i = 0; i < count; i += 128) {
        size_t run = count - i < 128 ? count - i : 128;
        unsigned char header = (unsigned char)(run - 1);
        test_bytes_put(out, &header, 1);
        for (size_t k = 0; k < run; k++)
            test_bytes_put(out, &bytes[(i + k) * stride], 1);
    }
    if (out->size & 1)
        test_bytes_put(out, "\x80", 1); /* a no-op byte keeps segments even */
}

/* RLE Lossless pixel data: an encapsulated element with an empty offset table and one fragment:
 * the 64-byte RLE header, then one segment a byte of the sample, most significant first. */
static inline void test_dicom_rle_pixels(test_bytes *b, const unsigned char *plane, size_t count,
                                         size_t sample)
{
    test_bytes frag = {0};
    uint32_t offsets[16] = {0};
    test_bytes_put(&frag, (unsigned char[64]){0}, 64);
    for (size_t k = 0; k < sample; k++) {
        offsets[k + 1] = (uint32_t)frag.size;
        test_rle_segment(&frag, plane + (sample - 1 - k), count, sample);
    }
    offsets[0] = (uint32_t)sample;
    for (int i = 0; i < 16; i++)
        for (int k = 0; k < 4; k++)
            frag.data[4 * i + k] = (unsigned char)(offsets[i] >> (8 * k));
    static const unsigned char head[] = {0xE0, 0x7F, 0x10, 0x00, 'O',  'B',
                                         0,    0,    0xFF, 0xFF, 0xFF, 0xFF};
    test_bytes_put(b, head, sizeof head);
    test_bytes_put(b, "\xFE\xFF\x00\xE0\0\0\0\0", 8); /* the empty basic offset table */
    test_bytes_put(b, "\xFE\xFF\x00\xE0", 4);
    test_bytes_uint(b, (uint32_t)frag.size, 4);
    test_bytes_put(b, frag.data, frag.size);
    test_bytes_put(b, "\xFE\xFF\xDD\xE0\0\0\0\0", 8); /* the sequence delimiter */
    free(frag.data);
}

/* The zlib level of deflated data sets: stored blocks (0) make bytes that do not depend on
 * the zlib version (tests/helpers/make_dicom_corpus.c, whose output is compared with files). */
#ifndef TEST_DICOM_DEFLATE_LEVEL
#define TEST_DICOM_DEFLATE_LEVEL Z_BEST_COMPRESSION
#endif

/* Replaces b->data[from ..] by its raw deflate stream (RFC 1951, no zlib header: PS3.5 A.5). */
static inline void test_deflate_tail(test_bytes *b, size_t from)
{
    z_stream z;
    memset(&z, 0, sizeof z);
    REQUIRE(deflateInit2(&z, TEST_DICOM_DEFLATE_LEVEL, Z_DEFLATED, -MAX_WBITS, 8,
                         Z_DEFAULT_STRATEGY) == Z_OK);
    uLong bound = deflateBound(&z, (uLong)(b->size - from));
    unsigned char *packed = malloc(bound);
    REQUIRE(packed != NULL);
    z.next_in = b->data + from;
    z.avail_in = (uInt)(b->size - from);
    z.next_out = packed;
    z.avail_out = (uInt)bound;
    REQUIRE(deflate(&z, Z_FINISH) == Z_STREAM_END);
    b->size = from;
    test_bytes_put(b, packed, bound - z.avail_out);
    if (b->size & 1)
        test_bytes_put(b, "\0", 1); /* the file's length even */
    deflateEnd(&z);
    free(packed);
}

/* The header of a sequence or an item of undefined length (an item or a sequence delimiter
 * when group is FFFE and element not E000), in b's encoding. */
static inline void test_dicom_open(test_bytes *b, uint16_t group, uint16_t element, int sequence)
{
    test_bytes_uint(b, group, 2);
    test_bytes_uint(b, element, 2);
    if (sequence && !b->implicit)
        test_bytes_put(b, "SQ\0\0", 4);
    test_bytes_uint(b, group == 0xFFFE && element != 0xE000 ? 0 : 0xFFFFFFFFu, 4);
}

/* A Referenced Image Sequence (0008,1140): one item of two UIDs; sequence and item of
 * undefined length. */
static inline void test_dicom_references(test_bytes *b)
{
    test_dicom_open(b, 0x0008, 0x1140, 1);
    test_dicom_open(b, 0xFFFE, 0xE000, 0);
    test_dicom_text(b, 0x0008, 0x1150, "UI", TEST_DICOM_CT_STORAGE);
    test_dicom_text(b, 0x0008, 0x1155, "UI", "1.2.826.0.1.3680043.2.1125.5");
    test_dicom_open(b, 0xFFFE, 0xE00D, 0);
    test_dicom_open(b, 0xFFFE, 0xE0DD, 0);
}

/* An Icon Image Sequence (0088,0200): one item holding a 2 x 2 8-bit image of its own. */
static inline void test_dicom_icon(test_bytes *b)
{
    test_dicom_open(b, 0x0088, 0x0200, 1);
    test_dicom_open(b, 0xFFFE, 0xE000, 0);
    test_dicom_us(b, 0x0028, 0x0002, 1);
    test_dicom_text(b, 0x0028, 0x0004, "CS", "MONOCHROME2");
    test_dicom_us(b, 0x0028, 0x0010, 2);
    test_dicom_us(b, 0x0028, 0x0011, 2);
    test_dicom_us(b, 0x0028, 0x0100, 8);
    test_dicom_us(b, 0x0028, 0x0101, 8);
    test_dicom_us(b, 0x0028, 0x0102, 7);
    test_dicom_us(b, 0x0028, 0x0103, 0);
    test_dicom_element(b, 0x7FE0, 0x0010, "OB", "\x10\x80\xF0\x40", 4);
    test_dicom_open(b, 0xFFFE, 0xE00D, 0);
    test_dicom_open(b, 0xFFFE, 0xE0DD, 0);
}

/* An overlay plane (group 6000) of columns x rows, every other bit set. */
static inline void test_dicom_overlay(test_bytes *b, uint32_t columns, uint32_t rows)
{
    test_bytes origin = {0};
    unsigned char bits[512];
    size_t size = ((size_t)columns * rows + 7) / 8;
    REQUIRE(size <= sizeof bits);
    memset(bits, 0x55, size);
    origin.big_endian = b->big_endian;
    test_bytes_uint(&origin, 1, 2);
    test_bytes_uint(&origin, 1, 2);
    test_dicom_us(b, 0x6000, 0x0010, rows);
    test_dicom_us(b, 0x6000, 0x0011, columns);
    test_dicom_text(b, 0x6000, 0x0040, "CS", "G");
    test_dicom_element(b, 0x6000, 0x0050, "SS", origin.data, 4);
    test_dicom_us(b, 0x6000, 0x0100, 1);
    test_dicom_us(b, 0x6000, 0x0102, 0);
    test_dicom_element(b, 0x6000, 0x3000, "OB", bits, size);
    free(origin.data);
}

/* Where pixel (x, y) of slice z lies (mm, LPS): the slice's Image Position (Patient), x
 * columns along its rows (+x) and y rows along its columns (+y). */
static inline void test_dicom_position(const test_dicom_series *s, uint32_t x, uint32_t y,
                                       uint32_t z, double p[3])
{
    p[0] = -12.5 + z * s->shift[0] + x * s->pixel_spacing[1];
    p[1] = 30 + z * s->shift[1] + y * s->pixel_spacing[0];
    p[2] = s->z_at ? s->z_at[z] : s->origin_z + z * s->step_z;
}

/* An int16 volume of s's dims (the caller frees it) imaging a ball in physical space: each
 * pixel, at its own position (test_dicom_position()), is 2000 less 40 a millimetre of its
 * distance from `centre` (mm), so that the iso value 2000 - 40 R bounds the sphere of radius
 * R about `centre` exactly, however the slices lie. */
static inline int16_t *test_dicom_ball(const test_dicom_series *s, const double centre[3])
{
    int16_t *v = malloc((size_t)s->dims[0] * s->dims[1] * s->dims[2] * sizeof *v);
    REQUIRE(v != NULL);
    for (uint32_t z = 0; z < s->dims[2]; z++)
        for (uint32_t y = 0; y < s->dims[1]; y++)
            for (uint32_t x = 0; x < s->dims[0]; x++) {
                double p[3];
                test_dicom_position(s, x, y, z, p);
                double d[3] = {p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]};
                v[((size_t)z * s->dims[1] + y) * s->dims[0] + x] =
                    (int16_t)lround(2000 - 40 * sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
            }
    return v;
}

/* A series imaging a ball (test_dicom_ball()) as a scanner with its gantry tilted writes it:
 * 40 x 36 x 13 int16 slices, 2.36 mm apart along their normal, each shifted -0.79 mm along
 * its columns (y) from the one before: a tilt of 18.5 degrees. */
static inline test_dicom_series test_dicom_tilted(void)
{
    test_dicom_series s = test_dicom_default(40, 36, 13, IP_INT16);
    s.step_z = 2.36, s.shift[1] = -0.79;
    s.syntax = TEST_DICOM_EXPLICIT_LE;
    s.series_uid = "1.2.826.0.1.3680043.2.1125.1.3";
    s.description = "Tilted head";
    return s;
}

/* The centre (mm, LPS) of the ball the tilted series images: within every slice's reach. */
#define TEST_DICOM_BALL_CENTRE \
    {                          \
        3.1, 37.5, -25.84      \
    }

/* The transfer syntax of slice z when the series names none: they take turns. */
static inline const char *test_dicom_syntax_of(const test_dicom_series *s, uint32_t z)
{
    static const char *const turns[] = {TEST_DICOM_EXPLICIT_LE, TEST_DICOM_IMPLICIT_LE,
                                        TEST_DICOM_EXPLICIT_BE, TEST_DICOM_RLE};
    return s->syntax ? s->syntax : turns[z % 4];
}

/* The bytes of plane z of `volume` (dims[0] x dims[1] x dims[2] samples of s->type, x fastest,
 * host order) as a DICOM file, into *out (empty; the caller frees out->data). */
static inline void test_dicom_slice_bytes(const test_dicom_series *s, const void *volume,
                                          uint32_t z, test_bytes *out)
{
    const char *syntax = test_dicom_syntax_of(s, z);
    size_t sample = ip_type_size(s->type), count = (size_t)s->dims[0] * s->dims[1];
    const unsigned char *plane = (const unsigned char *)volume + (size_t)z * count * sample;
    unsigned bits = s->bits_allocated ? s->bits_allocated : (unsigned)(8 * sample);
    char instance[96], text[128];
    test_bytes b = {0};
    snprintf(instance, sizeof instance, "%s.%u", s->series_uid, z + 1);
    test_bytes_put(&b, (unsigned char[128]){0}, 128);
    test_bytes_put(&b, "DICM", 4);
    test_dicom_meta(&b, instance, syntax);
    size_t data_set = b.size;
    b.implicit = strcmp(syntax, TEST_DICOM_IMPLICIT_LE) == 0;
    b.big_endian = strcmp(syntax, TEST_DICOM_EXPLICIT_BE) == 0;
    test_dicom_text(&b, 0x0008, 0x0016, "UI", TEST_DICOM_CT_STORAGE);
    test_dicom_text(&b, 0x0008, 0x0018, "UI", instance);
    if (!s->modality || s->modality[0])
        test_dicom_text(&b, 0x0008, 0x0060, "CS", s->modality ? s->modality : "CT");
    if (s->description)
        test_dicom_text(&b, 0x0008, 0x103E, "LO", s->description);
    if (s->sequences)
        test_dicom_references(&b);
    test_dicom_text(&b, 0x0020, 0x000D, "UI", "1.2.826.0.1.3680043.2.1125.7");
    test_dicom_text(&b, 0x0020, 0x000E, "UI", s->series_uid);
    snprintf(text, sizeof text, "%u", z + 1);
    test_dicom_text(&b, 0x0020, 0x0013, "IS", text);
    double at[3];
    test_dicom_position(s, 0, 0, z, at);
    snprintf(text, sizeof text, "%.10g\\%.10g\\%.10g", at[0], at[1], at[2]);
    if (!s->no_position)
        test_dicom_text(&b, 0x0020, 0x0032, "DS", text);
    test_dicom_text(&b, 0x0020, 0x0037, "DS", "1\\0\\0\\0\\1\\0");
    test_dicom_us(&b, 0x0028, 0x0002, 1);
    test_dicom_text(&b, 0x0028, 0x0004, "CS", s->photometric ? s->photometric : "MONOCHROME2");
    test_dicom_us(&b, 0x0028, 0x0010, s->dims[1]);
    test_dicom_us(&b, 0x0028, 0x0011, s->dims[0]);
    snprintf(text, sizeof text, "%g\\%g", s->pixel_spacing[0], s->pixel_spacing[1]);
    test_dicom_text(&b, 0x0028, 0x0030, "DS", text);
    test_dicom_us(&b, 0x0028, 0x0100, bits);
    test_dicom_us(&b, 0x0028, 0x0101, bits);
    test_dicom_us(&b, 0x0028, 0x0102, bits - 1);
    test_dicom_us(&b, 0x0028, 0x0103, s->type == IP_INT16);
    if (s->rescale) {
        snprintf(text, sizeof text, "%g", s->intercept);
        test_dicom_text(&b, 0x0028, 0x1052, "DS", text);
        snprintf(text, sizeof text, "%g", s->slope);
        test_dicom_text(&b, 0x0028, 0x1053, "DS", text);
        if (s->rescale_type)
            test_dicom_text(&b, 0x0028, 0x1054, "LO", s->rescale_type);
    }
    if (s->sequences)
        test_dicom_icon(&b);
    if (s->overlay)
        test_dicom_overlay(&b, s->dims[0], s->dims[1]);
    if (strcmp(syntax, TEST_DICOM_RLE) == 0) {
        test_dicom_rle_pixels(&b, plane, count, sample);
    } else {
        /* samples in the data set's byte order */
        unsigned char *swapped = malloc(count * sample);
        REQUIRE(swapped != NULL);
        for (size_t i = 0; i < count * sample; i++)
            swapped[i] = plane[b.big_endian ? (i ^ (sample - 1)) : i];
        test_dicom_element(&b, 0x7FE0, 0x0010, sample == 1 ? "OB" : "OW", swapped, count * sample);
        free(swapped);
    }
    if (strcmp(syntax, TEST_DICOM_DEFLATE) == 0)
        test_deflate_tail(&b, data_set);
    *out = b;
}

/* Writes plane z of `volume` as the DICOM file `path` (test_dicom_slice_bytes()). */
static inline void test_dicom_write_slice(const test_dicom_series *s, const void *volume,
                                          uint32_t z, const char *path)
{
    test_bytes b = {0};
    test_dicom_slice_bytes(s, volume, z, &b);
    FILE *f = fopen(path, "wb");
    REQUIRE(f != NULL);
    REQUIRE(fwrite(b.data, 1, b.size, f) == b.size);
    REQUIRE(fclose(f) == 0);
    free(b.data);
}

/* Writes the series into the folder `dir` (which must exist) as IM0001.dcm, IM0002.dcm, ...
 * in a shuffled order: file i holds plane (i * 7 + 3) mod dims[2] (dims[2] not a multiple of
 * 7), so that only the positions give the order. */
static inline void test_dicom_write_series(const test_dicom_series *s, const void *volume,
                                           const char *dir)
{
    char path[4096];
    REQUIRE(s->dims[2] % 7 != 0);
    for (uint32_t i = 0; i < s->dims[2]; i++) {
        snprintf(path, sizeof path, "%.4000s/IM%04u.dcm", dir, i + 1);
        test_dicom_write_slice(s, volume, (i * 7 + 3) % s->dims[2], path);
    }
}

/* A DICOM object that is not an image, of SOP class `sop_class` in series `series_uid` (none
 * for a directory, whose data set holds no SOP Class UID), as the file `path`: a few elements
 * of its module, no Pixel Data. */
static inline void test_dicom_write_object(const char *path, const char *sop_class,
                                           const char *series_uid)
{
    test_bytes b = {0};
    int directory = strcmp(sop_class, TEST_DICOM_DIRECTORY) == 0;
    int report = strncmp(sop_class, "1.2.840.10008.5.1.4.1.1.88.", 27) == 0;
    test_bytes_put(&b, (unsigned char[128]){0}, 128);
    test_bytes_put(&b, "DICM", 4);
    test_dicom_meta_of(&b, sop_class, "1.2.826.0.1.3680043.2.1125.77", TEST_DICOM_EXPLICIT_LE);
    if (directory) { /* File-set Identification and an empty Directory Record Sequence */
        test_dicom_text(&b, 0x0004, 0x1130, "CS", "SCANNER");
        test_dicom_us(&b, 0x0004, 0x1212, 0);
        test_dicom_open(&b, 0x0004, 0x1220, 1);
        test_dicom_open(&b, 0xFFFE, 0xE0DD, 0);
    } else {
        test_dicom_text(&b, 0x0008, 0x0016, "UI", sop_class);
        test_dicom_text(&b, 0x0008, 0x0018, "UI", "1.2.826.0.1.3680043.2.1125.77");
        test_dicom_text(&b, 0x0008, 0x0060, "CS", report ? "SR" : "PR");
        test_dicom_text(&b, 0x0020, 0x000E, "UI", series_uid);
        if (report)
            test_dicom_text(&b, 0x0040, 0xA040, "CS", "CONTAINER");
    }
    FILE *f = fopen(path, "wb");
    REQUIRE(f != NULL);
    REQUIRE(fwrite(b.data, 1, b.size, f) == b.size);
    REQUIRE(fclose(f) == 0);
    free(b.data);
}

#endif

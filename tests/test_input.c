/* SPDX-License-Identifier: BSD-3-Clause */
/* The input module: raw files by name and by overrides, NRRD, MetaImage, gzip, byte order,
 * large offsets, and every kind of bad input. Test files are generated in the scratch folder. */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdint.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include "check.h"
#include "input_check.h"
#include "isoprop/input.h"

static char scratch[4096];

static const char *in_scratch(char *buf, const char *name)
{
    int n = snprintf(buf, 4096, "%s/%s", scratch, name);
    REQUIRE(n > 0 && n < 4096);
    return buf;
}

/* ---- writing test files ---- */

static void write_bytes(const char *path, const char *mode, const void *data, size_t size)
{
    FILE *f = fopen(path, mode);
    REQUIRE(f != NULL);
    REQUIRE(size == 0 || fwrite(data, 1, size, f) == size);
    REQUIRE(fclose(f) == 0);
}

static void write_text(const char *path, const char *text)
{
    write_bytes(path, "wb", text, strlen(text));
}

static void append_text(const char *path, const char *text)
{
    write_bytes(path, "ab", text, strlen(text));
}

/* gzopen in append mode adds a complete gzip member after whatever the file holds. */
static void append_gzip(const char *path, const void *data, size_t size)
{
    gzFile gz = gzopen(path, "ab");
    REQUIRE(gz != NULL);
    REQUIRE(gzwrite(gz, data, (unsigned)size) == (int)size);
    REQUIRE(gzclose(gz) == Z_OK);
}

/* A zlib stream (what MetaImage writers produce for CompressedData = True). */
static void append_zlib(const char *path, const void *data, size_t size)
{
    uLongf packed_size = compressBound((uLong)size);
    unsigned char *packed = malloc(packed_size);
    REQUIRE(packed != NULL);
    REQUIRE(compress2(packed, &packed_size, data, (uLong)size, 6) == Z_OK);
    write_bytes(path, "ab", packed, packed_size);
    free(packed);
}

static uint64_t file_size(const char *path)
{
    struct stat st;
    REQUIRE(stat(path, &st) == 0);
    return (uint64_t)st.st_size;
}

/* ---- sample values: each a function of (x,y,z) that uses both bytes of 16-bit types ---- */

static double expected_value(ip_type type, uint32_t x, uint32_t y, uint32_t z)
{
    switch (type) {
    case IP_UINT8: return (double)((x + 3 * y + 7 * z) & 0xff);
    case IP_UINT16: return (double)(300 + x + 100 * y + 1000 * z);
    case IP_INT16: return (double)x + 10.0 * y + 100.0 * z - 500.0;
    case IP_FLOAT32: return 0.5 * x + 0.25 * y - 2.0 * z + 0.125;
    }
    return 0.0;
}

static void store_sample(unsigned char *dst, ip_type type, int big_endian, double value)
{
    uint32_t bits = 0;
    size_t size = ip_type_size(type);
    if (type == IP_UINT8 || type == IP_UINT16) {
        bits = (uint32_t)value;
    } else if (type == IP_INT16) {
        bits = (uint16_t)(int16_t)value;
    } else {
        float f = (float)value;
        memcpy(&bits, &f, sizeof bits);
    }
    for (size_t i = 0; i < size; i++) {
        size_t shift = big_endian ? size - 1 - i : i;
        dst[i] = (unsigned char)(bits >> (8 * shift));
    }
}

/* The bytes of a whole volume in the given byte order; free() the result. */
static unsigned char *make_volume(ip_type type, const uint32_t dims[3], int big_endian,
                                  size_t *size)
{
    size_t sample = ip_type_size(type);
    *size = (size_t)dims[0] * dims[1] * dims[2] * sample;
    unsigned char *data = malloc(*size);
    REQUIRE(data != NULL);
    unsigned char *p = data;
    for (uint32_t z = 0; z < dims[2]; z++)
        for (uint32_t y = 0; y < dims[1]; y++)
            for (uint32_t x = 0; x < dims[0]; x++, p += sample)
                store_sample(p, type, big_endian, expected_value(type, x, y, z));
    return data;
}

static void write_volume(const char *path, const char *mode, ip_type type, const uint32_t dims[3],
                         int big_endian)
{
    size_t size;
    unsigned char *data = make_volume(type, dims, big_endian, &size);
    write_bytes(path, mode, data, size);
    free(data);
}

static void append_gzip_volume(const char *path, ip_type type, const uint32_t dims[3],
                               int big_endian)
{
    size_t size;
    unsigned char *data = make_volume(type, dims, big_endian, &size);
    append_gzip(path, data, size);
    free(data);
}

/* ---- reading back ---- */

/* Reads every plane, `step` planes at a time, and compares each sample with expected_value();
 * then checks that one more plane is refused. Returns the number of wrong samples. */
static int read_and_compare(const ip_input_desc *desc, uint32_t step)
{
    ip_input_reader *reader = NULL;
    ip_error err;
    int wrong = 0;
    size_t plane = (size_t)desc->dims[0] * desc->dims[1];
    ip_status status = ip_input_open(desc, &reader, &err);
    CHECK_MSG(status == IP_OK, "%s", err.message);
    if (status != IP_OK)
        return 1;
    void *buf = malloc(plane * step * ip_type_size(desc->type));
    REQUIRE(buf != NULL);
    for (uint32_t z0 = 0; z0 < desc->dims[2]; z0 += step) {
        uint32_t count = desc->dims[2] - z0 < step ? desc->dims[2] - z0 : step;
        status = ip_input_read_planes(reader, buf, count, &err);
        CHECK_MSG(status == IP_OK, "%s", err.message);
        if (status != IP_OK) {
            wrong++;
            break;
        }
        for (size_t i = 0; i < plane * count; i++) {
            uint32_t x = (uint32_t)(i % desc->dims[0]);
            uint32_t y = (uint32_t)(i / desc->dims[0] % desc->dims[1]);
            uint32_t z = z0 + (uint32_t)(i / plane);
            if ((double)ip_sample_get(buf, desc->type, i) !=
                (double)(float)expected_value(desc->type, x, y, z))
                wrong++;
        }
    }
    CHECK_MSG(wrong == 0, "%s: %d wrong samples", desc->path, wrong);
    CHECK_EQ(ip_input_read_planes(reader, buf, 1, &err), IP_ERR_ARGUMENT);
    CHECK_CONTAINS(err.message, "planes");
    free(buf);
    ip_input_close(reader);
    return wrong;
}

/* Describes `path`, expecting success; returns 1 when it worked. */
static int describe_ok(const char *path, const ip_input_overrides *overrides, ip_input_desc *d)
{
    ip_error err;
    ip_status status = ip_input_describe(path, overrides, d, &err);
    CHECK_MSG(status == IP_OK, "%s: %s", path, err.message);
    return status == IP_OK;
}

/* Reads every plane of `desc` one at a time, expecting the reads to fail with `code` and a
 * message holding `needle`; then checks that the reader stays failed. */
static void read_fails(const ip_input_desc *desc, ip_status code, const char *needle)
{
    ip_input_reader *reader = NULL;
    ip_error err;
    ip_status status = IP_OK;
    ip_error_clear(&err);
    REQUIRE(ip_input_open(desc, &reader, &err) == IP_OK);
    void *buf = malloc((size_t)desc->dims[0] * desc->dims[1] * ip_type_size(desc->type));
    REQUIRE(buf != NULL);
    for (uint32_t z = 0; z < desc->dims[2] && status == IP_OK; z++)
        status = ip_input_read_planes(reader, buf, 1, &err);
    CHECK_MSG(status == code, "%s: got %d (%s), expected %d", desc->path, status, err.message,
              code);
    CHECK_CONTAINS(err.message, needle);
    CHECK_NE(ip_input_read_planes(reader, buf, 1, &err), IP_OK);
    free(buf);
    ip_input_close(reader);
}

/* ---- raw files ---- */

static void test_raw_by_name(void)
{
    static const struct {
        const char *name;
        ip_type type;
        uint32_t dims[3];
    } files[] = {
        {"tiny_ct_scan_5x4x3_uint8.raw", IP_UINT8, {5, 4, 3}},
        {"a_6x5x4_uint16.raw", IP_UINT16, {6, 5, 4}},
        {"b_3x3x7_int16.raw", IP_INT16, {3, 3, 7}},
        {"c_4x3x2_float32.raw", IP_FLOAT32, {4, 3, 2}},
        {"10x2x2_uint8.raw", IP_UINT8, {10, 2, 2}},
    };
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        char path[4096];
        ip_input_desc d;
        in_scratch(path, files[i].name);
        write_volume(path, "wb", files[i].type, files[i].dims, 0);
        if (!describe_ok(path, NULL, &d))
            continue;
        CHECK_EQ(d.dims[0], files[i].dims[0]);
        CHECK_EQ(d.dims[1], files[i].dims[1]);
        CHECK_EQ(d.dims[2], files[i].dims[2]);
        CHECK_EQ(d.type, files[i].type);
        CHECK_STR_EQ(d.path, path);
        CHECK_STR_EQ(d.data_path, path);
        CHECK_EQ(d.data_offset, 0);
        CHECK_EQ(d.big_endian, 0);
        CHECK_EQ(d.encoding, IP_ENCODING_RAW);
        CHECK_EQ(d.spacing[0], 1.0);
        CHECK_EQ(d.spacing[1], 1.0);
        CHECK_EQ(d.spacing[2], 1.0);
        read_and_compare(&d, 1);
        read_and_compare(&d, 2);
    }
}

static void test_raw_by_overrides(void)
{
    char path[4096];
    ip_input_desc d;
    const uint32_t dims[3] = {7, 6, 5};
    ip_input_overrides ov = {0};
    in_scratch(path, "volume.bin");
    write_volume(path, "wb", IP_INT16, dims, 0);
    ov.has_dims = 1;
    memcpy(ov.dims, dims, sizeof ov.dims);
    ov.has_type = 1;
    ov.type = IP_INT16;
    ov.has_spacing = 1;
    ov.spacing[0] = 0.5;
    ov.spacing[1] = 0.5;
    ov.spacing[2] = 2.5;
    if (describe_ok(path, &ov, &d)) {
        CHECK_EQ(d.dims[0], 7);
        CHECK_EQ(d.dims[1], 6);
        CHECK_EQ(d.dims[2], 5);
        CHECK_EQ(d.type, IP_INT16);
        CHECK_EQ(d.spacing[0], 0.5);
        CHECK_EQ(d.spacing[2], 2.5);
        read_and_compare(&d, 5);
    }
    /* Neither the name nor the overrides say enough. */
    describe_fails(path, NULL, IP_ERR_INPUT, "volume.bin",
                   "cannot tell dims and type: name it NAME_XxYxZ_TYPE.raw or pass --dims and "
                   "--type");
    ov.has_type = 0;
    describe_fails(path, &ov, IP_ERR_INPUT, "volume.bin", "cannot tell dims and type");
    in_scratch(path, "not_the_convention.raw");
    write_volume(path, "wb", IP_UINT8, dims, 0);
    describe_fails(path, NULL, IP_ERR_INPUT, "not_the_convention.raw", "cannot tell");
    ov.has_type = 1;
    ov.type = IP_UINT8;
    ov.has_spacing = 0;
    if (describe_ok(path, &ov, &d))
        read_and_compare(&d, 3);
}

/* The name says one thing, the overrides another: the overrides win, field by field. */
static void test_overrides_win(void)
{
    char path[4096];
    ip_input_desc d;
    const uint32_t dims[3] = {4, 3, 2};
    ip_input_overrides ov = {0};
    in_scratch(path, "misnamed_2x2x6_uint8.raw");
    write_volume(path, "wb", IP_UINT16, dims, 1);
    ov.has_dims = 1;
    memcpy(ov.dims, dims, sizeof ov.dims);
    ov.has_type = 1;
    ov.type = IP_UINT16;
    ov.has_endian = 1;
    ov.big_endian = 1;
    if (describe_ok(path, &ov, &d)) {
        CHECK_EQ(d.dims[0], 4);
        CHECK_EQ(d.dims[2], 2);
        CHECK_EQ(d.type, IP_UINT16);
        CHECK_EQ(d.big_endian, 1);
        read_and_compare(&d, 2);
    }
    /* Only the type overridden: dims still come from the name (2x2x6 x 2 bytes = 48). */
    ov.has_dims = 0;
    if (describe_ok(path, &ov, &d)) {
        CHECK_EQ(d.dims[0], 2);
        CHECK_EQ(d.dims[1], 2);
        CHECK_EQ(d.dims[2], 6);
        CHECK_EQ(d.type, IP_UINT16);
    }
    /* An unknown type in the name does not matter once the type is given. */
    in_scratch(path, "odd_4x3x2_uint64.raw");
    write_volume(path, "wb", IP_UINT16, dims, 0);
    ov.has_endian = 0;
    if (describe_ok(path, &ov, &d))
        read_and_compare(&d, 1);
}

static void test_big_endian_raw(void)
{
    char path[4096];
    ip_input_desc d;
    const uint32_t dims[3] = {9, 4, 3};
    ip_input_overrides ov = {0};
    ov.has_endian = 1;
    ov.big_endian = 1;
    in_scratch(path, "be_9x4x3_uint16.raw");
    write_volume(path, "wb", IP_UINT16, dims, 1);
    if (describe_ok(path, &ov, &d)) {
        CHECK_EQ(d.big_endian, 1);
        read_and_compare(&d, 1);
    }
    in_scratch(path, "be_9x4x3_float32.raw");
    write_volume(path, "wb", IP_FLOAT32, dims, 1);
    if (describe_ok(path, &ov, &d))
        read_and_compare(&d, 3);
    in_scratch(path, "be_9x4x3_int16.raw");
    write_volume(path, "wb", IP_INT16, dims, 1);
    if (describe_ok(path, &ov, &d))
        read_and_compare(&d, 2);
    /* A known value, checked byte by byte: 0x0102 stored big-endian reads back as 258. */
    in_scratch(path, "known_2x2x2_uint16.raw");
    const unsigned char bytes[16] = {1, 2, 1, 2, 1, 2, 1, 2, 1, 2, 1, 2, 1, 2, 1, 2};
    write_bytes(path, "wb", bytes, sizeof bytes);
    if (describe_ok(path, &ov, &d)) {
        ip_input_reader *r;
        ip_error err;
        uint16_t plane[4];
        REQUIRE(ip_input_open(&d, &r, &err) == IP_OK);
        CHECK_EQ(ip_input_read_planes(r, plane, 1, &err), IP_OK);
        CHECK_EQ(plane[0], 258);
        CHECK_EQ(plane[3], 258);
        ip_input_close(r);
    }
}

/* ---- NRRD ---- */

static void test_nrrd_attached(void)
{
    char path[4096];
    ip_input_desc d;
    const uint32_t dims[3] = {5, 4, 3};
    const char *header = "NRRD0004\n"
                         "# a comment: with a colon\n"
                         "content: test volume: attached\n"
                         "type: short\n"
                         "dimension: 3\n"
                         "sizes: 5 4 3\n"
                         "endian: little\n"
                         "encoding: raw\n"
                         "spacings: 0.5 -0.75 nan\n"
                         "kinds: domain domain domain\n"
                         "some key:=some: value\n"
                         "\n";
    in_scratch(path, "attached.nrrd");
    write_text(path, header);
    write_volume(path, "ab", IP_INT16, dims, 0);
    if (describe_ok(path, NULL, &d)) {
        CHECK_EQ(d.data_offset, strlen(header));
        CHECK_EQ(d.type, IP_INT16);
        CHECK_EQ(d.dims[0], 5);
        CHECK_EQ(d.dims[1], 4);
        CHECK_EQ(d.dims[2], 3);
        CHECK_EQ(d.spacing[0], 0.5);
        CHECK_EQ(d.spacing[1], 0.75);
        CHECK_EQ(d.spacing[2], 1.0);
        CHECK_STR_EQ(d.data_path, path);
        read_and_compare(&d, 1);
    }
    /* CRLF line endings and every type spelling of the format. */
    static const struct {
        const char *spelling;
        ip_type type;
    } types[] = {
        {"uchar", IP_UINT8},
        {"unsigned char", IP_UINT8},
        {"uint8", IP_UINT8},
        {"uint8_t", IP_UINT8},
        {"ushort", IP_UINT16},
        {"unsigned short", IP_UINT16},
        {"unsigned short int", IP_UINT16},
        {"uint16", IP_UINT16},
        {"uint16_t", IP_UINT16},
        {"short", IP_INT16},
        {"short int", IP_INT16},
        {"signed short", IP_INT16},
        {"signed short int", IP_INT16},
        {"int16", IP_INT16},
        {"int16_t", IP_INT16},
        {"float", IP_FLOAT32},
    };
    for (size_t i = 0; i < sizeof types / sizeof types[0]; i++) {
        char text[512];
        snprintf(text, sizeof text,
                 "NRRD0005\r\ntype: %s\r\ndimension: 3\r\nsizes: 5 4 3\r\nendian: big\r\n"
                 "encoding: raw\r\n\r\n",
                 types[i].spelling);
        write_text(path, text);
        write_volume(path, "ab", types[i].type, dims, 1);
        if (describe_ok(path, NULL, &d)) {
            CHECK_MSG(d.type == types[i].type, "%s", types[i].spelling);
            CHECK_EQ(d.data_offset, strlen(text));
            CHECK_EQ(d.big_endian, 1);
            read_and_compare(&d, 3);
        }
    }
}

static void test_nrrd_detached(void)
{
    char header[4096], data[4096];
    ip_input_desc d;
    const uint32_t dims[3] = {6, 5, 4};
    /* "data file:" relative to the header's folder, after a PGM-like text preamble. */
    in_scratch(data, "detached_data.bin");
    write_text(data, "P5\n# preamble line\nXYZ");
    write_volume(data, "ab", IP_FLOAT32, dims, 0);
    in_scratch(header, "detached.nhdr");
    write_text(header, "NRRD0004\ntype: float\ndimension: 3\nsizes: 6 5 4\nendian: little\n"
                       "encoding: raw\ndata file: detached_data.bin\nline skip: 2\n"
                       "byte skip: 3\n");
    if (describe_ok(header, NULL, &d)) {
        CHECK_STR_EQ(d.data_path, data);
        CHECK_EQ(d.data_offset, strlen("P5\n# preamble line\nXYZ"));
        read_and_compare(&d, 4);
    }
    /* "datafile:" spelling, an absolute path, and a header given by a relative path. */
    char text[8192];
    in_scratch(data, "detached_plain.raw");
    write_volume(data, "wb", IP_UINT8, dims, 0);
    snprintf(text, sizeof text,
             "NRRD0001\ntype: uchar\ndimension: 3\nsizes: 6 5 4\n"
             "encoding: raw\ndatafile: %s\n",
             data);
    write_text(header, text);
    if (describe_ok(header, NULL, &d)) {
        CHECK_STR_EQ(d.data_path, data);
        CHECK_EQ(d.data_offset, 0);
        read_and_compare(&d, 1);
    }
    char cwd[4096];
    REQUIRE(getcwd(cwd, sizeof cwd) != NULL);
    REQUIRE(chdir(scratch) == 0);
    write_text("relative.nhdr", "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 6 5 4\n"
                                "encoding: raw\ndata file: ./detached_plain.raw\n");
    if (describe_ok("relative.nhdr", NULL, &d)) {
        CHECK_STR_EQ(d.data_path, "./detached_plain.raw");
        read_and_compare(&d, 2);
    }
    REQUIRE(chdir(cwd) == 0);
}

static void test_nrrd_gzip(void)
{
    char path[4096], data[4096];
    ip_input_desc d;
    const uint32_t dims[3] = {17, 13, 11};
    const char *header = "NRRD0004\ntype: uint16\ndimension: 3\nsizes: 17 13 11\nendian: big\n"
                         "encoding: gzip\n\n";
    in_scratch(path, "gzip.nrrd");
    write_text(path, header);
    append_gzip_volume(path, IP_UINT16, dims, 1);
    if (describe_ok(path, NULL, &d)) {
        CHECK_EQ(d.encoding, IP_ENCODING_GZIP);
        CHECK_EQ(d.data_offset, strlen(header));
        read_and_compare(&d, 1);
        read_and_compare(&d, 4);
        read_and_compare(&d, 11);
    }
    /* Detached, "gz" spelling, float32. */
    in_scratch(data, "gzip_data.raw.gz");
    write_text(data, "");
    append_gzip_volume(data, IP_FLOAT32, dims, 0);
    in_scratch(path, "gzip.nhdr");
    write_text(path, "NRRD0004\ntype: float\ndimension: 3\nsizes: 17 13 11\nendian: little\n"
                     "encoding: gz\ndata file: gzip_data.raw.gz\n");
    if (describe_ok(path, NULL, &d)) {
        CHECK_EQ(d.encoding, IP_ENCODING_GZIP);
        CHECK_STR_EQ(d.data_path, data);
        read_and_compare(&d, 3);
    }
    /* Two gzip members one after the other are one valid gzip file. */
    size_t size;
    unsigned char *bytes = make_volume(IP_UINT8, dims, 0, &size);
    in_scratch(path, "members.nrrd");
    write_text(path, "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 17 13 11\nencoding: gzip\n\n");
    append_gzip(path, bytes, 1000);
    append_gzip(path, bytes + 1000, size - 1000);
    if (describe_ok(path, NULL, &d))
        read_and_compare(&d, 2);
    free(bytes);
}

static void test_nrrd_space_directions(void)
{
    char path[4096];
    ip_input_desc d;
    const uint32_t dims[3] = {3, 3, 3};
    in_scratch(path, "directions.nrrd");
    write_text(path, "NRRD0004\ntype: uint8\ndimension: 3\nspace: right-anterior-superior\n"
                     "sizes: 3 3 3\nspace directions: (0.5,0,0) (0,2,0) (0,0,3)\n"
                     "space origin: (1,2,3)\nencoding: raw\n\n");
    write_volume(path, "ab", IP_UINT8, dims, 0);
    if (describe_ok(path, NULL, &d)) {
        CHECK_EQ(d.spacing[0], 0.5);
        CHECK_EQ(d.spacing[1], 2.0);
        CHECK_EQ(d.spacing[2], 3.0);
        read_and_compare(&d, 3);
    }
    /* Oblique axes: the spacing is the length of each direction vector. */
    write_text(path, "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 3 3 3\n"
                     "space directions: (3,4,0) (0, 0, -2.5) (0.6,0,0.8)\nencoding: raw\n\n");
    write_volume(path, "ab", IP_UINT8, dims, 0);
    if (describe_ok(path, NULL, &d)) {
        CHECK_NEAR(d.spacing[0], 5.0, 1e-12);
        CHECK_NEAR(d.spacing[1], 2.5, 1e-12);
        CHECK_NEAR(d.spacing[2], 1.0, 1e-12);
    }
    /* "none" marks an axis without a direction: it keeps the default spacing. */
    write_text(path, "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 3 3 3\n"
                     "space directions: (0,0,4) none (2,0,0)\nencoding: raw\n\n");
    write_volume(path, "ab", IP_UINT8, dims, 0);
    if (describe_ok(path, NULL, &d)) {
        CHECK_EQ(d.spacing[0], 4.0);
        CHECK_EQ(d.spacing[1], 1.0);
        CHECK_EQ(d.spacing[2], 2.0);
    }
    /* An explicit spacing override wins over the directions. */
    ip_input_overrides ov = {0};
    ov.has_spacing = 1;
    ov.spacing[0] = ov.spacing[1] = ov.spacing[2] = 0.25;
    if (describe_ok(path, &ov, &d)) {
        CHECK_EQ(d.spacing[0], 0.25);
        CHECK_EQ(d.spacing[1], 0.25);
        CHECK_EQ(d.spacing[2], 0.25);
    }
}

static void test_nrrd_byte_skip(void)
{
    char header[4096], data[4096];
    ip_input_desc d;
    const uint32_t dims[3] = {8, 3, 2};
    /* byte skip -1: the data are the last bytes of the file, whatever precedes them. */
    in_scratch(data, "skip_end.dat");
    const char *prefix = "a header of some other format";
    write_text(data, prefix);
    write_volume(data, "ab", IP_INT16, dims, 1);
    in_scratch(header, "skip_end.nhdr");
    write_text(header, "NRRD0004\ntype: int16\ndimension: 3\nsizes: 8 3 2\nendian: big\n"
                       "encoding: raw\nbyte skip: -1\ndata file: skip_end.dat\n");
    if (describe_ok(header, NULL, &d)) {
        CHECK_EQ(d.data_offset, strlen(prefix));
        read_and_compare(&d, 1);
    }
    /* ... attached too: the blank line's position does not matter then. */
    in_scratch(header, "skip_end.nrrd");
    write_text(header, "NRRD0004\ntype: int16\ndimension: 3\nsizes: 8 3 2\nendian: big\n"
                       "encoding: raw\nbyte skip: -1\n\nsome padding");
    write_volume(header, "ab", IP_INT16, dims, 1);
    if (describe_ok(header, NULL, &d)) {
        CHECK_EQ(d.data_offset, file_size(header) - 8 * 3 * 2 * 2);
        read_and_compare(&d, 2);
    }
    /* A positive byte skip after an attached header. */
    write_text(header, "NRRD0004\ntype: int16\ndimension: 3\nsizes: 8 3 2\nendian: big\n"
                       "encoding: raw\nbyte skip: 5\n\n12345");
    write_volume(header, "ab", IP_INT16, dims, 1);
    if (describe_ok(header, NULL, &d)) {
        CHECK_EQ(d.data_offset, file_size(header) - 8 * 3 * 2 * 2);
        read_and_compare(&d, 2);
    }
}

/* Overridden fields are not even read from the header. */
static void test_nrrd_overrides(void)
{
    char path[4096];
    ip_input_desc d;
    const uint32_t dims[3] = {4, 4, 4};
    ip_input_overrides ov = {0};
    in_scratch(path, "overridden.nrrd");
    write_text(path, "NRRD0004\ntype: double\ndimension: 2\nsizes: 64 4\nendian: sideways\n"
                     "encoding: raw\n\n");
    write_volume(path, "ab", IP_UINT16, dims, 1);
    describe_fails(path, NULL, IP_ERR_INPUT, "overridden.nrrd", "unsupported NRRD type 'double'");
    ov.has_type = 1;
    ov.type = IP_UINT16;
    ov.has_dims = 1;
    memcpy(ov.dims, dims, sizeof ov.dims);
    ov.has_endian = 1;
    ov.big_endian = 1;
    if (describe_ok(path, &ov, &d))
        read_and_compare(&d, 4);
}

/* ---- MetaImage ---- */

static void test_mhd(void)
{
    char header[4096], data[4096], text[1024];
    ip_input_desc d;
    const uint32_t dims[3] = {7, 5, 3};
    /* A separate data file, big-endian, with spacing. */
    in_scratch(data, "meta_data.raw");
    write_volume(data, "wb", IP_UINT16, dims, 1);
    in_scratch(header, "meta.mhd");
    write_text(header, "ObjectType = Image\nNDims = 3\nDimSize = 7 5 3\n"
                       "ElementSpacing = 0.5 1.5 2\nBinaryData = True\n"
                       "BinaryDataByteOrderMSB = True\nElementType = MET_USHORT\n"
                       "ElementDataFile = meta_data.raw\n");
    if (describe_ok(header, NULL, &d)) {
        CHECK_STR_EQ(d.data_path, data);
        CHECK_EQ(d.big_endian, 1);
        CHECK_EQ(d.type, IP_UINT16);
        CHECK_EQ(d.spacing[0], 0.5);
        CHECK_EQ(d.spacing[1], 1.5);
        CHECK_EQ(d.spacing[2], 2.0);
        read_and_compare(&d, 1);
    }
    /* ElementSize stands in for a missing ElementSpacing; ElementByteOrderMSB spelling. */
    write_volume(data, "wb", IP_INT16, dims, 0);
    write_text(header, "NDims = 3\nDimSize = 7 5 3\nElementSize = 3 2 1\n"
                       "ElementByteOrderMSB = False\nElementType = MET_SHORT\n"
                       "ElementDataFile = meta_data.raw\n");
    if (describe_ok(header, NULL, &d)) {
        CHECK_EQ(d.spacing[0], 3.0);
        CHECK_EQ(d.spacing[1], 2.0);
        CHECK_EQ(d.spacing[2], 1.0);
        read_and_compare(&d, 3);
    }
    /* LOCAL: the data follow the header line that says so. */
    const char *local = "NDims = 3\r\nDimSize = 7 5 3\r\nElementType = MET_FLOAT\r\n"
                        "ElementDataFile = LOCAL\r\n";
    in_scratch(header, "meta_local.mha");
    write_text(header, local);
    write_volume(header, "ab", IP_FLOAT32, dims, 0);
    if (describe_ok(header, NULL, &d)) {
        CHECK_EQ(d.data_offset, strlen(local));
        CHECK_STR_EQ(d.data_path, header);
        read_and_compare(&d, 2);
    }
    /* HeaderSize skips bytes of the data file; -1 puts the data at its end. */
    in_scratch(data, "meta_skip.raw");
    write_text(data, "0123456789abcdef");
    write_volume(data, "ab", IP_UINT8, dims, 0);
    in_scratch(header, "meta_skip.mhd");
    for (int at_end = 0; at_end < 2; at_end++) {
        snprintf(text, sizeof text,
                 "NDims = 3\nDimSize = 7 5 3\nElementType = MET_UCHAR\n"
                 "HeaderSize = %d\nElementDataFile = meta_skip.raw\n",
                 at_end ? -1 : 16);
        write_text(header, text);
        if (describe_ok(header, NULL, &d)) {
            CHECK_EQ(d.data_offset, 16);
            read_and_compare(&d, 3);
        }
    }
}

/* The space the NRRD `space` field names, long or short; any other space is unknown. */
static void test_nrrd_spaces(void)
{
    static const struct {
        const char *field;
        ip_space space;
        const char *name;
    } cases[] = {{"right-anterior-superior", IP_SPACE_RAS, "RAS"},
                 {"RAS", IP_SPACE_RAS, "RAS"},
                 {"left-anterior-superior", IP_SPACE_LAS, "LAS"},
                 {"left-posterior-superior", IP_SPACE_LPS, "LPS"},
                 {"LPS", IP_SPACE_LPS, "LPS"},
                 {"scanner-xyz", IP_SPACE_UNKNOWN, ""}};
    char path[4096], text[512];
    ip_input_desc d;
    const uint32_t dims[3] = {3, 3, 3};
    in_scratch(path, "spaces.nrrd");
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        snprintf(text, sizeof text,
                 "NRRD0004\ntype: uint8\ndimension: 3\nspace: %s\nsizes: 3 3 3\n"
                 "space directions: (0,0,-2) (0,1,0) (1,0,0)\nspace origin: (1,2,3)\n"
                 "encoding: raw\n\n",
                 cases[i].field);
        write_text(path, text);
        write_volume(path, "ab", IP_UINT8, dims, 0);
        if (!describe_ok(path, NULL, &d))
            continue;
        CHECK_MSG(d.orientation.space == cases[i].space &&
                      strcmp(ip_space_name(d.orientation.space), cases[i].name) == 0,
                  "space: %s", cases[i].field);
        /* the file's own space, not converted: the origin and directions as written */
        CHECK_EQ(d.orientation.origin[0], 1);
        CHECK_EQ(d.orientation.origin[1], 2);
        CHECK_EQ(d.orientation.origin[2], 3);
        CHECK_EQ(d.orientation.directions[0][2], -1);
        CHECK_EQ(d.orientation.directions[1][1], 1);
        CHECK_EQ(d.orientation.directions[2][0], 1);
        CHECK_EQ(d.spacing[0], 2);
    }
}

/* MetaImage: Offset (or Position, Origin) is the origin; TransformMatrix (or Rotation,
 * Orientation) lists the x axis direction, then y, then z; the spacing stays ElementSpacing;
 * AnatomicalOrientation is not read and no space is named; a matrix without an orthonormal
 * frame gives the identity directions and keeps the origin. */
static void test_mhd_orientation(void)
{
    /* the rotation of the unit quaternion (0.8, 0.2, 0.4, 0.4): axis a's direction */
    static const double axes[3][3] = {{0.36, 0.8, -0.48}, {-0.48, 0.6, 0.64}, {0.8, 0.0, 0.6}};
    static const struct {
        const char *origin_key, *matrix_key, *matrix;
        int framed;
    } cases[] = {{"Offset", "TransformMatrix", "0.36 0.8 -0.48 -0.48 0.6 0.64 0.8 0 0.6", 1},
                 {"Position", "Rotation", "0.36 0.8 -0.48 -0.48 0.6 0.64 0.8 0 0.6", 1},
                 {"Origin", "Orientation", "0.36 0.8 -0.48 -0.48 0.6 0.64 0.8 0 0.6", 1},
                 {"Offset", "TransformMatrix", "1 0.5 0 0 1 0 0 0 1", 0}};
    char header[4096], data[4096], text[1024];
    ip_input_desc d;
    const uint32_t dims[3] = {7, 5, 3};
    in_scratch(data, "turned.raw");
    write_volume(data, "wb", IP_UINT8, dims, 0);
    in_scratch(header, "turned.mhd");
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        snprintf(text, sizeof text,
                 "ObjectType = Image\nNDims = 3\n%s = 10 -20 30.5\n%s = %s\n"
                 "AnatomicalOrientation = LPI\nDimSize = 7 5 3\nElementSpacing = 0.5 0.75 2\n"
                 "ElementType = MET_UCHAR\nElementDataFile = turned.raw\n",
                 cases[i].origin_key, cases[i].matrix_key, cases[i].matrix);
        write_text(header, text);
        if (!describe_ok(header, NULL, &d))
            continue;
        double worst = 0.0;
        for (int a = 0; a < 3; a++)
            for (int c = 0; c < 3; c++)
                worst = fmax(worst, fabs(d.orientation.directions[a][c] -
                                         (cases[i].framed ? axes[a][c] : a == c)));
        CHECK_MSG(worst < 1e-12, "%s: directions off by %g", cases[i].matrix_key, worst);
        CHECK_EQ(d.orientation.origin[0], 10);
        CHECK_EQ(d.orientation.origin[1], -20);
        CHECK_EQ(d.orientation.origin[2], 30.5);
        CHECK_EQ(d.spacing[0], 0.5);
        CHECK_EQ(d.spacing[1], 0.75);
        CHECK_EQ(d.spacing[2], 2);
        CHECK_EQ(d.orientation.space, IP_SPACE_UNKNOWN);
        CHECK_EQ(read_and_compare(&d, 3), 0);
    }
    /* neither key: the identity */
    write_text(header, "NDims = 3\nDimSize = 7 5 3\nElementType = MET_UCHAR\n"
                       "ElementDataFile = turned.raw\n");
    if (describe_ok(header, NULL, &d))
        CHECK(ip_orientation_is_identity(&d.orientation));
}

static void test_mhd_compressed(void)
{
    char header[4096], data[4096];
    ip_input_desc d;
    const uint32_t dims[3] = {12, 9, 6};
    size_t size;
    unsigned char *bytes = make_volume(IP_INT16, dims, 0, &size);
    /* A zlib stream in a separate file. */
    in_scratch(data, "meta_zlib.zraw");
    write_text(data, "");
    append_zlib(data, bytes, size);
    in_scratch(header, "meta_zlib.mhd");
    write_text(header, "NDims = 3\nDimSize = 12 9 6\nElementType = MET_SHORT\n"
                       "CompressedData = True\nCompressedDataSize = 999\n"
                       "ElementDataFile = meta_zlib.zraw\n");
    if (describe_ok(header, NULL, &d)) {
        CHECK_EQ(d.encoding, IP_ENCODING_GZIP);
        read_and_compare(&d, 2);
    }
    /* LOCAL, compressed with a gzip wrapper. */
    in_scratch(header, "meta_gzip.mhd");
    write_text(header, "NDims = 3\nDimSize = 12 9 6\nElementType = MET_SHORT\n"
                       "CompressedData = true\nElementDataFile = LOCAL\n");
    append_gzip(header, bytes, size);
    if (describe_ok(header, NULL, &d))
        read_and_compare(&d, 6);
    free(bytes);
}

/* ---- bad input ---- */

static void test_wrong_size(void)
{
    char path[4096], header[4096];
    const uint32_t dims[3] = {5, 4, 3};
    size_t size;
    unsigned char *bytes = make_volume(IP_UINT8, dims, 0, &size);
    in_scratch(path, "short_5x4x3_uint8.raw");
    write_bytes(path, "wb", bytes, size - 1);
    describe_fails(path, NULL, IP_ERR_INPUT, "short_5x4x3_uint8.raw",
                   "file size 59 bytes does not equal 5x4x3 x 1 byte = 60 bytes");
    in_scratch(path, "long_5x4x3_uint16.raw");
    write_bytes(path, "wb", bytes, size);
    write_bytes(path, "ab", bytes, 1);
    describe_fails(path, NULL, IP_ERR_INPUT, "long_5x4x3_uint16.raw",
                   "file size 61 bytes does not equal 5x4x3 x 2 bytes = 120 bytes");
    /* With a header in front, the message tells the offset apart. */
    in_scratch(header, "short.nrrd");
    write_text(header, "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 5 4 3\nencoding: raw\n\n");
    write_bytes(header, "ab", bytes, size - 2);
    describe_fails(header, NULL, IP_ERR_INPUT, "short.nrrd", "data size 58 bytes");
    describe_fails(header, NULL, IP_ERR_INPUT, "short.nrrd", "= 60 bytes");
    /* A detached header names its data file too. */
    in_scratch(path, "short_data.raw");
    write_bytes(path, "wb", bytes, size - 3);
    in_scratch(header, "short.nhdr");
    write_text(header, "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 5 4 3\nencoding: raw\n"
                       "data file: short_data.raw\n");
    describe_fails(header, NULL, IP_ERR_INPUT, "short_data.raw", "file size 57 bytes");
    describe_fails(header, NULL, IP_ERR_INPUT, "short.nhdr", "60 bytes");
    /* byte skip -1 with too little data. */
    write_text(header, "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 5 4 3\nencoding: raw\n"
                       "byte skip: -1\ndata file: short_data.raw\n");
    describe_fails(header, NULL, IP_ERR_INPUT, "short_data.raw", "57 bytes");
    free(bytes);
}

static void test_unknown_type(void)
{
    char path[4096];
    in_scratch(path, "wide_4x4x4_uint64.raw");
    write_text(path, "");
    describe_fails(path, NULL, IP_ERR_INPUT, "wide_4x4x4_uint64.raw", "unknown type 'uint64'");
    in_scratch(path, "double.nrrd");
    write_text(path, "NRRD0004\ntype: double\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n");
    describe_fails(path, NULL, IP_ERR_INPUT, "double.nrrd", "unsupported NRRD type 'double'");
    write_text(path, "NRRD0004\ntype: int\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n");
    describe_fails(path, NULL, IP_ERR_INPUT, "double.nrrd", "unsupported NRRD type 'int'");
    in_scratch(path, "double.mhd");
    write_text(path, "NDims = 3\nDimSize = 2 2 2\nElementType = MET_DOUBLE\n"
                     "ElementDataFile = LOCAL\n");
    describe_fails(path, NULL, IP_ERR_INPUT, "double.mhd", "MET_DOUBLE");
    /* An out-of-range type in the overrides is the caller's mistake. */
    ip_input_overrides ov = {0};
    ov.has_type = 1;
    ov.type = (ip_type)42;
    ov.has_dims = 1;
    ov.dims[0] = ov.dims[1] = ov.dims[2] = 2;
    describe_fails(path, &ov, IP_ERR_ARGUMENT, "double.mhd", "unknown type 42");
}

static void test_dimension_under_2(void)
{
    char path[4096];
    const uint32_t flat[3] = {4, 4, 1};
    in_scratch(path, "flat_4x4x1_uint8.raw");
    write_volume(path, "wb", IP_UINT8, flat, 0);
    describe_fails(path, NULL, IP_ERR_INPUT, "flat_4x4x1_uint8.raw",
                   "dimension 1 along z is under 2");
    in_scratch(path, "flat.nrrd");
    write_text(path, "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 4 1 4\nencoding: raw\n\n");
    write_volume(path, "ab", IP_UINT8, flat, 0);
    describe_fails(path, NULL, IP_ERR_INPUT, "flat.nrrd", "dimension 1 along y is under 2");
    in_scratch(path, "zero_0x4x4_uint8.raw");
    write_text(path, "");
    describe_fails(path, NULL, IP_ERR_INPUT, "zero_0x4x4_uint8.raw",
                   "dimension 0 along x is under 2");
    ip_input_overrides ov = {0};
    ov.has_dims = 1;
    ov.dims[0] = 1;
    ov.dims[1] = 16;
    ov.dims[2] = 1;
    describe_fails(path, &ov, IP_ERR_INPUT, "zero_0x4x4_uint8.raw", "along x is under 2");
}

static void test_bad_headers(void)
{
    char path[4096];
    static const struct {
        const char *name;
        const char *text;
        const char *needle;
    } cases[] = {
        {"garbage.nrrd", "\x89PNG\r\n\x1a\n not a volume at all", "not a NRRD file"},
        {"empty.nrrd", "", "not a NRRD file"},
        {"nomagic.nrrd", "type: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n",
         "not a NRRD file"},
        {"nosizes.nrrd", "NRRD0004\ntype: uint8\ndimension: 3\nencoding: raw\n\n",
         "missing field 'sizes'"},
        {"notype.nrrd", "NRRD0004\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n",
         "missing field 'type'"},
        {"nodim.nrrd", "NRRD0004\ntype: uint8\nsizes: 2 2 2\nencoding: raw\n\n",
         "missing field 'dimension'"},
        {"noenc.nrrd", "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\n\n",
         "missing field 'encoding'"},
        {"noendian.nrrd", "NRRD0004\ntype: uint16\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n",
         "missing field 'endian'"},
        {"dim2.nrrd", "NRRD0004\ntype: uint8\ndimension: 2\nsizes: 2 2\nencoding: raw\n\n",
         "dimension 2 is not supported"},
        {"badnum.nrrd", "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 two 2\nencoding: raw\n\n",
         "bad sizes '2 two 2'"},
        {"negsize.nrrd", "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 -2 2\nencoding: raw\n\n",
         "bad sizes"},
        {"count.nrrd", "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2 2\nencoding: raw\n\n",
         "sizes has 4 values"},
        {"spacings.nrrd",
         "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nspacings: 1 1\n"
         "encoding: raw\n\n",
         "spacings has 2 values"},
        {"zerospace.nrrd",
         "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nspacings: 1 0 1\n"
         "encoding: raw\n\n01234567",
         "spacing 0 along y"},
        {"badvec.nrrd",
         "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\n"
         "space directions: (1,0,0) (0,1 (0,0,1)\nencoding: raw\n\n",
         "bad space directions"},
        {"ascii.nrrd", "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: ascii\n\n",
         "unsupported NRRD encoding 'ascii'"},
        {"endian.nrrd",
         "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nendian: middle\n"
         "encoding: raw\n\n",
         "bad endian 'middle'"},
        {"noblank.nrrd", "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n",
         "no blank line"},
        {"nocolon.nrrd", "NRRD0004\ntype uint8\n\n", "line 2 is not 'field: value'"},
        {"case.nrrd", "NRRD0004\nType: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n",
         "missing field 'type'"},
        {"gzskip.nrrd",
         "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: gzip\n"
         "byte skip: -1\n\n",
         "byte skip -1 needs raw encoding"},
        {"badskip.nrrd",
         "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n"
         "byte skip: -2\n\n",
         "bad byte skip"},
        {"list.nhdr",
         "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n"
         "data file: LIST\na.raw\nb.raw\n",
         "not supported"},
        {"lines.nhdr",
         "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n"
         "line skip: 30\ndata file: lines.nhdr\n",
         "line skip 30 passes the end"},
        {"nodata.nhdr", "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n",
         "no blank line"},
        {"garbage.mhd", "this is not a MetaImage header\n", "not 'Key = Value'"},
        {"empty.mhd", "", "empty MetaImage header"},
        {"ndims.mhd",
         "NDims = 2\nDimSize = 4 4\nElementType = MET_UCHAR\n"
         "ElementDataFile = LOCAL\n",
         "NDims 2 is not supported"},
        {"nodims.mhd", "NDims = 3\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n",
         "missing key 'DimSize'"},
        {"nofile.mhd", "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\n",
         "missing key 'ElementDataFile'"},
        {"badmsb.mhd",
         "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\n"
         "BinaryDataByteOrderMSB = Maybe\nElementDataFile = LOCAL\n",
         "bad BinaryDataByteOrderMSB 'Maybe'"},
        {"channels.mhd",
         "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\n"
         "ElementNumberOfChannels = 3\nElementDataFile = LOCAL\n",
         "ElementNumberOfChannels 3"},
        {"pattern.mhd",
         "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\n"
         "ElementDataFile = slice%03d.raw 1 2 1\n",
         "not supported"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        in_scratch(path, cases[i].name);
        write_text(path, cases[i].text);
        describe_fails(path, NULL, IP_ERR_INPUT, cases[i].name, cases[i].needle);
    }
    /* Binary bytes (a NUL) where a header line should be. */
    in_scratch(path, "binary.mhd");
    write_bytes(path, "wb", "NDims = 3\n\0\0\0\1\2", 15);
    describe_fails(path, NULL, IP_ERR_INPUT, "binary.mhd", "NUL");
    /* A header line over 64 KiB is refused, not cut short. */
    size_t long_len = 70000;
    char *text = malloc(long_len + 64);
    REQUIRE(text != NULL);
    strcpy(text, "NRRD0004\n# ");
    memset(text + 11, 'x', long_len);
    strcpy(text + 11 + long_len, "\ntype: uint8\n\n");
    in_scratch(path, "longline.nrrd");
    write_text(path, text);
    describe_fails(path, NULL, IP_ERR_INPUT, "longline.nrrd", "line 2 is longer than 65536");
    /* ... but a long line under the limit is fine. */
    strcpy(text, "NRRD0004\n# ");
    memset(text + 11, 'y', 60000);
    strcpy(text + 11 + 60000, "\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n");
    write_text(path, text);
    append_text(path, "01234567");
    ip_input_desc d;
    describe_ok(path, NULL, &d);
    free(text);
}

static void test_missing_files(void)
{
    char path[4096];
    in_scratch(path, "does_not_exist_4x4x4_uint8.raw");
    describe_fails(path, NULL, IP_ERR_IO, "does_not_exist_4x4x4_uint8.raw",
                   "No such file or directory");
    in_scratch(path, "does_not_exist.nrrd");
    describe_fails(path, NULL, IP_ERR_IO, "does_not_exist.nrrd", "No such file or directory");
    in_scratch(path, "lost.nhdr");
    write_text(path, "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n"
                     "data file: lost_data.raw\n");
    describe_fails(path, NULL, IP_ERR_IO, "lost_data.raw", "No such file or directory");
    describe_fails(path, NULL, IP_ERR_IO, "lost.nhdr", "cannot open");
    in_scratch(path, "lost.mhd");
    write_text(path, "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\n"
                     "ElementDataFile = lost_meta.raw\n");
    describe_fails(path, NULL, IP_ERR_IO, "lost_meta.raw", "No such file or directory");
    /* A folder is not a volume. */
    in_scratch(path, "folder_2x2x2_uint8.raw");
    REQUIRE(mkdir(path, 0755) == 0);
    describe_fails(path, NULL, IP_ERR_INPUT, "folder_2x2x2_uint8.raw", "not a regular file");
    /* Nor is a FIFO, and naming one must not hang waiting for a writer. */
    char fifo[4096];
    in_scratch(fifo, "fifo_data.raw");
    REQUIRE(mkfifo(fifo, 0644) == 0);
    in_scratch(path, "fifo.nhdr");
    write_text(path, "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n"
                     "data file: fifo_data.raw\n");
    describe_fails(path, NULL, IP_ERR_INPUT, "fifo_data.raw", "not a regular file");
    append_text(path, "line skip: 1\n");
    describe_fails(path, NULL, IP_ERR_INPUT, "fifo_data.raw", "not a regular file");
}

static void test_bad_gzip(void)
{
    char path[4096];
    ip_input_desc d;
    const uint32_t dims[3] = {10, 6, 2};
    size_t size;
    unsigned char *bytes = make_volume(IP_UINT8, dims, 0, &size);
    const char *header = "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 10 6 2\nencoding: gzip\n\n";
    /* A complete stream that holds fewer bytes than the dims call for. */
    in_scratch(path, "gz_short.nrrd");
    write_text(path, header);
    append_gzip(path, bytes, 100);
    if (describe_ok(path, NULL, &d))
        read_fails(&d, IP_ERR_INPUT, "gzip data ends after 100 of 120 bytes");
    /* One that holds more. */
    in_scratch(path, "gz_long.nrrd");
    write_text(path, header);
    append_gzip(path, bytes, size);
    append_gzip(path, bytes, 1);
    if (describe_ok(path, NULL, &d))
        read_fails(&d, IP_ERR_INPUT, "gzip data are longer than the 10x6x2 x 1 = 120 bytes");
    /* A stream cut in the middle of the file. */
    unsigned char noise[4000];
    uint32_t state = 12345;
    for (size_t i = 0; i < sizeof noise; i++) {
        state = state * 1103515245u + 12345u;
        noise[i] = (unsigned char)(state >> 24);
    }
    in_scratch(path, "gz_cut.nrrd");
    write_text(path, "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 100 20 2\nencoding: gzip\n\n");
    append_gzip(path, noise, sizeof noise);
    REQUIRE(truncate(path, (off_t)(file_size(path) - 2000)) == 0);
    if (describe_ok(path, NULL, &d))
        read_fails(&d, IP_ERR_INPUT, "of 4000 bytes");
    /* Cut just before the trailer: every sample arrives, the end marker does not. */
    in_scratch(path, "gz_trailer.nrrd");
    write_text(path, header);
    append_gzip(path, bytes, size);
    REQUIRE(truncate(path, (off_t)(file_size(path) - 4)) == 0);
    if (describe_ok(path, NULL, &d))
        read_fails(&d, IP_ERR_INPUT, "end marker");
    /* A flipped bit: the checksum catches it. */
    in_scratch(path, "gz_flip.nrrd");
    write_text(path, header);
    append_gzip(path, noise, 120);
    {
        FILE *f = fopen(path, "r+b");
        REQUIRE(f != NULL);
        REQUIRE(fseek(f, (long)strlen(header) + 40, SEEK_SET) == 0);
        int c = fgetc(f);
        REQUIRE(fseek(f, (long)strlen(header) + 40, SEEK_SET) == 0);
        fputc(c ^ 0x10, f);
        REQUIRE(fclose(f) == 0);
    }
    if (describe_ok(path, NULL, &d))
        read_fails(&d, IP_ERR_INPUT, "gzip data are corrupt");
    /* Bytes after the stream that are not another gzip member. */
    in_scratch(path, "gz_tail.nrrd");
    write_text(path, header);
    append_gzip(path, bytes, size);
    append_text(path, "tail");
    if (describe_ok(path, NULL, &d))
        read_fails(&d, IP_ERR_INPUT, "unexpected bytes after the end of the gzip data");
    /* Not gzip at all. */
    in_scratch(path, "gz_plain.nrrd");
    write_text(path, header);
    write_bytes(path, "ab", bytes, size);
    if (describe_ok(path, NULL, &d))
        read_fails(&d, IP_ERR_INPUT, "corrupt");
    /* A header with nothing after it. */
    in_scratch(path, "gz_empty.nrrd");
    write_text(path, header);
    describe_fails(path, NULL, IP_ERR_INPUT, "gz_empty.nrrd", "no gzip data");
    free(bytes);
}

static void test_non_finite_floats(void)
{
    char path[4096];
    ip_input_desc d;
    const uint32_t dims[3] = {5, 4, 3};
    size_t size;
    unsigned char *bytes = make_volume(IP_FLOAT32, dims, 0, &size);
    in_scratch(path, "nan_5x4x3_float32.raw");
    store_sample(bytes + 4 * (2 + 5 * 1 + 20 * 1), IP_FLOAT32, 0, NAN);
    write_bytes(path, "wb", bytes, size);
    if (describe_ok(path, NULL, &d)) {
        ip_input_reader *r;
        ip_error err;
        float plane[20];
        REQUIRE(ip_input_open(&d, &r, &err) == IP_OK);
        CHECK_EQ(ip_input_read_planes(r, plane, 1, &err), IP_OK);
        CHECK_EQ(plane[19], (float)expected_value(IP_FLOAT32, 4, 3, 0));
        CHECK_EQ(ip_input_read_planes(r, plane, 1, &err), IP_ERR_INPUT);
        CHECK_CONTAINS(err.message, "nan_5x4x3_float32.raw");
        CHECK_CONTAINS(err.message, "(2,1,1)");
        CHECK_CONTAINS(err.message, "NaN");
        CHECK_EQ(ip_input_read_planes(r, plane, 1, &err), IP_ERR_INPUT);
        ip_input_close(r);
    }
    /* Infinity, big-endian, inside a gzip NRRD, in the last plane. */
    free(bytes);
    bytes = make_volume(IP_FLOAT32, dims, 1, &size);
    store_sample(bytes + 4 * (4 + 5 * 3 + 20 * 2), IP_FLOAT32, 1, -INFINITY);
    in_scratch(path, "inf.nrrd");
    write_text(path, "NRRD0004\ntype: float\ndimension: 3\nsizes: 5 4 3\nendian: big\n"
                     "encoding: gzip\n\n");
    append_gzip(path, bytes, size);
    if (describe_ok(path, NULL, &d))
        read_fails(&d, IP_ERR_INPUT, "(4,3,2) is infinite");
    free(bytes);
}

static void test_limits(void)
{
    char path[4096];
    ip_input_overrides ov = {0};
    in_scratch(path, "huge_2147483647x2147483647x2147483647_float32.raw");
    write_text(path, "");
    describe_fails(path, NULL, IP_ERR_INPUT, "huge_", "more than 2^63 bytes");
    in_scratch(path, "toobig_2147483648x2x2_uint8.raw");
    write_text(path, "");
    describe_fails(path, NULL, IP_ERR_INPUT, "toobig_",
                   "dimension 2147483648 along x is too large");
    in_scratch(path, "digits_2x99999999999999999999999999x2_uint8.raw");
    write_text(path, "");
    describe_fails(path, NULL, IP_ERR_INPUT, "digits_", "along y is too large");
    in_scratch(path, "overflow.raw");
    write_text(path, "");
    ov.has_dims = 1;
    ov.dims[0] = ov.dims[1] = ov.dims[2] = 0x7fffffffu;
    ov.has_type = 1;
    ov.type = IP_UINT8;
    describe_fails(path, &ov, IP_ERR_INPUT, "overflow.raw", "more than 2^63 bytes");
    ov.dims[2] = 0xffffffffu;
    describe_fails(path, &ov, IP_ERR_INPUT, "overflow.raw", "too large");
    in_scratch(path, "sizes.nrrd");
    write_text(path, "NRRD0004\ntype: uint8\ndimension: 3\n"
                     "sizes: 2 99999999999999999999999 2\nencoding: raw\n\n");
    describe_fails(path, NULL, IP_ERR_INPUT, "sizes.nrrd", "bad sizes");
    write_text(path, "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 4294967296 2\n"
                     "encoding: raw\n\n");
    describe_fails(path, NULL, IP_ERR_INPUT, "sizes.nrrd", "dimension 4294967296 along y");

    ip_input_desc d;
    ip_error err;
    CHECK_EQ(ip_input_describe(NULL, NULL, &d, &err), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_input_describe(path, NULL, NULL, &err), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_input_describe("", NULL, &d, &err), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_input_open(NULL, NULL, &err), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_input_read_planes(NULL, NULL, 1, &err), IP_ERR_ARGUMENT);
    ip_input_close(NULL);
}

/* Offsets past 4 GiB: a sparse file costs no disk space. */
static void test_large_offsets(void)
{
    char path[4096];
    ip_input_desc d;
    const uint32_t nx = 1024, ny = 1024, nz = 4100;
    const uint64_t plane = (uint64_t)nx * ny;
    in_scratch(path, "sparse_1024x1024x4100_uint8.raw");
    int fd = open(path, O_CREAT | O_TRUNC | O_WRONLY, 0644);
    REQUIRE(fd >= 0);
    if (ftruncate(fd, (off_t)(plane * nz)) != 0) {
        printf("test_input: skipping the 4 GiB sparse file: %s\n", strerror(errno));
        close(fd);
        unlink(path);
        return;
    }
    /* Marks at 4 GiB exactly (plane 4096) and at the very last sample. */
    const unsigned char mark_a = 0xa5, mark_b = 0x5a;
    REQUIRE(pwrite(fd, &mark_a, 1, (off_t)(plane * 4096)) == 1);
    REQUIRE(pwrite(fd, &mark_b, 1, (off_t)(plane * nz - 1)) == 1);
    close(fd);
    if (describe_ok(path, NULL, &d)) {
        ip_input_reader *r;
        ip_error err;
        const uint32_t step = 64;
        unsigned char *buf = malloc(plane * step);
        REQUIRE(buf != NULL);
        REQUIRE(ip_input_open(&d, &r, &err) == IP_OK);
        int ok = 1, seen_a = 0, seen_b = 0;
        for (uint32_t z = 0; z < nz && ok; z += step) {
            uint32_t count = nz - z < step ? nz - z : step;
            ok = ip_input_read_planes(r, buf, count, &err) == IP_OK;
            if (ok && z <= 4096 && 4096 < z + count)
                seen_a = buf[(4096 - z) * plane] == mark_a;
            if (ok && z + count == nz)
                seen_b = buf[count * plane - 1] == mark_b;
        }
        CHECK_MSG(ok, "%s", err.message);
        CHECK(seen_a);
        CHECK(seen_b);
        ip_input_close(r);
        free(buf);
    }
    unlink(path);
}

/* ---- the real volumes beside the project, when present ---- */

static void check_shared_volume(const char *path)
{
    ip_input_desc d;
    ip_input_reader *r;
    ip_error err;
    if (!describe_ok(path, NULL, &d))
        return;
    uint64_t plane = (uint64_t)d.dims[0] * d.dims[1] * ip_type_size(d.type);
    uint64_t size = file_size(path);
    CHECK_MSG(plane * d.dims[2] == size, "%s", path);
    unsigned char *buf = malloc(plane);
    unsigned char *direct = malloc(plane);
    REQUIRE(buf != NULL && direct != NULL);
    int fd = open(path, O_RDONLY);
    REQUIRE(fd >= 0);
    REQUIRE(ip_input_open(&d, &r, &err) == IP_OK);
    uint64_t bytes_read = 0;
    ip_status status = IP_OK;
    for (uint32_t z = 0; z < d.dims[2] && status == IP_OK; z++) {
        status = ip_input_read_planes(r, buf, 1, &err);
        if (status != IP_OK)
            break;
        bytes_read += plane;
        /* The files are little-endian, as this host is assumed to be for the comparison. */
        if (z == 0 || z == d.dims[2] - 1) {
            REQUIRE(pread(fd, direct, plane, (off_t)(plane * z)) == (ssize_t)plane);
            CHECK_MSG(memcmp(buf, direct, plane) == 0, "%s: plane %u differs", path, z);
        }
    }
    CHECK_MSG(status == IP_OK, "%s", err.message);
    CHECK_MSG(bytes_read == size, "%s: read %llu of %llu bytes", path,
              (unsigned long long)bytes_read, (unsigned long long)size);
    CHECK_EQ(ip_input_read_planes(r, buf, 1, &err), IP_ERR_ARGUMENT);
    ip_input_close(r);
    close(fd);
    free(buf);
    free(direct);
}

static void test_shared_data(void)
{
    const char *folder = getenv("IP_SHARED_DATA");
    DIR *dir = folder ? opendir(folder) : NULL;
    if (!dir) {
        printf("test_input: skipping the shared volumes: %s is not a folder\n",
               folder ? folder : "IP_SHARED_DATA");
        return;
    }
    struct dirent *entry;
    int count = 0;
    while ((entry = readdir(dir)) != NULL) {
        size_t len = strlen(entry->d_name);
        if (len < 4 || strcmp(entry->d_name + len - 4, ".raw") != 0)
            continue;
        char path[8192];
        snprintf(path, sizeof path, "%s/%s", folder, entry->d_name);
        check_shared_volume(path);
        count++;
    }
    closedir(dir);
    printf("test_input: checked %d shared volumes in %s\n", count, folder);
}

/* ---- the caller's plane source (ip_input_desc_from_planes()) ---- */

typedef struct planes_seen {
    uint32_t next_z, calls, fail_at; /* fail_at: the plane whose read fails (UINT32_MAX: none) */
    int with_message;
} planes_seen;

/* Plane z holds z * 1000 + y * 10 + x as uint16; checks that planes come in order. */
static ip_status fill_planes(void *user, uint32_t z, uint32_t count, void *dst, ip_error *err)
{
    planes_seen *seen = user;
    CHECK_EQ(z, seen->next_z);
    seen->next_z = z + count;
    seen->calls++;
    if (seen->fail_at >= z && seen->fail_at < z + count) {
        if (seen->with_message) {
            err->code = IP_ERR_IO;
            snprintf(err->message, sizeof err->message, "source: plane %u is gone", seen->fail_at);
        }
        return IP_ERR_IO;
    }
    uint16_t *out = dst;
    for (uint32_t k = 0; k < count; k++)
        for (uint32_t y = 0; y < 4; y++)
            for (uint32_t x = 0; x < 5; x++)
                *out++ = (uint16_t)((z + k) * 1000 + y * 10 + x);
    return IP_OK;
}

static void test_plane_source(void)
{
    const uint32_t dims[3] = {5, 4, 6};
    const double spacing[3] = {0.5, 1, 2};
    planes_seen seen = {0, 0, UINT32_MAX, 0};
    ip_input_desc d;
    ip_error err;
    REQUIRE(ip_input_desc_from_planes(&d, "array", dims, IP_UINT16, spacing, fill_planes, &seen,
                                      &err) == IP_OK);
    CHECK_EQ(d.encoding, IP_ENCODING_CALLBACK);
    CHECK_STR_EQ(d.path, "array");
    CHECK_EQ(d.spacing[0], 0.5);
    CHECK_EQ(d.spacing[2], 2.0);
    CHECK_EQ(d.has_rescale, 0);
    ip_input_reader *reader = NULL;
    REQUIRE(ip_input_open(&d, &reader, &err) == IP_OK);
    uint16_t buf[5 * 4 * 6];
    CHECK_EQ(ip_input_read_planes(reader, buf, 2, &err), IP_OK);
    CHECK_EQ(ip_input_read_planes(reader, buf + 40, 4, &err), IP_OK);
    CHECK_EQ(seen.calls, 2);
    CHECK_EQ(buf[0], 0);
    CHECK_EQ(buf[5 * 4 * 5 + 3 * 5 + 4], 5034);
    CHECK_NE(ip_input_read_planes(reader, buf, 1, &err), IP_OK); /* past the last plane */
    ip_input_close(reader);
    for (int with_message = 0; with_message < 2; with_message++) {
        seen = (planes_seen){0, 0, 3, with_message};
        read_fails(&d, IP_ERR_IO,
                   with_message ? "source: plane 3 is gone"
                                : "array: the plane source failed at planes 3 .. 3");
    }
    /* refused: no function, bad dims, unknown type, bad spacing */
    ip_input_desc untouched = d;
    const uint32_t flat[3] = {5, 1, 6};
    const double zero[3] = {1, 0, 1};
    CHECK_EQ(ip_input_desc_from_planes(&d, "array", dims, IP_UINT16, NULL, NULL, NULL, &err),
             IP_ERR_ARGUMENT);
    CHECK_EQ(ip_input_desc_from_planes(&d, "array", flat, IP_UINT16, NULL, fill_planes, NULL, &err),
             IP_ERR_ARGUMENT);
    CHECK_CONTAINS(err.message, "array: dimension y is 1");
    CHECK_EQ(
        ip_input_desc_from_planes(&d, "array", dims, (ip_type)9, NULL, fill_planes, NULL, &err),
        IP_ERR_ARGUMENT);
    CHECK_NE(ip_input_desc_from_planes(&d, "array", dims, IP_UINT16, zero, fill_planes, NULL, &err),
             IP_OK);
    CHECK_MEM_EQ(&d, &untouched, sizeof d);
}

static const test_case cases[] = {
    TEST_CASE(test_raw_by_name),       TEST_CASE(test_raw_by_overrides),
    TEST_CASE(test_overrides_win),     TEST_CASE(test_big_endian_raw),
    TEST_CASE(test_nrrd_attached),     TEST_CASE(test_nrrd_detached),
    TEST_CASE(test_nrrd_gzip),         TEST_CASE(test_nrrd_space_directions),
    TEST_CASE(test_nrrd_byte_skip),    TEST_CASE(test_nrrd_overrides),
    TEST_CASE(test_nrrd_spaces),       TEST_CASE(test_mhd),
    TEST_CASE(test_mhd_compressed),    TEST_CASE(test_mhd_orientation),
    TEST_CASE(test_wrong_size),        TEST_CASE(test_unknown_type),
    TEST_CASE(test_dimension_under_2), TEST_CASE(test_bad_headers),
    TEST_CASE(test_missing_files),     TEST_CASE(test_bad_gzip),
    TEST_CASE(test_non_finite_floats), TEST_CASE(test_limits),
    TEST_CASE(test_large_offsets),     TEST_CASE(test_shared_data),
    TEST_CASE(test_plane_source),
};

static void make_scratch_dir(void)
{
    snprintf(scratch, sizeof scratch, "%s", test_tmp_dir("test_input"));
}

int main(int argc, char **argv)
{
    return RUN_CASES_WITH(argc, argv, cases, "test_input", make_scratch_dir, NULL);
}

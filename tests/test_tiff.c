/* SPDX-License-Identifier: BSD-3-Clause */
/* TIFF input: multi-page files and folders of numbered files, every supported sample type,
 * strips and tiles, compressed pages, ImageJ's spacing, and the usual breakages (mixed
 * sizes, a missing slice, an unsupported type or compression), each one line naming the file.
 * The files are written here with libtiff. */
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "input_check.h"
#include "volume_files.h"

static char scratch[4096];

static const char *in_scratch(char *buf, const char *name)
{
    int n = snprintf(buf, 4096, "%s/%s", scratch, name);
    REQUIRE(n > 0 && n < 4096);
    return buf;
}

/* Reproducible samples of `type` that use every byte (finite floats). */
static void *make_samples(ip_type type, const uint32_t dims[3], uint64_t seed)
{
    size_t count = (size_t)dims[0] * dims[1] * dims[2];
    unsigned char *data = malloc(count * ip_type_size(type));
    REQUIRE(data != NULL);
    for (size_t i = 0; i < count; i++) {
        uint64_t r = test_xorshift(&seed);
        if (type == IP_FLOAT32) {
            float f = (float)((double)(r % 2000001) / 64.0 - 15000.0);
            memcpy(data + 4 * i, &f, 4);
        } else {
            memcpy(data + ip_type_size(type) * i, &r, ip_type_size(type));
        }
    }
    return data;
}

/* Describes `path`, checks dims and type, reads it whole and compares with `samples`. */
static void check_reads_as(const char *path, ip_type type, const uint32_t dims[3],
                           const void *samples)
{
    ip_input_desc d;
    ip_error err;
    ip_status st = ip_input_describe(path, NULL, &d, &err);
    CHECK_MSG(st == IP_OK, "%s: %s", path, err.message);
    if (st != IP_OK)
        return;
    CHECK_EQ(d.encoding, IP_ENCODING_TIFF);
    CHECK_MSG(d.type == type, "%s: type %s", path, ip_type_name(d.type));
    CHECK_MSG(d.dims[0] == dims[0] && d.dims[1] == dims[1] && d.dims[2] == dims[2],
              "%s: dims %ux%ux%u", path, d.dims[0], d.dims[1], d.dims[2]);
    CHECK(!d.has_rescale);
    void *got = read_volume(&d, &err);
    CHECK_MSG(got != NULL, "%s: %s", path, got ? "" : err.message);
    if (got)
        CHECK_MSG(memcmp(got, samples, (size_t)dims[0] * dims[1] * dims[2] * ip_type_size(type)) ==
                      0,
                  "%s: samples differ", path);
    free(got);
}

static void make_folder(const char *path)
{
    REQUIRE(mkdir(path, 0777) == 0);
}

/* Every type, in one multi-page file and in a folder, stripped, tiled and compressed. */
static void test_types_and_layouts(void)
{
    static const struct {
        ip_type type;
        uint16_t compression;
        uint32_t rows_per_strip, tile;
    } cases[] = {
        {IP_UINT8, COMPRESSION_NONE, 3, 0},          {IP_UINT16, COMPRESSION_LZW, 0, 0},
        {IP_INT16, COMPRESSION_ADOBE_DEFLATE, 5, 0}, {IP_FLOAT32, COMPRESSION_NONE, 0, 16},
        {IP_UINT16, COMPRESSION_PACKBITS, 0, 32},
    };
    const uint32_t dims[3] = {37, 21, 6};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char path[4096], name[64];
        tiff_style style = {cases[i].compression, cases[i].rows_per_strip, cases[i].tile, 0, 0};
        void *samples = make_samples(cases[i].type, dims, 17 + i);
        snprintf(name, sizeof name, "stack%zu.tif", i);
        REQUIRE(write_tiff(in_scratch(path, name), cases[i].type, dims[0], dims[1], dims[2],
                           samples, &style) == 0);
        check_reads_as(path, cases[i].type, dims, samples);
        snprintf(name, sizeof name, "folder%zu", i);
        make_folder(in_scratch(path, name));
        REQUIRE(write_tiff_folder(path, "slice_", 1, cases[i].type, dims, samples, &style) == 0);
        check_reads_as(path, cases[i].type, dims, samples);
        free(samples);
    }
}

/* slice9 comes before slice10 (natural order), numbering may start anywhere, and files that
 * are not .tif/.tiff are ignored. */
static void test_folder_order(void)
{
    char path[4096], other[4096];
    const uint32_t dims[3] = {8, 5, 12};
    tiff_style style = {COMPRESSION_NONE, 0, 0, 0, 0};
    void *samples = make_samples(IP_UINT8, dims, 5);
    make_folder(in_scratch(path, "natural"));
    REQUIRE(write_tiff_folder(path, "img", 7, IP_UINT8, dims, samples, &style) == 0);
    FILE *f = fopen(in_scratch(other, "natural/notes.txt"), "w");
    REQUIRE(f != NULL && fputs("not a slice\n", f) >= 0 && fclose(f) == 0);
    check_reads_as(path, IP_UINT8, dims, samples);
    free(samples);
}

/* ImageJ's calibration: X/YResolution give the pixel size, spacing= the slice distance. */
static void test_imagej_spacing(void)
{
    char path[4096];
    const uint32_t dims[3] = {10, 9, 4};
    tiff_style style = {COMPRESSION_NONE, 0, 0, 2.5, 0.25};
    void *samples = make_samples(IP_UINT16, dims, 9);
    REQUIRE(write_tiff(in_scratch(path, "imagej.tif"), IP_UINT16, dims[0], dims[1], dims[2],
                       samples, &style) == 0);
    ip_input_desc d;
    ip_error err;
    REQUIRE(ip_input_describe(path, NULL, &d, &err) == IP_OK);
    CHECK_EQ(d.spacing[0], 0.25);
    CHECK_EQ(d.spacing[1], 0.25);
    CHECK_EQ(d.spacing[2], 2.5);
    ip_input_overrides o = {0};
    o.has_spacing = 1;
    o.spacing[0] = o.spacing[1] = o.spacing[2] = 3;
    REQUIRE(ip_input_describe(path, &o, &d, &err) == IP_OK);
    CHECK_EQ(d.spacing[0], 3);
    CHECK_EQ(d.spacing[2], 3);
    /* dims and type may be repeated, not changed */
    ip_input_overrides same = {0};
    same.has_dims = same.has_type = 1;
    memcpy(same.dims, dims, sizeof same.dims);
    same.type = IP_UINT16;
    CHECK_EQ(ip_input_describe(path, &same, &d, &err), IP_OK);
    same.type = IP_UINT8;
    CHECK_EQ(ip_input_describe(path, &same, &d, &err), IP_ERR_INPUT);
    CHECK_CONTAINS(err.message, "cannot be overridden");
    /* a plain TIFF has no spacing: 1,1,1 */
    style.imagej_spacing = 0;
    REQUIRE(write_tiff(in_scratch(path, "plain.tif"), IP_UINT16, dims[0], dims[1], dims[2], samples,
                       &style) == 0);
    REQUIRE(ip_input_describe(path, NULL, &d, &err) == IP_OK);
    CHECK_EQ(d.spacing[0], 1);
    CHECK_EQ(d.spacing[1], 1);
    CHECK_EQ(d.spacing[2], 1);
    free(samples);
}

/* A folder with a plane of another size, a gap, a repeated number, a file without a number. */
static void test_bad_folders(void)
{
    char path[4096], file[4096];
    const uint32_t dims[3] = {8, 6, 4}, small[3] = {8, 5, 1};
    tiff_style style = {COMPRESSION_NONE, 0, 0, 0, 0};
    void *samples = make_samples(IP_UINT8, dims, 3);
    make_folder(in_scratch(path, "mixed"));
    REQUIRE(write_tiff_folder(path, "s", 1, IP_UINT8, dims, samples, &style) == 0);
    REQUIRE(write_tiff(in_scratch(file, "mixed/s3.tif"), IP_UINT8, small[0], small[1], 1, samples,
                       &style) == 0);
    describe_fails(path, NULL, IP_ERR_INPUT, "mixed/s3.tif", "8x5 uint8 differs from 8x6 uint8");
    REQUIRE(write_tiff(file, IP_UINT16, dims[0], dims[1], 1, samples, &style) == 0);
    describe_fails(path, NULL, IP_ERR_INPUT, "mixed/s3.tif", "uint16 differs");

    make_folder(in_scratch(path, "gap"));
    REQUIRE(write_tiff_folder(path, "s", 1, IP_UINT8, dims, samples, &style) == 0);
    REQUIRE(unlink(in_scratch(file, "gap/s2.tif")) == 0);
    describe_fails(path, NULL, IP_ERR_INPUT, "gap", "slice 2 is missing (the files go from s1.tif");
    REQUIRE(write_tiff(in_scratch(file, "gap/s02.tif"), IP_UINT8, dims[0], dims[1], 1, samples,
                       &style) == 0);
    REQUIRE(write_tiff(in_scratch(file, "gap/s2.tif"), IP_UINT8, dims[0], dims[1], 1, samples,
                       &style) == 0);
    describe_fails(path, NULL, IP_ERR_INPUT, "gap", "the same slice number 2");
    REQUIRE(unlink(file) == 0);
    REQUIRE(write_tiff(in_scratch(file, "gap/scout.tif"), IP_UINT8, dims[0], dims[1], 1, samples,
                       &style) == 0);
    describe_fails(path, NULL, IP_ERR_INPUT, "scout.tif", "no slice number");
    /* a folder whose files are not TIFF at all is told apart from the start */
    make_folder(in_scratch(path, "none"));
    FILE *f = fopen(in_scratch(file, "none/a.txt"), "w");
    REQUIRE(f != NULL && fputs("text\n", f) >= 0 && fclose(f) == 0);
    describe_fails(path, NULL, IP_ERR_INPUT, "none", "neither DICOM nor TIFF");
    free(samples);
}

/* Sets the value of tag `tag` (a SHORT) in the first IFD of the little-endian TIFF at `path`. */
static void patch_short_tag(const char *path, uint16_t tag, uint16_t value)
{
    FILE *f = fopen(path, "r+b");
    unsigned char head[8], entry[12], count[2];
    REQUIRE(f != NULL && fread(head, 1, 8, f) == 8 && head[0] == 'I');
    uint32_t ifd = head[4] | head[5] << 8 | head[6] << 16 | (uint32_t)head[7] << 24;
    REQUIRE(fseek(f, ifd, SEEK_SET) == 0 && fread(count, 1, 2, f) == 2);
    int patched = 0;
    for (int i = 0; i < (count[0] | count[1] << 8); i++) {
        REQUIRE(fread(entry, 1, 12, f) == 12);
        if ((entry[0] | entry[1] << 8) == tag) {
            entry[8] = (unsigned char)value;
            entry[9] = (unsigned char)(value >> 8);
            REQUIRE(fseek(f, -12, SEEK_CUR) == 0 && fwrite(entry, 1, 12, f) == 12);
            patched = 1;
            break;
        }
    }
    REQUIRE(patched && fclose(f) == 0);
}

/* Types and codecs that cannot be read, a page of another size, a file that is no TIFF. */
static void test_bad_files(void)
{
    char path[4096];
    const uint32_t dims[3] = {8, 6, 3};
    tiff_style style = {COMPRESSION_NONE, 0, 0, 0, 0};
    void *samples = make_samples(IP_UINT16, dims, 11);

    REQUIRE(write_tiff(in_scratch(path, "codec.tif"), IP_UINT8, dims[0], dims[1], dims[2], samples,
                       &style) == 0);
    patch_short_tag(path, TIFFTAG_COMPRESSION, 60000);
    describe_fails(path, NULL, IP_ERR_UNSUPPORTED, "codec.tif: page 1",
                   "compression 60000 (unknown) cannot be decoded");

    REQUIRE(write_tiff(in_scratch(path, "int8.tif"), IP_UINT8, dims[0], dims[1], dims[2], samples,
                       &style) == 0);
    patch_short_tag(path, TIFFTAG_SAMPLEFORMAT, SAMPLEFORMAT_INT);
    describe_fails(path, NULL, IP_ERR_UNSUPPORTED, "int8.tif", "8-bit signed integer samples");

    TIFF *t = TIFFOpen(in_scratch(path, "rgb.tif"), "w");
    REQUIRE(t != NULL);
    TIFFSetField(t, TIFFTAG_IMAGEWIDTH, 4);
    TIFFSetField(t, TIFFTAG_IMAGELENGTH, 2);
    TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, 8);
    TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, 3);
    TIFFSetField(t, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_RGB);
    TIFFSetField(t, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
    for (uint32_t y = 0; y < 2; y++)
        REQUIRE(TIFFWriteScanline(t, samples, y, 0) == 1);
    TIFFClose(t);
    describe_fails(path, NULL, IP_ERR_UNSUPPORTED, "rgb.tif", "3 samples per pixel");

    /* a multi-page file whose third page is smaller */
    t = TIFFOpen(in_scratch(path, "pages.tif"), "w");
    REQUIRE(t != NULL);
    for (uint32_t z = 0; z < 3; z++) {
        uint32_t height = z == 2 ? 4 : 6;
        tiff_set_layout(t, IP_UINT16, 8, height, &style);
        for (uint32_t y = 0; y < height; y++)
            REQUIRE(TIFFWriteScanline(t, samples, y, 0) == 1);
        REQUIRE(TIFFWriteDirectory(t));
    }
    TIFFClose(t);
    describe_fails(path, NULL, IP_ERR_INPUT, "pages.tif: page 3", "8x4 uint16 differs from 8x6");

    /* not a TIFF, and a TIFF cut short inside its samples */
    FILE *f = fopen(in_scratch(path, "fake.tif"), "w");
    REQUIRE(f != NULL && fputs("II*\0 not really", f) >= 0 && fclose(f) == 0);
    describe_fails(path, NULL, IP_ERR_INPUT, "fake.tif", "not a readable TIFF");
    REQUIRE(write_tiff(in_scratch(path, "cut.tif"), IP_UINT16, dims[0], dims[1], dims[2], samples,
                       &style) == 0);
    ip_input_desc d;
    ip_error err;
    REQUIRE(ip_input_describe(path, NULL, &d, &err) == IP_OK);
    REQUIRE(truncate(path, 8 + 2 * 8 * 6 + 20) == 0);
    void *got = read_volume(&d, &err);
    CHECK_EQ(got, NULL);
    CHECK_CONTAINS(err.message, "cut.tif");
    free(got);
    free(samples);
}

static const test_case cases[] = {
    TEST_CASE(test_types_and_layouts), TEST_CASE(test_folder_order), TEST_CASE(test_imagej_spacing),
    TEST_CASE(test_bad_folders),       TEST_CASE(test_bad_files),
};

static void make_scratch_dir(void)
{
    snprintf(scratch, sizeof scratch, "%s", test_tmp_dir("test_tiff"));
}

int main(int argc, char **argv)
{
    return RUN_CASES_WITH(argc, argv, cases, "test_tiff", make_scratch_dir, NULL);
}

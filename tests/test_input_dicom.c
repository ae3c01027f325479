/* SPDX-License-Identifier: BSD-3-Clause */
/* DICOM series input: folders of DICOM files the test writes (dicom_series.h) from a synthetic
 * volume, in shuffled file order and mixed transfer syntaxes, described and read back sample
 * for sample; and each way a series folder can be wrong, refused in one line naming it. */
#include <math.h>
#include <stdint.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "dicom_series.h"
#include "isoprop/input.h"

static char scratch[4096];

/* A fresh, empty folder scratch/name; its path into out. */
static const char *fresh_folder(char out[4096], const char *name)
{
    char cmd[8300];
    REQUIRE(snprintf(out, 4096, "%.3000s/%s", scratch, name) < 4096);
    snprintf(cmd, sizeof cmd, "rm -rf '%s' && mkdir -p '%s'", out, out);
    REQUIRE(system(cmd) == 0);
    return out;
}

/* Writes `text` as dir/name. */
static void write_text_file(const char *dir, const char *name, const char *text)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    REQUIRE(f != NULL && fputs(text, f) >= 0 && fclose(f) == 0);
}

/* A DICOMDIR: a DICOM file (a meta header alone here), the index of a folder, not a slice. */
static void write_index(const char *dir)
{
    char path[4200];
    test_bytes b = {0};
    snprintf(path, sizeof path, "%s/DICOMDIR", dir);
    test_bytes_put(&b, (unsigned char[128]){0}, 128);
    test_bytes_put(&b, "DICM", 4);
    test_dicom_meta(&b, "1.2.826.0.1.3680043.2.1125.8", TEST_DICOM_EXPLICIT_LE);
    FILE *f = fopen(path, "wb");
    REQUIRE(f != NULL && fwrite(b.data, 1, b.size, f) == b.size && fclose(f) == 0);
    free(b.data);
}

/* A volume of `type` whose every sample differs from its neighbours; signed types go negative. */
static void *make_volume(const test_dicom_series *s)
{
    size_t count = (size_t)s->dims[0] * s->dims[1] * s->dims[2];
    unsigned char *v = malloc(count * ip_type_size(s->type));
    REQUIRE(v != NULL);
    uint64_t state = 0x9E3779B97F4A7C15ull;
    for (size_t i = 0; i < count; i++) {
        uint64_t r = test_xorshift(&state);
        if (s->type == IP_UINT8)
            v[i] = (unsigned char)r;
        else if (s->type == IP_UINT16)
            ((uint16_t *)v)[i] = (uint16_t)r;
        else
            ((int16_t *)v)[i] = (int16_t)((int)(r % 4000) - 2000);
    }
    return v;
}

/* Reads the whole volume of `desc` (3 planes, then the rest) and compares it with `volume`. */
static void check_samples(const ip_input_desc *desc, const void *volume)
{
    ip_input_reader *r = NULL;
    ip_error err;
    size_t bytes = (size_t)desc->dims[0] * desc->dims[1] * desc->dims[2] * ip_type_size(desc->type);
    size_t plane = (size_t)desc->dims[0] * desc->dims[1] * ip_type_size(desc->type);
    unsigned char *got = malloc(bytes);
    REQUIRE(got != NULL);
    CHECK_MSG(ip_input_open(desc, &r, &err) == IP_OK, "%s", err.message);
    if (r) {
        CHECK_MSG(ip_input_read_planes(r, got, 3, &err) == IP_OK, "%s", err.message);
        CHECK_MSG(ip_input_read_planes(r, got + 3 * plane, desc->dims[2] - 3, &err) == IP_OK, "%s",
                  err.message);
        CHECK_MEM_EQ(got, volume, bytes);
        CHECK_EQ(ip_input_read_planes(r, got, 1, &err), IP_ERR_ARGUMENT);
    }
    ip_input_close(r);
    free(got);
}

/* A series of every type, in explicit and implicit VR little endian, explicit VR big endian
 * and RLE Lossless by turns, in shuffled file order: described and read back exactly. */
static void test_series(ip_type type, const char *name)
{
    char dir[4096];
    test_dicom_series s = test_dicom_default(13, 11, 9, type);
    void *volume = make_volume(&s);
    ip_input_desc desc;
    ip_error err;
    fresh_folder(dir, name);
    test_dicom_write_series(&s, volume, dir);
    /* a hidden file and a DICOMDIR are not slices */
    write_text_file(dir, ".hidden", "not a slice");
    write_index(dir);
    CHECK_MSG(ip_input_describe(dir, NULL, &desc, &err) == IP_OK, "%s", err.message);
    CHECK_EQ(desc.encoding, IP_ENCODING_DICOM);
    CHECK_EQ(desc.dims[0], 13);
    CHECK_EQ(desc.dims[1], 11);
    CHECK_EQ(desc.dims[2], 9);
    CHECK_EQ(desc.type, type);
    CHECK_MSG(fabs(desc.spacing[0] - 0.8) < 1e-9 && fabs(desc.spacing[1] - 0.7) < 1e-9 &&
                  fabs(desc.spacing[2] - 2.5) < 1e-9,
              "spacing %g %g %g", desc.spacing[0], desc.spacing[1], desc.spacing[2]);
    CHECK(desc.has_rescale);
    CHECK_EQ(desc.rescale_slope, 1.0);
    CHECK_EQ(desc.rescale_intercept, -1024.0);
    CHECK_STR_EQ(desc.rescale_unit, "HU"); /* a CT's */
    check_samples(&desc, volume);
    free(volume);
}

/* The rescale's unit: the Rescale Type when it names one, else HU for a CT, else none; no
 * rescale at all only for the identity without a unit. */
static void check_rescale(test_dicom_series s, const char *name, int has, double slope,
                          double intercept, const char *unit)
{
    char dir[4096];
    void *volume = make_volume(&s);
    ip_input_desc desc;
    ip_error err;
    test_dicom_write_series(&s, volume, fresh_folder(dir, name));
    CHECK_MSG(ip_input_describe(dir, NULL, &desc, &err) == IP_OK, "%s", err.message);
    CHECK_MSG(desc.has_rescale == has, "%s: has_rescale %d", name, desc.has_rescale);
    CHECK_MSG(desc.rescale_slope == slope && desc.rescale_intercept == intercept,
              "%s: rescale %g, %g", name, desc.rescale_slope, desc.rescale_intercept);
    CHECK_MSG(strcmp(desc.rescale_unit, unit) == 0, "%s: unit '%s', not '%s'", name,
              desc.rescale_unit, unit);
    free(volume);
}

static void test_rescale_unit(void)
{
    test_dicom_series s = test_dicom_default(5, 4, 3, IP_INT16);
    s.syntax = TEST_DICOM_EXPLICIT_LE;
    check_rescale(s, "ct", 1, 1, -1024, "HU");
    s.rescale_type = "US"; /* unspecified: a CT's values are still HU */
    check_rescale(s, "ct_us", 1, 1, -1024, "HU");
    s.rescale_type = "HU";
    s.modality = "";
    check_rescale(s, "hu_no_modality", 1, 1, -1024, "HU");
    s.modality = "PT", s.slope = 0.25, s.intercept = 0, s.rescale_type = "BQML";
    check_rescale(s, "pet", 1, 0.25, 0, "BQML");
    s.rescale_type = "ABCDEFGHIJKLMNOP"; /* 16 characters: more than a unit holds */
    check_rescale(s, "long_type", 1, 0.25, 0, "");
    s.rescale_type = NULL;
    check_rescale(s, "mr", 1, 0.25, 0, "");
    s.rescale = 0;
    check_rescale(s, "mr_no_rescale", 0, 1, 0, "");
    s.rescale = 1, s.slope = 1, s.modality = NULL; /* a CT stored in HU: the unit alone */
    check_rescale(s, "ct_identity", 1, 1, 0, "HU");
}

/* The spacing override replaces the headers' spacing; a dims override that is not the series'
 * is refused when the reader opens. */
static void test_overrides(void)
{
    char dir[4096];
    test_dicom_series s = test_dicom_default(6, 5, 4, IP_UINT16);
    void *volume = make_volume(&s);
    ip_input_overrides o = {0};
    ip_input_desc desc;
    ip_input_reader *r = NULL;
    ip_error err;
    s.syntax = TEST_DICOM_EXPLICIT_LE;
    s.rescale = 0;
    fresh_folder(dir, "overrides");
    test_dicom_write_series(&s, volume, dir);
    o.has_spacing = 1;
    o.spacing[0] = 1, o.spacing[1] = 2, o.spacing[2] = 3;
    CHECK_MSG(ip_input_describe(dir, &o, &desc, &err) == IP_OK, "%s", err.message);
    CHECK_EQ(desc.spacing[0], 1);
    CHECK_EQ(desc.spacing[1], 2);
    CHECK_EQ(desc.spacing[2], 3);
    CHECK(desc.has_rescale); /* no slope or intercept, but a CT: the identity, in HU */
    CHECK_EQ(desc.rescale_slope, 1.0);
    CHECK_EQ(desc.rescale_intercept, 0.0);
    CHECK_STR_EQ(desc.rescale_unit, "HU");
    check_samples(&desc, volume);
    o.has_dims = 1;
    o.dims[0] = 5, o.dims[1] = 6, o.dims[2] = 4;
    CHECK_MSG(ip_input_describe(dir, &o, &desc, &err) == IP_OK, "%s", err.message);
    CHECK_EQ(ip_input_open(&desc, &r, &err), IP_ERR_INPUT);
    CHECK_CONTAINS(err.message, "not the 5x6x4");
    ip_input_close(r);
    free(volume);
}

/* Describing `dir` fails with `code` and one line that names `names` and contains `text`. */
static void expect_refused(const char *dir, ip_status code, const char *names, const char *text)
{
    ip_input_desc desc;
    ip_error err;
    ip_status st = ip_input_describe(dir, NULL, &desc, &err);
    CHECK_MSG(st == code, "%s: status %d, not %d (%s)", dir, (int)st, (int)code,
              st == IP_OK ? "" : err.message);
    if (st == IP_OK)
        return;
    CHECK_CONTAINS(err.message, names);
    CHECK_CONTAINS(err.message, text);
    CHECK_EQ(strchr(err.message, '\n'), NULL);
}

/* A folder with the series of `s` less the plane `skip` (none when >= dims[2]), then the
 * plane `odd_plane` again as odd.dcm, written as `odd` says (odd NULL: no such file). */
static void write_case(const char *dir, const test_dicom_series *s, const void *volume,
                       uint32_t skip, const test_dicom_series *odd, uint32_t odd_plane)
{
    char path[4200];
    for (uint32_t z = 0; z < s->dims[2]; z++) {
        if (z == skip)
            continue;
        snprintf(path, sizeof path, "%s/IM%04u.dcm", dir, z + 1);
        test_dicom_write_slice(s, volume, z, path);
    }
    if (odd) {
        snprintf(path, sizeof path, "%s/odd.dcm", dir);
        test_dicom_write_slice(odd, volume, odd_plane, path);
    }
}

static void test_refused(void)
{
    char dir[4096];
    test_dicom_series s = test_dicom_default(8, 7, 6, IP_INT16), odd;
    void *volume = make_volume(&s);
    s.syntax = TEST_DICOM_EXPLICIT_LE;

    odd = s, odd.series_uid = "1.2.826.0.1.3680043.2.1125.1.2", odd.origin_z = 100;
    write_case(fresh_folder(dir, "two_series"), &s, volume, 99, &odd, 0);
    expect_refused(dir, IP_ERR_INPUT, "two_series", "holds 2 series: pick one by its UID");
    expect_refused(dir, IP_ERR_INPUT, "two_series",
                   "1.2.826.0.1.3680043.2.1125.1.1 CT 6 slices; 1.2.826.0.1.3680043.2.1125.1.2 "
                   "CT 1 slice");

    write_case(fresh_folder(dir, "missing"), &s, volume, 3, NULL, 0);
    expect_refused(dir, IP_ERR_INPUT, "missing",
                   "a slice is missing between IM0003.dcm (at -35 mm)");
    expect_refused(dir, IP_ERR_INPUT, "missing", "and IM0005.dcm (at -30 mm)");

    odd = s, odd.dims[1] = 6, odd.origin_z += 6 * s.step_z;
    write_case(fresh_folder(dir, "rows"), &s, volume, 99, &odd, 0);
    expect_refused(dir, IP_ERR_INPUT, "rows/odd.dcm", "mixed series: a different size");

    odd = s, odd.origin_z += 6 * s.step_z, odd.rescale_type = "OD"; /* the others' are HU */
    write_case(fresh_folder(dir, "unit"), &s, volume, 99, &odd, 0);
    expect_refused(dir, IP_ERR_INPUT, "unit/odd.dcm", "mixed series: a different rescale");

    odd = s, odd.origin_z += 6 * s.step_z, odd.syntax = "1.2.840.10008.1.2.4.999";
    write_case(fresh_folder(dir, "unknown_syntax"), &s, volume, 99, &odd, 0);
    expect_refused(dir, IP_ERR_UNSUPPORTED, "unknown_syntax/odd.dcm",
                   "unknown transfer syntax 1.2.840.10008.1.2.4.999");

    odd = s, odd.origin_z += 6 * s.step_z, odd.syntax = "1.2.840.10008.1.2.4.100";
    write_case(fresh_folder(dir, "mpeg2"), &s, volume, 99, &odd, 0);
    expect_refused(dir, IP_ERR_UNSUPPORTED, "mpeg2/odd.dcm", "no decoder");

    write_case(fresh_folder(dir, "stranger"), &s, volume, 99, NULL, 0);
    write_text_file(dir, "notes.txt", "scanned on Tuesday\n");
    expect_refused(dir, IP_ERR_INPUT, "stranger/notes.txt", "not a DICOM file");

    expect_refused(fresh_folder(dir, "empty"), IP_ERR_INPUT, "empty", "holds no files");

    write_case(fresh_folder(dir, "repeated"), &s, volume, 99, &s, 2);
    expect_refused(dir, IP_ERR_INPUT, "repeated", "at the same position");

    odd = s, odd.origin_z += 0.3;
    write_case(fresh_folder(dir, "uneven"), &s, volume, 2, &odd, 2);
    expect_refused(dir, IP_ERR_INPUT, "uneven", "uneven slice spacing");

    odd = s, odd.origin_z += 6 * s.step_z, odd.photometric = "MONOCHROME1";
    write_case(fresh_folder(dir, "inverted"), &s, volume, 99, &odd, 0);
    expect_refused(dir, IP_ERR_UNSUPPORTED, "inverted/odd.dcm", "MONOCHROME1");

    /* a header of 32-bit samples over 16-bit pixel data: its Pixel Data is half as long as
     * the image (the structure is checked before the library reads it: dicom_check.h) */
    odd = s, odd.origin_z += 6 * s.step_z, odd.bits_allocated = 32;
    write_case(fresh_folder(dir, "wide"), &s, volume, 99, &odd, 0);
    expect_refused(dir, IP_ERR_INPUT, "wide/odd.dcm",
                   "its Pixel Data holds 112 bytes, less than the 224 of the 8x7 image of 32 bits");

    odd = s, odd.origin_z += 6 * s.step_z, odd.no_position = 1;
    write_case(fresh_folder(dir, "unplaced"), &s, volume, 99, &odd, 0);
    expect_refused(dir, IP_ERR_INPUT, "unplaced/odd.dcm", "lacks Image Position (Patient)");

    static const double z_nan[] = {-40, -37.5, NAN, -32.5, -30, -27.5};
    odd = s, odd.z_at = z_nan;
    write_case(fresh_folder(dir, "nan_position"), &odd, volume, 99, NULL, 0);
    expect_refused(dir, IP_ERR_INPUT, "nan_position/IM0003.dcm",
                   "Image Position (Patient) or Image Orientation (Patient) is not finite");

    odd = s, odd.dims[2] = 1;
    write_case(fresh_folder(dir, "single"), &odd, volume, 99, NULL, 0);
    expect_refused(dir, IP_ERR_INPUT, "single", "holds one DICOM slice");
    free(volume);
}

/* Malformed slices (dicom_check.h): one slice of a series cut at every byte offset, in each
 * transfer syntax the writer knows, and one whose Rows were raised past its Pixel Data: each is
 * refused with one line naming the file, never a crash (the DICOM library alone stopped the
 * process on some cuts and read past its buffer on the short Pixel Data); a slice cut after the
 * description fails its plane's read, naming it. */
static void test_malformed(void)
{
    const char *syntaxes[] = {TEST_DICOM_EXPLICIT_LE, TEST_DICOM_IMPLICIT_LE,
                              TEST_DICOM_EXPLICIT_BE, TEST_DICOM_RLE, TEST_DICOM_DEFLATE};
    char dir[4096], path[4200];
    for (size_t k = 0; k < sizeof syntaxes / sizeof syntaxes[0]; k++) {
        test_dicom_series s = test_dicom_default(8, 7, 4, IP_UINT16);
        s.syntax = syntaxes[k];
        void *volume = make_volume(&s);
        write_case(fresh_folder(dir, "cut"), &s, volume, 99, NULL, 0);
        snprintf(path, sizeof path, "%s/IM0002.dcm", dir);
        FILE *f = fopen(path, "rb");
        REQUIRE(f != NULL);
        static unsigned char bytes[1 << 16];
        size_t size = fread(bytes, 1, sizeof bytes, f);
        fclose(f);
        REQUIRE(size > 132 && size < sizeof bytes);
        size_t refused = 0, cuts = 0;
        for (size_t cut = 132; cut < size; cut++) {
            f = fopen(path, "wb");
            REQUIRE(f != NULL && fwrite(bytes, 1, cut, f) == cut && fclose(f) == 0);
            ip_input_desc desc;
            ip_error err;
            ip_status st = ip_input_describe(dir, NULL, &desc, &err);
            cuts++;
            if (st != IP_OK) {
                refused += st == IP_ERR_INPUT && strstr(err.message, "IM0002.dcm") &&
                           !strchr(err.message, '\n');
                continue;
            }
            /* what describes (a cut among the elements after the image, none here) reads */
            ip_input_reader *r = NULL;
            CHECK_EQ(ip_input_open(&desc, &r, &err), IP_OK);
            ip_input_close(r);
        }
        CHECK_MSG(refused == cuts, "%s: %zu of %zu cuts refused with a line naming the file",
                  syntaxes[k], refused, cuts);
        /* the whole file again, then cut after the description: the plane's read fails */
        f = fopen(path, "wb");
        REQUIRE(f != NULL && fwrite(bytes, 1, size, f) == size && fclose(f) == 0);
        ip_input_desc desc;
        ip_input_reader *r = NULL;
        ip_error err;
        REQUIRE(ip_input_describe(dir, NULL, &desc, &err) == IP_OK);
        REQUIRE(ip_input_open(&desc, &r, &err) == IP_OK);
        REQUIRE(truncate(path, (off_t)(size - 3)) == 0);
        uint16_t *planes = malloc(4 * 8 * 7 * sizeof *planes);
        REQUIRE(planes != NULL);
        CHECK_EQ(ip_input_read_planes(r, planes, 4, &err), IP_ERR_INPUT);
        CHECK_CONTAINS(err.message, "IM0002.dcm");
        ip_input_close(r);
        free(planes);
        free(volume);
    }
    /* Rows raised past the Pixel Data (an uncompressed slice): refused before decoding */
    test_dicom_series s = test_dicom_default(8, 7, 4, IP_UINT16);
    s.syntax = TEST_DICOM_EXPLICIT_LE;
    void *volume = make_volume(&s);
    write_case(fresh_folder(dir, "short"), &s, volume, 99, NULL, 0);
    snprintf(path, sizeof path, "%s/IM0003.dcm", dir);
    FILE *f = fopen(path, "r+b");
    REQUIRE(f != NULL);
    static unsigned char bytes[1 << 16];
    size_t size = fread(bytes, 1, sizeof bytes, f);
    size_t patched = 0;
    for (size_t i = 132; i + 10 <= size; i++) /* (0028,0010) US 2 7 -> 2048 */
        if (!memcmp(bytes + i, "\x28\x00\x10\x00US\x02\x00\x07\x00", 10)) {
            bytes[i + 8] = 0x00, bytes[i + 9] = 0x08;
            patched++;
        }
    REQUIRE(patched == 1);
    REQUIRE(fseek(f, 0, SEEK_SET) == 0 && fwrite(bytes, 1, size, f) == size && fclose(f) == 0);
    expect_refused(dir, IP_ERR_INPUT, "short/IM0003.dcm", "its Pixel Data holds 112 bytes");
    /* one slice's High Bit unlike its neighbours' (15 -> 11: the same Bits Stored, 16, no
     * longer held) and, in another series, one with 12 bits stored (High Bit 11) among slices
     * of 16: each refused, naming the file */
    const struct {
        const char *name, *text;
        unsigned tag, value;
    } layouts[] = {{"highbit", "High Bit 11 does not hold 16 bits stored", 0x0102, 11},
                   {"stored", "a different bit layout (Bits Stored, High Bit)", 0, 12}};
    for (size_t c = 0; c < 2; c++) {
        write_case(fresh_folder(dir, layouts[c].name), &s, volume, 99, NULL, 0);
        snprintf(path, sizeof path, "%s/IM0002.dcm", dir);
        f = fopen(path, "r+b");
        REQUIRE(f != NULL);
        size = fread(bytes, 1, sizeof bytes, f);
        patched = 0;
        for (size_t i = 132; i + 10 <= size; i++) {
            /* (0028,0101) Bits Stored and (0028,0102) High Bit, US, 2 bytes */
            int stored = !memcmp(bytes + i, "\x28\x00\x01\x01US\x02\x00", 8);
            int high = !memcmp(bytes + i, "\x28\x00\x02\x01US\x02\x00", 8);
            if (layouts[c].tag ? high : stored || high) {
                unsigned v = layouts[c].tag || stored ? layouts[c].value : layouts[c].value - 1;
                bytes[i + 8] = (unsigned char)v, bytes[i + 9] = 0;
                patched++;
            }
        }
        REQUIRE(patched == (layouts[c].tag ? 1u : 2u));
        REQUIRE(fseek(f, 0, SEEK_SET) == 0 && fwrite(bytes, 1, size, f) == size && fclose(f) == 0);
        char name[64];
        snprintf(name, sizeof name, "%s/IM0002.dcm", layouts[c].name);
        expect_refused(dir, IP_ERR_INPUT, name, layouts[c].text);
    }
    free(volume);
}

/* A file that changes after the description: its plane fails, naming the file. */
static void test_changed_file(void)
{
    char dir[4096], path[4200];
    test_dicom_series s = test_dicom_default(8, 7, 6, IP_UINT16), wider;
    void *volume = make_volume(&s);
    ip_input_desc desc;
    ip_input_reader *r = NULL;
    ip_error err;
    s.syntax = TEST_DICOM_EXPLICIT_LE;
    write_case(fresh_folder(dir, "changed"), &s, volume, 99, NULL, 0);
    CHECK_MSG(ip_input_describe(dir, NULL, &desc, &err) == IP_OK, "%s", err.message);
    CHECK_MSG(ip_input_open(&desc, &r, &err) == IP_OK, "%s", err.message);
    wider = s, wider.bits_allocated = 8, wider.type = IP_UINT8;
    snprintf(path, sizeof path, "%s/IM0002.dcm", dir);
    test_dicom_write_slice(&wider, volume, 1, path);
    uint16_t *planes = malloc(2 * 8 * 7 * sizeof *planes);
    REQUIRE(planes != NULL);
    CHECK_EQ(ip_input_read_planes(r, planes, 2, &err), IP_ERR_INPUT);
    CHECK_CONTAINS(err.message, "changed/IM0002.dcm");
    ip_input_close(r);
    free(planes);
    free(volume);
}

/* Replaces the one occurrence of `from` (n bytes) in dir/name by `to` (n bytes). */
static void patch_file(const char *dir, const char *name, const void *from, const void *to,
                       size_t n)
{
    char path[4200];
    static unsigned char bytes[1 << 16];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "r+b");
    REQUIRE(f != NULL);
    size_t size = fread(bytes, 1, sizeof bytes, f), found = 0, at = 0;
    REQUIRE(size < sizeof bytes);
    for (size_t i = 0; i + n <= size; i++)
        if (memcmp(bytes + i, from, n) == 0)
            found++, at = i;
    REQUIRE(found == 1);
    memcpy(bytes + at, to, n);
    REQUIRE(fseek(f, 0, SEEK_SET) == 0 && fwrite(bytes, 1, size, f) == size && fclose(f) == 0);
}

/* Writes a DICOM file without Pixel Data (a presentation state, or an index under another
 * name than DICOMDIR) as dir/name: meta header, SOP class, a few elements. */
static void write_non_image(const char *dir, const char *name, const char *sop_class)
{
    char path[4200];
    test_bytes b = {0};
    snprintf(path, sizeof path, "%s/%s", dir, name);
    test_bytes_put(&b, (unsigned char[128]){0}, 128);
    test_bytes_put(&b, "DICM", 4);
    test_dicom_meta(&b, "1.2.826.0.1.3680043.2.1125.77", TEST_DICOM_EXPLICIT_LE);
    test_dicom_text(&b, 0x0008, 0x0016, "UI", sop_class);
    test_dicom_text(&b, 0x0008, 0x0018, "UI", "1.2.826.0.1.3680043.2.1125.77");
    test_dicom_text(&b, 0x0008, 0x0060, "CS", "PR");
    test_dicom_text(&b, 0x0020, 0x000E, "UI", "1.2.826.0.1.3680043.2.1125.1.1");
    FILE *f = fopen(path, "wb");
    REQUIRE(f != NULL && fwrite(b.data, 1, b.size, f) == b.size && fclose(f) == 0);
    free(b.data);
}

/* A deflated series (explicit VR little endian, its data set deflated): inflated for the check
 * of its structure, then read by the library, sample for sample. */
static void test_deflated(void)
{
    char dir[4096];
    test_dicom_series s = test_dicom_default(7, 5, 4, IP_INT16);
    void *volume = make_volume(&s);
    ip_input_desc desc;
    ip_error err;
    s.syntax = TEST_DICOM_DEFLATE;
    test_dicom_write_series(&s, volume, fresh_folder(dir, "deflated"));
    CHECK_MSG(ip_input_describe(dir, NULL, &desc, &err) == IP_OK, "%s", err.message);
    CHECK(desc.dims[0] == 7 && desc.dims[1] == 5 && desc.dims[2] == 4 && desc.type == IP_INT16);
    check_samples(&desc, volume);
    free(volume);
}

/* Slices holding sequences (a Referenced Image Sequence, an Icon Image Sequence with an image
 * of its own), in each transfer syntax: read exactly. */
static void test_sequences(void)
{
    const char *syntaxes[] = {TEST_DICOM_EXPLICIT_LE, TEST_DICOM_IMPLICIT_LE,
                              TEST_DICOM_EXPLICIT_BE, TEST_DICOM_RLE, TEST_DICOM_DEFLATE};
    char dir[4096];
    for (size_t k = 0; k < sizeof syntaxes / sizeof syntaxes[0]; k++) {
        test_dicom_series s = test_dicom_default(6, 5, 4, IP_UINT16);
        void *volume = make_volume(&s);
        ip_input_desc desc;
        ip_error err;
        s.syntax = syntaxes[k];
        s.sequences = 1;
        test_dicom_write_series(&s, volume, fresh_folder(dir, "sequences"));
        CHECK_MSG(ip_input_describe(dir, NULL, &desc, &err) == IP_OK, "%s: %s", syntaxes[k],
                  err.message);
        check_samples(&desc, volume);
        free(volume);
    }
}

/* Pixel Data longer than the image its header describes (Rows x Columns x samples x bytes x
 * frames): refused, since the header and the data then describe different images; only the
 * one byte that pads an odd length to an even one is taken (an 8-bit slice of 5 x 3 pixels,
 * 15 bytes in a Pixel Data of 16). */
static void test_long_pixel_data(void)
{
    char dir[4096];
    test_dicom_series s = test_dicom_default(8, 7, 4, IP_UINT16);
    void *volume = make_volume(&s);
    s.syntax = TEST_DICOM_EXPLICIT_LE;
    /* Rows lowered from 7 to 6: 112 bytes of Pixel Data for an image of 96 */
    write_case(fresh_folder(dir, "long_rows"), &s, volume, 99, NULL, 0);
    patch_file(dir, "IM0002.dcm", "\x28\x00\x10\x00US\x02\x00\x07\x00",
               "\x28\x00\x10\x00US\x02\x00\x06\x00", 10);
    expect_refused(dir, IP_ERR_INPUT, "long_rows/IM0002.dcm",
                   "its Pixel Data holds 112 bytes, more than the 96 of the 8x6 image");
    /* Bits Allocated 8 over 16-bit samples: twice the image */
    write_case(fresh_folder(dir, "long_bits"), &s, volume, 99, NULL, 0);
    patch_file(dir, "IM0003.dcm", "\x28\x00\x00\x01US\x02\x00\x10\x00",
               "\x28\x00\x00\x01US\x02\x00\x08\x00", 10);
    expect_refused(dir, IP_ERR_INPUT, "long_bits/IM0003.dcm",
                   "its Pixel Data holds 112 bytes, more than the 56 of the 8x7 image of 8 bits");
    free(volume);
    /* an odd number of 8-bit samples, padded by one byte: read exactly */
    test_dicom_series odd = test_dicom_default(5, 3, 4, IP_UINT8);
    ip_input_desc desc;
    ip_error err;
    volume = make_volume(&odd);
    odd.syntax = TEST_DICOM_EXPLICIT_LE;
    test_dicom_write_series(&odd, volume, fresh_folder(dir, "padded"));
    CHECK_MSG(ip_input_describe(dir, NULL, &desc, &err) == IP_OK, "%s", err.message);
    check_samples(&desc, volume);
    free(volume);
}

/* A series with one odd member: a slice of other Columns or Bits Allocated (each a consistent
 * file of its own), a DICOM object without Pixel Data whose SOP class is an image's (objects
 * that are not images are skipped: test_non_image), files that are not DICOM (text first in name order; an empty
 * file and one shorter than a preamble among the slices): each refused in one line naming the
 * file. */
static void test_odd_member(void)
{
    char dir[4096];
    test_dicom_series s = test_dicom_default(8, 7, 6, IP_UINT16), odd;
    void *volume = make_volume(&s);
    s.syntax = TEST_DICOM_EXPLICIT_LE;

    odd = s, odd.dims[0] = 7, odd.origin_z += 6 * s.step_z;
    write_case(fresh_folder(dir, "columns"), &s, volume, 99, &odd, 0);
    expect_refused(dir, IP_ERR_INPUT, "columns/odd.dcm",
                   "mixed series: a different size (rows, columns) than IM0001.dcm (7x7 uint16");

    odd = s, odd.type = IP_UINT8, odd.origin_z += 6 * s.step_z;
    write_case(fresh_folder(dir, "bits"), &s, volume, 99, &odd, 0);
    expect_refused(dir, IP_ERR_INPUT, "bits/odd.dcm", "mixed series: a different sample type");

    /* a DICOM object without Pixel Data of an image's SOP class: not skipped, refused */
    write_case(fresh_folder(dir, "no_pixels"), &s, volume, 99, NULL, 0);
    write_non_image(dir, "PS0001.dcm", TEST_DICOM_CT_STORAGE);
    expect_refused(dir, IP_ERR_INPUT, "no_pixels/PS0001.dcm", "holds no Pixel Data");

    write_case(fresh_folder(dir, "text_first"), &s, volume, 99, NULL, 0);
    write_text_file(dir, "0readme.txt", "series of Tuesday\n");
    expect_refused(dir, IP_ERR_INPUT, "text_first/0readme.txt", "neither DICOM nor TIFF");

    write_case(fresh_folder(dir, "empty_file"), &s, volume, 99, NULL, 0);
    write_text_file(dir, "zz_empty.dcm", "");
    expect_refused(dir, IP_ERR_INPUT, "empty_file/zz_empty.dcm", "not a DICOM file");

    write_case(fresh_folder(dir, "short_file"), &s, volume, 99, NULL, 0);
    write_text_file(dir, "zz_short.dcm", "DICM, but too early");
    expect_refused(dir, IP_ERR_INPUT, "short_file/zz_short.dcm", "not a DICOM file");
    free(volume);
}

/* What the fuzz harness (tests/fuzz/fuzz_dicom.c) found, each refused in one line naming the
 * file now: an unknown value representation in the meta header (GDCM reads it as UN, with a
 * 32-bit length, and stopped the process on an assertion); RLE Lossless Pixel Data whose header
 * gives no segment (GDCM's decoder divided by zero); a transfer syntax UID holding a line feed
 * (it went into the message as it was, making it two lines); an element GDCM reads through its
 * Attribute class (Frame Increment Pointer) of another value representation than its
 * dictionary's (an assertion in GDCM's decoding); a Rescale Intercept without a Rescale Slope
 * (GDCM read a slope of 0 for an MR image and asserted), and a slope of 0; 8-bit samples of 7
 * bits stored (an assertion in GDCM's decoders); an icon image of 2 samples a pixel (an
 * assertion when GDCM reads the file's image); an overlay plane (GDCM's overlay reader asserts
 * on standard elements it does not know: found by reading its source after the icon); a
 * Recognition Code (0008,0010) other than ACR-NEMA's (an assertion when GDCM reads the image).
 * And the structure rules that keep GDCM on its plain reading path: elements in ascending
 * order, Rows of its dictionary's value representation. */
static void test_fuzz_findings(void)
{
    char dir[4096];
    test_dicom_series s = test_dicom_default(8, 7, 4, IP_UINT16);
    void *volume = make_volume(&s);
    s.syntax = TEST_DICOM_EXPLICIT_LE;

    write_case(fresh_folder(dir, "meta_vr"), &s, volume, 99, NULL, 0);
    patch_file(dir, "IM0002.dcm", "\x02\x00\x10\x00UI", "\x02\x00\x10\x00UK", 6);
    expect_refused(dir, IP_ERR_INPUT, "meta_vr/IM0002.dcm",
                   "an unknown value representation at byte");

    write_case(fresh_folder(dir, "line_feed"), &s, volume, 99, NULL, 0);
    patch_file(dir, "IM0003.dcm", "1.2.840.10008.1.2.1\0", "1.2.840\n10008.1.2.1\0", 20);
    expect_refused(dir, IP_ERR_UNSUPPORTED, "line_feed/IM0003.dcm",
                   "unknown transfer syntax 1.2.840?10008.1.2.1");

    write_case(fresh_folder(dir, "order"), &s, volume, 99, NULL, 0);
    patch_file(dir, "IM0001.dcm", "\x20\x00\x13\x00IS", "\x20\x00\x33\x00IS", 6);
    expect_refused(dir, IP_ERR_INPUT, "order/IM0001.dcm", "out of ascending tag order");

    /* Frame Increment Pointer (0028,0009), AT in GDCM's dictionary, as CS: GDCM asserted on it
     * when decoding (here the Photometric Interpretation's element retagged) */
    write_case(fresh_folder(dir, "frame_pointer"), &s, volume, 99, NULL, 0);
    patch_file(dir, "IM0003.dcm",
               "\x28\x00\x04\x00"
               "CS",
               "\x28\x00\x09\x00"
               "CS",
               6);
    expect_refused(dir, IP_ERR_INPUT, "frame_pointer/IM0003.dcm",
                   "a value representation CS, not AT, at byte");

    /* a Recognition Code (0008,0010) that is not ACR-NEMA's (here the SOP Class UID's element
     * retagged): GDCM asserted on it when reading the image */
    write_case(fresh_folder(dir, "recognition"), &s, volume, 99, NULL, 0);
    patch_file(dir, "IM0002.dcm", "\x08\x00\x16\x00UI", "\x08\x00\x10\x00SH", 6);
    expect_refused(dir, IP_ERR_INPUT, "recognition/IM0002.dcm",
                   "a Recognition Code (0008,0010) other than ACR-NEMA's");

    write_case(fresh_folder(dir, "rows_vr"), &s, volume, 99, NULL, 0);
    patch_file(dir, "IM0004.dcm", "\x28\x00\x10\x00US", "\x28\x00\x10\x00SS", 6);
    expect_refused(dir, IP_ERR_INPUT, "rows_vr/IM0004.dcm", "a value representation SS, not US");

    /* Rescale Slope (0028,1053) retagged (0028,1055): an intercept without a slope, which
     * GDCM read as one over a slope of 0 for an MR image, and asserted on; a slope of 0 */
    write_case(fresh_folder(dir, "no_slope"), &s, volume, 99, NULL, 0);
    patch_file(dir, "IM0004.dcm",
               "\x28\x00\x53\x10"
               "DS",
               "\x28\x00\x55\x10"
               "DS",
               6);
    expect_refused(dir, IP_ERR_INPUT, "no_slope/IM0004.dcm",
                   "a Rescale Intercept without a Rescale Slope");
    test_dicom_series flat = s;
    flat.slope = 0;
    write_case(fresh_folder(dir, "zero_slope"), &flat, volume, 99, NULL, 0);
    expect_refused(dir, IP_ERR_INPUT, "zero_slope/IM0001.dcm",
                   "a Rescale Slope that is not a number other than 0");

    /* an Icon Image Sequence stored as OB (GDCM would guess at its items), a private
     * transfer syntax (GE's implicit VR big endian, which GDCM reads with its own rules) */
    test_dicom_series icon = s;
    icon.sequences = 1;
    write_case(fresh_folder(dir, "icon_ob"), &icon, volume, 99, NULL, 0);
    patch_file(dir, "IM0002.dcm", "\x88\x00\x00\x02SQ", "\x88\x00\x00\x02OB", 6);
    expect_refused(dir, IP_ERR_INPUT, "icon_ob/IM0002.dcm", "a value representation OB, not SQ");
    /* an icon of 2 samples a pixel: GDCM asserted on it while reading the file's image */
    write_case(fresh_folder(dir, "icon_samples"), &icon, volume, 99, NULL, 0);
    patch_file(dir, "IM0003.dcm",
               "\xFE\xFF\x00\xE0\xFF\xFF\xFF\xFF\x28\x00\x02\x00US\x02\x00\x01\x00",
               "\xFE\xFF\x00\xE0\xFF\xFF\xFF\xFF\x28\x00\x02\x00US\x02\x00\x02\x00", 18);
    expect_refused(dir, IP_ERR_INPUT, "icon_samples/IM0003.dcm",
                   "an icon image that GDCM cannot read");
    /* a well-formed overlay plane: refused all the same, since GDCM's overlay reader, which
     * runs whenever it reads the image, stops the process on a format other than RECT and on
     * elements it does not know, Overlay Activation Layer (60xx,1001) among them (the two
     * crafted_overlay_* inputs of the corpus) */
    test_dicom_series overlay = s;
    overlay.overlay = 1;
    write_case(fresh_folder(dir, "overlay"), &overlay, volume, 99, NULL, 0);
    expect_refused(dir, IP_ERR_INPUT, "overlay/IM0001.dcm",
                   "holds an overlay (group 6000): overlays and curves are not read");
    test_dicom_series private_syntax = s;
    private_syntax.syntax = "1.2.840.113619.5.2";
    write_case(fresh_folder(dir, "private_syntax"), &private_syntax, volume, 99, NULL, 0);
    expect_refused(dir, IP_ERR_INPUT, "private_syntax/IM0001.dcm",
                   "transfer syntax 1.2.840.113619.5.2: a private or non-standard encoding");

    s.syntax = TEST_DICOM_RLE;
    write_case(fresh_folder(dir, "rle_segments"), &s, volume, 99, NULL, 0);
    /* the RLE header: 2 segments (one a byte of the 16-bit samples), the first at byte 64 */
    patch_file(dir, "IM0002.dcm", "\x02\0\0\0\x40\0\0\0", "\0\0\0\0\x40\0\0\0", 8);
    expect_refused(dir, IP_ERR_INPUT, "rle_segments/IM0002.dcm",
                   "RLE Lossless Pixel Data without a header that fits its image");
    free(volume);

    /* 8-bit samples of 7 bits stored (High Bit 6): described, then GDCM's decoder asserted
     * that 8-bit samples store 8 bits */
    test_dicom_series bytes = test_dicom_default(8, 7, 4, IP_UINT8);
    volume = make_volume(&bytes);
    bytes.syntax = TEST_DICOM_EXPLICIT_LE;
    write_case(fresh_folder(dir, "seven_bits"), &bytes, volume, 99, NULL, 0);
    for (unsigned z = 1; z <= 4; z++) {
        char name[32];
        snprintf(name, sizeof name, "IM%04u.dcm", z);
        patch_file(dir, name, "\x28\x00\x01\x01US\x02\x00\x08\x00",
                   "\x28\x00\x01\x01US\x02\x00\x07\x00", 10);
        patch_file(dir, name, "\x28\x00\x02\x01US\x02\x00\x07\x00",
                   "\x28\x00\x02\x01US\x02\x00\x06\x00", 10);
    }
    expect_refused(dir, IP_ERR_INPUT, "seven_bits/IM0001.dcm",
                   "8-bit samples of 7 bits stored: only 8 bits stored in 8 are decoded");
    free(volume);
}

/* ---- folders as scanners write them ---- */

/* Describes `dir` with `o` (NULL: none), failing the test with the message when it fails. */
static int describe(const char *dir, const ip_input_overrides *o, ip_input_desc *desc)
{
    ip_error err;
    ip_status st = ip_input_describe(dir, o, desc, &err);
    CHECK_MSG(st == IP_OK, "%s: %s", dir, err.message);
    return st == IP_OK;
}

/* dir/name as a fresh folder (its parents made), its path into out. */
static const char *sub_folder(char out[4200], const char *dir, const char *name)
{
    char cmd[8600];
    snprintf(out, 4200, "%s/%s", dir, name);
    snprintf(cmd, sizeof cmd, "mkdir -p '%s'", out);
    REQUIRE(system(cmd) == 0);
    return out;
}

/* Objects that are not images, skipped by their SOP class whatever their name: a media storage
 * directory named DIRFILE (a DICOMDIR as Philips writes it beside the images), a grayscale
 * presentation state, a basic text structured report, a presentation state whose meta header
 * says CT (its data set's SOP class counts), and a DICOMDIR; counted in the description; the
 * samples read exactly. A folder of such objects alone holds no image. */
static void test_non_image(void)
{
    char dir[4096], path[4200];
    test_dicom_series s = test_dicom_default(8, 7, 6, IP_UINT16);
    void *volume = make_volume(&s);
    ip_input_desc desc;
    s.syntax = TEST_DICOM_EXPLICIT_LE;
    write_case(fresh_folder(dir, "non_image"), &s, volume, 99, NULL, 0);
    snprintf(path, sizeof path, "%s/DIRFILE", dir);
    test_dicom_write_object(path, TEST_DICOM_DIRECTORY, NULL);
    snprintf(path, sizeof path, "%s/PS0001", dir);
    test_dicom_write_object(path, TEST_DICOM_GRAYSCALE_PS, s.series_uid);
    snprintf(path, sizeof path, "%s/SR0001", dir);
    test_dicom_write_object(path, TEST_DICOM_BASIC_TEXT_SR, s.series_uid);
    write_non_image(dir, "PS0002.dcm", TEST_DICOM_GRAYSCALE_PS);
    write_index(dir);
    if (describe(dir, NULL, &desc)) {
        CHECK_EQ(desc.skipped_objects, 5);
        CHECK_EQ(desc.source_slices, 6);
        CHECK_EQ(desc.series_count, 1);
        CHECK_STR_EQ(desc.series_uid, s.series_uid);
        CHECK_EQ(desc.resampled, 0);
        check_samples(&desc, volume);
    }
    fresh_folder(dir, "objects_only");
    snprintf(path, sizeof path, "%s/DIRFILE", dir);
    test_dicom_write_object(path, TEST_DICOM_DIRECTORY, NULL);
    snprintf(path, sizeof path, "%s/SR0001", dir);
    test_dicom_write_object(path, TEST_DICOM_BASIC_TEXT_SR, s.series_uid);
    expect_refused(dir, IP_ERR_INPUT, "objects_only",
                   "holds no DICOM images (2 DICOM objects that are not images skipped)");
    free(volume);
}

/* A series spread over subfolders (a/, a/b/, c/), the folder itself holding only a DICOMDIR,
 * and a folder holding only subfolders: read whole, in order of position, exactly. */
static void test_subfolders(void)
{
    char dir[4096], sub[4200], path[4600];
    const char *const places[] = {"a", "a/b", "c"};
    test_dicom_series s = test_dicom_default(9, 8, 9, IP_INT16);
    void *volume = make_volume(&s);
    ip_input_desc desc;
    for (int with_index = 1; with_index >= 0; with_index--) {
        fresh_folder(dir, with_index ? "subfolders" : "only_subfolders");
        for (uint32_t z = 0; z < s.dims[2]; z++) {
            sub_folder(sub, dir, places[(z * 5) % 3]);
            snprintf(path, sizeof path, "%s/IM%04u", sub, z + 1);
            test_dicom_write_slice(&s, volume, z, path);
        }
        if (with_index)
            write_index(dir);
        if (describe(dir, NULL, &desc)) {
            CHECK_EQ(desc.dims[2], 9);
            CHECK_EQ(desc.skipped_objects, (uint32_t)with_index);
            check_samples(&desc, volume);
        }
    }
    free(volume);
}

/* Two series in one folder (each in a subfolder, with a report and a directory beside them):
 * refused without a pick, naming both; picked by UID and by a prefix of one only; a prefix of
 * both and a UID of none refused; the list gives each series' UID, description, modality,
 * slices, size and spacing, in the order of their first file. */
static void test_several_series(void)
{
    char dir[4096], sub[4200], path[4400];
    test_dicom_series head = test_dicom_default(8, 7, 6, IP_INT16);
    test_dicom_series lung = test_dicom_default(6, 5, 4, IP_INT16);
    void *volume = make_volume(&head);
    head.description = "Head 2.5";
    lung.series_uid = "1.2.826.0.1.3680043.2.1125.1.22", lung.description = "Lung";
    lung.step_z = 1.25;
    fresh_folder(dir, "several");
    test_dicom_write_series(&head, volume, sub_folder(sub, dir, "S1"));
    test_dicom_write_series(&lung, volume, sub_folder(sub, dir, "S2"));
    snprintf(path, sizeof path, "%s/DIRFILE", dir);
    test_dicom_write_object(path, TEST_DICOM_DIRECTORY, NULL);
    snprintf(path, sizeof path, "%s/S2/SR0001", dir);
    test_dicom_write_object(path, TEST_DICOM_BASIC_TEXT_SR, lung.series_uid);
    expect_refused(dir, IP_ERR_INPUT, "several",
                   "the folder holds 2 series: pick one by its UID (isobrick --series UID): "
                   "1.2.826.0.1.3680043.2.1125.1.1 \"Head 2.5\" CT 6 slices; "
                   "1.2.826.0.1.3680043.2.1125.1.22 \"Lung\" CT 4 slices");
    ip_input_overrides o = IP_SIZED(ip_input_overrides);
    ip_input_desc desc;
    o.series = head.series_uid; /* also a prefix of the other: the exact one wins */
    if (describe(dir, &o, &desc)) {
        CHECK_EQ(desc.dims[2], 6);
        CHECK_EQ(desc.series_count, 2);
        CHECK_EQ(desc.skipped_objects, 2);
        check_samples(&desc, volume);
    }
    o.series = "1.2.826.0.1.3680043.2.1125.1.2";
    if (describe(dir, &o, &desc)) {
        CHECK_STR_EQ(desc.series_uid, lung.series_uid);
        CHECK_EQ(desc.dims[0], 6);
        CHECK_EQ(desc.dims[2], 4);
        CHECK_NEAR(desc.spacing[2], 1.25, 1e-9);
    }
    ip_error err;
    o.series = "1.2.826.0.1.3680043.2.1125.1";
    CHECK_EQ(ip_input_describe(dir, &o, &desc, &err), IP_ERR_INPUT);
    CHECK_CONTAINS(err.message, "2 series UIDs start with 1.2.826.0.1.3680043.2.1125.1: give more");
    o.series = "1.2.3";
    CHECK_EQ(ip_input_describe(dir, &o, &desc, &err), IP_ERR_INPUT);
    CHECK_CONTAINS(err.message, "no series UID is or starts with 1.2.3; the folder holds");
    /* a series asked of another input */
    snprintf(path, sizeof path, "%s/volume_4x4x4_uint8.raw", scratch);
    FILE *f = fopen(path, "wb");
    REQUIRE(f != NULL && fwrite(volume, 1, 64, f) == 64 && fclose(f) == 0);
    CHECK_EQ(ip_input_describe(path, &o, &desc, &err), IP_ERR_ARGUMENT);
    CHECK_CONTAINS(err.message, "not a folder of DICOM files");

    ip_dicom_series_info *list = NULL;
    uint32_t count = 0, skipped = 0;
    CHECK_MSG(ip_dicom_list_series(dir, &list, &count, &skipped, &err) == IP_OK, "%s", err.message);
    CHECK_EQ(count, 2);
    CHECK_EQ(skipped, 2);
    if (count == 2) {
        CHECK_STR_EQ(list[0].uid, head.series_uid);
        CHECK_STR_EQ(list[0].description, "Head 2.5");
        CHECK_STR_EQ(list[0].modality, "CT");
        CHECK_EQ(list[0].slices, 6);
        CHECK_EQ(list[0].dims[0], 8);
        CHECK_EQ(list[0].dims[1], 7);
        CHECK_EQ(list[0].dims[2], 6);
        CHECK_NEAR(list[0].spacing[0], 0.8, 1e-12);
        CHECK_NEAR(list[0].spacing[1], 0.7, 1e-12);
        CHECK_NEAR(list[0].spacing[2], 2.5, 1e-12);
        CHECK_STR_EQ(list[0].problem, "");
        CHECK_STR_EQ(list[1].uid, lung.series_uid);
        CHECK_EQ(list[1].slices, 4);
        CHECK_NEAR(list[1].spacing[2], 1.25, 1e-12);
    }
    free(list);
    free(volume);
}

/* A series that cannot be read (MONOCHROME1) beside one that can: the other is read; the list
 * shows the failing one with the reason, its size unknown. */
static void test_failing_series(void)
{
    char dir[4096], sub[4200];
    test_dicom_series good = test_dicom_default(6, 5, 4, IP_UINT16);
    test_dicom_series inverted = good;
    void *volume = make_volume(&good);
    inverted.series_uid = "1.2.826.0.1.3680043.2.1125.9.9", inverted.photometric = "MONOCHROME1";
    fresh_folder(dir, "failing");
    test_dicom_write_series(&good, volume, sub_folder(sub, dir, "A"));
    test_dicom_write_series(&inverted, volume, sub_folder(sub, dir, "B"));
    ip_input_overrides o = IP_SIZED(ip_input_overrides);
    ip_input_desc desc;
    ip_error err;
    o.series = good.series_uid;
    if (describe(dir, &o, &desc))
        check_samples(&desc, volume);
    o.series = inverted.series_uid;
    CHECK_EQ(ip_input_describe(dir, &o, &desc, &err), IP_ERR_UNSUPPORTED);
    CHECK_CONTAINS(err.message, "failing/B/IM0001.dcm: MONOCHROME1");
    ip_dicom_series_info *list = NULL;
    uint32_t count = 0;
    CHECK(ip_dicom_list_series(dir, &list, &count, NULL, &err) == IP_OK && count == 2);
    if (count == 2) {
        CHECK_STR_EQ(list[0].problem, "");
        CHECK_EQ(list[1].slices, 4);
        CHECK_EQ(list[1].dims[0], 0);
        CHECK_CONTAINS(list[1].problem, "failing/B/IM0001.dcm: MONOCHROME1");
    }
    free(list);
    free(volume);
}

/* The ball the tilted series images (test_dicom_tilted()): centre (mm, LPS) and the radius
 * of the sphere of the iso value 2000 - 40 x radius. */
static const double sphere_centre[3] = TEST_DICOM_BALL_CENTRE, sphere_radius = 10;

/* The tilted series into dir. */
static void tilted_sphere(const char *dir)
{
    test_dicom_series s = test_dicom_tilted();
    int16_t *v = test_dicom_ball(&s, sphere_centre);
    test_dicom_write_series(&s, v, dir);
    free(v);
}

/* The centroid (mm, in desc's physical space) and the radius of the sphere of the same volume
 * of the samples of desc's volume at or above `iso`. */
static void measure_sphere(const ip_input_desc *desc, double iso, double centroid[3],
                           double *radius)
{
    size_t plane = (size_t)desc->dims[0] * desc->dims[1];
    int16_t *v = malloc(plane * desc->dims[2] * sizeof *v);
    REQUIRE(v != NULL);
    ip_input_reader *r = NULL;
    ip_error err;
    REQUIRE(ip_input_open(desc, &r, &err) == IP_OK);
    REQUIRE(ip_input_read_planes(r, v, desc->dims[2], &err) == IP_OK);
    ip_input_close(r);
    double sum[3] = {0, 0, 0}, count = 0;
    for (uint32_t z = 0; z < desc->dims[2]; z++)
        for (uint32_t y = 0; y < desc->dims[1]; y++)
            for (uint32_t x = 0; x < desc->dims[0]; x++) {
                if (v[z * plane + (size_t)y * desc->dims[0] + x] < iso)
                    continue;
                double w[3] = {x * desc->spacing[0], y * desc->spacing[1], z * desc->spacing[2]},
                       p[3];
                ip_orientation_apply(&desc->orientation, w, p);
                for (int a = 0; a < 3; a++)
                    sum[a] += p[a];
                count++;
            }
    for (int a = 0; a < 3; a++)
        centroid[a] = count ? sum[a] / count : 0;
    double volume = count * desc->spacing[0] * desc->spacing[1] * desc->spacing[2];
    *radius = cbrt(volume * 3 / (4 * M_PI));
    free(v);
}

/* A gantry tilt: resampled by default onto a grid along the slices' rows, columns and normal,
 * the sphere where it is in physical space (centroid and radius within half a voxel); refused
 * when asked, naming the tilt and the option; the list says it. */
static void test_tilt(void)
{
    char dir[4096];
    tilted_sphere(fresh_folder(dir, "tilted"));
    ip_input_desc desc;
    if (describe(dir, NULL, &desc)) {
        CHECK_EQ(desc.resampled, IP_RESAMPLED_TILT);
        CHECK_NEAR(desc.tilt_degrees, 18.5, 0.05);
        CHECK_EQ(desc.source_slices, 13);
        /* the slices' rows, and their columns widened by the 12 x 0.79 mm of the shift */
        CHECK_EQ(desc.dims[0], 40);
        CHECK_EQ(desc.dims[1], 36 + 14);
        CHECK_EQ(desc.dims[2], 13);
        CHECK_NEAR(desc.spacing[2], 2.36, 1e-9);
        /* the grid starts 14 rows before the first slice's, at y = 30 - 14 x 0.7 */
        CHECK_NEAR(desc.orientation.origin[0], -12.5, 1e-9);
        CHECK_NEAR(desc.orientation.origin[1], 30 - 14 * 0.7, 1e-9);
        CHECK_NEAR(desc.orientation.origin[2], -40, 1e-9);
        double centroid[3], radius;
        measure_sphere(&desc, 2000 - 40 * sphere_radius, centroid, &radius);
        for (int a = 0; a < 3; a++)
            CHECK_NEAR(centroid[a], sphere_centre[a], desc.spacing[a] / 2);
        CHECK_NEAR(radius, sphere_radius, 0.35);
    }
    ip_input_overrides o = IP_SIZED(ip_input_overrides);
    o.tilt = IP_REGRID_REFUSE;
    ip_error err;
    CHECK_EQ(ip_input_describe(dir, &o, &desc, &err), IP_ERR_INPUT);
    CHECK_CONTAINS(err.message, "tilted: gantry tilt: the slices stack 18.5 degrees off their "
                                "normal, shifted (0, -0.79) mm a slice");
    CHECK_CONTAINS(err.message, "--correct-tilt");
    o.tilt = (ip_regrid)7;
    CHECK_EQ(ip_input_describe(dir, &o, &desc, &err), IP_ERR_ARGUMENT);
    ip_dicom_series_info *list = NULL;
    uint32_t count = 0;
    CHECK(ip_dicom_list_series(dir, &list, &count, NULL, &err) == IP_OK && count == 1);
    if (count == 1) {
        CHECK_EQ(list[0].resampled, IP_RESAMPLED_TILT);
        CHECK_EQ(list[0].dims[1], 50);
        CHECK_NEAR(list[0].tilt_degrees, 18.5, 0.05);
    }
    free(list);
}

/* Uneven steps (2.5 mm, then a 5 mm gap, then 1.25 mm): refused by default, naming the
 * option; resampled when asked onto planes 1.25 mm apart, each the linear interpolation of the
 * two slices around it (exact for samples linear along z, within the rounding). */
static void test_uneven(void)
{
    char dir[4096];
    static const double z_at[] = {-40, -37.5, -35, -30, -28.75, -27.5, -26.25, -25};
    test_dicom_series s = test_dicom_default(5, 4, 8, IP_INT16);
    s.z_at = z_at;
    s.syntax = TEST_DICOM_EXPLICIT_LE;
    int16_t v[8 * 20];
    for (int z = 0; z < 8; z++)
        for (int i = 0; i < 20; i++)
            v[z * 20 + i] = (int16_t)(i + 8 * (z_at[z] + 40)); /* 8 a mm along z */
    test_dicom_write_series(&s, v, fresh_folder(dir, "uneven_steps"));
    expect_refused(
        dir, IP_ERR_INPUT, "uneven_steps",
        "a slice is missing between IM0004.dcm (at -40 mm) and IM0003.dcm (at -37.5 mm)");
    expect_refused(dir, IP_ERR_INPUT, "uneven_steps",
                   "isobrick --even-spacing resamples them onto an even grid");
    ip_input_overrides o = IP_SIZED(ip_input_overrides);
    ip_input_desc desc;
    o.uneven = IP_REGRID_RESAMPLE;
    if (!describe(dir, &o, &desc))
        return;
    CHECK_EQ(desc.resampled, IP_RESAMPLED_UNEVEN);
    CHECK_EQ(desc.dims[2], 13); /* 15 mm in steps of 1.25 */
    CHECK_NEAR(desc.spacing[2], 1.25, 1e-9);
    CHECK_EQ(desc.source_slices, 8);
    int16_t got[13 * 20];
    ip_input_reader *r = NULL;
    ip_error err;
    REQUIRE(ip_input_open(&desc, &r, &err) == IP_OK);
    CHECK_MSG(ip_input_read_planes(r, got, 13, &err) == IP_OK, "%s", err.message);
    ip_input_close(r);
    for (int z = 0; z < 13; z++)
        for (int i = 0; i < 20; i++)
            CHECK_EQ(got[z * 20 + i], (int16_t)(i + 10 * z));
}

static void test_series_int16(void)
{
    test_series(IP_INT16, "int16");
}
static void test_series_uint16(void)
{
    test_series(IP_UINT16, "uint16");
}
static void test_series_uint8(void)
{
    test_series(IP_UINT8, "uint8");
}

static const test_case cases[] = {
    {"test_series:int16", test_series_int16},
    {"test_series:uint16", test_series_uint16},
    {"test_series:uint8", test_series_uint8},
    TEST_CASE(test_overrides),
    TEST_CASE(test_rescale_unit),
    TEST_CASE(test_refused),
    TEST_CASE(test_changed_file),
    TEST_CASE(test_malformed),
    TEST_CASE(test_deflated),
    TEST_CASE(test_sequences),
    TEST_CASE(test_long_pixel_data),
    TEST_CASE(test_odd_member),
    TEST_CASE(test_fuzz_findings),
    TEST_CASE(test_non_image),
    TEST_CASE(test_subfolders),
    TEST_CASE(test_several_series),
    TEST_CASE(test_failing_series),
    TEST_CASE(test_tilt),
    TEST_CASE(test_uneven),
};

static void make_scratch_dir(void)
{
    snprintf(scratch, sizeof scratch, "%s", test_tmp_dir("test_input_dicom"));
}

int main(int argc, char **argv)
{
    return RUN_CASES_WITH(argc, argv, cases, "test_input_dicom", make_scratch_dir, NULL);
}

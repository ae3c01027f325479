/* SPDX-License-Identifier: BSD-3-Clause */
/* NIfTI input: NIfTI-1 and -2, both byte orders, .nii and .nii.gz, every supported type, the
 * spacing from pixdim, the scaling reported, overrides, and the usual breakages (truncated,
 * 4D, bad magic, unsupported datatype, .hdr/.img pairs), each one line naming the file. The
 * files are written here by hand. */
#include <math.h>
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

/* Samples of `type` that use both bytes of the 16-bit types; finite floats. */
static void *make_samples(ip_type type, const uint32_t dims[3])
{
    size_t count = (size_t)dims[0] * dims[1] * dims[2];
    unsigned char *data = malloc(count * ip_type_size(type));
    REQUIRE(data != NULL);
    for (size_t i = 0; i < count; i++) {
        double v = (double)((i * 2654435761u) % 65536);
        switch (type) {
        case IP_UINT8: data[i] = (unsigned char)((unsigned)v & 0xff); break;
        case IP_UINT16: ((uint16_t *)data)[i] = (uint16_t)v; break;
        case IP_INT16: ((int16_t *)data)[i] = (int16_t)(v - 32768); break;
        case IP_FLOAT32: ((float *)data)[i] = (float)(v / 8 - 1000); break;
        }
    }
    return data;
}

static nifti_style style_of(int version, int big_endian, int gzip)
{
    nifti_style s;
    memset(&s, 0, sizeof s);
    s.version = version;
    s.big_endian = big_endian;
    s.gzip = gzip;
    s.pixdim[0] = 0.5;
    s.pixdim[1] = -0.75; /* a flipped axis: the spacing is its size */
    s.pixdim[2] = 2.0;
    return s;
}

/* Every version, byte order, compression and type reads back the samples written. */
static void test_round_trips(void)
{
    const uint32_t dims[3] = {13, 7, 5};
    int cases = 0;
    for (int version = 1; version <= 2; version++)
        for (int be = 0; be < 2; be++)
            for (int gz = 0; gz < 2; gz++)
                for (int t = 0; t < 4; t++) {
                    char path[4096], name[64];
                    ip_type type = (ip_type)t;
                    nifti_style s = style_of(version, be, gz);
                    void *samples = make_samples(type, dims);
                    snprintf(name, sizeof name, "v%d_%s_%s.nii%s", version, be ? "be" : "le",
                             ip_type_name(type), gz ? ".gz" : "");
                    REQUIRE(write_nifti(in_scratch(path, name), type, dims, samples, &s) == 0);
                    ip_input_desc d;
                    ip_error err;
                    ip_status st = ip_input_describe(path, NULL, &d, &err);
                    CHECK_MSG(st == IP_OK, "%s: %s", name, err.message);
                    if (st != IP_OK)
                        continue;
                    CHECK_EQ(d.type, type);
                    CHECK_EQ(d.big_endian, be);
                    CHECK_EQ(d.dims[0], 13);
                    CHECK_EQ(d.dims[1], 7);
                    CHECK_EQ(d.dims[2], 5);
                    CHECK_EQ(d.spacing[0], 0.5);
                    CHECK_EQ(d.spacing[1], 0.75);
                    CHECK_EQ(d.spacing[2], 2.0);
                    CHECK_EQ(d.encoding, gz ? IP_ENCODING_GZIP : IP_ENCODING_RAW);
                    uint64_t offset = version == 1 ? 352 : 544;
                    CHECK_EQ(d.data_offset, gz ? 0 : offset);
                    CHECK_EQ(d.stream_skip, gz ? offset : 0);
                    CHECK(!d.has_rescale);
                    void *got = read_volume(&d, &err);
                    CHECK_MSG(got != NULL, "%s: %s", name, got ? "" : err.message);
                    if (got)
                        CHECK_MSG(memcmp(got, samples, 13 * 7 * 5 * ip_type_size(type)) == 0,
                                  "%s: samples differ", name);
                    free(got);
                    free(samples);
                    cases++;
                }
    CHECK_EQ(cases, 32);
}

/* The scaling is reported (slope 0 or 1 with intercept 0: none); a 4D file with one volume is
 * a 3D one; a larger vox_offset (extensions) is honoured; overrides win. */
static void test_header_fields(void)
{
    char path[4096];
    const uint32_t dims[3] = {4, 3, 2};
    void *samples = make_samples(IP_INT16, dims);
    nifti_style s = style_of(1, 0, 0);
    ip_input_desc d;
    ip_error err;
    s.slope = 2.5;
    s.intercept = -1024;
    s.dim[0] = 4, s.dim[1] = 4, s.dim[2] = 3, s.dim[3] = 2, s.dim[4] = 1;
    s.vox_offset = 400;
    REQUIRE(write_nifti(in_scratch(path, "scaled.nii"), IP_INT16, dims, samples, &s) == 0);
    REQUIRE(ip_input_describe(path, NULL, &d, &err) == IP_OK);
    CHECK(d.has_rescale);
    CHECK_EQ(d.rescale_slope, 2.5);
    CHECK_EQ(d.rescale_intercept, -1024);
    CHECK_STR_EQ(d.rescale_unit, ""); /* NIfTI names no unit for its values */
    CHECK_EQ(d.data_offset, 400);
    CHECK_EQ(d.dims[2], 2);
    void *got = read_volume(&d, &err);
    if (CHECK_NE(got, NULL))
        CHECK_MEM_EQ(got, samples, 4 * 3 * 2 * 2);
    free(got);
    s.slope = 0;
    REQUIRE(write_nifti(path, IP_INT16, dims, samples, &s) == 0);
    REQUIRE(ip_input_describe(path, NULL, &d, &err) == IP_OK);
    CHECK(!d.has_rescale);
    s.slope = 1, s.intercept = 0;
    REQUIRE(write_nifti(path, IP_INT16, dims, samples, &s) == 0);
    REQUIRE(ip_input_describe(path, NULL, &d, &err) == IP_OK);
    CHECK(!d.has_rescale);
    /* overrides: the spacing, and a type and dims standing in for unsupported ones */
    s.datatype = 8; /* int32: read as 2 x int16 per sample with --type and --dims */
    REQUIRE(write_nifti(path, IP_INT16, dims, samples, &s) == 0);
    ip_input_overrides o = {0};
    o.has_type = o.has_dims = o.has_spacing = 1;
    o.type = IP_UINT16;
    o.dims[0] = 2, o.dims[1] = 3, o.dims[2] = 4;
    o.spacing[0] = o.spacing[1] = o.spacing[2] = 0.1;
    ip_status st = ip_input_describe(path, &o, &d, &err);
    CHECK_MSG(st == IP_OK, "%s", err.message);
    CHECK_EQ(d.type, IP_UINT16);
    CHECK_EQ(d.dims[0], 2);
    CHECK_EQ(d.dims[2], 4);
    CHECK_EQ(d.spacing[1], 0.1);
    free(samples);
}

/* ---- orientation: sform, qform, both, neither ---- */

/* The rotation of the unit quaternion (0.8, 0.2, 0.4, 0.4), worked out by hand from the
 * NIfTI-1 formula: R[row][column], column a the direction of sample axis a. */
static const double turn[3][3] = {{0.36, -0.48, 0.8}, {0.8, 0.6, 0.0}, {-0.48, 0.64, 0.6}};

static void expect_orientation(const char *name, const ip_input_desc *d, const double origin[3],
                               const double columns[3][3], const double spacing[3], ip_space space)
{
    double worst = 0.0;
    for (int a = 0; a < 3; a++) {
        worst = fmax(worst, fabs(d->orientation.origin[a] - origin[a]));
        worst = fmax(worst, fabs(d->spacing[a] - spacing[a]));
        for (int c = 0; c < 3; c++)
            worst = fmax(worst, fabs(d->orientation.directions[a][c] - columns[c][a]));
    }
    CHECK_MSG(worst < 1e-6, "%s: off by %g", name, worst);
    CHECK_MSG(d->orientation.space == space, "%s: space %s", name,
              ip_space_name(d->orientation.space));
}

/* Sample index (i, j, k) lies at origin + D * (index x spacing): for an sform that is the
 * sform's own affine map, srow . (i, j, k, 1). */
static void expect_sform_map(const char *name, const ip_input_desc *d, const double srow[3][4])
{
    const double index[3] = {3, 4, 5};
    double world[3], physical[3], worst = 0.0;
    for (int a = 0; a < 3; a++)
        world[a] = index[a] * d->spacing[a];
    ip_orientation_apply(&d->orientation, world, physical);
    for (int r = 0; r < 3; r++) {
        double want =
            srow[r][0] * index[0] + srow[r][1] * index[1] + srow[r][2] * index[2] + srow[r][3];
        worst = fmax(worst, fabs(physical[r] - want));
    }
    CHECK_MSG(worst < 1e-5, "%s: index (3,4,5) off its sform position by %g", name, worst);
}

/* s's srow: the columns of `turn` times `spacing`, then `origin` (sform_code left as it is). */
static void put_sform(nifti_style *s, const double spacing[3], const double origin[3])
{
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++)
            s->srow[r][c] = turn[r][c] * spacing[c];
        s->srow[r][3] = origin[r];
    }
}

static void describe_ok(const char *path, ip_input_desc *d)
{
    ip_error err;
    ip_status st = ip_input_describe(path, NULL, d, &err);
    CHECK_MSG(st == IP_OK, "%s: %s", path, err.message);
    if (st != IP_OK)
        memset(d, 0, sizeof *d);
}

static void test_orientation(void)
{
    char path[4096], name[64];
    const uint32_t dims[3] = {6, 5, 4};
    void *samples = make_samples(IP_UINT8, dims);
    const double sform_origin[3] = {10, -20, 30.5}, spacing[3] = {0.5, 0.75, 2};
    const double qoffset[3] = {-5, 7.5, 12}, pixdim[3] = {1.25, 1.5, 3};
    const double identity[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, zero[3] = {0, 0, 0};
    double flipped[3][3]; /* turn with its third column times qfac = -1 */
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            flipped[r][c] = c == 2 ? -turn[r][c] : turn[r][c];
    ip_input_desc d;
    for (int version = 1; version <= 2; version++) {
        nifti_style s = style_of(version, version == 2, 0);
        memcpy(s.pixdim, pixdim, sizeof pixdim);
        put_sform(&s, spacing, sform_origin);
        s.quatern[0] = 0.2, s.quatern[1] = 0.4, s.quatern[2] = 0.4;
        memcpy(s.qoffset, qoffset, sizeof qoffset);

        /* only an sform: its columns' lengths are the spacing, pixdim unused */
        s.sform_code = 2;
        snprintf(name, sizeof name, "sform%d.nii", version);
        REQUIRE(write_nifti(in_scratch(path, name), IP_UINT8, dims, samples, &s) == 0);
        describe_ok(path, &d);
        expect_orientation(name, &d, sform_origin, turn, spacing, IP_SPACE_RAS);
        expect_sform_map(name, &d, s.srow);

        /* both: the sform wins */
        s.qform_code = 1;
        snprintf(name, sizeof name, "both%d.nii", version);
        REQUIRE(write_nifti(in_scratch(path, name), IP_UINT8, dims, samples, &s) == 0);
        describe_ok(path, &d);
        expect_orientation(name, &d, sform_origin, turn, spacing, IP_SPACE_RAS);

        /* only a qform (the srows filled but sform_code 0): pixdim is the spacing */
        s.sform_code = 0;
        snprintf(name, sizeof name, "qform%d.nii", version);
        REQUIRE(write_nifti(in_scratch(path, name), IP_UINT8, dims, samples, &s) == 0);
        describe_ok(path, &d);
        expect_orientation(name, &d, qoffset, turn, pixdim, IP_SPACE_RAS);

        /* qfac -1 turns the third axis round */
        s.qfac = -1;
        snprintf(name, sizeof name, "qfac%d.nii", version);
        REQUIRE(write_nifti(in_scratch(path, name), IP_UINT8, dims, samples, &s) == 0);
        describe_ok(path, &d);
        expect_orientation(name, &d, qoffset, flipped, pixdim, IP_SPACE_RAS);

        /* a sheared sform has no frame: the qform */
        s.sform_code = 1;
        s.srow[0][1] += 0.25;
        snprintf(name, sizeof name, "sheared%d.nii", version);
        REQUIRE(write_nifti(in_scratch(path, name), IP_UINT8, dims, samples, &s) == 0);
        describe_ok(path, &d);
        expect_orientation(name, &d, qoffset, flipped, pixdim, IP_SPACE_RAS);

        /* neither code: the identity, no space, pixdim */
        s.sform_code = s.qform_code = 0;
        snprintf(name, sizeof name, "neither%d.nii", version);
        REQUIRE(write_nifti(in_scratch(path, name), IP_UINT8, dims, samples, &s) == 0);
        describe_ok(path, &d);
        expect_orientation(name, &d, zero, identity, pixdim, IP_SPACE_UNKNOWN);
        CHECK(ip_orientation_is_identity(&d.orientation));
    }
    /* --spacing still replaces an sform's spacing; the directions stay */
    nifti_style s = style_of(1, 0, 0);
    put_sform(&s, spacing, sform_origin);
    s.sform_code = 4;
    REQUIRE(write_nifti(in_scratch(path, "override.nii"), IP_UINT8, dims, samples, &s) == 0);
    ip_input_overrides o = {0};
    ip_error err;
    o.has_spacing = 1;
    o.spacing[0] = o.spacing[1] = o.spacing[2] = 0.1;
    REQUIRE(ip_input_describe(path, &o, &d, &err) == IP_OK);
    const double tenths[3] = {0.1, 0.1, 0.1};
    expect_orientation("override.nii", &d, sform_origin, turn, tenths, IP_SPACE_RAS);
    free(samples);
}

static void patch(const char *path, long offset, const void *bytes, size_t size)
{
    FILE *f = fopen(path, "r+b");
    REQUIRE(f != NULL && fseek(f, offset, SEEK_SET) == 0 && fwrite(bytes, 1, size, f) == size);
    REQUIRE(fclose(f) == 0);
}

static void test_bad_files(void)
{
    char path[4096];
    const uint32_t dims[3] = {6, 5, 4};
    void *samples = make_samples(IP_UINT16, dims);
    nifti_style s = style_of(1, 0, 0);
    ip_input_desc d;
    ip_error err;

    /* truncated: inside the samples, inside the header, and a gzip stream cut short */
    REQUIRE(write_nifti(in_scratch(path, "short.nii"), IP_UINT16, dims, samples, &s) == 0);
    REQUIRE(truncate(path, 352 + 6 * 5 * 4 * 2 - 10) == 0);
    describe_fails(path, NULL, IP_ERR_INPUT, path, "does not equal 6x5x4 x 2 bytes");
    REQUIRE(truncate(path, 200) == 0);
    describe_fails(path, NULL, IP_ERR_INPUT, path, "truncated: 200 bytes, under the 348");
    s.gzip = 1;
    REQUIRE(write_nifti(in_scratch(path, "short.nii.gz"), IP_UINT16, dims, samples, &s) == 0);
    FILE *f = fopen(path, "rb");
    unsigned char whole[4096];
    size_t size = fread(whole, 1, sizeof whole, f);
    REQUIRE(fclose(f) == 0 && size > 40 && size < sizeof whole);
    f = fopen(path, "wb");
    REQUIRE(f != NULL && fwrite(whole, 1, size - 30, f) == size - 30 && fclose(f) == 0);
    REQUIRE(ip_input_describe(path, NULL, &d, &err) == IP_OK);
    void *got = read_volume(&d, &err);
    CHECK_EQ(got, NULL);
    CHECK_CONTAINS(err.message, "short.nii.gz");
    free(got);
    s.gzip = 0;

    /* 4D, 2D, bad magic, a .hdr/.img header, another datatype, not NIfTI at all */
    s.dim[0] = 4, s.dim[1] = 6, s.dim[2] = 5, s.dim[3] = 2, s.dim[4] = 2;
    REQUIRE(write_nifti(in_scratch(path, "4d.nii"), IP_UINT16, dims, samples, &s) == 0);
    describe_fails(path, NULL, IP_ERR_UNSUPPORTED, path, "a 4D image (dim[4] = 2)");
    s.dim[0] = 2;
    REQUIRE(write_nifti(in_scratch(path, "2d.nii"), IP_UINT16, dims, samples, &s) == 0);
    describe_fails(path, NULL, IP_ERR_UNSUPPORTED, path, "dim[0] = 2: only 3D");
    s.dim[0] = 0;
    REQUIRE(write_nifti(in_scratch(path, "magic.nii"), IP_UINT16, dims, samples, &s) == 0);
    patch(path, 344, "n+9", 4);
    describe_fails(path, NULL, IP_ERR_INPUT, path, "bad NIfTI-1 magic");
    patch(path, 344, "ni1", 4);
    describe_fails(path, NULL, IP_ERR_UNSUPPORTED, path, ".hdr/.img pair");
    s.version = 2;
    REQUIRE(write_nifti(in_scratch(path, "magic2.nii"), IP_UINT16, dims, samples, &s) == 0);
    patch(path, 4, "n+1", 4);
    describe_fails(path, NULL, IP_ERR_INPUT, path, "bad NIfTI-2 magic");
    s.datatype = 64;
    REQUIRE(write_nifti(in_scratch(path, "double.nii"), IP_UINT16, dims, samples, &s) == 0);
    describe_fails(path, NULL, IP_ERR_UNSUPPORTED, path, "datatype 64 (float64) is not supported");
    s.datatype = 0;
    s.vox_offset = 100;
    REQUIRE(write_nifti(in_scratch(path, "offset.nii"), IP_UINT16, dims, samples, &s) == 0);
    describe_fails(path, NULL, IP_ERR_INPUT, path,
                   "vox_offset 100 is not a byte offset past the 540");
    REQUIRE(write_nifti(in_scratch(path, "zeros.nii"), IP_UINT16, dims, samples, &s) == 0);
    patch(path, 0, "\0\0\0\0", 4);
    describe_fails(path, NULL, IP_ERR_INPUT, path, "not a NIfTI file");
    free(samples);
}

static const test_case cases[] = {
    TEST_CASE(test_round_trips),
    TEST_CASE(test_header_fields),
    TEST_CASE(test_orientation),
    TEST_CASE(test_bad_files),
};

static void make_scratch_dir(void)
{
    snprintf(scratch, sizeof scratch, "%s", test_tmp_dir("test_nifti"));
}

int main(int argc, char **argv)
{
    return RUN_CASES_WITH(argc, argv, cases, "test_nifti", make_scratch_dir, NULL);
}

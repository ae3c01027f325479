/* SPDX-License-Identifier: BSD-3-Clause */
/* Generators and upsampling: determinism, value conventions, structure, and atomic output. */
#include <dirent.h>
#include <math.h>
#include <stdint.h>
#include <sys/stat.h>

#include "check.h"
#include "isoprop/generate.h"
#include "isoprop/input.h"

static const char *tmp;

/* ---- small file helpers (plain stdio) ---- */

static unsigned char *read_file(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *data = malloc(n > 0 ? (size_t)n : 1);
    if (data && fread(data, 1, (size_t)n, f) != (size_t)n) {
        free(data);
        data = NULL;
    }
    fclose(f);
    *size = (size_t)n;
    return data;
}

static void write_file(const char *path, const void *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    REQUIRE(f);
    REQUIRE(fwrite(data, 1, size, f) == size);
    REQUIRE(fclose(f) == 0);
}

static int file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

static int count_entries(const char *dir)
{
    DIR *d = opendir(dir);
    int n = 0;
    if (!d)
        return -1;
    for (struct dirent *e; (e = readdir(d)) != NULL;)
        if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0)
            n++;
    closedir(d);
    return n;
}

static const char *tmp_path(const char *name)
{
    static char paths[8][4096];
    static int next;
    char *p = paths[next++ % 8];
    snprintf(p, sizeof paths[0], "%s/%s", tmp, name);
    return p;
}

/* Sample i of a little-endian file of `type`, as a double. */
static double file_sample(const unsigned char *data, ip_type type, size_t i)
{
    switch (type) {
    case IP_UINT8: return data[i];
    case IP_UINT16: return (uint16_t)(data[2 * i] | data[2 * i + 1] << 8);
    case IP_INT16: return (int16_t)(uint16_t)(data[2 * i] | data[2 * i + 1] << 8);
    case IP_FLOAT32: {
        uint32_t bits = (uint32_t)data[4 * i] | (uint32_t)data[4 * i + 1] << 8 |
                        (uint32_t)data[4 * i + 2] << 16 | (uint32_t)data[4 * i + 3] << 24;
        float f;
        memcpy(&f, &bits, sizeof f);
        return f;
    }
    }
    return 0.0;
}

static void store_le(unsigned char *dst, ip_type type, size_t i, double v)
{
    if (type == IP_FLOAT32) {
        float f = (float)v;
        uint32_t bits;
        memcpy(&bits, &f, sizeof bits);
        for (int k = 0; k < 4; k++)
            dst[4 * i + k] = (unsigned char)(bits >> (8 * k));
    } else if (type == IP_UINT8) {
        dst[i] = (unsigned char)v;
    } else {
        uint16_t u = (uint16_t)(int32_t)v;
        dst[2 * i] = (unsigned char)u;
        dst[2 * i + 1] = (unsigned char)(u >> 8);
    }
}

static ip_gen_params params_of(ip_field field, uint32_t nx, uint32_t ny, uint32_t nz, ip_type type)
{
    ip_gen_params p = {sizeof(ip_gen_params), field, {nx, ny, nz}, type, 0.0, 1};
    return p;
}

/* Generates the whole volume through ip_generate_write and reads it back. */
static unsigned char *generate_file(const ip_gen_params *p, const char *name, size_t *size)
{
    ip_error err;
    const char *path = tmp_path(name);
    ip_status st = ip_generate_write(p, path, 1, &err);
    CHECK_MSG(st == IP_OK, "%s", err.message);
    return st == IP_OK ? read_file(path, size) : NULL;
}

static double min_of(const unsigned char *data, ip_type type, size_t n, double *max)
{
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < n; i++) {
        double v = file_sample(data, type, i);
        lo = v < lo ? v : lo;
        hi = v > hi ? v : hi;
    }
    *max = hi;
    return lo;
}

/* ---- generators ---- */

static void test_names(void)
{
    ip_field f;
    char buf[64];
    uint32_t dims[3] = {512, 512, 234};
    for (int i = 0; i < 4; i++) {
        CHECK_EQ(ip_field_parse(ip_field_name((ip_field)i), &f), IP_OK);
        CHECK_EQ(f, (ip_field)i);
    }
    CHECK_STR_EQ(ip_field_name(IP_FIELD_MARSCHNER_LOBB), "marschner-lobb");
    CHECK_EQ(ip_field_parse("Shepp-Logan", &f), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_field_parse("cube", &f), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_raw_file_name(buf, sizeof buf, "ct_head", dims, IP_UINT16), IP_OK);
    CHECK_STR_EQ(buf, "ct_head_512x512x234_uint16.raw");
    CHECK_EQ(ip_raw_file_name(buf, 20, "ct_head", dims, IP_UINT16), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_raw_file_name(buf, sizeof buf, "x", dims, (ip_type)9), IP_ERR_ARGUMENT);
}

static void test_bad_params(void)
{
    ip_error err;
    uint16_t plane[16];
    ip_gen_params p = params_of(IP_FIELD_SPHERE, 4, 4, 4, IP_UINT16);
    CHECK_EQ(ip_generate_plane(&p, 4, plane, &err), IP_ERR_ARGUMENT);
    p.dims[1] = 1;
    CHECK_EQ(ip_generate_plane(&p, 0, plane, &err), IP_ERR_ARGUMENT);
    CHECK_CONTAINS(err.message, "at least 2");
    p = params_of((ip_field)7, 4, 4, 4, IP_UINT16);
    CHECK_EQ(ip_generate_plane(&p, 0, plane, &err), IP_ERR_ARGUMENT);
    p = params_of(IP_FIELD_SPHERE, 4, 4, 4, IP_UINT16);
    p.noise = -1.0;
    CHECK_EQ(ip_generate_plane(&p, 0, plane, &err), IP_ERR_ARGUMENT);
    p.noise = NAN;
    CHECK_EQ(ip_generate_plane(&p, 0, plane, &err), IP_ERR_ARGUMENT);
}

/* Same parameters give the same bytes, and a plane generated alone equals its place in the
 * file (the file is written in groups of planes, possibly by several threads). */
static void test_determinism(void)
{
    ip_gen_params p = params_of(IP_FIELD_SHEPP_LOGAN, 37, 29, 23, IP_UINT16);
    p.noise = 0.02;
    p.seed = 42;
    size_t n1 = 0, n2 = 0;
    unsigned char *a = generate_file(&p, "det_a.raw", &n1);
    unsigned char *b = generate_file(&p, "det_b.raw", &n2);
    REQUIRE(a && b);
    CHECK_EQ(n1, 37u * 29 * 23 * 2);
    if (CHECK_EQ(n1, n2))
        CHECK_MEM_EQ(a, b, n1);
    uint16_t plane[37 * 29];
    ip_error err;
    for (uint32_t z = 0; z < 23; z += 11) {
        CHECK_EQ(ip_generate_plane(&p, z, plane, &err), IP_OK);
        int same = 1;
        for (size_t i = 0; i < 37 * 29; i++)
            same &= plane[i] == file_sample(a, IP_UINT16, z * 37 * 29 + i);
        CHECK_MSG(same, "plane %u differs from the whole-volume file", z);
    }
    free(a);
    free(b);
}

/* The [0,1] field maps to 0..255, 0..4095, -1024..3071 and 0..1; the phantom reaches both ends. */
static void test_type_ranges(void)
{
    static const struct {
        ip_type type;
        double lo, hi;
    } cases[] = {
        {IP_UINT8, 0, 255}, {IP_UINT16, 0, 4095}, {IP_INT16, -1024, 3071}, {IP_FLOAT32, 0, 1}};
    for (size_t c = 0; c < 4; c++) {
        ip_gen_params p = params_of(IP_FIELD_SHEPP_LOGAN, 41, 41, 41, cases[c].type);
        size_t size = 0;
        double hi;
        unsigned char *data = generate_file(&p, "range.raw", &size);
        REQUIRE(data);
        CHECK_EQ(size, 41u * 41 * 41 * ip_type_size(cases[c].type));
        double lo = min_of(data, cases[c].type, 41u * 41 * 41, &hi);
        CHECK_MSG(lo == cases[c].lo && hi == cases[c].hi, "%s: %g..%g", ip_type_name(cases[c].type),
                  lo, hi);
        free(data);
    }
    for (int f = 1; f < 4; f++) {
        ip_gen_params p = params_of((ip_field)f, 24, 20, 16, IP_FLOAT32);
        size_t size = 0;
        double hi;
        unsigned char *data = generate_file(&p, "range_field.raw", &size);
        REQUIRE(data);
        double lo = min_of(data, IP_FLOAT32, 24u * 20 * 16, &hi);
        CHECK_MSG(lo >= 0.0 && hi <= 1.0 && hi - lo > 0.5, "%s: %g..%g", ip_field_name((ip_field)f),
                  lo, hi);
        free(data);
    }
}

static double plane_sample(const ip_gen_params *p, uint32_t x, uint32_t y, uint32_t z)
{
    size_t n = (size_t)p->dims[0] * p->dims[1];
    float *plane = malloc(n * sizeof *plane);
    ip_error err;
    REQUIRE(plane);
    ip_gen_params q = *p;
    q.type = IP_FLOAT32;
    REQUIRE(ip_generate_plane(&q, z, plane, &err) == IP_OK);
    double v = plane[(size_t)y * p->dims[0] + x];
    free(plane);
    return v;
}

static void test_sphere(void)
{
    ip_gen_params p = params_of(IP_FIELD_SPHERE, 33, 33, 33, IP_UINT8);
    size_t size = 0;
    double hi;
    unsigned char *data = generate_file(&p, "sphere.raw", &size);
    REQUIRE(data);
    size_t centre = 16 + 33 * (16 + 33 * 16);
    min_of(data, IP_UINT8, 33u * 33 * 33, &hi);
    CHECK_EQ(data[centre], 255);
    CHECK_EQ(hi, 255);
    CHECK_EQ(data[0], 0);
    CHECK_EQ(data[size - 1], 0);
    /* Linear fall-off: half way to the face centre, the value is one half. */
    CHECK_NEAR(plane_sample(&p, 24, 16, 16), 0.5, 1e-9);
    CHECK_EQ(data[32 + 33 * (16 + 33 * 16)], 0);
    free(data);
}

static void test_shepp_logan_structure(void)
{
    ip_gen_params p = params_of(IP_FIELD_SHEPP_LOGAN, 65, 65, 65, IP_FLOAT32);
    /* Outside the head, the corners and the middle of a face: 0. */
    CHECK_EQ(plane_sample(&p, 0, 0, 0), 0.0);
    CHECK_EQ(plane_sample(&p, 0, 32, 32), 0.0);
    /* The centre is brain: skull 1.0 minus 0.8. */
    CHECK_NEAR(plane_sample(&p, 32, 32, 32), 0.2, 1e-6);
    /* y = 0.906: inside the skull (b = 0.92), outside the brain (b = 0.874). */
    CHECK_EQ(plane_sample(&p, 32, 61, 32), 1.0);
    /* The left ventricle (centre x = -0.22, z = -0.25) is darker than the brain around it. */
    CHECK_LT(plane_sample(&p, 25, 32, 24), 0.05);
}

static void test_noise(void)
{
    ip_gen_params p = params_of(IP_FIELD_SPHERE, 40, 40, 40, IP_FLOAT32);
    size_t n0 = 0, n1 = 0, n2 = 0, n3 = 0;
    unsigned char *clean = generate_file(&p, "clean.raw", &n0);
    p.noise = 0.05;
    p.seed = 7;
    unsigned char *noisy = generate_file(&p, "noisy.raw", &n1);
    unsigned char *again = generate_file(&p, "noisy_again.raw", &n2);
    p.seed = 8;
    unsigned char *other = generate_file(&p, "noisy_other.raw", &n3);
    REQUIRE(clean && noisy && again && other);
    if (CHECK_EQ(n1, n0))
        CHECK_MEM_EQ(noisy, again, n1);
    CHECK_NE(memcmp(noisy, clean, n1), 0);
    CHECK_NE(memcmp(noisy, other, n1), 0);
    /* Where clamping cannot act, the added noise has mean 0 and standard deviation 0.05. */
    double sum = 0, sum2 = 0;
    size_t count = 0, changed = 0, samples = 40u * 40 * 40;
    for (size_t i = 0; i < samples; i++) {
        double c = file_sample(clean, IP_FLOAT32, i), d = file_sample(noisy, IP_FLOAT32, i) - c;
        changed += file_sample(noisy, IP_FLOAT32, i) != file_sample(other, IP_FLOAT32, i);
        if (c > 0.3 && c < 0.7) {
            sum += d;
            sum2 += d * d;
            count++;
        }
    }
    double mean = sum / (double)count, sd = sqrt(sum2 / (double)count - mean * mean);
    CHECK_MSG(count > 1000 && fabs(mean) < 0.005 && fabs(sd - 0.05) < 0.005,
              "count %zu mean %g sd %g", count, mean, sd);
    CHECK_GT(changed, samples / 2);
    free(clean);
    free(noisy);
    free(again);
    free(other);
}

static void test_existing_and_missing_folder(void)
{
    ip_error err;
    ip_gen_params p = params_of(IP_FIELD_GYROID, 8, 8, 8, IP_UINT8);
    const char *path = tmp_path("keep.raw");
    size_t size = 0;
    write_file(path, "keep", 4);
    CHECK_EQ(ip_generate_write(&p, path, 0, &err), IP_ERR_EXISTS);
    CHECK_CONTAINS(err.message, path);
    unsigned char *data = read_file(path, &size);
    if (CHECK_NE(data, NULL) && CHECK_EQ(size, 4))
        CHECK_MEM_EQ(data, "keep", 4);
    free(data);
    CHECK_EQ(ip_generate_write(&p, path, 1, &err), IP_OK);
    data = read_file(path, &size);
    CHECK_NE(data, NULL);
    CHECK_EQ(size, 512);
    free(data);

    const char *missing = tmp_path("no_such_folder/out.raw");
    CHECK_EQ(ip_generate_write(&p, missing, 0, &err), IP_ERR_IO);
    CHECK_CONTAINS(err.message, missing);
    CHECK(!file_exists(tmp_path("no_such_folder")));
}

/* ---- upsampling ---- */

/* Writes NAME_XxYxZ_TYPE.raw with sample values value(x, y, z) and describes it. */
static void write_input(const char *name, const uint32_t dims[3], ip_type type,
                        double (*value)(uint32_t, uint32_t, uint32_t), ip_input_desc *desc)
{
    char file[256];
    ip_error err;
    size_t n = (size_t)dims[0] * dims[1] * dims[2];
    unsigned char *data = malloc(n * ip_type_size(type));
    REQUIRE(data);
    for (uint32_t z = 0, i = 0; z < dims[2]; z++)
        for (uint32_t y = 0; y < dims[1]; y++)
            for (uint32_t x = 0; x < dims[0]; x++, i++)
                store_le(data, type, i, value(x, y, z));
    REQUIRE(ip_raw_file_name(file, sizeof file, name, dims, type) == IP_OK);
    write_file(tmp_path(file), data, n * ip_type_size(type));
    free(data);
    ip_status st = ip_input_describe(tmp_path(file), NULL, desc, &err);
    CHECK_MSG(st == IP_OK, "%s", err.message);
    REQUIRE(st == IP_OK);
}

static double ramp(uint32_t x, uint32_t y, uint32_t z)
{
    return x + 2.0 * y + 3.0 * z;
}

static double step3(uint32_t x, uint32_t y, uint32_t z)
{
    (void)y;
    (void)z;
    return x ? 3.0 : 0.0;
}

static double step3_negative(uint32_t x, uint32_t y, uint32_t z)
{
    return step3(x, y, z) - 3.0;
}

static unsigned char *upsample(const ip_input_desc *in, uint32_t factor, const char *name,
                               size_t *size)
{
    ip_error err;
    const char *path = tmp_path(name);
    ip_status st = ip_upsample_write(in, factor, path, 1, &err);
    CHECK_MSG(st == IP_OK, "%s", err.message);
    return st == IP_OK ? read_file(path, size) : NULL;
}

/* A linear function stays linear: output sample i is the input at i * (n - 1) / (2n - 1). */
static void test_upsample_linear(void)
{
    const uint32_t dims[3] = {5, 4, 3};
    ip_input_desc in;
    size_t size = 0;
    write_input("ramp", dims, IP_FLOAT32, ramp, &in);
    unsigned char *out = upsample(&in, 2, "ramp_x2.raw", &size);
    REQUIRE(out);
    CHECK_EQ(size, 10u * 8 * 6 * 4);
    double worst = 0;
    for (uint32_t z = 0, i = 0; z < 6; z++)
        for (uint32_t y = 0; y < 8; y++)
            for (uint32_t x = 0; x < 10; x++, i++) {
                double expect = x * 4.0 / 9.0 + 2.0 * y * 3.0 / 7.0 + 3.0 * z * 2.0 / 5.0;
                double e = fabs(file_sample(out, IP_FLOAT32, i) - expect);
                worst = e > worst ? e : worst;
            }
    CHECK_MSG(worst < 1e-5, "worst error %g", worst);
    /* The eight corners are the input's corners, exactly. */
    CHECK_EQ(file_sample(out, IP_FLOAT32, 0), 0.0);
    CHECK_EQ(file_sample(out, IP_FLOAT32, 9), 4.0);
    CHECK_EQ(file_sample(out, IP_FLOAT32, 9 + 10 * 7), 10.0);
    CHECK_EQ(file_sample(out, IP_FLOAT32, 10u * 8 * 6 - 1), 16.0);
    CHECK_EQ(file_sample(out, IP_FLOAT32, 10u * 8 * 5), 6.0);
    free(out);
}

static void test_upsample_identity(void)
{
    const uint32_t dims[3] = {7, 3, 4};
    const ip_type types[2] = {IP_FLOAT32, IP_INT16};
    for (int t = 0; t < 2; t++) {
        ip_input_desc in;
        size_t size = 0, in_size = 0;
        write_input(t ? "ident16" : "ident", dims, types[t], ramp, &in);
        unsigned char *out = upsample(&in, 1, "ident_x1.raw", &size);
        unsigned char *orig = read_file(in.path, &in_size);
        REQUIRE(out && orig);
        if (CHECK_EQ(size, in_size))
            CHECK_MEM_EQ(out, orig, size);
        free(out);
        free(orig);
    }
}

/* Integer types round to nearest: 0 -> 3 over five steps is 0, 0.6, 1.2, 1.8, 2.4, 3. */
static void test_upsample_rounding(void)
{
    const uint32_t dims[3] = {2, 2, 2};
    static const double unsigned_expect[6] = {0, 1, 1, 2, 2, 3};
    static const double signed_expect[6] = {-3, -2, -2, -1, -1, 0};
    ip_input_desc in;
    size_t size = 0;
    write_input("step", dims, IP_UINT16, step3, &in);
    unsigned char *out = upsample(&in, 3, "step_x3.raw", &size);
    REQUIRE(out);
    CHECK_EQ(size, 6u * 6 * 6 * 2);
    for (size_t row = 0; row < 36; row++)
        for (size_t x = 0; x < 6; x++)
            CHECK_EQ(file_sample(out, IP_UINT16, row * 6 + x), unsigned_expect[x]);
    free(out);
    write_input("step_signed", dims, IP_INT16, step3_negative, &in);
    out = upsample(&in, 3, "step_signed_x3.raw", &size);
    REQUIRE(out);
    for (size_t x = 0; x < 6; x++)
        CHECK_EQ(file_sample(out, IP_INT16, 6 * 35 + x), signed_expect[x]);
    free(out);
}

static void test_upsample_errors(void)
{
    const uint32_t dims[3] = {3, 3, 3};
    ip_input_desc in;
    ip_error err;
    size_t size = 0;
    write_input("small", dims, IP_UINT8, ramp, &in);
    const char *path = tmp_path("small_keep.raw");
    write_file(path, "keep", 4);
    CHECK_EQ(ip_upsample_write(&in, 2, path, 0, &err), IP_ERR_EXISTS);
    unsigned char *data = read_file(path, &size);
    if (CHECK_NE(data, NULL) && CHECK_EQ(size, 4))
        CHECK_MEM_EQ(data, "keep", 4);
    free(data);
    CHECK_EQ(ip_upsample_write(&in, 0, tmp_path("zero.raw"), 0, &err), IP_ERR_ARGUMENT);
    CHECK(!file_exists(tmp_path("zero.raw")));
    const char *missing = tmp_path("missing_folder/up.raw");
    CHECK_EQ(ip_upsample_write(&in, 2, missing, 0, &err), IP_ERR_IO);
    CHECK_CONTAINS(err.message, missing);
    /* An input shorter than its description fails while reading; no output remains. */
    ip_input_desc truncated = in;
    write_file(tmp_path("short.bin"), "\1\2\3", 3);
    snprintf(truncated.data_path, sizeof truncated.data_path, "%s", tmp_path("short.bin"));
    CHECK_NE(ip_upsample_write(&truncated, 2, tmp_path("from_short.raw"), 0, &err), IP_OK);
    CHECK_NE(err.message[0], '\0');
    CHECK(!file_exists(tmp_path("from_short.raw")));
}

/* Runs an upsampling case and checks that the folder holds only the inputs and outputs it names,
 * `files` of them more than before: no temporary file remains. */
static void without_temporaries(void (*test)(void), int files)
{
    int before = count_entries(tmp);
    test();
    CHECK_MSG(count_entries(tmp) == before + files, "%d entries, expected %d", count_entries(tmp),
              before + files);
}
static void upsample_linear(void)
{
    without_temporaries(test_upsample_linear, 2); /* ramp, ramp_x2 */
}
static void upsample_identity(void)
{
    without_temporaries(test_upsample_identity, 3); /* ident, ident16, ident_x1 */
}
static void upsample_rounding(void)
{
    without_temporaries(test_upsample_rounding, 4); /* step, step_signed and their x3 */
}
static void upsample_errors(void)
{
    without_temporaries(test_upsample_errors, 3); /* small, small_keep, short */
}

static const test_case cases[] = {
    TEST_CASE(test_names),
    TEST_CASE(test_bad_params),
    TEST_CASE(test_determinism),
    TEST_CASE(test_type_ranges),
    TEST_CASE(test_sphere),
    TEST_CASE(test_shepp_logan_structure),
    TEST_CASE(test_noise),
    TEST_CASE(test_existing_and_missing_folder),
    {"test_upsample_linear", upsample_linear},
    {"test_upsample_identity", upsample_identity},
    {"test_upsample_rounding", upsample_rounding},
    {"test_upsample_errors", upsample_errors},
};

static void make_scratch_dir(void)
{
    tmp = test_tmp_dir("test_generate");
}

int main(int argc, char **argv)
{
    return RUN_CASES_WITH(argc, argv, cases, "test_generate", make_scratch_dir, NULL);
}

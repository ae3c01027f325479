/* SPDX-License-Identifier: BSD-3-Clause */
/* The codec's fast decoding paths (the fused unshuffle + zigzag + running sum, in SSE2 or in
 * its portable form) against a reference decoder written plainly from docs/format.md
 * "Filters": one sample at a time, no buffers shared between steps. This file is built twice:
 * as test_codec_fast against the library, and as test_codec_fast_portable with its own copy
 * of src/brickfile/codec.c built with IP_CODEC_PORTABLE (the scalar fallback).
 *
 * Two sources of payloads: random byte streams taken as the filters' output (every bit
 * pattern: large residuals, wrap-around, the sign bit), over extents that leave every
 * remainder of the vector loops; and blocks of the real volumes in ../shared/data (skipped
 * when absent), at the volume's edge too, filtered by a reference encoder with each filter
 * set and encoded by ip__codec_encode() at the fast and the LZ4HC level. */
#include <lz4.h>
#include <stdint.h>

#include "check.h"
#include "codec.h"
#include "internal.h"

static uint64_t rng_state = 0x2545F4914F6CDD1Dull;

static uint32_t next_random(void)
{
    return (uint32_t)(test_xorshift(&rng_state) >> 16);
}

static const unsigned filter_sets[] = {0,
                                       IP_FILTER_DELTA,
                                       IP_FILTER_SHUFFLE,
                                       IP_FILTER_DELTA | IP_FILTER_SHUFFLE,
                                       IP_FILTER_MED,
                                       IP_FILTER_MED | IP_FILTER_SHUFFLE};
#define FILTER_SET_COUNT (sizeof filter_sets / sizeof filter_sets[0])

/* ---- the reference: one sample at a time, straight from the specification ---- */

/* Sample i of host-order samples of w bytes, as an integer. */
static uint64_t get_sample(const void *s, size_t w, size_t i)
{
    const unsigned char *p = (const unsigned char *)s + i * w;
    switch (w) {
    case 1: return p[0];
    case 2: {
        uint16_t v;
        memcpy(&v, p, 2);
        return v;
    }
    default: {
        uint32_t v;
        memcpy(&v, p, 4);
        return v;
    }
    }
}

static void set_sample(void *s, size_t w, size_t i, uint64_t v)
{
    unsigned char *p = (unsigned char *)s + i * w;
    if (w == 1) {
        p[0] = (unsigned char)v;
    } else if (w == 2) {
        uint16_t x = (uint16_t)v;
        memcpy(p, &x, 2);
    } else {
        uint32_t x = (uint32_t)v;
        memcpy(p, &x, 4);
    }
}

/* The median edge predictor's guess for sample i at (x, y) of a z slice `v` (decoded or
 * original samples) whose rows hold `row` samples. */
static uint64_t med_predict(const void *v, size_t w, size_t i, uint32_t x, uint32_t y, uint32_t row)
{
    int64_t a = x > 0 ? (int64_t)get_sample(v, w, i - 1) : 0;
    int64_t b = y > 0 ? (int64_t)get_sample(v, w, i - row) : 0;
    if (x == 0 || y == 0)
        return (uint64_t)(x > 0 ? a : b);
    int64_t c = (int64_t)get_sample(v, w, i - row - 1);
    int64_t lo = a < b ? a : b, hi = a < b ? b : a;
    return (uint64_t)(c >= hi ? lo : c <= lo ? hi : a + b - c);
}

/* The prediction of sample i at (x, y, z) from the samples before it in `v`. */
static uint64_t prediction(const void *v, size_t w, size_t i, uint32_t x, uint32_t y, uint32_t z,
                           const uint32_t e[3], unsigned filters)
{
    if (filters & IP_FILTER_DELTA)
        return i > 0 ? get_sample(v, w, i - 1) : 0;
    size_t slice = (size_t)e[0] * e[1];
    return med_predict((const unsigned char *)v + z * slice * w, w, i - z * slice, x, y, e[0]);
}

/* Byte b of stored value i in the filtered stream of n values of w bytes. */
static size_t stream_index(size_t i, size_t b, size_t n, size_t w, unsigned filters)
{
    return filters & IP_FILTER_SHUFFLE ? b * n + i : i * w + b;
}

/* The filtered stream (what LZ4 compresses) of host-order samples. */
static void reference_filter(const void *samples, const uint32_t e[3], size_t w, unsigned filters,
                             unsigned char *stream)
{
    size_t n = (size_t)e[0] * e[1] * e[2], i = 0;
    uint64_t mask = (w == 4 ? 0xFFFFFFFFull : (1ull << (8 * w)) - 1);
    for (uint32_t z = 0; z < e[2]; z++)
        for (uint32_t y = 0; y < e[1]; y++)
            for (uint32_t x = 0; x < e[0]; x++, i++) {
                uint64_t v = get_sample(samples, w, i);
                if (filters & (IP_FILTER_DELTA | IP_FILTER_MED)) {
                    uint64_t p = prediction(samples, w, i, x, y, z, e, filters);
                    uint64_t r = (v - p) & mask;
                    v = ((r << 1) ^ (0 - (r >> (8 * w - 1)))) & mask;
                }
                for (size_t b = 0; b < w; b++)
                    stream[stream_index(i, b, n, w, filters)] = (unsigned char)(v >> (8 * b));
            }
}

/* Host-order samples from the filtered stream: the inverse of reference_filter(). */
static void reference_unfilter(const unsigned char *stream, const uint32_t e[3], size_t w,
                               unsigned filters, void *samples)
{
    size_t n = (size_t)e[0] * e[1] * e[2], i = 0;
    uint64_t mask = (w == 4 ? 0xFFFFFFFFull : (1ull << (8 * w)) - 1);
    for (uint32_t z = 0; z < e[2]; z++)
        for (uint32_t y = 0; y < e[1]; y++)
            for (uint32_t x = 0; x < e[0]; x++, i++) {
                uint64_t v = 0;
                for (size_t b = 0; b < w; b++)
                    v |= (uint64_t)stream[stream_index(i, b, n, w, filters)] << (8 * b);
                if (filters & (IP_FILTER_DELTA | IP_FILTER_MED)) {
                    uint64_t r = (v >> 1) ^ (0 - (v & 1));
                    uint64_t p = prediction(samples, w, i, x, y, z, e, filters);
                    v = (p + r) & mask;
                }
                set_sample(samples, w, i, v);
            }
}

/* ---- the codec against it ---- */

/* LZ4-compresses `stream` as the payload of a brick with `filters` and decodes it with
 * ip__codec_decode(); checks the samples against `expected` (host order). */
static void check_decode(const unsigned char *stream, const uint32_t e[3], ip_type type,
                         unsigned filters, const void *expected, const char *what)
{
    size_t w = ip_type_size(type), n = (size_t)e[0] * e[1] * e[2], raw = n * w;
    int cap = LZ4_compressBound((int)raw);
    unsigned char *payload = malloc((size_t)cap), *dst = malloc(raw + 64);
    unsigned char *work = malloc(ip__codec_work_size(n, type));
    REQUIRE(payload && dst && work);
    int size = LZ4_compress_default((const char *)stream, (char *)payload, (int)raw, cap);
    REQUIRE(size > 0);
    memset(dst + raw, 0xA5, 64);
    ip_brick_entry entry = {0, (uint32_t)size, IP_BRICK_LZ4, (uint8_t)filters, 0};
    ip_status st = ip__codec_decode(&entry, payload, e, type, 0, dst, work);
    CHECK_MSG(st == IP_OK, "%s: status %d", what, (int)st);
    size_t first = raw;
    for (size_t i = 0; i < raw && first == raw; i++)
        if (dst[i] != ((const unsigned char *)expected)[i])
            first = i;
    CHECK_MSG(first == raw, "%s: first differing byte %zu of %zu", what, first, raw);
    int guard = 1;
    for (size_t i = 0; i < 64; i++)
        guard &= dst[raw + i] == 0xA5;
    CHECK_MSG(guard, "%s: wrote past the samples", what);
    free(payload);
    free(dst);
    free(work);
}

/* Random filtered streams, three kinds of byte, decoded by the codec and by the reference. */
static void test_random_streams(void)
{
    static const uint32_t shapes[][3] = {{33, 33, 33}, {33, 33, 11}, {32, 33, 33}, {33, 17, 2},
                                         {2, 2, 2},    {3, 5, 7},    {9, 9, 9},    {17, 2, 31}};
    int cases = 0;
    for (int t = 0; t < IP_TYPE_COUNT; t++)
        for (size_t f = 0; f < FILTER_SET_COUNT; f++)
            for (uint32_t k = 0; k < 70 + sizeof shapes / sizeof shapes[0]; k++) {
                /* every count 1 .. 70 along x, then brick shapes */
                uint32_t e[3] = {k + 1, 1, 1};
                if (k >= 70)
                    memcpy(e, shapes[k - 70], sizeof e);
                ip_type type = (ip_type)t;
                size_t w = ip_type_size(type), raw = (size_t)e[0] * e[1] * e[2] * w;
                unsigned char *stream = malloc(raw), *expected = malloc(raw);
                REQUIRE(stream && expected);
                int kind = (int)(k % 3); /* uniform bytes; small residuals; the extremes */
                for (size_t i = 0; i < raw; i++) {
                    uint32_t r = next_random();
                    stream[i] = kind == 0   ? (unsigned char)r
                                : kind == 1 ? (unsigned char)(r % 7 == 0 ? r >> 8 : r % 4)
                                            : (unsigned char)((r & 1) ? 0xFF : 0xFE + (r >> 1) % 3);
                }
                reference_unfilter(stream, e, w, filter_sets[f], expected);
                char what[128];
                snprintf(what, sizeof what, "random: type %d, %ux%ux%u, filters %u, kind %d", t,
                         e[0], e[1], e[2], filter_sets[f], kind);
                check_decode(stream, e, type, filter_sets[f], expected, what);
                cases++;
                free(stream);
                free(expected);
            }
    printf("codec fast paths: %d random streams\n", cases);
}

/* A raw volume in the shared data folder. */
typedef struct volume {
    const char *file;
    uint32_t dims[3];
    ip_type type; /* as stored */
} volume;

/* Reads the block of extent e at `origin` of the volume into host-order samples of `as`
 * (int16: the uint16 volume less 1024, CT values in Hounsfield units). 0 when read. */
static int read_block(const char *folder, const volume *v, const uint32_t origin[3],
                      const uint32_t e[3], ip_type as, void *out)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", folder, v->file);
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    size_t w = ip_type_size(v->type), row = (size_t)e[0] * w, i = 0;
    unsigned char *buf = malloc(row);
    REQUIRE(buf != NULL);
    int ok = 1;
    for (uint32_t z = 0; z < e[2] && ok; z++)
        for (uint32_t y = 0; y < e[1] && ok; y++) {
            long offset =
                (long)(((((size_t)origin[2] + z) * v->dims[1] + origin[1] + y) * v->dims[0] +
                        origin[0]) *
                       w);
            ok = fseek(f, offset, SEEK_SET) == 0 && fread(buf, 1, row, f) == row;
            for (uint32_t x = 0; ok && x < e[0]; x++, i++) {
                uint64_t s = 0;
                for (size_t b = 0; b < w; b++) /* the files are little-endian */
                    s |= (uint64_t)buf[x * w + b] << (8 * b);
                if (as == IP_INT16)
                    s = (uint64_t)(int16_t)((int64_t)s - 1024);
                set_sample(out, ip_type_size(as), i, s);
            }
        }
    free(buf);
    fclose(f);
    return ok ? 0 : -1;
}

/* One real block: every filter set through the reference encoder, then the codec's own
 * encoder at the fast and an LZ4HC level; each must decode to the block. */
static void check_real_block(const void *samples, const uint32_t e[3], ip_type type,
                             const char *name)
{
    size_t w = ip_type_size(type), n = (size_t)e[0] * e[1] * e[2], raw = n * w;
    unsigned char *stream = malloc(raw), *back = malloc(raw);
    REQUIRE(stream && back);
    char what[320];
    for (size_t f = 0; f < FILTER_SET_COUNT; f++) {
        reference_filter(samples, e, w, filter_sets[f], stream);
        reference_unfilter(stream, e, w, filter_sets[f], back);
        snprintf(what, sizeof what, "%s, filters %u", name, filter_sets[f]);
        CHECK_MSG(memcmp(back, samples, raw) == 0, "%s: the reference does not invert", what);
        check_decode(stream, e, type, filter_sets[f], samples, what);
    }
    static const int levels[] = {IP_LZ4_FAST, 9};
    unsigned char *out = malloc(ip__codec_bound(n, type)),
                  *work = malloc(ip__codec_work_size(n, type));
    REQUIRE(out && work);
    for (size_t l = 0; l < 2; l++) {
        ip_brick_entry entry;
        REQUIRE(ip__codec_encode(samples, e, type, levels[l], out, work, &entry) == IP_OK);
        snprintf(what, sizeof what, "%s, level %d, encoding %u, filters %u", name, levels[l],
                 entry.encoding, entry.filters);
        CHECK_MSG(ip__codec_decode(&entry, out, e, type, 0, back, work) == IP_OK, "%s", what);
        CHECK_MSG(entry.encoding == IP_BRICK_CONSTANT || memcmp(back, samples, raw) == 0,
                  "%s: decoded samples differ", what);
    }
    free(out);
    free(work);
    free(stream);
    free(back);
}

/* Blocks of the real volumes: inside, and at the far corner where bricks are smaller. */
static void test_real_volumes(void)
{
    const char *folder = getenv("IP_SKIP_SHARED_DATA") ? NULL : getenv("IP_SHARED_DATA");
    static const volume volumes[] = {
        {"ct_head_visible_woman_512x512x234_uint16.raw", {512, 512, 234}, IP_UINT16},
        {"bonsai_256x256x256_uint8.raw", {256, 256, 256}, IP_UINT8},
        {"tooth_103x94x161_uint8.raw", {103, 94, 161}, IP_UINT8},
        {"hydrogen_density_64x64x64_float32.raw", {64, 64, 64}, IP_FLOAT32}};
    int blocks = 0;
    for (size_t k = 0; folder && k < sizeof volumes / sizeof volumes[0]; k++) {
        const volume *v = &volumes[k];
        for (int as = 0; as < (v->type == IP_UINT16 ? 2 : 1); as++)
            for (int corner = 0; corner < 2; corner++) {
                ip_type type = as ? IP_INT16 : v->type;
                uint32_t origin[3], e[3];
                for (int a = 0; a < 3; a++) { /* bricks of 32 cells: the middle, the last */
                    uint32_t last = (v->dims[a] - 2) / 32 * 32;
                    origin[a] = corner ? last : (v->dims[a] / 2) / 32 * 32;
                    e[a] = v->dims[a] - origin[a] < 33 ? v->dims[a] - origin[a] : 33;
                }
                void *samples = malloc((size_t)e[0] * e[1] * e[2] * ip_type_size(type));
                REQUIRE(samples != NULL);
                if (read_block(folder, v, origin, e, type, samples) == 0) {
                    char name[160];
                    snprintf(name, sizeof name, "%s as %s, %ux%ux%u at %u,%u,%u", v->file,
                             ip_type_name(type), e[0], e[1], e[2], origin[0], origin[1], origin[2]);
                    check_real_block(samples, e, type, name);
                    blocks++;
                }
                free(samples);
            }
    }
    if (blocks == 0)
        printf("codec fast paths: no real volumes (IP_SHARED_DATA unset or empty): skipped\n");
    else
        printf("codec fast paths: %d blocks of real volumes\n", blocks);
}

static const test_case cases[] = {
    TEST_CASE(test_random_streams),
    TEST_CASE(test_real_volumes),
};

int main(int argc, char **argv)
{
    return RUN_CASES(argc, argv, cases, "test_codec_fast");
}

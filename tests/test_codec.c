/* SPDX-License-Identifier: BSD-3-Clause */
/* The brick codec (src/brickfile/codec.c) on its own: encode/decode round trips of every
 * sample type at both compression paths (LZ4 and LZ4HC) over odd extents, constant bricks, the
 * raw fallback, the decoder against a reference encoder written from docs/format.md for every
 * valid filter combination, and malformed payloads, which must give IP_ERR_CORRUPT and never
 * touch memory outside the buffers (each output buffer is followed by guard bytes checked after
 * every call; under AddressSanitizer the buffers have exactly their size). */
#include <lz4.h>
#include <math.h>
#include <stdint.h>

#include "check.h"
#include "codec.h"
#include "internal.h"

#define GUARD 64
#define GUARD_BYTE 0xA5

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;

static uint32_t next_random(void)
{
    return (uint32_t)(test_xorshift(&rng_state) >> 16);
}

/* A buffer of `size` bytes followed by GUARD guard bytes. */
static unsigned char *guarded(size_t size)
{
    unsigned char *p = malloc(size + GUARD);
    REQUIRE(p != NULL);
    memset(p, 0x3C, size);
    memset(p + size, GUARD_BYTE, GUARD);
    return p;
}

static int guard_intact(const unsigned char *p, size_t size)
{
    for (size_t i = 0; i < GUARD; i++)
        if (p[size + i] != GUARD_BYTE)
            return 0;
    return 1;
}

enum pattern {
    SMOOTH,
    PLANE,
    NOISE,
    CONSTANT,
    STEPS,
    PATTERN_COUNT
};
static const char *const pattern_names[] = {"smooth", "plane", "noise", "constant", "steps"};

/* Fills `count` samples of `type` laid out over extent e. */
static void fill(void *dst, ip_type type, const uint32_t e[3], enum pattern p)
{
    size_t i = 0;
    for (uint32_t z = 0; z < e[2]; z++)
        for (uint32_t y = 0; y < e[1]; y++)
            for (uint32_t x = 0; x < e[0]; x++, i++) {
                double v;
                switch (p) {
                case SMOOTH: v = 60 + 30 * sin(0.3 * x) + 20 * cos(0.2 * y + 0.1 * z); break;
                case PLANE: v = 3.0 * x + 5.0 * y + 7.0 * z; break;
                case NOISE: v = next_random() % 256; break;
                case CONSTANT: v = 77; break;
                default: v = ((x / 3 + y / 2 + z) % 4) * 60.0; break;
                }
                switch (type) {
                case IP_UINT8: ((uint8_t *)dst)[i] = (uint8_t)(unsigned)v; break; /* mod 256 */
                case IP_UINT16:
                    ((uint16_t *)dst)[i] =
                        (uint16_t)(p == NOISE ? next_random() : (unsigned)(v * 200));
                    break;
                case IP_INT16:
                    ((int16_t *)dst)[i] =
                        (int16_t)(p == NOISE ? (int16_t)next_random() : (int32_t)(v * 100 - 9000));
                    break;
                case IP_FLOAT32:
                    if (p == NOISE) {
                        uint32_t bits = next_random() & 0xBF7FFFFFu; /* finite */
                        memcpy((float *)dst + i, &bits, 4);
                    } else {
                        ((float *)dst)[i] = (float)(v * 0.37 - 11.0);
                    }
                    break;
                }
            }
}

/* {33, 33, 33} and {4, 3, 16}: bricks thick enough for the fast level's trial slices */
static const uint32_t extents[][3] = {{2, 2, 2},   {3, 5, 7},    {9, 9, 9}, {33, 17, 9},
                                      {17, 2, 31}, {33, 33, 33}, {4, 3, 16}};
#define EXTENT_COUNT (sizeof extents / sizeof extents[0])

/* Encodes and decodes one brick; checks the entry and that the samples come back bit for
 * bit. Returns the entry. */
static ip_brick_entry round_trip(const void *samples, const uint32_t e[3], ip_type type, int level,
                                 const char *what)
{
    size_t count = (size_t)e[0] * e[1] * e[2], raw = count * ip_type_size(type);
    size_t bound = ip__codec_bound(count, type), work_size = ip__codec_work_size(count, type);
    CHECK_GE(bound, raw);
    unsigned char *out = guarded(bound), *work = guarded(work_size), *dst = guarded(raw);
    ip_brick_entry entry;
    memset(&entry, 0xEE, sizeof entry);
    CHECK_MSG(ip__codec_encode(samples, e, type, level, out, work, &entry) == IP_OK, "%s", what);
    CHECK_MSG(guard_intact(out, bound) && guard_intact(work, work_size), "%s: encode", what);
    CHECK_EQ(entry.offset, 0);
    CHECK_MSG(entry.encoding <= IP_BRICK_LZ4, "%s: encoding %u", what, entry.encoding);
    if (entry.encoding == IP_BRICK_CONSTANT) {
        CHECK_EQ(entry.stored_size, 0);
        CHECK_EQ(entry.filters, 0);
        CHECK_EQ(entry.checksum, 0);
    } else if (entry.encoding == IP_BRICK_RAW) {
        CHECK_EQ(entry.stored_size, raw);
        CHECK_EQ(entry.filters, 0);
        CHECK_MSG(memcmp(out, samples, raw) == 0, "%s: raw payload", what); /* little-endian */
    } else {
        CHECK_MSG(entry.stored_size > 0 && entry.stored_size < raw, "%s: LZ4 of %u bytes for %zu",
                  what, entry.stored_size, raw);
        CHECK_EQ(entry.filters & ~7u, 0);
        CHECK_NE(entry.filters & 5u, 5u);
        /* shuffle is kept for wide samples, meaningless for bytes */
        CHECK_MSG((entry.filters & IP_FILTER_SHUFFLE) == (ip_type_size(type) > 1 ? 2u : 0u),
                  "%s: filters %u", what, entry.filters);
        if (level == IP_LZ4_FAST)
            CHECK_MSG(!(entry.filters & IP_FILTER_MED), "%s: MED at the fast level", what);
    }
    if (entry.encoding != IP_BRICK_CONSTANT)
        CHECK_MSG(entry.checksum == ip__format_checksum(out, entry.stored_size), "%s", what);
    float constant = 0;
    if (entry.encoding == IP_BRICK_CONSTANT) {
        switch (type) {
        case IP_UINT8: constant = ((const uint8_t *)samples)[0]; break;
        case IP_UINT16: constant = ((const uint16_t *)samples)[0]; break;
        case IP_INT16: constant = ((const int16_t *)samples)[0]; break;
        case IP_FLOAT32: constant = ((const float *)samples)[0]; break;
        }
    }
    CHECK_MSG(ip__codec_decode(&entry, out, e, type, constant, dst, work) == IP_OK, "%s", what);
    CHECK_MSG(memcmp(dst, samples, raw) == 0, "%s: decoded samples differ", what);
    CHECK_MSG(guard_intact(dst, raw) && guard_intact(work, work_size), "%s: decode", what);
    free(out);
    free(work);
    free(dst);
    return entry;
}

static void test_round_trips(void)
{
    static const int levels[] = {IP_LZ4_FAST, 1, 9};
    int seen[4] = {0}; /* encodings, and MED chosen at some LZ4HC level */
    for (int t = 0; t < IP_TYPE_COUNT; t++)
        for (size_t x = 0; x < EXTENT_COUNT; x++)
            for (int p = 0; p < PATTERN_COUNT; p++)
                for (size_t l = 0; l < sizeof levels / sizeof levels[0]; l++) {
                    const uint32_t *e = extents[x];
                    size_t count = (size_t)e[0] * e[1] * e[2];
                    void *samples = malloc(count * ip_type_size((ip_type)t));
                    REQUIRE(samples != NULL);
                    fill(samples, (ip_type)t, e, (enum pattern)p);
                    char what[128];
                    snprintf(what, sizeof what, "type %d, %ux%ux%u, %s, level %d", t, e[0], e[1],
                             e[2], pattern_names[p], levels[l]);
                    ip_brick_entry entry = round_trip(samples, e, (ip_type)t, levels[l], what);
                    seen[entry.encoding]++;
                    if (entry.encoding == IP_BRICK_LZ4 && (entry.filters & IP_FILTER_MED))
                        seen[3]++;
                    if (p == CONSTANT)
                        CHECK_MSG(entry.encoding == IP_BRICK_CONSTANT, "%s", what);
                    if (p == NOISE && t == IP_UINT8 && count >= 27)
                        CHECK_MSG(entry.encoding == IP_BRICK_RAW, "%s: noise is stored raw", what);
                    if ((p == SMOOTH || p == PLANE) && count >= 1000)
                        CHECK_MSG(entry.encoding == IP_BRICK_LZ4, "%s: compressible", what);
                    free(samples);
                }
    CHECK_GT(seen[IP_BRICK_CONSTANT], 0);
    CHECK_GT(seen[IP_BRICK_RAW], 0);
    CHECK_GT(seen[IP_BRICK_LZ4], 0);
    printf("codec: %d constant, %d raw, %d LZ4 (%d with MED)\n", seen[0], seen[1], seen[2],
           seen[3]);
}

/* A constant brick decodes to its value for every type, whatever the payload pointer. */
static void test_constant_fill(void)
{
    const uint32_t e[3] = {5, 3, 4};
    const float values[IP_TYPE_COUNT] = {200, 65535, -32768, -1.5f};
    ip_brick_entry entry = {0, 0, IP_BRICK_CONSTANT, 0, 0};
    for (int t = 0; t < IP_TYPE_COUNT; t++) {
        size_t raw = 60 * ip_type_size((ip_type)t);
        unsigned char *dst = guarded(raw);
        CHECK_EQ(ip__codec_decode(&entry, NULL, e, (ip_type)t, values[t], dst, NULL), IP_OK);
        int same = 1;
        for (size_t i = 0; i < 60; i++) {
            double v = t == IP_UINT8    ? ((uint8_t *)dst)[i]
                       : t == IP_UINT16 ? ((uint16_t *)dst)[i]
                       : t == IP_INT16  ? ((int16_t *)dst)[i]
                                        : ((float *)dst)[i];
            same &= v == values[t];
        }
        CHECK_MSG(same, "type %d: constant fill", t);
        CHECK(guard_intact(dst, raw));
        free(dst);
    }
}

/* ---- the reference encoder, from docs/format.md "Filters" ---- */

static uint64_t sample_bits(const void *s, size_t w, size_t i)
{
    const unsigned char *p = (const unsigned char *)s + i * w;
    uint64_t v = 0;
    for (size_t b = 0; b < w; b++) /* the samples as stored little-endian bytes */
        v |= (uint64_t)p[b] << (8 * b);
    if (!ip__host_little_endian()) {
        uint64_t r = 0;
        for (size_t b = 0; b < w; b++)
            r |= ((v >> (8 * b)) & 0xFF) << (8 * (w - 1 - b));
        v = r;
    }
    return v;
}

/* Encodes samples of w bytes with `filters` per the specification; returns the LZ4 block's
 * size in `payload` (capacity `cap`). */
static int reference_encode(const void *samples, const uint32_t e[3], size_t w, unsigned filters,
                            unsigned char *payload, int cap)
{
    size_t n = (size_t)e[0] * e[1] * e[2];
    uint64_t mask = w == 8 ? ~0ull : (1ull << (8 * w)) - 1;
    unsigned char *bytes = malloc(n * w), *shuffled = malloc(n * w);
    REQUIRE(bytes && shuffled);
    size_t i = 0;
    for (uint32_t z = 0; z < e[2]; z++)
        for (uint32_t y = 0; y < e[1]; y++)
            for (uint32_t x = 0; x < e[0]; x++, i++) {
                uint64_t v = sample_bits(samples, w, i), out = v;
                if (filters & (IP_FILTER_DELTA | IP_FILTER_MED)) {
                    int64_t p = 0;
                    if (filters & IP_FILTER_DELTA) {
                        p = i > 0 ? (int64_t)sample_bits(samples, w, i - 1) : 0;
                    } else {
                        int64_t a = x > 0 ? (int64_t)sample_bits(samples, w, i - 1) : 0;
                        int64_t b = y > 0 ? (int64_t)sample_bits(samples, w, i - e[0]) : 0;
                        if (x > 0 && y > 0) {
                            int64_t c = (int64_t)sample_bits(samples, w, i - e[0] - 1);
                            int64_t lo = a < b ? a : b, hi = a < b ? b : a;
                            p = c >= hi ? lo : c <= lo ? hi : a + b - c;
                        } else {
                            p = x > 0 ? a : y > 0 ? b : 0;
                        }
                    }
                    uint64_t r = (v - (uint64_t)p) & mask;
                    uint64_t sign = (r >> (8 * w - 1)) & 1;
                    out = ((r << 1) ^ (0 - sign)) & mask;
                }
                for (size_t b = 0; b < w; b++)
                    bytes[i * w + b] = (unsigned char)(out >> (8 * b));
            }
    const unsigned char *src = bytes;
    if (filters & IP_FILTER_SHUFFLE) {
        for (size_t b = 0; b < w; b++)
            for (size_t k = 0; k < n; k++)
                shuffled[b * n + k] = bytes[k * w + b];
        src = shuffled;
    }
    int size = LZ4_compress_default((const char *)src, (char *)payload, (int)(n * w), cap);
    free(bytes);
    free(shuffled);
    return size;
}

/* The decoder against the specification: every valid filter combination, every type. */
static void test_decoder_against_spec(void)
{
    static const unsigned combos[] = {0,
                                      IP_FILTER_DELTA,
                                      IP_FILTER_SHUFFLE,
                                      IP_FILTER_DELTA | IP_FILTER_SHUFFLE,
                                      IP_FILTER_MED,
                                      IP_FILTER_MED | IP_FILTER_SHUFFLE};
    for (int t = 0; t < IP_TYPE_COUNT; t++)
        for (size_t x = 0; x < EXTENT_COUNT; x++)
            for (int p = 0; p < PATTERN_COUNT; p++)
                for (size_t c = 0; c < sizeof combos / sizeof combos[0]; c++) {
                    const uint32_t *e = extents[x];
                    size_t w = ip_type_size((ip_type)t), count = (size_t)e[0] * e[1] * e[2];
                    size_t raw = count * w, work_size = ip__codec_work_size(count, (ip_type)t);
                    void *samples = malloc(raw);
                    int cap = LZ4_compressBound((int)raw);
                    unsigned char *payload = malloc((size_t)cap);
                    unsigned char *dst = guarded(raw), *work = guarded(work_size);
                    REQUIRE(samples && payload);
                    fill(samples, (ip_type)t, e, (enum pattern)p);
                    int size = reference_encode(samples, e, w, combos[c], payload, cap);
                    REQUIRE(size > 0);
                    ip_brick_entry entry = {0, (uint32_t)size, IP_BRICK_LZ4, (uint8_t)combos[c], 0};
                    ip_status st = ip__codec_decode(&entry, payload, e, (ip_type)t, 0, dst, work);
                    CHECK_MSG(st == IP_OK && memcmp(dst, samples, raw) == 0,
                              "type %d, %ux%ux%u, %s, filters %u: status %d", t, e[0], e[1], e[2],
                              pattern_names[p], combos[c], (int)st);
                    CHECK(guard_intact(dst, raw));
                    CHECK(guard_intact(work, work_size));
                    free(samples);
                    free(payload);
                    free(dst);
                    free(work);
                }
}

/* Decoding `entry` with `payload` gives IP_ERR_CORRUPT and stays inside the buffers. */
static void decode_fails(const ip_brick_entry *entry, const unsigned char *payload,
                         const uint32_t e[3], ip_type type, const char *what)
{
    size_t count = (size_t)e[0] * e[1] * e[2], raw = count * ip_type_size(type);
    size_t work_size = ip__codec_work_size(count, type);
    unsigned char *dst = guarded(raw), *work = guarded(work_size);
    /* the payload in a buffer of exactly its size, so that ASan sees any over-read */
    unsigned char *exact = malloc(entry->stored_size ? entry->stored_size : 1);
    REQUIRE(exact != NULL);
    memcpy(exact, payload, entry->stored_size);
    ip_status st = ip__codec_decode(entry, exact, e, type, 0, dst, work);
    CHECK_MSG(st == IP_ERR_CORRUPT, "%s: status %d", what, (int)st);
    CHECK_MSG(guard_intact(dst, raw) && guard_intact(work, work_size), "%s: out of bounds", what);
    free(exact);
    free(dst);
    free(work);
}

static void test_malformed(void)
{
    const uint32_t e[3] = {9, 7, 5};
    for (int t = 0; t < IP_TYPE_COUNT; t++) {
        ip_type type = (ip_type)t;
        size_t count = 315, raw = count * ip_type_size(type);
        size_t bound = ip__codec_bound(count, type);
        void *samples = malloc(raw);
        unsigned char *out = malloc(bound), *work = malloc(ip__codec_work_size(count, type));
        REQUIRE(samples && out && work);
        fill(samples, type, e, SMOOTH);
        ip_brick_entry good;
        REQUIRE(ip__codec_encode(samples, e, type, IP_LZ4_FAST, out, work, &good) == IP_OK);
        REQUIRE(good.encoding == IP_BRICK_LZ4);
        char what[96];
        ip_brick_entry bad = good;

        /* every truncation of the LZ4 block */
        for (uint32_t size = 1; size < good.stored_size; size++) {
            bad = good;
            bad.stored_size = size;
            snprintf(what, sizeof what, "type %d: LZ4 block cut to %u bytes", t, size);
            decode_fails(&bad, out, e, type, what);
        }
        /* a block that decodes to one sample too few or too many */
        const uint32_t smaller[3] = {e[0] - 1, e[1], e[2]}, larger[3] = {e[0] + 1, e[1], e[2]};
        snprintf(what, sizeof what, "type %d: block for a larger brick", t);
        decode_fails(&good, out, smaller, type, what);
        snprintf(what, sizeof what, "type %d: block for a smaller brick", t);
        decode_fails(&good, out, larger, type, what);
        /* garbage payloads */
        unsigned char garbage[512];
        for (int round = 0; round < 200; round++) {
            for (size_t i = 0; i < sizeof garbage; i++)
                garbage[i] = (unsigned char)next_random();
            bad = good;
            bad.stored_size = 1 + next_random() % sizeof garbage;
            ip_status st;
            size_t work_size = ip__codec_work_size(count, type);
            unsigned char *dst = guarded(raw), *scratch = guarded(work_size);
            st = ip__codec_decode(&bad, garbage, e, type, 0, dst, scratch);
            /* random bytes may happen to form a valid block of exactly the size: then OK */
            CHECK_MSG(st == IP_ERR_CORRUPT || st == IP_OK, "type %d: garbage: %d", t, (int)st);
            CHECK(guard_intact(dst, raw));
            CHECK(guard_intact(scratch, work_size));
            free(dst);
            free(scratch);
        }
        /* reserved filter bits and both predictors at once */
        static const unsigned bad_filters[] = {5, 7, 8, 16, 0x80, 0xFF};
        for (size_t i = 0; i < sizeof bad_filters / sizeof bad_filters[0]; i++) {
            bad = good;
            bad.filters = (uint8_t)bad_filters[i];
            snprintf(what, sizeof what, "type %d: filters 0x%x", t, bad_filters[i]);
            decode_fails(&bad, out, e, type, what);
        }
        /* unknown encodings */
        for (unsigned enc = 3; enc < 256; enc += 63) {
            bad = good;
            bad.encoding = (uint8_t)enc;
            snprintf(what, sizeof what, "type %d: encoding %u", t, enc);
            decode_fails(&bad, out, e, type, what);
        }
        /* raw: the size must be exact and no filter allowed */
        bad = (ip_brick_entry){0, (uint32_t)raw - 1, IP_BRICK_RAW, 0, 0};
        snprintf(what, sizeof what, "type %d: raw one byte short", t);
        decode_fails(&bad, samples, e, type, what);
        bad = (ip_brick_entry){0, (uint32_t)raw, IP_BRICK_RAW, IP_FILTER_DELTA, 0};
        snprintf(what, sizeof what, "type %d: raw with a filter", t);
        decode_fails(&bad, samples, e, type, what);
        free(samples);
        free(out);
        free(work);
    }
}

static void test_arguments(void)
{
    const uint32_t e[3] = {2, 2, 2}, empty[3] = {0, 2, 2};
    uint8_t samples[8] = {1, 2, 3, 4, 5, 6, 7, 8}, out[64], work[256];
    ip_brick_entry entry;
    CHECK_EQ(ip__codec_encode(samples, empty, IP_UINT8, IP_LZ4_FAST, out, work, &entry),
             IP_ERR_ARGUMENT);
    CHECK_EQ(ip__codec_encode(samples, e, (ip_type)IP_TYPE_COUNT, IP_LZ4_FAST, out, work, &entry),
             IP_ERR_ARGUMENT);
    CHECK_GE(ip__codec_bound(8, IP_UINT8), 8);
    CHECK_GE(ip__codec_bound(100, IP_FLOAT32), 400);
    CHECK_GE(ip__codec_work_size(100, IP_UINT16), 3 * 200 + ip__codec_bound(100, IP_UINT16));
}

/* The fast level's filter choice: its payload is exactly the specification's encoding with
 * the filters it names (no predictor or delta, shuffled when wide), and on every pattern it is
 * within 10 % of the smaller of the two whole-brick trials it replaces. */
static void test_fast_filter_choice(void)
{
    static const uint32_t e[3] = {33, 33, 33};
    size_t count = (size_t)e[0] * e[1] * e[2];
    for (int t = 0; t < IP_TYPE_COUNT; t++)
        for (int p = 0; p < PATTERN_COUNT; p++) {
            size_t w = ip_type_size((ip_type)t), raw = count * w;
            int cap = LZ4_compressBound((int)raw);
            void *samples = malloc(raw);
            unsigned char *out = malloc(ip__codec_bound(count, (ip_type)t));
            unsigned char *work = malloc(ip__codec_work_size(count, (ip_type)t));
            unsigned char *ref = malloc((size_t)cap);
            REQUIRE(samples && out && work && ref);
            fill(samples, (ip_type)t, e, (enum pattern)p);
            ip_brick_entry entry;
            REQUIRE(ip__codec_encode(samples, e, (ip_type)t, IP_LZ4_FAST, out, work, &entry) ==
                    IP_OK);
            if (entry.encoding == IP_BRICK_LZ4) {
                unsigned shuffled = w > 1 ? IP_FILTER_SHUFFLE : 0;
                CHECK_MSG(entry.filters == shuffled ||
                              entry.filters == (shuffled | IP_FILTER_DELTA),
                          "type %d, %s: filters %u", t, pattern_names[p], entry.filters);
                int size = reference_encode(samples, e, w, entry.filters, ref, cap);
                CHECK_MSG(size == (int)entry.stored_size && memcmp(ref, out, (size_t)size) == 0,
                          "type %d, %s: payload differs from the specification's", t,
                          pattern_names[p]);
                int plain = reference_encode(samples, e, w, shuffled, ref, cap);
                int delta = reference_encode(samples, e, w, shuffled | IP_FILTER_DELTA, ref, cap);
                int best = plain < delta ? plain : delta;
                CHECK_MSG((int)entry.stored_size <= best + best / 10,
                          "type %d, %s: %u bytes, best whole-brick trial %d", t, pattern_names[p],
                          entry.stored_size, best);
            }
            if (p == SMOOTH || p == PLANE)
                CHECK_MSG(entry.encoding == IP_BRICK_LZ4 && (entry.filters & IP_FILTER_DELTA),
                          "type %d, %s: smooth data take the delta predictor", t, pattern_names[p]);
            free(samples);
            free(out);
            free(work);
            free(ref);
        }
}

static const test_case cases[] = {
    TEST_CASE(test_arguments),
    TEST_CASE(test_round_trips),
    TEST_CASE(test_fast_filter_choice),
    TEST_CASE(test_constant_fill),
    TEST_CASE(test_decoder_against_spec),
    TEST_CASE(test_malformed),
};

int main(int argc, char **argv)
{
    return RUN_CASES(argc, argv, cases, "test_codec");
}

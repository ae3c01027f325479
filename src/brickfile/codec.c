/* SPDX-License-Identifier: BSD-3-Clause */
/* Brick payload codec: constant detection, predictors, byte shuffle, LZ4 blocks. */
#include <lz4.h>
#include <lz4hc.h>
#include <string.h>

#include "internal.h"
#include "codec.h"

/* The median edge predictor decodes several times slower than the delta predictor (its
 * prediction depends on three decoded neighbours), for about 2 % of size on CT data: it is
 * tried only at high-compression levels, where size was asked for over speed, and kept only
 * when it saves this fraction over the next best. */
#define MED_MIN_GAIN 0.02
/* The fast level picks its filters from this many z-slices of a brick (choose_filters()), and
 * only for bricks of at least CODEC_TRIAL_MIN_SLICES slices, where the trial costs at most a
 * fifth of compressing the brick once more; thinner bricks are compressed both ways. */
#define CODEC_TRIAL_SLICES 3
#define CODEC_TRIAL_MIN_SLICES 16

size_t ip__codec_bound(size_t count, ip_type type)
{
    size_t raw = count * ip_type_size(type);
    size_t bound = (size_t)LZ4_compressBound((int)raw);
    return bound > raw ? bound : raw;
}

size_t ip__codec_work_size(size_t count, ip_type type)
{
    /* predicted samples, shuffled samples, byte-swapped samples (big-endian hosts), then the
     * output of the candidate in hand */
    return 3 * count * ip_type_size(type) + ip__codec_bound(count, type);
}

/* Every sample equals the next exactly when the buffer equals itself shifted by one sample:
 * one memcmp at memory speed instead of a call per sample. */
static int all_equal(const unsigned char *p, size_t count, size_t size)
{
    return count < 2 || memcmp(p, p + size, (count - 1) * size) == 0;
}

/* ---- predictors, one instance per sample width (U: the unsigned type, W: its bits) ---- */

#define ZIGZAG(U, W, d) ((U)((U)((d) << 1) ^ (U)(0u - (U)((d) >> ((W)-1)))))
#define UNZIGZAG(U, z) ((U)(((z) >> 1) ^ (U)(0u - (U)((z)&1u))))

/* Median edge predictor (LOCO-I) from left a, up b and up-left c. */
#define MED(a, b, c)                                            \
    ((c) >= ((a) > (b) ? (a) : (b))   ? ((a) < (b) ? (a) : (b)) \
     : (c) <= ((a) < (b) ? (a) : (b)) ? ((a) > (b) ? (a) : (b)) \
                                      : (a) + (b) - (c))

#define DEFINE_PREDICTORS(U, W)                                                        \
    static void delta_encode_##W(const U *s, U *d, size_t n)                           \
    {                                                                                  \
        U prev = 0;                                                                    \
        for (size_t i = 0; i < n; i++) {                                               \
            U r = (U)(s[i] - prev);                                                    \
            d[i] = ZIGZAG(U, W, r);                                                    \
            prev = s[i];                                                               \
        }                                                                              \
    }                                                                                  \
    static void delta_decode_##W(U *d, size_t n)                                       \
    {                                                                                  \
        U prev = 0;                                                                    \
        for (size_t i = 0; i < n; i++) {                                               \
            prev = (U)(prev + UNZIGZAG(U, d[i]));                                      \
            d[i] = prev;                                                               \
        }                                                                              \
    }                                                                                  \
    static U med_predict_##W(const U *v, size_t i, uint32_t x, uint32_t y, size_t row) \
    {                                                                                  \
        if (x > 0 && y > 0) {                                                          \
            int64_t a = v[i - 1], b = v[i - row], c = v[i - row - 1];                  \
            return (U)MED(a, b, c);                                                    \
        }                                                                              \
        return x > 0 ? v[i - 1] : y > 0 ? v[i - row] : 0;                              \
    }                                                                                  \
    static void med_encode_##W(const U *s, U *d, const uint32_t e[3])                  \
    {                                                                                  \
        size_t i = 0;                                                                  \
        for (uint32_t z = 0; z < e[2]; z++)                                            \
            for (uint32_t y = 0; y < e[1]; y++)                                        \
                for (uint32_t x = 0; x < e[0]; x++, i++) {                             \
                    U r = (U)(s[i] - med_predict_##W(s, i, x, y, e[0]));               \
                    d[i] = ZIGZAG(U, W, r);                                            \
                }                                                                      \
    }                                                                                  \
    static void med_decode_##W(U *d, const uint32_t e[3])                              \
    {                                                                                  \
        size_t row = e[0];                                                             \
        for (uint32_t z = 0; z < e[2]; z++) {                                          \
            U *r = d + (size_t)z * row * e[1];                                         \
            U left = 0;                                                                \
            for (uint32_t x = 0; x < e[0]; x++) /* first row: from the left */         \
                r[x] = left = (U)(left + UNZIGZAG(U, r[x]));                           \
            for (uint32_t y = 1; y < e[1]; y++) {                                      \
                U *cur = r + (size_t)y * row;                                          \
                const U *up = cur - row;                                               \
                left = cur[0] = (U)(up[0] + UNZIGZAG(U, cur[0]));                      \
                for (uint32_t x = 1; x < e[0]; x++) {                                  \
                    int64_t a = left, b = up[x], c = up[x - 1];                        \
                    int64_t lo = a < b ? a : b, hi = a < b ? b : a;                    \
                    int64_t p = c >= hi ? lo : c <= lo ? hi : a + b - c;               \
                    cur[x] = left = (U)((U)p + UNZIGZAG(U, cur[x]));                   \
                }                                                                      \
            }                                                                          \
        }                                                                              \
    }

DEFINE_PREDICTORS(uint8_t, 8)
DEFINE_PREDICTORS(uint16_t, 16)
DEFINE_PREDICTORS(uint32_t, 32)

static void predict(const void *src, void *dst, const uint32_t e[3], size_t size, unsigned filters)
{
    size_t n = (size_t)e[0] * e[1] * e[2];
    int med = (filters & IP_FILTER_MED) != 0;
    if (size == 1)
        med ? med_encode_8(src, dst, e) : delta_encode_8(src, dst, n);
    else if (size == 2)
        med ? med_encode_16(src, dst, e) : delta_encode_16(src, dst, n);
    else
        med ? med_encode_32(src, dst, e) : delta_encode_32(src, dst, n);
}

static void unpredict(void *data, const uint32_t e[3], size_t size, unsigned filters)
{
    size_t n = (size_t)e[0] * e[1] * e[2];
    int med = (filters & IP_FILTER_MED) != 0;
    if (size == 1)
        med ? med_decode_8(data, e) : delta_decode_8(data, n);
    else if (size == 2)
        med ? med_decode_16(data, e) : delta_decode_16(data, n);
    else
        med ? med_decode_32(data, e) : delta_decode_32(data, n);
}

static void shuffle(const unsigned char *src, unsigned char *dst, size_t count, size_t size)
{
    for (size_t b = 0; b < size; b++)
        for (size_t i = 0; i < count; i++)
            dst[b * count + i] = src[i * size + b];
}

/* ---- decoding the delta predictor at memory speed (little-endian hosts) ----
 *
 * The running sum that undoes the delta predictor is serial, but within a vector it is a
 * prefix sum of log2(lanes) shifted adds, and across vectors only the carry (the last sum,
 * broadcast) depends on the previous vector: one add per 16 samples. Each function below
 * takes the byte planes straight from the LZ4 output and writes the samples once: unshuffle,
 * zigzag and running sum in one pass. SSE2 is the x86-64 baseline; elsewhere, or built with
 * IP_CODEC_PORTABLE (the tests build both), the same loops run one sample at a time. */

#if defined(__SSE2__) && !defined(IP_CODEC_PORTABLE)
#include <emmintrin.h>
#define CODEC_SSE2 1
#else
#define CODEC_SSE2 0
#endif

#if CODEC_SSE2
/* Every 16-bit lane set to the last one. */
static inline __m128i last16(__m128i v)
{
    v = _mm_shufflehi_epi16(v, 0xFF);
    return _mm_unpackhi_epi64(v, v);
}

/* Zigzag undone, then lane k = the sum of lanes 0..k (mod 2^16). */
static inline __m128i unzigzag_prefix16(__m128i z)
{
    __m128i d = _mm_xor_si128(_mm_srli_epi16(z, 1), _mm_srai_epi16(_mm_slli_epi16(z, 15), 15));
    d = _mm_add_epi16(d, _mm_slli_si128(d, 2));
    d = _mm_add_epi16(d, _mm_slli_si128(d, 4));
    return _mm_add_epi16(d, _mm_slli_si128(d, 8));
}

/* The whole vectors of unshuffle_undelta16(); returns the samples done, their sum in *sum. */
static size_t undelta16_sse2(const uint8_t *b0, const uint8_t *b1, uint16_t *d, size_t n,
                             uint16_t *sum)
{
    __m128i carry = _mm_setzero_si128();
    size_t i = 0;
    for (; i + 16 <= n; i += 16) {
        __m128i lo = _mm_loadu_si128((const __m128i *)(const void *)(b0 + i));
        __m128i hi = _mm_loadu_si128((const __m128i *)(const void *)(b1 + i));
        __m128i p0 = unzigzag_prefix16(_mm_unpacklo_epi8(lo, hi));
        __m128i p1 = _mm_add_epi16(unzigzag_prefix16(_mm_unpackhi_epi8(lo, hi)), last16(p0));
        _mm_storeu_si128((__m128i *)(void *)(d + i), _mm_add_epi16(p0, carry));
        _mm_storeu_si128((__m128i *)(void *)(d + i + 8), _mm_add_epi16(p1, carry));
        carry = _mm_add_epi16(carry, last16(p1));
    }
    *sum = (uint16_t)_mm_cvtsi128_si32(carry);
    return i;
}

/* Every 32-bit lane set to the last one. */
static inline __m128i last32(__m128i v)
{
    return _mm_shuffle_epi32(v, 0xFF);
}

/* Zigzag undone, then lane k = the sum of lanes 0..k (mod 2^32). */
static inline __m128i unzigzag_prefix32(__m128i z)
{
    __m128i d = _mm_xor_si128(_mm_srli_epi32(z, 1), _mm_srai_epi32(_mm_slli_epi32(z, 31), 31));
    d = _mm_add_epi32(d, _mm_slli_si128(d, 4));
    return _mm_add_epi32(d, _mm_slli_si128(d, 8));
}

/* The whole vectors of unshuffle_undelta32(); returns the samples done, their sum in *sum. */
static size_t undelta32_sse2(const uint8_t *const b[4], uint32_t *d, size_t n, uint32_t *sum)
{
    __m128i carry = _mm_setzero_si128();
    size_t i = 0;
    for (; i + 16 <= n; i += 16) {
        __m128i p[4], z[4];
        for (int k = 0; k < 4; k++)
            p[k] = _mm_loadu_si128((const __m128i *)(const void *)(b[k] + i));
        __m128i w01lo = _mm_unpacklo_epi8(p[0], p[1]), w23lo = _mm_unpacklo_epi8(p[2], p[3]);
        __m128i w01hi = _mm_unpackhi_epi8(p[0], p[1]), w23hi = _mm_unpackhi_epi8(p[2], p[3]);
        z[0] = unzigzag_prefix32(_mm_unpacklo_epi16(w01lo, w23lo));
        z[1] = unzigzag_prefix32(_mm_unpackhi_epi16(w01lo, w23lo));
        z[2] = unzigzag_prefix32(_mm_unpacklo_epi16(w01hi, w23hi));
        z[3] = unzigzag_prefix32(_mm_unpackhi_epi16(w01hi, w23hi));
        for (int k = 1; k < 4; k++)
            z[k] = _mm_add_epi32(z[k], last32(z[k - 1]));
        for (int k = 0; k < 4; k++)
            _mm_storeu_si128((__m128i *)(void *)(d + i + 4 * k), _mm_add_epi32(z[k], carry));
        carry = _mm_add_epi32(carry, last32(z[3]));
    }
    *sum = (uint32_t)_mm_cvtsi128_si32(carry);
    return i;
}

/* Every 8-bit lane set to the last one. */
static inline __m128i last8(__m128i v)
{
    v = _mm_unpackhi_epi8(v, v);
    v = _mm_shufflehi_epi16(v, 0xFF);
    return _mm_unpackhi_epi64(v, v);
}

/* Zigzag undone, then lane k = the sum of lanes 0..k (mod 2^8). */
static inline __m128i unzigzag_prefix8(__m128i z)
{
    const __m128i one = _mm_set1_epi8(1), low7 = _mm_set1_epi8(0x7F);
    __m128i half = _mm_and_si128(_mm_srli_epi16(z, 1), low7);
    __m128i d = _mm_xor_si128(half, _mm_sub_epi8(_mm_setzero_si128(), _mm_and_si128(z, one)));
    d = _mm_add_epi8(d, _mm_slli_si128(d, 1));
    d = _mm_add_epi8(d, _mm_slli_si128(d, 2));
    d = _mm_add_epi8(d, _mm_slli_si128(d, 4));
    return _mm_add_epi8(d, _mm_slli_si128(d, 8));
}

/* The whole vectors of undelta8(); returns the samples done, their sum in *sum. */
static size_t undelta8_sse2(uint8_t *d, size_t n, uint8_t *sum)
{
    __m128i carry = _mm_setzero_si128();
    size_t i = 0;
    for (; i + 32 <= n; i += 32) {
        __m128i p0 = unzigzag_prefix8(_mm_loadu_si128((const __m128i *)(void *)(d + i)));
        __m128i p1 = unzigzag_prefix8(_mm_loadu_si128((const __m128i *)(void *)(d + i + 16)));
        p1 = _mm_add_epi8(p1, last8(p0));
        _mm_storeu_si128((__m128i *)(void *)(d + i), _mm_add_epi8(p0, carry));
        _mm_storeu_si128((__m128i *)(void *)(d + i + 16), _mm_add_epi8(p1, carry));
        carry = _mm_add_epi8(carry, last8(p1));
    }
    *sum = (uint8_t)_mm_cvtsi128_si32(carry);
    return i;
}
#endif

/* 2-byte planes to host samples, zigzag and delta undone. */
static void unshuffle_undelta16(const uint8_t *b0, const uint8_t *b1, uint16_t *d, size_t n)
{
    size_t i = 0;
    uint16_t sum = 0;
#if CODEC_SSE2
    i = undelta16_sse2(b0, b1, d, n, &sum);
#endif
    for (; i < n; i++) {
        uint16_t z = (uint16_t)(b0[i] | b1[i] << 8);
        d[i] = sum = (uint16_t)(sum + UNZIGZAG(uint16_t, z));
    }
}

/* 4-byte planes to host samples, zigzag and delta undone. */
static void unshuffle_undelta32(const uint8_t *const b[4], uint32_t *d, size_t n)
{
    size_t i = 0;
    uint32_t sum = 0;
#if CODEC_SSE2
    i = undelta32_sse2(b, d, n, &sum);
#endif
    for (; i < n; i++) {
        uint32_t z = (uint32_t)b[0][i] | (uint32_t)b[1][i] << 8 | (uint32_t)b[2][i] << 16 |
                     (uint32_t)b[3][i] << 24;
        d[i] = sum = sum + UNZIGZAG(uint32_t, z);
    }
}

/* Zigzag and delta undone on bytes, in place. */
static void undelta8(uint8_t *d, size_t n)
{
    size_t i = 0;
    uint8_t sum = 0;
#if CODEC_SSE2
    i = undelta8_sse2(d, n, &sum);
#endif
    for (; i < n; i++)
        d[i] = sum = (uint8_t)(sum + UNZIGZAG(uint8_t, d[i]));
}

/* 2-byte planes to host samples. */
static void unshuffle16(const uint8_t *restrict b0, const uint8_t *restrict b1,
                        uint16_t *restrict d, size_t n)
{
    size_t i = 0;
#if CODEC_SSE2
    for (; i + 16 <= n; i += 16) { /* GCC's own vectorisation of the loop takes 10 operations */
        __m128i lo = _mm_loadu_si128((const __m128i *)(const void *)(b0 + i));
        __m128i hi = _mm_loadu_si128((const __m128i *)(const void *)(b1 + i));
        _mm_storeu_si128((__m128i *)(void *)(d + i), _mm_unpacklo_epi8(lo, hi));
        _mm_storeu_si128((__m128i *)(void *)(d + i + 8), _mm_unpackhi_epi8(lo, hi));
    }
#endif
    for (; i < n; i++)
        d[i] = (uint16_t)(b0[i] | b1[i] << 8);
}

/* 4-byte planes to host samples (the compiler vectorises it). */
static void unshuffle32(const uint8_t *restrict b0, const uint8_t *restrict b1,
                        const uint8_t *restrict b2, const uint8_t *restrict b3,
                        uint32_t *restrict d, size_t n)
{
    for (size_t i = 0; i < n; i++)
        d[i] =
            (uint32_t)b0[i] | (uint32_t)b1[i] << 8 | (uint32_t)b2[i] << 16 | (uint32_t)b3[i] << 24;
}

/* Undoes `filters` on a little-endian host: `src` is the LZ4 output, byte planes when
 * `planes`, else dst itself; `dst` receives the host samples. One pass over the samples, plus
 * a second for the median edge predictor. Wide samples without the shuffle (the encoder
 * never writes them) take the plain loops. */
static void unfilter_little_endian(const unsigned char *src, void *dst, const uint32_t e[3],
                                   size_t size, unsigned filters, int planes)
{
    size_t n = (size_t)e[0] * e[1] * e[2];
    int delta = (filters & IP_FILTER_DELTA) != 0;
    if (size == 1 && delta) {
        undelta8(dst, n);
    } else if (!planes) {
        if (delta)
            unpredict(dst, e, size, filters);
    } else if (size == 2) {
        if (delta)
            unshuffle_undelta16(src, src + n, dst, n);
        else
            unshuffle16(src, src + n, dst, n);
    } else {
        const uint8_t *const b[4] = {src, src + n, src + 2 * n, src + 3 * n};
        if (delta)
            unshuffle_undelta32(b, dst, n);
        else
            unshuffle32(b[0], b[1], b[2], b[3], dst, n);
    }
    if (filters & IP_FILTER_MED)
        unpredict(dst, e, size, filters);
}

static void unshuffle(const unsigned char *src, unsigned char *dst, size_t count, size_t size)
{
    for (size_t b = 0; b < size; b++)
        for (size_t i = 0; i < count; i++)
            dst[i * size + b] = src[b * count + i];
}

/* Applies `filters` to the little-endian samples `src`; returns where the result lies
 * (src itself when there is nothing to do, else one of the two scratch buffers). */
static const void *apply_filters(const void *src, unsigned char *scratch_a,
                                 unsigned char *scratch_b, const uint32_t e[3], size_t size,
                                 unsigned filters)
{
    size_t n = (size_t)e[0] * e[1] * e[2];
    const void *cur = src;
    if (filters & (IP_FILTER_DELTA | IP_FILTER_MED)) {
        predict(cur, scratch_a, e, size, filters);
        cur = scratch_a;
    }
    if (filters & IP_FILTER_SHUFFLE) {
        shuffle(cur, scratch_b, n, size);
        cur = scratch_b;
    }
    return cur;
}

static int compress_block(const void *src, size_t bytes, void *dst, size_t capacity, int level)
{
    if (level > 0)
        return LZ4_compress_HC(src, dst, (int)bytes, (int)capacity, level);
    return LZ4_compress_default(src, dst, (int)bytes, (int)capacity);
}

/* ---- the fast encoder: one filter pass and one LZ4 pass per brick ---- */

/* Delta (when asked), zigzag and byte shuffle in one pass over `n` little-endian samples of
 * `size` bytes, bytes identical to predict() then shuffle(); written so that GCC and clang
 * vectorise it (each residual depends on two source samples, not on the previous residual). */
#define DEFINE_FUSED_FILTER(U, W)                                                          \
    static void fused_filter_##W(const U *restrict s, unsigned char *restrict d, size_t n, \
                                 int delta)                                                \
    {                                                                                      \
        for (size_t i = 0; i < n; i++) {                                                   \
            U r = s[i];                                                                    \
            if (delta) {                                                                   \
                U prev = i > 0 ? s[i - 1] : 0;                                             \
                U diff = (U)(r - prev);                                                    \
                r = ZIGZAG(U, W, diff);                                                    \
            }                                                                              \
            for (size_t b = 0; b < sizeof(U); b++)                                         \
                d[b * n + i] = (unsigned char)(r >> (8 * b));                              \
        }                                                                                  \
    }

DEFINE_FUSED_FILTER(uint8_t, 8)
DEFINE_FUSED_FILTER(uint16_t, 16)
DEFINE_FUSED_FILTER(uint32_t, 32)

/* The fast encoder's filter pass on a little-endian host: no predictor or delta, then the
 * shuffle for wide types (the filters the fast level chooses between). */
static void fused_filter(const void *src, unsigned char *dst, size_t n, size_t size, int delta)
{
    if (size == 1)
        fused_filter_8(src, dst, n, delta);
    else if (size == 2)
        fused_filter_16(src, dst, n, delta);
    else
        fused_filter_32(src, dst, n, delta);
}

/* Chooses between no predictor and the delta predictor from trial slices: the brick's first,
 * middle and last z-slices, copied together, filtered both ways and compressed. The smaller
 * trial names the filters for the whole brick: on CT volumes the payloads come out within
 * 0.1 % of compressing the whole brick both ways, for a fifth of the extra work. `trial`
 * receives the slices, `filtered` and `candidate` are scratch (work buffers of the codec). */
static unsigned choose_filters(const unsigned char *le, const uint32_t e[3], size_t size,
                               unsigned char *trial, unsigned char *filtered,
                               unsigned char *candidate, size_t bound)
{
    size_t slice = (size_t)e[0] * e[1] * size;
    const uint32_t picks[CODEC_TRIAL_SLICES] = {0, e[2] / 2, e[2] - 1};
    for (int t = 0; t < CODEC_TRIAL_SLICES; t++)
        memcpy(trial + t * slice, le + picks[t] * slice, slice);
    size_t n = CODEC_TRIAL_SLICES * slice / size;
    int sizes[2];
    for (int delta = 0; delta < 2; delta++) {
        fused_filter(trial, filtered, n, size, delta);
        sizes[delta] = compress_block(filtered, n * size, candidate, bound, IP_LZ4_FAST);
    }
    unsigned shuffled = size > 1 ? IP_FILTER_SHUFFLE : 0;
    int delta_wins = sizes[1] > 0 && (sizes[0] <= 0 || sizes[1] < sizes[0]);
    return shuffled | (delta_wins ? IP_FILTER_DELTA : 0);
}

/* Fast LZ4 on a little-endian host, for bricks with more z-slices than the trial: one filter
 * pass and one compression of the whole brick. Returns the payload size (0: it did not fit in
 * `bound`) and sets *filters. */
static int encode_fast(const unsigned char *le, const uint32_t e[3], size_t size,
                       unsigned char *out, unsigned char *work, size_t bound, unsigned *filters)
{
    size_t count = (size_t)e[0] * e[1] * e[2], raw = count * size;
    unsigned char *trial = work, *filtered = work + raw, *candidate = filtered + raw;
    *filters = choose_filters(le, e, size, trial, filtered, candidate, bound);
    fused_filter(le, filtered, count, size, (*filters & IP_FILTER_DELTA) != 0);
    return compress_block(filtered, raw, out, bound, IP_LZ4_FAST);
}

void ip__codec_encode_constant(ip_brick_entry *entry)
{
    entry->offset = 0;
    entry->encoding = IP_BRICK_CONSTANT;
    entry->filters = 0;
    entry->stored_size = 0;
    entry->checksum = 0;
}

/* Stores the brick raw when LZ4 failed (n == 0) or did not shrink it, else records the LZ4
 * payload already in `out`; then the checksum. */
static ip_status finish_entry(const void *le, size_t raw, int n, unsigned filters, void *out,
                              ip_brick_entry *entry)
{
    if (n <= 0 || (size_t)n >= raw) {
        memcpy(out, le, raw);
        entry->encoding = IP_BRICK_RAW;
        entry->filters = 0;
        entry->stored_size = (uint32_t)raw;
    } else {
        entry->encoding = IP_BRICK_LZ4;
        entry->filters = (uint8_t)filters;
        entry->stored_size = (uint32_t)n;
    }
    entry->checksum = ip__format_checksum(out, entry->stored_size);
    return IP_OK;
}

ip_status ip__codec_encode(const void *samples, const uint32_t extent[3], ip_type type, int level,
                           void *out, void *work, ip_brick_entry *entry)
{
    size_t size = ip_type_size(type);
    size_t count = (size_t)extent[0] * extent[1] * extent[2];
    size_t raw = count * size;
    IP_ASSERT(samples != NULL && out != NULL && work != NULL && entry != NULL);
    if (size == 0 || count == 0 || raw > (size_t)LZ4_MAX_INPUT_SIZE)
        return IP_ERR_ARGUMENT;
    entry->offset = 0;
    entry->filters = 0;
    if (all_equal(samples, count, size)) {
        ip__codec_encode_constant(entry);
        return IP_OK;
    }
    unsigned char *scratch_a = work, *scratch_b = scratch_a + raw, *swapped = scratch_b + raw;
    unsigned char *candidate = swapped + raw;
    size_t bound = ip__codec_bound(count, type);
    const void *le = samples;
    if (!ip__host_little_endian() && size > 1) {
        /* the codec works on little-endian bytes: swap a copy on a big-endian host */
        memcpy(swapped, samples, raw);
        ip__swap_bytes(swapped, count, size);
        le = swapped;
    }
    if (level <= 0 && le == samples && extent[2] >= CODEC_TRIAL_MIN_SLICES) {
        unsigned filters = 0;
        int n = encode_fast(le, extent, size, out, work, bound, &filters);
        return finish_entry(le, raw, n, filters, out, entry);
    }
    unsigned shuffled = size > 1 ? IP_FILTER_SHUFFLE : 0;
    const unsigned choices[3] = {shuffled, IP_FILTER_DELTA | shuffled, IP_FILTER_MED | shuffled};
    int candidates = level > 0 ? 3 : 2;
    int best = 0;
    unsigned best_filters = 0;
    for (int c = 0; c < candidates; c++) {
        const void *filtered = apply_filters(le, scratch_a, scratch_b, extent, size, choices[c]);
        int n = compress_block(filtered, raw, candidate, bound, level);
        int wins = choices[c] & IP_FILTER_MED ? n < best - (int)(best * MED_MIN_GAIN) : n < best;
        if (n > 0 && (best == 0 || wins)) {
            best = n;
            best_filters = choices[c];
            memcpy(out, candidate, (size_t)n);
        }
    }
    return finish_entry(le, raw, best, best_filters, out, entry);
}

/* Fills count samples of `size` bytes with the first one by doubling copies (memcpy runs at
 * memory speed, a per-sample store loop does not). */
static void fill_doubling(unsigned char *dst, size_t count, size_t size)
{
    size_t done = 1, total = count * size;
    while (done * size < total) {
        size_t chunk = done * size < total - done * size ? done * size : total - done * size;
        memcpy(dst + done * size, dst, chunk);
        done += chunk / size;
    }
}

static void fill_constant(void *dst, size_t count, ip_type type, float value)
{
    if (type != IP_UINT8) {
        switch (type) {
        case IP_UINT16: ((uint16_t *)dst)[0] = (uint16_t)value; break;
        case IP_INT16: ((int16_t *)dst)[0] = (int16_t)value; break;
        default: ((float *)dst)[0] = value; break;
        }
        fill_doubling(dst, count, ip_type_size(type));
        return;
    }
    switch (type) {
    case IP_UINT8: memset(dst, (int)(uint8_t)value, count); break;
    case IP_UINT16:
        for (size_t i = 0; i < count; i++)
            ((uint16_t *)dst)[i] = (uint16_t)value;
        break;
    case IP_INT16:
        for (size_t i = 0; i < count; i++)
            ((int16_t *)dst)[i] = (int16_t)value;
        break;
    case IP_FLOAT32:
        for (size_t i = 0; i < count; i++)
            ((float *)dst)[i] = value;
        break;
    }
}

ip_status ip__codec_decode(const ip_brick_entry *entry, const void *payload,
                           const uint32_t extent[3], ip_type type, float constant_value, void *dst,
                           void *work)
{
    size_t size = ip_type_size(type);
    size_t count = (size_t)extent[0] * extent[1] * extent[2];
    size_t raw = count * size;
    IP_ASSERT(entry != NULL && dst != NULL);
    IP_ASSERT(entry->encoding == IP_BRICK_CONSTANT || (payload != NULL && work != NULL));
    if (size == 0 || count == 0)
        return IP_ERR_ARGUMENT;
    switch (entry->encoding) {
    case IP_BRICK_CONSTANT: fill_constant(dst, count, type, constant_value); return IP_OK;
    case IP_BRICK_RAW:
        if (entry->stored_size != raw || entry->filters != 0)
            return IP_ERR_CORRUPT;
        memcpy(dst, payload, raw);
        break;
    case IP_BRICK_LZ4: {
        unsigned f = entry->filters;
        if ((f & ~7u) ||
            (f & (IP_FILTER_DELTA | IP_FILTER_MED)) == (IP_FILTER_DELTA | IP_FILTER_MED))
            return IP_ERR_CORRUPT;
        /* byte planes go to the scratch and come back as samples; bytes (whose shuffle is
         * the identity) decode in place */
        int planes = (f & IP_FILTER_SHUFFLE) && size > 1;
        void *target = planes ? work : dst;
        int n = LZ4_decompress_safe(payload, target, (int)entry->stored_size, (int)raw);
        if (n < 0 || (size_t)n != raw)
            return IP_ERR_CORRUPT;
        if (ip__host_little_endian()) {
            unfilter_little_endian(target, dst, extent, size, f, planes);
            return IP_OK;
        }
        if (planes)
            unshuffle(work, dst, count, size);
        if (f & (IP_FILTER_DELTA | IP_FILTER_MED))
            unpredict(dst, extent, size, f);
        break;
    }
    default: return IP_ERR_CORRUPT;
    }
    if (!ip__host_little_endian() && size > 1)
        ip__swap_bytes(dst, count, size);
    return IP_OK;
}

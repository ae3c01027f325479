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

static int all_equal(const unsigned char *p, size_t count, size_t size)
{
    for (size_t i = 1; i < count; i++)
        if (memcmp(p, p + i * size, size) != 0)
            return 0;
    return 1;
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

/* Unshuffles 2- or 4-byte samples into host integers (little-endian hosts) and, when asked,
 * undoes the delta predictor: a first pass that the compiler vectorises (byte planes to
 * integers, zigzag undone), then a running sum, the only serial part. */
static void unshuffle_fast(const unsigned char *src, void *dst, size_t count, size_t size,
                           int delta)
{
    if (size == 2) {
        const unsigned char *restrict b0 = src, *restrict b1 = src + count;
        uint16_t *restrict d = dst;
        if (!delta) {
            for (size_t i = 0; i < count; i++)
                d[i] = (uint16_t)(b0[i] | b1[i] << 8);
            return;
        }
        for (size_t i = 0; i < count; i++) {
            uint16_t z = (uint16_t)(b0[i] | b1[i] << 8);
            d[i] = UNZIGZAG(uint16_t, z);
        }
        uint16_t sum = 0;
        for (size_t i = 0; i < count; i++)
            d[i] = sum = (uint16_t)(sum + d[i]);
    } else {
        const unsigned char *restrict b0 = src, *restrict b1 = src + count,
                                      *restrict b2 = b1 + count, *restrict b3 = b2 + count;
        uint32_t *restrict d = dst;
        for (size_t i = 0; i < count; i++) {
            uint32_t z = (uint32_t)b0[i] | (uint32_t)b1[i] << 8 | (uint32_t)b2[i] << 16 |
                         (uint32_t)b3[i] << 24;
            d[i] = delta ? UNZIGZAG(uint32_t, z) : z;
        }
        if (delta) {
            uint32_t sum = 0;
            for (size_t i = 0; i < count; i++)
                d[i] = sum = sum + d[i];
        }
    }
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
        entry->encoding = IP_BRICK_CONSTANT;
        entry->stored_size = 0;
        entry->checksum = 0;
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
    if (best == 0 || (size_t)best >= raw) {
        memcpy(out, le, raw);
        entry->encoding = IP_BRICK_RAW;
        entry->stored_size = (uint32_t)raw;
    } else {
        entry->encoding = IP_BRICK_LZ4;
        entry->filters = (uint8_t)best_filters;
        entry->stored_size = (uint32_t)best;
    }
    entry->checksum = ip__format_checksum(out, entry->stored_size);
    return IP_OK;
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
        void *target = (f & IP_FILTER_SHUFFLE) ? work : dst;
        int n = LZ4_decompress_safe(payload, target, (int)entry->stored_size, (int)raw);
        if (n < 0 || (size_t)n != raw)
            return IP_ERR_CORRUPT;
        if ((f & IP_FILTER_SHUFFLE) && size > 1 && ip__host_little_endian()) {
            unshuffle_fast(work, dst, count, size, (f & IP_FILTER_DELTA) != 0);
            if (f & IP_FILTER_MED)
                unpredict(dst, extent, size, f);
            return IP_OK;
        }
        if (f & IP_FILTER_SHUFFLE)
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

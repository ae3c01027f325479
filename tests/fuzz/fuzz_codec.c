/* SPDX-License-Identifier: BSD-3-Clause */
/* libFuzzer harness: the brick payload decoder on arbitrary payloads and directory entries.
 * Decoding must stay inside its buffers whatever the bytes; when the payload was produced by
 * the encoder from the fuzzed samples, decoding must give the samples back exactly. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "codec.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int round_trip(const uint8_t *data, size_t size, ip_type type, const uint32_t e[3])
{
    size_t count = (size_t)e[0] * e[1] * e[2], bytes = count * ip_type_size(type);
    if (size < bytes)
        return 0;
    unsigned char *samples = malloc(bytes), *out = malloc(ip__codec_bound(count, type));
    unsigned char *work = malloc(ip__codec_work_size(count, type)), *back = malloc(bytes);
    memcpy(samples, data, bytes);
    if (type == IP_FLOAT32) /* bricking only sees finite floats: clear exponent all-ones */
        for (size_t i = 0; i < count; i++)
            samples[4 * i + 3] &= 0x3f;
    ip_brick_entry entry;
    if (ip__codec_encode(samples, e, type, 0, out, work, &entry) != IP_OK)
        abort();
    float constant = ip_sample_get(samples, type, 0);
    if (ip__codec_decode(&entry, out, e, type, constant, back, work) != IP_OK ||
        memcmp(samples, back, bytes) != 0)
        abort();
    free(samples);
    free(out);
    free(work);
    free(back);
    return 1;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 6)
        return 0;
    ip_type type = (ip_type)(data[0] % IP_TYPE_COUNT);
    uint32_t e[3] = {1u + data[1] % 17u, 1u + data[2] % 17u, 1u + data[3] % 17u};
    ip_brick_entry entry = {0, (uint32_t)(size - 6), (uint8_t)(data[4] % 4), data[5], 0};
    size_t count = (size_t)e[0] * e[1] * e[2];
    size_t bytes = count * ip_type_size(type);
    unsigned char *dst = malloc(bytes), *work = malloc(ip__codec_work_size(count, type));
    unsigned char *payload = malloc(size - 6 + 1);
    memcpy(payload, data + 6, size - 6); /* an exact-size buffer: overreads are caught */
    (void)ip__codec_decode(&entry, payload, e, type, 1.0f, dst, work);
    free(payload);
    free(dst);
    free(work);
    round_trip(data + 6, size - 6, type, e);
    return 0;
}

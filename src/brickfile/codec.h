/* SPDX-License-Identifier: BSD-3-Clause */
/* isoprop: encoding and decoding of one brick's payload.
 *
 * A brick is stored as a constant (no payload), raw little-endian samples, or one LZ4 block of
 * the samples after reversible filters (a predictor, then byte shuffle for wide types). At the
 * fast level the encoder chooses between no predictor and the delta predictor by compressing
 * three z-slices of the brick both ways, then filters and compresses the whole brick once
 * (bricks thinner than 16 slices are compressed both ways). At LZ4HC levels it compresses the
 * whole brick with each predictor, the median edge predictor included, which compresses CT
 * data about 2 % better but decodes several times slower, and keeps the smallest. A brick that
 * does not shrink is stored raw. Every function here is pure: thread-safe on distinct buffers.
 */
#ifndef ISOPROP_CODEC_H
#define ISOPROP_CODEC_H

#include <stddef.h>
#include <stdint.h>

#include "format.h"
#include "isoprop/bricker.h"
#include "isoprop/status.h"
#include "isoprop/volume.h"

#ifdef __cplusplus
extern "C" {
#endif

/*! ip__codec_bound() : the largest payload ip__codec_encode() can write for `count`
 *  samples of `type`, in bytes. */
size_t ip__codec_bound(size_t count, ip_type type);

/*! ip__codec_work_size() : bytes of scratch memory ip__codec_encode()/ip__codec_decode() need
 *  for `count` samples of `type`. */
size_t ip__codec_work_size(size_t count, ip_type type);

/*! ip__codec_encode() : encodes a brick of extent[0] x extent[1] x extent[2] samples (host
 *  byte order, x fastest) of `type`.
 *  Writes the payload to `out` (ip__codec_bound() bytes, caller-owned) and sets
 *  entry->encoding, filters, stored_size and checksum (entry->offset is left to the caller).
 *  `work` is caller-owned scratch of ip__codec_work_size() bytes. `level` is IP_LZ4_FAST or an
 *  LZ4HC level. A constant brick writes nothing: its value is the brick's min in the summary.
 *  @return IP_OK or IP_ERR_ARGUMENT. */
ip_status ip__codec_encode(const void *samples, const uint32_t extent[3], ip_type type, int level,
                           void *out, void *work, ip_brick_entry *entry);

/*! ip__codec_encode_constant() : sets `entry` to what ip__codec_encode() writes for a brick
 *  whose samples are all equal, for a caller that knows it already (the bricker, from the
 *  brick's range): no payload, its value is the brick's min in the summary. */
void ip__codec_encode_constant(ip_brick_entry *entry);

/*! ip__codec_decode() : decodes a payload described by `entry` into `dst` (the brick's
 *  extent[0] x extent[1] x extent[2] samples of `type`, host byte order, caller-owned). A constant brick is filled with `constant_value`.
 *  Does not check the checksum (see ip__format_checksum()). `work` is scratch of
 *  ip__codec_work_size() bytes. Safe against malformed payloads: never reads or writes out of
 *  bounds. @return IP_OK, or IP_ERR_CORRUPT when the payload does not decode to exactly
 *  count samples. */
ip_status ip__codec_decode(const ip_brick_entry *entry, const void *payload,
                           const uint32_t extent[3], ip_type type, float constant_value, void *dst,
                           void *work);

#ifdef __cplusplus
}
#endif
#endif

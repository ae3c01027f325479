/* SPDX-License-Identifier: BSD-3-Clause */
/* Decoding a Zarr chunk: its checksum (crc32c), then its compressor (blosc, zlib, gzip, zstd,
 * numcodecs' lz4) into exactly the chunk's bytes. Every length is checked: a chunk cut short,
 * damaged or of another size is refused, never read past. */
#include <blosc.h>
#include <pthread.h>
#include <lz4.h>
#include <stdio.h>
#include <string.h>
#include <zlib.h>
#include <zstd.h>

#include "zarr.h"

/* CRC-32C (Castagnoli), reflected, polynomial 0x82F63B78: no Debian library offers it as C
 * (zlib's crc32 is the other polynomial), so a byte table. RFC 3720 B.4 gives the test
 * vectors (tests/test_zarr.c). */
static uint32_t crc_table[256];

static void crc_table_init(void)
{
    for (uint32_t n = 0; n < 256; n++) {
        uint32_t c = n;
        for (int k = 0; k < 8; k++)
            c = (c & 1) ? (c >> 1) ^ 0x82F63B78u : c >> 1;
        crc_table[n] = c;
    }
}

uint32_t ip__crc32c(const unsigned char *data, size_t size)
{
    static pthread_once_t once = PTHREAD_ONCE_INIT;
    pthread_once(&once, crc_table_init);
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < size; i++)
        c = crc_table[(c ^ data[i]) & 0xFF] ^ (c >> 8);
    return c ^ 0xFFFFFFFFu;
}

static int wrong_size(char *why, size_t why_size, const char *codec, size_t got, size_t want)
{
    snprintf(why, why_size, "%s: decodes to %zu bytes, not the chunk's %zu", codec, got, want);
    return -1;
}

static int decode_blosc(const unsigned char *src, size_t size, unsigned char *dst, size_t out_bytes,
                        char *why, size_t why_size)
{
    size_t nbytes = 0;
    if (size < BLOSC_MIN_HEADER_LENGTH || blosc_cbuffer_validate(src, size, &nbytes) != 0) {
        snprintf(why, why_size, "blosc: not a blosc buffer (cut short or damaged)");
        return -1;
    }
    if (nbytes != out_bytes)
        return wrong_size(why, why_size, "blosc", nbytes, out_bytes);
    int got = blosc_decompress_ctx(src, dst, out_bytes, 1);
    if (got < 0 || (size_t)got != out_bytes) {
        snprintf(why, why_size, "blosc: does not decode (damaged)");
        return -1;
    }
    return 0;
}

/* zlib and gzip streams alike (inflate's automatic header detection). */
static int decode_inflate(const unsigned char *src, size_t size, unsigned char *dst,
                          size_t out_bytes, const char *codec, char *why, size_t why_size)
{
    z_stream zs;
    memset(&zs, 0, sizeof zs);
    if (inflateInit2(&zs, 15 + 32) != Z_OK) {
        snprintf(why, why_size, "%s: out of memory", codec);
        return -1;
    }
    zs.next_in = (Bytef *)(uintptr_t)src;
    zs.next_out = dst;
    int rc = Z_OK;
    size_t in_left = size, out_left = out_bytes;
    while (rc == Z_OK) {
        uInt in = in_left > UINT32_MAX ? UINT32_MAX : (uInt)in_left;
        uInt out = out_left > UINT32_MAX ? UINT32_MAX : (uInt)out_left;
        zs.avail_in = in;
        zs.avail_out = out;
        rc = inflate(&zs, Z_FINISH);
        in_left -= in - zs.avail_in;
        out_left -= out - zs.avail_out;
        if (rc == Z_BUF_ERROR && (in_left == 0 || out_left == 0))
            break;
        if (rc == Z_BUF_ERROR)
            rc = Z_OK;
    }
    inflateEnd(&zs);
    if (rc == Z_STREAM_END && out_left == 0)
        return 0;
    if (rc == Z_STREAM_END || (rc == Z_BUF_ERROR && in_left == 0))
        snprintf(why, why_size, "%s: the stream ends after %zu of the chunk's %zu bytes", codec,
                 out_bytes - out_left, out_bytes);
    else if (rc == Z_BUF_ERROR)
        snprintf(why, why_size, "%s: decodes to more than the chunk's %zu bytes", codec, out_bytes);
    else
        snprintf(why, why_size, "%s: does not decode (%s)", codec, zs.msg ? zs.msg : "damaged");
    return -1;
}

static int decode_zstd(const unsigned char *src, size_t size, unsigned char *dst, size_t out_bytes,
                       char *why, size_t why_size)
{
    unsigned long long content = ZSTD_getFrameContentSize(src, size);
    if (content == ZSTD_CONTENTSIZE_ERROR) {
        snprintf(why, why_size, "zstd: not a zstd frame");
        return -1;
    }
    if (content != ZSTD_CONTENTSIZE_UNKNOWN && content != out_bytes)
        return wrong_size(why, why_size, "zstd", (size_t)content, out_bytes);
    size_t got = ZSTD_decompress(dst, out_bytes, src, size);
    if (ZSTD_isError(got)) {
        snprintf(why, why_size, "zstd: does not decode (%s)", ZSTD_getErrorName(got));
        return -1;
    }
    return got == out_bytes ? 0 : wrong_size(why, why_size, "zstd", got, out_bytes);
}

/* numcodecs' LZ4: the decoded size as 4 little-endian bytes, then one LZ4 block. */
static int decode_lz4(const unsigned char *src, size_t size, unsigned char *dst, size_t out_bytes,
                      char *why, size_t why_size)
{
    if (size < 4) {
        snprintf(why, why_size, "lz4: %zu bytes, under the 4-byte size header", size);
        return -1;
    }
    size_t stated =
        (size_t)src[0] | (size_t)src[1] << 8 | (size_t)src[2] << 16 | (size_t)src[3] << 24;
    if (stated != out_bytes)
        return wrong_size(why, why_size, "lz4", stated, out_bytes);
    if (size - 4 > INT32_MAX || out_bytes > INT32_MAX) {
        snprintf(why, why_size, "lz4: a block past 2 GiB");
        return -1;
    }
    int got =
        LZ4_decompress_safe((const char *)src + 4, (char *)dst, (int)(size - 4), (int)out_bytes);
    if (got < 0) {
        snprintf(why, why_size, "lz4: does not decode (damaged)");
        return -1;
    }
    return (size_t)got == out_bytes ? 0 : wrong_size(why, why_size, "lz4", (size_t)got, out_bytes);
}

int ip__zarr_decode(const zarr_chain *chain, const unsigned char *src, size_t size,
                    unsigned char *dst, size_t out_bytes, char *why, size_t why_size)
{
    uint32_t n = chain->count;
    if (n > 0 && chain->codecs[n - 1] == ZARR_CRC32C) {
        if (size < 4) {
            snprintf(why, why_size, "crc32c: %zu bytes, under the 4-byte checksum", size);
            return -1;
        }
        size -= 4;
        uint32_t stored = (uint32_t)src[size] | (uint32_t)src[size + 1] << 8 |
                          (uint32_t)src[size + 2] << 16 | (uint32_t)src[size + 3] << 24;
        if (ip__crc32c(src, size) != stored) {
            snprintf(why, why_size, "crc32c: checksum mismatch (damaged)");
            return -1;
        }
        n--;
    }
    if (n == 0) {
        if (size != out_bytes)
            return wrong_size(why, why_size, "uncompressed", size, out_bytes);
        memcpy(dst, src, size);
        return 0;
    }
    switch (chain->codecs[0]) {
    case ZARR_BLOSC: return decode_blosc(src, size, dst, out_bytes, why, why_size);
    case ZARR_ZLIB: return decode_inflate(src, size, dst, out_bytes, "zlib", why, why_size);
    case ZARR_GZIP: return decode_inflate(src, size, dst, out_bytes, "gzip", why, why_size);
    case ZARR_ZSTD: return decode_zstd(src, size, dst, out_bytes, why, why_size);
    case ZARR_LZ4: return decode_lz4(src, size, dst, out_bytes, why, why_size);
    case ZARR_CRC32C: break;
    }
    snprintf(why, why_size, "an unknown codec");
    return -1;
}

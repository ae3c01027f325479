/* SPDX-License-Identifier: BSD-3-Clause */
/* Writes Zarr v2 and v3 arrays and OME-Zarr images of a raw int16 volume for tests/tools/zarr.sh,
 * through the libraries the reader uses (c-blosc, zlib, zstd, lz4): each variant holds the raw
 * file's samples, so it must brick to the raw volume's brick file. Chunks all of the fill
 * value (the volume's first sample, its background) are left out, as Zarr writers do: shards
 * too, and a shard's empty inner chunks get the index's empty entry.
 *
 *   make_zarr RAW XxYxZ OUT_FOLDER
 *   make_zarr RAW XxYxZ OUT.zarr --bench   one Zarr v2 array, blosc lz4 with byte shuffle,
 *                                          64^3 chunks (tools/bench/bench_zarr.sh) */
#include <blosc.h>
#include <lz4.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <zlib.h>
#include <zstd.h>

#include "zarr.h"

enum {
    W_NONE,
    W_BLOSC_LZ4,
    W_BLOSC_ZSTD_BIT,
    W_ZLIB,
    W_GZIP,
    W_ZSTD,
    W_LZ4
};

typedef struct spec {
    int version, codec, crc, big, slash, v2keys;
    int nd;
    uint64_t shape[5], chunk[5], inner[5]; /* inner[0] != 0: sharded (v3) */
} spec;

static const int16_t *vol;
static uint64_t VX, VY, VZ;
static char dtype_kind = 'i'; /* v2 arrays: 'u' writes the same bits as uint16 (--bench) */
static int16_t fill;          /* the fill value: the volume's first sample (its background) */
static uint64_t stride = 1;   /* 2: scale 1 of an OME image, every other sample */

/* 5-D (t, c, z, y, x): the volume at t = 1, c = 2, 7 elsewhere; 4-D (c, z, y, x): at c = 2. */
static int16_t sample(const spec *s, const uint64_t *i)
{
    int n = s->nd;
    if ((n == 5 && (i[0] != 1 || i[1] != 2)) || (n == 4 && i[0] != 2))
        return 7;
    uint64_t z = i[n - 3] * stride, y = i[n - 2] * stride, x = i[n - 1] * stride;
    return vol[(z * VY + y) * VX + x];
}

static void mkdirs(const char *path)
{
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s", path);
    for (char *p = tmp + 1; *p; p++)
        if (*p == '/') {
            *p = 0;
            mkdir(tmp, 0755);
            *p = '/';
        }
    mkdir(tmp, 0755);
}

static void write_file(const char *path, const void *data, size_t size)
{
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", path);
    *strrchr(dir, '/') = 0;
    mkdirs(dir);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(data, 1, size, f) != size || fclose(f) != 0) {
        fprintf(stderr, "make_zarr: cannot write %s\n", path);
        exit(1);
    }
}

/* Encodes `raw` by the spec's codec (and crc32c) into out; returns the size. */
static size_t encode(const spec *s, const unsigned char *raw, size_t n, unsigned char *out)
{
    size_t m = n;
    uLongf zl;
    switch (s->codec) {
    case W_NONE: memcpy(out, raw, n); break;
    case W_BLOSC_LZ4:
    case W_BLOSC_ZSTD_BIT:
        m = (size_t)blosc_compress_ctx(5, s->codec == W_BLOSC_LZ4 ? 1 : 2, 2, n, raw, out,
                                       n + BLOSC_MAX_OVERHEAD,
                                       s->codec == W_BLOSC_LZ4 ? "lz4" : "zstd", 0, 1);
        break;
    case W_ZLIB:
        zl = compressBound(n);
        compress2(out, &zl, raw, n, 6);
        m = zl;
        break;
    case W_GZIP: {
        z_stream zs = {0};
        deflateInit2(&zs, 6, Z_DEFLATED, 31, 8, Z_DEFAULT_STRATEGY);
        zs.next_in = (Bytef *)raw;
        zs.avail_in = (uInt)n;
        zs.next_out = out;
        zs.avail_out = (uInt)(2 * n + 64);
        deflate(&zs, Z_FINISH);
        m = zs.total_out;
        deflateEnd(&zs);
        break;
    }
    case W_ZSTD: m = ZSTD_compress(out, 2 * n + 64, raw, n, 3); break;
    case W_LZ4:
        out[0] = (unsigned char)n, out[1] = (unsigned char)(n >> 8),
        out[2] = (unsigned char)(n >> 16), out[3] = (unsigned char)(n >> 24);
        m = 4 + (size_t)LZ4_compress_default((const char *)raw, (char *)out + 4, (int)n,
                                             (int)(2 * n + 64));
        break;
    }
    if (s->crc) {
        uint32_t c = ip__crc32c(out, m);
        for (int k = 0; k < 4; k++)
            out[m++] = (unsigned char)(c >> (8 * k));
    }
    return m;
}

/* The chunk (of shape cs) at grid index g, samples in the spec's byte order; 1 if all fill. */
static int gather(const spec *s, const uint64_t *cs, const uint64_t *g, unsigned char *raw,
                  size_t *n)
{
    uint64_t count = 1, i[5];
    int zero = 1;
    for (int d = 0; d < s->nd; d++)
        count *= cs[d];
    for (uint64_t k = 0; k < count; k++) {
        uint64_t r = k;
        int inside = 1;
        for (int d = s->nd - 1; d >= 0; d--) {
            i[d] = g[d] * cs[d] + r % cs[d];
            r /= cs[d];
            inside &= i[d] < s->shape[d];
        }
        int16_t v = inside ? sample(s, i) : fill;
        zero &= v == fill;
        raw[2 * k + (s->big ? 1 : 0)] = (unsigned char)(v & 0xff);
        raw[2 * k + (s->big ? 0 : 1)] = (unsigned char)((uint16_t)v >> 8);
    }
    *n = (size_t)count * 2;
    return zero;
}

static void key(const spec *s, const char *folder, const uint64_t *g, char *out)
{
    char sep = s->slash ? '/' : '.';
    int len = sprintf(out, "%s/%s", folder, s->version == 3 && !s->v2keys ? "c" : "");
    for (int d = 0; d < s->nd; d++)
        len += sprintf(out + len, "%s%llu",
                       d == 0 && (s->version == 2 || s->v2keys) ? "" : (char[]){sep, 0},
                       (unsigned long long)g[d]);
}

/* Walks the grid of chunks (or shards) of shape cs and writes each one not all zero. */
static void write_chunks(const spec *s, const char *folder)
{
    const uint64_t *cs = s->chunk;
    uint64_t grid[5], total = 1, g[5];
    for (int d = 0; d < s->nd; d++) {
        grid[d] = (s->shape[d] + cs[d] - 1) / cs[d];
        total *= grid[d];
    }
    size_t max = 2;
    for (int d = 0; d < s->nd; d++)
        max *= cs[d];
    unsigned char *raw = malloc(max), *enc = malloc(2 * max + 4096),
                  *shard = malloc(4 * max + 65536);
    char path[4096];
    for (uint64_t k = 0; k < total; k++) {
        uint64_t r = k;
        for (int d = s->nd - 1; d >= 0; d--) {
            g[d] = r % grid[d];
            r /= grid[d];
        }
        key(s, folder, g, path);
        size_t n, m;
        if (!s->inner[0]) {
            if (gather(s, cs, g, raw, &n))
                continue;
            m = encode(s, raw, n, enc);
            write_file(path, enc, m);
            continue;
        }
        /* a shard: inner chunks in C order, then the index (offset, size) and its crc32c */
        uint64_t per[5], inner_count = 1, ig[5];
        for (int d = 0; d < s->nd; d++) {
            per[d] = cs[d] / s->inner[d];
            inner_count *= per[d];
        }
        unsigned char *index = malloc(inner_count * 16 + 4);
        size_t at = 0;
        int any = 0;
        for (uint64_t j = 0; j < inner_count; j++) {
            uint64_t rr = j, off = UINT64_MAX, len = UINT64_MAX;
            for (int d = s->nd - 1; d >= 0; d--) {
                ig[d] = g[d] * per[d] + rr % per[d];
                rr /= per[d];
            }
            if (!gather(s, s->inner, ig, raw, &n)) {
                m = encode(s, raw, n, shard + at);
                off = at, len = m;
                at += m;
                any = 1;
            }
            for (int b = 0; b < 8; b++) {
                index[16 * j + b] = (unsigned char)(off >> (8 * b));
                index[16 * j + 8 + b] = (unsigned char)(len >> (8 * b));
            }
        }
        uint32_t c = ip__crc32c(index, inner_count * 16);
        for (int b = 0; b < 4; b++)
            index[inner_count * 16 + b] = (unsigned char)(c >> (8 * b));
        memcpy(shard + at, index, inner_count * 16 + 4);
        if (any)
            write_file(path, shard, at + inner_count * 16 + 4);
        free(index);
    }
    free(raw), free(enc), free(shard);
}

static void list(FILE *f, const uint64_t *v, int n)
{
    fputc('[', f);
    for (int d = 0; d < n; d++)
        fprintf(f, "%s%llu", d ? ", " : "", (unsigned long long)v[d]);
    fputc(']', f);
}

static const char *v3_codec(const spec *s)
{
    switch (s->codec) {
    case W_BLOSC_LZ4:
        return "{\"name\": \"blosc\", \"configuration\": {\"cname\": \"lz4\", \"clevel\": 5, "
               "\"shuffle\": \"shuffle\", \"typesize\": 2, \"blocksize\": 0}}";
    case W_GZIP: return "{\"name\": \"gzip\", \"configuration\": {\"level\": 5}}";
    case W_ZSTD:
        return "{\"name\": \"zstd\", \"configuration\": {\"level\": 3, \"checksum\": false}}";
    }
    return NULL;
}

static void v3_codecs(FILE *f, const spec *s)
{
    const char *c = v3_codec(s);
    fprintf(f, "[{\"name\": \"bytes\", \"configuration\": {\"endian\": \"%s\"}}%s%s%s]",
            s->big ? "big" : "little", c ? ", " : "", c ? c : "",
            s->crc ? ", {\"name\": \"crc32c\"}" : "");
}

/* The array's metadata and chunks in `folder`. */
static void write_array(const spec *s, const char *folder)
{
    static const char *const v2ids[] = {"null", "blosc", "blosc", "zlib", "gzip", "zstd", "lz4"};
    char path[4096];
    mkdirs(folder);
    snprintf(path, sizeof path, "%s/%s", folder, s->version == 2 ? ".zarray" : "zarr.json");
    FILE *f = fopen(path, "w");
    if (s->version == 2) {
        fprintf(f, "{\"zarr_format\": 2, \"shape\": ");
        list(f, s->shape, s->nd);
        fprintf(f, ", \"chunks\": ");
        list(f, s->chunk, s->nd);
        fprintf(f,
                ", \"dtype\": \"%c%c2\", \"fill_value\": %d, \"order\": \"C\", \"filters\": null, ",
                s->big ? '>' : '<', dtype_kind, fill);
        if (s->codec == W_NONE)
            fprintf(f, "\"compressor\": null");
        else
            fprintf(f, "\"compressor\": {\"id\": \"%s\"}", v2ids[s->codec]);
        fprintf(f, ", \"dimension_separator\": \"%c\"}\n", s->slash ? '/' : '.');
    } else {
        fprintf(f, "{\"zarr_format\": 3, \"node_type\": \"array\", \"shape\": ");
        list(f, s->shape, s->nd);
        fprintf(f, ", \"data_type\": \"int16\", \"chunk_grid\": {\"name\": \"regular\", "
                   "\"configuration\": {\"chunk_shape\": ");
        list(f, s->chunk, s->nd);
        fprintf(f,
                "}}, \"chunk_key_encoding\": {\"name\": \"%s\", \"configuration\": "
                "{\"separator\": \"%c\"}}, \"fill_value\": %d, \"codecs\": ",
                s->v2keys ? "v2" : "default", s->slash ? '/' : '.', fill);
        if (s->inner[0]) {
            fprintf(f, "[{\"name\": \"sharding_indexed\", \"configuration\": {\"chunk_shape\": ");
            list(f, s->inner, s->nd);
            fprintf(f, ", \"codecs\": ");
            v3_codecs(f, s);
            fprintf(f, ", \"index_codecs\": [{\"name\": \"bytes\", \"configuration\": "
                       "{\"endian\": \"little\"}}, {\"name\": \"crc32c\"}], "
                       "\"index_location\": \"end\"}}]");
        } else {
            v3_codecs(f, s);
        }
        fprintf(f, ", \"attributes\": {}}\n");
    }
    fclose(f);
    write_chunks(s, folder);
}

/* An OME-Zarr image of two scales (the volume, every other sample) in `folder`: version 0.4
 * (Zarr v2, axes t, c, z, y, x in micrometer) or 0.5 (Zarr v3 sharded, axes c, z, y, x; z in
 * millimeter, converted to the micrometer of x). */
static void write_ome(const char *folder, int v3)
{
    char path[4096];
    int nd = v3 ? 4 : 5;
    mkdirs(folder);
    snprintf(path, sizeof path, "%s/%s", folder, v3 ? "zarr.json" : ".zattrs");
    FILE *f = fopen(path, "w");
    const char *axes = v3 ? "[{\"name\": \"c\", \"type\": \"channel\"}, "
                            "{\"name\": \"z\", \"type\": \"space\", \"unit\": \"millimeter\"}, "
                            "{\"name\": \"y\", \"type\": \"space\", \"unit\": \"micrometer\"}, "
                            "{\"name\": \"x\", \"type\": \"space\", \"unit\": \"micrometer\"}]"
                          : "[{\"name\": \"t\", \"type\": \"time\"}, {\"name\": \"c\", \"type\": "
                            "\"channel\"}, {\"name\": \"z\", \"type\": \"space\", \"unit\": "
                            "\"micrometer\"}, {\"name\": \"y\", \"type\": \"space\", \"unit\": "
                            "\"micrometer\"}, {\"name\": \"x\", \"type\": \"space\", \"unit\": "
                            "\"micrometer\"}]";
    const char *lead = v3 ? "1, " : "1, 1, ";
    const char *zero = v3 ? "0, " : "0, 0, ";
    double z0 = v3 ? 0.00125 : 1.25, t = v3 ? 0 : 10;
    fprintf(f,
            "%s\"multiscales\": [{\"version\": \"%s\", \"axes\": %s, \"datasets\": ["
            "{\"path\": \"0\", \"coordinateTransformations\": [{\"type\": \"scale\", "
            "\"scale\": [%s%g, 0.5, 0.5]}, {\"type\": \"translation\", \"translation\": "
            "[%s%g, -5, 2.5]}]}, "
            "{\"path\": \"1\", \"coordinateTransformations\": [{\"type\": \"scale\", "
            "\"scale\": [%s%g, 1, 1]}]}]}]%s}\n",
            v3 ? "{\"zarr_format\": 3, \"node_type\": \"group\", \"attributes\": {\"ome\": "
                 "{\"version\": \"0.5\", "
               : "{",
            v3 ? "0.5" : "0.4", axes, lead, z0, zero, t, lead, 2 * z0, v3 ? "}}" : "");
    fclose(f);
    if (!v3) {
        snprintf(path, sizeof path, "%s/.zgroup", folder);
        write_file(path, "{\"zarr_format\": 2}\n", 19);
    }
    for (int k = 0; k < 2; k++) {
        stride = (uint64_t)k + 1;
        spec s = {v3 ? 3 : 2, W_BLOSC_LZ4, 0, 0, 1, 0, nd, {0}, {0}, {0}};
        uint64_t dims[3] = {(VZ + stride - 1) / stride, (VY + stride - 1) / stride,
                            (VX + stride - 1) / stride};
        for (int d = 0; d < nd; d++) {
            s.shape[d] = d < nd - 3 ? (uint64_t)(v3 ? 3 : 2 + d) : dims[d - (nd - 3)];
            s.chunk[d] = d < nd - 3 ? 1 : 16;
            s.inner[d] = v3 ? (d < nd - 3 ? 1 : 8) : 0;
        }
        snprintf(path, sizeof path, "%s/%d", folder, k);
        write_array(&s, path);
    }
    stride = 1;
}

int main(int argc, char **argv)
{
    unsigned long long x, y, z;
    int bench = argc == 5 && !strcmp(argv[4], "--bench");
    if ((argc != 4 && !bench) || sscanf(argv[2], "%llux%llux%llu", &x, &y, &z) != 3) {
        fprintf(stderr, "usage: make_zarr RAW XxYxZ OUT_FOLDER [--bench]\n");
        return 2;
    }
    VX = x, VY = y, VZ = z;
    size_t n = (size_t)(x * y * z);
    int16_t *v = malloc(n * 2);
    FILE *f = fopen(argv[1], "rb");
    if (!f || fread(v, 2, n, f) != n) {
        fprintf(stderr, "make_zarr: cannot read %s\n", argv[1]);
        return 1;
    }
    fclose(f);
    vol = v;
    fill = v[0];
    /* version, codec, crc32c, big-endian, '/' keys, v2 keys (v3), then name */
    static const struct {
        spec s;
        const char *name;
    } variants[] = {
        {{2, W_BLOSC_LZ4, 0, 0, 0, 0, 3, {0}, {8, 8, 8}, {0}}, "v2_blosc_lz4.zarr"},
        {{2, W_BLOSC_ZSTD_BIT, 0, 1, 1, 0, 3, {0}, {5, 16, 7}, {0}}, "v2_blosc_zstd_be.zarr"},
        {{2, W_ZLIB, 0, 0, 0, 0, 3, {0}, {16, 8, 32}, {0}}, "v2_zlib.zarr"},
        {{2, W_GZIP, 0, 1, 0, 0, 3, {0}, {8, 16, 16}, {0}}, "v2_gzip_be.zarr"},
        {{2, W_ZSTD, 0, 0, 1, 0, 3, {0}, {27, 38, 45}, {0}}, "v2_zstd.zarr"},
        {{2, W_LZ4, 0, 0, 0, 0, 3, {0}, {4, 8, 8}, {0}}, "v2_lz4.zarr"},
        {{2, W_NONE, 0, 1, 1, 0, 3, {0}, {8, 8, 8}, {0}}, "v2_none_be.zarr"},
        {{3, W_BLOSC_LZ4, 0, 0, 1, 0, 3, {0}, {8, 8, 8}, {0}}, "v3_blosc.zarr"},
        {{3, W_GZIP, 1, 1, 0, 0, 3, {0}, {8, 16, 8}, {0}}, "v3_gzip_crc_be.zarr"},
        {{3, W_ZSTD, 0, 0, 0, 1, 3, {0}, {8, 8, 16}, {0}}, "v3_zstd_v2keys.zarr"},
        {{3, W_NONE, 1, 0, 1, 0, 3, {0}, {16, 16, 16}, {8, 8, 8}}, "v3_sharded.zarr"},
        {{3, W_BLOSC_LZ4, 1, 0, 1, 0, 3, {0}, {16, 32, 16}, {4, 8, 8}}, "v3_sharded_blosc.zarr"},
    };
    char path[4096];
    if (bench) {
        dtype_kind = 'u';
        spec s = {2, W_BLOSC_LZ4, 0, 0, 0, 0, 3, {z, y, x}, {64, 64, 64}, {0}};
        write_array(&s, argv[3]);
        free(v);
        return 0;
    }
    for (size_t i = 0; i < sizeof variants / sizeof variants[0]; i++) {
        spec s = variants[i].s;
        s.shape[0] = z, s.shape[1] = y, s.shape[2] = x;
        snprintf(path, sizeof path, "%s/%s", argv[3], variants[i].name);
        write_array(&s, path);
    }
    snprintf(path, sizeof path, "%s/ome04.zarr", argv[3]);
    write_ome(path, 0);
    snprintf(path, sizeof path, "%s/ome05.zarr", argv[3]);
    write_ome(path, 1);
    /* scale 1's samples as raw, for comparison */
    snprintf(path, sizeof path, "%s/half_%llux%llux%llu_int16.raw", argv[3], (x + 1) / 2,
             (y + 1) / 2, (z + 1) / 2);
    f = fopen(path, "wb");
    for (uint64_t k = 0; k < z; k += 2)
        for (uint64_t j = 0; j < y; j += 2)
            for (uint64_t i = 0; i < x; i += 2)
                fwrite(&v[(k * y + j) * x + i], 2, 1, f);
    fclose(f);
    free(v);
    return 0;
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* Zarr metadata through cJSON: an array's .zarray (v2) or zarr.json (v3), and an OME-Zarr
 * image's multiscales (0.4 in .zattrs, 0.5 in zarr.json's attributes.ome). Every refusal is
 * one line naming the metadata file and the key. */
#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "atomic_file.h"
#include "internal.h"
#include "zarr.h"

/* Metadata files larger than this are refused (a real one is a few KiB). */
#define META_LIMIT ((off_t)16 << 20)

ip_status ip__zarr_read_text(const char *path, char **out, int *missing, ip_error *err)
{
    int fd;
    struct stat st;
    *out = NULL;
    *missing = access(path, F_OK) != 0 && errno == ENOENT;
    if (*missing)
        return IP_OK;
    ip_status s = ip__input_open_regular(path, &fd, err);
    if (s != IP_OK)
        return s;
    if (fstat(fd, &st) != 0 || st.st_size > META_LIMIT) {
        close(fd);
        return ip__fail(err, IP_ERR_INPUT, "%s: a metadata file over 16 MiB", path);
    }
    char *text = malloc((size_t)st.st_size + 1);
    if (!text) {
        close(fd);
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", path);
    }
    s = ip__pread_all(fd, text, (size_t)st.st_size, 0, path, err);
    close(fd);
    if (s != IP_OK) {
        free(text);
        return s;
    }
    text[st.st_size] = '\0';
    *out = text;
    return IP_OK;
}

const char *ip__zarr_shown(const char *text, char *buf, size_t size)
{
    size_t i = 0;
    for (; text && text[i] && i + 1 < size; i++)
        buf[i] = (unsigned char)text[i] < 0x20 || text[i] == 0x7f ? '?' : text[i];
    if (!text)
        buf[i++] = '?';
    buf[i] = '\0';
    return buf;
}

static ip_status bad(const char *name, const char *what, ip_error *err)
{
    return ip__fail(err, IP_ERR_INPUT, "%s: %s", name, what);
}

/* A JSON array of 1 .. ZARR_MAX_DIMS positive integers below 2^53. */
static ip_status read_dims(const char *name, const cJSON *list, const char *key, uint64_t *dims,
                           uint32_t *n, ip_error *err)
{
    int count = cJSON_IsArray(list) ? cJSON_GetArraySize(list) : -1;
    if (count < 1 || count > ZARR_MAX_DIMS)
        return ip__fail(err, IP_ERR_INPUT, "%s: '%s' is not a list of 1 to %d sizes", name, key,
                        ZARR_MAX_DIMS);
    for (int i = 0; i < count; i++) {
        const cJSON *v = cJSON_GetArrayItem(list, i);
        double d = cJSON_IsNumber(v) ? v->valuedouble : -1;
        if (!(d >= 1 && d < 9007199254740992.0) || d != floor(d))
            return ip__fail(err, IP_ERR_INPUT, "%s: '%s' holds %s, not a positive integer", name,
                            key, cJSON_IsNumber(v) ? "a number out of range" : "a non-number");
        dims[i] = (uint64_t)d;
    }
    *n = (uint32_t)count;
    return IP_OK;
}

/* The stored type: kind 'u'/'i'/'f' and bytes; what it is read as (docs/input.md). */
static ip_status take_type(const char *name, const char *text, char kind, uint32_t item,
                           zarr_array *a, ip_error *err)
{
    char shown[48];
    a->kind = kind;
    a->item = item;
    if (kind == 'u' && item == 1)
        a->type = IP_UINT8;
    else if (kind == 'u' && item == 2)
        a->type = IP_UINT16;
    else if (kind == 'i' && (item == 1 || item == 2))
        a->type = IP_INT16;
    else if ((kind == 'u' || kind == 'i' || kind == 'f') && item == 4)
        a->type = IP_FLOAT32;
    else
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: data type %s is not read (uint8, int8, uint16, int16, uint32, int32 "
                        "and float32 are)",
                        name, ip__zarr_shown(text, shown, sizeof shown));
    return IP_OK;
}

/* v2 "dtype": "<u2", ">f4", "|u1", ... */
static ip_status v2_dtype(const char *name, const cJSON *v, zarr_array *a, ip_error *err)
{
    const char *t = cJSON_GetStringValue(v);
    if (!t || strlen(t) != 3 || !strchr("<>|", t[0]) || t[2] < '1' || t[2] > '8')
        return bad(name,
                   "'dtype' is not a simple type such as \"<u2\" (structured types are not "
                   "read)",
                   err);
    a->chain.big_endian = t[0] == '>';
    return take_type(name, t, t[1], (uint32_t)(t[2] - '0'), a, err);
}

/* A fill value: a number, null (0), or "NaN", "Infinity", "-Infinity". */
static ip_status fill_value(const char *name, const cJSON *v, zarr_array *a, ip_error *err)
{
    const char *t = cJSON_GetStringValue(v);
    if (!v || cJSON_IsNull(v))
        a->fill = 0;
    else if (cJSON_IsNumber(v))
        a->fill = v->valuedouble;
    else if (cJSON_IsBool(v))
        a->fill = cJSON_IsTrue(v);
    else if (t && !strcmp(t, "NaN"))
        a->fill = NAN;
    else if (t && (!strcmp(t, "Infinity") || !strcmp(t, "-Infinity")))
        a->fill = t[0] == '-' ? -INFINITY : INFINITY;
    else
        return bad(name, "'fill_value' is not a number", err);
    return IP_OK;
}

/* v2 "compressor": null or {"id": ...}; blosc's cname and shuffle are in its own header. */
static ip_status v2_compressor(const char *name, const cJSON *c, zarr_chain *chain, ip_error *err)
{
    char shown[48];
    static const struct {
        const char *id;
        zarr_codec_id codec;
    } known[] = {{"blosc", ZARR_BLOSC},
                 {"zlib", ZARR_ZLIB},
                 {"gzip", ZARR_GZIP},
                 {"zstd", ZARR_ZSTD},
                 {"lz4", ZARR_LZ4}};
    chain->count = 0;
    if (!c || cJSON_IsNull(c))
        return IP_OK;
    const char *id = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(c, "id"));
    for (size_t i = 0; id && i < sizeof known / sizeof known[0]; i++)
        if (!strcmp(id, known[i].id)) {
            chain->codecs[chain->count++] = known[i].codec;
            return IP_OK;
        }
    return ip__fail(err, IP_ERR_INPUT,
                    "%s: compressor '%s' is not read (blosc, zlib, gzip, zstd, lz4 and none are)",
                    name, ip__zarr_shown(id, shown, sizeof shown));
}

static ip_status parse_v2(const char *name, const cJSON *j, zarr_array *a, ip_error *err)
{
    char shown[48];
    uint32_t n;
    ip_status s;
    const cJSON *filters = cJSON_GetObjectItemCaseSensitive(j, "filters");
    const char *order = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(j, "order"));
    const char *sep =
        cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(j, "dimension_separator"));
    const cJSON *format = cJSON_GetObjectItemCaseSensitive(j, "zarr_format");
    if (!cJSON_IsNumber(format) || format->valuedouble != 2)
        return bad(name, "'zarr_format' is not 2", err);
    if ((s = read_dims(name, cJSON_GetObjectItemCaseSensitive(j, "shape"), "shape", a->shape,
                       &a->ndim, err)) != IP_OK ||
        (s = read_dims(name, cJSON_GetObjectItemCaseSensitive(j, "chunks"), "chunks", a->chunk, &n,
                       err)) != IP_OK)
        return s;
    if (n != a->ndim)
        return bad(name, "'chunks' and 'shape' have different lengths", err);
    if (order && strcmp(order, "C") != 0)
        return bad(name, "order \"F\" (Fortran) is not read, only \"C\"", err);
    if (filters && !cJSON_IsNull(filters) &&
        !(cJSON_IsArray(filters) && cJSON_GetArraySize(filters) == 0)) {
        const cJSON *first = cJSON_GetArrayItem(filters, 0);
        const char *id = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(first, "id"));
        return ip__fail(err, IP_ERR_INPUT, "%s: filter '%s' is not read (no filters are)", name,
                        ip__zarr_shown(id, shown, sizeof shown));
    }
    if (sep && strcmp(sep, ".") != 0 && strcmp(sep, "/") != 0)
        return bad(name, "'dimension_separator' is neither \".\" nor \"/\"", err);
    a->separator = sep ? sep[0] : '.';
    a->key_prefix = 0;
    if ((s = v2_dtype(name, cJSON_GetObjectItemCaseSensitive(j, "dtype"), a, err)) != IP_OK ||
        (s = fill_value(name, cJSON_GetObjectItemCaseSensitive(j, "fill_value"), a, err)) != IP_OK)
        return s;
    return v2_compressor(name, cJSON_GetObjectItemCaseSensitive(j, "compressor"), &a->chain, err);
}

/* ---- v3 ---- */

static const cJSON *config_of(const cJSON *codec, const char *key)
{
    return cJSON_GetObjectItemCaseSensitive(
        cJSON_GetObjectItemCaseSensitive(codec, "configuration"), key);
}

/* A v3 codec list without sharding: "bytes" (endian) first, then at most one compressor
 * (blosc, gzip, zstd) and crc32c. */
static ip_status v3_chain(const char *name, const cJSON *codecs, zarr_chain *chain, ip_error *err)
{
    char shown[48];
    int bytes_seen = 0;
    chain->count = 0;
    chain->big_endian = 0;
    const cJSON *c;
    cJSON_ArrayForEach(c, codecs)
    {
        const char *id = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(c, "name"));
        if (!id)
            return bad(name, "a codec without a name", err);
        if (!strcmp(id, "bytes") && !bytes_seen) {
            const char *endian = cJSON_GetStringValue(config_of(c, "endian"));
            chain->big_endian = endian && !strcmp(endian, "big");
            bytes_seen = 1;
            continue;
        }
        zarr_codec_id codec;
        if (!strcmp(id, "blosc"))
            codec = ZARR_BLOSC;
        else if (!strcmp(id, "gzip"))
            codec = ZARR_GZIP;
        else if (!strcmp(id, "zstd"))
            codec = ZARR_ZSTD;
        else if (!strcmp(id, "crc32c"))
            codec = ZARR_CRC32C;
        else
            return ip__fail(err, IP_ERR_INPUT,
                            "%s: codec '%s' is not read here (bytes, blosc, gzip, zstd, crc32c "
                            "and sharding_indexed are)",
                            name, ip__zarr_shown(id, shown, sizeof shown));
        int fits = codec == ZARR_CRC32C
                       ? chain->count == 0 || (chain->count == 1 && chain->codecs[0] != ZARR_CRC32C)
                       : chain->count == 0;
        if (!bytes_seen || !fits)
            return ip__fail(err, IP_ERR_INPUT,
                            "%s: codec '%s' in an order not read (bytes, then one compressor, "
                            "then crc32c)",
                            name, ip__zarr_shown(id, shown, sizeof shown));
        chain->codecs[chain->count++] = codec;
    }
    if (!bytes_seen)
        return bad(name, "no 'bytes' codec (transpose and other array codecs are not read)", err);
    return IP_OK;
}

static ip_status v3_sharding(const char *name, const cJSON *codec, zarr_array *a, ip_error *err)
{
    uint32_t n;
    const char *where = cJSON_GetStringValue(config_of(codec, "index_location"));
    ip_status s =
        read_dims(name, config_of(codec, "chunk_shape"), "chunk_shape", a->inner, &n, err);
    if (s != IP_OK)
        return s;
    if (n != a->ndim)
        return bad(name, "the shard's 'chunk_shape' and 'shape' have different lengths", err);
    for (uint32_t d = 0; d < n; d++)
        if (a->chunk[d] % a->inner[d] != 0)
            return bad(name, "the inner chunk shape does not divide the shard shape", err);
    if ((s = v3_chain(name, config_of(codec, "codecs"), &a->chain, err)) != IP_OK ||
        (s = v3_chain(name, config_of(codec, "index_codecs"), &a->index_chain, err)) != IP_OK)
        return s;
    if (a->index_chain.count > 1 ||
        (a->index_chain.count == 1 && a->index_chain.codecs[0] != ZARR_CRC32C))
        return bad(name, "index codecs other than bytes and crc32c are not read", err);
    a->index_at_start = where && !strcmp(where, "start");
    a->sharded = 1;
    return IP_OK;
}

static ip_status v3_codecs(const char *name, const cJSON *codecs, zarr_array *a, ip_error *err)
{
    const cJSON *first = cJSON_GetArrayItem(codecs, 0);
    const char *id = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(first, "name"));
    if (!cJSON_IsArray(codecs) || !first)
        return bad(name, "'codecs' is not a list of codecs", err);
    if (id && !strcmp(id, "sharding_indexed")) {
        if (cJSON_GetArraySize(codecs) != 1)
            return bad(name, "codecs after sharding_indexed are not read", err);
        return v3_sharding(name, first, a, err);
    }
    return v3_chain(name, codecs, &a->chain, err);
}

static ip_status v3_type(const char *name, const cJSON *v, zarr_array *a, ip_error *err)
{
    static const struct {
        const char *text;
        char kind;
        uint32_t item;
    } types[] = {{"uint8", 'u', 1},  {"int8", 'i', 1},  {"uint16", 'u', 2}, {"int16", 'i', 2},
                 {"uint32", 'u', 4}, {"int32", 'i', 4}, {"float32", 'f', 4}};
    const char *t = cJSON_GetStringValue(v);
    for (size_t i = 0; t && i < sizeof types / sizeof types[0]; i++)
        if (!strcmp(t, types[i].text))
            return take_type(name, t, types[i].kind, types[i].item, a, err);
    return take_type(name, t ? t : "(not a string)", '?', 0, a, err);
}

/* The chunk key encoding: default ("c/0/0") or v2 ("0.0"), and its separator. */
static ip_status v3_keys(const char *name, const cJSON *enc, zarr_array *a, ip_error *err)
{
    const char *kind = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(enc, "name"));
    const char *sep = cJSON_GetStringValue(config_of(enc, "separator"));
    if (!kind || (strcmp(kind, "default") != 0 && strcmp(kind, "v2") != 0))
        return bad(name, "'chunk_key_encoding' is neither default nor v2", err);
    a->key_prefix = !strcmp(kind, "default");
    a->separator = sep ? sep[0] : (a->key_prefix ? '/' : '.');
    if (a->separator != '.' && a->separator != '/')
        return bad(name, "the chunk key separator is neither \".\" nor \"/\"", err);
    return IP_OK;
}

static ip_status parse_v3(const char *name, const cJSON *j, zarr_array *a, ip_error *err)
{
    uint32_t n;
    ip_status s;
    const cJSON *grid = cJSON_GetObjectItemCaseSensitive(j, "chunk_grid");
    const char *grid_name = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(grid, "name"));
    const char *node = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(j, "node_type"));
    const cJSON *transformers = cJSON_GetObjectItemCaseSensitive(j, "storage_transformers");
    if (!node || strcmp(node, "array") != 0)
        return bad(name, "'node_type' is not \"array\"", err);
    if (!grid_name || strcmp(grid_name, "regular") != 0)
        return bad(name, "'chunk_grid' is not regular", err);
    if (cJSON_GetArraySize(transformers) > 0)
        return bad(name, "storage transformers are not read", err);
    if ((s = read_dims(name, cJSON_GetObjectItemCaseSensitive(j, "shape"), "shape", a->shape,
                       &a->ndim, err)) != IP_OK ||
        (s = read_dims(name, config_of(grid, "chunk_shape"), "chunk_shape", a->chunk, &n, err)) !=
            IP_OK)
        return s;
    if (n != a->ndim)
        return bad(name, "'chunk_shape' and 'shape' have different lengths", err);
    if ((s = v3_type(name, cJSON_GetObjectItemCaseSensitive(j, "data_type"), a, err)) != IP_OK ||
        (s = fill_value(name, cJSON_GetObjectItemCaseSensitive(j, "fill_value"), a, err)) !=
            IP_OK ||
        (s = v3_keys(name, cJSON_GetObjectItemCaseSensitive(j, "chunk_key_encoding"), a, err)) !=
            IP_OK)
        return s;
    return v3_codecs(name, cJSON_GetObjectItemCaseSensitive(j, "codecs"), a, err);
}

/* An integer type's fill value must be a whole number within its range. */
static ip_status check_fill(const char *name, const zarr_array *a, ip_error *err)
{
    if (a->kind == 'f')
        return IP_OK;
    double bits = 8.0 * a->item, lo = a->kind == 'u' ? 0 : -ldexp(1, (int)bits - 1),
           hi = a->kind == 'u' ? ldexp(1, (int)bits) - 1 : ldexp(1, (int)bits - 1) - 1;
    if (a->fill == floor(a->fill) && a->fill >= lo && a->fill <= hi)
        return IP_OK;
    return ip__fail(err, IP_ERR_INPUT, "%s: 'fill_value' %g is not a value of the data type", name,
                    a->fill);
}

/* A chunk (an inner chunk) of at most 1 GiB decoded, a shard of at most 2^24 inner chunks. */
static ip_status check_sizes(const char *name, const zarr_array *a, ip_error *err)
{
    const uint64_t limit = (uint64_t)1 << 30;
    uint64_t bytes = a->item, inner = 1;
    for (uint32_t d = 0; d < a->ndim; d++) {
        uint64_t unit = a->sharded ? a->inner[d] : a->chunk[d];
        bytes = unit > limit ? limit + 1 : bytes * unit;
        if (bytes > limit)
            return bad(name, "a chunk of more than 1 GiB is not read", err);
        if (a->sharded) {
            uint64_t per = a->chunk[d] / a->inner[d];
            inner = per > limit ? limit + 1 : inner * per;
            if (inner > ((uint64_t)1 << 24))
                return bad(name, "a shard of more than 2^24 inner chunks is not read", err);
        }
    }
    return IP_OK;
}

ip_status ip__zarr_parse_array(const char *name, const char *text, int version, zarr_array *a,
                               ip_error *err)
{
    cJSON *j = cJSON_Parse(text);
    if (!cJSON_IsObject(j)) {
        cJSON_Delete(j);
        return bad(name, "not JSON (or not a JSON object)", err);
    }
    a->version = version;
    ip_status s = version == 2 ? parse_v2(name, j, a, err) : parse_v3(name, j, a, err);
    cJSON_Delete(j);
    if (s == IP_OK)
        s = check_fill(name, a, err);
    return s == IP_OK ? check_sizes(name, a, err) : s;
}

ip_status ip__zarr_read_array(const char *folder, zarr_array *a, ip_error *err)
{
    char path[IP_PATH_MAX + 16];
    char *text = NULL;
    int missing = 0;
    memset(a, 0, sizeof *a);
    snprintf(a->folder, sizeof a->folder, "%s", folder);
    int version = 2;
    snprintf(path, sizeof path, "%s/.zarray", folder);
    ip_status s = ip__zarr_read_text(path, &text, &missing, err);
    if (s == IP_OK && missing) {
        version = 3;
        snprintf(path, sizeof path, "%s/zarr.json", folder);
        s = ip__zarr_read_text(path, &text, &missing, err);
        if (s == IP_OK && missing)
            return ip__fail(err, IP_ERR_INPUT,
                            "%s: no Zarr array here (neither .zarray nor "
                            "zarr.json)",
                            folder);
    }
    if (s != IP_OK)
        return s;
    s = ip__zarr_parse_array(path, text, version, a, err);
    free(text);
    return s;
}

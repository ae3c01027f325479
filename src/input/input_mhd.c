/* MetaImage headers (.mhd with a separate data file, .mha or ElementDataFile = LOCAL with the
 * data right after the header): "Key = Value" lines ending with ElementDataFile. */
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "input_headers.h"
#include "internal.h"
#include "text_header.h"

typedef struct mhd_header {
    ip_text_place at;       /* first: see ip_text_place */
    int64_t ndims;          /* 0 until the key is seen */
    int dims_count;         /* -1 until the key is seen */
    uint64_t dims[3];
    int has_type;
    ip_type type;
    int spacing_count;      /* -1 until the key is seen */
    double spacing[3];
    int size_count;         /* ElementSize: the spacing when ElementSpacing is absent */
    double size[3];
    int has_msb;
    int msb;
    int compressed;
    int64_t header_size;
    int has_data_file;
    int local;
    char data_path[IP_PATH_MAX];
} mhd_header;

static ip_status parse_ndims(void *header, const ip_text_key *key, char *value, ip_error *err)
{
    mhd_header *h = header;
    if (ip__text_parse_i64(value, &h->ndims) != 0 || h->ndims < 1)
        return ip__text_bad_value(h, key->name, value, "not a positive whole number", err);
    if (h->ndims != 3)
        return ip__fail(err, IP_ERR_INPUT, "%s: NDims %lld is not supported (need 3)", h->at.path,
                       (long long)h->ndims);
    return IP_OK;
}

static ip_status parse_element_type(void *header, const ip_text_key *key, char *value,
                                    ip_error *err)
{
    mhd_header *h = header;
    (void)key;
    if (ip__type_from_name(value, IP_TYPE_SPELLING_METAIMAGE, &h->type) == IP_OK) {
        h->has_type = 1;
        return IP_OK;
    }
    return ip__fail(err, IP_ERR_INPUT,
                   "%s: unsupported MetaImage ElementType '%.80s' (supported: MET_UCHAR, "
                   "MET_USHORT, MET_SHORT, MET_FLOAT)", h->at.path, value);
}

static ip_status parse_msb(void *header, const ip_text_key *key, char *value, ip_error *err)
{
    mhd_header *h = header;
    if (ip__text_parse_bool(value, &h->msb) != 0)
        return ip__text_bad_value(h, key->name, value, "not True or False", err);
    h->has_msb = 1;
    return IP_OK;
}

static ip_status parse_compressed(void *header, const ip_text_key *key, char *value, ip_error *err)
{
    mhd_header *h = header;
    if (ip__text_parse_bool(value, &h->compressed) != 0)
        return ip__text_bad_value(h, key->name, value, "not True or False", err);
    return IP_OK;
}

static ip_status parse_header_size(void *header, const ip_text_key *key, char *value, ip_error *err)
{
    mhd_header *h = header;
    if (ip__text_parse_i64(value, &h->header_size) != 0 || h->header_size < -1)
        return ip__text_bad_value(h, key->name, value, "not -1 or a byte count", err);
    return IP_OK;
}

static ip_status parse_channels(void *header, const ip_text_key *key, char *value, ip_error *err)
{
    mhd_header *h = header;
    int64_t channels;
    if (ip__text_parse_i64(value, &channels) != 0 || channels < 1)
        return ip__text_bad_value(h, key->name, value, "not a positive whole number", err);
    if (channels != 1)
        return ip__fail(err, IP_ERR_INPUT,
                       "%s: ElementNumberOfChannels %lld is not supported (need 1)", h->at.path,
                       (long long)channels);
    return IP_OK;
}

static ip_status parse_binary(void *header, const ip_text_key *key, char *value, ip_error *err)
{
    mhd_header *h = header;
    int binary;
    if (ip__text_parse_bool(value, &binary) != 0)
        return ip__text_bad_value(h, key->name, value, "not True or False", err);
    if (!binary)
        return ip__fail(err, IP_ERR_INPUT, "%s: text data (BinaryData = False) are not supported",
                       h->at.path);
    return IP_OK;
}

static ip_status parse_data_file(void *header, const ip_text_key *key, char *value, ip_error *err)
{
    mhd_header *h = header;
    (void)key;
    h->has_data_file = 1;
    if (strcmp(value, "LOCAL") == 0) {
        h->local = 1;
        return IP_OK;
    }
    /* "LIST" and "pattern%03d.raw first last step" spread the data over several files. */
    if (strncmp(value, "LIST", 4) == 0 || strchr(value, '%'))
        return ip__fail(err, IP_ERR_INPUT,
                       "%s: data split over several files ('ElementDataFile = %.80s') is not "
                       "supported", h->at.path, value);
    return ip__text_data_path(h->at.path, value, h->data_path, err);
}

#define LIST(field) offsetof(mhd_header, field), offsetof(mhd_header, field##_count)
static const ip_text_key mhd_key_list[] = {
    {"NDims", BY_DIMS, parse_ndims, 0, 0},
    {"DimSize", BY_DIMS, ip__text_key_u64s, LIST(dims)},
    {"ElementType", BY_TYPE, parse_element_type, 0, 0},
    {"ElementSpacing", BY_SPACING, ip__text_key_doubles, LIST(spacing)},
    {"ElementSize", BY_SPACING, ip__text_key_doubles, LIST(size)},
    {"BinaryDataByteOrderMSB", BY_ENDIAN, parse_msb, 0, 0},
    {"ElementByteOrderMSB", BY_ENDIAN, parse_msb, 0, 0},
    {"CompressedData", BY_NOTHING, parse_compressed, 0, 0},
    {"HeaderSize", BY_NOTHING, parse_header_size, 0, 0},
    {"ElementNumberOfChannels", BY_NOTHING, parse_channels, 0, 0},
    {"BinaryData", BY_NOTHING, parse_binary, 0, 0},
    {"ElementDataFile", BY_NOTHING, parse_data_file, 0, 0},
};
#undef LIST
static const ip_text_keys mhd_keys = {mhd_key_list, sizeof mhd_key_list / sizeof mhd_key_list[0],
                                      1, NULL};

/* One "Key = Value" line; keys the reader does not need (ObjectType, Offset,
 * TransformMatrix, ...) are skipped. */
static ip_status parse_line(mhd_header *h, char *line, const ip_input_overrides *overrides,
                            ip_error *err)
{
    char *equals = strchr(line, '=');
    if (!equals)
        return ip__fail(err, IP_ERR_INPUT, "%s: line %lu is not 'Key = Value': '%.80s'", h->at.path,
                       h->at.line_number, line);
    *equals = '\0';
    return ip__text_dispatch(&mhd_keys, h, ip__text_trim(line), ip__text_trim(equals + 1),
                             overrides, err);
}

/* Reads keys up to ElementDataFile, which the format puts last. */
static ip_status read_keys(ip_text_file *file, mhd_header *h,
                           const ip_input_overrides *overrides, ip_error *err)
{
    int got;
    ip_status status = IP_OK;
    while (!h->has_data_file && (status = ip__text_next_line(file, &got, err)) == IP_OK && got) {
        char *line = ip__text_trim(file->line);
        if (line[0] == '\0' || line[0] == '#')
            continue;
        h->at.line_number = file->line_number;
        if ((status = parse_line(h, line, overrides, err)) != IP_OK)
            return status;
    }
    if (h->has_data_file)
        return IP_OK;
    if (status != IP_OK)
        return status;
    if (h->at.line_number == 0)
        return ip__fail(err, IP_ERR_INPUT, "%s: empty MetaImage header", h->at.path);
    return ip__fail(err, IP_ERR_INPUT, "%s: missing key 'ElementDataFile'", h->at.path);
}

static ip_status missing(const mhd_header *h, const char *key, ip_error *err)
{
    return ip__fail(err, IP_ERR_INPUT, "%s: missing key '%s'", h->at.path, key);
}

static ip_status check_keys(const mhd_header *h, const ip_input_overrides *overrides,
                            ip_error *err)
{
    int dims_given = overrides && overrides->has_dims;
    if (!dims_given && h->ndims == 0)
        return missing(h, "NDims", err);
    if (!dims_given && h->dims_count < 0)
        return missing(h, "DimSize", err);
    if (!dims_given && h->dims_count != 3)
        return ip__fail(err, IP_ERR_INPUT, "%s: DimSize has %d values, NDims is 3", h->at.path,
                       h->dims_count);
    if (!(overrides && overrides->has_type) && !h->has_type)
        return missing(h, "ElementType", err);
    if (h->spacing_count >= 0 && h->spacing_count != 3)
        return ip__fail(err, IP_ERR_INPUT, "%s: ElementSpacing has %d values, NDims is 3",
                       h->at.path, h->spacing_count);
    if (h->spacing_count < 0 && h->size_count >= 0 && h->size_count != 3)
        return ip__fail(err, IP_ERR_INPUT, "%s: ElementSize has %d values, NDims is 3",
                       h->at.path, h->size_count);
    if (h->compressed && h->header_size == -1)
        return ip__fail(err, IP_ERR_INPUT, "%s: HeaderSize -1 needs uncompressed data",
                       h->at.path);
    return IP_OK;
}

/* The data start HeaderSize bytes into the data file or, for LOCAL, into what follows the
 * header; HeaderSize -1 puts them at the end of the file. */
static void fill_desc(const mhd_header *h, uint64_t header_end, ip_input_desc *desc,
                      ip_text_found *found)
{
    if (h->has_type) {
        desc->type = h->type;
        found->has_type = 1;
    }
    if (h->dims_count == 3) {
        memcpy(found->dims, h->dims, sizeof found->dims);
        found->has_dims = 1;
    }
    desc->big_endian = h->has_msb ? h->msb : 0;
    desc->encoding = h->compressed ? IP_ENCODING_GZIP : IP_ENCODING_RAW;
    for (int axis = 0; axis < 3; axis++) {
        if (h->spacing_count == 3)
            desc->spacing[axis] = h->spacing[axis];
        else if (h->size_count == 3)
            desc->spacing[axis] = h->size[axis];
    }
    if (!h->local)
        snprintf(desc->data_path, sizeof desc->data_path, "%s", h->data_path);
    uint64_t base = h->local ? header_end : 0;
    if (h->header_size == -1)
        found->data_at_end = 1;
    else
        desc->data_offset = base + (uint64_t)h->header_size;
}

ip_status ip__mhd_read_header(const char *path, const ip_input_overrides *overrides,
                             ip_input_desc *desc, ip_text_found *found, ip_error *err)
{
    ip_text_file file;
    mhd_header *h = calloc(1, sizeof *h);
    if (!h)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory reading the header", path);
    h->at.path = path;
    h->dims_count = -1;
    h->spacing_count = -1;
    h->size_count = -1;
    ip_status status = ip__text_open(&file, path, err);
    if (status == IP_OK) {
        status = read_keys(&file, h, overrides, err);
        uint64_t header_end = file.offset;
        ip__text_close(&file);
        if (status == IP_OK)
            status = check_keys(h, overrides, err);
        if (status == IP_OK)
            fill_desc(h, header_end, desc, found);
    }
    free(h);
    return status;
}

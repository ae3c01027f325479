/* SPDX-License-Identifier: BSD-3-Clause */
/* MetaImage headers (.mhd with a separate data file, .mha or ElementDataFile = LOCAL with the
 * data right after the header): "Key = Value" lines ending with ElementDataFile. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "input_headers.h"
#include "internal.h"
#include "text_header.h"

typedef struct mhd_header {
    ip_text_place at; /* first: see ip_text_place */
    int64_t ndims;    /* 0 until the key is seen */
    int dims_count;   /* -1 until the key is seen */
    uint64_t dims[3];
    int has_type;
    ip_type type;
    int spacing_count; /* -1 until the key is seen */
    double spacing[3];
    int size_count; /* ElementSize: the spacing when ElementSpacing is absent */
    double size[3];
    int offset_count; /* Offset (or Position, Origin): -1 until the key is seen */
    double offset[3];
    int has_matrix;      /* TransformMatrix (or Rotation, Orientation) with 9 numbers */
    double matrix[3][3]; /* x axis direction, then y, then z */
    int has_msb;
    int msb;
    int compressed;
    int64_t header_size;
    int has_data_file;
    int local;
    char data_path[IP_PATH_MAX];
} mhd_header;

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
                        "supported",
                        h->at.path, value);
    return ip__text_data_path(h->at.path, value, h->data_path, err);
}

/* Nine numbers: the directions of the x, y and z axes, three each (as ITK writes them). */
static ip_status parse_matrix(void *header, const ip_text_key *key, char *value, ip_error *err)
{
    mhd_header *h = header;
    const char *p = value;
    for (int i = 0; i < 9; i++) {
        char *end;
        double v = strtod(p, &end);
        if (end == p || !isfinite(v))
            return ip__text_bad_value(h, key->name, value, "not 9 numbers", err);
        h->matrix[i / 3][i % 3] = v;
        p = end;
    }
    while (*p == ' ' || *p == '\t')
        p++;
    if (*p != '\0')
        return ip__text_bad_value(h, key->name, value, "not 9 numbers", err);
    h->has_matrix = 1;
    return IP_OK;
}

/* MetaImage keys are words: KEY(ElementType, ...) names the key "ElementType". */
#define KEY(name, by, parse)   \
    {                          \
#name, by, parse, 0, 0 \
    }
#define VALUE(name, by, parse, field, seen)                 \
    {                                                       \
#name, by, parse, offsetof(mhd_header, field), seen \
    }
#define LIST(name, by, parse, field) \
    VALUE(name, by, parse, field, offsetof(mhd_header, field##_count))
static const ip_text_key mhd_key_list[] = {
    VALUE(NDims, BY_DIMS, ip__text_key_dimensions, ndims, 0),
    LIST(DimSize, BY_DIMS, ip__text_key_u64s, dims),
    VALUE(ElementType, BY_TYPE, ip__text_key_type, type, offsetof(mhd_header, has_type)),
    LIST(ElementSpacing, BY_SPACING, ip__text_key_doubles, spacing),
    LIST(ElementSize, BY_SPACING, ip__text_key_doubles, size),
    VALUE(Offset, BY_NOTHING, ip__text_key_doubles, offset, offsetof(mhd_header, offset_count)),
    VALUE(Position, BY_NOTHING, ip__text_key_doubles, offset, offsetof(mhd_header, offset_count)),
    VALUE(Origin, BY_NOTHING, ip__text_key_doubles, offset, offsetof(mhd_header, offset_count)),
    KEY(TransformMatrix, BY_NOTHING, parse_matrix),
    KEY(Rotation, BY_NOTHING, parse_matrix),
    KEY(Orientation, BY_NOTHING, parse_matrix),
    KEY(BinaryDataByteOrderMSB, BY_ENDIAN, parse_msb),
    KEY(ElementByteOrderMSB, BY_ENDIAN, parse_msb),
    KEY(CompressedData, BY_NOTHING, parse_compressed),
    KEY(HeaderSize, BY_NOTHING, parse_header_size),
    KEY(ElementNumberOfChannels, BY_NOTHING, parse_channels),
    KEY(BinaryData, BY_NOTHING, parse_binary),
    KEY(ElementDataFile, BY_NOTHING, parse_data_file),
};
#undef KEY
#undef VALUE
#undef LIST
static const ip_text_keys mhd_keys = {mhd_key_list,
                                      sizeof mhd_key_list / sizeof mhd_key_list[0],
                                      1,
                                      NULL,
                                      "MetaImage",
                                      IP_TYPE_SPELLING_METAIMAGE};

/* One "Key = Value" line; keys the reader does not need (ObjectType,
 * AnatomicalOrientation, ...) are skipped. */
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
static ip_status read_keys(ip_text_file *file, void *header, const ip_input_overrides *overrides,
                           ip_error *err)
{
    mhd_header *h = header;
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

static ip_status check_keys(const mhd_header *h, const ip_input_overrides *overrides, ip_error *err)
{
    ip_status st =
        ip__text_check_dims(h, h->ndims, "NDims", h->dims_count, "DimSize", overrides, err);
    if (st != IP_OK)
        return st;
    if (!(overrides && overrides->has_type) && !h->has_type)
        return ip__text_missing(h, "ElementType", err);
    if (h->spacing_count >= 0 && h->spacing_count != 3)
        return ip__fail(err, IP_ERR_INPUT, "%s: ElementSpacing has %d values, NDims is 3",
                        h->at.path, h->spacing_count);
    if (h->spacing_count < 0 && h->size_count >= 0 && h->size_count != 3)
        return ip__fail(err, IP_ERR_INPUT, "%s: ElementSize has %d values, NDims is 3", h->at.path,
                        h->size_count);
    if (h->offset_count >= 0 && h->offset_count != 3)
        return ip__fail(err, IP_ERR_INPUT, "%s: Offset has %d values, NDims is 3", h->at.path,
                        h->offset_count);
    if (h->compressed && h->header_size == -1)
        return ip__fail(err, IP_ERR_INPUT, "%s: HeaderSize -1 needs uncompressed data", h->at.path);
    return IP_OK;
}

/* The matrix only where it is orthonormal (within the tolerance); ITK writes one so. */
static void fill_orientation(const mhd_header *h, ip_orientation *o)
{
    ip_orientation_identity(o);
    if (h->offset_count == 3)
        memcpy(o->origin, h->offset, sizeof o->origin);
    if (h->has_matrix)
        ip__orientation_frame(o, h->matrix);
}

/* The data start HeaderSize bytes into the data file or, for LOCAL, into what follows the
 * header; HeaderSize -1 puts them at the end of the file. */
static void fill_desc(const mhd_header *h, uint64_t header_end, ip_input_desc *desc,
                      ip_text_found *found)
{
    ip__text_found_layout(h->has_type, h->type, h->dims_count, h->dims, desc, found);
    desc->big_endian = h->has_msb ? h->msb : 0;
    desc->encoding = h->compressed ? IP_ENCODING_GZIP : IP_ENCODING_RAW;
    for (int axis = 0; axis < 3; axis++) {
        if (h->spacing_count == 3)
            desc->spacing[axis] = h->spacing[axis];
        else if (h->size_count == 3)
            desc->spacing[axis] = h->size[axis];
    }
    fill_orientation(h, &desc->orientation);
    if (!h->local)
        snprintf(desc->data_path, sizeof desc->data_path, "%s", h->data_path);
    uint64_t base = h->local ? header_end : 0;
    if (h->header_size == -1)
        found->data_at_end = 1;
    else
        desc->data_offset = base + (uint64_t)h->header_size;
}

static void init(void *header)
{
    mhd_header *h = header;
    h->dims_count = h->spacing_count = h->size_count = h->offset_count = -1; /* not seen yet */
}

static ip_status finish(void *header, uint64_t header_end, const ip_input_overrides *overrides,
                        ip_input_desc *desc, ip_text_found *found, ip_error *err)
{
    ip_status status = check_keys(header, overrides, err);
    if (status == IP_OK)
        fill_desc(header, header_end, desc, found);
    return status;
}

const ip_text_format ip__mhd_format = {&mhd_keys, sizeof(mhd_header), init, read_keys, finish};

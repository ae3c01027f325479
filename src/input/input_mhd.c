/* MetaImage headers (.mhd with a separate data file, .mha or ElementDataFile = LOCAL with the
 * data right after the header): "Key = Value" lines ending with ElementDataFile. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "input_headers.h"
#include "internal.h"

typedef struct mhd_header {
    const char *path;
    unsigned long line_number;
    const char *key;        /* the key being parsed, for messages */
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

typedef ip_status (*mhd_key_parser)(mhd_header *h, char *value, ip_error *err);

static ip_status bad_value(const mhd_header *h, const char *value, const char *why,
                           ip_error *err)
{
    return ip__fail(err, IP_ERR_INPUT, "%s: line %lu: bad %s '%.80s': %s", h->path,
                   h->line_number, h->key, value, why);
}

static ip_status parse_ndims(mhd_header *h, char *value, ip_error *err)
{
    if (ip__text_parse_i64(value, &h->ndims) != 0 || h->ndims < 1)
        return bad_value(h, value, "not a positive whole number", err);
    if (h->ndims != 3)
        return ip__fail(err, IP_ERR_INPUT, "%s: NDims %lld is not supported (need 3)", h->path,
                       (long long)h->ndims);
    return IP_OK;
}

static ip_status parse_dim_size(mhd_header *h, char *value, ip_error *err)
{
    if (ip__text_parse_u64_list(value, h->dims, 3, &h->dims_count) != 0)
        return bad_value(h, value, "not whole numbers", err);
    return IP_OK;
}

static ip_status parse_element_type(mhd_header *h, char *value, ip_error *err)
{
    static const struct { const char *name; ip_type type; } names[] = {
        {"MET_UCHAR", IP_UINT8},
        {"MET_USHORT", IP_UINT16},
        {"MET_SHORT", IP_INT16},
        {"MET_FLOAT", IP_FLOAT32},
    };
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        if (strcasecmp(value, names[i].name) == 0) {
            h->type = names[i].type;
            h->has_type = 1;
            return IP_OK;
        }
    }
    return ip__fail(err, IP_ERR_INPUT,
                   "%s: unsupported MetaImage ElementType '%.80s' (supported: MET_UCHAR, "
                   "MET_USHORT, MET_SHORT, MET_FLOAT)", h->path, value);
}

static ip_status parse_spacing(mhd_header *h, char *value, ip_error *err)
{
    if (ip__text_parse_double_list(value, h->spacing, 3, &h->spacing_count) != 0)
        return bad_value(h, value, "not numbers", err);
    return IP_OK;
}

static ip_status parse_size(mhd_header *h, char *value, ip_error *err)
{
    if (ip__text_parse_double_list(value, h->size, 3, &h->size_count) != 0)
        return bad_value(h, value, "not numbers", err);
    return IP_OK;
}

static ip_status parse_msb(mhd_header *h, char *value, ip_error *err)
{
    if (ip__text_parse_bool(value, &h->msb) != 0)
        return bad_value(h, value, "not True or False", err);
    h->has_msb = 1;
    return IP_OK;
}

static ip_status parse_compressed(mhd_header *h, char *value, ip_error *err)
{
    if (ip__text_parse_bool(value, &h->compressed) != 0)
        return bad_value(h, value, "not True or False", err);
    return IP_OK;
}

static ip_status parse_header_size(mhd_header *h, char *value, ip_error *err)
{
    if (ip__text_parse_i64(value, &h->header_size) != 0 || h->header_size < -1)
        return bad_value(h, value, "not -1 or a byte count", err);
    return IP_OK;
}

static ip_status parse_channels(mhd_header *h, char *value, ip_error *err)
{
    int64_t channels;
    if (ip__text_parse_i64(value, &channels) != 0 || channels < 1)
        return bad_value(h, value, "not a positive whole number", err);
    if (channels != 1)
        return ip__fail(err, IP_ERR_INPUT,
                       "%s: ElementNumberOfChannels %lld is not supported (need 1)", h->path,
                       (long long)channels);
    return IP_OK;
}

static ip_status parse_binary(mhd_header *h, char *value, ip_error *err)
{
    int binary;
    if (ip__text_parse_bool(value, &binary) != 0)
        return bad_value(h, value, "not True or False", err);
    if (!binary)
        return ip__fail(err, IP_ERR_INPUT, "%s: text data (BinaryData = False) are not supported",
                       h->path);
    return IP_OK;
}

static ip_status parse_data_file(mhd_header *h, char *value, ip_error *err)
{
    h->has_data_file = 1;
    if (strcmp(value, "LOCAL") == 0) {
        h->local = 1;
        return IP_OK;
    }
    /* "LIST" and "pattern%03d.raw first last step" spread the data over several files. */
    if (strncmp(value, "LIST", 4) == 0 || strchr(value, '%'))
        return ip__fail(err, IP_ERR_INPUT,
                       "%s: data split over several files ('ElementDataFile = %.80s') is not "
                       "supported", h->path, value);
    return ip__text_data_path(h->path, value, h->data_path, err);
}

static const struct {
    const char *name;
    ip_text_owner by;
    mhd_key_parser parse;
} mhd_keys[] = {
    {"NDims", BY_DIMS, parse_ndims},
    {"DimSize", BY_DIMS, parse_dim_size},
    {"ElementType", BY_TYPE, parse_element_type},
    {"ElementSpacing", BY_SPACING, parse_spacing},
    {"ElementSize", BY_SPACING, parse_size},
    {"BinaryDataByteOrderMSB", BY_ENDIAN, parse_msb},
    {"ElementByteOrderMSB", BY_ENDIAN, parse_msb},
    {"CompressedData", BY_NOTHING, parse_compressed},
    {"HeaderSize", BY_NOTHING, parse_header_size},
    {"ElementNumberOfChannels", BY_NOTHING, parse_channels},
    {"BinaryData", BY_NOTHING, parse_binary},
    {"ElementDataFile", BY_NOTHING, parse_data_file},
};

/* One "Key = Value" line; keys the reader does not need (ObjectType, Offset,
 * TransformMatrix, ...) are skipped. */
static ip_status parse_line(mhd_header *h, char *line, const ip_input_overrides *overrides,
                            ip_error *err)
{
    char *equals = strchr(line, '=');
    if (!equals)
        return ip__fail(err, IP_ERR_INPUT, "%s: line %lu is not 'Key = Value': '%.80s'", h->path,
                       h->line_number, line);
    *equals = '\0';
    char *key = ip__text_trim(line);
    char *value = ip__text_trim(equals + 1);
    for (size_t i = 0; i < sizeof mhd_keys / sizeof mhd_keys[0]; i++) {
        if (strcasecmp(key, mhd_keys[i].name) != 0)
            continue;
        if (ip__text_overridden(mhd_keys[i].by, overrides))
            return IP_OK;
        h->key = mhd_keys[i].name;
        if (value[0] == '\0')
            return ip__fail(err, IP_ERR_INPUT, "%s: line %lu: %s has no value", h->path,
                           h->line_number, mhd_keys[i].name);
        return mhd_keys[i].parse(h, value, err);
    }
    return IP_OK;
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
        h->line_number = file->line_number;
        if ((status = parse_line(h, line, overrides, err)) != IP_OK)
            return status;
    }
    if (h->has_data_file)
        return IP_OK;
    if (status != IP_OK)
        return status;
    if (h->line_number == 0)
        return ip__fail(err, IP_ERR_INPUT, "%s: empty MetaImage header", h->path);
    return ip__fail(err, IP_ERR_INPUT, "%s: missing key 'ElementDataFile'", h->path);
}

static ip_status missing(const mhd_header *h, const char *key, ip_error *err)
{
    return ip__fail(err, IP_ERR_INPUT, "%s: missing key '%s'", h->path, key);
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
        return ip__fail(err, IP_ERR_INPUT, "%s: DimSize has %d values, NDims is 3", h->path,
                       h->dims_count);
    if (!(overrides && overrides->has_type) && !h->has_type)
        return missing(h, "ElementType", err);
    if (h->spacing_count >= 0 && h->spacing_count != 3)
        return ip__fail(err, IP_ERR_INPUT, "%s: ElementSpacing has %d values, NDims is 3",
                       h->path, h->spacing_count);
    if (h->spacing_count < 0 && h->size_count >= 0 && h->size_count != 3)
        return ip__fail(err, IP_ERR_INPUT, "%s: ElementSize has %d values, NDims is 3",
                       h->path, h->size_count);
    if (h->compressed && h->header_size == -1)
        return ip__fail(err, IP_ERR_INPUT, "%s: HeaderSize -1 needs uncompressed data",
                       h->path);
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
    h->path = path;
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

/* SPDX-License-Identifier: BSD-3-Clause */
/* NRRD headers: attached (.nrrd, data after the blank line) and detached (.nhdr, data in the
 * file that `data file:` names), raw or gzip encoded. Follows the NRRD0001-0005 format
 * description; only what a 3-D scalar volume needs is interpreted, other fields are ignored. */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "input_headers.h"
#include "internal.h"
#include "text_header.h"

typedef struct nrrd_header {
    ip_text_place at; /* first: see ip_text_place */
    int has_type;
    ip_type type;
    int64_t dimension; /* 0 until the field is seen */
    int sizes_count;   /* -1 until the field is seen */
    uint64_t sizes[3];
    int has_endian;
    int big_endian;
    int has_encoding;
    ip_encoding encoding;
    int spacings_count; /* -1 until the field is seen */
    double spacings[3];
    int directions_count;
    double directions[3]; /* lengths of the space directions: the spacing */
    int has_vectors;      /* every space direction a 3-vector */
    double vectors[3][3]; /* the space directions as written */
    double origin[3];     /* space origin; 0 when absent */
    ip_space space;       /* from the space field */
    int64_t byte_skip;
    int64_t line_skip;
    int has_data_file;
    char data_path[IP_PATH_MAX];
    int blank_line; /* a blank line ended the header: attached data follow it */
} nrrd_header;

static ip_status parse_endian(void *header, const ip_text_key *key, char *value, ip_error *err)
{
    nrrd_header *h = header;
    if (strcasecmp(value, "little") == 0)
        h->big_endian = 0;
    else if (strcasecmp(value, "big") == 0)
        h->big_endian = 1;
    else
        return ip__text_bad_value(h, key->name, value, "not 'little' or 'big'", err);
    h->has_endian = 1;
    return IP_OK;
}

static ip_status parse_encoding(void *header, const ip_text_key *key, char *value, ip_error *err)
{
    nrrd_header *h = header;
    (void)key;
    if (strcasecmp(value, "raw") == 0)
        h->encoding = IP_ENCODING_RAW;
    else if (strcasecmp(value, "gzip") == 0 || strcasecmp(value, "gz") == 0)
        h->encoding = IP_ENCODING_GZIP;
    else
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: unsupported NRRD encoding '%.80s' (supported: raw, gzip)", h->at.path,
                        value);
    h->has_encoding = 1;
    return IP_OK;
}

/* NaN marks an axis without a spacing; a negative spacing only says which way the axis runs. */
static double spacing_of(double value)
{
    return isnan(value) ? 1.0 : fabs(value);
}

static ip_status parse_spacings(void *header, const ip_text_key *key, char *value, ip_error *err)
{
    nrrd_header *h = header;
    ip_status st = ip__text_key_doubles(header, key, value, err);
    for (int axis = 0; st == IP_OK && axis < h->spacings_count && axis < 3; axis++)
        h->spacings[axis] = spacing_of(h->spacings[axis]);
    return st;
}

/* Parses one "(a,b,...)" vector at *p: its length, and its first three components into v
 * (*count: how many it has). */
static int parse_vector(const char **p, double *norm, double v[3], int *count)
{
    const char *s = *p;
    double sum = 0.0;
    *count = 0;
    if (*s++ != '(')
        return -1;
    for (;;) {
        char *end;
        double c = strtod(s, &end);
        if (end == s)
            return -1;
        if (*count < 3)
            v[*count] = c;
        (*count)++;
        sum += c * c;
        s = end;
        while (*s == ' ' || *s == '\t')
            s++;
        if (*s == ')')
            break;
        if (*s++ != ',')
            return -1;
    }
    *p = s + 1;
    *norm = sqrt(sum);
    return 0;
}

/* Each axis's spacing is the length of its direction vector, and its direction the vector
 * over that length; "none" marks an axis outside world space, which gets the default
 * spacing. */
static ip_status parse_directions(void *header, const ip_text_key *key, char *value, ip_error *err)
{
    nrrd_header *h = header;
    const char *p = value;
    h->directions_count = 0;
    h->has_vectors = 1;
    for (;;) {
        double norm = NAN, v[3] = {0, 0, 0};
        int count = 0;
        while (*p == ' ' || *p == '\t')
            p++;
        if (*p == '\0')
            return IP_OK;
        if (strncmp(p, "none", 4) == 0)
            p += 4;
        else if (parse_vector(&p, &norm, v, &count) != 0)
            return ip__text_bad_value(h, key->name, value, "not '(x,y,z)' vectors or 'none'", err);
        if (*p != '\0' && *p != ' ' && *p != '\t')
            return ip__text_bad_value(h, key->name, value, "not '(x,y,z)' vectors or 'none'", err);
        if (count != 3)
            h->has_vectors = 0;
        if (h->directions_count < 3) {
            h->directions[h->directions_count] = spacing_of(norm);
            memcpy(h->vectors[h->directions_count], v, sizeof v);
        }
        h->directions_count++;
    }
}

static ip_status parse_origin(void *header, const ip_text_key *key, char *value, ip_error *err)
{
    nrrd_header *h = header;
    const char *p = value;
    double norm, v[3] = {0, 0, 0};
    int count = 0;
    int bad = parse_vector(&p, &norm, v, &count) != 0 || count != 3 || !isfinite(norm);
    while (!bad && (*p == ' ' || *p == '\t'))
        p++;
    if (bad || *p != '\0')
        return ip__text_bad_value(h, key->name, value, "not an '(x,y,z)' vector", err);
    memcpy(h->origin, v, sizeof v);
    return IP_OK;
}

/* The anatomical spaces that ip_space names; any other space is kept as unknown. */
static ip_status parse_space(void *header, const ip_text_key *key, char *value, ip_error *err)
{
    static const struct {
        const char *name;
        ip_space space;
    } spaces[] = {{"right-anterior-superior", IP_SPACE_RAS}, {"RAS", IP_SPACE_RAS},
                  {"left-anterior-superior", IP_SPACE_LAS},  {"LAS", IP_SPACE_LAS},
                  {"left-posterior-superior", IP_SPACE_LPS}, {"LPS", IP_SPACE_LPS}};
    nrrd_header *h = header;
    (void)key;
    (void)err;
    h->space = IP_SPACE_UNKNOWN;
    for (size_t i = 0; i < sizeof spaces / sizeof spaces[0]; i++)
        if (strcasecmp(value, spaces[i].name) == 0)
            h->space = spaces[i].space;
    return IP_OK;
}

static ip_status parse_byte_skip(void *header, const ip_text_key *key, char *value, ip_error *err)
{
    nrrd_header *h = header;
    (void)key;
    if (ip__text_parse_i64(value, &h->byte_skip) != 0 || h->byte_skip < -1)
        return ip__text_bad_value(h, "byte skip", value, "not -1 or a byte count", err);
    return IP_OK;
}

static ip_status parse_line_skip(void *header, const ip_text_key *key, char *value, ip_error *err)
{
    nrrd_header *h = header;
    (void)key;
    if (ip__text_parse_i64(value, &h->line_skip) != 0 || h->line_skip < 0)
        return ip__text_bad_value(h, "line skip", value, "not a line count", err);
    return IP_OK;
}

static ip_status parse_data_file(void *header, const ip_text_key *key, char *value, ip_error *err)
{
    nrrd_header *h = header;
    (void)key;
    /* "LIST" and "printf-pattern min max step" spread the data over several files. */
    if (strncmp(value, "LIST", 4) == 0 || strchr(value, '%'))
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: data split over several files ('data file: %.80s') is not supported",
                        h->at.path, value);
    h->has_data_file = 1;
    return ip__text_data_path(h->at.path, value, h->data_path, err);
}

static const ip_text_key nrrd_field_list[] = {
    {"type", BY_TYPE, ip__text_key_type, offsetof(nrrd_header, type),
     offsetof(nrrd_header, has_type)},
    {"dimension", BY_DIMS, ip__text_key_dimensions, offsetof(nrrd_header, dimension), 0},
    {"sizes", BY_DIMS, ip__text_key_u64s, offsetof(nrrd_header, sizes),
     offsetof(nrrd_header, sizes_count)},
    {"endian", BY_ENDIAN, parse_endian, 0, 0},
    {"encoding", BY_NOTHING, parse_encoding, 0, 0},
    {"spacings", BY_SPACING, parse_spacings, offsetof(nrrd_header, spacings),
     offsetof(nrrd_header, spacings_count)},
    {"space directions", BY_SPACING, parse_directions, 0, 0},
    {"space origin", BY_NOTHING, parse_origin, 0, 0},
    {"space", BY_NOTHING, parse_space, 0, 0},
    {"byte skip", BY_NOTHING, parse_byte_skip, 0, 0},
    {"byteskip", BY_NOTHING, parse_byte_skip, 0, 0},
    {"line skip", BY_NOTHING, parse_line_skip, 0, 0},
    {"lineskip", BY_NOTHING, parse_line_skip, 0, 0},
    {"data file", BY_NOTHING, parse_data_file, 0, 0},
    {"datafile", BY_NOTHING, parse_data_file, 0, 0},
};
static const ip_text_keys nrrd_fields = {
    nrrd_field_list,      sizeof nrrd_field_list / sizeof nrrd_field_list[0], 0, "field", "NRRD",
    IP_TYPE_SPELLING_NRRD};

/* One "field: value" line. Key/value pairs ("key:=value") and fields that describe anything
 * else (content, kinds, ...) are not needed to read the samples. */
static ip_status parse_line(nrrd_header *h, char *line, const ip_input_overrides *overrides,
                            ip_error *err)
{
    char *colon = strstr(line, ": ");
    char *pair = strstr(line, ":=");
    if (pair && (!colon || pair < colon))
        return IP_OK;
    if (!colon) {
        size_t len = strlen(line);
        if (len == 0 || line[len - 1] != ':')
            return ip__fail(err, IP_ERR_INPUT, "%s: line %lu is not 'field: value': '%.80s'",
                            h->at.path, h->at.line_number, line);
        colon = line + len - 1;
    }
    *colon = '\0';
    return ip__text_dispatch(&nrrd_fields, h, line, ip__text_trim(colon + 1), overrides, err);
}

/* Reads the magic and the fields; h->blank_line tells whether a blank line ended the header
 * (attached data follow it) or the end of the file did. */
static ip_status read_fields(ip_text_file *file, void *header, const ip_input_overrides *overrides,
                             ip_error *err)
{
    nrrd_header *h = header;
    int got;
    ip_status status = ip__text_next_line(file, &got, err);
    if (status != IP_OK)
        return status;
    if (!got || strncmp(file->line, "NRRD000", 7) != 0)
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: not a NRRD file (the first line does not start with NRRD000)",
                        h->at.path);
    h->blank_line = 0;
    while ((status = ip__text_next_line(file, &got, err)) == IP_OK && got) {
        if (file->line[0] == '\0') {
            h->blank_line = 1;
            break;
        }
        if (file->line[0] == '#')
            continue;
        h->at.line_number = file->line_number;
        if ((status = parse_line(h, file->line, overrides, err)) != IP_OK)
            return status;
    }
    return status;
}

/* Moves *offset past `lines` line endings of the data file. */
static ip_status skip_lines(const nrrd_header *h, const char *data_path, int64_t lines,
                            uint64_t *offset, ip_error *err)
{
    struct stat st;
    /* O_NONBLOCK: a header naming a FIFO must not hang the caller waiting for a writer. */
    int fd = open(data_path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return ip__fail_errno(err, IP_ERR_IO, errno, "%s: data file %s: cannot open", h->at.path,
                              data_path);
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(fd);
        return ip__fail(err, IP_ERR_INPUT, "%s: data file %s: not a regular file", h->at.path,
                        data_path);
    }
    FILE *f = fdopen(fd, "rb");
    if (!f) {
        int e = errno;
        close(fd);
        return ip__fail_errno(err, IP_ERR_NOMEM, e, "%s: data file %s: cannot read", h->at.path,
                              data_path);
    }
    if (fseeko(f, (off_t)*offset, SEEK_SET) != 0) {
        int e = errno;
        fclose(f);
        return ip__fail_errno(err, IP_ERR_IO, e, "%s: cannot seek in %s", h->at.path, data_path);
    }
    int64_t seen = 0;
    int c = 0;
    while (seen < lines && (c = getc(f)) != EOF) {
        (*offset)++;
        if (c == '\n')
            seen++;
    }
    int failed = ferror(f);
    fclose(f);
    if (failed)
        return ip__fail(err, IP_ERR_IO, "%s: cannot read %s", h->at.path, data_path);
    if (seen < lines)
        return ip__fail(err, IP_ERR_INPUT, "%s: line skip %lld passes the end of %s", h->at.path,
                        (long long)lines, data_path);
    return IP_OK;
}

static ip_status check_layout_fields(const nrrd_header *h, const ip_input_overrides *overrides,
                                     ip_error *err)
{
    ip_status st = IP_OK;
    if (!(overrides && overrides->has_type) && !h->has_type)
        return ip__text_missing(h, "type", err);
    st = ip__text_check_dims(h, h->dimension, "dimension", h->sizes_count, "sizes", overrides, err);
    if (st != IP_OK)
        return st;
    if (!h->has_encoding)
        return ip__text_missing(h, "encoding", err);
    if (h->spacings_count >= 0 && h->spacings_count != 3)
        return ip__fail(err, IP_ERR_INPUT, "%s: spacings has %d values, dimension is 3", h->at.path,
                        h->spacings_count);
    if (h->directions_count >= 0 && h->directions_count != 3)
        return ip__fail(err, IP_ERR_INPUT, "%s: space directions has %d vectors, dimension is 3",
                        h->at.path, h->directions_count);
    if (h->encoding == IP_ENCODING_GZIP && h->byte_skip == -1)
        return ip__fail(err, IP_ERR_INPUT, "%s: byte skip -1 needs raw encoding, not gzip",
                        h->at.path);
    /* For compressed data the format applies the byte skip after inflating. */
    if (h->encoding == IP_ENCODING_GZIP && h->byte_skip > 0)
        return ip__fail(err, IP_ERR_INPUT, "%s: byte skip with gzip encoding is not supported",
                        h->at.path);
    return IP_OK;
}

/* Multi-byte samples need a byte order; guessing one would read garbage without a word. */
static ip_status check_endian(const nrrd_header *h, const ip_input_overrides *overrides,
                              ip_error *err)
{
    if (h->has_endian || (overrides && overrides->has_endian))
        return IP_OK;
    ip_type type = overrides && overrides->has_type ? overrides->type : h->type;
    if (ip_type_size(type) <= 1)
        return IP_OK;
    return ip__fail(err, IP_ERR_INPUT, "%s: missing field 'endian' (needed for %s samples)",
                    h->at.path, ip_type_name(type));
}

/* Directions only where every axis has a vector and together they are orthonormal (a sheared
 * grid has no such frame); the origin and space always. */
static void fill_orientation(const nrrd_header *h, ip_orientation *o)
{
    ip_orientation_identity(o);
    memcpy(o->origin, h->origin, sizeof o->origin);
    o->space = h->space;
    if (h->directions_count == 3 && h->has_vectors)
        ip__orientation_frame(o, h->vectors);
}

static void fill_desc(const nrrd_header *h, ip_input_desc *desc, ip_text_found *found)
{
    ip__text_found_layout(h->has_type, h->type, h->sizes_count, h->sizes, desc, found);
    desc->big_endian = h->big_endian;
    desc->encoding = h->encoding;
    for (int axis = 0; axis < 3; axis++) {
        if (h->spacings_count == 3)
            desc->spacing[axis] = h->spacings[axis];
        else if (h->directions_count == 3)
            desc->spacing[axis] = h->directions[axis];
    }
    fill_orientation(h, &desc->orientation);
}

/* Works out where the samples start: after the header (attached) or at the start of the data
 * file (detached), then past `line skip` lines and `byte skip` bytes. */
static ip_status place_data(const nrrd_header *h, uint64_t header_end, ip_input_desc *desc,
                            ip_text_found *found, ip_error *err)
{
    uint64_t offset = 0;
    if (h->has_data_file) {
        snprintf(desc->data_path, sizeof desc->data_path, "%s", h->data_path);
    } else if (h->blank_line) {
        offset = header_end;
    } else {
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: no blank line ends the header and no 'data file' field names the "
                        "data",
                        h->at.path);
    }
    if (h->line_skip > 0) {
        ip_status status = skip_lines(h, desc->data_path, h->line_skip, &offset, err);
        if (status != IP_OK)
            return status;
    }
    if (h->byte_skip == -1)
        found->data_at_end = 1;
    else
        offset += (uint64_t)h->byte_skip;
    desc->data_offset = offset;
    return IP_OK;
}

static void init(void *header)
{
    nrrd_header *h = header;
    h->sizes_count = h->spacings_count = h->directions_count = -1; /* not seen yet */
}

/* Checks the fields, then fills `desc` and `found`. */
static ip_status finish(void *header, uint64_t header_end, const ip_input_overrides *overrides,
                        ip_input_desc *desc, ip_text_found *found, ip_error *err)
{
    nrrd_header *h = header;
    ip_status status = check_layout_fields(h, overrides, err);
    if (status == IP_OK)
        status = check_endian(h, overrides, err);
    if (status != IP_OK)
        return status;
    fill_desc(h, desc, found);
    return place_data(h, header_end, desc, found, err);
}

const ip_text_format ip__nrrd_format = {&nrrd_fields, sizeof(nrrd_header), init, read_fields,
                                        finish};

/* SPDX-License-Identifier: BSD-3-Clause */
/* Text headers (NRRD, MetaImage): the line reader, the value parsers and the table of keys
 * that both readers dispatch their lines through. */
#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "array.h"
#include "internal.h"
#include "text_header.h"

ip_status ip__text_open(ip_text_file *header, const char *path, ip_error *err)
{
    struct stat st;
    memset(header, 0, sizeof *header);
    header->path = path;
    /* O_NONBLOCK: a FIFO must be refused below, not hang the caller waiting for a writer. */
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot open", path);
    if (fstat(fd, &st) != 0) {
        int e = errno;
        close(fd);
        return ip__fail_errno(err, IP_ERR_IO, e, "%s: cannot stat", path);
    }
    if (!S_ISREG(st.st_mode)) {
        close(fd);
        return ip__fail(err, IP_ERR_INPUT, "%s: not a regular file", path);
    }
    header->file = fdopen(fd, "rb");
    if (!header->file) {
        int e = errno;
        close(fd);
        return ip__fail_errno(err, IP_ERR_NOMEM, e, "%s: cannot read", path);
    }
    return IP_OK;
}

static ip_status grow_line(ip_text_file *header, ip_error *err)
{
    if (header->capacity > IP_TEXT_LINE_MAX)
        return ip__fail(err, IP_ERR_INPUT, "%s: header line %lu is longer than %d bytes",
                        header->path, header->line_number + 1, IP_TEXT_LINE_MAX);
    uint64_t capacity =
        ip__array_capacity(header->capacity, header->capacity + 1, 256, 1, IP_ARRAY_DOUBLE);
    if (capacity > IP_TEXT_LINE_MAX + 1)
        capacity = IP_TEXT_LINE_MAX + 1;
    if (ip__array_resize(&header->line, capacity, 1) != IP_OK)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory reading the header", header->path);
    header->capacity = (size_t)capacity;
    return IP_OK;
}

ip_status ip__text_next_line(ip_text_file *header, int *got, ip_error *err)
{
    size_t len = 0;
    int c = EOF;
    ip_status status;
    *got = 0;
    if (!header->line && (status = grow_line(header, err)) != IP_OK)
        return status;
    while ((c = getc(header->file)) != EOF) {
        header->offset++;
        if (c == '\n')
            break;
        if (c == '\0')
            return ip__fail(err, IP_ERR_INPUT, "%s: header line %lu holds a NUL byte", header->path,
                            header->line_number + 1);
        if (len + 1 >= header->capacity && (status = grow_line(header, err)) != IP_OK)
            return status;
        header->line[len++] = (char)c;
    }
    if (c == EOF && ferror(header->file))
        return ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot read the header", header->path);
    if (c == EOF && len == 0)
        return IP_OK;
    if (len > 0 && header->line[len - 1] == '\r')
        len--;
    header->line[len] = '\0';
    header->line_number++;
    *got = 1;
    return IP_OK;
}

void ip__text_close(ip_text_file *header)
{
    if (header->file)
        fclose(header->file);
    free(header->line);
    memset(header, 0, sizeof *header);
}

char *ip__text_trim(char *text)
{
    while (isspace((unsigned char)*text))
        text++;
    size_t len = strlen(text);
    while (len > 0 && isspace((unsigned char)text[len - 1]))
        text[--len] = '\0';
    return text;
}

ip_status ip__text_data_path(const char *header_path, const char *name, char out[IP_PATH_MAX],
                             ip_error *err)
{
    int n;
    if (name[0] == '\0')
        return ip__fail(err, IP_ERR_INPUT, "%s: the data file name is empty", header_path);
    if (name[0] == '/') {
        n = snprintf(out, IP_PATH_MAX, "%s", name);
    } else {
        const char *slash = strrchr(header_path, '/');
        int folder_len = slash ? (int)(slash - header_path) + 1 : 0;
        n = snprintf(out, IP_PATH_MAX, "%.*s%s", folder_len, header_path, name);
    }
    if (n < 0 || n >= IP_PATH_MAX)
        return ip__fail(err, IP_ERR_INPUT, "%s: the data file path is too long", header_path);
    return IP_OK;
}

int ip__text_parse_i64(const char *text, int64_t *out)
{
    char *end;
    while (isspace((unsigned char)*text))
        text++;
    if (!isdigit((unsigned char)*text) && !(*text == '-' && isdigit((unsigned char)text[1])))
        return -1;
    errno = 0;
    long long v = strtoll(text, &end, 10);
    if (errno != 0)
        return -1;
    while (isspace((unsigned char)*end))
        end++;
    if (*end != '\0')
        return -1;
    *out = (int64_t)v;
    return 0;
}

int ip__text_parse_bool(const char *text, int *out)
{
    char buf[8];
    int n = snprintf(buf, sizeof buf, "%s", text);
    if (n < 0 || (size_t)n >= sizeof buf)
        return -1;
    char *word = ip__text_trim(buf);
    if (strcasecmp(word, "true") == 0 || strcmp(word, "1") == 0) {
        *out = 1;
        return 0;
    }
    if (strcasecmp(word, "false") == 0 || strcmp(word, "0") == 0) {
        *out = 0;
        return 0;
    }
    return -1;
}

/* Parses white-space separated numbers, whole (`values` of uint64_t) or not (double). */
static int parse_list(const char *text, int whole, void *values, int max, int *count)
{
    const char *p = text;
    *count = 0;
    for (;;) {
        while (isspace((unsigned char)*p))
            p++;
        if (*p == '\0')
            return 0;
        if (whole && !isdigit((unsigned char)*p))
            return -1;
        char *end;
        errno = 0;
        unsigned long long u = whole ? strtoull(p, &end, 10) : 0;
        double d = whole ? 0.0 : strtod(p, &end);
        if ((whole && errno != 0) || end == p || (*end != '\0' && !isspace((unsigned char)*end)))
            return -1;
        if (*count < max && whole)
            ((uint64_t *)values)[*count] = (uint64_t)u;
        else if (*count < max)
            ((double *)values)[*count] = d;
        (*count)++;
        p = end;
    }
}

int ip__text_parse_u64_list(const char *text, uint64_t *values, int max, int *count)
{
    return parse_list(text, 1, values, max, count);
}

int ip__text_parse_double_list(const char *text, double *values, int max, int *count)
{
    return parse_list(text, 0, values, max, count);
}

int ip__text_overridden(ip_text_owner by, const ip_input_overrides *overrides)
{
    if (!overrides)
        return 0;
    switch (by) {
    case BY_NOTHING: return 0;
    case BY_DIMS: return overrides->has_dims;
    case BY_TYPE: return overrides->has_type;
    case BY_ENDIAN: return overrides->has_endian;
    case BY_SPACING: return overrides->has_spacing;
    }
    return 0;
}

ip_status ip__text_bad_value(const void *header, const char *key, const char *value,
                             const char *why, ip_error *err)
{
    const ip_text_place *at = header;
    return ip__fail(err, IP_ERR_INPUT, "%s: line %lu: bad %s '%.80s': %s", at->path,
                    at->line_number, key, value, why);
}

static ip_status key_list(void *header, const ip_text_key *key, char *value, int whole,
                          ip_error *err)
{
    char *base = header;
    if (parse_list(value, whole, base + key->field, 3, (int *)(base + key->seen)) != 0)
        return ip__text_bad_value(header, key->name, value,
                                  whole ? "not whole numbers" : "not numbers", err);
    return IP_OK;
}

ip_status ip__text_key_u64s(void *header, const ip_text_key *key, char *value, ip_error *err)
{
    return key_list(header, key, value, 1, err);
}

ip_status ip__text_key_doubles(void *header, const ip_text_key *key, char *value, ip_error *err)
{
    return key_list(header, key, value, 0, err);
}

ip_status ip__text_key_type(void *header, const ip_text_key *key, char *value, ip_error *err)
{
    const ip_text_place *at = header;
    char *base = header;
    if (ip__type_from_name(value, at->keys->type_spellings, (ip_type *)(base + key->field)) ==
        IP_OK) {
        *(int *)(base + key->seen) = 1;
        return IP_OK;
    }
    char names[64];
    ip__type_names(at->keys->type_spellings, names, sizeof names);
    return ip__fail(err, IP_ERR_INPUT, "%s: unsupported %s %s '%.80s' (supported: %s)", at->path,
                    at->keys->format, key->name, value, names);
}

ip_status ip__text_key_dimensions(void *header, const ip_text_key *key, char *value, ip_error *err)
{
    const ip_text_place *at = header;
    int64_t *dimensions = (int64_t *)((char *)header + key->field);
    if (ip__text_parse_i64(value, dimensions) != 0 || *dimensions < 1)
        return ip__text_bad_value(header, key->name, value, "not a positive whole number", err);
    if (*dimensions != 3)
        return ip__fail(err, IP_ERR_INPUT, "%s: %s%s%s %lld is not supported (need 3)", at->path,
                        at->keys->key_word ? at->keys->format : "", at->keys->key_word ? " " : "",
                        key->name, (long long)*dimensions);
    return IP_OK;
}

ip_status ip__text_missing(const void *header, const char *key, ip_error *err)
{
    const ip_text_place *at = header;
    return ip__fail(err, IP_ERR_INPUT, "%s: missing %s '%s'", at->path,
                    at->keys->key_word ? at->keys->key_word : "key", key);
}

ip_status ip__text_check_dims(const void *header, int64_t dimensions, const char *dimensions_key,
                              int sizes_count, const char *sizes_key,
                              const ip_input_overrides *overrides, ip_error *err)
{
    const ip_text_place *at = header;
    if (overrides && overrides->has_dims)
        return IP_OK;
    if (dimensions == 0)
        return ip__text_missing(header, dimensions_key, err);
    if (sizes_count < 0)
        return ip__text_missing(header, sizes_key, err);
    if (sizes_count != 3)
        return ip__fail(err, IP_ERR_INPUT, "%s: %s has %d values, %s is 3", at->path, sizes_key,
                        sizes_count, dimensions_key);
    return IP_OK;
}

void ip__text_found_layout(int has_type, ip_type type, int sizes_count, const uint64_t sizes[3],
                           ip_input_desc *desc, ip_text_found *found)
{
    if (has_type) {
        desc->type = type;
        found->has_type = 1;
    }
    if (sizes_count == 3) {
        memcpy(found->dims, sizes, sizeof found->dims);
        found->has_dims = 1;
    }
}

ip_status ip__text_read_header(const ip_text_format *format, const char *path,
                               const ip_input_overrides *overrides, ip_input_desc *desc,
                               ip_text_found *found, ip_error *err)
{
    ip_text_file file;
    void *header = calloc(1, format->header_size);
    if (!header)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory reading the header", path);
    ((ip_text_place *)header)->path = path;
    ((ip_text_place *)header)->keys = format->keys;
    format->init(header);
    ip_status status = ip__text_open(&file, path, err);
    if (status == IP_OK) {
        status = format->read(&file, header, overrides, err);
        uint64_t header_end = file.offset;
        ip__text_close(&file);
        if (status == IP_OK)
            status = format->finish(header, header_end, overrides, desc, found, err);
    }
    free(header);
    return status;
}

ip_status ip__text_dispatch(const ip_text_keys *table, void *header, const char *key, char *value,
                            const ip_input_overrides *overrides, ip_error *err)
{
    ip_text_place *at = header;
    at->keys = table;
    for (size_t i = 0; i < table->count; i++) {
        const ip_text_key *k = &table->keys[i];
        if ((table->ignore_case ? strcasecmp(key, k->name) : strcmp(key, k->name)) != 0)
            continue;
        if (ip__text_overridden(k->by, overrides))
            return IP_OK;
        if (value[0] == '\0' && table->key_word)
            return ip__fail(err, IP_ERR_INPUT, "%s: line %lu: %s '%s' has no value", at->path,
                            at->line_number, table->key_word, key);
        if (value[0] == '\0')
            return ip__fail(err, IP_ERR_INPUT, "%s: line %lu: %s has no value", at->path,
                            at->line_number, k->name);
        return k->parse(header, k, value, err);
    }
    return IP_OK;
}

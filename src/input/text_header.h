/* SPDX-License-Identifier: BSD-3-Clause */
/* Internal to the input module: reading a text header (NRRD, MetaImage) line by line, parsing
 * its values, and one table-driven dispatch of "key, value" to the parser of the key. Not part
 * of the public API. */
#ifndef ISOPROP_TEXT_HEADER_H
#define ISOPROP_TEXT_HEADER_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "isoprop/input.h"
#include "isoprop/status.h"

/* Header lines are short in practice, but comments and key/value pairs may be long; a longer
 * line is an error rather than something cut short silently. */
#define IP_TEXT_LINE_MAX 65536

/* Reads a text header line by line, keeping count of the bytes used so that attached data
 * can be found right after the header. */
typedef struct ip_text_file {
    FILE *file;
    const char *path;
    char *line; /* the current line without its "\n" or "\r\n" */
    size_t capacity;
    uint64_t offset; /* bytes consumed so far: where the next line starts */
    unsigned long line_number;
} ip_text_file;

/* Opens `path` (kept by pointer, not copied); IP_ERR_IO with strerror when it cannot. */
ip_status ip__text_open(ip_text_file *header, const char *path, ip_error *err);

/* Reads the next line into header->line; *got is 0 at the end of the file. Lines over
 * IP_TEXT_LINE_MAX bytes and NUL bytes are IP_ERR_INPUT (binary data is not a header). */
ip_status ip__text_next_line(ip_text_file *header, int *got, ip_error *err);

void ip__text_close(ip_text_file *header);

/* Trims leading and trailing white space in place; returns the first kept character. */
char *ip__text_trim(char *text);

/* Resolves a data file name found in the header at `header_path`: absolute names stay as
 * they are, relative ones are taken from the header's folder. */
ip_status ip__text_data_path(const char *header_path, const char *name, char out[IP_PATH_MAX],
                             ip_error *err);

/* Strict number parsers over the whole text (surrounding white space allowed): 0 on
 * success, -1 on anything else, including a value out of range. */
int ip__text_parse_i64(const char *text, int64_t *out);
int ip__text_parse_bool(const char *text, int *out);

/* Parses white-space separated numbers. *count receives how many the text holds, even past
 * `max` (only the first `max` are stored), so a caller can report a wrong count. */
int ip__text_parse_u64_list(const char *text, uint64_t *values, int max, int *count);
int ip__text_parse_double_list(const char *text, double *values, int max, int *count);

/* Which override, if any, replaces a header field: a field that an override replaces is not
 * read at all, so the override can stand in for a value the reader cannot use. */
typedef enum ip_text_owner {
    BY_NOTHING,
    BY_DIMS,
    BY_TYPE,
    BY_ENDIAN,
    BY_SPACING
} ip_text_owner;

/* 1 when `overrides` (may be NULL) replaces fields owned by `by`. */
int ip__text_overridden(ip_text_owner by, const ip_input_overrides *overrides);

/* Where a header parser is: the first member of its header struct, so that the shared value
 * parsers below can name the file and line in their messages. */
typedef struct ip_text_keys ip_text_keys;
typedef struct ip_text_place {
    const char *path;
    unsigned long line_number;
    const ip_text_keys *keys; /* the format's keys, set by ip__text_dispatch() */
} ip_text_place;

typedef struct ip_text_key ip_text_key;

/* Parses the (non-empty, trimmed) value of `key` into `header`, a parser's header struct
 * (starting with an ip_text_place); fails naming the file, line and problem. */
typedef ip_status (*ip_text_key_parser)(void *header, const ip_text_key *key, char *value,
                                        ip_error *err);

/* One key of a format: its name, which override replaces it, and its parser. `field` and
 * `seen` are byte offsets in the header struct, for the shared parsers ip__text_key_u64s,
 * ip__text_key_doubles and ip__text_key_type (0 for the others). */
struct ip_text_key {
    const char *name;
    ip_text_owner by;
    ip_text_key_parser parse;
    size_t field, seen;
};

/* The keys of a format. */
struct ip_text_keys {
    const ip_text_key *keys;
    size_t count;
    int ignore_case;         /* MetaImage keys are case-insensitive, NRRD fields are not */
    const char *key_word;    /* a key in messages: "field 'sizes'" (NRRD); NULL: "DimSize" */
    const char *format;      /* the format's name in messages */
    unsigned type_spellings; /* the type names it uses: IP_TYPE_SPELLING_* (internal.h) */
};

/*! ip__text_dispatch() : finds `key` in `table` and has its parser read `value` into `header`;
 *  a key that an override replaces is skipped, one not in the table ignored.
 *  @return : IP_OK, the parser's error, or IP_ERR_INPUT for an empty value. */
ip_status ip__text_dispatch(const ip_text_keys *table, void *header, const char *key, char *value,
                            const ip_input_overrides *overrides, ip_error *err);

/* IP_ERR_INPUT "PATH: line N: bad KEY 'VALUE': WHY" for `header` (an ip_text_place first). */
ip_status ip__text_bad_value(const void *header, const char *key, const char *value,
                             const char *why, ip_error *err);

/* Key parsers for 3 numbers: whole (uint64_t[3] at the key's `field`) or not (double[3]), with
 * their count (int, as in ip__text_parse_u64_list) at its `seen` offset. */
ip_status ip__text_key_u64s(void *header, const ip_text_key *key, char *value, ip_error *err);
ip_status ip__text_key_doubles(void *header, const ip_text_key *key, char *value, ip_error *err);

/* Key parser for a sample type in the format's spellings: an ip_type at the key's `field`, and
 * 1 in the int at `seen`. */
ip_status ip__text_key_type(void *header, const ip_text_key *key, char *value, ip_error *err);

/* Key parser for the number of dimensions (int64_t at the key's `field`), which must be 3. A
 * format whose keys are "field"s (NRRD) is named before the key in the message. */
ip_status ip__text_key_dimensions(void *header, const ip_text_key *key, char *value, ip_error *err);

/* What a parser found beyond the ip_input_desc fields it fills directly (data_path,
 * data_offset, type, big_endian, spacing, encoding). Dims stay 64-bit until ip_input_describe
 * has checked their range in one place. */
typedef struct ip_text_found {
    int has_dims;
    uint64_t dims[3];
    int has_type;
    int data_at_end; /* NRRD byte skip -1 or MetaImage HeaderSize -1: the data are the file's
                        last bytes, so data_offset is worked out from the file size */
} ip_text_found;

/* IP_ERR_INPUT "PATH: missing key 'KEY'" ("field" for NRRD) for `header` (ip_text_place first,
 * its keys set). */
ip_status ip__text_missing(const void *header, const char *key, ip_error *err);

/*! ip__text_check_dims() : unless `overrides` give the dims, fails (naming the keys) when the
 *  header lacks the number of dimensions (`dimensions` 0) or the sizes (`sizes_count` < 0),
 *  or gives other than 3 sizes. */
ip_status ip__text_check_dims(const void *header, int64_t dimensions, const char *dimensions_key,
                              int sizes_count, const char *sizes_key,
                              const ip_input_overrides *overrides, ip_error *err);

/* Reports the type (when the header had one) and the 3 sizes (when it had 3) in `desc` and
 * `found`. */
void ip__text_found_layout(int has_type, ip_type type, int sizes_count, const uint64_t sizes[3],
                           ip_input_desc *desc, ip_text_found *found);

/* Reads the lines of an open header into `header`, stopping where the header ends. */
typedef ip_status (*ip_text_reader)(ip_text_file *file, void *header,
                                    const ip_input_overrides *overrides, ip_error *err);

/* A header format: its header struct (ip_text_place first, zeroed, then `init`), how to read
 * the lines into it, and how to check it and fill `desc` and `found` from it once the header,
 * of `header_end` bytes, has been read. */
typedef struct ip_text_format {
    const ip_text_keys *keys;
    size_t header_size;
    void (*init)(void *header);
    ip_text_reader read;
    ip_status (*finish)(void *header, uint64_t header_end, const ip_input_overrides *overrides,
                        ip_input_desc *desc, ip_text_found *found, ip_error *err);
} ip_text_format;

/*! ip__text_read_header() : reads the header at `path` in `format` and fills `desc` (already
 *  holding the defaults and `path`) and `found`.
 *  @return : IP_OK, or the first error (IP_ERR_IO, IP_ERR_INPUT naming `path`, IP_ERR_NOMEM). */
ip_status ip__text_read_header(const ip_text_format *format, const char *path,
                               const ip_input_overrides *overrides, ip_input_desc *desc,
                               ip_text_found *found, ip_error *err);

#endif

/* Internal to the input module: what a header parser reports, the header line reader it uses,
 * and the number parsers shared by the NRRD and MetaImage readers. Not part of the public API.
 */
#ifndef ISOPROP_INPUT_HEADERS_H
#define ISOPROP_INPUT_HEADERS_H

#include <stdint.h>
#include <stdio.h>

#include "isoprop/input.h"
#include "isoprop/status.h"

/* Header lines are short in practice, but comments and key/value pairs may be long; a longer
 * line is an error rather than something cut short silently. */
#define IP_TEXT_LINE_MAX 65536

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

/* The header parsers. Each fills `desc` (already holding the defaults and `path`) and
 * `found`, skips the fields that an override replaces, and fails naming `path` and the
 * problem. */
ip_status ip__nrrd_read_header(const char *path, const ip_input_overrides *overrides,
                              ip_input_desc *desc, ip_text_found *found, ip_error *err);
ip_status ip__mhd_read_header(const char *path, const ip_input_overrides *overrides,
                             ip_input_desc *desc, ip_text_found *found, ip_error *err);

/* Reads a text header line by line, keeping count of the bytes used so that attached data
 * can be found right after the header. */
typedef struct ip_text_file {
    FILE *file;
    const char *path;
    char *line;               /* the current line without its "\n" or "\r\n" */
    size_t capacity;
    uint64_t offset;          /* bytes consumed so far: where the next line starts */
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
ip_status ip__text_data_path(const char *header_path, const char *name,
                              char out[IP_PATH_MAX], ip_error *err);

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

#endif

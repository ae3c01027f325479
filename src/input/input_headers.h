/* Internal to the input module: the header parsers input.c calls and what they report. The
 * helpers they share are in text_header.h. Not part of the public API. */
#ifndef ISOPROP_INPUT_HEADERS_H
#define ISOPROP_INPUT_HEADERS_H

#include <stdint.h>

#include "isoprop/input.h"
#include "isoprop/status.h"

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

#endif

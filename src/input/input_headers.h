/* SPDX-License-Identifier: BSD-3-Clause */
/* Internal to the input module: the header formats input.c reads (NRRD, MetaImage), each a
 * table of what text_header.c needs to read it. Not part of the public API. */
#ifndef ISOPROP_INPUT_HEADERS_H
#define ISOPROP_INPUT_HEADERS_H

#include "text_header.h"

/* The header formats, read with ip__text_read_header(). Each fills `desc` (already holding
 * the defaults and `path`) and `found`, skips the fields that an override replaces, and fails
 * naming `path` and the problem. */
extern const ip_text_format ip__nrrd_format;
extern const ip_text_format ip__mhd_format;

#endif

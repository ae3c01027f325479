/* SPDX-License-Identifier: BSD-3-Clause */
/* Checks on ip_input shared by the tests of the input readers (after check.h). */
#ifndef ISOPROP_TEST_INPUT_CHECK_H
#define ISOPROP_TEST_INPUT_CHECK_H

#include <string.h>

#include "check.h"
#include "isoprop/input.h"

/* Describes `path` (with `overrides`, or none), expecting `code` and a one-line message that
 * names `name` and holds `needle`. */
static inline void describe_fails(const char *path, const ip_input_overrides *overrides,
                                  ip_status code, const char *name, const char *needle)
{
    ip_input_desc d;
    ip_error err;
    ip_error_clear(&err);
    ip_status status = ip_input_describe(path, overrides, &d, &err);
    CHECK_MSG(status == code, "%s: got %d (%s), expected %d", path, status, err.message, code);
    CHECK_CONTAINS(err.message, name);
    CHECK_CONTAINS(err.message, needle);
    CHECK_EQ(strchr(err.message, '\n'), NULL);
}

#endif

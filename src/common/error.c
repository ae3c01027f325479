/* SPDX-License-Identifier: BSD-3-Clause */
/* Status messages and the error-report helpers. */
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

const char *ip_status_message(int code)
{
    switch (code) {
    case IP_OK: return "success";
    case IP_ERR_IO: return "input/output error";
    case IP_ERR_NOMEM: return "out of memory";
    case IP_ERR_ARGUMENT: return "invalid argument";
    case IP_ERR_INPUT: return "inconsistent input volume";
    case IP_ERR_FORMAT: return "malformed brick file";
    case IP_ERR_CHECKSUM: return "checksum mismatch";
    case IP_ERR_CORRUPT: return "corrupt brick";
    case IP_ERR_EXISTS: return "output exists";
    case IP_ERR_LIMIT: return "memory limit too small";
    case IP_ERR_UNSUPPORTED: return "unsupported feature";
    case IP_ERR_CANCELLED: return "cancelled";
    default: return "unknown error";
    }
}

void ip_error_clear(ip_error *err)
{
    if (err) {
        err->code = IP_OK;
        err->message[0] = '\0';
    }
}

static void format_into(ip_error *err, ip_status code, const char *fmt, va_list ap)
{
    err->code = code;
    vsnprintf(err->message, sizeof err->message, fmt, ap);
}

ip_status ip__fail(ip_error *err, ip_status code, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        format_into(err, code, fmt, ap);
        va_end(ap);
    }
    return code;
}

ip_status ip__fail_errno(ip_error *err, ip_status code, int errnum, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        format_into(err, code, fmt, ap);
        va_end(ap);
        size_t used = strlen(err->message);
        snprintf(err->message + used, sizeof err->message - used, ": %s", strerror(errnum));
    }
    return code;
}

void ip__assert_fail(const char *file, int line, const char *condition)
{
    fprintf(stderr, "%s:%d: internal assertion failed: %s\n", file, line, condition);
    fflush(stderr);
    abort();
}

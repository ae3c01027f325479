/* SPDX-License-Identifier: BSD-3-Clause */
/* isoprop: status codes and error messages.
 *
 * Every library function that can fail returns an ip_status: IP_OK (0) or a negative code.
 * Functions that can say more take an optional ip_error*, which they fill with the code and a
 * one-line message naming the file (or object) and what is wrong. The library never prints and
 * never exits; the tools print ip_error.message and exit non-zero.
 */
#ifndef ISOPROP_STATUS_H
#define ISOPROP_STATUS_H

/* IP_API marks the library's public functions: the only symbols libisoprop.so exports (the
 * library is compiled with -fvisibility=hidden). */
#if defined(__GNUC__)
#define IP_API __attribute__((visibility("default")))
#else
#define IP_API
#endif

/* Structs that may grow (docs/api.md, "Stability").
 * - The option structs the caller fills (ip_engine_options, ip_bricker_options,
 *   ip_input_overrides, ip_gen_params, ip_shading) start with `uint32_t size`: the bytes of the
 *   struct as the caller's program was compiled. The library reads only that many bytes: the
 *   fields added after the caller was compiled keep their defaults, and a struct from a later
 *   version is taken when the fields this library does not know are zero (else
 *   IP_ERR_UNSUPPORTED). A size of 0, as a zero-initialised struct has, stands for the struct as
 *   version 0.2.0 declared it, so that `{0}` keeps working; the ip_*_default() functions and
 *   IP_SIZED() set the size. Initialise each such struct one of these ways before filling it.
 * - The structs the library fills (ip_input_desc, ip_bricker_report, ip_engine_counts,
 *   ip_engine_memory, ip_cache_stats) keep their size within a major version: they end with
 *   `reserved` words, zero, from which later fields are taken. */
#if !defined(__cplusplus)
/* IP_SIZED(type): a zero-initialised `type` that says its size, e.g.
 * `ip_input_overrides overrides = IP_SIZED(ip_input_overrides);`. */
#define IP_SIZED(type) ((type){.size = (uint32_t)sizeof(type)})
#endif

#ifdef __cplusplus
extern "C" {
#endif

typedef enum ip_status {
    IP_OK = 0,
    IP_ERR_IO = -1,           /* a read, write, open, map or rename failed */
    IP_ERR_NOMEM = -2,        /* an allocation failed */
    IP_ERR_ARGUMENT = -3,     /* the caller passed a value out of range */
    IP_ERR_INPUT = -4,        /* an input volume (raw, NRRD, MetaImage) is inconsistent */
    IP_ERR_FORMAT = -5,       /* a brick file's header or summary is malformed */
    IP_ERR_CHECKSUM = -6,     /* stored bytes do not match their checksum */
    IP_ERR_CORRUPT = -7,      /* a brick decodes wrongly or disagrees with its summary */
    IP_ERR_EXISTS = -8,       /* the output exists and overwriting was not asked for */
    IP_ERR_LIMIT = -9,        /* a memory cap or budget is too small for the work */
    IP_ERR_UNSUPPORTED = -10, /* a valid but unsupported feature (version, encoding) */
    IP_ERR_CANCELLED = -11    /* the caller asked the work to stop */
} ip_status;

/*! ip_status_message() : a short constant English description of `code` (never NULL). */
IP_API const char *ip_status_message(int code);

/* Detailed error report, owned by the caller (usually on its stack). */
typedef struct ip_error {
    ip_status code;
    char message[1024]; /* one line, no trailing newline, e.g. "a.raw: file size ..." */
} ip_error;

/*! ip_error_clear() : resets `err` (may be NULL) to IP_OK and an empty message. */
IP_API void ip_error_clear(ip_error *err);

#ifdef __cplusplus
}
#endif
#endif

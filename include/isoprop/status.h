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

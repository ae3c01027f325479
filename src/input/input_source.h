/* Internal to the input module: the formats with binary headers (TIFF, NIfTI, DICOM), each
 * described by one function, and the plane sources of the encodings that are not one byte
 * stream (TIFF pages or files, DICOM files), which the reader drives one plane at a time.
 * Not part of the public API. */
#ifndef ISOPROP_INPUT_SOURCE_H
#define ISOPROP_INPUT_SOURCE_H

#include <stdint.h>

#include "isoprop/input.h"
#include "text_header.h"

/* A binary-header format's describe function: fills `desc` (holding the defaults and `path`)
 * and `found` from the file or folder at `path`, leaves out what `overrides` replace (as the
 * text headers do, ip__text_overridden()), and fails naming `path` and the problem in one
 * line. The checks common to every format (dims, spacing, sizes) follow in input.c. */
typedef ip_status (*ip__describe_fn)(const char *path, const ip_input_overrides *overrides,
                                     ip_input_desc *desc, ip_text_found *found, ip_error *err);

ip_status ip__tiff_describe(const char *path, const ip_input_overrides *overrides,
                            ip_input_desc *desc, ip_text_found *found, ip_error *err);
ip_status ip__nifti_describe(const char *path, const ip_input_overrides *overrides,
                             ip_input_desc *desc, ip_text_found *found, ip_error *err);
ip_status ip__dicom_describe(const char *path, const ip_input_overrides *overrides,
                             ip_input_desc *desc, ip_text_found *found, ip_error *err);

/* A source of z-planes for IP_ENCODING_TIFF and IP_ENCODING_DICOM. The reader calls open once,
 * read_plane for z = 0, 1, ... in order (each plane exactly once), and close; a source keeps
 * at most a few planes' worth of memory. Messages name desc->path (and the file of the plane
 * where there is one). */
typedef struct ip__plane_source {
    /* Opens the source of `desc`; *state is the source's own, released by close (also after
     * a failed open, which leaves *state NULL or valid). */
    ip_status (*open)(const ip_input_desc *desc, void **state, ip_error *err);
    /* Reads plane z as dims[0] x dims[1] samples of desc->type, x fastest, in the host's byte
     * order, into dst (caller-owned, one plane). IP_ERR_INPUT when the plane's file no longer
     * matches the description (another size, type or compression). */
    ip_status (*read_plane)(void *state, uint32_t z, void *dst, ip_error *err);
    void (*close)(void *state);
} ip__plane_source;

extern const ip__plane_source ip__tiff_source;
extern const ip__plane_source ip__dicom_source;

/*! ip__input_open_regular() : opens `path` read-only without waiting (O_NONBLOCK: a FIFO is
 *  refused, never waited on) and checks that it is a regular file; *fd is the caller's to
 *  close. IP_ERR_IO when it cannot be opened, IP_ERR_INPUT when it is not a regular file. */
ip_status ip__input_open_regular(const char *path, int *fd, ip_error *err);

/*! ip__plane_source_of() : the plane source of an encoding; NULL for raw and gzip data. */
const ip__plane_source *ip__plane_source_of(ip_encoding encoding);

#endif

/* SPDX-License-Identifier: BSD-3-Clause */
/* Internal to the input module: the formats with binary headers (TIFF, NIfTI, DICOM), each
 * described by one function, and the plane sources of the encodings that are not one byte
 * stream (TIFF pages or files, DICOM files), which the reader drives one plane at a time.
 * TIFF and DICOM live in the input component (src/input_formats/, libisoprop_input), found
 * through ip__input_formats_load(). Not part of the public API. */
#ifndef ISOPROP_INPUT_SOURCE_H
#define ISOPROP_INPUT_SOURCE_H

#include <stdint.h>

#include "isoprop/input.h"
#include "isoprop/version.h"
#include "text_header.h"

/* A binary-header format's describe function: fills `desc` (holding the defaults and `path`)
 * and `found` from the file or folder at `path`, leaves out what `overrides` replace (as the
 * text headers do, ip__text_overridden()), and fails naming `path` and the problem in one
 * line. The checks common to every format (dims, spacing, sizes) follow in input.c. */
typedef ip_status (*ip__describe_fn)(const char *path, const ip_input_overrides *overrides,
                                     ip_input_desc *desc, ip_text_found *found, ip_error *err);

ip_status ip__nifti_describe(const char *path, const ip_input_overrides *overrides,
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

/* The series of a DICOM folder (ip_dicom_list_series(), include/isoprop/input.h). */
typedef ip_status (*ip__dicom_list_fn)(const char *folder, ip_dicom_series_info **out,
                                       uint32_t *count, uint32_t *skipped, ip_error *err);

/* The input component's readers, as the component hands them to the core
 * (ip_input_formats_table(), include/isoprop/input_formats.h). */
typedef struct ip__input_formats {
    uint32_t abi; /* IP__INPUT_FORMATS_ABI of the component's build */
    ip__describe_fn tiff_describe, dicom_describe;
    const ip__plane_source *tiff_source, *dicom_source;
    ip__dicom_list_fn dicom_list;
    ip__describe_fn hdf5_describe; /* HDF5 (input_hdf5.c); refuses when built without it */
    const ip__plane_source *hdf5_source;
    ip__describe_fn zarr_describe; /* Zarr v2/v3, OME-Zarr (a build without: a message) */
    const ip__plane_source *zarr_source;
} ip__input_formats;

/* The table's layout and the version of the structs it passes (ip_input_desc, ...): the core
 * takes only a component of its own version. Raise the last part when ip__input_formats or
 * ip__plane_source change. */
#define IP__INPUT_FORMATS_ABI \
    ((uint32_t)(IP_VERSION_MAJOR * 1000000 + IP_VERSION_MINOR * 10000 + IP_VERSION_PATCH * 100 + 4))

/*! ip__input_formats_load() : the input component's readers, which `path` (a TIFF file or a
 *  DICOM or TIFF folder) needs: the ones linked in (the static library, the component itself),
 *  else libisoprop_input.so.MAJOR loaded from the folder of libisoprop.so, else from the
 *  loader's path. IP_ERR_UNSUPPORTED naming `path` and the component when it cannot be loaded
 *  or is of another version. Thread-safe. */
ip_status ip__input_formats_load(const char *path, const ip__input_formats **out, ip_error *err);

/*! ip__encoding_is_planes() : 1 for the encodings read through a plane source (TIFF, DICOM,
 *  HDF5). */
int ip__encoding_is_planes(ip_encoding encoding);

/*! ip__input_format_named() : the input format `path` names by its extension, as words for a
 *  message ("a NIfTI volume", "a raw volume" for .raw), or NULL when it names none. */
const char *ip__input_format_named(const char *path);

/*! ip__input_open_regular() : opens `path` read-only without waiting (O_NONBLOCK: a FIFO is
 *  refused, never waited on) and checks that it is a regular file; *fd is the caller's to
 *  close. IP_ERR_IO when it cannot be opened, IP_ERR_INPUT when it is not a regular file. */
ip_status ip__input_open_regular(const char *path, int *fd, ip_error *err);

/*! ip__plane_source_of() : the plane source of desc's encoding into *out (loading the input
 *  component, ip__input_formats_load()); NULL for raw and gzip data. */
ip_status ip__plane_source_of(const ip_input_desc *desc, const ip__plane_source **out,
                              ip_error *err);

#endif

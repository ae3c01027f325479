/* SPDX-License-Identifier: BSD-3-Clause */
/* isoprop: the input component, libisoprop_input: the readers of TIFF (libtiff), DICOM
 * (GDCM) and Zarr (c-blosc, zstd, lz4, zlib, cJSON), apart from the core so that libisoprop
 * links only lz4, xxhash, zlib, libm and threads and a program that opens brick files loads
 * no image-format library.
 *
 * A program does not call it: ip_input_describe() and the bricker (ip_brick_volume()) load it
 * themselves the first time they meet a TIFF file or a DICOM, TIFF or Zarr folder, from the
 * folder of libisoprop.so (the build folder, the installed library folder, a Python
 * package), else from the loader's search path; without it, such an input fails with
 * IP_ERR_UNSUPPORTED naming the file and libisoprop_input. Linking it (pkg-config isoprop-input, CMake isoprop::input) only
 * makes the dependency explicit for a package manager. The static library libisoprop.a holds
 * the readers itself. Not included by isoprop/isoprop.h.
 */
#ifndef ISOPROP_INPUT_FORMATS_H
#define ISOPROP_INPUT_FORMATS_H

#include <stdint.h>

#include "isoprop/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/*! ip_input_formats_version() : the version of the component, as "MAJOR.MINOR.PATCH"; the core
 *  takes only a component of its own version. A constant string; thread-safe. */
IP_API const char *ip_input_formats_version(void);

/*! ip_input_formats_table() : the component's entry, for the core's loader: its readers'
 *  table when `abi` is the layout this component was built with, else NULL. The table is
 *  constant and owned by the component; thread-safe. */
IP_API const void *ip_input_formats_table(uint32_t abi);

#ifdef __cplusplus
}
#endif
#endif

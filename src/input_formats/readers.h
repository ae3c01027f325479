/* SPDX-License-Identifier: BSD-3-Clause */
/* Internal to the input component (libisoprop_input): its readers, which the core reaches
 * through the table of formats_table.c (ip__input_formats, src/input/input_source.h). */
#ifndef ISOPROP_INPUT_READERS_H
#define ISOPROP_INPUT_READERS_H

#include "input_source.h"

ip_status ip__tiff_describe(const char *path, const ip_input_overrides *overrides,
                            ip_input_desc *desc, ip_text_found *found, ip_error *err);
ip_status ip__dicom_describe(const char *path, const ip_input_overrides *overrides,
                             ip_input_desc *desc, ip_text_found *found, ip_error *err);

ip_status ip__hdf5_describe(const char *path, const ip_input_overrides *overrides,
                            ip_input_desc *desc, ip_text_found *found, ip_error *err);

ip_status ip__dicom_list(const char *folder, ip_dicom_series_info **out, uint32_t *count,
                         uint32_t *skipped, ip_error *err);

ip_status ip__zarr_describe(const char *path, const ip_input_overrides *overrides,
                            ip_input_desc *desc, ip_text_found *found, ip_error *err);

extern const ip__plane_source ip__tiff_source;
extern const ip__plane_source ip__zarr_source;
extern const ip__plane_source ip__dicom_source;
extern const ip__plane_source ip__hdf5_source;

#endif

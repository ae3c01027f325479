/* SPDX-License-Identifier: BSD-3-Clause */
/* The input component's entry: its readers as the core's loader takes them. */
#include <stddef.h>

#include "internal.h"
#include "readers.h"
#include "isoprop/input_formats.h"

static const ip__input_formats readers = {
    IP__INPUT_FORMATS_ABI, ip__tiff_describe, ip__dicom_describe, &ip__tiff_source,
    &ip__dicom_source,     ip__dicom_list,    ip__hdf5_describe,  &ip__hdf5_source,
    ip__zarr_describe,     &ip__zarr_source};

const char *ip_input_formats_version(void)
{
    return IP__VERSION_STRING;
}

const void *ip_input_formats_table(uint32_t abi)
{
    return abi == IP__INPUT_FORMATS_ABI ? &readers : NULL;
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* The Zarr reader's stand-in where the build has none (IP_ZARR off, or its libraries not
 * found at configure time): a Zarr input is refused naming what to install. */
#include "readers.h"
#include "internal.h"

ip_status ip__zarr_describe(const char *path, const ip_input_overrides *overrides,
                            ip_input_desc *desc, ip_text_found *found, ip_error *err)
{
    (void)overrides, (void)desc, (void)found;
    return ip__fail(err, IP_ERR_UNSUPPORTED,
                    "%s: a Zarr folder, but this build reads no Zarr: install libblosc-dev, "
                    "libzstd-dev, liblz4-dev, zlib1g-dev and libcjson-dev and build with "
                    "-DIP_ZARR=ON",
                    path);
}

static ip_status no_open(const ip_input_desc *desc, void **state, ip_error *err)
{
    *state = NULL;
    return ip__zarr_describe(desc->path, NULL, NULL, NULL, err);
}

static ip_status no_read(void *state, uint32_t z, void *dst, ip_error *err)
{
    (void)state, (void)z, (void)dst;
    return ip__fail(err, IP_ERR_UNSUPPORTED, "Zarr: not in this build");
}

static void no_close(void *state)
{
    (void)state;
}

const ip__plane_source ip__zarr_source = {no_open, no_read, no_close};

/* TIFF input: a multi-page TIFF file or a folder of numbered single-page TIFF files, one page
 * a z-plane. (To be written.) */
#include "input_source.h"
#include "internal.h"

ip_status ip__tiff_describe(const char *path, const ip_input_overrides *overrides,
                            ip_input_desc *desc, ip_text_found *found, ip_error *err)
{
    (void)overrides, (void)desc, (void)found;
    return ip__fail(err, IP_ERR_UNSUPPORTED, "%s: TIFF input is not supported yet", path);
}

static ip_status tiff_open(const ip_input_desc *desc, void **state, ip_error *err)
{
    *state = NULL;
    return ip__fail(err, IP_ERR_UNSUPPORTED, "%s: TIFF input is not supported yet", desc->path);
}

static ip_status tiff_read_plane(void *state, uint32_t z, void *dst, ip_error *err)
{
    (void)state, (void)z, (void)dst;
    return ip__fail(err, IP_ERR_UNSUPPORTED, "TIFF input is not supported yet");
}

static void tiff_close(void *state)
{
    (void)state;
}

const ip__plane_source ip__tiff_source = {tiff_open, tiff_read_plane, tiff_close};

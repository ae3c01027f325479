/* DICOM input: a folder holding one series of single-frame DICOM files, one file
 * a z-plane, sorted by position. (To be written.) */
#include "input_source.h"
#include "internal.h"

ip_status ip__dicom_describe(const char *path, const ip_input_overrides *overrides,
                             ip_input_desc *desc, ip_text_found *found, ip_error *err)
{
    (void)overrides, (void)desc, (void)found;
    return ip__fail(err, IP_ERR_UNSUPPORTED, "%s: DICOM input is not supported yet", path);
}

static ip_status dicom_open(const ip_input_desc *desc, void **state, ip_error *err)
{
    *state = NULL;
    return ip__fail(err, IP_ERR_UNSUPPORTED, "%s: DICOM input is not supported yet", desc->path);
}

static ip_status dicom_read_plane(void *state, uint32_t z, void *dst, ip_error *err)
{
    (void)state, (void)z, (void)dst;
    return ip__fail(err, IP_ERR_UNSUPPORTED, "DICOM input is not supported yet");
}

static void dicom_close(void *state)
{
    (void)state;
}

const ip__plane_source ip__dicom_source = {dicom_open, dicom_read_plane, dicom_close};

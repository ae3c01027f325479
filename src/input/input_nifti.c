/* NIfTI-1 and NIfTI-2 input (.nii, .nii.gz). (To be written.) */
#include "input_source.h"
#include "internal.h"

ip_status ip__nifti_describe(const char *path, const ip_input_overrides *overrides,
                             ip_input_desc *desc, ip_text_found *found, ip_error *err)
{
    (void)overrides, (void)desc, (void)found;
    return ip__fail(err, IP_ERR_UNSUPPORTED, "%s: NIfTI input is not supported yet", path);
}

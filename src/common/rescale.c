/* SPDX-License-Identifier: BSD-3-Clause */
/* A volume's rescale (isoprop/volume.h): the one conversion between the file's units and
 * stored sample values, and its check. */
#include <math.h>
#include <string.h>

#include "internal.h"
#include "isoprop/volume.h"

void ip_rescale_identity(ip_rescale *r)
{
    memset(r, 0, sizeof *r);
    r->slope = 1.0;
}

double ip_rescale_to_stored(const ip_rescale *r, double value)
{
    if (!r || !r->present)
        return value;
    return (value - r->intercept) / r->slope;
}

double ip_rescale_to_value(const ip_rescale *r, double stored)
{
    if (!r || !r->present)
        return stored;
    return stored * r->slope + r->intercept;
}

ip_status ip_rescale_check(const ip_rescale *r, const char *name, ip_error *err)
{
    const char *who = name && name[0] ? name : "rescale";
    const char *sep = name && name[0] ? ": rescale" : "";
    if (!r)
        return ip__fail(err, IP_ERR_ARGUMENT, "ip_rescale_check: r is required");
    if (!r->present)
        return IP_OK;
    if (!isfinite(r->slope) || r->slope == 0.0)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s%s slope %g is not a finite number other than 0",
                        who, sep, r->slope);
    if (!isfinite(r->intercept))
        return ip__fail(err, IP_ERR_ARGUMENT, "%s%s intercept %g is not finite", who, sep,
                        r->intercept);
    size_t n = strnlen(r->unit, sizeof r->unit);
    if (n == sizeof r->unit)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s%s unit is longer than %d characters", who, sep,
                        IP_RESCALE_UNIT_MAX - 1);
    for (size_t i = 0; i < n; i++)
        if (r->unit[i] < 0x20 || r->unit[i] > 0x7e)
            return ip__fail(err, IP_ERR_ARGUMENT,
                            "%s%s unit holds a character that is not printable ASCII", who, sep);
    return IP_OK;
}

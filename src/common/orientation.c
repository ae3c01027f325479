/* SPDX-License-Identifier: BSD-3-Clause */
/* Origin and axis directions of a volume in its file's physical space. */
#include <math.h>
#include <string.h>

#include "internal.h"
#include "isoprop/orientation.h"

void ip_orientation_identity(ip_orientation *orientation)
{
    memset(orientation, 0, sizeof *orientation);
    for (int a = 0; a < 3; a++)
        orientation->directions[a][a] = 1.0;
    orientation->space = IP_SPACE_UNKNOWN;
}

int ip_orientation_is_identity(const ip_orientation *orientation)
{
    for (int a = 0; a < 3; a++) {
        if (orientation->origin[a] != 0.0)
            return 0;
        for (int c = 0; c < 3; c++)
            if (orientation->directions[a][c] != (a == c ? 1.0 : 0.0))
                return 0;
    }
    return 1;
}

int ip__orientation_unset(const ip_orientation *o)
{
    for (int a = 0; a < 3; a++)
        for (int c = 0; c < 3; c++)
            if (o->directions[a][c] != 0.0)
                return 0;
    return 1;
}

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

ip_status ip_orientation_check(const ip_orientation *orientation, const char *name, ip_error *err)
{
    const char *prefix = name ? name : "orientation";
    for (int a = 0; a < 3; a++)
        if (!isfinite(orientation->origin[a]))
            return ip__fail(err, IP_ERR_ARGUMENT, "%s: origin %g along %c is not finite", prefix,
                            orientation->origin[a], "xyz"[a]);
    for (int a = 0; a < 3; a++)
        for (int c = 0; c < 3; c++)
            if (!isfinite(orientation->directions[a][c]))
                return ip__fail(err, IP_ERR_ARGUMENT, "%s: the %c direction is not finite", prefix,
                                "xyz"[a]);
    for (int a = 0; a < 3; a++)
        for (int b = a; b < 3; b++) {
            double d = dot3(orientation->directions[a], orientation->directions[b]);
            if (!(fabs(d - (a == b ? 1.0 : 0.0)) <= IP_ORIENTATION_TOLERANCE))
                return ip__fail(err, IP_ERR_ARGUMENT,
                                a == b ? "%s: the %c direction is not a unit vector"
                                       : "%s: the %c and %c directions are not perpendicular",
                                prefix, "xyz"[a], "xyz"[b]);
        }
    if ((unsigned)orientation->space > IP_SPACE_LPS)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: unknown space %u", prefix,
                        (unsigned)orientation->space);
    return IP_OK;
}

void ip_orientation_rotate(const ip_orientation *orientation, const double v[3], double out[3])
{
    double r[3];
    for (int c = 0; c < 3; c++)
        r[c] = orientation->directions[0][c] * v[0] + orientation->directions[1][c] * v[1] +
               orientation->directions[2][c] * v[2];
    memcpy(out, r, sizeof r);
}

void ip_orientation_apply(const ip_orientation *orientation, const double world[3], double out[3])
{
    ip_orientation_rotate(orientation, world, out);
    for (int c = 0; c < 3; c++)
        out[c] += orientation->origin[c];
}

void ip_orientation_unrotate(const ip_orientation *orientation, const double v[3], double out[3])
{
    double r[3];
    for (int a = 0; a < 3; a++)
        r[a] = dot3(orientation->directions[a], v);
    memcpy(out, r, sizeof r);
}

void ip_orientation_to_world(const ip_orientation *orientation, const double physical[3],
                             double out[3])
{
    double d[3];
    for (int c = 0; c < 3; c++)
        d[c] = physical[c] - orientation->origin[c];
    ip_orientation_unrotate(orientation, d, out);
}

int ip_orientation_mirrors(const ip_orientation *orientation)
{
    const double(*d)[3] = orientation->directions;
    double det = d[0][0] * (d[1][1] * d[2][2] - d[1][2] * d[2][1]) -
                 d[0][1] * (d[1][0] * d[2][2] - d[1][2] * d[2][0]) +
                 d[0][2] * (d[1][0] * d[2][1] - d[1][1] * d[2][0]);
    return det < 0;
}

void ip_orientation_plane_to_world(const ip_orientation *orientation, const double normal[3],
                                   double offset, double out_normal[3], double *out_offset)
{
    double shifted = offset + dot3(normal, orientation->origin);
    if (ip_orientation_is_identity(orientation))
        shifted = offset; /* as it is, a zero's sign too */
    ip_orientation_unrotate(orientation, normal, out_normal);
    *out_offset = shifted;
}

int ip_space_direction(ip_space space, const char *name, double out[3])
{
    /* the + end of each axis of each space, as -1 (left, posterior, inferior) or +1 */
    static const char *const names[6] = {"right",     "left",     "anterior",
                                         "posterior", "superior", "inferior"};
    double sign_x = space == IP_SPACE_RAS ? 1.0 : -1.0; /* +x is right only in RAS */
    double sign_y = space == IP_SPACE_LPS ? -1.0 : 1.0; /* +y is posterior only in LPS */
    if (!name || (space != IP_SPACE_RAS && space != IP_SPACE_LAS && space != IP_SPACE_LPS))
        return 0;
    for (int i = 0; i < 6; i++) {
        if (strcmp(name, names[i]) != 0)
            continue;
        double v[3] = {0, 0, 0};
        int axis = i / 2;
        double sign = i % 2 ? -1.0 : 1.0; /* right, anterior, superior first */
        v[axis] = sign * (axis == 0 ? sign_x : axis == 1 ? sign_y : 1.0);
        memcpy(out, v, sizeof v);
        return 1;
    }
    return 0;
}

const char *ip_space_name(ip_space space)
{
    switch (space) {
    case IP_SPACE_RAS: return "RAS";
    case IP_SPACE_LAS: return "LAS";
    case IP_SPACE_LPS: return "LPS";
    case IP_SPACE_UNKNOWN: break;
    }
    return "";
}

int ip_orientation_normalize(double columns[3][3], double lengths[3])
{
    for (int a = 0; a < 3; a++) {
        double n = sqrt(dot3(columns[a], columns[a]));
        if (!(n > 0.0) || !isfinite(n))
            return -1;
        lengths[a] = n;
        for (int c = 0; c < 3; c++)
            columns[a][c] /= n;
    }
    return 0;
}

int ip__orientation_frame(ip_orientation *o, const double directions[3][3])
{
    ip_orientation framed = *o;
    double lengths[3];
    memcpy(framed.directions, directions, sizeof framed.directions);
    if (ip_orientation_normalize(framed.directions, lengths) != 0 ||
        ip_orientation_check(&framed, NULL, NULL) != IP_OK)
        return 0;
    for (int a = 0; a < 3; a++)
        for (int c = 0; c < 3; c++)
            framed.directions[a][c] += 0.0; /* -0 (a zero times -1) becomes 0 */
    *o = framed;
    return 1;
}

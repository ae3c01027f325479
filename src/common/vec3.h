/* SPDX-License-Identifier: BSD-3-Clause */
/* Small operations on 3-vectors of doubles, inline. Internal. Each computes exactly what its
 * expression in the comment computes, in that order, so a caller that replaces the written-out
 * expression with it gets the same bits. `out` may alias an input. */
#ifndef ISOPROP_VEC3_H
#define ISOPROP_VEC3_H

#include <math.h>

/* a - b */
static inline void ip__vec3_sub(const double a[3], const double b[3], double out[3])
{
    out[0] = a[0] - b[0];
    out[1] = a[1] - b[1];
    out[2] = a[2] - b[2];
}

/* a[0] * b[0] + a[1] * b[1] + a[2] * b[2] */
static inline double ip__vec3_dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* a x b = {a1 b2 - a2 b1, a2 b0 - a0 b2, a0 b1 - a1 b0} */
static inline void ip__vec3_cross(const double a[3], const double b[3], double out[3])
{
    double r0 = a[1] * b[2] - a[2] * b[1];
    double r1 = a[2] * b[0] - a[0] * b[2];
    double r2 = a[0] * b[1] - a[1] * b[0];
    out[0] = r0;
    out[1] = r1;
    out[2] = r2;
}

/* sqrt(v . v) */
static inline double ip__vec3_length(const double v[3])
{
    return sqrt(ip__vec3_dot(v, v));
}

/* Divides v by its length when that is positive (a zero or NaN vector stays as it is);
 * returns the length. */
static inline double ip__vec3_normalize(double v[3])
{
    double n = ip__vec3_length(v);
    if (n > 0)
        for (int i = 0; i < 3; i++)
            v[i] /= n;
    return n;
}

#endif

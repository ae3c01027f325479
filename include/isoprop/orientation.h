/* SPDX-License-Identifier: BSD-3-Clause */
/* isoprop: where a volume lies in its file's physical space.
 *
 * A sample's engine (world) position is its index x spacing along each axis. Its physical
 * position, in the space of the file it came from, is origin + D * world, where column a of D
 * (directions[a]) is the unit direction of sample axis a. Spacing stays separate: the
 * directions have length 1.
 */
#ifndef ISOPROP_ORIENTATION_H
#define ISOPROP_ORIENTATION_H

#include <stdint.h>

#include "isoprop/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The anatomical space a file names for its axes; IP_SPACE_UNKNOWN where it names none. */
typedef enum ip_space {
    IP_SPACE_UNKNOWN = 0,
    IP_SPACE_RAS = 1, /* x right, y anterior, z superior (NIfTI, NRRD "right-anterior-superior") */
    IP_SPACE_LAS = 2, /* x left, y anterior, z superior */
    IP_SPACE_LPS = 3  /* x left, y posterior, z superior (DICOM) */
} ip_space;

/* Origin and axis directions of a volume in its file's space. */
typedef struct ip_orientation {
    double origin[3];        /* physical position of sample (0,0,0), in world units */
    double directions[3][3]; /* directions[a]: unit vector of sample axis a (x, y, z) */
    ip_space space;
} ip_orientation;

/* How far from unit length and from perpendicular the directions may be. */
#define IP_ORIENTATION_TOLERANCE 1e-4

/*! ip_orientation_identity() : origin 0, directions the unit axes, space unknown. */
IP_API void ip_orientation_identity(ip_orientation *orientation);

/*! ip_orientation_check() : checks that the origin is finite, the space a known value and
 *  the directions finite and orthonormal (within IP_ORIENTATION_TOLERANCE). `name` (may be
 *  NULL) starts the message. @return IP_OK, or IP_ERR_ARGUMENT with a one-line message. */
IP_API ip_status ip_orientation_check(const ip_orientation *orientation, const char *name,
                                      ip_error *err);

/*! ip_orientation_is_identity() : 1 when the origin is 0 and the directions the unit axes. */
IP_API int ip_orientation_is_identity(const ip_orientation *orientation);

/*! ip_orientation_apply() : physical position of world position `world`: origin + D * world. */
IP_API void ip_orientation_apply(const ip_orientation *orientation, const double world[3],
                                 double out[3]);

/*! ip_orientation_rotate() : `v` (a normal or a direction) turned by D: D * v. */
IP_API void ip_orientation_rotate(const ip_orientation *orientation, const double v[3],
                                  double out[3]);

/*! ip_space_name() : "RAS", "LAS", "LPS", or "" for IP_SPACE_UNKNOWN and other values. */
IP_API const char *ip_space_name(ip_space space);

/*! ip_orientation_normalize() : scales `columns` (three vectors) to unit length, writing
 *  their lengths to `lengths`. @return 0, or -1 when a vector is zero or not
 *  finite. */
IP_API int ip_orientation_normalize(double columns[3][3], double lengths[3]);

#ifdef __cplusplus
}
#endif
#endif

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

/* ---- Experimental (IP_EXPERIMENTAL) ----
 * Declared only where IP_EXPERIMENTAL is defined before the include (docs/api.md,
 * "Stability"): calls for advanced uses that may change in a minor version, as the
 * programs use them. Exported all the same.
 *
 * Physical space to world space. The engine, its cameras and its clipping planes work in world
 * units (index x spacing); the programs take views, cameras and planes in the file's physical
 * space and map them here. D being orthonormal, the map is rigid: world = D^T (physical -
 * origin). When D is a reflection (det D < 0: one axis stored in the other order, or three),
 * a world camera sees the mirror image of what the same camera sees in physical space:
 * ip_orientation_mirrors() says so, and the image's columns are then reversed (column x of the
 * world image is column width - 1 - x of the physical one, exactly: pixel centres are
 * symmetric about the image's centre). See camera.h for cameras and views. */
#ifdef IP_EXPERIMENTAL

/*! ip_orientation_to_world() : world position of physical position `physical`:
 *  D^T (physical - origin), the inverse of ip_orientation_apply(). `out` may alias it. */
IP_API void ip_orientation_to_world(const ip_orientation *orientation, const double physical[3],
                                    double out[3]);

/*! ip_orientation_unrotate() : `v` (a direction) turned back by D: D^T * v, the inverse of
 *  ip_orientation_rotate(). `out` may alias it. */
IP_API void ip_orientation_unrotate(const ip_orientation *orientation, const double v[3],
                                    double out[3]);

/*! ip_orientation_mirrors() : 1 when D is a reflection (its determinant is negative), so that
 *  a world camera's image is the mirror of the physical one; else 0. */
IP_API int ip_orientation_mirrors(const ip_orientation *orientation);

/*! ip_orientation_plane_to_world() : the plane that keeps normal . p + offset >= 0 for physical
 *  positions p, as world positions w see it: (D^T normal) . w + (offset + normal . origin) >= 0
 *  (the engine's ip_clip_plane). `out_normal` may alias `normal`. */
IP_API void ip_orientation_plane_to_world(const ip_orientation *orientation, const double normal[3],
                                          double offset, double out_normal[3], double *out_offset);

/*! ip_space_direction() : the unit vector, in `space`'s coordinates, of the anatomical
 *  direction `name`: "left", "right", "anterior", "posterior", "superior" or "inferior"
 *  (RAS: right +x, anterior +y, superior +z; LAS: left +x; LPS: left +x, posterior +y).
 *  @return 1, or 0 (out untouched) for IP_SPACE_UNKNOWN, another space value or another
 *  name. Thread-safe. */
IP_API int ip_space_direction(ip_space space, const char *name, double out[3]);

#endif /* IP_EXPERIMENTAL */

#ifdef __cplusplus
}
#endif
#endif

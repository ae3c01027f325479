/* SPDX-License-Identifier: BSD-3-Clause */
/* isoprop: the pinhole camera shared by ray casting and rendering.
 *
 * World coordinates honour voxel spacing: sample (i, j, k) of level 0 sits at
 * (i * spacing[0], j * spacing[1], k * spacing[2]). Pixels are addressed from the top-left
 * corner of the image, x to the right and y down; the ray of pixel (x, y) passes through the
 * pixel's centre (x + 0.5, y + 0.5), exactly where OpenGL samples it, so a ray and the
 * rasteriser agree on which surface a pixel shows.
 */
#ifndef ISOPROP_CAMERA_H
#define ISOPROP_CAMERA_H

#include <stdint.h>

#include "isoprop/orientation.h"
#include "isoprop/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ip_camera {
    double eye[3];          /* world units */
    double target[3];       /* the point the view is centred on */
    double up[3];           /* need not be orthogonal to the view direction, must not be parallel */
    double fov_y;           /* vertical field of view, degrees, in (0, 180) */
    uint32_t width, height; /* pixels */
} ip_camera;

/* An orthonormal basis: forward points from the eye to the target. */
typedef struct ip_camera_basis {
    double right[3], up[3], forward[3];
    double tan_half_y, tan_half_x; /* tangents of the half fields of view */
} ip_camera_basis;

/*! ip_camera_check() : validates a camera (finite values, eye != target, up not parallel to
 *  the view, fov in (0, 180), size >= 1). @return IP_OK or IP_ERR_ARGUMENT with a message. */
IP_API ip_status ip_camera_check(const ip_camera *camera, ip_error *err);

/*! ip_camera_basis_of() : the camera's basis; the camera must pass ip_camera_check(). */
IP_API void ip_camera_basis_of(const ip_camera *camera, ip_camera_basis *basis);

/*! ip_camera_pixel_ray() : the unit world direction of the ray through image point (px, py)
 *  (pixels from the top-left corner; a pixel's centre is at +0.5). */
IP_API void ip_camera_pixel_ray(const ip_camera_basis *basis, const ip_camera *camera, double px,
                                double py, double dir[3]);

/*! ip_camera_project() : image coordinates (pixels, top-left origin) and depth along the view
 *  direction of world point `p`; returns 0 when p is not in front of the eye. */
IP_API int ip_camera_project(const ip_camera_basis *basis, const ip_camera *camera,
                             const double p[3], double *px, double *py, double *depth);

/*! ip_camera_view_matrix() : the OpenGL view matrix (column-major 4x4). */
IP_API void ip_camera_view_matrix(const ip_camera *camera, float m[16]);

/*! ip_camera_projection_matrix() : the OpenGL perspective matrix (column-major 4x4) for the
 *  camera's field of view and aspect, with near and far planes in world units (0 < near < far). */
IP_API void ip_camera_projection_matrix(const ip_camera *camera, double near_plane,
                                        double far_plane, float m[16]);

/*! ip_camera_depth_range() : near and far planes that enclose the box [lo, hi] (world units)
 *  as seen from the camera, with near > 0 even when the eye is inside the box. */
IP_API void ip_camera_depth_range(const ip_camera *camera, const double lo[3], const double hi[3],
                                  double *near_plane, double *far_plane);

/*! ip_camera_fit_axis() : a camera on the `axis` side ("+x", "-x", "+y", "-y", "+z", "-z") of
 *  the box [lo, hi] (world units) looking at its centre, far enough for the whole box to fit
 *  the frame; up is +z, or +y for the z views. @return IP_OK or IP_ERR_ARGUMENT. */
IP_API ip_status ip_camera_fit_axis(const double lo[3], const double hi[3], const char *axis,
                                    double fov_y, uint32_t width, uint32_t height, ip_camera *out,
                                    ip_error *err);

/*! ip_camera_parse() : parses "ex,ey,ez,tx,ty,tz,ux,uy,uz,fov" (world units, degrees) into
 *  the camera's eye, target, up and fov; width and height are left untouched.
 *  @return IP_OK or IP_ERR_ARGUMENT. */
IP_API ip_status ip_camera_parse(const char *text, ip_camera *camera, ip_error *err);

/* Camera motions, as a viewer's mouse makes them. Each changes eye, target and up only (the
 * field of view and the image size stay); the camera must pass ip_camera_check() before, and
 * still does after. */

/*! ip_camera_orbit() : turns the eye around the target, keeping its distance: first
 *  `right_degrees` about the camera's up axis (positive: the eye moves to the left, so that the
 *  scene turns to the right, as a drag to the right turns it), then `down_degrees` about the
 *  camera's right axis after that turn (positive: the eye moves up, the scene turns down). Up
 *  turns along and leaves orthonormal to the view, so that no path of orbits makes the camera
 *  degenerate; orbiting by 360 degrees returns to the start (within rounding). */
IP_API void ip_camera_orbit(ip_camera *camera, double right_degrees, double down_degrees);

/*! ip_camera_pan() : moves eye and target together by `right` world units along the camera's
 *  right axis and `up` world units along its up axis (both of ip_camera_basis_of()), so the
 *  view direction and the distance stay. */
IP_API void ip_camera_pan(ip_camera *camera, double right, double up);

/*! ip_camera_pixel_size() : the world units one pixel spans at the target's distance, in an
 *  image `height` pixels tall (> 0) with the camera's vertical field of view: what a pan by
 *  one pixel moves for the point at the target to follow the cursor. */
IP_API double ip_camera_pixel_size(const ip_camera *camera, double height);

/*! ip_camera_distance() : the distance from the eye to the target, world units. */
IP_API double ip_camera_distance(const ip_camera *camera);

/*! ip_camera_dolly() : moves the eye along the view direction toward the target (the target
 *  stays): the distance is divided by `factor` (> 0; 2 halves it, 0.5 doubles it), then kept
 *  within [min_distance, max_distance] (world units, 0 < min_distance <= max_distance; pass
 *  0 and INFINITY for no limit). The view direction and up stay. */
IP_API void ip_camera_dolly(ip_camera *camera, double factor, double min_distance,
                            double max_distance);

/* ---- Experimental (IP_EXPERIMENTAL) ----
 * Declared only where IP_EXPERIMENTAL is defined before the include (docs/api.md,
 * "Stability"): calls for advanced uses that may change in a minor version, as the
 * programs use them. Exported all the same.
 *
 * Views in physical space. A volume is shown in its file's physical frame (origin, directions
 * and spacing applied: isoprop/orientation.h), so that one physical object stored in any order
 * gives the same picture. The programs take views and cameras there and hand the engine and the
 * renderers their world counterparts, made here: a physical camera maps exactly to a world
 * camera by the inverse rigid transform (eye and target D^T (p - origin), up D^T up). Where D
 * is a reflection (ip_orientation_mirrors()), the world camera's image is the mirror of the
 * physical view: its columns are reversed to show it (the programs do so, and
 * ip_overlay_axis_directions() draws the axes as the physical view shows them).
 *
 * Named views: "+x", "-x", "+y", "-y", "+z", "-z" put the eye on that side of the volume along
 * the file's physical axes (up +z, or +y for the z views), as ip_camera_fit_axis() does in world
 * space; "anterior", "posterior", "left", "right", "superior", "inferior" put it on that
 * anatomical side (up superior, or anterior for the superior and inferior views), in a file
 * whose space is known (RAS, LAS, LPS). "anterior" looks at the face. */
#ifdef IP_EXPERIMENTAL

/*! ip_camera_to_world() : the world camera of `physical` (eye, target and up in the physical
 *  space of `orientation`): eye and target ip_orientation_to_world(), up
 *  ip_orientation_unrotate(); the field of view and size copied. Where the orientation is
 *  the identity (origin 0, unit directions: ip_orientation_is_identity()) the world camera is
 *  `physical`, to the bit.
 *  `world` may alias `physical`. */
IP_API void ip_camera_to_world(const ip_orientation *orientation, const ip_camera *physical,
                               ip_camera *world);

/*! ip_camera_to_physical() : the inverse: eye and target ip_orientation_apply(), up
 *  ip_orientation_rotate() (`world` itself with the identity). `physical` may alias
 *  `world`. */
IP_API void ip_camera_to_physical(const ip_orientation *orientation, const ip_camera *world,
                                  ip_camera *physical);

/*! ip_view_check() : whether `view` is a view name (see above), for a command line read
 *  before any file is open. @return IP_OK or IP_ERR_ARGUMENT ("view 'NAME' is not one of
 *  ..."). Thread-safe. */
IP_API ip_status ip_view_check(const char *view, ip_error *err);

/*! ip_view_default() : the view shown when none is asked for: "anterior" for a file whose
 *  space is known, "-y" otherwise. A static string. Thread-safe. */
IP_API const char *ip_view_default(const ip_orientation *orientation);

/*! ip_camera_fit_view() : the world camera of the named view `view` (NULL: ip_view_default())
 *  of the volume whose world box is [lo, hi] (world units) and whose physical space is
 *  `orientation`: the eye on that side of the volume in physical space, looking at the box's
 *  centre, far enough for the whole box to fit the frame (as ip_camera_fit_axis(), which it
 *  equals to the bit for an axis name where the directions are the unit axes). Where the
 *  orientation mirrors, the image is to be mirrored (see above).
 *  @return IP_OK, or IP_ERR_ARGUMENT for a name that is not a view, or an anatomical name in a
 *  file whose space is unknown ("view 'anterior' needs a file with an anatomical space ...").
 *  Thread-safe. */
IP_API ip_status ip_camera_fit_view(const ip_orientation *orientation, const double lo[3],
                                    const double hi[3], const char *view, double fov_y,
                                    uint32_t width, uint32_t height, ip_camera *world,
                                    ip_error *err);

#endif /* IP_EXPERIMENTAL */

#ifdef __cplusplus
}
#endif
#endif

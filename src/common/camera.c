/* SPDX-License-Identifier: BSD-3-Clause */
/* The pinhole camera: basis, pixel rays, projection, OpenGL matrices, framing presets, motions. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "isoprop/camera.h"
#include "vec3.h"

#define DEG (3.14159265358979323846 / 180.0)

ip_status ip_camera_check(const ip_camera *c, ip_error *err)
{
    for (int i = 0; i < 3; i++)
        if (!isfinite(c->eye[i]) || !isfinite(c->target[i]) || !isfinite(c->up[i]))
            return ip__fail(err, IP_ERR_ARGUMENT, "camera: coordinates must be finite");
    if (!(c->fov_y > 0.0 && c->fov_y < 180.0))
        return ip__fail(err, IP_ERR_ARGUMENT, "camera: field of view %g is not in (0, 180) degrees",
                        c->fov_y);
    if (c->width < 1 || c->height < 1)
        return ip__fail(err, IP_ERR_ARGUMENT, "camera: image size must be at least 1x1");
    double f[3], u[3] = {c->up[0], c->up[1], c->up[2]}, r[3];
    ip__vec3_sub(c->target, c->eye, f);
    if (ip__vec3_normalize(f) == 0.0)
        return ip__fail(err, IP_ERR_ARGUMENT, "camera: eye and target coincide");
    if (ip__vec3_normalize(u) == 0.0)
        return ip__fail(err, IP_ERR_ARGUMENT, "camera: up is zero");
    ip__vec3_cross(f, u, r);
    if (ip__vec3_length(r) < 1e-6)
        return ip__fail(err, IP_ERR_ARGUMENT, "camera: up is parallel to the view direction");
    return IP_OK;
}

void ip_camera_basis_of(const ip_camera *c, ip_camera_basis *b)
{
    ip__vec3_sub(c->target, c->eye, b->forward);
    memcpy(b->up, c->up, sizeof b->up);
    ip__vec3_normalize(b->forward);
    ip__vec3_cross(b->forward, b->up, b->right);
    ip__vec3_normalize(b->right);
    ip__vec3_cross(b->right, b->forward, b->up);
    b->tan_half_y = tan(c->fov_y * DEG / 2);
    b->tan_half_x = b->tan_half_y * (double)c->width / (double)c->height;
}

void ip_camera_pixel_ray(const ip_camera_basis *b, const ip_camera *c, double px, double py,
                         double dir[3])
{
    double nx = (2.0 * px / c->width - 1.0) * b->tan_half_x;
    double ny = (1.0 - 2.0 * py / c->height) * b->tan_half_y;
    for (int i = 0; i < 3; i++)
        dir[i] = b->forward[i] + nx * b->right[i] + ny * b->up[i];
    ip__vec3_normalize(dir);
}

int ip_camera_project(const ip_camera_basis *b, const ip_camera *c, const double p[3], double *px,
                      double *py, double *depth)
{
    double v[3];
    ip__vec3_sub(p, c->eye, v);
    double z = ip__vec3_dot(v, b->forward);
    if (!(z > 0.0))
        return 0;
    double nx = ip__vec3_dot(v, b->right) / (z * b->tan_half_x);
    double ny = ip__vec3_dot(v, b->up) / (z * b->tan_half_y);
    *px = (nx + 1.0) * 0.5 * c->width;
    *py = (1.0 - ny) * 0.5 * c->height;
    *depth = z;
    return 1;
}

void ip_camera_view_matrix(const ip_camera *c, float m[16])
{
    ip_camera_basis b;
    ip_camera_basis_of(c, &b);
    const double *r = b.right, *u = b.up, *f = b.forward;
    float v[16] = {(float)r[0],
                   (float)u[0],
                   (float)-f[0],
                   0,
                   (float)r[1],
                   (float)u[1],
                   (float)-f[1],
                   0,
                   (float)r[2],
                   (float)u[2],
                   (float)-f[2],
                   0,
                   (float)-ip__vec3_dot(r, c->eye),
                   (float)-ip__vec3_dot(u, c->eye),
                   (float)ip__vec3_dot(f, c->eye),
                   1};
    memcpy(m, v, sizeof v);
}

void ip_camera_projection_matrix(const ip_camera *c, double n, double f, float m[16])
{
    double t = tan(c->fov_y * DEG / 2), aspect = (double)c->width / (double)c->height;
    memset(m, 0, 16 * sizeof *m);
    m[0] = (float)(1.0 / (t * aspect));
    m[5] = (float)(1.0 / t);
    m[10] = (float)(-(f + n) / (f - n));
    m[11] = -1.0f;
    m[14] = (float)(-2.0 * f * n / (f - n));
}

void ip_camera_depth_range(const ip_camera *c, const double lo[3], const double hi[3],
                           double *near_plane, double *far_plane)
{
    ip_camera_basis b;
    ip_camera_basis_of(c, &b);
    double zmin = INFINITY, zmax = -INFINITY;
    for (int k = 0; k < 8; k++) {
        double p[3] = {k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]};
        double v[3];
        ip__vec3_sub(p, c->eye, v);
        double z = ip__vec3_dot(v, b.forward);
        zmin = fmin(zmin, z);
        zmax = fmax(zmax, z);
    }
    double extent = 0;
    for (int i = 0; i < 3; i++)
        extent = fmax(extent, hi[i] - lo[i]);
    if (zmax <= 0)
        zmax = extent;
    /* the margin scales with the volume: an absolute one (it was 1e-3 world units) dwarfed
     * volumes a few nanometres across, and the near plane, far / 10^5, then clipped them */
    *far_plane = zmax * 1.01 + 1e-3 * extent;
    /* keep the depth buffer's precision: near no closer than far / 10^5 */
    *near_plane = fmax(zmin * 0.99, *far_plane * 1e-5);
}

/* The camera whose eye lies on the `back` side (a unit world vector) of the box [lo, hi],
 * looking at its centre with `up` (unit, perpendicular to back), as near as it can be with
 * all 8 corners inside the frame. With unit axes for back and up every product below is exact,
 * so that the axis views come out as they always did, to the bit. */
static ip_status fit_direction(const double lo[3], const double hi[3], const double back[3],
                               const double up[3], double fov_y, uint32_t width, uint32_t height,
                               ip_camera *out, ip_error *err)
{
    double centre[3], across[3], upward[3];
    for (int i = 0; i < 3; i++)
        centre[i] = 0.5 * (lo[i] + hi[i]);
    memset(out, 0, sizeof *out);
    out->fov_y = fov_y;
    out->width = width;
    out->height = height;
    memcpy(out->up, up, sizeof out->up);
    /* the image's horizontal axis, and its vertical one */
    ip__vec3_cross(up, back, across);
    ip__vec3_normalize(across);
    ip__vec3_cross(back, across, upward);
    double tan_y = tan(fov_y * DEG / 2), tan_x = tan_y * (double)width / (double)height;
    /* the nearest eye distance from the centre at which all 8 corners project inside the
     * frame: a corner offset (du, dv) across and dw towards the eye needs
     * distance >= dw + |du| / tan_x and >= dw + |dv| / tan_y */
    double distance = 0;
    for (int k = 0; k < 8; k++) {
        double p[3] = {k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]}, d[3];
        ip__vec3_sub(p, centre, d);
        double du = fabs(ip__vec3_dot(d, across)), dv = fabs(ip__vec3_dot(d, upward));
        double dw = ip__vec3_dot(d, back);
        distance = fmax(distance, dw + du / tan_x);
        distance = fmax(distance, dw + dv / tan_y);
    }
    distance *= 1.04; /* a small margin around the volume */
    memcpy(out->target, centre, sizeof centre);
    for (int i = 0; i < 3; i++)
        out->eye[i] = centre[i] + back[i] * distance;
    return ip_camera_check(out, err);
}

/* The physical eye side and up of an axis name ("+x" .. "-z"): 1, or 0 when it is not one. */
static int axis_view(const char *axis, double back[3], double up[3])
{
    if (!axis || strlen(axis) != 2 || (axis[0] != '+' && axis[0] != '-') || axis[1] < 'x' ||
        axis[1] > 'z')
        return 0;
    int a = axis[1] - 'x';
    for (int i = 0; i < 3; i++)
        back[i] = up[i] = 0.0;
    back[a] = axis[0] == '+' ? 1.0 : -1.0;
    up[a == 2 ? 1 : 2] = 1.0;
    return 1;
}

ip_status ip_camera_fit_axis(const double lo[3], const double hi[3], const char *axis, double fov_y,
                             uint32_t width, uint32_t height, ip_camera *out, ip_error *err)
{
    double back[3], up[3];
    if (!axis_view(axis, back, up))
        return ip__fail(err, IP_ERR_ARGUMENT, "view '%s' is not one of +x -x +y -y +z -z",
                        axis ? axis : "");
    return fit_direction(lo, hi, back, up, fov_y, width, height, out, err);
}

/* The anatomical views: the side the eye is on and the view's up. */
static const char *const anatomical_views[6][2] = {
    {"anterior", "superior"}, {"posterior", "superior"}, {"left", "superior"},
    {"right", "superior"},    {"superior", "anterior"},  {"inferior", "anterior"}};

static int anatomical_index(const char *view)
{
    for (int i = 0; view && i < 6; i++)
        if (!strcmp(view, anatomical_views[i][0]))
            return i;
    return -1;
}

#define VIEW_NAMES "+x -x +y -y +z -z anterior posterior left right superior inferior"

ip_status ip_view_check(const char *view, ip_error *err)
{
    double back[3], up[3];
    if (axis_view(view, back, up) || anatomical_index(view) >= 0)
        return IP_OK;
    return ip__fail(err, IP_ERR_ARGUMENT, "view '%s' is not one of " VIEW_NAMES, view ? view : "");
}

const char *ip_view_default(const ip_orientation *o)
{
    return o->space != IP_SPACE_UNKNOWN ? "anterior" : "-y";
}

ip_status ip_camera_fit_view(const ip_orientation *o, const double lo[3], const double hi[3],
                             const char *view, double fov_y, uint32_t width, uint32_t height,
                             ip_camera *out, ip_error *err)
{
    double back[3], up[3];
    if (!view)
        view = ip_view_default(o);
    int named = anatomical_index(view);
    if (named >= 0) {
        if (!ip_space_direction(o->space, anatomical_views[named][0], back) ||
            !ip_space_direction(o->space, anatomical_views[named][1], up))
            return ip__fail(err, IP_ERR_ARGUMENT,
                            "view '%s' needs a file with an anatomical space (RAS, LAS or LPS); "
                            "this one names none: use +x -x +y -y +z -z, its physical axes",
                            view);
    } else if (!axis_view(view, back, up)) {
        return ip_view_check(view, err);
    }
    /* into world space; D is orthonormal, so they stay unit vectors and perpendicular */
    ip_orientation_unrotate(o, back, back);
    ip_orientation_unrotate(o, up, up);
    return fit_direction(lo, hi, back, up, fov_y, width, height, out, err);
}

void ip_camera_to_world(const ip_orientation *o, const ip_camera *physical, ip_camera *world)
{
    ip_camera c = *physical;
    if (ip_orientation_is_identity(o)) { /* as it is, zeros' signs too */
        *world = c;
        return;
    }
    ip_orientation_to_world(o, physical->eye, c.eye);
    ip_orientation_to_world(o, physical->target, c.target);
    ip_orientation_unrotate(o, physical->up, c.up);
    *world = c;
}

void ip_camera_to_physical(const ip_orientation *o, const ip_camera *world, ip_camera *physical)
{
    ip_camera c = *world;
    if (ip_orientation_is_identity(o)) {
        *physical = c;
        return;
    }
    ip_orientation_apply(o, world->eye, c.eye);
    ip_orientation_apply(o, world->target, c.target);
    ip_orientation_rotate(o, world->up, c.up);
    *physical = c;
}

ip_status ip_camera_parse(const char *text, ip_camera *c, ip_error *err)
{
    double v[10];
    const char *p = text;
    for (int i = 0; i < 10; i++) {
        char *end;
        v[i] = strtod(p, &end);
        if (end == p || !isfinite(v[i]) || (i < 9 ? *end != ',' : *end != '\0'))
            return ip__fail(err, IP_ERR_ARGUMENT,
                            "--camera '%s' is not ex,ey,ez,tx,ty,tz,ux,uy,uz,fov", text);
        p = end + 1;
    }
    for (int i = 0; i < 3; i++) {
        c->eye[i] = v[i];
        c->target[i] = v[3 + i];
        c->up[i] = v[6 + i];
    }
    c->fov_y = v[9];
    return IP_OK;
}

/* Turns v by `degrees` about the unit `axis` (Rodrigues' formula). */
static void rotate3(double v[3], const double axis[3], double degrees)
{
    double a = degrees * 3.14159265358979323846 / 180.0, c = cos(a), s = sin(a);
    double d = ip__vec3_dot(axis, v);
    double x[3];
    ip__vec3_cross(axis, v, x);
    for (int i = 0; i < 3; i++)
        v[i] = v[i] * c + x[i] * s + axis[i] * d * (1 - c);
}

void ip_camera_orbit(ip_camera *c, double right_degrees, double down_degrees)
{
    ip_camera_basis b;
    ip_camera_basis_of(c, &b);
    double offset[3], up[3], axis[3];
    for (int i = 0; i < 3; i++) {
        offset[i] = c->eye[i] - c->target[i];
        up[i] = b.up[i];
        axis[i] = b.right[i];
    }
    rotate3(offset, b.up, -right_degrees);
    rotate3(axis, b.up, -right_degrees); /* the right axis after the first turn */
    rotate3(offset, axis, -down_degrees);
    rotate3(up, axis, -down_degrees);
    for (int i = 0; i < 3; i++) {
        c->eye[i] = c->target[i] + offset[i];
        c->up[i] = up[i];
    }
}

void ip_camera_pan(ip_camera *c, double right, double up)
{
    ip_camera_basis b;
    ip_camera_basis_of(c, &b);
    for (int i = 0; i < 3; i++) {
        double move = right * b.right[i] + up * b.up[i];
        c->eye[i] += move;
        c->target[i] += move;
    }
}

double ip_camera_distance(const ip_camera *c)
{
    double d[3] = {c->eye[0] - c->target[0], c->eye[1] - c->target[1], c->eye[2] - c->target[2]};
    return ip__vec3_length(d);
}

double ip_camera_pixel_size(const ip_camera *c, double height)
{
    return 2.0 * ip_camera_distance(c) * tan(c->fov_y * DEG / 2) / height;
}

void ip_camera_dolly(ip_camera *c, double factor, double min_distance, double max_distance)
{
    double d = ip_camera_distance(c), wanted = d / factor;
    if (wanted < min_distance)
        wanted = min_distance;
    if (wanted > max_distance)
        wanted = max_distance;
    for (int i = 0; i < 3; i++)
        c->eye[i] = c->target[i] + (c->eye[i] - c->target[i]) * wanted / d;
}

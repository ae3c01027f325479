/* SPDX-License-Identifier: BSD-3-Clause */
/* Adaptive resolution: the distance bands of a view's pyramid levels (lod.h). */
#include <math.h>

#include "lod.h"

uint32_t ip__lod_distances(const ip_layout *l, const ip_camera *camera, int lod, double pixel_error,
                           double D[IP_MAX_LEVELS + 1])
{
    ip_camera_basis basis;
    ip_camera_basis_of(camera, &basis);
    double spacing = fmax(l->spacing[0], fmax(l->spacing[1], l->spacing[2]));
    double pixels_per_radian = 0.5 * camera->height / basis.tan_half_y;
    double far = 0;
    for (int k = 0; k < 8; k++) {
        double corner[3], v[3];
        for (int a = 0; a < 3; a++)
            corner[a] = (k >> a & 1) ? (l->dims[a] - 1) * l->spacing[a] : 0;
        ip__vec3_sub(corner, camera->eye, v);
        far = fmax(far, ip__vec3_length(v));
    }
    uint32_t levels = 1;
    D[0] = 0;
    for (uint32_t k = 1; lod && k < l->level_count; k++) {
        double d = (double)(1u << k) * spacing * pixels_per_radian / pixel_error;
        if (d >= far)
            break;
        D[k] = d;
        levels = k + 1;
    }
    D[levels] = INFINITY;
    return levels;
}

int ip__lod_box_outside(const double lo[3], const double hi[3], const double eye[3], double near,
                        double far)
{
    double near2 = 0, far2 = 0; /* squared distances to the box's nearest and farthest points */
    for (int a = 0; a < 3; a++) {
        double e = eye[a], in = e < lo[a] ? lo[a] - e : e > hi[a] ? e - hi[a] : 0.0;
        double out = e - lo[a] > hi[a] - e ? e - lo[a] : hi[a] - e;
        near2 += in * in;
        far2 += out * out;
    }
    return sqrt(far2) < near || sqrt(near2) > far;
}

double ip__lod_cell_radius(const ip_layout *l, uint32_t k)
{
    double d2 = 0;
    for (int a = 0; a < 3; a++) {
        double side = l->spacing[a] * (double)(1u << k);
        d2 += side * side;
    }
    return 0.5 * sqrt(d2);
}

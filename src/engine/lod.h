/* SPDX-License-Identifier: BSD-3-Clause */
/* Adaptive resolution: the distance bands of a view's pyramid levels. Internal.
 *
 * A view uses levels 0 .. levels - 1. A cell of level k belongs to the view's surface when
 * the distance (world units) from the eye to its centre lies in [D[k], D[k + 1]), the band of
 * level k, with D[0] = 0 and D[levels] = +infinity. Propagation, the rays' walks and the full
 * extraction at adaptive resolution (ip_extract_full_lod()) all apply this one rule, the
 * centre by ip__sampler_cell_centre(), the distance by ip__lod_centre_distance() and the band
 * by ip__lod_in_band(), so that they agree to the bit on every cell: the progressive image
 * with adaptive resolution then equals that full extraction's once every ray has been cast. */
#ifndef ISOPROP_LOD_H
#define ISOPROP_LOD_H

#include <stdint.h>

#include "isoprop/camera.h"
#include "isoprop/layout.h"
#include "sampler.h"
#include "vec3.h"

/* Sets D[0 .. levels] for `camera` and returns `levels` (1 when `lod` is 0): D[k] is where a
 * level-k cell (2^k level-0 cells across, at the largest spacing) projects to `pixel_error`
 * pixels; levels whose D lies beyond the volume's farthest corner from the eye are not used. */
uint32_t ip__lod_distances(const ip_layout *l, const ip_camera *camera, int lod, double pixel_error,
                           double D[IP_MAX_LEVELS + 1]);

/* Half the diagonal of a level-k cell at the layout's spacing (world units): no point of a
 * level-k cell lies farther from its centre (the last cells along an axis are no larger). */
double ip__lod_cell_radius(const ip_layout *l, uint32_t k);

/* How far past level k's band (world units) a cell of the band may reach, for a view that
 * uses `levels` levels: ip__lod_cell_radius() with more than one, 0 with one (its band holds
 * every distance). What the rays walk and the reads ahead plan is the band widened by it. */
static inline double ip__lod_band_widening(const ip_layout *l, uint32_t k, uint32_t levels)
{
    return levels > 1 ? ip__lod_cell_radius(l, k) : 0.0;
}

/* 1 when every point of the world box [lo, hi] lies nearer than `near` to `eye`, or every
 * point farther than `far` (world units): then no cell centre in the box lies in [near, far).
 * Callers pass the band widened by whatever margin their box or their rounding needs. */
int ip__lod_box_outside(const double lo[3], const double hi[3], const double eye[3], double near,
                        double far);

/* Distance (world units) from `eye` to `centre`, a cell's ip__sampler_cell_centre(); v is
 * set to centre - eye. Propagation (which needs v too) and the rays both go through it. */
static inline double ip__lod_centre_distance(const double centre[3], const double eye[3],
                                             double v[3])
{
    ip__vec3_sub(centre, eye, v);
    return ip__vec3_length(v);
}

/* Distance (world units) from `eye` to the centre of `cell` of the sampler's level. */
static inline double ip__lod_cell_distance(const ip_sampler *s, const uint32_t cell[3],
                                           const double eye[3])
{
    double centre[3], v[3];
    ip__sampler_cell_centre(s, cell, centre);
    return ip__lod_centre_distance(centre, eye, v);
}

/* 1 when a cell whose centre lies `distance` from the eye is in the band [near, far). */
static inline int ip__lod_in_band(double distance, double near, double far)
{
    return !(distance < near || distance >= far);
}

/* 1 when `cell` of the sampler's level is in the band [near, far) from `eye`: the rule itself,
 * as the rays, the beams and the full extraction apply it (propagation, which needs the
 * centre's offset too, goes through ip__lod_centre_distance() and ip__lod_in_band()). */
static inline int ip__lod_cell_in_band(const ip_sampler *s, const uint32_t cell[3],
                                       const double eye[3], double near, double far)
{
    return ip__lod_in_band(ip__lod_cell_distance(s, cell, eye), near, far);
}

#endif

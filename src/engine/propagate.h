/* SPDX-License-Identifier: BSD-3-Clause */
/* Surface propagation from a seed cell, and the triangle output shared with full extraction.
 * Internal. */
#ifndef ISOPROP_PROPAGATE_H
#define ISOPROP_PROPAGATE_H

#include "isoprop/camera.h"
#include "isoprop/engine.h"
#include "isoprop/mesh.h"
#include "clip.h"
#include "coverage.h"
#include "depth_queue.h"
#include "sampler.h"
#include "visited.h"

#define IP_SHARE_CELLS 16 /* cells a propagation hands out at once */

/* Where a propagation may hand part of its queue to idle workers (share.c): while `hungry`
 * (workers waiting for cells) is above 0, give() may be offered `count` queued cells, already
 * marked visited, of the propagation for the ray `dir`, at the propagator's level; it returns
 * 1 when it took them (another worker propagates from them), 0 when it had no room. All zero:
 * nothing is handed out. */
typedef struct ip_share {
    atomic_int *hungry;
    int (*give)(void *user, uint32_t level, const ip_queued_cell *cells, unsigned count,
                const double dir[3]);
    void *user;
} ip_share;

/* Where a cell's triangles go (ip__extract_cell()): to `mesh`; with `coverage` (NULL: none),
 * recorded there first, and with `cull` as well, only those that may show in its image
 * (ip__coverage_add()) are appended. */
typedef struct ip_cell_output {
    ip_mesh *mesh;
    ip_coverage *coverage;
    int cull;
    int whole_cells; /* with cull: a cell keeps all its triangles when one of them may show, so
                        that every cell in the mesh is whole (the engine's reuse) */
} ip_cell_output;

typedef struct ip_propagator {
    ip_sampler *sampler;
    ip_visited *visited;
    ip_cell_output out;
    const ip_camera *camera;
    ip_camera_basis basis;
    float iso;
    double cutoff_versine;              /* 1 - cos(cut-off angle) */
    double cos_foldback, sin_foldback;  /* of the fold-back tolerance */
    double pixel_scale;                 /* pixels per unit of (size / depth) */
    ip_image_axes axes;                 /* image positions, as the coverage works them out */
    double near_distance, far_distance; /* the level's distance band from the eye */
    ip_clip clip;                       /* the options' planes: dropped cells are not entered */
    double window[4];     /* x0, y0, x1, y1 (pixels): propagation stays where cells may project
                         into this part of the image (init: the whole image) */
    ip_depth_queue queue; /* nearest first */
    ip_share share;       /* zero after init: set by the engine */
} ip_propagator;

/* Propagation within one level, into the cells the options' clipping planes keep: cells whose
 * centre lies outside the distance band [near_distance, far_distance) from the eye belong to
 * another level and stop it (the paper's resolution boundary). With `coverage` (NULL: off), the
 * triangles it extracts are recorded there (and with options->cull, only those that may show
 * are kept), and a neighbour that recorded surface already hides is deferred: neither queued
 * nor marked visited, so that a ray seeding it later still extracts it (coverage.c). */
ip_status ip__propagator_init(ip_propagator *p, ip_sampler *sampler, ip_visited *visited,
                              ip_mesh *mesh, const ip_camera *camera, float iso,
                              const ip_engine_options *options, double near_distance,
                              double far_distance, ip_coverage *coverage);
void ip__propagator_free(ip_propagator *p);

/* Propagates from `seed` (already marked visited) along the surface, for the ray `dir` (unit,
 * world) from the camera's eye. Adds to counts' cells, triangles, deferred cells and times.
 * @return IP_OK, IP_ERR_NOMEM or the sampler's error. */
ip_status ip__propagate(ip_propagator *p, const uint32_t seed[3], const double dir[3],
                        ip_engine_counts *counts);

/* Propagates from `count` queued cells (already marked visited) of a propagation for the ray
 * `dir`, as if they were its queue: the cells another propagation handed out (ip_share). */
ip_status ip__propagate_queued(ip_propagator *p, const ip_queued_cell *cells, unsigned count,
                               const double dir[3], ip_engine_counts *counts);

/* Triangulates `cell` and hands its triangles to `out`. Sets *mc_case, and adds to *culled the
 * triangles culled (none without out->cull). Returns the number of triangles appended, or -1 on
 * a read failure / out of memory (status in *st). */
int ip__extract_cell(ip_sampler *s, const ip_cell_output *out, const uint32_t cell[3], float iso,
                     unsigned *mc_case, uint64_t *culled, ip_status *st);

#endif

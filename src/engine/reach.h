/* SPDX-License-Identifier: BSD-3-Clause */
/* Screen tiles that the bricks holding the isovalue may show in: the rays of the others can meet
 * no active cell, so the engine settles them from the start (engine.c). Internal. */
#ifndef ISOPROP_REACH_H
#define ISOPROP_REACH_H

#include <stdint.h>

#include "isoprop/camera.h"
#include "isoprop/store.h"

/* Marks in reached[ty * tiles_x + tx] (tiles of 2^shift pixels a side, tiles_x * tiles_y of
 * them) each tile holding a pixel centre within a pixel of the bounding rectangle of the image
 * of the world box [lo, hi]: every tile when a corner of the box is not in front of the eye.
 * A ray through a pixel centre meets the box only where that centre lies in its image. */
void ip__reach_box(const ip_camera_basis *basis, const ip_camera *camera, const double lo[3],
                   const double hi[3], unsigned shift, uint32_t tiles_x, uint32_t tiles_y,
                   unsigned char *reached);

/* Clears `reached` and marks (ip__reach_box()) the tiles that the bricks whose range holds
 * `iso`, at levels 0 .. levels - 1 of the store, may show in, each brick as the seeder sees it:
 * cells of 2^k samples' spacing from sample 0. */
void ip__reach_tiles(const ip_store *store, float iso, uint32_t levels,
                     const ip_camera_basis *basis, const ip_camera *camera, unsigned shift,
                     uint32_t tiles_x, uint32_t tiles_y, unsigned char *reached);

#endif

/* SPDX-License-Identifier: BSD-3-Clause */
/* isowall's compositing of the display tiles (MPI). */
#ifndef ISOWALL_COMPOSITE_H
#define ISOWALL_COMPOSITE_H

#include <mpi.h>

#include "isowall.h"

/* What the owner of a tile does with its final colours (tile_w * tile_h * 4 bytes, RGBA, top
 * row first; valid during the call). Returns 0, or -1 with err set. */
typedef int wall_tile_done(uint32_t tile, const uint8_t *rgba, void *user, ip_error *err);

/* One composite of the wall; the counters add up over calls. */
typedef struct wall_composite {
    const wall_layout *layout;
    const ip_shading *shading;
    int rank, ranks;
    int (*owner_of)(uint32_t tile, int ranks); /* the rank that receives tile t */
    double busy_seconds;                       /* CPU: finding tiles, drawing, compositing */
    double idle_seconds;                       /* wall: waiting in MPI */
    uint64_t bytes_sent;
    uint64_t tiles_drawn; /* on the owners: tiles some rank's triangles reached */
} wall_composite;

/* CPU seconds of the process (every thread). */
double wall_cpu_seconds(void);

/* Composites `mesh` (this rank's triangles) with every other rank's, tile by tile in order;
 * every rank calls it. The owner of each tile gets done() with its colours. Returns 0, or -1
 * with err set (a rank that fails should abort the job: the others may be waiting on it). */
int wall_composite_run(wall_composite *c, const ip_mesh *mesh, wall_tile_done *done, void *user,
                       ip_error *err);

#endif

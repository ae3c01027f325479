/* SPDX-License-Identifier: BSD-3-Clause */
/* isowall: sort-first parallel extraction and rendering for a display wall, on MPI.
 *
 * The wall's image (C x R display tiles of W x H pixels, one camera) is cut into screen
 * regions, each inside one tile. Work units are a region's first rays (its coarse levels) in a
 * first pass over the whole wall, then the rest of its rays in a second pass: every rank casts
 * the rays of the units it takes with its own engine (ip_engine_set_region()), keeping what it
 * extracted for earlier units. Each rank takes units from its own share of each pass's list,
 * one word per rank in rank 0's MPI window (MPI_Fetch_and_op, passive target), and steals half
 * of the fullest share once its own is spent (main.c); or with --static by display tile (tile t
 * to rank t % N, one copy per projector). Each rank then draws its own triangles into the tiles
 * they touch, and the tile's owner keeps the nearest surface of each pixel (direct-send
 * compositing). A watchdog (watch.h) ends the wall, naming it, when a process stops answering.
 * MPI stays in this program; the library knows nothing of it.
 */
#ifndef ISOWALL_H
#define ISOWALL_H

#include <stdint.h>

#include "isoprop/camera.h"
#include "isoprop/mesh.h"
#include "isoprop/render.h"
#include "tool_common.h"

/* The command line. */
typedef struct wall_options {
    tool_view_options common;
    const char *file, *out, *tiles_dir, *coarse;
    uint32_t cols, rows;      /* --wall CxR: display tiles */
    uint32_t tile_w, tile_h;  /* --tile WxH: pixels of a tile */
    uint32_t unit_w, unit_h;  /* --unit WxH: pixels of a region (0: from the tile) */
    int is_static;            /* --static: one display tile's units per rank */
    tool_orbit_options orbit; /* --azimuth, --elevation, --zoom */
    ip_shading shading;       /* --color, --background */
    double timeout;           /* --timeout SECONDS: the watchdog (watch.h); 0: none */
} wall_options;

/* --timeout's default: seconds of silence from a process that end the wall. */
#define WALL_DEFAULT_TIMEOUT 60.0

/* A screen region: a rectangle inside one display tile. */
typedef struct wall_region {
    uint32_t x, y, width, height; /* pixels of the wall's image */
    uint32_t tile;                /* row * cols + column */
    uint32_t gx, gy;              /* its cell in the wall's grid of regions */
} wall_region;

/* The wall: its camera, tiles and regions in the progressive order. */
typedef struct wall_layout {
    ip_camera camera; /* the whole wall: cols * tile_w x rows * tile_h pixels */
    double lo[3], hi[3];
    uint32_t cols, rows, tile_w, tile_h, tile_count;
    wall_region *regions; /* in the progressive order across the wall */
    uint32_t region_count;
} wall_layout;

/* Parses argv (before MPI starts). Returns 0, or 2 after a usage error (one line on stderr);
 * exits 0 after --help or --version. */
int wall_parse_args(int argc, char **argv, wall_options *o);

/* Cuts the wall into regions of unit_w x unit_h pixels, inside tiles, in the progressive order
 * (the coarse-to-fine ordered-dither order over the grid of regions). Returns 0, or -1 when out
 * of memory. */
int wall_layout_regions(wall_layout *w, uint32_t unit_w, uint32_t unit_h);

/* Writes the indices of the regions (as wall_layout_regions() made them) into
 * order[0 .. region_count) in a Z order over the wall's grid of regions, so that any run of the
 * order is a compact patch of neighbours. Returns 0, or -1 when out of memory. */
int wall_spatial_order(const wall_layout *w, uint32_t *order);

/* The rays of a region's first pass: one per 8 x 8 pixels, at least one. */
uint64_t wall_coarse_rays(const wall_region *r);

/* Marks in touched[0 .. tile_count) the tiles that the projected bounds of the mesh's triangles
 * reach (a triangle with a vertex behind the eye touches every tile). */
void wall_touched_tiles(const wall_layout *w, const ip_mesh *mesh, uint8_t *touched);

#endif

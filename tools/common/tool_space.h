/* SPDX-License-Identifier: BSD-3-Clause */
/* The file's physical space as the programs show it: views, cameras and clipping planes given
 * there, turned into the world units the engine and the renderers work in, and images shown
 * the physical way round (isoprop/camera.h, "Views in physical space"). */
#ifndef ISOPROP_TOOL_SPACE_H
#define ISOPROP_TOOL_SPACE_H

#include <stdint.h>

#include "isoprop/camera.h"
#include "isoprop/orientation.h"
#include "isoprop/status.h"
#include "isoprop/store.h"
#include "tool_options.h"

typedef struct tool_space {
    const char *path;           /* the brick file, for messages */
    ip_orientation orientation; /* the file's (isoprop/orientation.h) */
    double spacing[3];          /* world units between samples */
    double lo[3], hi[3];        /* the volume's world box */
    /* ip_orientation_mirrors(): a world camera sees the mirror image, and the programs show
     * every image with its columns reversed (tool_space_show()) */
    int mirror;
} tool_space;

/* The space of the open brick file `store`. */
void tool_space_of(const ip_store *store, tool_space *space);

/* The world camera of width x height pixels: `camera_text` ("E,T,U,FOV" in physical units,
 * --camera) or, when it is NULL, the named view `view` (--view; NULL: the file's default,
 * ip_view_default()) fitted to the volume (30 degrees). Returns 0, or -1 with err set (an
 * anatomical view in a file without a space: "FILE: view ...") and *world untouched. */
int tool_space_camera(const tool_space *space, const char *camera_text, const char *view,
                      uint32_t width, uint32_t height, ip_camera *world, ip_error *err);

/* The physical camera of a world camera (what the statistics report). */
void tool_space_physical(const tool_space *space, const ip_camera *world, ip_camera *physical);

/* Turns o's planes as given (clip_given: physical units, or sample indices for --clip-index)
 * into world units (o->clip) and physical units (o->clip_physical). */
void tool_space_clip(const tool_space *space, tool_view_options *o);

/* ip_camera_orbit() and ip_camera_pan() of the world camera as the image shown sees them: a
 * turn or a move to the right of the shown image is one to the left of the world camera's
 * own where the space mirrors. */
void tool_space_orbit(const tool_space *space, ip_camera *world, double right_degrees,
                      double down_degrees);
void tool_space_pan(const tool_space *space, ip_camera *world, double right, double up);

/* Makes a world camera's image (width * height RGBA pixels, top row first, rows `stride`
 * pixels apart: width for a whole image) the one shown: its columns reversed where the space
 * mirrors, else untouched. */
void tool_space_show(const tool_space *space, uint8_t *rgba, uint32_t width, uint32_t height,
                     uint32_t stride);

#endif

/* SPDX-License-Identifier: BSD-3-Clause */
/* Figure options: the orbit (--azimuth, --elevation, --zoom), colours. */
#ifndef ISOPROP_TOOL_FIGURE_H
#define ISOPROP_TOOL_FIGURE_H

#include <stddef.h>
#include <stdint.h>

#include "isoprop/camera.h"
#include "isoprop/status.h"
#include "tool_options.h"
#include "tool_space.h"

/* --azimuth, --elevation and --zoom, applied after --view or --camera (tool_apply_orbit()). */
typedef struct tool_orbit_options {
    double azimuth;   /* degrees about the view's up axis; positive: the eye moves right */
    double elevation; /* degrees about the right axis after that; positive: the eye moves up */
    double zoom;      /* > 0; the image is magnified this much about its centre (1: none) */
} tool_orbit_options;

#define TOOL_ORBIT_OPTIONS_HELP                                                                    \
    "  --azimuth DEG       turn the eye around the target about the view's up axis, after\n"       \
    "                      --view or --camera: positive moves the eye right (the volume turns\n"   \
    "                      left); -y then --azimuth 90 looks from +x (default 0)\n"                \
    "  --elevation DEG     then turn it about the view's right axis: positive moves the eye up,\n" \
    "                      to look down on the volume (default 0)\n"                               \
    "  --zoom F            narrow the field of view F times (> 0; 2 shows the central half of\n"   \
    "                      the frame, twice as large; the eye stays; default 1)\n"

/* The rows of --azimuth, --elevation and --zoom for a program's option table, filling the
 * tool_orbit_options `member` of `type` (a bad value is a usage error: not a number, a zoom
 * that is not > 0). */
/* clang-format off */
#define TOOL_ORBIT_OPTION_ROWS(type, member)                                                       \
    {"--azimuth", NULL, 1, offsetof(type, member.azimuth), tool_option_number,                    \
     "is not a number of degrees", NULL},                                                          \
    {"--elevation", NULL, 1, offsetof(type, member.elevation), tool_option_number,                \
     "is not a number of degrees", NULL},                                                          \
    {"--zoom", NULL, 1, offsetof(type, member.zoom), tool_option_positive,                        \
     "is not a factor > 0", NULL}
/* clang-format on */

/* No turn, no zoom. */
void tool_orbit_options_default(tool_orbit_options *o);

/* Turns the world camera `camera` (valid: ip_camera_check()) by the azimuth, then the
 * elevation, around its target as the image shown sees them (tool_space_orbit()), and narrows
 * its field of view by the zoom: tan(fov / 2) is divided by it. The camera stays valid. */
void tool_apply_orbit(const tool_orbit_options *o, const tool_space *space, ip_camera *camera);

/* Parses a colour: "R,G,B" (numbers in [0, 1]) or "#rrggbb" (hexadecimal). Returns 0, or -1
 * on bad text. */
int tool_parse_colour(const char *text, float rgb[3]);

/* Parses a background: one colour (solid), or "TOP:BOTTOM", two colours for a vertical
 * gradient from the top image row to the bottom one. Returns 0, or -1 on bad text. */
int tool_parse_background(const char *text, float top[3], float bottom[3]);

#endif

/* SPDX-License-Identifier: BSD-3-Clause */
/* Figure options: the orbit (--azimuth, --elevation, --zoom), colours. */
#include <ctype.h>
#include <math.h>
#include <string.h>

#include "tool_common.h"

void tool_orbit_options_default(tool_orbit_options *o)
{
    o->azimuth = 0.0;
    o->elevation = 0.0;
    o->zoom = 1.0;
}

void tool_apply_orbit(const tool_orbit_options *o, const tool_space *space, ip_camera *camera)
{
    /* ip_camera_orbit() turns the scene: a positive turn to the right moves the eye left */
    if (o->azimuth != 0.0 || o->elevation != 0.0)
        tool_space_orbit(space, camera, -o->azimuth, o->elevation);
    if (o->zoom != 1.0) {
        double half = camera->fov_y * M_PI / 360.0;
        camera->fov_y = atan(tan(half) / o->zoom) * 360.0 / M_PI;
    }
}

/* One hexadecimal digit's value, or -1. */
static int hex_digit(char c)
{
    if (c >= '0' && c <= '9')
        return c - '0';
    c = (char)tolower((unsigned char)c);
    return c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1;
}

int tool_parse_colour(const char *text, float rgb[3])
{
    if (text[0] == '#') {
        if (strlen(text) != 7)
            return -1;
        for (int i = 0; i < 3; i++) {
            int hi = hex_digit(text[1 + 2 * i]), lo = hex_digit(text[2 + 2 * i]);
            if (hi < 0 || lo < 0)
                return -1;
            rgb[i] = (float)(hi * 16 + lo) / 255.0f;
        }
        return 0;
    }
    double v[3];
    if (tool_parse_double3(text, v) != 0)
        return -1;
    for (int i = 0; i < 3; i++) {
        if (!(v[i] >= 0.0 && v[i] <= 1.0))
            return -1;
        rgb[i] = (float)v[i];
    }
    return 0;
}

int tool_parse_background(const char *text, float top[3], float bottom[3])
{
    const char *colon = strchr(text, ':');
    if (!colon)
        return tool_parse_colour(text, top) != 0 || tool_parse_colour(text, bottom) != 0 ? -1 : 0;
    char first[64];
    size_t len = (size_t)(colon - text);
    if (len >= sizeof first)
        return -1;
    memcpy(first, text, len);
    first[len] = 0;
    return tool_parse_colour(first, top) != 0 || tool_parse_colour(colon + 1, bottom) != 0 ? -1 : 0;
}

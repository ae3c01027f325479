/* SPDX-License-Identifier: BSD-3-Clause */
/* The file's physical space as the programs show it: cameras, views, clipping planes, images. */
#include <stdio.h>
#include <string.h>

#include "tool_common.h"

void tool_space_of(const ip_store *store, tool_space *s)
{
    const ip_layout *l = ip_store_layout(store);
    memset(s, 0, sizeof *s);
    s->path = ip_store_path(store);
    s->orientation = l->orientation;
    memcpy(s->spacing, l->spacing, sizeof s->spacing);
    ip_layout_world_box(l, s->lo, s->hi);
    s->mirror = ip_orientation_mirrors(&s->orientation);
}

int tool_space_camera(const tool_space *s, const char *camera_text, const char *view,
                      uint32_t width, uint32_t height, ip_camera *world, ip_error *err)
{
    ip_camera c = {.width = width, .height = height};
    ip_status st;
    if (camera_text) {
        st = ip_camera_parse(camera_text, &c, err);
        if (st == IP_OK)
            st = ip_camera_check(&c, err);
        if (st == IP_OK)
            ip_camera_to_world(&s->orientation, &c, &c);
    } else {
        st = ip_camera_fit_view(&s->orientation, s->lo, s->hi, view, 30.0, width, height, &c, err);
    }
    if (st != IP_OK && !camera_text && view && ip_view_check(view, NULL) == IP_OK) {
        /* a view name this file cannot have (an anatomical one without a space): say which */
        char text[sizeof err->message];
        snprintf(text, sizeof text, "%s: %.700s", s->path, err->message);
        memcpy(err->message, text, sizeof text);
    }
    if (st != IP_OK)
        return -1;
    *world = c;
    return 0;
}

void tool_space_physical(const tool_space *s, const ip_camera *world, ip_camera *physical)
{
    ip_camera_to_physical(&s->orientation, world, physical);
}

void tool_space_clip(const tool_space *s, tool_view_options *o)
{
    for (unsigned i = 0; i < o->clip_count; i++) {
        const ip_clip_plane *given = &o->clip_given[i];
        ip_clip_plane *world = &o->clip[i], *physical = &o->clip_physical[i];
        if (!o->clip_index[i]) {
            *physical = *given;
            ip_orientation_plane_to_world(&s->orientation, given->normal, given->offset,
                                          world->normal, &world->offset);
            continue;
        }
        /* n . (w / spacing) + d: the normal divided by the spacing, the offset as it is */
        for (int a = 0; a < 3; a++)
            world->normal[a] = given->normal[a] / s->spacing[a];
        world->offset = given->offset;
        /* and in physical space: n . (D^T (p - origin)) + d = (D n) . p + d - (D n) . origin */
        ip_orientation_rotate(&s->orientation, world->normal, physical->normal);
        physical->offset = world->offset;
        for (int a = 0; a < 3; a++)
            physical->offset -= physical->normal[a] * s->orientation.origin[a];
    }
}

void tool_space_orbit(const tool_space *s, ip_camera *world, double right_degrees,
                      double down_degrees)
{
    /* a reflection reverses the turn about the up axis; the turn about the right axis, whose
     * direction it reverses too, stays */
    ip_camera_orbit(world, s->mirror ? -right_degrees : right_degrees, down_degrees);
}

void tool_space_pan(const tool_space *s, ip_camera *world, double right, double up)
{
    ip_camera_pan(world, s->mirror ? -right : right, up);
}

void tool_space_show(const tool_space *s, uint8_t *rgba, uint32_t width, uint32_t height,
                     uint32_t stride)
{
    if (!s->mirror || width < 2)
        return;
    for (uint32_t y = 0; y < height; y++) {
        uint8_t *row = rgba + (size_t)y * stride * 4;
        for (uint32_t a = 0, b = width - 1; a < b; a++, b--) {
            uint8_t t[4];
            memcpy(t, row + 4 * (size_t)a, 4);
            memcpy(row + 4 * (size_t)a, row + 4 * (size_t)b, 4);
            memcpy(row + 4 * (size_t)b, t, 4);
        }
    }
}

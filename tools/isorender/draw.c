/* SPDX-License-Identifier: BSD-3-Clause */
/* isorender's drawing: the renderer, the image of the surfaces and the figure overlays. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "isorender.h"

int figure_renderer(const run *r, uint32_t w, uint32_t h, ip_renderer **gl, ip_error *why,
                    ip_error *err)
{
    *gl = NULL;
    if (ip_renderer_create_headless(w, h, gl, why) != IP_OK) {
        *gl = NULL;
        return 1;
    }
    ip_status st = ip_renderer_set_shading(*gl, &r->o.shading, err);
    if (st == IP_OK && r->o.aa > 1)
        st = ip_renderer_set_samples(*gl, r->o.aa, err);
    if (st == IP_OK)
        return 0;
    ip_renderer_destroy(*gl);
    *gl = NULL;
    return -1;
}

/* Draws `mesh` into rgba with `gl`, or in software when gl is NULL: the image, the strip's
 * frames and the turntable's all go through here. */
static ip_status draw_mesh(const run *r, ip_renderer *gl, const ip_mesh *mesh, uint8_t *rgba,
                           ip_error *err)
{
    if (!gl)
        return ip_raster_mesh_shaded(mesh, &r->camera, &r->o.shading, r->lo, r->hi, NULL, rgba,
                                     err);
    /* streamed: the driver never holds a second copy of the whole mesh */
    ip_status st = ip_renderer_draw_mesh(gl, mesh, &r->camera, r->lo, r->hi, err);
    return st == IP_OK ? ip_renderer_read_rgba(gl, rgba, err) : st;
}

/* Draws every surface (their first prefix[i] triangles when prefix is not NULL) into rgba
 * with `gl`, or in software when gl is NULL. */
static ip_status draw_surfaces(const run *r, ip_renderer *gl, const uint64_t *prefix, uint8_t *rgba,
                               ip_error *err)
{
    ip_mesh views[TOOL_MAX_ISOS];
    ip_surface surfaces[TOOL_MAX_ISOS];
    size_t count = 1 + r->other_count;
    for (size_t i = 0; i < count; i++)
        surface_of(r, i, prefix, views, &surfaces[i]);
    if (!gl)
        return ip_raster_surfaces(surfaces, count, &r->camera, &r->o.shading, r->lo, r->hi, rgba,
                                  err);
    ip_status st = ip_renderer_draw_surfaces(gl, surfaces, count, &r->camera, r->lo, r->hi, err);
    return st == IP_OK ? ip_renderer_read_rgba(gl, rgba, err) : st;
}

ip_status draw_image(const run *r, ip_renderer *gl, const uint64_t *prefix, uint8_t *rgba,
                     ip_error *err)
{
    ip_status st;
    if (several_surfaces(r)) {
        st = draw_surfaces(r, gl, prefix, rgba, err);
    } else {
        ip_mesh view = *r->mesh; /* a view of the first triangles, not a copy */
        if (prefix)
            view.triangle_count = prefix[0];
        st = draw_mesh(r, gl, &view, rgba, err);
    }
    /* the world camera's image, as the physical view shows it */
    if (st == IP_OK)
        tool_space_show(&r->space, rgba, r->camera.width, r->camera.height, r->camera.width);
    return st;
}

/* ---- the figure overlays: --axes and --scale-bar ---- */

const char *scale_unit(const run *r)
{
    if (r->o.scale_unit)
        return r->o.scale_unit;
    return ip_store_layout(r->store)->orientation.space != IP_SPACE_UNKNOWN ? "mm" : "units";
}

/* Draws the overlays asked for into the rendered image; with --verbose, says what they show
 * and where. */
static ip_status draw_overlays(run *r, uint8_t *rgba, ip_error *err)
{
    const ip_orientation *space = &ip_store_layout(r->store)->orientation;
    uint32_t box[4], bar_box[4];
    if (r->o.axes) {
        if (ip_overlay_draw_axes(rgba, &r->camera, space, box, err) != IP_OK)
            return err->code;
        if (r->o.common.verbose) {
            double screen[3][3];
            ip_overlay_axis_directions(&r->camera, space, screen);
            fprintf(stderr, "isorender: axes: box %u,%u to %u,%u;", box[0], box[1], box[2], box[3]);
            for (int a = 0; a < 3; a++) {
                for (int k = 0; k < 3; k++) /* no "-0.0000" */
                    screen[a][k] = fabs(screen[a][k]) < 5e-5 ? 0.0 : screen[a][k];
                fprintf(stderr, " %s %+.4f,%+.4f,%+.4f", ip_overlay_axis_label(space->space, a),
                        screen[a][0], screen[a][1], screen[a][2]);
            }
            fprintf(stderr, " (right, down, toward the eye)\n");
        }
    }
    if (r->o.scale_bar) {
        if (ip_scale_bar_choose(&r->camera, r->camera.width / 4.0, &r->bar, err) != IP_OK ||
            ip_overlay_draw_scale_bar(rgba, &r->camera, &r->bar, scale_unit(r), box, bar_box,
                                      err) != IP_OK) {
            static const char prefix[] = "scale bar: "; /* the library's; the option's instead */
            char text[sizeof err->message];
            if (!strncmp(err->message, prefix, strlen(prefix))) {
                snprintf(text, sizeof text, "%s: --scale-bar: %s", r->o.file,
                         err->message + strlen(prefix));
                memcpy(err->message, text, sizeof text);
            }
            return err->code;
        }
        if (r->o.common.verbose)
            fprintf(stderr,
                    "isorender: scale bar: %g %s = %.3f pixels (%.6g %s a pixel at the "
                    "target's depth); bar %u,%u to %u,%u; box %u,%u to %u,%u\n",
                    r->bar.length, scale_unit(r), r->bar.pixels, r->bar.pixel_size, scale_unit(r),
                    bar_box[0], bar_box[1], bar_box[2], bar_box[3], box[0], box[1], box[2], box[3]);
    }
    return IP_OK;
}

int render_image(run *r, uint8_t *rgba, ip_renderer **keep, ip_error *err)
{
    double start = ip_now_seconds();
    ip_renderer *gl = keep ? *keep : NULL;
    if (!gl && !r->o.software) {
        ip_error why;
        int made = figure_renderer(r, r->camera.width, r->camera.height, &gl, &why, err);
        if (made < 0)
            return -1; /* a setting OpenGL refuses: not a reason to draw something else */
        if (made > 0)
            fprintf(stderr, "isorender: no headless OpenGL (%s); rendering in software\n",
                    why.message);
        /* auto: OpenGL that is itself software draws slower than the exact rasterizer */
        if (gl && r->o.renderer == TOOL_RENDERER_AUTO && r->o.aa <= 1 &&
            ip_gl_driver_is_software(ip_renderer_driver(gl))) {
            ip_renderer_destroy(gl);
            gl = NULL;
            r->o.software = 1; /* the turntable's next frames and the strip: the same */
        }
    }
    r->renderer_name = gl ? "opengl" : "software";
    ip_status st = draw_image(r, gl, NULL, rgba, err);
    if (keep)
        *keep = gl;
    else
        ip_renderer_destroy(gl);
    if (st == IP_OK)
        st = draw_overlays(r, rgba, err);
    r->totals.rendering_seconds += ip_now_seconds() - start;
    return st == IP_OK ? 0 : -1;
}

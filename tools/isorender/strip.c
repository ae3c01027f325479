/* SPDX-License-Identifier: BSD-3-Clause */
/* isorender --strip: the image as extracted by a few points of the run, side by side. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "isorender.h"

int parse_strip_at(const char *program, const tool_option *option, const char *const *values,
                   void *base)
{
    strip_plan *plan = (strip_plan *)((char *)base + option->offset);
    const char *text = values[0];
    plan->count = 0;
    for (const char *at = text;; at++) {
        size_t len = strcspn(at, ",");
        char item[64];
        double pct;
        if (len >= sizeof item)
            len = sizeof item - 1;
        memcpy(item, at, len);
        item[len] = 0;
        if (len > 1 && item[len - 1] == '%')
            item[len - 1] = 0;
        if (tool_parse_double(item, &pct) != 0 || !(pct > 0 && pct <= 100))
            return tool_usage_error(program,
                                    "--strip-at '%s': '%.*s' is not a percentage in "
                                    "(0, 100]",
                                    text, (int)len, at);
        if (plan->count == STRIP_MAX_FRAMES)
            return tool_usage_error(program, "--strip-at '%s': more than %d frames", text,
                                    STRIP_MAX_FRAMES);
        if (plan->count && pct <= plan->pct[plan->count - 1])
            return tool_usage_error(program, "--strip-at '%s': the percentages must increase",
                                    text);
        plan->pct[plan->count++] = pct;
        at += strcspn(at, ",");
        if (!*at)
            return 0;
    }
}

int check_strip_options(options *o)
{
    if (!o->strip) {
        if (o->strip_at.count)
            return tool_usage_error("isorender", "--strip-at needs --strip");
        return 0;
    }
    if (o->full || o->common.rays || o->common.time_limit > 0)
        return tool_usage_error("isorender", "--strip shows a progressive run to its last ray: "
                                             "no --full, --rays or --time");
    if (!o->strip_at.count)
        o->strip_at = (strip_plan){{0.01, 0.1, 1, 100}, 4};
    uint64_t width = (uint64_t)o->common.width * o->strip_at.count +
                     (uint64_t)STRIP_GAP * (o->strip_at.count - 1);
    if (width > STRIP_MAX_WIDTH)
        return tool_usage_error("isorender",
                                "--strip: %zu frames %u pixels wide make a strip "
                                "of %llu pixels, over %d",
                                o->strip_at.count, o->common.width, (unsigned long long)width,
                                STRIP_MAX_WIDTH);
    return 0;
}

void strip_plan_rays(run *r)
{
    uint64_t total = (uint64_t)r->camera.width * r->camera.height;
    for (size_t f = 0; f < r->o.strip_at.count; f++) {
        uint64_t rays = (uint64_t)ceil(r->o.strip_at.pct[f] / 100.0 * (double)total);
        r->strip.rays[f] = rays < 1 ? 1 : rays > total ? total : rays;
    }
    r->strip.recorded = 0;
}

uint64_t strip_stop(const run *r, uint64_t rays, uint64_t next)
{
    if (!r->o.strip)
        return next;
    for (size_t f = r->strip.recorded; f < r->o.strip_at.count; f++)
        if (r->strip.rays[f] > rays)
            return r->strip.rays[f] < next ? r->strip.rays[f] : next;
    return next;
}

void strip_record(run *r)
{
    if (!r->o.strip)
        return;
    ip_engine_counts t;
    ip_engine_totals(r->engine, &t);
    uint64_t triangles = ip_engine_mesh(r->engine)->triangle_count;
    while (r->strip.recorded < r->o.strip_at.count &&
           (r->strip.rays[r->strip.recorded] <= t.rays || ip_engine_done(r->engine)))
        r->strip.triangles[r->strip.recorded++] = triangles;
}

/* The triangles frame f of the strip shows, of every surface. */
static uint64_t strip_triangles(const run *r, size_t f)
{
    uint64_t sum = 0;
    for (size_t i = 0; i <= r->other_count; i++)
        sum += surface_run_c(r, i)->strip.triangles[f];
    return sum;
}

/* Frame f's label, "12 rays, 3456 triangles", or its short form when that is too wide for
 * the frame ("12 rays"; "" when even that is). */
static void strip_label(const run *r, size_t f, char *text, size_t size)
{
    snprintf(text, size, "%llu rays, %llu triangles", (unsigned long long)r->strip.rays[f],
             (unsigned long long)strip_triangles(r, f));
    if (ip_overlay_text_width(text, STRIP_TEXT_SCALE) + 8 > r->camera.width)
        snprintf(text, size, "%llu rays", (unsigned long long)r->strip.rays[f]);
    if (ip_overlay_text_width(text, STRIP_TEXT_SCALE) + 8 > r->camera.width)
        text[0] = 0;
}

/* Draws `text` into the strip's band, centred under the frame that starts at column x0 (the
 * render stage's text, as the figure overlays draw theirs). */
static ip_status strip_draw_label(uint8_t *rgba, uint32_t strip_width, uint32_t strip_height,
                                  uint32_t x0, uint32_t frame_width, const char *text,
                                  ip_error *err)
{
    static const uint8_t ink[3] = {226, 222, 206};
    int left =
        (int)x0 + ((int)frame_width - (int)ip_overlay_text_width(text, STRIP_TEXT_SCALE)) / 2;
    int top = (int)strip_height - STRIP_BAND + 4;
    return ip_overlay_draw_text(rgba, strip_width, strip_height, left, top, text, STRIP_TEXT_SCALE,
                                ink, NULL, err);
}

/* Fills err for a failed allocation of the strip. Returns -1. */
static int strip_out_of_memory(const run *r, ip_error *err)
{
    err->code = IP_ERR_NOMEM;
    snprintf(err->message, sizeof err->message, "%s: out of memory for the progress strip",
             r->o.strip);
    return -1;
}

/* Renders frame after frame (the mesh's first `triangles` of each) with the renderer of the
 * image, and copies each into its place in the strip. */
static int strip_render_frames(run *r, uint8_t *strip, uint32_t strip_width, ip_error *err)
{
    uint32_t w = r->camera.width, h = r->camera.height;
    uint8_t *frame = malloc((size_t)w * h * 4);
    ip_renderer *gl = NULL;
    if (!frame)
        return strip_out_of_memory(r, err);
    int rc = 0;
    if (!strcmp(r->renderer_name, "opengl") && figure_renderer(r, w, h, &gl, err, err) != 0)
        rc = -1;
    for (size_t f = 0; rc == 0 && f < r->o.strip_at.count; f++) {
        uint64_t prefix[TOOL_MAX_ISOS];
        for (size_t i = 0; i <= r->other_count; i++)
            prefix[i] = surface_run_c(r, i)->strip.triangles[f];
        if (draw_image(r, gl, prefix, frame, err) != IP_OK) {
            rc = -1;
            break;
        }
        size_t x0 = f * (w + STRIP_GAP);
        for (uint32_t y = 0; y < h; y++)
            memcpy(strip + ((size_t)y * strip_width + x0) * 4, frame + (size_t)y * w * 4,
                   (size_t)w * 4);
    }
    ip_renderer_destroy(gl);
    free(frame);
    return rc;
}

int strip_compose(run *r, uint8_t **out, uint32_t *width, uint32_t *height, ip_error *err)
{
    static const uint8_t band[4] = {14, 16, 22, 255};
    size_t n = r->o.strip_at.count;
    *width = (uint32_t)(n * r->camera.width + (n - 1) * STRIP_GAP);
    *height = r->camera.height + STRIP_BAND;
    uint8_t *rgba = malloc((size_t)*width * *height * 4);
    if (!rgba)
        return strip_out_of_memory(r, err);
    for (size_t p = 0; p < (size_t)*width * *height; p++)
        memcpy(rgba + p * 4, band, 4);
    if (strip_render_frames(r, rgba, *width, err) != 0) {
        free(rgba);
        return -1;
    }
    for (size_t f = 0; f < n; f++) {
        char text[64];
        strip_label(r, f, text, sizeof text);
        if (strip_draw_label(rgba, *width, *height, (uint32_t)(f * (r->camera.width + STRIP_GAP)),
                             r->camera.width, text, err) != IP_OK) {
            free(rgba);
            return -1;
        }
    }
    *out = rgba;
    return 0;
}

void strip_print(FILE *out, const run *r)
{
    fprintf(out, "  strip         %s:", r->o.strip);
    for (size_t f = 0; f < r->o.strip_at.count; f++)
        fprintf(out, " %g%% (%llu triangles)", r->o.strip_at.pct[f],
                (unsigned long long)strip_triangles(r, f));
    fprintf(out, "\n");
}

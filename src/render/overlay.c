/* SPDX-License-Identifier: BSD-3-Clause */
/* Figure overlays drawn into a finished RGBA image: the axis triad and the scale bar
 * (isoprop/render.h). They are drawn after rendering, on the CPU, so that the OpenGL and the
 * software renderers, with or without anti-aliasing, get the same overlay. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "isoprop/render.h"

#include <stb_easy_font.h>

/* The image being drawn into. */
typedef struct canvas {
    uint8_t *rgba;
    int width, height;
} canvas;

typedef struct colour {
    uint8_t r, g, b;
} colour;

static const colour axis_colours[3] = {{235, 80, 70}, {100, 205, 90}, {95, 150, 250}};
static const colour light = {240, 238, 230};
static const colour dark = {10, 10, 14};

/* The overlays' sizes for an image: the text scale (an integer, 1 to 4), the margin from the
 * image's edges and the triad's arm, both in pixels. */
typedef struct overlay_sizes {
    int text_scale, margin;
    double arm;
} overlay_sizes;

static overlay_sizes sizes_of(uint32_t width, uint32_t height)
{
    int side = (int)(width < height ? width : height);
    overlay_sizes s;
    int scale = (side + 120) / 240; /* the nearest whole multiple of 240 pixels */
    s.text_scale = scale < 1 ? 1 : scale > 4 ? 4 : scale;
    s.margin = 4 * s.text_scale;
    s.arm = 0.08 * side < 16 ? 16 : 0.08 * side;
    return s;
}

/* Blends `c` over pixel (x, y) with coverage a in [0, 1]; outside the image, nothing. */
static void blend(const canvas *cv, int x, int y, colour c, double a)
{
    if (x < 0 || y < 0 || x >= cv->width || y >= cv->height || a <= 0)
        return;
    if (a > 1)
        a = 1;
    uint8_t *p = cv->rgba + ((size_t)y * (size_t)cv->width + (size_t)x) * 4;
    const uint8_t rgb[3] = {c.r, c.g, c.b};
    for (int k = 0; k < 3; k++)
        p[k] = (uint8_t)lround(p[k] + a * ((double)rgb[k] - p[k]));
    p[3] = 255;
}

/* A filled rectangle of pixels [x0, x1) x [y0, y1): opaque, so each pixel becomes `c` (what
 * blend() gives at full coverage) without blending. */
static void fill_rect(const canvas *cv, int x0, int y0, int x1, int y1, colour c)
{
    x0 = x0 < 0 ? 0 : x0, y0 = y0 < 0 ? 0 : y0; /* the rest is outside the image */
    x1 = x1 > cv->width ? cv->width : x1, y1 = y1 > cv->height ? cv->height : y1;
    const uint8_t px[4] = {c.r, c.g, c.b, 255};
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++)
            memcpy(cv->rgba + ((size_t)y * (size_t)cv->width + (size_t)x) * 4, px, 4);
}

/* An anti-aliased segment from (ax, ay) to (bx, by) (pixel coordinates, pixel centres at
 * +0.5), `width` pixels wide with round ends: each pixel is covered by how far its centre
 * lies inside the stroke, over a one-pixel ramp. */
static void draw_segment(const canvas *cv, double ax, double ay, double bx, double by, double width,
                         colour c)
{
    double r = width / 2, dx = bx - ax, dy = by - ay, len2 = dx * dx + dy * dy;
    int x0 = (int)floor(fmin(ax, bx) - r - 1), x1 = (int)ceil(fmax(ax, bx) + r + 1);
    int y0 = (int)floor(fmin(ay, by) - r - 1), y1 = (int)ceil(fmax(ay, by) + r + 1);
    for (int y = y0; y <= y1; y++)
        for (int x = x0; x <= x1; x++) {
            double px = x + 0.5 - ax, py = y + 0.5 - ay;
            double t = len2 > 0 ? (px * dx + py * dy) / len2 : 0;
            t = t < 0 ? 0 : t > 1 ? 1 : t;
            double ex = px - t * dx, ey = py - t * dy;
            blend(cv, x, y, c, r + 0.5 - sqrt(ex * ex + ey * ey));
        }
}

/* The height of stb_easy_font's capitals and digits, pixels at scale 1 (its line height,
 * stb_easy_font_height(), adds the spacing between lines). */
#define GLYPH_HEIGHT 7

/* Room for one glyph's quads: stb_easy_font gives a printable ASCII character at most 11
 * (measured over ' ' to '~'), each 64 bytes (4 vertices of 3 floats and 4 bytes of colour). */
#define GLYPH_BUFFER_BYTES (16 * 64)

/* `c`, or '?' where stb_easy_font has no glyph (outside ' ' to '~': it would index its
 * tables out of bounds; a '\n' would start a line). */
static char printable(char c)
{
    return c < ' ' || c > '~' ? '?' : c;
}

/* The advance of one line of `text` in font units (stb_easy_font_width() of each character:
 * its widths add up, no spacing being set). */
static int text_units(const char *text)
{
    int units = 0;
    for (; *text; text++) {
        char one[2] = {printable(*text), 0};
        units += stb_easy_font_width(one);
    }
    return units;
}

/* The width and height of one line of `text` in pixels at `scale`. */
static void text_size(const char *text, int scale, int *w, int *h)
{
    *w = text_units(text) * scale;
    *h = GLYPH_HEIGHT * scale;
}

/* Fills the glyphs of `text` (each character's quads, axis-aligned rectangles, scaled up),
 * with the top-left corner at (left, top), in colour c. One character at a time: no buffer
 * for the whole text. */
static void fill_glyphs(const canvas *cv, int left, int top, const char *text, int scale, colour c)
{
    int pen = 0; /* font units */
    for (; *text; text++) {
        char one[2] = {printable(*text), 0}, quads[GLYPH_BUFFER_BYTES];
        int count = stb_easy_font_print(0, 0, one, NULL, quads, (int)sizeof quads);
        for (int q = 0; q < count; q++) {
            float lo[2] = {1e9f, 1e9f}, hi[2] = {-1e9f, -1e9f};
            for (int k = 0; k < 4; k++) { /* a vertex: x, y, z floats, then 4 bytes of colour */
                float v[2];
                memcpy(v, quads + (q * 4 + k) * 16, sizeof v);
                for (int a = 0; a < 2; a++) {
                    lo[a] = v[a] < lo[a] ? v[a] : lo[a];
                    hi[a] = v[a] > hi[a] ? v[a] : hi[a];
                }
            }
            fill_rect(cv, left + (pen + (int)lo[0]) * scale, top + (int)lo[1] * scale,
                      left + (pen + (int)hi[0]) * scale, top + (int)hi[1] * scale, c);
        }
        pen += stb_easy_font_width(one);
    }
}

/* Draws one line of `text` with its top-left corner at (left, top), `scale` times
 * stb_easy_font's size; with a shadow (may be NULL), first the whole text in it one text
 * pixel down and right. */
static void draw_text(const canvas *cv, int left, int top, const char *text, int scale, colour c,
                      const colour *shadow)
{
    if (shadow)
        fill_glyphs(cv, left + scale, top + scale, text, scale, *shadow);
    fill_glyphs(cv, left, top, text, scale, c);
}

/* The text functions' limits: a scale, and how far outside the image a corner may lie (so
 * that no pixel coordinate overflows). */
#define TEXT_MAX_SCALE 16
#define TEXT_MAX_OFFSET (1 << 24)

uint32_t ip_overlay_text_width(const char *text, int scale)
{
    if (!text || scale < 1 || scale > TEXT_MAX_SCALE)
        return 0;
    return (uint32_t)text_units(text) * (uint32_t)scale;
}

ip_status ip_overlay_draw_text(uint8_t *rgba, uint32_t width, uint32_t height, int left, int top,
                               const char *text, int scale, const uint8_t ink[3],
                               const uint8_t shadow[3], ip_error *err)
{
    if (!rgba || !text || !ink || width < 1 || height < 1 || width > INT32_MAX / 4 ||
        height > INT32_MAX / 4)
        return ip__fail(err, IP_ERR_ARGUMENT, "text: no image, text or ink, or a %ux%u image",
                        width, height);
    if (scale < 1 || scale > TEXT_MAX_SCALE)
        return ip__fail(err, IP_ERR_ARGUMENT, "text: scale %d is not 1 to %d", scale,
                        TEXT_MAX_SCALE);
    if (left < -TEXT_MAX_OFFSET || left > TEXT_MAX_OFFSET || top < -TEXT_MAX_OFFSET ||
        top > TEXT_MAX_OFFSET)
        return ip__fail(err, IP_ERR_ARGUMENT, "text: corner %d,%d is too far out", left, top);
    canvas cv = {rgba, (int)width, (int)height};
    const colour c = {ink[0], ink[1], ink[2]};
    colour under = {0, 0, 0};
    if (shadow)
        under = (colour){shadow[0], shadow[1], shadow[2]};
    draw_text(&cv, left, top, text, scale, c, shadow ? &under : NULL);
    return IP_OK;
}

/* The mean luma (0 to 255) of the image's pixels in [x0, x1) x [y0, y1), clipped; 0 when
 * none is inside. */
static double mean_luma(const canvas *cv, int x0, int y0, int x1, int y1)
{
    double sum = 0;
    uint64_t count = 0;
    for (int y = y0 < 0 ? 0 : y0; y < y1 && y < cv->height; y++)
        for (int x = x0 < 0 ? 0 : x0; x < x1 && x < cv->width; x++) {
            const uint8_t *p = cv->rgba + ((size_t)y * (size_t)cv->width + (size_t)x) * 4;
            sum += 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2];
            count++;
        }
    return count ? sum / (double)count : 0;
}

/* Clips {x0, y0, x1, y1} to the image and stores it in box (may be NULL). */
static void report_box(const ip_camera *camera, int x0, int y0, int x1, int y1, uint32_t box[4])
{
    if (!box)
        return;
    int w = (int)camera->width, h = (int)camera->height;
    int b[4] = {x0 < 0 ? 0 : x0, y0 < 0 ? 0 : y0, x1 > w ? w : x1, y1 > h ? h : y1};
    for (int k = 0; k < 4; k++)
        box[k] = (uint32_t)(b[k] < 0 ? 0 : b[k]);
}

/* Where the triad goes in a width x height image: its centre (cx, cy), the labels' distance
 * from it (reach) and their gap beyond the arms' tips, and the box {x0, y0, x1, y1} that holds
 * arms and labels, which may reach out of a small image. */
typedef struct axes_geometry {
    overlay_sizes s;
    double gap, reach, cx, cy;
    int radius, box[4];
} axes_geometry;

static void axes_geometry_of(uint32_t width, uint32_t height, axes_geometry *g)
{
    g->s = sizes_of(width, height);
    /* each label is centred beyond its arm's tip, `gap` out: the box holds arm and label */
    g->gap = GLYPH_HEIGHT * g->s.text_scale * 0.5 + 2 + g->s.text_scale;
    g->reach = g->s.arm + g->gap;
    g->radius = (int)ceil(g->reach + g->gap);
    g->cx = g->s.margin + g->radius;
    g->cy = (double)height - g->s.margin - g->radius;
    g->box[0] = (int)floor(g->cx - g->radius);
    g->box[1] = (int)floor(g->cy - g->radius);
    g->box[2] = (int)ceil(g->cx + g->radius) + 1;
    g->box[3] = (int)ceil(g->cy + g->radius) + 1;
}

ip_status ip_overlay_axes_check(uint32_t width, uint32_t height, ip_error *err)
{
    axes_geometry g;
    if (width < 1 || height < 1 || width > INT32_MAX / 2 || height > INT32_MAX / 2)
        return ip__fail(err, IP_ERR_ARGUMENT, "axes: an image of %ux%u pixels", width, height);
    axes_geometry_of(width, height, &g);
    if (g.box[0] < 0 || g.box[1] < 0 || g.box[2] > (int)width || g.box[3] > (int)height)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "axes: the triad needs an image of at least %dx%d pixels, not %ux%u",
                        g.box[2], g.s.margin + 2 * g.radius, width, height);
    return IP_OK;
}

static ip_status check_image(const uint8_t *rgba, const ip_camera *camera, ip_error *err)
{
    if (!rgba || !camera)
        return ip__fail(err, IP_ERR_ARGUMENT, "overlay: no image or no camera");
    return ip_camera_check(camera, err);
}

ip_status ip_scale_bar_choose(const ip_camera *camera, double max_pixels, ip_scale_bar *bar,
                              ip_error *err)
{
    ip_status st = ip_camera_check(camera, err);
    if (st != IP_OK)
        return st;
    if (!bar)
        return ip__fail(err, IP_ERR_ARGUMENT, "scale bar: nowhere to put it");
    if (!(max_pixels > 0 && isfinite(max_pixels)))
        return ip__fail(err, IP_ERR_ARGUMENT, "scale bar: %g pixels is not a length", max_pixels);
    double pixel_size = ip_camera_pixel_size(camera, camera->height);
    double longest = max_pixels * pixel_size;
    if (!(pixel_size > 0 && isfinite(longest)))
        return ip__fail(err, IP_ERR_ARGUMENT, "scale bar: the camera gives no pixel size");
    /* the decade at or under `longest`, then the largest of 1, 2, 5 times it that fits */
    double decade = pow(10.0, floor(log10(longest)));
    double length = decade;
    if (5 * decade <= longest * (1 + 1e-12))
        length = 5 * decade;
    else if (2 * decade <= longest * (1 + 1e-12))
        length = 2 * decade;
    bar->length = length;
    bar->pixel_size = pixel_size;
    bar->pixels = length / pixel_size;
    return IP_OK;
}

void ip_overlay_axis_directions(const ip_camera *camera, const ip_orientation *orientation,
                                double screen[3][3])
{
    ip_camera_basis basis;
    ip_camera_basis_of(camera, &basis);
    /* where D mirrors, the image shown is the world camera's mirrored (camera.h) */
    double across = ip_orientation_mirrors(orientation) ? -1.0 : 1.0;
    for (int a = 0; a < 3; a++) {
        double w[3]; /* physical axis a in world coordinates: row a of D (D is orthonormal) */
        for (int k = 0; k < 3; k++)
            w[k] = orientation->directions[k][a];
        double right = 0, up = 0, forward = 0;
        for (int k = 0; k < 3; k++) {
            right += w[k] * basis.right[k];
            up += w[k] * basis.up[k];
            forward += w[k] * basis.forward[k];
        }
        screen[a][0] = across * right;
        screen[a][1] = -up;
        screen[a][2] = -forward;
    }
}

const char *ip_overlay_axis_label(ip_space space, int axis)
{
    static const char *const labels[4][3] = {
        {"x", "y", "z"}, {"R", "A", "S"}, {"L", "A", "S"}, {"L", "P", "S"}};
    if (axis < 0 || axis > 2)
        return "";
    int s = space == IP_SPACE_RAS ? 1 : space == IP_SPACE_LAS ? 2 : space == IP_SPACE_LPS ? 3 : 0;
    return labels[s][axis];
}

ip_status ip_overlay_draw_axes(uint8_t *rgba, const ip_camera *camera,
                               const ip_orientation *orientation, uint32_t box[4], ip_error *err)
{
    ip_status st = check_image(rgba, camera, err);
    if (st == IP_OK)
        st = ip_overlay_axes_check(camera->width, camera->height, err);
    if (st != IP_OK)
        return st;
    if (!orientation)
        return ip__fail(err, IP_ERR_ARGUMENT, "axes: no orientation");
    canvas cv = {rgba, (int)camera->width, (int)camera->height};
    axes_geometry g;
    axes_geometry_of(camera->width, camera->height, &g);
    double screen[3][3];
    ip_overlay_axis_directions(camera, orientation, screen);
    /* farthest arm first, so that a nearer one passes over it */
    int order[3] = {0, 1, 2};
    for (int i = 0; i < 3; i++)
        for (int j = i + 1; j < 3; j++)
            if (screen[order[j]][2] < screen[order[i]][2]) {
                int t = order[i];
                order[i] = order[j];
                order[j] = t;
            }
    int scale = g.s.text_scale;
    double stroke = 1.0 + 0.5 * scale, arm = g.s.arm;
    for (int i = 0; i < 3; i++) {
        int a = order[i];
        double tx = g.cx + arm * screen[a][0], ty = g.cy + arm * screen[a][1];
        draw_segment(&cv, g.cx, g.cy, tx, ty, stroke + 1.5, dark);
        draw_segment(&cv, g.cx, g.cy, tx, ty, stroke, axis_colours[a]);
        /* the label beyond the tip, along the arm's direction in the image */
        double len = hypot(screen[a][0], screen[a][1]);
        double ux = len > 1e-6 ? screen[a][0] / len : 0, uy = len > 1e-6 ? screen[a][1] / len : 0;
        const char *label = ip_overlay_axis_label(orientation->space, a);
        int w, h;
        text_size(label, scale, &w, &h);
        double lx = tx + (g.reach - arm) * ux, ly = ty + (g.reach - arm) * uy;
        draw_text(&cv, (int)lround(lx - w / 2.0), (int)lround(ly - h / 2.0), label, scale,
                  axis_colours[a], &dark);
    }
    report_box(camera, g.box[0], g.box[1], g.box[2], g.box[3], box);
    return IP_OK;
}

ip_status ip_overlay_draw_scale_bar(uint8_t *rgba, const ip_camera *camera, const ip_scale_bar *bar,
                                    const char *unit, uint32_t box[4], uint32_t bar_box[4],
                                    ip_error *err)
{
    ip_status st = check_image(rgba, camera, err);
    if (st != IP_OK)
        return st;
    if (!bar || !(bar->length > 0 && isfinite(bar->length) && bar->pixels > 0 &&
                  isfinite(bar->pixels) && bar->pixels < 1e9))
        return ip__fail(err, IP_ERR_ARGUMENT, "scale bar: not a length");
    canvas cv = {rgba, (int)camera->width, (int)camera->height};
    overlay_sizes s = sizes_of(camera->width, camera->height);
    long n = lround(bar->pixels);
    if (n < 1)
        n = 1;
    int thick = (int)lround(1.5 * s.text_scale) < 2 ? 2 : (int)lround(1.5 * s.text_scale);
    int x1 = cv.width - s.margin, x0 = (int)(x1 - n), y1 = cv.height - s.margin, y0 = y1 - thick;
    int tick = thick * 2, tick_w = thick < (int)n ? thick : (int)n;
    size_t size = (unit ? strlen(unit) : 0) + 32; /* "%g " and the unit */
    char *label = malloc(size);
    if (!label)
        return ip__fail(err, IP_ERR_NOMEM, "scale bar: out of memory");
    if (unit && unit[0])
        snprintf(label, size, "%g %s", bar->length, unit);
    else
        snprintf(label, size, "%g", bar->length);
    for (char *p = label; *p; p++) /* a control character would break the message's line */
        *p = (unsigned char)*p < ' ' || *p == 127 ? '?' : *p;
    int w, h;
    text_size(label, s.text_scale, &w, &h);
    int lx = (x0 + x1) / 2 - w / 2, ly = y1 - tick - s.margin - h;
    if (lx + w + s.text_scale > x1)
        lx = x1 - w - s.text_scale; /* a label wider than the bar ends at its right end */
    int left = x0 < lx ? x0 : lx;
    if (left < 0 || ly < 0) { /* the bar or its label would be cut: draw nothing */
        st = ip__fail(err, IP_ERR_ARGUMENT,
                      "scale bar: \"%.60s\" and its bar need %ldx%d pixels in the corner, more "
                      "than the %ux%u image has",
                      label, (long)cv.width - left, cv.height - ly, camera->width, camera->height);
        free(label);
        return st;
    }
    /* light on a dark corner, dark on a light one (a white figure background) */
    int bright = mean_luma(&cv, left, ly, x1 + s.text_scale, y1 + 1) > 140;
    colour ink = bright ? dark : light, shadow = bright ? light : dark;
    /* the bar and its end ticks (inside its length), over a shadow one pixel below them */
    fill_rect(&cv, x0, y1, x1, y1 + 1, shadow);
    fill_rect(&cv, x0, y0, x1, y1, ink);
    fill_rect(&cv, x0, y1 - tick, x0 + tick_w, y0, ink);
    fill_rect(&cv, x1 - tick_w, y1 - tick, x1, y0, ink);
    draw_text(&cv, lx, ly, label, s.text_scale, ink, &shadow);
    free(label);
    report_box(camera, left, ly, x1 + s.text_scale, y1 + 1, box);
    report_box(camera, x0, y1 - tick, x1, y1, bar_box);
    return IP_OK;
}

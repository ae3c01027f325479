/* SPDX-License-Identifier: BSD-3-Clause */
/* isoview's overlay: the heads-up text and the help, stb_easy_font's quads drawn as indexed
 * triangles in pixel coordinates over the rendered frame. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The font is a header of static functions (some unused here) in its own style: its warnings
 * are not ours (CMake also adds its folder as a system include folder). */
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-braces"
#include <stb_easy_font.h>
#pragma GCC diagnostic pop

#include "isoview.h"
#include "layout.h"

static const char *const overlay_vertex_source =
    "#version 330 core\n"
    "layout(location = 0) in vec2 position; /* pixels, top-left origin */\n"
    "uniform vec2 viewport;\n"
    "uniform float scale;\n"
    "uniform vec2 offset;\n"
    "void main() {\n"
    "    vec2 p = (offset + position * scale) / viewport * 2.0 - 1.0;\n"
    "    gl_Position = vec4(p.x, -p.y, 0.0, 1.0);\n"
    "}\n";

static const char *const overlay_fragment_source = "#version 330 core\n"
                                                   "uniform vec4 colour;\n"
                                                   "out vec4 result;\n"
                                                   "void main() {\n"
                                                   "    result = colour;\n"
                                                   "}\n";

enum {
    FONT_VERTEX_BYTES = 16,
    QUAD_BYTES = 4 * FONT_VERTEX_BYTES
};

int overlay_create(overlay *t, ip_error *err)
{
    memset(t, 0, sizeof t[0]);
    t->quads_size = 4096 * QUAD_BYTES;
    t->quads = malloc((size_t)t->quads_size);
    if (!t->quads) {
        set_error(err, IP_ERR_NOMEM, "out of memory");
        return -1;
    }
    if (ip_gl_program(overlay_vertex_source, overlay_fragment_source, &t->program, err) != IP_OK)
        return -1;
    t->viewport_at = glGetUniformLocation(t->program, "viewport");
    t->scale_at = glGetUniformLocation(t->program, "scale");
    t->offset_at = glGetUniformLocation(t->program, "offset");
    t->colour_at = glGetUniformLocation(t->program, "colour");
    glGenVertexArrays(1, &t->array);
    glGenBuffers(1, &t->vertices);
    glGenBuffers(1, &t->indices);
    glBindVertexArray(t->array);
    glBindBuffer(GL_ARRAY_BUFFER, t->vertices);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, FONT_VERTEX_BYTES, NULL);
    glEnableVertexAttribArray(0);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, t->indices); /* kept by the vertex array */
    uint32_t quads = (uint32_t)(t->quads_size / QUAD_BYTES) + 1;
    uint32_t *index = malloc((size_t)quads * 6 * sizeof *index);
    if (!index) {
        glBindVertexArray(0);
        set_error(err, IP_ERR_NOMEM, "out of memory");
        return -1;
    }
    for (uint32_t q = 0; q < quads; q++) {
        const uint32_t corner[6] = {0, 1, 2, 0, 2, 3};
        for (int k = 0; k < 6; k++)
            index[6 * q + k] = 4 * q + corner[k];
    }
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)((size_t)quads * 6 * sizeof *index), index,
                 GL_STATIC_DRAW);
    free(index);
    t->index_quads = quads;
    glBindVertexArray(0);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    if (glGetError() != GL_NO_ERROR) {
        set_error(err, IP_ERR_UNSUPPORTED, "overlay: an OpenGL error while setting up");
        return -1;
    }
    return 0;
}

void overlay_destroy(overlay *t)
{
    if (t->program) {
        glDeleteProgram(t->program);
        glDeleteVertexArrays(1, &t->array);
        glDeleteBuffers(1, &t->vertices);
        glDeleteBuffers(1, &t->indices);
    }
    free(t->quads);
    memset(t, 0, sizeof t[0]);
}

/* Fills quad q of the buffer with the rectangle [x0, x1] x [y0, y1]. */
static void put_rectangle(char *quads, int q, float x0, float y0, float x1, float y1)
{
    const float corners[4][2] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
    for (int k = 0; k < 4; k++)
        memcpy(quads + q * QUAD_BYTES + k * FONT_VERTEX_BYTES, corners[k], 2 * sizeof(float));
}

/* Fills the quad buffer with the panel (quad 0) and the text of cells[0 .. n), offset by
 * `pad`; returns the number of quads. */
static int fill_quads(overlay *t, const text_cell *cells, size_t n, float w, float h, float pad)
{
    int quads = 1;
    put_rectangle(t->quads, 0, 0, 0, w + 2 * pad, h + 2 * pad);
    for (size_t i = 0; i < n; i++) {
        char copy[LAYOUT_MAX_CELL + 1];
        size_t length = cells[i].length < LAYOUT_MAX_CELL ? cells[i].length : LAYOUT_MAX_CELL;
        memcpy(copy, cells[i].text, length);
        copy[length] = 0;
        layout_printable(copy);
        int room = t->quads_size - quads * QUAD_BYTES;
        if (room < QUAD_BYTES)
            break;
        quads += stb_easy_font_print(cells[i].x + pad, cells[i].y + pad, copy, NULL,
                                     t->quads + quads * QUAD_BYTES, room);
    }
    return (uint32_t)quads > t->index_quads ? (int)t->index_quads : quads;
}

/* Draws `text` (a table: '\n' between rows, '\t' between columns) on a translucent panel whose
 * corner `corner` (0: top-left, 1: bottom-left, 2: centred) is `margin` framebuffer pixels from
 * the window's, scaled `scale` times. */
static void overlay_draw(overlay *t, const char *text, int corner, float margin, float scale,
                         uint32_t width, uint32_t height)
{
    const float pad = 4;
    text_cell cells[128];
    float w, h;
    size_t n = layout_table(text, 2 * pad, cells, sizeof cells / sizeof cells[0], &w, &h);
    int quads = fill_quads(t, cells, n < 128 ? n : 128, w, h, pad);
    float panel_w = (w + 2 * pad) * scale, panel_h = (h + 2 * pad) * scale;
    float x = margin, y = corner == 1 ? (float)height - margin - panel_h : margin;
    if (corner == 2) {
        x = ((float)width - panel_w) / 2;
        y = ((float)height - panel_h) / 2;
    }
    x = x > 0 ? x : 0;
    y = y > 0 ? y : 0;
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, (GLsizei)width, (GLsizei)height);
    glDisable(GL_DEPTH_TEST);
    glEnable(GL_BLEND);
    /* colour blends; alpha stays opaque, so that screenshots stay RGB */
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
    glUseProgram(t->program);
    glUniform2f(t->viewport_at, (float)width, (float)height);
    glUniform1f(t->scale_at, scale);
    glUniform2f(t->offset_at, x, y);
    glBindVertexArray(t->array);
    glBindBuffer(GL_ARRAY_BUFFER, t->vertices);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)quads * QUAD_BYTES, t->quads, GL_STREAM_DRAW);
    glUniform4f(t->colour_at, 0.0f, 0.0f, 0.0f, 0.6f);
    glDrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_INT, NULL);
    glUniform4f(t->colour_at, 1.0f, 1.0f, 0.85f, 1.0f);
    glDrawElements(GL_TRIANGLES, 6 * (quads - 1), GL_UNSIGNED_INT,
                   (const void *)(6 * sizeof(uint32_t)));
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    glBindVertexArray(0);
    glUseProgram(0);
    glDisable(GL_BLEND);
}

/* Overdraw of the finished image: the mesh's triangles over those that own at least one pixel
 * (from the software rasterizer's triangle ids at the window's size); measured once per
 * finished pass, as "final px" is known only then. */
static void measure_overdraw(viewer *v, const ip_mesh *mesh)
{
    size_t n = (size_t)v->camera.width * v->camera.height;
    /* the software renderer's canvas holds the ids already when it has drawn the whole mesh */
    int from_canvas = v->canvas && v->canvas_mesh == mesh &&
                      ip_canvas_triangle_count(v->canvas) == mesh->triangle_count;
    uint32_t *index = from_canvas ? NULL : malloc(n * sizeof *index);
    const uint32_t *ids = from_canvas ? ip_canvas_triangle_index(v->canvas) : index;
    uint8_t *owns = calloc(mesh->triangle_count / 8 + 1, 1);
    v->overdraw_state = -1;
    if (ids && owns &&
        (from_canvas ||
         ip_raster_mesh(mesh, &v->camera, v->lo, v->hi, index, NULL, NULL) == IP_OK)) {
        uint64_t visible = 0;
        for (size_t p = 0; p < n; p++) {
            uint32_t i = ids[p];
            if (i != UINT32_MAX && !(owns[i / 8] & (1u << (i % 8)))) {
                owns[i / 8] |= (uint8_t)(1u << (i % 8));
                visible++;
            }
        }
        v->overdraw = visible ? (double)mesh->triangle_count / (double)visible : 0.0;
        v->overdraw_state = 1;
    }
    free(index);
    free(owns);
}

static const char *overdraw_text(viewer *v, char *text, size_t size)
{
    int finished = v->full_shown || ip_engine_done(v->engine);
    if (finished && v->overdraw_state == 0)
        measure_overdraw(v, shown_mesh(v));
    if (!finished || v->overdraw_state != 1)
        return "-";
    snprintf(text, size, "%.2f", v->overdraw);
    return text;
}

/* The first line of the heads-up text: the isovalue (or the one being typed) and the state. */
static void iso_line(viewer *v, char *text, size_t size, int working_on_full, int detailed)
{
    char state[48] = "";
    if (working_on_full)
        snprintf(state, sizeof state, "  [extracting all...]");
    else if (v->full_shown)
        snprintf(state, sizeof state, "  [full]");
    else if (v->paused)
        snprintf(state, sizeof state, "  [paused]");
    else if (!ip_engine_done(v->engine) && pass_limit_reached(v))
        snprintf(state, sizeof state, "  [%s reached]",
                 pass_limit_reached(v) == 1 ? "--rays" : "--time");
    /* with --clip: whether the planes apply (the key c) */
    const char *clip = !v->o.common.clip_count ? "" : v->clip_on ? "  [clip on]" : "  [clip off]";
    char unit[IP_RESCALE_UNIT_MAX + 1]; /* " HU" with a rescale that names its unit */
    tool_unit_suffix(v->o.common.rescale, unit, sizeof unit);
    if (v->typing)
        snprintf(text, size, "iso> %s_  (Enter applies, Esc cancels)", v->typed);
    else if (detailed)
        snprintf(text, size, "iso %.7g%s  (values %.7g .. %.7g%s)%s%s", v->iso, unit, v->value_min,
                 v->value_max, unit, state, clip);
    else
        snprintf(text, size, "iso %.7g%s%s%s", v->iso, unit, state, clip);
}

/* The compact heads-up text: two lines, the isovalue and the state, then the pass's progress,
 * triangles, overdraw and frame rate. */
static int compact_text(viewer *v, char *text, size_t size, int working_on_full)
{
    ip_engine_counts t;
    ip_engine_totals(v->engine, &t);
    double pixels = (double)v->camera.width * v->camera.height;
    char iso[192], overdraw[32], rays[32];
    iso_line(v, iso, sizeof iso, working_on_full, 0);
    if (v->full_shown)
        snprintf(rays, sizeof rays, "full");
    else
        snprintf(rays, sizeof rays, "rays %.1f %%",
                 pixels > 0 ? 100.0 * (double)t.rays / pixels : 0.0);
    return snprintf(text, size, "%s   %.1f fps%s\n%s   %llu triangles   overdraw %s", iso,
                    v->clock.shown, v->help_on || v->typing ? "" : "   h: help", rays,
                    (unsigned long long)(v->full_shown ? v->full_counts.triangles : t.triangles),
                    overdraw_text(v, overdraw, sizeof overdraw));
}

/* The detailed heads-up text. "final px" is the share of pixels already showing their final
 * colour: it is known exactly once every ray has been cast (100 %), and shown as "-" before; so
 * is the overdraw (triangles extracted per triangle visible in the finished image). */
static int detailed_text(viewer *v, char *text, size_t size, int working_on_full)
{
    ip_engine_counts t;
    ip_cache_stats s;
    ip_engine_totals(v->engine, &t);
    ip_cache_get_stats(v->cache, &s);
    double pixels = (double)v->camera.width * v->camera.height;
    uint64_t lookups = s.hits + s.misses;
    char iso[192], progress[160], overdraw[32];
    iso_line(v, iso, sizeof iso, working_on_full, 1);
    if (v->full_shown)
        snprintf(progress, sizeof progress,
                 "full: %llu cells in %.2f s   final px 100 %%\n"
                 "triangles %llu   overdraw %s",
                 (unsigned long long)v->full_counts.cells, v->full_wall,
                 (unsigned long long)v->full_counts.triangles,
                 overdraw_text(v, overdraw, sizeof overdraw));
    else
        snprintf(progress, sizeof progress,
                 "rays %.1f %% of %.0f   final px %s\n"
                 "triangles %llu   overdraw %s",
                 pixels > 0 ? 100.0 * (double)t.rays / pixels : 0.0, pixels,
                 ip_engine_done(v->engine) ? "100 %" : "-", (unsigned long long)t.triangles,
                 overdraw_text(v, overdraw, sizeof overdraw));
    return snprintf(text, size,
                    "%s\n%s\nfps %.1f\ncache %.1f / %.1f MiB   hit rate %.1f %%\n"
                    "misses %llu   bricks %llu / %llu",
                    iso, progress, v->clock.shown, (double)s.resident_bytes / 1048576.0,
                    (double)s.budget_bytes / 1048576.0,
                    lookups ? 100.0 * (double)s.hits / (double)lookups : 0.0,
                    (unsigned long long)s.misses, (unsigned long long)s.bricks_touched,
                    (unsigned long long)s.bricks_total);
}

/* The heads-up text of the overlay's mode, then a message while one is shown, else the hint
 * for the help. */
static void hud_text(viewer *v, char *text, size_t size, int working_on_full)
{
    int n = v->overlay_mode == OVERLAY_DETAILED ? detailed_text(v, text, size, working_on_full)
                                                : compact_text(v, text, size, working_on_full);
    /* a frame saved as a screenshot shows no passing message (a "saved" line of the one before) */
    if (n > 0 && (size_t)n < size && v->message[0] && ip_now_seconds() < v->message_until &&
        !v->screenshot_pending)
        snprintf(text + n, size - (size_t)n, "\n%s", v->message);
    else if (n > 0 && (size_t)n < size && !v->help_on && v->overlay_mode == OVERLAY_DETAILED)
        snprintf(text + n, size - (size_t)n, "\nh: help");
}

void overlay_draw_frame(viewer *v, int working_on_full)
{
    uint32_t width = v->camera.width, height = v->camera.height;
    float scale = height >= 720 ? 2.0f : 1.0f;
    if (v->overlay_mode != OVERLAY_OFF || working_on_full) {
        char text[1024];
        hud_text(v, text, sizeof text, working_on_full);
        /* compact: the bottom-left corner, below the volume framed by --view */
        overlay_draw(&v->text, text, v->overlay_mode == OVERLAY_DETAILED ? 0 : 1, 4 * scale, scale,
                     width, height);
    }
    if (v->help_on)
        overlay_draw(&v->text, isoview_help_table, 2, 0, scale, width, height);
}

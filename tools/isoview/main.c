/* SPDX-License-Identifier: BSD-3-Clause */
/* isoview: the interactive viewer. The isosurface refines progressively in a window while it
 * stays responsive: each frame casts rays for a time slice (ip_engine_step() on the render
 * thread, whose workers use every core), uploads the triangles added since the last frame and
 * draws. The slice is FRAME_BUDGET_SECONDS, or DRAW_SHARE times as long as the previous frame
 * took to draw and show when that was longer (software OpenGL drawing a large mesh, or the
 * copy of a large window), up to MAX_SLICE_SECONDS, so that drawing never starves
 * refinement. Any change of view or isovalue restarts the progressive
 * order at once; as extraction is time-sliced, the work in flight is at most one slice.
 *
 * The other parts: options.c (the command line), script.c (--script), controls.c (mouse and
 * keyboard), overlay.c (the heads-up text). docs/isoview.md documents the controls, the
 * options and the script format.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "isoprop/output.h"
#include "isoview.h"

#define FRAME_BUDGET_SECONDS 0.012 /* ray casting per frame: keeps 30+ fps while refining */
#define MAX_SLICE_SECONDS 0.25     /* the longest slice: bounds the delay of input */
#define SOFTWARE_SLICE_SECONDS \
    0.04 /* the software renderer's slice while refining: 20 frames
                                       a second, each copying the whole window */
#define DRAW_SHARE \
    2.0                        /* the slice is at least this many times the last frame's
                                      drawing, so drawing never starves refinement */
#define FPS_WINDOW_SECONDS 0.5 /* the overlay's fps is averaged over this long */
#define MOTION_SECONDS 0.15    /* the view moves while the mouse moved it this recently */

static char glfw_error[512];

static void on_glfw_error(int code, const char *description)
{
    (void)code;
    if (!glfw_error[0])
        snprintf(glfw_error, sizeof glfw_error, "%s", description);
}

void set_error(ip_error *err, ip_status code, const char *fmt, ...)
{
    va_list ap;
    err->code = code;
    va_start(ap, fmt);
    vsnprintf(err->message, sizeof err->message, fmt, ap);
    va_end(ap);
}

int pass_limit_reached(const viewer *v)
{
    ip_engine_counts t;
    ip_engine_totals(v->engine, &t);
    if (v->o.common.rays && t.rays >= v->o.common.rays)
        return 1;
    return v->o.common.time_limit > 0 && v->pass_wall >= v->o.common.time_limit ? 2 : 0;
}

int refinement_complete(const viewer *v)
{
    if (v->paused && !v->want_full)
        return 1;
    if (v->engine == v->coarse && v->coarse && !v->full_shown)
        return 0; /* the fine pass follows once the view stops */
    return !v->restart && !v->want_full &&
           (v->full_shown || ip_engine_done(v->engine) || pass_limit_reached(v));
}

void request_screenshot(viewer *v, const char *path)
{
    free(v->screenshot_pending);
    v->screenshot_pending = copy_text(path);
    if (!v->screenshot_pending) {
        fprintf(stderr, "isoview: out of memory\n");
        v->failed = v->quit = 1;
    }
}

/* ---- frames ---- */

static void frame_done(frame_clock *k, double t)
{
    k->frames++;
    k->last = t;
    if (k->frames == 1) { /* rates count the frames that end after this one */
        k->first = k->window_start = k->second_start = t;
        return;
    }
    k->window_frames++;
    if (t - k->window_start >= FPS_WINDOW_SECONDS) {
        k->shown = (double)k->window_frames / (t - k->window_start);
        k->window_start = t;
        k->window_frames = 0;
    }
    k->second_frames++;
    if (t - k->second_start >= 1.0) {
        double fps = (double)k->second_frames / (t - k->second_start);
        if (k->seconds == 0 || fps < k->slowest)
            k->slowest = fps;
        if (k->seconds == 0 || fps > k->fastest)
            k->fastest = fps;
        k->seconds++;
        k->second_start = t;
        k->second_frames = 0;
    }
}

static double frames_per_second(const frame_clock *k)
{
    return k->frames > 1 && k->last > k->first ? (double)(k->frames - 1) / (k->last - k->first)
                                               : 0.0;
}

/* ---- the progressive engine and the mesh on the GPU ---- */

/* The engine with the command line's options and the clipping planes as they apply now
 * (clip_on), cancelled by a signal. An engine made before (its planes are fixed when it is
 * made) is replaced, and kept when the new one cannot be made. Returns 0, or -1 with the
 * error in *err. */
static int create_engine(viewer *v, ip_error *err)
{
    tool_view_options common;
    clip_options(v, &common);
    ip_engine_options eo;
    tool_engine_options(&common, &eo);
    eo.reuse = v->o.reuse;
    ip_engine *fine, *coarse = NULL;
    if (ip_engine_create(v->cache, &eo, &fine, err) != IP_OK)
        return -1;
    /* the coarse pass while the view moves: adaptive resolution at a larger pixel error */
    if (eo.lod && v->o.drag_pixel_error > eo.pixel_error) {
        eo.pixel_error = v->o.drag_pixel_error;
        eo.prefetch = IP_PREFETCH_OFF; /* its few bricks are read on demand */
        eo.reuse = 0;
        if (ip_engine_create(v->cache, &eo, &coarse, err) != IP_OK) {
            ip_engine_destroy(fine);
            return -1;
        }
    }
    tool_signals_cancel_engine(NULL); /* no handler uses the old ones from here */
    ip_engine_destroy(v->fine);
    ip_engine_destroy(v->coarse);
    v->engine = v->fine = fine;
    v->coarse = coarse;
    tool_signals_cancel_engine(v->engine);
    v->clip_changed = 0;
    v->restart = 1;
    return 0;
}

/* The engine for the next pass: the coarse one while the view moves (a script's drag, or the
 * mouse's drag or wheel within the last MOTION_SECONDS), the fine one otherwise; a change
 * starts the pass again. */
static void choose_engine(viewer *v)
{
    int moving = v->drag_end > 0 || ip_now_seconds() - v->last_motion < MOTION_SECONDS;
    ip_engine *want = moving && v->coarse ? v->coarse : v->fine;
    if (want == v->engine)
        return;
    tool_signals_cancel_engine(NULL);
    v->engine = want;
    tool_signals_cancel_engine(want);
    v->restart = 1;
}

static int begin_pass(viewer *v)
{
    v->restart = 0;
    v->full_shown = 0;
    v->overdraw_state = 0;
    v->passes++;
    v->pass_wall = v->pass_render = 0;
    if (v->renderer)
        ip_renderer_clear_mesh(v->renderer);
    v->canvas_mesh = NULL; /* the canvas starts over */
    v->uploaded = 0;
    if (record_begin(v) != 0)
        return -1;
    if (v->engine == v->fine) { /* the last two, for read_ahead() */
        v->pass_camera[0] = v->pass_camera[1];
        v->pass_camera[1] = v->camera;
        v->fine_passes++;
    }
    if (ip_engine_begin(v->engine, &v->camera, (float)v->iso_stored, &v->err) != IP_OK)
        return -1;
    return 0;
}

static int same_camera(const ip_camera *a, const ip_camera *b)
{
    for (int i = 0; i < 3; i++)
        if (a->eye[i] != b->eye[i] || a->target[i] != b->target[i] || a->up[i] != b->up[i])
            return 0;
    return a->fov_y == b->fov_y && a->width == b->width && a->height == b->height;
}

/* Once a fine pass is done: the next view, if the motion that led from the view before to this
 * one goes on (an orbit's or a zoom's step again), is read ahead into the cache. */
static void read_ahead(viewer *v)
{
    if (!v->o.read_ahead || v->fine_passes < 2 || v->engine != v->fine || v->paused ||
        v->full_shown)
        return;
    const ip_camera *a = &v->pass_camera[0], *b = &v->pass_camera[1];
    if (!same_camera(b, &v->camera) || same_camera(a, b) || a->width != b->width ||
        a->height != b->height)
        return;
    ip_camera next = *b;
    double da[3], db[3], la = 0, lb = 0, ln = 0;
    for (int i = 0; i < 3; i++) {
        da[i] = a->eye[i] - a->target[i];
        db[i] = b->eye[i] - b->target[i];
        la += da[i] * da[i];
        lb += db[i] * db[i];
    }
    la = sqrt(la), lb = sqrt(lb);
    double d[3];
    for (int i = 0; i < 3; i++) { /* the step again: the offset turned as much, scaled as much */
        next.target[i] = 2 * b->target[i] - a->target[i];
        next.up[i] = 2 * b->up[i] - a->up[i];
        d[i] = 2 * db[i] / lb - da[i] / la;
        ln += d[i] * d[i];
    }
    ln = sqrt(ln);
    for (int i = 0; i < 3; i++)
        next.eye[i] = next.target[i] + d[i] / ln * lb * (lb / la);
    if (ip_camera_check(&next, NULL) == IP_OK &&
        ip_engine_read_ahead(v->engine, &next, NULL) == IP_OK)
        v->read_aheads++;
}

/* One frame's slice of ray casting, then the new triangles to the GPU. */
static int refine(viewer *v)
{
    if (v->paused || v->full_shown || ip_engine_done(v->engine) || pass_limit_reached(v))
        return 0;
    /* drawing (and showing the frame) takes at most a third of a frame, half while the view
     * moves (each frame then draws a new view whole); the software renderer's frames after a
     * pass's first come at most every SOFTWARE_SLICE_SECONDS, as each copies the window */
    double drawing = (v->engine == v->coarse ? 1.0 : DRAW_SHARE) * v->draw_seconds;
    double least = v->canvas && v->frame_count > 0 && v->engine != v->coarse
                       ? SOFTWARE_SLICE_SECONDS
                       : FRAME_BUDGET_SECONDS;
    double slice = drawing < least               ? least
                   : drawing > MAX_SLICE_SECONDS ? MAX_SLICE_SECONDS
                                                 : drawing;
    if (v->o.common.time_limit > 0 && slice > v->o.common.time_limit - v->pass_wall)
        slice = v->o.common.time_limit - v->pass_wall;
    ip_engine_counts t;
    ip_engine_totals(v->engine, &t);
    uint64_t rays = v->o.common.rays ? v->o.common.rays - t.rays : 0;
    /* a pass's first frame: a ray a thread, whose propagations alone take longer than a slice
     * on a large volume (a step checks its time between batches of rays), then the picture;
     * not for a moving view's coarse pass, each frame of which is a pass's first */
    uint64_t first = ip_thread_count(v->o.common.threads);
    if (v->frame_count == 0 && v->engine != v->coarse && (!rays || rays > first))
        rays = first;
    double start = ip_now_seconds();
    ip_status st = ip_engine_step(v->engine, rays, slice, NULL, &v->err);
    v->pass_wall += ip_now_seconds() - start;
    if (st != IP_OK && st != IP_ERR_CANCELLED)
        return -1;
    const ip_mesh *mesh = ip_engine_mesh(v->engine);
    if (v->renderer && ip_renderer_upload(v->renderer, mesh, v->uploaded, &v->err) != IP_OK)
        return -1;
    v->uploaded = mesh->triangle_count;
    if (ip_engine_done(v->engine))
        read_ahead(v);
    return 0;
}

/* Extracts every active cell (blocking: the frame before shows that it is working): at full
 * resolution with --lod off, else at the view's adaptive resolution (each level's cells
 * within its distance band, isorender --full-lod), what the progressive pass equals once
 * every ray has been cast. */
static int extract_full(viewer *v)
{
    v->want_full = 0;
    v->restart = 0; /* the full mesh is the current view's, a change made while paused included */
    ip_mesh_clear(&v->full_mesh);
    memset(&v->full_counts, 0, sizeof v->full_counts);
    tool_view_options common; /* the clipping planes as they apply now */
    clip_options(v, &common);
    int mode = common.lod ? TOOL_FULL_LOD : TOOL_FULL;
    double start = ip_now_seconds();
    if (tool_full_extraction(v->cache, v->iso_stored, mode, &v->camera, &common, &v->full_mesh,
                             &v->full_counts, &v->err) != IP_OK)
        return -1;
    v->full_wall = ip_now_seconds() - start;
    v->pass_render = 0;
    v->canvas_mesh = NULL;
    if (v->renderer) {
        ip_renderer_clear_mesh(v->renderer);
        if (ip_renderer_upload(v->renderer, &v->full_mesh, 0, &v->err) != IP_OK)
            return -1;
    }
    v->full_shown = mode;
    v->overdraw_state = 0;
    return 0;
}

/* The software renderer: the canvas draws the triangles of the mesh shown that it does not
 * hold yet (all of them after a change of view, mesh or size) and shows the changed rows. */
const ip_mesh *shown_mesh(const viewer *v)
{
    return v->full_shown ? &v->full_mesh : ip_engine_mesh(v->engine);
}

/* Whether the kept image must be drawn again whole for `mesh`: another mesh, another view or
 * size, or fewer triangles than the `held` it was drawn with (a pass begun again). */
static int image_stale(const viewer *v, const ip_mesh *mesh, uint64_t held)
{
    return v->canvas_mesh != mesh || !same_camera(&v->canvas_camera, &v->camera) ||
           held > mesh->triangle_count;
}

static int draw_software(viewer *v)
{
    const ip_mesh *mesh = shown_mesh(v);
    if (image_stale(v, mesh, ip_canvas_triangle_count(v->canvas))) {
        v->canvas_mesh = NULL;
        if (ip_canvas_begin(v->canvas, &v->camera, NULL, v->lo, v->hi, &v->err) != IP_OK)
            return -1;
        v->canvas_mesh = mesh;
        v->canvas_camera = v->camera;
    }
    if (ip_canvas_add(v->canvas, mesh, ip_canvas_triangle_count(v->canvas), &v->err) != IP_OK)
        return -1;
    uint32_t rows[2];
    const uint8_t *rgba = ip_canvas_shade(v->canvas, rows);
    return display_show(&v->screen, rgba, v->camera.width, v->camera.height, rows, v->space.mirror,
                        &v->err);
}

/* OpenGL into the kept image: only the triangles uploaded since the last frame, unless the
 * view, the mesh shown or the size changed; then the image is copied to the window. */
static int draw_opengl(viewer *v)
{
    const ip_mesh *mesh = shown_mesh(v);
    uint64_t first = image_stale(v, mesh, v->gl_drawn) ? 0 : v->gl_drawn;
    v->canvas_mesh = NULL;
    if (display_size(&v->screen, v->camera.width, v->camera.height, &v->err) != 0 ||
        ip_renderer_draw_added(v->renderer, &v->camera, v->lo, v->hi, first, &v->err) != IP_OK)
        return -1;
    v->canvas_mesh = mesh;
    v->canvas_camera = v->camera;
    v->gl_drawn = ip_renderer_triangle_count(v->renderer);
    const uint32_t none[2] = {0, 0};
    return display_show(&v->screen, NULL, v->camera.width, v->camera.height, none, 0, &v->err);
}

static int draw_frame(viewer *v, int working_on_full)
{
    double start = ip_now_seconds();
    int rc =
        v->canvas ? draw_software(v)
        : v->keep_image
            ? draw_opengl(v)
            : (ip_renderer_draw(v->renderer, &v->camera, v->lo, v->hi, &v->err) == IP_OK ? 0 : -1);
    if (rc != 0)
        return -1;
    overlay_draw_frame(v, working_on_full);
    double seconds = ip_now_seconds() - start;
    v->pass_render += seconds;
    if (!v->full_shown)
        ip_engine_add_rendering_time(v->engine, seconds);
    return 0;
}

/* Reads the frame just drawn back and writes it; "" picks the next free isoview-NNN.png. */
static int save_screenshot(viewer *v)
{
    char name[64];
    const char *path = v->screenshot_pending;
    int automatic = !path[0];
    if (automatic) {
        do
            snprintf(name, sizeof name, "isoview-%03u.png", ++v->screenshot_number);
        while (access(name, F_OK) == 0 && v->screenshot_number < 100000);
        path = name;
    }
    size_t bytes = (size_t)v->camera.width * v->camera.height * 4;
    uint8_t *rgba = malloc(bytes);
    ip_error err;
    ip_error_clear(&err);
    int rc = -1;
    if (!rgba)
        set_error(&err, IP_ERR_NOMEM, "out of memory for a screenshot");
    else if ((v->canvas || v->keep_image
                  ? display_read(v->camera.width, v->camera.height, rgba, &err) == 0
                  : ip_renderer_read_rgba(v->renderer, rgba, &err) == IP_OK) &&
             ip_png_write(path, rgba, v->camera.width, v->camera.height,
                          automatic ? 0 : v->o.common.force, &err) == IP_OK)
        rc = 0;
    free(rgba);
    if (rc == 0) {
        show_message(v, "saved %s", path);
    } else if (automatic) {
        show_message(v, "screenshot: %s", err.message);
        fprintf(stderr, "isoview: %s\n", err.message);
        rc = 0; /* a key press that failed is reported, not fatal */
    } else {
        v->err = err;
    }
    free(v->screenshot_pending);
    v->screenshot_pending = NULL;
    return rc;
}

/* Follows the framebuffer's size (resizes, HiDPI); returns 0 when there is nothing to draw. */
static int follow_size(viewer *v)
{
    int width, height;
    glfwGetFramebufferSize(v->window, &width, &height);
    if (width <= 0 || height <= 0)
        return 0;
    if ((uint32_t)width != v->camera.width || (uint32_t)height != v->camera.height) {
        if (v->renderer &&
            ip_renderer_resize(v->renderer, (uint32_t)width, (uint32_t)height, &v->err) != IP_OK)
            return -1;
        v->camera.width = (uint32_t)width;
        v->camera.height = (uint32_t)height;
        change_view(v);
    }
    return 1;
}

/* A script's drag: the part of its turn due since the last frame. */
static void follow_drag(viewer *v, double t)
{
    if (v->drag_end <= 0)
        return;
    double until = t < v->drag_end ? t : v->drag_end;
    double dt = until - v->drag_last;
    if (dt > 0) {
        tool_space_orbit(&v->space, &v->camera, v->drag_rate[0] * dt, v->drag_rate[1] * dt);
        change_view(v);
        v->last_motion = ip_now_seconds();
    }
    v->drag_last = until;
    if (t >= v->drag_end)
        v->drag_end = 0;
}

/* One frame: input, script, timers, extraction slice, drawing, screenshot, swap.
 * Returns 0, or -1 after an error in v->err. */
static int frame(viewer *v)
{
    double frame_start = ip_now_seconds();
    glfwPollEvents();
    double t = ip_now_seconds() - v->start;
    if (glfwWindowShouldClose(v->window) || (v->o.exit_after >= 0 && t >= v->o.exit_after)) {
        v->quit = 1;
        return 0;
    }
    follow_drag(v, t);
    run_script(v, t);
    if (v->quit)
        return 0;
    if (v->o.screenshot_path && !v->screenshot_at_taken && t >= v->o.screenshot_at &&
        !v->screenshot_pending) {
        v->screenshot_at_taken = 1;
        request_screenshot(v, v->o.screenshot_path);
    }
    int visible = follow_size(v);
    if (visible < 0)
        return -1;
    if (!visible) {
        glfwWaitEventsTimeout(0.1);
        return 0;
    }
    if (v->clip_changed && create_engine(v, &v->err) != 0)
        return -1;
    if (!v->full_shown)
        choose_engine(v);
    /* paused, a change of view keeps the mesh shown until refinement resumes */
    if (v->restart && !v->paused && begin_pass(v) != 0)
        return -1;
    if (v->want_full) {
        /* show that it is working, then block */
        if (draw_frame(v, 1) != 0)
            return -1;
        glfwSwapBuffers(v->window);
        if (extract_full(v) != 0)
            return -1;
    }
    if (refine(v) != 0)
        return -1;
    double drawn = ip_now_seconds();
    if (draw_frame(v, 0) != 0)
        return -1;
    if (v->screenshot_pending && !tool_signal_caught() && save_screenshot(v) != 0)
        return -1;
    glfwSwapBuffers(v->window);
    double end = ip_now_seconds();
    v->draw_seconds = end - drawn;
    if (v->drag_end > 0 || end - v->last_motion < MOTION_SECONDS) {
        v->moving_frames++;
        v->moving_seconds += end - frame_start;
    }
    frame_done(&v->clock, end);
    record_frame(v, end);
    return 0;
}

/* ---- set-up, exit ---- */

static int open_window(viewer *v)
{
    glfwSetErrorCallback(on_glfw_error);
    if (!glfwInit()) {
        fprintf(stderr, "isoview: cannot open a window: %s\n",
                glfw_error[0] ? glfw_error : "GLFW cannot start");
        return -1;
    }
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_DEPTH_BITS, 24);
    /* without --aa, the image matches isorender's; the renderer enables GL_MULTISAMPLE */
    glfwWindowHint(GLFW_SAMPLES, v->o.aa > 1 ? v->o.aa : 0);
    char title[256];
    snprintf(title, sizeof title, "isoview: %s", v->o.file);
    v->window =
        glfwCreateWindow((int)v->o.common.width, (int)v->o.common.height, title, NULL, NULL);
    if (!v->window) {
        fprintf(stderr, "isoview: cannot open a window: %s\n",
                glfw_error[0] ? glfw_error : "no OpenGL 3.3 core context");
        return -1;
    }
    glfwMakeContextCurrent(v->window);
    glfwSwapInterval(1);
    glfwSetWindowUserPointer(v->window, v);
    controls_install(v->window);
    int width, height;
    glfwGetFramebufferSize(v->window, &width, &height);
    v->camera.width = width > 0 ? (uint32_t)width : v->o.common.width;
    v->camera.height = height > 0 ? (uint32_t)height : v->o.common.height;
    const char *name = (const char *)glGetString(GL_RENDERER);
    snprintf(v->gl_renderer, sizeof v->gl_renderer, "%s", name ? name : "unknown");
    int software = v->o.renderer == TOOL_RENDERER_SOFTWARE ||
                   (v->o.renderer == TOOL_RENDERER_AUTO && v->o.aa <= 1 &&
                    ip_gl_driver_is_software(v->gl_renderer));
    /* OpenGL draws into a kept image (only what is new each frame), but with --aa into the
     * window's multisampled framebuffer, every triangle each frame */
    v->keep_image = !software && v->o.aa <= 1;
    if (!software && (display_create(&v->screen, v->keep_image, &v->err) != 0 ||
                      (v->keep_image &&
                       display_size(&v->screen, v->camera.width, v->camera.height, &v->err) != 0) ||
                      ip_renderer_create_current(v->camera.width, v->camera.height,
                                                 v->keep_image ? v->screen.framebuffer : 0,
                                                 &v->renderer, &v->err) != IP_OK)) {
        if (v->o.renderer == TOOL_RENDERER_OPENGL) {
            fprintf(stderr, "isoview: the OpenGL renderer cannot start: %s\n", v->err.message);
            return -1;
        }
        fprintf(stderr,
                "isoview: note: the OpenGL renderer cannot start (%s); drawing in "
                "software\n",
                v->err.message);
        software = 1;
        v->keep_image = 0;
        ip_renderer_destroy(v->renderer);
        v->renderer = NULL;
        display_destroy(&v->screen);
    }
    if (v->renderer) /* it draws the physical view (the software one: display_show()) */
        ip_renderer_set_mirror(v->renderer, v->space.mirror);
    if (software && (ip_canvas_create(v->o.common.threads, &v->canvas, &v->err) != IP_OK ||
                     display_create(&v->screen, 0, &v->err) != 0)) {
        fprintf(stderr, "isoview: the software renderer cannot start: %s\n", v->err.message);
        return -1;
    }
    if (overlay_create(&v->text, &v->err) != 0) {
        fprintf(stderr, "isoview: %s\n", v->err.message);
        return -1;
    }
    return 0;
}

/* --stats' "memory": what the viewer holds besides the process's code, in bytes. */
static void memory_json(FILE *f, const viewer *v)
{
    ip_cache_stats s;
    ip_cache_get_stats(v->cache, &s);
    ip_engine_memory e, c;
    ip_engine_memory_of(v->fine, &e);
    if (v->coarse) { /* the coarse pass's engine counts with the fine one's */
        ip_engine_memory_of(v->coarse, &c);
        e.mesh += c.mesh, e.workers += c.workers, e.visited += c.visited;
        e.coverage += c.coverage;
    }
    uint64_t full = v->full_mesh.capacity * (9 * sizeof(float) + 9 * sizeof(int16_t));
    uint64_t gpu = v->renderer ? ip_renderer_memory(v->renderer) : 0;
    uint64_t canvas =
        v->canvas ? ip_canvas_memory(v->canvas) + 4ull * v->screen.width * v->screen.height : 0;
    uint64_t summaries = ip_store_summary_memory(v->store);
    fprintf(f,
            ", \"memory\": {\"cache_bytes\": %llu, \"cache_peak_bytes\": %llu, "
            "\"summaries_bytes\": %llu, \"engine_mesh_bytes\": %llu, "
            "\"engine_workers_bytes\": %llu, \"visited_bytes\": %llu, \"coverage_bytes\": %llu, "
            "\"full_mesh_bytes\": %llu, \"gpu_mesh_bytes\": %llu, \"canvas_bytes\": %llu, "
            "\"rss_bytes\": %llu, \"rss_peak_bytes\": %llu}",
            (unsigned long long)s.resident_bytes, (unsigned long long)s.resident_peak_bytes,
            (unsigned long long)summaries, (unsigned long long)e.mesh,
            (unsigned long long)e.workers, (unsigned long long)e.visited,
            (unsigned long long)e.coverage, (unsigned long long)full, (unsigned long long)gpu,
            (unsigned long long)canvas, (unsigned long long)ip_rss_bytes(),
            (unsigned long long)ip_peak_rss_bytes());
}

static void json_counts(FILE *f, void *user)
{
    const viewer *v = user;
    ip_engine_counts t;
    int full = v->full_shown;
    if (full)
        t = v->full_counts;
    else
        ip_engine_totals(v->engine, &t);
    int done = full || ip_engine_done(v->engine);
    tool_view_options common; /* "clip": the planes as they apply at the end */
    clip_options(v, &common);
    ip_camera physical; /* the camera as the file's space states it */
    tool_space_physical(&v->space, &v->camera, &physical);
    const tool_run_json j = {v->o.file,
                             v->iso,
                             full, /* TOOL_PROGRESSIVE when not shown */
                             &physical,
                             v->canvas ? "software" : "opengl",
                             &common,
                             0,
                             done,
                             &t,
                             full ? v->pass_render : t.rendering_seconds,
                             full ? v->full_wall : v->pass_wall,
                             0.0,
                             v->iso_stored,
                             v->o.common.rescale};
    tool_write_run_json(f, &j);
    if (done)
        fprintf(f, ", \"final_pixel_pct\": %.4f", 100.0);
    const frame_clock *k = &v->clock;
    double mean = frames_per_second(k);
    fprintf(f,
            ", \"passes\": %llu, \"fps\": {\"frames\": %llu, \"seconds\": %.6f, "
            "\"mean\": %.3f, \"min\": %.3f, \"max\": %.3f}",
            (unsigned long long)v->passes, (unsigned long long)k->frames,
            k->frames ? k->last - k->first : 0.0, mean, k->seconds ? k->slowest : mean,
            k->seconds ? k->fastest : mean);
    fprintf(f, ", \"read_aheads\": %llu", (unsigned long long)v->read_aheads);
    fprintf(f, ", \"fps_moving\": %.3f, \"gl_renderer\": ",
            v->moving_seconds > 0 ? (double)v->moving_frames / v->moving_seconds : 0.0);
    tool_json_string(f, v->gl_renderer);
    record_json(f, v);
    memory_json(f, v);
}

static void print_summary(const viewer *v)
{
    ip_engine_counts t;
    if (v->full_shown)
        t = v->full_counts;
    else
        ip_engine_totals(v->engine, &t);
    char unit[IP_RESCALE_UNIT_MAX + 1];
    printf("%s: iso %g%s, %s, %ux%u\n", v->o.file, v->iso,
           tool_unit_suffix(v->o.common.rescale, unit, sizeof unit),
           !v->full_shown                   ? "progressive"
           : v->full_shown == TOOL_FULL_LOD ? "full extraction at adaptive resolution"
                                            : "full extraction",
           v->camera.width, v->camera.height);
    printf("  rays          %llu of %llu\n", (unsigned long long)t.rays,
           (unsigned long long)v->camera.width * v->camera.height);
    printf("  triangles     %llu\n", (unsigned long long)t.triangles);
    printf("  frames        %llu, %.1f fps (passes: %llu)\n", (unsigned long long)v->clock.frames,
           frames_per_second(&v->clock), (unsigned long long)v->passes);
}

static int finish(viewer *v)
{
    record_end(v);
    ip_cache_stats s;
    ip_cache_get_stats(v->cache, &s);
    uint64_t summary = ip_store_summary_memory(v->store);
    if (!v->o.common.quiet && !tool_is_stdout(v->o.common.stats)) {
        print_summary(v);
        tool_print_cache_table(stdout, &s, summary);
    }
    /* a failed run (a bad brick, a renderer error) writes no statistics, as isorender */
    if (v->o.common.stats && !v->failed && !tool_signal_caught() &&
        tool_write_stats_file("isoview", v->o.common.stats, v->o.common.force, &s, summary,
                              json_counts, v) != 0)
        return 1;
    return 0;
}

/* The run's inputs and outputs: the brick file, the script, --stats, --screenshot-at and
 * the script's screenshots, checked together (tool_check_paths()). Returns 0, or 1 after
 * printing the problem. */
static int check_paths(const viewer *v)
{
    size_t outputs_count = 2;
    for (size_t i = 0; i < v->command_count; i++)
        outputs_count += v->commands[i].kind == COMMAND_SCREENSHOT;
    const char **outputs = calloc(outputs_count, sizeof *outputs);
    if (!outputs) {
        fprintf(stderr, "isoview: out of memory\n");
        return 1;
    }
    size_t n = 0;
    outputs[n++] = v->o.common.stats;
    outputs[n++] = v->o.screenshot_path;
    for (size_t i = 0; i < v->command_count; i++)
        if (v->commands[i].kind == COMMAND_SCREENSHOT)
            outputs[n++] = v->commands[i].text;
    const char *inputs[] = {v->o.file, v->o.script};
    int rc = tool_check_paths("isoview", inputs, 2, outputs, n, v->o.common.force);
    free(outputs);
    return rc;
}

/* Everything that needs no window, so that bad input fails before one opens. Returns 0, -1
 * with the error in v->err, or -2 after the error was printed. */
static int prepare(viewer *v)
{
    ip_error *err = &v->err;
    const char *inputs[] = {v->o.file, v->o.script};
    if (tool_check_paths("isoview", inputs, 2, NULL, 0, v->o.common.force) != 0)
        return -2;
    if (ip_store_open(v->o.file, &v->store, err) != IP_OK)
        return -1;
    if (ip_cache_create(v->store, v->o.common.cache_bytes, &v->cache, err) != IP_OK)
        return -1;
    const ip_layout *l = ip_store_layout(v->store);
    tool_space_of(v->store, &v->space);
    memcpy(v->lo, v->space.lo, sizeof v->lo);
    memcpy(v->hi, v->space.hi, sizeof v->hi);
    tool_space_clip(&v->space, &v->o.common);
    tool_settle_iso(&v->o.common, l);
    v->iso = v->o.common.iso_value;
    v->iso_stored = v->o.common.iso_stored;
    double range[2];
    tool_value_range(v->o.common.rescale, l->value_min, l->value_max, range);
    v->value_min = range[0];
    v->value_max = range[1];
    v->camera.width = v->o.common.width;
    v->camera.height = v->o.common.height;
    if (camera_from(v, v->o.common.camera, v->o.common.view, &v->camera, err) != 0)
        return -1;
    if (v->o.script && load_script(v, err) != 0)
        return -1;
    if (check_paths(v) != 0)
        return -2;
    v->clip_on = v->o.common.clip_count > 0;
    if (create_engine(v, err) != 0)
        return -1;
    tool_warn_iso_range("isoview", v->store, &v->o.common, NULL, 0);
    return 0;
}

int main(int argc, char **argv)
{
    viewer *v = calloc(1, sizeof *v);
    if (!v) {
        fprintf(stderr, "isoview: out of memory\n");
        return 1;
    }
    int rc = parse_args(argc, argv, &v->o);
    if (rc) {
        free(v);
        return rc;
    }
    ip_error_clear(&v->err);
    ip_mesh_init(&v->full_mesh);
    v->overlay_mode = OVERLAY_COMPACT;
    v->drag_button = -1;
    v->restart = 1;
    rc = 1;
    tool_signals_catch();
    int prepared = prepare(v);
    if (prepared == -1) {
        tool_fail("isoview", &v->err);
    } else if (prepared == 0 && open_window(v) == 0) {
        /* the window may have opened at another size than asked: fit --view to it */
        if (!v->o.common.camera)
            (void)camera_from(v, NULL, v->o.common.view, &v->camera, &v->err);
        v->start = ip_now_seconds();
        while (!v->quit && !tool_signal_caught())
            if (frame(v) != 0) {
                tool_fail("isoview", &v->err);
                v->failed = 1;
                break;
            }
        int written = finish(v);
        rc = v->failed || written != 0;
    }
    tool_signals_cancel_engine(NULL);
    if (tool_signal_caught())
        fprintf(stderr, "isoview: %s: interrupted; no --stats or pending screenshot written\n",
                v->o.file);
    free(v->screenshot_pending);
    overlay_destroy(&v->text);
    display_destroy(&v->screen);
    ip_canvas_destroy(v->canvas);
    ip_renderer_destroy(v->renderer);
    if (v->window)
        glfwDestroyWindow(v->window);
    glfwTerminate();
    ip_engine_destroy(v->fine);
    ip_engine_destroy(v->coarse);
    ip_mesh_free(&v->full_mesh);
    free_commands(v);
    record_free(v);
    ip_cache_destroy(v->cache);
    ip_store_close(v->store);
    free(v);
    tool_signals_reraise();
    return rc;
}

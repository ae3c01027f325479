/* SPDX-License-Identifier: BSD-3-Clause */
/* isoview's controls: the mouse and keyboard (GLFW callbacks), and the changes of view and
 * isovalue they and the script make (each restarts the progressive order). */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "isoview.h"

#define ORBIT_DEGREES_PER_PIXEL 0.3
#define WHEEL_ZOOM 1.1 /* per wheel notch */

int camera_from(viewer *v, const char *camera_text, const char *view, ip_camera *out, ip_error *err)
{
    return tool_space_camera(&v->space, camera_text, view, v->camera.width, v->camera.height, out,
                             err);
}

void change_view(viewer *v)
{
    v->restart = 1;
}

/* A paused viewer would otherwise keep showing the old isovalue's surface under the new
 * value: the new surface is what the change asks to see, so refinement resumes. */
static void set_iso(viewer *v, double iso, double stored)
{
    v->iso = iso;
    v->iso_stored = stored;
    v->restart = 1;
    if (v->paused) {
        v->paused = 0;
        show_message(v, "refinement resumed for the new isovalue");
    }
}

void change_iso(viewer *v, double iso)
{
    set_iso(v, iso, ip_rescale_to_stored(v->o.common.rescale, iso));
}

void change_iso_stored(viewer *v, double stored)
{
    set_iso(v, ip_rescale_to_value(v->o.common.rescale, stored), stored);
}

void set_clip(viewer *v, int on)
{
    unsigned planes = v->o.common.clip_count;
    if (!planes) {
        show_message(v, "no clipping planes: start isoview with --clip SPEC");
        return;
    }
    if (on != v->clip_on) {
        v->clip_on = on;
        v->clip_changed = 1;
        v->restart = 1;
        v->paused = 0;
    }
    show_message(v, on ? "clipping on: %u plane%s" : "clipping off (%u plane%s kept for c)", planes,
                 planes > 1 ? "s" : "");
}

void clip_options(const viewer *v, tool_view_options *o)
{
    *o = v->o.common;
    if (!v->clip_on)
        o->clip_count = 0;
}

static void reset_view(viewer *v)
{
    ip_error ignored;
    if (camera_from(v, v->o.common.camera, v->o.common.view, &v->camera, &ignored) == 0)
        change_view(v);
}

void show_message(viewer *v, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(v->message, sizeof v->message, fmt, ap);
    va_end(ap);
    v->message_until = ip_now_seconds() + 4.0;
}

/* The distance is kept within a thousandth to a hundred times the volume's diagonal, which
 * keeps the camera valid. */
void zoom_view(viewer *v, double factor)
{
    double diagonal = sqrt((v->hi[0] - v->lo[0]) * (v->hi[0] - v->lo[0]) +
                           (v->hi[1] - v->lo[1]) * (v->hi[1] - v->lo[1]) +
                           (v->hi[2] - v->lo[2]) * (v->hi[2] - v->lo[2]));
    if (diagonal <= 0)
        diagonal = 1;
    ip_camera_dolly(&v->camera, factor, 1e-3 * diagonal, 100 * diagonal);
}

static void step_iso(viewer *v, double fraction)
{
    double range = (double)v->value_max - (double)v->value_min;
    if (!(range > 0))
        range = 1;
    change_iso(v, v->iso + fraction * range);
}

static void on_key(GLFWwindow *window, int key, int scancode, int action, int mods)
{
    (void)scancode;
    viewer *v = glfwGetWindowUserPointer(window);
    if (action == GLFW_RELEASE)
        return;
    if (v->typing) {
        size_t n = strlen(v->typed);
        if (key == GLFW_KEY_ENTER || key == GLFW_KEY_KP_ENTER) {
            double value;
            v->typing = 0;
            if (tool_parse_double(v->typed, &value) == 0)
                change_iso(v, value);
            else if (n)
                show_message(v, "'%s' is not a number", v->typed);
        } else if (key == GLFW_KEY_BACKSPACE && n) {
            v->typed[n - 1] = 0;
        } else if (key == GLFW_KEY_ESCAPE) {
            v->typing = 0;
        }
        return;
    }
    double fine = mods & GLFW_MOD_SHIFT ? 0.001 : 0.01;
    switch (key) {
    case GLFW_KEY_ESCAPE: v->quit = 1; break;
    case GLFW_KEY_UP: step_iso(v, fine); break;
    case GLFW_KEY_DOWN: step_iso(v, -fine); break;
    case GLFW_KEY_PAGE_UP: step_iso(v, 0.1); break;
    case GLFW_KEY_PAGE_DOWN: step_iso(v, -0.1); break;
    default: break;
    }
    if (action != GLFW_PRESS)
        return; /* letters act once per press, not on auto-repeat */
    switch (key) {
    case GLFW_KEY_I:
        v->typing = 1;
        v->typed[0] = 0;
        break;
    case GLFW_KEY_R: reset_view(v); break;
    case GLFW_KEY_P: v->paused = !v->paused; break;
    case GLFW_KEY_F: v->want_full = 1; break;
    case GLFW_KEY_C: set_clip(v, !v->clip_on); break;
    case GLFW_KEY_S:
        if (!v->screenshot_pending)
            request_screenshot(v, "");
        break;
    case GLFW_KEY_H: v->help_on = !v->help_on; break;
    case GLFW_KEY_O: v->overlay_mode = (v->overlay_mode + 1) % (OVERLAY_DETAILED + 1); break;
    default: break;
    }
}

static void on_char(GLFWwindow *window, unsigned int codepoint)
{
    viewer *v = glfwGetWindowUserPointer(window);
    size_t n = strlen(v->typed);
    if (v->typing && n + 1 < sizeof v->typed && codepoint < 128 &&
        strchr("0123456789.-+eE", (int)codepoint) && codepoint) {
        v->typed[n] = (char)codepoint;
        v->typed[n + 1] = 0;
    }
}

static void on_mouse_button(GLFWwindow *window, int button, int action, int mods)
{
    (void)mods;
    viewer *v = glfwGetWindowUserPointer(window);
    if (action == GLFW_PRESS && v->drag_button < 0 &&
        (button == GLFW_MOUSE_BUTTON_LEFT || button == GLFW_MOUSE_BUTTON_RIGHT)) {
        v->drag_button = button;
        glfwGetCursorPos(window, &v->drag_x, &v->drag_y);
    } else if (action == GLFW_RELEASE && button == v->drag_button) {
        v->drag_button = -1;
    }
}

static void on_cursor(GLFWwindow *window, double x, double y)
{
    viewer *v = glfwGetWindowUserPointer(window);
    if (v->drag_button < 0)
        return;
    double dx = x - v->drag_x, dy = y - v->drag_y;
    v->drag_x = x;
    v->drag_y = y;
    if (dx == 0 && dy == 0)
        return;
    if (v->drag_button == GLFW_MOUSE_BUTTON_LEFT) {
        tool_space_orbit(&v->space, &v->camera, dx * ORBIT_DEGREES_PER_PIXEL,
                         dy * ORBIT_DEGREES_PER_PIXEL);
    } else {
        int width, height;
        glfwGetWindowSize(window, &width, &height);
        /* the point at the target follows the cursor */
        double pixel = ip_camera_pixel_size(&v->camera, height > 0 ? height : 1);
        tool_space_pan(&v->space, &v->camera, -dx * pixel, dy * pixel);
    }
    change_view(v);
    v->last_motion = ip_now_seconds(); /* the coarse pass while it moves (main.c) */
}

static void on_scroll(GLFWwindow *window, double dx, double dy)
{
    (void)dx;
    viewer *v = glfwGetWindowUserPointer(window);
    if (dy != 0) {
        zoom_view(v, pow(WHEEL_ZOOM, dy));
        change_view(v);
        v->last_motion = ip_now_seconds();
    }
}

void controls_install(GLFWwindow *window)
{
    glfwSetKeyCallback(window, on_key);
    glfwSetCharCallback(window, on_char);
    glfwSetMouseButtonCallback(window, on_mouse_button);
    glfwSetCursorPosCallback(window, on_cursor);
    glfwSetScrollCallback(window, on_scroll);
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* isoview's parts (not part of the library): the viewer's state and what each file gives the
 * others. main.c runs the frames (extraction slices, drawing, screenshots, statistics),
 * options.c reads the command line, script.c the --script commands, controls.c the mouse and
 * keyboard and the view changes they make, overlay.c the heads-up text. */
#ifndef ISOVIEW_H
#define ISOVIEW_H

#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <stddef.h>
#include <stdio.h>
#include <stdint.h>

#include "isoprop/cache.h"
#include "isoprop/engine.h"
#include "isoprop/render.h"
#include "isoprop/store.h"
#include "tool_common.h"

typedef struct options {
    tool_view_options common; /* with --stats, --force and --quiet */
    const char *file, *script, *screenshot_path;
    double screenshot_at, exit_after;
    int aa;                  /* --aa N: samples a pixel of the window (1: no multisampling) */
    int renderer;            /* --renderer: TOOL_RENDERER_AUTO, _OPENGL or _SOFTWARE */
    int reuse;               /* --reuse on|off: the engine's reuse across views */
    int read_ahead;          /* --read-ahead on|off: the next view of a motion read ahead */
    double drag_pixel_error; /* --drag-pixel-error P: the coarse pass while moving (0: none) */
} options;

typedef enum command_kind {
    COMMAND_CAMERA,
    COMMAND_VIEW,
    COMMAND_ISO,
    COMMAND_ISO_STORED,
    COMMAND_ORBIT,
    COMMAND_ZOOM,
    COMMAND_WAIT,
    COMMAND_WAIT_DONE,
    COMMAND_FULL,
    COMMAND_OVERLAY,
    COMMAND_PAUSE,
    COMMAND_HELP,
    COMMAND_CLIP,
    COMMAND_SCREENSHOT,
    COMMAND_DRAG,
    COMMAND_QUIT
} command_kind;

typedef struct command {
    command_kind kind;
    double a, b, c;
    char *text; /* camera, view, screenshot: owned */
} command;

/* What the heads-up text shows: nothing, two lines at the bottom-left corner, or everything at
 * the top-left corner (the key o cycles through them in this order). */
typedef enum overlay_mode {
    OVERLAY_OFF,
    OVERLAY_COMPACT,
    OVERLAY_DETAILED
} overlay_mode;

/* The text overlay: stb_easy_font's quads drawn as indexed triangles in pixel coordinates. */
typedef struct overlay {
    GLuint program, array, vertices, indices;
    GLint viewport_at, scale_at, offset_at, colour_at;
    uint32_t index_quads; /* quads the index buffer covers */
    char *quads;          /* stb_easy_font's vertex output */
    int quads_size;       /* bytes */
} overlay;

/* The software renderer's window side: the canvas's image as a texture over the window. */
typedef struct display {
    GLuint texture, framebuffer; /* the image, bottom row first, and its framebuffer */
    GLuint depth;                /* with_depth: the OpenGL renderer's depth buffer */
    int with_depth;              /* for the OpenGL renderer (display_create()) */
    uint8_t *rows;               /* the rows sent, turned bottom first (software) */
    uint32_t width, height;      /* of the texture (0: none yet) */
} display;

/* One pass's course, for --stats: when its frames came and what they had drawn. */
typedef struct pass_record {
    double start;                     /* seconds since the window opened: the change */
    double first_frame, complete;     /* seconds after start (complete < 0: never) */
    double final_85, final_995;       /* seconds after start to 85 % / 99.5 % of the final
                                          pixels (< 0: not measured) */
    uint64_t frames, triangles, rays; /* frames drawn, and the pass's mesh at its end */
    uint64_t kept;                    /* triangles kept from the view before (--reuse) */
    int moving;                       /* it began during a drag */
} pass_record;

/* A frame of a pass: seconds after the pass's start, and the triangles it had drawn. */
typedef struct frame_mark {
    double time;
    uint64_t triangles;
} frame_mark;

/* Frames per second, for the overlay (a short window) and the stats (whole seconds). */
typedef struct frame_clock {
    double first, last; /* times of the first and last frame, seconds */
    uint64_t frames;
    double window_start;
    uint64_t window_frames;
    double shown; /* the overlay's figure */
    double second_start;
    uint64_t second_frames, seconds; /* whole-second windows completed */
    double slowest, fastest;         /* frames in the slowest and fastest whole second */
} frame_clock;

typedef struct viewer {
    options o;
    ip_store *store;
    ip_cache *cache;
    ip_engine *engine;        /* the one in use: fine, or coarse while the view moves */
    ip_engine *fine, *coarse; /* coarse: --drag-pixel-error's (NULL: none) */
    GLFWwindow *window;
    ip_renderer *renderer; /* OpenGL (NULL with the software renderer) */
    ip_canvas *canvas;     /* the software renderer (NULL with OpenGL) */
    display screen;        /* the canvas's image in the window */
    /* the image kept between frames: the mesh it holds a prefix of (NULL: start over), the
     * camera it was drawn for and (OpenGL) the triangles drawn into it */
    const ip_mesh *canvas_mesh;
    ip_camera canvas_camera;
    uint64_t gl_drawn;
    int keep_image;       /* OpenGL draws into the kept image (not with --aa) */
    char gl_renderer[96]; /* GL_RENDERER */
    overlay text;
    tool_space space; /* the file's physical space: the views, the planes, the image */
    double lo[3], hi[3];
    double value_min, value_max;   /* the file's value range, in its units (lowest first) */
    ip_camera camera;              /* in world units, as the engine and the renderers take it */
    double iso;                    /* in the file's units (as stored without a rescale) */
    double iso_stored;             /* the same as a stored value: the engine takes it as a float */
    int restart;                   /* the view or the isovalue changed: begin again */
    uint64_t uploaded;             /* triangles of the engine's mesh on the GPU */
    uint64_t passes;               /* ip_engine_begin() calls */
    double pass_wall, pass_render; /* this pass: seconds stepping, seconds drawing */
    double draw_seconds;           /* the last frame, from the end of its slice to its swap */
    /* paused: no rays are cast; a change of view waits (restart stays set, the mesh shown stays
     * on screen) until resumed; a change of isovalue resumes */
    int paused, want_full, help_on;
    /* the full extraction is shown instead of the pass (0: not): TOOL_FULL, or TOOL_FULL_LOD
     * with --lod on (what full_mesh holds) */
    int full_shown;
    /* the --clip planes apply (the key c toggles them); clip_changed: the engine must be made
     * again with the planes on or off before the next pass */
    int clip_on, clip_changed;
    overlay_mode overlay_mode;
    ip_mesh full_mesh;
    ip_engine_counts full_counts;
    double full_wall;
    int overdraw_state; /* 0: not measured for the mesh shown, 1: measured, -1: failed */
    double overdraw;    /* triangles / those owning a pixel of the finished image */
    int typing;
    char typed[48];
    char message[160];
    double message_until;
    int drag_button; /* GLFW_MOUSE_BUTTON_LEFT or _RIGHT while dragging, else -1 */
    double drag_x, drag_y;
    command *commands;
    size_t command_count, next_command;
    double wait_until;
    int waiting_done;
    char *screenshot_pending; /* a path, or "" for the next free isoview-NNN.png */
    int screenshot_at_taken;
    uint32_t screenshot_number;
    double start;
    frame_clock clock;
    /* the course of each pass (--stats "views"): frame times and the triangles drawn by them */
    pass_record *records;
    size_t record_count, record_capacity;
    frame_mark *marks; /* this pass's frames */
    size_t frame_count, frame_capacity;
    int pass_recorded; /* this pass's record is complete */
    /* a drag from a script (COMMAND_DRAG): degrees a second left to turn, until drag_end */
    double drag_rate[2], drag_end, drag_last;
    double last_motion; /* when the mouse (or a script's drag) last moved the view */
    /* the cameras of the last two fine passes begun, for reading the next view ahead */
    ip_camera pass_camera[2];
    uint64_t fine_passes;
    uint64_t read_aheads;   /* views read ahead (ip_engine_read_ahead()) */
    uint64_t moving_frames; /* frames drawn during a drag (the mouse's or a script's) */
    double moving_seconds;  /* and the seconds they took */
    int quit, failed;
    ip_error err;
} viewer;

/* main.c */
/* Fills *err with code and the formatted message. */
void set_error(ip_error *err, ip_status code, const char *fmt, ...);
/* 1 once this pass has cast its --rays, 2 once it has extracted for its --time, else 0. */
int pass_limit_reached(const viewer *v);
/* 1 once nothing more will be extracted until the next change, or while paused; never while
 * the coarse pass of a moving view is shown (the fine one follows). */
int refinement_complete(const viewer *v);
/* The mesh on the screen: the full extraction when shown, else the pass's. */
const ip_mesh *shown_mesh(const viewer *v);
/* Saves the next frame to `path` ("" for the next free isoview-NNN.png). */
void request_screenshot(viewer *v, const char *path);

/* options.c */
/* Parses the command line into *o; returns 0, or 2 after a usage error (exits 0 after --help
 * and --version). */
int parse_args(int argc, char **argv, options *o);

/* script.c */
/* A malloc'd copy of text, or NULL. */
char *copy_text(const char *text);
/* Reads the whole --script up front, so that a bad line fails before a window opens. Returns
 * 0, or -1 with the error ("FILE:LINE: problem") in *err. */
int load_script(viewer *v, ip_error *err);
/* Runs script commands until a wait, a screenshot (taken at the end of this frame) or the
 * end of the script; t is seconds since the window opened. */
void run_script(viewer *v, double t);
void free_commands(viewer *v);

/* controls.c */
/* The world camera of the named view `view` (fitted to the volume; NULL: the file's default)
 * or of the camera text (physical units), at the current size. Returns 0, or -1 with the error
 * in *err. */
int camera_from(viewer *v, const char *camera_text, const char *view, ip_camera *out,
                ip_error *err);
void change_view(viewer *v);
/* A new isovalue: `iso` in the file's units, or (change_iso_stored()) a stored value; each
 * also sets the other through the file's rescale. */
void change_iso(viewer *v, double iso);
void change_iso_stored(viewer *v, double stored);
/* Moves the eye toward the target: the distance is divided by `factor`. */
void zoom_view(viewer *v, double factor);
/* Turns the --clip planes on or off (a new pass with them or without them; refinement
 * resumes if paused); says so in the overlay, or that there are none. */
void set_clip(viewer *v, int on);
/* The command line's options with the clipping planes as they apply now (none while off). */
void clip_options(const viewer *v, tool_view_options *o);
/* Shows a line in the overlay for a few seconds. */
void show_message(viewer *v, const char *fmt, ...);
/* Routes the window's keyboard and mouse to the viewer (the window's user pointer). */
void controls_install(GLFWwindow *window);

/* record.c */
/* Starts the record of a new pass (the one before ends unfinished if it was not complete).
 * Returns 0, or -1 with the error in v->err. */
int record_begin(viewer *v);
/* Notes a frame shown at `end` (ip_now_seconds()); the pass's record is complete with the
 * first frame that shows complete refinement (its final pixels then measured). */
void record_frame(viewer *v, double end);
/* Ends the record of the pass shown (unfinished unless complete), at exit. */
void record_end(viewer *v);
void record_free(viewer *v);
/* Writes --stats' "views" (each pass's record) and "views_median" (over the passes that did
 * not begin during a drag), each after ", ". */
void record_json(FILE *f, const viewer *v);

/* display.c */
/* Builds the kept image's texture and framebuffer, with a depth buffer for the OpenGL
 * renderer (the window's context current).
 * Returns 0, or -1 with the error in *err. */
int display_create(display *d, int with_depth, ip_error *err);
void display_destroy(display *d);
/* Gives the image (and its depth buffer) width x height pixels; 0, or -1 with the error. */
int display_size(display *d, uint32_t width, uint32_t height, ip_error *err);
/* Sends rows [rows[0], rows[1]) of the canvas's image (all of it after a change of size; none
 * when rgba is NULL, the OpenGL renderer having drawn into the image) to the texture, their
 * columns reversed with `mirror` (the physical view of a world camera's image: tool_space.h),
 * and copies the image to the window. Returns 0, or -1 with the error in *err. */
int display_show(display *d, const uint8_t *rgba, uint32_t width, uint32_t height,
                 const uint32_t rows[2], int mirror, ip_error *err);
/* Reads the window's back buffer as drawn (overlay included), top row first. Returns 0, or -1
 * with the error in *err. */
int display_read(uint32_t width, uint32_t height, uint8_t *rgba, ip_error *err);

/* overlay.c */
/* Builds the overlay's program and buffers (the window's context current). Returns 0, or -1
 * with the error in *err. */
int overlay_create(overlay *t, ip_error *err);
void overlay_destroy(overlay *t);
/* Draws the heads-up text (when on, or while a full extraction blocks) and the help over the
 * frame just rendered. */
void overlay_draw_frame(viewer *v, int working_on_full);

#endif

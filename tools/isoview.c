/* isoview: the interactive viewer. The isosurface refines progressively in a window while it
 * stays responsive: each frame casts rays for a time slice (ip_engine_step() on the render
 * thread, whose workers use every core), uploads the triangles added since the last frame and
 * draws. The slice is FRAME_BUDGET_SECONDS, or as long as the previous frame took to draw when
 * that was longer (software OpenGL drawing a large mesh), up to MAX_SLICE_SECONDS, so that
 * drawing never starves refinement. Any change of view or isovalue restarts the progressive
 * order at once; as extraction is time-sliced, the work in flight is at most one slice.
 *
 * Scripts (--script FILE) drive the viewer for tests and demos, one command a line; blank lines
 * and lines starting with '#' are ignored. Commands run in order, each at the start of a frame,
 * until a wait:
 *
 *     camera ex,ey,ez,tx,ty,tz,ux,uy,uz,fov   set the camera (world units, degrees)
 *     view AXIS                               +x -x +y -y +z -z, as --view
 *     iso V                                   set the isovalue
 *     orbit DX_DEGREES DY_DEGREES             orbit around the target, as a mouse drag does
 *     zoom FACTOR                             move toward the target: distance / FACTOR
 *     wait SECONDS                            let frames run for that long
 *     wait done                               until every ray has been cast (or the full
 *                                             extraction is shown)
 *     full                                    full extraction, as the key f
 *     overlay on|off                          show or hide the heads-up text
 *     screenshot PATH                         save the next frame as PNG
 *     quit                                    exit (status 0)
 *
 * docs/isoview.md documents the controls, the options and the script format.
 */
#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* The font is a header of static functions (some unused here) in its own style: its warnings
 * are not ours (CMake also adds its folder as a system include folder). */
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-braces"
#include <stb_easy_font.h>
#pragma GCC diagnostic pop

#include "isoprop/cache.h"
#include "isoprop/engine.h"
#include "isoprop/output.h"
#include "isoprop/render.h"
#include "isoprop/store.h"
#include "tool_common.h"

#define FRAME_BUDGET_SECONDS 0.012 /* ray casting per frame: keeps 30+ fps while refining */
#define MAX_SLICE_SECONDS 0.25     /* the longest slice: bounds the delay of input */
#define ORBIT_DEGREES_PER_PIXEL 0.3
#define WHEEL_ZOOM 1.1             /* per wheel notch */
#define FPS_WINDOW_SECONDS 0.5     /* the overlay's fps is averaged over this long */

static const char usage[] =
    "usage: isoview FILE.ibv --iso V [options]\n"
    "Shows the isosurface V in a window (OpenGL 3.3 core through GLFW), refining it\n"
    "progressively (rays in the paper's order) while you orbit, pan, zoom and change V.\n"
    "  --size WxH          window size (default 1280x960)\n"
    "  --view AXIS         +x -x +y -y +z -z: the side the eye is on, whole volume in frame\n"
    "                      (default -y; up is +z, or +y for the z views)\n"
    "  --camera E,T,U,FOV  ex,ey,ez,tx,ty,tz,ux,uy,uz,fov in world units and degrees\n"
    "  --rays N            each pass (view and isovalue) stops after N rays\n"
    "  --time SECONDS      each pass stops extracting after this long\n"
    "  --cutoff DEGREES    propagation cut-off angle (default 1.81)\n"
    "  --foldback DEGREES  fold-back tolerance (default 0.25)\n"
    "  --lod on|off        adaptive resolution: far regions from coarser levels (default on)\n"
    "  --pixel-error P     with --lod: coarsen where a cell projects to <= P pixels (default 1)\n"
    "  --cache-mb N        brick cache budget in MiB (default 512, or a quarter of RAM)\n"
    "  --threads N         threads for seeding, propagation and full extraction\n"
    "                      (default: all cores)\n"
    "  --stats OUT.json    on exit: counts, times, fps and the cache statistics as JSON\n"
    "  --script FILE       run the commands of FILE (see docs/isoview.md)\n"
    "  --screenshot-at SECONDS OUT.png\n"
    "                      save the window's image that long after it opened\n"
    "  --exit-after SECONDS\n"
    "                      close the window that long after it opened (exit status 0)\n"
    "  --force             replace existing outputs: --stats, screenshots named by --script\n"
    "                      or --screenshot-at (regular files only; never an input)\n"
    "  --quiet             print nothing but errors and warnings\n"
    "  --version           print the version and exit\n"
    "Ctrl-C (or SIGTERM) closes the window without writing --stats or pending screenshots;\n"
    "isoview then ends as killed by the signal.\n"
    "Controls: left drag orbits, right drag pans, the wheel zooms; Up/Down change V by 1 %\n"
    "of the value range (with Shift 0.1 %), PageUp/PageDown by 10 %; i types V (Enter\n"
    "applies); r resets the view; p pauses; f extracts everything; s saves a screenshot;\n"
    "o hides the overlay; h shows help; Esc quits.\n";

static const char help_text[] =
    "left drag      orbit around the target\n"
    "right drag     pan\n"
    "wheel          zoom\n"
    "Up / Down      isovalue +/- 1 % of the value range\n"
    "Shift+Up/Down  isovalue +/- 0.1 %\n"
    "PgUp / PgDn    isovalue +/- 10 %\n"
    "i              type an isovalue (Enter applies, Esc cancels)\n"
    "r              reset the view\n"
    "p              pause / resume refinement\n"
    "f              full extraction (until the next change)\n"
    "s              save a screenshot (isoview-NNN.png)\n"
    "o              overlay on / off\n"
    "h              this help\n"
    "Esc            quit";

typedef struct options {
    tool_view_options common;
    const char *file, *stats, *script, *screenshot_path;
    double screenshot_at, exit_after;
    int force, quiet;
} options;

typedef enum command_kind {
    COMMAND_CAMERA,
    COMMAND_VIEW,
    COMMAND_ISO,
    COMMAND_ORBIT,
    COMMAND_ZOOM,
    COMMAND_WAIT,
    COMMAND_WAIT_DONE,
    COMMAND_FULL,
    COMMAND_OVERLAY,
    COMMAND_SCREENSHOT,
    COMMAND_QUIT
} command_kind;

typedef struct command {
    command_kind kind;
    double a, b;
    char *text; /* camera, view, screenshot: owned */
} command;

/* The text overlay: stb_easy_font's quads drawn as indexed triangles in pixel coordinates. */
typedef struct overlay {
    GLuint program, array, vertices, indices;
    GLint viewport_at, scale_at, offset_at, colour_at;
    uint32_t index_quads; /* quads the index buffer covers */
    char *quads;          /* stb_easy_font's vertex output */
    int quads_size;       /* bytes */
} overlay;

/* Frames per second, for the overlay (a short window) and the stats (whole seconds). */
typedef struct frame_clock {
    double first, last;                /* times of the first and last frame, seconds */
    uint64_t frames;
    double window_start;
    uint64_t window_frames;
    double shown;                      /* the overlay's figure */
    double second_start;
    uint64_t second_frames, seconds;   /* whole-second windows completed */
    double slowest, fastest;           /* frames in the slowest and fastest whole second */
} frame_clock;

typedef struct viewer {
    options o;
    ip_store *store;
    ip_cache *cache;
    ip_engine *engine;
    GLFWwindow *window;
    ip_renderer *renderer;
    overlay text;
    double lo[3], hi[3];
    float value_min, value_max;
    ip_camera camera;
    double iso;              /* the engine takes it as a float */
    int restart;             /* the view or the isovalue changed: begin again */
    uint64_t uploaded;       /* triangles of the engine's mesh on the GPU */
    uint64_t passes;         /* ip_engine_begin() calls */
    double pass_wall, pass_render; /* this pass: seconds stepping, seconds drawing */
    double draw_seconds;     /* the last frame, from the end of its slice to its swap */
    int paused, want_full, full_shown, overlay_on, help_on;
    ip_mesh full_mesh;
    ip_engine_counts full_counts;
    double full_wall;
    int typing;
    char typed[48];
    char message[160];
    double message_until;
    int drag_button;         /* GLFW_MOUSE_BUTTON_LEFT or _RIGHT while dragging, else -1 */
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
    int quit, failed;
    ip_error err;
} viewer;

static char glfw_error[512];

static void on_glfw_error(int code, const char *description)
{
    (void)code;
    if (!glfw_error[0])
        snprintf(glfw_error, sizeof glfw_error, "%s", description);
}


static void set_error(ip_error *err, ip_status code, const char *fmt, ...)
{
    va_list ap;
    err->code = code;
    va_start(ap, fmt);
    vsnprintf(err->message, sizeof err->message, fmt, ap);
    va_end(ap);
}

static int parse_args(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    tool_view_options_default(&o->common, 1280, 960);
    o->screenshot_at = -1;
    o->exit_after = -1;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        int taken = tool_parse_view_option("isoview", argc, argv, &i, &o->common);
        if (taken == 2)
            return 2;
        if (taken)
            continue;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(usage, stdout);
            exit(0);
        } else if (!strcmp(a, "--version")) {
            tool_print_version("isoview");
            exit(0);
        } else if (!strcmp(a, "--stats") && v) {
            o->stats = v, i++;
        } else if (!strcmp(a, "--script") && v) {
            o->script = v, i++;
        } else if (!strcmp(a, "--screenshot-at") && v && i + 2 < argc) {
            if (tool_parse_double(v, &o->screenshot_at) != 0 || o->screenshot_at < 0)
                return tool_usage_error("isoview", "--screenshot-at '%s' is not seconds", v);
            o->screenshot_path = argv[i + 2], i += 2;
        } else if (!strcmp(a, "--exit-after") && v) {
            if (tool_parse_double(v, &o->exit_after) != 0 || o->exit_after < 0)
                return tool_usage_error("isoview", "--exit-after '%s' is not seconds", v);
            i++;
        } else if (!strcmp(a, "--force")) {
            o->force = 1;
        } else if (!strcmp(a, "--quiet") || !strcmp(a, "-q")) {
            o->quiet = 1;
        } else if (a[0] == '-' && a[1]) {
            return tool_usage_error("isoview", "unknown or incomplete option '%s'", a);
        } else if (!o->file) {
            o->file = a;
        } else {
            return tool_usage_error("isoview", "more than one file ('%s')", a);
        }
    }
    if (!o->file)
        return tool_usage_error("isoview", "no brick file");
    if (!o->common.has_iso)
        return tool_usage_error("isoview", "--iso V is required");
    return 0;
}

/* ---- vectors and camera moves ---- */

static void rotate(double v[3], const double axis[3], double degrees)
{
    double a = degrees * M_PI / 180.0, c = cos(a), s = sin(a);
    double d = axis[0] * v[0] + axis[1] * v[1] + axis[2] * v[2];
    double x[3] = {axis[1] * v[2] - axis[2] * v[1], axis[2] * v[0] - axis[0] * v[2],
                   axis[0] * v[1] - axis[1] * v[0]};
    for (int i = 0; i < 3; i++)
        v[i] = v[i] * c + x[i] * s + axis[i] * d * (1 - c); /* Rodrigues */
}

static double distance(const ip_camera *c)
{
    double d[3] = {c->eye[0] - c->target[0], c->eye[1] - c->target[1], c->eye[2] - c->target[2]};
    return sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

/* Moves the eye around the target: `right` degrees about the camera's up (the scene turns
 * right), `down` degrees about its right axis. Up turns along, so the camera never becomes
 * degenerate, whatever the path. */
static void orbit(ip_camera *c, double right, double down)
{
    ip_camera_basis b;
    ip_camera_basis_of(c, &b);
    double offset[3], up[3], axis[3];
    for (int i = 0; i < 3; i++) {
        offset[i] = c->eye[i] - c->target[i];
        up[i] = b.up[i];
        axis[i] = b.right[i];
    }
    rotate(offset, b.up, -right);
    rotate(axis, b.up, -right); /* the right axis after the first turn */
    rotate(offset, axis, -down);
    rotate(up, axis, -down);
    for (int i = 0; i < 3; i++) {
        c->eye[i] = c->target[i] + offset[i];
        c->up[i] = up[i];
    }
}

/* Pans by (dx, dy) pixels of an image `height` pixels tall: the point at the target follows
 * the cursor. */
static void pan(ip_camera *c, double dx, double dy, double height)
{
    ip_camera_basis b;
    ip_camera_basis_of(c, &b);
    double per_pixel = 2.0 * distance(c) * b.tan_half_y / height;
    for (int i = 0; i < 3; i++) {
        double move = -dx * per_pixel * b.right[i] + dy * per_pixel * b.up[i];
        c->eye[i] += move;
        c->target[i] += move;
    }
}

/* Moves the eye toward the target: the distance is divided by `factor`, within limits that
 * keep the camera valid (a thousandth to a hundred times the volume's diagonal). */
static void zoom(viewer *v, double factor)
{
    ip_camera *c = &v->camera;
    double diagonal = sqrt((v->hi[0] - v->lo[0]) * (v->hi[0] - v->lo[0]) +
                           (v->hi[1] - v->lo[1]) * (v->hi[1] - v->lo[1]) +
                           (v->hi[2] - v->lo[2]) * (v->hi[2] - v->lo[2]));
    if (diagonal <= 0)
        diagonal = 1;
    double d = distance(c), wanted = d / factor;
    if (wanted < 1e-3 * diagonal)
        wanted = 1e-3 * diagonal;
    if (wanted > 100 * diagonal)
        wanted = 100 * diagonal;
    for (int i = 0; i < 3; i++)
        c->eye[i] = c->target[i] + (c->eye[i] - c->target[i]) * wanted / d;
}

/* The camera of `axis` (fitted to the volume) or of the camera text, at the current size. */
static int camera_from(viewer *v, const char *camera_text, const char *axis, ip_camera *out,
                       ip_error *err)
{
    ip_camera c = v->camera;
    if (camera_text) {
        if (ip_camera_parse(camera_text, &c, err) != IP_OK ||
            ip_camera_check(&c, err) != IP_OK)
            return -1;
    } else if (ip_camera_fit_axis(v->lo, v->hi, axis, 30.0, c.width, c.height, &c, err) !=
               IP_OK) {
        return -1;
    }
    *out = c;
    return 0;
}

static void change_view(viewer *v)
{
    v->restart = 1;
}

static void change_iso(viewer *v, double iso)
{
    v->iso = iso;
    v->restart = 1;
}

static void reset_view(viewer *v)
{
    ip_error ignored;
    if (camera_from(v, v->o.common.camera, v->o.common.view, &v->camera, &ignored) == 0)
        change_view(v);
}

static void show_message(viewer *v, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(v->message, sizeof v->message, fmt, ap);
    va_end(ap);
    v->message_until = ip_now_seconds() + 4.0;
}

/* ---- script ---- */

static void free_commands(viewer *v)
{
    for (size_t i = 0; i < v->command_count; i++)
        free(v->commands[i].text);
    free(v->commands);
    v->commands = NULL;
    v->command_count = 0;
}

static char *copy_text(const char *text)
{
    size_t n = strlen(text) + 1;
    char *copy = malloc(n);
    if (copy)
        memcpy(copy, text, n);
    return copy;
}

/* Parses one script line into *c; returns 0, or -1 with a message (no file or line). */
static int parse_command(viewer *v, char *line, command *c, ip_error *err)
{
    char *save = NULL;
    char *word = strtok_r(line, " \t", &save);
    char *arg1 = strtok_r(NULL, " \t", &save);
    char *arg2 = strtok_r(NULL, " \t", &save);
    char *extra = strtok_r(NULL, " \t", &save);
    int args = !!arg1 + !!arg2;
    memset(c, 0, sizeof *c);
    if (extra)
        goto too_many;
    if (!strcmp(word, "camera")) {
        ip_camera probe = v->camera;
        if (args != 1)
            goto arguments;
        if (ip_camera_parse(arg1, &probe, err) != IP_OK || ip_camera_check(&probe, err) != IP_OK)
            return -1;
        c->kind = COMMAND_CAMERA;
    } else if (!strcmp(word, "view")) {
        ip_camera probe;
        if (args != 1)
            goto arguments;
        if (ip_camera_fit_axis(v->lo, v->hi, arg1, 30.0, 64, 48, &probe, err) != IP_OK)
            return -1;
        c->kind = COMMAND_VIEW;
    } else if (!strcmp(word, "iso")) {
        if (args != 1 || tool_parse_double(arg1, &c->a) != 0)
            goto arguments;
        c->kind = COMMAND_ISO;
    } else if (!strcmp(word, "orbit")) {
        if (args != 2 || tool_parse_double(arg1, &c->a) != 0 || tool_parse_double(arg2, &c->b))
            goto arguments;
        c->kind = COMMAND_ORBIT;
    } else if (!strcmp(word, "zoom")) {
        if (args != 1 || tool_parse_double(arg1, &c->a) != 0 || c->a <= 0)
            goto arguments;
        c->kind = COMMAND_ZOOM;
    } else if (!strcmp(word, "wait")) {
        if (args == 1 && !strcmp(arg1, "done")) {
            c->kind = COMMAND_WAIT_DONE;
        } else {
            if (args != 1 || tool_parse_double(arg1, &c->a) != 0 || c->a < 0)
                goto arguments;
            c->kind = COMMAND_WAIT;
        }
    } else if (!strcmp(word, "full")) {
        if (args != 0)
            goto too_many;
        c->kind = COMMAND_FULL;
    } else if (!strcmp(word, "overlay")) {
        if (args != 1 || (strcmp(arg1, "on") && strcmp(arg1, "off")))
            goto arguments;
        c->kind = COMMAND_OVERLAY;
        c->a = !strcmp(arg1, "on");
    } else if (!strcmp(word, "screenshot")) {
        if (args != 1)
            goto arguments;
        if (ip_output_check(arg1, v->o.force, err) != IP_OK)
            return -1;
        c->kind = COMMAND_SCREENSHOT;
    } else if (!strcmp(word, "quit")) {
        if (args != 0)
            goto too_many;
        c->kind = COMMAND_QUIT;
    } else {
        set_error(err, IP_ERR_ARGUMENT, "unknown command '%s'", word);
        return -1;
    }
    if (c->kind == COMMAND_CAMERA || c->kind == COMMAND_VIEW || c->kind == COMMAND_SCREENSHOT) {
        c->text = copy_text(arg1);
        if (!c->text) {
            set_error(err, IP_ERR_NOMEM, "out of memory");
            return -1;
        }
    }
    return 0;
too_many:
    set_error(err, IP_ERR_ARGUMENT, "'%s' takes fewer arguments", word);
    return -1;
arguments:
    set_error(err, IP_ERR_ARGUMENT, "bad arguments to '%s'", word);
    return -1;
}

/* Reads the whole script up front, so that a bad line fails before a window opens. */
static int load_script(viewer *v, ip_error *err)
{
    /* O_NONBLOCK and a type check: a FIFO is refused, not waited on */
    struct stat st;
    int fd = open(v->o.script, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        set_error(err, IP_ERR_IO, "%s: cannot open: %s", v->o.script, strerror(errno));
        return -1;
    }
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(fd);
        set_error(err, IP_ERR_IO, "%s: not a regular file", v->o.script);
        return -1;
    }
    FILE *f = fdopen(fd, "r");
    if (!f) {
        close(fd);
        set_error(err, IP_ERR_NOMEM, "%s: cannot read: %s", v->o.script, strerror(errno));
        return -1;
    }
    char line[4096];
    size_t capacity = 0;
    int number = 0, rc = 0;
    while (rc == 0 && fgets(line, sizeof line, f)) {
        number++;
        size_t n = strlen(line);
        if (n == sizeof line - 1 && line[n - 1] != '\n') {
            set_error(err, IP_ERR_ARGUMENT, "%s:%d: line too long", v->o.script, number);
            rc = -1;
            break;
        }
        while (n && (line[n - 1] == '\n' || line[n - 1] == '\r' || line[n - 1] == ' ' ||
                     line[n - 1] == '\t'))
            line[--n] = 0;
        char *start = line + strspn(line, " \t");
        if (!*start || *start == '#')
            continue;
        if (v->command_count == capacity) {
            size_t grown_capacity = capacity ? 2 * capacity : 16;
            command *grown = realloc(v->commands, grown_capacity * sizeof *grown);
            if (!grown) {
                set_error(err, IP_ERR_NOMEM, "%s: out of memory", v->o.script);
                rc = -1;
                break;
            }
            v->commands = grown;
            capacity = grown_capacity;
        }
        ip_error why;
        ip_error_clear(&why);
        if (parse_command(v, start, &v->commands[v->command_count], &why) != 0) {
            set_error(err, why.code, "%s:%d: %s", v->o.script, number, why.message);
            rc = -1;
            break;
        }
        v->command_count++;
    }
    if (rc == 0 && ferror(f)) {
        set_error(err, IP_ERR_IO, "%s: cannot read", v->o.script);
        rc = -1;
    }
    fclose(f);
    return rc;
}

/* 1 once this pass has cast its --rays, 2 once it has extracted for its --time, else 0. */
static int pass_limit_reached(const viewer *v)
{
    ip_engine_counts t;
    ip_engine_totals(v->engine, &t);
    if (v->o.common.rays && t.rays >= v->o.common.rays)
        return 1;
    return v->o.common.time_limit > 0 && v->pass_wall >= v->o.common.time_limit ? 2 : 0;
}

/* 1 once nothing more will be extracted until the next change (pausing aside). */
static int refinement_complete(const viewer *v)
{
    return !v->restart && !v->want_full &&
           (v->full_shown || ip_engine_done(v->engine) || pass_limit_reached(v));
}

static void request_screenshot(viewer *v, const char *path)
{
    free(v->screenshot_pending);
    v->screenshot_pending = copy_text(path);
    if (!v->screenshot_pending) {
        fprintf(stderr, "isoview: out of memory\n");
        v->failed = v->quit = 1;
    }
}

/* Runs script commands until a wait, a screenshot (taken at the end of this frame) or the
 * end of the script. */
static void run_script(viewer *v, double t)
{
    while (v->next_command < v->command_count && !v->quit) {
        if (t < v->wait_until)
            return;
        if (v->waiting_done) {
            if (!refinement_complete(v))
                return;
            v->waiting_done = 0;
        }
        const command *c = &v->commands[v->next_command++];
        ip_error err;
        switch (c->kind) {
        case COMMAND_CAMERA:
        case COMMAND_VIEW:
            if (camera_from(v, c->kind == COMMAND_CAMERA ? c->text : NULL, c->text, &v->camera,
                            &err) != 0) {
                fprintf(stderr, "isoview: %s: %s\n", v->o.script, err.message);
                v->failed = v->quit = 1;
                return;
            }
            change_view(v);
            break;
        case COMMAND_ISO:
            change_iso(v, c->a);
            break;
        case COMMAND_ORBIT:
            orbit(&v->camera, c->a, c->b);
            change_view(v);
            break;
        case COMMAND_ZOOM:
            zoom(v, c->a);
            change_view(v);
            break;
        case COMMAND_WAIT:
            v->wait_until = t + c->a;
            break;
        case COMMAND_WAIT_DONE:
            v->waiting_done = 1;
            break;
        case COMMAND_FULL:
            v->want_full = 1;
            break;
        case COMMAND_OVERLAY:
            v->overlay_on = c->a != 0;
            break;
        case COMMAND_SCREENSHOT:
            request_screenshot(v, c->text);
            return;
        case COMMAND_QUIT:
            v->quit = 1;
            return;
        }
    }
}

/* ---- input ---- */

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
    case GLFW_KEY_S:
        if (!v->screenshot_pending)
            request_screenshot(v, "");
        break;
    case GLFW_KEY_H: v->help_on = !v->help_on; break;
    case GLFW_KEY_O: v->overlay_on = !v->overlay_on; break;
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
        orbit(&v->camera, dx * ORBIT_DEGREES_PER_PIXEL, dy * ORBIT_DEGREES_PER_PIXEL);
    } else {
        int width, height;
        glfwGetWindowSize(window, &width, &height);
        pan(&v->camera, dx, dy, height > 0 ? height : 1);
    }
    change_view(v);
}

static void on_scroll(GLFWwindow *window, double dx, double dy)
{
    (void)dx;
    viewer *v = glfwGetWindowUserPointer(window);
    if (dy != 0) {
        zoom(v, pow(WHEEL_ZOOM, dy));
        change_view(v);
    }
}

/* ---- the overlay ---- */

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

static const char *const overlay_fragment_source =
    "#version 330 core\n"
    "uniform vec4 colour;\n"
    "out vec4 result;\n"
    "void main() {\n"
    "    result = colour;\n"
    "}\n";

enum { FONT_VERTEX_BYTES = 16, QUAD_BYTES = 4 * FONT_VERTEX_BYTES };

static GLuint compile_overlay_shader(GLenum kind, const char *source, ip_error *err)
{
    GLuint shader = glCreateShader(kind);
    glShaderSource(shader, 1, &source, NULL);
    glCompileShader(shader);
    GLint ok = GL_FALSE;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[512] = "";
        glGetShaderInfoLog(shader, sizeof log, NULL, log);
        glDeleteShader(shader);
        set_error(err, IP_ERR_UNSUPPORTED, "overlay shader does not compile: %s", log);
        return 0;
    }
    return shader;
}

static int overlay_create(overlay *t, ip_error *err)
{
    memset(t, 0, sizeof t[0]);
    t->quads_size = 4096 * QUAD_BYTES;
    t->quads = malloc((size_t)t->quads_size);
    if (!t->quads) {
        set_error(err, IP_ERR_NOMEM, "out of memory");
        return -1;
    }
    GLuint vs = compile_overlay_shader(GL_VERTEX_SHADER, overlay_vertex_source, err);
    GLuint fs = vs ? compile_overlay_shader(GL_FRAGMENT_SHADER, overlay_fragment_source, err) : 0;
    if (!fs) {
        glDeleteShader(vs);
        return -1;
    }
    t->program = glCreateProgram();
    glAttachShader(t->program, vs);
    glAttachShader(t->program, fs);
    glLinkProgram(t->program);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = GL_FALSE;
    glGetProgramiv(t->program, GL_LINK_STATUS, &ok);
    if (!ok) {
        set_error(err, IP_ERR_UNSUPPORTED, "overlay shaders do not link");
        return -1;
    }
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

static void overlay_destroy(overlay *t)
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

/* Draws `text` on a translucent panel whose top-left corner is at (x, y) framebuffer pixels
 * (top-left origin), scaled `scale` times. */
static void overlay_draw(overlay *t, char *text, float x, float y, float scale, uint32_t width,
                         uint32_t height)
{
    const float pad = 4;
    /* quad 0 is the panel; the text follows */
    int quads = stb_easy_font_print(0, 0, text, NULL, t->quads + QUAD_BYTES,
                                    t->quads_size - QUAD_BYTES);
    if ((uint32_t)quads + 1 > t->index_quads)
        quads = (int)t->index_quads - 1;
    float w = (float)stb_easy_font_width(text), h = (float)stb_easy_font_height(text);
    put_rectangle(t->quads, 0, -pad, -pad, w + pad, h + pad);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, (GLsizei)width, (GLsizei)height);
    glDisable(GL_DEPTH_TEST);
    glEnable(GL_BLEND);
    /* colour blends; alpha stays opaque, so that screenshots stay RGB */
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
    glUseProgram(t->program);
    glUniform2f(t->viewport_at, (float)width, (float)height);
    glUniform1f(t->scale_at, scale);
    glUniform2f(t->offset_at, x + pad * scale, y + pad * scale);
    glBindVertexArray(t->array);
    glBindBuffer(GL_ARRAY_BUFFER, t->vertices);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(quads + 1) * QUAD_BYTES, t->quads,
                 GL_STREAM_DRAW);
    glUniform4f(t->colour_at, 0.0f, 0.0f, 0.0f, 0.6f);
    glDrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_INT, NULL);
    glUniform4f(t->colour_at, 1.0f, 1.0f, 0.85f, 1.0f);
    glDrawElements(GL_TRIANGLES, 6 * quads, GL_UNSIGNED_INT,
                   (const void *)(6 * sizeof(uint32_t)));
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    glBindVertexArray(0);
    glUseProgram(0);
    glDisable(GL_BLEND);
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

static int begin_pass(viewer *v)
{
    v->restart = 0;
    v->full_shown = 0;
    v->passes++;
    v->pass_wall = v->pass_render = 0;
    ip_renderer_clear_mesh(v->renderer);
    v->uploaded = 0;
    if (ip_engine_begin(v->engine, &v->camera, (float)v->iso, &v->err) != IP_OK)
        return -1;
    return 0;
}

/* One frame's slice of ray casting, then the new triangles to the GPU. */
static int refine(viewer *v)
{
    if (v->paused || v->full_shown || ip_engine_done(v->engine) || pass_limit_reached(v))
        return 0;
    double slice = v->draw_seconds < FRAME_BUDGET_SECONDS ? FRAME_BUDGET_SECONDS
                   : v->draw_seconds > MAX_SLICE_SECONDS ? MAX_SLICE_SECONDS
                   : v->draw_seconds;
    if (v->o.common.time_limit > 0 && slice > v->o.common.time_limit - v->pass_wall)
        slice = v->o.common.time_limit - v->pass_wall;
    ip_engine_counts t;
    ip_engine_totals(v->engine, &t);
    double start = ip_now_seconds();
    ip_status st = ip_engine_step(v->engine, v->o.common.rays ? v->o.common.rays - t.rays : 0, slice, NULL,
                                  &v->err);
    v->pass_wall += ip_now_seconds() - start;
    if (st != IP_OK && st != IP_ERR_CANCELLED)
        return -1;
    const ip_mesh *mesh = ip_engine_mesh(v->engine);
    if (ip_renderer_upload(v->renderer, mesh, v->uploaded, &v->err) != IP_OK)
        return -1;
    v->uploaded = mesh->triangle_count;
    return 0;
}

/* Extracts every active cell (blocking: the frame before shows that it is working). */
static int extract_full(viewer *v)
{
    v->want_full = 0;
    ip_mesh_clear(&v->full_mesh);
    memset(&v->full_counts, 0, sizeof v->full_counts);
    double start = ip_now_seconds();
    if (ip_extract_full(v->cache, (float)v->iso, 0, v->o.common.threads, &v->full_mesh, &v->full_counts,
                        &v->err) != IP_OK)
        return -1;
    v->full_wall = ip_now_seconds() - start;
    v->pass_render = 0;
    ip_renderer_clear_mesh(v->renderer);
    if (ip_renderer_upload(v->renderer, &v->full_mesh, 0, &v->err) != IP_OK)
        return -1;
    v->full_shown = 1;
    return 0;
}

/* ---- drawing ---- */

/* The heads-up text. "final px" is the share of pixels already showing their final colour: it
 * is known exactly once every ray has been cast (100 %), and shown as "-" before. */
static void hud_text(viewer *v, char *text, size_t size, int working_on_full)
{
    ip_engine_counts t;
    ip_cache_stats s;
    ip_engine_totals(v->engine, &t);
    ip_cache_get_stats(v->cache, &s);
    double pixels = (double)v->camera.width * v->camera.height;
    uint64_t lookups = s.hits + s.misses;
    char iso[96], state[48] = "", progress[128];
    if (v->typing)
        snprintf(iso, sizeof iso, "iso> %s_  (Enter applies, Esc cancels)", v->typed);
    else
        snprintf(iso, sizeof iso, "iso %.7g  (values %.7g .. %.7g)", v->iso,
                 (double)v->value_min, (double)v->value_max);
    if (working_on_full)
        snprintf(state, sizeof state, "  [extracting all...]");
    else if (v->full_shown)
        snprintf(state, sizeof state, "  [full]");
    else if (v->paused)
        snprintf(state, sizeof state, "  [paused]");
    else if (!ip_engine_done(v->engine) && pass_limit_reached(v))
        snprintf(state, sizeof state, "  [%s reached]",
                 pass_limit_reached(v) == 1 ? "--rays" : "--time");
    if (v->full_shown)
        snprintf(progress, sizeof progress, "full: %llu cells in %.2f s   final px 100 %%\n"
                 "triangles %llu", (unsigned long long)v->full_counts.cells, v->full_wall,
                 (unsigned long long)v->full_counts.triangles);
    else
        snprintf(progress, sizeof progress, "rays %.1f %% of %.0f   final px %s\n"
                 "triangles %llu", pixels > 0 ? 100.0 * (double)t.rays / pixels : 0.0, pixels,
                 ip_engine_done(v->engine) ? "100 %" : "-", (unsigned long long)t.triangles);
    int n = snprintf(text, size, "%s%s\n%s\nfps %.1f\ncache %.1f / %.1f MiB   hit rate %.1f %%\n"
                     "misses %llu   bricks %llu / %llu",
                     iso, state, progress, v->clock.shown, (double)s.resident_bytes / 1048576.0,
                     (double)s.budget_bytes / 1048576.0,
                     lookups ? 100.0 * (double)s.hits / (double)lookups : 0.0,
                     (unsigned long long)s.misses, (unsigned long long)s.bricks_touched,
                     (unsigned long long)s.bricks_total);
    if (n > 0 && (size_t)n < size && v->message[0] && ip_now_seconds() < v->message_until)
        snprintf(text + n, size - (size_t)n, "\n%s", v->message);
    else if (n > 0 && (size_t)n < size && !v->help_on)
        snprintf(text + n, size - (size_t)n, "\nh: help");
}

static int draw_frame(viewer *v, int working_on_full)
{
    double start = ip_now_seconds();
    if (ip_renderer_draw(v->renderer, &v->camera, v->lo, v->hi, &v->err) != IP_OK)
        return -1;
    uint32_t width = v->camera.width, height = v->camera.height;
    float scale = height >= 720 ? 2.0f : 1.0f;
    if (v->overlay_on || working_on_full) {
        char text[1024];
        hud_text(v, text, sizeof text, working_on_full);
        overlay_draw(&v->text, text, 8 * scale, 8 * scale, scale, width, height);
    }
    if (v->help_on) {
        char text[sizeof help_text];
        memcpy(text, help_text, sizeof help_text);
        float w = (float)stb_easy_font_width(text) * scale;
        float h = (float)stb_easy_font_height(text) * scale;
        float x = ((float)width - w) / 2, y = ((float)height - h) / 2;
        overlay_draw(&v->text, text, x > 0 ? x : 0, y > 0 ? y : 0, scale, width, height);
    }
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
    else if (ip_renderer_read_rgba(v->renderer, rgba, &err) == IP_OK &&
             ip_png_write(path, rgba, v->camera.width, v->camera.height,
                          automatic ? 0 : v->o.force, &err) == IP_OK)
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
        if (ip_renderer_resize(v->renderer, (uint32_t)width, (uint32_t)height, &v->err) != IP_OK)
            return -1;
        v->camera.width = (uint32_t)width;
        v->camera.height = (uint32_t)height;
        change_view(v);
    }
    return 1;
}

/* One frame: input, script, timers, extraction slice, drawing, screenshot, swap.
 * Returns 0, or -1 after an error in v->err. */
static int frame(viewer *v)
{
    glfwPollEvents();
    double t = ip_now_seconds() - v->start;
    if (glfwWindowShouldClose(v->window) || (v->o.exit_after >= 0 && t >= v->o.exit_after)) {
        v->quit = 1;
        return 0;
    }
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
    if (v->restart && begin_pass(v) != 0)
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
    frame_done(&v->clock, end);
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
    glfwWindowHint(GLFW_SAMPLES, 0); /* the image must match isorender's */
    char title[256];
    snprintf(title, sizeof title, "isoview: %s", v->o.file);
    v->window = glfwCreateWindow((int)v->o.common.width, (int)v->o.common.height, title, NULL, NULL);
    if (!v->window) {
        fprintf(stderr, "isoview: cannot open a window: %s\n",
                glfw_error[0] ? glfw_error : "no OpenGL 3.3 core context");
        return -1;
    }
    glfwMakeContextCurrent(v->window);
    glfwSwapInterval(1);
    glfwSetWindowUserPointer(v->window, v);
    glfwSetKeyCallback(v->window, on_key);
    glfwSetCharCallback(v->window, on_char);
    glfwSetMouseButtonCallback(v->window, on_mouse_button);
    glfwSetCursorPosCallback(v->window, on_cursor);
    glfwSetScrollCallback(v->window, on_scroll);
    int width, height;
    glfwGetFramebufferSize(v->window, &width, &height);
    v->camera.width = width > 0 ? (uint32_t)width : v->o.common.width;
    v->camera.height = height > 0 ? (uint32_t)height : v->o.common.height;
    if (ip_renderer_create_current(v->camera.width, v->camera.height, 0, &v->renderer,
                                   &v->err) != IP_OK ||
        overlay_create(&v->text, &v->err) != 0) {
        fprintf(stderr, "isoview: %s\n", v->err.message);
        return -1;
    }
    return 0;
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
    fprintf(f, "\"file\": ");
    tool_json_string(f, v->o.file);
    fprintf(f, ", \"iso\": %.9g, \"mode\": \"%s\", \"width\": %u, \"height\": %u, "
               "\"renderer\": \"opengl\"",
            v->iso, full ? "full" : "progressive", v->camera.width, v->camera.height);
    fprintf(f, ", \"camera\": {\"eye\": [%.9g, %.9g, %.9g], \"target\": [%.9g, %.9g, %.9g], "
               "\"up\": [%.9g, %.9g, %.9g], \"fov\": %.9g}",
            v->camera.eye[0], v->camera.eye[1], v->camera.eye[2], v->camera.target[0],
            v->camera.target[1], v->camera.target[2], v->camera.up[0], v->camera.up[1],
            v->camera.up[2], v->camera.fov_y);
    fprintf(f, ", \"lod\": %s, \"pixel_error\": %.9g", v->o.common.lod ? "true" : "false",
            v->o.common.pixel_error);
    fprintf(f, ", \"warm\": false, \"threads\": %u", ip_thread_count(v->o.common.threads));
    fprintf(f, ", \"cutoff_degrees\": %.9g, \"foldback_degrees\": %.9g", v->o.common.cutoff,
            v->o.common.foldback);
    fprintf(f, ", \"rays\": %llu, \"rays_total\": %llu, \"done\": %s, \"seeds\": %llu, "
               "\"cells\": %llu, \"triangles\": %llu",
            (unsigned long long)t.rays,
            (unsigned long long)v->camera.width * v->camera.height, done ? "true" : "false",
            (unsigned long long)t.seeds, (unsigned long long)t.cells,
            (unsigned long long)t.triangles);
    fprintf(f, ", \"time\": {\"intersection_s\": %.6f, \"propagation_s\": %.6f, "
               "\"extraction_s\": %.6f, \"rendering_s\": %.6f, \"extraction_wall_s\": %.6f, "
               "\"progress_render_s\": %.6f}",
            t.intersection_seconds, t.propagation_seconds, t.extraction_seconds,
            full ? v->pass_render : t.rendering_seconds, full ? v->full_wall : v->pass_wall,
            0.0);
    if (done)
        fprintf(f, ", \"final_pixel_pct\": %.4f", 100.0);
    const frame_clock *k = &v->clock;
    double mean = frames_per_second(k);
    fprintf(f, ", \"passes\": %llu, \"fps\": {\"frames\": %llu, \"seconds\": %.6f, "
               "\"mean\": %.3f, \"min\": %.3f, \"max\": %.3f}",
            (unsigned long long)v->passes, (unsigned long long)k->frames,
            k->frames ? k->last - k->first : 0.0, mean, k->seconds ? k->slowest : mean,
            k->seconds ? k->fastest : mean);
}

static void print_summary(const viewer *v)
{
    ip_engine_counts t;
    if (v->full_shown)
        t = v->full_counts;
    else
        ip_engine_totals(v->engine, &t);
    printf("%s: iso %g, %s, %ux%u\n", v->o.file, v->iso,
           v->full_shown ? "full extraction" : "progressive", v->camera.width,
           v->camera.height);
    printf("  rays          %llu of %llu\n", (unsigned long long)t.rays,
           (unsigned long long)v->camera.width * v->camera.height);
    printf("  triangles     %llu\n", (unsigned long long)t.triangles);
    printf("  frames        %llu, %.1f fps (passes: %llu)\n",
           (unsigned long long)v->clock.frames, frames_per_second(&v->clock),
           (unsigned long long)v->passes);
}

static int finish(viewer *v)
{
    ip_cache_stats s;
    ip_cache_get_stats(v->cache, &s);
    uint64_t summary = ip_store_layout(v->store)->summary_size;
    if (!v->o.quiet) {
        print_summary(v);
        tool_print_cache_table(stdout, &s, summary);
    }
    /* a failed run (a bad brick, a renderer error) writes no statistics, as isorender */
    if (v->o.stats && !v->failed && !tool_signal_caught() &&
        tool_write_stats_file("isoview", v->o.stats, v->o.force, &s, summary, json_counts, v) !=
            0)
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
    outputs[n++] = v->o.stats;
    outputs[n++] = v->o.screenshot_path;
    for (size_t i = 0; i < v->command_count; i++)
        if (v->commands[i].kind == COMMAND_SCREENSHOT)
            outputs[n++] = v->commands[i].text;
    const char *inputs[] = {v->o.file, v->o.script};
    int rc = tool_check_paths("isoview", inputs, 2, outputs, n, v->o.force);
    free(outputs);
    return rc;
}

/* Everything that needs no window, so that bad input fails before one opens. Returns 0, -1
 * with the error in v->err, or -2 after the error was printed. */
static int prepare(viewer *v)
{
    ip_error *err = &v->err;
    const char *inputs[] = {v->o.file, v->o.script};
    if (tool_check_paths("isoview", inputs, 2, NULL, 0, v->o.force) != 0)
        return -2;
    if (ip_store_open(v->o.file, &v->store, err) != IP_OK)
        return -1;
    if (ip_cache_create(v->store, v->o.common.cache_bytes, &v->cache, err) != IP_OK)
        return -1;
    const ip_layout *l = ip_store_layout(v->store);
    ip_layout_world_box(l, v->lo, v->hi);
    v->value_min = l->value_min;
    v->value_max = l->value_max;
    v->camera.width = v->o.common.width;
    v->camera.height = v->o.common.height;
    if (camera_from(v, v->o.common.camera, v->o.common.view, &v->camera, err) != 0)
        return -1;
    if (v->o.script && load_script(v, err) != 0)
        return -1;
    if (check_paths(v) != 0)
        return -2;
    ip_engine_options eo;
    tool_engine_options(&v->o.common, &eo);
    if (ip_engine_create(v->cache, &eo, &v->engine, err) != IP_OK)
        return -1;
    tool_signals_cancel_engine(v->engine);
    tool_warn_iso_range("isoview", v->store, v->o.common.iso, NULL, 0);
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
    v->iso = v->o.common.iso;
    v->overlay_on = 1;
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
    ip_renderer_destroy(v->renderer);
    if (v->window)
        glfwDestroyWindow(v->window);
    glfwTerminate();
    ip_engine_destroy(v->engine);
    ip_mesh_free(&v->full_mesh);
    free_commands(v);
    ip_cache_destroy(v->cache);
    ip_store_close(v->store);
    free(v);
    tool_signals_reraise();
    return rc;
}

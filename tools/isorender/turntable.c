/* SPDX-License-Identifier: BSD-3-Clause */
/* isorender --turntable: frames with the eye turned around the target, and their MP4. */
#include <errno.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "isorender.h"

#define TURNTABLE_MAX_FRAMES 100000
#define TURNTABLE_FPS 25

int parse_turntable(const char *program, const tool_option *option, const char *const *values,
                    void *base)
{
    return tool_parse_bounded(program, option->name, values[0], 1, TURNTABLE_MAX_FRAMES,
                              "a frame count", &((options *)base)->turntable);
}

int check_turntable_options(options *o)
{
    if (!o->turntable) {
        if (!o->out)
            o->out = "isorender.png";
        if (o->mp4)
            return tool_usage_error("isorender", "--mp4 needs --turntable N");
        return 0;
    }
    if (!o->out)
        o->out = "turntable";
    if (o->mesh || o->progress || o->strip || o->common.stats || o->warm)
        return tool_usage_error("isorender", "--turntable writes frames only: no --mesh, "
                                             "--progress, --strip, --stats or --warm");
    return 0;
}

/* The digits of frame numbers: 3, or more for 1000 frames and over. */
static int turntable_digits(uint64_t frames)
{
    int digits = 3;
    for (uint64_t n = 1000; n < frames; n *= 10)
        digits++;
    return digits;
}

/* ---- the turntable's frames ---- */

/* Frame f's camera: the azimuth turned by f / N of a full turn (about the view's own up axis,
 * before the elevation, so that the volume turns as on a potter's wheel). */
static void turntable_camera(const run *r, uint64_t f, ip_camera *camera)
{
    tool_orbit_options orbit = r->o.orbit;
    orbit.azimuth += 360.0 * (double)f / (double)r->o.turntable;
    *camera = r->view_camera;
    tool_apply_orbit(&orbit, &r->space, camera);
}

/* The mesh of frame f: a progressive run from scratch for its camera (with --rays and --time
 * per frame), the one full extraction (--full), made for frame 0, or the full extraction at
 * the frame's own levels (--full-lod: the bands follow the eye). */
static int turntable_extract_one(run *r, ip_error *err)
{
    if (r->o.full == TOOL_FULL)
        return r->mesh ? 0 : extract_full(r, err);
    if (r->o.full == TOOL_FULL_LOD) {
        ip_mesh_free(&r->full_mesh);
        r->mesh = NULL;
        return extract_full(r, err);
    }
    if (create_engine(r, err) != 0)
        return -1;
    double start = ip_now_seconds();
    if (ip_engine_begin(r->engine, &r->camera, (float)r->o.common.iso_stored, err) != IP_OK ||
        ip_engine_step(r->engine, r->o.common.rays, r->o.common.time_limit, NULL, err) != IP_OK)
        return -1;
    r->extraction_wall = ip_now_seconds() - start;
    ip_engine_totals(r->engine, &r->totals);
    r->mesh = ip_engine_mesh(r->engine);
    return 0;
}

/* Frame f's meshes, of every surface. */
static int turntable_extract(run *r, ip_error *err)
{
    for (size_t i = 0; i <= r->other_count; i++) {
        run *s = surface_run(r, i);
        share_view(r, s);
        if (turntable_extract_one(s, err) != 0)
            return -1;
    }
    return 0;
}

/* Encodes the frames into r->o.mp4 with ffmpeg (H.264, yuv420p, TURNTABLE_FPS frames a
 * second), through a temporary file renamed at the end. Returns 0 or 1 after a message. */
static int turntable_encode(run *r)
{
    char pattern[4096], partial[4096], rate[16];
    snprintf(pattern, sizeof pattern, "%s/frame_%%0%dd.png", r->o.out,
             turntable_digits(r->o.turntable));
    snprintf(partial, sizeof partial, "%s.partial", r->o.mp4);
    snprintf(rate, sizeof rate, "%d", TURNTABLE_FPS);
    char *args[] = {"ffmpeg", "-nostdin", "-hide_banner", "-loglevel",
                    "error",  "-y",       "-framerate",   rate,
                    "-i",     pattern,    "-vf",          "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                    "-c:v",   "libx264",  "-pix_fmt",     "yuv420p",
                    "-f",     "mp4",      partial,        NULL};
    extern char **environ;
    pid_t pid;
    int error = posix_spawnp(&pid, "ffmpeg", NULL, NULL, args, environ), status = 0;
    if (error != 0 || waitpid(pid, &status, 0) != pid || !WIFEXITED(status) ||
        WEXITSTATUS(status) != 0) {
        fprintf(stderr, "isorender: %s: ffmpeg failed%s\n", r->o.mp4,
                error == ENOENT ? ": not found (install ffmpeg)" : "");
        remove(partial);
        return 1;
    }
    if (!r->o.common.force && access(r->o.mp4, F_OK) == 0) {
        fprintf(stderr, "isorender: %s: exists (--force replaces it)\n", r->o.mp4);
        remove(partial);
        return 1;
    }
    if (rename(partial, r->o.mp4) != 0) {
        fprintf(stderr, "isorender: %s: %s\n", r->o.mp4, strerror(errno));
        remove(partial);
        return 1;
    }
    if (tool_outputs_add(&r->outputs, r->o.mp4) != 0) {
        fprintf(stderr, "isorender: %s: out of memory\n", r->o.mp4);
        return 1;
    }
    return 0;
}

/* Whether `program` is an executable file in a folder of $PATH. */
static int on_path(const char *program)
{
    const char *path = getenv("PATH");
    while (path && *path) {
        const char *end = strchr(path, ':');
        size_t length = end ? (size_t)(end - path) : strlen(path);
        char file[4096];
        if (length > 0 && length < sizeof file - strlen(program) - 2) {
            snprintf(file, sizeof file, "%.*s/%s", (int)length, path, program);
            if (access(file, X_OK) == 0)
                return 1;
        }
        path = end ? end + 1 : NULL;
    }
    return 0;
}

/* Renders frame f of the turntable with the renderer in *gl (made by the first frame) and
 * writes it as OUT/frame_NNN.png. Returns 0 or -1. */
static int turntable_frame(run *r, uint64_t f, ip_renderer **gl, uint8_t *rgba, ip_error *err)
{
    turntable_camera(r, f, &r->camera);
    if (turntable_extract(r, err) != 0 || render_image(r, rgba, gl, err) != 0)
        return -1;
    if (!strcmp(r->renderer_name, "software"))
        r->o.software = 1; /* no OpenGL: say it once, not for every frame */
    char path[4096];
    int length = snprintf(path, sizeof path, "%s/frame_%0*llu.png", r->o.out,
                          turntable_digits(r->o.turntable), (unsigned long long)f);
    if (length < 0 || (size_t)length >= sizeof path) {
        err->code = IP_ERR_ARGUMENT;
        snprintf(err->message, sizeof err->message, "%.200s...: the frames' names are too long",
                 r->o.out);
        return -1;
    }
    if (ip_png_write(path, rgba, r->camera.width, r->camera.height, r->o.common.force, err) !=
        IP_OK)
        return -1;
    if (tool_outputs_add_or_error(&r->outputs, path, err) != 0)
        return -1;
    if (!r->o.common.quiet)
        printf("  frame %llu of %llu: %s, %llu triangles\n", (unsigned long long)f + 1,
               (unsigned long long)r->o.turntable, path, (unsigned long long)all_triangles(r));
    return 0;
}

int turntable_run(run *r, ip_error *err)
{
    if (r->o.mp4 && !on_path("ffmpeg")) { /* before any work: the frames alone are not asked */
        fprintf(stderr,
                "isorender: %s: --mp4 needs ffmpeg, which is not on the PATH (Debian "
                "package ffmpeg)\n",
                r->o.mp4);
        return 1;
    }
    if (mkdir(r->o.out, 0777) == 0) {
        if (tool_outputs_made_folder(&r->outputs, r->o.out) != 0) {
            rmdir(r->o.out);
            fprintf(stderr, "isorender: %s: out of memory\n", r->o.out);
            return 1;
        }
    } else if (errno != EEXIST) {
        fprintf(stderr, "isorender: %s: %s\n", r->o.out, strerror(errno));
        return 1;
    }
    struct stat st;
    if (stat(r->o.out, &st) != 0 || !S_ISDIR(st.st_mode)) {
        fprintf(stderr, "isorender: %s: not a folder (--turntable writes its frames there)\n",
                r->o.out);
        return 1;
    }
    uint8_t *rgba = malloc((size_t)r->camera.width * r->camera.height * 4);
    if (!rgba) {
        fprintf(stderr, "isorender: out of memory for a %ux%u image\n", r->camera.width,
                r->camera.height);
        return 1;
    }
    int rc = 0;
    ip_renderer *gl = NULL; /* one for all the frames */
    for (uint64_t f = 0; rc == 0 && f < r->o.turntable && !tool_signal_caught(); f++)
        rc = turntable_frame(r, f, &gl, rgba, err);
    ip_renderer_destroy(gl);
    free(rgba);
    if (rc != 0)
        return err->code == IP_ERR_CANCELLED && tool_signal_caught() ? 1
                                                                     : tool_fail("isorender", err);
    if (tool_signal_caught())
        return 1;
    if (!r->o.common.quiet)
        printf("%s: %llu frames in %s\n", r->o.file, (unsigned long long)r->o.turntable, r->o.out);
    if (r->o.mp4 && turntable_encode(r) != 0)
        return 1;
    tool_outputs_complete(&r->outputs);
    return 0;
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* isoview --script FILE: commands that drive the viewer for tests and demos, one a line;
 * blank lines and lines starting with '#' are ignored. Commands run in order, each at the
 * start of a frame, until a wait:
 *
 *     camera ex,ey,ez,tx,ty,tz,ux,uy,uz,fov   set the camera (physical units, degrees)
 *     view NAME                               anterior .. inferior, +x .. -z, as --view
 *     iso V                                   set the isovalue (in the file's units)
 *     iso-stored V                            set the isovalue as a stored sample value
 *     orbit DX_DEGREES DY_DEGREES             orbit around the target, as a mouse drag does
 *     drag DX DY SECONDS                      orbit by DX, DY degrees smoothly over SECONDS,
 *                                             frame by frame, as a mouse drag does (waits)
 *     zoom FACTOR                             move toward the target: distance / FACTOR
 *     wait SECONDS                            let frames run for that long
 *     wait done                               until every ray has been cast (or the full
 *                                             extraction is shown)
 *     full                                    full extraction, as the key f
 *     overlay compact|detailed|off|on         the heads-up text (on: compact)
 *     pause on|off                            pause or resume refinement, as the key p
 *     help on|off                             show or hide the help, as the key h
 *     screenshot PATH                         save the next frame as PNG
 *     quit                                    exit (status 0)
 *
 * docs/isoview.md documents the script format.
 */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "isoprop/output.h"
#include "isoview.h"

void free_commands(viewer *v)
{
    for (size_t i = 0; i < v->command_count; i++)
        free(v->commands[i].text);
    free(v->commands);
    v->commands = NULL;
    v->command_count = 0;
}

char *copy_text(const char *text)
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
    char *arg3 = arg2 ? strtok_r(NULL, " \t", &save) : NULL;
    char *extra = strtok_r(NULL, " \t", &save);
    int args = !!arg1 + !!arg2 + !!arg3;
    memset(c, 0, sizeof *c);
    if (extra)
        goto too_many;
    if (!strcmp(word, "camera")) {
        ip_camera probe; /* checked now, applied when the command runs */
        if (args != 1)
            goto arguments;
        if (camera_from(v, arg1, NULL, &probe, err) != 0)
            return -1;
        c->kind = COMMAND_CAMERA;
    } else if (!strcmp(word, "view")) {
        ip_camera probe;
        if (args != 1)
            goto arguments;
        if (camera_from(v, NULL, arg1, &probe, err) != 0)
            return -1;
        c->kind = COMMAND_VIEW;
    } else if (!strcmp(word, "iso") || !strcmp(word, "iso-stored")) {
        if (args != 1 || tool_parse_double(arg1, &c->a) != 0)
            goto arguments;
        c->kind = word[3] ? COMMAND_ISO_STORED : COMMAND_ISO;
    } else if (!strcmp(word, "orbit")) {
        if (args != 2 || tool_parse_double(arg1, &c->a) != 0 || tool_parse_double(arg2, &c->b))
            goto arguments;
        c->kind = COMMAND_ORBIT;
    } else if (!strcmp(word, "drag")) {
        if (args != 3 || tool_parse_double(arg1, &c->a) != 0 || tool_parse_double(arg2, &c->b) ||
            tool_parse_double(arg3, &c->c) || !(c->c > 0))
            goto arguments;
        c->kind = COMMAND_DRAG;
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
        if (args != 1)
            goto arguments;
        c->kind = COMMAND_OVERLAY;
        if (!strcmp(arg1, "off"))
            c->a = OVERLAY_OFF;
        else if (!strcmp(arg1, "on") || !strcmp(arg1, "compact"))
            c->a = OVERLAY_COMPACT;
        else if (!strcmp(arg1, "detailed"))
            c->a = OVERLAY_DETAILED;
        else
            goto arguments;
    } else if (!strcmp(word, "clip")) {
        if (args != 1 || (strcmp(arg1, "on") && strcmp(arg1, "off")))
            goto arguments;
        c->kind = COMMAND_CLIP;
        c->a = !strcmp(arg1, "on");
    } else if (!strcmp(word, "pause") || !strcmp(word, "help")) {
        if (args != 1 || (strcmp(arg1, "on") && strcmp(arg1, "off")))
            goto arguments;
        c->kind = word[0] == 'p' ? COMMAND_PAUSE : COMMAND_HELP;
        c->a = !strcmp(arg1, "on");
    } else if (!strcmp(word, "screenshot")) {
        if (args != 1)
            goto arguments;
        if (!tool_is_png_name(arg1)) {
            set_error(err, IP_ERR_ARGUMENT,
                      "screenshot %s: images are written as PNG: name it .png", arg1);
            return -1;
        }
        if (ip_output_check(arg1, v->o.common.force, err) != IP_OK)
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

int load_script(viewer *v, ip_error *err)
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

void run_script(viewer *v, double t)
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
        case COMMAND_ISO: change_iso(v, c->a); break;
        case COMMAND_ISO_STORED: change_iso_stored(v, c->a); break;
        case COMMAND_ORBIT:
            tool_space_orbit(&v->space, &v->camera, c->a, c->b);
            change_view(v);
            break;
        case COMMAND_DRAG:
            v->drag_rate[0] = c->a / c->c;
            v->drag_rate[1] = c->b / c->c;
            v->drag_last = t;
            v->drag_end = t + c->c;
            v->wait_until = t + c->c;
            break;
        case COMMAND_ZOOM:
            zoom_view(v, c->a);
            change_view(v);
            break;
        case COMMAND_WAIT: v->wait_until = t + c->a; break;
        case COMMAND_WAIT_DONE: v->waiting_done = 1; break;
        case COMMAND_FULL: v->want_full = 1; break;
        case COMMAND_OVERLAY: v->overlay_mode = (overlay_mode)c->a; break;
        case COMMAND_PAUSE: v->paused = c->a != 0; break;
        case COMMAND_HELP: v->help_on = c->a != 0; break;
        case COMMAND_CLIP: set_clip(v, c->a != 0); break;
        case COMMAND_SCREENSHOT: request_screenshot(v, c->text); return;
        case COMMAND_QUIT: v->quit = 1; return;
        }
    }
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* The outputs of one run, as a set: all of them or none. */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "tool_common.h"

int tool_outputs_add(tool_outputs *o, const char *path)
{
    if (tool_is_stdout(path))
        return 0;
    if (o->count == o->capacity) {
        size_t capacity = o->capacity ? 2 * o->capacity : 8;
        char **paths = realloc(o->paths, capacity * sizeof *paths);
        if (!paths) {
            unlink(path);
            return -1;
        }
        o->paths = paths;
        o->capacity = capacity;
    }
    char *copy = strdup(path);
    if (!copy) {
        unlink(path);
        return -1;
    }
    o->paths[o->count++] = copy;
    return 0;
}

int tool_outputs_add_or_error(tool_outputs *o, const char *path, ip_error *err)
{
    if (tool_outputs_add(o, path) == 0)
        return 0;
    err->code = IP_ERR_NOMEM;
    snprintf(err->message, sizeof err->message, "%.900s: out of memory", path);
    return -1;
}

int tool_outputs_made_folder(tool_outputs *o, const char *path)
{
    free(o->folder);
    o->folder = strdup(path);
    return o->folder ? 0 : -1;
}

void tool_outputs_complete(tool_outputs *o)
{
    o->complete = 1;
}

size_t tool_outputs_discard(tool_outputs *o)
{
    size_t removed = 0;
    while (o->count > 0) {
        char *path = o->paths[--o->count];
        removed += unlink(path) == 0;
        free(path);
    }
    if (o->folder)
        (void)rmdir(o->folder); /* only when empty: a folder that held other files stays */
    o->complete = 0;
    return removed;
}

static void outputs_free(tool_outputs *o)
{
    for (size_t i = 0; i < o->count; i++)
        free(o->paths[i]);
    free(o->paths);
    free(o->folder);
    memset(o, 0, sizeof *o);
}

int tool_outputs_end(tool_outputs *o, const char *program, const char *what, int rc)
{
    int sig = tool_signal_caught();
    int complete = o->complete;
    if (rc != 0 || (sig && !complete))
        tool_outputs_discard(o);
    outputs_free(o);
    if (!sig)
        return rc;
    if (rc == 0 && complete) {
        fprintf(stderr, "%s: every output was written before %s; ending normally\n", program,
                sig == SIGINT ? "SIGINT" : "SIGTERM");
        tool_signals_forget();
        return rc;
    }
    if (what)
        fprintf(stderr, "%s: %s: cancelled; no output written\n", program, what);
    tool_signals_reraise();
    return rc;
}

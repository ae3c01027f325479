/* SPDX-License-Identifier: BSD-3-Clause */
/* The programs' files: checked before any work; text outputs written all-or-nothing. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "isoprop/output.h"
#include "tool_common.h"

/* An input must be there and be a regular file: a FIFO would block the open or the reads,
 * a device would never end. stat() does not open, so it never blocks. */
static int check_input(const char *program, const char *path)
{
    struct stat st;
    if (stat(path, &st) != 0) {
        fprintf(stderr, "%s: %s: cannot open: %s\n", program, path, strerror(errno));
        return 1;
    }
    if (S_ISDIR(st.st_mode)) {
        fprintf(stderr, "%s: %s: is a directory, not a file\n", program, path);
        return 1;
    }
    if (!S_ISREG(st.st_mode)) {
        fprintf(stderr, "%s: %s: not a regular file (%s)\n", program, path,
                S_ISFIFO(st.st_mode)   ? "a FIFO"
                : S_ISCHR(st.st_mode)  ? "a character device"
                : S_ISBLK(st.st_mode)  ? "a block device"
                : S_ISSOCK(st.st_mode) ? "a socket"
                                       : "not a plain file");
        return 1;
    }
    return 0;
}

/* The folder an output goes into must be there and writable, so that a run with several
 * outputs does not write the first ones and then fail on a later one. */
static int check_output_folder(const char *program, const char *path)
{
    char folder[4096];
    const char *slash = strrchr(path, '/');
    if (!slash)
        snprintf(folder, sizeof folder, ".");
    else if (slash == path)
        snprintf(folder, sizeof folder, "/");
    else
        snprintf(folder, sizeof folder, "%.*s", (int)(slash - path), path);
    struct stat st;
    if (stat(folder, &st) != 0 || !S_ISDIR(st.st_mode) || access(folder, W_OK | X_OK) != 0) {
        int e = errno;
        fprintf(stderr, "%s: %s: cannot write in folder %s: %s\n", program, path, folder,
                stat(folder, &st) == 0 && !S_ISDIR(st.st_mode) ? "not a directory" : strerror(e));
        return 1;
    }
    return 0;
}

int tool_is_stdout(const char *path)
{
    return path && strcmp(path, "-") == 0;
}

/* At most one output may be standard output ("-"): two would run together there. */
static int check_stdout_outputs(const char *program, const char *const *outputs, size_t count)
{
    size_t named = 0;
    for (size_t o = 0; o < count; o++)
        named += tool_is_stdout(outputs[o]);
    if (named > 1) {
        fprintf(stderr, "%s: -: standard output named for %zu outputs; at most one may go there\n",
                program, named);
        return 1;
    }
    return 0;
}

int tool_check_paths(const char *program, const char *const *inputs, size_t input_count,
                     const char *const *outputs, size_t output_count, int force)
{
    ip_error err;
    for (size_t i = 0; i < input_count; i++)
        if (inputs[i] && check_input(program, inputs[i]) != 0)
            return 1;
    if (check_stdout_outputs(program, outputs, output_count) != 0)
        return 1;
    for (size_t o = 0; o < output_count; o++) {
        if (!outputs[o] || tool_is_stdout(outputs[o]))
            continue;
        for (size_t i = 0; i < input_count; i++)
            if (inputs[i] && ip_output_not_input(outputs[o], inputs[i], &err) != IP_OK)
                return tool_fail(program, &err);
        for (size_t k = 0; k < o; k++)
            if (outputs[k] && !tool_is_stdout(outputs[k]) &&
                ip_path_same_file(outputs[o], outputs[k])) {
                if (strcmp(outputs[o], outputs[k]) == 0)
                    fprintf(stderr,
                            "%s: %s: named for two outputs; each output needs a file "
                            "of its own\n",
                            program, outputs[o]);
                else
                    fprintf(stderr,
                            "%s: %s: is the same file as the output %s; each output "
                            "needs a file of its own\n",
                            program, outputs[o], outputs[k]);
                return 1;
            }
        if (ip_output_check(outputs[o], force, &err) != IP_OK)
            return tool_fail(program, &err);
        if (check_output_folder(program, outputs[o]) != 0)
            return 1;
    }
    return 0;
}

int tool_write_text_file(const char *program, const char *path, int force,
                         void (*fill)(FILE *out, void *user), void *user)
{
    char *text = NULL;
    size_t size = 0;
    FILE *out = open_memstream(&text, &size);
    if (!out) {
        fprintf(stderr, "%s: %s: out of memory\n", program, path);
        return -1;
    }
    fill(out, user);
    int failed = ferror(out);
    failed |= fclose(out) != 0;
    if (failed) {
        fprintf(stderr, "%s: %s: out of memory\n", program, path);
        free(text);
        return -1;
    }
    if (tool_is_stdout(path)) {
        failed = fwrite(text, 1, size, stdout) != size || fflush(stdout) != 0;
        free(text);
        if (failed)
            fprintf(stderr, "%s: standard output: %s\n", program, strerror(errno));
        return failed ? -1 : 0;
    }
    ip_error err;
    ip_status st = ip_output_write(path, text, size, force, &err);
    free(text);
    if (st != IP_OK) {
        tool_fail(program, &err);
        return -1;
    }
    return 0;
}

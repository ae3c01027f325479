/* SPDX-License-Identifier: BSD-3-Clause */
/* isogen: writes a synthetic test volume, or an upsampled copy of a volume, as a raw file. */
#include <inttypes.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>
#include <unistd.h>

#include "isoprop/generate.h"
#include "isoprop/input.h"
#include "tool_common.h"

#define PROGRAM "isogen"
#define MAX_DIM ((uint64_t)1 << 31)

static const char usage_text[] =
    "usage: isogen FIELD [--dims XxYxZ] [--type uint8|uint16|int16|float32] [--noise SIGMA]\n"
    "                    [--seed N] [-o OUT] [--force] [--quiet]\n"
    "       isogen --upsample K INPUT [--dims XxYxZ] [--type T] [--endian big|little]\n"
    "                    [-o OUT] [--force] [--quiet]\n"
    "\n"
    "Writes a little-endian raw volume named NAME_XxYxZ_TYPE.raw.\n"
    "\n"
    "  FIELD            shepp-logan, sphere, gyroid or marschner-lobb\n"
    "  --dims XxYxZ     samples along x, y, z, each >= 2 (default 128x128x128); with\n"
    "                   --upsample, the input's dims when its name and header lack them\n"
    "  --type T         sample type (default uint16); with --upsample, the input's type\n"
    "  --noise SIGMA    Gaussian noise, standard deviation in [0,1] field units (default 0)\n"
    "  --seed N         noise seed (default 1)\n"
    "  --upsample K     enlarge INPUT (raw NAME_XxYxZ_TYPE.raw, .nrrd, .nhdr or .mhd) K times\n"
    "                   along each axis by trilinear interpolation\n"
    "  --endian E       byte order of a raw INPUT (default little)\n"
    "  -o OUT           output file, or a folder (existing, or ending in '/') to write the\n"
    "                   conventionally named file into (default: that name, here);\n"
    "                   '-': the samples on standard output, in z order, for a pipe\n"
    "                   (isobrick - ...), never a terminal; the summary goes to stderr\n"
    "  --force          replace an existing output (a regular file; never the input)\n"
    "  --quiet          print nothing on success\n"
    "  --version        print the version and exit\n"
    "\n"
    "Prints the path written on stdout and a one-line summary on stderr.\n"
    "Exit status: 0 success, 1 failure, 2 bad command line.\n";

typedef struct options {
    const char *positional; /* FIELD, or INPUT with --upsample */
    uint32_t factor;        /* 0 unless --upsample */
    int has_dims;
    uint32_t dims[3];
    int has_type;
    ip_type type;
    int has_endian;
    int big_endian;
    int has_noise;
    double noise;
    int has_seed;
    uint64_t seed;
    const char *output;
    int force;
    int quiet;
} options;

/* Applies the value of a recognised option; returns 0, or 2 after a usage error. */
static int apply_value(options *o, const char *name, const char *value)
{
    uint64_t u;
    if (strcmp(name, "--dims") == 0) {
        if (tool_parse_dims(PROGRAM, "--dims", value, o->dims) != 0)
            return 2;
        o->has_dims = 1;
    } else if (strcmp(name, "--type") == 0) {
        if (ip_type_parse(value, &o->type) != IP_OK)
            return tool_usage_error(PROGRAM, "--type: unknown type '%s'", value);
        o->has_type = 1;
    } else if (strcmp(name, "--endian") == 0) {
        if (strcmp(value, "big") != 0 && strcmp(value, "little") != 0)
            return tool_usage_error(PROGRAM, "--endian: '%s' is not big or little", value);
        o->big_endian = strcmp(value, "big") == 0;
        o->has_endian = 1;
    } else if (strcmp(name, "--noise") == 0) {
        if (tool_parse_double(value, &o->noise) != 0 || o->noise < 0.0)
            return tool_usage_error(PROGRAM, "--noise: '%s' is not a number >= 0", value);
        o->has_noise = 1;
    } else if (strcmp(name, "--seed") == 0) {
        if (tool_parse_u64(value, &o->seed) != 0)
            return tool_usage_error(PROGRAM, "--seed: '%s' is not a non-negative integer", value);
        o->has_seed = 1;
    } else if (strcmp(name, "--upsample") == 0) {
        if (tool_parse_u64(value, &u) != 0 || u < 1 || u >= MAX_DIM)
            return tool_usage_error(PROGRAM, "--upsample: '%s' is not an integer >= 1", value);
        o->factor = (uint32_t)u;
    } else {
        o->output = value;
    }
    return 0;
}

static int parse_value(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    (void)p;
    return apply_value(base, opt->name, v[0]);
}

static const tool_option isogen_options[] = {
    {"--dims", NULL, 1, 0, parse_value, NULL, NULL},
    {"--type", NULL, 1, 0, parse_value, NULL, NULL},
    {"--endian", NULL, 1, 0, parse_value, NULL, NULL},
    {"--noise", NULL, 1, 0, parse_value, NULL, NULL},
    {"--seed", NULL, 1, 0, parse_value, NULL, NULL},
    {"--upsample", NULL, 1, 0, parse_value, NULL, NULL},
    {"-o", NULL, 1, 0, parse_value, NULL, NULL},
    {"--force", "-f", 0, offsetof(options, force), NULL, NULL, NULL},
    {"--quiet", "-q", 0, offsetof(options, quiet), NULL, NULL, NULL},
};

/* Checks that the options fit the mode; returns 0 or 2 after a usage error. */
static int check_mode(const options *o, ip_field *field)
{
    if (o->factor) {
        if (!o->positional)
            return tool_usage_error(PROGRAM, "--upsample needs an INPUT file");
        if (o->has_noise || o->has_seed)
            return tool_usage_error(PROGRAM, "--noise and --seed do not apply to --upsample");
        return 0;
    }
    if (!o->positional)
        return tool_usage_error(PROGRAM, "missing FIELD (shepp-logan, sphere, gyroid or "
                                         "marschner-lobb)");
    if (ip_field_parse(o->positional, field) != IP_OK)
        return tool_usage_error(PROGRAM,
                                "unknown field '%s' (shepp-logan, sphere, gyroid or "
                                "marschner-lobb)",
                                o->positional);
    if (o->has_endian)
        return tool_usage_error(PROGRAM, "--endian applies only to --upsample");
    if (o->has_dims && (o->dims[0] < 2 || o->dims[1] < 2 || o->dims[2] < 2))
        return tool_usage_error(PROGRAM, "--dims: each dimension must be at least 2");
    return 0;
}

/* The output path: OUT, OUT/NAME when OUT is a folder, or NAME. Returns 0, or 1 after an error. */
static int output_path(const char *out, const char *name, char *path, size_t size)
{
    struct stat st;
    int n;
    if (!out)
        n = snprintf(path, size, "%s", name);
    else if (out[0] && out[strlen(out) - 1] == '/')
        n = snprintf(path, size, "%s%s", out, name);
    else if (stat(out, &st) == 0 && S_ISDIR(st.st_mode))
        n = snprintf(path, size, "%s/%s", out, name);
    else
        n = snprintf(path, size, "%s", out);
    if (n < 0 || (size_t)n >= size) {
        fprintf(stderr, "%s: output path too long\n", PROGRAM);
        return 1;
    }
    return 0;
}

/* The NAME of NAME_XxYxZ_TYPE.ext (or of NAME.ext) for the file at `path`. */
static void input_name(const char *path, char *name, size_t size)
{
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    snprintf(name, size, "%s", base);
    char *dot = strrchr(name, '.');
    if (dot && dot != name && strcmp(dot, ".gz") == 0) {
        *dot = '\0';
        dot = strrchr(name, '.');
    }
    if (dot && dot != name)
        *dot = '\0';
    for (char *p = name + strlen(name); p > name; p--) {
        if (*p != '_')
            continue;
        uint32_t dims[3];
        ip_type type;
        char *sep = strchr(p + 1, '_');
        if (!sep)
            continue;
        *sep = '\0';
        int match = ip_dims_parse(p + 1, dims) == IP_OK && ip_type_parse(sep + 1, &type) == IP_OK;
        *sep = '_';
        if (match) {
            *p = '\0';
            break;
        }
    }
    if (!name[0])
        snprintf(name, size, "volume");
}

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static void report(const options *o, const char *path, const uint32_t dims[3], ip_type type,
                   double seconds)
{
    char human[32];
    double bytes = (double)dims[0] * dims[1] * dims[2] * (double)ip_type_size(type);
    if (o->quiet)
        return;
    if (!tool_is_stdout(o->output)) { /* with -o - stdout holds the samples */
        printf("%s\n", path);
        fflush(stdout);
    }
    fprintf(stderr, "%s: wrote %.0f bytes (%s) in %.2f s, %.1f MB/s\n", PROGRAM, bytes,
            tool_format_bytes(human, sizeof human, bytes), seconds,
            seconds > 0.0 ? bytes / seconds / 1e6 : 0.0);
}

/* -o -: standard output, which must not be a terminal. Returns 1 (stdout), 0 (a file), or -1
 * after the error. */
static int to_stdout(const options *o)
{
    if (!tool_is_stdout(o->output))
        return 0;
    if (isatty(STDOUT_FILENO)) {
        fprintf(stderr,
                "%s: -o -: standard output is a terminal; pipe it (isobrick - ...) or "
                "redirect it\n",
                PROGRAM);
        return -1;
    }
    return 1;
}

static int run_generate(const options *o, ip_field field)
{
    ip_gen_params params = {sizeof(ip_gen_params), field, {128, 128, 128}, IP_UINT16, 0.0, 1};
    char name[IP_PATH_MAX], path[IP_PATH_MAX];
    ip_error err;
    if (o->has_dims)
        memcpy(params.dims, o->dims, sizeof params.dims);
    if (o->has_type)
        params.type = o->type;
    if (o->has_noise)
        params.noise = o->noise;
    if (o->has_seed)
        params.seed = o->seed;
    int piped = to_stdout(o);
    if (piped < 0 ||
        ip_raw_file_name(name, sizeof name, ip_field_name(field), params.dims, params.type) !=
            IP_OK ||
        output_path(piped ? NULL : o->output, name, path, sizeof path) != 0)
        return 1;
    const char *outputs[] = {path};
    if (!piped && tool_check_paths(PROGRAM, NULL, 0, outputs, 1, o->force) != 0)
        return 1;
    double start = now_seconds();
    if ((piped ? ip_generate_write_fd(&params, STDOUT_FILENO, "stdout", &err)
               : ip_generate_write(&params, path, o->force, &err)) != IP_OK)
        return tool_fail(PROGRAM, &err);
    report(o, path, params.dims, params.type, now_seconds() - start);
    return 0;
}

static int run_upsample(const options *o)
{
    ip_input_overrides overrides;
    ip_input_desc desc;
    ip_error err;
    char base[IP_PATH_MAX], name[IP_PATH_MAX + 32], file[IP_PATH_MAX], path[IP_PATH_MAX];
    uint32_t dims[3];
    memset(&overrides, 0, sizeof overrides);
    overrides.has_dims = o->has_dims;
    memcpy(overrides.dims, o->dims, sizeof overrides.dims);
    overrides.has_type = o->has_type;
    overrides.type = o->type;
    overrides.has_endian = o->has_endian;
    overrides.big_endian = o->big_endian;
    if (ip_input_describe(o->positional, &overrides, &desc, &err) != IP_OK)
        return tool_fail(PROGRAM, &err);
    for (int axis = 0; axis < 3; axis++) {
        if ((uint64_t)desc.dims[axis] * o->factor >= MAX_DIM) {
            fprintf(stderr, "%s: %s: %" PRIu32 " samples x %" PRIu32 " is too many along an axis\n",
                    PROGRAM, o->positional, desc.dims[axis], o->factor);
            return 1;
        }
        dims[axis] = desc.dims[axis] * o->factor;
    }
    input_name(desc.path, base, sizeof base);
    snprintf(name, sizeof name, "%s_x%" PRIu32, base, o->factor);
    if (ip_raw_file_name(file, sizeof file, name, dims, desc.type) != IP_OK) {
        fprintf(stderr, "%s: output name too long\n", PROGRAM);
        return 1;
    }
    int piped = to_stdout(o);
    if (piped < 0 || output_path(piped ? NULL : o->output, file, path, sizeof path) != 0)
        return 1;
    const char *inputs[] = {desc.path, desc.data_path}, *outputs[] = {path};
    if (!piped && tool_check_paths(PROGRAM, inputs, 2, outputs, 1, o->force) != 0)
        return 1;
    double start = now_seconds();
    if ((piped ? ip_upsample_write_fd(&desc, o->factor, STDOUT_FILENO, "stdout", &err)
               : ip_upsample_write(&desc, o->factor, path, o->force, &err)) != IP_OK)
        return tool_fail(PROGRAM, &err);
    report(o, path, dims, desc.type, now_seconds() - start);
    return 0;
}

int main(int argc, char **argv)
{
    options o;
    ip_field field = IP_FIELD_SHEPP_LOGAN;
    memset(&o, 0, sizeof o);
    tool_option_table table = {isogen_options, sizeof isogen_options / sizeof isogen_options[0],
                               &o};
    tool_command_line c = {PROGRAM, usage_text, &table, 1, &o.positional, "argument"};
    if (tool_parse_command_line(&c, argc, argv) != 0)
        return 2;
    int rc = check_mode(&o, &field);
    if (rc != 0)
        return rc;
    return o.factor ? run_upsample(&o) : run_generate(&o, field);
}

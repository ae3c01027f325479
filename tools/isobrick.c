/* SPDX-License-Identifier: BSD-3-Clause */
/* isobrick: brick a volume (raw, NRRD, MetaImage, TIFF, NIfTI, HDF5, DICOM, or raw samples from
 * standard input) into a brick file (.ibv), once. */
#include <errno.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "isoprop/bricker.h"
#include "isoprop/input.h"
#include "tool_common.h"

static const char usage[] =
    "usage: isobrick INPUT [-o OUT.ibv] [options]\n"
    "       isobrick - --dims XxYxZ --type T -o OUT.ibv [options]\n"
    "Bricks INPUT (NAME_XxYxZ_TYPE.raw, any raw file with --dims/--type, .nrrd, .nhdr, .mhd,\n"
    ".tif, .nii, .h5, a folder holding a DICOM series, a Zarr array or an OME-Zarr image)\n"
    "into an LZ4-compressed brick file with min/max summaries and a level-of-detail\n"
    "pyramid. '-' reads raw samples from standard input in z order (x fastest), e.g.\n"
    "isogen ... -o - | isobrick - ...: a pipe that ends early or runs past the dims is\n"
    "refused (docs/input.md).\n"
    "  -o OUT.ibv          output (default: bricks/STEM.ibv, the input's name without its\n"
    "                      extension: ch2.nii.gz gives bricks/ch2.ibv)\n"
    "  --dims XxYxZ        samples along x, y, z (raw input)\n"
    "  --type T            uint8, uint16, int16 or float32 (raw input)\n"
    "  --endian E          little (default) or big\n"
    "  --spacing X,Y,Z     world units between samples (default 1,1,1)\n"
    "  --rescale S,I[,UNIT]\n"
    "                      the values stand for stored x S + I, in UNIT (e.g. 1,-1024,HU),\n"
    "                      instead of what the input says; none: no rescale. Kept in the\n"
    "                      brick file: isovalues are then given in UNIT (docs/input.md)\n"
    "  --dataset PATH      the 3-D dataset of an HDF5 file to read (/group/name); needed\n"
    "                      when the file holds several (the refusal lists them)\n"
    "A DICOM folder (docs/dicom.md) is read with its subfolders; objects that are not images\n"
    "(a DICOMDIR under any name, reports, presentation states) are skipped and counted.\n"
    "  --list-series       list the folder's series (UID, description, modality, slices,\n"
    "                      size, spacing) and exit; nothing is written\n"
    "  --series UID        the series to read (a UID, or a prefix of one only); needed when\n"
    "                      the folder holds several\n"
    "  --correct-tilt      resample slices sheared by a gantry tilt onto a regular grid along\n"
    "                      their normal (the default; the summary says so)\n"
    "  --no-correct-tilt   refuse a tilted series instead\n"
    "  --even-spacing      resample unevenly spaced slices (a slice missing included) onto an\n"
    "                      even grid of the smallest step (default: refused)\n"
    "A Zarr v2/v3 array or OME-Zarr image (0.4, 0.5) is a folder (docs/input.md, \"Zarr\").\n"
    "  --scale K           OME-Zarr: the scale to read (default 0, the finest)\n"
    "  --time T            OME-Zarr: the time point to read (needed when t is over 1)\n"
    "  --channel C         OME-Zarr: the channel to read (needed when c is over 1)\n"
    "  --brick-size B      cells per brick edge, a power of two (default 32)\n"
    "  --subblock-size S   cells per sub-block edge, a power of two <= B (default 8)\n"
    "  --hc [LEVEL]        LZ4 high compression (level 1-12, default 9) instead of fast\n"
    "  --threads N         compression threads (default: all cores)\n"
    "  --mem-mb N          cap on working memory in MiB (default: none)\n"
    "  --force             replace OUT if it exists (a regular file; never the input)\n"
    "  -q, --quiet         no progress bar and no summary\n"
    "  -v, --verbose       details on stderr: the input and the plan first, a line for each\n"
    "                      chunk of planes as it is read and encoded, then the phases' times,\n"
    "                      each level's bricks as written (encodings, bytes, filters) and the\n"
    "                      filter choices over all levels (not with --quiet)\n"
    "  --version           print the version and exit\n"
    "A progress bar (planes read and encoded) is drawn on stderr when it is a terminal\n"
    "(ISOBRICK_PROGRESS=1 forces it).\n"
    "Exit status: 0 success, 1 failure, 2 bad command line.\n"
    "Ctrl-C cancels cleanly: no output is left, and isobrick ends as killed by the signal.\n";

/* The bar and, with --verbose, a line for each chunk of planes: the library reports the
 * input bytes read and encoded so far after each chunk. */
typedef struct progress_state {
    tool_progress bar;
    int verbose;
    uint64_t plane_bytes, planes; /* of the input (level 0) */
    uint64_t planes_done;
} progress_state;

static int report_progress(void *user, uint64_t done, uint64_t total)
{
    progress_state *p = user;
    uint64_t planes = p->plane_bytes ? done / p->plane_bytes : 0;
    double elapsed = tool_progress_elapsed(&p->bar);
    char detail[48];
    snprintf(detail, sizeof detail, "%.1f MB/s", elapsed > 0 ? (double)done / elapsed / 1e6 : 0.0);
    tool_progress_draw(&p->bar, planes, p->planes, "planes", detail);
    if (p->verbose) {
        char done_b[32], total_b[32];
        tool_progress_end(&p->bar);
        fprintf(stderr,
                "isobrick: chunk: planes %llu-%llu of %llu read and encoded (%s of %s), %.2f s\n",
                (unsigned long long)p->planes_done, (unsigned long long)(planes ? planes - 1 : 0),
                (unsigned long long)p->planes,
                tool_format_bytes(done_b, sizeof done_b, (double)done),
                tool_format_bytes(total_b, sizeof total_b, (double)total), elapsed);
    }
    p->planes_done = planes;
    return tool_signal_caught() != 0; /* SIGINT/SIGTERM: a clean cancel */
}

typedef struct options {
    const char *input, *output;
    ip_input_overrides overrides;
    int has_rescale;    /* --rescale given: `rescale` replaces the input's */
    ip_rescale rescale; /* not present for --rescale none */
    ip_bricker_options brick;
    int quiet, verbose;
    int list_series, correct_tilt, no_correct_tilt, even_spacing; /* DICOM folders */
} options;

/* "-": the samples come from standard input. */
static int is_stdin(const char *path)
{
    return strcmp(path, "-") == 0;
}

/* The values of isobrick's options (tool_option_parse: base is the options). */
static int parse_dims(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    options *o = base;
    (void)opt;
    if (tool_parse_dims(p, "--dims", v[0], o->overrides.dims) != 0)
        return 2;
    o->overrides.has_dims = 1;
    return 0;
}

static int parse_type(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    options *o = base;
    (void)opt;
    if (ip_type_parse(v[0], &o->overrides.type) != IP_OK)
        return tool_usage_error(p, "--type: unknown type '%s'", v[0]);
    o->overrides.has_type = 1;
    return 0;
}

static int parse_endian(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    options *o = base;
    (void)opt;
    if (strcmp(v[0], "big") && strcmp(v[0], "little"))
        return tool_usage_error(p, "--endian must be big or little");
    o->overrides.big_endian = !strcmp(v[0], "big");
    o->overrides.has_endian = 1;
    return 0;
}

static int parse_spacing(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    options *o = base;
    (void)opt;
    double *s = o->overrides.spacing;
    if (tool_parse_double3(v[0], s) != 0 || !(s[0] > 0 && s[1] > 0 && s[2] > 0))
        return tool_usage_error(p, "--spacing '%s' is not three positive numbers", v[0]);
    o->overrides.has_spacing = 1;
    return 0;
}

/* --rescale S,I[,UNIT] or none */
static int parse_rescale(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    options *o = base;
    (void)opt;
    char text[128], *unit = NULL;
    ip_error err;
    ip_rescale_identity(&o->rescale);
    o->has_rescale = 1;
    if (!strcmp(v[0], "none"))
        return 0;
    snprintf(text, sizeof text, "%s", v[0]);
    char *comma = strchr(text, ',');
    if (comma && (unit = strchr(comma + 1, ',')) != NULL)
        *unit++ = '\0';
    if (comma)
        *comma = '\0';
    o->rescale.present = 1;
    if (!comma || strlen(v[0]) >= sizeof text || tool_parse_double(text, &o->rescale.slope) != 0 ||
        tool_parse_double(comma + 1, &o->rescale.intercept) != 0)
        return tool_usage_error(p, "--rescale '%s' is not SLOPE,INTERCEPT[,UNIT] or none", v[0]);
    if (unit && strlen(unit) >= sizeof o->rescale.unit)
        return tool_usage_error(p, "--rescale '%s': the unit is longer than %d characters", v[0],
                                IP_RESCALE_UNIT_MAX - 1);
    snprintf(o->rescale.unit, sizeof o->rescale.unit, "%s", unit ? unit : "");
    if (ip_rescale_check(&o->rescale, "--rescale", &err) != IP_OK)
        return tool_usage_error(p, "%s", err.message);
    return 0;
}

/* --brick-size and --subblock-size, into the uint32_t at the option's offset: a power of two
 * up to IP_MAX_BRICK_EDGE (a brick edge at least 2); that the sub-block fits the brick is
 * checked once both are known */
static int parse_edge(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    uint64_t n;
    uint64_t least = strcmp(opt->name, "--brick-size") == 0 ? 2 : 1;
    if (tool_parse_u64(v[0], &n) != 0 || n < least || n > IP_MAX_BRICK_EDGE || (n & (n - 1)))
        return tool_usage_error(p, "%s '%s' is not a power of two in [%llu, %u]", opt->name, v[0],
                                (unsigned long long)least, IP_MAX_BRICK_EDGE);
    *(uint32_t *)(void *)((char *)base + opt->offset) = (uint32_t)n;
    return 0;
}

/* --hc [LEVEL]: the next argument is the level when it is a whole number */
static int parse_hc(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    options *o = base;
    (void)opt;
    uint64_t n;
    o->brick.lz4_level = IP_LZ4_HC_DEFAULT;
    if (v[0] && tool_parse_u64(v[0], &n) == 0) {
        if (n < 1 || n > 12)
            return tool_usage_error(p, "--hc level must be 1-12");
        o->brick.lz4_level = (int)n;
    }
    return 0;
}

static int parse_threads(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    (void)opt;
    return tool_parse_threads(p, v[0], 256, &((options *)base)->brick.threads);
}

static int parse_mem_mb(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    uint64_t n;
    int rc = tool_parse_bounded(p, opt->name, v[0], 1, 1ull << 40, "a size in MiB", &n);
    if (rc == 0)
        ((options *)base)->brick.memory_limit = n << 20;
    return rc;
}

/* --scale, --time, --channel: an index of an OME-Zarr image, into the overrides. */
static int parse_ome_index(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    ip_input_overrides *o = &((options *)base)->overrides;
    uint64_t n;
    int rc = tool_parse_bounded(p, opt->name, v[0], 0, UINT32_MAX, "an index from 0", &n);
    if (rc != 0)
        return rc;
    int *has = opt->name[2] == 's'   ? &o->has_scale
               : opt->name[2] == 't' ? &o->has_time
                                     : &o->has_channel;
    uint32_t *value = opt->name[2] == 's'   ? &o->scale
                      : opt->name[2] == 't' ? &o->time
                                            : &o->channel;
    *has = 1;
    *value = (uint32_t)n;
    return 0;
}

static const tool_option isobrick_options[] = {
    {"-o", NULL, 1, offsetof(options, output), NULL, NULL, NULL},
    {"--dims", NULL, 1, 0, parse_dims, NULL, NULL},
    {"--type", NULL, 1, 0, parse_type, NULL, NULL},
    {"--endian", NULL, 1, 0, parse_endian, NULL, NULL},
    {"--spacing", NULL, 1, 0, parse_spacing, NULL, NULL},
    {"--rescale", NULL, 1, 0, parse_rescale, NULL, NULL},
    {"--brick-size", NULL, 1, offsetof(options, brick.brick_edge), parse_edge, NULL, NULL},
    {"--subblock-size", NULL, 1, offsetof(options, brick.subblock_edge), parse_edge, NULL, NULL},
    {"--hc", NULL, TOOL_OPTIONAL_VALUE, 0, parse_hc, NULL, tool_is_u64},
    {"--threads", NULL, 1, 0, parse_threads, NULL, NULL},
    {"--mem-mb", NULL, 1, 0, parse_mem_mb, NULL, NULL},
    {"--force", "-f", 0, offsetof(options, brick.force), NULL, NULL, NULL},
    {"--quiet", "-q", 0, offsetof(options, quiet), NULL, NULL, NULL},
    {"--verbose", "-v", 0, offsetof(options, verbose), NULL, NULL, NULL},
    {"--list-series", NULL, 0, offsetof(options, list_series), NULL, NULL, NULL},
    {"--series", NULL, 1, offsetof(options, overrides.series), NULL, NULL, NULL},
    {"--correct-tilt", NULL, 0, offsetof(options, correct_tilt), NULL, NULL, NULL},
    {"--no-correct-tilt", NULL, 0, offsetof(options, no_correct_tilt), NULL, NULL, NULL},
    {"--even-spacing", NULL, 0, offsetof(options, even_spacing), NULL, NULL, NULL},
    {"--dataset", NULL, 1, offsetof(options, overrides.dataset), NULL, NULL, NULL},
    {"--scale", NULL, 1, 0, parse_ome_index, NULL, NULL},
    {"--time", NULL, 1, 0, parse_ome_index, NULL, NULL},
    {"--channel", NULL, 1, 0, parse_ome_index, NULL, NULL},
};

static int parse_args(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    o->overrides = IP_SIZED(ip_input_overrides);
    ip_bricker_options_default(&o->brick);
    const tool_option_table table = {isobrick_options,
                                     sizeof isobrick_options / sizeof isobrick_options[0], o};
    const tool_command_line line = {"isobrick", usage, &table, 1, &o->input, "input"};
    int rc = tool_parse_command_line(&line, argc, argv);
    if (rc)
        return rc;
    if (!o->input)
        return tool_usage_error("isobrick", "no input file");
    if (is_stdin(o->input) && !o->output)
        return tool_usage_error("isobrick", "reading standard input ('-') needs -o OUT.ibv");
    if (o->quiet && o->verbose)
        return tool_usage_error("isobrick", "--quiet and --verbose: one or the other");
    if (o->correct_tilt && o->no_correct_tilt)
        return tool_usage_error("isobrick", "--correct-tilt and --no-correct-tilt: one or the "
                                            "other");
    o->overrides.tilt = o->no_correct_tilt ? IP_REGRID_REFUSE
                        : o->correct_tilt  ? IP_REGRID_RESAMPLE
                                           : IP_REGRID_DEFAULT;
    o->overrides.uneven = o->even_spacing ? IP_REGRID_RESAMPLE : IP_REGRID_DEFAULT;
    if (o->brick.subblock_edge > o->brick.brick_edge)
        return tool_usage_error("isobrick",
                                "the sub-block edge %u is larger than the brick edge %u",
                                o->brick.subblock_edge, o->brick.brick_edge);
    return 0;
}

/* bricks/NAME.ibv, NAME being the input's file name (or folder name: a DICOM series, trailing
 * slashes aside) without its extension. */
static int default_output(const char *input, char *out, size_t size)
{
    char name[IP_PATH_MAX];
    size_t end = strlen(input);
    while (end > 1 && input[end - 1] == '/')
        end--;
    snprintf(name, sizeof name, "%.*s", (int)end, input);
    const char *base = strrchr(name, '/');
    base = base ? base + 1 : name;
    /* the stem: without the extension, both parts of a compressed one (ch2.nii.gz: ch2) */
    const char *dot = strrchr(base, '.');
    size_t base_len = strlen(base);
    if (base_len > 7 && strcasecmp(base + base_len - 7, ".nii.gz") == 0)
        dot = base + base_len - 7;
    int len = dot && dot != base ? (int)(dot - base) : (int)base_len;
    if (mkdir("bricks", 0777) != 0 && errno != EEXIST)
        return -1;
    return snprintf(out, size, "bricks/%.*s.ibv", len, base) < (int)size ? 0 : -1;
}

/* How the input was read: "direct" (O_DIRECT, every byte), "buffered" (the page cache) or
 * "N% direct", then whether the reading overlapped the encoding. */
static const char *read_mode(const ip_bricker_report *r, char *text, size_t size)
{
    const char *overlap = r->read_overlap ? "overlapped" : "not overlapped";
    if (r->bytes_direct == 0)
        snprintf(text, size, "buffered, %s", overlap);
    else if (r->bytes_direct >= r->input_bytes)
        snprintf(text, size, "direct, %s", overlap);
    else
        snprintf(text, size, "%.0f%% direct, %s",
                 100.0 * (double)r->bytes_direct / (double)r->input_bytes, overlap);
    return text;
}

/* `text` on stdout with its control characters as '?' (DICOM values may hold any byte). */
static void print_shown(const char *text)
{
    for (const char *c = text; *c; c++)
        putchar((unsigned char)*c < 0x20 || *c == 0x7F ? '?' : *c);
}

/* A DICOM series' lines of the summary: which series, the objects skipped, the resampling. */
/* An OME-Zarr image's line of the summary: the scale, time point and channel read, and the
 * unit of the spacing and origin (the brick file keeps the numbers, not the unit). */
static void print_ome(const ip_input_desc *d)
{
    if (d->encoding != IP_ENCODING_ZARR || d->zarr_scales == 0)
        return;
    printf("  ome-zarr    scale %u of %u, time %u, channel %u; spacing %g,%g,%g and origin in %s\n",
           d->zarr_scale, d->zarr_scales, d->zarr_time, d->zarr_channel, d->spacing[0],
           d->spacing[1], d->spacing[2], d->space_unit[0] ? d->space_unit : "no named unit");
}

static void print_series(const ip_input_desc *d)
{
    if (d->encoding != IP_ENCODING_DICOM)
        return;
    printf("  series      ");
    print_shown(d->series_uid);
    printf(", %u slices", d->source_slices);
    if (d->series_count > 1)
        printf(" (one of the %u series in the folder)", d->series_count);
    printf("\n");
    if (d->skipped_objects)
        printf("  skipped     %u DICOM object%s that %s not images (by SOP class)\n",
               d->skipped_objects, d->skipped_objects == 1 ? "" : "s",
               d->skipped_objects == 1 ? "is" : "are");
    if (d->resampled & IP_RESAMPLED_TILT)
        printf("  resampled   gantry tilt of %.3g degrees: the sheared slices resampled onto a "
               "regular %ux%ux%u grid along their normal (interpolated samples; "
               "--no-correct-tilt refuses instead)\n",
               d->tilt_degrees, d->dims[0], d->dims[1], d->dims[2]);
    if (d->resampled & IP_RESAMPLED_UNEVEN)
        printf("  resampled   uneven slice spacing: %u slices resampled onto %u planes %g mm "
               "apart (interpolated samples)\n",
               d->source_slices, d->dims[2], d->spacing[2]);
}

/* --list-series: one line a series of the folder. Returns the exit status. */
static int list_series(const char *folder)
{
    ip_dicom_series_info *list = NULL;
    uint32_t count = 0, skipped = 0;
    ip_error err;
    if (ip_dicom_list_series(folder, &list, &count, &skipped, &err) != IP_OK)
        return tool_fail("isobrick", &err);
    print_shown(folder);
    printf(": %u series", count);
    if (skipped)
        printf(", %u DICOM object%s that %s not images skipped", skipped, skipped == 1 ? "" : "s",
               skipped == 1 ? "is" : "are");
    printf("\n");
    for (uint32_t i = 0; i < count; i++) {
        const ip_dicom_series_info *e = &list[i];
        print_shown(e->uid[0] ? e->uid : "(no UID)");
        printf("  \"");
        print_shown(e->description);
        printf("\"  ");
        print_shown(e->modality[0] ? e->modality : "-");
        printf("  %u slice%s", e->slices, e->slices == 1 ? "" : "s");
        if (e->dims[0]) /* 0: its files do not tell */
            printf("  %ux%ux%u %s  spacing %g,%g,%g mm", e->dims[0], e->dims[1], e->dims[2],
                   ip_type_name(e->type), e->spacing[0], e->spacing[1], e->spacing[2]);
        if (e->problem[0]) {
            printf("  not read as it is: ");
            print_shown(e->problem);
        } else if (e->resampled & IP_RESAMPLED_TILT) {
            printf("  gantry tilt %.3g degrees: resampled", e->tilt_degrees);
        }
        printf("\n");
    }
    free(list);
    return 0;
}

static void print_summary(const ip_bricker_report *r, const ip_input_desc *desc, const char *out)
{
    char in_b[32], file_b[32], rss_b[32], mode[64];
    printf("wrote %s\n", out);
    printf("  input       %s (%llu bytes)\n",
           tool_format_bytes(in_b, sizeof in_b, (double)r->input_bytes),
           (unsigned long long)r->input_bytes);
    print_series(desc);
    print_ome(desc);
    tool_print_rescale(stdout, desc);
    printf("  file        %s (%llu bytes)\n",
           tool_format_bytes(file_b, sizeof file_b, (double)r->file_bytes),
           (unsigned long long)r->file_bytes);
    printf("  ratio       %.2fx\n",
           r->file_bytes ? (double)r->input_bytes / (double)r->file_bytes : 0.0);
    printf("  bricks      %llu in %u levels: %llu constant, %llu compressed, %llu raw\n",
           (unsigned long long)r->bricks, r->levels, (unsigned long long)r->bricks_constant,
           (unsigned long long)r->bricks_compressed, (unsigned long long)r->bricks_raw);
    printf("  time        %.2f s, %.1f MB/s on %u threads\n", r->seconds,
           r->seconds > 0 ? (double)r->input_bytes / r->seconds / 1e6 : 0.0, r->threads);
    printf("  phases      read %.2f s (%s), encode %.2f s, write %.2f s\n", r->seconds_read,
           read_mode(r, mode, sizeof mode), r->seconds_encode, r->seconds_write);
    printf("  peak RSS    %s (working memory planned: %s)\n",
           tool_format_bytes(rss_b, sizeof rss_b, (double)r->peak_rss),
           tool_format_bytes(in_b, sizeof in_b, (double)r->memory_planned));
}

/* --verbose, before the run: what is read and how it will be bricked. */
static void print_plan(const ip_input_desc *desc, const ip_bricker_options *brick, const char *out)
{
    const char *space = ip_space_name(desc->orientation.space);
    fprintf(stderr, "isobrick: input: %s: %ux%ux%u %s, spacing %g,%g,%g%s%s\n", desc->path,
            desc->dims[0], desc->dims[1], desc->dims[2], ip_type_name(desc->type), desc->spacing[0],
            desc->spacing[1], desc->spacing[2], space[0] ? ", space " : "", space);
    uint64_t planned = 0;
    ip_error err;
    char b[32];
    if (ip_bricker_memory_needed(desc, brick, &planned, &err) == IP_OK)
        fprintf(stderr,
                "isobrick: plan: %s, brick size %u, sub-block size %u, LZ4 %s, %s of working "
                "memory\n",
                out, brick->brick_edge, brick->subblock_edge,
                brick->lz4_level == IP_LZ4_FAST ? "fast" : "high compression",
                tool_format_bytes(b, sizeof b, (double)planned));
}

/* The names of a brick's filter bits: "delta", "med+shuffle", "none". */
static const char *filter_name(unsigned filters, char *text, size_t size)
{
    static const struct {
        unsigned bit;
        const char *name;
    } names[] = {
        {IP_FILTER_DELTA, "delta"}, {IP_FILTER_MED, "med"}, {IP_FILTER_SHUFFLE, "shuffle"}};
    text[0] = 0;
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (filters & names[i].bit)
            snprintf(text + strlen(text), size - strlen(text), "%s%s", text[0] ? "+" : "",
                     names[i].name);
    if (!text[0])
        snprintf(text, size, "none");
    return text;
}

/* Ends a --verbose line with " NAME COUNT" for each combination of filters used (counts[] by
 * filter bits), each with its share of `total` when that is not 0; " -" when none is. */
static void print_filter_counts(const uint64_t counts[8], uint64_t total)
{
    int any = 0;
    for (unsigned f = 0; f < 8; f++)
        if (counts[f]) {
            char name[32];
            fprintf(stderr, " %s %llu", filter_name(f, name, sizeof name),
                    (unsigned long long)counts[f]);
            if (total)
                fprintf(stderr, " (%.1f%%)", 100.0 * (double)counts[f] / (double)total);
            any = 1;
        }
    fprintf(stderr, "%s\n", any ? "" : " -");
}

/* --verbose, after the run: each level's bricks as the file holds them (from its directory:
 * encodings, payload bytes, filters of the LZ4 bricks), then the filter choices over all
 * levels. Returns 0, or 1 when the new file cannot be read back. */
static int print_levels(const char *out)
{
    ip_store *store;
    ip_error err;
    if (ip_store_open(out, &store, &err) != IP_OK)
        return tool_fail("isobrick", &err);
    const ip_layout *l = ip_store_layout(store);
    uint64_t all_filters[8] = {0};
    for (uint32_t k = 0; k < l->level_count; k++) {
        const ip_level_layout *level = &l->levels[k];
        uint64_t count[3] = {0}, stored = 0, filters[8] = {0};
        for (uint64_t i = 0; i < level->brick_count; i++) {
            ip_brick_entry e;
            ip_store_brick_entry(store, level->first_brick + i, &e);
            count[e.encoding < 3 ? e.encoding : 0]++;
            stored += e.stored_size;
            if (e.encoding == IP_BRICK_LZ4)
                filters[e.filters & 7]++;
        }
        char b[32];
        fprintf(stderr,
                "isobrick: level %u: %ux%ux%u samples, %ux%ux%u = %llu brick%s: %llu constant, "
                "%llu LZ4, %llu raw; %s of payload; filters:",
                k, level->dims[0], level->dims[1], level->dims[2], level->bricks[0],
                level->bricks[1], level->bricks[2], (unsigned long long)level->brick_count,
                level->brick_count == 1 ? "" : "s", (unsigned long long)count[IP_BRICK_CONSTANT],
                (unsigned long long)count[IP_BRICK_LZ4], (unsigned long long)count[IP_BRICK_RAW],
                tool_format_bytes(b, sizeof b, (double)stored));
        print_filter_counts(filters, 0);
        for (unsigned f = 0; f < 8; f++)
            all_filters[f] += filters[f];
    }
    uint64_t lz4 = 0;
    for (unsigned f = 0; f < 8; f++)
        lz4 += all_filters[f];
    fprintf(stderr, "isobrick: filters chosen for %llu LZ4 bricks:", (unsigned long long)lz4);
    print_filter_counts(all_filters, lz4);
    ip_store_close(store);
    return 0;
}

/* `path`, or NULL for a folder (of TIFF or DICOM files), which the library has read file by
 * file, and for standard input ("-"): the checks of tool_check_paths() are for input files. */
static const char *input_file(const char *path)
{
    struct stat st;
    if (is_stdin(path))
        return NULL; /* the library checks the output against what standard input reads */
    return stat(path, &st) == 0 && S_ISDIR(st.st_mode) ? NULL : path;
}

int main(int argc, char **argv)
{
    options o;
    int rc = parse_args(argc, argv, &o);
    if (rc)
        return rc;
    ip_error err;
    ip_error_clear(&err);
    if (o.list_series)
        return list_series(o.input);
    ip_input_desc desc;
    if (ip_input_describe(o.input, &o.overrides, &desc, &err) != IP_OK)
        return tool_fail("isobrick", &err);
    if (o.has_rescale) { /* --rescale wins over the input's */
        desc.has_rescale = o.rescale.present;
        desc.rescale_slope = o.rescale.slope;
        desc.rescale_intercept = o.rescale.intercept;
        memcpy(desc.rescale_unit, o.rescale.unit, sizeof desc.rescale_unit);
    }
    char out[IP_PATH_MAX];
    if (o.output)
        snprintf(out, sizeof out, "%s", o.output);
    else if (default_output(o.input, out, sizeof out) != 0) {
        fprintf(stderr, "isobrick: cannot create the folder bricks/ for the output\n");
        return 1;
    }
    /* the input, its detached data file (NRRD, MetaImage) and the output, before any work */
    const char *inputs[] = {input_file(desc.path), input_file(desc.data_path)};
    const char *outputs[] = {out};
    if (tool_check_paths("isobrick", inputs, 2, outputs, 1, o.brick.force) != 0)
        return 1;
    tool_signals_catch();
    if (o.verbose)
        print_plan(&desc, &o.brick, out);
    progress_state progress;
    memset(&progress, 0, sizeof progress);
    tool_progress_start(&progress.bar, !o.quiet, "ISOBRICK_PROGRESS");
    progress.verbose = o.verbose;
    progress.plane_bytes = (uint64_t)desc.dims[0] * desc.dims[1] * ip_type_size(desc.type);
    progress.planes = desc.dims[2];
    o.brick.progress = report_progress;
    o.brick.progress_user = &progress;
    ip_bricker_report report;
    tool_outputs written = {0}; /* the brick file, once written: the rule of every program */
    if (ip_bricker_run(&desc, out, &o.brick, &report, &err) != IP_OK) {
        tool_progress_end(&progress.bar);
        /* cancelled by a signal: tool_outputs_end() says so, and ends as killed by it */
        rc = err.code == IP_ERR_CANCELLED && tool_signal_caught() ? 1 : tool_fail("isobrick", &err);
        return tool_outputs_end(&written, "isobrick", out, rc);
    }
    tool_progress_end(&progress.bar);
    if (tool_outputs_add(&written, out) != 0) {
        fprintf(stderr, "isobrick: %s: out of memory\n", out);
        return tool_outputs_end(&written, "isobrick", out, 1);
    }
    tool_outputs_complete(&written);
    if (o.verbose) {
        char mode[64];
        fprintf(stderr, "isobrick: phases: read %.2f s (%s), encode %.2f s, write %.2f s\n",
                report.seconds_read, read_mode(&report, mode, sizeof mode), report.seconds_encode,
                report.seconds_write);
        if (print_levels(out) != 0)
            return tool_outputs_end(&written, "isobrick", out, 1);
    }
    if (!o.quiet)
        print_summary(&report, &desc, out);
    return tool_outputs_end(&written, "isobrick", out, 0);
}

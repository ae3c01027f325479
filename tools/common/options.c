/* SPDX-License-Identifier: BSD-3-Clause */
/* The shared options: parsers for option tables; isorender's and isoview's view options. */
#include <ctype.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "isoprop/engine.h"
#include "tool_common.h"

void tool_view_options_default(tool_view_options *o, uint32_t width, uint32_t height)
{
    memset(o, 0, sizeof *o);
    o->width = width;
    o->height = height;
    o->cutoff = IP_DEFAULT_CUTOFF_DEGREES;
    o->foldback = IP_DEFAULT_FOLDBACK_DEGREES;
    o->lod = 1;
    o->pixel_error = 1.0;
    o->occlusion = 1;
    o->prefetch = IP_PREFETCH_ON;
    o->cull = -1;
    o->cache_bytes = ip_cache_default_budget();
}

void tool_engine_options(const tool_view_options *o, ip_engine_options *eo)
{
    ip_engine_options_default(eo);
    eo->cutoff_degrees = o->cutoff;
    eo->foldback_degrees = o->foldback;
    eo->threads = o->threads;
    eo->lod = o->lod;
    eo->pixel_error = o->pixel_error;
    eo->occlusion = o->occlusion;
    eo->prefetch = o->prefetch;
    eo->cull = o->cull > 0;
    eo->clip_count = o->clip_count;
    memcpy(eo->clip, o->clip, sizeof eo->clip);
}

/* An axis shortcut: "x=40", "-z=2.5". Returns 0, or -1 when `text` is not one. */
static int parse_clip_axis(const char *text, ip_clip_plane *plane)
{
    double sign = 1.0;
    if (text[0] == '-') {
        sign = -1.0;
        text++;
    }
    const char *axes = "xyz", *at = text[0] ? strchr(axes, tolower((unsigned char)text[0])) : NULL;
    double value;
    if (!at || text[1] != '=' || tool_parse_double(text + 2, &value) != 0)
        return -1;
    memset(plane, 0, sizeof *plane);
    plane->normal[at - axes] = sign; /* sign * (x - value) >= 0 */
    plane->offset = -sign * value;
    return 0;
}

int tool_parse_clip(const char *text, ip_clip_plane *plane)
{
    if (strchr(text, '='))
        return parse_clip_axis(text, plane);
    double v[4];
    char rest[256];
    if (strlen(text) >= sizeof rest)
        return -1;
    strcpy(rest, text);
    char *save = NULL, *item = strtok_r(rest, ",", &save);
    int n = 0;
    for (; item && n < 4; item = strtok_r(NULL, ",", &save))
        if (tool_parse_double(item, &v[n++]) != 0)
            return -1;
    if (n != 4 || item || strchr(text, ',') == text || strstr(text, ",,") ||
        text[strlen(text) - 1] == ',')
        return -1;
    if (v[0] == 0 && v[1] == 0 && v[2] == 0)
        return -1;
    *plane = (ip_clip_plane){{v[0], v[1], v[2]}, v[3]};
    return 0;
}

#define MAX_IMAGE_SIDE 16384 /* pixels; OpenGL's common maximum renderbuffer size */

/* ---- option parsers ---- */

/* The least a number may be: any finite one, more than 0, or 0 and more. */
enum {
    ANY_NUMBER,
    POSITIVE,
    NON_NEGATIVE
};

static int parse_double_option(const char *p, const tool_option *opt, const char *value, void *base,
                               int least)
{
    double *out = (double *)(void *)((char *)base + opt->offset);
    if (tool_parse_double(value, out) != 0 || (least == POSITIVE && *out <= 0) ||
        (least == NON_NEGATIVE && *out < 0))
        return tool_usage_error(p, "%s '%s' %s", opt->name, value, opt->problem);
    return 0;
}

int tool_option_number(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    return parse_double_option(p, opt, v[0], base, ANY_NUMBER);
}

int tool_option_positive(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    return parse_double_option(p, opt, v[0], base, POSITIVE);
}

int tool_option_non_negative(const char *p, const tool_option *opt, const char *const *v,
                             void *base)
{
    return parse_double_option(p, opt, v[0], base, NON_NEGATIVE);
}

int tool_option_background(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    ip_shading *s = (ip_shading *)((char *)base + opt->offset);
    if (tool_parse_background(v[0], s->background_top, s->background_bottom) != 0)
        return tool_usage_error(p,
                                "%s '%s' is not a colour (R,G,B or #rrggbb) or TOP:BOTTOM, two "
                                "of them",
                                opt->name, v[0]);
    return 0;
}

/* ---- the shared options (base: the tool_view_options) ---- */

/* --iso V and --iso-stored V alike, each noting which was given. */
static int parse_iso(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    tool_view_options *o = base;
    if (tool_option_number(p, opt, v, base) != 0)
        return 2;
    if (!strcmp(opt->name, "--iso-stored"))
        o->iso_given_stored = 1;
    else
        o->iso_given_units = 1;
    if (o->iso_count < TOOL_MAX_ISOS)
        o->isos[o->iso_count] = o->iso;
    o->iso_count++;
    return 0;
}

static int parse_size_option(const char *p, const tool_option *opt, const char *const *v,
                             void *base)
{
    tool_view_options *o = base;
    (void)opt;
    static const char *const sides[2] = {"width", "height"};
    return tool_parse_pair(p, "--size", v[0], MAX_IMAGE_SIDE, "WxH (e.g. 1600x1200)", sides,
                           "pixels", &o->width, &o->height);
}

static int parse_rays(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    tool_view_options *o = base;
    (void)opt;
    if (tool_parse_u64(v[0], &o->rays) != 0 || o->rays == 0)
        return tool_usage_error(p, "--rays '%s' is not a positive count", v[0]);
    return 0;
}

static int parse_view_threads(const char *p, const tool_option *opt, const char *const *v,
                              void *base)
{
    (void)opt;
    return tool_parse_threads(p, v[0], 64, &((tool_view_options *)base)->threads);
}

/* An on|off switch: *out = 1 or 0. */
static int parse_on_off(const char *p, const char *value, int *out, const char *option)
{
    if (strcmp(value, "on") && strcmp(value, "off"))
        return tool_usage_error(p, "%s must be on or off", option);
    *out = !strcmp(value, "on");
    return 0;
}

int tool_option_on_off(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    return parse_on_off(p, v[0], (int *)(void *)((char *)base + opt->offset), opt->name);
}

int tool_option_renderer(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    static const char *const names[3] = {"auto", "opengl", "software"};
    for (int i = 0; i < 3; i++)
        if (!strcmp(v[0], names[i])) {
            *(int *)(void *)((char *)base + opt->offset) = i; /* TOOL_RENDERER_* */
            return 0;
        }
    return tool_usage_error(p, "--renderer '%s': must be auto, opengl or software", v[0]);
}

static int parse_lod(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    (void)opt;
    return parse_on_off(p, v[0], &((tool_view_options *)base)->lod, "--lod");
}

static int parse_occlusion(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    (void)opt;
    return parse_on_off(p, v[0], &((tool_view_options *)base)->occlusion, "--occlusion");
}

/* --prefetch's names, indexed by the modes IP_PREFETCH_OFF, _ON and _ALWAYS (0, 1, 2). */
static const char *const prefetch_names[3] = {"off", "on", "always"};

const char *tool_prefetch_name(int mode)
{
    return mode >= 0 && mode < 3 ? prefetch_names[mode] : "unknown";
}

static int parse_prefetch(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    (void)opt;
    for (int i = 0; i < 3; i++)
        if (!strcmp(v[0], prefetch_names[i])) {
            ((tool_view_options *)base)->prefetch = i;
            return 0;
        }
    return tool_usage_error(p, "--prefetch must be on, off or always");
}

static int parse_cull(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    (void)opt;
    return parse_on_off(p, v[0], &((tool_view_options *)base)->cull, "--cull");
}

int tool_option_cache_mb(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    if (tool_parse_cache_mb(v[0], (uint64_t *)((char *)base + opt->offset)) != 0)
        return tool_usage_error(p, "bad --cache-mb '%s'", v[0]);
    return 0;
}

/* A --clip (index 0) or --clip-index (1) plane as given; tool_space_clip() turns it into world
 * units once the file is open. */
static int add_clip(const char *p, const char *name, const char *value, tool_view_options *o,
                    int index)
{
    if (o->clip_count == IP_MAX_CLIP_PLANES)
        return tool_usage_error(p, "at most %d --clip and --clip-index planes", IP_MAX_CLIP_PLANES);
    unsigned i = o->clip_count;
    if (tool_parse_clip(value, &o->clip_given[i]) != 0)
        return tool_usage_error(p, "bad %s '%s' (x=V, -x=V, y=V, ... or A,B,C,D)", name, value);
    o->clip_index[i] = (uint8_t)index;
    o->clip[i] = o->clip_physical[i] = o->clip_given[i];
    o->clip_count++;
    return 0;
}

static int parse_clip_option(const char *p, const tool_option *opt, const char *const *v,
                             void *base)
{
    return add_clip(p, opt->name, v[0], base, 0);
}

static int parse_clip_index(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    return add_clip(p, opt->name, v[0], base, 1);
}

/* --view and --camera are checked as they are parsed, so that a bad one is a usage error
 * (exit 2) before any file is opened; the library's own check says what is wrong. */
static int parse_view(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    ip_error err;
    (void)opt;
    if (ip_view_check(v[0], &err) != IP_OK)
        return tool_usage_error(p,
                                "--view '%s' is not a view (anterior posterior left right "
                                "superior inferior, or +x -x +y -y +z -z)",
                                v[0]);
    ((tool_view_options *)base)->view = v[0];
    return 0;
}

static int parse_camera(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    ip_camera probe;
    ip_error err;
    (void)opt;
    memset(&probe, 0, sizeof probe);
    probe.width = probe.height = 1;
    if (ip_camera_parse(v[0], &probe, &err) != IP_OK || ip_camera_check(&probe, &err) != IP_OK)
        return tool_usage_error(p, "--camera '%s': %s", v[0], err.message);
    ((tool_view_options *)base)->camera = v[0];
    return 0;
}

#define VIEW_FIELD(member) offsetof(tool_view_options, member)

static const tool_option view_options[] = {
    {"--iso", NULL, 1, VIEW_FIELD(iso), parse_iso, "is not a number", NULL},
    {"--iso-stored", NULL, 1, VIEW_FIELD(iso), parse_iso, "is not a number", NULL},
    {"--size", NULL, 1, 0, parse_size_option, NULL, NULL},
    {"--view", NULL, 1, VIEW_FIELD(view), parse_view, NULL, NULL},
    {"--camera", NULL, 1, VIEW_FIELD(camera), parse_camera, NULL, NULL},
    {"--rays", NULL, 1, 0, parse_rays, NULL, NULL},
    {"--time", NULL, 1, VIEW_FIELD(time_limit), tool_option_positive, "is not positive seconds",
     NULL},
    {"--cutoff", NULL, 1, VIEW_FIELD(cutoff), tool_option_number, "is not a number", NULL},
    {"--foldback", NULL, 1, VIEW_FIELD(foldback), tool_option_number, "is not a number", NULL},
    {"--threads", NULL, 1, 0, parse_view_threads, NULL, NULL},
    {"--lod", NULL, 1, 0, parse_lod, NULL, NULL},
    {"--pixel-error", NULL, 1, VIEW_FIELD(pixel_error), tool_option_positive, "is not positive",
     NULL},
    {"--occlusion", NULL, 1, 0, parse_occlusion, NULL, NULL},
    {"--prefetch", NULL, 1, 0, parse_prefetch, NULL, NULL},
    {"--cull", NULL, 1, 0, parse_cull, NULL, NULL},
    {"--clip", NULL, 1, 0, parse_clip_option, NULL, NULL},
    {"--clip-index", NULL, 1, 0, parse_clip_index, NULL, NULL},
    {"--cache-mb", NULL, 1, VIEW_FIELD(cache_bytes), tool_option_cache_mb, NULL, NULL},
    {"--stats", NULL, 1, VIEW_FIELD(stats), NULL, NULL, NULL},
    {"--force", "-f", 0, VIEW_FIELD(force), NULL, NULL, NULL},
    {"--quiet", "-q", 0, VIEW_FIELD(quiet), NULL, NULL, NULL},
};

tool_option_table tool_view_option_table(tool_view_options *o)
{
    return (tool_option_table){view_options, sizeof view_options / sizeof view_options[0], o};
}

int tool_parse_view_command_line(const char *program, const char *usage, tool_view_options *o,
                                 const tool_option *own, size_t own_count, void *own_base,
                                 const char **file, int argc, char **argv)
{
    const tool_option_table tables[] = {tool_view_option_table(o), {own, own_count, own_base}};
    const tool_command_line line = {program, usage, tables, 2, file, "file"};
    int rc = tool_parse_command_line(&line, argc, argv);
    if (rc)
        return rc;
    if (!*file)
        return tool_usage_error(program, "no brick file");
    if (!o->iso_count)
        return tool_usage_error(program, "--iso V is required (or --iso-stored V)");
    if (o->iso_given_stored && o->iso_given_units)
        return tool_usage_error(program,
                                "--iso and --iso-stored do not mix: give every isovalue in the "
                                "file's units (--iso) or every one as a stored value");
    return 0;
}

void tool_settle_iso(tool_view_options *o, const ip_layout *layout)
{
    o->rescale = &layout->rescale;
    if (o->iso_given_stored) {
        o->iso_stored = o->iso;
        o->iso_value = ip_rescale_to_value(o->rescale, o->iso);
    } else {
        o->iso_value = o->iso;
        o->iso_stored = ip_rescale_to_stored(o->rescale, o->iso);
    }
}

ip_status tool_full_extraction(ip_cache *cache, double iso, int mode, const ip_camera *camera,
                               const tool_view_options *o, ip_mesh *mesh, ip_engine_counts *counts,
                               ip_error *err)
{
    if (mode == TOOL_FULL_LOD)
        return ip_extract_full_lod(cache, (float)iso, camera, o->pixel_error, o->threads, o->clip,
                                   o->clip_count, mesh, counts, err);
    return ip_extract_full_clipped(cache, (float)iso, 0, o->threads, o->clip, o->clip_count, mesh,
                                   counts, err);
}

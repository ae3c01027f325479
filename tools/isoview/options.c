/* SPDX-License-Identifier: BSD-3-Clause */
/* isoview's command line: the shared view options (tool_common) and isoview's own. */
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "isoview.h"

static const char usage[] =
    "usage: isoview FILE.ibv --iso V [options]\n"
    "Shows the isosurface V in a window (OpenGL 3.3 core through GLFW), refining it\n"
    "progressively (rays in the paper's order) while you orbit, pan, zoom and change V.\n" TOOL_ISO_OPTIONS_HELP
    "  --size WxH          window size (default 1280x960)\n" TOOL_VIEW_OPTIONS_HELP
    "  --rays N            each pass (view and isovalue) stops after N rays\n"
    "  --time SECONDS      each pass stops extracting after this long\n" TOOL_ENGINE_OPTIONS_HELP
    "  --cache-mb N        brick cache budget in MiB (default 512, or a quarter of RAM)\n"
    "  --threads N         threads for seeding, propagation and full extraction\n"
    "                      (default: all cores)\n"
    "  --aa N              anti-aliasing: N samples a pixel of the window (1 to 16; default\n"
    "                      1, off: the image isorender draws)\n"
    "  --renderer auto|opengl|software\n"
    "                      draw the mesh with OpenGL, or with the exact software rasterizer\n"
    "                      shown as a texture, drawing only what is new; auto (the default):\n"
    "                      software where OpenGL is itself software (llvmpipe, softpipe)\n"
    "  --reuse on|off      a new view keeps the cells of the view before that stay valid and\n"
    "                      may show, and extracts what became visible (default off: slower\n"
    "                      here, see docs/isoview.md)\n"
    "  --read-ahead on|off once a view is done, read the next one of the same motion (an\n"
    "                      orbit's or a zoom's step again) ahead into the cache (with\n"
    "                      --prefetch on; default off: no gain measured, docs/isoview.md)\n"
    "  --drag-pixel-error P\n"
    "                      while the view moves (a drag), passes at this coarser pixel error\n"
    "                      (adaptive resolution); refinement resumes at --pixel-error when\n"
    "                      the motion stops (default 4; 0: off)\n"
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
    "applies); r resets the view; p pauses; f extracts everything; c turns the --clip planes\n"
    "off and on again (each restarts the pass); s saves a screenshot; o hides the overlay;\n"
    "h shows help; Esc quits.\n";

/* --screenshot-at SECONDS OUT.png */
static int parse_screenshot_at(const char *p, const tool_option *opt, const char *const *v,
                               void *base)
{
    options *o = base;
    (void)opt;
    if (tool_parse_double(v[0], &o->screenshot_at) != 0 || o->screenshot_at < 0)
        return tool_usage_error(p, "--screenshot-at '%s' is not seconds", v[0]);
    o->screenshot_path = v[1];
    return 0;
}

static int parse_exit_after(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    options *o = base;
    (void)opt;
    if (tool_parse_double(v[0], &o->exit_after) != 0 || o->exit_after < 0)
        return tool_usage_error(p, "--exit-after '%s' is not seconds", v[0]);
    return 0;
}

static int parse_aa(const char *p, const tool_option *opt, const char *const *v, void *base)
{
    uint64_t samples;
    int rc = tool_parse_bounded(p, opt->name, v[0], 1, 16, "a sample count", &samples);
    if (rc == 0)
        ((options *)base)->aa = (int)samples;
    return rc;
}

static int parse_drag_pixel_error(const char *p, const tool_option *opt, const char *const *v,
                                  void *base)
{
    options *o = base;
    (void)opt;
    if (tool_parse_double(v[0], &o->drag_pixel_error) != 0 || !(o->drag_pixel_error >= 0) ||
        o->drag_pixel_error > 1024)
        return tool_usage_error(p,
                                "--drag-pixel-error '%s': must be 0 (off) or a pixel error up "
                                "to 1024",
                                v[0]);
    return 0;
}

static const tool_option isoview_options[] = {
    {"--drag-pixel-error", NULL, 1, 0, parse_drag_pixel_error, NULL, NULL},
    {"--reuse", NULL, 1, offsetof(options, reuse), tool_option_on_off, NULL, NULL},
    {"--read-ahead", NULL, 1, offsetof(options, read_ahead), tool_option_on_off, NULL, NULL},
    {"--renderer", NULL, 1, offsetof(options, renderer), tool_option_renderer, NULL, NULL},
    {"--script", NULL, 1, offsetof(options, script), NULL, NULL, NULL},
    {"--screenshot-at", NULL, 2, 0, parse_screenshot_at, NULL, NULL},
    {"--exit-after", NULL, 1, 0, parse_exit_after, NULL, NULL},
    {"--aa", NULL, 1, 0, parse_aa, NULL, NULL},
};

int parse_args(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    tool_view_options_default(&o->common, 1280, 960);
    o->screenshot_at = -1;
    o->exit_after = -1;
    o->aa = 1;
    o->renderer = TOOL_RENDERER_AUTO;
    o->reuse = 0;
    o->read_ahead = 0;
    o->drag_pixel_error = 4;
    int rc = tool_parse_view_command_line("isoview", usage, &o->common, isoview_options,
                                          sizeof isoview_options / sizeof isoview_options[0], o,
                                          &o->file, argc, argv);
    /* on, as isorender: the mesh holds what the window shows (a paused viewer moved around
     * the surface then shows pinholes until it resumes), unless --aa, whose samples off the
     * pixel centres need every triangle */
    if (o->common.cull < 0)
        o->common.cull = o->aa <= 1;
    if (rc == 0 && o->aa > 1 && o->renderer == TOOL_RENDERER_SOFTWARE)
        return tool_usage_error("isoview",
                                "--aa is OpenGL's: --renderer software draws without it");
    if (rc == 0 && o->common.iso_count > 1) /* isorender draws each; here one would be lost */
        return tool_usage_error("isoview",
                                "--iso given %u times: isoview shows one surface (isorender "
                                "draws several)",
                                o->common.iso_count);
    return rc;
}

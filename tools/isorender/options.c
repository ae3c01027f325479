/* SPDX-License-Identifier: BSD-3-Clause */
/* isorender's command line: the usage, the option table and the checks across options. */
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "isorender.h"

static const char usage[] =
    "usage: isorender FILE.ibv --iso V [--iso V2 ...] [options]\n"
    "Extracts the isosurface V progressively (rays in the paper's order) and renders it to PNG\n"
    "with OpenGL 3.3 core through EGL (no display needed). --iso given up to 4 times draws as\n"
    "many surfaces together, each extracted by its own progressive run with the same view\n"
    "and options (see --color and --opacity); --iso-stored alike.\n" TOOL_ISO_OPTIONS_HELP
    "  --size WxH          image size in pixels (default 1600x1200)\n" TOOL_VIEW_OPTIONS_HELP
        TOOL_ORBIT_OPTIONS_HELP
    "  --color C           the surface colour: R,G,B (each 0 to 1) or #rrggbb (default\n"
    "                      #ede3c9, an ivory); repeated, the colours of the surfaces in the\n"
    "                      order of --iso (those without one: #ede3c9, #8fb3d9, #e0a370,\n"
    "                      #9ccf8f by position)\n"
    "  --opacity A         the surface's opacity, 0 < A <= 1 (default 1, opaque); repeated, in\n"
    "                      the order of --iso. A translucent surface shows its nearest layer,\n"
    "                      blended over the nearest opaque surface where in front of it\n"
    "  --background C      the background: one colour, or TOP:BOTTOM for a vertical gradient\n"
    "                      (default #3d4557:#141721)\n"
    "  --rays N            stop after N rays (default: every pixel)\n"
    "  --time SECONDS      stop extracting after this long\n" TOOL_ENGINE_OPTIONS_HELP
    "  --full              triangulate every active cell instead (the baseline)\n"
    "  --full-lod          every active cell at the view's adaptive resolution: each level's\n"
    "                      cells within its distance band (what --lod on equals at the end)\n"
    "  --warm              extract once untimed first, so the timed run finds a warm cache\n"
    "  --cache-mb N        brick cache budget in MiB (default 512, or a quarter of RAM)\n"
    "  --threads N         threads for seeding, propagation and --full (default: all cores)\n"
    "  -o OUT.png          the image (default isorender.png)\n"
    "  --mesh OUT          also write the triangles: binary PLY (.ply), binary STL (.stl),\n"
    "                      Wavefront OBJ (.obj) or binary glTF (.glb, units as metres),\n"
    "                      by the name's extension. A progressive run's mesh holds only what\n"
    "                      the view needed (open behind); with --full it is the whole, closed\n"
    "                      surface. With several --iso, one file a surface, the isovalue before\n"
    "                      the extension (head.ply: head_iso600.5.ply, head_iso1224.5.ply)\n"
    "  --mesh-grid         the mesh in the volume's grid instead: sample index x spacing from\n"
    "                      0 (the default is the file's physical space: origin, directions and\n"
    "                      spacing applied); the file names its space (docs/meshes.md)\n"
    "  --weld, --no-weld   PLY, OBJ and glTF meshes share their vertices (default), or repeat\n"
    "                      them for every triangle (STL always does)\n"
    "  --smooth N          smooth the mesh file by N iterations of Taubin's method (lambda 0.5,\n"
    "                      mu -0.53), which softens the terraces of nearly binary data without\n"
    "                      shrinking the surface; needs shared vertices (not --no-weld); the\n"
    "                      rim of an open mesh stays. Only the file changes: the image and\n"
    "                      what the summary says of it are those of the extracted triangles\n"
    "  --decimate RATIO    simplify the mesh file to about RATIO (0 < RATIO < 1) of its\n"
    "                      triangles by edge collapses (meshoptimizer), within an error bound;\n"
    "                      the rim where the surface meets the volume's faces stays; needs\n"
    "                      shared vertices. Only the file changes, as with --smooth\n"
    "  --decimate-error L  --decimate's bound: the farthest a removed vertex may lie from the\n"
    "                      simplified surface, in the mesh's units (default 1% of its size)\n"
    "  --cap               with --full: close the surface where it leaves the volume's box, the\n"
    "                      faces' region above the isovalue triangulated from the same samples\n"
    "                      (not with --clip)\n"
    "  --measure           print the surface's figures (docs/meshes.md, \"Measuring\"): area,\n"
    "                      enclosed volume, closed or open, connected components and the\n"
    "                      largest, bounding box; in the mesh file's units (physical unless\n"
    "                      --mesh-grid), after --smooth and the cleaning. --stats holds them as\n"
    "                      \"surface\". A progressive run's figures are for the visible part\n"
    "  --largest           keep only the largest connected component (by area) in the mesh\n"
    "                      written and measured\n"
    "  --min-area A        drop the connected components of an area under A (physical units\n"
    "                      squared) from the mesh written and measured (A >= 0). --largest and\n"
    "                      --min-area need --mesh, --measure or --stats, and shared vertices\n"
    "  --stats OUT.json    counts, times, warnings, the cache statistics and the overdraw\n"
    "                      (triangles / visible_triangles, those owning a final pixel) as JSON\n"
    "  --progress OUT.csv  time_s,rays,seeds,cells,triangles,final_pixel_pct,visible_triangles,\n"
    "                      overdraw at checkpoints\n"
    "                      (--stats - or --progress -: standard output, the summary on stderr).\n"
    "                      With several --iso, --stats adds \"surfaces\", an entry a surface\n"
    "                      (the rest is the first surface's), and --progress an iso column,\n"
    "                      each surface's rows after the previous one's\n"
    "  --strip OUT.png     also write the progress strip: the image as extracted by a few\n"
    "                      points of the run, side by side and labelled\n"
    "  --strip-at P,...    the strip's points, in percent of the view's rays, increasing\n"
    "                      (default 0.01%,0.1%,1%,100%; at most 8)\n"
    "  --turntable N       write N frames instead of one image, into the folder -o names\n"
    "                      (default turntable/; made when absent): frame_000.png ..., the eye\n"
    "                      turned 360/N degrees more in azimuth each time, each frame a\n"
    "                      complete image extracted for its own view (--full: one extraction)\n"
    "  --mp4 OUT.mp4       with --turntable: also encode the frames with ffmpeg (H.264, 25 fps);\n"
    "                      without ffmpeg on the PATH it is refused before any work\n"
    "  --axes              draw an axis triad in the bottom-left corner: the directions of the\n"
    "                      file's physical axes as the camera sees them (x red, y green, z\n"
    "                      blue), labelled R/L, A/P, S where the file names an anatomical space\n"
    "                      (RAS, LAS, LPS), else x, y, z\n"
    "  --scale-bar         draw a scale bar in the bottom-right corner: a round length (1, 2 or 5\n"
    "                      times a power of ten world units, at most a quarter of the width)\n"
    "                      as long as it looks at the depth of the view's target (perspective:\n"
    "                      nearer is larger)\n"
    "  --scale-unit TEXT   the scale bar's unit (default mm where the file names an anatomical\n"
    "                      space, else units: world units are the spacing's; printable ASCII,\n"
    "                      other bytes are drawn as ?)\n"
    "                      (--axes and --scale-bar mark the image and the turntable's frames,\n"
    "                      not the strip; each is drawn whole or not at all: --axes needs an\n"
    "                      image of 63x62 pixels or more (exit 2), a scale bar and label wider\n"
    "                      or taller than the image end the run with nothing written (exit 1))\n"
    "  --renderer auto|opengl|software\n"
    "                      draw with OpenGL (headless EGL; software with a note where none\n"
    "                      starts) or the exact software rasterizer; auto (the default):\n"
    "                      software where OpenGL is itself a software driver (llvmpipe), or\n"
    "                      with --aa OpenGL\n"
    "  --software          --renderer software\n"
    "  --aa N              OpenGL anti-aliasing: N samples a pixel (1 to 16; default 1, off,\n"
    "                      the image the software rasterizer draws; 4 or 8 for figures)\n"
    "  -f, --force         replace existing outputs (regular files only; never an input)\n"
    "  -q, --quiet         print nothing but errors and warnings (and no progress bar)\n"
    "  -v, --verbose       each extraction step's counts on stderr\n"
    "  --version           print the version and exit\n"
    "A progress bar (rays done, triangles) is drawn on stderr when it is a terminal\n"
    "(ISORENDER_PROGRESS=1 forces it). Options take their value as --iso V or --iso=V; short\n"
    "ones cluster (-qf); -- ends the options; a long name may be shortened while unambiguous.\n"
    "Exit status: 0 success, 1 failure, 2 bad command line.\n"
    "Every output appears only when complete. The summary's time line gives the extraction's\n"
    "wall time, then its parts (intersection, propagation, marching cubes) in CPU seconds\n"
    "summed over the threads, which can add up to more than the wall time. Ctrl-C cancels:\n"
    "no output is written, and isorender ends as killed by the signal.\n";

static tool_option_parse parse_color, parse_aa, parse_opacity;

static const tool_option isorender_options[] = {
    {"-o", NULL, 1, offsetof(options, out), NULL, NULL, NULL},
    {"--mesh", NULL, 1, offsetof(options, mesh), NULL, NULL, NULL},
    {"--progress", NULL, 1, offsetof(options, progress), NULL, NULL, NULL},
    {"--full", NULL, 0, offsetof(options, full), NULL, NULL, NULL},
    {"--full-lod", NULL, 0, offsetof(options, full_lod), NULL, NULL, NULL},
    {"--warm", NULL, 0, offsetof(options, warm), NULL, NULL, NULL},
    {"--software", NULL, 0, offsetof(options, software), NULL, NULL, NULL},
    {"--renderer", NULL, 1, offsetof(options, renderer), tool_option_renderer, NULL, NULL},
    {"--strip", NULL, 1, offsetof(options, strip), NULL, NULL, NULL},
    {"--strip-at", NULL, 1, offsetof(options, strip_at), parse_strip_at, NULL, NULL},
    {"--weld", NULL, 0, offsetof(options, weld), NULL, NULL, NULL},
    {"--no-weld", NULL, 0, offsetof(options, no_weld), NULL, NULL, NULL},
    {"--mesh-grid", NULL, 0, offsetof(options, mesh_grid), NULL, NULL, NULL},
    {"--smooth", NULL, 1, 0, parse_smooth, NULL, NULL},
    TOOL_ORBIT_OPTION_ROWS(options, orbit),
    {"--color", NULL, 1, 0, parse_color, NULL, NULL},
    {"--opacity", NULL, 1, 0, parse_opacity, NULL, NULL},
    {"--background", NULL, 1, offsetof(options, shading), tool_option_background, NULL, NULL},
    {"--turntable", NULL, 1, 0, parse_turntable, NULL, NULL},
    {"--mp4", NULL, 1, offsetof(options, mp4), NULL, NULL, NULL},
    {"--aa", NULL, 1, 0, parse_aa, NULL, NULL},
    {"--axes", NULL, 0, offsetof(options, axes), NULL, NULL, NULL},
    {"--scale-bar", NULL, 0, offsetof(options, scale_bar), NULL, NULL, NULL},
    {"--scale-unit", NULL, 1, offsetof(options, scale_unit), NULL, NULL, NULL},
    {"--verbose", "-v", 0, offsetof(options, common.verbose), NULL, NULL, NULL},
    {"--decimate", NULL, 1, 0, parse_decimate, NULL, NULL},
    {"--decimate-error", NULL, 1, 0, parse_decimate_error, NULL, NULL},
    {"--cap", NULL, 0, offsetof(options, cap), NULL, NULL, NULL},
    {"--measure", NULL, 0, offsetof(options, measure), NULL, NULL, NULL},
    {"--largest", NULL, 0, offsetof(options, largest), NULL, NULL, NULL},
    {"--min-area", NULL, 1, 0, parse_min_area, NULL, NULL},
};

/* ---- the figure's colours ---- */

/* --color, repeatable: the first is the shading's surface colour (one surface's image is
 * drawn with it), each one the next surface's. */
static int parse_color(const char *program, const tool_option *option, const char *const *values,
                       void *base)
{
    options *o = base;
    float rgb[3];
    (void)option;
    if (tool_parse_colour(values[0], rgb) != 0)
        return tool_usage_error(program, "--color '%s' is not R,G,B (each 0 to 1) or #rrggbb",
                                values[0]);
    if (o->colour_count == TOOL_MAX_ISOS)
        return tool_usage_error(program, "--color '%s': more than %d colours", values[0],
                                TOOL_MAX_ISOS);
    if (o->colour_count == 0)
        memcpy(o->shading.surface, rgb, sizeof rgb);
    memcpy(o->colours[o->colour_count++], rgb, sizeof rgb);
    return 0;
}

static int parse_opacity(const char *program, const tool_option *option, const char *const *values,
                         void *base)
{
    options *o = base;
    double a;
    (void)option;
    /* checked as the float the renderers take: 1e-50 would be 0 there */
    if (tool_parse_double(values[0], &a) != 0 || !((float)a > 0 && (float)a <= 1))
        return tool_usage_error(program, "--opacity '%s' is not a number in (0, 1]", values[0]);
    if (o->opacity_count == TOOL_MAX_ISOS)
        return tool_usage_error(program, "--opacity '%s': more than %d opacities", values[0],
                                TOOL_MAX_ISOS);
    o->opacity[o->opacity_count++] = (float)a;
    return 0;
}

/* Several --iso: at most TOOL_MAX_ISOS, no two alike, and no more colours or opacities than
 * surfaces. Returns 0, or 2 after a usage error. */
static int check_surface_options(const options *o)
{
    unsigned n = o->common.iso_count;
    const char *iso = o->common.iso_given_stored ? "--iso-stored" : "--iso";
    if (n > TOOL_MAX_ISOS)
        return tool_usage_error("isorender", "%s given %u times: at most %d surfaces", iso, n,
                                TOOL_MAX_ISOS);
    for (unsigned i = 0; i < n; i++)
        for (unsigned j = 0; j < i; j++)
            if ((float)o->common.isos[i] == (float)o->common.isos[j])
                return tool_usage_error("isorender", "%s %g is given twice", iso,
                                        o->common.isos[i]);
    if (o->colour_count > n || o->opacity_count > n)
        return tool_usage_error("isorender",
                                "%zu --color and %zu --opacity for %u --iso: at most one of each "
                                "a surface",
                                o->colour_count, o->opacity_count, n);
    return 0;
}

#define AA_MAX_SAMPLES 16

static int parse_aa(const char *program, const tool_option *option, const char *const *values,
                    void *base)
{
    uint64_t samples;
    int rc = tool_parse_bounded(program, option->name, values[0], 1, AA_MAX_SAMPLES,
                                "a sample count", &samples);
    if (rc == 0)
        ((options *)base)->aa = (uint32_t)samples;
    return rc;
}

int parse_args(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    tool_view_options_default(&o->common, 1600, 1200);
    tool_orbit_options_default(&o->orbit);
    ip_shading_default(&o->shading);
    o->aa = 1;
    int rc = tool_parse_view_command_line("isorender", usage, &o->common, isorender_options,
                                          sizeof isorender_options / sizeof isorender_options[0], o,
                                          &o->file, argc, argv);
    if (rc)
        return rc;
    if (o->full && o->full_lod)
        return tool_usage_error("isorender", "--full and --full-lod: one or the other");
    if (o->full_lod && !o->common.lod)
        return tool_usage_error("isorender",
                                "--full-lod is the full extraction at adaptive resolution: not "
                                "with --lod off (--full is that)");
    if (o->full_lod)
        o->full = TOOL_FULL_LOD;
    if (o->full && (o->common.rays || o->common.time_limit > 0))
        return tool_usage_error("isorender", "--full extracts everything: no --rays or --time");
    if (o->software && o->renderer == TOOL_RENDERER_OPENGL)
        return tool_usage_error("isorender", "--software and --renderer opengl: one or the other");
    if (o->renderer == TOOL_RENDERER_SOFTWARE)
        o->software = 1;
    if (o->software && o->aa > 1)
        return tool_usage_error("isorender", "--aa is OpenGL's: --software draws without it");
    if (o->weld && o->no_weld)
        return tool_usage_error("isorender", "--weld and --no-weld: one or the other");
    rc = check_surface_options(o);
    if (rc)
        return rc;
    if (o->scale_unit && !o->scale_bar)
        return tool_usage_error("isorender", "--scale-unit needs --scale-bar");
    /* Triangles no pixel centre shows are culled unless the mesh is written out, or drawn with
     * multisampling, which samples more than pixel centres (or --cull says otherwise). */
    if (o->common.cull < 0)
        o->common.cull = !o->mesh && o->aa <= 1;
    ip_error why;
    if (o->axes && ip_overlay_axes_check(o->common.width, o->common.height, &why) != IP_OK)
        return tool_usage_error("isorender", "--%s", why.message); /* "--axes: the triad..." */
    rc = check_mesh_options(o);
    if (!rc)
        rc = check_decimate_options(o);
    if (!rc)
        rc = check_cap_options(o);
    if (!rc)
        rc = check_measure_options(o);
    if (!rc && !o->turntable)
        rc = tool_check_png_name("isorender", "-o", o->out);
    if (!rc)
        rc = tool_check_png_name("isorender", "--strip", o->strip);
    if (rc)
        return rc;
    rc = check_turntable_options(o);
    if (rc)
        return rc;
    return check_strip_options(o);
}

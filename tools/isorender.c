/* isorender: extract an isosurface progressively (or fully) and render it to PNG, headless. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <errno.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

#include "isoprop/cache.h"
#include "isoprop/engine.h"
#include "isoprop/render.h"
#include "isoprop/store.h"
#include "tool_common.h"

static const char usage[] =
    "usage: isorender FILE.ibv --iso V [--iso V2 ...] [options]\n"
    "Extracts the isosurface V progressively (rays in the paper's order) and renders it to PNG\n"
    "with OpenGL 3.3 core through EGL (no display needed). --iso given up to 4 times draws as\n"
    "many surfaces together, each extracted by its own progressive run with the same view\n"
    "and options (see --color and --opacity).\n"
    "  --size WxH          image size in pixels (default 1600x1200)\n"
    "  --view AXIS         +x -x +y -y +z -z: the side the eye is on, whole volume in frame\n"
    "                      (default -y; up is +z, or +y for the z views)\n"
    "  --camera E,T,U,FOV  ex,ey,ez,tx,ty,tz,ux,uy,uz,fov in world units and degrees\n" TOOL_ORBIT_OPTIONS_HELP
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
    "                      Wavefront OBJ (.obj) or binary glTF (.glb, world units as metres),\n"
    "                      by the name's extension. A progressive run's mesh holds only what\n"
    "                      the view needed (open behind); with --full it is the whole, closed\n"
    "                      surface. With several --iso, one file a surface, the isovalue before\n"
    "                      the extension (head.ply: head_iso600.5.ply, head_iso1224.5.ply)\n"
    "  --weld, --no-weld   PLY, OBJ and glTF meshes share their vertices (default), or repeat\n"
    "                      them for every triangle (STL always does)\n"
    "  --smooth N          smooth the mesh file by N iterations of Taubin's method (lambda 0.5,\n"
    "                      mu -0.53), which softens the terraces of nearly binary data without\n"
    "                      shrinking the surface; needs shared vertices (not --no-weld); the\n"
    "                      rim of an open mesh stays. Only the file changes: the image and\n"
    "                      what the summary says of it are those of the extracted triangles\n"
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
    "                      without ffmpeg the frames stay and isorender exits 1\n"
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

/* The progress strip (--strip): frames side by side, STRIP_GAP pixels apart, over a band of
 * STRIP_BAND pixels with each frame's label, the render stage's text (ip_overlay_draw_text())
 * at STRIP_TEXT_SCALE. */
#define STRIP_MAX_FRAMES 8
#define STRIP_GAP 4
#define STRIP_BAND 24
#define STRIP_TEXT_SCALE 2
#define STRIP_MAX_WIDTH 65536

/* --strip-at: the strip's frames, in percent of the view's rays, increasing, in (0, 100] */
typedef struct strip_plan {
    double pct[STRIP_MAX_FRAMES];
    size_t count;
} strip_plan;

typedef struct options {
    tool_view_options common;
    const char *file, *out, *mesh, *progress, *strip;
    int full, software, warm; /* --stats, --force and --quiet are in common */
    int renderer;             /* --renderer: TOOL_RENDERER_AUTO, _OPENGL, _SOFTWARE (--software) */
    int full_lod;             /* --full-lod: full becomes TOOL_FULL_LOD (--full: TOOL_FULL) */
    strip_plan strip_at;      /* count 0 until --strip-at or the default sets it */
    int weld, no_weld;
    uint64_t smooth;          /* --smooth N: Taubin iterations for the mesh file (0: none) */
    tool_orbit_options orbit; /* --azimuth, --elevation, --zoom */
    uint64_t turntable;       /* --turntable N: frames (0: one image) */
    const char *mp4;          /* --mp4 OUT.mp4 (NULL: none) */
    ip_shading shading;       /* ip_shading_default() with --color and --background */
    uint32_t aa;              /* --aa N: OpenGL samples a pixel (1: none) */
    /* --color and --opacity, repeatable: the surfaces' in the order of --iso */
    float colours[TOOL_MAX_ISOS][3];
    size_t colour_count;
    float opacity[TOOL_MAX_ISOS];
    size_t opacity_count;
    int axes, scale_bar;    /* --axes, --scale-bar: the figure overlays */
    const char *scale_unit; /* --scale-unit TEXT (NULL: from the file's space) */
} options;

/* Where each frame of the strip stands: the ray count it shows and the triangles (a prefix
 * of the mesh, which only grows by appending) extracted by then. */
typedef struct strip_frames {
    uint64_t rays[STRIP_MAX_FRAMES], triangles[STRIP_MAX_FRAMES];
    size_t recorded; /* frames whose triangles are known */
} strip_frames;

typedef struct checkpoint {
    double time;
    uint64_t rays, seeds, cells, triangles;
    double final_pct;
    uint64_t visible; /* triangles extracted by then that own a pixel of the final image */
} checkpoint;

typedef struct run {
    options o;
    ip_store *store;
    ip_cache *cache;
    ip_engine *engine;
    ip_camera camera;
    ip_camera view_camera; /* --view's or --camera's, before --azimuth, --elevation, --zoom */
    double lo[3], hi[3];
    ip_mesh full_mesh;
    const ip_mesh *mesh;
    ip_engine_counts totals;
    checkpoint *checkpoints;
    size_t checkpoint_count;
    double extraction_wall, progress_render_seconds;
    uint64_t visible_triangles; /* triangles of the mesh that own a pixel of its image */
    int owners_known;           /* visible_triangles and the checkpoints' `visible` are set */
    const char *renderer_name;
    char warning[600]; /* the --iso warning, "" when none */
    int writing;       /* 1 once the outputs are being written */
    strip_frames strip;
    uint64_t mesh_vertices, mesh_dropped; /* of the mesh file: vertices, degenerate triangles */
    /* several --iso: this run is the first surface's; others[] the later ones', each a run of
     * its own (engine, mesh, counts) sharing the store, the cache and the camera */
    struct run *others;
    size_t other_count;
    char mesh_name[4096]; /* the surface's mesh file (o.mesh points here), several --iso */
    ip_scale_bar bar;     /* --scale-bar: the last image's */
} run;

static int parse_strip_at(const char *program, const tool_option *option, const char *const *values,
                          void *base);
static tool_option_parse parse_color, parse_turntable, parse_aa, parse_smooth, parse_opacity;

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

/* The colours of the second to last surfaces when --color leaves them out, by position (the
 * first surface's is the shading's, the default ivory). */
static const float surface_palette[TOOL_MAX_ISOS - 1][3] = {
    {0.561f, 0.702f, 0.851f}, /* #8fb3d9 */
    {0.878f, 0.639f, 0.439f}, /* #e0a370 */
    {0.612f, 0.812f, 0.561f}, /* #9ccf8f */
};

/* Several --iso: at most TOOL_MAX_ISOS, no two alike, and no more colours or opacities than
 * surfaces. Returns 0, or 2 after a usage error. */
static int check_surface_options(const options *o)
{
    unsigned n = o->common.iso_count;
    if (n > TOOL_MAX_ISOS)
        return tool_usage_error("isorender", "--iso given %u times: at most %d surfaces", n,
                                TOOL_MAX_ISOS);
    for (unsigned i = 0; i < n; i++)
        for (unsigned j = 0; j < i; j++)
            if ((float)o->common.isos[i] == (float)o->common.isos[j])
                return tool_usage_error("isorender", "--iso %g is given twice", o->common.isos[i]);
    if (o->colour_count > n || o->opacity_count > n)
        return tool_usage_error("isorender",
                                "%zu --color and %zu --opacity for %u --iso: at most one of each "
                                "a surface",
                                o->colour_count, o->opacity_count, n);
    return 0;
}

/* The shortest "%g" text (6 to 9 significant digits) of the isovalue the engine extracts,
 * (float)iso, that reads back as that float: isovalues no two alike as floats (as
 * check_surface_options() wants them) get texts no two alike (100.0001 and 100.0002, not 100
 * twice), and 600.5 stays 600.5. */
static void iso_text(double iso, char *out, size_t size)
{
    float value = (float)iso;
    for (int digits = 6; digits <= 9; digits++) {
        snprintf(out, size, "%.*g", digits, (double)value);
        if ((float)strtod(out, NULL) == value)
            return;
    }
}

/* Whether the image needs the several-surface drawing: several --iso, or a translucent one. */
static int several_surfaces(const run *r)
{
    return r->other_count > 0 || (r->o.opacity_count && r->o.opacity[0] < 1.0f);
}

/* Surface i's run: r itself for the first. */
static run *surface_run(run *r, size_t i)
{
    return i ? &r->others[i - 1] : r;
}

static const run *surface_run_c(const run *r, size_t i)
{
    return i ? &r->others[i - 1] : r;
}

/* Surface i as the renderers take it: its mesh (its first prefix[i] triangles when prefix is
 * not NULL; `views` holds them), colour and opacity. */
static void surface_of(const run *r, size_t i, const uint64_t *prefix, ip_mesh *views,
                       ip_surface *out)
{
    const options *o = &r->o;
    views[i] = *surface_run_c(r, i)->mesh; /* a view of the triangles, not a copy */
    if (prefix)
        views[i].triangle_count = prefix[i];
    out->mesh = &views[i];
    const float *colour = i < o->colour_count ? o->colours[i]
                          : i == 0            ? o->shading.surface
                                              : surface_palette[i - 1];
    memcpy(out->colour, colour, sizeof out->colour);
    out->opacity = i < o->opacity_count ? o->opacity[i] : 1.0f;
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

/* A headless renderer of w x h pixels with the figure's shading and anti-aliasing. Returns
 * 0; 1 when there is no headless OpenGL (`why` says why); -1 when it refuses a setting. */
static int figure_renderer(const run *r, uint32_t w, uint32_t h, ip_renderer **gl, ip_error *why,
                           ip_error *err)
{
    *gl = NULL;
    if (ip_renderer_create_headless(w, h, gl, why) != IP_OK) {
        *gl = NULL;
        return 1;
    }
    ip_status st = ip_renderer_set_shading(*gl, &r->o.shading, err);
    if (st == IP_OK && r->o.aa > 1)
        st = ip_renderer_set_samples(*gl, r->o.aa, err);
    if (st == IP_OK)
        return 0;
    ip_renderer_destroy(*gl);
    *gl = NULL;
    return -1;
}

/* Draws `mesh` into rgba with `gl`, or in software when gl is NULL: the image, the strip's
 * frames and the turntable's all go through here. */
static ip_status draw_mesh(const run *r, ip_renderer *gl, const ip_mesh *mesh, uint8_t *rgba,
                           ip_error *err)
{
    if (!gl)
        return ip_raster_mesh_shaded(mesh, &r->camera, &r->o.shading, r->lo, r->hi, NULL, rgba,
                                     err);
    /* streamed: the driver never holds a second copy of the whole mesh */
    ip_status st = ip_renderer_draw_mesh(gl, mesh, &r->camera, r->lo, r->hi, err);
    return st == IP_OK ? ip_renderer_read_rgba(gl, rgba, err) : st;
}

/* Draws every surface (their first prefix[i] triangles when prefix is not NULL) into rgba
 * with `gl`, or in software when gl is NULL. */
static ip_status draw_surfaces(const run *r, ip_renderer *gl, const uint64_t *prefix, uint8_t *rgba,
                               ip_error *err)
{
    ip_mesh views[TOOL_MAX_ISOS];
    ip_surface surfaces[TOOL_MAX_ISOS];
    size_t count = 1 + r->other_count;
    for (size_t i = 0; i < count; i++)
        surface_of(r, i, prefix, views, &surfaces[i]);
    if (!gl)
        return ip_raster_surfaces(surfaces, count, &r->camera, &r->o.shading, r->lo, r->hi, rgba,
                                  err);
    ip_status st = ip_renderer_draw_surfaces(gl, surfaces, count, &r->camera, r->lo, r->hi, err);
    return st == IP_OK ? ip_renderer_read_rgba(gl, rgba, err) : st;
}

/* The image of the run's surfaces (prefix: as draw_surfaces()); one opaque surface is drawn
 * as it always was. */
static ip_status draw_image(const run *r, ip_renderer *gl, const uint64_t *prefix, uint8_t *rgba,
                            ip_error *err)
{
    if (several_surfaces(r))
        return draw_surfaces(r, gl, prefix, rgba, err);
    ip_mesh view = *r->mesh; /* a view of the first triangles, not a copy */
    if (prefix)
        view.triangle_count = prefix[0];
    return draw_mesh(r, gl, &view, rgba, err);
}

/* ---- the progress strip ---- */

/* Parses --strip-at's "P,P,..." (each a number with an optional '%'). Returns 0, or 2 after a
 * usage error. */
static int parse_strip_at(const char *program, const tool_option *option, const char *const *values,
                          void *base)
{
    strip_plan *plan = (strip_plan *)((char *)base + option->offset);
    const char *text = values[0];
    plan->count = 0;
    for (const char *at = text;; at++) {
        size_t len = strcspn(at, ",");
        char item[64];
        double pct;
        if (len >= sizeof item)
            len = sizeof item - 1;
        memcpy(item, at, len);
        item[len] = 0;
        if (len > 1 && item[len - 1] == '%')
            item[len - 1] = 0;
        if (tool_parse_double(item, &pct) != 0 || !(pct > 0 && pct <= 100))
            return tool_usage_error(program,
                                    "--strip-at '%s': '%.*s' is not a percentage in "
                                    "(0, 100]",
                                    text, (int)len, at);
        if (plan->count == STRIP_MAX_FRAMES)
            return tool_usage_error(program, "--strip-at '%s': more than %d frames", text,
                                    STRIP_MAX_FRAMES);
        if (plan->count && pct <= plan->pct[plan->count - 1])
            return tool_usage_error(program, "--strip-at '%s': the percentages must increase",
                                    text);
        plan->pct[plan->count++] = pct;
        at += strcspn(at, ",");
        if (!*at)
            return 0;
    }
}

/* The strip's checks after parsing, and its default frames. Returns 0, or 2 after a usage
 * error. */
static int check_strip_options(options *o)
{
    if (!o->strip) {
        if (o->strip_at.count)
            return tool_usage_error("isorender", "--strip-at needs --strip");
        return 0;
    }
    if (o->full || o->common.rays || o->common.time_limit > 0)
        return tool_usage_error("isorender", "--strip shows a progressive run to its last ray: "
                                             "no --full, --rays or --time");
    if (!o->strip_at.count)
        o->strip_at = (strip_plan){{0.01, 0.1, 1, 100}, 4};
    uint64_t width = (uint64_t)o->common.width * o->strip_at.count +
                     (uint64_t)STRIP_GAP * (o->strip_at.count - 1);
    if (width > STRIP_MAX_WIDTH)
        return tool_usage_error("isorender",
                                "--strip: %zu frames %u pixels wide make a strip "
                                "of %llu pixels, over %d",
                                o->strip_at.count, o->common.width, (unsigned long long)width,
                                STRIP_MAX_WIDTH);
    return 0;
}

/* Each frame's ray count, from its percentage of the view's rays (at least 1). */
static void strip_plan_rays(run *r)
{
    uint64_t total = (uint64_t)r->camera.width * r->camera.height;
    for (size_t f = 0; f < r->o.strip_at.count; f++) {
        uint64_t rays = (uint64_t)ceil(r->o.strip_at.pct[f] / 100.0 * (double)total);
        r->strip.rays[f] = rays < 1 ? 1 : rays > total ? total : rays;
    }
    r->strip.recorded = 0;
}

/* Where the next step must stop: `next`, or the ray count of an earlier frame not yet
 * reached. */
static uint64_t strip_stop(const run *r, uint64_t rays, uint64_t next)
{
    if (!r->o.strip)
        return next;
    for (size_t f = r->strip.recorded; f < r->o.strip_at.count; f++)
        if (r->strip.rays[f] > rays)
            return r->strip.rays[f] < next ? r->strip.rays[f] : next;
    return next;
}

/* After a step: the frames whose ray count is reached show the mesh as it is now. */
static void strip_record(run *r)
{
    if (!r->o.strip)
        return;
    ip_engine_counts t;
    ip_engine_totals(r->engine, &t);
    uint64_t triangles = ip_engine_mesh(r->engine)->triangle_count;
    while (r->strip.recorded < r->o.strip_at.count &&
           (r->strip.rays[r->strip.recorded] <= t.rays || ip_engine_done(r->engine)))
        r->strip.triangles[r->strip.recorded++] = triangles;
}

/* The triangles frame f of the strip shows, of every surface. */
static uint64_t strip_triangles(const run *r, size_t f)
{
    uint64_t sum = 0;
    for (size_t i = 0; i <= r->other_count; i++)
        sum += surface_run_c(r, i)->strip.triangles[f];
    return sum;
}

/* Frame f's label, "12 rays, 3456 triangles", or its short form when that is too wide for
 * the frame ("12 rays"; "" when even that is). */
static void strip_label(const run *r, size_t f, char *text, size_t size)
{
    snprintf(text, size, "%llu rays, %llu triangles", (unsigned long long)r->strip.rays[f],
             (unsigned long long)strip_triangles(r, f));
    if (ip_overlay_text_width(text, STRIP_TEXT_SCALE) + 8 > r->camera.width)
        snprintf(text, size, "%llu rays", (unsigned long long)r->strip.rays[f]);
    if (ip_overlay_text_width(text, STRIP_TEXT_SCALE) + 8 > r->camera.width)
        text[0] = 0;
}

/* Draws `text` into the strip's band, centred under the frame that starts at column x0 (the
 * render stage's text, as the figure overlays draw theirs). */
static ip_status strip_draw_label(uint8_t *rgba, uint32_t strip_width, uint32_t strip_height,
                                  uint32_t x0, uint32_t frame_width, const char *text,
                                  ip_error *err)
{
    static const uint8_t ink[3] = {226, 222, 206};
    int left =
        (int)x0 + ((int)frame_width - (int)ip_overlay_text_width(text, STRIP_TEXT_SCALE)) / 2;
    int top = (int)strip_height - STRIP_BAND + 4;
    return ip_overlay_draw_text(rgba, strip_width, strip_height, left, top, text, STRIP_TEXT_SCALE,
                                ink, NULL, err);
}

/* Fills err for a failed allocation of the strip. Returns -1. */
static int strip_out_of_memory(const run *r, ip_error *err)
{
    err->code = IP_ERR_NOMEM;
    snprintf(err->message, sizeof err->message, "%s: out of memory for the progress strip",
             r->o.strip);
    return -1;
}

/* Renders frame after frame (the mesh's first `triangles` of each) with the renderer of the
 * image, and copies each into its place in the strip. */
static int strip_render_frames(run *r, uint8_t *strip, uint32_t strip_width, ip_error *err)
{
    uint32_t w = r->camera.width, h = r->camera.height;
    uint8_t *frame = malloc((size_t)w * h * 4);
    ip_renderer *gl = NULL;
    if (!frame)
        return strip_out_of_memory(r, err);
    int rc = 0;
    if (!strcmp(r->renderer_name, "opengl") && figure_renderer(r, w, h, &gl, err, err) != 0)
        rc = -1;
    for (size_t f = 0; rc == 0 && f < r->o.strip_at.count; f++) {
        uint64_t prefix[TOOL_MAX_ISOS];
        for (size_t i = 0; i <= r->other_count; i++)
            prefix[i] = surface_run_c(r, i)->strip.triangles[f];
        if (draw_image(r, gl, prefix, frame, err) != IP_OK) {
            rc = -1;
            break;
        }
        size_t x0 = f * (w + STRIP_GAP);
        for (uint32_t y = 0; y < h; y++)
            memcpy(strip + ((size_t)y * strip_width + x0) * 4, frame + (size_t)y * w * 4,
                   (size_t)w * 4);
    }
    ip_renderer_destroy(gl);
    free(frame);
    return rc;
}

/* The strip's image: the frames over a dark band with their labels; *out is the caller's
 * (free()). Returns 0 or -1 with err set. */
static int strip_compose(run *r, uint8_t **out, uint32_t *width, uint32_t *height, ip_error *err)
{
    static const uint8_t band[4] = {14, 16, 22, 255};
    size_t n = r->o.strip_at.count;
    *width = (uint32_t)(n * r->camera.width + (n - 1) * STRIP_GAP);
    *height = r->camera.height + STRIP_BAND;
    uint8_t *rgba = malloc((size_t)*width * *height * 4);
    if (!rgba)
        return strip_out_of_memory(r, err);
    for (size_t p = 0; p < (size_t)*width * *height; p++)
        memcpy(rgba + p * 4, band, 4);
    if (strip_render_frames(r, rgba, *width, err) != 0) {
        free(rgba);
        return -1;
    }
    for (size_t f = 0; f < n; f++) {
        char text[64];
        strip_label(r, f, text, sizeof text);
        if (strip_draw_label(rgba, *width, *height, (uint32_t)(f * (r->camera.width + STRIP_GAP)),
                             r->camera.width, text, err) != IP_OK) {
            free(rgba);
            return -1;
        }
    }
    *out = rgba;
    return 0;
}

/* The summary's strip line. */
static void strip_print(FILE *out, const run *r)
{
    fprintf(out, "  strip         %s:", r->o.strip);
    for (size_t f = 0; f < r->o.strip_at.count; f++)
        fprintf(out, " %g%% (%llu triangles)", r->o.strip_at.pct[f],
                (unsigned long long)strip_triangles(r, f));
    fprintf(out, "\n");
}

/* ---- smoothing the mesh file ---- */

#define SMOOTH_MAX_ITERATIONS 100000

static int parse_smooth(const char *program, const tool_option *option, const char *const *values,
                        void *base)
{
    return tool_parse_bounded(program, option->name, values[0], 0, SMOOTH_MAX_ITERATIONS,
                              "an iteration count", &((options *)base)->smooth);
}

/* --smooth smooths a welded mesh file. Returns 0, or 2 after a usage error. */
static int check_smooth_options(const options *o)
{
    if (!o->smooth)
        return 0;
    if (!o->mesh)
        return tool_usage_error("isorender", "--smooth smooths the mesh file: it needs --mesh");
    if (o->no_weld)
        return tool_usage_error("isorender", "--smooth needs shared vertices: no --no-weld");
    return 0;
}

/* Smooths the welded mesh of the file by --smooth's iterations. Returns 0, or 1 after the
 * error. */
static int smooth_mesh(const run *r, ip_indexed_mesh *welded, ip_error *err)
{
    if (!r->o.smooth)
        return 0;
    if (ip_indexed_mesh_smooth_taubin(welded, (unsigned)r->o.smooth, IP_TAUBIN_LAMBDA, IP_TAUBIN_MU,
                                      err) != IP_OK)
        return tool_fail("isorender", err);
    return 0;
}

/* ---- the turntable ---- */

#define TURNTABLE_MAX_FRAMES 100000
#define TURNTABLE_FPS 25

static int parse_turntable(const char *program, const tool_option *option,
                           const char *const *values, void *base)
{
    return tool_parse_bounded(program, option->name, values[0], 1, TURNTABLE_MAX_FRAMES,
                              "a frame count", &((options *)base)->turntable);
}

/* -o's default, and the options a turntable cannot have. Returns 0, or 2 after a usage
 * error. */
static int check_turntable_options(options *o)
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

static int parse_args(int argc, char **argv, options *o)
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
    rc = check_smooth_options(o);
    if (rc)
        return rc;
    rc = check_turntable_options(o);
    if (rc)
        return rc;
    return check_strip_options(o);
}

static int setup_camera(run *r, ip_error *err)
{
    const ip_layout *l = ip_store_layout(r->store);
    ip_layout_world_box(l, r->lo, r->hi);
    if (tool_camera_of(r->o.common.camera, r->o.common.view, r->o.common.width, r->o.common.height,
                       r->lo, r->hi, &r->camera, err) != 0)
        return -1;
    r->view_camera = r->camera;
    tool_apply_orbit(&r->o.orbit, &r->camera);
    return 0;
}

static int add_checkpoint(run *r, double start)
{
    ip_engine_counts t;
    ip_engine_totals(r->engine, &t);
    checkpoint *grown = realloc(r->checkpoints, (r->checkpoint_count + 1) * sizeof *grown);
    if (!grown)
        return -1;
    r->checkpoints = grown;
    r->checkpoints[r->checkpoint_count++] =
        (checkpoint){ip_now_seconds() - start, t.rays, t.seeds, t.cells, t.triangles, 0, 0};
    return 0;
}

/* After each step: the bar (rays done of those asked for, triangles so far) and, with
 * --verbose, the step's counts on a line of their own. */
static void step_report(const run *r, tool_progress *bar, uint64_t limit)
{
    ip_engine_counts t;
    ip_engine_totals(r->engine, &t);
    uint64_t pixels = (uint64_t)r->camera.width * r->camera.height;
    uint64_t total = limit < pixels ? limit : pixels;
    char detail[48];
    snprintf(detail, sizeof detail, "%llu triangles", (unsigned long long)t.triangles);
    tool_progress_draw(bar, ip_engine_done(r->engine) ? total : t.rays, total, "rays", detail);
    if (r->o.common.verbose) {
        tool_progress_end(bar);
        fprintf(
            stderr,
            "isorender: step: %llu rays (%llu retired), %llu seeds, %llu cells, %llu triangles, "
            "%.3f s\n",
            (unsigned long long)t.rays, (unsigned long long)t.retired, (unsigned long long)t.seeds,
            (unsigned long long)t.cells, (unsigned long long)t.triangles,
            tool_progress_elapsed(bar));
    }
}

/* The engine with the command line's options, cancelled by a signal; made once. */
static int create_engine(run *r, ip_error *err)
{
    if (r->engine)
        return 0;
    ip_engine_options eo;
    tool_engine_options(&r->o.common, &eo);
    if (ip_engine_create(r->cache, &eo, &r->engine, err) != IP_OK)
        return -1;
    tool_signals_cancel_engine(r->engine);
    return 0;
}

/* Casts rays until done, the ray count or the time limit, checkpointing as the count doubles. */
static int extract_progressive(run *r, ip_error *err)
{
    if (create_engine(r, err) != 0)
        return -1;
    if (r->o.warm) { /* the same work once, untimed: the bricks it needs stay in the cache */
        if (ip_engine_begin(r->engine, &r->camera, (float)r->o.common.iso, err) != IP_OK ||
            ip_engine_step(r->engine, r->o.common.rays, r->o.common.time_limit, NULL, err) != IP_OK)
            return -1;
    }
    strip_plan_rays(r);
    double start = ip_now_seconds(); /* a view's time counts its set-up (the coverage buffer) */
    if (ip_engine_begin(r->engine, &r->camera, (float)r->o.common.iso, err) != IP_OK)
        return -1;
    uint64_t target = 1, limit = r->o.common.rays ? r->o.common.rays : UINT64_MAX;
    tool_progress bar;
    tool_progress_start(&bar, !r->o.common.quiet, "ISORENDER_PROGRESS");
    /* ip_engine_begin() clears a cancel: a signal before it is seen through the flag */
    while (!ip_engine_done(r->engine) && !tool_signal_caught()) {
        ip_engine_counts t;
        ip_engine_totals(r->engine, &t);
        if (t.rays >= limit)
            break;
        double left =
            r->o.common.time_limit > 0 ? r->o.common.time_limit - (ip_now_seconds() - start) : 0;
        if (r->o.common.time_limit > 0 && left <= 0)
            break;
        uint64_t next = target < limit ? target : limit, stop = strip_stop(r, t.rays, next);
        if (ip_engine_step(r->engine, stop - t.rays, left, NULL, err) != IP_OK) {
            tool_progress_end(&bar);
            return -1;
        }
        step_report(r, &bar, limit);
        strip_record(r);
        if (stop < next && !ip_engine_done(r->engine))
            continue; /* a frame of the strip, between two checkpoints */
        if (add_checkpoint(r, start) != 0) {
            tool_progress_end(&bar);
            return -1;
        }
        target *= 2;
    }
    tool_progress_end(&bar);
    r->extraction_wall = ip_now_seconds() - start;
    ip_engine_totals(r->engine, &r->totals);
    r->mesh = ip_engine_mesh(r->engine);
    return 0;
}

/* --full (level 0) or --full-lod (the view's levels, each in its band) into r->full_mesh. */
static ip_status full_extraction(run *r, ip_engine_counts *counts, ip_error *err)
{
    return tool_full_extraction(r->cache, r->o.common.iso, r->o.full, &r->camera, &r->o.common,
                                &r->full_mesh, counts, err);
}

static int extract_full(run *r, ip_error *err)
{
    ip_mesh_init(&r->full_mesh);
    if (r->o.warm) {
        if (full_extraction(r, NULL, err) != IP_OK)
            return -1;
        ip_mesh_clear(&r->full_mesh);
    }
    double start = ip_now_seconds();
    if (full_extraction(r, &r->totals, err) != IP_OK)
        return -1;
    r->extraction_wall = ip_now_seconds() - start;
    r->mesh = &r->full_mesh;
    return 0;
}

/* What the surfaces' runs share with the first: the store, the cache and the view. */
static void share_view(const run *r, run *s)
{
    if (s == r)
        return;
    s->store = r->store;
    s->cache = r->cache;
    s->camera = r->camera;
    s->view_camera = r->view_camera;
    memcpy(s->lo, r->lo, sizeof s->lo);
    memcpy(s->hi, r->hi, sizeof s->hi);
}

/* Extracts every surface, one run after the other, each with the same view and options. */
static int extract_surfaces(run *r, ip_error *err)
{
    for (size_t i = 0; i <= r->other_count; i++) {
        run *s = surface_run(r, i);
        if (i && tool_signal_caught()) { /* the later surfaces have no mesh: stop here */
            err->code = IP_ERR_CANCELLED;
            snprintf(err->message, sizeof err->message, "cancelled");
            return -1;
        }
        share_view(r, s);
        if ((s->o.full ? extract_full(s, err) : extract_progressive(s, err)) != 0)
            return -1;
    }
    return 0;
}

/* The triangles of every surface. */
static uint64_t all_triangles(const run *r)
{
    uint64_t sum = 0;
    for (size_t i = 0; i <= r->other_count; i++)
        sum += surface_run_c(r, i)->mesh->triangle_count;
    return sum;
}

/* The first checkpoint whose mesh holds triangle i (checkpoint_count when none). */
static size_t checkpoint_of(const run *r, uint64_t i)
{
    size_t lo = 0, hi = r->checkpoint_count;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (r->checkpoints[mid].triangles > i)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

/* Final pixels of every checkpoint from one raster of the final mesh: a pixel has its final
 * colour at a checkpoint when the triangle it finally shows was already extracted (the mesh
 * only grows by appending, and the nearest triangle wins). The same raster gives the visible
 * triangles, those that own at least one pixel of the final image, in all and as extracted
 * by each checkpoint: overdraw = triangles extracted / visible triangles. */
static int final_pixels(run *r, ip_error *err)
{
    double start = ip_now_seconds();
    size_t n = (size_t)r->camera.width * r->camera.height;
    uint32_t *index = malloc(n * sizeof *index);
    if (!index)
        return -1;
    if (ip_raster_mesh(r->mesh, &r->camera, r->lo, r->hi, index, NULL, err) != IP_OK) {
        free(index);
        return -1;
    }
    uint64_t covered = 0;
    for (size_t c = 0; c < r->checkpoint_count; c++)
        r->checkpoints[c].final_pct = 0;
    uint64_t *shown = calloc(r->checkpoint_count + 1, sizeof *shown);
    uint64_t *owners = calloc(r->checkpoint_count + 1, sizeof *owners);
    uint8_t *owns = calloc(r->mesh->triangle_count / 8 + 1, 1); /* a bit per triangle */
    if (!shown || !owners || !owns) {
        free(shown);
        free(owners);
        free(owns);
        free(index);
        return -1;
    }
    r->visible_triangles = 0;
    for (size_t p = 0; p < n; p++) {
        uint32_t i = index[p];
        if (i == UINT32_MAX)
            continue;
        covered++;
        size_t c = checkpoint_of(r, i);
        shown[c]++;
        if (!(owns[i / 8] & (1u << (i % 8)))) {
            owns[i / 8] |= (uint8_t)(1u << (i % 8));
            owners[c]++;
            r->visible_triangles++;
        }
    }
    uint64_t running = 0, visible = 0;
    for (size_t c = 0; c < r->checkpoint_count; c++) {
        running += shown[c];
        visible += owners[c];
        r->checkpoints[c].final_pct = covered ? 100.0 * (double)running / (double)covered : 100.0;
        r->checkpoints[c].visible = visible;
    }
    r->owners_known = 1;
    free(shown);
    free(owners);
    free(owns);
    free(index);
    r->progress_render_seconds = ip_now_seconds() - start;
    return 0;
}

/* Triangles extracted per visible triangle; 0 when none is visible. */
static double overdraw(uint64_t triangles, uint64_t visible)
{
    return visible ? (double)triangles / (double)visible : 0.0;
}

static void progress_csv(FILE *f, void *user)
{
    const run *r = user;
    /* the columns scripts read come first, unchanged; later ones are appended: with several
     * surfaces, the isovalue, each surface's rows after the previous one's */
    fprintf(f, "time_s,rays,seeds,cells,triangles,final_pixel_pct,visible_triangles,overdraw%s\n",
            r->other_count ? ",iso" : "");
    for (size_t i = 0; i <= r->other_count; i++) {
        const run *s = surface_run_c(r, i);
        for (size_t c = 0; c < s->checkpoint_count; c++) {
            const checkpoint *k = &s->checkpoints[c];
            fprintf(f, "%.6f,%llu,%llu,%llu,%llu,%.4f,%llu,%.4f", k->time,
                    (unsigned long long)k->rays, (unsigned long long)k->seeds,
                    (unsigned long long)k->cells, (unsigned long long)k->triangles, k->final_pct,
                    (unsigned long long)k->visible, overdraw(k->triangles, k->visible));
            if (r->other_count)
                fprintf(f, ",%.9g", s->o.common.iso);
            fprintf(f, "\n");
        }
    }
}

/* ---- the figure overlays: --axes and --scale-bar ---- */

/* The scale bar's unit: --scale-unit, else mm in a named anatomical space (DICOM, NIfTI and
 * NRRD state lengths in millimetres there), else "units". */
static const char *scale_unit(const run *r)
{
    if (r->o.scale_unit)
        return r->o.scale_unit;
    return ip_store_layout(r->store)->orientation.space != IP_SPACE_UNKNOWN ? "mm" : "units";
}

/* Draws the overlays asked for into the rendered image; with --verbose, says what they show
 * and where. */
static ip_status draw_overlays(run *r, uint8_t *rgba, ip_error *err)
{
    const ip_orientation *space = &ip_store_layout(r->store)->orientation;
    uint32_t box[4], bar_box[4];
    if (r->o.axes) {
        if (ip_overlay_draw_axes(rgba, &r->camera, space, box, err) != IP_OK)
            return err->code;
        if (r->o.common.verbose) {
            double screen[3][3];
            ip_overlay_axis_directions(&r->camera, space, screen);
            fprintf(stderr, "isorender: axes: box %u,%u to %u,%u;", box[0], box[1], box[2], box[3]);
            for (int a = 0; a < 3; a++) {
                for (int k = 0; k < 3; k++) /* no "-0.0000" */
                    screen[a][k] = fabs(screen[a][k]) < 5e-5 ? 0.0 : screen[a][k];
                fprintf(stderr, " %s %+.4f,%+.4f,%+.4f", ip_overlay_axis_label(space->space, a),
                        screen[a][0], screen[a][1], screen[a][2]);
            }
            fprintf(stderr, " (right, down, toward the eye)\n");
        }
    }
    if (r->o.scale_bar) {
        if (ip_scale_bar_choose(&r->camera, r->camera.width / 4.0, &r->bar, err) != IP_OK ||
            ip_overlay_draw_scale_bar(rgba, &r->camera, &r->bar, scale_unit(r), box, bar_box,
                                      err) != IP_OK) {
            static const char prefix[] = "scale bar: "; /* the library's; the option's instead */
            char text[sizeof err->message];
            if (!strncmp(err->message, prefix, strlen(prefix))) {
                snprintf(text, sizeof text, "%s: --scale-bar: %s", r->o.file,
                         err->message + strlen(prefix));
                memcpy(err->message, text, sizeof text);
            }
            return err->code;
        }
        if (r->o.common.verbose)
            fprintf(stderr,
                    "isorender: scale bar: %g %s = %.3f pixels (%.6g %s a pixel at the "
                    "target's depth); bar %u,%u to %u,%u; box %u,%u to %u,%u\n",
                    r->bar.length, scale_unit(r), r->bar.pixels, r->bar.pixel_size, scale_unit(r),
                    bar_box[0], bar_box[1], bar_box[2], bar_box[3], box[0], box[1], box[2], box[3]);
    }
    return IP_OK;
}

/* Renders with OpenGL through EGL, or in software when asked or when no OpenGL is found.
 * With `keep` (the turntable's frames), the OpenGL renderer the first call makes stays in
 * *keep for the next calls, and the caller destroys it; without, it goes at the end. */
static int render_image(run *r, uint8_t *rgba, ip_renderer **keep, ip_error *err)
{
    double start = ip_now_seconds();
    ip_renderer *gl = keep ? *keep : NULL;
    if (!gl && !r->o.software) {
        ip_error why;
        int made = figure_renderer(r, r->camera.width, r->camera.height, &gl, &why, err);
        if (made < 0)
            return -1; /* a setting OpenGL refuses: not a reason to draw something else */
        if (made > 0)
            fprintf(stderr, "isorender: no headless OpenGL (%s); rendering in software\n",
                    why.message);
        /* auto: OpenGL that is itself software draws slower than the exact rasterizer */
        if (gl && r->o.renderer == TOOL_RENDERER_AUTO && r->o.aa <= 1 &&
            ip_gl_driver_is_software(ip_renderer_driver(gl))) {
            ip_renderer_destroy(gl);
            gl = NULL;
            r->o.software = 1; /* the turntable's next frames and the strip: the same */
        }
    }
    r->renderer_name = gl ? "opengl" : "software";
    ip_status st = draw_image(r, gl, NULL, rgba, err);
    if (keep)
        *keep = gl;
    else
        ip_renderer_destroy(gl);
    if (st == IP_OK)
        st = draw_overlays(r, rgba, err);
    r->totals.rendering_seconds += ip_now_seconds() - start;
    return st == IP_OK ? 0 : -1;
}

/* A run's "final_pixel_pct" (with checkpoints) and "visible_triangles" and "overdraw" (with
 * the triangles' owners known), as JSON members. */
static void json_quality(FILE *f, const run *r)
{
    if (r->checkpoint_count)
        fprintf(f, ", \"final_pixel_pct\": %.4f",
                r->checkpoints[r->checkpoint_count - 1].final_pct);
    if (r->owners_known)
        fprintf(f, ", \"visible_triangles\": %llu, \"overdraw\": %.4f",
                (unsigned long long)r->visible_triangles,
                overdraw(r->mesh->triangle_count, r->visible_triangles));
}

/* "surfaces": each surface's isovalue, colour, opacity, counts and mesh file. */
static void json_surfaces(FILE *f, const run *r)
{
    ip_mesh views[TOOL_MAX_ISOS];
    fprintf(f, ", \"surfaces\": [");
    for (size_t i = 0; i <= r->other_count; i++) {
        const run *s = surface_run_c(r, i);
        const ip_engine_counts *t = &s->totals;
        ip_surface look;
        surface_of(r, i, NULL, views, &look);
        fprintf(f,
                "%s{\"iso\": %.9g, \"color\": \"#%02x%02x%02x\", \"opacity\": %g, "
                "\"rays\": %llu, \"done\": %s, \"seeds\": %llu, \"cells\": %llu, "
                "\"triangles\": %llu, \"extraction_wall_s\": %.6f",
                i ? ", " : "", s->o.common.iso, (unsigned)lround(255 * look.colour[0]),
                (unsigned)lround(255 * look.colour[1]), (unsigned)lround(255 * look.colour[2]),
                (double)look.opacity, (unsigned long long)t->rays,
                s->o.full || (s->engine && ip_engine_done(s->engine)) ? "true" : "false",
                (unsigned long long)t->seeds, (unsigned long long)t->cells,
                (unsigned long long)t->triangles, s->extraction_wall);
        json_quality(f, s);
        if (!s->o.full)
            fprintf(f, ", \"deferred_cells\": %llu", (unsigned long long)t->deferred);
        if (s->o.mesh) {
            fprintf(f, ", \"mesh\": ");
            tool_json_string(f, s->o.mesh);
        }
        fprintf(f, "}");
    }
    fprintf(f, "]");
}

static void json_counts(FILE *f, void *user)
{
    const run *r = user;
    const tool_run_json j = {r->o.file,
                             r->o.common.iso,
                             r->o.full,
                             &r->camera,
                             r->renderer_name ? r->renderer_name : "none",
                             &r->o.common,
                             r->o.warm,
                             r->o.full || (r->engine && ip_engine_done(r->engine)),
                             &r->totals,
                             r->totals.rendering_seconds,
                             r->extraction_wall,
                             r->progress_render_seconds};
    tool_write_run_json(f, &j);
    json_quality(f, r);
    if (r->o.scale_bar) {
        fprintf(f, ", \"scale_bar\": {\"length\": %.17g, \"unit\": ", r->bar.length);
        tool_json_string(f, scale_unit(r));
        fprintf(f, ", \"pixel_size\": %.17g, \"pixels\": %.17g}", r->bar.pixel_size, r->bar.pixels);
    }
    if (!r->o.full) {
        fprintf(f,
                ", \"occlusion\": %s, \"deferred_cells\": %llu, \"retired_rays\": %llu, "
                "\"ray_nodes\": %llu, \"prefetch\": %s, \"prefetch_mode\": \"%s\", \"cull\": %s, "
                "\"culled_triangles\": %llu",
                r->o.common.occlusion ? "true" : "false", (unsigned long long)r->totals.deferred,
                (unsigned long long)r->totals.retired, (unsigned long long)r->totals.nodes,
                r->o.common.prefetch ? "true" : "false", tool_prefetch_name(r->o.common.prefetch),
                r->o.common.occlusion && r->o.common.cull ? "true" : "false",
                (unsigned long long)r->totals.culled);
    }
    fprintf(f, ", \"warnings\": [");
    for (size_t i = 0, written = 0; i <= r->other_count; i++) {
        const run *s = surface_run_c(r, i);
        if (!s->warning[0])
            continue;
        fprintf(f, "%s", written++ ? ", " : "");
        tool_json_string(f, s->warning);
    }
    fprintf(f, "]");
    if (r->other_count)
        json_surfaces(f, r);
}

/* The summary's lines of surface run s (r: the first surface's, which knows the renderer and
 * the image's rendering time: with several surfaces, given once after them). */
static void print_counts(FILE *out, const run *s, const run *r)
{
    const ip_engine_counts *t = &s->totals;
    fprintf(out, "  rays          %llu of %llu", (unsigned long long)t->rays,
            (unsigned long long)r->camera.width * r->camera.height);
    if (!s->o.full)
        fprintf(out, " (%llu retired without a walk; %llu nodes walked)",
                (unsigned long long)t->retired, (unsigned long long)t->nodes);
    fprintf(out, "\n");
    fprintf(out, "  seeds         %llu\n", (unsigned long long)t->seeds);
    fprintf(out, "  cells         %llu\n", (unsigned long long)t->cells);
    fprintf(out, "  triangles     %llu\n", (unsigned long long)t->triangles);
    if (s->owners_known)
        fprintf(out, "  visible       %llu triangles own a pixel: overdraw %.2f\n",
                (unsigned long long)s->visible_triangles,
                overdraw(s->mesh->triangle_count, s->visible_triangles));
    fprintf(out,
            "  time          %.3f s extraction (wall); CPU s summed over %u threads: "
            "intersection %.3f, propagation %.3f, marching cubes %.3f",
            s->extraction_wall, ip_thread_count(s->o.common.threads), t->intersection_seconds,
            t->propagation_seconds, t->extraction_seconds);
    if (!r->other_count)
        fprintf(out, "; rendering %.3f s (%s)", t->rendering_seconds, r->renderer_name);
    fprintf(out, "\n");
}

static void print_summary(FILE *out, const run *r)
{
    if (!r->other_count) {
        fprintf(out, "%s: iso %g, %s, %ux%u\n", r->o.file, r->o.common.iso,
                r->o.full ? "full extraction" : "progressive", r->camera.width, r->camera.height);
        print_counts(out, r, r);
    } else {
        fprintf(out, "%s: %zu surfaces, %s, %ux%u\n", r->o.file, r->other_count + 1,
                r->o.full ? "full extraction" : "progressive", r->camera.width, r->camera.height);
        for (size_t i = 0; i <= r->other_count; i++) {
            char iso[32];
            iso_text(surface_run_c(r, i)->o.common.iso, iso, sizeof iso);
            fprintf(out, "  surface %zu     iso %s\n", i + 1, iso);
            print_counts(out, surface_run_c(r, i), r);
        }
        fprintf(out, "  rendering     %.3f s (%s), the surfaces together\n",
                r->totals.rendering_seconds, r->renderer_name);
    }
    fprintf(out, "  image         %s\n", r->o.out);
    for (size_t i = 0; i <= r->other_count; i++) {
        const run *s = surface_run_c(r, i);
        if (s->o.mesh)
            fprintf(out, "  mesh          %s: %llu triangles, %llu vertices%s%s\n", s->o.mesh,
                    (unsigned long long)(s->mesh->triangle_count - s->mesh_dropped),
                    (unsigned long long)s->mesh_vertices,
                    s->mesh_vertices < 3 * s->mesh->triangle_count ? " (shared)" : "",
                    s->o.smooth ? ", smoothed" : "");
    }
}

/* Writes `mesh` to the mesh file: welded (shared vertices) unless --no-weld or STL (which is
 * welded for --smooth, then written with its corners repeated). A progressive run's mesh is
 * only what the view needed, which a note says. */
static int write_mesh_as(run *r, const ip_mesh *mesh, ip_error *err)
{
    const char *format = ip_mesh_format_of(r->o.mesh);
    ip_status st;
    int stl = strcmp(format, "STL") == 0;
    if (r->o.no_weld || (stl && !r->o.smooth)) {
        st = ip_mesh_write(mesh, r->o.mesh, r->o.common.force, err);
        r->mesh_vertices = 3 * mesh->triangle_count;
    } else {
        ip_indexed_mesh welded;
        st = ip_mesh_weld(mesh, &welded);
        if (st != IP_OK) {
            fprintf(stderr, "isorender: %s: cannot weld %llu triangles (%s)\n", r->o.mesh,
                    (unsigned long long)mesh->triangle_count, ip_status_message(st));
            return 1;
        }
        if (smooth_mesh(r, &welded, err) != 0) {
            ip_indexed_mesh_free(&welded);
            return 1;
        }
        st = ip_indexed_mesh_write(&welded, r->o.mesh, r->o.common.force, err);
        r->mesh_vertices = stl ? 3 * welded.triangle_count : welded.vertex_count;
        r->mesh_dropped = welded.dropped_triangles;
        ip_indexed_mesh_free(&welded);
    }
    if (st != IP_OK)
        return tool_fail("isorender", err);
    if (!r->o.full && !r->o.common.quiet)
        fprintf(stderr,
                "isorender: note: %s holds only the surface this view needed (open "
                "behind); --full --mesh writes the whole, closed surface\n",
                r->o.mesh);
    return 0;
}

/* The mesh goes out in the volume's physical space (origin, directions: docs/format.md); a
 * copy is moved there, unless the file's space is the engine's own. */
static int write_mesh(run *r, ip_error *err)
{
    const ip_orientation *space = &ip_store_layout(r->store)->orientation;
    if (ip_orientation_is_identity(space))
        return write_mesh_as(r, r->mesh, err);
    ip_mesh physical;
    ip_mesh_init(&physical);
    if (ip_mesh_append_mesh(&physical, r->mesh, 0, r->mesh->triangle_count) != IP_OK) {
        fprintf(stderr, "isorender: %s: out of memory\n", r->o.mesh);
        ip_mesh_free(&physical);
        return 1;
    }
    ip_mesh_to_physical(&physical, space);
    int rc = write_mesh_as(r, &physical, err);
    ip_mesh_free(&physical);
    return rc;
}

/* Frees the decoded bricks once extraction is over: the image needs only the mesh, and
 * rendering a large one needs memory of its own. The statistics are taken before. */
static void drop_bricks(run *r)
{
    ip_cache_trim(r->cache, 0);
#ifdef __GLIBC__
    malloc_trim(0); /* give the freed bricks back to the system now */
#endif
}

/* Renders, then writes every output (each all-or-nothing). A signal caught before the
 * writing starts means no output at all. */
static int finish(run *r, ip_error *err)
{
    ip_cache_stats st;
    ip_cache_get_stats(r->cache, &st);
    drop_bricks(r);
    size_t n = (size_t)r->camera.width * r->camera.height;
    uint8_t *rgba = malloc(n * 4);
    if (!rgba) {
        fprintf(stderr, "isorender: out of memory for a %ux%u image\n", r->camera.width,
                r->camera.height);
        return 1;
    }
    int rc = render_image(r, rgba, NULL, err);
    uint8_t *strip = NULL;
    uint32_t strip_width = 0, strip_height = 0;
    if (rc == 0 && r->o.strip && strip_compose(r, &strip, &strip_width, &strip_height, err) != 0)
        rc = -1;
    for (size_t i = 0; i <= r->other_count; i++)
        if (rc == 0 && ((r->o.progress && !r->o.full) || r->o.common.stats) &&
            final_pixels(surface_run(r, i), err) != 0)
            rc = -1;
    if (rc != 0 || tool_signal_caught()) {
        free(rgba);
        free(strip);
        return rc != 0 ? tool_fail("isorender", err) : 1;
    }
    r->writing = 1;
    if (ip_png_write(r->o.out, rgba, r->camera.width, r->camera.height, r->o.common.force, err) !=
        IP_OK)
        rc = -1;
    free(rgba);
    if (rc == 0 && strip &&
        ip_png_write(r->o.strip, strip, strip_width, strip_height, r->o.common.force, err) != IP_OK)
        rc = -1;
    free(strip);
    if (rc != 0)
        return tool_fail("isorender", err);
    for (size_t i = 0; i <= r->other_count; i++)
        if (r->o.mesh && write_mesh(surface_run(r, i), err) != 0)
            return 1;
    if (r->o.progress && !r->o.full &&
        tool_write_text_file("isorender", r->o.progress, r->o.common.force, progress_csv, r) != 0)
        return 1;
    uint64_t summary = ip_store_summary_memory(r->store);
    /* with --stats - or --progress -, stdout holds that output alone: the summary goes to
     * stderr */
    FILE *report =
        tool_is_stdout(r->o.common.stats) || tool_is_stdout(r->o.progress) ? stderr : stdout;
    if (!r->o.common.quiet) {
        print_summary(report, r);
        if (r->o.strip)
            strip_print(report, r);
        tool_print_cache_table(report, &st, summary);
    }
    if (r->o.common.stats &&
        tool_write_stats_file("isorender", r->o.common.stats, r->o.common.force, &st, summary,
                              json_counts, r) != 0)
        return 1;
    return 0;
}

/* ---- the turntable's frames ---- */

/* Frame f's camera: the azimuth turned by f / N of a full turn (about the view's own up axis,
 * before the elevation, so that the volume turns as on a potter's wheel). */
static void turntable_camera(const run *r, uint64_t f, ip_camera *camera)
{
    tool_orbit_options orbit = r->o.orbit;
    orbit.azimuth += 360.0 * (double)f / (double)r->o.turntable;
    *camera = r->view_camera;
    tool_apply_orbit(&orbit, camera);
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
    if (ip_engine_begin(r->engine, &r->camera, (float)r->o.common.iso, err) != IP_OK ||
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
static int turntable_encode(const run *r)
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
    if (error == ENOENT) {
        fprintf(stderr,
                "isorender: ffmpeg not found: frames are in %s; install ffmpeg to get an MP4\n",
                r->o.out);
        return 1;
    }
    if (error != 0 || waitpid(pid, &status, 0) != pid || !WIFEXITED(status) ||
        WEXITSTATUS(status) != 0) {
        fprintf(stderr, "isorender: %s: ffmpeg failed; frames are in %s\n", r->o.mp4, r->o.out);
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
    r->writing = 1;
    if (ip_png_write(path, rgba, r->camera.width, r->camera.height, r->o.common.force, err) !=
        IP_OK)
        return -1;
    if (!r->o.common.quiet)
        printf("  frame %llu of %llu: %s, %llu triangles\n", (unsigned long long)f + 1,
               (unsigned long long)r->o.turntable, path, (unsigned long long)all_triangles(r));
    return 0;
}

/* --turntable N: N frames, each a complete image, the eye turned 360 / N degrees more in
 * azimuth each time, in the folder -o names (made when absent); then the MP4 when asked. */
static int turntable_run(run *r, ip_error *err)
{
    if (mkdir(r->o.out, 0777) != 0 && errno != EEXIST) {
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
    return r->o.mp4 ? turntable_encode(r) : 0;
}

/* The mesh file of the surface of isovalue `iso`: `path` with "_isoV" before its extension
 * (head.ply: head_iso600.5.ply; V as iso_text() gives it). Returns 0, or 2 after a usage
 * error. */
static int surface_mesh_name(const char *path, double iso, char *out, size_t size)
{
    const char *slash = strrchr(path, '/'), *dot = strrchr(path, '.');
    if (!dot || (slash && dot < slash))
        dot = path + strlen(path);
    char value[32];
    iso_text(iso, value, sizeof value);
    int length = snprintf(out, size, "%.*s_iso%s%s", (int)(dot - path), path, value, dot);
    if (length < 0 || (size_t)length >= size)
        return tool_usage_error("isorender", "--mesh %s: the name is too long", path);
    return 0;
}

/* The surfaces' runs after the first (several --iso), copies of its options with their own
 * isovalues, and with --mesh each surface's file name. Returns 0, 1 (out of memory) or 2
 * (a usage error). */
static int setup_surfaces(run *r)
{
    size_t n = r->o.common.iso_count;
    r->o.common.iso = r->o.common.isos[0]; /* the first --iso is the first surface's */
    if (n < 2)
        return 0;
    r->others = calloc(n - 1, sizeof *r->others);
    if (!r->others) {
        fprintf(stderr, "isorender: out of memory\n");
        return 1;
    }
    r->other_count = n - 1;
    for (size_t i = 1; i < n; i++) {
        r->others[i - 1].o = r->o;
        r->others[i - 1].o.common.iso = r->o.common.isos[i];
    }
    for (size_t i = 0; r->o.mesh && i < n; i++) {
        run *s = surface_run(r, n - 1 - i); /* the first last: its name is the template */
        if (surface_mesh_name(r->o.mesh, s->o.common.iso, s->mesh_name, sizeof s->mesh_name))
            return 2;
        s->o.mesh = s->mesh_name;
    }
    return 0;
}

/* Frees what the surfaces' runs after the first hold. */
static void free_surfaces(run *r)
{
    for (size_t i = 0; i < r->other_count; i++) {
        ip_engine_destroy(r->others[i].engine);
        ip_mesh_free(&r->others[i].full_mesh);
        free(r->others[i].checkpoints);
    }
    free(r->others);
}

int main(int argc, char **argv)
{
    run r;
    memset(&r, 0, sizeof r);
    int rc = parse_args(argc, argv, &r.o);
    const char *mesh_option = r.o.mesh; /* as given: setup_surfaces() may name it per surface */
    if (!rc)
        rc = setup_surfaces(&r);
    if (rc) {
        free_surfaces(&r);
        return rc;
    }
    const char *inputs[] = {r.o.file};
    const char *outputs[5 + TOOL_MAX_ISOS - 1] = {r.o.turntable ? r.o.mp4 : r.o.out, r.o.mesh,
                                                  r.o.common.stats, r.o.full ? NULL : r.o.progress,
                                                  r.o.strip};
    for (size_t i = 0; i < r.other_count; i++)
        outputs[5 + i] = r.others[i].o.mesh;
    if (tool_check_paths("isorender", inputs, 1, outputs, 5 + r.other_count, r.o.common.force) !=
        0) {
        free_surfaces(&r);
        return 1;
    }
    if (r.o.mesh && !ip_mesh_format_of(r.o.mesh)) { /* before any work, after the paths' checks */
        free_surfaces(&r);
        return tool_usage_error(
            "isorender", "--mesh %s: the name must end in .ply, .stl, .obj or .glb", mesh_option);
    }
    tool_signals_catch();
    ip_error err;
    ip_error_clear(&err);
    if (ip_store_open(r.o.file, &r.store, &err) != IP_OK) {
        rc = tool_fail("isorender", &err);
        free_surfaces(&r);
        tool_signals_reraise();
        return rc;
    }
    rc = 1;
    if (ip_cache_create(r.store, r.o.common.cache_bytes, &r.cache, &err) != IP_OK ||
        setup_camera(&r, &err) != 0) {
        rc = tool_fail("isorender", &err);
    } else {
        /* the errors above come first: a bad command line is one line, not a warning too */
        for (size_t i = 0; i <= r.other_count; i++) {
            run *s = surface_run(&r, i);
            tool_warn_iso_range("isorender", r.store, s->o.common.iso, s->warning,
                                sizeof s->warning);
        }
        if (r.o.turntable)
            rc = turntable_run(&r, &err);
        else if (extract_surfaces(&r, &err) == 0)
            rc = finish(&r, &err);
        else if (!(err.code == IP_ERR_CANCELLED && tool_signal_caught()))
            rc = tool_fail("isorender", &err); /* a cancel by a signal is reported below */
    }
    tool_signals_cancel_engine(NULL);
    if (tool_signal_caught() && !r.writing)
        fprintf(stderr, "isorender: %s: cancelled; no output written\n", r.o.file);
    free_surfaces(&r);
    ip_engine_destroy(r.engine);
    ip_mesh_free(&r.full_mesh);
    free(r.checkpoints);
    ip_cache_destroy(r.cache);
    ip_store_close(r.store);
    tool_signals_reraise();
    return rc;
}

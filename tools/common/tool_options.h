/* SPDX-License-Identifier: BSD-3-Clause */
/* The shared options: parsers for option tables; isorender's and isoview's view options. */
#ifndef ISOPROP_TOOL_OPTIONS_H
#define ISOPROP_TOOL_OPTIONS_H

#include <stddef.h>
#include <stdint.h>

#include "isoprop/cache.h"
#include "isoprop/camera.h"
#include "isoprop/engine.h"
#include "isoprop/layout.h"
#include "isoprop/status.h"
#include "tool_command_line.h"

/* Parsers for tables: a finite number, a number > 0, and a number >= 0, into the double at
 * base + offset; a bad value is "NAME 'VALUE' PROBLEM" (option->problem). */
tool_option_parse tool_option_number, tool_option_positive, tool_option_non_negative;

/* An on|off switch into the int at base + offset (1 or 0); a bad value is "NAME must be on or
 * off". */
tool_option_parse tool_option_on_off;

/* --renderer auto|opengl|software (isorender, isoview) into the int at base + offset: */
enum {
    TOOL_RENDERER_AUTO, /* software where OpenGL is itself software (ip_gl_driver_is_software()) */
    TOOL_RENDERER_OPENGL,  /* OpenGL */
    TOOL_RENDERER_SOFTWARE /* the exact software rasterizer */
};
/* A bad value is "--renderer 'VALUE': must be auto, opengl or software". */
tool_option_parse tool_option_renderer;

/* Parses --cache-mb N (tool_parse_cache_mb()) into the uint64_t (bytes) at base + offset; a
 * bad value is "bad --cache-mb 'VALUE'". */
tool_option_parse tool_option_cache_mb;

/* Parses --background (tool_parse_background()) into the background colours of the ip_shading
 * at base + offset; a bad value is "--background 'VALUE' is not a colour (R,G,B or #rrggbb) or
 * TOP:BOTTOM, two of them". */
tool_option_parse tool_option_background;

/* The isovalues one command line keeps (isorender's surfaces). */
#define TOOL_MAX_ISOS 4

/* The options isorender and isoview share: what to extract, from where, and how, and the
 * statistics file, --force and --quiet. */
typedef struct tool_view_options {
    double iso; /* as given: in the file's units (--iso) or stored (--iso-stored) */
    /* every --iso (or --iso-stored) in order (iso is the last), the first TOOL_MAX_ISOS of
     * them; iso_count counts them all */
    double isos[TOOL_MAX_ISOS];
    unsigned iso_count;
    int iso_given_stored, iso_given_units; /* --iso-stored was given; --iso was */
    /* iso as the file's rescale has it (tool_settle_iso()): the stored value the engine
     * extracts, the value in the file's units (the same without a rescale), the rescale */
    double iso_stored, iso_value;
    const ip_rescale *rescale; /* the open store's; NULL before tool_settle_iso() */
    uint32_t width, height;    /* pixels */
    /* --view NAME (NULL: the file's default, ip_view_default()), --camera E,T,U,FOV in the
     * file's physical space (NULL: none) */
    const char *view, *camera;
    uint64_t rays;           /* 0: every pixel */
    double time_limit;       /* seconds; 0: none */
    double cutoff, foldback; /* degrees */
    unsigned threads;        /* 0: every core */
    int lod;
    double pixel_error;
    int occlusion; /* --occlusion on|off */
    int prefetch;  /* --prefetch on|off|always: IP_PREFETCH_ON, _OFF, _ALWAYS */
    int cull;      /* --cull on|off; -1 when not given, until the program settles its default */
    unsigned clip_count; /* --clip and --clip-index SPEC, repeatable, in the order given */
    /* the planes as given: physical units (--clip) or sample indices (--clip-index, where
     * clip_index[i] is 1), tool_parse_clip()'s; once the file is open, tool_space_clip() puts
     * them in world units into clip, which the engine takes, and in physical units into
     * clip_physical, which the statistics report */
    ip_clip_plane clip_given[IP_MAX_CLIP_PLANES];
    uint8_t clip_index[IP_MAX_CLIP_PLANES];
    ip_clip_plane clip[IP_MAX_CLIP_PLANES];
    ip_clip_plane clip_physical[IP_MAX_CLIP_PLANES];
    uint64_t cache_bytes;
    const char *stats; /* --stats OUT.json (NULL: none) */
    int force, quiet;
    int verbose; /* --verbose (-v): what each step did, on stderr */
} tool_view_options;

/* The --help lines of --iso and --iso-stored (the usage texts of isorender, isoview and
 * isowall include them). */
#define TOOL_ISO_OPTIONS_HELP                                                                    \
    "  --iso V             the isovalue, in the file's units where it has a rescale (HU for a\n" \
    "                      DICOM CT; isoinfo shows the rescale), else a stored sample value\n"   \
    "  --iso-stored V      the isovalue as a stored sample value, instead of --iso\n"

/* The --help lines of --view and --camera (isorender, isoview, isowall). */
#define TOOL_VIEW_OPTIONS_HELP                                                                   \
    "  --view NAME         the side the eye is on, whole volume in frame, in the file's\n"       \
    "                      physical space: anterior, posterior, left, right, superior or\n"      \
    "                      inferior where the file names an anatomical space (up superior, or\n" \
    "                      anterior for superior and inferior; default anterior), or +x -x +y\n" \
    "                      -y +z -z along its physical axes (up +z, or +y for the z views;\n"    \
    "                      default -y where it names no space)\n"                                \
    "  --camera E,T,U,FOV  ex,ey,ez,tx,ty,tz,ux,uy,uz,fov in the file's physical space (mm\n"    \
    "                      where it names an anatomical space) and degrees\n"

/* The --help lines of the shared options that steer the engine (the usage texts of isorender
 * and isoview include them). */
#define TOOL_ENGINE_OPTIONS_HELP                                                                   \
    "  --cutoff DEGREES    propagation cut-off angle (default 1.81)\n"                             \
    "  --foldback DEGREES  fold-back tolerance (default 0.25)\n"                                   \
    "  --lod on|off        adaptive resolution: far regions from coarser levels (default on)\n"    \
    "  --pixel-error P     with --lod: coarsen where a cell projects to <= P pixels (default 1)\n" \
    "  --occlusion on|off  propagation skips cells that extracted surface hides (default on)\n"    \
    "  --prefetch on|off|always\n"                                                                 \
    "                      a background thread reads and decodes the bricks the next rays need;\n" \
    "                      on (the default): only those the disk must deliver when the threads\n"  \
    "                      take every core; always: every one\n"                                   \
    "  --cull on|off       with --occlusion: keep no triangle the image shows at no pixel\n"       \
    "                      centre (default on, unless --mesh (isorender) or --aa)\n"               \
    "  --clip SPEC         keep one side of a plane in the file's physical space (mm where it\n"   \
    "                      names an anatomical space; repeatable, up to 6 with --clip-index):\n"   \
    "                      x=40 keeps x >= 40, -x=40 keeps x <= 40 (y, z alike),\n"                \
    "                      A,B,C,D keeps A*x + B*y + C*z + D >= 0\n"                               \
    "  --clip-index SPEC   the same in sample indices (i, j, k as x, y, z): z=40 keeps the\n"      \
    "                      slices from index 40 on\n"

/* The defaults: the file's default view (view NULL), the paper's angles, lod on with a 1-pixel
 * error, occlusion on, reading ahead on, every core, the default cache budget, an image of
 * width x height. */
void tool_view_options_default(tool_view_options *o, uint32_t width, uint32_t height);

/* --prefetch's name of a mode ("off", "on" or "always"; "unknown" for another value): a
 * static string. */
const char *tool_prefetch_name(int mode);

/* Parses a --clip SPEC (see TOOL_ENGINE_OPTIONS_HELP) into *plane; returns 0, or -1 when it
 * is not one (an unknown axis, a bad number, a zero normal). */
int tool_parse_clip(const char *text, ip_clip_plane *plane);

/* The engine options the shared options ask for (the clipping planes too; triangles culled as
 * o->cull, which the program has settled by then). */
void tool_engine_options(const tool_view_options *o, ip_engine_options *eo);

/* The shared options of tool_view_options as a table over `o`: --iso, --size, --view, --camera,
 * --rays, --time, --cutoff, --foldback, --threads, --lod, --pixel-error, --occlusion, --prefetch,
 * --cull, --clip, --clip-index, --cache-mb, --stats, --force and --quiet (-q). */
tool_option_table tool_view_option_table(tool_view_options *o);

/* The command line of isorender and isoview: the shared view options and the program's
 * own table (over own_base), one brick file (*file). The file and --iso (or --iso-stored) are
 * required ("no brick file", "--iso V is required"), and the two do not mix. Returns 0, or 2
 * after a usage error. */
int tool_parse_view_command_line(const char *program, const char *usage, tool_view_options *o,
                                 const tool_option *own, size_t own_count, void *own_base,
                                 const char **file, int argc, char **argv);

/* Settles o->iso (as given) against the rescale of `layout` (the open store's, which must
 * outlive o): o->iso_stored, the stored value the engine extracts, and o->iso_value, the value
 * in the file's units, one from the other through ip_rescale_to_stored() or
 * ip_rescale_to_value(); o->rescale. Without a rescale all three are o->iso. Idempotent. */
void tool_settle_iso(tool_view_options *o, const ip_layout *layout);

/* What a run extracts (tool_run_json.full, isorender's o.full): the progressive run, the full
 * extraction (--full, a flag: 1) or the full extraction at adaptive resolution (--full-lod). */
enum {
    TOOL_PROGRESSIVE = 0,
    TOOL_FULL = 1,
    TOOL_FULL_LOD = 2
};

/* The full extraction `mode` asks for, of isovalue `iso` with o's threads and clipping planes:
 * TOOL_FULL every active cell of level 0 (ip_extract_full_clipped()), TOOL_FULL_LOD those of
 * the levels o's pixel error gives `camera`, each within its distance band
 * (ip_extract_full_lod()). Triangles are appended to the caller's `mesh`; `counts` (may be
 * NULL) as those functions set it. */
ip_status tool_full_extraction(ip_cache *cache, double iso, int mode, const ip_camera *camera,
                               const tool_view_options *o, ip_mesh *mesh, ip_engine_counts *counts,
                               ip_error *err);

#endif

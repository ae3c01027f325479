/* SPDX-License-Identifier: BSD-3-Clause */
/* isorender's parts (not part of the library): the run's state and each file's functions. */
#ifndef ISORENDER_H
#define ISORENDER_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "isoprop/cache.h"
#include "isoprop/engine.h"
#include "isoprop/render.h"
#include "isoprop/store.h"
#include "tool_common.h"

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
    int mesh_grid;            /* --mesh-grid: the mesh file in index x spacing, not physical */
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
    double decimate;        /* --decimate RATIO: share of the mesh file's triangles (0: none) */
    double decimate_error;  /* --decimate-error LENGTH (0: 1 % of the mesh's size) */
    int cap;                /* --cap: close the --full surface at the volume's faces */
    int measure, largest;   /* --measure, --largest */
    double min_area;        /* --min-area A (0: none) */
    int min_area_given;
} options;

/* The figures of a surface's mesh (--measure, --stats' "surface"): welded, cleaned, in the
 * mesh file's space. */
typedef struct surface_figures {
    int known, closed;
    uint64_t triangles, vertices, components, removed;
    double area, volume, lo[3], hi[3];
    uint64_t largest_triangles; /* the component of the greatest area */
    double largest_area, largest_volume;
} surface_figures;

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
    tool_space space;      /* the file's physical space: the views, the planes, the image */
    ip_camera camera;      /* in world units, as the engine and the renderers take it */
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
    char warning[600];    /* the --iso warning, "" when none */
    tool_outputs outputs; /* the files this run wrote: all of them, or none when it fails */
    strip_frames strip;
    uint64_t mesh_vertices;  /* of the mesh file */
    uint64_t mesh_triangles; /* of the mesh file, after --decimate and cleaning */
    /* several --iso: this run is the first surface's; others[] the later ones', each a run of
     * its own (engine, mesh, counts) sharing the store, the cache and the camera */
    struct run *others;
    size_t other_count;
    char mesh_name[4096]; /* the surface's mesh file (o.mesh points here), several --iso */
    ip_scale_bar bar;     /* --scale-bar: the last image's */
    /* --decimate: done (the file's welded mesh), its triangles before and after, the error */
    int decimated;
    uint64_t decimate_before, decimate_after;
    double decimate_reached;
    uint64_t cap_triangles; /* --cap: the cap's triangles, appended to the --full mesh */
    surface_figures figures;
    char measure_warning[200]; /* a progressive mesh measured: "" when none */
} run;

/* options.c */
/* Parses the command line into *o, checks the options against each other and settles the
 * defaults that depend on others. Returns 0, or 2 after a usage error; exits 0 after --help
 * and --version. */
int parse_args(int argc, char **argv, options *o);

/* surfaces.c */
/* The shortest "%g" text (6 to 9 significant digits) of the isovalue the engine extracts,
 * (float)iso, that reads back as that float: isovalues no two alike as floats (as
 * check_surface_options() wants them) get texts no two alike (100.0001 and 100.0002, not 100
 * twice), and 600.5 stays 600.5. */
void iso_text(double iso, char *out, size_t size);
/* Whether the image needs the several-surface drawing: several --iso, or a translucent one. */
int several_surfaces(const run *r);
/* Surface i's run: r itself for the first. */
run *surface_run(run *r, size_t i);
const run *surface_run_c(const run *r, size_t i);
/* Surface i as the renderers take it: its mesh (its first prefix[i] triangles when prefix is
 * not NULL; `views` holds them), colour and opacity. */
void surface_of(const run *r, size_t i, const uint64_t *prefix, ip_mesh *views, ip_surface *out);
/* What the surfaces' runs share with the first: the store, the cache and the view. */
void share_view(const run *r, run *s);
/* The triangles of every surface. */
uint64_t all_triangles(const run *r);
/* The surfaces' runs after the first (several --iso), copies of its options with their own
 * isovalues, and with --mesh each surface's file name. Returns 0, 1 (out of memory) or 2
 * (a usage error). */
int setup_surfaces(run *r);
/* Frees what the surfaces' runs after the first hold. */
void free_surfaces(run *r);

/* extract.c */
/* The engine with the command line's options, cancelled by a signal; made once. */
int create_engine(run *r, ip_error *err);
/* --full or --full-lod into r->full_mesh (once untimed first with --warm), which r->mesh then
 * shows. Returns 0, or -1 with the error in *err. */
int extract_full(run *r, ip_error *err);
/* Extracts every surface, one run after the other, each with the same view and options. */
int extract_surfaces(run *r, ip_error *err);

/* draw.c */
/* A headless renderer of w x h pixels with the figure's shading and anti-aliasing. Returns
 * 0; 1 when there is no headless OpenGL (`why` says why); -1 when it refuses a setting. */
int figure_renderer(const run *r, uint32_t w, uint32_t h, ip_renderer **gl, ip_error *why,
                    ip_error *err);
/* The image of the run's surfaces (prefix: as draw_surfaces()); one opaque surface is drawn
 * as it always was. The image is the physical view's (mirrored where the space mirrors). */
ip_status draw_image(const run *r, ip_renderer *gl, const uint64_t *prefix, uint8_t *rgba,
                     ip_error *err);
/* The scale bar's unit: --scale-unit, else mm in a named anatomical space (DICOM, NIfTI and
 * NRRD state lengths in millimetres there), else "units". */
const char *scale_unit(const run *r);
/* Renders with OpenGL through EGL, or in software when asked or when no OpenGL is found.
 * With `keep` (the turntable's frames), the OpenGL renderer the first call makes stays in
 * *keep for the next calls, and the caller destroys it; without, it goes at the end. */
int render_image(run *r, uint8_t *rgba, ip_renderer **keep, ip_error *err);

/* strip.c */
/* Parses --strip-at's "P,P,..." (each a number with an optional '%'). Returns 0, or 2 after a
 * usage error. */
int parse_strip_at(const char *program, const tool_option *option, const char *const *values,
                   void *base);
/* The strip's checks after parsing, and its default frames. Returns 0, or 2 after a usage
 * error. */
int check_strip_options(options *o);
/* Each frame's ray count, from its percentage of the view's rays (at least 1). */
void strip_plan_rays(run *r);
/* Where the next step must stop: `next`, or the ray count of an earlier frame not yet
 * reached. */
uint64_t strip_stop(const run *r, uint64_t rays, uint64_t next);
/* After a step: the frames whose ray count is reached show the mesh as it is now. */
void strip_record(run *r);
/* The strip's image: the frames over a dark band with their labels; *out is the caller's
 * (free()). Returns 0 or -1 with err set. */
int strip_compose(run *r, uint8_t **out, uint32_t *width, uint32_t *height, ip_error *err);
/* The summary's strip line. */
void strip_print(FILE *out, const run *r);

/* stats.c */
/* Final pixels of every checkpoint from one raster of the final mesh: a pixel has its final
 * colour at a checkpoint when the triangle it finally shows was already extracted (the mesh
 * only grows by appending, and the nearest triangle wins). The same raster gives the visible
 * triangles, those that own at least one pixel of the final image, in all and as extracted
 * by each checkpoint: overdraw = triangles extracted / visible triangles. */
int final_pixels(run *r, ip_error *err);
/* --progress's CSV, a row per checkpoint of every surface (a tool_write_text_file() filler;
 * user: the run). */
void progress_csv(FILE *f, void *user);
/* --stats' members after "cache" (a tool_write_stats_file() extra; user: the run). */
void json_counts(FILE *f, void *user);
/* The summary: each surface's counts and times, the image and the mesh files. */
void print_summary(FILE *out, const run *r);

/* mesh.c */
/* --smooth N: the Taubin iterations for the mesh file. */
int parse_smooth(const char *program, const tool_option *option, const char *const *values,
                 void *base);
/* --smooth smooths a welded mesh file; --smooth and --mesh-grid need --mesh. Returns 0, or 2
 * after a usage error. */
int check_mesh_options(const options *o);
/* The mesh goes out in the volume's physical space (origin, directions: docs/format.md); a
 * copy is moved there, unless the file's space is the engine's own. */
int write_mesh(run *r, ip_error *err);

/* measure.c */
/* --min-area A: a number 0 or more. */
int parse_min_area(const char *program, const tool_option *option, const char *const *values,
                   void *base);
/* --largest and --min-area clean the mesh written or measured: they need --mesh, --measure or
 * --stats, and shared vertices. Returns 0, or 2 after a usage error. */
int check_measure_options(const options *o);
/* Whether the run measures its surfaces: --measure, or --stats with --full (or a cleaning). */
int measuring(const run *r);
/* Cleans the welded mesh by --largest and --min-area, then measures it into r->figures when
 * measuring(r). Returns 0, or 1 after the error. */
int clean_and_measure(run *r, ip_indexed_mesh *welded);
/* Measures the run's mesh without writing it (no --mesh, or --no-weld): moved into physical
 * space, welded, cleaned. Returns 0, or 1 after the error. */
int measure_unwritten(run *r, const ip_mesh *physical);
/* --stats' "surface": the figures as a JSON member (nothing when not measured). */
void json_surface(FILE *f, const run *r);
/* --measure's lines of the summary. */
void print_measure(FILE *out, const run *r);

/* turntable.c */
/* --turntable N: the frame count. */
int parse_turntable(const char *program, const tool_option *option, const char *const *values,
                    void *base);
/* -o's default, and the options a turntable cannot have. Returns 0, or 2 after a usage
 * error. */
int check_turntable_options(options *o);
/* --turntable N: N frames, each a complete image, the eye turned 360 / N degrees more in
 * azimuth each time, in the folder -o names (made when absent); then the MP4 when asked. */
int turntable_run(run *r, ip_error *err);

/* decimate.c */
/* --decimate RATIO, in (0, 1), and --decimate-error LENGTH, > 0. */
int parse_decimate(const char *program, const tool_option *option, const char *const *values,
                   void *base);
int parse_decimate_error(const char *program, const tool_option *option, const char *const *values,
                         void *base);
/* --decimate needs --mesh and shared vertices; --decimate-error needs --decimate. Returns 0, or
 * 2 after a usage error. */
int check_decimate_options(const options *o);
/* Simplifies the welded mesh of the file by --decimate (a warning where the error bound stops
 * it early; with -v its counts and error). Returns 0, or 1 after the error. */
int decimate_mesh(run *r, ip_indexed_mesh *welded, ip_error *err);
/* --stats' "decimate" member, after a --decimate. */
void json_decimate(FILE *f, const run *r);

/* cap.c */
/* --cap needs --full (level 0) and no --clip. Returns 0, or 2 after a usage error. */
int check_cap_options(const options *o);
/* --cap: the cap appended to r->full_mesh. Returns 0, or -1 with the error in *err. */
int cap_surface(run *r, ip_error *err);

#endif

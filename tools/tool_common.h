/* Helpers shared by the programs (not part of the library): option values, errors, JSON. */
#ifndef ISOPROP_TOOL_COMMON_H
#define ISOPROP_TOOL_COMMON_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "isoprop/cache.h"
#include "isoprop/camera.h"
#include "isoprop/engine.h"
#include "isoprop/input.h"
#include "isoprop/render.h"
#include "isoprop/status.h"
#include "isoprop/store.h"
#include "isoprop/system.h"

/* Prints "PROGRAM: message" on stderr and returns exit code 1 (2 for usage errors). */
int tool_fail(const char *program, const ip_error *err);
int tool_usage_error(const char *program, const char *fmt, ...);

/* Parses a non-negative integer option value; returns 0 on success, -1 on bad text. */
int tool_parse_u64(const char *text, uint64_t *out);
/* Parses the value of `option` as an integer from `least` to `most`, into *out. Returns 0, or
 * 2 after the usage error "OPTION 'TEXT' is not WHAT (LEAST to MOST)". */
int tool_parse_bounded(const char *program, const char *option, const char *text, uint64_t least,
                       uint64_t most, const char *what, uint64_t *out);
/* Parses a finite double; returns 0 on success, -1 on bad text. */
int tool_parse_double(const char *text, double *out);
/* Parses "a,b,c" into three finite doubles; returns 0 on success. */
int tool_parse_double3(const char *text, double out[3]);

/* Parses the value of a dims option ("XxYxZ", each 2 .. 2^31 - 1). Returns 0, or 2 after a
 * usage error that says what is wrong (not three numbers, a dimension that is zero or under 2,
 * one too large). */
int tool_parse_dims(const char *program, const char *option, const char *text, uint32_t dims[3]);

/* Parses the value of a two-number option ("AxB", each 1 .. max; x or X between): `form` says
 * what it should be in the usage error ("WxH (e.g. 1600x1200)"), sides[] and `unit` name the
 * numbers in the one about their range ("the height, 0 pixels, is not within 1 .. 16384").
 * Returns 0, or 2 after that usage error. */
int tool_parse_pair(const char *program, const char *option, const char *text, uint32_t max,
                    const char *form, const char *const sides[2], const char *unit, uint32_t *a,
                    uint32_t *b);

/* Handles --version: prints "PROGRAM VERSION" (the library's, isoprop/version.h) on stdout. */
void tool_print_version(const char *program);

/* Checks every file of a run before any work, so that a bad one fails the run at once: each input
 * (NULL entries are skipped) exists and is a regular file (a FIFO or a device is refused, never
 * opened); no output is an input (the same file by device and inode, however spelled); no two
 * outputs are the same file; each output may be written (absent, or a regular file and `force`; a
 * directory, device or FIFO is refused even with force; see isoprop/output.h). An output "-" is
 * standard output, which at most one output may be. Returns 0, or 1 after printing one line
 * "PROGRAM: path: problem". */
int tool_check_paths(const char *program, const char *const *inputs, size_t input_count,
                     const char *const *outputs, size_t output_count, int force);

/* Whether an output's path is "-", standard output (--stats -, --progress -). */
int tool_is_stdout(const char *path);

/* Writes what fill(out, user) prints as the whole file at `path`, all-or-nothing (nothing is
 * left at path on failure; an existing file is replaced only with `force`, and only when it
 * is a regular file). A path of "-" is standard output: the text is written there whole, at
 * once, but what has been written to stdout cannot be taken back when a later output fails.
 * Returns 0, or -1 after printing "PROGRAM: path: reason" on stderr. */
int tool_write_text_file(const char *program, const char *path, int force,
                         void (*fill)(FILE *out, void *user), void *user);

/* Ctrl-C and SIGTERM. tool_signals_catch() installs handlers that only record the signal
 * (and cancel the engine named by tool_signals_cancel_engine(), an atomic store), so that the
 * program can stop cleanly, write no output and then end as killed by that signal, with
 * tool_signals_reraise() (shell status 130 for SIGINT, 143 for SIGTERM). */
void tool_signals_catch(void);
/* The signal caught so far (SIGINT or SIGTERM), or 0. */
int tool_signal_caught(void);
/* The engine a signal cancels from now on (NULL: none). Before an engine is destroyed, call
 * with NULL: it returns once no handler can still be using the old one. */
void tool_signals_cancel_engine(ip_engine *engine);
/* When a signal was caught: flushes stdout and stderr, restores the default action and
 * raises the signal again (the process ends there). Returns when none was caught. */
void tool_signals_reraise(void);

/* A progress bar on stderr (isoinfo --verify, isorender): shown when stderr is a terminal, or
 * always when the environment variable `force_variable` is "1" (for tests, whose stderr is a
 * pipe); drawn at most five times a second and at the end, as
 * "[####      ]  40.0% DONE/TOTAL UNIT DETAIL ETA Ns" on one line that it redraws. */
typedef struct tool_progress {
    int show, drawn;
    double start, last; /* seconds */
} tool_progress;

/* Starts the clock; the bar shows only when `wanted` (not --quiet, not --json). */
void tool_progress_start(tool_progress *p, int wanted, const char *force_variable);
/* Draws done of total UNIT (e.g. "bricks"), then `detail` (may be ""). */
void tool_progress_draw(tool_progress *p, uint64_t done, uint64_t total, const char *unit,
                        const char *detail);
/* Seconds since tool_progress_start(). */
double tool_progress_elapsed(const tool_progress *p);
/* Ends the bar's line, so that what follows starts on a line of its own. */
void tool_progress_end(tool_progress *p);

/* Writes `text` as a JSON string literal (with quotes and escapes). */
void tool_json_string(FILE *out, const char *text);

/* Formats a byte count as "12.3 MiB" into buf. */
const char *tool_format_bytes(char *buf, size_t size, double bytes);

/* When the input says its values stand for stored x slope + intercept (DICOM rescale, NIfTI
 * scl_slope/scl_inter), prints that on `out` as an indented summary line, with the reminder that
 * samples, and so iso values, stay in stored units. Prints nothing otherwise. */
void tool_print_rescale(FILE *out, const ip_input_desc *desc);

/* Parses --cache-mb's value into bytes; returns 0 on success. */
int tool_parse_cache_mb(const char *text, uint64_t *bytes);

/* The isovalues one command line keeps (isorender's surfaces). */
#define TOOL_MAX_ISOS 4

/* The options isorender and isoview share: what to extract, from where, and how, and the
 * statistics file, --force and --quiet. */
typedef struct tool_view_options {
    double iso;
    /* every --iso in order (iso is the last), the first TOOL_MAX_ISOS of them; iso_count
     * counts them all */
    double isos[TOOL_MAX_ISOS];
    unsigned iso_count;
    uint32_t width, height;    /* pixels */
    const char *view, *camera; /* --view AXIS, --camera E,T,U,FOV (NULL: none) */
    uint64_t rays;             /* 0: every pixel */
    double time_limit;         /* seconds; 0: none */
    double cutoff, foldback;   /* degrees */
    unsigned threads;          /* 0: every core */
    int lod;
    double pixel_error;
    int occlusion; /* --occlusion on|off */
    int prefetch;  /* --prefetch on|off|always: IP_PREFETCH_ON, _OFF, _ALWAYS */
    int cull;      /* --cull on|off; -1 when not given, until the program settles its default */
    unsigned clip_count;                    /* --clip SPEC, repeatable */
    ip_clip_plane clip[IP_MAX_CLIP_PLANES]; /* world units (tool_parse_clip()) */
    uint64_t cache_bytes;
    const char *stats; /* --stats OUT.json (NULL: none) */
    int force, quiet;
    int verbose; /* --verbose (-v): what each step did, on stderr */
} tool_view_options;

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
    "  --clip SPEC         keep one side of a plane, world units (repeatable, up to 6):\n"         \
    "                      x=40 keeps x >= 40, -x=40 keeps x <= 40 (y, z alike),\n"                \
    "                      A,B,C,D keeps A*x + B*y + C*z + D >= 0\n"

/* The defaults: view -y, the paper's angles, lod on with a 1-pixel error, occlusion on, reading
 * ahead on, every core, the
 * default cache budget, an image of width x height. */
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

/* ---- the command line, parsed from tables ----
 *
 * A program describes its options in tables of tool_option (one of them may be the shared
 * view options, tool_view_option_table()), and tool_parse_command_line() walks argv once,
 * left to right: -h and --help print the program's usage on stdout and exit 0, --version its
 * version (exit 0); an option of a table takes its values; anything else starting with '-'
 * (but "-" alone) is "unknown or incomplete option '...'", as is an option without all its
 * values; the rest is the one positional argument. */

/* tool_option.values for an option whose value is optional: the next argument is its value
 * when `accepts` says so (isobrick --hc [LEVEL]). */
#define TOOL_OPTIONAL_VALUE (-1)

typedef struct tool_option tool_option;

/* Parses an option's values (values[0] .. ; values[0] is NULL for an absent optional value)
 * into the struct at `base` that the table describes (the field at base + option->offset,
 * or several). Returns 0, or 2 after a usage error (tool_usage_error()). */
typedef int tool_option_parse(const char *program, const tool_option *option,
                              const char *const *values, void *base);

struct tool_option {
    const char *name;  /* "--size" */
    const char *alias; /* a second name ("-q"), or NULL */
    int values;        /* the values after the name: 0, 1, 2 or TOOL_OPTIONAL_VALUE */
    /* without parse: a flag (values 0) sets the int at base + offset to 1, a text (values 1)
     * stores the value as the const char * at base + offset */
    size_t offset;
    tool_option_parse *parse;          /* NULL: a flag or a text, as above */
    const char *problem;               /* for parsers that use it: "is not a number" */
    int (*accepts)(const char *value); /* TOOL_OPTIONAL_VALUE: whether it is the value */
};

/* Parsers for tables: a finite number, and a number > 0, into the double at base + offset;
 * a bad value is "NAME 'VALUE' PROBLEM" (option->problem). */
tool_option_parse tool_option_number, tool_option_positive;

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

/* Parses --threads N: 1 .. max, else "--threads must be 1-MAX". Returns 0, or 2 after the
 * usage error. */
int tool_parse_threads(const char *program, const char *text, unsigned max, unsigned *threads);

/* A table and the struct its options fill. */
typedef struct tool_option_table {
    const tool_option *options;
    size_t count;
    void *base;
} tool_option_table;

typedef struct tool_command_line {
    const char *program; /* for messages: "isorender" */
    const char *usage;   /* --help's text */
    const tool_option_table *tables;
    size_t table_count;
    const char **positional;     /* receives the positional argument (NULL when none) */
    const char *positional_name; /* for "more than one NAME ('...')": "file", "input" */
} tool_command_line;

/* Parses argv[1 ..] as described above. Returns 0, or 2 after printing a usage error; exits
 * with status 0 after --help or --version. */
int tool_parse_command_line(const tool_command_line *c, int argc, char **argv);

/* The shared options of tool_view_options as a table over `o`: --iso, --size, --view, --camera,
 * --rays, --time, --cutoff, --foldback, --threads, --lod, --pixel-error, --occlusion, --prefetch,
 * --cull, --clip, --cache-mb, --stats, --force and --quiet (-q). */
tool_option_table tool_view_option_table(tool_view_options *o);

/* The command line of isorender and isoview: the shared view options and the program's
 * own table (over own_base), one brick file (*file). The file and --iso are required ("no
 * brick file", "--iso V is required"). Returns 0, or 2 after a usage error. */
int tool_parse_view_command_line(const char *program, const char *usage, tool_view_options *o,
                                 const tool_option *own, size_t own_count, void *own_base,
                                 const char **file, int argc, char **argv);

/* Whether `text` is a non-negative integer (tool_parse_u64() succeeds): for `accepts`. */
int tool_is_u64(const char *text);

/* ---- figure options: turning the view, and colours ---- */

/* --azimuth, --elevation and --zoom, applied after --view or --camera (tool_apply_orbit()). */
typedef struct tool_orbit_options {
    double azimuth;   /* degrees about the view's up axis; positive: the eye moves right */
    double elevation; /* degrees about the right axis after that; positive: the eye moves up */
    double zoom;      /* > 0; the image is magnified this much about its centre (1: none) */
} tool_orbit_options;

#define TOOL_ORBIT_OPTIONS_HELP                                                                    \
    "  --azimuth DEG       turn the eye around the target about the view's up axis, after\n"       \
    "                      --view or --camera: positive moves the eye right (the volume turns\n"   \
    "                      left); -y then --azimuth 90 looks from +x (default 0)\n"                \
    "  --elevation DEG     then turn it about the view's right axis: positive moves the eye up,\n" \
    "                      to look down on the volume (default 0)\n"                               \
    "  --zoom F            narrow the field of view F times (> 0; 2 shows the central half of\n"   \
    "                      the frame, twice as large; the eye stays; default 1)\n"

/* The rows of --azimuth, --elevation and --zoom for a program's option table, filling the
 * tool_orbit_options `member` of `type` (a bad value is a usage error: not a number, a zoom
 * that is not > 0). */
/* clang-format off */
#define TOOL_ORBIT_OPTION_ROWS(type, member)                                                       \
    {"--azimuth", NULL, 1, offsetof(type, member.azimuth), tool_option_number,                    \
     "is not a number of degrees", NULL},                                                          \
    {"--elevation", NULL, 1, offsetof(type, member.elevation), tool_option_number,                \
     "is not a number of degrees", NULL},                                                          \
    {"--zoom", NULL, 1, offsetof(type, member.zoom), tool_option_positive,                        \
     "is not a factor > 0", NULL}
/* clang-format on */

/* No turn, no zoom. */
void tool_orbit_options_default(tool_orbit_options *o);

/* Turns `camera` (valid: ip_camera_check()) by the azimuth, then the elevation, around its
 * target (ip_camera_orbit()), and narrows its field of view by the zoom: tan(fov / 2) is
 * divided by it. The camera stays valid. */
void tool_apply_orbit(const tool_orbit_options *o, ip_camera *camera);

/* A camera of width x height pixels: camera_text ("E,T,U,FOV", checked; --camera) or, when it
 * is NULL, the view along `axis` (--view) fitted to the world box [lo, hi] (30 degrees); before
 * any orbit. Returns 0, or -1 with err set and *camera untouched. */
int tool_camera_of(const char *camera_text, const char *axis, uint32_t width, uint32_t height,
                   const double lo[3], const double hi[3], ip_camera *camera, ip_error *err);

/* Parses a colour: "R,G,B" (numbers in [0, 1]) or "#rrggbb" (hexadecimal). Returns 0, or -1
 * on bad text. */
int tool_parse_colour(const char *text, float rgb[3]);

/* Parses a background: one colour (solid), or "TOP:BOTTOM", two colours for a vertical
 * gradient from the top image row to the bottom one. Returns 0, or -1 on bad text. */
int tool_parse_background(const char *text, float top[3], float bottom[3]);

/* Prints the cache statistics as a short human-readable table (on exit of every tool that
 * reads bricks). `summary_bytes` is the size of the file's summary section. */
void tool_print_cache_table(FILE *out, const ip_cache_stats *s, uint64_t summary_bytes);

/* Writes the "cache" object's members (without braces) as JSON. */
void tool_write_cache_json(FILE *out, const ip_cache_stats *s, uint64_t summary_bytes);

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

/* What isorender and isoview write about a run in --stats (members after "cache"). */
typedef struct tool_run_json {
    const char *file;
    double iso;
    int full; /* TOOL_PROGRESSIVE, TOOL_FULL or TOOL_FULL_LOD */
    const ip_camera *camera;
    const char *renderer; /* "opengl", "software", "none" */
    const tool_view_options *options;
    int warm, done;
    const ip_engine_counts *counts;
    double rendering_seconds, extraction_wall_seconds, progress_render_seconds;
} tool_run_json;

/* Writes the run's members ("file" .. "time"; without braces) as JSON. */
void tool_write_run_json(FILE *out, const tool_run_json *j);

/* Writes {"cache": {...}} plus, when extra is not NULL, the members that extra(out, user)
 * prints (preceded by ", "), to `path` with tool_write_text_file() (all-or-nothing; an
 * existing file is replaced only with `force`).
 * Returns 0, or -1 after printing "PROGRAM: path: reason" on stderr. */
int tool_write_stats_file(const char *program, const char *path, int force, const ip_cache_stats *s,
                          uint64_t summary_bytes, void (*extra)(FILE *out, void *user), void *user);

/* Warns (one line on stderr, "PROGRAM: warning: ...") when `iso` cannot cross the file's
 * value range (a cell is active when min < iso <= max), so that the image is legitimately
 * empty. `warning` (may be NULL) receives the warning's text, "" when none. Returns 1 when it
 * warned, else 0. */
int tool_warn_iso_range(const char *program, const ip_store *store, double iso, char *warning,
                        size_t warning_size);

#endif

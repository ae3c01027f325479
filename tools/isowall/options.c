/* SPDX-License-Identifier: BSD-3-Clause */
/* isowall's command line. */
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "isowall.h"

static const char usage[] =
    "usage: mpirun -np N isowall FILE.ibv --iso V --wall CxR --tile WxH [options]\n"
    "Extracts the isosurface V progressively for a display wall of C x R tiles of W x H pixels\n"
    "(one camera over the whole wall) on N MPI processes, sort-first with dynamic balance: the\n"
    "wall is cut into many more screen regions than processes, each process takes the next\n"
    "region of its own share (patches of neighbouring regions) when it is done with one, and,\n"
    "once its share is spent, steals half of what is left in the fullest share; it casts the\n"
    "rays with its own engine and cache over the same brick file. A first pass casts every\n"
    "region's coarse rays (the whole wall's coarse image), a second the rest, each process on\n"
    "the regions it took in the first. Each process draws its triangles into the tiles they\n"
    "touch (software rasterizer); per tile, the nearest surface wins.\n" TOOL_ISO_OPTIONS_HELP
    "  --wall CxR          display tiles across and down (required)\n"
    "  --tile WxH          pixels of a display tile (required); the image is C*W x R*H\n"
    "  --unit WxH          pixels of a screen region, inside a tile (default: an eighth of the\n"
    "                      tile each way, rounded up)\n"
    "  --static            no balance: the regions of tile t go to process t % N (one copy per\n"
    "                      projector, the paper's display wall), for comparison\n" TOOL_VIEW_OPTIONS_HELP
        TOOL_ORBIT_OPTIONS_HELP
    "  --color C           the surface colour: R,G,B (each 0 to 1) or #rrggbb\n"
    "  --background C      one colour, or TOP:BOTTOM for a vertical gradient over the wall\n" TOOL_ENGINE_OPTIONS_HELP
    "  --cache-mb N        each process's brick cache budget in MiB\n"
    "  --threads N         engine threads per process (default 1)\n"
    "  -o OUT.png          the whole wall as one image, composited on process 0 (default\n"
    "                      isowall.png unless --tiles-dir)\n"
    "  --tiles-dir DIR     instead, one PNG per display tile, tile_COL_ROW.png, written by the\n"
    "                      tile's owner (process t % N), as a projector's PC would show it\n"
    "  --coarse OUT.png    also the wall's image after the first (coarse) pass\n"
    "  --stats OUT.json    counts and times: one record per process (busy_s: CPU seconds on\n"
    "                      its regions and drawing; idle_s: wall seconds waiting for work or\n"
    "                      the composite; units; rays; triangles; bytes_sent; stolen: units\n"
    "                      taken from other processes' shares) and balance, the\n"
    "                      largest busy_s over the mean\n"
    "  --timeout SECONDS   the watchdog: when a process has sent nothing for this long (not\n"
    "                      even the heartbeat its helper thread sends while it computes), end\n"
    "                      the wall with an error naming it (default 60; 0: no watchdog)\n"
    "  -f, --force         replace existing outputs (regular files only; never an input)\n"
    "  -q, --quiet         print nothing but errors and warnings\n"
    "  --version           print the version and exit\n"
    "The image equals isorender's (--software, same camera, --size C*W x R*H). Options take\n"
    "their value as --iso V or --iso=V; -- ends the options.\n"
    "Exit status: 0 success, 1 failure, 2 bad command line.\n";

/* --wall CxR, --tile WxH and --unit WxH (tool_parse_pair()). */
static int parse_pair_option(const char *program, const tool_option *option,
                             const char *const *values, void *base)
{
    static const char *const tiles[2] = {"columns", "rows"}, *const pixels[2] = {"width", "height"};
    wall_options *o = base;
    if (strcmp(option->name, "--wall") == 0)
        return tool_parse_pair(program, option->name, values[0], 256, "CxR, tiles across and down",
                               tiles, "tiles", &o->cols, &o->rows);
    int tile = strcmp(option->name, "--tile") == 0;
    return tool_parse_pair(program, option->name, values[0], 65536, "WxH, pixels", pixels, "pixels",
                           tile ? &o->tile_w : &o->unit_w, tile ? &o->tile_h : &o->unit_h);
}

/* --color: the surface colour. */
static int parse_color(const char *program, const tool_option *option, const char *const *values,
                       void *base)
{
    (void)option;
    if (tool_parse_colour(values[0], ((wall_options *)base)->shading.surface) != 0)
        return tool_usage_error(program, "--color '%s' is not R,G,B (each 0 to 1) or #rrggbb",
                                values[0]);
    return 0;
}

static const tool_option wall_table[] = {
    {"-o", NULL, 1, offsetof(wall_options, out), NULL, NULL, NULL},
    {"--wall", NULL, 1, 0, parse_pair_option, NULL, NULL},
    {"--tile", NULL, 1, 0, parse_pair_option, NULL, NULL},
    {"--unit", NULL, 1, 0, parse_pair_option, NULL, NULL},
    {"--static", NULL, 0, offsetof(wall_options, is_static), NULL, NULL, NULL},
    {"--tiles-dir", NULL, 1, offsetof(wall_options, tiles_dir), NULL, NULL, NULL},
    {"--coarse", NULL, 1, offsetof(wall_options, coarse), NULL, NULL, NULL},
    {"--timeout", NULL, 1, offsetof(wall_options, timeout), tool_option_non_negative,
     "is not seconds (0: no watchdog)", NULL},
    TOOL_ORBIT_OPTION_ROWS(wall_options, orbit),
    {"--color", NULL, 1, 0, parse_color, NULL, NULL},
    {"--background", NULL, 1, offsetof(wall_options, shading), tool_option_background, NULL, NULL},
};

int wall_parse_args(int argc, char **argv, wall_options *o)
{
    memset(o, 0, sizeof *o);
    tool_view_options_default(&o->common, 0, 0);
    tool_orbit_options_default(&o->orbit);
    ip_shading_default(&o->shading);
    o->timeout = WALL_DEFAULT_TIMEOUT;
    int rc = tool_parse_view_command_line("isowall", usage, &o->common, wall_table,
                                          sizeof wall_table / sizeof wall_table[0], o, &o->file,
                                          argc, argv);
    if (rc)
        return rc;
    if (o->common.width || o->common.height)
        return tool_usage_error("isowall", "--size is isorender's: give --wall CxR and --tile WxH");
    if (o->common.rays || o->common.time_limit > 0)
        return tool_usage_error("isowall", "--rays and --time are isorender's: isowall casts "
                                           "every ray of the wall");
    if (!o->cols || !o->tile_w)
        return tool_usage_error("isowall", "--wall CxR and --tile WxH are required");
    uint64_t width = (uint64_t)o->cols * o->tile_w, height = (uint64_t)o->rows * o->tile_h;
    if (width > 65536 || height > 65536)
        return tool_usage_error("isowall", "the wall's image %llux%llu is larger than 65536 a side",
                                (unsigned long long)width, (unsigned long long)height);
    if (o->unit_w > o->tile_w || o->unit_h > o->tile_h)
        return tool_usage_error("isowall", "--unit %ux%u is larger than the tile %ux%u", o->unit_w,
                                o->unit_h, o->tile_w, o->tile_h);
    if (o->out && o->tiles_dir)
        return tool_usage_error("isowall", "-o and --tiles-dir: one or the other");
    if (!o->out && !o->tiles_dir)
        o->out = "isowall.png";
    if (o->out && !tool_is_png_name(o->out))
        return tool_usage_error("isowall", "-o %s: images are written as PNG: name it .png",
                                o->out);
    if (!o->unit_w) {
        o->unit_w = (o->tile_w + 7) / 8;
        o->unit_h = (o->tile_h + 7) / 8;
    }
    if (!o->common.threads)
        o->common.threads = 1;
    if (o->common.cull < 0) /* the wall's image only: culled unless --cull off */
        o->common.cull = 1;
    o->common.width = (uint32_t)width;
    o->common.height = (uint32_t)height;
    return 0;
}

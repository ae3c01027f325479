/* SPDX-License-Identifier: BSD-3-Clause */
/* extract: an example of a program built on libisoprop (docs/api.md).
 *
 *   extract FILE.ibv ISO [--full] [--size WxH] [--threads N] [--mesh OUT.ply]
 *
 * Opens a brick file (made by isobrick), keeps its bricks in a cache, and extracts the
 * isosurface ISO (in the file's units where it has a rescale, HU for a CT, as isorender
 * --iso): progressively, for a camera on the -y side of the volume, until every pixel
 * of a WxH image (640x480 by default) has had its ray; or, with --full, every active cell.
 * Prints the number of triangles and writes the mesh (binary PLY, binary STL, OBJ or glTF,
 * by the extension) in the volume's physical space, which the file names. It links
 * libisoprop alone, nothing graphical:
 *
 *   cc extract.c $(pkg-config --cflags --libs isoprop) -o extract
 *
 * Exit status: 0 done, 1 an error (one line on stderr), 2 a bad command line.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "isoprop/isoprop.h"

typedef struct request {
    const char *brick_file, *mesh_file;
    double iso; /* in the file's units (HU for a CT), as isorender --iso */
    int full;
    unsigned threads; /* 0: every core */
    unsigned width, height;
} request;

static int usage(const char *why)
{
    fprintf(stderr,
            "extract: %s (usage: extract FILE.ibv ISO [--full] [--size WxH] "
            "[--threads N] [--mesh OUT.ply])\n",
            why);
    return 2;
}

/* 0, or the exit status of a bad command line */
static int parse(int argc, char **argv, request *q)
{
    *q = (request){NULL, NULL, 0.0f, 0, 0, 640, 480};
    int positional = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *value = i + 1 < argc ? argv[i + 1] : NULL;
        char *end = NULL;
        if (strcmp(a, "--full") == 0) {
            q->full = 1;
        } else if (strcmp(a, "--size") == 0 && value) {
            if (sscanf(value, "%ux%u", &q->width, &q->height) != 2)
                return usage("--size takes WxH, e.g. 640x480");
            i++;
        } else if (strcmp(a, "--threads") == 0 && value) {
            q->threads = (unsigned)strtoul(value, &end, 10);
            if (*end != '\0')
                return usage("--threads takes a number");
            i++;
        } else if (strcmp(a, "--mesh") == 0 && value) {
            q->mesh_file = value;
            i++;
        } else if (a[0] == '-' && a[1] == '-') {
            return usage("unknown option, or one without its value");
        } else if (positional == 0) {
            q->brick_file = a;
            positional++;
        } else if (positional == 1) {
            q->iso = strtod(a, &end);
            if (*end != '\0')
                return usage("ISO must be a number");
            positional++;
        } else {
            return usage("too many arguments");
        }
    }
    return positional == 2 ? 0 : usage("FILE.ibv and ISO are required");
}

/* The isovalue as the engine takes it, a stored value: ISO is in the file's units where the
 * file has a rescale (stored x slope + intercept, e.g. Hounsfield units), as isorender --iso. */
static float stored_iso(const ip_store *store, double iso)
{
    const ip_rescale *r = &ip_store_layout(store)->rescale;
    return (float)(r->present ? (iso - r->intercept) / r->slope : iso);
}

/* Every ray of the view, in the paper's progressive order. The engine owns the mesh;
 * *engine is the caller's to destroy, also on failure. */
static ip_status extract_progressive(ip_cache *cache, const request *q, float iso,
                                     ip_engine **engine, ip_error *err)
{
    ip_engine_options options;
    ip_engine_options_default(&options);
    options.threads = q->threads;
    options.cull = 0; /* the mesh is written out: keep what the image would not show too */
    ip_status st = ip_engine_create(cache, &options, engine, err);
    if (st != IP_OK)
        return st;
    double lo[3], hi[3];
    ip_camera camera;
    ip_layout_world_box(ip_store_layout(ip_cache_store(cache)), lo, hi);
    st = ip_camera_fit_axis(lo, hi, "-y", 30.0, q->width, q->height, &camera, err);
    if (st == IP_OK)
        st = ip_engine_begin(*engine, &camera, iso, err);
    /* Each step casts the next rays; an interactive program would draw
     * ip_engine_mesh() between steps and stop early when the view changes. */
    while (st == IP_OK && !ip_engine_done(*engine))
        st = ip_engine_step(*engine, 4096, 0.0, NULL, err);
    return st;
}

/* Writes the mesh in the volume's physical space (origin, directions and spacing applied, as
 * isorender --mesh does), naming the space in the file. The engine's mesh is in world units
 * (sample index x spacing), so a copy is moved. */
static ip_status write_physical(const ip_store *store, const ip_mesh *mesh, const char *path,
                                ip_error *err)
{
    const ip_orientation *orientation = &ip_store_layout(store)->orientation;
    ip_mesh physical;
    ip_mesh_init(&physical);
    ip_status st = ip_mesh_append_mesh(&physical, mesh, 0, mesh->triangle_count);
    if (st == IP_OK) {
        ip_mesh_to_physical(&physical, orientation);
        st = ip_mesh_write_in(&physical, path, ip_mesh_space_of(orientation), 0, err);
    } else {
        err->code = st;
        snprintf(err->message, sizeof err->message, "%s: out of memory", path);
    }
    ip_mesh_free(&physical);
    return st;
}

static ip_status run(const request *q, ip_error *err)
{
    ip_store *store = NULL;
    ip_cache *cache = NULL;
    ip_engine *engine = NULL;
    ip_mesh full;
    ip_mesh_init(&full);
    const ip_mesh *mesh = &full;
    ip_status st = ip_store_open(q->brick_file, &store, err);
    if (st == IP_OK)
        st = ip_cache_create(store, ip_cache_default_budget(), &cache, err);
    if (st == IP_OK && q->full) {
        st = ip_extract_full(cache, stored_iso(store, q->iso), 0, q->threads, &full, NULL, err);
    } else if (st == IP_OK) {
        st = extract_progressive(cache, q, stored_iso(store, q->iso), &engine, err);
        mesh = ip_engine_mesh(engine);
    }
    if (st == IP_OK) {
        ip_cache_stats stats;
        ip_cache_get_stats(cache, &stats);
        printf("%llu triangles (%s), %llu bricks decoded, cache peak %llu bytes\n",
               (unsigned long long)mesh->triangle_count, q->full ? "full" : "progressive",
               (unsigned long long)(stats.misses + stats.prefetched),
               (unsigned long long)stats.resident_peak_bytes);
    }
    if (st == IP_OK && q->mesh_file)
        st = write_physical(store, mesh, q->mesh_file, err);
    ip_mesh_free(&full);
    ip_engine_destroy(engine);
    ip_cache_destroy(cache);
    ip_store_close(store);
    return st;
}

int main(int argc, char **argv)
{
    request q;
    int rc = parse(argc, argv, &q);
    if (rc != 0)
        return rc;
    ip_error err;
    if (run(&q, &err) != IP_OK) {
        fprintf(stderr, "extract: %s\n", err.message);
        return 1;
    }
    return 0;
}

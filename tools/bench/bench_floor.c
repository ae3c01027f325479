/* SPDX-License-Identifier: BSD-3-Clause */
/* bench_floor: the floor under any exact view. The cells whose triangles own a pixel of the
 * final image (the full extraction rasterised for the view) are what every exact method must
 * at least triangulate; this times marching cubes with normals over exactly those cells, as
 * an oracle that knew them would, with no rays, no propagation and no coverage: run 0 on an
 * empty cache (the bricks decoded as the cells ask for them), then REPEATS runs warm. The
 * cells are taken brick by brick (in id order within a brick), the kindest order for the caches,
 * and split in THREADS contiguous parts, one per thread. Prints the counts, each run's time
 * and the median of the warm runs. A benchmark, not a test (docs/benchmarks.md).
 *
 * With RAYS, the cells are instead those the engine extracts in its first RAYS rays (one
 * thread, no read-ahead, every triangle kept): the floor under the paper's propagation, which
 * walks through cells that own no pixel to reach those that do. Each such cell gets only what
 * the engine gives a cell whose triangles are all culled (its case and edge points); a cell
 * that owns a pixel gets marching cubes with normals, as above (part 27). With `cover` after
 * RAYS, every cell goes through the engine's own ip__extract_cell() with the coverage and
 * culling on, in the same brick order: the walked floor plus what recording each triangle in
 * the coverage costs (the coverage cleared before each run, untimed).
 */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "isoprop/isoprop.h"
#include "isoprop/render.h"
#include "internal.h"
#include "pool.h"
#include "propagate.h"
#include "sampler.h"

static const char usage[] =
    "usage: bench_floor FILE.ibv ISO VIEW WIDTHxHEIGHT THREADS REPEATS [RAYS [cover]]\n"
    "Triangulates only the cells whose triangles own a pixel of the final image of the view\n"
    "(from the full extraction), on THREADS threads: once on an empty cache, then REPEATS\n"
    "times warm. With RAYS: the cells the engine extracts in its first RAYS rays, those that\n"
    "own no pixel given only their edge points; with `cover` as well, every cell extracted as\n"
    "the engine does, recorded in a coverage buffer and culled.\n";

/* A cell to extract: its level-0 coordinates, and whether it owns a pixel of the image. */
typedef struct floor_cell {
    uint32_t xyz[3];
    uint32_t owns;
} floor_cell;

typedef struct part {
    ip_cache *cache;
    const floor_cell *cells;
    size_t count;
    ip_coverage *coverage; /* with `cover`: the coverage shared by the parts, else NULL */
    float iso;
    ip_mesh mesh;
    uint64_t triangles;
    uint64_t points; /* cells given edge points only */
    ip_status status;
} part;

/* Job `index` of a run (ip__pool_run()): part `index` of `user`, the parts. */
static void extract_part(void *user, unsigned index)
{
    part *p = (part *)user + index;
    ip_sampler s;
    p->status = ip__sampler_init(&s, p->cache, 0);
    if (p->status != IP_OK)
        return;
    ip_cell_output out = {&p->mesh, p->coverage, p->coverage != NULL, 0}; /* no coverage: all */
    uint64_t culled = 0;
    p->triangles = p->points = 0;
    for (size_t i = 0; i < p->count && p->status == IP_OK; i++) {
        unsigned mc;
        const floor_cell *c = &p->cells[i];
        if (!c->owns && !p->coverage) { /* what the engine pays for a cell all of whose
                                           triangles it culls */
            float values[8], lo[3], hi[3], points[12][3];
            if (ip__sampler_cell_case(&s, c->xyz, p->iso, values, &mc) < 0) {
                p->status = s.status;
                break;
            }
            if (mc != 0 && mc != 255) {
                ip__sampler_cell_box(&s, c->xyz, lo, hi);
                ip__mc_cell_edge_points(values, mc, p->iso, lo, hi, points);
                p->points++;
            }
            continue;
        }
        int n = ip__extract_cell(&s, &out, c->xyz, p->iso, &mc, &culled, &p->status);
        if (n > 0)
            p->triangles += (uint64_t)n;
    }
    ip__sampler_free(&s);
}

/* One run over all cells, a part per job on `pool` (the engine's kind of pool: its threads
 * started once, so that a run's time holds no thread start); returns its wall time, or -1 on
 * a failure. */
static double run(ip__pool *pool, part *parts, unsigned threads, uint64_t *triangles)
{
    if (parts[0].coverage)
        ip__coverage_clear(parts[0].coverage, 0, 1);
    double t0 = ip_now_seconds();
    ip__pool_run(pool, threads, extract_part, parts);
    double seconds = ip_now_seconds() - t0;
    *triangles = 0;
    for (unsigned t = 0; t < threads; t++) {
        if (parts[t].status != IP_OK)
            return -1;
        *triangles += parts[t].triangles;
        ip_mesh_clear(&parts[t].mesh);
    }
    return seconds;
}

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* A cell, the brick holding it and its id, for sorting brick by brick. */
typedef struct cell_key {
    uint64_t brick, id;
    floor_cell cell;
} cell_key;

static int compare_keys(const void *a, const void *b)
{
    const cell_key *x = a, *y = b;
    if (x->brick != y->brick)
        return x->brick < y->brick ? -1 : 1;
    return x->id < y->id ? -1 : x->id > y->id;
}

/* The key of the level-0 cell of id `id` (at level 0 its linear index, ip_cell_id()). */
static cell_key key_of(const ip_layout *layout, uint64_t id, uint32_t owns)
{
    uint64_t cx = layout->levels[0].dims[0] - 1, cy = layout->levels[0].dims[1] - 1;
    uint32_t shift = ip__ceil_log2(layout->brick_edge);
    cell_key k = {
        0, id, {{(uint32_t)(id % cx), (uint32_t)(id / cx % cy), (uint32_t)(id / cx / cy)}, owns}};
    uint32_t b[3] = {k.cell.xyz[0] >> shift, k.cell.xyz[1] >> shift, k.cell.xyz[2] >> shift};
    k.brick = ip_brick_global_index(layout, 0, b);
    return k;
}

/* Sorts keys[0..n) brick by brick and drops repeated cells (a cell owns a pixel when any of
 * its copies does); returns the count left. */
static size_t sort_distinct(cell_key *keys, size_t n)
{
    qsort(keys, n, sizeof *keys, compare_keys);
    size_t distinct = 0;
    for (size_t i = 0; i < n; i++) {
        if (distinct > 0 && keys[i].id == keys[distinct - 1].id)
            keys[distinct - 1].cell.owns |= keys[i].cell.owns;
        else
            keys[distinct++] = keys[i];
    }
    return distinct;
}

/* The distinct cells of the triangles that own a pixel of the image of `mesh` (level 0, with
 * cell ids), brick by brick and in id order within a brick, in *out (malloc'd); their count,
 * or -1 on a failure. */
static long owning_cells(const ip_mesh *mesh, const ip_layout *layout, const ip_camera *camera,
                         const double lo[3], const double hi[3], cell_key **out,
                         uint64_t *owning_triangles)
{
    size_t pixels = (size_t)camera->width * camera->height, n = 0;
    size_t triangles = mesh->triangle_count ? mesh->triangle_count : 1;
    uint32_t *owner = malloc(pixels * sizeof *owner);
    unsigned char *owns = calloc(triangles, 1);
    cell_key *keys = malloc(triangles * sizeof *keys);
    ip_error err;
    if (!owner || !owns || !keys ||
        ip_raster_mesh(mesh, camera, lo, hi, owner, NULL, &err) != IP_OK) {
        free(owner);
        free(owns);
        free(keys);
        return -1;
    }
    for (size_t i = 0; i < pixels; i++)
        if (owner[i] != UINT32_MAX)
            owns[owner[i]] = 1;
    free(owner);
    for (uint64_t t = 0; t < mesh->triangle_count; t++)
        if (owns[t])
            keys[n++] = key_of(layout, mesh->cells[t], 1);
    free(owns);
    *owning_triangles = n;
    *out = keys;
    return (long)sort_distinct(keys, n);
}

/* The distinct cells the engine extracts in its first `rays` rays of the view (one thread, no
 * read-ahead, every triangle kept), each marked as owning a pixel when it is among
 * owning[0..n_owning) (sorted), in *out (malloc'd); their count, or -1 with a message. */
static long walked_cells(ip_cache *cache, const ip_layout *layout, const ip_camera *camera,
                         float iso, uint64_t rays, const cell_key *owning, size_t n_owning,
                         cell_key **out)
{
    ip_error err;
    ip_engine_options o;
    ip_engine_options_default(&o);
    o.threads = 1;
    o.prefetch = IP_PREFETCH_OFF;
    o.cull = 0;
    o.cell_ids = 1;
    ip_engine *engine;
    if (ip_engine_create(cache, &o, &engine, &err) != IP_OK) {
        fprintf(stderr, "bench_floor: %s\n", err.message);
        return -1;
    }
    if (ip_engine_begin(engine, camera, iso, &err) != IP_OK ||
        ip_engine_step(engine, rays, 0, NULL, &err) != IP_OK) {
        fprintf(stderr, "bench_floor: %s\n", err.message);
        ip_engine_destroy(engine);
        return -1;
    }
    const ip_mesh *mesh = ip_engine_mesh(engine);
    size_t n = 0;
    cell_key *keys = malloc((mesh->triangle_count ? mesh->triangle_count : 1) * sizeof *keys);
    if (!keys)
        fprintf(stderr, "bench_floor: out of memory\n");
    for (uint64_t t = 0; keys && t < mesh->triangle_count; t++) {
        if (mesh->cells[t] >> 58 != 0) {
            fprintf(stderr, "bench_floor: the view uses coarser levels (adaptive resolution): "
                            "the walked floor is for views of level 0 alone\n");
            free(keys);
            keys = NULL;
            break;
        }
        cell_key k = key_of(layout, mesh->cells[t], 0);
        k.cell.owns = bsearch(&k, owning, n_owning, sizeof *owning, compare_keys) != NULL;
        keys[n++] = k;
    }
    ip_engine_destroy(engine);
    if (!keys)
        return -1;
    *out = keys;
    return (long)sort_distinct(keys, n);
}

/* The child: the full extraction, its image's owning cells (or, with `rays`, the engine's
 * cells), sent down `to` (count, then the cells). Returns the process's exit status. */
static int child(ip_store *store, const ip_camera *camera, float iso, uint64_t rays,
                 const double lo[3], const double hi[3], FILE *to)
{
    ip_error err;
    ip_cache *cache;
    ip_mesh full;
    ip_mesh_init_with_cells(&full);
    if (ip_cache_create(store, (uint64_t)512 << 20, &cache, &err) != IP_OK ||
        ip_extract_full(cache, iso, 0, 0, &full, NULL, &err) != IP_OK) {
        fprintf(stderr, "bench_floor: %s\n", err.message);
        return 1;
    }
    cell_key *keys, *walked = NULL;
    uint64_t owning;
    long count = owning_cells(&full, ip_store_layout(store), camera, lo, hi, &keys, &owning);
    if (count < 0) {
        fprintf(stderr, "bench_floor: out of memory\n");
        return 1;
    }
    printf("full extraction: %" PRIu64 " triangles; %" PRIu64 " own a pixel, from %ld cells\n",
           full.triangle_count, owning, count);
    if (rays > 0) {
        long owned = count;
        count = walked_cells(cache, ip_store_layout(store), camera, iso, rays, keys, (size_t)owned,
                             &walked);
        if (count < 0)
            return 1;
        long owns = 0;
        for (long i = 0; i < count; i++)
            owns += walked[i].cell.owns;
        printf("engine, %" PRIu64 " rays: %ld cells, %ld of them own a pixel (%ld do not)\n", rays,
               count, owns, count - owns);
        free(keys);
        keys = walked;
    }
    fflush(stdout);
    uint64_t n = (uint64_t)count;
    int sent = fwrite(&n, sizeof n, 1, to) == 1;
    for (uint64_t i = 0; i < n && sent; i++)
        sent = fwrite(&keys[i].cell, sizeof keys[i].cell, 1, to) == 1;
    sent = sent && fflush(to) == 0;
    return sent ? 0 : 1;
}

/* The cells, from a child process (child()), in *cells (malloc'd); their count, or -1 with a
 * message on standard error. */
static long cells_from_child(ip_store *store, const ip_camera *camera, float iso, uint64_t rays,
                             const double lo[3], const double hi[3], floor_cell **cells)
{
    int fds[2];
    fflush(stdout);
    if (pipe(fds) != 0)
        return -1;
    pid_t pid = fork();
    if (pid < 0)
        return -1;
    if (pid == 0) {
        close(fds[0]);
        FILE *to = fdopen(fds[1], "wb");
        _exit(to ? child(store, camera, iso, rays, lo, hi, to) : 1);
    }
    close(fds[1]);
    FILE *from = fdopen(fds[0], "rb");
    uint64_t n = 0;
    int ok = from && fread(&n, sizeof n, 1, from) == 1 && n < ((uint64_t)1 << 40) &&
             (*cells = malloc((n ? n : 1) * sizeof **cells)) != NULL &&
             fread(*cells, sizeof **cells, (size_t)n, from) == (size_t)n;
    if (from)
        fclose(from);
    else
        close(fds[0]);
    int status;
    if (waitpid(pid, &status, 0) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0 || !ok) {
        fprintf(stderr, "bench_floor: finding the cells failed\n");
        return -1;
    }
    return (long)n;
}

int main(int argc, char **argv)
{
    uint32_t width, height;
    int cover = argc == 9 && strcmp(argv[8], "cover") == 0;
    if ((argc != 7 && argc != 8 && !cover) ||
        sscanf(argv[4], "%" SCNu32 "x%" SCNu32, &width, &height) != 2) {
        fputs(usage, stderr);
        return 2;
    }
    float iso = strtof(argv[2], NULL);
    unsigned threads = (unsigned)strtoul(argv[5], NULL, 10);
    int repeats = atoi(argv[6]);
    uint64_t rays = 0;
    if (argc >= 8) { /* RAYS: a positive count */
        char *end;
        rays = strtoull(argv[7], &end, 10);
        if (end == argv[7] || *end || rays == 0 || argv[7][0] == '-') {
            fputs(usage, stderr);
            return 2;
        }
    }
    if (threads < 1 || threads > IP_MAX_THREADS || repeats < 0) {
        fputs(usage, stderr);
        return 2;
    }
    ip_error err;
    ip_store *store;
    ip_cache *cache;
    ip_camera camera;
    double lo[3], hi[3];
    if (ip_store_open(argv[1], &store, &err) != IP_OK) {
        fprintf(stderr, "bench_floor: %s\n", err.message);
        return 1;
    }
    const ip_layout *layout = ip_store_layout(store);
    ip_layout_world_box(layout, lo, hi);
    if (ip_camera_fit_axis(lo, hi, argv[3], 30.0, width, height, &camera, &err) != IP_OK) {
        fprintf(stderr, "bench_floor: %s\n", err.message);
        return 1;
    }
    /* the cells, found in a child process, so that run 0 finds this one as a fresh process
     * would: no brick decoded, no memory ever used for them */
    floor_cell *cells = NULL;
    long count = cells_from_child(store, &camera, iso, rays, lo, hi, &cells);
    if (count < 0)
        return 1;
    if (ip_cache_create(store, (uint64_t)512 << 20, &cache, &err) != IP_OK) {
        fprintf(stderr, "bench_floor: %s\n", err.message);
        return 1;
    }
    ip_coverage coverage;
    memset(&coverage, 0, sizeof coverage);
    if (cover && ip__coverage_prepare(&coverage, &camera, lo, hi) != IP_OK) {
        fprintf(stderr, "bench_floor: out of memory\n");
        return 1;
    }
    part parts[IP_MAX_THREADS];
    for (unsigned t = 0; t < threads; t++) {
        size_t first = (size_t)count * t / threads, end = (size_t)count * (t + 1) / threads;
        parts[t] = (part){.cache = cache,
                          .cells = cells + first,
                          .count = end - first,
                          .coverage = cover ? &coverage : NULL,
                          .iso = iso,
                          .status = IP_OK};
        ip_mesh_init(&parts[t].mesh);
    }
    ip__pool *pool;
    double *times = malloc(((size_t)repeats + 1) * sizeof *times);
    if (!times || ip__pool_create(threads, &pool, &err) != IP_OK) {
        fprintf(stderr, "bench_floor: out of memory\n");
        return 1;
    }
    uint64_t triangles = 0;
    for (int r = 0; r <= repeats; r++) {
        times[r] = run(pool, parts, threads, &triangles);
        if (times[r] < 0) {
            fprintf(stderr, "bench_floor: a brick could not be read\n");
            return 1;
        }
        uint64_t points = 0;
        for (unsigned t = 0; t < threads; t++)
            points += parts[t].points;
        printf("run %d: %.4f s, %ld cells, %" PRIu64 " triangles", r, times[r], count, triangles);
        if (rays > 0 && !cover)
            printf(", %" PRIu64 " cells edge points only", points);
        if (r == 0) {
            ip_cache_stats cs;
            ip_cache_get_stats(cache, &cs);
            printf(" (empty cache: %" PRIu64 " bricks decoded, %" PRIu64 " bytes)", cs.misses,
                   cs.bytes_decompressed);
        }
        printf("\n");
    }
    ip__pool_destroy(pool);
    if (repeats > 0) {
        qsort(times + 1, (size_t)repeats, sizeof *times, compare_doubles);
        printf("median %.4f s [%.4f-%.4f] of %d warm runs, %u threads\n",
               times[1 + (repeats - 1) / 2], times[1], times[repeats], repeats, threads);
    }
    for (unsigned t = 0; t < threads; t++)
        ip_mesh_free(&parts[t].mesh);
    free(times);
    free(cells);
    ip__coverage_free(&coverage);
    ip_cache_destroy(cache);
    ip_store_close(store);
    return 0;
}

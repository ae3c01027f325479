/* SPDX-License-Identifier: BSD-3-Clause */
/* The engine against the paper's guarantee: once every pixel has had its ray, the image of the
 * progressive mesh equals the image of the full extraction (same coverage, >= 99.99 % equal
 * pixels), and every progressive triangle is a triangle of the full result (same cell, same
 * vertices), with occlusion on (the default) as off. Also: occlusion extracts less hidden
 * surface; empty space reads summaries only; cancel and restart leave nothing stale; the image
 * cast region by region on two engines composites to the full image. */
#include <dirent.h>
#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <unistd.h>

#include "check.h"
#include "coverage.h"
#include "depth_queue.h"
#include "mc.h"
#include "reach.h"
#include "isoprop/bricker.h"
#include "isoprop/engine.h"
#include "isoprop/generate.h"
#include "isoprop/render.h"
#include "volumes.h"

/* The stated tolerance of adaptive resolution against full resolution, on the long gyroid of
 * check_lod(): pixels whose coverage changes, in % of covered pixels, and the mean absolute
 * colour difference over the image, in % of full scale. */
#define LOD_COVERAGE_TOLERANCE_PCT 2
#define LOD_COLOUR_TOLERANCE_PCT 1

typedef struct scene {
    ip_store *store;
    ip_cache *cache;
    double lo[3], hi[3];
} scene;

static void open_scene(const char *ibv, scene *s)
{
    ip_error err;
    REQUIRE(ip_store_open(ibv, &s->store, &err) == IP_OK);
    REQUIRE(ip_cache_create(s->store, 256ull << 20, &s->cache, &err) == IP_OK);
    const ip_layout *l = ip_store_layout(s->store);
    ip_layout_world_box(l, s->lo, s->hi);
}

static void close_scene(scene *s)
{
    ip_cache_destroy(s->cache);
    ip_store_close(s->store);
}

/* Generates a field, writes it as raw and bricks it with small bricks (many brick faces). */
static void make_volume(const char *dir, ip_field field, uint32_t n, ip_type type, uint32_t edge,
                        char *ibv, size_t size)
{
    ip_gen_params p = {sizeof(ip_gen_params), field, {n, n + 3, n - 5}, type, 0.0, 1};
    char name[256], raw[4096];
    ip_error err;
    REQUIRE(ip_raw_file_name(name, sizeof name, ip_field_name(field), p.dims, type) == IP_OK);
    snprintf(raw, sizeof raw, "%s/%s", dir, name);
    REQUIRE(ip_generate_write(&p, raw, 1, &err) == IP_OK);
    snprintf(ibv, size, "%s/%s.b%u.ibv", dir, ip_field_name(field), edge);
    ip_input_desc d;
    ip_bricker_options o;
    REQUIRE(ip_input_describe(raw, NULL, &d, &err) == IP_OK);
    d.spacing[2] = 1.25; /* anisotropic: world coordinates must honour spacing */
    ip_bricker_options_default(&o);
    o.brick_edge = edge;
    o.subblock_edge = edge / 4 ? edge / 4 : 1;
    o.force = 1;
    REQUIRE(ip_bricker_run(&d, ibv, &o, NULL, &err) == IP_OK);
}

/* Two triangles are the same when they come from the same cell and have the same vertices
 * and normals. */
static int same_triangle(const ip_mesh *a, uint64_t i, const ip_mesh *b, uint64_t j)
{
    return a->cells[i] == b->cells[j] &&
           memcmp(&a->positions[9 * i], &b->positions[9 * j], 9 * sizeof(float)) == 0 &&
           memcmp(&a->normals[9 * i], &b->normals[9 * j], 9 * sizeof(int16_t)) == 0;
}

static int compare_cells(const void *x, const void *y)
{
    uint64_t a = *(const uint64_t *)x, b = *(const uint64_t *)y;
    return (a > b) - (a < b);
}

/* Every triangle of `part` is a triangle of `full`: full's triangles of a cell are contiguous
 * and in a fixed order, so a cell's triangles are looked up by binary search over cell ids. */
static uint64_t triangles_not_in(const ip_mesh *part, const ip_mesh *full)
{
    uint64_t(*keys)[2] = malloc(full->triangle_count * sizeof *keys);
    REQUIRE(keys || full->triangle_count == 0);
    for (uint64_t i = 0; i < full->triangle_count; i++) {
        keys[i][0] = full->cells[i];
        keys[i][1] = i;
    }
    qsort(keys, full->triangle_count, sizeof *keys, compare_cells);
    uint64_t missing = 0;
    for (uint64_t i = 0; i < part->triangle_count; i++) {
        uint64_t lo = 0, hi = full->triangle_count;
        while (lo < hi) {
            uint64_t mid = (lo + hi) / 2;
            if (keys[mid][0] < part->cells[i])
                lo = mid + 1;
            else
                hi = mid;
        }
        int found = 0;
        for (uint64_t k = lo; k < full->triangle_count && keys[k][0] == part->cells[i]; k++)
            found |= same_triangle(part, i, full, keys[k][1]);
        missing += !found;
    }
    free(keys);
    return missing;
}

static void run_all_rays(ip_engine *e, const ip_camera *cam, float iso, ip_engine_counts *t)
{
    ip_error err;
    REQUIRE(ip_engine_begin(e, cam, iso, &err) == IP_OK);
    uint64_t batch = 1;
    while (!ip_engine_done(e)) {
        REQUIRE(ip_engine_step(e, batch, 0, NULL, &err) == IP_OK);
        batch *= 2;
    }
    ip_engine_totals(e, t);
}

/* The guarantee for one volume, view and isovalue. */
static void check_view(scene *s, const char *what, const char *axis, float iso, uint32_t w,
                       uint32_t h)
{
    ip_error err;
    ip_camera cam;
    REQUIRE(ip_camera_fit_axis(s->lo, s->hi, axis, 30.0, w, h, &cam, &err) == IP_OK);
    ip_engine *e;
    ip_engine_options o;
    ip_engine_options_default(&o);
    o.lod = 0; /* the exact-image guarantee is for full resolution */
    o.cell_ids = 1;
    REQUIRE(ip_engine_create(s->cache, &o, &e, &err) == IP_OK);
    ip_engine_counts t;
    run_all_rays(e, &cam, iso, &t);
    const ip_mesh *part = ip_engine_mesh(e);
    REQUIRE(part->with_cells && (part->cells || part->triangle_count == 0));
    ip_mesh full;
    ip_mesh_init_with_cells(&full);
    ip_engine_counts fc;
    REQUIRE(ip_extract_full(s->cache, iso, 0, 0, &full, &fc, &err) == IP_OK);
    CHECK_EQ(t.rays, (uint64_t)w * h);
    CHECK_LT(t.retired, t.rays);
    CHECK_GT(t.nodes, 0);
    CHECK_EQ(part->triangle_count, t.triangles);
    CHECK_EQ(full.triangle_count, fc.triangles);
    CHECK_MSG(part->triangle_count > 0 && part->triangle_count <= full.triangle_count,
              "%s %s: %llu progressive, %llu full triangles", what, axis,
              (unsigned long long)part->triangle_count, (unsigned long long)full.triangle_count);
    uint64_t missing = triangles_not_in(part, &full);
    CHECK_MSG(missing == 0, "%s %s: %llu progressive triangles are not full triangles", what, axis,
              (unsigned long long)missing);

    size_t n = (size_t)w * h;
    uint32_t *ia = malloc(n * 4), *ib = malloc(n * 4);
    uint8_t *ca = malloc(n * 4), *cb = malloc(n * 4);
    REQUIRE(ia && ib && ca && cb);
    REQUIRE(ip_raster_mesh(part, &cam, s->lo, s->hi, ia, ca, &err) == IP_OK);
    REQUIRE(ip_raster_mesh(&full, &cam, s->lo, s->hi, ib, cb, &err) == IP_OK);
    size_t covered = 0, coverage_diff = 0, pixel_diff = 0;
    for (size_t i = 0; i < n; i++) {
        int a = ia[i] != UINT32_MAX, b = ib[i] != UINT32_MAX;
        covered += b;
        coverage_diff += a != b;
        pixel_diff += memcmp(ca + 4 * i, cb + 4 * i, 4) != 0;
    }
    double same = covered ? 100.0 * (double)(n - pixel_diff) / (double)n : 0;
    printf("test_engine: %s %s iso %g: %llu rays (%llu retired), %llu seeds, %llu of %llu "
           "triangles, %zu covered pixels, %zu coverage and %zu colour differences\n",
           what, axis, (double)iso, (unsigned long long)t.rays, (unsigned long long)t.retired,
           (unsigned long long)t.seeds, (unsigned long long)part->triangle_count,
           (unsigned long long)full.triangle_count, covered, coverage_diff, pixel_diff);
    CHECK_MSG(covered > n / 50, "%s %s: the surface covers only %zu pixels", what, axis, covered);
    CHECK_MSG(coverage_diff == 0, "%s %s: %zu pixels differ in coverage", what, axis,
              coverage_diff);
    CHECK_MSG(same >= 99.99, "%s %s: %.4f %% identical pixels", what, axis, same);
    free(ia);
    free(ib);
    free(ca);
    free(cb);
    ip_mesh_free(&full);
    ip_engine_destroy(e);
}

/* The long volume check_lod() and the checks after it look at, a gyroid of 24 x 24 x 512
 * samples in bricks of 8: generated and bricked into dir/long.ibv by the first that runs. */
static void long_volume(const char *dir, char *ibv, size_t size)
{
    static int made;
    snprintf(ibv, size, "%s/long.ibv", dir);
    if (made)
        return;
    char raw[4200];
    ip_gen_params p = {sizeof(ip_gen_params), IP_FIELD_GYROID, {24, 24, 512}, IP_UINT8, 0.0, 1};
    ip_error err;
    snprintf(raw, sizeof raw, "%s/long_24x24x512_uint8.raw", dir);
    REQUIRE(ip_generate_write(&p, raw, 1, &err) == IP_OK);
    ip_input_desc d;
    ip_bricker_options bo;
    REQUIRE(ip_input_describe(raw, NULL, &d, &err) == IP_OK);
    ip_bricker_options_default(&bo);
    bo.brick_edge = 8;
    bo.subblock_edge = 4;
    bo.force = 1;
    REQUIRE(ip_bricker_run(&d, ibv, &bo, NULL, &err) == IP_OK);
    made = 1;
}

/* Adaptive resolution on a long volume seen end-on, whose far half projects to less than a
 * pixel per cell: the far part comes from coarse levels, so fewer level-0 bricks are decoded,
 * and the image stays close to the full-resolution one. */
static void check_lod(const char *dir)
{
    char ibv[4200];
    ip_error err;
    long_volume(dir, ibv, sizeof ibv);
    scene s;
    open_scene(ibv, &s);
    ip_camera cam;
    REQUIRE(ip_camera_fit_axis(s.lo, s.hi, "-z", 30.0, 64, 64, &cam, &err) == IP_OK);
    uint32_t *index[2];
    uint8_t *rgba[2];
    uint64_t fine_misses[2], coarse_misses[2];
    for (int lod = 0; lod < 2; lod++) {
        ip_cache *cache;
        REQUIRE(ip_cache_create(s.store, 64ull << 20, &cache, &err) == IP_OK);
        ip_engine *e;
        ip_engine_options o;
        ip_engine_options_default(&o);
        o.lod = lod;
        REQUIRE(ip_engine_create(cache, &o, &e, &err) == IP_OK);
        ip_engine_counts t;
        run_all_rays(e, &cam, 127.5f, &t);
        if (lod) {
            double d1 = ip_engine_lod_distance(e, 1);
            CHECK_MSG(d1 > 0 && d1 < s.hi[2], "D[1] = %g", d1);
        }
        ip_cache_stats st;
        ip_cache_get_stats(cache, &st);
        fine_misses[lod] = st.level[0].misses;
        coarse_misses[lod] = st.misses - st.level[0].misses;
        index[lod] = malloc(64 * 64 * 4);
        rgba[lod] = malloc(64 * 64 * 4);
        REQUIRE(ip_raster_mesh(ip_engine_mesh(e), &cam, s.lo, s.hi, index[lod], rgba[lod], &err) ==
                IP_OK);
        ip_engine_destroy(e);
        ip_cache_destroy(cache);
    }
    size_t covered = 0, coverage_diff = 0;
    double colour_diff = 0;
    for (size_t i = 0; i < 64 * 64; i++) {
        covered += index[0][i] != UINT32_MAX;
        coverage_diff += (index[0][i] != UINT32_MAX) != (index[1][i] != UINT32_MAX);
        for (int c = 0; c < 3; c++)
            colour_diff += abs((int)rgba[0][4 * i + c] - (int)rgba[1][4 * i + c]);
    }
    colour_diff /= 64.0 * 64.0 * 3.0 * 255.0;
    printf("test_engine: lod: level-0 bricks decoded %llu (off) -> %llu (on), coarse %llu; "
           "coverage differs on %zu of %zu pixels, mean colour difference %.2f %%\n",
           (unsigned long long)fine_misses[0], (unsigned long long)fine_misses[1],
           (unsigned long long)coarse_misses[1], coverage_diff, covered, 100 * colour_diff);
    CHECK_EQ(coarse_misses[0], 0);
    CHECK_GT(coarse_misses[1], 0);
    CHECK_MSG(fine_misses[1] * 10 < fine_misses[0] * 7, "lod decoded %llu of %llu fine bricks",
              (unsigned long long)fine_misses[1], (unsigned long long)fine_misses[0]);
    CHECK_MSG(coverage_diff * 100 <= covered * LOD_COVERAGE_TOLERANCE_PCT,
              "lod changes coverage on %zu of %zu pixels", coverage_diff, covered);
    CHECK_MSG(colour_diff * 100 <= LOD_COLOUR_TOLERANCE_PCT, "lod colour difference %.2f %%",
              100 * colour_diff);
    for (int lod = 0; lod < 2; lod++) {
        free(index[lod]);
        free(rgba[lod]);
    }
    close_scene(&s);
}

/* Adaptive resolution's guarantee: once every ray has been cast, the progressive mesh holds
 * only triangles of the full extraction at the view's levels (ip_extract_full_lod(): each
 * level's cells within its distance band), and its image is that extraction's, pixel for
 * pixel, on 1 and 2 threads, with occlusion on and off. The long gyroid seen end-on and from
 * an angle, at a pixel error of 1 and 2, uses 3 to 5 levels. */
static void check_lod_exact(const char *dir)
{
    char ibv[4200];
    long_volume(dir, ibv, sizeof ibv);
    scene s;
    open_scene(ibv, &s);
    static const struct {
        const char *axis;
        double azimuth, elevation, pixel_error;
        uint32_t w, h;
    } views[] = {{"-z", 0, 0, 1, 64, 64}, {"-z", 35, 20, 2, 96, 72}, {"+z", -50, 10, 1, 80, 60}};
    const uint32_t n = 96 * 72;
    uint32_t *ia = malloc(n * 4), *ib = malloc(n * 4);
    uint8_t *ca = malloc(n * 4), *cb = malloc(n * 4);
    REQUIRE(ia && ib && ca && cb);
    for (size_t v = 0; v < sizeof views / sizeof views[0]; v++) {
        ip_error err;
        ip_camera cam;
        REQUIRE(ip_camera_fit_axis(s.lo, s.hi, views[v].axis, 30.0, views[v].w, views[v].h, &cam,
                                   &err) == IP_OK);
        ip_camera_orbit(&cam, views[v].azimuth, views[v].elevation);
        ip_mesh full;
        ip_mesh_init_with_cells(&full);
        REQUIRE(ip_extract_full_lod(s.cache, 127.5f, &cam, views[v].pixel_error, 2, NULL, 0, &full,
                                    NULL, &err) == IP_OK);
        REQUIRE(ip_raster_mesh(&full, &cam, s.lo, s.hi, ib, cb, &err) == IP_OK);
        uint32_t pixels = views[v].w * views[v].h, levels = 0;
        size_t covered = 0;
        for (uint32_t i = 0; i < pixels; i++)
            covered += ib[i] != UINT32_MAX;
        for (int threads = 1; threads <= 2; threads++)
            for (int occlusion = 0; occlusion < 2; occlusion++) {
                ip_engine *e;
                ip_engine_options o;
                ip_engine_options_default(&o);
                o.pixel_error = views[v].pixel_error;
                o.cell_ids = 1;
                o.threads = (unsigned)threads;
                o.occlusion = occlusion;
                REQUIRE(ip_engine_create(s.cache, &o, &e, &err) == IP_OK);
                ip_engine_counts t;
                run_all_rays(e, &cam, 127.5f, &t);
                while (levels < IP_MAX_LEVELS && isfinite(ip_engine_lod_distance(e, levels)))
                    levels++;
                const ip_mesh *part = ip_engine_mesh(e);
                uint64_t missing = triangles_not_in(part, &full);
                REQUIRE(ip_raster_mesh(part, &cam, s.lo, s.hi, ia, ca, &err) == IP_OK);
                size_t differ = 0;
                for (uint32_t i = 0; i < pixels; i++)
                    differ += ia[i] == UINT32_MAX ? ib[i] != UINT32_MAX
                                                  : memcmp(ca + 4 * i, cb + 4 * i, 4) != 0;
                CHECK_MSG(missing == 0 && differ == 0,
                          "lod view %zu, %d threads, occlusion %d: %llu triangles not in the "
                          "full extraction at its levels, %zu pixels differ",
                          v, threads, occlusion, (unsigned long long)missing, differ);
                CHECK_GT(part->triangle_count, 0);
                CHECK_LE(part->triangle_count, full.triangle_count);
                ip_engine_destroy(e);
            }
        printf("test_engine: lod exact, view %zu: %u levels, %llu triangles in the full "
               "extraction at them, %zu of %u pixels covered\n",
               v, levels, (unsigned long long)full.triangle_count, covered, pixels);
        CHECK_MSG(levels >= 3 && covered > pixels / 10, "lod view %zu: %u levels, %zu pixels", v,
                  levels, covered);
        ip_mesh_free(&full);
    }
    free(ia);
    free(ib);
    free(ca);
    free(cb);
    close_scene(&s);
}

/* Reuse across views (engine.h, "Reuse"): an orbit with zooms that change the levels' bands,
 * each view's image once every ray has been cast is the full extraction's at its levels, pixel
 * for pixel, its triangles all of that extraction, while later views keep triangles of the
 * ones before; on 1 and 2 threads, culling on and off. */
static void check_reuse_exact(const char *dir)
{
    char ibv[4200];
    long_volume(dir, ibv, sizeof ibv);
    scene s;
    open_scene(ibv, &s);
    const uint32_t w = 96, h = 72, n = w * h;
    uint32_t *ia = malloc(n * 4), *ib = malloc(n * 4);
    uint8_t *ca = malloc(n * 4), *cb = malloc(n * 4);
    REQUIRE(ia && ib && ca && cb);
    for (int threads = 1; threads <= 2; threads++)
        for (int cull = 0; cull < 2; cull++) {
            ip_error err;
            ip_engine *e;
            ip_engine_options o;
            ip_engine_options_default(&o);
            o.threads = (unsigned)threads;
            o.cull = cull;
            o.reuse = 1;
            REQUIRE(ip_engine_create(s.cache, &o, &e, &err) == IP_OK);
            ip_camera cam;
            REQUIRE(ip_camera_fit_axis(s.lo, s.hi, "-z", 30.0, w, h, &cam, &err) == IP_OK);
            ip_camera_orbit(&cam, 20, 25);
            uint64_t kept_views = 0;
            for (int step = 0; step < 8; step++) {
                if (step > 0) {
                    ip_camera_orbit(&cam, 15, step % 3 == 0 ? -5 : 0);
                    double zoom = step < 5 ? 1.25 : 0.8; /* in, then out again */
                    for (int a = 0; a < 3; a++)
                        cam.eye[a] = cam.target[a] + (cam.eye[a] - cam.target[a]) / zoom;
                }
                ip_engine_counts t;
                run_all_rays(e, &cam, 127.5f, &t);
                kept_views += t.kept > 0;
                ip_mesh full;
                ip_mesh_init_with_cells(&full);
                REQUIRE(ip_extract_full_lod(s.cache, 127.5f, &cam, 1.0, 2, NULL, 0, &full, NULL,
                                            &err) == IP_OK);
                REQUIRE(ip_raster_mesh(&full, &cam, s.lo, s.hi, ib, cb, &err) == IP_OK);
                const ip_mesh *part = ip_engine_mesh(e);
                uint64_t missing = triangles_not_in(part, &full);
                REQUIRE(ip_raster_mesh(part, &cam, s.lo, s.hi, ia, ca, &err) == IP_OK);
                size_t differ = 0;
                for (uint32_t i = 0; i < n; i++)
                    differ += ia[i] == UINT32_MAX ? ib[i] != UINT32_MAX
                                                  : memcmp(ca + 4 * i, cb + 4 * i, 4) != 0;
                CHECK_MSG(missing == 0 && differ == 0,
                          "reuse, %d threads, cull %d, view %d: %llu triangles not in the full "
                          "extraction at its levels, %zu pixels differ (%llu kept)",
                          threads, cull, step, (unsigned long long)missing, differ,
                          (unsigned long long)t.kept);
                CHECK_EQ(t.triangles, part->triangle_count);
                ip_mesh_free(&full);
            }
            printf("test_engine: reuse, %d threads, cull %d: %llu of 7 views kept triangles\n",
                   threads, cull, (unsigned long long)kept_views);
            CHECK_MSG(kept_views >= 5,
                      "reuse, %d threads, cull %d: %llu of 7 views kept "
                      "triangles",
                      threads, cull, (unsigned long long)kept_views);
            /* another isovalue keeps nothing */
            ip_engine_counts t;
            run_all_rays(e, &cam, 100.5f, &t);
            CHECK_EQ(t.kept, 0);
            ip_engine_destroy(e);
        }
    free(ia);
    free(ib);
    free(ca);
    free(cb);
    close_scene(&s);
}

/* ip_engine_read_ahead(): refused before the view is done; once it is, the reader loads bricks
 * of the predicted view (the other side of the volume) into the cache, and the next begin stops
 * it; the mesh of the view done stays. */
static void check_read_ahead(const char *dir)
{
    char ibv[4200];
    long_volume(dir, ibv, sizeof ibv);
    ip_error err;
    ip_store *store;
    ip_cache *cache;
    REQUIRE(ip_store_open(ibv, &store, &err) == IP_OK);
    REQUIRE(ip_cache_create(store, 256ull << 20, &cache, &err) == IP_OK);
    double lo[3], hi[3];
    ip_layout_world_box(ip_store_layout(store), lo, hi);
    ip_engine_options o;
    ip_engine_options_default(&o);
    o.threads = 1;
    o.prefetch = IP_PREFETCH_ON;
    o.lod = 0; /* level 0 alone: the far side's bricks are not those of the near side */
    ip_engine *e;
    REQUIRE(ip_engine_create(cache, &o, &e, &err) == IP_OK);
    ip_camera a, b;
    REQUIRE(ip_camera_fit_axis(lo, hi, "-x", 30.0, 96, 72, &a, &err) == IP_OK);
    REQUIRE(ip_camera_fit_axis(lo, hi, "+x", 30.0, 96, 72, &b, &err) == IP_OK);
    REQUIRE(ip_engine_begin(e, &a, 127.5f, &err) == IP_OK);
    CHECK_EQ(ip_engine_read_ahead(e, &b, &err), IP_ERR_ARGUMENT); /* not done yet */
    while (!ip_engine_done(e))
        REQUIRE(ip_engine_step(e, 0, 0, NULL, &err) == IP_OK);
    uint64_t triangles = ip_engine_mesh(e)->triangle_count;
    ip_cache_stats before, after;
    ip_cache_get_stats(cache, &before);
    REQUIRE(ip_engine_read_ahead(e, &b, &err) == IP_OK);
    for (int i = 0; i < 200; i++) { /* up to 2 s for the reader */
        ip_cache_get_stats(cache, &after);
        if (after.prefetched > before.prefetched)
            break;
        usleep(10000);
    }
    CHECK_MSG(after.prefetched > before.prefetched,
              "read ahead: %llu bricks loaded ahead (%llu of %llu touched before)",
              (unsigned long long)(after.prefetched - before.prefetched),
              (unsigned long long)before.bricks_touched, (unsigned long long)before.bricks_total);
    CHECK_EQ(ip_engine_mesh(e)->triangle_count, triangles);
    ip_camera bad = b;
    bad.fov_y = 0;
    CHECK_EQ(ip_engine_read_ahead(e, &bad, &err), IP_ERR_ARGUMENT);
    ip_engine_counts t;
    run_all_rays(e, &b, 127.5f, &t); /* begin stops the reader; the view as ever */
    CHECK_EQ(t.rays, 96 * 72);
    ip_engine_destroy(e);
    ip_cache_destroy(cache);
    ip_store_close(store);
}

typedef struct canceller {
    ip_engine *engine;
    atomic_int stop;
} canceller;

static void *cancel_soon(void *p)
{
    canceller *c = p;
    for (int i = 0; i < 200 && !atomic_load(&c->stop); i++)
        sched_yield();
    ip_engine_cancel(c->engine);
    return NULL;
}

/* Many threads, cancelled from another thread mid-step, then run to the end: the result covers
 * exactly the pixels one thread covers. Run under ThreadSanitizer by the test suite. */
static void check_threads(scene *s, float iso)
{
    ip_error err;
    ip_camera cam;
    REQUIRE(ip_camera_fit_axis(s->lo, s->hi, "+y", 30.0, 90, 70, &cam, &err) == IP_OK);
    uint32_t *index[2];
    for (int run = 0; run < 2; run++) {
        ip_engine *e;
        ip_engine_options o;
        ip_engine_options_default(&o);
        o.lod = 0;
        o.threads = run == 0 ? 1 : 8;
        REQUIRE(ip_engine_create(s->cache, &o, &e, &err) == IP_OK);
        if (run == 1) {
            for (int round = 0; round < 3; round++) { /* cancel in flight, several times */
                REQUIRE(ip_engine_begin(e, &cam, iso + 0.05f * (float)round, &err) == IP_OK);
                canceller c = {e, 0};
                pthread_t t;
                REQUIRE(pthread_create(&t, NULL, cancel_soon, &c) == 0);
                ip_status st = IP_OK;
                while (st == IP_OK && !ip_engine_done(e))
                    st = ip_engine_step(e, 500, 0, NULL, &err);
                atomic_store(&c.stop, 1);
                pthread_join(t, NULL);
                CHECK(st == IP_OK || st == IP_ERR_CANCELLED);
            }
        }
        ip_engine_counts t;
        run_all_rays(e, &cam, iso, &t);
        index[run] = malloc(90 * 70 * 4);
        REQUIRE(ip_raster_mesh(ip_engine_mesh(e), &cam, s->lo, s->hi, index[run], NULL, &err) ==
                IP_OK);
        ip_engine_destroy(e);
    }
    size_t differ = 0, covered = 0;
    for (size_t i = 0; i < 90 * 70; i++) {
        covered += index[0][i] != UINT32_MAX;
        differ += (index[0][i] != UINT32_MAX) != (index[1][i] != UINT32_MAX);
    }
    CHECK_MSG(differ == 0 && covered > 0, "8 threads cover %zu pixels differently (of %zu)", differ,
              covered);
    free(index[0]);
    free(index[1]);
}

/* A ray through empty space reads summaries only: no brick is decoded. */
static void check_empty_space(scene *s, float iso)
{
    ip_error err;
    ip_cache *cache;
    REQUIRE(ip_cache_create(s->store, 64ull << 20, &cache, &err) == IP_OK);
    ip_engine *e;
    ip_engine_options o;
    ip_engine_options_default(&o);
    REQUIRE(ip_engine_create(cache, &o, &e, &err) == IP_OK);
    /* a narrow view past the sphere's edge, through the volume's empty corner region */
    ip_camera cam = {{-40, -40, -40},
                     {s->hi[0] * 0.02, s->hi[1] * 0.02, s->hi[2] * 0.98},
                     {0, 0, 1},
                     2.0,
                     16,
                     16};
    ip_engine_counts t;
    run_all_rays(e, &cam, iso, &t);
    ip_cache_stats st;
    ip_cache_get_stats(cache, &st);
    CHECK_EQ(t.rays, 256);
    CHECK_EQ(t.seeds, 0);
    CHECK_MSG(st.misses == 0 && st.bricks_touched == 0, "empty space decoded %llu bricks",
              (unsigned long long)st.misses);
    /* and the same engine on a view of the sphere does decode bricks */
    REQUIRE(ip_camera_fit_axis(s->lo, s->hi, "+z", 30.0, 32, 32, &cam, &err) == IP_OK);
    run_all_rays(e, &cam, iso, &t);
    ip_cache_get_stats(cache, &st);
    CHECK_GT(t.seeds, 0);
    CHECK_GT(st.misses, 0);
    ip_engine_destroy(e);
    ip_cache_destroy(cache);
}

/* Cancelling mid-way and starting again gives exactly what a fresh engine gives (with one
 * thread, so that the order is fixed). */
static void check_cancel_restart(scene *s, float iso_a, float iso_b)
{
    ip_error err;
    ip_camera cam;
    REQUIRE(ip_camera_fit_axis(s->lo, s->hi, "-x", 30.0, 96, 80, &cam, &err) == IP_OK);
    ip_engine *e, *fresh;
    ip_engine_options o;
    ip_engine_options_default(&o);
    o.threads = 1; /* one thread extracts the same cells in the same order every time */
    o.lod = 0;
    o.cell_ids = 1;
    REQUIRE(ip_engine_create(s->cache, &o, &e, &err) == IP_OK);
    REQUIRE(ip_engine_create(s->cache, &o, &fresh, &err) == IP_OK);
    REQUIRE(ip_engine_begin(e, &cam, iso_a, &err) == IP_OK);
    REQUIRE(ip_engine_step(e, 300, 0, NULL, &err) == IP_OK);
    CHECK_GT(ip_engine_mesh(e)->triangle_count, 0);
    ip_engine_cancel(e);
    CHECK_EQ(ip_engine_step(e, 0, 0, NULL, &err), IP_ERR_CANCELLED);
    CHECK(!ip_engine_done(e));
    ip_engine_counts ta, tb;
    run_all_rays(e, &cam, iso_b, &ta);
    run_all_rays(fresh, &cam, iso_b, &tb);
    const ip_mesh *a = ip_engine_mesh(e), *b = ip_engine_mesh(fresh);
    int same = a->triangle_count == b->triangle_count && ta.rays == tb.rays && ta.seeds == tb.seeds;
    for (uint64_t i = 0; same && i < a->triangle_count; i++)
        same = same_triangle(a, i, b, i);
    CHECK_MSG(same, "restart: %llu triangles against %llu from a fresh engine",
              (unsigned long long)a->triangle_count, (unsigned long long)b->triangle_count);
    ip_engine_destroy(e);
    ip_engine_destroy(fresh);
}

/* A number in [0, 1) from the generator state *seed. */
static double unit_random(uint64_t *seed)
{
    *seed = *seed * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(*seed >> 11) / 9007199254740992.0;
}

/* The coverage tests' camera (64x48 pixels, the eye at z = -10 looking along +z) and an
 * empty coverage for it, of a volume box around the eye (-5..5 in x and y, -20..20 in z). */
static void test_coverage(ip_camera *cam, ip_camera_basis *basis, ip_coverage *c)
{
    *cam = (ip_camera){{0, 0, -10}, {0, 0, 0}, {0, 1, 0}, 60.0, 64, 48};
    ip_camera_basis_of(cam, basis);
    double lo[3] = {-5, -5, -20}, hi[3] = {5, 5, 20};
    memset(c, 0, sizeof *c);
    REQUIRE(ip__coverage_reset(c, cam, lo, hi) == IP_OK);
}

/* The coverage buffer's test on its own: a wall of two triangles hides a box behind it, but
 * never a box in front of it, one crossing the near plane, one behind the eye, or one whose
 * projection reaches past the wall. */
static void check_coverage_box_test(void)
{
    ip_camera cam;
    ip_camera_basis basis;
    ip_coverage c;
    test_coverage(&cam, &basis, &c); /* the volume's box holds the eye */
    double a[3] = {-0.5, -0.5, 1}, b[3] = {0.5, 0.5, 2};
    CHECK(!ip__coverage_hides(&c, a, b)); /* nothing recorded yet */
    const float wall[18] = {-2, -2, 0, 2, -2, 0, 2, 2, 0, -2, -2, 0, 2, 2, 0, -2, 2, 0};
    ip__coverage_add(&c, wall, 2);
    CHECK(ip__coverage_hides(&c, a, b)); /* behind the wall, within its image */
    double front_lo[3] = {-0.5, -0.5, -1}, front_hi[3] = {0.5, 0.5, -0.5};
    CHECK(!ip__coverage_hides(&c, front_lo, front_hi)); /* in front of the wall */
    double touch_lo[3] = {-0.5, -0.5, 0}, touch_hi[3] = {0.5, 0.5, 1};
    CHECK(!ip__coverage_hides(&c, touch_lo, touch_hi)); /* its nearest face on the wall */
    double cross_lo[3] = {-0.5, -0.5, -10.5}, cross_hi[3] = {0.5, 0.5, 3};
    CHECK(!ip__coverage_hides(&c, cross_lo, cross_hi)); /* crosses the near plane */
    double back_lo[3] = {-0.5, -0.5, -14}, back_hi[3] = {0.5, 0.5, -12};
    CHECK(!ip__coverage_hides(&c, back_lo, back_hi)); /* behind the eye */
    double wide_lo[3] = {-3, -0.5, 1}, wide_hi[3] = {0.5, 0.5, 2};
    CHECK(!ip__coverage_hides(&c, wide_lo, wide_hi)); /* reaches past the wall's image */
    ip__coverage_free(&c);
}

/* The depth queue: cells come out bucket by bucket, nearest first, whatever the order they
 * went in (depths beyond the range in the first or last bucket); take_far() takes from the far
 * end; slots are used again, so queueing and taking one at a time needs no more; a start
 * empties what an earlier use left. */
static void check_depth_queue(void)
{
    ip_depth_queue q;
    ip__depth_queue_init(&q);
    ip__depth_queue_start(&q, 100.0, 0.5);
    uint64_t seed = 99;
    unsigned n = 5000;
    for (unsigned i = 0; i < n; i++) {
        double depth = 100.0 + 900.0 * (unit_random(&seed) - 0.2);
        ip_queued_cell c = {{i, 0, 0}, (float)depth}; /* the depth kept in max_versine */
        REQUIRE(ip__depth_queue_push(&q, &c, depth) == IP_OK);
    }
    ip_queued_cell far[4];
    CHECK_EQ(ip__depth_queue_take_far(&q, far, 4), 4);
    for (int k = 0; k < 4; k++)
        CHECK_GE(far[k].max_versine, 100.0 + 0.75 * IP_DEPTH_BUCKETS * 0.5 - 0.5);
    unsigned taken = 4, out_of_order = 0;
    double last_bucket = -1;
    ip_queued_cell c;
    while (ip__depth_queue_pop(&q, &c)) {
        double b = floor((c.max_versine - (100.0 - 0.25 * IP_DEPTH_BUCKETS * 0.5)) / 0.5);
        b = b < 0 ? 0 : b > IP_DEPTH_BUCKETS - 1 ? IP_DEPTH_BUCKETS - 1 : b;
        out_of_order += b < last_bucket;
        last_bucket = b;
        taken++;
    }
    CHECK_MSG(taken == n && out_of_order == 0, "depth queue: %u of %u taken, %u out of order",
              taken, n, out_of_order);
    uint32_t capacity = q.capacity;
    unsigned wrong = 0;
    for (unsigned i = 0; i < 3 * capacity; i++) { /* one in, one out: no growth */
        ip_queued_cell one = {{i, 1, 2}, 0};
        REQUIRE(ip__depth_queue_push(&q, &one, 150.0 + i % 7) == IP_OK);
        wrong += !ip__depth_queue_pop(&q, &c) || c.cell[0] != i;
    }
    CHECK_EQ(wrong, 0);
    CHECK_EQ(q.capacity, capacity);
    ip_queued_cell left = {{7, 7, 7}, 0};
    REQUIRE(ip__depth_queue_push(&q, &left, 120.0) == IP_OK);
    ip__depth_queue_start(&q, 10.0, 1.0); /* leaves nothing of the cell above */
    CHECK(!ip__depth_queue_pop(&q, &c));
    ip_queued_cell a = {{1, 0, 0}, 0}, b = {{2, 0, 0}, 0};
    REQUIRE(ip__depth_queue_push(&q, &a, 30.0) == IP_OK);
    REQUIRE(ip__depth_queue_push(&q, &b, 12.0) == IP_OK);
    CHECK(ip__depth_queue_pop(&q, &c));
    CHECK_EQ(c.cell[0], 2);
    CHECK(ip__depth_queue_pop(&q, &c));
    CHECK_EQ(c.cell[0], 1);
    CHECK(!ip__depth_queue_pop(&q, &c));
    ip__depth_queue_free(&q);
}

/* Distance (pixels) from point (px, py) to the triangle with corners (x[k], y[k]): 0 inside. */
static double point_triangle_distance(const double x[3], const double y[3], double px, double py)
{
    double area = (x[1] - x[0]) * (y[2] - y[0]) - (y[1] - y[0]) * (x[2] - x[0]);
    int inside = 1;
    double nearest = INFINITY;
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3;
        double ex = x[j] - x[i], ey = y[j] - y[i];
        double side = ex * (py - y[i]) - ey * (px - x[i]); /* > 0: left of the edge */
        inside &= area > 0 ? side >= 0 : side <= 0;
        double t = ((px - x[i]) * ex + (py - y[i]) * ey) / (ex * ex + ey * ey);
        t = t < 0 ? 0 : t > 1 ? 1 : t;
        double dx = x[i] + t * ex - px, dy = y[i] + t * ey - py;
        double d = sqrt(dx * dx + dy * dy);
        nearest = d < nearest ? d : nearest;
    }
    return inside ? 0 : nearest;
}

/* Culling's test (ip__coverage_add()'s mask): small random triangles facing the eye, many
 * smaller than a pixel, some off the image. A triangle's bit is set whenever some pixel centre
 * of the image lies within IP_COVERAGE_SHOW_MARGIN of its projection (a brute-force search;
 * triangles within 1e-6 pixel of that margin, or of no area, are left out). It may be set for
 * a few more (the test widens each edge by the margin, which reaches farther at the corners),
 * but not for many. */
static void check_cull_mask(void)
{
    ip_camera cam;
    ip_camera_basis basis;
    ip_coverage c;
    test_coverage(&cam, &basis, &c);
    uint64_t seed = 12345;
    unsigned tested = 0, shown = 0, wrong = 0, extra = 0;
    for (int n = 0; n < 20000; n++) {
        float tri[9];
        double x[3], y[3];
        double cx = -2 + 68 * unit_random(&seed), cy = -2 + 52 * unit_random(&seed);
        double size = 0.1 + 2.5 * unit_random(&seed);
        for (int k = 0; k < 3; k++) {
            double px = cx + size * (unit_random(&seed) - 0.5),
                   py = cy + size * (unit_random(&seed) - 0.5);
            double dir[3], depth = 12.0;
            ip_camera_pixel_ray(&basis, &cam, px, py, dir);
            double t = depth / (dir[0] * basis.forward[0] + dir[1] * basis.forward[1] +
                                dir[2] * basis.forward[2]);
            double world[3];
            for (int a = 0; a < 3; a++) {
                tri[3 * k + a] = (float)(cam.eye[a] + t * dir[a]);
                world[a] = tri[3 * k + a];
            }
            double z;
            REQUIRE(ip_camera_project(&basis, &cam, world, &x[k], &y[k], &z));
        }
        double area = (x[1] - x[0]) * (y[2] - y[0]) - (y[1] - y[0]) * (x[2] - x[0]);
        if (fabs(area) < 1e-6)
            continue;
        double nearest = INFINITY;
        for (int py = 0; py < 48; py++)
            for (int px = 0; px < 64; px++) {
                double d = point_triangle_distance(x, y, px + 0.5, py + 0.5);
                nearest = d < nearest ? d : nearest;
            }
        if (fabs(nearest - IP_COVERAGE_SHOW_MARGIN) < 1e-6)
            continue;
        int want = nearest <= IP_COVERAGE_SHOW_MARGIN;
        int got = (int)(ip__coverage_add(&c, tri, 1) & 1);
        if (want && !got)
            printf("test_engine: cull mask: triangle (%.6f %.6f) (%.6f %.6f) (%.6f %.6f) culled, "
                   "its nearest centre %.9f pixel away\n",
                   x[0], y[0], x[1], y[1], x[2], y[2], nearest);
        tested++;
        shown += (unsigned)want;
        wrong += (unsigned)(want && !got);
        extra += (unsigned)(got && !want);
    }
    printf("test_engine: cull mask: %u triangles, %u within the margin of a pixel centre, %u "
           "culled wrongly, %u kept beyond it\n",
           tested, shown, wrong, extra);
    CHECK_GT(tested, 15000);
    CHECK_GT(shown, tested / 10);
    CHECK_LT(shown, tested - tested / 10);
    CHECK_MSG(wrong == 0, "cull mask: %u of %u triangles culled wrongly", wrong, tested);
    CHECK_MSG(extra < tested / 100, "cull mask: %u of %u triangles kept beyond the margin", extra,
              tested);
    ip__coverage_free(&c);
}

/* ip__coverage_add_indexed(), which projects each of a cell's crossings once, against
 * ip__coverage_add() given the same triangles corner by corner: random cells of one to three
 * pixels, partly off the image, give the same masks and, entry for entry, the same coverage. */
static void check_coverage_indexed(void)
{
    ip_camera cam;
    ip_camera_basis basis;
    ip_coverage by_corner, indexed;
    test_coverage(&cam, &basis, &by_corner);
    test_coverage(&cam, &basis, &indexed);
    uint64_t seed = 4242;
    unsigned cells = 0, differ = 0, shown = 0;
    double pixel = 2.0 * 12.0 * basis.tan_half_y / cam.height; /* world units at depth 12 */
    for (int n = 0; n < 4000; n++) {
        float values[8];
        for (int i = 0; i < 8; i++)
            values[i] = (float)unit_random(&seed);
        unsigned mc = ip__mc_case(values, 0.5f);
        int count = ip__mc_triangle_count[mc];
        if (count == 0)
            continue;
        double dir[3], size = pixel * (1.0 + 2.0 * unit_random(&seed));
        ip_camera_pixel_ray(&basis, &cam, -2 + 68 * unit_random(&seed),
                            -2 + 52 * unit_random(&seed), dir);
        double t = 12.0 / (dir[0] * basis.forward[0] + dir[1] * basis.forward[1] +
                           dir[2] * basis.forward[2]);
        float lo[3], hi[3], points[12][3], corners[9 * IP_MC_MAX_TRIANGLES];
        for (int a = 0; a < 3; a++) {
            lo[a] = (float)(cam.eye[a] + t * dir[a]);
            hi[a] = (float)(lo[a] + size);
        }
        ip__mc_cell_edge_points(values, mc, 0.5f, lo, hi, points);
        const int8_t *row = ip__mc_triangle_table[mc];
        for (int i = 0; i < 3 * count; i++)
            memcpy(corners + 3 * i, points[row[i]], sizeof points[0]);
        uint32_t a = ip__coverage_add(&by_corner, corners, (unsigned)count);
        uint32_t b =
            ip__coverage_add_indexed(&indexed, (const float(*)[3])points, row, (unsigned)count);
        cells++;
        differ += a != b;
        shown += a != 0;
    }
    unsigned entries = 0, written = 0, unequal = 0;
    for (size_t i = 0; i < by_corner.capacity; i++) {
        unsigned d = atomic_load(&by_corner.depth[i]), s2 = atomic_load(&by_corner.solid[i]);
        entries++;
        written += d != ip__float_bits(INFINITY);
        unequal += d != atomic_load(&indexed.depth[i]) || s2 != atomic_load(&indexed.solid[i]);
    }
    printf("test_engine: indexed coverage: %u cells (%u shown), %u masks differ; %u of %u entries "
           "written, %u differ\n",
           cells, shown, differ, written, entries, unequal);
    CHECK_GT(cells, 3000);
    CHECK_GT(shown, cells / 4);
    CHECK_GT(written, entries / 4);
    CHECK_MSG(differ == 0 && unequal == 0, "indexed coverage: %u masks, %u entries differ", differ,
              unequal);
    ip__coverage_free(&by_corner);
    ip__coverage_free(&indexed);
}

/* Culling (ip_engine_options.cull) against keeping every triangle, on one thread where cells
 * are smaller than pixels: the same cells are extracted in the same order (a culled triangle
 * records nothing), so the kept and culled triangles add up to those kept without culling,
 * every kept one is among them, and the image is the same after a few rays and after all. */
static void check_culling(scene *s, float iso)
{
    ip_error err;
    ip_camera cam;
    REQUIRE(ip_camera_fit_axis(s->lo, s->hi, "-y", 30.0, 40, 30, &cam, &err) == IP_OK);
    ip_engine *e[2];
    for (int cull = 0; cull <= 1; cull++) {
        ip_engine_options o;
        ip_engine_options_default(&o);
        o.lod = 0;
        o.threads = 1;
        o.cell_ids = 1;
        o.cull = cull;
        REQUIRE(ip_engine_create(s->cache, &o, &e[cull], &err) == IP_OK);
        REQUIRE(ip_engine_begin(e[cull], &cam, iso, &err) == IP_OK);
    }
    size_t n = (size_t)cam.width * cam.height;
    uint32_t *index[2] = {malloc(n * 4), malloc(n * 4)};
    uint8_t *rgba[2] = {malloc(n * 4), malloc(n * 4)};
    REQUIRE(index[0] && index[1] && rgba[0] && rgba[1]);
    ip_engine_counts t[2];
    for (int stage = 0; stage < 2; stage++) { /* 40 rays, then all */
        for (int k = 0; k < 2; k++) {
            do
                REQUIRE(ip_engine_step(e[k], stage == 0 ? 40 : 0, 0, NULL, &err) == IP_OK);
            while (stage == 1 && !ip_engine_done(e[k]));
            ip_engine_totals(e[k], &t[k]);
            REQUIRE(ip_raster_mesh(ip_engine_mesh(e[k]), &cam, s->lo, s->hi, index[k], rgba[k],
                                   &err) == IP_OK);
        }
        size_t differ = 0;
        for (size_t i = 0; i < n; i++)
            differ += (index[0][i] == UINT32_MAX) != (index[1][i] == UINT32_MAX) ||
                      memcmp(rgba[0] + 4 * i, rgba[1] + 4 * i, 4) != 0;
        const ip_mesh *kept = ip_engine_mesh(e[1]), *whole = ip_engine_mesh(e[0]);
        printf("test_engine: culling, %llu rays: %llu triangles kept, %llu culled, %llu without "
               "culling; %zu pixels differ\n",
               (unsigned long long)t[1].rays, (unsigned long long)t[1].triangles,
               (unsigned long long)t[1].culled, (unsigned long long)t[0].triangles, differ);
        CHECK_MSG(differ == 0, "culling: %zu pixels differ after %llu rays", differ,
                  (unsigned long long)t[1].rays);
        CHECK_EQ(t[0].rays, t[1].rays);
        CHECK_EQ(t[0].cells, t[1].cells);
        CHECK_EQ(t[0].culled, 0);
        CHECK_GT(t[1].culled, 0);
        CHECK_EQ(t[1].triangles + t[1].culled, t[0].triangles);
        CHECK_EQ(kept->triangle_count, t[1].triangles);
        CHECK_EQ(triangles_not_in(kept, whole), 0);
    }
    for (int k = 0; k < 2; k++) {
        free(index[k]);
        free(rgba[k]);
        ip_engine_destroy(e[k]);
    }
}

/* ip__coverage_reach(): the entries of tiles not kept are left as they are by a clear, a
 * triangle over them records nothing there, and a box reaching them is never found hidden,
 * while one within the kept tiles behind the same triangles is. */
static void check_coverage_reach(void)
{
    ip_camera cam;
    ip_camera_basis basis;
    ip_coverage c;
    test_coverage(&cam, &basis, &c);
    double lo[3] = {-5, -5, -20}, hi[3] = {5, 5, 20}; /* test_coverage()'s box */
    for (size_t i = 0; i < 64 * 48; i++) {            /* a value no clear writes */
        atomic_store(&c.depth[i], 12345u);
        atomic_store(&c.solid[i], 12345u);
    }
    /* boxes behind a wall, left and right of the image's centre: the left one's half kept */
    double left_lo[3] = {-1.6, -0.5, 1}, left_hi[3] = {-0.9, 0.5, 2};
    double right_lo[3] = {0.9, -0.5, 1}, right_hi[3] = {1.6, 0.5, 2};
    double centre[3] = {-1.25, 0, 1.5}, px, py, depth;
    REQUIRE(ip_camera_project(&basis, &cam, centre, &px, &py, &depth));
    unsigned char reached[8 * 6];
    for (int t = 0; t < 8 * 6; t++)
        reached[t] = (t % 8 < 4) == (px < 32);
    REQUIRE(ip__coverage_prepare(&c, &cam, lo, hi) == IP_OK);
    ip__coverage_reach(&c, reached, 3, 8);
    ip__coverage_clear(&c, 0, 2);
    ip__coverage_clear(&c, 1, 2);
    const float wall[18] = {-2, -2, 0, 2, -2, 0, 2, 2, 0, -2, -2, 0, 2, 2, 0, -2, 2, 0};
    ip__coverage_add(&c, wall, 2);
    size_t wrong = 0;
    for (uint32_t y = 0; y < 48; y++)
        for (uint32_t x = 0; x < 64; x++) {
            size_t at = ip__coverage_index(&c, x, y);
            unsigned d = atomic_load(&c.depth[at]), sd = atomic_load(&c.solid[at]);
            wrong += reached[(y >> 3) * 8 + (x >> 3)] ? d == 12345u || sd == 12345u
                                                      : d != 12345u || sd != 12345u;
        }
    CHECK_MSG(wrong == 0, "%zu entries kept or dropped wrongly", wrong);
    CHECK(ip__coverage_hides(&c, left_lo, left_hi));
    CHECK(!ip__coverage_hides(&c, right_lo, right_hi));
    ip__coverage_reach(&c, NULL, 3, 8); /* every entry again: the right one is hidden too */
    ip__coverage_clear(&c, 0, 1);
    ip__coverage_add(&c, wall, 2);
    CHECK(ip__coverage_hides(&c, right_lo, right_hi));
    ip__coverage_free(&c);
}

/* The tiles a box may show in (ip__reach_box(), tiles of 8x8 pixels): every pixel whose ray
 * meets one of 200 random boxes in front of the eye lies in a marked tile, and no tile is
 * marked more than one tile away from such a pixel's, for boxes that show in more than a few
 * pixels; a box behind the eye marks every tile. */
static void check_reach_box(void)
{
    ip_camera cam = {{0, 0, -40}, {0, 0, 0}, {0, 1, 0}, 40.0, 160, 120};
    ip_camera_basis basis;
    ip_camera_basis_of(&cam, &basis);
    const uint32_t tx = 20, ty = 15;
    unsigned char reached[20 * 15];
    uint64_t seed = 12345, missed = 0, loose = 0, boxes = 0;
    for (int b = 0; b < 200; b++) {
        double lo[3], hi[3];
        for (int a = 0; a < 3; a++) {
            double c = unit_random(&seed) * 20 - 10;
            double h = unit_random(&seed) * 2 + 0.05;
            lo[a] = c - h;
            hi[a] = c + h;
        }
        memset(reached, 0, sizeof reached);
        ip__reach_box(&basis, &cam, lo, hi, 3, tx, ty, reached);
        uint32_t hit_lo[2] = {tx, ty}, hit_hi[2] = {0, 0}, hits = 0;
        for (uint32_t y = 0; y < cam.height; y++)
            for (uint32_t x = 0; x < cam.width; x++) {
                double d[3], t0 = 0, t1 = INFINITY;
                ip_camera_pixel_ray(&basis, &cam, x + 0.5, y + 0.5, d);
                for (int a = 0; a < 3; a++) { /* slab test of the ray against the box */
                    double u = (lo[a] - cam.eye[a]) / d[a], v = (hi[a] - cam.eye[a]) / d[a];
                    t0 = fmax(t0, fmin(u, v));
                    t1 = fmin(t1, fmax(u, v));
                }
                if (!(t0 <= t1))
                    continue;
                hits++;
                missed += !reached[(y >> 3) * tx + (x >> 3)];
                hit_lo[0] = x >> 3 < hit_lo[0] ? x >> 3 : hit_lo[0];
                hit_lo[1] = y >> 3 < hit_lo[1] ? y >> 3 : hit_lo[1];
                hit_hi[0] = x >> 3 > hit_hi[0] ? x >> 3 : hit_hi[0];
                hit_hi[1] = y >> 3 > hit_hi[1] ? y >> 3 : hit_hi[1];
            }
        if (hits < 16)
            continue;
        boxes++;
        for (uint32_t y = 0; y < ty; y++)
            for (uint32_t x = 0; x < tx; x++)
                loose += reached[y * tx + x] && (x + 1 < hit_lo[0] || x > hit_hi[0] + 1 ||
                                                 y + 1 < hit_lo[1] || y > hit_hi[1] + 1);
    }
    CHECK_MSG(missed == 0 && loose == 0 && boxes > 50,
              "%llu pixels hit in unmarked tiles, %llu tiles marked too far, %llu boxes",
              (unsigned long long)missed, (unsigned long long)loose, (unsigned long long)boxes);
    double back_lo[3] = {-1, -1, -45}, back_hi[3] = {1, 1, -42};
    memset(reached, 0, sizeof reached);
    ip__reach_box(&basis, &cam, back_lo, back_hi, 3, tx, ty, reached);
    CHECK_EQ(memchr(reached, 0, sizeof reached), NULL);
}

/* The tiles every brick holding `iso` may show in, brick by brick over each level's whole grid:
 * what ip__reach_tiles() finds by the octree. */
static void reach_every_brick(const ip_store *store, float iso, uint32_t levels,
                              const ip_camera_basis *basis, const ip_camera *cam, uint32_t tx,
                              uint32_t ty, unsigned char *reached, uint64_t *active)
{
    const ip_layout *l = ip_store_layout(store);
    memset(reached, 0, (size_t)tx * ty);
    for (uint32_t k = 0; k < levels; k++) {
        const ip_level_layout *lv = &l->levels[k];
        uint32_t b[3];
        for (b[2] = 0; b[2] < lv->bricks[2]; b[2]++)
            for (b[1] = 0; b[1] < lv->bricks[1]; b[1]++)
                for (b[0] = 0; b[0] < lv->bricks[0]; b[0]++) {
                    float range[2];
                    ip_store_brick_range(store, ip_brick_global_index(l, k, b), range);
                    if (!(range[0] < iso && range[1] >= iso))
                        continue;
                    ++*active;
                    uint32_t origin[3], extent[3];
                    ip_brick_extent(l, k, b, origin, extent);
                    double lo[3], hi[3];
                    for (int a = 0; a < 3; a++) {
                        double scale = l->spacing[a] * (double)(1u << k);
                        lo[a] = origin[a] * scale;
                        hi[a] = (origin[a] + extent[a] - 1.0) * scale;
                    }
                    ip__reach_box(basis, cam, lo, hi, 3, tx, ty, reached);
                }
    }
}

/* ip__reach_tiles() walks the octree, passing over the nodes that do not hold the isovalue: it
 * marks exactly the tiles that testing every brick marks, at every level count, for isovalues
 * crossing few or many bricks or none, seen along the axes and from off them. */
static void check_reach_tiles(scene *s)
{
    const ip_layout *l = ip_store_layout(s->store);
    const float isos[] = {30.5f, 127.5f, 250.5f, 1000.0f};
    const char *axes[] = {"-y", "+z", "+x", "-z"};
    uint64_t cases = 0, with_active = 0, partial = 0;
    for (size_t v = 0; v < sizeof axes / sizeof axes[0]; v++) {
        ip_camera cam;
        ip_error err;
        REQUIRE(ip_camera_fit_axis(s->lo, s->hi, axes[v], 30.0, 150, 110, &cam, &err) == IP_OK);
        if (v == 2) { /* off the axes, and near enough that the volume fills the image */
            cam.eye[1] += 0.6 * (cam.eye[0] - cam.target[0]);
            cam.eye[2] -= 0.3 * (cam.eye[0] - cam.target[0]);
            for (int a = 0; a < 3; a++)
                cam.eye[a] = cam.target[a] + 0.6 * (cam.eye[a] - cam.target[a]);
        }
        if (v == 3) /* far: a brick is a tile or two, and a node a few */
            for (int a = 0; a < 3; a++)
                cam.eye[a] = cam.target[a] + 4.0 * (cam.eye[a] - cam.target[a]);
        ip_camera_basis basis;
        ip_camera_basis_of(&cam, &basis);
        const uint32_t tx = (150 + 7) / 8, ty = (110 + 7) / 8;
        unsigned char walked[19 * 14], every[19 * 14];
        REQUIRE(tx * ty == sizeof walked);
        for (size_t i = 0; i < sizeof isos / sizeof isos[0]; i++)
            for (uint32_t levels = 1; levels <= l->level_count; levels++) {
                uint64_t active = 0;
                memset(walked, 7, sizeof walked);
                ip__reach_tiles(s->store, isos[i], levels, &basis, &cam, 3, tx, ty, walked);
                reach_every_brick(s->store, isos[i], levels, &basis, &cam, tx, ty, every, &active);
                CHECK_MSG(memcmp(walked, every, sizeof walked) == 0,
                          "iso %g, %u levels, view %s: the octree walk marks other tiles",
                          (double)isos[i], levels, axes[v]);
                cases++;
                with_active += active > 0;
                partial += memchr(every, 0, sizeof every) && memchr(every, 1, sizeof every);
            }
    }
    CHECK_MSG(l->level_count > 1 && with_active >= cases / 2 && partial > 0 && with_active < cases,
              "%llu cases: %llu with active bricks, %llu with tiles both reached and not",
              (unsigned long long)cases, (unsigned long long)with_active,
              (unsigned long long)partial);
}

/* The full extraction of an isovalue at level 0 and its image under one camera, beside
 * buffers for the image of a progressive mesh to compare with it. */
typedef struct reference {
    size_t n; /* pixels */
    ip_mesh full;
    uint32_t *index, *full_index; /* the triangle each pixel shows (UINT32_MAX: none) */
    uint8_t *rgba, *full_rgba;
} reference;

static void reference_open(scene *s, const ip_camera *cam, float iso, reference *r)
{
    ip_error err;
    r->n = (size_t)cam->width * cam->height;
    r->index = malloc(r->n * 4);
    r->full_index = malloc(r->n * 4);
    r->rgba = malloc(r->n * 4);
    r->full_rgba = malloc(r->n * 4);
    REQUIRE(r->index && r->full_index && r->rgba && r->full_rgba);
    ip_mesh_init(&r->full);
    REQUIRE(ip_extract_full(s->cache, iso, 0, 1, &r->full, NULL, &err) == IP_OK);
    REQUIRE(ip_raster_mesh(&r->full, cam, s->lo, s->hi, r->full_index, r->full_rgba, &err) ==
            IP_OK);
}

static void reference_close(reference *r)
{
    free(r->index);
    free(r->full_index);
    free(r->rgba);
    free(r->full_rgba);
    ip_mesh_free(&r->full);
}

/* Draws `m` into r->index and r->rgba and counts the pixels whose coverage, and whose colour,
 * differ from the full extraction's image. */
static void reference_compare(scene *s, const ip_camera *cam, reference *r, const ip_mesh *m,
                              size_t *coverage_diff, size_t *colour_diff)
{
    ip_error err;
    REQUIRE(ip_raster_mesh(m, cam, s->lo, s->hi, r->index, r->rgba, &err) == IP_OK);
    *coverage_diff = *colour_diff = 0;
    for (size_t i = 0; i < r->n; i++) {
        *coverage_diff += (r->index[i] == UINT32_MAX) != (r->full_index[i] == UINT32_MAX);
        *colour_diff += memcmp(r->rgba + 4 * i, r->full_rgba + 4 * i, 4) != 0;
    }
}

/* An engine at full resolution (lod off) with `threads` threads and occlusion on or off. */
static ip_engine *full_resolution_engine(scene *s, unsigned threads, int occlusion)
{
    ip_engine *e;
    ip_engine_options o;
    ip_error err;
    ip_engine_options_default(&o);
    o.lod = 0;
    o.threads = threads;
    o.occlusion = occlusion;
    REQUIRE(ip_engine_create(s->cache, &o, &e, &err) == IP_OK);
    return e;
}

/* Occlusion on a volume with hidden surface (the Shepp-Logan phantom: the skull's inner
 * surface and the ellipsoids inside it, seen through the outer surface): with 1 and 2
 * threads it extracts fewer triangles than without, and the final image is the full
 * extraction's, pixel by pixel; the triangles that own a pixel are among those extracted,
 * and as many with occlusion as without. */
static void check_occlusion(const char *dir)
{
    char ibv[4200];
    make_volume(dir, IP_FIELD_SHEPP_LOGAN, 48, IP_UINT8, 8, ibv, sizeof ibv);
    scene s;
    open_scene(ibv, &s);
    ip_error err;
    ip_camera cam;
    const uint32_t w = 120, h = 100;
    const float iso = 25.5f; /* between air (0) and brain (0.2 of 255): every shell */
    REQUIRE(ip_camera_fit_axis(s.lo, s.hi, "+x", 30.0, w, h, &cam, &err) == IP_OK);
    reference r;
    reference_open(&s, &cam, iso, &r);
    uint64_t triangles[2][2], visible[2][2];
    for (int threads = 1; threads <= 2; threads++)
        for (int occlusion = 0; occlusion <= 1; occlusion++) {
            ip_engine *e = full_resolution_engine(&s, (unsigned)threads, occlusion);
            ip_engine_counts t;
            run_all_rays(e, &cam, iso, &t);
            const ip_mesh *m = ip_engine_mesh(e);
            size_t coverage_diff, colour_diff;
            reference_compare(&s, &cam, &r, m, &coverage_diff, &colour_diff);
            uint8_t *owns = calloc(m->triangle_count / 8 + 1, 1);
            REQUIRE(owns);
            uint64_t owners = 0;
            for (size_t i = 0; i < r.n; i++) {
                uint32_t k = r.index[i];
                if (k != UINT32_MAX && !(owns[k / 8] & (1u << (k % 8)))) {
                    owns[k / 8] |= (uint8_t)(1u << (k % 8));
                    owners++;
                }
            }
            free(owns);
            triangles[threads - 1][occlusion] = m->triangle_count;
            visible[threads - 1][occlusion] = owners;
            printf("test_engine: occlusion %s, %d thread%s: %llu of %llu triangles extracted, "
                   "%llu visible, %llu cells deferred; %zu coverage, %zu colour differences\n",
                   occlusion ? "on" : "off", threads, threads > 1 ? "s" : "",
                   (unsigned long long)m->triangle_count, (unsigned long long)r.full.triangle_count,
                   (unsigned long long)owners, (unsigned long long)t.deferred, coverage_diff,
                   colour_diff);
            CHECK_MSG(coverage_diff == 0 && colour_diff == 0,
                      "occlusion %d, %d threads: %zu coverage, %zu colour differences from the "
                      "full extraction",
                      occlusion, threads, coverage_diff, colour_diff);
            CHECK_GT(owners, 0);
            CHECK_LE(owners, m->triangle_count);
            CHECK(occlusion ? t.deferred > 0 : t.deferred == 0);
            ip_engine_destroy(e);
        }
    for (int k = 0; k < 2; k++) {
        /* hidden shells: well under what propagation extracts without the test */
        CHECK_MSG(10 * triangles[k][1] < 9 * triangles[k][0],
                  "%d threads: occlusion extracts %llu triangles, %llu without", k + 1,
                  (unsigned long long)triangles[k][1], (unsigned long long)triangles[k][0]);
        CHECK_EQ(visible[k][1], visible[k][0]);
    }
    reference_close(&r);
    close_scene(&s);
}

/* Rays retired in bulk: a wall across the volume near the eye hides blobs behind it. Once the
 * wall is extracted, the rays of the tiles it covers solidly stop at it and find nothing new,
 * so most of them are retired without a walk, as are those of tiles whose beam meets no active
 * cell at all (outside the volume); the image stays that of the full extraction, with 1 and 2
 * threads, and the walks enter fewer nodes than without occlusion (no stops, no retirement). */
static void check_retirement(const char *dir)
{
    const uint32_t d[3] = {40, 36, 44};
    size_t count = (size_t)d[0] * d[1] * d[2];
    uint8_t *v = malloc(count);
    REQUIRE(v);
    for (uint32_t z = 0; z < d[2]; z++)
        for (uint32_t y = 0; y < d[1]; y++)
            for (uint32_t x = 0; x < d[0]; x++) {
                int wall = z >= 3 && z <= 6;
                /* blobs behind the wall: a lattice of small balls */
                int bx = (int)x % 9 - 4, by = (int)y % 9 - 4, bz = (int)z % 11 - 5;
                int blob = z >= 14 && bx * bx + by * by + bz * bz <= 6;
                v[x + (size_t)d[0] * (y + (size_t)d[1] * z)] = wall || blob ? 200 : 10;
            }
    char name[256], raw[4096], ibv[4200];
    ip_error err;
    REQUIRE(ip_raw_file_name(name, sizeof name, "wall", d, IP_UINT8) == IP_OK);
    REQUIRE(snprintf(raw, sizeof raw, "%s/%s", dir, name) < (int)sizeof raw);
    FILE *f = fopen(raw, "wb");
    REQUIRE(f && fwrite(v, 1, count, f) == count && fclose(f) == 0);
    free(v);
    REQUIRE(snprintf(ibv, sizeof ibv, "%s/wall.ibv", dir) < (int)sizeof ibv);
    test_brick_raw(raw, ibv, 16, 4);
    scene s;
    open_scene(ibv, &s);
    const uint32_t w = 128, h = 112;
    const float iso = 100.5f;
    ip_camera cam;
    REQUIRE(ip_camera_fit_axis(s.lo, s.hi, "-z", 30.0, w, h, &cam, &err) == IP_OK);
    reference r;
    reference_open(&s, &cam, iso, &r);
    size_t n = r.n, covered = 0;
    for (size_t i = 0; i < n; i++)
        covered += r.full_index[i] != UINT32_MAX;
    uint64_t nodes[2] = {0, 0};
    for (int threads = 1; threads <= 2; threads++)
        for (int occlusion = 0; occlusion <= 1; occlusion++) {
            ip_engine *e = full_resolution_engine(&s, (unsigned)threads, occlusion);
            ip_engine_counts t;
            run_all_rays(e, &cam, iso, &t);
            size_t coverage_diff, colour_diff;
            reference_compare(&s, &cam, &r, ip_engine_mesh(e), &coverage_diff, &colour_diff);
            printf("test_engine: wall, occlusion %s, %d thread%s: %llu rays, %llu retired, %llu "
                   "nodes walked, %llu cells; %zu covered pixels, %zu coverage, %zu colour "
                   "differences\n",
                   occlusion ? "on" : "off", threads, threads > 1 ? "s" : "",
                   (unsigned long long)t.rays, (unsigned long long)t.retired,
                   (unsigned long long)t.nodes, (unsigned long long)t.cells, covered, coverage_diff,
                   colour_diff);
            CHECK_MSG(coverage_diff == 0 && colour_diff == 0,
                      "wall, occlusion %d, %d threads: %zu coverage, %zu colour differences",
                      occlusion, threads, coverage_diff, colour_diff);
            CHECK_EQ(t.rays, n);
            if (occlusion) /* more than the rays outside the wall: the wall's own retired */
                CHECK_MSG(t.retired > n - covered + covered / 2,
                          "%d threads: %llu rays retired, %zu pixels covered of %zu", threads,
                          (unsigned long long)t.retired, covered, n);
            else
                CHECK_EQ(t.retired, 0);
            nodes[occlusion] = t.nodes;
            ip_engine_destroy(e);
        }
    CHECK_MSG(2 * nodes[1] < nodes[0], "%llu nodes walked with occlusion, %llu without",
              (unsigned long long)nodes[1], (unsigned long long)nodes[0]);
    reference_close(&r);
    close_scene(&s);
}

/* Step budgets with the ray order handed out in ranges to several workers: each step casts
 * exactly its budget (the rest at the end), a step cut short by its deadline leaves no pixel
 * out, and the rays add up to the pixels once the engine is done. At width x height, with
 * blocks of the Z-order levels whose rays to walk overfill a batch at the larger size. */
static void check_ray_budgets(scene *s, float iso, uint32_t width, uint32_t height)
{
    ip_error err;
    ip_camera cam;
    REQUIRE(ip_camera_fit_axis(s->lo, s->hi, "-x", 30.0, width, height, &cam, &err) == IP_OK);
    ip_engine *e;
    ip_engine_options o;
    ip_engine_options_default(&o);
    o.threads = 4;
    REQUIRE(ip_engine_create(s->cache, &o, &e, &err) == IP_OK);
    REQUIRE(ip_engine_begin(e, &cam, iso, &err) == IP_OK);
    uint64_t pixels = (uint64_t)width * height, cast = 0, exact = 0, steps = 0;
    static const uint64_t budgets[] = {1, 5, 37, 64, 100, 1000};
    while (!ip_engine_done(e)) {
        uint64_t budget = budgets[steps % (sizeof budgets / sizeof budgets[0])];
        ip_engine_counts c;
        REQUIRE(ip_engine_step(e, budget, 0, &c, &err) == IP_OK);
        uint64_t expected = pixels - cast < budget ? pixels - cast : budget;
        exact += c.rays == expected;
        cast += c.rays;
        steps++;
        if (steps == 7) { /* a step that may stop anywhere: its deadline is already near */
            REQUIRE(ip_engine_step(e, 0, 1e-9, &c, &err) == IP_OK);
            cast += c.rays;
        }
    }
    CHECK_MSG(exact == steps && cast == pixels,
              "%llu of %llu steps cast their budget; %llu rays "
              "for %llu pixels",
              (unsigned long long)exact, (unsigned long long)steps, (unsigned long long)cast,
              (unsigned long long)pixels);
    ip_engine_counts t;
    ip_engine_totals(e, &t);
    CHECK_EQ(t.rays, pixels);
    ip_engine_destroy(e);
}

/* Sort-first in regions (ip_engine_set_region()): the image is cut into rectangles, each cast
 * in two passes (its first rays, then the rest) by one of two engines, as two processes of a
 * display wall would; every region casts exactly its rays, and the nearest-depth composite of
 * the two meshes' parts (ip_raster_mesh_part()) equals the full extraction's image. */
static void check_regions(scene *s, float iso)
{
    enum {
        W = 203,
        H = 151,
        RW = 48,
        RH = 40
    };
    ip_error err;
    ip_camera cam;
    REQUIRE(ip_camera_fit_axis(s->lo, s->hi, "-x", 30.0, W, H, &cam, &err) == IP_OK);
    ip_engine *e[2]; /* the exact-image tolerance of check_view(): >= 99.99 % equal pixels */
    ip_engine_options o;
    ip_engine_options_default(&o);
    o.lod = 0;
    o.threads = 2;
    for (int k = 0; k < 2; k++) {
        REQUIRE(ip_engine_create(s->cache, &o, &e[k], &err) == IP_OK);
        CHECK_EQ(ip_engine_set_region(e[k], 0, 0, 1, 1, 0, 1, &err), IP_ERR_ARGUMENT);
        REQUIRE(ip_engine_begin(e[k], &cam, iso, &err) == IP_OK);
    }
    CHECK_EQ(ip_engine_set_region(e[0], W - 7, 0, 8, 1, 0, 1, &err), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_engine_set_region(e[0], 0, 0, 0, 5, 0, 0, &err), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_engine_set_region(e[0], 0, 0, 4, 4, 10, 7, &err), IP_ERR_ARGUMENT);
    uint64_t rays = 0, exact = 0, regions = 0;
    for (int pass = 0; pass < 2; pass++)
        for (uint32_t y = 0; y < H; y += RH)
            for (uint32_t x = 0; x < W; x += RW) {
                uint32_t w = W - x < RW ? W - x : RW, h = H - y < RH ? H - y : RH;
                uint64_t pixels = (uint64_t)w * h, coarse = pixels / 16 + 1;
                uint64_t first = pass ? coarse : 0, count = pass ? pixels - coarse : coarse;
                ip_engine *en = e[(x / RW + y / RH) % 2];
                REQUIRE(ip_engine_set_region(en, x, y, w, h, first, count, &err) == IP_OK);
                uint64_t cast = 0;
                while (!ip_engine_done(en)) {
                    ip_engine_counts c;
                    REQUIRE(ip_engine_step(en, 37, 0, &c, &err) == IP_OK);
                    cast += c.rays;
                }
                exact += cast == count;
                rays += cast;
                regions++;
            }
    CHECK_MSG(exact == regions && rays == (uint64_t)W * H,
              "regions: %llu of %llu cast their rays; %llu rays for %d pixels",
              (unsigned long long)exact, (unsigned long long)regions, (unsigned long long)rays,
              W * H);
    ip_mesh full;
    ip_mesh_init(&full);
    REQUIRE(ip_extract_full(s->cache, iso, 0, 0, &full, NULL, &err) == IP_OK);
    size_t n = (size_t)W * H;
    uint8_t *want = malloc(n * 4), *got = malloc(n * 4), *part = malloc(n * 4);
    double *depth = malloc(n * sizeof *depth), *nearest = calloc(n, sizeof *nearest);
    REQUIRE(want && got && part && depth && nearest);
    REQUIRE(ip_raster_mesh(&full, &cam, s->lo, s->hi, NULL, want, &err) == IP_OK);
    /* a part of the image is drawn exactly as in the whole image */
    REQUIRE(ip_raster_mesh_part(&full, &cam, NULL, s->lo, s->hi, 31, 17, 40, 30, depth, part,
                                &err) == IP_OK);
    size_t part_diff = 0;
    for (uint32_t y = 0; y < 30; y++)
        part_diff +=
            memcmp(part + 4 * (size_t)y * 40, want + 4 * ((y + 17) * (size_t)W + 31), 4 * 40) != 0;
    CHECK_MSG(part_diff == 0, "ip_raster_mesh_part: %zu rows differ from the whole image",
              part_diff);
    CHECK_EQ(
        ip_raster_mesh_part(&full, &cam, NULL, s->lo, s->hi, W - 7, 0, 8, 1, depth, part, &err),
        IP_ERR_ARGUMENT);
    memcpy(got, want, n * 4);
    for (int k = 0; k < 2; k++) {
        REQUIRE(ip_raster_mesh_part(ip_engine_mesh(e[k]), &cam, NULL, s->lo, s->hi, 0, 0, W, H,
                                    depth, part, &err) == IP_OK);
        for (size_t i = 0; i < n; i++)
            if (k == 0 || depth[i] > nearest[i]) {
                nearest[i] = depth[i];
                memcpy(got + 4 * i, part + 4 * i, 4);
            }
    }
    size_t diff = 0, covered = 0;
    for (size_t i = 0; i < n; i++) {
        diff += memcmp(got + 4 * i, want + 4 * i, 4) != 0;
        covered += nearest[i] > 0;
    }
    printf("test_engine: regions: %llu + %llu triangles (%llu full), %zu covered pixels, %zu "
           "differ\n",
           (unsigned long long)ip_engine_mesh(e[0])->triangle_count,
           (unsigned long long)ip_engine_mesh(e[1])->triangle_count,
           (unsigned long long)full.triangle_count, covered, diff);
    CHECK_MSG(covered > n / 50, "regions: the surface covers only %zu pixels", covered);
    CHECK_MSG(100.0 * (double)(n - diff) / (double)n >= 99.99,
              "regions: %zu of %zu pixels differ from the full extraction's image", diff, n);
    free(want);
    free(got);
    free(part);
    free(depth);
    free(nearest);
    ip_mesh_free(&full);
    ip_engine_destroy(e[0]);
    ip_engine_destroy(e[1]);
}

static void check_shared_data(void)
{
    const char *data = getenv("IP_SKIP_SHARED_DATA") ? NULL : getenv("IP_SHARED_DATA");
    static const struct {
        const char *file;
        float iso;
    } volumes[] = {{"neghip_66x66x66_uint8.raw", 40.5f}, {"tooth_103x94x161_uint8.raw", 120.5f}};
    for (size_t v = 0; v < sizeof volumes / sizeof volumes[0]; v++) {
        char raw[4096], ibv[4200];
        snprintf(raw, sizeof raw, "%s/%s", data ? data : "", volumes[v].file);
        FILE *f = data ? fopen(raw, "rb") : NULL;
        if (!f) {
            printf("test_engine: skipping %s: the shared data folder is absent\n", volumes[v].file);
            continue;
        }
        fclose(f);
        snprintf(ibv, sizeof ibv, "%s/%s.ibv", test_tmp_dir("test_engine_shared"), volumes[v].file);
        ip_input_desc d;
        ip_bricker_options o;
        ip_error err;
        REQUIRE(ip_input_describe(raw, NULL, &d, &err) == IP_OK);
        ip_bricker_options_default(&o);
        o.force = 1;
        REQUIRE(ip_bricker_run(&d, ibv, &o, NULL, &err) == IP_OK);
        scene s;
        open_scene(ibv, &s);
        check_view(&s, volumes[v].file, "-y", volumes[v].iso, 200, 160);
        check_view(&s, volumes[v].file, "+x", volumes[v].iso, 160, 200);
        close_scene(&s);
    }
}

/* The scenes the first cases share, each made and opened by the first case that looks at it and
 * closed when a case looks at another one, or after the last case. */
enum {
    SPHERE,
    GYROID,
    MARSCHNER_LOBB
};
static const char *scratch_dir;
static scene the_scene;
static int scene_kind = -1; /* the scene the_scene holds, or -1 */

static void close_the_scene(void)
{
    if (scene_kind >= 0)
        close_scene(&the_scene);
    scene_kind = -1;
}

static scene *scene_of(int kind)
{
    if (scene_kind != kind) {
        close_the_scene();
        char ibv[4200];
        if (kind == SPHERE)
            make_volume(scratch_dir, IP_FIELD_SPHERE, 40, IP_UINT8, 8, ibv, sizeof ibv);
        else if (kind == GYROID)
            make_volume(scratch_dir, IP_FIELD_GYROID, 36, IP_FLOAT32, 8, ibv, sizeof ibv);
        else
            make_volume(scratch_dir, IP_FIELD_MARSCHNER_LOBB, 41, IP_UINT16, 16, ibv, sizeof ibv);
        open_scene(ibv, &the_scene);
        scene_kind = kind;
    }
    return &the_scene;
}

static void sphere_views(void)
{
    check_view(scene_of(SPHERE), "sphere", "-y", 127.5f, 120, 100);
    check_view(scene_of(SPHERE), "sphere", "+z", 90.5f, 100, 120);
}
static void sphere_empty_space(void)
{
    check_empty_space(scene_of(SPHERE), 200.5f);
}
static void sphere_reach_tiles(void)
{
    check_reach_tiles(scene_of(SPHERE));
}
static void gyroid_views(void)
{
    check_view(scene_of(GYROID), "gyroid", "-x", 0.5f, 128, 96);
    check_view(scene_of(GYROID), "gyroid", "+y", 0.6f, 96, 128);
}
static void gyroid_cancel_restart(void)
{
    check_cancel_restart(scene_of(GYROID), 0.5f, 0.45f);
}
static void gyroid_ray_budgets(void)
{
    check_ray_budgets(scene_of(GYROID), 0.5f, 97, 61);
    check_ray_budgets(scene_of(GYROID), 0.5f, 320, 240);
}
static void gyroid_regions(void)
{
    check_regions(scene_of(GYROID), 0.5f);
}
static void gyroid_threads(void)
{
    check_threads(scene_of(GYROID), 0.5f);
}
static void gyroid_culling(void)
{
    check_culling(scene_of(GYROID), 0.5f);
}
static void marschner_lobb_views(void)
{
    check_view(scene_of(MARSCHNER_LOBB), "marschner-lobb", "+x", 2047.5f, 140, 110);
    check_view(scene_of(MARSCHNER_LOBB), "marschner-lobb", "-z", 2047.5f, 110, 140);
}
static void lod(void)
{
    check_lod(scratch_dir);
}
static void lod_exact(void)
{
    check_lod_exact(scratch_dir);
}
static void reuse_exact(void)
{
    check_reuse_exact(scratch_dir);
}
static void read_ahead(void)
{
    check_read_ahead(scratch_dir);
}
static void occlusion(void)
{
    check_occlusion(scratch_dir);
}
static void retirement(void)
{
    check_retirement(scratch_dir);
}

static const test_case cases[] = {
    {"check_view:sphere", sphere_views},
    {"check_empty_space", sphere_empty_space},
    {"check_reach_tiles", sphere_reach_tiles},
    {"check_view:gyroid", gyroid_views},
    {"check_cancel_restart", gyroid_cancel_restart},
    {"check_ray_budgets", gyroid_ray_budgets},
    {"check_regions", gyroid_regions},
    {"check_threads", gyroid_threads},
    {"check_culling", gyroid_culling},
    {"check_view:marschner-lobb", marschner_lobb_views},
    {"check_lod", lod},
    {"check_lod_exact", lod_exact},
    {"check_reuse_exact", reuse_exact},
    {"check_read_ahead", read_ahead},
    TEST_CASE(check_coverage_box_test),
    TEST_CASE(check_cull_mask),
    TEST_CASE(check_coverage_indexed),
    TEST_CASE(check_depth_queue),
    TEST_CASE(check_reach_box),
    TEST_CASE(check_coverage_reach),
    {"check_occlusion", occlusion},
    {"check_retirement", retirement},
    TEST_CASE(check_shared_data),
};

static void make_scratch_dir(void)
{
    scratch_dir = test_tmp_dir("test_engine");
}

int main(int argc, char **argv)
{
    return RUN_CASES_WITH(argc, argv, cases, "test_engine", make_scratch_dir, close_the_scene);
}

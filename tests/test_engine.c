/* The engine against the paper's guarantee: once every pixel has had its ray, the image of the
 * progressive mesh equals the image of the full extraction (same coverage, >= 99.99 % equal
 * pixels), and every progressive triangle is a triangle of the full result (same cell, same
 * vertices). Also: empty space reads summaries only; cancel and restart leave nothing stale. */
#include <dirent.h>
#include <math.h>

#include "check.h"
#include "isoprop/bricker.h"
#include "isoprop/engine.h"
#include "isoprop/generate.h"
#include "isoprop/render.h"

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
    for (int a = 0; a < 3; a++) {
        s->lo[a] = 0;
        s->hi[a] = (l->dims[a] - 1) * l->spacing[a];
    }
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
    ip_gen_params p = {field, {n, n + 3, n - 5}, type, 0.0, 1};
    char name[256], raw[4096];
    ip_error err;
    REQUIRE(ip_raw_file_name(name, sizeof name, ip_field_name(field), p.dims, type) == IP_OK);
    snprintf(raw, sizeof raw, "%s/%s", dir, name);
    REQUIRE(ip_generate_write(&p, raw, 1, &err) == IP_OK);
    snprintf(ibv, size, "%s/%s.b%u.ibv", dir, ip_field_name(field), edge);
    ip_input_desc d;
    ip_brick_options o;
    REQUIRE(ip_input_describe(raw, NULL, &d, &err) == IP_OK);
    d.spacing[2] = 1.25; /* anisotropic: world coordinates must honour spacing */
    ip_brick_options_default(&o);
    o.brick_edge = edge;
    o.subblock_edge = edge / 4 ? edge / 4 : 1;
    o.force = 1;
    REQUIRE(ip_brick_volume(&d, ibv, &o, NULL, &err) == IP_OK);
}

/* Two triangles are the same when they come from the same cell and have the same vertices. */
static int same_triangle(const ip_mesh *a, uint64_t i, const ip_mesh *b, uint64_t j)
{
    return a->cells[i] == b->cells[j] &&
           memcmp(&a->positions[9 * i], &b->positions[9 * j], 9 * sizeof(float)) == 0;
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
    uint64_t (*keys)[2] = malloc(full->triangle_count * sizeof *keys);
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
    REQUIRE(ip_engine_create(s->cache, &o, &e, &err) == IP_OK);
    ip_engine_counts t;
    run_all_rays(e, &cam, iso, &t);
    const ip_mesh *part = ip_engine_mesh(e);
    ip_mesh full;
    ip_mesh_init(&full);
    ip_engine_counts fc;
    REQUIRE(ip_extract_full(s->cache, iso, 0, 0, &full, &fc, &err) == IP_OK);
    CHECK(t.rays == (uint64_t)w * h);
    CHECK(part->triangle_count == t.triangles && full.triangle_count == fc.triangles);
    CHECK_MSG(part->triangle_count > 0 && part->triangle_count <= full.triangle_count,
              "%s %s: %llu progressive, %llu full triangles", what, axis,
              (unsigned long long)part->triangle_count, (unsigned long long)full.triangle_count);
    uint64_t missing = triangles_not_in(part, &full);
    CHECK_MSG(missing == 0, "%s %s: %llu progressive triangles are not full triangles", what,
              axis, (unsigned long long)missing);

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
    printf("test_engine: %s %s iso %g: %llu rays, %llu seeds, %llu of %llu triangles, "
           "%zu covered pixels, %zu coverage and %zu colour differences\n",
           what, axis, (double)iso, (unsigned long long)t.rays, (unsigned long long)t.seeds,
           (unsigned long long)part->triangle_count, (unsigned long long)full.triangle_count,
           covered, coverage_diff, pixel_diff);
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
    ip_camera cam = {{-40, -40, -40}, {s->hi[0] * 0.02, s->hi[1] * 0.02, s->hi[2] * 0.98},
                     {0, 0, 1}, 2.0, 16, 16};
    ip_engine_counts t;
    run_all_rays(e, &cam, iso, &t);
    ip_cache_stats st;
    ip_cache_get_stats(cache, &st);
    CHECK(t.rays == 256 && t.seeds == 0);
    CHECK_MSG(st.misses == 0 && st.bricks_touched == 0, "empty space decoded %llu bricks",
              (unsigned long long)st.misses);
    /* and the same engine on a view of the sphere does decode bricks */
    REQUIRE(ip_camera_fit_axis(s->lo, s->hi, "+z", 30.0, 32, 32, &cam, &err) == IP_OK);
    run_all_rays(e, &cam, iso, &t);
    ip_cache_get_stats(cache, &st);
    CHECK(t.seeds > 0 && st.misses > 0);
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
    REQUIRE(ip_engine_create(s->cache, &o, &e, &err) == IP_OK);
    REQUIRE(ip_engine_create(s->cache, &o, &fresh, &err) == IP_OK);
    REQUIRE(ip_engine_begin(e, &cam, iso_a, &err) == IP_OK);
    REQUIRE(ip_engine_step(e, 300, 0, NULL, &err) == IP_OK);
    CHECK(ip_engine_mesh(e)->triangle_count > 0);
    ip_engine_cancel(e);
    CHECK(ip_engine_step(e, 0, 0, NULL, &err) == IP_ERR_CANCELLED);
    CHECK(!ip_engine_done(e));
    ip_engine_counts ta, tb;
    run_all_rays(e, &cam, iso_b, &ta);
    run_all_rays(fresh, &cam, iso_b, &tb);
    const ip_mesh *a = ip_engine_mesh(e), *b = ip_engine_mesh(fresh);
    int same = a->triangle_count == b->triangle_count && ta.rays == tb.rays &&
               ta.seeds == tb.seeds;
    for (uint64_t i = 0; same && i < a->triangle_count; i++)
        same = same_triangle(a, i, b, i);
    CHECK_MSG(same, "restart: %llu triangles against %llu from a fresh engine",
              (unsigned long long)a->triangle_count, (unsigned long long)b->triangle_count);
    ip_engine_destroy(e);
    ip_engine_destroy(fresh);
}

static void check_shared_data(void)
{
    const char *data = getenv("IP_SKIP_SHARED_DATA") ? NULL : getenv("IP_SHARED_DATA");
    static const struct { const char *file; float iso; } volumes[] = {
        {"neghip_66x66x66_uint8.raw", 40.5f}, {"tooth_103x94x161_uint8.raw", 120.5f}};
    for (size_t v = 0; v < sizeof volumes / sizeof volumes[0]; v++) {
        char raw[4096], ibv[4200];
        snprintf(raw, sizeof raw, "%s/%s", data ? data : "", volumes[v].file);
        FILE *f = data ? fopen(raw, "rb") : NULL;
        if (!f) {
            printf("test_engine: skipping %s: the shared data folder is absent\n",
                   volumes[v].file);
            continue;
        }
        fclose(f);
        snprintf(ibv, sizeof ibv, "%s/%s.ibv", test_tmp_dir("test_engine_shared"), volumes[v].file);
        ip_input_desc d;
        ip_brick_options o;
        ip_error err;
        REQUIRE(ip_input_describe(raw, NULL, &d, &err) == IP_OK);
        ip_brick_options_default(&o);
        o.force = 1;
        REQUIRE(ip_brick_volume(&d, ibv, &o, NULL, &err) == IP_OK);
        scene s;
        open_scene(ibv, &s);
        check_view(&s, volumes[v].file, "-y", volumes[v].iso, 200, 160);
        check_view(&s, volumes[v].file, "+x", volumes[v].iso, 160, 200);
        close_scene(&s);
    }
}

int main(void)
{
    const char *dir = test_tmp_dir("test_engine");
    char ibv[4200];
    scene s;
    make_volume(dir, IP_FIELD_SPHERE, 40, IP_UINT8, 8, ibv, sizeof ibv);
    open_scene(ibv, &s);
    check_view(&s, "sphere", "-y", 127.5f, 120, 100);
    check_view(&s, "sphere", "+z", 90.5f, 100, 120);
    check_empty_space(&s, 200.5f);
    close_scene(&s);

    make_volume(dir, IP_FIELD_GYROID, 36, IP_FLOAT32, 8, ibv, sizeof ibv);
    open_scene(ibv, &s);
    check_view(&s, "gyroid", "-x", 0.5f, 128, 96);
    check_view(&s, "gyroid", "+y", 0.6f, 96, 128);
    check_cancel_restart(&s, 0.5f, 0.45f);
    close_scene(&s);

    make_volume(dir, IP_FIELD_MARSCHNER_LOBB, 41, IP_UINT16, 16, ibv, sizeof ibv);
    open_scene(ibv, &s);
    check_view(&s, "marschner-lobb", "+x", 2047.5f, 140, 110);
    check_view(&s, "marschner-lobb", "-z", 2047.5f, 110, 140);
    close_scene(&s);

    check_shared_data();
    return test_summary("test_engine");
}

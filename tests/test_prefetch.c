/* SPDX-License-Identifier: BSD-3-Clause */
/* Reading bricks ahead (src/store/cache_prefetch.h, src/engine/prefetch.c): counts, never times.
 * The cache: a brick loaded ahead is a hit at its first pin and counted once in prefetch_hits;
 * a load ahead never goes over the budget, never evicts a pinned brick or one pinned since the
 * tick it names; a bad brick loaded ahead is not cached, not counted as an error, and its pin
 * reports the same message as without it. The engine: with reading ahead the triangles (one
 * thread) and the image (two threads) equal those without; every brick touched is either a
 * miss or a brick loaded ahead and then pinned; the budget holds; a corrupt brick gives the same
 * one-line error; cancel and a new view leave nothing stale. */
#include <stdint.h>

#include "cache_prefetch.h"
#include "check.h"
#include "isoprop/engine.h"
#include "isoprop/render.h"
#include "volumes.h"

#define WIDTH 160
#define HEIGHT 120
#define ISO 2047.5f

typedef struct scene {
    char path[4200];
    ip_camera camera;
    double lo[3], hi[3];
} scene;

typedef struct run_result {
    ip_status status;
    char message[sizeof(((ip_error *)0)->message)];
    ip_mesh mesh;
    uint8_t *rgba;
    ip_cache_stats stats;
} run_result;

/* What the cases share: the scratch folder and the scene in it (setup). */
static const char *scratch_dir;
static scene the_scene;

/* A gyroid in bricks of 8 cells: many bricks, and a surface across the whole picture. */
static void make_scene(const char *dir, scene *s)
{
    ip_gen_params p = {sizeof(ip_gen_params), IP_FIELD_GYROID, {41, 37, 33}, IP_UINT16, 0.0, 1};
    char raw[4400];
    ip_store *store;
    ip_error err;
    test_generate_raw(dir, "gyroid", &p, raw, sizeof raw);
    snprintf(s->path, sizeof s->path, "%s/gyroid.ibv", dir);
    test_brick_raw(raw, s->path, 8, 2);
    REQUIRE(ip_store_open(s->path, &store, &err) == IP_OK);
    ip_layout_world_box(ip_store_layout(store), s->lo, s->hi);
    ip_store_close(store);
    REQUIRE(ip_camera_fit_axis(s->lo, s->hi, "-y", 30.0, WIDTH, HEIGHT, &s->camera, &err) == IP_OK);
}

/* Every ray of the view in doubling steps, as isorender does. */
static void render(const scene *s, const char *path, int prefetch, unsigned threads,
                   uint64_t budget, run_result *r)
{
    ip_store *store = NULL;
    ip_cache *cache = NULL;
    ip_engine *engine = NULL;
    ip_engine_options o;
    ip_error err = {0};
    ip_engine_options_default(&o);
    o.threads = threads;
    o.prefetch = prefetch;
    o.cell_ids = 1;
    memset(r, 0, sizeof *r);
    ip_mesh_init(&r->mesh);
    r->mesh.with_cells = 1;
    r->rgba = malloc((size_t)WIDTH * HEIGHT * 4);
    REQUIRE(r->rgba);
    ip_status st = ip_store_open(path, &store, &err);
    if (st == IP_OK)
        st = ip_cache_create(store, budget, &cache, &err);
    if (st == IP_OK)
        st = ip_engine_create(cache, &o, &engine, &err);
    if (st == IP_OK)
        st = ip_engine_begin(engine, &s->camera, ISO, &err);
    for (uint64_t batch = 1; st == IP_OK && !ip_engine_done(engine); batch *= 2)
        st = ip_engine_step(engine, batch, 0, NULL, &err);
    if (st == IP_OK) {
        const ip_mesh *m = ip_engine_mesh(engine);
        REQUIRE(ip_mesh_append_mesh(&r->mesh, m, 0, m->triangle_count) == IP_OK);
        st = ip_raster_mesh(m, &s->camera, s->lo, s->hi, NULL, r->rgba, &err);
    }
    ip_engine_destroy(engine); /* the reader is stopped: the counts are final */
    if (cache)
        ip_cache_get_stats(cache, &r->stats);
    ip_cache_destroy(cache);
    ip_store_close(store);
    r->status = st;
    snprintf(r->message, sizeof r->message, "%s", st == IP_OK ? "" : err.message);
}

static void free_result(run_result *r)
{
    ip_mesh_free(&r->mesh);
    free(r->rgba);
}

static int same_mesh(const ip_mesh *a, const ip_mesh *b)
{
    return a->triangle_count == b->triangle_count &&
           memcmp(a->positions, b->positions, a->triangle_count * 9 * sizeof(float)) == 0 &&
           memcmp(a->cells, b->cells, a->triangle_count * sizeof(uint64_t)) == 0;
}

/* Same triangles (one thread) or same image (two), and the counts' relationship, reading
 * ahead every brick planned or only those not in memory. */
static void check_engine(void)
{
    const scene *s = &the_scene;
    for (unsigned threads = 1; threads <= 2; threads++)
        for (int mode = IP_PREFETCH_ON; mode <= IP_PREFETCH_ALWAYS; mode++) {
            run_result off, on;
            render(s, s->path, IP_PREFETCH_OFF, threads, 256ull << 20, &off);
            render(s, s->path, mode, threads, 256ull << 20, &on);
            CHECK_MSG(off.status == IP_OK && on.status == IP_OK, "%s / %s", off.message,
                      on.message);
            if (threads == 1)
                CHECK_MSG(same_mesh(&off.mesh, &on.mesh), "%llu against %llu triangles",
                          (unsigned long long)off.mesh.triangle_count,
                          (unsigned long long)on.mesh.triangle_count);
            CHECK_MEM_EQ(off.rgba, on.rgba, (size_t)WIDTH * HEIGHT * 4);
            CHECK_GT(off.mesh.triangle_count, 1000);
            CHECK_EQ(off.stats.prefetched, 0);
            CHECK_EQ(off.stats.prefetch_hits, 0);
            /* nothing is evicted: each touched brick was loaded once, by a miss or ahead */
            CHECK_EQ(on.stats.evictions, 0);
            CHECK_EQ(off.stats.evictions, 0);
            CHECK_EQ(off.stats.misses, off.stats.bricks_touched);
            CHECK_MSG(on.stats.misses + on.stats.prefetch_hits == on.stats.bricks_touched,
                      "%llu misses + %llu prefetch hits, %llu bricks touched",
                      (unsigned long long)on.stats.misses,
                      (unsigned long long)on.stats.prefetch_hits,
                      (unsigned long long)on.stats.bricks_touched);
            CHECK_LE(on.stats.prefetch_hits, on.stats.prefetched);
            CHECK(on.stats.bricks_touched == off.stats.bricks_touched || threads == 2);
            CHECK_EQ(on.stats.errors, 0);
            CHECK_GE(on.stats.wait_seconds, 0);
            printf(
                "test_prefetch: %u thread(s), %s: %llu bricks touched; off: %llu misses; on: %llu "
                "misses, %llu loaded ahead, %llu of them pinned\n",
                threads, mode == IP_PREFETCH_ON ? "on" : "always",
                (unsigned long long)on.stats.bricks_touched, (unsigned long long)off.stats.misses,
                (unsigned long long)on.stats.misses, (unsigned long long)on.stats.prefetched,
                (unsigned long long)on.stats.prefetch_hits);
            free_result(&off);
            free_result(&on);
        }
}

/* Reads the whole file, so that the page cache holds it. */
static void read_whole(const char *path)
{
    FILE *f = fopen(path, "rb");
    REQUIRE(f);
    char buf[65536];
    while (fread(buf, 1, sizeof buf, f) == sizeof buf)
        ;
    fclose(f);
}

/* With the workers on every core and every payload in the page cache, IP_PREFETCH_ON leaves
 * every brick to the workers (nothing is loaded ahead) and draws the same image. */
static void check_leaves_in_memory(void)
{
    const scene *s = &the_scene;
    read_whole(s->path);
    ip_store *store;
    ip_error err;
    REQUIRE(ip_store_open(s->path, &store, &err) == IP_OK);
    int all = 1;
    for (uint64_t g = 0; g < ip_store_layout(store)->brick_count; g++)
        all &= ip_store_brick_in_memory(store, g) == 1;
    ip_store_close(store);
    if (!all) { /* the kernel cannot tell, or dropped pages since: nothing to compare */
        printf("test_prefetch: the page cache does not hold every payload: not checked\n");
        return;
    }
    unsigned cores = ip_thread_count(0);
    run_result off, on;
    render(s, s->path, IP_PREFETCH_OFF, cores, 256ull << 20, &off);
    render(s, s->path, IP_PREFETCH_ON, cores, 256ull << 20, &on);
    CHECK_EQ(off.status, IP_OK);
    CHECK_EQ(on.status, IP_OK);
    CHECK_MSG(on.stats.prefetched == 0, "%llu bricks loaded ahead",
              (unsigned long long)on.stats.prefetched);
    CHECK_EQ(on.stats.misses, on.stats.bricks_touched);
    CHECK_MEM_EQ(off.rgba, on.rgba, (size_t)WIDTH * HEIGHT * 4);
    free_result(&off);
    free_result(&on);
}

/* A budget far below the bricks the view needs: loads ahead never raise the peak past it. */
static void check_budget(void)
{
    const scene *s = &the_scene;
    ip_cache_stats st;
    ip_store *store;
    ip_cache *cache;
    ip_error err;
    REQUIRE(ip_store_open(s->path, &store, &err) == IP_OK);
    ip_brick b;
    REQUIRE(ip_cache_create(store, 1 << 20, &cache, &err) == IP_OK);
    REQUIRE(ip_cache_pin_brick(cache, 0, &b, &err) == IP_OK);
    ip_cache_get_stats(cache, &st);
    uint64_t brick_bytes = st.resident_bytes;
    ip_cache_unpin_brick(cache, &b);
    ip_cache_destroy(cache);
    ip_store_close(store);
    uint64_t budget = 40 * brick_bytes; /* room for the bricks pinned at once, not for all */
    run_result off, on;
    render(s, s->path, IP_PREFETCH_OFF, 2, budget, &off);
    render(s, s->path, IP_PREFETCH_ALWAYS, 2, budget, &on);
    CHECK_EQ(off.status, IP_OK);
    CHECK_EQ(on.status, IP_OK);
    CHECK_MEM_EQ(off.rgba, on.rgba, (size_t)WIDTH * HEIGHT * 4);
    CHECK_GT(on.stats.evictions, 0);
    CHECK_EQ(on.stats.over_budget_pins, 0);
    CHECK_EQ(off.stats.over_budget_pins, 0);
    CHECK_MSG(on.stats.resident_peak_bytes <= budget, "peak %llu, budget %llu",
              (unsigned long long)on.stats.resident_peak_bytes, (unsigned long long)budget);
    free_result(&off);
    free_result(&on);
}

/* The cache's side, on one thread: deterministic outcomes and counts. */
static void check_cache(void)
{
    const scene *s = &the_scene;
    ip_store *store;
    ip_cache *cache;
    ip_error err;
    ip_cache_stats st;
    ip_brick b[3];
    REQUIRE(ip_store_open(s->path, &store, &err) == IP_OK);
    REQUIRE(ip_cache_create(store, 1 << 20, &cache, &err) == IP_OK);
    REQUIRE(ip_cache_pin_brick(cache, 0, &b[0], &err) == IP_OK);
    ip_cache_get_stats(cache, &st);
    uint64_t bytes = st.resident_bytes; /* the file's bricks have the same size here */
    ip_cache_unpin_brick(cache, &b[0]);
    ip_cache_destroy(cache);
    /* room for 3 bricks */
    REQUIRE(ip_cache_create(store, 3 * bytes, &cache, &err) == IP_OK);
    uint64_t before = ip__cache_tick_now(cache);
    CHECK_EQ(ip__cache_prefetch_brick(cache, 0, before), IP__PREFETCH_LOADED);
    CHECK_EQ(ip__cache_prefetch_brick(cache, 0, before), IP__PREFETCH_PRESENT);
    CHECK_EQ(ip__cache_prefetch_unused(cache), 1);
    REQUIRE(ip_cache_pin_brick(cache, 0, &b[0], &err) == IP_OK);
    ip_cache_get_stats(cache, &st);
    CHECK_EQ(st.prefetched, 1);
    CHECK_EQ(st.prefetch_hits, 1);
    CHECK_EQ(st.misses, 0);
    CHECK_EQ(st.hits, 1);
    CHECK_EQ(ip__cache_prefetch_unused(cache), 0);
    REQUIRE(ip_cache_pin_brick(cache, 1, &b[1], &err) == IP_OK);
    REQUIRE(ip_cache_pin_brick(cache, 2, &b[2], &err) == IP_OK);
    /* full of pinned bricks: a load ahead must not go over the budget */
    CHECK_EQ(ip__cache_prefetch_brick(cache, 3, UINT64_MAX), IP__PREFETCH_FULL);
    for (int i = 0; i < 3; i++)
        ip_cache_unpin_brick(cache, &b[i]);
    /* unpinned, but pinned since `before`: still too valuable to push out */
    CHECK_EQ(ip__cache_prefetch_brick(cache, 3, before), IP__PREFETCH_FULL);
    ip_cache_get_stats(cache, &st);
    CHECK_EQ(st.resident_bricks, 3);
    CHECK_EQ(st.evictions, 0);
    /* older than the tick given: the least recently used goes */
    uint64_t now = ip__cache_tick_now(cache);
    CHECK_EQ(ip__cache_prefetch_brick(cache, 3, now), IP__PREFETCH_LOADED);
    CHECK_EQ(ip__cache_prefetch_brick(cache, 4, now), IP__PREFETCH_LOADED);
    /* the two loaded ahead are not pushed out by a third: brick 2 goes, then nothing */
    CHECK_EQ(ip__cache_prefetch_brick(cache, 5, now), IP__PREFETCH_LOADED);
    CHECK_EQ(ip__cache_prefetch_brick(cache, 6, now), IP__PREFETCH_FULL);
    ip_cache_get_stats(cache, &st);
    CHECK_LE(st.resident_peak_bytes, 3 * bytes);
    CHECK_EQ(st.prefetched, 4);
    CHECK_EQ(st.prefetch_hits, 1);
    CHECK_EQ(ip__cache_prefetch_unused(cache), 3);
    /* a brick loaded ahead and evicted unpinned is no prefetch hit */
    CHECK_EQ(ip_cache_trim(cache, 0), 3 * bytes);
    CHECK_EQ(ip__cache_prefetch_unused(cache), 0);
    REQUIRE(ip_cache_pin_brick(cache, 3, &b[0], &err) == IP_OK);
    ip_cache_unpin_brick(cache, &b[0]);
    ip_cache_get_stats(cache, &st);
    CHECK_EQ(st.prefetch_hits, 1);
    CHECK_EQ(st.misses, 3);
    CHECK_EQ(st.errors, 0);
    ip_cache_destroy(cache);
    ip_store_close(store);
}

/* Copies the file with one byte of every payload flipped: each such brick fails its checksum. */
static void corrupt_copy(const char *from, const char *to)
{
    ip_store *store;
    ip_error err;
    FILE *f = fopen(from, "rb");
    REQUIRE(f && fseek(f, 0, SEEK_END) == 0);
    long size = ftell(f);
    unsigned char *bytes = malloc((size_t)size);
    REQUIRE(bytes && fseek(f, 0, SEEK_SET) == 0 &&
            fread(bytes, 1, (size_t)size, f) == (size_t)size);
    fclose(f);
    REQUIRE(ip_store_open(from, &store, &err) == IP_OK);
    uint64_t flipped = 0;
    for (uint64_t g = 0; g < ip_store_layout(store)->brick_count; g++) {
        ip_brick_entry be;
        ip_store_brick_entry(store, g, &be);
        if (be.stored_size > 0) {
            bytes[be.offset + be.stored_size / 2] ^= 0x10;
            flipped++;
        }
    }
    ip_store_close(store);
    REQUIRE(flipped > 0);
    f = fopen(to, "wb");
    REQUIRE(f && fwrite(bytes, 1, (size_t)size, f) == (size_t)size && fclose(f) == 0);
    free(bytes);
}

/* A failing read ahead surfaces as the worker's own error, the same line as without it. */
static void check_corrupt(void)
{
    const scene *s = &the_scene;
    const char *dir = scratch_dir;
    char bad[4300];
    snprintf(bad, sizeof bad, "%s/bad.ibv", dir);
    corrupt_copy(s->path, bad);
    for (unsigned threads = 1; threads <= 2; threads++) {
        run_result off, on;
        render(s, bad, IP_PREFETCH_OFF, threads, 256ull << 20, &off);
        render(s, bad, IP_PREFETCH_ALWAYS, threads, 256ull << 20, &on);
        CHECK_EQ(off.status, IP_ERR_CHECKSUM);
        CHECK_EQ(on.status, IP_ERR_CHECKSUM);
        CHECK_CONTAINS(on.message, "checksum mismatch");
        CHECK_CONTAINS(on.message, bad);
        CHECK_EQ(strchr(on.message, '\n'), NULL);
        if (threads == 1) /* the same first brick fails */
            CHECK_MSG(strcmp(off.message, on.message) == 0, "'%s' against '%s'", off.message,
                      on.message);
        CHECK_EQ(on.stats.prefetched, 0); /* nothing bad was ever cached */
        free_result(&off);
        free_result(&on);
    }
}

/* Cancelled halfway, then the same view again: the triangles of an uninterrupted run. */
static void check_cancel(void)
{
    const scene *s = &the_scene;
    ip_store *store;
    ip_cache *cache;
    ip_engine *engine;
    ip_engine_options o;
    ip_error err;
    ip_engine_options_default(&o);
    o.threads = 1;
    o.cell_ids = 1;
    REQUIRE(ip_store_open(s->path, &store, &err) == IP_OK);
    REQUIRE(ip_cache_create(store, 256ull << 20, &cache, &err) == IP_OK);
    REQUIRE(ip_engine_create(cache, &o, &engine, &err) == IP_OK);
    REQUIRE(ip_engine_begin(engine, &s->camera, ISO, &err) == IP_OK);
    REQUIRE(ip_engine_step(engine, 64, 0, NULL, &err) == IP_OK);
    ip_engine_cancel(engine);
    CHECK_EQ(ip_engine_step(engine, 0, 0, NULL, &err), IP_ERR_CANCELLED);
    REQUIRE(ip_engine_begin(engine, &s->camera, ISO, &err) == IP_OK);
    while (!ip_engine_done(engine))
        REQUIRE(ip_engine_step(engine, 0, 0, NULL, &err) == IP_OK);
    run_result off;
    render(s, s->path, 0, 1, 256ull << 20, &off);
    CHECK(same_mesh(ip_engine_mesh(engine), &off.mesh));
    free_result(&off);
    ip_engine_destroy(engine);
    ip_cache_destroy(cache);
    ip_store_close(store);
}

static const test_case cases[] = {
    TEST_CASE(check_cache),  TEST_CASE(check_engine),  TEST_CASE(check_leaves_in_memory),
    TEST_CASE(check_budget), TEST_CASE(check_corrupt), TEST_CASE(check_cancel),
};

static void make_the_scene(void)
{
    scratch_dir = test_tmp_dir("test_prefetch");
    make_scene(scratch_dir, &the_scene);
}

int main(int argc, char **argv)
{
    return RUN_CASES_WITH(argc, argv, cases, "test_prefetch", make_the_scene, NULL);
}

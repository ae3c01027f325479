/* SPDX-License-Identifier: BSD-3-Clause */
/* The stable path of the API (include/isoprop/status.h, "Structs that may grow"): option structs
 * read only as far as the caller's size says, a zero size standing for the 0.2.0 struct, a
 * later caller's struct taken when what this library does not know is zero and refused
 * otherwise; and the structs the library fills keep their reserved words zero. */
#include <stdalign.h>
#include <stdint.h>

#include "check.h"
#include "isoprop/isoprop.h"
#include "isoprop/render.h"
#include "sized.h"

/* A caller's option struct from a later version: this library's, then `extra` bytes more. */
typedef struct later_engine_options {
    ip_engine_options known;
    uint64_t extra[2];
} later_engine_options;

static void check_sized_in(void)
{
    ip_engine_options defaults, taken, given;
    ip_error err;
    ip_engine_options_default(&defaults);
    CHECK(defaults.size == sizeof defaults);
    /* the size the caller says: all of it */
    given = defaults;
    given.cutoff_degrees = 3.5;
    REQUIRE(ip__sized_in(&taken, sizeof taken, &given, sizeof given, "o", &err) == IP_OK);
    CHECK(taken.cutoff_degrees == 3.5);
    CHECK(taken.size == sizeof taken);
    /* 0: the struct as 0.2.0 declared it, which is all of today's */
    given.size = 0;
    ip_engine_options_default(&taken);
    REQUIRE(ip__sized_in(&taken, sizeof taken, &given, sizeof given, "o", &err) == IP_OK);
    CHECK(taken.cutoff_degrees == 3.5);
    CHECK(taken.size == sizeof taken);
    /* a shorter struct: the fields past it keep the library's defaults */
    given = defaults;
    given.size = (uint32_t)offsetof(ip_engine_options, foldback_degrees);
    given.cutoff_degrees = 7.0;
    given.foldback_degrees = 99.0; /* past the caller's size: not read */
    ip_engine_options_default(&taken);
    REQUIRE(ip__sized_in(&taken, sizeof taken, &given, offsetof(ip_engine_options, cutoff_degrees),
                         "o", &err) == IP_OK);
    CHECK(taken.cutoff_degrees == 7.0);
    CHECK(taken.foldback_degrees == defaults.foldback_degrees);
    /* under the 0.2.0 size: refused, naming the struct */
    given.size = 4;
    CHECK(ip__sized_in(&taken, sizeof taken, &given, sizeof given, "engine options", &err) ==
          IP_ERR_ARGUMENT);
    CHECK_CONTAINS(err.message, "engine options: size 4");
}

static void check_later_caller(void)
{
    later_engine_options later;
    ip_engine_options taken;
    ip_error err;
    memset(&later, 0, sizeof later);
    ip_engine_options_default(&later.known);
    later.known.size = sizeof later;
    later.known.pixel_error = 2.0;
    REQUIRE(ip__sized_in(&taken, sizeof taken, &later, sizeof taken, "o", &err) == IP_OK);
    CHECK(taken.pixel_error == 2.0);
    CHECK(taken.size == sizeof taken);
    later.extra[1] = 1; /* a field this library does not know, set */
    CHECK(ip__sized_in(&taken, sizeof taken, &later, sizeof taken, "engine options", &err) ==
          IP_ERR_UNSUPPORTED);
    CHECK_CONTAINS(err.message, "engine options: sets fields of a later isoprop");
}

/* The public entry points go through it: bad sizes are refused where options come in. */
static void check_entry_points(void)
{
    ip_error err;
    ip_input_overrides overrides = IP_SIZED(ip_input_overrides);
    CHECK(overrides.size == sizeof overrides);
    overrides.size = 3;
    ip_input_desc desc;
    CHECK(ip_input_describe("nothing_4x4x4_uint8.raw", &overrides, &desc, &err) == IP_ERR_ARGUMENT);
    CHECK_CONTAINS(err.message, "input overrides: size 3");
    ip_gen_params params = {0};
    params.size = 2;
    CHECK(ip_generate_plane(&params, 0, NULL, &err) == IP_ERR_ARGUMENT);
    CHECK_CONTAINS(err.message, "generate: size 2");
    ip_shading shading;
    ip_shading_default(&shading);
    CHECK(shading.size == sizeof shading);
    CHECK(ip_shading_check(&shading, &err) == IP_OK);
    shading.size = 0; /* the 0.2.0 struct */
    CHECK(ip_shading_check(&shading, &err) == IP_OK);
    shading.size = 1;
    CHECK(ip_shading_check(&shading, &err) == IP_ERR_ARGUMENT);
    ip_bricker_options bricker;
    ip_bricker_options_default(&bricker);
    CHECK(bricker.size == sizeof bricker);
    bricker.size = 5;
    uint64_t bytes = 0;
    memset(&desc, 0, sizeof desc);
    desc.dims[0] = desc.dims[1] = desc.dims[2] = 8;
    desc.spacing[0] = desc.spacing[1] = desc.spacing[2] = 1;
    CHECK(ip_bricker_memory_needed(&desc, &bricker, &bytes, &err) == IP_ERR_ARGUMENT);
    CHECK_CONTAINS(err.message, "bricker options: size 5");
}

static int all_zero(const uint64_t *words, size_t count)
{
    for (size_t i = 0; i < count; i++)
        if (words[i] != 0)
            return 0;
    return 1;
}

#define RESERVED_COUNT(s) (sizeof(s).reserved / sizeof(s).reserved[0])

/* What the library fills keeps the reserved words zero, whatever the caller's memory held. */
static void check_reserved_zero(void)
{
    const char *dir = test_tmp_dir("test_api");
    char raw[4200], ibv[4200];
    ip_error err;
    ip_gen_params params = {0, IP_FIELD_SPHERE, {20, 18, 16}, IP_UINT8, 0.0, 1};
    snprintf(raw, sizeof raw, "%s/sphere_20x18x16_uint8.raw", dir);
    snprintf(ibv, sizeof ibv, "%s/sphere.ibv", dir);
    REQUIRE(ip_generate_write(&params, raw, 1, &err) == IP_OK);
    ip_input_desc desc;
    memset(&desc, 0xA5, sizeof desc);
    REQUIRE(ip_input_describe(raw, NULL, &desc, &err) == IP_OK);
    CHECK(all_zero(desc.reserved, RESERVED_COUNT(desc)));
    ip_bricker_options options;
    ip_bricker_options_default(&options);
    options.brick_edge = 8;
    options.threads = 1;
    options.force = 1;
    ip_bricker_report report;
    memset(&report, 0xA5, sizeof report);
    REQUIRE(ip_bricker_run(&desc, ibv, &options, &report, &err) == IP_OK);
    CHECK(all_zero(report.reserved, RESERVED_COUNT(report)));
    ip_store *store;
    ip_cache *cache;
    REQUIRE(ip_store_open(ibv, &store, &err) == IP_OK);
    REQUIRE(ip_cache_create(store, 64u << 20, &cache, &err) == IP_OK);
    ip_engine_counts counts;
    memset(&counts, 0xA5, sizeof counts);
    ip_mesh mesh;
    ip_mesh_init(&mesh);
    REQUIRE(ip_extract_full(cache, 128.5f, 0, 1, &mesh, &counts, &err) == IP_OK);
    CHECK(counts.triangles == mesh.triangle_count);
    CHECK(counts.triangles > 0);
    CHECK(all_zero(counts.reserved, RESERVED_COUNT(counts)));
    ip_cache_stats stats;
    memset(&stats, 0xA5, sizeof stats);
    ip_cache_get_stats(cache, &stats);
    CHECK(all_zero(stats.reserved, RESERVED_COUNT(stats)));
    ip_engine_options eo;
    ip_engine_options_default(&eo);
    eo.threads = 1;
    ip_engine *engine;
    REQUIRE(ip_engine_create(cache, &eo, &engine, &err) == IP_OK);
    ip_camera camera;
    double lo[3], hi[3];
    ip_layout_world_box(ip_store_layout(store), lo, hi);
    REQUIRE(ip_camera_fit_axis(lo, hi, "-y", 30.0, 64, 48, &camera, &err) == IP_OK);
    REQUIRE(ip_engine_begin(engine, &camera, 128.5f, &err) == IP_OK);
    memset(&counts, 0xA5, sizeof counts);
    REQUIRE(ip_engine_step(engine, 0, 0, &counts, &err) == IP_OK);
    CHECK(all_zero(counts.reserved, RESERVED_COUNT(counts)));
    memset(&counts, 0xA5, sizeof counts);
    ip_engine_totals(engine, &counts);
    CHECK(all_zero(counts.reserved, RESERVED_COUNT(counts)));
    CHECK(counts.rays == 64u * 48u);
    ip_engine_memory memory;
    memset(&memory, 0xA5, sizeof memory);
    ip_engine_memory_of(engine, &memory);
    CHECK(all_zero(memory.reserved, RESERVED_COUNT(memory)));
    ip_engine_destroy(engine);
    ip_mesh_free(&mesh);
    ip_cache_destroy(cache);
    ip_store_close(store);
}

int main(int argc, char **argv)
{
    static const test_case cases[] = {TEST_CASE(check_sized_in), TEST_CASE(check_later_caller),
                                      TEST_CASE(check_entry_points),
                                      TEST_CASE(check_reserved_zero)};
    return RUN_CASES(argc, argv, cases, "test_api");
}

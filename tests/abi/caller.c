/* SPDX-License-Identifier: BSD-3-Clause */
/* A caller compiled against the headers of isoprop 0.2.0 (tests/abi/0.2.0/, the stable tier: no
 * IP_EXPERIMENTAL) and run against the library being built: the stable API must keep working
 * for programs compiled before, every struct laid out as they know it. It generates a sphere,
 * describes and bricks it, opens it, extracts it fully and progressively, and checks what the
 * structs it receives say against what it knows independently (the volume it made, the image it
 * asked for, the counts two calls must agree on). Argument: a scratch folder. */
#undef IP_EXPERIMENTAL
#include <stdio.h>
#include <string.h>

#include "isoprop/isoprop.h"

static int failures;

static void expect(int ok, const char *what)
{
    if (!ok) {
        fprintf(stderr, "abi_caller: %s\n", what);
        failures++;
    }
}

static int fail(const char *what, const ip_error *err)
{
    fprintf(stderr, "abi_caller: %s: %s\n", what, err->message);
    return 1;
}

int main(int argc, char **argv)
{
    if (argc != 2)
        return 2;
    char raw[4096], ibv[4096];
    snprintf(raw, sizeof raw, "%s/sphere_40x36x30_uint8.raw", argv[1]);
    snprintf(ibv, sizeof ibv, "%s/sphere.ibv", argv[1]);
    ip_error err;
    ip_gen_params params = {0}; /* size 0: the 0.2.0 struct */
    params.field = IP_FIELD_SPHERE;
    params.dims[0] = 40;
    params.dims[1] = 36;
    params.dims[2] = 30;
    params.type = IP_UINT8;
    params.seed = 1;
    if (ip_generate_write(&params, raw, 1, &err) != IP_OK)
        return fail("generate", &err);
    ip_input_overrides overrides = IP_SIZED(ip_input_overrides);
    overrides.has_spacing = 1;
    overrides.spacing[0] = overrides.spacing[1] = 1.0;
    overrides.spacing[2] = 2.0;
    ip_input_desc desc;
    if (ip_input_describe(raw, &overrides, &desc, &err) != IP_OK)
        return fail("describe", &err);
    expect(desc.dims[0] == 40 && desc.dims[1] == 36 && desc.dims[2] == 30, "desc.dims");
    expect(desc.type == IP_UINT8 && desc.spacing[2] == 2.0, "desc.type, desc.spacing");
    expect(strcmp(desc.path, raw) == 0, "desc.path");
    ip_bricker_options options;
    ip_bricker_options_default(&options);
    options.brick_edge = 8;
    options.force = 1;
    ip_bricker_report report;
    if (ip_bricker_run(&desc, ibv, &options, &report, &err) != IP_OK)
        return fail("brick", &err);
    expect(report.input_bytes == 40u * 36u * 30u, "report.input_bytes");
    expect(report.bricks >= 5u * 5u * 4u && report.levels >= 2, "report.bricks, report.levels");
    ip_store *store;
    if (ip_store_open(ibv, &store, &err) != IP_OK)
        return fail("open", &err);
    const ip_layout *layout = ip_store_layout(store);
    expect(layout->dims[0] == 40 && layout->dims[2] == 30 && layout->spacing[2] == 2.0, "layout");
    ip_cache *cache;
    if (ip_cache_create(store, 32u << 20, &cache, &err) != IP_OK)
        return fail("cache", &err);
    ip_mesh full;
    ip_mesh_init(&full);
    ip_engine_counts counts;
    if (ip_extract_full(cache, 128.5f, 0, 2, &full, &counts, &err) != IP_OK)
        return fail("full extraction", &err);
    expect(counts.triangles == full.triangle_count && counts.triangles > 100, "counts.triangles");
    ip_engine_options eo;
    ip_engine_options_default(&eo);
    eo.threads = 2;
    ip_engine *engine;
    if (ip_engine_create(cache, &eo, &engine, &err) != IP_OK)
        return fail("engine", &err);
    double lo[3], hi[3];
    ip_layout_world_box(layout, lo, hi);
    ip_camera camera;
    if (ip_camera_fit_axis(lo, hi, "-y", 30.0, 96, 72, &camera, &err) != IP_OK ||
        ip_engine_begin(engine, &camera, 128.5f, &err) != IP_OK)
        return fail("begin", &err);
    uint64_t rays = 0, triangles = 0;
    while (!ip_engine_done(engine)) {
        ip_engine_counts step;
        if (ip_engine_step(engine, 500, 0, &step, &err) != IP_OK)
            return fail("step", &err);
        rays += step.rays;
        triangles += step.triangles;
    }
    ip_engine_totals(engine, &counts);
    expect(counts.rays == 96u * 72u && rays == counts.rays, "counts.rays");
    expect(counts.triangles == triangles && triangles == ip_engine_mesh(engine)->triangle_count,
           "counts.triangles of the steps");
    expect(triangles > 0 && triangles <= full.triangle_count, "a view's triangles");
    ip_cache_stats stats;
    ip_cache_get_stats(cache, &stats);
    expect(stats.budget_bytes == 32u << 20, "stats.budget_bytes");
    expect(stats.misses > 0 && stats.resident_bytes <= stats.budget_bytes, "stats");
    printf("abi_caller: isoprop %s, %llu triangles full, %llu in view, %d failures\n", ip_version(),
           (unsigned long long)full.triangle_count, (unsigned long long)triangles, failures);
    ip_engine_destroy(engine);
    ip_mesh_free(&full);
    ip_cache_destroy(cache);
    ip_store_close(store);
    return failures == 0 ? 0 : 1;
}

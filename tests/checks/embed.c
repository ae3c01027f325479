/* SPDX-License-Identifier: BSD-3-Clause */
/* An embedder's program: the whole chain through the public API alone (isoprop/isoprop.h,
 * linked with libisoprop.so, no internal header on its include path). Generates a sphere,
 * bricks it, opens it with a small cache, extracts the isosurface progressively until every
 * ray has been cast, and fully; both must find the sphere. Argument: a scratch folder. Only
 * the stable tier of the API (the build defines IP_EXPERIMENTAL for everything else). */
#undef IP_EXPERIMENTAL
#include <stdio.h>
#include <string.h>

#include "isoprop/isoprop.h"

static int fail(const char *what, const ip_error *err)
{
    fprintf(stderr, "embed: %s: %s\n", what, err->message);
    return 1;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: embed SCRATCH_FOLDER\n");
        return 2;
    }
    char raw[4096], ibv[4096];
    snprintf(raw, sizeof raw, "%s/sphere_48x40x32_uint8.raw", argv[1]);
    snprintf(ibv, sizeof ibv, "%s/sphere.ibv", argv[1]);
    ip_error err;
    ip_gen_params g = {sizeof(ip_gen_params), IP_FIELD_SPHERE, {48, 40, 32}, IP_UINT8, 0.0, 1};
    if (ip_generate_write(&g, raw, 1, &err) != IP_OK)
        return fail("generate", &err);
    ip_input_desc in;
    ip_bricker_options bo;
    ip_bricker_options_default(&bo);
    bo.brick_edge = 8;
    bo.force = 1;
    if (ip_input_describe(raw, NULL, &in, &err) != IP_OK ||
        ip_bricker_run(&in, ibv, &bo, NULL, &err) != IP_OK)
        return fail("brick", &err);

    ip_store *store = NULL;
    ip_cache *cache = NULL;
    ip_engine *engine = NULL;
    ip_engine_options eo;
    ip_engine_options_default(&eo);
    eo.threads = 2;
    ip_camera camera;
    double lo[3], hi[3];
    if (ip_store_open(ibv, &store, &err) != IP_OK ||
        ip_cache_create(store, 1u << 20, &cache, &err) != IP_OK ||
        ip_engine_create(cache, &eo, &engine, &err) != IP_OK)
        return fail("open", &err);
    ip_layout_world_box(ip_store_layout(store), lo, hi);
    if (ip_camera_fit_axis(lo, hi, "-y", 30.0, 64, 48, &camera, &err) != IP_OK ||
        ip_engine_begin(engine, &camera, 128.5f, &err) != IP_OK)
        return fail("begin", &err);
    while (!ip_engine_done(engine))
        if (ip_engine_step(engine, 256, 0, NULL, &err) != IP_OK)
            return fail("step", &err);
    ip_engine_counts t;
    ip_engine_totals(engine, &t);
    uint64_t progressive = ip_engine_mesh(engine)->triangle_count;

    ip_mesh full;
    ip_mesh_init(&full);
    if (ip_extract_full(cache, 128.5f, 0, 2, &full, NULL, &err) != IP_OK)
        return fail("full extraction", &err);
    ip_cache_stats cs;
    ip_cache_get_stats(cache, &cs);
    printf("embed: isoprop %s: %llu rays, %llu triangles progressive (visible side), %llu full; "
           "cache peak %llu of %llu bytes\n",
           ip_version(), (unsigned long long)t.rays, (unsigned long long)progressive,
           (unsigned long long)full.triangle_count, (unsigned long long)cs.resident_peak_bytes,
           (unsigned long long)cs.budget_bytes);
    int ok = t.rays == 64u * 48u && progressive > 0 && full.triangle_count >= progressive &&
             cs.resident_peak_bytes <= cs.budget_bytes;
    ip_mesh_free(&full);
    ip_engine_destroy(engine);
    ip_cache_destroy(cache);
    ip_store_close(store);
    if (!ok)
        fprintf(stderr, "embed: unexpected counts\n");
    return ok ? 0 : 1;
}

/* bench_steps: the progressive engine driven as the viewer drives it, in many small steps of a
 * fixed number of rays, through the public API only (so the same source measures any build of
 * the library). Prints the wall time of the whole image, the steps and the time per step.
 * A benchmark, not a test: the figures depend on the machine and on what else runs on it.
 */
#include <stdio.h>
#include <stdlib.h>

#include "isoprop/isoprop.h"

static const char usage[] =
    "usage: bench_steps FILE.ibv ISO VIEW WIDTHxHEIGHT RAYS_PER_STEP THREADS REPEATS\n"
    "Casts every ray of the view RAYS_PER_STEP at a time, REPEATS times on one warm engine.\n";

int main(int argc, char **argv)
{
    if (argc != 8) {
        fputs(usage, stderr);
        return 2;
    }
    ip_error err;
    ip_store *store = NULL;
    ip_cache *cache = NULL;
    ip_engine *engine = NULL;
    uint32_t width, height;
    if (sscanf(argv[4], "%ux%u", &width, &height) != 2) {
        fputs(usage, stderr);
        return 2;
    }
    float iso = strtof(argv[2], NULL);
    uint64_t rays = strtoull(argv[5], NULL, 10);
    ip_engine_options o;
    ip_engine_options_default(&o);
    o.threads = (unsigned)strtoul(argv[6], NULL, 10);
    int repeats = atoi(argv[7]);
    double lo[3], hi[3];
    ip_camera camera;
    if (ip_store_open(argv[1], &store, &err) != IP_OK ||
        ip_cache_create(store, (uint64_t)512 << 20, &cache, &err) != IP_OK ||
        ip_engine_create(cache, &o, &engine, &err) != IP_OK)
        goto fail;
    ip_layout_world_box(ip_store_layout(store), lo, hi);
    if (ip_camera_fit_axis(lo, hi, argv[3], 30.0, width, height, &camera, &err) != IP_OK)
        goto fail;
    for (int r = 0; r <= repeats; r++) { /* run 0 warms the cache */
        double t0 = ip_now_seconds();    /* the view's set-up counts */
        if (ip_engine_begin(engine, &camera, iso, &err) != IP_OK)
            goto fail;
        uint64_t steps = 0;
        while (!ip_engine_done(engine)) {
            if (ip_engine_step(engine, rays, 0, NULL, &err) != IP_OK)
                goto fail;
            steps++;
        }
        double seconds = ip_now_seconds() - t0;
        if (r > 0)
            printf("run %d: %.4f s, %llu steps, %.2f us per step, %llu triangles\n", r, seconds,
                   (unsigned long long)steps, seconds / (double)steps * 1e6,
                   (unsigned long long)ip_engine_mesh(engine)->triangle_count);
    }
    ip_engine_destroy(engine);
    ip_cache_destroy(cache);
    ip_store_close(store);
    return 0;
fail:
    fprintf(stderr, "bench_steps: %s\n", err.message);
    return 1;
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* bench_steps: the progressive engine driven as the viewer drives it, in many small steps of a
 * fixed number of rays, or as isorender's --progress drives it, in steps ending at 1, 2, 4, ...
 * rays, through the public API only (so the same source measures any build of the library).
 * Prints the wall time of each run (the view's ip_engine_begin() included, and that call alone),
 * its steps and the time per step, then the median of the warm runs. Run 0 is the process's
 * first view, on an empty cache (REPEATS 0 runs only that one, e.g. to profile it). A
 * benchmark, not a test: the figures depend on the machine and on what else runs on it.
 */
#include <stdio.h>
#include <stdlib.h>

#include "isoprop/isoprop.h"

static const char usage[] =
    "usage: bench_steps FILE.ibv ISO VIEW WIDTHxHEIGHT RAYS_PER_STEP THREADS REPEATS [MAX_RAYS]\n"
    "Casts the rays of the view RAYS_PER_STEP at a time (0: steps ending at 1, 2, 4, ... rays),\n"
    "all of them or the first MAX_RAYS, REPEATS times on one engine after run 0, the first\n"
    "view on an empty cache, which warms it.\n";

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* The rays of the next step: `per_step`, or up to the next power of two (per_step 0), no more
 * than what is left of `max_rays` (0: no limit; ip_engine_step() stops at the last ray). */
static uint64_t step_rays(uint64_t per_step, uint64_t done, uint64_t max_rays)
{
    uint64_t n = per_step;
    if (n == 0) {
        uint64_t next = 1;
        while (next <= done)
            next *= 2;
        n = next - done;
    }
    if (max_rays && n > max_rays - done)
        n = max_rays - done;
    return n;
}

int main(int argc, char **argv)
{
    if (argc != 8 && argc != 9) {
        fputs(usage, stderr);
        return 2;
    }
    ip_error err;
    ip_store *store = NULL;
    ip_cache *cache = NULL;
    ip_engine *engine = NULL;
    uint32_t width, height;
    int repeats = atoi(argv[7]);
    if (sscanf(argv[4], "%ux%u", &width, &height) != 2 || repeats < 0 || repeats > 1000) {
        fputs(usage, stderr);
        return 2;
    }
    float iso = strtof(argv[2], NULL);
    uint64_t rays = strtoull(argv[5], NULL, 10);
    uint64_t max_rays = argc == 9 ? strtoull(argv[8], NULL, 10) : 0;
    ip_engine_options o;
    ip_engine_options_default(&o);
    o.threads = (unsigned)strtoul(argv[6], NULL, 10);
    double lo[3], hi[3], times[1000];
    ip_camera camera;
    if (ip_store_open(argv[1], &store, &err) != IP_OK ||
        ip_cache_create(store, (uint64_t)512 << 20, &cache, &err) != IP_OK ||
        ip_engine_create(cache, &o, &engine, &err) != IP_OK)
        goto fail;
    ip_layout_world_box(ip_store_layout(store), lo, hi);
    if (ip_camera_fit_axis(lo, hi, argv[3], 30.0, width, height, &camera, &err) != IP_OK)
        goto fail;
    for (int r = 0; r <= repeats; r++) { /* run 0 fills the cache */
        double t0 = ip_now_seconds();    /* the view's set-up counts */
        if (ip_engine_begin(engine, &camera, iso, &err) != IP_OK)
            goto fail;
        double begun = ip_now_seconds() - t0;
        uint64_t steps = 0, done = 0;
        while (!ip_engine_done(engine) && (!max_rays || done < max_rays)) {
            uint64_t n = step_rays(rays, done, max_rays);
            ip_engine_counts counts;
            if (ip_engine_step(engine, n, 0, &counts, &err) != IP_OK)
                goto fail;
            done += counts.rays;
            steps++;
        }
        double seconds = ip_now_seconds() - t0;
        if (r > 0)
            times[r - 1] = seconds;
        printf("run %d: %.4f s (begin %.4f s), %llu steps, %.2f us per step, %llu rays, "
               "%llu triangles\n",
               r, seconds, begun, (unsigned long long)steps, seconds / (double)steps * 1e6,
               (unsigned long long)done,
               (unsigned long long)ip_engine_mesh(engine)->triangle_count);
    }
    if (repeats > 0) {
        qsort(times, (size_t)repeats, sizeof times[0], compare_doubles);
        printf("median %.4f s [%.4f-%.4f] of %d runs\n", times[(repeats - 1) / 2], times[0],
               times[repeats - 1], repeats);
    }
    ip_engine_destroy(engine);
    ip_cache_destroy(cache);
    ip_store_close(store);
    return 0;
fail:
    fprintf(stderr, "bench_steps: %s\n", err.message);
    return 1;
}

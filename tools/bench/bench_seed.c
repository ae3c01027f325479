/* SPDX-License-Identifier: BSD-3-Clause */
/* Ray seeding alone: casts the ray of every pixel through level 0 of a brick file (one
 * thread, the bricks already decoded), with the cell-group ranges used and not, and prints
 * the time and the cells read and tested per ray of each, and what decoding the bricks cost
 * (the first, untimed pass); fails when the two find different cells. Run by hand
 * (docs/notes/performance-notebook.md, part 8), never by the tests.
 *
 *   bench_seed FILE.ibv ISO VIEW [WxH] [REPEAT]    e.g. bench_seed head.ibv 600.5 -y 1600x1200 3
 */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "isoprop/isoprop.h"
#include "seed.h"

typedef struct pass {
    double seconds;
    uint64_t cells_read, cells_tested, seeds, digest;
} pass;

/* One pass over every pixel; the digest sums what each ray found, so that passes compare. */
static int cast_all(ip_seeder *s, const ip_camera *camera, const ip_camera_basis *basis, pass *p)
{
    s->cells_read = s->cells_tested = 0;
    uint64_t digest = 1469598103934665603ull, seeds = 0;
    double t0 = ip_now_seconds();
    for (uint32_t y = 0; y < camera->height; y++)
        for (uint32_t x = 0; x < camera->width; x++) {
            double dir[3];
            uint32_t cells[IP_SEED_MAX_CELLS][3];
            unsigned count;
            int seed;
            ip_camera_pixel_ray(basis, camera, x + 0.5, y + 0.5, dir);
            int found = ip__seed_find(s, camera->eye, dir, 0, INFINITY, cells, &count, &seed);
            if (found < 0)
                return 0;
            seeds += found == 1;
            digest = (digest ^ (uint64_t)(seed + 1)) * 1099511628211ull;
            for (unsigned i = 0; i < count; i++)
                for (int k = 0; k < 3; k++)
                    digest = (digest ^ cells[i][k]) * 1099511628211ull;
        }
    p->seconds = ip_now_seconds() - t0;
    p->cells_read = s->cells_read;
    p->cells_tested = s->cells_tested;
    p->seeds = seeds;
    p->digest = digest;
    return 1;
}

int main(int argc, char **argv)
{
    if (argc < 4) {
        fprintf(stderr, "usage: bench_seed FILE.ibv ISO VIEW [WxH] [REPEAT]\n");
        return 2;
    }
    uint32_t width = 1600, height = 1200;
    int repeat = argc > 5 ? atoi(argv[5]) : 3;
    if (argc > 4 && sscanf(argv[4], "%" SCNu32 "x%" SCNu32, &width, &height) != 2) {
        fprintf(stderr, "bench_seed: '%s' is not WxH\n", argv[4]);
        return 2;
    }
    ip_error err;
    ip_store *store;
    ip_cache *cache;
    if (ip_store_open(argv[1], &store, &err) != IP_OK ||
        ip_cache_create(store, ip_cache_default_budget(), &cache, &err) != IP_OK) {
        fprintf(stderr, "bench_seed: %s\n", err.message);
        return 1;
    }
    double lo[3], hi[3];
    ip_camera camera;
    ip_camera_basis basis;
    ip_layout_world_box(ip_store_layout(store), lo, hi);
    if (ip_camera_fit_axis(lo, hi, argv[3], 30.0, width, height, &camera, &err) != IP_OK) {
        fprintf(stderr, "bench_seed: %s\n", err.message);
        return 1;
    }
    ip_camera_basis_of(&camera, &basis);
    ip_sampler sampler;
    ip_seeder seeder;
    if (ip__sampler_init(&sampler, cache, 0) != IP_OK)
        return 1;
    ip__seeder_init(&seeder, &sampler, strtof(argv[2], NULL),
                    2.0 * basis.tan_half_y / camera.height);
    pass p[2], best[2] = {{INFINITY, 0, 0, 0, 0}, {INFINITY, 0, 0, 0, 0}};
    if (!cast_all(&seeder, &camera, &basis, &p[0])) /* decodes the bricks, untimed */
        return 1;
    for (int i = 0; i < repeat; i++)
        for (int groups = 0; groups < 2; groups++) {
            seeder.use_group_ranges = groups;
            if (!cast_all(&seeder, &camera, &basis, &p[groups])) {
                fprintf(stderr, "bench_seed: %s\n", sampler.error.message);
                return 1;
            }
            if (p[groups].seconds < best[groups].seconds)
                best[groups] = p[groups];
        }
    ip_cache_stats cs;
    ip_cache_get_stats(cache, &cs);
    printf("cache: %" PRIu64 " bricks decoded in %.3f s (%.1f us each), %.1f MiB resident\n",
           cs.misses, cs.decode_seconds, 1e6 * cs.decode_seconds / (double)cs.misses,
           (double)cs.resident_bytes / (1 << 20));
    double rays = (double)width * height;
    for (int groups = 0; groups < 2; groups++)
        printf("%-16s %8.3f s (best of %d)  %7.2f cells read/ray  %6.3f tested/ray  %" PRIu64
               " seeds\n",
               groups ? "group ranges" : "no group ranges", best[groups].seconds, repeat,
               (double)best[groups].cells_read / rays, (double)best[groups].cells_tested / rays,
               best[groups].seeds);
    int same = best[0].digest == best[1].digest && best[0].seeds == best[1].seeds &&
               best[0].cells_tested == best[1].cells_tested;
    printf("%s (digest %016" PRIx64 ")\n", same ? "same cells found" : "DIFFERENT cells found",
           best[1].digest);
    ip__sampler_free(&sampler);
    ip_cache_destroy(cache);
    ip_store_close(store);
    return same ? 0 : 1;
}

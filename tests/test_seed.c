/* Ray seeding: passing over the cells of inactive cell groups (the cache's group ranges)
 * changes nothing a ray finds, ray by ray, and reads the corners of fewer cells. Counts, no
 * clock. */
#include <math.h>

#include "check.h"
#include "isoprop/camera.h"
#include "seed.h"
#include "volumes.h"

/* The Shepp-Logan phantom (int16, with noise) bricked with B = 16, S = 8 into dir. */
static void brick_phantom(const char *dir, char *ibv, size_t size)
{
    ip_gen_params params = {IP_FIELD_SHEPP_LOGAN, {67, 58, 49}, IP_INT16, 0.01, 7};
    char raw[4400];
    test_generate_raw(dir, "phantom", &params, raw, sizeof raw);
    snprintf(ibv, size, "%s/phantom.ibv", dir);
    test_brick_raw(raw, ibv, 16, 8);
}

/* Casts every pixel's ray through level 0 twice, without the group ranges and with them,
 * and compares what each ray finds. */
static void check_view(ip_cache *cache, const char *axis, float iso)
{
    const ip_layout *l = ip_store_layout(ip_cache_store(cache));
    double lo[3], hi[3];
    ip_camera camera;
    ip_camera_basis basis;
    ip_error err;
    ip_layout_world_box(l, lo, hi);
    REQUIRE(ip_camera_fit_axis(lo, hi, axis, 30.0, 160, 120, &camera, &err) == IP_OK);
    ip_camera_basis_of(&camera, &basis);
    ip_sampler sampler;
    ip_seeder plain, grouped;
    REQUIRE(ip__sampler_init(&sampler, cache, 0) == IP_OK);
    double pixel_angle = 2.0 * basis.tan_half_y / camera.height;
    ip__seeder_init(&plain, &sampler, iso, pixel_angle);
    ip__seeder_init(&grouped, &sampler, iso, pixel_angle);
    CHECK(grouped.use_group_ranges == 1); /* the default */
    plain.use_group_ranges = 0;
    uint64_t rays = 0, differ = 0, seeds = 0;
    for (uint32_t y = 0; y < camera.height; y++)
        for (uint32_t x = 0; x < camera.width; x++) {
            double dir[3];
            uint32_t a[IP_SEED_MAX_CELLS][3], b[IP_SEED_MAX_CELLS][3];
            unsigned na, nb;
            int sa, sb;
            ip_camera_pixel_ray(&basis, &camera, x + 0.5, y + 0.5, dir);
            int fa = ip__seed_find(&plain, camera.eye, dir, 0, INFINITY, a, &na, &sa);
            int fb = ip__seed_find(&grouped, camera.eye, dir, 0, INFINITY, b, &nb, &sb);
            REQUIRE(fa >= 0 && fb >= 0);
            differ += fa != fb || na != nb || sa != sb || memcmp(a, b, na * sizeof a[0]) != 0;
            seeds += fa == 1;
            rays++;
        }
    CHECK_MSG(differ == 0, "view %s, iso %g: %llu of %llu rays found other cells", axis,
              (double)iso, (unsigned long long)differ, (unsigned long long)rays);
    CHECK_MSG(seeds > rays / 20, "view %s, iso %g: only %llu seeds", axis, (double)iso,
              (unsigned long long)seeds);
    /* the same cells reach the triangle test; far fewer have their corners read (groups of
     * 4^3 cells on this noisy phantom: about half) */
    CHECK(grouped.cells_tested == plain.cells_tested && plain.cells_tested > 0);
    CHECK(plain.cells_read >= plain.cells_tested);
    CHECK_MSG(grouped.cells_read * 3 < plain.cells_read * 2,
              "view %s, iso %g: %llu cells read with the group ranges, %llu without", axis,
              (double)iso, (unsigned long long)grouped.cells_read,
              (unsigned long long)plain.cells_read);
    ip__sampler_free(&sampler);
}

int main(void)
{
    const char *dir = test_tmp_dir("test_seed");
    char ibv[4400];
    brick_phantom(dir, ibv, sizeof ibv);
    ip_store *store;
    ip_cache *cache;
    ip_error err;
    REQUIRE(ip_store_open(ibv, &store, &err) == IP_OK);
    REQUIRE(ip_cache_create(store, 64u << 20, &cache, &err) == IP_OK);
    /* the skull (value 1: 3071 as int16) and the brain (0.2: -205) */
    check_view(cache, "-y", 1000.5f);
    check_view(cache, "+x", -300.5f);
    check_view(cache, "-z", -300.5f);
    ip_cache_destroy(cache);
    ip_store_close(store);
    return test_summary("test_seed");
}

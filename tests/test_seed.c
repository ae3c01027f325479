/* SPDX-License-Identifier: BSD-3-Clause */
/* Ray seeding: passing over the cells of inactive cell groups (the cache's group ranges)
 * changes nothing a ray finds, ray by ray, and reads the corners of fewer cells. Counts, no
 * clock. */
#include <math.h>

#include "beam.h"
#include "check.h"
#include "isoprop/camera.h"
#include "lod.h"
#include "mc.h"
#include "seed.h"
#include "volumes.h"

/* The Shepp-Logan phantom (int16, with noise) bricked with B = 16, S = 8 into dir. */
static void brick_phantom(const char *dir, char *ibv, size_t size)
{
    ip_gen_params params = {
        sizeof(ip_gen_params), IP_FIELD_SHEPP_LOGAN, {67, 58, 49}, IP_INT16, 0.01, 7};
    char raw[4400];
    test_generate_raw(dir, "phantom", &params, raw, sizeof raw);
    snprintf(ibv, size, "%s/phantom.ibv", dir);
    test_brick_raw(raw, ibv, 16, 8);
}

/* A 160x120 camera fitted to the volume along `axis`, and a sampler of its level 0. */
static void view_setup(ip_cache *cache, const char *axis, ip_camera *camera, ip_camera_basis *basis,
                       ip_sampler *sampler)
{
    const ip_layout *l = ip_store_layout(ip_cache_store(cache));
    double lo[3], hi[3];
    ip_error err;
    ip_layout_world_box(l, lo, hi);
    REQUIRE(ip_camera_fit_axis(lo, hi, axis, 30.0, 160, 120, camera, &err) == IP_OK);
    ip_camera_basis_of(camera, basis);
    REQUIRE(ip__sampler_init(sampler, cache, 0) == IP_OK);
}

static int cell_order(const void *a, const void *b)
{
    return memcmp(a, b, 3 * sizeof(uint32_t));
}

/* 1 when two walks of a ray found the same: the same result and seed cell, and the same cells.
 * Down the octree and over the bricks, the cells a ray passes close by (near_cells() in seed.c)
 * come at other places in the list: the lists are compared as sets. */
static int same_finds(int fa, unsigned na, int sa, uint32_t a[][3], int fb, unsigned nb, int sb,
                      uint32_t b[][3])
{
    if (fa != fb || na != nb || (sa < 0) != (sb < 0) ||
        (sa >= 0 && memcmp(a[sa], b[sb], sizeof a[0]) != 0))
        return 0;
    qsort(a, na, sizeof a[0], cell_order);
    qsort(b, nb, sizeof b[0], cell_order);
    return memcmp(a, b, na * sizeof a[0]) == 0;
}

/* Casts every pixel's ray through level 0 three times: without the group ranges, with them
 * (the default), and down the octree instead of over the bricks by a DDA (short_walk 0); what
 * each ray finds must not change. */
static void check_view(ip_cache *cache, const char *axis, float iso)
{
    ip_camera camera;
    ip_camera_basis basis;
    ip_sampler sampler;
    view_setup(cache, axis, &camera, &basis, &sampler);
    ip_seeder plain, grouped, octree;
    double pixel_angle = 2.0 * basis.tan_half_y / camera.height;
    ip__seeder_init(&plain, &sampler, iso, pixel_angle);
    ip__seeder_init(&grouped, &sampler, iso, pixel_angle);
    ip__seeder_init(&octree, &sampler, iso, pixel_angle);
    CHECK_EQ(grouped.use_group_ranges, 1); /* the default */
    plain.use_group_ranges = 0;
    octree.short_walk = 0; /* down the octree, where the others walk the bricks by a DDA */
    uint64_t walks_differ = 0;
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
            uint32_t c[IP_SEED_MAX_CELLS][3];
            unsigned nc;
            int sc, fc = ip__seed_find(&octree, camera.eye, dir, 0, INFINITY, c, &nc, &sc);
            differ += fa != fb || na != nb || sa != sb || memcmp(a, b, na * sizeof a[0]) != 0;
            walks_differ += !same_finds(fc, nc, sc, c, fb, nb, sb, b);
            seeds += fa == 1;
            rays++;
        }
    CHECK_MSG(differ == 0, "view %s, iso %g: %llu of %llu rays found other cells", axis,
              (double)iso, (unsigned long long)differ, (unsigned long long)rays);
    CHECK_MSG(walks_differ == 0 && octree.nodes > grouped.nodes,
              "view %s, iso %g: %llu of %llu rays found other cells down the octree (%llu "
              "nodes, %llu by the bricks)",
              axis, (double)iso, (unsigned long long)walks_differ, (unsigned long long)rays,
              (unsigned long long)octree.nodes, (unsigned long long)grouped.nodes);
    CHECK_MSG(seeds > rays / 20, "view %s, iso %g: only %llu seeds", axis, (double)iso,
              (unsigned long long)seeds);
    /* the same cells reach the triangle test; far fewer have their corners read (groups of
     * 4^3 cells on this noisy phantom: about half) */
    CHECK_EQ(grouped.cells_tested, plain.cells_tested);
    CHECK_GT(plain.cells_tested, 0);
    CHECK_GE(plain.cells_read, plain.cells_tested);
    CHECK_MSG(grouped.cells_read * 3 < plain.cells_read * 2,
              "view %s, iso %g: %llu cells read with the group ranges, %llu without", axis,
              (double)iso, (unsigned long long)grouped.cells_read,
              (unsigned long long)plain.cells_read);
    ip__sampler_free(&sampler);
}

/* 1 when cell c of level 0 is active for iso (a marching-cubes case other than 0 and 255). */
static int cell_active(ip_sampler *sampler, float iso, const uint32_t c[3])
{
    float values[8];
    unsigned mc;
    REQUIRE(ip__sampler_cell_case(sampler, c, iso, values, &mc) == 1);
    return mc != 0 && mc != 255;
}

/* Marks in v every active cell of level 0 whose hash is below `share` of 256: the same cells
 * every time, and more as `share` grows. */
static void mark_active(ip_visited *v, ip_sampler *sampler, const ip_layout *l, float iso,
                        unsigned share)
{
    const uint32_t *d = l->levels[0].dims;
    for (uint32_t z = 0; z + 1 < d[2]; z++)
        for (uint32_t y = 0; y + 1 < d[1]; y++)
            for (uint32_t x = 0; x + 1 < d[0]; x++) {
                uint32_t c[3] = {x, y, z};
                if ((x * 73856093u ^ y * 19349663u ^ z * 83492791u) % 256 < share &&
                    cell_active(sampler, iso, c))
                    REQUIRE(ip__visited_mark(v, 0, c) >= 0);
            }
}

/* The depth short of which `beam` is settled, found the slow way: the least nearest depth
 * (world units) of the active cells of level 0 not marked in v, whose centre lies in the
 * distance band [near, far) from the eye (lod.h) and whose box is not wholly outside one of the
 * beam's planes (cells [i, i+1] x ... scaled by the spacing); +infinity when there is none. */
static double settled_depth(const ip_beam *beam, const ip_visited *v, ip_sampler *sampler,
                            const ip_layout *l, float iso, double near_d, double far_d)
{
    const uint32_t *d = l->levels[0].dims;
    double least = INFINITY;
    for (uint32_t z = 0; z + 1 < d[2]; z++)
        for (uint32_t y = 0; y + 1 < d[1]; y++)
            for (uint32_t x = 0; x + 1 < d[0]; x++) {
                uint32_t c[3] = {x, y, z};
                double lo[3], hi[3], near = 0;
                for (int a = 0; a < 3; a++) {
                    lo[a] = c[a] * l->spacing[a] - beam->eye[a];
                    hi[a] = (c[a] + 1.0) * l->spacing[a] - beam->eye[a];
                    near += beam->forward[a] * (beam->forward[a] >= 0 ? lo[a] : hi[a]);
                }
                int out = near >= least;
                for (int p = 0; p < 4 && !out; p++) {
                    const double *n = beam->normal[p];
                    out = n[0] * (n[0] >= 0 ? hi[0] : lo[0]) + n[1] * (n[1] >= 0 ? hi[1] : lo[1]) +
                              n[2] * (n[2] >= 0 ? hi[2] : lo[2]) <
                          0;
                }
                if (!out && !ip__visited_test(v, 0, c) && cell_active(sampler, iso, c) &&
                    ip__lod_in_band(ip__lod_cell_distance(sampler, c, beam->eye), near_d, far_d))
                    least = near;
            }
    return least;
}

/* Beams of 8x8-pixel tiles, 3 pixels apart: as the visited cells grow, the answers of one
 * visited set that keeps the sub-blocks and cell groups the tests found settled
 * (ip__visited_mark_part()) are those of a set built afresh with the same cells and no such
 * record, and some are recorded. Where a beam is not settled, the depth it is settled short
 * of is the nearest depth of the nearest cell that may spoil it (checked on every 4th tile
 * against settled_depth()), and a beam whose min_depth skips what lies nearer than that gives
 * the same depth. With `band` 1 or 2 the seeder keeps only the cells whose centres lie farther
 * (1) or nearer (2) than the volume's centre (ip__seeder_band(), as adaptive resolution does):
 * the cells outside the band are never the view's, and do not spoil a beam. */
static void check_beams(ip_cache *cache, const char *axis, float iso, int band)
{
    const ip_layout *l = ip_store_layout(ip_cache_store(cache));
    ip_camera camera;
    ip_camera_basis basis;
    ip_sampler sampler;
    view_setup(cache, axis, &camera, &basis, &sampler);
    ip_seeder seeder;
    ip__seeder_init(&seeder, &sampler, iso, 2.0 * basis.tan_half_y / camera.height);
    double middle = 0.0;
    for (int a = 0; a < 3; a++) {
        double m = 0.5 * (l->levels[0].dims[a] - 1.0) * l->spacing[a] - camera.eye[a];
        middle += m * m;
    }
    middle = sqrt(middle);
    if (band)
        ip__seeder_band(&seeder, band == 1 ? middle : 0.0, band == 1 ? INFINITY : middle);
    double near_d = seeder.band_near, far_d = seeder.band_far;
    ip_visited kept, fresh;
    REQUIRE(ip__visited_init(&kept, l) == IP_OK);
    REQUIRE(ip__visited_init(&fresh, l) == IP_OK);
    uint64_t tests = 0, differ = 0, settled = 0, parts = 0, deep = 0, wrong = 0, floored = 0;
    static const unsigned shares[] = {0, 64, 160, 240, 256};
    for (size_t p = 0; p < sizeof shares / sizeof shares[0]; p++) {
        mark_active(&kept, &sampler, l, iso, shares[p]);
        ip__visited_clear(&fresh);
        mark_active(&fresh, &sampler, l, iso, shares[p]);
        for (uint32_t ty = 0; ty < camera.height; ty += 3) /* tiles that overlap */
            for (uint32_t tx = 0; tx < camera.width; tx += 3) {
                double corner[4][3];
                double cx[4] = {tx, tx + 8.0, tx + 8.0, tx}, cy[4] = {ty, ty, ty + 8.0, ty + 8.0};
                for (int i = 0; i < 4; i++)
                    ip_camera_pixel_ray(&basis, &camera, cx[i], cy[i], corner[i]);
                ip_beam beam;
                ip__beam_init(&beam, camera.eye, basis.forward, corner, INFINITY);
                double ta, tb;
                int a = ip__beam_settled(&seeder, &kept, &beam, &ta);
                int b = ip__beam_settled(&seeder, &fresh, &beam, &tb);
                differ += a != b || ta != tb;
                settled += a;
                tests++;
                if (a || (tx + ty) % 4 != 0)
                    continue;
                double want = settled_depth(&beam, &fresh, &sampler, l, iso, near_d, far_d);
                wrong += !(fabs(ta - want) <= 1e-9 * want);
                deep++;
                /* what lies wholly nearer than that depth less two cells is settled:
                 * passing over it changes nothing */
                beam.min_depth = ta - 2 * fmax(l->spacing[0], fmax(l->spacing[1], l->spacing[2]));
                double tc;
                floored += ip__beam_settled(&seeder, &fresh, &beam, &tc) != 0 || tc != ta;
            }
    }
    /* the records the kept set holds: bits past the cells' of its bitmaps */
    for (uint64_t g = 0; g < l->brick_count; g++) {
        const atomic_uint_fast64_t *m = ip__visited_bitmap(&kept, g);
        for (uint64_t part = 0; m && part < kept.subblocks_per_brick + 64; part++)
            parts += ip__visited_part_in(&kept, m, part);
    }
    CHECK_MSG(differ == 0 && settled > tests / 4 && settled < tests && parts > 0,
              "view %s, iso %g, band %d: %llu of %llu beam tests differ, %llu settled, %llu "
              "parts recorded",
              axis, (double)iso, band, (unsigned long long)differ, (unsigned long long)tests,
              (unsigned long long)settled, (unsigned long long)parts);
    CHECK_MSG(wrong == 0 && floored == 0 && deep > 100,
              "view %s, iso %g, band %d: of %llu beams not settled, %llu gave the wrong depth, "
              "%llu another with min_depth",
              axis, (double)iso, band, (unsigned long long)deep, (unsigned long long)wrong,
              (unsigned long long)floored);
    ip__visited_free(&kept);
    ip__visited_free(&fresh);
    ip__sampler_free(&sampler);
}

/* A ray that runs beside a cell without entering it, within the ray's reach of one of the
 * cell's triangles (IP_SEED_REACH_PIXELS): the cell must be among the cells the ray finds, as a
 * near miss (a rasteriser's snapping may show that triangle at the pixel), down the octree and
 * over the bricks alike; with no reach, it is not. For each of the first cells found whose edge
 * along z at their high x and y is crossed, the ray runs along z, parallel to that edge, half
 * the reach outside it diagonally, from half a cell before the cell. */
static void check_near_passes(ip_cache *cache, float iso)
{
    const ip_layout *l = ip_store_layout(ip_cache_store(cache));
    const uint32_t *d = l->levels[0].dims;
    ip_sampler sampler;
    REQUIRE(ip__sampler_init(&sampler, cache, 0) == IP_OK);
    int edge = -1; /* the edge along z joining corners 3 (x1, y1, z0) and 7 (x1, y1, z1) */
    for (int e = 0; e < 12; e++)
        if (ip__mc_edge_corners[e][0] == 3 && ip__mc_edge_corners[e][1] == 7)
            edge = e;
    REQUIRE(edge >= 0);
    const double pixel_angle = 0.01, eye_distance = 50.0;
    unsigned cases = 0, found_near = 0, found_without = 0;
    for (uint32_t z = 2; z + 3 < d[2] && cases < 40; z += 3)
        for (uint32_t y = 2; y + 3 < d[1] && cases < 40; y++)
            for (uint32_t x = 2; x + 3 < d[0] && cases < 40; x++) {
                uint32_t c[3] = {x, y, z};
                float values[8], lo[3], hi[3], points[12][3];
                unsigned mc;
                REQUIRE(ip__sampler_cell_case(&sampler, c, iso, values, &mc) == 1);
                if (!(ip__mc_edge_table[mc] >> edge & 1u))
                    continue;
                ip__sampler_cell_box(&sampler, c, lo, hi);
                ip__mc_cell_edge_points(values, mc, iso, lo, hi, points);
                /* the reach there: thick x (eye distance to where the ray leaves the volume
                 * plus a cell), as ip__seed_find() works it out */
                double far = eye_distance + (double)(d[2] - 1 - z) + 1.5;
                double reach = IP_SEED_REACH_PIXELS * pixel_angle * far, off = 0.5 * reach;
                double eye[3] = {points[edge][0] + off, points[edge][1] + off,
                                 lo[2] - eye_distance};
                const double dir[3] = {0, 0, 1};
                double t_min = eye_distance - 0.5;
                cases++;
                for (int way = 0; way < 3; way++) { /* bricks, octree, bricks without reach */
                    ip_seeder s;
                    ip__seeder_init(&s, &sampler, iso, pixel_angle);
                    s.short_walk = way == 1 ? 0.0 : s.short_walk;
                    s.thick = way == 2 ? 0.0 : s.thick;
                    uint32_t cells[IP_SEED_MAX_CELLS][3];
                    unsigned count;
                    int seed;
                    REQUIRE(ip__seed_find(&s, eye, dir, t_min, INFINITY, cells, &count, &seed) >=
                            0);
                    int has = 0;
                    for (unsigned i = 0; i < count; i++)
                        has |= memcmp(cells[i], c, sizeof c) == 0;
                    CHECK_MSG(seed < 0 || memcmp(cells[seed], c, sizeof c) != 0,
                              "cell %u %u %u: a ray beside it took it as its seed", x, y, z);
                    if (way < 2)
                        found_near += (unsigned)has;
                    else
                        found_without += (unsigned)has;
                }
            }
    CHECK_MSG(cases >= 10, "only %u cells with the edge crossed", cases);
    CHECK_MSG(found_near == 2 * cases, "%u of %u rays beside a cell found it", found_near,
              2 * cases);
    CHECK_MSG(found_without == 0, "%u rays found a cell they only pass beside with no reach",
              found_without);
    printf("test_seed: near passes: %u cells, each found by the rays beside them\n", cases);
    ip__sampler_free(&sampler);
}

/* What the cases share: the phantom's store and a cache on it, warm from the cases before. */
static ip_store *the_store;
static ip_cache *the_cache;

/* the skull (value 1: 3071 as int16) and the brain (0.2: -205) */
static void views(void)
{
    check_view(the_cache, "-y", 1000.5f);
    check_view(the_cache, "+x", -300.5f);
    check_view(the_cache, "-z", -300.5f);
}
/* check_beams() holds the beams' answers to a brute force over every cell, while a beam looks
 * only at the bricks already loaded (beam.c, settled_cells()): every brick of level 0 is loaded
 * first, whatever ran before. */
static void load_level_0(void)
{
    const ip_layout *l = ip_store_layout(the_store);
    for (uint64_t g = l->levels[0].first_brick;
         g < l->levels[0].first_brick + l->levels[0].brick_count; g++) {
        ip_brick b;
        ip_error err;
        REQUIRE(ip_cache_pin_brick(the_cache, g, &b, &err) == IP_OK);
        ip_cache_unpin_brick(the_cache, &b);
    }
}

static void beams(void)
{
    load_level_0();
    check_beams(the_cache, "-y", 1000.5f, 0);
    check_beams(the_cache, "+x", -300.5f, 0);
    check_beams(the_cache, "-y", 1000.5f, 1);
    check_beams(the_cache, "+x", -300.5f, 2);
}
static void near_passes(void)
{
    check_near_passes(the_cache, 1000.5f);
    check_near_passes(the_cache, -300.5f);
}

static const test_case cases[] = {
    {"check_view", views},
    {"check_beams", beams},
    {"check_near_passes", near_passes},
};

static void open_cache(void)
{
    const char *dir = test_tmp_dir("test_seed");
    char ibv[4400];
    brick_phantom(dir, ibv, sizeof ibv);
    ip_error err;
    REQUIRE(ip_store_open(ibv, &the_store, &err) == IP_OK);
    REQUIRE(ip_cache_create(the_store, 64u << 20, &the_cache, &err) == IP_OK);
}

static void close_cache(void)
{
    ip_cache_destroy(the_cache);
    ip_store_close(the_store);
}

int main(int argc, char **argv)
{
    return RUN_CASES_WITH(argc, argv, cases, "test_seed", open_cache, close_cache);
}

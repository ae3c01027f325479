/* SPDX-License-Identifier: BSD-3-Clause */
/* Tests of the software rasterizer (coverage, fill rule, depth, clipping, shading) and PNGs. */
#include <math.h>
#include <png.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "check.h"
#include "isoprop/render.h"

enum {
    W = 64,
    H = 48
};

static const double box_lo[3] = {-20, -20, -20}, box_hi[3] = {20, 20, 5};

/* Looks down -z from z = 10: depth 10 is the plane z = 0. */
static ip_camera front_camera(uint32_t width, uint32_t height)
{
    ip_camera c = {.eye = {0, 0, 10},
                   .target = {0, 0, 0},
                   .up = {0, 1, 0},
                   .fov_y = 60,
                   .width = width,
                   .height = height};
    return c;
}

/* The world point that projects to image point (px, py) at view depth `depth`. */
static void point_at(const ip_camera *c, double px, double py, double depth, float out[3])
{
    ip_camera_basis b;
    ip_camera_basis_of(c, &b);
    double nx = (2.0 * px / c->width - 1.0) * b.tan_half_x;
    double ny = (1.0 - 2.0 * py / c->height) * b.tan_half_y;
    for (int i = 0; i < 3; i++)
        out[i] = (float)(c->eye[i] + depth * (b.forward[i] + nx * b.right[i] + ny * b.up[i]));
}

/* Appends the triangle with image points (x, y) at depth `depth`; normals face the eye. */
static void add_screen_triangle(ip_mesh *m, const ip_camera *c, const double xy[6], double depth)
{
    float p[9], n[9];
    uint64_t cell = m->triangle_count;
    for (int k = 0; k < 3; k++) {
        point_at(c, xy[2 * k], xy[2 * k + 1], depth, p + 3 * k);
        n[3 * k] = 0, n[3 * k + 1] = 0, n[3 * k + 2] = 1;
    }
    REQUIRE(ip_mesh_append_float_normals(m, p, n, &cell, 1) == IP_OK);
}

/* Coverage of one triangle alone: 1 where covered. */
static void coverage_of(const ip_camera *c, const double xy[6], double depth, uint8_t *covered)
{
    ip_mesh m;
    ip_mesh_init(&m);
    add_screen_triangle(&m, c, xy, depth);
    uint32_t *index = malloc((size_t)c->width * c->height * sizeof *index);
    REQUIRE(index);
    REQUIRE(ip_raster_mesh(&m, c, box_lo, box_hi, index, NULL, NULL) == IP_OK);
    for (size_t i = 0; i < (size_t)c->width * c->height; i++)
        covered[i] = index[i] == 0;
    free(index);
    ip_mesh_free(&m);
}

static void test_single_triangle(void)
{
    ip_camera c = front_camera(W, H);
    /* vertices on pixel centres: the top and left edges pass through centres (included), the
     * hypotenuse too (a right edge: excluded) */
    const double orders[2][6] = {{2.5, 2.5, 10.5, 2.5, 2.5, 10.5},
                                 {2.5, 2.5, 2.5, 10.5, 10.5, 2.5}};
    for (int o = 0; o < 2; o++) {
        uint8_t covered[W * H];
        coverage_of(&c, orders[o], 10.0, covered);
        int wrong = 0, count = 0;
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                int expected = x >= 2 && y >= 2 && x + y <= 11;
                wrong += covered[y * W + x] != expected;
                count += covered[y * W + x];
            }
        CHECK_MSG(wrong == 0, "winding %d: %d pixels differ from the fill rule", o, wrong);
        CHECK_EQ(count, 36);
    }
}

/* Covers the triangles one at a time; counts pixels covered twice and fills the union. */
static int union_coverage(const ip_camera *c, const double (*tri)[6], int count, uint8_t *out)
{
    size_t pixels = (size_t)c->width * c->height;
    uint8_t *one = malloc(pixels);
    REQUIRE(one);
    memset(out, 0, pixels);
    int twice = 0;
    for (int t = 0; t < count; t++) {
        coverage_of(c, tri[t], 10.0, one);
        for (size_t i = 0; i < pixels; i++) {
            twice += one[i] && out[i];
            out[i] |= one[i];
        }
    }
    free(one);
    return twice;
}

static void test_shared_edges_square(void)
{
    ip_camera c = front_camera(W, H);
    const double split[2][6] = {{2.5, 2.5, 10.5, 2.5, 2.5, 10.5},
                                {10.5, 10.5, 2.5, 10.5, 10.5, 2.5}};
    uint8_t all[W * H];
    CHECK_EQ(union_coverage(&c, split, 2, all), 0);
    int wrong = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            wrong += all[y * W + x] != (x >= 2 && x <= 9 && y >= 2 && y <= 9);
    CHECK_MSG(wrong == 0, "%d pixels of the split square are wrong", wrong);
}

/* A convex polygon triangulated two ways (a fan from its centre, a fan from a corner) must
 * cover the same pixels, each once. Vertices on pixel centres put many centres on edges. */
static void check_polygon(const ip_camera *c, const double *xy, int n, double cx, double cy)
{
    double centre_fan[16][6], corner_fan[16][6];
    for (int i = 0; i < n; i++) {
        int j = (i + 1) % n;
        double t[6] = {cx, cy, xy[2 * i], xy[2 * i + 1], xy[2 * j], xy[2 * j + 1]};
        memcpy(centre_fan[i], t, sizeof t);
    }
    for (int i = 1; i + 1 < n; i++) {
        double t[6] = {xy[0], xy[1], xy[2 * i], xy[2 * i + 1], xy[2 * i + 2], xy[2 * i + 3]};
        memcpy(corner_fan[i - 1], t, sizeof t);
    }
    size_t pixels = (size_t)c->width * c->height;
    uint8_t *a = malloc(pixels), *b = malloc(pixels);
    REQUIRE(a && b);
    CHECK_EQ(union_coverage(c, (const double(*)[6])centre_fan, n, a), 0);
    CHECK_EQ(union_coverage(c, (const double(*)[6])corner_fan, n - 2, b), 0);
    CHECK_MEM_EQ(a, b, pixels);
    free(a);
    free(b);
}

static void test_shared_edges_polygons(void)
{
    ip_camera c = front_camera(W, H);
    srand(7);
    for (int trial = 0; trial < 40; trial++) {
        int n = 3 + rand() % 10;
        double xy[32], cx = 32, cy = 24, radius = 6 + rand() % 14;
        double phase = rand() / (double)RAND_MAX;
        int on_centres = trial % 2 == 0;
        for (int i = 0; i < n; i++) {
            double angle = 2 * M_PI * (i + phase) / n;
            double x = cx + radius * cos(angle), y = cy + radius * sin(angle);
            if (on_centres)
                x = floor(x) + 0.5, y = floor(y) + 0.5;
            xy[2 * i] = x;
            xy[2 * i + 1] = y;
        }
        check_polygon(&c, xy, n, on_centres ? 32.5 : cx, on_centres ? 24.5 : cy);
    }
}

static void test_depth(void)
{
    ip_camera c = front_camera(W, H);
    const double big[6] = {1, 1, 60, 1, 1, 45}, small[6] = {10, 10, 30, 10, 10, 30};
    uint32_t index[W * H];
    for (int order = 0; order < 2; order++) {
        ip_mesh m;
        ip_mesh_init(&m);
        add_screen_triangle(&m, &c, order ? small : big, order ? 8.0 : 10.0);
        add_screen_triangle(&m, &c, order ? big : small, order ? 10.0 : 8.0);
        REQUIRE(ip_raster_mesh(&m, &c, box_lo, box_hi, index, NULL, NULL) == IP_OK);
        uint32_t near_index = order ? 0 : 1;
        CHECK_EQ(index[15 * W + 15], near_index);    /* inside both: the nearer one */
        CHECK_EQ(index[5 * W + 40], 1 - near_index); /* the big one alone */
        CHECK_EQ(index[40 * W + 40], UINT32_MAX);
        ip_mesh_free(&m);
    }
    /* equal depth: the lower index wins */
    ip_mesh m;
    ip_mesh_init(&m);
    add_screen_triangle(&m, &c, small, 9.0);
    add_screen_triangle(&m, &c, small, 9.0);
    REQUIRE(ip_raster_mesh(&m, &c, box_lo, box_hi, index, NULL, NULL) == IP_OK);
    int second = 0, first = 0;
    for (int i = 0; i < W * H; i++) {
        second += index[i] == 1;
        first += index[i] == 0;
    }
    CHECK_GT(first, 100);
    CHECK_EQ(second, 0);
    ip_mesh_free(&m);
}

/* A part of the image (ip_raster_mesh_part()) is exactly that part of the whole image, with
 * 1 / depth of the surface each pixel shows; parts outside the image are refused. */
static void test_part(void)
{
    ip_camera c = front_camera(W, H);
    const double big[6] = {1, 1, 60, 1, 1, 45}, small[6] = {10, 10, 30, 10, 10, 30};
    ip_mesh m;
    ip_mesh_init(&m);
    add_screen_triangle(&m, &c, big, 10.0);
    add_screen_triangle(&m, &c, small, 8.0);
    uint8_t whole[W * H * 4], part[W * H * 4];
    uint32_t index[W * H];
    double depth[W * H];
    REQUIRE(ip_raster_mesh_shaded(&m, &c, NULL, box_lo, box_hi, index, whole, NULL) == IP_OK);
    const uint32_t parts[4][4] = {
        {0, 0, W, H}, {13, 7, 20, 15}, {W - 1, H - 1, 1, 1}, {30, 0, 34, H}};
    for (int p = 0; p < 4; p++) {
        const uint32_t x = parts[p][0], y = parts[p][1], w = parts[p][2], h = parts[p][3];
        REQUIRE(ip_raster_mesh_part(&m, &c, NULL, box_lo, box_hi, x, y, w, h, depth, part, NULL) ==
                IP_OK);
        size_t rows_wrong = 0, depth_wrong = 0;
        for (uint32_t j = 0; j < h; j++) {
            rows_wrong += memcmp(part + (size_t)j * w * 4, whole + ((size_t)(y + j) * W + x) * 4,
                                 (size_t)w * 4) != 0;
            for (uint32_t i = 0; i < w; i++) {
                uint32_t shown = index[(y + j) * W + x + i];
                double want = shown == UINT32_MAX ? 0 : shown == 0 ? 1 / 10.0 : 1 / 8.0;
                depth_wrong += fabs(depth[(size_t)j * w + i] - want) > 1e-6;
            }
        }
        CHECK_MSG(rows_wrong == 0 && depth_wrong == 0, "part %d: %zu rows, %zu depths differ", p,
                  rows_wrong, depth_wrong);
    }
    /* the depth alone, without an image */
    REQUIRE(ip_raster_mesh_part(&m, &c, NULL, box_lo, box_hi, 0, 0, W, H, depth, NULL, NULL) ==
            IP_OK);
    CHECK_NEAR(depth[15 * W + 15], 1 / 8.0, 1e-6);
    CHECK_EQ(depth[40 * W + 40], 0);
    ip_error err;
    const uint32_t bad[4][4] = {{0, 0, 0, H}, {0, 0, W, 0}, {1, 0, W, H}, {0, H, 1, 1}};
    for (int p = 0; p < 4; p++) {
        CHECK_EQ(ip_raster_mesh_part(&m, &c, NULL, box_lo, box_hi, bad[p][0], bad[p][1], bad[p][2],
                                     bad[p][3], depth, part, &err),
                 IP_ERR_ARGUMENT);
        CHECK_CONTAINS(err.message, "part");
    }
    ip_mesh_free(&m);
}

/* A cube [-1, 1]^3 with outward normals: 12 triangles, each face's normal in `face`. */
static void build_cube(ip_mesh *m, float face[12][3])
{
    static const int quads[6][4][3] = {{{1, -1, -1}, {1, 1, -1}, {1, 1, 1}, {1, -1, 1}},
                                       {{-1, -1, -1}, {-1, -1, 1}, {-1, 1, 1}, {-1, 1, -1}},
                                       {{-1, 1, -1}, {-1, 1, 1}, {1, 1, 1}, {1, 1, -1}},
                                       {{-1, -1, -1}, {1, -1, -1}, {1, -1, 1}, {-1, -1, 1}},
                                       {{-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}},
                                       {{-1, -1, -1}, {-1, 1, -1}, {1, 1, -1}, {1, -1, -1}}};
    static const float normals[6][3] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                        {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
    ip_mesh_init(m);
    for (int f = 0; f < 6; f++)
        for (int half = 0; half < 2; half++) {
            const int corner[3] = {0, half ? 2 : 1, half ? 3 : 2};
            float p[9], n[9];
            for (int k = 0; k < 3; k++)
                for (int i = 0; i < 3; i++) {
                    p[3 * k + i] = (float)quads[f][corner[k]][i];
                    n[3 * k + i] = normals[f][i];
                }
            uint64_t cell = (uint64_t)f;
            memcpy(face[2 * f + half], normals[f], sizeof normals[f]);
            REQUIRE(ip_mesh_append_float_normals(m, p, n, &cell, 1) == IP_OK);
        }
}

/* 1 when the ray from `o` along `d` meets the box [-1, 1]^3 in front of `o`. */
static int ray_hits_cube(const double o[3], const double d[3])
{
    double t0 = 0, t1 = INFINITY;
    for (int i = 0; i < 3; i++) {
        double a = (-1 - o[i]) / d[i], b = (1 - o[i]) / d[i];
        t0 = fmax(t0, fmin(a, b));
        t1 = fmin(t1, fmax(a, b));
    }
    return t0 <= t1;
}

static void test_cube(void)
{
    ip_camera c = {.eye = {3.1, 2.3, 4.7},
                   .target = {0, 0, 0},
                   .up = {0, 0, 1},
                   .fov_y = 40,
                   .width = 160,
                   .height = 120};
    const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
    ip_mesh m;
    float face[12][3];
    build_cube(&m, face);
    size_t pixels = (size_t)c.width * c.height;
    uint32_t *index = malloc(pixels * sizeof *index);
    uint8_t *rgba = malloc(pixels * 4);
    REQUIRE(index && rgba);
    REQUIRE(ip_raster_mesh(&m, &c, lo, hi, index, rgba, NULL) == IP_OK);
    ip_camera_basis basis;
    ip_camera_basis_of(&c, &basis);
    int covered = 0, back_faces = 0, ray_mismatch = 0;
    for (uint32_t y = 0; y < c.height; y++)
        for (uint32_t x = 0; x < c.width; x++) {
            uint32_t t = index[y * c.width + x];
            double ray[3];
            ip_camera_pixel_ray(&basis, &c, x + 0.5, y + 0.5, ray);
            ray_mismatch += ray_hits_cube(c.eye, ray) != (t != UINT32_MAX);
            if (t == UINT32_MAX)
                continue;
            covered++;
            const float *p = m.positions + 9 * t;
            double facing = 0;
            for (int i = 0; i < 3; i++)
                facing += face[t][i] * (c.eye[i] - p[i]);
            back_faces += facing <= 0;
        }
    CHECK_GT(covered, 1000);
    CHECK_MSG(back_faces == 0, "%d pixels show a back face", back_faces);
    CHECK_MSG(ray_mismatch <= covered / 200, "%d of %d pixels disagree with ray casting",
              ray_mismatch, covered);
    /* shading: background rows exact, surfaces between the darkest and the brightest colour */
    ip_shading s;
    ip_shading_default(&s);
    int out_of_range = 0, bad_background = 0;
    for (uint32_t y = 0; y < c.height; y++)
        for (uint32_t x = 0; x < c.width; x++) {
            const uint8_t *px = rgba + 4 * ((size_t)y * c.width + x);
            out_of_range += px[3] != 255;
            for (int i = 0; i < 3; i++) {
                if (index[y * c.width + x] == UINT32_MAX) {
                    double t = (y + 0.5) / c.height;
                    double top = s.background_top[i], bottom = s.background_bottom[i];
                    bad_background += px[i] != (int)lround((top + t * (bottom - top)) * 255);
                    continue;
                }
                double dark = 255 * s.surface[i] * s.ambient;
                double bright = 255 * (s.surface[i] * (s.ambient + s.diffuse) + s.specular);
                out_of_range += px[i] < floor(dark) || px[i] > ceil(fmin(bright, 255));
            }
        }
    CHECK_EQ(out_of_range, 0);
    CHECK_EQ(bad_background, 0);
    /* two-sided lighting: inward normals give the same image */
    uint8_t *flipped = malloc(pixels * 4);
    REQUIRE(flipped);
    for (uint64_t i = 0; i < 9 * m.triangle_count; i++)
        m.normals[i] = -m.normals[i];
    REQUIRE(ip_raster_mesh(&m, &c, lo, hi, NULL, flipped, NULL) == IP_OK);
    CHECK_MEM_EQ(rgba, flipped, pixels * 4);
    free(flipped);
    free(index);
    free(rgba);
    ip_mesh_free(&m);
}

static void test_head_on_shading(void)
{
    ip_camera c = front_camera(W, H);
    ip_mesh m;
    ip_mesh_init(&m);
    const double xy[6] = {20, 10, 44, 10, 32, 40};
    add_screen_triangle(&m, &c, xy, 10.0);
    uint8_t rgba[W * H * 4];
    REQUIRE(ip_raster_mesh(&m, &c, box_lo, box_hi, NULL, rgba, NULL) == IP_OK);
    ip_shading s;
    ip_shading_default(&s);
    const uint8_t *centre = rgba + 4 * (24 * W + 32);
    for (int i = 0; i < 3; i++) {
        double bright = fmin(1.0, s.surface[i] * (s.ambient + s.diffuse) + s.specular);
        CHECK_LE(abs(centre[i] - (int)lround(255 * bright)), 1);
    }
    ip_mesh_free(&m);
}

/* Renders `m` alone in colour `colour` (the other shading the default's). */
static void raster_alone(const ip_mesh *m, const ip_camera *c, const float colour[3], uint8_t *rgba)
{
    ip_shading s;
    ip_shading_default(&s);
    memcpy(s.surface, colour, sizeof s.surface);
    REQUIRE(ip_raster_mesh_shaded(m, c, &s, box_lo, box_hi, NULL, rgba, NULL) == IP_OK);
}

/* The largest channel difference between `out` and round(a * top + (1 - a) * under). */
static int blend_error(const uint8_t *out, const uint8_t *top, const uint8_t *under, double a)
{
    int worst = 0;
    for (int k = 0; k < 3; k++) {
        int d = abs(out[k] - (int)lround(a * top[k] + (1 - a) * under[k]));
        worst = d > worst ? d : worst;
    }
    return worst;
}

/* Several surfaces: opaque ones make one depth-tested scene; a translucent one shows its
 * nearest layer blended over the nearest opaque fragment when at least as near. */
static void test_surfaces(void)
{
    ip_camera c = front_camera(W, H);
    const double big[6] = {1, 1, 60, 1, 1, 45}, small[6] = {10, 10, 30, 10, 10, 30};
    const float red[3] = {0.9f, 0.2f, 0.1f}, blue[3] = {0.1f, 0.3f, 0.9f};
    ip_mesh near_small, far_big, near_big, far_small;
    ip_mesh_init(&near_small), ip_mesh_init(&far_big), ip_mesh_init(&near_big);
    ip_mesh_init(&far_small);
    add_screen_triangle(&near_small, &c, small, 8.0);
    add_screen_triangle(&far_big, &c, big, 10.0);
    add_screen_triangle(&near_big, &c, big, 8.0);
    add_screen_triangle(&far_small, &c, small, 10.0);
    uint8_t out[W * H * 4], a_img[W * H * 4], b_img[W * H * 4], bg[W * H * 4];
    const size_t inside = 4 * (15 * W + 15), big_only = 4 * (5 * W + 40), empty = 4 * (40 * W + 40);
    ip_mesh none;
    ip_mesh_init(&none);
    raster_alone(&none, &c, red, bg);
    /* a translucent red triangle in front of an opaque blue one */
    ip_surface two[2] = {{&near_small, {0.9f, 0.2f, 0.1f}, 0.4f},
                         {&far_big, {0.1f, 0.3f, 0.9f}, 1.0f}};
    raster_alone(&near_small, &c, red, a_img);
    raster_alone(&far_big, &c, blue, b_img);
    REQUIRE(ip_raster_surfaces(two, 2, &c, NULL, box_lo, box_hi, out, NULL) == IP_OK);
    CHECK_LE(blend_error(out + inside, a_img + inside, b_img + inside, 0.4), 1);
    CHECK_MEM_EQ(out + big_only, b_img + big_only, 4);
    CHECK_MEM_EQ(out + empty, bg + empty, 4);
    CHECK_EQ(out[inside + 3], 255);
    /* the order of the surfaces does not matter with one translucent surface */
    ip_surface swapped[2] = {two[1], two[0]};
    uint8_t other[W * H * 4];
    REQUIRE(ip_raster_surfaces(swapped, 2, &c, NULL, box_lo, box_hi, other, NULL) == IP_OK);
    CHECK_MEM_EQ(out, other, sizeof out);
    /* behind the opaque surface, a translucent one does not show */
    ip_surface hidden[2] = {{&far_small, {0.9f, 0.2f, 0.1f}, 0.4f},
                            {&near_big, {0.1f, 0.3f, 0.9f}, 1.0f}};
    raster_alone(&near_big, &c, blue, b_img);
    REQUIRE(ip_raster_surfaces(hidden, 2, &c, NULL, box_lo, box_hi, out, NULL) == IP_OK);
    CHECK_MEM_EQ(out, b_img, sizeof out);
    /* over the background alone */
    ip_surface alone = {&near_small, {0.9f, 0.2f, 0.1f}, 0.4f};
    REQUIRE(ip_raster_surfaces(&alone, 1, &c, NULL, box_lo, box_hi, out, NULL) == IP_OK);
    CHECK_LE(blend_error(out + inside, a_img + inside, bg + inside, 0.4), 1);
    CHECK_MEM_EQ(out + empty, bg + empty, 4);
    /* only the nearest layer of a translucent surface shows, whatever its triangles' order:
     * a second layer behind it changes nothing */
    ip_mesh layers[2];
    for (int order = 0; order < 2; order++) {
        ip_mesh_init(&layers[order]);
        add_screen_triangle(&layers[order], &c, small, order ? 9.0 : 8.0);
        add_screen_triangle(&layers[order], &c, small, order ? 8.0 : 9.0);
    }
    ip_surface l0 = {&layers[0], {0.9f, 0.2f, 0.1f}, 0.4f}, l1 = l0;
    l1.mesh = &layers[1];
    uint8_t first[W * H * 4];
    REQUIRE(ip_raster_surfaces(&l0, 1, &c, NULL, box_lo, box_hi, first, NULL) == IP_OK);
    REQUIRE(ip_raster_surfaces(&l1, 1, &c, NULL, box_lo, box_hi, other, NULL) == IP_OK);
    CHECK_MEM_EQ(first, other, sizeof out);
    REQUIRE(ip_raster_surfaces(&alone, 1, &c, NULL, box_lo, box_hi, out, NULL) == IP_OK);
    CHECK_MEM_EQ(first, out, sizeof out);
    /* opaque surfaces only: the concatenated mesh, each pixel in its surface's colour */
    ip_mesh both;
    ip_mesh_init(&both);
    REQUIRE(ip_mesh_append_mesh(&both, &far_big, 0, 1) == IP_OK);
    REQUIRE(ip_mesh_append_mesh(&both, &near_small, 0, 1) == IP_OK);
    uint32_t index[W * H];
    REQUIRE(ip_raster_mesh(&both, &c, box_lo, box_hi, index, NULL, NULL) == IP_OK);
    raster_alone(&far_big, &c, blue, b_img);
    ip_surface opaque[2] = {{&far_big, {0.1f, 0.3f, 0.9f}, 1.0f},
                            {&near_small, {0.9f, 0.2f, 0.1f}, 1.0f}};
    REQUIRE(ip_raster_surfaces(opaque, 2, &c, NULL, box_lo, box_hi, out, NULL) == IP_OK);
    size_t wrong = 0, shown[2] = {0, 0};
    for (size_t i = 0; i < W * H; i++) {
        const uint8_t *want = index[i] == UINT32_MAX ? bg : index[i] == 0 ? b_img : a_img;
        wrong += memcmp(out + 4 * i, want + 4 * i, 4) != 0;
        if (index[i] != UINT32_MAX)
            shown[index[i]]++;
    }
    CHECK_EQ(wrong, 0);
    CHECK_GT(shown[0], 100);
    CHECK_GT(shown[1], 100);
    /* bad surfaces */
    ip_error err;
    ip_surface bad = alone;
    CHECK_EQ(ip_raster_surfaces(&bad, 0, &c, NULL, box_lo, box_hi, out, &err), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_raster_surfaces(&bad, IP_MAX_SURFACES + 1, &c, NULL, box_lo, box_hi, out, &err),
             IP_ERR_ARGUMENT);
    const float opacities[3] = {0.0f, 1.5f, NAN};
    for (int i = 0; i < 3; i++) {
        bad.opacity = opacities[i];
        CHECK_EQ(ip_raster_surfaces(&bad, 1, &c, NULL, box_lo, box_hi, out, &err), IP_ERR_ARGUMENT);
        CHECK_CONTAINS(err.message, "opacity");
    }
    bad = alone;
    bad.colour[1] = -0.1f;
    CHECK_EQ(ip_surfaces_check(&bad, 1, &err), IP_ERR_ARGUMENT);
    bad = alone;
    bad.mesh = NULL;
    CHECK_EQ(ip_surfaces_check(&bad, 1, &err), IP_ERR_ARGUMENT);
    /* no image: an argument error, not a write through NULL */
    CHECK_EQ(ip_raster_surfaces(&alone, 1, &c, NULL, box_lo, box_hi, NULL, &err), IP_ERR_ARGUMENT);
    CHECK_CONTAINS(err.message, "no image");
    ip_mesh *meshes[] = {&near_small, &far_big,   &near_big, &far_small,
                         &layers[0],  &layers[1], &both};
    for (size_t i = 0; i < sizeof meshes / sizeof meshes[0]; i++)
        ip_mesh_free(meshes[i]);
}

/* A ground plane much larger than the view, reaching behind the eye: near-plane and
 * guard-band clipping must leave exactly the pixels whose rays meet it. */
static void test_clipping(void)
{
    ip_camera c = {.eye = {0, -5, 2},
                   .target = {0, 10, 0},
                   .up = {0, 0, 1},
                   .fov_y = 70,
                   .width = 120,
                   .height = 90};
    const double lo[3] = {-1000, -1000, -1}, hi[3] = {1000, 1000, 1};
    const float p[18] = {-1000, -1000, 0, 1000, -1000, 0, 1000,  1000, 0,
                         -1000, -1000, 0, 1000, 1000,  0, -1000, 1000, 0};
    const float n[18] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    const uint64_t cells[2] = {0, 1};
    ip_mesh m;
    ip_mesh_init(&m);
    REQUIRE(ip_mesh_append_float_normals(&m, p, n, cells, 2) == IP_OK);
    uint32_t index[120 * 90];
    REQUIRE(ip_raster_mesh(&m, &c, lo, hi, index, NULL, NULL) == IP_OK);
    ip_camera_basis b;
    ip_camera_basis_of(&c, &b);
    double near_plane, far_plane;
    ip_camera_depth_range(&c, lo, hi, &near_plane, &far_plane);
    int covered = 0, mismatch = 0;
    for (uint32_t y = 0; y < c.height; y++)
        for (uint32_t x = 0; x < c.width; x++) {
            double d[3];
            ip_camera_pixel_ray(&b, &c, x + 0.5, y + 0.5, d);
            double t = d[2] < 0 ? -c.eye[2] / d[2] : -1;
            double hx = c.eye[0] + t * d[0], hy = c.eye[1] + t * d[1];
            double depth = t * (d[0] * b.forward[0] + d[1] * b.forward[1] + d[2] * b.forward[2]);
            int hit = t > 0 && fabs(hx) <= 1000 && fabs(hy) <= 1000 && depth >= near_plane &&
                      depth <= far_plane;
            uint32_t i = index[y * c.width + x];
            covered += i != UINT32_MAX;
            mismatch += hit != (i != UINT32_MAX) || (i != UINT32_MAX && i > 1);
        }
    CHECK_GT(covered, 120 * 90 / 3);
    CHECK_MSG(mismatch <= covered / 200, "%d of %d pixels disagree with ray casting", mismatch,
              covered);
    /* a triangle wholly behind the eye covers nothing */
    ip_mesh_clear(&m);
    const float behind[9] = {-1, -20, 2, 1, -20, 2, 0, -20, 3};
    REQUIRE(ip_mesh_append_float_normals(&m, behind, n, cells, 1) == IP_OK);
    REQUIRE(ip_raster_mesh(&m, &c, lo, hi, index, NULL, NULL) == IP_OK);
    int any = 0;
    for (int i = 0; i < 120 * 90; i++)
        any += index[i] != UINT32_MAX;
    CHECK_EQ(any, 0);
    ip_mesh_free(&m);
}

static void test_bad_arguments(void)
{
    ip_mesh m;
    ip_mesh_init(&m);
    ip_camera c = front_camera(W, H);
    uint32_t index[W * H];
    ip_error err;
    c.fov_y = 0;
    CHECK_EQ(ip_raster_mesh(&m, &c, box_lo, box_hi, index, NULL, &err), IP_ERR_ARGUMENT);
    c = front_camera(70000, 2);
    CHECK_EQ(ip_raster_mesh(&m, &c, box_lo, box_hi, NULL, NULL, &err), IP_ERR_ARGUMENT);
    CHECK_CONTAINS(err.message, "larger");
    const double bad_hi[3] = {20, NAN, 5}, inverted_hi[3] = {-30, 20, 5};
    c = front_camera(W, H);
    CHECK_EQ(ip_raster_mesh(&m, &c, box_lo, bad_hi, index, NULL, &err), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_raster_mesh(&m, &c, box_lo, inverted_hi, index, NULL, &err), IP_ERR_ARGUMENT);
    CHECK_CONTAINS(err.message, "box");
    /* a triangle with a non-finite vertex is skipped, the others drawn */
    const double xy[6] = {2.5, 2.5, 30.5, 2.5, 2.5, 30.5};
    add_screen_triangle(&m, &c, xy, 10.0);
    add_screen_triangle(&m, &c, xy, 9.0);
    m.positions[4] = NAN;
    CHECK_EQ(ip_raster_mesh(&m, &c, box_lo, box_hi, index, NULL, &err), IP_OK);
    CHECK_EQ(index[5 * W + 5], 1);
    ip_mesh_clear(&m);
    /* an empty mesh: only background */
    c = front_camera(W, H);
    CHECK_EQ(ip_raster_mesh(&m, &c, box_lo, box_hi, index, NULL, &err), IP_OK);
    int any = 0;
    for (int i = 0; i < W * H; i++)
        any += index[i] != UINT32_MAX;
    CHECK_EQ(any, 0);
    ip_mesh_free(&m);
}

/* Reads a PNG back as RGBA with libpng; returns the pixels (malloc) and whether it had alpha. */
static uint8_t *read_png(const char *path, uint32_t *w, uint32_t *h, int *had_alpha)
{
    png_image image;
    memset(&image, 0, sizeof image);
    image.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&image, path))
        return NULL;
    *had_alpha = (image.format & PNG_FORMAT_FLAG_ALPHA) != 0;
    image.format = PNG_FORMAT_RGBA;
    uint8_t *pixels = malloc(PNG_IMAGE_SIZE(image));
    if (!pixels || !png_image_finish_read(&image, NULL, pixels, 0, NULL)) {
        free(pixels);
        png_image_free(&image);
        return NULL;
    }
    *w = image.width;
    *h = image.height;
    return pixels;
}

static void test_png(void)
{
    const char *dir = test_tmp_dir("test_raster");
    char path[4200];
    snprintf(path, sizeof path, "%s/image.png", dir);
    enum {
        PW = 37,
        PH = 23
    };
    uint8_t rgba[PW * PH * 4];
    srand(3);
    for (int opaque = 0; opaque < 2; opaque++) {
        for (int i = 0; i < PW * PH * 4; i++)
            rgba[i] = (uint8_t)(i % 4 == 3 && opaque ? 255 : rand() & 255);
        ip_error err;
        CHECK_EQ(ip_png_write(path, rgba, PW, PH, opaque, &err), IP_OK);
        uint32_t w = 0, h = 0;
        int had_alpha = -1;
        uint8_t *back = read_png(path, &w, &h, &had_alpha);
        CHECK_NE(back, NULL);
        if (back) {
            CHECK_EQ(w, PW);
            CHECK_EQ(h, PH);
            CHECK_EQ(had_alpha, !opaque);
            CHECK_MEM_EQ(back, rgba, sizeof rgba);
        }
        free(back);
    }
    /* an existing file is kept without force */
    struct stat before, after;
    REQUIRE(stat(path, &before) == 0);
    ip_error err;
    memset(rgba, 0, sizeof rgba);
    CHECK_EQ(ip_png_write(path, rgba, PW, PH, 0, &err), IP_ERR_EXISTS);
    CHECK_CONTAINS(err.message, "exists");
    REQUIRE(stat(path, &after) == 0);
    CHECK_EQ(before.st_size, after.st_size);
    CHECK_EQ(before.st_ino, after.st_ino);
    CHECK_EQ(ip_png_write(path, rgba, 0, PH, 1, &err), IP_ERR_ARGUMENT);
    snprintf(path, sizeof path, "%s/missing/image.png", dir);
    CHECK_EQ(ip_png_write(path, rgba, PW, PH, 0, &err), IP_ERR_IO);
    CHECK_NE(stat(path, &after), 0);
}

/* A mesh of `count` random triangles in front of the camera (some crossing the near plane and
 * the image's sides), with random normals: overlaps, ties and clipping for the canvas. */
static void random_mesh(ip_mesh *m, const ip_camera *c, uint64_t count, uint64_t seed)
{
    for (uint64_t i = 0; i < count; i++) {
        float p[9], n[9];
        double depth = 2.0 + (double)(test_xorshift(&seed) % 1600) / 100.0;
        double cx = (double)(test_xorshift(&seed) % (c->width + 20)) - 10;
        double cy = (double)(test_xorshift(&seed) % (c->height + 20)) - 10;
        for (int k = 0; k < 3; k++) {
            double dx = (double)(test_xorshift(&seed) % 2400) / 100.0 - 12;
            double dy = (double)(test_xorshift(&seed) % 2400) / 100.0 - 12;
            double dz = i % 7 == 0 ? (double)(test_xorshift(&seed) % 1000) / 100.0 - 9 : 0;
            point_at(c, cx + dx, cy + dy, depth + dz, p + 3 * k);
            for (int a = 0; a < 3; a++)
                n[3 * k + a] = (float)((double)(test_xorshift(&seed) % 2001) / 1000.0 - 1.0);
        }
        REQUIRE(ip_mesh_append_float_normals(m, p, n, NULL, 1) == IP_OK);
    }
}

/* The canvas: a mesh added in pieces gives ip_raster_mesh_shaded()'s image and triangle ids
 * exactly, at every piece, on one thread or several; each shading reports rows that hold
 * every pixel it changed. */
static void test_canvas(void)
{
    ip_shading shading;
    ip_shading_default(&shading);
    shading.surface[0] = 0.5f; /* not the default, to see that it is the one used */
    const uint32_t sizes[2][2] = {{W, H}, {53, 61}};
    const unsigned thread_counts[3] = {1, 2, 3};
    for (int z = 0; z < 2; z++) {
        ip_camera c = front_camera(sizes[z][0], sizes[z][1]);
        ip_mesh m;
        ip_mesh_init(&m);
        random_mesh(&m, &c, 700, 0x9e3779b97f4a7c15ull + (uint64_t)z);
        size_t pixels = (size_t)c.width * c.height;
        uint8_t *want = malloc(4 * pixels), *before = malloc(4 * pixels);
        uint32_t *want_index = malloc(pixels * sizeof *want_index);
        REQUIRE(want && before && want_index);
        for (int t = 0; t < 3; t++) {
            ip_canvas *canvas;
            ip_error err;
            REQUIRE(ip_canvas_create(thread_counts[t], &canvas, &err) == IP_OK);
            CHECK_EQ(ip_canvas_shade(canvas, NULL), NULL);
            CHECK_EQ(ip_canvas_add(canvas, &m, 0, &err), IP_ERR_ARGUMENT);
            REQUIRE(ip_canvas_begin(canvas, &c, &shading, box_lo, box_hi, &err) == IP_OK);
            const uint64_t cuts[] = {0, 1, 6, 69, 70, 400, 700};
            uint32_t rows[2];
            const uint8_t *got = ip_canvas_shade(canvas, rows);
            CHECK_EQ(rows[0], 0);
            CHECK_EQ(rows[1], c.height);
            for (size_t k = 1; k < sizeof cuts / sizeof cuts[0]; k++) {
                memcpy(before, got, 4 * pixels);
                ip_mesh part = m;
                part.triangle_count = cuts[k]; /* the mesh's first triangles */
                CHECK_EQ(ip_canvas_add(canvas, &part, cuts[k - 1] + 1, &err), IP_ERR_ARGUMENT);
                REQUIRE(ip_canvas_add(canvas, &part, cuts[k - 1], &err) == IP_OK);
                CHECK_EQ(ip_canvas_triangle_count(canvas), cuts[k]);
                got = ip_canvas_shade(canvas, rows);
                REQUIRE(ip_raster_mesh_shaded(&part, &c, &shading, box_lo, box_hi, want_index, want,
                                              &err) == IP_OK);
                CHECK_MSG(!memcmp(got, want, 4 * pixels), "%u threads, %llu triangles",
                          thread_counts[t], (unsigned long long)cuts[k]);
                CHECK_MEM_EQ(ip_canvas_triangle_index(canvas), want_index,
                             pixels * sizeof *want_index);
                size_t outside = 0;
                for (size_t p = 0; p < pixels; p++)
                    if (memcmp(got + 4 * p, before + 4 * p, 4) &&
                        (p / c.width < rows[0] || p / c.width >= rows[1]))
                        outside++;
                CHECK_MSG(outside == 0, "%zu changed pixels outside rows %u .. %u", outside,
                          rows[0], rows[1]);
            }
            ip_canvas_shade(canvas, rows); /* nothing changed since */
            CHECK_EQ(rows[0], 0);
            CHECK_EQ(rows[1], 0);
            CHECK_GE(ip_canvas_memory(canvas), pixels * 29);
            /* a new image of another size, default shading: buffers reused or grown */
            ip_camera small = front_camera(20, 10);
            REQUIRE(ip_canvas_begin(canvas, &small, NULL, box_lo, box_hi, &err) == IP_OK);
            REQUIRE(ip_canvas_add(canvas, &m, 0, &err) == IP_OK);
            uint8_t small_want[20 * 10 * 4];
            REQUIRE(ip_raster_mesh(&m, &small, box_lo, box_hi, NULL, small_want, &err) == IP_OK);
            CHECK_MEM_EQ(ip_canvas_shade(canvas, NULL), small_want, sizeof small_want);
            ip_camera bad = small;
            bad.fov_y = 0;
            CHECK_EQ(ip_canvas_begin(canvas, &bad, NULL, box_lo, box_hi, &err), IP_ERR_ARGUMENT);
            ip_canvas_destroy(canvas);
        }
        free(want);
        free(before);
        free(want_index);
        ip_mesh_free(&m);
    }
    ip_canvas_destroy(NULL);
}

static const test_case cases[] = {
    TEST_CASE(test_single_triangle),
    TEST_CASE(test_shared_edges_square),
    TEST_CASE(test_shared_edges_polygons),
    TEST_CASE(test_depth),
    TEST_CASE(test_part),
    TEST_CASE(test_cube),
    TEST_CASE(test_head_on_shading),
    TEST_CASE(test_surfaces),
    TEST_CASE(test_clipping),
    TEST_CASE(test_bad_arguments),
    TEST_CASE(test_png),
    TEST_CASE(test_canvas),
};

int main(int argc, char **argv)
{
    return RUN_CASES(argc, argv, cases, "test_raster");
}

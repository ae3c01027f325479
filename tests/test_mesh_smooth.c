/* SPDX-License-Identifier: BSD-3-Clause */
/* Taubin smoothing: on a sphere extracted fully from a binary volume (terraced), the radius varies
 * less afterwards and the sphere barely shrinks, while Laplacian smoothing (mu = 0) of as many
 * iterations shrinks it clearly; a plane stays flat and keeps its rim; counts and indices stay;
 * bad factors are refused. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "isoprop/bricker.h"
#include "isoprop/cache.h"
#include "isoprop/engine.h"
#include "isoprop/input.h"
#include "isoprop/store.h"

#define SPHERE_EDGE 40 /* samples along each axis, spacing 1: the centre is at 19.5 */
#define SPHERE_RADIUS 14.3
#define SMOOTH_ITERATIONS 10

/* The welded surface of a binary ball (255 within SPHERE_RADIUS of the centre, 0 outside:
 * the nearly binary data that terraces) at 127.5, extracted fully. */
static void sphere_mesh(ip_indexed_mesh *out)
{
    const char *dir = test_tmp_dir("test_mesh_smooth");
    char raw[4400], ibv[4400];
    snprintf(raw, sizeof raw, "%s/ball_%dx%dx%d_uint8.raw", dir, SPHERE_EDGE, SPHERE_EDGE,
             SPHERE_EDGE);
    snprintf(ibv, sizeof ibv, "%s/ball.ibv", dir);
    FILE *f = fopen(raw, "wb");
    REQUIRE(f);
    const double c = (SPHERE_EDGE - 1) / 2.0;
    for (int z = 0; z < SPHERE_EDGE; z++)
        for (int y = 0; y < SPHERE_EDGE; y++)
            for (int x = 0; x < SPHERE_EDGE; x++) {
                double r = sqrt((x - c) * (x - c) + (y - c) * (y - c) + (z - c) * (z - c));
                REQUIRE(fputc(r <= SPHERE_RADIUS ? 255 : 0, f) != EOF);
            }
    REQUIRE(fclose(f) == 0);
    ip_error err;
    ip_input_desc d;
    ip_bricker_options o;
    REQUIRE(ip_input_describe(raw, NULL, &d, &err) == IP_OK);
    ip_bricker_options_default(&o);
    o.brick_edge = 16;
    o.force = 1;
    o.threads = 2;
    REQUIRE(ip_bricker_run(&d, ibv, &o, NULL, &err) == IP_OK);
    ip_store *store;
    ip_cache *cache;
    REQUIRE(ip_store_open(ibv, &store, &err) == IP_OK);
    REQUIRE(ip_cache_create(store, 64ull << 20, &cache, &err) == IP_OK);
    ip_mesh soup;
    ip_mesh_init(&soup);
    REQUIRE(ip_extract_full(cache, 127.5f, 0, 2, &soup, NULL, &err) == IP_OK);
    REQUIRE(ip_mesh_weld(&soup, out) == IP_OK);
    ip_mesh_free(&soup);
    ip_cache_destroy(cache);
    ip_store_close(store);
}

/* The mean and the standard deviation of the vertices' distances to the centre. */
static void radius_stats(const ip_indexed_mesh *m, double *mean, double *deviation)
{
    const double c = (SPHERE_EDGE - 1) / 2.0;
    double sum = 0, sum2 = 0;
    for (uint64_t v = 0; v < m->vertex_count; v++) {
        const float *p = m->positions + 3 * v;
        double r =
            sqrt((p[0] - c) * (p[0] - c) + (p[1] - c) * (p[1] - c) + (p[2] - c) * (p[2] - c));
        sum += r;
        sum2 += r * r;
    }
    *mean = sum / (double)m->vertex_count;
    *deviation = sqrt(fmax(sum2 / (double)m->vertex_count - *mean * *mean, 0.0));
}

/* A copy of `m` (positions, normals and indices). */
static void copy_mesh(const ip_indexed_mesh *m, ip_indexed_mesh *out)
{
    *out = *m;
    out->positions = malloc(3 * m->vertex_count * sizeof(float));
    out->normals = malloc(3 * m->vertex_count * sizeof(int16_t));
    out->indices = malloc(3 * m->triangle_count * sizeof(uint32_t));
    REQUIRE(out->positions && out->normals && out->indices);
    memcpy(out->positions, m->positions, 3 * m->vertex_count * sizeof(float));
    memcpy(out->normals, m->normals, 3 * m->vertex_count * sizeof(int16_t));
    memcpy(out->indices, m->indices, 3 * m->triangle_count * sizeof(uint32_t));
}

/* Whether every vertex's normal is of unit length and points away from the centre. */
static int normals_outward(const ip_indexed_mesh *m)
{
    const double c = (SPHERE_EDGE - 1) / 2.0;
    for (uint64_t v = 0; v < m->vertex_count; v++) {
        double dot = 0, length = 0;
        for (int k = 0; k < 3; k++) {
            double n = ip_normal_unpack(m->normals[3 * v + (uint64_t)k]);
            dot += n * (m->positions[3 * v + (uint64_t)k] - c);
            length += n * n;
        }
        if (!(dot > 0) || fabs(length - 1) > 1e-3)
            return 0;
    }
    return 1;
}

static void test_sphere(void)
{
    ip_indexed_mesh original, taubin, laplace;
    sphere_mesh(&original);
    REQUIRE(original.vertex_count > 1000);
    copy_mesh(&original, &taubin);
    copy_mesh(&original, &laplace);
    ip_error err;
    REQUIRE(ip_indexed_mesh_smooth_taubin(&taubin, SMOOTH_ITERATIONS, IP_TAUBIN_LAMBDA,
                                          IP_TAUBIN_MU, &err) == IP_OK);
    REQUIRE(ip_indexed_mesh_smooth_taubin(&laplace, SMOOTH_ITERATIONS, IP_TAUBIN_LAMBDA, 0.0,
                                          &err) == IP_OK);
    double r0, d0, rt, dt, rl, dl;
    radius_stats(&original, &r0, &d0);
    radius_stats(&taubin, &rt, &dt);
    radius_stats(&laplace, &rl, &dl);
    printf("sphere, %llu vertices: radius %.4f (sd %.4f); Taubin %.4f (sd %.4f); "
           "Laplacian %.4f (sd %.4f)\n",
           (unsigned long long)original.vertex_count, r0, d0, rt, dt, rl, dl);
    CHECK_MSG(dt < 0.7 * d0, "Taubin: the radius's deviation %.4f, before %.4f", dt, d0);
    CHECK_MSG(fabs(rt - r0) < 0.01 * r0, "Taubin: the mean radius %.4f, before %.4f", rt, r0);
    CHECK_MSG(r0 - rl > 10 * fabs(r0 - rt) && r0 - rl > 0.005 * r0,
              "Laplacian smoothing shrinks the radius to %.4f, Taubin to %.4f, from %.4f", rl, rt,
              r0);
    CHECK_EQ(taubin.vertex_count, original.vertex_count);
    if (CHECK_EQ(taubin.triangle_count, original.triangle_count))
        CHECK_MEM_EQ(taubin.indices, original.indices, 3 * original.triangle_count * 4);
    CHECK_MSG(normals_outward(&taubin), "the smoothed normals are not outward unit vectors");
    ip_indexed_mesh_free(&original);
    ip_indexed_mesh_free(&taubin);
    ip_indexed_mesh_free(&laplace);
}

/* An n x n grid of vertices at height z, jittered in x and y, 2 triangles per square. */
static void plane_mesh(int n, float z, ip_indexed_mesh *m)
{
    ip_indexed_mesh_init(m);
    m->vertex_count = (uint64_t)n * (uint64_t)n;
    m->triangle_count = 2 * (uint64_t)(n - 1) * (uint64_t)(n - 1);
    m->positions = malloc(3 * m->vertex_count * sizeof(float));
    m->normals = calloc(3 * m->vertex_count, sizeof(int16_t));
    m->indices = malloc(3 * m->triangle_count * sizeof(uint32_t));
    REQUIRE(m->positions && m->normals && m->indices);
    uint64_t state = 12345;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            float *p = m->positions + 3 * (uint64_t)(j * n + i);
            int inside = i > 0 && j > 0 && i < n - 1 && j < n - 1;
            p[0] = (float)i + (inside ? (float)(test_xorshift(&state) % 1000) / 2500.0f : 0.0f);
            p[1] = (float)j + (inside ? (float)(test_xorshift(&state) % 1000) / 2500.0f : 0.0f);
            p[2] = z;
        }
    uint32_t *t = m->indices;
    for (int j = 0; j + 1 < n; j++)
        for (int i = 0; i + 1 < n; i++) {
            uint32_t a = (uint32_t)(j * n + i), b = a + 1, c = a + (uint32_t)n, d = c + 1;
            const uint32_t square[6] = {a, b, d, a, d, c};
            memcpy(t, square, sizeof square);
            t += 6;
        }
}

static void test_plane(void)
{
    const int n = 12;
    const float z = 2.7f;
    ip_indexed_mesh m, before;
    plane_mesh(n, z, &m);
    copy_mesh(&m, &before);
    ip_error err;
    REQUIRE(ip_indexed_mesh_smooth_taubin(&m, 20, IP_TAUBIN_LAMBDA, IP_TAUBIN_MU, &err) == IP_OK);
    int flat = 1, rim_kept = 1, moved = 0, up = 1;
    for (uint64_t v = 0; v < m.vertex_count; v++) {
        const float *p = m.positions + 3 * v, *q = before.positions + 3 * v;
        int i = (int)(v % (uint64_t)n), j = (int)(v / (uint64_t)n);
        flat &= p[2] == z;
        if (i == 0 || j == 0 || i == n - 1 || j == n - 1)
            rim_kept &= p[0] == q[0] && p[1] == q[1];
        else
            moved += p[0] != q[0] || p[1] != q[1];
        up &= m.normals[3 * v] == 0 && m.normals[3 * v + 1] == 0 && m.normals[3 * v + 2] == 32767;
    }
    CHECK_MSG(flat, "the plane did not stay flat");
    CHECK_MSG(rim_kept, "a boundary vertex moved");
    CHECK_MSG(moved > (n - 2) * (n - 2) / 2, "only %d inner vertices moved", moved);
    CHECK_MSG(up, "the plane's normals are not +z");
    CHECK_EQ(m.vertex_count, before.vertex_count);
    if (CHECK_EQ(m.triangle_count, before.triangle_count))
        CHECK_MEM_EQ(m.indices, before.indices, 3 * m.triangle_count * 4);

    /* bad factors: refused, the mesh unchanged; 0 iterations change nothing */
    ip_indexed_mesh_free(&before);
    copy_mesh(&m, &before);
    const double bad[][2] = {{0, -0.53}, {1.5, -0.53}, {NAN, -0.53},
                             {0.5, 0.1}, {0.5, -2},    {0.5, NAN}};
    for (size_t b = 0; b < sizeof bad / sizeof bad[0]; b++) {
        err.message[0] = 0;
        CHECK_EQ(ip_indexed_mesh_smooth_taubin(&m, 3, bad[b][0], bad[b][1], &err), IP_ERR_ARGUMENT);
        CHECK_CONTAINS(err.message, "Taubin");
    }
    CHECK_EQ(ip_indexed_mesh_smooth_taubin(&m, 0, IP_TAUBIN_LAMBDA, IP_TAUBIN_MU, NULL), IP_OK);
    CHECK_MEM_EQ(m.positions, before.positions, 3 * m.vertex_count * sizeof(float));
    ip_indexed_mesh_free(&m);
    ip_indexed_mesh_free(&before);

    ip_indexed_mesh empty;
    ip_indexed_mesh_init(&empty);
    CHECK_EQ(ip_indexed_mesh_smooth_taubin(&empty, 5, IP_TAUBIN_LAMBDA, IP_TAUBIN_MU, NULL), IP_OK);
}

static const test_case cases[] = {
    TEST_CASE(test_plane),
    TEST_CASE(test_sphere),
};

int main(int argc, char **argv)
{
    return RUN_CASES(argc, argv, cases, "test_mesh_smooth");
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* Simplifying (ip_indexed_mesh_decimate()) and capping (ip_extract_cap()) the full surface of
 * a ball given as a smooth field (radius minus distance, float32, level 0 at the sphere):
 * centred inside the volume, decimation reaches its ratio, stays closed, and every vertex of
 * the original lies within twice the reported error of the simplified surface; cut by the volume's
 * corner, the open surface keeps every rim vertex, and capped it is closed and encloses the
 * part of the ball inside the box within 1 %; a volume wholly above the level caps to the
 * box itself. Bad ratios and errors are refused, the mesh unchanged. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "internal.h"
#include "isoprop/cache.h"
#include "isoprop/engine.h"
#include "isoprop/store.h"
#include "volumes.h"

#define EDGE 32 /* samples along each axis, spacing 1: the box is [0, 31]^3 */

typedef struct ball {
    double centre[3], radius;
} ball;

/* The level-0 cache of the field radius - |p - centre| (bricks of 16), written and bricked in
 * the test's folder; the caller destroys the cache and closes the store. */
static void ball_cache(const ball *b, const char *name, ip_store **store, ip_cache **cache)
{
    const char *dir = test_tmp_dir("test_mesh_decimate");
    char raw[4400], ibv[4400];
    snprintf(raw, sizeof raw, "%s/%s_%dx%dx%d_float32.raw", dir, name, EDGE, EDGE, EDGE);
    snprintf(ibv, sizeof ibv, "%s/%s.ibv", dir, name);
    FILE *f = fopen(raw, "wb");
    REQUIRE(f);
    for (int z = 0; z < EDGE; z++)
        for (int y = 0; y < EDGE; y++)
            for (int x = 0; x < EDGE; x++) {
                double d[3] = {x - b->centre[0], y - b->centre[1], z - b->centre[2]};
                float v = (float)(b->radius - sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
                REQUIRE(fwrite(&v, sizeof v, 1, f) == 1);
            }
    REQUIRE(fclose(f) == 0);
    test_brick_raw(raw, ibv, 16, 4);
    ip_error err;
    REQUIRE(ip_store_open(ibv, store, &err) == IP_OK);
    REQUIRE(ip_cache_create(*store, 64ull << 20, cache, &err) == IP_OK);
}

/* The welded full surface at level 0, capped when asked. */
static void ball_surface(const ball *b, const char *name, int cap, ip_indexed_mesh *out)
{
    ip_store *store;
    ip_cache *cache;
    ip_error err;
    ball_cache(b, name, &store, &cache);
    ip_mesh soup;
    ip_mesh_init(&soup);
    REQUIRE(ip_extract_full(cache, 0.0f, 0, 2, &soup, NULL, &err) == IP_OK);
    if (cap)
        REQUIRE(ip_extract_cap(cache, 0.0f, 0, &soup, &err) == IP_OK);
    REQUIRE(ip_mesh_weld(&soup, out) == IP_OK);
    ip_mesh_free(&soup);
    ip_cache_destroy(cache);
    ip_store_close(store);
}

static int compare_edges(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* The undirected edges (low index << 32 | high), sorted; *count of them (3 a triangle). */
static uint64_t *sorted_edges(const ip_indexed_mesh *m, uint64_t *count)
{
    *count = 3 * m->triangle_count;
    uint64_t *e = malloc((*count + 1) * sizeof *e);
    REQUIRE(e);
    for (uint64_t t = 0; t < m->triangle_count; t++)
        for (int k = 0; k < 3; k++) {
            uint64_t a = m->indices[3 * t + k], c = m->indices[3 * t + (k + 1) % 3];
            e[3 * t + k] = a < c ? a << 32 | c : c << 32 | a;
        }
    qsort(e, *count, sizeof *e, compare_edges);
    return e;
}

/* Edges in exactly one triangle (the rim), and edges in more than two. */
static void edge_uses(const ip_indexed_mesh *m, uint64_t *open, uint64_t *crowded)
{
    uint64_t n;
    uint64_t *e = sorted_edges(m, &n);
    *open = *crowded = 0;
    for (uint64_t i = 0; i < n;) {
        uint64_t j = i;
        while (j < n && e[j] == e[i])
            j++;
        *open += j - i == 1;
        *crowded += j - i > 2;
        i = j;
    }
    free(e);
}

/* The volume enclosed, by the divergence theorem (double sums). */
static double enclosed_volume(const ip_indexed_mesh *m)
{
    double sum = 0;
    for (uint64_t t = 0; t < m->triangle_count; t++) {
        const float *a = m->positions + 3 * m->indices[3 * t];
        const float *b = m->positions + 3 * m->indices[3 * t + 1];
        const float *c = m->positions + 3 * m->indices[3 * t + 2];
        sum += a[0] * ((double)b[1] * c[2] - (double)b[2] * c[1]) +
               a[1] * ((double)b[2] * c[0] - (double)b[0] * c[2]) +
               a[2] * ((double)b[0] * c[1] - (double)b[1] * c[0]);
    }
    return sum / 6;
}

/* The volume of the ball within [0, EDGE - 1]^3: along x exactly, midpoints over y and z. */
static double ball_in_box(const ball *b)
{
    const int n = 1500;
    const double l = EDGE - 1, h = l / n;
    double sum = 0;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double y = (i + 0.5) * h - b->centre[1], z = (j + 0.5) * h - b->centre[2];
            double r2 = b->radius * b->radius - y * y - z * z;
            if (r2 <= 0)
                continue;
            double lo = fmax(b->centre[0] - sqrt(r2), 0), hi = fmin(b->centre[0] + sqrt(r2), l);
            sum += hi > lo ? hi - lo : 0;
        }
    return sum * h * h;
}

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The distance from p to triangle (a, b, c) (Ericson's closest-point regions). */
static double point_triangle(const double p[3], const float *fa, const float *fb, const float *fc)
{
    double ab[3], ac[3], ap[3];
    for (int k = 0; k < 3; k++) {
        ab[k] = (double)fb[k] - fa[k];
        ac[k] = (double)fc[k] - fa[k];
        ap[k] = p[k] - fa[k];
    }
    double d1 = dot3(ab, ap), d2 = dot3(ac, ap), d3 = dot3(ab, ab), d4 = dot3(ab, ac);
    double d5 = dot3(ac, ac);
    /* minimise |ap - s ab - t ac| over s, t >= 0, s + t <= 1: the plane's point, else edges */
    double det = d3 * d5 - d4 * d4, best = INFINITY;
    if (det > 0) {
        double s = (d5 * d1 - d4 * d2) / det, t = (d3 * d2 - d4 * d1) / det;
        if (s >= 0 && t >= 0 && s + t <= 1) {
            double q[3];
            for (int k = 0; k < 3; k++)
                q[k] = ap[k] - s * ab[k] - t * ac[k];
            return sqrt(dot3(q, q));
        }
    }
    const float *ends[3][2] = {{fa, fb}, {fa, fc}, {fb, fc}};
    for (int e = 0; e < 3; e++) {
        double u[3], w[3];
        for (int k = 0; k < 3; k++) {
            u[k] = (double)ends[e][1][k] - ends[e][0][k];
            w[k] = p[k] - ends[e][0][k];
        }
        double uu = dot3(u, u), s = uu > 0 ? fmin(fmax(dot3(u, w) / uu, 0), 1) : 0;
        for (int k = 0; k < 3; k++)
            w[k] -= s * u[k];
        best = fmin(best, sqrt(dot3(w, w)));
    }
    return best;
}

/* The largest distance from a vertex of `from` to the surface `to` (brute force). */
static double one_sided_distance(const ip_indexed_mesh *from, const ip_indexed_mesh *to)
{
    double worst = 0;
    for (uint64_t v = 0; v < from->vertex_count; v++) {
        const double p[3] = {from->positions[3 * v], from->positions[3 * v + 1],
                             from->positions[3 * v + 2]};
        double nearest = INFINITY;
        for (uint64_t t = 0; t < to->triangle_count && nearest > 0; t++) {
            const uint32_t *c = to->indices + 3 * t;
            nearest =
                fmin(nearest, point_triangle(p, to->positions + 3 * c[0], to->positions + 3 * c[1],
                                             to->positions + 3 * c[2]));
        }
        worst = fmax(worst, nearest);
    }
    return worst;
}

/* Whether position p is one of m's vertices. */
static int has_position(const ip_indexed_mesh *m, const float *p)
{
    for (uint64_t v = 0; v < m->vertex_count; v++)
        if (memcmp(m->positions + 3 * v, p, 3 * sizeof *p) == 0)
            return 1;
    return 0;
}

static void test_decimate_closed(void)
{
    const ball b = {{15.5, 15.2, 14.9}, 11.3};
    ip_indexed_mesh m, before;
    ball_surface(&b, "inside", 0, &m);
    ball_surface(&b, "inside", 0, &before);
    uint64_t open, crowded;
    edge_uses(&m, &open, &crowded);
    REQUIRE(open == 0 && crowded == 0);
    double error = -1;
    ip_error err;
    CHECK_EQ(ip_indexed_mesh_decimate(&m, 0.1, 0, &error, &err), IP_OK);
    CHECK_LE(m.triangle_count, before.triangle_count / 10);
    CHECK_GT(m.triangle_count, before.triangle_count / 20);
    CHECK_LT(m.vertex_count, before.vertex_count / 5);
    edge_uses(&m, &open, &crowded);
    CHECK_EQ(open, 0);
    CHECK_EQ(crowded, 0);
    /* the bound: 1 % of the mesh's extent (about 23 units) */
    CHECK_GT(error, 0.0);
    CHECK_LE(error, 0.01 * 2 * b.radius * 1.01);
    double hausdorff = one_sided_distance(&before, &m);
    printf("decimated %llu -> %llu triangles: error %.4f, one-sided distance %.4f\n",
           (unsigned long long)before.triangle_count, (unsigned long long)m.triangle_count, error,
           hausdorff);
    /* meshoptimizer's error is its quadric estimate, not a strict bound on the distance: on
     * this coarse result (about 40 vertices around the equator) the distance is 1.7 times it */
    CHECK_LE(hausdorff, 2 * error);
    for (uint64_t v = 0; v < m.vertex_count; v++) /* kept vertices are original ones */
        CHECK(has_position(&before, m.positions + 3 * v));
    CHECK_NEAR(enclosed_volume(&m) / enclosed_volume(&before), 1.0, 0.03);

    /* a tight bound stops it early: more triangles, a smaller error */
    ip_indexed_mesh tight;
    ball_surface(&b, "inside", 0, &tight);
    double tight_error = -1;
    CHECK_EQ(ip_indexed_mesh_decimate(&tight, 0.1, 0.01, &tight_error, &err), IP_OK);
    CHECK_GT(tight.triangle_count, m.triangle_count);
    CHECK_LE(tight_error, 0.01);
    ip_indexed_mesh_free(&tight);
    ip_indexed_mesh_free(&m);
    ip_indexed_mesh_free(&before);
}

static void test_decimate_keeps_rim(void)
{
    const ball b = {{-3.0, -4.0, 15.5}, 14.0};
    ip_indexed_mesh m, before;
    ball_surface(&b, "corner", 0, &m);
    ball_surface(&b, "corner", 0, &before);
    uint64_t open_before, open_after, crowded;
    edge_uses(&before, &open_before, &crowded);
    REQUIRE(open_before > 0);
    CHECK_EQ(ip_indexed_mesh_decimate(&m, 0.1, 0, NULL, NULL), IP_OK);
    CHECK_LT(m.triangle_count, before.triangle_count / 2);
    edge_uses(&m, &open_after, &crowded);
    CHECK_EQ(open_after, open_before);
    /* every vertex on the rim of the original is still there */
    uint64_t n, rim = 0, kept = 0;
    uint64_t *e = sorted_edges(&before, &n);
    for (uint64_t i = 0; i < n; i++)
        if ((i == 0 || e[i - 1] != e[i]) && (i + 1 == n || e[i + 1] != e[i])) {
            rim++;
            kept += has_position(&m, before.positions + 3 * (e[i] >> 32));
        }
    free(e);
    CHECK_EQ(kept, rim);
    ip_indexed_mesh_free(&m);
    ip_indexed_mesh_free(&before);
}

static void test_decimate_arguments(void)
{
    const ball b = {{15.5, 15.5, 15.5}, 8.0};
    ip_indexed_mesh m;
    ball_surface(&b, "small", 0, &m);
    uint64_t triangles = m.triangle_count;
    const double bad[][2] = {{0, 0},    {1, 0},    {1.5, 0},   {NAN, 0},
                             {-0.5, 0}, {0.5, -1}, {0.5, NAN}, {0.5, INFINITY}};
    ip_error err;
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        err.message[0] = 0;
        CHECK_EQ(ip_indexed_mesh_decimate(&m, bad[i][0], bad[i][1], NULL, &err), IP_ERR_ARGUMENT);
        CHECK_CONTAINS(err.message, "decimate");
        CHECK_EQ(m.triangle_count, triangles);
    }
    ip_indexed_mesh_free(&m);
    ip_indexed_mesh empty;
    ip_indexed_mesh_init(&empty);
    CHECK_EQ(ip_indexed_mesh_decimate(&empty, 0.5, 0, NULL, NULL), IP_OK);
    CHECK_EQ(empty.triangle_count, 0);
}

/* The capped surface, which must be closed: every edge in exactly two triangles. */
static void capped_closed(const ball *b, const char *name, ip_indexed_mesh *m)
{
    uint64_t open, crowded;
    ball_surface(b, name, 1, m);
    edge_uses(m, &open, &crowded);
    CHECK_EQ(open, 0);
    CHECK_EQ(crowded, 0);
}

static void test_cap_corner(void)
{
    const ball b = {{-3.0, -4.0, 15.5}, 14.0};
    ip_indexed_mesh m;
    capped_closed(&b, "corner", &m);
    double volume = enclosed_volume(&m), exact = ball_in_box(&b);
    printf("capped corner ball: volume %.3f, inside the box %.3f\n", volume, exact);
    CHECK_NEAR(volume / exact, 1.0, 0.01);
    /* the capped surface decimates, still closed */
    CHECK_EQ(ip_indexed_mesh_decimate(&m, 0.2, 0, NULL, NULL), IP_OK);
    uint64_t open, crowded;
    edge_uses(&m, &open, &crowded);
    CHECK_EQ(open, 0);
    ip_indexed_mesh_free(&m);
}

static void test_cap_whole_box(void)
{
    /* every sample above the level: no surface, and the cap is the box's six faces */
    const ball b = {{15.5, 15.5, 15.5}, 100.0};
    ip_indexed_mesh m;
    capped_closed(&b, "full", &m);
    CHECK_EQ(m.triangle_count, 6 * 2 * (EDGE - 1) * (EDGE - 1));
    CHECK_NEAR(enclosed_volume(&m), pow(EDGE - 1, 3), 1e-6);
    ip_indexed_mesh_free(&m);

    ip_store *store;
    ip_cache *cache;
    ball_cache(&b, "full", &store, &cache);
    ip_mesh soup;
    ip_mesh_init(&soup);
    ip_error err;
    CHECK_EQ(ip_extract_cap(cache, 0.0f, 7, &soup, &err), IP_ERR_ARGUMENT);
    CHECK_CONTAINS(err.message, "level");
    CHECK_EQ(ip_extract_cap(cache, 1000.0f, 0, &soup, &err), IP_OK); /* all below: nothing */
    CHECK_EQ(soup.triangle_count, 0);
    ip_mesh_free(&soup);
    ip_cache_destroy(cache);
    ip_store_close(store);
}

static void test_drop_folds(void)
{
    /* a tetrahedron; a fold on 0, 1, 4 (the second one turned); one on 2, 4, 3 with a third
     * triangle there wound like the first; a repeat of triangle 0, 1, 2 wound the same way */
    uint32_t indices[] = {0, 1, 2, 0, 3, 1, 1, 3, 2, 2, 3, 0, 0, 1, 4,
                          0, 4, 1, 1, 2, 0, 2, 4, 3, 3, 4, 2, 4, 3, 2};
    ip_indexed_mesh m;
    ip_indexed_mesh_init(&m);
    m.indices = indices;
    m.triangle_count = 10;
    m.vertex_count = 5;
    uint64_t dropped = 0;
    CHECK_EQ(ip__indexed_mesh_drop_folds(&m, &dropped), IP_OK);
    CHECK_EQ(dropped, 4);
    CHECK_EQ(m.triangle_count, 6);
    const uint32_t kept[] = {0, 1, 2, 0, 3, 1, 1, 3, 2, 2, 3, 0, 1, 2, 0};
    CHECK_MEM_EQ(indices, kept, sizeof kept);
    CHECK(memcmp(indices + 15, (const uint32_t[]){2, 4, 3}, 3 * sizeof(uint32_t)) == 0 ||
          memcmp(indices + 15, (const uint32_t[]){4, 3, 2}, 3 * sizeof(uint32_t)) == 0);
}

static const test_case cases[] = {
    TEST_CASE(test_decimate_closed),    TEST_CASE(test_decimate_keeps_rim),
    TEST_CASE(test_decimate_arguments), TEST_CASE(test_cap_corner),
    TEST_CASE(test_cap_whole_box),      TEST_CASE(test_drop_folds),
};

int main(int argc, char **argv)
{
    return RUN_CASES(argc, argv, cases, "test_mesh_decimate");
}

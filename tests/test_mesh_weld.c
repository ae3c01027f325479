/* SPDX-License-Identifier: BSD-3-Clause */
/* Vertex welding: shared vertices by exact position, averaged normals, degenerate triangles
 * left out; and the surface of a full extraction comes out closed (a sphere well inside the
 * volume) or open exactly where it meets the volume's faces. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "isoprop/bricker.h"
#include "isoprop/cache.h"
#include "isoprop/engine.h"
#include "isoprop/generate.h"
#include "isoprop/layout.h"
#include "isoprop/mesh.h"
#include "isoprop/store.h"

/* Appends a triangle with corners p (9 floats) and the same normal n at each corner. */
static void add_triangle(ip_mesh *m, const float p[9], const float n[3])
{
    float normals[9];
    for (int k = 0; k < 9; k++)
        normals[k] = n[k % 3];
    REQUIRE(ip_mesh_append_float_normals(m, p, normals, NULL, 1) == IP_OK);
}

/* Two triangles sharing an edge (one corner of it at -0, the other at +0), a degenerate one,
 * and one that repeats a triangle: indices, averaged normals, the count left out. */
static void test_small(void)
{
    ip_mesh m;
    ip_mesh_init(&m);
    const float a[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0}, b[9] = {1, 0, 0, 1, 1, 0, -0.0f, 1, 0};
    const float flat[9] = {1, 0, 0, 1, 0, 0, 5, 5, 5}; /* two corners at one position */
    const float up[3] = {0, 0, 1}, side[3] = {1, 0, 0};
    add_triangle(&m, a, up);
    add_triangle(&m, b, side);
    add_triangle(&m, flat, up);
    add_triangle(&m, a, up);
    ip_indexed_mesh w;
    REQUIRE(ip_mesh_weld(&m, &w) == IP_OK);
    CHECK_MSG(w.vertex_count == 4, "%llu vertices", (unsigned long long)w.vertex_count);
    CHECK_EQ(w.triangle_count, 3);
    CHECK_EQ(w.dropped_triangles, 1);
    static const uint32_t expected[9] = {0, 1, 2, 1, 3, 2, 0, 1, 2};
    CHECK_MEM_EQ(w.indices, expected, sizeof expected);
    CHECK_EQ(w.positions[9], 1);
    CHECK_EQ(w.positions[10], 1);
    CHECK_EQ(w.positions[11], 0);
    /* vertex 0 only ever had "up"; vertices 1 and 2 are shared by "up" and "side" */
    CHECK_EQ(w.normals[0], 0);
    CHECK_EQ(w.normals[1], 0);
    CHECK_EQ(w.normals[2], 32767);
    float n1[3] = {ip_normal_unpack(w.normals[3]), ip_normal_unpack(w.normals[4]),
                   ip_normal_unpack(w.normals[5])};
    /* twice up and once side, normalised */
    CHECK_NEAR(n1[0], 1 / sqrtf(5), 1e-4f);
    CHECK_EQ(n1[1], 0);
    CHECK_NEAR(n1[2], 2 / sqrtf(5), 1e-4f);
    CHECK_EQ(m.triangle_count, 4); /* the soup is unchanged */
    ip_indexed_mesh_free(&w);
    CHECK_EQ(w.positions, NULL);
    CHECK_EQ(w.vertex_count, 0);

    /* opposite normals cancel: the first corner's stays */
    ip_mesh_clear(&m);
    const float down[3] = {0, 0, -1};
    add_triangle(&m, a, up);
    add_triangle(&m, a, down);
    REQUIRE(ip_mesh_weld(&m, &w) == IP_OK);
    CHECK_EQ(w.vertex_count, 3);
    CHECK_EQ(w.normals[2], 32767);
    ip_indexed_mesh_free(&w);

    ip_mesh_clear(&m);
    REQUIRE(ip_mesh_weld(&m, &w) == IP_OK);
    CHECK_EQ(w.vertex_count, 0);
    CHECK_EQ(w.triangle_count, 0);
    CHECK_EQ(w.dropped_triangles, 0);
    ip_indexed_mesh_free(&w);
    ip_mesh_free(&m);
}

/* ip_mesh_weld_keep_degenerate(): the same soup keeps its degenerate triangle, as a triangle
 * that repeats a vertex, and every triangle in the soup's order. */
static void test_keep_degenerate(void)
{
    ip_mesh m;
    ip_mesh_init(&m);
    const float a[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const float flat[9] = {1, 0, 0, 1, 0, 0, 5, 5, 5};
    const float point[9] = {0, 1, 0, 0, 1, 0, 0, 1, 0}; /* all three corners at one position */
    const float up[3] = {0, 0, 1};
    add_triangle(&m, a, up);
    add_triangle(&m, flat, up);
    add_triangle(&m, point, up);
    ip_indexed_mesh w;
    REQUIRE(ip_mesh_weld_keep_degenerate(&m, &w) == IP_OK);
    CHECK_EQ(w.vertex_count, 4);
    CHECK_EQ(w.triangle_count, 3);
    CHECK_EQ(w.dropped_triangles, 0);
    static const uint32_t expected[9] = {0, 1, 2, 1, 1, 3, 2, 2, 2};
    CHECK_MEM_EQ(w.indices, expected, sizeof expected);
    CHECK_EQ(w.positions[9], 5);
    ip_indexed_mesh_free(&w);
    REQUIRE(ip_mesh_weld(&m, &w) == IP_OK); /* the plain weld leaves both out */
    CHECK_EQ(w.triangle_count, 1);
    CHECK_EQ(w.dropped_triangles, 2);
    ip_indexed_mesh_free(&w);
    ip_mesh_free(&m);
}

/* Many distinct vertices: the hash table grows past its first size and keeps every one. */
static void test_growth(void)
{
    ip_mesh m;
    ip_mesh_init(&m);
    const float up[3] = {0, 0, 1};
    enum {
        N = 5000
    };
    for (int i = 0; i < N; i++) { /* a strip: triangle i shares two corners with i - 1 */
        float p[9] = {(float)i,     (float)(i % 2), 0, (float)i + 1, (float)((i + 1) % 2), 0,
                      (float)i + 2, (float)(i % 2), 0};
        add_triangle(&m, p, up);
    }
    ip_indexed_mesh w;
    REQUIRE(ip_mesh_weld(&m, &w) == IP_OK);
    CHECK_MSG(w.vertex_count == N + 2, "%llu vertices", (unsigned long long)w.vertex_count);
    int same = w.triangle_count == N;
    for (uint64_t t = 0; same && t < N; t++)
        for (int k = 0; k < 9; k++)
            same &= w.positions[3 * w.indices[3 * t + k / 3] + (uint64_t)(k % 3)] ==
                    m.positions[9 * t + (uint64_t)k];
    CHECK_MSG(same, "welded triangles differ from the soup's");
    ip_indexed_mesh_free(&w);
    ip_mesh_free(&m);
}

/* What the edges of an indexed mesh say about its surface. */
typedef struct topology {
    uint64_t edges;           /* undirected */
    uint64_t boundary;        /* directed edges whose reverse is missing */
    uint64_t boundary_inside; /* those of them not on a face of the volume */
    uint64_t repeated;        /* directed edges used more than once: inconsistent orientation */
    uint64_t degenerate;      /* triangles with a repeated index */
    uint64_t unused_vertices; /* vertices no triangle uses */
} topology;

static int compare_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* Whether vertex v lies on a face of the box lo..hi. */
static int on_face(const ip_indexed_mesh *w, uint64_t v, const double lo[3], const double hi[3])
{
    int on = 0;
    for (int a = 0; a < 3; a++)
        on |= w->positions[3 * v + (uint64_t)a] == (float)lo[a] ||
              w->positions[3 * v + (uint64_t)a] == (float)hi[a];
    return on;
}

static topology check_topology(const ip_indexed_mesh *w, const double lo[3], const double hi[3])
{
    topology r;
    memset(&r, 0, sizeof r);
    uint64_t n = 3 * w->triangle_count;
    uint64_t *directed = malloc((n + 1) * sizeof *directed);
    uint64_t *undirected = malloc((n + 1) * sizeof *undirected);
    unsigned char *used = calloc(w->vertex_count + 1, 1);
    REQUIRE(directed && undirected && used);
    for (uint64_t t = 0; t < w->triangle_count; t++) {
        const uint32_t *v = w->indices + 3 * t;
        r.degenerate += v[0] == v[1] || v[1] == v[2] || v[0] == v[2];
        for (int k = 0; k < 3; k++) {
            uint64_t a = v[k], b = v[(k + 1) % 3];
            used[a] = 1;
            directed[3 * t + (uint64_t)k] = a << 32 | b;
            undirected[3 * t + (uint64_t)k] = a < b ? a << 32 | b : b << 32 | a;
        }
    }
    qsort(directed, n, sizeof *directed, compare_u64);
    qsort(undirected, n, sizeof *undirected, compare_u64);
    for (uint64_t i = 0; i < n; i++) {
        r.repeated += i > 0 && directed[i] == directed[i - 1];
        r.edges += i == 0 || undirected[i] != undirected[i - 1];
        uint64_t reverse = (directed[i] & 0xffffffffu) << 32 | directed[i] >> 32;
        if (!bsearch(&reverse, directed, n, sizeof *directed, compare_u64)) {
            r.boundary++;
            r.boundary_inside += !on_face(w, directed[i] >> 32, lo, hi) ||
                                 !on_face(w, directed[i] & 0xffffffffu, lo, hi);
        }
    }
    for (uint64_t v = 0; v < w->vertex_count; v++)
        r.unused_vertices += !used[v];
    free(directed);
    free(undirected);
    free(used);
    return r;
}

/* Whether the welded mesh holds the soup's triangles, in order, as the same position triples,
 * but for the degenerate ones it left out. */
static int same_triangles(const ip_mesh *soup, const ip_indexed_mesh *w)
{
    uint64_t t = 0;
    for (uint64_t s = 0; s < soup->triangle_count; s++) {
        const float *p = soup->positions + 9 * s;
        if (!memcmp(p, p + 3, 12) || !memcmp(p + 3, p + 6, 12) || !memcmp(p, p + 6, 12))
            continue;
        if (t == w->triangle_count)
            return 0;
        for (int k = 0; k < 9; k++)
            if (w->positions[3 * w->indices[3 * t + (uint64_t)(k / 3)] + (uint64_t)(k % 3)] != p[k])
                return 0;
        t++;
    }
    return t == w->triangle_count;
}

/* A float32 field with an inexact anisotropic spacing, bricked small (many brick faces), in
 * `ibv`. */
static void make_volume(const char *dir, ip_field field, char *ibv, size_t size)
{
    ip_gen_params p = {sizeof(ip_gen_params), field, {37, 41, 34}, IP_FLOAT32, 0.0, 1};
    char name[256], raw[4400];
    ip_error err;
    REQUIRE(ip_raw_file_name(name, sizeof name, ip_field_name(field), p.dims, p.type) == IP_OK);
    snprintf(raw, sizeof raw, "%s/%s", dir, name);
    REQUIRE(ip_generate_write(&p, raw, 1, &err) == IP_OK);
    snprintf(ibv, size, "%s/%s.ibv", dir, ip_field_name(field));
    ip_input_desc d;
    ip_bricker_options o;
    REQUIRE(ip_input_describe(raw, NULL, &d, &err) == IP_OK);
    d.spacing[0] = 0.7;
    d.spacing[1] = 1.1;
    d.spacing[2] = 0.3;
    ip_bricker_options_default(&o);
    o.brick_edge = 8;
    o.subblock_edge = 4;
    o.force = 1;
    o.threads = 2;
    REQUIRE(ip_bricker_run(&d, ibv, &o, NULL, &err) == IP_OK);
}

/* Extracts every cell at `iso`, welds, and returns the surface's topology. */
static topology weld_extraction(ip_cache *cache, float iso, const char *what)
{
    ip_mesh soup;
    ip_mesh_init(&soup);
    ip_error err;
    REQUIRE(ip_extract_full(cache, iso, 0, 2, &soup, NULL, &err) == IP_OK);
    ip_indexed_mesh w;
    REQUIRE(ip_mesh_weld(&soup, &w) == IP_OK);
    double lo[3], hi[3];
    ip_layout_world_box(ip_store_layout(ip_cache_store(cache)), lo, hi);
    topology r = check_topology(&w, lo, hi);
    long long euler = (long long)w.vertex_count - (long long)r.edges + (long long)w.triangle_count;
    printf("%s: %llu triangles -> %llu vertices, %llu edges, %llu triangles (%llu left out); "
           "V - E + F = %lld; %llu boundary, %llu repeated edges\n",
           what, (unsigned long long)soup.triangle_count, (unsigned long long)w.vertex_count,
           (unsigned long long)r.edges, (unsigned long long)w.triangle_count,
           (unsigned long long)w.dropped_triangles, euler, (unsigned long long)r.boundary,
           (unsigned long long)r.repeated);
    CHECK_MSG(soup.triangle_count > 1000, "%s: only %llu triangles", what,
              (unsigned long long)soup.triangle_count);
    CHECK_MSG(same_triangles(&soup, &w), "%s: the welded triangles are not the soup's", what);
    CHECK_MSG(w.triangle_count + w.dropped_triangles == soup.triangle_count, "%s: counts", what);
    CHECK_MSG(r.degenerate == 0 && r.unused_vertices == 0,
              "%s: %llu degenerate triangles, "
              "%llu unused vertices",
              what, (unsigned long long)r.degenerate, (unsigned long long)r.unused_vertices);
    CHECK_MSG(r.repeated == 0, "%s: %llu directed edges repeated", what,
              (unsigned long long)r.repeated);
    CHECK_MSG(r.boundary_inside == 0, "%s: %llu open edges inside the volume", what,
              (unsigned long long)r.boundary_inside);
    if (r.boundary == 0) {
        CHECK_MSG(euler == 2, "%s: V - E + F = %lld, not a sphere's 2", what, euler);
        CHECK_EQ(2 * r.edges, 3 * w.triangle_count); /* every edge in exactly two triangles */
    }
    ip_indexed_mesh_free(&w);
    ip_mesh_free(&soup);
    return r;
}

/* Opens `ibv`, extracts at `iso`, welds and checks; returns the topology. */
static topology weld_file(const char *ibv, float iso, const char *what)
{
    ip_store *store;
    ip_cache *cache;
    ip_error err;
    REQUIRE(ip_store_open(ibv, &store, &err) == IP_OK);
    REQUIRE(ip_cache_create(store, 64ull << 20, &cache, &err) == IP_OK);
    topology r = weld_extraction(cache, iso, what);
    ip_cache_destroy(cache);
    ip_store_close(store);
    return r;
}

static void test_closed_and_open(void)
{
    const char *dir = test_tmp_dir("test_mesh_weld");
    char ibv[4200];
    /* 1 - distance from the centre, the volume's half extent being 1: at 0.5, a sphere well
     * inside, a closed surface */
    make_volume(dir, IP_FIELD_SPHERE, ibv, sizeof ibv);
    topology closed = weld_file(ibv, 0.5f, "sphere inside");
    CHECK_MSG(closed.boundary == 0, "the sphere inside the volume has %llu open edges",
              (unsigned long long)closed.boundary);
    /* the gyroid runs through the volume's faces: the checker must see that it is open, and
     * only there */
    make_volume(dir, IP_FIELD_GYROID, ibv, sizeof ibv);
    topology open = weld_file(ibv, 0.5f, "gyroid");
    CHECK_MSG(open.boundary > 0, "the gyroid shows no open edge");
}

/* The largest difference, in packed units, between two meshes' normals. */
static int normal_difference(const ip_indexed_mesh *a, const ip_indexed_mesh *b)
{
    int most = 0;
    for (uint64_t i = 0; i < 3 * a->vertex_count; i++) {
        int d = abs((int)a->normals[i] - (int)b->normals[i]);
        most = d > most ? d : most;
    }
    return most;
}

/* Whether two indexed meshes have the same vertices, numbering and triangles, bit for bit
 * (normals too when `normals`). */
static int same_indexed(const ip_indexed_mesh *a, const ip_indexed_mesh *b, int normals)
{
    return a->vertex_count == b->vertex_count && a->triangle_count == b->triangle_count &&
           a->dropped_triangles == b->dropped_triangles &&
           !memcmp(a->positions, b->positions, 12 * a->vertex_count) &&
           !memcmp(a->indices, b->indices, 12 * a->triangle_count) &&
           (!normals || !memcmp(a->normals, b->normals, 6 * a->vertex_count));
}

/* Whether each vertex's value is the larger sample at the ends of its edge (its sample's where
 * it sits on one) of the uint8 volume `samples` (dims d, unit spacing: a vertex's coordinates
 * are sample indices, whole but along its edge). */
static int values_right(const ip_indexed_mesh *m, const float *values, const uint8_t *samples,
                        const uint32_t d[3])
{
    for (uint64_t v = 0; v < m->vertex_count; v++) {
        const float *p = m->positions + 3 * v;
        uint32_t low[3], high[3];
        for (int a = 0; a < 3; a++) {
            low[a] = (uint32_t)floorf(p[a]);
            high[a] = (uint32_t)ceilf(p[a]);
        }
        float a = samples[low[0] + d[0] * (low[1] + (size_t)d[1] * low[2])];
        float b = samples[high[0] + d[0] * (high[1] + (size_t)d[1] * high[2])];
        if (values[v] != (a > b ? a : b))
            return 0;
    }
    return 1;
}

/* The welded full extraction at `iso` against ip_mesh_weld(_keep_degenerate)() of the soup,
 * on 1 and 2 threads, and its values against `samples` (when not NULL: values_right());
 * returns the triangles with a repeated vertex it kept. */
static uint64_t check_indexed(ip_cache *cache, float iso, int keep, const char *what,
                              const uint8_t *samples)
{
    ip_mesh soup;
    ip_mesh_init(&soup);
    ip_error err;
    REQUIRE(ip_extract_full(cache, iso, 0, 2, &soup, NULL, &err) == IP_OK);
    ip_indexed_mesh want, one, two;
    REQUIRE((keep ? ip_mesh_weld_keep_degenerate(&soup, &want) : ip_mesh_weld(&soup, &want)) ==
            IP_OK);
    float *values1, *values2;
    ip_engine_counts c1, c2;
    REQUIRE(ip_extract_full_indexed(cache, iso, 0, 1, keep, &one, &values1, &c1, &err) == IP_OK);
    REQUIRE(ip_extract_full_indexed(cache, iso, 0, 2, keep, &two, &values2, &c2, &err) == IP_OK);
    printf("%s, iso %g%s: %llu triangles -> %llu vertices, %llu triangles (%llu left out), "
           "normals within %d\n",
           what, (double)iso, keep ? ", degenerate kept" : "",
           (unsigned long long)soup.triangle_count, (unsigned long long)one.vertex_count,
           (unsigned long long)one.triangle_count, (unsigned long long)one.dropped_triangles,
           normal_difference(&one, &want));
    CHECK_MSG(soup.triangle_count > 1000, "%s: only %llu triangles", what,
              (unsigned long long)soup.triangle_count);
    CHECK_MSG(same_indexed(&one, &want, 0), "%s: not the welded soup", what);
    CHECK_MSG(normal_difference(&one, &want) <= 2, "%s: normals differ by %d", what,
              normal_difference(&one, &want));
    CHECK_MSG(same_indexed(&one, &two, 1) &&
                  !memcmp(values1, values2, sizeof(float) * one.vertex_count),
              "%s: 1 and 2 threads differ", what);
    CHECK_EQ(c1.triangles, soup.triangle_count);
    CHECK_EQ(c2.cells, c1.cells);
    uint64_t degenerate = 0;
    for (uint64_t t = 0; t < one.triangle_count; t++) {
        const uint32_t *v = one.indices + 3 * t;
        degenerate += v[0] == v[1] || v[1] == v[2] || v[0] == v[2];
    }
    CHECK_MSG(keep ? one.dropped_triangles == 0 : degenerate == 0, "%s: degenerate", what);
    if (samples)
        CHECK_MSG(
            values_right(&one, values1, samples, ip_store_layout(ip_cache_store(cache))->dims),
            "%s: values", what);
    free(values1);
    free(values2);
    ip_indexed_mesh_free(&want);
    ip_indexed_mesh_free(&one);
    ip_indexed_mesh_free(&two);
    ip_mesh_free(&soup);
    return degenerate;
}

/* The welded full extraction equals the welded soup: float fields with an anisotropic spacing
 * in small bricks (a closed sphere, the gyroid through the volume's faces), and a uint8 ball
 * at a level its samples take, where vertices sit on samples (degenerate triangles kept or
 * dropped). */
static void test_extract_indexed(void)
{
    const char *dir = test_tmp_dir("test_mesh_weld");
    char ibv[4200];
    const ip_field fields[2] = {IP_FIELD_SPHERE, IP_FIELD_GYROID};
    for (int f = 0; f < 2; f++) {
        make_volume(dir, fields[f], ibv, sizeof ibv);
        ip_store *store;
        ip_cache *cache;
        ip_error err;
        REQUIRE(ip_store_open(ibv, &store, &err) == IP_OK);
        REQUIRE(ip_cache_create(store, 64ull << 20, &cache, &err) == IP_OK);
        for (int keep = 0; keep < 2; keep++)
            check_indexed(cache, 0.5f, keep, ip_field_name(fields[f]), NULL);
        ip_cache_destroy(cache);
        ip_store_close(store);
    }
    enum {
        X = 29,
        Y = 23,
        Z = 31
    };
    uint8_t *ball = malloc(X * Y * Z);
    REQUIRE(ball);
    for (int z = 0; z < Z; z++)
        for (int y = 0; y < Y; y++)
            for (int x = 0; x < X; x++) {
                double d = sqrt((x - 13.3) * (x - 13.3) + (y - 11.1) * (y - 11.1) * 0.8 +
                                (z - 15.4) * (z - 15.4) * 0.9);
                ball[x + X * (y + Y * z)] = (uint8_t)lrint(d < 10 ? 100 - 10 * d : 0);
            }
    ip_memory_volume mv;
    ip_memory_volume_default(&mv);
    mv.dims[0] = X;
    mv.dims[1] = Y;
    mv.dims[2] = Z;
    mv.type = IP_UINT8;
    mv.brick_edge = 8;
    mv.subblock_edge = 4;
    ip_store *store;
    ip_cache *cache;
    ip_error err;
    REQUIRE(ip_store_open_memory(ball, &mv, &store, &err) == IP_OK);
    REQUIRE(ip_cache_create(store, 64ull << 20, &cache, &err) == IP_OK);
    CHECK_MSG(check_indexed(cache, 50.0f, 1, "uint8 ball", ball) > 0,
              "no degenerate triangle at a level the samples take");
    check_indexed(cache, 50.0f, 0, "uint8 ball", ball);
    check_indexed(cache, 47.5f, 1, "uint8 ball", ball);
    ip_cache_destroy(cache);
    ip_store_close(store);
    free(ball);
}

static const test_case cases[] = {
    TEST_CASE(test_small),           TEST_CASE(test_keep_degenerate), TEST_CASE(test_growth),
    TEST_CASE(test_closed_and_open), TEST_CASE(test_extract_indexed),
};

int main(int argc, char **argv)
{
    return RUN_CASES(argc, argv, cases, "test_mesh_weld");
}

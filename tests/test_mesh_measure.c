/* SPDX-License-Identifier: BSD-3-Clause */
/* Measuring and cleaning a welded mesh: two disjoint cubes of known area and volume, their
 * components, the largest, --min-area's cut, and an open mesh's boundary. */
#include <math.h>
#include <stdlib.h>

#include "check.h"
#include "isoprop/mesh.h"

/* The 12 triangles of an axis-aligned cube of side s from corner o, counter-clockwise seen
 * from outside (corner i at o + s * (i & 1, i >> 1 & 1, i >> 2 & 1)). */
static void add_cube(ip_mesh *m, const float o[3], float s)
{
    static const int faces[12][3] = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6},
                                     {0, 1, 5}, {0, 5, 4}, {2, 6, 7}, {2, 7, 3},
                                     {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
    for (int f = 0; f < 12; f++) {
        float p[9], n[9] = {0};
        for (int c = 0; c < 3; c++)
            for (int k = 0; k < 3; k++)
                p[3 * c + k] = o[k] + s * (float)(faces[f][c] >> k & 1);
        REQUIRE(ip_mesh_append_float_normals(m, p, n, NULL, 1) == IP_OK);
    }
}

/* A unit cube at the origin and a cube of side 2 at x = 5, welded. */
static void two_cubes(ip_indexed_mesh *w, int drop_last)
{
    ip_mesh m;
    ip_mesh_init(&m);
    const float a[3] = {0, 0, 0}, b[3] = {5, 0, 0};
    add_cube(&m, a, 1);
    add_cube(&m, b, 2);
    if (drop_last)
        m.triangle_count--;
    REQUIRE(ip_mesh_weld(&m, w) == IP_OK);
    ip_mesh_free(&m);
}

static void test_measure(void)
{
    ip_indexed_mesh w;
    two_cubes(&w, 0);
    CHECK_EQ(w.triangle_count, 24);
    CHECK_EQ(w.vertex_count, 16);
    CHECK_NEAR(ip_indexed_mesh_area(&w), 30.0, 1e-12);
    CHECK_NEAR(ip_indexed_mesh_volume(&w), 9.0, 1e-12);
    double lo[3], hi[3];
    ip_indexed_mesh_bounds(&w, lo, hi);
    CHECK_EQ(lo[0], 0);
    CHECK_EQ(hi[0], 7);
    CHECK_EQ(hi[1], 2);
    CHECK_EQ(hi[2], 2);
    uint64_t boundary, nonmanifold;
    REQUIRE(ip_indexed_mesh_edges(&w, &boundary, &nonmanifold) == IP_OK);
    CHECK_EQ(boundary, 0);
    CHECK_EQ(nonmanifold, 0);
    uint32_t labels[24];
    uint64_t count, tris[2];
    double area[2], volume[2];
    REQUIRE(ip_indexed_mesh_components(&w, labels, &count) == IP_OK);
    CHECK_EQ(count, 2);
    CHECK_EQ(labels[0], 0);
    CHECK_EQ(labels[23], 1);
    ip_indexed_mesh_component_measures(&w, labels, count, tris, area, volume);
    CHECK_EQ(tris[0], 12);
    CHECK_EQ(tris[1], 12);
    CHECK_NEAR(area[0], 6.0, 1e-12);
    CHECK_NEAR(area[1], 24.0, 1e-12);
    CHECK_NEAR(volume[0], 1.0, 1e-12);
    CHECK_NEAR(volume[1], 8.0, 1e-12);
    ip_indexed_mesh_free(&w);
}

/* One triangle less: the cube of side 2 is open, by the 3 edges of the hole. */
static void test_open(void)
{
    ip_indexed_mesh w;
    two_cubes(&w, 1);
    uint64_t boundary, nonmanifold;
    REQUIRE(ip_indexed_mesh_edges(&w, &boundary, &nonmanifold) == IP_OK);
    CHECK_EQ(boundary, 3);
    CHECK_EQ(nonmanifold, 0);
    ip_indexed_mesh_free(&w);
}

static void test_clean(void)
{
    ip_indexed_mesh w;
    uint64_t removed;
    two_cubes(&w, 0);
    REQUIRE(ip_indexed_mesh_clean(&w, 1, 0, &removed) == IP_OK);
    CHECK_EQ(removed, 1);
    CHECK_EQ(w.triangle_count, 12);
    CHECK_EQ(w.vertex_count, 8);
    CHECK_NEAR(ip_indexed_mesh_area(&w), 24.0, 1e-12);
    CHECK_NEAR(ip_indexed_mesh_volume(&w), 8.0, 1e-12);
    uint64_t boundary, nonmanifold;
    REQUIRE(ip_indexed_mesh_edges(&w, &boundary, &nonmanifold) == IP_OK);
    CHECK_EQ(boundary, 0);
    for (uint64_t i = 0; i < 3 * w.triangle_count; i++)
        CHECK(w.indices[i] < 8);
    ip_indexed_mesh_free(&w);

    two_cubes(&w, 0); /* the cut: 6 is under 10, 24 is not; exactly 6 is kept */
    REQUIRE(ip_indexed_mesh_clean(&w, 0, 6.0, &removed) == IP_OK);
    CHECK_EQ(removed, 0);
    CHECK_EQ(w.triangle_count, 24);
    REQUIRE(ip_indexed_mesh_clean(&w, 0, 10.0, &removed) == IP_OK);
    CHECK_EQ(removed, 1);
    CHECK_EQ(w.triangle_count, 12);
    CHECK_EQ(w.positions[0], 5); /* the large cube's first corner, now vertex 0 */
    CHECK(ip_indexed_mesh_clean(&w, 0, -1.0, NULL) == IP_ERR_ARGUMENT);
    CHECK(ip_indexed_mesh_clean(&w, 0, NAN, NULL) == IP_ERR_ARGUMENT);
    CHECK_EQ(w.triangle_count, 12);
    REQUIRE(ip_indexed_mesh_clean(&w, 0, 100.0, &removed) == IP_OK);
    CHECK_EQ(removed, 1);
    CHECK_EQ(w.triangle_count, 0);
    CHECK_EQ(w.vertex_count, 0);
    ip_indexed_mesh_free(&w);
}

static const test_case cases[] = {
    TEST_CASE(test_measure),
    TEST_CASE(test_open),
    TEST_CASE(test_clean),
};

int main(int argc, char **argv)
{
    return RUN_CASES(argc, argv, cases, "test_mesh_measure");
}

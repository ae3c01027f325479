/* SPDX-License-Identifier: BSD-3-Clause */
/* The min/max octree walk shared by the bricker and the store (src/brickfile/summary.c): every
 * node gets the range of the bricks below it, and a checking visitor stops at the first node
 * that disagrees. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "check.h"
#include "format.h"
#include "summary.h"

static int store_node(void *nodes, uint32_t level, uint32_t depth, const uint32_t node[3],
                      uint64_t node_index, const float range[2])
{
    (void)level, (void)depth, (void)node;
    ((float *)nodes)[2 * node_index] = range[0];
    ((float *)nodes)[2 * node_index + 1] = range[1];
    return 0;
}

typedef struct visit_log {
    const float *stored;
    uint64_t visits;
    int order_ok;
    uint32_t last_level, last_depth, bad[5]; /* level, depth, x, y, z of the disagreeing node */
} visit_log;

static int check_node(void *user, uint32_t level, uint32_t depth, const uint32_t node[3],
                      uint64_t node_index, const float range[2])
{
    visit_log *v = user;
    /* level by level, depth 1 first within a level */
    if (v->visits > 0 &&
        (level < v->last_level || (level == v->last_level && depth < v->last_depth)))
        v->order_ok = 0;
    v->visits++;
    v->last_level = level;
    v->last_depth = depth;
    if (range[0] == v->stored[2 * node_index] && range[1] == v->stored[2 * node_index + 1])
        return 0;
    v->bad[0] = level, v->bad[1] = depth, v->bad[2] = node[0], v->bad[3] = node[1],
    v->bad[4] = node[2];
    return 7;
}

/* The range of a node by brute force: the bricks of its level whose coordinates shifted by
 * `depth` are the node's. */
static void brute_range(const ip_layout *l, uint32_t k, uint32_t depth, const uint32_t node[3],
                        const float *bricks, float out[2])
{
    const ip_level_layout *lv = &l->levels[k];
    out[0] = INFINITY;
    out[1] = -INFINITY;
    for (uint32_t z = 0; z < lv->bricks[2]; z++)
        for (uint32_t y = 0; y < lv->bricks[1]; y++)
            for (uint32_t x = 0; x < lv->bricks[0]; x++) {
                if (x >> depth != node[0] || y >> depth != node[1] || z >> depth != node[2])
                    continue;
                uint32_t b[3] = {x, y, z};
                const float *r = &bricks[2 * ip_brick_global_index(l, k, b)];
                out[0] = r[0] < out[0] ? r[0] : out[0];
                out[1] = r[1] > out[1] ? r[1] : out[1];
            }
}

/* What the cases share: a layout, random ranges for its bricks and the octree built on them
 * (built_nodes()). */
static ip_layout the_layout;
static float *the_bricks, *the_nodes;

static void make_bricks(void)
{
    ip_layout *l = &the_layout;
    const uint32_t dims[3] = {300, 170, 90}; /* odd brick counts: partial nodes on each axis */
    const double spacing[3] = {1, 1, 1};
    REQUIRE(ip__layout_init(l, dims, IP_UINT8, spacing, 16, 4, NULL) == IP_OK);
    REQUIRE(l->node_count > 0 && l->levels[0].octree_depth >= 2);
    the_bricks = malloc(2 * l->brick_count * sizeof(float));
    the_nodes = calloc(2 * l->node_count, sizeof(float));
    REQUIRE(the_bricks && the_nodes);
    uint64_t state = 3;
    for (uint64_t g = 0; g < l->brick_count; g++) {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        float a = (float)(state >> 40) / 1000.0f, b = (float)((state >> 20) & 0xfffff) / 1000.0f;
        the_bricks[2 * g] = a < b ? a : b;
        the_bricks[2 * g + 1] = a < b ? b : a;
    }
}

static void free_bricks(void)
{
    free(the_bricks);
    free(the_nodes);
}

/* The octree of the bricks' ranges, built by the walk once, by the first case that needs it. */
static float *built_nodes(void)
{
    static int built;
    if (!built)
        CHECK_EQ(ip__octree_walk(&the_layout, the_bricks, the_nodes, store_node, the_nodes), 0);
    built = 1;
    return the_nodes;
}

/* every node of every level and depth holds the range of the bricks below it */
static void walk_stores_ranges(void)
{
    const ip_layout *l = &the_layout;
    const float *nodes = built_nodes();
    int all_right = 1;
    uint64_t node_total = 0;
    for (uint32_t k = 0; k < l->level_count; k++)
        for (uint32_t depth = 1; depth <= l->levels[k].octree_depth; depth++) {
            uint32_t grid[3];
            ip__octree_grid(l, k, depth, grid);
            for (uint32_t z = 0; z < grid[2]; z++)
                for (uint32_t y = 0; y < grid[1]; y++)
                    for (uint32_t x = 0; x < grid[0]; x++) {
                        uint32_t node[3] = {x, y, z};
                        float want[2];
                        brute_range(l, k, depth, node, the_bricks, want);
                        const float *got = &nodes[2 * ip__octree_node_index(l, k, depth, node)];
                        all_right &= got[0] == want[0] && got[1] == want[1];
                        node_total++;
                    }
        }
    CHECK(all_right);
    CHECK_EQ(node_total, l->node_count);
}

/* checking against the built octree visits every node and finds nothing */
static void walk_checks_every_node(void)
{
    const ip_layout *l = &the_layout;
    float *nodes = built_nodes();
    visit_log v = {nodes, 0, 1, 0, 0, {0}};
    CHECK_EQ(ip__octree_walk(l, the_bricks, nodes, check_node, &v), 0);
    CHECK_EQ(v.visits, l->node_count);
    CHECK(v.order_ok);
}

/* a wrong node at depth 2 of level 0: the walk stops there with the visitor's value (the node
 * is right again after) */
static void walk_stops_at_wrong_node(void)
{
    const ip_layout *l = &the_layout;
    float *nodes = built_nodes();
    uint32_t target[3] = {1, 0, 1};
    float *wrong = &nodes[2 * ip__octree_node_index(l, 0, 2, target) + 1];
    float right = *wrong;
    *wrong += 1.0f;
    visit_log w = {nodes, 0, 1, 0, 0, {0}};
    CHECK_EQ(ip__octree_walk(l, the_bricks, nodes, check_node, &w), 7);
    CHECK_EQ(w.bad[0], 0);
    CHECK_EQ(w.bad[1], 2);
    CHECK_EQ(w.bad[2], 1);
    CHECK_EQ(w.bad[3], 0);
    CHECK_EQ(w.bad[4], 1);
    CHECK_LT(w.visits, l->node_count);
    *wrong = right;
}

static const test_case cases[] = {
    TEST_CASE(walk_stores_ranges),
    TEST_CASE(walk_checks_every_node),
    TEST_CASE(walk_stops_at_wrong_node),
};

int main(int argc, char **argv)
{
    return RUN_CASES_WITH(argc, argv, cases, "test_octree", make_bricks, free_bricks);
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* A store on samples in memory (ip_store_open_memory()) against the brick file of the same
 * samples: the same layout, brick and sub-block ranges, octree and brick samples, the same
 * triangles from full and progressive extraction; strided views of the samples; what it
 * refuses. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "isoprop/bricker.h"
#include "isoprop/camera.h"
#include "isoprop/engine.h"
#include "isoprop/generate.h"
#include "isoprop/input.h"
#include "isoprop/store.h"
#include "summary.h"

/* A generated volume: its samples in memory (x fastest) and its brick file. */
typedef struct volume {
    ip_gen_params p;
    unsigned char *samples;
    size_t sample_size;
    char ibv[4400];
} volume;

/* Volume `field` of `dims` and `type` in memory, and bricked with B = 8, s = 2 (several levels)
 * into the test's scratch folder as STEM.ibv. */
static void make_volume(volume *v, ip_field field, const uint32_t dims[3], ip_type type,
                        const char *stem)
{
    ip_error err;
    v->p =
        (ip_gen_params){sizeof(ip_gen_params), field, {dims[0], dims[1], dims[2]}, type, 0.02, 7};
    v->sample_size = ip_type_size(type);
    size_t plane = (size_t)dims[0] * dims[1] * v->sample_size;
    v->samples = malloc(plane * dims[2]);
    REQUIRE(v->samples);
    for (uint32_t z = 0; z < dims[2]; z++)
        REQUIRE(ip_generate_plane(&v->p, z, v->samples + z * plane, &err) == IP_OK);
    const char *dir = test_tmp_dir("test_memory_store");
    char name[256], raw[4400];
    REQUIRE(ip_raw_file_name(name, sizeof name, stem, dims, type) == IP_OK);
    snprintf(raw, sizeof raw, "%s/%s", dir, name);
    REQUIRE(ip_generate_write(&v->p, raw, 1, &err) == IP_OK);
    snprintf(v->ibv, sizeof v->ibv, "%s/%s.ibv", dir, stem);
    ip_input_desc d;
    ip_bricker_options o;
    REQUIRE(ip_input_describe(raw, NULL, &d, &err) == IP_OK);
    ip_bricker_options_default(&o);
    o.brick_edge = 8;
    o.subblock_edge = 2;
    o.force = 1;
    REQUIRE(ip_bricker_run(&d, v->ibv, &o, NULL, &err) == IP_OK);
}

/* The description of v's samples, contiguous, with the brick file's edges. */
static ip_memory_volume describe(const volume *v)
{
    ip_memory_volume m;
    ip_memory_volume_default(&m);
    memcpy(m.dims, v->p.dims, sizeof m.dims);
    m.type = v->p.type;
    m.brick_edge = 8;
    m.subblock_edge = 2;
    m.threads = 2;
    return m;
}

static int same_bits(const float *a, const float *b, size_t n)
{
    return memcmp(a, b, n * sizeof(float)) == 0;
}

/* ip__octree_walk() visitor over the octree of two stores: keeps the range the walk computes
 * (its node ranges, read back for the next depth) and counts the nodes whose stored ranges
 * are the same in both stores and equal the one computed. */
typedef struct node_compare {
    const ip_store *a, *b;
    float *nodes;
    uint64_t visited, same;
} node_compare;

static int compare_node(void *user, uint32_t level, uint32_t depth, const uint32_t node[3],
                        uint64_t node_index, const float range[2])
{
    node_compare *c = user;
    const float *ra = ip_store_node_range(c->a, level, depth, node);
    memcpy(c->nodes + 2 * node_index, range, 2 * sizeof(float));
    c->visited++;
    c->same +=
        same_bits(ra, ip_store_node_range(c->b, level, depth, node), 2) && same_bits(ra, range, 2);
    return 0;
}

/* Layout (but for the file's figures), every brick range, sub-block range, octree node and
 * brick's samples equal, bit for bit. */
static void check_same_store(const ip_store *file, const ip_store *mem)
{
    const ip_layout *a = ip_store_layout(file), *b = ip_store_layout(mem);
    CHECK_MEM_EQ(a->dims, b->dims, sizeof a->dims);
    CHECK_EQ(a->type, b->type);
    CHECK_MEM_EQ(a->spacing, b->spacing, sizeof a->spacing);
    CHECK_MEM_EQ(&a->orientation, &b->orientation, sizeof a->orientation);
    CHECK_EQ(a->brick_edge, b->brick_edge);
    CHECK_EQ(a->subblock_edge, b->subblock_edge);
    CHECK_EQ(a->brick_count, b->brick_count);
    CHECK_EQ(a->node_count, b->node_count);
    CHECK_EQ(a->format_version, b->format_version);
    CHECK(same_bits(&a->value_min, &b->value_min, 1) && same_bits(&a->value_max, &b->value_max, 1));
    REQUIRE(a->level_count == b->level_count && a->level_count > 2);
    CHECK_MEM_EQ(a->levels, b->levels, a->level_count * sizeof a->levels[0]);
    CHECK_EQ(b->file_size, 0);
    uint32_t subblocks = ip_layout_subblocks_per_brick(a);
    size_t edge = a->brick_edge + 1, bytes = edge * edge * edge * ip_type_size(a->type);
    unsigned char *sa = malloc(bytes), *sb = malloc(bytes);
    void *work = malloc(ip_store_read_work_size(file)),
         *work_m = malloc(ip_store_read_work_size(mem));
    REQUIRE(sa && sb && work && work_m);
    uint64_t ranges = 0, subs = 0, samples = 0, constant = 0;
    ip_error err;
    for (uint64_t g = 0; g < a->brick_count; g++) {
        float ra[2], rb[2];
        ip_store_brick_range(file, g, ra);
        ip_store_brick_range(mem, g, rb);
        ranges += same_bits(ra, rb, 2);
        subs += same_bits(ip_store_subblock_ranges(file, g), ip_store_subblock_ranges(mem, g),
                          2 * subblocks);
        REQUIRE(ip_store_read_brick(file, g, sa, work, &err) == IP_OK);
        REQUIRE(ip_store_read_brick(mem, g, sb, work_m, &err) == IP_OK);
        samples += memcmp(sa, sb, ip_store_brick_samples(file, g) * ip_type_size(a->type)) == 0;
        ip_brick_entry e;
        ip_store_brick_entry(mem, g, &e);
        constant += e.encoding == IP_BRICK_CONSTANT;
        CHECK(e.offset == 0 && e.stored_size == 0 && e.checksum == 0);
    }
    CHECK_EQ(ranges, a->brick_count);
    CHECK_EQ(subs, a->brick_count);
    CHECK_EQ(samples, a->brick_count);
    CHECK_LT(constant, a->brick_count);
    node_compare c = {file, mem, malloc(2 * a->node_count * sizeof(float)), 0, 0};
    float *brick_ranges = malloc(2 * a->brick_count * sizeof(float));
    REQUIRE(c.nodes && brick_ranges);
    for (uint64_t g = 0; g < a->brick_count; g++)
        ip_store_brick_range(mem, g, brick_ranges + 2 * g);
    ip__octree_walk(a, brick_ranges, c.nodes, compare_node, &c);
    CHECK_EQ(c.visited, a->node_count);
    CHECK_EQ(c.same, a->node_count);
    CHECK_GT(c.visited, 0);
    free(c.nodes);
    free(brick_ranges);
    free(sa);
    free(sb);
    free(work);
    free(work_m);
}

/* Same triangles, bytes and order: positions and normals. */
static void check_same_mesh(const ip_mesh *a, const ip_mesh *b, const char *what)
{
    CHECK_MSG(a->triangle_count == b->triangle_count && a->triangle_count > 0,
              "%s: %llu and %llu triangles", what, (unsigned long long)a->triangle_count,
              (unsigned long long)b->triangle_count);
    if (a->triangle_count != b->triangle_count)
        return;
    CHECK_MEM_EQ(a->positions, b->positions, a->triangle_count * 9 * sizeof(float));
    CHECK_MEM_EQ(a->normals, b->normals, a->triangle_count * 9 * sizeof(int16_t));
}

/* ip_extract_full() of level `level` through a cache on `s`. */
static void extract_full(const ip_store *s, float iso, uint32_t level, ip_mesh *mesh)
{
    ip_error err;
    ip_cache *c;
    REQUIRE(ip_cache_create(s, 64u << 20, &c, &err) == IP_OK);
    ip_mesh_init(mesh);
    REQUIRE(ip_extract_full(c, iso, level, 2, mesh, NULL, &err) == IP_OK);
    ip_cache_destroy(c);
}

/* A progressive view of `s` from `axis` (one thread: the same triangles in the same order each
 * time), every ray to the end, with the levels of detail; or, `full_lod`, the full extraction
 * at that view's adaptive resolution (ip_extract_full_lod(), a coarse pixel error so that the
 * coarser levels serve most cells). */
static void extract_view(const ip_store *s, float iso, const char *axis, int full_lod,
                         ip_mesh *mesh)
{
    ip_error err;
    ip_cache *c;
    REQUIRE(ip_cache_create(s, 64u << 20, &c, &err) == IP_OK);
    double lo[3], hi[3];
    ip_layout_world_box(ip_store_layout(s), lo, hi);
    ip_camera cam;
    REQUIRE(ip_camera_fit_axis(lo, hi, axis, 30.0, 160, 120, &cam, &err) == IP_OK);
    ip_mesh_init(mesh);
    if (full_lod) {
        REQUIRE(ip_extract_full_lod(c, iso, &cam, 8.0, 2, NULL, 0, mesh, NULL, &err) == IP_OK);
        ip_cache_destroy(c);
        return;
    }
    ip_engine_options o;
    ip_engine_options_default(&o);
    o.threads = 1;
    ip_engine *e;
    REQUIRE(ip_engine_create(c, &o, &e, &err) == IP_OK);
    REQUIRE(ip_engine_begin(e, &cam, iso, &err) == IP_OK);
    while (!ip_engine_done(e))
        REQUIRE(ip_engine_step(e, 4096, 0, NULL, &err) == IP_OK);
    const ip_mesh *m = ip_engine_mesh(e);
    REQUIRE(ip_mesh_append_mesh(mesh, m, 0, m->triangle_count) == IP_OK);
    ip_engine_destroy(e);
    ip_cache_destroy(c);
}

/* An isovalue `t` of the way through the store's value range. */
static float iso_at(const ip_store *s, float t)
{
    const ip_layout *l = ip_store_layout(s);
    return l->value_min + t * (l->value_max - l->value_min);
}

/* The memory store of `v` (contiguous) against its brick file: summaries, samples, full
 * extraction at levels 0 and 1, a progressive view, at `t` of the value range. */
static void check_against_file(volume *v, float t)
{
    ip_error err;
    ip_store *file, *mem;
    ip_memory_volume m = describe(v);
    REQUIRE(ip_store_open(v->ibv, &file, &err) == IP_OK);
    CHECK_MSG(ip_store_open_memory(v->samples, &m, &mem, &err) == IP_OK, "%s", err.message);
    REQUIRE(mem);
    CHECK_STR_EQ(ip_store_path(mem), "array");
    check_same_store(file, mem);
    float iso = iso_at(file, t);
    /* the coarser levels are held: the samples of levels 1.. */
    const ip_layout *l = ip_store_layout(mem);
    uint64_t held = 0;
    for (uint32_t k = 1; k < l->level_count; k++)
        held += (uint64_t)l->levels[k].dims[0] * l->levels[k].dims[1] * l->levels[k].dims[2] *
                v->sample_size;
    CHECK_EQ(ip_store_held_samples(mem), held);
    CHECK_EQ(ip_store_held_samples(file), 0);
    CHECK_GT(ip_store_summary_memory(mem), 0);
    CHECK_EQ(ip_store_verify_octree(mem, &err), IP_OK);
    uint64_t level0 = 0;
    for (uint32_t level = 0; level < 2; level++) {
        ip_mesh a, b;
        extract_full(file, iso, level, &a);
        level0 = level == 0 ? a.triangle_count : level0;
        extract_full(mem, iso, level, &b);
        check_same_mesh(&a, &b, level ? "full, level 1" : "full");
        ip_mesh_free(&a);
        ip_mesh_free(&b);
    }
    for (int full_lod = 0; full_lod < 2; full_lod++) {
        ip_mesh a, b;
        extract_view(file, iso, "-y", full_lod, &a);
        extract_view(mem, iso, "-y", full_lod, &b);
        check_same_mesh(&a, &b, full_lod ? "full at the view's resolution" : "view -y");
        if (full_lod) /* the coarser levels served some of the cells */
            CHECK_LT(b.triangle_count, level0);
        ip_mesh_free(&a);
        ip_mesh_free(&b);
    }
    ip_store_close(file);
    ip_store_close(mem);
}

static void test_uint16_as_file(void)
{
    volume v;
    make_volume(&v, IP_FIELD_SHEPP_LOGAN, (const uint32_t[3]){37, 29, 33}, IP_UINT16, "shepp");
    check_against_file(&v, 0.3f);
    free(v.samples);
}

static void test_float32_as_file(void)
{
    volume v;
    make_volume(&v, IP_FIELD_GYROID, (const uint32_t[3]){30, 27, 26}, IP_FLOAT32, "gyroid");
    check_against_file(&v, 0.5f);
    free(v.samples);
}

static void test_uint8_as_file(void)
{
    volume v;
    make_volume(&v, IP_FIELD_SPHERE, (const uint32_t[3]){25, 34, 21}, IP_UINT8, "sphere");
    check_against_file(&v, 0.4f);
    free(v.samples);
}

/* A strided view: the samples of v every other int16 of a larger buffer, y running backwards
 * and planes padded, opened without a copy: the same store and triangles as the contiguous
 * samples. */
static void test_strided_view(void)
{
    volume v;
    make_volume(&v, IP_FIELD_GYROID, (const uint32_t[3]){23, 26, 19}, IP_INT16, "strided");
    const uint32_t *d = v.p.dims;
    size_t ss = v.sample_size, row = 2 * d[0] * ss, plane = row * d[1] + 40;
    unsigned char *big = calloc(plane * d[2], 1);
    REQUIRE(big);
    for (uint32_t z = 0; z < d[2]; z++)
        for (uint32_t y = 0; y < d[1]; y++)
            for (uint32_t x = 0; x < d[0]; x++)
                memcpy(big + z * plane + (d[1] - 1 - y) * row + 2 * x * ss,
                       v.samples + (((size_t)z * d[1] + y) * d[0] + x) * ss, ss);
    ip_error err;
    ip_store *flat, *strided;
    ip_memory_volume m = describe(&v);
    REQUIRE(ip_store_open_memory(v.samples, &m, &flat, &err) == IP_OK);
    m.strides[0] = (int64_t)(2 * ss);
    m.strides[1] = -(int64_t)row;
    m.strides[2] = (int64_t)plane;
    m.name = "view";
    CHECK_MSG(ip_store_open_memory(big + (d[1] - 1) * row, &m, &strided, &err) == IP_OK, "%s",
              err.message);
    CHECK_STR_EQ(ip_store_path(strided), "view");
    check_same_store(flat, strided);
    ip_mesh a, b;
    extract_full(flat, iso_at(flat, 0.5f), 0, &a);
    extract_full(strided, iso_at(flat, 0.5f), 0, &b);
    check_same_mesh(&a, &b, "strided, full");
    ip_mesh_free(&a);
    ip_mesh_free(&b);
    ip_store_close(flat);
    ip_store_close(strided);
    free(big);
    free(v.samples);
}

/* ip_store_verify_brick() on a memory store checks the samples now against the summaries of
 * the samples at open: a change the caller made since is found. */
static void test_verify_changed_samples(void)
{
    uint32_t dims[3] = {20, 20, 20};
    uint8_t *samples = malloc(8000);
    REQUIRE(samples);
    for (int i = 0; i < 8000; i++)
        samples[i] = (uint8_t)(i % 20 * 10);
    ip_memory_volume m;
    ip_memory_volume_default(&m);
    memcpy(m.dims, dims, sizeof dims);
    m.type = IP_UINT8;
    ip_store *s;
    ip_error err;
    REQUIRE(ip_store_open_memory(samples, &m, &s, &err) == IP_OK);
    CHECK_EQ(ip_store_layout(s)->brick_edge, IP_DEFAULT_BRICK_EDGE);
    unsigned char brick[33 * 33 * 33], work[64];
    REQUIRE(ip_store_read_work_size(s) <= sizeof work);
    CHECK_EQ(ip_store_verify_brick(s, 0, brick, work, &err), IP_OK);
    samples[5 * 400 + 5 * 20 + 5] = 255;
    CHECK_EQ(ip_store_verify_brick(s, 0, brick, work, &err), IP_ERR_CORRUPT);
    CHECK_CONTAINS(err.message, "array: brick 0 (level 0, brick 0,0,0): samples disagree");
    ip_store_close(s);
    free(samples);
}

/* The rescale and orientation given are kept as a brick file keeps them. */
static void test_rescale_and_orientation(void)
{
    int16_t samples[3 * 3 * 3];
    for (int i = 0; i < 27; i++)
        samples[i] = (int16_t)(i * 100 - 1000);
    ip_memory_volume m;
    ip_memory_volume_default(&m);
    m.dims[0] = m.dims[1] = m.dims[2] = 3;
    m.type = IP_INT16;
    m.spacing[0] = 0.5, m.spacing[1] = 0.5, m.spacing[2] = 2.0;
    ip_orientation_identity(&m.orientation);
    m.orientation.origin[0] = -10;
    m.orientation.directions[0][0] = -1; /* x runs left */
    m.orientation.space = IP_SPACE_LPS;
    m.rescale = (ip_rescale){1, 0.5, -1024, "HU"};
    ip_store *s;
    ip_error err;
    REQUIRE(ip_store_open_memory(samples, &m, &s, &err) == IP_OK);
    const ip_layout *l = ip_store_layout(s);
    CHECK_EQ(l->format_version, 3);
    CHECK(l->rescale.present && l->rescale.slope == 0.5 && l->rescale.intercept == -1024);
    CHECK_STR_EQ(l->rescale.unit, "HU");
    CHECK_EQ(l->orientation.space, IP_SPACE_LPS);
    CHECK_EQ(l->orientation.directions[0][0], -1.0);
    CHECK_EQ(l->spacing[2], 2.0);
    CHECK_EQ(l->value_min, -1000.0f);
    CHECK_EQ(l->value_max, 1600.0f);
    ip_store_close(s);
}

/* Opening `samples` as `m` fails with `status` and a message containing `needle`. */
static void check_refused(const void *samples, const ip_memory_volume *m, ip_status status,
                          const char *needle)
{
    ip_store *s = NULL;
    ip_error err;
    CHECK_EQ(ip_store_open_memory(samples, m, &s, &err), status);
    CHECK(s == NULL);
    CHECK_CONTAINS(err.message, needle);
}

static void test_refused(void)
{
    float samples[4 * 4 * 4];
    for (int i = 0; i < 64; i++)
        samples[i] = (float)i;
    ip_memory_volume m;
    ip_memory_volume_default(&m);
    m.dims[0] = m.dims[1] = m.dims[2] = 4;
    m.type = IP_FLOAT32;
    ip_memory_volume bad = m;
    check_refused(samples, NULL, IP_ERR_ARGUMENT, "ip_store_open_memory: volume and out");
    check_refused(NULL, &m, IP_ERR_ARGUMENT, "array: the samples are NULL");
    bad.dims[1] = 1;
    check_refused(samples, &bad, IP_ERR_ARGUMENT,
                  "array: 4 x 1 x 4 samples: each dimension must be at least 2");
    bad = m;
    bad.type = (ip_type)9;
    check_refused(samples, &bad, IP_ERR_ARGUMENT, "array: sample type 9 is none of");
    bad = m;
    bad.size = 8;
    check_refused(samples, &bad, IP_ERR_ARGUMENT, "ip_store_open_memory: volume: size 8");
    bad = m;
    bad.brick_edge = 6;
    bad.name = "head";
    check_refused(samples, &bad, IP_ERR_ARGUMENT, "head: ");
    bad = m;
    bad.spacing[0] = -1;
    check_refused(samples, &bad, IP_ERR_UNSUPPORTED, "array: ");
    bad = m;
    bad.rescale = (ip_rescale){1, 0.0, 0.0, ""};
    check_refused(samples, &bad, IP_ERR_ARGUMENT, "array: ");
    samples[2 * 16 + 1 * 4 + 3] = NAN;
    check_refused(samples, &m, IP_ERR_INPUT, "array: float32 sample at (x,y,z) = (3,1,2) is NaN");
    samples[1] = -INFINITY;
    check_refused(samples, &m, IP_ERR_INPUT,
                  "array: float32 sample at (x,y,z) = (1,0,0) is infinite");
}

static const test_case cases[] = {
    TEST_CASE(test_uint16_as_file),
    TEST_CASE(test_float32_as_file),
    TEST_CASE(test_uint8_as_file),
    TEST_CASE(test_strided_view),
    TEST_CASE(test_verify_changed_samples),
    TEST_CASE(test_rescale_and_orientation),
    TEST_CASE(test_refused),
};

int main(int argc, char **argv)
{
    return RUN_CASES(argc, argv, cases, "test_memory_store");
}

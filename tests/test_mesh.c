/* SPDX-License-Identifier: BSD-3-Clause */
/* Meshes: packed normals, cell ids on request, appends, and the writers (PLY, STL, OBJ, binary
 * glTF) of soups and of welded meshes. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "internal.h"
#include "isoprop/mesh.h"

static void test_normal_packing(void)
{
    CHECK_EQ(ip_normal_pack(1.0f), 32767);
    CHECK_EQ(ip_normal_pack(-1.0f), -32767);
    CHECK_EQ(ip_normal_pack(0.0f), 0);
    CHECK_EQ(ip_normal_pack(-0.0f), 0);
    CHECK_EQ(ip_normal_pack(2.0f), 32767);
    CHECK_EQ(ip_normal_pack(-5.0f), -32767); /* clamped */
    CHECK_EQ(ip_normal_pack(NAN), 0);
    CHECK_EQ(ip_normal_pack(INFINITY), 32767);
    CHECK_EQ(ip_normal_pack(-INFINITY), -32767);
    float worst = 0;
    for (int i = -1000; i <= 1000; i++) {
        float v = (float)i / 1000.0f;
        float back = ip_normal_unpack(ip_normal_pack(v));
        worst = fabsf(back - v) > worst ? fabsf(back - v) : worst;
    }
    /* rounding to nearest: at most half a step of 1/32767 */
    CHECK_MSG(worst <= 0.5f / 32767.0f + 1e-7f, "round trip error %g", (double)worst);
}

/* n triangles: triangle t has positions t + k/10 and normals (1, 0, 0) or (0, -1, 0). */
static void fill(float *p, float *n, uint64_t *cells, uint64_t count, uint64_t first)
{
    for (uint64_t t = 0; t < count; t++) {
        for (int i = 0; i < 9; i++) {
            p[9 * t + i] = (float)(first + t) + (float)i / 10.0f;
            n[9 * t + i] = 0;
        }
        for (int k = 0; k < 3; k++)
            n[9 * t + 3 * k + ((first + t) % 2 ? 1 : 0)] = (first + t) % 2 ? -1.0f : 1.0f;
        cells[t] = 1000 + first + t;
    }
}

static void test_appends(void)
{
    enum {
        N = 700
    }; /* more than the 256 triangles ip_mesh_append_float_normals packs at once */
    float *p = malloc(N * 9 * sizeof *p), *n = malloc(N * 9 * sizeof *n);
    uint64_t *cells = malloc(N * sizeof *cells);
    REQUIRE(p && n && cells);
    fill(p, n, cells, N, 0);

    ip_mesh plain, with;
    ip_mesh_init(&plain);
    ip_mesh_init_with_cells(&with);
    CHECK(!plain.with_cells);
    CHECK(with.with_cells);
    CHECK_EQ(ip_mesh_append_float_normals(&plain, p, n, NULL, N), IP_OK);
    CHECK_EQ(ip_mesh_append_float_normals(&with, p, n, cells, N), IP_OK);
    CHECK_EQ(plain.triangle_count, N);
    CHECK_EQ(with.triangle_count, N);
    CHECK_EQ(plain.cells, NULL);
    CHECK_NE(with.cells, NULL);
    int same = 1;
    for (uint64_t t = 0; t < N; t++) {
        same &= with.cells[t] == 1000 + t;
        for (int i = 0; i < 9; i++)
            same &= plain.positions[9 * t + i] == p[9 * t + i] &&
                    plain.normals[9 * t + i] == ip_normal_pack(n[9 * t + i]) &&
                    with.normals[9 * t + i] == plain.normals[9 * t + i];
    }
    CHECK(same);
    CHECK_GE(plain.capacity, N);
    CHECK_LE(plain.capacity, 2 * N + 1024);

    /* a range of one mesh onto another, with and without cell ids */
    ip_mesh part;
    ip_mesh_init_with_cells(&part);
    CHECK_EQ(ip_mesh_append_mesh(&part, &with, 100, 50), IP_OK);
    if (CHECK_EQ(part.triangle_count, 50)) {
        CHECK_EQ(part.cells[0], 1100);
        CHECK_EQ(part.cells[49], 1149);
    }
    CHECK_EQ(part.positions[0], p[900]);
    CHECK_EQ(part.normals[9 * 49 + 4], with.normals[9 * 149 + 4]);
    CHECK_EQ(ip_mesh_append_mesh(&part, &plain, 0, 10), IP_ERR_ARGUMENT);   /* no ids to copy */
    CHECK_EQ(ip_mesh_append_mesh(&part, &with, N - 5, 6), IP_ERR_ARGUMENT); /* past the end */
    CHECK_EQ(ip_mesh_append_mesh(&part, &with, N + 1, 0), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_mesh_append_mesh(&part, &with, N, 0), IP_OK);
    CHECK_EQ(part.triangle_count, 50);
    CHECK_EQ(ip_mesh_append_mesh(&plain, &with, 0, 3), IP_OK); /* ids dropped */
    CHECK_EQ(plain.triangle_count, N + 3);
    CHECK_EQ(plain.cells, NULL);

    /* clear keeps the memory; free keeps the choice of cell ids */
    ip_mesh_clear(&with);
    CHECK_EQ(with.triangle_count, 0);
    CHECK_GE(with.capacity, N);
    ip_mesh_free(&with);
    CHECK_EQ(with.positions, NULL);
    CHECK_EQ(with.capacity, 0);
    CHECK(with.with_cells);
    if (CHECK_EQ(ip_mesh_append_float_normals(&with, p, n, cells, 1), IP_OK))
        CHECK_EQ(with.cells[0], 1000);
    ip_mesh_free(&with);
    ip_mesh_free(&plain);
    ip_mesh_free(&part);
    free(p);
    free(n);
    free(cells);
}

/* A mesh of the two triangles fill() makes (their corners in p). */
static void two_triangles(ip_mesh *m, float p[18])
{
    float n[18];
    uint64_t cells[2];
    fill(p, n, cells, 2, 0);
    ip_mesh_init(m);
    REQUIRE(ip_mesh_append_float_normals(m, p, n, NULL, 2) == IP_OK);
}

static void test_ply(void)
{
    const char *dir = test_tmp_dir("test_mesh");
    char path[4200];
    snprintf(path, sizeof path, "%s/two.ply", dir);
    remove(path);
    float p[18];
    ip_mesh m;
    two_triangles(&m, p);
    ip_error err;
    REQUIRE(ip_mesh_write_ply(&m, path, 0, &err) == IP_OK);
    CHECK_EQ(ip_mesh_write_ply(&m, path, 0, &err), IP_ERR_EXISTS);
    CHECK_EQ(ip_mesh_write_ply(&m, path, 1, &err), IP_OK);

    FILE *f = fopen(path, "rb");
    REQUIRE(f);
    static unsigned char buf[4096];
    size_t size = fread(buf, 1, sizeof buf, f);
    fclose(f);
    const char *end = strstr((const char *)buf, "end_header\n");
    REQUIRE(end);
    CHECK_NE(strstr((const char *)buf, "element vertex 6\n"), NULL);
    CHECK_NE(strstr((const char *)buf, "element face 2\n"), NULL);
    size_t body = (size_t)(end - (const char *)buf) + strlen("end_header\n");
    CHECK_EQ(size, body + 6 * 24 + 2 * 13); /* 6 vertices of 6 floats, 2 faces of 1 + 3 ints */
    const unsigned char *v = buf + body;
    /* vertex 4 (triangle 1, vertex 1): position p[12..14], normal (0, -1, 0) */
    CHECK_EQ(ip__load_f32le(v + 4 * 24), p[12]);
    CHECK_EQ(ip__load_f32le(v + 4 * 24 + 8), p[14]);
    CHECK_EQ(ip__load_f32le(v + 4 * 24 + 12), 0.0f);
    CHECK_EQ(ip__load_f32le(v + 4 * 24 + 16), -1.0f);
    const unsigned char *face = v + 6 * 24 + 13;
    CHECK_EQ(face[0], 3);
    CHECK_EQ(face[1], 3);
    CHECK_EQ(face[5], 4);
    CHECK_EQ(face[9], 5);
    ip_mesh_free(&m);
}

/* The bytes of file `path` (at most `capacity`); their count in *size. */
static size_t read_file(const char *path, unsigned char *buf, size_t capacity)
{
    FILE *f = fopen(path, "rb");
    REQUIRE(f);
    size_t size = fread(buf, 1, capacity, f);
    fclose(f);
    return size;
}

/* path[4200]: `name` in the test's scratch folder, removed if it is there. */
static void scratch_path(char *path, const char *name)
{
    snprintf(path, 4200, "%s/%s", test_tmp_dir("test_mesh"), name);
    remove(path);
}

/* Whether no file is at `path`. */
static int no_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (f)
        fclose(f);
    return f == NULL;
}

/* Binary STL and OBJ of two triangles, by extension through ip_mesh_write(): sizes, corners,
 * face normals, indices; an unknown extension is refused and writes nothing. */
static void test_stl_obj(void)
{
    char stl[4200], obj[4200], bad[4200];
    scratch_path(stl, "two.STL");
    scratch_path(obj, "two.obj");
    scratch_path(bad, "two.off");
    float p[18];
    ip_mesh m;
    two_triangles(&m, p);
    ip_error err;
    CHECK_STR_EQ(ip_mesh_format_of(stl), "STL");
    CHECK_STR_EQ(ip_mesh_format_of(obj), "OBJ");
    CHECK_EQ(ip_mesh_format_of(bad), NULL);
    CHECK_EQ(ip_mesh_format_of(".stl"), NULL);
    REQUIRE(ip_mesh_write(&m, stl, 0, &err) == IP_OK);
    REQUIRE(ip_mesh_write(&m, obj, 0, &err) == IP_OK);
    if (CHECK_EQ(ip_mesh_write(&m, bad, 0, &err), IP_ERR_ARGUMENT))
        CHECK_CONTAINS(err.message, "two.off");
    CHECK(no_file(bad));

    static unsigned char buf[4096];
    size_t size = read_file(stl, buf, sizeof buf);
    CHECK_EQ(size, 84 + 2 * 50);
    CHECK_NE(memcmp(buf, "solid", 5), 0);
    CHECK_EQ(buf[80], 2);
    CHECK_EQ(buf[81], 0);
    CHECK_EQ(buf[82], 0);
    CHECK_EQ(buf[83], 0);
    for (int t = 0; t < 2; t++) {
        const unsigned char *r = buf + 84 + 50 * t;
        float a[3], b[3], c[3], nx = ip__load_f32le(r), ny = ip__load_f32le(r + 4),
                                nz = ip__load_f32le(r + 8);
        for (int k = 0; k < 9; k++)
            CHECK_EQ(ip__load_f32le(r + 12 + 4 * k), p[9 * t + k]);
        for (int k = 0; k < 3; k++) {
            a[k] = p[9 * t + k];
            b[k] = p[9 * t + 3 + k] - a[k];
            c[k] = p[9 * t + 6 + k] - a[k];
        }
        /* the face normal is unit length and at right angles to both edges */
        CHECK_LT(fabsf(nx * nx + ny * ny + nz * nz - 1.0f), 1e-5f);
        CHECK_LT(fabsf(nx * b[0] + ny * b[1] + nz * b[2]), 1e-4f);
        CHECK_LT(fabsf(nx * c[0] + ny * c[1] + nz * c[2]), 1e-4f);
    }

    size = read_file(obj, buf, sizeof buf - 1);
    buf[size] = 0;
    int v = 0, vn = 0, faces = 0;
    for (char *line = strtok((char *)buf, "\n"); line; line = strtok(NULL, "\n")) {
        float x, y, z;
        if (sscanf(line, "v %f %f %f", &x, &y, &z) == 3) {
            CHECK_EQ(x, p[3 * v]);
            CHECK_EQ(y, p[3 * v + 1]);
            CHECK_EQ(z, p[3 * v + 2]);
            v++;
        } else if (strncmp(line, "vn ", 3) == 0) {
            vn++;
        } else if (line[0] == 'f') {
            unsigned a, b, c, a2, b2, c2;
            CHECK_EQ(sscanf(line, "f %u//%u %u//%u %u//%u", &a, &a2, &b, &b2, &c, &c2), 6);
            CHECK_EQ(a, 3u * (unsigned)faces + 1);
            CHECK_EQ(b, a + 1);
            CHECK_EQ(c, a + 2);
            CHECK_EQ(a2, a);
            faces++;
        }
    }
    CHECK_EQ(v, 6);
    CHECK_EQ(vn, 6);
    CHECK_EQ(faces, 2);
    ip_mesh_free(&m);
}

/* The number after `key` ("\"count\":") at or after `from` in json; -1 when absent. */
static long long json_number(const char *from, const char *key)
{
    const char *p = strstr(from, key);
    return p ? strtoll(p + strlen(key), NULL, 10) : -1;
}

/* A .glb read back: header, chunks, and the JSON's buffer, views and accessors. */
typedef struct glb_file {
    const char *json;         /* the JSON chunk, terminated */
    const unsigned char *bin; /* the binary chunk's data, NULL when none */
    uint32_t bin_length;
    long long count[3]; /* the accessors' counts: positions, normals, indices (-1: none) */
    float min[3], max[3];
} glb_file;

/* Checks the container of the file in buf[size] and reads it into g. */
static void read_glb(unsigned char *buf, size_t size, glb_file *g)
{
    memset(g, 0, sizeof *g);
    REQUIRE(size >= 20);
    CHECK_MEM_EQ(buf, "glTF", 4);
    CHECK_EQ(ip__load_u32le(buf + 4), 2);
    CHECK_MSG(ip__load_u32le(buf + 8) == size, "header length %u, file %zu",
              (unsigned)ip__load_u32le(buf + 8), size);
    uint32_t json_length = ip__load_u32le(buf + 12);
    CHECK_EQ(json_length % 4, 0);
    CHECK_MEM_EQ(buf + 16, "JSON", 4);
    REQUIRE(20 + (size_t)json_length <= size);
    size_t end = 20 + json_length;
    if (end < size) {
        REQUIRE(end + 8 <= size);
        g->bin_length = ip__load_u32le(buf + end);
        CHECK_MEM_EQ(buf + end + 4, "BIN\0", 4);
        CHECK_EQ(g->bin_length % 4, 0);
        CHECK_EQ(end + 8 + g->bin_length, size);
        g->bin = buf + end + 8;
    }
    char *json = (char *)buf + 16; /* over the chunk header, now read: room for a terminator */
    memmove(json, buf + 20, json_length);
    json[json_length] = 0;
    g->json = json;
    CHECK_CONTAINS(json, "\"version\":\"2.0\"");
    CHECK_CONTAINS(json, "\"generator\":\"isoprop ");
    const char *accessors = strstr(json, "\"accessors\":");
    for (int i = 0; i < 3; i++)
        g->count[i] = -1;
    if (!accessors)
        return;
    const char *a = accessors;
    for (int i = 0; i < 3 && (a = strstr(a, "{\"bufferView\":")); i++, a++)
        g->count[i] = json_number(a, "\"count\":");
    const char *min = strstr(accessors, "\"min\":["), *max = strstr(accessors, "\"max\":[");
    REQUIRE(min && max);
    CHECK_EQ(sscanf(min, "\"min\":[%f,%f,%f]", &g->min[0], &g->min[1], &g->min[2]), 3);
    CHECK_EQ(sscanf(max, "\"max\":[%f,%f,%f]", &g->max[0], &g->max[1], &g->max[2]), 3);
    CHECK_EQ(json_number(json, "\"buffers\":[{\"byteLength\":"), g->bin_length);
}

/* Compares a .glb's vertices (and indices, if any) with those expected: positions exactly,
 * normals within packing, unit length; min and max those of the positions. */
static void check_glb_arrays(const glb_file *g, const float *positions, const int16_t *normals,
                             uint64_t vertices, const uint32_t *indices, uint64_t triangles)
{
    CHECK_EQ(g->count[0], (long long)vertices);
    CHECK_EQ(g->count[1], (long long)vertices);
    CHECK_EQ(g->count[2], indices ? (long long)(3 * triangles) : -1);
    CHECK_EQ(g->bin_length, 24 * vertices + (indices ? 12 * triangles : 0));
    CHECK_EQ(json_number(g->json, "\"mode\":"), 4);
    CHECK_EQ(strstr(g->json, "\"indices\":2") != NULL, indices != NULL);
    int same = 1;
    for (uint64_t i = 0; i < vertices; i++) {
        float length = 0;
        for (int k = 0; k < 3; k++) {
            float p = ip__load_f32le(g->bin + 12 * i + 4 * (uint64_t)k);
            float n = ip__load_f32le(g->bin + 12 * (vertices + i) + 4 * (uint64_t)k);
            same &= p == positions[3 * i + (uint64_t)k] && p >= g->min[k] && p <= g->max[k];
            same &= fabsf(n - ip_normal_unpack(normals[3 * i + (uint64_t)k])) < 1e-4f;
            length += n * n;
        }
        same &= fabsf(length - 1.0f) < 1e-6f;
    }
    for (int k = 0; k < 3; k++) { /* the bounds are reached */
        int low = 0, high = 0;
        for (uint64_t i = 0; i < vertices; i++) {
            low |= positions[3 * i + (uint64_t)k] == g->min[k];
            high |= positions[3 * i + (uint64_t)k] == g->max[k];
        }
        same &= low && high;
    }
    for (uint64_t i = 0; indices && i < 3 * triangles; i++)
        same &= ip__load_u32le(g->bin + 24 * vertices + 4 * i) == indices[i];
    CHECK_MSG(same, "the .glb's arrays differ from the mesh");
}

/* Binary glTF of a soup and of its welded mesh, and of an empty mesh, read back. */
static void test_glb(void)
{
    char soup_path[4200], welded_path[4200], empty_path[4200];
    scratch_path(soup_path, "soup.glb");
    scratch_path(welded_path, "welded.GLB");
    scratch_path(empty_path, "empty.glb");
    /* a fan of 5 triangles around a centre: 15 corners, 7 vertices */
    ip_mesh m;
    ip_mesh_init(&m);
    for (int t = 0; t < 5; t++) {
        float p[9] = {0.5f, -1.25f, 3};
        float n[9];
        for (int k = 1; k < 3; k++) {
            double angle = (t + k - 1) * 0.7;
            p[3 * k] = 0.5f + (float)cos(angle);
            p[3 * k + 1] = -1.25f + (float)sin(angle);
            p[3 * k + 2] = 3 + 0.1f * (float)(t + k);
        }
        for (int k = 0; k < 9; k++)
            n[k] = k % 3 == 2 ? 0.8f : k % 3 == 0 ? 0.6f : 0.0f;
        REQUIRE(ip_mesh_append_float_normals(&m, p, n, NULL, 1) == IP_OK);
    }
    ip_error err;
    CHECK_STR_EQ(ip_mesh_format_of(welded_path), "GLB");
    REQUIRE(ip_mesh_write(&m, soup_path, 0, &err) == IP_OK);
    CHECK_EQ(ip_mesh_write_glb(&m, soup_path, 0, &err), IP_ERR_EXISTS);
    static unsigned char buf[1 << 16];
    glb_file g;
    read_glb(buf, read_file(soup_path, buf, sizeof buf), &g);
    check_glb_arrays(&g, m.positions, m.normals, 15, NULL, 5);

    ip_indexed_mesh w;
    REQUIRE(ip_mesh_weld(&m, &w) == IP_OK);
    CHECK_EQ(w.vertex_count, 7);
    CHECK_EQ(w.triangle_count, 5);
    REQUIRE(ip_indexed_mesh_write(&w, welded_path, 0, &err) == IP_OK);
    read_glb(buf, read_file(welded_path, buf, sizeof buf), &g);
    check_glb_arrays(&g, w.positions, w.normals, 7, w.indices, 5);

    ip_mesh empty;
    ip_mesh_init(&empty);
    REQUIRE(ip_mesh_write_glb(&empty, empty_path, 0, &err) == IP_OK);
    size_t size = read_file(empty_path, buf, sizeof buf);
    read_glb(buf, size, &g);
    CHECK_EQ(g.bin, NULL);
    CHECK_EQ(g.count[0], -1);
    CHECK_EQ(strstr(g.json, "\"meshes\""), NULL);

    /* a position that is not finite has no place in glTF's bounds: refused, nothing written */
    m.positions[4] = INFINITY;
    remove(soup_path);
    if (CHECK_EQ(ip_mesh_write(&m, soup_path, 0, &err), IP_ERR_ARGUMENT))
        CHECK_CONTAINS(err.message, "soup.glb");
    CHECK(no_file(soup_path));
    ip_indexed_mesh_free(&w);
    ip_mesh_free(&m);
}

/* A welded mesh as PLY and OBJ: shared vertices, faces of indices; STL still a soup. */
static void test_indexed_files(void)
{
    char ply[4200], obj[4200], stl[4200];
    scratch_path(ply, "welded.ply");
    scratch_path(obj, "welded.obj");
    scratch_path(stl, "welded.stl");
    ip_mesh m;
    ip_mesh_init(&m);
    /* a square of two triangles: 4 vertices */
    const float p[18] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 0, 0, 1, 1, 0, 0, 1, 0};
    float n[18];
    for (int k = 0; k < 18; k++)
        n[k] = k % 3 == 2;
    REQUIRE(ip_mesh_append_float_normals(&m, p, n, NULL, 2) == IP_OK);
    ip_indexed_mesh w;
    REQUIRE(ip_mesh_weld(&m, &w) == IP_OK);
    REQUIRE(w.vertex_count == 4);
    ip_error err;
    REQUIRE(ip_indexed_mesh_write(&w, ply, 1, &err) == IP_OK);
    REQUIRE(ip_indexed_mesh_write(&w, obj, 1, &err) == IP_OK);
    REQUIRE(ip_indexed_mesh_write(&w, stl, 1, &err) == IP_OK);

    static unsigned char buf[4096];
    size_t size = read_file(ply, buf, sizeof buf - 1);
    buf[size] = 0;
    const char *end = strstr((const char *)buf, "end_header\n");
    REQUIRE(end);
    CHECK(strstr((const char *)buf, "element vertex 4\n"));
    CHECK(strstr((const char *)buf, "element face 2\n"));
    size_t body = (size_t)(end - (const char *)buf) + strlen("end_header\n");
    CHECK_EQ(size, body + 4 * 24 + 2 * 13);
    const unsigned char *face = buf + body + 4 * 24;
    CHECK_EQ(face[0], 3);
    CHECK_EQ(ip__load_u32le(face + 1), 0);
    CHECK_EQ(ip__load_u32le(face + 5), 1);
    CHECK_EQ(ip__load_u32le(face + 9), 2);
    CHECK_EQ(face[13], 3);
    CHECK_EQ(ip__load_u32le(face + 14), 0);
    CHECK_EQ(ip__load_u32le(face + 18), 2);
    CHECK_EQ(ip__load_u32le(face + 22), 3);
    CHECK_EQ(ip__load_f32le(buf + body + 3 * 24 + 4), 1.0f); /* vertex 3 is (0, 1, 0) */

    size = read_file(obj, buf, sizeof buf - 1);
    buf[size] = 0;
    int v = 0, vn = 0, faces = 0;
    for (char *line = strtok((char *)buf, "\n"); line; line = strtok(NULL, "\n")) {
        v += strncmp(line, "v ", 2) == 0;
        vn += strncmp(line, "vn ", 3) == 0;
        if (line[0] == 'f') {
            unsigned a, b, c, a2, b2, c2;
            CHECK_EQ(sscanf(line, "f %u//%u %u//%u %u//%u", &a, &a2, &b, &b2, &c, &c2), 6);
            CHECK_EQ(a, 1);
            CHECK_EQ(b, faces ? 3u : 2u);
            CHECK_EQ(c, faces ? 4u : 3u);
            CHECK_EQ(a2, a);
            CHECK_EQ(c2, c);
            faces++;
        }
    }
    CHECK_EQ(v, 4);
    CHECK_EQ(vn, 4);
    CHECK_EQ(faces, 2);

    size = read_file(stl, buf, sizeof buf);
    CHECK_EQ(size, 84 + 2 * 50);
    for (int k = 0; k < 9; k++)
        CHECK_EQ(ip__load_f32le(buf + 84 + 50 + 12 + 4 * k), p[9 + k]);
    ip_indexed_mesh_free(&w);
    ip_mesh_free(&m);
}

/* Appends across many populated stretches of the arrays (mesh.c maps them ahead in one system
 * call each) keep every triangle; populating memory keeps its contents. */
static void test_populated_growth(void)
{
    ip_mesh m;
    ip_mesh_init_with_cells(&m);
    float p[9 * 3];
    int16_t n[9 * 3];
    uint64_t cells[3];
    uint64_t total = 0;
    for (uint64_t i = 0; i < 40000; i++) {
        uint64_t count = 1 + i % 3;
        for (uint64_t t = 0; t < count; t++) {
            for (int k = 0; k < 9; k++) {
                p[9 * t + k] = (float)(total + t) + (float)k / 16;
                n[9 * t + k] = (int16_t)((total + t + (uint64_t)k) % 30000);
            }
            cells[t] = (total + t) * 7;
        }
        REQUIRE(ip_mesh_append(&m, p, n, cells, count) == IP_OK);
        total += count;
    }
    int same = m.triangle_count == total;
    for (uint64_t t = 0; same && t < total; t++)
        for (int k = 0; k < 9; k++)
            same &= m.positions[9 * t + k] == (float)t + (float)k / 16 &&
                    m.normals[9 * t + k] == (int16_t)((t + (uint64_t)k) % 30000) &&
                    m.cells[t] == t * 7;
    CHECK_MSG(same, "%llu triangles appended, %llu kept", (unsigned long long)total,
              (unsigned long long)m.triangle_count);
    /* the populated mark: ahead of the triangles, within the arrays, past a clear */
    uint64_t populated = m.populated;
    CHECK_MSG(populated >= total && populated <= m.capacity && populated % 16384 == 0,
              "%llu of %llu triangles populated, %llu allocated", (unsigned long long)populated,
              (unsigned long long)total, (unsigned long long)m.capacity);
    ip_mesh_clear(&m);
    REQUIRE(ip_mesh_append(&m, p, n, cells, 1) == IP_OK);
    CHECK_EQ(m.triangle_count, 1);
    CHECK_EQ(m.cells[0], cells[0]);
    for (uint64_t i = 1; i < total; i++) /* filled again to the same size: nothing asked again */
        REQUIRE(ip_mesh_append(&m, p, n, cells, 1) == IP_OK);
    CHECK_EQ(m.populated, populated);
    /* grown: the mark holds the moved triangles, then goes ahead of them again */
    for (uint64_t before = m.capacity; m.capacity == before;)
        REQUIRE(ip_mesh_append(&m, p, n, cells, 1) == IP_OK);
    CHECK_GT(m.populated, m.triangle_count);
    CHECK_LE(m.populated, m.triangle_count + 16384);
    CHECK_LE(m.populated, m.capacity);

    unsigned char *buffer = malloc(3 << 20);
    REQUIRE(buffer);
    for (size_t i = 0; i < 3 << 20; i += 4096)
        buffer[i] = (unsigned char)(i >> 12);
    ip__memory_populate(buffer + 100, (3 << 20) - 200);
    ip__memory_populate(NULL, 0);
    ip__memory_populate(buffer, 10); /* no whole page inside */
    int kept = 1;
    for (size_t i = 0; i < 3 << 20; i += 4096)
        kept &= buffer[i] == (unsigned char)(i >> 12);
    CHECK_MSG(kept, "ip__memory_populate changed the contents");
    free(buffer);
    ip_mesh_free(&m);
}

/* Whether the `size` bytes at buf hold the text `text`. */
static int holds(const unsigned char *buf, size_t size, const char *text)
{
    size_t n = strlen(text);
    for (size_t i = 0; i + n <= size; i++)
        if (memcmp(buf + i, text, n) == 0)
            return 1;
    return 0;
}

/* The space a mesh file names: in each format, soup and welded; none without a name; a bad
 * name refused with nothing written; the names ip_mesh_space_of() gives. */
static void test_space_named(void)
{
    static const char *const names[] = {"spaced.ply", "spaced.obj", "spaced.stl", "spaced.glb"};
    static const char *const tags[] = {"comment space LPS\n", "# space LPS\n",
                                       "binary STL, space LPS", "\"extras\":{\"space\":\"LPS\"}"};
    float p[18];
    ip_mesh m;
    two_triangles(&m, p);
    ip_indexed_mesh w;
    REQUIRE(ip_mesh_weld(&m, &w) == IP_OK);
    static unsigned char buf[8192];
    ip_error err;
    for (size_t i = 0; i < 4; i++) {
        char path[4200];
        scratch_path(path, names[i]);
        REQUIRE(ip_mesh_write_in(&m, path, "LPS", 0, &err) == IP_OK);
        size_t size = read_file(path, buf, sizeof buf);
        CHECK_MSG(holds(buf, size, tags[i]), "%s: no space tag", names[i]);
        REQUIRE(ip_indexed_mesh_write_in(&w, path, "LPS", 1, &err) == IP_OK);
        size = read_file(path, buf, sizeof buf);
        CHECK_MSG(holds(buf, size, tags[i]), "%s (welded): no space tag", names[i]);
        REQUIRE(ip_mesh_write_in(&m, path, NULL, 1, &err) == IP_OK);
        size = read_file(path, buf, sizeof buf);
        CHECK_MSG(!holds(buf, size, "space"), "%s: a space named without one", names[i]);
        scratch_path(path, names[i]);
        CHECK_EQ(ip_mesh_write_in(&m, path, "R A S", 0, &err), IP_ERR_ARGUMENT);
        CHECK_EQ(ip_mesh_write_in(&m, path, "", 0, &err), IP_ERR_ARGUMENT);
        CHECK_EQ(ip_mesh_write_in(&m, path, "a23456789012345678901234567890123", 0, &err),
                 IP_ERR_ARGUMENT);
        CHECK_EQ(ip_indexed_mesh_write_in(&w, path, "x\"}", 0, &err), IP_ERR_ARGUMENT);
        CHECK(no_file(path));
    }
    ip_orientation o;
    ip_orientation_identity(&o);
    CHECK_STR_EQ(ip_mesh_space_of(&o), "volume");
    o.space = IP_SPACE_RAS;
    CHECK_STR_EQ(ip_mesh_space_of(&o), "RAS");
    o.space = IP_SPACE_LPS;
    CHECK_STR_EQ(ip_mesh_space_of(&o), "LPS");
    ip_indexed_mesh_free(&w);
    ip_mesh_free(&m);
}

/* Into physical space: origin + D p and D n; a reflection also swaps each triangle's second and
 * third vertices, so that it stays counter-clockwise about its normal. */
static void test_to_physical(void)
{
    /* counter-clockwise seen from +z, its normals +z */
    const float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0}, n[9] = {0, 0, 1, 0, 0, 1, 0, 0, 1};
    for (int mirrored = 0; mirrored < 2; mirrored++) {
        ip_mesh m;
        ip_mesh_init(&m);
        REQUIRE(ip_mesh_append_float_normals(&m, p, n, NULL, 1) == IP_OK);
        ip_orientation o;
        ip_orientation_identity(&o);
        o.origin[0] = 10, o.origin[1] = 20, o.origin[2] = 30;
        o.directions[0][0] = mirrored ? -1 : 1; /* x the other way: a reflection */
        ip_mesh_to_physical(&m, &o);
        const float *q = m.positions;
        /* the vertices moved, b and c in each other's place where mirrored */
        const float b[3] = {mirrored ? 9 : 11, 20, 30}, c[3] = {10, 21, 30};
        CHECK(q[0] == 10 && q[1] == 20 && q[2] == 30);
        const float *second = mirrored ? q + 6 : q + 3, *third = mirrored ? q + 3 : q + 6;
        CHECK_MSG(!memcmp(second, b, sizeof b) && !memcmp(third, c, sizeof c), "mirrored %d",
                  mirrored);
        /* counter-clockwise about the normal (still +z) */
        double u[3], w[3];
        for (int a = 0; a < 3; a++)
            u[a] = q[3 + a] - q[a], w[a] = q[6 + a] - q[a];
        CHECK_MSG(u[0] * w[1] - u[1] * w[0] > 0, "mirrored %d: winding", mirrored);
        CHECK_EQ(m.normals[2], 32767);
        ip_mesh_free(&m);
    }
}

static const test_case cases[] = {
    TEST_CASE(test_normal_packing),
    TEST_CASE(test_populated_growth),
    TEST_CASE(test_to_physical),
    TEST_CASE(test_appends),
    TEST_CASE(test_ply),
    TEST_CASE(test_stl_obj),
    TEST_CASE(test_glb),
    TEST_CASE(test_indexed_files),
    TEST_CASE(test_space_named),
};

int main(int argc, char **argv)
{
    return RUN_CASES(argc, argv, cases, "test_mesh");
}

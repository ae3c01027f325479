/* SPDX-License-Identifier: BSD-3-Clause */
/* ply_triangles: the triangles of a binary PLY that isorender wrote (vertices of float
 * x,y,z,nx,ny,nz; faces of 3 int indices), for the end-to-end tests of welding and smoothing.
 *
 *   ply_triangles FILE.ply             one line per triangle: its 3 corners' positions as exact
 *                                      hexadecimal floats, in file order, leaving out triangles
 *                                      with two corners at one position
 *   ply_triangles --topology FILE.ply  "vertices V edges E faces F open O repeated R": the
 *                                      undirected edges, the directed edges whose reverse is
 *                                      missing, and those used twice, by vertex index
 *   ply_triangles --shape FILE.ply     "volume V area A normal_angle D": the enclosed volume
 *                                      (signed, by the divergence theorem: a closed surface's),
 *                                      the area, and the mean angle in degrees between the
 *                                      normals of two triangles sharing an edge (terraces make
 *                                      it large; smoothing makes it smaller)
 *
 * Exit status: 0 done, 1 a file it cannot read, 2 a bad command line.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

typedef struct ply {
    unsigned long long vertices, faces;
    float *positions;  /* 3 per vertex */
    uint32_t *indices; /* 3 per face */
} ply;

static int read_ply(const char *path, ply *p)
{
    FILE *f = fopen(path, "rb");
    char line[256];
    memset(p, 0, sizeof *p);
    while (f && fgets(line, sizeof line, f) && strcmp(line, "end_header\n") != 0) {
        sscanf(line, "element vertex %llu", &p->vertices);
        sscanf(line, "element face %llu", &p->faces);
    }
    p->positions = malloc(3 * p->vertices * sizeof(float) + 1);
    p->indices = malloc(3 * p->faces * sizeof(uint32_t) + 1);
    int ok = f && p->positions && p->indices;
    unsigned char v[24], face[13];
    for (unsigned long long i = 0; ok && i < p->vertices; i++) {
        ok = fread(v, 1, 24, f) == 24;
        for (int k = 0; k < 3; k++)
            p->positions[3 * i + (unsigned long long)k] = ip__load_f32le(v + 4 * k);
    }
    for (unsigned long long t = 0; ok && t < p->faces; t++) {
        ok = fread(face, 1, 13, f) == 13 && face[0] == 3;
        for (int k = 0; ok && k < 3; k++) {
            p->indices[3 * t + (unsigned long long)k] = ip__load_u32le(face + 1 + 4 * k);
            ok = p->indices[3 * t + (unsigned long long)k] < p->vertices;
        }
    }
    if (f)
        fclose(f);
    if (!ok)
        fprintf(stderr, "ply_triangles: %s: not a PLY as isorender writes them\n", path);
    return ok;
}

static void print_triangles(const ply *p)
{
    for (unsigned long long t = 0; t < p->faces; t++) {
        const float *c[3];
        for (int k = 0; k < 3; k++)
            c[k] = p->positions + 3 * (unsigned long long)p->indices[3 * t + (unsigned long long)k];
        if (!memcmp(c[0], c[1], 12) || !memcmp(c[1], c[2], 12) || !memcmp(c[0], c[2], 12))
            continue;
        for (int k = 0; k < 9; k++)
            printf("%a%c", (double)c[k / 3][k % 3], k == 8 ? '\n' : ' ');
    }
}

static int compare_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

static void print_topology(const ply *p)
{
    unsigned long long n = 3 * p->faces, edges = 0, open = 0, repeated = 0;
    uint64_t *directed = malloc(n * sizeof *directed + 1),
             *undirected = malloc(n * sizeof *directed + 1);
    if (!directed || !undirected)
        exit(1);
    for (unsigned long long i = 0; i < n; i++) {
        uint64_t a = p->indices[i], b = p->indices[i % 3 == 2 ? i - 2 : i + 1];
        directed[i] = a << 32 | b;
        undirected[i] = a < b ? a << 32 | b : b << 32 | a;
    }
    qsort(directed, n, sizeof *directed, compare_u64);
    qsort(undirected, n, sizeof *undirected, compare_u64);
    for (unsigned long long i = 0; i < n; i++) {
        uint64_t reverse = (directed[i] & 0xffffffffu) << 32 | directed[i] >> 32;
        open += !bsearch(&reverse, directed, n, sizeof *directed, compare_u64);
        repeated += i > 0 && directed[i] == directed[i - 1];
        edges += i == 0 || undirected[i] != undirected[i - 1];
    }
    printf("vertices %llu edges %llu faces %llu open %llu repeated %llu\n", p->vertices, edges,
           p->faces, open, repeated);
    free(directed);
    free(undirected);
}

/* Face t's normal (the cross product of two edges, counter-clockwise) in n; returns its
 * length, twice the area. */
static double face_normal(const ply *p, uint64_t t, double n[3])
{
    const float *c[3];
    for (int k = 0; k < 3; k++)
        c[k] = p->positions + 3 * (uint64_t)p->indices[3 * t + (uint64_t)k];
    double e1[3], e2[3];
    for (int k = 0; k < 3; k++) {
        e1[k] = (double)c[1][k] - c[0][k];
        e2[k] = (double)c[2][k] - c[0][k];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    return sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

/* The angle in degrees between the normals of faces a and b (0 where one has no area). */
static double normal_angle(const ply *p, uint64_t a, uint64_t b)
{
    double na[3], nb[3];
    double la = face_normal(p, a, na), lb = face_normal(p, b, nb);
    if (la == 0 || lb == 0)
        return 0;
    double c = (na[0] * nb[0] + na[1] * nb[1] + na[2] * nb[2]) / (la * lb);
    return acos(c > 1 ? 1 : c < -1 ? -1 : c) * 180.0 / 3.14159265358979323846;
}

static void print_shape(const ply *p)
{
    double volume = 0, area = 0, angles = 0;
    unsigned long long pairs = 0, n = 3 * p->faces;
    /* (undirected edge, face) pairs, sorted by edge: a shared edge's two faces are adjacent */
    uint64_t(*edge_faces)[2] = malloc(n * sizeof *edge_faces + 1);
    if (!edge_faces)
        exit(1);
    for (uint64_t t = 0; t < p->faces; t++) {
        double nt[3];
        area += face_normal(p, t, nt) / 2;
        const float *c0 = p->positions + 3 * (uint64_t)p->indices[3 * t];
        volume += (c0[0] * nt[0] + c0[1] * nt[1] + c0[2] * nt[2]) / 6;
        for (int k = 0; k < 3; k++) {
            uint64_t a = p->indices[3 * t + (uint64_t)k],
                     b = p->indices[3 * t + (uint64_t)(k + 1) % 3];
            edge_faces[3 * t + (uint64_t)k][0] = a < b ? a << 32 | b : b << 32 | a;
            edge_faces[3 * t + (uint64_t)k][1] = t;
        }
    }
    qsort(edge_faces, n, sizeof *edge_faces, compare_u64); /* by the first of the two */
    for (unsigned long long i = 0; i + 1 < n; i++)
        if (edge_faces[i][0] == edge_faces[i + 1][0] &&
            (i + 2 == n || edge_faces[i + 2][0] != edge_faces[i][0]) &&
            (i == 0 || edge_faces[i - 1][0] != edge_faces[i][0])) {
            angles += normal_angle(p, edge_faces[i][1], edge_faces[i + 1][1]);
            pairs++;
        }
    printf("volume %.6g area %.6g normal_angle %.4f\n", volume, area,
           pairs ? angles / (double)pairs : 0.0);
    free(edge_faces);
}

int main(int argc, char **argv)
{
    int topology = argc == 3 && strcmp(argv[1], "--topology") == 0;
    int shape = argc == 3 && strcmp(argv[1], "--shape") == 0;
    if (argc != 2 + topology + shape) {
        fputs("usage: ply_triangles [--topology | --shape] FILE.ply\n", stderr);
        return 2;
    }
    ply p;
    int ok = read_ply(argv[1 + topology + shape], &p);
    if (ok && topology)
        print_topology(&p);
    else if (ok && shape)
        print_shape(&p);
    else if (ok)
        print_triangles(&p);
    free(p.positions);
    free(p.indices);
    return ok ? 0 : 1;
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* Marching cubes: regenerates the case tables from the face rule, then checks that meshes from
 * many fields are closed and consistently oriented, and that the seeding ray test is exact.
 * "test_mc --emit-table" prints src/engine/mc_table.c; "test_mc --bench N" times a sphere of N^3. */
#include <math.h>
#include <stdint.h>

#include "check.h"
#include "internal.h"
#include "mc.h"

/* ---------------------------------------------------------------------------------------------
 * The generator. It knows only the corner numbering, the edge numbering rule and the ambiguity
 * rule; it traces the surface's outline across the 6 faces, chains the segments into closed
 * outlines and fans each one from a vertex whose diagonals stay off the cell's faces. */

enum {
    RULE_SEPARATE_INSIDE,
    RULE_SEPARATE_OUTSIDE
};

typedef struct generated_case {
    unsigned edge_mask;
    int polygon_count;
    int triangle_count;
    int8_t row[16]; /* edge triples, then -1 */
} generated_case;

/* Edges are numbered by axis, then by their low corner in increasing order. */
static int gen_edge(unsigned c0, unsigned c1)
{
    unsigned low = c0 < c1 ? c0 : c1;
    unsigned axis = (c0 ^ c1) == 1 ? 0 : (c0 ^ c1) == 2 ? 1 : 2;
    int rank = 0;
    for (unsigned c = 0; c < low; c++)
        if (!(c >> axis & 1u))
            rank++;
    return (int)axis * 4 + rank;
}

static int corner_inside(unsigned mc_case, unsigned corner)
{
    return (int)(mc_case >> corner & 1u);
}

/* Twice the corner's position, so that edge midpoints have integer coordinates. */
static void corner_pos2(unsigned corner, int out[3])
{
    for (int a = 0; a < 3; a++)
        out[a] = 2 * (int)(corner >> a & 1u);
}

static void edge_mid2(unsigned c0, unsigned c1, int out[3])
{
    int p0[3], p1[3];
    corner_pos2(c0, p0);
    corner_pos2(c1, p1);
    for (int a = 0; a < 3; a++)
        out[a] = (p0[a] + p1[a]) / 2;
}

typedef struct face_segment {
    unsigned from[2], to[2]; /* the corner pairs of the edges it joins */
    int face_axis, face_side;
    unsigned inside_corner;
} face_segment;

/* Orients a segment so that, seen from outside the surface, the polygon it bounds winds
 * counter-clockwise: its direction d must satisfy d . (m x n) > 0, where n is the face's outward
 * normal and m points across the segment from the inside corner toward the outside. */
static int orient_segment(face_segment *s)
{
    int p[3], q[3], c[3], n[3] = {0, 0, 0};
    edge_mid2(s->from[0], s->from[1], p);
    edge_mid2(s->to[0], s->to[1], q);
    corner_pos2(s->inside_corner, c);
    n[s->face_axis] = s->face_side ? 1 : -1;
    int d[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
    int m[3] = {p[0] + q[0] - 2 * c[0], p[1] + q[1] - 2 * c[1], p[2] + q[2] - 2 * c[2]};
    int mxn[3] = {m[1] * n[2] - m[2] * n[1], m[2] * n[0] - m[0] * n[2], m[0] * n[1] - m[1] * n[0]};
    int sign = d[0] * mxn[0] + d[1] * mxn[1] + d[2] * mxn[2];
    if (sign < 0) {
        unsigned t0 = s->from[0], t1 = s->from[1];
        s->from[0] = s->to[0];
        s->from[1] = s->to[1];
        s->to[0] = t0;
        s->to[1] = t1;
    }
    return sign != 0;
}

/* The segments on one face: 0, 1 or (ambiguous face) 2. Returns the count, -1 on failure. */
static int face_segments(unsigned mc_case, int axis, int side, int rule, face_segment out[2])
{
    unsigned u = 1u << ((axis + 1) % 3), v = 1u << ((axis + 2) % 3);
    unsigned base = (unsigned)side << axis;
    unsigned ring[4] = {base, base | u, base | u | v, base | v}; /* cyclic around the face */
    unsigned crossed = 0;
    for (int i = 0; i < 4; i++)
        if (corner_inside(mc_case, ring[i]) != corner_inside(mc_case, ring[(i + 1) % 4]))
            crossed |= 1u << i; /* side i joins ring[i] and ring[i + 1] */
    int count = 0;
    for (int i = 0; i < 4; i++) {
        unsigned corner = ring[i];
        unsigned before = (unsigned)(i + 3) % 4; /* the side entering corner i */
        if (!(crossed >> i & 1u) || !(crossed >> before & 1u))
            continue;
        /* Both sides at this corner are crossed: the segment cuts this corner off. On an
         * ambiguous face all 4 corners qualify, and the rule keeps only one diagonal. */
        int is_inside = corner_inside(mc_case, corner);
        if (crossed == 15 && is_inside != (rule == RULE_SEPARATE_INSIDE))
            continue;
        face_segment *s = &out[count++];
        s->from[0] = ring[before];
        s->from[1] = corner;
        s->to[0] = corner;
        s->to[1] = ring[(i + 1) % 4];
        s->face_axis = axis;
        s->face_side = side;
        s->inside_corner = is_inside ? corner : ring[before];
    }
    if (count == 0 && crossed != 0) {
        /* Two opposite sides crossed: the segment runs between them. */
        int i = (crossed & 1u) ? 0 : 1;
        face_segment *s = &out[count++];
        s->from[0] = ring[i];
        s->from[1] = ring[i + 1];
        s->to[0] = ring[(i + 2) % 4];
        s->to[1] = ring[(i + 3) % 4];
        s->face_axis = axis;
        s->face_side = side;
        s->inside_corner = corner_inside(mc_case, ring[i]) ? ring[i] : ring[i + 1];
    }
    for (int k = 0; k < count; k++)
        if (!orient_segment(&out[k]))
            return -1;
    return count;
}

static void gen_edge_corners(int edge, unsigned corners[2])
{
    for (unsigned a = 0; a < 8; a++)
        for (unsigned b = a + 1; b < 8; b++)
            if (((a ^ b) & ((a ^ b) - 1)) == 0 && gen_edge(a, b) == edge) {
                corners[0] = a;
                corners[1] = b;
            }
}

/* 1 when both edges lie on one face of the cell (their 4 corners agree on some axis bit). */
static int edges_share_face(int e1, int e2)
{
    unsigned c[4] = {0, 0, 0, 0};
    gen_edge_corners(e1, c);
    gen_edge_corners(e2, c + 2);
    for (unsigned axis = 0; axis < 3; axis++) {
        unsigned bits = 0;
        for (int k = 0; k < 4; k++)
            bits |= 1u << (c[k] >> axis & 1u);
        if (bits != 3)
            return 1;
    }
    return 0;
}

/* The first loop position whose fan has no diagonal lying on a cell face. Such a diagonal
 * (possible when both segments of an ambiguous face are on one loop) could be chosen by the
 * neighbour across that face too, and the welded mesh would have 4 triangles on one edge. */
static int fan_apex(const int *loop, int length)
{
    for (int apex = 0; apex < length; apex++) {
        int ok = 1;
        for (int i = 2; i + 1 < length; i++)
            ok &= !edges_share_face(loop[apex], loop[(apex + i) % length]);
        if (ok)
            return apex;
    }
    return -1;
}

/* Builds the case's triangles; returns 0, or -1 when the outlines do not close into loops. */
static int generate_case(unsigned mc_case, int rule, generated_case *g)
{
    int next[12], incoming[12];
    memset(g, 0, sizeof *g);
    memset(g->row, -1, sizeof g->row);
    for (int e = 0; e < 12; e++)
        next[e] = -1, incoming[e] = 0;
    for (unsigned a = 0; a < 8; a++)
        for (unsigned b = a + 1; b < 8; b++)
            if (((a ^ b) & ((a ^ b) - 1)) == 0 &&
                corner_inside(mc_case, a) != corner_inside(mc_case, b))
                g->edge_mask |= 1u << gen_edge(a, b);
    for (int axis = 0; axis < 3; axis++) {
        for (int side = 0; side < 2; side++) {
            face_segment segs[2];
            int count = face_segments(mc_case, axis, side, rule, segs);
            if (count < 0)
                return -1;
            for (int k = 0; k < count; k++) {
                int from = gen_edge(segs[k].from[0], segs[k].from[1]);
                int to = gen_edge(segs[k].to[0], segs[k].to[1]);
                if (next[from] != -1)
                    return -1;
                next[from] = to;
                incoming[to]++;
            }
        }
    }
    int used = 0;
    unsigned visited = 0;
    for (int start = 0; start < 12; start++) {
        if (!(g->edge_mask >> start & 1u) || (visited >> start & 1u))
            continue;
        if (next[start] < 0 || incoming[start] != 1)
            return -1;
        int loop[12], length = 0;
        int e = start;
        do {
            if (e < 0 || incoming[e] != 1 || (visited >> e & 1u))
                return -1;
            visited |= 1u << e;
            loop[length++] = e;
            e = next[e];
        } while (e != start);
        g->polygon_count++;
        int apex = fan_apex(loop, length);
        if (apex < 0)
            return -1;
        for (int i = 1; i + 1 < length; i++) {
            if (used + 3 > 15)
                return -1;
            g->row[used++] = (int8_t)loop[apex];
            g->row[used++] = (int8_t)loop[(apex + i) % length];
            g->row[used++] = (int8_t)loop[(apex + i + 1) % length];
            g->triangle_count++;
        }
    }
    return visited == g->edge_mask ? 0 : -1;
}

static void emit_table(FILE *f)
{
    generated_case g[256];
    for (unsigned c = 0; c < 256; c++)
        REQUIRE(generate_case(c, RULE_SEPARATE_INSIDE, &g[c]) == 0);
    fprintf(f, "/* Marching cubes case tables for the rules stated in src/engine/mc.h.\n"
               " * Generated by tests/test_mc.c (\"test_mc --emit-table\"), which regenerates them"
               " on every\n * test run and compares: edit the generator, not this file. */\n");
    fprintf(f, "#include \"isoprop/mc.h\"\n\n");
    fprintf(f, "const uint8_t ip__mc_edge_corners[12][2] = {\n");
    for (unsigned axis = 0; axis < 3; axis++) {
        fprintf(f, "   ");
        for (unsigned c = 0; c < 8; c++)
            if (!(c >> axis & 1u))
                fprintf(f, " {%u, %u},", c, c | 1u << axis);
        fprintf(f, "\n");
    }
    fprintf(f, "};\n\nconst uint16_t ip__mc_edge_table[256] = {\n");
    for (unsigned c = 0; c < 256; c++)
        fprintf(f, "%s0x%03x,%s", c % 8 == 0 ? "    " : " ", g[c].edge_mask,
                c % 8 == 7 ? "\n" : "");
    fprintf(f, "};\n\nconst uint8_t ip__mc_triangle_count[256] = {\n");
    for (unsigned c = 0; c < 256; c++)
        fprintf(f, "%s%d,%s", c % 16 == 0 ? "    " : " ", g[c].triangle_count,
                c % 16 == 15 ? "\n" : "");
    fprintf(f, "};\n\nconst int8_t ip__mc_triangle_table[256][16] = {\n");
    for (unsigned c = 0; c < 256; c++) {
        fprintf(f, "    /* 0x%02x */ {", c);
        for (int i = 0; i < 16; i++)
            fprintf(f, "%d%s", g[c].row[i], i < 15 ? ", " : "},\n");
    }
    fprintf(f, "};\n");
}

/* ---------------------------------------------------------------------------------------------
 * Table checks. */

static int popcount12(unsigned mask)
{
    int n = 0;
    for (; mask; mask &= mask - 1)
        n++;
    return n;
}

static int has_ambiguous_face(unsigned mc_case)
{
    for (int axis = 0; axis < 3; axis++) {
        for (int side = 0; side < 2; side++) {
            unsigned u = 1u << ((axis + 1) % 3), v = 1u << ((axis + 2) % 3);
            unsigned base = (unsigned)side << axis;
            int a = corner_inside(mc_case, base), b = corner_inside(mc_case, base | u);
            int c = corner_inside(mc_case, base | u | v), d = corner_inside(mc_case, base | v);
            if (a == c && b == d && a != b)
                return 1;
        }
    }
    return 0;
}

static void test_table_matches_generator(void)
{
    for (unsigned a = 0; a < 8; a++)
        for (unsigned b = a + 1; b < 8; b++)
            if (((a ^ b) & ((a ^ b) - 1)) == 0) {
                int e = gen_edge(a, b);
                CHECK_MSG(ip__mc_edge_corners[e][0] == a && ip__mc_edge_corners[e][1] == b,
                          "edge %d", e);
            }
    int max_triangles = 0;
    for (unsigned c = 0; c < 256; c++) {
        generated_case g;
        CHECK_MSG(generate_case(c, RULE_SEPARATE_INSIDE, &g) == 0, "case 0x%02x does not close", c);
        CHECK_MSG(ip__mc_edge_table[c] == g.edge_mask, "case 0x%02x edge mask", c);
        CHECK_MSG(ip__mc_triangle_count[c] == g.triangle_count, "case 0x%02x count", c);
        CHECK_MSG(memcmp(ip__mc_triangle_table[c], g.row, sizeof g.row) == 0, "case 0x%02x row", c);
        if (g.triangle_count > max_triangles)
            max_triangles = g.triangle_count;
    }
    CHECK_EQ(max_triangles, IP_MC_MAX_TRIANGLES);
}

/* Within one cell, a triangle side joining two edges of one face is an outline segment and is
 * used once (its other use is in the neighbour across the face); any other side is a diagonal,
 * used twice in opposite directions. */
static int row_edges_manifold(const int8_t *row, int count)
{
    int uses[12][12];
    memset(uses, 0, sizeof uses);
    for (int i = 0; i < 3 * count; i += 3)
        for (int k = 0; k < 3; k++)
            uses[row[i + k]][row[i + (k + 1) % 3]]++;
    for (int a = 0; a < 12; a++)
        for (int b = 0; b < 12; b++) {
            if (a == b || (uses[a][b] == 0 && uses[b][a] == 0))
                continue;
            int on_face = edges_share_face(a, b);
            if (on_face && uses[a][b] + uses[b][a] != 1)
                return 0;
            if (!on_face && (uses[a][b] != 1 || uses[b][a] != 1))
                return 0;
        }
    return 1;
}

static void test_case_counts(void)
{
    int complement_equal = 0, complement_differs = 0;
    for (unsigned c = 0; c < 256; c++) {
        generated_case g, other_rule;
        REQUIRE(generate_case(c, RULE_SEPARATE_INSIDE, &g) == 0);
        REQUIRE(generate_case(c, RULE_SEPARATE_OUTSIDE, &other_rule) == 0);
        int crossed = popcount12(ip__mc_edge_table[c]);
        int count = ip__mc_triangle_count[c];
        CHECK_MSG(count == crossed - 2 * g.polygon_count, "case 0x%02x: %d != %d - 2 * %d", c,
                  count, crossed, g.polygon_count);
        int filled = 0;
        while (filled < 16 && ip__mc_triangle_table[c][filled] >= 0)
            filled++;
        CHECK_MSG(filled == 3 * count, "case 0x%02x: row holds %d entries", c, filled);
        unsigned used = 0;
        int bad = 0;
        for (int t = 0; t < count; t++) {
            const int8_t *tri = &ip__mc_triangle_table[c][3 * t];
            for (int k = 0; k < 3; k++) {
                bad |= tri[k] < 0 || tri[k] >= 12 || !(ip__mc_edge_table[c] >> tri[k] & 1u);
                used |= 1u << tri[k];
            }
            bad |= tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2];
        }
        CHECK_MSG(!bad && used == ip__mc_edge_table[c], "case 0x%02x: triangle edges", c);
        CHECK_MSG(row_edges_manifold(ip__mc_triangle_table[c], count),
                  "case 0x%02x: a diagonal on a face", c);
        /* The complement has the same crossed edges; with no ambiguous face it is the same
         * outline reversed. With one, it is the case's outline under the opposite rule. */
        CHECK_EQ(ip__mc_edge_table[255 - c], ip__mc_edge_table[c]);
        CHECK_MSG(ip__mc_triangle_count[255 - c] == other_rule.triangle_count,
                  "case 0x%02x: complement %d, opposite rule %d", c, ip__mc_triangle_count[255 - c],
                  other_rule.triangle_count);
        if (!has_ambiguous_face(c)) {
            CHECK_MSG(ip__mc_triangle_count[255 - c] == count, "case 0x%02x complement", c);
            complement_equal++;
        } else if (ip__mc_triangle_count[255 - c] != count) {
            complement_differs++;
        }
        unsigned faces = 0;
        for (int f = 0; f < 6; f++) {
            unsigned mask = 0;
            for (unsigned k = 0; k < 8; k++)
                if ((int)(k >> (f / 2) & 1u) == (f & 1))
                    mask |= 1u << k;
            if ((c & mask) != 0 && (c & mask) != mask)
                faces |= 1u << f;
        }
        CHECK_MSG(ip__mc_crossed_faces(c) == faces, "case 0x%02x faces", c);
    }
    printf("complement: %d cases without an ambiguous face match; %d cases with one differ\n",
           complement_equal, complement_differs);
    CHECK_EQ(complement_equal, 136);
    CHECK_EQ(complement_differs, 88); /* as stated in mc.h */
}

/* ---------------------------------------------------------------------------------------------
 * Meshes over whole grids. */

#define GRID 32

typedef struct grid {
    float v[GRID][GRID][GRID]; /* [z][y][x] */
    float g[GRID][GRID][GRID][3];
} grid;

/* The grid the extraction cases fill (setup), too large for the stack. */
static grid *the_grid;

typedef struct mesh_report {
    long triangles;
    long bad_vertices;   /* off their edge, NaN, or a normal that is not unit length */
    long open_edges;     /* a directed edge without its reverse */
    long repeated_edges; /* a directed edge used twice */
    long split_vertices; /* a grid edge's vertex with other bits in another cell */
    long ambiguous_faces;
    long inward;  /* sphere only: triangles or normals facing the centre */
    long slivers; /* sphere only: too thin to orient numerically */
} mesh_report;

static uint64_t next_random(uint64_t *state)
{
    uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static double random_unit(uint64_t *state)
{
    return (double)(next_random(state) >> 11) / 9007199254740992.0;
}

/* Samples on the volume's boundary are forced outside, so every surface is closed. */
static void close_boundary(grid *gr, float outside)
{
    for (int z = 0; z < GRID; z++)
        for (int y = 0; y < GRID; y++)
            for (int x = 0; x < GRID; x++)
                if (x == 0 || y == 0 || z == 0 || x == GRID - 1 || y == GRID - 1 || z == GRID - 1)
                    gr->v[z][y][x] = outside;
}

static void central_gradients(grid *gr)
{
    for (int z = 0; z < GRID; z++)
        for (int y = 0; y < GRID; y++)
            for (int x = 0; x < GRID; x++) {
                int xl = x > 0 ? x - 1 : x, xh = x < GRID - 1 ? x + 1 : x;
                int yl = y > 0 ? y - 1 : y, yh = y < GRID - 1 ? y + 1 : y;
                int zl = z > 0 ? z - 1 : z, zh = z < GRID - 1 ? z + 1 : z;
                gr->g[z][y][x][0] = (gr->v[z][y][xh] - gr->v[z][y][xl]) / (float)(xh - xl);
                gr->g[z][y][x][1] = (gr->v[z][yh][x] - gr->v[z][yl][x]) / (float)(yh - yl);
                gr->g[z][y][x][2] = (gr->v[zh][y][x] - gr->v[zl][y][x]) / (float)(zh - zl);
            }
}

static int compare_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

static uint64_t grid_edge_id(int x, int y, int z, unsigned edge)
{
    unsigned low = ip__mc_edge_corners[edge][0];
    x += (int)(low & 1u);
    y += (int)(low >> 1 & 1u);
    z += (int)(low >> 2 & 1u);
    return ((uint64_t)((z * GRID + y) * GRID + x)) * 3 + edge / 4;
}

static int vertex_on_edge(const ip_mc_vertex *v, unsigned edge, const float lo[3],
                          const float hi[3])
{
    unsigned low = ip__mc_edge_corners[edge][0];
    for (unsigned a = 0; a < 3; a++) {
        if (!isfinite(v->position[a]) || !isfinite(v->normal[a]))
            return 0;
        if (a == edge / 4) {
            if (v->position[a] < lo[a] || v->position[a] > hi[a])
                return 0;
        } else if (v->position[a] != ((low >> a & 1u) ? hi[a] : lo[a])) {
            return 0;
        }
    }
    float n2 =
        v->normal[0] * v->normal[0] + v->normal[1] * v->normal[1] + v->normal[2] * v->normal[2];
    return fabsf(n2 - 1.0f) < 1e-4f;
}

static void count_ambiguous_faces(const float values[8], float iso, mesh_report *r)
{
    unsigned c = ip__mc_case(values, iso);
    /* Only the low faces, so that each grid face is counted once. */
    static const unsigned low_faces[3][4] = {{0, 2, 6, 4}, {0, 4, 5, 1}, {0, 1, 3, 2}};
    for (int f = 0; f < 3; f++) {
        int a = corner_inside(c, low_faces[f][0]), b = corner_inside(c, low_faces[f][1]);
        int cc = corner_inside(c, low_faces[f][2]), d = corner_inside(c, low_faces[f][3]);
        r->ambiguous_faces += a == cc && b == d && a != b;
    }
}

static void check_sphere_triangle(const ip_mc_vertex *t, const double centre[3], mesh_report *r)
{
    double e1[3], e2[3], n[3], radial[3];
    for (int a = 0; a < 3; a++) {
        e1[a] = (double)t[1].position[a] - t[0].position[a];
        e2[a] = (double)t[2].position[a] - t[0].position[a];
        radial[a] =
            ((double)t[0].position[a] + t[1].position[a] + t[2].position[a]) / 3.0 - centre[a];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    double area2 = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (area2 < 1e-6)
        r->slivers++;
    else if (n[0] * radial[0] + n[1] * radial[1] + n[2] * radial[2] <= 0.0)
        r->inward++;
    for (int k = 0; k < 3; k++) {
        double dot = 0.0;
        for (int a = 0; a < 3; a++)
            dot += t[k].normal[a] * ((double)t[k].position[a] - centre[a]);
        r->inward += dot <= 0.0;
    }
}

/* Counts a vertex on grid edge `id` whose position differs in its bits from the one another
 * cell put there (at[id], set[id] once one did). */
static void check_same_bits(float (*at)[3], unsigned char *set, uint64_t id, const float p[3],
                            mesh_report *r)
{
    if (set[id])
        r->split_vertices += memcmp(at[id], p, sizeof at[id]) != 0;
    memcpy(at[id], p, sizeof at[id]);
    set[id] = 1;
}

/* Triangulates every cell, welds vertices by grid edge and checks the mesh is closed and
 * consistently oriented: every directed edge once, and its reverse once; and that the cells
 * sharing a grid edge put its vertex at the same bits (what welding by position relies on). */
static mesh_report mesh_grid_at(const grid *gr, float iso, int use_gradients, const float size[3],
                                float shift, const double *sphere_centre)
{
    float(*at)[3] = malloc((size_t)GRID * GRID * GRID * 3 * sizeof *at);
    unsigned char *set = calloc((size_t)GRID * GRID * GRID * 3, 1);
    REQUIRE(at && set);
    mesh_report r;
    memset(&r, 0, sizeof r);
    size_t capacity = 1 << 16, used = 0;
    uint64_t *edges = malloc(capacity * sizeof *edges);
    REQUIRE(edges);
    for (int z = 0; z + 1 < GRID; z++)
        for (int y = 0; y + 1 < GRID; y++)
            for (int x = 0; x + 1 < GRID; x++) {
                float values[8], grads[8][3];
                for (unsigned c = 0; c < 8; c++) {
                    int cx = x + (int)(c & 1u), cy = y + (int)(c >> 1 & 1u), cz = z + (int)(c >> 2);
                    values[c] = gr->v[cz][cy][cx];
                    memcpy(grads[c], gr->g[cz][cy][cx], sizeof grads[c]);
                }
                count_ambiguous_faces(values, iso, &r);
                float lo[3] = {((float)x - shift) * size[0], ((float)y - shift) * size[1],
                               ((float)z - shift) * size[2]};
                float hi[3] = {((float)x + 1 - shift) * size[0], ((float)y + 1 - shift) * size[1],
                               ((float)z + 1 - shift) * size[2]};
                ip_mc_vertex out[IP_MC_MAX_VERTICES];
                int n =
                    ip__mc_triangulate_cell(values, use_gradients ? grads : NULL, iso, lo, hi, out);
                unsigned c = ip__mc_case(values, iso);
                REQUIRE(n == ip__mc_triangle_count[c]);
                if (used + 3 * (size_t)n > capacity) {
                    capacity *= 2;
                    edges = realloc(edges, capacity * sizeof *edges);
                    REQUIRE(edges);
                }
                for (int t = 0; t < n; t++) {
                    uint64_t id[3];
                    for (int k = 0; k < 3; k++) {
                        unsigned e = (unsigned)ip__mc_triangle_table[c][3 * t + k];
                        id[k] = grid_edge_id(x, y, z, e);
                        r.bad_vertices += !vertex_on_edge(&out[3 * t + k], e, lo, hi);
                        check_same_bits(at, set, id[k], out[3 * t + k].position, &r);
                    }
                    for (int k = 0; k < 3; k++)
                        edges[used++] = id[k] << 32 | id[(k + 1) % 3];
                    if (sphere_centre)
                        check_sphere_triangle(&out[3 * t], sphere_centre, &r);
                }
                r.triangles += n;
            }
    qsort(edges, used, sizeof *edges, compare_u64);
    for (size_t i = 0; i < used; i++) {
        if (i + 1 < used && edges[i] == edges[i + 1])
            r.repeated_edges++;
        uint64_t reverse = (edges[i] & 0xffffffffu) << 32 | edges[i] >> 32;
        if (!bsearch(&reverse, edges, used, sizeof *edges, compare_u64))
            r.open_edges++;
    }
    free(edges);
    free(at);
    free(set);
    return r;
}

/* mesh_grid_at() with sample (0, 0, 0) at the origin. */
static mesh_report mesh_grid(const grid *gr, float iso, int use_gradients, const float size[3],
                             const double *sphere_centre)
{
    return mesh_grid_at(gr, iso, use_gradients, size, 0.0f, sphere_centre);
}

static void check_closed(const char *name, const mesh_report *r, long min_triangles)
{
    printf("%-22s %7ld triangles, %6ld ambiguous faces, %ld open, %ld repeated, %ld bad vertices, "
           "%ld split\n",
           name, r->triangles, r->ambiguous_faces, r->open_edges, r->repeated_edges,
           r->bad_vertices, r->split_vertices);
    CHECK_MSG(r->triangles >= min_triangles, "%s: only %ld triangles", name, r->triangles);
    CHECK_MSG(r->open_edges == 0, "%s: %ld open edges", name, r->open_edges);
    CHECK_MSG(r->repeated_edges == 0, "%s: %ld repeated edges", name, r->repeated_edges);
    CHECK_MSG(r->bad_vertices == 0, "%s: %ld bad vertices", name, r->bad_vertices);
    CHECK_MSG(r->split_vertices == 0, "%s: %ld vertices at other bits in a neighbour", name,
              r->split_vertices);
}

static double sphere_value(double x, double y, double z, const double c[3], double radius)
{
    double dx = x - c[0], dy = y - c[1], dz = z - c[2];
    return radius - sqrt(dx * dx + dy * dy + dz * dz);
}

static void test_sphere(void)
{
    grid *gr = the_grid;
    const double centre[3] = {15.37, 16.11, 15.73};
    for (int z = 0; z < GRID; z++)
        for (int y = 0; y < GRID; y++)
            for (int x = 0; x < GRID; x++)
                gr->v[z][y][x] = (float)sphere_value(x, y, z, centre, 11.3);
    central_gradients(gr);
    const float unit[3] = {1, 1, 1};
    for (int use_gradients = 0; use_gradients < 2; use_gradients++) {
        mesh_report r = mesh_grid(gr, 0.0f, use_gradients, unit, centre);
        check_closed(use_gradients ? "sphere (gradients)" : "sphere", &r, 2000);
        printf("%-22s %ld facing inward, %ld slivers\n", "", r.inward, r.slivers);
        CHECK_MSG(r.inward == 0, "sphere: %ld triangles or normals face inward", r.inward);
        CHECK_LT(r.slivers, r.triangles / 100);
    }
    /* Topology does not depend on the cell's shape. */
    const float stretched[3] = {0.5f, 1.75f, 1.25f};
    mesh_report r = mesh_grid(gr, 0.0f, 0, stretched, NULL);
    check_closed("sphere (anisotropic)", &r, 2000);
    /* Spacings with no exact float, and the world's zero inside the sphere: near zero,
     * lo + (hi - lo) need not round to hi, which the neighbour uses as its lo; shared vertices
     * must still come out at the same bits. */
    const float inexact[3] = {0.1f, 0.3f, 0.7f};
    r = mesh_grid_at(gr, 0.0f, 1, inexact, 15.45f, NULL);
    check_closed("sphere (inexact spacing)", &r, 2000);
}

static void test_touching_spheres(void)
{
    grid *gr = the_grid;
    /* Centres along a face diagonal, touching at the centre of a cell face: the face's two
     * diagonal corners fall one in each sphere and the other two just outside both. */
    const double d = 3.5, radius = d * sqrt(2.0);
    const double a[3] = {15.5 - d, 15.5 - d, 15.0}, b[3] = {15.5 + d, 15.5 + d, 15.0};
    for (int z = 0; z < GRID; z++)
        for (int y = 0; y < GRID; y++)
            for (int x = 0; x < GRID; x++) {
                double va = sphere_value(x, y, z, a, radius), vb = sphere_value(x, y, z, b, radius);
                gr->v[z][y][x] = (float)(va > vb ? va : vb);
            }
    const float unit[3] = {1, 1, 1};
    mesh_report r = mesh_grid(gr, 0.0f, 0, unit, NULL);
    check_closed("touching spheres", &r, 500);
    CHECK_GT(r.ambiguous_faces, 0);
    r = mesh_grid(gr, -0.1f, 0, unit, NULL);
    check_closed("merged spheres", &r, 500);
    r = mesh_grid(gr, 0.1f, 0, unit, NULL);
    check_closed("nearly touching", &r, 500);
}

static void test_gyroid(void)
{
    grid *gr = the_grid;
    const double k = 2.0 * 3.14159265358979 / 9.7;
    for (int z = 0; z < GRID; z++)
        for (int y = 0; y < GRID; y++)
            for (int x = 0; x < GRID; x++)
                gr->v[z][y][x] = (float)(sin(k * x) * cos(k * y) + sin(k * y) * cos(k * z) +
                                         sin(k * z) * cos(k * x));
    close_boundary(gr, -10.0f);
    central_gradients(gr);
    const float unit[3] = {1, 1, 1};
    mesh_report r = mesh_grid(gr, 0.3f, 1, unit, NULL);
    check_closed("gyroid", &r, 5000);
}

static void test_random(void)
{
    grid *gr = the_grid;
    for (uint64_t seed = 1; seed <= 3; seed++) {
        uint64_t state = seed;
        for (int z = 0; z < GRID; z++)
            for (int y = 0; y < GRID; y++)
                for (int x = 0; x < GRID; x++)
                    gr->v[z][y][x] = (float)random_unit(&state);
        close_boundary(gr, 0.0f);
        central_gradients(gr);
        const float unit[3] = {1, 1, 1};
        mesh_report r = mesh_grid(gr, 0.5f, seed == 2, unit, NULL);
        char name[32];
        snprintf(name, sizeof name, "random (seed %d)", (int)seed);
        check_closed(name, &r, 20000);
        CHECK_MSG(r.ambiguous_faces > 5000, "%ld ambiguous faces", r.ambiguous_faces);
    }
}

/* Many samples exactly equal to iso: vertices land on corners, triangles collapse, yet the
 * welded mesh must still be closed and free of NaN. */
static void test_values_equal_to_iso(void)
{
    grid *gr = the_grid;
    const double centre[3] = {15.5, 15.2, 16.0};
    for (int z = 0; z < GRID; z++)
        for (int y = 0; y < GRID; y++)
            for (int x = 0; x < GRID; x++)
                gr->v[z][y][x] = floorf((float)sphere_value(x, y, z, centre, 10.0) * 0.5f) * 2.0f;
    const float unit[3] = {1, 1, 1};
    long at_iso = 0;
    for (int z = 0; z < GRID; z++)
        for (int y = 0; y < GRID; y++)
            for (int x = 0; x < GRID; x++)
                at_iso += gr->v[z][y][x] == 2.0f;
    CHECK_GT(at_iso, 1000);
    mesh_report r = mesh_grid(gr, 2.0f, 0, unit, NULL);
    check_closed("quantised sphere", &r, 1000);

    uint64_t state = 99;
    for (int z = 0; z < GRID; z++)
        for (int y = 0; y < GRID; y++)
            for (int x = 0; x < GRID; x++)
                gr->v[z][y][x] = (float)(next_random(&state) % 3);
    close_boundary(gr, 0.0f);
    central_gradients(gr);
    r = mesh_grid(gr, 1.0f, 1, unit, NULL);
    check_closed("random {0,1,2} at 1", &r, 20000);

    /* The whole interior exactly at iso: a closed box whose vertices all sit on corners. */
    for (int z = 0; z < GRID; z++)
        for (int y = 0; y < GRID; y++)
            for (int x = 0; x < GRID; x++)
                gr->v[z][y][x] = 1.0f;
    close_boundary(gr, 0.0f);
    r = mesh_grid(gr, 1.0f, 0, unit, NULL);
    check_closed("flat box at iso", &r, 1000);
}

/* Samples that are NaN or infinite must still give finite positions and unit normals. */
static void test_non_finite_values(void)
{
    const float specials[4] = {NAN, INFINITY, -INFINITY, 0.5f};
    const float origin[3] = {1, 2, 3}, far[3] = {2, 3, 4};
    uint64_t state = 5;
    long bad = 0;
    for (int trial = 0; trial < 20000; trial++) {
        float values[8];
        for (int c = 0; c < 8; c++) {
            uint64_t r = next_random(&state);
            values[c] = (r & 3) == 0 ? specials[(r >> 2) % 4] : (float)random_unit(&state);
        }
        ip_mc_vertex out[IP_MC_MAX_VERTICES];
        int n = ip__mc_triangulate_cell(values, NULL, 0.5f, origin, far, out);
        for (int i = 0; i < 3 * n; i++) {
            unsigned e = (unsigned)ip__mc_triangle_table[ip__mc_case(values, 0.5f)][i];
            bad += !vertex_on_edge(&out[i], e, origin, far);
        }
    }
    CHECK_MSG(bad == 0, "%ld non-finite or misplaced vertices", bad);
}

/* ---------------------------------------------------------------------------------------------
 * Ray tests. */

/* A linear field a . p + b is reproduced exactly by the interpolation, so the cell's surface is
 * the plane itself: a ray hits it inside the cell exactly where the plane equation says. */
static void test_ray_plane(void)
{
    uint64_t state = 17;
    const float origin[3] = {4.0f, -2.0f, 1.0f}, size[3] = {2.0f, 1.0f, 1.5f};
    const float far[3] = {origin[0] + size[0], origin[1] + size[1], origin[2] + size[2]};
    int hits = 0, misses = 0, wrong = 0;
    for (int trial = 0; trial < 20000; trial++) {
        double n[3], p[3], dir[3], start[3];
        for (int a = 0; a < 3; a++) {
            n[a] = random_unit(&state) * 2.0 - 1.0;
            p[a] = origin[a] + size[a] * (random_unit(&state) * 1.4 - 0.2);
            dir[a] = random_unit(&state) * 2.0 - 1.0;
        }
        double offset = -(n[0] * (origin[0] + 0.5 * size[0]) + n[1] * (origin[1] + 0.5 * size[1]) +
                          n[2] * (origin[2] + 0.5 * size[2])) +
                        (random_unit(&state) - 0.5) * 0.5;
        float values[8];
        for (unsigned c = 0; c < 8; c++) {
            double v = offset;
            for (unsigned a = 0; a < 3; a++)
                v += n[a] * (origin[a] + (double)(c >> a & 1u) * size[a]);
            values[c] = (float)v;
        }
        /* The ray passes through p, starting 3 units before it. */
        for (int a = 0; a < 3; a++)
            start[a] = p[a] - 3.0 * dir[a];
        double denom = n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2];
        double num = -(offset + n[0] * start[0] + n[1] * start[1] + n[2] * start[2]);
        if (fabs(denom) < 1e-3)
            continue;
        double t = num / denom, hit[3];
        int inside = t >= 0.0, margin_ok = 1;
        for (int a = 0; a < 3; a++) {
            hit[a] = start[a] + t * dir[a];
            double rel = (hit[a] - origin[a]) / size[a];
            inside &= rel >= 0.0 && rel <= 1.0;
            margin_ok &= fabs(rel) > 1e-3 && fabs(rel - 1.0) > 1e-3;
        }
        if (!margin_ok)
            continue;
        float ro[3] = {(float)start[0], (float)start[1], (float)start[2]};
        float rd[3] = {(float)dir[0], (float)dir[1], (float)dir[2]};
        float t_hit = -1.0f;
        int got = ip__mc_ray_hits_cell(values, 0.0f, origin, far, ro, rd, &t_hit);
        if (inside) {
            hits++;
            wrong += !got || fabs(t_hit - t) > 1e-3 * (1.0 + fabs(t));
        } else {
            misses++;
            wrong += got;
        }
    }
    printf("plane rays: %d hits, %d misses\n", hits, misses);
    CHECK_GT(hits, 1000);
    CHECK_GT(misses, 1000);
    CHECK_MSG(wrong == 0, "%d rays disagree with the plane", wrong);
}

/* The paper's Figure 2: the first active cell on the ray holds only a small cap around one
 * corner, which the ray passes; the real hit is in the next cell. */
static void test_ray_first_active_cell_missed(void)
{
    /* Samples on a 3 x 2 x 2 grid: cell A spans x in [0,1], cell B x in [1,2]. */
    float sample[2][2][3]; /* [z][y][x] */
    for (int z = 0; z < 2; z++)
        for (int y = 0; y < 2; y++) {
            sample[z][y][0] = 0.0f;
            sample[z][y][1] = 0.0f;
            sample[z][y][2] = 1.0f;
        }
    sample[0][0][0] = 1.0f; /* only corner 0 of cell A is inside */
    float cell[2][8];
    for (int k = 0; k < 2; k++)
        for (unsigned c = 0; c < 8; c++)
            cell[k][c] = sample[c >> 2][c >> 1 & 1u][k + (int)(c & 1u)];
    const float origin_a[3] = {0, 0, 0}, origin_b[3] = {2, 0, 0};
    const float far_a[3] = {2, 2, 2}, far_b[3] = {4, 2, 2};
    const float ray_origin[3] = {-1.0f, 1.6f, 1.6f}, ray_dir[3] = {1.0f, 0.0f, 0.0f};
    float t = -1.0f;
    CHECK_EQ(ip__mc_case(cell[0], 0.5f), 0x01);
    CHECK_NE(ip__mc_edge_table[0x01], 0); /* A is active */
    CHECK_EQ(ip__mc_ray_hits_cell(cell[0], 0.5f, origin_a, far_a, ray_origin, ray_dir, &t), 0);
    CHECK_EQ(t, -1.0f);
    CHECK_EQ(ip__mc_ray_hits_cell(cell[1], 0.5f, origin_b, far_b, ray_origin, ray_dir, &t), 1);
    CHECK_NEAR(t, 4.0f, 1e-6f); /* the plane x = 3 */
    CHECK_EQ(ip__mc_ray_hits_cell(cell[1], 0.5f, origin_b, far_b, ray_origin, ray_dir, NULL), 1);
    /* Aimed at the cap instead, the same cell is hit; from behind the ray misses (t < 0). */
    const float at_cap[3] = {-1.0f, 0.2f, 0.2f};
    CHECK_EQ(ip__mc_ray_hits_cell(cell[0], 0.5f, origin_a, far_a, at_cap, ray_dir, &t), 1);
    CHECK_NEAR(t, 1.6f, 1e-5f); /* the cap lies on x + y + z = 1 */
    const float behind[3] = {5.0f, 0.2f, 0.2f};
    CHECK_EQ(ip__mc_ray_hits_cell(cell[0], 0.5f, origin_a, far_a, behind, ray_dir, &t), 0);
}

/* ---------------------------------------------------------------------------------------------
 * Benchmark (not part of the test run). */

/* Times every cell of an n^3 sphere (mostly empty cells), then only its active cells. */
static int bench(int n)
{
    if (n < 2 || n > 1024)
        return 1;
    size_t count = (size_t)n * n * n, cells = (size_t)(n - 1) * (n - 1) * (n - 1);
    float *v = malloc(count * sizeof *v);
    float(*active)[8] = malloc(cells * sizeof *active);
    float(*origins)[6] = malloc(cells * sizeof *origins); /* low and high corners */
    REQUIRE(v && active && origins);
    double c = (n - 1) / 2.0, radius = 0.4 * (n - 1);
    for (int z = 0; z < n; z++)
        for (int y = 0; y < n; y++)
            for (int x = 0; x < n; x++) {
                double dx = x - c, dy = y - c, dz = z - c;
                double r = sqrt(dx * dx + dy * dy + dz * dz);
                v[((size_t)z * n + y) * n + x] = (float)(radius - r);
            }
    const float size[3] = {1, 1, 1};
    ip_mc_vertex out[IP_MC_MAX_VERTICES];
    size_t active_count = 0;
    long triangles = 0;
    double start = ip_now_seconds();
    for (int z = 0; z + 1 < n; z++)
        for (int y = 0; y + 1 < n; y++)
            for (int x = 0; x + 1 < n; x++) {
                float values[8];
                for (unsigned k = 0; k < 8; k++) {
                    size_t row = (size_t)(z + (int)(k >> 2)) * n + (size_t)y + (k >> 1 & 1u);
                    values[k] = v[row * n + (size_t)x + (k & 1u)];
                }
                float origin[3] = {(float)x, (float)y, (float)z};
                float far[3] = {origin[0] + size[0], origin[1] + size[1], origin[2] + size[2]};
                int t = ip__mc_triangulate_cell(values, NULL, 0.0f, origin, far, out);
                triangles += t;
                if (t > 0) {
                    memcpy(active[active_count], values, sizeof values);
                    memcpy(origins[active_count], origin, sizeof origin);
                    memcpy(origins[active_count++] + 3, far, sizeof far);
                }
            }
    double all_seconds = ip_now_seconds() - start;
    const int repeats = 20;
    start = ip_now_seconds();
    long active_triangles = 0;
    for (int r = 0; r < repeats; r++)
        for (size_t i = 0; i < active_count; i++)
            active_triangles +=
                ip__mc_triangulate_cell(active[i], NULL, 0.0f, origins[i], origins[i] + 3, out);
    double active_seconds = ip_now_seconds() - start;
    printf("%d^3 sphere: all %zu cells in %.4f s = %.1f M cells/s (%zu active, %ld triangles); "
           "active cells only: %.1f M cells/s, %.1f M triangles/s\n",
           n, cells, all_seconds, cells / all_seconds / 1e6, active_count, triangles,
           repeats * (double)active_count / active_seconds / 1e6,
           active_triangles / active_seconds / 1e6);
    free(v);
    free(active);
    free(origins);
    return 0;
}

/* ---------------------------------------------------------------------------------------------
 * Frames (mc.h): the table turned by each of the cube's 48 symmetries. */

static const uint8_t permutations[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                           {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};

/* Every row of the turned table crosses the case's edges, keeps its triangle count and puts
 * no diagonal on a face; the identity's rows are the table's. */
static void check_frame_rows(const ip_mc_frame *f, int8_t rows[256][16], const char *name)
{
    int identity = f->axis[0] == 0 && f->axis[1] == 1 && f->axis[2] == 2 && !f->flip[0] &&
                   !f->flip[1] && !f->flip[2];
    if (identity)
        CHECK_MSG(memcmp(rows, ip__mc_triangle_table, sizeof ip__mc_triangle_table) == 0, "%s",
                  name);
    for (unsigned c = 0; c < 256; c++) {
        int count = ip__mc_triangle_count[c], filled = 0;
        unsigned used = 0;
        while (filled < 16 && rows[c][filled] >= 0)
            used |= 1u << rows[c][filled++];
        CHECK_MSG(filled == 3 * count && used == ip__mc_edge_table[c], "%s: case 0x%02x", name, c);
        CHECK_MSG(row_edges_manifold(rows[c], count), "%s: case 0x%02x: a diagonal on a face", name,
                  c);
    }
}

/* Random cells: the world cell's triangles (the turned rows) are those of the same cell in the
 * canonical frame (the table's), corner for corner, wound the same way about the outward
 * normals. */
static void check_frame_cells(const ip_mc_frame *f, int8_t rows[256][16], const char *name,
                              uint64_t *seed)
{
    static const float lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    int bad = 0, reflected = f->flip[0] ^ f->flip[1] ^ f->flip[2];
    int fixed = (f->axis[0] == 0) + (f->axis[1] == 1) + (f->axis[2] == 2);
    reflected ^= fixed == 1;
    for (int n = 0; n < 300 && !bad; n++) {
        float canonical[8], world[8];
        for (unsigned k = 0; k < 8; k++)
            canonical[k] = (float)random_unit(seed);
        for (unsigned k = 0; k < 8; k++) { /* canonical corner k's world corner */
            unsigned j = 0;
            for (unsigned a = 0; a < 3; a++)
                j |= ((k >> f->axis[a] & 1u) ^ f->flip[a]) << a;
            world[j] = canonical[k];
        }
        ip_mc_vertex want[IP_MC_MAX_VERTICES];
        int count = ip__mc_triangulate_cell(canonical, NULL, 0.5f, lo, hi, want);
        unsigned mc = ip__mc_case(world, 0.5f);
        float points[12][3], normals[12][3];
        ip__mc_cell_edge_points(world, mc, 0.5f, lo, hi, points);
        ip__mc_cell_edge_normals(world, mc, NULL, 0.5f, lo, hi, normals);
        bad |= count != ip__mc_triangle_count[mc];
        for (int t = 0; t < count && !bad; t++) {
            double orient[2] = {0, 0}; /* (b - a) x (c - a) . (the vertices' normals) */
            for (int side = 0; side < 2; side++) {
                double v[3][3], m[3] = {0, 0, 0};
                for (int i = 0; i < 3; i++) {
                    int e = rows[mc][3 * t + i];
                    for (unsigned a = 0; a < 3; a++) {
                        v[i][a] = side ? points[e][a] : want[3 * t + i].position[a];
                        m[a] += side ? normals[e][a] : want[3 * t + i].normal[a];
                    }
                    if (side) { /* the world corner back in the canonical frame */
                        double c[3];
                        for (unsigned a = 0; a < 3; a++)
                            c[f->axis[a]] = f->flip[a] ? 1.0 - points[e][a] : points[e][a];
                        int k = reflected && i ? 3 - i : i; /* b and c swap places */
                        for (unsigned a = 0; a < 3; a++)
                            bad |= fabs(c[a] - want[3 * t + k].position[a]) > 1e-6;
                    }
                }
                double u[3], w[3];
                for (unsigned a = 0; a < 3; a++)
                    u[a] = v[1][a] - v[0][a], w[a] = v[2][a] - v[0][a];
                orient[side] = (u[1] * w[2] - u[2] * w[1]) * m[0] +
                               (u[2] * w[0] - u[0] * w[2]) * m[1] +
                               (u[0] * w[1] - u[1] * w[0]) * m[2];
            }
            bad |=
                (orient[0] > 1e-9 && orient[1] < -1e-9) || (orient[0] < -1e-9 && orient[1] > 1e-9);
        }
    }
    CHECK_MSG(!bad, "%s: a cell triangulated otherwise", name);
}

static void test_frames(void)
{
    static int8_t rows[256][16];
    uint64_t seed = 42;
    for (int p = 0; p < 6; p++)
        for (unsigned flips = 0; flips < 8; flips++) {
            ip_mc_frame f;
            char name[64];
            for (int a = 0; a < 3; a++) {
                f.axis[a] = permutations[p][a];
                f.flip[a] = (uint8_t)(flips >> a & 1u);
            }
            snprintf(name, sizeof name, "axes %d%d%d flips %u", f.axis[0], f.axis[1], f.axis[2],
                     flips);
            ip__mc_frame_rows(&f, rows);
            check_frame_rows(&f, rows, name);
            check_frame_cells(&f, rows, name, &seed);
        }
}

/* The frame of an orientation: its axes matched with LPS's (a named space) or the physical
 * ones (none). */
static void test_frame_of(void)
{
    ip_orientation o;
    ip_mc_frame f;
    ip_orientation_identity(&o);
    CHECK_EQ(ip__mc_frame_of(&o, &f), 1); /* no orientation: the table as it is */
    o.space = IP_SPACE_LPS;
    CHECK_EQ(ip__mc_frame_of(&o, &f), 1);
    o.space = IP_SPACE_RAS; /* x right and y anterior run opposite LPS's */
    CHECK_EQ(ip__mc_frame_of(&o, &f), 0);
    CHECK(f.axis[0] == 0 && f.axis[1] == 1 && f.axis[2] == 2);
    CHECK(f.flip[0] && f.flip[1] && !f.flip[2]);
    o.space = IP_SPACE_LAS;
    CHECK_EQ(ip__mc_frame_of(&o, &f), 0);
    CHECK(!f.flip[0] && f.flip[1] && !f.flip[2]);
    /* no space: the physical frame; x along -z, y along +x, z along +y (tilted a little) */
    memset(o.directions, 0, sizeof o.directions);
    o.space = IP_SPACE_UNKNOWN;
    o.directions[0][2] = -1;
    o.directions[1][0] = 0.995, o.directions[1][1] = 0.0998749;
    o.directions[2][0] = -0.0998749, o.directions[2][1] = 0.995;
    CHECK_EQ(ip__mc_frame_of(&o, &f), 0);
    CHECK(f.axis[0] == 2 && f.axis[1] == 0 && f.axis[2] == 1);
    CHECK(f.flip[0] && !f.flip[1] && !f.flip[2]);
}

static const test_case cases[] = {
    TEST_CASE(test_table_matches_generator),
    TEST_CASE(test_case_counts),
    TEST_CASE(test_frames),
    TEST_CASE(test_frame_of),
    TEST_CASE(test_sphere),
    TEST_CASE(test_touching_spheres),
    TEST_CASE(test_gyroid),
    TEST_CASE(test_random),
    TEST_CASE(test_values_equal_to_iso),
    TEST_CASE(test_non_finite_values),
    TEST_CASE(test_ray_plane),
    TEST_CASE(test_ray_first_active_cell_missed),
};

static void make_grid(void)
{
    the_grid = calloc(1, sizeof *the_grid);
    REQUIRE(the_grid);
}

static void free_grid(void)
{
    free(the_grid);
}

int main(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "--emit-table") == 0) {
        emit_table(stdout);
        return 0;
    }
    if (argc > 2 && strcmp(argv[1], "--bench") == 0)
        return bench(atoi(argv[2]));
    return RUN_CASES_WITH(argc, argv, cases, "test_mc", make_grid, free_grid);
}

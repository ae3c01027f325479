/* SPDX-License-Identifier: BSD-3-Clause */
/* isoprop: marching cubes: the case tables and the triangulation of one cell.
 *
 * Corners. Corner i of a cell sits at offset (i & 1, (i >> 1) & 1, (i >> 2) & 1) along (x, y, z)
 * from the cell's origin, so corner 0 is (0,0,0), corner 7 is (1,1,1).
 *
 * Edges. Edge e joins corners ip__mc_edge_corners[e][0] < ip__mc_edge_corners[e][1]; the edges are
 * grouped by axis (e / 4 is the axis: 0 = x, 1 = y, 2 = z) and always run in the + direction:
 *     x edges:  0: 0-1   1: 2-3   2: 4-5   3: 6-7
 *     y edges:  4: 0-2   5: 1-3   6: 4-6   7: 5-7
 *     z edges:  8: 0-4   9: 1-5  10: 2-6  11: 3-7
 * A vertex on edge e is therefore also on the same grid edge of the (up to) three other cells that
 * share it, which is what makes welding by edge identity possible. It is computed from the
 * edge's two samples and end points alone, in the same order and arithmetic by each of those
 * cells (given the same corner coordinates), so its position has the same bits in all of them:
 * welding by exact position (ip_mesh_weld()) needs no tolerance.
 *
 * Faces. Face f is the cell side at axis f / 2, on the low (f even) or high (f odd) side:
 * 0 = -x, 1 = +x, 2 = -y, 3 = +y, 4 = -z, 5 = +z.
 *
 * Inside. A corner is inside when its value >= iso; the case index is the OR of (1 << i) over the
 * inside corners. An edge is crossed exactly when one end is inside and the other is not, so the
 * interpolation denominator is never zero and values equal to iso need no special treatment.
 *
 * Ambiguity. A face whose inside corners are diagonally opposite is ambiguous. The tables always
 * separate the two inside corners on such a face (the outside corners join across it). The rule
 * reads only the 4 signs of the face, and the two cells sharing a face see the same 4 signs, so
 * they draw the same segments on it: meshes from these tables have no cracks. The price is that a
 * case and its complement are not mirror images when an ambiguous face is involved: two inside
 * corners on a face diagonal give two corner caps (2 triangles), while two outside corners there
 * are joined by one hexagon (4 triangles). So the triangle counts of a case and its complement
 * differ in 88 of the 256 cases; without an ambiguous face they are always equal.
 *
 * Triangles. The face segments of a case join into closed outlines; each is fanned from the
 * first of its vertices whose fan has no diagonal lying on a cell face. A diagonal on a face
 * could be drawn by the neighbour across that face too, leaving 4 triangles on one edge; with
 * none, every edge of a welded mesh (away from the volume's boundary) is shared by exactly 2
 * triangles, once in each direction.
 *
 * Winding. Every triangle (a, b, c) is counter-clockwise seen from outside (from values < iso):
 * its geometric normal (b - a) x (c - a) points from the inside region (>= iso) toward the outside,
 * the direction of decreasing values. Vertex normals point the same way.
 *
 * The tables were generated once from these rules by tests/test_mc.c, which regenerates them on
 * every test run and compares (run "test_mc --emit-table" to print src/engine/mc_table.c).
 *
 * Frames. The fan's first vertex, and so which diagonal splits a quadrilateral, depends on how
 * the corners are numbered, so one object stored in another order (an axis reversed, two axes
 * swapped) would be split otherwise. The engine triangulates every cell in the volume's
 * canonical frame instead: LPS where the file names an anatomical space, its physical frame
 * otherwise (origin + D * world: isoprop/orientation.h). ip__mc_frame_of() finds the cube
 * symmetry between a cell's world corners and its canonical ones (each world axis matched
 * with the canonical axis it runs along most), and ip__mc_frame_rows() turns the triangle
 * table by it: the triangles of world case c are those of the case the cell has in the
 * canonical frame, on the world edges they lie on, wound counter-clockwise from outside in
 * world space too. The crossed edges and the triangle counts of a case are those of the table
 * (a symmetry keeps the faces' ambiguity rule and each outline's size). Where the frame is the
 * world's own (no orientation, or the unit axes in LPS), the rows are the table's.
 *
 * Thread safety: everything here is a pure function of its arguments or a constant table.
 */
#ifndef ISOPROP_MC_H
#define ISOPROP_MC_H

#include <stdint.h>

#include "isoprop/orientation.h"

#ifdef __cplusplus
extern "C" {
#endif

#define IP_MC_MAX_TRIANGLES 5 /* no case needs more than 5 triangles */
#define IP_MC_MAX_VERTICES 15 /* 3 * IP_MC_MAX_TRIANGLES: room needed by ip__mc_triangulate_cell */

/* Corners joined by each edge (low corner first; see the list above). */
extern const uint8_t ip__mc_edge_corners[12][2];

/* For each case, the 12-bit mask of crossed edges (bit e set when edge e is crossed). */
extern const uint16_t ip__mc_edge_table[256];

/* For each case, the number of triangles (0 to IP_MC_MAX_TRIANGLES). */
extern const uint8_t ip__mc_triangle_count[256];

/* For each case, its triangles as edge-index triples, 3 * ip__mc_triangle_count[case] entries,
 * followed by -1 up to the end of the row. */
extern const int8_t ip__mc_triangle_table[256][16];

/* The cube symmetry between a cell's world corners and its canonical ones: world axis a runs
 * along canonical axis axis[a], the other way where flip[a]. */
typedef struct ip_mc_frame {
    uint8_t axis[3];
    uint8_t flip[3];
} ip_mc_frame;

/* The frame of a volume whose physical space is `orientation` (see Frames above). Returns 1
 * when it is the identity (the table's rows serve as they are), else 0. */
int ip__mc_frame_of(const ip_orientation *orientation, ip_mc_frame *frame);

/* The triangle table turned by `frame` (see Frames above): rows[c] lists the world edges of
 * case c's triangles, 3 * ip__mc_triangle_count[c] entries, then -1. */
void ip__mc_frame_rows(const ip_mc_frame *frame, int8_t rows[256][16]);

/* One output vertex of the triangulation, in world units. */
typedef struct ip_mc_vertex {
    float position[3];
    float normal[3]; /* unit length, toward decreasing values (out of the >= iso region) */
} ip_mc_vertex;

/*! ip__mc_case() : the case index (0..255) of a cell: bit i is set when corner_values[i] >= iso.
 *  A NaN value is never >= iso, so it counts as outside. An inline definition: seeding and the
 *  full extraction classify every cell they visit with it; src/engine/mc.c holds the external
 *  one. */
inline unsigned ip__mc_case(const float corner_values[8], float iso)
{
    unsigned mc_case = 0;
    for (unsigned i = 0; i < 8; i++)
        mc_case |= (unsigned)(corner_values[i] >= iso) << i;
    return mc_case;
}

/*! ip__mc_crossed_faces() : a 6-bit mask of the faces of a cell of case `mc_case` that the surface
 *  crosses (bit f set when face f has a crossed edge): the neighbours across those faces are
 *  active too, which is what propagation follows. Only the low 8 bits of mc_case are used. An
 *  inline definition (propagation asks once per cell); src/engine/mc.c holds the external one. */
inline unsigned ip__mc_crossed_faces(unsigned mc_case)
{
    /* Corners of faces -x, +x, -y, +y, -z, +z: a face is crossed unless its corners agree. */
    static const uint8_t face_corners[6] = {0x55, 0xAA, 0x33, 0xCC, 0x0F, 0xF0};
    unsigned faces = 0;
    for (unsigned f = 0; f < 6; f++) {
        unsigned inside = mc_case & face_corners[f];
        faces |= (unsigned)(inside != 0 && inside != face_corners[f]) << f;
    }
    return faces;
}

/*! ip__mc_triangulate_cell() : the isosurface triangles of one cell.
 *  values      : the 8 corner samples, in the corner order above.
 *  gradients   : the field gradient at each corner (any common scale; only directions matter), or
 *                NULL to use the gradient of the cell's own trilinear interpolant. For anisotropic
 *                cells the gradients must be in world coordinates.
 *  iso         : the isovalue.
 *  lo, hi      : world positions of corners 0 and 7, hi > lo along each axis (a reversed axis
 *                mirrors the cell and flips the winding). Neighbouring cells must be given the
 *                same coordinates for their shared corners (not lo + size), so that they put
 *                shared vertices at the same bits.
 *  out         : room for IP_MC_MAX_VERTICES vertices, owned by the caller; triangle t is
 *                out[3t], out[3t+1], out[3t+2], in the order of ip__mc_triangle_table.
 *  Each vertex lies on its edge at t = (iso - v0) / (v1 - v0) from the edge's low corner, clamped
 *  to [0, 1], at lo + t * (hi - lo) along the edge's axis (exactly lo or hi at t = 0 or 1), so a
 *  value equal to iso puts the vertex on that corner. The normal is the negated,
 *  normalised interpolated gradient; where that is zero or not finite it falls back to the
 *  trilinear gradient, then to the edge direction from its inside corner to its outside corner,
 *  so no output is ever NaN for finite inputs.
 *  @return the number of triangles written, 0 to IP_MC_MAX_TRIANGLES. No allocation. */
int ip__mc_triangulate_cell(const float values[8], const float gradients[8][3], float iso,
                            const float lo[3], const float hi[3], ip_mc_vertex *out);

/*! ip__mc_cell_edge_points() : the points where the surface crosses the cell's edges, exactly
 *  where ip__mc_triangulate_cell() (same values, iso, lo, hi) puts its vertices, without
 *  the normals: points[e] is set for every edge e whose bit is set in the returned mask
 *  (ip__mc_edge_table of the cell's case, `mc_case`, which is ip__mc_case(values, iso)); the
 *  others are left alone. A cell's triangles are then the rows of ip__mc_triangle_table. No
 *  allocation. */
unsigned ip__mc_cell_edge_points(const float values[8], unsigned mc_case, float iso,
                                 const float lo[3], const float hi[3], float points[12][3]);

/*! ip__mc_cell_edge_normals() : the normals ip__mc_triangulate_cell() (same arguments) gives its
 *  vertices, per crossed edge: normals[e] for every edge e whose bit is set in the returned
 *  mask; the others are left alone (`mc_case` as there). With ip__mc_cell_edge_points(), a
 *  caller that may drop some of a cell's triangles works out the normals only for a cell it
 *  keeps. */
unsigned ip__mc_cell_edge_normals(const float values[8], unsigned mc_case,
                                  const float gradients[8][3], float iso, const float lo[3],
                                  const float hi[3], float normals[12][3]);

/*! ip__mc_ray_hits_cell() : whether the ray ray_origin + t * ray_dir, t >= 0, hits a triangle of
 *  the cell's triangulation (either side), as produced by ip__mc_triangulate_cell with the same
 *  values, iso, lo and hi. A ray can cross an active cell without touching its triangles;
 *  this is the test that tells the two apart when seeding.
 *  t_hit : if not NULL and the ray hits, receives the smallest t of a hit, in units of the length
 *          of ray_dir (the distance when ray_dir is a unit vector); untouched otherwise.
 *  Triangle edges count as hits, so a ray through an edge shared by two triangles is not lost.
 *  @return 1 on a hit, 0 otherwise. No allocation. */
int ip__mc_ray_hits_cell(const float values[8], float iso, const float lo[3], const float hi[3],
                         const float ray_origin[3], const float ray_dir[3], float *t_hit);

#ifdef __cplusplus
}
#endif
#endif

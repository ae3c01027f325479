/* SPDX-License-Identifier: BSD-3-Clause */
/* isoprop: triangle meshes produced by extraction.
 *
 * A mesh is a triangle soup in world units: each triangle has 3 positions (floats) and 3 unit
 * normals (from the data's gradient, pointing toward lower values), stored as signed
 * normalised 16-bit integers (component = value / 32767, as OpenGL reads GL_SHORT with
 * normalisation on). That is 54 bytes a triangle. On request (`with_cells`) it also keeps the
 * id of the cell each triangle came from (8 bytes more), so that two extractions can be
 * compared triangle by triangle.
 *
 * Welded, the same surface is an indexed mesh (ip_indexed_mesh): each distinct position once,
 * and triangles as 3 vertex indices. Marching cubes puts a vertex shared by neighbouring cells
 * at the same bits in each of them, so welding by exact position joins exactly the corners
 * that are one point of the surface, and a closed surface comes out closed (every edge shared
 * by two triangles).
 *
 * Files, by the name's extension: binary PLY, binary STL, Wavefront OBJ and binary glTF 2.0
 * (.glb). PLY, OBJ and glTF keep the vertices as they are given (a soup's 3 per triangle, or
 * an indexed mesh's shared ones); STL is a triangle soup by definition. glTF has no units of
 * its own but says that one unit is a metre: world units are written as they are, so a volume
 * with 1 mm spacing shows 1000 times too large in a viewer that takes glTF at its word.
 */
#ifndef ISOPROP_MESH_H
#define ISOPROP_MESH_H

#include <stdint.h>

#include "isoprop/orientation.h"
#include "isoprop/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ip_mesh {
    float *positions; /* 9 floats per triangle: x,y,z of its 3 vertices, world units */
    int16_t *normals; /* 9 per triangle: unit normals of its 3 vertices, ip_normal_pack() */
    uint64_t *cells;  /* per triangle: ip_cell_id() of the cell it came from; NULL
                                unless with_cells */
    uint64_t triangle_count;
    uint64_t capacity;  /* triangles allocated */
    uint64_t populated; /* triangles whose pages appends have had populated (ip_mesh_append()) */
    int with_cells; /* keep cell ids: set before the first append, or by ip_mesh_init_with_cells() */
} ip_mesh;

/*! ip_normal_pack() : a normal component in [-1, 1] as a signed normalised 16-bit integer
 *  (rounded to nearest; out-of-range and NaN values are clamped, NaN to 0). */
static inline int16_t ip_normal_pack(float v)
{
    if (!(v == v))
        return 0;
    float s = v * 32767.0f;
    s = s > 32767.0f ? 32767.0f : s;
    s = s < -32767.0f ? -32767.0f : s;
    return (int16_t)(s + (s < 0 ? -0.5f : 0.5f)); /* halves away from zero, truncated */
}

/*! ip_normal_unpack() : the component a packed value stands for (value / 32767). */
static inline float ip_normal_unpack(int16_t v)
{
    return (float)v / 32767.0f;
}

/*! ip_cell_id() : a cell's id: its level in the top 6 bits, then its linear index
 *  x + cells_x * (y + cells_y * z) among the level's cells. */
static inline uint64_t ip_cell_id(uint32_t level, uint64_t linear)
{
    return (uint64_t)level << 58 | linear;
}

/*! ip_mesh_init() : an empty mesh that keeps no cell ids (no allocation). */
IP_API void ip_mesh_init(ip_mesh *mesh);

/*! ip_mesh_init_with_cells() : an empty mesh that keeps each triangle's cell id. */
IP_API void ip_mesh_init_with_cells(ip_mesh *mesh);

/*! ip_mesh_free() : releases the arrays; the mesh is empty afterwards (and keeps its
 *  with_cells choice). */
IP_API void ip_mesh_free(ip_mesh *mesh);

/*! ip_mesh_clear() : drops every triangle, keeping the memory. */
IP_API void ip_mesh_clear(ip_mesh *mesh);

/*! ip_mesh_reserve() : makes room for `triangles` in all (grows by half again, at least).
 *  @return IP_OK or IP_ERR_NOMEM (the mesh is unchanged). */
IP_API ip_status ip_mesh_reserve(ip_mesh *mesh, uint64_t triangles);

/*! ip_mesh_append() : appends `count` triangles from arrays laid out like the mesh's;
 *  `cells` is read only when the mesh keeps cell ids (and may be NULL otherwise).
 *  @return IP_OK or IP_ERR_NOMEM. */
IP_API ip_status ip_mesh_append(ip_mesh *mesh, const float *positions, const int16_t *normals,
                                const uint64_t *cells, uint64_t count);

/*! ip_mesh_append_float_normals() : ip_mesh_append() with normals given as 9 floats per
 *  triangle, packed with ip_normal_pack(). @return IP_OK or IP_ERR_NOMEM. */
IP_API ip_status ip_mesh_append_float_normals(ip_mesh *mesh, const float *positions,
                                              const float *normals, const uint64_t *cells,
                                              uint64_t count);

/*! ip_mesh_append_mesh() : appends triangles [first, first + count) of `from` (which must
 *  hold them), with their cell ids when `mesh` keeps them, in which case `from` must too.
 *  @return IP_OK, IP_ERR_ARGUMENT (a range past `from`, or no cell ids to copy) or
 *  IP_ERR_NOMEM. */
IP_API ip_status ip_mesh_append_mesh(ip_mesh *mesh, const ip_mesh *from, uint64_t first,
                                     uint64_t count);

/*! ip_mesh_to_physical() : moves the mesh from world coordinates (sample index x spacing, as
 *  the engine makes it) into its volume's physical space: each position p becomes
 *  origin + D * p and each normal D * n (D: the directions as columns; docs/format.md); where
 *  D is a reflection, each triangle's second and third vertices swap places, so that triangles
 *  stay counter-clockwise seen from outside (from lower values). Done in double precision,
 *  stored back as float32 and packed normals. Changes `mesh` in place. */
IP_API void ip_mesh_to_physical(ip_mesh *mesh, const ip_orientation *orientation);

/*! ip_mesh_write_ply() : writes the mesh as binary little-endian PLY (float x,y,z,nx,ny,nz per
 *  vertex, 3 vertices per triangle, faces as uchar-counted int lists), atomically; only a
 *  regular file is ever replaced (isoprop/output.h). An indexed mesh is written with
 *  ip_indexed_mesh_write().
 *  @return IP_OK, IP_ERR_EXISTS (force == 0 and the file exists), IP_ERR_ARGUMENT (the path
 *  exists and is not a regular file), IP_ERR_NOMEM or IP_ERR_IO. */
IP_API ip_status ip_mesh_write_ply(const ip_mesh *mesh, const char *path, int force, ip_error *err);

/*! ip_mesh_write_stl() : writes the mesh as binary STL (an 80-byte header that does not start
 *  with "solid", the triangle count, then per triangle its unit face normal from its corners
 *  and its 3 corners, float32 little-endian), atomically, like ip_mesh_write_ply(). STL keeps
 *  no per-vertex normals. @return as ip_mesh_write_ply(), and IP_ERR_ARGUMENT for more than
 *  2^32 - 1 triangles. */
IP_API ip_status ip_mesh_write_stl(const ip_mesh *mesh, const char *path, int force, ip_error *err);

/*! ip_mesh_write_obj() : writes the mesh as Wavefront OBJ text ("v x y z" and "vn nx ny nz"
 *  per corner, 3 per triangle, then "f a//a b//b c//c", counting from 1), atomically, like
 *  ip_mesh_write_ply(). @return as ip_mesh_write_ply(). */
IP_API ip_status ip_mesh_write_obj(const ip_mesh *mesh, const char *path, int force, ip_error *err);

/*! ip_mesh_write_glb() : writes the mesh as binary glTF 2.0 (.glb), atomically, like
 *  ip_mesh_write_ply(): a 12-byte header, a JSON chunk (padded with spaces to 4 bytes) and a
 *  binary chunk holding float32 positions (with their min and max in the JSON) and float32
 *  unit normals, 3 vertices per triangle and no indices; one buffer, mesh, node and scene;
 *  asset.generator "isoprop VERSION". A mesh without triangles has no buffer, mesh or node.
 *  @return as ip_mesh_write_ply(), and IP_ERR_ARGUMENT for a file past glTF's 4 GiB limit or
 *  a position that is not finite. */
IP_API ip_status ip_mesh_write_glb(const ip_mesh *mesh, const char *path, int force, ip_error *err);

/*! ip_mesh_format_of() : "PLY", "STL", "OBJ" or "GLB" for a name ending in .ply, .stl, .obj or
 *  .glb (ignoring case), NULL for any other (a static string: not to be freed). */
IP_API const char *ip_mesh_format_of(const char *path);

/*! ip_mesh_write() : writes the mesh in the format its name ends in, ignoring case: .ply,
 *  .stl, .obj or .glb. @return as those, or IP_ERR_ARGUMENT with a message naming the file for
 *  any other name. */
IP_API ip_status ip_mesh_write(const ip_mesh *mesh, const char *path, int force, ip_error *err);

/* A welded mesh: shared vertices and triangles of indices into them. */
typedef struct ip_indexed_mesh {
    float *positions;  /* 3 floats per vertex: x, y, z in world units, each position once */
    int16_t *normals;  /* 3 per vertex: its unit normal, ip_normal_pack() */
    uint32_t *indices; /* 3 per triangle: its vertices, in the soup's order (counter-clockwise
                          seen from outside) */
    uint64_t vertex_count;
    uint64_t triangle_count;
    uint64_t dropped_triangles; /* soup triangles with two corners at one position, left out */
} ip_indexed_mesh;

/*! ip_indexed_mesh_init() : an empty indexed mesh (no allocation). */
IP_API void ip_indexed_mesh_init(ip_indexed_mesh *mesh);

/*! ip_indexed_mesh_free() : releases the arrays; the mesh is empty afterwards. */
IP_API void ip_indexed_mesh_free(ip_indexed_mesh *mesh);

/*! ip_mesh_weld() : the soup `mesh` as an indexed mesh in `out`: corners at the same position
 *  (compared bit for bit, with -0 equal to +0; no tolerance) become one vertex, numbered in the
 *  order of their first appearance. A vertex's normal is the average of its corners' normals,
 *  normalised again (the first corner's where they cancel out). A triangle with two corners at
 *  one position has no area and no edge of its own: it is left out and counted in
 *  out->dropped_triangles (its vertices too, unless another triangle uses them). Cell ids are
 *  not kept. Takes O(triangles) time; the memory is `out`'s arrays and, while it runs, a hash
 *  table of 8 bytes per triangle and 12 bytes per vertex. `out` is overwritten (an earlier
 *  content is not freed) and owned by the caller, who frees it with ip_indexed_mesh_free();
 *  after a failure it is empty. `mesh` is not changed.
 *  @return IP_OK, IP_ERR_NOMEM, or IP_ERR_ARGUMENT for more than 2^32 - 2 distinct vertices. */
IP_API ip_status ip_mesh_weld(const ip_mesh *mesh, ip_indexed_mesh *out);

/* Taubin's factors for ip_indexed_mesh_smooth_taubin(): lambda 0.5 and mu -0.53 pass
 * frequencies below about 0.11 (1/lambda + 1/mu) and damp those above, the terraces of
 * nearly binary data among them. */
#define IP_TAUBIN_LAMBDA 0.5
#define IP_TAUBIN_MU (-0.53)

/*! ip_indexed_mesh_smooth_taubin() : smooths the welded mesh in place by Taubin's method:
 *  `iterations` times, every vertex p moves to p + lambda * (a - p), a being the average of
 *  its neighbours' positions (the uniform, or umbrella, Laplacian over the triangles' edges),
 *  then likewise with mu; a negative mu (mu < -lambda, e.g. IP_TAUBIN_LAMBDA, IP_TAUBIN_MU)
 *  undoes the shrinking that lambda alone (mu = 0: Laplacian smoothing) causes. Vertices on
 *  an edge that is not in exactly two triangles (a boundary, where the surface meets the
 *  volume's faces, or a non-manifold edge) stay where they are, so an open surface keeps its
 *  rim. Afterwards each vertex's normal is the area-weighted average of its triangles' normals
 *  (from their corners' order, counter-clockwise seen from outside), normalised. Vertex and
 *  triangle counts and indices do not change. Memory while it runs: 24 bytes per triangle and
 *  21 bytes per vertex (a table of each vertex's neighbours, new positions); time O(iterations
 *  * (vertices + edges)). Not thread-safe on one mesh.
 *  @return IP_OK (also for 0 iterations, which change nothing), IP_ERR_ARGUMENT (lambda not in
 *  (0, 1] or mu not in [-1, 0]; the mesh unchanged) or IP_ERR_NOMEM (the mesh unchanged). */
IP_API ip_status ip_indexed_mesh_smooth_taubin(ip_indexed_mesh *mesh, unsigned iterations,
                                               double lambda, double mu, ip_error *err);

/*! ip_indexed_mesh_write() : writes the indexed mesh in the format its name ends in, like
 *  ip_mesh_write(): PLY with its vertex list and faces of indices into it, OBJ with one "v" and
 *  "vn" per vertex and faces "f a//a b//b c//c", glTF with a uint32 index accessor; STL repeats
 *  the corners of each triangle, as STL must.
 *  @return as ip_mesh_write(). */
IP_API ip_status ip_indexed_mesh_write(const ip_indexed_mesh *mesh, const char *path, int force,
                                       ip_error *err);

/* The space of a written mesh's coordinates, named in the file (docs/meshes.md, "Space"). */
#define IP_MESH_SPACE_GRID "grid" /* world coordinates: sample index x spacing, from 0 */
#define IP_MESH_SPACE_MAX 31      /* longest space name accepted */

/*! ip_mesh_space_of() : the name of the space a mesh is in once ip_mesh_to_physical() has
 *  moved it by `orientation`: "RAS", "LAS" or "LPS" where the volume's file names that space,
 *  "volume" where it names none (its own axes, from its origin, in its spacing's units). A
 *  static string: not to be freed. */
IP_API const char *ip_mesh_space_of(const ip_orientation *orientation);

/*! ip_mesh_write_in() : as ip_mesh_write(), naming `space` in the file: a PLY comment
 *  "space NAME", an OBJ comment "# space NAME", "space NAME" in the STL header, and
 *  asset.extras.space in glTF. `space`: 1 to IP_MESH_SPACE_MAX letters, digits, '.', '_' or
 *  '-' (IP_ERR_ARGUMENT otherwise, nothing written); NULL names none, as ip_mesh_write().
 *  The coordinates are written as they are: moving them is the caller's (ip_mesh_to_physical()).
 *  @return as ip_mesh_write(). */
IP_API ip_status ip_mesh_write_in(const ip_mesh *mesh, const char *path, const char *space,
                                  int force, ip_error *err);

/*! ip_indexed_mesh_write_in() : ip_indexed_mesh_write() naming `space` in the file, as
 *  ip_mesh_write_in(). @return as ip_mesh_write(). */
IP_API ip_status ip_indexed_mesh_write_in(const ip_indexed_mesh *mesh, const char *path,
                                          const char *space, int force, ip_error *err);

/* ---- Experimental (IP_EXPERIMENTAL) ----
 * Declared only where IP_EXPERIMENTAL is defined before the include (docs/api.md,
 * "Stability"): calls that may change in a minor version. Exported all the same. */
#ifdef IP_EXPERIMENTAL

/*! ip_mesh_weld_keep_degenerate() : ip_mesh_weld() that keeps the triangles with two (or
 *  three) corners at one position, as marching cubes makes them where the surface passes
 *  through a sample: such a triangle becomes one whose indices repeat a vertex, so that the
 *  triangle count stays the soup's (what scikit-image's marching_cubes(allow_degenerate=True)
 *  and VTK's filters give). out->dropped_triangles is 0. Memory, time, ownership and returns
 *  as ip_mesh_weld(). */
IP_API ip_status ip_mesh_weld_keep_degenerate(const ip_mesh *mesh, ip_indexed_mesh *out);

/*! ip_indexed_mesh_decimate() : simplifies the welded mesh in place by edge collapses
 *  (meshoptimizer's meshopt_simplify(): quadric error, loaded at the call from the system's
 *  libmeshoptimizer, which libisoprop does not link) toward `ratio` x its triangles
 *  (0 < ratio < 1), as far as the error stays within `max_error` world units (0: 1 % of the
 *  mesh's extent, meshopt_simplifyScale()). Vertices on an edge of one triangle only (the rim
 *  where an open surface meets the volume's faces or a clip plane) stay where they are
 *  (meshopt_SimplifyLockBorder). Pairs of triangles the collapses leave on the same three
 *  vertices wound opposite ways (a thin part flattened onto itself) are removed: they enclose
 *  nothing. The vertices kept are a subset of the mesh's, with their
 *  positions and normals, in their old order; dropped_triangles stays. *error (may be NULL)
 *  receives the error reached, world units (meshoptimizer's relative error times its scale:
 *  about the largest distance of a removed vertex from the simplified surface). Where the
 *  error bound stops it first, more triangles than the target stay: the caller compares
 *  triangle_count with it. Not thread-safe on one mesh.
 *  @return IP_OK, IP_ERR_ARGUMENT (ratio not in (0, 1), max_error negative, infinite or NaN),
 *  IP_ERR_UNSUPPORTED (no meshoptimizer: the message names the Debian package
 *  libmeshoptimizer-dev) or IP_ERR_NOMEM; the mesh is unchanged after a failure. */
IP_API ip_status ip_indexed_mesh_decimate(ip_indexed_mesh *mesh, double ratio, double max_error,
                                          double *error, ip_error *err);
/* Measuring and cleaning a welded mesh (docs/meshes.md, "Measuring" and "Cleaning"). The
 * figures are in the mesh's own units (physical, once ip_mesh_to_physical() has moved it), in
 * double precision. */

/*! ip_indexed_mesh_area() : the sum of the triangles' areas. */
IP_API double ip_indexed_mesh_area(const ip_indexed_mesh *mesh);

/*! ip_indexed_mesh_volume() : the signed volume the triangles enclose, by the divergence
 *  theorem: the sum over triangles of p0 . (p1 x p2) / 6. Positive for a closed surface whose
 *  triangles are counter-clockwise seen from outside (as extraction makes them, the inside
 *  holding the higher values); for an open surface it depends on where the origin is. */
IP_API double ip_indexed_mesh_volume(const ip_indexed_mesh *mesh);

/*! ip_indexed_mesh_bounds() : the least and greatest coordinate of the vertices on each axis
 *  (all zero for a mesh without vertices). */
IP_API void ip_indexed_mesh_bounds(const ip_indexed_mesh *mesh, double lo[3], double hi[3]);

/*! ip_indexed_mesh_edges() : counts the edges in one triangle only (`boundary`) and in more
 *  than two (`nonmanifold`); the mesh is closed where both are 0 (and it has triangles). A
 *  triangle's edge between a repeated vertex and itself is not counted. Memory while it runs:
 *  12 bytes per triangle and 8 per vertex; time O(triangles).
 *  @return IP_OK or IP_ERR_NOMEM (the counts 0). */
IP_API ip_status ip_indexed_mesh_edges(const ip_indexed_mesh *mesh, uint64_t *boundary,
                                       uint64_t *nonmanifold);

/*! ip_indexed_mesh_components() : the connected components, triangles joined by a shared
 *  vertex (union-find over the vertices): labels[t] (an array of triangle_count) is triangle
 *  t's component, numbered from 0 in the order of the components' first triangles; *count is
 *  their number. Memory while it runs: 8 bytes per vertex.
 *  @return IP_OK or IP_ERR_NOMEM. */
IP_API ip_status ip_indexed_mesh_components(const ip_indexed_mesh *mesh, uint32_t *labels,
                                            uint64_t *count);

/*! ip_indexed_mesh_component_measures() : for each of `count` components of `labels`, its
 *  triangle count, area and signed volume (as ip_indexed_mesh_volume()), into arrays of
 *  `count` (any may be NULL). */
IP_API void ip_indexed_mesh_component_measures(const ip_indexed_mesh *mesh, const uint32_t *labels,
                                               uint64_t count, uint64_t *triangles, double *area,
                                               double *volume);

/*! ip_indexed_mesh_keep_triangles() : keeps the triangles t with keep[t] != 0, in their order,
 *  and the vertices they use, in theirs (renumbered); in place (the arrays are not shrunk).
 *  dropped_triangles is unchanged. @return IP_OK or IP_ERR_NOMEM (the mesh unchanged). */
IP_API ip_status ip_indexed_mesh_keep_triangles(ip_indexed_mesh *mesh, const uint8_t *keep);

/*! ip_indexed_mesh_clean() : drops whole components (ip_indexed_mesh_components()): with
 *  `largest`, all but the one of the greatest area (the first of equal ones); and those of an
 *  area under `min_area` (0 keeps all). *removed (may be NULL) is the number of components
 *  dropped. In place, as ip_indexed_mesh_keep_triangles(). Memory while it runs: 5 bytes per
 *  triangle, 8 per vertex and 8 per component.
 *  @return IP_OK, IP_ERR_ARGUMENT (min_area negative or NaN; the mesh unchanged) or
 *  IP_ERR_NOMEM (the mesh unchanged). */
IP_API ip_status ip_indexed_mesh_clean(ip_indexed_mesh *mesh, int largest, double min_area,
                                       uint64_t *removed);

#endif /* IP_EXPERIMENTAL */

#ifdef __cplusplus
}
#endif
#endif

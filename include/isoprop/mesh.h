/* isoprop: triangle meshes produced by extraction.
 *
 * A mesh is a triangle soup in world units: each triangle has 3 positions (floats) and 3 unit
 * normals (from the data's gradient, pointing toward lower values), stored as signed
 * normalised 16-bit integers (component = value / 32767, as OpenGL reads GL_SHORT with
 * normalisation on). That is 54 bytes a triangle. On request (`with_cells`) it also keeps the
 * id of the cell each triangle came from (8 bytes more), so that two extractions can be
 * compared triangle by triangle.
 */
#ifndef ISOPROP_MESH_H
#define ISOPROP_MESH_H

#include <stdint.h>

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
    uint64_t capacity; /* triangles allocated */
    int with_cells; /* keep cell ids: set before the first append, or by ip_mesh_init_with_cells() */
} ip_mesh;

/*! ip_normal_pack() : a normal component in [-1, 1] as a signed normalised 16-bit integer
 *  (rounded to nearest; out-of-range and NaN values are clamped, NaN to 0). */
static inline int16_t ip_normal_pack(float v)
{
    if (!(v == v))
        return 0;
    float s = v * 32767.0f;
    s = s > 32767.0f ? 32767.0f : s < -32767.0f ? -32767.0f : s;
    return (int16_t)(s < 0 ? s - 0.5f : s + 0.5f);
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

/*! ip_mesh_write_ply() : writes the mesh as binary little-endian PLY (float x,y,z,nx,ny,nz per
 *  vertex, 3 vertices per triangle, faces as uchar-counted int lists), atomically; only a
 *  regular file is ever replaced (isoprop/output.h).
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

/*! ip_mesh_format_of() : "PLY", "STL" or "OBJ" for a name ending in .ply, .stl or .obj
 *  (ignoring case), NULL for any other (a static string: not to be freed). */
IP_API const char *ip_mesh_format_of(const char *path);

/*! ip_mesh_write() : writes the mesh in the format its name ends in, ignoring case: .ply,
 *  .stl or .obj. @return as those, or IP_ERR_ARGUMENT with a message naming the file for any
 *  other name. */
IP_API ip_status ip_mesh_write(const ip_mesh *mesh, const char *path, int force, ip_error *err);

#ifdef __cplusplus
}
#endif
#endif

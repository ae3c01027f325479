/* isoprop: triangle meshes produced by extraction.
 *
 * A mesh is a triangle soup in world units: each triangle has 3 positions, 3 unit normals
 * (from the data's gradient, pointing toward lower values) and the id of the cell it came
 * from, so that two extractions can be compared triangle by triangle.
 */
#ifndef ISOPROP_MESH_H
#define ISOPROP_MESH_H

#include <stdint.h>

#include "isoprop/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ip_mesh {
    float *positions;        /* 9 floats per triangle: x,y,z of its 3 vertices, world units */
    float *normals;          /* 9 floats per triangle: unit normals of its 3 vertices */
    uint64_t *cells;         /* per triangle: ip_cell_id() of the cell it came from */
    uint64_t triangle_count;
    uint64_t capacity;       /* triangles allocated */
} ip_mesh;

/*! ip_cell_id() : a cell's id: its level in the top 6 bits, then its linear index
 *  x + cells_x * (y + cells_y * z) among the level's cells. */
static inline uint64_t ip_cell_id(uint32_t level, uint64_t linear)
{
    return (uint64_t)level << 58 | linear;
}

/*! ip_mesh_init() : an empty mesh (no allocation). */
void ip_mesh_init(ip_mesh *mesh);

/*! ip_mesh_free() : releases the arrays; the mesh is empty afterwards. */
void ip_mesh_free(ip_mesh *mesh);

/*! ip_mesh_clear() : drops every triangle, keeping the memory. */
void ip_mesh_clear(ip_mesh *mesh);

/*! ip_mesh_reserve() : makes room for `triangles` in all (grows geometrically).
 *  @return IP_OK or IP_ERR_NOMEM (the mesh is unchanged). */
ip_status ip_mesh_reserve(ip_mesh *mesh, uint64_t triangles);

/*! ip_mesh_append() : appends `count` triangles from arrays laid out like the mesh's.
 *  @return IP_OK or IP_ERR_NOMEM. */
ip_status ip_mesh_append(ip_mesh *mesh, const float *positions, const float *normals,
                         const uint64_t *cells, uint64_t count);

/*! ip_mesh_write_ply() : writes the mesh as binary little-endian PLY (float x,y,z,nx,ny,nz per
 *  vertex, 3 vertices per triangle, faces as uchar-counted int lists), atomically.
 *  @return IP_OK, IP_ERR_EXISTS (force == 0 and the file exists) or IP_ERR_IO. */
ip_status ip_mesh_write_ply(const ip_mesh *mesh, const char *path, int force, ip_error *err);

#ifdef __cplusplus
}
#endif
#endif

/* SPDX-License-Identifier: BSD-3-Clause */
/* A mesh moved from world coordinates into its volume's physical space. */
#include "isoprop/mesh.h"

void ip_mesh_to_physical(ip_mesh *mesh, const ip_orientation *orientation)
{
    for (uint64_t v = 0; v < 3 * mesh->triangle_count; v++) {
        float *p = mesh->positions + 3 * v;
        int16_t *n = mesh->normals + 3 * v;
        double world[3] = {p[0], p[1], p[2]}, physical[3];
        double normal[3] = {ip_normal_unpack(n[0]), ip_normal_unpack(n[1]), ip_normal_unpack(n[2])},
               turned[3];
        ip_orientation_apply(orientation, world, physical);
        ip_orientation_rotate(orientation, normal, turned);
        for (int c = 0; c < 3; c++) {
            p[c] = (float)physical[c];
            n[c] = ip_normal_pack((float)turned[c]);
        }
    }
}

const char *ip_mesh_space_of(const ip_orientation *orientation)
{
    const char *name = ip_space_name(orientation->space);
    return name[0] ? name : "volume";
}

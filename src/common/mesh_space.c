/* SPDX-License-Identifier: BSD-3-Clause */
/* A mesh moved from world coordinates into its volume's physical space. */
#include <string.h>

#include "isoprop/mesh.h"

/* Swaps a triangle's second and third vertices (positions and normals): its winding reversed. */
static void reverse_winding(float *p, int16_t *n)
{
    float pt[3];
    int16_t nt[3];
    memcpy(pt, p + 3, sizeof pt);
    memcpy(p + 3, p + 6, sizeof pt);
    memcpy(p + 6, pt, sizeof pt);
    memcpy(nt, n + 3, sizeof nt);
    memcpy(n + 3, n + 6, sizeof nt);
    memcpy(n + 6, nt, sizeof nt);
}

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
    /* a reflection turns counter-clockwise into clockwise: turn it back (mc.h, "Winding") */
    if (ip_orientation_mirrors(orientation))
        for (uint64_t t = 0; t < mesh->triangle_count; t++)
            reverse_winding(mesh->positions + 9 * t, mesh->normals + 9 * t);
}

const char *ip_mesh_space_of(const ip_orientation *orientation)
{
    const char *name = ip_space_name(orientation->space);
    return name[0] ? name : "volume";
}

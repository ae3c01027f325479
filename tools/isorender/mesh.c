/* SPDX-License-Identifier: BSD-3-Clause */
/* isorender --mesh: the mesh file, welded, smoothed and in the volume's physical space. */
#include <stdio.h>
#include <string.h>

#include "isorender.h"

#define SMOOTH_MAX_ITERATIONS 100000

int parse_smooth(const char *program, const tool_option *option, const char *const *values,
                 void *base)
{
    return tool_parse_bounded(program, option->name, values[0], 0, SMOOTH_MAX_ITERATIONS,
                              "an iteration count", &((options *)base)->smooth);
}

int check_mesh_options(const options *o)
{
    if (o->mesh_grid && !o->mesh)
        return tool_usage_error("isorender", "--mesh-grid says how to write the mesh file: it "
                                             "needs --mesh");
    if (!o->smooth)
        return 0;
    if (!o->mesh)
        return tool_usage_error("isorender", "--smooth smooths the mesh file: it needs --mesh");
    if (o->no_weld)
        return tool_usage_error("isorender", "--smooth needs shared vertices: no --no-weld");
    return 0;
}

/* Smooths the welded mesh of the file by --smooth's iterations. Returns 0, or 1 after the
 * error. */
static int smooth_mesh(const run *r, ip_indexed_mesh *welded, ip_error *err)
{
    if (!r->o.smooth)
        return 0;
    if (ip_indexed_mesh_smooth_taubin(welded, (unsigned)r->o.smooth, IP_TAUBIN_LAMBDA, IP_TAUBIN_MU,
                                      err) != IP_OK)
        return tool_fail("isorender", err);
    return 0;
}

/* Writes `mesh` to the mesh file, naming `space` in it: welded (shared vertices, degenerate
 * triangles left out), smoothed, cleaned and measured, unless --no-weld (the soup as it is; STL
 * is welded too, then written with its corners repeated). A progressive run's mesh is
 * only what the view needed, which a note says. */
static int write_mesh_as(run *r, const ip_mesh *mesh, const char *space, ip_error *err)
{
    const char *format = ip_mesh_format_of(r->o.mesh);
    ip_status st;
    int stl = strcmp(format, "STL") == 0;
    if (r->o.no_weld) {
        if (measuring(r) && measure_unwritten(r, mesh) != 0)
            return 1;
        st = ip_mesh_write_in(mesh, r->o.mesh, space, r->o.common.force, err);
        r->mesh_vertices = 3 * mesh->triangle_count;
        r->mesh_triangles = mesh->triangle_count;
    } else {
        ip_indexed_mesh welded;
        st = ip_mesh_weld(mesh, &welded);
        if (st != IP_OK) {
            fprintf(stderr, "isorender: %s: cannot weld %llu triangles (%s)\n", r->o.mesh,
                    (unsigned long long)mesh->triangle_count, ip_status_message(st));
            return 1;
        }
        if (smooth_mesh(r, &welded, err) != 0 || decimate_mesh(r, &welded, err) != 0 ||
            clean_and_measure(r, &welded) != 0) {
            ip_indexed_mesh_free(&welded);
            return 1;
        }
        st = ip_indexed_mesh_write_in(&welded, r->o.mesh, space, r->o.common.force, err);
        r->mesh_vertices = stl ? 3 * welded.triangle_count : welded.vertex_count;
        r->mesh_triangles = welded.triangle_count;
        ip_indexed_mesh_free(&welded);
    }
    if (st != IP_OK)
        return tool_fail("isorender", err);
    if (!r->o.full && !r->o.common.quiet)
        fprintf(stderr,
                "isorender: note: %s holds only the surface this view needed (open "
                "behind); --full --mesh writes the whole, closed surface\n",
                r->o.mesh);
    return 0;
}

/* The mesh file, or without one the figures of the mesh that would be written. */
static int mesh_output(run *r, const ip_mesh *mesh, const char *space, ip_error *err)
{
    return r->o.mesh ? write_mesh_as(r, mesh, space, err) : measure_unwritten(r, mesh);
}

int write_mesh(run *r, ip_error *err)
{
    const ip_orientation *space = &ip_store_layout(r->store)->orientation;
    if (!r->o.mesh && !measuring(r))
        return 0;
    if (r->o.mesh_grid)
        return mesh_output(r, r->mesh, IP_MESH_SPACE_GRID, err);
    if (ip_orientation_is_identity(space))
        return mesh_output(r, r->mesh, ip_mesh_space_of(space), err);
    ip_mesh physical;
    ip_mesh_init(&physical);
    if (ip_mesh_append_mesh(&physical, r->mesh, 0, r->mesh->triangle_count) != IP_OK) {
        fprintf(stderr, "isorender: %s: out of memory\n", r->o.mesh ? r->o.mesh : r->o.file);
        ip_mesh_free(&physical);
        return 1;
    }
    ip_mesh_to_physical(&physical, space);
    int rc = mesh_output(r, &physical, ip_mesh_space_of(space), err);
    ip_mesh_free(&physical);
    return rc;
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* Simplifying a welded mesh by edge collapses with meshoptimizer (meshopt_simplify(), its
 * quadric error metric, the rim locked). meshoptimizer is C++ behind a C interface: it is
 * loaded by its soname at the call (IP_MESHOPT_SONAME, found by CMake), never linked, so that
 * libisoprop links no C++ runtime (the test lean_core) and a program that never simplifies
 * never loads it. No state is kept: each call opens it (the loader counts the references;
 * RTLD_NODELETE keeps it loaded) and looks its two functions up. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "isoprop/mesh.h"

#define DECIMATE_PACKAGE "libmeshoptimizer-dev"
#define DEFAULT_RELATIVE_ERROR 1e-2 /* of the mesh's extent (meshopt_simplifyScale()) */
#define LOCK_BORDER 1u              /* meshopt_SimplifyLockBorder (meshoptimizer 0.18) */

#ifdef IP_MESHOPT_SONAME

#include <dlfcn.h>
#include <meshoptimizer.h>

typedef size_t (*simplify_fn)(unsigned int *destination, const unsigned int *indices,
                              size_t index_count, const float *vertex_positions,
                              size_t vertex_count, size_t vertex_positions_stride,
                              size_t target_index_count, float target_error, unsigned int options,
                              float *result_error);
typedef float (*scale_fn)(const float *vertex_positions, size_t vertex_count,
                          size_t vertex_positions_stride);

/* The prototypes above are the header's (_Generic does not evaluate its operand: no reference
 * to the library is made). */
_Static_assert(_Generic(&meshopt_simplify, simplify_fn : 1, default : 0), "meshopt_simplify");
_Static_assert(_Generic(&meshopt_simplifyScale, scale_fn : 1, default : 0),
               "meshopt_simplifyScale");
_Static_assert(LOCK_BORDER == meshopt_SimplifyLockBorder, "meshopt_SimplifyLockBorder");

typedef struct meshopt {
    simplify_fn simplify;
    scale_fn scale;
} meshopt;

static ip_status load(meshopt *m, ip_error *err)
{
    void *handle = dlopen(IP_MESHOPT_SONAME, RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE);
    if (!handle) {
        const char *why = dlerror();
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "mesh: simplifying needs meshoptimizer (" IP_MESHOPT_SONAME
                        ", Debian package " DECIMATE_PACKAGE "), which cannot be loaded (%s)",
                        why ? why : "not found");
    }
    *(void **)&m->simplify = dlsym(handle, "meshopt_simplify");
    *(void **)&m->scale = dlsym(handle, "meshopt_simplifyScale");
    dlclose(handle); /* RTLD_NODELETE: stays loaded */
    if (!m->simplify || !m->scale)
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "mesh: " IP_MESHOPT_SONAME " lacks meshopt_simplify or "
                        "meshopt_simplifyScale");
    return IP_OK;
}

#else

typedef struct meshopt {
    size_t (*simplify)(unsigned int *, const unsigned int *, size_t, const float *, size_t, size_t,
                       size_t, float, unsigned int, float *);
    float (*scale)(const float *, size_t, size_t);
} meshopt;

static ip_status load(meshopt *m, ip_error *err)
{
    (void)m;
    return ip__fail(err, IP_ERR_UNSUPPORTED,
                    "mesh: simplifying needs meshoptimizer: this build was made without it "
                    "(apt-get install " DECIMATE_PACKAGE ", then configure again)");
}

#endif

/* Keeps only the vertices the `count` indices use, in their old order, renumbering the
 * indices. Returns IP_OK or IP_ERR_NOMEM (the mesh unchanged). */
static ip_status compact(ip_indexed_mesh *mesh, uint32_t *indices, uint64_t count)
{
    uint32_t *renumber = malloc((mesh->vertex_count + 1) * sizeof *renumber);
    if (!renumber)
        return IP_ERR_NOMEM;
    for (uint64_t v = 0; v < mesh->vertex_count; v++)
        renumber[v] = UINT32_MAX;
    for (uint64_t i = 0; i < count; i++)
        renumber[indices[i]] = 0;
    uint32_t kept = 0;
    for (uint64_t v = 0; v < mesh->vertex_count; v++)
        if (renumber[v] == 0) {
            renumber[v] = kept;
            memmove(mesh->positions + 3 * (uint64_t)kept, mesh->positions + 3 * v,
                    3 * sizeof *mesh->positions);
            memmove(mesh->normals + 3 * (uint64_t)kept, mesh->normals + 3 * v,
                    3 * sizeof *mesh->normals);
            kept++;
        }
    for (uint64_t i = 0; i < count; i++)
        mesh->indices[i] = renumber[indices[i]];
    free(renumber);
    mesh->vertex_count = kept;
    mesh->triangle_count = count / 3;
    return IP_OK;
}

ip_status ip_indexed_mesh_decimate(ip_indexed_mesh *mesh, double ratio, double max_error,
                                   double *error, ip_error *err)
{
    if (error)
        *error = 0;
    if (!mesh || !(ratio > 0 && ratio < 1))
        return ip__fail(err, IP_ERR_ARGUMENT, "mesh: decimate ratio %g is not in (0, 1)", ratio);
    if (!(max_error >= 0) || isinf(max_error))
        return ip__fail(err, IP_ERR_ARGUMENT, "mesh: decimate error %g is not a finite length >= 0",
                        max_error);
    meshopt m = {NULL, NULL};
    ip_status st = load(&m, err);
    if (st != IP_OK || mesh->triangle_count == 0)
        return st;
    size_t count = (size_t)(3 * mesh->triangle_count);
    size_t target = 3 * (size_t)(ratio * (double)mesh->triangle_count);
    float scale = m.scale(mesh->positions, (size_t)mesh->vertex_count, 3 * sizeof(float));
    double relative = max_error > 0 && scale > 0 ? max_error / scale : DEFAULT_RELATIVE_ERROR;
    uint32_t *out = malloc(count * sizeof *out);
    if (!out)
        return ip__fail(err, IP_ERR_NOMEM, "mesh: no memory to simplify %llu triangles",
                        (unsigned long long)mesh->triangle_count);
    float reached = 0;
    size_t kept = m.simplify(out, mesh->indices, count, mesh->positions, (size_t)mesh->vertex_count,
                             3 * sizeof(float), target, (float)relative, LOCK_BORDER, &reached);
    /* folds (a thin part flattened onto itself) go: they enclose nothing */
    ip_indexed_mesh simplified = *mesh;
    uint64_t folded = 0;
    simplified.indices = out;
    simplified.triangle_count = kept / 3;
    st = ip__indexed_mesh_drop_folds(&simplified, &folded);
    if (st == IP_OK)
        st = compact(mesh, out, 3 * (size_t)simplified.triangle_count);
    free(out);
    if (st != IP_OK)
        return ip__fail(err, st, "mesh: no memory to simplify %llu triangles",
                        (unsigned long long)mesh->triangle_count);
    if (error)
        *error = (double)reached * (double)scale;
    return IP_OK;
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* isorender --decimate RATIO [--decimate-error LENGTH]: the welded mesh file simplified by
 * edge collapses (ip_indexed_mesh_decimate(): meshoptimizer) to about RATIO of its triangles,
 * the error bounded, the rim kept. */
#include <math.h>
#include <stdio.h>

#include "isorender.h"

int parse_decimate(const char *program, const tool_option *option, const char *const *values,
                   void *base)
{
    double ratio;
    if (tool_parse_double(values[0], &ratio) != 0 || !(ratio > 0 && ratio < 1))
        return tool_usage_error(program,
                                "%s '%s' is not a share of the triangles to keep, in (0, 1)",
                                option->name, values[0]);
    ((options *)base)->decimate = ratio;
    return 0;
}

int parse_decimate_error(const char *program, const tool_option *option, const char *const *values,
                         void *base)
{
    double length;
    if (tool_parse_double(values[0], &length) != 0 || !(length > 0) || isinf(length))
        return tool_usage_error(program, "%s '%s' is not a length > 0", option->name, values[0]);
    ((options *)base)->decimate_error = length;
    return 0;
}

int check_decimate_options(const options *o)
{
    if (o->decimate_error > 0 && !(o->decimate > 0))
        return tool_usage_error("isorender", "--decimate-error bounds --decimate: it needs it");
    if (!(o->decimate > 0))
        return 0;
    if (!o->mesh)
        return tool_usage_error("isorender",
                                "--decimate simplifies the mesh file: it needs --mesh");
    if (o->no_weld)
        return tool_usage_error("isorender", "--decimate needs shared vertices: no --no-weld");
    return 0;
}

int decimate_mesh(run *r, ip_indexed_mesh *welded, ip_error *err)
{
    if (!(r->o.decimate > 0))
        return 0;
    uint64_t before = welded->triangle_count;
    uint64_t target = (uint64_t)(r->o.decimate * (double)before);
    double reached = 0;
    if (ip_indexed_mesh_decimate(welded, r->o.decimate, r->o.decimate_error, &reached, err) !=
        IP_OK)
        return tool_fail("isorender", err);
    r->decimated = 1;
    r->decimate_before = before;
    r->decimate_after = welded->triangle_count;
    r->decimate_reached = reached;
    if (welded->triangle_count > target)
        fprintf(stderr,
                "isorender: warning: %s: --decimate %g stops at %llu of %llu triangles (%.3g%%): "
                "fewer would pass the error bound %s; the mesh keeps the best within it\n",
                r->o.mesh, r->o.decimate, (unsigned long long)welded->triangle_count,
                (unsigned long long)before, 100.0 * (double)welded->triangle_count / (double)before,
                r->o.decimate_error > 0 ? "(--decimate-error)" : "(1% of the mesh's size)");
    if (r->o.common.verbose)
        fprintf(stderr,
                "isorender: decimate: %s: %llu -> %llu triangles, %llu vertices, error %.6g\n",
                r->o.mesh, (unsigned long long)before, (unsigned long long)welded->triangle_count,
                (unsigned long long)welded->vertex_count, reached);
    return 0;
}

void json_decimate(FILE *f, const run *r)
{
    if (!r->decimated)
        return;
    fprintf(f,
            ", \"decimate\": {\"ratio\": %.17g, \"triangles_before\": %llu, "
            "\"triangles_after\": %llu, \"error\": %.9g, \"error_bound\": ",
            r->o.decimate, (unsigned long long)r->decimate_before,
            (unsigned long long)r->decimate_after, r->decimate_reached);
    if (r->o.decimate_error > 0) /* else 1 % of the mesh's size, as the library takes it */
        fprintf(f, "%.9g}", r->o.decimate_error);
    else
        fprintf(f, "null}");
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* isorender's surfaces (several --iso): a run each; their colours, opacities and mesh files. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "isorender.h"

/* The colours of the second to last surfaces when --color leaves them out, by position (the
 * first surface's is the shading's, the default ivory). */
static const float surface_palette[TOOL_MAX_ISOS - 1][3] = {
    {0.561f, 0.702f, 0.851f}, /* #8fb3d9 */
    {0.878f, 0.639f, 0.439f}, /* #e0a370 */
    {0.612f, 0.812f, 0.561f}, /* #9ccf8f */
};

void iso_text(double iso, char *out, size_t size)
{
    float value = (float)iso;
    for (int digits = 6; digits <= 9; digits++) {
        snprintf(out, size, "%.*g", digits, (double)value);
        if ((float)strtod(out, NULL) == value)
            return;
    }
}

int several_surfaces(const run *r)
{
    return r->other_count > 0 || (r->o.opacity_count && r->o.opacity[0] < 1.0f);
}

run *surface_run(run *r, size_t i)
{
    return i ? &r->others[i - 1] : r;
}

const run *surface_run_c(const run *r, size_t i)
{
    return i ? &r->others[i - 1] : r;
}

void surface_of(const run *r, size_t i, const uint64_t *prefix, ip_mesh *views, ip_surface *out)
{
    const options *o = &r->o;
    views[i] = *surface_run_c(r, i)->mesh; /* a view of the triangles, not a copy */
    if (prefix)
        views[i].triangle_count = prefix[i];
    out->mesh = &views[i];
    const float *colour = i < o->colour_count ? o->colours[i]
                          : i == 0            ? o->shading.surface
                                              : surface_palette[i - 1];
    memcpy(out->colour, colour, sizeof out->colour);
    out->opacity = i < o->opacity_count ? o->opacity[i] : 1.0f;
}

void share_view(const run *r, run *s)
{
    if (s == r)
        return;
    s->store = r->store;
    s->cache = r->cache;
    s->space = r->space;
    s->camera = r->camera;
    s->view_camera = r->view_camera;
    memcpy(s->o.common.clip, r->o.common.clip, sizeof s->o.common.clip);
    memcpy(s->o.common.clip_physical, r->o.common.clip_physical, sizeof s->o.common.clip_physical);
    memcpy(s->lo, r->lo, sizeof s->lo);
    memcpy(s->hi, r->hi, sizeof s->hi);
}

uint64_t all_triangles(const run *r)
{
    uint64_t sum = 0;
    for (size_t i = 0; i <= r->other_count; i++)
        sum += surface_run_c(r, i)->mesh->triangle_count;
    return sum;
}

/* The mesh file of the surface of isovalue `iso`: `path` with "_isoV" before its extension
 * (head.ply: head_iso600.5.ply; V as iso_text() gives it). Returns 0, or 2 after a usage
 * error. */
static int surface_mesh_name(const char *path, double iso, char *out, size_t size)
{
    const char *slash = strrchr(path, '/'), *dot = strrchr(path, '.');
    if (!dot || (slash && dot < slash))
        dot = path + strlen(path);
    char value[32];
    iso_text(iso, value, sizeof value);
    int length = snprintf(out, size, "%.*s_iso%s%s", (int)(dot - path), path, value, dot);
    if (length < 0 || (size_t)length >= size)
        return tool_usage_error("isorender", "--mesh %s: the name is too long", path);
    return 0;
}

int setup_surfaces(run *r)
{
    size_t n = r->o.common.iso_count;
    r->o.common.iso = r->o.common.isos[0]; /* the first --iso is the first surface's */
    if (n < 2)
        return 0;
    r->others = calloc(n - 1, sizeof *r->others);
    if (!r->others) {
        fprintf(stderr, "isorender: out of memory\n");
        return 1;
    }
    r->other_count = n - 1;
    for (size_t i = 1; i < n; i++) {
        r->others[i - 1].o = r->o;
        r->others[i - 1].o.common.iso = r->o.common.isos[i];
    }
    for (size_t i = 0; r->o.mesh && i < n; i++) {
        run *s = surface_run(r, n - 1 - i); /* the first last: its name is the template */
        if (surface_mesh_name(r->o.mesh, s->o.common.iso, s->mesh_name, sizeof s->mesh_name))
            return 2;
        s->o.mesh = s->mesh_name;
    }
    return 0;
}

void free_surfaces(run *r)
{
    for (size_t i = 0; i < r->other_count; i++) {
        ip_engine_destroy(r->others[i].engine);
        ip_mesh_free(&r->others[i].full_mesh);
        free(r->others[i].checkpoints);
    }
    free(r->others);
}

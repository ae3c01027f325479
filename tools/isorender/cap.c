/* SPDX-License-Identifier: BSD-3-Clause */
/* isorender --cap: the --full surface closed where it leaves the volume's box
 * (ip_extract_cap()), so that the image and the mesh file show a closed solid. */
#include "isorender.h"

int check_cap_options(const options *o)
{
    if (!o->cap)
        return 0;
    if (o->full != TOOL_FULL)
        return tool_usage_error("isorender", "--cap closes the whole surface: it needs --full");
    if (o->common.clip_count)
        return tool_usage_error("isorender", "--cap closes the surface at the volume's faces "
                                             "only: not with --clip");
    return 0;
}

int cap_surface(run *r, ip_error *err)
{
    if (!r->o.cap)
        return 0;
    uint64_t before = r->full_mesh.triangle_count;
    if (ip_extract_cap(r->cache, r->o.common.iso_stored, 0, &r->full_mesh, err) != IP_OK)
        return -1;
    r->cap_triangles = r->full_mesh.triangle_count - before;
    if (r->o.common.verbose)
        fprintf(stderr, "isorender: cap: %llu triangles on the volume's faces\n",
                (unsigned long long)r->cap_triangles);
    return 0;
}

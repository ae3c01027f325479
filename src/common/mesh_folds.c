/* SPDX-License-Identifier: BSD-3-Clause */
/* Folds in a welded mesh: two triangles on the same three vertices, wound opposite ways, as
 * edge collapses leave where a thin part is flattened onto itself. The pair encloses nothing
 * and its edges are each other's, so dropping both keeps a closed mesh closed and the enclosed
 * volume the same, and makes the edges they shared with the rest manifold again. */
#include <stdlib.h>

#include "internal.h"
#include "isoprop/mesh.h"

typedef struct fold_key {
    uint32_t v[3];  /* the triangle's vertices, sorted */
    uint32_t odd;   /* 1 when sorting them took an odd permutation (the other winding) */
    uint64_t index; /* the triangle */
} fold_key;

static int compare_keys(const void *pa, const void *pb)
{
    const fold_key *a = pa, *b = pb;
    for (int k = 0; k < 3; k++)
        if (a->v[k] != b->v[k])
            return a->v[k] < b->v[k] ? -1 : 1;
    if (a->odd != b->odd)
        return a->odd < b->odd ? -1 : 1;
    return a->index < b->index ? -1 : a->index > b->index;
}

static fold_key key_of(const uint32_t *c, uint64_t t)
{
    fold_key k = {{c[0], c[1], c[2]}, 0, t};
    for (int pass = 0; pass < 2; pass++) /* three compare-swaps, counting the swaps */
        for (int i = 0; i + 1 < 3 - pass; i++)
            if (k.v[i] > k.v[i + 1]) {
                uint32_t x = k.v[i];
                k.v[i] = k.v[i + 1];
                k.v[i + 1] = x;
                k.odd ^= 1u;
            }
    return k;
}

ip_status ip__indexed_mesh_drop_folds(ip_indexed_mesh *mesh, uint64_t *dropped)
{
    *dropped = 0;
    uint64_t n = mesh->triangle_count;
    fold_key *keys = malloc((n + 1) * sizeof *keys);
    unsigned char *drop = calloc(n + 1, 1);
    if (!keys || !drop) {
        free(keys);
        free(drop);
        return IP_ERR_NOMEM;
    }
    for (uint64_t t = 0; t < n; t++)
        keys[t] = key_of(mesh->indices + 3 * t, t);
    qsort(keys, n, sizeof *keys, compare_keys);
    for (uint64_t i = 0; i < n;) { /* a run of one vertex set: evens first, then odds */
        uint64_t j = i, odd = i;
        while (j < n && keys[j].v[0] == keys[i].v[0] && keys[j].v[1] == keys[i].v[1] &&
               keys[j].v[2] == keys[i].v[2])
            odd += keys[j++].odd == 0;
        for (uint64_t e = i, o = odd; e < odd && o < j; e++, o++) { /* pair them off */
            drop[keys[e].index] = drop[keys[o].index] = 1;
            *dropped += 2;
        }
        i = j;
    }
    uint64_t kept = 0;
    for (uint64_t t = 0; t < n; t++)
        if (!drop[t]) {
            for (int k = 0; k < 3; k++)
                mesh->indices[3 * kept + (uint64_t)k] = mesh->indices[3 * t + (uint64_t)k];
            kept++;
        }
    mesh->triangle_count = kept;
    free(keys);
    free(drop);
    return IP_OK;
}

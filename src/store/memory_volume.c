/* SPDX-License-Identifier: BSD-3-Clause */
/* A volume in the caller's memory: the coarser levels of its pyramid, its summaries, and
 * gathering a brick from it. */
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "memory_volume.h"
#include "pool.h"
#include "pyramid.h"
#include "summary.h"

/* One run of the pool over `total` items (planes or bricks) taken from a shared counter. */
typedef struct build_job {
    const ip__memory_volume *m;
    const ip_layout *l;
    uint32_t level;           /* subsampling: the level being built */
    const uint32_t *index[2]; /* subsampling: level `level - 1`'s x and y of each sample */
    float *brick_ranges, *subblock_ranges;
    unsigned char **scratch; /* summaries: a brick's samples, one per job */
    uint64_t total;
    atomic_uint_fast64_t next;
    atomic_uint_fast64_t first_bad; /* non-finite search: the lowest linear index found */
} build_job;

static size_t sample_size(const ip_layout *l)
{
    return ip_type_size(l->type);
}

/* Where level `level`'s samples lie: the caller's strides at level 0, the held level's
 * (contiguous) above. */
static const unsigned char *level_base(const ip__memory_volume *m, const ip_layout *l,
                                       uint32_t level, ptrdiff_t strides[3])
{
    if (level == 0) {
        memcpy(strides, m->strides, sizeof m->strides);
        return m->samples;
    }
    const ip_level_layout *lv = &l->levels[level];
    strides[0] = (ptrdiff_t)sample_size(l);
    strides[1] = strides[0] * (ptrdiff_t)lv->dims[0];
    strides[2] = strides[1] * (ptrdiff_t)lv->dims[1];
    return m->levels[level];
}

void ip__memory_volume_gather(const ip__memory_volume *m, const ip_layout *l, uint32_t level,
                              const uint32_t origin[3], const uint32_t extent[3], void *dst)
{
    ptrdiff_t st[3];
    const unsigned char *base = level_base(m, l, level, st);
    size_t ss = sample_size(l), row_bytes = extent[0] * ss;
    unsigned char *out = dst;
    base +=
        (ptrdiff_t)origin[0] * st[0] + (ptrdiff_t)origin[1] * st[1] + (ptrdiff_t)origin[2] * st[2];
    for (uint32_t z = 0; z < extent[2]; z++)
        for (uint32_t y = 0; y < extent[1]; y++) {
            const unsigned char *row = base + (ptrdiff_t)z * st[2] + (ptrdiff_t)y * st[1];
            if (st[0] == (ptrdiff_t)ss) {
                memcpy(out, row, row_bytes);
                out += row_bytes;
                continue;
            }
            for (uint32_t x = 0; x < extent[0]; x++, out += ss)
                memcpy(out, row + (ptrdiff_t)x * st[0], ss);
        }
}

/* ---- finite float32 samples ---- */

static void nonfinite_worker(void *user, unsigned index)
{
    build_job *job = user;
    const ip_layout *l = job->l;
    const uint32_t exponent = 0x7f800000u;
    (void)index;
    for (;;) {
        uint64_t z = atomic_fetch_add(&job->next, 1);
        if (z >= job->total)
            break;
        for (uint32_t y = 0; y < l->dims[1]; y++) {
            const unsigned char *row = job->m->samples + (ptrdiff_t)z * job->m->strides[2] +
                                       (ptrdiff_t)y * job->m->strides[1];
            for (uint32_t x = 0; x < l->dims[0]; x++) {
                uint32_t bits;
                memcpy(&bits, row + (ptrdiff_t)x * job->m->strides[0], sizeof bits);
                if ((bits & exponent) != exponent)
                    continue;
                uint64_t at = (z * l->dims[1] + y) * l->dims[0] + x;
                uint64_t seen = atomic_load(&job->first_bad);
                while (at < seen && !atomic_compare_exchange_weak(&job->first_bad, &seen, at))
                    ;
                y = l->dims[1]; /* the rest of the plane comes later in order */
                break;
            }
        }
    }
}

int ip__memory_volume_find_nonfinite(const ip__memory_volume *m, const ip_layout *l,
                                     unsigned threads, uint32_t xyz[3])
{
    if (l->type != IP_FLOAT32)
        return 0;
    build_job job;
    memset(&job, 0, sizeof job);
    job.m = m;
    job.l = l;
    job.total = l->dims[2];
    atomic_init(&job.next, 0);
    atomic_init(&job.first_bad, UINT64_MAX);
    ip__pool *pool = NULL;
    if (threads > 1 && ip__pool_create(threads, &pool, NULL) == IP_OK)
        ip__pool_run(pool, threads, nonfinite_worker, &job);
    else
        nonfinite_worker(&job, 0);
    ip__pool_destroy(pool);
    uint64_t at = atomic_load(&job.first_bad);
    if (at == UINT64_MAX)
        return 0;
    xyz[0] = (uint32_t)(at % l->dims[0]);
    xyz[1] = (uint32_t)(at / l->dims[0] % l->dims[1]);
    xyz[2] = (uint32_t)(at / ((uint64_t)l->dims[0] * l->dims[1]));
    return 1;
}

/* ---- the pyramid and the summaries ---- */

/* Plane z of job->level from the level below it: every level samples every other sample of
 * the one below (and its last), which is the level-0 sample ip_level_sample_index() names. */
static void subsample_worker(void *user, unsigned index)
{
    build_job *job = user;
    const ip_layout *l = job->l;
    const ip_level_layout *lv = &l->levels[job->level];
    uint32_t below = job->level - 1;
    (void)index;
    for (;;) {
        uint64_t z = atomic_fetch_add(&job->next, 1);
        if (z >= job->total)
            break;
        ptrdiff_t st[3];
        const unsigned char *base = level_base(job->m, l, below, st);
        uint32_t source_z = ip_level_sample_index(l->levels[below].dims[2], 1, (uint32_t)z);
        ip__plane_source src = {base + (ptrdiff_t)source_z * st[2], st[0], st[1], sample_size(l)};
        unsigned char *dst =
            job->m->levels[job->level] + z * lv->dims[0] * lv->dims[1] * sample_size(l);
        ip__subsample_plane(&src, job->index[0], job->index[1], lv->dims[0], lv->dims[1], dst);
    }
}

static void summary_worker(void *user, unsigned index)
{
    build_job *job = user;
    const ip_layout *l = job->l;
    uint32_t subblocks = ip_layout_subblocks_per_brick(l);
    for (;;) {
        uint64_t g = atomic_fetch_add(&job->next, 1);
        if (g >= job->total)
            break;
        uint32_t level, brick[3], origin[3], extent[3];
        ip_brick_coords(l, g, &level, brick);
        ip_brick_extent(l, level, brick, origin, extent);
        ip__memory_volume_gather(job->m, l, level, origin, extent, job->scratch[index]);
        ip__summarise_brick(job->scratch[index], l->type, extent, l->brick_edge, l->subblock_edge,
                            &job->brick_ranges[2 * g], &job->subblock_ranges[2 * g * subblocks]);
    }
}

/* Runs fn over job->total items on the pool. */
static void run(ip__pool *pool, build_job *job, uint64_t total, ip__pool_job fn)
{
    unsigned jobs = ip__pool_threads(pool);
    job->total = total;
    atomic_store(&job->next, 0);
    ip__pool_run(pool, total < jobs ? (unsigned)total : jobs, fn, job);
}

/* Levels 1.. from the level below each, plane by plane on the pool. */
static ip_status build_levels(ip__memory_volume *m, const ip_layout *l, ip__pool *pool,
                              build_job *job)
{
    for (uint32_t k = 1; k < l->level_count; k++) {
        const ip_level_layout *lv = &l->levels[k], *below = &l->levels[k - 1];
        uint64_t bytes = (uint64_t)lv->dims[0] * lv->dims[1] * lv->dims[2] * sample_size(l);
        uint32_t *index[2] = {malloc(lv->dims[0] * sizeof(uint32_t)),
                              malloc(lv->dims[1] * sizeof(uint32_t))};
        m->levels[k] = bytes <= SIZE_MAX ? malloc((size_t)bytes) : NULL;
        ip_status st = index[0] && index[1] && m->levels[k] ? IP_OK : IP_ERR_NOMEM;
        if (st == IP_OK) {
            m->held_bytes += bytes;
            for (int a = 0; a < 2; a++)
                for (uint32_t i = 0; i < lv->dims[a]; i++)
                    index[a][i] = ip_level_sample_index(below->dims[a], 1, i);
            job->level = k;
            job->index[0] = index[0];
            job->index[1] = index[1];
            run(pool, job, lv->dims[2], subsample_worker);
        }
        free(index[0]);
        free(index[1]);
        if (st != IP_OK)
            return st;
    }
    return IP_OK;
}

ip_status ip__memory_volume_build(ip__memory_volume *m, const ip_layout *l, unsigned threads,
                                  float *brick_ranges, float *subblock_ranges)
{
    ip__pool *pool = NULL;
    if (ip__pool_create(threads, &pool, NULL) != IP_OK)
        return IP_ERR_NOMEM;
    unsigned jobs = ip__pool_threads(pool);
    size_t edge = (size_t)l->brick_edge + 1;
    build_job job;
    memset(&job, 0, sizeof job);
    job.m = m;
    job.l = l;
    job.brick_ranges = brick_ranges;
    job.subblock_ranges = subblock_ranges;
    atomic_init(&job.next, 0);
    atomic_init(&job.first_bad, UINT64_MAX);
    job.scratch = calloc(jobs, sizeof *job.scratch);
    ip_status st = job.scratch ? IP_OK : IP_ERR_NOMEM;
    for (unsigned t = 0; st == IP_OK && t < jobs; t++)
        if (!(job.scratch[t] = malloc(edge * edge * edge * sample_size(l))))
            st = IP_ERR_NOMEM;
    if (st == IP_OK)
        st = build_levels(m, l, pool, &job);
    if (st == IP_OK)
        run(pool, &job, l->brick_count, summary_worker);
    for (unsigned t = 0; job.scratch && t < jobs; t++)
        free(job.scratch[t]);
    free(job.scratch);
    ip__pool_destroy(pool);
    return st;
}

void ip__memory_volume_free(ip__memory_volume *m)
{
    for (uint32_t k = 0; k < IP_MAX_LEVELS; k++)
        free(m->levels[k]);
    memset(m, 0, sizeof *m);
}

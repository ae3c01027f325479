/* SPDX-License-Identifier: BSD-3-Clause */
/* Streaming bricking: input planes -> pyramid slabs -> compressed bricks -> brick file. */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#include <xxhash.h>

#include "atomic_file.h"
#include "internal.h"
#include "isoprop/bricker.h"
#include "codec.h"
#include "format.h"
#include "input_positioned.h"
#include "isoprop/output.h"
#include "pool.h"
#include "pyramid.h"
#include "sized.h"
#include "summary.h"

/* One pyramid level's slab: the B+1 planes of the brick layer being filled, kept in a ring
 * of B+1 slots (level plane p lives in slot p % slots), so that the + face of a layer stays
 * where it is when it becomes the - face of the next. When reading overlaps encoding, level 0
 * has 2B+1 slots: the B planes of the next chunk land in slots the layer being encoded does
 * not use. */
typedef struct level_slab {
    unsigned char *planes;
    size_t plane_bytes;
    uint32_t slots;    /* planes in the ring */
    uint32_t arrived;  /* level planes placed so far: planes [0, arrived) */
    uint32_t layer;    /* next brick layer (bz) to compress */
    uint32_t *x_index; /* level-0 x of each level x (levels >= 1) */
    uint32_t *y_index;
    float *layer_ranges; /* sub-block ranges of one layer of bricks, until they are spilled */
} level_slab;

typedef struct bricker bricker;

/* Per-thread scratch for gathering and encoding one brick, and the thread's first error. */
typedef struct brick_scratch {
    unsigned char *samples, *out, *work;
    unsigned char *rows; /* integer types: the min and max rows of ip__summarise_brick_row() */
    ip_status status;
    ip_error error;
} brick_scratch;

/* The layers of bricks that one chunk of planes completed (at most one per level). */
typedef struct layer_ref {
    uint32_t level, bz;
    uint64_t first; /* index of the layer's first brick among the job's bricks */
    uint64_t count;
} layer_ref;

/* One run of the pool: the planes of a chunk to read or to feed to the coarser levels, or the
 * bricks of its layers to encode. */
typedef struct chunk_job {
    bricker *b;
    const ip_input_reader *reader;
    uint32_t z0; /* reading and feeding: first level-0 plane */
    layer_ref layers[IP_MAX_LEVELS];
    uint32_t layer_count;
    uint64_t total;            /* planes or bricks */
    atomic_uint_fast64_t next; /* next plane or brick to take */
    atomic_int failed;
} chunk_job;

struct bricker {
    ip_layout layout;
    const ip_bricker_options *options;
    const char *out_path;
    size_t sample_size;
    unsigned threads;
    ip__pool *pool; /* reads and encodes every chunk; started at init */
    int overlap;    /* a thread reads the next chunk while the pool encodes (read_ahead) */
    atomic_uint_fast64_t direct_bytes; /* input bytes read with O_DIRECT */
    level_slab slabs[IP_MAX_LEVELS];
    brick_scratch *scratch;  /* one per job of a run (per thread) */
    ip_brick_entry *entries; /* offsets point into the spill file until the end */
    float *brick_ranges;     /* 2 per brick */
    uint32_t subblocks;      /* per brick */
    /* The spill file: the sub-block ranges (host floats, by global brick index) in
     * [0, ranges_bytes), then the payloads in the order the threads finish them. */
    int spill_fd;
    uint64_t ranges_bytes;
    atomic_uint_fast64_t spill_end;
    ip_bricker_report report;
};

/* Bytes of the summary section written per pwrite while it is streamed out. */
#define SUMMARY_CHUNK ((size_t)1 << 20)

/* ---- memory ---- */

static size_t brick_samples_max(const ip_layout *l)
{
    size_t e = (size_t)l->brick_edge + 1;
    return e * e * e;
}

/* Planes in level k's ring: B+1, and B more at level 0 when reading overlaps encoding. */
static uint32_t slab_slots(const ip_layout *l, uint32_t k, int overlap)
{
    return l->brick_edge + 1 + (k == 0 && overlap ? l->brick_edge : 0);
}

static uint64_t slab_bytes(const ip_layout *l, uint32_t k, int overlap)
{
    const ip_level_layout *lv = &l->levels[k];
    return (uint64_t)slab_slots(l, k, overlap) * lv->dims[0] * lv->dims[1] * ip_type_size(l->type);
}

/* Slabs are allocated in whole huge pages (alloc_slab()). */
#define SLAB_ALIGN ((size_t)2 << 20)

static size_t slab_rounded(uint64_t bytes)
{
    return (size_t)((bytes + SLAB_ALIGN - 1) / SLAB_ALIGN * SLAB_ALIGN);
}

/* Bytes of one layer of sub-block ranges of level k. */
static uint64_t layer_ranges_bytes(const ip_layout *l, uint32_t k)
{
    const ip_level_layout *lv = &l->levels[k];
    return (uint64_t)lv->bricks[0] * lv->bricks[1] * ip_layout_subblocks_per_brick(l) * 2 *
           sizeof(float);
}

/* Bytes of a thread's min and max rows for the summaries of integer levels (level 0 is the
 * widest); float32 has none. */
static size_t summary_rows_bytes(const ip_layout *l)
{
    return l->type == IP_FLOAT32 ? 0 : ip__brick_row_scratch_bytes(l->dims[0], l->type);
}

static unsigned thread_count(const ip_bricker_options *o)
{
    return ip_thread_count(o->threads);
}

/* Everything the run allocates, counted from the same sizes the allocations use: the slabs and
 * their index tables, a layer of sub-block ranges per level, the per-thread scratch (with its
 * min and max rows), the directory and brick ranges (the sub-block ranges wait in the spill
 * file), the octree nodes, the Morton order of the largest level and the buffer the summary is
 * streamed through. */
static uint64_t memory_for(const ip_layout *l, unsigned threads, int overlap)
{
    uint64_t total = 0, widest_level = 0;
    size_t bs = brick_samples_max(l);
    for (uint32_t k = 0; k < l->level_count; k++) {
        const ip_level_layout *lv = &l->levels[k];
        total += slab_rounded(slab_bytes(l, k, overlap)) + layer_ranges_bytes(l, k);
        total += (uint64_t)(lv->dims[0] + lv->dims[1]) * sizeof(uint32_t);
        if (lv->brick_count > widest_level)
            widest_level = lv->brick_count;
    }
    total += (uint64_t)threads * (bs * ip_type_size(l->type) + ip__codec_bound(bs, l->type) +
                                  ip__codec_work_size(bs, l->type) + summary_rows_bytes(l));
    total += l->brick_count * (sizeof(ip_brick_entry) + 2 * sizeof(float));
    total += 2 * sizeof(float) * (l->node_count ? l->node_count : 1);
    total += widest_level * sizeof(uint64_t) + SUMMARY_CHUNK;
    return total;
}

/* Whether reading overlaps encoding: when the input has more than one chunk and the plan with
 * the second level-0 chunk, and the `reader` bytes the input's reader holds
 * (ip_input_desc.reader_bytes), fits `limit` (0: no limit). */
static int plan_overlap(const ip_layout *l, unsigned threads, uint64_t reader, uint64_t limit)
{
    return l->levels[0].bricks[2] > 1 &&
           (limit == 0 || reader + memory_for(l, threads, 1) <= limit);
}

void ip_bricker_options_default(ip_bricker_options *options)
{
    memset(options, 0, sizeof *options);
    options->size = sizeof *options;
    options->brick_edge = IP_DEFAULT_BRICK_EDGE;
    options->subblock_edge = IP_DEFAULT_SUBBLOCK_EDGE;
    options->lz4_level = IP_LZ4_FAST;
}

/* The caller's options (a sized struct, status.h) as this library's, into *taken. */
static ip_status take_options(const ip_bricker_options *given, ip_bricker_options *taken,
                              ip_error *err)
{
    ip_bricker_options_default(taken);
    return ip__sized_in(taken, sizeof *taken, given,
                        IP__SIZE_UPTO(ip_bricker_options, progress_user), "bricker options", err);
}

ip_status ip_bricker_memory_needed(const ip_input_desc *input, const ip_bricker_options *given,
                                   uint64_t *bytes, ip_error *err)
{
    ip_layout l;
    ip_bricker_options taken;
    const ip_bricker_options *options = &taken;
    ip_status st = take_options(given, &taken, err);
    if (st != IP_OK)
        return st;
    st = ip__layout_init(&l, input->dims, input->type, input->spacing, options->brick_edge,
                         options->subblock_edge, err);
    if (st == IP_OK) {
        unsigned threads = thread_count(options);
        *bytes = input->reader_bytes +
                 memory_for(&l, threads,
                            plan_overlap(&l, threads, input->reader_bytes, options->memory_limit));
    }
    return st;
}

/* Records a worker's first failure; the run stops taking work. */
static void worker_failed(chunk_job *job, brick_scratch *s, ip_status st)
{
    if (s->status == IP_OK)
        s->status = st;
    atomic_store(&job->failed, 1);
}

/* ---- one brick ---- */

static const unsigned char *slab_plane(const level_slab *slab, uint32_t plane)
{
    return slab->planes + (size_t)(plane % slab->slots) * slab->plane_bytes;
}

/* Where the brick's slices lie in the slab: slice z of the brick starts at planes[z]. */
static void brick_planes(const level_slab *slab, const ip_layout *l, uint32_t level,
                         const uint32_t origin[3], const uint32_t extent[3],
                         const unsigned char **planes)
{
    size_t ss = ip_type_size(l->type);
    size_t level_row = (size_t)l->levels[level].dims[0] * ss;
    for (uint32_t z = 0; z < extent[2]; z++)
        planes[z] =
            slab_plane(slab, origin[2] + z) + (size_t)origin[1] * level_row + origin[0] * ss;
}

static void gather_brick(const unsigned char *const *planes, size_t level_row,
                         const uint32_t extent[3], size_t ss, unsigned char *dst)
{
    size_t row_bytes = (size_t)extent[0] * ss;
    for (uint32_t z = 0; z < extent[2]; z++)
        for (uint32_t y = 0; y < extent[1]; y++) {
            memcpy(dst, planes[z] + y * level_row, row_bytes);
            dst += row_bytes;
        }
}

/* Appends a payload to the spill file at a place reserved for it alone, so that the threads
 * write concurrently; write_payloads() puts the payloads in order at the end. */
static ip_status spill_payload(bricker *b, ip_brick_entry *e, const unsigned char *payload,
                               ip_error *err)
{
    e->offset = atomic_fetch_add(&b->spill_end, e->stored_size);
    return ip__pwrite_all(b->spill_fd, payload, e->stored_size, e->offset, b->out_path, err);
}

static ip_status process_brick(bricker *b, const layer_ref *ref, uint64_t i, brick_scratch *s)
{
    const ip_layout *l = &b->layout;
    const level_slab *slab = &b->slabs[ref->level];
    uint32_t brick[3] = {(uint32_t)(i % l->levels[ref->level].bricks[0]),
                         (uint32_t)(i / l->levels[ref->level].bricks[0]), ref->bz};
    uint32_t origin[3], extent[3];
    ip_brick_extent(l, ref->level, brick, origin, extent);
    uint64_t g = ip_brick_global_index(l, ref->level, brick);
    const unsigned char *planes[IP_MAX_BRICK_EDGE + 1];
    brick_planes(slab, l, ref->level, origin, extent, planes);
    size_t level_row = (size_t)l->levels[ref->level].dims[0] * b->sample_size;
    float *range = &b->brick_ranges[2 * g], *ranges = &slab->layer_ranges[2 * i * b->subblocks];
    ip_brick_entry *e = &b->entries[g];
    if (l->type == IP_FLOAT32) {
        /* -0 and +0 compare equal but are different bytes: the codec decides what is constant */
        gather_brick(planes, level_row, extent, b->sample_size, s->samples);
        ip__summarise_brick(s->samples, l->type, extent, l->brick_edge, l->subblock_edge, range,
                            ranges);
    } else {
        /* its sub-block ranges are in the layer's (summarise_layers()); an integer brick is
         * constant when its range is a single value: no copy is made */
        ip__union_range(ranges, b->subblocks, range);
        if (range[0] == range[1]) {
            ip__codec_encode_constant(e);
            return IP_OK;
        }
        gather_brick(planes, level_row, extent, b->sample_size, s->samples);
    }
    if (ip__codec_encode(s->samples, extent, l->type, b->options->lz4_level, s->out, s->work, e) !=
        IP_OK)
        return ip__fail(&s->error, IP_ERR_ARGUMENT, "%s: brick %llu does not encode", b->out_path,
                        (unsigned long long)g);
    return e->stored_size > 0 ? spill_payload(b, e, s->out, &s->error) : IP_OK;
}

/* The layer of `job` that its item `i` (a brick or a brick row) belongs to. */
static const layer_ref *job_layer(const chunk_job *job, uint64_t i)
{
    uint32_t r = 0;
    while (i >= job->layers[r].first + job->layers[r].count)
        r++;
    return &job->layers[r];
}

/* One job of an encoding run (on the pool): takes bricks from the shared counter until none is
 * left, with scratch buffers of its own. */
static void encode_worker(void *user, unsigned index)
{
    chunk_job *job = user;
    brick_scratch *scratch = &job->b->scratch[index];
    for (;;) {
        uint64_t i = atomic_fetch_add(&job->next, 1);
        if (i >= job->total || atomic_load(&job->failed))
            break;
        const layer_ref *ref = job_layer(job, i);
        ip_status st = process_brick(job->b, ref, i - ref->first, scratch);
        if (st != IP_OK)
            worker_failed(job, scratch, st);
    }
}

/* One job of a summary run (on the pool): takes brick rows of the layers from the shared
 * counter and writes the sub-block ranges of their bricks into the layers' ranges. */
static void summary_worker(void *user, unsigned index)
{
    chunk_job *job = user;
    bricker *b = job->b;
    const ip_layout *l = &b->layout;
    for (;;) {
        uint64_t i = atomic_fetch_add(&job->next, 1);
        if (i >= job->total)
            break;
        const layer_ref *ref = job_layer(job, i);
        const level_slab *slab = &b->slabs[ref->level];
        const ip_level_layout *lv = &l->levels[ref->level];
        uint32_t brick[3] = {0, 0, ref->bz}, origin[3], extent[3];
        ip_brick_extent(l, ref->level, brick, origin, extent);
        const unsigned char *planes[IP_MAX_BRICK_EDGE + 1];
        for (uint32_t z = 0; z < extent[2]; z++)
            planes[z] = slab_plane(slab, origin[2] + z);
        ip__layer_rows rows = {planes,        (size_t)lv->dims[0] * b->sample_size,
                               l->type,       {lv->dims[0], lv->dims[1]},
                               extent[2],     {lv->bricks[0], lv->bricks[1]},
                               l->brick_edge, l->subblock_edge};
        ip__summarise_brick_row(&rows, (uint32_t)(i - ref->first), b->scratch[index].rows,
                                slab->layer_ranges);
    }
}

/* ---- the pool's runs ---- */

/* Runs `fn` on the pool with one job per thread (fewer when there is less work) and returns
 * the first error a job recorded. */
static ip_status run_jobs(bricker *b, chunk_job *job, ip__pool_job fn, ip_error *err)
{
    atomic_init(&job->next, 0);
    atomic_init(&job->failed, 0);
    unsigned jobs = b->threads;
    if (jobs > job->total)
        jobs = (unsigned)(job->total > 0 ? job->total : 1);
    for (unsigned t = 0; t < jobs; t++)
        b->scratch[t].status = IP_OK;
    ip__pool_run(b->pool, jobs, fn, job);
    for (unsigned t = 0; t < jobs; t++)
        if (b->scratch[t].status != IP_OK) {
            if (err)
                *err = b->scratch[t].error;
            return b->scratch[t].status;
        }
    return IP_OK;
}

/* The last level plane of brick layer bz of level k. */
static uint32_t layer_last_plane(const ip_layout *l, uint32_t k, uint32_t bz)
{
    uint64_t last = (uint64_t)l->brick_edge * (bz + 1);
    uint32_t top = l->levels[k].dims[2] - 1;
    return last < top ? (uint32_t)last : top;
}

/* The sub-block ranges of the layers of `encode` (integer types), brick row by brick row on
 * every thread, before their bricks are encoded: full-width rows are read in order, which the
 * memory serves faster than the short rows of one brick at a time. */
static ip_status summarise_layers(bricker *b, const chunk_job *encode, ip_error *err)
{
    if (b->layout.type == IP_FLOAT32)
        return IP_OK;
    chunk_job job;
    memset(&job, 0, sizeof job);
    job.b = b;
    job.layer_count = encode->layer_count;
    for (uint32_t r = 0; r < encode->layer_count; r++) {
        job.layers[r] = encode->layers[r];
        job.layers[r].first = job.total;
        job.layers[r].count = b->layout.levels[encode->layers[r].level].bricks[1];
        job.total += job.layers[r].count;
    }
    return run_jobs(b, &job, summary_worker, err);
}

/* Encodes every layer whose planes have all arrived, on every thread, then sends each layer's
 * sub-block ranges to the spill file. A chunk completes at most one layer per level: a level-k
 * layer ends at a level-0 plane that is a multiple of B, or at the last plane. */
static ip_status encode_ready_layers(bricker *b, ip_error *err)
{
    const ip_layout *l = &b->layout;
    chunk_job job;
    memset(&job, 0, sizeof job);
    job.b = b;
    for (uint32_t k = 0; k < l->level_count; k++) {
        level_slab *slab = &b->slabs[k];
        if (slab->layer >= l->levels[k].bricks[2] ||
            slab->arrived <= layer_last_plane(l, k, slab->layer))
            continue;
        layer_ref *ref = &job.layers[job.layer_count++];
        ref->level = k;
        ref->bz = slab->layer;
        ref->first = job.total;
        ref->count = (uint64_t)l->levels[k].bricks[0] * l->levels[k].bricks[1];
        job.total += ref->count;
    }
    ip_status st = job.total ? summarise_layers(b, &job, err) : IP_OK;
    if (st == IP_OK && job.total)
        st = run_jobs(b, &job, encode_worker, err);
    for (uint32_t r = 0; st == IP_OK && r < job.layer_count; r++) {
        const layer_ref *ref = &job.layers[r];
        level_slab *slab = &b->slabs[ref->level];
        uint32_t brick[3] = {0, 0, ref->bz};
        uint64_t g = ip_brick_global_index(l, ref->level, brick);
        st = ip__pwrite_all(b->spill_fd, slab->layer_ranges, layer_ranges_bytes(l, ref->level),
                            g * b->subblocks * 2 * sizeof(float), b->out_path, err);
        slab->layer++;
    }
    return st;
}

/* ---- reading a chunk of planes and the pyramid ---- */

/* Whether level k samples level-0 plane z, and as which level plane (*plane). */
static int level_samples_plane(const ip_layout *l, uint32_t k, uint32_t z, uint32_t *plane)
{
    if (z == l->dims[2] - 1) {
        *plane = l->levels[k].dims[2] - 1;
        return 1;
    }
    *plane = z >> k;
    return (z & ((1u << k) - 1)) == 0;
}

/* Subsamples level-0 plane `src` into level plane `plane` of level k. */
static void subsample_plane(const bricker *b, uint32_t k, uint32_t plane, const unsigned char *src)
{
    const level_slab *slab = &b->slabs[k];
    const ip_level_layout *lv = &b->layout.levels[k];
    ip__plane_source from = {src, (ptrdiff_t)b->sample_size,
                             (ptrdiff_t)(b->layout.dims[0] * b->sample_size), b->sample_size};
    ip__subsample_plane(&from, slab->x_index, slab->y_index, lv->dims[0], lv->dims[1],
                        (unsigned char *)slab_plane(slab, plane));
}

/* Level-0 plane z is in its slot: places it in every coarser level that samples it. */
static void feed_levels(const bricker *b, uint32_t z)
{
    const unsigned char *src = slab_plane(&b->slabs[0], z);
    for (uint32_t k = 1; k < b->layout.level_count; k++) {
        uint32_t plane;
        if (level_samples_plane(&b->layout, k, z, &plane))
            subsample_plane(b, k, plane, src);
    }
}

/* One job of a reading run (on the pool): reads planes into their slots and feeds the
 * pyramid. Distinct planes land in distinct slots of every level, so the threads never share
 * a byte. */
static void read_worker(void *user, unsigned index)
{
    chunk_job *job = user;
    bricker *b = job->b;
    brick_scratch *scratch = &b->scratch[index];
    for (;;) {
        uint64_t i = atomic_fetch_add(&job->next, 1);
        if (i >= job->total || atomic_load(&job->failed))
            break;
        uint32_t z = job->z0 + (uint32_t)i;
        unsigned char *dst = (unsigned char *)slab_plane(&b->slabs[0], z);
        uint64_t direct = 0;
        ip_status st = ip__input_read_planes_at(job->reader, z, 1, dst, &direct, &scratch->error);
        atomic_fetch_add(&b->direct_bytes, direct);
        if (st != IP_OK) {
            worker_failed(job, scratch, st);
            break;
        }
        feed_levels(b, z);
    }
}

/* Level-0 planes up to z1 are in the slabs, and every coarser plane they give. */
static void planes_arrived(bricker *b, uint32_t z1)
{
    for (uint32_t k = 0; k < b->layout.level_count; k++)
        b->slabs[k].arrived =
            z1 == b->layout.dims[2] - 1 ? b->layout.levels[k].dims[2] : (z1 >> k) + 1;
}

/* One job of a feeding run (on the pool): places level-0 planes already read into the
 * coarser levels. */
static void feed_worker(void *user, unsigned index)
{
    chunk_job *job = user;
    (void)index;
    for (;;) {
        uint64_t i = atomic_fetch_add(&job->next, 1);
        if (i >= job->total)
            break;
        feed_levels(job->b, job->z0 + (uint32_t)i);
    }
}

/* Feeds level-0 planes [z0, z1], already in their slots (read by the reader thread, or in order
 * by read_chunk()), to the pyramid on every thread. */
static ip_status feed_chunk(bricker *b, uint32_t z0, uint32_t z1, ip_error *err)
{
    chunk_job job;
    memset(&job, 0, sizeof job);
    job.b = b;
    job.z0 = z0;
    job.total = z1 - z0 + 1;
    ip_status st = b->layout.level_count > 1 ? run_jobs(b, &job, feed_worker, err) : IP_OK;
    if (st == IP_OK)
        planes_arrived(b, z1);
    return st;
}

/* Reads level-0 planes [z0, z1] into their slots on this thread: one read per run of slots
 * that does not wrap around the ring. */
static ip_status read_level0(bricker *b, ip_input_reader *reader, uint32_t z0, uint32_t z1,
                             ip_error *err)
{
    const level_slab *slab = &b->slabs[0];
    ip_status st = IP_OK;
    for (uint32_t z = z0; st == IP_OK && z <= z1;) {
        uint32_t slot = z % slab->slots, run = z1 - z + 1;
        if (run > slab->slots - slot)
            run = slab->slots - slot;
        unsigned char *dst = slab->planes + (size_t)slot * slab->plane_bytes;
        if (ip__input_positioned(reader)) {
            uint64_t direct = 0;
            st = ip__input_read_planes_at(reader, z, run, dst, &direct, err);
            atomic_fetch_add(&b->direct_bytes, direct);
        } else {
            st = ip_input_read_planes(reader, dst, run, err);
        }
        z += run;
    }
    return st;
}

/* Reads level-0 planes [z0, z1] into the slabs and feeds the pyramid: on every thread, each
 * plane fed as it arrives, when the input can be read at any plane; else read in order on this
 * thread (gzip), then fed on every thread. */
static ip_status read_chunk(bricker *b, ip_input_reader *reader, uint32_t z0, uint32_t z1,
                            ip_error *err)
{
    if (!ip__input_positioned(reader)) {
        ip_status st = read_level0(b, reader, z0, z1, err);
        return st == IP_OK ? feed_chunk(b, z0, z1, err) : st;
    }
    chunk_job job;
    memset(&job, 0, sizeof job);
    job.b = b;
    job.reader = reader;
    job.z0 = z0;
    job.total = z1 - z0 + 1;
    ip_status st = run_jobs(b, &job, read_worker, err);
    if (st == IP_OK)
        planes_arrived(b, z1);
    return st;
}

/* ---- reading ahead on a thread of its own ---- */

/* The reader thread's work: level-0 planes [z0, z1] into their slots and nothing else, while
 * the pool encodes the layers of the chunk before. The coarser levels are fed after the thread
 * is joined, when no brick of theirs is being encoded. */
typedef struct read_ahead {
    bricker *b;
    ip_input_reader *reader;
    uint32_t z0, z1;
    ip_status status;
    ip_error error;
    pthread_t thread;
    int started;
} read_ahead;

static void *read_ahead_main(void *arg)
{
    read_ahead *ra = arg;
    ra->status = read_level0(ra->b, ra->reader, ra->z0, ra->z1, &ra->error);
    return NULL;
}

/* Starts reading planes [z0, z1]; where no thread can be started, reads them now. */
static void read_ahead_start(read_ahead *ra, uint32_t z0, uint32_t z1)
{
    ra->z0 = z0;
    ra->z1 = z1;
    ra->status = IP_OK;
    ra->started = ip__thread_start(&ra->thread, read_ahead_main, ra) == 0;
    if (!ra->started)
        read_ahead_main(ra);
}

/* Waits for the reads read_ahead_start() began; their error goes to `err` (may be NULL). */
static ip_status read_ahead_finish(read_ahead *ra, ip_error *err)
{
    if (ra->started)
        pthread_join(ra->thread, NULL);
    ra->started = 0;
    if (ra->status != IP_OK && err)
        *err = ra->error;
    return ra->status;
}

/* ---- setup and teardown ---- */

/* Slab memory in transparent huge pages where the system grants them on request: the first
 * touch of a slab then takes one page fault per 2 MiB instead of one per 4 KiB, which in a
 * virtual machine cost more than the copying. Rounded up to whole huge pages. */
static void *alloc_slab(uint64_t bytes)
{
    void *p = NULL;
    if (bytes > SIZE_MAX - SLAB_ALIGN || posix_memalign(&p, SLAB_ALIGN, slab_rounded(bytes)) != 0)
        return NULL;
#ifdef MADV_HUGEPAGE
    (void)madvise(p, slab_rounded(bytes), MADV_HUGEPAGE);
#endif
    return p;
}

static ip_status alloc_level(bricker *b, uint32_t k, ip_error *err)
{
    level_slab *slab = &b->slabs[k];
    const ip_level_layout *lv = &b->layout.levels[k];
    slab->plane_bytes = (size_t)lv->dims[0] * lv->dims[1] * b->sample_size;
    slab->slots = slab_slots(&b->layout, k, b->overlap);
    slab->planes = alloc_slab(slab_bytes(&b->layout, k, b->overlap));
    slab->layer_ranges = malloc(layer_ranges_bytes(&b->layout, k));
    if (k > 0) {
        slab->x_index = malloc(lv->dims[0] * sizeof *slab->x_index);
        slab->y_index = malloc(lv->dims[1] * sizeof *slab->y_index);
    }
    if (!slab->planes || !slab->layer_ranges || (k > 0 && (!slab->x_index || !slab->y_index)))
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory for level %u", b->out_path, k);
    for (uint32_t i = 0; k > 0 && i < lv->dims[0]; i++)
        slab->x_index[i] = ip_level_sample_index(b->layout.dims[0], k, i);
    for (uint32_t i = 0; k > 0 && i < lv->dims[1]; i++)
        slab->y_index[i] = ip_level_sample_index(b->layout.dims[1], k, i);
    return IP_OK;
}

static ip_status open_spill(bricker *b, ip_error *err)
{
    char folder[IP_PATH_MAX];
    snprintf(folder, sizeof folder, "%s", b->out_path);
    char *slash = strrchr(folder, '/');
    if (slash)
        *(slash == folder ? slash + 1 : slash) = '\0';
    else
        snprintf(folder, sizeof folder, ".");
    b->spill_fd = open(folder, O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
    if (b->spill_fd >= 0)
        return IP_OK;
    char name[IP_PATH_MAX + 32];
    snprintf(name, sizeof name, "%s/.isoprop-spill.XXXXXX", folder);
    b->spill_fd = mkstemp(name);
    if (b->spill_fd < 0)
        return ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot create a spill file in %s",
                              b->out_path, folder);
    unlink(name); /* unnamed from now on: it vanishes with the process */
    return IP_OK;
}

static ip_status alloc_scratch(bricker *b, ip_error *err)
{
    size_t bs = brick_samples_max(&b->layout);
    for (unsigned t = 0; t < b->threads; t++) {
        b->scratch[t].samples = malloc(bs * b->sample_size);
        b->scratch[t].out = malloc(ip__codec_bound(bs, b->layout.type));
        b->scratch[t].work = malloc(ip__codec_work_size(bs, b->layout.type));
        size_t rows = summary_rows_bytes(&b->layout);
        b->scratch[t].rows = rows ? malloc(rows) : NULL;
        if (!b->scratch[t].samples || !b->scratch[t].out || !b->scratch[t].work ||
            (rows && !b->scratch[t].rows))
            return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", b->out_path);
    }
    return IP_OK;
}

/* The input's rescale, as the layout keeps it. */
static ip_rescale rescale_of(const ip_input_desc *in)
{
    ip_rescale r;
    ip_rescale_identity(&r);
    if (in->has_rescale) {
        r.present = 1;
        r.slope = in->rescale_slope;
        r.intercept = in->rescale_intercept;
        memcpy(r.unit, in->rescale_unit, sizeof r.unit);
    }
    return r;
}

static ip_status bricker_init(bricker *b, const ip_input_desc *in, const char *out_path,
                              const ip_bricker_options *o, ip_error *err)
{
    memset(b, 0, sizeof *b);
    b->spill_fd = -1;
    b->options = o;
    b->out_path = out_path;
    ip_error why;
    ip_status st = ip__layout_init(&b->layout, in->dims, in->type, in->spacing, o->brick_edge,
                                   o->subblock_edge, &why);
    if (st != IP_OK)
        return ip__fail(err, st, "%s: %s", in->path, why.message);
    if (!ip__orientation_unset(&in->orientation))
        b->layout.orientation = in->orientation;
    ip_rescale rescale = rescale_of(in);
    ip__layout_set_rescale(&b->layout, &rescale);
    b->sample_size = ip_type_size(in->type);
    b->threads = thread_count(o);
    b->overlap = plan_overlap(&b->layout, b->threads, in->reader_bytes, o->memory_limit);
    atomic_init(&b->direct_bytes, 0);
    uint64_t need = in->reader_bytes + memory_for(&b->layout, b->threads, b->overlap);
    b->report.memory_planned = need;
    if (o->memory_limit && need > o->memory_limit)
        return ip__fail(err, IP_ERR_LIMIT,
                        "%s: bricking needs %llu MiB of working memory "
                        "(%u-cell bricks, %u threads) but the limit is %llu MiB",
                        in->path, (unsigned long long)((need + (1 << 20) - 1) >> 20), o->brick_edge,
                        b->threads, (unsigned long long)(o->memory_limit >> 20));
    b->subblocks = ip_layout_subblocks_per_brick(&b->layout);
    b->ranges_bytes = b->layout.brick_count * b->subblocks * 2 * sizeof(float);
    atomic_init(&b->spill_end, b->ranges_bytes);
    b->entries = calloc(b->layout.brick_count, sizeof *b->entries);
    b->brick_ranges = calloc(2 * b->layout.brick_count, sizeof(float));
    b->scratch = calloc(b->threads, sizeof *b->scratch);
    if (!b->entries || !b->brick_ranges || !b->scratch)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", out_path);
    if ((st = alloc_scratch(b, err)) != IP_OK)
        return st;
    for (uint32_t k = 0; k < b->layout.level_count; k++)
        if ((st = alloc_level(b, k, err)) != IP_OK)
            return st;
    if (ip__pool_create(b->threads, &b->pool, NULL) != IP_OK)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", out_path);
    return open_spill(b, err);
}

static void bricker_free(bricker *b)
{
    ip__pool_destroy(b->pool);
    for (uint32_t k = 0; k < IP_MAX_LEVELS; k++) {
        free(b->slabs[k].planes);
        free(b->slabs[k].layer_ranges);
        free(b->slabs[k].x_index);
        free(b->slabs[k].y_index);
    }
    for (unsigned t = 0; b->scratch && t < b->threads; t++) {
        free(b->scratch[t].samples);
        free(b->scratch[t].out);
        free(b->scratch[t].work);
        free(b->scratch[t].rows);
    }
    free(b->scratch);
    free(b->entries);
    free(b->brick_ranges);
    if (b->spill_fd >= 0)
        close(b->spill_fd);
}

/* ---- streaming pass ---- */

/* Tells the caller's progress callback that `done` of `total` input bytes are read and
 * encoded; IP_ERR_CANCELLED when it asks to stop. */
static ip_status report_progress(const bricker *b, uint64_t done, uint64_t total, ip_error *err)
{
    if (b->options->progress && b->options->progress(b->options->progress_user, done, total))
        return ip__fail(err, IP_ERR_CANCELLED, "%s: cancelled; no output written", b->out_path);
    return IP_OK;
}

/* The input is read in chunks that each complete one layer of level-0 bricks: planes up to
 * B * (layer + 1). While the pool encodes a chunk, the next one is read: by a thread of its own
 * into the level-0 slots the chunk does not use when the plan has room for them (overlap),
 * else by the kernel into its page cache (a read-ahead hint, no memory of the process; none
 * when reads are direct). seconds_read counts what the encoding did not hide: the first chunk,
 * the wait for the reader thread, and feeding the pyramid. */
static ip_status stream_input(bricker *b, const ip_input_desc *in, ip_error *err)
{
    ip_input_reader *reader = NULL;
    ip_status st = ip_input_open(in, &reader, err);
    if (st == IP_OK)
        (void)ip__input_direct_open(reader); /* raw data only; else the reads stay buffered */
    uint64_t plane_bytes = b->slabs[0].plane_bytes;
    uint64_t total = plane_bytes * in->dims[2];
    read_ahead ahead;
    memset(&ahead, 0, sizeof ahead);
    ahead.b = b;
    ahead.reader = reader;
    uint32_t z1 = layer_last_plane(&b->layout, 0, 0);
    double t0 = ip_now_seconds();
    if (st == IP_OK)
        st = read_chunk(b, reader, 0, z1, err);
    b->report.seconds_read += ip_now_seconds() - t0;
    while (st == IP_OK && z1 < in->dims[2] - 1) {
        /* planes up to z1 are in the slabs: encode them while the next chunk is read */
        uint32_t n0 = z1 + 1, n1 = layer_last_plane(&b->layout, 0, b->slabs[0].layer + 1);
        if (b->overlap)
            read_ahead_start(&ahead, n0, n1);
        else
            ip__input_prefetch(reader, n0, n1 - n0 + 1);
        double t1 = ip_now_seconds();
        st = encode_ready_layers(b, err);
        double t2 = ip_now_seconds();
        if (b->overlap) {
            ip_status read_st = read_ahead_finish(&ahead, st == IP_OK ? err : NULL);
            if (st == IP_OK)
                st = read_st;
            if (st == IP_OK)
                st = feed_chunk(b, n0, n1, err);
        } else if (st == IP_OK) {
            st = read_chunk(b, reader, n0, n1, err);
        }
        b->report.seconds_encode += t2 - t1;
        b->report.seconds_read += ip_now_seconds() - t2;
        if (st == IP_OK)
            st = report_progress(b, n0 * plane_bytes, total, err);
        z1 = n1;
    }
    double t3 = ip_now_seconds();
    if (st == IP_OK)
        st = encode_ready_layers(b, err);
    b->report.seconds_encode += ip_now_seconds() - t3;
    if (st == IP_OK)
        st = report_progress(b, total, total, err);
    b->report.bytes_direct = atomic_load(&b->direct_bytes);
    b->report.read_overlap = b->overlap;
    ip_input_close(reader);
    return st;
}

/* ---- finishing ---- */

static ip_status copy_range(bricker *b, int out_fd, uint64_t from, uint64_t to, uint32_t size,
                            ip_error *err)
{
    loff_t in_off = (loff_t)from, out_off = (loff_t)to;
    uint32_t left = size;
    while (left > 0) {
        ssize_t n = copy_file_range(b->spill_fd, &in_off, out_fd, &out_off, left, 0);
        if (n <= 0)
            break;
        left -= (uint32_t)n;
    }
    if (left == 0)
        return IP_OK;
    /* copy_file_range is not available across every pair of file systems: copy by hand */
    unsigned char *buf = malloc(left);
    if (!buf)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", b->out_path);
    ip_status st = ip__pread_all(b->spill_fd, buf, left, (uint64_t)in_off, b->out_path, err);
    if (st == IP_OK)
        st = ip__pwrite_all(out_fd, buf, left, (uint64_t)out_off, b->out_path, err);
    free(buf);
    return st;
}

/* Copies payloads from the spill file into the output in Morton order, fixing offsets. */
static ip_status write_payloads(bricker *b, int out_fd, ip_error *err)
{
    ip_layout *l = &b->layout;
    uint64_t cursor = l->data_offset;
    for (uint32_t k = 0; k < l->level_count; k++) {
        const ip_level_layout *lv = &l->levels[k];
        uint64_t *order = malloc(lv->brick_count * sizeof *order);
        if (!order || ip__morton_order(l, k, order) != IP_OK) {
            free(order);
            return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", b->out_path);
        }
        for (uint64_t i = 0; i < lv->brick_count; i++) {
            ip_brick_entry *e = &b->entries[lv->first_brick + order[i]];
            if (e->stored_size == 0)
                continue;
            ip_status st = copy_range(b, out_fd, e->offset, cursor, e->stored_size, err);
            if (st != IP_OK) {
                free(order);
                return st;
            }
            e->offset = cursor;
            cursor += e->stored_size;
        }
        free(order);
    }
    l->data_size = cursor - l->data_offset;
    l->summary_offset = (cursor + IP_SUMMARY_ALIGN - 1) / IP_SUMMARY_ALIGN * IP_SUMMARY_ALIGN;
    return IP_OK;
}

static void store_ranges(unsigned char *dst, const float *ranges, uint64_t count)
{
    for (uint64_t i = 0; i < 2 * count; i++) {
        uint32_t bits;
        memcpy(&bits, &ranges[i], 4);
        ip__store_u32le(dst + 4 * i, bits);
    }
}

/* The summary section is streamed to the file through one buffer, hashed on the way, so that
 * it never exists whole in memory (its sub-block ranges alone are 1/140 of a uint16 input). */
typedef struct summary_writer {
    bricker *b;
    int fd;
    uint64_t written; /* summary bytes flushed */
    unsigned char *buf;
    size_t used;
    XXH64_state_t *hash;
} summary_writer;

static ip_status summary_flush(summary_writer *w, ip_error *err)
{
    XXH64_update(w->hash, w->buf, w->used);
    ip_status st = ip__pwrite_all(w->fd, w->buf, w->used, w->b->layout.summary_offset + w->written,
                                  w->b->out_path, err);
    w->written += w->used;
    w->used = 0;
    return st;
}

/* Room for `bytes` (at most SUMMARY_CHUNK) at the end of the buffer, flushing it first when
 * it lacks them; NULL on a write error. */
static unsigned char *summary_room(summary_writer *w, size_t bytes, ip_error *err)
{
    if (w->used + bytes > SUMMARY_CHUNK && summary_flush(w, err) != IP_OK)
        return NULL;
    unsigned char *p = w->buf + w->used;
    w->used += bytes;
    return p;
}

/* Zeros up to section offset `at` (the sections are aligned). */
static ip_status summary_pad(summary_writer *w, uint64_t at, ip_error *err)
{
    while (w->written + w->used < at) {
        uint64_t gap = at - (w->written + w->used);
        size_t n = gap < SUMMARY_CHUNK ? (size_t)gap : SUMMARY_CHUNK;
        unsigned char *p = summary_room(w, n, err);
        if (!p)
            return IP_ERR_IO;
        memset(p, 0, n);
    }
    return IP_OK;
}

/* `count` ranges (2 floats each) from memory, in little-endian order. */
static ip_status summary_ranges(summary_writer *w, const float *ranges, uint64_t count,
                                ip_error *err)
{
    uint64_t step = SUMMARY_CHUNK / (2 * sizeof(float));
    for (uint64_t i = 0; i < count; i += step) {
        uint64_t n = count - i < step ? count - i : step;
        unsigned char *p = summary_room(w, (size_t)n * 2 * sizeof(float), err);
        if (!p)
            return IP_ERR_IO;
        store_ranges(p, ranges + 2 * i, n);
    }
    return IP_OK;
}

/* The sub-block ranges, read back from the spill file a buffer at a time. */
static ip_status summary_spilled_ranges(summary_writer *w, ip_error *err)
{
    uint64_t floats = w->b->ranges_bytes / sizeof(float);
    uint64_t step = SUMMARY_CHUNK / sizeof(float);
    ip_status st = IP_OK;
    for (uint64_t i = 0; st == IP_OK && i < floats; i += step) {
        uint64_t n = floats - i < step ? floats - i : step;
        unsigned char *p = summary_room(w, (size_t)n * sizeof(float), err);
        if (!p)
            return IP_ERR_IO;
        st = ip__pread_all(w->b->spill_fd, p, (size_t)n * sizeof(float), i * sizeof(float),
                           w->b->out_path, err);
        for (uint64_t j = 0; st == IP_OK && j < n; j++) {
            uint32_t bits;
            memcpy(&bits, p + 4 * j, 4);
            ip__store_u32le(p + 4 * j, bits);
        }
    }
    return st;
}

static ip_status summary_directory(summary_writer *w, ip_error *err)
{
    for (uint64_t g = 0; g < w->b->layout.brick_count; g++) {
        unsigned char *p = summary_room(w, IP_DIRECTORY_ENTRY_SIZE, err);
        if (!p)
            return IP_ERR_IO;
        ip__format_entry_encode(&w->b->entries[g], p);
    }
    return IP_OK;
}

/* Writes the sections in file order, then the header that records the summary's checksum. */
static ip_status summary_sections(summary_writer *w, const float *nodes, ip_error *err)
{
    ip_layout *l = &w->b->layout;
    ip_summary_offsets o;
    ip__summary_offsets_of(l, &o);
    if (o.level_table) { /* version 3: the rescale first */
        unsigned char *record = summary_room(w, IP_RESCALE_RECORD_SIZE, err);
        if (!record)
            return IP_ERR_IO;
        ip__format_rescale_encode(l, record);
    }
    unsigned char *table = summary_room(w, (size_t)l->level_count * IP_LEVEL_ENTRY_SIZE, err);
    if (!table)
        return IP_ERR_IO;
    ip__format_level_table_encode(l, table);
    ip_status st = summary_pad(w, o.directory, err);
    if (st == IP_OK)
        st = summary_directory(w, err);
    if (st == IP_OK)
        st = summary_pad(w, o.brick_ranges, err);
    if (st == IP_OK)
        st = summary_ranges(w, w->b->brick_ranges, l->brick_count, err);
    if (st == IP_OK)
        st = summary_pad(w, o.subblock_ranges, err);
    if (st == IP_OK)
        st = summary_spilled_ranges(w, err);
    if (st == IP_OK)
        st = summary_pad(w, o.nodes, err);
    if (st == IP_OK)
        st = summary_ranges(w, nodes, l->node_count, err);
    if (st == IP_OK)
        st = summary_pad(w, o.end, err);
    if (st == IP_OK)
        st = summary_flush(w, err);
    l->summary_size = o.end;
    return st;
}

static ip_status write_summary(bricker *b, int out_fd, ip_error *err)
{
    ip_layout *l = &b->layout;
    summary_writer w = {b, out_fd, 0, malloc(SUMMARY_CHUNK), 0, XXH64_createState()};
    float *nodes = calloc(2 * (l->node_count ? l->node_count : 1), sizeof(float));
    ip_status st = IP_OK;
    if (!w.buf || !w.hash || !nodes)
        st = ip__fail(err, IP_ERR_NOMEM, "%s: out of memory for the summary", b->out_path);
    if (st == IP_OK) {
        ip__level_value_ranges(l, b->brick_ranges);
        ip__octree_build(l, b->brick_ranges, nodes);
        XXH64_reset(w.hash, 0);
        st = summary_sections(&w, nodes, err);
    }
    if (st == IP_OK) {
        l->summary_checksum = XXH64_digest(w.hash);
        l->file_size = l->summary_offset + l->summary_size;
        unsigned char header[IP_HEADER_SIZE];
        ip__format_header_encode(l, header);
        st = ip__pwrite_all(out_fd, header, sizeof header, 0, b->out_path, err);
    }
    free(w.buf);
    free(nodes);
    XXH64_freeState(w.hash);
    return st;
}

static void count_bricks(bricker *b)
{
    for (uint64_t g = 0; g < b->layout.brick_count; g++) {
        switch (b->entries[g].encoding) {
        case IP_BRICK_CONSTANT: b->report.bricks_constant++; break;
        case IP_BRICK_RAW: b->report.bricks_raw++; break;
        default: b->report.bricks_compressed++; break;
        }
    }
    b->report.bricks = b->layout.brick_count;
    b->report.levels = b->layout.level_count;
    b->report.threads = b->threads;
    b->report.file_bytes = b->layout.file_size;
    b->report.input_bytes =
        (uint64_t)b->layout.dims[0] * b->layout.dims[1] * b->layout.dims[2] * b->sample_size;
}

/* What no option can make right: a spacing nothing downstream renders correctly, a rescale
 * the file cannot keep, and an output that is the input file (or its detached data file), which
 * --force would replace with the brick file, or which would be read while it is being
 * written. */
static ip_status check_request(const ip_input_desc *in, const char *out_path, ip_error *err)
{
    ip_status st = ip_spacing_check(in->spacing, in->path, err);
    if (st == IP_OK && !ip__orientation_unset(&in->orientation))
        st = ip_orientation_check(&in->orientation, in->path, err);
    ip_rescale rescale = rescale_of(in);
    if (st == IP_OK)
        st = ip_rescale_check(&rescale, in->path, err);
    if (in->encoding == IP_ENCODING_CALLBACK) /* no input file: its path is a name */
        return st;
    if (ip__input_is_stdin(in->data_path)) /* "-": the file standard input reads, if a file */
        return st == IP_OK ? ip_output_not_input(out_path, "/dev/stdin", err) : st;
    if (st == IP_OK)
        st = ip_output_not_input(out_path, in->path, err);
    if (st == IP_OK && strcmp(in->data_path, in->path) != 0)
        st = ip_output_not_input(out_path, in->data_path, err);
    return st;
}

ip_status ip_bricker_run(const ip_input_desc *input, const char *out_path,
                         const ip_bricker_options *given, ip_bricker_report *report, ip_error *err)
{
    double start = ip_now_seconds();
    if (!input || !out_path || !given)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "ip_bricker_run: input, out_path and options "
                        "are required");
    ip_bricker_options taken;
    const ip_bricker_options *options = &taken;
    ip_status st = take_options(given, &taken, err);
    if (st == IP_OK)
        st = check_request(input, out_path, err);
    if (st != IP_OK)
        return st;
    bricker b;
    ip_atomic_file out;
    out.fd = -1;
    out.named = 0;
    st = bricker_init(&b, input, out_path, options, err);
    if (st == IP_OK)
        st = ip__atomic_create(&out, out_path, options->force, err);
    if (st == IP_OK)
        st = stream_input(&b, input, err);
    double finish = ip_now_seconds();
    if (st == IP_OK)
        st = write_payloads(&b, out.fd, err);
    if (st == IP_OK)
        st = write_summary(&b, out.fd, err);
    b.report.seconds_write = ip_now_seconds() - finish;
    if (st == IP_OK)
        st = ip__atomic_commit(&out, err);
    else
        ip__atomic_abort(&out);
    if (st == IP_OK) {
        count_bricks(&b);
        b.report.seconds = ip_now_seconds() - start;
        b.report.peak_rss = ip_peak_rss_bytes();
        if (report)
            *report = b.report;
    }
    bricker_free(&b);
    return st;
}

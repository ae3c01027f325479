/* Streaming bricking: input planes -> pyramid slabs -> compressed bricks -> brick file. */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "atomic_file.h"
#include "internal.h"
#include "isoprop/bricker.h"
#include "codec.h"
#include "format.h"
#include "isoprop/output.h"
#include "pool.h"
#include "summary.h"

/* One pyramid level's slab: up to B+1 consecutive planes of the level. */
typedef struct level_slab {
    unsigned char *planes;
    size_t plane_bytes;
    uint32_t filled;     /* planes currently held */
    uint32_t next_plane; /* index of the next level plane to arrive */
    uint32_t layer;      /* next brick layer (bz) to emit */
    uint32_t *x_index;   /* level-0 x of each level x (levels >= 1) */
    uint32_t *y_index;
} level_slab;

typedef struct bricker bricker;

/* Per-thread scratch for gathering and encoding one brick. */
typedef struct brick_scratch {
    unsigned char *samples, *out, *work;
} brick_scratch;

/* One layer of bricks being compressed by the worker threads. */
typedef struct layer_job {
    bricker *b;
    uint32_t level, bz;
    const level_slab *slab;
    uint64_t brick_total;      /* bricks in the layer */
    atomic_uint_fast64_t next; /* next brick to take */
    unsigned char **payloads;  /* per brick, malloc'ed copies; NULL for constant bricks */
    atomic_int failed;
} layer_job;

struct bricker {
    ip_layout layout;
    const ip_bricker_options *options;
    const char *out_path;
    size_t sample_size;
    unsigned threads;
    ip__pool *pool; /* compresses every layer; started at init */
    level_slab slabs[IP_MAX_LEVELS];
    brick_scratch *scratch;  /* one per job of a layer (per thread) */
    ip_brick_entry *entries; /* offsets point into the spill file until the end */
    float *brick_ranges;     /* 2 per brick */
    float *subblock_ranges;  /* 2 per sub-block */
    uint32_t subblocks;      /* per brick */
    int spill_fd;
    uint64_t spill_size;
    ip_bricker_report report;
};

/* ---- memory ---- */

static size_t brick_samples_max(const ip_layout *l)
{
    size_t e = (size_t)l->brick_edge + 1;
    return e * e * e;
}

static uint64_t slab_bytes(const ip_layout *l, uint32_t k)
{
    const ip_level_layout *lv = &l->levels[k];
    return (uint64_t)(l->brick_edge + 1) * lv->dims[0] * lv->dims[1] * ip_type_size(l->type);
}

static unsigned thread_count(const ip_bricker_options *o)
{
    return ip_thread_count(o->threads);
}

static uint64_t memory_for(const ip_layout *l, unsigned threads)
{
    uint64_t total = 0, widest = 0;
    size_t bs = brick_samples_max(l);
    for (uint32_t k = 0; k < l->level_count; k++) {
        total += slab_bytes(l, k);
        if (slab_bytes(l, k) > widest)
            widest = slab_bytes(l, k);
    }
    total += widest + widest / 128; /* one layer's payloads, incompressible worst case */
    total += (uint64_t)threads * (bs * ip_type_size(l->type) + ip__codec_bound(bs, l->type) +
                                  ip__codec_work_size(bs, l->type));
    total += 2 * ip__layout_summary_size(l); /* the arrays, then their encoded copy */
    return total;
}

void ip_bricker_options_default(ip_bricker_options *options)
{
    memset(options, 0, sizeof *options);
    options->brick_edge = IP_DEFAULT_BRICK_EDGE;
    options->subblock_edge = IP_DEFAULT_SUBBLOCK_EDGE;
    options->lz4_level = IP_LZ4_FAST;
}

ip_status ip_bricker_memory_needed(const ip_input_desc *input, const ip_bricker_options *options,
                                   uint64_t *bytes, ip_error *err)
{
    ip_layout l;
    ip_status st = ip__layout_init(&l, input->dims, input->type, input->spacing,
                                   options->brick_edge, options->subblock_edge, err);
    if (st == IP_OK)
        *bytes = memory_for(&l, thread_count(options));
    return st;
}

/* ---- one brick ---- */

static void gather_brick(const level_slab *slab, const ip_layout *l, uint32_t level,
                         const uint32_t origin[3], const uint32_t extent[3], unsigned char *dst)
{
    size_t ss = ip_type_size(l->type);
    size_t row_bytes = (size_t)extent[0] * ss;
    size_t level_row = (size_t)l->levels[level].dims[0] * ss;
    for (uint32_t z = 0; z < extent[2]; z++)
        for (uint32_t y = 0; y < extent[1]; y++) {
            const unsigned char *src = slab->planes + (size_t)z * slab->plane_bytes +
                                       (size_t)(origin[1] + y) * level_row + origin[0] * ss;
            memcpy(dst, src, row_bytes);
            dst += row_bytes;
        }
}

static int process_brick(layer_job *job, uint64_t i, brick_scratch *s)
{
    bricker *b = job->b;
    const ip_layout *l = &b->layout;
    uint32_t brick[3] = {(uint32_t)(i % l->levels[job->level].bricks[0]),
                         (uint32_t)(i / l->levels[job->level].bricks[0]), job->bz};
    uint32_t origin[3], extent[3];
    ip_brick_extent(l, job->level, brick, origin, extent);
    uint64_t g = ip_brick_global_index(l, job->level, brick);
    gather_brick(job->slab, l, job->level, origin, extent, s->samples);
    ip__summarise_brick(s->samples, l->type, extent, l->brick_edge, l->subblock_edge,
                        &b->brick_ranges[2 * g], &b->subblock_ranges[2 * g * b->subblocks]);
    ip_brick_entry *e = &b->entries[g];
    if (ip__codec_encode(s->samples, extent, l->type, b->options->lz4_level, s->out, s->work, e) !=
        IP_OK)
        return -1;
    job->payloads[i] = NULL;
    if (e->stored_size > 0) {
        job->payloads[i] = malloc(e->stored_size);
        if (!job->payloads[i])
            return -1;
        memcpy(job->payloads[i], s->out, e->stored_size);
    }
    return 0;
}

/* One job of a layer (on the pool): takes bricks from the shared counter until none is left,
 * with scratch buffers of its own. */
static void layer_worker(void *user, unsigned index)
{
    layer_job *job = user;
    brick_scratch *scratch = &job->b->scratch[index];
    for (;;) {
        uint64_t i = atomic_fetch_add(&job->next, 1);
        if (i >= job->brick_total || atomic_load(&job->failed))
            break;
        if (process_brick(job, i, scratch) != 0)
            atomic_store(&job->failed, 1);
    }
}

/* ---- one layer ---- */

static ip_status append_spill(bricker *b, const unsigned char *data, uint32_t size, ip_error *err)
{
    ip_status st = ip__pwrite_all(b->spill_fd, data, size, b->spill_size, b->out_path, err);
    b->spill_size += size;
    return st;
}

static ip_status emit_layer(bricker *b, uint32_t level, ip_error *err)
{
    const ip_layout *l = &b->layout;
    level_slab *slab = &b->slabs[level];
    layer_job job;
    memset(&job, 0, sizeof job);
    job.b = b;
    job.level = level;
    job.bz = slab->layer;
    job.slab = slab;
    job.brick_total = (uint64_t)l->levels[level].bricks[0] * l->levels[level].bricks[1];
    atomic_init(&job.next, 0);
    atomic_init(&job.failed, 0);
    job.payloads = calloc(job.brick_total, sizeof *job.payloads);
    if (!job.payloads)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", b->out_path);
    unsigned jobs = b->threads;
    if (jobs > job.brick_total)
        jobs = (unsigned)(job.brick_total > 0 ? job.brick_total : 1);
    ip__pool_run(b->pool, jobs, layer_worker, &job);
    ip_status st =
        atomic_load(&job.failed)
            ? ip__fail(err, IP_ERR_NOMEM, "%s: out of memory while compressing", b->out_path)
            : IP_OK;
    for (uint64_t i = 0; i < job.brick_total; i++) {
        uint32_t brick[3] = {(uint32_t)(i % l->levels[level].bricks[0]),
                             (uint32_t)(i / l->levels[level].bricks[0]), job.bz};
        ip_brick_entry *e = &b->entries[ip_brick_global_index(l, level, brick)];
        if (st == IP_OK && job.payloads[i]) {
            e->offset = b->spill_size;
            st = append_spill(b, job.payloads[i], e->stored_size, err);
        }
        free(job.payloads[i]);
    }
    free(job.payloads);
    slab->layer++;
    return st;
}

/* A level plane has been placed at slot `filled`; emit a layer when the slab is complete. */
static ip_status plane_arrived(bricker *b, uint32_t level, ip_error *err)
{
    level_slab *slab = &b->slabs[level];
    uint32_t last_plane = b->layout.levels[level].dims[2] - 1;
    uint32_t plane = slab->next_plane++;
    slab->filled++;
    if (slab->filled < b->layout.brick_edge + 1 && plane < last_plane)
        return IP_OK;
    ip_status st = emit_layer(b, level, err);
    if (st == IP_OK && plane < last_plane) {
        /* the + face of this layer is the - face of the next */
        memmove(slab->planes, slab->planes + (size_t)(slab->filled - 1) * slab->plane_bytes,
                slab->plane_bytes);
        slab->filled = 1;
    }
    return st;
}

static void subsample_plane(const bricker *b, uint32_t level, const unsigned char *src)
{
    const level_slab *slab = &b->slabs[level];
    size_t ss = b->sample_size;
    size_t row0 = (size_t)b->layout.dims[0] * ss;
    unsigned char *dst = slab->planes + (size_t)slab->filled * slab->plane_bytes;
    const ip_level_layout *lv = &b->layout.levels[level];
    for (uint32_t y = 0; y < lv->dims[1]; y++) {
        const unsigned char *row = src + (size_t)slab->y_index[y] * row0;
        for (uint32_t x = 0; x < lv->dims[0]; x++, dst += ss)
            memcpy(dst, row + (size_t)slab->x_index[x] * ss, ss);
    }
}

/* Level-0 plane z has just been read into its slab; feed it to every level that samples it. */
static ip_status feed_plane(bricker *b, uint32_t z, ip_error *err)
{
    const unsigned char *plane =
        b->slabs[0].planes + (size_t)b->slabs[0].filled * b->slabs[0].plane_bytes;
    for (uint32_t k = 1; k < b->layout.level_count; k++) {
        level_slab *slab = &b->slabs[k];
        if (ip_level_sample_index(b->layout.dims[2], k, slab->next_plane) != z)
            continue;
        subsample_plane(b, k, plane);
        ip_status st = plane_arrived(b, k, err);
        if (st != IP_OK)
            return st;
    }
    return plane_arrived(b, 0, err);
}

/* ---- setup and teardown ---- */

static ip_status alloc_level(bricker *b, uint32_t k, ip_error *err)
{
    level_slab *slab = &b->slabs[k];
    const ip_level_layout *lv = &b->layout.levels[k];
    slab->plane_bytes = (size_t)lv->dims[0] * lv->dims[1] * b->sample_size;
    slab->planes = malloc(slab_bytes(&b->layout, k));
    if (k > 0) {
        slab->x_index = malloc(lv->dims[0] * sizeof *slab->x_index);
        slab->y_index = malloc(lv->dims[1] * sizeof *slab->y_index);
    }
    if (!slab->planes || (k > 0 && (!slab->x_index || !slab->y_index)))
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
    b->sample_size = ip_type_size(in->type);
    b->threads = thread_count(o);
    uint64_t need = memory_for(&b->layout, b->threads);
    b->report.memory_planned = need;
    if (o->memory_limit && need > o->memory_limit)
        return ip__fail(err, IP_ERR_LIMIT,
                        "%s: bricking needs %llu MiB of working memory "
                        "(%u-cell bricks, %u threads) but the limit is %llu MiB",
                        in->path, (unsigned long long)((need + (1 << 20) - 1) >> 20), o->brick_edge,
                        b->threads, (unsigned long long)(o->memory_limit >> 20));
    b->subblocks = ip_layout_subblocks_per_brick(&b->layout);
    b->entries = calloc(b->layout.brick_count, sizeof *b->entries);
    b->brick_ranges = calloc(2 * b->layout.brick_count, sizeof(float));
    b->subblock_ranges = calloc(2 * b->layout.brick_count * b->subblocks, sizeof(float));
    b->scratch = calloc(b->threads, sizeof *b->scratch);
    if (!b->entries || !b->brick_ranges || !b->subblock_ranges || !b->scratch)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", out_path);
    size_t bs = brick_samples_max(&b->layout);
    for (unsigned t = 0; t < b->threads; t++) {
        b->scratch[t].samples = malloc(bs * b->sample_size);
        b->scratch[t].out = malloc(ip__codec_bound(bs, in->type));
        b->scratch[t].work = malloc(ip__codec_work_size(bs, in->type));
        if (!b->scratch[t].samples || !b->scratch[t].out || !b->scratch[t].work)
            return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", out_path);
    }
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
        free(b->slabs[k].x_index);
        free(b->slabs[k].y_index);
    }
    for (unsigned t = 0; b->scratch && t < b->threads; t++) {
        free(b->scratch[t].samples);
        free(b->scratch[t].out);
        free(b->scratch[t].work);
    }
    free(b->scratch);
    free(b->entries);
    free(b->brick_ranges);
    free(b->subblock_ranges);
    if (b->spill_fd >= 0)
        close(b->spill_fd);
}

/* ---- streaming pass ---- */

static ip_status stream_input(bricker *b, const ip_input_desc *in, ip_error *err)
{
    ip_input_reader *reader = NULL;
    ip_status st = ip_input_open(in, &reader, err);
    uint64_t plane_bytes = b->slabs[0].plane_bytes;
    uint64_t total = plane_bytes * in->dims[2];
    for (uint32_t z = 0; st == IP_OK && z < in->dims[2]; z++) {
        level_slab *slab = &b->slabs[0];
        st =
            ip_input_read_planes(reader, slab->planes + (size_t)slab->filled * plane_bytes, 1, err);
        if (st == IP_OK)
            st = feed_plane(b, z, err);
        if (st == IP_OK && b->options->progress &&
            b->options->progress(b->options->progress_user, (z + 1) * plane_bytes, total))
            st = ip__fail(err, IP_ERR_CANCELLED, "%s: cancelled; no output written", b->out_path);
    }
    ip_input_close(reader);
    return st;
}

/* ---- finishing ---- */

/* ip__octree_walk() visitor: stores each node's range, read back for the next depth. */
static int store_node(void *nodes, uint32_t level, uint32_t depth, const uint32_t node[3],
                      uint64_t node_index, const float range[2])
{
    (void)level, (void)depth, (void)node;
    memcpy((float *)nodes + 2 * node_index, range, 2 * sizeof(float));
    return 0;
}

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

static void level_ranges(bricker *b)
{
    ip_layout *l = &b->layout;
    for (uint32_t k = 0; k < l->level_count; k++) {
        ip_level_layout *lv = &l->levels[k];
        lv->value_min = INFINITY;
        lv->value_max = -INFINITY;
        for (uint64_t i = 0; i < lv->brick_count; i++) {
            lv->value_min = fminf(lv->value_min, b->brick_ranges[2 * (lv->first_brick + i)]);
            lv->value_max = fmaxf(lv->value_max, b->brick_ranges[2 * (lv->first_brick + i) + 1]);
        }
    }
    l->value_min = l->levels[0].value_min;
    l->value_max = l->levels[0].value_max;
}

static ip_status write_summary(bricker *b, int out_fd, ip_error *err)
{
    ip_layout *l = &b->layout;
    ip_summary_offsets o;
    ip__summary_offsets_of(l, &o);
    unsigned char *s = calloc(1, o.end);
    float *nodes = calloc(2 * (l->node_count ? l->node_count : 1), sizeof(float));
    if (!s || !nodes) {
        free(s);
        free(nodes);
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory for the summary", b->out_path);
    }
    level_ranges(b);
    ip__octree_walk(l, b->brick_ranges, nodes, store_node, nodes);
    ip__format_level_table_encode(l, s + o.level_table);
    for (uint64_t g = 0; g < l->brick_count; g++)
        ip__format_entry_encode(&b->entries[g], s + o.directory + g * IP_DIRECTORY_ENTRY_SIZE);
    store_ranges(s + o.brick_ranges, b->brick_ranges, l->brick_count);
    store_ranges(s + o.subblock_ranges, b->subblock_ranges, l->brick_count * b->subblocks);
    store_ranges(s + o.nodes, nodes, l->node_count);
    l->summary_size = o.end;
    l->summary_checksum = ip__format_checksum(s, o.end);
    l->file_size = l->summary_offset + l->summary_size;
    ip_status st = ip__pwrite_all(out_fd, s, o.end, l->summary_offset, b->out_path, err);
    free(s);
    free(nodes);
    if (st == IP_OK) {
        unsigned char header[IP_HEADER_SIZE];
        ip__format_header_encode(l, header);
        st = ip__pwrite_all(out_fd, header, sizeof header, 0, b->out_path, err);
    }
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

/* What no option can make right: a spacing nothing downstream renders correctly, and an
 * output that is the input (or its detached data file), which --force would replace with the
 * brick file, or which would be read while it is being written. */
static ip_status check_request(const ip_input_desc *in, const char *out_path, ip_error *err)
{
    ip_status st = ip_spacing_check(in->spacing, in->path, err);
    if (st == IP_OK)
        st = ip_output_not_input(out_path, in->path, err);
    if (st == IP_OK && strcmp(in->data_path, in->path) != 0)
        st = ip_output_not_input(out_path, in->data_path, err);
    return st;
}

ip_status ip_bricker_run(const ip_input_desc *input, const char *out_path,
                         const ip_bricker_options *options, ip_bricker_report *report,
                         ip_error *err)
{
    double start = ip_now_seconds();
    if (!input || !out_path || !options)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "ip_bricker_run: input, out_path and options "
                        "are required");
    ip_status st = check_request(input, out_path, err);
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
    if (st == IP_OK)
        st = write_payloads(&b, out.fd, err);
    if (st == IP_OK)
        st = write_summary(&b, out.fd, err);
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

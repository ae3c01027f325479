/* SPDX-License-Identifier: BSD-3-Clause */
/* A brick file opened for reading: its summaries held in memory, bricks read on demand. */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/uio.h>
#include <unistd.h>
#include <xxhash.h>

#include "array.h"
#include "internal.h"
#include "codec.h"
#include "isoprop/store.h"
#include "memory_volume.h"
#include "pyramid.h"
#include "sized.h"
#include "summary.h"

struct ip_store {
    char path[IP_PATH_MAX];
    int fd;
    uint64_t size; /* the file's size when opened */
    ip_layout layout;
    ip_summary_offsets offsets;
    unsigned char *summary; /* the summary section up to its sub-block ranges (level table,
                               directory, brick ranges), read and verified once at open; owned */
    float *ranges;          /* the brick ranges, host floats; owned */
    float *nodes;           /* the octree's node ranges, host floats; owned */
    /* Sub-block ranges, 2 * subblocks floats per block: the blocks of the bricks that are not
     * uniform, and one block per value shared by the uniform bricks of that value (those whose
     * every sub-block range is (v, v): constant bricks). block_of[g] is brick g's block. */
    float *blocks;
    uint64_t block_count, block_capacity;
    uint32_t *block_of;
    uint64_t memory; /* bytes of the above */
    uint32_t subblocks;
    size_t largest_payload;    /* bytes of the largest stored payload */
    size_t largest_samples;    /* samples of the largest brick */
    ip__memory_volume *volume; /* a store on samples in memory (ip_store_open_memory()): its
                                  bricks are gathered from them; NULL for a brick file */
};

/* Opens without blocking (a FIFO would wait for a writer) and accepts only a regular file. */
static ip_status open_file(ip_store *s, ip_error *err)
{
    struct stat st;
    s->fd = open(s->path, O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (s->fd < 0)
        return ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot open", s->path);
    if (fstat(s->fd, &st) != 0)
        return ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot stat", s->path);
    if (!S_ISREG(st.st_mode))
        return ip__fail(err, IP_ERR_IO, "%s: not a regular file", s->path);
    (void)fcntl(s->fd, F_SETFL, fcntl(s->fd, F_GETFL) & ~O_NONBLOCK);
    s->size = (uint64_t)st.st_size;
    return IP_OK;
}

/* The file's size now, for messages about a file that changed while open (0 when unknown). */
static uint64_t size_now(const ip_store *s)
{
    struct stat st;
    return fstat(s->fd, &st) == 0 ? (uint64_t)st.st_size : 0;
}

/* Reads `size` bytes at `offset`: 0, an errno value, or -1 when the file ends first. */
static int read_fully(const ip_store *s, void *dst, size_t size, uint64_t offset)
{
    unsigned char *p = dst;
    while (size > 0) {
        ssize_t n = pread(s->fd, p, size, (off_t)offset);
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0)
            return errno;
        if (n == 0)
            return -1;
        p += n;
        size -= (size_t)n;
        offset += (uint64_t)n;
    }
    return 0;
}

/* The message of a failed read_fully() of `what`; a short read means the file shrank since
 * it was opened. */
static ip_status read_failed(const ip_store *s, int failure, const char *what, ip_error *err)
{
    if (failure > 0)
        return ip__fail_errno(err, IP_ERR_IO, failure, "%s: cannot read %s", s->path, what);
    return ip__fail(err, IP_ERR_IO,
                    "%s: the file ends at byte %llu, before the end of "
                    "%s (it was %llu bytes when opened: truncated or rewritten since)",
                    s->path, (unsigned long long)size_now(s), what, (unsigned long long)s->size);
}

/* Reads `size` bytes at `offset`, or fails with a message about `what`. */
static ip_status read_at(const ip_store *s, void *dst, size_t size, uint64_t offset,
                         const char *what, ip_error *err)
{
    int failure = read_fully(s, dst, size, offset);
    return failure == 0 ? IP_OK : read_failed(s, failure, what, err);
}

/* Host floats from `count` little-endian ones. */
static void load_floats(const unsigned char *src, float *dst, uint64_t count)
{
    for (uint64_t i = 0; i < count; i++)
        dst[i] = ip__load_f32le(src + 4 * i);
}

/* Reads `size` bytes of the summary section from `offset` (relative to it) into dst and adds
 * them to the checksum. */
static ip_status read_summary_part(ip_store *s, void *dst, uint64_t size, uint64_t offset,
                                   XXH64_state_t *hash, ip_error *err)
{
    ip_status st = read_at(s, dst, (size_t)size, s->layout.summary_offset + offset,
                           "the summary section", err);
    if (st == IP_OK)
        XXH64_update(hash, dst, (size_t)size);
    return st;
}

/* A new block of sub-block ranges (2 * subblocks floats, to be filled) and its index in
 * *index; NULL when out of memory. */
static float *new_block(ip_store *s, uint32_t *index)
{
    size_t floats = 2 * (size_t)s->subblocks;
    if (s->block_count >= UINT32_MAX - 1 ||
        ip__array_reserve(&s->blocks, &s->block_capacity, (s->block_count + 1) * floats,
                          sizeof(float), 64 * floats) != IP_OK)
        return NULL;
    *index = (uint32_t)s->block_count;
    return s->blocks + s->block_count++ * floats;
}

/* The shared blocks of uniform bricks by value: an open-addressing table of `slots` (a power
 * of two; block UINT32_MAX marks an empty slot). */
typedef struct uniform_table {
    uint32_t *keys, *block, slots, used;
} uniform_table;

/* Rehashes the table into twice the slots (64 at first). Returns 0 when out of memory. */
static int grow_table(uniform_table *t)
{
    uint32_t slots = t->slots ? 2 * t->slots : 64;
    uint32_t *keys = malloc(slots * sizeof *keys), *block = malloc(slots * sizeof *block);
    if (!keys || !block) {
        free(keys);
        free(block);
        return 0;
    }
    memset(block, 0xff, slots * sizeof *block);
    for (uint32_t i = 0; i < t->slots; i++)
        if (t->block[i] != UINT32_MAX) {
            uint32_t j = (t->keys[i] * 2654435761u) & (slots - 1);
            while (block[j] != UINT32_MAX)
                j = (j + 1) & (slots - 1);
            keys[j] = t->keys[i];
            block[j] = t->block[i];
        }
    free(t->keys);
    free(t->block);
    t->keys = keys;
    t->block = block;
    t->slots = slots;
    return 1;
}

/* The block shared by the uniform bricks of value `bits` (a float's bits), added when new.
 * Returns UINT32_MAX when out of memory. */
static uint32_t uniform_block(ip_store *s, uniform_table *t, uint32_t bits)
{
    if (2 * (t->used + 1) > t->slots && !grow_table(t))
        return UINT32_MAX;
    uint32_t j = (bits * 2654435761u) & (t->slots - 1);
    while (t->block[j] != UINT32_MAX && t->keys[j] != bits)
        j = (j + 1) & (t->slots - 1);
    if (t->block[j] == UINT32_MAX) {
        uint32_t b;
        float v, *uniform = new_block(s, &b);
        if (!uniform)
            return UINT32_MAX;
        memcpy(&v, &bits, 4);
        for (uint32_t i = 0; i < 2 * s->subblocks; i++)
            uniform[i] = v;
        t->keys[j] = bits;
        t->block[j] = b;
        t->used++;
    }
    return t->block[j];
}

/* A brick's block for its sub-block ranges `r` (host floats): the shared one when every
 * range is (v, v) for one v (bit for bit), else a block of its own. */
static uint32_t block_for(ip_store *s, uniform_table *t, const float *r)
{
    uint32_t bits, other;
    memcpy(&bits, &r[0], 4);
    int uniform = 1;
    for (uint32_t i = 1; uniform && i < 2 * s->subblocks; i++) {
        memcpy(&other, &r[i], 4);
        uniform = other == bits;
    }
    if (uniform)
        return uniform_block(s, t, bits);
    uint32_t b;
    float *own = new_block(s, &b);
    if (!own)
        return UINT32_MAX;
    memcpy(own, r, 2 * (size_t)s->subblocks * sizeof(float));
    return b;
}

/* The sub-block ranges, read in pieces of whole bricks and compacted (see struct ip_store). */
static ip_status read_subblock_ranges(ip_store *s, XXH64_state_t *hash, ip_error *err)
{
    enum {
        PIECE_BYTES = 1 << 20
    };
    uint64_t brick_bytes = (uint64_t)s->subblocks * IP_RANGE_SIZE;
    uint64_t per_piece = PIECE_BYTES / brick_bytes ? PIECE_BYTES / brick_bytes : 1;
    uint64_t bricks = s->layout.brick_count;
    unsigned char *piece = malloc((size_t)(per_piece * brick_bytes));
    float *host = malloc(2 * (size_t)s->subblocks * sizeof(float));
    uniform_table t = {NULL, NULL, 0, 0};
    s->block_of = malloc((bricks ? bricks : 1) * sizeof *s->block_of);
    ip_status st = piece && host && s->block_of ? IP_OK : IP_ERR_NOMEM;
    for (uint64_t g = 0; st == IP_OK && g < bricks; g += per_piece) {
        uint64_t n = bricks - g < per_piece ? bricks - g : per_piece;
        st = read_summary_part(s, piece, n * brick_bytes,
                               s->offsets.subblock_ranges + g * brick_bytes, hash, err);
        for (uint64_t i = 0; st == IP_OK && i < n; i++) {
            load_floats(piece + i * brick_bytes, host, 2 * (uint64_t)s->subblocks);
            s->block_of[g + i] = block_for(s, &t, host);
            if (s->block_of[g + i] == UINT32_MAX)
                st = IP_ERR_NOMEM;
        }
    }
    free(piece);
    free(host);
    free(t.keys);
    free(t.block);
    if (st == IP_ERR_NOMEM)
        return ip__fail(err, st, "%s: out of memory for the summaries", s->path);
    return st;
}

/* The header, then the padding and the summary section, read once and validated. The summary
 * is read in parts (level table, directory and brick ranges; the sub-block ranges in pieces;
 * the node ranges) with its checksum computed along, so that its largest array, the sub-block
 * ranges, is never held whole. */
static ip_status read_metadata(ip_store *s, ip_error *err)
{
    unsigned char header[IP_HEADER_SIZE], gap[IP_SUMMARY_ALIGN];
    if (s->size < IP_HEADER_SIZE)
        return ip__fail(err, IP_ERR_FORMAT, "%s: %llu bytes is too short for a brick file", s->path,
                        (unsigned long long)s->size);
    ip_status st = read_at(s, header, sizeof header, 0, "the header", err);
    if (st == IP_OK)
        st = ip__format_parse_header(header, s->size, s->path, 0, &s->layout, err);
    if (st != IP_OK)
        return st;
    const ip_layout *l = &s->layout;
    ip__summary_offsets_of(l, &s->offsets);
    s->subblocks = ip_layout_subblocks_per_brick(l);
    const ip_summary_offsets *o = &s->offsets;
    uint64_t data_end = l->data_offset + l->data_size, node_bytes = l->summary_size - o->nodes;
    uint64_t node_floats = node_bytes / 4;
    s->summary = malloc(o->subblock_ranges ? o->subblock_ranges : 1);
    s->ranges = malloc((2 * l->brick_count + 1) * sizeof(float));
    s->nodes = malloc((node_floats + 1) * sizeof(float));
    unsigned char *stored_nodes = malloc(node_bytes ? node_bytes : 1);
    XXH64_state_t *hash = XXH64_createState();
    if (!s->summary || !s->ranges || !s->nodes || !stored_nodes || !hash) {
        free(stored_nodes);
        XXH64_freeState(hash);
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory for the summaries", s->path);
    }
    XXH64_reset(hash, 0);
    st = read_at(s, gap, l->summary_offset - data_end, data_end, "the data section", err);
    if (st == IP_OK)
        st = read_summary_part(s, s->summary, o->subblock_ranges, 0, hash, err);
    if (st == IP_OK)
        st = read_subblock_ranges(s, hash, err);
    if (st == IP_OK)
        st = read_summary_part(s, stored_nodes, node_bytes, o->nodes, hash, err);
    if (st == IP_OK)
        st = ip__format_check_summary(&s->layout, gap, s->summary, XXH64_digest(hash), s->path, 0,
                                      err);
    if (st == IP_OK) {
        load_floats(s->summary + o->brick_ranges, s->ranges, 2 * l->brick_count);
        load_floats(stored_nodes, s->nodes, node_floats);
        s->memory = o->subblock_ranges + (2 * l->brick_count + node_floats) * sizeof(float) +
                    s->block_count * 2 * s->subblocks * sizeof(float) +
                    l->brick_count * sizeof *s->block_of;
    }
    free(stored_nodes);
    XXH64_freeState(hash);
    return st;
}

/* The largest payload and brick, which size the scratch of ip_store_read_brick(). */
static void find_largest(ip_store *s)
{
    for (uint64_t g = 0; g < s->layout.brick_count; g++) {
        ip_brick_entry e;
        ip_store_brick_entry(s, g, &e);
        if (e.stored_size > s->largest_payload)
            s->largest_payload = e.stored_size;
    }
    size_t edge = (size_t)s->layout.brick_edge + 1;
    s->largest_samples = edge * edge * edge;
}

ip_status ip_store_open(const char *path, ip_store **out, ip_error *err)
{
    ip_store *s = calloc(1, sizeof *s);
    if (!s)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", path);
    s->fd = -1;
    snprintf(s->path, sizeof s->path, "%s", path);
    ip_status st = open_file(s, err);
    if (st == IP_OK)
        st = read_metadata(s, err);
    if (st != IP_OK) {
        ip_store_close(s);
        return st;
    }
    find_largest(s);
    /* From here on the file is read brick by brick, in the order the view needs them: the
     * kernel's sequential readahead would read megabytes past each small payload. The reads
     * the engine plans are asked for explicitly (ip_store_prefetch_brick()). */
    (void)posix_fadvise(s->fd, 0, 0, POSIX_FADV_RANDOM);
    *out = s;
    return IP_OK;
}

void ip_store_close(ip_store *s)
{
    if (!s)
        return;
    if (s->fd >= 0)
        close(s->fd);
    free(s->summary);
    free(s->ranges);
    free(s->nodes);
    free(s->blocks);
    free(s->block_of);
    if (s->volume)
        ip__memory_volume_free(s->volume);
    free(s->volume);
    free(s);
}

const ip_layout *ip_store_layout(const ip_store *s)
{
    return &s->layout;
}

const char *ip_store_path(const ip_store *s)
{
    return s->path;
}

void ip_store_brick_entry(const ip_store *s, uint64_t g, ip_brick_entry *entry)
{
    IP_ASSERT(g < s->layout.brick_count);
    ip__format_entry_decode(s->summary + s->offsets.directory + g * IP_DIRECTORY_ENTRY_SIZE, entry);
}

void ip_store_brick_range(const ip_store *s, uint64_t g, float range[2])
{
    range[0] = s->ranges[2 * g];
    range[1] = s->ranges[2 * g + 1];
}

const float *ip_store_subblock_ranges(const ip_store *s, uint64_t g)
{
    IP_ASSERT(g < s->layout.brick_count);
    return s->blocks + 2 * (uint64_t)s->subblocks * s->block_of[g];
}

uint64_t ip_store_summary_memory(const ip_store *s)
{
    return s->memory;
}

/* The octree's node ranges. */
static const float *stored_nodes(const ip_store *s)
{
    return s->nodes;
}

const float *ip_store_node_range(const ip_store *s, uint32_t level, uint32_t depth,
                                 const uint32_t node[3])
{
    if (depth == 0)
        return s->ranges + 2 * ip_brick_global_index(&s->layout, level, node);
    return stored_nodes(s) + 2 * ip__octree_node_index(&s->layout, level, depth, node);
}

uint64_t ip_store_brick_samples(const ip_store *s, uint64_t g)
{
    uint32_t level, brick[3], origin[3], extent[3];
    ip_brick_coords(&s->layout, g, &level, brick);
    ip_brick_extent(&s->layout, level, brick, origin, extent);
    return (uint64_t)extent[0] * extent[1] * extent[2];
}

static ip_status brick_fail(const ip_store *s, uint64_t g, ip_status code, ip_error *err,
                            const char *what)
{
    uint32_t level, brick[3];
    ip_brick_coords(&s->layout, g, &level, brick);
    return ip__fail(err, code, "%s: brick %llu (level %u, brick %u,%u,%u): %s", s->path,
                    (unsigned long long)g, level, brick[0], brick[1], brick[2], what);
}

/* Scratch of ip_store_read_brick(): the payload, then the codec's own scratch. */
static size_t payload_room(const ip_store *s)
{
    return (s->largest_payload + 63) & ~(size_t)63;
}

size_t ip_store_read_work_size(const ip_store *s)
{
    if (s->volume)
        return 64; /* unused: a token, so that a caller's allocation of it succeeds */
    return payload_room(s) + ip__codec_work_size(s->largest_samples, s->layout.type);
}

/* Reads brick g's payload into `payload`; the message, which names the brick and its bytes,
 * is written only on failure (a read that succeeds costs a pread and nothing else). */
static ip_status read_payload(const ip_store *s, uint64_t g, const ip_brick_entry *e,
                              unsigned char *payload, ip_error *err)
{
    int failure = read_fully(s, payload, e->stored_size, e->offset);
    if (failure == 0)
        return IP_OK;
    char what[160];
    uint32_t level, b[3];
    ip_brick_coords(&s->layout, g, &level, b);
    snprintf(what, sizeof what,
             "the payload of brick %llu (level %u, brick %u,%u,%u; "
             "bytes %llu-%llu)",
             (unsigned long long)g, level, b[0], b[1], b[2], (unsigned long long)e->offset,
             (unsigned long long)(e->offset + e->stored_size));
    return read_failed(s, failure, what, err);
}

/* A memory store's brick: gathered from the samples (level 0) or the held pyramid. */
static void gather_brick(const ip_store *s, uint64_t g, void *dst)
{
    uint32_t level, brick[3], origin[3], extent[3];
    ip_brick_coords(&s->layout, g, &level, brick);
    ip_brick_extent(&s->layout, level, brick, origin, extent);
    ip__memory_volume_gather(s->volume, &s->layout, level, origin, extent, dst);
}

ip_status ip_store_read_brick(const ip_store *s, uint64_t g, void *dst, void *work, ip_error *err)
{
    if (s->volume) {
        gather_brick(s, g, dst);
        return IP_OK;
    }
    ip_brick_entry e;
    ip_store_brick_entry(s, g, &e);
    unsigned char *payload = work;
    if (e.stored_size > 0) {
        /* Read once into memory of our own, then checked and decoded there: the bytes decoded
         * are the bytes verified, whatever happens to the file meanwhile. */
        ip_status st = read_payload(s, g, &e, payload, err);
        if (st != IP_OK)
            return st;
        if (ip__format_checksum(payload, e.stored_size) != e.checksum)
            return brick_fail(s, g, IP_ERR_CHECKSUM, err, "checksum mismatch");
    }
    uint32_t level, brick[3], origin[3], extent[3];
    ip_brick_coords(&s->layout, g, &level, brick);
    ip_brick_extent(&s->layout, level, brick, origin, extent);
    if (ip__codec_decode(&e, payload, extent, s->layout.type, s->ranges[2 * g], dst,
                         payload + payload_room(s)) != IP_OK)
        return brick_fail(s, g, IP_ERR_CORRUPT, err, "payload does not decode");
    return IP_OK;
}

void ip_store_prefetch_brick(const ip_store *s, uint64_t g)
{
    ip_brick_entry e;
    ip_store_brick_entry(s, g, &e);
    if (e.stored_size > 0)
        (void)posix_fadvise(s->fd, (off_t)e.offset, (off_t)e.stored_size, POSIX_FADV_WILLNEED);
}

/* Whether byte `offset` of the file is in the page cache: a read of it that may not wait for
 * the disk (RWF_NOWAIT) gets it (1), is refused as it would wait (0), or fails otherwise:
 * the kernel or the file system cannot tell (-1). */
static int byte_in_memory(int fd, uint64_t offset)
{
#ifdef RWF_NOWAIT
    char byte;
    struct iovec v = {&byte, 1};
    ssize_t n = preadv2(fd, &v, 1, (off_t)offset, RWF_NOWAIT);
    if (n == 1)
        return 1;
    return n < 0 && errno == EAGAIN ? 0 : -1;
#else
    (void)fd;
    (void)offset;
    return -1;
#endif
}

int ip_store_brick_in_memory(const ip_store *s, uint64_t g)
{
    ip_brick_entry e;
    ip_store_brick_entry(s, g, &e);
    if (e.stored_size == 0)
        return 1; /* a constant brick: nothing to read */
    /* its first, middle and last pages: the kernel reads a payload's pages together (a miss,
     * a hint, its read-ahead), so these stand for the others */
    uint64_t at[3] = {e.offset, e.offset + e.stored_size / 2, e.offset + e.stored_size - 1};
    for (int i = 0; i < 3; i++) {
        int in = byte_in_memory(s->fd, at[i]);
        if (in != 1)
            return in;
    }
    return 1;
}

static int same_range(const float *a, const float *b)
{
    /* empty sub-blocks store [+inf, -inf]; compare bit patterns' values exactly */
    return a[0] == b[0] && a[1] == b[1];
}

ip_status ip_store_check_summary(const ip_store *s, uint64_t g, const void *samples, ip_error *err)
{
    uint32_t level, brick[3], origin[3], extent[3];
    ip_brick_coords(&s->layout, g, &level, brick);
    ip_brick_extent(&s->layout, level, brick, origin, extent);
    float range[2];
    float *sub = malloc(2 * sizeof(float) * s->subblocks);
    if (!sub)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", s->path);
    ip__summarise_brick(samples, s->layout.type, extent, s->layout.brick_edge,
                        s->layout.subblock_edge, range, sub);
    const float *stored = ip_store_subblock_ranges(s, g);
    int ok = same_range(range, &s->ranges[2 * g]);
    for (uint32_t i = 0; ok && i < s->subblocks; i++)
        ok = same_range(&sub[2 * i], &stored[2 * i]);
    free(sub);
    return ok ? IP_OK : brick_fail(s, g, IP_ERR_CORRUPT, err, "samples disagree with the summary");
}

ip_status ip_store_verify_brick(const ip_store *s, uint64_t g, void *dst, void *work, ip_error *err)
{
    ip_status st = ip_store_read_brick(s, g, dst, work, err);
    return st == IP_OK ? ip_store_check_summary(s, g, dst, err) : st;
}

/* ip__octree_walk() visitor: the first node whose stored range differs from its children's. */
typedef struct octree_check {
    const float *stored; /* the node ranges */
    uint32_t level, depth, node[3];
} octree_check;

static int check_node(void *user, uint32_t level, uint32_t depth, const uint32_t node[3],
                      uint64_t node_index, const float range[2])
{
    octree_check *c = user;
    if (same_range(range, &c->stored[2 * node_index]))
        return 0;
    *c = (octree_check){c->stored, level, depth, {node[0], node[1], node[2]}};
    return 1;
}

ip_status ip_store_verify_octree(const ip_store *s, ip_error *err)
{
    octree_check c = {stored_nodes(s), 0, 0, {0, 0, 0}};
    if (ip__octree_walk(&s->layout, s->ranges, c.stored, check_node, &c) == 0)
        return IP_OK;
    return ip__fail(err, IP_ERR_CORRUPT,
                    "%s: octree node %u,%u,%u at depth %u of level %u disagrees with its children",
                    s->path, c.node[0], c.node[1], c.node[2], c.depth, c.level);
}

/* ---- a volume in memory ---- */

void ip_memory_volume_default(ip_memory_volume *v)
{
    memset(v, 0, sizeof *v);
    v->size = sizeof *v;
    v->name = "array";
}

/* The caller's description as this library's, checked and with its defaults, into *v. */
static ip_status take_volume(const void *samples, const ip_memory_volume *given,
                             ip_memory_volume *v, ip_error *err)
{
    ip_memory_volume_default(v);
    ip_status st =
        ip__sized_in(v, sizeof *v, given, sizeof *v, "ip_store_open_memory: volume", err);
    if (st != IP_OK)
        return st;
    if (!v->name)
        v->name = "array";
    if (!samples)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: the samples are NULL", v->name);
    if (v->dims[0] < 2 || v->dims[1] < 2 || v->dims[2] < 2)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "%s: %u x %u x %u samples: each dimension must be at least 2", v->name,
                        v->dims[0], v->dims[1], v->dims[2]);
    if ((unsigned)v->type > IP_FLOAT32)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "%s: sample type %d is none of uint8, uint16, int16, float32", v->name,
                        (int)v->type);
    if (v->spacing[0] == 0 && v->spacing[1] == 0 && v->spacing[2] == 0)
        v->spacing[0] = v->spacing[1] = v->spacing[2] = 1.0;
    if (v->strides[0] == 0 && v->strides[1] == 0 && v->strides[2] == 0) {
        v->strides[0] = (int64_t)ip_type_size(v->type);
        v->strides[1] = v->strides[0] * v->dims[0];
        v->strides[2] = v->strides[1] * v->dims[1];
    }
    if (ip__orientation_unset(&v->orientation))
        for (int a = 0; a < 3; a++)
            v->orientation.directions[a][a] = 1.0;
    st = ip_spacing_check(v->spacing, v->name, err);
    if (st == IP_OK)
        st = ip_orientation_check(&v->orientation, v->name, err);
    if (st == IP_OK && v->rescale.present)
        st = ip_rescale_check(&v->rescale, v->name, err);
    return st;
}

/* The layout a brick file of the volume has, but for its file figures (0). */
static ip_status memory_layout(ip_store *s, const ip_memory_volume *v, ip_error *err)
{
    ip_error why;
    uint32_t B = v->brick_edge ? v->brick_edge : IP_DEFAULT_BRICK_EDGE;
    uint32_t sub = v->subblock_edge ? v->subblock_edge : IP_DEFAULT_SUBBLOCK_EDGE;
    ip_status st = ip__layout_init(&s->layout, v->dims, v->type, v->spacing, B, sub, &why);
    if (st != IP_OK)
        return ip__fail(err, st, "%s: %s", v->name, why.message);
    s->layout.orientation = v->orientation;
    ip_rescale rescale;
    ip_rescale_identity(&rescale);
    if (v->rescale.present)
        rescale = v->rescale;
    ip__layout_set_rescale(&s->layout, &rescale);
    s->subblocks = ip_layout_subblocks_per_brick(&s->layout);
    return IP_OK;
}

/* The first NaN or infinite float32 sample, refused with its coordinates. */
static ip_status check_finite(const ip_store *s, unsigned threads, ip_error *err)
{
    uint32_t at[3];
    if (!ip__memory_volume_find_nonfinite(s->volume, &s->layout, threads, at))
        return IP_OK;
    const ip__memory_volume *m = s->volume;
    uint32_t bits;
    memcpy(&bits,
           m->samples + (ptrdiff_t)at[0] * m->strides[0] + (ptrdiff_t)at[1] * m->strides[1] +
               (ptrdiff_t)at[2] * m->strides[2],
           sizeof bits);
    return ip__fail(err, IP_ERR_INPUT, "%s: float32 sample at (x,y,z) = (%u,%u,%u) is %s", s->path,
                    at[0], at[1], at[2], (bits & 0x007fffffu) ? "NaN" : "infinite");
}

/* The summaries from every brick's ranges (`subblock_ranges`: 2 * subblocks floats per brick),
 * held as a brick file's are: sub-block ranges compacted, the octree, the directory. */
static ip_status memory_summaries(ip_store *s, const float *subblock_ranges)
{
    const ip_layout *l = &s->layout;
    uniform_table t = {NULL, NULL, 0, 0};
    s->block_of = malloc((l->brick_count ? l->brick_count : 1) * sizeof *s->block_of);
    s->nodes = malloc((2 * l->node_count + 1) * sizeof(float));
    s->summary = malloc(l->brick_count * IP_DIRECTORY_ENTRY_SIZE + 1);
    ip_status st = s->block_of && s->nodes && s->summary ? IP_OK : IP_ERR_NOMEM;
    for (uint64_t g = 0; st == IP_OK && g < l->brick_count; g++) {
        s->block_of[g] = block_for(s, &t, subblock_ranges + 2 * g * s->subblocks);
        if (s->block_of[g] == UINT32_MAX)
            st = IP_ERR_NOMEM;
        ip_brick_entry e = {0, 0, IP_BRICK_RAW, 0, 0};
        if (s->ranges[2 * g] == s->ranges[2 * g + 1])
            e.encoding = IP_BRICK_CONSTANT;
        ip__format_entry_encode(&e, s->summary + g * IP_DIRECTORY_ENTRY_SIZE);
    }
    free(t.keys);
    free(t.block);
    if (st != IP_OK)
        return st;
    ip__octree_build(l, s->ranges, s->nodes);
    ip__level_value_ranges(&s->layout, s->ranges);
    s->memory = l->brick_count * (IP_DIRECTORY_ENTRY_SIZE + 2 * sizeof(float)) +
                2 * l->node_count * sizeof(float) +
                s->block_count * 2 * s->subblocks * sizeof(float) +
                l->brick_count * sizeof *s->block_of;
    return IP_OK;
}

/* The pyramid and every summary of the memory store `s`. */
static ip_status build_memory(ip_store *s, unsigned threads, ip_error *err)
{
    const ip_layout *l = &s->layout;
    uint64_t floats = 2 * l->brick_count * s->subblocks;
    float *subblock_ranges =
        floats <= SIZE_MAX / sizeof(float) ? malloc(floats * sizeof(float)) : NULL;
    s->ranges = malloc((2 * l->brick_count + 1) * sizeof(float));
    ip_status st = subblock_ranges && s->ranges ? IP_OK : IP_ERR_NOMEM;
    if (st == IP_OK)
        st = ip__memory_volume_build(s->volume, l, threads, s->ranges, subblock_ranges);
    if (st == IP_OK)
        st = memory_summaries(s, subblock_ranges);
    free(subblock_ranges);
    if (st != IP_OK)
        return ip__fail(err, st, "%s: out of memory for the pyramid and summaries", s->path);
    s->largest_samples = ((size_t)l->brick_edge + 1) * (l->brick_edge + 1) * (l->brick_edge + 1);
    return IP_OK;
}

ip_status ip_store_open_memory(const void *samples, const ip_memory_volume *volume, ip_store **out,
                               ip_error *err)
{
    if (!volume || !out)
        return ip__fail(err, IP_ERR_ARGUMENT, "ip_store_open_memory: volume and out are required");
    ip_memory_volume v;
    ip_status st = take_volume(samples, volume, &v, err);
    if (st != IP_OK)
        return st;
    ip_store *s = calloc(1, sizeof *s);
    if (s)
        s->volume = calloc(1, sizeof *s->volume);
    if (!s || !s->volume) {
        free(s);
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", v.name);
    }
    s->fd = -1;
    snprintf(s->path, sizeof s->path, "%s", v.name);
    s->volume->samples = samples;
    for (int a = 0; a < 3; a++)
        s->volume->strides[a] = (ptrdiff_t)v.strides[a];
    unsigned threads = ip_thread_count(v.threads);
    st = memory_layout(s, &v, err);
    if (st == IP_OK)
        st = check_finite(s, threads, err);
    if (st == IP_OK)
        st = build_memory(s, threads, err);
    if (st != IP_OK) {
        ip_store_close(s);
        return st;
    }
    *out = s;
    return IP_OK;
}

uint64_t ip_store_held_samples(const ip_store *s)
{
    return s->volume ? s->volume->held_bytes : 0;
}

/* A brick file opened for reading: its summaries held in memory, bricks read on demand. */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "internal.h"
#include "codec.h"
#include "isoprop/store.h"
#include "summary.h"

struct ip_store {
    char path[IP_PATH_MAX];
    int fd;
    uint64_t size; /* the file's size when opened */
    ip_layout layout;
    ip_summary_offsets offsets;
    unsigned char *summary; /* the summary section, read and verified once at open; owned */
    const float *ranges;    /* brick, sub-block and node ranges, host floats */
    float *ranges_copy;     /* owned copy on big-endian hosts, else NULL */
    uint32_t subblocks;
    size_t largest_payload; /* bytes of the largest stored payload */
    size_t largest_samples; /* samples of the largest brick */
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

/* The header, then the padding and the summary section, each read once and validated. */
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
    uint64_t data_end = l->data_offset + l->data_size;
    s->summary = malloc(l->summary_size ? l->summary_size : 1);
    if (!s->summary)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory for the %llu-byte summary section",
                        s->path, (unsigned long long)l->summary_size);
    st = read_at(s, gap, l->summary_offset - data_end, data_end, "the data section", err);
    if (st == IP_OK)
        st = read_at(s, s->summary, l->summary_size, l->summary_offset, "the summary section", err);
    if (st == IP_OK)
        st = ip__format_parse_summary(&s->layout, gap, s->summary, s->path, 0, err);
    return st;
}

static ip_status host_ranges(ip_store *s, ip_error *err)
{
    const unsigned char *first = s->summary + s->offsets.brick_ranges;
    uint64_t floats = (s->offsets.end - s->offsets.brick_ranges) / 4;
    if (ip__host_little_endian()) {
        s->ranges = (const float *)(const void *)first; /* 8-aligned: see docs/format.md */
        return IP_OK;
    }
    s->ranges_copy = malloc(floats * sizeof(float));
    if (!s->ranges_copy)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", s->path);
    for (uint64_t i = 0; i < floats; i++) {
        uint32_t bits = ip__load_u32le(first + 4 * i);
        memcpy(&s->ranges_copy[i], &bits, 4);
    }
    s->ranges = s->ranges_copy;
    return IP_OK;
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
    if (st == IP_OK) {
        ip__summary_offsets_of(&s->layout, &s->offsets);
        s->subblocks = ip_layout_subblocks_per_brick(&s->layout);
        st = host_ranges(s, err);
    }
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
    free(s->ranges_copy);
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
    return s->ranges + 2 * s->layout.brick_count + 2 * g * s->subblocks;
}

/* The octree's node ranges: after the brick and sub-block ranges. */
static const float *stored_nodes(const ip_store *s)
{
    return s->ranges + 2 * s->layout.brick_count * (1 + (uint64_t)s->subblocks);
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

ip_status ip_store_read_brick(const ip_store *s, uint64_t g, void *dst, void *work, ip_error *err)
{
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

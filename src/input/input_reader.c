/* SPDX-License-Identifier: BSD-3-Clause */
/* Streaming z-planes out of an input volume: positioned reads for raw data, zlib's inflate for
 * gzip (and zlib) streams, then conversion to the host's byte order and a float32 check. */
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include "atomic_file.h"
#include "internal.h"
#include "input_positioned.h"
#include "input_source.h"
#include "isoprop/input.h"

/* Compressed bytes read per refill: small next to a plane, large enough for few system calls. */
#define GZIP_INPUT_CHUNK ((size_t)256 * 1024)
/* zlib counts output space in uInt; larger reads are inflated in pieces of this size. */
#define GZIP_OUTPUT_STEP ((size_t)1 << 30)
/* 15-bit window, +32: inflate recognises both the gzip and the zlib wrapper. */
#define GZIP_WINDOW_BITS (15 + 32)

struct ip_input_reader {
    ip_input_desc desc;
    char label[2 * IP_PATH_MAX + 16]; /* how messages name the data */
    int fd;
    uint32_t next_z;
    size_t sample_size;
    uint64_t plane_bytes;
    uint64_t total_bytes;
    ip_status failed;  /* sticky: after an error the position in the data is unknown */
    int stream;        /* raw samples from standard input: read once, in order, never seeked */
    uint64_t streamed; /* bytes of standard input read so far */
    /* TIFF and DICOM: a plane source instead of the data file */
    const ip__plane_source *source;
    void *source_state;
    /* raw data read past the page cache (ip__input_direct_open()): the data file opened a
     * second time with O_DIRECT, or -1; the alignments it needs; set for good at the first
     * read the file system refuses */
    int direct_fd;
    uint32_t direct_mem_align, direct_offset_align;
    atomic_int direct_refused;
    /* gzip only */
    z_stream zs;
    int zs_live;
    int stream_ended;
    int file_eof;
    unsigned char *in_buf;
    uint64_t file_pos;
    uint64_t produced;
};

static void set_label(ip_input_reader *r)
{
    const ip_input_desc *d = &r->desc;
    if (ip__input_is_stdin(d->data_path))
        snprintf(r->label, sizeof r->label, "stdin");
    else if (strcmp(d->path, d->data_path) == 0)
        snprintf(r->label, sizeof r->label, "%s", d->path);
    else
        snprintf(r->label, sizeof r->label, "%s: data file %s", d->path, d->data_path);
}

/* Sizes are checked against 64 bits here as well as in ip_input_describe(), since a caller
 * may fill a desc by hand. */
static ip_status measure(ip_input_reader *r, ip_error *err)
{
    const ip_input_desc *d = &r->desc;
    r->sample_size = ip_type_size(d->type);
    if (r->sample_size == 0 || d->dims[0] < 1 || d->dims[1] < 1 || d->dims[2] < 1)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: the description has no type or dims", d->path);
    uint64_t plane = (uint64_t)d->dims[0] * d->dims[1];
    if (plane > UINT64_MAX / r->sample_size / d->dims[2])
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: %ux%ux%u samples overflow 64 bits", d->path,
                        d->dims[0], d->dims[1], d->dims[2]);
    r->plane_bytes = plane * r->sample_size;
    r->total_bytes = r->plane_bytes * d->dims[2];
    if (r->plane_bytes > SIZE_MAX)
        return ip__fail(err, IP_ERR_NOMEM, "%s: a plane of %llu bytes does not fit in memory",
                        d->path, (unsigned long long)r->plane_bytes);
    return IP_OK;
}

static ip_status gzip_skip(ip_input_reader *r, ip_error *err);

static ip_status start_gzip(ip_input_reader *r, ip_error *err)
{
    r->in_buf = malloc(GZIP_INPUT_CHUNK);
    if (!r->in_buf)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory for the gzip input", r->label);
    int ret = inflateInit2(&r->zs, GZIP_WINDOW_BITS);
    if (ret == Z_MEM_ERROR)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory for the gzip decoder", r->label);
    if (ret != Z_OK)
        return ip__fail(err, IP_ERR_IO, "%s: cannot start the gzip decoder (zlib error %d)",
                        r->label, ret);
    r->zs_live = 1;
    r->file_pos = r->desc.data_offset;
    return IP_OK;
}

ip_status ip_input_open(const ip_input_desc *desc, ip_input_reader **out, ip_error *err)
{
    ip_status status;
    if (!desc || !out)
        return ip__fail(err, IP_ERR_ARGUMENT, "ip_input_open: desc and out are required");
    *out = NULL;
    ip_input_reader *r = calloc(1, sizeof *r);
    if (!r)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory for the reader", desc->path);
    r->desc = *desc;
    r->fd = -1;
    r->direct_fd = -1;
    atomic_init(&r->direct_refused, 0);
    set_label(r);
    if ((status = measure(r, err)) != IP_OK) {
        ip_input_close(r);
        return status;
    }
    if ((status = ip__plane_source_of(desc, &r->source, err)) != IP_OK) {
        ip_input_close(r);
        return status;
    }
    if (desc->encoding == IP_ENCODING_CALLBACK) {
        if (!desc->plane_source) {
            ip_input_close(r);
            return ip__fail(err, IP_ERR_ARGUMENT, "%s: the description has no plane source",
                            desc->path);
        }
        *out = r;
        return IP_OK;
    }
    if (r->source) {
        if ((status = r->source->open(&r->desc, &r->source_state, err)) != IP_OK) {
            ip_input_close(r);
            return status;
        }
        *out = r;
        return IP_OK;
    }
    if (desc->encoding == IP_ENCODING_RAW && ip__input_is_stdin(desc->data_path)) {
        r->stream = 1;
        r->fd = fcntl(STDIN_FILENO, F_DUPFD_CLOEXEC, 0);
        if (r->fd < 0) {
            status = ip__fail_errno(err, IP_ERR_IO, errno, "stdin: cannot read");
            ip_input_close(r);
            return status;
        }
        *out = r;
        return IP_OK;
    }
    /* O_NONBLOCK and the type check: the file may have been replaced by a FIFO or a device
     * since ip_input_describe() looked at it; reading one would hang or never end. */
    r->fd = open(desc->data_path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (r->fd < 0) {
        status = ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot open", r->label);
        ip_input_close(r);
        return status;
    }
    struct stat st;
    if (fstat(r->fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        status = ip__fail(err, IP_ERR_INPUT, "%s: not a regular file", r->label);
        ip_input_close(r);
        return status;
    }
    /* Planes are read once, front to back: a hint for read-ahead, harmless if ignored. */
    (void)posix_fadvise(r->fd, 0, 0, POSIX_FADV_SEQUENTIAL);
    if (desc->encoding == IP_ENCODING_GZIP &&
        ((status = start_gzip(r, err)) != IP_OK || (status = gzip_skip(r, err)) != IP_OK)) {
        ip_input_close(r);
        return status;
    }
    *out = r;
    return IP_OK;
}

void ip_input_close(ip_input_reader *reader)
{
    if (!reader)
        return;
    if (reader->source)
        reader->source->close(reader->source_state);
    if (reader->zs_live)
        inflateEnd(&reader->zs);
    if (reader->fd >= 0)
        close(reader->fd);
    if (reader->direct_fd >= 0)
        close(reader->direct_fd);
    free(reader->in_buf);
    free(reader);
}

/* ---- gzip ---- */

/* Moves unread input to the front of the buffer and tops it up from the file. */
static ip_status gzip_refill(ip_input_reader *r, ip_error *err)
{
    size_t kept = r->zs.avail_in;
    if (kept > 0 && r->zs.next_in != r->in_buf)
        memmove(r->in_buf, r->zs.next_in, kept);
    r->zs.next_in = r->in_buf;
    if (r->file_eof || kept == GZIP_INPUT_CHUNK)
        return IP_OK;
    ssize_t n;
    do {
        n = pread(r->fd, r->in_buf + kept, GZIP_INPUT_CHUNK - kept, (off_t)r->file_pos);
    } while (n < 0 && errno == EINTR);
    if (n < 0)
        return ip__fail_errno(err, IP_ERR_IO, errno, "%s: read failed", r->label);
    if (n == 0)
        r->file_eof = 1;
    r->zs.avail_in = (uInt)(kept + (size_t)n);
    r->file_pos += (uint64_t)n;
    return IP_OK;
}

/* After one member another may follow (concatenated gzip files are valid gzip); anything else
 * after the compressed data means the file is not what its header says. */
static ip_status gzip_member_end(ip_input_reader *r, ip_error *err)
{
    ip_status status;
    if (r->zs.avail_in < 2 && (status = gzip_refill(r, err)) != IP_OK)
        return status;
    if (r->zs.avail_in == 0) {
        r->stream_ended = 1;
        return IP_OK;
    }
    if (r->zs.avail_in >= 2 && r->zs.next_in[0] == 0x1f && r->zs.next_in[1] == 0x8b) {
        inflateReset(&r->zs);
        return IP_OK;
    }
    return ip__fail(err, IP_ERR_INPUT, "%s: unexpected bytes after the end of the gzip data",
                    r->label);
}

/* Inflates once into out[0..avail). *made counts the bytes produced; *starved is set when the
 * file ends inside the compressed stream. */
static ip_status gzip_step(ip_input_reader *r, unsigned char *out, size_t avail, size_t *made,
                           int *starved, ip_error *err)
{
    ip_status status;
    *made = 0;
    *starved = 0;
    if (r->zs.avail_in == 0) {
        if ((status = gzip_refill(r, err)) != IP_OK)
            return status;
        if (r->zs.avail_in == 0) {
            *starved = 1;
            return IP_OK;
        }
    }
    uInt space = (uInt)(avail < GZIP_OUTPUT_STEP ? avail : GZIP_OUTPUT_STEP);
    r->zs.next_out = out;
    r->zs.avail_out = space;
    int ret = inflate(&r->zs, Z_NO_FLUSH);
    *made = space - r->zs.avail_out;
    r->produced += *made;
    switch (ret) {
    case Z_OK: return IP_OK;
    case Z_STREAM_END: return gzip_member_end(r, err);
    case Z_BUF_ERROR:
        /* No progress with input and output space left cannot happen; refuse to spin. */
        if (r->zs.avail_in == 0 || *made > 0)
            return IP_OK;
        break;
    case Z_MEM_ERROR:
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory inflating gzip data", r->label);
    default: break;
    }
    return ip__fail(err, IP_ERR_INPUT, "%s: gzip data are corrupt after %llu bytes: %s", r->label,
                    (unsigned long long)r->produced, r->zs.msg ? r->zs.msg : "invalid data");
}

static ip_status gzip_ends_early(const ip_input_reader *r, ip_error *err)
{
    return ip__fail(err, IP_ERR_INPUT, "%s: gzip data ends after %llu of %llu bytes", r->label,
                    (unsigned long long)r->produced, (unsigned long long)r->total_bytes);
}

static ip_status gzip_read(ip_input_reader *r, unsigned char *dst, size_t size, ip_error *err)
{
    size_t done = 0;
    while (done < size) {
        size_t made;
        int starved;
        if (r->stream_ended)
            return gzip_ends_early(r, err);
        ip_status status = gzip_step(r, dst + done, size - done, &made, &starved, err);
        if (status != IP_OK)
            return status;
        done += made;
        if (starved)
            return gzip_ends_early(r, err);
    }
    return IP_OK;
}

/* After the last plane the stream must end: one more byte means the dims are wrong. */
static ip_status gzip_finish(ip_input_reader *r, ip_error *err)
{
    unsigned char scratch[4096];
    while (!r->stream_ended) {
        size_t made;
        int starved;
        ip_status status = gzip_step(r, scratch, sizeof scratch, &made, &starved, err);
        if (status != IP_OK)
            return status;
        if (made > 0)
            return ip__fail(err, IP_ERR_INPUT,
                            "%s: gzip data are longer than the %ux%ux%u x %zu = %llu bytes of the "
                            "dims",
                            r->label, r->desc.dims[0], r->desc.dims[1], r->desc.dims[2],
                            r->sample_size, (unsigned long long)r->total_bytes);
        if (starved)
            return ip__fail(err, IP_ERR_INPUT,
                            "%s: gzip data end without their end marker after all %llu bytes",
                            r->label, (unsigned long long)r->total_bytes);
    }
    return IP_OK;
}

/* Inflates and drops the desc's stream_skip bytes before the first sample (a header inside
 * the stream); the counts of later messages start after them. */
static ip_status gzip_skip(ip_input_reader *r, ip_error *err)
{
    unsigned char scratch[4096];
    uint64_t left = r->desc.stream_skip;
    while (left > 0) {
        size_t made;
        int starved;
        if (r->stream_ended)
            starved = 1;
        else {
            size_t want = left < sizeof scratch ? (size_t)left : sizeof scratch;
            ip_status status = gzip_step(r, scratch, want, &made, &starved, err);
            if (status != IP_OK)
                return status;
            left -= made;
        }
        if (starved)
            return ip__fail(err, IP_ERR_INPUT,
                            "%s: gzip data end inside the %llu header bytes before the samples",
                            r->label, (unsigned long long)r->desc.stream_skip);
    }
    r->produced = 0;
    return IP_OK;
}

/* ---- standard input ---- */

/* Reads exactly `size` bytes of standard input into dst, whatever size the pipe hands over at
 * a time (waiting when the descriptor was left non-blocking); a pipe that ends first is an
 * IP_ERR_INPUT naming how far it got. */
static ip_status stream_read(ip_input_reader *r, unsigned char *dst, size_t size, ip_error *err)
{
    size_t done = 0;
    while (done < size) {
        ssize_t n = read(r->fd, dst + done, size - done);
        if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
            struct pollfd p = {r->fd, POLLIN, 0};
            (void)poll(&p, 1, -1);
            continue;
        }
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0)
            return ip__fail_errno(err, IP_ERR_IO, errno, "stdin: read failed after %llu bytes",
                                  (unsigned long long)r->streamed);
        if (n == 0)
            return ip__fail(err, IP_ERR_INPUT, "stdin: ended after %llu of %llu bytes",
                            (unsigned long long)r->streamed, (unsigned long long)r->total_bytes);
        done += (size_t)n;
        r->streamed += (uint64_t)n;
    }
    return IP_OK;
}

/* After the last plane the pipe must end: one more byte means the dims are wrong. */
static ip_status stream_finish(ip_input_reader *r, ip_error *err)
{
    unsigned char extra;
    r->total_bytes++; /* a byte past the end is what is asked for */
    ip_status st = stream_read(r, &extra, 1, err);
    r->total_bytes--;
    if (st == IP_OK)
        return ip__fail(err, IP_ERR_INPUT,
                        "stdin: longer than the %ux%ux%u x %zu = %llu bytes of the dims",
                        r->desc.dims[0], r->desc.dims[1], r->desc.dims[2], r->sample_size,
                        (unsigned long long)r->total_bytes);
    if (st == IP_ERR_INPUT) { /* ended: as it should */
        if (err)
            ip_error_clear(err);
        return IP_OK;
    }
    return st;
}

/* ---- samples ---- */

static void to_host_order(const ip_input_reader *r, void *samples, size_t count)
{
    int host_big = !ip__host_little_endian();
    if (r->sample_size > 1 && (r->desc.big_endian != 0) != host_big)
        ip__swap_bytes(samples, count, r->sample_size);
}

/* NaN and infinity have no place in an isosurface's scalar field; name the first one
 * (`samples` start at plane first_z). */
static ip_status check_finite(const ip_input_reader *r, const void *samples, size_t count,
                              uint32_t first_z, ip_error *err)
{
    const unsigned char *p = samples;
    const uint32_t exponent = 0x7f800000u;
    for (size_t i = 0; i < count; i++) {
        uint32_t bits;
        memcpy(&bits, p + 4 * i, sizeof bits);
        if ((bits & exponent) != exponent)
            continue;
        uint64_t plane = (uint64_t)r->desc.dims[0] * r->desc.dims[1];
        unsigned x = (unsigned)(i % r->desc.dims[0]);
        unsigned y = (unsigned)((i / r->desc.dims[0]) % r->desc.dims[1]);
        unsigned long long z = first_z + i / plane;
        return ip__fail(err, IP_ERR_INPUT, "%s: float32 sample at (x,y,z) = (%u,%u,%llu) is %s",
                        r->label, x, y, z, (bits & 0x007fffffu) ? "NaN" : "infinite");
    }
    return IP_OK;
}

/* Planes of a plane source, already in the host's byte order. */
static ip_status read_source_planes(ip_input_reader *r, unsigned char *dst, uint32_t count,
                                    ip_error *err)
{
    for (uint32_t i = 0; i < count; i++) {
        ip_status status =
            r->source->read_plane(r->source_state, r->next_z + i, dst + i * r->plane_bytes, err);
        if (status != IP_OK)
            return status;
    }
    return IP_OK;
}

/* Planes of the caller's function (IP_ENCODING_CALLBACK), in the host's byte order. A failure
 * without a message gets one that names the source. */
static ip_status read_callback_planes(ip_input_reader *r, void *dst, uint32_t count, ip_error *err)
{
    if (err)
        err->message[0] = '\0';
    ip_status status = r->desc.plane_source(r->desc.plane_user, r->next_z, count, dst, err);
    if (status == IP_OK)
        return IP_OK;
    if (status > IP_OK || status < IP_ERR_CANCELLED)
        status = IP_ERR_INPUT;
    if (err && err->message[0] != '\0') {
        err->code = status;
        return status;
    }
    return ip__fail(err, status, "%s: the plane source failed at planes %u .. %u", r->label,
                    r->next_z, r->next_z + count - 1);
}

static ip_status read_samples(ip_input_reader *r, void *dst, uint32_t count, ip_error *err)
{
    uint64_t bytes = (uint64_t)count * r->plane_bytes;
    ip_status status;
    if (bytes > SIZE_MAX)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: %u planes are too many to read at once",
                        r->label, count);
    if (r->source || r->desc.encoding == IP_ENCODING_CALLBACK) {
        status = r->source ? read_source_planes(r, dst, count, err)
                           : read_callback_planes(r, dst, count, err);
        if (status == IP_OK && r->desc.type == IP_FLOAT32)
            status = check_finite(r, dst, (size_t)(bytes / r->sample_size), r->next_z, err);
        return status;
    }
    if (r->desc.encoding == IP_ENCODING_GZIP) {
        status = gzip_read(r, dst, (size_t)bytes, err);
        if (status == IP_OK && r->next_z + count == r->desc.dims[2])
            status = gzip_finish(r, err);
    } else if (r->stream) {
        status = stream_read(r, dst, (size_t)bytes, err);
        if (status == IP_OK && r->next_z + count == r->desc.dims[2])
            status = stream_finish(r, err);
    } else {
        uint64_t offset = r->desc.data_offset + (uint64_t)r->next_z * r->plane_bytes;
        status = ip__pread_all(r->fd, dst, (size_t)bytes, offset, r->desc.data_path, err);
    }
    if (status != IP_OK)
        return status;
    size_t samples = (size_t)(bytes / r->sample_size);
    to_host_order(r, dst, samples);
    if (r->desc.type == IP_FLOAT32)
        return check_finite(r, dst, samples, r->next_z, err);
    return IP_OK;
}

ip_status ip_input_read_planes(ip_input_reader *reader, void *dst, uint32_t count, ip_error *err)
{
    if (!reader || (!dst && count > 0))
        return ip__fail(err, IP_ERR_ARGUMENT, "ip_input_read_planes: reader and dst are required");
    if (reader->failed != IP_OK)
        return ip__fail(err, reader->failed, "%s: the reader stopped at an earlier error",
                        reader->label);
    if (count > reader->desc.dims[2] - reader->next_z)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "%s: cannot read %u planes from z = %u: the volume has %u planes",
                        reader->label, count, reader->next_z, reader->desc.dims[2]);
    if (count == 0)
        return IP_OK;
    ip_status status = read_samples(reader, dst, count, err);
    if (status != IP_OK) {
        reader->failed = status;
        return status;
    }
    reader->next_z += count;
    return IP_OK;
}

int ip__encoding_is_planes(ip_encoding encoding)
{
    return encoding == IP_ENCODING_TIFF || encoding == IP_ENCODING_DICOM ||
           encoding == IP_ENCODING_HDF5 || encoding == IP_ENCODING_ZARR;
}

ip_status ip__plane_source_of(const ip_input_desc *desc, const ip__plane_source **out,
                              ip_error *err)
{
    const ip__input_formats *formats;
    *out = NULL;
    if (!ip__encoding_is_planes(desc->encoding))
        return IP_OK;
    ip_status st = ip__input_formats_load(desc->path, &formats, err);
    if (st == IP_OK)
        *out = desc->encoding == IP_ENCODING_TIFF   ? formats->tiff_source
               : desc->encoding == IP_ENCODING_HDF5 ? formats->hdf5_source
               : desc->encoding == IP_ENCODING_ZARR ? formats->zarr_source
                                                    : formats->dicom_source;
    return st;
}

/* ---- positioned reads (internal, input_positioned.h) ---- */

int ip__input_positioned(const ip_input_reader *reader)
{
    return reader->desc.encoding == IP_ENCODING_RAW && !reader->stream;
}

/* Where the kernel gives it (statx STATX_DIOALIGN), the alignment O_DIRECT needs of buffer
 * addresses and of file offsets and lengths; 4096 for both where it does not. Returns 0 when
 * the file system says it has no direct I/O. */
static int direct_alignment(int fd, uint32_t *mem_align, uint32_t *offset_align)
{
    *mem_align = *offset_align = 4096;
#ifdef STATX_DIOALIGN
    struct statx stx;
    if (statx(fd, "", AT_EMPTY_PATH, STATX_DIOALIGN, &stx) == 0 &&
        (stx.stx_mask & STATX_DIOALIGN)) {
        if (stx.stx_dio_mem_align == 0 || stx.stx_dio_offset_align == 0)
            return 0;
        *mem_align = stx.stx_dio_mem_align;
        *offset_align = stx.stx_dio_offset_align;
    }
#endif
    return 1;
}

/* Whether every plane starts and ends on the direct alignment in the file. A header of a size
 * that is not a multiple (a .nii's 352 bytes) leaves the planes to buffered reads: reading the
 * aligned superset and moving the samples into place would cost a copy of every plane. */
static int planes_aligned(const ip_input_reader *r)
{
    uint64_t a = r->direct_offset_align;
    return r->desc.data_offset % a == 0 && r->plane_bytes % a == 0;
}

/* Whether reads go past the page cache: the O_DIRECT descriptor is open and no read was
 * refused yet. */
static int direct_on(const ip_input_reader *r)
{
    return r->direct_fd >= 0 && !atomic_load(&r->direct_refused);
}

int ip__input_direct_open(ip_input_reader *reader)
{
    ip_input_reader *r = reader;
    if (!ip__input_positioned(r) || r->fd < 0)
        return 0;
    if (r->direct_fd >= 0)
        return direct_on(r);
    int fd = open(r->desc.data_path, O_RDONLY | O_DIRECT | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return 0; /* EINVAL: the file system has no O_DIRECT; any other error: the same */
    /* the same file as the buffered descriptor, not one put in its place since */
    struct stat a, b;
    if (fstat(fd, &a) != 0 || fstat(r->fd, &b) != 0 || a.st_dev != b.st_dev ||
        a.st_ino != b.st_ino ||
        !direct_alignment(fd, &r->direct_mem_align, &r->direct_offset_align) ||
        !planes_aligned(r)) {
        close(fd);
        return 0;
    }
    r->direct_fd = fd;
    return 1;
}

/* Reads [offset, offset + size) into dst with O_DIRECT when the reader has it and the
 * buffer, offset and size meet its alignment. Returns the bytes read that way: all of them,
 * or fewer when the file system refused (EINVAL: direct reads stop for good) or a short read
 * left an unaligned rest; the caller reads the rest through the page cache. */
static size_t read_direct(const ip_input_reader *r, unsigned char *dst, size_t size,
                          uint64_t offset)
{
    ip_input_reader *mut = (ip_input_reader *)r; /* only the atomic flag changes */
    if (!direct_on(r))
        return 0;
    uint64_t oa = r->direct_offset_align, ma = r->direct_mem_align;
    size_t done = 0;
    while (done < size && (offset + done) % oa == 0 && (size - done) % oa == 0 &&
           (uintptr_t)(dst + done) % ma == 0) {
        ssize_t n = pread(r->direct_fd, dst + done, size - done, (off_t)(offset + done));
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0 && errno == EINVAL)
            atomic_store(&mut->direct_refused, 1);
        if (n <= 0)
            break;
        done += (size_t)n;
    }
    return done;
}

ip_status ip__input_read_planes_at(const ip_input_reader *reader, uint32_t z, uint32_t count,
                                   void *dst, uint64_t *direct_bytes, ip_error *err)
{
    const ip_input_reader *r = reader;
    if (direct_bytes)
        *direct_bytes = 0;
    if (!ip__input_positioned(r) || z > r->desc.dims[2] || count > r->desc.dims[2] - z)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: cannot read %u planes at z = %u", r->label,
                        count, z);
    uint64_t bytes = (uint64_t)count * r->plane_bytes;
    if (bytes > SIZE_MAX)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: %u planes are too many to read at once",
                        r->label, count);
    uint64_t offset = r->desc.data_offset + (uint64_t)z * r->plane_bytes;
    size_t fast = read_direct(r, dst, (size_t)bytes, offset);
    if (direct_bytes)
        *direct_bytes = fast;
    ip_status status = ip__pread_all(r->fd, (unsigned char *)dst + fast, (size_t)bytes - fast,
                                     offset + fast, r->desc.data_path, err);
    if (status != IP_OK)
        return status;
    size_t samples = (size_t)(bytes / r->sample_size);
    to_host_order(r, dst, samples);
    if (r->desc.type == IP_FLOAT32)
        return check_finite(r, dst, samples, z, err);
    return IP_OK;
}

void ip__input_prefetch(const ip_input_reader *reader, uint32_t z, uint32_t count)
{
    const ip_input_reader *r = reader;
    if (!ip__input_positioned(r) || z >= r->desc.dims[2] || count == 0)
        return;
    if (direct_on(r))
        return; /* direct reads bypass the page cache: nothing to read ahead into */
    if (count > r->desc.dims[2] - z)
        count = r->desc.dims[2] - z;
    uint64_t offset = r->desc.data_offset + (uint64_t)z * r->plane_bytes;
    (void)posix_fadvise(r->fd, (off_t)offset, (off_t)(count * r->plane_bytes), POSIX_FADV_WILLNEED);
}

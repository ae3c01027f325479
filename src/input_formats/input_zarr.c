/* SPDX-License-Identifier: BSD-3-Clause */
/* Zarr v2 and v3 arrays and OME-Zarr images as a plane source: the chunks of one z-row (or a
 * shard's inner chunks) are read and decoded together, every chunk a job on a pool of every
 * core, each into its own slot; read_plane then gathers plane z from the slots, converting to
 * the type read, in one copy. Memory: the row's decoded chunks and a compressed chunk per
 * thread (ip_input_desc.reader_bytes). */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "atomic_file.h"
#include "internal.h"
#include "isoprop/system.h"
#include "pool.h"
#include "readers.h"
#include "zarr.h"

/* The array, the 3-D volume chosen from it and where the planes of a row of chunks go. */
typedef struct zarr_state {
    zarr_array a;
    const ip_input_desc *desc;
    uint64_t at[ZARR_MAX_DIMS];   /* per dim: the index read (z, y, x: unused) */
    uint64_t unit[ZARR_MAX_DIMS]; /* the chunk read as one piece: a chunk or an inner chunk */
    uint32_t n;                   /* ndim */
    size_t out_size;              /* bytes of an output sample */
    uint64_t per_x, per_y;        /* chunks across x and y */
    unsigned jobs;                /* chunks in a row: per_x * per_y */
    unsigned char *slots;         /* the decoded chunks of row `row_at`, one slot each */
    unsigned char *present;       /* per slot: 0 when its chunk is missing (the fill) */
    int64_t row_at;
    uint64_t loading; /* the row being read */
    ip__pool *pool;
    unsigned char *fill_run; /* a chunk's x-run of the fill value, in the type read */
    int fill_inexact;        /* it is a 32-bit integer float32 does not hold */
    /* the run of one row */
    atomic_int failed;
    pthread_mutex_t lock;
    unsigned error_job;
    ip_error error;
} zarr_state;

static size_t chunk_bytes(const zarr_state *s)
{
    size_t b = s->a.item;
    for (uint32_t d = 0; d < s->n; d++)
        b *= (size_t)s->unit[d];
    return b;
}

/* The path of the chunk (or shard) at grid index idx: FOLDER/[c SEP]i SEP j ... */
static void key_path(const zarr_array *a, const uint64_t *idx, char *out, size_t size)
{
    int len = snprintf(out, size, "%s/%s", a->folder, a->key_prefix ? "c" : "");
    for (uint32_t d = 0; d < a->ndim && len > 0 && (size_t)len < size; d++) {
        const char *sep = (d == 0 && !a->key_prefix) ? "" : (a->separator == '/' ? "/" : ".");
        len += snprintf(out + len, size - (size_t)len, "%s%llu", sep, (unsigned long long)idx[d]);
    }
}

/* Reads the whole file `path` into *out (*size bytes, the caller's to free); *out NULL when it
 * does not exist. */
static int read_file(const char *path, unsigned char **out, size_t *size, ip_error *err)
{
    struct stat st;
    *out = NULL;
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        if (errno == ENOENT)
            return IP_OK;
        return ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot open", path);
    }
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(fd);
        return ip__fail(err, IP_ERR_INPUT, "%s: not a regular file", path);
    }
    *size = (size_t)st.st_size;
    *out = malloc(*size ? *size : 1);
    ip_status s = *out ? ip__pread_all(fd, *out, *size, 0, path, err)
                       : ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", path);
    close(fd);
    if (s != IP_OK) {
        free(*out);
        *out = NULL;
    }
    return s;
}

static uint64_t le64(const unsigned char *p)
{
    uint64_t v = 0;
    for (int i = 7; i >= 0; i--)
        v = v << 8 | p[i];
    return v;
}

/* The inner chunk at grid index idx of a sharded array: its bytes into *out (NULL: empty, the
 * fill value), reading the shard's index and then only that chunk. */
static ip_status read_inner(const zarr_state *s, const uint64_t *idx, unsigned char **out,
                            size_t *size, char *path, size_t path_size, ip_error *err)
{
    const zarr_array *a = &s->a;
    uint64_t shard[ZARR_MAX_DIMS], entry = 0, count = 1;
    for (uint32_t d = 0; d < s->n; d++) {
        uint64_t per = a->chunk[d] / a->inner[d];
        shard[d] = idx[d] / per;
        entry = entry * per + idx[d] % per;
        count *= per;
    }
    *out = NULL;
    key_path(a, shard, path, path_size);
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return errno == ENOENT ? IP_OK
                               : ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot open", path);
    struct stat st;
    size_t index_bytes = (size_t)count * 16 + (a->index_chain.count ? 4 : 0);
    unsigned char *index = malloc(index_bytes);
    ip_status st_ = IP_OK;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || (uint64_t)st.st_size < index_bytes)
        st_ = ip__fail(err, IP_ERR_INPUT, "%s: shard of %lld bytes, under its %zu-byte index", path,
                       (long long)st.st_size, index_bytes);
    else if (!index)
        st_ = ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", path);
    else
        st_ = ip__pread_all(fd, index, index_bytes,
                            a->index_at_start ? 0 : (uint64_t)st.st_size - index_bytes, path, err);
    char why[160];
    if (st_ == IP_OK && a->index_chain.count &&
        ip__zarr_decode(&a->index_chain, index, index_bytes, index, index_bytes - 4, why,
                        sizeof why) != 0)
        st_ = ip__fail(err, IP_ERR_INPUT, "%s: shard index: %s", path, why);
    uint64_t offset = 0, bytes = 0;
    if (st_ == IP_OK) {
        offset = le64(index + entry * 16);
        bytes = le64(index + entry * 16 + 8);
        if (offset == UINT64_MAX && bytes == UINT64_MAX)
            bytes = 0; /* an empty inner chunk: the fill value */
        else if (offset > (uint64_t)st.st_size || bytes > (uint64_t)st.st_size - offset)
            st_ = ip__fail(err, IP_ERR_INPUT,
                           "%s: inner chunk %llu at %llu + %llu bytes lies past the shard's end "
                           "(%lld bytes)",
                           path, (unsigned long long)entry, (unsigned long long)offset,
                           (unsigned long long)bytes, (long long)st.st_size);
    }
    if (st_ == IP_OK && bytes > 0) {
        *out = malloc((size_t)bytes);
        *size = (size_t)bytes;
        st_ = *out ? ip__pread_all(fd, *out, (size_t)bytes, offset, path, err)
                   : ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", path);
        if (st_ != IP_OK) {
            free(*out);
            *out = NULL;
        }
    }
    free(index);
    close(fd);
    return st_;
}

/* ---- samples: stored type to the type read, host order ---- */

/* The stored sample at p as a double (byte order big when `big`). */
static double stored_value(const zarr_array *a, const unsigned char *p, int big)
{
    unsigned char b[4] = {0};
    for (uint32_t i = 0; i < a->item; i++)
        b[i] = big ? p[a->item - 1 - i] : p[i];
    uint32_t u = (uint32_t)b[0];
    if (a->item >= 2)
        u |= (uint32_t)b[1] << 8;
    if (a->item == 4)
        u |= (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
    if (a->kind == 'f') {
        float f;
        memcpy(&f, &u, sizeof f);
        return f;
    }
    if (a->kind == 'u')
        return u;
    int64_t v = u;
    if (v >> (8 * a->item - 1))
        v -= (int64_t)1 << (8 * a->item);
    return (double)v;
}

/* Stores `v` as the type read at dst; -1 when a 32-bit integer is past float32's exact 2^24. */
static int put_value(ip_type type, double v, unsigned char *dst)
{
    switch (type) {
    case IP_UINT8: *dst = (uint8_t)v; return 0;
    case IP_UINT16: {
        uint16_t x = (uint16_t)v;
        memcpy(dst, &x, 2);
        return 0;
    }
    case IP_INT16: {
        int16_t x = (int16_t)v;
        memcpy(dst, &x, 2);
        return 0;
    }
    case IP_FLOAT32: {
        float x = (float)v;
        memcpy(dst, &x, 4);
        return (double)x == v || isnan(v) ? 0 : -1;
    }
    }
    return 0;
}

/* Converts `count` stored samples at src into the type read at dst; -1 at a 32-bit integer
 * that float32 does not hold exactly. */
static int convert_run(const zarr_array *a, const unsigned char *src, size_t count,
                       unsigned char *dst, size_t out_size)
{
    int big = a->chain.big_endian;
    int same =
        (a->kind == 'u' && a->item <= 2) || (a->kind == 'i' && a->item == 2) || a->kind == 'f';
    if (same) {
        memcpy(dst, src, count * out_size);
        if (out_size > 1 && big == ip__host_little_endian())
            ip__swap_bytes(dst, count, out_size);
        return 0;
    }
    for (size_t i = 0; i < count; i++)
        if (put_value(a->type, stored_value(a, src + i * a->item, big), dst + i * out_size) != 0)
            return -1;
    return 0;
}

/* ---- one row of chunks ---- */

static void job_failed(zarr_state *s, unsigned job, const ip_error *e)
{
    pthread_mutex_lock(&s->lock);
    if (!atomic_load(&s->failed) || job < s->error_job) {
        s->error = *e;
        s->error_job = job;
    }
    atomic_store(&s->failed, 1);
    pthread_mutex_unlock(&s->lock);
}

/* One chunk of the row: read and decoded into its slot (present[job] 0: the fill value); a
 * failure names the chunk's file. */
static void row_chunk(void *user, unsigned job)
{
    zarr_state *s = user;
    uint64_t idx[ZARR_MAX_DIMS];
    char path[IP_PATH_MAX + 128], why[200];
    ip_error e;
    if (atomic_load(&s->failed))
        return;
    for (uint32_t d = 0; d + 3 < s->n; d++)
        idx[d] = s->at[d] / s->unit[d];
    idx[s->n - 3] = s->loading;
    idx[s->n - 2] = job / s->per_x;
    idx[s->n - 1] = job % s->per_x;
    unsigned char *bytes = NULL;
    size_t size = 0, want = chunk_bytes(s);
    ip_status st;
    if (s->a.sharded) {
        st = read_inner(s, idx, &bytes, &size, path, sizeof path, &e);
    } else {
        key_path(&s->a, idx, path, sizeof path);
        st = read_file(path, &bytes, &size, &e);
    }
    if (st == IP_OK && bytes &&
        ip__zarr_decode(&s->a.chain, bytes, size, s->slots + (size_t)job * want, want, why,
                        sizeof why) != 0)
        st = ip__fail(&e, IP_ERR_INPUT, "%s: %s", path, why);
    s->present[job] = bytes != NULL;
    if (st != IP_OK)
        job_failed(s, job, &e);
    free(bytes);
}

static ip_status load_row(zarr_state *s, uint64_t row, ip_error *err)
{
    s->loading = row;
    atomic_store(&s->failed, 0);
    ip__pool_run(s->pool, s->jobs, row_chunk, s);
    if (atomic_load(&s->failed)) {
        if (err)
            *err = s->error;
        return s->error.code;
    }
    s->row_at = (int64_t)row;
    return IP_OK;
}

/* Plane z (of the loaded row) from the chunks' slots, converted, into dst. */
static ip_status copy_plane(zarr_state *s, uint32_t z, unsigned char *dst, ip_error *err)
{
    const zarr_array *a = &s->a;
    uint32_t n = s->n;
    uint64_t ux = s->unit[n - 1], uy = s->unit[n - 2], uz = s->unit[n - 3];
    uint64_t X = a->shape[n - 1], Y = a->shape[n - 2], zl = z % uz;
    size_t want = chunk_bytes(s), base = 0;
    for (uint32_t d = 0; d + 3 < n; d++)
        base = base * s->unit[d] + s->at[d] % s->unit[d];
    for (uint64_t y = 0; y < Y; y++) {
        uint64_t iy = y / uy, yl = y % uy;
        for (uint64_t ix = 0; ix < s->per_x; ix++) {
            uint64_t x0 = ix * ux, nx = x0 + ux > X ? X - x0 : ux;
            unsigned char *out = dst + (y * X + x0) * s->out_size;
            size_t job = (size_t)(iy * s->per_x + ix);
            int bad;
            if (s->present[job])
                bad = convert_run(
                    a, s->slots + job * want + (((base * uz + zl) * uy + yl) * ux) * a->item,
                    (size_t)nx, out, s->out_size);
            else
                bad = s->fill_inexact, memcpy(out, s->fill_run, (size_t)nx * s->out_size);
            if (bad)
                return ip__fail(err, IP_ERR_INPUT,
                                "%s: a %s sample in (x,y,z) = (%llu..%llu,%llu,%u) is past 2^24, "
                                "which float32 does not hold exactly",
                                a->folder, a->kind == 'u' ? "uint32" : "int32",
                                (unsigned long long)x0, (unsigned long long)(x0 + nx - 1),
                                (unsigned long long)y, z);
        }
    }
    return IP_OK;
}

/* ---- the 3-D volume of the array ---- */

/* The index along each dim before z, y, x: an OME image's t and c as asked (required where
 * longer than 1), any other dim of size 1 only. */
static ip_status choose(const char *path, const zarr_array *a, const zarr_ome *o, int has_time,
                        uint32_t time, int has_channel, uint32_t channel, uint64_t *at,
                        ip_error *err)
{
    char sizes[128] = "";
    int len = 0;
    for (uint32_t d = 0; d < a->ndim && len < (int)sizeof sizes - 24; d++)
        len += snprintf(sizes + len, sizeof sizes - (size_t)len, "%s%c=%llu", d ? ", " : "",
                        o ? o->axis[d] : "?????"[d], (unsigned long long)a -> shape[d]);
    if (a->ndim < 3)
        return ip__fail(err, IP_ERR_INPUT, "%s: a %u-D array, not a volume", path, a->ndim);
    if (o && o->ndim != a->ndim)
        return ip__fail(err, IP_ERR_INPUT, "%s: %u axes for a %u-D array", path, o->ndim, a->ndim);
    for (uint32_t d = 0; d + 3 < a->ndim; d++) {
        int role = o ? o->axis[d] : 0;
        int given = role == 't' ? has_time : role == 'c' ? has_channel : 0;
        uint64_t want = role == 't' ? time : role == 'c' ? channel : 0;
        if (!given && a->shape[d] > 1)
            return ip__fail(err, IP_ERR_INPUT,
                            o ? "%s: a %u-D image (%s): pick a volume with --time and --channel"
                              : "%s: a %u-D array (%s) that is not OME-Zarr: only dims of 1 "
                                "before z, y, x are read",
                            path, a->ndim, sizes);
        if (want >= a->shape[d])
            return ip__fail(err, IP_ERR_ARGUMENT, "%s: %s %llu asked for, but the image has %llu",
                            path, role == 't' ? "time point" : "channel", (unsigned long long)want,
                            (unsigned long long)a->shape[d]);
        at[d] = want;
    }
    if (o && ((has_time && !memchr(o->axis, 't', o->ndim)) ||
              (has_channel && !memchr(o->axis, 'c', o->ndim))))
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: --%s asked for, but the image has no %c axis",
                        path, has_time && !memchr(o->axis, 't', o->ndim) ? "time" : "channel",
                        has_time && !memchr(o->axis, 't', o->ndim) ? 't' : 'c');
    for (uint32_t d = a->ndim - 3; d < a->ndim; d++)
        if (a->shape[d] >= ((uint64_t)1 << 31))
            return ip__fail(err, IP_ERR_INPUT, "%s: dimension %llu is too large", path,
                            (unsigned long long)a->shape[d]);
    return IP_OK;
}

/* The OME image (if the folder is one) and its array, as desc or the overrides choose. */
static ip_status open_array(const char *path, uint32_t scale, zarr_ome *o, int *is_ome,
                            zarr_array *a, ip_error *err)
{
    ip_status s = ip__zarr_read_ome(path, scale, is_ome, o, err);
    if (s != IP_OK)
        return s;
    return ip__zarr_read_array(*is_ome ? o->array : path, a, err);
}

static void units_of(const zarr_array *a, uint64_t *unit)
{
    for (uint32_t d = 0; d < a->ndim; d++)
        unit[d] = a->sharded ? a->inner[d] : a->chunk[d];
}

/* The memory the source holds: a row of decoded chunks, and a compressed chunk per thread (at
 * most the decoded size and blosc's overhead, as a bound). */
static uint64_t reader_bytes(const zarr_array *a)
{
    uint64_t unit[ZARR_MAX_DIMS], chunk = a->item;
    units_of(a, unit);
    for (uint32_t d = 0; d < a->ndim; d++)
        chunk *= unit[d];
    uint32_t n = a->ndim;
    uint64_t per = ((a->shape[n - 1] + unit[n - 1] - 1) / unit[n - 1]) *
                   ((a->shape[n - 2] + unit[n - 2] - 1) / unit[n - 2]);
    return per * (chunk + 1) + (uint64_t)ip_thread_count(0) * (chunk + 64);
}

ip_status ip__zarr_describe(const char *path, const ip_input_overrides *overrides,
                            ip_input_desc *desc, ip_text_found *found, ip_error *err)
{
    zarr_ome o;
    zarr_array a;
    int is_ome;
    uint64_t at[ZARR_MAX_DIMS];
    const ip_input_overrides none = {0};
    const ip_input_overrides *v = overrides ? overrides : &none;
    ip_status s = open_array(path, v->has_scale ? v->scale : 0, &o, &is_ome, &a, err);
    if (s != IP_OK)
        return s;
    if (!is_ome && (v->has_scale || v->has_time || v->has_channel))
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "%s: --scale, --time or --channel was given, but this is a Zarr array, "
                        "not an OME-Zarr image",
                        path);
    if ((s = choose(path, &a, is_ome ? &o : NULL, v->has_time, v->time, v->has_channel, v->channel,
                    at, err)) != IP_OK)
        return s;
    if (v->has_scale && v->scale > 255)
        return ip__fail(err, IP_ERR_UNSUPPORTED, "%s: scales past 255 are not read", path);
    if (v->has_channel && v->channel > 65535)
        return ip__fail(err, IP_ERR_UNSUPPORTED, "%s: channels past 65535 are not read", path);
    uint32_t n = a.ndim;
    for (int axis = 0; axis < 3; axis++)
        found->dims[axis] = a.shape[n - 1 - (uint32_t)axis];
    found->has_dims = found->has_type = 1;
    desc->type = a.type;
    desc->big_endian = !ip__host_little_endian();
    desc->encoding = IP_ENCODING_ZARR;
    snprintf(desc->data_path, sizeof desc->data_path, "%s", a.folder);
    desc->reader_bytes = reader_bytes(&a);
    if (is_ome) {
        for (int axis = 0; axis < 3; axis++) {
            desc->spacing[axis] = o.spacing[axis];
            desc->orientation.origin[axis] = o.origin[axis];
        }
        desc->zarr_scale = (uint8_t)(v->has_scale ? v->scale : 0);
        desc->zarr_scales = (uint8_t)(o.scales > 255 ? 255 : o.scales);
        desc->zarr_time = v->time;
        desc->zarr_channel = (uint16_t)v->channel;
        ip__zarr_unit_symbol(o.unit, desc->space_unit, sizeof desc->space_unit);
    }
    return IP_OK;
}

/* ---- the plane source ---- */

static void zarr_close(void *state)
{
    zarr_state *s = state;
    if (!s)
        return;
    ip__pool_destroy(s->pool);
    pthread_mutex_destroy(&s->lock);
    free(s->slots);
    free(s->present);
    free(s->fill_run);
    free(s);
}

static ip_status zarr_open(const ip_input_desc *desc, void **state, ip_error *err)
{
    zarr_ome o;
    int is_ome;
    zarr_state *s = calloc(1, sizeof *s);
    *state = s;
    if (!s)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", desc->path);
    pthread_mutex_init(&s->lock, NULL);
    s->desc = desc;
    s->row_at = -1;
    ip_status st = open_array(desc->path, desc->zarr_scale, &o, &is_ome, &s->a, err);
    if (st == IP_OK) {
        int t = is_ome && memchr(o.axis, 't', o.ndim), c = is_ome && memchr(o.axis, 'c', o.ndim);
        st = choose(desc->path, &s->a, is_ome ? &o : NULL, t, desc->zarr_time, c,
                    desc->zarr_channel, s->at, err);
    }
    if (st != IP_OK)
        return st;
    s->n = s->a.ndim;
    s->out_size = ip_type_size(desc->type);
    units_of(&s->a, s->unit);
    if (s->a.type != desc->type || s->a.shape[s->n - 1] != desc->dims[0] ||
        s->a.shape[s->n - 2] != desc->dims[1] || s->a.shape[s->n - 3] != desc->dims[2])
        return ip__fail(err, IP_ERR_INPUT, "%s: the array changed since it was described",
                        desc->path);
    uint64_t ux = s->unit[s->n - 1], uy = s->unit[s->n - 2];
    s->per_x = (desc->dims[0] + ux - 1) / ux;
    s->per_y = (desc->dims[1] + uy - 1) / uy;
    if (s->per_x * s->per_y > UINT32_MAX / 2)
        return ip__fail(err, IP_ERR_UNSUPPORTED, "%s: too many chunks in a row", desc->path);
    s->jobs = (unsigned)(s->per_x * s->per_y);
    size_t bytes = (size_t)s->jobs * chunk_bytes(s);
    s->slots = malloc(bytes);
    s->present = calloc(s->jobs, 1);
    s->fill_run = malloc((size_t)ux * s->out_size);
    if (!s->slots || !s->present || !s->fill_run)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory for a row of chunks (%zu bytes)",
                        desc->path, bytes);
    for (uint64_t x = 0; x < ux; x++)
        s->fill_inexact |= put_value(s->a.type, s->a.fill, s->fill_run + x * s->out_size) != 0;
    return ip__pool_create(ip_thread_count(0), &s->pool, err);
}

static ip_status zarr_read_plane(void *state, uint32_t z, void *dst, ip_error *err)
{
    zarr_state *s = state;
    uint64_t row = z / s->unit[s->n - 3];
    if ((int64_t)row != s->row_at) {
        ip_status st = load_row(s, row, err);
        if (st != IP_OK)
            return st;
    }
    return copy_plane(s, z, dst, err);
}

const ip__plane_source ip__zarr_source = {zarr_open, zarr_read_plane, zarr_close};

/* SPDX-License-Identifier: BSD-3-Clause */
/* Trilinear upsampling of an input volume into a larger raw file, streamed plane by plane. */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "atomic_file.h"
#include "internal.h"
#include "isoprop/generate.h"
#include "isoprop/output.h"

/* Output planes are gathered into writes of about this many bytes. */
#define WRITE_GROUP_BYTES ((size_t)16 << 20)
/* The largest output dimension, as for every other volume (see ip_dims_parse). */
#define MAX_DIM ((uint64_t)1 << 31)

/* Where output sample i of an axis reads the input: (1 - weight) * in[index] +
 * weight * in[index + 1]. */
typedef struct axis_table {
    uint32_t *index;
    float *weight;
    uint32_t count;
} axis_table;

/* Everything one upsampling run holds: input planes as floats, the tables and the buffers. */
typedef struct upsampler {
    const ip_input_desc *input;
    uint32_t factor;
    uint32_t in[3], out[3];
    size_t sample_size;
    size_t out_plane_bytes;
    uint32_t group; /* output planes per write */
    axis_table axes[3];
    void *raw;              /* one input plane as read */
    float *lower, *upper;   /* input planes index and index + 1 of the z table */
    uint32_t lower_z;       /* input plane held in `lower` */
    uint32_t planes_read;   /* input planes consumed from the reader */
    float *blend_z;         /* lower and upper blended for one output plane */
    float *rows;            /* blend_z's rows interpolated along x: in[1] x out[0] */
    unsigned char *out_buf; /* `group` output planes */
    ip_input_reader *reader;
    ip_atomic_file file; /* the output: a file written at offsets, or with `stream` (then only
                            its fd and path are set) a stream written in order */
    int stream;
} upsampler;

/* Output sample i of n_out maps to input coordinate i * (n_in - 1) / (n_out - 1), computed
 * exactly in integers so that corners land on corners and factor 1 copies. */
static int axis_table_init(axis_table *t, uint32_t n_in, uint32_t n_out)
{
    t->count = n_out;
    t->index = malloc((size_t)n_out * sizeof *t->index);
    t->weight = malloc((size_t)n_out * sizeof *t->weight);
    if (!t->index || !t->weight)
        return -1;
    uint64_t span_in = n_in - 1, span_out = n_out - 1;
    for (uint32_t i = 0; i < n_out; i++) {
        uint64_t pos = (uint64_t)i * span_in;
        uint64_t whole = pos / span_out, rest = pos % span_out;
        if (whole >= span_in) { /* the last sample: interpolate the last cell at weight 1 */
            whole = span_in - 1;
            rest = span_out;
        }
        t->index[i] = (uint32_t)whole;
        t->weight[i] = (float)((double)rest / (double)span_out);
    }
    return 0;
}

static void axis_table_free(axis_table *t)
{
    free(t->index);
    free(t->weight);
}

static void upsampler_free(upsampler *u)
{
    for (int axis = 0; axis < 3; axis++)
        axis_table_free(&u->axes[axis]);
    free(u->raw);
    free(u->lower);
    free(u->upper);
    free(u->blend_z);
    free(u->rows);
    free(u->out_buf);
    ip_input_close(u->reader);
}

/* Checks the sizes and fills the dims; every size below is then known to fit. */
static ip_status upsampler_size(upsampler *u, const char *path, ip_error *err)
{
    for (int axis = 0; axis < 3; axis++) {
        uint64_t n = (uint64_t)u->input->dims[axis] * u->factor;
        if (u->input->dims[axis] < 2)
            return ip__fail(err, IP_ERR_ARGUMENT, "%s: input dimension %" PRIu32 " is under 2",
                            path, u->input->dims[axis]);
        if (n >= MAX_DIM)
            return ip__fail(err, IP_ERR_ARGUMENT,
                            "%s: %" PRIu32 " x %" PRIu32 " samples is too many along an axis", path,
                            u->input->dims[axis], u->factor);
        u->in[axis] = u->input->dims[axis];
        u->out[axis] = (uint32_t)n;
    }
    u->sample_size = ip_type_size(u->input->type);
    if (u->sample_size == 0)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: unknown input sample type", path);
    uint64_t plane = (uint64_t)u->out[0] * u->out[1] * u->sample_size;
    if (plane > SIZE_MAX / 4 || plane > (uint64_t)INT64_MAX / u->out[2])
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "%s: output of %" PRIu32 "x%" PRIu32 "x%" PRIu32 " samples is too large",
                        path, u->out[0], u->out[1], u->out[2]);
    u->out_plane_bytes = (size_t)plane;
    size_t group = plane >= WRITE_GROUP_BYTES ? 1 : WRITE_GROUP_BYTES / (size_t)plane;
    u->group = group > u->out[2] ? u->out[2] : (uint32_t)group;
    return IP_OK;
}

static ip_status upsampler_alloc(upsampler *u, const char *path, ip_error *err)
{
    size_t in_plane = (size_t)u->in[0] * u->in[1];
    int bad = 0;
    for (int axis = 0; axis < 3; axis++)
        bad |= axis_table_init(&u->axes[axis], u->in[axis], u->out[axis]);
    u->raw = malloc(in_plane * u->sample_size);
    u->lower = malloc(in_plane * sizeof(float));
    u->upper = malloc(in_plane * sizeof(float));
    u->blend_z = malloc(in_plane * sizeof(float));
    u->rows = malloc((size_t)u->in[1] * u->out[0] * sizeof(float));
    u->out_buf = malloc((size_t)u->group * u->out_plane_bytes);
    if (bad || !u->raw || !u->lower || !u->upper || !u->blend_z || !u->rows || !u->out_buf)
        return ip__fail(err, IP_ERR_NOMEM, "%s: cannot allocate the upsampling buffers", path);
    return IP_OK;
}

/* Reads the next input plane into `dst` as floats. */
static ip_status read_plane(upsampler *u, float *dst, ip_error *err)
{
    size_t n = (size_t)u->in[0] * u->in[1];
    ip_status st = ip_input_read_planes(u->reader, u->raw, 1, err);
    if (st != IP_OK)
        return st;
    u->planes_read++;
    switch (u->input->type) {
    case IP_UINT8:
        for (size_t i = 0; i < n; i++)
            dst[i] = (float)((const uint8_t *)u->raw)[i];
        break;
    case IP_UINT16:
        for (size_t i = 0; i < n; i++)
            dst[i] = (float)((const uint16_t *)u->raw)[i];
        break;
    case IP_INT16:
        for (size_t i = 0; i < n; i++)
            dst[i] = (float)((const int16_t *)u->raw)[i];
        break;
    case IP_FLOAT32: memcpy(dst, u->raw, n * sizeof(float)); break;
    }
    return IP_OK;
}

/* Makes `lower` and `upper` hold input planes z and z + 1. The z table never decreases and
 * advances by at most one plane per output plane (factor >= 1): each input plane is read once. */
static ip_status advance_to(upsampler *u, uint32_t z, ip_error *err)
{
    ip_status st = IP_OK;
    if (u->planes_read == 0) {
        st = read_plane(u, u->lower, err);
        if (st == IP_OK)
            st = read_plane(u, u->upper, err);
        u->lower_z = 0;
    }
    while (st == IP_OK && u->lower_z < z) {
        float *t = u->lower;
        u->lower = u->upper;
        u->upper = t;
        u->lower_z++;
        st = read_plane(u, u->upper, err);
    }
    return st;
}

static void blend_planes(const float *a, const float *b, float w, float *dst, size_t n)
{
    float v = 1.0f - w;
    for (size_t i = 0; i < n; i++)
        dst[i] = v * a[i] + w * b[i];
}

/* Interpolates every row of blend_z along x into `rows`. */
static void interpolate_rows(upsampler *u)
{
    const axis_table *tx = &u->axes[0];
    for (uint32_t y = 0; y < u->in[1]; y++) {
        const float *src = u->blend_z + (size_t)y * u->in[0];
        float *dst = u->rows + (size_t)y * u->out[0];
        for (uint32_t i = 0; i < u->out[0]; i++) {
            float w = tx->weight[i];
            const float *p = src + tx->index[i];
            dst[i] = (1.0f - w) * p[0] + w * p[1];
        }
    }
}

/* Stores `n` interpolated values as `type`, rounding integers to nearest; the values are convex
 * combinations of samples, so they are already inside the type's range. The offsets keep the
 * truncating conversion's argument positive, which makes it round to nearest. */
static void store_row(const float *a, const float *b, float w, ip_type type, void *dst, size_t n)
{
    float v = 1.0f - w;
    switch (type) {
    case IP_UINT8:
        for (size_t i = 0; i < n; i++)
            ((uint8_t *)dst)[i] = (uint8_t)(int32_t)(v * a[i] + w * b[i] + 0.5f);
        break;
    case IP_UINT16:
        for (size_t i = 0; i < n; i++)
            ((uint16_t *)dst)[i] = (uint16_t)(int32_t)(v * a[i] + w * b[i] + 0.5f);
        break;
    case IP_INT16:
        for (size_t i = 0; i < n; i++)
            ((int16_t *)dst)[i] = (int16_t)((int32_t)(v * a[i] + w * b[i] + 32768.5f) - 32768);
        break;
    case IP_FLOAT32:
        for (size_t i = 0; i < n; i++)
            ((float *)dst)[i] = v * a[i] + w * b[i];
        break;
    }
}

static void make_plane(upsampler *u, uint32_t z, unsigned char *dst)
{
    const axis_table *ty = &u->axes[1];
    size_t row_bytes = (size_t)u->out[0] * u->sample_size;
    blend_planes(u->lower, u->upper, u->axes[2].weight[z], u->blend_z, (size_t)u->in[0] * u->in[1]);
    interpolate_rows(u);
    for (uint32_t j = 0; j < u->out[1]; j++) {
        const float *r0 = u->rows + (size_t)ty->index[j] * u->out[0];
        store_row(r0, r0 + u->out[0], ty->weight[j], u->input->type, dst + j * row_bytes,
                  u->out[0]);
    }
}

static ip_status write_all_planes(upsampler *u, ip_error *err)
{
    for (uint32_t z = 0; z < u->out[2]; z += u->group) {
        uint32_t count = u->out[2] - z < u->group ? u->out[2] - z : u->group;
        for (uint32_t p = 0; p < count; p++) {
            ip_status st = advance_to(u, u->axes[2].index[z + p], err);
            if (st != IP_OK)
                return st;
            make_plane(u, z + p, u->out_buf + (size_t)p * u->out_plane_bytes);
        }
        size_t bytes = (size_t)count * u->out_plane_bytes;
        if (!ip__host_little_endian())
            ip__swap_bytes(u->out_buf, bytes / u->sample_size, u->sample_size);
        ip_status st = ip__write_at(u->file.fd, u->stream, u->out_buf, bytes,
                                    (uint64_t)z * u->out_plane_bytes, u->file.path, err);
        if (st != IP_OK)
            return st;
    }
    return IP_OK;
}

/* The upsampled volume into the file at `path` (fd < 0), or in order into the stream fd, `path`
 * its name. */
static ip_status upsample_into(const ip_input_desc *input, uint32_t factor, const char *path,
                               int force, int fd, ip_error *err)
{
    upsampler u;
    memset(&u, 0, sizeof u);
    u.file.fd = -1;
    if (!input || !path)
        return ip__fail(err, IP_ERR_ARGUMENT, "upsample: no input or no output path");
    if (factor < 1)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: upsampling factor must be at least 1", path);
    u.input = input;
    u.factor = factor;
    u.stream = fd >= 0;
    /* the output replaces nothing it reads (with force it would otherwise replace the input) */
    ip_status st = u.stream ? IP_OK : ip_output_not_input(path, input->path, err);
    if (st == IP_OK && !u.stream && strcmp(input->data_path, input->path) != 0)
        st = ip_output_not_input(path, input->data_path, err);
    if (st != IP_OK)
        return st;
    st = upsampler_size(&u, path, err);
    if (st == IP_OK)
        st = upsampler_alloc(&u, path, err);
    if (st == IP_OK && u.stream) {
        u.file.fd = fd;
        snprintf(u.file.path, sizeof u.file.path, "%s", path);
        if ((st = ip_input_open(input, &u.reader, err)) == IP_OK)
            st = write_all_planes(&u, err);
        upsampler_free(&u);
        return st;
    }
    if (st == IP_OK)
        st = ip__atomic_create(&u.file, path, force, err);
    if (st == IP_OK)
        st = ip_input_open(input, &u.reader, err);
    if (st == IP_OK)
        st = write_all_planes(&u, err);
    if (st == IP_OK)
        st = ip__atomic_commit(&u.file, err);
    else
        ip__atomic_abort(&u.file);
    upsampler_free(&u);
    return st;
}

ip_status ip_upsample_write(const ip_input_desc *input, uint32_t factor, const char *path,
                            int force, ip_error *err)
{
    return upsample_into(input, factor, path, force, -1, err);
}

ip_status ip_upsample_write_fd(const ip_input_desc *input, uint32_t factor, int fd,
                               const char *name, ip_error *err)
{
    if (fd < 0)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: no file descriptor", name ? name : "upsample");
    return upsample_into(input, factor, name, 0, fd, err);
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* Synthetic volumes: the Shepp-Logan phantom and test fields, deterministic noise, raw output. */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "atomic_file.h"
#include "internal.h"
#include "isoprop/generate.h"
#include "pool.h"
#include "sized.h"

#define GEN_PI 3.14159265358979323846
/* Whole gyroid periods across each axis's [-1, 1] span. */
#define GYROID_PERIODS 4.0
/* Marschner-Lobb parameters from their 1994 paper. */
#define ML_FM 6.0
#define ML_ALPHA 0.25
/* Planes are generated in groups of about this many bytes and written with one pwrite. */
#define WRITE_GROUP_BYTES ((size_t)16 << 20)
#define MAX_GEN_THREADS 8
/* Samples along x whose coordinates are prepared together. */
#define X_CHUNK 256
#define FIELD_COUNT 4

/* One ellipsoid of the 3D phantom, rotated by `angle_deg` about the z axis (counter-clockwise,
 * from +x towards +y) around its own centre. */
typedef struct ellipsoid {
    double x0, y0, z0;
    double a, b, c;
    double angle_deg;
    double density;
} ellipsoid;

/* Geometry from Kak & Slaney, "Principles of Computerized Tomographic Imaging" (1988), p. 102
 * (their 3D table, angles in degrees); the contrast-enhanced densities of Yu, Ye & Wang (2004)
 * for the same ellipsoids, with the same signs as Kak & Slaney's, so that the brain's
 * structures differ by 10-20 % of the range instead of 0.5-1 %. Sums lie in [0, 1]: air 0,
 * brain 0.2, the ventricles and ellipsoid 10 0, the other structures 0.3-0.6, skull 1. */
static const ellipsoid shepp_logan_ellipsoids[10] = {
    {0.00, 0.000, 0.000, 0.6900, 0.920, 0.900, 0.0, 1.0},
    {0.00, 0.000, 0.000, 0.6624, 0.874, 0.880, 0.0, -0.8},
    {-0.22, 0.000, -0.250, 0.4100, 0.160, 0.210, 108.0, -0.2},
    {0.22, 0.000, -0.250, 0.3100, 0.110, 0.220, 72.0, -0.2},
    {0.00, 0.350, -0.250, 0.2100, 0.250, 0.500, 0.0, 0.2},
    {0.00, 0.100, -0.250, 0.0460, 0.046, 0.046, 0.0, 0.2},
    {-0.08, -0.650, -0.250, 0.0460, 0.023, 0.020, 0.0, 0.1},
    {0.06, -0.650, -0.250, 0.0460, 0.023, 0.020, 90.0, 0.1},
    {0.06, -0.105, 0.625, 0.0560, 0.040, 0.100, 90.0, 0.2},
    {0.00, 0.100, 0.625, 0.0560, 0.056, 0.100, 0.0, -0.2},
};

#define ELLIPSOID_COUNT (sizeof shepp_logan_ellipsoids / sizeof shepp_logan_ellipsoids[0])

/* An ellipsoid prepared for one z-plane: only those the plane cuts are kept. */
typedef struct plane_ellipsoid {
    double x0, y0;
    double cos_t, sin_t;
    double inv_a2, inv_b2;
    double z_term; /* ((z - z0) / c)^2 */
    double reach;  /* max(a, b): rows farther than this from y0 miss the ellipsoid */
    double density;
} plane_ellipsoid;

/* The phantom is averaged over PARTIAL^3 points spread across each voxel, as a scanner
 * integrates over its voxels: edges get the intermediate (partial-volume) values of a real
 * CT, and isosurfaces between two tissues are smooth instead of voxel staircases. */
#define PARTIAL 3

/* Everything a plane's samples share. */
typedef struct plane_context {
    const ip_gen_params *params;
    uint32_t z_index;
    double z;
    double half_voxel[3]; /* half a voxel along each axis, normalised units */
    plane_ellipsoid ellipsoids[PARTIAL][ELLIPSOID_COUNT]; /* per sub-plane in z */
    size_t ellipsoid_count[PARTIAL];
    double gyroid_sin_z, gyroid_cos_z;
    double ml_z_term; /* 1 - sin(pi z / 2) */
} plane_context;

/* A normalised x or y coordinate, with the gyroid's sine and cosine of it when needed. */
typedef struct axis_point {
    double t;
    double sin_k, cos_k;
} axis_point;

static const char *const field_names[FIELD_COUNT] = {"shepp-logan", "sphere", "gyroid",
                                                     "marschner-lobb"};

const char *ip_field_name(ip_field field)
{
    if ((unsigned)field >= FIELD_COUNT)
        return "unknown";
    return field_names[field];
}

ip_status ip_field_parse(const char *name, ip_field *out)
{
    if (!name || !out)
        return IP_ERR_ARGUMENT;
    for (int i = 0; i < FIELD_COUNT; i++) {
        if (strcmp(name, field_names[i]) == 0) {
            *out = (ip_field)i;
            return IP_OK;
        }
    }
    return IP_ERR_ARGUMENT;
}

ip_status ip_raw_file_name(char *buf, size_t size, const char *name, const uint32_t dims[3],
                           ip_type type)
{
    if (!buf || size == 0 || !name || !dims || ip_type_size(type) == 0)
        return IP_ERR_ARGUMENT;
    int n = snprintf(buf, size, "%s_%" PRIu32 "x%" PRIu32 "x%" PRIu32 "_%s.raw", name, dims[0],
                     dims[1], dims[2], ip_type_name(type));
    if (n < 0 || (size_t)n >= size) {
        buf[0] = '\0';
        return IP_ERR_ARGUMENT;
    }
    return IP_OK;
}

/* Sample index i of n mapped to [-1, 1]. */
static double normalised(uint32_t i, uint32_t n)
{
    return -1.0 + 2.0 * (double)i / (double)(n - 1);
}

/* Offset of sub-point j (0 .. PARTIAL-1) from a voxel's centre, in half voxels. */
static double partial_offset(int j)
{
    return (2.0 * j + 1.0) / PARTIAL - 1.0;
}

static void prepare_shepp_logan(plane_context *pc)
{
    for (int s = 0; s < PARTIAL; s++) {
        double z = pc->z + partial_offset(s) * pc->half_voxel[2];
        pc->ellipsoid_count[s] = 0;
        for (size_t i = 0; i < ELLIPSOID_COUNT; i++) {
            const ellipsoid *e = &shepp_logan_ellipsoids[i];
            double dz = (z - e->z0) / e->c;
            if (dz * dz > 1.0)
                continue;
            plane_ellipsoid *p = &pc->ellipsoids[s][pc->ellipsoid_count[s]++];
            double angle = e->angle_deg * GEN_PI / 180.0;
            p->x0 = e->x0;
            p->y0 = e->y0;
            p->cos_t = cos(angle);
            p->sin_t = sin(angle);
            p->inv_a2 = 1.0 / (e->a * e->a);
            p->inv_b2 = 1.0 / (e->b * e->b);
            p->z_term = dz * dz;
            p->reach = e->a > e->b ? e->a : e->b;
            p->density = e->density;
        }
    }
}

static void prepare_plane(plane_context *pc, const ip_gen_params *params, uint32_t z)
{
    memset(pc, 0, sizeof *pc);
    pc->params = params;
    pc->z_index = z;
    pc->z = normalised(z, params->dims[2]);
    for (int a = 0; a < 3; a++)
        pc->half_voxel[a] = 1.0 / (double)(params->dims[a] - 1);
    if (params->field == IP_FIELD_SHEPP_LOGAN)
        prepare_shepp_logan(pc);
    double k = GYROID_PERIODS * GEN_PI;
    pc->gyroid_sin_z = sin(k * pc->z);
    pc->gyroid_cos_z = cos(k * pc->z);
    pc->ml_z_term = 1.0 - sin(GEN_PI * pc->z / 2.0);
}

static void axis_point_at(axis_point *p, const plane_context *pc, uint32_t i, uint32_t n)
{
    double k = GYROID_PERIODS * GEN_PI;
    p->t = normalised(i, n);
    p->sin_k = pc->params->field == IP_FIELD_GYROID ? sin(k * p->t) : 0.0;
    p->cos_k = pc->params->field == IP_FIELD_GYROID ? cos(k * p->t) : 0.0;
}

/* Sum of the densities of the ellipsoids of sub-plane `s` that contain (x, y); 0 outside. */
static double shepp_logan_point(const plane_context *pc, int s, double x, double y)
{
    double sum = 0.0;
    for (size_t i = 0; i < pc->ellipsoid_count[s]; i++) {
        const plane_ellipsoid *e = &pc->ellipsoids[s][i];
        double dx = x - e->x0, dy = y - e->y0;
        if (fabs(dy) > e->reach)
            continue;
        double u = dx * e->cos_t + dy * e->sin_t;
        double w = dy * e->cos_t - dx * e->sin_t;
        if (u * u * e->inv_a2 + w * w * e->inv_b2 + e->z_term <= 1.0)
            sum += e->density;
    }
    return sum;
}

/* The phantom averaged over the voxel around (x, y, z): PARTIAL^3 points. */
static double shepp_logan_value(const plane_context *pc, double x, double y)
{
    double sum = 0.0;
    for (int s = 0; s < PARTIAL; s++)
        for (int j = 0; j < PARTIAL; j++)
            for (int i = 0; i < PARTIAL; i++)
                sum += shepp_logan_point(pc, s, x + partial_offset(i) * pc->half_voxel[0],
                                         y + partial_offset(j) * pc->half_voxel[1]);
    return sum / (PARTIAL * PARTIAL * PARTIAL);
}

static double sphere_value(const plane_context *pc, double x, double y)
{
    return 1.0 - sqrt(x * x + y * y + pc->z * pc->z);
}

/* sin kx cos ky + sin ky cos kz + sin kz cos kx lies in [-1.5, 1.5]. */
static double gyroid_value(const plane_context *pc, const axis_point *x, const axis_point *y)
{
    double g = x->sin_k * y->cos_k + y->sin_k * pc->gyroid_cos_z + pc->gyroid_sin_z * x->cos_k;
    return 0.5 + g / 3.0;
}

static double marschner_lobb_value(const plane_context *pc, double x, double y)
{
    double r = sqrt(x * x + y * y);
    double rho_r = cos(2.0 * GEN_PI * ML_FM * cos(GEN_PI * r / 2.0));
    return (pc->ml_z_term + ML_ALPHA * (1.0 + rho_r)) / (2.0 * (1.0 + ML_ALPHA));
}

static double field_value(const plane_context *pc, const axis_point *x, const axis_point *y)
{
    switch (pc->params->field) {
    case IP_FIELD_SHEPP_LOGAN: return shepp_logan_value(pc, x->t, y->t);
    case IP_FIELD_SPHERE: return sphere_value(pc, x->t, y->t);
    case IP_FIELD_GYROID: return gyroid_value(pc, x, y);
    case IP_FIELD_MARSCHNER_LOBB: return marschner_lobb_value(pc, x->t, y->t);
    }
    return 0.0;
}

/* The splitmix64 finaliser: a bijective 64-bit mix. */
static uint64_t mix64(uint64_t v)
{
    v ^= v >> 30;
    v *= 0xbf58476d1ce4e5b9ull;
    v ^= v >> 27;
    v *= 0x94d049bb133111ebull;
    v ^= v >> 31;
    return v;
}

/* A standard normal deviate that depends only on (seed, index): one hash gives the two
 * uniforms of a Box-Muller transform, so samples can be generated in any order. */
static double gaussian(uint64_t seed, uint64_t index)
{
    uint64_t h = mix64(mix64(seed ^ 0x5851f42d4c957f2dull) + index * 0x9e3779b97f4a7c15ull);
    double u1 = ((double)(h >> 32) + 1.0) / 4294967296.0; /* (0, 1] */
    double u2 = (double)(h & 0xffffffffu) / 4294967296.0; /* [0, 1) */
    return sqrt(-2.0 * log(u1)) * cos(2.0 * GEN_PI * u2);
}

static void store_sample(void *dst, size_t i, ip_type type, double v)
{
    switch (type) {
    case IP_UINT8: ((uint8_t *)dst)[i] = (uint8_t)floor(v * 255.0 + 0.5); break;
    case IP_UINT16: ((uint16_t *)dst)[i] = (uint16_t)floor(v * 4095.0 + 0.5); break;
    case IP_INT16: ((int16_t *)dst)[i] = (int16_t)(floor(v * 4095.0 + 0.5) - 1024.0); break;
    case IP_FLOAT32: ((float *)dst)[i] = (float)v; break;
    }
}

/* Takes the caller's params (a sized struct, status.h) into *params and validates them;
 * messages start with `what` (the output path, or "generate"). */
static ip_status take_params(const ip_gen_params *given, ip_gen_params *params, const char *what,
                             ip_error *err)
{
    if (!given)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: no parameters", what);
    memset(params, 0, sizeof *params);
    ip_status st =
        ip__sized_in(params, sizeof *params, given, IP__SIZE_UPTO(ip_gen_params, seed), what, err);
    if (st != IP_OK)
        return st;
    if ((unsigned)params->field >= FIELD_COUNT)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: unknown field %d", what, (int)params->field);
    if (ip_type_size(params->type) == 0)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: unknown sample type %d", what,
                        (int)params->type);
    for (int axis = 0; axis < 3; axis++) {
        if (params->dims[axis] < 2)
            return ip__fail(err, IP_ERR_ARGUMENT,
                            "%s: dimensions %" PRIu32 "x%" PRIu32 "x%" PRIu32
                            " must each be at least 2",
                            what, params->dims[0], params->dims[1], params->dims[2]);
    }
    if (!(params->noise >= 0.0) || !isfinite(params->noise))
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: noise %g must be finite and >= 0", what,
                        params->noise);
    return IP_OK;
}

/* Fills samples x0 .. x0 + count - 1 of rows y_first .. y_end - 1 of the plane at dst. */
static void generate_columns(const plane_context *pc, uint32_t x0, uint32_t count, uint32_t y_first,
                             uint32_t y_end, void *dst)
{
    const ip_gen_params *params = pc->params;
    uint32_t nx = params->dims[0], ny = params->dims[1];
    uint64_t plane_first = (uint64_t)pc->z_index * nx * ny;
    axis_point xs[X_CHUNK], y;
    for (uint32_t k = 0; k < count; k++)
        axis_point_at(&xs[k], pc, x0 + k, nx);
    for (uint32_t iy = y_first; iy < y_end; iy++) {
        axis_point_at(&y, pc, iy, ny);
        size_t i = (size_t)iy * nx + x0;
        for (uint32_t k = 0; k < count; k++, i++) {
            double v = field_value(pc, &xs[k], &y);
            if (params->noise > 0.0)
                v += params->noise * gaussian(params->seed, plane_first + i);
            v = v < 0.0 ? 0.0 : v > 1.0 ? 1.0 : v;
            store_sample(dst, i, params->type, v);
        }
    }
}

/* Fills rows y_first .. y_end - 1 of plane z into the plane at dst. */
static void generate_rows(const ip_gen_params *params, uint32_t z, uint32_t y_first, uint32_t y_end,
                          void *dst)
{
    plane_context pc;
    prepare_plane(&pc, params, z);
    for (uint32_t x0 = 0; x0 < params->dims[0]; x0 += X_CHUNK) {
        uint32_t left = params->dims[0] - x0;
        generate_columns(&pc, x0, left < X_CHUNK ? left : X_CHUNK, y_first, y_end, dst);
    }
}

ip_status ip_generate_plane(const ip_gen_params *given, uint32_t z, void *dst, ip_error *err)
{
    ip_gen_params taken;
    const ip_gen_params *params = &taken;
    ip_status st = take_params(given, &taken, "generate", err);
    if (st != IP_OK)
        return st;
    if (z >= params->dims[2])
        return ip__fail(err, IP_ERR_ARGUMENT, "generate: plane %" PRIu32 " is outside 0..%" PRIu32,
                        z, params->dims[2] - 1);
    if (!dst)
        return ip__fail(err, IP_ERR_ARGUMENT, "generate: no destination buffer");
    generate_rows(params, z, 0, params->dims[1], dst);
    return IP_OK;
}

/* A group of planes, generated by `workers` jobs: the group's rows, counted across its planes,
 * are cut into `workers` contiguous runs, so even a one-plane group keeps every thread busy. */
typedef struct plane_group {
    const ip_gen_params *params;
    unsigned char *buf;
    size_t plane_bytes;
    uint32_t first, count;
    unsigned workers;
} plane_group;

/* Job `worker` of a group (on the pool): its run of rows. */
static void run_plane_job(void *user, unsigned worker)
{
    const plane_group *job = user;
    uint64_t ny = job->params->dims[1], rows = job->count * ny;
    uint64_t row = rows * worker / job->workers;
    uint64_t end = rows * (worker + 1) / job->workers;
    while (row < end) {
        uint32_t p = (uint32_t)(row / ny), y = (uint32_t)(row % ny);
        uint32_t y_end = end - row < ny - y ? (uint32_t)(y + (end - row)) : (uint32_t)ny;
        generate_rows(job->params, job->first + p, y, y_end,
                      job->buf + (size_t)p * job->plane_bytes);
        row += y_end - y;
    }
}

static unsigned worker_count(void)
{
    unsigned n = ip_thread_count(0);
    return n > MAX_GEN_THREADS ? MAX_GEN_THREADS : n;
}

/* Generates `count` planes from `first` into buf on the pool's threads. The bytes never depend
 * on the split, because every sample is a pure function of its position. */
static void generate_group(const ip_gen_params *params, uint32_t first, uint32_t count,
                           unsigned char *buf, size_t plane_bytes, ip__pool *pool)
{
    plane_group group = {params, buf, plane_bytes, first, count, ip__pool_threads(pool)};
    if ((uint64_t)group.workers > (uint64_t)count * params->dims[1])
        group.workers = count * params->dims[1];
    ip__pool_run(pool, group.workers, run_plane_job, &group);
}

/* Bytes of one plane, refusing volumes whose size a file offset cannot hold. */
static ip_status plane_size(const uint32_t dims[3], ip_type type, const char *path,
                            size_t *plane_bytes, ip_error *err)
{
    uint64_t plane = (uint64_t)dims[0] * dims[1] * ip_type_size(type);
    if (plane / ip_type_size(type) / dims[0] != dims[1] || plane > SIZE_MAX / 2 ||
        plane > (uint64_t)INT64_MAX / dims[2])
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "%s: a %" PRIu32 "x%" PRIu32 "x%" PRIu32 " %s volume is too large", path,
                        dims[0], dims[1], dims[2], ip_type_name(type));
    *plane_bytes = (size_t)plane;
    return IP_OK;
}

/* Where the planes go: a file written at offsets, or a stream (standard output) in order. */
typedef struct plane_sink {
    int fd, stream;
    const char *name;
} plane_sink;

static ip_status write_planes(const ip_gen_params *params, const plane_sink *out,
                              unsigned char *buf, size_t plane_bytes, uint32_t group, ip_error *err)
{
    size_t size = ip_type_size(params->type);
    ip__pool *pool;
    if (ip__pool_create(worker_count(), &pool, NULL) != IP_OK)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", out->name);
    ip_status st = IP_OK;
    for (uint32_t z = 0; st == IP_OK && z < params->dims[2]; z += group) {
        uint32_t count = params->dims[2] - z < group ? params->dims[2] - z : group;
        generate_group(params, z, count, buf, plane_bytes, pool);
        if (!ip__host_little_endian())
            ip__swap_bytes(buf, (size_t)count * plane_bytes / size, size);
        st = ip__write_at(out->fd, out->stream, buf, (size_t)count * plane_bytes,
                          (uint64_t)z * plane_bytes, out->name, err);
    }
    ip__pool_destroy(pool);
    return st;
}

/* The volume into the file at `path` (fd < 0), or in order into the stream fd, `path` its name. */
static ip_status generate_into(const ip_gen_params *given, const char *path, int force, int fd,
                               ip_error *err)
{
    size_t plane_bytes = 0;
    ip_atomic_file out;
    ip_gen_params taken;
    const ip_gen_params *params = &taken;
    plane_sink sink = {fd, fd >= 0, path};
    if (!path)
        return ip__fail(err, IP_ERR_ARGUMENT, "generate: no output path");
    ip_status st = take_params(given, &taken, path, err);
    if (st != IP_OK)
        return st;
    st = plane_size(params->dims, params->type, path, &plane_bytes, err);
    if (st != IP_OK)
        return st;
    size_t group = plane_bytes >= WRITE_GROUP_BYTES ? 1 : WRITE_GROUP_BYTES / plane_bytes;
    if (group > params->dims[2])
        group = params->dims[2];
    unsigned char *buf = malloc(group * plane_bytes);
    if (!buf)
        return ip__fail(err, IP_ERR_NOMEM, "%s: cannot allocate %zu bytes for %zu planes", path,
                        group * plane_bytes, group);
    if (sink.stream) {
        st = write_planes(params, &sink, buf, plane_bytes, (uint32_t)group, err);
        free(buf);
        return st;
    }
    st = ip__atomic_create(&out, path, force, err);
    sink.fd = out.fd;
    if (st == IP_OK)
        st = write_planes(params, &sink, buf, plane_bytes, (uint32_t)group, err);
    if (st == IP_OK)
        st = ip__atomic_commit(&out, err);
    else
        ip__atomic_abort(&out);
    free(buf);
    return st;
}

ip_status ip_generate_write(const ip_gen_params *params, const char *path, int force, ip_error *err)
{
    return generate_into(params, path, force, -1, err);
}

ip_status ip_generate_write_fd(const ip_gen_params *params, int fd, const char *name, ip_error *err)
{
    if (fd < 0)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: no file descriptor", name ? name : "generate");
    return generate_into(params, name, 0, fd, err);
}

/* Triangle soups to files: binary PLY, binary STL, Wavefront OBJ, chosen by extension. Every
 * file is written all-or-nothing (atomic_file.h). */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "atomic_file.h"
#include "internal.h"
#include "isoprop/mesh.h"

#define BUFFER_BYTES (1u << 20) /* written in pieces of this size */

/* A file being written through a buffer; the first failure sticks in st. */
typedef struct writer {
    ip_atomic_file out;
    unsigned char *buf;
    size_t used;
    uint64_t offset;
    const char *path;
    ip_error *err;
    ip_status st;
} writer;

static ip_status writer_open(writer *w, const char *path, int force, ip_error *err)
{
    memset(w, 0, sizeof *w);
    w->path = path;
    w->err = err;
    w->st = ip__atomic_create(&w->out, path, force, err);
    if (w->st != IP_OK)
        return w->st;
    w->buf = malloc(BUFFER_BYTES);
    if (!w->buf) {
        ip__atomic_abort(&w->out);
        w->st = ip__fail(err, IP_ERR_NOMEM, "%s: out of memory", path);
    }
    return w->st;
}

static void writer_flush(writer *w)
{
    if (w->st == IP_OK && w->used > 0)
        w->st = ip__pwrite_all(w->out.fd, w->buf, w->used, w->offset, w->path, w->err);
    w->offset += w->used;
    w->used = 0;
}

/* Room for `bytes` (at most BUFFER_BYTES) at the end of the buffer; NULL after a failure. */
static unsigned char *writer_room(writer *w, size_t bytes)
{
    if (w->used + bytes > BUFFER_BYTES)
        writer_flush(w);
    return w->st == IP_OK ? w->buf + w->used : NULL;
}

/* Commits the file, or removes it after a failure; returns the status. */
static ip_status writer_close(writer *w)
{
    writer_flush(w);
    free(w->buf);
    if (w->st == IP_OK)
        return ip__atomic_commit(&w->out, w->err);
    ip__atomic_abort(&w->out);
    return w->st;
}

/* Appends printf-formatted text (a line of at most 255 bytes). */
static void put_text(writer *w, const char *format, ...) __attribute__((format(printf, 2, 3)));
static void put_text(writer *w, const char *format, ...)
{
    unsigned char *p = writer_room(w, 256);
    if (!p)
        return;
    va_list args;
    va_start(args, format);
    int n = vsnprintf((char *)p, 256, format, args);
    va_end(args);
    IP_ASSERT(n >= 0 && n < 256); /* the formats above are bounded */
    w->used += (size_t)n;
}

ip_status ip_mesh_write_ply(const ip_mesh *m, const char *path, int force, ip_error *err)
{
    writer w;
    if (writer_open(&w, path, force, err) != IP_OK)
        return w.st;
    put_text(&w,
             "ply\nformat binary_little_endian 1.0\ncomment isoprop isosurface\n"
             "element vertex %llu\nproperty float x\nproperty float y\nproperty float z\n",
             (unsigned long long)(3 * m->triangle_count));
    put_text(&w,
             "property float nx\nproperty float ny\nproperty float nz\n"
             "element face %llu\nproperty list uchar int vertex_indices\nend_header\n",
             (unsigned long long)m->triangle_count);
    for (uint64_t i = 0; i < 3 * m->triangle_count; i++) {
        unsigned char *p = writer_room(&w, 24);
        if (!p)
            break;
        for (int k = 0; k < 3; k++) {
            ip__store_f32le(p + 4 * k, m->positions[3 * i + k]);
            ip__store_f32le(p + 12 + 4 * k, ip_normal_unpack(m->normals[3 * i + k]));
        }
        w.used += 24;
    }
    for (uint64_t t = 0; t < m->triangle_count; t++) {
        unsigned char *p = writer_room(&w, 13);
        if (!p)
            break;
        p[0] = 3;
        for (int k = 0; k < 3; k++)
            ip__store_u32le(p + 1 + 4 * k, (uint32_t)(3 * t + (uint64_t)k));
        w.used += 13;
    }
    return writer_close(&w);
}

/* The unit normal of triangle t from its corners (counter-clockwise seen from where it points);
 * zero for a degenerate triangle. */
static void face_normal(const ip_mesh *m, uint64_t t, float n[3])
{
    const float *a = m->positions + 9 * t, *b = a + 3, *c = a + 6;
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double x[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    double length = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    for (int k = 0; k < 3; k++)
        n[k] = length > 0 ? (float)(x[k] / length) : 0.0f;
}

ip_status ip_mesh_write_stl(const ip_mesh *m, const char *path, int force, ip_error *err)
{
    if (m->triangle_count > UINT32_MAX)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "%s: %llu triangles are more than binary STL can hold (2^32 - 1)", path,
                        (unsigned long long)m->triangle_count);
    writer w;
    if (writer_open(&w, path, force, err) != IP_OK)
        return w.st;
    unsigned char *p = writer_room(&w, 84);
    if (p) { /* a header that does not start with "solid", which would read as ASCII STL */
        memset(p, 0, 84);
        memcpy(p, "isoprop isosurface, binary STL", 30);
        ip__store_u32le(p + 80, (uint32_t)m->triangle_count);
        w.used += 84;
    }
    for (uint64_t t = 0; t < m->triangle_count; t++) {
        if (!(p = writer_room(&w, 50)))
            break;
        float n[3];
        face_normal(m, t, n);
        for (int k = 0; k < 3; k++)
            ip__store_f32le(p + 4 * k, n[k]);
        for (int k = 0; k < 9; k++)
            ip__store_f32le(p + 12 + 4 * k, m->positions[9 * t + k]);
        p[48] = p[49] = 0; /* attribute byte count */
        w.used += 50;
    }
    return writer_close(&w);
}

ip_status ip_mesh_write_obj(const ip_mesh *m, const char *path, int force, ip_error *err)
{
    writer w;
    if (writer_open(&w, path, force, err) != IP_OK)
        return w.st;
    put_text(&w, "# isoprop isosurface: %llu triangles, 3 vertices each, with normals\n",
             (unsigned long long)m->triangle_count);
    for (uint64_t i = 0; i < 3 * m->triangle_count; i++) {
        const float *p = m->positions + 3 * i;
        const int16_t *n = m->normals + 3 * i;
        put_text(&w, "v %.9g %.9g %.9g\n", (double)p[0], (double)p[1], (double)p[2]);
        put_text(&w, "vn %.6g %.6g %.6g\n", (double)ip_normal_unpack(n[0]),
                 (double)ip_normal_unpack(n[1]), (double)ip_normal_unpack(n[2]));
    }
    for (uint64_t t = 0; t < m->triangle_count; t++) {
        unsigned long long a = 3 * t + 1; /* OBJ counts from 1 */
        put_text(&w, "f %llu//%llu %llu//%llu %llu//%llu\n", a, a, a + 1, a + 1, a + 2, a + 2);
    }
    return writer_close(&w);
}

/* Whether `path` ends in `extension` (".ply"), ignoring case. */
static int has_extension(const char *path, const char *extension)
{
    size_t n = strlen(path), e = strlen(extension);
    return n > e && strcasecmp(path + n - e, extension) == 0;
}

const char *ip_mesh_format_of(const char *path)
{
    static const char *const formats[][2] = {{".ply", "PLY"}, {".stl", "STL"}, {".obj", "OBJ"}};
    for (size_t i = 0; i < sizeof formats / sizeof formats[0]; i++)
        if (has_extension(path, formats[i][0]))
            return formats[i][1];
    return NULL;
}

ip_status ip_mesh_write(const ip_mesh *m, const char *path, int force, ip_error *err)
{
    const char *format = ip_mesh_format_of(path);
    if (!format)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "%s: unknown mesh format (the name must end in .ply, .stl or .obj)", path);
    if (strcmp(format, "STL") == 0)
        return ip_mesh_write_stl(m, path, force, err);
    if (strcmp(format, "OBJ") == 0)
        return ip_mesh_write_obj(m, path, force, err);
    return ip_mesh_write_ply(m, path, force, err);
}

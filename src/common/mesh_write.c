/* SPDX-License-Identifier: BSD-3-Clause */
/* Meshes to files: binary PLY, binary STL, Wavefront OBJ and binary glTF, chosen by extension,
 * from a triangle soup or an indexed mesh alike (a soup is written as the indexed mesh whose
 * triangle t has vertices 3t, 3t + 1, 3t + 2). Every file is written all-or-nothing
 * (atomic_file.h). */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "atomic_file.h"
#include "internal.h"
#include "isoprop/mesh.h"
#include "isoprop/version.h"

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

/* A mesh as the writers see it: vertices, and triangles of indices into them. */
typedef struct mesh_view {
    const float *positions;  /* 3 per vertex */
    const int16_t *normals;  /* 3 per vertex, packed */
    const uint32_t *indices; /* 3 per triangle; NULL: triangle t is 3t, 3t + 1, 3t + 2 */
    uint64_t vertex_count, triangle_count;
    const char *space; /* named in the file; NULL: none */
} mesh_view;

static mesh_view soup_view(const ip_mesh *m)
{
    return (mesh_view){m->positions,          m->normals,        NULL,
                       3 * m->triangle_count, m->triangle_count, NULL};
}

static mesh_view indexed_view(const ip_indexed_mesh *m)
{
    return (mesh_view){m->positions,    m->normals,        m->indices,
                       m->vertex_count, m->triangle_count, NULL};
}

/* Vertex k (0..2) of triangle t. */
static uint64_t corner(const mesh_view *v, uint64_t t, int k)
{
    return v->indices ? v->indices[3 * t + (uint64_t)k] : 3 * t + (uint64_t)k;
}

static ip_status write_ply(const mesh_view *m, const char *path, int force, ip_error *err)
{
    if (m->vertex_count > (uint64_t)INT32_MAX + 1)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "%s: %llu vertices are more than PLY's int indices can count (2^31)", path,
                        (unsigned long long)m->vertex_count);
    writer w;
    if (writer_open(&w, path, force, err) != IP_OK)
        return w.st;
    put_text(&w, "ply\nformat binary_little_endian 1.0\ncomment isoprop isosurface\n");
    if (m->space)
        put_text(&w, "comment space %s\n", m->space);
    put_text(&w, "element vertex %llu\nproperty float x\nproperty float y\nproperty float z\n",
             (unsigned long long)m->vertex_count);
    put_text(&w,
             "property float nx\nproperty float ny\nproperty float nz\n"
             "element face %llu\nproperty list uchar int vertex_indices\nend_header\n",
             (unsigned long long)m->triangle_count);
    for (uint64_t i = 0; i < m->vertex_count; i++) {
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
            ip__store_u32le(p + 1 + 4 * k, (uint32_t)corner(m, t, k));
        w.used += 13;
    }
    return writer_close(&w);
}

ip_status ip_mesh_write_ply(const ip_mesh *m, const char *path, int force, ip_error *err)
{
    mesh_view v = soup_view(m);
    return write_ply(&v, path, force, err);
}

/* The unit normal of triangle t from its corners (counter-clockwise seen from where it points);
 * zero for a degenerate triangle. */
static void face_normal(const mesh_view *m, uint64_t t, float n[3])
{
    const float *a = m->positions + 3 * corner(m, t, 0), *b = m->positions + 3 * corner(m, t, 1),
                *c = m->positions + 3 * corner(m, t, 2);
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double x[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    double length = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    for (int k = 0; k < 3; k++)
        n[k] = length > 0 ? (float)(x[k] / length) : 0.0f;
}

static ip_status write_stl(const mesh_view *m, const char *path, int force, ip_error *err)
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
        snprintf((char *)p, 80, "isoprop isosurface, binary STL%s%s", m->space ? ", space " : "",
                 m->space ? m->space : ""); /* at most 30 + 8 + IP_MESH_SPACE_MAX bytes */
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
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++)
                ip__store_f32le(p + 12 + 12 * k + 4 * a, m->positions[3 * corner(m, t, k) + a]);
        p[48] = p[49] = 0; /* attribute byte count */
        w.used += 50;
    }
    return writer_close(&w);
}

ip_status ip_mesh_write_stl(const ip_mesh *m, const char *path, int force, ip_error *err)
{
    mesh_view v = soup_view(m);
    return write_stl(&v, path, force, err);
}

static ip_status write_obj(const mesh_view *m, const char *path, int force, ip_error *err)
{
    writer w;
    if (writer_open(&w, path, force, err) != IP_OK)
        return w.st;
    put_text(&w, "# isoprop isosurface: %llu triangles, %llu vertices with normals\n",
             (unsigned long long)m->triangle_count, (unsigned long long)m->vertex_count);
    if (m->space)
        put_text(&w, "# space %s\n", m->space);
    for (uint64_t i = 0; i < m->vertex_count; i++) {
        const float *p = m->positions + 3 * i;
        const int16_t *n = m->normals + 3 * i;
        put_text(&w, "v %.9g %.9g %.9g\n", (double)p[0], (double)p[1], (double)p[2]);
        put_text(&w, "vn %.6g %.6g %.6g\n", (double)ip_normal_unpack(n[0]),
                 (double)ip_normal_unpack(n[1]), (double)ip_normal_unpack(n[2]));
    }
    for (uint64_t t = 0; t < m->triangle_count; t++) {
        unsigned long long a = corner(m, t, 0) + 1, b = corner(m, t, 1) + 1,
                           c = corner(m, t, 2) + 1; /* OBJ counts from 1 */
        put_text(&w, "f %llu//%llu %llu//%llu %llu//%llu\n", a, a, b, b, c, c);
    }
    return writer_close(&w);
}

ip_status ip_mesh_write_obj(const ip_mesh *m, const char *path, int force, ip_error *err)
{
    mesh_view v = soup_view(m);
    return write_obj(&v, path, force, err);
}

/* Binary glTF 2.0 (the container: a 12-byte header, then chunks of a length, a type and data
 * padded to 4 bytes). The binary chunk holds positions, normals and (indexed) the indices, one
 * after the other, each a multiple of 4 bytes long. */
#define GLB_MAGIC 0x46546c67u      /* "glTF" */
#define GLB_CHUNK_JSON 0x4e4f534au /* "JSON" */
#define GLB_CHUNK_BIN 0x004e4942u  /* "BIN\0" */
#define GLB_JSON_BYTES 4096        /* the JSON is short: a few numbers and fixed text */

/* The positions' smallest and largest coordinates; 0 when one is not finite. */
static int position_bounds(const mesh_view *m, float lo[3], float hi[3])
{
    for (int a = 0; a < 3; a++)
        lo[a] = hi[a] = m->vertex_count ? m->positions[a] : 0.0f;
    for (uint64_t i = 0; i < 3 * m->vertex_count; i++) {
        float x = m->positions[i];
        if (!isfinite(x))
            return 0;
        lo[i % 3] = x < lo[i % 3] ? x : lo[i % 3];
        hi[i % 3] = x > hi[i % 3] ? x : hi[i % 3];
    }
    return 1;
}

/* The JSON of the file with a binary chunk of `bin_bytes`, into json (GLB_JSON_BYTES); its
 * length. */
static size_t glb_json(const mesh_view *m, const float lo[3], const float hi[3], uint64_t bin_bytes,
                       char *json)
{
    size_t n = (size_t)snprintf(json, GLB_JSON_BYTES,
                                "{\"asset\":{\"version\":\"2.0\",\"generator\":\"isoprop %s\"",
                                ip_version());
    if (m->space) /* the name's characters need no escaping in JSON (space_ok()) */
        n += (size_t)snprintf(json + n, GLB_JSON_BYTES - n, ",\"extras\":{\"space\":\"%s\"}",
                              m->space);
    n += (size_t)snprintf(json + n, GLB_JSON_BYTES - n, "}");
    if (m->triangle_count == 0)
        return n + (size_t)snprintf(json + n, GLB_JSON_BYTES - n, "}");
    unsigned long long v = m->vertex_count, bytes = 12 * v;
    n += (size_t)snprintf(
        json + n, GLB_JSON_BYTES - n,
        ",\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
        "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},%s"
        "\"mode\":4}]}],\"buffers\":[{\"byteLength\":%llu}],\"bufferViews\":["
        "{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%llu,\"target\":34962},"
        "{\"buffer\":0,\"byteOffset\":%llu,\"byteLength\":%llu,\"target\":34962}",
        m->indices ? "\"indices\":2," : "", (unsigned long long)bin_bytes, bytes, bytes, bytes);
    if (m->indices)
        n += (size_t)snprintf(json + n, GLB_JSON_BYTES - n,
                              ",{\"buffer\":0,\"byteOffset\":%llu,\"byteLength\":%llu,"
                              "\"target\":34963}",
                              2 * bytes, 12ull * (unsigned long long)m->triangle_count);
    n += (size_t)snprintf(json + n, GLB_JSON_BYTES - n,
                          "],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,"
                          "\"count\":%llu,\"type\":\"VEC3\",\"min\":[%.9g,%.9g,%.9g],"
                          "\"max\":[%.9g,%.9g,%.9g]},{\"bufferView\":1,\"componentType\":5126,"
                          "\"count\":%llu,\"type\":\"VEC3\"}",
                          v, (double)lo[0], (double)lo[1], (double)lo[2], (double)hi[0],
                          (double)hi[1], (double)hi[2], v);
    if (m->indices)
        n += (size_t)snprintf(json + n, GLB_JSON_BYTES - n,
                              ",{\"bufferView\":2,\"componentType\":5125,\"count\":%llu,"
                              "\"type\":\"SCALAR\"}",
                              3ull * (unsigned long long)m->triangle_count);
    n += (size_t)snprintf(json + n, GLB_JSON_BYTES - n, "]}");
    IP_ASSERT(n < GLB_JSON_BYTES);
    return n;
}

/* Appends `bytes` (at most BUFFER_BYTES) from p. */
static void put_bytes(writer *w, const void *p, size_t bytes)
{
    unsigned char *to = writer_room(w, bytes);
    if (!to)
        return;
    memcpy(to, p, bytes);
    w->used += bytes;
}

/* Appends a chunk's header: its length and type. */
static void put_chunk_header(writer *w, uint32_t length, uint32_t type)
{
    unsigned char h[8];
    ip__store_u32le(h, length);
    ip__store_u32le(h + 4, type);
    put_bytes(w, h, 8);
}

/* Appends the binary chunk's data: positions, unit normals (renormalised after packing), and
 * the indices when the mesh has them. */
static void put_glb_arrays(writer *w, const mesh_view *m)
{
    unsigned char *p;
    for (uint64_t i = 0; i < 3 * m->vertex_count && (p = writer_room(w, 4)); i++, w->used += 4)
        ip__store_f32le(p, m->positions[i]);
    for (uint64_t i = 0; i < m->vertex_count && (p = writer_room(w, 12)); i++, w->used += 12) {
        float n[3] = {ip_normal_unpack(m->normals[3 * i]), ip_normal_unpack(m->normals[3 * i + 1]),
                      ip_normal_unpack(m->normals[3 * i + 2])};
        float length = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int k = 0; k < 3; k++) /* glTF requires unit normals: +z stands in for none */
            ip__store_f32le(p + 4 * k, length > 0 ? n[k] / length : (float)(k == 2));
    }
    for (uint64_t i = 0; m->indices && i < 3 * m->triangle_count && (p = writer_room(w, 4));
         i++, w->used += 4)
        ip__store_u32le(p, m->indices[i]);
}

static ip_status write_glb(const mesh_view *m, const char *path, int force, ip_error *err)
{
    float lo[3], hi[3];
    if (!position_bounds(m, lo, hi))
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "%s: a position is not finite, which glTF cannot hold", path);
    uint64_t bin_bytes = 0;
    if (m->triangle_count > 0)
        bin_bytes = 24 * m->vertex_count + (m->indices ? 12 * m->triangle_count : 0);
    char json[GLB_JSON_BYTES + 4];
    size_t json_bytes = glb_json(m, lo, hi, bin_bytes, json);
    while (json_bytes % 4)
        json[json_bytes++] = ' ';
    uint64_t total = 12 + 8 + json_bytes + (bin_bytes ? 8 + bin_bytes : 0);
    if (total > UINT32_MAX)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "%s: %llu bytes are more than binary glTF can hold (4 GiB)", path,
                        (unsigned long long)total);
    writer w;
    if (writer_open(&w, path, force, err) != IP_OK)
        return w.st;
    unsigned char header[12];
    ip__store_u32le(header, GLB_MAGIC);
    ip__store_u32le(header + 4, 2);
    ip__store_u32le(header + 8, (uint32_t)total);
    put_bytes(&w, header, 12);
    put_chunk_header(&w, (uint32_t)json_bytes, GLB_CHUNK_JSON);
    put_bytes(&w, json, json_bytes);
    if (bin_bytes) {
        put_chunk_header(&w, (uint32_t)bin_bytes, GLB_CHUNK_BIN);
        put_glb_arrays(&w, m);
    }
    return writer_close(&w);
}

ip_status ip_mesh_write_glb(const ip_mesh *m, const char *path, int force, ip_error *err)
{
    mesh_view v = soup_view(m);
    return write_glb(&v, path, force, err);
}

/* Whether `path` ends in `extension` (".ply"), ignoring case. */
static int has_extension(const char *path, const char *extension)
{
    size_t n = strlen(path), e = strlen(extension);
    return n > e && strcasecmp(path + n - e, extension) == 0;
}

const char *ip_mesh_format_of(const char *path)
{
    static const char *const formats[][2] = {
        {".ply", "PLY"}, {".stl", "STL"}, {".obj", "OBJ"}, {".glb", "GLB"}};
    for (size_t i = 0; i < sizeof formats / sizeof formats[0]; i++)
        if (has_extension(path, formats[i][0]))
            return formats[i][1];
    return NULL;
}

/* Writes the mesh in the format its name ends in. */
static ip_status write_by_extension(const mesh_view *m, const char *path, int force, ip_error *err)
{
    const char *format = ip_mesh_format_of(path);
    if (!format)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "%s: unknown mesh format (the name must end in .ply, .stl, .obj or .glb)",
                        path);
    if (strcmp(format, "STL") == 0)
        return write_stl(m, path, force, err);
    if (strcmp(format, "OBJ") == 0)
        return write_obj(m, path, force, err);
    if (strcmp(format, "GLB") == 0)
        return write_glb(m, path, force, err);
    return write_ply(m, path, force, err);
}

ip_status ip_mesh_write(const ip_mesh *m, const char *path, int force, ip_error *err)
{
    mesh_view v = soup_view(m);
    return write_by_extension(&v, path, force, err);
}

ip_status ip_indexed_mesh_write(const ip_indexed_mesh *m, const char *path, int force,
                                ip_error *err)
{
    mesh_view v = indexed_view(m);
    return write_by_extension(&v, path, force, err);
}

/* 1 when `space` is a name ip_mesh_write_in() accepts. */
static int space_ok(const char *space)
{
    size_t n = strlen(space);
    if (n == 0 || n > IP_MESH_SPACE_MAX)
        return 0;
    for (size_t i = 0; i < n; i++) {
        char c = space[i];
        if (!((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') ||
              c == '.' || c == '_' || c == '-'))
            return 0;
    }
    return 1;
}

/* Writes `v` by its name's extension with `space` named in the file (NULL: none). */
static ip_status write_in(mesh_view *v, const char *path, const char *space, int force,
                          ip_error *err)
{
    if (space && !space_ok(space))
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "%s: the mesh's space name must be 1 to %d letters, digits, '.', '_' or "
                        "'-'",
                        path, IP_MESH_SPACE_MAX);
    v->space = space;
    return write_by_extension(v, path, force, err);
}

ip_status ip_mesh_write_in(const ip_mesh *m, const char *path, const char *space, int force,
                           ip_error *err)
{
    mesh_view v = soup_view(m);
    return write_in(&v, path, space, force, err);
}

ip_status ip_indexed_mesh_write_in(const ip_indexed_mesh *m, const char *path, const char *space,
                                   int force, ip_error *err)
{
    mesh_view v = indexed_view(m);
    return write_in(&v, path, space, force, err);
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* Internal helpers shared by the library's source files; not part of the public API. */
#ifndef ISOPROP_INTERNAL_H
#define ISOPROP_INTERNAL_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "isoprop/status.h"
#include "isoprop/system.h"
#include "isoprop/version.h"
#include "isoprop/volume.h"

#if defined(__GNUC__)
#define IP_PRINTF(a, b) __attribute__((format(printf, a, b)))
#define IP_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define IP_PRINTF(a, b)
#define IP_ALWAYS_INLINE inline
#endif

/* The version as a string literal, "MAJOR.MINOR.PATCH", from isoprop/version.h. */
#define IP__STRINGIFY_(x) #x
#define IP__STRINGIFY(x) IP__STRINGIFY_(x)
#define IP__VERSION_STRING          \
    IP__STRINGIFY(IP_VERSION_MAJOR) \
    "." IP__STRINGIFY(IP_VERSION_MINOR) "." IP__STRINGIFY(IP_VERSION_PATCH)

/* IP_ASSERT(cond): an internal invariant (a precondition of an internal function: an index in
 * range, a size, a pointer that is not NULL), never a check of input, which gets an ip_status.
 * Without NDEBUG (the Debug build that tools/setup.sh test runs under the sanitizers) a false
 * condition prints "file:line: internal assertion failed: cond" to stderr and aborts: the one
 * place the library prints. With NDEBUG (every other build) the condition is not evaluated. */
#ifdef NDEBUG
#define IP_ASSERT(cond) ((void)sizeof((cond) ? 1 : 0))
#else
#define IP_ASSERT(cond) ((cond) ? (void)0 : ip__assert_fail(__FILE__, __LINE__, #cond))
#endif

/* Prints the failed IP_ASSERT condition with its place and aborts. */
#if defined(__GNUC__)
__attribute__((noreturn))
#endif
void ip__assert_fail(const char *file, int line, const char *condition);

/* Fills err (may be NULL) with code and a formatted one-line message; returns code. */
ip_status ip__fail(ip_error *err, ip_status code, const char *fmt, ...) IP_PRINTF(3, 4);

/* Like ip__fail, appending ": strerror(errnum)". */
ip_status ip__fail_errno(ip_error *err, ip_status code, int errnum, const char *fmt, ...)
    IP_PRINTF(4, 5);

struct ip_orientation;
/* Sets o's directions to `directions` (one vector an axis) over their lengths and returns 1
 * when they form an orthonormal frame that passes ip_orientation_check with o's origin and
 * space; else returns 0 and leaves o as it was. */
int ip__orientation_frame(struct ip_orientation *o, const double directions[3][3]);

/* 1 when every direction of o is zero: a description filled by hand without an orientation,
 * which the bricker and the store of a volume in memory take as the unit axes. */
int ip__orientation_unset(const struct ip_orientation *o);

/* Little-endian loads and stores, independent of the host's byte order. */
static inline uint32_t ip__load_u32le(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static inline uint64_t ip__load_u64le(const unsigned char *p)
{
    return (uint64_t)ip__load_u32le(p) | (uint64_t)ip__load_u32le(p + 4) << 32;
}
static inline void ip__store_u32le(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)v;
    p[1] = (unsigned char)(v >> 8);
    p[2] = (unsigned char)(v >> 16);
    p[3] = (unsigned char)(v >> 24);
}
static inline void ip__store_u64le(unsigned char *p, uint64_t v)
{
    ip__store_u32le(p, (uint32_t)v);
    ip__store_u32le(p + 4, (uint32_t)(v >> 32));
}

static inline float ip__load_f32le(const unsigned char *p)
{
    uint32_t bits = ip__load_u32le(p);
    float v;
    memcpy(&v, &bits, 4);
    return v;
}
static inline double ip__load_f64le(const unsigned char *p)
{
    uint64_t bits = ip__load_u64le(p);
    double v;
    memcpy(&v, &bits, 8);
    return v;
}
static inline void ip__store_f32le(unsigned char *p, float v)
{
    uint32_t bits;
    memcpy(&bits, &v, 4);
    ip__store_u32le(p, bits);
}
static inline void ip__store_f64le(unsigned char *p, double v)
{
    uint64_t bits;
    memcpy(&bits, &v, 8);
    ip__store_u64le(p, bits);
}

/* The smallest r with 2^r >= v (0 for v <= 1): the exponent of a power of two. */
static inline uint32_t ip__ceil_log2(uint64_t v)
{
    uint32_t r = 0;
    while ((UINT64_C(1) << r) < v)
        r++;
    return r;
}

/* The index of the lowest set bit of m (not 0). */
static inline unsigned ip__lowest_bit(unsigned m)
{
#if defined(__GNUC__) || defined(__clang__)
    return (unsigned)__builtin_ctz(m);
#else
    unsigned i = 0;
    while (!(m >> i & 1u))
        i++;
    return i;
#endif
}

/* 1 on a little-endian host. */
static inline int ip__host_little_endian(void)
{
    const uint16_t one = 1;
    return *(const unsigned char *)&one == 1;
}

/* Maps the whole pages inside [p, p + bytes) into the process, writable, in one system call
 * (MADV_POPULATE_WRITE), for memory about to be written: first touches of fresh memory then find
 * their pages present instead of taking a page fault each, which costs several times more in a
 * virtual machine (docs/notes/performance-notebook.md, part 7). Contents are unchanged. Best effort: does
 * nothing where the kernel (before Linux 5.14) or the range does not allow it. */
void ip__memory_populate(void *p, size_t bytes);

/* Bytes this process (all its threads, those that ended included) made the kernel read from
 * a block device: Linux's /proc/self/io `read_bytes`, which counts the reads the process
 * caused (its read-ahead included) and not those served from the page cache; 0 where the
 * kernel does not keep it. */
uint64_t ip__process_read_bytes(void);

/* Reverses the bytes of each of `count` elements of `size` bytes (2 or 4) in place. */
void ip__swap_bytes(void *data, size_t count, size_t size);

/* Who spells a sample type how (a bit set): the canonical names ("uint8", "float32"), the NRRD
 * format's, MetaImage's ("MET_UCHAR"), and short aliases ("u8", "f32"). */
enum {
    IP_TYPE_SPELLING_CANONICAL = 1,
    IP_TYPE_SPELLING_NRRD = 2,
    IP_TYPE_SPELLING_METAIMAGE = 4,
    IP_TYPE_SPELLING_OTHER = 8,
    IP_TYPE_SPELLING_ALL = 15
};

/*! ip__type_from_name() : the type named `name` (case-insensitive) in one of `spellings`.
 *  @return : IP_OK and *out set, or IP_ERR_ARGUMENT (NULL or unknown name; *out untouched). */
ip_status ip__type_from_name(const char *name, unsigned spellings, ip_type *out);

/* Writes to `out` (`size` bytes, cut short if need be, always terminated) the first name in
 * `spellings` of each type, in the order of ip_type, separated by ", ": "uint8, uint16, int16,
 * float" for IP_TYPE_SPELLING_NRRD. */
void ip__type_names(unsigned spellings, char *out, size_t size);

/* Drops each pair of triangles on the same three vertices wound opposite ways (a fold, which
 * encloses nothing: mesh_folds.c); *dropped counts the triangles dropped. The vertices stay
 * (the caller compacts). Returns IP_OK or IP_ERR_NOMEM (the mesh unchanged). */
struct ip_indexed_mesh;
ip_status ip__indexed_mesh_drop_folds(struct ip_indexed_mesh *mesh, uint64_t *dropped);
/* Triangle t of a welded mesh: its area and the signed volume of the tetrahedron it makes
 * with the origin, p0 . (p1 x p2) / 6 (mesh_measure.c). */
void ip__triangle_measure(const struct ip_indexed_mesh *m, uint64_t t, double *area,
                          double *volume);

#endif

/* SPDX-License-Identifier: BSD-3-Clause */
/* The coverage depth buffer of occlusion-aware propagation. Internal.
 *
 * Two entries per pixel of the image. The first, `depth`: an upper bound on the view depth of
 * the nearest extracted triangle whose projection holds the pixel's centre (+infinity where
 * none is known yet). The second, `solid`: the same bound from the triangles whose projection
 * holds the centre by a margin (IP_COVERAGE_SOLID_MARGIN), which the rasterizer draws there
 * whatever its rounding: rays stop at it (see cast.c, ip__engine_cast_ray()).
 * Workers add the triangles they extract and test, before queueing a cell, whether extracted
 * surface already hides it (docs/occlusion.md; the argument is in coverage.c).
 *
 * Granularity: cells, the unit propagation queues. At the sizes the engine makes them (about
 * a pixel with lod, a few pixels at full resolution) a cell's box holds a handful of pixel
 * centres, so the test reads those entries directly and stops at the first one not covered;
 * a max-depth pyramid (hierarchical Z) would pay only for boxes of hundreds of pixels, which
 * propagation never tests, and would need its levels kept conservative under concurrent
 * writes. Boxes and triangles larger than IP_COVERAGE_MAX_PIXELS are simply not used (not
 * deferred, not recorded), which is always safe.
 *
 * Thread-safe: entries are atomic; a write lowers one with a relaxed load and store (not a
 * compare-and-swap loop: two threads lowering one entry at once may leave the larger of their
 * two depths, so an entry may rise, though never above a depth some triangle recorded there),
 * a read is a relaxed load. Every value ever stored is backed by a triangle already in a
 * worker's mesh, so a stale or risen entry only makes the tests less eager. */
#ifndef ISOPROP_COVERAGE_H
#define ISOPROP_COVERAGE_H

#include <stdatomic.h>
#include <stdint.h>
#include <string.h>

#include "isoprop/camera.h"
#include "isoprop/status.h"
#include "vec3.h"

#define IP_COVERAGE_MAX_PIXELS 1024 /* the largest box or triangle (bounding pixels) used */

/* A triangle records a pixel centre as solidly covered when the centre lies inside its exact
 * projection by at least this distance (pixels) from every edge: 2.8 times what the
 * 1/256-pixel vertex snapping of the rasterizer can move a point (at most sqrt(2) / 512
 * pixel), so the rasterizer draws the triangle there in any mesh that holds it (the argument
 * is at ip__engine_cast_ray() in cast.c). */
#define IP_COVERAGE_SOLID_MARGIN (1.0 / 128)

/* Entries are stored tile by tile, the IP_COVERAGE_TILE^2 pixels of a tile row by row in 256
 * contiguous bytes per buffer: the few pixels a small box or triangle covers lie in one or two
 * cache lines, and only the memory of the tiles kept (ip__coverage_reach()) is ever touched. */
#define IP_COVERAGE_TILE_SHIFT 3
#define IP_COVERAGE_TILE (1u << IP_COVERAGE_TILE_SHIFT)

/* The image projection the coverage and propagation share: a point v (world units, from the
 * eye) at view depth z > 0 shows at image x = v . to_x / z + centre_x (pixels), y likewise.
 * One definition, so that a caller of ip__coverage_hides_seen() gets the very bits that
 * ip__coverage_hides() would work out. */
typedef struct ip_image_axes {
    double to_x[3], to_y[3];
    double centre_x, centre_y;
} ip_image_axes;

static inline void ip__image_axes_of(const ip_camera_basis *b, uint32_t width, uint32_t height,
                                     ip_image_axes *ax)
{
    for (int a = 0; a < 3; a++) {
        ax->to_x[a] = b->right[a] * 0.5 * width / b->tan_half_x;
        ax->to_y[a] = -b->up[a] * 0.5 * height / b->tan_half_y;
    }
    ax->centre_x = 0.5 * width;
    ax->centre_y = 0.5 * height;
}

/* Image position (pixels) of v (from the eye) at view depth z > 0 (ip_image_axes). */
static inline void ip__image_position(const ip_image_axes *ax, const double v[3], double z,
                                      double *x, double *y)
{
    *x = ip__vec3_dot(v, ax->to_x) / z + ax->centre_x;
    *y = ip__vec3_dot(v, ax->to_y) / z + ax->centre_y;
}

typedef struct ip_coverage {
    ip_camera camera;
    ip_camera_basis basis;
    double near_plane, far_plane; /* the renderers' clip planes for the volume's box */
    ip_image_axes axes;
    uint32_t width, height;
    uint32_t tiles_x;   /* tiles of IP_COVERAGE_TILE pixels a side in a row of the image */
    atomic_uint *depth; /* per pixel, tile by tile (ip__coverage_index()): the bits of a float
                           depth, +inf: unknown */
    atomic_uint *solid; /* the same, from triangles holding the centre by the solid margin */
    size_t capacity;    /* entries allocated */
    /* NULL, or per tile of 2^reached_shift pixels a side (reached_x of them a row): whether its
     * entries are kept. The others are never cleared, written or read: no extracted surface
     * can show there (ip__coverage_reach()). */
    const unsigned char *reached;
    unsigned reached_shift;
    uint32_t reached_x;
} ip_coverage;

/* Starts over for `camera` (image size and view) and the volume's world box [lo, hi]: every
 * entry unknown. Reallocates when the image grew. Not while other threads use it.
 * @return IP_OK or IP_ERR_NOMEM. */
ip_status ip__coverage_reset(ip_coverage *c, const ip_camera *camera, const double lo[3],
                             const double hi[3]);

/* ip__coverage_reset() in two parts, for threads to share the writes (15 MiB at 1600x1200):
 * the set-up alone, entries left as they are; then part `part` of `parts` of the entries made
 * unknown (parts at once on as many threads, none using the buffer otherwise). */
ip_status ip__coverage_prepare(ip_coverage *c, const ip_camera *camera, const double lo[3],
                               const double hi[3]);
void ip__coverage_clear(ip_coverage *c, unsigned part, unsigned parts);

/* After ip__coverage_prepare() and before ip__coverage_clear(): keeps only the entries of the
 * tiles of 2^shift pixels marked in `reached` (tiles_x a row; borrowed, NULL: every entry;
 * shift >= IP_COVERAGE_TILE_SHIFT, so that each tile of the entries' layout lies in one).
 * The caller vouches that no triangle it adds reaches another tile (its image lies within a
 * marked tile's pixels); boxes reaching another tile are never found hidden, and the solid
 * entries of the others must not be read (ip__coverage_solid()). Clearing then writes only
 * the kept entries, and the memory of the others is never touched. */
void ip__coverage_reach(ip_coverage *c, const unsigned char *reached, unsigned shift,
                        uint32_t tiles_x);

void ip__coverage_free(ip_coverage *c);

/* A triangle may show in the image when some pixel centre lies within this distance (pixels)
 * of its exact projection: 5.5 times what the rasterizer's 1/256-pixel vertex snapping can
 * move a point (sqrt(2) / 512 pixel). One whose projection is farther from every centre is
 * drawn at none, in any mesh (ip__coverage_add()). */
#define IP_COVERAGE_SHOW_MARGIN (1.0 / 64)

/* Records `count` triangles (9 floats each, world units; count <= 32). Any thread. Returns a
 * mask, bit t set unless triangle t can be drawn at no pixel centre of the image: it lies
 * wholly between the near and far planes, its projection is non-degenerate and within
 * IP_COVERAGE_MAX_PIXELS bounding pixels, and no pixel centre of the image lies within
 * IP_COVERAGE_SHOW_MARGIN of it. A triangle without its bit records nothing. */
uint32_t ip__coverage_add(ip_coverage *c, const float *positions, unsigned count);

/* The same for triangles given as indices into `points` (world units): corner k of triangle t
 * is points[corners[3 * t + k]], each index below 32. Each point is projected once, however
 * many triangles share it (a cell's edge crossings). */
uint32_t ip__coverage_add_indexed(ip_coverage *c, const float points[][3], const int8_t *corners,
                                  unsigned count);

/* The bits of a float, and back: an entry holds a non-negative float's bits, so that integer
 * order is float order and an atomic integer minimum is a float minimum. */
static inline unsigned ip__float_bits(float f)
{
    unsigned bits;
    memcpy(&bits, &f, sizeof bits);
    return bits;
}

static inline float ip__float_of_bits(unsigned bits)
{
    float f;
    memcpy(&f, &bits, sizeof f);
    return f;
}

/* Where pixel (x, y)'s entries are in c->depth and c->solid. */
static inline size_t ip__coverage_index(const ip_coverage *c, uint64_t x, uint64_t y)
{
    size_t tile =
        (size_t)(y >> IP_COVERAGE_TILE_SHIFT) * c->tiles_x + (size_t)(x >> IP_COVERAGE_TILE_SHIFT);
    return tile << 2 * IP_COVERAGE_TILE_SHIFT |
           (size_t)((y & (IP_COVERAGE_TILE - 1)) << IP_COVERAGE_TILE_SHIFT |
                    (x & (IP_COVERAGE_TILE - 1)));
}

/* The solid entry of pixel (x, y) (inside the image, in a kept tile): an upper bound on the
 * view depth (world units) of an extracted triangle whose projection holds the pixel centre by
 * at least IP_COVERAGE_SOLID_MARGIN pixels from every edge, or +infinity where none is known.
 * Bounds the depth that the rasterizer shows there once that triangle is drawn. Any thread. */
static inline double ip__coverage_solid(const ip_coverage *c, uint32_t x, uint32_t y)
{
    return ip__float_of_bits(
        atomic_load_explicit(&c->solid[ip__coverage_index(c, x, y)], memory_order_relaxed));
}

/* 1 when the world box [lo, hi] is certainly hidden: it lies wholly in front of the eye and
 * beyond the near plane, its projection holds at least one pixel centre, and at every pixel
 * centre it may cover the recorded surface is nearer than the box's nearest point. 0 when
 * in doubt. Any thread. */
int ip__coverage_hides(const ip_coverage *c, const double lo[3], const double hi[3]);

/* The same, given the box's centre as the caller has seen it: its view depth zc and image
 * position (xc, yc), pixels, by ip__image_position() with the coverage's axes (v the centre
 * less the eye). */
int ip__coverage_hides_seen(const ip_coverage *c, const double lo[3], const double hi[3], double zc,
                            double xc, double yc);

#endif

/* SPDX-License-Identifier: BSD-3-Clause */
/* isoprop: progressive view-dependent isosurface extraction (Liu, Finkelstein, Li).
 *
 * ip_engine_begin() fixes a view and an isovalue; each ip_engine_step() casts the next rays of
 * the progressive order (centre first, then the centres of quadrants, ...). A ray walks the
 * min/max octree front to back and stops at the first cell whose marching-cubes triangles it
 * hits, its seed; the seed's surface is propagated into neighbouring cells within the cut-off
 * angle of the ray, without folding back, and appended to the engine's mesh. Once every pixel
 * has had its ray, the image of the mesh equals the image of the full isosurface
 * (ip_extract_full(); with adaptive resolution, ip_extract_full_lod()). docs/design.md describes
 * the method and the data flow, and gives the argument for the exact image as statements E1-E14,
 * which the options below cite.
 *
 * Adaptive resolution (options.lod, on by default; the paper's section 2.3): far regions come
 * from the coarse levels of the brick file and never load fine bricks; each level serves a band
 * of distances from the eye (ip_engine_lod_distance()). The image is exact against
 * ip_extract_full_lod() (docs/design.md, E13), with sub-pixel cracks where the bands meet.
 *
 * Occlusion (options.occlusion, on by default): a coverage depth buffer of the surface extracted
 * so far, 8 bytes a pixel, lets propagation pass over hidden cells, rays stop where nothing
 * further can show, and the rays of 8 x 8 pixel tiles retire without a walk (`deferred`,
 * `retired`). The image once every ray has been cast is unchanged (E5, E7-E12); what changes is
 * how much hidden surface is extracted (docs/occlusion.md).
 *
 * Culling (options.cull, on by default, with occlusion): triangles drawn at no pixel centre of
 * the image are not kept in the mesh but counted in `culled`. The image is the same, every step
 * (E6); the mesh is what this view's image needs. Keep them (cull 0) for a mesh to be written
 * out, drawn with multisampling or from another view (docs/occlusion.md).
 *
 * Reuse (options.reuse, with occlusion; off by default): ip_engine_begin() at the isovalue of the
 * view before (the engine's planes and options unchanged, and that view's steps all successful)
 * keeps, of the mesh, the whole cells that belong to the new view's surface and may show in it,
 * first and in their order, and the pass extracts what became visible; the image once every ray
 * has been cast is the one without reuse (E14). Hidden cells and those outside the image are
 * dropped. The mesh then keeps cell ids (with_cells), 8 bytes a triangle.
 *
 * Reading ahead (options.prefetch, IP_PREFETCH_ON by default): one more thread per engine reads
 * and decodes into the cache, from the first step after ip_engine_begin() on and between steps,
 * the bricks that the next rays of the order will seed in and their neighbours, within the
 * cache's budget and without evicting a brick of the current view (docs/cache.md,
 * "Prefetching"). When the workers have every core (threads >= ip_thread_count(0)) it reads
 * ahead only the bricks the disk has to deliver (not those whose payload the page cache holds,
 * ip_store_brick_in_memory()). IP_PREFETCH_ALWAYS reads every planned brick ahead;
 * IP_PREFETCH_OFF starts no reader. The triangles do not depend on it. A brick that fails to
 * load in the background is read again by the worker that needs it, which reports the error as
 * without reading ahead. It stops at ip_engine_begin() (for the new view), ip_engine_cancel()
 * and ip_engine_destroy().
 *
 * Threads: an engine is driven by one thread. ip_engine_create() starts its worker threads
 * (ip_thread_count(options.threads) in all, the driving thread counted), which sleep between
 * steps; ip_engine_step() wakes them, works as one of them and returns when all have stopped and
 * every cell queued in the step is extracted. Every pixel has one ray, and one thread casts
 * exactly the sequential order. With several threads the triangles' order and, where
 * propagations meet, which cells are extracted may vary from run to run; what every pixel
 * finally shows does not (E4). The times are then summed over the threads. ip_engine_cancel()
 * may be called from any thread.
 */
#ifndef ISOPROP_ENGINE_H
#define ISOPROP_ENGINE_H

#include <stdint.h>

#include "isoprop/cache.h"
#include "isoprop/camera.h"
#include "isoprop/mesh.h"
#include "isoprop/status.h"
#include "isoprop/system.h"

#ifdef __cplusplus
extern "C" {
#endif

#define IP_DEFAULT_CUTOFF_DEGREES 1.81   /* the paper's cut-off angle */
#define IP_DEFAULT_FOLDBACK_DEGREES 0.25 /* fold-back tolerance */
#define IP_MAX_CLIP_PLANES 6

/* A clipping plane: keeps the half-space normal . x + offset >= 0 (x in world units; the normal
 * need not be of unit length). Cells are kept or dropped whole: a cell is kept unless its box
 * lies wholly beyond one of the planes (normal . x + offset < 0 at all 8 corners), so the cut
 * is ragged at cell resolution. A dropped cell is neither seeded nor propagated into, nor
 * extracted by ip_extract_full_clipped(), nor read ahead. */
typedef struct ip_clip_plane {
    double normal[3];
    double offset;
} ip_clip_plane;

/* ip_engine_options.prefetch (see Reading ahead above). */
#define IP_PREFETCH_OFF 0    /* no reader */
#define IP_PREFETCH_ON 1     /* read ahead what the disk must deliver, all when a core is spare */
#define IP_PREFETCH_ALWAYS 2 /* read every planned brick ahead */

typedef struct ip_engine_options {
    uint32_t size; /* bytes of the struct as the caller compiled it (IP_SIZED); see status.h */
    double cutoff_degrees;   /* propagation cut-off angle around the seed's ray */
    double foldback_degrees; /* fold-back tolerance */
    unsigned threads;        /* worker threads for seeding and propagation; 0 = every core */
    int lod;                 /* adaptive resolution: far regions from coarser pyramid levels */
    double pixel_error;      /* with lod: a meta-cell is used once it projects to at most this
                                 many pixels (1: the paper's sub-pixel rule) */
    int cell_ids;            /* keep each triangle's cell id in the mesh (8 bytes a triangle
                                 more; for comparing extractions) */
    int occlusion;           /* occlusion-aware propagation (see Occlusion above; default on) */
    int prefetch;            /* a background reader loads the bricks the next rays need:
                                IP_PREFETCH_OFF, _ON (the default) or _ALWAYS (see Reading
                                ahead above) */
    int cull;                /* with occlusion: triangles drawn at no pixel centre of the view's
                                image are not kept (see Culling above; default on) */
    unsigned clip_count;     /* planes in use in clip (0: none, the default) */
    ip_clip_plane clip[IP_MAX_CLIP_PLANES]; /* the surface is kept where every plane keeps it:
                                               the exact-image guarantee holds for the kept
                                               cells (ip_extract_full_clipped()) */
    int reuse; /* with occlusion: a view keeps what stays valid of the view before it at the
                  same isovalue (see Reuse above; default off) */
} ip_engine_options;

/* Counters and times, per step or in total. Times are wall seconds, split as the paper does.
 * To keep clock reads off the hot paths, seeding is timed per batch of rays (less what
 * propagation measured inside it) and, within a propagation, one extraction in 16 is timed
 * and counted 16 times: the split between propagation and extraction is an estimate. */
typedef struct ip_engine_counts {
    uint64_t rays;  /* rays cast */
    uint64_t seeds; /* rays whose seed cell was new and started a propagation */
    uint64_t cells; /* cells extracted (triangulated) */
    uint64_t triangles;
    double intersection_seconds; /* ray seeding: octree walks and ray-triangle tests */
    double propagation_seconds;  /* queue, neighbour and criteria work */
    double extraction_seconds;   /* marching cubes: samples, gradients, triangles */
    double rendering_seconds;    /* reported by the caller, ip_engine_add_rendering_time() */
    uint64_t deferred;    /* with occlusion: neighbours propagation left because surface already
                          extracted hid them (a cell may count more than once) */
    uint64_t retired;     /* with occlusion: rays (counted in rays) retired with their screen tile,
                          without a walk (see Occlusion above) */
    uint64_t nodes;       /* octree nodes (bricks included), sub-blocks and cells the rays' walks
                          entered: the seeding work, independent of the clock */
    uint64_t culled;      /* with options.cull: triangles made and not kept, not in `triangles` */
    uint64_t kept;        /* with options.reuse: triangles kept from the view before, counted in
                          `triangles` (their cells in `cells`) */
    uint64_t reserved[8]; /* zero: room for later fields at the same size (status.h) */
} ip_engine_counts;

typedef struct ip_engine ip_engine;

/*! ip_engine_options_default() : the paper's cut-off (1.81 degrees), a 0.25 degree
 *  fold-back tolerance, every core, adaptive resolution with a 1-pixel error, no cell ids,
 *  occlusion on, reading ahead on. */
IP_API void ip_engine_options_default(ip_engine_options *options);

/*! ip_engine_create() : an engine reading through `cache` (which must outlive it), with its
 *  worker threads started: ip_thread_count(options.threads) - 1 of them, idle until a step
 *  (see Threads above). *out is the caller's, released with ip_engine_destroy().
 *  @return IP_OK, IP_ERR_ARGUMENT (also for more than IP_MAX_CLIP_PLANES planes, a zero or
 *  non-finite normal or a non-finite offset) or IP_ERR_NOMEM. */
IP_API ip_status ip_engine_create(ip_cache *cache, const ip_engine_options *options,
                                  ip_engine **out, ip_error *err);

/*! ip_engine_destroy() : stops and joins the engine's worker threads and frees the engine and
 *  its mesh; not during a step. NULL is allowed. */
IP_API void ip_engine_destroy(ip_engine *engine);

/*! ip_engine_begin() : starts over with a new view and isovalue: drops the mesh, the visited
 *  cells and the ray order, and clears a pending cancel. @return IP_OK or IP_ERR_ARGUMENT. */
IP_API ip_status ip_engine_begin(ip_engine *engine, const ip_camera *camera, float iso,
                                 ip_error *err);

/*! ip_engine_step() : casts up to `max_rays` more rays (0: no limit) for at most `max_seconds`
 *  (0: no limit; checked between rays), appending new triangles to the mesh. `counts` (may be
 *  NULL) receives what this step did. @return IP_OK, IP_ERR_CANCELLED after ip_engine_cancel(),
 *  or the error of a brick that could not be read (IP_ERR_CHECKSUM, IP_ERR_CORRUPT, naming it);
 *  the mesh keeps what was extracted before. */
IP_API ip_status ip_engine_step(ip_engine *engine, uint64_t max_rays, double max_seconds,
                                ip_engine_counts *counts, ip_error *err);

/*! ip_engine_done() : 1 once every pixel has had its ray (after ip_engine_set_region(): once
 *  the region's rays have). */
IP_API int ip_engine_done(const ip_engine *engine);

/*! ip_engine_cancel() : asks a running or later step to stop at the next ray (any thread). */
IP_API void ip_engine_cancel(ip_engine *engine);

/*! ip_engine_mesh() : the triangles extracted since ip_engine_begin(), in extraction order;
 *  owned by the engine, valid until the next begin, step or destroy. */
IP_API const ip_mesh *ip_engine_mesh(const ip_engine *engine);

/*! ip_engine_totals() : counts and times since ip_engine_begin(). */
IP_API void ip_engine_totals(const ip_engine *engine, ip_engine_counts *counts);

/* The engine's memory, bytes, besides the brick cache it reads through (ip_cache_get_stats()). */
typedef struct ip_engine_memory {
    uint64_t mesh;     /* the mesh's arrays as allocated (ip_engine_mesh(); kept between views) */
    uint64_t workers;  /* the workers' triangle buffers and propagation queues */
    uint64_t visited;  /* the visited cells' bitmaps (one per brick the view reached) and index */
    uint64_t coverage; /* with occlusion: the coverage buffers and screen tiles */
    uint64_t total;    /* the sum */
    uint64_t reserved[8]; /* zero: room for later fields at the same size (status.h) */
} ip_engine_memory;

/*! ip_extract_full() : triangulates every active cell of level `level`, brick by brick, skipping
 *  bricks and sub-blocks whose summary range excludes `iso`; the oracle and the baseline.
 *  Cell ids are kept when `mesh` keeps them (mesh->with_cells).
 *  Triangles equal those of the progressive engine for the same cells. Runs on `threads`
 *  threads (0 = every core; the calling thread and threads started for the call and joined
 *  before it returns) and appends to `mesh` in brick order, so the result is the same
 *  for any number of threads. Times are summed over threads.
 *  @return IP_OK or a brick read error. */
IP_API ip_status ip_extract_full(ip_cache *cache, float iso, uint32_t level, unsigned threads,
                                 ip_mesh *mesh, ip_engine_counts *counts, ip_error *err);

/*! ip_extract_full_clipped() : ip_extract_full() of the cells the `clip_count` planes `clip`
 *  keep (the rule of ip_clip_plane; the engine with the same planes extracts among the same
 *  cells), also skipping bricks and sub-blocks that lie wholly beyond a plane. `clip` is the
 *  caller's, read during the call; NULL with a count of 0 is ip_extract_full().
 *  @return IP_OK, IP_ERR_ARGUMENT for bad planes (as ip_engine_create()) or a brick read
 *  error. */
IP_API ip_status ip_extract_full_clipped(ip_cache *cache, float iso, uint32_t level,
                                         unsigned threads, const ip_clip_plane *clip,
                                         unsigned clip_count, ip_mesh *mesh,
                                         ip_engine_counts *counts, ip_error *err);

/* ---- Experimental (IP_EXPERIMENTAL) ----
 * Declared only where IP_EXPERIMENTAL is defined before the include (docs/api.md,
 * "Stability"): calls for advanced uses that may change in a minor version, as the
 * programs use them. Exported all the same. */
#ifdef IP_EXPERIMENTAL

/*! ip_engine_set_region() : restricts the next steps to rays [first_ray, first_ray +
 *  ray_count) of the progressive order of the rectangle of width x height pixels whose top-left
 *  pixel is (x, y) in the image of ip_engine_begin()'s camera (the rectangle's own order: its
 *  centre first, as for an image of that size, shifted to (x, y)). The mesh, the visited cells
 *  and the occlusion coverage are kept, so a cell extracted for an earlier rectangle is not
 *  extracted again; what the rays of the earlier rectangles did not finish is dropped.
 *  Propagation stays within the rectangle's part of the view (a cell whose projection may
 *  reach the rectangle, with a 2-pixel margin), leaving the surface beyond to the rays of the
 *  rectangles around it. ip_engine_done() is then 1 once those ray_count rays are cast. From
 *  the thread that drives the engine. For sort-first parallel
 *  rendering: every pixel given a ray in some rectangle, the union of the meshes shows the
 *  image of one full run. Call after ip_engine_begin(), between steps.
 *  @return IP_OK, or IP_ERR_ARGUMENT (before begin, an empty rectangle or one not inside the
 *  image, more rays than the rectangle's pixels). */
IP_API ip_status ip_engine_set_region(ip_engine *engine, uint32_t x, uint32_t y, uint32_t width,
                                      uint32_t height, uint64_t first_ray, uint64_t ray_count,
                                      ip_error *err);

/*! ip_engine_read_ahead() : once the view is done (ip_engine_done()), lets the background
 *  reader (options.prefetch) read into the cache the bricks that the first rays of `camera`'s
 *  view would seed in, and their neighbours, as it does for a view begun (see Reading ahead
 *  above), within the budget, evicting the least recently used bricks: for a viewer
 *  that predicts the next view of an orbit or a zoom from the last motions. It reads until the
 *  next ip_engine_begin(), which stops it; `camera` is copied. Nothing else changes: the mesh
 *  and the view stay. A no-op without the reader.
 *  @return IP_OK, or IP_ERR_ARGUMENT (a bad camera, or a view not done). */
IP_API ip_status ip_engine_read_ahead(ip_engine *engine, const ip_camera *camera, ip_error *err);

/*! ip_engine_lod_distance() : D[level] of the current view, world units (0 for level 0;
 *  infinity for levels that are never used). Valid after ip_engine_begin(). */
IP_API double ip_engine_lod_distance(const ip_engine *engine, uint32_t level);

/*! ip_engine_memory_of() : what the engine holds now (*memory is the caller's); not during a
 *  step. */
IP_API void ip_engine_memory_of(const ip_engine *engine, ip_engine_memory *memory);

/*! ip_engine_add_rendering_time() : adds the caller's rendering time to the totals. */
IP_API void ip_engine_add_rendering_time(ip_engine *engine, double seconds);

/*! ip_extract_full_lod() : the full extraction at the adaptive resolution of a view: for each
 *  level that an engine with `lod` on and `pixel_error` (ip_engine_options) uses for `camera`,
 *  the active cells whose centre lies within that level's distance band from the eye
 *  ([ip_engine_lod_distance(k), ip_engine_lod_distance(k + 1)), world units), among those the
 *  planes keep (as ip_extract_full_clipped()). Appended level by level, each in brick order,
 *  so the result is the same for any number of threads; the reference that the progressive
 *  image with adaptive resolution equals once every ray has been cast (isorender --full-lod).
 *  With one level in use it is ip_extract_full_clipped() of level 0. Cells outside the view
 *  are included: the bands are distances, not the frustum. `camera` (its eye, field of view
 *  and image height set the bands) and `clip` are the caller's, read during the call; the
 *  triangles are appended to the caller's `mesh` (cell ids, which name the level, when it
 *  keeps them). Threads as ip_extract_full() (0 = every core, joined before it returns).
 *  @return IP_OK, IP_ERR_ARGUMENT for a bad camera, pixel error or planes, or a brick read
 *  error. */
IP_API ip_status ip_extract_full_lod(ip_cache *cache, float iso, const ip_camera *camera,
                                     double pixel_error, unsigned threads,
                                     const ip_clip_plane *clip, unsigned clip_count, ip_mesh *mesh,
                                     ip_engine_counts *counts, ip_error *err);

/*! ip_extract_full_indexed() : ip_extract_full() welded as it extracts: the result is
 *  ip_mesh_weld() of its soup (ip_mesh_weld_keep_degenerate() with `keep_degenerate`), the same
 *  vertices in the same order, the same triangles; the normals equal to float rounding (the
 *  corners' sums are added in another order). Each vertex is keyed by the grid edge it lies on,
 *  or by the sample it sits on, welded brick by brick on `threads` threads (0 = every core) and
 *  joined across brick faces in brick order, so the result is the same for any number of
 *  threads, and no soup is made. `out` is overwritten (an earlier content is not freed) and
 *  owned by the caller (ip_indexed_mesh_free()); empty after a failure. With `values` (may be
 *  NULL), *values receives per vertex the larger of the two samples at the ends of its edge
 *  (the sample's where the vertex sits on one), an array the caller frees with free() (NULL
 *  after a failure). Counts as ip_extract_full()'s.
 *  @return IP_OK, IP_ERR_ARGUMENT (no such level, or more than 2^32 - 2 vertices),
 *  IP_ERR_NOMEM or a brick read error. */
IP_API ip_status ip_extract_full_indexed(ip_cache *cache, float iso, uint32_t level,
                                         unsigned threads, int keep_degenerate,
                                         ip_indexed_mesh *out, float **values,
                                         ip_engine_counts *counts, ip_error *err);

/*! ip_extract_cap() : appends to `mesh` the cap that closes ip_extract_full()'s surface of
 *  level `level` where it leaves the volume's box: on each of the box's 6 faces, the region of
 *  samples >= iso, cut by marching squares on each cell side (corners >= iso and the side's
 *  crossings, the corners of a side with diagonally opposite inside corners cut off apart, as
 *  marching cubes separates them) and fanned. Its rim vertices are the surface's boundary
 *  vertices, bit for bit, so that ip_mesh_weld() of the surface and the cap together is closed
 *  (every edge in two triangles) and encloses the region >= iso within the box. Triangles are
 *  counter-clockwise seen from outside the box, with the face's outward normal; cell id 0 where
 *  the mesh keeps them. Reads the cells along the faces on the calling thread. Clip planes are
 *  not capped.
 *  @return IP_OK, IP_ERR_ARGUMENT (no such level), IP_ERR_NOMEM or a brick read error. */
IP_API ip_status ip_extract_cap(ip_cache *cache, float iso, uint32_t level, ip_mesh *mesh,
                                ip_error *err);

#endif /* IP_EXPERIMENTAL */

#ifdef __cplusplus
}
#endif
#endif

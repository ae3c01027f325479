/* SPDX-License-Identifier: BSD-3-Clause */
/* isoprop: rendering of extracted meshes, on the GPU (OpenGL 3.3 core) and in software.
 *
 * Both renderers draw the same picture of an ip_mesh seen by an ip_camera (see camera.h for
 * the pixel conventions): triangles are clipped to the near and far planes that
 * ip_camera_depth_range() gives for the volume's world box, the nearest surface wins each
 * pixel, and a covered pixel is shaded from the normal interpolated across its triangle:
 *
 *     c      = |dot(n, v)| / |n|      (two-sided: n is flipped toward the eye; c = 1 if n = 0)
 *     colour = surface * (ambient + diffuse * c) + specular * c^shininess, clamped to [0, 1]
 *
 * where v is the unit vector from the surface point to the eye: a headlight, so the light
 * and the half vector both equal v. An empty pixel of image row y (0 = top) shows
 * mix(background_top, background_bottom, (y + 0.5) / height). Colours go to 8 bits as
 * round(255 * value), alpha is 255 everywhere, and images are stored top row first, 4 bytes
 * (R, G, B, A) per pixel.
 *
 * The software rasterizer ip_raster_mesh() is the exact, deterministic reference: the engine
 * tests compare images pixel by pixel with it. The GPU renderer matches it up to silhouette
 * pixels and a few levels of rounding (see tests/test_render.c for the measured tolerances).
 */
#ifndef ISOPROP_RENDER_H
#define ISOPROP_RENDER_H

#include <stddef.h>
#include <stdint.h>

#include "isoprop/camera.h"
#include "isoprop/mesh.h"
#include "isoprop/orientation.h"
#include "isoprop/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The shading parameters shared by both renderers; colours are 0..1 per channel. */
typedef struct ip_shading {
    uint32_t size;    /* bytes of the struct as the caller compiled it (IP_SIZED); see status.h */
    float surface[3]; /* the surface colour (a light bone/ivory) */
    float ambient;    /* light a surface gets when seen edge-on */
    float diffuse;    /* Lambert weight of the headlight */
    float specular;   /* weight of the white highlight */
    float shininess;  /* exponent of the highlight */
    float background_top[3];    /* background colour of the top image row */
    float background_bottom[3]; /* background colour of the bottom image row */
} ip_shading;

/*! ip_shading_default() : the parameters both renderers use unless given others.
 *  Thread-safe. */
IP_API void ip_shading_default(ip_shading *shading);

/*! ip_shading_check() : validates shading parameters: every colour channel in [0, 1];
 *  ambient, diffuse and specular finite and >= 0; shininess finite and > 0.
 *  @return IP_OK or IP_ERR_ARGUMENT with a message. Thread-safe. */
IP_API ip_status ip_shading_check(const ip_shading *shading, ip_error *err);

/*! ip_raster_mesh() : renders `mesh` in software, the reference for the GPU renderer.
 *  `camera` gives the image size (width x height pixels) and the view; near and far planes
 *  come from ip_camera_depth_range(camera, lo, hi), lo and hi being the world box of the
 *  volume (world units). A pixel is covered by a triangle when its centre (x + 0.5, y + 0.5)
 *  lies inside the triangle's projection, vertices being snapped to 1/256 pixel; a centre
 *  exactly on an edge belongs to the triangle only for a top edge (horizontal, the triangle
 *  below it) or a left edge, so triangles that share an edge cover each pixel once, without
 *  gaps. Triangles are clipped to the near and far planes first. Depth is compared in double
 *  precision (1 / view depth, interpolated); the nearest triangle wins, and on equal depth
 *  the lower triangle index wins (as OpenGL's GL_LESS with triangles drawn in order), so
 *  coverage depends on the set of triangles only, never on their order.
 *  Degenerate triangles (zero projected area) cover nothing.
 *  `triangle_index` (may be NULL): width * height entries, top row first, filled with the
 *  index in `mesh` of the triangle each pixel shows, or UINT32_MAX where it shows none.
 *  `rgba` (may be NULL): width * height * 4 bytes, filled with the shaded image described at
 *  the top of this header. Both buffers are owned by the caller.
 *  Single-threaded; reentrant (no shared state), so calls may run concurrently.
 *  Triangles with a non-finite coordinate are skipped.
 *  @return IP_OK, IP_ERR_ARGUMENT (bad camera or box, image over 65536 pixels a side, mesh
 *  with UINT32_MAX triangles or more) or IP_ERR_NOMEM (working buffers: about 12 bytes a
 *  pixel, 24 with rgba). */
IP_API ip_status ip_raster_mesh(const ip_mesh *mesh, const ip_camera *camera, const double lo[3],
                                const double hi[3], uint32_t *triangle_index, uint8_t *rgba,
                                ip_error *err);

/*! ip_raster_mesh_shaded() : ip_raster_mesh() with the given shading (a surface colour and
 *  a background of the caller's, say) instead of ip_shading_default()'s; NULL is the default.
 *  `shading` is read during the call only.
 *  @return as ip_raster_mesh(), and IP_ERR_ARGUMENT when ip_shading_check() fails. */
IP_API ip_status ip_raster_mesh_shaded(const ip_mesh *mesh, const ip_camera *camera,
                                       const ip_shading *shading, const double lo[3],
                                       const double hi[3], uint32_t *triangle_index, uint8_t *rgba,
                                       ip_error *err);

/* One surface of a several-surface image (ip_raster_surfaces(), ip_renderer_draw_surfaces()):
 * a mesh with its own colour and opacity. The other shading terms are the shading's. */
typedef struct ip_surface {
    const ip_mesh *mesh; /* read during the call only */
    float colour[3];     /* replaces ip_shading.surface for this mesh; 0..1 per channel */
    float opacity;       /* 1: opaque; (0, 1): translucent, drawn by the front-layer rule */
} ip_surface;

/* The most surfaces one image takes. */
#define IP_MAX_SURFACES 16

/* The canvas: ip_raster_mesh_shaded()'s image of a mesh that grows frame after frame, kept
 * between frames, so that a frame draws only the triangles added since the last one and
 * shades only the pixels they changed (an interactive viewer on a machine without a GPU).
 * After ip_canvas_begin() and ip_canvas_add() calls that added triangles [0, n) of a mesh in
 * any number of pieces, the image and the triangle ids are exactly those ip_raster_mesh_shaded()
 * gives for the mesh's first n triangles: the nearest triangle wins, the lower index on equal
 * depth, which is also the one drawn first. Rows are drawn in bands on the canvas's threads.
 * A canvas is used by one thread at a time. */
typedef struct ip_canvas ip_canvas;

/*! ip_png_write() : writes an image given as width * height * 4 bytes (RGBA, top row first)
 *  as an 8-bit PNG: RGB when every alpha is 255, RGBA otherwise. The file appears only once
 *  complete (atomic); an existing `path` is replaced only when `force` is non-zero, and
 *  only when it is a regular file (isoprop/output.h).
 *  Reentrant. @return IP_OK, IP_ERR_EXISTS, IP_ERR_ARGUMENT (an empty image, or a path that
 *  is not a regular file), IP_ERR_NOMEM or IP_ERR_IO. */
IP_API ip_status ip_png_write(const char *path, const uint8_t *rgba, uint32_t width,
                              uint32_t height, int force, ip_error *err);

/* A headless OpenGL 3.3 core context: EGL on Mesa's surfaceless platform (no window, no
 * display server; llvmpipe where no GPU is present). It has no default framebuffer: draw into
 * a framebuffer object. The EGL display is process-wide and, once initialised, is left
 * initialised, because terminating it would destroy every other context on it. */
typedef struct ip_gl_context ip_gl_context;

/* The GPU renderer: holds the mesh in GPU buffers and draws it with the shading above.
 * A renderer is not thread-safe. A headless renderer makes its own context current on the
 * calling thread at each call, so it may move between threads provided the thread that used
 * it last calls ip_renderer_release() first; a renderer on the caller's context needs that
 * context current at every call. OpenGL state the calls change, which a caller sharing the
 * context must set again for its own drawing: the bound framebuffers, renderbuffer, vertex
 * array, program and buffers (array, copy, pixel pack: 0 afterwards); the viewport; depth
 * test (on, GL_LESS, writes on); face culling, blending, scissor test, depth clamp and sRGB
 * conversion (off); multisampling (on); polygon mode (fill); colour mask (all on); pack
 * alignment and row layout (1, tight). */
typedef struct ip_renderer ip_renderer;

/*! ip_renderer_create_headless() : a renderer with its own headless context and an
 *  off-screen framebuffer of width x height pixels (RGBA8 colour, 24-bit depth).
 *  @return IP_OK, IP_ERR_ARGUMENT (a size of 0 or over the GL limit), IP_ERR_UNSUPPORTED
 *  (no headless OpenGL 3.3 core here) or IP_ERR_NOMEM; *out is NULL on failure. */
IP_API ip_status ip_renderer_create_headless(uint32_t width, uint32_t height, ip_renderer **out,
                                             ip_error *err);

/*! ip_renderer_resize() : changes the image size (pixels). A headless renderer reallocates
 *  its off-screen framebuffer; otherwise the caller has resized its framebuffer already.
 *  @return IP_OK, IP_ERR_ARGUMENT or IP_ERR_NOMEM (the old size remains). */
IP_API ip_status ip_renderer_resize(ip_renderer *renderer, uint32_t width, uint32_t height,
                                    ip_error *err);

/*! ip_renderer_upload() : appends the triangles [first_triangle, mesh->triangle_count) of
 *  `mesh` to the renderer's GPU buffers. The buffers grow geometrically, copying what they
 *  hold on the GPU, so what was uploaded before is never sent again. The caller keeps `mesh`
 *  (it is read during the call only) and decides what to append: passing the count uploaded
 *  so far appends exactly the triangles added since.
 *  @return IP_OK, IP_ERR_ARGUMENT (first_triangle > mesh->triangle_count) or IP_ERR_NOMEM
 *  (GPU memory; nothing of this call is kept). */
IP_API ip_status ip_renderer_upload(ip_renderer *renderer, const ip_mesh *mesh,
                                    uint64_t first_triangle, ip_error *err);

/*! ip_renderer_clear_mesh() : forgets every uploaded triangle, keeping the GPU buffers. */
IP_API void ip_renderer_clear_mesh(ip_renderer *renderer);

/*! ip_renderer_triangle_count() : the number of triangles uploaded and not cleared. */
IP_API uint64_t ip_renderer_triangle_count(const ip_renderer *renderer);

/*! ip_renderer_draw() : draws the background and the uploaded triangles in upload order,
 *  seen by `camera` (whose width and height must be the renderer's), with near and far planes
 *  from ip_camera_depth_range(camera, lo, hi) for the volume's world box [lo, hi].
 *  The image is complete when the call returns from the caller's point of view (OpenGL may
 *  still be working: ip_renderer_read_rgba() waits for it).
 *  @return IP_OK, IP_ERR_ARGUMENT (bad camera or box, size mismatch) or IP_ERR_UNSUPPORTED
 *  (an OpenGL error, named in the message). */
IP_API ip_status ip_renderer_draw(ip_renderer *renderer, const ip_camera *camera,
                                  const double lo[3], const double hi[3], ip_error *err);

/*! ip_renderer_set_shading() : the shading of later draws (NULL: ip_shading_default(),
 *  which a new renderer starts with); copied. Needs no context.
 *  @return IP_OK or IP_ERR_ARGUMENT (ip_shading_check() fails; the shading stays). */
IP_API ip_status ip_renderer_set_shading(ip_renderer *renderer, const ip_shading *shading,
                                         ip_error *err);

/*! ip_renderer_read_rgba() : copies the image drawn last into `rgba` (width * height * 4
 *  bytes, caller-owned), top row first, waiting for OpenGL to finish.
 *  @return IP_OK or IP_ERR_UNSUPPORTED (an OpenGL error). */
IP_API ip_status ip_renderer_read_rgba(ip_renderer *renderer, uint8_t *rgba, ip_error *err);

/*! ip_renderer_destroy() : frees the GPU objects and, for a headless renderer, its context
 *  (NULL is a no-op). A renderer on the caller's context needs that context current. */
IP_API void ip_renderer_destroy(ip_renderer *renderer);

/* ---- figure overlays: an axis triad and a scale bar, drawn into a finished image ----
 *
 * Both draw into an RGBA image as the renderers give it (width * height * 4 bytes, top row
 * first; the camera's width and height), after rendering, so they look the same whichever
 * renderer drew it, with or without anti-aliasing. Each draws only inside a box in one corner,
 * which it reports as {x0, y0, x1, y1} (pixels; x0, y0 included, x1, y1 excluded): the triad
 * in the bottom-left corner, the scale bar in the bottom-right; an overlay that would not fit
 * whole in the image is refused, never cut. Their sizes follow the
 * image's smaller side s: text (stb_easy_font's, scaled by round(s / 240), 1 to 4), the
 * triad's arms 8 % of s (at least 16 pixels). Lines are anti-aliased, text is not. */

/* A scale bar: a round length and what it spans in the image at the target's depth. */
typedef struct ip_scale_bar {
    double length;     /* world units (the spacing's): 1, 2 or 5 times a power of ten */
    double pixel_size; /* world units one pixel spans at the depth of the camera's target */
    double pixels;     /* length / pixel_size: the bar's length in the image, pixels */
} ip_scale_bar;

/* ---- Experimental (IP_EXPERIMENTAL) ----
 * Declared only where IP_EXPERIMENTAL is defined before the include (docs/api.md,
 * "Stability"): calls for advanced uses that may change in a minor version, as the
 * programs use them. Exported all the same. */
#ifdef IP_EXPERIMENTAL

/*! ip_render_check_box() : validates the world box [lo, hi] (world units) that both
 *  renderers take for their near and far planes: finite, lo <= hi on every axis.
 *  @return IP_OK or IP_ERR_ARGUMENT with a message. Thread-safe. */
IP_API ip_status ip_render_check_box(const double lo[3], const double hi[3], ip_error *err);

/*! ip_surfaces_check() : validates surfaces for a several-surface image: 1 to
 *  IP_MAX_SURFACES of them, each with a mesh, colour channels in [0, 1] and an opacity in
 *  (0, 1]. @return IP_OK or IP_ERR_ARGUMENT with a message. Thread-safe. */
IP_API ip_status ip_surfaces_check(const ip_surface *surfaces, size_t count, ip_error *err);

/*! ip_raster_surfaces() : renders several surfaces into one image in software, the reference
 *  for ip_renderer_draw_surfaces(). The rule ("front layer only"), per pixel: the opaque
 *  surfaces (opacity 1) are one depth-tested scene, as ip_raster_mesh() draws one mesh (on
 *  equal depth the lower surface index wins, then the lower triangle index), shaded with
 *  their own colours over the background; then each translucent surface, in index order, is
 *  blended over that colour with its opacity a, colour = a * shaded + (1 - a) * colour,
 *  rounded to 8 bits after each blend, at the pixels where its own nearest fragment is at
 *  least as near as the nearest opaque fragment (or where no opaque surface is). Only the
 *  nearest layer of a translucent surface shows, and it hides nothing of the others: the
 *  image depends on the surfaces' order, never on the order of the triangles. With every
 *  surface opaque the image is that of the meshes concatenated in index order, each pixel
 *  shaded with the colour of the surface it shows. `shading` (NULL: ip_shading_default())
 *  gives the background and the lighting terms; its surface colour is not used. `rgba`:
 *  width * height * 4 bytes, caller-owned. Single-threaded; reentrant.
 *  @return IP_OK, IP_ERR_ARGUMENT (as ip_raster_mesh_shaded(), ip_surfaces_check() fails, or
 *  `rgba` is NULL) or IP_ERR_NOMEM (24 bytes a pixel for the opaque surfaces together, 24
 *  more for each translucent one). */
IP_API ip_status ip_raster_surfaces(const ip_surface *surfaces, size_t count,
                                    const ip_camera *camera, const ip_shading *shading,
                                    const double lo[3], const double hi[3], uint8_t *rgba,
                                    ip_error *err);

/*! ip_raster_mesh_part() : the part [x, x + width) x [y, y + height) (pixels) of the image
 *  that ip_raster_mesh_shaded() draws of `mesh` for `camera` (the whole image's view, near and
 *  far planes, guard band and background gradient), with the nearest depth: each pixel of the
 *  part gets exactly the colour it has in the whole image, at a cost that grows with the
 *  part's pixels, not the image's (triangles outside it are rejected by their bounds). For
 *  sort-first parallel rendering, where each process draws its own triangles into the tiles
 *  of a display wall and a composite keeps the nearest surface per pixel.
 *  `inverse_depth` (may be NULL): width * height entries, top row first, 1 / view depth (world
 *  units) of the surface each pixel shows, 0 where it shows none (a larger value is nearer).
 *  `rgba` (may be NULL): width * height * 4 bytes, the shaded part. `shading` NULL is
 *  ip_shading_default(). Buffers are the caller's. Reentrant.
 *  @return IP_OK, IP_ERR_ARGUMENT (as ip_raster_mesh_shaded(), or a part that is empty or not
 *  inside the image) or IP_ERR_NOMEM. */
IP_API ip_status ip_raster_mesh_part(const ip_mesh *mesh, const ip_camera *camera,
                                     const ip_shading *shading, const double lo[3],
                                     const double hi[3], uint32_t x, uint32_t y, uint32_t width,
                                     uint32_t height, double *inverse_depth, uint8_t *rgba,
                                     ip_error *err);

/*! ip_canvas_create() : an empty canvas drawing on `threads` threads (0: every core; the
 *  calling thread counts, the others are started here and sleep between calls). *out is the
 *  caller's, released with ip_canvas_destroy(). @return IP_OK or IP_ERR_NOMEM. */
IP_API ip_status ip_canvas_create(unsigned threads, ip_canvas **out, ip_error *err);

/*! ip_canvas_destroy() : stops the canvas's threads and frees it (NULL is a no-op). */
IP_API void ip_canvas_destroy(ip_canvas *canvas);

/*! ip_canvas_begin() : starts a new image of camera->width x camera->height pixels seen by
 *  `camera`, near and far planes from the box [lo, hi] (world units) as ip_raster_mesh(), with
 *  `shading` (copied; NULL: ip_shading_default()): every pixel the background, no triangle.
 *  The buffers grow to the size (about 29 bytes a pixel) and are kept for later images.
 *  @return IP_OK, IP_ERR_ARGUMENT (a bad camera, box or shading, a side over 65536) or
 *  IP_ERR_NOMEM (the canvas then holds no image until the next successful begin). */
IP_API ip_status ip_canvas_begin(ip_canvas *canvas, const ip_camera *camera,
                                 const ip_shading *shading, const double lo[3], const double hi[3],
                                 ip_error *err);

/*! ip_canvas_add() : draws triangles [first, mesh->triangle_count) of `mesh`, numbered as in
 *  the mesh; `first` must be the number of triangles the canvas holds
 *  (ip_canvas_triangle_count()), so that the pieces added since begin are one mesh's first
 *  triangles, in order. `mesh` is read during the call only.
 *  @return IP_OK or IP_ERR_ARGUMENT (no begin, another `first`, UINT32_MAX triangles or
 *  more). */
IP_API ip_status ip_canvas_add(ip_canvas *canvas, const ip_mesh *mesh, uint64_t first,
                               ip_error *err);

/*! ip_canvas_shade() : shades the pixels changed since the last call (every pixel after
 *  begin) and returns the image: width * height * 4 bytes (RGBA, top row first), owned by the
 *  canvas, valid until the next begin or destroy. `rows` (may be NULL) receives the rows
 *  [rows[0], rows[1]) that hold every pixel changed by this call ({0, 0}: none), the part a
 *  caller showing the image in a texture has to send again. NULL before the first begin. */
IP_API const uint8_t *ip_canvas_shade(ip_canvas *canvas, uint32_t rows[2]);

/*! ip_canvas_triangle_index() : width * height entries, top row first: the index of the
 *  triangle each pixel shows, UINT32_MAX where none; owned by the canvas, current after each
 *  add. NULL before the first begin. */
IP_API const uint32_t *ip_canvas_triangle_index(const ip_canvas *canvas);

/*! ip_canvas_triangle_count() : the triangles added since begin. */
IP_API uint64_t ip_canvas_triangle_count(const ip_canvas *canvas);

/*! ip_canvas_memory() : the bytes of the canvas's image buffers. */
IP_API size_t ip_canvas_memory(const ip_canvas *canvas);

/*! ip_gl_context_create_headless() : creates the context and makes it current on the calling
 *  thread. @return IP_OK, IP_ERR_UNSUPPORTED (no EGL, no surfaceless platform, no OpenGL 3.3
 *  core: the message says which) or IP_ERR_NOMEM; *out is NULL on failure. */
IP_API ip_status ip_gl_context_create_headless(ip_gl_context **out, ip_error *err);

/*! ip_gl_context_make_current() : makes the context current on the calling thread (a no-op
 *  when it already is). A context is current on one thread at most: release it on the other
 *  thread first (ip_gl_context_release()). @return IP_OK or IP_ERR_UNSUPPORTED. */
IP_API ip_status ip_gl_context_make_current(ip_gl_context *context, ip_error *err);

/*! ip_gl_context_release() : makes no context current on the calling thread if `context`
 *  is the current one there. */
IP_API void ip_gl_context_release(ip_gl_context *context);

/*! ip_gl_context_destroy() : destroys the context (NULL is a no-op); call it from the thread
 *  where the context is current, or from any thread if it is current nowhere. */
IP_API void ip_gl_context_destroy(ip_gl_context *context);

/*! ip_gl_program() : compiles `vertex_source` and `fragment_source` (GLSL, NUL-terminated)
 *  and links them into a program on the OpenGL context current on the calling thread (one
 *  must be, 3.3 core or later), for a caller drawing beside the renderer (a viewer's text).
 *  *program receives the program's name (the caller deletes it with glDeleteProgram), 0 on
 *  failure. @return IP_OK, or IP_ERR_UNSUPPORTED with the compiler's or linker's log. */
IP_API ip_status ip_gl_program(const char *vertex_source, const char *fragment_source,
                               unsigned *program, ip_error *err);

/*! ip_renderer_create_current() : a renderer on the OpenGL 3.3 core (or later) context that
 *  is current on the calling thread (for example a window's), drawing into `framebuffer` (0:
 *  the default framebuffer) of width x height pixels. The caller keeps the context current
 *  for every later call, destroy included, and owns the framebuffer.
 *  @return IP_OK, IP_ERR_ARGUMENT, IP_ERR_UNSUPPORTED (no current context, or older than 3.3
 *  core) or IP_ERR_NOMEM. */
IP_API ip_status ip_renderer_create_current(uint32_t width, uint32_t height, uint32_t framebuffer,
                                            ip_renderer **out, ip_error *err);

/*! ip_renderer_driver() : OpenGL's GL_RENDERER for the renderer's context (read once, owned by
 *  the renderer), "unknown" where it cannot be read. A headless renderer makes its context
 *  current on the calling thread. */
IP_API const char *ip_renderer_driver(ip_renderer *renderer);

/*! ip_gl_driver_is_software() : 1 when `gl_renderer` (OpenGL's GL_RENDERER: ip_renderer_driver(),
 *  or a window's) names a software driver (Mesa's llvmpipe, softpipe, swrast), on which the
 *  software rasterizer draws a large mesh faster and in less memory; else 0 (NULL too).
 *  Thread-safe. */
IP_API int ip_gl_driver_is_software(const char *gl_renderer);

/*! ip_renderer_memory() : the bytes of the mesh buffers the renderer holds on the GPU (for
 *  a software OpenGL driver, in the process's memory): those of ip_renderer_upload() (grown
 *  geometrically) and of ip_renderer_draw_mesh()'s streaming, once used. */
IP_API uint64_t ip_renderer_memory(const ip_renderer *renderer);

/*! ip_renderer_draw_added() : draws only the uploaded triangles [first, count) over the image
 *  drawn last, whose colour and depth the framebuffer still holds (a renderer's own, or a
 *  caller's framebuffer object: not a window's, whose back buffer a swap may leave undefined);
 *  `camera` must be the one of that image. The image is then the one ip_renderer_draw() gives
 *  of every uploaded triangle (drawn in order, the nearest wins, the earlier on equal depth),
 *  at the cost of the new triangles only: for a mesh that grows while the view stays. `first`
 *  0 is ip_renderer_draw().
 *  @return as ip_renderer_draw(), and IP_ERR_ARGUMENT when first is past the uploaded count. */
IP_API ip_status ip_renderer_draw_added(ip_renderer *renderer, const ip_camera *camera,
                                        const double lo[3], const double hi[3], uint64_t first,
                                        ip_error *err);

/*! ip_renderer_draw_mesh() : draws the background and the triangles of `mesh`, in order,
 *  like ip_renderer_draw() would after uploading exactly `mesh` (the same image), but
 *  streams them through one GPU buffer of 65,536 triangles, so that neither the GPU nor the
 *  driver holds a second copy of a large mesh: for one-off images. The uploaded triangles are
 *  left alone and not drawn. `mesh` is read during the call only.
 *  @return as ip_renderer_draw(). */
IP_API ip_status ip_renderer_draw_mesh(ip_renderer *renderer, const ip_mesh *mesh,
                                       const ip_camera *camera, const double lo[3],
                                       const double hi[3], ip_error *err);

/*! ip_renderer_draw_surfaces() : draws the background and several surfaces by the rule of
 *  ip_raster_surfaces() (the opaque ones depth-tested together; then each translucent one,
 *  in index order, by a depth pass of the opaque surfaces and of itself and a blended colour
 *  pass of its fragments at that depth), streamed as ip_renderer_draw_mesh() streams one
 *  mesh. The renderer's shading gives the background and the lighting terms; each surface
 *  its colour and opacity. The uploaded triangles are left alone and not drawn. One opaque
 *  surface gives ip_renderer_draw_mesh()'s image with that colour. The meshes are read
 *  during the call only.
 *  @return as ip_renderer_draw(), and IP_ERR_ARGUMENT when ip_surfaces_check() fails. */
IP_API ip_status ip_renderer_draw_surfaces(ip_renderer *renderer, const ip_surface *surfaces,
                                           size_t count, const ip_camera *camera,
                                           const double lo[3], const double hi[3], ip_error *err);

/*! ip_renderer_set_samples() : anti-aliasing of a headless renderer: each pixel of later
 *  draws keeps `samples` coverage and depth samples (OpenGL multisampling; 1: none, the
 *  default), averaged when the image is read, so silhouettes get intermediate colours while
 *  a pixel inside a surface keeps the colour shaded at its centre. Reallocates the
 *  off-screen framebuffer, discarding the image drawn last. For a renderer on the caller's
 *  context, the caller's framebuffer decides and only 1 is accepted.
 *  @return IP_OK, IP_ERR_ARGUMENT (0, or more than OpenGL's GL_MAX_SAMPLES: the message says
 *  the limit; the setting stays), IP_ERR_UNSUPPORTED or IP_ERR_NOMEM. */
IP_API ip_status ip_renderer_set_samples(ip_renderer *renderer, uint32_t samples, ip_error *err);

/*! ip_renderer_set_mirror() : with `mirror` non-zero, later draws give the mirror image, its
 *  columns reversed (column x shows what column width - 1 - x shows without), the background
 *  unchanged: the physical view of a world camera whose file's orientation mirrors
 *  (isoprop/camera.h, "Views in physical space"). 0, the default, draws the camera's own
 *  image. Needs no context. */
IP_API void ip_renderer_set_mirror(ip_renderer *renderer, int mirror);

/*! ip_renderer_release() : makes a headless renderer's context no longer current on the
 *  calling thread, so that another thread may use the renderer; a no-op for a renderer on the
 *  caller's context. */
IP_API void ip_renderer_release(ip_renderer *renderer);

/*! ip_overlay_text_width() : the width in pixels of one line of `text` as
 *  ip_overlay_draw_text() draws it at `scale` (1 to 16); 0 for NULL text or another scale.
 *  Thread-safe. */
IP_API uint32_t ip_overlay_text_width(const char *text, int scale);

/*! ip_overlay_draw_text() : draws one line of `text` into `rgba` (width * height * 4 bytes,
 *  RGBA, top row first; caller-owned) with its top-left corner at pixel (left, top) (within
 *  2^24 of the image; what falls outside it is clipped): stb_easy_font's glyphs, capitals 7
 *  pixels high at `scale` 1, scaled by `scale` (1 to 16), opaque in `ink` (RGB), not
 *  anti-aliased; with `shadow` (RGB, may be NULL), the whole text first in that colour one
 *  text pixel down and right. A byte outside printable ASCII (UTF-8, a control character,
 *  '\n') is drawn as '?'. Thread-safe on distinct images.
 *  @return IP_OK or IP_ERR_ARGUMENT (a NULL image, text or ink, an empty image, a scale or a
 *  corner out of range). */
IP_API ip_status ip_overlay_draw_text(uint8_t *rgba, uint32_t width, uint32_t height, int left,
                                      int top, const char *text, int scale, const uint8_t ink[3],
                                      const uint8_t shadow[3], ip_error *err);

/*! ip_scale_bar_choose() : the longest length of 1, 2 or 5 times a power of ten world units
 *  whose bar spans at most `max_pixels` (> 0) pixels at the depth of the camera's target,
 *  where a pixel spans ip_camera_pixel_size(camera, height) world units. The view is a
 *  perspective one: the bar holds for lengths at that depth, across the view (nearer
 *  lengths look longer, farther ones shorter). `bar` (caller-owned) receives it. Thread-safe.
 *  @return IP_OK, or IP_ERR_ARGUMENT (a bad camera, max_pixels not finite and > 0, a NULL
 *  bar). */
IP_API ip_status ip_scale_bar_choose(const ip_camera *camera, double max_pixels, ip_scale_bar *bar,
                                     ip_error *err);

/*! ip_overlay_axis_directions() : how the camera sees the axes of the volume's physical space
 *  (origin + D * world: isoprop/orientation.h; the world's own axes when D is the identity).
 *  screen[a] receives the unit world direction of physical axis a (row a of D) in the
 *  camera's basis: {right, down (image y), toward the eye}, so that {screen[a][0],
 *  screen[a][1]} is where the axis points in the image, the image being the physical view's:
 *  where D mirrors (ip_orientation_mirrors()), the world camera's image with its columns
 *  reversed (isoprop/camera.h, "Views in physical space"), and right the other way. The
 *  camera (world units) must pass ip_camera_check(), the orientation ip_orientation_check().
 *  Thread-safe. */
IP_API void ip_overlay_axis_directions(const ip_camera *camera, const ip_orientation *orientation,
                                       double screen[3][3]);

/*! ip_overlay_axis_label() : the label of physical axis `axis` (0, 1, 2) in `space`: the
 *  anatomical direction its positive end points to ("R", "A", "S" in RAS; "L", "A", "S" in
 *  LAS; "L", "P", "S" in LPS), or "x", "y", "z" where the space is unknown; "" for another
 *  axis. A static string. Thread-safe. */
IP_API const char *ip_overlay_axis_label(ip_space space, int axis);

/*! ip_overlay_axes_check() : whether the axis triad fits whole in an image of width x height
 *  pixels (the arms' 16-pixel minimum and the labels need 63x62 pixels at least).
 *  Thread-safe. @return IP_OK or IP_ERR_ARGUMENT, the message giving the size needed. */
IP_API ip_status ip_overlay_axes_check(uint32_t width, uint32_t height, ip_error *err);

/*! ip_overlay_draw_axes() : draws the axis triad into `rgba` (the camera's size) in the
 *  bottom-left corner: an arm for each physical axis (ip_overlay_axis_directions(); x red,
 *  y green, z blue) from a common centre, the nearer arms over the farther ones, each
 *  labelled at its tip (ip_overlay_axis_label()). An arm along the view is short, as the
 *  camera sees it. `box` (may be NULL) receives the corner box drawn in. Thread-safe on
 *  distinct images.
 *  @return IP_OK or IP_ERR_ARGUMENT (a bad camera, a NULL image or orientation, an image the
 *  triad does not fit: ip_overlay_axes_check(); nothing is drawn). */
IP_API ip_status ip_overlay_draw_axes(uint8_t *rgba, const ip_camera *camera,
                                      const ip_orientation *orientation, uint32_t box[4],
                                      ip_error *err);

/*! ip_overlay_draw_scale_bar() : draws `bar` (ip_scale_bar_choose()) into `rgba` (the
 *  camera's size) in the bottom-right corner: a horizontal bar round(bar->pixels) pixels long
 *  (at least 1), with end ticks inside that length, under the label "LENGTH UNIT" (`unit`
 *  may be NULL or "": the length alone; a byte outside printable ASCII is drawn as '?', the
 *  font has no other glyphs); light on a dark corner, dark where the corner's mean luma is
 *  over 140 of 255 (a white background). `box` (may be NULL) receives the corner box drawn
 *  in; `bar_box` (may be NULL) the bar's own pixels, ticks included. `unit` is read during
 *  the call only. Thread-safe on distinct images.
 *  @return IP_OK, IP_ERR_ARGUMENT (a bad camera, a NULL image, a bar that is not finite and
 *  > 0, or a bar or label that would not fit whole in the image: nothing is drawn) or
 *  IP_ERR_NOMEM. */
IP_API ip_status ip_overlay_draw_scale_bar(uint8_t *rgba, const ip_camera *camera,
                                           const ip_scale_bar *bar, const char *unit,
                                           uint32_t box[4], uint32_t bar_box[4], ip_error *err);

#endif /* IP_EXPERIMENTAL */

#ifdef __cplusplus
}
#endif
#endif

/* SPDX-License-Identifier: BSD-3-Clause */
/* Tests of the OpenGL renderer against the software rasterizer; skipped without headless EGL. */
#include <epoxy/gl.h>
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "isoprop/render.h"

/* Tolerances, measured on llvmpipe and kept with a margin:
 * - coverage: pixels covered by one renderer and not the other happen only where a pixel
 *   centre lies within float rounding of a silhouette edge (OpenGL projects in float, the
 *   rasterizer in double before both snap to 1/256 pixel); at most 0.5 % of covered pixels;
 * - shading: OpenGL interpolates and shades in float, the rasterizer in double, and 8-bit
 *   rounding of nearly equal values may go either way: measured at most 1 level, asserted
 *   2. Pixels differing more are those where another surface wins a near tie in depth: along
 *   the curve where two surfaces cross, OpenGL compares 24-bit depths and the rasterizer
 *   doubles (measured 0.05 % of the pixels both cover in the inside view); asserted under
 *   0.5 %. The background differs by at most 1 level. */
#define COVERAGE_MISMATCH_FRACTION 0.005
#define SHADE_LEVELS 2
#define SHADE_OUTLIER_FRACTION 0.005

static const double scene_lo[3] = {-1.2, -1.2, -1.2}, scene_hi[3] = {1.5, 1.5, 1.5};

static ip_camera scene_camera(uint32_t width, uint32_t height)
{
    ip_camera c = {.eye = {2.5, -3.0, 1.8},
                   .target = {0.1, 0, 0.1},
                   .up = {0, 0, 1},
                   .fov_y = 45,
                   .width = width,
                   .height = height};
    return c;
}

static void add_triangle(ip_mesh *m, const float a[3], const float b[3], const float c[3],
                         const float na[3], const float nb[3], const float nc[3])
{
    float p[9], n[9];
    memcpy(p, a, 12), memcpy(p + 3, b, 12), memcpy(p + 6, c, 12);
    memcpy(n, na, 12), memcpy(n + 3, nb, 12), memcpy(n + 6, nc, 12);
    uint64_t cell = m->triangle_count;
    REQUIRE(ip_mesh_append_float_normals(m, p, n, &cell, 1) == IP_OK);
}

static void midpoint(const float a[3], const float b[3], float out[3])
{
    float s[3] = {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
    float len = sqrtf(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    for (int i = 0; i < 3; i++)
        out[i] = s[i] / len;
}

/* A unit sphere: an icosahedron subdivided `level` times; normals point inward (the data
 * would be higher outside). Shared edges get bit-identical midpoints, so it is watertight. */
static void add_sphere_face(ip_mesh *m, const float a[3], const float b[3], const float c[3],
                            int level)
{
    if (level == 0) {
        float na[3] = {-a[0], -a[1], -a[2]}, nb[3] = {-b[0], -b[1], -b[2]};
        float nc[3] = {-c[0], -c[1], -c[2]};
        add_triangle(m, a, b, c, na, nb, nc);
        return;
    }
    float ab[3], bc[3], ca[3];
    midpoint(a, b, ab);
    midpoint(b, c, bc);
    midpoint(c, a, ca);
    add_sphere_face(m, a, ab, ca, level - 1);
    add_sphere_face(m, ab, b, bc, level - 1);
    add_sphere_face(m, ca, bc, c, level - 1);
    add_sphere_face(m, ab, bc, ca, level - 1);
}

static void add_sphere(ip_mesh *m, int level)
{
    const float t = 1.6180339887f, s = 1.0f / sqrtf(1.0f + t * t), u = t * s;
    const float v[12][3] = {{-s, u, 0}, {s, u, 0}, {-s, -u, 0}, {s, -u, 0},
                            {0, -s, u}, {0, s, u}, {0, -s, -u}, {0, s, -u},
                            {u, 0, -s}, {u, 0, s}, {-u, 0, -s}, {-u, 0, s}};
    static const int f[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    for (int i = 0; i < 20; i++)
        add_sphere_face(m, v[f[i][0]], v[f[i][1]], v[f[i][2]], level);
}

/* An axis-aligned box [lo, hi] with outward normals, cutting into the sphere. */
static void add_box(ip_mesh *m, const float lo[3], const float hi[3])
{
    for (int axis = 0; axis < 3; axis++)
        for (int side = 0; side < 2; side++) {
            int a = (axis + 1) % 3, b = (axis + 2) % 3;
            float corner[4][3], n[3] = {0, 0, 0};
            n[axis] = side ? 1.0f : -1.0f;
            for (int k = 0; k < 4; k++) {
                corner[k][axis] = side ? hi[axis] : lo[axis];
                corner[k][a] = (k == 1 || k == 2) ? hi[a] : lo[a];
                corner[k][b] = k >= 2 ? hi[b] : lo[b];
            }
            add_triangle(m, corner[0], corner[1], corner[2], n, n, n);
            add_triangle(m, corner[0], corner[2], corner[3], n, n, n);
        }
}

static void build_scene(ip_mesh *m)
{
    ip_mesh_init(m);
    add_sphere(m, 4);
    const float lo[3] = {0.3f, -1.15f, -0.95f}, hi[3] = {1.2f, -0.4f, -0.15f};
    add_box(m, lo, hi);
}

/* 1 when the pixel at image row y shows the background (all channels within 2 levels). */
static int is_background(const uint8_t *px, uint32_t y, uint32_t height)
{
    ip_shading s;
    ip_shading_default(&s);
    double t = (y + 0.5) / height;
    for (int i = 0; i < 3; i++) {
        double top = s.background_top[i], bottom = s.background_bottom[i];
        double v = 255 * (top + t * (bottom - top));
        if (fabs(px[i] - v) > 2.5)
            return 0;
    }
    return 1;
}

/* Compares an OpenGL image with the rasterizer's for the same scene; prints the statistics. */
static void compare_with_raster(const ip_mesh *m, const ip_camera *c, const uint8_t *gl)
{
    size_t pixels = (size_t)c->width * c->height;
    uint32_t *index = malloc(pixels * sizeof *index);
    uint8_t *ref = malloc(pixels * 4);
    REQUIRE(index && ref);
    REQUIRE(ip_raster_mesh(m, c, scene_lo, scene_hi, index, ref, NULL) == IP_OK);
    size_t covered = 0, coverage_mismatch = 0, both = 0, outliers = 0, bad_background = 0;
    int worst = 0;
    for (uint32_t y = 0; y < c->height; y++)
        for (uint32_t x = 0; x < c->width; x++) {
            size_t i = (size_t)y * c->width + x;
            int ref_covered = index[i] != UINT32_MAX;
            int gl_covered = !is_background(gl + 4 * i, y, c->height);
            CHECK_EQ(is_background(ref + 4 * i, y, c->height), !ref_covered);
            covered += ref_covered;
            coverage_mismatch += ref_covered != gl_covered;
            int diff = 0;
            for (int k = 0; k < 4; k++) {
                int d = abs(gl[4 * i + k] - ref[4 * i + k]);
                diff = d > diff ? d : diff;
            }
            if (!ref_covered && !gl_covered)
                bad_background += diff > 1;
            if (!ref_covered || !gl_covered)
                continue;
            both++;
            outliers += diff > SHADE_LEVELS;
            worst = diff > worst ? diff : worst;
        }
    printf("%ux%u: %zu covered, %zu coverage mismatches, %zu shading outliers (> %d levels) "
           "of %zu, worst %d\n",
           c->width, c->height, covered, coverage_mismatch, outliers, SHADE_LEVELS, both, worst);
    CHECK_GT(covered, pixels / 10);
    CHECK_LE(coverage_mismatch, COVERAGE_MISMATCH_FRACTION * covered);
    CHECK_LE(outliers, SHADE_OUTLIER_FRACTION * both);
    CHECK_EQ(bad_background, 0);
    free(index);
    free(ref);
}

static void draw_and_read(ip_renderer *r, const ip_camera *c, uint8_t *rgba)
{
    ip_error err;
    ip_status st = ip_renderer_draw(r, c, scene_lo, scene_hi, &err);
    CHECK_MSG(st == IP_OK, "%s", err.message);
    st = ip_renderer_read_rgba(r, rgba, &err);
    CHECK_MSG(st == IP_OK, "%s", err.message);
}

static void test_against_raster(ip_renderer *r, const ip_mesh *m)
{
    ip_camera c = scene_camera(320, 240);
    uint8_t *gl = malloc(320 * 240 * 4);
    REQUIRE(gl);
    REQUIRE(ip_renderer_upload(r, m, 0, NULL) == IP_OK);
    CHECK_EQ(ip_renderer_triangle_count(r), m->triangle_count);
    draw_and_read(r, &c, gl);
    compare_with_raster(m, &c, gl);
    /* the eye inside the sphere: triangles cross the near plane and reach behind the eye */
    ip_camera inside = {.eye = {0.1, 0.2, 0.0},
                        .target = {0.8, -0.9, -0.4},
                        .up = {0, 0, 1},
                        .fov_y = 80,
                        .width = 320,
                        .height = 240};
    draw_and_read(r, &inside, gl);
    compare_with_raster(m, &inside, gl);
    free(gl);
}

/* Three uploads (with buffer growth) must give the very image of one upload. */
static void test_incremental_upload(ip_renderer *r, const ip_mesh *m)
{
    ip_camera c = scene_camera(320, 240);
    size_t bytes = 320 * 240 * 4;
    uint8_t *once = malloc(bytes), *parts = malloc(bytes), *again = malloc(bytes);
    REQUIRE(once && parts && again);
    ip_renderer_clear_mesh(r);
    REQUIRE(ip_renderer_upload(r, m, 0, NULL) == IP_OK);
    draw_and_read(r, &c, once);
    draw_and_read(r, &c, again);
    CHECK_MEM_EQ(once, again, bytes);

    ip_renderer *fresh = NULL;
    REQUIRE(ip_renderer_create_headless(320, 240, &fresh, NULL) == IP_OK);
    ip_mesh partial;
    ip_mesh_init(&partial);
    const uint64_t cuts[4] = {0, 1000, 4100, m->triangle_count};
    for (int k = 0; k < 3; k++) {
        uint64_t count = cuts[k + 1] - cuts[k];
        REQUIRE(ip_mesh_append_mesh(&partial, m, cuts[k], count) == IP_OK);
        CHECK_EQ(ip_renderer_upload(fresh, &partial, cuts[k], NULL), IP_OK);
        CHECK_EQ(ip_renderer_triangle_count(fresh), cuts[k + 1]);
    }
    draw_and_read(fresh, &c, parts);
    CHECK_MEM_EQ(once, parts, bytes);

    /* drawing only what each upload added over the image drawn before gives the same image */
    ip_renderer *added = NULL;
    REQUIRE(ip_renderer_create_headless(320, 240, &added, NULL) == IP_OK);
    for (int k = 0; k < 3; k++) {
        ip_mesh prefix = *m;
        prefix.triangle_count = cuts[k + 1];
        REQUIRE(ip_renderer_upload(added, &prefix, cuts[k], NULL) == IP_OK);
        ip_error why;
        CHECK_MSG(ip_renderer_draw_added(added, &c, scene_lo, scene_hi, cuts[k], &why) == IP_OK,
                  "%s", why.message);
    }
    REQUIRE(ip_renderer_read_rgba(added, again, NULL) == IP_OK);
    CHECK_MEM_EQ(once, again, bytes);
    ip_error why;
    CHECK_EQ(ip_renderer_draw_added(added, &c, scene_lo, scene_hi, m->triangle_count + 1, &why),
             IP_ERR_ARGUMENT);
    ip_renderer_destroy(added);

    /* nothing to append, then a first triangle past the end */
    ip_error err;
    CHECK_EQ(ip_renderer_upload(fresh, &partial, partial.triangle_count, &err), IP_OK);
    CHECK_EQ(ip_renderer_upload(fresh, &partial, partial.triangle_count + 1, &err),
             IP_ERR_ARGUMENT);
    CHECK_EQ(ip_renderer_triangle_count(fresh), m->triangle_count);

    /* cleared: the background alone, as the rasterizer draws it for an empty mesh */
    ip_renderer_clear_mesh(fresh);
    CHECK_EQ(ip_renderer_triangle_count(fresh), 0);
    draw_and_read(fresh, &c, parts);
    ip_mesh empty;
    ip_mesh_init(&empty);
    REQUIRE(ip_raster_mesh(&empty, &c, scene_lo, scene_hi, NULL, again, NULL) == IP_OK);
    int worst = 0;
    for (size_t i = 0; i < bytes; i++)
        worst = abs(parts[i] - again[i]) > worst ? abs(parts[i] - again[i]) : worst;
    CHECK_LE(worst, 1);
    ip_renderer_destroy(fresh);
    ip_mesh_free(&partial);
    free(once);
    free(parts);
    free(again);
}

/* Streaming a mesh in parts (more than one part: 65,536 triangles each) gives the very image
 * of uploading it whole, and leaves the uploaded triangles alone. */
static void test_streamed_draw(ip_renderer *r)
{
    ip_mesh big;
    ip_mesh_init(&big);
    add_sphere(&big, 6); /* 81,920 triangles */
    const float lo[3] = {0.3f, -1.15f, -0.95f}, hi[3] = {1.2f, -0.4f, -0.15f};
    add_box(&big, lo, hi);
    REQUIRE(big.triangle_count > 65536);
    ip_camera c = scene_camera(320, 240);
    size_t bytes = 320 * 240 * 4;
    uint8_t *whole = malloc(bytes), *streamed = malloc(bytes), *empty = malloc(bytes);
    REQUIRE(whole && streamed && empty);
    ip_error err;
    ip_renderer_clear_mesh(r);
    REQUIRE(ip_renderer_upload(r, &big, 0, NULL) == IP_OK);
    draw_and_read(r, &c, whole);
    ip_renderer_clear_mesh(r);
    CHECK_EQ(ip_renderer_draw_mesh(r, &big, &c, scene_lo, scene_hi, &err), IP_OK);
    CHECK_EQ(ip_renderer_read_rgba(r, streamed, &err), IP_OK);
    CHECK_MSG(memcmp(whole, streamed, bytes) == 0, "a streamed draw differs from one draw");
    CHECK_EQ(ip_renderer_triangle_count(r), 0);
    /* an empty mesh: the background alone */
    ip_mesh none;
    ip_mesh_init(&none);
    CHECK_EQ(ip_renderer_draw_mesh(r, &none, &c, scene_lo, scene_hi, &err), IP_OK);
    CHECK_EQ(ip_renderer_read_rgba(r, streamed, &err), IP_OK);
    draw_and_read(r, &c, empty);
    CHECK_MEM_EQ(empty, streamed, bytes);
    /* a camera of another size is refused */
    ip_camera small = scene_camera(100, 80);
    CHECK_EQ(ip_renderer_draw_mesh(r, &big, &small, scene_lo, scene_hi, &err), IP_ERR_ARGUMENT);
    free(whole);
    free(streamed);
    free(empty);
    ip_mesh_free(&big);
}

/* Draws the surfaces with OpenGL and in software; returns how many pixels differ by more
 * than SHADE_LEVELS + 1 (blending rounds once more) and prints the statistics. */
static size_t surfaces_outliers(ip_renderer *r, const ip_surface *f, size_t count,
                                const ip_camera *c, uint8_t *gl)
{
    size_t pixels = (size_t)c->width * c->height, outliers = 0;
    uint8_t *ref = malloc(pixels * 4);
    REQUIRE(ref);
    ip_error err;
    ip_status st = ip_renderer_draw_surfaces(r, f, count, c, scene_lo, scene_hi, &err);
    CHECK_MSG(st == IP_OK, "%s", err.message);
    CHECK_EQ(ip_renderer_read_rgba(r, gl, &err), IP_OK);
    REQUIRE(ip_raster_surfaces(f, count, c, NULL, scene_lo, scene_hi, ref, NULL) == IP_OK);
    int worst = 0;
    for (size_t i = 0; i < pixels; i++) {
        int diff = 0;
        for (int k = 0; k < 4; k++) {
            int d = abs(gl[4 * i + k] - ref[4 * i + k]);
            diff = d > diff ? d : diff;
        }
        outliers += diff > SHADE_LEVELS + 1;
        worst = diff > worst ? diff : worst;
    }
    printf("%zu surfaces: %zu pixels differ by more than %d levels, worst %d\n", count, outliers,
           SHADE_LEVELS + 1, worst);
    free(ref);
    return outliers;
}

/* Several surfaces, one translucent or two, agree with the software rasterizer; one opaque
 * surface is ip_renderer_draw_mesh()'s image. */
static void test_surfaces(ip_renderer *r)
{
    ip_mesh sphere, box;
    ip_mesh_init(&sphere);
    ip_mesh_init(&box);
    add_sphere(&sphere, 4);
    const float lo[3] = {0.3f, -1.15f, -0.95f}, hi[3] = {1.2f, -0.4f, -0.15f};
    add_box(&box, lo, hi);
    ip_camera c = scene_camera(320, 240);
    size_t pixels = 320 * 240;
    uint8_t *gl = malloc(pixels * 4), *plain = malloc(pixels * 4);
    REQUIRE(gl && plain);
    ip_surface f[2] = {{&sphere, {0.93f, 0.6f, 0.5f}, 0.4f}, {&box, {0.3f, 0.5f, 0.9f}, 1.0f}};
    CHECK_LE(surfaces_outliers(r, f, 2, &c, gl), SHADE_OUTLIER_FRACTION * pixels);
    f[1].opacity = 0.7f; /* two translucent surfaces: the depth is redrawn for the second */
    CHECK_LE(surfaces_outliers(r, f, 2, &c, gl), SHADE_OUTLIER_FRACTION * pixels);
    f[0].opacity = 1.0f;
    CHECK_LE(surfaces_outliers(r, f, 2, &c, gl), SHADE_OUTLIER_FRACTION * pixels);
    /* one opaque surface: draw_mesh's image in its colour */
    ip_error err;
    ip_shading s;
    ip_shading_default(&s);
    memcpy(s.surface, f[0].colour, sizeof s.surface);
    REQUIRE(ip_renderer_set_shading(r, &s, NULL) == IP_OK);
    CHECK_EQ(ip_renderer_draw_mesh(r, &sphere, &c, scene_lo, scene_hi, &err), IP_OK);
    CHECK_EQ(ip_renderer_read_rgba(r, plain, &err), IP_OK);
    REQUIRE(ip_renderer_set_shading(r, NULL, NULL) == IP_OK);
    CHECK_EQ(ip_renderer_draw_surfaces(r, f, 1, &c, scene_lo, scene_hi, &err), IP_OK);
    CHECK_EQ(ip_renderer_read_rgba(r, gl, &err), IP_OK);
    CHECK_MEM_EQ(gl, plain, pixels * 4);
    /* the translucent sphere changes the picture */
    f[0].opacity = 0.4f;
    CHECK_EQ(ip_renderer_draw_surfaces(r, f, 1, &c, scene_lo, scene_hi, &err), IP_OK);
    CHECK_EQ(ip_renderer_read_rgba(r, gl, &err), IP_OK);
    CHECK_NE(memcmp(gl, plain, pixels * 4), 0);
    f[0].opacity = 0.0f;
    CHECK_EQ(ip_renderer_draw_surfaces(r, f, 1, &c, scene_lo, scene_hi, &err), IP_ERR_ARGUMENT);
    free(gl);
    free(plain);
    ip_mesh_free(&sphere);
    ip_mesh_free(&box);
}

static void test_resize_and_errors(ip_renderer *r, const ip_mesh *m)
{
    ip_error err;
    ip_camera c = scene_camera(320, 240);
    CHECK_EQ(ip_renderer_resize(r, 0, 10, &err), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_renderer_resize(r, 201, 150, &err), IP_OK);
    CHECK_EQ(ip_renderer_draw(r, &c, scene_lo, scene_hi, &err), IP_ERR_ARGUMENT);
    CHECK_CONTAINS(err.message, "camera is 320x240");
    c = scene_camera(201, 150);
    uint8_t *gl = malloc(201 * 150 * 4);
    REQUIRE(gl);
    draw_and_read(r, &c, gl);
    compare_with_raster(m, &c, gl);
    const double inverted_hi[3] = {-2, 1.5, 1.5};
    CHECK_EQ(ip_renderer_draw(r, &c, scene_lo, inverted_hi, &err), IP_ERR_ARGUMENT);
    c.fov_y = 200;
    CHECK_EQ(ip_renderer_draw(r, &c, scene_lo, scene_hi, &err), IP_ERR_ARGUMENT);
    free(gl);
}

/* Multisampling: bad counts are refused and change nothing; 4 samples keep every pixel whose
 * samples see one surface (up to rounding) and give the others colours between. */
static void test_samples(ip_renderer *r, const uint8_t *image)
{
    ip_error err;
    ip_camera c = scene_camera(320, 240);
    CHECK_EQ(ip_renderer_set_samples(r, 0, &err), IP_ERR_ARGUMENT);
    CHECK_CONTAINS(err.message, "samples a pixel");
    CHECK_EQ(ip_renderer_set_samples(r, 100000, &err), IP_ERR_ARGUMENT);
    uint8_t *aa = malloc(320 * 240 * 4);
    REQUIRE(aa);
    draw_and_read(r, &c, aa);
    CHECK_MEM_EQ(aa, image, 320 * 240 * 4);
    REQUIRE(ip_renderer_set_samples(r, 4, &err) == IP_OK);
    draw_and_read(r, &c, aa);
    size_t changed = 0, far = 0;
    for (size_t i = 0; i < 320 * 240 * 4; i++) {
        int d = abs((int)aa[i] - (int)image[i]);
        changed += d > 0;
        far += d > 4;
    }
    CHECK_GT(changed, 0);
    CHECK_LT(far, 320 * 240 * 4 / 20); /* the silhouettes and the edges between surfaces */
    REQUIRE(ip_renderer_set_samples(r, 1, &err) == IP_OK);
    draw_and_read(r, &c, aa);
    CHECK_MEM_EQ(aa, image, 320 * 240 * 4);
    free(aa);
}

typedef struct thread_job {
    ip_renderer *renderer;
    uint8_t *rgba;
} thread_job;

static void *draw_on_thread(void *arg)
{
    thread_job *job = arg;
    ip_camera c = scene_camera(320, 240);
    draw_and_read(job->renderer, &c, job->rgba);
    ip_renderer_release(job->renderer);
    return NULL;
}

/* A headless renderer released by one thread can be used by another, then come back. */
static void test_threads(ip_renderer *r, const uint8_t *image)
{
    ip_camera c = scene_camera(320, 240);
    thread_job job = {r, malloc(320 * 240 * 4)};
    REQUIRE(job.rgba);
    ip_renderer_release(r);
    pthread_t thread;
    REQUIRE(pthread_create(&thread, NULL, draw_on_thread, &job) == 0);
    REQUIRE(pthread_join(thread, NULL) == 0);
    CHECK_MEM_EQ(job.rgba, image, 320 * 240 * 4);
    memset(job.rgba, 0, 320 * 240 * 4);
    draw_and_read(r, &c, job.rgba);
    CHECK_MEM_EQ(job.rgba, image, 320 * 240 * 4);
    free(job.rgba);
}

/* The viewer's path: a renderer on a context the caller made current, drawing into the
 * caller's framebuffer, gives the headless renderer's image. */
static void test_on_current_context(const ip_mesh *m, const uint8_t *headless_image)
{
    ip_gl_context *context = NULL;
    REQUIRE(ip_gl_context_create_headless(&context, NULL) == IP_OK);
    GLuint fbo, buffers[2];
    glGenFramebuffers(1, &fbo);
    glGenRenderbuffers(2, buffers);
    glBindRenderbuffer(GL_RENDERBUFFER, buffers[0]);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, 320, 240);
    glBindRenderbuffer(GL_RENDERBUFFER, buffers[1]);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, 320, 240);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, buffers[0]);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, buffers[1]);
    CHECK_EQ(glCheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);
    /* state a caller might leave behind */
    glEnable(GL_CULL_FACE);
    glEnable(GL_BLEND);
    glDepthFunc(GL_ALWAYS);

    ip_renderer *r = NULL;
    ip_error err;
    ip_status st = ip_renderer_create_current(320, 240, fbo, &r, &err);
    CHECK_MSG(st == IP_OK, "%s", err.message);
    if (st == IP_OK) {
        uint8_t *rgba = malloc(320 * 240 * 4);
        REQUIRE(rgba);
        ip_camera c = scene_camera(320, 240);
        CHECK_EQ(ip_renderer_upload(r, m, 0, NULL), IP_OK);
        draw_and_read(r, &c, rgba);
        CHECK_MEM_EQ(rgba, headless_image, 320 * 240 * 4);
        ip_renderer_destroy(r);
        free(rgba);
    }
    glDeleteRenderbuffers(2, buffers);
    glDeleteFramebuffers(1, &fbo);
    ip_gl_context_destroy(context);
}

/* What the cases share: a headless renderer of 320 x 240 (made again by a case after
 * on_current_context() destroyed it), the scene's mesh, and the scene's image as drawn with the
 * mesh uploaded again (reference_image()). */
static ip_renderer *the_renderer;
static int mesh_uploaded; /* the renderer holds the mesh alone (renderer_with_mesh()) */
static ip_mesh the_mesh;
static uint8_t *the_image;

static void open_renderer(void)
{
    ip_error err;
    ip_status st = ip_renderer_create_headless(320, 240, &the_renderer, &err);
    if (st == IP_ERR_UNSUPPORTED) {
        printf("test_render: skipped: %s\n", err.message);
        exit(77);
    }
    REQUIRE(st == IP_OK);
    build_scene(&the_mesh);
    printf("scene: %llu triangles\n", (unsigned long long)the_mesh.triangle_count);
}

static void close_renderer(void)
{
    ip_renderer_destroy(the_renderer);
    free(the_image);
    ip_mesh_free(&the_mesh);
}

static ip_renderer *renderer(void)
{
    if (!the_renderer) {
        REQUIRE(ip_renderer_create_headless(320, 240, &the_renderer, NULL) == IP_OK);
        mesh_uploaded = 0;
    }
    return the_renderer;
}

/* The renderer with the scene's mesh uploaded again, alone (the cases before change what it
 * holds). */
static ip_renderer *renderer_with_mesh(void)
{
    ip_renderer *r = renderer();
    if (!mesh_uploaded) {
        ip_renderer_clear_mesh(r);
        REQUIRE(ip_renderer_upload(r, &the_mesh, 0, NULL) == IP_OK);
        mesh_uploaded = 1;
    }
    return r;
}

/* The scene drawn by the renderer with the mesh, made by the first case that compares with it. */
static const uint8_t *reference_image(void)
{
    if (!the_image) {
        ip_renderer *r = renderer_with_mesh();
        the_image = malloc(320 * 240 * 4);
        REQUIRE(the_image);
        ip_camera c = scene_camera(320, 240);
        draw_and_read(r, &c, the_image);
    }
    return the_image;
}

static void against_raster(void)
{
    test_against_raster(renderer(), &the_mesh);
    mesh_uploaded = 0;
}
static void incremental_upload(void)
{
    test_incremental_upload(renderer(), &the_mesh);
    mesh_uploaded = 0;
}
static void streamed_draw(void)
{
    test_streamed_draw(renderer());
    mesh_uploaded = 0;
}
static void surfaces(void)
{
    test_surfaces(renderer());
    mesh_uploaded = 0;
}
static void threads(void)
{
    const uint8_t *image = reference_image();
    test_threads(renderer_with_mesh(), image);
}
static void samples(void)
{
    const uint8_t *image = reference_image();
    test_samples(renderer_with_mesh(), image);
}
static void resize_and_errors(void)
{
    test_resize_and_errors(renderer_with_mesh(), &the_mesh);
}
static void on_current_context(void)
{
    const uint8_t *image = reference_image();
    ip_renderer *r = renderer();
    ip_renderer_destroy(r);
    the_renderer = NULL;
    test_on_current_context(&the_mesh, image);
    /* no context is current any more: refused, r cleared */
    ip_error err;
    CHECK_EQ(ip_renderer_create_current(320, 240, 0, &r, &err), IP_ERR_UNSUPPORTED);
    CHECK_EQ(r, NULL);
    CHECK_CONTAINS(err.message, "no OpenGL context");
}

static const test_case cases[] = {
    {"test_against_raster", against_raster},
    {"test_incremental_upload", incremental_upload},
    {"test_streamed_draw", streamed_draw},
    {"test_surfaces", surfaces},
    {"test_threads", threads},
    {"test_samples", samples},
    {"test_resize_and_errors", resize_and_errors},
    {"test_on_current_context", on_current_context},
};

int main(int argc, char **argv)
{
    return RUN_CASES_WITH(argc, argv, cases, "test_render", open_renderer, close_renderer);
}

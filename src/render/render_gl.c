/* SPDX-License-Identifier: BSD-3-Clause */
/* The OpenGL 3.3 core renderer: mesh buffers on the GPU, shaders, drawing and read-back. */
#include <epoxy/gl.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "isoprop/render.h"
#include "raster_core.h"

enum {
    POSITION_BYTES = 9 * sizeof(float), /* a triangle's positions */
    NORMAL_BYTES = 9 * sizeof(int16_t), /* a triangle's packed normals */
    MIN_CAPACITY = 4096,                /* triangles; growth is geometric */
    STREAM_TRIANGLES = 65536,           /* triangles per draw of ip_renderer_draw_mesh() */
};
/* glDrawArrays counts vertices in a GLint */
#define MAX_TRIANGLES ((uint64_t)INT32_MAX / 3)

struct ip_renderer {
    ip_gl_context *context;            /* owned; NULL on the caller's context */
    int has_objects;                   /* OpenGL objects may exist (a context was current) */
    uint32_t width, height;            /* pixels */
    GLuint framebuffer;                /* drawn into and read from */
    GLuint color_buffer, depth_buffer; /* the headless renderer's own framebuffer */
    uint32_t samples;                  /* per pixel of that framebuffer; 1: no multisampling */
    GLuint resolve_framebuffer, resolve_color; /* samples > 1: the averaged image, read back */
    GLuint mesh_program, background_program;
    GLint view_at, projection_at, eye_at, surface_at, terms_at, opacity_at; /* mesh uniforms */
    GLint top_at, bottom_at, height_at;  /* background uniforms */
    GLuint mesh_array, background_array; /* vertex arrays; the background has no attributes */
    GLuint positions, normals;           /* POSITION_BYTES and NORMAL_BYTES per triangle */
    uint64_t triangle_count, triangle_capacity;
    GLuint stream_array; /* ip_renderer_draw_mesh(): its vertex array, */
    GLuint stream_positions,
        stream_normals; /* and buffers of STREAM_TRIANGLES, made on first use */
    ip_shading shading;
    int mirror;       /* ip_renderer_set_mirror(): the image's columns reversed */
    char driver[128]; /* GL_RENDERER, read once */
};

/* The formulas are those of render.h and raster.c, in world space: v points to the eye. */
static const char *const mesh_vertex_source =
    "#version 330 core\n"
    "layout(location = 0) in vec3 position;\n"
    "layout(location = 1) in vec3 normal;\n"
    "uniform mat4 view;\n"
    "uniform mat4 projection;\n"
    "out vec3 world;\n"
    "out vec3 world_normal;\n"
    "void main() {\n"
    "    world = position;\n"
    "    world_normal = normal;\n"
    "    gl_Position = projection * (view * vec4(position, 1.0));\n"
    "}\n";

static const char *const mesh_fragment_source =
    "#version 330 core\n"
    "in vec3 world;\n"
    "in vec3 world_normal;\n"
    "uniform vec3 eye;\n"
    "uniform vec3 surface;\n"
    "uniform vec4 terms; /* ambient, diffuse, specular, shininess */\n"
    "uniform float opacity;\n"
    "out vec4 colour;\n"
    "void main() {\n"
    "    vec3 v = normalize(eye - world);\n"
    "    float len = length(world_normal);\n"
    "    float c = len > 1e-12 ? min(1.0, abs(dot(world_normal, v)) / len) : 1.0;\n"
    "    vec3 lit = surface * (terms.x + terms.y * c) + vec3(terms.z * pow(c, terms.w));\n"
    "    colour = vec4(clamp(lit, 0.0, 1.0), opacity);\n"
    "}\n";

static const char *const background_vertex_source =
    "#version 330 core\n"
    "void main() {\n"
    "    vec2 p = vec2(float((gl_VertexID & 1) * 4 - 1), float((gl_VertexID >> 1) * 4 - 1));\n"
    "    gl_Position = vec4(p, 0.0, 1.0);\n"
    "}\n";

static const char *const background_fragment_source =
    "#version 330 core\n"
    "uniform vec3 top;\n"
    "uniform vec3 bottom;\n"
    "uniform float height;\n"
    "out vec4 colour;\n"
    "void main() {\n"
    "    float t = (height - gl_FragCoord.y) / height; /* (row + 0.5) / height, row 0 on top */\n"
    "    colour = vec4(clamp(top + t * (bottom - top), 0.0, 1.0), 1.0);\n"
    "}\n";

static const char *gl_error_name(GLenum e)
{
    switch (e) {
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    default: return "an unknown OpenGL error";
    }
}

/* Forgets errors left by earlier calls (the caller's, on a shared context). */
static void drain_gl_errors(void)
{
    for (int i = 0; i < 32 && glGetError() != GL_NO_ERROR; i++) {
    }
}

/* Reports the first OpenGL error raised since drain_gl_errors(), naming `what`. */
static ip_status check_gl(const char *what, ip_error *err)
{
    GLenum e = glGetError();
    if (e == GL_NO_ERROR)
        return IP_OK;
    drain_gl_errors();
    return ip__fail(err, e == GL_OUT_OF_MEMORY ? IP_ERR_NOMEM : IP_ERR_UNSUPPORTED,
                    "renderer: %s: %s", what, gl_error_name(e));
}

static ip_status make_current(ip_renderer *r, ip_error *err)
{
    ip_status st = r->context ? ip_gl_context_make_current(r->context, err) : IP_OK;
    if (st == IP_OK)
        drain_gl_errors();
    return st;
}

/* IP_OK when the shader or program `object` compiled or linked; otherwise deletes it and
 * fails with "WHAT: PROBLEM: its info log". */
static ip_status check_built(GLuint object, int is_program, const char *what, const char *problem,
                             ip_error *err)
{
    GLint ok = GL_FALSE;
    char log[512] = "";
    if (is_program)
        glGetProgramiv(object, GL_LINK_STATUS, &ok);
    else
        glGetShaderiv(object, GL_COMPILE_STATUS, &ok);
    if (ok)
        return IP_OK;
    if (is_program) {
        glGetProgramInfoLog(object, sizeof log, NULL, log);
        glDeleteProgram(object);
    } else {
        glGetShaderInfoLog(object, sizeof log, NULL, log);
        glDeleteShader(object);
    }
    return ip__fail(err, IP_ERR_UNSUPPORTED, "%s: %s: %s", what, problem, log);
}

static ip_status compile_shader(GLenum kind, const char *source, const char *what, GLuint *out,
                                ip_error *err)
{
    GLuint shader = glCreateShader(kind);
    glShaderSource(shader, 1, &source, NULL);
    glCompileShader(shader);
    ip_status st = check_built(shader, 0, what, "shader does not compile", err);
    if (st == IP_OK)
        *out = shader;
    return st;
}

/* The program of the two shaders; `what` names the caller in messages. */
static ip_status link_program(const char *vertex, const char *fragment, const char *what,
                              GLuint *out, ip_error *err)
{
    GLuint vs = 0, fs = 0;
    ip_status st = compile_shader(GL_VERTEX_SHADER, vertex, what, &vs, err);
    if (st == IP_OK)
        st = compile_shader(GL_FRAGMENT_SHADER, fragment, what, &fs, err);
    if (st != IP_OK) {
        glDeleteShader(vs);
        return st;
    }
    GLuint program = glCreateProgram();
    glAttachShader(program, vs);
    glAttachShader(program, fs);
    glLinkProgram(program);
    glDeleteShader(vs); /* flagged: freed with the program */
    glDeleteShader(fs);
    st = check_built(program, 1, what, "shaders do not link", err);
    if (st == IP_OK)
        *out = program;
    return st;
}

ip_status ip_gl_program(const char *vertex_source, const char *fragment_source, unsigned *program,
                        ip_error *err)
{
    GLuint built = 0;
    ip_status st = link_program(vertex_source, fragment_source, "OpenGL", &built, err);
    *program = st == IP_OK ? built : 0;
    return st;
}

static ip_status build_programs(ip_renderer *r, ip_error *err)
{
    ip_status st =
        link_program(mesh_vertex_source, mesh_fragment_source, "renderer", &r->mesh_program, err);
    if (st == IP_OK)
        st = link_program(background_vertex_source, background_fragment_source, "renderer",
                          &r->background_program, err);
    if (st != IP_OK)
        return st;
    r->view_at = glGetUniformLocation(r->mesh_program, "view");
    r->projection_at = glGetUniformLocation(r->mesh_program, "projection");
    r->eye_at = glGetUniformLocation(r->mesh_program, "eye");
    r->surface_at = glGetUniformLocation(r->mesh_program, "surface");
    r->terms_at = glGetUniformLocation(r->mesh_program, "terms");
    r->opacity_at = glGetUniformLocation(r->mesh_program, "opacity");
    r->top_at = glGetUniformLocation(r->background_program, "top");
    r->bottom_at = glGetUniformLocation(r->background_program, "bottom");
    r->height_at = glGetUniformLocation(r->background_program, "height");
    return check_gl("building the shaders", err);
}

/* Points a vertex array at position and normal buffers: floats, and signed normalised
 * shorts (OpenGL reads v / 32767, as ip_normal_unpack() does). */
static void bind_array(GLuint array, GLuint positions, GLuint normals)
{
    glBindVertexArray(array);
    glBindBuffer(GL_ARRAY_BUFFER, positions);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, NULL);
    glEnableVertexAttribArray(0);
    glBindBuffer(GL_ARRAY_BUFFER, normals);
    glVertexAttribPointer(1, 3, GL_SHORT, GL_TRUE, 0, NULL);
    glEnableVertexAttribArray(1);
    glBindVertexArray(0);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
}

/* Points the mesh vertex array at the current buffers. */
static void bind_mesh_array(ip_renderer *r)
{
    bind_array(r->mesh_array, r->positions, r->normals);
}

/* Whether the bound framebuffer is complete, after no OpenGL error. */
static ip_status check_framebuffer(const char *what, ip_error *err)
{
    GLenum complete = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    ip_status st = check_gl(what, err);
    if (st == IP_OK && complete != GL_FRAMEBUFFER_COMPLETE)
        st = ip__fail(err, IP_ERR_UNSUPPORTED, "renderer: framebuffer incomplete (0x%04x)",
                      (unsigned)complete);
    return st;
}

/* The single-sample framebuffer a multisampled image is averaged into before it is read. */
static ip_status allocate_resolve(ip_renderer *r, GLsizei width, GLsizei height, ip_error *err)
{
    if (!r->resolve_framebuffer) {
        glGenFramebuffers(1, &r->resolve_framebuffer);
        glGenRenderbuffers(1, &r->resolve_color);
    }
    glBindRenderbuffer(GL_RENDERBUFFER, r->resolve_color);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
    glBindRenderbuffer(GL_RENDERBUFFER, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, r->resolve_framebuffer);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                              r->resolve_color);
    return check_framebuffer("allocating the resolve framebuffer", err);
}

/* (Re)allocates the headless renderer's colour and depth buffers. */
static ip_status allocate_framebuffer(ip_renderer *r, uint32_t width, uint32_t height,
                                      ip_error *err)
{
    GLint max_size = 0;
    glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_size);
    if (width > (uint32_t)max_size || height > (uint32_t)max_size)
        return ip__fail(err, IP_ERR_ARGUMENT, "renderer: %ux%u exceeds the OpenGL limit of %d",
                        width, height, (int)max_size);
    if (!r->framebuffer) {
        glGenFramebuffers(1, &r->framebuffer);
        glGenRenderbuffers(1, &r->color_buffer);
        glGenRenderbuffers(1, &r->depth_buffer);
    }
    GLsizei samples = r->samples > 1 ? (GLsizei)r->samples : 0, w = (GLsizei)width,
            h = (GLsizei)height;
    glBindRenderbuffer(GL_RENDERBUFFER, r->color_buffer);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, w, h);
    glBindRenderbuffer(GL_RENDERBUFFER, r->depth_buffer);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT24, w, h);
    glBindRenderbuffer(GL_RENDERBUFFER, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, r->framebuffer);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                              r->color_buffer);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                              r->depth_buffer);
    ip_status st = check_framebuffer("allocating the framebuffer", err);
    if (st == IP_OK && samples)
        st = allocate_resolve(r, w, h, err);
    if (st == IP_OK) {
        r->width = width;
        r->height = height;
    }
    return st;
}

static ip_status check_size(uint32_t width, uint32_t height, ip_error *err)
{
    if (width == 0 || height == 0 || width > INT32_MAX || height > INT32_MAX)
        return ip__fail(err, IP_ERR_ARGUMENT, "renderer: image size %ux%u is invalid", width,
                        height);
    return IP_OK;
}

/* Objects every renderer has, on the context current now. */
static ip_status setup_objects(ip_renderer *r, ip_error *err)
{
    ip_shading_default(&r->shading);
    r->has_objects = 1;
    drain_gl_errors();
    ip_status st = build_programs(r, err);
    if (st != IP_OK)
        return st;
    glGenVertexArrays(1, &r->mesh_array);
    glGenVertexArrays(1, &r->background_array);
    glGenBuffers(1, &r->positions);
    glGenBuffers(1, &r->normals);
    bind_mesh_array(r);
    return check_gl("creating the vertex arrays", err);
}

ip_status ip_renderer_create_headless(uint32_t width, uint32_t height, ip_renderer **out,
                                      ip_error *err)
{
    *out = NULL;
    ip_status st = check_size(width, height, err);
    if (st != IP_OK)
        return st;
    ip_renderer *r = calloc(1, sizeof *r);
    if (!r)
        return ip__fail(err, IP_ERR_NOMEM, "renderer: out of memory");
    r->samples = 1;
    st = ip_gl_context_create_headless(&r->context, err);
    if (st == IP_OK)
        st = setup_objects(r, err);
    if (st == IP_OK)
        st = allocate_framebuffer(r, width, height, err);
    if (st != IP_OK) {
        ip_renderer_destroy(r);
        return st;
    }
    *out = r;
    return IP_OK;
}

ip_status ip_renderer_create_current(uint32_t width, uint32_t height, uint32_t framebuffer,
                                     ip_renderer **out, ip_error *err)
{
    *out = NULL;
    ip_status st = check_size(width, height, err);
    if (st != IP_OK)
        return st;
    if (!glGetString(GL_VERSION))
        return ip__fail(err, IP_ERR_UNSUPPORTED, "renderer: no OpenGL context is current");
    if (!epoxy_is_desktop_gl() || epoxy_gl_version() < 33)
        return ip__fail(err, IP_ERR_UNSUPPORTED, "renderer: OpenGL %s is older than 3.3 core",
                        (const char *)glGetString(GL_VERSION));
    ip_renderer *r = calloc(1, sizeof *r);
    if (!r)
        return ip__fail(err, IP_ERR_NOMEM, "renderer: out of memory");
    st = setup_objects(r, err);
    if (st != IP_OK) {
        ip_renderer_destroy(r);
        return st;
    }
    r->framebuffer = framebuffer;
    r->samples = 1;
    r->width = width;
    r->height = height;
    *out = r;
    return IP_OK;
}

ip_status ip_renderer_resize(ip_renderer *r, uint32_t width, uint32_t height, ip_error *err)
{
    ip_status st = check_size(width, height, err);
    if (st == IP_OK && r->context) {
        uint32_t old_width = r->width, old_height = r->height;
        st = make_current(r, err);
        if (st == IP_OK)
            st = allocate_framebuffer(r, width, height, err);
        if (st != IP_OK && make_current(r, NULL) == IP_OK)
            (void)allocate_framebuffer(r, old_width, old_height, NULL);
        return st;
    }
    if (st == IP_OK) {
        r->width = width;
        r->height = height;
    }
    return st;
}

/* Grows both buffers to hold `needed` triangles, copying their contents on the GPU. */
static ip_status reserve_triangles(ip_renderer *r, uint64_t needed, ip_error *err)
{
    if (needed <= r->triangle_capacity)
        return IP_OK;
    uint64_t capacity = r->triangle_capacity ? 2 * r->triangle_capacity : MIN_CAPACITY;
    capacity = capacity < needed ? needed : capacity;
    capacity = capacity > MAX_TRIANGLES ? MAX_TRIANGLES : capacity;
    GLuint grown[2] = {0, 0}, old[2] = {r->positions, r->normals};
    const uint64_t bytes[2] = {POSITION_BYTES, NORMAL_BYTES};
    glGenBuffers(2, grown);
    for (int i = 0; i < 2; i++) {
        glBindBuffer(GL_COPY_WRITE_BUFFER, grown[i]);
        glBufferData(GL_COPY_WRITE_BUFFER, (GLsizeiptr)(capacity * bytes[i]), NULL, GL_STATIC_DRAW);
        glBindBuffer(GL_COPY_READ_BUFFER, old[i]);
        if (r->triangle_count)
            glCopyBufferSubData(GL_COPY_READ_BUFFER, GL_COPY_WRITE_BUFFER, 0, 0,
                                (GLsizeiptr)(r->triangle_count * bytes[i]));
    }
    glBindBuffer(GL_COPY_READ_BUFFER, 0);
    glBindBuffer(GL_COPY_WRITE_BUFFER, 0);
    ip_status st = check_gl("growing the mesh buffers", err);
    if (st != IP_OK) {
        glDeleteBuffers(2, grown);
        return st;
    }
    glDeleteBuffers(2, old);
    r->positions = grown[0];
    r->normals = grown[1];
    r->triangle_capacity = capacity;
    bind_mesh_array(r);
    return IP_OK;
}

ip_status ip_renderer_upload(ip_renderer *r, const ip_mesh *m, uint64_t first, ip_error *err)
{
    if (first > m->triangle_count)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "renderer: first triangle %llu is past the %llu "
                        "of the mesh",
                        (unsigned long long)first, (unsigned long long)m->triangle_count);
    uint64_t added = m->triangle_count - first;
    if (added == 0)
        return IP_OK;
    if (added > MAX_TRIANGLES - r->triangle_count)
        return ip__fail(err, IP_ERR_LIMIT, "renderer: more than %llu triangles",
                        (unsigned long long)MAX_TRIANGLES);
    ip_status st = make_current(r, err);
    if (st == IP_OK)
        st = reserve_triangles(r, r->triangle_count + added, err);
    if (st != IP_OK)
        return st;
    glBindBuffer(GL_ARRAY_BUFFER, r->positions);
    glBufferSubData(GL_ARRAY_BUFFER, (GLintptr)(r->triangle_count * POSITION_BYTES),
                    (GLsizeiptr)(added * POSITION_BYTES), m->positions + 9 * first);
    glBindBuffer(GL_ARRAY_BUFFER, r->normals);
    glBufferSubData(GL_ARRAY_BUFFER, (GLintptr)(r->triangle_count * NORMAL_BYTES),
                    (GLsizeiptr)(added * NORMAL_BYTES), m->normals + 9 * first);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    st = check_gl("uploading triangles", err);
    if (st == IP_OK)
        r->triangle_count += added;
    return st;
}

void ip_renderer_clear_mesh(ip_renderer *r)
{
    r->triangle_count = 0;
}

const char *ip_renderer_driver(ip_renderer *r)
{
    if (!r->driver[0] && make_current(r, NULL) == IP_OK) {
        const char *name = (const char *)glGetString(GL_RENDERER);
        snprintf(r->driver, sizeof r->driver, "%s", name ? name : "unknown");
    }
    return r->driver[0] ? r->driver : "unknown";
}

int ip_gl_driver_is_software(const char *name)
{
    return name && (strstr(name, "llvmpipe") || strstr(name, "softpipe") ||
                    strstr(name, "Software Rasterizer") || strstr(name, "swrast"));
}

uint64_t ip_renderer_memory(const ip_renderer *r)
{
    uint64_t stream =
        r->stream_array ? (uint64_t)STREAM_TRIANGLES * (POSITION_BYTES + NORMAL_BYTES) : 0;
    return r->triangle_capacity * (POSITION_BYTES + NORMAL_BYTES) + stream;
}

uint64_t ip_renderer_triangle_count(const ip_renderer *r)
{
    return r->triangle_count;
}

/* The fixed-function state both draws rely on, whatever the caller left. */
static void set_draw_state(const ip_renderer *r)
{
    glBindFramebuffer(GL_FRAMEBUFFER, r->framebuffer);
    glViewport(0, 0, (GLsizei)r->width, (GLsizei)r->height);
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glDisable(GL_DEPTH_CLAMP);
    glDisable(GL_FRAMEBUFFER_SRGB);
    glEnable(GL_MULTISAMPLE); /* a no-op on a single-sample framebuffer */
    glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_LESS);
}

static void draw_background(const ip_renderer *r)
{
    const ip_shading *s = &r->shading;
    glDisable(GL_DEPTH_TEST);
    glUseProgram(r->background_program);
    glUniform3fv(r->top_at, 1, s->background_top);
    glUniform3fv(r->bottom_at, 1, s->background_bottom);
    glUniform1f(r->height_at, (GLfloat)r->height);
    glBindVertexArray(r->background_array);
    glDrawArrays(GL_TRIANGLES, 0, 3);
}

/* Depth test on, the mesh program with the camera's and the shading's uniforms. */
static void use_mesh_program(const ip_renderer *r, const ip_camera *camera, double near_plane,
                             double far_plane)
{
    const ip_shading *s = &r->shading;
    float view[16], projection[16];
    ip_camera_view_matrix(camera, view);
    ip_camera_projection_matrix(camera, near_plane, far_plane, projection);
    if (r->mirror) /* x in clip space the other way: the mirror image (faces are not culled) */
        projection[0] = -projection[0];
    float eye[3] = {(float)camera->eye[0], (float)camera->eye[1], (float)camera->eye[2]};
    float terms[4] = {s->ambient, s->diffuse, s->specular, s->shininess};
    glEnable(GL_DEPTH_TEST);
    glUseProgram(r->mesh_program);
    glUniformMatrix4fv(r->view_at, 1, GL_FALSE, view);
    glUniformMatrix4fv(r->projection_at, 1, GL_FALSE, projection);
    glUniform3fv(r->eye_at, 1, eye);
    glUniform3fv(r->surface_at, 1, s->surface);
    glUniform4fv(r->terms_at, 1, terms);
    glUniform1f(r->opacity_at, 1.0f);
}

/* Draws the uploaded triangles [first, triangle_count). */
static void draw_mesh(const ip_renderer *r, const ip_camera *camera, double near_plane,
                      double far_plane, uint64_t first)
{
    use_mesh_program(r, camera, near_plane, far_plane);
    glBindVertexArray(r->mesh_array);
    glDrawArrays(GL_TRIANGLES, (GLint)(3 * first), (GLsizei)(3 * (r->triangle_count - first)));
    glBindVertexArray(0);
    glUseProgram(0);
}

/* Checks the view and makes the context current; then, with `clear`, clears the depth and draws
 * the background (else the image drawn last stays). */
static ip_status begin_image(ip_renderer *r, const ip_camera *camera, const double lo[3],
                             const double hi[3], int clear, double *near_plane, double *far_plane,
                             ip_error *err)
{
    ip_status st = ip_camera_check(camera, err);
    if (st == IP_OK)
        st = ip_render_check_box(lo, hi, err);
    if (st != IP_OK)
        return st;
    if (camera->width != r->width || camera->height != r->height)
        return ip__fail(err, IP_ERR_ARGUMENT, "renderer: camera is %ux%u, the image %ux%u",
                        camera->width, camera->height, r->width, r->height);
    st = make_current(r, err);
    if (st != IP_OK)
        return st;
    ip_camera_depth_range(camera, lo, hi, near_plane, far_plane);
    set_draw_state(r);
    if (clear) {
        glClearDepth(1.0);
        glClear(GL_DEPTH_BUFFER_BIT);
        draw_background(r);
    }
    return IP_OK;
}

ip_status ip_renderer_draw(ip_renderer *r, const ip_camera *camera, const double lo[3],
                           const double hi[3], ip_error *err)
{
    return ip_renderer_draw_added(r, camera, lo, hi, 0, err);
}

ip_status ip_renderer_draw_added(ip_renderer *r, const ip_camera *camera, const double lo[3],
                                 const double hi[3], uint64_t first, ip_error *err)
{
    if (first > r->triangle_count)
        return ip__fail(err, IP_ERR_ARGUMENT,
                        "renderer: triangles from %llu drawn, but %llu uploaded",
                        (unsigned long long)first, (unsigned long long)r->triangle_count);
    double near_plane, far_plane;
    ip_status st = begin_image(r, camera, lo, hi, first == 0, &near_plane, &far_plane, err);
    if (st != IP_OK)
        return st;
    if (first < r->triangle_count)
        draw_mesh(r, camera, near_plane, far_plane, first);
    return check_gl("drawing", err);
}

/* The streaming buffers, allocated once at their full size. */
static ip_status make_stream_buffers(ip_renderer *r, ip_error *err)
{
    if (r->stream_array)
        return IP_OK;
    glGenVertexArrays(1, &r->stream_array);
    glGenBuffers(1, &r->stream_positions);
    glGenBuffers(1, &r->stream_normals);
    bind_array(r->stream_array, r->stream_positions, r->stream_normals);
    return check_gl("creating the streaming buffers", err);
}

/* Draws the triangles of `m` with the program in use, through the streaming buffers. */
static void stream_mesh(const ip_renderer *r, const ip_mesh *m)
{
    glBindVertexArray(r->stream_array);
    /* Each part replaces the buffers' storage (orphaning it), so the driver never waits for
     * the previous draw and frees each part's copy once drawn. Drawing in parts, in order,
     * gives the image of one draw: the depth test sees the same triangles in the same order. */
    for (uint64_t first = 0; first < m->triangle_count; first += STREAM_TRIANGLES) {
        uint64_t count = m->triangle_count - first;
        count = count < STREAM_TRIANGLES ? count : STREAM_TRIANGLES;
        glBindBuffer(GL_ARRAY_BUFFER, r->stream_positions);
        glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(count * POSITION_BYTES),
                     m->positions + 9 * first, GL_STREAM_DRAW);
        glBindBuffer(GL_ARRAY_BUFFER, r->stream_normals);
        glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(count * NORMAL_BYTES), m->normals + 9 * first,
                     GL_STREAM_DRAW);
        glDrawArrays(GL_TRIANGLES, 0, (GLsizei)(3 * count));
    }
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    glBindVertexArray(0);
}

ip_status ip_renderer_draw_mesh(ip_renderer *r, const ip_mesh *m, const ip_camera *camera,
                                const double lo[3], const double hi[3], ip_error *err)
{
    double near_plane, far_plane;
    ip_status st = begin_image(r, camera, lo, hi, 1, &near_plane, &far_plane, err);
    if (st == IP_OK)
        st = make_stream_buffers(r, err);
    if (st != IP_OK || m->triangle_count == 0)
        return st == IP_OK ? check_gl("drawing", err) : st;
    use_mesh_program(r, camera, near_plane, far_plane);
    stream_mesh(r, m);
    glUseProgram(0);
    return check_gl("drawing", err);
}

/* Draws the opaque surfaces, each in its colour; with depth writes only when `colour` is 0. */
static void draw_opaque(const ip_renderer *r, const ip_surface *surfaces, size_t count, int colour)
{
    for (size_t i = 0; i < count; i++) {
        if (surfaces[i].opacity < 1.0f)
            continue;
        if (colour)
            glUniform3fv(r->surface_at, 1, surfaces[i].colour);
        stream_mesh(r, surfaces[i].mesh);
    }
}

/* Translucent surface f by the front-layer rule, over the opaque surfaces drawn: the depth
 * buffer is made the nearer of the opaque surfaces' (redrawn when `restore`, after an
 * earlier translucent surface) and f's own; then f's fragments at that depth are blended.
 * The same program and vertices give the same depths in both passes. */
static void draw_translucent(const ip_renderer *r, const ip_surface *surfaces, size_t count,
                             const ip_surface *f, int restore)
{
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    if (restore) {
        glClear(GL_DEPTH_BUFFER_BIT);
        draw_opaque(r, surfaces, count, 0);
    }
    stream_mesh(r, f->mesh);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthMask(GL_FALSE);
    glDepthFunc(GL_LEQUAL);
    glEnable(GL_BLEND);
    /* colour: a * shaded + (1 - a) * below; the alpha channel stays 1 */
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
    glUniform3fv(r->surface_at, 1, f->colour);
    glUniform1f(r->opacity_at, f->opacity);
    stream_mesh(r, f->mesh);
    glUniform1f(r->opacity_at, 1.0f);
    glDisable(GL_BLEND);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
}

ip_status ip_renderer_draw_surfaces(ip_renderer *r, const ip_surface *surfaces, size_t count,
                                    const ip_camera *camera, const double lo[3], const double hi[3],
                                    ip_error *err)
{
    ip_status st = ip_surfaces_check(surfaces, count, err);
    double near_plane, far_plane;
    if (st == IP_OK)
        st = begin_image(r, camera, lo, hi, 1, &near_plane, &far_plane, err);
    if (st == IP_OK)
        st = make_stream_buffers(r, err);
    if (st != IP_OK)
        return st;
    use_mesh_program(r, camera, near_plane, far_plane);
    draw_opaque(r, surfaces, count, 1);
    int translucent = 0;
    for (size_t i = 0; i < count; i++)
        if (surfaces[i].opacity < 1.0f)
            draw_translucent(r, surfaces, count, &surfaces[i], translucent++ > 0);
    glUseProgram(0);
    return check_gl("drawing", err);
}

/* OpenGL's rows start at the bottom; images here start at the top. */
static void flip_rows(uint8_t *rgba, uint32_t width, uint32_t height)
{
    size_t row = (size_t)width * 4;
    for (uint32_t y = 0; y < height / 2; y++) {
        uint8_t *a = rgba + y * row, *b = rgba + (size_t)(height - 1 - y) * row;
        for (size_t i = 0; i < row; i++) {
            uint8_t t = a[i];
            a[i] = b[i];
            b[i] = t;
        }
    }
}

ip_status ip_renderer_set_shading(ip_renderer *r, const ip_shading *shading, ip_error *err)
{
    ip_shading taken;
    ip_status st = ip__shading_take(shading, &taken, err);
    if (st == IP_OK)
        r->shading = taken;
    return st;
}

void ip_renderer_set_mirror(ip_renderer *r, int mirror)
{
    r->mirror = mirror != 0;
}

ip_status ip_renderer_set_samples(ip_renderer *r, uint32_t samples, ip_error *err)
{
    if (!r->context)
        return samples == 1 ? IP_OK
                            : ip__fail(err, IP_ERR_ARGUMENT,
                                       "renderer: the caller's framebuffer sets its samples");
    ip_status st = make_current(r, err);
    if (st != IP_OK)
        return st;
    GLint max_samples = 1;
    glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
    if (samples == 0 || samples > (uint32_t)(max_samples > 1 ? max_samples : 1))
        return ip__fail(err, IP_ERR_ARGUMENT, "renderer: %u samples a pixel (1 to %d here)",
                        samples, max_samples > 1 ? (int)max_samples : 1);
    uint32_t old_samples = r->samples;
    r->samples = samples;
    st = allocate_framebuffer(r, r->width, r->height, err);
    if (st != IP_OK) {
        r->samples = old_samples;
        (void)allocate_framebuffer(r, r->width, r->height, NULL);
    }
    return st;
}

ip_status ip_renderer_read_rgba(ip_renderer *r, uint8_t *rgba, ip_error *err)
{
    ip_status st = make_current(r, err);
    if (st != IP_OK)
        return st;
    glBindFramebuffer(GL_READ_FRAMEBUFFER, r->framebuffer);
    if (r->samples > 1) { /* average each pixel's samples, then read that */
        GLint w = (GLint)r->width, h = (GLint)r->height;
        glDisable(GL_SCISSOR_TEST);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, r->resolve_framebuffer);
        glBlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
        glBindFramebuffer(GL_FRAMEBUFFER, r->resolve_framebuffer);
    }
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glPixelStorei(GL_PACK_ROW_LENGTH, 0);
    glPixelStorei(GL_PACK_SKIP_ROWS, 0);
    glPixelStorei(GL_PACK_SKIP_PIXELS, 0);
    glReadPixels(0, 0, (GLsizei)r->width, (GLsizei)r->height, GL_RGBA, GL_UNSIGNED_BYTE, rgba);
    st = check_gl("reading the image back", err);
    if (st == IP_OK)
        flip_rows(rgba, r->width, r->height);
    return st;
}

void ip_renderer_release(ip_renderer *r)
{
    ip_gl_context_release(r->context);
}

void ip_renderer_destroy(ip_renderer *r)
{
    if (!r)
        return;
    int current = !r->context || ip_gl_context_make_current(r->context, NULL) == IP_OK;
    if (r->has_objects && current) {
        GLuint buffers[4] = {r->positions, r->normals, r->stream_positions, r->stream_normals};
        GLuint arrays[3] = {r->mesh_array, r->background_array, r->stream_array};
        glDeleteBuffers(4, buffers);
        glDeleteVertexArrays(3, arrays);
        glDeleteProgram(r->mesh_program);
        glDeleteProgram(r->background_program);
        if (r->context) {
            GLuint renderbuffers[3] = {r->color_buffer, r->depth_buffer, r->resolve_color};
            GLuint framebuffers[2] = {r->framebuffer, r->resolve_framebuffer};
            glDeleteRenderbuffers(3, renderbuffers);
            glDeleteFramebuffers(2, framebuffers);
        }
    }
    ip_gl_context_destroy(r->context);
    free(r);
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* Headless OpenGL 3.3 core contexts: EGL on Mesa's surfaceless platform (llvmpipe, no GPU). */
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "isoprop/render.h"

struct ip_gl_context {
    EGLDisplay display; /* process-wide, shared with every other context on the platform */
    EGLContext context;
};

/* 1 when the space-separated `list` holds the token `name`. */
static int has_extension(const char *list, const char *name)
{
    size_t n = strlen(name);
    for (const char *p = list; p && (p = strstr(p, name)) != NULL; p += n)
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0'))
            return 1;
    return 0;
}

static ip_status egl_fail(ip_error *err, const char *what)
{
    return ip__fail(err, IP_ERR_UNSUPPORTED, "headless OpenGL: %s (EGL error 0x%04x)", what,
                    (unsigned)eglGetError());
}

/* The surfaceless display needs no window system and no GPU: Mesa falls back to llvmpipe. */
static ip_status open_display(EGLDisplay *out, ip_error *err)
{
    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!client || !has_extension(client, "EGL_EXT_platform_base") ||
        !has_extension(client, "EGL_MESA_platform_surfaceless"))
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "headless OpenGL: EGL lacks the surfaceless platform "
                        "(EGL_MESA_platform_surfaceless; install Mesa's libegl-mesa0)");
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_display =
        (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    if (!get_display)
        return egl_fail(err, "no eglGetPlatformDisplayEXT");
    EGLDisplay display = get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
    if (display == EGL_NO_DISPLAY)
        return egl_fail(err, "no surfaceless EGL display");
    EGLint major, minor;
    if (!eglInitialize(display, &major, &minor))
        return egl_fail(err, "cannot initialise the surfaceless EGL display "
                             "(no Mesa driver: install libgl1-mesa-dri)");
    *out = display;
    return IP_OK;
}

/* A config is needed only where the display cannot create contexts without one. */
static ip_status choose_config(EGLDisplay display, EGLConfig *out, ip_error *err)
{
    const char *ext = eglQueryString(display, EGL_EXTENSIONS);
    if (!has_extension(ext, "EGL_KHR_surfaceless_context"))
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "headless OpenGL: EGL lacks "
                        "EGL_KHR_surfaceless_context");
    if (!has_extension(ext, "EGL_KHR_create_context"))
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "headless OpenGL: EGL lacks "
                        "EGL_KHR_create_context");
    *out = EGL_NO_CONFIG_KHR;
    if (has_extension(ext, "EGL_KHR_no_config_context"))
        return IP_OK;
    const EGLint attributes[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLint count = 0;
    if (!eglChooseConfig(display, attributes, out, 1, &count) || count < 1)
        return egl_fail(err, "no EGL config for desktop OpenGL");
    return IP_OK;
}

static ip_status create_core_context(ip_gl_context *c, ip_error *err)
{
    EGLConfig config;
    ip_status st = choose_config(c->display, &config, err);
    if (st != IP_OK)
        return st;
    if (!eglBindAPI(EGL_OPENGL_API))
        return egl_fail(err, "EGL cannot bind desktop OpenGL");
    const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION_KHR,
                                 3,
                                 EGL_CONTEXT_MINOR_VERSION_KHR,
                                 3,
                                 EGL_CONTEXT_OPENGL_PROFILE_MASK_KHR,
                                 EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT_KHR,
                                 EGL_NONE};
    c->context = eglCreateContext(c->display, config, EGL_NO_CONTEXT, attributes);
    if (c->context == EGL_NO_CONTEXT)
        return egl_fail(err, "cannot create an OpenGL 3.3 core context");
    if (!eglMakeCurrent(c->display, EGL_NO_SURFACE, EGL_NO_SURFACE, c->context))
        return egl_fail(err, "cannot make the OpenGL context current");
    return IP_OK;
}

ip_status ip_gl_context_create_headless(ip_gl_context **out, ip_error *err)
{
    *out = NULL;
    ip_gl_context *c = calloc(1, sizeof *c);
    if (!c)
        return ip__fail(err, IP_ERR_NOMEM, "headless OpenGL: out of memory");
    c->context = EGL_NO_CONTEXT;
    ip_status st = open_display(&c->display, err);
    if (st == IP_OK)
        st = create_core_context(c, err);
    if (st != IP_OK) {
        ip_gl_context_destroy(c);
        return st;
    }
    *out = c;
    return IP_OK;
}

/* eglGetCurrentContext() answers for the thread's bound API, which starts as OpenGL ES. */
static int is_current(const ip_gl_context *c)
{
    return eglBindAPI(EGL_OPENGL_API) && eglGetCurrentContext() == c->context;
}

ip_status ip_gl_context_make_current(ip_gl_context *c, ip_error *err)
{
    if (is_current(c))
        return IP_OK;
    if (!eglMakeCurrent(c->display, EGL_NO_SURFACE, EGL_NO_SURFACE, c->context))
        return egl_fail(err, "cannot make the OpenGL context current on this thread");
    return IP_OK;
}

void ip_gl_context_release(ip_gl_context *c)
{
    if (c && c->context != EGL_NO_CONTEXT && is_current(c))
        eglMakeCurrent(c->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
}

void ip_gl_context_destroy(ip_gl_context *c)
{
    if (!c)
        return;
    if (c->context != EGL_NO_CONTEXT) {
        ip_gl_context_release(c);
        eglDestroyContext(c->display, c->context);
    }
    free(c);
}

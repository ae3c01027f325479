/* SPDX-License-Identifier: BSD-3-Clause */
/* isoview's image between frames: a framebuffer object that keeps the picture from one frame to
 * the next (a window's back buffer is undefined after a swap), so that a frame draws only what
 * is new, and is copied to the window before the overlay. The software renderer sends the
 * canvas's changed rows into its texture; the OpenGL renderer draws into it, with a depth
 * buffer of its own. */
#include <stdlib.h>
#include <string.h>

#include "isoview.h"

int display_create(display *d, int with_depth, ip_error *err)
{
    memset(d, 0, sizeof *d);
    d->with_depth = with_depth;
    glGenTextures(1, &d->texture);
    glGenFramebuffers(1, &d->framebuffer);
    if (glGetError() != GL_NO_ERROR) {
        set_error(err, IP_ERR_UNSUPPORTED, "display: an OpenGL error while setting up");
        return -1;
    }
    return 0;
}

void display_destroy(display *d)
{
    if (d->texture) {
        glDeleteFramebuffers(1, &d->framebuffer);
        glDeleteTextures(1, &d->texture);
        glDeleteRenderbuffers(1, &d->depth);
    }
    free(d->rows);
    memset(d, 0, sizeof *d);
}

int display_size(display *d, uint32_t width, uint32_t height, ip_error *err)
{
    if (width == d->width && height == d->height)
        return 0;
    uint8_t *rows = d->with_depth ? d->rows : realloc(d->rows, (size_t)width * height * 4);
    if (!d->with_depth && !rows) {
        set_error(err, IP_ERR_NOMEM, "display: out of memory for a %ux%u image", width, height);
        return -1;
    }
    d->rows = rows;
    glBindTexture(GL_TEXTURE_2D, d->texture);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, (GLsizei)width, (GLsizei)height, 0, GL_RGBA,
                 GL_UNSIGNED_BYTE, NULL);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glBindTexture(GL_TEXTURE_2D, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, d->framebuffer);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, d->texture, 0);
    if (d->with_depth) {
        if (!d->depth)
            glGenRenderbuffers(1, &d->depth);
        glBindRenderbuffer(GL_RENDERBUFFER, d->depth);
        glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, (GLsizei)width,
                              (GLsizei)height);
        glBindRenderbuffer(GL_RENDERBUFFER, 0);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, d->depth);
    }
    GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
        set_error(err, IP_ERR_UNSUPPORTED, "display: the image's framebuffer is incomplete");
        return -1;
    }
    d->width = width;
    d->height = height;
    return 0;
}

int display_show(display *d, const uint8_t *rgba, uint32_t width, uint32_t height,
                 const uint32_t rows[2], int mirror, ip_error *err)
{
    uint32_t first = rows[0], last = rows[1];
    if (width != d->width || height != d->height) {
        if (display_size(d, width, height, err) != 0)
            return -1;
        first = 0, last = height; /* the whole image */
    }
    if (rgba && last > first) {
        /* the changed rows, turned bottom first, so that the copy to the window is a plain one
         * (a software driver then copies memory instead of running a shader per pixel) */
        size_t row = (size_t)width * 4;
        for (uint32_t y = first; y < last; y++) {
            uint8_t *to = d->rows + (size_t)(last - 1 - y) * row;
            const uint8_t *from = rgba + (size_t)y * row;
            if (!mirror) {
                memcpy(to, from, row);
                continue;
            }
            for (uint32_t x = 0; x < width; x++) /* the physical view: columns reversed */
                memcpy(to + 4 * (size_t)x, from + 4 * (size_t)(width - 1 - x), 4);
        }
        glBindTexture(GL_TEXTURE_2D, d->texture);
        glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
        glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, (GLint)(height - last), (GLsizei)width,
                        (GLsizei)(last - first), GL_RGBA, GL_UNSIGNED_BYTE, d->rows);
        glBindTexture(GL_TEXTURE_2D, 0);
    }
    glBindFramebuffer(GL_READ_FRAMEBUFFER, d->framebuffer);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glDisable(GL_SCISSOR_TEST);
    glBlitFramebuffer(0, 0, (GLint)width, (GLint)height, 0, 0, (GLint)width, (GLint)height,
                      GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (glGetError() != GL_NO_ERROR) {
        set_error(err, IP_ERR_UNSUPPORTED, "display: an OpenGL error while showing the image");
        return -1;
    }
    return 0;
}

int display_read(uint32_t width, uint32_t height, uint8_t *rgba, ip_error *err)
{
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    glReadBuffer(GL_BACK);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glPixelStorei(GL_PACK_ROW_LENGTH, 0);
    glReadPixels(0, 0, (GLsizei)width, (GLsizei)height, GL_RGBA, GL_UNSIGNED_BYTE, rgba);
    if (glGetError() != GL_NO_ERROR) {
        set_error(err, IP_ERR_UNSUPPORTED, "screenshot: an OpenGL error while reading the window");
        return -1;
    }
    size_t row = (size_t)width * 4; /* OpenGL's rows are bottom first */
    uint8_t *swap = malloc(row);
    if (!swap) {
        set_error(err, IP_ERR_NOMEM, "out of memory for a screenshot");
        return -1;
    }
    for (uint32_t y = 0; y < height / 2; y++) {
        uint8_t *a = rgba + (size_t)y * row, *b = rgba + (size_t)(height - 1 - y) * row;
        memcpy(swap, a, row);
        memcpy(a, b, row);
        memcpy(b, swap, row);
    }
    free(swap);
    return 0;
}

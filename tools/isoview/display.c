/* isoview's software display: the canvas's image (the exact software rasterizer, drawing only
 * what is new) shown in the window as a texture, for machines whose OpenGL is itself software
 * (llvmpipe), where drawing the whole mesh every frame would set the pace. */
#include <stdlib.h>
#include <string.h>

#include "isoview.h"

/* One triangle over the window; each fragment fetches its pixel, the texture's row 0 (the
 * canvas's top row) at the top. */
static const char *const display_vertex_source =
    "#version 330 core\n"
    "void main() {\n"
    "    vec2 p = vec2(float((gl_VertexID & 1) * 4 - 1), float((gl_VertexID >> 1) * 4 - 1));\n"
    "    gl_Position = vec4(p, 0.0, 1.0);\n"
    "}\n";

static const char *const display_fragment_source =
    "#version 330 core\n"
    "uniform sampler2D image;\n"
    "uniform int height;\n"
    "out vec4 colour;\n"
    "void main() {\n"
    "    ivec2 p = ivec2(gl_FragCoord.xy);\n"
    "    colour = texelFetch(image, ivec2(p.x, height - 1 - p.y), 0);\n"
    "}\n";

int display_create(display *d, ip_error *err)
{
    memset(d, 0, sizeof *d);
    if (ip_gl_program(display_vertex_source, display_fragment_source, &d->program, err) != IP_OK)
        return -1;
    d->height_at = glGetUniformLocation(d->program, "height");
    glGenVertexArrays(1, &d->array);
    glGenTextures(1, &d->texture);
    if (glGetError() != GL_NO_ERROR) {
        set_error(err, IP_ERR_UNSUPPORTED, "display: an OpenGL error while setting up");
        return -1;
    }
    return 0;
}

void display_destroy(display *d)
{
    if (d->program) {
        glDeleteProgram(d->program);
        glDeleteVertexArrays(1, &d->array);
        glDeleteTextures(1, &d->texture);
    }
    memset(d, 0, sizeof *d);
}

int display_show(display *d, const uint8_t *rgba, uint32_t width, uint32_t height,
                 const uint32_t rows[2], ip_error *err)
{
    glBindTexture(GL_TEXTURE_2D, d->texture);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    if (width != d->width || height != d->height) { /* a new size: the whole image */
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, (GLsizei)width, (GLsizei)height, 0, GL_RGBA,
                     GL_UNSIGNED_BYTE, rgba);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        d->width = width;
        d->height = height;
    } else if (rows[1] > rows[0]) { /* the rows that changed */
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, (GLint)rows[0], (GLsizei)width,
                        (GLsizei)(rows[1] - rows[0]), GL_RGBA, GL_UNSIGNED_BYTE,
                        rgba + (size_t)rows[0] * width * 4);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, (GLsizei)width, (GLsizei)height);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glDisable(GL_SCISSOR_TEST);
    glUseProgram(d->program);
    glUniform1i(d->height_at, (GLint)height);
    glActiveTexture(GL_TEXTURE0);
    glBindVertexArray(d->array);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glUseProgram(0);
    glBindTexture(GL_TEXTURE_2D, 0);
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

/* SPDX-License-Identifier: BSD-3-Clause */
/* PNG output of rendered images through libpng, written atomically. */
#include <png.h>
#include <setjmp.h>
#include <stdio.h>
#include <string.h>

#include "atomic_file.h"
#include "internal.h"
#include "isoprop/render.h"

/* Where libpng's output goes, and what went wrong: libpng reports errors by longjmp. */
typedef struct png_sink {
    int fd;
    uint64_t offset;
    const char *path;
    ip_error *err;
    ip_status status;  /* the first failure */
    char message[256]; /* libpng's own error message */
} png_sink;

static void sink_write(png_structp png, png_bytep data, size_t size)
{
    png_sink *sink = png_get_io_ptr(png);
    ip_status st = ip__pwrite_all(sink->fd, data, size, sink->offset, sink->path, sink->err);
    if (st != IP_OK) {
        sink->status = st;
        png_error(png, "write failed");
    }
    sink->offset += size;
}

static void sink_flush(png_structp png)
{
    (void)png; /* ip__atomic_commit() makes the file durable */
}

static void sink_error(png_structp png, png_const_charp message)
{
    png_sink *sink = png_get_error_ptr(png);
    if (sink->status == IP_OK) {
        sink->status = IP_ERR_IO;
        snprintf(sink->message, sizeof sink->message, "%s", message);
    }
    png_longjmp(png, 1);
}

static void sink_warning(png_structp png, png_const_charp message)
{
    (void)png; /* the library never prints; warnings do not change the file */
    (void)message;
}

static int fully_opaque(const uint8_t *rgba, size_t pixels)
{
    for (size_t i = 0; i < pixels; i++)
        if (rgba[4 * i + 3] != 255)
            return 0;
    return 1;
}

/* Everything libpng may longjmp out of; nothing here is used after a longjmp. */
static int encode(png_structp png, png_infop info, const uint8_t *rgba, uint32_t width,
                  uint32_t height, int opaque)
{
    if (setjmp(png_jmpbuf(png)))
        return -1;
    png_set_IHDR(png, info, width, height, 8, opaque ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_RGBA,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    if (opaque)
        png_set_filler(png, 0, PNG_FILLER_AFTER); /* rows keep 4 bytes; alpha is dropped */
    for (uint32_t y = 0; y < height; y++)
        png_write_row(png, (png_const_bytep)(rgba + (size_t)y * width * 4));
    png_write_end(png, NULL);
    return 0;
}

static ip_status write_stream(png_sink *sink, const uint8_t *rgba, uint32_t width, uint32_t height)
{
    png_structp png =
        png_create_write_struct(PNG_LIBPNG_VER_STRING, sink, sink_error, sink_warning);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!info) {
        png_destroy_write_struct(&png, NULL);
        return ip__fail(sink->err, IP_ERR_NOMEM, "%s: out of memory", sink->path);
    }
    png_set_write_fn(png, sink, sink_write, sink_flush);
    int opaque = fully_opaque(rgba, (size_t)width * height);
    int failed = encode(png, info, rgba, width, height, opaque);
    png_destroy_write_struct(&png, &info);
    if (!failed)
        return IP_OK;
    if (sink->message[0])
        return ip__fail(sink->err, sink->status, "%s: PNG encoding failed: %s", sink->path,
                        sink->message);
    return sink->status; /* a write error, already reported by ip__pwrite_all */
}

ip_status ip_png_write(const char *path, const uint8_t *rgba, uint32_t width, uint32_t height,
                       int force, ip_error *err)
{
    if (width == 0 || height == 0 || width > PNG_UINT_31_MAX || height > PNG_UINT_31_MAX)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: image size %ux%u is not a PNG size", path, width,
                        height);
    ip_atomic_file out;
    ip_status st = ip__atomic_create(&out, path, force, err);
    if (st != IP_OK)
        return st;
    png_sink sink = {.fd = out.fd, .path = path, .err = err, .status = IP_OK};
    st = write_stream(&sink, rgba, width, height);
    if (st == IP_OK)
        return ip__atomic_commit(&out, err);
    ip__atomic_abort(&out);
    return st;
}

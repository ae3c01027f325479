/* SPDX-License-Identifier: BSD-3-Clause */
/* png_read: reading a PNG image as 8-bit RGBA for the image helpers (png_read.h). */
#include "png_read.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

unsigned char *png_read_rgba(const char *program, const char *path, png_uint_32 *width,
                             png_uint_32 *height)
{
    png_image image;
    memset(&image, 0, sizeof image);
    image.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&image, path)) {
        fprintf(stderr, "%s: %s: %s\n", program, path, image.message);
        return NULL;
    }
    image.format = PNG_FORMAT_RGBA;
    unsigned char *rgba = malloc(PNG_IMAGE_SIZE(image));
    if (!rgba || !png_image_finish_read(&image, NULL, rgba, 0, NULL)) {
        fprintf(stderr, "%s: %s: %s\n", program, path, rgba ? image.message : "out of memory");
        png_image_free(&image);
        free(rgba);
        return NULL;
    }
    *width = image.width;
    *height = image.height;
    return rgba;
}

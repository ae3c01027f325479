/* SPDX-License-Identifier: BSD-3-Clause */
/* png_read: reading a PNG image as 8-bit RGBA, shared by the image helpers of the end-to-end
 * tests (png_compare, png_over, png_pixel). */
#ifndef ISOPROP_TESTS_PNG_READ_H
#define ISOPROP_TESTS_PNG_READ_H

#include <png.h>

/* Reads `path` as 8-bit RGBA, top row first, into a malloc'd buffer (the caller frees it) and
 * its size into width and height. On failure prints "PROGRAM: PATH: why" to stderr and
 * returns NULL. */
unsigned char *png_read_rgba(const char *program, const char *path, png_uint_32 *width,
                             png_uint_32 *height);

#endif

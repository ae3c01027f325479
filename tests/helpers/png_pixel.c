/* SPDX-License-Identifier: BSD-3-Clause */
/* png_pixel: prints the colour of one pixel of a PNG image, for the end-to-end tests.
 *
 *   png_pixel IMAGE.png X,Y
 *
 * (X, Y) counts from the top-left pixel; X or Y may be negative to count from the right or the
 * bottom (-1: the last column or row). Prints "R G B A" (8-bit channels, the image read as
 * RGBA). Exit status: 0, or 2 for a bad command line, an unreadable image or a pixel outside
 * it.
 */
#include "png_read.h"

#include <stdio.h>
#include <stdlib.h>

int main(int argc, char **argv)
{
    long x, y;
    char tail;
    if (argc != 3 || sscanf(argv[2], "%ld,%ld%c", &x, &y, &tail) != 2) {
        fprintf(stderr, "usage: png_pixel IMAGE.png X,Y\n");
        return 2;
    }
    png_uint_32 width, height;
    unsigned char *rgba = png_read_rgba("png_pixel", argv[1], &width, &height);
    if (!rgba)
        return 2;
    long w = (long)width, h = (long)height;
    x = x < 0 ? w + x : x;
    y = y < 0 ? h + y : y;
    if (x < 0 || x >= w || y < 0 || y >= h) {
        fprintf(stderr, "png_pixel: %s: %s is outside its %ldx%ld pixels\n", argv[1], argv[2], w,
                h);
        free(rgba);
        return 2;
    }
    const unsigned char *p = rgba + ((size_t)y * (size_t)w + (size_t)x) * 4;
    printf("%u %u %u %u\n", p[0], p[1], p[2], p[3]);
    free(rgba);
    return 0;
}

/* png_pixel: prints the colour of one pixel of a PNG image, for the end-to-end tests.
 *
 *   png_pixel IMAGE.png X,Y
 *
 * (X, Y) counts from the top-left pixel; X or Y may be negative to count from the right or the
 * bottom (-1: the last column or row). Prints "R G B A" (8-bit channels, the image read as
 * RGBA). Exit status: 0, or 2 for a bad command line, an unreadable image or a pixel outside
 * it.
 */
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int main(int argc, char **argv)
{
    long x, y;
    char tail;
    if (argc != 3 || sscanf(argv[2], "%ld,%ld%c", &x, &y, &tail) != 2) {
        fprintf(stderr, "usage: png_pixel IMAGE.png X,Y\n");
        return 2;
    }
    png_image image;
    memset(&image, 0, sizeof image);
    image.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&image, argv[1])) {
        fprintf(stderr, "png_pixel: %s: %s\n", argv[1], image.message);
        return 2;
    }
    image.format = PNG_FORMAT_RGBA;
    unsigned char *rgba = malloc(PNG_IMAGE_SIZE(image));
    if (!rgba || !png_image_finish_read(&image, NULL, rgba, 0, NULL)) {
        fprintf(stderr, "png_pixel: %s: %s\n", argv[1], rgba ? image.message : "out of memory");
        png_image_free(&image);
        free(rgba);
        return 2;
    }
    long w = (long)image.width, h = (long)image.height;
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

/* SPDX-License-Identifier: BSD-3-Clause */
/* png_over: the expected image of a translucent surface over another, for the end-to-end
 * tests, made from images of each surface alone.
 *
 *   png_over TOP.png UNDER.png BACKGROUND.png ALPHA OUT.png
 *
 * TOP is the translucent surface drawn alone and opaque, UNDER what lies behind it drawn
 * alone, BACKGROUND the empty image. Each pixel of OUT is UNDER's where TOP shows the
 * background (equals BACKGROUND), and round(ALPHA * TOP + (1 - ALPHA) * UNDER) elsewhere:
 * the rule of a translucent surface whose nearest layer lies in front of what is under it.
 * Exit status: 0, 1 when an image cannot be read or written, 2 for a bad command line.
 */
#include "png_read.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int main(int argc, char **argv)
{
    if (argc != 6) {
        fprintf(stderr, "usage: png_over TOP.png UNDER.png BACKGROUND.png ALPHA OUT.png\n");
        return 2;
    }
    char *end;
    double a = strtod(argv[4], &end);
    if (*end || !(a >= 0 && a <= 1)) {
        fprintf(stderr, "png_over: ALPHA '%s' is not in [0, 1]\n", argv[4]);
        return 2;
    }
    png_uint_32 w[3], h[3];
    unsigned char *img[3] = {NULL, NULL, NULL};
    int rc = 0;
    for (int i = 0; i < 3 && rc == 0; i++)
        if (!(img[i] = png_read_rgba("png_over", argv[1 + i], &w[i], &h[i])))
            rc = 1;
    if (rc == 0 && (w[1] != w[0] || w[2] != w[0] || h[1] != h[0] || h[2] != h[0])) {
        fprintf(stderr, "png_over: the images' sizes differ\n");
        rc = 1;
    }
    if (rc == 0) {
        const unsigned char *top = img[0], *background = img[2];
        unsigned char *out = img[1];
        for (size_t p = 0; p < (size_t)w[0] * h[0]; p++) {
            if (memcmp(top + 4 * p, background + 4 * p, 4) == 0)
                continue;
            for (int k = 0; k < 3; k++)
                out[4 * p + k] =
                    (unsigned char)lround(a * top[4 * p + k] + (1 - a) * out[4 * p + k]);
        }
        png_image image;
        memset(&image, 0, sizeof image);
        image.version = PNG_IMAGE_VERSION;
        image.width = w[0];
        image.height = h[0];
        image.format = PNG_FORMAT_RGBA;
        if (!png_image_write_to_file(&image, argv[5], 0, out, 0, NULL)) {
            fprintf(stderr, "png_over: %s: %s\n", argv[5], image.message);
            rc = 1;
        }
    }
    for (int i = 0; i < 3; i++)
        free(img[i]);
    return rc;
}

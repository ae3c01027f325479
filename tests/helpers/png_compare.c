/* SPDX-License-Identifier: BSD-3-Clause */
/* png_compare: compares two PNG images pixel by pixel, for the end-to-end tests.
 *
 *   png_compare A.png B.png [--level L] [--max-pct P] [--crop X,Y,W,H] [--bbox]
 *
 * Both images are read as 8-bit RGBA. With --crop, A's rectangle of W x H pixels whose top-left
 * pixel is (X, Y) stands for A (a frame of a strip, say). A pixel differs when one of its channels differs by more
 * than L (default 0). Prints one line: the size, how many pixels differ and the largest channel
 * difference. Exit status: 0 when the sizes agree and at most P % of the pixels differ
 * (default 0), 1 otherwise, 2 for a bad command line or an unreadable image. With --bbox, a
 * second line gives the smallest rectangle holding every pixel that differs: "bbox X Y W H"
 * (top-left pixel, size), or "bbox none".
 *
 *   png_compare A.png BIG.png --box K
 *
 * for anti-aliasing: BIG, K times A's size on both axes, is shrunk by averaging each K x K
 * block (per channel, as real numbers), and the mean absolute difference between that and A,
 * over every pixel and the R, G and B channels, is printed with 4 decimals. Exit status 0, or
 * 2 when the sizes do not fit.
 */
#include "png_read.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Replaces the image by its rectangle crop[] = x, y, w, h; -1 when that lies outside it. */
static int crop_image(unsigned char **rgba, png_uint_32 *width, png_uint_32 *height,
                      const unsigned long crop[4])
{
    if (crop[2] == 0 || crop[3] == 0 || crop[0] + crop[2] > *width || crop[1] + crop[3] > *height)
        return -1;
    unsigned char *part = malloc((size_t)crop[2] * crop[3] * 4);
    if (!part)
        return -1;
    for (unsigned long y = 0; y < crop[3]; y++)
        memcpy(part + (size_t)y * crop[2] * 4,
               *rgba + ((size_t)(crop[1] + y) * *width + crop[0]) * 4, (size_t)crop[2] * 4);
    free(*rgba);
    *rgba = part;
    *width = (png_uint_32)crop[2];
    *height = (png_uint_32)crop[3];
    return 0;
}

/* The block of BIG (k x k pixels, big_width wide) at (x, y) of the small image, averaged. */
static double block_mean(const unsigned char *big, png_uint_32 big_width, unsigned long k,
                         png_uint_32 x, png_uint_32 y, int channel)
{
    double sum = 0;
    for (unsigned long j = 0; j < k; j++)
        for (unsigned long i = 0; i < k; i++)
            sum += big[(((size_t)y * k + j) * big_width + (size_t)x * k + i) * 4 + channel];
    return sum / (double)(k * k);
}

/* --box K: prints the mean absolute difference between A and BIG box-filtered by K. */
static int box_difference(const unsigned char *a, png_uint_32 w, png_uint_32 h,
                          const unsigned char *big, png_uint_32 bw, png_uint_32 bh, unsigned long k)
{
    if (bw != w * k || bh != h * k) {
        fprintf(stderr, "png_compare: %ux%u is not %lu times %ux%u\n", (unsigned)bw, (unsigned)bh,
                k, (unsigned)w, (unsigned)h);
        return 2;
    }
    double total = 0;
    for (png_uint_32 y = 0; y < h; y++)
        for (png_uint_32 x = 0; x < w; x++)
            for (int c = 0; c < 3; c++) {
                double d = block_mean(big, bw, k, x, y, c) - a[((size_t)y * w + x) * 4 + c];
                total += d < 0 ? -d : d;
            }
    printf("%.4f\n", total / (3.0 * w * h));
    return 0;
}

static int parse_crop(const char *text, unsigned long crop[4])
{
    char tail;
    return sscanf(text, "%lu,%lu,%lu,%lu%c", &crop[0], &crop[1], &crop[2], &crop[3], &tail) == 4
               ? 0
               : -1;
}

static int parse_number(const char *text, double *out)
{
    char *end;
    *out = strtod(text, &end);
    return end != text && !*end && *out >= 0 ? 0 : -1;
}

int main(int argc, char **argv)
{
    const char *path[2] = {NULL, NULL};
    double level = 0, max_pct = 0;
    int files = 0, cropped = 0, bbox = 0;
    double box = 0;
    unsigned long crop[4];
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--level") && i + 1 < argc) {
            if (parse_number(argv[++i], &level) != 0)
                goto usage;
        } else if (!strcmp(argv[i], "--max-pct") && i + 1 < argc) {
            if (parse_number(argv[++i], &max_pct) != 0)
                goto usage;
        } else if (!strcmp(argv[i], "--crop") && i + 1 < argc) {
            if (parse_crop(argv[++i], crop) != 0)
                goto usage;
            cropped = 1;
        } else if (!strcmp(argv[i], "--box") && i + 1 < argc) {
            if (parse_number(argv[++i], &box) != 0 || box < 1 || box > 64 || box != (int)box)
                goto usage;
        } else if (!strcmp(argv[i], "--bbox")) {
            bbox = 1;
        } else if (argv[i][0] != '-' && files < 2) {
            path[files++] = argv[i];
        } else {
            goto usage;
        }
    }
    if (files != 2)
        goto usage;
    png_uint_32 w[2] = {0, 0}, h[2] = {0, 0};
    unsigned char *a = png_read_rgba("png_compare", path[0], &w[0], &h[0]);
    unsigned char *b = a ? png_read_rgba("png_compare", path[1], &w[1], &h[1]) : NULL;
    if (!b) {
        free(a);
        return 2;
    }
    if (box >= 1) {
        int rc = box_difference(a, w[0], h[0], b, w[1], h[1], (unsigned long)box);
        free(a);
        free(b);
        return rc;
    }
    if (cropped && crop_image(&a, &w[0], &h[0], crop) != 0) {
        fprintf(stderr, "png_compare: %s: --crop %lu,%lu,%lu,%lu is not within its %ux%u pixels\n",
                path[0], crop[0], crop[1], crop[2], crop[3], (unsigned)w[0], (unsigned)h[0]);
        free(a);
        free(b);
        return 2;
    }
    if (w[0] != w[1] || h[0] != h[1]) {
        printf("%s %s: sizes differ (%ux%u, %ux%u)\n", path[0], path[1], (unsigned)w[0],
               (unsigned)h[0], (unsigned)w[1], (unsigned)h[1]);
        free(a);
        free(b);
        return 1;
    }
    size_t pixels = (size_t)w[0] * h[0], differ = 0;
    int largest = 0;
    size_t x0 = w[0], y0 = h[0], x1 = 0, y1 = 0; /* the differing pixels' bounds */
    for (size_t p = 0; p < pixels; p++) {
        int worst = 0;
        for (int c = 0; c < 4; c++) {
            int d = abs((int)a[4 * p + c] - (int)b[4 * p + c]);
            worst = d > worst ? d : worst;
        }
        largest = worst > largest ? worst : largest;
        differ += worst > level;
        if (worst > level) {
            size_t x = p % w[0], y = p / w[0];
            x0 = x < x0 ? x : x0;
            y0 = y < y0 ? y : y0;
            x1 = x > x1 ? x : x1;
            y1 = y > y1 ? y : y1;
        }
    }
    double pct = pixels ? 100.0 * (double)differ / (double)pixels : 0.0;
    printf("%s %s: %ux%u, %zu pixels (%.3f %%) differ by more than %g, largest difference %d\n",
           path[0], path[1], (unsigned)w[0], (unsigned)h[0], differ, pct, level, largest);
    if (bbox && differ)
        printf("bbox %zu %zu %zu %zu\n", x0, y0, x1 - x0 + 1, y1 - y0 + 1);
    else if (bbox)
        printf("bbox none\n");
    free(a);
    free(b);
    return pct <= max_pct ? 0 : 1;
usage:
    fprintf(stderr,
            "usage: png_compare A.png B.png [--level L] [--max-pct P] [--crop X,Y,W,H] [--bbox]\n"
            "       png_compare A.png BIG.png --box K\n");
    return 2;
}

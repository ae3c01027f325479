/* SPDX-License-Identifier: BSD-3-Clause */
/* make_dicom: writes a small int16 volume twice, as a raw file and as a DICOM series made from
 * it (dicom_series.h: shuffled file order, transfer syntaxes by turns), and folders as
 * scanners write them, for the end-to-end tests of DICOM input.
 *
 *   make_dicom DIR [--air]   writes DIR/volume_40x36x13_int16.raw and DIR/series/IM0001.dcm
 *                     ...; DIR/tilted/: a ball imaged with a gantry tilt (test_dicom_tilted());
 *                     DIR/scanner/: DIRFILE (a media storage directory), SR0001 (a basic
 *                     text report), PS0001 (a grayscale presentation state), S1/ the series
 *                     again ("Head") and S2/ the tilted one
 *
 * The series, a CT, says spacing 0.8 (x), 0.7 (y), 2.5 (z) mm and rescale stored x 1 - 1024
 * (Hounsfield units). The volume is an ellipsoid, stored 2000 at its centre falling by 40 a
 * millimetre; with --air by 80 a millimetre, down to stored 24 (-1000 HU, air), so that it
 * crosses -500 HU (stored 524) well inside the volume.
 * Exit status: 0 done, 1 a file could not be written, 2 a bad command line. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "dicom_series.h"

/* DIR/name as a new folder, its path into out; 0 or -1. */
static int folder(const char *dir, const char *name, char out[4096])
{
    snprintf(out, 4096, "%.3900s/%s", dir, name);
    if (mkdir(out, 0777) != 0) {
        fprintf(stderr, "make_dicom: %s: cannot create\n", out);
        return -1;
    }
    return 0;
}

/* The scanner's folder: the objects that are not images beside the two series' folders. */
static int write_scanner(const char *dir, const test_dicom_series *head, const int16_t *volume,
                         const test_dicom_series *tilted, const int16_t *ball)
{
    char path[4096], sub[4096];
    if (folder(dir, "scanner", path) != 0)
        return -1;
    snprintf(sub, sizeof sub, "%.3900s/DIRFILE", path);
    test_dicom_write_object(sub, TEST_DICOM_DIRECTORY, NULL);
    snprintf(sub, sizeof sub, "%.3900s/SR0001", path);
    test_dicom_write_object(sub, TEST_DICOM_BASIC_TEXT_SR, head->series_uid);
    snprintf(sub, sizeof sub, "%.3900s/PS0001", path);
    test_dicom_write_object(sub, TEST_DICOM_GRAYSCALE_PS, head->series_uid);
    if (folder(path, "S1", sub) != 0)
        return -1;
    test_dicom_write_series(head, volume, sub);
    if (folder(path, "S2", sub) != 0)
        return -1;
    test_dicom_write_series(tilted, ball, sub);
    return 0;
}

int main(int argc, char **argv)
{
    char path[4096];
    int air = argc == 3 && strcmp(argv[2], "--air") == 0;
    if (argc != 2 && !air) {
        fputs("usage: make_dicom DIR [--air]\n", stderr);
        return 2;
    }
    double fall = air ? 80.0 : 40.0, floor = air ? 24.0 : -32768.0;
    test_dicom_series s = test_dicom_default(40, 36, 13, IP_INT16);
    size_t count = (size_t)s.dims[0] * s.dims[1] * s.dims[2];
    int16_t *volume = malloc(count * sizeof *volume);
    if (!volume)
        return 1;
    /* an ellipsoid in world units: 2000 at its centre, falling by 40 (80) a millimetre */
    for (uint32_t z = 0; z < s.dims[2]; z++)
        for (uint32_t y = 0; y < s.dims[1]; y++)
            for (uint32_t x = 0; x < s.dims[0]; x++) {
                double dx = (x - 19.5) * 0.8, dy = (y - 17.5) * 0.7, dz = (z - 6.0) * 2.5;
                double r = sqrt(dx * dx + dy * dy + dz * dz);
                volume[(size_t)z * s.dims[0] * s.dims[1] + (size_t)y * s.dims[0] + x] =
                    (int16_t)lround(fmax(floor, 2000.0 - fall * r));
            }
    snprintf(path, sizeof path, "%.4000s/volume_40x36x13_int16.raw", argv[1]);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(volume, sizeof *volume, count, f) != count || fclose(f) != 0) {
        fprintf(stderr, "make_dicom: %s: cannot write\n", path);
        return 1;
    }
    if (folder(argv[1], "series", path) != 0)
        return 1;
    test_dicom_write_series(&s, volume, path);
    test_dicom_series tilted = test_dicom_tilted();
    const double centre[3] = TEST_DICOM_BALL_CENTRE;
    int16_t *ball = test_dicom_ball(&tilted, centre);
    if (folder(argv[1], "tilted", path) != 0)
        return 1;
    test_dicom_write_series(&tilted, ball, path);
    s.description = "Head";
    int rc = write_scanner(argv[1], &s, volume, &tilted, ball) != 0;
    free(ball);
    free(volume);
    return rc;
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* make_formats: a raw volume written again as TIFF and NIfTI, for the end-to-end test that
 * they brick to the same samples as the raw file.
 *
 *   make_formats RAW OUTDIR PIXEL,SLICE
 *
 * RAW is read through ip_input (NAME_XxYxZ_TYPE.raw). Writes in OUTDIR (which must exist):
 * stack.tif (one LZW page a plane, ImageJ's calibration: pixel size PIXEL, slice distance
 * SLICE), slices/ (one deflate-compressed, tiled file a plane, slice1.tif ...), volume.nii.gz
 * (NIfTI-1, little-endian, gzip) and volume_be.nii (NIfTI-2, big-endian), both with pixdim
 * PIXEL,PIXEL,SLICE and a scaling of 2 x stored - 10.
 *
 * Exit status: 0 done, 1 a failure, 2 a bad command line. */
#include <stdio.h>
#include <sys/stat.h>

#include "volume_files.h"

static int fail(const char *what)
{
    fprintf(stderr, "make_formats: %s\n", what);
    return 1;
}

int main(int argc, char **argv)
{
    double pixel, slice;
    char path[4096];
    if (argc != 4 || sscanf(argv[3], "%lf,%lf", &pixel, &slice) != 2) {
        fputs("usage: make_formats RAW OUTDIR PIXEL,SLICE\n", stderr);
        return 2;
    }
    ip_input_desc d;
    ip_error err;
    if (ip_input_describe(argv[1], NULL, &d, &err) != IP_OK)
        return fail(err.message);
    void *samples = read_volume(&d, &err);
    if (!samples)
        return fail(err.message);
    int bad = 0;
    tiff_style stack = {COMPRESSION_LZW, 4, 0, slice, pixel};
    snprintf(path, sizeof path, "%s/stack.tif", argv[2]);
    bad |= write_tiff(path, d.type, d.dims[0], d.dims[1], d.dims[2], samples, &stack);
    tiff_style tiles = {COMPRESSION_ADOBE_DEFLATE, 0, 16, slice, pixel};
    snprintf(path, sizeof path, "%s/slices", argv[2]);
    bad |= mkdir(path, 0777);
    bad |= write_tiff_folder(path, "slice", 1, d.type, d.dims, samples, &tiles);
    for (int version = 1; version <= 2; version++) {
        nifti_style s = {.version = version,
                         .big_endian = version == 2,
                         .gzip = version == 1,
                         .pixdim = {pixel, pixel, slice},
                         .slope = 2.0,
                         .intercept = -10.0};
        snprintf(path, sizeof path, "%s/%s", argv[2],
                 version == 1 ? "volume.nii.gz" : "volume_be.nii");
        bad |= write_nifti(path, d.type, d.dims, samples, &s);
    }
    free(samples);
    return bad ? fail("cannot write the files") : 0;
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* make_orders: one asymmetric object in physical space, stored in several sample orders, for the
 * end-to-end test that views, meshes and statistics follow the physical object, not the order
 * its samples are stored in (tests/tools/orders.sh).
 *
 *   make_orders DIR
 *
 * The object, in RAS millimetres about the grid's centre: a head-like ellipsoid (semi-axes 7,
 * 12 and 13 mm along right, anterior and superior) with a nose on its anterior side, an ear on
 * its right and a knot on top, left of the middle and behind it; int16 samples on a grid of
 * 33 x 33 x 17, 0.75 x 1.25 x 2.5 mm apart (powers of two plus one: every pyramid level samples
 * the same points whichever way an axis runs). Writes in DIR (which must exist):
 *   ras.nii   NIfTI-1, the samples in RAS order (x right, y anterior, z superior), an sform
 *             whose directions are the unit axes;
 *   las.nii   x reversed (x runs left), the sform adjusted: a reflection of ras.nii's order;
 *   lai.nii   x and z reversed (x left, z inferior), the sform adjusted: a half turn;
 *   series/   a DICOM series (LPS: rows run left, columns posterior) whose slices go from
 *             head to foot (Image Position z falls as the instance number rises), each file a
 *             plane, in a shuffled order (dicom_series.h).
 * No rescale anywhere: every file holds the same sample values at the same physical points.
 *
 * Exit status: 0 done, 1 a file could not be written, 2 a bad command line. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>

#include "dicom_series.h"
#include "volume_files.h"

enum {
    NX = 33,
    NY = 33,
    NZ = 17
};
static const double spacing[3] = {0.75, 1.25, 2.5};

/* The DICOM series' grid (dicom_series.h): pixel (i, j) of a slice at L = -12.5 + 0.75 i,
 * P = 30 + 1.25 j; slice z at S = 20 - 2.5 z. */
#define DICOM_L0 (-12.5)
#define DICOM_P0 30.0
#define DICOM_S0 20.0

/* A bump of `height` over a ball of `radius` mm about c: height at c, 0 from the radius on. */
static double bump(const double p[3], const double c[3], double radius, double height)
{
    double d = sqrt((p[0] - c[0]) * (p[0] - c[0]) + (p[1] - c[1]) * (p[1] - c[1]) +
                    (p[2] - c[2]) * (p[2] - c[2]));
    return d < radius ? height * (1.0 - d / radius) : 0.0;
}

/* The object's value at p (RAS mm about the grid's centre). */
static int16_t object(const double p[3])
{
    double q = p[0] * p[0] / 49.0 + p[1] * p[1] / 144.0 + p[2] * p[2] / 169.0;
    double v = 1000.0 * (1.0 - sqrt(q)); /* 0 on the ellipsoid, 1000 at its centre */
    static const double nose[3] = {0, 12.5, 0}, ear[3] = {7, 0, 2}, knot[3] = {-3, -4, 13};
    v = fmax(v, bump(p, nose, 4.0, 600.0) - 100.0);
    v = fmax(v, bump(p, ear, 3.0, 500.0) - 100.0);
    v = fmax(v, bump(p, knot, 4.5, 700.0) - 100.0);
    return (int16_t)lround(fmax(v, -300.0));
}

/* Sample (i, j, k) of the RAS-ordered grid: i right, j anterior, k superior. Its RAS position
 * is that of DICOM pixel (NX - 1 - i, NY - 1 - j) of the slice at S = -20 + 2.5 k. */
static void ras_position(int i, int j, int k, double ras[3])
{
    ras[0] = -(DICOM_L0 + spacing[0] * (NX - 1 - i));
    ras[1] = -(DICOM_P0 + spacing[1] * (NY - 1 - j));
    ras[2] = DICOM_S0 - spacing[2] * (NZ - 1) + spacing[2] * k;
}

static size_t at(int i, int j, int k)
{
    return (size_t)i + NX * ((size_t)j + NY * (size_t)k);
}

/* A NIfTI-1 file of the RAS-ordered `ras` samples stored with x (flip_x) and z (flip_z)
 * reversed, and the sform that puts each sample where it was. */
static int write_order(const char *dir, const char *name, const int16_t *ras, int flip_x,
                       int flip_z)
{
    static const uint32_t dims[3] = {NX, NY, NZ};
    int16_t *stored = malloc(sizeof *stored * NX * NY * NZ);
    if (!stored)
        return 1;
    for (int k = 0; k < NZ; k++)
        for (int j = 0; j < NY; j++)
            for (int i = 0; i < NX; i++)
                stored[at(i, j, k)] = ras[at(flip_x ? NX - 1 - i : i, j, flip_z ? NZ - 1 - k : k)];
    double first[3]; /* where the stored sample 0 lies */
    ras_position(flip_x ? NX - 1 : 0, 0, flip_z ? NZ - 1 : 0, first);
    nifti_style s = {.version = 1, .pixdim = {spacing[0], spacing[1], spacing[2]}};
    s.sform_code = 1;
    s.srow[0][0] = flip_x ? -spacing[0] : spacing[0];
    s.srow[1][1] = spacing[1];
    s.srow[2][2] = flip_z ? -spacing[2] : spacing[2];
    for (int a = 0; a < 3; a++)
        s.srow[a][3] = first[a];
    char path[4096];
    snprintf(path, sizeof path, "%.4000s/%s", dir, name);
    int bad = write_nifti(path, IP_INT16, dims, stored, &s);
    free(stored);
    return bad;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fputs("usage: make_orders DIR\n", stderr);
        return 2;
    }
    int16_t *ras = malloc(sizeof *ras * NX * NY * NZ),
            *dicom = malloc(sizeof *dicom * NX * NY * NZ);
    if (!ras || !dicom)
        return 1;
    double centre[3], p[3];
    ras_position(0, 0, 0, centre);
    ras_position(NX - 1, NY - 1, NZ - 1, p);
    for (int a = 0; a < 3; a++)
        centre[a] = 0.5 * (centre[a] + p[a]);
    for (int k = 0; k < NZ; k++)
        for (int j = 0; j < NY; j++)
            for (int i = 0; i < NX; i++) {
                ras_position(i, j, k, p);
                for (int a = 0; a < 3; a++)
                    p[a] -= centre[a];
                ras[at(i, j, k)] = object(p);
                /* the series' plane z (S = 20 - 2.5 z), pixel (NX-1-i, NY-1-j) */
                dicom[at(NX - 1 - i, NY - 1 - j, NZ - 1 - k)] = ras[at(i, j, k)];
            }
    int bad = write_order(argv[1], "ras.nii", ras, 0, 0) ||
              write_order(argv[1], "las.nii", ras, 1, 0) ||
              write_order(argv[1], "lai.nii", ras, 1, 1);
    char path[4096];
    snprintf(path, sizeof path, "%.4000s/series", argv[1]);
    if (!bad && mkdir(path, 0777) != 0)
        bad = 1;
    if (!bad) {
        test_dicom_series s = test_dicom_default(NX, NY, NZ, IP_INT16);
        s.pixel_spacing[0] = spacing[1]; /* between rows: along y */
        s.pixel_spacing[1] = spacing[0];
        s.origin_z = DICOM_S0;
        s.step_z = -spacing[2]; /* head to foot */
        s.rescale = 0;
        test_dicom_write_series(&s, dicom, path);
    }
    free(ras);
    free(dicom);
    if (bad)
        fprintf(stderr, "make_orders: %s: cannot write the files\n", argv[1]);
    return bad;
}

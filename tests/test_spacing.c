/* SPDX-License-Identifier: BSD-3-Clause */
/* Spacing bounds: ip_spacing_check() accepts exactly [IP_SPACING_MIN, IP_SPACING_MAX] with a
 * largest-to-smallest ratio of at most IP_SPACING_RATIO_MAX; ip_input_describe() and
 * ip_bricker_run() refuse the rest; and the camera's depth range scales with the volume, so
 * that the smallest accepted spacing is framed like any other (docs/format.md gives the
 * measured limits behind the bounds). */
#include <math.h>
#include <sys/stat.h>

#include "check.h"
#include "isoprop/bricker.h"
#include "isoprop/camera.h"
#include "isoprop/generate.h"
#include "isoprop/input.h"
#include "isoprop/volume.h"

static const char *scratch_dir;

static void check_accepted(double x, double y, double z)
{
    const double s[3] = {x, y, z};
    ip_error err;
    ip_error_clear(&err);
    CHECK_MSG(ip_spacing_check(s, "v.raw", &err) == IP_OK, "%g,%g,%g refused: %s", x, y, z,
              err.message);
}

/* Refused with IP_ERR_UNSUPPORTED, a message naming the file and holding `needle`. */
static void check_refused(double x, double y, double z, const char *needle)
{
    const double s[3] = {x, y, z};
    ip_error err;
    ip_error_clear(&err);
    CHECK_MSG(ip_spacing_check(s, "v.raw", &err) == IP_ERR_UNSUPPORTED, "%g,%g,%g accepted", x, y,
              z);
    CHECK_CONTAINS(err.message, "v.raw: spacing");
    CHECK_CONTAINS(err.message, needle);
    CHECK_EQ(strchr(err.message, '\n'), NULL);
}

static void test_bounds(void)
{
    check_accepted(1, 1, 1);
    check_accepted(IP_SPACING_MIN, IP_SPACING_MIN, IP_SPACING_MIN);
    check_accepted(IP_SPACING_MAX, IP_SPACING_MAX, IP_SPACING_MAX);
    check_accepted(1e-6, 1e-6, 2e-6); /* micrometre voxels in metres */
    check_accepted(4e-9, 4e-9, 4e-8); /* nanometre voxels in metres */
    check_accepted(0.3, 0.3, 0.3 * IP_SPACING_RATIO_MAX);
    check_accepted(1e-9, 1e-6, 1e-9 * IP_SPACING_RATIO_MAX);
    check_refused(1e-12, 1e-12, 1e-12, "1e-09 to 1e+06");
    check_refused(1e-12, 1e-12, 1e-12, "micrometres instead of metres");
    check_refused(1, 1, IP_SPACING_MIN / 2, "along z");
    check_refused(2e6, 2e6, 2e6, "kilometres instead of metres");
    check_refused(1, 1, 1.01 * IP_SPACING_RATIO_MAX, "1000 times");
    check_refused(1, 1, 1.01 * IP_SPACING_RATIO_MAX, "resample");
    check_refused(0, 1, 1, "along x");
    check_refused(1, NAN, 1, "along y");
    check_refused(1, 1, INFINITY, "along z");
    const double s[3] = {1e-12, 1, 1};
    ip_error err;
    CHECK_EQ(ip_spacing_check(s, NULL, &err), IP_ERR_UNSUPPORTED);
    CHECK_EQ(strncmp(err.message, "spacing 1e-12", 13), 0);
}

/* The library refuses such a spacing where volumes come in and where brick files are made. */
static void test_refused_by_the_library(void)
{
    const char *dir = scratch_dir;
    char raw[4096], ibv[4096];
    ip_error err;
    ip_gen_params params = {sizeof(ip_gen_params), IP_FIELD_SPHERE, {6, 5, 4}, IP_UINT8, 0.0, 1};
    snprintf(raw, sizeof raw, "%s/sphere_6x5x4_uint8.raw", dir);
    snprintf(ibv, sizeof ibv, "%s/tiny.ibv", dir);
    REQUIRE(ip_generate_write(&params, raw, 0, &err) == IP_OK);
    ip_input_overrides o;
    memset(&o, 0, sizeof o);
    o.has_spacing = 1;
    o.spacing[0] = o.spacing[1] = o.spacing[2] = 1e-12;
    ip_input_desc desc;
    CHECK_EQ(ip_input_describe(raw, &o, &desc, &err), IP_ERR_UNSUPPORTED);
    CHECK_CONTAINS(err.message, "sphere_6x5x4_uint8.raw: spacing 1e-12 along x");
    o.spacing[0] = o.spacing[1] = 1;
    o.spacing[2] = 5000;
    CHECK_EQ(ip_input_describe(raw, &o, &desc, &err), IP_ERR_UNSUPPORTED);
    o.spacing[2] = 1000;
    CHECK_EQ(ip_input_describe(raw, &o, &desc, &err), IP_OK);
    /* a description made by hand goes through the same check */
    REQUIRE(ip_input_describe(raw, NULL, &desc, &err) == IP_OK);
    desc.spacing[1] = 1e-12;
    ip_bricker_options options;
    ip_bricker_options_default(&options);
    options.threads = 1;
    CHECK_EQ(ip_bricker_run(&desc, ibv, &options, NULL, &err), IP_ERR_UNSUPPORTED);
    CHECK_CONTAINS(err.message, "along y");
    struct stat st;
    CHECK_NE(stat(ibv, &st), 0);
    desc.spacing[1] = IP_SPACING_MIN;
    desc.spacing[0] = desc.spacing[2] = IP_SPACING_MIN;
    CHECK_EQ(ip_bricker_run(&desc, ibv, &options, NULL, &err), IP_OK);
}

/* The depth range encloses the box at every accepted scale: the near plane stays in front of
 * the nearest corner and the ratio far / near does not depend on the scale. `cells`: the
 * box's size in samples - 1 (1: the smallest volume, 2 samples a side). */
static void check_depth_range_scales(const double cells[3])
{
    const double scales[] = {IP_SPACING_MIN, 1e-6, 1.0, 1e3, IP_SPACING_MAX};
    double reference = 0;
    for (size_t i = 0; i < sizeof scales / sizeof scales[0]; i++) {
        double k = scales[i];
        double lo[3] = {0, 0, 0}, hi[3] = {cells[0] * k, cells[1] * k, cells[2] * k};
        ip_camera c;
        ip_error err;
        REQUIRE(ip_camera_fit_axis(lo, hi, "-y", 30.0, 160, 120, &c, &err) == IP_OK);
        double near_plane, far_plane;
        ip_camera_depth_range(&c, lo, hi, &near_plane, &far_plane);
        double nearest = c.target[1] - c.eye[1] - 0.5 * (hi[1] - lo[1]);
        double farthest = nearest + (hi[1] - lo[1]);
        CHECK_MSG(near_plane > 0 && near_plane <= nearest, "scale %g: near %g, box from %g", k,
                  near_plane, nearest);
        CHECK_MSG(far_plane >= farthest, "scale %g: far %g, box to %g", k, far_plane, farthest);
        double ratio = far_plane / near_plane;
        if (i == 0)
            reference = ratio;
        CHECK_MSG(fabs(ratio - reference) <= 1e-9 * reference,
                  "scale %g: far / near %.12g, "
                  "at the smallest scale %.12g",
                  k, ratio, reference);
    }
}

static void test_depth_range_scales(void)
{
    const double smallest[3] = {1, 1, 1}, box[3] = {47, 39, 35};
    check_depth_range_scales(smallest);
    check_depth_range_scales(box);
}

static const test_case cases[] = {
    TEST_CASE(test_bounds),
    TEST_CASE(test_refused_by_the_library),
    TEST_CASE(test_depth_range_scales),
};

static void make_scratch_dir(void)
{
    scratch_dir = test_tmp_dir("test_spacing");
}

int main(int argc, char **argv)
{
    return RUN_CASES_WITH(argc, argv, cases, "test_spacing", make_scratch_dir, NULL);
}

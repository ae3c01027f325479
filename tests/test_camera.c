/* SPDX-License-Identifier: BSD-3-Clause */
/* Camera motions: orbit, pan, dolly and the sizes they use; views and cameras in physical space
 * (isoprop/camera.h). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "isoprop/camera.h"

#define NEAR(a, b, tolerance) (fabs((a) - (b)) <= (tolerance))

/* An oblique camera: eye, target and up in general position, up not orthogonal to the view. */
static ip_camera oblique(void)
{
    ip_camera c = {{3.0, -7.0, 2.5}, {0.5, 1.0, -0.25}, {0.1, 0.2, 1.0}, 35.0, 640, 480};
    return c;
}

static double dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static double length(const double a[3])
{
    return sqrt(dot(a, a));
}

/* The unit direction from the eye to the target. */
static void direction(const ip_camera *c, double d[3])
{
    double n = ip_camera_distance(c);
    for (int i = 0; i < 3; i++)
        d[i] = (c->target[i] - c->eye[i]) / n;
}

static int same_point(const double a[3], const double b[3], double tolerance)
{
    return NEAR(a[0], b[0], tolerance) && NEAR(a[1], b[1], tolerance) &&
           NEAR(a[2], b[2], tolerance);
}

/* up is a unit vector orthogonal to the view: the camera stays valid whatever the path. */
static void check_up_orthonormal(const ip_camera *c, const char *what)
{
    double d[3];
    direction(c, d);
    CHECK_MSG(NEAR(length(c->up), 1.0, 1e-12), "%s: |up| = %.17g", what, length(c->up));
    CHECK_MSG(NEAR(dot(c->up, d), 0.0, 1e-12), "%s: up . view = %g", what, dot(c->up, d));
    ip_error err;
    CHECK_MSG(ip_camera_check(c, &err) == IP_OK, "%s: %s", what, err.message);
}

static void test_distance_and_pixel_size(void)
{
    ip_camera c = {{0, 0, 10}, {0, 0, 0}, {0, 1, 0}, 90.0, 100, 50};
    CHECK_NEAR(ip_camera_distance(&c), 10.0, 1e-12);
    /* a 90 degree field of view spans 2 * distance at the target: 20 world units / 50 px */
    CHECK_NEAR(ip_camera_pixel_size(&c, 50), 0.4, 1e-12);
    CHECK_NEAR(ip_camera_pixel_size(&c, 100), 0.2, 1e-12);
}

static void test_orbit(void)
{
    const ip_camera start = oblique();
    double distance = ip_camera_distance(&start);

    /* a whole turn either way returns to the start */
    ip_camera c = start;
    ip_camera_orbit(&c, 360.0, 0.0);
    CHECK_MSG(same_point(c.eye, start.eye, 1e-9), "360 right: eye %g %g %g", c.eye[0], c.eye[1],
              c.eye[2]);
    c = start;
    ip_camera_orbit(&c, 0.0, 360.0);
    CHECK_MSG(same_point(c.eye, start.eye, 1e-9), "360 down: eye %g %g %g", c.eye[0], c.eye[1],
              c.eye[2]);
    c = start;
    for (int k = 0; k < 36; k++)
        ip_camera_orbit(&c, 10.0, 0.0);
    CHECK(same_point(c.eye, start.eye, 1e-9));

    /* nothing moves the target, every orbit keeps the distance and up orthonormal */
    c = start;
    for (int k = 0; k < 200; k++) {
        ip_camera_orbit(&c, 7.3 * (k % 5) - 11.0, 13.1 - 3.7 * (k % 7));
        CHECK(same_point(c.target, start.target, 0.0));
        CHECK_MSG(NEAR(ip_camera_distance(&c), distance, 1e-9 * distance), "step %d: %.17g", k,
                  ip_camera_distance(&c));
    }
    check_up_orthonormal(&c, "after 200 orbits");

    /* over the pole and on: up turns along, the camera never degenerates */
    c = start;
    for (int k = 0; k < 10; k++)
        ip_camera_orbit(&c, 0.0, 45.0);
    check_up_orthonormal(&c, "over the pole");

    /* the direction: turning right by 90 degrees moves the eye to the camera's left, so that
     * the old right axis points at the target */
    ip_camera flat = {{0, -10, 0}, {0, 0, 0}, {0, 0, 1}, 30.0, 64, 48}; /* right is +x */
    ip_camera_orbit(&flat, 90.0, 0.0);
    const double left[3] = {-10, 0, 0};
    CHECK_MSG(same_point(flat.eye, left, 1e-9), "eye %g %g %g", flat.eye[0], flat.eye[1],
              flat.eye[2]);
    /* down by 90 degrees from the side: the eye goes over the top */
    ip_camera side = {{0, -10, 0}, {0, 0, 0}, {0, 0, 1}, 30.0, 64, 48};
    ip_camera_orbit(&side, 0.0, 90.0);
    const double top[3] = {0, 0, 10};
    CHECK_MSG(same_point(side.eye, top, 1e-9), "eye %g %g %g", side.eye[0], side.eye[1],
              side.eye[2]);
}

static void test_pan(void)
{
    const ip_camera start = oblique();
    ip_camera c = start;
    ip_camera_basis b;
    ip_camera_basis_of(&start, &b);
    ip_camera_pan(&c, 1.5, -0.75);
    double eye_move[3], target_move[3], d0[3], d1[3];
    for (int i = 0; i < 3; i++) {
        eye_move[i] = c.eye[i] - start.eye[i];
        target_move[i] = c.target[i] - start.target[i];
    }
    CHECK(same_point(eye_move, target_move, 1e-12));
    /* by the asked world units along right and up */
    CHECK_NEAR(dot(eye_move, b.right), 1.5, 1e-12);
    CHECK_NEAR(dot(eye_move, b.up), -0.75, 1e-12);
    CHECK_NEAR(dot(eye_move, b.forward), 0.0, 1e-12);
    /* the view direction, the distance and up stay */
    direction(&start, d0);
    direction(&c, d1);
    CHECK(same_point(d0, d1, 1e-12));
    CHECK_NEAR(ip_camera_distance(&c), ip_camera_distance(&start), 1e-12);
    CHECK(same_point(c.up, start.up, 0.0));
    /* and back */
    ip_camera_pan(&c, -1.5, 0.75);
    CHECK(same_point(c.eye, start.eye, 1e-12));
    CHECK(same_point(c.target, start.target, 1e-12));
}

static void test_dolly(void)
{
    const ip_camera start = oblique();
    double distance = ip_camera_distance(&start), d0[3], d1[3];
    direction(&start, d0);

    ip_camera c = start;
    ip_camera_dolly(&c, 2.0, 0.0, INFINITY);
    CHECK_MSG(NEAR(ip_camera_distance(&c), distance / 2.0, 1e-12), "%.17g", ip_camera_distance(&c));
    direction(&c, d1);
    CHECK(same_point(d0, d1, 1e-12));
    CHECK(same_point(c.target, start.target, 0.0));
    CHECK(same_point(c.up, start.up, 0.0));

    ip_camera_dolly(&c, 0.25, 0.0, INFINITY); /* away: twice the start */
    CHECK_NEAR(ip_camera_distance(&c), 2.0 * distance, 1e-12);
    direction(&c, d1);
    CHECK(same_point(d0, d1, 1e-12));

    /* the limits */
    c = start;
    ip_camera_dolly(&c, 1e9, 0.5, 100.0);
    CHECK_NEAR(ip_camera_distance(&c), 0.5, 1e-12);
    ip_camera_dolly(&c, 1e-9, 0.5, 100.0);
    CHECK_NEAR(ip_camera_distance(&c), 100.0, 1e-9);
    direction(&c, d1);
    CHECK(same_point(d0, d1, 1e-12));
    ip_error err;
    CHECK_EQ(ip_camera_check(&c, &err), IP_OK);
}

/* ---- views in physical space ---- */

static const double box_lo[3] = {0, 0, 0}, box_hi[3] = {30, 22.5, 40};

/* An orientation of the unit axes in `space`, its origin elsewhere (which no fitted view
 * depends on). */
static ip_orientation axes_in(ip_space space)
{
    ip_orientation o;
    ip_orientation_identity(&o);
    o.origin[0] = -12.5, o.origin[1] = 30, o.origin[2] = 7;
    o.space = space;
    return o;
}

/* With the unit axes, a view fitted in physical space is the world's, to the bit: the axis
 * names as ip_camera_fit_axis() has them, the anatomical ones as the axis they name. */
static void test_views_on_the_unit_axes(void)
{
    static const char *const axes[6] = {"+x", "-x", "+y", "-y", "+z", "-z"};
    /* RAS: right +x, anterior +y, superior +z; LPS: left +x, posterior +y; LAS: left +x */
    static const struct {
        ip_space space;
        const char *view, *axis;
    } named[] = {{IP_SPACE_RAS, "anterior", "+y"}, {IP_SPACE_RAS, "posterior", "-y"},
                 {IP_SPACE_RAS, "right", "+x"},    {IP_SPACE_RAS, "left", "-x"},
                 {IP_SPACE_LPS, "anterior", "-y"}, {IP_SPACE_LPS, "left", "+x"},
                 {IP_SPACE_LAS, "left", "+x"},     {IP_SPACE_LAS, "posterior", "-y"},
                 {IP_SPACE_LPS, "superior", NULL}, {IP_SPACE_LPS, "inferior", NULL}};
    ip_error err;
    ip_camera a, b;
    ip_orientation o = axes_in(IP_SPACE_UNKNOWN);
    for (int i = 0; i < 6; i++) {
        REQUIRE(ip_camera_fit_axis(box_lo, box_hi, axes[i], 30, 160, 120, &a, &err) == IP_OK);
        REQUIRE(ip_camera_fit_view(&o, box_lo, box_hi, axes[i], 30, 160, 120, &b, &err) == IP_OK);
        CHECK_MSG(memcmp(&a, &b, sizeof a) == 0, "%s", axes[i]);
    }
    CHECK_STR_EQ(ip_view_default(&o), "-y");
    REQUIRE(ip_camera_fit_view(&o, box_lo, box_hi, NULL, 30, 160, 120, &b, &err) == IP_OK);
    REQUIRE(ip_camera_fit_axis(box_lo, box_hi, "-y", 30, 160, 120, &a, &err) == IP_OK);
    CHECK(memcmp(&a, &b, sizeof a) == 0);
    for (size_t i = 0; i < sizeof named / sizeof named[0]; i++) {
        o = axes_in(named[i].space);
        REQUIRE(ip_camera_fit_view(&o, box_lo, box_hi, named[i].view, 30, 160, 120, &b, &err) ==
                IP_OK);
        if (named[i].axis) {
            REQUIRE(ip_camera_fit_axis(box_lo, box_hi, named[i].axis, 30, 160, 120, &a, &err) ==
                    IP_OK);
            CHECK_MSG(memcmp(&a, &b, sizeof a) == 0, "%s in %s", named[i].view,
                      ip_space_name(named[i].space));
        } else { /* superior and inferior: up is anterior, -y in LPS; the eye above or below */
            CHECK_MSG(b.up[0] == 0 && b.up[1] == -1 && b.up[2] == 0, "%s", named[i].view);
            CHECK_MSG((b.eye[2] > b.target[2]) == !strcmp(named[i].view, "superior"), "%s",
                      named[i].view);
        }
    }
    o = axes_in(IP_SPACE_RAS);
    CHECK_STR_EQ(ip_view_default(&o), "anterior");
}

static void test_view_names(void)
{
    static const char *const good[] = {"anterior", "posterior", "left", "right",
                                       "superior", "inferior",  "+x",   "-x",
                                       "+y",       "-y",        "+z",   "-z"};
    static const char *const bad[] = {"front", "x", "+w", "Anterior", "", "-xy"};
    ip_error err;
    for (size_t i = 0; i < sizeof good / sizeof good[0]; i++)
        CHECK_MSG(ip_view_check(good[i], &err) == IP_OK, "%s", good[i]);
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        CHECK_MSG(ip_view_check(bad[i], &err) == IP_ERR_ARGUMENT, "%s", bad[i]);
        CHECK(strstr(err.message, "is not one of") != NULL);
    }
    CHECK_EQ(ip_view_check(NULL, &err), IP_ERR_ARGUMENT);
    /* an anatomical name needs a space; the axes do not */
    ip_orientation o = axes_in(IP_SPACE_UNKNOWN);
    ip_camera c;
    CHECK_EQ(ip_camera_fit_view(&o, box_lo, box_hi, "anterior", 30, 16, 12, &c, &err),
             IP_ERR_ARGUMENT);
    CHECK(strstr(err.message, "view 'anterior' needs a file with an anatomical space") != NULL);
    CHECK_EQ(ip_camera_fit_view(&o, box_lo, box_hi, "front", 30, 16, 12, &c, &err),
             IP_ERR_ARGUMENT);
    CHECK_EQ(ip_camera_fit_view(&o, box_lo, box_hi, "+z", 30, 16, 12, &c, &err), IP_OK);
    double v[3];
    CHECK_EQ(ip_space_direction(IP_SPACE_UNKNOWN, "left", v), 0);
    CHECK_EQ(ip_space_direction(IP_SPACE_RAS, "up", v), 0);
    REQUIRE(ip_space_direction(IP_SPACE_LPS, "anterior", v) == 1);
    CHECK(v[0] == 0 && v[1] == -1 && v[2] == 0);
    REQUIRE(ip_space_direction(IP_SPACE_LAS, "right", v) == 1);
    CHECK(v[0] == -1 && v[1] == 0 && v[2] == 0);
    REQUIRE(ip_space_direction(IP_SPACE_RAS, "inferior", v) == 1);
    CHECK(v[0] == 0 && v[1] == 0 && v[2] == -1);
}

/* A turned and mirrored orientation: sample x along physical -z, y along +x, z along +y
 * (det -1), its origin off zero. */
static ip_orientation turned_mirror(void)
{
    ip_orientation o;
    ip_orientation_identity(&o);
    memset(o.directions, 0, sizeof o.directions);
    o.directions[0][2] = -1;
    o.directions[1][0] = 1;
    o.directions[2][1] = 1;
    o.origin[0] = 4, o.origin[1] = -9, o.origin[2] = 120;
    o.space = IP_SPACE_RAS;
    return o;
}

/* The world camera sees what the physical one sees; mirrored, column x is column w - 1 - x. */
static void test_physical_to_world(void)
{
    ip_orientation mirrored = turned_mirror(), turned = mirrored;
    turned.directions[2][1] = -1; /* det +1 */
    CHECK_EQ(ip_orientation_mirrors(&mirrored), 1);
    CHECK_EQ(ip_orientation_mirrors(&turned), 0);
    ip_orientation identity;
    ip_orientation_identity(&identity);
    CHECK_EQ(ip_orientation_mirrors(&identity), 0);
    const ip_orientation *cases[2] = {&turned, &mirrored};
    ip_camera physical = oblique();
    for (int k = 0; k < 2; k++) {
        const ip_orientation *o = cases[k];
        ip_camera world, back;
        ip_camera_to_world(o, &physical, &world);
        ip_camera_to_physical(o, &world, &back);
        CHECK(same_point(back.eye, physical.eye, 1e-12));
        CHECK(same_point(back.target, physical.target, 1e-12));
        CHECK(same_point(back.up, physical.up, 1e-12));
        CHECK_EQ(world.width, physical.width);
        CHECK_EQ(world.fov_y, physical.fov_y);
        /* a physical point's pixel, through either camera */
        ip_camera_basis pb, wb;
        ip_camera_basis_of(&physical, &pb);
        ip_camera_basis_of(&world, &wb);
        const double p[3] = {1.5, 3.0, 0.25};
        double w[3], px, py, pd, wx, wy, wd;
        ip_orientation_to_world(o, p, w);
        REQUIRE(ip_camera_project(&pb, &physical, p, &px, &py, &pd));
        REQUIRE(ip_camera_project(&wb, &world, w, &wx, &wy, &wd));
        double want = ip_orientation_mirrors(o) ? physical.width - px : px;
        CHECK_NEAR(wx, want, 1e-9);
        CHECK_NEAR(wy, py, 1e-9);
        CHECK_NEAR(wd, pd, 1e-9);
        /* a plane keeps the same points on both sides */
        const double n[3] = {0.3, -1.2, 0.5};
        double nw[3], dw;
        ip_orientation_plane_to_world(o, n, 2.5, nw, &dw);
        CHECK_NEAR(dot(n, p) + 2.5, dot(nw, w) + dw, 1e-9);
    }
    /* with the identity, the world camera is the physical one, to the bit */
    ip_camera same;
    ip_camera_to_world(&identity, &physical, &same);
    CHECK(memcmp(&same, &physical, sizeof same) == 0);
}

/* A named view fitted in physical space, whatever the orientation: its world camera is the
 * physical fit's (the eye on the anatomical side, up superior) turned into world space. */
static void test_views_turned(void)
{
    ip_orientation o = turned_mirror();
    ip_error err;
    ip_camera world, physical;
    REQUIRE(ip_camera_fit_view(&o, box_lo, box_hi, "anterior", 30, 160, 120, &world, &err) ==
            IP_OK);
    ip_camera_to_physical(&o, &world, &physical);
    double centre_w[3], centre_p[3], v[3];
    for (int a = 0; a < 3; a++)
        centre_w[a] = 0.5 * (box_lo[a] + box_hi[a]);
    ip_orientation_apply(&o, centre_w, centre_p);
    CHECK(same_point(physical.target, centre_p, 1e-9));
    for (int a = 0; a < 3; a++)
        v[a] = physical.eye[a] - physical.target[a];
    CHECK(fabs(v[0]) < 1e-9 && v[1] > 0 && fabs(v[2]) < 1e-9); /* anterior: RAS +y */
    CHECK(same_point(physical.up, (double[3]){0, 0, 1}, 1e-12));
    /* the whole box in frame, tightly: every corner inside, one near an edge */
    ip_camera_basis b;
    ip_camera_basis_of(&world, &b);
    double widest = 0;
    for (int k = 0; k < 8; k++) {
        double p[3] = {k & 1 ? box_hi[0] : box_lo[0], k & 2 ? box_hi[1] : box_lo[1],
                       k & 4 ? box_hi[2] : box_lo[2]};
        double x, y, depth;
        REQUIRE(ip_camera_project(&b, &world, p, &x, &y, &depth));
        CHECK(x > 0 && x < world.width && y > 0 && y < world.height);
        widest = fmax(widest, fmax(fabs(2 * x / world.width - 1), fabs(2 * y / world.height - 1)));
    }
    CHECK_MSG(widest > 0.9, "the box spans %g of the half frame", widest);
}

static const test_case cases[] = {
    TEST_CASE(test_distance_and_pixel_size),
    TEST_CASE(test_orbit),
    TEST_CASE(test_pan),
    TEST_CASE(test_dolly),
    TEST_CASE(test_views_on_the_unit_axes),
    TEST_CASE(test_view_names),
    TEST_CASE(test_physical_to_world),
    TEST_CASE(test_views_turned),
};

int main(int argc, char **argv)
{
    return RUN_CASES(argc, argv, cases, "test_camera");
}

/* SPDX-License-Identifier: BSD-3-Clause */
/* Camera motions: orbit, pan, dolly and the sizes they use (isoprop/camera.h). */
#include <math.h>
#include <stdio.h>

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

static const test_case cases[] = {
    TEST_CASE(test_distance_and_pixel_size),
    TEST_CASE(test_orbit),
    TEST_CASE(test_pan),
    TEST_CASE(test_dolly),
};

int main(int argc, char **argv)
{
    return RUN_CASES(argc, argv, cases, "test_camera");
}

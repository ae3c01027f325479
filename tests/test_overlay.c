/* SPDX-License-Identifier: BSD-3-Clause */
/* Tests of the figure overlays (src/render/overlay.c): the scale bar's length against the
 * camera's projection, the axis triad's directions as the camera turns, and that each draws
 * only inside the corner box it reports. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "isoprop/render.h"

/* An eye 100 world units from the target on -y, looking along +y, up +z: right is +x. */
static ip_camera front_camera(uint32_t width, uint32_t height)
{
    ip_camera c = {.eye = {0, -100, 0},
                   .target = {0, 0, 0},
                   .up = {0, 0, 1},
                   .fov_y = 30,
                   .width = width,
                   .height = height};
    return c;
}

static void test_scale_bar_choice(void)
{
    ip_camera c = front_camera(400, 300);
    ip_scale_bar bar;
    ip_error err;
    double pixel = 2 * 100 * tan(15 * M_PI / 180) / 300; /* 0.1786 world units */
    CHECK_EQ(ip_scale_bar_choose(&c, 100, &bar, &err), IP_OK);
    CHECK_NEAR(bar.pixel_size, pixel, 1e-12);
    CHECK_EQ(bar.length, 10); /* 100 pixels span 17.9 units: 10 is the round length under it */
    CHECK_NEAR(bar.pixels, 10 / pixel, 1e-9);
    /* the bar's length is what the projection makes of that length at the target's depth */
    ip_camera_basis basis;
    ip_camera_basis_of(&c, &basis);
    double end[3] = {bar.length, 0, 0}, px, py, depth, cx, cy;
    double centre[3] = {0, 0, 0};
    CHECK_EQ(ip_camera_project(&basis, &c, end, &px, &py, &depth), 1);
    CHECK_EQ(ip_camera_project(&basis, &c, centre, &cx, &cy, &depth), 1);
    CHECK_MSG(fabs((px - cx) - bar.pixels) < 1e-6, "%g vs %g", px - cx, bar.pixels);
    /* 1, 2 or 5 times a power of ten, the largest that fits */
    const double limits[][2] = {{0.3 / pixel, 0.2},
                                {5.0 / pixel, 5},
                                {99 / pixel, 50},
                                {19.99 / pixel, 10},
                                {2.5e-3 / pixel, 2e-3}};
    for (size_t i = 0; i < sizeof limits / sizeof limits[0]; i++) {
        CHECK_EQ(ip_scale_bar_choose(&c, limits[i][0], &bar, &err), IP_OK);
        CHECK_MSG(fabs(bar.length - limits[i][1]) < 1e-12 * limits[i][1], "%g pixels: %g",
                  limits[i][0], bar.length);
        CHECK_LE(bar.pixels, limits[i][0] * (1 + 1e-9));
    }
    /* a zoom (narrower field of view) makes each unit longer */
    ip_camera narrow = c;
    narrow.fov_y = 2 * atan(tan(15 * M_PI / 180) / 2) * 180 / M_PI;
    CHECK_EQ(ip_scale_bar_choose(&narrow, 100, &bar, &err), IP_OK);
    CHECK_NEAR(bar.pixel_size, pixel / 2, 1e-12);
    CHECK_EQ(ip_scale_bar_choose(&c, 0, &bar, &err), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_scale_bar_choose(&c, NAN, &bar, &err), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_scale_bar_choose(&c, 100, NULL, &err), IP_ERR_ARGUMENT);
    c.fov_y = 0;
    CHECK_EQ(ip_scale_bar_choose(&c, 100, &bar, &err), IP_ERR_ARGUMENT);
}

static int near(const double a[3], double x, double y, double z)
{
    return fabs(a[0] - x) < 1e-9 && fabs(a[1] - y) < 1e-9 && fabs(a[2] - z) < 1e-9;
}

static void test_axis_directions(void)
{
    ip_camera c = front_camera(400, 300);
    ip_orientation o;
    ip_orientation_identity(&o);
    double s[3][3];
    ip_overlay_axis_directions(&c, &o, s);
    CHECK(near(s[0], 1, 0, 0));  /* x to the right */
    CHECK(near(s[1], 0, 0, -1)); /* y away from the eye */
    CHECK(near(s[2], 0, -1, 0)); /* z up: toward the image's top, y decreasing */
    /* the eye turned half round: x points left, y toward the eye, z still up */
    ip_camera turned = c;
    ip_camera_orbit(&turned, 180, 0);
    ip_overlay_axis_directions(&turned, &o, s);
    CHECK(near(s[0], -1, 0, 0));
    CHECK(near(s[1], 0, 0, 1));
    CHECK(near(s[2], 0, -1, 0));
    /* a file whose sample x axis runs along physical -x (LPS, say): physical x, the one the
     * triad shows, points left in the world camera's image, and so right in the physical
     * view shown, that image mirrored (D is a reflection) */
    o.directions[0][0] = -1;
    o.origin[0] = 40;
    o.space = IP_SPACE_LPS;
    ip_overlay_axis_directions(&c, &o, s);
    CHECK(near(s[0], 1, 0, 0));
    CHECK(near(s[1], 0, 0, -1));
    CHECK(near(s[2], 0, -1, 0));
    /* which is what the physical camera sees of the physical axes */
    ip_camera physical;
    ip_orientation axes;
    double p[3][3];
    ip_camera_to_physical(&o, &c, &physical);
    ip_orientation_identity(&axes);
    ip_overlay_axis_directions(&physical, &axes, p);
    for (int a = 0; a < 3; a++)
        CHECK_MSG(near(s[a], p[a][0], p[a][1], p[a][2]), "axis %d", a);
    /* a file whose sample axes are the physical axes permuted: world x is physical y */
    ip_orientation_identity(&o);
    memset(o.directions, 0, sizeof o.directions);
    o.directions[0][1] = 1; /* sample x -> physical y */
    o.directions[1][2] = 1; /* sample y -> physical z */
    o.directions[2][0] = 1; /* sample z -> physical x */
    ip_overlay_axis_directions(&c, &o, s);
    CHECK(near(s[0], 0, -1, 0)); /* physical x is world z: up */
    CHECK(near(s[1], 1, 0, 0));  /* physical y is world x: right */
    CHECK(near(s[2], 0, 0, -1)); /* physical z is world y: away */
    CHECK_STR_EQ(ip_overlay_axis_label(IP_SPACE_UNKNOWN, 0), "x");
    CHECK_STR_EQ(ip_overlay_axis_label(IP_SPACE_RAS, 0), "R");
    CHECK_STR_EQ(ip_overlay_axis_label(IP_SPACE_LAS, 0), "L");
    CHECK_STR_EQ(ip_overlay_axis_label(IP_SPACE_LPS, 1), "P");
    CHECK_STR_EQ(ip_overlay_axis_label(IP_SPACE_RAS, 2), "S");
    CHECK_STR_EQ(ip_overlay_axis_label(IP_SPACE_RAS, 3), "");
}

/* The pixels of `a` and `b` that differ: how many, and how many of them lie outside `box`. */
static void count_changes(const uint8_t *a, const uint8_t *b, uint32_t w, uint32_t h,
                          const uint32_t box[4], size_t *changed, size_t *outside)
{
    *changed = *outside = 0;
    for (uint32_t y = 0; y < h; y++)
        for (uint32_t x = 0; x < w; x++) {
            size_t p = ((size_t)y * w + x) * 4;
            if (!memcmp(a + p, b + p, 4))
                continue;
            (*changed)++;
            if (x < box[0] || x >= box[2] || y < box[1] || y >= box[3])
                (*outside)++;
        }
}

static void test_drawing(uint32_t w, uint32_t h)
{
    ip_camera c = front_camera(w, h);
    ip_camera_orbit(&c, 30, -20);
    size_t bytes = (size_t)w * h * 4;
    uint8_t *plain = malloc(bytes), *image = malloc(bytes);
    REQUIRE(plain && image);
    for (size_t i = 0; i < bytes; i++)
        plain[i] = (i % 4 == 3) ? 255 : (uint8_t)(40 + i % 7);
    ip_orientation o;
    ip_orientation_identity(&o);
    ip_error err;
    uint32_t box[4], bar_box[4];
    size_t changed, outside;

    memcpy(image, plain, bytes);
    CHECK_EQ(ip_overlay_draw_axes(image, &c, &o, box, &err), IP_OK);
    count_changes(plain, image, w, h, box, &changed, &outside);
    CHECK_MSG(changed > 20 && outside == 0, "%ux%u axes: %zu changed, %zu outside", w, h, changed,
              outside);
    CHECK_LT(box[0], box[2]);
    CHECK_LE(box[2], w);
    CHECK_LE(box[3], h);
    if (w >= 200) { /* in its corner */
        CHECK_LE(box[2], w / 2);
        CHECK_GE(box[1], h / 2);
    }

    ip_scale_bar bar;
    CHECK_EQ(ip_scale_bar_choose(&c, w / 4.0, &bar, &err), IP_OK);
    memcpy(image, plain, bytes);
    CHECK_EQ(ip_overlay_draw_scale_bar(image, &c, &bar, "mm", box, bar_box, &err), IP_OK);
    count_changes(plain, image, w, h, box, &changed, &outside);
    CHECK_MSG(changed > 20 && outside == 0, "%ux%u bar: %zu changed, %zu outside", w, h, changed,
              outside);
    CHECK_LE(box[2], w);
    CHECK_LE(box[3], h);
    if (w >= 200) {
        CHECK_GE(box[0], w / 2);
        CHECK_GE(box[1], h / 2);
    }
    /* the bar is round(pixels) long, within a pixel of the projection's length */
    CHECK_MSG(bar_box[2] - bar_box[0] == (uint32_t)lround(bar.pixels), "%u vs %g",
              bar_box[2] - bar_box[0], bar.pixels);
    /* its bottom row is the bar's colour over its whole length, and only there */
    uint32_t row = bar_box[3] - 1, lit = 0;
    for (uint32_t x = 0; x < w; x++) {
        const uint8_t *p = image + ((size_t)row * w + x) * 4;
        if (p[0] > 200 && p[1] > 200 && p[2] > 200)
            lit++;
    }
    CHECK_MSG(lit == bar_box[2] - bar_box[0], "%u lit", lit);

    /* on a white background the bar is dark */
    memset(image, 255, bytes);
    CHECK_EQ(ip_overlay_draw_scale_bar(image, &c, &bar, "mm", box, bar_box, &err), IP_OK);
    const uint8_t *p = image + ((size_t)(bar_box[3] - 1) * w + bar_box[0]) * 4;
    CHECK_MSG(p[0] < 60 && p[1] < 60 && p[2] < 60, "%u %u %u on white", p[0], p[1], p[2]);

    CHECK_EQ(ip_overlay_draw_axes(NULL, &c, &o, box, &err), IP_ERR_ARGUMENT);
    bar.pixels = -1;
    CHECK_EQ(ip_overlay_draw_scale_bar(image, &c, &bar, NULL, NULL, NULL, &err), IP_ERR_ARGUMENT);
    free(plain);
    free(image);
}

/* An overlay that would not fit whole in the image is refused and draws nothing. */
static void test_small_images(void)
{
    ip_orientation o;
    ip_orientation_identity(&o);
    ip_error err;
    uint32_t box[4], bar_box[4];
    uint8_t image[64 * 64 * 4], plain[64 * 64 * 4];
    for (size_t i = 0; i < sizeof plain; i++)
        plain[i] = (i % 4 == 3) ? 255 : (uint8_t)(40 + i % 7);
    /* the triad's arms (16 pixels) and labels need 63x62 pixels */
    const uint32_t sizes[][3] = {{16, 16, 0}, {40, 30, 0}, {62, 62, 0},
                                 {63, 61, 0}, {63, 62, 1}, {64, 64, 1}};
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++) {
        ip_camera c = front_camera(sizes[i][0], sizes[i][1]);
        int fits = (int)sizes[i][2];
        CHECK_MSG((ip_overlay_axes_check(c.width, c.height, &err) == IP_OK) == fits, "%ux%u",
                  c.width, c.height);
        memcpy(image, plain, sizeof image);
        ip_status st = ip_overlay_draw_axes(image, &c, &o, box, &err);
        CHECK_MSG((st == IP_OK) == fits, "%ux%u: %s", c.width, c.height, err.message);
        if (!fits) {
            CHECK_CONTAINS(err.message, "at least 63x62");
            CHECK_MEM_EQ(image, plain, sizeof image);
        } else {
            CHECK_LE(box[2], c.width);
            CHECK_LE(box[3], c.height);
        }
    }
    /* a 16x16 image has no room for "10 units" */
    ip_camera c = front_camera(16, 16);
    ip_scale_bar bar;
    CHECK_EQ(ip_scale_bar_choose(&c, 4, &bar, &err), IP_OK);
    memcpy(image, plain, sizeof image);
    CHECK_EQ(ip_overlay_draw_scale_bar(image, &c, &bar, "units", box, bar_box, &err),
             IP_ERR_ARGUMENT);
    CHECK_CONTAINS(err.message, "units");
    CHECK_MEM_EQ(image, plain, sizeof image);
    /* a bar longer than the image (a caller's own): refused, not drawn off the image */
    c = front_camera(64, 64);
    bar.pixels = 5e8;
    CHECK_EQ(ip_overlay_draw_scale_bar(image, &c, &bar, NULL, box, bar_box, &err), IP_ERR_ARGUMENT);
    CHECK_MEM_EQ(image, plain, sizeof image);
}

/* The whole label is drawn however long, and a byte the font has no glyph for is a '?'. */
static void test_labels(void)
{
    const uint32_t w = 1600, h = 300;
    ip_camera c = front_camera(w, h);
    size_t bytes = (size_t)w * h * 4;
    uint8_t *a = calloc(bytes, 1), *b = calloc(bytes, 1);
    REQUIRE(a && b);
    ip_scale_bar bar;
    ip_error err;
    uint32_t box[4], short_box[4], bar_box[4];
    CHECK_EQ(ip_scale_bar_choose(&c, w / 4.0, &bar, &err), IP_OK);
    const char *unit = "ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789";
    CHECK_EQ(ip_overlay_draw_scale_bar(a, &c, &bar, unit, box, bar_box, &err), IP_OK);
    CHECK_EQ(
        ip_overlay_draw_scale_bar(b, &c, &bar, "ABCDEFGHIJKLMNOPQRSTUVWXYZ", short_box, NULL, &err),
        IP_OK);
    /* the long label's ink (above the bar) spans its 76 characters, about 6 pixels each */
    uint32_t first = w, last = 0;
    for (uint32_t y = box[1]; y < bar_box[1]; y++)
        for (uint32_t x = box[0]; x < box[2]; x++)
            if (a[((size_t)y * w + x) * 4]) {
                first = x < first ? x : first;
                last = x > last ? x : last;
            }
    CHECK_MSG(last > first && last - first > 400, "ink from %u to %u", first, last);
    CHECK_LT(box[0], short_box[0]);
    /* "\xc2\xb5m" (UTF-8 micro sign) and "\tm" draw as "??m" and "?m" */
    memset(a, 0, bytes);
    memset(b, 0, bytes);
    CHECK_EQ(ip_overlay_draw_scale_bar(a, &c, &bar, "\xc2\xb5m", NULL, NULL, &err), IP_OK);
    CHECK_EQ(ip_overlay_draw_scale_bar(b, &c, &bar, "??m", NULL, NULL, &err), IP_OK);
    CHECK_MEM_EQ(a, b, bytes);
    memset(a, 0, bytes);
    memset(b, 0, bytes);
    CHECK_EQ(ip_overlay_draw_scale_bar(a, &c, &bar, "\tm\x7f", NULL, NULL, &err), IP_OK);
    CHECK_EQ(ip_overlay_draw_scale_bar(b, &c, &bar, "?m?", NULL, NULL, &err), IP_OK);
    CHECK_MEM_EQ(a, b, bytes);
    free(a);
    free(b);
}

/* The shared text: its width adds up character by character, it draws inside its box, with
 * a shadow one text pixel down and right, and clips at the image's edges. */
static void test_text(void)
{
    CHECK_EQ(ip_overlay_text_width("AB", 1),
             ip_overlay_text_width("A", 1) + ip_overlay_text_width("B", 1));
    CHECK_EQ(ip_overlay_text_width("10 mm", 3), 3 * ip_overlay_text_width("10 mm", 1));
    CHECK_EQ(ip_overlay_text_width("\xc3\xa9\n", 1), ip_overlay_text_width("???", 1));
    CHECK_EQ(ip_overlay_text_width(NULL, 1), 0);
    CHECK_EQ(ip_overlay_text_width("A", 0), 0);
    CHECK_EQ(ip_overlay_text_width("A", 17), 0);
    enum {
        W = 64,
        H = 32
    };
    static uint8_t image[W * H * 4];
    const uint8_t ink[3] = {250, 250, 250}, shade[3] = {20, 30, 40};
    ip_error err;
    memset(image, 0, sizeof image);
    CHECK_EQ(ip_overlay_draw_text(image, W, H, 3, 4, "A7", 2, ink, NULL, &err), IP_OK);
    uint32_t w = ip_overlay_text_width("A7", 2), inked = 0, outside = 0;
    for (uint32_t y = 0; y < H; y++)
        for (uint32_t x = 0; x < W; x++) {
            const uint8_t *p = image + ((size_t)y * W + x) * 4;
            if (!p[0])
                continue;
            inked++;
            outside += x < 3 || x >= 3 + w || y < 4 || y >= 4 + 2 * 7 + 2;
            CHECK_EQ(p[0], 250);
            CHECK_EQ(p[3], 255);
        }
    CHECK_MSG(inked > 20 && outside == 0, "%u inked, %u outside", inked, outside);
    /* the shadow: the same glyphs one text pixel (2) down and right, under the ink */
    memset(image, 0, sizeof image);
    CHECK_EQ(ip_overlay_draw_text(image, W, H, 3, 4, "A7", 2, ink, shade, &err), IP_OK);
    uint32_t shadowed = 0;
    for (size_t p = 0; p < (size_t)W * H; p++)
        shadowed += image[4 * p] == 20 && image[4 * p + 2] == 40;
    CHECK_MSG(shadowed > 0, "%u shadow pixels", shadowed);
    /* partly outside: clipped, not written out of bounds (the sanitizer build checks) */
    CHECK_EQ(ip_overlay_draw_text(image, W, H, -5, H - 6, "WIDE TEXT", 3, ink, shade, &err), IP_OK);
    CHECK_EQ(ip_overlay_draw_text(NULL, W, H, 0, 0, "A", 1, ink, NULL, &err), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_overlay_draw_text(image, W, H, 0, 0, NULL, 1, ink, NULL, &err), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_overlay_draw_text(image, W, H, 0, 0, "A", 17, ink, NULL, &err), IP_ERR_ARGUMENT);
    CHECK_EQ(ip_overlay_draw_text(image, W, H, 1 << 25, 0, "A", 1, ink, NULL, &err),
             IP_ERR_ARGUMENT);
    CHECK_EQ(ip_overlay_draw_text(image, 0, H, 0, 0, "A", 1, ink, NULL, &err), IP_ERR_ARGUMENT);
}

static void test_drawing_sizes(void)
{
    test_drawing(400, 300);
    test_drawing(1600, 1200);
    test_drawing(64, 64); /* small: each overlay still whole */
}

static const test_case cases[] = {
    TEST_CASE(test_scale_bar_choice),
    TEST_CASE(test_axis_directions),
    {"test_drawing", test_drawing_sizes},
    TEST_CASE(test_small_images),
    TEST_CASE(test_labels),
    TEST_CASE(test_text),
};

int main(int argc, char **argv)
{
    return RUN_CASES(argc, argv, cases, "test_overlay");
}

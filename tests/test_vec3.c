/* SPDX-License-Identifier: BSD-3-Clause */
/* The vec3 helpers (src/common/vec3.h): values, aliasing, and the same bits as the written-out
 * expressions they replaced. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "check.h"
#include "vec3.h"

static double next_value(uint64_t *state)
{
    *state = *state * 6364136223846793005ull + 1442695040888963407ull;
    return ((double)(*state >> 11) / 9007199254740992.0 - 0.5) * 1e3;
}

static int same_bits(double a, double b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

static void test_values(void)
{
    const double x[3] = {1, 0, 0}, y[3] = {0, 1, 0};
    double z[3], d[3];
    ip__vec3_cross(x, y, z);
    CHECK_EQ(z[0], 0);
    CHECK_EQ(z[1], 0);
    CHECK_EQ(z[2], 1);
    CHECK_EQ(ip__vec3_dot(x, y), 0);
    CHECK_EQ(ip__vec3_dot(z, z), 1);
    const double a[3] = {4, 6, 3}, b[3] = {1, 2, 3};
    ip__vec3_sub(a, b, d);
    CHECK_EQ(d[0], 3);
    CHECK_EQ(d[1], 4);
    CHECK_EQ(d[2], 0);
    CHECK_EQ(ip__vec3_length(d), 5);
    CHECK_EQ(ip__vec3_normalize(d), 5);
    CHECK_EQ(d[0], 0.6);
    CHECK_EQ(d[1], 0.8);
    CHECK_EQ(d[2], 0);
    double zero[3] = {0, 0, 0};
    CHECK_EQ(ip__vec3_normalize(zero), 0);
    CHECK_EQ(zero[0], 0);
    CHECK_EQ(zero[1], 0);
    CHECK_EQ(zero[2], 0);
    /* out may alias an input */
    double u[3] = {1, 0, 0};
    ip__vec3_cross(u, y, u);
    CHECK_EQ(u[0], 0);
    CHECK_EQ(u[1], 0);
    CHECK_EQ(u[2], 1);
    double s[3] = {5, 5, 5};
    ip__vec3_sub(s, b, s);
    CHECK_EQ(s[0], 4);
    CHECK_EQ(s[1], 3);
    CHECK_EQ(s[2], 2);
}

static void test_same_bits(void)
{
    uint64_t state = 7;
    int ok = 1;
    for (int i = 0; i < 10000; i++) {
        double a[3], b[3], c[3], r[3];
        for (int k = 0; k < 3; k++) {
            a[k] = next_value(&state);
            b[k] = next_value(&state);
        }
        ok &= same_bits(ip__vec3_dot(a, b), a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
        ip__vec3_cross(a, b, c);
        ok &= same_bits(c[0], a[1] * b[2] - a[2] * b[1]);
        ok &= same_bits(c[1], a[2] * b[0] - a[0] * b[2]);
        ok &= same_bits(c[2], a[0] * b[1] - a[1] * b[0]);
        ip__vec3_sub(a, b, r);
        ok &= same_bits(r[0], a[0] - b[0]) && same_bits(r[2], a[2] - b[2]);
        ok &= same_bits(ip__vec3_length(a), sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]));
        double n = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        double want[3] = {a[0] / n, a[1] / n, a[2] / n};
        ip__vec3_normalize(a);
        ok &= same_bits(a[0], want[0]) && same_bits(a[1], want[1]) && same_bits(a[2], want[2]);
    }
    CHECK(ok);
}

static const test_case cases[] = {
    TEST_CASE(test_values),
    TEST_CASE(test_same_bits),
};

int main(int argc, char **argv)
{
    return RUN_CASES(argc, argv, cases, "test_vec3");
}

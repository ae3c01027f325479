/* A tiny test harness: CHECK records a failure and goes on; main() returns test_summary(). */
#ifndef ISOPROP_TEST_CHECK_H
#define ISOPROP_TEST_CHECK_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int test_checks_passed;
static int test_checks_failed;

#define CHECK(cond)                                                                  \
    do {                                                                             \
        if (cond) {                                                                  \
            test_checks_passed++;                                                    \
        } else {                                                                     \
            test_checks_failed++;                                                    \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond); \
        }                                                                            \
    } while (0)

#define CHECK_MSG(cond, ...)                                                         \
    do {                                                                             \
        if (cond) {                                                                  \
            test_checks_passed++;                                                    \
        } else {                                                                     \
            test_checks_failed++;                                                    \
            fprintf(stderr, "%s:%d: CHECK failed: %s: ", __FILE__, __LINE__, #cond); \
            fprintf(stderr, __VA_ARGS__);                                            \
            fputc('\n', stderr);                                                     \
        }                                                                            \
    } while (0)

/* Fatal precondition: stops the test program at once. */
#define REQUIRE(cond)                                                                  \
    do {                                                                               \
        if (!(cond)) {                                                                 \
            fprintf(stderr, "%s:%d: REQUIRE failed: %s\n", __FILE__, __LINE__, #cond); \
            exit(1);                                                                   \
        }                                                                              \
    } while (0)

#define CHECK_CONTAINS(text, needle) \
    CHECK_MSG(strstr((text), (needle)) != NULL, "\"%s\" lacks \"%s\"", (text), (needle))

/* The scratch folders test_tmp_dir() made, removed by test_summary() when every check
 * passed and kept, for diagnosis, otherwise (and after a REQUIRE or a crash). */
/* The next value of a xorshift64 generator (*state nonzero, updated): reproducible test data. */
static inline uint64_t test_xorshift(uint64_t *state)
{
    uint64_t x = *state;
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    return *state = x;
}

#define TEST_TMP_DIRS_MAX 16
static char test_tmp_dirs[TEST_TMP_DIRS_MAX][4096];
static int test_tmp_dir_count;

static inline int test_summary(const char *name)
{
    printf("%s: %d passed, %d failed\n", name, test_checks_passed, test_checks_failed);
    for (int i = 0; i < test_tmp_dir_count; i++) {
        char cmd[sizeof test_tmp_dirs[0] + 64];
        if (test_checks_failed == 0) {
            int n = snprintf(cmd, sizeof cmd, "rm -rf '%s'", test_tmp_dirs[i]);
            if (n < 0 || (size_t)n >= sizeof cmd || system(cmd) != 0)
                fprintf(stderr, "%s: cannot remove %s\n", name, test_tmp_dirs[i]);
        } else {
            fprintf(stderr, "%s: scratch files kept in %s\n", name, test_tmp_dirs[i]);
        }
    }
    return test_checks_failed == 0 ? 0 : 1;
}

/* A scratch folder for this test program, created on demand: $IP_TEST_TMP/<name>. */
static inline const char *test_tmp_dir(const char *name)
{
    static char dir[4096];
    const char *base = getenv("IP_TEST_TMP");
    char cmd[2 * sizeof dir + 64];
    snprintf(dir, sizeof dir, "%s/%s", base ? base : "/tmp/isoprop-test", name);
    snprintf(cmd, sizeof cmd, "rm -rf '%s' && mkdir -p '%s'", dir, dir);
    if (system(cmd) != 0) {
        fprintf(stderr, "cannot create %s\n", dir);
        exit(1);
    }
    int known = 0;
    for (int i = 0; i < test_tmp_dir_count; i++)
        known |= strcmp(test_tmp_dirs[i], dir) == 0;
    if (!known && test_tmp_dir_count < TEST_TMP_DIRS_MAX)
        snprintf(test_tmp_dirs[test_tmp_dir_count++], sizeof test_tmp_dirs[0], "%s", dir);
    return dir;
}

#endif

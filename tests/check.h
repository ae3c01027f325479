/* SPDX-License-Identifier: BSD-3-Clause */
/* A tiny test harness: CHECK and its kin record a failure and go on; main() runs the program's
 * cases with RUN_CASES (every case, or those named on its command line), which returns
 * test_summary(). */
#ifndef ISOPROP_TEST_CHECK_H
#define ISOPROP_TEST_CHECK_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int test_checks_passed;
static int test_checks_failed;

static inline int test_check(int ok, const char *file, int line, const char *condition)
{
    if (ok) {
        test_checks_passed++;
        return 1;
    }
    test_checks_failed++;
    fprintf(stderr, "%s:%d: CHECK failed: %s\n", file, line, condition);
    return 0;
}

/* CHECK(cond): an expression, 1 when cond held, else 0 (as CHECK_EQ and its kin below) */
#define CHECK(cond) test_check((cond) ? 1 : 0, __FILE__, __LINE__, #cond)

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

/* Comparisons that print both operands, each with its expression, when they fail:
 *
 *   CHECK_EQ(a, b)  CHECK_NE(a, b)  CHECK_LT(a, b)  CHECK_LE(a, b)  CHECK_GT(a, b)  CHECK_GE(a, b)
 *
 * The operands are numbers (integers of any width and sign, float, double, enums) or, for
 * CHECK_EQ and CHECK_NE, pointers; each is evaluated once. A signed and an unsigned integer
 * compare by their values (-1 is less than 0u, unlike C's <); a float with an integer compares
 * as floats and with a double as doubles, as in C. Each is an expression: 1 when it passed,
 * else 0, so that a check that the next ones depend on can guard them:
 *
 *   if (!CHECK_NE(p, NULL))
 *       return;
 *   CHECK_EQ(p->count, 3);
 *
 *   CHECK_NEAR(a, b, tol)   |a - b| <= tol, as doubles (a NaN never passes)
 *   CHECK_MEM_EQ(a, b, n)   n bytes alike; prints the first differing offset and both bytes
 *   CHECK_STR_EQ(a, b)      strings alike (NULL only equals NULL); prints both */
typedef enum {
    TEST_SIGNED,
    TEST_UNSIGNED,
    TEST_FLOAT,
    TEST_DOUBLE,
    TEST_POINTER
} test_kind;
typedef struct test_value {
    test_kind kind;
    long long i;          /* TEST_SIGNED */
    unsigned long long u; /* TEST_UNSIGNED, TEST_POINTER (its address) */
    double d;             /* TEST_FLOAT, TEST_DOUBLE */
} test_value;

static inline test_value test_value_signed(long long v)
{
    test_value t = {TEST_SIGNED, v, 0, 0};
    return t;
}
static inline test_value test_value_unsigned(unsigned long long v)
{
    test_value t = {TEST_UNSIGNED, 0, v, 0};
    return t;
}
static inline test_value test_value_float(double v)
{
    test_value t = {TEST_FLOAT, 0, 0, v};
    return t;
}
static inline test_value test_value_double(long double v)
{
    test_value t = {TEST_DOUBLE, 0, 0, (double)v};
    return t;
}
static inline test_value test_value_pointer(const volatile void *v)
{
    test_value t = {TEST_POINTER, 0, (unsigned long long)(uintptr_t)v, 0};
    return t;
}

/* The value of x (evaluated once). Its type is taken from (0 ? (x) : (x)), which promotes char,
 * short and bit-fields to int as arithmetic does and turns arrays into pointers. */
#define TEST_VALUE(x)                                  \
    _Generic((0 ? (x) : (x)), _Bool                    \
             : test_value_unsigned, int                \
             : test_value_signed, long                 \
             : test_value_signed, long long            \
             : test_value_signed, unsigned int         \
             : test_value_unsigned, unsigned long      \
             : test_value_unsigned, unsigned long long \
             : test_value_unsigned, float              \
             : test_value_float, double                \
             : test_value_double, long double          \
             : test_value_double, default              \
             : test_value_pointer)(x)

/* v as a double; as a float where as_float (C's conversion of an integer to a float) */
static inline double test_value_real(test_value v, int as_float)
{
    switch (v.kind) {
    case TEST_SIGNED: return as_float ? (double)(float)v.i : (double)v.i;
    case TEST_UNSIGNED:
    case TEST_POINTER: return as_float ? (double)(float)v.u : (double)v.u;
    default: return v.d;
    }
}

/* a against b: -1, 0 or 1, or 2 when they are unordered (a NaN) */
static inline int test_value_compare(test_value a, test_value b)
{
    if (a.kind == TEST_DOUBLE || b.kind == TEST_DOUBLE || a.kind == TEST_FLOAT ||
        b.kind == TEST_FLOAT) {
        int as_float = a.kind != TEST_DOUBLE && b.kind != TEST_DOUBLE;
        double x = test_value_real(a, as_float), y = test_value_real(b, as_float);
        return x < y ? -1 : x > y ? 1 : x == y ? 0 : 2;
    }
    if (a.kind == TEST_SIGNED && b.kind == TEST_SIGNED)
        return a.i < b.i ? -1 : a.i > b.i;
    if (a.kind == TEST_SIGNED && a.i < 0)
        return -1;
    if (b.kind == TEST_SIGNED && b.i < 0)
        return 1;
    unsigned long long x = a.kind == TEST_SIGNED ? (unsigned long long)a.i : a.u;
    unsigned long long y = b.kind == TEST_SIGNED ? (unsigned long long)b.i : b.u;
    return x < y ? -1 : x > y;
}

/* Prints "    expr = value", or nothing where expr is the value as written (a literal). */
static inline void test_value_print(const char *expr, test_value v)
{
    char text[64];
    switch (v.kind) {
    case TEST_SIGNED: snprintf(text, sizeof text, "%lld", v.i); break;
    case TEST_UNSIGNED:
        snprintf(text, sizeof text, v.u < 256 ? "%llu" : "%llu (0x%llx)", v.u, v.u);
        break;
    case TEST_FLOAT: snprintf(text, sizeof text, "%.9g", v.d); break;
    case TEST_DOUBLE: snprintf(text, sizeof text, "%.17g", v.d); break;
    case TEST_POINTER:
        if (v.u == 0)
            snprintf(text, sizeof text, "NULL");
        else
            snprintf(text, sizeof text, "%p", (void *)(uintptr_t)v.u);
        break;
    }
    size_t n = strlen(text);
    if (strncmp(expr, text, n) != 0 || expr[n] != '\0')
        fprintf(stderr, "    %s = %s\n", expr, text);
}

typedef enum {
    TEST_EQ,
    TEST_NE,
    TEST_LT,
    TEST_LE,
    TEST_GT,
    TEST_GE
} test_op;

static inline int test_check_compare(const char *file, int line, test_op op, const char *ea,
                                     const char *eb, test_value a, test_value b)
{
    static const char *const names[] = {"EQ", "NE", "LT", "LE", "GT", "GE"};
    static const char *const symbols[] = {"==", "!=", "<", "<=", ">", ">="};
    int c = test_value_compare(a, b);
    int ok = op == TEST_EQ   ? c == 0
             : op == TEST_NE ? c != 0
             : op == TEST_LT ? c == -1
             : op == TEST_LE ? c == -1 || c == 0
             : op == TEST_GT ? c == 1
                             : c == 1 || c == 0;
    if (ok) {
        test_checks_passed++;
        return 1;
    }
    test_checks_failed++;
    fprintf(stderr, "%s:%d: CHECK_%s failed: %s %s %s\n", file, line, names[op], ea, symbols[op],
            eb);
    test_value_print(ea, a);
    test_value_print(eb, b);
    return 0;
}

/* (each names its operands itself: NULL prints as NULL, not as its expansion) */
#define TEST_COMPARE(op, a, b, ea, eb) \
    test_check_compare(__FILE__, __LINE__, op, ea, eb, TEST_VALUE(a), TEST_VALUE(b))
#define CHECK_EQ(a, b) TEST_COMPARE(TEST_EQ, a, b, #a, #b)
#define CHECK_NE(a, b) TEST_COMPARE(TEST_NE, a, b, #a, #b)
#define CHECK_LT(a, b) TEST_COMPARE(TEST_LT, a, b, #a, #b)
#define CHECK_LE(a, b) TEST_COMPARE(TEST_LE, a, b, #a, #b)
#define CHECK_GT(a, b) TEST_COMPARE(TEST_GT, a, b, #a, #b)
#define CHECK_GE(a, b) TEST_COMPARE(TEST_GE, a, b, #a, #b)

static inline int test_check_near(const char *file, int line, const char *ea, const char *eb,
                                  const char *et, double a, double b, double tol)
{
    if (fabs(a - b) <= tol) {
        test_checks_passed++;
        return 1;
    }
    test_checks_failed++;
    fprintf(stderr, "%s:%d: CHECK_NEAR failed: |%s - %s| <= %s\n", file, line, ea, eb, et);
    test_value_print(ea, test_value_double(a));
    test_value_print(eb, test_value_double(b));
    fprintf(stderr, "    difference %.17g, tolerance %g\n", fabs(a - b), tol);
    return 0;
}
#define CHECK_NEAR(a, b, tol) test_check_near(__FILE__, __LINE__, #a, #b, #tol, a, b, tol)

static inline int test_check_mem_eq(const char *file, int line, const char *ea, const char *eb,
                                    const char *en, const void *a, const void *b, size_t n)
{
    const unsigned char *x = (const unsigned char *)a, *y = (const unsigned char *)b;
    if (n == 0 || memcmp(x, y, n) == 0) {
        test_checks_passed++;
        return 1;
    }
    size_t i = 0;
    while (x[i] == y[i])
        i++;
    test_checks_failed++;
    fprintf(stderr, "%s:%d: CHECK_MEM_EQ failed: %s and %s differ in their %s = %zu bytes\n", file,
            line, ea, eb, en, n);
    fprintf(stderr, "    first at byte %zu: %s has 0x%02x, %s has 0x%02x\n", i, ea, x[i], eb, y[i]);
    return 0;
}
#define CHECK_MEM_EQ(a, b, n) test_check_mem_eq(__FILE__, __LINE__, #a, #b, #n, a, b, n)

/* Prints "    expr = "text"" (or NULL), or nothing where expr is that string literal. */
static inline void test_string_print(const char *expr, const char *text)
{
    size_t n = text ? strlen(text) : 0;
    if (!text && strcmp(expr, "NULL") == 0)
        return;
    if (text && expr[0] == '"' && strncmp(expr + 1, text, n) == 0 &&
        strcmp(expr + 1 + n, "\"") == 0)
        return;
    fprintf(stderr, text ? "    %s = \"%s\"\n" : "    %s = %s\n", expr, text ? text : "NULL");
}

static inline int test_check_str_eq(const char *file, int line, const char *ea, const char *eb,
                                    const char *a, const char *b)
{
    if (a == b || (a != NULL && b != NULL && strcmp(a, b) == 0)) {
        test_checks_passed++;
        return 1;
    }
    test_checks_failed++;
    fprintf(stderr, "%s:%d: CHECK_STR_EQ failed: %s equals %s\n", file, line, ea, eb);
    test_string_print(ea, a);
    test_string_print(eb, b);
    return 0;
}
#define CHECK_STR_EQ(a, b) test_check_str_eq(__FILE__, __LINE__, #a, #b, a, b)

/* The next value of a xorshift64 generator (*state nonzero, updated): reproducible test data. */
static inline uint64_t test_xorshift(uint64_t *state)
{
    uint64_t x = *state;
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    return *state = x;
}

/* The scratch folders test_tmp_dir() made, removed by test_summary() when every check
 * passed and kept, for diagnosis, otherwise (and after a REQUIRE or a crash). */
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

/* The cases of a test program, run by name:
 *
 *   static const test_case cases[] = {
 *       TEST_CASE(test_capacity),          the function void test_capacity(void), by its name
 *       {"test_spread", spread_sizes},     a name and a function
 *   };
 *   int main(int argc, char **argv)
 *   {
 *       return RUN_CASES(argc, argv, cases, "test_array");
 *   }
 *
 * With no argument every case runs, in the table's order; with names, those cases, in the
 * order named; "--list" prints the names. An unknown name runs nothing and fails (status 2)
 * with the names it knows. RUN_CASES_WITH(argc, argv, cases, program, setup, teardown) also
 * runs setup before the first case and teardown after the last (either may be NULL), so that
 * what several cases share is made only when a case runs. Both return test_summary(program)
 * after the cases, and print the name of each case that had failures. */
typedef struct test_case {
    const char *name;
    void (*run)(void);
} test_case;

#define TEST_CASE(fn) \
    {                 \
#fn, fn       \
    }

static inline int test_run_cases(int argc, char **argv, const test_case *cases, size_t count,
                                 const char *program, void (*setup)(void), void (*teardown)(void))
{
    for (int a = 1; a < argc; a++) {
        int list = strcmp(argv[a], "--list") == 0, known = list;
        for (size_t c = 0; c < count && !known; c++)
            known = strcmp(argv[a], cases[c].name) == 0;
        if (!known)
            fprintf(stderr, "%s: no case named \"%s\"; the cases:\n", program, argv[a]);
        if (list || !known) {
            for (size_t c = 0; c < count; c++)
                fprintf(list ? stdout : stderr, "%s\n", cases[c].name);
            return list ? 0 : 2;
        }
    }
    if (setup)
        setup();
    size_t runs = argc > 1 ? (size_t)argc - 1 : count;
    for (size_t r = 0; r < runs; r++) {
        const test_case *c = cases + r;
        if (argc > 1) /* the case named (known: checked above) */
            for (c = cases; strcmp(c->name, argv[r + 1]) != 0; c++)
                continue;
        int failed_before = test_checks_failed;
        c->run();
        if (test_checks_failed > failed_before)
            fprintf(stderr, "%s: case %s: %d failed\n", program, c->name,
                    test_checks_failed - failed_before);
    }
    if (teardown)
        teardown();
    return test_summary(program);
}

#define TEST_CASE_COUNT(cases) (sizeof(cases) / sizeof((cases)[0]))
#define RUN_CASES(argc, argv, cases, program) \
    test_run_cases(argc, argv, cases, TEST_CASE_COUNT(cases), program, NULL, NULL)
#define RUN_CASES_WITH(argc, argv, cases, program, setup, teardown) \
    test_run_cases(argc, argv, cases, TEST_CASE_COUNT(cases), program, setup, teardown)

#endif

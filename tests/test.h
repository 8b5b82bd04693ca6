/* test.h - the tiny harness shared by the unit-test files (included once, by test_main.c).
   A test is a function void f(void); CHECK* record failures and keep going; each test file
   ends with a table of its tests. */
#ifndef RAD_TEST_H
#define RAD_TEST_H
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>

typedef struct rad_test_case { const char *name; void (*fn)(void); } rad_test_case;

static int rad_test_failures; /* failed checks in the current test */

#define CHECK(cond)                                                                                  \
    do {                                                                                             \
        if (!(cond)) {                                                                               \
            printf("    FAIL %s:%d: %s\n", __FILE__, __LINE__, #cond);                              \
            rad_test_failures++;                                                                     \
        }                                                                                            \
    } while (0)

/* |a - b| <= tol */
#define CHECK_NEAR(a, b, tol)                                                                        \
    do {                                                                                             \
        double a_ = (double)(a), b_ = (double)(b), t_ = (double)(tol);                               \
        if (!(fabs(a_ - b_) <= t_)) {                                                                \
            printf("    FAIL %s:%d: %s = %.9g, %s = %.9g, |diff| %.3g > %.3g\n", __FILE__, __LINE__, #a, a_, \
                   #b, b_, fabs(a_ - b_), t_);                                                       \
            rad_test_failures++;                                                                     \
        }                                                                                            \
    } while (0)

/* |a - b| <= rel * |b| */
#define CHECK_REL(a, b, rel)                                                                         \
    do {                                                                                             \
        double a_ = (double)(a), b_ = (double)(b), r_ = (double)(rel);                               \
        if (!(fabs(a_ - b_) <= r_ * fabs(b_))) {                                                     \
            printf("    FAIL %s:%d: %s = %.9g, %s = %.9g, relative error %.3g > %.3g\n", __FILE__, __LINE__, #a, \
                   a_, #b, b_, b_ != 0.0 ? fabs(a_ - b_) / fabs(b_) : fabs(a_ - b_), r_);           \
            rad_test_failures++;                                                                     \
        }                                                                                            \
    } while (0)

#define CHECK_RESULT(expr, expected)                                                                 \
    do {                                                                                             \
        rad_result got_ = (expr);                                                                    \
        if (got_ != (expected)) {                                                                    \
            printf("    FAIL %s:%d: %s returned %s, expected %s\n", __FILE__, __LINE__, #expr,       \
                   rad_result_string(got_), rad_result_string(expected));                            \
            rad_test_failures++;                                                                     \
        }                                                                                            \
    } while (0)

#define CHECK_OK(expr) CHECK_RESULT(expr, RAD_SUCCESS)

/* RAD_TEST_QUICK=1 (sanitizer builds) asks tests to use smaller sizes */
static int rad_test_quick(void)
{
    const char *q = getenv("RAD_TEST_QUICK");
    return q && q[0] == '1';
}

/* A scratch file path: in $RAD_TEST_TMPDIR (tests/run.sh gives each suite its own, so suites
   run side by side without sharing files), else $TMPDIR, else /tmp. Four buffers in turn, so a
   test can hold a few paths at once. */
static const char *rad_test_path(const char *name)
{
    static char buf[4][512];
    static int next;
    const char *dir = getenv("RAD_TEST_TMPDIR");
    char *out = buf[next++ & 3];
    if (!dir || !dir[0]) dir = getenv("TMPDIR");
    if (!dir || !dir[0]) dir = "/tmp";
    snprintf(out, sizeof(buf[0]), "%s/rad_test_%s", dir, name);
    return out;
}

#endif

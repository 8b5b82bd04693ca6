/* test.h - the tiny harness shared by the unit-test files (through fixtures.h).
   A test is a function void f(void); CHECK* record failures and keep going; each test file
   ends with a table of its tests and RAD_TEST_MAIN(table), which is the file's main when it
   is built on its own and nothing inside test_main.c (which defines RAD_TEST_ALL and runs
   every table). Usage of either binary: [NAME-SUBSTRING]; prints "N passed, N failed" last.
   Environment: RAD_TEST_QUICK=1 smaller sizes; RAD_TEST_SHARD=i/n every n-th test from the
   i-th; RAD_TEST_SKIP=a,b leaves out the tests of those names; RAD_TEST_TIMES=1 CPU seconds
   per test; RAD_TEST_TMPDIR where scratch files go. */
#ifndef RAD_TEST_H
#define RAD_TEST_H
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <time.h>

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

/* 1 when 'name' is one of the comma-separated names in 'list' */
static int rad_test_listed(const char *list, const char *name)
{
    size_t n = strlen(name);
    const char *p = list;
    while (*p) {
        const char *e = strchr(p, ',');
        size_t len = e ? (size_t)(e - p) : strlen(p);
        if (len == n && strncmp(p, name, n) == 0) return 1;
        if (!e) break;
        p = e + 1;
    }
    return 0;
}

/* Runs the tests of 'count' tables (filtered by argv[1] and the environment above); returns
   the exit status. */
static int rad_test_run(const rad_test_case *const *tables, size_t count, int argc, char **argv)
{
    int passed = 0, failed = 0;
    int times = getenv("RAD_TEST_TIMES") != NULL; /* CPU seconds per test, to keep the suite short */
    size_t t;
    unsigned shard = 0, shards = 1, index = 0; /* RAD_TEST_SHARD=i/n: every n-th test from the i-th */
    const char *sh = getenv("RAD_TEST_SHARD"), *skip = getenv("RAD_TEST_SKIP");
    if (sh && (sscanf(sh, "%u/%u", &shard, &shards) != 2 || shards == 0 || shard >= shards)) {
        printf("RAD_TEST_SHARD='%s' is not i/n with i < n\n", sh);
        return 2;
    }
    (void)&rad_test_quick; /* helpers some builds do not call */
    if (getenv("RAD_TEST_TMPDIR") && getenv("RAD_TEST_TMPDIR")[0]) {
        /* a missing scratch folder would fail the file tests one by one with an I/O error */
        const char *probe = rad_test_path("writable");
        FILE *f = fopen(probe, "w");
        if (!f) {
            printf("RAD_TEST_TMPDIR='%s' is not a writable folder (create it first)\n", getenv("RAD_TEST_TMPDIR"));
            return 2;
        }
        fclose(f);
        remove(probe);
    }
    for (t = 0; t < count; ++t) {
        const rad_test_case *c;
        for (c = tables[t]; c->name; ++c) {
            clock_t t0;
            if (argc > 1 && !strstr(c->name, argv[1])) continue;
            if (skip && rad_test_listed(skip, c->name)) continue;
            if (index++ % shards != shard) continue;
            rad_test_failures = 0;
            printf("%s\n", c->name);
            fflush(stdout);
            t0 = clock();
            c->fn();
            if (times) printf("  time %s %.2f s\n", c->name, (double)(clock() - t0) / CLOCKS_PER_SEC);
            if (rad_test_failures) { printf("  FAILED %s (%d checks)\n", c->name, rad_test_failures); failed++; }
            else passed++;
        }
    }
    printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}

#ifdef RAD_TEST_ALL
#define RAD_TEST_MAIN(table)
#else
#define RAD_TEST_MAIN(table)                                                                         \
    int main(int argc, char **argv)                                                                  \
    {                                                                                                \
        static const rad_test_case *const tables_[] = { table };                                     \
        return rad_test_run(tables_, 1, argc, argv);                                                 \
    }
#endif

#endif

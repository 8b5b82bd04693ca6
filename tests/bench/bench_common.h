/* bench_common.h - what every benchmark program shares: a monotonic wall clock and emit(),
   which prints a line to stdout and, when g_md is open, appends it to the Markdown report.
   Include it first, before any system header (it asks for POSIX clock_gettime). */
#ifndef RAD_BENCH_COMMON_H
#define RAD_BENCH_COMMON_H
#if !defined(_WIN32) && !defined(_POSIX_C_SOURCE)
#  define _POSIX_C_SOURCE 200809L /* clock_gettime, popen */
#endif
#include <stdarg.h>
#include <stdio.h>
#include <time.h>

static FILE *g_md; /* the report; every table line goes to stdout and here */

/* seconds on a monotonic clock */
static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static inline void emit(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vprintf(fmt, ap);
    va_end(ap);
    fflush(stdout);
    if (g_md) {
        va_start(ap, fmt);
        vfprintf(g_md, fmt, ap);
        va_end(ap);
    }
}
#endif

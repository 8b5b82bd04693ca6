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
#include <string.h>
#include <time.h>
#if !defined(_WIN32)
#  include <unistd.h> /* sysconf */
#endif

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
/* One line under each section's heading: the machine it ran on (CPU model, logical CPUs), the
   load average when it started and the date, so a section measured apart from the others
   (another day, another machine, a busy one) says so itself. */
static inline void emit_machine(void)
{
    char model[128] = "unknown CPU", line[256];
    double load = -1.0;
    long cpus = -1;
    FILE *f = fopen("/proc/cpuinfo", "r");
    time_t t = time(NULL);
    char when[64] = "?";
    if (f) {
        while (fgets(line, sizeof(line), f)) {
            char *c = strchr(line, ':');
            if (!strncmp(line, "model name", 10) && c) {
                size_t n;
                c += 1 + (c[1] == ' ');
                n = strcspn(c, "\n");
                if (n >= sizeof(model)) n = sizeof(model) - 1;
                memcpy(model, c, n);
                model[n] = 0;
                break;
            }
        }
        fclose(f);
    }
    if ((f = fopen("/proc/loadavg", "r")) != NULL) {
        if (fscanf(f, "%lf", &load) != 1) load = -1.0;
        fclose(f);
    }
#if defined(_SC_NPROCESSORS_ONLN)
    cpus = sysconf(_SC_NPROCESSORS_ONLN);
#endif
    strftime(when, sizeof(when), "%Y-%m-%d %H:%M UTC", gmtime(&t));
    emit("Machine: %s, %ld logical CPUs, load average %.1f at the start; %s.\n\n", model, cpus, load, when);
}
#endif

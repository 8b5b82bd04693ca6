/* common.c - the implementation of radiosity.h for the rad tool, and the helpers every command
   shares (tool.h): progress and logging, contexts and threads, number and camera parsing,
   reading files. The scene ("world") and the default camera are world.c's. */
#if !defined(_WIN32) && !defined(_POSIX_C_SOURCE)
#define _POSIX_C_SOURCE 199309L /* clock_gettime, isatty */
#endif
#define RADIOSITY_IMPLEMENTATION
#include "tool.h"
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#ifdef _OPENMP
#include <omp.h>
#endif
#if defined(__unix__) || defined(__APPLE__)
#include <unistd.h>
#define TOOL_ISATTY(fd) isatty(fd)
#else
#define TOOL_ISATTY(fd) 0
#endif

/* ---- shared helpers ------------------------------------------------------------------- */

static struct {
    const void *label;
    int last;     /* last percentage shown, -1: none */
    int open;     /* a bar line is open on a terminal */
} g_progress = {NULL, -1, 0};

void tool_progress_end(void)
{
    if (g_progress.open) fprintf(stderr, "\n");
    g_progress.open = 0;
    g_progress.last = -1;
    g_progress.label = NULL;
}

int tool_progress(void *user, float fraction)
{
    const char *label = user ? (const char *)user : "working";
    int pct;
    if (!(fraction >= 0.0f)) fraction = 0.0f;
    if (fraction > 1.0f) fraction = 1.0f;
    pct = (int)(fraction * 100.0f);
    if (g_progress.label != user || pct < g_progress.last) {
        tool_progress_end();
        g_progress.label = user;
    }
    if (pct == g_progress.last) return 0;
    if (TOOL_ISATTY(2)) {
        char bar[31];
        int i, fill = pct * 30 / 100;
        for (i = 0; i < 30; ++i) bar[i] = i < fill ? '#' : '.';
        bar[30] = 0;
        fprintf(stderr, "\r  %-14s [%s] %3d%%", label, bar, pct);
        g_progress.open = 1;
        if (pct >= 100) {
            fprintf(stderr, "\n");
            g_progress.open = 0;
        }
        fflush(stderr);
        g_progress.last = pct;
    } else {
        /* a plain line every 10% */
        if (g_progress.last < 0 || pct / 10 != g_progress.last / 10) {
            fprintf(stderr, "  %s %d%%\n", label, pct / 10 * 10);
            g_progress.last = pct / 10 * 10;
        }
    }
    if (pct >= 100) g_progress.last = 100;
    return 0;
}

void tool_log(void *user, rad_log_level level, const char *message)
{
    (void)user;
    if (g_progress.open) {
        fprintf(stderr, "\n");
        g_progress.open = 0;
    }
    fprintf(stderr, "rad: %s: %s\n", level == RAD_LOG_ERROR ? "error" : level == RAD_LOG_WARNING ? "warning" : "info",
            message);
}

static int g_progress_on = 1;

void tool_show_progress(int on)
{
    g_progress_on = on;
}

void tool_context(rad_context *ctx, const char *label)
{
    memset(ctx, 0, sizeof *ctx);
    ctx->log = tool_log;
    if (label && g_progress_on) {
        ctx->progress = tool_progress;
        ctx->progress_user = (void *)(size_t)label;
    }
}

void tool_set_threads(int threads)
{
#ifdef _OPENMP
    if (threads > (int)TOOL_MAX_THREADS) threads = (int)TOOL_MAX_THREADS; /* the parsers refuse more */
    if (threads > 0) omp_set_num_threads(threads);
#else
    (void)threads;
#endif
}

void *tool_calloc(size_t n, size_t size)
{
    void *p = calloc(n ? n : 1, size);
    if (!p) {
        fprintf(stderr, "rad: out of memory (%lu x %lu bytes)\n", (unsigned long)n, (unsigned long)size);
        exit(1);
    }
    return p;
}

int tool_cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

void *tool_malloc(size_t size)
{
    void *p = malloc(size ? size : 1);
    if (!p) {
        fprintf(stderr, "rad: out of memory (%lu bytes)\n", (unsigned long)size);
        exit(1);
    }
    return p;
}

int tool_fail(const char *cmd, const char *what, rad_result r)
{
    tool_progress_end();
    fprintf(stderr, "rad %s: %s failed: %s\n", cmd, what, rad_result_string(r));
    return 1;
}

int tool_parse_uint(const char *cmd, const char *opt, const char *text, uint32_t *out)
{
    char *end;
    unsigned long v;
    if (!text || !*text || *text == '-') goto bad;
    v = strtoul(text, &end, 10);
    if (*end != '\0' || v > 0xFFFFFFFFul) goto bad;
    *out = (uint32_t)v;
    return 0;
bad:
    fprintf(stderr, "rad %s: bad value '%s' for %s (want a whole number >= 0)\n", cmd, text ? text : "", opt);
    return 2;
}

int tool_parse_threads(const char *cmd, const char *opt, const char *text, uint32_t *out)
{
    uint32_t v = 0;
    if (tool_parse_uint(cmd, opt, text, &v)) return 2;
    if (v > TOOL_MAX_THREADS) {
        fprintf(stderr, "rad %s: %s %s is too many (at most %u; 0 means all cores)\n", cmd, opt, text,
                TOOL_MAX_THREADS);
        return 2;
    }
    *out = v;
    return 0;
}

int tool_parse_float(const char *cmd, const char *opt, const char *text, float *out)
{
    char *end;
    float v;
    if (!text || !*text) goto bad;
    v = strtof(text, &end);
    if (*end != '\0' || !(v == v) || fabsf(v) > 1e30f) goto bad;
    *out = v;
    return 0;
bad:
    fprintf(stderr, "rad %s: bad value '%s' for %s (want a number)\n", cmd, text ? text : "", opt);
    return 2;
}

double tool_seconds(void)
{
#if defined(_OPENMP)
    return omp_get_wtime();
#elif defined(CLOCK_MONOTONIC)
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
#else
    return (double)clock() / (double)CLOCKS_PER_SEC;
#endif
}

const char *tool_vector_problem(const float v[3], int direction)
{
    float s;
    int i;
    for (i = 0; i < 3; ++i) {
        if (!(v[i] - v[i] == 0.0f)) return "is not finite";
        if (fabsf(v[i]) > 1e30f) return "has a component beyond 1e30";
    }
    if (!direction) return NULL;
    /* what the library does with a direction: divide by the length computed in float */
    s = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    if (!(s <= FLT_MAX)) return "is too long (its squared length overflows a float; scale it down)";
    if (!(s >= FLT_MIN)) return "is zero (or too short to normalise)";
    return NULL;
}

int tool_parse_camera(const char *text, rad_camera *out, const char **why)
{
    float v[9], d[3];
    char extra;
    const char *w;
    int i;
    *why = "want PX,PY,PZ:TX,TY,TZ:UX,UY,UZ";
    if (!text) return 1;
    if (sscanf(text, "%f,%f,%f:%f,%f,%f:%f,%f,%f%c", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5], &v[6], &v[7], &v[8],
               &extra) != 9)
        return 1;
    if ((w = tool_vector_problem(v, 0)) != NULL || (w = tool_vector_problem(v + 3, 0)) != NULL) {
        *why = w[0] == 'i' ? "a point is not finite" : "a point has a component beyond 1e30";
        return 1;
    }
    for (i = 0; i < 3; ++i) d[i] = v[3 + i] - v[i];
    if ((w = tool_vector_problem(d, 1)) != NULL) {
        static char buf[128];
        snprintf(buf, sizeof buf, "the view direction (target - position) %s", w);
        *why = buf;
        return 1;
    }
    if ((w = tool_vector_problem(v + 6, 1)) != NULL) {
        static char buf[128];
        snprintf(buf, sizeof buf, "the up vector %s", w);
        *why = buf;
        return 1;
    }
    {
        /* up along the view direction leaves the image's horizontal axis undefined */
        double dl = sqrt((double)d[0] * d[0] + (double)d[1] * d[1] + (double)d[2] * d[2]);
        double ul = sqrt((double)v[6] * v[6] + (double)v[7] * v[7] + (double)v[8] * v[8]);
        double c0 = ((double)d[1] * v[8] - (double)d[2] * v[7]) / (dl * ul);
        double c1 = ((double)d[2] * v[6] - (double)d[0] * v[8]) / (dl * ul);
        double c2 = ((double)d[0] * v[7] - (double)d[1] * v[6]) / (dl * ul);
        if (!(c0 * c0 + c1 * c1 + c2 * c2 > 1e-12)) {
            *why = "the up vector is parallel to the view direction";
            return 1;
        }
    }
    memcpy(out->position, v, 3 * sizeof(float));
    memcpy(out->target, v + 3, 3 * sizeof(float));
    memcpy(out->up, v + 6, 3 * sizeof(float));
    *why = NULL;
    return 0;
}

int tool_parse_size(const char *text, int *w, int *h)
{
    unsigned long a, b;
    char extra;
    if (!text || sscanf(text, "%lux%lu%c", &a, &b, &extra) != 2) return 1;
    if (a == 0 || b == 0 || a > 32768 || b > 32768) return 1;
    *w = (int)a;
    *h = (int)b;
    return 0;
}

int tool_check_size(const char *cmd, int w, int h)
{
    double bytes = (double)w * (double)h * 3.0 * sizeof(float);
    if (w <= 0 || h <= 0) return 2;
    if (bytes > TOOL_MAX_IMAGE_BYTES) {
        fprintf(stderr, "rad %s: --size %dx%d needs %.0f bytes (%.1f GiB) for the image, more than the limit of %.0f bytes (%.0f GiB)\n",
                cmd, w, h, bytes, bytes / 1073741824.0, TOOL_MAX_IMAGE_BYTES, TOOL_MAX_IMAGE_BYTES / 1073741824.0);
        return 2;
    }
    return 0;
}

int tool_read_file(const char *cmd, const char *what, const char *path, void **data, size_t *size)
{
    FILE *f;
    unsigned char *buf = NULL;
    size_t n = 0, cap = 0;
    int e = 0;
    *data = NULL;
    *size = 0;
    errno = 0;
    if (!(f = fopen(path, "rb"))) {
        if (cmd) fprintf(stderr, "rad %s: cannot open %s '%s': %s\n", cmd, what, path, strerror(errno ? errno : ENOENT));
        return 1;
    }
    /* read to the end rather than trust a size from the file system (pipes, /proc report 0) */
    for (;;) {
        size_t got;
        if (n == cap) {
            size_t ncap = cap ? cap * 2 : (size_t)1 << 16;
            unsigned char *nb = ncap > cap ? (unsigned char *)realloc(buf, ncap) : NULL;
            if (!nb) { e = ENOMEM; break; }
            buf = nb;
            cap = ncap;
        }
        errno = 0;
        got = fread(buf + n, 1, cap - n, f);
        n += got;
        if (got == 0) {
            if (ferror(f)) e = errno ? errno : EIO;
            break;
        }
    }
    fclose(f);
    if (e) {
        if (cmd) fprintf(stderr, "rad %s: cannot read %s '%s': %s\n", cmd, what, path, strerror(e));
        free(buf);
        return 1;
    }
    if (n == 0) {
        if (cmd) fprintf(stderr, "rad %s: %s '%s' is empty\n", cmd, what, path);
        free(buf);
        return 1;
    }
    *data = buf; /* malloc'd: aligned for any type, as the loaders want */
    *size = n;
    return 0;
}

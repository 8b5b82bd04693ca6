/* common.c - the implementation of radiosity.h for the rad tool, and the helpers every command
   shares (tool.h): progress and logging, contexts and threads, number and camera parsing, the
   scene ("world") with its ray backend and lights, and the default camera. */
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

int tool_open_world(const char *cmd, const char *path_or_name, tool_world *w)
{
    return tool_open_world_lit(cmd, path_or_name, NULL, w);
}

int tool_open_world_lit(const char *cmd, const char *path_or_name, const tool_lights *lights,
                            tool_world *w)
{
    char err[1024];
    rad_context ctx;
    rad_result r;
    memset(w, 0, sizeof *w);
    if (tool_load_scene(path_or_name, &w->file, err, sizeof err) != 0) {
        fprintf(stderr, "rad %s: %s\n", cmd, err);
        return 1;
    }
    w->file_light_count = w->file.light_count;
    if (tool_add_lights(cmd, &w->file, lights, &w->lights_storage)) {
        tool_free_scene(&w->file);
        return 1;
    }
    tool_context(&ctx, NULL);
    if ((r = rad_scene_create(&w->file.desc, &ctx, &w->scene)) != RAD_SUCCESS) {
        tool_close_world(w);
        return tool_fail(cmd, "rad_scene_create", r);
    }
    if (w->scene->skipped_triangles)
        fprintf(stderr, "rad: warning: %u degenerate triangles skipped\n", w->scene->skipped_triangles);
    if ((r = rad_bvh_create(w->scene, &ctx, &w->bvh)) != RAD_SUCCESS) {
        tool_close_world(w);
        return tool_fail(cmd, "rad_bvh_create", r);
    }
    rad_bvh_raycaster(w->bvh, &w->rc);
    return 0;
}

void tool_close_world(tool_world *w)
{
    rad_bvh_destroy(w->bvh);
    rad_scene_destroy(w->scene);
    tool_free_scene(&w->file);
    tool_lights_release(w->lights_storage);
    memset(w, 0, sizeof *w);
}

/* ---- a camera for a scene that has none ------------------------------------------------ */

/* How much of a candidate view sees the front of surfaces: a grid of camera rays, counting the
   hits on front faces and on back faces (the patches are one-sided: a back face renders black). */
static void camera_score(const rad_scene *scene, const rad_raycaster *rc, const rad_camera *cam, int width, int height,
                         uint32_t *front, uint32_t *back)
{
    enum { GRID = 24 };
    rad_ray rays[GRID * GRID];
    rad_hit hits[GRID * GRID];
    uint32_t n = 0, k;
    int x, y;
    *front = *back = 0;
    for (y = 0; y < GRID; ++y)
        for (x = 0; x < GRID; ++x)
            rad_camera_ray(cam, (uint32_t)width, (uint32_t)height, ((float)x + 0.5f) * (float)width / GRID,
                           ((float)y + 0.5f) * (float)height / GRID, &rays[n++]);
    if (rc->intersect(rc->user, rays, n, hits) != RAD_SUCCESS) return;
    for (k = 0; k < n; ++k) {
        const float *nt;
        if (hits[k].triangle == RAD_NONE || hits[k].triangle >= scene->triangle_count) continue;
        nt = scene->normals + 3 * (size_t)hits[k].triangle;
        if (nt[0] * rays[k].dir[0] + nt[1] * rays[k].dir[1] + nt[2] * rays[k].dir[2] < 0.0f) ++*front;
        else ++*back;
    }
}

void tool_choose_camera(const char *cmd, const rad_scene *scene, const rad_raycaster *rc, int width, int height,
                            rad_camera *cam)
{
    /* view directions in order of preference: along +z first (the Cornell box's camera and
       the old default), then the other horizontal ones, then from above and from below */
    static const float dirs[6][3] = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {-1, 0, 0}, {0, -1, 0}, {0, 1, 0}};
    static const char *const names[6] = {"+z", "-z", "+x", "-x", "-y (from above)", "+y (from below)"};
    const float *lo = scene->bounds_min, *hi = scene->bounds_max;
    float c[3], ext[3], r = 0.0f, d, fov = 39.3077f;
    rad_camera cand[12];
    uint32_t front[12], back[12], best_front = 0;
    int i, k, pick = -1;
    for (k = 0; k < 3; ++k) {
        c[k] = 0.5f * (lo[k] + hi[k]);
        ext[k] = hi[k] - lo[k];
        r += ext[k] * ext[k];
    }
    r = 0.5f * sqrtf(r);
    if (!(r > 0.0f)) r = 1.0f;
    d = r / sinf(0.5f * fov / 57.29577951f);
    for (i = 0; i < 12; ++i) {
        const float *v = dirs[i % 6];
        rad_camera *q = &cand[i];
        for (k = 0; k < 3; ++k) {
            /* 0-5: outside, the bounding sphere in view; 6-11: inside, near the side of the
               bounds behind the camera, looking across */
            float back_off = i < 6 ? d : 0.45f * ext[k];
            q->position[k] = c[k] - v[k] * back_off;
            q->target[k] = q->position[k] + v[k];
        }
        q->up[0] = 0.0f, q->up[1] = v[1] != 0.0f ? 0.0f : 1.0f, q->up[2] = v[1] != 0.0f ? 1.0f : 0.0f;
        q->fov_y_degrees = i < 6 ? fov : 75.0f; /* inside: wide, to see the room around the far wall */
        camera_score(scene, rc, q, width, height, &front[i], &back[i]);
    }
    /* a view qualifies when nine in ten of its hits are front faces; outside views come first
       (the first qualifying one seeing at least half as much as the best of them), then the
       inside ones (the one seeing most) */
    for (i = 0; i < 6; ++i)
        if (front[i] > 0 && 10u * front[i] >= 9u * (front[i] + back[i]) && front[i] > best_front) best_front = front[i];
    for (i = 0; i < 6 && pick < 0 && best_front; ++i)
        if (front[i] > 0 && 10u * front[i] >= 9u * (front[i] + back[i]) && 2u * front[i] >= best_front) pick = i;
    for (i = 6; i < 12 && pick < 0; ++i)
        if (front[i] > 0 && 10u * front[i] >= 9u * (front[i] + back[i]) &&
            (pick < 0 || front[i] > front[pick]))
            pick = i;
    if (pick < 0) { /* nothing clean: the view with the most front faces over back faces */
        long best = 0;
        for (i = 0; i < 12; ++i)
            if ((long)front[i] - (long)back[i] > best) best = (long)front[i] - (long)back[i], pick = i;
        if (pick < 0) pick = 0;
    }
    *cam = cand[pick];
    fprintf(stderr,
            "rad %s: the scene has no camera: bounds (%g, %g, %g) to (%g, %g, %g); chose --camera %g,%g,%g:%g,%g,%g:%g,%g,%g "
            "--fov %g (%s the bounds, looking along %s: %u of %u sample rays see a front face, %u a back face)\n",
            cmd, (double)lo[0], (double)lo[1], (double)lo[2], (double)hi[0], (double)hi[1], (double)hi[2],
            (double)cam->position[0], (double)cam->position[1], (double)cam->position[2], (double)cam->target[0],
            (double)cam->target[1], (double)cam->target[2], (double)cam->up[0], (double)cam->up[1], (double)cam->up[2],
            (double)cam->fov_y_degrees, pick < 6 ? "outside" : "inside", names[pick % 6], front[pick], 24u * 24u,
            back[pick]);
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

/* rad - command-line tool built on radiosity.h: one program with subcommands.

       rad help | rad CMD --help
       rad formfactors SCENE   group form factors between the scene's named objects
       rad bake SCENE -o FILE.radb     a solution, saved (classic, multibounce or temporal)
       rad merge PART... -o FILE.radb  the parts of a sharded bake (bake --shard I/N) joined
       rad render SCENE -o OUT.png|OUT.pfm     an image (classic, multibounce or temporal
                                       radiosity, or path tracing)
       rad trace SCENE -o OUT  the reference path tracer
       (render, trace, bake: --sun, --sky, --point, --spot, --area add lights: lights.c)
       rad compare A B         image metrics
       rad info FILE.radb      what a bake holds
       rad export SCENE -o OUT.obj     the scene as OBJ + MTL
       rad probes SCENE -o OUT.json|OUT.bin    irradiance probes (SH L2) on a grid
       rad lightmap SCENE -o OUT.pfm|OUT.png   a lightmap over the second uv set (cmd_lightmap.c)

   This file holds the implementation of radiosity.h, the dispatcher, the shared helpers of
   tool.h and the formfactors command. Exit codes: 0 ok, 1 failure, 2 usage error. */
#if !defined(_WIN32) && !defined(_POSIX_C_SOURCE)
#define _POSIX_C_SOURCE 199309L /* clock_gettime, isatty */
#endif
#define RADIOSITY_IMPLEMENTATION
#include "tool.h"
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
#define RAD_TOOL_ISATTY(fd) isatty(fd)
#else
#define RAD_TOOL_ISATTY(fd) 0
#endif

/* ---- shared helpers ------------------------------------------------------------------- */

static struct {
    const void *label;
    int last;     /* last percentage shown, -1: none */
    int open;     /* a bar line is open on a terminal */
} g_progress = {NULL, -1, 0};

void rad_tool_progress_end(void)
{
    if (g_progress.open) fprintf(stderr, "\n");
    g_progress.open = 0;
    g_progress.last = -1;
    g_progress.label = NULL;
}

int rad_tool_progress(void *user, float fraction)
{
    const char *label = user ? (const char *)user : "working";
    int pct;
    if (!(fraction >= 0.0f)) fraction = 0.0f;
    if (fraction > 1.0f) fraction = 1.0f;
    pct = (int)(fraction * 100.0f);
    if (g_progress.label != user || pct < g_progress.last) {
        rad_tool_progress_end();
        g_progress.label = user;
    }
    if (pct == g_progress.last) return 0;
    if (RAD_TOOL_ISATTY(2)) {
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

void rad_tool_log(void *user, rad_log_level level, const char *message)
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

void rad_tool_show_progress(int on)
{
    g_progress_on = on;
}

void rad_tool_context(rad_context *ctx, const char *label)
{
    memset(ctx, 0, sizeof *ctx);
    ctx->log = rad_tool_log;
    if (label && g_progress_on) {
        ctx->progress = rad_tool_progress;
        ctx->progress_user = (void *)(size_t)label;
    }
}

void rad_tool_set_threads(int threads)
{
#ifdef _OPENMP
    if (threads > (int)RAD_TOOL_MAX_THREADS) threads = (int)RAD_TOOL_MAX_THREADS; /* the parsers refuse more */
    if (threads > 0) omp_set_num_threads(threads);
#else
    (void)threads;
#endif
}

void *rad_tool_calloc(size_t n, size_t size)
{
    void *p = calloc(n ? n : 1, size);
    if (!p) {
        fprintf(stderr, "rad: out of memory (%lu x %lu bytes)\n", (unsigned long)n, (unsigned long)size);
        exit(1);
    }
    return p;
}

int rad_tool_fail(const char *cmd, const char *what, rad_result r)
{
    rad_tool_progress_end();
    fprintf(stderr, "rad %s: %s failed: %s\n", cmd, what, rad_result_string(r));
    return 1;
}

int rad_tool_parse_uint(const char *cmd, const char *opt, const char *text, uint32_t *out)
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

int rad_tool_parse_threads(const char *cmd, const char *opt, const char *text, uint32_t *out)
{
    uint32_t v = 0;
    if (rad_tool_parse_uint(cmd, opt, text, &v)) return 2;
    if (v > RAD_TOOL_MAX_THREADS) {
        fprintf(stderr, "rad %s: %s %s is too many (at most %u; 0 means all cores)\n", cmd, opt, text,
                RAD_TOOL_MAX_THREADS);
        return 2;
    }
    *out = v;
    return 0;
}

int rad_tool_parse_float(const char *cmd, const char *opt, const char *text, float *out)
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

double rad_tool_seconds(void)
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

int rad_tool_parse_camera(const char *text, rad_camera *out)
{
    float v[9];
    char extra;
    if (!text) return 1;
    if (sscanf(text, "%f,%f,%f:%f,%f,%f:%f,%f,%f%c", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5], &v[6], &v[7], &v[8],
               &extra) != 9)
        return 1;
    {
        int i;
        float d2 = 0.0f, u2 = 0.0f;
        for (i = 0; i < 9; ++i)
            if (!(v[i] == v[i]) || fabsf(v[i]) > 1e30f) return 1;
        for (i = 0; i < 3; ++i) {
            d2 += (v[3 + i] - v[i]) * (v[3 + i] - v[i]);
            u2 += v[6 + i] * v[6 + i];
        }
        if (!(d2 > 0.0f) || !(u2 > 0.0f)) return 1;
    }
    memcpy(out->position, v, 3 * sizeof(float));
    memcpy(out->target, v + 3, 3 * sizeof(float));
    memcpy(out->up, v + 6, 3 * sizeof(float));
    return 0;
}

int rad_tool_parse_size(const char *text, int *w, int *h)
{
    unsigned long a, b;
    char extra;
    if (!text || sscanf(text, "%lux%lu%c", &a, &b, &extra) != 2) return 1;
    if (a == 0 || b == 0 || a > 32768 || b > 32768) return 1;
    *w = (int)a;
    *h = (int)b;
    return 0;
}

int rad_tool_check_size(const char *cmd, int w, int h)
{
    double bytes = (double)w * (double)h * 3.0 * sizeof(float);
    if (w <= 0 || h <= 0) return 2;
    if (bytes > RAD_TOOL_MAX_IMAGE_BYTES) {
        fprintf(stderr, "rad %s: --size %dx%d needs %.0f bytes (%.1f GiB) for the image, more than the limit of %.0f bytes (%.0f GiB)\n",
                cmd, w, h, bytes, bytes / 1073741824.0, RAD_TOOL_MAX_IMAGE_BYTES, RAD_TOOL_MAX_IMAGE_BYTES / 1073741824.0);
        return 2;
    }
    return 0;
}

int rad_tool_open_world(const char *cmd, const char *path_or_name, rad_tool_world *w)
{
    return rad_tool_open_world_lit(cmd, path_or_name, NULL, w);
}

int rad_tool_open_world_lit(const char *cmd, const char *path_or_name, const rad_tool_lights *lights,
                            rad_tool_world *w)
{
    char err[1024];
    rad_context ctx;
    rad_result r;
    memset(w, 0, sizeof *w);
    if (rad_tool_load_scene(path_or_name, &w->file, err, sizeof err) != 0) {
        fprintf(stderr, "rad %s: %s\n", cmd, err);
        return 1;
    }
    w->file_light_count = w->file.light_count;
    if (rad_tool_add_lights(cmd, &w->file, lights, &w->lights_storage)) {
        rad_tool_free_scene(&w->file);
        return 1;
    }
    rad_tool_context(&ctx, NULL);
    if ((r = rad_scene_create(&w->file.desc, &ctx, &w->scene)) != RAD_SUCCESS) {
        rad_tool_close_world(w);
        return rad_tool_fail(cmd, "rad_scene_create", r);
    }
    if (w->scene->skipped_triangles)
        fprintf(stderr, "rad: warning: %u degenerate triangles skipped\n", w->scene->skipped_triangles);
    if ((r = rad_bvh_create(w->scene, &ctx, &w->bvh)) != RAD_SUCCESS) {
        rad_tool_close_world(w);
        return rad_tool_fail(cmd, "rad_bvh_create", r);
    }
    rad_bvh_raycaster(w->bvh, &w->rc);
    return 0;
}

void rad_tool_close_world(rad_tool_world *w)
{
    rad_bvh_destroy(w->bvh);
    rad_scene_destroy(w->scene);
    rad_tool_free_scene(&w->file);
    rad_tool_lights_release(w->lights_storage);
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

void rad_tool_choose_camera(const char *cmd, const rad_scene *scene, const rad_raycaster *rc, int width, int height,
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

/* ---- help ------------------------------------------------------------------------------ */

static void usage(FILE *f)
{
    fprintf(f, "usage: rad COMMAND [options]        (rad COMMAND --help for its options)\n"
               "commands:\n"
               "  help                     this text\n"
               "  version                  the library version\n"
               "  formfactors SCENE        group form factors between the scene's named objects\n"
               "  bake SCENE -o FILE.radb  compute and save a solution: --method classic|multibounce|temporal|\n"
               "                           stochastic|hierarchical|vp|aavp\n"
               "                           --shard I/N or --rows A:B: one part of it (docs/distributed.md)\n"
               "  merge PART... -o FILE    join the parts of a sharded bake into the bake itself\n"
               "  render SCENE -o OUT      render an image (.png or .pfm):\n"
               "                           --method classic|multibounce|temporal|local|vp|aavp|hierarchical|pathtrace\n"
               "                           [--bake FILE.radb]\n"
               "  trace SCENE -o OUT       the reference path tracer\n"
               "  compare A B              compare two images (MSE, PSNR, SSIM)\n"
               "  info FILE.radb           list what a bake holds and check it\n"
               "  export SCENE -o OUT.obj  write the scene as OBJ + MTL (Kd albedo, Ke emission)\n"
               "  probes SCENE -o OUT      irradiance probes (SH L2) on a grid: OUT.json or OUT.bin\n"
               "  lightmap SCENE -o OUT    bake a lightmap (.pfm or .png) over the second uv set, or an\n"
               "                           automatic unwrap; --sh for L1 spherical harmonics\n"
               "SCENE is 'cornell' (the built-in Cornell box) or a file assimp reads\n"
               "(OBJ+MTL, glTF 2.0, FBX, PLY ...). Every command takes --threads N (default: all cores;\n"
               "at most 1024). render, trace and bake add lights to the file's own: --sun DIR:RGB,\n"
               "--sky RGB, --point POS:RGB, --spot POS:DIR:ANGLES:RGB, --area P:U:V:RGB (units: rad render\n"
               "--help). Dense methods (classic, multibounce, temporal, local) refuse a build estimated\n"
               "beyond the free memory (--max-memory SIZE) or an hour; --force runs it anyway.\n");
}

static void formfactors_usage(FILE *f)
{
    fprintf(f, "usage: rad formfactors SCENE [--patches N] [--max-edge L] [--samples S] [--ff M] [--hemicube-res R]\n"
               "                        [--max-memory SIZE] [--force] [--threads N]\n"
               "Prints one line 'FROM TO VALUE' per ordered pair of named objects: the area-weighted\n"
               "group form factor F_GH = sum_{i in G} A_i sum_{j in H} F_ij / sum_{i in G} A_i.\n"
               "  --patches N   target patch count (default 2000)\n"
               "  --max-edge L  longest patch edge (default: no limit)\n"
               "  --samples S   points per patch pair (default 16, up to 256; analytic and montecarlo)\n"
               "  --ff M        analytic (default: the point-to-polygon integral at S points of the other\n"
               "                patch, one visibility ray each), montecarlo (S point pairs) or hemicube\n"
               "                (a hemicube at each patch centroid with an item buffer; no rays)\n"
               "  --hemicube-res R  cells across the hemicube's top face (default 128; even, 4 to 2048)\n"
               "  --max-memory SIZE, --force   the dense build's limit (rad render --help)\n"
               "  --threads N   worker threads (default: all cores; at most 1024)\n");
}

/* ---- formfactors ----------------------------------------------------------------------- */

int rad_cmd_formfactors(int argc, char **argv)
{
    const char *scene_name = NULL, *cmd = "formfactors";
    uint32_t patches_target = 2000, samples = 16, threads = 0, G, H, i, j, gc, hemicube_res = 0;
    rad_ff_method ff_method = RAD_FF_ANALYTIC;
    float max_edge = 0.0f;
    rad_tool_world w;
    rad_patches *P = NULL;
    rad_form_factors *ff = NULL;
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_context ctx;
    rad_result r;
    double *num, *den;
    int a;
    rad_tool_classic_options budget;
    rad_tool_classic_options_default(&budget);
    for (a = 0; a < argc; ++a) {
        const char *o = argv[a];
        int need = !strcmp(o, "--patches") || !strcmp(o, "--samples") || !strcmp(o, "--threads") || !strcmp(o, "--max-edge") ||
                   !strcmp(o, "--ff") || !strcmp(o, "--hemicube-res");
        if (!strcmp(o, "--help") || !strcmp(o, "-h")) { formfactors_usage(stdout); return 0; }
        if (!strcmp(o, "--force")) { budget.force = 1; continue; }
        if (!strcmp(o, "--max-memory")) {
            if (a + 1 >= argc) { fprintf(stderr, "rad %s: %s needs a value\n", cmd, o); return 2; }
            if (rad_tool_parse_bytes(cmd, o, argv[++a], &budget.max_memory)) return 2;
            continue;
        }
        if (need && a + 1 >= argc) { fprintf(stderr, "rad %s: %s needs a value\n", cmd, o); return 2; }
        if (!strcmp(o, "--patches")) { if (rad_tool_parse_uint(cmd, o, argv[++a], &patches_target)) return 2; }
        else if (!strcmp(o, "--samples")) { if (rad_tool_parse_uint(cmd, o, argv[++a], &samples)) return 2; }
        else if (!strcmp(o, "--threads")) { if (rad_tool_parse_threads(cmd, o, argv[++a], &threads)) return 2; }
        else if (!strcmp(o, "--max-edge")) { if (rad_tool_parse_float(cmd, o, argv[++a], &max_edge)) return 2; }
        else if (!strcmp(o, "--hemicube-res")) { if (rad_tool_parse_uint(cmd, o, argv[++a], &hemicube_res)) return 2; }
        else if (!strcmp(o, "--ff")) {
            const char *m = argv[++a];
            if (!strcmp(m, "analytic")) ff_method = RAD_FF_ANALYTIC;
            else if (!strcmp(m, "montecarlo") || !strcmp(m, "monte-carlo")) ff_method = RAD_FF_MONTE_CARLO;
            else if (!strcmp(m, "hemicube")) ff_method = RAD_FF_HEMICUBE;
            else { fprintf(stderr, "rad %s: unknown --ff '%s' (analytic, montecarlo or hemicube)\n", cmd, m); return 2; }
        }
        else if (o[0] == '-' && o[1]) { fprintf(stderr, "rad %s: unknown option '%s'\n", cmd, o); return 2; }
        else if (!scene_name) scene_name = o;
        else { fprintf(stderr, "rad %s: more than one scene given\n", cmd); return 2; }
    }
    if (!scene_name) { fprintf(stderr, "rad %s: no scene given\n", cmd); formfactors_usage(stderr); return 2; }
    if (samples == 0 || max_edge < 0.0f) { fprintf(stderr, "rad %s: --samples must be > 0, --max-edge >= 0\n", cmd); return 2; }
    rad_tool_set_threads((int)threads);
    budget.samples = samples;
    if (rad_tool_open_world(cmd, scene_name, &w)) return 1;
    if (rad_tool_dense_check(cmd, &budget, w.scene->triangle_count, 1)) {
        rad_tool_close_world(&w);
        return 1;
    }
    rad_tool_context(&ctx, "form factors");
    rad_patch_options_default(&po);
    po.target_count = patches_target;
    po.max_edge = max_edge;
    if ((r = rad_patches_create(w.scene, &po, &ctx, &P)) != RAD_SUCCESS) {
        rad_tool_close_world(&w);
        return rad_tool_fail(cmd, "rad_patches_create", r);
    }
    rad_form_factor_options_default(&fo);
    fo.samples = samples;
    fo.method = ff_method;
    if (hemicube_res) fo.hemicube_resolution = hemicube_res;
    fprintf(stderr, "rad %s: %u triangles, %u patches\n", cmd, w.scene->triangle_count, P->count);
    if (rad_tool_dense_check(cmd, &budget, P->count, 0)) {
        rad_patches_destroy(P);
        rad_tool_close_world(&w);
        return 1;
    }
    r = rad_form_factors_dense(P, &w.rc, &fo, &ctx, &ff);
    rad_tool_progress_end();
    if (r != RAD_SUCCESS) {
        rad_patches_destroy(P);
        rad_tool_close_world(&w);
        return rad_tool_fail(cmd, "rad_form_factors_dense", r);
    }
    gc = w.scene->mesh_count;
    num = (double *)calloc((size_t)gc * gc, sizeof(double));
    den = (double *)calloc(gc, sizeof(double));
    if (!num || !den) { fprintf(stderr, "rad %s: out of memory\n", cmd); return 1; }
    for (i = 0; i < P->count; ++i) {
        uint32_t gi = w.scene->meshes[P->patches[i].triangle];
        const float *row = ff->matrix.dense + (size_t)i * P->count;
        double *nrow = num + (size_t)gi * gc;
        den[gi] += P->areas[i];
        for (j = 0; j < P->count; ++j)
            if (row[j] != 0.0f) nrow[w.scene->meshes[P->patches[j].triangle]] += (double)P->areas[i] * row[j];
    }
    for (G = 0; G < gc; ++G)
        for (H = 0; H < gc; ++H)
            printf("%s %s %.6f\n", w.scene->mesh_names[G][0] ? w.scene->mesh_names[G] : "-",
                   w.scene->mesh_names[H][0] ? w.scene->mesh_names[H] : "-",
                   den[G] > 0.0 ? num[(size_t)G * gc + H] / den[G] : 0.0);
    free(num);
    free(den);
    rad_form_factors_destroy(ff);
    rad_patches_destroy(P);
    rad_tool_close_world(&w);
    return 0;
}

/* ---- dispatch -------------------------------------------------------------------------- */

/* main.c calls it; tools/mpi/rad_mpi.c links the other sources with a main of its own */
int rad_tool_main(int argc, char **argv)
{
    static const struct {
        const char *name;
        int (*fn)(int, char **);
    } cmds[] = {{"formfactors", rad_cmd_formfactors}, {"bake", rad_cmd_bake},       {"render", rad_cmd_render},
                {"trace", rad_cmd_trace},             {"compare", rad_cmd_compare}, {"info", rad_cmd_info},
                {"export", rad_cmd_export},           {"probes", rad_cmd_probes},   {"merge", rad_cmd_merge},
                {"lightmap", rad_cmd_lightmap}};
    size_t i;
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    if (!strcmp(argv[1], "help") || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
        if (argc > 2 && strcmp(argv[1], "help") == 0) {
            char *h[1];
            h[0] = (char *)"--help";
            for (i = 0; i < sizeof cmds / sizeof cmds[0]; ++i)
                if (!strcmp(argv[2], cmds[i].name)) return cmds[i].fn(1, h);
        }
        usage(stdout);
        return 0;
    }
    if (!strcmp(argv[1], "version") || !strcmp(argv[1], "--version")) {
        printf("rad (radiosity.h %s)\n", RAD_VERSION_STRING);
        return 0;
    }
    for (i = 0; i < sizeof cmds / sizeof cmds[0]; ++i)
        if (!strcmp(argv[1], cmds[i].name)) return cmds[i].fn(argc - 2, argv + 2);
    fprintf(stderr, "rad: unknown command '%s' (try 'rad help')\n", argv[1]);
    return 2;
}

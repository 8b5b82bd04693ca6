/* cornell.c - render the Cornell box with radiosity.h: direct light per pixel, indirect light
   from radiosity.

   This example shows the way an engine uses radiosity.h (direct light as the source,
   docs/methods/direct-light.md): the built-in
   Cornell box is cut into a few thousand patches, the dense form-factor matrix F is computed
   with the built-in BVH, the direct irradiance D of every patch from the area light is the
   source E = rho * D (the light's own emission is NOT put into the system, so nothing is
   counted twice), Jacobi bounces give the indirect light L, and H = F (E + L) is the
   irradiance every patch receives from the secondary sources (the lit walls). H is smoothed
   into per-vertex values (taking care of patches partly hidden under the light and the
   blocks, see step 7). The image is then drawn per pixel: a camera ray finds the surface,
   the direct irradiance D is computed at that very point with shadow rays (soft shadows at
   pixel resolution), H is interpolated from the patch vertices (colour bleeding), and the
   pixel shows rho / pi * (D + H), plus the emitted radiance where the ray sees the front of
   the light.
   The result is tone mapped (exposure, clamp, sRGB) and written as a PNG.

   Build:  cc -std=c99 -O2 -I. examples/cornell.c -o build/cornell -lm     (add -fopenmp for
           threads: the header's default parallel_for then runs tasks on OpenMP threads)
   Run:    build/cornell [--patches N] [--size WxH] [-o FILE] [--exposure X]
                         [--spp N] [--light-samples N] [--bounces N]                        */

#if !defined(_WIN32) && !defined(_POSIX_C_SOURCE)
#  define _POSIX_C_SOURCE 200112L /* clock_gettime; isatty and fileno */
#endif

#if defined(__unix__) || defined(__APPLE__)
#include <stdio.h>
#include <unistd.h>
#define CORNELL_ISATTY(f) isatty(fileno(f))
#else
#define CORNELL_ISATTY(f) 1
#endif
#define RADIOSITY_IMPLEMENTATION
#include "radiosity.h"
#include "png_write.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#ifdef _OPENMP
#  include <omp.h>
#endif

#define PI_F 3.14159265358979323846f

/* ---- small helpers ------------------------------------------------------------------- */

static double now_seconds(void)
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

static void check(rad_result r, const char *what)
{
    if (r != RAD_SUCCESS) {
        fprintf(stderr, "\ncornell: %s failed: %s\n", what, rad_result_string(r));
        exit(1);
    }
}

static void *xmalloc(size_t size)
{
    void *p = malloc(size ? size : 1);
    if (!p) {
        fprintf(stderr, "cornell: out of memory (%lu bytes)\n", (unsigned long)size);
        exit(1);
    }
    return p;
}

/* Progress to stderr: "  form factors  42%". */
typedef struct progress_state {
    const char *label;
    int last;
} progress_state;

/* On a terminal one line updated in place; in a file or pipe a line per 25% */
static int progress_on_tty(void)
{
    static int tty = -1;
    if (tty < 0) tty = CORNELL_ISATTY(stderr) ? 1 : 0;
    return tty;
}

static int on_progress(void *user, float fraction)
{
    progress_state *s = (progress_state *)user;
    int pct = (int)(fraction * 100.0f + 0.5f);
    if (pct != s->last) {
        if (progress_on_tty()) {
            fprintf(stderr, "\r  %-14s %3d%%", s->label, pct);
        } else if (pct / 25 != (s->last < 0 ? -1 : s->last / 25)) {
            fprintf(stderr, "  %-14s %3d%%\n", s->label, pct);
        }
        fflush(stderr);
        s->last = pct;
    }
    return 0; /* never cancel */
}

static void progress_begin(progress_state *s, const char *label)
{
    s->label = label;
    s->last = -1;
}

static void progress_end(progress_state *s)
{
    if (s->last >= 0 && progress_on_tty()) {
        fprintf(stderr, "\r%40s\r", "");
        fflush(stderr);
    }
    s->last = -1;
}

static void on_log(void *user, rad_log_level level, const char *message)
{
    (void)user;
    fprintf(stderr, "\nradiosity.h %s: %s\n",
            level == RAD_LOG_ERROR ? "error" : level == RAD_LOG_WARNING ? "warning" : "info", message);
}

/* One line of the step report: "  label   what it did   time". */
static void report(const char *label, double seconds, const char *fmt, ...)
{
    char what[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    if (seconds >= 0.0)
        printf("  %-14s %-74s %8.3f s\n", label, what, seconds);
    else
        printf("  %-14s %s\n", label, what);
    fflush(stdout);
}

/* linear [0,1] -> 8-bit sRGB */
static unsigned char srgb8(float v)
{
    float s;
    if (!(v > 0.0f)) v = 0.0f; /* also maps NaN to 0 */
    if (v > 1.0f) v = 1.0f;
    s = v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
    return (unsigned char)(s * 255.0f + 0.5f);
}

static float clamp01(float v)
{
    return v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f;
}

static void usage(void)
{
    fprintf(stderr,
            "usage: cornell [--patches N] [--size WxH] [-o FILE] [--exposure X]\n"
            "               [--spp N] [--light-samples N] [--bounces N]\n"
            "  --patches N        target patch count (default 3000)\n"
            "  --size WxH         image size (default 512x512)\n"
            "  -o FILE            output PNG (default cornell.png)\n"
            "  --exposure X       multiplies radiance before clamping (default 2.5)\n"
            "  --spp N            samples per pixel, rounded down to a square: 1, 4, 9, .. 256 (default 4)\n"
            "  --light-samples N  shadow rays per pixel sample (default 32)\n"
            "  --bounces N        Jacobi bounces of the indirect light (default 32)\n");
    exit(1);
}

static unsigned long parse_count(const char *s, const char *opt)
{
    char *end;
    unsigned long v = strtoul(s, &end, 10);
    if (end == s || *end != '\0' || v == 0) {
        fprintf(stderr, "cornell: bad value '%s' for %s\n", s, opt);
        usage();
    }
    return v;
}

/* ---- main -------------------------------------------------------------------------- */

int main(int argc, char **argv)
{
    uint32_t target_patches = 3000, width = 512, height = 512, spp = 4, light_samples = 32, bounces = 32;
    float exposure = 2.5f; /* see the note at DEFAULT EXPOSURE below */
    const char *out_path = "cornell.png";

    rad_scene_desc desc;
    rad_camera camera;
    rad_scene *scene = NULL;
    rad_patches *patches = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_form_factors *ff = NULL;
    rad_patch_options popt;
    rad_form_factor_options fopt;
    rad_direct_options dopt;
    rad_solve_options sopt;
    rad_solve_stats sstats;
    rad_system sys;
    rad_context ctx, quiet;
    progress_state ps;
    float *D, *E, *L, *EL, *H, *Hv, *S;
    uint32_t blind = 0;
    unsigned char *image;
    uint32_t n, i, k, strata, rows_per_batch, y0;
    size_t batch_cap;
    rad_ray *rays;
    rad_hit *hits;
    float *points, *normals, *irr, *accum;
    uint32_t *valid;
    double t0, t_scene, t_patches, t_bvh, t_ff, t_direct, t_solve, t_gather, t_render, t_start;
    uint64_t samples_total = 0, samples_clipped = 0;
    float max_surface = 0.0f;
    int a;

    for (a = 1; a < argc; ++a) {
        const char *arg = argv[a];
        if (!strcmp(arg, "-h") || !strcmp(arg, "--help")) usage();
        if (a + 1 >= argc) {
            fprintf(stderr, "cornell: unknown option or missing value: %s\n", arg);
            usage();
        }
        if (!strcmp(arg, "--patches")) {
            target_patches = (uint32_t)parse_count(argv[++a], arg);
        } else if (!strcmp(arg, "--size")) {
            unsigned long w, h;
            char extra;
            if (sscanf(argv[++a], "%lux%lu%c", &w, &h, &extra) != 2 || w == 0 || h == 0 || w > 16384 || h > 16384) {
                fprintf(stderr, "cornell: bad size '%s' (want WxH, e.g. 512x512)\n", argv[a]);
                usage();
            }
            width = (uint32_t)w;
            height = (uint32_t)h;
        } else if (!strcmp(arg, "-o")) {
            out_path = argv[++a];
        } else if (!strcmp(arg, "--exposure")) {
            char *end;
            exposure = strtof(argv[++a], &end);
            if (end == argv[a] || *end != '\0' || !(exposure > 0.0f) || exposure > 1e30f) {
                fprintf(stderr, "cornell: bad exposure '%s'\n", argv[a]);
                usage();
            }
        } else if (!strcmp(arg, "--spp")) {
            spp = (uint32_t)parse_count(argv[++a], arg);
            if (spp > 256) spp = 256;
        } else if (!strcmp(arg, "--light-samples")) {
            light_samples = (uint32_t)parse_count(argv[++a], arg);
        } else if (!strcmp(arg, "--bounces")) {
            bounces = (uint32_t)parse_count(argv[++a], arg);
        } else {
            fprintf(stderr, "cornell: unknown option %s\n", arg);
            usage();
        }
    }
    for (strata = 1; (strata + 1) * (strata + 1) <= spp; ++strata) {
    }
    spp = strata * strata; /* a square number of stratified samples per pixel */

    memset(&ctx, 0, sizeof ctx);
    ctx.log = on_log;
    ctx.progress = on_progress;
    ctx.progress_user = &ps;
    quiet = ctx;
    quiet.progress = NULL;
    quiet.progress_user = NULL;
    ps.last = -1;

#ifdef _OPENMP
    printf("radiosity.h %s: Cornell box demo (OpenMP, %d threads)\n", RAD_VERSION_STRING, omp_get_max_threads());
#else
    printf("radiosity.h %s: Cornell box demo (one thread; build with -fopenmp for more)\n", RAD_VERSION_STRING);
#endif
    t_start = now_seconds();

    /* 1. scene */
    t0 = now_seconds();
    rad_cornell_box(&desc, &camera);
    check(rad_scene_create(&desc, &ctx, &scene), "rad_scene_create");
    t_scene = now_seconds() - t0;

    /* 2. patches */
    t0 = now_seconds();
    rad_patch_options_default(&popt);
    popt.target_count = target_patches;
    check(rad_patches_create(scene, &popt, &ctx, &patches), "rad_patches_create");
    t_patches = now_seconds() - t0;
    n = patches->count;
    report("scene", t_scene, "built-in Cornell box, %u triangles", scene->triangle_count);
    report("patches", t_patches, "%u (target %u), %u vertices", n, target_patches, patches->vertex_count);

    /* 3. BVH */
    t0 = now_seconds();
    check(rad_bvh_create(scene, &ctx, &bvh), "rad_bvh_create");
    rad_bvh_raycaster(bvh, &rc);
    t_bvh = now_seconds() - t0;
    report("BVH", t_bvh, "%lu bytes", (unsigned long)rad_bvh_memory(bvh));

    /* 4. dense form factors */
    rad_form_factor_options_default(&fopt);
    progress_begin(&ps, "form factors");
    t0 = now_seconds();
    check(rad_form_factors_dense(patches, &rc, &fopt, &ctx, &ff), "rad_form_factors_dense");
    t_ff = now_seconds() - t0;
    progress_end(&ps);
    report("form factors", t_ff, "%u x %u dense (%.1f MB), %llu pairs, %llu rays, %.2f Mrays/s", n, n,
           4.0 * (double)n * (double)n / 1e6, (unsigned long long)ff->pairs_evaluated,
           (unsigned long long)ff->rays_cast, t_ff > 0 ? (double)ff->rays_cast / t_ff / 1e6 : 0.0);

    /* 5. direct irradiance of the patches from the area light (the emissive triangles) */
    D = (float *)xmalloc(sizeof(float) * 3 * n);
    E = (float *)xmalloc(sizeof(float) * 3 * n);
    L = (float *)xmalloc(sizeof(float) * 3 * n);
    EL = (float *)xmalloc(sizeof(float) * 3 * n);
    H = (float *)xmalloc(sizeof(float) * 3 * n);
    Hv = (float *)xmalloc(sizeof(float) * 3 * (size_t)patches->vertex_count);
    rad_direct_options_default(&dopt);
    dopt.exclude_emitters = 0;
    dopt.light_samples = 32;
    progress_begin(&ps, "direct light");
    t0 = now_seconds();
    check(rad_direct_patches(patches, &rc, NULL, 0, &dopt, D, &ctx), "rad_direct_patches");
    /* E = rho * D: direct light is the source, the light's emission stays out (RAD_SOURCE_DIRECT) */
    check(rad_sources(patches, RAD_SOURCE_DIRECT, D, E), "rad_sources");
    t_direct = now_seconds() - t0;
    progress_end(&ps);
    report("direct light", t_direct, "on patches: %u points x %u shadow rays; E = rho D", dopt.samples ? dopt.samples : 16,
           dopt.light_samples);

    /* 6. indirect light: L = sum of bounces 1..K of B^k = (rho o F) B^(k-1), B^0 = E */
    rad_system_init(&sys, &ff->matrix, patches, E);
    rad_solve_options_default(&sopt);
    sopt.output = RAD_OUTPUT_INDIRECT;
    sopt.bounces = bounces;
    memset(&sstats, 0, sizeof sstats);
    progress_begin(&ps, "solve");
    t0 = now_seconds();
    check(rad_solve_jacobi(&sys, &sopt, L, &sstats, &ctx), "rad_solve_jacobi");
    t_solve = now_seconds() - t0;
    progress_end(&ps);
    report("solve", t_solve, "Jacobi, %u bounces of indirect light L", sstats.iterations);

    /* 7. H = F (E + L): irradiance from the secondary sources, then smoothed to the vertices.
       Plain vertex averages of H would darken the visible surface next to anything that covers
       part of a patch (the ceiling patches under the one-sided light, the floor under the
       blocks): rad_patches_vertex_irradiance takes the row sums S = F 1 (how much each patch
       sees) to interpolate H as (mean radiosity seen) x (how much is seen). */
    t0 = now_seconds();
    S = (float *)xmalloc(sizeof(float) * n);
    for (i = 0; i < 3 * n; ++i) EL[i] = 1.0f;
    check(rad_matrix_multiply(&ff->matrix, EL, H, &quiet), "rad_matrix_multiply (row sums)");
    for (i = 0; i < n; ++i) {
        S[i] = H[3 * i];
        blind += S[i] < 1e-4f;
    }
    for (i = 0; i < 3 * n; ++i) EL[i] = E[i] + L[i];
    check(rad_matrix_multiply(&ff->matrix, EL, H, &quiet), "rad_matrix_multiply");
    check(rad_patches_vertex_irradiance(patches, H, S, Hv, &ctx), "rad_patches_vertex_irradiance");
    t_gather = now_seconds() - t0;
    report("gather", t_gather, "H = F (E + L), per-vertex values (%u patches see nothing)", blind);

    /* 8. render: rows in batches, 'spp' stratified camera rays per pixel.
       DEFAULT EXPOSURE. With the light's radiance (17, 12, 4) the lit surfaces of this open box
       show radiances of about 0.1 to 0.4 (floor under the light ~0.3 in red, back wall ~0.2,
       top of the short block ~0.4; the light itself 17). Exposure 2.5 maps the brightest visible
       surface to just below 1, so the walls look bright without clipping; only the light clips. */
    rows_per_batch = (uint32_t)(16384 / ((size_t)width * spp));
    if (rows_per_batch < 1) rows_per_batch = 1;
    batch_cap = (size_t)rows_per_batch * width * spp;
    rays = (rad_ray *)xmalloc(sizeof(rad_ray) * batch_cap);
    hits = (rad_hit *)xmalloc(sizeof(rad_hit) * batch_cap);
    points = (float *)xmalloc(sizeof(float) * 3 * batch_cap);
    normals = (float *)xmalloc(sizeof(float) * 3 * batch_cap);
    irr = (float *)xmalloc(sizeof(float) * 3 * batch_cap);
    valid = (uint32_t *)xmalloc(sizeof(uint32_t) * batch_cap);
    accum = (float *)xmalloc(sizeof(float) * 3 * (size_t)width * height);
    memset(accum, 0, sizeof(float) * 3 * (size_t)width * height);
    image = (unsigned char *)xmalloc((size_t)3 * width * height);
    rad_direct_options_default(&dopt);
    dopt.exclude_emitters = 0;
    dopt.light_samples = light_samples;

    t0 = now_seconds();
    for (y0 = 0; y0 < height; y0 += rows_per_batch) {
        uint32_t y1 = y0 + rows_per_batch < height ? y0 + rows_per_batch : height;
        uint32_t count = 0, nvalid = 0, x, y, s;
        rad_result r;

        /* primary rays, one batch */
        for (y = y0; y < y1; ++y)
            for (x = 0; x < width; ++x)
                for (s = 0; s < spp; ++s) {
                    float px = (float)x + ((float)(s % strata) + 0.5f) / (float)strata;
                    float py = (float)y + ((float)(s / strata) + 0.5f) / (float)strata;
                    rad_camera_ray(&camera, width, height, px, py, &rays[count++]);
                }
        r = rc.intersect(rc.user, rays, count, hits);
        if (r != RAD_SUCCESS) check(RAD_ERROR_RAYCAST_FAILED, "raycaster intersect");

        /* hit points seen from the front: the exact point on the triangle, its normal */
        for (k = 0; k < count; ++k) {
            uint32_t t = hits[k].triangle;
            const float *v, *nt;
            if (t == RAD_NONE) continue;
            nt = scene->normals + 3 * (size_t)t;
            if (nt[0] * rays[k].dir[0] + nt[1] * rays[k].dir[1] + nt[2] * rays[k].dir[2] >= 0.0f) {
                hits[k].triangle = RAD_NONE; /* back face: patches are one-sided, shows black */
                continue;
            }
            v = scene->positions + 9 * (size_t)t;
            for (i = 0; i < 3; ++i) {
                points[3 * nvalid + i] = v[i] + hits[k].b1 * (v[3 + i] - v[i]) + hits[k].b2 * (v[6 + i] - v[i]);
                normals[3 * nvalid + i] = nt[i];
            }
            valid[nvalid++] = k;
        }

        /* per-point direct irradiance from the area light, shadow rays included */
        if (nvalid > 0)
            check(rad_direct_irradiance(scene, &rc, NULL, 0, &dopt, points, normals, nvalid, irr, &quiet),
                  "rad_direct_irradiance");

        for (k = 0; k < nvalid; ++k) {
            uint32_t ray = valid[k], pixel = (uint32_t)((size_t)y0 * width + ray / spp);
            const rad_hit *h = &hits[ray];
            const rad_material *m = &scene->materials_table[scene->materials[h->triangle]];
            float albedo[3], w[3], radiance[3];
            uint32_t p = rad_patches_locate(patches, h->triangle, h->b1, h->b2, w);
            const uint32_t *vi;
            int clipped = 0;
            if (p == RAD_NONE) check(RAD_ERROR_INVALID_ARGUMENT, "rad_patches_locate");
            vi = patches->patches[p].vertices;
            rad_scene_albedo(scene, h->triangle, h->b1, h->b2, albedo);
            for (i = 0; i < 3; ++i) {
                float hi = w[0] * Hv[3 * (size_t)vi[0] + i] + w[1] * Hv[3 * (size_t)vi[1] + i] +
                           w[2] * Hv[3 * (size_t)vi[2] + i];
                float v;
                radiance[i] = albedo[i] / PI_F * (irr[3 * k + i] + hi) + m->emission[i];
                v = radiance[i] * exposure;
                if (m->emission[i] == 0.0f) {
                    if (v > 1.0f) clipped = 1;
                    if (radiance[i] > max_surface) max_surface = radiance[i];
                }
                accum[3 * (size_t)pixel + i] += clamp01(v); /* clamp per sample: clean light edges */
            }
            if (m->emission[0] == 0.0f && m->emission[1] == 0.0f && m->emission[2] == 0.0f) {
                samples_total++;
                samples_clipped += (uint64_t)clipped;
            }
        }
        if (progress_on_tty()) fprintf(stderr, "\r  %-14s %3d%%", "render", (int)(100.0 * y1 / height + 0.5));
        fflush(stderr);
    }
    t_render = now_seconds() - t0;
    if (progress_on_tty()) fprintf(stderr, "\r%40s\r", "");
    for (i = 0; i < 3 * width * height; ++i) image[i] = srgb8(accum[i] / (float)spp);
    if (png_write_rgb8(out_path, width, height, image, (size_t)3 * width) != 0) {
        fprintf(stderr, "cornell: cannot write %s\n", out_path);
        exit(1);
    }
    report("render", t_render, "%ux%u, %u spp, %u shadow rays per sample", width, height, spp, light_samples);
    report("image", -1.0, "brightest surface radiance %.3f, %.2f%% of surface samples clipped at exposure %g",
           (double)max_surface, samples_total ? 100.0 * (double)samples_clipped / (double)samples_total : 0.0,
           (double)exposure);
    report("total", now_seconds() - t_start, "");
    printf("wrote %s\n", out_path);

    free(rays);
    free(hits);
    free(points);
    free(normals);
    free(irr);
    free(valid);
    free(accum);
    free(image);
    free(D);
    free(E);
    free(L);
    free(EL);
    free(H);
    free(Hv);
    free(S);
    rad_form_factors_destroy(ff);
    rad_bvh_destroy(bvh);
    rad_patches_destroy(patches);
    rad_scene_destroy(scene);
    return 0;
}

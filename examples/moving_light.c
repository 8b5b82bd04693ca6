/* moving_light.c - temporal radiosity (docs/methods/temporal.md) under a moving light: a point light circles
   inside the Cornell box and every frame costs O(N k) draws from alias tables instead of an
   O(N^2) gather; written as a numbered PNG sequence with the per-frame error against the exact
   solution.

   Once: the Cornell box cut into about --patches patches, the dense form factors F, the alias
   tables of F (rad_alias_tables_create), the direct irradiance of the ceiling emitter.
   Per frame f:
     1. the point light moves along a horizontal circle at 3/4 height (one turn in --frames
        frames, --turns to change that); --warmup frames at frame 0's position come first
        (stepped, not drawn nor counted), so that B starts near its steady state;
     2. its direct irradiance on the patches (rad_direct_patches with the light, emitters
        off, shadow rays) plus the ceiling's gives D and the source E = rho o D (rad_sources,
        RAD_SOURCE_DIRECT);
     3. one rad_temporal_step with E: mode feedback (default) converges to the infinite-bounce
        indirect light L_inf, mode single to one bounce rho o (F E);
     4. the exact answer for the same E (single: rad_matrix_multiply and rho; feedback:
        rad_solve_gauss_seidel to 1e-6, RAD_OUTPUT_INDIRECT) and the relative RMS error of the
        frame's indirect light against it (sqrt(sum (B - L)^2 / sum L^2) over the 3N values);
     5. every --every frames, the image: one camera ray per pixel, the hit patch shows its
        exitance (E + B + the emitter's own pi L_e) / pi, tone mapped (exposure, sRGB), to
        PREFIX_NNNN.png.
   A CSV PREFIX.csv gets frame, light position, the error, the step's and the exact solve's
   milliseconds and the blend weight (with --adaptive the mean of the per-row weights). With a moving light the blend weight w trades lag for noise: the light moves
   360/frames degrees per frame and B follows with a delay of about 1/(1 - w) frames (and each
   further bounce of mode feedback one frame more), while the noise of one frame's estimate
   shrinks by sqrt((1 - w)/(1 + w)); hence the defaults k = 64, w = 0.8. --adaptive uses the
   per-row weight of rad_temporal_options.adaptive, made for lights that jump and then stay: a light that moves a
   little every frame does not trip its change test, so the weights climb towards weight_max
   and B lags far behind (docs/BENCHMARKS.md). The step's time includes the parallel_for's start and join
   (OpenMP), which dominate at these sizes and on a busy machine.

   Build:  make moving-light   (cc -std=c99 -O2 -fopenmp -I. examples/moving_light.c -o build/moving_light -lm)
   Run:    build/moving_light [--patches N] [--frames F] [--every E] [--warmup F] [--size WxH]
                              [--k K] [--w W] [--adaptive] [--mode feedback|single] [--turns T]
                              [--ceiling 0|1] [--exposure X] [--seed S] [-o PREFIX]
           (defaults: 1500 patches, 120 frames, every frame, 30 warm-up frames, 256x256, k 64,
           w 0.8, feedback, one turn, ceiling on, exposure 0.8, PREFIX "moving_light")
   Make a video: ffmpeg -framerate 30 -i moving_light_%04d.png moving_light.mp4 */
#if !defined(_WIN32) && !defined(_POSIX_C_SOURCE)
#  define _POSIX_C_SOURCE 199309L /* clock_gettime */
#endif
#define RADIOSITY_IMPLEMENTATION
#include "radiosity.h"
#include "png_write.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void check(rad_result r, const char *what)
{
    if (r != RAD_SUCCESS) {
        fprintf(stderr, "moving_light: %s failed: %s\n", what, rad_result_string(r));
        exit(1);
    }
}

static void *xmalloc(size_t bytes)
{
    void *p = malloc(bytes ? bytes : 1);
    if (!p) {
        fprintf(stderr, "moving_light: out of memory (%zu bytes)\n", bytes);
        exit(1);
    }
    return p;
}

static void usage(void)
{
    fprintf(stderr, "usage: moving_light [--patches N] [--frames F] [--every E] [--warmup F] [--size WxH] [--k K] [--w W]\n"
                    "                    [--adaptive] [--mode feedback|single] [--turns T] [--ceiling 0|1] [--exposure X] [--seed S]\n"
                    "                    [-o PREFIX]\n");
    exit(2);
}

/* a positive number in [lo, hi] or exit */
static double parse_num(const char *opt, const char *v, double lo, double hi)
{
    char *end;
    double x = strtod(v, &end);
    if (end == v || *end != '\0' || !(x >= lo && x <= hi)) {
        fprintf(stderr, "moving_light: %s wants a number in [%g, %g], not '%s'\n", opt, lo, hi, v);
        exit(2);
    }
    return x;
}

static unsigned char srgb8(float v)
{
    float s;
    if (!(v > 0.0f)) v = 0.0f;
    if (v > 1.0f) v = 1.0f;
    s = v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
    return (unsigned char)(s * 255.0f + 0.5f);
}

/* relative RMS of a against b over 3n values */
static double rel_rms(const float *a, const float *b, uint32_t n)
{
    double num = 0.0, den = 0.0;
    size_t i;
    for (i = 0; i < 3 * (size_t)n; ++i) {
        num += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
        den += (double)b[i] * b[i];
    }
    return den > 0.0 ? sqrt(num / den) : sqrt(num);
}

int main(int argc, char **argv)
{
    uint32_t target = 1500, frames = 120, every = 1, W = 256, H = 256, k = 64, seed = 1, ceiling = 1, adaptive = 0, warmup = 30;
    float w = 0.8f, exposure = 0.8f, turns = 1.0f;
    int single = 0, a;
    const char *prefix = "moving_light";
    rad_scene_desc desc;
    rad_camera cam;
    rad_scene *scene = NULL;
    rad_patch_options po;
    rad_patches *P = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_form_factor_options fo;
    rad_form_factors *ff = NULL;
    rad_alias_tables *tables = NULL;
    rad_temporal_options to;
    rad_temporal *tm = NULL;
    rad_direct_options dopt;
    rad_light light;
    float *Dc, *D, *E, *Em, *L, *B, lo[3] = { 1e30f, 1e30f, 1e30f }, hi[3] = { -1e30f, -1e30f, -1e30f };
    unsigned char *image;
    rad_ray *rays;
    rad_hit *hits;
    uint32_t *pix_patch, n, i, f, c;
    FILE *csv;
    char path[1024];
    double t0, err_sum = 0.0, step_sum = 0.0, err_last = 0.0;

    for (a = 1; a < argc; ++a) {
        const char *o = argv[a], *v = a + 1 < argc ? argv[a + 1] : NULL;
        if (!strcmp(o, "-h") || !strcmp(o, "--help")) usage();
        if (!strcmp(o, "--adaptive")) { adaptive = 1; continue; }
        if (!v) usage();
        ++a;
        if (!strcmp(o, "--patches")) target = (uint32_t)parse_num(o, v, 16, 20000);
        else if (!strcmp(o, "--frames")) frames = (uint32_t)parse_num(o, v, 1, 1e6);
        else if (!strcmp(o, "--every")) every = (uint32_t)parse_num(o, v, 1, 1e6);
        else if (!strcmp(o, "--warmup")) warmup = (uint32_t)parse_num(o, v, 0, 1e6);
        else if (!strcmp(o, "--k")) k = (uint32_t)parse_num(o, v, 1, 4096);
        else if (!strcmp(o, "--w")) w = (float)parse_num(o, v, 0, 0.99999);
        else if (!strcmp(o, "--turns")) turns = (float)parse_num(o, v, 0, 1000);
        else if (!strcmp(o, "--ceiling")) ceiling = (uint32_t)parse_num(o, v, 0, 1);
        else if (!strcmp(o, "--exposure")) exposure = (float)parse_num(o, v, 1e-6, 1e6);
        else if (!strcmp(o, "--seed")) seed = (uint32_t)parse_num(o, v, 0, 4294967295.0);
        else if (!strcmp(o, "-o")) prefix = v;
        else if (!strcmp(o, "--mode")) {
            if (!strcmp(v, "single")) single = 1;
            else if (!strcmp(v, "feedback")) single = 0;
            else usage();
        } else if (!strcmp(o, "--size")) {
            unsigned long x, y;
            char extra;
            if (sscanf(v, "%lux%lu%c", &x, &y, &extra) != 2 || x == 0 || y == 0 || x > 8192 || y > 8192) usage();
            W = (uint32_t)x;
            H = (uint32_t)y;
        } else usage();
    }

    /* ---- once: scene, patches, F, alias tables, the ceiling's direct light ---- */
    rad_cornell_box(&desc, &cam);
    check(rad_scene_create(&desc, NULL, &scene), "rad_scene_create");
    rad_patch_options_default(&po);
    po.target_count = target;
    check(rad_patches_create(scene, &po, NULL, &P), "rad_patches_create");
    n = P->count;
    check(rad_bvh_create(scene, NULL, &bvh), "rad_bvh_create");
    rad_bvh_raycaster(bvh, &rc);
    rad_form_factor_options_default(&fo);
    t0 = now_s();
    check(rad_form_factors_dense(P, &rc, &fo, NULL, &ff), "rad_form_factors_dense");
    printf("%u patches: F in %.2f s", n, now_s() - t0);
    t0 = now_s();
    check(rad_alias_tables_create(&ff->matrix, RAD_ALIAS_AUTO, NULL, &tables), "rad_alias_tables_create");
    printf(", alias tables in %.3f s (%.1f MB)\n", now_s() - t0, (double)rad_alias_tables_memory(tables) / 1e6);

    Dc = (float *)xmalloc(sizeof(float) * 3 * n);
    D = (float *)xmalloc(sizeof(float) * 3 * n);
    E = (float *)xmalloc(sizeof(float) * 3 * n);
    Em = (float *)xmalloc(sizeof(float) * 3 * n);
    L = (float *)xmalloc(sizeof(float) * 3 * n);
    B = (float *)xmalloc(sizeof(float) * 3 * n);
    rad_direct_options_default(&dopt);
    if (ceiling) check(rad_direct_patches(P, &rc, NULL, 0, &dopt, Dc, NULL), "rad_direct_patches (ceiling)");
    else memset(Dc, 0, sizeof(float) * 3 * n);
    check(rad_sources(P, RAD_SOURCE_EMISSION, NULL, Em), "rad_sources (emission)");
    if (!ceiling) memset(Em, 0, sizeof(float) * 3 * n);
    dopt.exclude_emitters = 1; /* per frame: the point light only */

    for (i = 0; i < P->vertex_count; ++i)
        for (c = 0; c < 3; ++c) {
            if (P->vertices[3 * i + c] < lo[c]) lo[c] = P->vertices[3 * i + c];
            if (P->vertices[3 * i + c] > hi[c]) hi[c] = P->vertices[3 * i + c];
        }
    memset(&light, 0, sizeof(light));
    light.type = RAD_LIGHT_POINT;
    light.falloff = RAD_FALLOFF_QUADRATIC;
    /* about as bright as the ceiling light (the jump of tests/bench/temporal.c) */
    light.color[0] = light.color[1] = light.color[2] = 0.05f * (hi[1] - lo[1]) * (hi[1] - lo[1]) * 30.0f;
    light.color[2] *= 0.8f; /* slightly warm, to tell it from the ceiling */

    rad_temporal_options_default(&to);
    to.mode = single ? RAD_TEMPORAL_SINGLE : RAD_TEMPORAL_FEEDBACK;
    to.samples = k;
    to.weight = w > 0.0f ? w : -1.0f; /* --w 0: no history (a weight of 0 is the default) */
    to.adaptive = (int)adaptive;
    to.seed = seed;
    {
        const rad_alias_tables *tc = tables;
        check(rad_temporal_create(&tc, 1, P->albedo, &to, NULL, &tm), "rad_temporal_create");
    }

    /* the camera rays do not change: the patch under each pixel, once */
    image = (unsigned char *)xmalloc((size_t)3 * W * H);
    rays = (rad_ray *)xmalloc(sizeof(rad_ray) * W);
    hits = (rad_hit *)xmalloc(sizeof(rad_hit) * W);
    pix_patch = (uint32_t *)xmalloc(sizeof(uint32_t) * W * H);
    for (i = 0; i < H; ++i) {
        uint32_t x;
        for (x = 0; x < W; ++x) rad_camera_ray(&cam, W, H, (float)x + 0.5f, (float)i + 0.5f, &rays[x]);
        if (rc.intersect(rc.user, rays, W, hits) != RAD_SUCCESS) check(RAD_ERROR_RAYCAST_FAILED, "camera rays");
        for (x = 0; x < W; ++x)
            pix_patch[(size_t)i * W + x] =
                hits[x].triangle == RAD_NONE ? RAD_NONE : rad_patches_locate(P, hits[x].triangle, hits[x].b1, hits[x].b2, NULL);
    }

    snprintf(path, sizeof path, "%s.csv", prefix);
    csv = fopen(path, "w");
    if (!csv) {
        fprintf(stderr, "moving_light: cannot write %s\n", path);
        return 1;
    }
    fprintf(csv, "frame,light_x,light_y,light_z,relative_rms_error,step_ms,exact_ms,mean_w\n");
    printf("mode %s, k %u, %s %.4g, %u warm-up frames, %u frames; exact: %s\n", single ? "single" : "feedback", k,
           adaptive ? "adaptive, w max" : "w", (double)(adaptive ? to.weight_max : w), warmup, frames, single ? "rho o (F E)" : "Gauss-Seidel L_inf to 1e-6");
    printf("frame | light x y z | rel. RMS error | step ms | exact ms | file\n");

    for (f = 0; f < warmup + frames; ++f) {
        /* the warm-up frames keep the light where frame 0 has it and are neither drawn nor counted */
        const uint32_t g = f < warmup ? 0u : f - warmup;
        const double ang = 2.0 * 3.14159265358979 * (double)turns * (double)g / (double)frames;
        double t_step, t_exact, err;
        light.position[0] = 0.5f * (lo[0] + hi[0]) + 0.3f * (hi[0] - lo[0]) * (float)cos(ang);
        light.position[1] = lo[1] + 0.75f * (hi[1] - lo[1]); /* above both blocks, below the ceiling */
        light.position[2] = 0.5f * (lo[2] + hi[2]) + 0.3f * (hi[2] - lo[2]) * (float)sin(ang);

        /* 1-2. E for this frame's light (the warm-up reuses frame 0's) */
        if (f > warmup || f == 0) check(rad_direct_patches(P, &rc, &light, 1, &dopt, D, NULL), "rad_direct_patches (point light)");
        if (f > warmup || f == 0) {
            for (i = 0; i < 3 * n; ++i) D[i] += Dc[i];
            check(rad_sources(P, RAD_SOURCE_DIRECT, D, E), "rad_sources");
        }

        /* 3. the temporal step */
        t0 = now_s();
        check(rad_temporal_step(tm, E, NULL, B), "rad_temporal_step");
        t_step = now_s() - t0;
        if (f < warmup) continue;

        /* 4. the exact indirect light for the same E */
        t0 = now_s();
        if (single) {
            check(rad_matrix_multiply(&ff->matrix, E, L, NULL), "rad_matrix_multiply");
            for (i = 0; i < 3 * n; ++i) L[i] *= P->albedo[i];
        } else {
            rad_system sys;
            rad_solve_options so;
            rad_system_init(&sys, &ff->matrix, P, E);
            rad_solve_options_default(&so);
            so.output = RAD_OUTPUT_INDIRECT;
            so.tolerance = 1e-6;
            check(rad_solve_gauss_seidel(&sys, &so, L, NULL, NULL), "rad_solve_gauss_seidel");
        }
        t_exact = now_s() - t0;
        err = rel_rms(B, L, n);
        err_sum += err;
        step_sum += t_step;
        err_last = err;
        {
            /* the blend weight: fixed, or the mean of the adaptive per-row weights */
            const float *wr = rad_temporal_weights(tm);
            double wm = 0.0;
            if (wr)
                for (i = 0; i < n; ++i) wm += wr[i] / (double)n;
            else
                wm = w;
            fprintf(csv, "%u,%.6g,%.6g,%.6g,%.6f,%.4f,%.4f,%.5f\n", g, (double)light.position[0], (double)light.position[1],
                    (double)light.position[2], err, 1e3 * t_step, 1e3 * t_exact, wm);
        }

        /* 5. the image */
        path[0] = '\0';
        if (g % every == 0 || g + 1 == frames) {
            size_t p;
            for (p = 0; p < (size_t)W * H; ++p) {
                const uint32_t q = pix_patch[p];
                unsigned char *px = image + 3 * p;
                for (c = 0; c < 3; ++c) {
                    const float x = q == RAD_NONE ? 0.0f : (E[3 * q + c] + B[3 * q + c] + Em[3 * q + c]) / 3.14159265f;
                    px[c] = srgb8(exposure * x);
                }
            }
            snprintf(path, sizeof path, "%s_%04u.png", prefix, g);
            if (png_write_rgb8(path, W, H, image, (size_t)3 * W) != 0) {
                fprintf(stderr, "moving_light: cannot write %s\n", path);
                return 1;
            }
        }
        printf("%5u | %6.3f %6.3f %6.3f | %8.4f | %7.3f | %8.2f | %s\n", g, (double)light.position[0], (double)light.position[1],
               (double)light.position[2], err, 1e3 * t_step, 1e3 * t_exact, path);
    }
    fclose(csv);
    printf("mean relative RMS error %.4f (last frame %.4f), mean step %.3f ms; errors in %s.csv\n", err_sum / frames, err_last,
           1e3 * step_sum / frames, prefix);

    free(image); free(rays); free(hits); free(pix_patch);
    free(Dc); free(D); free(E); free(Em); free(L); free(B);
    rad_temporal_destroy(tm);
    rad_alias_tables_destroy(tables);
    rad_form_factors_destroy(ff);
    rad_bvh_destroy(bvh);
    rad_patches_destroy(P);
    rad_scene_destroy(scene);
    return 0;
}

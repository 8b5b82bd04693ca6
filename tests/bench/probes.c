/* probes.c - irradiance probes (docs/methods/probes.md) in the Cornell box against an
   independent irradiance: the direct light of rad_direct_irradiance (analytic emitter, 256
   shadow rays) plus the indirect light by Monte Carlo (16384 stratified cosine rays, each
   bringing the radiosity of the patch it hits: the same patch solution the probes gather).

   Test points: four spheres of radius 0.05 m in the open air of the box, 32 points on each
   (spherical Fibonacci normals). Four ways to read the probes:
     centre probes    one probe at each sphere's centre (user positions), E(n) evaluated there
                      against the reference at the centre: the gather and the L2 band limit
     grid, sampled    the default grid (8 x 8 x 8), rad_probes_sample at the sphere's surface
                      point against the reference at that point: plus the interpolation
   each with the direct light (RAD_PROBES_DIRECT, "total") and without it ("indirect", what an
   engine adds to per-pixel direct light). Also the create and update times and the entries.

   Each of these also with RAD_PROBES_BAND4 (band 4 stored beside L2, rows marked "band 4").

   Build: cc -std=c99 -O2 -fopenmp -I. tests/bench/probes.c -o build/probes -lm
   Run:   probes [--quick] [--detail] [--half-spacing] [--sweep] [--proxy] [--append FILE.md]
          (--detail adds the table of total light, direct included, before the indirect one)
   --proxy adds the points read from probes over AAVP and VP (rad_probes_create_vp) of the box at
   resolution 16 (8 with --quick), against the same classic reference.
   The grid rows come three times: with the default weighting of rad_probes_sample
   (RAD_PROBE_WEIGHT_NORMAL_FIT), with RAD_PROBE_WEIGHT_NORMAL and with RAD_PROBE_WEIGHT_PLAIN
   (trilinear alone); --half-spacing adds grids of spacing 0.035 m (4096 probes, 8x the create
   time); --sweep adds band-4 grids of 12^3 to 24^3 probes, indirect light, with their memory
   (24^3: about 700 MB and 20 s). */
#include "bench_common.h"
#define RADIOSITY_IMPLEMENTATION
#include "../../radiosity.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846
#define SPHERES 4
#define PER 32

static rad_scene *S;
static rad_patches *P;
static rad_raycaster rc;
static float *B;

static void reference(const float *p, const float *n, int direct, uint32_t rays, float out[3])
{
    rad_ray *rr = (rad_ray *)calloc(rays, sizeof(rad_ray));
    rad_hit *hh = (rad_hit *)calloc(rays, sizeof(rad_hit));
    float t1[3], t2[3], a[3] = {1, 0, 0}, D[3] = {0, 0, 0};
    double acc[3] = {0, 0, 0}, l;
    uint32_t k, m = (uint32_t)sqrt((double)rays);
    int c;
    if (fabs(n[0]) > 0.5) { a[0] = 0; a[1] = 1; }
    t1[0] = n[1] * a[2] - n[2] * a[1]; t1[1] = n[2] * a[0] - n[0] * a[2]; t1[2] = n[0] * a[1] - n[1] * a[0];
    l = sqrt(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2]);
    for (c = 0; c < 3; ++c) t1[c] = (float)(t1[c] / l);
    t2[0] = n[1] * t1[2] - n[2] * t1[1]; t2[1] = n[2] * t1[0] - n[0] * t1[2]; t2[2] = n[0] * t1[1] - n[1] * t1[0];
    for (k = 0; k < rays; ++k) {
        uint32_t ia = k % m, ib = k / m;
        double u1 = (ia + 0.5 + 0.4 * sin(7.1 * k)) / m, u2 = (ib + 0.5 + 0.4 * cos(3.3 * k)) / m, r = sqrt(u1), ph = 2 * PI * u2;
        for (c = 0; c < 3; ++c) {
            rr[k].origin[c] = p[c];
            rr[k].dir[c] = (float)(t1[c] * r * cos(ph) + t2[c] * r * sin(ph) + n[c] * sqrt(1.0 - u1));
        }
        rr[k].tmin = 0.0f;
        rr[k].tmax = 1e30f;
    }
    rc.intersect(rc.user, rr, rays, hh);
    for (k = 0; k < rays; ++k) {
        uint32_t t = hh[k].triangle, j;
        float w[3];
        if (t == RAD_NONE) continue;
        if (S->normals[3 * t] * rr[k].dir[0] + S->normals[3 * t + 1] * rr[k].dir[1] + S->normals[3 * t + 2] * rr[k].dir[2] >= 0.0f) continue;
        j = rad_patches_locate(P, t, hh[k].b1, hh[k].b2, w);
        for (c = 0; c < 3; ++c) acc[c] += B[3 * j + c];
    }
    if (direct) {
        rad_direct_options o;
        rad_direct_options_default(&o);
        o.light_samples = 256;
        rad_direct_irradiance(S, &rc, NULL, 0, &o, p, n, 1, D, NULL);
    }
    for (c = 0; c < 3; ++c) out[c] = (float)(acc[c] / (m * m)) + D[c];
    free(rr);
    free(hh);
}

static float pts[SPHERES * PER][3], nrm[SPHERES * PER][3];

static const rad_probe_weighting weightings[3] = {RAD_PROBE_WEIGHT_NORMAL_FIT, RAD_PROBE_WEIGHT_NORMAL, RAD_PROBE_WEIGHT_PLAIN};
static const char *const wnames[3] = {"", " normal", " plain"};
static double g_mb, g_create; /* the last grid_errors grid: memory (MB) and create time (s) */
static uint32_t g_dims[3];

/* relative errors of grid probes read by rad_probes_sample at the test points */
static void grid_errors(const rad_probe_options *o, float (*ref)[3], double *err)
{
    rad_probes *pp = NULL;
    int i, c;
    double t0 = now();
    if (rad_probes_create(P, &rc, NULL, 0, NULL, 0, o, B, NULL, &pp) != RAD_SUCCESS) {
        fprintf(stderr, "probes: create failed\n");
        exit(1);
    }
    g_create = now() - t0;
    /* the create's doc: 40 bytes per entry (76 with band 4), and per probe its position, state,
       offset and 27 coefficients and direct terms (twice that with band 4) */
    g_mb = 1e-6 * ((double)rad_probes_entry_count(pp) * (rad_probes_band4(pp) ? 76.0 : 40.0) +
                   (double)rad_probes_count(pp) * (12.0 + 1.0 + 8.0 + (rad_probes_band4(pp) ? 432.0 : 216.0)));
    rad_probes_grid(pp, g_dims, NULL, NULL);
    for (i = 0; i < SPHERES * PER; ++i) {
        float e[3];
        rad_probes_sample(pp, pts[i], nrm[i], e);
        for (c = 0; c < 3; ++c) err[3 * i + c] = fabs(e[c] - ref[i][c]) / ref[i][c];
    }
    rad_probes_destroy(pp);
}

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static int g_silent; /* report() prints nothing (the total-light rows without --detail) */

/* share within 5%, median and 95th percentile of the relative errors (over points and channels) */
static void report(const char *what, double *err, int n)
{
    int i, within = 0;
    if (g_silent) return;
    for (i = 0; i < n; ++i) within += err[i] <= 0.05;
    qsort(err, (size_t)n, sizeof(double), cmp);
    emit("| %s | %d | %.1f%% | %.2f%% | %.2f%% |\n", what, n, 100.0 * within / n, 100.0 * err[n / 2], 100.0 * err[(n * 95) / 100]);
}

/* --proxy: the same test points read from probes over virtual patches (rad_probes_create_vp)
   of the box at 'resolution', solved as rad render --method aavp (E = rho D with the emitters,
   B = E + L by Gauss-Seidel), against the same reference (the classic patches' Monte Carlo) */
static void proxy_rows(rad_vp_kind kind, uint32_t resolution, float (*ref)[SPHERES * PER][3],
                       float (*cref)[SPHERES * PER][3], const float (*centres)[3], double *err)
{
    rad_vp_options vo;
    rad_virtual_patches *vp = NULL;
    rad_direct_options dopt;
    rad_solve_options so;
    rad_system sys;
    float *Ev, *Bv;
    int mode, band, i, c;
    double t0 = now(), tb;
    char name[128];
    rad_vp_options_default(&vo);
    vo.resolution = resolution;
    vo.kind = kind;
    if (rad_vp_create(S, &rc, &vo, NULL, &vp) != RAD_SUCCESS) { fprintf(stderr, "probes: rad_vp_create failed\n"); exit(1); }
    tb = now() - t0;
    Ev = (float *)malloc(sizeof(float) * 3 * vp->count);
    Bv = (float *)malloc(sizeof(float) * 3 * vp->count);
    rad_direct_options_default(&dopt);
    dopt.exclude_emitters = 0;
    rad_vp_sources(vp, &rc, NULL, 0, &dopt, RAD_SOURCE_DIRECT, Ev, NULL);
    rad_vp_system(&sys, vp, Ev);
    rad_solve_options_default(&so);
    so.output = RAD_OUTPUT_TOTAL;
    rad_solve_gauss_seidel(&sys, &so, Bv, NULL, NULL);
    for (mode = 0; mode < 2; ++mode)
        for (band = 0; band < 2; ++band) {
            rad_probe_options o;
            rad_probes *pc = NULL, *pg = NULL;
            double tc;
            rad_probe_options_default(&o);
            o.flags = (mode == 0 ? RAD_PROBES_DIRECT : 0u) | (band ? RAD_PROBES_BAND4 : 0u);
            rad_probes_create_vp(vp, &rc, NULL, 0, &centres[0][0], SPHERES, &o, Bv, NULL, &pc);
            t0 = now();
            rad_probes_create_vp(vp, &rc, NULL, 0, NULL, 0, &o, Bv, NULL, &pg);
            tc = now() - t0;
            if (!pc || !pg) { fprintf(stderr, "probes: rad_probes_create_vp failed\n"); exit(1); }
            for (i = 0; i < SPHERES * PER; ++i) {
                float e[3];
                if (band) rad_sh_l4_irradiance(rad_probes_coefficients(pc) + 27 * (i / PER), rad_probes_band4(pc) + 27 * (i / PER), nrm[i], e);
                else rad_sh9_irradiance(rad_probes_coefficients(pc) + 27 * (i / PER), nrm[i], e);
                for (c = 0; c < 3; ++c) err[3 * i + c] = fabs(e[c] - cref[mode][i][c]) / cref[mode][i][c];
            }
            snprintf(name, sizeof(name), "%s %u (%u patches), centre probes%s, %s", kind ? "vp" : "aavp", resolution, vp->count,
                     band ? " band 4" : "", mode == 0 ? "total" : "indirect");
            report(name, err, SPHERES * PER * 3);
            for (i = 0; i < SPHERES * PER; ++i) {
                float e[3];
                rad_probes_sample(pg, pts[i], nrm[i], e);
                for (c = 0; c < 3; ++c) err[3 * i + c] = fabs(e[c] - ref[mode][i][c]) / ref[mode][i][c];
            }
            snprintf(name, sizeof(name), "%s %u, grid 8x8x8%s, sampled, %s (create %.2f s, %lu entries)", kind ? "vp" : "aavp",
                     resolution, band ? " band 4" : "", mode == 0 ? "total" : "indirect", tc,
                     (unsigned long)rad_probes_entry_count(pg));
            report(name, err, SPHERES * PER * 3);
            rad_probes_destroy(pc);
            rad_probes_destroy(pg);
        }
    fprintf(stderr, "probes: %s virtual patches at resolution %u built in %.1f s\n", kind ? "vp" : "aavp", resolution, tb);
    free(Ev);
    free(Bv);
    rad_vp_destroy(vp);
}

int main(int argc, char **argv)
{
    static const float centres[SPHERES][3] = {{0.15f, 0.35f, 0.15f}, {0.40f, 0.45f, 0.15f}, {0.278f, 0.25f, 0.10f}, {0.15f, 0.30f, 0.42f}};
    int quick = 0, half = 0, sweep = 0, proxy = 0, detail = 0, a, s, i, c, mode, w;
    char name[128];
    const char *append = NULL;
    rad_scene_desc d;
    rad_patch_options po;
    rad_bvh *bvh;
    rad_form_factors *ff;
    rad_form_factor_options fo;
    rad_system sys;
    rad_solve_options so;
    float *D, *E, ref[2][SPHERES * PER][3], cref[2][SPHERES * PER][3];
    double err[SPHERES * PER * 3];
    uint32_t patches, psamples = 0;
    for (a = 1; a < argc; ++a) {
        if (!strcmp(argv[a], "--quick")) quick = 1;
        else if (!strcmp(argv[a], "--append") && a + 1 < argc) append = argv[++a];
        else if (!strcmp(argv[a], "--patch-samples") && a + 1 < argc) psamples = (uint32_t)atoi(argv[++a]);
        else if (!strcmp(argv[a], "--half-spacing")) half = 1;
        else if (!strcmp(argv[a], "--detail")) detail = 1; /* the total-light table too */
        else if (!strcmp(argv[a], "--sweep")) sweep = 1;
        else if (!strcmp(argv[a], "--proxy")) proxy = 1;
    }
    if (append && !(g_md = fopen(append, "a"))) { perror(append); return 1; }
    patches = quick ? 300 : 1000;
    rad_cornell_box(&d, NULL);
    rad_scene_create(&d, NULL, &S);
    rad_patch_options_default(&po);
    po.target_count = patches;
    rad_patches_create(S, &po, NULL, &P);
    rad_bvh_create(S, NULL, &bvh);
    rad_bvh_raycaster(bvh, &rc);
    rad_form_factor_options_default(&fo);
    if (rad_form_factors_dense(P, &rc, &fo, NULL, &ff) != RAD_SUCCESS) return 1;
    D = (float *)malloc(sizeof(float) * 3 * P->count);
    E = (float *)malloc(sizeof(float) * 3 * P->count);
    B = (float *)malloc(sizeof(float) * 3 * P->count);
    rad_direct_patches(P, &rc, NULL, 0, NULL, D, NULL);
    rad_sources(P, RAD_SOURCE_DIRECT, D, E);
    rad_system_init(&sys, &ff->matrix, P, E);
    rad_solve_options_default(&so);
    so.output = RAD_OUTPUT_TOTAL;
    so.bounces = 64;
    rad_solve_jacobi(&sys, &so, B, NULL, NULL);
    for (s = 0; s < SPHERES; ++s)
        for (i = 0; i < PER; ++i) {
            float *n = nrm[s * PER + i], *p = pts[s * PER + i];
            double z = 1.0 - (2.0 * i + 1.0) / PER, r = sqrt(1.0 - z * z), ph = i * 2.39996322972865332;
            n[0] = (float)(r * cos(ph)); n[1] = (float)(r * sin(ph)); n[2] = (float)z;
            for (c = 0; c < 3; ++c) p[c] = centres[s][c] + 0.05f * n[c];
            for (mode = 0; mode < 2; ++mode) {
                reference(p, n, !mode, 16384, ref[mode][s * PER + i]);
                reference(centres[s], n, !mode, 16384, cref[mode][s * PER + i]);
            }
        }
    emit("\n## Irradiance probes in the Cornell box (target: within 5%% at 95%% of test points)\n\n");
    emit_machine();
    emit("`build/probes%s`: %u patches (direct light as the source, 64 Jacobi bounces), 4 spheres of radius 0.05 m, "
         "32 normals each; reference = rad_direct_irradiance (256 shadow rays) + 16384 cosine rays over the same patch "
         "solution. Relative error per point and channel.\n\n", quick ? " --quick" : "", P->count);
    if (detail) emit("| probes, light | values | within 5%% | median error | 95th percentile |\n|---|---|---|---|---|\n");
    for (mode = 0; mode < 2; ++mode) {
        g_silent = mode == 0 && !detail;
        rad_probe_options o;
        rad_probes *pc = NULL, *pg = NULL;
        double t0, tc, tu;
        rad_probe_options_default(&o);
        o.flags = mode == 0 ? RAD_PROBES_DIRECT : 0u;
        o.patch_samples = psamples;
        rad_probes_create(P, &rc, NULL, 0, &centres[0][0], SPHERES, &o, B, NULL, &pc);
        t0 = now();
        rad_probes_create(P, &rc, NULL, 0, NULL, 0, &o, B, NULL, &pg);
        tc = now() - t0;
        t0 = now();
        for (i = 0; i < 10; ++i) rad_probes_update(pg, B, NULL);
        tu = (now() - t0) / 10.0;
        for (i = 0; i < SPHERES * PER; ++i) {
            float e[3];
            rad_sh9_irradiance(rad_probes_coefficients(pc) + 27 * (i / PER), nrm[i], e);
            for (c = 0; c < 3; ++c) err[3 * i + c] = fabs(e[c] - cref[mode][i][c]) / cref[mode][i][c];
        }
        report(mode == 0 ? "centre probes, total" : "centre probes, indirect", err, SPHERES * PER * 3);
        {
            /* the same probes with band 4 */
            rad_probes *p4 = NULL;
            o.flags |= RAD_PROBES_BAND4;
            rad_probes_create(P, &rc, NULL, 0, &centres[0][0], SPHERES, &o, B, NULL, &p4);
            o.flags &= ~(uint32_t)RAD_PROBES_BAND4;
            for (i = 0; i < SPHERES * PER; ++i) {
                float e[3];
                rad_sh_l4_irradiance(rad_probes_coefficients(p4) + 27 * (i / PER), rad_probes_band4(p4) + 27 * (i / PER), nrm[i], e);
                for (c = 0; c < 3; ++c) err[3 * i + c] = fabs(e[c] - cref[mode][i][c]) / cref[mode][i][c];
            }
            report(mode == 0 ? "centre probes band 4, total" : "centre probes band 4, indirect", err, SPHERES * PER * 3);
            rad_probes_destroy(p4);
        }
        for (i = 0; i < SPHERES * PER; ++i) {
            float e[3];
            rad_probes_sample(pg, pts[i], nrm[i], e);
            for (c = 0; c < 3; ++c) err[3 * i + c] = fabs(e[c] - ref[mode][i][c]) / ref[mode][i][c];
        }
        report(mode == 0 ? "grid 8x8x8, sampled, total" : "grid 8x8x8, sampled, indirect", err, SPHERES * PER * 3);
        /* the same grid read with the other weightings, then all three with band 4 */
        o.weighting = RAD_PROBE_WEIGHT_NORMAL;
        grid_errors(&o, ref[mode], err);
        report(mode == 0 ? "grid 8x8x8, sampled normal, total" : "grid 8x8x8, sampled normal, indirect", err, SPHERES * PER * 3);
        o.weighting = RAD_PROBE_WEIGHT_PLAIN;
        grid_errors(&o, ref[mode], err);
        report(mode == 0 ? "grid 8x8x8, sampled plain, total" : "grid 8x8x8, sampled plain, indirect", err, SPHERES * PER * 3);
        o.flags |= RAD_PROBES_BAND4;
        o.weighting = RAD_PROBE_WEIGHT_NORMAL_FIT;
        grid_errors(&o, ref[mode], err);
        report(mode == 0 ? "grid 8x8x8 band 4, sampled, total" : "grid 8x8x8 band 4, sampled, indirect", err, SPHERES * PER * 3);
        o.weighting = RAD_PROBE_WEIGHT_NORMAL;
        grid_errors(&o, ref[mode], err);
        report(mode == 0 ? "grid 8x8x8 band 4, sampled normal, total" : "grid 8x8x8 band 4, sampled normal, indirect", err,
               SPHERES * PER * 3);
        o.weighting = RAD_PROBE_WEIGHT_PLAIN;
        grid_errors(&o, ref[mode], err);
        report(mode == 0 ? "grid 8x8x8 band 4, sampled plain, total" : "grid 8x8x8 band 4, sampled plain, indirect", err,
               SPHERES * PER * 3);
        o.flags &= ~(uint32_t)RAD_PROBES_BAND4;
        if (half) {
            /* and a grid of half the spacing (8x the probes) */
            o.spacing = 0.035f;
            for (w = 0; w < 3; ++w) {
                o.weighting = weightings[w];
                grid_errors(&o, ref[mode], err);
                snprintf(name, sizeof(name), "grid spacing 0.035 (4096), sampled%s, %s", wnames[w], mode == 0 ? "total" : "indirect");
                report(name, err, SPHERES * PER * 3);
                o.flags |= RAD_PROBES_BAND4;
                grid_errors(&o, ref[mode], err);
                snprintf(name, sizeof(name), "grid spacing 0.035 (4096) band 4, sampled%s, %s", wnames[w], mode == 0 ? "total" : "indirect");
                report(name, err, SPHERES * PER * 3);
                o.flags &= ~(uint32_t)RAD_PROBES_BAND4;
            }
            o.spacing = 0.0f;
        }
        o.weighting = RAD_PROBE_WEIGHT_NORMAL_FIT;
        g_silent = 0;
        if (mode == 0)
            emit("%sGrid of %u probes: create %.2f s, update from a solution %.3f ms (%lu entries), 2 threads.\n\n"
                 "| probes, light | values | within 5%% | median error | 95th percentile |\n|---|---|---|---|---|\n",
                 detail ? "\n" : "", rad_probes_count(pg), tc, 1e3 * tu, (unsigned long)rad_probes_entry_count(pg));
        rad_probes_destroy(pc);
        rad_probes_destroy(pg);
    }
    if (proxy) {
        emit("\nProbes over virtual patches (rad_probes_create_vp, 2048 rays a probe), the same points and reference "
             "(the classic patches' Monte Carlo: the virtual patches' own discretization is part of the error):\n\n"
             "| probes, light | values | within 5%% | median error | 95th percentile |\n|---|---|---|---|---|\n");
        proxy_rows(RAD_VP_AXIS_ALIGNED, quick ? 8u : 16u, ref, cref, centres, err);
        proxy_rows(RAD_VP_CLUSTERED, quick ? 8u : 16u, ref, cref, centres, err);
    }
    if (sweep) {
        /* finer grids, band 4, indirect light: where the target is met, and what it costs */
        static const float spacings[4] = {0.0463f, 0.035f, 0.0278f, 0.0232f};
        rad_probe_options o;
        rad_probe_options_default(&o);
        o.flags = RAD_PROBES_BAND4;
        o.patch_samples = psamples;
        emit("\nFiner grids, band 4, indirect light (memory: weights and coefficients; create: wall time, 2 threads):\n\n"
             "| grid, weighting | values | within 5%% | median error | 95th percentile | memory | create |\n|---|---|---|---|---|---|---|\n");
        for (s = 0; s < 4; ++s)
            for (w = 0; w < 3; ++w) {
                int n = SPHERES * PER * 3, within = 0;
                o.spacing = spacings[s];
                o.weighting = weightings[w];
                grid_errors(&o, ref[1], err);
                for (i = 0; i < n; ++i) within += err[i] <= 0.05;
                qsort(err, (size_t)n, sizeof(double), cmp);
                emit("| %ux%ux%u (%.4f)%s | %d | %.1f%% | %.2f%% | %.2f%% | %.0f MB | %.1f s |\n", g_dims[0], g_dims[1], g_dims[2],
                     (double)spacings[s], w == 0 ? " normal fit (default)" : wnames[w], n, 100.0 * within / n, 100.0 * err[n / 2],
                     100.0 * err[(n * 95) / 100], g_mb, g_create);
            }
    }
    free(D); free(E); free(B);
    rad_form_factors_destroy(ff);
    rad_bvh_destroy(bvh);
    rad_patches_destroy(P);
    rad_scene_destroy(S);
    if (g_md) fclose(g_md);
    return 0;
}

/* lightmap.c - lightmap timings and noise (docs/methods/lightmap.md; docs/performance-notes.md
   "Lightmaps"): the Cornell box with one atlas cell per quad (as examples/lightmap.c).
   Usage: lightmap [--size N] [--patches N] [--refresh-size N] [--refresh-patches N] [--refresh-only 1]
                   [--append FILE.md]
   Prints: texel build, the gather with 1 and 4 visibility rays and the texel-to-texel
   difference between two seeds (the gather's noise), dilation, stitching; then, on a larger
   atlas, the refresh weights and the best of 20 refreshes, in the factored layout of
   rad_lightmap_weights and, side by side, in the expanded texel-from-patch layout it
   replaced (with the largest difference between the two). */
#include "bench_common.h" /* first: it asks for POSIX clock_gettime */
#define RADIOSITY_IMPLEMENTATION
#include "radiosity.h"
#include "bench_scenes.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* the atlas box and its BVH */
static rad_scene *cornell_atlas(uint32_t N, rad_bvh **bvh)
{
    rad_scene *S = bench_cornell_atlas(N);
    if (rad_bvh_create(S, NULL, bvh) != RAD_SUCCESS) exit(1);
    return S;
}

/* the refresh as it was before the factored layout, kept here to measure against: texel-from-
   patch rows over every texel (uint64 offsets), expanded from the factored rows */
typedef struct old_weights {
    uint32_t texels;
    uint64_t *row_offsets;
    uint32_t *columns;
    float *values;
} old_weights;

typedef struct old_job {
    const old_weights *W;
    const float *H;
    float *out;
    uint32_t tasks;
} old_job;

static void old_refresh_task(void *data, uint32_t task)
{
    const old_job *f = (const old_job *)data;
    const old_weights *W = f->W;
    uint32_t t = (uint32_t)((uint64_t)W->texels * task / f->tasks), end = (uint32_t)((uint64_t)W->texels * (task + 1) / f->tasks);
    for (; t < end; ++t) {
        uint64_t a = W->row_offsets[t], b = W->row_offsets[t + 1], e;
        float s0 = 0.0f, s1 = 0.0f, s2 = 0.0f;
        if (a == b) continue;
        for (e = a; e < b; ++e) {
            const float *h = f->H + 3 * (size_t)W->columns[e], w = W->values[e];
            s0 += w * h[0];
            s1 += w * h[1];
            s2 += w * h[2];
        }
        f->out[3 * (size_t)t] = s0;
        f->out[3 * (size_t)t + 1] = s1;
        f->out[3 * (size_t)t + 2] = s2;
    }
}

static void old_expand(const rad_lightmap_weights *w, old_weights *o)
{
    double *acc = (double *)calloc(w->patch_count, sizeof(double));
    uint32_t *touched = (uint32_t *)malloc(sizeof(uint32_t) * w->patch_count), r, t, n;
    uint64_t total = 0, cap = 8 * (uint64_t)w->row_first[w->row_count] + 16;
    o->texels = w->texels;
    o->row_offsets = (uint64_t *)malloc(8 * ((size_t)w->texels + 1));
    o->columns = (uint32_t *)malloc(4 * cap);
    o->values = (float *)malloc(4 * cap);
    if (!acc || !touched || !o->row_offsets || !o->columns || !o->values) exit(1);
    for (t = 0, r = 0; t < w->texels; ++t) {
        uint32_t e, k, m;
        o->row_offsets[t] = total;
        if (r == w->row_count || w->row_texels[r] != t) continue;
        n = 0;
        for (e = w->row_first[r]; e < w->row_first[r + 1]; ++e) {
            uint32_t v = w->entry_vertices[e];
            for (k = w->vertex_first[v]; k < w->vertex_first[v + 1]; ++k) {
                uint32_t p = w->vertex_patches[k];
                for (m = 0; m < n && touched[m] != p; ++m) {}
                if (m == n) touched[n++] = p;
                acc[p] += (double)w->entry_weights[e] * w->vertex_weights[k];
            }
        }
        if (total + n > cap) exit(1);
        for (m = 0; m < n; ++m) { o->columns[total + m] = touched[m]; o->values[total + m] = (float)acc[touched[m]]; acc[touched[m]] = 0.0; }
        total += n;
        ++r;
    }
    o->row_offsets[w->texels] = total;
    free(acc); free(touched);
}

int main(int argc, char **argv)
{
    uint32_t N = 128, target = 600, RN = 1024, Rtarget = 2000, i, vr, k;
    rad_scene *S; rad_bvh *bvh; rad_raycaster rc; rad_patches *P; rad_patch_options po; rad_form_factor_options fo;
    rad_form_factors *ff; rad_system sys; rad_solve_options so; rad_lightmap *lm; rad_lightmap_options lo;
    rad_lightmap_gather_options go; rad_lightmap_seam_stats st; rad_lightmap_weights *w;
    float *E, *B, *H1, *H2, *Hp, *out, *out_old;
    double t, best = 1e30, best_old = 1e30, best_serial = 1e30, worst = 0.0;
    rad_context serial;
    old_weights ow;
    uint32_t refresh_only = 0;
    memset(&serial, 0, sizeof serial);
    serial.task_count = 1;
    int a;
    for (a = 1; a + 1 < argc; a += 2) {
        uint32_t v = (uint32_t)atoi(argv[a + 1]);
        if (!strcmp(argv[a], "--append")) {
            if (!(g_md = fopen(argv[a + 1], "a"))) return fprintf(stderr, "lightmap: cannot open %s\n", argv[a + 1]), 1;
        } else if (!strcmp(argv[a], "--size")) N = v;
        else if (!strcmp(argv[a], "--patches")) target = v;
        else if (!strcmp(argv[a], "--refresh-size")) RN = v;
        else if (!strcmp(argv[a], "--refresh-patches")) Rtarget = v;
        else if (!strcmp(argv[a], "--refresh-only")) refresh_only = v;
    }
    emit("\n## Lightmaps: bake stages and the refresh (tests/bench/lightmap.c)\n\n");
    emit_machine();
    emit("The Cornell box with one atlas cell per quad; the gather's noise is the texel-to-texel difference between two "
         "seeds; the refresh rebuilds the lightmap from a new patch solution (2 threads, and in the calling thread).\n\n"
         "| atlas | stage | time | note |\n|---|---|---|---|\n");
    rad_patch_options_default(&po);
    rad_lightmap_options_default(&lo);
    E = B = H1 = H2 = NULL;
    if (refresh_only) goto refresh;
    S = cornell_atlas(N, &bvh);
    rad_bvh_raycaster(bvh, &rc);
    po.target_count = target;
    rad_form_factor_options_default(&fo);
    if (rad_patches_create(S, &po, NULL, &P) != RAD_SUCCESS || rad_form_factors_dense(P, &rc, &fo, NULL, &ff) != RAD_SUCCESS) return 1;
    E = (float *)malloc(12 * (size_t)P->count); B = (float *)malloc(12 * (size_t)P->count);
    rad_sources(P, RAD_SOURCE_EMISSION, NULL, E); rad_system_init(&sys, &ff->matrix, P, E);
    rad_solve_options_default(&so); so.output = RAD_OUTPUT_TOTAL; rad_solve_gauss_seidel(&sys, &so, B, NULL, NULL);
    lo.width = lo.height = N;
    t = now();
    if (rad_lightmap_create(S, &rc, &lo, NULL, &lm) != RAD_SUCCESS) return 1;
    emit("| %ux%u, %u patches | texels | %.2f s | %u samples, %u valid texels |\n", N, N, P->count, now() - t, lm->sample_count, lm->valid_texels);
    H1 = (float *)calloc(3 * (size_t)N * N, 4); H2 = (float *)calloc(3 * (size_t)N * N, 4);
    for (vr = 1; vr <= 4; vr *= 4) {
        double num = 0.0, den = 0.0;
        rad_lightmap_gather_options_default(&go); go.visibility_rays = vr;
        t = now(); rad_lightmap_gather(lm, P, B, &rc, &go, H1, NULL); t = now() - t;
        go.seed = 12345; rad_lightmap_gather(lm, P, B, &rc, &go, H2, NULL);
        for (i = 0; i < N * N; ++i)
            if (lm->flags[i] & RAD_TEXEL_VALID) { double d = H1[3 * i + 1] - H2[3 * i + 1]; num += d * d; den += H1[3 * i + 1]; }
        emit("| | gather, %u visibility ray%s | %.2f s | seed-to-seed rms difference %.4f of the mean texel |\n", vr, vr > 1 ? "s" : "", t,
               sqrt(num / lm->valid_texels) / (den / lm->valid_texels));
    }
    t = now(); rad_lightmap_dilate(lm, 3, H1, 0, NULL); emit("| | dilate (all passes) | %.4f s | |\n", now() - t);
    t = now(); rad_lightmap_stitch(lm, 3, H1, 0, &st, NULL); emit("| | stitch | %.4f s | %u seams |\n", now() - t, st.seams);
    rad_lightmap_destroy(lm); rad_form_factors_destroy(ff); rad_patches_destroy(P); rad_bvh_destroy(bvh); rad_scene_destroy(S);
refresh:
    /* refresh on a larger atlas: no gather needed (weights without a detail factor) */
    S = cornell_atlas(RN, &bvh);
    rad_bvh_raycaster(bvh, &rc);
    po.target_count = Rtarget;
    if (rad_patches_create(S, &po, NULL, &P) != RAD_SUCCESS) return 1;
    lo.width = lo.height = RN;
    t = now();
    if (rad_lightmap_create(S, &rc, &lo, NULL, &lm) != RAD_SUCCESS) return 1;
    emit("| %ux%u, %u patches | texels | %.2f s | %u samples, %u valid texels |\n", RN, RN, P->count, now() - t, lm->sample_count, lm->valid_texels);
    t = now();
    if (rad_lightmap_weights_create(lm, P, NULL, NULL, NULL, &w) != RAD_SUCCESS) return 1;
    emit("| | refresh weights | %.2f s | %.1f vertex entries per valid texel, %u vertices |\n", now() - t,
           (double)w->row_first[w->row_count] / lm->valid_texels, w->vertex_count);
    old_expand(w, &ow);
    emit("| | expanded texel-from-patch rows (the old layout) | | %.1f patch entries per valid texel |\n",
           (double)ow.row_offsets[ow.texels] / lm->valid_texels);
    Hp = (float *)malloc(12 * (size_t)P->count); out = (float *)calloc(3 * (size_t)RN * RN, 4);
    out_old = (float *)calloc(3 * (size_t)RN * RN, 4);
    for (i = 0; i < 3 * P->count; ++i) Hp[i] = (float)(i % 7) * 0.1f;
    /* interleaved, so both see the same load from other jobs */
    for (k = 0; k < 20; ++k) {
        old_job oj;
        oj.W = &ow; oj.H = Hp; oj.out = out_old; oj.tasks = 64;
        t = now(); rad__parallel_default(NULL, oj.tasks, old_refresh_task, &oj); t = now() - t; if (t < best_old) best_old = t;
        t = now(); rad_lightmap_refresh(w, Hp, out, NULL); t = now() - t; if (t < best) best = t;
        t = now(); rad_lightmap_refresh(w, Hp, out, &serial); t = now() - t; if (t < best_serial) best_serial = t;
    }
    for (i = 0; i < 3 * RN * RN; ++i) {
        double d = fabs((double)out[i] - out_old[i]) / (fabs((double)out_old[i]) > 1e-3 ? fabs((double)out_old[i]) : 1e-3);
        if (d > worst) worst = d;
    }
    emit("| | refresh, old layout (best of 20) | %.2f ms | %.0f MB read |\n", best_old * 1e3,
           (12.0 * ow.texels + 8.0 * (double)ow.row_offsets[ow.texels] + 12.0 * lm->valid_texels) / 1e6);
    emit("| | refresh, factored layout (best of 20) | %.2f ms | %.0f MB read; largest difference from the old %.1e relative |\n",
           best * 1e3, (8.0 * w->row_count + 8.0 * w->row_first[w->row_count] + 12.0 * lm->valid_texels) / 1e6, worst);
    emit("| | refresh, factored layout, task_count 1 (best of 20) | %.2f ms | in the calling thread |\n", best_serial * 1e3);
    free(ow.row_offsets); free(ow.columns); free(ow.values); free(out_old);
    rad_lightmap_weights_destroy(w); rad_lightmap_destroy(lm); rad_patches_destroy(P); rad_bvh_destroy(bvh); rad_scene_destroy(S);
    free(E); free(B); free(H1); free(H2); free(Hp); free(out);
    if (g_md) fclose(g_md);
    return 0;
}

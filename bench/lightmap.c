/* lightmap.c - lightmap timings and noise (docs/methods/lightmap.md; docs/performance-notes.md
   "Lightmaps"): the Cornell box with one atlas cell per quad (as examples/lightmap.c).
   Usage: lightmap [--size N] [--patches N] [--refresh-size N] [--refresh-patches N]
   Prints: texel build, the gather with 1 and 4 visibility rays and the texel-to-texel
   difference between two seeds (the gather's noise), dilation, stitching; then, on a larger
   atlas, the refresh weights and the best of 20 refreshes. */
#define RADIOSITY_IMPLEMENTATION
#include "radiosity.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#define NOW() omp_get_wtime()
#else
#include <time.h>
#define NOW() ((double)clock() / CLOCKS_PER_SEC)
#endif

static rad_scene *cornell_atlas(uint32_t N, rad_bvh **bvh)
{
    static rad_mesh_desc meshes[16];
    static float luv[16][2 * 20]; /* the blocks have 5 quads of 4 vertices */
    rad_scene_desc desc;
    rad_scene *S = NULL;
    uint32_t m, q, i, cell = 0, cells = 6;
    rad_cornell_box(&desc, NULL);
    memcpy(meshes, desc.meshes, sizeof(rad_mesh_desc) * desc.mesh_count);
    for (m = 0; m < desc.mesh_count; ++m) {
        for (q = 0; q < meshes[m].vertex_count / 4; ++q, ++cell) {
            static const float cu[4] = { 0, 1, 1, 0 }, cv[4] = { 0, 0, 1, 1 };
            float x0 = (float)(cell % cells) / cells, y0 = (float)(cell / cells) / cells, g = 1.0f / N, s = 1.0f / cells - 2.0f * g;
            for (i = 0; i < 4; ++i) { luv[m][8 * q + 2 * i] = x0 + g + s * cu[i]; luv[m][8 * q + 2 * i + 1] = y0 + g + s * cv[i]; }
        }
        meshes[m].lightmap_uvs = luv[m];
    }
    desc.meshes = meshes;
    if (rad_scene_create(&desc, NULL, &S) != RAD_SUCCESS || rad_bvh_create(S, NULL, bvh) != RAD_SUCCESS) exit(1);
    return S;
}

int main(int argc, char **argv)
{
    uint32_t N = 128, target = 600, RN = 1024, Rtarget = 2000, i, vr, k;
    rad_scene *S; rad_bvh *bvh; rad_raycaster rc; rad_patches *P; rad_patch_options po; rad_form_factor_options fo;
    rad_form_factors *ff; rad_system sys; rad_solve_options so; rad_lightmap *lm; rad_lightmap_options lo;
    rad_lightmap_gather_options go; rad_lightmap_seam_stats st; rad_lightmap_weights *w;
    float *E, *B, *H1, *H2, *Hp, *out;
    double t, best = 1e30;
    int a;
    for (a = 1; a + 1 < argc; a += 2) {
        uint32_t v = (uint32_t)atoi(argv[a + 1]);
        if (!strcmp(argv[a], "--size")) N = v;
        else if (!strcmp(argv[a], "--patches")) target = v;
        else if (!strcmp(argv[a], "--refresh-size")) RN = v;
        else if (!strcmp(argv[a], "--refresh-patches")) Rtarget = v;
    }
    S = cornell_atlas(N, &bvh);
    rad_bvh_raycaster(bvh, &rc);
    rad_patch_options_default(&po); po.target_count = target;
    rad_form_factor_options_default(&fo);
    if (rad_patches_create(S, &po, NULL, &P) != RAD_SUCCESS || rad_form_factors_dense(P, &rc, &fo, NULL, &ff) != RAD_SUCCESS) return 1;
    E = (float *)malloc(12 * (size_t)P->count); B = (float *)malloc(12 * (size_t)P->count);
    rad_sources(P, RAD_SOURCE_EMISSION, NULL, E); rad_system_init(&sys, &ff->matrix, P, E);
    rad_solve_options_default(&so); so.output = RAD_OUTPUT_TOTAL; rad_solve_gauss_seidel(&sys, &so, B, NULL, NULL);
    rad_lightmap_options_default(&lo); lo.width = lo.height = N;
    t = NOW();
    if (rad_lightmap_create(S, &rc, &lo, NULL, &lm) != RAD_SUCCESS) return 1;
    printf("| %ux%u, %u patches | texels | %.2f s | %u samples, %u valid texels |\n", N, N, P->count, NOW() - t, lm->sample_count, lm->valid_texels);
    H1 = (float *)calloc(3 * (size_t)N * N, 4); H2 = (float *)calloc(3 * (size_t)N * N, 4);
    for (vr = 1; vr <= 4; vr *= 4) {
        double num = 0.0, den = 0.0;
        rad_lightmap_gather_options_default(&go); go.visibility_rays = vr;
        t = NOW(); rad_lightmap_gather(lm, P, B, &rc, &go, H1, NULL); t = NOW() - t;
        go.seed = 12345; rad_lightmap_gather(lm, P, B, &rc, &go, H2, NULL);
        for (i = 0; i < N * N; ++i)
            if (lm->flags[i] & RAD_TEXEL_VALID) { double d = H1[3 * i + 1] - H2[3 * i + 1]; num += d * d; den += H1[3 * i + 1]; }
        printf("| | gather, %u visibility ray%s | %.2f s | seed-to-seed rms difference %.4f of the mean texel |\n", vr, vr > 1 ? "s" : "", t,
               sqrt(num / lm->valid_texels) / (den / lm->valid_texels));
    }
    t = NOW(); rad_lightmap_dilate(lm, 3, H1, 0, NULL); printf("| | dilate (all passes) | %.4f s | |\n", NOW() - t);
    t = NOW(); rad_lightmap_stitch(lm, 3, H1, 0, &st, NULL); printf("| | stitch | %.4f s | %u seams |\n", NOW() - t, st.seams);
    rad_lightmap_destroy(lm); rad_form_factors_destroy(ff); rad_patches_destroy(P); rad_bvh_destroy(bvh); rad_scene_destroy(S);
    /* refresh on a larger atlas: no gather needed (weights without a detail factor) */
    S = cornell_atlas(RN, &bvh);
    rad_bvh_raycaster(bvh, &rc);
    po.target_count = Rtarget;
    if (rad_patches_create(S, &po, NULL, &P) != RAD_SUCCESS) return 1;
    lo.width = lo.height = RN;
    t = NOW();
    if (rad_lightmap_create(S, &rc, &lo, NULL, &lm) != RAD_SUCCESS) return 1;
    printf("| %ux%u, %u patches | texels | %.2f s | %u samples, %u valid texels |\n", RN, RN, P->count, NOW() - t, lm->sample_count, lm->valid_texels);
    t = NOW();
    if (rad_lightmap_weights_create(lm, P, NULL, NULL, NULL, &w) != RAD_SUCCESS) return 1;
    printf("| | refresh weights | %.2f s | %.1f entries per valid texel |\n", NOW() - t, (double)w->row_offsets[w->texels] / lm->valid_texels);
    Hp = (float *)malloc(12 * (size_t)P->count); out = (float *)calloc(3 * (size_t)RN * RN, 4);
    for (i = 0; i < 3 * P->count; ++i) Hp[i] = (float)(i % 7) * 0.1f;
    for (k = 0; k < 20; ++k) { t = NOW(); rad_lightmap_refresh(w, Hp, out, NULL); t = NOW() - t; if (t < best) best = t; }
    printf("| | refresh (best of 20) | %.2f ms | |\n", best * 1e3);
    rad_lightmap_weights_destroy(w); rad_lightmap_destroy(lm); rad_patches_destroy(P); rad_bvh_destroy(bvh); rad_scene_destroy(S);
    free(E); free(B); free(H1); free(H2); free(Hp); free(out);
    return 0;
}

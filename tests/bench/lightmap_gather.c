/* lightmap_gather.c - the lightmap final gather: the hemisphere gather against the exact one
   (docs/methods/lightmap.md; docs/performance-notes.md "Lightmap bake").
   Usage: lightmap_gather [--size N] [--patches N] [--rays N,N,...] [--data DIR]
                          [--bunny-size N] [--bunny-exact-size N] [--bunny-exact-texels N] [--exact 0|1] [--exact-vis N]
   Cornell box (one atlas cell per quad, emission as the source, Gauss-Seidel B = E + L):
   the exact gather and the hemisphere gather with each ray count on an N x N atlas; per valid
   texel the relative difference of the luminance (mean, 95th percentile, max) and the times.
   With the bunny (DIR/stanford-bunny.obj, or $RAD_DATA_DIR): the box without its blocks and
   the bunny scaled to 0.25 m on its floor, unwrapped by the tool's simple unwrap (one patch per
   triangle or smaller, the stochastic Jacobi solution, B = E + L), the same comparison on a
   small atlas (--bunny-exact-size, one sample a texel, only --bunny-exact-texels of its valid
   texels: the exact gather visits ~70 000 patches per sample), then the full bake (texels + hemisphere gather + dilate + stitch) on
   --bunny-size texels, timed (wall and process CPU time: on a shared machine the CPU time
   over the core count is the run's cost on idle cores). LMG_DEBUG=1 in the environment prints
   the texels whose two gathers differ by more than 30%. */
#include "bench_common.h" /* first: it asks for POSIX clock_gettime */
#define RADIOSITY_IMPLEMENTATION
#include "radiosity.h"
#include "bench_scenes.h"
#include "tools/tool.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* CPU time of the process, all threads: on a shared machine the wall time of a parallel run
   mostly measures the other jobs; CPU / cores is what the run costs on idle cores */
static double cpu_now(void)
{
#if defined(CLOCK_PROCESS_CPUTIME_ID)
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
#else
    return (double)clock() / CLOCKS_PER_SEC;
#endif
}

/* the box without its blocks, plus the bunny 0.25 m tall in the middle of the floor */
static rad_scene *bunny_box(const char *path)
{
    rad_scene_desc desc, d2;
    static rad_mesh_desc meshes[32];
    float *bp; uint32_t nv, *bi, nt, v, m, n = 0;
    float lo[3] = { 1e30f, 1e30f, 1e30f }, hi[3] = { -1e30f, -1e30f, -1e30f }, sc;
    rad_scene *S = NULL;
    int k;
    if (!bench_load_obj(path, &bp, &nv, &bi, &nt)) return NULL;
    rad_cornell_box(&desc, NULL);
    for (m = 0; m < desc.mesh_count; ++m)
        if (!desc.meshes[m].name || !strstr(desc.meshes[m].name, "block")) meshes[n++] = desc.meshes[m];
    for (v = 0; v < nv; ++v)
        for (k = 0; k < 3; ++k) { if (bp[3 * v + k] < lo[k]) lo[k] = bp[3 * v + k]; if (bp[3 * v + k] > hi[k]) hi[k] = bp[3 * v + k]; }
    sc = 0.25f / (hi[1] - lo[1]);
    for (v = 0; v < nv; ++v) {
        bp[3 * v] = (bp[3 * v] - 0.5f * (lo[0] + hi[0])) * sc + 0.28f;
        bp[3 * v + 1] = (bp[3 * v + 1] - lo[1]) * sc + 0.0005f;
        bp[3 * v + 2] = (bp[3 * v + 2] - 0.5f * (lo[2] + hi[2])) * sc + 0.30f;
    }
    memset(&meshes[n], 0, sizeof(meshes[n]));
    meshes[n].name = "bunny"; meshes[n].positions = bp; meshes[n].vertex_count = nv;
    meshes[n].indices = bi; meshes[n].triangle_count = nt; meshes[n].material = 0;
    d2 = desc; d2.meshes = meshes; d2.mesh_count = n + 1; d2.flags = RAD_SCENE_SKIP_DEGENERATE;
    if (rad_scene_create(&d2, NULL, &S) != RAD_SUCCESS) return NULL;
    return S;
}

/* a copy of S with the tool's unwrap as its lightmap uv set (one unindexed mesh) */
static rad_scene *unwrapped(const rad_scene *S, uint32_t N, float **uvs_out)
{
    rad_mesh_desc mesh;
    rad_scene_desc desc;
    rad_material *mats = (rad_material *)malloc(sizeof(rad_material) * S->material_count);
    float *uvs = (float *)calloc(6 * (size_t)S->triangle_count, sizeof(float));
    rad_scene *U = NULL;
    uint32_t charts = 0, w = N, h = N;
    if (tool_unwrap("lightmap_gather", "--bunny-size or --bunny-exact-size", S, &w, &h, NULL, uvs, &charts)) exit(1);
    memcpy(mats, S->materials_table, sizeof(rad_material) * S->material_count);
    memset(&mesh, 0, sizeof mesh);
    mesh.name = "unwrapped";
    mesh.positions = S->positions;
    mesh.vertex_count = 3 * S->triangle_count;
    mesh.triangle_count = S->triangle_count;
    mesh.material_ids = S->materials;
    mesh.lightmap_uvs = uvs;
    memset(&desc, 0, sizeof desc);
    desc.meshes = &mesh; desc.mesh_count = 1;
    desc.materials = mats; desc.material_count = S->material_count;
    if (rad_scene_create(&desc, NULL, &U) != RAD_SUCCESS) exit(1);
    *uvs_out = uvs;
    free(mats);
    return U;
}

/* per valid texel: |Y(a) - Y(b)| / Y(b) over texels with Y(b) above 1% of the mean */
static void compare(const rad_lightmap *lm, const float *a, const float *b, double *mean, double *p95, double *mx, double *rms_all)
{
    uint32_t i, n = 0, T = lm->width * lm->height;
    double *e = (double *)malloc(sizeof(double) * (T ? T : 1)), ym = 0.0, num = 0.0;
    uint32_t nv = 0;
    for (i = 0; i < T; ++i)
        if (lm->flags[i] & RAD_TEXEL_VALID) { ym += 0.2126 * b[3 * i] + 0.7152 * b[3 * i + 1] + 0.0722 * b[3 * i + 2]; ++nv; }
    ym /= nv ? nv : 1;
    *mean = *mx = 0.0;
    for (i = 0; i < T; ++i) {
        double ya, yb;
        if (!(lm->flags[i] & RAD_TEXEL_VALID)) continue;
        ya = 0.2126 * a[3 * i] + 0.7152 * a[3 * i + 1] + 0.0722 * a[3 * i + 2];
        yb = 0.2126 * b[3 * i] + 0.7152 * b[3 * i + 1] + 0.0722 * b[3 * i + 2];
        num += (ya - yb) * (ya - yb);
        if (yb < 0.01 * ym) continue;
        e[n] = fabs(ya - yb) / yb;
        if (getenv("LMG_DEBUG") && e[n] > 0.3)
            printf("texel %u at %.4f %.4f %.4f normal %.2f %.2f %.2f: %.4g against %.4g (mean %.4g)\n", i, lm->positions[3 * i],
                   lm->positions[3 * i + 1], lm->positions[3 * i + 2], lm->normals[3 * i], lm->normals[3 * i + 1], lm->normals[3 * i + 2],
                   ya, yb, ym);
        *mean += e[n];
        if (e[n] > *mx) *mx = e[n];
        ++n;
    }
    *mean /= n ? n : 1;
    /* 95th percentile by partial selection sort is too slow; a histogram of 0.1% bins */
    {
        uint32_t hist[2001], c = 0, k;
        memset(hist, 0, sizeof hist);
        for (i = 0; i < n; ++i) hist[e[i] >= 2.0 ? 2000 : (uint32_t)(e[i] * 1000.0)]++;
        *p95 = 2.0;
        for (k = 0; k <= 2000; ++k) { c += hist[k]; if (c >= 0.95 * n) { *p95 = (k + 1) / 1000.0; break; } }
    }
    *rms_all = sqrt(num / (nv ? nv : 1)) / (ym > 0 ? ym : 1);
    free(e);
}

static void solve_classic(const rad_patches *P, const rad_raycaster *rc, float *B)
{
    rad_form_factor_options fo; rad_form_factors *ff; rad_system sys; rad_solve_options so;
    float *E = (float *)malloc(12 * (size_t)P->count);
    rad_form_factor_options_default(&fo);
    if (rad_form_factors_dense(P, rc, &fo, NULL, &ff) != RAD_SUCCESS) exit(1);
    rad_sources(P, RAD_SOURCE_EMISSION, NULL, E); rad_system_init(&sys, &ff->matrix, P, E);
    rad_solve_options_default(&so); so.output = RAD_OUTPUT_TOTAL; rad_solve_gauss_seidel(&sys, &so, B, NULL, NULL);
    rad_form_factors_destroy(ff); free(E);
}

static uint32_t exact_vis = 4;

static void run_compare(const char *name, const rad_lightmap *lm, const rad_patches *P, const float *B, const rad_raycaster *rc,
                        const uint32_t *rays, uint32_t nrays, int exact)
{
    rad_lightmap_gather_options go;
    uint32_t T = lm->width * lm->height, k;
    float *X = (float *)calloc(3 * (size_t)T, 4), *Hh = (float *)calloc(3 * (size_t)T, 4);
    double t, tx = 0.0, mean, p95, mx, rms;
    rad_lightmap_gather_options_default(&go);
    if (exact) {
        go.visibility_rays = exact_vis;
        t = now(); if (rad_lightmap_gather(lm, P, B, rc, &go, X, NULL) != RAD_SUCCESS) exit(1); tx = now() - t;
        printf("| %s, %ux%u, %u patches, %u valid texels | exact, %u visibility rays | %.2f s | | | | |\n", name, lm->width,
               lm->height, P->count, lm->valid_texels, exact_vis, tx);
        go.visibility_rays = 4;
    }
    for (k = 0; k < nrays; ++k) {
        go.method = RAD_LIGHTMAP_GATHER_HEMISPHERE;
        go.hemisphere_rays = rays[k];
        t = now(); if (rad_lightmap_gather(lm, P, B, rc, &go, Hh, NULL) != RAD_SUCCESS) exit(1); t = now() - t;
        if (exact) {
            compare(lm, Hh, X, &mean, &p95, &mx, &rms);
            printf("| | hemisphere, %u rays a texel | %.2f s | %.2f%% | %.2f%% | %.1f%% | %.2f%% |\n", rays[k], t, 100 * mean, 100 * p95,
                   100 * mx, 100 * rms);
        } else {
            printf("| %s, %ux%u, %u patches | hemisphere, %u rays a texel | %.2f s | | | | |\n", name, lm->width, lm->height, P->count,
                   rays[k], t);
        }
    }
    free(X); free(Hh);
}

int main(int argc, char **argv)
{
    uint32_t N = 64, target = 600, BN = 1024, BX = 128, BT = 300, rays[8] = { 64, 256, 1024 }, nrays = 3, i;
    const char *dir = getenv("RAD_DATA_DIR");
    int a, exact = 1;
    rad_scene *S; rad_bvh *bvh; rad_raycaster rc; rad_patches *P; rad_patch_options po;
    rad_lightmap *lm; rad_lightmap_options lo;
    float *B;
    for (a = 1; a + 1 < argc; a += 2) {
        if (!strcmp(argv[a], "--size")) N = (uint32_t)atoi(argv[a + 1]);
        else if (!strcmp(argv[a], "--patches")) target = (uint32_t)atoi(argv[a + 1]);
        else if (!strcmp(argv[a], "--bunny-size")) BN = (uint32_t)atoi(argv[a + 1]);
        else if (!strcmp(argv[a], "--bunny-exact-size")) BX = (uint32_t)atoi(argv[a + 1]);
        else if (!strcmp(argv[a], "--bunny-exact-texels")) BT = (uint32_t)atoi(argv[a + 1]);
        else if (!strcmp(argv[a], "--exact-vis")) exact_vis = (uint32_t)atoi(argv[a + 1]);
        else if (!strcmp(argv[a], "--exact")) exact = atoi(argv[a + 1]);
        else if (!strcmp(argv[a], "--data")) dir = argv[a + 1];
        else if (!strcmp(argv[a], "--rays")) {
            char *p = argv[a + 1];
            for (nrays = 0; nrays < 8 && *p; ++nrays) { rays[nrays] = (uint32_t)strtoul(p, &p, 10); if (*p == ',') ++p; }
        }
    }
    printf("| scene | gather | time | mean rel. diff. | 95th pct. | max | rms / mean texel |\n|---|---|---:|---:|---:|---:|---:|\n");
    if (N) {
        S = bench_cornell_atlas(N);
        if (rad_bvh_create(S, NULL, &bvh) != RAD_SUCCESS) return 1;
        rad_bvh_raycaster(bvh, &rc);
        rad_patch_options_default(&po); po.target_count = target;
        if (rad_patches_create(S, &po, NULL, &P) != RAD_SUCCESS) return 1;
        B = (float *)malloc(12 * (size_t)P->count);
        solve_classic(P, &rc, B);
        rad_lightmap_options_default(&lo); lo.width = lo.height = N;
        if (rad_lightmap_create(S, &rc, &lo, NULL, &lm) != RAD_SUCCESS) return 1;
        run_compare("Cornell", lm, P, B, &rc, rays, nrays, exact);
        rad_lightmap_destroy(lm); rad_patches_destroy(P); rad_bvh_destroy(bvh); rad_scene_destroy(S); free(B);
    }
    if (dir && *dir) {
        char path[4096];
        rad_scene *S0, *U;
        float *uvs;
        rad_stochastic_options sto;
        rad_stochastic_stats sst;
        double t, t0, c0, cb = 0.0, cg = 0.0, cd = 0.0;
        float *E, *H;
        rad_lightmap_gather_options go;
        rad_lightmap_seam_stats st;
        snprintf(path, sizeof path, "%s/stanford-bunny.obj", dir);
        S0 = bunny_box(path);
        if (!S0) { printf("bunny box: %s not read\n", path); return 0; }
        /* the unwrap depends on the atlas size: one scene per size */
        for (a = 0; a < 2; ++a) {
            uint32_t size = a == 0 ? BX : BN;
            if (!size || (a == 0 && !exact)) continue;
            U = unwrapped(S0, size, &uvs);
            if (rad_bvh_create(U, NULL, &bvh) != RAD_SUCCESS) return 1;
            rad_bvh_raycaster(bvh, &rc);
            rad_patch_options_default(&po); po.target_count = 1; /* one patch per triangle at least */
            if (rad_patches_create(U, &po, NULL, &P) != RAD_SUCCESS) return 1;
            E = (float *)malloc(12 * (size_t)P->count); B = (float *)malloc(12 * (size_t)P->count);
            rad_sources(P, RAD_SOURCE_EMISSION, NULL, E);
            rad_stochastic_options_default(&sto); sto.output = RAD_OUTPUT_TOTAL;
            t = now();
            if (rad_solve_stochastic(P, &rc, E, &sto, B, &sst, NULL) != RAD_SUCCESS) return 1;
            printf("| bunny box, %u triangles, %u patches | stochastic Jacobi | %.2f s | %llu rays | | | |\n", U->triangle_count, P->count,
                   now() - t, (unsigned long long)sst.rays_cast);
            fflush(stdout);
            rad_lightmap_options_default(&lo); lo.width = lo.height = size;
            if (a == 0) lo.samples = 1;
            t0 = now(); c0 = cpu_now();
            if (rad_lightmap_create(U, &rc, &lo, NULL, &lm) != RAD_SUCCESS) return 1;
            t = now() - t0; cb = cpu_now() - c0;
            printf("| | texels (rasterize, validity) | %.2f s (CPU %.2f s) | %u samples, %u valid texels | | | |\n", t, cb, lm->sample_count, lm->valid_texels);
            fflush(stdout);
            if (a == 0) {
                /* the exact gather on every texel would visit all patches from each: keep
                   every k-th valid texel (a shallow copy with its own flags and validity) */
                rad_lightmap sub = *lm;
                uint32_t T = lm->width * lm->height, step = lm->valid_texels / (BT ? BT : 1), c = 0, s;
                if (step < 1) step = 1;
                sub.flags = (uint8_t *)malloc(T);
                sub.sample_valid = (uint8_t *)malloc(lm->sample_count);
                memcpy(sub.flags, lm->flags, T);
                memcpy(sub.sample_valid, lm->sample_valid, lm->sample_count);
                for (i = 0; i < T; ++i) {
                    if (!(lm->flags[i] & RAD_TEXEL_VALID)) continue;
                    if (c++ % step == 0) continue;
                    sub.flags[i] &= (uint8_t)~RAD_TEXEL_VALID;
                    for (s = lm->sample_first[i]; s < lm->sample_first[i + 1]; ++s) sub.sample_valid[s] = 0;
                }
                sub.valid_texels = (c + step - 1) / step;
                run_compare("bunny box", &sub, P, B, &rc, rays, nrays, 1);
                free(sub.flags); free(sub.sample_valid);
            } else {
                H = (float *)calloc(3 * (size_t)size * size, 4);
                rad_lightmap_gather_options_default(&go);
                go.method = RAD_LIGHTMAP_GATHER_HEMISPHERE;
                for (i = 0; i < nrays; ++i) {
                    go.hemisphere_rays = rays[i];
                    t = now(); c0 = cpu_now();
                    if (rad_lightmap_gather(lm, P, B, &rc, &go, H, NULL) != RAD_SUCCESS) return 1;
                    cg = cpu_now() - c0;
                    printf("| | hemisphere gather, %u rays a texel | %.2f s (CPU %.2f s) | | | | |\n", rays[i], now() - t, cg);
                    fflush(stdout);
                }
                t = now(); c0 = cpu_now();
                rad_lightmap_dilate(lm, 3, H, 0, NULL);
                rad_lightmap_stitch(lm, 3, H, 0, &st, NULL);
                cd = cpu_now() - c0;
                printf("| | dilate + stitch | %.2f s (CPU %.2f s) | %u seams | | | |\n", now() - t, cd, st.seams);
                printf("| | bake (texels + last gather + dilate + stitch) | CPU %.2f s: %.1f s on 2 idle cores | | | | |\n", cb + cg + cd,
                       (cb + cg + cd) / 2.0);
                free(H);
            }
            rad_lightmap_destroy(lm); rad_patches_destroy(P); rad_bvh_destroy(bvh); rad_scene_destroy(U);
            free(E); free(B); free(uvs);
        }
        rad_scene_destroy(S0);
    }
    return 0;
}

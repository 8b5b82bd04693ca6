/* multibounce.c - the multi-bounce matrix (docs/methods/multibounce.md) against K Jacobi bounces, and its block
   compression, on the built-in Cornell box.

   For each size (about 1.7k and 5.5k patches, rad_patch_options.target_count) the program
   bakes the dense form factors, then reports side by side: apply time (best of 7) of K Jacobi
   bounces (K = 1, 3, 8), of the float and half F_mb for the same K, and of the BC1 and 3xBC4
   forms of F_mb (K = 3 and 8); the bytes each form reads against the plain float F; the
   decoded-matrix MSE with and without greedy reordering (and the ratio); the relative error of
   L = F_mb E for the Cornell E (E = rad_sources(RAD_SOURCE_EMISSION)), max |dL| / max |L|;
   and the build times of F_mb and of each compression.

   Build: cc -O3 -march=native -fopenmp -I. tests/bench/multibounce.c -lm   (make build/multibounce)
   Run:   multibounce [--quick] [--reorder-only] [--append FILE.md]   (--quick: the 1.7k size only;
          --reorder-only: only the table of reordering methods, MSE and build time, no apply timings;
          --reorder-search: a slow local search on the real encoded error from the default ordering, N = 1850,
          to see how far the methods are from it: about 10 minutes on one core)
          multibounce --apply-only [--dense] [--size TARGET] [--cache FILE] [--label TEXT] [--append FILE.md]
            only the apply table: K Jacobi bounces (K = 3, 8) against the BC1 and 3xBC4 forms of
            F_mb (rad_block_options_default), best of 31, with the share
            of the outlier pass. --cache FILE keeps F, E, albedo and the four compressed
            matrices between runs (built when FILE is missing: the O(N^3) steps run once), so
            a second build of this program (e.g. -DRAD_BENCH_HEADER='"old.h"', an older
            radiosity.h) times its apply on the same bytes. --dense adds the float and half
            F_mb (K = 1, 3, 8, built from the cached F) against K Jacobi bounces. */
#include "bench_common.h"
#define RADIOSITY_IMPLEMENTATION
#ifdef RAD_BENCH_HEADER
#include RAD_BENCH_HEADER
#else
#include "../../radiosity.h"
#endif
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <stdarg.h>
#include <time.h>
#ifdef _OPENMP
#include <omp.h>
#endif

static double rel_err(const float *a, const float *b, size_t n)
{
    double d = 0.0, m = 0.0;
    size_t i;
    for (i = 0; i < n; ++i) {
        if (fabs((double)a[i] - b[i]) > d) d = fabs((double)a[i] - b[i]);
        if (fabs((double)b[i]) > m) m = fabs((double)b[i]);
    }
    return m > 0.0 ? d / m : d;
}

#define REPS 31
typedef struct run { const rad_system *sys; const rad_multibounce *mb; const rad_multibounce_blocks *b; uint32_t k; } run;

/* best of REPS, milliseconds */
static double time_it(const run *r, const float *E, float *out)
{
    double best = 1e30;
    int rep;
    for (rep = 0; rep < REPS; ++rep) {
        double t0 = now(), dt;
        if (r->sys) {
            rad_solve_options so;
            rad_solve_options_default(&so);
            so.bounces = r->k;
            rad_solve_jacobi(r->sys, &so, out, NULL, NULL);
        } else if (r->mb) {
            rad_multibounce_apply(r->mb, E, out, RAD_OUTPUT_INDIRECT, NULL);
        } else {
            rad_multibounce_blocks_apply(r->b, E, out, RAD_OUTPUT_INDIRECT, NULL);
        }
        dt = (now() - t0) * 1e3;
        if (dt < best) best = dt;
    }
    return best;
}

/* K = 3 extras: the orderings on a scrambled patch order (F_mb conjugated by a fixed
   pseudo-random permutation, as a mesh without spatial coherence would give), and the
   outlier fraction against bytes and error with the default ordering */
static int scrambled(const rad_multibounce *mb, double t_jac, size_t bytes_f)
{
    static const float fractions[4] = { 0.0f, 0.01f, 0.02f, 0.05f };
    uint32_t n = mb->n, i, j, ch, f, ro, *p = (uint32_t *)malloc(sizeof(uint32_t) * n);
    float *P = (float *)malloc(sizeof(float) * 3 * (size_t)n * n);
    uint64_t st = 12345u;
    rad_multibounce view;
    if (!p || !P) return 1;
    for (i = 0; i < n; ++i) p[i] = i;
    for (i = n - 1; i > 0; --i) {
        uint32_t t;
        st = st * 6364136223846793005ull + 1442695040888963407ull;
        j = (uint32_t)((st >> 33) % (i + 1u));
        t = p[i]; p[i] = p[j]; p[j] = t;
    }
    for (ch = 0; ch < 3; ++ch)
        for (i = 0; i < n; ++i)
            for (j = 0; j < n; ++j) P[(size_t)ch * n * n + (size_t)i * n + j] = mb->planes[(size_t)ch * n * n + (size_t)p[i] * n + p[j]];
    view = *mb;
    view.planes = P;
    view.storage = NULL;
    emit("\nThe same K = 3 matrix with its patch order scrambled (a fixed pseudo-random permutation: a mesh whose patch\n");
    emit("order has no spatial coherence), tile 64:\n\n| form | reorder | MSE | MSE ratio |\n|---|---|---|---|\n");
    for (f = 0; f < 2; ++f) {
        double plain = 0.0;
        for (ro = 0; ro <= RAD_REORDER_MATCH; ++ro) {
            rad_block_options bo;
            rad_block_report rep;
            rad_multibounce_blocks *b = NULL;
            if (ro == RAD_REORDER_GREEDY_2OPT) continue;
            rad_block_options_default(&bo);
            bo.format = f ? RAD_BLOCK_BC4X3 : RAD_BLOCK_BC1;
            bo.reorder = ro ? (int)ro : RAD_REORDER_NONE; /* ro 0: "none" */
            if (rad_multibounce_blocks_create(&view, &bo, NULL, &b, &rep)) return 1;
            if (!ro) plain = rep.mse;
            emit("| %s | %d | %.3g | %.2f |\n", f ? "3xBC4" : "BC1", (int)ro, rep.mse, plain / rep.mse);
            rad_multibounce_blocks_destroy(b);
        }
    }
    free(P);
    free(p);
    emit("\nOutlier fraction (K = 3, tile 64, the default reorder: matching): bytes per outlier = 4 (column) + 12 (exact RGB floats),\n");
    emit("plus 8 (N + 1) bytes of row offsets.\n\n| form | outliers | bytes (MiB) | / float F | of which outliers | MSE | apply ms | vs 3 Jacobi |\n|---|---|---|---|---|---|---|---|\n");
    for (f = 0; f < 2; ++f)
        for (i = 0; i < 4; ++i) {
            rad_block_options bo;
            rad_block_report rep;
            rad_multibounce_blocks *b = NULL;
            run r;
            float *E = (float *)malloc(sizeof(float) * 3 * n), *out = (float *)malloc(sizeof(float) * 3 * n);
            double ta;
            if (!E || !out) return 1;
            for (j = 0; j < 3 * n; ++j) E[j] = (float)((j * 2654435761u) % 1000u) / 1000.0f;
            rad_block_options_default(&bo);
            bo.format = f ? RAD_BLOCK_BC4X3 : RAD_BLOCK_BC1;
            bo.outlier_fraction = fractions[i] > 0.0f ? fractions[i] : -1.0f; /* 0%: no outlier step */
            if (rad_multibounce_blocks_create(mb, &bo, NULL, &b, &rep)) return 1;
            memset(&r, 0, sizeof(r));
            r.b = b;
            ta = time_it(&r, E, out);
            emit("| %s | %g%% | %.1f | %.3f | %.3f | %.3g | %.2f | %.2fx |\n", f ? "3xBC4" : "BC1", 100.0 * fractions[i],
                 (double)rep.bytes_total / 1048576.0, (double)rep.bytes_total / (double)bytes_f, (double)rep.bytes_outliers / (double)bytes_f,
                 rep.mse, ta, t_jac / ta);
            rad_multibounce_blocks_destroy(b);
            free(E);
            free(out);
        }
    emit("\n");
    return 0;
}

static int bench_size(uint32_t target)
{
    rad_scene_desc desc;
    rad_camera cam;
    rad_scene *scene = NULL;
    rad_patches *patches = NULL;
    rad_bvh *bvh = NULL;
    rad_form_factors *ff = NULL;
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_raycaster rc;
    rad_system sys;
    float *E, *ref, *out;
    uint32_t n, ki, f, ro;
    static const uint32_t ks[3] = { 1, 3, 8 };
    double t0, t_ff, t_jac[3], t_build[3], t_float[3], t_half[3], e_float[3], e_half[3];
    size_t n3, bytes_f;
    rad_cornell_box(&desc, &cam);
    rad_patch_options_default(&po);
    po.target_count = target;
    rad_form_factor_options_default(&fo);
    if (rad_scene_create(&desc, NULL, &scene) || rad_patches_create(scene, &po, NULL, &patches) || rad_bvh_create(scene, NULL, &bvh))
        return 1;
    rad_bvh_raycaster(bvh, &rc);
    t0 = now();
    if (rad_form_factors_dense(patches, &rc, &fo, NULL, &ff)) return 1;
    t_ff = now() - t0;
    n = patches->count;
    n3 = 3 * (size_t)n;
    bytes_f = (size_t)n * n * sizeof(float);
    E = (float *)malloc(n3 * sizeof(float));
    ref = (float *)malloc(n3 * sizeof(float));
    out = (float *)malloc(n3 * sizeof(float));
    if (!E || !ref || !out) return 1;
    rad_sources(patches, RAD_SOURCE_EMISSION, NULL, E);
    rad_system_init(&sys, &ff->matrix, patches, E);
    emit("\n### Multi-bounce matrix, Cornell box, N = %u patches\n\n", n);
    emit("Form factors (dense, BVH): %.1f s. Plain float F: %.1f MiB.\n\n", t_ff, (double)bytes_f / 1048576.0);
    for (ki = 0; ki < 3; ++ki) {
        rad_multibounce_options o;
        rad_multibounce *mb = NULL, *h = NULL;
        run r;
        rad_solve_options so;
        memset(&r, 0, sizeof(r));
        r.sys = &sys;
        r.k = ks[ki];
        t_jac[ki] = time_it(&r, E, out);
        rad_solve_options_default(&so);
        so.bounces = ks[ki];
        rad_solve_jacobi(&sys, &so, ref, NULL, NULL);
        rad_multibounce_options_default(&o);
        o.bounces = ks[ki];
        t0 = now();
        if (rad_multibounce_create(&ff->matrix, patches->albedo, &o, NULL, &mb)) return 1;
        t_build[ki] = now() - t0;
        if (rad_multibounce_convert(mb, RAD_MB_HALF, NULL, &h)) return 1;
        memset(&r, 0, sizeof(r));
        r.mb = mb;
        t_float[ki] = time_it(&r, E, out);
        e_float[ki] = rel_err(out, ref, n3);
        r.mb = h;
        t_half[ki] = time_it(&r, E, out);
        e_half[ki] = rel_err(out, ref, n3);
        if (ks[ki] != 1) {
            static const char *const methods[5] = { "none", "greedy chain", "greedy + 2-opt", "2-opt + group swaps",
                                                           "matching + group swaps" };
            if (ki == 1) {
                emit("Compressed forms of F_mb (outliers 5%%). Bytes are what one apply reads (blocks + scales + permutations +\n");
                emit("outliers); MSE of the decoded matrix over 3 N^2 entries; ratio = MSE without reordering / MSE (same form and tile);\n");
                emit("L error = max |dL| / max |L| against K Jacobi bounces; apply and Jacobi times best of %d in this run.\n\n", REPS);
                emit("| K | form | tile | reorder | build s | bytes (MiB) | / float F | MSE | MSE ratio | L error | apply ms | vs K Jacobi |\n");
                emit("|---|---|---|---|---|---|---|---|---|---|---|---|\n");
            }
            for (f = 0; f < 2; ++f) {
                uint32_t tl;
                for (tl = 0; tl < (ki == 1 ? 2u : 1u); ++tl) {
                    double mse_plain = 0.0;
                    for (ro = 0; ro <= RAD_REORDER_MATCH; ++ro) {
                        rad_block_options bo;
                        rad_block_report rep;
                        rad_multibounce_blocks *b = NULL;
                        double tb, ta, e;
                        if (ki != 1 && (ro == RAD_REORDER_GREEDY_2OPT)) continue;
                        rad_block_options_default(&bo);
                        bo.format = f ? RAD_BLOCK_BC4X3 : RAD_BLOCK_BC1;
                        bo.reorder = ro ? (int)ro : RAD_REORDER_NONE; /* ro 0: "none" */
                        bo.reorder_samples = 0;
                        bo.tile = tl ? RAD_BLOCK_WHOLE_MATRIX : 64u;
                        t0 = now();
                        if (rad_multibounce_blocks_create(mb, &bo, NULL, &b, &rep)) return 1;
                        tb = now() - t0;
                        memset(&r, 0, sizeof(r));
                        r.b = b;
                        ta = tl ? 0.0 : time_it(&r, E, out);
                        e = rel_err(out, ref, n3);
                        if (!ro) mse_plain = rep.mse;
                        if (tl)
                            emit("| %u | %s | matrix | %s | %.2f | %.1f | %.3f | %.3g | %.2f | - | - | - |\n", ks[ki], f ? "3xBC4" : "BC1",
                                 methods[ro], tb, (double)rep.bytes_total / 1048576.0, (double)rep.bytes_total / (double)bytes_f,
                                 rep.mse, mse_plain / rep.mse);
                        else
                            emit("| %u | %s | 64 | %s | %.2f | %.1f | %.3f | %.3g | %.2f | %.4f | %.2f | %.2fx |\n", ks[ki], f ? "3xBC4" : "BC1",
                                 methods[ro], tb, (double)rep.bytes_total / 1048576.0, (double)rep.bytes_total / (double)bytes_f, rep.mse,
                                 mse_plain / rep.mse, e, ta, t_jac[ki] / ta);
                        rad_multibounce_blocks_destroy(b);
                    }
                }
            }
            if (ki == 1 && scrambled(mb, t_jac[ki], bytes_f)) return 1;
        }
        rad_multibounce_destroy(mb);
        rad_multibounce_destroy(h);
    }
    emit("\nDense F_mb (float: %.1f MiB = %.0fx F; half: %.1f MiB) against K Jacobi bounces on F, apply times best of %d:\n\n",
         3.0 * (double)bytes_f / 1048576.0, 3.0, 1.5 * (double)bytes_f / 1048576.0, REPS);
    emit("| K | Jacobi ms | F_mb build s | float F_mb ms | speed-up | L error | half F_mb ms | speed-up | L error |\n");
    emit("|---|---|---|---|---|---|---|---|---|\n");
    for (ki = 0; ki < 3; ++ki)
        emit("| %u | %.2f | %.2f | %.2f | %.2fx | %.1e | %.2f | %.2fx | %.1e |\n", ks[ki], t_jac[ki], t_build[ki], t_float[ki],
             t_jac[ki] / t_float[ki], e_float[ki], t_half[ki], t_jac[ki] / t_half[ki], e_half[ki]);
    free(E); free(ref); free(out);
    rad_form_factors_destroy(ff);
    rad_bvh_destroy(bvh);
    rad_patches_destroy(patches);
    rad_scene_destroy(scene);
    return 0;
}

/* --reorder-only: the reordering methods alone (no apply timings), K = 3, tile 64, outliers
   5%: decoded-matrix MSE, ratio to the unreordered MSE and build time of
   rad_multibounce_blocks_create, on the patch order and on a scrambled one (a fixed
   pseudo-random permutation). */
static int reorder_only(uint32_t target)
{
    static const char *const names[RAD_REORDER_MATCH + 1] = { "none", "greedy chain", "greedy + 2-opt", "2-opt + group swaps",
                                                               "matching + group swaps" };
    rad_scene_desc desc;
    rad_camera cam;
    rad_scene *scene = NULL;
    rad_patches *patches = NULL;
    rad_bvh *bvh = NULL;
    rad_form_factors *ff = NULL;
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_raycaster rc;
    rad_multibounce_options mo;
    rad_multibounce *mb = NULL, view;
    float *P;
    uint32_t n, i, j, ch, *p, sc, f, ro;
    uint64_t st = 12345u;
    double t0;
    rad_cornell_box(&desc, &cam);
    rad_patch_options_default(&po);
    po.target_count = target;
    rad_form_factor_options_default(&fo);
    if (rad_scene_create(&desc, NULL, &scene) || rad_patches_create(scene, &po, NULL, &patches) || rad_bvh_create(scene, NULL, &bvh))
        return 1;
    rad_bvh_raycaster(bvh, &rc);
    if (rad_form_factors_dense(patches, &rc, &fo, NULL, &ff)) return 1;
    rad_multibounce_options_default(&mo);
    mo.bounces = 3;
    t0 = now();
    if (rad_multibounce_create(&ff->matrix, patches->albedo, &mo, NULL, &mb)) return 1;
    n = mb->n;
    emit("\n### Reordering methods, Cornell box, N = %u, K = 3 (F_mb built in %.2f s), outliers 5%%, tile 64\n\n", n, now() - t0);
    emit("Build = rad_multibounce_blocks_create (outliers, reordering, scales, encoding), best of 3 on the Cornell order, one run\n");
    emit("on the scrambled one; ratio = MSE without reordering / MSE.\n\n");
    emit("| patch order | form | reorder | build s | MSE | MSE ratio |\n|---|---|---|---|---|---|\n");
    p = (uint32_t *)malloc(sizeof(uint32_t) * n);
    P = (float *)malloc(sizeof(float) * 3 * (size_t)n * n);
    if (!p || !P) return 1;
    for (i = 0; i < n; ++i) p[i] = i;
    for (i = n - 1; i > 0; --i) {
        uint32_t t;
        st = st * 6364136223846793005ull + 1442695040888963407ull;
        j = (uint32_t)((st >> 33) % (i + 1u));
        t = p[i]; p[i] = p[j]; p[j] = t;
    }
    for (ch = 0; ch < 3; ++ch)
        for (i = 0; i < n; ++i)
            for (j = 0; j < n; ++j) P[(size_t)ch * n * n + (size_t)i * n + j] = mb->planes[(size_t)ch * n * n + (size_t)p[i] * n + p[j]];
    view = *mb;
    view.planes = P;
    view.storage = NULL;
    for (sc = 0; sc < 2; ++sc)
        for (f = 0; f < 2; ++f) {
            double plain = 0.0;
            for (ro = 0; ro <= RAD_REORDER_MATCH + 1u; ++ro) { /* the last: matching on 256 sampled coordinates */
                rad_block_options bo;
                rad_block_report rep;
                rad_multibounce_blocks *b = NULL;
                double tb = 1e30;
                int rep_i;
                rad_block_options_default(&bo);
                bo.format = f ? RAD_BLOCK_BC4X3 : RAD_BLOCK_BC1;
                bo.reorder = ro > RAD_REORDER_MATCH ? RAD_REORDER_MATCH : ro ? (int)ro : RAD_REORDER_NONE;
                bo.reorder_samples = ro > RAD_REORDER_MATCH ? 256u : 0u;
                for (rep_i = 0; rep_i < (sc ? 1 : 3); ++rep_i) { /* build time: best of 3 on the patch order */
                    rad_multibounce_blocks_destroy(b);
                    b = NULL;
                    t0 = now();
                    if (rad_multibounce_blocks_create(sc ? &view : mb, &bo, NULL, &b, &rep)) return 1;
                    if (now() - t0 < tb) tb = now() - t0;
                }
                if (!ro) plain = rep.mse;
                emit("| %s | %s | %s | %.2f | %.3g | %.2f |\n", sc ? "scrambled" : "Cornell", f ? "3xBC4" : "BC1",
                     ro > RAD_REORDER_MATCH ? "matching, 256 sampled coordinates" : names[ro], tb, rep.mse, plain / rep.mse);
                rad_multibounce_blocks_destroy(b);
            }
        }
    free(P);
    free(p);
    rad_multibounce_destroy(mb);
    rad_form_factors_destroy(ff);
    rad_bvh_destroy(bvh);
    rad_patches_destroy(patches);
    rad_scene_destroy(scene);
    return 0;
}

/* --reorder-search: how far the reordering methods are from what a slow search on the real
   error finds. From the default ordering (RAD_REORDER_MATCH), each row in turn is swapped
   with each row up to 16 positions away in another group of four whenever re-encoding the
   two block rows involved (tile scales held for the pass) lowers their real squared error;
   then the same for columns; two rounds. Deterministic; minutes at N = 1850. Not a library
   method: too slow for what it gains (see docs/BENCHMARKS.md). */
typedef struct rsearch {
    uint32_t n, bpr, tpr;
    int bc4;
    float *Wp, *scales; /* permuted planes (outliers zeroed), 3 floats per 64-texel tile */
} rsearch;

/* real squared error of block row I with row slot 'slot' holding permuted row 'with' (slot 4: as is) */
static double rs_row_err(const rsearch *s, uint32_t I, uint32_t slot, uint32_t with)
{
    size_t nn = (size_t)s->n * s->n;
    double e = 0.0;
    uint32_t J, t, ch;
    for (J = 0; J < s->bpr; ++J) {
        const float *sc = s->scales + 3 * (size_t)((I * 4u / 64u) * s->tpr + J * 4u / 64u);
        float tex[48], dec[48], val[48];
        uint8_t blk[8];
        for (t = 0; t < 16; ++t) {
            uint32_t y = I * 4u + t / 4u, x = J * 4u + t % 4u, src = t / 4u == slot ? with : y;
            for (ch = 0; ch < 3; ++ch) {
                float v = (y < s->n && x < s->n) ? s->Wp[ch * nn + (size_t)src * s->n + x] : 0.0f;
                val[3 * t + ch] = v;
                tex[3 * t + ch] = sc[ch] > 0.0f ? v / sc[ch] : 0.0f;
            }
        }
        if (!s->bc4) {
            rad_bc1_encode_block(tex, blk);
            rad_bc1_decode_block(blk, dec);
        } else
            for (ch = 0; ch < 3; ++ch) {
                float v[16], d[16];
                for (t = 0; t < 16; ++t) v[t] = tex[3 * t + ch];
                rad_bc4_encode_block(v, blk);
                rad_bc4_decode_block(blk, d);
                for (t = 0; t < 16; ++t) dec[3 * t + ch] = d[t];
            }
        for (t = 0; t < 16; ++t)
            if (I * 4u + t / 4u < s->n && J * 4u + t % 4u < s->n)
                for (ch = 0; ch < 3; ++ch) {
                    double d = (double)(dec[3 * t + ch] * sc[ch] - val[3 * t + ch]);
                    e += d * d;
                }
    }
    return e;
}

/* Wp = W permuted by (rp, cp), and its tile scales */
static void rs_setup(rsearch *s, const float *W, const uint32_t *rp, const uint32_t *cp)
{
    size_t nn = (size_t)s->n * s->n;
    uint32_t ch, i, j;
    memset(s->scales, 0, sizeof(float) * 3 * s->tpr * s->tpr);
    for (ch = 0; ch < 3; ++ch)
        for (i = 0; i < s->n; ++i)
            for (j = 0; j < s->n; ++j) {
                float v = W[ch * nn + (size_t)rp[i] * s->n + cp[j]];
                float *sc = s->scales + 3 * (size_t)((i / 64u) * s->tpr + j / 64u) + ch;
                s->Wp[ch * nn + (size_t)i * s->n + j] = v;
                if (v > *sc) *sc = v;
            }
}

/* one pass of row swaps (columns: call with the transposed planes and the orders exchanged); returns the swaps made */
static uint32_t rs_pass(rsearch *s, const float *W, uint32_t *rp, const uint32_t *cp)
{
    uint32_t full = s->n & ~3u, pa, pb, I, made = 0;
    size_t nn = (size_t)s->n * s->n;
    double *re = (double *)malloc(sizeof(double) * s->bpr);
    if (!re) return 0;
    rs_setup(s, W, rp, cp);
    for (I = 0; I < s->bpr; ++I) re[I] = rs_row_err(s, I, 4u, 0u);
    for (pa = 0; pa < full; ++pa)
        for (pb = pa > 16u ? pa - 16u : 0u; pb < full && pb <= pa + 16u; ++pb) {
            uint32_t A = pa / 4u, B = pb / 4u, ch, j;
            double ea, eb;
            if (A == B) continue;
            ea = rs_row_err(s, A, pa % 4u, pb);
            if (ea - re[A] >= re[B]) continue; /* B cannot fall below zero */
            eb = rs_row_err(s, B, pb % 4u, pa);
            if (ea + eb < (re[A] + re[B]) * (1.0 - 1e-9)) {
                uint32_t t = rp[pa];
                rp[pa] = rp[pb];
                rp[pb] = t;
                for (ch = 0; ch < 3; ++ch)
                    for (j = 0; j < s->n; ++j) {
                        float *x = s->Wp + ch * nn + (size_t)pa * s->n + j, *y = s->Wp + ch * nn + (size_t)pb * s->n + j, q = *x;
                        *x = *y;
                        *y = q;
                    }
                re[A] = ea;
                re[B] = eb;
                ++made;
            }
        }
    free(re);
    return made;
}

static int reorder_search(uint32_t target)
{
    rad_scene_desc desc;
    rad_camera cam;
    rad_scene *scene = NULL;
    rad_patches *patches = NULL;
    rad_bvh *bvh = NULL;
    rad_form_factors *ff = NULL;
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_raycaster rc;
    rad_multibounce_options mo;
    rad_multibounce *mb = NULL;
    uint32_t n, f;
    size_t nn;
    rad_cornell_box(&desc, &cam);
    rad_patch_options_default(&po);
    po.target_count = target;
    rad_form_factor_options_default(&fo);
    if (rad_scene_create(&desc, NULL, &scene) || rad_patches_create(scene, &po, NULL, &patches) || rad_bvh_create(scene, NULL, &bvh))
        return 1;
    rad_bvh_raycaster(bvh, &rc);
    if (rad_form_factors_dense(patches, &rc, &fo, NULL, &ff)) return 1;
    rad_multibounce_options_default(&mo);
    if (rad_multibounce_create(&ff->matrix, patches->albedo, &mo, NULL, &mb)) return 1;
    n = mb->n;
    nn = (size_t)n * n;
    emit("\n### Search on the real error, Cornell box, N = %u, K = 3, outliers 5%%, tile 64\n\n", n);
    emit("| form | step | swaps (rows, columns) | seconds | MSE | MSE ratio |\n|---|---|---|---|---|---|\n");
    for (f = 0; f < 2; ++f) {
        rad_block_options bo;
        rad_block_report rep0, rep;
        rad_multibounce_blocks *b = NULL;
        rsearch s, st;
        float *W = (float *)malloc(sizeof(float) * 3 * nn), *WT = (float *)malloc(sizeof(float) * 3 * nn);
        uint32_t *rp = (uint32_t *)malloc(sizeof(uint32_t) * n), *cp = (uint32_t *)malloc(sizeof(uint32_t) * n), i, j, ch, round;
        uint64_t q;
        if (!W || !WT || !rp || !cp) return 1;
        rad_block_options_default(&bo);
        bo.format = f ? RAD_BLOCK_BC4X3 : RAD_BLOCK_BC1;
        bo.reorder = RAD_REORDER_NONE;
        if (rad_multibounce_blocks_create(mb, &bo, NULL, &b, &rep0)) return 1;
        rad_multibounce_blocks_destroy(b);
        bo.reorder = RAD_REORDER_MATCH;
        if (rad_multibounce_blocks_create(mb, &bo, NULL, &b, &rep)) return 1;
        emit("| %s | matching (the default) | - | - | %.4g | %.3f |\n", f ? "3xBC4" : "BC1", rep.mse, rep0.mse / rep.mse);
        memcpy(W, mb->planes, sizeof(float) * 3 * nn);
        for (i = 0; i < n; ++i)
            for (q = b->outlier_offsets[i]; q < b->outlier_offsets[i + 1]; ++q)
                for (ch = 0; ch < 3; ++ch) W[ch * nn + (size_t)i * n + b->outlier_columns[q]] = 0.0f;
        for (ch = 0; ch < 3; ++ch)
            for (i = 0; i < n; ++i)
                for (j = 0; j < n; ++j) WT[ch * nn + (size_t)j * n + i] = W[ch * nn + (size_t)i * n + j];
        memcpy(rp, b->row_perm, sizeof(uint32_t) * n);
        memcpy(cp, b->col_perm, sizeof(uint32_t) * n);
        rad_multibounce_blocks_destroy(b);
        s.n = n;
        s.bpr = (n + 3u) / 4u;
        s.tpr = (n + 63u) / 64u;
        s.bc4 = (int)f;
        s.Wp = (float *)malloc(sizeof(float) * 3 * nn);
        s.scales = (float *)malloc(sizeof(float) * 3 * s.tpr * s.tpr);
        if (!s.Wp || !s.scales) return 1;
        st = s;
        for (round = 0; round < 2; ++round) {
            double t0 = now(), sse = 0.0;
            uint32_t a = rs_pass(&s, W, rp, cp), c = rs_pass(&st, WT, cp, rp), I;
            rs_setup(&s, W, rp, cp);
            for (I = 0; I < s.bpr; ++I) sse += rs_row_err(&s, I, 4u, 0u);
            emit("| %s | + search round %u | %u, %u | %.0f | %.4g | %.3f |\n", f ? "3xBC4" : "BC1", round + 1u, a, c, now() - t0,
                 sse / (3.0 * (double)nn), rep0.mse * 3.0 * (double)nn / sse);
        }
        free(s.Wp);
        free(s.scales);
        free(W);
        free(WT);
        free(rp);
        free(cp);
    }
    rad_multibounce_destroy(mb);
    rad_form_factors_destroy(ff);
    rad_bvh_destroy(bvh);
    rad_patches_destroy(patches);
    rad_scene_destroy(scene);
    return 0;
}

/* ---- --apply-only: the apply table alone, with a cache of the O(N^3) results ---- */

static const char *const g_apply_names[4] = { "bc1k3", "bc1k8", "bc4k3", "bc4k8" };

static int apply_build(uint32_t target, const char *cache)
{
    rad_scene_desc desc;
    rad_camera cam;
    rad_scene *scene = NULL;
    rad_patches *patches = NULL;
    rad_bvh *bvh = NULL;
    rad_form_factors *ff = NULL;
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_raycaster rc;
    rad_multibounce_blocks *bl[4] = { NULL, NULL, NULL, NULL };
    rad_section sec[4 * RAD_MB_MAX_SECTIONS];
    uint32_t n, cnt = 0, k, f, c;
    size_t bytes;
    void *buf;
    FILE *fp;
    double t0;
    rad_cornell_box(&desc, &cam);
    rad_patch_options_default(&po);
    po.target_count = target;
    rad_form_factor_options_default(&fo);
    if (rad_scene_create(&desc, NULL, &scene) || rad_patches_create(scene, &po, NULL, &patches) || rad_bvh_create(scene, NULL, &bvh))
        return 1;
    rad_bvh_raycaster(bvh, &rc);
    t0 = now();
    if (rad_form_factors_dense(patches, &rc, &fo, NULL, &ff)) return 1;
    n = patches->count;
    fprintf(stderr, "N = %u: form factors %.1f s\n", n, now() - t0);
    {
        float *E = (float *)malloc(sizeof(float) * 3 * n);
        if (!E) return 1;
        rad_sources(patches, RAD_SOURCE_EMISSION, NULL, E);
        fp = fopen(cache, "wb");
        if (!fp) return 1;
        fwrite(&n, sizeof(n), 1, fp);
        fwrite(E, sizeof(float), 3 * (size_t)n, fp);
        fwrite(patches->albedo, sizeof(float), 3 * (size_t)n, fp);
        fwrite(ff->matrix.dense, sizeof(float), (size_t)n * n, fp);
        free(E);
    }
    for (k = 0; k < 2; ++k) {
        rad_multibounce_options o;
        rad_multibounce *mb = NULL;
        rad_multibounce_options_default(&o);
        o.bounces = k ? 8u : 3u;
        t0 = now();
        if (rad_multibounce_create(&ff->matrix, patches->albedo, &o, NULL, &mb)) return 1;
        fprintf(stderr, "F_mb K = %u: %.1f s\n", o.bounces, now() - t0);
        for (f = 0; f < 2; ++f) {
            rad_block_options bo;
            rad_block_options_default(&bo);
            bo.format = f ? RAD_BLOCK_BC4X3 : RAD_BLOCK_BC1;
            t0 = now();
            if (rad_multibounce_blocks_create(mb, &bo, NULL, &bl[2 * f + k], NULL)) return 1;
            fprintf(stderr, "%s: %.1f s\n", g_apply_names[2 * f + k], now() - t0);
            if (rad_multibounce_blocks_sections(bl[2 * f + k], g_apply_names[2 * f + k], sec + cnt, &c)) return 1;
            cnt += c;
        }
        rad_multibounce_destroy(mb);
    }
    if (rad_container_size(sec, cnt, &bytes)) return 1;
    buf = malloc(bytes);
    if (!buf || rad_container_write(sec, cnt, buf, bytes)) return 1;
    fwrite(&bytes, sizeof(bytes), 1, fp);
    fwrite(buf, 1, bytes, fp);
    fclose(fp);
    free(buf);
    for (k = 0; k < 4; ++k) rad_multibounce_blocks_destroy(bl[k]);
    rad_form_factors_destroy(ff);
    rad_bvh_destroy(bvh);
    rad_patches_destroy(patches);
    rad_scene_destroy(scene);
    return 0;
}

/* --dense: float and half F_mb (K = 1, 3, 8) built from the cached F, against K Jacobi bounces */
static int apply_dense(rad_system *sys, rad_matrix *F, const float *albedo, const float *E, float *out, float *ref, int threads)
{
    static const uint32_t ks[3] = { 1u, 3u, 8u };
    uint32_t ki, n = sys->n;
    size_t n3 = 3 * (size_t)n;
    emit("\nDense F_mb, N = %u, %d thread%s, best of %d (float F_mb: %.1f MiB = 3x F; half: %.1f MiB); L error = max |dL| / max |L|:\n\n",
         n, threads, threads == 1 ? "" : "s", REPS, 12.0 * n * n / 1048576.0, 6.0 * n * n / 1048576.0);
    emit("| K | Jacobi ms | F_mb build s | float F_mb ms | speed-up | L error | half F_mb ms | speed-up | L error |\n");
    emit("|---|---|---|---|---|---|---|---|---|\n");
    for (ki = 0; ki < 3; ++ki) {
        rad_multibounce_options o;
        rad_multibounce *mb = NULL, *h = NULL;
        rad_solve_options so;
        run r;
        double tj, tb, tf, th, ef, eh, t0;
        memset(&r, 0, sizeof(r));
        r.sys = sys;
        r.k = ks[ki];
        tj = time_it(&r, E, out);
        rad_solve_options_default(&so);
        so.bounces = ks[ki];
        rad_solve_jacobi(sys, &so, ref, NULL, NULL);
        rad_multibounce_options_default(&o);
        o.bounces = ks[ki];
        t0 = now();
        if (rad_multibounce_create(F, albedo, &o, NULL, &mb)) return 1;
        tb = now() - t0;
        if (rad_multibounce_convert(mb, RAD_MB_HALF, NULL, &h)) return 1;
        memset(&r, 0, sizeof(r));
        r.mb = mb;
        tf = time_it(&r, E, out);
        ef = rel_err(out, ref, n3);
        r.mb = h;
        th = time_it(&r, E, out);
        eh = rel_err(out, ref, n3);
        emit("| %u | %.2f | %.1f | %.2f | %.2fx | %.1e | %.2f | %.2fx | %.1e |\n", ks[ki], tj, tb, tf, tj / tf, ef, th, tj / th, eh);
        rad_multibounce_destroy(h);
        rad_multibounce_destroy(mb);
    }
    return 0;
}

static int apply_only(uint32_t target, const char *cache, const char *label, int threads, int dense)
{
    FILE *fp;
    uint32_t n, k, f;
    float *E, *albedo, *Fd, *out, *ref;
    size_t bytes, n3;
    void *buf;
    rad_container *ct = NULL;
    rad_matrix F;
    rad_system sys;
    double t_jac[2];
    char tmp[256];
    if (!cache) {
        snprintf(tmp, sizeof(tmp), "/tmp/rad_mb_apply_%u.bin", target);
        cache = tmp;
    }
    fp = fopen(cache, "rb");
    if (!fp) {
        if (apply_build(target, cache)) { fprintf(stderr, "building the cache failed\n"); return 1; }
        fp = fopen(cache, "rb");
        if (!fp) return 1;
    }
    if (fread(&n, sizeof(n), 1, fp) != 1) return 1;
    n3 = 3 * (size_t)n;
    E = (float *)malloc(sizeof(float) * n3);
    albedo = (float *)malloc(sizeof(float) * n3);
    out = (float *)malloc(sizeof(float) * n3);
    ref = (float *)malloc(sizeof(float) * n3);
    Fd = (float *)malloc(sizeof(float) * (size_t)n * n);
    if (!E || !albedo || !out || !ref || !Fd) return 1;
    if (fread(E, sizeof(float), n3, fp) != n3 || fread(albedo, sizeof(float), n3, fp) != n3 ||
        fread(Fd, sizeof(float), (size_t)n * n, fp) != (size_t)n * n || fread(&bytes, sizeof(bytes), 1, fp) != 1)
        return 1;
    buf = malloc(bytes);
    if (!buf || fread(buf, 1, bytes, fp) != bytes) return 1;
    fclose(fp);
    if (rad_container_create(buf, bytes, NULL, &ct)) return 1;
    memset(&F, 0, sizeof(F));
    F.rows = F.cols = n;
    F.storage = RAD_STORAGE_DENSE;
    F.dense = Fd;
    memset(&sys, 0, sizeof(sys));
    sys.F = &F;
    sys.albedo = albedo;
    sys.E = E;
    sys.n = n;
    emit("\n%s, N = %u, %d thread%s (OMP_NUM_THREADS), best of %d; L error = max |dL| / max |L| against K Jacobi bounces:\n\n",
         label ? label : "apply", n, threads, threads == 1 ? "" : "s", REPS);
    emit("| form | K | bytes (MiB) | apply ms | of which outliers ms | K Jacobi ms | speed-up | L error |\n|---|---|---|---|---|---|---|---|\n");
    for (k = 0; k < 2; ++k) {
        run r;
        memset(&r, 0, sizeof(r));
        r.sys = &sys;
        r.k = k ? 8u : 3u;
        t_jac[k] = time_it(&r, E, out);
    }
    for (f = 0; f < 2; ++f)
        for (k = 0; k < 2; ++k) {
            rad_multibounce_blocks *b = NULL, nob;
            rad_solve_options so;
            run r;
            double ta, to, e;
            size_t blocks = (size_t)((n + 3) / 4) * ((n + 3) / 4) * 8 * (f ? 3 : 1), other;
            if (rad_multibounce_blocks_load(ct, g_apply_names[2 * f + k], NULL, &b)) return 1;
            rad_solve_options_default(&so);
            so.bounces = k ? 8u : 3u;
            rad_solve_jacobi(&sys, &so, ref, NULL, NULL);
            memset(&r, 0, sizeof(r));
            r.b = b;
            ta = time_it(&r, E, out);
            e = rel_err(out, ref, n3);
            /* the same without the outliers: the difference is the outlier pass */
            nob = *b;
            nob.outlier_count = 0;
            nob.outlier_offsets = NULL;
            nob.outlier_columns = NULL;
            nob.outlier_values = NULL;
            r.b = &nob;
            to = ta - time_it(&r, E, out);
            other = (size_t)b->tiles_per_row * b->tiles_per_row * 12 + (b->row_perm ? 8 * (size_t)n : 0) +
                    (b->outlier_count ? 8 * ((size_t)n + 1) + 16 * (size_t)b->outlier_count : 0);
            emit("| %s | %u | %.1f | %.3f | %.3f | %.3f | %.2fx | %.1e |\n", f ? "3xBC4" : "BC1", so.bounces,
                 (double)(blocks + other) / 1048576.0, ta, to, t_jac[k], t_jac[k] / ta, e);
            rad_multibounce_blocks_destroy(b);
        }
    if (dense && apply_dense(&sys, &F, albedo, E, out, ref, threads)) return 1;
    rad_container_destroy(ct);
    free(buf); free(E); free(albedo); free(out); free(ref); free(Fd);
    return 0;
}

int main(int argc, char **argv)
{
    int i, quick = 0, threads = 1, reorder = 0, apply = 0, dense = 0;
    uint32_t size = 1736;
    const char *cache = NULL, *label = NULL;
    for (i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--quick")) quick = 1;
        else if (!strcmp(argv[i], "--apply-only")) apply = 1;
        else if (!strcmp(argv[i], "--dense")) dense = 1;
        else if (!strcmp(argv[i], "--size") && i + 1 < argc) size = (uint32_t)strtoul(argv[++i], NULL, 10);
        else if (!strcmp(argv[i], "--cache") && i + 1 < argc) cache = argv[++i];
        else if (!strcmp(argv[i], "--label") && i + 1 < argc) label = argv[++i];
        else if (!strcmp(argv[i], "--reorder-only")) reorder = 1;
        else if (!strcmp(argv[i], "--reorder-search")) reorder = 2;
        else if (!strcmp(argv[i], "--append") && i + 1 < argc) {
            g_md = fopen(argv[++i], "a");
            if (!g_md) { fprintf(stderr, "cannot open %s\n", argv[i]); return 1; }
        }
    }
#ifdef _OPENMP
    threads = omp_get_max_threads();
#endif
    if (apply) {
        int r = apply_only(size, cache, label, threads, dense);
        if (g_md) fclose(g_md);
        return r;
    }
    if (reorder) {
        emit("\n## Multi-bounce compression: reordering methods\n\nCPU, %d threads.\n", threads);
        emit("\n");
        emit_machine();
        if (reorder == 2) {
            if (reorder_search(1736)) return 1;
        } else {
            if (reorder_only(1736)) return 1;
            if (!quick && reorder_only(5485)) return 1;
        }
        if (g_md) fclose(g_md);
        return 0;
    }
    emit("\n## Multi-bounce matrix and block compression\n\nCPU, %d threads; Jacobi = rad_solve_jacobi (dense F, one pass per bounce).\n", threads);
    emit("\n");
    emit_machine();
    if (bench_size(1736)) return 1;
    if (!quick && bench_size(5485)) return 1;
    if (g_md) fclose(g_md);
    return 0;
}

/* temporal.c - temporal radiosity (docs/methods/temporal.md) against the dense gather, side by side
   with Table 1 of Shcherbakov 2025 (RTX 3060; docs/references.md), plus the lag and noise of the adaptive blend weight.

   For the Cornell box cut into about 1736, 5485, 8786 and 10422 patches (actual N reported;
   --quick: the two smaller sizes only): dense form factors, alias tables (compact format),
   E = rho * direct light of the ceiling emitter. Per size:
   - per-frame time on one thread of rad_temporal_step (single bounce, k = 10 and k = 64;
     median of 200 frames) against one dense RGB matrix-vector product rad_matrix_multiply (median of 20),
     and their ratio;
   - relative RMS error against the exact single bounce rho o (F E) after 3000 warm-up frames
     at w = 0.998 (mean over 100 further frames of the per-frame error);
   - lag after a light jump (a point light switched on at frame 3000): frames until the
     projection of B onto the change reaches 90% of the exact change and stays 5 frames, and
     the steady noise before the jump, for fixed w = 0.998 and the adaptive weight.
   Writes the error-against-frame series of the largest size to temporal_error.csv (or the
   --csv path); if gnuplot is on the PATH, also temporal_error.png.

   Build: cc -std=c99 -O3 -march=native -fopenmp -I. tests/bench/temporal.c -o temporal -lm
   Run:   temporal [--quick] [--detail] [--sizes N,N,...] [--append FILE.md] [--csv FILE.csv]
          (--detail adds the tables of where the step's time goes, ns per draw and huge pages, and
          of the memory of F, its CSR form and the tables, and the lag after a light jump)
          (--sizes: up to four patch-count targets instead of the published four; tools/report.sh) */
#include "bench_common.h"
#define RADIOSITY_IMPLEMENTATION
#include "../../radiosity.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#ifdef _OPENMP
#include <omp.h>
#endif

static void die(rad_result r, const char *what)
{
    if (r == RAD_SUCCESS) return;
    fprintf(stderr, "%s: %s\n", what, rad_result_string(r));
    exit(1);
}

/* timings run on one thread (the machine this was written on is shared: more stable) */
static void serial_for(void *user, uint32_t count, rad_task_fn fn, void *data)
{
    uint32_t i;
    (void)user;
    for (i = 0; i < count; ++i) fn(data, i);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof(double), cmp_double);
    return v[n / 2];
}

static double rel_rms(const float *a, const float *b, uint32_t n)
{
    double num = 0.0, den = 0.0;
    size_t i;
    for (i = 0; i < 3 * (size_t)n; ++i) {
        num += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
        den += (double)b[i] * b[i];
    }
    return sqrt(num / den);
}

/* fraction of the change La -> Lb that B has made */
static double progress(const float *B, const float *La, const float *Lb, uint32_t n)
{
    double num = 0.0, den = 0.0;
    size_t i;
    for (i = 0; i < 3 * (size_t)n; ++i) {
        num += ((double)B[i] - La[i]) * ((double)Lb[i] - La[i]);
        den += ((double)Lb[i] - La[i]) * ((double)Lb[i] - La[i]);
    }
    return num / den;
}

/* kB of transparent huge pages backing the mapping that holds p (Linux /proc/self/smaps; -1
   elsewhere) */
static long huge_kb(const void *p)
{
#if defined(__linux__)
    FILE *f = fopen("/proc/self/smaps", "r");
    char line[512];
    int inside = 0;
    long kb = -1;
    if (!f) return -1;
    while (fgets(line, sizeof(line), f)) {
        unsigned long lo, hi;
        if (sscanf(line, "%lx-%lx ", &lo, &hi) == 2) { /* a mapping's first line */
            if (inside) break;
            inside = (uintptr_t)p >= lo && (uintptr_t)p < hi;
        } else if (inside && sscanf(line, "AnonHugePages: %ld kB", &kb) == 1) {
            break;
        }
    }
    fclose(f);
    return kb;
#else
    (void)p;
    return -1;
#endif
}

/* median per-frame time of 'frames' steps after 'warm' frames */
static double time_steps(const rad_alias_tables *t, const float *albedo, const float *E, uint32_t k, const rad_context *ctx,
                         uint32_t warm, uint32_t frames, double *times)
{
    rad_temporal_options o;
    rad_temporal *tm = NULL;
    uint32_t fr;
    double t0;
    rad_temporal_options_default(&o);
    o.samples = k;
    die(rad_temporal_create(&t, 1, albedo, &o, ctx, &tm), "rad_temporal_create");
    for (fr = 0; fr < warm + frames; ++fr) {
        t0 = now();
        rad_temporal_step(tm, E, NULL, NULL);
        if (fr >= warm) times[fr - warm] = now() - t0;
    }
    rad_temporal_destroy(tm);
    return median(times, (int)frames);
}

typedef struct lag_result { uint32_t lag; double noise; } lag_result;

/* 3000 frames of Ea, then Eb; errors[frame] (frames 2500..4500) when series != NULL */
static lag_result lag_run(const rad_alias_tables *t, const rad_patches *P, const float *Ea, const float *Eb, const float *La,
                          const float *Lb, int adaptive, float target, double *series)
{
    rad_temporal_options o;
    rad_temporal *tm = NULL;
    lag_result res;
    uint32_t fr, ok = 0, n = P->count, jump = 3000, end = 4500;
    float *out = (float *)malloc(sizeof(float) * 3 * n);
    res.lag = 0xFFFFFFFFu;
    res.noise = 0.0;
    rad_temporal_options_default(&o);
    o.samples = 10;
    o.adaptive = adaptive;
    o.noise_target = target;
    die(rad_temporal_create(&t, 1, P->albedo, &o, NULL, &tm), "rad_temporal_create");
    for (fr = 0; fr < end; ++fr) {
        rad_temporal_step(tm, fr < jump ? Ea : Eb, NULL, out);
        if (fr >= jump - 200 && fr < jump) res.noise += rel_rms(out, La, n) / 200.0;
        if (series && fr >= 2500) series[fr - 2500] = rel_rms(out, fr < jump ? La : Lb, n);
        if (fr >= jump && res.lag == 0xFFFFFFFFu) {
            if (progress(out, La, Lb, n) >= 0.9) { if (++ok == 5) res.lag = fr - jump + 1 - 4; }
            else ok = 0;
        }
        if (!series && res.lag != 0xFFFFFFFFu) break;
    }
    rad_temporal_destroy(tm);
    free(out);
    return res;
}

int main(int argc, char **argv)
{
    static const uint32_t published_sizes[4] = { 1736, 5485, 8786, 10422 };
    uint32_t targets[4] = { 1736, 5485, 8786, 10422 };
    int custom = 0;
    static const double published_temporal[4] = { 0.02, 0.04, 0.06, 0.08 }, published_mv[4] = { 0.34, 2.94, 7.34, 12.01 };
    const char *csv_path = "temporal_error.csv";
    int quick = 0, detail = 0, a, s, sizes, threads = 1;
    char rows_t1[4][512], rows_lag[4][512], rows_mem[4][256], rows_draw[4][256];
    double *series_f = NULL, *series_a = NULL;
    uint32_t series_n = 0;
    for (a = 1; a < argc; ++a) {
        if (!strcmp(argv[a], "--quick")) quick = 1;
        else if (!strcmp(argv[a], "--detail")) detail = 1;
        else if (!strcmp(argv[a], "--append") && a + 1 < argc) g_md = fopen(argv[++a], "a");
        else if (!strcmp(argv[a], "--csv") && a + 1 < argc) csv_path = argv[++a];
        else if (!strcmp(argv[a], "--sizes") && a + 1 < argc) {
            /* patch-count targets instead of the published four (tools/report.sh --quick) */
            const char *p = argv[++a];
            char *end;
            custom = 0;
            while (*p && custom < 4) {
                unsigned long v = strtoul(p, &end, 10);
                if (end == p || v < 16 || v > 20000) break;
                targets[custom++] = (uint32_t)v;
                p = *end == ',' ? end + 1 : end;
            }
            if (custom == 0 || *p) { fprintf(stderr, "--sizes wants 1 to 4 patch counts in 16..20000, e.g. 300,600\n"); return 2; }
        }
        else { fprintf(stderr, "usage: temporal [--quick] [--sizes N,N,...] [--append FILE.md] [--csv FILE.csv]\n"); return 2; }
    }
#ifdef _OPENMP
    threads = omp_get_max_threads();
#endif
    sizes = custom ? custom : quick ? 2 : 4;
    for (s = 0; s < sizes; ++s) {
        rad_scene_desc desc;
        rad_scene *scene = NULL;
        rad_patch_options po;
        rad_patches *P = NULL;
        rad_bvh *bvh = NULL;
        rad_raycaster rc;
        rad_form_factor_options fo;
        rad_form_factors *ff = NULL;
        rad_direct_options dopt;
        rad_light light;
        rad_alias_tables *t = NULL;
        rad_temporal *tm = NULL;
        rad_temporal_options o;
        uint32_t n, i, fr, k, nnz;
        float *D, *Ea, *Eb, *La, *Lb, *out;
        double t0, tff, ttab, tmv, tstep[2], err[2], times[200];
        lag_result lf, la, la2;
        rad_context tctx;
        int r;

        rad_cornell_box(&desc, NULL);
        die(rad_scene_create(&desc, NULL, &scene), "rad_scene_create");
        rad_patch_options_default(&po);
        po.target_count = targets[s];
        die(rad_patches_create(scene, &po, NULL, &P), "rad_patches_create");
        n = P->count;
        die(rad_bvh_create(scene, NULL, &bvh), "rad_bvh_create");
        rad_bvh_raycaster(bvh, &rc);
        rad_form_factor_options_default(&fo);
        fprintf(stderr, "N = %u: form factors...\n", n);
        t0 = now();
        die(rad_form_factors_dense(P, &rc, &fo, NULL, &ff), "rad_form_factors_dense");
        tff = now() - t0;
        t0 = now();
        die(rad_alias_tables_create(&ff->matrix, RAD_ALIAS_AUTO, NULL, &t), "rad_alias_tables_create");
        ttab = now() - t0;
        nnz = (uint32_t)(t->row_offsets[n] - n);
        {
            uint64_t bins = t->row_offsets[n];
            snprintf(rows_mem[s], sizeof(rows_mem[s]), "| %u | %.1f%% | %.1f MB | %.1f MB | %.1f MB | %u B | %.2f | %.1f s | %.2f s |\n", n,
                     100.0 * (double)nnz / ((double)n * n), 4.0 * n * (double)n / 1e6, 8.0 * nnz / 1e6,
                     (double)rad_alias_tables_memory(t) / 1e6, 4u * (uint32_t)t->format,
                     (double)rad_alias_tables_memory(t) / ((double)bins), tff, ttab);
        }
        D = (float *)malloc(sizeof(float) * 3 * n);
        Ea = (float *)malloc(sizeof(float) * 3 * n);
        Eb = (float *)malloc(sizeof(float) * 3 * n);
        La = (float *)malloc(sizeof(float) * 3 * n);
        Lb = (float *)malloc(sizeof(float) * 3 * n);
        out = (float *)malloc(sizeof(float) * 3 * n);
        rad_direct_options_default(&dopt);
        die(rad_direct_patches(P, &rc, NULL, 0, &dopt, D, NULL), "rad_direct_patches");
        die(rad_sources(P, RAD_SOURCE_DIRECT, D, Ea), "rad_sources");
        /* the jump: a point light switched on low in the left half of the box */
        memset(&light, 0, sizeof(light));
        light.type = RAD_LIGHT_POINT;
        light.color[0] = light.color[1] = light.color[2] = 30.0f;
        {
            /* position relative to the scene bounds */
            float lo[3] = { 1e30f, 1e30f, 1e30f }, hi[3] = { -1e30f, -1e30f, -1e30f };
            uint32_t v, c;
            for (v = 0; v < P->vertex_count; ++v)
                for (c = 0; c < 3; ++c) {
                    if (P->vertices[3 * v + c] < lo[c]) lo[c] = P->vertices[3 * v + c];
                    if (P->vertices[3 * v + c] > hi[c]) hi[c] = P->vertices[3 * v + c];
                }
            light.position[0] = lo[0] + 0.25f * (hi[0] - lo[0]);
            light.position[1] = lo[1] + 0.3f * (hi[1] - lo[1]);
            light.position[2] = lo[2] + 0.5f * (hi[2] - lo[2]);
            /* intensity scaled so the new light is comparable to the ceiling light */
            for (c = 0; c < 3; ++c) light.color[c] = 0.05f * (hi[1] - lo[1]) * (hi[1] - lo[1]) * 30.0f;
        }
        die(rad_direct_patches(P, &rc, &light, 1, &dopt, D, NULL), "rad_direct_patches (point)");
        die(rad_sources(P, RAD_SOURCE_DIRECT, D, Eb), "rad_sources");
        /* exact single bounce before and after */
        die(rad_matrix_multiply(&ff->matrix, Ea, La, NULL), "rad_matrix_multiply");
        die(rad_matrix_multiply(&ff->matrix, Eb, Lb, NULL), "rad_matrix_multiply");
        for (i = 0; i < 3 * n; ++i) { La[i] *= P->albedo[i]; Lb[i] *= P->albedo[i]; }
        /* dense matrix-vector product */
        memset(&tctx, 0, sizeof(tctx));
        tctx.parallel_for = serial_for;
        for (r = 0; r < 20; ++r) {
            t0 = now();
            rad_matrix_multiply(&ff->matrix, Ea, out, &tctx);
            times[r] = now() - t0;
        }
        tmv = median(times, 20);
        /* where the time goes: ns per draw; the same tables copied into memory without the
           huge-page advice (4 KiB pages where THP is in 'madvise' mode); the MV's bytes/s */
        {
            rad_alias_tables plain = *t;
            size_t bin_bytes = (size_t)t->row_offsets[n] * 4u * (uint32_t)t->format;
            uint32_t *copy = (uint32_t *)malloc(bin_bytes);
            double th, tp;
            long kb_h = huge_kb(t->bins), kb_p;
            if (!copy) die(RAD_ERROR_OUT_OF_MEMORY, "copy of the bins");
            memcpy(copy, t->bins, bin_bytes);
            plain.bins = copy;
            plain.storage = NULL;
            kb_p = huge_kb(copy);
            th = time_steps(t, P->albedo, Ea, 10, &tctx, 20, 100, times);
            tp = time_steps(&plain, P->albedo, Ea, 10, &tctx, 20, 100, times);
            snprintf(rows_draw[s], sizeof(rows_draw[s]), "| %u | %.1f MB | %ld MB | %.2f | %ld MB | %.2f | %.2f | %.1f GB/s |\n", n,
                     (double)bin_bytes / 1e6, kb_h < 0 ? -1L : kb_h / 1024, th * 1e9 / (10.0 * n), kb_p < 0 ? -1L : kb_p / 1024,
                     tp * 1e9 / (10.0 * n), tp / th, 4.0 * n * (double)n / tmv / 1e9);
            fprintf(stderr, "%s", rows_draw[s]);
            free(copy);
        }
        /* temporal step, k = 10 and 64 */
        for (k = 0; k < 2; ++k) {
            rad_temporal_options_default(&o);
            o.samples = k == 0 ? 10u : 64u;
            {
                const rad_alias_tables *tc = t;
                die(rad_temporal_create(&tc, 1, P->albedo, &o, &tctx, &tm), "rad_temporal_create");
            }
            for (fr = 0; fr < 3000; ++fr) {
                if (fr >= 100 && fr < 300) t0 = now();
                rad_temporal_step(tm, Ea, NULL, NULL);
                if (fr >= 100 && fr < 300) times[fr - 100] = now() - t0;
            }
            tstep[k] = median(times, 200);
            err[k] = 0.0;
            for (fr = 0; fr < 100; ++fr) {
                rad_temporal_step(tm, Ea, NULL, out);
                err[k] += rel_rms(out, La, n) / 100.0;
            }
            rad_temporal_destroy(tm);
            tm = NULL;
        }
        {
            int p, pub = -1;
            char pubtext[64] = "-";
            for (p = 0; p < 4; ++p)
                if (targets[s] == published_sizes[p]) pub = p;
            if (pub >= 0)
                snprintf(pubtext, sizeof(pubtext), "%.2f vs %.2f (%.0fx)", published_temporal[pub], published_mv[pub],
                         published_mv[pub] / published_temporal[pub]);
            snprintf(rows_t1[s], sizeof(rows_t1[s]),
                     "| %u (%u) | %.3f | %.3f | %.3f | %.1fx | %.1fx | %.2f%% | %.2f%% | %s |\n", n, targets[s],
                     tstep[0] * 1e3, tstep[1] * 1e3, tmv * 1e3, tmv / tstep[0], tmv / tstep[1], 100.0 * err[0],
                     100.0 * err[1], pubtext);
        }
        fprintf(stderr, "%s", rows_t1[s]);
        /* lag: fixed w = 0.998 against adaptive */
        if (s == sizes - 1) {
            series_n = 2000;
            series_f = (double *)malloc(sizeof(double) * series_n);
            series_a = (double *)malloc(sizeof(double) * series_n);
        }
        lf = lag_run(t, P, Ea, Eb, La, Lb, 0, 0.0f, s == sizes - 1 ? series_f : NULL);
        la = lag_run(t, P, Ea, Eb, La, Lb, 1, 0.01f, s == sizes - 1 ? series_a : NULL);
        la2 = lag_run(t, P, Ea, Eb, La, Lb, 1, 0.005f, NULL);
        snprintf(rows_lag[s], sizeof(rows_lag[s]), "| %u | %u | %.2f%% | %u | %.2f%% | %u | %.2f%% |\n", n, lf.lag, 100.0 * lf.noise, la.lag,
                 100.0 * la.noise, la2.lag, 100.0 * la2.noise);
        fprintf(stderr, "%s", rows_lag[s]);
        free(D); free(Ea); free(Eb); free(La); free(Lb); free(out);
        rad_alias_tables_destroy(t);
        rad_form_factors_destroy(ff);
        rad_bvh_destroy(bvh);
        rad_patches_destroy(P);
        rad_scene_destroy(scene);
    }
    emit("\n## Temporal radiosity: alias-table sampling against the dense gather\n\n");
    emit_machine();
    emit("CPU, timings on 1 thread (bake and lag runs on %d OpenMP threads). Cornell box, E = rho * direct light of the ceiling emitter; single bounce. "
         "Step = rad_temporal_step (compact alias tables, w = 0.998), MV = one dense RGB rad_matrix_multiply; "
         "times are medians (ms). Error = relative RMS against rho o (F E) after 3000 warm-up frames (mean of 100 frames). "
         "Published: Shcherbakov 2025, Table 1, RTX 3060, k = 10.\n\n", threads);
    emit("| N (target) | step k=10 ms | step k=64 ms | MV ms | ratio k=10 | ratio k=64 | error k=10 | error k=64 | published step vs MV ms (ratio) |\n");
    emit("|---|---|---|---|---|---|---|---|---|\n");
    for (s = 0; s < sizes; ++s) emit("%s", rows_t1[s]);
    if (detail) {
        emit("\nWhere the step's time goes (k = 10, 1 thread, median of 100 frames): nanoseconds per draw with the "
             "library's tables (2 MiB aligned, MADV_HUGEPAGE on Linux) and with the same bins copied into plain malloc memory "
             "(4 KiB pages when THP is in 'madvise' mode); huge-page MB backing each, from /proc/self/smaps (-1: not Linux); "
             "the dense product's read rate for comparison.\n\n");
        emit("| N | bins | huge pages (library) | ns per draw | huge pages (copy) | ns per draw (copy) | copy / library | MV read rate |\n");
        emit("|---|---|---|---|---|---|---|---|\n");
        for (s = 0; s < sizes; ++s) emit("%s", rows_draw[s]);
    }
    if (detail) {
        emit("\nMemory: dense F (4 B per entry), its non-zeros as CSR (8 B per entry), the alias tables "
             "(bins over non-zeros + 1 environment bin per row, offsets, T_i).\n\n");
        emit("| N | non-zero | dense F | CSR F | tables | bytes per bin | table bytes per bin incl. offsets | F bake | table build |\n");
        emit("|---|---|---|---|---|---|---|---|---|\n");
        for (s = 0; s < sizes; ++s) emit("%s", rows_mem[s]);
    }
    if (detail) {
        emit("\nLag after a light jump (a point light switched on; frames until 90%% of the change, k = 10) and steady "
             "noise before it (relative RMS against the exact result, mean of 200 frames). Adaptive: noise targets 0.01 and 0.005.\n\n");
        emit("| N | lag w=0.998 | noise w=0.998 | lag adaptive 0.01 | noise adaptive 0.01 | lag adaptive 0.005 | noise adaptive 0.005 |\n|---|---|---|---|---|---|---|\n");
        for (s = 0; s < sizes; ++s) emit("%s", rows_lag[s]);
    }
    if (series_f) {
        FILE *f = fopen(csv_path, "w");
        if (f) {
            uint32_t i;
            fprintf(f, "frame,error_fixed_0998,error_adaptive\n");
            for (i = 0; i < series_n; ++i) fprintf(f, "%u,%.6f,%.6f\n", 2500 + i, series_f[i], series_a[i]);
            fclose(f);
            emit("\nError against frame around the jump (frame 3000) for the largest N: %s", csv_path);
            if (system("command -v gnuplot >/dev/null 2>&1") == 0) {
                char cmd[1024];
                snprintf(cmd, sizeof(cmd),
                         "gnuplot -e \"set terminal png size 900,500; set output '%s.png'; set datafile separator ','; "
                         "set logscale y; set xlabel 'frame'; set ylabel 'relative RMS error'; plot '%s' using 1:2 with lines "
                         "title 'w = 0.998', '' using 1:3 with lines title 'adaptive'\"",
                         csv_path, csv_path);
                if (system(cmd) == 0) emit(" (plot: %s.png)", csv_path);
            }
            emit("\n");
        }
    }
    free(series_f);
    free(series_a);
    if (g_md) fclose(g_md);
    return 0;
}

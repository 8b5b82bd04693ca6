/* bench.c - radiosity.h benchmarks; writes docs/BENCHMARKS.md and prints the same tables.

   a) Form-factor bake of the built-in Cornell box at about 1k, 4k and 10k patches
      (rad_form_factors_dense, default options, built-in BVH): time, rays cast, rays/s, pairs/s.
   b) One dense Jacobi bounce at N = 10 000 on a synthetic random N x N float matrix
      (rad_matrix_multiply on an RGB vector, and rad_solve_jacobi with bounces = 1) next to a
      plain streaming read (a vectorisable sum) of the same bytes in the same run: best of 5,
      GB/s, and the ratio bounce / streaming.

   Build:  cc -std=c99 -O3 -march=native -fopenmp -I. tests/bench/bench.c -o build/bench -lm
           (also builds without -fopenmp, then everything runs on one thread, and without
           -march=native). Optionally -DBENCH_CFLAGS='"-O3 -march=native -fopenmp"' to record
           the exact flags in the report.
   Run:    build/bench [--quick] [--bounce-n N] [OUTPUT.md]      (default docs/BENCHMARKS.md)
           --quick bakes ~250 and ~1000 patches instead of 1k/4k/10k and uses N = 4000 for the
           bounce, so that it finishes in seconds. */


#include "bench_common.h"
#define RADIOSITY_IMPLEMENTATION
#include "radiosity.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#ifdef _OPENMP
#  include <omp.h>
#endif

#define BENCH_REPEATS 5

/* ---- helpers ------------------------------------------------------------------------- */


static void check(rad_result r, const char *what)
{
    if (r != RAD_SUCCESS) {
        fprintf(stderr, "\nbench: %s failed: %s\n", what, rad_result_string(r));
        exit(1);
    }
}

static void *xmalloc(size_t size)
{
    void *p = malloc(size ? size : 1);
    if (!p) {
        fprintf(stderr, "bench: out of memory (%.0f MB)\n", (double)size / 1e6);
        exit(1);
    }
    return p;
}

typedef struct progress_state {
    const char *label;
    int last;
} progress_state;

static int on_progress(void *user, float fraction)
{
    progress_state *s = (progress_state *)user;
    int pct = (int)(fraction * 100.0f + 0.5f);
    if (pct != s->last) {
        fprintf(stderr, "\r  %-24s %3d%%", s->label, pct);
        fflush(stderr);
        s->last = pct;
    }
    return 0;
}

static void on_log(void *user, rad_log_level level, const char *message)
{
    (void)user;
    fprintf(stderr, "\nradiosity.h %s: %s\n",
            level == RAD_LOG_ERROR ? "error" : level == RAD_LOG_WARNING ? "warning" : "info", message);
}

static int thread_count(void)
{
#ifdef _OPENMP
    return omp_get_max_threads();
#else
    return 1;
#endif
}

/* ---- machine description ------------------------------------------------------------ */

static void trim(char *s)
{
    size_t n = strlen(s);
    while (n > 0 && (s[n - 1] == '\n' || s[n - 1] == '\r' || s[n - 1] == ' ' || s[n - 1] == '\t')) s[--n] = '\0';
}

static void cpu_info(char *model, size_t model_size, int *logical_cpus)
{
    FILE *f = fopen("/proc/cpuinfo", "r");
    char line[1024];
    snprintf(model, model_size, "unknown (no /proc/cpuinfo)");
    *logical_cpus = 0;
    if (!f) return;
    model[0] = '\0';
    while (fgets(line, sizeof line, f)) {
        if (!strncmp(line, "processor", 9) && (line[9] == ' ' || line[9] == '\t' || line[9] == ':')) ++*logical_cpus;
        if (!model[0] && !strncmp(line, "model name", 10)) {
            const char *colon = strchr(line, ':');
            if (colon) {
                colon++;
                while (*colon == ' ' || *colon == '\t') colon++;
                snprintf(model, model_size, "%s", colon);
                trim(model);
            }
        }
    }
    fclose(f);
    if (!model[0]) snprintf(model, model_size, "unknown (no 'model name' in /proc/cpuinfo)");
}

static void uname_all(char *out, size_t size)
{
    snprintf(out, size, "unknown");
#if defined(__unix__) || defined(__APPLE__)
    {
        FILE *p = popen("uname -a", "r");
        if (p) {
            if (fgets(out, (int)size, p)) trim(out);
            else snprintf(out, size, "unknown");
            pclose(p);
        }
    }
#endif
}

/* The largest data or unified CPU cache (Linux sysfs), e.g. "L3 491520K"; bytes in *bytes. */
static void last_level_cache(char *out, size_t size, double *bytes)
{
    int index, best_level = 0;
    snprintf(out, size, "unknown");
    *bytes = 0.0;
    for (index = 0; index < 16; ++index) {
        char path[128], type[32] = "", text[32] = "";
        int level = 0;
        FILE *f;
        snprintf(path, sizeof path, "/sys/devices/system/cpu/cpu0/cache/index%d/level", index);
        if (!(f = fopen(path, "r"))) break;
        if (fscanf(f, "%d", &level) != 1) level = 0;
        fclose(f);
        snprintf(path, sizeof path, "/sys/devices/system/cpu/cpu0/cache/index%d/type", index);
        if ((f = fopen(path, "r"))) {
            if (!fgets(type, sizeof type, f)) type[0] = '\0';
            fclose(f);
        }
        if (!strncmp(type, "Instruction", 11)) continue;
        snprintf(path, sizeof path, "/sys/devices/system/cpu/cpu0/cache/index%d/size", index);
        if ((f = fopen(path, "r"))) {
            if (!fgets(text, sizeof text, f)) text[0] = '\0';
            fclose(f);
        }
        trim(text);
        if (level > best_level && text[0]) {
            double v = strtod(text, NULL);
            char unit = text[strlen(text) - 1];
            best_level = level;
            *bytes = v * (unit == 'K' ? 1024.0 : unit == 'M' ? 1048576.0 : unit == 'G' ? 1073741824.0 : 1.0);
            snprintf(out, size, "L%d %s", level, text);
        }
    }
}

static const char *compiler_name(void)
{
#if defined(__clang__)
    return "clang " __clang_version__;
#elif defined(__GNUC__)
    return "gcc " __VERSION__;
#elif defined(_MSC_VER)
    return "MSVC";
#else
    return "unknown C compiler";
#endif
}

/* What the predefined macros say about the flags the file was built with. */
static void detected_flags(char *out, size_t size)
{
    size_t n = 0;
    out[0] = '\0';
#define BENCH_ADD(s) n += (size_t)snprintf(out + n, n < size ? size - n : 0, "%s%s", n ? " " : "", s)
#if defined(__OPTIMIZE__)
    BENCH_ADD("optimised (__OPTIMIZE__)");
#else
    BENCH_ADD("not optimised");
#endif
#if defined(__AVX512F__)
    BENCH_ADD("AVX-512F");
#endif
#if defined(__AVX2__)
    BENCH_ADD("AVX2");
#endif
#if defined(__AVX__)
    BENCH_ADD("AVX");
#endif
#if defined(__FMA__)
    BENCH_ADD("FMA");
#endif
#if defined(__SSE2__)
    BENCH_ADD("SSE2");
#endif
#if defined(__ARM_NEON) || defined(__ARM_NEON__)
    BENCH_ADD("NEON");
#endif
#if defined(_OPENMP)
    {
        char omp[48];
        snprintf(omp, sizeof omp, "OpenMP %d", (int)_OPENMP);
        BENCH_ADD(omp);
    }
#else
    BENCH_ADD("no OpenMP");
#endif
#if defined(RAD_NO_SIMD)
    BENCH_ADD("RAD_NO_SIMD");
#endif
#undef BENCH_ADD
}

/* ---- a) form-factor bake --------------------------------------------------------------- */

typedef struct bake_result {
    uint32_t target, n;
    double seconds;
    uint64_t rays, pairs;
} bake_result;

static bake_result bake(const rad_scene *scene, const rad_raycaster *rc, uint32_t target, const rad_context *base)
{
    rad_patch_options popt;
    rad_form_factor_options fopt;
    rad_patches *patches = NULL;
    rad_form_factors *ff = NULL;
    rad_context ctx = *base;
    progress_state ps;
    char label[64];
    bake_result res;
    double t0;

    rad_patch_options_default(&popt);
    popt.target_count = target;
    check(rad_patches_create(scene, &popt, base, &patches), "rad_patches_create");
    rad_form_factor_options_default(&fopt);

    snprintf(label, sizeof label, "bake N=%u", patches->count);
    ps.label = label;
    ps.last = -1;
    ctx.progress = on_progress;
    ctx.progress_user = &ps;

    t0 = now();
    check(rad_form_factors_dense(patches, rc, &fopt, &ctx, &ff), "rad_form_factors_dense");
    res.seconds = now() - t0;
    fprintf(stderr, "\r%48s\r", "");

    res.target = target;
    res.n = patches->count;
    res.rays = ff->rays_cast;
    res.pairs = ff->pairs_evaluated;
    rad_form_factors_destroy(ff);
    rad_patches_destroy(patches);
    return res;
}

/* ---- b) dense bounce vs streaming read ------------------------------------------------- */

static uint32_t lcg_next(uint32_t *state)
{
    *state = *state * 1664525u + 1013904223u;
    return *state;
}

/* Fills row r of the matrix from its own seed, so threads can first-touch their rows. */
static void fill_matrix(float *m, uint32_t n)
{
    long r;
    float scale = 1.0f / (4294967296.0f * (float)n); /* entries in [0, 1/n): row sums < 1 */
#ifdef _OPENMP
#  pragma omp parallel for schedule(static)
#endif
    for (r = 0; r < (long)n; ++r) {
        uint32_t state = 0x9E3779B9u ^ (uint32_t)r * 2654435761u, c;
        float *row = m + (size_t)r * n;
        for (c = 0; c < n; ++c) row[c] = (float)lcg_next(&state) * scale;
    }
}

/* Sum of n floats with 32 independent accumulators, so the compiler can keep them in vector
   registers without -ffast-math (two 512-bit, four 256-bit or eight 128-bit registers). */
static float sum_range(const float *p, size_t n)
{
    float acc[32], s = 0.0f;
    size_t i, blocks = n / 32;
    int l;
    for (l = 0; l < 32; ++l) acc[l] = 0.0f;
    for (i = 0; i < blocks; ++i)
        for (l = 0; l < 32; ++l) acc[l] += p[32 * i + (size_t)l];
    for (l = 0; l < 32; ++l) s += acc[l];
    for (i = 32 * blocks; i < n; ++i) s += p[i];
    return s;
}

/* The streaming read: every thread sums one contiguous part of the 'count' floats. */
static double stream_sum(const float *m, size_t count)
{
    double total = 0.0;
#ifdef _OPENMP
#  pragma omp parallel reduction(+ : total)
#endif
    {
        size_t threads = 1, me = 0, begin, end;
#ifdef _OPENMP
        threads = (size_t)omp_get_num_threads();
        me = (size_t)omp_get_thread_num();
#endif
        begin = (count / threads * me) & ~(size_t)15;
        end = me + 1 == threads ? count : (count / threads * (me + 1)) & ~(size_t)15;
        total += (double)sum_range(m + begin, end - begin);
    }
    return total;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y ? 1 : 0;
}

/* ---- main -------------------------------------------------------------------------- */

int main(int argc, char **argv)
{
    const char *out_path = "docs/BENCHMARKS.md";
    int quick = 0, a, i, ncases;
    uint32_t full_targets[3] = { 1000, 4000, 10000 }, quick_targets[2] = { 250, 1000 };
    const uint32_t *targets;
    uint32_t bounce_n = 0;
    char model[256], uname_str[512], flags[256], date[64], llc[64];
    double llc_bytes;
    int logical_cpus;
    time_t started;
    rad_context ctx;
    rad_scene_desc desc;
    rad_scene *scene = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_form_factor_options fopt;
    bake_result results[3];

    for (a = 1; a < argc; ++a) {
        if (!strcmp(argv[a], "--quick")) {
            quick = 1;
        } else if (!strcmp(argv[a], "--bounce-n") && a + 1 < argc) {
            long v = strtol(argv[++a], NULL, 10);
            if (v < 16 || v > 60000) {
                fprintf(stderr, "bench: --bounce-n wants 16..60000\n");
                return 1;
            }
            bounce_n = (uint32_t)v;
        } else if (argv[a][0] == '-') {
            fprintf(stderr, "usage: bench [--quick] [--bounce-n N] [OUTPUT.md]\n");
            return 1;
        } else {
            out_path = argv[a];
        }
    }
    if (!bounce_n) bounce_n = quick ? 4000 : 10000;
    targets = quick ? quick_targets : full_targets;
    ncases = quick ? 2 : 3;

    g_md = fopen(out_path, "w");
    if (!g_md) {
        fprintf(stderr, "bench: cannot write %s\n", out_path);
        return 1;
    }

    memset(&ctx, 0, sizeof ctx);
    ctx.log = on_log;

    cpu_info(model, sizeof model, &logical_cpus);
    uname_all(uname_str, sizeof uname_str);
    detected_flags(flags, sizeof flags);
    last_level_cache(llc, sizeof llc, &llc_bytes);
    started = time(NULL);
    strftime(date, sizeof date, "%Y-%m-%d %H:%M:%S UTC", gmtime(&started));

    emit("# radiosity.h benchmarks\n\n");
    emit("Written by `make bench`%s: this head (the machine of sections a and b) from tests/bench/bench.c, then\n"
         "each bench appends its section with its own machine line. Compare ratios measured side by side;\n"
         "absolute times move 2-3x with the shared machine's load. What was tried and the detail tables\n"
         "are in [docs/performance-notes.md](performance-notes.md).\n\n",
         quick ? " in `--quick` mode (small cases only)" : "");
    emit("| | |\n|---|---|\n");
    emit("| library | radiosity.h %s |\n", RAD_VERSION_STRING);
    emit("| date | %s |\n", date);
    emit("| CPU | %s |\n", model);
    emit("| logical CPUs | %d |\n", logical_cpus);
    emit("| last-level cache | %s (as the OS reports it, per cpu0) |\n", llc);
    emit("| uname -a | `%s` |\n", uname_str);
    emit("| compiler | %s |\n", compiler_name());
#ifdef BENCH_CFLAGS
    emit("| flags | `%s` |\n", BENCH_CFLAGS);
#else
    emit("| flags | not recorded (build with -DBENCH_CFLAGS='\"...\"' to record them) |\n");
#endif
    emit("| flags seen by the compiler | %s |\n", flags);
    emit("| threads | %d%s |\n\n", thread_count(),
#ifdef _OPENMP
         " (OpenMP; the header's default parallel_for)"
#else
         " (built without OpenMP: serial)"
#endif
    );

    /* a) form-factor bake */
    rad_cornell_box(&desc, NULL);
    check(rad_scene_create(&desc, &ctx, &scene), "rad_scene_create");
    check(rad_bvh_create(scene, &ctx, &bvh), "rad_bvh_create");
    rad_bvh_raycaster(bvh, &rc);
    rad_form_factor_options_default(&fopt);
    emit("## a) Form-factor bake, Cornell box\n\n");
    emit("`rad_form_factors_dense` with `rad_form_factor_options_default` (method %s, samples %u%s, "
         "ray_epsilon %g%s), built-in BVH over the %u scene triangles. Time is the form-factor call "
         "only (patches and BVH are built before). Rays: `rays_cast`; pairs: `pairs_evaluated` "
         "(unordered pairs).\n\n",
         fopt.method == RAD_FF_ANALYTIC ? "analytic" : "Monte Carlo", fopt.samples ? fopt.samples : 16u,
         fopt.samples ? "" : " (0 = default 16)", (double)fopt.ray_epsilon, fopt.ray_epsilon > 0 ? "" : " (0 = 1e-5)",
         scene->triangle_count);
    for (i = 0; i < ncases; ++i) {
        results[i] = bake(scene, &rc, targets[i], &ctx);
        fprintf(stderr, "  bake target %u: N = %u, %.3f s\n", targets[i], results[i].n, results[i].seconds);
    }
    emit("| target | N | matrix (MB) | time (s) | rays cast | Mrays/s | pairs | Mpairs/s |\n");
    emit("|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (i = 0; i < ncases; ++i) {
        const bake_result *r = &results[i];
        emit("| %u | %u | %.1f | %.3f | %llu | %.2f | %llu | %.2f |\n", r->target, r->n,
             4.0 * (double)r->n * (double)r->n / 1e6, r->seconds, (unsigned long long)r->rays,
             r->seconds > 0 ? (double)r->rays / r->seconds / 1e6 : 0.0, (unsigned long long)r->pairs,
             r->seconds > 0 ? (double)r->pairs / r->seconds / 1e6 : 0.0);
    }
    if (!quick)
        emit("\nTarget: the ~4k-patch bake in under 60 s: %s (%.1f s at N = %u).\n\n",
             results[1].seconds < 60.0 ? "met" : "NOT met", results[1].seconds, results[1].n);
    else
        emit("\nTarget (~4k-patch bake under 60 s): not measured in --quick mode.\n\n");
    rad_bvh_destroy(bvh);
    rad_scene_destroy(scene);

    /* b) one dense bounce vs a streaming read */
    {
        uint32_t n = bounce_n, k;
        size_t count = (size_t)n * n;
        double bytes = 4.0 * (double)count, t_mul[BENCH_REPEATS], t_jac[BENCH_REPEATS], t_str[BENCH_REPEATS];
        double g_mul, g_jac, g_str, sink = 0.0;
        float *m = (float *)xmalloc(sizeof(float) * count);
        float *x = (float *)xmalloc(sizeof(float) * 3 * n);
        float *albedo = (float *)xmalloc(sizeof(float) * 3 * n);
        float *out = (float *)xmalloc(sizeof(float) * 3 * n);
        uint32_t state = 12345u;
        rad_matrix view;
        rad_system sys;
        rad_solve_options sopt;
        rad_solve_stats st;
        double t0;

        fprintf(stderr, "  filling a %u x %u matrix (%.0f MB)\n", n, n, bytes / 1e6);
        fill_matrix(m, n);
        for (k = 0; k < 3 * n; ++k) {
            x[k] = (float)lcg_next(&state) / 4294967296.0f;
            albedo[k] = 0.9f * (float)lcg_next(&state) / 4294967296.0f;
        }
        memset(&view, 0, sizeof view);
        view.rows = n;
        view.cols = n;
        view.storage = RAD_STORAGE_DENSE;
        view.dense = m;
        sys.F = &view;
        sys.albedo = albedo;
        sys.E = x;
        sys.areas = NULL;
        sys.n = n;
        rad_solve_options_default(&sopt);
        sopt.bounces = 1;
        sopt.output = RAD_OUTPUT_INDIRECT;

        /* one untimed pass of each first (page faults, caches, thread start-up) */
        check(rad_matrix_multiply(&view, x, out, &ctx), "rad_matrix_multiply");
        check(rad_solve_jacobi(&sys, &sopt, out, &st, &ctx), "rad_solve_jacobi");
        sink += stream_sum(m, count);
        /* interleave the three so that they see the same machine state */
        for (i = 0; i < BENCH_REPEATS; ++i) {
            t0 = now();
            check(rad_matrix_multiply(&view, x, out, &ctx), "rad_matrix_multiply");
            t_mul[i] = now() - t0;
            sink += out[0];
            t0 = now();
            check(rad_solve_jacobi(&sys, &sopt, out, &st, &ctx), "rad_solve_jacobi");
            t_jac[i] = now() - t0;
            sink += out[0];
            t0 = now();
            sink += stream_sum(m, count);
            t_str[i] = now() - t0;
        }
        qsort(t_mul, BENCH_REPEATS, sizeof(double), cmp_double);
        qsort(t_jac, BENCH_REPEATS, sizeof(double), cmp_double);
        qsort(t_str, BENCH_REPEATS, sizeof(double), cmp_double);
        g_mul = bytes / t_mul[0] / 1e9;
        g_jac = bytes / t_jac[0] / 1e9;
        g_str = bytes / t_str[0] / 1e9;

        emit("## b) One dense bounce vs a streaming read, N = %u\n\n", n);
        emit("A synthetic random %u x %u float matrix (%.1f MB, entries in [0, 1/N)) wrapped in a dense "
             "`rad_matrix` view; RGB vectors of 3N floats. Best of %d timed runs each (after one untimed "
             "run), the three interleaved. GB/s counts the matrix bytes only (4 N^2). The streaming read "
             "is a plain sum of the same floats (32 accumulators, vectorisable) on %d thread%s.\n\n",
             n, n, bytes / 1e6, BENCH_REPEATS, thread_count(), thread_count() == 1 ? "" : "s");
        emit("| kernel | best (ms) | median (ms) | GB/s | vs streaming |\n");
        emit("|---|---:|---:|---:|---:|\n");
        emit("| streaming read (sum of floats) | %.2f | %.2f | %.2f | 100%% |\n", 1e3 * t_str[0],
             1e3 * t_str[BENCH_REPEATS / 2], g_str);
        emit("| `rad_matrix_multiply` (F x, RGB) | %.2f | %.2f | %.2f | %.0f%% |\n", 1e3 * t_mul[0],
             1e3 * t_mul[BENCH_REPEATS / 2], g_mul, 100.0 * g_mul / g_str);
        emit("| `rad_solve_jacobi`, bounces = 1 | %.2f | %.2f | %.2f | %.0f%% |\n", 1e3 * t_jac[0],
             1e3 * t_jac[BENCH_REPEATS / 2], g_jac, 100.0 * g_jac / g_str);
        emit("\nTarget: a bounce at >= 80%% of the streaming bandwidth: %s (rad_matrix_multiply %.0f%%).\n",
             g_mul >= 0.8 * g_str ? "met" : "NOT met", 100.0 * g_mul / g_str);
        if (llc_bytes > 0.0 && bytes <= llc_bytes)
            emit("\nNote: the %.0f MB matrix fits in the reported last-level cache (%s), so both figures may be "
                 "cache rather than DRAM bandwidth on this machine.\n",
                 bytes / 1e6, llc);
        if (sink == 12345.678) fprintf(stderr, "(checksum %g)\n", sink); /* keeps the sums alive */

        free(m);
        free(x);
        free(albedo);
        free(out);
    }

    if (fclose(g_md) != 0) {
        fprintf(stderr, "bench: error writing %s\n", out_path);
        return 1;
    }
    g_md = NULL;
    printf("\nwrote %s\n", out_path);
    return 0;
}

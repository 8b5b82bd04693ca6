/* vulkan.c - time per dispatch of the GLSL kernels on the Vulkan device the loader finds first
   (Mesa's lavapipe on a machine without a GPU), next to the CPU path on the same inputs.

       vulkan [--n N] [--reps R] [--local SIZE] [--map SIZE] [--append FILE.md]

   Inputs: a random N x N form-factor-like matrix (rows sum to 0.3..0.9), K = 1 so the
   multi-bounce matrix is rho o F (building it costs nothing), E with half its entries zero;
   for the layer mix, 8 random light layers of a --map x --map RGB lightmap (at most 1024: the
   8 layers are bound whole, 96 MiB, under lavapipe's 128 MiB storage range) and RGB scales,
   and the same 8 layers packed as RGB9E5 (rad_rgb9e5_pack of random floats, 32 MiB).
   Each GPU time is the wall time of one dispatch including submit and wait (what a frame
   would pay), the median of R runs; the CPU time is the median of R calls of the CPU function
   with the header's default parallel_for. */
#if !defined(_WIN32) && !defined(_POSIX_C_SOURCE)
#define _POSIX_C_SOURCE 199309L
#endif
#define RADIOSITY_IMPLEMENTATION
#include "bench_common.h"
#include "../../radiosity.h"
#include "../vk_util.h"
#include <time.h>
#include <math.h>

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

static uint32_t rng = 1u;
static float frand(void)
{
    rng = rng * 1664525u + 1013904223u;
    return (float)(rng >> 8) / 16777216.0f;
}

static vk_ctx V;
static FILE *md;

static void row(const char *what, double gpu_s, double cpu_s, double bytes)
{
    printf("%-34s GPU %8.3f ms   CPU %8.3f ms   (%.1f MB read)\n", what, gpu_s * 1e3, cpu_s * 1e3, bytes / 1e6);
    if (md) fprintf(md, "| %s | %.3f | %.3f | %.1f |\n", what, gpu_s * 1e3, cpu_s * 1e3, bytes / 1e6);
}

int main(int argc, char **argv)
{
    uint32_t n = 2048, i, j, c, ls = 128, map = 1024;
    int reps = 15, r, a;
    const char *append = NULL;
    float *F, *E, *rho, *out;
    rad_matrix m;
    rad_multibounce_options mo;
    rad_multibounce *mb = NULL, *mbh = NULL;
    rad_alias_tables *tables = NULL;
    rad_temporal *tstate = NULL;
    rad_temporal_options to;
    double *tg, *tc;
    char dir[] = "build";
    for (a = 1; a < argc; ++a) {
        if (!strcmp(argv[a], "--n") && a + 1 < argc) n = (uint32_t)atoi(argv[++a]);
        else if (!strcmp(argv[a], "--reps") && a + 1 < argc) reps = atoi(argv[++a]);
        else if (!strcmp(argv[a], "--append") && a + 1 < argc) append = argv[++a];
        else if (!strcmp(argv[a], "--local") && a + 1 < argc) ls = (uint32_t)atoi(argv[++a]);
        else if (!strcmp(argv[a], "--map") && a + 1 < argc) map = (uint32_t)atoi(argv[++a]);
        else { fprintf(stderr, "usage: vulkan [--n N] [--reps R] [--local SIZE] [--map SIZE] [--append FILE.md]\n"); return 2; }
    }
    if (reps < 1) reps = 1;
    if (map < 1 || map > 1024) map = 1024;
    (void)vk_chunk; (void)vk_image_blocks; (void)vk_image_free; /* helpers of the tests this program does not need */
    if (!vk_init(&V, dir)) return 1;
    F = (float *)malloc((size_t)n * n * 4);
    E = (float *)malloc((size_t)n * 12);
    rho = (float *)malloc((size_t)n * 12);
    out = (float *)malloc((size_t)n * 12);
    tg = (double *)malloc(sizeof(double) * (size_t)reps);
    tc = (double *)malloc(sizeof(double) * (size_t)reps);
    if (!F || !E || !rho || !out || !tg || !tc) return 1;
    for (i = 0; i < n; ++i) {
        double s = 0.0, t = 0.3 + 0.6 * frand();
        for (j = 0; j < n; ++j) { F[(size_t)i * n + j] = i == j ? 0.0f : frand(); s += F[(size_t)i * n + j]; }
        for (j = 0; j < n; ++j) F[(size_t)i * n + j] = (float)(F[(size_t)i * n + j] * t / s);
    }
    for (i = 0; i < 3 * n; ++i) { E[i] = frand() < 0.5f ? 0.0f : frand(); rho[i] = 0.9f * frand(); }
    memset(&m, 0, sizeof(m));
    m.rows = m.cols = n;
    m.storage = RAD_STORAGE_DENSE;
    m.dense = F;
    rad_multibounce_options_default(&mo);
    mo.bounces = 1;
    if (rad_multibounce_create(&m, rho, &mo, NULL, &mb) != RAD_SUCCESS ||
        rad_multibounce_convert(mb, RAD_MB_HALF, NULL, &mbh) != RAD_SUCCESS ||
        rad_alias_tables_create(&m, RAD_ALIAS_AUTO, NULL, &tables) != RAD_SUCCESS) return 1;
    rad_temporal_options_default(&to);
    to.samples = 32;
    {
        const rad_alias_tables *one[1];
        one[0] = tables;
        if (rad_temporal_create(one, 1, rho, &to, NULL, &tstate) != RAD_SUCCESS) return 1;
    }
    printf("device %s, N = %u, %d runs each (medians)\n", V.props.deviceName, n, reps);
    if (append) {
        md = fopen(append, "a");
        if (md) {
            fprintf(md, "\n## GLSL kernels on a Vulkan device (tests/bench/vulkan.c)\n\n");
            g_md = md; /* emit_machine writes to stdout and to g_md */
            emit_machine();
            g_md = NULL;
            fprintf(md, "Device: %s. N = %u, random dense F (rows sum to 0.3..0.9), K = 1. GPU: wall time of one "
                        "dispatch with submit and wait (workgroup size %u), median of %d; CPU: the header's function, "
                        "same inputs, median of %d. On lavapipe both run on the same CPU cores.\n\n", V.props.deviceName, n, ls, reps, reps);
            fprintf(md, "| kernel (CPU function) | GPU ms | CPU ms | MB read |\n|---|---:|---:|---:|\n");
        }
    }
    /* dense gather and multi-bounce applies: one workgroup per row */
    for (c = 0; c < 3; ++c) {
        const rad_multibounce *x = c == 2 ? mbh : mb;
        vk_kernel k;
        vk_buf planes[3], bE, bP, bR, bOut;
        uint32_t p;
        size_t esz = c == 2 ? 2 : 4, nn = (size_t)n * n;
        vk_range rg[7];
        if (c == 0) {
            rad_glsl_gather_dense_push pc;
            rad_system sys;
            rad_solve_options so;
            if (!vk_kernel_create(&V, &k, RAD_GLSL_GATHER_DENSE, 0, 4, sizeof(pc), ls)) return 1;
            vk_buffer(&V, &planes[0], nn * 4, F);
            vk_buffer(&V, &bE, 12 * (size_t)n, E);
            vk_buffer(&V, &bR, 12 * (size_t)n, rho);
            vk_buffer(&V, &bOut, 12 * (size_t)n, NULL);
            rg[0] = vk_whole(&planes[0]); rg[1] = vk_whole(&bE); rg[2] = vk_whole(&bR); rg[3] = vk_whole(&bOut);
            pc.row_offset = 0; pc.row_count = n; pc.cols = n; pc.f_base = 0; pc.flags = 0;
            memset(&sys, 0, sizeof(sys));
            sys.F = &m; sys.albedo = rho; sys.E = E; sys.n = n;
            rad_solve_options_default(&so);
            so.bounces = 1;
            for (r = 0; r < reps; ++r) {
                double t0 = now();
                vk_dispatch(&V, &k, rg, &pc, n);
                tg[r] = now() - t0;
                t0 = now();
                rad_solve_jacobi(&sys, &so, out, NULL, NULL);
                tc[r] = now() - t0;
            }
            row("dense gather (rad_solve_jacobi K=1)", median(tg, reps), median(tc, reps), 4.0 * (double)nn);
            vk_buffer_free(&V, &planes[0]); vk_buffer_free(&V, &bE); vk_buffer_free(&V, &bR); vk_buffer_free(&V, &bOut);
            vk_kernel_destroy(&V, &k);
            continue;
        }
        {
            rad_glsl_mb_apply_push pc;
            if (!vk_kernel_create(&V, &k, c == 2 ? RAD_GLSL_MB_APPLY_HALF : RAD_GLSL_MB_APPLY_FLOAT, 0, 7, sizeof(pc), ls)) return 1;
            for (p = 0; p < 3; ++p)
                vk_buffer(&V, &planes[p], nn * esz, c == 2 ? (const void *)(x->half + p * nn) : (const void *)(x->planes + p * nn));
            vk_buffer(&V, &bE, 12 * (size_t)n, E);
            vk_buffer(&V, &bP, 4, NULL);
            vk_buffer(&V, &bOut, 12 * (size_t)n, NULL);
            for (p = 0; p < 3; ++p) rg[p] = vk_whole(&planes[p]);
            rg[3] = vk_whole(&bE); rg[4] = vk_whole(&bP); rg[5] = vk_whole(&bP); rg[6] = vk_whole(&bOut);
            pc.n = n; pc.row_offset = 0; pc.row_count = n; pc.base = 0; pc.flags = 0;
            for (r = 0; r < reps; ++r) {
                double t0 = now();
                vk_dispatch(&V, &k, rg, &pc, n);
                tg[r] = now() - t0;
                t0 = now();
                rad_multibounce_apply(x, E, out, RAD_OUTPUT_INDIRECT, NULL);
                tc[r] = now() - t0;
            }
            row(c == 2 ? "mb apply half (rad_multibounce_apply)" : "mb apply float (rad_multibounce_apply)", median(tg, reps),
                median(tc, reps), (double)esz * 3.0 * (double)nn);
            for (p = 0; p < 3; ++p) vk_buffer_free(&V, &planes[p]);
            vk_buffer_free(&V, &bE); vk_buffer_free(&V, &bP); vk_buffer_free(&V, &bOut);
            vk_kernel_destroy(&V, &k);
        }
    }
    /* temporal step, one invocation per row */
    {
        vk_kernel k;
        vk_buf bOff, bBins, bTot, bE, bR, bB0, bB1;
        vk_range rg[8];
        rad_glsl_temporal_push pc;
        if (!vk_kernel_create(&V, &k, RAD_GLSL_TEMPORAL_STEP, 0, 8, sizeof(pc), ls)) return 1;
        vk_buffer(&V, &bOff, 8 * ((size_t)n + 1), tables->row_offsets);
        vk_buffer(&V, &bBins, 4 * (size_t)tables->row_offsets[n] * (uint32_t)tables->format, tables->bins);
        vk_buffer(&V, &bTot, 4 * (size_t)n, tables->totals);
        vk_buffer(&V, &bE, 12 * (size_t)n, E);
        vk_buffer(&V, &bR, 12 * (size_t)n, rho);
        vk_buffer(&V, &bB0, 12 * (size_t)n, NULL);
        vk_buffer(&V, &bB1, 12 * (size_t)n, NULL);
        rg[0] = vk_whole(&bOff); rg[1] = vk_whole(&bBins); rg[2] = vk_whole(&bTot); rg[3] = vk_whole(&bE);
        rg[4] = vk_whole(&bR); rg[5] = vk_whole(&bB0); rg[6] = vk_whole(&bB1); rg[7] = vk_whole(&bTot);
        memset(&pc, 0, sizeof(pc));
        pc.row_count = n; pc.n = n; pc.samples = to.samples; pc.words = (uint32_t)tables->format;
        pc.flags = RAD_GLSL_TEMPORAL_ALBEDO; pc.channel = 3; pc.weight = to.weight;
        for (r = 0; r < reps; ++r) {
            double t0 = now();
            pc.frame = (uint32_t)r;
            vk_dispatch(&V, &k, rg, &pc, n);
            tg[r] = now() - t0;
            t0 = now();
            rad_temporal_step(tstate, E, NULL, NULL);
            tc[r] = now() - t0;
        }
        row("temporal step k=32 (rad_temporal_step)", median(tg, reps), median(tc, reps),
            (double)n * to.samples * (4.0 * (uint32_t)tables->format + 12.0));
        vk_buffer_free(&V, &bOff); vk_buffer_free(&V, &bBins); vk_buffer_free(&V, &bTot); vk_buffer_free(&V, &bE);
        vk_buffer_free(&V, &bR); vk_buffer_free(&V, &bB0); vk_buffer_free(&V, &bB1);
        vk_kernel_destroy(&V, &k);
    }
    /* the baker's light layers: 8 groups into a map x map RGB lightmap, one invocation per float */
    {
        vk_kernel k;
        vk_buf bL, bS, bO;
        vk_range rg[3];
        rad_glsl_layer_mix_push pc;
        size_t count3 = 3 * (size_t)map * map, q;
        uint32_t groups = 8;
        float *layers = (float *)malloc(count3 * groups * 4), *mixed = (float *)malloc(count3 * 4), scales[24];
        if (!layers || !mixed || !vk_kernel_create(&V, &k, RAD_GLSL_LAYER_MIX, 0, 3, sizeof(pc), ls)) return 1;
        for (q = 0; q < count3 * groups; ++q) layers[q] = frand();
        for (q = 0; q < 24; ++q) scales[q] = 0.2f + frand();
        vk_buffer(&V, &bL, count3 * groups * 4, layers);
        vk_buffer(&V, &bS, sizeof(scales), scales);
        vk_buffer(&V, &bO, count3 * 4, NULL);
        rg[0] = vk_whole(&bL); rg[1] = vk_whole(&bS); rg[2] = vk_whole(&bO);
        memset(&pc, 0, sizeof(pc));
        pc.row_count = (uint32_t)count3; pc.stride = (uint32_t)count3; pc.plane_count = groups;
        for (r = 0; r < reps; ++r) {
            double t0 = now();
            vk_dispatch(&V, &k, rg, &pc, pc.row_count);
            tg[r] = now() - t0;
            t0 = now();
            rad_baker_mix_layers(layers, groups, count3, scales, mixed, NULL);
            tc[r] = now() - t0;
        }
        {
            char what[64];
            snprintf(what, sizeof(what), "layer mix 8 x %u^2 (rad_baker_mix_layers)", map);
            row(what, median(tg, reps), median(tc, reps), 4.0 * (double)count3 * groups);
        }
        vk_buffer_free(&V, &bL); vk_buffer_free(&V, &bS); vk_buffer_free(&V, &bO);
        vk_kernel_destroy(&V, &k);
        free(layers); free(mixed);
    }
    /* the same 8 groups packed as RGB9E5 (4 bytes a texel), one invocation per texel */
    {
        vk_kernel k;
        vk_buf bL, bS, bO;
        vk_range rg[3];
        rad_glsl_layer_mix_push pc;
        size_t texels = (size_t)map * map, q;
        uint32_t groups = 8;
        float *rgb = (float *)malloc(3 * texels * 4), *mixed = (float *)malloc(3 * texels * 4), scales[24];
        uint32_t *packed = (uint32_t *)malloc(texels * groups * 4);
        if (!rgb || !mixed || !packed || !vk_kernel_create(&V, &k, RAD_GLSL_LAYER_MIX_RGB9E5, 0, 3, sizeof(pc), ls)) return 1;
        for (c = 0; c < groups; ++c) { /* one plane at a time: the float layers of all 8 would be 96 MiB more */
            for (q = 0; q < 3 * texels; ++q) rgb[q] = frand();
            if (rad_rgb9e5_pack(rgb, texels, packed + c * texels, NULL) != RAD_SUCCESS) return 1;
        }
        for (q = 0; q < 24; ++q) scales[q] = 0.2f + frand();
        vk_buffer(&V, &bL, texels * groups * 4, packed);
        vk_buffer(&V, &bS, sizeof(scales), scales);
        vk_buffer(&V, &bO, 3 * texels * 4, NULL);
        rg[0] = vk_whole(&bL); rg[1] = vk_whole(&bS); rg[2] = vk_whole(&bO);
        memset(&pc, 0, sizeof(pc));
        pc.row_count = (uint32_t)texels; pc.stride = (uint32_t)texels; pc.plane_count = groups;
        for (r = 0; r < reps; ++r) {
            double t0 = now();
            vk_dispatch(&V, &k, rg, &pc, pc.row_count);
            tg[r] = now() - t0;
            t0 = now();
            rad_baker_mix_layers_rgb9e5(packed, groups, texels, scales, mixed, NULL);
            tc[r] = now() - t0;
        }
        {
            char what[64];
            snprintf(what, sizeof(what), "layer mix RGB9E5 8 x %u^2 (rad_baker_mix_layers_rgb9e5)", map);
            row(what, median(tg, reps), median(tc, reps), 4.0 * (double)texels * groups);
        }
        vk_buffer_free(&V, &bL); vk_buffer_free(&V, &bS); vk_buffer_free(&V, &bO);
        vk_kernel_destroy(&V, &k);
        free(rgb); free(mixed); free(packed);
    }
    if (md) {
        fprintf(md, "\nMB read: the matrix bytes one product reads (temporal: bins and E values touched by the draws).\n");
        fclose(md);
    }
    rad_temporal_destroy(tstate);
    rad_alias_tables_destroy(tables);
    rad_multibounce_destroy(mb);
    rad_multibounce_destroy(mbh);
    vk_shutdown(&V);
    free(F); free(E); free(rho); free(out); free(tg); free(tc);
    return 0;
}

/* baker_save.c - the cost of saving and loading an engine-tier result (SAVE AND LOAD in
   >>api_bake): a synthetic result with a 1024 x 1024 RGB lightmap of 8 light groups (float
   layers, and with --rgb9e5 the packed planes too), its file size, the CPU time of
   rad_baker_result_save_memory and rad_baker_result_load_memory (the load's mix of the outputs
   on its own beside it) and, for scale, a memcpy of the file's bytes. One thread (a serial
   parallel_for); R rounds, best and median CPU time of the process per call
   (CLOCK_PROCESS_CPUTIME_ID). Results: docs/performance-notes.md, "Saving a bake".
   Build: make build/bench_baker_save.

       baker_save [--reps R] [--groups G] [--size N] [--rgb9e5] */
#define _POSIX_C_SOURCE 199309L /* clock_gettime */
#define RADIOSITY_IMPLEMENTATION
#include "../../radiosity.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

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

static void row(const char *what, double *t, int reps)
{
    qsort(t, (size_t)reps, sizeof(double), cmp_double);
    printf("| %-34s | %8.2f | %8.2f |\n", what, 1e3 * t[0], 1e3 * t[reps / 2]);
}

int main(int argc, char **argv)
{
    int reps = 9, rgb9e5 = 0, a, k;
    uint32_t groups = 8, size = 1024, seed = 1u;
    size_t texels, n, i, bytes = 0;
    rad_baker_result *R;
    rad_context ctx;
    void *file = NULL, *copy;
    double *ts, *tl, *tm, *tc;
    for (a = 1; a < argc; ++a) {
        if (!strcmp(argv[a], "--reps") && a + 1 < argc) reps = atoi(argv[++a]);
        else if (!strcmp(argv[a], "--groups") && a + 1 < argc) groups = (uint32_t)atoi(argv[++a]);
        else if (!strcmp(argv[a], "--size") && a + 1 < argc) size = (uint32_t)atoi(argv[++a]);
        else if (!strcmp(argv[a], "--rgb9e5")) rgb9e5 = 1;
        else {
            fprintf(stderr, "usage: baker_save [--reps R] [--groups G] [--size N] [--rgb9e5]\n");
            return 2;
        }
    }
    if (reps < 1 || groups < 1 || groups > RAD_BAKER_MAX_GROUPS || size < 1 || size > 8192) return 2;
    memset(&ctx, 0, sizeof ctx);
    ctx.parallel_for = serial_for;
    texels = (size_t)size * size;
    n = 3 * texels;
    /* a result as rad_baker_run leaves one (the default allocator frees it) */
    R = (rad_baker_result *)calloc(1, sizeof *R);
    if (!R) return 1;
    R->method = RAD_BAKER_CLASSIC;
    strcpy(R->reason, "synthetic");
    strcpy(R->plan.reason, "synthetic");
    R->group_count = groups;
    R->lightmap_width = R->lightmap_height = size;
    R->lightmap_channels = 3;
    R->lightmap = (float *)malloc(n * sizeof(float));
    R->lightmap_layers = (float *)malloc(n * groups * sizeof(float));
    R->lightmap_flags = (uint8_t *)malloc(texels);
    if (!R->lightmap || !R->lightmap_layers || !R->lightmap_flags) return 1;
    for (i = 0; i < n * groups; ++i) {
        seed = seed * 1664525u + 1013904223u;
        R->lightmap_layers[i] = (float)(seed >> 8) * (1.0f / 16777216.0f) * 4.0f;
    }
    memset(R->lightmap_flags, RAD_TEXEL_COVERED | RAD_TEXEL_VALID, texels);
    if (rgb9e5) {
        R->lightmap_rgb9e5 = (uint32_t *)malloc(texels * groups * sizeof(uint32_t));
        if (!R->lightmap_rgb9e5 || rad_rgb9e5_pack(R->lightmap_layers, texels * groups, R->lightmap_rgb9e5, &ctx) != RAD_SUCCESS)
            return 1;
    }
    if (rad_baker_mix(R, NULL, &ctx) != RAD_SUCCESS) return 1;
    ts = (double *)malloc(4 * (size_t)reps * sizeof(double));
    if (!ts) return 1;
    tl = ts + reps, tm = tl + reps, tc = tm + reps;
    if (rad_baker_result_save_memory(R, &ctx, &file, &bytes) != RAD_SUCCESS) return 1;
    copy = malloc(bytes);
    if (!copy) return 1;
    for (k = 0; k < reps; ++k) {
        void *f2 = NULL;
        size_t b2 = 0;
        rad_baker_result *L = NULL;
        double t0 = cpu_now();
        if (rad_baker_result_save_memory(R, &ctx, &f2, &b2) != RAD_SUCCESS) return 1;
        ts[k] = cpu_now() - t0;
        rad_free_buffer(f2, &ctx);
        t0 = cpu_now();
        if (rad_baker_result_load_memory(file, bytes, &ctx, &L) != RAD_SUCCESS) return 1;
        tl[k] = cpu_now() - t0;
        if (memcmp(L->lightmap, R->lightmap, n * sizeof(float)) != 0) {
            fprintf(stderr, "baker_save: the loaded lightmap differs\n");
            return 1;
        }
        t0 = cpu_now();
        rad_baker_mix(L, NULL, &ctx);
        tm[k] = cpu_now() - t0;
        rad_baker_result_destroy(L);
        t0 = cpu_now();
        memcpy(copy, file, bytes);
        tc[k] = cpu_now() - t0;
    }
    printf("%u x %u RGB lightmap, %u groups%s: file %.1f MiB (%zu bytes), %d rounds, one thread\n\n", size, size, groups,
           rgb9e5 ? " (float and RGB9E5 layers)" : "", (double)bytes / 1048576.0, bytes, reps);
    printf("| %-34s | %8s | %8s |\n| --- | ---: | ---: |\n", "call (CPU ms)", "best", "median");
    row("rad_baker_result_save_memory", ts, reps);
    row("rad_baker_result_load_memory", tl, reps);
    row("  of which could be its mix", tm, reps);
    row("memcpy of the file", tc, reps);
    free(copy);
    free(ts);
    rad_free_buffer(file, &ctx);
    rad_baker_result_destroy(R);
    return 0;
}

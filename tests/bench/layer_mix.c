/* layer_mix.c - ways to mix the baker's light layers on one core, side by side: the header's
   rad_baker_mix_layers and variants that move fewer bytes or move them differently (half-float
   layers, streaming stores, software prefetch, planes per pass, planes padded apart, texels
   outside the charts skipped), each the mix of 8 groups into a 1024 x 1024 RGB lightmap (the
   engine tier's target: < 2 ms). Results: docs/performance-notes.md, "Mixing light layers fast".
   Build: make build/bench_layer_mix.

       layer_mix [--reps R] [--groups G] [--coverage F] [--huge]

   --huge asks the kernel for transparent huge pages on every array (madvise MADV_HUGEPAGE, 2 MiB
   aligned): an engine's allocator may, and with 4 KiB pages the mix touches 24 000 pages a call.

   Every call runs on one core (a serial parallel_for). The variants are timed round-robin, one
   call of each per round, R rounds after a warm-up round, so load on a shared machine hits them
   alike; each row prints the best and the median CPU time of the process per call
   (CLOCK_PROCESS_CPUTIME_ID: memory stalls count) and the largest relative difference from the
   header's mix. The variants are measurement code, not the library's: x86-64 with AVX2 and F16C
   (build with -O3 -march=native). */
#if !defined(__AVX2__) || !defined(__F16C__)
#error "tests/bench/layer_mix.c needs x86-64 with AVX2 and F16C (build with -march=native on such a CPU)"
#endif
#define RADIOSITY_IMPLEMENTATION
#include "bench_common.h"
#include "../../radiosity.h"
#include <math.h>
#include <immintrin.h>
#include <sys/mman.h>

#define MAP 1024u
#define CHUNK 24576u /* floats per chunk, as the header's RAD__BAKER_MIX_CHUNK (96 KiB) */
#define MAXG 16u

static int g_huge;

/* 2 MiB-aligned memory, huge pages asked for with --huge (before the first touch) */
static void *alloc_big(size_t bytes)
{
    void *p = NULL;
    if (posix_memalign(&p, (size_t)2 << 20, bytes)) return NULL;
#ifdef MADV_HUGEPAGE
    if (g_huge) madvise(p, bytes, MADV_HUGEPAGE);
#endif
    return p;
}

static double cpu_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int cmp_d(const void *a, const void *b)
{
    return (*(const double *)a > *(const double *)b) - (*(const double *)a < *(const double *)b);
}

static void serial_for(void *user, uint32_t count, rad_task_fn fn, void *data)
{
    uint32_t i;
    (void)user;
    for (i = 0; i < count; ++i) fn(data, i);
}

typedef struct mix_in {
    uint32_t groups;
    size_t count3;
    const float *const *fl;       /* float planes (contiguous or padded apart) */
    const uint16_t *const *hl;    /* half planes */
    const float *pattern;         /* 24 floats per group: its RGB scale repeated eight times */
    const uint32_t *span;         /* coverage: pairs [begin, end) of floats inside the charts, per chunk */
    size_t spans;
    rad_context *ctx;
    const float *rgb;
    const float *contiguous;
} mix_in;

/* the scale pattern for 8 lanes starting at float j (j a multiple of 24: the pattern repeats) */
static __m256 pat(const float *p, size_t k) { return _mm256_loadu_ps(p + k); }

/* float layers, AVX, 'streams' planes a pass, plain or streaming stores for the last pass */
static void mix_float(const mix_in *m, float *out, uint32_t streams, int nt, size_t ahead)
{
    size_t b, j;
    uint32_t g0, g;
    for (b = 0; b < m->count3; b += CHUNK) {
        size_t e = b + CHUNK < m->count3 ? b + CHUNK : m->count3;
        for (g0 = 0; g0 < m->groups; g0 += streams) {
            uint32_t g1 = g0 + streams < m->groups ? g0 + streams : m->groups;
            int last = g1 == m->groups;
            for (j = b; j + 24 <= e; j += 24) {
                __m256 a0 = _mm256_setzero_ps(), a1 = a0, a2 = a0;
                if (g0) { a0 = _mm256_loadu_ps(out + j); a1 = _mm256_loadu_ps(out + j + 8); a2 = _mm256_loadu_ps(out + j + 16); }
                for (g = g0; g < g1; ++g) {
                    const float *l = m->fl[g] + j, *p = m->pattern + 24 * g;
                    if (ahead) { _mm_prefetch((const char *)(l + ahead), _MM_HINT_T0); _mm_prefetch((const char *)(l + ahead + 16), _MM_HINT_T0); }
                    a0 = _mm256_add_ps(a0, _mm256_mul_ps(_mm256_loadu_ps(l), pat(p, 0)));
                    a1 = _mm256_add_ps(a1, _mm256_mul_ps(_mm256_loadu_ps(l + 8), pat(p, 8)));
                    a2 = _mm256_add_ps(a2, _mm256_mul_ps(_mm256_loadu_ps(l + 16), pat(p, 16)));
                }
                if (nt && last) { _mm256_stream_ps(out + j, a0); _mm256_stream_ps(out + j + 8, a1); _mm256_stream_ps(out + j + 16, a2); }
                else { _mm256_storeu_ps(out + j, a0); _mm256_storeu_ps(out + j + 8, a1); _mm256_storeu_ps(out + j + 16, a2); }
            }
        }
    }
    if (nt) _mm_sfence();
}

/* half layers (F16C), 'streams' planes a pass */
static void mix_half(const mix_in *m, float *out, uint32_t streams, int nt, size_t ahead)
{
    size_t b, j;
    uint32_t g0, g;
    for (b = 0; b < m->count3; b += CHUNK) {
        size_t e = b + CHUNK < m->count3 ? b + CHUNK : m->count3;
        for (g0 = 0; g0 < m->groups; g0 += streams) {
            uint32_t g1 = g0 + streams < m->groups ? g0 + streams : m->groups;
            int last = g1 == m->groups;
            for (j = b; j + 24 <= e; j += 24) {
                __m256 a0 = _mm256_setzero_ps(), a1 = a0, a2 = a0;
                if (g0) { a0 = _mm256_loadu_ps(out + j); a1 = _mm256_loadu_ps(out + j + 8); a2 = _mm256_loadu_ps(out + j + 16); }
                for (g = g0; g < g1; ++g) {
                    const uint16_t *l = m->hl[g] + j;
                    const float *p = m->pattern + 24 * g;
                    if (ahead) _mm_prefetch((const char *)(l + ahead), _MM_HINT_T0);
                    a0 = _mm256_add_ps(a0, _mm256_mul_ps(_mm256_cvtph_ps(_mm_loadu_si128((const __m128i *)l)), pat(p, 0)));
                    a1 = _mm256_add_ps(a1, _mm256_mul_ps(_mm256_cvtph_ps(_mm_loadu_si128((const __m128i *)(l + 8))), pat(p, 8)));
                    a2 = _mm256_add_ps(a2, _mm256_mul_ps(_mm256_cvtph_ps(_mm_loadu_si128((const __m128i *)(l + 16))), pat(p, 16)));
                }
                if (nt && last) { _mm256_stream_ps(out + j, a0); _mm256_stream_ps(out + j + 8, a1); _mm256_stream_ps(out + j + 16, a2); }
                else { _mm256_storeu_ps(out + j, a0); _mm256_storeu_ps(out + j + 8, a1); _mm256_storeu_ps(out + j + 16, a2); }
            }
        }
    }
    if (nt) _mm_sfence();
}

/* float layers, only the spans inside the charts (24-float aligned), 4 planes a pass */
static void mix_spans(const mix_in *m, float *out)
{
    size_t s, j;
    uint32_t g0, g;
    for (s = 0; s < m->spans; ++s) {
        size_t b = m->span[2 * s], e = m->span[2 * s + 1];
        for (g0 = 0; g0 < m->groups; g0 += 4) {
            uint32_t g1 = g0 + 4 < m->groups ? g0 + 4 : m->groups;
            for (j = b; j + 24 <= e; j += 24) {
                __m256 a0 = _mm256_setzero_ps(), a1 = a0, a2 = a0;
                if (g0) { a0 = _mm256_loadu_ps(out + j); a1 = _mm256_loadu_ps(out + j + 8); a2 = _mm256_loadu_ps(out + j + 16); }
                for (g = g0; g < g1; ++g) {
                    const float *l = m->fl[g] + j, *p = m->pattern + 24 * g;
                    a0 = _mm256_add_ps(a0, _mm256_mul_ps(_mm256_loadu_ps(l), pat(p, 0)));
                    a1 = _mm256_add_ps(a1, _mm256_mul_ps(_mm256_loadu_ps(l + 8), pat(p, 8)));
                    a2 = _mm256_add_ps(a2, _mm256_mul_ps(_mm256_loadu_ps(l + 16), pat(p, 16)));
                }
                _mm256_storeu_ps(out + j, a0); _mm256_storeu_ps(out + j + 8, a1); _mm256_storeu_ps(out + j + 16, a2);
            }
        }
    }
}

/* the bound: read every float layer once (four accumulators), write nothing */
static float read_only(const mix_in *m)
{
    __m256 a0 = _mm256_setzero_ps(), a1 = a0, a2 = a0, a3 = a0;
    float r[8];
    uint32_t g;
    size_t j;
    for (g = 0; g < m->groups; ++g)
        for (j = 0; j + 32 <= m->count3; j += 32) {
            const float *l = m->fl[g] + j;
            a0 = _mm256_add_ps(a0, _mm256_loadu_ps(l)); a1 = _mm256_add_ps(a1, _mm256_loadu_ps(l + 8));
            a2 = _mm256_add_ps(a2, _mm256_loadu_ps(l + 16)); a3 = _mm256_add_ps(a3, _mm256_loadu_ps(l + 24));
        }
    _mm256_storeu_ps(r, _mm256_add_ps(_mm256_add_ps(a0, a1), _mm256_add_ps(a2, a3)));
    return r[0] + r[7];
}

/* the bound of half layers: read them once, converted, write nothing */
static float read_half(const mix_in *m)
{
    __m256 a0 = _mm256_setzero_ps(), a1 = a0, a2 = a0, a3 = a0;
    float r[8];
    uint32_t g;
    size_t j;
    for (g = 0; g < m->groups; ++g)
        for (j = 0; j + 32 <= m->count3; j += 32) {
            const uint16_t *l = m->hl[g] + j;
            a0 = _mm256_add_ps(a0, _mm256_cvtph_ps(_mm_loadu_si128((const __m128i *)l)));
            a1 = _mm256_add_ps(a1, _mm256_cvtph_ps(_mm_loadu_si128((const __m128i *)(l + 8))));
            a2 = _mm256_add_ps(a2, _mm256_cvtph_ps(_mm_loadu_si128((const __m128i *)(l + 16))));
            a3 = _mm256_add_ps(a3, _mm256_cvtph_ps(_mm_loadu_si128((const __m128i *)(l + 24))));
        }
    _mm256_storeu_ps(r, _mm256_add_ps(_mm256_add_ps(a0, a1), _mm256_add_ps(a2, a3)));
    return r[0] + r[7];
}

/* the bound of RGB9E5 layers: read the packed words once, write nothing */
static uint32_t read_packed(const uint32_t *const *pl, uint32_t groups, size_t texels)
{
    __m256i a0 = _mm256_setzero_si256(), a1 = a0;
    uint32_t r[8], g;
    size_t j;
    for (g = 0; g < groups; ++g)
        for (j = 0; j + 16 <= texels; j += 16) {
            a0 = _mm256_xor_si256(a0, _mm256_loadu_si256((const __m256i *)(pl[g] + j)));
            a1 = _mm256_xor_si256(a1, _mm256_loadu_si256((const __m256i *)(pl[g] + j + 8)));
        }
    _mm256_storeu_si256((__m256i *)r, _mm256_xor_si256(a0, a1));
    return r[0] ^ r[7];
}

enum { V_LIB, V_READ, V_F4, V_F4NT, V_F4PF, V_F8PADNT, V_F8PF, V_H4, V_H8, V_H8NT, V_H8PF, V_H8PF2, V_H4PF, V_H1, V_H2PF, V_HREAD, V_SPANS, V_PACKED, V_PREAD, V_COUNT };
static const char *const names[V_COUNT] = {
    "rad_baker_mix_layers (float, 4 planes a pass)", "read the float layers only (bound)",
    "float, 4 a pass, AVX (the header's loop, 8 lanes)", "float, 4 a pass, streaming stores", "float, 4, streaming, prefetch 2 KiB ahead", "float, 8 a pass, padded apart, streaming",
    "float, 8 padded, streaming, prefetch 2 KiB ahead",
    "half (F16C), 4 a pass", "half, 8 a pass", "half, 8 a pass, streaming stores",
    "half, 8, streaming, prefetch 1 KiB ahead", "half, 8, streaming, prefetch 2 KiB ahead", "half, 4 a pass, streaming, prefetch 1 KiB",
    "half, 1 a pass, streaming", "half, 2 a pass, streaming, prefetch 1 KiB",
    "read the half layers only (bound)", "float, chart texels only (coverage)",
    "rad_baker_mix_layers_rgb9e5 (RGB9E5 layers, 4 bytes a texel)", "read the RGB9E5 layers only (bound)",
};

int main(int argc, char **argv)
{
    uint32_t groups = 8, reps = 41, r, v, g;
    double coverage = 0.7;
    size_t count3 = 3u * MAP * MAP, i, pad = 0;
    float *cont, *padded, *out, *ref, pattern[24 * MAXG], rgb[3 * MAXG], sink = 0.0f;
    uint16_t *halves;
    uint32_t *packed, psink = 0;
    const uint32_t *pl[MAXG];
    const float *fl[MAXG], *flp[MAXG];
    const uint16_t *hl[MAXG];
    uint32_t *span;
    double *t[V_COUNT], err[V_COUNT];
    mix_in m;
    rad_context ctx;
    int a;
    for (a = 1; a < argc; ++a) {
        if (!strcmp(argv[a], "--reps") && a + 1 < argc) reps = (uint32_t)atoi(argv[++a]);
        else if (!strcmp(argv[a], "--groups") && a + 1 < argc) groups = (uint32_t)atoi(argv[++a]);
        else if (!strcmp(argv[a], "--coverage") && a + 1 < argc) coverage = atof(argv[++a]);
        else if (!strcmp(argv[a], "--huge")) g_huge = 1;
        else { fprintf(stderr, "usage: layer_mix [--reps R] [--groups G] [--coverage F] [--huge]\n"); return 2; }
    }
    if (groups < 1 || groups > MAXG || reps < 1) return 2;
    (void)now;
    cont = (float *)alloc_big(count3 * groups * sizeof(float));
    padded = (float *)alloc_big((count3 + 4096) * groups * sizeof(float));
    halves = (uint16_t *)alloc_big(count3 * groups * sizeof(uint16_t));
    packed = (uint32_t *)alloc_big(count3 / 3 * groups * sizeof(uint32_t));
    out = (float *)alloc_big(count3 * sizeof(float)); /* streaming stores: 32-byte aligned */
    ref = (float *)malloc(count3 * sizeof(float));
    span = (uint32_t *)malloc(2 * (count3 / 24 + 1) * sizeof(uint32_t));
    for (v = 0; v < V_COUNT; ++v) t[v] = (double *)malloc(reps * sizeof(double));
    if (!cont || !padded || !halves || !packed || !out || !ref || !span || !t[V_COUNT - 1]) return 1;
    /* light layers of plausible magnitudes (0..4 W m^-2, a fifth zero) */
    srand(7);
    for (i = 0; i < count3 * groups; ++i) cont[i] = rand() % 5 == 0 ? 0.0f : 4.0f * (float)rand() / (float)RAND_MAX;
    for (g = 0; g < groups; ++g) {
        fl[g] = cont + g * count3;
        pad = (size_t)g * (count3 + 4096) + 16u * g * 17u; /* planes 4 KiB + 1 KiB g apart: no shared cache sets */
        flp[g] = padded + pad;
        memcpy(padded + pad, fl[g], count3 * sizeof(float));
        hl[g] = halves + g * count3;
        for (i = 0; i < count3; ++i) halves[g * count3 + i] = rad_half_from_float(fl[g][i]);
        pl[g] = packed + g * (count3 / 3);
        if (rad_rgb9e5_pack(fl[g], count3 / 3, packed + g * (count3 / 3), NULL) != RAD_SUCCESS) return 1;
        for (i = 0; i < 3; ++i) rgb[3 * g + i] = 0.3f + 0.1f * (float)((g + i) % 7);
        for (i = 0; i < 24; ++i) pattern[24 * g + i] = rgb[3 * g + i % 3];
    }
    /* coverage: rows of the map inside charts in runs (a chart row about 200 texels, gaps between) */
    m.spans = 0;
    for (i = 0; i < count3; i += 24 * 50) {
        size_t e = i + (size_t)(coverage * 50.0 + 0.5) * 24;
        if (e > count3) e = count3;
        if (e > i) { span[2 * m.spans] = (uint32_t)i; span[2 * m.spans + 1] = (uint32_t)e; m.spans++; }
    }
    memset(&ctx, 0, sizeof ctx);
    ctx.parallel_for = serial_for;
    ctx.task_count = 1;
    m.groups = groups; m.count3 = count3; m.fl = fl; m.hl = hl; m.pattern = pattern; m.span = span; m.ctx = &ctx;
    m.rgb = rgb; m.contiguous = cont;
    if (rad_baker_mix_layers(cont, groups, count3, rgb, ref, &ctx) != RAD_SUCCESS) return 1;
    for (r = 0; r <= reps; ++r)
        for (v = 0; v < V_COUNT; ++v) {
            double c0 = cpu_seconds(), e = 0.0;
            mix_in mp = m;
            mp.fl = flp;
            switch (v) {
            case V_LIB: rad_baker_mix_layers(cont, groups, count3, rgb, out, &ctx); break;
            case V_READ: sink += read_only(&m); break;
            case V_F4: mix_float(&m, out, 4, 0, 0); break;
            case V_F4NT: mix_float(&m, out, 4, 1, 0); break;
            case V_F4PF: mix_float(&m, out, 4, 1, 512); break;
            case V_F8PADNT: mix_float(&mp, out, 8, 1, 0); break;
            case V_F8PF: mix_float(&mp, out, 8, 1, 512); break;
            case V_H4: mix_half(&m, out, 4, 0, 0); break;
            case V_H8: mix_half(&m, out, 8, 0, 0); break;
            case V_H8NT: mix_half(&m, out, 8, 1, 0); break;
            case V_H8PF: mix_half(&m, out, 8, 1, 512); break;
            case V_H8PF2: mix_half(&m, out, 8, 1, 1024); break;
            case V_H4PF: mix_half(&m, out, 4, 1, 512); break;
            case V_H1: mix_half(&m, out, 1, 1, 0); break;
            case V_H2PF: mix_half(&m, out, 2, 1, 512); break;
            case V_HREAD: sink += read_half(&m); break;
            case V_SPANS: mix_spans(&m, out); break;
            case V_PACKED: rad_baker_mix_layers_rgb9e5(packed, groups, count3 / 3, rgb, out, &ctx); break;
            case V_PREAD: psink ^= read_packed(pl, groups, count3 / 3); break;
            }
            if (r) t[v][r - 1] = 1e3 * (cpu_seconds() - c0);
            if (r == 0 && v != V_READ && v != V_HREAD && v != V_PREAD) { /* the difference from the header's mix, in the warm-up round */
                size_t n = v == V_SPANS ? 0 : count3, s, k;
                for (k = 0; k < n; ++k) {
                    double d = fabs((double)out[k] - ref[k]) / (fabs(ref[k]) > 1e-3 ? fabs(ref[k]) : 1e-3);
                    if (d > e) e = d;
                }
                for (s = 0; v == V_SPANS && s < m.spans; ++s)
                    for (k = span[2 * s]; k < span[2 * s + 1]; ++k) {
                        double d = fabs((double)out[k] - ref[k]) / (fabs(ref[k]) > 1e-3 ? fabs(ref[k]) : 1e-3);
                        if (d > e) e = d;
                    }
                err[v] = e;
            }
        }
    printf("%u groups into a %u x %u RGB lightmap, one core, %u rounds (CPU ms per call; coverage %.2f; %s pages)\n", groups,
           MAP, MAP, reps, coverage, g_huge ? "huge" : "4 KiB");
    printf("| variant | best ms | median ms | MB moved | max rel. diff |\n|---|---:|---:|---:|---:|\n");
    for (v = 0; v < V_COUNT; ++v) {
        double mb = (double)count3 * groups * (v >= V_H4 && v <= V_HREAD ? 2.0 : v >= V_PACKED ? 4.0 / 3.0 : 4.0);
        int ro = v == V_READ || v == V_HREAD || v == V_PREAD;
        if (v == V_SPANS) mb *= coverage;
        if (!ro) mb += (double)count3 * 4.0 * (v == V_SPANS ? coverage : 1.0) * (v == V_LIB || v == V_F4 || v == V_H4 || v == V_H8 || v == V_SPANS || v == V_PACKED ? 2.0 : 1.0);
        qsort(t[v], reps, sizeof(double), cmp_d);
        if (ro) printf("| %s | %.2f | %.2f | %.0f | - |\n", names[v], t[v][0], t[v][reps / 2], mb / 1e6);
        else printf("| %s | %.2f | %.2f | %.0f | %.1e |\n", names[v], t[v][0], t[v][reps / 2], mb / 1e6, err[v]);
    }
    printf("rad_baker_mix_layers_rgb9e5 / rad_baker_mix_layers (medians, this run): %.2f\n", t[V_PACKED][reps / 2] / t[V_LIB][reps / 2]);
    if (sink == 12345.0f || psink == 12345u) printf("%g\n", (double)sink);
    return 0;
}

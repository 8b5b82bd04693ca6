/* shading.c - cost of one lighting-model evaluation in C (docs/methods/shading.md, >>shading).

   For each model (and the microfacet variants), 2^18 random unit configurations (l, v in the
   upper hemisphere of n, a tangent frame) are evaluated in a loop, on one thread:
   - rad_shade on a packed material (the unchecked evaluator, the C twin of GLSL rad_shade),
   - rad_shading_eval (validates the material, normalizes the vectors, packs, evaluates).
   Reported: nanoseconds per evaluation (best of 5 passes) and, as a checksum that keeps the
   compiler honest, the mean response.

   Build: cc -std=c99 -O3 -march=native -I. tests/bench/shading.c -o shading -lm
   Run:   shading [--quick] [--append FILE.md] */
#include "bench_common.h"
#define RADIOSITY_IMPLEMENTATION
#include "../../radiosity.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>

static uint32_t g_seed = 7u;
static float frand(void)
{
    g_seed = g_seed * 1664525u + 1013904223u;
    return (float)(g_seed >> 8) / 16777216.0f;
}

static void hemi(float *d)
{
    float z = 0.02f + 0.98f * frand(), p = 6.2831853f * frand(), r = sqrtf(1.0f - z * z);
    d[0] = r * cosf(p); d[1] = r * sinf(p); d[2] = z;
}

int main(int argc, char **argv)
{
    static const char *names[] = { "lambert", "half-lambert", "banded", "phong", "blinn-phong", "minnaert", "oren-nayar",
                                   "GGX, height-correlated, Lambert diffuse", "GGX anisotropic", "Beckmann, separable, Shirley diffuse",
                                   "Beckmann anisotropic" };
    const float n[3] = { 0.0f, 0.0f, 1.0f }, t[3] = { 1.0f, 0.0f, 0.0f }, b[3] = { 0.0f, 1.0f, 0.0f };
    int quick = 0, a, m, pass, passes;
    uint32_t count, i;
    float *lv;
    for (a = 1; a < argc; ++a) {
        if (!strcmp(argv[a], "--quick")) quick = 1;
        else if (!strcmp(argv[a], "--append") && a + 1 < argc) g_md = fopen(argv[++a], "a");
        else { fprintf(stderr, "usage: shading [--quick] [--append FILE.md]\n"); return 2; }
    }
    count = quick ? (1u << 16) : (1u << 18);
    passes = quick ? 3 : 5;
    lv = (float *)malloc(sizeof(float) * 6 * count);
    if (!lv) return 1;
    for (i = 0; i < count; ++i) { hemi(lv + 6 * i); hemi(lv + 6 * i + 3); }
    {
        char cpu[256] = "unknown", line[512], date[64] = "unknown";
        FILE *f = fopen("/proc/cpuinfo", "r");
        time_t tt = time(NULL);
        struct tm *tm = gmtime(&tt);
        if (f) {
            while (fgets(line, sizeof(line), f))
                if (!strncmp(line, "model name", 10) && strchr(line, ':')) {
                    snprintf(cpu, sizeof(cpu), "%s", strchr(line, ':') + 2);
                    cpu[strcspn(cpu, "\n")] = 0;
                    break;
                }
            fclose(f);
        }
        if (tm) strftime(date, sizeof(date), "%Y-%m-%d %H:%M UTC", tm);
        emit("\n## Lighting models: cost of one evaluation in C\n\n");
        emit_machine();
        emit("Measured %s on %s (%s), compiled `-std=c99 -O3 -march=native`.\n\n", date, cpu,
#ifdef __VERSION__
             "gcc/clang " __VERSION__
#else
             "compiler unknown"
#endif
        );
    }
    emit("Run as `build/shading%s`: %u random configurations (l, v over the hemisphere), one thread, best of %d "
         "passes. `rad_shade` is the unchecked evaluator on a packed material; `rad_shading_eval` validates the "
         "material, normalizes the vectors and packs first.\n\n", quick ? " --quick" : "", count, passes);
    emit("| model | rad_shade ns | rad_shading_eval ns | mean R |\n|---|---|---|---|\n");
    for (m = 0; m < 11; ++m) {
        rad_shading s;
        rad_shading_gpu g;
        double best_packed = 1e30, best_checked = 1e30, sum = 0.0;
        rad_shading_default(&s, m < 7 ? (rad_shading_model)m : RAD_SHADING_MICROFACET);
        if (m == 8 || m == 10) s.microfacet.alpha_y = 0.1f;
        if (m >= 9) { s.microfacet.ndf = RAD_NDF_BECKMANN; }
        if (m == 9) { s.microfacet.masking = RAD_MASKING_SEPARABLE; s.microfacet.diffuse = RAD_DIFFUSE_SHIRLEY; }
        if (rad_shading_pack(&s, &g, NULL) != RAD_SUCCESS) return 1;
        for (pass = 0; pass < passes; ++pass) {
            double t0, acc = 0.0;
            float r[3];
            t0 = now();
            for (i = 0; i < count; ++i) {
                rad_shade(&g, lv + 6 * i, lv + 6 * i + 3, n, t, b, NULL, r);
                acc += r[0];
            }
            t0 = now() - t0;
            if (t0 < best_packed) best_packed = t0;
            sum = acc;
            t0 = now();
            acc = 0.0;
            for (i = 0; i < count; ++i) {
                if (rad_shading_eval(&s, lv + 6 * i, lv + 6 * i + 3, n, t, b, r, NULL) != RAD_SUCCESS) return 1;
                acc += r[0];
            }
            t0 = now() - t0;
            if (t0 < best_checked) best_checked = t0;
            if (fabs(acc - sum) > 1e-3 * fabs(sum) + 1e-9) { fprintf(stderr, "checksums differ\n"); return 1; }
        }
        emit("| %s | %.1f | %.1f | %.4f |\n", names[m], 1e9 * best_packed / count, 1e9 * best_checked / count, sum / count);
    }
    free(lv);
    if (g_md) fclose(g_md);
    return 0;
}

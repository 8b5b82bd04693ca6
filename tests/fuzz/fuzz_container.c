/* fuzz_container.c - libFuzzer harness for the baked-data loader.
   Any bytes go to rad_container_create and rad_load_memory (copied into an aligned buffer, as a
   mapped file would be); then a second copy whose table, section and header checksums the
   harness recomputes goes through the same calls, so mutations also reach the structural and
   index checks behind the checksums. When a bake loads, everything it claims is used: every
   patch is located and smoothed, the matrix multiplies a vector and drives two Jacobi
   bounces, so an index that validation let through would be caught by the sanitizers.
   Build: clang -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -I. tests/fuzz/fuzz_container.c */
#define RADIOSITY_IMPLEMENTATION
#include "../../radiosity.h"
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void exercise(void *buf, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    void *buf = malloc(size ? size : 1);
    if (!buf) return 0;
    if (size) memcpy(buf, data, size);
    exercise(buf, size);
    if (size) memcpy(buf, data, size);
    fuzz_fix_checksums((unsigned char *)buf, size);
    exercise(buf, size);
    free(buf);
    return 0;
}

static void exercise(void *buf, size_t size)
{
    rad_container *c = NULL;
    rad_bake *b = NULL;
    if (rad_container_create(buf, size, NULL, &c) == RAD_SUCCESS) {
        uint32_t i, n = rad_container_section_count(c);
        volatile uint8_t sink = 0;
        for (i = 0; i < n; ++i) {
            const rad_section *s = rad_container_section(c, i);
            if (s->count && s->elem_size) sink ^= ((const uint8_t *)s->data)[s->count * s->elem_size - 1];
        }
        (void)sink;
        rad_container_destroy(c);
    }
    if (rad_load_memory(buf, size, NULL, &b) == RAD_SUCCESS) {
        uint32_t N = b->patches.count, t;
        float *x = (float *)calloc(3 * (size_t)N, sizeof(float)), *y = (float *)calloc(3 * (size_t)N, sizeof(float));
        float *v = (float *)calloc(3 * (size_t)(b->patches.vertex_count + 1), sizeof(float));
        if (x && y && v) {
            for (t = 0; t < b->patches.triangle_count; ++t) {
                float w[3];
                (void)rad_patches_locate(&b->patches, t, 0.25f, 0.5f, w);
            }
            (void)rad_patches_vertex_values(&b->patches, b->patches.areas, 1, v);
            if (b->F.rows == N) {
                rad_system sys;
                rad_solve_options so;
                for (t = 0; t < 3 * N; ++t) x[t] = b->E ? b->E[t] : 1.0f;
                (void)rad_matrix_multiply(&b->F, x, y, NULL);
                rad_system_init(&sys, &b->F, &b->patches, x);
                rad_solve_options_default(&so);
                so.bounces = 2;
                (void)rad_solve_jacobi(&sys, &so, y, NULL, NULL);
            }
        }
        free(x);
        free(y);
        free(v);
        rad_bake_destroy(b);
    }
}

/* fuzz_multibounce.c - libFuzzer harness for the multi-bounce loaders: rad_multibounce_load
   (F_mb in float or half, with or without permutations) and rad_multibounce_blocks_load (the
   BC1 and 3xBC4 forms with their scales, permutations and outliers), both views into
   container bytes. The input goes to rad_container_create (copied into an aligned buffer, as
   a mapped file would be), then a second copy with recomputed checksums (fuzz_common.h), so
   mutations reach the loaders' own checks. Every object a multi-bounce info section names
   (up to 4 per input) is loaded both ways; what loads is used:
   - dense: applied (indirect and total) and converted to the other precision;
   - blocks: applied (indirect and total) and decoded to the full matrix;
   - both: written back through their _sections into a new container, reopened, reloaded and
     applied again, which must give the same bits.
   Outputs must be finite whenever the loaded values are tame (fuzz_bounded); loaded NaN, Inf
   or huge values are counted, not a crash (value validation is not this harness's check).
   Build: clang -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -I. tests/fuzz/fuzz_multibounce.c */
#define RADIOSITY_IMPLEMENTATION
#include "../../radiosity.h"
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define FUZZ_MAX_OBJECTS 4u
#define FUZZ_MAX_N 1024u   /* larger N cannot come from inputs of libFuzzer's sizes anyway */
#define FUZZ_TAME 1e4f      /* below the largest half (65504): conversion keeps tame values finite */

static int mb_tame(const rad_multibounce *mb)
{
    size_t i, n3 = 3 * (size_t)mb->n * mb->n;
    if (mb->planes) return fuzz_bounded(mb->planes, n3, FUZZ_TAME);
    for (i = 0; i < n3; ++i) {
        float v = rad_half_to_float(mb->half[i]);
        if (!fuzz_bounded(&v, 1, FUZZ_TAME)) return 0;
    }
    return 1;
}

static int blocks_tame(const rad_multibounce_blocks *b)
{
    return fuzz_bounded(b->scales, 3 * (size_t)b->tiles_per_row * b->tiles_per_row, FUZZ_TAME) &&
           fuzz_bounded(b->outlier_values, 3 * (size_t)b->outlier_count, FUZZ_TAME);
}

/* the object written through its sections into a fresh container, reopened: 1 on success */
static int rewrite(const rad_section *s, uint32_t count, void **buf, rad_container **ct)
{
    size_t bytes;
    *buf = NULL;
    *ct = NULL;
    if (rad_container_size(s, count, &bytes) != RAD_SUCCESS) abort(); /* the loaded sizes fit once */
    *buf = malloc(bytes);
    if (!*buf) return 0;
    if (rad_container_write(s, count, *buf, bytes) != RAD_SUCCESS) abort();
    if (rad_container_create(*buf, bytes, NULL, ct) != RAD_SUCCESS) abort(); /* what the library wrote, it reads */
    return 1;
}

static void dense(const rad_multibounce *mb, const char *name, const float *E, float *o1, float *o2)
{
    size_t n3 = 3 * (size_t)mb->n;
    int tame = mb_tame(mb);
    rad_multibounce *other = NULL, *again = NULL;
    rad_section s[RAD_MB_MAX_SECTIONS];
    uint32_t count = 0;
    rad_container *ct = NULL;
    void *buf = NULL;
    if (!tame) fuzz_untamed("non-finite or huge F_mb entries, block scales or outliers");
    if (rad_multibounce_apply(mb, E, o1, RAD_OUTPUT_INDIRECT, NULL) == RAD_SUCCESS && tame) fuzz_check_finite(o1, n3);
    if (rad_multibounce_apply(mb, E, o2, RAD_OUTPUT_TOTAL, NULL) == RAD_SUCCESS && tame) fuzz_check_finite(o2, n3);
    if (rad_multibounce_convert(mb, mb->precision == RAD_MB_FLOAT ? RAD_MB_HALF : RAD_MB_FLOAT, NULL, &other) == RAD_SUCCESS &&
        rad_multibounce_apply(other, E, o2, RAD_OUTPUT_INDIRECT, NULL) == RAD_SUCCESS && tame)
        fuzz_check_finite(o2, n3);
    rad_multibounce_destroy(other);
    if (rad_multibounce_sections(mb, name, s, &count) == RAD_SUCCESS && rewrite(s, count, &buf, &ct)) {
        if (rad_multibounce_load(ct, name, NULL, &again) != RAD_SUCCESS) abort();
        if (rad_multibounce_apply(mb, E, o1, RAD_OUTPUT_INDIRECT, NULL) == RAD_SUCCESS &&
            (rad_multibounce_apply(again, E, o2, RAD_OUTPUT_INDIRECT, NULL) != RAD_SUCCESS || memcmp(o1, o2, n3 * sizeof(float)) != 0))
            abort();
    }
    rad_multibounce_destroy(again);
    rad_container_destroy(ct);
    free(buf);
}

static void blocks(const rad_multibounce_blocks *b, const char *name, const float *E, float *o1, float *o2)
{
    size_t n3 = 3 * (size_t)b->n;
    int tame = blocks_tame(b);
    rad_multibounce_blocks *again = NULL;
    rad_section s[RAD_MB_MAX_SECTIONS];
    uint32_t count = 0;
    rad_container *ct = NULL;
    void *buf = NULL;
    float *planes = (float *)malloc(3 * (size_t)b->n * b->n * sizeof(float));
    if (!tame) fuzz_untamed("non-finite or huge F_mb entries, block scales or outliers");
    if (rad_multibounce_blocks_apply(b, E, o1, RAD_OUTPUT_INDIRECT, NULL) == RAD_SUCCESS && tame) fuzz_check_finite(o1, n3);
    if (rad_multibounce_blocks_apply(b, E, o2, RAD_OUTPUT_TOTAL, NULL) == RAD_SUCCESS && tame) fuzz_check_finite(o2, n3);
    if (planes && rad_multibounce_blocks_decode(b, planes, NULL) == RAD_SUCCESS && tame)
        fuzz_check_finite(planes, 3 * (size_t)b->n * b->n);
    free(planes);
    if (rad_multibounce_blocks_sections(b, name, s, &count) == RAD_SUCCESS && rewrite(s, count, &buf, &ct)) {
        if (rad_multibounce_blocks_load(ct, name, NULL, &again) != RAD_SUCCESS) abort();
        if (rad_multibounce_blocks_apply(b, E, o1, RAD_OUTPUT_INDIRECT, NULL) == RAD_SUCCESS &&
            (rad_multibounce_blocks_apply(again, E, o2, RAD_OUTPUT_INDIRECT, NULL) != RAD_SUCCESS ||
             memcmp(o1, o2, n3 * sizeof(float)) != 0))
            abort();
    }
    rad_multibounce_blocks_destroy(again);
    rad_container_destroy(ct);
    free(buf);
}

static void exercise(const void *buf, size_t size)
{
    rad_container *ct = NULL;
    uint32_t i, n, objects = 0;
    if (rad_container_create(buf, size, NULL, &ct) != RAD_SUCCESS) return;
    n = rad_container_section_count(ct);
    for (i = 0; i < n && objects < FUZZ_MAX_OBJECTS; ++i) {
        const rad_section *info = rad_container_section(ct, i);
        rad_multibounce *mb = NULL;
        rad_multibounce_blocks *b = NULL;
        if (info->type != RAD_SECTION_MB_INFO) continue;
        ++objects;
        if (rad_multibounce_load(ct, info->name, NULL, &mb) == RAD_SUCCESS && mb->n <= FUZZ_MAX_N) {
            float *E = fuzz_fill(3 * (size_t)mb->n, 1.0f), *o1 = fuzz_fill(3 * (size_t)mb->n, 0.0f),
                  *o2 = fuzz_fill(3 * (size_t)mb->n, 0.0f);
            if (E && o1 && o2) dense(mb, info->name, E, o1, o2);
            free(E);
            free(o1);
            free(o2);
        }
        rad_multibounce_destroy(mb);
        if (rad_multibounce_blocks_load(ct, info->name, NULL, &b) == RAD_SUCCESS && b->n <= FUZZ_MAX_N) {
            float *E = fuzz_fill(3 * (size_t)b->n, 1.0f), *o1 = fuzz_fill(3 * (size_t)b->n, 0.0f),
                  *o2 = fuzz_fill(3 * (size_t)b->n, 0.0f);
            if (E && o1 && o2) blocks(b, info->name, E, o1, o2);
            free(E);
            free(o1);
            free(o2);
        }
        rad_multibounce_blocks_destroy(b);
    }
    rad_container_destroy(ct);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    void *buf = malloc(size ? size : 1);
    if (!buf) return 0;
    if (size) memcpy(buf, data, size);
    exercise(buf, size);
    fuzz_fix_checksums((unsigned char *)buf, size);
    if (size && memcmp(buf, data, size) != 0) exercise(buf, size);
    free(buf);
    return 0;
}

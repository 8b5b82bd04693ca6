/* fuzz_common.h - helpers shared by the libFuzzer harnesses in tests/fuzz/. Include it after
   radiosity.h with RADIOSITY_IMPLEMENTATION defined: it uses the container's private byte
   helpers (rad__get32, rad__crc32, ...), so the harness checks the same layout as the loader.
   Not part of the library. */
#ifndef RAD_FUZZ_COMMON_H
#define RAD_FUZZ_COMMON_H
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Recomputes the checksums of a container in place: each section whose table entry lies in
   range, then the section table, then the header. A mutated input repaired this way gets
   past the CRC-32 checks, so mutations reach the structural, index and value checks behind
   them (every loader checks the checksums first). */
static inline void fuzz_fix_checksums(unsigned char *p, size_t size)
{
    uint32_t count, i;
    if (size < 64) return;
    count = rad__get32(p + 8);
    if (count > 4096 || 64 + 64 * (size_t)count > size) return;
    for (i = 0; i < count; ++i) {
        unsigned char *e = p + 64 + 64 * (size_t)i;
        uint64_t off = rad__get64(e + 16), bytes = rad__get64(e + 24);
        if (off <= size && bytes <= size - off) rad__put32(e + 32, rad__crc32(p + off, (size_t)bytes));
    }
    rad__put32(p + 36, rad__crc32(p + 64, 64 * (size_t)count));
    rad__put32(p + 60, rad__crc32(p, 60));
}

/* Aborts (a crash for libFuzzer) when one of the n floats is NaN or infinite. */
static inline void fuzz_check_finite(const float *v, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i)
        if (!(v[i] == v[i]) || v[i] - v[i] != 0.0f) abort();
}

/* 1 when every one of the n floats is finite and |v| <= bound: inputs this tame cannot
   overflow a sum of a few thousand products, so an output that is not finite would be a bug
   in the code, not in the data. (NaN, Inf and absurd values that a loader accepts are a
   value-validation question, counted by the harnesses but not a crash.) */
static inline int fuzz_bounded(const float *v, size_t n, float bound)
{
    size_t i;
    for (i = 0; i < n; ++i)
        if (!(v[i] >= -bound && v[i] <= bound)) return 0;
    return 1;
}

/* Loaded objects (one per load: several per input and pass) whose values were not tame
   enough for fuzz_bounded (NaN, Inf or huge values that the loaders let through): counted,
   and the count printed when the process exits, so a run's log says how often it met them. */
static unsigned long fuzz_untamed_count;
static const char *fuzz_untamed_what = "";
static void fuzz_untamed_report(void)
{
    if (fuzz_untamed_count)
        fprintf(stderr, "fuzz: %lu loaded objects held %s (not checked for finite outputs)\n", fuzz_untamed_count,
                fuzz_untamed_what);
}
static inline void fuzz_untamed(const char *what)
{
    if (!fuzz_untamed_count++) {
        fuzz_untamed_what = what;
        atexit(fuzz_untamed_report);
    }
}

/* 3n floats, every one 'value' (NULL when out of memory) */
static inline float *fuzz_fill(size_t n3, float value)
{
    float *v = (float *)malloc((n3 ? n3 : 1) * sizeof(float));
    size_t i;
    if (v)
        for (i = 0; i < n3; ++i) v[i] = value;
    return v;
}

#endif

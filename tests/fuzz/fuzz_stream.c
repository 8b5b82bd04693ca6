/* fuzz_stream.c - libFuzzer harness for the row stream (rad_row_stream_create), the loader
   that reads a bake from a path and never holds its matrix: the input bytes are written to
   a temporary file (one per process, rewritten for every input) and opened as a stream;
   then a second copy whose checksums the harness recomputes (fuzz_common.h), so mutations
   also reach the checks behind the header, table, patch and offset CRC-32s and, above all,
   the rows, which the stream reads unchecksummed one at a time.
   When a stream opens, rows go through a rad_local of small capacity: a fixed walk of adds
   and removes (new members, a hidden member shown again, evictions once the set is full),
   one explicit eviction, an apply (its result must be finite when it succeeds), then a
   rebuild from scratch over a few patches, and a final apply. Any row that validation let
   through with a bad index or a repeat reaches the sanitizers through the update's scatter.
   Build: clang -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -I. tests/fuzz/fuzz_stream.c */
#define _POSIX_C_SOURCE 200809L /* mkstemp, unlink */
#define RADIOSITY_IMPLEMENTATION
#include "../../radiosity.h"
#include "fuzz_common.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define FUZZ_CAPACITY 6u /* members of the local set: small, so adds soon evict */
#define FUZZ_STEPS 16u   /* steps of the walk */

static char stream_path[4096];

static void remove_stream_file(void) { if (stream_path[0]) unlink(stream_path); }

/* the per-process file the inputs are written to ($TMPDIR or /tmp), made once */
static const char *stream_file(void)
{
    if (!stream_path[0]) {
        const char *dir = getenv("TMPDIR");
        int fd;
        snprintf(stream_path, sizeof(stream_path), "%s/rad_fuzz_stream_XXXXXX", dir && dir[0] ? dir : "/tmp");
        fd = mkstemp(stream_path);
        if (fd < 0) abort(); /* a harness that cannot write its file tests nothing */
        close(fd);
        atexit(remove_stream_file);
    }
    return stream_path;
}

static int visible(const rad_local *L, uint32_t p)
{
    uint32_t slot = L->patch_slot[p];
    return slot != RAD_NONE && !L->slot_hidden[slot];
}

static void apply_and_check(const rad_local *L, const float *E, float *out)
{
    uint32_t i;
    memset(out, 0, sizeof(float) * 3 * (size_t)L->n);
    if (rad_local_apply(L, E, NULL, 0, NULL, 0, out, RAD_OUTPUT_TOTAL, NULL) == RAD_SUCCESS)
        for (i = 0; i < L->slot_end; ++i)
            if (L->slot_patch[i] != RAD_NONE) fuzz_check_finite(out + 3 * (size_t)L->slot_patch[i], 3);
}

static void exercise(rad_row_stream *stream)
{
    rad_row_source src;
    rad_local_options lo;
    rad_local *L = NULL;
    float *E, *out;
    uint32_t k, n, set[FUZZ_CAPACITY], count, prev;
    rad_row_stream_source(stream, &src);
    n = src.n;
    (void)rad_row_stream_memory(stream);
    rad_local_options_default(&lo);
    lo.capacity = n < FUZZ_CAPACITY ? n : FUZZ_CAPACITY;
    if (rad_local_create(&src, &lo, NULL, &L) != RAD_SUCCESS) return;
    E = fuzz_fill(3 * (size_t)n, 1.0f);
    out = fuzz_fill(3 * (size_t)n, 0.0f);
    if (E && out) {
        /* the walk: patch k(k+1)/2 mod n (0, 1, 3, 6, 10, ...: low rows first, then spread
           out) joins the set, or leaves it when it is visible; every third step the patch of
           the step before is removed too, so hidden members pile up and later adds evict */
        for (k = 0, prev = RAD_NONE; k < FUZZ_STEPS; ++k) {
            uint32_t p = (uint32_t)(((uint64_t)k * (k + 1u) / 2u) % n);
            if (visible(L, p)) (void)rad_local_remove(L, p, NULL);
            else (void)rad_local_add(L, p, NULL);
            if (k % 3u == 2u && prev != RAD_NONE && visible(L, prev)) (void)rad_local_remove(L, prev, NULL);
            prev = p;
        }
        apply_and_check(L, E, out);
        for (k = 0; k < L->slot_end; ++k)
            if (L->slot_patch[k] != RAD_NONE) { (void)rad_local_evict(L, L->slot_patch[k], NULL); break; }
        apply_and_check(L, E, out);
        /* from scratch: the first patches, as many as fit */
        for (count = 0; count < lo.capacity; ++count) set[count] = (uint32_t)(((uint64_t)count * 3u + 2u) % n);
        for (k = 1; k < count; ++k) /* drop repeats (n smaller than the set) */
            if (set[k] == set[0]) { count = k; break; }
        if (rad_local_rebuild(L, set, count, NULL) == RAD_SUCCESS) apply_and_check(L, E, out);
    }
    free(E);
    free(out);
    rad_local_destroy(L);
}

static void run(const uint8_t *bytes, size_t size)
{
    const char *path = stream_file();
    FILE *f = fopen(path, "wb");
    rad_row_stream *s = NULL;
    if (!f) abort();
    if (size && fwrite(bytes, 1, size, f) != size) abort();
    if (fclose(f) != 0) abort();
    if (rad_row_stream_create(path, NULL, &s) == RAD_SUCCESS) {
        exercise(s);
        rad_row_stream_destroy(s);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    unsigned char *copy;
    run(data, size);
    copy = (unsigned char *)malloc(size ? size : 1);
    if (!copy) return 0;
    if (size) memcpy(copy, data, size);
    fuzz_fix_checksums(copy, size);
    if (size && memcmp(copy, data, size) != 0) run(copy, size); /* skip when nothing changed */
    free(copy);
    return 0;
}

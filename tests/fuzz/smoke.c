/* smoke.c - the libFuzzer harnesses of tests/fuzz/ in one binary, for the short runs of
   tests/run.sh: the implementation is compiled once instead of once per harness (each harness
   includes it, and uses its internal rad__ helpers, so they cannot share an object). The
   harness code is included unchanged; FUZZ_TARGET=container|scene|stream|multibounce|temporal|vp
   in the environment picks the one a run drives. make fuzz still builds one binary each. */
#define _POSIX_C_SOURCE 200809L /* first, as fuzz_stream.c asks: mkstemp, unlink */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LLVMFuzzerTestOneInput fuzz_container_one
#define exercise container_exercise
#include "fuzz_container.c"
#undef LLVMFuzzerTestOneInput
#undef exercise

#define LLVMFuzzerTestOneInput fuzz_scene_one
#define exercise scene_exercise
#include "fuzz_scene.c"
#undef LLVMFuzzerTestOneInput
#undef exercise

#define LLVMFuzzerTestOneInput fuzz_stream_one
#define exercise stream_exercise
#include "fuzz_stream.c"
#undef LLVMFuzzerTestOneInput
#undef exercise

#define LLVMFuzzerTestOneInput fuzz_multibounce_one
#define exercise multibounce_exercise
#include "fuzz_multibounce.c"
#undef LLVMFuzzerTestOneInput
#undef exercise

#define LLVMFuzzerTestOneInput fuzz_temporal_one
#define exercise temporal_exercise
#include "fuzz_temporal.c"
#undef LLVMFuzzerTestOneInput
#undef exercise

#define LLVMFuzzerTestOneInput fuzz_vp_one
#define exercise vp_exercise
#include "fuzz_vp.c"
#undef LLVMFuzzerTestOneInput
#undef exercise

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int (*fuzz_smoke_target)(const uint8_t *, size_t);

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    static const struct { const char *name; int (*fn)(const uint8_t *, size_t); } harnesses[] = {
        { "container", fuzz_container_one }, { "scene", fuzz_scene_one }, { "stream", fuzz_stream_one },
        { "multibounce", fuzz_multibounce_one }, { "temporal", fuzz_temporal_one }, { "vp", fuzz_vp_one },
    };
    const char *want = getenv("FUZZ_TARGET");
    size_t i;
    (void)argc;
    (void)argv;
    for (i = 0; want && i < sizeof(harnesses) / sizeof(harnesses[0]); ++i)
        if (!strcmp(want, harnesses[i].name)) fuzz_smoke_target = harnesses[i].fn;
    if (!fuzz_smoke_target) {
        fprintf(stderr, "fuzz_smoke: FUZZ_TARGET='%s' names no harness (container scene stream multibounce temporal vp)\n", want ? want : "");
        exit(2);
    }
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    return fuzz_smoke_target(data, size);
}

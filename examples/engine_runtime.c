/* engine_runtime.c - the engine's frame loop over a bake (docs/methods/bake.md "Run time"):
   rad_baker_run bakes the Cornell box with a point lamp of the engine's, then
   rad_baker_runtime_create keeps what the bake needs, and each frame one call,
   rad_baker_runtime_update, takes the lamp where it is now and refreshes the vertex light and
   the probes within a budget in milliseconds. While the lamp moves the frames follow it by a
   temporal step; when it stops they refine until the outputs equal a bake with the lamp
   there (phase CONVERGED), after which a frame costs nothing. Then the ceiling light (group
   0, the box's emissive material) is dimmed to 20% by rad_baker_runtime_set_groups, and the
   frames converge again. The bake keeps its solver objects (options.keep), so the runtime
   borrows them instead of building them again. examples/engine_bake.c is the
   bake and the light layers; examples/realtime.c is the same loop written with the lower-
   level calls. Prints what each frame did and checks that every vertex value is finite and
   >= 0 and that the frames converge (exit 1 if not). */
#define RADIOSITY_IMPLEMENTATION
#include "radiosity.h"
#include <math.h>
#include <stdio.h>
#include <string.h>

static const char *phase_name(rad_baker_runtime_phase p)
{
    return p == RAD_BAKER_RUNTIME_MOVING ? "moving" : p == RAD_BAKER_RUNTIME_REFINING ? "refining"
                                         : p == RAD_BAKER_RUNTIME_EXACT ? "exact" : "converged";
}

static uint32_t count_bad(const float *v, size_t n)
{
    uint32_t bad = 0;
    size_t i;
    for (i = 0; i < n; ++i) bad += !(v[i] >= 0.0f && v[i] < 1e30f);
    return bad;
}

int main(void)
{
    rad_baker_desc desc;
    rad_baker_options options;
    rad_baker_result *baked = NULL;
    rad_baker_runtime *runtime = NULL;
    rad_baker_light lamp;
    rad_baker_frame frame;
    rad_light now;
    rad_result r;
    uint32_t f, bad = 0;
    int dimmed = 0;

    memset(&desc, 0, sizeof desc);
    rad_cornell_box(&desc.scene, NULL);
    memset(&lamp, 0, sizeof lamp);
    lamp.light.type = RAD_LIGHT_POINT;
    lamp.light.position[0] = 0.28f; lamp.light.position[1] = 0.35f; lamp.light.position[2] = 0.28f;
    lamp.light.color[0] = lamp.light.color[1] = lamp.light.color[2] = 0.05f; /* W/sr */
    lamp.group = 1;                               /* the ceiling's emission is group 0 */
    desc.lights = &lamp;
    desc.light_count = 1;
    desc.outputs = RAD_BAKER_VERTEX | RAD_BAKER_PROBES;
    memset(&options, 0, sizeof options);
    options.method = RAD_BAKER_VIRTUAL_PATCHES;   /* AUTO would take classic for this small box */
    options.vp_resolution = 8;
    options.keep = 1;                             /* the runtime borrows the bake's objects */

    r = rad_baker_run(&desc, &options, NULL, &baked);
    if (r == RAD_SUCCESS) r = rad_baker_runtime_create(&desc, &options, baked, NULL, NULL, &runtime);
    if (r != RAD_SUCCESS) {
        fprintf(stderr, "engine_runtime: %s\n", rad_result_string(r));
        rad_baker_result_destroy(baked);
        return 1;
    }
    {
        double mean = 0.0;
        for (f = 0; f < baked->vertex_count; ++f) mean += baked->vertex[3 * f + 1];
        printf("baked %u virtual patches, %u vertices (mean irradiance %.5f), %u probes\n", baked->patch_count,
               baked->vertex_count, mean / baked->vertex_count, baked->probe_count);
    }
    printf("frame  phase      sweeps  probes  planned ms  mean vertex irradiance\n");
    now = lamp.light;
    for (f = 1; f <= 120; ++f) {
        double mean = 0.0;
        uint32_t i;
        if (f <= 24) { /* the lamp swings across the room for 24 frames, then stays */
            float a = 3.14159265f * (float)f / 24.0f;
            now.position[0] = 0.28f + 0.15f * sinf(a);
            now.position[2] = 0.28f - 0.12f * sinf(a);
        }
        r = rad_baker_runtime_update(runtime, &now, 1, 2.0, &frame); /* a 2 ms budget */
        if (r != RAD_SUCCESS) {
            fprintf(stderr, "rad_baker_runtime_update: %s\n", rad_result_string(r));
            break;
        }
        /* an engine uploads frame.vertex (and frame.probes) here */
        for (i = 0; i < baked->vertex_count; ++i) mean += frame.vertex[3 * i + 1];
        bad += count_bad(frame.vertex, 3 * (size_t)baked->vertex_count); /* (SH coefficients may be negative) */
        if (f <= 3 || f % 6 == 0 || frame.phase == RAD_BAKER_RUNTIME_CONVERGED)
            printf("%5u  %-9s  %6u  %6u  %10.3f  %.5f\n", f, phase_name(frame.phase), frame.sweeps, frame.probes_refreshed,
                   frame.planned_ms, mean / baked->vertex_count);
        if (frame.phase == RAD_BAKER_RUNTIME_CONVERGED && dimmed) break;
        if (frame.phase == RAD_BAKER_RUNTIME_CONVERGED) {
            const float dim[6] = { 0.2f, 0.2f, 0.2f, 1.0f, 1.0f, 1.0f }; /* ceiling at 20%, lamp as is */
            printf("the ceiling light dimmed to 20%%\n");
            r = rad_baker_runtime_set_groups(runtime, dim); /* from the next update on */
            if (r != RAD_SUCCESS) break;
            dimmed = 1;
        }
    }
    if (r == RAD_SUCCESS && frame.phase != RAD_BAKER_RUNTIME_CONVERGED) fprintf(stderr, "engine_runtime: not converged\n"), bad++;
    if (bad) fprintf(stderr, "%u values not finite or negative\n", bad);
    rad_baker_runtime_destroy(runtime);
    rad_baker_result_destroy(baked);
    return r == RAD_SUCCESS && bad == 0 ? 0 : 1;
}

/* engine_bake.c - the engine path of the README in one call: an engine keeps its own direct
   lighting and wants the bounced light at the vertices of its own meshes, and probes for what
   moves. The meshes are the built-in Cornell box's (any rad_mesh_desc works), lit by its
   emissive ceiling light (light group 0) and one point light of the engine's (group 1).
   rad_baker_run picks the method for the scene and the budget, logs its estimate, and returns
   one layer per group; rad_baker_mix then dims or tints each group without a new bake. Two
   sky bands (options.sky_bands) add the sky through the box's open front as four SH layers:
   rad_baker_mix_sky relights them by any sky, here a bluish gradient, brighter at the zenith.
   examples/learn_vertex_light.c does the per-vertex part step by step with the lower-level
   calls. Prints the mean per mesh, then after a mix, and checks that every value is finite
   and >= 0 (exit 1 if not). */
#define RADIOSITY_IMPLEMENTATION
#include "radiosity.h"
#include <stdio.h>
#include <string.h>

static void on_log(void *user, rad_log_level level, const char *message)
{
    (void)user;
    fprintf(stderr, "%s: %s\n", level == RAD_LOG_ERROR ? "error" : level == RAD_LOG_WARNING ? "warning" : "info", message);
}

static int on_progress(void *user, float fraction)
{
    int *tenth = (int *)user;
    while (fraction >= 0.1f * (float)(*tenth + 1) && *tenth < 10) fprintf(stderr, "%d%% ", 10 * ++*tenth);
    if (*tenth == 10) fprintf(stderr, "\n"), ++*tenth;
    return 0; /* non-zero cancels the bake */
}

static uint32_t print_means(const rad_baker_desc *d, const rad_baker_result *R, const char *title)
{
    uint32_t m, i, bad = 0;
    printf("%s\n", title);
    for (m = 0; m < R->mesh_count; ++m) {
        const float *v = R->vertex + 3 * (size_t)R->vertex_first[m];
        uint32_t n = R->vertex_first[m + 1] - R->vertex_first[m];
        double mean[3] = { 0, 0, 0 };
        for (i = 0; i < 3 * n; ++i) {
            mean[i % 3] += v[i] / n;
            bad += !(v[i] >= 0.0f && v[i] < 1e30f);
        }
        printf("  %-10s %2u vertices, mean bounced irradiance %.4f %.4f %.4f W/m^2\n", d->scene.meshes[m].name, n, mean[0],
               mean[1], mean[2]);
    }
    return bad;
}

int main(void)
{
    rad_baker_desc desc;
    rad_baker_options options;
    rad_baker_result *result = NULL;
    rad_baker_light lamp;
    rad_context ctx;
    rad_result r;
    int tenth = 0;
    uint32_t bad;
    /* group 0 (the ceiling light) at half strength, group 1 (the lamp) warm and twice as bright */
    const float mix[6] = { 0.5f, 0.5f, 0.5f, 2.0f, 1.4f, 0.8f };

    memset(&desc, 0, sizeof desc);
    rad_cornell_box(&desc.scene, NULL);            /* the engine's meshes and materials */
    memset(&lamp, 0, sizeof lamp);                 /* and one light of its own, in group 1 */
    lamp.light.type = RAD_LIGHT_POINT;
    lamp.light.position[0] = 0.28f; lamp.light.position[1] = 0.35f; lamp.light.position[2] = 0.28f;
    lamp.light.color[0] = lamp.light.color[1] = lamp.light.color[2] = 0.05f; /* W/sr */
    lamp.group = 1;
    desc.lights = &lamp;
    desc.light_count = 1;
    desc.outputs = RAD_BAKER_VERTEX | RAD_BAKER_PROBES; /* the emissive materials are group 0 */

    memset(&options, 0, sizeof options);           /* zero: the defaults (1 GiB, 600 s, ...) */
    options.patches = 800;
    options.sky_bands = 2;                         /* bands 0..1 of the sky: 4 more layers */
    memset(&ctx, 0, sizeof ctx);
    ctx.log = on_log;
    ctx.progress = on_progress;
    ctx.progress_user = &tenth;

    r = rad_baker_run(&desc, &options, &ctx, &result);
    if (r != RAD_SUCCESS) {
        fprintf(stderr, "rad_baker_run: %s\n", rad_result_string(r));
        return 1;
    }
    printf("chose %s: %s\n%u probes on a %u x %u x %u grid\n",
           result->method == RAD_BAKER_CLASSIC ? "classic patches" : "virtual patches", result->reason,
           result->probe_count, result->probe_grid[0], result->probe_grid[1], result->probe_grid[2]);
    bad = print_means(&desc, result, "both groups at full strength:");
    r = rad_baker_mix(result, mix, NULL);          /* vertices and probes again, no new bake */
    if (r == RAD_SUCCESS) bad += print_means(&desc, result, "ceiling at 50%, lamp warm and at 200%:");
    else fprintf(stderr, "rad_baker_mix: %s\n", rad_result_string(r));
    if (r == RAD_SUCCESS) {
        /* the sky L(w) = (0.6 + 0.4 y) (0.5 0.7 1.0), y up: its SH coefficients in closed form,
           l_0 = sqrt(4 pi) a and l_1 = sqrt(4 pi / 3) b per channel (Y_1 is the y band; an
           engine projects its own sky map with rad_sky_project_sh) */
        const float tint[3] = { 0.5f, 0.7f, 1.0f };
        float sky[12];
        int c;
        memset(sky, 0, sizeof sky);
        for (c = 0; c < 3; ++c) {
            sky[c] = 3.5449077f * 0.6f * tint[c];
            sky[3 + c] = 2.0466534f * 0.4f * tint[c];
        }
        r = rad_baker_mix_sky(result, mix, sky, NULL);
        if (r == RAD_SUCCESS) bad += print_means(&desc, result, "the same, and a blue sky through the open front:");
        else fprintf(stderr, "rad_baker_mix_sky: %s\n", rad_result_string(r));
    }
    if (bad) fprintf(stderr, "%u values not finite or negative\n", bad);
    rad_baker_result_destroy(result);
    return r == RAD_SUCCESS && bad == 0 ? 0 : 1;
}

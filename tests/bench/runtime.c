/* runtime.c - a light that moves over a bake (rad_baker_runtime_*, docs/methods/bake.md "Run
   time"; docs/performance-notes.md "Moving lights over a bake"). Sponza (DIR/sponza.obj, or
   $RAD_DATA_DIR; without it the Cornell box) unwrapped by the tool's simple unwrap into a
   --size^2 lightmap, one stone material, a sun that stays and a point light that circles the
   atrium; rad_baker_run with virtual patches at --res, --probes probes on a grid, then the
   runtime: --frames frames of the moving light within --budget ms, each timed (wall and
   process CPU), then the same frames with no budget (every output every frame). At --checks
   frames the outputs are compared with a fresh rad_baker_run with the lights there (mean
   relative difference of the vertex light, the lightmap's valid texels and the probes), and at
   the end the light rests and the frames run until CONVERGED, compared again.
   --orbit N: the point light turns once in N frames (default: --frames).
   The bake keeps its solver objects (rad_baker_options.keep) and the runtime is created twice:
   building its own (a copy of the result without them) and borrowing the kept ones.
   First, the layer mix on one core: 8 groups into a 1024 x 1024 lightmap (rad_baker_mix_layers,
   CPU ms per call, the median of 15), and 17 planes (8 groups and 9 sky layers: the pass of
   rad_baker_mix_sky, the same kernel); --mix-only stops after it.
   Usage: runtime [--data DIR] [--res N] [--size N] [--probes N] [--frames N] [--budget MS]
                  [--checks N] [--orbit N] [--quick] [--mix-only] [--append FILE.md] */
#include "bench_common.h" /* first: it asks for POSIX clock_gettime */
#define RADIOSITY_IMPLEMENTATION
#include "radiosity.h"
#include "bench_scenes.h"
#include "tools/tool.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double cpu_now(void)
{
#if defined(CLOCK_PROCESS_CPUTIME_ID)
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
#else
    return (double)clock() / CLOCKS_PER_SEC;
#endif
}

static void check(rad_result r, const char *what)
{
    if (r != RAD_SUCCESS) fprintf(stderr, "runtime: %s failed: %s\n", what, rad_result_string(r)), exit(1);
}

static double rel(const float *a, const float *b, size_t n, const uint8_t *valid, uint32_t stride)
{
    double d = 0.0, s = 0.0;
    size_t i;
    for (i = 0; i < n; ++i) {
        if (valid && !(valid[i / stride] & RAD_TEXEL_VALID)) continue;
        d += fabs((double)a[i] - b[i]);
        s += fabs((double)b[i]);
    }
    return s > 0.0 ? d / s : d;
}

static int cmp_double(const void *a, const void *b)
{
    return (*(const double *)a > *(const double *)b) - (*(const double *)a < *(const double *)b);
}

static rad_baker_desc g_desc;
static rad_baker_options g_opt;
static rad_baker_light g_lights[2];
static float g_centre[3], g_radius;
static uint32_t g_orbit; /* frames per turn of the point light (0: --frames) */

static void light_at(uint32_t frame, uint32_t frames, rad_light *out)
{
    float a = 6.2831853f * (float)frame / (float)(g_orbit ? g_orbit : frames);
    *out = g_lights[1].light;
    out->position[0] = g_centre[0] + g_radius * cosf(a);
    out->position[2] = g_centre[2] + g_radius * sinf(a);
}

static void serial_for(void *user, uint32_t count, rad_task_fn fn, void *data)
{
    uint32_t i;
    (void)user;
    for (i = 0; i < count; ++i) fn(data, i);
}

/* The mix of 'planes' layers of a 1024 x 1024 RGB lightmap on one core: CPU ms per call, the
   median of 15 after one warm-up call. */
static double mix_ms(uint32_t planes, float *layers, float *out)
{
    rad_context ctx;
    float rgb[3 * 80];
    double ms[15];
    size_t count3 = 3u * 1024u * 1024u;
    uint32_t i, k;
    memset(&ctx, 0, sizeof ctx);
    ctx.parallel_for = serial_for;
    ctx.task_count = 1;
    for (i = 0; i < 3 * planes; ++i) rgb[i] = 0.5f + 0.01f * (float)i;
    for (k = 0; k < 16; ++k) {
        double c = cpu_now();
        check(rad_baker_mix_layers(layers, planes, count3, rgb, out, &ctx), "rad_baker_mix_layers");
        if (k) ms[k - 1] = 1e3 * (cpu_now() - c);
    }
    qsort(ms, 15, sizeof(double), cmp_double);
    return ms[7];
}

/* The mix of 8 groups into a 1024 x 1024 lightmap from float layers and from the same layers
   packed as RGB9E5 (rad_baker_mix_layers_rgb9e5), one call of each in turn on one core: the
   medians of 15 CPU times each after a warm-up call of each, side by side in the same run. */
static void mix_packed_ms(const float *layers, const uint32_t *packed, float *out, double *float_ms, double *packed_ms)
{
    rad_context ctx;
    float rgb[3 * 8];
    double fm[15], pm[15];
    size_t texels = 1024u * 1024u;
    uint32_t i, k;
    memset(&ctx, 0, sizeof ctx);
    ctx.parallel_for = serial_for;
    ctx.task_count = 1;
    for (i = 0; i < 3 * 8; ++i) rgb[i] = 0.5f + 0.01f * (float)i;
    for (k = 0; k < 16; ++k) {
        double c = cpu_now(), c1;
        check(rad_baker_mix_layers(layers, 8, 3 * texels, rgb, out, &ctx), "rad_baker_mix_layers");
        c1 = cpu_now();
        check(rad_baker_mix_layers_rgb9e5(packed, 8, texels, rgb, out, &ctx), "rad_baker_mix_layers_rgb9e5");
        if (k) fm[k - 1] = 1e3 * (c1 - c), pm[k - 1] = 1e3 * (cpu_now() - c1);
    }
    qsort(fm, 15, sizeof(double), cmp_double);
    qsort(pm, 15, sizeof(double), cmp_double);
    *float_ms = fm[7];
    *packed_ms = pm[7];
}

/* the runtime's frame against a fresh bake with the lights of that frame */
static void compare_bake(const rad_baker_frame *f, const rad_light *lights, const char *what)
{
    rad_baker_light bl[2];
    rad_baker_desc d = g_desc;
    rad_baker_result *Q = NULL;
    double t = now();
    bl[0] = g_lights[0];
    bl[1] = g_lights[1];
    bl[0].light = lights[0];
    bl[1].light = lights[1];
    d.lights = bl;
    check(rad_baker_run(&d, &g_opt, NULL, &Q), "rad_baker_run (the check)");
    emit("| %s | %.2f%% | %.2f%% | %.2f%% | %.0f s |\n", what,
         100.0 * rel(f->vertex, Q->vertex, 3 * (size_t)Q->vertex_count, NULL, 1),
         100.0 * rel(f->lightmap, Q->lightmap, 3 * (size_t)Q->lightmap_width * Q->lightmap_height, Q->lightmap_flags, 3),
         100.0 * rel(f->probes, Q->probes, 27 * (size_t)Q->probe_count, NULL, 1), now() - t);
    rad_baker_result_destroy(Q);
}

int main(int argc, char **argv)
{
    const char *dir = getenv("RAD_DATA_DIR"), *append = NULL;
    uint32_t res = 27, size = 1024, nprobes = 512, frames = 60, checks = 2, i, k, nv = 0, nt = 0, charts = 0;
    double budget = 16.0, t, c, t_bake, c_bake, t_rt, c_rt, t_kept, c_kept, *wall, *cpu, sum_plan = 0.0, lm_share = 0.0, pr_share = 0.0;
    int quick = 0, have_sponza, mix_only = 0;
    char path[4096];
    float *pos = NULL, *uvs = NULL, *probe_at;
    uint32_t *idx = NULL, side, over = 0;
    rad_material stone = {{0.7f, 0.68f, 0.63f}, {0.0f, 0.0f, 0.0f}, 0, 0, 0, 0, 0.0f};
    rad_scene_desc sd;
    rad_mesh_desc mesh, flat;
    rad_scene *S = NULL;
    rad_baker_result *R = NULL;
    rad_baker_runtime *rt = NULL;
    rad_baker_frame f;
    rad_light lights[2];
    for (i = 1; i < (uint32_t)argc; ++i) {
        if (i + 1 < (uint32_t)argc && !strcmp(argv[i], "--data")) dir = argv[++i];
        else if (i + 1 < (uint32_t)argc && !strcmp(argv[i], "--res")) res = (uint32_t)atoi(argv[++i]);
        else if (i + 1 < (uint32_t)argc && !strcmp(argv[i], "--size")) size = (uint32_t)atoi(argv[++i]);
        else if (i + 1 < (uint32_t)argc && !strcmp(argv[i], "--probes")) nprobes = (uint32_t)atoi(argv[++i]);
        else if (i + 1 < (uint32_t)argc && !strcmp(argv[i], "--frames")) frames = (uint32_t)atoi(argv[++i]);
        else if (i + 1 < (uint32_t)argc && !strcmp(argv[i], "--budget")) budget = atof(argv[++i]);
        else if (i + 1 < (uint32_t)argc && !strcmp(argv[i], "--checks")) checks = (uint32_t)atoi(argv[++i]);
        else if (i + 1 < (uint32_t)argc && !strcmp(argv[i], "--orbit")) g_orbit = (uint32_t)atoi(argv[++i]);
        else if (i + 1 < (uint32_t)argc && !strcmp(argv[i], "--append")) append = argv[++i];
        else if (!strcmp(argv[i], "--quick")) quick = 1;
        else if (!strcmp(argv[i], "--mix-only")) mix_only = 1;
        else return fprintf(stderr, "usage: runtime [--data DIR] [--res N] [--size N] [--probes N] [--frames N] "
                                    "[--budget MS] [--checks N] [--orbit N] [--quick] [--mix-only] [--append FILE.md]\n"), 2;
    }
    if (quick) res = res < 12 ? res : 12, size = size < 256 ? size : 256, nprobes = nprobes < 64 ? nprobes : 64,
               frames = frames < 20 ? frames : 20, checks = checks < 1 ? checks : 1;
    if (frames < 2 || nprobes < 1 || size < 16) return fprintf(stderr, "runtime: --frames >= 2, --probes >= 1, --size >= 16\n"), 2;
    if (append && !(g_md = fopen(append, "a"))) return fprintf(stderr, "runtime: cannot open %s\n", append), 1;
    {
        size_t n = 3u * 1024u * 1024u, j;
        float *layers = (float *)malloc(17 * n * sizeof(float)), *out = (float *)malloc(n * sizeof(float));
        if (!layers || !out) return fprintf(stderr, "runtime: out of memory for the mix\n"), 1;
        for (j = 0; j < 17 * n; ++j) layers[j] = (float)(j % 1009) * 1e-3f;
        emit("\n### Mixing light layers (rad_baker_mix_layers, one core)\n\n");
        emit("8 groups into a 1024x1024 RGB lightmap: %.2f ms CPU (median of 15); 8 groups and 9 sky layers "
             "(rad_baker_mix_sky's pass): %.2f ms\n",
             mix_ms(8, layers, out), mix_ms(17, layers, out));
        {
            uint32_t *packed = (uint32_t *)malloc(8 * (n / 3) * sizeof(uint32_t));
            double fms, pms;
            if (!packed) return fprintf(stderr, "runtime: out of memory for the packed mix\n"), 1;
            check(rad_rgb9e5_pack(layers, 8 * (n / 3), packed, NULL), "rad_rgb9e5_pack");
            mix_packed_ms(layers, packed, out, &fms, &pms);
            emit("8 groups packed as RGB9E5 (rad_baker_mix_layers_rgb9e5, 4 bytes a texel): %.2f ms CPU against %.2f ms "
                 "for the float layers in the same run (%.2fx)\n", pms, fms, pms / fms);
            free(packed);
        }
        free(layers), free(out);
        if (mix_only) return 0;
    }
    snprintf(path, sizeof path, "%s/sponza.obj", dir ? dir : ".");
    have_sponza = dir && bench_load_obj(path, &pos, &nv, &idx, &nt);

    /* the scene, unwrapped: one unindexed mesh with a lightmap uv set */
    memset(&sd, 0, sizeof sd);
    if (have_sponza) {
        memset(&mesh, 0, sizeof mesh);
        mesh.positions = pos, mesh.vertex_count = nv, mesh.indices = idx, mesh.triangle_count = nt;
        sd.meshes = &mesh, sd.mesh_count = 1, sd.materials = &stone, sd.material_count = 1;
        sd.flags = RAD_SCENE_SKIP_DEGENERATE;
    } else {
        rad_cornell_box(&sd, NULL);
    }
    check(rad_scene_create(&sd, NULL, &S), "rad_scene_create");
    uvs = (float *)calloc(6 * (size_t)S->triangle_count, sizeof(float));
    side = size;
    {
        uint32_t h = size;
        if (!uvs || tool_unwrap("runtime", "--size", S, &side, &h, NULL, uvs, &charts)) return 1;
    }
    memset(&flat, 0, sizeof flat);
    flat.positions = S->positions;
    flat.vertex_count = 3 * S->triangle_count;
    flat.triangle_count = S->triangle_count;
    flat.material_ids = S->materials;
    flat.lightmap_uvs = uvs;
    memset(&g_desc, 0, sizeof g_desc);
    g_desc.scene.meshes = &flat;
    g_desc.scene.mesh_count = 1;
    g_desc.scene.materials = S->materials_table;
    g_desc.scene.material_count = S->material_count;
    g_desc.outputs = RAD_BAKER_VERTEX | RAD_BAKER_LIGHTMAP | RAD_BAKER_PROBES;
    g_desc.lightmap_width = g_desc.lightmap_height = side;
    /* probes on a grid inside the bounds, inset half a cell */
    probe_at = (float *)malloc(sizeof(float) * 3 * nprobes);
    {
        uint32_t n = (uint32_t)ceil(cbrt((double)nprobes)), x, y, z, p = 0;
        for (z = 0; z < n && p < nprobes; ++z)
            for (y = 0; y < n && p < nprobes; ++y)
                for (x = 0; x < n && p < nprobes; ++x, ++p) {
                    uint32_t q[3];
                    q[0] = x, q[1] = y, q[2] = z;
                    for (k = 0; k < 3; ++k)
                        probe_at[3 * p + k] = S->bounds_min[k] + (S->bounds_max[k] - S->bounds_min[k]) * ((float)q[k] + 0.5f) / (float)n;
                }
    }
    g_desc.probe_positions = probe_at;
    g_desc.probe_count = nprobes;
    for (k = 0; k < 3; ++k) g_centre[k] = 0.5f * (S->bounds_min[k] + S->bounds_max[k]);
    g_radius = 0.25f * fminf(S->bounds_max[0] - S->bounds_min[0], S->bounds_max[2] - S->bounds_min[2]);
    memset(g_lights, 0, sizeof g_lights);
    g_lights[0].light.type = RAD_LIGHT_DIRECTIONAL; /* a sun that stays */
    g_lights[0].light.direction[0] = 0.3f, g_lights[0].light.direction[1] = -1.0f, g_lights[0].light.direction[2] = 0.2f;
    g_lights[0].light.color[0] = g_lights[0].light.color[1] = g_lights[0].light.color[2] = have_sponza ? 3.0f : 0.0f;
    g_lights[1].light.type = RAD_LIGHT_POINT;
    g_lights[1].light.falloff = RAD_FALLOFF_QUADRATIC;
    g_lights[1].light.color[0] = g_lights[1].light.color[1] = g_lights[1].light.color[2] = 0.25f * S->diagonal * S->diagonal;
    g_lights[1].light.position[1] = g_centre[1];
    light_at(0, frames, &g_lights[1].light);
    g_desc.lights = g_lights;
    g_desc.light_count = 2;
    memset(&g_opt, 0, sizeof g_opt);
    g_opt.method = RAD_BAKER_VIRTUAL_PATCHES;
    g_opt.vp_resolution = res;
    g_opt.lightmap_samples = 1;
    g_opt.max_memory = 4.0 * 1073741824.0;

    emit("\n### Moving lights over a bake (rad_baker_runtime)\n\n");
    {
        rad_baker_options keep = g_opt;
        rad_baker_result plain;
        keep.keep = 1;
        t = now(), c = cpu_now();
        check(rad_baker_run(&g_desc, &keep, NULL, &R), "rad_baker_run");
        t_bake = now() - t, c_bake = cpu_now() - c;
        /* the runtime building its own objects: the result without the kept ones */
        plain = *R;
        plain.kept = NULL;
        t = now(), c = cpu_now();
        check(rad_baker_runtime_create(&g_desc, &g_opt, &plain, NULL, NULL, &rt), "rad_baker_runtime_create");
        t_rt = now() - t, c_rt = cpu_now() - c;
        rad_baker_runtime_destroy(rt);
        t = now(), c = cpu_now();
        check(rad_baker_runtime_create(&g_desc, &g_opt, R, NULL, NULL, &rt), "rad_baker_runtime_create (kept)");
        t_kept = now() - t, c_kept = cpu_now() - c;
    }
    emit("%s (%u triangles), %u virtual patches (resolution %u), a %ux%u lightmap (%u charts), %u probes, a sun and a "
         "point light turning once in %u frames; bake %.1f s (CPU %.1f s), runtime create %.1f s (CPU %.1f s), from the "
         "objects the bake kept (rad_baker_options.keep) %.1f s (CPU %.1f s); load average at the start %s\n\n",
         have_sponza ? "Sponza" : "Cornell box", S->triangle_count, R->patch_count, R->vp_resolution, side, side, charts,
         R->probe_count, g_orbit ? g_orbit : frames, t_bake, c_bake, t_rt, c_rt, t_kept, c_kept, "(see below)");
    {
        FILE *la = fopen("/proc/loadavg", "r");
        char buf[128] = "?";
        if (la) {
            if (!fgets(buf, sizeof buf, la)) buf[0] = 0;
            fclose(la);
        }
        emit("load average before the frames: %s\n", buf);
    }
    wall = (double *)malloc(sizeof(double) * 2 * frames);
    cpu = wall + frames;
    lights[0] = g_lights[0].light;
    emit("| frames | budget | median wall ms | mean wall ms | mean CPU ms | planned ms (model) | lightmap rows per frame | probes per frame | over budget |\n");
    emit("|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (k = 0; k < 2; ++k) {
        double b = k == 0 ? budget : 0.0, sw = 0.0, sc = 0.0;
        sum_plan = lm_share = pr_share = 0.0;
        over = 0;
        for (i = 1; i <= frames; ++i) {
            light_at(i, frames, &lights[1]);
            t = now(), c = cpu_now();
            check(rad_baker_runtime_update(rt, lights, 2, b, &f), "rad_baker_runtime_update");
            wall[i - 1] = 1e3 * (now() - t), cpu[i - 1] = 1e3 * (cpu_now() - c);
            sw += wall[i - 1], sc += cpu[i - 1];
            sum_plan += f.planned_ms;
            lm_share += (double)f.lightmap_rows / (f.lightmap_rows_total ? f.lightmap_rows_total : 1u);
            pr_share += (double)f.probes_refreshed / R->probe_count;
            over += (uint32_t)f.over_budget;
            if (k == 0 && checks && i % (frames / (checks + 1)) == 0 && i < frames) {
                char what[64];
                snprintf(what, sizeof what, "moving, frame %u", i);
                if (i == frames / (checks + 1)) {
                    emit("\n| check | vertex | lightmap | probes | re-bake |\n|---|---:|---:|---:|---:|\n");
                }
                compare_bake(&f, lights, what);
            }
        }
        qsort(wall, frames, sizeof(double), cmp_double);
        if (k == 0 && checks) emit("\n");
        emit("| %u | %s | %.2f | %.2f | %.2f | %.2f | %.0f%% | %.0f%% | %u |\n", frames, k == 0 ? "budget" : "none (0)",
             wall[frames / 2], sw / frames, sc / frames, sum_plan / frames, 100.0 * lm_share / frames,
             100.0 * pr_share / frames, over);
        if (k == 0) emit("\n(budget %.1f ms)\n\n", budget);
    }
    /* at rest: until CONVERGED, then against a fresh bake */
    t = now();
    for (i = 0; i < 10000; ++i) {
        check(rad_baker_runtime_update(rt, lights, 2, budget, &f), "rad_baker_runtime_update");
        if (f.phase == RAD_BAKER_RUNTIME_CONVERGED) break;
    }
    emit("\nthe light at rest: CONVERGED after %u frames of %.0f ms budget (%.1f s wall)\n\n", i, budget, now() - t);
    emit("| check | vertex | lightmap | probes | re-bake |\n|---|---:|---:|---:|---:|\n");
    compare_bake(&f, lights, "at rest, converged");
    rad_baker_runtime_destroy(rt);
    rad_baker_result_destroy(R);
    rad_scene_destroy(S);
    free(wall), free(probe_at), free(uvs), free(pos), free(idx);
    if (g_md) fclose(g_md);
    return 0;
}

/* realtime.c - the loop an engine runs with radiosity.h on a scene of any size (docs/methods/
   aavp.md, temporal.md): load a mesh, build axis-aligned virtual patches with sparse rows, bake
   the rows into alias tables and the vertices into gather tables, then per frame move a point
   light, update E at the patches' samples (rad_vp_lights: the light's falloff exact every frame,
   its shadows re-tested for --rays samples per frame, round-robin), take one temporal step (all
   bounces by feedback) and gather the radiosity at every vertex, printing each stage's
   milliseconds. No mesh: the built-in Cornell box (lit by the moving light only). MESH.obj:
   positions and faces (one stone material, albedo 0.7 0.68 0.63), also lit by a fixed sun.
   --patches N: the resolution is predicted from a coarse first build (default 2000).
   --rays R: shadow rays per light and frame (default 0: every sample, exact every frame).
   Build:  cc -std=c99 -O2 -fopenmp -I. examples/realtime.c -o build/realtime -lm
   Run:    build/realtime [MESH.obj] [--patches N] [--frames F] [--k K] [--rays R] */
#if !defined(_WIN32) && !defined(_POSIX_C_SOURCE)
#  define _POSIX_C_SOURCE 199309L /* clock_gettime */
#endif
#define RADIOSITY_IMPLEMENTATION
#include "radiosity.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return 1e3 * (double)t.tv_sec + 1e-6 * (double)t.tv_nsec;
}
static void check(rad_result r, const char *what)
{
    if (r != RAD_SUCCESS) fprintf(stderr, "realtime: %s failed: %s\n", what, rad_result_string(r)), exit(1);
}

static void *grow(void *p, size_t *cap, size_t need, size_t size)
{
    if (need <= *cap) return p;
    *cap = need * 2;
    p = realloc(p, *cap * size);
    if (!p) {
        fprintf(stderr, "realtime: out of memory\n");
        exit(1);
    }
    return p;
}

/* 'v x y z' and 'f a b c ...' (fans; 'a/b/c' and negative indices accepted) */
static int load_obj(const char *path, float **pos, uint32_t *nv, uint32_t **idx, uint32_t *nt)
{
    FILE *f = fopen(path, "r");
    char line[4096];
    size_t cv = 0, ct = 0;
    *pos = NULL, *idx = NULL, *nv = *nt = 0;
    if (!f) return 0;
    while (fgets(line, sizeof line, f)) {
        if (line[0] == 'v' && line[1] == ' ') {
            *pos = (float *)grow(*pos, &cv, 3 * (size_t)(*nv + 1), sizeof(float));
            if (sscanf(line + 2, "%f %f %f", *pos + 3 * *nv, *pos + 3 * *nv + 1, *pos + 3 * *nv + 2) == 3) ++*nv;
        } else if (line[0] == 'f' && line[1] == ' ') {
            long id[3];
            uint32_t n = 0;
            char *p = line + 2, *end;
            for (;;) {
                long v = strtol(p, &end, 10);
                if (end == p) break;
                id[n < 2 ? n : 2] = v < 0 ? (long)*nv + v : v - 1;
                for (p = end; *p && *p != ' ' && *p != '\t'; ++p) {}
                if (++n >= 3) {
                    if (id[0] < 0 || id[1] < 0 || id[2] < 0 || id[0] >= (long)*nv || id[1] >= (long)*nv || id[2] >= (long)*nv)
                        break;
                    *idx = (uint32_t *)grow(*idx, &ct, 3 * (size_t)(*nt + 1), sizeof(uint32_t));
                    (*idx)[3 * *nt] = (uint32_t)id[0], (*idx)[3 * *nt + 1] = (uint32_t)id[1];
                    (*idx)[3 * *nt + 2] = (uint32_t)id[2];
                    ++*nt;
                    id[1] = id[2];
                }
            }
        }
    }
    fclose(f);
    return *nv > 0 && *nt > 0;
}

static int cmp_double(const void *a, const void *b)
{
    return (*(const double *)a > *(const double *)b) - (*(const double *)a < *(const double *)b);
}

int main(int argc, char **argv)
{
    const char *path = NULL;
    uint32_t want = 2000, frames = 60, k = 10, rays = 0, nv = 0, nt = 0, f, i, m, total_vertices = 0, light_count = 1;
    float *pos = NULL, *E, *B, **vertex_out, centre[3], radius;
    uint32_t *idx = NULL;
    rad_material stone = {{0.7f, 0.68f, 0.63f}, {0.0f, 0.0f, 0.0f}, 0, 0, 0, 0, 0.0f};
    rad_mesh_desc mesh;
    rad_scene_desc desc;
    rad_camera cam;
    rad_scene *scene = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_vp_options vo;
    rad_virtual_patches *vp = NULL;
    rad_alias_tables *tables = NULL;
    const rad_alias_tables *tp[1];
    rad_temporal_options to;
    rad_temporal *temporal = NULL;
    rad_vp_lights_options lo;
    rad_vp_lights *dyn = NULL;
    rad_vp_gather_table **gt;
    rad_light light[2];
    double t, t_build, t_bake, sum[3] = {0.0, 0.0, 0.0}, *times;

    for (i = 1; i < (uint32_t)argc; ++i) {
        if (i + 1 < (uint32_t)argc && !strcmp(argv[i], "--patches")) want = (uint32_t)atoi(argv[++i]);
        else if (i + 1 < (uint32_t)argc && !strcmp(argv[i], "--frames")) frames = (uint32_t)atoi(argv[++i]);
        else if (i + 1 < (uint32_t)argc && !strcmp(argv[i], "--k")) k = (uint32_t)atoi(argv[++i]);
        else if (i + 1 < (uint32_t)argc && !strcmp(argv[i], "--rays")) rays = (uint32_t)atoi(argv[++i]);
        else if (argv[i][0] != '-' && !path) path = argv[i];
        else return fprintf(stderr, "usage: realtime [MESH.obj] [--patches N] [--frames F] [--k K] [--rays R]\n"), 2;
    }
    if (want < 8 || frames < 1 || k < 1 || k > RAD_TEMPORAL_MAX_SAMPLES)
        return fprintf(stderr, "realtime: --patches >= 8, --frames >= 1, --k in 1..%u\n", RAD_TEMPORAL_MAX_SAMPLES), 2;

    /* 1. the scene: the mesh, or the built-in Cornell box with its ceiling light switched off */
    t = now_ms();
    if (path) {
        if (!load_obj(path, &pos, &nv, &idx, &nt)) return fprintf(stderr, "realtime: cannot read '%s'\n", path), 1;
        memset(&mesh, 0, sizeof mesh);
        mesh.positions = pos, mesh.vertex_count = nv, mesh.indices = idx, mesh.triangle_count = nt;
        memset(&desc, 0, sizeof desc);
        desc.meshes = &mesh, desc.mesh_count = 1, desc.materials = &stone, desc.material_count = 1;
        desc.flags = RAD_SCENE_SKIP_DEGENERATE; /* real meshes hold zero-area triangles */
    } else {
        rad_cornell_box(&desc, &cam);
    }
    check(rad_scene_create(&desc, NULL, &scene), "rad_scene_create");
    check(rad_bvh_create(scene, NULL, &bvh), "rad_bvh_create");
    rad_bvh_raycaster(bvh, &rc);
    for (m = 0; m < desc.mesh_count; ++m) total_vertices += desc.meshes[m].vertex_count;
    printf("scene: %u triangles, %u vertices, loaded and BVH in %.0f ms\n", scene->triangle_count, total_vertices,
           now_ms() - t);

    /* 2. axis-aligned virtual patches with sparse rows; the patch count grows about as the
       square of the resolution, so one coarse build predicts the resolution for 'want' */
    rad_vp_options_default(&vo);
    vo.storage = RAD_STORAGE_SPARSE;
    vo.resolution = 8;
    t = now_ms();
    check(rad_vp_create(scene, &rc, &vo, NULL, &vp), "rad_vp_create");
    vo.resolution = (uint32_t)(8.0 * sqrt((double)want / (double)vp->count) + 0.5);
    if (vo.resolution < 2) vo.resolution = 2;
    rad_vp_destroy(vp);
    check(rad_vp_create(scene, &rc, &vo, NULL, &vp), "rad_vp_create");
    t_build = now_ms() - t;
    printf("aavp: resolution %u, %u patches, %u samples, %llu non-zeros (%.1f%% of N^2), %.1f MiB, built in %.0f ms\n",
           vo.resolution, vp->count, vp->sample_count, (unsigned long long)vp->matrix.row_offsets[vp->count],
           100.0 * (double)vp->matrix.row_offsets[vp->count] / ((double)vp->count * vp->count),
           (double)rad_vp_memory(vp) / 1048576.0, t_build);

    /* 3. bake the rows: one alias table per row of the CSR matrix */
    t = now_ms();
    check(rad_alias_tables_create(&vp->matrix, RAD_ALIAS_AUTO, NULL, &tables), "rad_alias_tables_create");
    t_bake = now_ms() - t;
    tp[0] = tables;
    rad_temporal_options_default(&to);
    to.mode = RAD_TEMPORAL_FEEDBACK; /* samples E + B: all bounces, one more per frame */
    to.samples = k;
    to.weight = 0.9f;                /* a light that moves every frame: short memory, lag ~10 frames */
    check(rad_temporal_create(tp, 1, vp->albedo, &to, NULL, &temporal), "rad_temporal_create");
    printf("bake: alias tables %.1f MiB in %.1f ms\n", (double)rad_alias_tables_memory(tables) / 1048576.0, t_bake);

    E = (float *)malloc(sizeof(float) * 3 * vp->count);
    B = (float *)malloc(sizeof(float) * 3 * vp->count);
    vertex_out = (float **)malloc(sizeof(float *) * desc.mesh_count);
    gt = (rad_vp_gather_table **)calloc(desc.mesh_count, sizeof(rad_vp_gather_table *));
    times = (double *)malloc(sizeof(double) * 3 * frames);
    if (!E || !B || !vertex_out || !gt || !times) return 1;
    /* the gather tables: the voxels and weights of every vertex, found once (the mesh is static) */
    t = now_ms();
    for (m = 0; m < desc.mesh_count; ++m) {
        if (!(vertex_out[m] = (float *)malloc(sizeof(float) * 3 * (desc.meshes[m].vertex_count + 1)))) return 1;
        /* area-weighted vertex normals when the mesh has none (an engine passes its own) */
        check(rad_vp_gather_table_mesh(vp, &desc.meshes[m], NULL, &gt[m]), "rad_vp_gather_table_mesh");
    }
    printf("gather tables: %u vertices in %.1f ms\n", total_vertices, now_ms() - t);
    for (i = 0; i < 3; ++i) centre[i] = 0.5f * (scene->bounds_min[i] + scene->bounds_max[i]);
    radius = 0.25f * fminf(scene->bounds_max[0] - scene->bounds_min[0], scene->bounds_max[2] - scene->bounds_min[2]);
    memset(light, 0, sizeof light);
    light[0].type = RAD_LIGHT_POINT;
    light[0].falloff = RAD_FALLOFF_QUADRATIC;
    light[0].color[0] = light[0].color[1] = light[0].color[2] = 0.25f * scene->diagonal * scene->diagonal;
    if (path) { /* a sun that stays: its shadows are tested once, then kept */
        light[1].type = RAD_LIGHT_DIRECTIONAL;
        light[1].direction[0] = 0.3f, light[1].direction[1] = -1.0f, light[1].direction[2] = 0.2f;
        light[1].color[0] = light[1].color[1] = light[1].color[2] = 3.0f;
        light_count = 2;
    }
    rad_vp_lights_options_default(&lo);
    lo.rays_per_frame = rays;
    lo.direct.exclude_emitters = 1; /* the lights above only: the lamp's own light is not part of this loop */
    check(rad_vp_lights_create(vp, &rc, &lo, NULL, &dyn), "rad_vp_lights_create");

    /* 4. the frames */
    printf("frame     E ms  step ms  gather ms  mean B\n");
    for (f = 0; f < frames; ++f) {
        double t0, t1, t2, t3, mean = 0.0;
        float a = 6.2831853f * (float)f / (float)frames;
        light[0].position[0] = centre[0] + radius * cosf(a);
        light[0].position[1] = centre[1];
        light[0].position[2] = centre[2] + radius * sinf(a);
        t0 = now_ms();
        check(rad_vp_lights_update(dyn, light, light_count, E, NULL), "rad_vp_lights_update");
        t1 = now_ms();
        check(rad_temporal_step(temporal, E, NULL, B), "rad_temporal_step");
        t2 = now_ms();
        for (i = 0; i < 3 * vp->count; ++i) B[i] += E[i]; /* the step gives the indirect part */
        for (m = 0; m < desc.mesh_count; ++m)
            check(rad_vp_gather_table_apply(gt[m], B, vertex_out[m], NULL), "rad_vp_gather_table_apply");
        t3 = now_ms();
        for (i = 0; i < desc.meshes[0].vertex_count; ++i) mean += vertex_out[0][3 * i + 1];
        sum[0] += t1 - t0, sum[1] += t2 - t1, sum[2] += t3 - t2;
        times[f] = t1 - t0, times[frames + f] = t2 - t1, times[2 * frames + f] = t3 - t2;
        if (f < 3 || f + 1 == frames || f % (frames / 8 + 1) == 0)
            printf("%5u %8.2f %8.3f %10.2f  %.4g\n", f, t1 - t0, t2 - t1, t3 - t2, mean / desc.meshes[0].vertex_count);
    }
    printf("mean per frame over %u frames: E update %.2f ms, temporal step %.3f ms, per-vertex gather %.2f ms "
           "(%u vertices), total %.2f ms\n", frames, sum[0] / frames, sum[1] / frames, sum[2] / frames, total_vertices,
           (sum[0] + sum[1] + sum[2]) / frames);
    /* the medians: on a busy machine a few slow frames move the means */
    for (i = 0; i < 3; ++i) qsort(times + (size_t)i * frames, frames, sizeof(double), cmp_double);
    printf("median per frame: E update %.2f ms, temporal step %.3f ms, per-vertex gather %.2f ms, total %.2f ms\n",
           times[frames / 2], times[frames + frames / 2], times[2 * frames + frames / 2],
           times[frames / 2] + times[frames + frames / 2] + times[2 * frames + frames / 2]);

    for (m = 0; m < desc.mesh_count; ++m) free(vertex_out[m]), rad_vp_gather_table_destroy(gt[m]);
    free(vertex_out), free(gt), free(times), free(E), free(B), free(pos), free(idx);
    rad_vp_lights_destroy(dyn);
    rad_temporal_destroy(temporal);
    rad_alias_tables_destroy(tables);
    rad_vp_destroy(vp);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(scene);
    return 0;
}

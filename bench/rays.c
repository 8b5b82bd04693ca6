/* rays.c - ray-query throughput of the built-in BVH against Embree on the rays a form-factor
   bake really casts.

   For each scene the program records the occlusion rays of a sample of form-factor rows
   (rad_form_factor_rows through a recording raycaster), then replays the same rays through
   each backend on 1 and 2 threads (chunks of 1024 rays, OpenMP), best of 3. Intersection
   throughput replays the same rays as closest-hit queries with tmax = infinity. BVH build time
   (best of 3) and memory are reported for each backend.

   Scenes: the built-in Cornell box cut into about 4000 patches, and the Stanford bunny
   (stanford-bunny.obj, 69 451 triangles, a public model that is not part of the repository:
   see docs/data.md) standing on the Cornell box floor, read from the folder given by
   --data DIR, else $RAD_DATA_DIR; the bunny scene is skipped with a message when no folder is
   given or the file is absent. The OBJ reading here is a bench-only reader of the plain "v x y z" /
   "f a b c" lines these data files use, not a general importer.

   Build: cc -O3 -march=native -fopenmp [-DRAD_EMBREE ... -lembree3] bench/rays.c
   Run:   rays [--data DIR] [--append FILE.md]    (prints the tables, and appends them to FILE.md) */
#include "bench_common.h"
#define RADIOSITY_IMPLEMENTATION
#include "../radiosity.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#ifdef _OPENMP
#include <omp.h>
#endif

/* ---- recording ---- */
typedef struct recorder {
    rad_raycaster inner;
    rad_ray *rays;
    size_t count, cap;
} recorder;

static rad_result rec_occluded(void *user, const rad_ray *rays, uint32_t count, uint8_t *out)
{
    recorder *r = (recorder *)user;
    if (r->count + count > r->cap) {
        size_t nc = r->cap ? r->cap * 2 : 1u << 20;
        while (nc < r->count + count) nc *= 2;
        r->rays = (rad_ray *)realloc(r->rays, nc * sizeof(rad_ray));
        if (!r->rays) return RAD_ERROR_OUT_OF_MEMORY;
        r->cap = nc;
    }
    memcpy(r->rays + r->count, rays, count * sizeof(rad_ray));
    r->count += count;
    return r->inner.occluded(r->inner.user, rays, count, out);
}

static void serial_for(void *user, uint32_t count, rad_task_fn fn, void *data)
{
    uint32_t i;
    (void)user;
    for (i = 0; i < count; ++i) fn(data, i);
}

/* ---- replay ---- */
static double replay(const rad_raycaster *rc, const rad_ray *rays, size_t n, int threads, int intersect, uint64_t *hits)
{
    double best = 1e30;
    int rep;
    for (rep = 0; rep < 3; ++rep) {
        long chunks = (long)((n + 1023) / 1024), c;
        uint64_t h = 0;
        double t0 = now();
#ifdef _OPENMP
#pragma omp parallel for schedule(dynamic, 16) num_threads(threads) reduction(+ : h)
#endif
        for (c = 0; c < chunks; ++c) {
            size_t b = (size_t)c * 1024, e = b + 1024 > n ? n : b + 1024, i;
            if (intersect) {
                rad_hit hit[1024];
                rc->intersect(rc->user, rays + b, (uint32_t)(e - b), hit);
                for (i = 0; i < e - b; ++i) h += hit[i].triangle != RAD_NONE;
            } else {
                uint8_t occ[1024];
                rc->occluded(rc->user, rays + b, (uint32_t)(e - b), occ);
                for (i = 0; i < e - b; ++i) h += occ[i];
            }
        }
        t0 = now() - t0;
        if (t0 < best) best = t0;
        *hits = h;
    }
    (void)threads;
    return best;
}

/* ---- scenes ---- */
static int load_obj(const char *path, float **pos, uint32_t *nv, uint32_t **idx, uint32_t *nt)
{
    FILE *f = fopen(path, "r");
    char line[512];
    size_t vc = 0, vcap = 0, tc = 0, tcap = 0;
    float *v = NULL;
    uint32_t *t = NULL;
    if (!f) return 0;
    while (fgets(line, sizeof(line), f)) {
        if (line[0] == 'v' && line[1] == ' ') {
            if (vc == vcap) { vcap = vcap ? 2 * vcap : 4096; v = (float *)realloc(v, vcap * 3 * sizeof(float)); }
            if (sscanf(line + 2, "%f %f %f", &v[3 * vc], &v[3 * vc + 1], &v[3 * vc + 2]) == 3) vc++;
        } else if (line[0] == 'f' && line[1] == ' ') {
            unsigned a, b, c;
            if (tc == tcap) { tcap = tcap ? 2 * tcap : 4096; t = (uint32_t *)realloc(t, tcap * 3 * sizeof(uint32_t)); }
            if (sscanf(line + 2, "%u %u %u", &a, &b, &c) == 3) { t[3 * tc] = a - 1; t[3 * tc + 1] = b - 1; t[3 * tc + 2] = c - 1; tc++; }
        }
    }
    fclose(f);
    *pos = v; *nv = (uint32_t)vc; *idx = t; *nt = (uint32_t)tc;
    return tc > 0;
}

static void run_scene(const char *name, const rad_scene *scene, uint32_t target, uint32_t rows_wanted)
{
    rad_patches *P = NULL;
    rad_bvh *bvh = NULL;
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_raycaster rb;
    recorder rec;
    rad_context ctx;
    uint32_t r, step;
    double tb = 1e30, t;
    float *rowbuf;
    int k;
    size_t i;
    rad_patch_options_default(&po);
    po.target_count = target;
    if (rad_patches_create(scene, &po, NULL, &P) != RAD_SUCCESS) { printf("patches failed\n"); return; }
    for (k = 0; k < 3; ++k) {
        rad_bvh *b2 = NULL;
        t = now();
        rad_bvh_create(scene, NULL, &b2);
        t = now() - t;
        if (t < tb) tb = t;
        if (k < 2) rad_bvh_destroy(b2); else bvh = b2;
    }
    rad_bvh_raycaster(bvh, &rb);
    memset(&rec, 0, sizeof(rec));
    rec.inner = rb;
    memset(&ctx, 0, sizeof(ctx));
    ctx.parallel_for = serial_for;
    rad_form_factor_options_default(&fo);
    {
        rad_raycaster rr;
        rr.user = &rec;
        rr.occluded = rec_occluded;
        rr.intersect = rb.intersect;
        rowbuf = (float *)malloc(sizeof(float) * P->count);
        step = P->count / rows_wanted;
        if (step == 0) step = 1;
        for (r = step / 2; r < P->count; r += step) rad_form_factor_rows(P, &rr, &fo, r, r + 1, rowbuf, &ctx);
        free(rowbuf);
    }
    emit("\n### %s: %u triangles, %u patches; %zu occlusion rays recorded from %u form-factor rows\n\n", name,
         scene->triangle_count, P->count, rec.count, (P->count + step - 1 - step / 2) / step);
    emit("| backend | build (ms) | memory (KiB) | threads | occlusion Mrays/s | intersection Mrays/s |\n");
    emit("|---|---:|---:|---:|---:|---:|\n");
    {
        uint64_t h1 = 0, h2 = 0;
        int th;
        for (th = 1; th <= 2; ++th) {
            double o = replay(&rb, rec.rays, rec.count, th, 0, &h1);
            rad_ray *ext = (rad_ray *)malloc(rec.count * sizeof(rad_ray));
            double x;
            for (i = 0; i < rec.count; ++i) { ext[i] = rec.rays[i]; ext[i].tmax = FLT_MAX; }
            x = replay(&rb, ext, rec.count, th, 1, &h2);
            emit("| built-in BVH | %.3f | %.1f | %d | %.2f | %.2f |\n", tb * 1e3, rad_bvh_memory(bvh) / 1024.0, th,
                 rec.count / o * 1e-6, rec.count / x * 1e-6);
            free(ext);
        }
#ifdef RAD_EMBREE
        {
            rad_embree *e = NULL;
            rad_raycaster re;
            uint64_t g1 = 0, g2 = 0;
            double te = 1e30;
            for (k = 0; k < 3; ++k) {
                rad_embree *e2 = NULL;
                t = now();
                rad_embree_create(scene, NULL, &e2);
                t = now() - t;
                if (t < te) te = t;
                if (k < 2) rad_embree_destroy(e2); else e = e2;
            }
            rad_embree_raycaster(e, &re);
            for (th = 1; th <= 2; ++th) {
                double o = replay(&re, rec.rays, rec.count, th, 0, &g1);
                rad_ray *ext = (rad_ray *)malloc(rec.count * sizeof(rad_ray));
                double x;
                for (i = 0; i < rec.count; ++i) { ext[i] = rec.rays[i]; ext[i].tmax = FLT_MAX; }
                x = replay(&re, ext, rec.count, th, 1, &g2);
                emit("| Embree 3 | %.3f | %.1f | %d | %.2f | %.2f |\n", te * 1e3, rad_embree_memory(e) / 1024.0, th,
                     rec.count / o * 1e-6, rec.count / x * 1e-6);
                free(ext);
            }
            emit("\nOccluded rays: BVH %llu, Embree %llu (the same rays; equal counts mean the same answers).\n",
                 (unsigned long long)h1, (unsigned long long)g1);
            (void)g2;
            rad_embree_destroy(e);
        }
#else
        emit("\nEmbree rows: not measured (built without RAD_EMBREE; install libembree-dev).\n");
#endif
        (void)h2;
    }
    free(rec.rays);
    rad_bvh_destroy(bvh);
    rad_patches_destroy(P);
}

int main(int argc, char **argv)
{
    rad_scene_desc desc;
    rad_scene *cornell = NULL;
    const char *dir = getenv("RAD_DATA_DIR");
    char path[1024];
    float *bpos = NULL;
    uint32_t *bidx = NULL, bnv = 0, bnt = 0;
    int a;
    for (a = 1; a < argc; ++a)
        if (!strcmp(argv[a], "--append") && a + 1 < argc) g_md = fopen(argv[++a], "a");
        else if (!strcmp(argv[a], "--data") && a + 1 < argc) dir = argv[++a];
    emit("\n## c) Ray queries: built-in BVH against Embree\n\n");
    emit("Occlusion rays recorded from form-factor rows (rad_form_factor_rows, default options) and replayed "
         "through each backend in chunks of 1024; intersection replays the same rays as closest-hit queries "
         "with tmax = infinity. Best of 3. Built %s RAD_EMBREE.\n", rad_embree_available() ? "with" : "without");
    rad_cornell_box(&desc, NULL);
    if (rad_scene_create(&desc, NULL, &cornell) != RAD_SUCCESS) return 1;
    run_scene("Cornell box", cornell, 4000, 48);
    snprintf(path, sizeof(path), "%s/stanford-bunny.obj", dir ? dir : "");
    if (!dir || !dir[0]) {
        emit("\n### Stanford bunny in the Cornell box: skipped (no data folder: pass --data DIR or set RAD_DATA_DIR; "
             "see docs/data.md)\n");
    } else if (load_obj(path, &bpos, &bnv, &bidx, &bnt)) {
        /* the bunny, scaled to 0.25 m tall, standing in the middle of the Cornell floor */
        rad_mesh_desc *meshes = (rad_mesh_desc *)calloc(desc.mesh_count + 1, sizeof(rad_mesh_desc));
        rad_scene_desc d2 = desc;
        rad_scene *s2 = NULL;
        float lo[3] = { 1e30f, 1e30f, 1e30f }, hi[3] = { -1e30f, -1e30f, -1e30f }, sc;
        uint32_t v;
        int k;
        for (v = 0; v < bnv; ++v)
            for (k = 0; k < 3; ++k) {
                if (bpos[3 * v + k] < lo[k]) lo[k] = bpos[3 * v + k];
                if (bpos[3 * v + k] > hi[k]) hi[k] = bpos[3 * v + k];
            }
        sc = 0.25f / (hi[1] - lo[1]);
        for (v = 0; v < bnv; ++v) {
            bpos[3 * v] = (bpos[3 * v] - 0.5f * (lo[0] + hi[0])) * sc + 0.28f;
            bpos[3 * v + 1] = (bpos[3 * v + 1] - lo[1]) * sc + 0.0005f;
            bpos[3 * v + 2] = (bpos[3 * v + 2] - 0.5f * (lo[2] + hi[2])) * sc + 0.30f;
        }
        memcpy(meshes, desc.meshes, desc.mesh_count * sizeof(rad_mesh_desc));
        meshes[desc.mesh_count].name = "bunny";
        meshes[desc.mesh_count].positions = bpos;
        meshes[desc.mesh_count].vertex_count = bnv;
        meshes[desc.mesh_count].indices = bidx;
        meshes[desc.mesh_count].triangle_count = bnt;
        meshes[desc.mesh_count].material = 0;
        d2.meshes = meshes;
        d2.mesh_count = desc.mesh_count + 1;
        d2.flags = RAD_SCENE_SKIP_DEGENERATE;
        if (rad_scene_create(&d2, NULL, &s2) == RAD_SUCCESS) {
            run_scene("Stanford bunny in the Cornell box", s2, 1, 8);
            rad_scene_destroy(s2);
        } else {
            emit("\nbunny scene: rad_scene_create failed\n");
        }
        free(meshes);
        free(bpos);
        free(bidx);
    } else {
        emit("\n### Stanford bunny in the Cornell box: skipped (%s not found; see docs/data.md)\n", path);
    }
    rad_scene_destroy(cornell);
    if (g_md) fclose(g_md);
    return 0;
}

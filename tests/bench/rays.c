/* rays.c - ray-query throughput of the built-in BVH against Embree on the rays a bake and a
   path tracer really cast.

   For each scene four ray sets: the occlusion rays of a sample of form-factor rows (recorded
   through a recording raycaster; replayed as closest-hit queries with tmax = infinity too),
   512x512 camera rays, cosine-distributed bounce rays from the camera hits, and shadow
   segments from the bounce hits to a point light. Each set runs through both backends on 1
   and 2 threads (chunks of 1024 rays, OpenMP), the backends alternating, best of 5; one thread
   is timed by its own CPU time, two by wall time. Answers are compared ray for ray. Build time
   (best of 5, alternating) and memory are reported for each backend.

   Scenes: the built-in Cornell box cut into about 4000 patches, the Stanford bunny
   (stanford-bunny.obj, 69 451 triangles) standing on the Cornell box floor, and the Dabrovic
   Sponza atrium (sponza.obj, 66 454 triangles): public models that are not part of the
   repository (see docs/data.md), read from the folder given by --data DIR, else
   $RAD_DATA_DIR; a scene is skipped with a message when no folder is given or its file is
   absent. The OBJ reading here is a bench-only reader of the "v x y z" and "f" lines these
   data files use (indices a, a/b or a/b/c; polygons fanned), not a general importer.

   Build: cc -O3 -march=native -fopenmp [-DRAD_EMBREE ... -lembree3] tests/bench/rays.c
   Run:   rays [--data DIR] [--append FILE.md] [--only NAME] [--sets N]
          (prints the tables and appends them to FILE.md; --only: the scenes whose name
          contains NAME; --sets N: the first N ray sets) */
#include "bench_common.h"
#define RADIOSITY_IMPLEMENTATION
#include "../../radiosity.h"
#include "bench_scenes.h"
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
/* One timed pass of rays through rc on 'threads' threads in chunks of 1024; the answers go to
   occ (occlusion) or hit (closest hit). */
static double thread_cpu(void)
{
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* One thread: the CPU time of the calling thread, which time slices given to other processes
   do not inflate (caches shared with them still do). Two threads: wall time. */
static double replay_once(const rad_raycaster *rc, const rad_ray *rays, size_t n, int threads, uint8_t *occ, rad_hit *hit)
{
    long chunks = (long)((n + 1023) / 1024), c;
    double t0;
    if (threads == 1) {
        t0 = thread_cpu();
        for (c = 0; c < chunks; ++c) {
            size_t b = (size_t)c * 1024, e = b + 1024 > n ? n : b + 1024;
            if (hit) rc->intersect(rc->user, rays + b, (uint32_t)(e - b), hit + b);
            else rc->occluded(rc->user, rays + b, (uint32_t)(e - b), occ + b);
        }
        return thread_cpu() - t0;
    }
    t0 = now();
#ifdef _OPENMP
#pragma omp parallel for schedule(dynamic, 16) num_threads(threads)
#endif
    for (c = 0; c < chunks; ++c) {
        size_t b = (size_t)c * 1024, e = b + 1024 > n ? n : b + 1024;
        if (hit) rc->intersect(rc->user, rays + b, (uint32_t)(e - b), hit + b);
        else rc->occluded(rc->user, rays + b, (uint32_t)(e - b), occ + b);
    }
    (void)threads;
    return now() - t0;
}

/* ---- ray sets ---- */
typedef struct rayset {
    const char *name;
    rad_ray *occ;    /* occlusion queries */
    rad_ray *hit;    /* closest-hit queries */
    size_t n;
} rayset;

static uint32_t g_rng = 12345u;
static const char *g_only; /* --only NAME: the scenes whose name contains NAME */
static int g_sets = 4;      /* --sets N: the first N ray sets only */
static float rnd(void)
{
    g_rng ^= g_rng << 13; g_rng ^= g_rng >> 17; g_rng ^= g_rng << 5;
    return (float)(g_rng >> 8) / 16777216.0f;
}

/* camera rays (coherent), bounce rays from their hits in cosine-distributed directions about the
   geometric normal (incoherent), and shadow rays from the bounce hits to a point light
   (incoherent origins): what a path tracer casts */
static void path_sets(const rad_scene *scene, const rad_raycaster *rc, const rad_camera *cam, const float light[3],
                      uint32_t w, uint32_t h, rayset *camera, rayset *bounce, rayset *shadow)
{
    size_t n = (size_t)w * h, i, nb = 0, ns = 0;
    rad_hit *hits = (rad_hit *)malloc(n * sizeof(rad_hit));
    uint32_t x, y;
    camera->name = "camera";
    camera->n = n;
    camera->hit = (rad_ray *)malloc(n * sizeof(rad_ray));
    camera->occ = camera->hit; /* occlusion: any hit along the whole ray */
    for (y = 0; y < h; ++y)
        for (x = 0; x < w; ++x) rad_camera_ray(cam, w, h, (float)x + 0.5f, (float)y + 0.5f, &camera->hit[(size_t)y * w + x]);
    rc->intersect(rc->user, camera->hit, (uint32_t)n, hits);
    bounce->name = "bounce";
    bounce->hit = (rad_ray *)malloc(n * sizeof(rad_ray));
    bounce->occ = bounce->hit;
    for (i = 0; i < n; ++i) {
        const float *v;
        float e1[3], e2[3], nn[3], p[3], t1[3], t2[3], len, u1, u2, r, phi, s;
        int k;
        rad_ray *b = &bounce->hit[nb];
        if (hits[i].triangle == RAD_NONE) continue;
        v = scene->positions + 9 * (size_t)hits[i].triangle;
        for (k = 0; k < 3; ++k) { e1[k] = v[3 + k] - v[k]; e2[k] = v[6 + k] - v[k]; }
        nn[0] = e1[1] * e2[2] - e1[2] * e2[1]; nn[1] = e1[2] * e2[0] - e1[0] * e2[2]; nn[2] = e1[0] * e2[1] - e1[1] * e2[0];
        len = sqrtf(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
        if (!(len > 0.0f)) continue;
        s = (nn[0] * camera->hit[i].dir[0] + nn[1] * camera->hit[i].dir[1] + nn[2] * camera->hit[i].dir[2]) > 0.0f ? -1.0f : 1.0f;
        for (k = 0; k < 3; ++k) { nn[k] *= s / len; p[k] = camera->hit[i].origin[k] + hits[i].t * camera->hit[i].dir[k]; }
        if (fabsf(nn[0]) > 0.5f) { t1[0] = -nn[1]; t1[1] = nn[0]; t1[2] = 0.0f; }
        else { t1[0] = 0.0f; t1[1] = -nn[2]; t1[2] = nn[1]; }
        len = sqrtf(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2]);
        for (k = 0; k < 3; ++k) t1[k] /= len;
        t2[0] = nn[1] * t1[2] - nn[2] * t1[1]; t2[1] = nn[2] * t1[0] - nn[0] * t1[2]; t2[2] = nn[0] * t1[1] - nn[1] * t1[0];
        u1 = rnd(); u2 = rnd();
        r = sqrtf(u1); phi = 6.2831853f * u2;
        for (k = 0; k < 3; ++k) {
            b->origin[k] = p[k] + 1e-4f * nn[k];
            b->dir[k] = r * cosf(phi) * t1[k] + r * sinf(phi) * t2[k] + sqrtf(1.0f - u1) * nn[k];
        }
        b->tmin = 0.0f;
        b->tmax = FLT_MAX;
        nb++;
    }
    bounce->n = nb;
    rc->intersect(rc->user, bounce->hit, (uint32_t)nb, hits);
    shadow->name = "shadow";
    shadow->occ = (rad_ray *)malloc((nb + 1) * sizeof(rad_ray));
    shadow->hit = NULL; /* occlusion only */
    for (i = 0; i < nb; ++i) {
        rad_ray *s = &shadow->occ[ns];
        int k;
        if (hits[i].triangle == RAD_NONE) continue;
        for (k = 0; k < 3; ++k) {
            float d = bounce->hit[i].dir[k];
            s->origin[k] = bounce->hit[i].origin[k] + hits[i].t * d - 1e-4f * d;
            s->dir[k] = light[k] - s->origin[k];
        }
        s->tmin = 1e-4f;
        s->tmax = 1.0f - 1e-4f;
        ns++;
    }
    shadow->n = ns;
    free(hits);
}

/* ABAB: the two backends alternate, best of 'reps' each, so load from other processes hits
   both alike. Returns the two times; counts answers that differ ray for ray. */
static void compare(const rad_raycaster *a, const rad_raycaster *b, const rad_ray *rays, size_t n, int threads, int intersect,
                    int reps, double *ta, double *tb, size_t *differ, size_t *positive)
{
    uint8_t *oa = NULL, *ob = NULL;
    rad_hit *ha = NULL, *hb = NULL;
    size_t i;
    int r;
    if (intersect) { ha = (rad_hit *)malloc(n * sizeof(rad_hit)); hb = (rad_hit *)malloc(n * sizeof(rad_hit)); }
    else { oa = (uint8_t *)malloc(n); ob = (uint8_t *)malloc(n); }
    *ta = *tb = 1e30;
    for (r = 0; r < reps; ++r) {
        double t = replay_once(a, rays, n, threads, oa, ha);
        if (t < *ta) *ta = t;
        if (!b->occluded) continue;
        t = replay_once(b, rays, n, threads, ob, hb);
        if (t < *tb) *tb = t;
    }
    *differ = *positive = 0;
    for (i = 0; i < n; ++i) {
        if (intersect) {
            *positive += ha[i].triangle != RAD_NONE;
            if (b->occluded && ha[i].triangle != hb[i].triangle) (*differ)++;
        } else {
            *positive += oa[i];
            if (b->occluded && oa[i] != ob[i]) (*differ)++;
        }
    }
    free(oa); free(ob); free(ha); free(hb);
}

static void run_scene(const char *name, const rad_scene *scene, uint32_t target, uint32_t rows_wanted,
                      const rad_camera *cam, const float light[3])
{
    rad_patches *P = NULL;
    rad_bvh *bvh = NULL;
    rad_embree *emb = NULL;
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_raycaster rb, re;
    recorder rec;
    rad_context ctx;
    uint32_t r, step;
    double tb = 1e30, te = 1e30, t;
    float *rowbuf;
    int k, reps = 5;
    size_t i, s;
    rayset sets[4];
    if (g_only && !strstr(name, g_only)) return;
    memset(&re, 0, sizeof(re));
    memset(sets, 0, sizeof(sets));
    rad_patch_options_default(&po);
    po.target_count = target;
    if (rad_patches_create(scene, &po, NULL, &P) != RAD_SUCCESS) { printf("patches failed\n"); return; }
    for (k = 0; k < 5; ++k) { /* ABAB build timing */
        rad_bvh *b2 = NULL;
        rad_embree *e2 = NULL;
        t = now();
        rad_bvh_create(scene, NULL, &b2);
        t = now() - t;
        if (t < tb) tb = t;
        if (k < 4) rad_bvh_destroy(b2); else bvh = b2;
        if (!rad_embree_available()) continue;
        t = now();
        rad_embree_create(scene, NULL, &e2);
        t = now() - t;
        if (t < te) te = t;
        if (k < 4) rad_embree_destroy(e2); else emb = e2;
    }
    rad_bvh_raycaster(bvh, &rb);
    if (emb) rad_embree_raycaster(emb, &re);
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
    sets[0].name = "form-factor rows";
    sets[0].occ = rec.rays;
    sets[0].n = rec.count;
    sets[0].hit = (rad_ray *)malloc(rec.count * sizeof(rad_ray));
    for (i = 0; i < rec.count; ++i) { sets[0].hit[i] = rec.rays[i]; sets[0].hit[i].tmax = FLT_MAX; }
    path_sets(scene, &rb, cam, light, 512, 512, &sets[1], &sets[2], &sets[3]);
    emit("\n### %s: %u triangles\n\n", name, scene->triangle_count);
    emit("Build (best of 5, alternating): built-in BVH %.1f ms, %.0f KiB", tb * 1e3, rad_bvh_memory(bvh) / 1024.0);
    if (emb) emit("; Embree %.1f ms, %.0f KiB (Embree builds on all its threads)", te * 1e3, rad_embree_memory(emb) / 1024.0);
    emit(".\n\n");
    emit("| rays | query | count | 1 thread: BVH / Embree Mrays/s | ratio | 2 threads: BVH / Embree Mrays/s | ratio | answers differing |\n");
    emit("|---|---|---:|---:|---:|---:|---:|---:|\n");
    for (s = 0; s < 4 && (int)s < g_sets; ++s) {
        int q, th;
        for (q = 0; q < 2; ++q) {
            const rad_ray *rays = q ? sets[s].hit : sets[s].occ;
            size_t most = 0;
            if (!rays || sets[s].n == 0) continue;
            emit("| %s | %s | %zu |", sets[s].name, q ? "closest hit" : "occlusion", sets[s].n);
            for (th = 1; th <= 2; ++th) {
                double ta, tbb;
                size_t diff, pos;
                compare(&rb, &re, rays, sets[s].n, th, q, reps, &ta, &tbb, &diff, &pos);
                if (diff > most) most = diff;
                if (emb) emit(" %.2f / %.2f | %.2f |", sets[s].n / ta * 1e-6, sets[s].n / tbb * 1e-6, tbb / ta);
                else emit(" %.2f / - | - |", sets[s].n / ta * 1e-6);
            }
            if (emb) emit(" %zu |\n", most);
            else emit(" - |\n");
        }
    }
    for (s = 0; s < 4; ++s) {
        if (sets[s].hit != sets[s].occ) free(sets[s].hit);
        free(sets[s].occ);
    }
    rad_embree_destroy(emb);
    rad_bvh_destroy(bvh);
    rad_patches_destroy(P);
}

int main(int argc, char **argv)
{
    rad_scene_desc desc;
    rad_scene *cornell = NULL;
    rad_camera cam;
    const char *dir = getenv("RAD_DATA_DIR");
    char path[1024];
    float *bpos = NULL, box_light[3] = { 0.278f, 0.54f, 0.28f };
    uint32_t *bidx = NULL, bnv = 0, bnt = 0;
    int a;
    for (a = 1; a < argc; ++a)
        if (!strcmp(argv[a], "--append") && a + 1 < argc) g_md = fopen(argv[++a], "a");
        else if (!strcmp(argv[a], "--data") && a + 1 < argc) dir = argv[++a];
        else if (!strcmp(argv[a], "--only") && a + 1 < argc) g_only = argv[++a];
        else if (!strcmp(argv[a], "--sets") && a + 1 < argc) g_sets = atoi(argv[++a]);
    emit("\n## c) Ray queries: built-in BVH against Embree\n\n");
    emit_machine();
    emit("Ray sets: *form-factor rows* are the occlusion rays of a sample of rows (rad_form_factor_rows, default "
         "options), replayed as closest-hit queries with tmax = infinity; *camera* are 512x512 pinhole rays "
         "(coherent; occlusion = any hit along the ray); *bounce* are cosine-distributed rays from the camera hits "
         "(incoherent); *shadow* are segments from the bounce hits to a point light (incoherent origins). Chunks of "
         "1024 rays over OpenMP threads; one thread is timed by its CPU time (not inflated by other processes' "
         "time slices), two by wall time. The backends alternate (BVH, Embree, BVH, ...), best of 5 each, so load from "
         "other processes falls on both alike: compare the ratio column. Answers differing: rays whose occlusion "
         "flag or hit triangle differ between the backends. Built %s RAD_EMBREE.\n",
         rad_embree_available() ? "with" : "without");
    rad_cornell_box(&desc, &cam);
    if (rad_scene_create(&desc, NULL, &cornell) != RAD_SUCCESS) return 1;
    /* the 32-triangle box says little about speed: measured when there is no real scene, or asked by --only */
    if (!dir || !dir[0] || g_only) run_scene("Cornell box", cornell, 4000, 48, &cam, box_light);
    snprintf(path, sizeof(path), "%s/stanford-bunny.obj", dir ? dir : "");
    if (!dir || !dir[0]) {
        emit("\n### Stanford bunny in the Cornell box, Sponza: skipped (no data folder: pass --data DIR or set RAD_DATA_DIR; "
             "see docs/data.md)\n");
    } else if (bench_load_obj(path, &bpos, &bnv, &bidx, &bnt)) {
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
            run_scene("Stanford bunny in the Cornell box", s2, 1, 8, &cam, box_light);
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
    snprintf(path, sizeof(path), "%s/sponza.obj", dir ? dir : "");
    if (dir && dir[0] && bench_load_obj(path, &bpos, &bnv, &bidx, &bnt)) {
        /* the atrium as modelled (x along the nave, y up); one material; camera at one end of the
           nave looking down it, the point light high in the open roof */
        rad_mesh_desc mesh;
        rad_scene_desc d3 = desc;
        rad_scene *s3 = NULL;
        rad_camera sc;
        float sky[3] = { 0.0f, 14.0f, 0.0f };
        memset(&mesh, 0, sizeof(mesh));
        mesh.name = "sponza";
        mesh.positions = bpos;
        mesh.vertex_count = bnv;
        mesh.indices = bidx;
        mesh.triangle_count = bnt;
        d3.meshes = &mesh;
        d3.mesh_count = 1;
        d3.flags = RAD_SCENE_SKIP_DEGENERATE;
        sc.position[0] = -14.0f; sc.position[1] = 3.0f; sc.position[2] = 0.0f;
        sc.target[0] = 10.0f; sc.target[1] = 5.0f; sc.target[2] = 0.0f;
        sc.up[0] = 0.0f; sc.up[1] = 1.0f; sc.up[2] = 0.0f;
        sc.fov_y_degrees = 60.0f;
        if (rad_scene_create(&d3, NULL, &s3) == RAD_SUCCESS) {
            run_scene("Sponza atrium (Dabrovic)", s3, 1, 8, &sc, sky);
            rad_scene_destroy(s3);
        } else {
            emit("\nsponza scene: rad_scene_create failed\n");
        }
        free(bpos);
        free(bidx);
    } else if (dir && dir[0]) {
        emit("\n### Sponza: skipped (%s not found; see docs/data.md)\n", path);
    }
    rad_scene_destroy(cornell);
    if (g_md) fclose(g_md);
    return 0;
}

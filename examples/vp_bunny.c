/* vp_bunny.c - virtual patches (docs/methods/aavp.md) on real high-polygon meshes: the Stanford bunny
   (69 451 triangles) in the Cornell box, and with --ogre the bunny and the ogre (193 459
   triangles together) side by side in it. The meshes are public models that are not part of
   the repository (docs/data.md): the program reads them from the folder given by --data DIR,
   else $RAD_DATA_DIR; with no folder, or when a mesh is missing, it says it skipped and exits 0.

   What it does, timing every stage and tracking the peak bytes allocated through the library
   (a counting rad_context allocator):
     1. loads the OBJ files, fits each model on the floor of the built-in Cornell box (the two
        blocks removed), builds the scene and the BVH;
     2. builds axis-aligned virtual patches (rad_vp_create: voxels, face rays, exact clipped
        areas, then the form factors between samples merged per voxel and axis), or with
        --clustered Q general virtual patches (at most Q clusters per voxel);
     3. E = rho D from the ceiling light at the samples (rad_vp_sources), K Jacobi bounces,
        H = F (E + L) per patch;
     4. renders the image the way an engine would: per pixel, the direct irradiance D at the
        visible point with shadow rays, the indirect irradiance H gathered from the virtual
        patches (normal weights, trilinear filter), and radiance rho / pi (D + H) plus the
        light's own radiance; writes a PFM (linear radiance);
     5. with --classic N: the same with classic radiosity (at least one patch per triangle) on
        a copy whose models are decimated by vertex clustering (--classic-cell, metres), cut
        into about N patches (analytic form factors with visibility, 4 samples), rendered on
        that copy with H interpolated from the patch vertices;
     6. with --write-obj FILE: writes the combined scene (OBJ + MTL) so the reference path
        tracer can render it: the exact `rad trace` and `rad compare` commands are printed.

   Build:  cc -std=c99 -O2 -fopenmp -I. examples/vp_bunny.c -o build/vp_bunny -lm
   Run:    build/vp_bunny [--data DIR] [--ogre] [--resolution N] [--face-points P] [--clustered Q]
                          [--bounces K] [--size WxH] [--spp N] [-o OUT.pfm]
                          [--classic N] [--classic-cell C] [--classic-out OUT.pfm]
                          [--write-obj FILE.obj]                                            */

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

/* ---- small helpers ------------------------------------------------------------------------ */

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void *xmalloc(size_t n)
{
    void *p = malloc(n ? n : 1);
    if (!p) { fprintf(stderr, "vp_bunny: out of memory (%lu bytes)\n", (unsigned long)n); exit(1); }
    return p;
}

static void check(rad_result r, const char *what)
{
    if (r != RAD_SUCCESS) { fprintf(stderr, "vp_bunny: %s: %s\n", what, rad_result_string(r)); exit(1); }
}

static void on_log(void *user, rad_log_level level, const char *message)
{
    (void)user;
    fprintf(stderr, "  [%s] %s\n", level == RAD_LOG_ERROR ? "error" : level == RAD_LOG_WARNING ? "warning" : "info", message);
}

/* the counting allocator: live and peak bytes of everything the library allocates */
typedef struct counter { long long live, peak; } counter;

static void *count_alloc(void *user, size_t size)
{
    counter *c = (counter *)user;
    unsigned char *p = (unsigned char *)malloc(size + 16);
    if (!p) return NULL;
    memcpy(p, &size, sizeof(size));
#ifdef _OPENMP
#pragma omp critical(vp_bunny_count)
#endif
    {
        c->live += (long long)size;
        if (c->live > c->peak) c->peak = c->live;
    }
    return p + 16;
}

static void count_free(void *user, void *ptr)
{
    counter *c = (counter *)user;
    size_t size;
    if (!ptr) return;
    memcpy(&size, (unsigned char *)ptr - 16, sizeof(size));
#ifdef _OPENMP
#pragma omp critical(vp_bunny_count)
#endif
    {
        c->live -= (long long)size;
    }
    free((unsigned char *)ptr - 16);
}

/* progress: remembers when rad_vp_create passes 10% (face rays done, form factors start) */
typedef struct stage_clock { double face_done; } stage_clock;

static int on_progress(void *user, float fraction)
{
    stage_clock *s = (stage_clock *)user;
    if (fraction >= 0.1f && s->face_done == 0.0) s->face_done = now();
    return 0;
}

/* ---- OBJ (positions and faces only; polygons as fans) ------------------------------------- */

typedef struct mesh { float *pos; uint32_t nv, cap_v; uint32_t *idx; uint32_t nt, cap_t; } mesh;

static int load_obj(const char *path, mesh *m)
{
    FILE *f = fopen(path, "r");
    char line[4096];
    memset(m, 0, sizeof(*m));
    if (!f) return 0;
    while (fgets(line, sizeof(line), f)) {
        if (line[0] == 'v' && line[1] == ' ') {
            float x, y, z;
            if (sscanf(line + 2, "%f %f %f", &x, &y, &z) != 3) continue;
            if (m->nv == m->cap_v) {
                m->cap_v = m->cap_v ? 2 * m->cap_v : 4096;
                m->pos = (float *)realloc(m->pos, sizeof(float) * 3 * m->cap_v);
                if (!m->pos) { fclose(f); return 0; }
            }
            m->pos[3 * m->nv] = x; m->pos[3 * m->nv + 1] = y; m->pos[3 * m->nv + 2] = z;
            m->nv++;
        } else if (line[0] == 'f' && line[1] == ' ') {
            uint32_t ids[64], n = 0;
            char *p = line + 2;
            while (*p && n < 64) {
                long v;
                char *end;
                while (*p == ' ' || *p == '\t') ++p;
                v = strtol(p, &end, 10);
                if (end == p) break;
                ids[n++] = (uint32_t)(v < 0 ? (long)m->nv + v : v - 1);
                p = end;
                while (*p && *p != ' ' && *p != '\t' && *p != '\n' && *p != '\r') ++p;
            }
            for (; n >= 3; --n) {
                if (m->nt == m->cap_t) {
                    m->cap_t = m->cap_t ? 2 * m->cap_t : 8192;
                    m->idx = (uint32_t *)realloc(m->idx, sizeof(uint32_t) * 3 * m->cap_t);
                    if (!m->idx) { fclose(f); return 0; }
                }
                m->idx[3 * m->nt] = ids[0]; m->idx[3 * m->nt + 1] = ids[n - 2]; m->idx[3 * m->nt + 2] = ids[n - 1];
                m->nt++;
                if (n == 3) break;
            }
        }
    }
    fclose(f);
    return m->nv > 0 && m->nt > 0;
}

/* scales the mesh to 'height' and puts its bottom centre at (x, 0, z) */
static void fit(mesh *m, float height, float x, float z)
{
    float lo[3] = { 1e30f, 1e30f, 1e30f }, hi[3] = { -1e30f, -1e30f, -1e30f }, s;
    uint32_t i;
    int k;
    for (i = 0; i < m->nv; ++i)
        for (k = 0; k < 3; ++k) {
            if (m->pos[3 * i + k] < lo[k]) lo[k] = m->pos[3 * i + k];
            if (m->pos[3 * i + k] > hi[k]) hi[k] = m->pos[3 * i + k];
        }
    s = height / (hi[1] - lo[1]);
    for (i = 0; i < m->nv; ++i) {
        m->pos[3 * i] = (m->pos[3 * i] - 0.5f * (lo[0] + hi[0])) * s + x;
        m->pos[3 * i + 1] = (m->pos[3 * i + 1] - lo[1]) * s + 0.0005f; /* just above the floor */
        m->pos[3 * i + 2] = (m->pos[3 * i + 2] - 0.5f * (lo[2] + hi[2])) * s + z;
    }
}

/* Vertex clustering: every vertex moves to the mean of the vertices in its cell of side
   'cell'; triangles that collapse are dropped. Classic radiosity needs at least one patch per
   triangle, so it runs on this decimated copy. */
typedef struct cell_key { uint64_t key; uint32_t vertex; } cell_key;

static int cmp_cell(const void *a, const void *b)
{
    const cell_key *x = (const cell_key *)a, *y = (const cell_key *)b;
    if (x->key != y->key) return x->key < y->key ? -1 : 1;
    return x->vertex < y->vertex ? -1 : (x->vertex > y->vertex ? 1 : 0);
}

static void decimate(const mesh *in, float cell, mesh *out)
{
    cell_key *keys = (cell_key *)xmalloc(sizeof(cell_key) * in->nv);
    uint32_t *remap = (uint32_t *)xmalloc(sizeof(uint32_t) * in->nv), i, t, n = 0;
    memset(out, 0, sizeof(*out));
    out->pos = (float *)xmalloc(sizeof(float) * 3 * in->nv);
    out->idx = (uint32_t *)xmalloc(sizeof(uint32_t) * 3 * in->nt);
    for (i = 0; i < in->nv; ++i) {
        uint64_t k = 0;
        int c;
        for (c = 0; c < 3; ++c) k = k * 2097152u + (uint64_t)(int64_t)(floor(in->pos[3 * i + c] / cell) + 1048576.0);
        keys[i].key = k;
        keys[i].vertex = i;
    }
    qsort(keys, in->nv, sizeof(cell_key), cmp_cell);
    for (i = 0; i < in->nv;) {
        uint32_t j = i;
        double m[3] = { 0, 0, 0 };
        while (j < in->nv && keys[j].key == keys[i].key) {
            int c;
            for (c = 0; c < 3; ++c) m[c] += in->pos[3 * keys[j].vertex + c];
            remap[keys[j].vertex] = n;
            ++j;
        }
        out->pos[3 * n] = (float)(m[0] / (j - i));
        out->pos[3 * n + 1] = (float)(m[1] / (j - i));
        out->pos[3 * n + 2] = (float)(m[2] / (j - i));
        ++n;
        i = j;
    }
    out->nv = n;
    for (t = 0; t < in->nt; ++t) {
        uint32_t a = remap[in->idx[3 * t]], b = remap[in->idx[3 * t + 1]], c = remap[in->idx[3 * t + 2]];
        if (a == b || b == c || a == c) continue;
        out->idx[3 * out->nt] = a; out->idx[3 * out->nt + 1] = b; out->idx[3 * out->nt + 2] = c;
        out->nt++;
    }
    free(keys);
    free(remap);
}

/* ---- the combined scene as OBJ + MTL, for `rad trace` --------------------------------------- */

static int write_obj(const char *path, const rad_scene *S)
{
    char mtl[1024];
    const char *base;
    FILE *f, *g;
    uint32_t t, m;
    snprintf(mtl, sizeof(mtl), "%.*s.mtl", (int)(strlen(path) > 4 ? strlen(path) - 4 : strlen(path)), path);
    base = strrchr(mtl, '/');
    base = base ? base + 1 : mtl;
    f = fopen(path, "w");
    g = fopen(mtl, "w");
    if (!f || !g) { if (f) fclose(f); if (g) fclose(g); return 0; }
    for (m = 0; m < S->material_count; ++m) {
        const rad_material *mt = &S->materials_table[m];
        fprintf(g, "newmtl m%u\nKd %.6f %.6f %.6f\nKe %.6f %.6f %.6f\n\n", m, mt->albedo[0], mt->albedo[1], mt->albedo[2],
                mt->emission[0], mt->emission[1], mt->emission[2]);
    }
    fprintf(f, "mtllib %s\n", base);
    for (t = 0; t < S->triangle_count; ++t) {
        const float *v = S->positions + 9 * (size_t)t;
        fprintf(f, "v %.7g %.7g %.7g\nv %.7g %.7g %.7g\nv %.7g %.7g %.7g\n", v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8]);
    }
    for (t = 0, m = RAD_NONE; t < S->triangle_count; ++t) {
        if (S->materials[t] != m) { m = S->materials[t]; fprintf(f, "usemtl m%u\n", m); }
        fprintf(f, "f %u %u %u\n", 3 * t + 1, 3 * t + 2, 3 * t + 3);
    }
    fclose(g);
    return fclose(f) == 0;
}

static int write_pfm(const char *path, const float *rgb, uint32_t w, uint32_t h)
{
    FILE *f = fopen(path, "wb");
    uint32_t y;
    if (!f) return 0;
    fprintf(f, "PF\n%u %u\n-1.0\n", w, h);
    for (y = h; y-- > 0;) fwrite(rgb + (size_t)y * w * 3, sizeof(float), (size_t)w * 3, f);
    return fclose(f) == 0;
}

/* ---- rendering ------------------------------------------------------------------------------ */

/* the visible points of every sub-pixel sample: hit flag, triangle, barycentrics, point, normal */
typedef struct view {
    uint32_t count, w, h, spp;
    rad_hit *hits;
    float *pts, *nrm;
} view;

static void trace_view(view *v, const rad_scene *S, const rad_raycaster *rc, const rad_camera *cam, uint32_t w, uint32_t h,
                       uint32_t spp)
{
    uint32_t n = w * h * spp, i, side = (uint32_t)floor(sqrt((double)spp) + 0.5);
    rad_ray *rays = (rad_ray *)xmalloc(sizeof(rad_ray) * n);
    if (side * side != spp) side = 1;
    v->count = n; v->w = w; v->h = h; v->spp = spp;
    v->hits = (rad_hit *)xmalloc(sizeof(rad_hit) * n);
    v->pts = (float *)xmalloc(sizeof(float) * 3 * n);
    v->nrm = (float *)xmalloc(sizeof(float) * 3 * n);
    for (i = 0; i < n; ++i) {
        uint32_t pix = i / spp, s = i % spp;
        float jx = side > 1 ? ((float)(s % side) + 0.5f) / (float)side : 0.5f, jy = side > 1 ? ((float)(s / side) + 0.5f) / (float)side : 0.5f;
        rad_camera_ray(cam, w, h, (float)(pix % w) + jx, (float)(pix / w) + jy, &rays[i]);
    }
    check(rc->intersect(rc->user, rays, n, v->hits), "camera rays");
    for (i = 0; i < n; ++i) {
        int k;
        if (v->hits[i].triangle == RAD_NONE) {
            for (k = 0; k < 3; ++k) { v->pts[3 * i + k] = 0.0f; v->nrm[3 * i + k] = (k == 1) ? 1.0f : 0.0f; }
            continue;
        }
        for (k = 0; k < 3; ++k) {
            v->pts[3 * i + k] = rays[i].origin[k] + v->hits[i].t * rays[i].dir[k];
            v->nrm[3 * i + k] = S->normals[3 * (size_t)v->hits[i].triangle + k];
        }
        /* a back face is black (one-sided, as the reference tracer): mark it as a miss */
        if (rays[i].dir[0] * v->nrm[3 * i] + rays[i].dir[1] * v->nrm[3 * i + 1] + rays[i].dir[2] * v->nrm[3 * i + 2] > 0.0f)
            v->hits[i].triangle = RAD_NONE - 1u;
    }
    free(rays);
}

/* radiance rho / pi (D + H) + emission, averaged over the sub-pixel samples */
static void shade(const view *v, const rad_scene *S, const float *D, const float *H, float *img)
{
    uint32_t i, k;
    memset(img, 0, sizeof(float) * 3 * v->w * v->h);
    for (i = 0; i < v->count; ++i) {
        uint32_t t = v->hits[i].triangle, pix = i / v->spp;
        float rho[3];
        if (t >= S->triangle_count) continue;
        rad_scene_albedo(S, t, v->hits[i].b1, v->hits[i].b2, rho);
        for (k = 0; k < 3; ++k)
            img[3 * pix + k] += (rho[k] / 3.14159265f * (D[3 * i + k] + H[3 * i + k]) +
                                 S->materials_table[S->materials[t]].emission[k]) / (float)v->spp;
    }
}

static void usage(void)
{
    fprintf(stderr, "usage: vp_bunny [--data DIR] [--ogre] [--resolution N] [--face-points P] [--clustered Q] [--bounces K]\n"
                    "                [--size WxH] [--spp N] [-o OUT.pfm] [--classic N] [--classic-cell C]\n"
                    "                [--classic-out OUT.pfm]\n"
                    "                [--write-obj FILE.obj]\n");
    exit(2);
}

int main(int argc, char **argv)
{
    const char *data = getenv("RAD_DATA_DIR"), *out = "vp_bunny.pfm", *classic_out = "vp_bunny_classic.pfm", *obj_out = NULL;
    char path[2048];
    int ogre = 0, a;
    uint32_t resolution = 32, face_points = 16, bounces = 16, W = 128, Hh = 128, spp = 4, classic = 0, i, k;
    float classic_cell = 0.012f;
    uint32_t clustered = 0;
    mesh bunny, ogre_mesh;
    rad_scene_desc cornell, desc;
    rad_camera cam;
    rad_mesh_desc meshes[16];
    rad_material materials[16];
    rad_scene *scene = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_context ctx;
    counter cnt;
    stage_clock sc;
    rad_vp_options vo;
    rad_virtual_patches *vp = NULL;
    rad_direct_options dopt;
    rad_solve_options so;
    rad_system sys;
    view v;
    float *E, *L, *EL, *Hp, *D, *Hpix, *img;
    double t0, t1, t_scene, t_bvh, t_vp_face, t_vp_ff, t_E, t_solve, t_direct, t_gather;
    long long peak_vp, peak_classic = 0;
    uint32_t total_tris = 0;

    setvbuf(stdout, NULL, _IOLBF, 0);
    for (a = 1; a < argc; ++a) {
        const char *s = argv[a];
        if (!strcmp(s, "--data") && a + 1 < argc) data = argv[++a];
        else if (!strcmp(s, "--ogre")) ogre = 1;
        else if (!strcmp(s, "--clustered") && a + 1 < argc) clustered = (uint32_t)strtoul(argv[++a], NULL, 10);
        else if (!strcmp(s, "--resolution") && a + 1 < argc) resolution = (uint32_t)strtoul(argv[++a], NULL, 10);
        else if (!strcmp(s, "--face-points") && a + 1 < argc) face_points = (uint32_t)strtoul(argv[++a], NULL, 10);
        else if (!strcmp(s, "--bounces") && a + 1 < argc) bounces = (uint32_t)strtoul(argv[++a], NULL, 10);
        else if (!strcmp(s, "--spp") && a + 1 < argc) spp = (uint32_t)strtoul(argv[++a], NULL, 10);
        else if (!strcmp(s, "--size") && a + 1 < argc) { if (sscanf(argv[++a], "%ux%u", &W, &Hh) != 2) usage(); }
        else if (!strcmp(s, "-o") && a + 1 < argc) out = argv[++a];
        else if (!strcmp(s, "--classic") && a + 1 < argc) classic = (uint32_t)strtoul(argv[++a], NULL, 10);
        else if (!strcmp(s, "--classic-out") && a + 1 < argc) classic_out = argv[++a];
        else if (!strcmp(s, "--classic-cell") && a + 1 < argc) classic_cell = (float)atof(argv[++a]);
        else if (!strcmp(s, "--write-obj") && a + 1 < argc) obj_out = argv[++a];
        else usage();
    }
    if (W == 0 || Hh == 0 || spp == 0 || resolution == 0) usage();

    /* 1. meshes and scene */
    if (!data || !data[0]) {
        printf("vp_bunny: skipped: no data folder (pass --data DIR or set RAD_DATA_DIR to a folder holding the meshes "
               "of docs/data.md)\n");
        return 0;
    }
    t0 = now();
    snprintf(path, sizeof(path), "%s/stanford-bunny.obj", data);
    if (!load_obj(path, &bunny)) {
        printf("vp_bunny: skipped: %s not found or unreadable (see docs/data.md; set RAD_DATA_DIR or --data)\n", path);
        return 0;
    }
    if (ogre) {
        snprintf(path, sizeof(path), "%s/ogre.obj", data);
        if (!load_obj(path, &ogre_mesh)) {
            printf("vp_bunny: skipped: %s not found or unreadable (see docs/data.md; set RAD_DATA_DIR or --data)\n", path);
            return 0;
        }
        fit(&bunny, 0.22f, 0.16f, 0.30f);
        fit(&ogre_mesh, 0.30f, 0.40f, 0.30f);
    } else {
        fit(&bunny, 0.30f, 0.28f, 0.28f);
    }
    rad_cornell_box(&cornell, &cam);
    memset(&desc, 0, sizeof(desc));
    for (i = 0; i < cornell.mesh_count; ++i) {
        if (cornell.meshes[i].name && strstr(cornell.meshes[i].name, "block")) continue; /* room for the models */
        meshes[desc.mesh_count++] = cornell.meshes[i];
        total_tris += cornell.meshes[i].triangle_count;
    }
    memcpy(materials, cornell.materials, sizeof(rad_material) * cornell.material_count);
    memset(&materials[cornell.material_count], 0, sizeof(rad_material));
    for (k = 0; k < 3; ++k) materials[cornell.material_count].albedo[k] = 0.7f;
    memset(&meshes[desc.mesh_count], 0, sizeof(rad_mesh_desc));
    meshes[desc.mesh_count].name = "bunny";
    meshes[desc.mesh_count].positions = bunny.pos;
    meshes[desc.mesh_count].vertex_count = bunny.nv;
    meshes[desc.mesh_count].indices = bunny.idx;
    meshes[desc.mesh_count].triangle_count = bunny.nt;
    meshes[desc.mesh_count].material = cornell.material_count;
    total_tris += bunny.nt;
    desc.mesh_count++;
    if (ogre) {
        meshes[desc.mesh_count] = meshes[desc.mesh_count - 1];
        meshes[desc.mesh_count].name = "ogre";
        meshes[desc.mesh_count].positions = ogre_mesh.pos;
        meshes[desc.mesh_count].vertex_count = ogre_mesh.nv;
        meshes[desc.mesh_count].indices = ogre_mesh.idx;
        meshes[desc.mesh_count].triangle_count = ogre_mesh.nt;
        total_tris += ogre_mesh.nt;
        desc.mesh_count++;
    }
    desc.meshes = meshes;
    desc.materials = materials;
    desc.material_count = cornell.material_count + 1;
    desc.flags = RAD_SCENE_SKIP_DEGENERATE;

    memset(&ctx, 0, sizeof(ctx));
    memset(&cnt, 0, sizeof(cnt));
    ctx.allocator.alloc = count_alloc;
    ctx.allocator.free = count_free;
    ctx.allocator.user = &cnt;
    ctx.log = on_log;
    check(rad_scene_create(&desc, &ctx, &scene), "scene");
    t1 = now();
    t_scene = t1 - t0;
    printf("scene: %u triangles (%u degenerate skipped), load + validate %.2f s\n", scene->triangle_count,
           scene->skipped_triangles, t_scene);
    if (obj_out) {
        if (!write_obj(obj_out, scene)) { fprintf(stderr, "vp_bunny: cannot write %s\n", obj_out); return 1; }
        printf("wrote %s; reference: rad trace %s --camera %g,%g,%g:%g,%g,%g:%g,%g,%g --fov %g --size %ux%u --spp 256 -o ref.pfm\n",
               obj_out, obj_out, cam.position[0], cam.position[1], cam.position[2], cam.target[0], cam.target[1],
               cam.target[2], cam.up[0], cam.up[1], cam.up[2], cam.fov_y_degrees, W, Hh);
    }
    t0 = now();
    check(rad_bvh_create(scene, &ctx, &bvh), "BVH");
    rad_bvh_raycaster(bvh, &rc);
    t_bvh = now() - t0;
    printf("BVH: %.2f s, %.1f MiB\n", t_bvh, (double)rad_bvh_memory(bvh) / 1048576.0);

    /* 2. virtual patches */
    rad_vp_options_default(&vo);
    vo.resolution = resolution;
    vo.face_points = face_points;
    if (clustered) {
        vo.kind = RAD_VP_CLUSTERED;
        vo.max_clusters = clustered;
    }
    memset(&sc, 0, sizeof(sc));
    ctx.progress = on_progress;
    ctx.progress_user = &sc;
    cnt.peak = cnt.live;
    t0 = now();
    check(rad_vp_create(scene, &rc, &vo, &ctx, &vp), "virtual patches");
    t1 = now();
    ctx.progress = NULL;
    peak_vp = cnt.peak;
    t_vp_face = (sc.face_done > 0.0 ? sc.face_done : t1) - t0;
    t_vp_ff = t1 - t0 - t_vp_face;
    printf("%s virtual patches: grid %ux%ux%u (voxel %.4f), %u candidate and %u non-empty voxels, %llu face rays\n",
           clustered ? "general (clustered)" : "axis-aligned", vp->dims[0], vp->dims[1], vp->dims[2], vp->voxel_size[0], vp->candidate_voxels, vp->voxel_count,
           (unsigned long long)vp->face_rays);
    printf("  %u samples, %u patches; voxelize + face rays %.2f s, form factors %.2f s (%llu shadow rays)\n",
           vp->sample_count, vp->count, t_vp_face, t_vp_ff, (unsigned long long)vp->pair_rays);
    {
        double mean = 0.0, area = 0.0, mx = 0.0;
        uint32_t r, c, worst = 0;
        for (r = 0; r < vp->count; ++r) {
            double sum = 0.0;
            for (c = 0; c < vp->count; ++c) sum += vp->matrix.dense[(size_t)r * vp->count + c];
            mean += vp->areas[r] * sum;
            area += vp->areas[r];
            if (sum > mx) { mx = sum; worst = r; }
        }
        printf("  row sums: area-weighted mean %.4f, largest %.4f (patch %u, area %.3g)\n", mean / area, mx, worst,
               vp->areas[worst]);
    }
    printf("  peak memory during the build %.1f MiB (scene + BVH + build), held after %.1f MiB\n",
           (double)peak_vp / 1048576.0, (double)rad_vp_memory(vp) / 1048576.0);

    /* 3. E, bounces, H per patch */
    rad_direct_options_default(&dopt);
    E = (float *)xmalloc(sizeof(float) * 3 * vp->count);
    L = (float *)xmalloc(sizeof(float) * 3 * vp->count);
    EL = (float *)xmalloc(sizeof(float) * 3 * vp->count);
    Hp = (float *)xmalloc(sizeof(float) * 3 * vp->count);
    t0 = now();
    check(rad_vp_sources(vp, &rc, NULL, 0, &dopt, RAD_SOURCE_DIRECT, E, &ctx), "sources");
    t_E = now() - t0;
    t0 = now();
    rad_vp_system(&sys, vp, E);
    rad_solve_options_default(&so);
    so.output = RAD_OUTPUT_INDIRECT;
    so.bounces = bounces;
    check(rad_solve_jacobi(&sys, &so, L, NULL, &ctx), "Jacobi");
    for (i = 0; i < 3 * vp->count; ++i) EL[i] = E[i] + L[i];
    check(rad_matrix_multiply(&vp->matrix, EL, Hp, &ctx), "H = F (E + L)");
    t_solve = now() - t0;
    printf("  E at the samples %.2f s; %u Jacobi bounces + H %.2f s\n", t_E, bounces, t_solve);

    /* 4. the image */
    trace_view(&v, scene, &rc, &cam, W, Hh, spp);
    D = (float *)xmalloc(sizeof(float) * 3 * v.count);
    Hpix = (float *)xmalloc(sizeof(float) * 3 * v.count);
    img = (float *)xmalloc(sizeof(float) * 3 * W * Hh);
    t0 = now();
    check(rad_direct_irradiance(scene, &rc, NULL, 0, &dopt, v.pts, v.nrm, v.count, D, &ctx), "direct light per pixel");
    t_direct = now() - t0;
    t0 = now();
    check(rad_vp_gather(vp, Hp, v.pts, v.nrm, v.count, Hpix, &ctx), "gather");
    t_gather = now() - t0;
    shade(&v, scene, D, Hpix, img);
    if (!write_pfm(out, img, W, Hh)) { fprintf(stderr, "vp_bunny: cannot write %s\n", out); return 1; }
    printf("  image %ux%u, %u spp: direct light %.2f s, gathering %.3f s (%.0f ns per point) -> %s\n", W, Hh, spp, t_direct,
           t_gather, 1e9 * t_gather / v.count, out);

    /* 5. classic radiosity with about the same number of patches */
    if (classic) {
        rad_patches *P = NULL;
        rad_patch_options po;
        rad_form_factor_options fo;
        rad_form_factors *ff = NULL;
        rad_scene *cs = NULL;
        rad_bvh *cbvh = NULL;
        rad_raycaster crc;
        rad_mesh_desc cmeshes[16];
        rad_scene_desc cdesc = desc;
        mesh dec[2];
        view cv;
        float *Ec, *Lc, *ELc, *Hc, *Dc, *Hv, *Hpc, *Dpix;
        uint32_t n, m, nd = 0;
        memcpy(cmeshes, meshes, sizeof(rad_mesh_desc) * desc.mesh_count);
        for (m = 0; m < desc.mesh_count; ++m) {
            mesh src;
            if (strcmp(cmeshes[m].name, "bunny") && strcmp(cmeshes[m].name, "ogre")) continue;
            src.pos = (float *)cmeshes[m].positions;
            src.nv = cmeshes[m].vertex_count;
            src.idx = (uint32_t *)cmeshes[m].indices;
            src.nt = cmeshes[m].triangle_count;
            decimate(&src, classic_cell, &dec[nd]);
            cmeshes[m].positions = dec[nd].pos;
            cmeshes[m].vertex_count = dec[nd].nv;
            cmeshes[m].indices = dec[nd].idx;
            cmeshes[m].triangle_count = dec[nd].nt;
            printf("classic: '%s' decimated to %u triangles (vertex clustering, cell %.4f)\n", cmeshes[m].name, dec[nd].nt,
                   classic_cell);
            ++nd;
        }
        cdesc.meshes = cmeshes;
        check(rad_scene_create(&cdesc, &ctx, &cs), "classic scene");
        check(rad_bvh_create(cs, &ctx, &cbvh), "classic BVH");
        rad_bvh_raycaster(cbvh, &crc);
        rad_patch_options_default(&po);
        po.target_count = classic;
        cnt.peak = cnt.live;
        t0 = now();
        check(rad_patches_create(cs, &po, &ctx, &P), "patches");
        n = P->count;
        rad_form_factor_options_default(&fo);
        fo.samples = 4;
        check(rad_form_factors_dense(P, &crc, &fo, &ctx, &ff), "form factors");
        t1 = now();
        peak_classic = cnt.peak;
        printf("classic: %u patches (target %u), patches + form factors %.2f s, peak %.1f MiB\n", n, classic, t1 - t0,
               (double)peak_classic / 1048576.0);
        Ec = (float *)xmalloc(sizeof(float) * 3 * n);
        Lc = (float *)xmalloc(sizeof(float) * 3 * n);
        ELc = (float *)xmalloc(sizeof(float) * 3 * n);
        Hc = (float *)xmalloc(sizeof(float) * 3 * n);
        Dc = (float *)xmalloc(sizeof(float) * 3 * n);
        Hv = (float *)xmalloc(sizeof(float) * 3 * P->vertex_count);
        trace_view(&cv, cs, &crc, &cam, W, Hh, spp);
        Hpc = (float *)xmalloc(sizeof(float) * 3 * cv.count);
        Dpix = (float *)xmalloc(sizeof(float) * 3 * cv.count);
        t0 = now();
        check(rad_direct_patches(P, &crc, NULL, 0, &dopt, Dc, &ctx), "classic direct");
        check(rad_sources(P, RAD_SOURCE_DIRECT, Dc, Ec), "classic sources");
        rad_system_init(&sys, &ff->matrix, P, Ec);
        check(rad_solve_jacobi(&sys, &so, Lc, NULL, &ctx), "classic Jacobi");
        for (i = 0; i < 3 * n; ++i) ELc[i] = Ec[i] + Lc[i];
        check(rad_matrix_multiply(&ff->matrix, ELc, Hc, &ctx), "classic H");
        check(rad_patches_vertex_values(P, Hc, 3, Hv), "vertex values");
        printf("  E + bounces + H %.2f s\n", now() - t0);
        check(rad_direct_irradiance(cs, &crc, NULL, 0, &dopt, cv.pts, cv.nrm, cv.count, Dpix, &ctx), "classic direct per pixel");
        for (i = 0; i < cv.count; ++i) {
            float w[3];
            uint32_t p, t = cv.hits[i].triangle;
            for (k = 0; k < 3; ++k) Hpc[3 * i + k] = 0.0f;
            if (t >= cs->triangle_count) continue;
            p = rad_patches_locate(P, t, cv.hits[i].b1, cv.hits[i].b2, w);
            if (p == RAD_NONE) continue;
            for (k = 0; k < 3; ++k)
                Hpc[3 * i + k] = w[0] * Hv[3 * P->patches[p].vertices[0] + k] + w[1] * Hv[3 * P->patches[p].vertices[1] + k] +
                                 w[2] * Hv[3 * P->patches[p].vertices[2] + k];
        }
        shade(&cv, cs, Dpix, Hpc, img);
        if (!write_pfm(classic_out, img, W, Hh)) { fprintf(stderr, "vp_bunny: cannot write %s\n", classic_out); return 1; }
        printf("  image -> %s\n", classic_out);
        free(Ec); free(Lc); free(ELc); free(Hc); free(Dc); free(Hv); free(Hpc); free(Dpix);
        free(cv.hits); free(cv.pts); free(cv.nrm);
        for (m = 0; m < nd; ++m) { free(dec[m].pos); free(dec[m].idx); }
        rad_form_factors_destroy(ff);
        rad_patches_destroy(P);
        rad_bvh_destroy(cbvh);
        rad_scene_destroy(cs);
    }
    if (obj_out) printf("compare: rad compare %s ref.pfm%s%s\n", out, classic ? "; rad compare " : "", classic ? classic_out : "");
    printf("scene triangles %u -> %u virtual patches; peak through the allocator: virtual patches %.1f MiB%s",
           total_tris, vp->count, (double)peak_vp / 1048576.0, classic ? "" : "\n");
    if (classic) printf(", classic %.1f MiB\n", (double)peak_classic / 1048576.0);

    free(E); free(L); free(EL); free(Hp); free(D); free(Hpix); free(img);
    free(v.hits); free(v.pts); free(v.nrm);
    rad_vp_destroy(vp);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(scene);
    free(bunny.pos); free(bunny.idx);
    if (ogre) { free(ogre_mesh.pos); free(ogre_mesh.idx); }
    return 0;
}

/* fixtures.h - what the unit-test files share: the implementation (each test file is one
   translation unit, alone or inside test_main.c), the harness (test.h), the Embree stand-in of
   the unit-embree suite, and the scene builders, allocators and worlds that several test files
   build their cases from. The functions are static inline so that a file built on its own
   compiles warning-free while leaving most of them unused. Names keep the prefix of the file
   they came from (sc_, ff_, vp_, ct_, so_), so the tests that call them read as before; fx_
   names are the ones written here. */
#ifndef RAD_TEST_FIXTURES_H
#define RAD_TEST_FIXTURES_H
#define RADIOSITY_IMPLEMENTATION
/* small chunks, so the sparse virtual-patch build's chunking is exercised (vp_sparse_rows) */
#ifndef RAD_VP_ROW_CHUNK_BYTES
#define RAD_VP_ROW_CHUNK_BYTES 65536u
#endif
#include "../radiosity.h"
#include "test.h"

#ifndef FF_PI
#define FF_PI 3.14159265358979323846
#endif

/* the library's own rad_bvh_destroy, defined before the Embree stand-in below redefines the name */
static inline void rad__bvh_destroy_real(rad_bvh *bvh) { rad_bvh_destroy(bvh); }

#ifdef RAD_TEST_EMBREE
/* The Embree suite: every raycaster the tests take from a BVH is an Embree raycaster over the
   same triangles, so the whole suite checks the Embree backend against the same expectations. */
#define RAD_TEST_EMBREE_MAX 256
static struct { const rad_bvh *bvh; rad_embree *embree; } rad_test_embree_map[RAD_TEST_EMBREE_MAX];

/* The BVH's leaves (each wide node is followed by its leaves' triangles), by a walk of its
   tree; *count of them in a malloc'ed array, NULL when out of memory. */
static inline const rad__tri4 **rad_test_bvh_leaves(const rad_bvh *bvh, uint32_t *count)
{
    const rad__tri4 **out = (const rad__tri4 **)malloc(sizeof(*out) * (bvh->leaf_count + 1u));
    uint32_t *stack = (uint32_t *)malloc(sizeof(uint32_t) * (bvh->node_count + 1u)), sp = 0, k;
    *count = 0;
    if (!out || !stack) { free(out); free(stack); return NULL; }
    stack[sp++] = 0;
    while (sp > 0) {
        const rad__bvhw *n = (const rad__bvhw *)(const void *)(bvh->tree + (size_t)stack[--sp] * 64u);
        for (k = 0; k < RAD__BVH_W; ++k) {
            uint32_t ch = n->child[k];
            if (ch == RAD_NONE) continue;
            if (ch & RAD__BVH4_LEAF) out[(*count)++] = (const rad__tri4 *)(const void *)((const unsigned char *)n + RAD__BVH_LEAF_AT(ch));
            else stack[sp++] = ch;
        }
    }
    free(stack);
    return out;
}

static inline void rad_test_embree_raycaster(const rad_bvh *bvh, rad_raycaster *out)
{
    const rad__tri4 **leaves;
    uint32_t nleaves;
    rad_scene fake;
    float *pos;
    uint32_t i, slot = RAD_TEST_EMBREE_MAX;
    rad_embree *e = NULL;
    rad_bvh_raycaster(bvh, out); /* a fallback that keeps tests running if Embree fails */
    if (!bvh) return;
    for (i = 0; i < RAD_TEST_EMBREE_MAX; ++i) {
        if (rad_test_embree_map[i].bvh == bvh) { rad_embree_raycaster(rad_test_embree_map[i].embree, out); return; }
        if (!rad_test_embree_map[i].bvh && slot == RAD_TEST_EMBREE_MAX) slot = i;
    }
    /* two-sided and cutout scenes keep the BVH: this copy of the triangles has no twins array
       for Embree's front-only filter and no uvs for its cutout filter (test_twosided.c and
       test_cutout.c check Embree on them directly) */
    leaves = rad_test_bvh_leaves(bvh, &nleaves);
    if (!leaves) { printf("    FAIL out of memory\n"); rad_test_failures++; return; }
    for (i = 0; i < nleaves; ++i) {
        uint32_t j;
        for (j = 0; j < 4; ++j)
            if (leaves[i]->id[j] != RAD_NONE && (leaves[i]->id[j] & (RAD__BVH_FRONT_ONLY | RAD__BVH_CUTOUT))) { free((void *)leaves); return; }
    }
    pos = (float *)malloc(sizeof(float) * 9 * bvh->tri_count);
    if (!pos || slot == RAD_TEST_EMBREE_MAX) { free(pos); free((void *)leaves); printf("    FAIL embree map full\n"); rad_test_failures++; return; }
    for (i = 0; i < nleaves; ++i) { /* the BVH's own copy of the triangles, lane by lane */
        const rad__tri4 *q = leaves[i];
        uint32_t j, c, a;
        for (j = 0; j < 4; ++j)
            if (q->id[j] != RAD_NONE)
                for (c = 0; c < 3; ++c)
                    for (a = 0; a < 3; ++a) pos[9 * (size_t)q->id[j] + 3 * c + a] = q->v[c][a][j];
    }
    free((void *)leaves);
    memset(&fake, 0, sizeof(fake));
    fake.positions = pos;
    fake.triangle_count = bvh->tri_count;
    if (rad_embree_create(&fake, NULL, &e) != RAD_SUCCESS) { printf("    FAIL rad_embree_create\n"); rad_test_failures++; free(pos); return; }
    free(pos);
    rad_test_embree_map[slot].bvh = bvh;
    rad_test_embree_map[slot].embree = e;
    rad_embree_raycaster(e, out);
}

static inline void rad_test_embree_bvh_destroy(rad_bvh *bvh)
{
    uint32_t i;
    for (i = 0; i < RAD_TEST_EMBREE_MAX; ++i)
        if (bvh && rad_test_embree_map[i].bvh == bvh) {
            rad_embree_destroy(rad_test_embree_map[i].embree);
            rad_test_embree_map[i].bvh = NULL;
            rad_test_embree_map[i].embree = NULL;
        }
    rad_bvh_destroy(bvh);
}
#define rad_bvh_raycaster(bvh, out) rad_test_embree_raycaster(bvh, out)
#define rad_bvh_destroy(bvh) rad_test_embree_bvh_destroy(bvh)
#endif

/* ---- schedules: parallel_for hooks that run the tasks serially, forwards or backwards -------- */

static inline void fx_serial_for(void *user, uint32_t count, rad_task_fn fn, void *data)
{
    uint32_t i;
    (void)user;
    for (i = 0; i < count; ++i) fn(data, i);
}

static inline void fx_reverse_for(void *user, uint32_t count, rad_task_fn fn, void *data)
{
    uint32_t i;
    (void)user;
    for (i = count; i-- > 0;) fn(data, i);
}

/* ---- a log sink and a counting allocator (sc_) ---------------------------------------------- */

typedef struct sc_log_state {
    int count;
    char last[512];
} sc_log_state;

static inline void sc_log_fn(void *user, rad_log_level level, const char *message)
{
    sc_log_state *s = (sc_log_state *)user;
    (void)level;
    s->count++;
    strncpy(s->last, message, sizeof(s->last) - 1);
    s->last[sizeof(s->last) - 1] = '\0';
}

/* A counting allocator: a 16-byte header holds the size so live bytes can be tracked, and a
   64-byte canary after each block catches writes past the end (counted in 'corrupt' on free)
   without corrupting the heap. fail_at > 0 makes the fail_at-th allocation (1-based) fail. */
#define SC_CANARY 64
typedef struct sc_alloc_state {
    long calls, allocs, frees, failed, corrupt;
    long long live_bytes;
    long fail_at;
} sc_alloc_state;

static inline void *sc_alloc_fn(void *user, size_t size)
{
    sc_alloc_state *s = (sc_alloc_state *)user;
    unsigned char *p;
    long n;
#ifdef _OPENMP
#pragma omp critical(sc_alloc_lock)
#endif
    {
        n = ++s->calls;
    }
    if (s->fail_at > 0 && n == s->fail_at) {
#ifdef _OPENMP
#pragma omp critical(sc_alloc_lock)
#endif
        {
            s->failed++;
        }
        return NULL;
    }
    p = (unsigned char *)malloc(size + 16 + SC_CANARY);
    if (!p) return NULL;
    memcpy(p, &size, sizeof(size));
    memset(p + 16 + size, 0xA5, SC_CANARY);
#ifdef _OPENMP
#pragma omp critical(sc_alloc_lock)
#endif
    {
        s->allocs++;
        s->live_bytes += (long long)size;
    }
    return p + 16;
}

static inline void sc_free_fn(void *user, void *ptr)
{
    sc_alloc_state *s = (sc_alloc_state *)user;
    unsigned char *p;
    size_t size, i;
    int bad = 0;
    if (!ptr) return;
    p = (unsigned char *)ptr - 16;
    memcpy(&size, p, sizeof(size));
    for (i = 0; i < SC_CANARY; ++i) bad |= p[16 + size + i] != 0xA5;
#ifdef _OPENMP
#pragma omp critical(sc_alloc_lock)
#endif
    {
        s->frees++;
        s->corrupt += bad;
        s->live_bytes -= (long long)size;
    }
    free(p);
}

static inline void sc_ctx_alloc(rad_context *ctx, sc_alloc_state *st)
{
    memset(ctx, 0, sizeof(*ctx));
    ctx->allocator.alloc = sc_alloc_fn;
    ctx->allocator.free = sc_free_fn;
    ctx->allocator.user = st;
}


/* ---- quads, small worlds and Howell's closed forms (ff_) ----------------------------------- */

/* A planar quad o, o+u, o+u+v, o+v: counter-clockwise seen from the side u x v points to, so
   that side is its front. Two triangles (0 1 2) (0 2 3). */
typedef struct ff_quad {
    float pos[12];
} ff_quad;

static const uint32_t ff_quad_indices[6] = { 0, 1, 2, 0, 2, 3 };

static inline void ff_quad_set(ff_quad *q, float ox, float oy, float oz, float ux, float uy, float uz, float vx, float vy,
                        float vz)
{
    float o[3], u[3], v[3];
    int k;
    o[0] = ox; o[1] = oy; o[2] = oz;
    u[0] = ux; u[1] = uy; u[2] = uz;
    v[0] = vx; v[1] = vy; v[2] = vz;
    for (k = 0; k < 3; ++k) {
        q->pos[k] = o[k];
        q->pos[3 + k] = o[k] + u[k];
        q->pos[6 + k] = o[k] + u[k] + v[k];
        q->pos[9 + k] = o[k] + v[k];
    }
}

static inline void ff_mesh_quad(rad_mesh_desc *m, const ff_quad *q)
{
    memset(m, 0, sizeof(*m));
    m->positions = q->pos;
    m->vertex_count = 4;
    m->indices = ff_quad_indices;
    m->triangle_count = 2;
    m->material = 0;
}

/* A scene, its patches, its BVH and a raycaster over it. */
typedef struct ff_world {
    rad_scene *scene;
    rad_patches *patches;
    rad_bvh *bvh;
    rad_raycaster rc;
} ff_world;

static inline void ff_world_free(ff_world *w)
{
    rad_bvh_destroy(w->bvh);
    rad_patches_destroy(w->patches);
    rad_scene_destroy(w->scene);
    memset(w, 0, sizeof(*w));
}

/* Builds scene + patches (max_edge and/or target_count) + BVH. Returns 1 on success. */
static inline int ff_world_make(const rad_scene_desc *desc, float max_edge, uint32_t target_count, ff_world *w)
{
    rad_patch_options popt;
    rad_result r;
    memset(w, 0, sizeof(*w));
    r = rad_scene_create(desc, NULL, &w->scene);
    CHECK_OK(r);
    if (r != RAD_SUCCESS) return 0;
    rad_patch_options_default(&popt);
    popt.max_edge = max_edge;
    popt.target_count = target_count;
    r = rad_patches_create(w->scene, &popt, NULL, &w->patches);
    CHECK_OK(r);
    if (r != RAD_SUCCESS) { ff_world_free(w); return 0; }
    r = rad_bvh_create(w->scene, NULL, &w->bvh);
    CHECK_OK(r);
    if (r != RAD_SUCCESS) { ff_world_free(w); return 0; }
    rad_bvh_raycaster(w->bvh, &w->rc);
    return 1;
}

static const rad_material ff_grey = { { 0.5f, 0.5f, 0.5f }, { 0.0f, 0.0f, 0.0f }, 0, 0, 0, 0, 0.0f };

static inline void ff_desc(rad_scene_desc *d, const rad_mesh_desc *meshes, uint32_t count)
{
    memset(d, 0, sizeof(*d));
    d->meshes = meshes;
    d->mesh_count = count;
    d->materials = &ff_grey;
    d->material_count = 1;
}


/* Area-weighted group form factor F_GH = sum_{i in G} A_i sum_{j in H} F_ij / sum_{i in G} A_i,
   groups by the scene mesh of each patch's triangle. */
static inline double ff_group(const rad_patches *P, const float *F, uint32_t g, uint32_t h, double *area_g)
{
    const rad_scene *s = P->scene;
    double num = 0.0, den = 0.0;
    uint32_t i, j, N = P->count;
    for (i = 0; i < N; ++i) {
        double row = 0.0;
        if (s->meshes[P->patches[i].triangle] != g) continue;
        for (j = 0; j < N; ++j)
            if (s->meshes[P->patches[j].triangle] == h) row += (double)F[(size_t)i * N + j];
        num += (double)P->patches[i].area * row;
        den += (double)P->patches[i].area;
    }
    if (area_g) *area_g = den;
    return den > 0.0 ? num / den : 0.0;
}


/* Howell C-11: identical parallel opposed rectangles a x b at gap c */
static inline double ff_c11(double a, double b, double c)
{
    double X = a / c, Y = b / c;
    return 2.0 / (FF_PI * X * Y) *
           (log(sqrt((1 + X * X) * (1 + Y * Y) / (1 + X * X + Y * Y))) + X * sqrt(1 + Y * Y) * atan(X / sqrt(1 + Y * Y)) +
            Y * sqrt(1 + X * X) * atan(Y / sqrt(1 + X * X)) - X * atan(X) - Y * atan(Y));
}

/* Howell C-14: A1 = l x w, A2 = l x h, common edge l; F_12 */
static inline double ff_c14(double l, double w, double h)
{
    double H = h / l, W = w / l, H2 = H * H, W2 = W * W, S = sqrt(H2 + W2);
    double t1 = (1 + W2) * (1 + H2) / (1 + W2 + H2);
    double t2 = pow(W2 * (1 + W2 + H2) / ((1 + W2) * (W2 + H2)), W2);
    double t3 = pow(H2 * (1 + W2 + H2) / ((1 + H2) * (W2 + H2)), H2);
    return 1.0 / (FF_PI * W) * (W * atan(1 / W) + H * atan(1 / H) - S * atan(1 / S) + 0.25 * log(t1 * t2 * t3));
}


/* The six faces of the unit cube [0,1]^3 as quads (four corners each, at pos[12 f]), fronts
   facing inwards: face f lies on axis f / 2 at 0 (f even) or 1 (f odd); two triangles each
   with ff_quad_indices. */
static inline void fx_cube_faces(float *pos)
{
    int f, k;
    for (f = 0; f < 6; ++f) {
        int a = f / 2, s = (f % 2) ? -1 : 1; /* inward normal s * e_a: on the face at coord (s > 0 ? 0 : 1) */
        float cen[3] = { 0.5f, 0.5f, 0.5f }, u[3] = { 0, 0, 0 }, v[3] = { 0, 0, 0 }, *p = pos + 12 * f;
        cen[a] = s > 0 ? 0.0f : 1.0f;
        if (s > 0) { u[(a + 1) % 3] = 1.0f; v[(a + 2) % 3] = 1.0f; }
        else { v[(a + 1) % 3] = 1.0f; u[(a + 2) % 3] = 1.0f; }
        for (k = 0; k < 3; ++k) {
            p[k] = cen[k] - 0.5f * u[k] - 0.5f * v[k];
            p[3 + k] = cen[k] + 0.5f * u[k] - 0.5f * v[k];
            p[6 + k] = cen[k] + 0.5f * u[k] + 0.5f * v[k];
            p[9 + k] = cen[k] - 0.5f * u[k] + 0.5f * v[k];
        }
    }
}

/* The 6 faces of [0,1]^3, fronts facing inwards. Face order: z=0, z=1, x=0, x=1, y=0, y=1
   (so faces 2f and 2f+1 are parallel). */
static inline void ff_cube_quads(ff_quad *q)
{
    ff_quad_set(&q[0], 0, 0, 0, 1, 0, 0, 0, 1, 0); /* +z */
    ff_quad_set(&q[1], 0, 0, 1, 0, 1, 0, 1, 0, 0); /* -z */
    ff_quad_set(&q[2], 0, 0, 0, 0, 1, 0, 0, 0, 1); /* +x */
    ff_quad_set(&q[3], 1, 0, 0, 0, 0, 1, 0, 1, 0); /* -x */
    ff_quad_set(&q[4], 0, 0, 0, 0, 0, 1, 1, 0, 0); /* +y */
    ff_quad_set(&q[5], 0, 1, 0, 1, 0, 0, 0, 0, 1); /* -y */
}

static inline int ff_cube_world(ff_quad *q, rad_mesh_desc *meshes, ff_world *w)
{
    rad_scene_desc d;
    int f;
    ff_cube_quads(q);
    for (f = 0; f < 6; ++f) ff_mesh_quad(&meshes[f], &q[f]);
    ff_desc(&d, meshes, 6);
    /* max_edge 0.25: each face triangle (legs 1) is cut 6 x 6; 432 patches */
    return ff_world_make(&d, rad_test_quick() ? 0.5f : 0.25f, 0, w);
}


/* ---- a peak-tracking allocator and boxes of gridded quads (vp_) ---------------------------- */

/* A peak-tracking allocator: a 16-byte header keeps each block's size. */
typedef struct vp_peak_state {
    long long live, peak;
} vp_peak_state;

static inline void *vp_peak_alloc(void *user, size_t size)
{
    vp_peak_state *s = (vp_peak_state *)user;
    unsigned char *p = (unsigned char *)malloc(size + 16);
    if (!p) return NULL;
    memcpy(p, &size, sizeof(size));
#ifdef _OPENMP
#pragma omp critical(vp_peak_lock)
#endif
    {
        s->live += (long long)size;
        if (s->live > s->peak) s->peak = s->live;
    }
    return p + 16;
}

static inline void vp_peak_free(void *user, void *ptr)
{
    vp_peak_state *s = (vp_peak_state *)user;
    unsigned char *p;
    size_t size;
    if (!ptr) return;
    p = (unsigned char *)ptr - 16;
    memcpy(&size, p, sizeof(size));
#ifdef _OPENMP
#pragma omp critical(vp_peak_lock)
#endif
    {
        s->live -= (long long)size;
    }
    free(p);
}

/* Up to 10 axis-aligned quads, each cut into an n x n grid of triangle pairs. */
#define VP_MAX_QUADS 16
typedef struct vp_scene {
    float pos[VP_MAX_QUADS][3 * 41 * 41];
    uint32_t idx[VP_MAX_QUADS][6 * 40 * 40];
    rad_mesh_desc meshes[VP_MAX_QUADS];
    rad_material materials[2];
    uint32_t count;
} vp_scene;

/* quad o, o+u, o+u+v, o+v, front on the side u x v points to, material m, n x n cells */
static inline void vp_add_quad(vp_scene *s, const float *o, const float *u, const float *v, uint32_t m, uint32_t n)
{
    uint32_t q = s->count++, i, j, k;
    rad_mesh_desc *d = &s->meshes[q];
    for (j = 0; j <= n; ++j)
        for (i = 0; i <= n; ++i)
            for (k = 0; k < 3; ++k)
                s->pos[q][3 * (j * (n + 1) + i) + k] = o[k] + u[k] * (float)i / (float)n + v[k] * (float)j / (float)n;
    for (j = 0; j < n; ++j)
        for (i = 0; i < n; ++i) {
            uint32_t a = j * (n + 1) + i, *t = &s->idx[q][6 * (j * n + i)];
            t[0] = a; t[1] = a + 1; t[2] = a + n + 2;
            t[3] = a; t[4] = a + n + 2; t[5] = a + n + 1;
        }
    memset(d, 0, sizeof(*d));
    d->positions = s->pos[q];
    d->vertex_count = (n + 1) * (n + 1);
    d->indices = s->idx[q];
    d->triangle_count = 2 * n * n;
    d->material = m;
}

/* The inside of the box [0,sx] x [0,sy] x [0,sz], faces pointing in; material 0 everywhere,
   or material 1 on the ceiling (y = sy) when ceiling_light. */
static inline void vp_box(vp_scene *s, float sx, float sy, float sz, uint32_t n, int ceiling_light)
{
    float o0[3] = { 0, 0, 0 }, X[3], Y[3], Z[3], oX[3], oY[3], oZ[3];
    memset(s, 0, sizeof(*s));
    X[0] = sx; X[1] = 0; X[2] = 0;
    Y[0] = 0; Y[1] = sy; Y[2] = 0;
    Z[0] = 0; Z[1] = 0; Z[2] = sz;
    oX[0] = sx; oX[1] = 0; oX[2] = 0;
    oY[0] = 0; oY[1] = sy; oY[2] = 0;
    oZ[0] = 0; oZ[1] = 0; oZ[2] = sz;
    vp_add_quad(s, o0, Z, X, 0, n);                      /* floor y = 0, normal +y */
    vp_add_quad(s, oY, X, Z, ceiling_light ? 1u : 0u, n); /* ceiling y = sy, normal -y */
    vp_add_quad(s, o0, Y, Z, 0, n);                      /* x = 0, normal +x */
    vp_add_quad(s, oX, Z, Y, 0, n);                      /* x = sx, normal -x */
    vp_add_quad(s, o0, X, Y, 0, n);                      /* z = 0, normal +z */
    vp_add_quad(s, oZ, Y, X, 0, n);                      /* z = sz, normal -z */
}

static inline void vp_desc(vp_scene *s, rad_scene_desc *d, float rho, float emission)
{
    int k;
    for (k = 0; k < 3; ++k) {
        s->materials[0].albedo[k] = rho;
        s->materials[0].emission[k] = emission;
        s->materials[1].albedo[k] = rho;
        s->materials[1].emission[k] = 0.0f;
    }
    memset(d, 0, sizeof(*d));
    d->meshes = s->meshes;
    d->mesh_count = s->count;
    d->materials = s->materials;
    d->material_count = 2;
}


/* ---- damaged containers and the logger that reads their refusals (ct_) -------------------- */

/* rewrites the CRC of section i (after the test modified its data) */
static inline void ct_fix_section_crc(unsigned char *buf, uint32_t i)
{
    unsigned char *e = buf + 64 + 64 * (size_t)i;
    rad__put32(e + 32, rad__crc32(buf + rad__get64(e + 16), (size_t)rad__get64(e + 24)));
    rad__put32(buf + 36, rad__crc32(buf + 64, 64 * (size_t)rad__get32(buf + 8)));
    rad__put32(buf + 60, rad__crc32(buf, 60));
}


/* the last message of the library's logger, to check that it names the section, entry and value */
static char ct_log_last[512];
static int ct_log_warnings;
static inline void ct_log(void *user, rad_log_level level, const char *message)
{
    (void)user;
    if (level == RAD_LOG_WARNING) ct_log_warnings++;
    snprintf(ct_log_last, sizeof(ct_log_last), "%s", message);
}

static inline void ct_log_context(rad_context *ctx)
{
    memset(ctx, 0, sizeof(*ctx));
    ctx->log = ct_log;
    ct_log_last[0] = '\0';
    ct_log_warnings = 0;
}

/* a malloc'd copy of the container 'buf' with 'bytes' written at byte 'at' of its section of
   'type' called 'name', every checksum fixed (NULL when there is no such section) */
static inline unsigned char *ct_poke(const void *buf, size_t size, uint32_t type, const char *name, size_t at, const void *bytes,
                              size_t n)
{
    unsigned char *copy = (unsigned char *)malloc(size);
    uint32_t i, count;
    if (!copy) return NULL;
    memcpy(copy, buf, size);
    count = rad__get32(copy + 8);
    for (i = 0; i < count; ++i) {
        unsigned char *e = copy + 64 + 64 * (size_t)i;
        if (rad__get32(e) == type && strncmp((const char *)e + 40, name, 24) == 0 && at + n <= rad__get64(e + 24)) {
            memcpy(copy + rad__get64(e + 16) + at, bytes, n);
            ct_fix_section_crc(copy, i);
            return copy;
        }
    }
    free(copy);
    return NULL;
}


/* ---- small numeric helpers ----------------------------------------------------------------- */

/* max |a| over 3n values */
static inline double so_max_abs(const float *a, uint32_t n)
{
    double m = 0.0;
    size_t i;
    for (i = 0; i < 3 * (size_t)n; ++i) if (fabs((double)a[i]) > m) m = fabs((double)a[i]);
    return m;
}


/* ---- the built-in Cornell box with its patches, BVH and form factors (fx_) ----------------- */

/* A scene with its BVH, patches, dense (and optionally sparse) form factors and E = emission. */
typedef struct fx_world {
    rad_scene *scene;
    rad_bvh *bvh;
    rad_raycaster rc;
    rad_patches *patches;
    rad_form_factors *ff, *ffs;
    float *E;
    uint32_t n; /* patches->count */
} fx_world;

static inline void fx_world_free(fx_world *w)
{
    free(w->E);
    rad_form_factors_destroy(w->ff);
    rad_form_factors_destroy(w->ffs);
    rad_bvh_destroy(w->bvh);
    rad_patches_destroy(w->patches);
    rad_scene_destroy(w->scene);
    memset(w, 0, sizeof(*w));
}

/* The built-in Cornell box cut into about 'target' patches, form factors through the BVH with
   'samples' per pair (0: the default) and a sparse copy when 'sparse'. Returns 0 on failure,
   with w freed; the callers record the failure. */
static inline int fx_cornell(fx_world *w, uint32_t target, uint32_t samples, int sparse)
{
    rad_scene_desc desc;
    rad_patch_options po;
    rad_form_factor_options fo;
    memset(w, 0, sizeof(*w));
    rad_cornell_box(&desc, NULL);
    rad_patch_options_default(&po);
    po.target_count = target;
    rad_form_factor_options_default(&fo);
    if (samples) fo.samples = samples;
    if (rad_scene_create(&desc, NULL, &w->scene) != RAD_SUCCESS || rad_patches_create(w->scene, &po, NULL, &w->patches) != RAD_SUCCESS ||
        rad_bvh_create(w->scene, NULL, &w->bvh) != RAD_SUCCESS) {
        fx_world_free(w);
        return 0;
    }
    rad_bvh_raycaster(w->bvh, &w->rc);
    w->n = w->patches->count;
    w->E = (float *)malloc(sizeof(float) * 3 * w->n);
    if (!w->E || rad_form_factors_dense(w->patches, &w->rc, &fo, NULL, &w->ff) != RAD_SUCCESS ||
        (sparse && rad_form_factors_sparse(w->patches, &w->rc, &fo, NULL, &w->ffs) != RAD_SUCCESS) ||
        rad_sources(w->patches, RAD_SOURCE_EMISSION, NULL, w->E) != RAD_SUCCESS) {
        fx_world_free(w);
        return 0;
    }
    return 1;
}

/* ---- two rooms split by a wall, and their classic solution (lm_, fx_) ------------------------ */

/* A growing quad soup: one mesh per call of lm_quad's caller, positions, indices and
   (optional) lightmap uvs per vertex. */
typedef struct lm_soup {
    float pos[3 * 256];
    float luv[2 * 256];
    uint32_t idx[3 * 128];
    uint32_t nv, nt;
} lm_soup;

/* quad o, o + a, o + a + b, o + b (front: a x b); lightmap uv of corner o and the uv edges */
static inline void lm_quad(lm_soup *s, const float *o, const float *a, const float *b, const float *uv0, const float *ua,
                    const float *ub)
{
    uint32_t v = s->nv;
    int k;
    for (k = 0; k < 3; ++k) {
        s->pos[3 * v + k] = o[k];
        s->pos[3 * (v + 1) + k] = o[k] + a[k];
        s->pos[3 * (v + 2) + k] = o[k] + a[k] + b[k];
        s->pos[3 * (v + 3) + k] = o[k] + b[k];
    }
    for (k = 0; k < 2; ++k) {
        float u0 = uv0 ? uv0[k] : 0.0f, da = ua ? ua[k] : 0.0f, db = ub ? ub[k] : 0.0f;
        s->luv[2 * v + k] = u0;
        s->luv[2 * (v + 1) + k] = u0 + da;
        s->luv[2 * (v + 2) + k] = u0 + da + db;
        s->luv[2 * (v + 3) + k] = u0 + db;
    }
    s->idx[3 * s->nt] = v; s->idx[3 * s->nt + 1] = v + 1; s->idx[3 * s->nt + 2] = v + 2;
    s->idx[3 * s->nt + 3] = v; s->idx[3 * s->nt + 4] = v + 2; s->idx[3 * s->nt + 5] = v + 3;
    s->nv += 4;
    s->nt += 2;
}

static inline void lm_mesh(rad_mesh_desc *m, const lm_soup *s, uint32_t material, int lightmapped)
{
    memset(m, 0, sizeof(*m));
    m->positions = s->pos;
    m->vertex_count = s->nv;
    m->indices = s->idx;
    m->triangle_count = s->nt;
    m->material = material;
    m->lightmap_uvs = lightmapped ? s->luv : NULL;
}

/* Two rooms (x in [0, 0.98] and [1.06, 2], y and z in [0, 1]) split by an 8 cm wall, the lamp
   (10 10 10) under the left room's ceiling; m[0] the rooms (floor uv = (x / 2, z), lightmapped),
   m[1] the wall's two faces, m[2] the lamp; mats[0] grey 0.7, mats[1] the lamp. The leak tests
   of the lightmap and the probes read it. */
static inline void fx_two_rooms(lm_soup *room, lm_soup *wall, lm_soup *lamp, rad_mesh_desc m[3], rad_scene_desc *d,
                                rad_material mats[2])
{
    const float O[3] = { 0, 0, 0 }, Y[3] = { 0, 1, 0 }, Z[3] = { 0, 0, 1 }, R[3] = { 2, 0, 0 }, V[2] = { 0, 1 };
    const float W0[3] = { 0.98f, 0, 0 }, W1[3] = { 1.06f, 0, 0 };
    const float L0[3] = { 0.3f, 0.999f, 0.3f }, LX[3] = { 0.4f, 0, 0 }, LZ[3] = { 0, 0, 0.4f };
    uint32_t i;
    memset(mats, 0, 2 * sizeof(rad_material));
    for (i = 0; i < 3; ++i) {
        mats[0].albedo[i] = 0.7f;
        mats[1].albedo[i] = 0.5f;
        mats[1].emission[i] = 10.0f;
    }
    memset(room, 0, sizeof(*room));
    memset(wall, 0, sizeof(*wall));
    memset(lamp, 0, sizeof(*lamp));
    /* floor, ceiling and the long walls in three pieces split at the wall's faces, so that
       no patch spans both rooms (a patch across the wall would carry light over it: a leak
       of the patch solution, not of the lightmap); floor uv = (x / 2, z) */
    for (i = 0; i < 3; ++i) {
        const float x0 = i == 0 ? 0.0f : i == 1 ? 0.98f : 1.06f, x1 = i == 0 ? 0.98f : i == 1 ? 1.06f : 2.0f;
        const float o0[3] = { x0, 0, 0 }, o1[3] = { x0, 1, 0 }, o2[3] = { x0, 0, 1 }, dx[3] = { x1 - x0, 0, 0 };
        const float uv0[2] = { x0 / 2.0f, 0.0f }, du[2] = { (x1 - x0) / 2.0f, 0.0f };
        lm_quad(room, o0, Z, dx, uv0, V, du);      /* floor, up */
        lm_quad(room, o1, dx, Z, NULL, NULL, NULL); /* ceiling, down */
        lm_quad(room, o0, dx, Y, NULL, NULL, NULL); /* z = 0 */
        lm_quad(room, o2, Y, dx, NULL, NULL, NULL); /* z = 1 */
    }
    lm_quad(room, O, Y, Z, NULL, NULL, NULL);  /* x = 0 */
    lm_quad(room, R, Z, Y, NULL, NULL, NULL);  /* x = 2 */
    lm_quad(wall, W0, Z, Y, NULL, NULL, NULL); /* facing -x (the lit room) */
    lm_quad(wall, W1, Y, Z, NULL, NULL, NULL); /* facing +x (the dark room) */
    lm_quad(lamp, L0, LX, LZ, NULL, NULL, NULL);
    lm_mesh(&m[0], room, 0, 1);
    lm_mesh(&m[1], wall, 0, 0);
    lm_mesh(&m[2], lamp, 1, 0);
    memset(d, 0, sizeof(*d));
    d->meshes = m; d->mesh_count = 3; d->materials = mats; d->material_count = 2;
}

/* The classic solution of a scene the leak tests share: patches (max_edge 0.25, 0.5 quick),
   dense form factors (4 samples, 1 quick), E the emission and B the total after 8 Jacobi
   bounces. 0 when a step failed (its CHECK failed too); the caller frees what is non-NULL. */
static inline int fx_classic_jacobi8(const rad_scene *S, const rad_raycaster *rc, rad_patches **P, rad_form_factors **ff,
                                     float **E, float **B)
{
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_system sys;
    rad_solve_options so;
    rad_patch_options_default(&po);
    po.max_edge = rad_test_quick() ? 0.5f : 0.25f;
    CHECK_OK(rad_patches_create(S, &po, NULL, P));
    rad_form_factor_options_default(&fo);
    fo.samples = rad_test_quick() ? 1 : 4;
    if (*P) CHECK_OK(rad_form_factors_dense(*P, rc, &fo, NULL, ff));
    if (!*P || !*ff) return 0;
    *E = (float *)malloc(sizeof(float) * 3 * (*P)->count);
    *B = (float *)malloc(sizeof(float) * 3 * (*P)->count);
    if (!*E || !*B) {
        CHECK(0);
        return 0;
    }
    CHECK_OK(rad_sources(*P, RAD_SOURCE_EMISSION, NULL, *E));
    rad_system_init(&sys, &(*ff)->matrix, *P, *E);
    rad_solve_options_default(&so);
    so.output = RAD_OUTPUT_TOTAL;
    so.bounces = 8;
    CHECK_OK(rad_solve_jacobi(&sys, &so, *B, NULL, NULL));
    return 1;
}

/* ---- hierarchical radiosity scenes (test_hier_source.c, test_hier_open.c) --------------- */

/* (hierarchical tests) the unit square [x0, x0 + 1] x [0, 1] at height z, cut g x g into
   triangles, facing +z (up) or -z, appended to v (9 floats a triangle); returns the triangles
   added */
static inline uint32_t fx_square_grid(float *v, float x0, float z, int up, uint32_t g)
{
    uint32_t i, j, n = 0, c;
    for (i = 0; i < g; ++i)
        for (j = 0; j < g; ++j) {
            float q[4][3];
            static const int tri[2][3] = { { 0, 1, 2 }, { 0, 2, 3 } };
            q[0][0] = q[3][0] = x0 + (float)i / (float)g;
            q[1][0] = q[2][0] = x0 + (float)(i + 1u) / (float)g;
            q[0][1] = q[1][1] = (float)j / (float)g;
            q[2][1] = q[3][1] = (float)(j + 1u) / (float)g;
            for (c = 0; c < 4; ++c) q[c][2] = z;
            for (c = 0; c < 2; ++c) { /* counter-clockwise seen from +z; swapped for -z */
                int k, o[3] = { tri[c][0], up ? tri[c][1] : tri[c][2], up ? tri[c][2] : tri[c][1] };
                for (k = 0; k < 3; ++k) memcpy(v + 9u * n + 3u * (uint32_t)k, q[o[k]], 3 * sizeof(float));
                ++n;
            }
        }
    return n;
}

/* (hierarchical tests) the area-weighted mean B (channel 0) of the leaves on scene triangles
   [t0, t1), -1 when they have no area; their area into *area when not NULL */
static inline double fx_hier_mean_B_area(const rad_hierarchical *h, uint32_t t0, uint32_t t1, double *area)
{
    rad_hierarchical_stats st;
    float *C, *B;
    uint32_t *T, i, nl;
    double a = 0.0, s = 0.0;
    rad_hierarchical_get_stats(h, &st);
    nl = st.leaves;
    C = (float *)malloc(sizeof(float) * 9u * nl);
    B = (float *)malloc(sizeof(float) * 3u * nl);
    T = (uint32_t *)malloc(sizeof(uint32_t) * nl);
    if (C && B && T && rad_hierarchical_leaves(h, 0, nl, C, T, B, NULL) == RAD_SUCCESS) {
        for (i = 0; i < nl; ++i) {
            double e1[3], e2[3], x, y, z;
            int k;
            if (T[i] < t0 || T[i] >= t1) continue;
            for (k = 0; k < 3; ++k) {
                e1[k] = (double)C[9 * i + 3 + k] - (double)C[9 * i + k];
                e2[k] = (double)C[9 * i + 6 + k] - (double)C[9 * i + k];
            }
            x = e1[1] * e2[2] - e1[2] * e2[1];
            y = e1[2] * e2[0] - e1[0] * e2[2];
            z = e1[0] * e2[1] - e1[1] * e2[0];
            x = 0.5 * sqrt(x * x + y * y + z * z);
            a += x;
            s += x * (double)B[3 * i];
        }
    }
    free(C);
    free(B);
    free(T);
    if (area) *area = a;
    return a > 0.0 ? s / a : -1.0;
}

static inline double fx_hier_mean_B(const rad_hierarchical *h, uint32_t t0, uint32_t t1)
{
    return fx_hier_mean_B_area(h, t0, t1, NULL);
}

/* (hierarchical tests) one mesh of n triangles (9 floats each in v, material ids), its scene,
   BVH and hierarchical solution at the given clustering, tolerance and visibility rays; the
   failures are CHECKs, what was made is in w (NULL beyond the step that failed) */
typedef struct fx_hier_world {
    rad_scene *scene;
    rad_bvh *bvh;
    rad_hierarchical *h;
} fx_hier_world;

static inline void fx_hier_build(const float *v, uint32_t n, const uint32_t *ids, const rad_material *mats,
                                 uint32_t material_count, rad_hierarchical_clustering clustering, double tolerance,
                                 uint32_t visibility_rays, fx_hier_world *w)
{
    rad_mesh_desc m;
    rad_scene_desc d;
    rad_raycaster rc;
    rad_hierarchical_options o;
    memset(w, 0, sizeof(*w));
    memset(&m, 0, sizeof(m));
    m.positions = v;
    m.vertex_count = 3u * n;
    m.triangle_count = n;
    m.material_ids = ids;
    memset(&d, 0, sizeof(d));
    d.meshes = &m;
    d.mesh_count = 1;
    d.materials = mats;
    d.material_count = material_count;
    CHECK_OK(rad_scene_create(&d, NULL, &w->scene));
    if (w->scene) CHECK_OK(rad_bvh_create(w->scene, NULL, &w->bvh));
    if (!w->bvh) return;
    rad_bvh_raycaster(w->bvh, &rc);
    rad_hierarchical_options_default(&o);
    o.clustering = clustering;
    o.tolerance = tolerance;
    o.visibility_rays = visibility_rays;
    CHECK_OK(rad_hierarchical_create(w->scene, &rc, &o, NULL, &w->h));
    if (w->h) CHECK_OK(rad_hierarchical_solve(w->h, NULL));
}

static inline void fx_hier_world_free(fx_hier_world *w)
{
    rad_hierarchical_destroy(w->h);
    rad_bvh_destroy(w->bvh);
    rad_scene_destroy(w->scene);
    memset(w, 0, sizeof(*w));
}

/* quad q of an indexed mesh: its corners c (4 x 3 floats) into pos at 12 q, its two triangles
   into idx at 6 q, wound so that their normal points along 'want' */
static inline void fx_quad_wound(float *pos, uint32_t *idx, uint32_t q, const float *c, const float *want)
{
    float e1[3], e2[3], n[3];
    uint32_t k, b = 4 * q;
    for (k = 0; k < 12; ++k) pos[12 * q + k] = c[k];
    for (k = 0; k < 3; ++k) {
        e1[k] = c[3 + k] - c[k];
        e2[k] = c[6 + k] - c[k];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    if (n[0] * want[0] + n[1] * want[1] + n[2] * want[2] > 0.0f) {
        idx[6 * q] = b; idx[6 * q + 1] = b + 1; idx[6 * q + 2] = b + 2;
        idx[6 * q + 3] = b; idx[6 * q + 4] = b + 2; idx[6 * q + 5] = b + 3;
    } else {
        idx[6 * q] = b; idx[6 * q + 1] = b + 2; idx[6 * q + 2] = b + 1;
        idx[6 * q + 3] = b; idx[6 * q + 4] = b + 3; idx[6 * q + 5] = b + 2;
    }
}

/* (direct-light tests) a 10 x 5 x 10 box open at the top, walls facing in (albedo 0.7), under a
   40 x 40 emitter of radiance 1 at y = 6 facing down (with_emitter; its triangles 10 and 11),
   or without it (for a sky). The floor's centre sees the emitter only through the opening. */
typedef struct fx_open_box {
    float pos[72];
    uint32_t idx[36], mats[12];
    rad_material m[2];
    rad_mesh_desc mesh;
    rad_scene_desc desc;
    rad_scene *S;
    rad_bvh *bvh;
    rad_raycaster rc;
} fx_open_box;

/* 1, or 0 when the scene or its BVH failed (free it all the same) */
static inline int fx_open_box_make(fx_open_box *w, int with_emitter)
{
    static const float quads[6][12] = {
        { 0, 0, 0, 0, 0, 10, 10, 0, 10, 10, 0, 0 },       /* floor */
        { 0, 0, 0, 10, 0, 0, 10, 5, 0, 0, 5, 0 },         /* walls */
        { 0, 0, 10, 10, 0, 10, 10, 5, 10, 0, 5, 10 },
        { 0, 0, 0, 0, 0, 10, 0, 5, 10, 0, 5, 0 },
        { 10, 0, 0, 10, 0, 10, 10, 5, 10, 10, 5, 0 },
        { -15, 6, -15, 25, 6, -15, 25, 6, 25, -15, 6, 25 } /* the emitter */
    };
    static const float wants[6][3] = { { 0, 1, 0 }, { 0, 0, 1 }, { 0, 0, -1 }, { 1, 0, 0 }, { -1, 0, 0 }, { 0, -1, 0 } };
    uint32_t q;
    memset(w, 0, sizeof(*w));
    for (q = 0; q < 6; ++q) fx_quad_wound(w->pos, w->idx, q, quads[q], wants[q]);
    for (q = 0; q < 12; ++q) w->mats[q] = q >= 10 ? 1u : 0u;
    w->m[0].albedo[0] = w->m[0].albedo[1] = w->m[0].albedo[2] = 0.7f;
    w->m[1].emission[0] = w->m[1].emission[1] = w->m[1].emission[2] = 1.0f;
    w->mesh.positions = w->pos;
    w->mesh.vertex_count = 24;
    w->mesh.indices = w->idx;
    w->mesh.triangle_count = with_emitter ? 12u : 10u;
    w->mesh.material_ids = w->mats;
    w->desc.meshes = &w->mesh;
    w->desc.mesh_count = 1;
    w->desc.materials = w->m;
    w->desc.material_count = 2;
    if (rad_scene_create(&w->desc, NULL, &w->S) != RAD_SUCCESS) return 0;
    if (rad_bvh_create(w->S, NULL, &w->bvh) != RAD_SUCCESS) return 0;
    rad_bvh_raycaster(w->bvh, &w->rc);
    return 1;
}

static inline void fx_open_box_free(fx_open_box *w)
{
    rad_bvh_destroy(w->bvh);
    rad_scene_destroy(w->S);
    w->bvh = NULL;
    w->S = NULL;
}

/* (baker tests) the last error a context logged, and how many */
typedef struct fx_err_log {
    int errors;
    char last[512];
} fx_err_log;

static inline void fx_err_log_fn(void *user, rad_log_level level, const char *msg)
{
    fx_err_log *l = (fx_err_log *)user;
    if (level == RAD_LOG_ERROR) {
        l->errors++;
        strncpy(l->last, msg, sizeof(l->last) - 1);
        l->last[sizeof(l->last) - 1] = 0;
    }
}

/* (baker tests) one bad bake: the expected code, no result, a logged error holding 'word'
   (NULL: any), nothing leaked */
static inline void fx_baker_expect(const rad_baker_desc *d, const rad_baker_options *o, rad_result want, const char *word)
{
    rad_context ctx;
    sc_alloc_state st;
    fx_err_log lg;
    rad_baker_result *R = NULL;
    memset(&st, 0, sizeof st);
    memset(&lg, 0, sizeof lg);
    sc_ctx_alloc(&ctx, &st);
    ctx.log = fx_err_log_fn;
    ctx.log_user = &lg;
    CHECK_RESULT(rad_baker_run(d, o, &ctx, &R), want);
    CHECK(R == NULL);
    CHECK(lg.errors > 0);
    if (word && !strstr(lg.last, word)) {
        printf("    log '%s' lacks '%s'\n", lg.last, word);
        CHECK(!"the log names the problem");
    }
    CHECK(st.live_bytes == 0);
}

#endif

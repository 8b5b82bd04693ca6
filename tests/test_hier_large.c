/* test_hier_large.c - hierarchical radiosity (>>api_hierarchical) on the geometry of real
   furnished rooms: coincident duplicate layers, back-to-back zero-thickness sheets, slivers
   and nearly degenerate triangles. Closed furnaces filled with such junk against their closed
   form B = E / (1 - rho), a duplicated floor against the same scene with one copy, the
   solver's own bound on B, and progress and cancel through refinement and sweeps. Its names
   are prefixed hl_. */
#include "fixtures.h"

/* a triangle soup (vertices in threes) */
typedef struct hl_soup {
    float *v;
    uint32_t n, cap;
} hl_soup;

static void hl_tri(hl_soup *s, const float *a, const float *b, const float *c)
{
    if (s->n == s->cap) {
        s->cap = s->cap ? 2u * s->cap : 256u;
        s->v = (float *)realloc(s->v, 9u * sizeof(float) * s->cap);
    }
    memcpy(s->v + 9u * s->n, a, 3 * sizeof(float));
    memcpy(s->v + 9u * s->n + 3, b, 3 * sizeof(float));
    memcpy(s->v + 9u * s->n + 6, c, 3 * sizeof(float));
    s->n++;
}

/* the quad o + [0,1] u + [0,1] v cut g x g, its front toward u x v */
static void hl_quad(hl_soup *s, const float *o, const float *u, const float *v, uint32_t g)
{
    uint32_t i, j, k;
    for (i = 0; i < g; ++i)
        for (j = 0; j < g; ++j) {
            float p[4][3];
            for (k = 0; k < 3; ++k) {
                float a = (float)i / (float)g, b = (float)(i + 1u) / (float)g, c = (float)j / (float)g, d = (float)(j + 1u) / (float)g;
                p[0][k] = o[k] + a * u[k] + c * v[k];
                p[1][k] = o[k] + b * u[k] + c * v[k];
                p[2][k] = o[k] + b * u[k] + d * v[k];
                p[3][k] = o[k] + a * u[k] + d * v[k];
            }
            hl_tri(s, p[0], p[1], p[2]);
            hl_tri(s, p[0], p[2], p[3]);
        }
}

typedef struct hl_world {
    rad_scene *scene;
    rad_bvh *bvh;
    rad_raycaster rc;
} hl_world;

static int hl_world_make(const hl_soup *s, const rad_material *mats, const uint32_t *mat_ids, uint32_t nmat, hl_world *w)
{
    rad_mesh_desc m;
    rad_scene_desc d;
    memset(w, 0, sizeof(*w));
    memset(&m, 0, sizeof(m));
    m.positions = s->v;
    m.vertex_count = 3u * s->n;
    m.triangle_count = s->n;
    m.material_ids = mat_ids;
    memset(&d, 0, sizeof(d));
    d.meshes = &m;
    d.mesh_count = 1;
    d.materials = mats;
    d.material_count = nmat;
    d.flags = RAD_SCENE_SKIP_DEGENERATE;
    CHECK_OK(rad_scene_create(&d, NULL, &w->scene));
    if (!w->scene) return 0;
    CHECK_OK(rad_bvh_create(w->scene, NULL, &w->bvh));
    if (!w->bvh) { rad_scene_destroy(w->scene); return 0; }
    rad_bvh_raycaster(w->bvh, &w->rc);
    return 1;
}

static void hl_world_free(hl_world *w)
{
    rad_bvh_destroy(w->bvh);
    rad_scene_destroy(w->scene);
}

/* the area-weighted mean of channel 0 of B over the leaves on scene triangles [first, last),
   and the largest B of any leaf (-1 if a leaf is not finite) */
static double hl_mean_B(const rad_hierarchical *h, uint32_t first, uint32_t last, double *bmax)
{
    rad_hierarchical_stats st;
    float *C, *B;
    uint32_t *T, i;
    double a = 0.0, s = 0.0;
    rad_hierarchical_get_stats(h, &st);
    C = (float *)malloc(9u * sizeof(float) * st.leaves);
    B = (float *)malloc(3u * sizeof(float) * st.leaves);
    T = (uint32_t *)malloc(sizeof(uint32_t) * st.leaves);
    *bmax = 0.0;
    CHECK_OK(rad_hierarchical_leaves(h, 0, st.leaves, C, T, B, NULL));
    for (i = 0; i < st.leaves; ++i) {
        float e1[3], e2[3], n[3];
        double A;
        int k;
        for (k = 0; k < 3; ++k) {
            if (!(B[3 * i + k] == B[3 * i + k]) || fabs((double)B[3 * i + k]) > 1e30) *bmax = -1.0;
            else if (*bmax >= 0.0 && B[3 * i + k] > *bmax) *bmax = B[3 * i + k];
        }
        if (T[i] < first || T[i] >= last) continue;
        for (k = 0; k < 3; ++k) {
            e1[k] = C[9 * i + 3 + k] - C[9 * i + k];
            e2[k] = C[9 * i + 6 + k] - C[9 * i + k];
        }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        A = 0.5 * sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
        a += A;
        s += A * (double)B[3 * i];
    }
    free(C);
    free(B);
    free(T);
    return a > 0.0 ? s / a : 0.0;
}

/* 1. A floor (albedo 0.85) stored three times over, coincident, 0.1 under an emitting ceiling
   of the same albedo. The visibility rays stop short of their target (the ray epsilon), so
   every copy passes: the ceiling's form factors to the floor sum to about 3 x 0.82, and with
   rho 0.85 the sweeps grew B to infinity ("value 0 is inf: lights or emission too strong"
   from a scene emitting 1). Now: solved, every B finite and within the solver's bound
   E / (1 - 0.999) (no leaf gathers more than 0.999 of the largest B), and the floor and
   ceiling within the cap's reach of the scene holding one copy. */
static double hl_layers(uint32_t copies, rad_hierarchical_clustering cl, double *floor_B, double *bmax)
{
    static const rad_material mats[2] = { { { 0.85f, 0.85f, 0.85f }, { 0.0f, 0.0f, 0.0f }, 0, 0, 0, 0, 0.0f },
                                          { { 0.85f, 0.85f, 0.85f }, { 1.0f, 1.0f, 1.0f }, 0, 0, 0, 0, 0.0f } };
    static const float o0[3] = { 0, 0, 0 }, o1[3] = { 0, 0.1f, 0 }, ux[3] = { 1, 0, 0 }, uz[3] = { 0, 0, 1 };
    hl_soup s;
    hl_world w;
    uint32_t *ids, i, c;
    rad_hierarchical_options o;
    rad_hierarchical *h = NULL;
    double ceil_B = -1.0, b2;
    memset(&s, 0, sizeof(s));
    for (c = 0; c < copies; ++c) hl_quad(&s, o0, uz, ux, 2); /* front +y */
    hl_quad(&s, o1, ux, uz, 2);                               /* front -y */
    ids = (uint32_t *)calloc(s.n, sizeof(uint32_t));
    for (i = 8u * copies; i < s.n; ++i) ids[i] = 1;
    *floor_B = *bmax = -1.0;
    if (hl_world_make(&s, mats, ids, 2, &w)) {
        rad_hierarchical_options_default(&o);
        o.clustering = cl;
        CHECK_OK(rad_hierarchical_create(w.scene, &w.rc, &o, NULL, &h));
        if (h) {
            CHECK_OK(rad_hierarchical_solve(h, NULL));
            *floor_B = hl_mean_B(h, 0, 8u * copies, bmax);
            ceil_B = hl_mean_B(h, 8u * copies, s.n, &b2);
        }
        rad_hierarchical_destroy(h);
        hl_world_free(&w);
    }
    free(ids);
    free(s.v);
    return ceil_B;
}

static void hl_test_coincident_layers(void)
{
    double f1, c1, f3, c3, m1, m3, bound = 3.14159265 / (1.0 - 0.999);
    int cl;
    for (cl = 1; cl <= 2; ++cl) {
        c1 = hl_layers(1, (rad_hierarchical_clustering)cl, &f1, &m1);
        c3 = hl_layers(3, (rad_hierarchical_clustering)cl, &f3, &m3);
        printf("    clustering %s: one floor: floor B %.4g, ceiling B %.4g; three coincident floors: %.4g, %.4g "
               "(largest B %.4g, bound %.4g)\n", cl == 1 ? "off" : "on", f1, c1, f3, c3, m3, bound);
        CHECK(m1 > 0.0 && m3 > 0.0 && m3 <= bound);
        CHECK(f1 > 0.0 && c1 > 0.0);
        /* the ceiling gathers over a sum of 0.999 / 0.85 = 1.18 at most where one copy gives
           0.82, and the floor gathers the ceiling: B = E / (1 - rho^2 S F), about 1.7 x */
        CHECK(c3 >= 0.95 * c1 && c3 <= 1.8 * c1);
        CHECK(f3 >= 0.95 * f1 && f3 <= 1.8 * f1);
    }
}

/* 2. The closed unit cube (faces cut 4 x 4), everything of albedo rho emitting E, filled with
   what furnished rooms hold: boxes of very different sizes, slivers (aspect 1e4), nearly
   degenerate triangles, back-to-back sheets of zero thickness (coincident layers are test
   1's). Whatever hides what, every point of a closed furnace has B = E / (1 - rho): the
   area-weighted means over the walls and over the junk hold it, with clustering, within 5%
   and 10% at four rays per link and tolerance 1e-3, within 20% at one ray and 1e-2 (the
   coarse estimates' error), and no leaf strays far above it. */
static void hl_junk(hl_soup *s, uint32_t seed)
{
    uint32_t i, k, r = seed;
    float o[3], u[3], v[3];
#define HL_RND() ((r = r * 1664525u + 1013904223u), (float)(r >> 8) / 16777216.0f)
    for (i = 0; i < 6; ++i) { /* boxes, 0.01 to 0.2 on a side */
        float b = 0.01f + 0.19f * HL_RND(), x = 0.1f + 0.6f * HL_RND(), y = 0.1f + 0.6f * HL_RND(), z = 0.1f + 0.6f * HL_RND();
        float p[8][3];
        static const int f[6][4] = { { 0, 2, 3, 1 }, { 4, 5, 7, 6 }, { 0, 1, 5, 4 }, { 2, 6, 7, 3 }, { 0, 4, 6, 2 }, { 1, 3, 7, 5 } };
        int c;
        for (c = 0; c < 8; ++c) {
            p[c][0] = x + ((c & 1) ? b : 0.0f);
            p[c][1] = y + ((c & 2) ? b : 0.0f);
            p[c][2] = z + ((c & 4) ? b : 0.0f);
        }
        for (c = 0; c < 6; ++c) {
            hl_tri(s, p[f[c][0]], p[f[c][1]], p[f[c][2]]);
            hl_tri(s, p[f[c][0]], p[f[c][2]], p[f[c][3]]);
        }
    }
    for (i = 0; i < 60; ++i) { /* slivers and nearly degenerate triangles, both sides */
        float a[3], b[3], c[3], L = powf(10.0f, -3.0f + 2.5f * HL_RND()), e = i % 2 ? 1e-4f * L : 1e-6f;
        for (k = 0; k < 3; ++k) {
            a[k] = 0.2f + 0.6f * HL_RND();
            b[k] = a[k] + L * (2.0f * HL_RND() - 1.0f);
            c[k] = 0.5f * (a[k] + b[k]) + e * (k == 1 ? 1.0f : 0.3f);
        }
        hl_tri(s, a, b, c);
        hl_tri(s, a, c, b);
    }
    /* back-to-back sheets of zero thickness */
    o[0] = 0.3f; o[1] = 0.2f; o[2] = 0.5f; u[0] = 0.4f; u[1] = 0; u[2] = 0; v[0] = 0; v[1] = 0.5f; v[2] = 0;
    hl_quad(s, o, u, v, 3);
    hl_quad(s, o, v, u, 3);
#undef HL_RND
}

/* the junk furnace's world; returns the walls' triangle count (0 on failure) */
static uint32_t hl_junk_world(hl_world *w)
{
    static const rad_material mat = { { 0.8f, 0.8f, 0.8f }, { 1.0f, 1.0f, 1.0f }, 0, 0, 0, 0, 0.0f };
    ff_quad q[6];
    hl_soup s;
    uint32_t f, walls;
    int ok;
    memset(&s, 0, sizeof(s));
    ff_cube_quads(q);
    for (f = 0; f < 6; ++f) { /* ff_quad: o, o + u, o + u + v, o + v */
        float o[3], u[3], v[3];
        int k;
        for (k = 0; k < 3; ++k) {
            o[k] = q[f].pos[k];
            u[k] = q[f].pos[3 + k] - o[k];
            v[k] = q[f].pos[9 + k] - o[k];
        }
        hl_quad(&s, o, u, v, 4);
    }
    walls = s.n;
    hl_junk(&s, 7u);
    ok = hl_world_make(&s, &mat, NULL, 1, w);
    free(s.v);
    return ok ? walls : 0u;
}

static void hl_test_junk_furnace(void)
{
    static const uint32_t rays[2] = { 1, 4 };
    static const double tol[2] = { 1e-2, 1e-3 };
    hl_world w;
    uint32_t walls = hl_junk_world(&w), t;
    double exact = 3.14159265 / (1.0 - 0.8);
    if (!walls) return;
    for (t = 0; t < 2; ++t) {
        rad_hierarchical_options o;
        rad_hierarchical *h = NULL;
        rad_hierarchical_stats st;
        double mw, mj, bmax, b2;
        rad_hierarchical_options_default(&o);
        o.clustering = RAD_HIERARCHICAL_CLUSTER_ON;
        o.visibility_rays = rays[t];
        o.tolerance = tol[t];
        CHECK_OK(rad_hierarchical_create(w.scene, &w.rc, &o, NULL, &h));
        if (!h) continue;
        CHECK_OK(rad_hierarchical_solve(h, NULL));
        rad_hierarchical_get_stats(h, &st);
        mw = hl_mean_B(h, 0, walls, &bmax);
        mj = hl_mean_B(h, walls, w.scene->triangle_count, &b2);
        printf("    %u triangles, %u ray(s), tolerance %g: %u leaves, %llu links; walls %.4f, junk %.4f of E / (1 - rho); "
               "largest B %.4f of it\n", w.scene->triangle_count, rays[t], tol[t], st.leaves, (unsigned long long)st.links,
               mw / exact, mj / exact, bmax / exact);
        CHECK(bmax > 0.0 && bmax < 1.5 * exact);
        CHECK(fabs(mw / exact - 1.0) < (t ? 0.05 : 0.2));
        CHECK(fabs(mj / exact - 1.0) < (t ? 0.10 : 0.2));
        rad_hierarchical_destroy(h);
    }
    hl_world_free(&w);
}

/* 3. Progress, cancel and memory_limit on the junk furnace. Progress comes after each
   refinement level and sweep, more often than rounds, never falls, and ends at 1; a cancel at
   the first report (inside the first refinement) and at the tenth (in the sweeps) gives
   CANCELLED; a memory_limit of half the unlimited solve's peak refuses refinements, holds the
   peak near it (splits of overlapping ends are not refused), and the furnace still holds
   within 10% on the walls. */
typedef struct hl_prog {
    int calls, stop_at, fell;
    float last;
} hl_prog;

static int hl_prog_fn(void *user, float f)
{
    hl_prog *p = (hl_prog *)user;
    if (f < p->last) p->fell = 1;
    p->last = f;
    return ++p->calls == p->stop_at;
}

static void hl_test_progress_memory(void)
{
    hl_world w;
    uint32_t walls = hl_junk_world(&w);
    rad_hierarchical_options o;
    rad_hierarchical *h = NULL;
    rad_hierarchical_stats st, lim;
    rad_context ctx;
    hl_prog p;
    double exact = 3.14159265 / (1.0 - 0.8), mw, bmax;
    int stop;
    if (!walls) return;
    rad_hierarchical_options_default(&o);
    o.clustering = RAD_HIERARCHICAL_CLUSTER_ON;
    o.tolerance = 1e-3;
    memset(&ctx, 0, sizeof(ctx));
    ctx.progress = hl_prog_fn;
    ctx.progress_user = &p;
    memset(&p, 0, sizeof(p));
    CHECK_OK(rad_hierarchical_create(w.scene, &w.rc, &o, NULL, &h));
    if (h) CHECK_OK(rad_hierarchical_solve(h, &ctx));
    rad_hierarchical_get_stats(h, &st);
    rad_hierarchical_destroy(h);
    printf("    %d progress reports over %u rounds and %u sweeps, last %.3f; peak %.2f MiB\n", p.calls, st.rounds, st.sweeps,
           (double)p.last, (double)st.peak_bytes / 1048576.0);
    CHECK(p.calls > (int)st.rounds + 2 && !p.fell && p.last == 1.0f);
    CHECK(st.memory_limited == 0 && st.peak_bytes > 0);
    for (stop = 1; stop <= 10; stop += 9) {
        memset(&p, 0, sizeof(p));
        p.stop_at = stop;
        h = NULL;
        CHECK_OK(rad_hierarchical_create(w.scene, &w.rc, &o, NULL, &h));
        if (h) CHECK_RESULT(rad_hierarchical_solve(h, &ctx), RAD_ERROR_CANCELLED);
        CHECK(p.calls == stop);
        rad_hierarchical_destroy(h);
    }
    o.memory_limit = st.peak_bytes / 2u;
    h = NULL;
    CHECK_OK(rad_hierarchical_create(w.scene, &w.rc, &o, NULL, &h));
    if (h) {
        CHECK_OK(rad_hierarchical_solve(h, NULL));
        rad_hierarchical_get_stats(h, &lim);
        mw = hl_mean_B(h, 0, walls, &bmax);
        printf("    memory_limit %.2f MiB: peak %.2f MiB, %llu refinements refused, %u leaves (%u unlimited); walls %.4f of "
               "E / (1 - rho)\n", (double)o.memory_limit / 1048576.0, (double)lim.peak_bytes / 1048576.0,
               (unsigned long long)lim.memory_limited, lim.leaves, st.leaves, mw / exact);
        /* the splits of links whose ends overlap (no F yet) are made all the same */
        CHECK(lim.memory_limited > 0 && lim.peak_bytes <= o.memory_limit + o.memory_limit / 4u);
        CHECK(bmax > 0.0 && fabs(mw / exact - 1.0) < 0.1);
        rad_hierarchical_destroy(h);
    }
    hl_world_free(&w);
}

static const rad_test_case tests_hier_large[] = {
    { "hier_large_coincident_layers", hl_test_coincident_layers },
    { "hier_large_junk_furnace", hl_test_junk_furnace },
    { "hier_large_progress_memory", hl_test_progress_memory },
    { NULL, NULL }
};
RAD_TEST_MAIN(tests_hier_large)

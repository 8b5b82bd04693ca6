/* test_hier_scale.c - hierarchical radiosity (>>api_hierarchical) at scale: the clusters'
   gather by normal cones and the clamped cosine's quadratic fit, and progress that gives the
   first round (most of a large scene's work) half the bar. Its names are prefixed hs_. */
#include "fixtures.h"

/* a triangle soup (vertices in threes) */
typedef struct hs_soup {
    float *v;
    uint32_t n, cap;
} hs_soup;

/* the quad o + [0,1] u + [0,1] v cut g x g, its front toward u x v */
static void hs_quad(hs_soup *s, const float *o, const float *u, const float *v, uint32_t g)
{
    uint32_t i, j, k, c;
    for (i = 0; i < g; ++i)
        for (j = 0; j < g; ++j) {
            float p[4][3];
            static const int tri[6] = { 0, 1, 2, 0, 2, 3 };
            for (k = 0; k < 3; ++k) {
                float a = (float)i / (float)g, b = (float)(i + 1u) / (float)g, cc = (float)j / (float)g, d = (float)(j + 1u) / (float)g;
                p[0][k] = o[k] + a * u[k] + cc * v[k];
                p[1][k] = o[k] + b * u[k] + cc * v[k];
                p[2][k] = o[k] + b * u[k] + d * v[k];
                p[3][k] = o[k] + a * u[k] + d * v[k];
            }
            if (s->n + 2u > s->cap) {
                s->cap = s->cap ? 2u * s->cap : 256u;
                s->v = (float *)realloc(s->v, 9u * sizeof(float) * s->cap);
            }
            for (c = 0; c < 6; ++c) memcpy(s->v + 9u * s->n + 3u * (c % 3u) + (c / 3u) * 9u, p[tri[c]], 3 * sizeof(float));
            s->n += 2u;
        }
}

typedef struct hs_world {
    rad_scene *scene;
    rad_bvh *bvh;
    rad_raycaster rc;
} hs_world;

/* The box of test 1 (6 faces cut 4 x 4, albedo 0.5, the +x face's 32 triangles first, the -x
   face's next) and an emitting wall of radiance 1 at x = 4 facing it. */
static int hs_box_world(hs_world *w)
{
    static const float o[6][3] = { { 1, 0, 0 }, { 0, 0, 0 }, { 0, 1, 0 }, { 0, 0, 0 }, { 0, 0, 1 }, { 0, 0, 0 } };
    static const float u[6][3] = { { 0, 1, 0 }, { 0, 0, 1 }, { 0, 0, 1 }, { 1, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 } };
    static const float v[6][3] = { { 0, 0, 1 }, { 0, 1, 0 }, { 1, 0, 0 }, { 0, 0, 1 }, { 0, 1, 0 }, { 1, 0, 0 } };
    static const float wo[3] = { 4, -2, -2 }, wu[3] = { 0, 0, 5 }, wv[3] = { 0, 5, 0 };
    rad_material mats[2];
    rad_mesh_desc m;
    rad_scene_desc d;
    hs_soup s;
    uint32_t *ids, i, f, box;
    int ok = 0;
    memset(w, 0, sizeof(*w));
    memset(&s, 0, sizeof(s));
    memset(mats, 0, sizeof(mats));
    for (i = 0; i < 3; ++i) {
        mats[0].albedo[i] = 0.5f;
        mats[1].emission[i] = 1.0f;
    }
    for (f = 0; f < 6; ++f) hs_quad(&s, o[f], u[f], v[f], 4);
    box = s.n;
    hs_quad(&s, wo, wu, wv, 2);
    ids = (uint32_t *)calloc(s.n, sizeof(uint32_t));
    if (ids) {
        for (i = box; i < s.n; ++i) ids[i] = 1;
        memset(&m, 0, sizeof(m));
        m.positions = s.v;
        m.vertex_count = 3u * s.n;
        m.triangle_count = s.n;
        m.material_ids = ids;
        memset(&d, 0, sizeof(d));
        d.meshes = &m;
        d.mesh_count = 1;
        d.materials = mats;
        d.material_count = 2;
        CHECK_OK(rad_scene_create(&d, NULL, &w->scene));
        if (w->scene) CHECK_OK(rad_bvh_create(w->scene, NULL, &w->bvh));
        if (w->bvh) {
            rad_bvh_raycaster(w->bvh, &w->rc);
            ok = w->scene->triangle_count == s.n;
        }
    }
    free(ids);
    free(s.v);
    return ok;
}

static void hs_world_free(hs_world *w)
{
    rad_bvh_destroy(w->bvh);
    rad_scene_destroy(w->scene);
}

/* the area-weighted mean B (channel 0) of the leaves on scene triangles [first, last) */
static double hs_mean_B(const rad_hierarchical *h, uint32_t first, uint32_t last)
{
    rad_hierarchical_stats st;
    float *C, *B;
    uint32_t *T, i;
    double a = 0.0, s = 0.0;
    rad_hierarchical_get_stats(h, &st);
    C = (float *)malloc(9u * sizeof(float) * st.leaves);
    B = (float *)malloc(3u * sizeof(float) * st.leaves);
    T = (uint32_t *)malloc(sizeof(uint32_t) * st.leaves);
    if (C && B && T && rad_hierarchical_leaves(h, 0, st.leaves, C, T, B, NULL) == RAD_SUCCESS)
        for (i = 0; i < st.leaves; ++i) {
            float e1[3], e2[3], n[3];
            double A;
            int k;
            if (T[i] < first || T[i] >= last) continue;
            for (k = 0; k < 3; ++k) {
                e1[k] = C[9 * i + 3 + k] - C[9 * i + k];
                e2[k] = C[9 * i + 6 + k] - C[9 * i + k];
            }
            n[0] = e1[1] * e2[2] - e1[2] * e2[1];
            n[1] = e1[2] * e2[0] - e1[0] * e2[2];
            n[2] = e1[0] * e2[1] - e1[1] * e2[0];
            A = 0.5 * sqrt((double)(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]));
            a += A;
            s += A * (double)B[3 * i];
        }
    free(C);
    free(B);
    free(T);
    return a > 0.0 ? s / a : 0.0;
}

/* 1. A box of 6 faces cut 4 x 4 lit by an emitting wall on its +x side, 3 units away:
   clustering on (the box's triangles gather through the clusters above them, some links
   reaching members that face the wall and members that do not) against off (every link to
   a triangle, its own cosine exact). The lit face's mean B agrees within 10%, and the face
   turned away stays dark with clustering (the fit leaks at most 1/16 of a source to a member
   facing straight away from it). */
static void hs_test_cluster_gather(void)
{
    hs_world w;
    uint32_t per = 32u;
    double lit[2], dark[2];
    int c;
    if (!hs_box_world(&w)) {
        CHECK(0);
        hs_world_free(&w);
        return;
    }
    for (c = 0; c < 2; ++c) {
        rad_hierarchical_options ho;
        rad_hierarchical *h = NULL;
        rad_hierarchical_options_default(&ho);
        ho.clustering = c ? RAD_HIERARCHICAL_CLUSTER_ON : RAD_HIERARCHICAL_CLUSTER_OFF;
        ho.tolerance = 1e-2;
        CHECK_OK(rad_hierarchical_create(w.scene, &w.rc, &ho, NULL, &h));
        if (h) CHECK_OK(rad_hierarchical_solve(h, NULL));
        lit[c] = h ? hs_mean_B(h, 0, per) : 0.0;
        dark[c] = h ? hs_mean_B(h, per, 2u * per) : 0.0;
        rad_hierarchical_destroy(h);
    }
    printf("    box face toward the wall: B %.4f off, %.4f on; face away: %.4f off, %.4f on\n", lit[0], lit[1], dark[0], dark[1]);
    CHECK(lit[0] > 0.0 && fabs(lit[1] / lit[0] - 1.0) < 0.1);
    CHECK(dark[0] < 1e-6 && dark[1] < 0.07 * lit[1]);
    hs_world_free(&w);
}

/* progress: the largest report below 1, whether any fell, the last */
typedef struct hs_prog {
    float mid, last;
    int calls, fell;
} hs_prog;

static int hs_prog_fn(void *user, float f)
{
    hs_prog *p = (hs_prog *)user;
    if (f < p->last) p->fell = 1;
    if (f < 1.0f && f > p->mid) p->mid = f;
    p->last = f;
    p->calls++;
    return 0;
}

/* 2. Progress over rounds: the first round spans [0, 1/2), so a solve of a few rounds reports
   values in the middle of the bar before its end (a share of 1 / max_iterations per round
   kept a few rounds under 0.2 until the jump to 1), rising and ending at 1. */
static void hs_test_progress_rounds(void)
{
    hs_world w;
    hs_prog p;
    rad_hierarchical_options o;
    rad_hierarchical_stats st;
    rad_hierarchical *h = NULL;
    rad_context ctx;
    if (!hs_box_world(&w)) {
        CHECK(0);
        hs_world_free(&w);
        return;
    }
    rad_hierarchical_options_default(&o);
    o.clustering = RAD_HIERARCHICAL_CLUSTER_ON;
    o.tolerance = 1e-3;
    memset(&ctx, 0, sizeof(ctx));
    memset(&p, 0, sizeof(p));
    ctx.progress = hs_prog_fn;
    ctx.progress_user = &p;
    CHECK_OK(rad_hierarchical_create(w.scene, &w.rc, &o, NULL, &h));
    if (h) CHECK_OK(rad_hierarchical_solve(h, &ctx));
    rad_hierarchical_get_stats(h, &st);
    rad_hierarchical_destroy(h);
    printf("    %u rounds, %d reports, largest before the end %.3f\n", st.rounds, p.calls, (double)p.mid);
    CHECK(st.rounds < o.max_iterations && !p.fell && p.last == 1.0f);
    CHECK(p.mid >= 0.4f && p.mid < 1.0f);
    hs_world_free(&w);
}

static const rad_test_case tests_hier_scale[] = {
    { "hier_scale_cluster_gather", hs_test_cluster_gather },
    { "hier_scale_progress_rounds", hs_test_progress_rounds },
    { NULL, NULL }
};
RAD_TEST_MAIN(tests_hier_scale)

/* test_plan_small.c - the baker's plan on small scenes of touching objects (PLAN and ESTIMATE
   in >>api_bake): a row of emitting spheres, each touching the next. The direct light of
   emitting triangles is counted in the time estimate (the cost grows with the emitters each
   sample sees), the estimate grows with the resolution, a time budget then holds the
   resolution down, and a scene ten times larger gets the same plan. Included by test_main.c
   after the implementation: every name is static and prefixed ps_. */
#include "fixtures.h"

#define PS_RINGS 10u
#define PS_SEGMENTS 20u
#define PS_MAX_SPHERES 8u
#define PS_VERTS ((PS_RINGS + 1u) * (PS_SEGMENTS + 1u))
#define PS_TRIS (2u * (PS_RINGS - 1u) * PS_SEGMENTS)

typedef struct ps_world {
    float *pos;
    uint32_t *idx;
    rad_mesh_desc meshes[PS_MAX_SPHERES];
    rad_material mats[2];
    rad_scene *scene;
    rad_bvh *bvh;
    rad_raycaster rc;
} ps_world;

/* 'count' spheres of radius 'r' in a row along x, each touching the next; the odd ones emit
   when 'emit' (material 1), the others only reflect (albedo 0.9) */
static int ps_row(ps_world *w, uint32_t count, float r, int emit)
{
    rad_scene_desc d;
    uint32_t s, i, j, t;
    memset(w, 0, sizeof(*w));
    if (count > PS_MAX_SPHERES) return 0;
    w->pos = (float *)malloc(sizeof(float) * 3u * PS_VERTS * count);
    w->idx = (uint32_t *)malloc(sizeof(uint32_t) * 3u * PS_TRIS);
    if (!w->pos || !w->idx) return 0;
    for (i = 0, t = 0; i < PS_RINGS; ++i)
        for (j = 0; j < PS_SEGMENTS; ++j) {
            uint32_t a = i * (PS_SEGMENTS + 1u) + j, b = a + PS_SEGMENTS + 1u;
            /* counter-clockwise seen from outside (the normals point out); the poles' rings
               take one triangle a cell, the other would have no area */
            if (i > 0) w->idx[t++] = a, w->idx[t++] = a + 1u, w->idx[t++] = b;
            if (i + 1u < PS_RINGS) w->idx[t++] = a + 1u, w->idx[t++] = b + 1u, w->idx[t++] = b;
        }
    for (s = 0; s < count; ++s) {
        float *p = w->pos + 3u * PS_VERTS * s;
        for (i = 0; i <= PS_RINGS; ++i)
            for (j = 0; j <= PS_SEGMENTS; ++j) {
                double th = FF_PI * (double)i / PS_RINGS, ph = 2.0 * FF_PI * (double)j / PS_SEGMENTS;
                float *v = p + 3u * (i * (PS_SEGMENTS + 1u) + j);
                v[0] = (float)(2.0 * r * s + r * sin(th) * cos(ph));
                v[1] = (float)(r * cos(th));
                v[2] = (float)(r * sin(th) * sin(ph));
            }
        w->meshes[s].positions = p;
        w->meshes[s].vertex_count = PS_VERTS;
        w->meshes[s].indices = w->idx;
        w->meshes[s].triangle_count = PS_TRIS;
        w->meshes[s].material = emit && (s & 1u) ? 1u : 0u;
    }
    for (i = 0; i < 2; ++i) w->mats[i].albedo[0] = w->mats[i].albedo[1] = w->mats[i].albedo[2] = 0.9f;
    w->mats[1].emission[0] = w->mats[1].emission[1] = w->mats[1].emission[2] = 1.0f;
    memset(&d, 0, sizeof d);
    d.meshes = w->meshes;
    d.mesh_count = count;
    d.materials = w->mats;
    d.material_count = 2;
    if (rad_scene_create(&d, NULL, &w->scene) != RAD_SUCCESS) return 0;
    if (rad_bvh_create(w->scene, NULL, &w->bvh) != RAD_SUCCESS) return 0;
    rad_bvh_raycaster(w->bvh, &w->rc);
    return 1;
}

static void ps_free(ps_world *w)
{
    rad_bvh_destroy(w->bvh);
    rad_scene_destroy(w->scene);
    free(w->pos);
    free(w->idx);
    memset(w, 0, sizeof(*w));
}

static int ps_plan(ps_world *w, uint32_t resolution, double max_seconds, rad_baker_choice *p)
{
    rad_baker_options o;
    memset(&o, 0, sizeof o);
    o.method = RAD_BAKER_VIRTUAL_PATCHES;
    o.vp_resolution = resolution;
    o.max_seconds = max_seconds;
    return rad_baker_plan(w->scene, &w->rc, &o, NULL, p) == RAD_SUCCESS;
}

/* the same row with and without emitters: the emitters' direct light (every sample tests
   the emitters in front of it and traces shadow rays to those above its plane) is in the
   time estimate, and only there: the memory and the patches are the same */
static void ps_test_emitters_cost(void)
{
    ps_world w;
    rad_baker_choice dark, lit;
    CHECK(ps_row(&w, 6, 1.0f, 0));
    CHECK(ps_plan(&w, 16, 0.0, &dark));
    ps_free(&w);
    CHECK(ps_row(&w, 6, 1.0f, 1));
    CHECK(ps_plan(&w, 16, 0.0, &lit));
    ps_free(&w);
    CHECK(dark.patch_count == lit.patch_count && dark.vp_samples == lit.vp_samples);
    CHECK(dark.estimated_bytes == lit.estimated_bytes);
    /* 3 emitting spheres of 400 triangles: about a hundred emitters lit per sample (their
       tests and the rays drawn among them) against the kernel sums of a few thousand samples */
    CHECK(lit.estimated_seconds > 2.0 * dark.estimated_seconds);
}

/* the estimate grows with the resolution (more samples, each paying for the emitters) */
static void ps_test_estimate_monotone(void)
{
    ps_world w;
    rad_baker_choice p[4];
    uint32_t res[4] = { 6, 10, 16, 24 }, k;
    CHECK(ps_row(&w, 6, 1.0f, 1));
    for (k = 0; k < 4; ++k) CHECK(ps_plan(&w, res[k], 0.0, &p[k]));
    for (k = 1; k < 4; ++k) {
        CHECK(p[k].vp_samples > p[k - 1].vp_samples);
        CHECK(p[k].estimated_seconds > p[k - 1].estimated_seconds);
    }
    ps_free(&w);
}

/* a time budget below the emitters' cost lowers the resolution, and the reason says so; the
   same budget leaves the row without emitters at its resolution */
static void ps_test_budget_counts_emitters(void)
{
    ps_world w;
    rad_baker_choice lit, dark, free_plan, free_dark;
    double budget;
    CHECK(ps_row(&w, 6, 1.0f, 0));
    CHECK(ps_plan(&w, 24, 0.0, &free_dark));
    budget = 1.5 * free_dark.estimated_seconds;
    CHECK(ps_plan(&w, 24, budget, &dark));
    ps_free(&w);
    CHECK(ps_row(&w, 6, 1.0f, 1));
    CHECK(ps_plan(&w, 24, 0.0, &free_plan));
    CHECK(ps_plan(&w, 24, budget, &lit));
    ps_free(&w);
    CHECK(free_plan.estimated_seconds > budget);
    CHECK(!free_plan.budget_limited && free_plan.vp_resolution == 24);
    CHECK(lit.budget_limited && lit.vp_resolution < 24 && lit.estimated_seconds <= budget);
    CHECK(strstr(lit.reason, "budget") != NULL);
    CHECK(!dark.budget_limited && dark.vp_resolution == 24);
}

/* the row ten times larger: the same mean free path in units of the radius, the same plan */
static void ps_test_units(void)
{
    ps_world w;
    rad_baker_choice a, b;
    CHECK(ps_row(&w, 6, 1.0f, 1));
    CHECK(ps_plan(&w, 0, 0.0, &a));
    ps_free(&w);
    CHECK(ps_row(&w, 6, 10.0f, 1));
    CHECK(ps_plan(&w, 0, 0.0, &b));
    ps_free(&w);
    CHECK_REL(b.free_path, 10.0f * a.free_path, 1e-3);
    CHECK(a.needed_resolution == b.needed_resolution && a.vp_resolution == b.vp_resolution && a.patch_count == b.patch_count);
    CHECK_REL(a.estimated_seconds, b.estimated_seconds, 0.05);
}

static const rad_test_case tests_plan_small[] = {
    { "plan_small_emitters_cost", ps_test_emitters_cost },
    { "plan_small_estimate_monotone", ps_test_estimate_monotone },
    { "plan_small_budget_counts_emitters", ps_test_budget_counts_emitters },
    { "plan_small_units", ps_test_units },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_plan_small)

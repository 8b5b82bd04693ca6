/* test_plan.c - the baker's plan (rad_baker_plan, PLAN in >>api_bake): the same plan twice,
   a resolution that follows the scene's shape and not its size, the memory and time budgets
   obeyed and said, AUTO's choice between classic and virtual patches, rad_baker_run taking
   the same plan, and the errors of bad input. Included by test_main.c after the
   implementation: every name is static and prefixed pl_. */
#include "fixtures.h"

typedef struct pl_world {
    vp_scene *s;
    rad_scene *scene;
    rad_bvh *bvh;
    rad_raycaster rc;
} pl_world;

/* the inside of a box sx x sy x sz (times 'scale'), n x n cells a face, a lit ceiling */
static int pl_box(pl_world *w, float sx, float sy, float sz, float scale, uint32_t n)
{
    rad_scene_desc d;
    memset(w, 0, sizeof(*w));
    w->s = (vp_scene *)malloc(sizeof(vp_scene));
    if (!w->s) return 0;
    vp_box(w->s, sx * scale, sy * scale, sz * scale, n, 1);
    vp_desc(w->s, &d, 0.6f, 0.0f);
    w->s->materials[1].emission[0] = w->s->materials[1].emission[1] = w->s->materials[1].emission[2] = 1.0f;
    if (rad_scene_create(&d, NULL, &w->scene) != RAD_SUCCESS) return 0;
    if (rad_bvh_create(w->scene, NULL, &w->bvh) != RAD_SUCCESS) return 0;
    rad_bvh_raycaster(w->bvh, &w->rc);
    return 1;
}

static void pl_free(pl_world *w)
{
    rad_bvh_destroy(w->bvh);
    rad_scene_destroy(w->scene);
    free(w->s);
    memset(w, 0, sizeof(*w));
}

static void pl_vp_options(rad_baker_options *o)
{
    memset(o, 0, sizeof(*o));
    o->method = RAD_BAKER_VIRTUAL_PATCHES;
}

/* the same scene and options give the same plan, bit for bit; NULL options = zeroed ones */
static void pl_test_deterministic(void)
{
    pl_world w;
    rad_baker_options o;
    rad_baker_choice a, b, c;
    CHECK(pl_box(&w, 3.0f, 1.0f, 1.0f, 1.0f, 6));
    pl_vp_options(&o);
    memset(&a, 0x55, sizeof a);
    memset(&b, 0xAA, sizeof b);
    CHECK_OK(rad_baker_plan(w.scene, &w.rc, &o, NULL, &a));
    CHECK_OK(rad_baker_plan(w.scene, &w.rc, &o, NULL, &b));
    CHECK(memcmp(&a, &b, sizeof a) == 0);
    CHECK(a.method == RAD_BAKER_VIRTUAL_PATCHES && a.vp_resolution >= 4 && a.patch_count > 0 && a.vp_samples >= a.patch_count);
    CHECK(a.free_path > 0.0f && a.escaped >= 0.0f && a.escaped < 0.05f); /* a closed box: hardly any ray leaves */
    CHECK(a.estimated_bytes > 0.0 && a.estimated_seconds > 0.0);
    memset(&c, 0, sizeof c);
    CHECK_OK(rad_baker_plan(w.scene, &w.rc, NULL, NULL, &c));
    memset(&o, 0, sizeof o);
    CHECK_OK(rad_baker_plan(w.scene, &w.rc, &o, NULL, &b));
    CHECK(memcmp(&b, &c, sizeof b) == 0);
    pl_free(&w);
}

/* a cube's mean free path is about 2/3 of its side (4 V / S); the resolution follows the
   shape (a corridor 8 long needs finer voxels along its length than a cube) and not the
   units (the cube ten times larger gets the same plan) */
static void pl_test_scales_with_scene(void)
{
    pl_world w;
    rad_baker_options o;
    rad_baker_choice cube, big, corridor;
    pl_vp_options(&o);
    CHECK(pl_box(&w, 1.0f, 1.0f, 1.0f, 1.0f, 6));
    CHECK_OK(rad_baker_plan(w.scene, &w.rc, &o, NULL, &cube));
    pl_free(&w);
    CHECK(pl_box(&w, 1.0f, 1.0f, 1.0f, 10.0f, 6));
    CHECK_OK(rad_baker_plan(w.scene, &w.rc, &o, NULL, &big));
    pl_free(&w);
    CHECK(pl_box(&w, 8.0f, 1.0f, 1.0f, 1.0f, 6));
    CHECK_OK(rad_baker_plan(w.scene, &w.rc, &o, NULL, &corridor));
    pl_free(&w);
    CHECK_REL(cube.free_path, 2.0f / 3.0f, 0.1);
    CHECK_REL(big.free_path, 20.0f / 3.0f, 0.1);
    CHECK(cube.needed_resolution >= 6 && cube.needed_resolution <= 14);
    CHECK(big.needed_resolution == cube.needed_resolution && big.patch_count == cube.patch_count);
    CHECK(corridor.needed_resolution > 3 * cube.needed_resolution);
    CHECK(corridor.patch_count > 2 * cube.patch_count);
    CHECK(corridor.estimated_seconds > cube.estimated_seconds && corridor.estimated_bytes > cube.estimated_bytes);
    CHECK(!cube.budget_limited && !corridor.budget_limited);
}

/* vp_voxels_per_path scales what the mean free path asks for: 6.5 given is the default, half
   of it asks for half the resolution (each rounded up), the path itself unchanged */
static void pl_test_voxels_per_path(void)
{
    pl_world w;
    rad_baker_options o;
    rad_baker_choice def, same, half;
    pl_vp_options(&o);
    CHECK(pl_box(&w, 8.0f, 1.0f, 1.0f, 1.0f, 6));
    CHECK_OK(rad_baker_plan(w.scene, &w.rc, &o, NULL, &def));
    o.vp_voxels_per_path = 6.5f;
    CHECK_OK(rad_baker_plan(w.scene, &w.rc, &o, NULL, &same));
    o.vp_voxels_per_path = 3.25f;
    CHECK_OK(rad_baker_plan(w.scene, &w.rc, &o, NULL, &half));
    pl_free(&w);
    CHECK(memcmp(&def, &same, sizeof def) == 0);
    CHECK(half.free_path == def.free_path && half.escaped == def.escaped);
    CHECK(def.needed_resolution >= 20);
    CHECK(2 * half.needed_resolution >= def.needed_resolution && 2 * half.needed_resolution <= def.needed_resolution + 2);
    CHECK(half.patch_count < def.patch_count && half.estimated_seconds < def.estimated_seconds);
}

/* one quad in the open: every ray leaves, nothing is exchanged, the coarsest resolution */
static void pl_test_open_scene(void)
{
    vp_scene *s = (vp_scene *)malloc(sizeof(vp_scene));
    float o0[3] = { 0, 0, 0 }, U[3] = { 0, 0, 2 }, V[3] = { 2, 0, 0 };
    rad_scene_desc d;
    rad_scene *S = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_baker_options o;
    rad_baker_choice p;
    CHECK(s != NULL);
    if (!s) return;
    memset(s, 0, sizeof(*s));
    vp_add_quad(s, o0, U, V, 0, 4);
    vp_desc(s, &d, 0.5f, 1.0f);
    CHECK_OK(rad_scene_create(&d, NULL, &S));
    CHECK_OK(rad_bvh_create(S, NULL, &bvh));
    if (S && bvh) {
        rad_bvh_raycaster(bvh, &rc);
        pl_vp_options(&o);
        CHECK_OK(rad_baker_plan(S, &rc, &o, NULL, &p));
        CHECK(p.escaped == 1.0f && p.needed_resolution == 4 && p.vp_resolution == 4);
    }
    rad_bvh_destroy(bvh);
    rad_scene_destroy(S);
    free(s);
}

/* the budget holds the resolution down, and the reason says so; a budget below the coarsest
   set is an error naming max_memory */
static void pl_test_budgets(void)
{
    pl_world w;
    rad_baker_options o;
    rad_baker_choice free_plan, mem, secs;
    rad_context ctx;
    CHECK(pl_box(&w, 8.0f, 1.0f, 1.0f, 1.0f, 6));
    pl_vp_options(&o);
    CHECK_OK(rad_baker_plan(w.scene, &w.rc, &o, NULL, &free_plan));
    o.max_memory = free_plan.estimated_bytes / 4.0;
    CHECK_OK(rad_baker_plan(w.scene, &w.rc, &o, NULL, &mem));
    CHECK(mem.budget_limited && mem.vp_resolution < free_plan.vp_resolution && mem.estimated_bytes <= o.max_memory);
    CHECK(mem.needed_resolution == free_plan.needed_resolution);
    CHECK(strstr(mem.reason, "max_memory") != NULL && strstr(mem.reason, "mean free path") != NULL);
    pl_vp_options(&o);
    o.max_seconds = free_plan.estimated_seconds / 8.0;
    CHECK_OK(rad_baker_plan(w.scene, &w.rc, &o, NULL, &secs));
    CHECK(secs.budget_limited && secs.vp_resolution < free_plan.vp_resolution);
    CHECK(secs.estimated_seconds <= o.max_seconds || secs.over_budget);
    pl_vp_options(&o);
    o.max_memory = 1024.0;
    ct_log_context(&ctx);
    CHECK_RESULT(rad_baker_plan(w.scene, &w.rc, &o, &ctx, &mem), RAD_ERROR_OUT_OF_MEMORY);
    CHECK(strstr(ct_log_last, "max_memory") != NULL);
    pl_free(&w);
}

/* AUTO: classic while its dense matrix fits, virtual patches when it does not */
static void pl_test_auto(void)
{
    pl_world w;
    rad_baker_options o;
    rad_baker_choice p;
    CHECK(pl_box(&w, 1.0f, 1.0f, 1.0f, 1.0f, 12));
    memset(&o, 0, sizeof o);
    o.patches = 200;
    CHECK_OK(rad_baker_plan(w.scene, &w.rc, &o, NULL, &p));
    CHECK(p.method == RAD_BAKER_CLASSIC && p.patch_count >= 864 && p.vp_resolution == 0 && !p.over_budget);
    CHECK(strncmp(p.reason, "classic", 7) == 0);
    o.max_memory = 2.5 * 1048576.0; /* below the 864 triangles' matrix (2.8 MiB) */
    CHECK_OK(rad_baker_plan(w.scene, &w.rc, &o, NULL, &p));
    CHECK(p.method == RAD_BAKER_VIRTUAL_PATCHES && strstr(p.reason, "classic would need") != NULL);
    o.method = RAD_BAKER_CLASSIC;
    CHECK_RESULT(rad_baker_plan(w.scene, &w.rc, &o, NULL, &p), RAD_ERROR_OUT_OF_MEMORY);
    memset(&o, 0, sizeof o);
    o.max_seconds = 1e-6; /* classic forced over the time budget runs, and says so */
    o.method = RAD_BAKER_CLASSIC;
    CHECK_OK(rad_baker_plan(w.scene, &w.rc, &o, NULL, &p));
    CHECK(p.method == RAD_BAKER_CLASSIC && p.over_budget && strstr(p.reason, "over (forced)") != NULL);
    pl_free(&w);
}

/* rad_baker_run makes the same plan and returns it */
static void pl_test_run_uses_plan(void)
{
    pl_world w;
    rad_baker_desc d;
    rad_baker_options o;
    rad_baker_choice p;
    rad_baker_result *R = NULL;
    CHECK(pl_box(&w, 2.0f, 1.0f, 1.0f, 1.0f, 3));
    pl_vp_options(&o);
    o.bounces = 4;
    o.light_samples = 4;
    CHECK_OK(rad_baker_plan(w.scene, &w.rc, &o, NULL, &p));
    memset(&d, 0, sizeof d);
    vp_desc(w.s, &d.scene, 0.6f, 0.0f);
    w.s->materials[1].emission[0] = w.s->materials[1].emission[1] = w.s->materials[1].emission[2] = 1.0f;
    CHECK_OK(rad_baker_run(&d, &o, NULL, &R));
    if (R) {
        CHECK(R->method == RAD_BAKER_VIRTUAL_PATCHES && R->vp_resolution == p.vp_resolution);
        CHECK(R->plan.needed_resolution == p.needed_resolution && R->plan.free_path == p.free_path);
        CHECK(R->patch_count == p.patch_count && strcmp(R->reason, R->plan.reason) == 0);
    }
    rad_baker_result_destroy(R);
    pl_free(&w);
}

static void pl_test_bad_input(void)
{
    pl_world w;
    rad_baker_options o;
    rad_baker_choice p;
    rad_raycaster none;
    CHECK(pl_box(&w, 1.0f, 1.0f, 1.0f, 1.0f, 2));
    memset(&none, 0, sizeof none);
    CHECK_RESULT(rad_baker_plan(NULL, &w.rc, NULL, NULL, &p), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_baker_plan(w.scene, NULL, NULL, NULL, &p), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_baker_plan(w.scene, &none, NULL, NULL, &p), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_baker_plan(w.scene, &w.rc, NULL, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    memset(&o, 0, sizeof o);
    o.method = (rad_baker_method)7;
    CHECK_RESULT(rad_baker_plan(w.scene, &w.rc, &o, NULL, &p), RAD_ERROR_INVALID_ARGUMENT);
    memset(&o, 0, sizeof o);
    o.max_memory = -1.0;
    CHECK_RESULT(rad_baker_plan(w.scene, &w.rc, &o, NULL, &p), RAD_ERROR_INVALID_ARGUMENT);
    memset(&o, 0, sizeof o);
    o.max_seconds = HUGE_VAL;
    CHECK_RESULT(rad_baker_plan(w.scene, &w.rc, &o, NULL, &p), RAD_ERROR_INVALID_ARGUMENT);
    memset(&o, 0, sizeof o);
    o.vp_voxels_per_path = -1.0f;
    CHECK_RESULT(rad_baker_plan(w.scene, &w.rc, &o, NULL, &p), RAD_ERROR_INVALID_ARGUMENT);
    o.vp_voxels_per_path = 65.0f;
    CHECK_RESULT(rad_baker_plan(w.scene, &w.rc, &o, NULL, &p), RAD_ERROR_INVALID_ARGUMENT);
    o.vp_voxels_per_path = (float)NAN;
    CHECK_RESULT(rad_baker_plan(w.scene, &w.rc, &o, NULL, &p), RAD_ERROR_INVALID_ARGUMENT);
    pl_free(&w);
}

static const rad_test_case tests_plan[] = {
    { "plan_deterministic", pl_test_deterministic },
    { "plan_scales_with_scene", pl_test_scales_with_scene },
    { "plan_voxels_per_path", pl_test_voxels_per_path },
    { "plan_open_scene", pl_test_open_scene },
    { "plan_budgets", pl_test_budgets },
    { "plan_auto", pl_test_auto },
    { "plan_run_uses_plan", pl_test_run_uses_plan },
    { "plan_bad_input", pl_test_bad_input },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_plan)

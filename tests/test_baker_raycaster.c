/* test_baker_raycaster.c - the engine tier with the caller's ray caster
   (rad_baker_desc.raycaster, RAYCASTER in >>api_bake): a counting caster over a BVH built with
   the public calls is used (calls counted) and gives the tier's own outputs bit for bit
   (vertices, a lightmap, probes; classic and virtual patches), the runtime takes it too (and
   builds a BVH of its own over a kept scene whose bake had none), a caster without its
   callbacks is refused with INVALID_ARGUMENT, and with Embree an Embree caster gives the same
   light within its rounding. Included by test_main.c after the implementation: every name is
   static and prefixed brc_. */
#include "fixtures.h"

/* A caster that forwards to another and counts the batches of each kind. */
typedef struct brc_counter {
    rad_raycaster inner;
    unsigned long occluded_calls, intersect_calls;
} brc_counter;

static rad_result brc_occluded(void *user, const rad_ray *rays, uint32_t count, uint8_t *out)
{
    brc_counter *c = (brc_counter *)user;
#ifdef _OPENMP
#pragma omp atomic
#endif
    c->occluded_calls++;
    return c->inner.occluded(c->inner.user, rays, count, out);
}

static rad_result brc_intersect(void *user, const rad_ray *rays, uint32_t count, rad_hit *out)
{
    brc_counter *c = (brc_counter *)user;
#ifdef _OPENMP
#pragma omp atomic
#endif
    c->intersect_calls++;
    return c->inner.intersect(c->inner.user, rays, count, out);
}

/* The scene of desc->scene and its BVH built as a caller would, and the counting caster over it. */
typedef struct brc_world {
    rad_scene *scene;
    rad_bvh *bvh;
    brc_counter count;
    rad_raycaster rc;
} brc_world;

static int brc_world_make(brc_world *w, const rad_scene_desc *sd)
{
    memset(w, 0, sizeof *w);
    CHECK_OK(rad_scene_create(sd, NULL, &w->scene));
    if (!w->scene) return 0;
    CHECK_OK(rad_bvh_create(w->scene, NULL, &w->bvh));
    if (!w->bvh) return 0;
    /* the library's BVH caster even in the Embree suite (fixtures.h maps the name to Embree
       there): the outputs must be the tier's own BVH's, bit for bit */
    (rad_bvh_raycaster)(w->bvh, &w->count.inner);
    w->rc.user = &w->count;
    w->rc.occluded = brc_occluded;
    w->rc.intersect = brc_intersect;
    return 1;
}

static void brc_world_free(brc_world *w)
{
    rad_bvh_destroy(w->bvh);
    rad_scene_destroy(w->scene);
}

/* The two rooms with a point light in the left one: vertices, a 16 x 8 lightmap, 2 probes. */
typedef struct brc_scene {
    lm_soup room, wall, lamp;
    rad_mesh_desc meshes[3];
    rad_material mats[2];
    rad_baker_desc d;
    rad_baker_light bl;
    float probe_at[6];
} brc_scene;

static void brc_make(brc_scene *s)
{
    const float at[6] = { 0.5f, 0.5f, 0.5f, 1.5f, 0.5f, 0.5f };
    memset(&s->d, 0, sizeof s->d);
    fx_two_rooms(&s->room, &s->wall, &s->lamp, s->meshes, &s->d.scene, s->mats);
    memset(&s->bl, 0, sizeof s->bl);
    s->bl.light.type = RAD_LIGHT_POINT;
    s->bl.light.position[0] = 0.5f; s->bl.light.position[1] = 0.7f; s->bl.light.position[2] = 0.4f;
    s->bl.light.color[0] = s->bl.light.color[1] = s->bl.light.color[2] = 1.0f;
    memcpy(s->probe_at, at, sizeof at);
    s->d.lights = &s->bl;
    s->d.light_count = 1;
    s->d.outputs = RAD_BAKER_VERTEX | RAD_BAKER_LIGHTMAP | RAD_BAKER_PROBES;
    s->d.lightmap_width = 16;
    s->d.lightmap_height = 8;
    s->d.probe_positions = s->probe_at;
    s->d.probe_count = 2;
}

static void brc_options(rad_baker_options *o, rad_baker_method method)
{
    memset(o, 0, sizeof(*o));
    o->method = method;
    o->patches = 64;
    o->vp_resolution = 5;
    o->ff_samples = 4;
    o->bounces = 8;
    o->light_samples = 4;
    o->lightmap_samples = 1;
}

static int brc_same(const float *a, const float *b, size_t n)
{
    return (a == NULL) == (b == NULL) && (n == 0 || !a || memcmp(a, b, n * sizeof(float)) == 0);
}

/* every output of B is A's, bit for bit */
static void brc_check_same(const rad_baker_result *A, const rad_baker_result *B)
{
    CHECK(A->method == B->method && A->patch_count == B->patch_count && A->vp_resolution == B->vp_resolution);
    CHECK(A->vertex_count == B->vertex_count && A->probe_count == B->probe_count);
    CHECK(A->lightmap_width == B->lightmap_width && A->lightmap_height == B->lightmap_height);
    if (A->vertex_count != B->vertex_count || A->probe_count != B->probe_count || A->lightmap_width != B->lightmap_width ||
        A->lightmap_height != B->lightmap_height)
        return;
    CHECK(A->vertex && brc_same(A->vertex, B->vertex, 3 * (size_t)A->vertex_count));
    CHECK(A->lightmap && brc_same(A->lightmap, B->lightmap, 3 * (size_t)A->lightmap_width * A->lightmap_height));
    CHECK(A->lightmap_flags && B->lightmap_flags &&
          memcmp(A->lightmap_flags, B->lightmap_flags, (size_t)A->lightmap_width * A->lightmap_height) == 0);
    CHECK(A->probes && brc_same(A->probes, B->probes, 27 * (size_t)A->probe_count));
    CHECK(A->probe_positions && brc_same(A->probe_positions, B->probe_positions, 3 * (size_t)A->probe_count));
}

/* the given caster is the one cast through, and its answers are the tier's own BVH's: the
   same bits for both methods */
static void brc_test_same_bits(void)
{
    int pass;
    for (pass = 0; pass < 2; ++pass) {
        brc_scene s;
        brc_world w;
        rad_baker_options o;
        rad_baker_result *A = NULL, *B = NULL;
        double sum = 0.0;
        uint32_t i;
        brc_make(&s);
        brc_options(&o, pass ? RAD_BAKER_VIRTUAL_PATCHES : RAD_BAKER_CLASSIC);
        if (brc_world_make(&w, &s.d.scene)) {
            CHECK_OK(rad_baker_run(&s.d, &o, NULL, &A));
            s.d.raycaster = &w.rc;
            CHECK_OK(rad_baker_run(&s.d, &o, NULL, &B));
            if (A && B) {
                CHECK(w.count.occluded_calls > 0);
                CHECK(w.count.intersect_calls > 0);
                brc_check_same(A, B);
                for (i = 0; i < 3 * A->vertex_count; ++i) sum += A->vertex[i];
                CHECK(sum > 0.0); /* light reached the vertices: the comparison is not of zeros */
            }
        }
        rad_baker_result_destroy(A);
        rad_baker_result_destroy(B);
        brc_world_free(&w);
    }
}

/* the runtime casts through the desc's caster (create and updates), and one over a kept
   result whose bake had a caster (no BVH kept) builds its own: every frame the same bits */
static void brc_test_runtime(void)
{
    brc_scene s;
    brc_world w;
    rad_baker_options o, ok;
    rad_baker_result *A = NULL, *B = NULL, *K0 = NULL, *K1 = NULL;
    rad_baker_runtime *ra = NULL, *rb = NULL, *rk0 = NULL, *rk1 = NULL;
    rad_baker_frame fa, fb, fk0, fk1;
    rad_light moved;
    unsigned long before;
    brc_make(&s);
    brc_options(&o, RAD_BAKER_CLASSIC);
    ok = o;
    ok.keep = 1;
    if (!brc_world_make(&w, &s.d.scene)) {
        brc_world_free(&w);
        return;
    }
    moved = s.bl.light;
    moved.position[0] = 0.3f;
    moved.position[2] = 0.7f;
    /* without a caster: the bake's own BVH, the runtime's own (A) or the kept one (K0) */
    CHECK_OK(rad_baker_run(&s.d, &o, NULL, &A));
    CHECK_OK(rad_baker_run(&s.d, &ok, NULL, &K0));
    if (A) CHECK_OK(rad_baker_runtime_create(&s.d, &o, A, NULL, NULL, &ra));
    if (K0) CHECK_OK(rad_baker_runtime_create(&s.d, &ok, K0, NULL, NULL, &rk0));
    /* with it: the runtime over B casts through it; K1 keeps no BVH, and its runtime without
       a caster builds one */
    s.d.raycaster = &w.rc;
    CHECK_OK(rad_baker_run(&s.d, &o, NULL, &B));
    CHECK_OK(rad_baker_run(&s.d, &ok, NULL, &K1));
    if (B) CHECK_OK(rad_baker_runtime_create(&s.d, &o, B, NULL, NULL, &rb));
    s.d.raycaster = NULL;
    if (K1) CHECK_OK(rad_baker_runtime_create(&s.d, &ok, K1, NULL, NULL, &rk1));
    if (ra && rb && rk0 && rk1) {
        size_t nv = 3 * (size_t)A->vertex_count, nl = 3 * (size_t)A->lightmap_width * A->lightmap_height,
               np = 27 * (size_t)A->probe_count;
        CHECK_OK(rad_baker_runtime_update(ra, &moved, 1, 0.0, &fa));
        before = w.count.occluded_calls;
        CHECK_OK(rad_baker_runtime_update(rb, &moved, 1, 0.0, &fb));
        CHECK(w.count.occluded_calls > before); /* the frame's shadow rays went through the caster */
        before = w.count.occluded_calls + w.count.intersect_calls;
        CHECK_OK(rad_baker_runtime_update(rk0, &moved, 1, 0.0, &fk0));
        CHECK_OK(rad_baker_runtime_update(rk1, &moved, 1, 0.0, &fk1));
        CHECK(w.count.occluded_calls + w.count.intersect_calls == before); /* those two have BVHs */
        CHECK(fa.phase == RAD_BAKER_RUNTIME_EXACT && fa.lights_changed == 1);
        CHECK(brc_same(fa.vertex, fb.vertex, nv) && brc_same(fa.lightmap, fb.lightmap, nl) &&
              brc_same(fa.probes, fb.probes, np));
        CHECK(brc_same(fk0.vertex, fk1.vertex, nv) && brc_same(fk0.lightmap, fk1.lightmap, nl) &&
              brc_same(fk0.probes, fk1.probes, np));
        CHECK(fa.vertex && fk0.vertex && !brc_same(fa.vertex, A->vertex, nv)); /* the light did move */
    }
    rad_baker_runtime_destroy(ra);
    rad_baker_runtime_destroy(rb);
    rad_baker_runtime_destroy(rk0);
    rad_baker_runtime_destroy(rk1);
    rad_baker_result_destroy(A);
    rad_baker_result_destroy(B);
    rad_baker_result_destroy(K0);
    rad_baker_result_destroy(K1);
    brc_world_free(&w);
}

/* a caster without a callback the tier calls: INVALID_ARGUMENT, the log naming it, no leak */
static void brc_test_refused(void)
{
    brc_scene s;
    brc_world w;
    rad_baker_options o;
    rad_baker_result *R = NULL, *ok = NULL;
    rad_baker_runtime *rt = NULL;
    rad_raycaster bad;
    rad_context ctx;
    sc_alloc_state st;
    fx_err_log lg;
    int which;
    brc_make(&s);
    brc_options(&o, RAD_BAKER_CLASSIC);
    s.d.outputs = RAD_BAKER_VERTEX;
    if (!brc_world_make(&w, &s.d.scene)) {
        brc_world_free(&w);
        return;
    }
    for (which = 0; which < 3; ++which) {
        bad = w.rc;
        if (which != 1) bad.occluded = NULL;
        if (which != 0) bad.intersect = NULL;
        memset(&st, 0, sizeof st);
        memset(&lg, 0, sizeof lg);
        sc_ctx_alloc(&ctx, &st);
        ctx.log = fx_err_log_fn;
        ctx.log_user = &lg;
        s.d.raycaster = &bad;
        R = (rad_baker_result *)(uintptr_t)1;
        CHECK_RESULT(rad_baker_run(&s.d, &o, &ctx, &R), RAD_ERROR_INVALID_ARGUMENT);
        CHECK(R == NULL);
        CHECK(lg.errors > 0 && strstr(lg.last, "raycaster") && strstr(lg.last, which == 1 ? "intersect" : "occluded"));
        CHECK(st.live_bytes == 0);
        CHECK(w.count.occluded_calls == 0 && w.count.intersect_calls == 0);
    }
    /* the runtime refuses it too, over a good bake */
    s.d.raycaster = &w.rc;
    CHECK_OK(rad_baker_run(&s.d, &o, NULL, &ok));
    if (ok) {
        bad = w.rc;
        bad.intersect = NULL;
        s.d.raycaster = &bad;
        memset(&lg, 0, sizeof lg);
        memset(&ctx, 0, sizeof ctx);
        ctx.log = fx_err_log_fn;
        ctx.log_user = &lg;
        CHECK_RESULT(rad_baker_runtime_create(&s.d, &o, ok, NULL, &ctx, &rt), RAD_ERROR_INVALID_ARGUMENT);
        CHECK(rt == NULL);
        CHECK(lg.errors > 0 && strstr(lg.last, "raycaster") && strstr(lg.last, "intersect"));
    }
    rad_baker_runtime_destroy(rt);
    rad_baker_result_destroy(ok);
    brc_world_free(&w);
}

/* Embree's caster over the same scene: the same light within its rounding (a hit's t and
   barycentrics differ in the last bits, which moves a few shadow and gather rays) */
static void brc_test_embree(void)
{
#ifdef RAD_EMBREE
    brc_scene s;
    rad_scene *S = NULL;
    rad_embree *e = NULL;
    rad_raycaster rc;
    rad_baker_options o;
    rad_baker_result *A = NULL, *B = NULL;
    double diff = 0.0, sum = 0.0;
    uint32_t i;
    brc_make(&s);
    s.d.outputs = RAD_BAKER_VERTEX;
    brc_options(&o, RAD_BAKER_CLASSIC);
    CHECK_OK(rad_scene_create(&s.d.scene, NULL, &S));
    if (S) CHECK_OK(rad_embree_create(S, NULL, &e));
    if (e) {
        rad_embree_raycaster(e, &rc);
        CHECK_OK(rad_baker_run(&s.d, &o, NULL, &A));
        s.d.raycaster = &rc;
        CHECK_OK(rad_baker_run(&s.d, &o, NULL, &B));
        if (A && B && A->vertex_count == B->vertex_count) {
            for (i = 0; i < 3 * A->vertex_count; ++i) {
                diff += fabs((double)A->vertex[i] - B->vertex[i]);
                sum += A->vertex[i];
            }
            CHECK(sum > 0.0 && diff <= 0.01 * sum);
        }
    }
    rad_baker_result_destroy(A);
    rad_baker_result_destroy(B);
    rad_embree_destroy(e);
    rad_scene_destroy(S);
#endif
}

static const rad_test_case tests_baker_raycaster[] = {
    { "baker_raycaster_same_bits", brc_test_same_bits },
    { "baker_raycaster_runtime", brc_test_runtime },
    { "baker_raycaster_refused", brc_test_refused },
    { "baker_raycaster_embree", brc_test_embree },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_baker_raycaster)

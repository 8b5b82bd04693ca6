/* test_runtime.c - lights that move over a bake (rad_baker_runtime_*, docs/methods/bake.md
   "Run time"): an update with the baked lights leaves the bake's outputs as they are, bit for
   bit; a light moved and updated to convergence gives the outputs of a fresh rad_baker_run
   with the light there (classic and virtual patches, the Cornell box and the two rooms with a
   lightmap), also when the budget splits the work over frames; another task split gives the
   same bits; bad input gives specific errors and changes nothing. Included by test_main.c
   after the implementation: every name is static and prefixed rtm_. */
#include "fixtures.h"

/* the mean of |a - b| over the mean of |b|: the error the docs state */
static double rtm_rel(const float *a, const float *b, size_t n)
{
    double d = 0.0, s = 0.0;
    size_t i;
    for (i = 0; i < n; ++i) d += fabs((double)a[i] - b[i]), s += fabs((double)b[i]);
    return s > 0.0 ? d / s : d;
}

/* the largest |a - b| over the largest |b| */
static double rtm_max_rel(const float *a, const float *b, size_t n)
{
    double d = 0.0, s = 0.0;
    size_t i;
    for (i = 0; i < n; ++i) {
        if (fabs((double)a[i] - b[i]) > d) d = fabs((double)a[i] - b[i]);
        if (fabs((double)b[i]) > s) s = fabs((double)b[i]);
    }
    return s > 0.0 ? d / s : d;
}

static void rtm_point(rad_light *l, float x, float y, float z, float power)
{
    memset(l, 0, sizeof(*l));
    l->type = RAD_LIGHT_POINT;
    l->position[0] = x; l->position[1] = y; l->position[2] = z;
    l->color[0] = l->color[1] = l->color[2] = power;
}

static void rtm_options(rad_baker_options *o, rad_baker_method method)
{
    memset(o, 0, sizeof(*o));
    o->method = method;
    o->patches = rad_test_quick() ? 80u : 150u;
    o->vp_resolution = rad_test_quick() ? 5u : 7u;
    o->ff_samples = 4;
    o->bounces = 8;
    o->light_samples = 4;
    o->lightmap_samples = 1;
}

/* A scene with its lights: 0 the Cornell box (the ceiling lamp stays, a point light moves;
   vertices and probes), 1 the two rooms (a point light in the right room; vertices, a
   lightmap and probes). */
typedef struct rtm_scene {
    lm_soup room, wall, lamp;
    rad_mesh_desc meshes[3];
    rad_material mats[2];
    rad_baker_desc d;
    rad_baker_light bl;
} rtm_scene;

static void rtm_make(rtm_scene *s, int which)
{
    memset(&s->d, 0, sizeof s->d);
    memset(&s->bl, 0, sizeof s->bl);
    if (which == 0) {
        rad_cornell_box(&s->d.scene, NULL);
        rtm_point(&s->bl.light, 0.28f, 0.35f, 0.28f, 0.05f);
        s->d.outputs = RAD_BAKER_VERTEX | RAD_BAKER_PROBES;
        s->d.probe_spacing = 0.2f;
    } else {
        fx_two_rooms(&s->room, &s->wall, &s->lamp, s->meshes, &s->d.scene, s->mats);
        rtm_point(&s->bl.light, 1.3f, 0.7f, 0.3f, 1.0f);
        s->d.outputs = RAD_BAKER_VERTEX | RAD_BAKER_LIGHTMAP | RAD_BAKER_PROBES;
        s->d.lightmap_width = 32;
        s->d.lightmap_height = 16;
        s->d.probe_spacing = 0.4f;
    }
    s->d.lights = &s->bl;
    s->d.light_count = 1;
}

static void rtm_compare(const rad_baker_frame *f, const rad_baker_result *R, double tol_v, double tol_lm, double tol_p,
                        const char *what)
{
    size_t nv = 3 * (size_t)R->vertex_count, nl = 3 * (size_t)R->lightmap_width * R->lightmap_height,
           np = 27 * (size_t)R->probe_count;
    double ev = R->vertex ? rtm_rel(f->vertex, R->vertex, nv) : 0.0;
    double el = R->lightmap ? rtm_rel(f->lightmap, R->lightmap, nl) : 0.0;
    double ep = R->probes ? rtm_rel(f->probes, R->probes, np) : 0.0;
    if (!(ev <= tol_v && el <= tol_lm && ep <= tol_p))
        printf("    %s: mean relative error vertex %.3g (tol %.3g), lightmap %.3g (%.3g), probes %.3g (%.3g)\n", what, ev,
               tol_v, el, tol_lm, ep, tol_p);
    CHECK(ev <= tol_v);
    CHECK(el <= tol_lm);
    CHECK(ep <= tol_p);
    if (R->vertex) CHECK(rtm_max_rel(f->vertex, R->vertex, nv) <= 50.0 * tol_v + 1e-5);
}

/* the baked lights again: nothing changes, the outputs are the bake's bits */
static void rtm_test_zero_move(void)
{
    int which, pass;
    for (which = 0; which < 2; ++which)
        for (pass = 0; pass < 2; ++pass) {
            rtm_scene s;
            rad_baker_options o;
            rad_baker_result *R = NULL;
            rad_baker_runtime *rt = NULL;
            rad_baker_frame f;
            rtm_make(&s, which);
            rtm_options(&o, pass ? RAD_BAKER_VIRTUAL_PATCHES : RAD_BAKER_CLASSIC);
            CHECK_OK(rad_baker_run(&s.d, &o, NULL, &R));
            if (R) CHECK_OK(rad_baker_runtime_create(&s.d, &o, R, NULL, NULL, &rt));
            if (rt) {
                CHECK_OK(rad_baker_runtime_update(rt, &s.bl.light, 1, 0.0, &f));
                CHECK(f.phase == RAD_BAKER_RUNTIME_CONVERGED && f.lights_changed == 0 && f.frame == 1);
                CHECK(f.vertex && memcmp(f.vertex, R->vertex, 3 * sizeof(float) * R->vertex_count) == 0);
                CHECK(f.probes && memcmp(f.probes, R->probes, 27 * sizeof(float) * R->probe_count) == 0);
                if (which == 1)
                    CHECK(f.lightmap &&
                          memcmp(f.lightmap, R->lightmap, 3 * sizeof(float) * R->lightmap_width * R->lightmap_height) == 0);
                else
                    CHECK(f.lightmap == NULL);
                CHECK(f.planned_ms == 0.0 && f.shadow_rays == 0);
            }
            rad_baker_runtime_destroy(rt);
            rad_baker_result_destroy(R);
        }
}

/* moved, then updated to convergence with no budget: a fresh bake with the light there.
   Virtual patches: exact sweeps, float rounding (measured 2e-7; tolerance 1e-4). Classic: exact
   too, but the lightmap keeps the bake's sub-patch detail (measured 4.8%, 7.7% with RAD_TEST_QUICK; tolerance 15%). */
static void rtm_test_moved(void)
{
    int which, pass;
    for (which = 0; which < 2; ++which)
        for (pass = 0; pass < 2; ++pass) {
            rtm_scene s, t;
            rad_baker_options o;
            rad_baker_result *R = NULL, *Q = NULL;
            rad_baker_runtime *rt = NULL;
            rad_baker_frame f;
            rad_light moved;
            int k;
            rtm_make(&s, which);
            rtm_make(&t, which);
            if (which == 0) rtm_point(&t.bl.light, 0.15f, 0.2f, 0.4f, 0.08f);
            else rtm_point(&t.bl.light, 1.75f, 0.35f, 0.7f, 1.5f);
            moved = t.bl.light;
            rtm_options(&o, pass ? RAD_BAKER_VIRTUAL_PATCHES : RAD_BAKER_CLASSIC);
            CHECK_OK(rad_baker_run(&s.d, &o, NULL, &R));
            CHECK_OK(rad_baker_run(&t.d, &o, NULL, &Q));
            if (R) CHECK_OK(rad_baker_runtime_create(&s.d, &o, R, NULL, NULL, &rt));
            if (!rt || !Q) goto next;
            CHECK_OK(rad_baker_runtime_update(rt, &moved, 1, 0.0, &f));
            CHECK(f.lights_changed == 1 && f.vertex_refreshed == 1);
            CHECK(f.phase == (pass ? RAD_BAKER_RUNTIME_MOVING : RAD_BAKER_RUNTIME_EXACT));
            for (k = 0; k < 50 && f.phase != RAD_BAKER_RUNTIME_CONVERGED; ++k)
                CHECK_OK(rad_baker_runtime_update(rt, &moved, 1, 0.0, &f));
            CHECK(f.phase == RAD_BAKER_RUNTIME_CONVERGED);
            CHECK(k <= (pass ? 12 : 1)); /* shadows settle in 8 frames, then one call refines */
            rtm_compare(&f, Q, 1e-4, pass ? 1e-4 : 0.15, 1e-4, pass ? "moved, virtual patches" : "moved, classic");
            /* and back: the bake again */
            CHECK_OK(rad_baker_runtime_update(rt, &s.bl.light, 1, 0.0, &f));
            for (k = 0; k < 50 && f.phase != RAD_BAKER_RUNTIME_CONVERGED; ++k)
                CHECK_OK(rad_baker_runtime_update(rt, &s.bl.light, 1, 0.0, &f));
            rtm_compare(&f, R, 1e-4, 1e-4, 1e-4, "moved back");
        next:
            rad_baker_runtime_destroy(rt);
            rad_baker_result_destroy(R);
            rad_baker_result_destroy(Q);
        }
}

/* A light moving on a budget: the temporal estimate follows it (within 30% while it moves),
   the outputs refresh round-robin, and once it rests the frames converge to the fresh bake. */
static void rtm_test_budget(void)
{
    rtm_scene s, t;
    rad_baker_options o;
    rad_baker_runtime_options ro;
    rad_baker_result *R = NULL, *Q = NULL;
    rad_baker_runtime *rt = NULL;
    rad_baker_frame f;
    rad_light l;
    int k, partial = 0, frames = 0;
    rtm_make(&s, 1);
    rtm_make(&t, 1);
    rtm_point(&t.bl.light, 1.75f, 0.35f, 0.7f, 1.0f);
    rtm_options(&o, RAD_BAKER_VIRTUAL_PATCHES);
    CHECK_OK(rad_baker_run(&s.d, &o, NULL, &R));
    CHECK_OK(rad_baker_run(&t.d, &o, NULL, &Q));
    memset(&ro, 0, sizeof ro);
    ro.work_per_ms = 1e4; /* a slow machine: the budget below then splits the outputs */
    if (R) CHECK_OK(rad_baker_runtime_create(&s.d, &o, R, &ro, NULL, &rt));
    if (!rt || !Q) goto done;
    for (k = 1; k <= 20; ++k) { /* from the baked place to the new one in 20 frames */
        float a = (float)k / 20.0f;
        rtm_point(&l, 1.3f + a * 0.45f, 0.7f - a * 0.35f, 0.3f + a * 0.4f, 1.0f);
        CHECK_OK(rad_baker_runtime_update(rt, &l, 1, 1.0, &f));
        CHECK(f.phase == RAD_BAKER_RUNTIME_MOVING);
        partial += f.lightmap_rows < f.lightmap_rows_total;
        CHECK(f.lightmap_rows >= f.lightmap_rows_total / 64);
    }
    CHECK(partial > 0);
    CHECK(rtm_rel(f.vertex, Q->vertex, 3 * (size_t)Q->vertex_count) < 0.3);
    for (frames = 0; frames < 2000 && f.phase != RAD_BAKER_RUNTIME_CONVERGED; ++frames)
        CHECK_OK(rad_baker_runtime_update(rt, &l, 1, 1.0, &f));
    CHECK(f.phase == RAD_BAKER_RUNTIME_CONVERGED && f.lightmap_stale == 0 && f.probes_stale == 0);
    CHECK(frames < 2000);
    rtm_compare(&f, Q, 1e-4, 1e-4, 1e-4, "budget, at rest");
done:
    rad_baker_runtime_destroy(rt);
    rad_baker_result_destroy(R);
    rad_baker_result_destroy(Q);
}

static void rtm_reverse_for(void *user, uint32_t count, rad_task_fn fn, void *data)
{
    uint32_t i;
    (void)user;
    for (i = count; i-- > 0;) fn(data, i);
}

/* the same frames with another task count and order give the same bits */
static void rtm_test_deterministic(void)
{
    rtm_scene s;
    rad_baker_options o;
    rad_baker_runtime_options ro;
    rad_baker_result *R = NULL;
    rad_baker_runtime *a = NULL, *b = NULL;
    rad_baker_frame fa, fb;
    rad_context ctx;
    rad_light l;
    int k, pass;
    memset(&ctx, 0, sizeof ctx);
    ctx.parallel_for = rtm_reverse_for;
    ctx.task_count = 7;
    memset(&ro, 0, sizeof ro);
    ro.work_per_ms = 1e4;
    for (pass = 0; pass < 2; ++pass) {
        rtm_make(&s, 1);
        rtm_options(&o, pass ? RAD_BAKER_VIRTUAL_PATCHES : RAD_BAKER_CLASSIC);
        CHECK_OK(rad_baker_run(&s.d, &o, NULL, &R));
        if (R) CHECK_OK(rad_baker_runtime_create(&s.d, &o, R, &ro, NULL, &a));
        if (R) CHECK_OK(rad_baker_runtime_create(&s.d, &o, R, &ro, &ctx, &b));
        for (k = 0; a && b && k < 30; ++k) {
            rtm_point(&l, 1.3f + 0.02f * (float)(k < 15 ? k : 15), 0.7f, 0.3f, 1.0f);
            CHECK_OK(rad_baker_runtime_update(a, &l, 1, 1.0, &fa));
            CHECK_OK(rad_baker_runtime_update(b, &l, 1, 1.0, &fb));
            CHECK(fa.phase == fb.phase && fa.lightmap_rows == fb.lightmap_rows && fa.rows_swept == fb.rows_swept);
            CHECK(memcmp(fa.vertex, fb.vertex, 3 * sizeof(float) * R->vertex_count) == 0);
            CHECK(memcmp(fa.lightmap, fb.lightmap, 3 * sizeof(float) * R->lightmap_width * R->lightmap_height) == 0);
            CHECK(memcmp(fa.probes, fb.probes, 27 * sizeof(float) * R->probe_count) == 0);
        }
        rad_baker_runtime_destroy(a);
        rad_baker_runtime_destroy(b);
        rad_baker_result_destroy(R);
        a = b = NULL;
        R = NULL;
    }
}

static void rtm_expect(rad_baker_runtime *rt, fx_err_log *lg, const rad_light *l, uint32_t n, double budget, rad_result want,
                       const char *word)
{
    rad_baker_frame f;
    int before = lg->errors;
    CHECK_RESULT(rad_baker_runtime_update(rt, l, n, budget, &f), want);
    CHECK(lg->errors > before);
    if (word && !strstr(lg->last, word)) {
        printf("    log '%s' lacks '%s'\n", lg->last, word);
        CHECK(!"the log names the problem");
    }
}

static void rtm_test_bad_input(void)
{
    rtm_scene s;
    rad_baker_options o;
    rad_baker_runtime_options ro;
    rad_baker_result *R = NULL;
    rad_baker_runtime *rt = NULL;
    rad_baker_frame f;
    rad_context ctx;
    fx_err_log lg;
    sc_alloc_state st;
    rad_light two[2], l;
    float *before = NULL;
    memset(&lg, 0, sizeof lg);
    memset(&st, 0, sizeof st);
    sc_ctx_alloc(&ctx, &st);
    ctx.log = fx_err_log_fn;
    ctx.log_user = &lg;
    rtm_make(&s, 0);
    rtm_options(&o, RAD_BAKER_VIRTUAL_PATCHES);
    CHECK_OK(rad_baker_run(&s.d, &o, NULL, &R));
    if (!R) return;
    CHECK_RESULT(rad_baker_runtime_create(NULL, &o, R, NULL, &ctx, &rt), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_baker_runtime_create(&s.d, &o, NULL, NULL, &ctx, &rt), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(rt == NULL);
    memset(&ro, 0, sizeof ro);
    ro.temporal_weight = 1.0f;
    CHECK_RESULT(rad_baker_runtime_create(&s.d, &o, R, &ro, &ctx, &rt), RAD_ERROR_INVALID_ARGUMENT);
    ro.temporal_weight = 0.0f;
    ro.work_per_ms = -1.0;
    CHECK_RESULT(rad_baker_runtime_create(&s.d, &o, R, &ro, &ctx, &rt), RAD_ERROR_INVALID_ARGUMENT);
    /* a result of other options, or of another scene */
    o.method = RAD_BAKER_CLASSIC;
    CHECK_RESULT(rad_baker_runtime_create(&s.d, &o, R, NULL, &ctx, &rt), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(lg.last, "other bake options") != NULL);
    o.method = RAD_BAKER_VIRTUAL_PATCHES;
    s.d.outputs = RAD_BAKER_VERTEX; /* the result has probes, this desc asks for none */
    CHECK_RESULT(rad_baker_runtime_create(&s.d, &o, R, NULL, &ctx, &rt), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(lg.last, "not a bake of this desc") != NULL);
    s.d.outputs = RAD_BAKER_VERTEX | RAD_BAKER_PROBES;
    {
        rtm_scene other;
        rtm_make(&other, 1);
        other.d.outputs = s.d.outputs;
        CHECK_RESULT(rad_baker_runtime_create(&other.d, &o, R, NULL, &ctx, &rt), RAD_ERROR_INVALID_ARGUMENT);
    }
    CHECK(rt == NULL && st.live_bytes == 0);
    CHECK_OK(rad_baker_runtime_create(&s.d, &o, R, NULL, &ctx, &rt));
    if (!rt) goto done;
    before = (float *)malloc(sizeof(float) * 3 * R->vertex_count);
    if (!before) goto done;
    memcpy(before, R->vertex, sizeof(float) * 3 * R->vertex_count);
    CHECK_RESULT(rad_baker_runtime_update(NULL, &s.bl.light, 1, 0.0, &f), RAD_ERROR_INVALID_ARGUMENT);
    /* wrong count */
    two[0] = two[1] = s.bl.light;
    rtm_expect(rt, &lg, two, 2, 0.0, RAD_ERROR_SIZE_MISMATCH, "2 lights, the bake had 1");
    rtm_expect(rt, &lg, NULL, 0, 0.0, RAD_ERROR_SIZE_MISMATCH, "0 lights");
    rtm_expect(rt, &lg, NULL, 1, 0.0, RAD_ERROR_INVALID_ARGUMENT, "NULL");
    /* NaN and infinite fields, a negative colour, a bad budget */
    l = s.bl.light;
    l.position[1] = (float)NAN;
    rtm_expect(rt, &lg, &l, 1, 0.0, RAD_ERROR_NON_FINITE, "light 0 has a non-finite position");
    l = s.bl.light;
    l.color[2] = (float)INFINITY;
    rtm_expect(rt, &lg, &l, 1, 0.0, RAD_ERROR_NON_FINITE, "non-finite color");
    l = s.bl.light;
    l.min_distance = (float)NAN;
    rtm_expect(rt, &lg, &l, 1, 0.0, RAD_ERROR_NON_FINITE, "min_distance");
    l = s.bl.light;
    l.color[0] = -1.0f;
    rtm_expect(rt, &lg, &l, 1, 0.0, RAD_ERROR_NEGATIVE_EMISSION, "negative colour");
    rtm_expect(rt, &lg, &s.bl.light, 1, -1.0, RAD_ERROR_INVALID_ARGUMENT, "budget_ms");
    rtm_expect(rt, &lg, &s.bl.light, 1, (double)NAN, RAD_ERROR_INVALID_ARGUMENT, "budget_ms");
    /* a bad light type: the lights' own check */
    l = s.bl.light;
    l.type = (rad_light_type)99;
    rtm_expect(rt, &lg, &l, 1, 0.0, RAD_ERROR_INVALID_ARGUMENT, NULL);
    /* nothing changed: the baked light is still at rest, the outputs the bake's */
    CHECK_OK(rad_baker_runtime_update(rt, &s.bl.light, 1, 0.0, &f));
    CHECK(f.phase == RAD_BAKER_RUNTIME_CONVERGED && f.frame == 1);
    CHECK(memcmp(f.vertex, before, sizeof(float) * 3 * R->vertex_count) == 0);
done:
    free(before);
    rad_baker_runtime_destroy(rt);
    CHECK(st.live_bytes == 0);
    rad_baker_result_destroy(R);
}

static const rad_test_case tests_runtime[] = {
    { "runtime_zero_move", rtm_test_zero_move },
    { "runtime_moved", rtm_test_moved },
    { "runtime_budget", rtm_test_budget },
    { "runtime_deterministic", rtm_test_deterministic },
    { "runtime_bad_input", rtm_test_bad_input },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_runtime)

/* test_stochastic.c - stochastic radiosity (rad_solve_stochastic): the mean over seeds against
   the direct solve, the variance against the ray count, the closed furnace, determinism across
   thread counts, and bad input. Everything static and prefixed st_. */
#include "fixtures.h"

/* A closed unit cube seen from inside, one material per face (so the light changes colour from
   face to face); no occluders, so the analytic form factors (relative error below 1e-4) are
   the exact system the stochastic estimators sample. */
typedef struct st_box {
    float pos[6 * 12];
    uint32_t mats[6 * 2];
    rad_mesh_desc meshes[6];
    rad_material mat[6];
    rad_scene_desc desc;
    rad_scene *scene;
    rad_patches *P;
    rad_bvh *bvh;
    rad_raycaster rc;
    float *E;
} st_box;

/* albedo: 6 RGB triples (NULL: a palette of six); emit: E on the patches of face 2 (the floor,
   y = 0) only, else E = 1 everywhere */
static int st_box_build(st_box *b, const float *albedo, float max_edge, int floor_source)
{
    static const float palette[18] = { 0.7f, 0.7f, 0.7f, 0.63f, 0.065f, 0.05f, 0.5f, 0.5f, 0.5f,
                                       0.14f, 0.45f, 0.091f, 0.8f, 0.8f, 0.8f, 0.3f, 0.5f, 0.9f };
    rad_patch_options po;
    uint32_t i;
    int f, k;
    memset(b, 0, sizeof(*b));
    if (!albedo) albedo = palette;
    fx_cube_faces(b->pos);
    for (f = 0; f < 6; ++f) {
        for (k = 0; k < 3; ++k) b->mat[f].albedo[k] = albedo[3 * f + k];
        b->meshes[f].positions = b->pos + 12 * f;
        b->meshes[f].vertex_count = 4;
        b->meshes[f].indices = ff_quad_indices;
        b->meshes[f].triangle_count = 2;
        b->meshes[f].material = (uint32_t)f;
    }
    b->desc.meshes = b->meshes;
    b->desc.mesh_count = 6;
    b->desc.materials = b->mat;
    b->desc.material_count = 6;
    if (rad_scene_create(&b->desc, NULL, &b->scene) != RAD_SUCCESS) return 0;
    rad_patch_options_default(&po);
    po.max_edge = max_edge;
    if (rad_patches_create(b->scene, &po, NULL, &b->P) != RAD_SUCCESS) return 0;
    if (rad_bvh_create(b->scene, NULL, &b->bvh) != RAD_SUCCESS) return 0;
    rad_bvh_raycaster(b->bvh, &b->rc);
    b->E = (float *)calloc(3 * (size_t)b->P->count, sizeof(float));
    if (!b->E) return 0;
    for (i = 0; i < b->P->count; ++i) {
        const float *n = b->P->patches[i].normal;
        int on_floor = n[1] > 0.9f;
        for (k = 0; k < 3; ++k) b->E[3 * i + k] = !floor_source ? 1.0f : on_floor ? (k == 0 ? 3.0f : k == 1 ? 2.0f : 1.0f) : 0.0f;
    }
    return 1;
}

static void st_box_free(st_box *b)
{
    free(b->E);
    rad_bvh_destroy(b->bvh);
    rad_patches_destroy(b->P);
    rad_scene_destroy(b->scene);
}

/* the direct solve (LU) of the same patches with analytic, unoccluded form factors */
static int st_reference(const st_box *b, float *B)
{
    rad_form_factor_options fo;
    rad_form_factors *ff = NULL;
    rad_solve_options so;
    rad_system sys;
    rad_result r;
    rad_form_factor_options_default(&fo);
    fo.skip_visibility = 1;
    if (rad_form_factors_dense(b->P, NULL, &fo, NULL, &ff) != RAD_SUCCESS) return 0;
    rad_system_init(&sys, &ff->matrix, b->P, b->E);
    rad_solve_options_default(&so);
    so.output = RAD_OUTPUT_TOTAL;
    r = rad_solve_direct(&sys, &so, B, NULL);
    rad_form_factors_destroy(ff);
    return r == RAD_SUCCESS;
}

/* S runs (seeds 1..S): per-value mean and unbiased variance, and the total of the variances */
static double st_runs(const st_box *b, const rad_stochastic_options *base, uint32_t S, double *mean, double *var)
{
    size_t n3 = 3 * (size_t)b->P->count, i;
    float *B = (float *)malloc(n3 * sizeof(float));
    double total = 0.0;
    uint32_t s;
    if (!B) return -1.0;
    for (i = 0; i < n3; ++i) mean[i] = var[i] = 0.0;
    for (s = 0; s < S; ++s) {
        rad_stochastic_options o = *base;
        o.seed = s + 1u;
        o.output = RAD_OUTPUT_TOTAL;
        CHECK_OK(rad_solve_stochastic(b->P, &b->rc, b->E, &o, B, NULL, NULL));
        for (i = 0; i < n3; ++i) { /* Welford */
            double d = (double)B[i] - mean[i];
            mean[i] += d / (double)(s + 1u);
            var[i] += d * ((double)B[i] - mean[i]);
        }
    }
    for (i = 0; i < n3; ++i) { var[i] /= (double)(S - 1u); total += var[i]; }
    free(B);
    return total;
}

/* The mean of S independent runs against the direct solve: t = (mean - ref) / (sd / sqrt(S))
   has a Student t distribution with S - 1 degrees of freedom when the estimator is unbiased.
   With S = 16, P(|t| > 6.5) is about 1e-5 per value, so over the ~300 values the bound fails
   by chance about once in 300 (and the seeds are fixed: it either always passes or never);
   a bias of a few standard errors shows in the mean of t^2 (about 15/13 without bias). The
   form-factor error of the reference (1e-4 relative) is far below the standard errors. */
static void st_mean_check(rad_stochastic_method method)
{
    st_box b;
    rad_stochastic_options o;
    uint32_t S = 16, i;
    size_t n3;
    float *ref = NULL;
    double *mean = NULL, *var = NULL, tmax = 0.0, t2 = 0.0;
    if (!st_box_build(&b, NULL, 0.5f, 1)) { CHECK(0); st_box_free(&b); return; }
    n3 = 3 * (size_t)b.P->count;
    ref = (float *)malloc(n3 * sizeof(float));
    mean = (double *)malloc(n3 * sizeof(double));
    var = (double *)malloc(n3 * sizeof(double));
    if (!ref || !mean || !var || !st_reference(&b, ref)) { CHECK(0); goto done; }
    rad_stochastic_options_default(&o);
    o.method = method;
    o.rays = rad_test_quick() ? 2000u : 16000u;
    st_runs(&b, &o, S, mean, var);
    for (i = 0; i < n3; ++i) {
        double se = sqrt(var[i] / (double)S), t;
        CHECK(se > 0.0);
        if (!(se > 0.0)) break;
        t = (mean[i] - (double)ref[i]) / se;
        if (fabs(t) > tmax) tmax = fabs(t);
        t2 += t * t;
    }
    t2 /= (double)n3;
    printf("    %s, %u patches, %u seeds: max |t| %.2f, mean t^2 %.2f\n", method == RAD_STOCHASTIC_WALK ? "walk" : "Jacobi",
           b.P->count, S, tmax, t2);
    CHECK(tmax < 6.5);
    CHECK(t2 > 0.5 && t2 < 2.0);
done:
    free(ref);
    free(mean);
    free(var);
    st_box_free(&b);
}

static void st_test_mean_jacobi(void) { st_mean_check(RAD_STOCHASTIC_JACOBI); }
static void st_test_mean_walk(void) { st_mean_check(RAD_STOCHASTIC_WALK); }

/* Variance against samples: 4x the rays should give 1/4 of the variance (summed over every
   patch and channel). The ratio of two sums of sample variances from S = 16 runs each has a
   spread of a few tens of percent; the bounds [2.8, 5.7] leave that room while a 1/sqrt(rays)
   or a constant noise floor (ratio 2 or 1) fails. */
static void st_variance_check(rad_stochastic_method method)
{
    st_box b;
    rad_stochastic_options o;
    uint32_t S = 16;
    size_t n3;
    double *mean = NULL, *var = NULL, v1, v4;
    if (!st_box_build(&b, NULL, 0.5f, 1)) { CHECK(0); st_box_free(&b); return; }
    n3 = 3 * (size_t)b.P->count;
    mean = (double *)malloc(n3 * sizeof(double));
    var = (double *)malloc(n3 * sizeof(double));
    if (!mean || !var) { CHECK(0); goto done; }
    rad_stochastic_options_default(&o);
    o.method = method;
    o.rays = rad_test_quick() ? 2000u : 5000u;
    v1 = st_runs(&b, &o, S, mean, var);
    o.rays *= 4u;
    v4 = st_runs(&b, &o, S, mean, var);
    printf("    %s: variance %.4g at %u rays, %.4g at 4x: ratio %.2f\n", method == RAD_STOCHASTIC_WALK ? "walk" : "Jacobi", v1,
           o.rays / 4u, v4, v1 / v4);
    CHECK(v4 > 0.0 && v1 / v4 > 2.8 && v1 / v4 < 5.7);
done:
    free(mean);
    free(var);
    st_box_free(&b);
}

static void st_test_variance_jacobi(void) { st_variance_check(RAD_STOCHASTIC_JACOBI); }
static void st_test_variance_walk(void) { st_variance_check(RAD_STOCHASTIC_WALK); }

/* The closed furnace: E = 1 everywhere, albedo rho per channel on every face, so B = 1 / (1 - rho)
   on every patch. Every ray lands in a closed box, so the shooting Jacobi conserves power
   exactly: the area-weighted mean of B is the closed form up to the truncation (unshot power
   below 1e-4 of the source, at most 1e-4 / (1 - rho) relative); each patch is a Monte Carlo
   estimate within a few percent. The walk's mean is within its noise. */
static void st_test_furnace(void)
{
    static const float a1[3] = { 0.5f, 0.7f, 0.9f };
    float albedo[18], *B = NULL;
    st_box b;
    rad_stochastic_options o;
    rad_stochastic_stats st;
    uint32_t i, m;
    int k;
    for (i = 0; i < 6; ++i)
        for (k = 0; k < 3; ++k) albedo[3 * i + k] = a1[k];
    if (!st_box_build(&b, albedo, 0.5f, 0)) { CHECK(0); st_box_free(&b); return; }
    B = (float *)malloc(3 * sizeof(float) * b.P->count);
    if (!B) { CHECK(0); st_box_free(&b); return; }
    for (m = 0; m < 2; ++m) {
        double area = 0.0, sum[3] = { 0.0, 0.0, 0.0 }, worst = 0.0;
        rad_stochastic_options_default(&o);
        o.method = m ? RAD_STOCHASTIC_WALK : RAD_STOCHASTIC_JACOBI;
        o.output = RAD_OUTPUT_TOTAL;
        o.rays = rad_test_quick() ? 20000u : 60000u;
        CHECK_OK(rad_solve_stochastic(b.P, &b.rc, b.E, &o, B, &st, NULL));
        for (i = 0; i < b.P->count; ++i) {
            area += b.P->areas[i];
            for (k = 0; k < 3; ++k) {
                double want = 1.0 / (1.0 - a1[k]), rel = fabs((double)B[3 * i + k] / want - 1.0);
                sum[k] += b.P->areas[i] * (double)B[3 * i + k];
                if (rel > worst) worst = rel;
            }
        }
        printf("    %s furnace: %u patches, %llu rays, %u iterations, unshot %.2g; mean B %.5f %.5f %.5f (closed form %.5f "
               "%.5f %.5f), worst patch %.3f relative\n", m ? "walk" : "Jacobi", b.P->count, (unsigned long long)st.rays_cast,
               st.iterations, st.unshot, sum[0] / area, sum[1] / area, sum[2] / area, 1.0 / (1.0 - a1[0]),
               1.0 / (1.0 - a1[1]), 1.0 / (1.0 - a1[2]), worst);
        for (k = 0; k < 3; ++k) CHECK_REL(sum[k] / area, 1.0 / (1.0 - a1[k]), m ? 0.01 : 1e-3);
        CHECK(worst < (m ? 0.15 : 0.1));
        if (!m) CHECK(st.unshot < 1e-4 && st.iterations > 50 && st.rays_cast > o.rays);
    }
    free(B);
    st_box_free(&b);
}

/* tasks in reverse order on the calling thread: another schedule than the default */
static int st_calls;
static int st_stop_after_two(void *user, uint32_t iteration, uint64_t rays, const float *B)
{
    (void)user; (void)rays; (void)B;
    ++st_calls;
    return iteration >= 2;
}
static int st_cancel(void *user, float fraction) { (void)user; (void)fraction; return 1; }

/* Same bits for any task count and order (each ray's numbers come from its index; deposits
   are summed in ray order); another seed gives other bits. */
static void st_test_threads(void)
{
    st_box b;
    rad_stochastic_options o;
    rad_context c1, c2;
    float *B1 = NULL, *B2 = NULL;
    uint32_t m;
    size_t bytes;
    if (!st_box_build(&b, NULL, 0.5f, 1)) { CHECK(0); st_box_free(&b); return; }
    bytes = 3 * sizeof(float) * b.P->count;
    B1 = (float *)malloc(bytes);
    B2 = (float *)malloc(bytes);
    if (!B1 || !B2) { CHECK(0); goto done; }
    memset(&c1, 0, sizeof(c1));
    memset(&c2, 0, sizeof(c2));
    c1.task_count = 1;
    c2.task_count = 13;
    c2.parallel_for = fx_reverse_for;
    for (m = 0; m < 2; ++m) {
        rad_stochastic_options_default(&o);
        o.method = m ? RAD_STOCHASTIC_WALK : RAD_STOCHASTIC_JACOBI;
        o.rays = 3000;  /* several chunks of 1024 rays */
        o.iterations = m ? 2u : 0u;
        o.regular_iterations = m ? 0u : 2u;
        o.seed = 7;
        CHECK_OK(rad_solve_stochastic(b.P, &b.rc, b.E, &o, B1, NULL, &c1));
        CHECK_OK(rad_solve_stochastic(b.P, &b.rc, b.E, &o, B2, NULL, &c2));
        CHECK(memcmp(B1, B2, bytes) == 0);
        CHECK_OK(rad_solve_stochastic(b.P, &b.rc, b.E, &o, B2, NULL, NULL)); /* the default (OpenMP when built with it) */
        CHECK(memcmp(B1, B2, bytes) == 0);
        o.seed = 8;
        CHECK_OK(rad_solve_stochastic(b.P, &b.rc, b.E, &o, B2, NULL, &c2));
        CHECK(memcmp(B1, B2, bytes) != 0);
    }
done:
    free(B1);
    free(B2);
    st_box_free(&b);
}

static void st_test_errors(void)
{
    st_box b;
    rad_stochastic_options o;
    rad_stochastic_stats st;
    rad_context ctx;
    float *B = NULL, keep;
    uint32_t i;
    if (!st_box_build(&b, NULL, 0.5f, 1)) { CHECK(0); st_box_free(&b); return; }
    B = (float *)malloc(3 * sizeof(float) * b.P->count);
    if (!B) { CHECK(0); st_box_free(&b); return; }
    rad_stochastic_options_default(&o);
    o.rays = 500;
    CHECK_RESULT(rad_solve_stochastic(NULL, &b.rc, b.E, &o, B, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_solve_stochastic(b.P, NULL, b.E, &o, B, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_solve_stochastic(b.P, &b.rc, NULL, &o, B, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_solve_stochastic(b.P, &b.rc, b.E, &o, NULL, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    o.method = (rad_stochastic_method)7;
    CHECK_RESULT(rad_solve_stochastic(b.P, &b.rc, b.E, &o, B, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    rad_stochastic_options_default(&o);
    o.output = (rad_output)5;
    CHECK_RESULT(rad_solve_stochastic(b.P, &b.rc, b.E, &o, B, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    rad_stochastic_options_default(&o);
    o.ray_epsilon = 0.5f;
    CHECK_RESULT(rad_solve_stochastic(b.P, &b.rc, b.E, &o, B, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    o.ray_epsilon = -1e-5f;
    CHECK_RESULT(rad_solve_stochastic(b.P, &b.rc, b.E, &o, B, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    rad_stochastic_options_default(&o);
    o.tolerance = -1.0;
    CHECK_RESULT(rad_solve_stochastic(b.P, &b.rc, b.E, &o, B, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    o.tolerance = HUGE_VAL;
    CHECK_RESULT(rad_solve_stochastic(b.P, &b.rc, b.E, &o, B, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    rad_stochastic_options_default(&o);
    o.method = RAD_STOCHASTIC_WALK;
    o.regular_iterations = 3;
    CHECK_RESULT(rad_solve_stochastic(b.P, &b.rc, b.E, &o, B, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    rad_stochastic_options_default(&o);
    o.rays = 500;
    keep = b.E[4];
    b.E[4] = -1.0f;
    CHECK_RESULT(rad_solve_stochastic(b.P, &b.rc, b.E, &o, B, NULL, NULL), RAD_ERROR_NEGATIVE_EMISSION);
    b.E[4] = (float)HUGE_VAL - (float)HUGE_VAL;
    CHECK_RESULT(rad_solve_stochastic(b.P, &b.rc, b.E, &o, B, NULL, NULL), RAD_ERROR_NON_FINITE);
    b.E[4] = keep;
    /* the callback stops after two iterations: success, with that estimate */
    st_calls = 0;
    o.on_iteration = st_stop_after_two;
    CHECK_OK(rad_solve_stochastic(b.P, &b.rc, b.E, &o, B, &st, NULL));
    CHECK(st_calls == 2 && st.iterations == 2 && st.unshot > 0.01);
    o.on_iteration = NULL;
    memset(&ctx, 0, sizeof(ctx));
    ctx.progress = st_cancel;
    CHECK_RESULT(rad_solve_stochastic(b.P, &b.rc, b.E, &o, B, NULL, &ctx), RAD_ERROR_CANCELLED);
    /* options NULL: the defaults (Jacobi, 64 rays per patch in the first iteration) */
    CHECK_OK(rad_solve_stochastic(b.P, &b.rc, b.E, NULL, B, &st, NULL));
    CHECK(st.rays_cast >= 64u * b.P->count && st.iterations > 5 && st.unshot < 1e-4);
    /* no source: no light, no rays */
    for (i = 0; i < 3 * b.P->count; ++i) b.E[i] = 0.0f;
    o.output = RAD_OUTPUT_TOTAL;
    CHECK_OK(rad_solve_stochastic(b.P, &b.rc, b.E, &o, B, &st, NULL));
    CHECK(st.rays_cast == 0 && so_max_abs(B, b.P->count) == 0.0);
    free(B);
    st_box_free(&b);
}

/* allocation failure at every allocation (the counting allocator of test_scene.c): success or
   OUT_OF_MEMORY, the failure reported, nothing leaked or overrun; both estimators */
static void st_test_alloc_failure(void)
{
    st_box b;
    rad_stochastic_options o;
    rad_context ctx;
    sc_alloc_state st;
    float *B = NULL;
    long n, total;
    uint32_t m;
    if (!st_box_build(&b, NULL, 0.5f, 1)) { CHECK(0); st_box_free(&b); return; }
    B = (float *)malloc(3 * sizeof(float) * b.P->count);
    if (!B) { CHECK(0); st_box_free(&b); return; }
    memset(&ctx, 0, sizeof(ctx));
    ctx.allocator.alloc = sc_alloc_fn;
    ctx.allocator.free = sc_free_fn;
    ctx.allocator.user = &st;
    for (m = 0; m < 2; ++m) {
        rad_stochastic_options_default(&o);
        o.method = m ? RAD_STOCHASTIC_WALK : RAD_STOCHASTIC_JACOBI;
        o.rays = 300;
        o.iterations = m ? 1u : 3u;
        for (n = 0, total = 1; n <= total; ++n) {
            rad_result r;
            memset(&st, 0, sizeof(st));
            st.fail_at = n;
            r = rad_solve_stochastic(b.P, &b.rc, b.E, &o, B, NULL, &ctx);
            CHECK(r == RAD_SUCCESS || r == RAD_ERROR_OUT_OF_MEMORY);
            if (n > 0 && n <= st.calls) CHECK(r == RAD_ERROR_OUT_OF_MEMORY);
            CHECK(st.allocs == st.frees && st.live_bytes == 0 && st.corrupt == 0);
            if (n == 0) total = st.calls;
        }
        CHECK(total >= 10);
    }
    free(B);
    st_box_free(&b);
}

static const rad_test_case tests_stochastic[] = {
    { "stochastic_mean_jacobi", st_test_mean_jacobi },
    { "stochastic_mean_walk", st_test_mean_walk },
    { "stochastic_variance_jacobi", st_test_variance_jacobi },
    { "stochastic_variance_walk", st_test_variance_walk },
    { "stochastic_furnace", st_test_furnace },
    { "stochastic_threads", st_test_threads },
    { "stochastic_errors", st_test_errors },
    { "stochastic_alloc_failure", st_test_alloc_failure },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_stochastic)

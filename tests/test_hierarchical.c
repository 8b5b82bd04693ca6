/* test_hierarchical.c - hierarchical radiosity (>>api_hierarchical; Hanrahan, Salzman and
   Aupperle 1991): a closed furnace against its closed form B = E / (1 - rho), convergence to
   the classic solution on fine patches as the tolerance shrinks, links growing about linearly
   in the elements, the source callback, the smooth lookup, bad options and allocation
   failures. Uses the fixtures' quads (ff_quad, ff_cube_quads, ff_mesh_quad), the counting
   allocator and the log sink (sc_alloc_*, sc_log_*); its names are prefixed hr_. */
#include "fixtures.h"


typedef struct hr_world {
    rad_scene *scene;
    rad_bvh *bvh;
    rad_raycaster rc;
} hr_world;

static int hr_world_make(const rad_scene_desc *d, hr_world *w)
{
    memset(w, 0, sizeof(*w));
    CHECK_OK(rad_scene_create(d, NULL, &w->scene));
    if (!w->scene) return 0;
    CHECK_OK(rad_bvh_create(w->scene, NULL, &w->bvh));
    if (!w->bvh) { rad_scene_destroy(w->scene); return 0; }
    rad_bvh_raycaster(w->bvh, &w->rc);
    return 1;
}

static void hr_world_free(hr_world *w)
{
    rad_bvh_destroy(w->bvh);
    rad_scene_destroy(w->scene);
    memset(w, 0, sizeof(*w));
}

/* a solved hierarchy of w at tolerance tol (NULL on failure, counted) */
static rad_hierarchical *hr_solve(const hr_world *w, double tol, rad_hierarchical_stats *st)
{
    rad_hierarchical_options o;
    rad_hierarchical *h = NULL;
    rad_hierarchical_options_default(&o);
    o.tolerance = tol;
    CHECK_OK(rad_hierarchical_create(w->scene, &w->rc, &o, NULL, &h));
    if (!h) return NULL;
    CHECK_OK(rad_hierarchical_solve(h, NULL));
    if (st) rad_hierarchical_get_stats(h, st);
    return h;
}

/* 1. The closed unit cube, every face albedo rho and emitting E: every point receives the
   whole of its hemisphere from surfaces of radiosity B, so B = E + rho B, B = E / (1 - rho).
   The links of each leaf (its ancestors' included) cover the hemisphere once, but a link's F
   is the mean over its receiver's points, not the leaf's: the leaves' row sums scatter around
   1 (the method's error, bounded per link by the tolerance), and the scatter falls as the
   tolerance shrinks; the mean over the surface holds the closed form. */
static double hr_furnace(double tol, double *mean_abs, double *mean_B)
{
    static const rad_material mat = { { 0.5f, 0.5f, 0.5f }, { 1.0f, 0.5f, 0.25f }, 0 };
    ff_quad q[6];
    rad_mesh_desc meshes[6];
    rad_scene_desc d;
    hr_world w;
    rad_hierarchical *h;
    rad_hierarchical_stats st;
    uint32_t i, k;
    float *B, *C;
    double worst = 1e9, area = 0.0;
    int f;
    ff_cube_quads(q);
    for (f = 0; f < 6; ++f) ff_mesh_quad(&meshes[f], &q[f]);
    memset(&d, 0, sizeof(d));
    d.meshes = meshes;
    d.mesh_count = 6;
    d.materials = &mat;
    d.material_count = 1;
    *mean_abs = *mean_B = 1e9;
    if (!hr_world_make(&d, &w)) return worst;
    h = hr_solve(&w, tol, &st);
    if (!h) { hr_world_free(&w); return worst; }
    CHECK(st.leaves > 12u); /* it did refine */
    CHECK(st.rays_cast > 0u && st.kernel_evaluations >= st.rays_cast);
    B = (float *)malloc(sizeof(float) * 3 * st.leaves);
    C = (float *)malloc(sizeof(float) * 9 * st.leaves);
    if (B && C) {
        CHECK_OK(rad_hierarchical_leaves(h, 0, st.leaves, C, NULL, B, NULL));
        worst = *mean_abs = *mean_B = 0.0;
        for (i = 0; i < st.leaves; ++i) {
            float a[3], b[3], n[3];
            double A;
            a[0] = C[9 * i + 3] - C[9 * i]; a[1] = C[9 * i + 4] - C[9 * i + 1]; a[2] = C[9 * i + 5] - C[9 * i + 2];
            b[0] = C[9 * i + 6] - C[9 * i]; b[1] = C[9 * i + 7] - C[9 * i + 1]; b[2] = C[9 * i + 8] - C[9 * i + 2];
            n[0] = a[1] * b[2] - a[2] * b[1]; n[1] = a[2] * b[0] - a[0] * b[2]; n[2] = a[0] * b[1] - a[1] * b[0];
            A = 0.5 * sqrt((double)(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]));
            area += A;
            for (k = 0; k < 3; ++k) {
                double exact = FF_PI * mat.emission[k] / (1.0 - 0.5), e = (B[3 * i + k] - exact) / exact;
                if (fabs(e) > worst) worst = fabs(e);
                *mean_abs += A * fabs(e) / 3.0;
                *mean_B += A * e / 3.0;
            }
        }
        CHECK_NEAR(area, 6.0, 1e-4); /* the leaves tile the cube */
        *mean_abs /= area;
        *mean_B /= area;
    }
    printf("    furnace tolerance %.0e: %u leaves, %llu links; |B - E/(1-rho)| / B: worst %.3f, mean %.4f; "
           "mean signed %.5f\n", tol, st.leaves, (unsigned long long)st.links, worst, *mean_abs, *mean_B);
    free(B);
    free(C);
    rad_hierarchical_destroy(h);
    hr_world_free(&w);
    return worst;
}

static void hr_test_furnace(void)
{
    double m1, s1, m2, s2, w1 = hr_furnace(1e-2, &m1, &s1), w2 = hr_furnace(1e-4, &m2, &s2);
    CHECK(w2 < w1);
    CHECK(m2 < m1);
    CHECK(m2 < 0.03);
    CHECK(fabs(s2) < 2e-3);
}

/* The classic solution on fine patches (RAD_SOURCE_EMISSION, direct solve): the reference. */
typedef struct hr_classic {
    rad_patches *P;
    float *B;
} hr_classic;

static int hr_classic_make(const hr_world *w, uint32_t patches, hr_classic *c)
{
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_form_factors *ff = NULL;
    rad_solve_options so;
    rad_system sys;
    float *E;
    int ok = 0;
    memset(c, 0, sizeof(*c));
    rad_patch_options_default(&po);
    po.target_count = patches;
    CHECK_OK(rad_patches_create(w->scene, &po, NULL, &c->P));
    if (!c->P) return 0;
    rad_form_factor_options_default(&fo);
    fo.samples = 4;
    CHECK_OK(rad_form_factors_dense(c->P, &w->rc, &fo, NULL, &ff));
    E = (float *)malloc(sizeof(float) * 3 * c->P->count);
    c->B = (float *)malloc(sizeof(float) * 3 * c->P->count);
    if (ff && E && c->B) {
        CHECK_OK(rad_sources(c->P, RAD_SOURCE_EMISSION, NULL, E));
        rad_system_init(&sys, &ff->matrix, c->P, E);
        rad_solve_options_default(&so);
        so.output = RAD_OUTPUT_TOTAL;
        so.tolerance = 1e-7;
        CHECK_OK(rad_solve_gauss_seidel(&sys, &so, c->B, NULL, NULL));
        ok = 1;
    }
    free(E);
    rad_form_factors_destroy(ff);
    return ok;
}

/* Mean |B_h - B_classic| over the non-emitting surfaces (area weighted, a lattice of points per
   scene triangle, each compared with the classic patch it falls in), over the mean B there. */
static double hr_error(const hr_world *w, const hr_classic *c, const rad_hierarchical *h, int smooth)
{
    const rad_scene *s = w->scene;
    uint32_t t, i, j, n = 8;
    double num = 0.0, den = 0.0;
    for (t = 0; t < s->triangle_count; ++t) {
        const rad_material *m = &s->materials_table[s->materials[t]];
        if (m->emission[0] + m->emission[1] + m->emission[2] > 0.0f) continue;
        for (j = 0; j < n; ++j)
            for (i = 0; i + j < n; ++i) {
                float bc[2], wts[3], out[3];
                uint32_t p, k;
                bc[0] = ((float)i + 1.0f / 3.0f) / (float)n;
                bc[1] = ((float)j + 1.0f / 3.0f) / (float)n;
                p = rad_patches_locate(c->P, t, bc[0], bc[1], wts);
                if (p == RAD_NONE || rad_hierarchical_lookup(h, RAD_HIERARCHICAL_RADIOSITY, smooth, &t, bc, 1, out) != RAD_SUCCESS)
                    return 1e9;
                for (k = 0; k < 3; ++k) {
                    num += (double)s->areas[t] * fabs((double)out[k] - (double)c->B[3 * p + k]);
                    den += (double)s->areas[t] * (double)c->B[3 * p + k];
                }
            }
    }
    return den > 0.0 ? num / den : 1e9;
}

/* 2. Convergence: against the classic solution on fine patches (RAD_SOURCE_EMISSION, Gauss-
   Seidel), the error falls as the tolerance shrinks. The reference has its own discretisation
   error (~3% on the floor at 1000 patches), which bounds what the last step can show.
   3. The links grow about linearly in the elements: far below the N^2 of the classic matrix,
   and with a growth exponent well under 2 from one tolerance to the next. */
static void hr_test_converges(void)
{
    static const double tol[3] = { 1e-2, 1e-3, 1e-4 };
    rad_scene_desc d;
    hr_world w;
    hr_classic c;
    double err[3], smooth[3], leaves[3], links[3];
    int i;
    rad_cornell_box(&d, NULL);
    if (!hr_world_make(&d, &w)) return;
    if (!hr_classic_make(&w, rad_test_quick() ? 1500u : 3000u, &c)) { hr_world_free(&w); return; }
    for (i = 0; i < 3; ++i) {
        rad_hierarchical_stats st;
        rad_hierarchical *h = hr_solve(&w, tol[i], &st);
        err[i] = h ? hr_error(&w, &c, h, 0) : 1e9;
        smooth[i] = h ? hr_error(&w, &c, h, 1) : 1e9;
        leaves[i] = (double)st.leaves;
        links[i] = (double)st.links;
        printf("    tolerance %.0e: N = %u leaves, %llu links (%.1f N, %.5f N^2), %llu kernels, %llu rays; "
               "mean |B - classic %u| / B = %.4f (smooth %.4f)\n", tol[i], st.leaves, (unsigned long long)st.links,
               links[i] / leaves[i], links[i] / (leaves[i] * leaves[i]), (unsigned long long)st.kernel_evaluations,
               (unsigned long long)st.rays_cast, c.P->count, err[i], smooth[i]);
        rad_hierarchical_destroy(h);
    }
    CHECK(err[1] < err[0]);
    CHECK(err[2] < err[1]);
    CHECK(err[2] < 0.1);
    CHECK(smooth[2] < smooth[0]);
    for (i = 1; i < 3; ++i) {
        double exponent = log(links[i] / links[i - 1]) / log(leaves[i] / leaves[i - 1]);
        printf("    links ~ N^%.2f from tolerance %.0e to %.0e\n", exponent, tol[i - 1], tol[i]);
        CHECK(exponent < 1.75);
        CHECK(links[i] < leaves[i] * leaves[i] / 50.0);
    }
    rad_patches_destroy(c.P);
    free(c.B);
    hr_world_free(&w);
}

/* 4. The source callback: pi L of each element's material through the callback gives the same
   bits as the default; a negative or non-finite value is refused. Lookups: the leaf value at
   points, the smooth value between the leaves around it. */
typedef struct hr_source_state {
    const rad_scene *scene;
    float bad;   /* 0: correct values; else returned for every point */
    uint32_t calls, points;
} hr_source_state;

static rad_result hr_source(void *user, const float *points, const float *normals, const uint32_t *triangles,
                            const float *albedos, uint32_t count, float *out_E)
{
    hr_source_state *s = (hr_source_state *)user;
    uint32_t i, k;
    (void)points;
    (void)normals;
    (void)albedos;
    s->calls++;
    s->points += count;
    for (i = 0; i < count; ++i)
        for (k = 0; k < 3; ++k)
            out_E[3 * i + k] = s->bad != 0.0f ? s->bad
                                              : (float)FF_PI * s->scene->materials_table[s->scene->materials[triangles[i]]].emission[k];
    return RAD_SUCCESS;
}

static void hr_test_source_lookup(void)
{
    rad_scene_desc d;
    hr_world w;
    rad_hierarchical_options o;
    rad_hierarchical *h0 = NULL, *h1 = NULL;
    rad_hierarchical_stats s0, s1;
    hr_source_state ss;
    float *B0, *B1;
    rad_cornell_box(&d, NULL);
    if (!hr_world_make(&d, &w)) return;
    rad_hierarchical_options_default(&o);
    o.tolerance = 3e-3;
    CHECK_OK(rad_hierarchical_create(w.scene, &w.rc, &o, NULL, &h0));
    CHECK_OK(rad_hierarchical_solve(h0, NULL));
    memset(&ss, 0, sizeof(ss));
    ss.scene = w.scene;
    o.source = hr_source;
    o.source_user = &ss;
    CHECK_OK(rad_hierarchical_create(w.scene, &w.rc, &o, NULL, &h1));
    CHECK_OK(rad_hierarchical_solve(h1, NULL));
    rad_hierarchical_get_stats(h0, &s0);
    rad_hierarchical_get_stats(h1, &s1);
    CHECK(s0.leaves == s1.leaves && s0.links == s1.links && s0.rays_cast == s1.rays_cast);
    CHECK(ss.points == s1.elements && ss.calls >= 2u); /* once per element: the roots, then each round's children */
    B0 = (float *)malloc(sizeof(float) * 3 * s0.leaves);
    B1 = (float *)malloc(sizeof(float) * 3 * s0.leaves);
    if (B0 && B1 && s0.leaves == s1.leaves) {
        uint32_t i, t, n = 0;
        CHECK_OK(rad_hierarchical_leaves(h0, 0, s0.leaves, NULL, NULL, B0, NULL));
        CHECK_OK(rad_hierarchical_leaves(h1, 0, s1.leaves, NULL, NULL, B1, NULL));
        CHECK(memcmp(B0, B1, sizeof(float) * 3 * s0.leaves) == 0);
        /* the leaf value at each leaf's centroid is the leaf's B; smooth values stay within the
           range of the leaves' values on that triangle's plane */
        for (i = 0; i < s0.leaves; i += 7) {
            float C[9], bc[2], v[3], sm[3], ax[3], ay[3], px[3], det, bmax = 0.0f;
            uint32_t j, k;
            CHECK_OK(rad_hierarchical_leaves(h0, i, 1, C, &t, NULL, NULL));
            {
                const float *T = w.scene->positions + 9 * (size_t)t;
                for (k = 0; k < 3; ++k) {
                    ax[k] = T[3 + k] - T[k];
                    ay[k] = T[6 + k] - T[k];
                    px[k] = (C[k] + C[3 + k] + C[6 + k]) / 3.0f - T[k];
                }
                /* barycentrics of the centroid by the normal equations of the triangle's edges */
                {
                    float aa = ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2], bb = ay[0] * ay[0] + ay[1] * ay[1] + ay[2] * ay[2];
                    float ab = ax[0] * ay[0] + ax[1] * ay[1] + ax[2] * ay[2];
                    float pa = px[0] * ax[0] + px[1] * ax[1] + px[2] * ax[2], pb = px[0] * ay[0] + px[1] * ay[1] + px[2] * ay[2];
                    det = aa * bb - ab * ab;
                    bc[0] = (pa * bb - pb * ab) / det;
                    bc[1] = (pb * aa - pa * ab) / det;
                }
            }
            CHECK_OK(rad_hierarchical_lookup(h0, RAD_HIERARCHICAL_RADIOSITY, 0, &t, bc, 1, v));
            CHECK_OK(rad_hierarchical_lookup(h0, RAD_HIERARCHICAL_RADIOSITY, 1, &t, bc, 1, sm));
            for (k = 0; k < 3; ++k) CHECK_REL(v[k], B0[3 * i + k], 1e-6);
            for (j = 0; j < s0.leaves; ++j)
                for (k = 0; k < 3; ++k)
                    if (B0[3 * j + k] > bmax) bmax = B0[3 * j + k];
            for (k = 0; k < 3; ++k) CHECK(sm[k] >= 0.0f && sm[k] <= bmax);
            ++n;
        }
        CHECK(n > 10u);
    }
    free(B0);
    free(B1);
    rad_hierarchical_destroy(h1);
    h1 = NULL;
    ss.bad = -1.0f;
    CHECK_OK(rad_hierarchical_create(w.scene, &w.rc, &o, NULL, &h1));
    CHECK_RESULT(rad_hierarchical_solve(h1, NULL), RAD_ERROR_NEGATIVE_EMISSION);
    CHECK_RESULT(rad_hierarchical_leaves(h1, 0, 1, NULL, NULL, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT); /* failed: unusable */
    rad_hierarchical_destroy(h1);
    h1 = NULL;
    ss.bad = (float)HUGE_VAL;
    CHECK_OK(rad_hierarchical_create(w.scene, &w.rc, &o, NULL, &h1));
    CHECK_RESULT(rad_hierarchical_solve(h1, NULL), RAD_ERROR_NON_FINITE);
    rad_hierarchical_destroy(h1);
    rad_hierarchical_destroy(h0);
    hr_world_free(&w);
}

/* 5. Bad input: each refused with its error and a log message naming the problem. */
static void hr_test_bad_options(void)
{
    rad_scene_desc d;
    hr_world w;
    rad_hierarchical_options o;
    rad_hierarchical *h = NULL;
    rad_context ctx;
    sc_log_state log;
    uint32_t t = 0;
    float bc[2] = { 0.2f, 0.2f }, out[3];
    rad_cornell_box(&d, NULL);
    if (!hr_world_make(&d, &w)) return;
    memset(&ctx, 0, sizeof(ctx));
    memset(&log, 0, sizeof(log));
    ctx.log = sc_log_fn;
    ctx.log_user = &log;
#define HR_BAD(field, value, expect, word)                                                                 \
    do {                                                                                                   \
        rad_hierarchical_options_default(&o);                                                              \
        o.field = value;                                                                                   \
        log.count = 0;                                                                                     \
        CHECK_RESULT(rad_hierarchical_create(w.scene, &w.rc, &o, &ctx, &h), expect);                       \
        CHECK(h == NULL && log.count == 1 && strstr(log.last, word) != NULL);                              \
    } while (0)
    HR_BAD(tolerance, -1.0, RAD_ERROR_INVALID_ARGUMENT, "tolerance");
    HR_BAD(tolerance, 1.0, RAD_ERROR_INVALID_ARGUMENT, "tolerance");
    HR_BAD(tolerance, HUGE_VAL - HUGE_VAL, RAD_ERROR_INVALID_ARGUMENT, "tolerance");
    HR_BAD(min_area, -1.0f, RAD_ERROR_INVALID_ARGUMENT, "min_area");
    HR_BAD(min_area, (float)HUGE_VAL, RAD_ERROR_INVALID_ARGUMENT, "min_area");
    HR_BAD(min_area, 1e-12f, RAD_ERROR_INVALID_ARGUMENT, "min_area");
    HR_BAD(visibility_rays, 5u, RAD_ERROR_INVALID_ARGUMENT, "visibility_rays");
    HR_BAD(visibility_rays, 81u, RAD_ERROR_INVALID_ARGUMENT, "visibility_rays");
    HR_BAD(ray_epsilon, 0.5f, RAD_ERROR_INVALID_ARGUMENT, "ray_epsilon");
    HR_BAD(ray_epsilon, -1e-5f, RAD_ERROR_INVALID_ARGUMENT, "ray_epsilon");
#undef HR_BAD
    rad_hierarchical_options_default(&o);
    CHECK_RESULT(rad_hierarchical_create(w.scene, NULL, &o, &ctx, &h), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(log.last, "raycaster") != NULL);
    CHECK_RESULT(rad_hierarchical_create(NULL, &w.rc, &o, &ctx, &h), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_hierarchical_create(w.scene, &w.rc, &o, &ctx, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_hierarchical_solve(NULL, &ctx), RAD_ERROR_INVALID_ARGUMENT);
    /* not solved yet: nothing to read; solved: a second solve, out-of-range reads */
    o.tolerance = 0.5;
    CHECK_OK(rad_hierarchical_create(w.scene, &w.rc, &o, &ctx, &h));
    CHECK_RESULT(rad_hierarchical_lookup(h, RAD_HIERARCHICAL_RADIOSITY, 0, &t, bc, 1, out), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_hierarchical_links(h, 0, 1, NULL, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_OK(rad_hierarchical_solve(h, &ctx));
    CHECK_RESULT(rad_hierarchical_solve(h, &ctx), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(log.last, "already solved") != NULL);
    {
        rad_hierarchical_stats st;
        float pts[6], F;
        uint32_t dep[2];
        rad_hierarchical_get_stats(h, &st);
        CHECK(st.leaves == w.scene->triangle_count); /* tolerance 0.5: nothing refined */
        CHECK_RESULT(rad_hierarchical_leaves(h, st.leaves, 1, NULL, NULL, NULL, NULL), RAD_ERROR_INDEX_OUT_OF_RANGE);
        CHECK_OK(rad_hierarchical_leaves(h, st.leaves, 0, NULL, NULL, NULL, NULL));
        CHECK_RESULT(rad_hierarchical_links(h, st.links, 1, pts, &F, dep), RAD_ERROR_INDEX_OUT_OF_RANGE);
        CHECK_OK(rad_hierarchical_links(h, st.links - 1u, 1, pts, &F, dep));
        CHECK(F >= 0.0f && F <= 1.0f && dep[0] == 0u && dep[1] == 0u);
    }
    t = w.scene->triangle_count;
    CHECK_RESULT(rad_hierarchical_lookup(h, RAD_HIERARCHICAL_RADIOSITY, 1, &t, bc, 1, out), RAD_ERROR_INDEX_OUT_OF_RANGE);
    t = 0;
    CHECK_RESULT(rad_hierarchical_lookup(h, (rad_hierarchical_value)7, 1, &t, bc, 1, out), RAD_ERROR_INVALID_ARGUMENT);
    bc[0] = (float)(HUGE_VAL - HUGE_VAL);
    CHECK_RESULT(rad_hierarchical_lookup(h, RAD_HIERARCHICAL_GATHERED, 1, &t, bc, 1, out), RAD_ERROR_INVALID_ARGUMENT);
    rad_hierarchical_destroy(h);
    rad_hierarchical_destroy(NULL);
    hr_world_free(&w);
}

/* 6. Allocation failure at every allocation of create and solve: success or OUT_OF_MEMORY,
   nothing leaks, no block overrun (the counting allocator of test_scene.c). */
static void hr_test_alloc(void)
{
    rad_scene_desc d;
    hr_world w;
    rad_hierarchical_options o;
    sc_alloc_state st;
    rad_context ctx;
    long n, total = 1;
    rad_cornell_box(&d, NULL);
    if (!hr_world_make(&d, &w)) return;
    rad_hierarchical_options_default(&o);
    o.tolerance = 1e-2;
    sc_ctx_alloc(&ctx, &st);
    for (n = 0; n <= total; ++n) {
        rad_hierarchical *h = NULL;
        rad_result r;
        memset(&st, 0, sizeof(st));
        st.fail_at = n;
        r = rad_hierarchical_create(w.scene, &w.rc, &o, &ctx, &h);
        if (r == RAD_SUCCESS) r = rad_hierarchical_solve(h, &ctx);
        if (r != RAD_SUCCESS && r != RAD_ERROR_OUT_OF_MEMORY) {
            printf("    fail_at %ld: %s\n", n, rad_result_string(r));
            CHECK(0);
        }
        if (n > 0 && n <= st.calls) CHECK(r == RAD_ERROR_OUT_OF_MEMORY);
        rad_hierarchical_destroy(h);
        if (st.allocs != st.frees || st.live_bytes != 0 || st.corrupt != 0) {
            printf("    fail_at %ld: %ld allocs, %ld frees, %lld live bytes, %ld overruns\n", n, st.allocs, st.frees,
                   st.live_bytes, st.corrupt);
            CHECK(0);
        }
        if (n == 0) total = st.calls;
    }
    CHECK(total >= 10);
    hr_world_free(&w);
}

static const rad_test_case tests_hierarchical[] = {
    { "hierarchical_furnace", hr_test_furnace },
    { "hierarchical_converges", hr_test_converges },
    { "hierarchical_source_lookup", hr_test_source_lookup },
    { "hierarchical_bad_options", hr_test_bad_options },
    { "hierarchical_alloc", hr_test_alloc },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_hierarchical)

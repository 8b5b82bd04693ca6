/* test_baker_solver.c - the engine tier's solver and patch options (SOLVER in >>api_bake:
   rad_baker_options.solver, max_edge, vp_face_points): each solver's per-vertex light against
   the same calls made by hand (bit for bit), Gauss-Seidel and LU against each other and
   Jacobi approaching them, no bounce giving H = F E, the plan counting with max_edge and face
   points, the runtime following such a bake, and the refusals. Included by test_main.c after
   the implementation: every name is static and prefixed bsv_. */
#include "fixtures.h"

/* the Cornell box's point lamp of the other baker tests */
static void bsv_lamp(rad_light *l)
{
    memset(l, 0, sizeof(*l));
    l->type = RAD_LIGHT_POINT;
    l->position[0] = 0.28f; l->position[1] = 0.35f; l->position[2] = 0.28f;
    l->color[0] = l->color[1] = l->color[2] = 0.05f;
}

/* small options: about 80 patches, more where max_edge splits the walls */
static void bsv_options(rad_baker_options *o, rad_baker_method method, rad_baker_solver solver)
{
    memset(o, 0, sizeof(*o));
    o->method = method;
    o->solver = solver;
    o->patches = 60;
    o->max_edge = 0.2f;
    o->ff_samples = 4;
    o->bounces = 8;
    o->light_samples = 8;
}

static void bsv_desc(rad_baker_desc *d, rad_baker_light *bl)
{
    memset(d, 0, sizeof(*d));
    rad_cornell_box(&d->scene, NULL);
    bsv_lamp(&bl->light);
    bl->group = 0;
    d->lights = bl;
    d->light_count = 1;
}

/* max |a - b| over max |b| */
static double bsv_rel(const float *a, const float *b, size_t n)
{
    double e = 0.0, m = 0.0;
    size_t i;
    for (i = 0; i < n; ++i) {
        double d = fabs((double)a[i] - (double)b[i]);
        if (d > e) e = d;
        if (fabs((double)b[i]) > m) m = fabs((double)b[i]);
    }
    return m > 0.0 ? e / m : e;
}

/* The classic patches, F and E of the bake's options, made by hand in the tier's order */
typedef struct bsv_classic {
    rad_scene *S;
    rad_bvh *bvh;
    rad_raycaster rc;
    rad_patches *P;
    rad_form_factors *ff;
    float *E, *Sr;
} bsv_classic;

static void bsv_classic_free(bsv_classic *c)
{
    free(c->E);
    free(c->Sr);
    rad_form_factors_destroy(c->ff);
    rad_patches_destroy(c->P);
    rad_bvh_destroy(c->bvh);
    rad_scene_destroy(c->S);
    memset(c, 0, sizeof(*c));
}

static int bsv_classic_make(const rad_baker_desc *d, const rad_baker_options *o, bsv_classic *c)
{
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_direct_options dopt;
    float *D, *ones;
    uint32_t i, n;
    int ok;
    memset(c, 0, sizeof(*c));
    CHECK_OK(rad_scene_create(&d->scene, NULL, &c->S));
    if (c->S) CHECK_OK(rad_bvh_create(c->S, NULL, &c->bvh));
    if (!c->bvh) return 0;
    (rad_bvh_raycaster)(c->bvh, &c->rc); /* the baker's own ray queries, also in the Embree build of the tests */
    rad_patch_options_default(&po);
    po.target_count = o->patches;
    po.max_edge = o->max_edge;
    CHECK_OK(rad_patches_create(c->S, &po, NULL, &c->P));
    if (!c->P) return 0;
    rad_form_factor_options_default(&fo);
    fo.samples = o->ff_samples;
    fo.seed = o->seed;
    CHECK_OK(rad_form_factors_dense(c->P, &c->rc, &fo, NULL, &c->ff));
    if (!c->ff) return 0;
    n = c->P->count;
    c->E = (float *)malloc(sizeof(float) * 3 * n);
    c->Sr = (float *)malloc(sizeof(float) * n);
    D = (float *)malloc(sizeof(float) * 3 * n);
    ones = (float *)malloc(sizeof(float) * 6 * n);
    ok = c->E && c->Sr && D && ones;
    if (ok) {
        for (i = 0; i < 3 * n; ++i) ones[i] = 1.0f;
        CHECK_OK(rad_matrix_multiply(&c->ff->matrix, ones, ones + 3 * (size_t)n, NULL));
        for (i = 0; i < n; ++i) c->Sr[i] = ones[3 * (size_t)n + 3 * i];
        rad_direct_options_default(&dopt);
        dopt.light_samples = o->light_samples;
        dopt.seed = o->seed;
        CHECK_OK(rad_direct_patches(c->P, &c->rc, &d->lights[0].light, 1, &dopt, D, NULL));
        CHECK_OK(rad_sources(c->P, RAD_SOURCE_DIRECT, D, c->E));
    }
    free(D);
    free(ones);
    return ok;
}

/* The per-vertex output of 'solver' on c, into out (3 per vertex of the desc's meshes) */
static void bsv_classic_vertices(const bsv_classic *c, const rad_baker_desc *d, const rad_baker_options *o,
                                rad_baker_solver solver, float *out)
{
    uint32_t n = c->P->count, i, m, v0 = 0;
    float *L = (float *)calloc(3 * (size_t)n, sizeof(float)), *B = (float *)malloc(sizeof(float) * 3 * n);
    float *H = (float *)malloc(sizeof(float) * 3 * n), *Hv = (float *)malloc(sizeof(float) * 3 * c->P->vertex_count);
    rad_solve_options so;
    rad_system sys;
    if (!L || !B || !H || !Hv) goto done;
    rad_system_init(&sys, &c->ff->matrix, c->P, c->E);
    rad_solve_options_default(&so);
    so.bounces = o->bounces;
    if (solver == RAD_BAKER_SOLVE_JACOBI) CHECK_OK(rad_solve_jacobi(&sys, &so, L, NULL, NULL));
    else if (solver == RAD_BAKER_SOLVE_GAUSS_SEIDEL) CHECK_OK(rad_solve_gauss_seidel(&sys, &so, L, NULL, NULL));
    else if (solver == RAD_BAKER_SOLVE_DIRECT) CHECK_OK(rad_solve_direct(&sys, &so, L, NULL));
    for (i = 0; i < 3 * n; ++i) B[i] = c->E[i] + L[i]; /* NONE: L = 0, so H = F E */
    CHECK_OK(rad_matrix_multiply(&c->ff->matrix, B, H, NULL));
    CHECK_OK(rad_patches_vertex_irradiance(c->P, H, c->Sr, Hv, NULL));
    for (m = 0; m < d->scene.mesh_count; ++m) {
        CHECK_OK(rad_patches_gather_mesh(c->P, Hv, m, &d->scene.meshes[m], out + 3 * (size_t)v0, NULL));
        v0 += d->scene.meshes[m].vertex_count;
    }
done:
    free(L); free(B); free(H); free(Hv);
}

/* each solver's bake (classic, max_edge splitting the walls) is the calls made by hand, bit
   for bit; GS and LU agree; Jacobi with many bounces approaches them; no bounce is H = F E */
static void bsv_test_classic(void)
{
    static const rad_baker_solver solvers[4] = { RAD_BAKER_SOLVE_JACOBI, RAD_BAKER_SOLVE_GAUSS_SEIDEL,
                                                 RAD_BAKER_SOLVE_DIRECT, RAD_BAKER_SOLVE_NONE };
    rad_baker_desc d;
    rad_baker_light bl;
    rad_baker_options o;
    rad_baker_result *R[4] = { NULL, NULL, NULL, NULL }, *J = NULL;
    rad_patches *plain = NULL;
    rad_patch_options po;
    bsv_classic c;
    float *out = NULL;
    size_t nv3;
    int s;
    bsv_desc(&d, &bl);
    bsv_options(&o, RAD_BAKER_CLASSIC, RAD_BAKER_SOLVE_JACOBI);
    if (!bsv_classic_make(&d, &o, &c)) goto done;
    /* max_edge counts: the walls split beyond the target's patches */
    rad_patch_options_default(&po);
    po.target_count = o.patches;
    CHECK_OK(rad_patches_create(c.S, &po, NULL, &plain));
    if (plain) CHECK(c.P->count > plain->count);
    for (s = 0; s < 4; ++s) {
        o.solver = solvers[s];
        CHECK_OK(rad_baker_run(&d, &o, NULL, &R[s]));
        if (!R[s]) goto done;
        CHECK(R[s]->method == RAD_BAKER_CLASSIC && R[s]->patch_count == c.P->count);
    }
    nv3 = 3 * (size_t)R[0]->vertex_count;
    out = (float *)malloc(sizeof(float) * nv3);
    if (!out) goto done;
    for (s = 0; s < 4; ++s) {
        bsv_classic_vertices(&c, &d, &o, solvers[s], out);
        if (memcmp(out, R[s]->vertex, nv3 * sizeof(float)) != 0) {
            printf("    solver %d: the bake differs from the calls by hand (max rel %g)\n", (int)solvers[s],
                   bsv_rel(R[s]->vertex, out, nv3));
            CHECK(!"the tier's solve is the calls made by hand");
        }
    }
    /* GS to its tolerance and LU: every bounce, the same light */
    CHECK(bsv_rel(R[1]->vertex, R[2]->vertex, nv3) < 1e-4);
    /* 8 Jacobi bounces are short of it, 64 close */
    o.solver = RAD_BAKER_SOLVE_JACOBI;
    o.bounces = 64;
    CHECK_OK(rad_baker_run(&d, &o, NULL, &J));
    if (J) {
        double e8 = bsv_rel(R[0]->vertex, R[2]->vertex, nv3), e64 = bsv_rel(J->vertex, R[2]->vertex, nv3);
        CHECK(e64 < e8 && e64 < 1e-4);
    }
    /* one bounce is less light than all of them (and not none) */
    {
        double none = 0.0, all = 0.0;
        size_t i;
        for (i = 0; i < nv3; ++i) none += R[3]->vertex[i], all += R[2]->vertex[i];
        CHECK(none > 0.0 && none < 0.99 * all);
    }
done:
    free(out);
    for (s = 0; s < 4; ++s) rad_baker_result_destroy(R[s]);
    rad_baker_result_destroy(J);
    rad_patches_destroy(plain);
    bsv_classic_free(&c);
}

/* virtual patches with 4 face points: the plan counts the set that is built; Gauss-Seidel and
   no bounce are the calls made by hand, bit for bit */
static void bsv_test_vp(void)
{
    rad_baker_desc d;
    rad_baker_light bl;
    rad_baker_options o;
    rad_baker_result *R = NULL;
    rad_baker_choice plan, plan16;
    rad_scene *S = NULL;
    rad_bvh *bvh = NULL;
    rad_virtual_patches *vp = NULL;
    rad_vp_options vo;
    rad_direct_options dopt;
    rad_solve_options so;
    rad_system sys;
    rad_raycaster rc;
    float *E = NULL, *L = NULL, *B = NULL, *H = NULL, *out = NULL;
    uint32_t i, m, n, k;
    bsv_desc(&d, &bl);
    bsv_options(&o, RAD_BAKER_VIRTUAL_PATCHES, RAD_BAKER_SOLVE_GAUSS_SEIDEL);
    o.vp_resolution = 5;
    o.vp_face_points = 4;
    CHECK_OK(rad_scene_create(&d.scene, NULL, &S));
    if (S) CHECK_OK(rad_bvh_create(S, NULL, &bvh));
    if (!bvh) goto done;
    (rad_bvh_raycaster)(bvh, &rc);
    rad_vp_options_default(&vo);
    vo.resolution = o.vp_resolution;
    vo.face_points = o.vp_face_points;
    CHECK_OK(rad_vp_create(S, &rc, &vo, NULL, &vp));
    if (!vp) goto done;
    n = vp->count;
    CHECK_OK(rad_baker_plan(S, &rc, &o, NULL, &plan));
    CHECK(plan.patch_count == n);
    o.vp_face_points = 0;
    CHECK_OK(rad_baker_plan(S, &rc, &o, NULL, &plan16));
    CHECK(plan16.patch_count != plan.patch_count); /* the face points change the set */
    o.vp_face_points = 4;
    E = (float *)malloc(sizeof(float) * 3 * n);
    L = (float *)calloc(3 * (size_t)n, sizeof(float));
    B = (float *)malloc(sizeof(float) * 3 * n);
    H = (float *)malloc(sizeof(float) * 3 * n);
    if (!E || !L || !B || !H) goto done;
    rad_direct_options_default(&dopt);
    dopt.light_samples = o.light_samples;
    CHECK_OK(rad_vp_sources(vp, &rc, &bl.light, 1, &dopt, RAD_SOURCE_DIRECT, E, NULL));
    for (k = 0; k < 2; ++k) {
        o.solver = k ? RAD_BAKER_SOLVE_NONE : RAD_BAKER_SOLVE_GAUSS_SEIDEL;
        CHECK_OK(rad_baker_run(&d, &o, NULL, &R));
        if (!R) goto done;
        CHECK(R->method == RAD_BAKER_VIRTUAL_PATCHES && R->patch_count == n);
        if (!out) out = (float *)malloc(sizeof(float) * 3 * R->vertex_count);
        if (!out) goto done;
        memset(L, 0, sizeof(float) * 3 * n);
        if (!k) {
            rad_vp_system(&sys, vp, E);
            rad_solve_options_default(&so);
            so.bounces = o.bounces;
            CHECK_OK(rad_solve_gauss_seidel(&sys, &so, L, NULL, NULL));
        }
        for (i = 0; i < 3 * n; ++i) B[i] = E[i] + L[i];
        CHECK_OK(rad_matrix_multiply(&vp->matrix, B, H, NULL));
        for (m = 0; m < d.scene.mesh_count; ++m)
            CHECK_OK(rad_vp_gather_mesh(vp, H, &d.scene.meshes[m], out + 3 * (size_t)R->vertex_first[m], NULL));
        CHECK(memcmp(out, R->vertex, sizeof(float) * 3 * R->vertex_count) == 0);
        rad_baker_result_destroy(R);
        R = NULL;
    }
done:
    free(E); free(L); free(B); free(H); free(out);
    rad_baker_result_destroy(R);
    rad_vp_destroy(vp);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(S);
}

/* the plan's estimate: LU adds its 8 N^2 bytes, no bounce takes less time */
static void bsv_test_plan(void)
{
    rad_baker_desc d;
    rad_baker_light bl;
    rad_baker_options o;
    rad_baker_choice pj, pd, pn;
    rad_scene *S = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    double N;
    bsv_desc(&d, &bl);
    bsv_options(&o, RAD_BAKER_CLASSIC, RAD_BAKER_SOLVE_JACOBI);
    CHECK_OK(rad_scene_create(&d.scene, NULL, &S));
    if (S) CHECK_OK(rad_bvh_create(S, NULL, &bvh));
    if (!bvh) goto done;
    (rad_bvh_raycaster)(bvh, &rc);
    CHECK_OK(rad_baker_plan(S, &rc, &o, NULL, &pj));
    o.solver = RAD_BAKER_SOLVE_DIRECT;
    CHECK_OK(rad_baker_plan(S, &rc, &o, NULL, &pd));
    o.solver = RAD_BAKER_SOLVE_NONE;
    CHECK_OK(rad_baker_plan(S, &rc, &o, NULL, &pn));
    N = (double)pj.patch_count;
    CHECK(pd.patch_count == pj.patch_count && pn.patch_count == pj.patch_count);
    CHECK(fabs(pd.estimated_bytes - pj.estimated_bytes - 8.0 * N * N) < 1e-6 * pd.estimated_bytes);
    CHECK(pn.estimated_seconds < pj.estimated_seconds && pd.estimated_seconds > pn.estimated_seconds);
done:
    rad_bvh_destroy(bvh);
    rad_scene_destroy(S);
}

static void bsv_test_refusals(void)
{
    rad_baker_desc d;
    rad_baker_light bl;
    rad_baker_options o;
    rad_baker_result *R = NULL;
    rad_baker_runtime *rt = NULL;
    rad_context ctx;
    fx_err_log lg;
    bsv_desc(&d, &bl);
    bsv_options(&o, RAD_BAKER_VIRTUAL_PATCHES, RAD_BAKER_SOLVE_DIRECT);
    o.vp_resolution = 4;
    fx_baker_expect(&d, &o, RAD_ERROR_INVALID_ARGUMENT, "RAD_BAKER_SOLVE_DIRECT");
    /* AUTO that the budget sends to virtual patches: refused too */
    o.method = RAD_BAKER_AUTO;
    o.max_memory = 4096.0 * 4096.0;
    o.patches = 4000;
    fx_baker_expect(&d, &o, RAD_ERROR_INVALID_ARGUMENT, "RAD_BAKER_SOLVE_DIRECT");
    bsv_options(&o, RAD_BAKER_CLASSIC, (rad_baker_solver)7);
    fx_baker_expect(&d, &o, RAD_ERROR_INVALID_ARGUMENT, "unknown solver");
    bsv_options(&o, RAD_BAKER_CLASSIC, RAD_BAKER_SOLVE_JACOBI);
    o.max_edge = -0.1f;
    fx_baker_expect(&d, &o, RAD_ERROR_INVALID_ARGUMENT, "max_edge");
    o.max_edge = (float)HUGE_VAL;
    fx_baker_expect(&d, &o, RAD_ERROR_INVALID_ARGUMENT, "max_edge");
    o.max_edge = 0.0f;
    o.vp_face_points = 5000;
    fx_baker_expect(&d, &o, RAD_ERROR_INVALID_ARGUMENT, "vp_face_points");
    /* the runtime folds Jacobi bounces: another solver's bake is refused by name */
    o.vp_face_points = 0;
    o.solver = RAD_BAKER_SOLVE_GAUSS_SEIDEL;
    CHECK_OK(rad_baker_run(&d, &o, NULL, &R));
    memset(&ctx, 0, sizeof ctx);
    memset(&lg, 0, sizeof lg);
    ctx.log = fx_err_log_fn;
    ctx.log_user = &lg;
    if (R) {
        CHECK_RESULT(rad_baker_runtime_create(&d, &o, R, NULL, &ctx, &rt), RAD_ERROR_INVALID_ARGUMENT);
        CHECK(rt == NULL && strstr(lg.last, "RAD_BAKER_SOLVE_JACOBI") != NULL);
    }
    rad_baker_runtime_destroy(rt);
    rad_baker_result_destroy(R);
}

/* the runtime rebuilds the bake's objects (no keep) with its max_edge and face points: the
   same patch counts, so it follows the bake */
static void bsv_test_runtime(void)
{
    rad_baker_desc d;
    rad_baker_light bl;
    rad_baker_options o;
    int k;
    bsv_desc(&d, &bl);
    for (k = 0; k < 2; ++k) {
        rad_baker_result *R = NULL;
        rad_baker_runtime *rt = NULL;
        bsv_options(&o, k ? RAD_BAKER_VIRTUAL_PATCHES : RAD_BAKER_CLASSIC, RAD_BAKER_SOLVE_JACOBI);
        o.vp_resolution = 4;
        o.vp_face_points = 4;
        CHECK_OK(rad_baker_run(&d, &o, NULL, &R));
        if (R) CHECK_OK(rad_baker_runtime_create(&d, &o, R, NULL, NULL, &rt));
        CHECK(rt != NULL);
        rad_baker_runtime_destroy(rt);
        rad_baker_result_destroy(R);
    }
}

static const rad_test_case tests_baker_solver[] = {
    { "baker_solver_classic", bsv_test_classic },
    { "baker_solver_vp", bsv_test_vp },
    { "baker_solver_plan", bsv_test_plan },
    { "baker_solver_refusals", bsv_test_refusals },
    { "baker_solver_runtime", bsv_test_runtime },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_baker_solver)

/* test_solve.c - the classic solvers: furnace tests, agreement on the Cornell box, matrix
   multiply, residual callbacks, error codes, determinism. Everything static and prefixed so_. */
#include "fixtures.h"


/* A closed unit cube: 6 inward-facing faces, 2 triangles each, material per face from 'albedo'. */
typedef struct so_cube {
    float pos[6 * 12];
    rad_mesh_desc meshes[6];
    rad_material mat;
    rad_scene_desc desc;
    rad_scene *scene;
    rad_patches *P;
    rad_form_factors *ff;
    double row_dev; /* max |row sum - 1| */
} so_cube;

static int so_cube_build(so_cube *c, const float albedo[3], float max_edge)
{
    int f, k;
    rad_patch_options po;
    rad_form_factor_options fo;
    uint32_t i, j;
    memset(c, 0, sizeof(*c));
    for (k = 0; k < 3; ++k) c->mat.albedo[k] = albedo[k];
    fx_cube_faces(c->pos);
    for (f = 0; f < 6; ++f) {
        c->meshes[f].positions = c->pos + 12 * f;
        c->meshes[f].vertex_count = 4;
        c->meshes[f].indices = ff_quad_indices;
        c->meshes[f].triangle_count = 2;
    }
    c->desc.meshes = c->meshes;
    c->desc.mesh_count = 6;
    c->desc.materials = &c->mat;
    c->desc.material_count = 1;
    if (rad_scene_create(&c->desc, NULL, &c->scene) != RAD_SUCCESS) return 0;
    /* every normal points into the cube */
    for (i = 0; i < c->scene->triangle_count; ++i) {
        const float *v0 = c->scene->positions + 9 * i, *n = c->scene->normals + 3 * i;
        float d = 0.0f;
        for (k = 0; k < 3; ++k) d += n[k] * (0.5f - (v0[k] + v0[3 + k] + v0[6 + k]) / 3.0f);
        CHECK(d > 0.49f);
    }
    rad_patch_options_default(&po);
    po.max_edge = max_edge;
    if (rad_patches_create(c->scene, &po, NULL, &c->P) != RAD_SUCCESS) return 0;
    rad_form_factor_options_default(&fo);
    fo.skip_visibility = 1;
    if (rad_form_factors_dense(c->P, NULL, &fo, NULL, &c->ff) != RAD_SUCCESS) return 0;
    c->row_dev = 0.0;
    for (i = 0; i < c->P->count; ++i) {
        double sum = 0.0;
        for (j = 0; j < c->P->count; ++j) sum += c->ff->matrix.dense[(size_t)i * c->P->count + j];
        if (fabs(sum - 1.0) > c->row_dev) c->row_dev = fabs(sum - 1.0);
    }
    return 1;
}

static void so_cube_free(so_cube *c)
{
    rad_form_factors_destroy(c->ff);
    rad_patches_destroy(c->P);
    rad_scene_destroy(c->scene);
}

/* max |a - b| over 3n floats */
static double so_max_diff(const float *a, const float *b, uint32_t n)
{
    double m = 0.0;
    size_t i;
    for (i = 0; i < 3 * (size_t)n; ++i) {
        double d = fabs((double)a[i] - (double)b[i]);
        if (!(d <= m)) m = d == d ? d : 1e30; /* NaN counts as a huge difference */
    }
    return m;
}

static void so_furnace(const float albedo[3])
{
    so_cube c;
    rad_system sys;
    rad_solve_options so;
    rad_solve_stats st;
    float *E, *B;
    const float e0 = 2.0f;
    uint32_t i, n, K;
    int ch, out_mode, solver;
    if (!so_cube_build(&c, albedo, rad_test_quick() ? 0.48f : 0.36f)) { CHECK(0); so_cube_free(&c); return; }
    n = c.P->count;
    printf("    cube: %u patches, max |row sum - 1| = %.3g\n", n, c.row_dev);
    CHECK(c.row_dev < 0.01);
    E = (float *)malloc(sizeof(float) * 3 * n);
    B = (float *)malloc(sizeof(float) * 3 * n);
    if (!E || !B) { free(E); free(B); so_cube_free(&c); return; }
    for (i = 0; i < 3 * n; ++i) E[i] = e0;
    rad_system_init(&sys, &c.ff->matrix, c.P, E);
    CHECK(sys.n == n && sys.areas == c.P->areas && sys.albedo == c.P->albedo && sys.E == E);
    for (i = 0; i < n; ++i) for (ch = 0; ch < 3; ++ch) CHECK(c.P->albedo[3 * i + ch] == albedo[ch]);

    /* Jacobi, K bounces: E sum_{k=0..K} rho^k (total), E sum_{k=1..K} rho^k (indirect).
       A row sum off by d changes bounce k by at most k rho^k d E. */
    for (K = 1; K <= 7; K += 3) /* K = 0 would be the default, 8 */
        for (out_mode = 0; out_mode < 2; ++out_mode) {
            rad_solve_options_default(&so);
            so.bounces = K;
            so.output = out_mode ? RAD_OUTPUT_TOTAL : RAD_OUTPUT_INDIRECT;
            memset(&st, 0, sizeof(st));
            CHECK_OK(rad_solve_jacobi(&sys, &so, B, &st, NULL));
            CHECK(st.iterations == K);
            for (ch = 0; ch < 3; ++ch) {
                double rho = albedo[ch], expect = out_mode ? e0 : 0.0, tol = 1e-5 * e0, pk = 1.0;
                uint32_t k;
                for (k = 1; k <= K; ++k) { pk *= rho; expect += e0 * pk; tol += 1.5 * e0 * k * pk * c.row_dev; }
                for (i = 0; i < n; ++i) CHECK_NEAR(B[3 * i + ch], expect, tol);
            }
        }

    /* GS, progressive, direct: E / (1 - rho); sum_k k rho^k = rho / (1 - rho)^2 */
    for (solver = 0; solver < 3; ++solver)
        for (out_mode = 0; out_mode < 2; ++out_mode) {
            rad_result r;
            rad_solve_options_default(&so);
            so.output = out_mode ? RAD_OUTPUT_TOTAL : RAD_OUTPUT_INDIRECT;
            so.tolerance = 1e-6; /* B is float: GS's sweep-to-sweep change stalls near 2e-7 here */
            so.max_iterations = solver == 1 ? 1000000u : 0u;
            memset(&st, 0, sizeof(st));
            for (i = 0; i < 3 * n; ++i) B[i] = -1.0f;
            if (solver == 0) r = rad_solve_gauss_seidel(&sys, &so, B, &st, NULL);
            else if (solver == 1) r = rad_solve_progressive(&sys, &so, B, &st, NULL);
            else r = rad_solve_direct(&sys, &so, B, NULL);
            if (r != RAD_SUCCESS) printf("    solver %d: %u iterations, residual %.3g\n", solver, st.iterations, st.residual);
            CHECK_OK(r);
            for (ch = 0; ch < 3; ++ch) {
                double rho = albedo[ch], total = e0 / (1.0 - rho);
                double expect = out_mode ? total : total - e0;
                double tol = 1.5 * e0 * rho / ((1.0 - rho) * (1.0 - rho)) * c.row_dev + 2e-5 * total;
                double worst = 0.0;
                for (i = 0; i < n; ++i) {
                    double d = fabs(B[3 * i + ch] - expect);
                    if (!(d <= worst)) worst = d;
                }
                if (!(worst <= tol)) printf("    solver %d output %d channel %d rho %.2f\n", solver, out_mode, ch, rho);
                CHECK_NEAR(worst, 0.0, tol);
            }
        }
    free(E);
    free(B);
    so_cube_free(&c);
}

static void so_test_furnace_gray(void)
{
    const float a[3] = { 0.5f, 0.5f, 0.5f };
    so_furnace(a);
}

static void so_test_furnace_rgb(void)
{
    const float a[3] = { 0.3f, 0.5f, 0.8f };
    so_furnace(a);
}

/* ---- the Cornell box: all solvers agree ---------------------------------------------------- */

/* the shared Cornell world (fixtures.h): E = emission, ffs the sparse form factors */
typedef fx_world so_cornell;

static int so_cornell_build(so_cornell *c, uint32_t target, int sparse) { return fx_cornell(c, target, 0, sparse); }

/* the four solvers with output 'mode' into out[4][3n]: direct, GS, progressive, Jacobi(100) */
static void so_all_solvers(const rad_system *sys, rad_output mode, float **out)
{
    rad_solve_options so;
    rad_solve_stats st;
    rad_solve_options_default(&so);
    so.output = mode;
    CHECK_OK(rad_solve_direct(sys, &so, out[0], NULL));
    so.tolerance = 1e-7;
    CHECK_OK(rad_solve_gauss_seidel(sys, &so, out[1], &st, NULL));
    so.max_iterations = 1000000u;
    CHECK_OK(rad_solve_progressive(sys, &so, out[2], &st, NULL));
    so.bounces = 100;
    CHECK_OK(rad_solve_jacobi(sys, &so, out[3], &st, NULL));
}

static void so_test_cornell_agree(void)
{
    so_cornell c;
    rad_system sys;
    float *out[4], *outs[4];
    uint32_t n, s, mode;
    int ok = so_cornell_build(&c, rad_test_quick() ? 150 : 400, 1);
    CHECK(ok);
    if (!ok) { fx_world_free(&c); return; }
    n = c.patches->count;
    printf("    %u patches, dense %u x %u, sparse %llu non-zeros\n", n, n, n,
           (unsigned long long)c.ffs->matrix.row_offsets[n]);
    for (s = 0; s < 4; ++s) {
        out[s] = (float *)malloc(sizeof(float) * 3 * n);
        outs[s] = (float *)malloc(sizeof(float) * 3 * n);
    }
    for (mode = 0; mode < 2; ++mode) {
        double ref, worst = 0.0;
        rad_system_init(&sys, &c.ff->matrix, c.patches, c.E);
        so_all_solvers(&sys, (rad_output)mode, out);
        rad_system_init(&sys, &c.ffs->matrix, c.patches, c.E);
        so_all_solvers(&sys, (rad_output)mode, outs);
        /* the scale is max |B_total| for both outputs: L = B - E has the same absolute errors */
        if (mode == 1) ref = so_max_abs(out[0], n);
        else {
            uint32_t i;
            ref = 0.0;
            for (i = 0; i < 3 * n; ++i) if (out[0][i] + c.E[i] > ref) ref = out[0][i] + c.E[i];
        }
        CHECK(ref > 0.1);
        for (s = 1; s < 4; ++s) {
            double d = so_max_diff(out[s], out[0], n);
            if (d > worst) worst = d;
            if (!(d <= 1e-4 * ref)) printf("    solver %u (mode %u) vs direct\n", s, mode);
            CHECK_NEAR(d, 0.0, 1e-4 * ref);
        }
        printf("    output %u: max |B| %.4g, worst solver vs direct %.3g (relative %.3g)\n", mode, ref, worst, worst / ref);
        for (s = 0; s < 4; ++s) {
            double d = so_max_diff(outs[s], out[s], n);
            if (!(d <= 1e-5 * ref)) printf("    solver %u (mode %u) sparse vs dense\n", s, mode);
            CHECK_NEAR(d, 0.0, 1e-5 * ref);
        }
    }
    /* total = indirect + E for the direct solver */
    {
        rad_solve_options so;
        uint32_t i;
        rad_system_init(&sys, &c.ff->matrix, c.patches, c.E);
        rad_solve_options_default(&so);
        so.output = RAD_OUTPUT_TOTAL;
        CHECK_OK(rad_solve_direct(&sys, &so, out[0], NULL));
        so.output = RAD_OUTPUT_INDIRECT;
        CHECK_OK(rad_solve_direct(&sys, &so, out[1], NULL));
        for (i = 0; i < 3 * n; ++i) CHECK_NEAR(out[0][i], out[1][i] + c.E[i], 1e-5 * (1.0 + fabs(out[0][i])));
    }
    for (s = 0; s < 4; ++s) { free(out[s]); free(outs[s]); }
    fx_world_free(&c);
}

/* ---- matrix multiply ---------------------------------------------------------------------- */

static uint32_t so_rng(uint32_t *s)
{
    *s ^= *s << 13; *s ^= *s >> 17; *s ^= *s << 5;
    return *s;
}

static void so_test_matrix_multiply(void)
{
    const uint32_t n = 300;
    float *dense = (float *)malloc(sizeof(float) * n * n), *vals = (float *)malloc(sizeof(float) * n * n);
    uint32_t *cols = (uint32_t *)malloc(sizeof(uint32_t) * n * n);
    uint64_t *offs = (uint64_t *)malloc(sizeof(uint64_t) * (n + 1));
    float *x = (float *)malloc(sizeof(float) * 3 * n), *o1 = (float *)malloc(sizeof(float) * 3 * n),
          *o2 = (float *)malloc(sizeof(float) * 3 * n);
    double *ref = (double *)malloc(sizeof(double) * 3 * n), rmax = 0.0;
    rad_matrix Md, Ms;
    uint32_t seed = 2463534242u, i, j, ch;
    uint64_t nnz = 0;
    if (!dense || !vals || !cols || !offs || !x || !o1 || !o2 || !ref) { CHECK(0); goto done; }
    for (i = 0; i < n; ++i) {
        offs[i] = nnz;
        for (j = 0; j < n; ++j) {
            float v = (so_rng(&seed) % 3 == 0) ? 0.0f : (float)(so_rng(&seed) % 100000) / 100000.0f / (float)n;
            if (i == 7) v = 0.0f; /* an empty row */
            dense[(size_t)i * n + j] = v;
            if (v != 0.0f) { cols[nnz] = j; vals[nnz] = v; nnz++; }
        }
    }
    offs[n] = nnz;
    for (i = 0; i < 3 * n; ++i) x[i] = (float)(so_rng(&seed) % 200000) / 1000.0f - 50.0f;
    for (i = 0; i < n; ++i)
        for (ch = 0; ch < 3; ++ch) {
            double s = 0.0;
            for (j = 0; j < n; ++j) s += (double)dense[(size_t)i * n + j] * x[3 * j + ch];
            ref[3 * i + ch] = s;
            if (fabs(s) > rmax) rmax = fabs(s);
        }
    memset(&Md, 0, sizeof(Md));
    Md.rows = Md.cols = n;
    Md.storage = RAD_STORAGE_DENSE;
    Md.dense = dense;
    memset(&Ms, 0, sizeof(Ms));
    Ms.rows = Ms.cols = n;
    Ms.storage = RAD_STORAGE_SPARSE;
    Ms.row_offsets = offs;
    Ms.columns = cols;
    Ms.values = vals;
    CHECK_OK(rad_matrix_multiply(&Md, x, o1, NULL));
    CHECK_OK(rad_matrix_multiply(&Ms, x, o2, NULL));
    for (i = 0; i < 3 * n; ++i) {
        CHECK_NEAR(o1[i], ref[i], 1e-5 * rmax);
        CHECK_NEAR(o2[i], ref[i], 1e-5 * rmax);
        if (rad_test_failures > 10) break;
    }
    CHECK(o1[21] == 0.0f && o2[21] == 0.0f && o1[23] == 0.0f);
    /* errors: aliasing, NULL */
    CHECK_RESULT(rad_matrix_multiply(&Md, x, x, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_matrix_multiply(NULL, x, o1, NULL), RAD_ERROR_INVALID_ARGUMENT);
    Ms.values = NULL;
    CHECK_RESULT(rad_matrix_multiply(&Ms, x, o1, NULL), RAD_ERROR_INVALID_ARGUMENT);
done:
    free(dense); free(vals); free(cols); free(offs); free(x); free(o1); free(o2); free(ref);
}

/* ---- residual callback, error codes ----------------------------------------------------------- */

typedef struct so_res_state {
    uint32_t calls, bad_order, stop_at;
    uint32_t last_it;
    double first, last;
} so_res_state;

static int so_res_fn(void *user, uint32_t iteration, double residual)
{
    so_res_state *s = (so_res_state *)user;
    if (s->calls == 0) s->first = residual;
    else if (iteration <= s->last_it) s->bad_order++;
    s->calls++;
    s->last_it = iteration;
    s->last = residual;
    return s->stop_at > 0 && s->calls >= s->stop_at;
}

static void so_test_residual_and_errors(void)
{
    so_cornell c;
    rad_system sys, bad;
    rad_solve_options so;
    rad_solve_stats st;
    so_res_state rs;
    float *B;
    uint32_t n, i, solver;
    int ok = so_cornell_build(&c, rad_test_quick() ? 80 : 200, 0);
    CHECK(ok);
    if (!ok) { fx_world_free(&c); return; }
    n = c.patches->count;
    B = (float *)malloc(sizeof(float) * 3 * n);
    rad_system_init(&sys, &c.ff->matrix, c.patches, c.E);
    for (solver = 0; solver < 2; ++solver) {
        rad_result r;
        /* run to convergence: iterations increase, the residual drops */
        rad_solve_options_default(&so);
        so.tolerance = 1e-6;
        so.max_iterations = solver ? 1000000u : 0u;
        so.on_residual = so_res_fn;
        so.residual_user = &rs;
        memset(&rs, 0, sizeof(rs));
        memset(&st, 0, sizeof(st));
        r = solver ? rad_solve_progressive(&sys, &so, B, &st, NULL) : rad_solve_gauss_seidel(&sys, &so, B, &st, NULL);
        CHECK_OK(r);
        CHECK(rs.calls >= 2);
        CHECK(rs.bad_order == 0);
        CHECK(rs.last < rs.first);
        /* the converged residual itself is not reported: the last report is the one before */
        CHECK(rs.last_it + 1 == st.iterations || rs.last_it == st.iterations);
        CHECK(st.residual < 1e-6);
        printf("    %s: %u iterations, residual %.3g -> %.3g\n", solver ? "progressive" : "gauss-seidel", st.iterations,
               rs.first, rs.last);
        /* stop at the third report */
        memset(&rs, 0, sizeof(rs));
        rs.stop_at = 3;
        memset(&st, 0, sizeof(st));
        r = solver ? rad_solve_progressive(&sys, &so, B, &st, NULL) : rad_solve_gauss_seidel(&sys, &so, B, &st, NULL);
        CHECK_OK(r);
        CHECK(rs.calls == 3);
        CHECK(st.iterations <= 3);
    }
    /* GS that cannot converge in 2 sweeps still writes out */
    rad_solve_options_default(&so);
    so.max_iterations = 2;
    so.tolerance = 1e-12;
    for (i = 0; i < 3 * n; ++i) B[i] = (float)NAN;
    memset(&st, 0, sizeof(st));
    CHECK_RESULT(rad_solve_gauss_seidel(&sys, &so, B, &st, NULL), RAD_ERROR_NOT_CONVERGED);
    CHECK(st.iterations == 2);
    {
        int finite = 1;
        double mx = 0.0;
        for (i = 0; i < 3 * n; ++i) { if (!(B[i] == B[i])) finite = 0; if (B[i] > mx) mx = B[i]; }
        CHECK(finite);
        CHECK(mx > 0.0);
    }
    /* progressive stops with NOT_CONVERGED too */
    so.max_iterations = 5;
    CHECK_RESULT(rad_solve_progressive(&sys, &so, B, &st, NULL), RAD_ERROR_NOT_CONVERGED);
    /* progressive needs areas */
    bad = sys;
    bad.areas = NULL;
    rad_solve_options_default(&so);
    CHECK_RESULT(rad_solve_progressive(&bad, &so, B, &st, NULL), RAD_ERROR_INVALID_ARGUMENT);
    /* mismatched n */
    bad = sys;
    bad.n = n - 1;
    CHECK_RESULT(rad_solve_jacobi(&bad, &so, B, &st, NULL), RAD_ERROR_SIZE_MISMATCH);
    CHECK_RESULT(rad_solve_gauss_seidel(&bad, &so, B, &st, NULL), RAD_ERROR_SIZE_MISMATCH);
    CHECK_RESULT(rad_solve_progressive(&bad, &so, B, &st, NULL), RAD_ERROR_SIZE_MISMATCH);
    CHECK_RESULT(rad_solve_direct(&bad, &so, B, NULL), RAD_ERROR_SIZE_MISMATCH);
    /* NULL pieces */
    bad = sys;
    bad.E = NULL;
    CHECK_RESULT(rad_solve_jacobi(&bad, &so, B, &st, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_solve_jacobi(&sys, &so, NULL, &st, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_solve_direct(NULL, &so, B, NULL), RAD_ERROR_INVALID_ARGUMENT);
    free(B);
    fx_world_free(&c);
}

static void so_test_singular(void)
{
    /* 1x1: B = E + rho F B with rho F = 1 exactly */
    float F = 2.0f, albedo[3] = { 0.5f, 0.5f, 0.5f }, E[3] = { 1, 1, 1 }, area = 1.0f, B[3] = { 7, 7, 7 };
    rad_matrix M;
    rad_system sys;
    rad_solve_options so;
    memset(&M, 0, sizeof(M));
    M.rows = M.cols = 1;
    M.storage = RAD_STORAGE_DENSE;
    M.dense = &F;
    sys.F = &M;
    sys.albedo = albedo;
    sys.E = E;
    sys.areas = &area;
    sys.n = 1;
    rad_solve_options_default(&so);
    CHECK_RESULT(rad_solve_direct(&sys, &so, B, NULL), RAD_ERROR_SINGULAR);
    CHECK(B[0] == 7.0f); /* outputs are written only on success */
    /* one channel singular is enough */
    albedo[0] = 0.25f; albedo[1] = 0.25f;
    CHECK_RESULT(rad_solve_direct(&sys, &so, B, NULL), RAD_ERROR_SINGULAR);
    /* a nearly singular but regular 2x2: F = [[0 1][1 0]], rho = 0.999 */
    {
        float F2[4] = { 0, 1, 1, 0 }, a2[6], E2[6] = { 1, 0, 0, 0, 0, 0 }, B2[6], ar2[2] = { 1, 1 };
        int k;
        for (k = 0; k < 6; ++k) a2[k] = 0.999f;
        M.rows = M.cols = 2;
        M.dense = F2;
        sys.albedo = a2;
        sys.E = E2;
        sys.areas = ar2;
        sys.n = 2;
        so.output = RAD_OUTPUT_TOTAL;
        CHECK_OK(rad_solve_direct(&sys, &so, B2, NULL));
        /* B0 = 1 + r B1, B1 = r B0: B0 = 1 / (1 - r^2), B1 = r / (1 - r^2) */
        {
            double r = (double)0.999f;
            CHECK_REL(B2[0], 1.0 / (1.0 - r * r), 1e-3);
            CHECK_REL(B2[3], r / (1.0 - r * r), 1e-3);
            CHECK_NEAR(B2[1], 0.0, 1e-6);
        }
    }
}

/* ---- determinism --------------------------------------------------------------------------------- */

static void so_test_jacobi_deterministic(void)
{
    so_cornell c;
    rad_system sys;
    rad_solve_options so;
    rad_context rev;
    float *B1, *B2;
    uint32_t n;
    int ok = so_cornell_build(&c, rad_test_quick() ? 100 : 300, 1);
    CHECK(ok);
    if (!ok) { fx_world_free(&c); return; }
    n = c.patches->count;
    B1 = (float *)malloc(sizeof(float) * 3 * n);
    B2 = (float *)malloc(sizeof(float) * 3 * n);
    memset(&rev, 0, sizeof(rev));
    rev.parallel_for = fx_reverse_for;
    rev.task_count = 7;
    rad_solve_options_default(&so);
    so.bounces = 12;
    so.output = RAD_OUTPUT_TOTAL;
    rad_system_init(&sys, &c.ff->matrix, c.patches, c.E);
    CHECK_OK(rad_solve_jacobi(&sys, &so, B1, NULL, NULL));
    CHECK_OK(rad_solve_jacobi(&sys, &so, B2, NULL, &rev));
    CHECK(memcmp(B1, B2, sizeof(float) * 3 * n) == 0);
    rad_system_init(&sys, &c.ffs->matrix, c.patches, c.E);
    CHECK_OK(rad_solve_jacobi(&sys, &so, B1, NULL, NULL));
    CHECK_OK(rad_solve_jacobi(&sys, &so, B2, NULL, &rev));
    CHECK(memcmp(B1, B2, sizeof(float) * 3 * n) == 0);
    /* and the multiply */
    CHECK_OK(rad_matrix_multiply(&c.ff->matrix, c.E, B1, NULL));
    CHECK_OK(rad_matrix_multiply(&c.ff->matrix, c.E, B2, &rev));
    CHECK(memcmp(B1, B2, sizeof(float) * 3 * n) == 0);
    free(B1);
    free(B2);
    fx_world_free(&c);
}

static const rad_test_case tests_solve[] = {
    { "solve_furnace_gray", so_test_furnace_gray },
    { "solve_furnace_rgb", so_test_furnace_rgb },
    { "solve_cornell_agree", so_test_cornell_agree },
    { "solve_matrix_multiply", so_test_matrix_multiply },
    { "solve_residual_and_errors", so_test_residual_and_errors },
    { "solve_singular", so_test_singular },
    { "solve_jacobi_deterministic", so_test_jacobi_deterministic },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_solve)

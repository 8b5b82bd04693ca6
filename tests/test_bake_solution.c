/* test_bake_solution.c - the baker's kept solution (RAD_BAKER_SOLUTION, rad_baker_irradiance,
   docs/methods/bake.md): the bounced irradiance inside a closed emitting box against its
   closed form for both methods, the classic gather at triangle corners against the baker's
   own per-vertex output, the mix applied to it, and the errors of bad input. Included by
   test_main.c after the implementation: every name is static and prefixed bs_. */
#include "fixtures.h"

/* A closed unit cube seen from inside: 12 triangles with their own vertices (no sharing, so
   a vertex of the per-vertex output is one triangle's corner), every face emitting radiance
   Le and reflecting rho. */
typedef struct bs_box {
    float pos[36 * 3];
    rad_mesh_desc mesh;
    rad_material mat;
    rad_baker_desc desc;
} bs_box;

static void bs_box_make(bs_box *b, float Le, float rho)
{
    uint32_t a, s, t = 0, k;
    memset(b, 0, sizeof *b);
    for (a = 0; a < 3; ++a)
        for (s = 0; s < 2; ++s) {
            uint32_t u = (a + 1) % 3, v = (a + 2) % 3, q;
            float c[4][3], e1[3], e2[3], n;
            static const float uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
            for (q = 0; q < 4; ++q) {
                c[q][a] = (float)s;
                c[q][u] = uv[q][0];
                c[q][v] = uv[q][1];
            }
            for (k = 0; k < 3; ++k) e1[k] = c[1][k] - c[0][k], e2[k] = c[2][k] - c[0][k];
            n = e1[u] * e2[v] - e1[v] * e2[u]; /* the a component of the winding's normal */
            /* inward: +a on the face at 0, -a on the face at 1 */
            if ((n > 0.0f) != (s == 0)) {
                float tmp[3];
                memcpy(tmp, c[1], sizeof tmp);
                memcpy(c[1], c[3], sizeof tmp);
                memcpy(c[3], tmp, sizeof tmp);
            }
            {
                static const int tri[6] = {0, 1, 2, 0, 2, 3};
                for (q = 0; q < 6; ++q) memcpy(b->pos + 3 * (size_t)(t * 3 + q), c[tri[q]], 3 * sizeof(float));
            }
            t += 2;
        }
    for (k = 0; k < 3; ++k) b->mat.albedo[k] = rho, b->mat.emission[k] = Le;
    b->mesh.positions = b->pos;
    b->mesh.vertex_count = 36;
    b->mesh.triangle_count = 12;
    b->desc.scene.meshes = &b->mesh;
    b->desc.scene.mesh_count = 1;
    b->desc.scene.materials = &b->mat;
    b->desc.scene.material_count = 1;
}

static void bs_options(rad_baker_options *o, rad_baker_method m)
{
    memset(o, 0, sizeof *o);
    o->method = m;
    o->patches = 150;
    o->ff_samples = 16;
    o->bounces = 8;
    o->light_samples = 4;
    o->vp_resolution = 4;
}

/* The points a camera would see: each triangle's centroid and two other inner points, with
   their hits on the scene's triangle numbering. */
static uint32_t bs_points(const rad_scene *S, rad_hit *hits, float *pts, float *nrm)
{
    static const float bary[3][2] = {{1.0f / 3.0f, 1.0f / 3.0f}, {0.6f, 0.2f}, {0.15f, 0.7f}};
    uint32_t t, j, k, n = 0;
    for (t = 0; t < S->triangle_count; ++t)
        for (j = 0; j < 3; ++j, ++n) {
            const float *v = S->positions + 9 * (size_t)t;
            hits[n].triangle = t;
            hits[n].b1 = bary[j][0];
            hits[n].b2 = bary[j][1];
            hits[n].t = 1.0f;
            for (k = 0; k < 3; ++k) {
                pts[3 * n + k] = v[k] + bary[j][0] * (v[3 + k] - v[k]) + bary[j][1] * (v[6 + k] - v[k]);
                nrm[3 * n + k] = S->normals[3 * (size_t)t + k];
            }
        }
    return n;
}

/* Inside a closed box every surface emits exitance pi Le and sees only emitters: the direct
   irradiance is D = pi Le, the source E = rho D, and K Jacobi bounces then H = F (E + L) give
   H = pi Le (rho + rho^2 + ... + rho^(K+1)) wherever the form-factor rows sum to 1. */
static void bs_test_closed_form(void)
{
    static const rad_baker_method methods[2] = {RAD_BAKER_CLASSIC, RAD_BAKER_VIRTUAL_PATCHES};
    /* measured worst point: classic (150 patches, 16 samples) 0.04%, virtual patches
       (resolution 4, rows scaled to their sums) float rounding */
    static const double tol[2] = {0.005, 0.005};
    const float Le = 1.0f, rho = 0.5f;
    double want = 0.0, p = 1.0;
    bs_box b;
    rad_scene *S = NULL;
    rad_hit hits[36];
    float pts[108], nrm[108], H[108];
    uint32_t i, k, m, n;
    for (k = 0; k <= 8; ++k) p *= rho, want += p;
    want *= 3.14159265358979 * Le;
    bs_box_make(&b, Le, rho);
    b.desc.outputs = RAD_BAKER_SOLUTION;
    CHECK_OK(rad_scene_create(&b.desc.scene, NULL, &S));
    if (!S) return;
    n = bs_points(S, hits, pts, nrm);
    for (m = 0; m < 2; ++m) {
        rad_baker_options o;
        rad_baker_result *R = NULL;
        double worst = 0.0;
        bs_options(&o, methods[m]);
        CHECK_OK(rad_baker_run(&b.desc, &o, NULL, &R));
        if (!R) continue;
        CHECK(R->method == methods[m]);
        CHECK(R->solution != NULL);
        CHECK(R->vertex == NULL); /* only the solution was asked for */
        CHECK_OK(rad_baker_irradiance(R, hits, pts, nrm, n, H, NULL));
        for (i = 0; i < 3 * n; ++i) {
            double e = fabs((double)H[i] - want) / want;
            if (e > worst) worst = e;
        }
        if (worst > tol[m]) printf("    %s: worst relative error %.4f (closed form %.4f)\n", m ? "vp" : "classic", worst, want);
        CHECK(worst <= tol[m]);
        rad_baker_result_destroy(R);
    }
    rad_scene_destroy(S);
}

/* Classic: the gather at a triangle's corners is the per-vertex output of that corner (the
   box shares no vertex, so each output vertex is one corner); and the mix scales the kept
   solution as it scales the outputs. */
static void bs_test_corners_and_mix(void)
{
    bs_box b;
    rad_baker_options o;
    rad_baker_result *R = NULL;
    rad_hit hits[36];
    float pts[108], nrm[108], H[108], H2[108];
    const float scale[3] = {2.0f, 0.5f, 0.0f};
    uint32_t t, j, k, bad = 0;
    bs_box_make(&b, 1.0f, 0.6f);
    b.desc.outputs = RAD_BAKER_VERTEX | RAD_BAKER_SOLUTION;
    bs_options(&o, RAD_BAKER_CLASSIC);
    CHECK_OK(rad_baker_run(&b.desc, &o, NULL, &R));
    if (!R) return;
    CHECK(R->vertex != NULL && R->vertex_count == 36);
    for (t = 0; t < 12; ++t)
        for (j = 0; j < 3; ++j) {
            rad_hit *h = &hits[3 * t + j];
            h->triangle = t;
            h->b1 = j == 1 ? 1.0f : 0.0f;
            h->b2 = j == 2 ? 1.0f : 0.0f;
            h->t = 1.0f;
            for (k = 0; k < 3; ++k) {
                pts[3 * (3 * t + j) + k] = b.pos[3 * (3 * t + j) + k];
                nrm[3 * (3 * t + j) + k] = 0.0f;
            }
            nrm[3 * (3 * t + j)] = 1.0f;
        }
    CHECK_OK(rad_baker_irradiance(R, hits, pts, nrm, 36, H, NULL));
    for (k = 0; k < 108; ++k)
        if (fabsf(H[k] - R->vertex[k]) > 1e-5f * fabsf(R->vertex[k]) + 1e-6f) ++bad;
    CHECK(bad == 0);
    CHECK_OK(rad_baker_mix(R, scale, NULL));
    CHECK_OK(rad_baker_irradiance(R, hits, pts, nrm, 36, H2, NULL));
    for (k = 0, bad = 0; k < 108; ++k)
        if (H2[k] != scale[k % 3] * H[k]) ++bad; /* scales by 2, 1/2 and 0: exact in float */
    CHECK(bad == 0);
    /* a hit off the scene gets 0 */
    hits[0].triangle = RAD_NONE;
    H[0] = H[1] = H[2] = -1.0f;
    CHECK_OK(rad_baker_irradiance(R, hits, pts, nrm, 1, H, NULL));
    CHECK(H[0] == 0.0f && H[1] == 0.0f && H[2] == 0.0f);
    rad_baker_result_destroy(R);
}

static void bs_test_bad_input(void)
{
    bs_box b;
    rad_baker_options o;
    rad_baker_result *R = NULL, *V = NULL;
    rad_hit hit;
    float p[3] = {0.5f, 0.5f, 0.0f}, n[3] = {0.0f, 0.0f, 1.0f}, out[3];
    bs_box_make(&b, 1.0f, 0.5f);
    bs_options(&o, RAD_BAKER_CLASSIC);
    memset(&hit, 0, sizeof hit);
    /* an unknown output bit is still refused */
    b.desc.outputs = 16u;
    CHECK_RESULT(rad_baker_run(&b.desc, &o, NULL, &R), RAD_ERROR_INVALID_ARGUMENT);
    /* a bake without the solution keeps none */
    b.desc.outputs = RAD_BAKER_VERTEX;
    CHECK_OK(rad_baker_run(&b.desc, &o, NULL, &R));
    if (R) {
        CHECK(R->solution == NULL);
        CHECK_RESULT(rad_baker_irradiance(R, &hit, p, n, 1, out, NULL), RAD_ERROR_INVALID_ARGUMENT);
        rad_baker_result_destroy(R);
        R = NULL;
    }
    CHECK_RESULT(rad_baker_irradiance(NULL, &hit, p, n, 1, out, NULL), RAD_ERROR_INVALID_ARGUMENT);
    b.desc.outputs = RAD_BAKER_SOLUTION;
    bs_options(&o, RAD_BAKER_VIRTUAL_PATCHES);
    CHECK_OK(rad_baker_run(&b.desc, &o, NULL, &V));
    if (V) {
        float bad[3] = {0.5f, NAN, 0.5f};
        CHECK_RESULT(rad_baker_irradiance(V, NULL, p, n, 1, out, NULL), RAD_ERROR_INVALID_ARGUMENT);
        CHECK_RESULT(rad_baker_irradiance(V, &hit, NULL, n, 1, out, NULL), RAD_ERROR_INVALID_ARGUMENT);
        CHECK_RESULT(rad_baker_irradiance(V, &hit, p, NULL, 1, out, NULL), RAD_ERROR_INVALID_ARGUMENT);
        CHECK_RESULT(rad_baker_irradiance(V, &hit, p, n, 1, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
        CHECK_OK(rad_baker_irradiance(V, NULL, NULL, NULL, 0, NULL, NULL)); /* nothing asked */
        CHECK_RESULT(rad_baker_irradiance(V, &hit, bad, n, 1, out, NULL), RAD_ERROR_NON_FINITE);
        rad_baker_result_destroy(V);
    }
}

/* With rad_baker_options.keep the kept solution reads the kept objects (no second copy): its
   gather equals a bake without keep (classic bit for bit; virtual patches are then built
   with sparse rows: float rounding), a runtime borrows the same objects, and destroying the
   result frees each object once (the sanitizer builds check that). Sky layers stay out of the
   solution, and with direct or band-4 probes they are refused. */
static void bs_test_keep(void)
{
    static const rad_baker_method methods[2] = {RAD_BAKER_CLASSIC, RAD_BAKER_VIRTUAL_PATCHES};
    bs_box b;
    rad_scene *S = NULL;
    rad_hit hits[36];
    float pts[108], nrm[108], H[108], K[108];
    uint32_t i, m, n, bad;
    bs_box_make(&b, 1.0f, 0.5f);
    CHECK_OK(rad_scene_create(&b.desc.scene, NULL, &S));
    if (!S) return;
    n = bs_points(S, hits, pts, nrm);
    for (m = 0; m < 2; ++m) {
        rad_baker_options o;
        rad_baker_result *A = NULL, *B = NULL;
        rad_baker_runtime *rt = NULL;
        bs_options(&o, methods[m]);
        b.desc.outputs = RAD_BAKER_VERTEX | RAD_BAKER_SOLUTION;
        CHECK_OK(rad_baker_run(&b.desc, &o, NULL, &A));
        o.keep = 1;
        o.sky_bands = 1;
        o.sky_rays = 8;
        CHECK_OK(rad_baker_run(&b.desc, &o, NULL, &B));
        if (A && B) {
            CHECK(B->kept != NULL && B->solution != NULL && B->sky_count == 1);
            CHECK_OK(rad_baker_irradiance(A, hits, pts, nrm, n, H, NULL));
            CHECK_OK(rad_baker_irradiance(B, hits, pts, nrm, n, K, NULL));
            for (i = 0, bad = 0; i < 3 * n; ++i)
                if (m == 0 ? H[i] != K[i] : fabsf(H[i] - K[i]) > 1e-5f * fabsf(H[i])) ++bad;
            CHECK(bad == 0);
            o.sky_bands = 0; /* the runtime's options as the bake's, the sky aside */
            CHECK_OK(rad_baker_runtime_create(&b.desc, &o, B, NULL, NULL, &rt));
            rad_baker_runtime_destroy(rt);
        }
        rad_baker_result_destroy(A);
        rad_baker_result_destroy(B);
    }
    {
        rad_baker_options o;
        rad_probe_options po;
        rad_baker_result *R = NULL;
        bs_options(&o, RAD_BAKER_CLASSIC);
        o.sky_bands = 1;
        rad_probe_options_default(&po);
        po.flags |= RAD_PROBES_DIRECT;
        b.desc.outputs = RAD_BAKER_PROBES;
        b.desc.probe_options = &po;
        CHECK_RESULT(rad_baker_run(&b.desc, &o, NULL, &R), RAD_ERROR_INVALID_ARGUMENT);
        CHECK(R == NULL);
        b.desc.probe_options = NULL;
    }
    rad_scene_destroy(S);
}

/* The estimate counts what the solution keeps: 12 (groups + 1) bytes per virtual patch. */
static void bs_test_estimate(void)
{
    bs_box b;
    rad_baker_options o;
    rad_baker_result *A = NULL, *B = NULL;
    bs_box_make(&b, 1.0f, 0.5f);
    bs_options(&o, RAD_BAKER_VIRTUAL_PATCHES);
    b.desc.outputs = RAD_BAKER_VERTEX;
    CHECK_OK(rad_baker_run(&b.desc, &o, NULL, &A));
    b.desc.outputs = RAD_BAKER_VERTEX | RAD_BAKER_SOLUTION;
    CHECK_OK(rad_baker_run(&b.desc, &o, NULL, &B));
    if (A && B) {
        double want = 12.0 * (A->group_count + 1.0) * A->patch_count;
        CHECK(A->patch_count == B->patch_count);
        CHECK_NEAR(B->estimated_bytes - A->estimated_bytes, want, 1e-6 * want);
    }
    rad_baker_result_destroy(A);
    rad_baker_result_destroy(B);
}

static const rad_test_case tests_bake_solution[] = {
    { "bake_solution_closed_form", bs_test_closed_form },
    { "bake_solution_corners_and_mix", bs_test_corners_and_mix },
    { "bake_solution_bad_input", bs_test_bad_input },
    { "bake_solution_keep", bs_test_keep },
    { "bake_solution_estimate", bs_test_estimate },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_bake_solution)

/* test_emissive.c - emission textures (rad_material.emission_texture through
   rad_scene_desc.emission_lookup, docs/methods/emission.md): a unit square lamp 0.5 above a
   unit square floor, facing it. The power a half-black texture lets through is half the
   closed form (Howell C-11) by symmetry, for the direct light of emissive triangles and for
   the classic patches; a 2 x 2 checker texture gives what the same lamp cut into four quads
   of constant emission gives (classic radiosity and AAVP); bad lookups are errors. */
#include "fixtures.h"

#define EM_GAP 0.5f

/* texture 1: black where u < 0.5; texture 2: a 2 x 2 checker, white where (u < .5) == (v < .5);
   texture 3: NaN; texture 4: negative; anything else: white */
static void em_lookup(void *user, uint32_t texture, float u, float v, float out[3])
{
    float x = 1.0f;
    (void)user;
    if (texture == 1) x = u < 0.5f ? 0.0f : 1.0f;
    else if (texture == 2) x = (u < 0.5f) == (v < 0.5f) ? 1.0f : 0.0f;
    else if (texture == 3) x = (float)NAN;
    else if (texture == 4) x = -1.0f;
    out[0] = out[1] = out[2] = x;
}

/* The floor (mesh 0, material 0) and the lamp (mesh 1+, material 1 with 'tex'), or with
   split != 0 the lamp as four quads, the checker's white ones of material 1 (constant
   emission) and its black ones of material 0. */
typedef struct em_world {
    ff_quad q[5];
    float uv[5][8];
    rad_mesh_desc m[5];
    rad_material mat[2];
    rad_scene_desc d;
} em_world;

static void em_make(em_world *w, uint32_t tex, int split)
{
    uint32_t i, n = split ? 4u : 1u;
    memset(w, 0, sizeof(*w));
    ff_quad_set(&w->q[0], 0, 0, 0, 0, 0, 1, 1, 0, 0); /* floor, y = 0, facing +y */
    for (i = 0; i < n; ++i) {
        float s = split ? 0.5f : 1.0f, ox = split ? 0.5f * (float)(i & 1u) : 0.0f, oz = split ? 0.5f * (float)(i >> 1) : 0.0f;
        float *uv = w->uv[1 + i];
        ff_quad_set(&w->q[1 + i], ox, EM_GAP, oz, s, 0, 0, 0, 0, s); /* lamp, facing -y */
        /* u = x, v = z at the four corners o, o+u, o+u+v, o+v */
        uv[0] = ox; uv[1] = oz; uv[2] = ox + s; uv[3] = oz; uv[4] = ox + s; uv[5] = oz + s; uv[6] = ox; uv[7] = oz + s;
    }
    for (i = 0; i < 1 + n; ++i) {
        ff_mesh_quad(&w->m[i], &w->q[i]);
        w->m[i].uvs = w->uv[i];
        w->m[i].material = i == 0 ? 0u : 1u;
    }
    if (split) /* cells (0,0) and (1,1) are white in the checker */
        w->m[2].material = w->m[3].material = 0;
    w->mat[0].albedo[0] = w->mat[0].albedo[1] = w->mat[0].albedo[2] = 0.5f;
    w->mat[1] = w->mat[0];
    w->mat[1].emission[0] = w->mat[1].emission[1] = w->mat[1].emission[2] = 1.0f;
    w->mat[1].emission_texture = tex;
    w->d.meshes = w->m;
    w->d.mesh_count = 1 + n;
    w->d.materials = w->mat;
    w->d.material_count = 2;
    w->d.emission_lookup = em_lookup;
}

#define EM_GRID 16

/* The floor's direct irradiance at EM_GRID^2 cell centres (out), and the power on it */
static double em_direct_power(const em_world *w, float *out)
{
    rad_scene *s = NULL;
    rad_bvh *b = NULL;
    rad_raycaster rc;
    rad_direct_options o;
    float pts[3 * EM_GRID * EM_GRID], nrm[3 * EM_GRID * EM_GRID];
    double power = 0.0;
    uint32_t i;
    for (i = 0; i < EM_GRID * EM_GRID; ++i) {
        pts[3 * i] = ((float)(i % EM_GRID) + 0.5f) / EM_GRID;
        pts[3 * i + 1] = 0.0f;
        pts[3 * i + 2] = ((float)(i / EM_GRID) + 0.5f) / EM_GRID;
        nrm[3 * i] = 0.0f; nrm[3 * i + 1] = 1.0f; nrm[3 * i + 2] = 0.0f;
    }
    CHECK_OK(rad_scene_create(&w->d, NULL, &s));
    if (!s) return -1.0;
    CHECK_OK(rad_bvh_create(s, NULL, &b));
    rad_bvh_raycaster(b, &rc);
    rad_direct_options_default(&o);
    o.light_samples = 64;
    CHECK_OK(rad_direct_irradiance(s, &rc, NULL, 0, &o, pts, nrm, EM_GRID * EM_GRID, out, NULL));
    for (i = 0; i < EM_GRID * EM_GRID; ++i) power += (double)out[3 * i] / (EM_GRID * EM_GRID);
    rad_bvh_destroy(b);
    rad_scene_destroy(s);
    return power;
}

/* The classic patches' first bounce: the power the lamp's patches (E = pi L, texture-averaged)
   send to the floor's, sum_i A_i sum_j F_ij E_j, with analytic form factors */
static double em_classic_power(const em_world *w)
{
    ff_world fw;
    rad_form_factor_options fo;
    rad_form_factors *ff = NULL;
    float *E;
    double power = 0.0;
    uint32_t i, j, N;
    if (!ff_world_make(&w->d, 0.25f, 0, &fw)) return -1.0;
    N = fw.patches->count;
    E = (float *)malloc(sizeof(float) * 3 * N);
    rad_form_factor_options_default(&fo);
    CHECK_OK(rad_sources(fw.patches, RAD_SOURCE_EMISSION, NULL, E));
    CHECK_OK(rad_form_factors_dense(fw.patches, &fw.rc, &fo, NULL, &ff));
    for (i = 0; ff && ff->matrix.dense && E && i < N; ++i) {
        if (fw.scene->meshes[fw.patches->patches[i].triangle] != 0) continue;
        for (j = 0; j < N; ++j) power += (double)fw.patches->patches[i].area * ff->matrix.dense[(size_t)i * N + j] * E[3 * j];
    }
    free(E);
    rad_form_factors_destroy(ff);
    ff_world_free(&fw);
    return power;
}

static void em_test_half_black(void)
{
    em_world w;
    float *D0 = (float *)malloc(sizeof(float) * 3 * EM_GRID * EM_GRID), *D1 = (float *)malloc(sizeof(float) * 3 * EM_GRID * EM_GRID);
    double exact = FF_PI * ff_c11(1.0, 1.0, EM_GAP); /* pi L A_lamp F_lamp->floor, L = 1, A = 1 */
    double p0, p1, c0, c1;
    if (!D0 || !D1) { free(D0); free(D1); CHECK(0); return; }
    em_make(&w, 0, 0);
    p0 = em_direct_power(&w, D0);
    c0 = em_classic_power(&w);
    em_make(&w, 1, 0);
    p1 = em_direct_power(&w, D1);
    c1 = em_classic_power(&w);
    printf("    closed form %.5f: direct untextured %.5f, half-black %.5f (x2 %.5f); classic %.5f, half-black %.5f\n", exact,
           p0, p1, 2.0 * p1, c0, c1);
    CHECK_REL(p0, exact, 0.01);     /* the 16 x 16 midpoint rule over the floor */
    CHECK_REL(2.0 * p1, exact, 0.01);
    CHECK_REL(c0, exact, 0.01);
    CHECK_REL(2.0 * c1, exact, 0.01);
    /* the light comes from the white half: the floor under it gets more than the mirror point */
    CHECK(D1[3 * (EM_GRID * 8 + 12)] > 2.0f * D1[3 * (EM_GRID * 8 + 3)]);
    free(D0);
    free(D1);
}

/* the floor's radiosity B at EM_GRID^2 points from classic radiosity (vp == 0) or AAVP */
static int em_floor_B(const em_world *w, int vp, float *out)
{
    ff_world fw;
    rad_system sys;
    rad_solve_options so;
    float *E = NULL, *B = NULL, pts[3 * EM_GRID * EM_GRID], nrm[3 * EM_GRID * EM_GRID];
    rad_form_factors *ff = NULL;
    rad_virtual_patches *V = NULL;
    uint32_t i, N;
    int ok = 0;
    for (i = 0; i < EM_GRID * EM_GRID; ++i) {
        pts[3 * i] = ((float)(i % EM_GRID) + 0.5f) / EM_GRID;
        pts[3 * i + 1] = 0.0f;
        pts[3 * i + 2] = ((float)(i / EM_GRID) + 0.5f) / EM_GRID;
        nrm[3 * i] = 0.0f; nrm[3 * i + 1] = 1.0f; nrm[3 * i + 2] = 0.0f;
    }
    if (!ff_world_make(&w->d, 1.0f / 8.0f, 0, &fw)) return 0;
    rad_solve_options_default(&so);
    so.output = RAD_OUTPUT_TOTAL;
    if (vp) {
        rad_vp_options vo;
        rad_vp_options_default(&vo);
        vo.resolution = 8;
        CHECK_OK(rad_vp_create(fw.scene, &fw.rc, &vo, NULL, &V));
        if (!V) goto out;
        N = V->count;
        E = (float *)malloc(sizeof(float) * 3 * N);
        B = (float *)malloc(sizeof(float) * 3 * N);
        if (!E || !B) goto out;
        CHECK_OK(rad_vp_sources(V, &fw.rc, NULL, 0, NULL, RAD_SOURCE_EMISSION, E, NULL));
        rad_vp_system(&sys, V, E);
        CHECK_OK(rad_solve_jacobi(&sys, &so, B, NULL, NULL));
        CHECK_OK(rad_vp_gather(V, B, pts, nrm, EM_GRID * EM_GRID, out, NULL));
    } else {
        rad_form_factor_options fo;
        N = fw.patches->count;
        E = (float *)malloc(sizeof(float) * 3 * N);
        B = (float *)malloc(sizeof(float) * 3 * N);
        if (!E || !B) goto out;
        rad_form_factor_options_default(&fo);
        CHECK_OK(rad_sources(fw.patches, RAD_SOURCE_EMISSION, NULL, E));
        CHECK_OK(rad_form_factors_dense(fw.patches, &fw.rc, &fo, NULL, &ff));
        if (!ff) goto out;
        rad_system_init(&sys, &ff->matrix, fw.patches, E);
        CHECK_OK(rad_solve_jacobi(&sys, &so, B, NULL, NULL));
        /* the floor patch under each point (the floor is the first mesh: its patches come first) */
        for (i = 0; i < EM_GRID * EM_GRID; ++i) {
            uint32_t p, best = 0;
            float bd = 1e30f;
            for (p = 0; p < N; ++p) {
                const rad_patch *pt = &fw.patches->patches[p];
                float dx = pt->centroid[0] - pts[3 * i], dy = pt->centroid[1], dz = pt->centroid[2] - pts[3 * i + 2];
                float dd = dx * dx + dy * dy + dz * dz;
                if (dd < bd) { bd = dd; best = p; }
            }
            memcpy(out + 3 * i, B + 3 * best, 3 * sizeof(float));
        }
    }
    ok = 1;
out:
    free(E);
    free(B);
    rad_vp_destroy(V);
    rad_form_factors_destroy(ff);
    ff_world_free(&fw);
    return ok;
}

static void em_compare_checker(int vp)
{
    em_world w;
    float a[3 * EM_GRID * EM_GRID], b[3 * EM_GRID * EM_GRID];
    double sa = 0.0, sb = 0.0, worst = 0.0;
    uint32_t i;
    em_make(&w, 2, 0);
    if (!em_floor_B(&w, vp, a)) return;
    em_make(&w, 0, 1);
    if (!em_floor_B(&w, vp, b)) return;
    for (i = 0; i < EM_GRID * EM_GRID; ++i) {
        double e = fabs((double)a[3 * i] - b[3 * i]);
        sa += a[3 * i];
        sb += b[3 * i];
        if (e > worst) worst = e;
    }
    printf("    %s: floor mean B textured %.5f, split %.5f; largest difference %.5f\n", vp ? "AAVP" : "classic",
           sa / (EM_GRID * EM_GRID), sb / (EM_GRID * EM_GRID), worst);
    CHECK(sb > 0.0);
    CHECK_REL(sa, sb, 0.01);
    CHECK(worst <= 0.03 * sb / (EM_GRID * EM_GRID));
}

static void em_test_checker_classic(void) { em_compare_checker(0); }
static void em_test_checker_aavp(void) { em_compare_checker(1); }

/* a probe between floor and lamp with RAD_PROBES_DIRECT: the emitters' light takes the texture
   per lattice point, so the half-black lamp gives the probe half of the plain lamp's irradiance
   (by symmetry, under the lamp's centre) */
static double em_probe_up(const em_world *w)
{
    ff_world fw;
    rad_probe_options po;
    rad_probes *pr = NULL;
    const float pos[3] = { 0.5f, 0.25f, 0.5f }, up[3] = { 0.0f, 1.0f, 0.0f };
    float e[3] = { -1.0f, -1.0f, -1.0f }, *B;
    if (!ff_world_make(&w->d, 0.5f, 0, &fw)) return -1.0;
    B = (float *)calloc(3 * (size_t)fw.patches->count, sizeof(float)); /* no bounce: the coefficients are D */
    rad_probe_options_default(&po);
    po.flags |= RAD_PROBES_DIRECT;
    if (B) CHECK_OK(rad_probes_create(fw.patches, &fw.rc, NULL, 0, pos, 1, &po, B, NULL, &pr));
    if (pr) CHECK_OK(rad_probes_sample(pr, pos, up, e));
    rad_probes_destroy(pr);
    free(B);
    ff_world_free(&fw);
    return e[1];
}

static void em_test_probes(void)
{
    em_world w;
    double a, b;
    em_make(&w, 0, 0);
    a = em_probe_up(&w);
    em_make(&w, 1, 0);
    b = em_probe_up(&w);
    printf("    probe irradiance facing the lamp: plain %.5f, half-black %.5f\n", a, b);
    CHECK(a > 0.0);
    CHECK_REL(2.0 * b, a, 0.02);
}

static void em_test_errors(void)
{
    em_world w;
    rad_scene *s = NULL;
    rad_patches *P = NULL;
    rad_context ctx;
    float e[3];
    uint32_t tex;
    memset(&ctx, 0, sizeof(ctx));
    ctx.log = ct_log;
    /* a texture without the callback */
    em_make(&w, 1, 0);
    w.d.emission_lookup = NULL;
    CHECK_RESULT(rad_scene_create(&w.d, &ctx, &s), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(ct_log_last, "emission_lookup") != NULL);
    /* a mesh without uvs under an emission texture */
    em_make(&w, 1, 0);
    w.m[1].uvs = NULL;
    ct_log_last[0] = 0;
    CHECK_RESULT(rad_scene_create(&w.d, &ctx, &s), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(ct_log_last, "no uvs") != NULL);
    /* NaN and negative texels: the patches name the material */
    for (tex = 3; tex <= 4; ++tex) {
        em_make(&w, tex, 0);
        CHECK_OK(rad_scene_create(&w.d, &ctx, &s));
        if (!s) return;
        ct_log_last[0] = 0;
        CHECK_RESULT(rad_patches_create(s, NULL, &ctx, &P), RAD_ERROR_NEGATIVE_EMISSION);
        CHECK(P == NULL);
        CHECK(strstr(ct_log_last, "material 1") != NULL);
        rad_scene_destroy(s);
        s = NULL;
    }
    /* rad_scene_emission: factor times texture; no texture keeps the factor */
    em_make(&w, 1, 0);
    w.mat[1].emission[0] = 3.0f;
    CHECK_OK(rad_scene_create(&w.d, NULL, &s));
    if (!s) return;
    rad_scene_emission(s, 2, 0.1f, 0.1f, e); /* lamp triangle 0 (scene triangle 2) near corner o (u = 0) */
    CHECK(e[0] == 0.0f);
    rad_scene_emission(s, 2, 0.8f, 0.1f, e); /* near o + u (u = 1) */
    CHECK(e[0] == 3.0f && e[1] == 1.0f);
    rad_scene_emission(s, 0, 0.3f, 0.3f, e); /* the floor: no emission */
    CHECK(e[0] == 0.0f && e[1] == 0.0f);
    rad_scene_destroy(s);
}

static const rad_test_case tests_emissive[] = {
    { "emissive_half_black", em_test_half_black },
    { "emissive_checker_classic", em_test_checker_classic },
    { "emissive_checker_aavp", em_test_checker_aavp },
    { "emissive_probes", em_test_probes },
    { "emissive_errors", em_test_errors },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_emissive)

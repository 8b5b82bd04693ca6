/* test_regress.c - regressions found by fuzzing and review, one test each, with where they
   came from. The fuzzers' crash inputs live in tests/fuzz/crashes and are replayed by the fuzz
   smoke suite. */
#include "fixtures.h"


/* fuzz_scene, tests/fuzz/crashes/scene-nonfinite-1: a point light 1e-20 from a surface gave
   irradiance 1/d^2 = inf (here a 1e-15 quad with the light 1e-21 above it). Outputs must never carry Inf: the call reports NON_FINITE. */
static void rg_test_point_light_overflow(void)
{
    static const float quad[12] = { 0, 0, 0, 1e-15f, 0, 0, 1e-15f, 1e-15f, 0, 0, 1e-15f, 0 };
    static const uint32_t idx[6] = { 0, 1, 2, 0, 2, 3 };
    rad_material m = { { 0.5f, 0.5f, 0.5f }, { 0.0f, 0.0f, 0.0f }, 0, 0, 0, 0, 0.0f };
    rad_mesh_desc mesh;
    rad_scene_desc d;
    rad_scene *s = NULL;
    rad_bvh *b = NULL;
    rad_raycaster rc;
    rad_light light;
    float p[3] = { 5e-16f, 5e-16f, 0.0f }, n[3] = { 0.0f, 0.0f, 1.0f }, D[3] = { -1.0f, -1.0f, -1.0f };
    memset(&mesh, 0, sizeof(mesh));
    mesh.positions = quad;
    mesh.vertex_count = 4;
    mesh.indices = idx;
    mesh.triangle_count = 2;
    memset(&d, 0, sizeof(d));
    d.meshes = &mesh;
    d.mesh_count = 1;
    d.materials = &m;
    d.material_count = 1;
    CHECK_OK(rad_scene_create(&d, NULL, &s));
    if (!s) return;
    CHECK_OK(rad_bvh_create(s, NULL, &b));
    rad_bvh_raycaster(b, &rc);
    memset(&light, 0, sizeof(light));
    light.type = RAD_LIGHT_POINT;
    light.color[0] = light.color[1] = light.color[2] = 1.0f;
    light.position[0] = 5e-16f;
    light.position[1] = 5e-16f;
    light.position[2] = 1e-21f;
    CHECK_RESULT(rad_direct_irradiance(s, &rc, &light, 1, NULL, p, n, 1, D, NULL), RAD_ERROR_NON_FINITE);
    rad_bvh_destroy(b);
    rad_scene_destroy(s);
}

/* review: emission so large that pi * L overflows float must not reach E */
static void rg_test_emission_overflow(void)
{
    static const float quad[12] = { 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0 };
    static const uint32_t idx[6] = { 0, 1, 2, 0, 2, 3 };
    rad_material m = { { 0.5f, 0.5f, 0.5f }, { 3e38f, 0.0f, 0.0f }, 0, 0, 0, 0, 0.0f };
    rad_mesh_desc mesh;
    rad_scene_desc d;
    rad_scene *s = NULL;
    rad_patches *P = NULL;
    float E[6];
    memset(&mesh, 0, sizeof(mesh));
    mesh.positions = quad;
    mesh.vertex_count = 4;
    mesh.indices = idx;
    mesh.triangle_count = 2;
    memset(&d, 0, sizeof(d));
    d.meshes = &mesh;
    d.mesh_count = 1;
    d.materials = &m;
    d.material_count = 1;
    CHECK_OK(rad_scene_create(&d, NULL, &s));
    if (!s) return;
    CHECK_OK(rad_patches_create(s, NULL, NULL, &P));
    if (P && P->count == 2) CHECK_RESULT(rad_sources(P, RAD_SOURCE_EMISSION, NULL, E), RAD_ERROR_NON_FINITE);
    rad_patches_destroy(P);
    rad_scene_destroy(s);
}

/* fuzz_scene, tests/fuzz/crashes/scene-ff-nonfinite: a patch of area 4e-38 beside patches of area
   1e3: the reciprocity factor A_j / A_i overflowed float and 0 * inf gave NaN form factors.
   Pairs are now integrated from the smaller patch, so the factor is at most 1. */
static void rg_test_extreme_area_ratio(void)
{
    /* a big quad facing +z and, above it, a tiny triangle facing down (area about 1e-37) */
    static const float pos[15] = { -30, -30, 0, 30, -30, 0, 30, 30, 0, -30, 30, 0,  0, 0, 0 };
    float tri[9] = { 0.0f, 0.0f, 1.0f, 0.0f, 4.5e-19f, 1.0f, 4.5e-19f, 0.0f, 1.0f };
    static const uint32_t qi[6] = { 0, 1, 2, 0, 2, 3 };
    static const uint32_t ti[3] = { 0, 1, 2 };
    rad_material m = { { 0.5f, 0.5f, 0.5f }, { 1.0f, 1.0f, 1.0f }, 0, 0, 0, 0, 0.0f };
    rad_mesh_desc mesh[2];
    rad_scene_desc d;
    rad_scene *s = NULL;
    rad_patches *P = NULL;
    rad_bvh *b = NULL;
    rad_raycaster rc;
    rad_form_factors *ff = NULL;
    size_t i;
    memset(mesh, 0, sizeof(mesh));
    mesh[0].positions = pos; mesh[0].vertex_count = 4; mesh[0].indices = qi; mesh[0].triangle_count = 2;
    mesh[1].positions = tri; mesh[1].vertex_count = 3; mesh[1].indices = ti; mesh[1].triangle_count = 1;
    memset(&d, 0, sizeof(d));
    d.meshes = mesh;
    d.mesh_count = 2;
    d.materials = &m;
    d.material_count = 1;
    CHECK_OK(rad_scene_create(&d, NULL, &s));
    if (!s) return;
    CHECK(s->areas[2] < 1e-36f && s->areas[2] > 0.0f);
    CHECK_OK(rad_patches_create(s, NULL, NULL, &P));
    CHECK_OK(rad_bvh_create(s, NULL, &b));
    rad_bvh_raycaster(b, &rc);
    CHECK_OK(rad_form_factors_dense(P, &rc, NULL, NULL, &ff));
    if (ff) {
        for (i = 0; i < (size_t)P->count * P->count; ++i) CHECK(rad__finite(ff->matrix.dense[i]) && ff->matrix.dense[i] >= 0.0f);
        /* the tiny patch sees almost all of the big quad below it */
        CHECK(ff->matrix.dense[2 * 3 + 0] + ff->matrix.dense[2 * 3 + 1] > 0.9f);
    }
    rad_form_factors_destroy(ff);
    rad_bvh_destroy(b);
    rad_patches_destroy(P);
    rad_scene_destroy(s);
}

/* the run-time products: a NaN or Inf in E, or a product that overflows
   float, returned success with NaN/Inf in the output from rad_matrix_multiply, the two
   multi-bounce applies and the temporal step, while the solvers refused it. One rule now:
   NON_FINITE, and the temporal state is left as it was. */
static void rg_test_nonfinite_products(void)
{
    rad_scene_desc d;
    rad_scene *S = NULL;
    rad_patches *P = NULL;
    rad_bvh *b = NULL;
    rad_raycaster rc;
    rad_form_factors *ff = NULL;
    rad_form_factor_options fo;
    rad_patch_options po;
    rad_multibounce *mb = NULL;
    rad_multibounce_options mo;
    rad_multibounce_blocks *bl = NULL;
    rad_block_options bo;
    rad_alias_tables *at = NULL;
    rad_temporal *tp = NULL;
    rad_temporal_options to;
    float *E = NULL, *out = NULL, *B0 = NULL;
    uint32_t N, i, frame;
    int c;
    rad_cornell_box(&d, NULL);
    CHECK_OK(rad_scene_create(&d, NULL, &S));
    rad_patch_options_default(&po);
    po.target_count = 100;
    if (S) CHECK_OK(rad_patches_create(S, &po, NULL, &P));
    if (S) CHECK_OK(rad_bvh_create(S, NULL, &b));
    if (!P || !b) goto done;
    N = P->count;
    rad_bvh_raycaster(b, &rc);
    rad_form_factor_options_default(&fo);
    fo.samples = 4;
    CHECK_OK(rad_form_factors_dense(P, &rc, &fo, NULL, &ff));
    if (!ff) goto done;
    rad_multibounce_options_default(&mo);
    mo.bounces = RAD_MB_INFINITE;
    CHECK_OK(rad_multibounce_create(&ff->matrix, P->albedo, &mo, NULL, &mb));
    rad_block_options_default(&bo);
    if (mb) CHECK_OK(rad_multibounce_blocks_create(mb, &bo, NULL, &bl, NULL));
    CHECK_OK(rad_alias_tables_create(&ff->matrix, RAD_ALIAS_AUTO, NULL, &at));
    if (at) {
        const rad_alias_tables *l[1];
        l[0] = at;
        rad_temporal_options_default(&to);
        CHECK_OK(rad_temporal_create(l, 1, P->albedo, &to, NULL, &tp));
    }
    E = (float *)malloc(sizeof(float) * 3 * N);
    out = (float *)malloc(sizeof(float) * 3 * N);
    B0 = (float *)malloc(sizeof(float) * 3 * N);
    if (!mb || !bl || !tp || !E || !out || !B0) goto done;
    CHECK_OK(rad_sources(P, RAD_SOURCE_EMISSION, NULL, E));
    CHECK_OK(rad_temporal_step(tp, E, NULL, NULL));
    memcpy(B0, rad_temporal_indirect(tp), sizeof(float) * 3 * N);
    frame = rad_temporal_frame(tp);
    for (c = 0; c < 2; ++c) {
        CHECK_OK(rad_sources(P, RAD_SOURCE_EMISSION, NULL, E));
        E[3 * (N / 2) + 1] = c == 0 ? (float)(HUGE_VAL - HUGE_VAL) : (float)HUGE_VAL;
        CHECK_RESULT(rad_matrix_multiply(&ff->matrix, E, out, NULL), RAD_ERROR_NON_FINITE);
        CHECK_RESULT(rad_multibounce_apply(mb, E, out, RAD_OUTPUT_INDIRECT, NULL), RAD_ERROR_NON_FINITE);
        CHECK_RESULT(rad_multibounce_blocks_apply(bl, E, out, RAD_OUTPUT_TOTAL, NULL), RAD_ERROR_NON_FINITE);
        CHECK_RESULT(rad_temporal_step(tp, E, NULL, out), RAD_ERROR_NON_FINITE);
    }
    /* finite but huge: the products overflow float */
    CHECK_OK(rad_sources(P, RAD_SOURCE_EMISSION, NULL, E));
    for (i = 0; i < 3 * N; ++i) E[i] = 3e38f; /* F_mb's row sums are above 1.5 here */
    CHECK_RESULT(rad_multibounce_apply(mb, E, out, RAD_OUTPUT_INDIRECT, NULL), RAD_ERROR_NON_FINITE);
    CHECK_RESULT(rad_temporal_step(tp, E, NULL, out), RAD_ERROR_NON_FINITE);
    {
        float e0[3] = { 0.0f, 1.0f, 0.0f };
        CHECK_OK(rad_sources(P, RAD_SOURCE_EMISSION, NULL, E));
        e0[0] = (float)HUGE_VAL;
        CHECK_RESULT(rad_temporal_step(tp, E, e0, out), RAD_ERROR_NON_FINITE);
    }
    CHECK(rad_temporal_frame(tp) == frame);
    CHECK(memcmp(B0, rad_temporal_indirect(tp), sizeof(float) * 3 * N) == 0);
    /* and a good step still works after the refusals */
    CHECK_OK(rad_sources(P, RAD_SOURCE_EMISSION, NULL, E));
    CHECK_OK(rad_temporal_step(tp, E, NULL, out));
    for (i = 0; i < 3 * N; ++i) CHECK(rad__finite(out[i]));
done:
    free(E);
    free(out);
    free(B0);
    rad_temporal_destroy(tp);
    rad_alias_tables_destroy(at);
    rad_multibounce_blocks_destroy(bl);
    rad_multibounce_destroy(mb);
    rad_form_factors_destroy(ff);
    rad_bvh_destroy(b);
    rad_patches_destroy(P);
    rad_scene_destroy(S);
}

/* review: a hand-built CSR matrix with a column past the end or offsets that decrease read
   out of its arrays in rad_matrix_multiply; a hand-made system with albedo 1.5 diverged (or
   went negative in the direct solve) with success. */
static void rg_test_hand_made_systems(void)
{
    static const uint64_t offs_bad_col[4] = { 0, 1, 2, 3 }, offs_down[4] = { 0, 2, 1, 3 }, offs_start[4] = { 1, 2, 3, 3 };
    static const uint64_t offs_ok[4] = { 0, 2, 3, 4 }, offs_wide[4] = { 0, 4, 4, 4 };
    static const uint32_t cols_bad[4] = { 1, 1000000, 0, 0 }, cols_ok[4] = { 1, 2, 0, 1 }, cols_desc[4] = { 2, 1, 0, 1 };
    static const float vals[4] = { 0.25f, 0.25f, 0.5f, 0.5f };
    float x[9] = { 1, 1, 1, 1, 1, 1, 1, 1, 1 }, y[9], albedo[9], E[9] = { 1, 1, 1, 0, 0, 0, 0, 0, 0 };
    rad_matrix M;
    rad_system sys;
    rad_solve_options so;
    rad_alias_tables *at = NULL;
    uint32_t i;
    memset(&M, 0, sizeof(M));
    M.rows = M.cols = 3;
    M.storage = RAD_STORAGE_SPARSE;
    M.values = vals;
    M.row_offsets = offs_bad_col; M.columns = cols_bad;
    CHECK_RESULT(rad_matrix_multiply(&M, x, y, NULL), RAD_ERROR_CORRUPT);
    CHECK_RESULT(rad_alias_tables_create(&M, RAD_ALIAS_AUTO, NULL, &at), RAD_ERROR_CORRUPT);
    CHECK(at == NULL);
    M.row_offsets = offs_down; M.columns = cols_ok;
    CHECK_RESULT(rad_matrix_multiply(&M, x, y, NULL), RAD_ERROR_CORRUPT);
    M.row_offsets = offs_start;
    CHECK_RESULT(rad_matrix_multiply(&M, x, y, NULL), RAD_ERROR_CORRUPT);
    M.row_offsets = offs_wide; /* four entries in one row of a 3-column matrix */
    CHECK_RESULT(rad_matrix_multiply(&M, x, y, NULL), RAD_ERROR_CORRUPT);
    M.row_offsets = offs_ok; M.columns = cols_desc;
    CHECK_RESULT(rad_matrix_multiply(&M, x, y, NULL), RAD_ERROR_CORRUPT);
    M.columns = cols_ok;
    CHECK_OK(rad_matrix_multiply(&M, x, y, NULL));
    CHECK_NEAR(y[0], 0.5, 1e-6);
    CHECK_NEAR(y[3], 0.5, 1e-6);
    CHECK_NEAR(y[6], 0.5, 1e-6);
    /* the same matrix as a system: albedo 0.5 solves, 1.5 and -0.5 are refused by every solver */
    memset(&sys, 0, sizeof(sys));
    sys.F = &M;
    sys.albedo = albedo;
    sys.E = E;
    sys.n = 3;
    rad_solve_options_default(&so);
    so.bounces = 4;
    for (i = 0; i < 9; ++i) albedo[i] = 0.5f;
    CHECK_OK(rad_solve_jacobi(&sys, &so, y, NULL, NULL));
    albedo[4] = 1.5f;
    CHECK_RESULT(rad_solve_jacobi(&sys, &so, y, NULL, NULL), RAD_ERROR_ALBEDO_RANGE);
    CHECK_RESULT(rad_solve_gauss_seidel(&sys, &so, y, NULL, NULL), RAD_ERROR_ALBEDO_RANGE);
    CHECK_RESULT(rad_solve_direct(&sys, &so, y, NULL), RAD_ERROR_ALBEDO_RANGE);
    albedo[4] = -0.5f;
    CHECK_RESULT(rad_solve_jacobi(&sys, &so, y, NULL, NULL), RAD_ERROR_ALBEDO_RANGE);
    albedo[4] = (float)(HUGE_VAL - HUGE_VAL);
    CHECK_RESULT(rad_solve_direct(&sys, &so, y, NULL), RAD_ERROR_ALBEDO_RANGE);
    albedo[4] = 0.5f;
    M.columns = cols_bad;
    M.row_offsets = offs_bad_col;
    CHECK_RESULT(rad_solve_jacobi(&sys, &so, y, NULL, NULL), RAD_ERROR_CORRUPT);
}

/* scale: the BVH missed every ray of a Cornell box scaled 1e14 (the
   watertight test's t was a length^3 product that overflowed float; below 1e-13 it
   underflowed), so images came out black with success. Radiosity is scale-free: the mean
   radiosity, the direct light and the camera hits must be those of the unit box at both
   ends of the supported range, and a scene outside it is refused by name. */
/* The built-in Cornell box scaled by 'scale' (and its camera, when cam is not NULL): the
   scene copies the positions, so the scaled copies live only for the call. */
static rad_result rg_cornell_scaled(double scale, rad_camera *cam, rad_scene **out)
{
    rad_scene_desc d;
    rad_mesh_desc m[16];
    float *pos[16];
    uint32_t i, k;
    rad_result r;
    rad_camera c;
    rad_cornell_box(&d, &c);
    if (d.mesh_count > 16) return RAD_ERROR_INVALID_ARGUMENT;
    for (i = 0; i < d.mesh_count; ++i) {
        m[i] = d.meshes[i];
        pos[i] = (float *)malloc(sizeof(float) * 3 * m[i].vertex_count);
        if (pos[i])
            for (k = 0; k < 3 * m[i].vertex_count; ++k) pos[i][k] = (float)(m[i].positions[k] * scale);
        m[i].positions = pos[i];
    }
    d.meshes = m;
    r = rad_scene_create(&d, NULL, out);
    for (i = 0; i < d.mesh_count; ++i) free(pos[i]);
    for (k = 0; k < 3; ++k) {
        c.position[k] = (float)(c.position[k] * scale);
        c.target[k] = (float)(c.target[k] * scale);
    }
    if (cam) *cam = c;
    return r;
}

static int rg_scaled_cornell(double scale, double *mean_B, double *mean_direct, uint32_t *hits, rad_result *why)
{
    rad_scene *S = NULL;
    rad_patches *P = NULL;
    rad_bvh *b = NULL;
    rad_raycaster rc;
    rad_form_factors *ff = NULL;
    rad_form_factor_options fo;
    rad_patch_options po;
    rad_direct_options dop;
    rad_system sys;
    rad_solve_options so;
    rad_camera cam;
    uint32_t i;
    float *E = NULL, *B = NULL, *D = NULL;
    int ok = 0;
    *why = rg_cornell_scaled(scale, &cam, &S);
    if (*why != RAD_SUCCESS) goto out;
    rad_patch_options_default(&po);
    po.target_count = 80;
    if (rad_patches_create(S, &po, NULL, &P) != RAD_SUCCESS || rad_bvh_create(S, NULL, &b) != RAD_SUCCESS) goto out;
    (rad_bvh_raycaster)(b, &rc); /* the built-in BVH even in the Embree suite: its range is what is promised */
    rad_form_factor_options_default(&fo);
    fo.samples = 4;
    if (rad_form_factors_dense(P, &rc, &fo, NULL, &ff) != RAD_SUCCESS) goto out;
    E = (float *)calloc(3 * (size_t)P->count, sizeof(float));
    B = (float *)calloc(3 * (size_t)P->count, sizeof(float));
    D = (float *)calloc(3 * (size_t)P->count, sizeof(float));
    if (!E || !B || !D || rad_sources(P, RAD_SOURCE_EMISSION, NULL, E) != RAD_SUCCESS) goto out;
    rad_system_init(&sys, &ff->matrix, P, E);
    rad_solve_options_default(&so);
    so.bounces = 8;
    rad_direct_options_default(&dop);
    if (rad_solve_jacobi(&sys, &so, B, NULL, NULL) != RAD_SUCCESS ||
        rad_direct_patches(P, &rc, NULL, 0, &dop, D, NULL) != RAD_SUCCESS)
        goto out;
    *mean_B = *mean_direct = 0.0;
    for (i = 0; i < 3 * P->count; ++i) {
        *mean_B += (double)B[i] * P->areas[i / 3] / (scale * scale);
        *mean_direct += (double)D[i] * P->areas[i / 3] / (scale * scale);
    }
    *hits = 0;
    for (i = 0; i < 256; ++i) {
        rad_ray ray;
        rad_hit h;
        rad_camera_ray(&cam, 16, 16, (float)(i % 16) + 0.5f, (float)(i / 16) + 0.5f, &ray);
        if (rc.intersect(rc.user, &ray, 1, &h) == RAD_SUCCESS && h.triangle != RAD_NONE) ++*hits;
    }
    ok = 1;
out:
    free(E);
    free(B);
    free(D);
    rad_form_factors_destroy(ff);
    (rad_bvh_destroy)(b);
    rad_patches_destroy(P);
    rad_scene_destroy(S);
    return ok;
}

static void rg_test_scene_scale(void)
{
    /* the Cornell box's diagonal is about 0.96 units: 2e-15 and 1e18 sit just inside the range */
    static const double scales[] = { 2e-15, 1e-9, 1e9, 1e14, 1e18 };
    double B0 = 0.0, D0 = 0.0, Bs, Ds;
    uint32_t h0 = 0, hs, i;
    rad_result why = RAD_SUCCESS;
    CHECK(rg_scaled_cornell(1.0, &B0, &D0, &h0, &why));
    CHECK(h0 > 200);
    for (i = 0; i < sizeof(scales) / sizeof(scales[0]); ++i) {
        Bs = Ds = -1.0;
        hs = 0;
        CHECK(rg_scaled_cornell(scales[i], &Bs, &Ds, &hs, &why));
        CHECK_REL(Bs, B0, 1e-5);
        CHECK_REL(Ds, D0, 1e-5);
        CHECK(hs == h0);
    }
    CHECK(!rg_scaled_cornell(2e18, &Bs, &Ds, &hs, &why));
    CHECK_RESULT(why, RAD_ERROR_SCALE_RANGE);
    CHECK(!rg_scaled_cornell(5e-16, &Bs, &Ds, &hs, &why));
    CHECK_RESULT(why, RAD_ERROR_SCALE_RANGE);
}

#ifndef RAD_NO_STDIO
/* files: rad_load_file on a folder asked for a 9.2e18-byte buffer
   (OUT_OF_MEMORY), any file was read whole before its header was looked at, and a failed
   save left a partial file where the old one was. */
static void rg_test_file_io(void)
{
    rad_scene_desc d;
    rad_scene *S = NULL;
    rad_patches *P = NULL;
    rad_patch_options po;
    rad_bake *b = NULL;
    void *buf = NULL;
    size_t size = 0;
    FILE *f;
    const char *path = rad_test_path("regress_io.radb"), *other = rad_test_path("regress_io.txt");
    CHECK_RESULT(rad_load_file(".", NULL, &b), RAD_ERROR_IO);
    CHECK(b == NULL);
    f = fopen(other, "wb");
    if (f) {
        int i;
        for (i = 0; i < 100; ++i) fputs("v 0 0 0 # not a bake\n", f);
        fclose(f);
    }
    CHECK_RESULT(rad_load_file(other, NULL, &b), RAD_ERROR_CORRUPT);
    f = fopen(other, "wb");
    if (f) { fputs("RADB", f); fclose(f); }
    CHECK_RESULT(rad_load_file(other, NULL, &b), RAD_ERROR_TRUNCATED);
    remove(other);
    rad_cornell_box(&d, NULL);
    CHECK_OK(rad_scene_create(&d, NULL, &S));
    rad_patch_options_default(&po);
    po.target_count = 40;
    if (S) CHECK_OK(rad_patches_create(S, &po, NULL, &P));
    if (P) {
        CHECK_OK(rad_save_file(path, P, NULL, NULL, NULL, NULL));
        CHECK_OK(rad_save_memory(P, NULL, NULL, NULL, NULL, &buf, &size));
        /* the header says more bytes than the file holds: refused before reading it */
        f = fopen(path, "rb+");
        if (f && buf && size > 128) {
            unsigned char *copy = (unsigned char *)malloc(size);
            if (copy) {
                memcpy(copy, buf, size);
                fclose(f);
                f = fopen(path, "wb");
                if (f) { fwrite(copy, 1, size - 64, f); fclose(f); f = NULL; }
                CHECK_RESULT(rad_load_file(path, NULL, &b), RAD_ERROR_TRUNCATED);
                free(copy);
            }
        }
        if (f) fclose(f);
        /* a save over an existing file replaces it whole and leaves no temporary behind */
        CHECK_OK(rad_save_file(path, P, NULL, NULL, NULL, NULL));
        CHECK_OK(rad_load_file(path, NULL, &b));
        CHECK(b && b->patches.count == P->count);
        rad_bake_destroy(b);
        b = NULL;
        {
            char tmp[128];
            snprintf(tmp, sizeof(tmp), "%s.partial", path);
            f = fopen(tmp, "rb");
            CHECK(f == NULL);
            if (f) fclose(f);
        }
        /* a save that cannot be written reports IO and leaves nothing */
        CHECK_RESULT(rad_save_file(rad_test_path("no-such-folder/x/out.radb"), P, NULL, NULL, NULL, NULL), RAD_ERROR_IO);
        f = fopen(rad_test_path("no-such-folder/x/out.radb.partial"), "rb");
        CHECK(f == NULL);
        if (f) fclose(f);
    }
    remove(path);
    rad_free_buffer(buf, NULL);
    rad_patches_destroy(P);
    rad_scene_destroy(S);
}
#endif

/* option ranges: ray_epsilon 0.3 or 1e30 was accepted (rays then start past
   the walls: row sums above 1, energy from nowhere), and rad_direct_irradiance scaled its
   answer by the length of the normal it was given (a zero normal gave 0 with success). */
static void rg_test_epsilon_and_normals(void)
{
    rad_scene_desc d;
    rad_scene *S = NULL;
    rad_patches *P = NULL;
    rad_bvh *b = NULL;
    rad_raycaster rc;
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_direct_options dop;
    rad_vp_options vo;
    rad_form_factors *ff = NULL;
    rad_virtual_patches *vp = NULL;
    rad_light l;
    float p[3] = { 0.25f, 0.001f, 0.25f }, n1[3] = { 0.0f, 1.0f, 0.0f }, n2[3] = { 0.0f, 1e-30f, 0.0f };
    float n3[3] = { 0.0f, 1e20f, 0.0f }, n0[3] = { 0.0f, 0.0f, 0.0f }, e1[3], e2[3], e3[3];
    rad_cornell_box(&d, NULL);
    CHECK_OK(rad_scene_create(&d, NULL, &S));
    rad_patch_options_default(&po);
    po.target_count = 30;
    if (S) CHECK_OK(rad_patches_create(S, &po, NULL, &P));
    if (S) CHECK_OK(rad_bvh_create(S, NULL, &b));
    if (!P || !b) goto done;
    rad_bvh_raycaster(b, &rc);
    rad_form_factor_options_default(&fo);
    fo.ray_epsilon = 0.3f;
    CHECK_RESULT(rad_form_factors_dense(P, &rc, &fo, NULL, &ff), RAD_ERROR_INVALID_ARGUMENT);
    fo.ray_epsilon = 1e30f;
    CHECK_RESULT(rad_form_factors_dense(P, &rc, &fo, NULL, &ff), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(ff == NULL);
    fo.ray_epsilon = 1e-2f; /* the largest accepted */
    fo.samples = 1;
    CHECK_OK(rad_form_factors_dense(P, &rc, &fo, NULL, &ff));
    rad_vp_options_default(&vo);
    vo.resolution = 2;
    vo.ray_epsilon = 0.5f;
    CHECK_RESULT(rad_vp_create(S, &rc, &vo, NULL, &vp), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(vp == NULL);
    memset(&l, 0, sizeof(l));
    l.type = RAD_LIGHT_POINT;
    l.color[0] = l.color[1] = l.color[2] = 1.0f;
    l.position[0] = 0.25f;
    l.position[1] = 0.4f;
    l.position[2] = 0.25f;
    rad_direct_options_default(&dop);
    dop.ray_epsilon = 0.05f;
    CHECK_RESULT(rad_direct_irradiance(S, &rc, &l, 1, &dop, p, n1, 1, e1, NULL), RAD_ERROR_INVALID_ARGUMENT);
    rad_direct_options_default(&dop);
    CHECK_OK(rad_direct_irradiance(S, &rc, &l, 1, &dop, p, n1, 1, e1, NULL));
    CHECK_OK(rad_direct_irradiance(S, &rc, &l, 1, &dop, p, n2, 1, e2, NULL));
    CHECK_OK(rad_direct_irradiance(S, &rc, &l, 1, &dop, p, n3, 1, e3, NULL));
    CHECK(e1[0] > 0.0f);
    CHECK_REL(e2[0], e1[0], 1e-6);
    CHECK_REL(e3[1], e1[1], 1e-6);
    CHECK_RESULT(rad_direct_irradiance(S, &rc, &l, 1, &dop, p, n0, 1, e1, NULL), RAD_ERROR_INVALID_ARGUMENT);
done:
    rad_form_factors_destroy(ff);
    rad_bvh_destroy(b);
    rad_patches_destroy(P);
    rad_scene_destroy(S);
}

/* errors name their cause: a raycaster callback's failure came back as RAYCAST_FAILED
   with nothing in the log, so a user could not tell which call or why. */
static int rg_log_lines;
static char rg_log_last[512];
static void rg_log(void *user, rad_log_level level, const char *message)
{
    (void)user;
    (void)level;
    rg_log_lines++;
    snprintf(rg_log_last, sizeof(rg_log_last), "%s", message);
}
static rad_result rg_failing_occluded(void *user, const rad_ray *rays, uint32_t count, uint8_t *out)
{
    (void)user; (void)rays; (void)count; (void)out;
    return RAD_ERROR_IO;
}

static void rg_test_raycaster_failure_logged(void)
{
    rad_scene_desc d;
    rad_scene *S = NULL;
    rad_patches *P = NULL;
    rad_patch_options po;
    rad_raycaster rc;
    rad_form_factors *ff = NULL;
    rad_context ctx;
    float *D = NULL;
    memset(&ctx, 0, sizeof(ctx));
    ctx.log = rg_log;
    rad_cornell_box(&d, NULL);
    CHECK_OK(rad_scene_create(&d, NULL, &S));
    rad_patch_options_default(&po);
    po.target_count = 30;
    if (S) CHECK_OK(rad_patches_create(S, &po, NULL, &P));
    if (!P) goto done;
    memset(&rc, 0, sizeof(rc));
    rc.occluded = rg_failing_occluded;
    rg_log_lines = 0;
    CHECK_RESULT(rad_form_factors_dense(P, &rc, NULL, &ctx, &ff), RAD_ERROR_RAYCAST_FAILED);
    CHECK(rg_log_lines >= 1 && strstr(rg_log_last, "ray query callback") != NULL);
    D = (float *)malloc(sizeof(float) * 3 * P->count);
    rg_log_lines = 0;
    if (D) CHECK_RESULT(rad_direct_patches(P, &rc, NULL, 0, NULL, D, &ctx), RAD_ERROR_RAYCAST_FAILED);
    CHECK(rg_log_lines >= 1 && strstr(rg_log_last, "ray query callback") != NULL);
done:
    free(D);
    rad_form_factors_destroy(ff);
    rad_patches_destroy(P);
    rad_scene_destroy(S);
}

/* scale: virtual patches failed at scale 1e12 (NaN form factors,
   reported as if the lights were too strong) and lost half the light at 1e-12 without a word:
   the pair kernel multiplied two sample areas (length^4) in float. */
static double rg_vp_mean(double scale, rad_result *why)
{
    rad_scene *S = NULL;
    rad_bvh *b = NULL;
    rad_raycaster rc;
    rad_vp_options vo;
    rad_virtual_patches *vp = NULL;
    rad_system sys;
    rad_solve_options so;
    uint32_t i;
    float *E = NULL, *B = NULL;
    double mean = -1.0;
    *why = rg_cornell_scaled(scale, NULL, &S);
    if (*why == RAD_SUCCESS) *why = rad_bvh_create(S, NULL, &b);
    if (*why != RAD_SUCCESS) goto out;
    (rad_bvh_raycaster)(b, &rc);
    rad_vp_options_default(&vo);
    vo.resolution = 4;
    *why = rad_vp_create(S, &rc, &vo, NULL, &vp);
    if (*why != RAD_SUCCESS) goto out;
    E = (float *)calloc(3 * (size_t)vp->count, sizeof(float));
    B = (float *)calloc(3 * (size_t)vp->count, sizeof(float));
    if (!E || !B) goto out;
    *why = rad_vp_sources(vp, &rc, NULL, 0, NULL, RAD_SOURCE_DIRECT, E, NULL);
    if (*why != RAD_SUCCESS) goto out;
    rad_vp_system(&sys, vp, E);
    rad_solve_options_default(&so);
    so.bounces = 8;
    so.output = RAD_OUTPUT_TOTAL;
    *why = rad_solve_jacobi(&sys, &so, B, NULL, NULL);
    if (*why != RAD_SUCCESS) goto out;
    mean = 0.0;
    for (i = 0; i < 3 * vp->count; ++i) mean += (double)B[i] * sys.areas[i / 3] / (scale * scale);
out:
    free(E);
    free(B);
    rad_vp_destroy(vp);
    (rad_bvh_destroy)(b);
    rad_scene_destroy(S);
    return mean;
}

static void rg_test_vp_scale(void)
{
    rad_result why = RAD_SUCCESS;
    double m0 = rg_vp_mean(1.0, &why), m;
    CHECK_OK(why);
    CHECK(m0 > 0.0);
    m = rg_vp_mean(1e-12, &why);
    CHECK_OK(why);
    CHECK_REL(m, m0, 1e-4);
    m = rg_vp_mean(1e12, &why);
    CHECK_OK(why);
    CHECK_REL(m, m0, 1e-4);
}

static const rad_test_case tests_regress[] = {
    { "regress_point_light_overflow", rg_test_point_light_overflow },
    { "regress_emission_overflow", rg_test_emission_overflow },
    { "regress_extreme_area_ratio", rg_test_extreme_area_ratio },
    { "regress_nonfinite_products", rg_test_nonfinite_products },
    { "regress_hand_made_systems", rg_test_hand_made_systems },
    { "regress_scene_scale", rg_test_scene_scale },
    { "regress_vp_scale", rg_test_vp_scale },
    { "regress_epsilon_and_normals", rg_test_epsilon_and_normals },
    { "regress_raycaster_failure_logged", rg_test_raycaster_failure_logged },
#ifndef RAD_NO_STDIO
    { "regress_file_io", rg_test_file_io },
#endif
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_regress)

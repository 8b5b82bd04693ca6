/* test_regress.c - regressions found by fuzzing and review, one test each, with where they
   came from. The fuzzers' crash inputs live in fuzz/crashes and are replayed by the fuzz
   smoke suite. */

/* fuzz_scene, fuzz/crashes/scene-nonfinite-1: a point light 1e-20 from a surface gave
   irradiance 1/d^2 = inf (here a 1e-15 quad with the light 1e-21 above it). Outputs must never carry Inf: the call reports NON_FINITE. */
static void rg_test_point_light_overflow(void)
{
    static const float quad[12] = { 0, 0, 0, 1e-15f, 0, 0, 1e-15f, 1e-15f, 0, 0, 1e-15f, 0 };
    static const uint32_t idx[6] = { 0, 1, 2, 0, 2, 3 };
    rad_material m = { { 0.5f, 0.5f, 0.5f }, { 0.0f, 0.0f, 0.0f }, 0 };
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
    rad_material m = { { 0.5f, 0.5f, 0.5f }, { 3e38f, 0.0f, 0.0f }, 0 };
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

/* fuzz_scene, fuzz/crashes/scene-ff-nonfinite: a patch of area 4e-38 beside patches of area
   1e3: the reciprocity factor A_j / A_i overflowed float and 0 * inf gave NaN form factors.
   Pairs are now integrated from the smaller patch, so the factor is at most 1. */
static void rg_test_extreme_area_ratio(void)
{
    /* a big quad facing +z and, above it, a tiny triangle facing down (area about 1e-37) */
    static const float pos[15] = { -30, -30, 0, 30, -30, 0, 30, 30, 0, -30, 30, 0,  0, 0, 0 };
    float tri[9] = { 0.0f, 0.0f, 1.0f, 0.0f, 4.5e-19f, 1.0f, 4.5e-19f, 0.0f, 1.0f };
    static const uint32_t qi[6] = { 0, 1, 2, 0, 2, 3 };
    static const uint32_t ti[3] = { 0, 1, 2 };
    rad_material m = { { 0.5f, 0.5f, 0.5f }, { 1.0f, 1.0f, 1.0f }, 0 };
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

static const rad_test_case tests_regress[] = {
    { "regress_point_light_overflow", rg_test_point_light_overflow },
    { "regress_emission_overflow", rg_test_emission_overflow },
    { "regress_extreme_area_ratio", rg_test_extreme_area_ratio },
    { NULL, NULL }
};

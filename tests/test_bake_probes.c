/* test_bake_probes.c - the baker's probe options (rad_baker_desc.probe_options, PROBE OPTIONS
   in docs/methods/bake.md): RAD_PROBES_DIRECT adds each group's direct light (the difference
   to the bounced-only bake is rad_probes_create's direct term, and a group's layer is the bake
   of that group alone, bit for bit, band 4 included), and the errors of bad options. Included
   by test_main.c after the implementation: every name is static and prefixed bp_. */
#include "fixtures.h"

static void bp_lamp(rad_light *l)
{
    memset(l, 0, sizeof(*l));
    l->type = RAD_LIGHT_POINT;
    l->position[0] = 0.28f; l->position[1] = 0.35f; l->position[2] = 0.28f;
    l->color[0] = l->color[1] = l->color[2] = 0.05f;
}

static void bp_options(rad_baker_options *o)
{
    memset(o, 0, sizeof(*o));
    o->method = RAD_BAKER_CLASSIC;
    o->patches = 120;
    o->ff_samples = 4;
    o->bounces = 8;
    o->light_samples = 8;
}

static void bp_probe_options(rad_probe_options *po, uint32_t flags)
{
    rad_probe_options_default(po);
    po->spacing = 0.18f;
    po->rays = 64;
    po->flags = flags;
}

/* DIRECT minus bounced only = the direct term of rad_probes_create on the same patches */
static void bp_test_direct_term(void)
{
    rad_baker_desc d;
    rad_baker_options o;
    rad_baker_light bl;
    rad_probe_options pi, pd;
    rad_baker_result *I = NULL, *T = NULL;
    rad_scene *S = NULL;
    rad_bvh *bvh = NULL;
    rad_patches *P = NULL;
    rad_probes *Dp = NULL;
    rad_patch_options po;
    rad_raycaster rc;
    float *zero = NULL;
    uint32_t i, bad = 0, lit = 0;
    memset(&d, 0, sizeof d);
    rad_cornell_box(&d.scene, NULL);
    bp_lamp(&bl.light);
    bl.group = 0;
    d.lights = &bl;
    d.light_count = 1;
    d.outputs = RAD_BAKER_PROBES;
    bp_options(&o);
    bp_probe_options(&pi, 0);
    bp_probe_options(&pd, RAD_PROBES_DIRECT);
    d.probe_options = &pi;
    CHECK_OK(rad_baker_run(&d, &o, NULL, &I));
    d.probe_options = &pd;
    CHECK_OK(rad_baker_run(&d, &o, NULL, &T));
    CHECK_OK(rad_scene_create(&d.scene, NULL, &S));
    if (S) CHECK_OK(rad_bvh_create(S, NULL, &bvh));
    rad_patch_options_default(&po);
    po.target_count = o.patches;
    if (S) CHECK_OK(rad_patches_create(S, &po, NULL, &P));
    if (!I || !T || !P || !bvh) goto done;
    (rad_bvh_raycaster)(bvh, &rc);
    CHECK(I->probe_count == T->probe_count && I->probe_count > 8);
    CHECK(I->probe_band4 == NULL);
    zero = (float *)calloc(3 * (size_t)P->count, sizeof(float));
    if (!zero) goto done;
    CHECK_OK(rad_probes_create(P, &rc, &bl.light, 1, NULL, 0, &pd, zero, NULL, &Dp));
    if (!Dp) goto done;
    CHECK(rad_probes_count(Dp) == T->probe_count);
    for (i = 0; i < 27 * T->probe_count; ++i) {
        float want = I->probes[i] + rad_probes_coefficients(Dp)[i];
        if (fabsf(T->probes[i] - want) > 1e-5f * (fabsf(want) + 1e-3f)) ++bad;
    }
    for (i = 0; i < T->probe_count; ++i) lit += rad_probes_coefficients(Dp)[27 * (size_t)i] > 0.0f;
    CHECK(bad == 0);
    CHECK(lit > T->probe_count / 2); /* the lamp lights most probes directly */
done:
    free(zero);
    rad_probes_destroy(Dp);
    rad_patches_destroy(P);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(S);
    rad_baker_result_destroy(I);
    rad_baker_result_destroy(T);
}

/* Two groups (the ceiling light 0, the lamp 1) with DIRECT and band 4: each layer is the
   bake of its group alone, bit for bit, and the mix at scale 1 their sum; classic patches and
   virtual patches. */
static void bp_direct_groups(rad_baker_method method)
{
    rad_baker_desc d, dl, de;
    rad_baker_options o;
    rad_baker_light bl;
    rad_probe_options pd;
    rad_baker_result *A = NULL, *Bl = NULL, *Be = NULL;
    rad_material mats[16];
    uint32_t i, bad = 0;
    size_t n;
    memset(&d, 0, sizeof d);
    rad_cornell_box(&d.scene, NULL);
    bp_lamp(&bl.light);
    bl.group = 1;
    d.lights = &bl;
    d.light_count = 1;
    d.outputs = RAD_BAKER_PROBES;
    bp_probe_options(&pd, RAD_PROBES_DIRECT | RAD_PROBES_BAND4);
    d.probe_options = &pd;
    bp_options(&o);
    o.method = method;
    o.vp_resolution = 4;
    CHECK_OK(rad_baker_run(&d, &o, NULL, &A));
    if (A) CHECK(A->method == method);
    dl = d;
    CHECK(d.scene.material_count <= 16);
    for (i = 0; i < d.scene.material_count && i < 16; ++i) {
        mats[i] = d.scene.materials[i];
        mats[i].emission[0] = mats[i].emission[1] = mats[i].emission[2] = 0.0f;
    }
    dl.scene.materials = mats;
    bl.group = 0;
    CHECK_OK(rad_baker_run(&dl, &o, NULL, &Bl));
    de = d;
    de.lights = NULL;
    de.light_count = 0;
    CHECK_OK(rad_baker_run(&de, &o, NULL, &Be));
    if (!A || !Bl || !Be) goto done;
    CHECK(A->probe_band4 && A->probe_band4_layers && Bl->probe_band4 && Be->probe_band4);
    if (!A->probe_band4 || !Bl->probe_band4 || !Be->probe_band4) goto done;
    n = 27 * (size_t)A->probe_count;
    CHECK(memcmp(A->probe_layers, Be->probes, n * sizeof(float)) == 0);
    CHECK(memcmp(A->probe_layers + n, Bl->probes, n * sizeof(float)) == 0);
    CHECK(memcmp(A->probe_band4_layers, Be->probe_band4, n * sizeof(float)) == 0);
    CHECK(memcmp(A->probe_band4_layers + n, Bl->probe_band4, n * sizeof(float)) == 0);
    for (i = 0; i < n; ++i)
        if (A->probes[i] != Be->probes[i] + Bl->probes[i] || A->probe_band4[i] != Be->probe_band4[i] + Bl->probe_band4[i]) ++bad;
    CHECK(bad == 0);
done:
    rad_baker_result_destroy(A);
    rad_baker_result_destroy(Bl);
    rad_baker_result_destroy(Be);
}

static void bp_test_direct_groups(void)
{
    bp_direct_groups(RAD_BAKER_CLASSIC);
    bp_direct_groups(RAD_BAKER_VIRTUAL_PATCHES);
}

static void bp_test_bad_input(void)
{
    rad_baker_desc d;
    rad_baker_options o;
    rad_baker_light bl;
    rad_probe_options pd;
    rad_baker_result *R = NULL;
    rad_baker_runtime *rt = NULL;
    memset(&d, 0, sizeof d);
    rad_cornell_box(&d.scene, NULL);
    bp_lamp(&bl.light);
    bl.group = 0;
    d.lights = &bl;
    d.light_count = 1;
    d.outputs = RAD_BAKER_PROBES;
    bp_options(&o);
    bp_probe_options(&pd, 0);
    pd.rays = 70000; /* beyond rad_probes_create's 65536 */
    d.probe_options = &pd;
    CHECK_RESULT(rad_baker_run(&d, &o, NULL, &R), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(R == NULL);
    /* a grid past rad_probes_create's 2^24 probes is named before any work */
    bp_probe_options(&pd, 0);
    d.probe_spacing = 1e-4f;
    CHECK_RESULT(rad_baker_run(&d, &o, NULL, &R), RAD_ERROR_SIZE_OVERFLOW);
    CHECK(R == NULL);
    d.probe_spacing = 0.0f;
    /* the runtime refreshes the bounced L2 light only: DIRECT and band 4 are refused */
    bp_probe_options(&pd, RAD_PROBES_DIRECT);
    CHECK_OK(rad_baker_run(&d, &o, NULL, &R));
    if (R) {
        CHECK_RESULT(rad_baker_runtime_create(&d, &o, R, NULL, NULL, &rt), RAD_ERROR_INVALID_ARGUMENT);
        CHECK(rt == NULL);
        rad_baker_runtime_destroy(rt);
        rad_baker_result_destroy(R);
    }
}

static const rad_test_case tests_bake_probes[] = {
    { "bake_probes_direct_term", bp_test_direct_term },
    { "bake_probes_direct_groups", bp_test_direct_groups },
    { "bake_probes_bad_input", bp_test_bad_input },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_bake_probes)

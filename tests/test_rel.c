/* test_rel.c - reliability at the edges of the number range: row sums too small for a float
   reciprocal, run-time outputs that are not finite, user vectors too long for their squared
   length, and the safe write of rad_save_file. Included by test_main.c after the
   implementation: every name is static and prefixed rl_. */
#include "fixtures.h"

#include <math.h>

/* the Cornell box cut into about 'target' patches */
static int rl_cornell_patches(uint32_t target, rad_scene **scene, rad_patches **P)
{
    rad_scene_desc d;
    rad_patch_options po;
    *scene = NULL;
    *P = NULL;
    rad_cornell_box(&d, NULL);
    if (rad_scene_create(&d, NULL, scene) != RAD_SUCCESS) return 0;
    rad_patch_options_default(&po);
    po.target_count = target;
    if (rad_patches_create(*scene, &po, NULL, P) != RAD_SUCCESS) {
        rad_scene_destroy(*scene);
        *scene = NULL;
        return 0;
    }
    return 1;
}

/* rad_patches_vertex_irradiance: H_v = [sum A H / sum A S] S_v, so the row sums cancel when
   they are equal at every patch: H = 100 everywhere must give 100 at every vertex whatever
   the common S, also one whose float reciprocal overflows (1e-38) and a denormal (1e-45).
   With half the patches at a denormal S and the rest at 1, a vertex touching an S = 1
   patch sees the uncovered mean: still finite and at most H times the area ratio. */
static void rl_test_vertex_irradiance_tiny_rows(void)
{
    static const float svals[4] = { 1.0f, 1e-30f, 1e-38f, 1e-45f };
    rad_scene *scene;
    rad_patches *P;
    float *H, *S, *hv;
    uint32_t i, t, k;
    if (!rl_cornell_patches(100, &scene, &P)) { CHECK(!"cornell patches"); return; }
    H = (float *)malloc(sizeof(float) * 3 * P->count);
    S = (float *)malloc(sizeof(float) * P->count);
    hv = (float *)malloc(sizeof(float) * 3 * P->vertex_count);
    if (H && S && hv) {
        for (i = 0; i < 3 * P->count; ++i) H[i] = 100.0f;
        for (t = 0; t < 4; ++t) {
            uint32_t wrong = 0;
            for (i = 0; i < P->count; ++i) S[i] = svals[t];
            CHECK_OK(rad_patches_vertex_irradiance(P, H, S, hv, NULL));
            for (i = 0; i < 3 * P->vertex_count; ++i) wrong += !(fabsf(hv[i] - 100.0f) <= 1e-3f);
            CHECK(wrong == 0);
        }
        for (i = 0; i < P->count; ++i) S[i] = (i & 1) ? 1e-45f : 1.0f;
        CHECK_OK(rad_patches_vertex_irradiance(P, H, S, hv, NULL));
        for (i = 0; i < P->vertex_count; ++i)
            for (k = 0; k < 3; ++k) CHECK(isfinite(hv[3 * i + k]) && hv[3 * i + k] >= 0.0f);
        /* an H whose vertex value leaves the float range is refused, not returned as Inf */
        for (i = 0; i < P->count; ++i) S[i] = (i & 1) ? 1e-45f : 1.0f;
        for (i = 0; i < 3 * P->count; ++i) H[i] = 3e38f;
        CHECK_RESULT(rad_patches_vertex_irradiance(P, H, S, hv, NULL), RAD_ERROR_NON_FINITE);
    }
    free(H);
    free(S);
    free(hv);
    rad_patches_destroy(P);
    rad_scene_destroy(scene);
}

static const rad_test_case tests_rel[] = {
    { "rel_vertex_irradiance_tiny_rows", rl_test_vertex_irradiance_tiny_rows },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_rel)

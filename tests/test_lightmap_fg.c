/* test_lightmap_fg.c - the lightmap's final gather (rad_lightmap_final_gather, and the engine
   tier's rad_baker_options.lightmap_final_gather): the tier's texels equal the lower-level
   call over the kept solution bit for bit (classic and virtual patches), the traced bounce
   moves the texels, and the refusals. Included by test_main.c after the implementation: every
   name is static and prefixed lfg_. */
#include "fixtures.h"

/* The inside of a unit box (4 x 4 cells a face), each face a cell of a 3 x 2 lightmap atlas,
   lit by a point light under the ceiling; the arrays live in *s. */
typedef struct lfg_scene {
    vp_scene box;
    float luv[6][2 * 25];
    rad_baker_light light;
    rad_baker_desc d;
} lfg_scene;

static void lfg_scene_make(lfg_scene *s)
{
    uint32_t q, i, j;
    memset(s, 0, sizeof *s);
    vp_box(&s->box, 1.0f, 1.0f, 1.0f, 4, 0);
    for (q = 0; q < 6; ++q) {
        float u0 = (float)(q % 3) / 3.0f + 0.02f, v0 = (float)(q / 3) / 2.0f + 0.02f;
        for (j = 0; j <= 4; ++j)
            for (i = 0; i <= 4; ++i) {
                s->luv[q][2 * (j * 5 + i)] = u0 + 0.29f * (float)i / 4.0f;
                s->luv[q][2 * (j * 5 + i) + 1] = v0 + 0.46f * (float)j / 4.0f;
            }
        s->box.meshes[q].lightmap_uvs = s->luv[q];
    }
    vp_desc(&s->box, &s->d.scene, 0.6f, 0.0f);
    s->light.light.type = RAD_LIGHT_POINT;
    s->light.light.position[0] = 0.3f;
    s->light.light.position[1] = 0.85f;
    s->light.light.position[2] = 0.4f;
    s->light.light.color[0] = s->light.light.color[1] = s->light.light.color[2] = 0.5f;
    s->d.lights = &s->light;
    s->d.light_count = 1;
    s->d.outputs = RAD_BAKER_LIGHTMAP;
    s->d.lightmap_width = s->d.lightmap_height = 48;
}

static void lfg_options(rad_baker_options *o, rad_baker_method method)
{
    memset(o, 0, sizeof *o);
    o->method = method;
    o->patches = 48;
    o->vp_resolution = 4;
    o->ff_samples = 4;
    o->bounces = 8;
    o->light_samples = 4;
    o->lightmap_samples = 2;
    o->seed = 7;
    o->keep = 1;
}

/* the lookup of the lower-level call: the kept solution's H (rad_baker_irradiance) */
static rad_result lfg_lookup(void *user, const rad_hit *hits, const float *points, const float *normals, uint32_t count,
                             float *out)
{
    return rad_baker_irradiance((const rad_baker_result *)user, hits, points, normals, count, out, NULL);
}

/* For classic patches and virtual patches: a bake with lightmap_final_gather gives the texels
   of rad_lightmap_final_gather over the kept texels and solution of the bake without it, then
   rad_lightmap_dilate, bit for bit; and the traced bounce changes the texels (the first bounce
   no longer the patches' average) without changing their scale much. */
static void lfg_test_lower_level(void)
{
    int pass;
    for (pass = 0; pass < 2; ++pass) {
        lfg_scene s;
        rad_baker_options o;
        rad_baker_result *A = NULL, *B = NULL;
        const rad_lightmap *lm;
        rad_bvh *bvh = NULL;
        rad_raycaster rc;
        rad_final_gather_options fo;
        float *mine = NULL;
        size_t i, count;
        double plain = 0.0, traced = 0.0, diff = 0.0;
        lfg_scene_make(&s);
        lfg_options(&o, pass ? RAD_BAKER_VIRTUAL_PATCHES : RAD_BAKER_CLASSIC);
        s.d.outputs = RAD_BAKER_LIGHTMAP | RAD_BAKER_SOLUTION;
        CHECK_OK(rad_baker_run(&s.d, &o, NULL, &A));
        o.lightmap_final_gather = 24;
        CHECK_OK(rad_baker_run(&s.d, &o, NULL, &B));
        if (!A || !B) goto next;
        lm = rad_baker_result_lightmap(A);
        CHECK(lm != NULL && lm->valid_texels > 500);
        if (!lm) goto next;
        count = 3 * (size_t)lm->width * lm->height;
        CHECK_OK(rad_bvh_create(lm->scene, NULL, &bvh));
        mine = (float *)malloc(count * sizeof(float));
        if (!bvh || !mine) goto next;
        (rad_bvh_raycaster)(bvh, &rc); /* the library's own, as the tier's */
        rad_final_gather_options_default(&fo);
        fo.rays = 24;
        fo.seed = o.seed; /* the bake's seed plus group 0 */
        CHECK_OK(rad_lightmap_final_gather(lm, &rc, &s.light.light, 1, &fo, lfg_lookup, A, mine, NULL));
        CHECK_OK(rad_lightmap_dilate(lm, 3, mine, 0, NULL));
        CHECK(memcmp(mine, B->lightmap, count * sizeof(float)) == 0);
        for (i = 0; i < count; ++i) {
            plain += A->lightmap[i];
            traced += B->lightmap[i];
            diff += fabs((double)A->lightmap[i] - (double)B->lightmap[i]);
        }
        if (getenv("RAD_TEST_VERBOSE"))
            printf("    %s: sum %g plain, %g traced, |difference| %g\n", pass ? "vp" : "classic", plain, traced, diff);
        CHECK(plain > 0.0 && traced > 0.8 * plain && traced < 1.25 * plain && diff > 1e-3 * plain);
    next:
        free(mine);
        rad_bvh_destroy(bvh);
        rad_baker_result_destroy(A);
        rad_baker_result_destroy(B);
    }
}

/* the specific errors: too many rays, the SH encoding, a runtime over such a bake, and the
   lower-level call's own checks */
static void lfg_test_refusals(void)
{
    lfg_scene s;
    rad_baker_options o;
    rad_lightmap_gather_options go;
    rad_baker_result *R = NULL;
    rad_baker_runtime *rt = NULL;
    rad_context ctx;
    fx_err_log lg;
    float out[3];
    lfg_scene_make(&s);
    lfg_options(&o, RAD_BAKER_CLASSIC);
    memset(&ctx, 0, sizeof ctx);
    memset(&lg, 0, sizeof lg);
    ctx.log = fx_err_log_fn;
    ctx.log_user = &lg;
    o.lightmap_final_gather = 5000;
    CHECK_RESULT(rad_baker_run(&s.d, &o, &ctx, &R), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(R == NULL && strstr(lg.last, "lightmap_final_gather") != NULL);
    o.lightmap_final_gather = 8;
    rad_lightmap_gather_options_default(&go);
    go.encoding = RAD_LIGHTMAP_SH_L1;
    s.d.lightmap_gather = &go;
    lg.last[0] = 0;
    CHECK_RESULT(rad_baker_run(&s.d, &o, &ctx, &R), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(R == NULL && strstr(lg.last, "SH encoding") != NULL);
    s.d.lightmap_gather = NULL;
    CHECK_OK(rad_baker_run(&s.d, &o, NULL, &R));
    if (R) {
        lg.last[0] = 0;
        CHECK_RESULT(rad_baker_runtime_create(&s.d, &o, R, NULL, &ctx, &rt), RAD_ERROR_INVALID_ARGUMENT);
        CHECK(rt == NULL && strstr(lg.last, "lightmap_final_gather") != NULL);
        if (rad_baker_result_lightmap(R)) {
            rad_final_gather_options fo;
            rad_bvh *bvh = NULL;
            rad_raycaster rc;
            CHECK_RESULT(rad_lightmap_final_gather(NULL, NULL, NULL, 0, NULL, NULL, NULL, out, &ctx),
                         RAD_ERROR_INVALID_ARGUMENT);
            CHECK_OK(rad_bvh_create(rad_baker_result_lightmap(R)->scene, NULL, &bvh));
            if (bvh) {
                rad_bvh_raycaster(bvh, &rc);
                rad_final_gather_options_default(&fo);
                fo.rays = 4097;
                lg.last[0] = 0;
                CHECK_RESULT(rad_lightmap_final_gather(rad_baker_result_lightmap(R), &rc, NULL, 0, &fo, NULL, NULL, out, &ctx),
                             RAD_ERROR_INVALID_ARGUMENT);
                CHECK(strstr(lg.last, "4096") != NULL);
            }
            rad_bvh_destroy(bvh);
        }
    }
    rad_baker_runtime_destroy(rt);
    rad_baker_result_destroy(R);
}

static const rad_test_case tests_lightmap_fg[] = {
    { "lightmap_fg_lower_level", lfg_test_lower_level },
    { "lightmap_fg_refusals", lfg_test_refusals },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_lightmap_fg)

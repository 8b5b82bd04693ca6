/* test_baker_lightmap.c - the engine tier's lightmap options (LIGHTMAP OPTIONS in >>api_bake):
   the gather's options and SH encoding, direct light per texel and seam stitching against the
   same steps made with the lower-level lightmap calls (bit for bit), the exact-gather
   threshold, the kept texels, and the refusals. Included by test_main.c after the
   implementation: every name is static and prefixed blm_. */
#include "fixtures.h"

static int blm_same_bits(const float *a, const float *b, size_t n)
{
    return memcmp(a, b, n * sizeof(float)) == 0;
}

/* A floor of two triangles whose lightmap charts meet at one seam (the diagonal; the second
   side mirrored at half the texel density, as lm_test_seam), a lamp above it and a point
   light, all in group 0. The arrays live in *s. */
typedef struct blm_scene {
    float floor[18], luv[12];
    rad_mesh_desc m[2];
    rad_material mats[2];
    rad_baker_light light;
    rad_baker_desc d;
} blm_scene;

static void blm_scene_make(blm_scene *s)
{
    static const float lamp[12] = { 0.3f, 0.9f, 0.3f, 0.3f, 0.9f, 0.7f, 0.7f, 0.9f, 0.7f, 0.7f, 0.9f, 0.3f };
    static const uint32_t lidx[6] = { 0, 2, 1, 0, 3, 2 }; /* facing down, to the floor */
    const float corner[12] = { 0, 0, 0, 0, 0, 1, 1, 0, 1, 1, 0, 0 };
    const int tri[6] = { 0, 1, 2, 0, 2, 3 };
    int v, k;
    memset(s, 0, sizeof *s);
    for (v = 0; v < 6; ++v) {
        const float *p = corner + 3 * tri[v];
        for (k = 0; k < 3; ++k) s->floor[3 * v + k] = p[k];
        if (v < 3) s->luv[2 * v] = 0.05f + 0.4f * p[2], s->luv[2 * v + 1] = 0.05f + 0.8f * p[0];
        else s->luv[2 * v] = 0.95f - 0.2f * p[0], s->luv[2 * v + 1] = 0.05f + 0.4f * p[2];
    }
    s->m[0].positions = s->floor;
    s->m[0].vertex_count = 6;
    s->m[0].triangle_count = 2;
    s->m[0].lightmap_uvs = s->luv;
    s->m[1].positions = lamp;
    s->m[1].vertex_count = 4;
    s->m[1].indices = lidx;
    s->m[1].triangle_count = 2;
    s->m[1].material = 1;
    for (k = 0; k < 3; ++k) {
        s->mats[0].albedo[k] = s->mats[1].albedo[k] = 0.5f;
        s->mats[1].emission[k] = 5.0f;
    }
    s->light.light.type = RAD_LIGHT_POINT;
    s->light.light.position[0] = 0.8f;
    s->light.light.position[1] = 0.5f;
    s->light.light.position[2] = 0.2f;
    s->light.light.color[0] = s->light.light.color[1] = s->light.light.color[2] = 0.3f;
    s->d.scene.meshes = s->m;
    s->d.scene.mesh_count = 2;
    s->d.scene.materials = s->mats;
    s->d.scene.material_count = 2;
    s->d.lights = &s->light;
    s->d.light_count = 1;
    s->d.outputs = RAD_BAKER_LIGHTMAP;
    s->d.lightmap_width = s->d.lightmap_height = 40;
}

static void blm_options(rad_baker_options *o)
{
    memset(o, 0, sizeof *o);
    o->method = RAD_BAKER_CLASSIC;
    o->patches = 60;
    o->ff_samples = 4;
    o->bounces = 8;
    o->light_samples = 4;
    o->lightmap_samples = 2;
    o->keep = 1;
}

/* The tier's lightmap for desc d and options o made with the lower-level calls: patches,
   dense F, the direct light as the source, Jacobi, B = E + L, the texels, the gather with go,
   the direct light per texel (DIRECT), dilation, stitching (STITCH). Into out (channels per
   texel of go's encoding); 0 when a step failed. */
static int blm_lower_level(const rad_baker_desc *d, const rad_baker_options *o, const rad_lightmap_gather_options *go,
                           float *out, rad_lightmap_seam_stats *st)
{
    rad_scene *S = NULL;
    rad_bvh *bvh = NULL;
    rad_patches *P = NULL;
    rad_form_factors *ff = NULL;
    rad_lightmap *lm = NULL;
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_direct_options dopt;
    rad_solve_options so;
    rad_lightmap_options lo;
    rad_raycaster rc;
    rad_system sys;
    float *D = NULL, *E = NULL, *L = NULL;
    uint32_t i, n, ch = rad_lightmap_channels(go->encoding);
    int ok = 0;
    CHECK_OK(rad_scene_create(&d->scene, NULL, &S));
    if (!S) return 0;
    CHECK_OK(rad_bvh_create(S, NULL, &bvh));
    rad_patch_options_default(&po);
    po.target_count = o->patches;
    CHECK_OK(rad_patches_create(S, &po, NULL, &P));
    if (!bvh || !P) goto done;
    (rad_bvh_raycaster)(bvh, &rc);
    rad_form_factor_options_default(&fo);
    fo.samples = o->ff_samples;
    CHECK_OK(rad_form_factors_dense(P, &rc, &fo, NULL, &ff));
    if (!ff) goto done;
    n = P->count;
    D = (float *)calloc(3 * (size_t)n, sizeof(float));
    E = (float *)calloc(3 * (size_t)n, sizeof(float));
    L = (float *)calloc(3 * (size_t)n, sizeof(float));
    if (!D || !E || !L) goto done;
    rad_direct_options_default(&dopt);
    dopt.light_samples = o->light_samples;
    CHECK_OK(rad_direct_patches(P, &rc, &d->lights[0].light, d->light_count, &dopt, D, NULL));
    CHECK_OK(rad_sources(P, RAD_SOURCE_DIRECT, D, E));
    rad_system_init(&sys, &ff->matrix, P, E);
    rad_solve_options_default(&so);
    so.bounces = o->bounces;
    CHECK_OK(rad_solve_jacobi(&sys, &so, L, NULL, NULL));
    for (i = 0; i < 3 * n; ++i) L[i] += E[i];
    rad_lightmap_options_default(&lo);
    lo.width = d->lightmap_width;
    lo.height = d->lightmap_height;
    lo.samples = o->lightmap_samples;
    CHECK_OK(rad_lightmap_create(S, &rc, &lo, NULL, &lm));
    if (!lm) goto done;
    memset(out, 0, sizeof(float) * ch * lo.width * lo.height);
    CHECK_OK(rad_lightmap_gather(lm, P, L, &rc, go, out, NULL));
    if (d->lightmap_flags & RAD_BAKER_LIGHTMAP_DIRECT) {
        dopt.exclude_emitters = 0;
        CHECK_OK(rad_lightmap_direct(lm, &rc, &d->lights[0].light, d->light_count, &dopt, out, NULL));
    }
    CHECK_OK(rad_lightmap_dilate(lm, ch, out, 0, NULL));
    if (d->lightmap_flags & RAD_BAKER_LIGHTMAP_STITCH) CHECK_OK(rad_lightmap_stitch(lm, ch, out, 0, st, NULL));
    ok = rad_test_failures == 0;
done:
    free(D); free(E); free(L);
    rad_lightmap_destroy(lm);
    rad_form_factors_destroy(ff);
    rad_patches_destroy(P);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(S);
    return ok;
}

/* lightmap_gather (visibility rays, SH encoding), RAD_BAKER_LIGHTMAP_DIRECT and _STITCH give
   the lower-level calls' texels bit for bit, the seam closes, and the texels are kept */
static void blm_test_lower_level(void)
{
    int pass;
    for (pass = 0; pass < 2; ++pass) {
        blm_scene s;
        rad_baker_options o;
        rad_lightmap_gather_options go;
        rad_lightmap_seam_stats st;
        rad_baker_result *R = NULL, *plain = NULL;
        const rad_lightmap *lm;
        float *mine;
        uint32_t ch = pass ? 12u : 3u;
        size_t i, count;
        double with = 0.0, without = 0.0;
        blm_scene_make(&s);
        blm_options(&o);
        rad_lightmap_gather_options_default(&go);
        go.visibility_rays = 2; /* not the default 4: the option must reach the gather */
        go.encoding = pass ? RAD_LIGHTMAP_SH_L1 : RAD_LIGHTMAP_IRRADIANCE;
        s.d.lightmap_gather = &go;
        s.d.lightmap_flags = RAD_BAKER_LIGHTMAP_STITCH | (pass ? 0u : (uint32_t)RAD_BAKER_LIGHTMAP_DIRECT);
        CHECK_OK(rad_baker_run(&s.d, &o, NULL, &R));
        if (!R) return;
        count = (size_t)ch * R->lightmap_width * R->lightmap_height;
        CHECK(R->lightmap_channels == ch);
        lm = rad_baker_result_lightmap(R);
        CHECK(lm != NULL && lm->width == 40 && lm->height == 40 && lm->valid_texels > 100);
        mine = (float *)malloc(count * sizeof(float));
        memset(&st, 0, sizeof st);
        if (mine && blm_lower_level(&s.d, &o, &go, mine, &st)) {
            CHECK(blm_same_bits(mine, R->lightmap_layers, count));
            CHECK(blm_same_bits(mine, R->lightmap, count));
            CHECK(R->lightmap_seams.seams == 1 && st.seams == 1);
            CHECK(R->lightmap_seams.max_jump_before == st.max_jump_before);
            CHECK(R->lightmap_seams.max_jump_after < 0.2f * R->lightmap_seams.max_jump_before);
        }
        /* without the direct light (and the stitch) the floor holds less: only the bounces */
        s.d.lightmap_flags = 0;
        CHECK_OK(rad_baker_run(&s.d, &o, NULL, &plain));
        if (plain) {
            for (i = 0; i < count; i += ch) with += R->lightmap[i], without += plain->lightmap[i];
            CHECK(plain->lightmap_seams.seams == 0);
            if (getenv("RAD_TEST_VERBOSE"))
                printf("    pass %d: mean %g with, %g without; jumps %g -> %g\n", pass, with, without,
                       (double)R->lightmap_seams.max_jump_before, (double)R->lightmap_seams.max_jump_after);
            CHECK(pass ? fabs(with - without) < 0.05 * without : with > 3.0 * without);
        }
        free(mine);
        rad_baker_result_destroy(plain);
        rad_baker_result_destroy(R);
    }
}

/* lightmap_exact_pairs: under the valid samples x patches the hemisphere gather is chosen,
   the bake of lightmap_gather's method HEMISPHERE bit for bit; above them the exact one */
static void blm_test_exact_pairs(void)
{
    blm_scene s;
    rad_baker_options o;
    rad_lightmap_gather_options go;
    rad_baker_result *A = NULL, *H = NULL, *X = NULL;
    size_t count;
    blm_scene_make(&s);
    blm_options(&o);
    o.keep = 0;
    rad_lightmap_gather_options_default(&go);
    go.hemisphere_rays = 64;
    go.exact_ratio = FLT_MAX; /* no patch is bright: the hemisphere gather is all rays, unlike the exact one */
    s.d.lightmap_gather = &go;
    o.lightmap_exact_pairs = 1.0; /* any scene has more pairs */
    CHECK_OK(rad_baker_run(&s.d, &o, NULL, &A));
    o.lightmap_exact_pairs = 0.0;
    go.method = RAD_LIGHTMAP_GATHER_HEMISPHERE;
    CHECK_OK(rad_baker_run(&s.d, &o, NULL, &H));
    go.method = RAD_LIGHTMAP_GATHER_HEMISPHERE;
    o.lightmap_exact_pairs = 1e12; /* far above: the exact gather whatever the method given */
    CHECK_OK(rad_baker_run(&s.d, &o, NULL, &X));
    if (A && H && X) {
        count = 3 * (size_t)A->lightmap_width * A->lightmap_height;
        CHECK(blm_same_bits(A->lightmap, H->lightmap, count));
        CHECK(!blm_same_bits(A->lightmap, X->lightmap, count));
        CHECK(rad_baker_result_lightmap(A) == NULL); /* no keep: no texels */
    }
    rad_baker_result_destroy(A);
    rad_baker_result_destroy(H);
    rad_baker_result_destroy(X);
}

/* the specific errors: SH with virtual patches, direct light with SH or sky layers, unknown
   flags or encoding, a bad threshold, and a runtime over these options */
static void blm_test_refusals(void)
{
    blm_scene s;
    rad_baker_options o;
    rad_lightmap_gather_options go;
    rad_baker_result *R = NULL;
    rad_baker_runtime *rt = NULL;
    rad_context ctx;
    fx_err_log lg;
    blm_scene_make(&s);
    blm_options(&o);
    rad_lightmap_gather_options_default(&go);
    s.d.lightmap_gather = &go;
    go.encoding = RAD_LIGHTMAP_SH_L1;
    o.method = RAD_BAKER_VIRTUAL_PATCHES;
    fx_baker_expect(&s.d, &o, RAD_ERROR_INVALID_ARGUMENT, "SH lightmap encoding");
    o.method = RAD_BAKER_CLASSIC;
    s.d.lightmap_flags = RAD_BAKER_LIGHTMAP_DIRECT;
    fx_baker_expect(&s.d, &o, RAD_ERROR_INVALID_ARGUMENT, "RAD_BAKER_LIGHTMAP_DIRECT");
    go.encoding = RAD_LIGHTMAP_IRRADIANCE;
    o.sky_bands = 1;
    fx_baker_expect(&s.d, &o, RAD_ERROR_INVALID_ARGUMENT, "sky layers");
    o.sky_bands = 0;
    s.d.lightmap_flags = 64; /* no such bit (8 is RAD_BAKER_LIGHTMAP_RGB9E5_ONLY) */
    fx_baker_expect(&s.d, &o, RAD_ERROR_INVALID_ARGUMENT, "lightmap_flags");
    s.d.lightmap_flags = 0;
    go.encoding = (rad_lightmap_encoding)7;
    fx_baker_expect(&s.d, &o, RAD_ERROR_INVALID_ARGUMENT, "encoding");
    go.encoding = RAD_LIGHTMAP_IRRADIANCE;
    o.lightmap_exact_pairs = -1.0;
    fx_baker_expect(&s.d, &o, RAD_ERROR_INVALID_ARGUMENT, "lightmap_exact_pairs");
    o.lightmap_exact_pairs = 0.0;
    s.d.lightmap_flags = RAD_BAKER_LIGHTMAP_STITCH;
    CHECK_OK(rad_baker_run(&s.d, &o, NULL, &R));
    memset(&ctx, 0, sizeof ctx);
    memset(&lg, 0, sizeof lg);
    ctx.log = fx_err_log_fn;
    ctx.log_user = &lg;
    if (R) {
        CHECK_RESULT(rad_baker_runtime_create(&s.d, &o, R, NULL, &ctx, &rt), RAD_ERROR_INVALID_ARGUMENT);
        CHECK(rt == NULL && strstr(lg.last, "lightmap_flags") != NULL);
    }
    rad_baker_runtime_destroy(rt);
    rad_baker_result_destroy(R);
}

static const rad_test_case tests_baker_lightmap[] = {
    { "baker_lightmap_lower_level", blm_test_lower_level },
    { "baker_lightmap_exact_pairs", blm_test_exact_pairs },
    { "baker_lightmap_refusals", blm_test_refusals },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_baker_lightmap)

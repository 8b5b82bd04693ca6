/* test_layers.c - more light layers of the engine tier (docs/methods/bake.md "Sky layers" and
   "Run time"): a bake's sky layers mixed with a sky's SH coefficients give the bake with that
   sky as an ordinary light (a constant sky, and a linear gradient sky, for which bands 0..1
   are exact), for vertices, the lightmap and probes, classic and virtual patches; the sky
   planes follow the groups' and equal a sky-only bake's bit for bit; the projection of a
   gradient map gives its closed-form coefficients; the runtime's group scales converge to
   rad_baker_mix's outputs with the same scales (lights and emissive materials, both
   methods); bad input gives specific errors. Included by test_main.c after the
   implementation: every name is static and prefixed ly_. */
#include "fixtures.h"

/* the mean of |a - b| over the mean of |b| (valid lightmap texels only when flags is given) */
static double ly_rel(const float *a, const float *b, size_t n, const uint8_t *flags)
{
    double d = 0.0, s = 0.0;
    size_t i;
    for (i = 0; i < n; ++i) {
        if (flags && !(flags[i / 3] & RAD_TEXEL_VALID)) continue;
        d += fabs((double)a[i] - b[i]), s += fabs((double)b[i]);
    }
    return s > 0.0 ? d / s : d;
}

/* An open corner: a lightmapped floor (2 x 2, y = 0) and two walls (the back wall z = 0 and
   the side wall x = 0, 1 high), tinted grey, under the sky; two probes above the floor. */
typedef struct ly_scene {
    lm_soup floor, walls;
    rad_mesh_desc meshes[2];
    rad_material mat;
    float probe_at[6];
    rad_baker_desc d;
} ly_scene;

static void ly_corner(ly_scene *s)
{
    const float O[3] = { 0, 0, 0 }, X2[3] = { 2, 0, 0 }, Y[3] = { 0, 1, 0 }, Z2[3] = { 0, 0, 2 };
    const float uv0[2] = { 0.02f, 0.02f }, ua[2] = { 0.0f, 0.96f }, ub[2] = { 0.96f, 0.0f };
    const float at[6] = { 1.0f, 0.5f, 1.0f, 0.5f, 0.3f, 1.5f };
    memset(s, 0, sizeof *s);
    lm_quad(&s->floor, O, Z2, X2, uv0, ua, ub); /* Z x X = +Y */
    lm_quad(&s->walls, O, X2, Y, NULL, NULL, NULL); /* X x Y = +Z */
    lm_quad(&s->walls, O, Y, Z2, NULL, NULL, NULL); /* Y x Z = +X */
    lm_mesh(&s->meshes[0], &s->floor, 0, 1);
    lm_mesh(&s->meshes[1], &s->walls, 0, 0);
    s->mat.albedo[0] = 0.75f, s->mat.albedo[1] = 0.6f, s->mat.albedo[2] = 0.45f;
    memcpy(s->probe_at, at, sizeof at);
    s->d.scene.meshes = s->meshes;
    s->d.scene.mesh_count = 2;
    s->d.scene.materials = &s->mat;
    s->d.scene.material_count = 1;
    s->d.outputs = RAD_BAKER_VERTEX | RAD_BAKER_LIGHTMAP | RAD_BAKER_PROBES;
    s->d.lightmap_width = s->d.lightmap_height = 16;
    s->d.probe_positions = s->probe_at;
    s->d.probe_count = 2;
}

static void ly_options(rad_baker_options *o, rad_baker_method method)
{
    memset(o, 0, sizeof *o);
    o->method = method;
    o->patches = rad_test_quick() ? 60u : 120u;
    o->vp_resolution = 6;
    o->ff_samples = 4;
    o->bounces = 8;
    o->light_samples = rad_test_quick() ? 128u : 256u;
    o->sky_rays = rad_test_quick() ? 128u : 256u;
    o->lightmap_samples = 1;
}

/* the gradient sky: L(w) = (a + b y) rgb, y the direction's up component */
static const float ly_rgb[3] = { 0.6f, 0.8f, 1.0f };
#define LY_A 1.0f
#define LY_B 0.75f
static void ly_gradient(void *user, const float dir[3], float out[3])
{
    int k;
    (void)user;
    for (k = 0; k < 3; ++k) out[k] = (LY_A + LY_B * dir[1]) * ly_rgb[k];
}

/* Bands 0..1 hold a + b y exactly: l_0 = a sqrt(4 pi), l_1 = b (sqrt(3 / (4 pi))) (4 pi / 3)
   (Y_1 = sqrt(3 / (4 pi)) y, and the integral of y^2 over the sphere is 4 pi / 3). */
static void ly_gradient_sh(float a, float b, float *sh /* 3 * 4 */)
{
    double pi = 3.14159265358979323846, c0 = sqrt(4.0 * pi), c1 = sqrt(3.0 / (4.0 * pi)) * 4.0 * pi / 3.0;
    int k;
    memset(sh, 0, 12 * sizeof(float));
    for (k = 0; k < 3; ++k) {
        sh[k] = (float)(a * c0 * ly_rgb[k]);
        sh[3 + k] = (float)(b * c1 * ly_rgb[k]);
    }
}

/* The sky's SH layers mixed with the sky's coefficients against a bake with the sky as a light:
   the constant sky (RAD_LIGHT_SKY) and the gradient (RAD_LIGHT_ENVIRONMENT over a lookup),
   both methods. The two bakes trace their own rays (the sky light: light_samples cosine rays
   per point, the environment half of them drawn from the map; the layers: sky_rays cosine
   rays), so they differ by their noise: measured 0.03-0.12% mean (vertices, valid texels,
   probes), 0.07-0.5% with RAD_TEST_QUICK; tolerance 2%. */
static void ly_test_sky_against_light(void)
{
    int kind, pass;
    rad_environment_desc ed;
    rad_environment *env = NULL;
    memset(&ed, 0, sizeof ed);
    ed.width = 64, ed.height = 32, ed.lookup = ly_gradient;
    CHECK_OK(rad_environment_create(&ed, NULL, &env));
    if (!env) return;
    for (kind = 0; kind < 2; ++kind)
        for (pass = 0; pass < 2; ++pass) {
            ly_scene s;
            rad_baker_desc lit, sky;
            rad_baker_light bl;
            rad_baker_options o;
            rad_baker_result *A = NULL, *B = NULL;
            float sh[12];
            double ev, el, ep;
            ly_corner(&s);
            memset(&bl, 0, sizeof bl);
            if (kind == 0) {
                bl.light.type = RAD_LIGHT_SKY;
                bl.light.color[0] = 3.14159265f * 0.5f, bl.light.color[1] = 3.14159265f * 0.7f;
                bl.light.color[2] = 3.14159265f * 0.9f;
                memset(sh, 0, sizeof sh);
                sh[0] = 3.5449077f * 0.5f, sh[1] = 3.5449077f * 0.7f, sh[2] = 3.5449077f * 0.9f; /* sqrt(4 pi) L */
            } else {
                bl.light.type = RAD_LIGHT_ENVIRONMENT;
                bl.light.environment = env;
                bl.light.color[0] = bl.light.color[1] = bl.light.color[2] = 1.0f;
                ly_gradient_sh(LY_A, LY_B, sh);
            }
            lit = s.d;
            lit.lights = &bl;
            lit.light_count = 1;
            sky = s.d;
            ly_options(&o, pass ? RAD_BAKER_VIRTUAL_PATCHES : RAD_BAKER_CLASSIC);
            CHECK_OK(rad_baker_run(&lit, &o, NULL, &A));
            o.sky_bands = kind == 0 ? 1u : 2u;
            CHECK_OK(rad_baker_run(&sky, &o, NULL, &B));
            if (!A || !B) goto next;
            CHECK(B->group_count == 0 && B->sky_count == o.sky_bands * o.sky_bands);
            CHECK(B->vertex[0] == 0.0f); /* no groups: the plain mix is dark */
            CHECK_OK(rad_baker_mix_sky(B, NULL, sh, NULL));
            ev = ly_rel(B->vertex, A->vertex, 3 * (size_t)A->vertex_count, NULL);
            el = ly_rel(B->lightmap, A->lightmap, 3 * (size_t)A->lightmap_width * A->lightmap_height, A->lightmap_flags);
            ep = ly_rel(B->probes, A->probes, 27 * (size_t)A->probe_count, NULL);
            if (!(ev < 0.02 && el < 0.02 && ep < 0.02) || getenv("RAD_TEST_VERBOSE"))
                printf("    %s sky, %s: mean relative difference vertex %.4f, lightmap %.4f, probes %.4f\n",
                       kind ? "gradient" : "constant", pass ? "virtual patches" : "classic", ev, el, ep);
            CHECK(ev < 0.02 && el < 0.02 && ep < 0.02);
            CHECK(A->vertex[3 * 2 + 1] > 0.0f && A->probes[0] > 0.0f); /* something was lit */
        next:
            rad_baker_result_destroy(A);
            rad_baker_result_destroy(B);
        }
    rad_environment_destroy(env);
}

/* Sky planes follow the groups' planes; each equals the plane of a sky-only bake bit for bit;
   rad_baker_mix leaves the sky out, rad_baker_mix_sky adds it (to float rounding of the sum),
   and the same bits come for another task split. */
static void ly_reverse_for(void *user, uint32_t count, rad_task_fn fn, void *data)
{
    uint32_t i;
    (void)user;
    for (i = count; i-- > 0;) fn(data, i);
}

static void ly_test_sky_planes(void)
{
    int pass;
    for (pass = 0; pass < 2; ++pass) {
        ly_scene s;
        rad_baker_desc d, sky;
        rad_baker_light bl[2];
        rad_baker_options o;
        rad_baker_result *A = NULL, *B = NULL, *C = NULL;
        rad_context ctx;
        float g[6] = { 0.5f, 1.0f, 2.0f, 1.5f, 0.25f, 0.0f }, sh[27];
        size_t nv, nl, np, i, K;
        ly_corner(&s);
        memset(bl, 0, sizeof bl);
        bl[0].light.type = RAD_LIGHT_POINT;
        bl[0].light.position[0] = 1.2f, bl[0].light.position[1] = 0.6f, bl[0].light.position[2] = 0.7f;
        bl[0].light.color[0] = bl[0].light.color[1] = bl[0].light.color[2] = 1.0f;
        bl[1] = bl[0];
        bl[1].light.position[0] = 0.4f;
        bl[1].group = 1;
        d = s.d;
        d.lights = bl;
        d.light_count = 2;
        ly_options(&o, pass ? RAD_BAKER_VIRTUAL_PATCHES : RAD_BAKER_CLASSIC);
        o.light_samples = 4;
        o.sky_rays = 16;
        o.sky_bands = 3;
        CHECK_OK(rad_baker_run(&d, &o, NULL, &A));
        sky = s.d;
        CHECK_OK(rad_baker_run(&sky, &o, NULL, &B));
        memset(&ctx, 0, sizeof ctx);
        ctx.parallel_for = ly_reverse_for;
        ctx.task_count = 3;
        CHECK_OK(rad_baker_run(&d, &o, &ctx, &C));
        if (!A || !B || !C) goto next;
        CHECK(A->group_count == 2 && A->sky_count == 9 && B->group_count == 0 && B->sky_count == 9);
        {
            rad_baker_runtime *rt = NULL; /* a sky-only bake has nothing a runtime follows */
            CHECK(rad_baker_runtime_create(&sky, &o, B, NULL, NULL, &rt) == RAD_ERROR_INVALID_ARGUMENT && !rt);
        }
        K = A->sky_count;
        nv = 3 * (size_t)A->vertex_count, nl = 3 * (size_t)A->lightmap_width * A->lightmap_height;
        np = 27 * (size_t)A->probe_count;
        CHECK(memcmp(A->vertex_layers + 2 * nv, B->vertex_layers, K * nv * sizeof(float)) == 0);
        CHECK(memcmp(A->lightmap_layers + 2 * nl, B->lightmap_layers, K * nl * sizeof(float)) == 0);
        CHECK(memcmp(A->probe_layers + 2 * np, B->probe_layers, K * np * sizeof(float)) == 0);
        CHECK(memcmp(A->vertex_layers, C->vertex_layers, (2 + K) * nv * sizeof(float)) == 0);
        CHECK(memcmp(A->lightmap_layers, C->lightmap_layers, (2 + K) * nl * sizeof(float)) == 0);
        CHECK(memcmp(A->probe_layers, C->probe_layers, (2 + K) * np * sizeof(float)) == 0);
        for (i = 0; i < 27; ++i) sh[i] = 0.3f + 0.1f * (float)(i % 5) - (i >= 12 ? 0.35f : 0.0f);
        CHECK_OK(rad_baker_mix(A, g, NULL));
        CHECK_OK(rad_baker_mix_sky(B, NULL, sh, NULL));
        CHECK_OK(rad_baker_mix_sky(C, g, sh, NULL));
        for (i = 0; i < nl; ++i) {
            double want = (double)A->lightmap[i] + B->lightmap[i];
            CHECK_NEAR(C->lightmap[i], want, 1e-5 * (fabs(A->lightmap[i]) + fabs(B->lightmap[i])) + 1e-12);
        }
        for (i = 0; i < np; ++i) {
            double want = (double)A->probes[i] + B->probes[i];
            CHECK_NEAR(C->probes[i], want, 1e-5 * (fabs(A->probes[i]) + fabs(B->probes[i])) + 1e-12);
        }
        for (i = 0; i < nv; ++i) {
            double want = (double)A->vertex[i] + B->vertex[i];
            CHECK_NEAR(C->vertex[i], want, 1e-5 * (fabs(A->vertex[i]) + fabs(B->vertex[i])) + 1e-12);
        }
    next:
        rad_baker_result_destroy(A);
        rad_baker_result_destroy(B);
        rad_baker_result_destroy(C);
    }
}

/* rad_sky_project_sh of the gradient map (64 x 32 pixels): its closed-form bands 0..1 within
   0.1%, bands 2..3 within 0.1% of l_0 (the pixel sum's error: measured 0.08%); with a scale. */
static void ly_test_project(void)
{
    rad_environment_desc ed;
    rad_environment *env = NULL;
    float got[48], want[12];
    const float scale[3] = { 2.0f, 1.0f, 0.5f };
    uint32_t k;
    memset(&ed, 0, sizeof ed);
    ed.width = 64, ed.height = 32, ed.lookup = ly_gradient;
    CHECK_OK(rad_environment_create(&ed, NULL, &env));
    if (!env) return;
    ly_gradient_sh(LY_A, LY_B, want);
    CHECK_OK(rad_sky_project_sh(env, 4, NULL, got));
    for (k = 0; k < 12; ++k) CHECK_NEAR(got[k], want[k], 1e-3 * fabs(want[k]) + 1e-4);
    for (k = 12; k < 48; ++k) CHECK_NEAR(got[k], 0.0, 1e-3 * want[k % 3]); /* the pixel sum's own error */
    CHECK_OK(rad_sky_project_sh(env, 1, scale, got));
    for (k = 0; k < 3; ++k) CHECK_NEAR(got[k], want[k] * scale[k], 1e-3 * fabs(want[k] * scale[k]));
    rad_environment_destroy(env);
}

typedef struct ly_log {
    char last[512];
} ly_log;

static void ly_log_fn(void *user, rad_log_level level, const char *msg)
{
    ly_log *l = (ly_log *)user;
    if (level == RAD_LOG_ERROR) snprintf(l->last, sizeof l->last, "%s", msg);
}

static void ly_test_sky_bad_input(void)
{
    ly_scene s;
    rad_baker_options o;
    rad_baker_result *R = NULL, *Q = NULL;
    rad_context ctx;
    ly_log lg;
    rad_environment_desc ed;
    rad_environment *env = NULL;
    float sh[48], nan_sh[3];
    memset(&ctx, 0, sizeof ctx);
    memset(&lg, 0, sizeof lg);
    ctx.log = ly_log_fn;
    ctx.log_user = &lg;
    ly_corner(&s);
    s.d.outputs = RAD_BAKER_VERTEX;
    ly_options(&o, RAD_BAKER_CLASSIC);
    o.sky_rays = 8;
    o.light_samples = 4;
    o.sky_bands = 5;
    CHECK_RESULT(rad_baker_run(&s.d, &o, &ctx, &R), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(R == NULL && strstr(lg.last, "sky_bands") != NULL);
    o.sky_bands = 1;
    o.sky_rays = 5000;
    CHECK_RESULT(rad_baker_run(&s.d, &o, &ctx, &R), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(R == NULL && strstr(lg.last, "sky_rays") != NULL);
    o.sky_bands = 0;
    o.sky_rays = 8;
    CHECK_RESULT(rad_baker_run(&s.d, &o, &ctx, &R), RAD_ERROR_INVALID_ARGUMENT); /* nothing emits: no light, no sky */
    CHECK(R == NULL && strstr(lg.last, "nothing emits") != NULL);
    o.sky_bands = 2;
    CHECK_OK(rad_baker_run(&s.d, &o, &ctx, &R));
    {
        rad_baker_light bl;
        rad_baker_desc d = s.d;
        memset(&bl, 0, sizeof bl);
        bl.light.type = RAD_LIGHT_SKY;
        bl.light.color[0] = bl.light.color[1] = bl.light.color[2] = 1.0f;
        d.lights = &bl;
        d.light_count = 1;
        o.sky_bands = 0;
        CHECK_OK(rad_baker_run(&d, &o, &ctx, &Q));
    }
    if (R && Q) {
        memset(sh, 0, sizeof sh);
        CHECK_RESULT(rad_baker_mix_sky(Q, NULL, sh, &ctx), RAD_ERROR_INVALID_ARGUMENT);
        CHECK(strstr(lg.last, "without sky layers") != NULL);
        sh[7] = (float)NAN;
        memcpy(nan_sh, sh + 6, sizeof nan_sh);
        CHECK_RESULT(rad_baker_mix_sky(R, NULL, sh, &ctx), RAD_ERROR_NON_FINITE);
        CHECK(strstr(lg.last, "coefficient 2 channel 1") != NULL);
        CHECK(!isfinite(nan_sh[1]));
        CHECK_RESULT(rad_baker_mix_sky(NULL, NULL, NULL, &ctx), RAD_ERROR_INVALID_ARGUMENT);
        sh[7] = 0.0f;
        CHECK_OK(rad_baker_mix_sky(R, NULL, sh, &ctx)); /* a black sky: dark */
        CHECK(R->vertex[0] == 0.0f);
    }
    memset(&ed, 0, sizeof ed);
    ed.width = 8, ed.height = 4, ed.lookup = ly_gradient;
    CHECK_OK(rad_environment_create(&ed, NULL, &env));
    CHECK_RESULT(rad_sky_project_sh(env, 0, NULL, sh), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_sky_project_sh(env, 5, NULL, sh), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_sky_project_sh(NULL, 2, NULL, sh), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_sky_project_sh(env, 2, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    nan_sh[0] = nan_sh[2] = 1.0f;
    CHECK_RESULT(rad_sky_project_sh(env, 2, nan_sh, sh), RAD_ERROR_NON_FINITE);
    rad_environment_destroy(env);
    rad_baker_result_destroy(R);
    rad_baker_result_destroy(Q);
}

/* The Cornell box with a point light in group 0 and the short block glowing in group 1, both
   methods: with the baked lights and group scales set, the runtime converges to rad_baker_mix
   with those scales (virtual patches: exact sweeps; classic: exact in one update; float
   rounding and the emitters' light traced apart from the lights': measured 3e-8 to 2e-7;
   tolerance 1e-4), then back to the bake with NULL; a dimmed light alone counts as a changed light. */
static void ly_glow_box(rad_baker_desc *d, rad_mesh_desc *meshes, rad_material *mats, uint32_t *groups, rad_baker_light *bl)
{
    uint32_t i, glow;
    memset(d, 0, sizeof *d);
    rad_cornell_box(&d->scene, NULL);
    for (i = 0; i < d->scene.mesh_count; ++i) meshes[i] = d->scene.meshes[i];
    for (i = 0; i < d->scene.material_count; ++i) mats[i] = d->scene.materials[i], groups[i] = 0;
    glow = d->scene.material_count;
    mats[glow] = mats[meshes[6].material];
    mats[glow].emission[0] = 0.5f, mats[glow].emission[1] = 1.0f, mats[glow].emission[2] = 3.0f;
    groups[glow] = 1;
    meshes[6].material = glow;
    d->scene.meshes = meshes;
    d->scene.materials = mats;
    d->scene.material_count = glow + 1;
    d->material_groups = groups;
    memset(bl, 0, sizeof *bl);
    bl->light.type = RAD_LIGHT_POINT;
    bl->light.position[0] = 0.28f, bl->light.position[1] = 0.35f, bl->light.position[2] = 0.28f;
    bl->light.color[0] = bl->light.color[1] = bl->light.color[2] = 0.05f;
    d->lights = bl;
    d->light_count = 1;
    d->outputs = RAD_BAKER_VERTEX | RAD_BAKER_PROBES;
    d->probe_spacing = 0.2f;
}

static void ly_test_runtime_groups(void)
{
    int pass, step;
    for (pass = 0; pass < 2; ++pass) {
        rad_baker_desc d;
        rad_mesh_desc meshes[16];
        rad_material mats[17];
        uint32_t groups[17];
        rad_baker_light bl;
        rad_baker_options o;
        rad_baker_result *R = NULL;
        rad_baker_runtime *rt = NULL;
        rad_baker_frame f;
        float *want_v = NULL, *want_p = NULL;
        size_t nv, np;
        ly_glow_box(&d, meshes, mats, groups, &bl);
        memset(&o, 0, sizeof o);
        o.method = pass ? RAD_BAKER_VIRTUAL_PATCHES : RAD_BAKER_CLASSIC;
        o.patches = rad_test_quick() ? 80u : 150u;
        o.vp_resolution = rad_test_quick() ? 5u : 7u;
        o.ff_samples = 4;
        o.bounces = 8;
        o.light_samples = 4;
        CHECK_OK(rad_baker_run(&d, &o, NULL, &R));
        if (R) CHECK_OK(rad_baker_runtime_create(&d, &o, R, NULL, NULL, &rt));
        if (!R || !rt) goto next;
        CHECK(R->group_count == 2);
        nv = 3 * (size_t)R->vertex_count, np = 27 * (size_t)R->probe_count;
        want_v = (float *)malloc(nv * sizeof(float));
        want_p = (float *)malloc(np * sizeof(float));
        if (!want_v || !want_p) goto next;
        for (step = 0; step < 4; ++step) {
            static const float sc[4][6] = { { 1, 1, 1, 0.25f, 0.5f, 2.0f },   /* the glow recoloured */
                                            { 0.3f, 0.6f, 1.0f, 0, 0, 0 },    /* the glow off, the light tinted */
                                            { 0, 0, 0, 1, 1, 1 },             /* the light off */
                                            { 1, 1, 1, 1, 1, 1 } };           /* as baked */
            const float *g = step == 3 ? NULL : sc[step];
            int k;
            double ev, ep;
            CHECK_OK(rad_baker_mix(R, sc[step], NULL));
            memcpy(want_v, R->vertex, nv * sizeof(float));
            memcpy(want_p, R->probes, np * sizeof(float));
            CHECK_OK(rad_baker_runtime_set_groups(rt, g));
            CHECK_OK(rad_baker_runtime_update(rt, &bl.light, 1, 0.0, &f));
            if (step == 0) CHECK(f.lights_changed == 0 && f.vertex_refreshed == 1); /* only the glow changed */
            if (step == 1) CHECK(f.lights_changed == 1);
            for (k = 0; k < 50 && f.phase != RAD_BAKER_RUNTIME_CONVERGED; ++k)
                CHECK_OK(rad_baker_runtime_update(rt, &bl.light, 1, 0.0, &f));
            CHECK(f.phase == RAD_BAKER_RUNTIME_CONVERGED);
            ev = ly_rel(f.vertex, want_v, nv, NULL);
            ep = ly_rel(f.probes, want_p, np, NULL);
            if (!(ev < 1e-4 && ep < 1e-4) || getenv("RAD_TEST_VERBOSE"))
                printf("    %s, scales %d: mean relative difference from rad_baker_mix vertex %.3g, probes %.3g\n",
                       pass ? "virtual patches" : "classic", step, ev, ep);
            CHECK(ev < 1e-4 && ep < 1e-4);
        }
    next:
        free(want_v);
        free(want_p);
        rad_baker_runtime_destroy(rt);
        rad_baker_result_destroy(R);
    }
}

/* The two rooms' outputs (a 32 x 16 lightmap, probes every 0.4) and small bake options,
   classic (pass 0) or virtual patches (pass 1), for the runtime tests. */
static void ly_rooms_bake(rad_baker_desc *d, rad_baker_options *o, int pass)
{
    d->outputs = RAD_BAKER_VERTEX | RAD_BAKER_LIGHTMAP | RAD_BAKER_PROBES;
    d->lightmap_width = 32;
    d->lightmap_height = 16;
    d->probe_spacing = 0.4f;
    memset(o, 0, sizeof *o);
    o->method = pass ? RAD_BAKER_VIRTUAL_PATCHES : RAD_BAKER_CLASSIC;
    o->patches = rad_test_quick() ? 80u : 150u;
    o->vp_resolution = rad_test_quick() ? 5u : 7u;
    o->ff_samples = 4;
    o->bounces = 8;
    o->light_samples = 4;
    o->lightmap_samples = 1;
}

/* The same on the two rooms with a lightmap (the lamp's emission group 0, a point light in the
   other room group 1): vertices, valid texels and probes within 1e-4 of rad_baker_mix (measured
   2e-8 to 1.3e-7, the classic lightmap included). */
static void ly_test_runtime_groups_lightmap(void)
{
    int pass, step;
    for (pass = 0; pass < 2; ++pass) {
        lm_soup room, wall, lamp;
        rad_mesh_desc meshes[3];
        rad_material mats[2];
        rad_baker_desc d;
        rad_baker_light bl;
        rad_baker_options o;
        rad_baker_result *R = NULL;
        rad_baker_runtime *rt = NULL;
        rad_baker_frame f;
        uint32_t groups[2] = { 0, 0 };
        memset(&d, 0, sizeof d);
        fx_two_rooms(&room, &wall, &lamp, meshes, &d.scene, mats);
        memset(&bl, 0, sizeof bl);
        bl.light.type = RAD_LIGHT_POINT;
        bl.light.position[0] = 1.3f, bl.light.position[1] = 0.7f, bl.light.position[2] = 0.3f;
        bl.light.color[0] = bl.light.color[1] = bl.light.color[2] = 1.0f;
        bl.group = 1;
        d.lights = &bl;
        d.light_count = 1;
        d.material_groups = groups;
        ly_rooms_bake(&d, &o, pass);
        CHECK_OK(rad_baker_run(&d, &o, NULL, &R));
        if (R) CHECK_OK(rad_baker_runtime_create(&d, &o, R, NULL, NULL, &rt));
        for (step = 0; rt && step < 2; ++step) {
            static const float sc[2][6] = { { 0.2f, 0.2f, 0.2f, 1, 1, 1 }, { 1, 0.5f, 0.2f, 0, 0, 0 } };
            double ev, el, ep;
            int k;
            CHECK_OK(rad_baker_runtime_set_groups(rt, sc[step]));
            for (k = 0; k < 60; ++k) {
                CHECK_OK(rad_baker_runtime_update(rt, &bl.light, 1, 0.0, &f));
                if (f.phase == RAD_BAKER_RUNTIME_CONVERGED) break;
            }
            CHECK(f.phase == RAD_BAKER_RUNTIME_CONVERGED);
            CHECK_OK(rad_baker_mix(R, sc[step], NULL));
            ev = ly_rel(f.vertex, R->vertex, 3 * (size_t)R->vertex_count, NULL);
            el = ly_rel(f.lightmap, R->lightmap, 3 * (size_t)R->lightmap_width * R->lightmap_height, R->lightmap_flags);
            ep = ly_rel(f.probes, R->probes, 27 * (size_t)R->probe_count, NULL);
            if (!(ev < 1e-4 && el < 1e-4 && ep < 1e-4) || getenv("RAD_TEST_VERBOSE"))
                printf("    two rooms, %s, scales %d: vertex %.3g, lightmap %.3g, probes %.3g\n",
                       pass ? "virtual patches" : "classic", step, ev, el, ep);
            CHECK(ev < 1e-4 && el < 1e-4 && ep < 1e-4);
        }
        rad_baker_runtime_destroy(rt);
        rad_baker_result_destroy(R);
    }
}

static void ly_test_runtime_groups_bad_input(void)
{
    rad_baker_desc d;
    rad_mesh_desc meshes[16];
    rad_material mats[17];
    uint32_t groups[17];
    rad_baker_light bl;
    rad_baker_options o;
    rad_baker_result *R = NULL;
    rad_baker_runtime *rt = NULL;
    rad_baker_frame f;
    rad_context ctx;
    ly_log lg;
    float g[6] = { 1, 1, 1, 1, 1, 1 };
    memset(&ctx, 0, sizeof ctx);
    memset(&lg, 0, sizeof lg);
    ctx.log = ly_log_fn;
    ctx.log_user = &lg;
    ly_glow_box(&d, meshes, mats, groups, &bl);
    memset(&o, 0, sizeof o);
    o.method = RAD_BAKER_CLASSIC;
    o.patches = 60;
    o.ff_samples = 2;
    o.bounces = 4;
    o.light_samples = 2;
    CHECK_OK(rad_baker_run(&d, &o, NULL, &R));
    if (R) CHECK_OK(rad_baker_runtime_create(&d, &o, R, NULL, &ctx, &rt));
    if (rt) {
        CHECK_RESULT(rad_baker_runtime_set_groups(NULL, g), RAD_ERROR_INVALID_ARGUMENT);
        g[4] = (float)NAN;
        CHECK_RESULT(rad_baker_runtime_set_groups(rt, g), RAD_ERROR_NON_FINITE);
        CHECK(strstr(lg.last, "group 1 channel 1") != NULL);
        g[4] = 1.0f, g[2] = -0.5f;
        CHECK_RESULT(rad_baker_runtime_set_groups(rt, g), RAD_ERROR_NEGATIVE_EMISSION);
        CHECK(strstr(lg.last, "group 0 channel 2") != NULL);
        /* nothing changed: the next update is a no-op */
        CHECK_OK(rad_baker_runtime_update(rt, &bl.light, 1, 0.0, &f));
        CHECK(f.phase == RAD_BAKER_RUNTIME_CONVERGED && f.lights_changed == 0);
        CHECK(memcmp(f.vertex, R->vertex, 3 * sizeof(float) * R->vertex_count) == 0);
    }
    rad_baker_runtime_destroy(rt);
    rad_baker_result_destroy(R);
}

/* options.keep: the runtime borrows the bake's solver objects instead of building them; its
   frames then equal, bit for bit, those of a runtime that built its own from a bake without
   keep (the two rooms with a lightmap, a light moved to convergence, both methods: the objects
   are the same, and after a move nothing of the bake's outputs is left but the classic
   lightmap's detail, the same bake there), and with the baked lights the outputs are the
   bake's. Virtual patches kept have sparse rows: that bake differs from the dense one by
   float rounding (measured below 1e-6). */
static void ly_test_keep(void)
{
    int pass;
    for (pass = 0; pass < 2; ++pass) {
        lm_soup room, wall, lamp;
        rad_mesh_desc meshes[3];
        rad_material mats[2];
        rad_baker_desc d;
        rad_baker_light bl;
        rad_baker_options o;
        rad_baker_result *R = NULL, *K = NULL;
        rad_baker_runtime *a = NULL, *b = NULL;
        rad_baker_frame fa, fb;
        rad_light moved;
        int k;
        memset(&d, 0, sizeof d);
        fx_two_rooms(&room, &wall, &lamp, meshes, &d.scene, mats);
        memset(&bl, 0, sizeof bl);
        bl.light.type = RAD_LIGHT_POINT;
        bl.light.position[0] = 1.3f, bl.light.position[1] = 0.7f, bl.light.position[2] = 0.3f;
        bl.light.color[0] = bl.light.color[1] = bl.light.color[2] = 1.0f;
        d.lights = &bl;
        d.light_count = 1;
        ly_rooms_bake(&d, &o, pass);
        CHECK_OK(rad_baker_run(&d, &o, NULL, &R));
        o.keep = 1;
        CHECK_OK(rad_baker_run(&d, &o, NULL, &K));
        if (!R || !K) goto next;
        CHECK(R->kept == NULL && K->kept != NULL);
        if (!pass) CHECK(memcmp(R->vertex, K->vertex, 3 * sizeof(float) * R->vertex_count) == 0); /* classic: the same bake */
        if (getenv("RAD_TEST_VERBOSE"))
            printf("    keep, %s: the bake's vertices differ by %.3g\n", pass ? "virtual patches" : "classic",
                   ly_rel(K->vertex, R->vertex, 3 * (size_t)R->vertex_count, NULL));
        CHECK(ly_rel(K->vertex, R->vertex, 3 * (size_t)R->vertex_count, NULL) < 1e-5);
        CHECK_OK(rad_baker_runtime_create(&d, &o, K, NULL, NULL, &a));
        o.keep = 0;
        CHECK_OK(rad_baker_runtime_create(&d, &o, R, NULL, NULL, &b)); /* builds its own */
        if (!a || !b) goto next;
        CHECK_OK(rad_baker_runtime_update(a, &bl.light, 1, 0.0, &fa));
        CHECK(fa.phase == RAD_BAKER_RUNTIME_CONVERGED);
        CHECK(memcmp(fa.vertex, K->vertex, 3 * sizeof(float) * K->vertex_count) == 0);
        moved = bl.light;
        moved.position[0] = 1.75f, moved.position[1] = 0.35f;
        for (k = 0; k < 50; ++k) {
            CHECK_OK(rad_baker_runtime_update(a, &moved, 1, 0.0, &fa));
            CHECK_OK(rad_baker_runtime_update(b, &moved, 1, 0.0, &fb));
            if (fa.phase == RAD_BAKER_RUNTIME_CONVERGED) break;
        }
        CHECK(fa.phase == RAD_BAKER_RUNTIME_CONVERGED && fb.phase == RAD_BAKER_RUNTIME_CONVERGED);
        CHECK(memcmp(fa.vertex, fb.vertex, 3 * sizeof(float) * K->vertex_count) == 0);
        CHECK(memcmp(fa.lightmap, fb.lightmap, 3 * sizeof(float) * K->lightmap_width * K->lightmap_height) == 0);
        CHECK(memcmp(fa.probes, fb.probes, 27 * sizeof(float) * K->probe_count) == 0);
    next:
        rad_baker_runtime_destroy(a);
        rad_baker_runtime_destroy(b);
        rad_baker_result_destroy(R);
        rad_baker_result_destroy(K);
    }
}

/* An allocator that fails from the n-th allocation on, and counts what is still held. */
typedef struct ly_alloc {
    long left, held;
} ly_alloc;

static void *ly_alloc_fn(void *user, size_t size)
{
    ly_alloc *a = (ly_alloc *)user;
    void *p;
    if (a->left-- <= 0) return NULL;
    p = malloc(size);
    if (p) ++a->held;
    return p;
}

static void ly_free_fn(void *user, void *p)
{
    ly_alloc *a = (ly_alloc *)user;
    if (p) --a->held, free(p);
}

/* Every allocation of a bake with sky layers and keep, then of a runtime borrowing its objects
   with an emitting group, failed in turn: OUT_OF_MEMORY, nothing held after, never a crash. */
static void ly_test_out_of_memory(void)
{
    int pass;
    for (pass = 0; pass < 2; ++pass) {
        rad_baker_desc d;
        rad_mesh_desc meshes[16];
        rad_material mats[17];
        uint32_t groups[17];
        rad_baker_light bl;
        rad_baker_options o;
        rad_context ctx;
        ly_alloc al;
        long n, runs = 0;
        int done = 0;
        ly_glow_box(&d, meshes, mats, groups, &bl);
        memset(&o, 0, sizeof o);
        o.method = pass ? RAD_BAKER_VIRTUAL_PATCHES : RAD_BAKER_CLASSIC;
        o.patches = 40;
        o.vp_resolution = 4;
        o.ff_samples = 1;
        o.bounces = 2;
        o.light_samples = 1;
        o.sky_bands = 2;
        o.sky_rays = 4;
        o.keep = 1;
        memset(&ctx, 0, sizeof ctx);
        ctx.allocator.alloc = ly_alloc_fn;
        ctx.allocator.free = ly_free_fn;
        ctx.allocator.user = &al;
        for (n = 0; !done && n < 1000000; n += n < 24 ? 1 : n / 6) {
            rad_baker_result *R = NULL;
            rad_baker_runtime *rt = NULL;
            rad_result r;
            al.left = n, al.held = 0;
            r = rad_baker_run(&d, &o, &ctx, &R);
            if (r == RAD_SUCCESS) r = rad_baker_runtime_create(&d, &o, R, NULL, &ctx, &rt);
            if (r == RAD_SUCCESS) done = 1;
            else CHECK(r == RAD_ERROR_OUT_OF_MEMORY);
            rad_baker_runtime_destroy(rt);
            rad_baker_result_destroy(R);
            CHECK(al.held == 0);
            ++runs;
        }
        CHECK(done && runs > 10);
        if (getenv("RAD_TEST_VERBOSE")) printf("    %s: %ld runs, success at %ld allocations\n", pass ? "virtual patches" : "classic", runs, n);
    }
}

static const rad_test_case tests_layers[] = {
    { "layers_sky_against_light", ly_test_sky_against_light },
    { "layers_sky_planes", ly_test_sky_planes },
    { "layers_sky_project", ly_test_project },
    { "layers_sky_bad_input", ly_test_sky_bad_input },
    { "layers_runtime_groups", ly_test_runtime_groups },
    { "layers_runtime_groups_lightmap", ly_test_runtime_groups_lightmap },
    { "layers_runtime_groups_bad_input", ly_test_runtime_groups_bad_input },
    { "layers_keep", ly_test_keep },
    { "layers_out_of_memory", ly_test_out_of_memory },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_layers)

/* test_rgb9e5.c - packed light layers (RGB9E5 in >>api_baker): packing rounds each channel
   within 2^-9 of the texel's largest (random and edge values: 0, the float denormals, the
   format's largest value, above it, negatives, NaN and infinities refused with the texel
   named); unpacking gives the format's definition; the mix of packed layers gives the bits of
   the float mix of the unpacked layers (1 to 8 groups, odd texel counts, scales with zeros
   and negatives, any task order); a bake with RAD_BAKER_LIGHTMAP_RGB9E5 keeps packed layers
   within the bound of its float layers, _ONLY mixes its lightmap from them, and both are
   refused where the layers go negative; the runtime mixes its lightmap from the packed layers
   and matches the float runtime within the bound. Included by test_main.c after the
   implementation: every name is static and prefixed pk_. */
#include "fixtures.h"

/* the format's definition, in doubles: mantissa 2^(e - 15 - 9) */
static double pk_ref(uint32_t w, int c)
{
    return ldexp((double)((w >> (9 * c)) & 511u), (int)(w >> 27) - 24);
}

static float pk_clamp(float x)
{
    if (!(x > 0.0f)) return 0.0f;
    return x > RAD_RGB9E5_MAX ? RAD_RGB9E5_MAX : x;
}

/* a random float of any exponent from 2^-40 to 2^18, a tenth of them 0 */
static float pk_random(uint32_t *seed)
{
    *seed = *seed * 1664525u + 1013904223u;
    if ((*seed >> 8) % 10u == 0) return 0.0f;
    return (float)ldexp(1.0 + (double)(*seed >> 9) / 8388608.0, (int)((*seed >> 3) % 59u) - 40);
}

/* every texel within 2^-9 of its largest clamped channel (2^-25 below the smallest step), and
   the unpacking equals the definition */
static int pk_within(const float *rgb, const uint32_t *w, size_t count)
{
    size_t t;
    int c, ok = 1;
    float back[3];
    for (t = 0; t < count; ++t) {
        float x[3];
        double top = 0.0;
        rad_rgb9e5_unpack(w + t, 1, back);
        for (c = 0; c < 3; ++c) {
            x[c] = pk_clamp(rgb[3 * t + c]);
            if (x[c] > top) top = x[c];
        }
        for (c = 0; c < 3; ++c) {
            double bound = ldexp(top, -9) + ldexp(1.0, -25);
            if ((double)back[c] != pk_ref(w[t], c)) ok = 0;
            if (fabs((double)back[c] - x[c]) > bound) {
                if (ok) printf("    texel %lu channel %d: %.9g packed as %.9g (bound %.3g)\n", (unsigned long)t, c, (double)x[c],
                               (double)back[c], bound);
                ok = 0;
            }
        }
    }
    return ok;
}

static void pk_test_round_trip(void)
{
    enum { N = 20000 };
    static float rgb[3 * N];
    static uint32_t w[N];
    /* edges: zero, float denormals, below the smallest step, the largest value, above it,
       negatives (and -0), a channel that rounds up into the next exponent */
    const float edge[] = { 0.0f, 0.0f, 0.0f,        1e-40f, 1e-45f, 0.0f,       1e-8f, 3e-8f, 5.9604645e-8f,
                           65408.0f, 65408.0f, 65408.0f, 70000.0f, 1e30f, 65407.0f, -1.0f, -0.0f, 2.0f,
                           0.99999f, 0.5f, 0.25f,   1.0f, 1.0f, 1.0f,           65535.0f, 1.0f, 0.0f };
    const size_t ne = sizeof edge / sizeof edge[0] / 3;
    uint32_t seed = 12345u, i, k;
    size_t t;
    float back[3];
    for (t = 0; t < 3 * (size_t)N; ++t) rgb[t] = pk_random(&seed);
    /* a fifth of the texels grey-ish, the others' channels far apart */
    for (t = 0; t < N; t += 5) rgb[3 * t + 1] = rgb[3 * t] * 0.9f, rgb[3 * t + 2] = rgb[3 * t] * 1.1f;
    CHECK_OK(rad_rgb9e5_pack(rgb, N, w, NULL));
    CHECK(pk_within(rgb, w, N));
    CHECK_OK(rad_rgb9e5_pack(edge, ne, w, NULL));
    CHECK(pk_within(edge, w, ne));
    CHECK(w[0] == 0u);                          /* 0: every field 0 */
    CHECK(w[1] == 0u);                          /* the float denormals: below half the smallest step, 2^-24 */
    CHECK(w[2] == (1u << 18 | 1u << 9));        /* 2^-24 is one step; 3e-8 rounds up to it, 1e-8 down to 0 */
    CHECK(w[3] == 0xFFFFFFFFu && w[4] == 0xFFFFFFFFu); /* 65408; above it clamped (and 65407 rounds to 511) */
    rad_rgb9e5_unpack(w + 5, 1, back);
    CHECK(back[0] == 0.0f && back[1] == 0.0f && back[2] == 2.0f); /* negatives and -0 become +0 */
    CHECK(w[7] == (16u << 27 | 256u << 18 | 256u << 9 | 256u));  /* 1 1 1: mantissa 256 at exponent 16 */
    CHECK(w[6] == (16u << 27 | 64u << 18 | 128u << 9 | 256u));   /* 0.99999 rounds up to 512 steps: the next exponent */
    rad_rgb9e5_unpack(w + 8, 1, back);
    CHECK(back[0] == 65408.0f && back[1] == 0.0f);               /* 1 is below half a step of 128 */
    /* every exponent and mantissa unpacks to the definition, bit for bit */
    for (i = 0; i < 32; ++i)
        for (k = 0; k < 512; k += 7) {
            uint32_t word = i << 27 | k << 18 | (511u - k) << 9 | (k ^ 0x155u);
            rad_rgb9e5_unpack(&word, 1, back);
            CHECK((double)back[0] == pk_ref(word, 0) && (double)back[1] == pk_ref(word, 1) && (double)back[2] == pk_ref(word, 2));
        }
    /* count 0 with NULL is fine; NULL with texels, NaN and infinities are refused by texel */
    CHECK_OK(rad_rgb9e5_pack(NULL, 0, NULL, NULL));
    {
        rad_context ctx;
        sc_log_state lg;
        float bad[9] = { 1, 2, 3, 4, 5, 6, 7, 8, 9 };
        memset(&ctx, 0, sizeof ctx);
        memset(&lg, 0, sizeof lg);
        ctx.log = sc_log_fn;
        ctx.log_user = &lg;
        CHECK_RESULT(rad_rgb9e5_pack(NULL, 3, w, &ctx), RAD_ERROR_INVALID_ARGUMENT);
        CHECK_RESULT(rad_rgb9e5_pack(bad, 3, NULL, &ctx), RAD_ERROR_INVALID_ARGUMENT);
        bad[7] = (float)NAN;
        CHECK_RESULT(rad_rgb9e5_pack(bad, 3, w, &ctx), RAD_ERROR_NON_FINITE);
        CHECK(strstr(lg.last, "texel 2 channel 1") != NULL);
        bad[7] = 8.0f;
        bad[3] = (float)INFINITY;
        CHECK_RESULT(rad_rgb9e5_pack(bad, 3, w, &ctx), RAD_ERROR_NON_FINITE);
        CHECK(strstr(lg.last, "texel 1 channel 0") != NULL);
        bad[3] = -(float)INFINITY;
        CHECK_RESULT(rad_rgb9e5_pack(bad, 3, w, &ctx), RAD_ERROR_NON_FINITE);
    }
}

/* bit for bit where the implementation does not fuse (RAD_FMA lets it: then to rounding) */
static int pk_same(const float *a, const float *b, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i) {
#if defined(RAD_FMA)
        if (fabs((double)a[i] - b[i]) > 1e-6 * (fabs((double)b[i]) + 1e-3)) return 0;
#else
        if (memcmp(a + i, b + i, sizeof(float)) != 0) return 0;
#endif
    }
    return 1;
}

static void pk_test_mix_equals_float(void)
{
    static const size_t counts[] = { 1, 3, 63, 64, 65, 127, 1001, 8191, 8192, 8193, 20011 };
    const size_t most = 20011;
    uint32_t *w = (uint32_t *)malloc(8 * most * sizeof(uint32_t));
    float *un = (float *)malloc(8 * 3 * most * sizeof(float)), *a = (float *)malloc(3 * most * sizeof(float)),
          *b = (float *)malloc(3 * most * sizeof(float));
    float rgb[24];
    uint32_t seed = 99u, G, ci, k;
    size_t i;
    rad_context serial, reverse;
    memset(&serial, 0, sizeof serial);
    serial.parallel_for = fx_serial_for;
    reverse = serial;
    reverse.parallel_for = fx_reverse_for;
    if (!w || !un || !a || !b) {
        CHECK(0);
        free(w), free(un), free(a), free(b);
        return;
    }
    /* words of every exponent (random mantissas) */
    for (i = 0; i < 8 * most; ++i) {
        seed = seed * 1664525u + 1013904223u;
        w[i] = seed;
    }
    for (G = 1; G <= 8; ++G) {
        for (k = 0; k < 3 * G; ++k) {
            seed = seed * 1664525u + 1013904223u;
            rgb[k] = (float)((int)(seed >> 20) % 2001 - 500) / 250.0f; /* -2 to 6 */
            if (k % 4 == 1) rgb[k] = 0.0f;                               /* single channels off */
        }
        if (G > 2) rgb[3] = rgb[4] = rgb[5] = 0.0f;                      /* group 1 off: skipped */
        for (ci = 0; ci < sizeof counts / sizeof counts[0]; ++ci) {
            size_t T = counts[ci];
            /* the groups' planes T texels apart, as the bake lays them */
            for (k = 0; k < G; ++k) rad_rgb9e5_unpack(w + (size_t)k * T, T, un + 3 * (size_t)k * T);
            CHECK_OK(rad_baker_mix_layers(un, G, 3 * T, rgb, a, &serial));
            memset(b, 0xFF, 3 * T * sizeof(float));
            CHECK_OK(rad_baker_mix_layers_rgb9e5(w, G, T, rgb, b, ci % 2 ? &reverse : &serial));
            if (!pk_same(b, a, 3 * T)) printf("    %u groups, %lu texels: the packed mix differs\n", G, (unsigned long)T);
            CHECK(pk_same(b, a, 3 * T));
        }
        /* NULL scales: the plain sum */
        for (k = 0; k < G; ++k) rad_rgb9e5_unpack(w + (size_t)k * 1001, 1001, un + 3 * (size_t)k * 1001);
        CHECK_OK(rad_baker_mix_layers(un, G, 3 * 1001, NULL, a, NULL));
        CHECK_OK(rad_baker_mix_layers_rgb9e5(w, G, 1001, NULL, b, NULL));
        CHECK(pk_same(b, a, 3 * 1001));
    }
    /* every group off: zeros */
    for (k = 0; k < 24; ++k) rgb[k] = 0.0f;
    memset(b, 0xFF, 3 * 100 * sizeof(float));
    CHECK_OK(rad_baker_mix_layers_rgb9e5(w, 8, 100, rgb, b, NULL));
    for (i = 0; i < 300; ++i) CHECK(b[i] == 0.0f);
    /* bad input */
    {
        rad_context ctx;
        sc_log_state lg;
        memset(&ctx, 0, sizeof ctx);
        memset(&lg, 0, sizeof lg);
        ctx.log = sc_log_fn;
        ctx.log_user = &lg;
        CHECK_RESULT(rad_baker_mix_layers_rgb9e5(NULL, 1, 4, NULL, b, &ctx), RAD_ERROR_INVALID_ARGUMENT);
        CHECK_RESULT(rad_baker_mix_layers_rgb9e5(w, 1, 4, NULL, NULL, &ctx), RAD_ERROR_INVALID_ARGUMENT);
        CHECK_RESULT(rad_baker_mix_layers_rgb9e5(w, 0, 4, NULL, b, &ctx), RAD_ERROR_INVALID_ARGUMENT);
        CHECK_RESULT(rad_baker_mix_layers_rgb9e5(w, RAD_BAKER_MAX_GROUPS + 1, 4, NULL, b, &ctx), RAD_ERROR_INVALID_ARGUMENT);
        rgb[4] = (float)NAN;
        CHECK_RESULT(rad_baker_mix_layers_rgb9e5(w, 2, 4, rgb, b, &ctx), RAD_ERROR_NON_FINITE);
        CHECK(strstr(lg.last, "group 1 channel 1") != NULL);
    }
    free(w), free(un), free(a), free(b);
}

/* The two rooms (fixtures.h) with a lightmap, two point lights in two groups. */
typedef struct pk_scene {
    lm_soup room, wall, lamp;
    rad_mesh_desc meshes[3];
    rad_material mats[2];
    rad_baker_desc d;
    rad_baker_light bl[2];
} pk_scene;

static void pk_point(rad_light *l, float x, float y, float z, float power)
{
    memset(l, 0, sizeof(*l));
    l->type = RAD_LIGHT_POINT;
    l->position[0] = x, l->position[1] = y, l->position[2] = z;
    l->color[0] = power, l->color[1] = 0.8f * power, l->color[2] = 0.6f * power;
}

static void pk_make(pk_scene *s, uint32_t flags)
{
    memset(&s->d, 0, sizeof s->d);
    memset(s->bl, 0, sizeof s->bl);
    fx_two_rooms(&s->room, &s->wall, &s->lamp, s->meshes, &s->d.scene, s->mats);
    pk_point(&s->bl[0].light, 1.3f, 0.7f, 0.3f, 1.0f);
    pk_point(&s->bl[1].light, 0.4f, 0.6f, 0.6f, 0.5f);
    s->bl[1].group = 1;
    s->d.lights = s->bl;
    s->d.light_count = 2;
    s->d.outputs = RAD_BAKER_LIGHTMAP;
    s->d.lightmap_width = 32;
    s->d.lightmap_height = 16;
    s->d.lightmap_flags = flags;
}

static void pk_options(rad_baker_options *o, rad_baker_method method)
{
    memset(o, 0, sizeof(*o));
    o->method = method;
    o->patches = rad_test_quick() ? 80u : 150u;
    o->vp_resolution = 5;
    o->ff_samples = 4;
    o->bounces = 8;
    o->light_samples = 4;
    o->lightmap_samples = 1;
}

static void pk_test_bake(void)
{
    int pass;
    for (pass = 0; pass < 2; ++pass) {
        pk_scene s;
        rad_baker_options o;
        rad_baker_result *F = NULL, *A = NULL, *P = NULL;
        pk_options(&o, pass ? RAD_BAKER_VIRTUAL_PATCHES : RAD_BAKER_CLASSIC);
        pk_make(&s, 0);
        CHECK_OK(rad_baker_run(&s.d, &o, NULL, &F));
        pk_make(&s, RAD_BAKER_LIGHTMAP_RGB9E5);
        CHECK_OK(rad_baker_run(&s.d, &o, NULL, &A));
        pk_make(&s, RAD_BAKER_LIGHTMAP_RGB9E5_ONLY);
        CHECK_OK(rad_baker_run(&s.d, &o, NULL, &P));
        if (F && A && P) {
            size_t T = (size_t)F->lightmap_width * F->lightmap_height, i;
            float scale[6] = { 0.5f, 1.0f, 2.0f, 3.0f, 0.0f, 1.0f };
            float *mix = (float *)malloc(3 * T * sizeof(float));
            double sum = 0.0;
            CHECK(F->group_count == 2 && F->lightmap_rgb9e5 == NULL);
            /* ALSO: the float layers and lightmap as without the flag, the packed ones within the bound */
            CHECK(A->lightmap_layers && A->lightmap_rgb9e5 &&
                  memcmp(A->lightmap_layers, F->lightmap_layers, 2 * 3 * T * sizeof(float)) == 0);
            CHECK(memcmp(A->lightmap, F->lightmap, 3 * T * sizeof(float)) == 0);
            CHECK(pk_within(F->lightmap_layers, A->lightmap_rgb9e5, 2 * T));
            for (i = 0; i < 3 * T; ++i) sum += F->lightmap_layers[i];
            CHECK(sum > 0.0); /* the layers hold light: the bound is not met by zeros */
            /* ONLY: the same packed layers, no float ones, the lightmap their mix */
            CHECK(P->lightmap_layers == NULL && P->lightmap_rgb9e5 &&
                  memcmp(P->lightmap_rgb9e5, A->lightmap_rgb9e5, 2 * T * sizeof(uint32_t)) == 0);
            if (mix) {
                CHECK_OK(rad_baker_mix_layers_rgb9e5(P->lightmap_rgb9e5, 2, T, NULL, mix, NULL));
                CHECK(memcmp(mix, P->lightmap, 3 * T * sizeof(float)) == 0);
                CHECK_OK(rad_baker_mix(P, scale, NULL));
                CHECK_OK(rad_baker_mix_layers_rgb9e5(P->lightmap_rgb9e5, 2, T, scale, mix, NULL));
                CHECK(memcmp(mix, P->lightmap, 3 * T * sizeof(float)) == 0);
            }
            free(mix);
        }
        rad_baker_result_destroy(F);
        rad_baker_result_destroy(A);
        rad_baker_result_destroy(P);
    }
}

static void pk_test_bake_refused(void)
{
    pk_scene s;
    rad_baker_options o;
    rad_baker_result *R = NULL;
    rad_lightmap_gather_options go;
    rad_context ctx;
    sc_log_state lg;
    memset(&ctx, 0, sizeof ctx);
    memset(&lg, 0, sizeof lg);
    ctx.log = sc_log_fn;
    ctx.log_user = &lg;
    pk_options(&o, RAD_BAKER_CLASSIC);
    /* sky layers are SH coefficients (negative): not packed-only */
    pk_make(&s, RAD_BAKER_LIGHTMAP_RGB9E5_ONLY);
    o.sky_bands = 2;
    CHECK_RESULT(rad_baker_run(&s.d, &o, &ctx, &R), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(R == NULL && strstr(lg.last, "RGB9E5_ONLY with sky layers") != NULL);
    o.sky_bands = 0;
    /* the SH lightmap encoding: not packed at all */
    rad_lightmap_gather_options_default(&go);
    go.encoding = RAD_LIGHTMAP_SH_L1;
    pk_make(&s, RAD_BAKER_LIGHTMAP_RGB9E5);
    s.d.lightmap_gather = &go;
    CHECK_RESULT(rad_baker_run(&s.d, &o, &ctx, &R), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(R == NULL && strstr(lg.last, "RGB9E5") != NULL && strstr(lg.last, "SH") != NULL);
    /* an unknown flag still is */
    pk_make(&s, 64u);
    CHECK_RESULT(rad_baker_run(&s.d, &o, &ctx, &R), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(R == NULL);
}

/* The runtime on a packed-only bake: the lightmap its packed layers' mix, within the bound of
   the float runtime's (the bake's lights, and moved, budget 0: classic exact in one frame) */
static void pk_test_runtime(void)
{
    int pass;
    for (pass = 0; pass < 2; ++pass) {
        pk_scene s;
        rad_baker_options o;
        rad_baker_result *F = NULL, *P = NULL;
        rad_baker_runtime *rf = NULL, *rp = NULL;
        rad_baker_frame ff, fp;
        rad_light moved[2];
        pk_options(&o, pass ? RAD_BAKER_VIRTUAL_PATCHES : RAD_BAKER_CLASSIC);
        pk_make(&s, 0);
        CHECK_OK(rad_baker_run(&s.d, &o, NULL, &F));
        if (F) CHECK_OK(rad_baker_runtime_create(&s.d, &o, F, NULL, NULL, &rf));
        pk_make(&s, RAD_BAKER_LIGHTMAP_RGB9E5_ONLY);
        CHECK_OK(rad_baker_run(&s.d, &o, NULL, &P));
        if (P) CHECK_OK(rad_baker_runtime_create(&s.d, &o, P, NULL, NULL, &rp));
        if (rf && rp) {
            size_t T = (size_t)F->lightmap_width * F->lightmap_height, t;
            int c, within = 1;
            moved[0] = s.bl[0].light, moved[1] = s.bl[1].light;
            CHECK_OK(rad_baker_runtime_update(rf, moved, 2, 0.0, &ff));
            CHECK_OK(rad_baker_runtime_update(rp, moved, 2, 0.0, &fp));
            /* the bake's lights: each runtime's lightmap is its bake's, bit for bit */
            CHECK(fp.lightmap && memcmp(fp.lightmap, P->lightmap, 3 * T * sizeof(float)) == 0);
            CHECK(ff.lightmap && memcmp(ff.lightmap, F->lightmap, 3 * T * sizeof(float)) == 0);
            /* and within the bound of each other: the two groups' rounding added */
            for (t = 0; fp.lightmap && ff.lightmap && t < T; ++t) {
                double top = 0.0;
                int g;
                for (g = 0; g < 2; ++g)
                    for (c = 0; c < 3; ++c) {
                        double v = F->lightmap_layers[3 * ((size_t)g * T + t) + (size_t)c];
                        if (v > top) top = v;
                    }
                for (c = 0; c < 3; ++c)
                    if (fabs((double)fp.lightmap[3 * t + c] - ff.lightmap[3 * t + c]) > 2.0 * ldexp(top, -9) * 1.0001 + 1e-7)
                        within = 0;
            }
            CHECK(within);
            if (pass == 0) {
                /* a light that moves: the classic frame is exact, the packed lightmap enters only as detail */
                moved[0].position[0] -= 0.2f;
                CHECK_OK(rad_baker_runtime_update(rf, moved, 2, 0.0, &ff));
                CHECK_OK(rad_baker_runtime_update(rp, moved, 2, 0.0, &fp));
                if (ff.lightmap && fp.lightmap) {
                    double d = 0.0, m = 0.0;
                    for (t = 0; t < 3 * T; ++t) d += fabs((double)fp.lightmap[t] - ff.lightmap[t]), m += fabs((double)ff.lightmap[t]);
                    CHECK(m > 0.0 && d <= ldexp(m, -8));
                }
            }
        }
        rad_baker_runtime_destroy(rf);
        rad_baker_runtime_destroy(rp);
        rad_baker_result_destroy(F);
        rad_baker_result_destroy(P);
    }
}

static const rad_test_case tests_rgb9e5[] = {
    { "rgb9e5_round_trip", pk_test_round_trip },
    { "rgb9e5_mix_equals_float", pk_test_mix_equals_float },
    { "rgb9e5_bake", pk_test_bake },
    { "rgb9e5_bake_refused", pk_test_bake_refused },
    { "rgb9e5_runtime", pk_test_runtime },
    { NULL, NULL }
};

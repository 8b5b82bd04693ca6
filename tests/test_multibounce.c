/* test_multibounce.c - the multi-bounce matrix and its compression (docs/methods/multibounce.md,
   docs/methods/compression.md): F_mb E against K
   Jacobi bounces and the direct solve, binary16, hand-built BC1/BC4 blocks against the
   decode rules of the Khronos Data Format specification, encoder error bounds, permutations, the compressed apply, and
   the container sections. Included by test_main.c after the implementation: every name is
   static and prefixed mb_. */
#include "fixtures.h"


/* ---------------------------------------------------------------------------------------- */
/* helpers                                                                                  */
/* ---------------------------------------------------------------------------------------- */

/* the shared Cornell world (fixtures.h) */
typedef fx_world mb_world;

/* The built-in Cornell box cut into about 'target' patches, dense form factors through the
   BVH, E = emission. Returns 0 on failure (and records it). */
static int mb_cornell(mb_world *w, uint32_t target)
{
    if (fx_cornell(w, target, 0, 0)) return 1;
    CHECK(!"cornell setup");
    return 0;
}

static uint32_t mb_target(void) { return rad_test_quick() ? 120u : 300u; }

/* max |a - b| / max |b| over n values */
static double mb_rel(const float *a, const float *b, size_t n)
{
    double d = 0.0, m = 0.0;
    size_t i;
    for (i = 0; i < n; ++i) {
        if (fabs((double)a[i] - b[i]) > d) d = fabs((double)a[i] - b[i]);
        if (fabs((double)b[i]) > m) m = fabs((double)b[i]);
    }
    return m > 0.0 ? d / m : d;
}

static int mb_is_permutation(const uint32_t *p, uint32_t n)
{
    unsigned char *seen = (unsigned char *)calloc(n, 1);
    uint32_t i;
    int ok = seen != NULL;
    for (i = 0; i < n && ok; ++i) {
        if (p[i] >= n || seen[p[i]]) ok = 0;
        else seen[p[i]] = 1;
    }
    free(seen);
    return ok;
}

static float mb_rand(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return (float)(*s >> 8) / 16777216.0f;
}

/* ---------------------------------------------------------------------------------------- */
/* tests                                                                                    */
/* ---------------------------------------------------------------------------------------- */

static void mb_half(void)
{
    uint32_t h;
    int bad = 0;
    CHECK(rad_half_from_float(1.0f) == 0x3C00u);
    CHECK(rad_half_from_float(-2.0f) == 0xC000u);
    CHECK(rad_half_from_float(65504.0f) == 0x7BFFu);
    CHECK(rad_half_from_float(65519.0f) == 0x7BFFu);
    CHECK(rad_half_from_float(65520.0f) == 0x7C00u);            /* tie rounds to even: infinity */
    CHECK(rad_half_from_float(5.9604644775390625e-8f) == 0x0001u); /* 2^-24, smallest subnormal */
    CHECK(rad_half_from_float(2.98023223876953125e-8f) == 0x0000u); /* 2^-25: tie to even 0 */
    CHECK(rad_half_from_float(4.4703483581542969e-8f) == 0x0001u);  /* 1.5 * 2^-25 */
    CHECK(rad_half_from_float(1.0f + 1.0f / 2048.0f) == 0x3C00u);   /* tie, even stays */
    CHECK(rad_half_from_float(1.0f + 3.0f / 2048.0f) == 0x3C02u);   /* tie, odd rounds up */
    CHECK(rad_half_from_float(6.103515625e-5f) == 0x0400u);         /* 2^-14, smallest normal */
    CHECK((rad_half_from_float(sqrtf(-1.0f)) & 0x7C00u) == 0x7C00u && (rad_half_from_float(sqrtf(-1.0f)) & 0x3FFu) != 0);
    for (h = 0; h < 65536u; ++h) {
        if ((h & 0x7C00u) == 0x7C00u && (h & 0x3FFu)) continue; /* NaN */
        if (rad_half_from_float(rad_half_to_float((uint16_t)h)) != h) bad++;
    }
    CHECK(bad == 0);
    CHECK(rad_half_to_float(0x3555u) > 0.333f && rad_half_to_float(0x3555u) < 0.3334f);
}

static void mb_jacobi(void)
{
    mb_world w;
    uint32_t ks[3] = { 1, 3, 8 }, k, n;
    if (!mb_cornell(&w, mb_target())) return;
    n = w.patches->count;
    for (k = 0; k < 3; ++k) {
        rad_multibounce_options o;
        rad_multibounce *mb = NULL;
        rad_solve_options so;
        rad_system sys;
        float *ref = (float *)malloc(sizeof(float) * 3 * n), *got = (float *)malloc(sizeof(float) * 3 * n);
        rad_multibounce_options_default(&o);
        o.bounces = ks[k];
        CHECK_OK(rad_multibounce_create(&w.ff->matrix, w.patches->albedo, &o, NULL, &mb));
        rad_system_init(&sys, &w.ff->matrix, w.patches, w.E);
        rad_solve_options_default(&so);
        so.bounces = ks[k];
        so.output = RAD_OUTPUT_INDIRECT;
        CHECK_OK(rad_solve_jacobi(&sys, &so, ref, NULL, NULL));
        if (mb && ref && got) {
            CHECK_OK(rad_multibounce_apply(mb, w.E, got, RAD_OUTPUT_INDIRECT, NULL));
            CHECK(mb_rel(got, ref, 3 * (size_t)n) <= 1e-5);
            CHECK_OK(rad_multibounce_apply(mb, w.E, got, RAD_OUTPUT_TOTAL, NULL));
            CHECK_NEAR(got[0] - w.E[0], ref[0], 1e-5 * (fabs(ref[0]) + 1e-3));
        }
        rad_multibounce_destroy(mb);
        free(ref);
        free(got);
    }
    fx_world_free(&w);
}

static void mb_infinite(void)
{
    mb_world w;
    rad_multibounce_options o;
    rad_multibounce *mb = NULL;
    rad_solve_options so;
    rad_system sys;
    float *ref, *got;
    uint32_t n;
    if (!mb_cornell(&w, rad_test_quick() ? 80u : 200u)) return;
    n = w.patches->count;
    ref = (float *)malloc(sizeof(float) * 3 * n);
    got = (float *)malloc(sizeof(float) * 3 * n);
    rad_multibounce_options_default(&o);
    o.bounces = RAD_MB_INFINITE;
    CHECK_OK(rad_multibounce_create(&w.ff->matrix, w.patches->albedo, &o, NULL, &mb));
    rad_system_init(&sys, &w.ff->matrix, w.patches, w.E);
    rad_solve_options_default(&so);
    so.output = RAD_OUTPUT_INDIRECT;
    CHECK_OK(rad_solve_direct(&sys, &so, ref, NULL));
    if (mb && ref && got) {
        CHECK_OK(rad_multibounce_apply(mb, w.E, got, RAD_OUTPUT_INDIRECT, NULL));
        CHECK(mb_rel(got, ref, 3 * (size_t)n) <= 1e-5);
    }
    /* a tolerance that cannot be met in 2 doublings */
    rad_multibounce_destroy(mb);
    mb = NULL;
    o.max_doublings = 2;
    CHECK_RESULT(rad_multibounce_create(&w.ff->matrix, w.patches->albedo, &o, NULL, &mb), RAD_ERROR_NOT_CONVERGED);
    CHECK(mb == NULL);
    free(ref);
    free(got);
    fx_world_free(&w);
}

static void mb_bc1_decode(void)
{
    /* four-colour mode: c0 = red 0xF800 > c1 = blue 0x001F; texels 0..3 take codes 0..3, the
       rest code 0; texel 15 code 3 */
    uint8_t blk[8] = { 0x00, 0xF8, 0x1F, 0x00, 0xE4, 0x00, 0x00, 0xC0 };
    float rgb[48];
    rad_bc1_decode_block(blk, rgb);
    CHECK(rgb[0] == 1.0f && rgb[1] == 0.0f && rgb[2] == 0.0f);             /* C0 */
    CHECK(rgb[3] == 0.0f && rgb[4] == 0.0f && rgb[5] == 1.0f);             /* C1 */
    CHECK_NEAR(rgb[6], 2.0 / 3.0, 1e-7); CHECK_NEAR(rgb[8], 1.0 / 3.0, 1e-7); /* (2C0+C1)/3 */
    CHECK_NEAR(rgb[9], 1.0 / 3.0, 1e-7); CHECK_NEAR(rgb[11], 2.0 / 3.0, 1e-7); /* (C0+2C1)/3 */
    CHECK(rgb[12] == 1.0f);                                                  /* texel 4: code 0 */
    CHECK_NEAR(rgb[45], 1.0 / 3.0, 1e-7);                                    /* texel 15: code 3 */
    /* three-colour mode: c0 = blue 0x001F <= c1 = green 0x07E0; code 2 = (C0+C1)/2, code 3 black */
    {
        uint8_t b2[8] = { 0x1F, 0x00, 0xE0, 0x07, 0xE4, 0x00, 0x00, 0x00 };
        rad_bc1_decode_block(b2, rgb);
        CHECK(rgb[0] == 0.0f && rgb[1] == 0.0f && rgb[2] == 1.0f);
        CHECK(rgb[3] == 0.0f && rgb[4] == 1.0f && rgb[5] == 0.0f);
        CHECK(rgb[6] == 0.0f && rgb[7] == 0.5f && rgb[8] == 0.5f);
        CHECK(rgb[9] == 0.0f && rgb[10] == 0.0f && rgb[11] == 0.0f);        /* black */
    }
    /* equal endpoints are the three-colour mode; 565 expansion uses /31 and /63 */
    {
        uint8_t b3[8] = { 0x21, 0x08, 0x21, 0x08, 0xFF, 0xFF, 0xFF, 0xFF };  /* 0x0821: r 1, g 1, b 1 */
        rad_bc1_decode_block(b3, rgb);
        CHECK(rgb[0] == 0.0f && rgb[47] == 0.0f);                          /* all code 3: black */
        b3[4] = b3[5] = b3[6] = b3[7] = 0;
        rad_bc1_decode_block(b3, rgb);
        CHECK(rgb[0] == 1.0f / 31.0f && rgb[1] == 1.0f / 63.0f && rgb[2] == 1.0f / 31.0f);
    }
}

static void mb_bc4_decode(void)
{
    /* eight-value mode: r0 = 200 > r1 = 10, texel t has code t % 8 */
    uint8_t blk[8];
    float v[16];
    uint64_t bits = 0;
    int t;
    for (t = 0; t < 16; ++t) bits |= (uint64_t)(t % 8) << (3 * t);
    blk[0] = 200; blk[1] = 10;
    for (t = 0; t < 6; ++t) blk[2 + t] = (uint8_t)(bits >> (8 * t));
    rad_bc4_decode_block(blk, v);
    CHECK(v[0] == 200.0f / 255.0f && v[1] == 10.0f / 255.0f);
    for (t = 2; t < 8; ++t) CHECK_NEAR(v[t], ((8.0 - t) * 200.0 / 255.0 + (t - 1.0) * 10.0 / 255.0) / 7.0, 1e-7);
    CHECK_NEAR(v[2], (6.0 * 200.0 + 10.0) / 7.0 / 255.0, 1e-7);
    CHECK(v[8] == v[0] && v[15] == v[7]);
    /* six-value mode: r0 = 10 <= r1 = 200; codes 6 and 7 are exactly 0 and 1 */
    blk[0] = 10; blk[1] = 200;
    rad_bc4_decode_block(blk, v);
    CHECK(v[0] == 10.0f / 255.0f && v[1] == 200.0f / 255.0f);
    for (t = 2; t < 6; ++t) CHECK_NEAR(v[t], ((6.0 - t) * 10.0 / 255.0 + (t - 1.0) * 200.0 / 255.0) / 5.0, 1e-7);
    CHECK_NEAR(v[2], (4.0 * 10.0 + 200.0) / 5.0 / 255.0, 1e-7);
    CHECK(v[6] == 0.0f && v[7] == 1.0f);
    /* equal endpoints are the six-value mode too */
    blk[0] = blk[1] = 77;
    rad_bc4_decode_block(blk, v);
    CHECK(v[6] == 0.0f && v[7] == 1.0f && v[3] == 77.0f / 255.0f);
}

static void mb_encode_bounds(void)
{
    uint32_t seed = 12345u, trial, t;
    double bc4_rand = 0.0, bc4_smooth = 0.0, bc1_smooth = 0.0, bc1_rand_rms = 0.0;
    for (trial = 0; trial < 2000; ++trial) {
        float v[16], d[16], rgb[48], drgb[48], base = mb_rand(&seed) * 0.8f, slope = mb_rand(&seed) * 0.1f;
        uint8_t blk[8];
        double sse = 0.0;
        for (t = 0; t < 16; ++t) v[t] = mb_rand(&seed);
        rad_bc4_encode_block(v, blk);
        rad_bc4_decode_block(blk, d);
        for (t = 0; t < 16; ++t) if (fabs((double)d[t] - v[t]) > bc4_rand) bc4_rand = fabs((double)d[t] - v[t]);
        for (t = 0; t < 16; ++t) v[t] = base + slope * (float)(t % 4) / 3.0f + 0.5f * slope * (float)(t / 4) / 3.0f;
        rad_bc4_encode_block(v, blk);
        rad_bc4_decode_block(blk, d);
        for (t = 0; t < 16; ++t) if (fabs((double)d[t] - v[t]) > bc4_smooth) bc4_smooth = fabs((double)d[t] - v[t]);
        for (t = 0; t < 16; ++t) {
            float g = base + slope * (float)(t % 4) / 3.0f + 0.5f * slope * (float)(t / 4) / 3.0f;
            rgb[3 * t] = g; rgb[3 * t + 1] = 0.9f * g; rgb[3 * t + 2] = 0.7f * g + 0.05f;
        }
        rad_bc1_encode_block(rgb, blk);
        rad_bc1_decode_block(blk, drgb);
        for (t = 0; t < 48; ++t) if (fabs((double)drgb[t] - rgb[t]) > bc1_smooth) bc1_smooth = fabs((double)drgb[t] - rgb[t]);
        for (t = 0; t < 48; ++t) rgb[t] = mb_rand(&seed);
        rad_bc1_encode_block(rgb, blk);
        rad_bc1_decode_block(blk, drgb);
        for (t = 0; t < 48; ++t) sse += ((double)drgb[t] - rgb[t]) * ((double)drgb[t] - rgb[t]);
        bc1_rand_rms += sse / 48.0;
    }
    bc1_rand_rms = sqrt(bc1_rand_rms / 2000.0);
    /* BC4: 8 levels over a range of at most 1 (step 1/7); the encoder minimises the squared
       error, so a single texel may sit up to one step from its value */
    CHECK(bc4_rand <= 1.0 / 7.0);
    /* smooth ramps of range <= 0.15: an eighth of a 1/255 step plus the interpolation step */
    CHECK(bc4_smooth <= 0.15 / 14.0 + 1.0 / 255.0);
    /* BC1 on smooth correlated colour: 5-bit endpoints (1/62) plus a third of the range */
    CHECK(bc1_smooth <= 1.0 / 31.0 + 0.15 / 6.0 + 1e-3);
    /* BC1 on white noise: 4 colours for 16 random RGB texels; rms well below uniform (0.41) */
    CHECK(bc1_rand_rms <= 0.25);
    /* exact cases: zeros, the endpoints, 0 and 1 in the six-value mode */
    {
        float v[16], d[16], rgb[48], drgb[48];
        uint8_t blk[8];
        for (t = 0; t < 16; ++t) v[t] = (t % 3 == 0) ? 0.0f : ((t % 3 == 1) ? 1.0f : 128.0f / 255.0f);
        rad_bc4_encode_block(v, blk);
        rad_bc4_decode_block(blk, d);
        for (t = 0; t < 16; ++t) CHECK(d[t] == v[t]);
        for (t = 0; t < 48; ++t) rgb[t] = (t / 3) % 2 ? 0.0f : 1.0f;
        rad_bc1_encode_block(rgb, blk);
        rad_bc1_decode_block(blk, drgb);
        for (t = 0; t < 48; ++t) CHECK(drgb[t] == rgb[t]);
    }
}

static void mb_permutations(void)
{
    /* dyadic entries and integer E: every partial sum is exact in float, so any summation
       order gives the same bits and the permuted apply must equal the plain one exactly */
    enum { N = 37 };
    static float planes[3 * N * N];
    float E[3 * N], a[3 * N], b[3 * N];
    rad_multibounce view, *perm = NULL, *sampled = NULL;
    uint32_t i, seed = 7u;
    for (i = 0; i < 3 * N * N; ++i) planes[i] = (float)((uint32_t)(mb_rand(&seed) * 16.0f) * (uint32_t)(i % 5 == 0)) / 1024.0f;
    for (i = 0; i < 3 * N; ++i) E[i] = (float)(uint32_t)(mb_rand(&seed) * 8.0f);
    memset(&view, 0, sizeof(view));
    view.n = N;
    view.bounces = 1;
    view.precision = RAD_MB_FLOAT;
    view.planes = planes;
    CHECK_OK(rad_multibounce_reorder(&view, 0, NULL, &perm));
    CHECK_OK(rad_multibounce_reorder(&view, 10, NULL, &sampled));
    if (!perm || !sampled) return;
    CHECK(mb_is_permutation(perm->row_perm, N) && mb_is_permutation(perm->col_perm, N));
    CHECK(mb_is_permutation(sampled->row_perm, N) && mb_is_permutation(sampled->col_perm, N));
    CHECK_OK(rad_multibounce_apply(&view, E, a, RAD_OUTPUT_INDIRECT, NULL));
    CHECK_OK(rad_multibounce_apply(perm, E, b, RAD_OUTPUT_INDIRECT, NULL));
    CHECK(memcmp(a, b, sizeof(a)) == 0);
    CHECK_OK(rad_multibounce_apply(sampled, E, b, RAD_OUTPUT_INDIRECT, NULL));
    CHECK(memcmp(a, b, sizeof(a)) == 0);
    rad_multibounce_destroy(sampled);
    CHECK_RESULT(rad_multibounce_reorder(perm, 0, NULL, &sampled), RAD_ERROR_INVALID_ARGUMENT); /* already permuted */
    CHECK(sampled == NULL);
    rad_multibounce_destroy(perm);
    /* on the Cornell matrix: bijections, and the same L up to float summation order */
    {
        mb_world w;
        rad_multibounce *mb = NULL, *p = NULL;
        float *x, *y;
        uint32_t n;
        if (!mb_cornell(&w, mb_target())) return;
        n = w.patches->count;
        x = (float *)malloc(sizeof(float) * 3 * n);
        y = (float *)malloc(sizeof(float) * 3 * n);
        CHECK_OK(rad_multibounce_create(&w.ff->matrix, w.patches->albedo, NULL, NULL, &mb));
        CHECK_OK(rad_multibounce_reorder(mb, 0, NULL, &p));
        if (mb && p && x && y) {
            CHECK(mb_is_permutation(p->row_perm, n) && mb_is_permutation(p->col_perm, n));
            CHECK_OK(rad_multibounce_apply(mb, w.E, x, RAD_OUTPUT_INDIRECT, NULL));
            CHECK_OK(rad_multibounce_apply(p, w.E, y, RAD_OUTPUT_INDIRECT, NULL));
            CHECK(mb_rel(y, x, 3 * (size_t)n) <= 1e-6);
        }
        rad_multibounce_destroy(mb);
        rad_multibounce_destroy(p);
        free(x);
        free(y);
        fx_world_free(&w);
    }
}

static void mb_half_apply(void)
{
    mb_world w;
    rad_multibounce *mb = NULL, *h = NULL, *back = NULL;
    float *x, *y;
    uint32_t n, i;
    if (!mb_cornell(&w, mb_target())) return;
    n = w.patches->count;
    x = (float *)malloc(sizeof(float) * 3 * n);
    y = (float *)malloc(sizeof(float) * 3 * n);
    CHECK_OK(rad_multibounce_create(&w.ff->matrix, w.patches->albedo, NULL, NULL, &mb));
    CHECK_OK(rad_multibounce_convert(mb, RAD_MB_HALF, NULL, &h));
    CHECK_OK(rad_multibounce_convert(h, RAD_MB_FLOAT, NULL, &back));
    if (mb && h && back && x && y) {
        CHECK(h->precision == RAD_MB_HALF && h->half && !h->planes);
        CHECK_OK(rad_multibounce_apply(mb, w.E, x, RAD_OUTPUT_INDIRECT, NULL));
        CHECK_OK(rad_multibounce_apply(h, w.E, y, RAD_OUTPUT_INDIRECT, NULL));
        /* every entry and E are >= 0, so each result is within the relative rounding of
           binary16 (2^-11), plus subnormal flushes (below 6e-5 absolute per entry) */
        for (i = 0; i < 3 * n; ++i) CHECK(fabs((double)y[i] - x[i]) <= 4.9e-4 * fabs((double)x[i]) + 1e-4);
        for (i = 0; i < 3 * n * n; i += 97) CHECK(fabs((double)back->planes[i] - mb->planes[i]) <= 4.9e-4 * mb->planes[i] + 3e-8);
    }
    rad_multibounce_destroy(mb);
    rad_multibounce_destroy(h);
    rad_multibounce_destroy(back);
    free(x);
    free(y);
    fx_world_free(&w);
}

static void mb_compressed(void)
{
    mb_world w;
    rad_multibounce *mb = NULL;
    uint32_t n, f, ro;
    double mse[RAD_REORDER_MATCH + 1];
    float *exact, *got, *dec, *viadec;
    if (!mb_cornell(&w, mb_target())) return;
    n = w.patches->count;
    exact = (float *)malloc(sizeof(float) * 3 * n);
    got = (float *)malloc(sizeof(float) * 3 * n);
    viadec = (float *)malloc(sizeof(float) * 3 * n);
    dec = (float *)malloc(sizeof(float) * 3 * n * n);
    CHECK_OK(rad_multibounce_create(&w.ff->matrix, w.patches->albedo, NULL, NULL, &mb));
    if (!mb || !exact || !got || !dec || !viadec) goto done;
    CHECK_OK(rad_multibounce_apply(mb, w.E, exact, RAD_OUTPUT_INDIRECT, NULL));
    for (f = 0; f < 2; ++f)
        for (ro = 0; ro <= RAD_REORDER_MATCH; ++ro) {
            rad_block_options o;
            rad_block_report rep;
            rad_multibounce_blocks *b = NULL;
            rad_multibounce view;
            double sse = 0.0, rel;
            size_t i;
            rad_block_options_default(&o);
            o.format = f ? RAD_BLOCK_BC4X3 : RAD_BLOCK_BC1;
            o.reorder = ro ? (int)ro : RAD_REORDER_NONE; /* ro 0: the patch order kept */
            CHECK_OK(rad_multibounce_blocks_create(mb, &o, NULL, &b, &rep));
            if (!b) continue;
            CHECK(rep.outlier_count == (uint64_t)(0.05 * (double)n * n) || rep.outlier_count < (uint64_t)(0.05 * (double)n * n));
            CHECK(rep.outlier_count > 0);
            if (ro) CHECK(mb_is_permutation(b->row_perm, n) && mb_is_permutation(b->col_perm, n));
            CHECK_OK(rad_multibounce_blocks_decode(b, dec, NULL));
            for (i = 0; i < 3 * (size_t)n * n; ++i) sse += ((double)dec[i] - mb->planes[i]) * ((double)dec[i] - mb->planes[i]);
            CHECK_REL(sse / (3.0 * n * n), rep.mse, 1e-3);
            /* the on-the-fly apply equals the decoded matrix times E */
            memset(&view, 0, sizeof(view));
            view.n = n; view.bounces = 3; view.precision = RAD_MB_FLOAT; view.planes = dec;
            CHECK_OK(rad_multibounce_apply(&view, w.E, viadec, RAD_OUTPUT_INDIRECT, NULL));
            CHECK_OK(rad_multibounce_blocks_apply(b, w.E, got, RAD_OUTPUT_INDIRECT, NULL));
            CHECK(mb_rel(got, viadec, 3 * (size_t)n) <= 1e-5);
            /* stated bounds for the Cornell E, relative to max |L|. Measured: 3xBC4 1.8-2.6%; BC1
               3.4-8.8% (one 5-6-5 palette shared by R, G and B per 4x4 block; reordering groups
               rows by overall shape, which can put unlike colours in one block: with the
               form factors integrated from the smaller patch of each pair the reordered BC1
               case measures 8.8%). BC1 is the low-precision format: 3xBC4 is the one to use
               when L matters. */
            rel = mb_rel(got, exact, 3 * (size_t)n);
            printf("    %s reorder %u: mse %.3g (mean square %.3g), L error %.3g, %zu bytes of %zu\n", f ? "BC4x3" : "BC1",
                   ro, rep.mse, rep.source_mean_square, rel, rep.bytes_total, rep.bytes_float_f);
            CHECK(rel <= (f ? 0.04 : 0.12));
            /* every ordering keeps the MSE at or below the patch order's */
            mse[ro] = rep.mse;
            if (ro) CHECK(mse[ro] <= mse[0]);
            rad_multibounce_blocks_destroy(b);
        }
done:
    rad_multibounce_destroy(mb);
    free(exact);
    free(got);
    free(dec);
    free(viadec);
    fx_world_free(&w);
}

static void mb_container(void)
{
    mb_world w;
    rad_multibounce *mb = NULL, *h = NULL, *lmb = NULL;
    rad_multibounce_blocks *b = NULL, *lb = NULL;
    rad_section s[3 * RAD_MB_MAX_SECTIONS];
    uint32_t k1 = 0, k2 = 0, k3 = 0, n, i;
    size_t bytes;
    void *buf = NULL;
    rad_container *ct = NULL;
    float *x, *y;
    rad_block_options o;
    if (!mb_cornell(&w, rad_test_quick() ? 80u : 150u)) return;
    n = w.patches->count;
    x = (float *)malloc(sizeof(float) * 3 * n);
    y = (float *)malloc(sizeof(float) * 3 * n);
    CHECK_OK(rad_multibounce_create(&w.ff->matrix, w.patches->albedo, NULL, NULL, &mb));
    CHECK_OK(rad_multibounce_reorder(mb, 0, NULL, &h));
    rad_block_options_default(&o);
    o.tile = 16;
    CHECK_OK(rad_multibounce_blocks_create(mb, &o, NULL, &b, NULL));
    if (!mb || !h || !b || !x || !y) goto done;
    CHECK_OK(rad_multibounce_sections(mb, "Fmb", s, &k1));
    CHECK_OK(rad_multibounce_sections(h, "Fmb-perm", s + k1, &k2));
    CHECK_OK(rad_multibounce_blocks_sections(b, "Fmb-bc4", s + k1 + k2, &k3));
    CHECK(k1 == 2 && k2 == 4 && k3 == 8);
    CHECK_OK(rad_container_size(s, k1 + k2 + k3, &bytes));
    buf = malloc(bytes);
    CHECK_OK(rad_container_write(s, k1 + k2 + k3, buf, bytes));
    CHECK_OK(rad_container_create(buf, bytes, NULL, &ct));
    if (!ct) goto done;
    CHECK_OK(rad_multibounce_blocks_load(ct, "Fmb-bc4", NULL, &lb));
    CHECK_RESULT(rad_multibounce_load(ct, "Fmb-bc4", NULL, &lmb), RAD_ERROR_CORRUPT); /* wrong kind */
    CHECK_RESULT(rad_multibounce_load(ct, "nothing", NULL, &lmb), RAD_ERROR_CORRUPT);
    CHECK_OK(rad_multibounce_load(ct, "Fmb-perm", NULL, &lmb));
    if (lmb && lb) {
        CHECK(lmb->n == n && lmb->bounces == 3 && lmb->row_perm && lb->outlier_count == b->outlier_count);
        CHECK_OK(rad_multibounce_apply(h, w.E, x, RAD_OUTPUT_INDIRECT, NULL));
        CHECK_OK(rad_multibounce_apply(lmb, w.E, y, RAD_OUTPUT_INDIRECT, NULL));
        CHECK(memcmp(x, y, sizeof(float) * 3 * n) == 0);
        CHECK_OK(rad_multibounce_blocks_apply(b, w.E, x, RAD_OUTPUT_INDIRECT, NULL));
        CHECK_OK(rad_multibounce_blocks_apply(lb, w.E, y, RAD_OUTPUT_INDIRECT, NULL));
        CHECK(memcmp(x, y, sizeof(float) * 3 * n) == 0);
    }
    rad_multibounce_destroy(lmb);
    lmb = NULL;
    rad_multibounce_blocks_destroy(lb);
    lb = NULL;
    rad_container_destroy(ct);
    ct = NULL;
    /* a corrupted permutation (a repeated index, valid checksum) and an outlier column >= N */
    {
        uint32_t *bad = (uint32_t *)malloc(sizeof(uint32_t) * n), *badcol = (uint32_t *)malloc(sizeof(uint32_t) * b->outlier_count);
        rad_section t[RAD_MB_MAX_SECTIONS];
        uint32_t kt = 0;
        if (bad && badcol) {
            memcpy(bad, b->row_perm, sizeof(uint32_t) * n);
            bad[1] = bad[0];
            CHECK_OK(rad_multibounce_blocks_sections(b, "x", t, &kt));
            for (i = 0; i < kt; ++i)
                if (t[i].type == RAD_SECTION_MB_ROW_PERM) t[i].data = bad;
            free(buf);
            CHECK_OK(rad_container_size(t, kt, &bytes));
            buf = malloc(bytes);
            CHECK_OK(rad_container_write(t, kt, buf, bytes));
            CHECK_OK(rad_container_create(buf, bytes, NULL, &ct));
            CHECK_RESULT(rad_multibounce_blocks_load(ct, "x", NULL, &lb), RAD_ERROR_CORRUPT);
            CHECK(lb == NULL);
            rad_container_destroy(ct);
            ct = NULL;
            memcpy(badcol, b->outlier_columns, sizeof(uint32_t) * b->outlier_count);
            badcol[b->outlier_count / 2] = n;
            for (i = 0; i < kt; ++i) {
                if (t[i].type == RAD_SECTION_MB_ROW_PERM) t[i].data = b->row_perm;
                if (t[i].type == RAD_SECTION_MB_OUTLIER_COLUMNS) t[i].data = badcol;
            }
            CHECK_OK(rad_container_write(t, kt, buf, bytes));
            CHECK_OK(rad_container_create(buf, bytes, NULL, &ct));
            CHECK_RESULT(rad_multibounce_blocks_load(ct, "x", NULL, &lb), RAD_ERROR_INDEX_OUT_OF_RANGE);
            rad_container_destroy(ct);
            ct = NULL;
        }
        free(bad);
        free(badcol);
    }
done:
    rad_container_destroy(ct);
    free(buf);
    rad_multibounce_destroy(mb);
    rad_multibounce_destroy(h);
    rad_multibounce_blocks_destroy(b);
    free(x);
    free(y);
    fx_world_free(&w);
}

static void mb_errors(void)
{
    float F[4] = { 0.0f, 0.5f, 0.5f, 0.0f }, albedo[6] = { 0.5f, 0.5f, 0.5f, 0.5f, 1.0f, 0.5f };
    rad_matrix m;
    rad_multibounce_options o;
    rad_multibounce *mb = NULL;
    memset(&m, 0, sizeof(m));
    m.rows = m.cols = 2;
    m.storage = RAD_STORAGE_DENSE;
    m.dense = F;
    rad_multibounce_options_default(&o);
    CHECK_RESULT(rad_multibounce_create(&m, albedo, &o, NULL, &mb), RAD_ERROR_ALBEDO_RANGE);
    albedo[4] = 0.5f;
    o.precision = (rad_mb_precision)7;
    CHECK_RESULT(rad_multibounce_create(&m, albedo, &o, NULL, &mb), RAD_ERROR_INVALID_ARGUMENT);
    o.precision = RAD_MB_FLOAT;
    o.bounces = 2;
    m.cols = 1;
    CHECK_RESULT(rad_multibounce_create(&m, albedo, &o, NULL, &mb), RAD_ERROR_SIZE_MISMATCH);
    m.cols = 2;
    CHECK_RESULT(rad_multibounce_create(&m, NULL, &o, NULL, &mb), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_OK(rad_multibounce_create(&m, albedo, &o, NULL, &mb));
    if (mb) {
        /* K = 2 on a 2-patch exchange: A = 0.25 [0 1; 1 0] -> A + A^2 */
        CHECK_NEAR(mb->planes[1], 0.25, 1e-7);
        CHECK_NEAR(mb->planes[0], 0.0625, 1e-7);
    }
    {
        rad_block_options bo;
        rad_multibounce_blocks *b = NULL;
        rad_block_options_default(&bo);
        bo.tile = 6;
        CHECK_RESULT(rad_multibounce_blocks_create(mb, &bo, NULL, &b, NULL), RAD_ERROR_INVALID_ARGUMENT);
        bo.tile = 4;
        bo.outlier_fraction = 1.5f;
        CHECK_RESULT(rad_multibounce_blocks_create(mb, &bo, NULL, &b, NULL), RAD_ERROR_INVALID_ARGUMENT);
        bo.outlier_fraction = -1.0f; /* no outlier step */
        CHECK_OK(rad_multibounce_blocks_create(mb, &bo, NULL, &b, NULL));
        if (b) CHECK(b->outlier_count == 0 && b->outlier_offsets == NULL);
        rad_multibounce_blocks_destroy(b);
    }
    rad_multibounce_destroy(mb);
}

/* The orderings on a scrambled patch order (F_mb conjugated by a fixed pseudo-random
   permutation, as a mesh without spatial coherence would give): bijections, the decoded
   matrix in the original order, and each ordering well below the scrambled order's MSE
   (the greedy chain measured 10-17x at N = 1850); the refinements of the chain and the
   matching no worse than 1.1x the chain itself; and on the patch order the matching below
   the greedy chain in both formats. */
static void mb_reorder_methods(void)
{
    mb_world w;
    rad_multibounce *mb = NULL, view;
    uint32_t n, i, j, ch, ro, *p = NULL;
    uint64_t st = 12345u;
    float *P = NULL, *dec = NULL;
    double mse[RAD_REORDER_MATCH + 1];
    if (!mb_cornell(&w, mb_target())) return;
    n = w.patches->count;
    CHECK_OK(rad_multibounce_create(&w.ff->matrix, w.patches->albedo, NULL, NULL, &mb));
    p = (uint32_t *)malloc(sizeof(uint32_t) * n);
    P = (float *)malloc(sizeof(float) * 3 * n * n);
    dec = (float *)malloc(sizeof(float) * 3 * n * n);
    if (!mb || !p || !P || !dec) goto done;
    for (i = 0; i < n; ++i) p[i] = i;
    for (i = n - 1; i > 0; --i) {
        uint32_t t;
        st = st * 6364136223846793005ull + 1442695040888963407ull;
        j = (uint32_t)((st >> 33) % (i + 1u));
        t = p[i]; p[i] = p[j]; p[j] = t;
    }
    for (ch = 0; ch < 3; ++ch)
        for (i = 0; i < n; ++i)
            for (j = 0; j < n; ++j) P[(size_t)ch * n * n + (size_t)i * n + j] = mb->planes[(size_t)ch * n * n + (size_t)p[i] * n + p[j]];
    memset(&view, 0, sizeof(view));
    view.n = n; view.bounces = 3; view.precision = RAD_MB_FLOAT; view.planes = P;
    for (ro = 0; ro <= RAD_REORDER_MATCH; ++ro) {
        rad_block_options o;
        rad_block_report rep;
        rad_multibounce_blocks *b = NULL;
        double sse = 0.0;
        size_t q;
        rad_block_options_default(&o);
        o.reorder = ro ? (int)ro : RAD_REORDER_NONE; /* ro 0: the patch order kept (mse[0]) */
        CHECK_OK(rad_multibounce_blocks_create(&view, &o, NULL, &b, &rep));
        if (!b) continue;
        if (ro) CHECK(mb_is_permutation(b->row_perm, n) && mb_is_permutation(b->col_perm, n));
        else CHECK(b->row_perm == NULL && b->col_perm == NULL);
        CHECK_OK(rad_multibounce_blocks_decode(b, dec, NULL));
        for (q = 0; q < 3 * (size_t)n * n; ++q) sse += ((double)dec[q] - P[q]) * ((double)dec[q] - P[q]);
        CHECK_REL(sse / (3.0 * n * n), rep.mse, 1e-3);
        mse[ro] = rep.mse;
        printf("    reorder %u on a scrambled order: mse %.3g\n", ro, rep.mse);
        rad_multibounce_blocks_destroy(b);
    }
    CHECK(mse[RAD_REORDER_GREEDY] * 2.0 <= mse[0]);
    CHECK(mse[RAD_REORDER_GREEDY_2OPT] * 2.0 <= mse[0]);
    CHECK(mse[RAD_REORDER_GROUPS] * 2.0 <= mse[0]);
    CHECK(mse[RAD_REORDER_GREEDY_2OPT] <= 1.1 * mse[RAD_REORDER_GREEDY]);
    CHECK(mse[RAD_REORDER_GROUPS] <= 1.1 * mse[RAD_REORDER_GREEDY]);
    CHECK(mse[RAD_REORDER_MATCH] * 2.0 <= mse[0]);
    CHECK(mse[RAD_REORDER_MATCH] <= 1.1 * mse[RAD_REORDER_GREEDY]);
    /* on the patch order: matching gives a lower real encoded MSE than the greedy chain
       (RAD_REORDER_GREEDY) in both formats (measured: 378 patches 25% / 28% lower for BC1 / 3xBC4,
       206 patches 17% / 14%); RAD_TEST_QUICK: 3xBC4 only */
    for (ch = rad_test_quick() ? 1u : 0u; ch < 2; ++ch) {
        double m2[2];
        for (ro = 0; ro < 2; ++ro) {
            rad_block_options o;
            rad_block_report rep;
            rad_multibounce_blocks *b = NULL;
            rad_block_options_default(&o);
            o.format = ch ? RAD_BLOCK_BC4X3 : RAD_BLOCK_BC1;
            o.reorder = ro ? RAD_REORDER_MATCH : RAD_REORDER_GREEDY;
            CHECK_OK(rad_multibounce_blocks_create(mb, &o, NULL, &b, &rep));
            m2[ro] = rep.mse;
            rad_multibounce_blocks_destroy(b);
        }
        printf("    %s on the patch order: greedy mse %.4g, match %.4g (%.1f%% lower)\n", ch ? "3xBC4" : "BC1", m2[0], m2[1],
               100.0 * (1.0 - m2[1] / m2[0]));
        CHECK(m2[1] < m2[0]);
    }
    {   /* an unknown method is refused */
        rad_block_options o;
        rad_multibounce_blocks *b = NULL;
        rad_block_options_default(&o);
        o.reorder = RAD_REORDER_NONE + 1;
        CHECK_RESULT(rad_multibounce_blocks_create(&view, &o, NULL, &b, NULL), RAD_ERROR_INVALID_ARGUMENT);
        CHECK(b == NULL);
        o.reorder = -1;
        CHECK_RESULT(rad_multibounce_blocks_create(&view, &o, NULL, &b, NULL), RAD_ERROR_INVALID_ARGUMENT);
    }
done:
    rad_multibounce_destroy(mb);
    free(p);
    free(P);
    free(dec);
    fx_world_free(&w);
}

/* Whatever decode path the build compiled (AVX2 or scalar), the compressed apply uses the
   decoder's values: with E = e_j (1 in every channel at patch j) every output is one decoded
   entry times 1 plus exact zeros, so it must equal column j of rad_multibounce_blocks_decode
   (outliers included): 3xBC4 to the bit; BC1 within 1e-6 of the value (a few float
   roundings: its apply folds the palette's thirds into per-column tables instead of forming
   the palette, so (2a + b)/93 becomes (a/31)(2/3) + (b/31)(1/3)), and exactly 0 where the
   decoder gives 0. */
static void mb_decode_exact(void)
{
    mb_world w;
    rad_multibounce *mb = NULL;
    uint32_t n, f, fr, j, i, ch;
    float *dec = NULL, *E = NULL, *out = NULL;
    if (!mb_cornell(&w, rad_test_quick() ? 120u : 200u)) return;
    n = w.patches->count;
    CHECK_OK(rad_multibounce_create(&w.ff->matrix, w.patches->albedo, NULL, NULL, &mb));
    dec = (float *)malloc(sizeof(float) * 3 * n * n);
    E = (float *)calloc(3 * (size_t)n, sizeof(float));
    out = (float *)malloc(sizeof(float) * 3 * n);
    if (!mb || !dec || !E || !out) goto done;
    for (f = 0; f < 2; ++f)
        for (fr = 0; fr < 2; ++fr) {
            rad_block_options o;
            rad_multibounce_blocks *b = NULL;
            uint64_t bad = 0;
            rad_block_options_default(&o);
            o.format = f ? RAD_BLOCK_BC4X3 : RAD_BLOCK_BC1;
            o.outlier_fraction = fr ? 0.05f : -1.0f; /* negative: no outliers */
            CHECK_OK(rad_multibounce_blocks_create(mb, &o, NULL, &b, NULL));
            if (!b) continue;
            CHECK_OK(rad_multibounce_blocks_decode(b, dec, NULL));
            for (j = 0; j < n; j += 3) {
                E[3 * j] = E[3 * j + 1] = E[3 * j + 2] = 1.0f;
                CHECK_OK(rad_multibounce_blocks_apply(b, E, out, RAD_OUTPUT_INDIRECT, NULL));
                E[3 * j] = E[3 * j + 1] = E[3 * j + 2] = 0.0f;
                for (i = 0; i < n; ++i)
                    for (ch = 0; ch < 3; ++ch)
                    {
                        const float got = out[3 * (size_t)i + ch], want = dec[ch * (size_t)n * n + (size_t)i * n + j];
                        if (f ? got != want : !(fabs((double)got - want) <= 1e-6 * fabs((double)want))) ++bad;
                    }
            }
            CHECK(bad == 0);
            if (bad) printf("    %s, outliers %u: %llu entries differ\n", f ? "BC4x3" : "BC1", fr, (unsigned long long)bad);
            rad_multibounce_blocks_destroy(b);
        }
done:
    rad_multibounce_destroy(mb);
    free(dec);
    free(E);
    free(out);
    fx_world_free(&w);
}

/* The AVX2 palettes divide by the FMA-corrected reciprocal product; it must equal IEEE
   division for every quotient the BC1 and BC4 decoders form: integer numerators 0..1785 over
   the denominators 31, 63, 255 (endpoints), 62, 93, 126, 189 (BC1 interpolants), 1275, 1785
   (BC4 interpolants). */
static void mb_simd_division(void)
{
#if defined(RAD__MB_AVX2)
    static const float den[9] = { 31.0f, 63.0f, 255.0f, 62.0f, 93.0f, 126.0f, 189.0f, 1275.0f, 1785.0f };
    uint32_t d, x, l, bad = 0, count = 0;
    for (d = 0; d < 9; ++d)
        for (x = 0; x <= 1785u; x += 8) {
            float xs[8], got[8];
            __m256 dv = _mm256_set1_ps(den[d]);
            for (l = 0; l < 8; ++l) xs[l] = (float)(x + l);
            _mm256_storeu_ps(got, rad__mb_div(_mm256_loadu_ps(xs), dv, _mm256_div_ps(_mm256_set1_ps(1.0f), dv)));
            for (l = 0; l < 8; ++l) {
                volatile float q = xs[l] / den[d];
                bad += got[l] != q;
                ++count;
            }
        }
    printf("    %u quotients, %u differ\n", count, bad);
    CHECK(bad == 0);
#else
    printf("    (no AVX2 decode path in this build)\n");
#endif
}

/* rad_multibounce_blocks_apply against decode-then-multiply on hand-built objects: random
   blocks with both BC1 modes (c0 > c1, c0 <= c1, c0 == c1) and both BC4 modes forced, N not a
   multiple of 4 (outside RAD_TEST_QUICK also 194 block columns: more than one BC1 table tile
   (RAD__MB_LUT_TILE = 64) and pass (RAD__MB_LUT_PASS = 192)), scale tiles of 3 blocks that
   divide neither, row and column permutations, outliers,
   signed E, both outputs. The reference decodes every block with rad_bc1_decode_block /
   rad_bc4_decode_block, multiplies by its tile scale and sums in double; the apply may only
   differ by the order of its float sums, so per row and channel |got - ref| <= 1e-5 (sum_j
   |F_ij E_j| + |E_i|): about 80 float roundings of terms of that size at most. The scalar
   build (RAD_NO_SIMD, tests/run.sh unit-scalar) runs the same test on the portable path. */
static void mb_apply_vs_decode(void)
{
    static const uint32_t sizes[3] = { 141u, 37u, 775u };
    uint32_t si, f, cfg, nsizes = rad_test_quick() ? 2u : 3u;
    uint64_t st = 99u;
#define MB_RND() (st = st * 6364136223846793005ull + 1442695040888963407ull, (uint32_t)(st >> 33))
    for (si = 0; si < nsizes; ++si)
        for (f = 0; f < 2; ++f)
            for (cfg = 0; cfg < 2; ++cfg) {
                uint32_t n = sizes[si], bpr = (n + 3u) / 4u, tile = cfg ? 0u : 12u, tpr = tile ? (n + tile - 1u) / tile : 1u;
                uint32_t planes = f ? 3u : 1u, i, j, k, bx, by, ch, x, y, modes[2] = { 0, 0 };
                size_t nb = (size_t)bpr * bpr, bad = 0;
                uint8_t *blocks = (uint8_t *)malloc(8 * nb * planes);
                float *scales = (float *)malloc(sizeof(float) * 3 * tpr * tpr), *E = (float *)malloc(sizeof(float) * 3 * n);
                float *got = (float *)malloc(sizeof(float) * 3 * n), *tot = (float *)malloc(sizeof(float) * 3 * n);
                double *ref = (double *)calloc(3 * (size_t)n, sizeof(double)), *mag = (double *)calloc(3 * (size_t)n, sizeof(double));
                uint32_t *rp = (uint32_t *)malloc(sizeof(uint32_t) * n), *cp = (uint32_t *)malloc(sizeof(uint32_t) * n);
                uint64_t *off = (uint64_t *)malloc(sizeof(uint64_t) * (n + 1u));
                uint32_t *ocol = NULL;
                float *oval = NULL;
                rad_multibounce_blocks b;
                /* 0, 1 or 2 outliers per row (original order); the arrays exactly that long, so
                   that a read past the last one shows under the sanitizers */
                if (off) {
                    off[0] = 0;
                    for (i = 0; i < n; ++i) off[i + 1] = off[i] + (cfg ? 0u : i % 3u);
                    ocol = (uint32_t *)malloc(off[n] ? sizeof(uint32_t) * off[n] : 1u);
                    oval = (float *)malloc(off[n] ? sizeof(float) * 3 * off[n] : 1u);
                }
                if (!blocks || !scales || !E || !got || !tot || !ref || !mag || !rp || !cp || !off || !ocol || !oval) {
                    CHECK(0);
                    goto next;
                }
                for (i = 0; i < 8 * nb * planes; ++i) blocks[i] = (uint8_t)(MB_RND() >> 7);
                for (i = 0; i < nb * planes; ++i) {
                    uint8_t *q = blocks + 8 * i;
                    if (f) {
                        /* BC4: alternate the 8-value (r0 > r1) and the 6-value (r0 <= r1) mode */
                        if ((i & 1u) != (q[0] > q[1])) { uint8_t t = q[0]; q[0] = q[1]; q[1] = t; }
                        if (i % 7u == 0) q[1] = q[0];
                        modes[q[0] > q[1]]++;
                    } else {
                        /* BC1: alternate the 4-colour (c0 > c1) and the 3-colour (c0 <= c1) mode */
                        uint32_t c0 = (uint32_t)q[0] | (uint32_t)q[1] << 8, c1 = (uint32_t)q[2] | (uint32_t)q[3] << 8;
                        if ((i & 1u) != (c0 > c1)) { uint8_t t0 = q[0], t1 = q[1]; q[0] = q[2]; q[1] = q[3]; q[2] = t0; q[3] = t1; }
                        if (i % 7u == 0) { q[2] = q[0]; q[3] = q[1]; }
                        c0 = (uint32_t)q[0] | (uint32_t)q[1] << 8;
                        c1 = (uint32_t)q[2] | (uint32_t)q[3] << 8;
                        modes[c0 > c1]++;
                    }
                }
                CHECK(modes[0] > 0 && modes[1] > 0);
                for (i = 0; i < 3 * tpr * tpr; ++i) scales[i] = 0.5f + (float)(MB_RND() % 1000u) / 666.0f;
                for (i = 0; i < 3 * n; ++i) E[i] = (float)((int)(MB_RND() % 2001u) - 1000) / 1000.0f;
                for (i = 0; i < n; ++i) rp[i] = cp[i] = i;
                for (i = n - 1; i > 0; --i) {
                    uint32_t t;
                    j = MB_RND() % (i + 1u); t = rp[i]; rp[i] = rp[j]; rp[j] = t;
                    j = MB_RND() % (i + 1u); t = cp[i]; cp[i] = cp[j]; cp[j] = t;
                }
                for (k = 0; k < (uint32_t)off[n]; ++k) {
                    ocol[k] = MB_RND() % n;
                    for (ch = 0; ch < 3; ++ch) oval[3 * k + ch] = (float)(MB_RND() % 1000u) / 100.0f;
                }
                memset(&b, 0, sizeof(b));
                b.n = n;
                b.bounces = 3;
                b.format = f ? RAD_BLOCK_BC4X3 : RAD_BLOCK_BC1;
                b.blocks_per_row = bpr;
                b.blocks = blocks;
                b.tile = tile;
                b.tiles_per_row = tpr;
                b.scales = scales;
                b.row_perm = cfg ? NULL : rp;
                b.col_perm = cfg ? NULL : cp;
                b.outlier_count = off[n];
                b.outlier_offsets = off[n] ? off : NULL;
                b.outlier_columns = ocol;
                b.outlier_values = oval;
                /* the reference: every texel decoded, in the original order */
                for (by = 0; by < bpr; ++by)
                    for (bx = 0; bx < bpr; ++bx) {
                        float dec[3][16];
                        size_t at = (size_t)by * bpr + bx;
                        const float *sc = scales + 3 * (size_t)(tile ? (by * 4u / tile) * tpr + bx * 4u / tile : 0u);
                        if (f) {
                            for (ch = 0; ch < 3; ++ch) rad_bc4_decode_block(blocks + 8 * (ch * nb + at), dec[ch]);
                        } else {
                            float rgb[48];
                            rad_bc1_decode_block(blocks + 8 * at, rgb);
                            for (k = 0; k < 16; ++k)
                                for (ch = 0; ch < 3; ++ch) dec[ch][k] = rgb[3 * k + ch];
                        }
                        for (y = 0; y < 4; ++y)
                            for (x = 0; x < 4; ++x) {
                                uint32_t ty = 4 * by + y, tx = 4 * bx + x, oi, oj;
                                if (ty >= n || tx >= n) continue;
                                oi = b.row_perm ? rp[ty] : ty;
                                oj = b.col_perm ? cp[tx] : tx;
                                for (ch = 0; ch < 3; ++ch) {
                                    double v = (double)(dec[ch][4 * y + x] * sc[ch]) * E[3 * (size_t)oj + ch];
                                    ref[3 * (size_t)oi + ch] += v;
                                    mag[3 * (size_t)oi + ch] += fabs(v);
                                }
                            }
                    }
                for (i = 0; i < n; ++i)
                    for (k = (uint32_t)off[i]; k < (uint32_t)off[i + 1]; ++k)
                        for (ch = 0; ch < 3; ++ch) {
                            double v = (double)oval[3 * k + ch] * E[3 * (size_t)ocol[k] + ch];
                            ref[3 * (size_t)i + ch] += v;
                            mag[3 * (size_t)i + ch] += fabs(v);
                        }
                CHECK_OK(rad_multibounce_blocks_apply(&b, E, got, RAD_OUTPUT_INDIRECT, NULL));
                CHECK_OK(rad_multibounce_blocks_apply(&b, E, tot, RAD_OUTPUT_TOTAL, NULL));
                for (i = 0; i < 3 * n; ++i) {
                    double tol = 1e-5 * (mag[i] + fabs((double)E[i]));
                    if (!(fabs((double)got[i] - ref[i]) <= tol) || !(fabs((double)tot[i] - (ref[i] + E[i])) <= tol)) ++bad;
                }
                if (bad) printf("    %s N %u tile %u: %zu of %u values off\n", f ? "BC4x3" : "BC1", n, tile, bad, 3 * n);
                CHECK(bad == 0);
            next:
                free(blocks); free(scales); free(E); free(got); free(tot); free(ref); free(mag);
                free(rp); free(cp); free(off); free(ocol); free(oval);
            }
#undef MB_RND
}

/* RAD_REORDER_MATCH: bijections for sizes that leave unmatched rows and a partial group
   (n = 1..9 and 37), the uncompressed apply through its permutations equal to the plain one
   to the bit (dyadic entries, integer E: every summation order gives the same sums). Its
   MSE against the greedy chain is checked in mb_reorder_methods. */
static void mb_reorder_match(void)
{
    enum { NMAX = 37 };
    static float planes[3 * NMAX * NMAX], permuted[3 * NMAX * NMAX];
    static const uint32_t sizes[] = { 1, 2, 3, 4, 5, 6, 7, 8, 9, NMAX };
    float E[3 * NMAX], a[3 * NMAX], b2[3 * NMAX];
    uint32_t s, i, j, ch, seed = 11u;
    for (s = 0; s < sizeof(sizes) / sizeof(sizes[0]); ++s) {
        uint32_t n = sizes[s];
        rad_multibounce view, pview;
        rad_block_options o;
        rad_multibounce_blocks *b = NULL;
        for (i = 0; i < 3 * n * n; ++i) planes[i] = (float)((uint32_t)(mb_rand(&seed) * 16.0f) * (uint32_t)(i % 3 != 0)) / 1024.0f;
        for (i = 0; i < 3 * n; ++i) E[i] = (float)(uint32_t)(mb_rand(&seed) * 8.0f);
        memset(&view, 0, sizeof(view));
        view.n = n;
        view.bounces = 1;
        view.precision = RAD_MB_FLOAT;
        view.planes = planes;
        rad_block_options_default(&o);
        o.reorder = RAD_REORDER_MATCH;
        CHECK_OK(rad_multibounce_blocks_create(&view, &o, NULL, &b, NULL));
        if (!b) continue;
        CHECK(mb_is_permutation(b->row_perm, n) && mb_is_permutation(b->col_perm, n));
        for (ch = 0; ch < 3; ++ch)
            for (i = 0; i < n; ++i)
                for (j = 0; j < n; ++j) permuted[(ch * n + i) * n + j] = planes[(ch * n + b->row_perm[i]) * n + b->col_perm[j]];
        pview = view;
        pview.planes = permuted;
        pview.row_perm = b->row_perm;
        pview.col_perm = b->col_perm;
        CHECK_OK(rad_multibounce_apply(&view, E, a, RAD_OUTPUT_INDIRECT, NULL));
        CHECK_OK(rad_multibounce_apply(&pview, E, b2, RAD_OUTPUT_INDIRECT, NULL));
        CHECK(memcmp(a, b2, sizeof(float) * 3 * n) == 0);
        rad_multibounce_blocks_destroy(b);
    }
}

/* one poked copy of a multi-bounce container (ct_poke: checksums fixed) opened and loaded:
   'expected', and a message naming 'what' */
static void mb_expect_load(const void *buf, size_t size, uint32_t type, const char *name, size_t at, const void *bytes,
                           size_t n, rad_result expected, const char *what)
{
    unsigned char *copy = ct_poke(buf, size, type, name, at, bytes, n);
    rad_container *ct = NULL;
    rad_multibounce *mb = NULL;
    rad_multibounce_blocks *b = NULL;
    rad_context ctx;
    CHECK(copy != NULL);
    if (!copy) return;
    CHECK_OK(rad_container_create(copy, size, NULL, &ct));
    ct_log_context(&ctx);
    if (type == RAD_SECTION_MB_SCALES || type == RAD_SECTION_MB_OUTLIER_VALUES) {
        CHECK_RESULT(rad_multibounce_blocks_load(ct, name, &ctx, &b), expected);
        CHECK((b != NULL) == (expected == RAD_SUCCESS));
    } else {
        CHECK_RESULT(rad_multibounce_load(ct, name, &ctx, &mb), expected);
        CHECK((mb != NULL) == (expected == RAD_SUCCESS));
    }
    if (expected != RAD_SUCCESS && (!strstr(ct_log_last, what) || !strstr(ct_log_last, "entry"))) {
        printf("    message '%s' lacks '%s'\n", ct_log_last, what);
        CHECK(0);
    }
    rad_multibounce_destroy(mb);
    rad_multibounce_blocks_destroy(b);
    rad_container_destroy(ct);
    free(copy);
}

/* F_mb planes (float and half), block scales and outliers with valid checksums but NaN, 3e38
   or negative values are refused at load (else they render NaN with exit 0) */
static void mb_bad_values(void)
{
    mb_world w;
    rad_multibounce *mb = NULL, *h = NULL;
    rad_multibounce_blocks *b = NULL;
    rad_block_options o;
    rad_section s[3 * RAD_MB_MAX_SECTIONS];
    uint32_t k1 = 0, k2 = 0, k3 = 0;
    size_t bytes = 0;
    void *buf = NULL;
    const float qnan = (float)NAN, huge = 3e38f, neg = -1.0f, fine = 0.5f;
    const uint16_t hnan = 0x7E00u, hinf = 0x7C00u, hneg = 0xBC00u, hzero = 0x8000u;
    if (!mb_cornell(&w, 60u)) return;
    CHECK_OK(rad_multibounce_create(&w.ff->matrix, w.patches->albedo, NULL, NULL, &mb));
    CHECK_OK(rad_multibounce_convert(mb, RAD_MB_HALF, NULL, &h));
    rad_block_options_default(&o);
    o.tile = 16;
    CHECK_OK(rad_multibounce_blocks_create(mb, &o, NULL, &b, NULL));
    if (!mb || !h || !b) goto done;
    CHECK(b->outlier_count > 2);
    CHECK_OK(rad_multibounce_sections(mb, "f", s, &k1));
    CHECK_OK(rad_multibounce_sections(h, "h", s + k1, &k2));
    CHECK_OK(rad_multibounce_blocks_sections(b, "b", s + k1 + k2, &k3));
    CHECK_OK(rad_container_size(s, k1 + k2 + k3, &bytes));
    buf = malloc(bytes);
    if (!buf) goto done;
    CHECK_OK(rad_container_write(s, k1 + k2 + k3, buf, bytes));
    mb_expect_load(buf, bytes, RAD_SECTION_MB_FLOAT, "f", 40, &fine, 4, RAD_SUCCESS, "");
    mb_expect_load(buf, bytes, RAD_SECTION_MB_FLOAT, "f", 40, &qnan, 4, RAD_ERROR_NON_FINITE, "MB_FLOAT");
    mb_expect_load(buf, bytes, RAD_SECTION_MB_FLOAT, "f", 40, &huge, 4, RAD_ERROR_CORRUPT, "3e+38");
    mb_expect_load(buf, bytes, RAD_SECTION_MB_FLOAT, "f", 40, &neg, 4, RAD_ERROR_CORRUPT, "negative");
    mb_expect_load(buf, bytes, RAD_SECTION_MB_HALF, "h", 20, &hzero, 2, RAD_SUCCESS, "");
    mb_expect_load(buf, bytes, RAD_SECTION_MB_HALF, "h", 20, &hnan, 2, RAD_ERROR_NON_FINITE, "MB_HALF");
    mb_expect_load(buf, bytes, RAD_SECTION_MB_HALF, "h", 20, &hinf, 2, RAD_ERROR_NON_FINITE, "inf");
    mb_expect_load(buf, bytes, RAD_SECTION_MB_HALF, "h", 20, &hneg, 2, RAD_ERROR_CORRUPT, "negative");
    mb_expect_load(buf, bytes, RAD_SECTION_MB_SCALES, "b", 4, &fine, 4, RAD_SUCCESS, "");
    mb_expect_load(buf, bytes, RAD_SECTION_MB_SCALES, "b", 4, &huge, 4, RAD_ERROR_CORRUPT, "MB_SCALES");
    mb_expect_load(buf, bytes, RAD_SECTION_MB_SCALES, "b", 4, &qnan, 4, RAD_ERROR_NON_FINITE, "MB_SCALES");
    mb_expect_load(buf, bytes, RAD_SECTION_MB_OUTLIER_VALUES, "b", 8, &huge, 4, RAD_ERROR_CORRUPT, "MB_OUTLIER_VALUES");
    mb_expect_load(buf, bytes, RAD_SECTION_MB_OUTLIER_VALUES, "b", 8, &neg, 4, RAD_ERROR_CORRUPT, "negative");
done:
    free(buf);
    rad_multibounce_blocks_destroy(b);
    rad_multibounce_destroy(h);
    rad_multibounce_destroy(mb);
    fx_world_free(&w);
}

static const rad_test_case tests_multibounce[] = {
    { "multibounce: binary16 conversion", mb_half },
    { "multibounce: F_mb E equals K Jacobi bounces (K = 1, 3, 8)", mb_jacobi },
    { "multibounce: K = infinity equals the direct solve", mb_infinite },
    { "multibounce: BC1 blocks decode as the specification says", mb_bc1_decode },
    { "multibounce: BC4 blocks decode as the specification says", mb_bc4_decode },
    { "multibounce: BC1/BC4 encoder error bounds", mb_encode_bounds },
    { "multibounce: reordering gives bijections and the same apply", mb_permutations },
    { "multibounce: half-precision apply", mb_half_apply },
    { "multibounce: compressed apply and its error", mb_compressed },
    { "multibounce: reordering methods on a scrambled patch order", mb_reorder_methods },
    { "multibounce: matching reorder: bijections and the exact permuted apply", mb_reorder_match },
    { "multibounce: compressed apply uses the decoder's values to the bit", mb_decode_exact },
    { "multibounce: SIMD palette division equals IEEE division", mb_simd_division },
    { "multibounce: compressed apply equals decode-then-multiply (hand-built blocks)", mb_apply_vs_decode },
    { "multibounce: container sections, round trip, corruption", mb_container },
    { "multibounce: NaN, 3e38 and negative values refused at load", mb_bad_values },
    { "multibounce: argument errors", mb_errors },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_multibounce)

/* test_temporal.c - temporal radiosity (docs/methods/temporal.md): the generator's published vectors, alias
   tables (exact implied probabilities, chi-square of draws, streamed rows, container round
   trip), the step's expectation against the exact gather, convergence to rho o (F E) and to
   L_inf with feedback, rows with sums above 1, the environment entry, determinism across
   thread counts, the adaptive weight, error codes. Everything static and prefixed tp_. */
#include "fixtures.h"


/* the shared Cornell world (fixtures.h) */
typedef fx_world tp_cornell;

/* Cornell box near 'target' patches, dense F and (optionally) sparse F; E: a positive
   pseudo-random source with a few bright patches and some zeros (heavy-tailed on purpose). */
static int tp_cornell_build(tp_cornell *c, uint32_t target, int sparse)
{
    uint32_t i, state = 12345u;
    if (!fx_cornell(c, target, 0, sparse)) return 0;
    for (i = 0; i < 3 * c->n; ++i) {
        state = state * 1664525u + 1013904223u;
        c->E[i] = (float)(state >> 8) / 16777216.0f;
        if (i % 17 == 3) c->E[i] *= 20.0f;
        if (i % 23 == 5) c->E[i] = 0.0f;
    }
    return 1;
}

/* relative RMS of a against b over 3n floats: sqrt(sum (a-b)^2 / sum b^2) */
static double tp_rel_rms(const float *a, const float *b, uint32_t n)
{
    double num = 0.0, den = 0.0;
    size_t i;
    for (i = 0; i < 3 * (size_t)n; ++i) {
        num += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
        den += (double)b[i] * b[i];
    }
    return den > 0.0 ? sqrt(num / den) : sqrt(num);
}

/* the exact probability of each column (N+1 slots, slot N = environment) implied by a row's bins */
static void tp_implied(const uint32_t *bins, uint32_t nb, rad_alias_format f, uint32_t cols, double *p)
{
    uint32_t b;
    memset(p, 0, sizeof(double) * (cols + 1u));
    for (b = 0; b < nb; ++b) {
        const uint32_t *e = bins + (size_t)b * (uint32_t)f;
        uint32_t c0 = f == RAD_ALIAS_COMPACT ? (e[1] & 0xFFFFu) : e[1], c1 = f == RAD_ALIAS_COMPACT ? (e[1] >> 16) : e[2];
        double keep = (double)e[0] / 4294967296.0;
        if (c0 == c1) keep = 1.0;
        p[c0] += keep / nb;
        p[c1] += (1.0 - keep) / nb;
    }
}

static void tp_random_vectors(void)
{
    /* the values published in the header's doc comment */
    static const uint32_t v[3][6] = { { 0u, 0u, 0u, 0u, 0x8D324821u, 0x5A5950DFu },
                                      { 1u, 2u, 3u, 4u, 0xBE9148C4u, 0xB2A7FCBEu },
                                      { 0xDEADBEEFu, 1000u, 10421u, 63u, 0xA62F1C1Eu, 0x399CE3D2u } };
    int i;
    uint32_t o[2];
    for (i = 0; i < 3; ++i) {
        rad_temporal_random(v[i][0], v[i][1], v[i][2], v[i][3], o);
        CHECK(o[0] == v[i][4]);
        CHECK(o[1] == v[i][5]);
    }
    /* the draw rule: bin = high word of u1 * n, keep when u2 < threshold */
    {
        uint32_t bins[4] = { 0x80000000u, 7u | (9u << 16), 0xFFFFFFFFu, 9u | (9u << 16) };
        CHECK(rad_alias_draw(bins, 2, RAD_ALIAS_COMPACT, 0x7FFFFFFFu, 0x7FFFFFFFu) == 7u);
        CHECK(rad_alias_draw(bins, 2, RAD_ALIAS_COMPACT, 0x7FFFFFFFu, 0x80000000u) == 9u);
        CHECK(rad_alias_draw(bins, 2, RAD_ALIAS_COMPACT, 0x80000000u, 0u) == 9u);
        CHECK(rad_alias_draw(bins, 2, RAD_ALIAS_COMPACT, 0xFFFFFFFFu, 0xFFFFFFFFu) == 9u);
    }
}

/* Exact: the probabilities the thresholds imply equal G_ij / T_i within 2^-30 (threshold
   rounding is 2^-33 per bin). Statistical: 400 000 draws of the generator from a 12-entry row
   with an environment entry, chi-square with 12 degrees of freedom below 40 (p ~ 1e-4). */
static void tp_alias_chi_square(void)
{
    static const float row[16] = { 0.1f, 0.0f, 0.05f, 0.2f, 0.001f, 0.0f, 0.3f, 0.04f, 0.0f, 0.07f, 0.02f, 0.005f, 0.0f, 0.06f, 0.009f, 0.011f };
    uint32_t bins[17 * 3], nb, f, i, s, cols = 16;
    float total;
    unsigned char scratch[17 * 16];
    double p[17], W = 0.0;
    for (i = 0; i < 16; ++i) W += row[i];
    for (f = RAD_ALIAS_COMPACT; f <= RAD_ALIAS_WIDE; ++f) {
        uint32_t counts[17];
        double chi = 0.0, M = 400000.0;
        CHECK(rad_alias_row_scratch_size(16) <= sizeof(scratch));
        CHECK_OK(rad_alias_build_row(NULL, row, 16, cols, (rad_alias_format)f, bins, &nb, &total, scratch));
        CHECK(nb == 13u); /* 12 non-zeros + environment */
        CHECK(total == 1.0f);
        tp_implied(bins, nb, (rad_alias_format)f, cols, p);
        for (i = 0; i < 16; ++i) CHECK_NEAR(p[i], row[i], 1e-9);
        CHECK_NEAR(p[16], 1.0 - W, 1e-9);
        memset(counts, 0, sizeof(counts));
        for (s = 0; s < (uint32_t)M; ++s) {
            uint32_t u[2];
            rad_temporal_random(7u, s / 1000u, 3u, s % 1000u, u);
            counts[rad_alias_draw(bins, nb, (rad_alias_format)f, u[0], u[1])]++;
        }
        for (i = 0; i < 17; ++i) {
            double e = M * (i < 16 ? (double)row[i] : 1.0 - W);
            if (e == 0.0) { CHECK(counts[i] == 0); continue; }
            chi += ((double)counts[i] - e) * ((double)counts[i] - e) / e;
        }
        printf("    chi-square %.2f (12 dof, threshold 40), format %u\n", chi, f);
        CHECK(chi < 40.0);
    }
}

/* Rows with sum > 1 (a multi-bounce-like plane 2F + a spike): no environment entry, T_i = S_i;
   and the whole-matrix tables imply G_ij / T_i exactly for every row of the Cornell box. */
static void tp_alias_tables_exact(void)
{
    tp_cornell c;
    rad_alias_tables *t = NULL, *t2 = NULL;
    float *plane;
    double *p, worst = 0.0, worst2 = 0.0;
    uint32_t i, j, n;
    if (!tp_cornell_build(&c, 120, 0)) { CHECK(0); fx_world_free(&c); return; }
    n = c.n;
    plane = (float *)malloc(sizeof(float) * n * n);
    p = (double *)malloc(sizeof(double) * (n + 1));
    for (i = 0; i < n * n; ++i) plane[i] = 2.0f * c.ff->matrix.dense[i];
    CHECK_OK(rad_alias_tables_create(&c.ff->matrix, RAD_ALIAS_AUTO, NULL, &t));
    CHECK_OK(rad_alias_tables_create_dense(plane, n, RAD_ALIAS_WIDE, NULL, &t2));
    if (t && t2) {
        CHECK(t->format == RAD_ALIAS_COMPACT);
        CHECK(t2->format == RAD_ALIAS_WIDE);
        printf("    N %u: %.1f%% of F non-zero; tables %.2f bytes per source float entry (compact), %.2f (wide)\n", n,
               100.0 * (double)(t->row_offsets[n] - n) / ((double)n * n), (double)rad_alias_tables_memory(t) / ((double)n * n),
               (double)rad_alias_tables_memory(t2) / ((double)n * n));
        for (i = 0; i < n; ++i) {
            double S = 0.0, S2 = 0.0;
            const float *row = c.ff->matrix.dense + (size_t)i * n;
            for (j = 0; j < n; ++j) { S += row[j]; S2 += plane[(size_t)i * n + j]; }
            CHECK_NEAR(t->totals[i], S > 1.0 ? S : 1.0, 1e-6);
            CHECK_NEAR(t2->totals[i], S2 > 1.0 ? S2 : 1.0, 1e-6);
            tp_implied(t->bins + t->row_offsets[i] * 2, (uint32_t)(t->row_offsets[i + 1] - t->row_offsets[i]), t->format, n, p);
            for (j = 0; j < n; ++j) if (fabs(p[j] - row[j] / t->totals[i]) > worst) worst = fabs(p[j] - row[j] / t->totals[i]);
            if (fabs(p[n] - (S < 1.0 ? 1.0 - S : 0.0)) > worst) worst = fabs(p[n] - (S < 1.0 ? 1.0 - S : 0.0));
            tp_implied(t2->bins + t2->row_offsets[i] * 3, (uint32_t)(t2->row_offsets[i + 1] - t2->row_offsets[i]), t2->format, n, p);
            for (j = 0; j < n; ++j)
                if (fabs(p[j] - plane[(size_t)i * n + j] / t2->totals[i]) > worst2) worst2 = fabs(p[j] - plane[(size_t)i * n + j] / t2->totals[i]);
            if (S2 > 1.0) CHECK(p[n] == 0.0);
        }
        CHECK(worst < 1e-6);
        CHECK(worst2 < 1e-6);
    }
    rad_alias_tables_destroy(t);
    rad_alias_tables_destroy(t2);
    free(plane);
    free(p);
    fx_world_free(&c);
}

/* Streamed rows (rad_alias_build_row): every row rebuilt alone from the dense row and from the CSR row gives
   the same bins and T_i as the pre-built tables (bit for bit); CSR-built tables equal dense-built. */
static void tp_streamed_rows(void)
{
    tp_cornell c;
    rad_alias_tables *t = NULL, *ts = NULL;
    uint32_t i, n, nb, f;
    uint32_t *bins;
    void *scratch;
    float total;
    int same = 1;
    if (!tp_cornell_build(&c, 100, 1)) { CHECK(0); fx_world_free(&c); return; }
    n = c.n;
    bins = (uint32_t *)malloc(sizeof(uint32_t) * 3 * (n + 1));
    scratch = malloc(rad_alias_row_scratch_size(n));
    for (f = RAD_ALIAS_COMPACT; f <= RAD_ALIAS_WIDE; ++f) {
        CHECK_OK(rad_alias_tables_create(&c.ff->matrix, (rad_alias_format)f, NULL, &t));
        CHECK_OK(rad_alias_tables_create(&c.ffs->matrix, (rad_alias_format)f, NULL, &ts));
        if (!t || !ts) break;
        CHECK(t->row_offsets[n] == ts->row_offsets[n]);
        CHECK(memcmp(t->bins, ts->bins, (size_t)t->row_offsets[n] * f * 4) == 0);
        CHECK(memcmp(t->totals, ts->totals, n * sizeof(float)) == 0);
        for (i = 0; i < n; ++i) {
            uint64_t a = t->row_offsets[i], b = t->row_offsets[i + 1];
            const rad_matrix *S = &c.ffs->matrix;
            CHECK_OK(rad_alias_build_row(NULL, c.ff->matrix.dense + (size_t)i * n, n, n, (rad_alias_format)f, bins, &nb, &total, scratch));
            same &= nb == (uint32_t)(b - a) && total == t->totals[i] && memcmp(bins, t->bins + a * f, (size_t)nb * f * 4) == 0;
            CHECK_OK(rad_alias_build_row(S->columns + S->row_offsets[i], S->values + S->row_offsets[i],
                                         (uint32_t)(S->row_offsets[i + 1] - S->row_offsets[i]), n, (rad_alias_format)f, bins, &nb,
                                         &total, scratch));
            same &= nb == (uint32_t)(b - a) && total == t->totals[i] && memcmp(bins, t->bins + a * f, (size_t)nb * f * 4) == 0;
        }
        CHECK(same);
        rad_alias_tables_destroy(t);
        rad_alias_tables_destroy(ts);
        t = ts = NULL;
    }
    rad_alias_tables_destroy(t);
    rad_alias_tables_destroy(ts);
    free(bins);
    free(scratch);
    fx_world_free(&c);
}

/* The step's expectation: M independent single steps (w = 0, each frame new draws) average
   to rho o (F E + G_0 E_0) row by row within 5 standard errors (estimated from the frames). */
static void tp_expectation(void)
{
    tp_cornell c;
    rad_alias_tables *t = NULL;
    rad_temporal *tm = NULL;
    rad_temporal_options o;
    float *FE, *ref, *out, E0[3] = { 0.3f, 0.5f, 0.7f };
    double *sum, *sum2;
    uint32_t i, j, n, fr, M = rad_test_quick() ? 500u : 2000u, bad = 0;
    if (!tp_cornell_build(&c, 100, 0)) { CHECK(0); fx_world_free(&c); return; }
    n = c.n;
    FE = (float *)malloc(sizeof(float) * 3 * n);
    ref = (float *)malloc(sizeof(float) * 3 * n);
    out = (float *)malloc(sizeof(float) * 3 * n);
    sum = (double *)calloc(3 * n, sizeof(double));
    sum2 = (double *)calloc(3 * n, sizeof(double));
    CHECK_OK(rad_matrix_multiply(&c.ff->matrix, c.E, FE, NULL));
    for (i = 0; i < n; ++i) {
        double S = 0.0;
        for (j = 0; j < n; ++j) S += c.ff->matrix.dense[(size_t)i * n + j];
        for (j = 0; j < 3; ++j) ref[3 * i + j] = c.patches->albedo[3 * i + j] * (FE[3 * i + j] + (S < 1.0 ? (float)(1.0 - S) : 0.0f) * E0[j]);
    }
    CHECK_OK(rad_alias_tables_create(&c.ff->matrix, RAD_ALIAS_AUTO, NULL, &t));
    rad_temporal_options_default(&o);
    o.weight = -1.0f; /* no history */
    o.samples = 10;
    CHECK_OK(rad_temporal_create((const rad_alias_tables *const *)&t, 1, c.patches->albedo, &o, NULL, &tm));
    if (tm) {
        for (fr = 0; fr < M; ++fr) {
            CHECK_OK(rad_temporal_step(tm, c.E, E0, out));
            for (i = 0; i < 3 * n; ++i) { sum[i] += out[i]; sum2[i] += (double)out[i] * out[i]; }
        }
        for (i = 0; i < 3 * n; ++i) {
            double mean = sum[i] / M, var = sum2[i] / M - mean * mean, se = sqrt((var > 0 ? var : 0) / M);
            if (fabs(mean - ref[i]) > 5.0 * se + 1e-5 * fabs(ref[i]) + 1e-7) ++bad;
            out[i] = (float)mean;
        }
        printf("    %u frames: relative RMS of the mean %.4f, %u of %u values beyond 5 standard errors\n", M, tp_rel_rms(out, ref, n), bad, 3 * n);
        CHECK(bad <= 1u);
        CHECK(tp_rel_rms(out, ref, n) < (rad_test_quick() ? 0.06 : 0.03));
    }
    rad_temporal_destroy(tm);
    rad_alias_tables_destroy(t);
    free(FE); free(ref); free(out); free(sum); free(sum2);
    fx_world_free(&c);
}

/* Constant E: single bounce converges to rho o (F E); feedback to L_inf of rad_solve_direct
   (RAD_OUTPUT_INDIRECT). k = 64, w = 0.995 (noise factor sqrt((1-w)/(1+w)) = 0.05 of one
   frame's). Tolerances: relative RMS of the frame after warm-up below 3%, and of the mean of
   200 further frames below 2%. */
static void tp_converge(void)
{
    tp_cornell c;
    rad_alias_tables *t = NULL;
    rad_temporal *tm = NULL;
    rad_temporal_options o;
    rad_system sys;
    rad_solve_options so;
    float *ref, *out, *avg;
    uint32_t i, n, fr, mode;
    if (!tp_cornell_build(&c, 100, 0)) { CHECK(0); fx_world_free(&c); return; }
    n = c.n;
    ref = (float *)malloc(sizeof(float) * 3 * n);
    out = (float *)malloc(sizeof(float) * 3 * n);
    avg = (float *)malloc(sizeof(float) * 3 * n);
    CHECK_OK(rad_alias_tables_create(&c.ff->matrix, RAD_ALIAS_AUTO, NULL, &t));
    for (mode = 0; mode < 2 && t; ++mode) {
        double e1, e2;
        uint32_t warm = mode == 0 ? 1500u : 3000u;
        if (mode == 0) {
            CHECK_OK(rad_matrix_multiply(&c.ff->matrix, c.E, ref, NULL));
            for (i = 0; i < 3 * n; ++i) ref[i] *= c.patches->albedo[i];
        } else {
            rad_system_init(&sys, &c.ff->matrix, c.patches, c.E);
            rad_solve_options_default(&so);
            so.output = RAD_OUTPUT_INDIRECT;
            CHECK_OK(rad_solve_direct(&sys, &so, ref, NULL));
        }
        rad_temporal_options_default(&o);
        o.mode = mode == 0 ? RAD_TEMPORAL_SINGLE : RAD_TEMPORAL_FEEDBACK;
        o.samples = 64;
        o.weight = 0.995f;
        CHECK_OK(rad_temporal_create((const rad_alias_tables *const *)&t, 1, c.patches->albedo, &o, NULL, &tm));
        if (!tm) break;
        for (fr = 0; fr < warm; ++fr) CHECK_OK(rad_temporal_step(tm, c.E, NULL, out));
        e1 = tp_rel_rms(out, ref, n);
        memset(avg, 0, sizeof(float) * 3 * n);
        for (fr = 0; fr < 200; ++fr) {
            CHECK_OK(rad_temporal_step(tm, c.E, NULL, out));
            for (i = 0; i < 3 * n; ++i) avg[i] += out[i] / 200.0f;
        }
        e2 = tp_rel_rms(avg, ref, n);
        printf("    %s: after %u frames relative RMS %.4f, mean of 200 more %.4f\n", mode ? "feedback vs L_inf" : "single vs rho o FE",
               warm, e1, e2);
        CHECK(e1 < 0.03);
        CHECK(e2 < 0.02);
        CHECK(rad_temporal_frame(tm) == warm + 200u);
        rad_temporal_reset(tm);
        CHECK(rad_temporal_frame(tm) == 0u && rad_temporal_indirect(tm)[0] == 0.0f);
        rad_temporal_destroy(tm);
        tm = NULL;
    }
    rad_alias_tables_destroy(t);
    free(ref); free(out); free(avg);
    fx_world_free(&c);
}

/* A multi-bounce-like input: one plane per channel (2F, 1.5F, F: rows above 1) in
   RAD_TEMPORAL_MULTIBOUNCE mode (no albedo) averages to the exact per-channel products. */
static void tp_multibounce_channels(void)
{
    tp_cornell c;
    rad_alias_tables *t[3] = { NULL, NULL, NULL };
    rad_temporal *tm = NULL;
    rad_temporal_options o;
    float *plane, *ref, *out, *avg, scale[3] = { 2.0f, 1.5f, 1.0f };
    uint32_t i, j, k, n, fr, M = 1500;
    if (!tp_cornell_build(&c, 80, 0)) { CHECK(0); fx_world_free(&c); return; }
    n = c.n;
    plane = (float *)malloc(sizeof(float) * n * n);
    ref = (float *)calloc(3 * n, sizeof(float));
    out = (float *)malloc(sizeof(float) * 3 * n);
    avg = (float *)calloc(3 * n, sizeof(float));
    for (k = 0; k < 3; ++k) {
        for (i = 0; i < n * n; ++i) plane[i] = scale[k] * c.ff->matrix.dense[i];
        CHECK_OK(rad_alias_tables_create_dense(plane, n, RAD_ALIAS_AUTO, NULL, &t[k]));
        for (i = 0; i < n; ++i) {
            double s = 0.0;
            for (j = 0; j < n; ++j) s += (double)plane[(size_t)i * n + j] * c.E[3 * j + k];
            ref[3 * i + k] = (float)s;
        }
    }
    rad_temporal_options_default(&o);
    o.mode = RAD_TEMPORAL_MULTIBOUNCE;
    o.weight = -1.0f; /* no history */
    o.samples = 16;
    if (t[0] && t[1] && t[2]) {
        CHECK_OK(rad_temporal_create((const rad_alias_tables *const *)t, 3, NULL, &o, NULL, &tm));
        for (fr = 0; tm && fr < M; ++fr) {
            CHECK_OK(rad_temporal_step(tm, c.E, NULL, out));
            for (i = 0; i < 3 * n; ++i) avg[i] += out[i] / (float)M;
        }
        printf("    3 channel tables (2F, 1.5F, F): relative RMS of the mean of %u frames %.4f\n", M, tp_rel_rms(avg, ref, n));
        CHECK(tp_rel_rms(avg, ref, n) < 0.02);
        /* three tables need MULTIBOUNCE */
        o.mode = RAD_TEMPORAL_SINGLE;
        rad_temporal_destroy(tm);
        tm = NULL;
        CHECK_RESULT(rad_temporal_create((const rad_alias_tables *const *)t, 3, c.patches->albedo, &o, NULL, &tm), RAD_ERROR_INVALID_ARGUMENT);
    }
    rad_temporal_destroy(tm);
    for (k = 0; k < 3; ++k) rad_alias_tables_destroy(t[k]);
    free(plane); free(ref); free(out); free(avg);
    fx_world_free(&c);
}

/* a parallel_for that runs tasks in reverse order (and checks nothing runs twice) */
/* Same seed, same bits: serial vs reversed custom parallel_for with 1, 7 and 64 tasks, and
   the OpenMP default; a different seed differs. Also adaptive mode. */
static void tp_determinism(void)
{
    tp_cornell c;
    rad_alias_tables *t = NULL, *t7 = NULL;
    rad_context ctx;
    rad_temporal_options o;
    float *ref, *out;
    uint32_t n, fr, v, ad;
    static const uint32_t tasks[4] = { 0, 1, 7, 64 };
    if (!tp_cornell_build(&c, 80, 0)) { CHECK(0); fx_world_free(&c); return; }
    n = c.n;
    ref = (float *)malloc(sizeof(float) * 3 * n);
    out = (float *)malloc(sizeof(float) * 3 * n);
    CHECK_OK(rad_alias_tables_create(&c.ff->matrix, RAD_ALIAS_AUTO, NULL, &t));
    memset(&ctx, 0, sizeof(ctx));
    ctx.parallel_for = fx_reverse_for;
    ctx.task_count = 7;
    CHECK_OK(rad_alias_tables_create(&c.ff->matrix, RAD_ALIAS_AUTO, &ctx, &t7));
    if (t && t7) CHECK(memcmp(t->bins, t7->bins, (size_t)t->row_offsets[n] * t->format * 4) == 0);
    for (ad = 0; ad < 2 && t; ++ad) {
        rad_temporal_options_default(&o);
        o.mode = RAD_TEMPORAL_FEEDBACK;
        o.weight = 0.9f;
        o.seed = 99;
        o.adaptive = (int)ad;
        for (v = 0; v < 5; ++v) {
            rad_temporal *tm = NULL;
            memset(&ctx, 0, sizeof(ctx));
            if (v > 0 && v < 4) { ctx.parallel_for = fx_reverse_for; ctx.task_count = tasks[v]; }
            if (v == 4) o.seed = 100;
            CHECK_OK(rad_temporal_create((const rad_alias_tables *const *)&t, 1, c.patches->albedo, &o, &ctx, &tm));
            if (!tm) continue;
            for (fr = 0; fr < 20; ++fr) CHECK_OK(rad_temporal_step(tm, c.E, NULL, out));
            if (v == 0) memcpy(ref, out, sizeof(float) * 3 * n);
            else if (v < 4) CHECK(memcmp(ref, out, sizeof(float) * 3 * n) == 0);
            else CHECK(memcmp(ref, out, sizeof(float) * 3 * n) != 0);
            /* reset replays the same frames */
            if (v == 0) {
                rad_temporal_reset(tm);
                for (fr = 0; fr < 20; ++fr) CHECK_OK(rad_temporal_step(tm, c.E, NULL, out));
                CHECK(memcmp(ref, out, sizeof(float) * 3 * n) == 0);
            }
            rad_temporal_destroy(tm);
        }
    }
    rad_alias_tables_destroy(t);
    rad_alias_tables_destroy(t7);
    free(ref); free(out);
    fx_world_free(&c);
}

/* frames after a jump of E (E -> 2.5 E at frame 'jump') until the projection of B - L_a onto
   L_b - L_a reaches 90% (and stays there for 5 frames); steady relative RMS before the jump */
static void tp_lag_run(tp_cornell *c, const rad_alias_tables *t, int adaptive, float target, uint32_t *lag, double *noise)
{
    rad_temporal_options o;
    rad_temporal *tm = NULL;
    uint32_t n = c->n, i, fr, jump = 3000, ok = 0;
    float *E2 = (float *)malloc(sizeof(float) * 3 * n), *La = (float *)malloc(sizeof(float) * 3 * n),
          *Lb = (float *)malloc(sizeof(float) * 3 * n), *out = (float *)malloc(sizeof(float) * 3 * n);
    double acc = 0.0;
    *lag = 0xFFFFFFFFu;
    *noise = 1.0;
    for (i = 0; i < 3 * n; ++i) E2[i] = 2.5f * c->E[i];
    rad_matrix_multiply(&c->ff->matrix, c->E, La, NULL);
    for (i = 0; i < 3 * n; ++i) { La[i] *= c->patches->albedo[i]; Lb[i] = 2.5f * La[i]; }
    rad_temporal_options_default(&o);
    o.samples = 10;
    o.adaptive = adaptive;
    o.noise_target = target;
    if (rad_temporal_create(&t, 1, c->patches->albedo, &o, NULL, &tm) != RAD_SUCCESS) { CHECK(0); goto done; }
    for (fr = 0; fr < jump + 3000; ++fr) {
        rad_temporal_step(tm, fr < jump ? c->E : E2, NULL, out);
        if (fr >= jump - 200 && fr < jump) acc += tp_rel_rms(out, La, n) / 200.0;
        if (fr >= jump) {
            double num = 0.0, den = 0.0;
            for (i = 0; i < 3 * n; ++i) { num += ((double)out[i] - La[i]) * (Lb[i] - La[i]); den += ((double)Lb[i] - La[i]) * (Lb[i] - La[i]); }
            if (num / den >= 0.9) { if (++ok == 5 && *lag == 0xFFFFFFFFu) { *lag = fr - jump + 1 - 4; break; } }
            else ok = 0;
        }
    }
    *noise = acc;
done:
    rad_temporal_destroy(tm);
    free(E2); free(La); free(Lb); free(out);
}

/* Adaptive weight: at a noise target that gives at most the fixed w = 0.998 noise, the lag after
   a light jump is at least 3x shorter; weights stay in [0, weight_max]. */
static void tp_adaptive(void)
{
    tp_cornell c;
    rad_alias_tables *t = NULL;
    uint32_t lag_f, lag_a;
    double noise_f, noise_a;
    if (rad_test_quick()) { printf("    (skipped in quick mode)\n"); return; }
    if (!tp_cornell_build(&c, 100, 0)) { CHECK(0); fx_world_free(&c); return; }
    CHECK_OK(rad_alias_tables_create(&c.ff->matrix, RAD_ALIAS_AUTO, NULL, &t));
    if (t) {
        tp_lag_run(&c, t, 0, 0.0f, &lag_f, &noise_f);
        tp_lag_run(&c, t, 1, 0.01f, &lag_a, &noise_a);
        printf("    w = 0.998: lag %u frames, noise %.4f; adaptive (target 0.01): lag %u frames, noise %.4f\n", lag_f, noise_f,
               lag_a, noise_a);
        CHECK(lag_a * 3u <= lag_f);
        CHECK(noise_a <= noise_f * 1.05);
    }
    rad_alias_tables_destroy(t);
    fx_world_free(&c);
}

static int tp_log_count;
static void tp_log(void *user, rad_log_level level, const char *msg)
{
    (void)user; (void)level; (void)msg;
    tp_log_count++;
}

static void tp_errors(void)
{
    float bad[4] = { 0.1f, -0.2f, 0.3f, 0.0f }, nanrow[3] = { 0.1f, 0.0f, 0.0f }, dense[4] = { 0.5f, 0.5f, 0.25f, 0.0f };
    uint32_t cols[3] = { 0, 5, 1 }, bins[16], nb;
    unsigned char scratch[256];
    float total, E[6] = { 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f }, alb[6] = { 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f };
    rad_context ctx;
    rad_matrix m;
    rad_alias_tables *t = NULL, *t3 = NULL;
    rad_temporal *tm = NULL;
    rad_temporal_options o;
    memset(&ctx, 0, sizeof(ctx));
    ctx.log = tp_log;
    {
        volatile float zero = 0.0f;
        nanrow[1] = zero / zero;
    }
    CHECK_RESULT(rad_alias_build_row(NULL, bad, 4, 4, RAD_ALIAS_AUTO, bins, &nb, &total, scratch), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_alias_build_row(NULL, nanrow, 3, 3, RAD_ALIAS_AUTO, bins, &nb, &total, scratch), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_alias_build_row(cols, dense, 3, 4, RAD_ALIAS_AUTO, bins, &nb, &total, scratch), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_alias_build_row(NULL, dense, 3, 4, RAD_ALIAS_AUTO, bins, &nb, &total, scratch), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_alias_build_row(NULL, dense, 3, 3, RAD_ALIAS_COMPACT, bins, &nb, &total, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_alias_build_row(NULL, dense, 70000, 70000, RAD_ALIAS_COMPACT, bins, &nb, &total, scratch), RAD_ERROR_INVALID_ARGUMENT);
    /* an all-zero row: only the environment bin, T = 1 */
    {
        float z[3] = { 0, 0, 0 };
        CHECK_OK(rad_alias_build_row(NULL, z, 3, 3, RAD_ALIAS_WIDE, bins, &nb, &total, scratch));
        CHECK(nb == 1u && total == 1.0f && bins[1] == 3u && bins[2] == 3u);
        CHECK(rad_alias_draw(bins, 1, RAD_ALIAS_WIDE, 0xFFFFFFFFu, 0xFFFFFFFFu) == 3u);
    }
    memset(&m, 0, sizeof(m));
    m.rows = 2; m.cols = 2; m.storage = RAD_STORAGE_DENSE; m.dense = bad;
    tp_log_count = 0;
    CHECK_RESULT(rad_alias_tables_create(&m, RAD_ALIAS_AUTO, &ctx, &t), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(t == NULL && tp_log_count >= 1);
    m.cols = 3;
    CHECK_RESULT(rad_alias_tables_create(&m, RAD_ALIAS_AUTO, &ctx, &t), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_alias_tables_create(NULL, RAD_ALIAS_AUTO, &ctx, &t), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_alias_tables_create_dense(NULL, 2, RAD_ALIAS_AUTO, &ctx, &t), RAD_ERROR_INVALID_ARGUMENT);
    m.cols = 2; m.dense = dense;
    CHECK_OK(rad_alias_tables_create(&m, RAD_ALIAS_AUTO, &ctx, &t));
    CHECK_OK(rad_alias_tables_create_dense(dense, 1, RAD_ALIAS_AUTO, &ctx, &t3));
    rad_temporal_options_default(&o);
    if (t && t3) {
        const rad_alias_tables *pair[2];
        pair[0] = t; pair[1] = t3;
        CHECK_RESULT(rad_temporal_create(pair, 1, NULL, &o, &ctx, &tm), RAD_ERROR_INVALID_ARGUMENT); /* no albedo */
        o.samples = RAD_TEMPORAL_MAX_SAMPLES + 1u;
        CHECK_RESULT(rad_temporal_create(pair, 1, alb, &o, &ctx, &tm), RAD_ERROR_INVALID_ARGUMENT);
        o.samples = 4; o.weight = 1.0f;
        CHECK_RESULT(rad_temporal_create(pair, 1, alb, &o, &ctx, &tm), RAD_ERROR_INVALID_ARGUMENT);
        o.weight = 0.5f; o.adaptive = 1; o.noise_target = -1.0f;
        CHECK_RESULT(rad_temporal_create(pair, 1, alb, &o, &ctx, &tm), RAD_ERROR_INVALID_ARGUMENT);
        o.adaptive = 0;
        CHECK_RESULT(rad_temporal_create(pair, 2, alb, &o, &ctx, &tm), RAD_ERROR_INVALID_ARGUMENT);
        {
            const rad_alias_tables *three[3];
            three[0] = t; three[1] = t3; three[2] = t;
            o.mode = RAD_TEMPORAL_MULTIBOUNCE;
            CHECK_RESULT(rad_temporal_create(three, 3, NULL, &o, &ctx, &tm), RAD_ERROR_SIZE_MISMATCH);
            o.mode = RAD_TEMPORAL_SINGLE;
        }
        CHECK(tm == NULL);
        CHECK_OK(rad_temporal_create(pair, 1, alb, &o, &ctx, &tm));
        CHECK_RESULT(rad_temporal_step(tm, NULL, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
        CHECK_OK(rad_temporal_step(tm, E, alb, NULL));
        CHECK(rad_temporal_weights(tm) == NULL);
        /* row 1 is {0.25, 0} + environment 0.75: with E = E_0 = 0.5 every draw gives 0.5, so
           X = rho 0.5 = 0.25 and B = (1 - w) X = 0.125 exactly */
        CHECK_NEAR(rad_temporal_indirect(tm)[3], 0.125, 1e-7);
    }
    rad_temporal_destroy(tm);
    rad_temporal_destroy(NULL);
    rad_alias_tables_destroy(t);
    rad_alias_tables_destroy(t3);
    rad_alias_tables_destroy(NULL);
}

/* Tables through a container: write, open, view; the view equals the tables and steps give the
   same bits; a bin naming a column > N is refused (CORRUPT) with a message. */
static void tp_container(void)
{
    tp_cornell c;
    rad_alias_tables *t = NULL, v;
    rad_section sec[3];
    rad_container *ct = NULL;
    rad_context ctx;
    void *buf = NULL;
    size_t size = 0;
    uint32_t n;
    if (!tp_cornell_build(&c, 60, 0)) { CHECK(0); fx_world_free(&c); return; }
    n = c.n;
    memset(&ctx, 0, sizeof(ctx));
    ctx.log = tp_log;
    CHECK_OK(rad_alias_tables_create(&c.ff->matrix, RAD_ALIAS_AUTO, NULL, &t));
    if (t) {
        rad_alias_tables_sections(t, "F", sec, NULL);
        CHECK_OK(rad_container_size(sec, 3, &size));
        buf = malloc(size);
        CHECK_OK(rad_container_write(sec, 3, buf, size));
        CHECK_OK(rad_container_create(buf, size, NULL, &ct));
        CHECK_OK(rad_alias_tables_view(ct, "F", NULL, &v));
        CHECK(v.rows == n && v.format == t->format && v.row_offsets[n] == t->row_offsets[n]);
        CHECK(memcmp(v.bins, t->bins, (size_t)t->row_offsets[n] * t->format * 4) == 0);
        CHECK_RESULT(rad_alias_tables_view(ct, "G", &ctx, &v), RAD_ERROR_INVALID_ARGUMENT);
        rad_container_destroy(ct);
        ct = NULL;
        {
            /* a corrupt copy of the bins, written with a valid checksum */
            size_t bytes = (size_t)t->row_offsets[n] * t->format * 4;
            uint32_t *bad = (uint32_t *)malloc(bytes);
            memcpy(bad, t->bins, bytes);
            bad[1] = (uint32_t)(n + 1u);
            sec[1].data = bad;
            CHECK_OK(rad_container_write(sec, 3, buf, size));
            CHECK_OK(rad_container_create(buf, size, NULL, &ct));
            tp_log_count = 0;
            CHECK_RESULT(rad_alias_tables_view(ct, "F", &ctx, &v), RAD_ERROR_CORRUPT);
            CHECK(tp_log_count == 1);
            rad_container_destroy(ct);
            free(bad);
        }
    }
    free(buf);
    rad_alias_tables_destroy(t);
    fx_world_free(&c);
}

/* The step written out plainly from the doc block (rad_temporal_random + rad_alias_draw, the
   float operations in the documented order, fixed weight) for 'frames' frames; B: 3N, starts
   at 0. The library's software-pipelined step must give the same bits. */
static void tp_plain_steps(const rad_alias_tables *const *tb, uint32_t sets, const float *albedo, const rad_temporal_options *o,
                           const float *E, const float *E0, uint32_t frames, float *B)
{
    const uint32_t n = tb[0]->rows, k = o->samples;
    float *V = (float *)malloc(sizeof(float) * 3 * n), *Bn = (float *)malloc(sizeof(float) * 3 * n);
    uint32_t fr, i, c, s, u[2];
    memset(B, 0, sizeof(float) * 3 * n);
    for (fr = 0; fr < frames; ++fr) {
        for (i = 0; i < 3 * n; ++i) V[i] = o->mode == RAD_TEMPORAL_FEEDBACK ? E[i] + B[i] : E[i];
        for (i = 0; i < n; ++i) {
            float acc[3] = { 0.0f, 0.0f, 0.0f }, X[3];
            for (c = 0; c < sets; ++c) {
                const uint64_t first = tb[c]->row_offsets[i];
                const uint32_t nb = (uint32_t)(tb[c]->row_offsets[i + 1] - first);
                for (s = 0; s < k; ++s) {
                    uint32_t col, ch;
                    rad_temporal_random(o->seed, fr, i, c * k + s, u);
                    col = rad_alias_draw(tb[c]->bins + (size_t)first * (uint32_t)tb[c]->format, nb, tb[c]->format, u[0], u[1]);
                    for (ch = 0; ch < 3; ++ch)
                        if (sets == 1u || ch == c) acc[ch] += col < n ? V[3 * (size_t)col + ch] : (E0 ? E0[ch] : 0.0f);
                }
            }
            for (c = 0; c < 3; ++c) {
                X[c] = acc[c] * (tb[sets == 1u ? 0 : c]->totals[i] / (float)k);
                if (o->mode != RAD_TEMPORAL_MULTIBOUNCE) X[c] *= albedo[3 * i + c];
                Bn[3 * i + c] = o->weight * B[3 * i + c] + (1.0f - o->weight) * X[c];
            }
        }
        memcpy(B, Bn, sizeof(float) * 3 * n);
    }
    free(V);
    free(Bn);
}

/* The pipelined step (draws hashed and prefetched RAD__TEMPORAL_AHEAD ahead, across rows) equals
   the plain loop bit for bit: k = 1 with one row per task (fewer draws than the look-ahead),
   k = 10, k = 70 (more draws per row than the look-ahead) in feedback mode with wide bins,
   three channel tables of mixed formats, three compact channel tables with k = 3, several task
   splits (on x86-64 with AVX2, compact tables take the path that puts 8 rows side by side:
   one row per task and splits of 7 leave partial blocks of rows). */
static void tp_pipeline_bits(void)
{
    tp_cornell c;
    rad_alias_tables *t = NULL, *tw = NULL, *tc[3] = { NULL, NULL, NULL }, *tk[3] = { NULL, NULL, NULL };
    rad_context ctx;
    rad_temporal_options o;
    float *ref, *out, *plane, E0[3] = { 0.2f, 0.4f, 0.1f };
    uint32_t n, v, i;
    /* v: 0, 1 single compact; 2 feedback wide; 3 multibounce mixed; 4 multibounce compact; 5 feedback compact */
    static const uint32_t ks[6] = { 1, 10, 70, 10, 3, 9 }, tasks[6] = { 4096, 0, 7, 3, 7, 5 };
    if (!tp_cornell_build(&c, rad_test_quick() ? 40 : 80, 0)) { CHECK(0); fx_world_free(&c); return; }
    n = c.n;
    ref = (float *)malloc(sizeof(float) * 3 * n);
    out = (float *)malloc(sizeof(float) * 3 * n);
    plane = (float *)malloc(sizeof(float) * n * n);
    CHECK_OK(rad_alias_tables_create(&c.ff->matrix, RAD_ALIAS_COMPACT, NULL, &t));
    CHECK_OK(rad_alias_tables_create(&c.ff->matrix, RAD_ALIAS_WIDE, NULL, &tw));
    for (v = 0; v < 3; ++v) {
        for (i = 0; i < n * n; ++i) plane[i] = (1.0f + 0.5f * (float)v) * c.ff->matrix.dense[i];
        CHECK_OK(rad_alias_tables_create_dense(plane, n, v == 1 ? RAD_ALIAS_WIDE : RAD_ALIAS_COMPACT, NULL, &tc[v]));
        CHECK_OK(rad_alias_tables_create_dense(plane, n, RAD_ALIAS_COMPACT, NULL, &tk[v]));
    }
    for (v = 0; v < 6 && t && tw && tc[0] && tc[1] && tc[2] && tk[0] && tk[1] && tk[2]; ++v) {
        const rad_alias_tables *const *tb = v == 4 ? (const rad_alias_tables *const *)tk
                                          : v == 3 ? (const rad_alias_tables *const *)tc
                                                   : (const rad_alias_tables *const *)(v == 2 ? &tw : &t);
        const uint32_t sets = v == 3 || v == 4 ? 3u : 1u;
        rad_temporal *tm = NULL;
        uint32_t fr;
        rad_temporal_options_default(&o);
        o.samples = ks[v];
        o.seed = 1234u + v;
        o.weight = 0.75f;
        o.mode = v == 2 || v == 5 ? RAD_TEMPORAL_FEEDBACK : v >= 3 ? RAD_TEMPORAL_MULTIBOUNCE : RAD_TEMPORAL_SINGLE;
        memset(&ctx, 0, sizeof(ctx));
        if (tasks[v]) { ctx.parallel_for = fx_reverse_for; ctx.task_count = tasks[v]; }
        tp_plain_steps(tb, sets, c.patches->albedo, &o, c.E, E0, 3, ref);
        CHECK_OK(rad_temporal_create(tb, sets, c.patches->albedo, &o, &ctx, &tm));
        if (!tm) continue;
        for (fr = 0; fr < 3; ++fr) CHECK_OK(rad_temporal_step(tm, c.E, E0, out));
        CHECK(memcmp(ref, out, sizeof(float) * 3 * n) == 0);
        rad_temporal_destroy(tm);
    }
    rad_alias_tables_destroy(t);
    rad_alias_tables_destroy(tw);
    for (v = 0; v < 3; ++v) {
        rad_alias_tables_destroy(tc[v]);
        rad_alias_tables_destroy(tk[v]);
    }
    free(ref); free(out); free(plane);
    fx_world_free(&c);
}

/* counts the bytes a custom allocator hands out and takes back (huge-page path below) */
typedef struct tp_counting { size_t live, calls; } tp_counting;
static void *tp_count_alloc(void *user, size_t size)
{
    tp_counting *a = (tp_counting *)user;
    size_t *p = (size_t *)malloc(size + 16u);
    if (!p) return NULL;
    p[0] = size;
    a->live += size;
    a->calls++;
    return (unsigned char *)p + 16;
}
static void tp_count_free(void *user, void *ptr)
{
    tp_counting *a = (tp_counting *)user;
    size_t *p = (size_t *)(void *)((unsigned char *)ptr - 16);
    a->live -= p[0];
    free(p);
}

/* Tables of more than two huge pages (about 4.4 MB): on Linux the block is 2 MiB aligned
   (placed inside an over-allocation, the original pointer kept for free) and advised
   MADV_HUGEPAGE. The bins equal the streamed-row builder's, draws work, and destroy gives back
   every byte through a custom allocator (and frees correctly under ASan/valgrind). */
static void tp_huge_tables(void)
{
    const uint32_t n = 740;
    float *plane = (float *)malloc(sizeof(float) * n * n), total;
    uint32_t *bins = (uint32_t *)malloc(sizeof(uint32_t) * 2 * (n + 1)), i, nb, state = 7u, bad = 0;
    void *scratch = malloc(rad_alias_row_scratch_size(n));
    rad_alias_tables *t = NULL;
    rad_context ctx;
    tp_counting counter = { 0, 0 };
    for (i = 0; i < n * n; ++i) {
        state = state * 1664525u + 1013904223u;
        plane[i] = (float)(1u + (state >> 20)) * (0.9f / (4096.0f * (float)n)); /* rows sum to < 0.9 */
    }
    memset(&ctx, 0, sizeof(ctx));
    ctx.allocator.alloc = tp_count_alloc;
    ctx.allocator.free = tp_count_free;
    ctx.allocator.user = &counter;
    CHECK_OK(rad_alias_tables_create_dense(plane, n, RAD_ALIAS_COMPACT, &ctx, &t));
    if (t) {
        CHECK(t->row_offsets[n] == (uint64_t)n * (n + 1u)); /* every entry plus the environment */
        CHECK(rad_alias_tables_memory(t) > 4u * ((size_t)1 << 20));
#ifdef RAD__MADV_HUGEPAGE
        CHECK(((uintptr_t)t->row_offsets & (((uintptr_t)2 << 20) - 1u)) == 0);
        CHECK((void *)t->row_offsets != t->storage);
#endif
        for (i = 0; i < n; i += 37) {
            CHECK_OK(rad_alias_build_row(NULL, plane + (size_t)i * n, n, n, RAD_ALIAS_COMPACT, bins, &nb, &total, scratch));
            if (nb != n + 1u || total != t->totals[i] ||
                memcmp(bins, t->bins + (size_t)t->row_offsets[i] * 2u, sizeof(uint32_t) * 2u * nb) != 0)
                ++bad;
            CHECK(rad_alias_draw(t->bins + (size_t)t->row_offsets[i] * 2u, n + 1u, RAD_ALIAS_COMPACT, 0x12345678u, 0x9ABCDEF0u) <= n);
        }
        CHECK(bad == 0);
    }
    rad_alias_tables_destroy(t);
    CHECK(counter.calls > 0 && counter.live == 0);
    free(plane); free(bins); free(scratch);
}

/* Alias totals with a valid checksum but NaN or 3e38 are refused at load, and the draw count k
   is bounded (a bake with k = 16M took 10 s per frame at 206 patches) */
static void tp_bad_values(void)
{
    tp_cornell c;
    rad_alias_tables *t = NULL, v;
    rad_section sec[3];
    rad_container *ct = NULL;
    rad_context ctx;
    rad_temporal_options o;
    rad_temporal *tm = NULL;
    void *buf = NULL;
    size_t size = 0;
    int q;
    if (!tp_cornell_build(&c, 60, 0)) { CHECK(0); fx_world_free(&c); return; }
    CHECK_OK(rad_alias_tables_create(&c.ff->matrix, RAD_ALIAS_AUTO, NULL, &t));
    if (t) {
        rad_alias_tables_sections(t, "F", sec, NULL);
        CHECK_OK(rad_container_size(sec, 3, &size));
        buf = malloc(size);
        CHECK_OK(rad_container_write(sec, 3, buf, size));
        for (q = 0; q < 3; ++q) {
            const float value = q == 0 ? 3e38f : q == 1 ? (float)NAN : -2.0f;
            unsigned char *copy = ct_poke(buf, size, RAD_SECTION_TEMPORAL_TOTALS, "F", 3 * 4, &value, 4);
            CHECK(copy != NULL);
            if (!copy) continue;
            CHECK_OK(rad_container_create(copy, size, NULL, &ct));
            ct_log_context(&ctx);
            CHECK_RESULT(rad_alias_tables_view(ct, "F", &ctx, &v), q == 1 ? RAD_ERROR_NON_FINITE : RAD_ERROR_CORRUPT);
            CHECK(strstr(ct_log_last, "TEMPORAL_TOTALS") != NULL && strstr(ct_log_last, "row 3") != NULL);
            rad_container_destroy(ct);
            ct = NULL;
            free(copy);
        }
        /* k: 1 to RAD_TEMPORAL_MAX_SAMPLES */
        rad_temporal_options_default(&o);
        o.mode = RAD_TEMPORAL_FEEDBACK;
        o.samples = RAD_TEMPORAL_MAX_SAMPLES;
        CHECK_OK(rad_temporal_create((const rad_alias_tables *const *)&t, 1, c.patches->albedo, &o, NULL, &tm));
        rad_temporal_destroy(tm);
        tm = NULL;
        o.samples = RAD_TEMPORAL_MAX_SAMPLES + 1u;
        CHECK_RESULT(rad_temporal_create((const rad_alias_tables *const *)&t, 1, c.patches->albedo, &o, NULL, &tm), RAD_ERROR_INVALID_ARGUMENT);
        o.samples = 16777216u;
        CHECK_RESULT(rad_temporal_create((const rad_alias_tables *const *)&t, 1, c.patches->albedo, &o, NULL, &tm), RAD_ERROR_INVALID_ARGUMENT);
        CHECK(tm == NULL);
    }
    free(buf);
    rad_alias_tables_destroy(t);
    fx_world_free(&c);
}

/* a hand-made table whose bins name a column past N: every step path reads E_0 for it (as
   for the environment column N) and never reads past the sampled vector; 11 rows, so the
   vector step has a full block of 8 and a partial one */
static void tp_column_past_n(void)
{
    enum { N = 11 };
    uint64_t offsets[N + 1];
    uint32_t bins[2 * N];
    float totals[N], albedo[3 * N], E[3 * N], out[3 * N], E0[3] = { 0.5f, 0.25f, 2.0f };
    rad_alias_tables tb;
    const rad_alias_tables *tp1[1];
    rad_temporal_options o;
    rad_temporal *tm = NULL;
    uint32_t i, mode;
    for (i = 0; i < N; ++i) {
        offsets[i] = i;
        bins[2 * i] = 0xFFFFFFFFu; /* probability 1: the bin's own column */
        bins[2 * i + 1] = (i % 2 ? 40000u : (uint32_t)N) | (7u << 16);
        totals[i] = 1.0f;
        albedo[3 * i] = albedo[3 * i + 1] = albedo[3 * i + 2] = 1.0f;
        E[3 * i] = E[3 * i + 1] = E[3 * i + 2] = 3.0f;
    }
    offsets[N] = N;
    memset(&tb, 0, sizeof(tb));
    tb.rows = tb.cols = N;
    tb.format = RAD_ALIAS_COMPACT;
    tb.row_offsets = offsets;
    tb.bins = bins;
    tb.totals = totals;
    tp1[0] = &tb;
    for (mode = 0; mode < 2; ++mode) {
        rad_temporal_options_default(&o);
        o.mode = mode ? RAD_TEMPORAL_FEEDBACK : RAD_TEMPORAL_SINGLE;
        o.samples = 4;
        o.weight = -1.0f; /* no history */
        CHECK_OK(rad_temporal_create(tp1, 1, albedo, &o, NULL, &tm));
        if (!tm) continue;
        CHECK_OK(rad_temporal_step(tm, E, E0, out));
        for (i = 0; i < 3 * N; ++i) CHECK(out[i] == E0[i % 3]);
        rad_temporal_destroy(tm);
    }
}

static const rad_test_case tests_temporal[] = {
    { "temporal_random_vectors", tp_random_vectors },
    { "temporal_alias_chi_square", tp_alias_chi_square },
    { "temporal_alias_tables_exact", tp_alias_tables_exact },
    { "temporal_streamed_rows", tp_streamed_rows },
    { "temporal_expectation", tp_expectation },
    { "temporal_converge", tp_converge },
    { "temporal_multibounce_channels", tp_multibounce_channels },
    { "temporal_determinism", tp_determinism },
    { "temporal_adaptive", tp_adaptive },
    { "temporal_errors", tp_errors },
    { "temporal_container", tp_container },
    { "temporal_bad_values", tp_bad_values },
    { "temporal_pipeline_bits", tp_pipeline_bits },
    { "temporal_huge_tables", tp_huge_tables },
    { "temporal_column_past_n", tp_column_past_n },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_temporal)

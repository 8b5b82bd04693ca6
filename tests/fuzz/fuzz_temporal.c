/* fuzz_temporal.c - libFuzzer harness for the temporal alias-table view
   (rad_alias_tables_view: row offsets, bins and totals in container bytes). The input goes
   to rad_container_create (copied into an aligned buffer, as a mapped file would be), then a
   second copy with recomputed checksums (fuzz_common.h), so mutations reach the view's own
   checks. Every table set a bins section names (up to 4 per input) is viewed; each view that
   opens is used:
   - draws: every row (up to 64) draws 4 columns through rad_alias_draw, each <= N;
   - steps: a temporal state in each mode (SINGLE with a fixed weight, FEEDBACK adaptive with
     a restart, MULTIBOUNCE with one table) steps a few frames with a sky value, so every
     draw resolves into E and B;
   - three views of the same size (the per-channel tables of F_mb) drive a MULTIBOUNCE state
     with three tables;
   - a round trip: the view written through rad_alias_tables_sections into a new container,
     reopened and viewed again, must hold the same bins.
   The indirect light must be finite whenever the totals are tame (fuzz_bounded); loaded
   huge totals are counted, not a crash (value validation is not this harness's check).
   Build: clang -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -I. tests/fuzz/fuzz_temporal.c */
#define RADIOSITY_IMPLEMENTATION
#include "../../radiosity.h"
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define FUZZ_MAX_VIEWS 4u
#define FUZZ_MAX_ROWS 65536u
#define FUZZ_TAME 1e4f     /* totals up to this: three feedback frames stay far from FLT_MAX */
#define FUZZ_SAMPLES 4u

static const float sky[3] = { 0.25f, 0.5f, 1.0f };

/* steps a state 'frames' times (a change signalled before the last) and checks B */
static void steps(const rad_alias_tables *const *tables, uint32_t count, const rad_temporal_options *o, const float *albedo,
                  const float *E, float *out, int tame, uint32_t frames)
{
    rad_temporal *t = NULL;
    uint32_t f, n = tables[0]->rows;
    if (rad_temporal_create(tables, count, albedo, o, NULL, &t) != RAD_SUCCESS) return;
    for (f = 0; f < frames; ++f) {
        if (f + 1 == frames) rad_temporal_signal_change(t);
        if (rad_temporal_step(t, E, sky, out) != RAD_SUCCESS) break;
        if (tame) {
            fuzz_check_finite(out, 3 * (size_t)n);
            fuzz_check_finite(rad_temporal_indirect(t), 3 * (size_t)n);
            if (rad_temporal_weights(t)) fuzz_check_finite(rad_temporal_weights(t), n);
        }
    }
    rad_temporal_destroy(t);
}

static void use_view(const rad_alias_tables *v, const char *name)
{
    uint32_t n = v->rows, r, s;
    int tame = fuzz_bounded(v->totals, n, FUZZ_TAME);
    float *E = fuzz_fill(3 * (size_t)n, 1.0f), *albedo = fuzz_fill(3 * (size_t)n, 0.5f), *out = fuzz_fill(3 * (size_t)n, 0.0f);
    const rad_alias_tables *one[1];
    rad_temporal_options o;
    rad_section sec[3];
    size_t bytes;
    void *buf = NULL;
    rad_container *ct = NULL;
    rad_alias_tables again;
    if (!tame) fuzz_untamed("alias totals above 1e4");
    for (r = 0; r < n && r < 64u; ++r)
        for (s = 0; s < 4u; ++s) {
            uint32_t u[2], first = (uint32_t)v->row_offsets[r], bins = (uint32_t)(v->row_offsets[r + 1] - v->row_offsets[r]);
            rad_temporal_random(7u, 0u, r, s, u);
            if (rad_alias_draw(v->bins + (size_t)first * v->format, bins, v->format, u[0], u[1]) > v->cols) abort();
        }
    if (E && albedo && out) {
        one[0] = v;
        rad_temporal_options_default(&o);
        o.samples = FUZZ_SAMPLES;
        o.weight = 0.5f;
        o.mode = RAD_TEMPORAL_SINGLE;
        steps(one, 1, &o, albedo, E, out, tame, 2);
        o.mode = RAD_TEMPORAL_FEEDBACK;
        o.adaptive = 1;
        steps(one, 1, &o, albedo, E, out, tame, 3);
        o.mode = RAD_TEMPORAL_MULTIBOUNCE;
        o.adaptive = 0;
        steps(one, 1, &o, NULL, E, out, tame, 2);
    }
    /* the round trip */
    rad_alias_tables_sections(v, name, sec, NULL);
    if (rad_container_size(sec, 3, &bytes) != RAD_SUCCESS) abort();
    buf = malloc(bytes);
    if (buf) {
        if (rad_container_write(sec, 3, buf, bytes) != RAD_SUCCESS || rad_container_create(buf, bytes, NULL, &ct) != RAD_SUCCESS ||
            rad_alias_tables_view(ct, name, NULL, &again) != RAD_SUCCESS || again.rows != n || again.format != v->format ||
            memcmp(again.bins, v->bins, (size_t)v->row_offsets[n] * v->format * 4u) != 0)
            abort();
        rad_container_destroy(ct);
        free(buf);
    }
    free(E);
    free(albedo);
    free(out);
}

static void exercise(const void *buf, size_t size)
{
    rad_container *ct = NULL;
    rad_alias_tables views[FUZZ_MAX_VIEWS];
    uint32_t i, n, count = 0;
    if (rad_container_create(buf, size, NULL, &ct) != RAD_SUCCESS) return;
    n = rad_container_section_count(ct);
    for (i = 0; i < n && count < FUZZ_MAX_VIEWS; ++i) {
        const rad_section *s = rad_container_section(ct, i);
        if (s->type != RAD_SECTION_TEMPORAL_BINS) continue;
        if (rad_alias_tables_view(ct, s->name, NULL, &views[count]) != RAD_SUCCESS || views[count].rows > FUZZ_MAX_ROWS) continue;
        use_view(&views[count], s->name);
        ++count;
    }
    if (count >= 3 && views[0].rows == views[1].rows && views[0].rows == views[2].rows) {
        const rad_alias_tables *three[3];
        uint32_t rows = views[0].rows;
        int tame = 1;
        float *E = fuzz_fill(3 * (size_t)rows, 1.0f), *out = fuzz_fill(3 * (size_t)rows, 0.0f);
        rad_temporal_options o;
        for (i = 0; i < 3; ++i) {
            three[i] = &views[i];
            tame = tame && fuzz_bounded(views[i].totals, rows, FUZZ_TAME);
        }
        rad_temporal_options_default(&o);
        o.mode = RAD_TEMPORAL_MULTIBOUNCE;
        o.samples = FUZZ_SAMPLES;
        o.adaptive = 1;
        if (E && out) steps(three, 3, &o, NULL, E, out, tame, 3);
        free(E);
        free(out);
    }
    rad_container_destroy(ct);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    void *buf = malloc(size ? size : 1);
    if (!buf) return 0;
    if (size) memcpy(buf, data, size);
    exercise(buf, size);
    fuzz_fix_checksums((unsigned char *)buf, size);
    if (size && memcmp(buf, data, size) != 0) exercise(buf, size);
    free(buf);
    return 0;
}

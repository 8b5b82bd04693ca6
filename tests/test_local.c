/* test_local.c - the local multi-bounce matrix (docs/methods/local.md): adding patches one by one against
   (I - A)^-1 - I by Gauss-Jordan in double computed here, the first-order update
   against the exact one, removal keeping the transport through the removed patch, a long
   add/remove walk bounded by the physical limit and between the rebuilt and the full-world
   transport, apply over P_Vis x P_Lit, the CSR and baked-container row sources, and bad
   input. Included by test_main.c after the implementation: every name is static and
   prefixed lc_. */
#include "fixtures.h"


/* the shared Cornell world (fixtures.h) */
typedef fx_world lc_world;

/* Cornell box of about 'target' patches with dense form factors; E = emission plus a little
   everywhere (so every column matters). */
static int lc_cornell(lc_world *w, uint32_t target)
{
    uint32_t i;
    if (!fx_cornell(w, target, 4, 0)) {
        CHECK(!"cornell setup");
        return 0;
    }
    for (i = 0; i < 3 * w->n; ++i) w->E[i] += 0.05f * (float)(i % 7);
    return 1;
}

static uint32_t lc_target(void) { return rad_test_quick() ? 90u : 200u; }

/* a parallel_for that runs the tasks in reverse order on the calling thread */
/* T = (I - A)^-1 - I on the set 'ids' (m patches), A_ij = rho_i F_ij, channel ch, by
   Gauss-Jordan with partial pivoting in double: out m*m. Returns 0 on a zero pivot. */
static int lc_reference(const lc_world *w, const uint32_t *ids, uint32_t m, uint32_t ch, double *out)
{
    double *G = (double *)malloc(sizeof(double) * 2 * (size_t)m * m);
    uint32_t i, j, k, piv, w2 = 2 * m;
    const float *F = w->ff->matrix.dense;
    if (!G) return 0;
    for (i = 0; i < m; ++i)
        for (j = 0; j < m; ++j) {
            double a = (double)w->patches->albedo[3 * (size_t)ids[i] + ch] * F[(size_t)ids[i] * w->n + ids[j]];
            G[(size_t)i * w2 + j] = (i == j ? 1.0 : 0.0) - a;
            G[(size_t)i * w2 + m + j] = i == j ? 1.0 : 0.0;
        }
    for (k = 0; k < m; ++k) {
        double best = 0.0, p;
        piv = k;
        for (i = k; i < m; ++i)
            if (fabs(G[(size_t)i * w2 + k]) > best) { best = fabs(G[(size_t)i * w2 + k]); piv = i; }
        if (best == 0.0) { free(G); return 0; }
        if (piv != k)
            for (j = 0; j < w2; ++j) { double t = G[(size_t)k * w2 + j]; G[(size_t)k * w2 + j] = G[(size_t)piv * w2 + j]; G[(size_t)piv * w2 + j] = t; }
        p = G[(size_t)k * w2 + k];
        for (j = 0; j < w2; ++j) G[(size_t)k * w2 + j] /= p;
        for (i = 0; i < m; ++i)
            if (i != k && G[(size_t)i * w2 + k] != 0.0) {
                double f = G[(size_t)i * w2 + k];
                for (j = 0; j < w2; ++j) G[(size_t)i * w2 + j] -= f * G[(size_t)k * w2 + j];
            }
    }
    for (i = 0; i < m; ++i)
        for (j = 0; j < m; ++j) out[(size_t)i * m + j] = G[(size_t)i * w2 + m + j] - (i == j ? 1.0 : 0.0);
    free(G);
    return 1;
}

/* entry (patch pi, patch pj) of channel ch of the local matrix */
static double lc_entry(const rad_local *L, uint32_t ch, uint32_t pi, uint32_t pj)
{
    size_t M = L->capacity;
    return (double)L->planes[ch * M * M + (size_t)L->patch_slot[pi] * M + L->patch_slot[pj]];
}

/* max over channels and the set of |T_local - T_ref| / max |T_ref| */
static double lc_error(const lc_world *w, const rad_local *L, const uint32_t *ids, uint32_t m)
{
    double *ref = (double *)malloc(sizeof(double) * (size_t)m * m), d = 0.0, big = 0.0;
    uint32_t ch, i, j;
    if (!ref) return 1e30;
    for (ch = 0; ch < 3; ++ch) {
        if (!lc_reference(w, ids, m, ch, ref)) { free(ref); return 1e30; }
        for (i = 0; i < m; ++i)
            for (j = 0; j < m; ++j) {
                double r = ref[(size_t)i * m + j], x = lc_entry(L, ch, ids[i], ids[j]);
                if (fabs(x - r) > d) d = fabs(x - r);
                if (fabs(r) > big) big = fabs(r);
            }
    }
    free(ref);
    return big > 0.0 ? d / big : d;
}

static void lc_shuffle(uint32_t *ids, uint32_t n, uint32_t seed)
{
    uint32_t i;
    for (i = 0; i < n; ++i) ids[i] = i;
    for (i = n; i > 1; --i) {
        uint32_t j = rad__hash(seed + i) % i, t = ids[i - 1];
        ids[i - 1] = ids[j];
        ids[j] = t;
    }
}

static int lc_source(const lc_world *w, rad_row_source *src)
{
    rad_result r = rad_row_source_matrix(&w->ff->matrix, w->patches->areas, w->patches->albedo, src);
    CHECK_OK(r);
    return r == RAD_SUCCESS;
}

/* ---------------------------------------------------------------------------------------- */

/* Adding every patch one by one from empty reproduces (I - A)^-1 - I; the first-order
   update (RAD_LOCAL_FIRST_ORDER) lands measurably further away. */
static void test_local_add_exact_and_first_order(void)
{
    lc_world w;
    rad_row_source src;
    rad_local_options o;
    rad_local *ex = NULL, *fo = NULL, *rb = NULL, *tk = NULL, *rn = NULL;
    rad_context ctx;
    uint32_t *ids, i;
    double e_ex, e_fo, e_rb, e_rn;
    if (!lc_cornell(&w, lc_target())) return;
    ids = (uint32_t *)malloc(sizeof(uint32_t) * w.n);
    if (!ids || !lc_source(&w, &src)) { free(ids); fx_world_free(&w); return; }
    lc_shuffle(ids, w.n, 11u);
    rad_local_options_default(&o);
    o.capacity = w.n;
    CHECK_OK(rad_local_create(&src, &o, NULL, &ex));
    CHECK_OK(rad_local_create(&src, &o, NULL, &rb));
    CHECK_OK(rad_local_create(&src, &o, NULL, &tk));
    o.rebuild = RAD_LOCAL_REBUILD_NEUMANN;
    CHECK_OK(rad_local_create(&src, &o, NULL, &rn));
    o.rebuild = RAD_LOCAL_REBUILD_INVERSE;
    o.update = RAD_LOCAL_FIRST_ORDER;
    CHECK_OK(rad_local_create(&src, &o, NULL, &fo));
    memset(&ctx, 0, sizeof(ctx));
    ctx.parallel_for = fx_reverse_for;
    ctx.task_count = 5;
    if (ex && fo && rb && tk && rn) {
        for (i = 0; i < w.n; ++i) {
            CHECK_OK(rad_local_add(ex, ids[i], NULL));
            CHECK_OK(rad_local_add(fo, ids[i], NULL));
            CHECK_OK(rad_local_add(tk, ids[i], &ctx));
        }
        /* split into tasks in another order: the same bits */
        CHECK(memcmp(ex->planes, tk->planes, sizeof(float) * 3 * (size_t)w.n * w.n) == 0);
        CHECK(ex->count == w.n && ex->slot_end == w.n);
        CHECK_OK(rad_local_rebuild(rb, ids, w.n, NULL));
        CHECK_OK(rad_local_rebuild(rn, ids, w.n, NULL));
        e_ex = lc_error(&w, ex, ids, w.n);
        e_fo = lc_error(&w, fo, ids, w.n);
        e_rb = lc_error(&w, rb, ids, w.n);
        e_rn = lc_error(&w, rn, ids, w.n);
        printf("    N = %u: exact add %.3g, first-order %.3g, rebuild: blocked inverse %.3g, Neumann %.3g "
               "(max |T - T_ref| / max T_ref)\n", w.n, e_ex, e_fo, e_rb, e_rn);
        CHECK(e_ex < 1e-4);
        CHECK(e_rb < 1e-4);
        CHECK(e_rn < 1e-4);
        CHECK(e_fo > 0.01);        /* the first-order form misses the return paths */
        CHECK(e_fo > 100.0 * e_ex);
    }
    rad_local_destroy(ex);
    rad_local_destroy(fo);
    rad_local_destroy(rb);
    rad_local_destroy(tk);
    rad_local_destroy(rn);
    free(ids);
    fx_world_free(&w);
}

/* Removing hides a patch and keeps T exactly; evicting it by the downdate gives the inverse
   without it; the drop (RAD_LOCAL_EVICT_DROP) keeps the block of the inverse with it (the paths through it). */
static void test_local_remove_and_evict(void)
{
    lc_world w;
    rad_row_source src;
    rad_local_options o;
    rad_local *L = NULL, *D = NULL;
    uint32_t *ids, i, j, m, gone = 0, slot, mode;
    double *with, *without, dkeep = 0.0, ddown = 0.0, ddrop = 0.0, dpaths = 0.0, big = 0.0;
    float *before = NULL, *out = NULL;
    size_t planes;
    if (!lc_cornell(&w, rad_test_quick() ? 60u : 120u)) return;
    m = w.n < 60 ? w.n : 60;
    planes = 3 * (size_t)m * m;
    ids = (uint32_t *)malloc(sizeof(uint32_t) * w.n);
    with = (double *)malloc(sizeof(double) * m * m);
    without = (double *)malloc(sizeof(double) * m * m);
    before = (float *)malloc(sizeof(float) * planes);
    out = (float *)malloc(sizeof(float) * 3 * w.n);
    if (!ids || !with || !without || !before || !out || !lc_source(&w, &src)) goto out;
    lc_shuffle(ids, w.n, 5u);
    /* the largest patch of the set goes: many paths run through it */
    for (i = 1; i < m; ++i)
        if (w.patches->areas[ids[i]] > w.patches->areas[ids[gone]]) gone = i;
    { uint32_t t = ids[m - 1]; ids[m - 1] = ids[gone]; ids[gone] = t; gone = ids[m - 1]; }
    CHECK(lc_reference(&w, ids, m, 1, with));
    CHECK(lc_reference(&w, ids, m - 1, 1, without));
    for (mode = 0; mode < 2; ++mode) {
        rad_local *X = NULL;
        rad_local_options_default(&o);
        o.capacity = m;
        o.evict = mode ? RAD_LOCAL_EVICT_DROP : RAD_LOCAL_EVICT_DOWNDATE;
        CHECK_OK(rad_local_create(&src, &o, NULL, &X));
        if (!X) break;
        if (mode) D = X; else L = X;
        for (i = 0; i < m; ++i) CHECK_OK(rad_local_add(X, ids[i], NULL));
        memcpy(before, X->planes, sizeof(float) * planes);
        slot = X->patch_slot[gone];
        CHECK_OK(rad_local_remove(X, gone, NULL));
        CHECK(X->count == m - 1 && X->hidden == 1 && X->slot_hidden[slot] == 1 && X->patch_slot[gone] == slot);
        CHECK(memcmp(before, X->planes, sizeof(float) * planes) == 0); /* hiding changes nothing in T */
        CHECK_RESULT(rad_local_remove(X, gone, NULL), RAD_ERROR_INVALID_ARGUMENT);
        /* the default rows skip it; as an explicit lit patch it still counts */
        for (i = 0; i < 3 * w.n; ++i) out[i] = -1.0f;
        CHECK_OK(rad_local_apply(X, w.E, NULL, 0, NULL, 0, out, RAD_OUTPUT_INDIRECT, NULL));
        CHECK(out[3 * (size_t)gone] == -1.0f && out[3 * (size_t)ids[0]] >= 0.0f);
        CHECK_OK(rad_local_apply(X, w.E, &gone, 1, &gone, 1, out, RAD_OUTPUT_INDIRECT, NULL));
        /* showing it again restores it exactly; then evict */
        CHECK_OK(rad_local_add(X, gone, NULL));
        CHECK(X->hidden == 0 && X->count == m && memcmp(before, X->planes, sizeof(float) * planes) == 0);
        CHECK_OK(rad_local_evict(X, gone, NULL));
        CHECK(X->count == m - 1 && X->patch_slot[gone] == RAD_NONE && X->slot_patch[slot] == RAD_NONE);
        for (i = 0; i < m; ++i) {
            CHECK(X->planes[(size_t)m * m + (size_t)slot * m + i] == 0.0f);
            CHECK(X->planes[(size_t)m * m + (size_t)i * m + slot] == 0.0f);
        }
        for (i = 0; i + 1 < m; ++i)
            for (j = 0; j + 1 < m; ++j) {
                double x = lc_entry(X, 1, ids[i], ids[j]), wi = with[(size_t)i * m + j], wo = without[(size_t)i * (m - 1) + j];
                if (mode == 0 && fabs(x - wo) > ddown) ddown = fabs(x - wo);
                if (mode == 1 && fabs(x - wi) > ddrop) ddrop = fabs(x - wi);
                if (fabs(wi - wo) > dpaths) dpaths = fabs(wi - wo);
                if (fabs(wi) > big) big = fabs(wi);
            }
        /* the slot is reused by the next add */
        CHECK_OK(rad_local_add(X, gone, NULL));
        CHECK(X->patch_slot[gone] == slot);
    }
    (void)dkeep;
    printf("    evicting the largest patch: downdate vs inverse without it %.2g, drop vs block with it %.2g; paths through it %.3g "
           "(max T %.3g)\n", ddown, ddrop, dpaths, big);
    CHECK(ddown <= 1e-5 * big);
    CHECK(ddrop <= 1e-5 * big);
    CHECK(dpaths > 1e-5 * big && dpaths > 100.0 * (ddown > ddrop ? ddown : ddrop));
out:
    rad_local_destroy(L);
    rad_local_destroy(D);
    free(ids); free(with); free(without); free(before); free(out);
    fx_world_free(&w);
}

/* the 'count' patches nearest (px, py, pz), by selection with ties by index, into want */
static void lc_nearest(const lc_world *w, float px, float py, float pz, uint32_t count, uint32_t *want)
{
    float *d2 = (float *)malloc(sizeof(float) * w->n);
    uint32_t i, j;
    for (i = 0; i < w->n; ++i) want[i] = i;
    if (!d2) return;
    for (i = 0; i < w->n; ++i) {
        const float *cc = w->patches->patches[i].centroid;
        d2[i] = (cc[0] - px) * (cc[0] - px) + (cc[1] - py) * (cc[1] - py) + (cc[2] - pz) * (cc[2] - pz);
    }
    for (i = 0; i < count; ++i)
        for (j = i + 1; j < w->n; ++j)
            if (d2[want[j]] < d2[want[i]] || (d2[want[j]] == d2[want[i]] && want[j] < want[i])) { uint32_t t = want[i]; want[i] = want[j]; want[j] = t; }
    free(d2);
}

/* moves the visible set to 'want' (count patches): removes what left, adds what came */
static void lc_move(rad_local *L, const uint32_t *want, uint32_t count, uint32_t n, uint32_t *inset, rad_result *first_error)
{
    uint32_t i;
    rad_result r;
    for (i = 0; i < n; ++i) inset[i] = 0;
    for (i = 0; i < count; ++i) inset[want[i]] = 1;
    for (i = 0; i < n; ++i)
        if (L->patch_slot[i] != RAD_NONE && !L->slot_hidden[L->patch_slot[i]] && !inset[i]) rad_local_remove(L, i, NULL);
    for (i = 0; i < count; ++i)
        if (L->patch_slot[want[i]] == RAD_NONE || L->slot_hidden[L->patch_slot[want[i]]]) {
            r = rad_local_add(L, want[i], NULL);
            if (r != RAD_SUCCESS && *first_error == RAD_SUCCESS) *first_error = r;
        }
}

static double lc_max_row_sum(const rad_local *L)
{
    double worst = 0.0;
    uint32_t ch, i, j, M = L->capacity;
    for (ch = 0; ch < 3; ++ch)
        for (i = 0; i < L->slot_end; ++i) {
            double s = 0.0;
            for (j = 0; j < L->slot_end; ++j) s += L->planes[(size_t)ch * M * M + (size_t)i * M + j];
            if (s > worst) worst = s;
        }
    return worst;
}

/* A camera walk: the visible set is the V patches nearest a moving point, with room for
   hidden members. After every step T is exactly the transport over the members (checked at
   the end against Gauss-Jordan), row sums stay under rho_max / (1 - rho_max), and on the
   visible set T lies between the transport of that set alone (rebuild) and the full-world
   transport, so it is closer to the full solution than a rebuild. */
static void test_local_walk_bounded(void)
{
    lc_world w;
    rad_row_source src;
    rad_local_options o;
    rad_local *L = NULL, *R = NULL;
    uint32_t *ids = NULL, *want = NULL, *inset = NULL, *members = NULL, i, j, step, steps = rad_test_quick() ? 10u : 40u, V, m = 0, ch;
    double *full = NULL, rho_max = 0.0, bound, worst_row = 0.0, below = 0.0, above = 0.0, big = 0.0, err;
    float *Lw = NULL, *Lr = NULL;
    rad_result first = RAD_SUCCESS;
    if (!lc_cornell(&w, rad_test_quick() ? 90u : 200u)) return;
    V = w.n / 2;
    ids = (uint32_t *)malloc(sizeof(uint32_t) * w.n);
    want = (uint32_t *)malloc(sizeof(uint32_t) * w.n);
    members = (uint32_t *)malloc(sizeof(uint32_t) * w.n);
    inset = (uint32_t *)calloc(w.n, sizeof(uint32_t));
    full = (double *)malloc(sizeof(double) * w.n * w.n * 3);
    Lw = (float *)malloc(sizeof(float) * 3 * w.n);
    Lr = (float *)malloc(sizeof(float) * 3 * w.n);
    if (!ids || !want || !members || !inset || !full || !Lw || !Lr || !lc_source(&w, &src)) goto out;
    for (i = 0; i < w.n; ++i) ids[i] = i;
    for (ch = 0; ch < 3; ++ch) CHECK(lc_reference(&w, ids, w.n, ch, full + (size_t)ch * w.n * w.n));
    for (i = 0; i < 3 * w.n; ++i) if (w.patches->albedo[i] > rho_max) rho_max = w.patches->albedo[i];
    bound = rho_max / (1.0 - rho_max);
    rad_local_options_default(&o);
    o.capacity = V + V / 4;
    CHECK_OK(rad_local_create(&src, &o, NULL, &L));
    CHECK_OK(rad_local_create(&src, &o, NULL, &R));
    if (!L || !R) goto out;
    for (step = 0; step < steps; ++step) {
        float ang = 6.2831853f * (float)step / (float)steps;
        uint32_t kept = L->count;
        lc_nearest(&w, 0.278f + 0.35f * (float)cos(ang), 0.27f, 0.28f + 0.35f * (float)sin(ang), V, want);
        lc_move(L, want, V, w.n, inset, &first);
        CHECK(L->count == V);
        CHECK(kept == (step ? V : 0));
        if (lc_max_row_sum(L) > worst_row) worst_row = lc_max_row_sum(L);
    }
    CHECK_OK(first);
    CHECK(L->evictions > 0 && L->hidden > 0);
    for (i = 0; i < L->slot_end; ++i)
        if (L->slot_patch[i] != RAD_NONE) members[m++] = L->slot_patch[i];
    err = lc_error(&w, L, members, m);
    /* sandwich on the visible set: rebuild(V) <= T <= full(V, V) */
    CHECK_OK(rad_local_rebuild(R, want, V, NULL));
    for (ch = 0; ch < 3; ++ch)
        for (i = 0; i < V; ++i)
            for (j = 0; j < V; ++j) {
                uint32_t a = want[i], b = want[j];
                double t = lc_entry(L, ch, a, b), f = full[(size_t)ch * w.n * w.n + (size_t)a * w.n + b], r = lc_entry(R, ch, a, b);
                if (f > big) big = f;
                if (t - f > above) above = t - f;
                if (r - t > below) below = r - t;
            }
    printf("    V = %u of %u, capacity %u, %u steps, %llu evictions: T vs the members' inverse %.2g, max row sum %.4f (bound %.4f), "
           "T - full %.2g, rebuild - T %.2g (max %.3g)\n", V, w.n, o.capacity, steps, (unsigned long long)L->evictions, err,
           worst_row, bound, above, below, big);
    CHECK(err <= 1e-4);
    CHECK(worst_row <= bound * (1.0 + 1e-5));
    CHECK(above <= 1e-4 * big);
    CHECK(below <= 1e-4 * big);
    /* L over the visible set from the visible sources, against the full-world transport */
    CHECK_OK(rad_local_apply(L, w.E, want, V, want, V, Lw, RAD_OUTPUT_INDIRECT, NULL));
    CHECK_OK(rad_local_apply(R, w.E, want, V, want, V, Lr, RAD_OUTPUT_INDIRECT, NULL));
    {
        double ew = 0.0, er = 0.0, nf = 0.0;
        for (ch = 0; ch < 3; ++ch)
            for (i = 0; i < V; ++i) {
                double f = 0.0;
                uint32_t a = want[i];
                for (j = 0; j < V; ++j) f += full[(size_t)ch * w.n * w.n + (size_t)a * w.n + want[j]] * w.E[3 * (size_t)want[j] + ch];
                ew += (Lw[3 * (size_t)a + ch] - f) * (Lw[3 * (size_t)a + ch] - f);
                er += (Lr[3 * (size_t)a + ch] - f) * (Lr[3 * (size_t)a + ch] - f);
                nf += f * f;
            }
        printf("    L on the visible set vs the full-world transport of the same sources: walk %.4f, rebuild %.4f (relative L2)\n",
               sqrt(ew / nf), sqrt(er / nf));
        CHECK(ew < er);
    }
out:
    rad_local_destroy(L);
    rad_local_destroy(R);
    free(ids); free(want); free(members); free(inset); free(full); free(Lw); free(Lr);
    fx_world_free(&w);
}

/* A camera going back and forth between two ends of the box. With the exact downdate the
   row sums stay under the bound for every round trip; the drop (RAD_LOCAL_EVICT_DROP) counts the paths of
   each patch that re-enters once more and passes the bound (then s <= 0: SINGULAR). */
static void test_local_back_and_forth(void)
{
    lc_world w;
    rad_row_source src;
    rad_local_options o;
    rad_local *L = NULL;
    uint32_t *want = NULL, *inset = NULL, i, V, mode, step, steps = rad_test_quick() ? 18u : 40u;
    double rho_max = 0.0, bound;
    if (!lc_cornell(&w, rad_test_quick() ? 90u : 200u)) return;
    V = w.n * 6 / 10;
    want = (uint32_t *)malloc(sizeof(uint32_t) * 2 * w.n);
    inset = (uint32_t *)malloc(sizeof(uint32_t) * w.n);
    if (!want || !inset || !lc_source(&w, &src)) goto out;
    for (i = 0; i < 3 * w.n; ++i) if (w.patches->albedo[i] > rho_max) rho_max = w.patches->albedo[i];
    bound = rho_max / (1.0 - rho_max);
    lc_nearest(&w, 0.0f, 0.27f, 0.28f, V, want);
    lc_nearest(&w, 0.55f, 0.27f, 0.28f, V, want + w.n);
    for (mode = 0; mode < 2; ++mode) {
        double worst = 0.0;
        uint32_t passed = 0;
        rad_result first = RAD_SUCCESS;
        rad_local_options_default(&o);
        o.capacity = V;
        o.evict = mode ? RAD_LOCAL_EVICT_DROP : RAD_LOCAL_EVICT_DOWNDATE;
        CHECK_OK(rad_local_create(&src, &o, NULL, &L));
        if (!L) break;
        for (step = 0; step < steps && first == RAD_SUCCESS; ++step) {
            double rs;
            lc_move(L, want + (step & 1u) * w.n, V, w.n, inset, &first);
            rs = lc_max_row_sum(L);
            if (rs > worst) worst = rs;
            if (!passed && rs > bound) passed = step + 1;
        }
        printf("    %s: %u trips, largest row sum %.3f (bound %.3f), first above the bound at trip %u (0: never)%s\n",
               mode ? "drop (seed)" : "downdate", step, worst, bound, passed, first != RAD_SUCCESS ? ", then SINGULAR" : "");
        if (mode == 0) {
            CHECK_OK(first);
            CHECK(worst <= bound * (1.0 + 1e-5));
        } else
            CHECK(passed > 0 || first == RAD_ERROR_SINGULAR);
        rad_local_destroy(L);
        L = NULL;
    }
out:
    rad_local_destroy(L);
    free(want);
    free(inset);
    fx_world_free(&w);
}

/* apply over P_Vis x P_Lit against the planes summed here; TOTAL adds E; untouched rows */
static void test_local_apply_subsets(void)
{
    lc_world w;
    rad_row_source src;
    rad_local_options o;
    rad_local *L = NULL;
    uint32_t vis[10], lit[20], i, j, ch, nv = 0, nl = 0, *ids = NULL;
    float *out = NULL, *tot = NULL;
    if (!lc_cornell(&w, 60u)) return;
    if (w.n < 64) { CHECK(w.n >= 64); fx_world_free(&w); return; }
    out = (float *)malloc(sizeof(float) * 3 * w.n);
    tot = (float *)malloc(sizeof(float) * 3 * w.n);
    ids = (uint32_t *)malloc(sizeof(uint32_t) * w.n);
    if (!out || !tot || !ids || !lc_source(&w, &src)) goto out;
    rad_local_options_default(&o);
    o.capacity = 40;
    CHECK_OK(rad_local_create(&src, &o, NULL, &L));
    if (!L) goto out;
    lc_shuffle(ids, w.n, 3u);
    for (i = 0; i < 40; ++i) CHECK_OK(rad_local_add(L, ids[i], NULL));
    for (i = 0; i < 10; ++i) vis[nv++] = ids[3 * i];
    for (i = 0; i < 20; ++i) lit[nl++] = ids[2 * i + 1];
    for (i = 0; i < 3 * w.n; ++i) out[i] = tot[i] = -1.0f;
    CHECK_OK(rad_local_apply(L, w.E, vis, nv, lit, nl, out, RAD_OUTPUT_INDIRECT, NULL));
    CHECK_OK(rad_local_apply(L, w.E, vis, nv, lit, nl, tot, RAD_OUTPUT_TOTAL, NULL));
    for (i = 0; i < nv; ++i)
        for (ch = 0; ch < 3; ++ch) {
            double s = 0.0;
            for (j = 0; j < nl; ++j) s += lc_entry(L, ch, vis[i], lit[j]) * w.E[3 * (size_t)lit[j] + ch];
            CHECK_NEAR(out[3 * (size_t)vis[i] + ch], s, 1e-5 * (fabs(s) + 1e-3));
            CHECK_NEAR(tot[3 * (size_t)vis[i] + ch], s + w.E[3 * (size_t)vis[i] + ch], 1e-5 * (fabs(s) + 1.0));
        }
    CHECK(out[3 * (size_t)ids[1]] == -1.0f); /* not visible: untouched */
    /* errors */
    vis[0] = ids[50]; /* not in the set */
    CHECK_RESULT(rad_local_apply(L, w.E, vis, nv, lit, nl, out, RAD_OUTPUT_INDIRECT, NULL), RAD_ERROR_INDEX_OUT_OF_RANGE);
    CHECK_RESULT(rad_local_apply(L, w.E, NULL, 0, NULL, 0, out, (rad_output)7, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_local_add(L, ids[7], NULL), RAD_ERROR_INVALID_ARGUMENT);     /* already there */
    CHECK_RESULT(rad_local_add(L, ids[50], NULL), RAD_ERROR_INVALID_ARGUMENT);    /* full */
    CHECK_RESULT(rad_local_add(L, w.n, NULL), RAD_ERROR_INDEX_OUT_OF_RANGE);
    CHECK_RESULT(rad_local_remove(L, ids[50], NULL), RAD_ERROR_INVALID_ARGUMENT); /* not there */
    CHECK_RESULT(rad_local_evict(L, ids[50], NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_local_remove(L, w.n + 5, NULL), RAD_ERROR_INDEX_OUT_OF_RANGE);
out:
    rad_local_destroy(L);
    free(out);
    free(tot);
    free(ids);
    fx_world_free(&w);
}

/* a two-patch world with a configurable row for bad-input tests */
typedef struct lc_toy { float F[4]; int fail; } lc_toy;

static rad_result lc_toy_fetch(void *user, uint32_t row, uint32_t capacity, uint32_t *cols, float *vals, uint32_t *count)
{
    lc_toy *t = (lc_toy *)user;
    (void)capacity;
    if (t->fail) return RAD_ERROR_IO;
    cols[0] = 1 - row;
    vals[0] = t->F[row * 2 + 1 - row];
    *count = 1;
    return RAD_SUCCESS;
}

static void test_local_bad_input(void)
{
    lc_toy toy;
    float areas[2] = {1.0f, 1.0f}, albedo[6] = {0.99f, 0.99f, 0.99f, 0.99f, 0.99f, 0.99f};
    rad_row_source src;
    rad_local_options o;
    rad_local *L = NULL;
    memset(&toy, 0, sizeof(toy));
    toy.F[1] = toy.F[2] = 1.5f; /* row sums 1.5: s = 1 - 0.99^2 * 2.25 < 0 */
    memset(&src, 0, sizeof(src));
    src.n = 2; src.areas = areas; src.albedo = albedo; src.fetch = lc_toy_fetch; src.user = &toy;
    rad_local_options_default(&o);
    o.capacity = 2;
    CHECK_RESULT(rad_local_create(NULL, &o, NULL, &L), RAD_ERROR_INVALID_ARGUMENT);
    o.capacity = 3; /* more than the n = 2 patches: taken as 2 */
    CHECK_OK(rad_local_create(&src, &o, NULL, &L));
    if (L) CHECK(L->capacity == 2);
    rad_local_destroy(L);
    L = NULL;
    o.rebuild = (rad_local_rebuild_method)2;
    CHECK_RESULT(rad_local_create(&src, &o, NULL, &L), RAD_ERROR_INVALID_ARGUMENT);
    o.rebuild = RAD_LOCAL_REBUILD_INVERSE;
    o.capacity = 2;
    albedo[4] = 1.0f;
    CHECK_RESULT(rad_local_create(&src, &o, NULL, &L), RAD_ERROR_ALBEDO_RANGE);
    albedo[4] = 0.99f;
    areas[1] = 0.0f;
    CHECK_RESULT(rad_local_create(&src, &o, NULL, &L), RAD_ERROR_INVALID_ARGUMENT);
    areas[1] = 1.0f;
    CHECK_OK(rad_local_create(&src, &o, NULL, &L));
    if (!L) return;
    CHECK_OK(rad_local_add(L, 0, NULL));
    CHECK_RESULT(rad_local_add(L, 1, NULL), RAD_ERROR_SINGULAR);
    CHECK(L->count == 1);
    toy.F[1] = toy.F[2] = -0.5f;
    CHECK_RESULT(rad_local_add(L, 1, NULL), RAD_ERROR_NON_FINITE);
    toy.fail = 1;
    CHECK_RESULT(rad_local_add(L, 1, NULL), RAD_ERROR_IO);
    toy.fail = 0;
    toy.F[1] = toy.F[2] = 0.5f;
    CHECK_OK(rad_local_add(L, 1, NULL));
    /* two patches facing each other: T_01 = a / (1 - a^2) - ... closed form of the 2x2 inverse */
    {
        double a = 0.99 * 0.5, det = 1.0 - a * a;
        CHECK_NEAR(L->planes[(size_t)L->patch_slot[0] * 2 + L->patch_slot[1]], a / det, 1e-6);
        CHECK_NEAR(L->planes[(size_t)L->patch_slot[0] * 2 + L->patch_slot[0]], 1.0 / det - 1.0, 1e-6);
    }
    rad_local_destroy(L);
}

/* rows from a CSR matrix and from a baked container opened in place give the same T as the
   dense matrix */
static void test_local_row_sources(void)
{
    lc_world w;
    rad_row_source sd, ss, sb;
    rad_local_options o;
    rad_local *Ld = NULL, *Ls = NULL, *Lb = NULL;
    rad_form_factors *sp = NULL;
    rad_form_factor_options fo;
    rad_raycaster rc;
    rad_bake *bake = NULL;
    void *buf = NULL;
    size_t size = 0, i, planes;
    uint32_t p;
    double d1 = 0.0, d2 = 0.0;
    if (!lc_cornell(&w, 70u)) return;
    rad_form_factor_options_default(&fo);
    fo.samples = 4;
    rad_bvh_raycaster(w.bvh, &rc);
    CHECK_OK(rad_form_factors_sparse(w.patches, &rc, &fo, NULL, &sp));
    if (!sp) { fx_world_free(&w); return; }
    CHECK_OK(rad_save_memory(w.patches, &sp->matrix, w.E, NULL, NULL, &buf, &size));
    if (buf) CHECK_OK(rad_load_memory(buf, size, NULL, &bake));
    CHECK(lc_source(&w, &sd));
    CHECK_OK(rad_row_source_matrix(&sp->matrix, w.patches->areas, w.patches->albedo, &ss));
    if (bake) CHECK_OK(rad_row_source_bake(bake, &sb));
    rad_local_options_default(&o);
    o.capacity = w.n / 2;
    CHECK_OK(rad_local_create(&sd, &o, NULL, &Ld));
    CHECK_OK(rad_local_create(&ss, &o, NULL, &Ls));
    if (bake) CHECK_OK(rad_local_create(&sb, &o, NULL, &Lb));
    if (Ld && Ls && Lb) {
        for (p = 0; p < o.capacity; ++p) {
            CHECK_OK(rad_local_add(Ld, (p * 5) % w.n, NULL));
            CHECK_OK(rad_local_add(Ls, (p * 5) % w.n, NULL));
            CHECK_OK(rad_local_add(Lb, (p * 5) % w.n, NULL));
        }
        planes = 3 * (size_t)o.capacity * o.capacity;
        for (i = 0; i < planes; ++i) {
            if (fabs((double)Ld->planes[i] - Ls->planes[i]) > d1) d1 = fabs((double)Ld->planes[i] - Ls->planes[i]);
            if (fabs((double)Ls->planes[i] - Lb->planes[i]) > d2) d2 = fabs((double)Ls->planes[i] - Lb->planes[i]);
        }
        CHECK(d1 <= 1e-6);
        CHECK(d2 == 0.0);
        CHECK(rad_local_memory(Lb) >= planes * sizeof(float));
    }
    CHECK_RESULT(rad_row_source_bake(NULL, &sb), RAD_ERROR_INVALID_ARGUMENT);
#ifndef RAD_NO_STDIO
    /* the same rows streamed from a file: same planes; a damaged file is refused */
    if (Ls && buf) {
        const char *path = rad_test_path("local_stream.radb");
        FILE *f = fopen(path, "wb");
        rad_row_stream *st = NULL;
        rad_row_source sf;
        rad_local *Lf = NULL;
        int wrote = f && fwrite(buf, 1, size, f) == size;
        if (f) fclose(f);
        CHECK(wrote);
        CHECK_OK(rad_row_stream_create(path, NULL, &st));
        if (st) {
            rad_row_stream_source(st, &sf);
            CHECK(sf.n == w.n && rad_row_stream_memory(st) < 64u * w.n);
            CHECK_OK(rad_local_create(&sf, &o, NULL, &Lf));
            if (Lf) {
                for (p = 0; p < o.capacity; ++p) CHECK_OK(rad_local_add(Lf, (p * 5) % w.n, NULL));
                CHECK(memcmp(Lf->planes, Ls->planes, sizeof(float) * 3 * (size_t)o.capacity * o.capacity) == 0);
            }
            rad_local_destroy(Lf);
            rad_row_stream_destroy(st);
        }
        /* truncated, then a flipped byte in the row offsets' region of the header table */
        f = fopen(path, "wb");
        if (f) { fwrite(buf, 1, size / 2, f); fclose(f); }
        CHECK_RESULT(rad_row_stream_create(path, NULL, &st), RAD_ERROR_TRUNCATED);
        ((unsigned char *)buf)[70] ^= 1u;
        f = fopen(path, "wb");
        if (f) { fwrite(buf, 1, size, f); fclose(f); }
        CHECK_RESULT(rad_row_stream_create(path, NULL, &st), RAD_ERROR_CORRUPT);
        ((unsigned char *)buf)[70] ^= 1u;
        remove(path);
        CHECK_RESULT(rad_row_stream_create(path, NULL, &st), RAD_ERROR_IO);
        CHECK(st == NULL);
    }
#endif
    rad_local_destroy(Ld);
    rad_local_destroy(Ls);
    rad_local_destroy(Lb);
    rad_bake_destroy(bake);
    rad_free_buffer(buf, NULL);
    rad_form_factors_destroy(sp);
    fx_world_free(&w);
}


/* a row that names a column twice: from a user's source and from a streamed bake whose
   column bytes were edited (the stream does not checksum the matrix sections). Before the
   check a repeat of a member column overflowed the scratch of member slots. */
typedef struct lc_rep { uint32_t n, repeat; } lc_rep;

static rad_result lc_rep_fetch(void *user, uint32_t row, uint32_t capacity, uint32_t *cols, float *vals, uint32_t *count)
{
    lc_rep *t = (lc_rep *)user;
    uint32_t j, k = 0;
    for (j = 0; j < t->n && k < capacity; ++j) {
        if (j == row) continue;
        cols[k] = j;
        vals[k++] = 0.1f;
    }
    if (t->repeat && row == 3 && k >= 2) cols[1] = cols[0]; /* column 0 twice */
    *count = k;
    return RAD_SUCCESS;
}

static void test_local_repeated_columns(void)
{
    float areas[6] = {1, 1, 1, 1, 1, 1}, albedo[18];
    lc_rep rep = {6u, 1u};
    rad_row_source src;
    rad_local_options o;
    rad_local *L = NULL;
    uint32_t i;
    for (i = 0; i < 18; ++i) albedo[i] = 0.5f;
    memset(&src, 0, sizeof(src));
    src.n = 6; src.areas = areas; src.albedo = albedo; src.fetch = lc_rep_fetch; src.user = &rep;
    rad_local_options_default(&o);
    o.capacity = 2;
    CHECK_OK(rad_local_create(&src, &o, NULL, &L));
    if (L) {
        CHECK_OK(rad_local_add(L, 0, NULL));
        CHECK_RESULT(rad_local_add(L, 3, NULL), RAD_ERROR_CORRUPT);
        CHECK(L->count == 1 && L->patch_slot[3] == RAD_NONE);
        /* the refused row left no marks behind: the same row without the repeat is taken */
        rep.repeat = 0;
        CHECK_OK(rad_local_add(L, 3, NULL));
        CHECK(L->count == 2);
    }
    rad_local_destroy(L);
#ifndef RAD_NO_STDIO
    {
        lc_world w;
        rad_form_factors *sp = NULL;
        rad_form_factor_options fo;
        rad_raycaster rc;
        void *buf = NULL;
        size_t size = 0;
        const char *path = rad_test_path("local_repeat.radb");
        if (!lc_cornell(&w, 70u)) return;
        rad_form_factor_options_default(&fo);
        fo.samples = 2;
        rad_bvh_raycaster(w.bvh, &rc);
        CHECK_OK(rad_form_factors_sparse(w.patches, &rc, &fo, NULL, &sp));
        if (sp) CHECK_OK(rad_save_memory(w.patches, &sp->matrix, NULL, NULL, NULL, &buf, &size));
        if (buf) {
            unsigned char *b = (unsigned char *)buf;
            uint32_t n = rad__get32(b + 8), k, row = 5, e0 = (uint32_t)sp->matrix.row_offsets[row],
                     e1 = (uint32_t)sp->matrix.row_offsets[row + 1];
            uint64_t col_at = 0, val_at = 0;
            int mode;
            for (k = 0; k < n; ++k) {
                const unsigned char *e = b + 64 + 64 * (size_t)k;
                if (rad__get32(e) == RAD_SECTION_FF_COLUMNS) col_at = rad__get64(e + 16);
                if (rad__get32(e) == RAD_SECTION_FF_VALUES) val_at = rad__get64(e + 16);
            }
            CHECK(col_at != 0 && val_at != 0 && e1 >= e0 + 2);
            /* mode 0: row 5 names one member column twice; 1: columns out of order; 2: a NaN */
            for (mode = 0; mode < 3 && col_at && val_at && e1 >= e0 + 2; ++mode) {
                unsigned char *copy = (unsigned char *)malloc(size);
                FILE *f;
                rad_row_stream *st = NULL;
                rad_row_source sf;
                rad_local *Lf = NULL;
                int wrote;
                if (!copy) break;
                memcpy(copy, buf, size);
                if (mode == 0) for (k = e0; k < e1; ++k) memcpy(copy + col_at + 4 * (size_t)k, b + col_at + 4 * (size_t)e0, 4);
                if (mode == 1) {
                    memcpy(copy + col_at + 4 * (size_t)e0, b + col_at + 4 * (size_t)(e0 + 1), 4);
                    memcpy(copy + col_at + 4 * (size_t)(e0 + 1), b + col_at + 4 * (size_t)e0, 4);
                }
                if (mode == 2) memset(copy + val_at + 4 * (size_t)e0, 0xFF, 4); /* a NaN bit pattern */
                f = fopen(path, "wb");
                wrote = f && fwrite(copy, 1, size, f) == size;
                if (f) fclose(f);
                free(copy);
                CHECK(wrote);
                CHECK_OK(rad_row_stream_create(path, NULL, &st));
                if (st) {
                    rad_row_stream_source(st, &sf);
                    rad_local_options_default(&o);
                    o.capacity = 2;
                    CHECK_OK(rad_local_create(&sf, &o, NULL, &Lf));
                    if (Lf) {
                        uint32_t first = rad__get32(b + col_at + 4 * (size_t)e0);
                        CHECK_OK(rad_local_add(Lf, first, NULL));
                        CHECK_RESULT(rad_local_add(Lf, row, NULL), RAD_ERROR_CORRUPT);
                        CHECK(Lf->count == 1);
                    }
                    rad_local_destroy(Lf);
                    rad_row_stream_destroy(st);
                }
                remove(path);
            }
        }
        rad_free_buffer(buf, NULL);
        rad_form_factors_destroy(sp);
        fx_world_free(&w);
    }
#endif
}

/* nearest-M against a brute-force count, P_Vis against per-pixel camera rays (every patch a
   pixel hits is visible; a patch behind the camera or facing away never is), P_Lit */
static void test_local_sets(void)
{
    lc_world w;
    rad_scene_desc desc;
    rad_camera cam;
    rad_raycaster rc;
    uint32_t *near = NULL, *all = NULL, *vis = NULL, *lit = NULL, *seen = NULL, i, j, nv = 0, nl = 0, M, W = 48, H = 48;
    float pos[3] = {0.3f, 0.2f, 0.25f};
    if (!lc_cornell(&w, rad_test_quick() ? 100u : 150u)) return;
    rad_cornell_box(&desc, &cam);
    rad_bvh_raycaster(w.bvh, &rc);
    M = w.n / 3;
    near = (uint32_t *)malloc(sizeof(uint32_t) * w.n);
    all = (uint32_t *)calloc(w.n, sizeof(uint32_t));
    vis = (uint32_t *)malloc(sizeof(uint32_t) * w.n);
    lit = (uint32_t *)malloc(sizeof(uint32_t) * w.n);
    seen = (uint32_t *)calloc(w.n, sizeof(uint32_t));
    if (!near || !all || !vis || !lit || !seen) goto out;
    CHECK_OK(rad_local_nearest(w.patches, pos, M, near, NULL));
    {
        /* every chosen patch is at most as far as every patch left out */
        double worst_in = 0.0, best_out = 1e30;
        for (i = 0; i < w.n; ++i) seen[i] = 0;
        for (i = 0; i < M; ++i) seen[near[i]] = 1;
        for (i = 0; i < w.n; ++i) {
            const float *q = w.patches->patches[i].centroid;
            double d = (q[0] - pos[0]) * (q[0] - pos[0]) + (q[1] - pos[1]) * (q[1] - pos[1]) + (q[2] - pos[2]) * (q[2] - pos[2]);
            if (seen[i] && d > worst_in) worst_in = d;
            if (!seen[i] && d < best_out) best_out = d;
        }
        CHECK(worst_in <= best_out);
        for (i = 1; i < M; ++i) CHECK(near[i] != near[i - 1]);
    }
    CHECK_RESULT(rad_local_nearest(w.patches, pos, w.n + 1, near, NULL), RAD_ERROR_INVALID_ARGUMENT);
    pos[1] = (float)NAN;
    CHECK_RESULT(rad_local_nearest(w.patches, pos, M, near, NULL), RAD_ERROR_NON_FINITE);
    /* P_Vis of the whole box from the Cornell camera */
    for (i = 0; i < w.n; ++i) all[i] = i;
    CHECK_OK(rad_local_visible(w.patches, &rc, &cam, 1.0f, all, w.n, vis, &nv, NULL));
    for (i = 0; i < w.n; ++i) seen[i] = 0;
    for (i = 0; i < nv; ++i) seen[vis[i]] = 1;
    {
        uint32_t hit_patches = 0, missed = 0, x, y;
        for (y = 0; y < H; ++y)
            for (x = 0; x < W; ++x) {
                rad_ray ray;
                rad_hit hit;
                float wts[3];
                uint32_t p;
                rad_camera_ray(&cam, W, H, (float)x + 0.5f, (float)y + 0.5f, &ray);
                CHECK_OK(rc.intersect(rc.user, &ray, 1, &hit));
                if (hit.triangle == RAD_NONE) continue;
                p = rad_patches_locate(w.patches, hit.triangle, hit.b1, hit.b2, wts);
                if (p == RAD_NONE) continue;
                if (seen[p] == 1) { seen[p] = 2; hit_patches++; }
                else if (seen[p] == 0) { seen[p] = 3; missed++; }
            }
        printf("    P_Vis: %u of %u patches; %u hit by %ux%u pixel rays, %u hit but not in P_Vis\n", nv, w.n, hit_patches, W, H, missed);
        CHECK(nv < w.n && nv > w.n / 3);
        CHECK(missed <= hit_patches / 20); /* patches seen only between the four test points */
    }
    /* from behind the box's open front looking away: nothing */
    {
        rad_camera back = cam;
        back.target[2] = cam.position[2] - 1.0f;
        CHECK_OK(rad_local_visible(w.patches, &rc, &back, 1.0f, all, w.n, vis, &nv, NULL));
        CHECK(nv == 0);
    }
    all[0] = w.n;
    CHECK_RESULT(rad_local_visible(w.patches, &rc, &cam, 1.0f, all, w.n, vis, &nv, NULL), RAD_ERROR_INDEX_OUT_OF_RANGE);
    all[0] = 0;
    CHECK_RESULT(rad_local_visible(w.patches, &rc, &cam, 0.0f, all, w.n, vis, &nv, NULL), RAD_ERROR_INVALID_ARGUMENT);
    /* P_Lit: E above a threshold */
    CHECK_OK(rad_local_lit(w.E, all, w.n, 0.2f, lit, &nl));
    for (i = 0, j = 0; i < w.n; ++i) {
        const float *e = w.E + 3 * (size_t)i;
        if (e[0] > 0.2f || e[1] > 0.2f || e[2] > 0.2f) { CHECK(j < nl && lit[j] == i); ++j; }
    }
    CHECK(j == nl && nl > 0 && nl < w.n);
    CHECK_RESULT(rad_local_lit(w.E, all, w.n, -1.0f, lit, &nl), RAD_ERROR_INVALID_ARGUMENT);
out:
    free(near); free(all); free(vis); free(lit); free(seen);
    fx_world_free(&w);
}


/* allocation failure injected at every allocation of create, add, evict, both rebuilds,
   apply, nearest and visible: each call returns success or OUT_OF_MEMORY, nothing leaks and
   no block is overrun (the counting allocator of test_scene.c) */
static void test_local_alloc_failure(void)
{
    lc_world w;
    rad_row_source src;
    sc_alloc_state st;
    rad_context ctx;
    rad_scene_desc desc;
    rad_camera cam;
    rad_raycaster rc;
    long n, total = 1;
    uint32_t i, ids[48], vis[48], nv = 0;
    float *out = NULL;
    if (!lc_cornell(&w, 48u)) return;
    rad_cornell_box(&desc, &cam);
    rad_bvh_raycaster(w.bvh, &rc);
    out = (float *)malloc(sizeof(float) * 3 * w.n);
    if (!out || w.n < 40 || !lc_source(&w, &src)) { free(out); fx_world_free(&w); return; }
    for (i = 0; i < 40; ++i) ids[i] = i;
    memset(&ctx, 0, sizeof(ctx));
    ctx.allocator.alloc = sc_alloc_fn;
    ctx.allocator.free = sc_free_fn;
    ctx.allocator.user = &st;
    for (n = 0; n <= total; ++n) {
        rad_local_options o;
        rad_local *L = NULL, *N = NULL;
        rad_result r[8];
        int k, failed = 0;
        memset(&st, 0, sizeof(st));
        st.fail_at = n;
        for (k = 0; k < 8; ++k) r[k] = RAD_SUCCESS;
        rad_local_options_default(&o);
        o.capacity = 20;
        r[0] = rad_local_create(&src, &o, &ctx, &L);
        if (r[0] == RAD_SUCCESS) {
            for (i = 0; i < 20 && r[1] == RAD_SUCCESS; ++i) r[1] = rad_local_add(L, ids[i], &ctx);
            for (i = 0; i < 3 && r[1] == RAD_SUCCESS; ++i) r[1] = rad_local_remove(L, ids[i], &ctx);
            for (i = 20; i < 23 && r[1] == RAD_SUCCESS; ++i) r[1] = rad_local_add(L, ids[i], &ctx);
            r[2] = rad_local_apply(L, w.E, NULL, 0, NULL, 0, out, RAD_OUTPUT_INDIRECT, &ctx);
            r[3] = rad_local_rebuild(L, ids + 10, 20, &ctx);
        }
        o.rebuild = RAD_LOCAL_REBUILD_NEUMANN;
        r[4] = rad_local_create(&src, &o, &ctx, &N);
        if (r[4] == RAD_SUCCESS) r[5] = rad_local_rebuild(N, ids, 20, &ctx);
        r[6] = rad_local_nearest(w.patches, cam.position, 10, vis, &ctx);
        r[7] = rad_local_visible(w.patches, &rc, &cam, 1.0f, ids, 40, vis, &nv, &ctx);
        for (k = 0; k < 8; ++k) {
            if (r[k] != RAD_SUCCESS && r[k] != RAD_ERROR_OUT_OF_MEMORY) {
                printf("    fail_at %ld: step %d returned %s\n", n, k, rad_result_string(r[k]));
                CHECK(0);
            }
            if (r[k] != RAD_SUCCESS) failed = 1;
        }
        if (n > 0 && n <= st.calls) CHECK(failed);
        rad_local_destroy(L);
        rad_local_destroy(N);
        if (st.allocs != st.frees || st.live_bytes != 0 || st.corrupt != 0) {
            printf("    fail_at %ld: %ld allocs, %ld frees, %lld live bytes, %ld overruns\n", n, st.allocs, st.frees, st.live_bytes,
                   st.corrupt);
            CHECK(0);
        }
        if (n == 0) total = st.calls;
    }
    CHECK(total >= 10);
    free(out);
    fx_world_free(&w);
}


/* NULL and bad arguments everywhere: the documented error, no crash, nothing written */
static void test_local_null_arguments(void)
{
    rad_row_source src;
    rad_local_options o;
    rad_local *L = (rad_local *)(void *)&src;
    rad_matrix F;
    float areas[2] = {1.0f, 1.0f}, albedo[6] = {0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f}, dense[4] = {0.0f, 0.5f, 0.5f, 0.0f}, E[6] = {1, 1, 1, 1, 1, 1};
    float pos[3] = {0.0f, 0.0f, 0.0f};
    uint32_t ids[2] = {0, 1}, out[2] = {7, 7}, count = 9;
    rad_row_stream *st = (rad_row_stream *)(void *)&src;
    rad_local_options_default(NULL);
    rad_local_destroy(NULL);
    CHECK(rad_local_memory(NULL) == 0);
    CHECK_RESULT(rad_local_add(NULL, 0, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_local_remove(NULL, 0, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_local_evict(NULL, 0, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_local_rebuild(NULL, ids, 2, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_local_apply(NULL, E, NULL, 0, NULL, 0, E, RAD_OUTPUT_INDIRECT, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_local_nearest(NULL, pos, 1, out, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_local_visible(NULL, NULL, NULL, 1.0f, ids, 2, out, &count, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_local_lit(NULL, ids, 2, 0.0f, out, &count), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_local_lit(E, NULL, 2, 0.0f, out, &count), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(out[0] == 7 && count == 9);
    CHECK_RESULT(rad_row_source_matrix(NULL, areas, albedo, &src), RAD_ERROR_INVALID_ARGUMENT);
    memset(&F, 0, sizeof(F));
    F.rows = 2; F.cols = 3; F.storage = RAD_STORAGE_DENSE; F.dense = dense;
    CHECK_RESULT(rad_row_source_matrix(&F, areas, albedo, &src), RAD_ERROR_SIZE_MISMATCH);
    F.cols = 2;
    CHECK_RESULT(rad_row_source_matrix(&F, NULL, albedo, &src), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_OK(rad_row_source_matrix(&F, areas, albedo, &src));
    CHECK_RESULT(rad_local_create(&src, NULL, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    rad_local_options_default(&o);
    o.capacity = 2;
    o.update = (rad_local_update)5;
    CHECK_RESULT(rad_local_create(&src, &o, NULL, &L), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(L == NULL);
    o.update = RAD_LOCAL_EXACT;
    o.rebuild = (rad_local_rebuild_method)9;
    CHECK_RESULT(rad_local_create(&src, &o, NULL, &L), RAD_ERROR_INVALID_ARGUMENT);
    o.rebuild = RAD_LOCAL_REBUILD_INVERSE;
    CHECK_OK(rad_local_create(&src, &o, NULL, &L));
    if (L) {
        CHECK_OK(rad_local_rebuild(L, ids, 2, NULL));
        CHECK_NEAR(L->planes[1], 0.25 / (1.0 - 0.0625), 1e-6); /* T_01 = a / (1 - a^2), a = 0.25 */
        CHECK_RESULT(rad_local_rebuild(L, ids, 3, NULL), RAD_ERROR_INVALID_ARGUMENT);
        CHECK(L->count == 0);
        ids[1] = 0;
        CHECK_RESULT(rad_local_rebuild(L, ids, 2, NULL), RAD_ERROR_INVALID_ARGUMENT);
        CHECK(L->count == 0 && L->patch_slot[0] == RAD_NONE);
        CHECK_OK(rad_local_rebuild(L, ids, 0, NULL));
        E[0] = (float)NAN;
        CHECK_OK(rad_local_add(L, 0, NULL));
        CHECK_RESULT(rad_local_apply(L, E, NULL, 0, NULL, 0, E + 3, RAD_OUTPUT_INDIRECT, NULL), RAD_ERROR_NON_FINITE);
        CHECK_RESULT(rad_local_apply(L, E, NULL, 0, NULL, 0, NULL, RAD_OUTPUT_INDIRECT, NULL), RAD_ERROR_INVALID_ARGUMENT);
        rad_local_destroy(L);
    }
#ifndef RAD_NO_STDIO
    CHECK_RESULT(rad_row_stream_create(NULL, NULL, &st), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(st == NULL);
    CHECK_RESULT(rad_row_stream_create("no/such/file.radb", NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(rad_row_stream_memory(NULL) == 0);
    rad_row_stream_source(NULL, &src);
    CHECK(src.fetch == NULL && src.n == 0);
    rad_row_stream_source(NULL, NULL);
    rad_row_stream_destroy(NULL);
#endif
}

static const rad_test_case tests_local[] = {
    {"local_add_exact_and_first_order", test_local_add_exact_and_first_order},
    {"local_remove_and_evict", test_local_remove_and_evict},
    {"local_walk_bounded", test_local_walk_bounded},
    {"local_back_and_forth", test_local_back_and_forth},
    {"local_apply_subsets", test_local_apply_subsets},
    {"local_bad_input", test_local_bad_input},
    {"local_row_sources", test_local_row_sources},
    {"local_repeated_columns", test_local_repeated_columns},
    {"local_sets", test_local_sets},
    {"local_alloc_failure", test_local_alloc_failure},
    {"local_null_arguments", test_local_null_arguments},
    {NULL, NULL}};

RAD_TEST_MAIN(tests_local)

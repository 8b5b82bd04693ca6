/* test_hier_scale.c - hierarchical radiosity (>>api_hierarchical) at scale: the clusters'
   gather by normal cones and the clamped cosine's quadratic fit, and progress that gives the
   first round (most of a large scene's work) half the bar. Uses the soups and worlds of
   test_hier_large.c. Its names are prefixed hs_. */
#include "fixtures.h"

/* 1. A box of 6 faces cut 4 x 4 lit by an emitting wall on its +x side, 3 units away:
   clustering on (the box's triangles gather through the clusters above them, some links
   reaching members that face the wall and members that do not) against off (every link to
   a triangle, its own cosine exact). The lit face's mean B agrees within 10%, and the face
   turned away stays dark with clustering (the fit leaks at most 1/16 of a source to a member
   facing straight away from it). */
static void hs_test_cluster_gather(void)
{
    static const float o[6][3] = { { 1, 0, 0 }, { 0, 0, 0 }, { 0, 1, 0 }, { 0, 0, 0 }, { 0, 0, 1 }, { 0, 0, 0 } };
    static const float u[6][3] = { { 0, 1, 0 }, { 0, 0, 1 }, { 0, 0, 1 }, { 1, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 } };
    static const float v[6][3] = { { 0, 0, 1 }, { 0, 1, 0 }, { 1, 0, 0 }, { 0, 0, 1 }, { 0, 1, 0 }, { 1, 0, 0 } };
    static const float wo[3] = { 4, -2, -2 }, wu[3] = { 0, 0, 5 }, wv[3] = { 0, 5, 0 };
    rad_material mats[2];
    hl_soup s;
    hl_world w;
    uint32_t *ids, i, f, per = 32u, box;
    double lit[2], dark[2], bmax;
    int c;
    memset(&s, 0, sizeof(s));
    memset(mats, 0, sizeof(mats));
    for (i = 0; i < 3; ++i) {
        mats[0].albedo[i] = 0.5f;
        mats[1].emission[i] = 1.0f;
    }
    for (f = 0; f < 6; ++f) hl_quad(&s, o[f], u[f], v[f], 4); /* +x face first (its front +x), -x second */
    box = s.n;
    hl_quad(&s, wo, wu, wv, 2); /* the wall at x = 4, facing -x */
    ids = (uint32_t *)calloc(s.n, sizeof(uint32_t));
    for (i = box; i < s.n; ++i) ids[i] = 1;
    if (!ids || !hl_world_make(&s, mats, ids, 2, &w)) {
        CHECK(0);
        free(ids);
        free(s.v);
        return;
    }
    CHECK(w.scene->triangle_count == s.n);
    for (c = 0; c < 2; ++c) {
        rad_hierarchical_options ho;
        rad_hierarchical *h = NULL;
        rad_hierarchical_options_default(&ho);
        ho.clustering = c ? RAD_HIERARCHICAL_CLUSTER_ON : RAD_HIERARCHICAL_CLUSTER_OFF;
        ho.tolerance = 1e-2;
        CHECK_OK(rad_hierarchical_create(w.scene, &w.rc, &ho, NULL, &h));
        if (h) CHECK_OK(rad_hierarchical_solve(h, NULL));
        lit[c] = h ? hl_mean_B(h, 0, per, &bmax) : 0.0;
        dark[c] = h ? hl_mean_B(h, per, 2u * per, &bmax) : 0.0;
        rad_hierarchical_destroy(h);
    }
    printf("    box face toward the wall: B %.4f off, %.4f on; face away: %.4f off, %.4f on\n", lit[0], lit[1], dark[0], dark[1]);
    CHECK(lit[0] > 0.0 && fabs(lit[1] / lit[0] - 1.0) < 0.1);
    CHECK(dark[0] < 1e-6 && dark[1] < 0.07 * lit[1]);
    hl_world_free(&w);
    free(ids);
    free(s.v);
}

/* the largest report below 1 */
static float hs_mid;
static int hs_prog_fn(void *user, float f)
{
    if (f < 1.0f && f > hs_mid) hs_mid = f;
    (void)hl_prog_fn(user, f);
    return 0;
}

/* 2. Progress over rounds: the first round spans [0, 1/2), so a solve of a few rounds reports
   values in the middle of the bar before its end (a share of 1 / max_iterations per round
   kept 3 rounds under 0.19 until the jump to 1), rising and ending at 1. */
static void hs_test_progress_rounds(void)
{
    hl_world w;
    hl_prog p;
    rad_hierarchical_options o;
    rad_hierarchical_stats st;
    rad_hierarchical *h = NULL;
    rad_context ctx;
    if (!hl_junk_world(&w)) return;
    rad_hierarchical_options_default(&o);
    o.clustering = RAD_HIERARCHICAL_CLUSTER_ON;
    o.tolerance = 1e-2;
    memset(&ctx, 0, sizeof(ctx));
    memset(&p, 0, sizeof(p));
    p.stop_at = -1;
    ctx.progress = hs_prog_fn;
    ctx.progress_user = &p;
    CHECK_OK(rad_hierarchical_create(w.scene, &w.rc, &o, NULL, &h));
    if (h) CHECK_OK(rad_hierarchical_solve(h, &ctx));
    rad_hierarchical_get_stats(h, &st);
    rad_hierarchical_destroy(h);
    printf("    %u rounds, %d reports, largest before the end %.3f\n", st.rounds, p.calls, (double)hs_mid);
    CHECK(st.rounds < o.max_iterations && !p.fell && p.last == 1.0f);
    CHECK(hs_mid >= 0.4f && hs_mid < 1.0f);
    hl_world_free(&w);
}

static const rad_test_case tests_hier_scale[] = {
    { "hier_scale_cluster_gather", hs_test_cluster_gather },
    { "hier_scale_progress_rounds", hs_test_progress_rounds },
    { NULL, NULL }
};
RAD_TEST_MAIN(tests_hier_scale)

/* test_hier_source.c - hierarchical radiosity (>>api_hierarchical): what a link from a cluster
   carries when the cluster's members differ, the case of a thin roof lit on top whose cluster
   sent the lit top's radiosity down into the interior. Its names are prefixed hsrc_. */
#include "fixtures.h"

/* 1. A thin roof (a unit square 1 above the floor, its underside facing down, albedo 0.5, and
   its top 0.02 above facing up and emitting) over a lamp square on the floor facing up, between
   two floor squares (albedo 0.5). The floor squares see only the roof's underside, lit by the
   lamp: nothing of the top's light reaches them. Clustered at a coarse tolerance the roof's
   clusters hold both faces, and a link that carried their mean B sent half of the top's
   radiosity down: the floor's B came out 4.5 times the unclustered solve's (all pairs of
   triangles, the independent answer). Within 25% of it now. */
static void hsrc_test_thin_roof(void)
{
    const uint32_t g = 4, per = 2u * g * g;
    float *v = (float *)malloc(sizeof(float) * 9u * 5u * per);
    uint32_t *ids = (uint32_t *)calloc(5u * per, sizeof(uint32_t));
    uint32_t n = 0, i, pass;
    double floor_B[2] = { -1.0, -1.0 };
    rad_material mats[3];
    if (!v || !ids) {
        CHECK(0);
        free(v);
        free(ids);
        return;
    }
    /* triangles: floor [0, 2 per), lamp [2 per, 3 per), roof underside, roof top */
    n += fx_square_grid(v + 9u * n, -1.0f, 0.0f, 1, g);
    n += fx_square_grid(v + 9u * n, 1.0f, 0.0f, 1, g);
    n += fx_square_grid(v + 9u * n, 0.0f, 0.0f, 1, g);
    for (i = 2u * per; i < 3u * per; ++i) ids[i] = 1;
    n += fx_square_grid(v + 9u * n, 0.0f, 1.0f, 0, g);
    n += fx_square_grid(v + 9u * n, 0.0f, 1.02f, 1, g);
    for (i = 4u * per; i < 5u * per; ++i) ids[i] = 2;
    memset(mats, 0, sizeof(mats));
    for (i = 0; i < 3; ++i) {
        mats[0].albedo[i] = 0.5f;
        mats[1].emission[i] = 1.0f;
        mats[2].emission[i] = 1.0f;
    }
    for (pass = 0; pass < 2; ++pass) {
        fx_hier_world w;
        rad_hierarchical *h;
        /* coarse: the roof's links stay at clusters that hold both faces */
        fx_hier_build(v, n, ids, mats, 3, pass == 0 ? RAD_HIERARCHICAL_CLUSTER_OFF : RAD_HIERARCHICAL_CLUSTER_ON, 0.5,
                      16, &w);
        h = w.h;
        if (h) {
            rad_hierarchical_stats st;
            rad_hierarchical_get_stats(h, &st);
            if (pass == 1) CHECK(st.cluster_links > 0);
            floor_B[pass] = fx_hier_mean_B(h, 0, 2u * per);
            printf("    thin roof, clustering %s: %llu links (%llu at clusters), floor B %.5f, underside %.5f\n",
                   pass == 0 ? "off" : "on", (unsigned long long)st.links, (unsigned long long)st.cluster_links,
                   floor_B[pass], fx_hier_mean_B(h, 3u * per, 4u * per));
        }
        fx_hier_world_free(&w);
    }
    CHECK(floor_B[0] > 0.0 && floor_B[1] > 0.0);
    if (floor_B[0] > 0.0 && floor_B[1] > 0.0) {
        printf("    clustered / unclustered floor B %.3f\n", floor_B[1] / floor_B[0]);
        CHECK(fabs(floor_B[1] / floor_B[0] - 1.0) < 0.25);
    }
    free(v);
    free(ids);
}

static const rad_test_case tests_hier_source[] = {
    { "hier_source_thin_roof", hsrc_test_thin_roof },
    { NULL, NULL }
};
RAD_TEST_MAIN(tests_hier_source)

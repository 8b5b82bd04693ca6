/* test_hier_open.c - hierarchical radiosity (>>api_hierarchical): how a cluster receiver splits
   a link's light among its members when some of them are hidden behind others. Uses the
   fixtures (fx_square_grid, fx_hier_mean_B). Its names are prefixed hopen_. */
#include "fixtures.h"

/* 1. A shelf of two plates facing down, 1 and 1.05 above a lamp on the floor (each plate three
   unit squares side by side, the lamp the middle one, albedo 0.5): the upper plate sees only
   the back of the lower one. Clustered at a coarse tolerance the receiving clusters hold both
   plates, and a split by each member's cosine to the source alone handed the hidden upper
   plate half of what the lower one receives: the lower plate's B came out about half the
   unclustered solve's (all pairs of triangles, the independent answer). Within 25% now. */
static void hopen_test_shelf(void)
{
    const uint32_t g = 4, per = 2u * g * g;
    float *v = (float *)malloc(sizeof(float) * 9u * 7u * per);
    uint32_t *ids = (uint32_t *)calloc(7u * per, sizeof(uint32_t));
    uint32_t n = 0, i, pass;
    double lower_B[2] = { -1.0, -1.0 };
    rad_material mats[2];
    if (!v || !ids) {
        CHECK(0);
        free(v);
        free(ids);
        return;
    }
    /* triangles: the lamp [0, per), the lower plate [per, 4 per), the upper plate [4 per, 7 per) */
    n += fx_square_grid(v + 9u * n, 0.0f, 0.0f, 1, g);
    for (i = 0; i < per; ++i) ids[i] = 1;
    for (i = 0; i < 3; ++i) n += fx_square_grid(v + 9u * n, (float)i - 1.0f, 1.0f, 0, g);
    for (i = 0; i < 3; ++i) n += fx_square_grid(v + 9u * n, (float)i - 1.0f, 1.05f, 0, g);
    memset(mats, 0, sizeof(mats));
    for (i = 0; i < 3; ++i) {
        mats[0].albedo[i] = 0.5f;
        mats[1].emission[i] = 1.0f;
    }
    for (pass = 0; pass < 2; ++pass) {
        fx_hier_world w;
        rad_hierarchical *h;
        /* coarse: the links into the shelf stay at clusters holding both plates */
        fx_hier_build(v, n, ids, mats, 2, pass == 0 ? RAD_HIERARCHICAL_CLUSTER_OFF : RAD_HIERARCHICAL_CLUSTER_ON, 0.5,
                      16, &w);
        h = w.h;
        if (h) {
            rad_hierarchical_stats st;
            rad_hierarchical_get_stats(h, &st);
            if (pass == 1) CHECK(st.cluster_links > 0);
            lower_B[pass] = fx_hier_mean_B(h, per, 4u * per);
            printf("    shelf, clustering %s: %llu links (%llu at clusters), lower plate B %.5f, upper %.5f\n",
                   pass == 0 ? "off" : "on", (unsigned long long)st.links, (unsigned long long)st.cluster_links,
                   lower_B[pass], fx_hier_mean_B(h, 4u * per, 7u * per));
        }
        fx_hier_world_free(&w);
    }
    CHECK(lower_B[0] > 0.0 && lower_B[1] > 0.0);
    if (lower_B[0] > 0.0 && lower_B[1] > 0.0) {
        printf("    clustered / unclustered lower plate B %.3f\n", lower_B[1] / lower_B[0]);
        CHECK(fabs(lower_B[1] / lower_B[0] - 1.0) < 0.25);
    }
    free(v);
    free(ids);
}

static const rad_test_case tests_hier_open[] = {
    { "hier_open_shelf", hopen_test_shelf },
    { NULL, NULL }
};

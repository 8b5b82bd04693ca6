/* test_hier_source.c - hierarchical radiosity (>>api_hierarchical): what a link from a cluster
   carries when the cluster's members differ, the case of a thin roof lit on top whose cluster
   sent the lit top's radiosity down into the interior. Its names are prefixed hsrc_. */
#include "fixtures.h"

/* the unit square [x0, x0 + 1] x [0, 1] at height z, cut g x g into triangles, facing +z (up)
   or -z, appended to v (9 floats a triangle); returns the triangles added */
static uint32_t hsrc_square(float *v, float x0, float z, int up, uint32_t g)
{
    uint32_t i, j, n = 0, c;
    for (i = 0; i < g; ++i)
        for (j = 0; j < g; ++j) {
            float q[4][3];
            static const int tri[2][3] = { { 0, 1, 2 }, { 0, 2, 3 } };
            q[0][0] = q[3][0] = x0 + (float)i / (float)g;
            q[1][0] = q[2][0] = x0 + (float)(i + 1u) / (float)g;
            q[0][1] = q[1][1] = (float)j / (float)g;
            q[2][1] = q[3][1] = (float)(j + 1u) / (float)g;
            for (c = 0; c < 4; ++c) q[c][2] = z;
            for (c = 0; c < 2; ++c) { /* counter-clockwise seen from +z; swapped for -z */
                int k, o[3] = { tri[c][0], up ? tri[c][1] : tri[c][2], up ? tri[c][2] : tri[c][1] };
                for (k = 0; k < 3; ++k) memcpy(v + 9u * n + 3u * (uint32_t)k, q[o[k]], 3 * sizeof(float));
                ++n;
            }
        }
    return n;
}

/* the area-weighted mean B (channel 0) of the leaves on scene triangles [t0, t1) */
static double hsrc_mean_B(const rad_hierarchical *h, uint32_t t0, uint32_t t1)
{
    rad_hierarchical_stats st;
    float *C, *B;
    uint32_t *T, i, nl;
    double a = 0.0, s = 0.0;
    rad_hierarchical_get_stats(h, &st);
    nl = st.leaves;
    C = (float *)malloc(sizeof(float) * 9u * nl);
    B = (float *)malloc(sizeof(float) * 3u * nl);
    T = (uint32_t *)malloc(sizeof(uint32_t) * nl);
    if (C && B && T && rad_hierarchical_leaves(h, 0, nl, C, T, B, NULL) == RAD_SUCCESS) {
        for (i = 0; i < nl; ++i) {
            double e1[3], e2[3], x, y, z;
            int k;
            if (T[i] < t0 || T[i] >= t1) continue;
            for (k = 0; k < 3; ++k) {
                e1[k] = (double)C[9 * i + 3 + k] - (double)C[9 * i + k];
                e2[k] = (double)C[9 * i + 6 + k] - (double)C[9 * i + k];
            }
            x = e1[1] * e2[2] - e1[2] * e2[1];
            y = e1[2] * e2[0] - e1[0] * e2[2];
            z = e1[0] * e2[1] - e1[1] * e2[0];
            x = 0.5 * sqrt(x * x + y * y + z * z);
            a += x;
            s += x * (double)B[3 * i];
        }
    }
    free(C);
    free(B);
    free(T);
    return a > 0.0 ? s / a : -1.0;
}

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
    n += hsrc_square(v + 9u * n, -1.0f, 0.0f, 1, g);
    n += hsrc_square(v + 9u * n, 1.0f, 0.0f, 1, g);
    n += hsrc_square(v + 9u * n, 0.0f, 0.0f, 1, g);
    for (i = 2u * per; i < 3u * per; ++i) ids[i] = 1;
    n += hsrc_square(v + 9u * n, 0.0f, 1.0f, 0, g);
    n += hsrc_square(v + 9u * n, 0.0f, 1.02f, 1, g);
    for (i = 4u * per; i < 5u * per; ++i) ids[i] = 2;
    memset(mats, 0, sizeof(mats));
    for (i = 0; i < 3; ++i) {
        mats[0].albedo[i] = 0.5f;
        mats[1].emission[i] = 1.0f;
        mats[2].emission[i] = 1.0f;
    }
    for (pass = 0; pass < 2; ++pass) {
        rad_mesh_desc m;
        rad_scene_desc d;
        rad_scene *scene = NULL;
        rad_bvh *bvh = NULL;
        rad_raycaster rc;
        rad_hierarchical *h = NULL;
        rad_hierarchical_options o;
        memset(&m, 0, sizeof(m));
        m.positions = v;
        m.vertex_count = 3u * n;
        m.triangle_count = n;
        m.material_ids = ids;
        memset(&d, 0, sizeof(d));
        d.meshes = &m;
        d.mesh_count = 1;
        d.materials = mats;
        d.material_count = 3;
        CHECK_OK(rad_scene_create(&d, NULL, &scene));
        if (scene) CHECK_OK(rad_bvh_create(scene, NULL, &bvh));
        if (bvh) {
            rad_bvh_raycaster(bvh, &rc);
            rad_hierarchical_options_default(&o);
            o.clustering = pass == 0 ? RAD_HIERARCHICAL_CLUSTER_OFF : RAD_HIERARCHICAL_CLUSTER_ON;
            o.tolerance = 0.5; /* coarse: the roof's links stay at clusters that hold both faces */
            o.visibility_rays = 16;
            CHECK_OK(rad_hierarchical_create(scene, &rc, &o, NULL, &h));
            if (h) CHECK_OK(rad_hierarchical_solve(h, NULL));
        }
        if (h) {
            rad_hierarchical_stats st;
            rad_hierarchical_get_stats(h, &st);
            if (pass == 1) CHECK(st.cluster_links > 0);
            floor_B[pass] = hsrc_mean_B(h, 0, 2u * per);
            printf("    thin roof, clustering %s: %llu links (%llu at clusters), floor B %.5f, underside %.5f\n",
                   pass == 0 ? "off" : "on", (unsigned long long)st.links, (unsigned long long)st.cluster_links,
                   floor_B[pass], hsrc_mean_B(h, 3u * per, 4u * per));
        }
        rad_hierarchical_destroy(h);
        rad_bvh_destroy(bvh);
        rad_scene_destroy(scene);
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

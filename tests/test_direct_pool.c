/* test_direct_pool.c - the direct light of many small emitters (rad__direct_point's draw among
   them): a point that sees more emitters than RAD__EMITTER_POOL x light_samples rays would
   cover draws that many among them. Unoccluded, the draw is exact (each emitter's share
   scaled back by its odds sums to pi L sum F); under a blocker its mean over points and seeds
   is the light of the same emitter as one quad; it casts the pool's rays and no more; the
   same bits in any task order. Everything static and prefixed dp_. */
#include "fixtures.h"

#define DP_N 16 /* cells a side of the emitting grid: 2 x 16 x 16 = 512 triangles */

typedef struct dp_world {
    float pos[3 * 4 * (DP_N * DP_N + 1)];
    uint32_t idx[6 * (DP_N * DP_N + 1)], mats[2 * (DP_N * DP_N + 1)];
    rad_material m[2];
    rad_mesh_desc mesh;
    rad_scene_desc desc;
    rad_scene *S;
    rad_bvh *bvh;
    rad_raycaster rc;
    uint32_t emitters;
} dp_world;

/* quad q: corners c (4 x 3), wound so its normal is along 'want', of material mat */
static void dp_quad(dp_world *w, uint32_t q, const float *c, const float *want, uint32_t mat)
{
    fx_quad_wound(w->pos, w->idx, q, c, want);
    w->mats[2 * q] = w->mats[2 * q + 1] = mat;
}

/* An emitter of radiance 1 over [0, 2] x [0, 2] at y = 1 facing down, as DP_N x DP_N cells
   (grid) or one quad; with 'blocker', a black square over x in [0, 1] at y = 0.5. */
static int dp_world_make(dp_world *w, int grid, int blocker)
{
    const float down[3] = { 0, -1, 0 };
    uint32_t q = 0, i, j;
    memset(w, 0, sizeof(*w));
    for (i = 0; i < (grid ? DP_N : 1u); ++i)
        for (j = 0; j < (grid ? DP_N : 1u); ++j) {
            float s = 2.0f / (float)(grid ? DP_N : 1), x0 = s * (float)i, z0 = s * (float)j;
            float c[12] = { x0, 1, z0, x0 + s, 1, z0, x0 + s, 1, z0 + s, x0, 1, z0 + s };
            dp_quad(w, q++, c, down, 1);
        }
    w->emitters = 2 * q;
    if (blocker) {
        float c[12] = { 0, 0.5f, -1, 1, 0.5f, -1, 1, 0.5f, 3, 0, 0.5f, 3 };
        dp_quad(w, q++, c, down, 0);
    }
    w->m[1].emission[0] = w->m[1].emission[1] = w->m[1].emission[2] = 1.0f;
    w->mesh.positions = w->pos;
    w->mesh.vertex_count = 4 * q;
    w->mesh.indices = w->idx;
    w->mesh.triangle_count = 2 * q;
    w->mesh.material_ids = w->mats;
    w->desc.meshes = &w->mesh;
    w->desc.mesh_count = 1;
    w->desc.materials = w->m;
    w->desc.material_count = 2;
    if (rad_scene_create(&w->desc, NULL, &w->S) != RAD_SUCCESS) return 0;
    if (rad_bvh_create(w->S, NULL, &w->bvh) != RAD_SUCCESS) return 0;
    rad_bvh_raycaster(w->bvh, &w->rc);
    return 1;
}

static void dp_world_free(dp_world *w)
{
    rad_bvh_destroy(w->bvh);
    rad_scene_destroy(w->S);
}

/* a raycaster that counts the shadow rays it passes on (serial use only) */
typedef struct dp_counter {
    const rad_raycaster *inner;
    size_t rays;
} dp_counter;

static rad_result dp_count_occluded(void *user, const rad_ray *rays, uint32_t count, uint8_t *out)
{
    dp_counter *c = (dp_counter *)user;
    c->rays += count;
    return c->inner->occluded(c->inner->user, rays, count, out);
}

static rad_result dp_count_intersect(void *user, const rad_ray *rays, uint32_t count, rad_hit *out)
{
    dp_counter *c = (dp_counter *)user;
    return c->inner->intersect(c->inner->user, rays, count, out);
}

/* Unoccluded, every drawn ray is visible: the estimate is pi sum F over the 512 emitters for
   any seed, the rays are the pool's (16 x 16 per point, not 16 per emitter), and any task
   order gives the same bits. */
static void dp_test_unoccluded_exact(void)
{
    dp_world w;
    const float pts[9] = { 1, 0, 1, 0.2f, 0.3f, 1.7f, 3, 0, -1 }, nrm[9] = { 0, 1, 0, 0.3f, 1, -0.2f, -1, 1, 0 };
    float out[9], out2[9];
    rad_direct_options o;
    rad_context ctx;
    rad_raycaster counting;
    dp_counter cnt;
    uint32_t sd, i, t;
    if (!dp_world_make(&w, 1, 0)) {
        CHECK(0);
        dp_world_free(&w);
        return;
    }
    CHECK(w.emitters == 2 * DP_N * DP_N);
    rad_direct_options_default(&o);
    memset(&ctx, 0, sizeof(ctx));
    ctx.parallel_for = fx_reverse_for;
    ctx.task_count = 3;
    cnt.inner = &w.rc;
    counting = w.rc;
    counting.user = &cnt;
    counting.occluded = dp_count_occluded;
    counting.intersect = dp_count_intersect;
    for (sd = 0; sd < 4; ++sd) {
        o.seed = sd;
        cnt.rays = 0;
        CHECK_OK(rad_direct_irradiance(w.S, &counting, NULL, 0, &o, pts, nrm, 3, out, &ctx));
        CHECK(cnt.rays > 0 && cnt.rays <= 3u * RAD__EMITTER_POOL * o.light_samples);
        for (i = 0; i < 3; ++i) {
            double P[3], N[3], want = 0.0, l = sqrt((double)nrm[3 * i] * nrm[3 * i] + (double)nrm[3 * i + 1] * nrm[3 * i + 1] +
                                                    (double)nrm[3 * i + 2] * nrm[3 * i + 2]);
            int k;
            for (k = 0; k < 3; ++k) P[k] = pts[3 * i + k], N[k] = nrm[3 * i + k] / l;
            for (t = 0; t < w.S->triangle_count; ++t) {
                const float *tv = w.S->positions + 9 * (size_t)t, *tn = w.S->normals + 3 * (size_t)t;
                float dv[3];
                for (k = 0; k < 3; ++k) dv[k] = pts[3 * i + k] - tv[k];
                if (dv[0] * tn[0] + dv[1] * tn[1] + dv[2] * tn[2] > 0.0f) want += fabs(rad__ff_point_tri(P, N, tv));
            }
            want *= 3.14159265358979323846;
            if (getenv("RAD_TEST_VERBOSE")) printf("    point %u: %.6f, pi L sum F %.6f\n", i, (double)out[3 * i], want);
            CHECK(want > 0.05);
            CHECK_REL(out[3 * i], want, 1e-4);
        }
    }
    CHECK_OK(rad_direct_irradiance(w.S, &w.rc, NULL, 0, &o, pts, nrm, 3, out2, NULL));
    CHECK(memcmp(out, out2, sizeof(out)) == 0);
    dp_world_free(&w);
}

/* Under the blocker: 40 points along x below the emitter, 8 seeds; the grid's mean against the
   one quad's (its own per-emitter rays, 64 light samples), per half: in the blocker's shadow
   and beside it. */
static void dp_test_occluded_mean(void)
{
    dp_world g, q;
    float pts[3 * 40], nrm[3 * 40], out[3 * 40];
    double mg[2] = { 0, 0 }, mq[2] = { 0, 0 };
    rad_direct_options o;
    uint32_t i, sd;
    int ok = dp_world_make(&g, 1, 1);
    ok = dp_world_make(&q, 0, 1) && ok;
    if (!ok) {
        CHECK(0);
        dp_world_free(&g);
        dp_world_free(&q);
        return;
    }
    for (i = 0; i < 40; ++i) {
        pts[3 * i] = 0.025f + 0.05f * (float)i, pts[3 * i + 1] = 0.0f, pts[3 * i + 2] = 1.0f;
        nrm[3 * i] = 0.0f, nrm[3 * i + 1] = 1.0f, nrm[3 * i + 2] = 0.0f;
    }
    rad_direct_options_default(&o);
    for (sd = 0; sd < 8; ++sd) {
        o.seed = sd;
        o.light_samples = 16;
        CHECK_OK(rad_direct_irradiance(g.S, &g.rc, NULL, 0, &o, pts, nrm, 40, out, NULL));
        for (i = 0; i < 40; ++i) mg[i >= 20] += (double)out[3 * i];
        o.light_samples = 64;
        CHECK_OK(rad_direct_irradiance(q.S, &q.rc, NULL, 0, &o, pts, nrm, 40, out, NULL));
        for (i = 0; i < 40; ++i) mq[i >= 20] += (double)out[3 * i];
    }
    if (getenv("RAD_TEST_VERBOSE"))
        printf("    shadowed half: grid %.5f, quad %.5f; open half: grid %.5f, quad %.5f\n", mg[0] / 160.0, mq[0] / 160.0,
               mg[1] / 160.0, mq[1] / 160.0);
    CHECK(mq[0] < 0.8 * mq[1]); /* the blocker's shadow is there */
    CHECK_REL(mg[0], mq[0], 0.02);
    CHECK_REL(mg[1], mq[1], 0.02);
    dp_world_free(&g);
    dp_world_free(&q);
}

static const rad_test_case tests_direct_pool[] = {
    { "direct_pool_unoccluded_exact", dp_test_unoccluded_exact },
    { "direct_pool_occluded_mean", dp_test_occluded_mean },
    { NULL, NULL }
};

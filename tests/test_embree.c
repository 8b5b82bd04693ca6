/* test_embree.c - the Embree backend: unavailable without RAD_EMBREE; with it, the same hits as
   the built-in BVH, the same form factors, a wrapped user RTCScene, errors to the logger. */
#include "fixtures.h"


static void em_test_availability(void)
{
    rad_embree *e = (rad_embree *)(uintptr_t)1;
    rad_raycaster rc;
#ifdef RAD_EMBREE
    CHECK(rad_embree_available() == 1);
    CHECK_RESULT(rad_embree_create(NULL, NULL, &e), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(e == NULL);
    CHECK_RESULT(rad_embree_wrap(NULL, NULL, 0, NULL, &e), RAD_ERROR_INVALID_ARGUMENT);
#else
    rad_scene_desc d;
    rad_scene *s = NULL;
    CHECK(rad_embree_available() == 0);
    rad_cornell_box(&d, NULL);
    CHECK_OK(rad_scene_create(&d, NULL, &s));
    CHECK_RESULT(rad_embree_create(s, NULL, &e), RAD_ERROR_UNAVAILABLE);
    CHECK(e == NULL);
    e = (rad_embree *)(uintptr_t)1;
    CHECK_RESULT(rad_embree_wrap((void *)s, NULL, 0, NULL, &e), RAD_ERROR_UNAVAILABLE);
    CHECK(e == NULL);
    rad_scene_destroy(s);
#endif
    rad_embree_raycaster(NULL, &rc);
    CHECK(rc.occluded == NULL && rc.intersect == NULL);
    CHECK(rad_embree_memory(NULL) == 0);
    rad_embree_destroy(NULL);
}

#ifdef RAD_EMBREE
static uint32_t em_lcg(uint32_t *s) { *s = *s * 1664525u + 1013904223u; return *s >> 8; }
static float em_rand(uint32_t *s) { return (float)em_lcg(s) / 16777216.0f; }

/* Random rays in the Cornell box: Embree and the BVH agree on occlusion and on the closest hit
   (triangle, and t within 1e-5 relative; ties on shared edges may name either triangle). */
static void em_test_agrees_with_bvh(void)
{
    rad_scene_desc d;
    rad_scene *s = NULL;
    rad_bvh *b = NULL;
    rad_embree *e = NULL;
    rad_raycaster rb, re;
    enum { N = 20000 };
    static rad_ray rays[N];
    static rad_hit hb[N], he[N];
    static uint8_t ob[N], oe[N];
    uint32_t seed = 7, i, occ_mismatch = 0, hit_mismatch = 0;
    rad_cornell_box(&d, NULL);
    CHECK_OK(rad_scene_create(&d, NULL, &s));
    CHECK_OK(rad_bvh_create(s, NULL, &b));
    CHECK_OK(rad_embree_create(s, NULL, &e));
    if (!s || !b || !e) return;
    /* the real BVH table: this file may be built with the Embree redirection of test_main.c */
    rb.user = (void *)b;
    rb.occluded = rad__bvh_occluded;
    rb.intersect = rad__bvh_intersect;
    rad_embree_raycaster(e, &re);
    CHECK(rad_embree_memory(e) > 0);
    for (i = 0; i < N; ++i) {
        int k;
        for (k = 0; k < 3; ++k) {
            rays[i].origin[k] = 0.02f + 0.5f * em_rand(&seed);
            rays[i].dir[k] = em_rand(&seed) - 0.5f;
        }
        rays[i].tmin = 0.0f;
        rays[i].tmax = (i % 3 == 0) ? 0.3f + em_rand(&seed) : FLT_MAX;
    }
    CHECK_OK(rb.occluded(rb.user, rays, N, ob));
    CHECK_OK(re.occluded(re.user, rays, N, oe));
    CHECK_OK(rb.intersect(rb.user, rays, N, hb));
    CHECK_OK(re.intersect(re.user, rays, N, he));
    for (i = 0; i < N; ++i) {
        if (ob[i] != oe[i]) occ_mismatch++;
        if (hb[i].triangle != he[i].triangle) {
            if (hb[i].triangle == RAD_NONE || he[i].triangle == RAD_NONE || fabs(hb[i].t - he[i].t) > 1e-5 * hb[i].t + 1e-7)
                hit_mismatch++;
        } else if (hb[i].triangle != RAD_NONE) {
            /* two float intersection tests: 1e-5 relative, 1e-7 absolute (rays leaving a surface) */
            CHECK_NEAR(he[i].t, hb[i].t, 1e-5 * hb[i].t + 1e-7);
            CHECK_NEAR(he[i].b1, hb[i].b1, 1e-4);
            CHECK_NEAR(he[i].b2, hb[i].b2, 1e-4);
        }
    }
    /* grazing rays may differ between two watertight tests; a handful in 20000 at most */
    CHECK(occ_mismatch <= 2);
    CHECK(hit_mismatch <= 2);
    rad_embree_destroy(e);
    rad__bvh_destroy_real(b);
    rad_scene_destroy(s);
}

/* A user's own RTCScene wrapped: geometry 1 holds triangles numbered from first_triangle[1]. */
static void em_test_wrap(void)
{
    RTCDevice dev = rtcNewDevice(NULL);
    RTCScene sc = rtcNewScene(dev);
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    float *v = (float *)rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, 3);
    unsigned *ix = (unsigned *)rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, 1);
    const uint32_t first[2] = { 0, 40 };
    rad_embree *e = NULL;
    rad_raycaster rc;
    rad_ray ray;
    rad_hit hit;
    uint8_t occ = 0;
    v[0] = -1; v[1] = -1; v[2] = 1; v[3] = 1; v[4] = -1; v[5] = 1; v[6] = 0; v[7] = 1; v[8] = 1;
    ix[0] = 0; ix[1] = 1; ix[2] = 2;
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(sc, g, 1);
    rtcReleaseGeometry(g);
    rtcCommitScene(sc);
    CHECK_OK(rad_embree_wrap((void *)sc, first, 2, NULL, &e));
    rad_embree_raycaster(e, &rc);
    memset(&ray, 0, sizeof(ray));
    ray.dir[2] = 1.0f;
    ray.tmax = 10.0f;
    CHECK_OK(rc.intersect(rc.user, &ray, 1, &hit));
    CHECK(hit.triangle == 40);
    CHECK_REL(hit.t, 1.0, 1e-6);
    CHECK_OK(rc.occluded(rc.user, &ray, 1, &occ));
    CHECK(occ == 1);
    ray.tmax = 0.5f;
    CHECK_OK(rc.occluded(rc.user, &ray, 1, &occ));
    CHECK(occ == 0);
    CHECK(rad_embree_memory(e) == 0);
    rad_embree_destroy(e);
    rtcReleaseScene(sc);
    rtcReleaseDevice(dev);
}

/* Embree's own errors reach the logger: asking the device for a geometry of an unknown type is
   reported through the device's error function. */
static int em_logged;
static void em_log(void *user, rad_log_level level, const char *message)
{
    (void)user;
    if (level == RAD_LOG_ERROR && strstr(message, "Embree")) em_logged++;
}

static void em_test_error_callback(void)
{
    rad_scene_desc d;
    rad_scene *s = NULL;
    rad_embree *e = NULL;
    rad_context ctx;
    rad_cornell_box(&d, NULL);
    CHECK_OK(rad_scene_create(&d, NULL, &s));
    memset(&ctx, 0, sizeof(ctx));
    ctx.log = em_log;
    CHECK_OK(rad_embree_create(s, &ctx, &e));
    if (!e) { rad_scene_destroy(s); return; }
    em_logged = 0;
    CHECK(rtcNewGeometry(e->device, (enum RTCGeometryType)9999) == NULL);
    CHECK(em_logged >= 1);
    rad_embree_destroy(e);
    rad_scene_destroy(s);
}
#endif

static const rad_test_case tests_embree[] = {
    { "embree_availability", em_test_availability },
#ifdef RAD_EMBREE
    { "embree_agrees_with_bvh", em_test_agrees_with_bvh },
    { "embree_wrap_user_scene", em_test_wrap },
    { "embree_errors_to_logger", em_test_error_callback },
#endif
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_embree)

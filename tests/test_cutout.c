/* test_cutout.c - alpha cutouts: the scene's checks and rad_scene_opaque, the raycasters
   passing through holes (BVH, and Embree against it), the patches' opaque fraction, and a
   checkerboard screen between an emitter and a floor against the closed form (half the
   light through a 50% screen, all of it through a clear one, none through a solid one). */
#include "fixtures.h"

/* Opacity textures by id: 1 a checkerboard of CO_CELLS x CO_CELLS cells over uv [0, 1]^2
   (opaque where the cell's row plus column is even), 2 clear everywhere, 3 solid, 4 a ramp
   alpha = u (for the cutoff). */
#define CO_CELLS 64
static float co_opacity(void *user, uint32_t texture, float u, float v)
{
    long cu = (long)floor((double)u * CO_CELLS), cv = (long)floor((double)v * CO_CELLS);
    if (user) ++*(unsigned long *)user;
    switch (texture) {
    case 1: return ((cu + cv) & 1) ? 0.0f : 1.0f;
    case 2: return 0.0f;
    case 3: return 1.0f;
    default: return u;
    }
}

#ifdef RAD_EMBREE
/* a uniform number in [0, 1) (xorshift64*) */
static double co_rand(uint64_t *x)
{
    *x ^= *x >> 12;
    *x ^= *x << 25;
    *x ^= *x >> 27;
    return (double)((*x * 0x2545F4914F6CDD1Dull) >> 11) / 9007199254740992.0;
}
#endif

static const float co_uvs[8] = { 0, 0, 1, 0, 1, 1, 0, 1 };

/* The floor (unit square, z = 0, facing up, mesh 0), the emitter (unit square at z = c,
   facing down, radiance 1, mesh 1) and a screen at z = c / 2 over [-0.5, 1.5]^2 (mesh 2,
   black, one-sided facing down; every segment from the emitter to the floor crosses it
   inside [0, 1]^2) whose material has opacity texture 'tex' (0: none). Its uv u runs along
   y and v along x. */
typedef struct co_setup {
    ff_quad q[3];
    rad_mesh_desc m[3];
    rad_material mats[3];
    rad_scene_desc d;
} co_setup;

static void co_make(co_setup *s, double c, uint32_t tex, void *count)
{
    int i;
    memset(s, 0, sizeof(*s));
    ff_quad_set(&s->q[0], 0, 0, 0, 1, 0, 0, 0, 1, 0);
    ff_quad_set(&s->q[1], 0, 0, (float)c, 0, 1, 0, 1, 0, 0);
    ff_quad_set(&s->q[2], -0.5f, -0.5f, (float)(c / 2), 0, 2, 0, 2, 0, 0);
    for (i = 0; i < 3; ++i) {
        ff_mesh_quad(&s->m[i], &s->q[i]);
        s->m[i].material = (uint32_t)i;
        s->m[i].uvs = co_uvs;
    }
    s->mats[0].albedo[0] = s->mats[0].albedo[1] = s->mats[0].albedo[2] = 0.5f;
    s->mats[1].emission[0] = s->mats[1].emission[1] = s->mats[1].emission[2] = 1.0f;
    s->mats[2].opacity_texture = tex;
    s->d.meshes = s->m;
    s->d.mesh_count = 3;
    s->d.materials = s->mats;
    s->d.material_count = 3;
    s->d.opacity_lookup = co_opacity;
    s->d.opacity_user = count;
}

/* Validation: a cutout needs the lookup, uvs and a cutoff in [0, 1]; rad_scene_opaque and
   rad_scene_cutout answer per point and per triangle. */
static void co_test_scene(void)
{
    co_setup s;
    rad_scene *sc = NULL;
    co_make(&s, 0.5, 4, NULL);
    s.d.opacity_lookup = NULL;
    CHECK(rad_scene_create(&s.d, NULL, &sc) == RAD_ERROR_INVALID_ARGUMENT && !sc);
    co_make(&s, 0.5, 4, NULL);
    s.m[2].uvs = NULL;
    CHECK(rad_scene_create(&s.d, NULL, &sc) == RAD_ERROR_INVALID_ARGUMENT && !sc);
    co_make(&s, 0.5, 4, NULL);
    s.mats[2].alpha_cutoff = 1.5f;
    CHECK(rad_scene_create(&s.d, NULL, &sc) == RAD_ERROR_INVALID_ARGUMENT && !sc);
    s.mats[2].alpha_cutoff = (float)NAN;
    CHECK(rad_scene_create(&s.d, NULL, &sc) == RAD_ERROR_INVALID_ARGUMENT && !sc);
    /* no opacity texture: the lookup is never kept, every point is there */
    co_make(&s, 0.5, 0, NULL);
    CHECK_OK(rad_scene_create(&s.d, NULL, &sc));
    if (sc) {
        CHECK(sc->opacity_lookup == NULL);
        CHECK(!rad_scene_cutout(sc, 4) && rad_scene_opaque(sc, 4, 0.1f, 0.1f));
        rad_scene_destroy(sc);
        sc = NULL;
    }
    /* the ramp alpha = u: triangle 4 is the screen's first (corners uv 0 0, 1 0, 1 1), so the
       point at barycentrics (b1, b2) has u = b1 + b2; cutoff 0 means 0.5 */
    co_make(&s, 0.5, 4, NULL);
    CHECK_OK(rad_scene_create(&s.d, NULL, &sc));
    if (sc) {
        CHECK(rad_scene_cutout(sc, 4) && !rad_scene_cutout(sc, 0) && !rad_scene_cutout(sc, 99));
        CHECK(rad_scene_opaque(sc, 4, 0.3f, 0.3f) == 1);
        CHECK(rad_scene_opaque(sc, 4, 0.2f, 0.2f) == 0);
        CHECK(rad_scene_opaque(sc, 0, 0.2f, 0.2f) == 1);
        CHECK(rad_scene_opaque(sc, 99, 0.2f, 0.2f) == 0);
        rad_scene_destroy(sc);
        sc = NULL;
    }
    s.mats[2].alpha_cutoff = 0.25f;
    CHECK_OK(rad_scene_create(&s.d, NULL, &sc));
    if (sc) {
        CHECK(rad_scene_opaque(sc, 4, 0.2f, 0.2f) == 1);
        CHECK(rad_scene_opaque(sc, 4, 0.1f, 0.1f) == 0);
        rad_scene_destroy(sc);
    }
}

/* A vertical ray down through the screen's cell centres: on an opaque cell it stops at the
   screen (and is occluded short of the floor), in a hole it reaches the floor. The opacity
   lookup is called only for the screen: rays that meet only the floor never call it. */
static void co_check_rays(const rad_raycaster *rc, const rad_scene *sc, unsigned long *calls)
{
    int cell, missed = 0;
    for (cell = 0; cell < 40; ++cell) {
        /* cells (cu, cv) along a walk, centred at y = -0.5 + 2 (cu + 0.5) / N, x likewise by cv */
        long cu = 17 + cell % 28, cv = 20 + (cell * 7) % 11;
        rad_ray r;
        rad_hit h;
        uint8_t occ = 2;
        int opaque = ((cu + cv) & 1) == 0;
        r.origin[0] = (float)(-0.5 + 2.0 * ((double)cv + 0.5) / CO_CELLS);
        r.origin[1] = (float)(-0.5 + 2.0 * ((double)cu + 0.5) / CO_CELLS);
        r.origin[2] = 0.4f;
        r.dir[0] = r.dir[1] = 0.0f;
        r.dir[2] = -1.0f;
        r.tmin = 0.0f;
        r.tmax = 1.0f;
        CHECK_OK(rc->intersect(rc->user, &r, 1, &h));
        if (h.triangle == RAD_NONE || sc->meshes[h.triangle] != (opaque ? 2u : 0u)) ++missed;
        else if (!opaque && fabs(h.t - 0.4) > 1e-5) ++missed;
        r.tmax = 0.3f; /* short of the floor */
        CHECK_OK(rc->occluded(rc->user, &r, 1, &occ));
        if (occ != (opaque ? 1 : 0)) ++missed;
    }
    CHECK(missed == 0);
    /* a ray from below that meets the floor before the screen never calls the lookup */
    {
        rad_ray r;
        rad_hit h;
        unsigned long before = *calls;
        r.origin[0] = 0.5f; r.origin[1] = 0.5f; r.origin[2] = -1.0f;
        r.dir[0] = r.dir[1] = 0.0f; r.dir[2] = 1.0f;
        r.tmin = 0.0f; r.tmax = 1.1f;
        CHECK_OK(rc->intersect(rc->user, &r, 1, &h));
        CHECK(h.triangle != RAD_NONE && sc->meshes[h.triangle] == 0);
        CHECK(*calls == before);
    }
}

static void co_test_bvh_rays(void)
{
    co_setup s;
    rad_scene *sc = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    unsigned long calls = 0;
    co_make(&s, 0.5, 1, &calls);
    CHECK_OK(rad_scene_create(&s.d, NULL, &sc));
    if (!sc) return;
    CHECK_OK(rad_bvh_create(sc, NULL, &bvh));
    if (bvh) {
        (rad_bvh_raycaster)(bvh, &rc);
        co_check_rays(&rc, sc, &calls);
        CHECK(calls > 0);
    }
    rad_bvh_destroy(bvh);
    rad_scene_destroy(sc);
}

#ifdef RAD_EMBREE
/* Embree's filter against the BVH: the same cell walk, then random rays from above the
   screen to the floor region: the same triangle (and nearly the same t) for all but rays
   that graze a cell edge. */
static void co_test_embree_matches_bvh(void)
{
    co_setup s;
    rad_scene *sc = NULL;
    rad_bvh *bvh = NULL;
    rad_embree *e = NULL;
    rad_raycaster rb, re;
    unsigned long calls = 0;
    uint32_t i, n = 4000, differ = 0, hits = 0, occ_differ = 0;
    rad_ray *rays = (rad_ray *)malloc(n * sizeof(rad_ray));
    rad_hit *hb = (rad_hit *)malloc(n * sizeof(rad_hit)), *he = (rad_hit *)malloc(n * sizeof(rad_hit));
    uint8_t *ob = (uint8_t *)malloc(n), *oe = (uint8_t *)malloc(n);
    uint64_t rng = 12345;
    co_make(&s, 0.5, 1, &calls);
    CHECK_OK(rad_scene_create(&s.d, NULL, &sc));
    if (sc) CHECK_OK(rad_bvh_create(sc, NULL, &bvh));
    if (sc) CHECK_OK(rad_embree_create(sc, NULL, &e));
    if (bvh && e && rays && hb && he && ob && oe) {
        (rad_bvh_raycaster)(bvh, &rb);
        rad_embree_raycaster(e, &re);
        co_check_rays(&re, sc, &calls);
        for (i = 0; i < n; ++i) {
            float x = (float)co_rand(&rng), y = (float)co_rand(&rng);
            float tx = (float)co_rand(&rng), ty = (float)co_rand(&rng);
            rays[i].origin[0] = x; rays[i].origin[1] = y; rays[i].origin[2] = 0.45f;
            rays[i].dir[0] = tx - x; rays[i].dir[1] = ty - y; rays[i].dir[2] = -0.45f;
            rays[i].tmin = 0.0f;
            rays[i].tmax = i % 2 ? 1.5f : 0.9f; /* half of them short of the floor */
        }
        CHECK_OK(rb.intersect(rb.user, rays, n, hb));
        CHECK_OK(re.intersect(re.user, rays, n, he));
        CHECK_OK(rb.occluded(rb.user, rays, n, ob));
        CHECK_OK(re.occluded(re.user, rays, n, oe));
        for (i = 0; i < n; ++i) {
            if (hb[i].triangle != he[i].triangle || (hb[i].triangle != RAD_NONE && fabs(hb[i].t - he[i].t) > 1e-4)) ++differ;
            if (hb[i].triangle != RAD_NONE && sc->meshes[hb[i].triangle] == 2) ++hits;
            if (ob[i] != oe[i]) ++occ_differ;
        }
        CHECK(differ <= n / 500);
        CHECK(occ_differ <= n / 500);
        /* about half the rays stop on the screen */
        CHECK(hits > 0.45 * n && hits < 0.55 * n);
    }
    free(rays); free(hb); free(he); free(ob); free(oe);
    rad_embree_destroy(e);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(sc);
}
#endif

/* Patches of a cutout stand for their opaque part: the checkerboard screen's patch areas sum
   to half its area, a clear screen's to (almost) nothing, a solid one's to all of it. */
static void co_test_patch_areas(void)
{
    uint32_t tex;
    for (tex = 1; tex <= 3; ++tex) {
        co_setup s;
        ff_world w;
        double a = 0.0;
        uint32_t i;
        co_make(&s, 0.5, tex, NULL);
        if (!ff_world_make(&s.d, 0.25f, 0, &w)) return;
        for (i = 0; i < w.patches->count; ++i)
            if (w.scene->meshes[w.patches->patches[i].triangle] == 2) a += w.patches->patches[i].area;
        if (tex == 1) CHECK_REL(a, 2.0, 0.02);
        if (tex == 2) CHECK(a < 4.0 * 1e-5);
        if (tex == 3) CHECK_REL(a, 4.0, 1e-5);
        ff_world_free(&w);
    }
}

/* The floor's mean radiosity under the emitter through the screen (classic, dense form
   factors, Jacobi): rho pi L F T with T the screen's transmission. emitter_tex: the
   emitter's own opacity texture (0: none). */
static double co_floor_lit(uint32_t tex, uint32_t emitter_tex, double c, float max_edge)
{
    co_setup s;
    ff_world w;
    rad_form_factors *ff = NULL;
    rad_form_factor_options fo;
    rad_system sys;
    rad_solve_options so;
    float *E = NULL, *B = NULL;
    double sum = 0.0, area = 0.0;
    uint32_t i;
    co_make(&s, c, tex, NULL);
    s.mats[1].opacity_texture = emitter_tex;
    if (!ff_world_make(&s.d, max_edge, 0, &w)) return -1.0;
    rad_form_factor_options_default(&fo);
    CHECK_OK(rad_form_factors_dense(w.patches, &w.rc, &fo, NULL, &ff));
    E = (float *)calloc(3 * (size_t)w.patches->count, sizeof(float));
    B = (float *)calloc(3 * (size_t)w.patches->count, sizeof(float));
    if (ff && E && B) {
        CHECK_OK(rad_sources(w.patches, RAD_SOURCE_EMISSION, NULL, E));
        rad_system_init(&sys, &ff->matrix, w.patches, E);
        rad_solve_options_default(&so);
        so.output = RAD_OUTPUT_TOTAL;
        so.bounces = 4;
        CHECK_OK(rad_solve_jacobi(&sys, &so, B, NULL, NULL));
        for (i = 0; i < w.patches->count; ++i) {
            const rad_patch *p = &w.patches->patches[i];
            if (w.scene->meshes[p->triangle] != 0) continue;
            sum += p->area * B[3 * i];
            area += p->area;
        }
    }
    free(E);
    free(B);
    rad_form_factors_destroy(ff);
    ff_world_free(&w);
    return area > 0.0 ? sum / area : -1.0;
}

static double co_floor(uint32_t tex, double c) { return co_floor_lit(tex, 0, c, rad_test_quick() ? 0.25f : 0.2f); }

static void co_test_screen_closed_form(void)
{
    const double c = 0.5, open = 0.5 * FF_PI * ff_c11(1.0, 1.0, c);
    double half = co_floor(1, c), clear = co_floor(2, c), solid = co_floor(3, c), none = co_floor(0, c);
    if (getenv("CO_PRINT")) printf("    open %g: clear %g, checkerboard %g (%g of open), solid %g\n", open, clear, half, half / open, solid);
    CHECK_REL(clear, open, 0.01);
    CHECK_REL(half, 0.5 * open, 0.03);
    CHECK(solid >= 0.0 && solid < 1e-6);
    CHECK(none >= 0.0 && none < 1e-6); /* no opacity texture: a solid screen */
}

/* An emitter that is itself a checkerboard cutout sends half its light: the patches' source
   term (classic) and the direct light's per-point quadrature (rad_direct_irradiance at the
   floor's centre) both leave the holes dark. */
static void co_test_cutout_emitter(void)
{
    const double c = 0.5, open = 0.5 * FF_PI * ff_c11(1.0, 1.0, c);
    /* patches 1/8 of the emitter wide, 8 checker cells each: a regular lattice of 16 x 16
       points per patch measures their opaque fraction without aliasing (at 10.7 cells per
       patch it measured 0.89 of the light) */
    double half = co_floor_lit(2, 1, c, 0.2f);
    co_setup s;
    rad_scene *sc = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    CHECK_REL(half, 0.5 * open, 0.03);
    co_make(&s, c, 2, NULL);
    CHECK_OK(rad_scene_create(&s.d, NULL, &sc));
    if (sc) CHECK_OK(rad_bvh_create(sc, NULL, &bvh));
    if (bvh) {
        float pts[3] = { 0.5f, 0.5f, 0.0f }, nrm[3] = { 0.0f, 0.0f, 1.0f }, D[3] = { 0, 0, 0 }, D2[3] = { 0, 0, 0 };
        rad_direct_options o;
        (rad_bvh_raycaster)(bvh, &rc);
        rad_direct_options_default(&o);
        o.light_samples = 256; /* a 16-point quadrature aliases with a 64-cell checkerboard */
        CHECK_OK(rad_direct_irradiance(sc, &rc, NULL, 0, &o, pts, nrm, 1, D, NULL));
        rad_bvh_destroy(bvh);
        rad_scene_destroy(sc);
        bvh = NULL;
        sc = NULL;
        s.mats[1].opacity_texture = 1;
        CHECK_OK(rad_scene_create(&s.d, NULL, &sc));
        if (sc) CHECK_OK(rad_bvh_create(sc, NULL, &bvh));
        if (bvh) {
            (rad_bvh_raycaster)(bvh, &rc);
            CHECK_OK(rad_direct_irradiance(sc, &rc, NULL, 0, &o, pts, nrm, 1, D2, NULL));
            CHECK(D[0] > 0.0f);
            CHECK_REL(D2[0], 0.5 * D[0], 0.05);
        }
    }
    rad_bvh_destroy(bvh);
    rad_scene_destroy(sc);
}

static const rad_test_case tests_cutout[] = {
    { "cutout_scene", co_test_scene },
    { "cutout_bvh_rays_pass_holes", co_test_bvh_rays },
#ifdef RAD_EMBREE
    { "cutout_embree_matches_bvh", co_test_embree_matches_bvh },
#endif
    { "cutout_patch_areas", co_test_patch_areas },
    { "cutout_screen_closed_form", co_test_screen_closed_form },
    { "cutout_emitter", co_test_cutout_emitter },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_cutout)

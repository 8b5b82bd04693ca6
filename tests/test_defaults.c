/* test_defaults.c - zero means default, for every public option struct: each consumer is run
   once with a zeroed struct and once with the struct its _options_default function filled, on
   a small scene, and the outputs must be bit-identical. A field whose zero is a setting (not
   the default) makes its struct's test fail. Every rad_*_options_default of radiosity.h must
   be named in df_covered below (tests/check_docs.sh defaults checks that), so a new option
   struct cannot go untested. Everything static and prefixed df_. */
#include "fixtures.h"

/* the option structs this file covers, by the name of their _default function */
static const char *const df_covered[] = {
    "rad_patch_options_default", "rad_direct_options_default", "rad_final_gather_options_default",
    "rad_form_factor_options_default", "rad_solve_options_default", "rad_stochastic_options_default",
    "rad_hierarchical_options_default", "rad_multibounce_options_default", "rad_block_options_default",
    "rad_local_options_default", "rad_temporal_options_default", "rad_vp_options_default",
    "rad_vp_lights_options_default", "rad_lightmap_options_default", "rad_lightmap_gather_options_default",
    "rad_probe_options_default", "rad_sky_transfer_options_default", "rad_baker_runtime_options_default", NULL
};

/* a and b hold the same bytes (n floats) */
static int df_same(const float *a, const float *b, size_t n)
{
    return a && b && memcmp(a, b, n * sizeof(float)) == 0;
}

static float *df_floats(size_t n)
{
    float *p = (float *)calloc(n ? n : 1, sizeof(float));
    CHECK(p != NULL);
    return p;
}

static const rad_light df_sun = { RAD_LIGHT_DIRECTIONAL, { 3.0f, 3.0f, 3.0f }, { 0, 0, 0 }, { 0.3f, -1.0f, 0.2f },
                                  RAD_FALLOFF_QUADRATIC, 0.0f, 0.0f, 0.0f, NULL };

static void df_patches(void)
{
    rad_scene_desc desc;
    rad_scene *S = NULL;
    rad_patches *a = NULL, *b = NULL, *c = NULL;
    rad_patch_options z, d;
    rad_cornell_box(&desc, NULL);
    CHECK_OK(rad_scene_create(&desc, NULL, &S));
    memset(&z, 0, sizeof z);
    rad_patch_options_default(&d);
    if (S) {
        CHECK_OK(rad_patches_create(S, &z, NULL, &a));
        CHECK_OK(rad_patches_create(S, &d, NULL, &b));
        CHECK_OK(rad_patches_create(S, NULL, NULL, &c));
    }
    if (a && b && c) {
        CHECK(a->count == b->count && a->count == c->count);
        CHECK(a->count == b->count && memcmp(a->patches, b->patches, a->count * sizeof(rad_patch)) == 0);
        CHECK(a->count == c->count && memcmp(a->patches, c->patches, a->count * sizeof(rad_patch)) == 0);
    }
    rad_patches_destroy(a);
    rad_patches_destroy(b);
    rad_patches_destroy(c);
    rad_scene_destroy(S);
}

static void df_form_factors(void)
{
    fx_world w;
    rad_form_factor_options z, d;
    rad_form_factors *a = NULL, *b = NULL;
    if (!fx_cornell(&w, 48, 1, 0)) { CHECK(0); return; }
    memset(&z, 0, sizeof z);
    rad_form_factor_options_default(&d);
    CHECK_OK(rad_form_factors_dense(w.patches, &w.rc, &z, NULL, &a));
    CHECK_OK(rad_form_factors_dense(w.patches, &w.rc, &d, NULL, &b));
    if (a && b) CHECK(df_same(a->matrix.dense, b->matrix.dense, (size_t)w.n * w.n));
    rad_form_factors_destroy(a);
    rad_form_factors_destroy(b);
    /* the hemicube's resolution */
    z.method = d.method = RAD_FF_HEMICUBE;
    a = b = NULL;
    CHECK_OK(rad_form_factors_dense(w.patches, NULL, &z, NULL, &a));
    CHECK_OK(rad_form_factors_dense(w.patches, NULL, &d, NULL, &b));
    if (a && b) CHECK(df_same(a->matrix.dense, b->matrix.dense, (size_t)w.n * w.n));
    rad_form_factors_destroy(a);
    rad_form_factors_destroy(b);
    fx_world_free(&w);
}

static void df_direct(void)
{
    fx_world w;
    rad_direct_options z, d;
    float *a, *b, *c;
    if (!fx_cornell(&w, 48, 1, 0)) { CHECK(0); return; }
    a = df_floats(3 * (size_t)w.n); b = df_floats(3 * (size_t)w.n); c = df_floats(3 * (size_t)w.n);
    memset(&z, 0, sizeof z);
    rad_direct_options_default(&d);
    /* the sun and the box's own emitter */
    CHECK_OK(rad_direct_patches(w.patches, &w.rc, &df_sun, 1, &z, a, NULL));
    CHECK_OK(rad_direct_patches(w.patches, &w.rc, &df_sun, 1, &d, b, NULL));
    CHECK_OK(rad_direct_patches(w.patches, &w.rc, &df_sun, 1, NULL, c, NULL));
    CHECK(df_same(a, b, 3 * (size_t)w.n));
    CHECK(df_same(a, c, 3 * (size_t)w.n));
    /* at points, through rad_direct_irradiance */
    {
        const float pts[6] = { 0.3f, 0.01f, 0.3f, 0.2f, 0.3f, 0.001f }, nrm[6] = { 0, 1, 0, 0, 0, 1 };
        CHECK_OK(rad_direct_irradiance(w.scene, &w.rc, &df_sun, 1, &z, pts, nrm, 2, a, NULL));
        CHECK_OK(rad_direct_irradiance(w.scene, &w.rc, &df_sun, 1, &d, pts, nrm, 2, b, NULL));
        CHECK(df_same(a, b, 6));
    }
    free(a); free(b); free(c);
    fx_world_free(&w);
}

/* the indirect irradiance lookup of rad_final_gather: a constant */
static rad_result df_lookup(void *user, const rad_hit *hits, const float *points, const float *normals, uint32_t count,
                            float *out)
{
    uint32_t i;
    (void)user; (void)hits; (void)points; (void)normals;
    for (i = 0; i < 3 * count; ++i) out[i] = 0.5f;
    return RAD_SUCCESS;
}

static void df_final_gather(void)
{
    fx_world w;
    rad_final_gather_options z, d;
    const float pts[6] = { 0.3f, 0.01f, 0.3f, 0.2f, 0.3f, 0.001f }, nrm[6] = { 0, 1, 0, 0, 0, 1 };
    float a[6], b[6];
    if (!fx_cornell(&w, 16, 1, 0)) { CHECK(0); return; }
    memset(&z, 0, sizeof z);
    rad_final_gather_options_default(&d);
    CHECK_OK(rad_final_gather(w.scene, &w.rc, &df_sun, 1, &z, df_lookup, NULL, pts, nrm, 2, a, NULL));
    CHECK_OK(rad_final_gather(w.scene, &w.rc, &df_sun, 1, &d, df_lookup, NULL, pts, nrm, 2, b, NULL));
    CHECK(df_same(a, b, 6));
    fx_world_free(&w);
}

static void df_solve(void)
{
    fx_world w;
    rad_solve_options z, d;
    rad_system sys;
    float *a, *b;
    int k;
    if (!fx_cornell(&w, 48, 1, 0)) { CHECK(0); return; }
    a = df_floats(3 * (size_t)w.n); b = df_floats(3 * (size_t)w.n);
    rad_system_init(&sys, &w.ff->matrix, w.patches, w.E);
    memset(&z, 0, sizeof z);
    rad_solve_options_default(&d);
    for (k = 0; k < 3; ++k) {
        rad_result (*solve)(const rad_system *, const rad_solve_options *, float *, rad_solve_stats *, const rad_context *) =
            k == 0 ? rad_solve_jacobi : k == 1 ? rad_solve_gauss_seidel : rad_solve_progressive;
        memset(a, 0, 3 * sizeof(float) * w.n);
        memset(b, 0xFF, 3 * sizeof(float) * w.n);
        CHECK_OK(solve(&sys, &z, a, NULL, NULL));
        CHECK_OK(solve(&sys, &d, b, NULL, NULL));
        CHECK(df_same(a, b, 3 * (size_t)w.n));
    }
    free(a); free(b);
    fx_world_free(&w);
}

static void df_stochastic(void)
{
    fx_world w;
    rad_stochastic_options z, d;
    float *a, *b;
    if (!fx_cornell(&w, 24, 1, 0)) { CHECK(0); return; }
    a = df_floats(3 * (size_t)w.n); b = df_floats(3 * (size_t)w.n);
    memset(&z, 0, sizeof z);
    rad_stochastic_options_default(&d);
    z.iterations = d.iterations = 2; /* short: the other fields are what is compared */
    CHECK_OK(rad_solve_stochastic(w.patches, &w.rc, w.E, &z, a, NULL, NULL));
    CHECK_OK(rad_solve_stochastic(w.patches, &w.rc, w.E, &d, b, NULL, NULL));
    CHECK(df_same(a, b, 3 * (size_t)w.n));
    free(a); free(b);
    fx_world_free(&w);
}

static void df_hierarchical(void)
{
    fx_world w;
    rad_hierarchical_options z, d;
    rad_hierarchical *ha = NULL, *hb = NULL;
    uint32_t t[4] = { 0, 5, 11, 20 };
    float bc[8] = { 0.3f, 0.3f, 0.2f, 0.5f, 0.1f, 0.1f, 0.4f, 0.4f }, a[12], b[12];
    if (!fx_cornell(&w, 16, 1, 0)) { CHECK(0); return; }
    memset(&z, 0, sizeof z);
    rad_hierarchical_options_default(&d);
    z.max_iterations = d.max_iterations = 2; /* short */
    z.min_area = d.min_area = 0.01f;
    CHECK_OK(rad_hierarchical_create(w.scene, &w.rc, &z, NULL, &ha));
    CHECK_OK(rad_hierarchical_create(w.scene, &w.rc, &d, NULL, &hb));
    if (ha && hb) {
        CHECK_OK(rad_hierarchical_solve(ha, NULL));
        CHECK_OK(rad_hierarchical_solve(hb, NULL));
        CHECK_OK(rad_hierarchical_lookup(ha, RAD_HIERARCHICAL_RADIOSITY, 0, t, bc, 4, a));
        CHECK_OK(rad_hierarchical_lookup(hb, RAD_HIERARCHICAL_RADIOSITY, 0, t, bc, 4, b));
        CHECK(df_same(a, b, 12));
    }
    rad_hierarchical_destroy(ha);
    rad_hierarchical_destroy(hb);
    fx_world_free(&w);
}

static void df_multibounce(void)
{
    fx_world w;
    rad_multibounce_options z, d;
    rad_block_options bz, bd;
    rad_multibounce *a = NULL, *b = NULL;
    rad_multibounce_blocks *ca = NULL, *cb = NULL;
    if (!fx_cornell(&w, 48, 1, 0)) { CHECK(0); return; }
    memset(&z, 0, sizeof z);
    rad_multibounce_options_default(&d);
    CHECK_OK(rad_multibounce_create(&w.ff->matrix, w.patches->albedo, &z, NULL, &a));
    CHECK_OK(rad_multibounce_create(&w.ff->matrix, w.patches->albedo, &d, NULL, &b));
    if (a && b) {
        CHECK(a->bounces == b->bounces);
        CHECK(df_same(a->planes, b->planes, 3 * (size_t)w.n * w.n));
    }
    /* the compressed form of the same matrix */
    memset(&bz, 0, sizeof bz);
    rad_block_options_default(&bd);
    if (b) {
        CHECK_OK(rad_multibounce_blocks_create(b, &bz, NULL, &ca, NULL));
        CHECK_OK(rad_multibounce_blocks_create(b, &bd, NULL, &cb, NULL));
    }
    if (ca && cb) {
        size_t bytes = (size_t)ca->blocks_per_row * ca->blocks_per_row * 8u * (ca->format == RAD_BLOCK_BC1 ? 1u : 3u);
        CHECK(ca->format == cb->format && ca->tile == cb->tile && ca->outlier_count == cb->outlier_count);
        CHECK(ca->format == cb->format && memcmp(ca->blocks, cb->blocks, bytes) == 0);
        CHECK(ca->tiles_per_row == cb->tiles_per_row &&
              df_same(ca->scales, cb->scales, 3 * (size_t)ca->tiles_per_row * ca->tiles_per_row));
        CHECK((ca->row_perm == NULL) == (cb->row_perm == NULL));
        if (ca->row_perm && cb->row_perm) CHECK(memcmp(ca->row_perm, cb->row_perm, w.n * sizeof(uint32_t)) == 0);
    }
    rad_multibounce_blocks_destroy(ca);
    rad_multibounce_blocks_destroy(cb);
    rad_multibounce_destroy(a);
    rad_multibounce_destroy(b);
    fx_world_free(&w);
}

static void df_local(void)
{
    fx_world w;
    rad_local_options z, d;
    rad_row_source src;
    rad_local *a = NULL, *b = NULL;
    uint32_t i;
    if (!fx_cornell(&w, 48, 1, 0)) { CHECK(0); return; }
    memset(&z, 0, sizeof z);
    rad_local_options_default(&d);
    CHECK_OK(rad_row_source_matrix(&w.ff->matrix, w.patches->areas, w.patches->albedo, &src));
    CHECK_OK(rad_local_create(&src, &z, NULL, &a));
    CHECK_OK(rad_local_create(&src, &d, NULL, &b));
    if (a && b) {
        CHECK(a->capacity == b->capacity && a->update == b->update && a->evict == b->evict && a->rebuild == b->rebuild);
        for (i = 0; i < w.n; i += 3) {
            CHECK_OK(rad_local_add(a, i, NULL));
            CHECK_OK(rad_local_add(b, i, NULL));
        }
        if (a->capacity == b->capacity) CHECK(df_same(a->planes, b->planes, 3 * (size_t)a->capacity * a->capacity));
    }
    rad_local_destroy(a);
    rad_local_destroy(b);
    fx_world_free(&w);
}

static void df_temporal(void)
{
    fx_world w;
    rad_temporal_options z, d;
    rad_alias_tables *t = NULL;
    rad_temporal *ta = NULL, *tb = NULL;
    float *a, *b;
    int f, adaptive;
    if (!fx_cornell(&w, 48, 1, 0)) { CHECK(0); return; }
    a = df_floats(3 * (size_t)w.n); b = df_floats(3 * (size_t)w.n);
    CHECK_OK(rad_alias_tables_create(&w.ff->matrix, RAD_ALIAS_AUTO, NULL, &t));
    for (adaptive = 0; adaptive < 2 && t; ++adaptive) {
        memset(&z, 0, sizeof z);
        rad_temporal_options_default(&d);
        z.adaptive = d.adaptive = adaptive;
        ta = tb = NULL;
        CHECK_OK(rad_temporal_create((const rad_alias_tables *const *)&t, 1, w.patches->albedo, &z, NULL, &ta));
        CHECK_OK(rad_temporal_create((const rad_alias_tables *const *)&t, 1, w.patches->albedo, &d, NULL, &tb));
        for (f = 0; f < 8 && ta && tb; ++f) {
            CHECK_OK(rad_temporal_step(ta, w.E, NULL, a));
            CHECK_OK(rad_temporal_step(tb, w.E, NULL, b));
        }
        if (ta && tb) CHECK(df_same(a, b, 3 * (size_t)w.n));
        rad_temporal_destroy(ta);
        rad_temporal_destroy(tb);
    }
    rad_alias_tables_destroy(t);
    free(a); free(b);
    fx_world_free(&w);
}

/* the Cornell box's virtual patches at a coarse resolution (the rest of the options as given) */
static void df_vp_pair(const rad_vp_options *z, const rad_vp_options *d, const fx_world *w, rad_virtual_patches **a,
                       rad_virtual_patches **b)
{
    CHECK_OK(rad_vp_create(w->scene, &w->rc, z, NULL, a));
    CHECK_OK(rad_vp_create(w->scene, &w->rc, d, NULL, b));
}

static void df_vp(void)
{
    fx_world w;
    rad_vp_options z, d;
    rad_virtual_patches *a = NULL, *b = NULL;
    if (!fx_cornell(&w, 16, 1, 0)) { CHECK(0); return; }
    memset(&z, 0, sizeof z);
    rad_vp_options_default(&d);
    z.resolution = d.resolution = 4; /* small: the other fields are what is compared */
    df_vp_pair(&z, &d, &w, &a, &b);
    if (a && b) {
        CHECK(a->count == b->count && a->sample_count == b->sample_count && a->kind == b->kind);
        CHECK(a->count == b->count && df_same(a->matrix.dense, b->matrix.dense, (size_t)a->count * a->count));
    }
    rad_vp_destroy(a);
    rad_vp_destroy(b);
    /* the resolution itself, on its own */
    memset(&z, 0, sizeof z);
    rad_vp_options_default(&d);
    z.skip_visibility = d.skip_visibility = 1;
    z.face_points = d.face_points = 1;
    z.share_rays = d.share_rays = 1;
    a = b = NULL;
    df_vp_pair(&z, &d, &w, &a, &b);
    if (a && b) CHECK(a->count == b->count && a->dims[0] == b->dims[0] && a->dims[1] == b->dims[1] && a->dims[2] == b->dims[2]);
    rad_vp_destroy(a);
    rad_vp_destroy(b);
    fx_world_free(&w);
}

static void df_vp_lights(void)
{
    fx_world w;
    rad_vp_options vo;
    rad_vp_lights_options z, d;
    rad_virtual_patches *vp = NULL;
    rad_vp_lights *la = NULL, *lb = NULL;
    float *a = NULL, *b = NULL;
    if (!fx_cornell(&w, 16, 1, 0)) { CHECK(0); return; }
    rad_vp_options_default(&vo);
    vo.resolution = 4;
    CHECK_OK(rad_vp_create(w.scene, &w.rc, &vo, NULL, &vp));
    if (vp) {
        a = df_floats(3 * (size_t)vp->count); b = df_floats(3 * (size_t)vp->count);
        memset(&z, 0, sizeof z);
        rad_vp_lights_options_default(&d);
        CHECK_OK(rad_vp_lights_create(vp, &w.rc, &z, NULL, &la));
        CHECK_OK(rad_vp_lights_create(vp, &w.rc, &d, NULL, &lb));
        if (la && lb) {
            CHECK_OK(rad_vp_lights_update(la, &df_sun, 1, a, NULL));
            CHECK_OK(rad_vp_lights_update(lb, &df_sun, 1, b, NULL));
            CHECK(df_same(a, b, 3 * (size_t)vp->count));
        }
    }
    rad_vp_lights_destroy(la);
    rad_vp_lights_destroy(lb);
    rad_vp_destroy(vp);
    free(a); free(b);
    fx_world_free(&w);
}

static void df_lightmap(void)
{
    lm_soup room, wall, lamp;
    rad_mesh_desc m[3];
    rad_scene_desc desc;
    rad_material mats[2];
    rad_scene *S = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_patches *P = NULL;
    rad_form_factors *ff = NULL;
    float *E = NULL, *B = NULL, *a = NULL, *b = NULL;
    rad_lightmap_options z, d;
    rad_lightmap_gather_options gz, gd;
    rad_lightmap *la = NULL, *lb = NULL;
    fx_two_rooms(&room, &wall, &lamp, m, &desc, mats);
    CHECK_OK(rad_scene_create(&desc, NULL, &S));
    if (S) CHECK_OK(rad_bvh_create(S, NULL, &bvh));
    if (!bvh) { rad_scene_destroy(S); return; }
    rad_bvh_raycaster(bvh, &rc);
    memset(&z, 0, sizeof z);
    rad_lightmap_options_default(&d);
    z.width = d.width = z.height = d.height = 16; /* small: the other fields are what is compared */
    CHECK_OK(rad_lightmap_create(S, &rc, &z, NULL, &la));
    CHECK_OK(rad_lightmap_create(S, &rc, &d, NULL, &lb));
    if (la && lb) {
        CHECK(la->sample_count == lb->sample_count && la->valid_texels == lb->valid_texels);
        CHECK(la->sample_count == lb->sample_count &&
              memcmp(la->sample_valid, lb->sample_valid, la->sample_count) == 0 &&
              df_same(la->positions, lb->positions, 3 * (size_t)la->width * la->height));
    }
    /* the gather, from the lightmap made with the defaults */
    if (lb && fx_classic_jacobi8(S, &rc, &P, &ff, &E, &B)) {
        size_t n = 3 * (size_t)lb->width * lb->height;
        a = df_floats(n); b = df_floats(n);
        memset(&gz, 0, sizeof gz);
        rad_lightmap_gather_options_default(&gd);
        CHECK_OK(rad_lightmap_gather(lb, P, B, &rc, &gz, a, NULL));
        CHECK_OK(rad_lightmap_gather(lb, P, B, &rc, &gd, b, NULL));
        CHECK(df_same(a, b, n));
        gz.method = gd.method = RAD_LIGHTMAP_GATHER_HEMISPHERE;
        CHECK_OK(rad_lightmap_gather(lb, P, B, &rc, &gz, a, NULL));
        CHECK_OK(rad_lightmap_gather(lb, P, B, &rc, &gd, b, NULL));
        CHECK(df_same(a, b, n));
    }
    free(a); free(b); free(E); free(B);
    rad_form_factors_destroy(ff);
    rad_patches_destroy(P);
    rad_lightmap_destroy(la);
    rad_lightmap_destroy(lb);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(S);
}

static void df_probes(void)
{
    fx_world w;
    rad_probe_options z, d;
    rad_probes *a = NULL, *b = NULL;
    rad_solve_options so;
    rad_system sys;
    float *B;
    int direct;
    if (!fx_cornell(&w, 48, 1, 0)) { CHECK(0); return; }
    B = df_floats(3 * (size_t)w.n);
    rad_system_init(&sys, &w.ff->matrix, w.patches, w.E);
    rad_solve_options_default(&so);
    so.output = RAD_OUTPUT_TOTAL;
    CHECK_OK(rad_solve_jacobi(&sys, &so, B, NULL, NULL));
    for (direct = 0; direct < 2; ++direct) {
        memset(&z, 0, sizeof z);
        rad_probe_options_default(&d);
        z.flags = d.flags = direct ? RAD_PROBES_DIRECT : 0u;
        z.rays = d.rays = 64; /* short: the other fields are what is compared */
        a = b = NULL;
        CHECK_OK(rad_probes_create(w.patches, &w.rc, &df_sun, 1, NULL, 0, &z, B, NULL, &a));
        CHECK_OK(rad_probes_create(w.patches, &w.rc, &df_sun, 1, NULL, 0, &d, B, NULL, &b));
        if (a && b) {
            CHECK(rad_probes_count(a) == rad_probes_count(b));
            CHECK(rad_probes_count(a) == rad_probes_count(b) &&
                  df_same(rad_probes_coefficients(a), rad_probes_coefficients(b), 27 * (size_t)rad_probes_count(a)));
            CHECK(rad_probes_count(a) == rad_probes_count(b) &&
                  df_same(rad_probes_positions(a), rad_probes_positions(b), 3 * (size_t)rad_probes_count(a)));
        }
        rad_probes_destroy(a);
        rad_probes_destroy(b);
    }
    free(B);
    fx_world_free(&w);
}

/* the sky transfer: the response tables of a zeroed and a default struct (few rays: the fields
   compared are the defaults, not the accuracy) */
static void df_sky_transfer(void)
{
    fx_world w;
    rad_sky_transfer_options z, d;
    rad_sky_transfer *a = NULL, *b = NULL;
    if (!fx_cornell(&w, 24, 1, 0)) { CHECK(0); return; }
    memset(&z, 0, sizeof z);
    rad_sky_transfer_options_default(&d);
    z.rays = d.rays = 16;
    CHECK_OK(rad_sky_transfer_create(w.patches, &w.rc, &w.ff->matrix, &z, NULL, &a));
    CHECK_OK(rad_sky_transfer_create(w.patches, &w.rc, &w.ff->matrix, &d, NULL, &b));
    if (a && b) {
        CHECK(a->coefficients == b->coefficients && a->basis == RAD_SKY_BASIS_BINS);
        CHECK(df_same(a->response, b->response, 3 * (size_t)a->coefficients * a->n));
    }
    rad_sky_transfer_destroy(a);
    rad_sky_transfer_destroy(b);
    fx_world_free(&w);
}

/* the runtime over a bake: a zeroed and a default struct give the same frames, bit for bit
   (a light that moves for a few frames on a budget, so that every field is used) */
static void df_baker_runtime(void)
{
    rad_baker_desc d;
    rad_baker_options o;
    rad_baker_runtime_options z, dd;
    rad_baker_result *R = NULL;
    rad_baker_runtime *a = NULL, *b = NULL;
    rad_baker_frame fa, fb;
    rad_baker_light bl;
    rad_light l;
    int k;
    memset(&d, 0, sizeof d);
    rad_cornell_box(&d.scene, NULL);
    memset(&bl, 0, sizeof bl);
    bl.light.type = RAD_LIGHT_POINT;
    bl.light.position[0] = 0.28f; bl.light.position[1] = 0.35f; bl.light.position[2] = 0.28f;
    bl.light.color[0] = bl.light.color[1] = bl.light.color[2] = 0.05f;
    d.lights = &bl;
    d.light_count = 1;
    d.outputs = RAD_BAKER_VERTEX | RAD_BAKER_PROBES;
    d.probe_spacing = 0.25f;
    memset(&o, 0, sizeof o);
    o.method = RAD_BAKER_VIRTUAL_PATCHES;
    o.vp_resolution = 5;
    o.bounces = 4;
    o.light_samples = 2;
    memset(&z, 0, sizeof z);
    rad_baker_runtime_options_default(&dd);
    CHECK(dd.temporal_samples == 16 && dd.temporal_weight == 0.75f && dd.shadow_rays == 0 && dd.work_per_ms == 1e6);
    CHECK_OK(rad_baker_run(&d, &o, NULL, &R));
    if (R) CHECK_OK(rad_baker_runtime_create(&d, &o, R, &z, NULL, &a));
    if (R) CHECK_OK(rad_baker_runtime_create(&d, &o, R, &dd, NULL, &b));
    for (k = 1; a && b && k <= 12; ++k) {
        l = bl.light;
        l.position[0] += 0.01f * (float)(k < 6 ? k : 6);
        CHECK_OK(rad_baker_runtime_update(a, &l, 1, 0.05, &fa));
        CHECK_OK(rad_baker_runtime_update(b, &l, 1, 0.05, &fb));
        CHECK(fa.phase == fb.phase && fa.probes_refreshed == fb.probes_refreshed && fa.shadow_rays == fb.shadow_rays);
        CHECK(df_same(fa.vertex, fb.vertex, 3 * (size_t)R->vertex_count));
        CHECK(df_same(fa.probes, fb.probes, 27 * (size_t)R->probe_count));
    }
    rad_baker_runtime_destroy(a);
    rad_baker_runtime_destroy(b);
    rad_baker_result_destroy(R);
}

/* the list tests/check_docs.sh compares with the header is well formed */
static void df_list(void)
{
    int i;
    for (i = 0; df_covered[i]; ++i) CHECK(strncmp(df_covered[i], "rad_", 4) == 0);
    CHECK(i >= 16);
}

static const rad_test_case tests_defaults[] = {
    { "defaults_covered", df_list },
    { "defaults_patches", df_patches },
    { "defaults_form_factors", df_form_factors },
    { "defaults_direct", df_direct },
    { "defaults_final_gather", df_final_gather },
    { "defaults_solve", df_solve },
    { "defaults_stochastic", df_stochastic },
    { "defaults_hierarchical", df_hierarchical },
    { "defaults_multibounce_blocks", df_multibounce },
    { "defaults_local", df_local },
    { "defaults_temporal", df_temporal },
    { "defaults_vp", df_vp },
    { "defaults_vp_lights", df_vp_lights },
    { "defaults_lightmap", df_lightmap },
    { "defaults_probes", df_probes },
    { "defaults_sky_transfer", df_sky_transfer },
    { "defaults_baker_runtime", df_baker_runtime },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_defaults)

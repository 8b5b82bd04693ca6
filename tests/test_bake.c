/* test_bake.c - the engine tier (rad_baker_run, docs/methods/bake.md): its per-vertex light
   against the same choices made with the lower-level calls (classic patches and virtual
   patches, bit for bit), light layers against bakes of each group alone and the mix against
   their linear combination (vertices, lightmap, probes), cancel from the progress hook with
   nothing leaked, zeroed options, and the specific errors of bad input. Included by
   test_main.c after the implementation: every name is static and prefixed bk_. */
#include "fixtures.h"

/* the Cornell box's point lamp of examples/engine_bake.c */
static void bk_lamp(rad_light *l)
{
    memset(l, 0, sizeof(*l));
    l->type = RAD_LIGHT_POINT;
    l->position[0] = 0.28f; l->position[1] = 0.35f; l->position[2] = 0.28f;
    l->color[0] = l->color[1] = l->color[2] = 0.05f;
}

/* options small enough for a unit test */
static void bk_options(rad_baker_options *o, rad_baker_method method)
{
    memset(o, 0, sizeof(*o));
    o->method = method;
    o->patches = rad_test_quick() ? 120u : 200u;
    o->ff_samples = 4;
    o->bounces = 8;
    o->light_samples = 8;
}

static int bk_same_bits(const float *a, const float *b, size_t n)
{
    return n == 0 || memcmp(a, b, n * sizeof(float)) == 0;
}

/* the baker's per-vertex layers must be the lower-level calls' values for the same choices */
static void bk_test_classic_lower_level(void)
{
    rad_baker_desc d;
    rad_baker_options o;
    rad_baker_result *R = NULL;
    rad_baker_light bl;
    rad_scene *S = NULL;
    rad_patches *P = NULL;
    rad_bvh *bvh = NULL;
    rad_form_factors *ff = NULL;
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_direct_options dopt;
    rad_solve_options so;
    rad_raycaster rc;
    rad_system sys;
    float *D = NULL, *E = NULL, *L = NULL, *H = NULL, *X = NULL, *Sr = NULL, *Hv = NULL, *out = NULL;
    uint32_t i, m, n;
    int same = 1;
    memset(&d, 0, sizeof d);
    rad_cornell_box(&d.scene, NULL);
    bk_lamp(&bl.light);
    bl.group = 0; /* lamp and ceiling light in one group: one solve, as the lower-level path does it */
    d.lights = &bl;
    d.light_count = 1;
    bk_options(&o, RAD_BAKER_AUTO);
    CHECK_OK(rad_baker_run(&d, &o, NULL, &R));
    if (!R) return;
    CHECK(R->method == RAD_BAKER_CLASSIC);
    CHECK(R->group_count == 1);
    CHECK(strstr(R->reason, "classic") != NULL);
    CHECK(R->estimated_bytes > 0.0 && R->estimated_seconds > 0.0);

    CHECK_OK(rad_scene_create(&d.scene, NULL, &S));
    rad_patch_options_default(&po);
    po.target_count = o.patches;
    if (S) CHECK_OK(rad_patches_create(S, &po, NULL, &P));
    if (S) CHECK_OK(rad_bvh_create(S, NULL, &bvh));
    if (!P || !bvh) goto done;
    CHECK(P->count == R->patch_count);
    (rad_bvh_raycaster)(bvh, &rc); /* the baker's own ray queries, also in the Embree build of the tests */
    rad_form_factor_options_default(&fo);
    fo.samples = o.ff_samples;
    CHECK_OK(rad_form_factors_dense(P, &rc, &fo, NULL, &ff));
    if (!ff) goto done;
    n = P->count;
    D = (float *)malloc(sizeof(float) * 3 * n);
    E = (float *)malloc(sizeof(float) * 3 * n);
    L = (float *)malloc(sizeof(float) * 3 * n);
    H = (float *)malloc(sizeof(float) * 3 * n);
    X = (float *)malloc(sizeof(float) * 3 * n);
    Sr = (float *)malloc(sizeof(float) * n);
    Hv = (float *)malloc(sizeof(float) * 3 * P->vertex_count);
    out = (float *)malloc(sizeof(float) * 3 * R->vertex_count);
    if (!D || !E || !L || !H || !X || !Sr || !Hv || !out) goto done;
    rad_direct_options_default(&dopt);
    dopt.light_samples = o.light_samples;
    CHECK_OK(rad_direct_patches(P, &rc, &bl.light, 1, &dopt, D, NULL));
    CHECK_OK(rad_sources(P, RAD_SOURCE_DIRECT, D, E));
    rad_system_init(&sys, &ff->matrix, P, E);
    rad_solve_options_default(&so);
    so.bounces = o.bounces;
    CHECK_OK(rad_solve_jacobi(&sys, &so, L, NULL, NULL));
    for (i = 0; i < 3 * n; ++i) X[i] = 1.0f;
    CHECK_OK(rad_matrix_multiply(&ff->matrix, X, H, NULL));
    for (i = 0; i < n; ++i) Sr[i] = H[3 * i];
    for (i = 0; i < 3 * n; ++i) X[i] = E[i] + L[i];
    CHECK_OK(rad_matrix_multiply(&ff->matrix, X, H, NULL));
    CHECK_OK(rad_patches_vertex_irradiance(P, H, Sr, Hv, NULL));
    for (m = 0; m < d.scene.mesh_count; ++m) {
        uint32_t v0 = R->vertex_first[m], nv = R->vertex_first[m + 1] - v0;
        CHECK(nv == d.scene.meshes[m].vertex_count);
        CHECK_OK(rad_patches_gather_mesh(P, Hv, m, &d.scene.meshes[m], out + 3 * (size_t)v0, NULL));
    }
    same = bk_same_bits(out, R->vertex, 3 * (size_t)R->vertex_count) &&
           bk_same_bits(out, R->vertex_layers, 3 * (size_t)R->vertex_count);
    CHECK(same);
    for (i = 0; i < 3 * R->vertex_count; ++i) CHECK(R->vertex[i] >= 0.0f && R->vertex[i] < 1e30f);
    {
        double mean = 0.0; /* the floor gets bounced light: something was solved */
        for (i = 0; i < 3 * d.scene.meshes[0].vertex_count; ++i) mean += R->vertex[i];
        CHECK(mean > 0.0);
    }
done:
    free(D); free(E); free(L); free(H); free(X); free(Sr); free(Hv); free(out);
    rad_form_factors_destroy(ff);
    rad_bvh_destroy(bvh);
    rad_patches_destroy(P);
    rad_scene_destroy(S);
    rad_baker_result_destroy(R);
}

/* AUTO under a memory budget too small for the classic matrix takes virtual patches at the
   finest resolution that fits, and its vertices are the lower-level virtual-patch calls' */
static void bk_test_auto_vp_lower_level(void)
{
    rad_baker_desc d;
    rad_baker_options o;
    rad_baker_result *R = NULL;
    rad_baker_light bl;
    rad_scene *S = NULL;
    rad_bvh *bvh = NULL;
    rad_virtual_patches *vp = NULL;
    rad_vp_options vo;
    rad_direct_options dopt;
    rad_solve_options so;
    rad_system sys;
    rad_raycaster rc;
    float *E = NULL, *L = NULL, *H = NULL, *out = NULL;
    uint32_t i, m, n;
    memset(&d, 0, sizeof d);
    rad_cornell_box(&d.scene, NULL);
    bk_lamp(&bl.light);
    bl.group = 0;
    d.lights = &bl;
    d.light_count = 1;
    bk_options(&o, RAD_BAKER_AUTO);
    o.patches = 4000;                     /* 64 MB of F: over the budget */
    o.vp_resolution = 8;
    o.max_memory = 1.5 * 1048576.0;       /* resolution 8 (about 500 patches) does not fit either */
    CHECK_OK(rad_baker_run(&d, &o, NULL, &R));
    if (!R) return;
    CHECK(R->method == RAD_BAKER_VIRTUAL_PATCHES);
    CHECK(R->vp_resolution > 0 && R->vp_resolution < 8);
    CHECK(R->estimated_bytes <= o.max_memory);
    CHECK(strstr(R->reason, "classic would need") != NULL);
    CHECK_OK(rad_scene_create(&d.scene, NULL, &S));
    if (S) CHECK_OK(rad_bvh_create(S, NULL, &bvh));
    if (!bvh) goto done;
    (rad_bvh_raycaster)(bvh, &rc); /* the baker's own ray queries, also in the Embree build of the tests */
    rad_vp_options_default(&vo);
    vo.resolution = R->vp_resolution;
    CHECK_OK(rad_vp_create(S, &rc, &vo, NULL, &vp));
    if (!vp) goto done;
    n = vp->count;
    CHECK(n == R->patch_count);
    E = (float *)malloc(sizeof(float) * 3 * n);
    L = (float *)malloc(sizeof(float) * 3 * n);
    H = (float *)malloc(sizeof(float) * 3 * n);
    out = (float *)malloc(sizeof(float) * 3 * R->vertex_count);
    if (!E || !L || !H || !out) goto done;
    rad_direct_options_default(&dopt);
    dopt.light_samples = o.light_samples;
    CHECK_OK(rad_vp_sources(vp, &rc, &bl.light, 1, &dopt, RAD_SOURCE_DIRECT, E, NULL));
    rad_vp_system(&sys, vp, E);
    rad_solve_options_default(&so);
    so.bounces = o.bounces;
    CHECK_OK(rad_solve_jacobi(&sys, &so, L, NULL, NULL));
    for (i = 0; i < 3 * n; ++i) L[i] += E[i];
    CHECK_OK(rad_matrix_multiply(&vp->matrix, L, H, NULL));
    for (m = 0; m < d.scene.mesh_count; ++m)
        CHECK_OK(rad_vp_gather_mesh(vp, H, &d.scene.meshes[m], out + 3 * (size_t)R->vertex_first[m], NULL));
    CHECK(bk_same_bits(out, R->vertex, 3 * (size_t)R->vertex_count));
done:
    free(E); free(L); free(H); free(out);
    rad_vp_destroy(vp);
    rad_bvh_destroy(bvh);
    rad_scene_destroy(S);
    rad_baker_result_destroy(R);
}

/* Two groups on the Cornell box (the ceiling light 0, the lamp 1): each layer is the bake of
   that group alone, bit for bit, and the mix with (1,0), (0,1) and any scales is the linear
   combination of the two. */
static void bk_test_layers_cornell(void)
{
    rad_baker_desc d, dl, de;
    rad_baker_options o;
    rad_baker_result *A = NULL, *Bl = NULL, *Be = NULL;
    rad_baker_light bl;
    rad_material mats[16];
    const float one0[6] = { 1, 1, 1, 0, 0, 0 }, one1[6] = { 0, 0, 0, 1, 1, 1 };
    const float sc[6] = { 0.5f, 2.0f, 1.0f, 3.0f, 0.0f, 0.25f };
    uint32_t i, k;
    size_t nv;
    memset(&d, 0, sizeof d);
    rad_cornell_box(&d.scene, NULL);
    bk_lamp(&bl.light);
    bl.group = 1;
    d.lights = &bl;
    d.light_count = 1;
    bk_options(&o, RAD_BAKER_CLASSIC);
    CHECK_OK(rad_baker_run(&d, &o, NULL, &A));
    /* the lamp alone: the same scene with no emission */
    dl = d;
    CHECK(d.scene.material_count <= 16);
    for (i = 0; i < d.scene.material_count && i < 16; ++i) {
        mats[i] = d.scene.materials[i];
        mats[i].emission[0] = mats[i].emission[1] = mats[i].emission[2] = 0.0f;
    }
    dl.scene.materials = mats;
    bl.group = 0;
    CHECK_OK(rad_baker_run(&dl, &o, NULL, &Bl));
    /* the ceiling light alone */
    de = d;
    de.lights = NULL;
    de.light_count = 0;
    CHECK_OK(rad_baker_run(&de, &o, NULL, &Be));
    if (!A || !Bl || !Be) goto done;
    CHECK(A->group_count == 2 && Bl->group_count == 1 && Be->group_count == 1);
    nv = 3 * (size_t)A->vertex_count;
    CHECK(bk_same_bits(A->vertex_layers, Be->vertex, nv));
    CHECK(bk_same_bits(A->vertex_layers + nv, Bl->vertex, nv));
    CHECK_OK(rad_baker_mix(A, one0, NULL));
    CHECK(bk_same_bits(A->vertex, Be->vertex, nv));
    CHECK_OK(rad_baker_mix(A, one1, NULL));
    CHECK(bk_same_bits(A->vertex, Bl->vertex, nv));
    CHECK_OK(rad_baker_mix(A, sc, NULL));
    for (i = 0; i < nv; ++i) {
        double want = (double)sc[i % 3] * Be->vertex[i] + (double)sc[3 + i % 3] * Bl->vertex[i];
        CHECK_NEAR(A->vertex[i], want, 1e-6 * want + 1e-12);
    }
    for (k = 0; k < 3; ++k) { /* both groups light the floor */
        double a = 0.0, b = 0.0;
        for (i = 0; i < d.scene.meshes[0].vertex_count; ++i) {
            a += Be->vertex[3 * i + k];
            b += Bl->vertex[3 * i + k];
        }
        CHECK(a > 0.0 && b > 0.0);
    }
done:
    rad_baker_result_destroy(A);
    rad_baker_result_destroy(Bl);
    rad_baker_result_destroy(Be);
}

/* The lightmap and the probes mix as the vertices do: the two rooms with the left room's lamp
   (group 0) and a point light in the right room (group 1). */
static void bk_test_layers_lightmap_probes(void)
{
    lm_soup room, wall, lamp;
    rad_mesh_desc meshes[3];
    rad_material mats[2];
    rad_baker_desc d;
    rad_baker_options o;
    rad_baker_result *R = NULL;
    rad_baker_light bl;
    const float probe_at[6] = { 0.5f, 0.5f, 0.5f, 1.5f, 0.5f, 0.5f };
    const float sc[6] = { 0.25f, 1.0f, 2.0f, 4.0f, 0.5f, 0.0f };
    size_t i, nt, np;
    double left0 = 0.0, right0 = 0.0, right1 = 0.0;
    uint32_t x, y;
    memset(&d, 0, sizeof d);
    fx_two_rooms(&room, &wall, &lamp, meshes, &d.scene, mats);
    memset(&bl, 0, sizeof bl);
    bl.light.type = RAD_LIGHT_POINT;
    bl.light.position[0] = 1.5f; bl.light.position[1] = 0.8f; bl.light.position[2] = 0.5f;
    bl.light.color[0] = bl.light.color[1] = bl.light.color[2] = 1.0f;
    bl.group = 1;
    d.lights = &bl;
    d.light_count = 1;
    d.outputs = RAD_BAKER_VERTEX | RAD_BAKER_LIGHTMAP | RAD_BAKER_PROBES;
    d.lightmap_width = 32;
    d.lightmap_height = 16;
    d.probe_positions = probe_at;
    d.probe_count = 2;
    bk_options(&o, RAD_BAKER_CLASSIC);
    o.patches = rad_test_quick() ? 80u : 150u;
    o.lightmap_samples = 1;
    CHECK_OK(rad_baker_run(&d, &o, NULL, &R));
    if (!R) return;
    CHECK(R->lightmap_width == 32 && R->lightmap_height == 16 && R->probe_count == 2 && R->group_count == 2);
    CHECK(R->lightmap_flags != NULL && R->probe_grid[0] == 0);
    nt = 3 * (size_t)R->lightmap_width * R->lightmap_height;
    np = 27 * (size_t)R->probe_count;
    /* the floor's uv is (x / 2, z): the left room's floor is u < 0.49, the right room's u > 0.53 */
    for (y = 0; y < R->lightmap_height; ++y)
        for (x = 0; x < R->lightmap_width; ++x) {
            size_t t = 3 * ((size_t)x + (size_t)R->lightmap_width * y);
            float u = ((float)x + 0.5f) / (float)R->lightmap_width;
            if (u < 0.45f) left0 += R->lightmap_layers[t];
            if (u > 0.58f) right0 += R->lightmap_layers[t], right1 += R->lightmap_layers[nt + t];
        }
    CHECK(left0 > 0.0 && right1 > 0.0);
    CHECK(right0 < 0.02 * left0); /* the wall keeps the lamp's bounced light out of the right room */
    CHECK(R->probe_layers[0] > 0.0f && R->probe_layers[np + 27] > 0.0f);
    CHECK_OK(rad_baker_mix(R, sc, NULL));
    for (i = 0; i < nt; ++i) {
        double want = (double)sc[i % 3] * R->lightmap_layers[i] + (double)sc[3 + i % 3] * R->lightmap_layers[nt + i];
        CHECK_NEAR(R->lightmap[i], want, 1e-6 * fabs(want) + 1e-12);
    }
    for (i = 0; i < np; ++i) {
        double want = (double)sc[i % 3] * R->probe_layers[i] + (double)sc[3 + i % 3] * R->probe_layers[np + i];
        CHECK_NEAR(R->probes[i], want, 1e-6 * fabs(want) + 1e-12);
    }
    rad_baker_result_destroy(R);
}

/* Emitters in two groups (the ceiling light 0, a glowing short block 1): each layer equals the
   bake with only that group's material emitting, bit for bit, for both methods (the group's
   view of the scene keeps only its own emission). */
static void bk_test_emitter_groups(void)
{
    rad_baker_desc d, one;
    rad_baker_options o;
    rad_baker_result *A = NULL, *B0 = NULL, *B1 = NULL;
    rad_mesh_desc meshes[16];
    rad_material mats[17], m0[17], m1[17];
    uint32_t groups[17], i, glow, pass;
    memset(&d, 0, sizeof d);
    rad_cornell_box(&d.scene, NULL);
    CHECK(d.scene.mesh_count <= 16 && d.scene.material_count < 17);
    if (d.scene.mesh_count > 16 || d.scene.material_count >= 17) return;
    for (i = 0; i < d.scene.mesh_count; ++i) meshes[i] = d.scene.meshes[i];
    for (i = 0; i < d.scene.material_count; ++i) mats[i] = d.scene.materials[i], groups[i] = 0;
    glow = d.scene.material_count; /* a new material: white, glowing faintly blue */
    mats[glow] = mats[meshes[6].material];
    mats[glow].emission[0] = 0.5f; mats[glow].emission[1] = 1.0f; mats[glow].emission[2] = 3.0f;
    groups[glow] = 1;
    CHECK(meshes[6].material_ids == NULL && strcmp(meshes[6].name, "shortblock") == 0);
    meshes[6].material = glow;
    d.scene.meshes = meshes;
    d.scene.materials = mats;
    d.scene.material_count = glow + 1;
    d.material_groups = groups;
    for (i = 0; i <= glow; ++i) { /* m0: group 0's emission only, m1: group 1's */
        m0[i] = m1[i] = mats[i];
        if (groups[i] != 0) m0[i].emission[0] = m0[i].emission[1] = m0[i].emission[2] = 0.0f;
        if (groups[i] != 1) m1[i].emission[0] = m1[i].emission[1] = m1[i].emission[2] = 0.0f;
    }
    for (pass = 0; pass < 2; ++pass) {
        size_t nv;
        bk_options(&o, pass ? RAD_BAKER_VIRTUAL_PATCHES : RAD_BAKER_CLASSIC);
        o.patches = rad_test_quick() ? 60u : 120u;
        o.vp_resolution = 4;
        o.light_samples = 4;
        CHECK_OK(rad_baker_run(&d, &o, NULL, &A));
        one = d;
        one.material_groups = NULL;
        one.scene.materials = m0;
        CHECK_OK(rad_baker_run(&one, &o, NULL, &B0));
        one.scene.materials = m1;
        CHECK_OK(rad_baker_run(&one, &o, NULL, &B1));
        if (A && B0 && B1) {
            nv = 3 * (size_t)A->vertex_count;
            CHECK(A->group_count == 2);
            CHECK(bk_same_bits(A->vertex_layers, B0->vertex, nv));
            CHECK(bk_same_bits(A->vertex_layers + nv, B1->vertex, nv));
            CHECK(!bk_same_bits(B0->vertex, B1->vertex, nv));
        }
        rad_baker_result_destroy(A);
        rad_baker_result_destroy(B0);
        rad_baker_result_destroy(B1);
        A = B0 = B1 = NULL;
    }
}

typedef struct bk_progress {
    int calls, stop_at, backwards, out_of_range;
    float last;
} bk_progress;

static int bk_progress_fn(void *user, float f)
{
    bk_progress *p = (bk_progress *)user;
    ++p->calls;
    if (f < p->last) p->backwards++;
    if (!(f >= 0.0f && f <= 1.0f)) p->out_of_range++;
    p->last = f;
    return p->stop_at && p->calls >= p->stop_at;
}

/* Progress runs from 0 to 1 without going back; a cancel at any call returns CANCELLED and
   leaves nothing allocated (the counting allocator's live bytes, and ASan). */
static void bk_test_cancel(void)
{
    rad_baker_desc d;
    rad_baker_options o;
    rad_baker_result *R = NULL;
    rad_baker_light bl;
    rad_context ctx;
    sc_alloc_state st;
    bk_progress p;
    int stops[5], k, total;
    memset(&d, 0, sizeof d);
    rad_cornell_box(&d.scene, NULL);
    bk_lamp(&bl.light);
    bl.group = 1;
    d.lights = &bl;
    d.light_count = 1;
    bk_options(&o, RAD_BAKER_CLASSIC);
    o.patches = 100;
    memset(&st, 0, sizeof st);
    sc_ctx_alloc(&ctx, &st);
    memset(&p, 0, sizeof p);
    ctx.progress = bk_progress_fn;
    ctx.progress_user = &p;
    CHECK_OK(rad_baker_run(&d, &o, &ctx, &R));
    CHECK(p.backwards == 0 && p.out_of_range == 0);
    CHECK(p.last == 1.0f);
    total = p.calls;
    CHECK(total > 4);
    rad_baker_result_destroy(R);
    CHECK(st.live_bytes == 0);
    stops[0] = 1; stops[1] = 2; stops[2] = total / 3; stops[3] = (2 * total) / 3; stops[4] = total;
    for (k = 0; k < 5; ++k) {
        memset(&p, 0, sizeof p);
        p.stop_at = stops[k] > 0 ? stops[k] : 1;
        R = (rad_baker_result *)&p; /* must come back NULL */
        CHECK_RESULT(rad_baker_run(&d, &o, &ctx, &R), RAD_ERROR_CANCELLED);
        CHECK(R == NULL);
        CHECK(p.calls == p.stop_at);
        CHECK(st.live_bytes == 0);
    }
    CHECK(st.corrupt == 0);
}

/* NULL options and a zeroed struct are the defaults, and give the same bits */
static void bk_test_zeroed_options(void)
{
    rad_baker_desc d;
    rad_baker_options o;
    rad_baker_result *A = NULL, *B = NULL;
    uint32_t i;
    memset(&d, 0, sizeof d);
    rad_cornell_box(&d.scene, NULL); /* the ceiling light is the only source: no light needed */
    memset(&o, 0, sizeof o);
    CHECK_OK(rad_baker_run(&d, NULL, NULL, &A));
    CHECK_OK(rad_baker_run(&d, &o, NULL, &B));
    if (!A || !B) goto done;
    CHECK(A->method == RAD_BAKER_CLASSIC && A->group_count == 1);
    CHECK(A->patch_count >= 400 && A->patch_count <= 700); /* near the default target */
    CHECK(A->vertex && !A->lightmap && !A->probes);        /* outputs 0: the vertices */
    CHECK(bk_same_bits(A->vertex, B->vertex, 3 * (size_t)A->vertex_count));
    for (i = 0; i < 3 * A->vertex_count; ++i) CHECK(A->vertex[i] >= 0.0f && A->vertex[i] < 1e30f);
done:
    rad_baker_result_destroy(A);
    rad_baker_result_destroy(B);
}

static void bk_test_bad_input(void)
{
    rad_baker_desc d, bad;
    rad_baker_options o;
    rad_baker_light bl;
    rad_baker_result *R = NULL;
    rad_mesh_desc meshes[16];
    rad_material mats[16];
    uint32_t idx[6] = { 0, 1, 2, 0, 2, 7 }, groups[16], i;
    float lm_scale[2] = { 1.0f, 1.0f };
    memset(&d, 0, sizeof d);
    rad_cornell_box(&d.scene, NULL);
    bk_lamp(&bl.light);
    bl.group = 0;
    d.lights = &bl;
    d.light_count = 1;
    bk_options(&o, RAD_BAKER_AUTO);

    CHECK_RESULT(rad_baker_run(NULL, &o, NULL, &R), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_baker_run(&d, &o, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    /* nothing emits */
    bad = d;
    for (i = 0; i < d.scene.material_count && i < 16; ++i) {
        mats[i] = d.scene.materials[i];
        mats[i].emission[0] = mats[i].emission[1] = mats[i].emission[2] = 0.0f;
    }
    bad.scene.materials = mats;
    bad.lights = NULL;
    bad.light_count = 0;
    fx_baker_expect(&bad, &o, RAD_ERROR_INVALID_ARGUMENT, "nothing emits");
    /* a light beyond the groups */
    bad = d;
    bad.group_count = 1;
    bl.group = 1;
    fx_baker_expect(&bad, &o, RAD_ERROR_INVALID_ARGUMENT, "group");
    bl.group = RAD_BAKER_MAX_GROUPS;
    bad.group_count = 0;
    fx_baker_expect(&bad, &o, RAD_ERROR_INVALID_ARGUMENT, "group");
    bl.group = 0;
    /* an emissive material beyond the groups */
    for (i = 0; i < 16; ++i) groups[i] = 3;
    bad = d;
    bad.material_groups = groups;
    bad.group_count = 2;
    fx_baker_expect(&bad, &o, RAD_ERROR_INVALID_ARGUMENT, "emissive material");
    /* a lightmap, but no mesh has lightmap uvs */
    bad = d;
    bad.outputs = RAD_BAKER_LIGHTMAP;
    fx_baker_expect(&bad, &o, RAD_ERROR_INVALID_ARGUMENT, "lightmap_uvs");
    /* unknown method and output bits, a negative budget */
    bad = d;
    bad.outputs = 16; /* the bit after RAD_BAKER_SOLUTION */
    fx_baker_expect(&bad, &o, RAD_ERROR_INVALID_ARGUMENT, "output");
    o.method = (rad_baker_method)7;
    fx_baker_expect(&d, &o, RAD_ERROR_INVALID_ARGUMENT, "method");
    bk_options(&o, RAD_BAKER_AUTO);
    o.max_memory = -1.0;
    fx_baker_expect(&d, &o, RAD_ERROR_INVALID_ARGUMENT, "max_memory");
    bk_options(&o, RAD_BAKER_AUTO);
    /* a bad mesh: an index out of range, a NaN position (the scene's own errors) */
    CHECK(d.scene.mesh_count <= 16);
    for (i = 0; i < d.scene.mesh_count && i < 16; ++i) meshes[i] = d.scene.meshes[i];
    bad = d;
    bad.scene.meshes = meshes;
    meshes[0].indices = idx;
    meshes[0].triangle_count = 2;
    meshes[0].vertex_count = 4;
    fx_baker_expect(&bad, &o, RAD_ERROR_INDEX_OUT_OF_RANGE, NULL);
    meshes[0] = d.scene.meshes[0];
    {
        float pos[12];
        memcpy(pos, d.scene.meshes[0].positions, sizeof pos);
        pos[4] = NAN;
        meshes[0].positions = pos;
        meshes[0].position_stride = 0;
        meshes[0].vertex_count = 4;
        fx_baker_expect(&bad, &o, RAD_ERROR_NON_FINITE, NULL);
    }
    /* a bad light: a NaN colour */
    bl.light.color[1] = NAN;
    fx_baker_expect(&d, &o, RAD_ERROR_NON_FINITE, NULL);
    bk_lamp(&bl.light);
    /* a budget too small for any bake, and a classic bake forced over the budget */
    o.max_memory = 4096.0;
    fx_baker_expect(&d, &o, RAD_ERROR_OUT_OF_MEMORY, "too small");
    bk_options(&o, RAD_BAKER_CLASSIC);
    o.max_memory = 65536.0;
    fx_baker_expect(&d, &o, RAD_ERROR_OUT_OF_MEMORY, "budget");
    /* the mix: NULL, a NaN scale */
    CHECK_RESULT(rad_baker_mix(NULL, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_baker_mix_layers(lm_scale, 1, 1, NULL, lm_scale, NULL), RAD_ERROR_INVALID_ARGUMENT);
    {
        float layers[6] = { 1, 2, 3, 4, 5, 6 }, outv[3], s[6] = { 1, 1, 1, 1, NAN, 1 };
        CHECK_RESULT(rad_baker_mix_layers(layers, 2, 3, s, outv, NULL), RAD_ERROR_NON_FINITE);
        s[4] = 2.0f;
        CHECK_OK(rad_baker_mix_layers(layers, 2, 3, s, outv, NULL));
        CHECK(outv[0] == 5.0f && outv[1] == 12.0f && outv[2] == 9.0f);
        s[0] = s[1] = s[2] = s[3] = s[4] = s[5] = 0.0f; /* every group off: zeros */
        CHECK_OK(rad_baker_mix_layers(layers, 2, 3, s, outv, NULL));
        CHECK(outv[0] == 0.0f && outv[1] == 0.0f && outv[2] == 0.0f);
    }
}

/* the mix kernel against a plain loop, over sizes that are not multiples of its steps and
   more groups than it reads in one pass */
static void bk_test_mix_kernel(void)
{
    const size_t n = 3 * 70001; /* past one task chunk, a tail of 12-float steps */
    const uint32_t G = 11;
    float *layers = (float *)malloc(sizeof(float) * n * G), *out = (float *)malloc(sizeof(float) * n);
    float s[33];
    size_t i;
    uint32_t g;
    int bad = 0;
    if (!layers || !out) {
        CHECK(0);
        free(layers);
        free(out);
        return;
    }
    for (i = 0; i < n * G; ++i) layers[i] = (float)((i * 2654435761u) % 1000u) * 0.001f;
    for (g = 0; g < 33; ++g) s[g] = 0.1f * (float)(g + 1);
    s[6] = s[7] = s[8] = 0.0f; /* group 2 off */
    CHECK_OK(rad_baker_mix_layers(layers, G, n, s, out, NULL));
    for (i = 0; i < n; ++i) {
        float want = 0.0f;
        int first = 1;
        for (g = 0; g < G; ++g) {
            if (g == 2) continue;
            want = first ? layers[g * n + i] * s[3 * g + i % 3] : want + layers[g * n + i] * s[3 * g + i % 3];
            first = 0;
        }
        bad += !(fabsf(out[i] - want) <= 1e-6f * want);
    }
    CHECK(bad == 0);
    free(layers);
    free(out);
}

/* a parallel_for that runs the tasks in reverse order on the calling thread */
static void bk_reverse_for(void *user, uint32_t count, rad_task_fn fn, void *data)
{
    uint32_t i;
    (void)user;
    for (i = count; i-- > 0;) fn(data, i);
}

/* another task split and order give the same bits (classic with a lightmap and probes, and
   virtual patches) */
static void bk_test_deterministic(void)
{
    lm_soup room, wall, lamp;
    rad_mesh_desc meshes[3];
    rad_material mats[2];
    rad_baker_desc d;
    rad_baker_options o;
    rad_baker_result *A = NULL, *B = NULL;
    rad_context ctx;
    int pass;
    memset(&d, 0, sizeof d);
    fx_two_rooms(&room, &wall, &lamp, meshes, &d.scene, mats);
    d.outputs = RAD_BAKER_VERTEX | RAD_BAKER_LIGHTMAP | RAD_BAKER_PROBES;
    d.lightmap_width = 16;
    d.probe_spacing = 0.5f;
    memset(&ctx, 0, sizeof ctx);
    ctx.parallel_for = bk_reverse_for;
    ctx.task_count = 7;
    for (pass = 0; pass < 2; ++pass) {
        bk_options(&o, pass ? RAD_BAKER_VIRTUAL_PATCHES : RAD_BAKER_CLASSIC);
        o.patches = 80;
        o.vp_resolution = 6;
        o.lightmap_samples = 1;
        CHECK_OK(rad_baker_run(&d, &o, NULL, &A));
        CHECK_OK(rad_baker_run(&d, &o, &ctx, &B));
        if (A && B) {
            CHECK(A->method == B->method && A->patch_count == B->patch_count && A->probe_count == B->probe_count);
            CHECK(A->probe_count > 8 && A->probe_grid[0] > 1);
            CHECK(bk_same_bits(A->vertex_layers, B->vertex_layers, 3 * (size_t)A->vertex_count));
            CHECK(bk_same_bits(A->lightmap_layers, B->lightmap_layers, 3 * (size_t)A->lightmap_width * A->lightmap_height));
            CHECK(bk_same_bits(A->probe_layers, B->probe_layers, 27 * (size_t)A->probe_count));
        }
        rad_baker_result_destroy(A);
        rad_baker_result_destroy(B);
        A = B = NULL;
    }
}

static const rad_test_case tests_bake[] = {
    { "bake_classic_lower_level", bk_test_classic_lower_level },
    { "bake_auto_vp_lower_level", bk_test_auto_vp_lower_level },
    { "bake_layers_cornell", bk_test_layers_cornell },
    { "bake_layers_lightmap_probes", bk_test_layers_lightmap_probes },
    { "bake_emitter_groups", bk_test_emitter_groups },
    { "bake_cancel", bk_test_cancel },
    { "bake_zeroed_options", bk_test_zeroed_options },
    { "bake_bad_input", bk_test_bad_input },
    { "bake_mix_kernel", bk_test_mix_kernel },
    { "bake_deterministic", bk_test_deterministic },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_bake)

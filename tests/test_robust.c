/* test_robust.c - numeric robustness and determinism: the Cornell
   box scaled by 1e-3 and 1e4 gives the same lighting; hard geometry (coincident, touching,
   nearly parallel patches, thin triangles, albedo contrast, huge emission, tiny and huge
   scenes, one triangle) never puts a NaN or Inf into any output; the BVH on degenerate-ish
   inputs; bit-identical results run to run and across thread counts, task counts and task
   orders (THREADING). Everything static and prefixed rb_. */
#include "fixtures.h"

#include <pthread.h>

/* ---- helpers -------------------------------------------------------------------------------- */

/* the number of non-finite floats in p[0..n) */
static size_t rb_nonfinite(const float *p, size_t n)
{
    size_t i, bad = 0;
    for (i = 0; i < n; ++i) if (!(p[i] - p[i] == 0.0f)) bad++;
    return bad;
}

#define RB_SCAN(what, p, n)                                                                         \
    do {                                                                                            \
        size_t bad_ = rb_nonfinite((p), (n));                                                       \
        if (bad_) printf("    %s: %s has %llu non-finite of %llu floats\n", rb_case, (what),       \
                         (unsigned long long)bad_, (unsigned long long)(n));                       \
        CHECK(bad_ == 0);                                                                           \
    } while (0)

static const char *rb_case = "";

/* the NaN scans and the scale test run serially: their subject is numerics, and with many
   tiny calls the OpenMP default spends more time starting regions than working (determinism
   covers the default context) */
static const rad_context *rb_serial_ctx(void)
{
    static rad_context c;
    memset(&c, 0, sizeof(c));
    c.parallel_for = fx_serial_for;
    return &c;
}

/* a scene from loose triangles: tris[9 t .. 9 t + 8], material mats[t] (NULL: 0) */
static rad_result rb_scene(const float *tris, uint32_t count, const uint32_t *mats, const rad_material *materials,
                           uint32_t material_count, rad_scene **out)
{
    rad_mesh_desc m;
    rad_scene_desc d;
    memset(&m, 0, sizeof(m));
    m.name = "rb";
    m.positions = tris;
    m.vertex_count = 3 * count;
    m.triangle_count = count;
    m.material_ids = mats;
    memset(&d, 0, sizeof(d));
    d.meshes = &m;
    d.mesh_count = 1;
    d.materials = materials;
    d.material_count = material_count;
    return rad_scene_create(&d, NULL, out);
}

/* a quad (two triangles) from a corner and two edge vectors; front = u x v */
static float *rb_quad(float *dst, const float o[3], const float u[3], const float v[3])
{
    int k;
    for (k = 0; k < 3; ++k) {
        dst[k] = o[k];              dst[3 + k] = o[k] + u[k];        dst[6 + k] = o[k] + u[k] + v[k];
        dst[9 + k] = o[k];          dst[12 + k] = o[k] + u[k] + v[k]; dst[15 + k] = o[k] + v[k];
    }
    return dst + 18;
}

static void rb_materials(rad_material m[4], float emission)
{
    int k;
    memset(m, 0, 4 * sizeof(rad_material));
    for (k = 0; k < 3; ++k) {
        m[0].albedo[k] = 0.5f;          /* grey */
        m[1].albedo[k] = 0.0f;          /* black */
        m[2].albedo[k] = 0.999f;        /* white */
        m[3].albedo[k] = 0.3f;          /* light */
        m[3].emission[k] = emission;
    }
}

/* Every output of the pipeline on 'scene', scanned for NaN and Inf: patches, form factors
   (dense, sparse, rows), direct light (patches and points), sources, every solver. Documented
   solver outcomes (NOT_CONVERGED, SINGULAR) are accepted; outputs written with
   NOT_CONVERGED are scanned too. */
static void rb_pipeline(const rad_scene *S, float max_edge_rel)
{
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_direct_options dop;
    rad_solve_options so;
    rad_solve_stats st;
    rad_patches *P = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_form_factors *ffd = NULL, *ffs = NULL;
    rad_light lights[3];
    rad_system sys;
    float *rows = NULL, *D = NULL, *E = NULL, *B = NULL, *pts = NULL, *nrm = NULL, *Dp = NULL;
    uint32_t n, i, half, s, mode;
    size_t n3;
    rad_result r;
    int k;
    RB_SCAN("scene positions", S->positions, 9 * (size_t)S->triangle_count);
    RB_SCAN("scene normals", S->normals, 3 * (size_t)S->triangle_count);
    RB_SCAN("scene areas", S->areas, S->triangle_count);
    CHECK(S->diagonal > 0.0f && S->diagonal - S->diagonal == 0.0f);
    rad_patch_options_default(&po);
    po.max_edge = max_edge_rel * S->diagonal;
    r = rad_patches_create(S, &po, NULL, &P);
    CHECK_OK(r);
    if (r != RAD_SUCCESS) return;
    n = P->count;
    n3 = 3 * (size_t)n;
    RB_SCAN("patch vertices", P->vertices, 3 * (size_t)P->vertex_count);
    RB_SCAN("patch areas", P->areas, n);
    RB_SCAN("patch albedo", P->albedo, n3);
    for (i = 0; i < n; ++i) {
        RB_SCAN("patch centroid", P->patches[i].centroid, 3);
        RB_SCAN("patch normal", P->patches[i].normal, 3);
        CHECK(P->patches[i].area > 0.0f);
        if (rad_test_failures > 20) break;
    }
    CHECK_OK(rad_bvh_create(S, NULL, &bvh));
    rad_bvh_raycaster(bvh, &rc);
    rows = (float *)malloc(sizeof(float) * (size_t)n * n);
    D = (float *)malloc(sizeof(float) * n3);
    Dp = (float *)malloc(sizeof(float) * n3);
    E = (float *)malloc(sizeof(float) * n3);
    B = (float *)malloc(sizeof(float) * n3);
    pts = (float *)malloc(sizeof(float) * n3);
    nrm = (float *)calloc(n3, sizeof(float));
    if (!bvh || !rows || !D || !Dp || !E || !B || !pts || !nrm) { CHECK(0); goto done; }
    /* form factors, both methods for dense; sparse and rows with the analytic one */
    for (k = 1; k >= 0; --k) {
        rad_form_factor_options_default(&fo);
        fo.method = k ? RAD_FF_MONTE_CARLO : RAD_FF_ANALYTIC;
        rad_form_factors_destroy(ffd);
        ffd = NULL;
        CHECK_OK(rad_form_factors_dense(P, &rc, &fo, rb_serial_ctx(), &ffd));
        if (ffd) RB_SCAN(k ? "dense form factors (Monte Carlo)" : "dense form factors", ffd->matrix.dense, (size_t)n * n);
    }
    CHECK_OK(rad_form_factors_sparse(P, &rc, &fo, rb_serial_ctx(), &ffs));
    if (ffs) RB_SCAN("sparse form factors", ffs->matrix.values, (size_t)ffs->matrix.row_offsets[n]);
    half = n / 2;
    CHECK_OK(rad_form_factor_rows(P, &rc, &fo, 0, half, rows, rb_serial_ctx()));
    CHECK_OK(rad_form_factor_rows(P, &rc, &fo, half, n, rows + (size_t)half * n, rb_serial_ctx()));
    RB_SCAN("form factor rows", rows, (size_t)n * n);
    fo.skip_visibility = 1;
    CHECK_OK(rad_form_factor_rows(P, NULL, &fo, 0, n, rows, rb_serial_ctx()));
    RB_SCAN("unoccluded form factor rows", rows, (size_t)n * n);
    if (!ffd) goto done;
    /* direct light: emitters, a point light inside the bounds, the sky */
    memset(lights, 0, sizeof(lights));
    for (k = 0; k < 3; ++k) {
        lights[0].color[k] = 1.0f;
        lights[0].position[k] = 0.5f * (S->bounds_min[k] + S->bounds_max[k]) + 0.1f * (S->bounds_max[k] - S->bounds_min[k]);
        lights[1].color[k] = 0.5f;
        lights[2].color[k] = 0.25f;
    }
    lights[0].type = RAD_LIGHT_POINT;
    lights[1].type = RAD_LIGHT_SKY;
    lights[2].type = RAD_LIGHT_DIRECTIONAL;
    lights[2].direction[0] = 0.3f; lights[2].direction[1] = -1.0f; lights[2].direction[2] = -0.2f;
    rad_direct_options_default(&dop);
    CHECK_OK(rad_direct_patches(P, &rc, lights, 3, &dop, Dp, rb_serial_ctx()));
    RB_SCAN("direct irradiance (patches)", Dp, n3);
    for (i = 0; i < n; ++i)
        for (k = 0; k < 3; ++k) { pts[3 * i + k] = P->patches[i].centroid[k]; nrm[3 * i + k] = P->patches[i].normal[k]; }
    CHECK_OK(rad_direct_irradiance(S, &rc, lights, 3, &dop, pts, nrm, n, D, rb_serial_ctx()));
    RB_SCAN("direct irradiance (points)", D, n3);
    /* sources and solvers, both source modes */
    for (mode = 0; mode < 2; ++mode) {
        if (mode == 0) CHECK_OK(rad_sources(P, RAD_SOURCE_EMISSION, NULL, E));
        else CHECK_OK(rad_sources(P, RAD_SOURCE_DIRECT, Dp, E));
        RB_SCAN("E", E, n3);
        for (k = 0; k < 2; ++k) {
            rad_system_init(&sys, k ? &ffs->matrix : &ffd->matrix, P, E);
            CHECK_OK(rad_matrix_multiply(sys.F, E, B, rb_serial_ctx()));
            RB_SCAN("F E", B, n3);
            for (s = 0; s < 4; ++s) {
                const char *names[4] = { "jacobi", "gauss-seidel", "progressive", "direct" };
                rad_solve_options_default(&so);
                so.output = (s & 1) ? RAD_OUTPUT_TOTAL : RAD_OUTPUT_INDIRECT;
                so.bounces = 50;
                so.max_iterations = s == 2 ? 20000u : 0u;
                if (s == 0) r = rad_solve_jacobi(&sys, &so, B, &st, rb_serial_ctx());
                else if (s == 1) r = rad_solve_gauss_seidel(&sys, &so, B, &st, rb_serial_ctx());
                else if (s == 2) r = rad_solve_progressive(&sys, &so, B, &st, rb_serial_ctx());
                else r = rad_solve_direct(&sys, &so, B, rb_serial_ctx());
                if (r != RAD_SUCCESS && !(r == RAD_ERROR_NOT_CONVERGED && (s == 1 || s == 2)) &&
                    !(r == RAD_ERROR_SINGULAR && s == 3)) {
                    printf("    %s: solver %s returned %s\n", rb_case, names[s], rad_result_string(r));
                    CHECK(0);
                } else if (r != RAD_ERROR_SINGULAR) {
                    RB_SCAN(names[s], B, n3);
                }
            }
        }
        {
            float *vv = (float *)malloc(sizeof(float) * 3 * (size_t)P->vertex_count);
            CHECK(vv != NULL);
            if (vv) {
                CHECK_OK(rad_patches_vertex_values(P, B, 3, vv));
                RB_SCAN("vertex values", vv, 3 * (size_t)P->vertex_count);
                free(vv);
            }
        }
    }
done:
    free(rows); free(D); free(Dp); free(E); free(B); free(pts); free(nrm);
    rad_form_factors_destroy(ffd);
    rad_form_factors_destroy(ffs);
    rad_bvh_destroy(bvh);
    rad_patches_destroy(P);
}

/* builds the scene from 'tris' and runs the pipeline; a scene that cannot be built must fail
   with one of the documented validation errors */
static void rb_run(const char *name, const float *tris, uint32_t count, const uint32_t *mats, float emission,
                   float max_edge_rel)
{
    rad_material m[4];
    rad_scene *S = NULL;
    rad_result r;
    rb_case = name;
    rb_materials(m, emission);
    r = rb_scene(tris, count, mats, m, 4, &S);
    if (r != RAD_SUCCESS) {
        printf("    %s: rad_scene_create: %s\n", name, rad_result_string(r));
        CHECK(r == RAD_ERROR_DEGENERATE_TRIANGLE || r == RAD_ERROR_NON_FINITE || r == RAD_ERROR_EMPTY_SCENE ||
              r == RAD_ERROR_SCALE_RANGE);
        CHECK(S == NULL);
        return;
    }
    rb_pipeline(S, max_edge_rel);
    rad_scene_destroy(S);
}

/* a unit-ish box floor to carry light onto: floor quad z=0 facing +z, a light above facing down */
static float *rb_light_above(float *dst, float z)
{
    const float o[3] = { 0.2f, 0.2f, 0.0f }, u[3] = { 0.0f, 0.6f, 0.0f }, v[3] = { 0.6f, 0.0f, 0.0f };
    float oo[3];
    oo[0] = o[0]; oo[1] = o[1]; oo[2] = z;
    return rb_quad(dst, oo, u, v); /* u x v = -z: faces down */
}

/* ---- scale invariance ------------------------------------------------------------------------ */

typedef struct rb_scaled {
    float *pos;
    rad_mesh_desc meshes[16];
    rad_scene_desc desc;
    rad_scene *scene;
    rad_patches *P;
    rad_bvh *bvh;
    rad_raycaster rc;
    rad_form_factors *ff;
    float *E, *B, *D, *Dpt;
} rb_scaled;

static int rb_scaled_build(rb_scaled *c, float scale, uint32_t target)
{
    rad_scene_desc base;
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_solve_options so;
    rad_system sys;
    rad_direct_options dop;
    rad_light pl;
    uint32_t m, v, total = 0, at = 0, n;
    int k;
    memset(c, 0, sizeof(*c));
    rad_cornell_box(&base, NULL);
    if (base.mesh_count > 16) return 0;
    for (m = 0; m < base.mesh_count; ++m) total += base.meshes[m].vertex_count;
    c->pos = (float *)malloc(sizeof(float) * 3 * total);
    if (!c->pos) return 0;
    for (m = 0; m < base.mesh_count; ++m) {
        const rad_mesh_desc *src = &base.meshes[m];
        size_t stride = src->position_stride ? src->position_stride : 3 * sizeof(float);
        c->meshes[m] = *src;
        for (v = 0; v < src->vertex_count; ++v) {
            const float *p = (const float *)(const void *)((const char *)src->positions + stride * v);
            for (k = 0; k < 3; ++k) c->pos[3 * (at + v) + k] = p[k] * scale;
        }
        c->meshes[m].positions = c->pos + 3 * at;
        c->meshes[m].position_stride = 0;
        at += src->vertex_count;
    }
    c->desc = base;
    c->desc.meshes = c->meshes;
    if (rad_scene_create(&c->desc, NULL, &c->scene) != RAD_SUCCESS) return 0;
    rad_patch_options_default(&po);
    po.target_count = target;
    if (rad_patches_create(c->scene, &po, NULL, &c->P) != RAD_SUCCESS) return 0;
    if (rad_bvh_create(c->scene, NULL, &c->bvh) != RAD_SUCCESS) return 0;
    rad_bvh_raycaster(c->bvh, &c->rc);
    rad_form_factor_options_default(&fo);
    if (rad_form_factors_dense(c->P, &c->rc, &fo, rb_serial_ctx(), &c->ff) != RAD_SUCCESS) return 0;
    n = c->P->count;
    c->E = (float *)malloc(sizeof(float) * 3 * n);
    c->B = (float *)malloc(sizeof(float) * 3 * n);
    c->D = (float *)malloc(sizeof(float) * 3 * n);
    c->Dpt = (float *)malloc(sizeof(float) * 3 * n);
    if (!c->E || !c->B || !c->D || !c->Dpt) return 0;
    if (rad_sources(c->P, RAD_SOURCE_EMISSION, NULL, c->E) != RAD_SUCCESS) return 0;
    rad_system_init(&sys, &c->ff->matrix, c->P, c->E);
    rad_solve_options_default(&so);
    so.output = RAD_OUTPUT_TOTAL;
    if (rad_solve_direct(&sys, &so, c->B, rb_serial_ctx()) != RAD_SUCCESS) return 0;
    /* the area light alone */
    rad_direct_options_default(&dop);
    if (rad_direct_patches(c->P, &c->rc, NULL, 0, &dop, c->D, rb_serial_ctx()) != RAD_SUCCESS) return 0;
    /* a point light alone, at a scaled position */
    memset(&pl, 0, sizeof(pl));
    pl.type = RAD_LIGHT_POINT;
    for (k = 0; k < 3; ++k) pl.color[k] = 1.0f;
    pl.position[0] = 0.278f * scale; pl.position[1] = 0.45f * scale; pl.position[2] = 0.28f * scale;
    dop.exclude_emitters = 1;
    if (rad_direct_patches(c->P, &c->rc, &pl, 1, &dop, c->Dpt, rb_serial_ctx()) != RAD_SUCCESS) return 0;
    return 1;
}

static void rb_scaled_free(rb_scaled *c)
{
    free(c->E); free(c->B); free(c->D); free(c->Dpt);
    rad_form_factors_destroy(c->ff);
    rad_bvh_destroy(c->bvh);
    rad_patches_destroy(c->P);
    rad_scene_destroy(c->scene);
    free(c->pos);
}

static void rb_test_scale_invariance(void)
{
    const float scales[2] = { 1e-3f, 1e4f };
    const uint32_t target = rad_test_quick() ? 120 : 300;
    rb_scaled ref, c;
    uint32_t n, i, si;
    int ok = rb_scaled_build(&ref, 1.0f, target);
    CHECK(ok);
    if (!ok) { rb_scaled_free(&ref); return; }
    n = ref.P->count;
    for (si = 0; si < 2; ++si) {
        double s = scales[si], ffd = 0.0, bmax = 0.0, brel = 0.0, dmax = 0.0, drel = 0.0, pmax = 0.0, prel = 0.0;
        int before = rad_test_failures;
        ok = rb_scaled_build(&c, scales[si], target);
        CHECK(ok);
        if (!ok) { rb_scaled_free(&c); continue; }
        CHECK(c.P->count == n);
        if (c.P->count != n) { rb_scaled_free(&c); continue; }
        for (i = 0; i < 3 * n; ++i) {
            if (ref.B[i] > bmax) bmax = ref.B[i];
            if (ref.D[i] > dmax) dmax = ref.D[i];
            if (ref.Dpt[i] > pmax) pmax = ref.Dpt[i];
        }
        for (i = 0; i < n * n; ++i) {
            double d = fabs((double)c.ff->matrix.dense[i] - (double)ref.ff->matrix.dense[i]);
            if (!(d <= ffd)) ffd = d == d ? d : 1e30;
        }
        /* relative differences, with a floor of 1e-6 of the largest value for exact zeros */
        for (i = 0; i < 3 * n; ++i) {
            double d = fabs((double)c.B[i] - ref.B[i]) / (fabs((double)ref.B[i]) + 1e-6 * bmax);
            double e = fabs((double)c.D[i] - ref.D[i]) / (fabs((double)ref.D[i]) + 1e-6 * dmax);
            double f = fabs((double)c.Dpt[i] * s * s - ref.Dpt[i]) / (fabs((double)ref.Dpt[i]) + 1e-6 * pmax);
            if (!(d <= brel)) brel = d == d ? d : 1e30;
            if (!(e <= drel)) drel = e == e ? e : 1e30;
            if (!(f <= prel)) prel = f == f ? f : 1e30;
        }
        printf("    scale %g: %u patches, max |dF| %.3g, radiosity rel %.3g, area-light irradiance rel %.3g, point light s^2 D rel %.3g\n",
               s, n, ffd, brel, drel, prel);
        CHECK(ffd <= 1e-4);
        CHECK(brel <= 1e-4);
        CHECK(drel <= 1e-3);
        CHECK(prel <= 1e-3);
        if (rad_test_failures != before) printf("    ^ at scale %g\n", s);
        rb_scaled_free(&c);
    }
    rb_scaled_free(&ref);
}

/* ---- hard geometry --------------------------------------------------------------------------- */

static void rb_test_coincident(void)
{
    float t[18 * 4], *p;
    const float o[3] = { 0, 0, 0.5f }, u[3] = { 1, 0, 0 }, v[3] = { 0, 1, 0 }, o2[3] = { 0, 1, 0.5f }, v2[3] = { 0, -1, 0 };
    uint32_t mats[8] = { 0, 0, 2, 2, 3, 3, 0, 0 };
    /* facing each other: the same square, opposite windings; plus a light below and above */
    p = rb_quad(t, o, u, v);         /* faces +z */
    p = rb_quad(p, o2, u, v2);       /* the same square, faces -z */
    {
        const float lo[3] = { 0.2f, 0.2f, 1.0f }, lu[3] = { 0, 0.6f, 0 }, lv[3] = { 0.6f, 0, 0 };
        const float bo[3] = { 0.2f, 0.2f, 0.0f };
        p = rb_quad(p, lo, lu, lv);  /* light above, faces down */
        p = rb_quad(p, bo, lv, lu);  /* grey floor below, faces up */
    }
    rb_run("coincident, facing each other", t, 8, mats, 1.0f, 0.3f);
    /* facing the same way: two identical copies */
    p = rb_quad(t, o, u, v);
    p = rb_quad(p, o, u, v);
    p = rb_light_above(p, 1.0f);
    rb_run("coincident, same facing", t, 6, mats, 1.0f, 0.3f);
    (void)p;
}

/* two unit squares sharing the edge x = 0 (y in [0,1]) at dihedral 'deg' degrees (180: flat) */
static void rb_hinge(const char *name, double deg, int corner_only)
{
    float t[18 * 3], *p;
    const double a = (180.0 - deg) * 3.14159265358979323846 / 180.0;
    const float o[3] = { 0, 0, 0 }, u[3] = { -1, 0, 0 }, v[3] = { 0, 1, 0 };
    float u2[3], o2[3] = { 0, 0, 0 };
    uint32_t mats[6] = { 2, 2, 1, 1, 3, 3 };
    /* A: x in [-1, 0], faces +z. B: rotated up about the y axis by a, faces +z tilted */
    u2[0] = (float)cos(a); u2[1] = 0.0f; u2[2] = (float)sin(a);
    if (corner_only) { o2[1] = 1.0f; } /* B starts at A's corner (0,1,0) and goes on in +y */
    p = rb_quad(t, o, v, u);              /* v x u = +z */
    p = rb_quad(p, o2, u2, v);            /* u2 x v: normal (-sin a, 0, cos a) */
    p = rb_light_above(p, 2.0f);
    rb_run(name, t, 6, mats, 2.0f, 0.25f);
    (void)p;
}

static void rb_test_touching(void)
{
    rb_hinge("edge, 90 degrees", 90.0, 0);
    rb_hinge("edge, 179.9 degrees", 179.9, 0);
    rb_hinge("edge, 0.1 degrees (folded)", 0.1, 0);
    rb_hinge("corner, 90 degrees", 90.0, 1);
    rb_hinge("corner, 179.9 degrees", 179.9, 1);
}

static void rb_test_nearly_parallel(void)
{
    const float gaps[3] = { 1e-6f, 1e-7f, 1e-4f };
    int g, tilt;
    for (g = 0; g < 3; ++g)
        for (tilt = 0; tilt < 2; ++tilt) {
            float t[18 * 3], *p;
            const float o[3] = { 0, 0, 0 }, u[3] = { 1, 0, 0 }, v[3] = { 0, 1, 0 }, v2[3] = { 0, -1, 0 };
            float o2[3] = { 0, 1, 0 }, u2[3] = { 1, 0, 0 };
            uint32_t mats[6] = { 2, 2, 2, 2, 3, 3 };
            char name[96];
            o2[2] = gaps[g];
            if (tilt) u2[2] = 1e-3f; /* nearly parallel: 1e-3 radians */
            p = rb_quad(t, o, u, v);       /* faces +z */
            p = rb_quad(p, o2, u2, v2);    /* faces about -z, gap above */
            p = rb_light_above(p, 1.5f);
            sprintf(name, "%s at gap %g", tilt ? "nearly parallel" : "parallel, facing", (double)gaps[g]);
            rb_run(name, t, 6, mats, 1.0f, 0.3f);
            (void)p;
        }
}

static void rb_test_thin_triangles(void)
{
    const float aspects[2] = { 1e5f, 1e7f };
    int a;
    for (a = 0; a < 2; ++a) {
        float t[9 * 4 + 18], *p = t;
        uint32_t mats[6] = { 0, 2, 1, 0, 3, 3 };
        const float h = 1.0f / aspects[a];
        char name[64];
        int i;
        /* four slivers side by side in the floor plane, facing up */
        for (i = 0; i < 4; ++i) {
            float y = 0.1f + 0.2f * (float)i;
            p[0] = 0.0f; p[1] = y;     p[2] = 0.0f;
            p[3] = 1.0f; p[4] = y;     p[5] = 0.0f;
            p[6] = 0.5f; p[7] = y + h; p[8] = 0.0f;
            p += 9;
        }
        p = rb_light_above(p, 0.5f);
        sprintf(name, "thin triangles, aspect %g", (double)aspects[a]);
        rb_run(name, t, 6, mats, 1.0f, 0.3f);
        (void)p;
    }
}

static void rb_test_albedo_contrast(void)
{
    /* a 4 x 4 checkerboard of black (0) and white (0.999) quads in a closed box with a light:
       strong interreflection next to none */
    float t[18 * 22], *p = t;
    uint32_t mats[44], nt = 0, i, j;
    const float e1[3] = { 0.25f, 0, 0 }, e2[3] = { 0, 0.25f, 0 };
    for (i = 0; i < 4; ++i)
        for (j = 0; j < 4; ++j) {
            float o[3];
            o[0] = 0.25f * (float)i; o[1] = 0.25f * (float)j; o[2] = 0.0f;
            p = rb_quad(p, o, e1, e2);
            mats[nt++] = ((i + j) & 1) ? 2u : 1u;
            mats[nt++] = ((i + j) & 1) ? 2u : 1u;
        }
    {
        const float wo[3] = { 0, 0, 0 }, wz[3] = { 0, 0, 1 }, wx[3] = { 1, 0, 0 }, wy[3] = { 0, 1, 0 };
        const float co[3] = { 0, 0, 1 };
        p = rb_quad(p, wo, wz, wy);    /* wall x = 0, faces +x */
        mats[nt++] = 2; mats[nt++] = 2;
        p = rb_quad(p, wo, wx, wz);    /* wall y = 0, faces +y */
        mats[nt++] = 1; mats[nt++] = 1;
        p = rb_quad(p, co, wy, wx);    /* ceiling, faces down */
        mats[nt++] = 2; mats[nt++] = 2;
        p = rb_light_above(p, 0.95f);
        mats[nt++] = 3; mats[nt++] = 3;
    }
    rb_run("albedo 0 next to 0.999", t, nt, mats, 1.0f, 0.2f);
}

static void rb_test_huge_emission(void)
{
    float t[18 * 2], *p;
    const float o[3] = { 0, 0, 0 }, u[3] = { 1, 0, 0 }, v[3] = { 0, 1, 0 };
    uint32_t mats[4] = { 2, 2, 3, 3 };
    p = rb_quad(t, o, u, v);
    p = rb_light_above(p, 0.5f);
    rb_run("emission 1e30", t, 4, mats, 1e30f, 0.3f);
    (void)p;
    /* a finite radiance whose exitance pi L overflows float: the scene must be rejected
       (NEGATIVE_EMISSION: "not finite"), or E and the direct light must stay finite */
    {
        rad_material m[4];
        rad_scene *S = NULL;
        rad_patches *P = NULL;
        rad_bvh *bvh = NULL;
        rad_raycaster rc;
        float E[3 * 64], D[3 * 64];
        rad_result r;
        rb_case = "emission 3e38";
        rb_materials(m, 3e38f);
        r = rb_scene(t, 4, mats, m, 4, &S);
        if (r == RAD_SUCCESS) {
            CHECK_OK(rad_patches_create(S, NULL, NULL, &P));
            CHECK_OK(rad_bvh_create(S, NULL, &bvh));
            if (P && bvh && P->count <= 64) {
                rad_bvh_raycaster(bvh, &rc);
                r = rad_sources(P, RAD_SOURCE_EMISSION, NULL, E);
                CHECK(r == RAD_SUCCESS || r == RAD_ERROR_NON_FINITE);
                if (r == RAD_SUCCESS) RB_SCAN("E (RAD_SOURCE_EMISSION)", E, 3 * (size_t)P->count);
                r = rad_direct_patches(P, &rc, NULL, 0, NULL, D, NULL);
                CHECK(r == RAD_SUCCESS || r == RAD_ERROR_NON_FINITE);
                if (r == RAD_SUCCESS) RB_SCAN("direct irradiance", D, 3 * (size_t)P->count);
            }
            rad_bvh_destroy(bvh);
            rad_patches_destroy(P);
            rad_scene_destroy(S);
        } else {
            CHECK(r == RAD_ERROR_NEGATIVE_EMISSION);
        }
    }
}

static void rb_test_tiny_and_huge_scenes(void)
{
    const float sizes[6] = { 1e-20f, 1e-18f, 1e-15f, 1e-10f, 1e15f, 1e18f };
    int si;
    for (si = 0; si < 6; ++si) {
        float t[18 * 2], *p;
        float o[3] = { 0, 0, 0 }, u[3] = { 0, 0, 0 }, v[3] = { 0, 0, 0 }, lo[3], lu[3] = { 0, 0, 0 }, lv[3] = { 0, 0, 0 };
        uint32_t mats[4] = { 0, 0, 3, 3 };
        const float s = sizes[si];
        char name[64];
        u[0] = s; v[1] = s;
        lo[0] = 0.2f * s; lo[1] = 0.2f * s; lo[2] = 0.5f * s;
        lu[1] = 0.6f * s; lv[0] = 0.6f * s;
        p = rb_quad(t, o, u, v);
        p = rb_quad(p, lo, lu, lv);
        sprintf(name, "scene of size %g", (double)s);
        rb_run(name, t, 4, mats, 1.0f, 0.3f);
        (void)p;
    }
}

static void rb_test_single_triangle(void)
{
    const float t[9] = { 0, 0, 0, 1, 0, 0, 0, 1, 0 };
    const uint32_t lit[1] = { 3 };
    rb_run("one triangle", t, 1, NULL, 0.0f, 0.0f);
    rb_run("one emitting triangle", t, 1, lit, 1.0f, 0.0f);
    rb_run("one triangle, subdivided", t, 1, NULL, 0.0f, 0.1f);
}

/* ---- BVH on degenerate-ish inputs ------------------------------------------------------------- */

/* brute-force closest hit (Moller-Trumbore in double) for checking */
static int rb_brute(const rad_scene *S, const rad_ray *r, double *t_out, uint32_t *tri_out)
{
    uint32_t t;
    int hit = 0;
    double best = r->tmax;
    for (t = 0; t < S->triangle_count; ++t) {
        const float *v = S->positions + 9 * (size_t)t;
        double e1[3], e2[3], pv[3], tv[3], qv[3], det, u, w, tt;
        int k;
        for (k = 0; k < 3; ++k) { e1[k] = v[3 + k] - v[k]; e2[k] = v[6 + k] - v[k]; tv[k] = r->origin[k] - v[k]; }
        pv[0] = r->dir[1] * e2[2] - r->dir[2] * e2[1];
        pv[1] = r->dir[2] * e2[0] - r->dir[0] * e2[2];
        pv[2] = r->dir[0] * e2[1] - r->dir[1] * e2[0];
        det = e1[0] * pv[0] + e1[1] * pv[1] + e1[2] * pv[2];
        if (fabs(det) < 1e-300) continue;
        u = (tv[0] * pv[0] + tv[1] * pv[1] + tv[2] * pv[2]) / det;
        qv[0] = tv[1] * e1[2] - tv[2] * e1[1];
        qv[1] = tv[2] * e1[0] - tv[0] * e1[2];
        qv[2] = tv[0] * e1[1] - tv[1] * e1[0];
        w = (r->dir[0] * qv[0] + r->dir[1] * qv[1] + r->dir[2] * qv[2]) / det;
        tt = (e2[0] * qv[0] + e2[1] * qv[1] + e2[2] * qv[2]) / det;
        if (u < 0.0 || w < 0.0 || u + w > 1.0 || !(tt > r->tmin) || !(tt < best)) continue;
        best = tt;
        *tri_out = t;
        hit = 1;
    }
    *t_out = best;
    return hit;
}

static uint32_t rb_rng(uint32_t *s)
{
    *s ^= *s << 13; *s ^= *s >> 17; *s ^= *s << 5;
    return *s;
}

static float rb_unit(uint32_t *s) { return (float)(rb_rng(s) >> 8) / 16777216.0f; }

static void rb_test_bvh_degenerate(void)
{
    const uint32_t grid = 24, copies = 200;
    float *t = (float *)malloc(sizeof(float) * 18 * grid * grid + sizeof(float) * 9 * copies);
    rad_material m[4];
    int config;
    if (!t) { CHECK(0); return; }
    rb_materials(m, 0.0f);
    for (config = 0; config < 2; ++config) {
        rad_scene *S = NULL;
        rad_bvh *bvh = NULL;
        rad_raycaster rc;
        uint32_t count, i, seed = 12345u, misses = 0, wrong = 0, occ_wrong = 0;
        if (config == 0) { /* every triangle in the plane z = 0.25: a grid of quads */
            float *p = t;
            uint32_t a, b;
            const float e1[3] = { 1.0f / 24.0f, 0, 0 }, e2[3] = { 0, 1.0f / 24.0f, 0 };
            for (a = 0; a < grid; ++a)
                for (b = 0; b < grid; ++b) {
                    float o[3];
                    o[0] = (float)a / 24.0f; o[1] = (float)b / 24.0f; o[2] = 0.25f;
                    p = rb_quad(p, o, e1, e2);
                }
            count = 2 * grid * grid;
        } else { /* the same triangle, many times */
            static const float tri[9] = { 0.1f, 0.1f, 0.3f, 0.9f, 0.2f, 0.3f, 0.4f, 0.8f, 0.3f };
            for (i = 0; i < copies; ++i) memcpy(t + 9 * i, tri, sizeof(tri));
            count = copies;
        }
        CHECK_OK(rb_scene(t, count, NULL, m, 4, &S));
        if (!S) continue;
        CHECK_OK(rad_bvh_create(S, NULL, &bvh));
        if (!bvh) { rad_scene_destroy(S); continue; }
        rad_bvh_raycaster(bvh, &rc);
        for (i = 0; i < 2000; ++i) {
            rad_ray r;
            rad_hit h;
            uint8_t occ;
            double bt;
            uint32_t btri = RAD_NONE;
            int bh;
            /* random rays from above and below, some grazing */
            r.origin[0] = rb_unit(&seed) * 1.2f - 0.1f;
            r.origin[1] = rb_unit(&seed) * 1.2f - 0.1f;
            r.origin[2] = (i & 1) ? 1.0f : -0.5f;
            r.dir[0] = rb_unit(&seed) - 0.5f;
            r.dir[1] = rb_unit(&seed) - 0.5f;
            r.dir[2] = ((i & 1) ? -1.0f : 1.0f) * (0.05f + rb_unit(&seed));
            r.tmin = 0.0f;
            r.tmax = 1e30f;
            CHECK_OK(rc.intersect(rc.user, &r, 1, &h));
            CHECK_OK(rc.occluded(rc.user, &r, 1, &occ));
            bh = rb_brute(S, &r, &bt, &btri);
            if (bh != (h.triangle != RAD_NONE)) {
                /* only rays within float precision of an edge may disagree */
                misses++;
                continue;
            }
            if (occ != (uint8_t)(h.triangle != RAD_NONE)) occ_wrong++;
            if (bh) {
                if (!(fabs(h.t - bt) <= 1e-5 * (1.0 + bt))) wrong++;
                if (!(h.b1 >= -1e-5f && h.b2 >= -1e-5f && h.b1 + h.b2 <= 1.0f + 1e-5f)) wrong++;
                /* in the identical-copies scene any copy is a right answer; in the plane the
                   hit point must lie in the reported triangle, checked by the barycentrics */
                if (config == 0 && h.triangle != btri) {
                    /* a shared edge: both triangles contain the point; check the point is on h.triangle */
                    const float *v = S->positions + 9 * (size_t)h.triangle;
                    double px = r.origin[0] + h.t * r.dir[0], py = r.origin[1] + h.t * r.dir[1];
                    double qx = (1.0 - h.b1 - h.b2) * v[0] + h.b1 * v[3] + h.b2 * v[6];
                    double qy = (1.0 - h.b1 - h.b2) * v[1] + h.b1 * v[4] + h.b2 * v[7];
                    if (fabs(px - qx) > 1e-5 || fabs(py - qy) > 1e-5) wrong++;
                }
            }
        }
        printf("    %s: %u triangles, 2000 rays: %u edge disagreements, %u wrong hits, %u occluded mismatches\n",
               config ? "identical copies" : "one plane", count, misses, wrong, occ_wrong);
        CHECK(misses <= 4);
        CHECK(wrong == 0);
        CHECK(occ_wrong == 0);
        /* straight down onto every cell centre of the plane: always the right cell */
        if (config == 0) {
            uint32_t a, b, bad = 0;
            for (a = 0; a < grid; ++a)
                for (b = 0; b < grid; ++b) {
                    rad_ray r;
                    rad_hit h;
                    r.origin[0] = ((float)a + 0.3f) / 24.0f; r.origin[1] = ((float)b + 0.6f) / 24.0f; r.origin[2] = 1.0f;
                    r.dir[0] = 0.0f; r.dir[1] = 0.0f; r.dir[2] = -1.0f;
                    r.tmin = 0.0f; r.tmax = 10.0f;
                    CHECK_OK(rc.intersect(rc.user, &r, 1, &h));
                    if (h.triangle == RAD_NONE || h.triangle / 2 != a * grid + b || fabs(h.t - 0.75) > 1e-6) bad++;
                }
            CHECK(bad == 0);
        }
        rad_bvh_destroy(bvh);
        rad_scene_destroy(S);
    }
    free(t);
}

/* ---- determinism ------------------------------------------------------------------------------- */

/* parallel_for on two POSIX threads pulling task indices from a shared counter: the assignment
   of tasks to threads changes from run to run */
typedef struct rb_pool {
    pthread_mutex_t lock;
    uint32_t next, count;
    rad_task_fn fn;
    void *data;
} rb_pool;

static void *rb_worker(void *arg)
{
    rb_pool *p = (rb_pool *)arg;
    for (;;) {
        uint32_t i;
        pthread_mutex_lock(&p->lock);
        i = p->next < p->count ? p->next++ : p->count;
        pthread_mutex_unlock(&p->lock);
        if (i >= p->count) break;
        p->fn(p->data, i);
    }
    return NULL;
}

static void rb_pthreads_for(void *user, uint32_t count, rad_task_fn fn, void *data)
{
    rb_pool p;
    pthread_t th;
    int started;
    (void)user;
    pthread_mutex_init(&p.lock, NULL);
    p.next = 0;
    p.count = count;
    p.fn = fn;
    p.data = data;
    started = pthread_create(&th, NULL, rb_worker, &p) == 0;
    rb_worker(&p);
    if (started) pthread_join(th, NULL);
    pthread_mutex_destroy(&p.lock);
}

/* every output of one run, for bitwise comparison */
typedef struct rb_outputs {
    float *dense, *dense_mc, *sparse_vals, *rows, *D, *Dpt, *solve[4], *mv, *vv;
    uint64_t *offs;
    uint32_t *cols;
    uint64_t nnz, rays, pairs, rays_mc;
    uint32_t iters[4];
} rb_outputs;

static void rb_outputs_free(rb_outputs *o)
{
    int s;
    free(o->dense); free(o->dense_mc); free(o->sparse_vals); free(o->rows); free(o->D); free(o->Dpt);
    free(o->mv); free(o->vv); free(o->offs); free(o->cols);
    for (s = 0; s < 4; ++s) free(o->solve[s]);
    memset(o, 0, sizeof(*o));
}

static float *rb_dup(const float *p, size_t n)
{
    float *q = (float *)malloc(sizeof(float) * (n ? n : 1));
    if (q && n) memcpy(q, p, sizeof(float) * n);
    return q;
}

static int rb_compute(const rad_patches *P, const rad_raycaster *rc, const rad_context *ctx, rb_outputs *o)
{
    rad_form_factor_options fo;
    rad_direct_options dop;
    rad_solve_options so;
    rad_solve_stats st;
    rad_form_factors *ff = NULL;
    rad_system sys;
    rad_light l;
    float *E = NULL, *pts = NULL, *nrm = NULL;
    uint32_t n = P->count, i, cut;
    size_t n3 = 3 * (size_t)n;
    int s, k, ok = 0;
    memset(o, 0, sizeof(*o));
    rad_form_factor_options_default(&fo);
    fo.seed = 77;
    fo.samples = 4; /* every code path, at a quarter of the cost */
    if (rad_form_factors_dense(P, rc, &fo, ctx, &ff) != RAD_SUCCESS) goto done;
    o->dense = rb_dup(ff->matrix.dense, (size_t)n * n);
    o->rays = ff->rays_cast;
    o->pairs = ff->pairs_evaluated;
    rad_form_factors_destroy(ff);
    ff = NULL;
    fo.method = RAD_FF_MONTE_CARLO;
    if (rad_form_factors_dense(P, rc, &fo, ctx, &ff) != RAD_SUCCESS) goto done;
    o->dense_mc = rb_dup(ff->matrix.dense, (size_t)n * n);
    o->rays_mc = ff->rays_cast;
    rad_form_factors_destroy(ff);
    ff = NULL;
    fo.method = RAD_FF_ANALYTIC;
    fo.drop_threshold = 1e-4f;
    if (rad_form_factors_sparse(P, rc, &fo, ctx, &ff) != RAD_SUCCESS) goto done;
    o->nnz = ff->matrix.row_offsets[n];
    o->sparse_vals = rb_dup(ff->matrix.values, (size_t)o->nnz);
    o->offs = (uint64_t *)malloc(sizeof(uint64_t) * (n + 1));
    o->cols = (uint32_t *)malloc(sizeof(uint32_t) * (size_t)(o->nnz ? o->nnz : 1));
    if (!o->offs || !o->cols) goto done;
    memcpy(o->offs, ff->matrix.row_offsets, sizeof(uint64_t) * (n + 1));
    memcpy(o->cols, ff->matrix.columns, sizeof(uint32_t) * (size_t)o->nnz);
    rad_form_factors_destroy(ff);
    ff = NULL;
    /* rows in three uneven pieces */
    fo.drop_threshold = 0.0f;
    o->rows = (float *)malloc(sizeof(float) * (size_t)n * n);
    if (!o->rows) goto done;
    cut = n / 3;
    if (rad_form_factor_rows(P, rc, &fo, 0, cut, o->rows, ctx) != RAD_SUCCESS) goto done;
    if (rad_form_factor_rows(P, rc, &fo, cut, cut + 1, o->rows + (size_t)cut * n, ctx) != RAD_SUCCESS) goto done;
    if (rad_form_factor_rows(P, rc, &fo, cut + 1, n, o->rows + (size_t)(cut + 1) * n, ctx) != RAD_SUCCESS) goto done;
    /* direct light: emitters, a spot light and the sky */
    memset(&l, 0, sizeof(l));
    l.type = RAD_LIGHT_SPOT;
    for (k = 0; k < 3; ++k) l.color[k] = 0.7f;
    l.position[0] = 0.3f; l.position[1] = 0.5f; l.position[2] = 0.25f;
    l.direction[1] = -1.0f; l.direction[0] = 0.2f;
    l.inner_angle = 0.4f;
    l.outer_angle = 0.9f;
    rad_direct_options_default(&dop);
    dop.seed = 5;
    o->D = (float *)malloc(sizeof(float) * n3);
    o->Dpt = (float *)malloc(sizeof(float) * n3);
    E = (float *)malloc(sizeof(float) * n3);
    pts = (float *)malloc(sizeof(float) * n3);
    nrm = (float *)calloc(n3, sizeof(float));
    if (!o->D || !o->Dpt || !E || !pts || !nrm) goto done;
    if (rad_direct_patches(P, rc, &l, 1, &dop, o->D, ctx) != RAD_SUCCESS) goto done;
    for (i = 0; i < n; ++i)
        for (k = 0; k < 3; ++k) { pts[3 * i + k] = P->patches[i].centroid[k]; nrm[3 * i + k] = P->patches[i].normal[k]; }
    if (rad_direct_irradiance(P->scene, rc, &l, 1, &dop, pts, nrm, n, o->Dpt, ctx) != RAD_SUCCESS) goto done;
    /* solvers on the dense matrix with E = rho D + pi L (both, so nothing is zero) */
    if (rad_sources(P, RAD_SOURCE_DIRECT, o->D, E) != RAD_SUCCESS) goto done;
    for (i = 0; i < n3; ++i) E[i] += (float)(3.14159265358979323846 * P->patches[i / 3].emission[i % 3]);
    rad_system_init(&sys, NULL, P, E);
    {
        rad_matrix M;
        memset(&M, 0, sizeof(M));
        M.rows = M.cols = n;
        M.storage = RAD_STORAGE_DENSE;
        M.dense = o->dense;
        sys.F = &M;
        for (s = 0; s < 4; ++s) {
            rad_result r;
            o->solve[s] = (float *)malloc(sizeof(float) * n3);
            if (!o->solve[s]) goto done;
            rad_solve_options_default(&so);
            so.bounces = 20;
            so.max_iterations = s == 2 ? 1000000u : 0u;
            so.output = RAD_OUTPUT_TOTAL;
            memset(&st, 0, sizeof(st));
            if (s == 0) r = rad_solve_jacobi(&sys, &so, o->solve[s], &st, ctx);
            else if (s == 1) r = rad_solve_gauss_seidel(&sys, &so, o->solve[s], &st, ctx);
            else if (s == 2) r = rad_solve_progressive(&sys, &so, o->solve[s], &st, ctx);
            else r = rad_solve_direct(&sys, &so, o->solve[s], ctx);
            if (r != RAD_SUCCESS) goto done;
            o->iters[s] = st.iterations;
        }
        o->mv = (float *)malloc(sizeof(float) * n3);
        if (!o->mv || rad_matrix_multiply(&M, E, o->mv, ctx) != RAD_SUCCESS) goto done;
    }
    o->vv = (float *)malloc(sizeof(float) * 3 * (size_t)P->vertex_count);
    if (!o->vv || rad_patches_vertex_values(P, o->solve[3], 3, o->vv) != RAD_SUCCESS) goto done;
    ok = 1;
done:
    rad_form_factors_destroy(ff);
    free(E); free(pts); free(nrm);
    return ok;
}

/* compares b against a bit for bit; names what differs */
static void rb_compare(const rb_outputs *a, const rb_outputs *b, uint32_t n, uint32_t nv, const char *what)
{
    size_t n3 = 3 * (size_t)n, nn = (size_t)n * n;
    int s;
    const char *names[4] = { "jacobi", "gauss-seidel", "progressive", "direct solve" };
#define RB_SAME(field, bytes, label)                                                                 \
    do {                                                                                             \
        if (memcmp(a->field, b->field, (bytes)) != 0) {                                              \
            printf("    %s: %s differs\n", what, label);                                            \
            CHECK(0);                                                                                \
        }                                                                                            \
    } while (0)
    RB_SAME(dense, sizeof(float) * nn, "dense form factors (analytic)");
    RB_SAME(dense_mc, sizeof(float) * nn, "dense form factors (Monte Carlo)");
    if (a->nnz != b->nnz) { printf("    %s: sparse non-zero count differs\n", what); CHECK(0); }
    else {
        RB_SAME(offs, sizeof(uint64_t) * (n + 1), "sparse row offsets");
        RB_SAME(cols, sizeof(uint32_t) * (size_t)a->nnz, "sparse columns");
        RB_SAME(sparse_vals, sizeof(float) * (size_t)a->nnz, "sparse values");
    }
    RB_SAME(rows, sizeof(float) * nn, "form factor rows");
    RB_SAME(D, sizeof(float) * n3, "direct irradiance (patches)");
    RB_SAME(Dpt, sizeof(float) * n3, "direct irradiance (points)");
    for (s = 0; s < 4; ++s) {
        RB_SAME(solve[s], sizeof(float) * n3, names[s]);
        if (a->iters[s] != b->iters[s]) { printf("    %s: %s iteration count differs\n", what, names[s]); CHECK(0); }
    }
    RB_SAME(mv, sizeof(float) * n3, "matrix multiply");
    RB_SAME(vv, sizeof(float) * 3 * (size_t)nv, "vertex values");
    if (a->rays != b->rays || a->pairs != b->pairs || a->rays_mc != b->rays_mc) {
        printf("    %s: rays_cast / pairs_evaluated differ (%llu/%llu vs %llu/%llu)\n", what, (unsigned long long)a->rays,
               (unsigned long long)a->pairs, (unsigned long long)b->rays, (unsigned long long)b->pairs);
        CHECK(0);
    }
#undef RB_SAME
}

static void rb_test_determinism(void)
{
    rad_scene_desc desc;
    rad_scene *S = NULL;
    rad_patches *P = NULL;
    rad_bvh *bvh = NULL;
    rad_raycaster rc;
    rad_patch_options po;
    rad_context ctx[8];
    const char *names[8] = { "default context again (run to run)", "serial", "reverse order", "2 POSIX threads",
                             "2 POSIX threads, task_count 7", "task_count 1", "task_count 7", "task_count 64, reverse" };
    rb_outputs ref, o;
    int i, ok;
    rad_cornell_box(&desc, NULL);
    CHECK_OK(rad_scene_create(&desc, NULL, &S));
    rad_patch_options_default(&po);
    po.target_count = rad_test_quick() ? 50 : 100;
    CHECK_OK(rad_patches_create(S, &po, NULL, &P));
    CHECK_OK(rad_bvh_create(S, NULL, &bvh));
    if (!S || !P || !bvh) goto done;
    rad_bvh_raycaster(bvh, &rc);
    memset(ctx, 0, sizeof(ctx));
    ctx[1].parallel_for = fx_serial_for;
    ctx[2].parallel_for = fx_reverse_for;
    ctx[3].parallel_for = rb_pthreads_for;
    ctx[4].parallel_for = rb_pthreads_for;
    ctx[4].task_count = 7;
    ctx[5].task_count = 1;
    ctx[6].task_count = 7;
    ctx[7].task_count = 64;
    ctx[7].parallel_for = fx_reverse_for;
    ok = rb_compute(P, &rc, NULL, &ref);
    CHECK(ok);
    if (!ok) { rb_outputs_free(&ref); goto done; }
    printf("    %u patches, %llu sparse non-zeros\n", P->count, (unsigned long long)ref.nnz);
    for (i = 0; i < 8; ++i) {
        ok = rb_compute(P, &rc, i == 0 ? NULL : &ctx[i], &o);
        CHECK(ok);
        if (ok) rb_compare(&ref, &o, P->count, P->vertex_count, names[i]);
        rb_outputs_free(&o);
    }
    rb_outputs_free(&ref);
done:
    rad_bvh_destroy(bvh);
    rad_patches_destroy(P);
    rad_scene_destroy(S);
}

static const rad_test_case tests_robust[] = {
    { "robust_scale_invariance", rb_test_scale_invariance },
    { "robust_coincident", rb_test_coincident },
    { "robust_touching", rb_test_touching },
    { "robust_nearly_parallel", rb_test_nearly_parallel },
    { "robust_thin_triangles", rb_test_thin_triangles },
    { "robust_albedo_contrast", rb_test_albedo_contrast },
    { "robust_huge_emission", rb_test_huge_emission },
    { "robust_tiny_and_huge_scenes", rb_test_tiny_and_huge_scenes },
    { "robust_single_triangle", rb_test_single_triangle },
    { "robust_bvh_degenerate", rb_test_bvh_degenerate },
    { "robust_determinism", rb_test_determinism },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_robust)

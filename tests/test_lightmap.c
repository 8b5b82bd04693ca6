/* test_lightmap.c - lightmaps (>>lightmap): texel coverage, validity (no leak under a wall),
   the gather against closed forms and the patch solution, SH L1 projection, dilation and seam
   stitching. Included by test_main.c. */
#include "fixtures.h"


#define LM_PI 3.14159265358979323846

/* A copy of 'scene' with one unindexed mesh whose triangle t has lightmap uvs in grid cell t
   (a right triangle in the cell, a one-texel gutter): every triangle its own chart. */
typedef struct lm_grid {
    float *pos, *luv;
    rad_mesh_desc mesh;
    rad_scene_desc desc;
    uint32_t cells, cell;       /* cells per side, texels per cell */
} lm_grid;

static void lm_grid_make(lm_grid *g, const rad_scene *s, uint32_t cell)
{
    uint32_t t, side = 1;
    while (side * side < s->triangle_count) ++side;
    g->cells = side;
    g->cell = cell;
    g->pos = (float *)malloc(sizeof(float) * 9 * s->triangle_count);
    g->luv = (float *)malloc(sizeof(float) * 6 * s->triangle_count);
    memcpy(g->pos, s->positions, sizeof(float) * 9 * s->triangle_count);
    for (t = 0; t < s->triangle_count; ++t) {
        float W = (float)(side * cell), x0 = (float)((t % side) * cell + 1), y0 = (float)((t / side) * cell + 1), e = (float)(cell - 2);
        g->luv[6 * t] = x0 / W; g->luv[6 * t + 1] = y0 / W;
        g->luv[6 * t + 2] = (x0 + e) / W; g->luv[6 * t + 3] = y0 / W;
        g->luv[6 * t + 4] = x0 / W; g->luv[6 * t + 5] = (y0 + e) / W;
    }
    memset(&g->mesh, 0, sizeof(g->mesh));
    g->mesh.positions = g->pos;
    g->mesh.vertex_count = 3 * s->triangle_count;
    g->mesh.triangle_count = s->triangle_count;
    g->mesh.material_ids = s->materials;
    g->mesh.lightmap_uvs = g->luv;
    memset(&g->desc, 0, sizeof(g->desc));
    g->desc.meshes = &g->mesh;
    g->desc.mesh_count = 1;
    g->desc.materials = s->materials_table;
    g->desc.material_count = s->material_count;
}

static void lm_grid_free(lm_grid *g)
{
    free(g->pos);
    free(g->luv);
}

/* The polygon projections against a fine quadrature of the hemisphere: solid angle, vector
   irradiance (and so the form factor of rad_ff_point_polygon). */
static void lm_test_polygon(void)
{
    const float tri[9] = { -0.3f, 0.4f, 0.9f, 0.8f, -0.2f, 0.6f, 0.1f, 0.9f, 0.2f }; /* partly below z = 0.5? no: all above */
    const float tri2[9] = { -0.5f, -0.5f, -0.4f, 0.9f, -0.1f, 0.7f, -0.2f, 0.8f, 0.5f }; /* crosses the plane z = 0 */
    const float *tris[2] = { tri, tri2 };
    double p[3] = { 0.0, 0.0, 0.0 }, n[3] = { 0.0, 0.0, 1.0 }, proj[4];
    float pf[3] = { 0, 0, 0 }, nf[3] = { 0, 0, 1 };
    int which;
    for (which = 0; which < 2; ++which) {
        const float *v = tris[which];
        double q[4] = { 0, 0, 0, 0 }, e1[3], e2[3], nn[3];
        int i, j, k, NT = rad_test_quick() ? 400 : 800, NP = 2 * NT;
        CHECK(rad__lm_polygon(p, n, v, proj));
        for (k = 0; k < 3; ++k) { e1[k] = (double)v[3 + k] - v[k]; e2[k] = (double)v[6 + k] - v[k]; }
        nn[0] = e1[1] * e2[2] - e1[2] * e2[1]; nn[1] = e1[2] * e2[0] - e1[0] * e2[2]; nn[2] = e1[0] * e2[1] - e1[1] * e2[0];
        /* midpoint rule in (cos theta, phi): equal solid angle cells */
        for (i = 0; i < NT; ++i)
            for (j = 0; j < NP; ++j) {
                double ct = (i + 0.5) / NT, st = sqrt(1.0 - ct * ct), ph = 2.0 * LM_PI * (j + 0.5) / NP, d[3], dn, tt, x[3], b1, b2;
                double dw = (1.0 / NT) * (2.0 * LM_PI / NP), w[3], den;
                d[0] = st * cos(ph); d[1] = st * sin(ph); d[2] = ct;
                dn = d[0] * nn[0] + d[1] * nn[1] + d[2] * nn[2];
                if (fabs(dn) < 1e-12) continue;
                tt = (v[0] * nn[0] + v[1] * nn[1] + v[2] * nn[2]) / dn;
                if (!(tt > 0.0)) continue;
                for (k = 0; k < 3; ++k) x[k] = tt * d[k] - v[k];
                /* barycentrics in 3D */
                {
                    double d00 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2], d01 = e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2];
                    double d11 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
                    double d20 = x[0] * e1[0] + x[1] * e1[1] + x[2] * e1[2], d21 = x[0] * e2[0] + x[1] * e2[1] + x[2] * e2[2];
                    den = d00 * d11 - d01 * d01;
                    b1 = (d11 * d20 - d01 * d21) / den;
                    b2 = (d00 * d21 - d01 * d20) / den;
                }
                if (b1 < 0.0 || b2 < 0.0 || b1 + b2 > 1.0) continue;
                for (k = 0; k < 3; ++k) w[k] = d[k];
                q[0] += dw;
                for (k = 0; k < 3; ++k) q[1 + k] += w[k] * dw;
            }
        CHECK_REL(proj[0], q[0], 5e-3);
        for (k = 0; k < 3; ++k) CHECK_NEAR(proj[1 + k], q[1 + k], 5e-3 * q[0] + 1e-6);
        {
            /* rad_ff_point_polygon wants the polygon counter-clockwise seen from p */
            float rv[9];
            double ffv;
            memcpy(rv, v, 3 * sizeof(float));
            memcpy(rv + 3, v + 6, 3 * sizeof(float));
            memcpy(rv + 6, v + 3, 3 * sizeof(float));
            ffv = rad_ff_point_polygon(pf, nf, v, 3) + rad_ff_point_polygon(pf, nf, rv, 3);
            CHECK_REL(proj[3] / LM_PI, ffv, 1e-5);
        }
    }
}

/* every triangle's uv area lies in covered texels, each covered texel has samples on a
   triangle that overlaps it, uncovered texels have none; an old scene (no lightmap uvs) is
   refused */
static void lm_test_coverage(void)
{
    rad_scene_desc desc;
    rad_scene *S = NULL, *S0 = NULL;
    rad_bvh *b = NULL;
    rad_raycaster rc;
    rad_lightmap *lm = NULL;
    rad_lightmap_options o;
    lm_grid g;
    uint32_t t, i, covered = 0;
    rad_cornell_box(&desc, NULL);
    CHECK_OK(rad_scene_create(&desc, NULL, &S0));
    if (!S0) return;
    CHECK(S0->lightmap_uvs == NULL);
    CHECK_OK(rad_bvh_create(S0, NULL, &b));
    rad_bvh_raycaster(b, &rc);
    CHECK_RESULT(rad_lightmap_create(S0, &rc, NULL, NULL, &lm), RAD_ERROR_INVALID_ARGUMENT);
    rad_bvh_destroy(b);
    lm_grid_make(&g, S0, 11);
    /* shear the cells' triangles so that their edges cross texels at odd angles */
    for (t = 0; t < S0->triangle_count; ++t) { g.luv[6 * t + 4] += 0.3f / (float)(g.cells * g.cell); g.luv[6 * t + 3] += 0.37f / (float)(g.cells * g.cell); }
    CHECK_OK(rad_scene_create(&g.desc, NULL, &S));
    if (!S) { lm_grid_free(&g); rad_scene_destroy(S0); return; }
    CHECK_OK(rad_bvh_create(S, NULL, &b));
    rad_bvh_raycaster(b, &rc);
    rad_lightmap_options_default(&o);
    o.width = o.height = g.cells * g.cell;
    CHECK_OK(rad_lightmap_create(S, &rc, &o, NULL, &lm));
    if (lm) {
        /* dense points of each uv triangle fall into covered texels */
        for (t = 0; t < S->triangle_count; ++t) {
            const float *uv = S->lightmap_uvs + 6 * t;
            int a, c, miss = 0;
            for (a = 0; a <= 40; ++a)
                for (c = 0; a + c <= 40; ++c) {
                    double b1 = a / 40.0, b2 = c / 40.0, u = uv[0] + b1 * (uv[2] - uv[0]) + b2 * (uv[4] - uv[0]);
                    double v = uv[1] + b1 * (uv[3] - uv[1]) + b2 * (uv[5] - uv[1]);
                    uint32_t x = (uint32_t)(u * o.width), y = (uint32_t)(v * o.height);
                    if (x >= o.width) x = o.width - 1;
                    if (y >= o.height) y = o.height - 1;
                    if (!(lm->flags[y * o.width + x] & RAD_TEXEL_COVERED)) ++miss;
                }
            CHECK(miss == 0);
        }
        for (i = 0; i < o.width * o.height; ++i) {
            uint32_t n = lm->sample_first[i + 1] - lm->sample_first[i], s;
            if (lm->flags[i] & RAD_TEXEL_COVERED) {
                ++covered;
                CHECK(n >= 1 && n <= 4);
                for (s = lm->sample_first[i]; s < lm->sample_first[i + 1]; ++s) CHECK(lm->sample_triangles[s] < S->triangle_count);
            } else {
                CHECK(n == 0);
            }
        }
        CHECK(covered == lm->covered_texels);
        /* the Cornell box's samples are all valid except those under the blocks (no bottom
           faces: their sides seen from inside are back faces) and the ceiling behind the
           one-sided lamp */
        for (i = 0; i < lm->sample_count; ++i) {
            static const float foot[2][8] = { { 0.13f, 0.065f, 0.082f, 0.225f, 0.24f, 0.272f, 0.29f, 0.114f },
                                              { 0.423f, 0.247f, 0.265f, 0.296f, 0.314f, 0.456f, 0.472f, 0.406f } };
            uint32_t tt = lm->sample_triangles[i];
            const char *mesh = S0->mesh_names[S0->meshes[tt]];
            const float *p = lm->sample_positions + 3 * i;
            int inside = 0, outside = 1, f, e;
            if (strcmp(mesh, "floor") == 0) {
                for (f = 0; f < 2; ++f) {
                    float dmin = 1e9f;
                    int in, pos = 0, neg = 0;
                    for (e = 0; e < 4; ++e) {
                        const float *a = foot[f] + 2 * e, *c = foot[f] + 2 * ((e + 1) % 4);
                        float ex = c[0] - a[0], ez = c[1] - a[1], l = (float)sqrt((double)(ex * ex + ez * ez));
                        float sd = ((p[0] - a[0]) * ez - (p[2] - a[1]) * ex) / l;
                        if (sd > 0.0f) pos = 1; else neg = 1;
                        if (fabsf(sd) < dmin) dmin = fabsf(sd);
                    }
                    in = !(pos && neg);
                    if (in && dmin > 0.004f) inside = 1;
                    if (dmin < 0.004f || in) outside = 0;
                }
            } else if (strcmp(mesh, "ceiling") == 0) {
                if (p[0] > 0.216f && p[0] < 0.340f && p[2] > 0.230f && p[2] < 0.329f) inside = 1;
                if (p[0] > 0.210f && p[0] < 0.346f && p[2] > 0.224f && p[2] < 0.335f) outside = 0;
            }
            if (inside) CHECK(!lm->sample_valid[i]);
            if (outside && !lm->sample_valid[i]) {
                printf("    %s %g %g %g\n", mesh, p[0], p[1], p[2]);
                CHECK(lm->sample_valid[i]);
            }
        }
        rad_lightmap_destroy(lm);
    }
    rad_bvh_destroy(b);
    rad_scene_destroy(S);
    rad_scene_destroy(S0);
    lm_grid_free(&g);
}

/* Closed box, every wall of radiosity B: at the floor's centre H = B exactly and the SH L1
   projection of the uniform hemisphere: L00 = 2 B Y0, L1(up) = B Y1, the rest 0; the
   reconstruction at the normal gives back B. */
static void lm_test_sh_uniform(void)
{
    lm_soup s;
    rad_mesh_desc m;
    rad_scene_desc d;
    rad_material mat = { { 0.5f, 0.5f, 0.5f }, { 0, 0, 0 }, 0, 0, 0, 0, 0.0f };
    rad_scene *S = NULL;
    rad_bvh *b = NULL;
    rad_raycaster rc;
    rad_patches *P = NULL;
    rad_lightmap *lm = NULL;
    rad_lightmap_options o;
    rad_lightmap_gather_options go;
    float *B, out[12 * 16], out3[3 * 16];
    const float O[3] = { 0, 0, 0 }, X[3] = { 1, 0, 0 }, Y[3] = { 0, 1, 0 }, Z[3] = { 0, 0, 1 }, O1[3] = { 0, 1, 0 };
    const float O2[3] = { 1, 0, 0 }, O3[3] = { 0, 0, 1 }, U[2] = { 1, 0 }, V[2] = { 0, 1 };
    float nX[3] = { -1, 0, 0 }, nY[3] = { 0, -1, 0 }, nZ[3] = { 0, 0, -1 };
    uint32_t i;
    (void)nX; (void)nY; (void)nZ;
    memset(&s, 0, sizeof(s));
    lm_quad(&s, O, Z, X, NULL, V, U);      /* floor y = 0, up; lightmapped: uv = (x, z) */
    lm_quad(&s, O1, X, Z, NULL, NULL, NULL); /* ceiling, down */
    lm_quad(&s, O, Y, Z, NULL, NULL, NULL);  /* x = 0, +x */
    lm_quad(&s, O2, Z, Y, NULL, NULL, NULL); /* x = 1, -x */
    lm_quad(&s, O, X, Y, NULL, NULL, NULL);  /* z = 0, +z */
    lm_quad(&s, O3, Y, X, NULL, NULL, NULL); /* z = 1, -z */
    lm_mesh(&m, &s, 0, 1);
    memset(&d, 0, sizeof(d));
    d.meshes = &m; d.mesh_count = 1; d.materials = &mat; d.material_count = 1;
    CHECK_OK(rad_scene_create(&d, NULL, &S));
    if (!S) return;
    for (i = 2; i < S->triangle_count; ++i) S->lightmapped[i] = 0; /* only the floor */
    CHECK_OK(rad_bvh_create(S, NULL, &b));
    rad_bvh_raycaster(b, &rc);
    CHECK_OK(rad_patches_create(S, NULL, NULL, &P));
    rad_lightmap_options_default(&o);
    o.width = o.height = 4;
    o.samples = 1;
    CHECK_OK(rad_lightmap_create(S, &rc, &o, NULL, &lm));
    B = (float *)malloc(sizeof(float) * 3 * P->count);
    for (i = 0; i < 3 * P->count; ++i) B[i] = 2.0f;
    rad_lightmap_gather_options_default(&go);
    go.encoding = RAD_LIGHTMAP_SH_L1;
    if (lm && P) {
        CHECK(lm->valid_texels == 16);
        CHECK_OK(rad_lightmap_gather(lm, P, B, &rc, &go, out, NULL));
        go.encoding = RAD_LIGHTMAP_IRRADIANCE;
        CHECK_OK(rad_lightmap_gather(lm, P, B, &rc, &go, out3, NULL));
        for (i = 0; i < 16; ++i) {
            const float *c = out + 12 * i;
            double E;
            int k;
            for (k = 0; k < 3; ++k) {
                CHECK_REL(out3[3 * i + k], 2.0, 1e-4);
                CHECK_REL(c[k], 2.0 * 2.0 * 0.282094792, 1e-4);
                CHECK_REL(c[3 + k], 2.0 * 0.488602512, 1e-4); /* L_1,-1: y is up */
                CHECK_NEAR(c[6 + k], 0.0, 1e-4);
                CHECK_NEAR(c[9 + k], 0.0, 1e-4);
                E = LM_PI * 0.282094792 * c[k] + (2.0 * LM_PI / 3.0) * 0.488602512 * c[3 + k];
                CHECK_REL(E, 2.0, 1e-4);
            }
        }
    }
    free(B);
    rad_lightmap_destroy(lm);
    rad_patches_destroy(P);
    rad_bvh_destroy(b);
    rad_scene_destroy(S);
}

/* Two rooms, a wall between them standing on the floor (2.6 texels thick), the light in the
   left room only: floor samples under the wall are invalid, those beside it valid; the right
   room's floor stays dark up to the wall; the left room's contact texel is not darkened by
   the samples under the wall. */
static void lm_test_no_leak(void)
{
    lm_soup room, wall, lamp;
    rad_mesh_desc m[3];
    rad_scene_desc d;
    rad_material mats[2];
    rad_scene *S = NULL;
    rad_bvh *b = NULL;
    rad_raycaster rc;
    rad_patches *P = NULL;
    rad_form_factors *ff = NULL;
    rad_lightmap *lm = NULL;
    rad_lightmap_options o;
    rad_lightmap_gather_options go;
    float *E = NULL, *B = NULL, *H = NULL;
    uint32_t i, x, y;
    fx_two_rooms(&room, &wall, &lamp, m, &d, mats);
    CHECK_OK(rad_scene_create(&d, NULL, &S));
    if (!S) return;
    for (i = 0; i < S->triangle_count; ++i) /* the floor only */
        if (S->normals[3 * i + 1] < 0.5f || S->positions[9 * i + 1] > 0.5f) S->lightmapped[i] = 0;
    CHECK_OK(rad_bvh_create(S, NULL, &b));
    if (!b) goto out;
    rad_bvh_raycaster(b, &rc);
    if (!fx_classic_jacobi8(S, &rc, &P, &ff, &E, &B)) goto out;
    rad_lightmap_options_default(&o);
    o.width = 64;
    o.height = rad_test_quick() ? 8 : 32; /* rows along z: the wall runs across all of them */
    CHECK_OK(rad_lightmap_create(S, &rc, &o, NULL, &lm));
    if (!lm) goto out;
    for (i = 0; i < lm->sample_count; ++i) {
        float px = lm->sample_positions[3 * i];
        if (px > 0.985f && px < 1.055f) CHECK(!lm->sample_valid[i]);
        if (px < 0.95f || px > 1.09f) CHECK(lm->sample_valid[i]);
    }
    H = (float *)malloc(sizeof(float) * 3 * 64 * 32);
    rad_lightmap_gather_options_default(&go);
    go.visibility_rays = rad_test_quick() ? 1 : 4;
    CHECK_OK(rad_lightmap_gather(lm, P, B, &rc, &go, H, NULL));
    for (y = o.height / 8; y < o.height - o.height / 8; ++y) {
        float lit = H[3 * (y * 64 + 29)];
        CHECK(lit > 0.05f);
        /* the texel at the contact (x 31: sub-point 31.25 beside the wall, 31.75 under it) */
        CHECK(lm->flags[y * 64 + 31] & RAD_TEXEL_VALID);
        CHECK(H[3 * (y * 64 + 31)] > 0.5f * lit);
        CHECK(!(lm->flags[y * 64 + 32] & RAD_TEXEL_VALID));
        for (x = 34; x < 40; ++x) CHECK(H[3 * (y * 64 + x)] <= 1e-4f * lit);
    }
out:
    free(E);
    free(B);
    free(H);
    rad_lightmap_destroy(lm);
    rad_form_factors_destroy(ff);
    rad_patches_destroy(P);
    rad_bvh_destroy(b);
    rad_scene_destroy(S);
}

/* The Cornell box, every triangle its own chart: per triangle, the mean lightmap irradiance
   over its texels matches the area mean of H = F B over its patches (the patch value is the
   area average of the point irradiance the lightmap samples) */
/* The Cornell box with every triangle its own chart (lm_grid_make, 'cell' texels a side), its
   BVH, classic patches ('patches' of them), dense F and the total radiosity B = E + L by
   Gauss-Seidel. direct 0: E is the emission (the lightmap then holds the total); 1: E = rho D,
   the direct light of the lamp (rad_direct_patches with the emitters as lights), so the lamp
   is a light and the lightmap of B holds the indirect irradiance, as the tool bakes it.
   The set-up every Cornell lightmap test shares; 0 when every step succeeded. */
typedef struct lm_cornell {
    rad_scene_desc desc;
    rad_scene *S0, *S;          /* the box, and its copy with per-triangle charts */
    rad_bvh *b;
    rad_raycaster rc;
    rad_patches *P;
    rad_form_factors *ff;
    rad_solve_options so;       /* Gauss-Seidel, RAD_OUTPUT_TOTAL */
    float *E, *B;               /* 3N each */
    lm_grid g;
    int has_grid;
} lm_cornell;

static int lm_cornell_make(lm_cornell *c, uint32_t cell, uint32_t patches, int direct)
{
    rad_patch_options po;
    rad_form_factor_options fo;
    rad_system sys;
    memset(c, 0, sizeof(*c));
    rad_cornell_box(&c->desc, NULL);
    CHECK_OK(rad_scene_create(&c->desc, NULL, &c->S0));
    if (!c->S0) return 1;
    lm_grid_make(&c->g, c->S0, cell);
    c->has_grid = 1;
    CHECK_OK(rad_scene_create(&c->g.desc, NULL, &c->S));
    if (!c->S) return 1;
    CHECK_OK(rad_bvh_create(c->S, NULL, &c->b));
    if (!c->b) return 1;
    rad_bvh_raycaster(c->b, &c->rc);
    rad_patch_options_default(&po);
    po.target_count = patches;
    CHECK_OK(rad_patches_create(c->S, &po, NULL, &c->P));
    rad_form_factor_options_default(&fo);
    if (c->P) CHECK_OK(rad_form_factors_dense(c->P, &c->rc, &fo, NULL, &c->ff));
    if (!c->P || !c->ff) return 1;
    c->E = (float *)malloc(sizeof(float) * 3 * c->P->count);
    c->B = (float *)malloc(sizeof(float) * 3 * c->P->count);
    if (direct) {
        rad_direct_options dopt;
        float *D = (float *)malloc(sizeof(float) * 3 * c->P->count);
        rad_direct_options_default(&dopt);
        dopt.exclude_emitters = 0;
        CHECK_OK(rad_direct_patches(c->P, &c->rc, NULL, 0, &dopt, D, NULL));
        CHECK_OK(rad_sources(c->P, RAD_SOURCE_DIRECT, D, c->E));
        free(D);
    } else {
        CHECK_OK(rad_sources(c->P, RAD_SOURCE_EMISSION, NULL, c->E));
    }
    rad_system_init(&sys, &c->ff->matrix, c->P, c->E);
    rad_solve_options_default(&c->so);
    c->so.output = RAD_OUTPUT_TOTAL;
    CHECK_OK(rad_solve_gauss_seidel(&sys, &c->so, c->B, NULL, NULL));
    return rad_test_failures != 0;
}

static void lm_cornell_free(lm_cornell *c)
{
    free(c->E);
    free(c->B);
    rad_form_factors_destroy(c->ff);
    rad_patches_destroy(c->P);
    rad_bvh_destroy(c->b);
    rad_scene_destroy(c->S);
    rad_scene_destroy(c->S0);
    if (c->has_grid) lm_grid_free(&c->g);
    memset(c, 0, sizeof(*c));
}

static void lm_test_cornell(void)
{
    lm_cornell cb;
    rad_scene *S0, *S;
    rad_raycaster rc;
    rad_patches *P;
    rad_form_factors *ff;
    rad_system sys;
    rad_solve_options so;
    rad_lightmap *lm = NULL;
    rad_lightmap_options o;
    rad_lightmap_gather_options go;
    rad_lightmap_seam_stats st;
    float *E, *B, *Hp = NULL, *H = NULL, *Hd = NULL;
    double *sum = NULL, *cnt = NULL, *hp = NULL, *ap = NULL, worst = 0.0, mean = 0.0;
    uint32_t i, t, checked = 0;
    if (lm_cornell_make(&cb, rad_test_quick() ? 8 : 14, rad_test_quick() ? 150 : 300, 0)) goto out;
    S0 = cb.S0, S = cb.S, rc = cb.rc, P = cb.P, ff = cb.ff, so = cb.so, E = cb.E, B = cb.B;
    Hp = (float *)malloc(sizeof(float) * 3 * P->count);
    CHECK_OK(rad_matrix_multiply(&ff->matrix, B, Hp, NULL));
    rad_lightmap_options_default(&o);
    o.width = o.height = cb.g.cells * cb.g.cell;
    o.samples = rad_test_quick() ? 9 : 16;
    CHECK_OK(rad_lightmap_create(S, &rc, &o, NULL, &lm));
    if (!lm) goto out;
    H = (float *)calloc(3 * (size_t)o.width * o.height, sizeof(float));
    Hd = (float *)calloc(3 * (size_t)o.width * o.height, sizeof(float));
    rad_lightmap_gather_options_default(&go);
    go.visibility_rays = rad_test_quick() ? 2 : 4;
    CHECK_OK(rad_lightmap_gather(lm, P, B, &rc, &go, H, NULL));
    sum = (double *)calloc(S->triangle_count, sizeof(double));
    cnt = (double *)calloc(S->triangle_count, sizeof(double));
    hp = (double *)calloc(S->triangle_count, sizeof(double));
    ap = (double *)calloc(S->triangle_count, sizeof(double));
    /* each cell holds one triangle: its texels weighted by their valid samples (a 3 x 3 or
       4 x 4 grid: the covered share of the texel) */
    for (i = 0; i < o.width * o.height; ++i) {
        uint32_t a = lm->sample_first[i], e = lm->sample_first[i + 1], s;
        for (s = a; s < e; ++s) {
            if (!lm->sample_valid[s]) continue;
            sum[lm->sample_triangles[s]] += H[3 * i + 1];
            cnt[lm->sample_triangles[s]] += 1.0;
        }
    }
    for (i = 0; i < P->count; ++i) {
        hp[P->patches[i].triangle] += (double)Hp[3 * i + 1] * P->patches[i].area;
        ap[P->patches[i].triangle] += P->patches[i].area;
    }
    for (t = 0; t < S->triangle_count; ++t) {
        const char *mesh = S0->mesh_names[S0->meshes[t]];
        double ref = hp[t] / ap[t], got;
        /* the floor's patches under the blocks are dark, its invalid texels there count for
           nothing: the two means differ by right */
        if (strcmp(mesh, "light") == 0 || strcmp(mesh, "floor") == 0) continue;
        got = sum[t] / cnt[t];
        /* single triangles: 8% (the patch value of a dark block face comes mostly from the
           floor next to it, where the patch form factors are least accurate); on average 3% */
        CHECK_REL(got, ref, 0.08);
        if (getenv("RAD_TEST_VERBOSE")) printf("    triangle %u of '%s': %g against %g\n", t, mesh, got, ref);
        if (fabs(got - ref) / ref > worst) worst = fabs(got - ref) / ref;
        mean += fabs(got - ref) / ref;
        ++checked;
    }
    CHECK(checked >= 26);
    CHECK(mean / checked < 0.03);
    if (rad_test_failures || getenv("RAD_TEST_VERBOSE"))
        printf("    relative difference: worst %.4f, mean %.4f over %u triangles\n", worst, mean / checked, checked);
    /* run time: weights from this bake; a refresh from the same patch irradiance gives back
       the bake's luminance, it is linear, and from another solution (the lamp's left half
       alone) it stays near a full new gather */
    {
        rad_lightmap_weights *wt = NULL;
        float *R = (float *)calloc(3 * (size_t)o.width * o.height, sizeof(float));
        float *R2 = (float *)calloc(3 * (size_t)o.width * o.height, sizeof(float));
        float *E2 = (float *)malloc(sizeof(float) * 3 * P->count), *B2 = (float *)malloc(sizeof(float) * 3 * P->count);
        float *Hp2 = (float *)malloc(sizeof(float) * 3 * P->count), *Hp3 = (float *)malloc(sizeof(float) * 3 * P->count);
        float *G2 = (float *)calloc(3 * (size_t)o.width * o.height, sizeof(float));
        double err = 0.0, tot = 0.0;
        uint64_t entries;
        CHECK_RESULT(rad_lightmap_weights_create(lm, P, H, NULL, NULL, &wt), RAD_ERROR_INVALID_ARGUMENT);
        CHECK_OK(rad_lightmap_weights_create(lm, P, H, Hp, NULL, &wt));
        if (wt && R && R2 && E2 && B2 && Hp2 && Hp3 && G2) {
            entries = wt->row_first[wt->row_count];
            CHECK(entries <= 12u * (uint64_t)lm->valid_texels); /* a few vertices per texel */
            CHECK_OK(rad_lightmap_refresh(wt, Hp, R, NULL));
            for (i = 0; i < 3 * P->count; ++i) Hp3[i] = 2.0f * Hp[i];
            CHECK_OK(rad_lightmap_refresh(wt, Hp3, R2, NULL));
            for (i = 0; i < o.width * o.height; ++i) {
                if (!(lm->flags[i] & RAD_TEXEL_VALID)) { CHECK(R[3 * i] == 0.0f); continue; }
                CHECK_NEAR(R[3 * i] + R[3 * i + 1] + R[3 * i + 2], H[3 * i] + H[3 * i + 1] + H[3 * i + 2],
                           1e-4 * (H[3 * i] + H[3 * i + 1] + H[3 * i + 2]) + 1e-6);
                CHECK_NEAR(R2[3 * i + 1], 2.0 * R[3 * i + 1], 1e-5 * R[3 * i + 1] + 1e-6);
            }
            for (i = 0; i < P->count; ++i)
                for (t = 0; t < 3; ++t) E2[3 * i + t] = P->patches[i].centroid[0] < 0.278f ? E[3 * i + t] : 0.0f;
            rad_system_init(&sys, &ff->matrix, P, E2);
            CHECK_OK(rad_solve_gauss_seidel(&sys, &so, B2, NULL, NULL));
            CHECK_OK(rad_matrix_multiply(&ff->matrix, B2, Hp2, NULL));
            CHECK_OK(rad_lightmap_refresh(wt, Hp2, R, NULL));
            CHECK_OK(rad_lightmap_gather(lm, P, B2, &rc, &go, G2, NULL));
            for (i = 0; i < o.width * o.height; ++i)
                if (lm->flags[i] & RAD_TEXEL_VALID) { err += fabs((double)R[3 * i + 1] - G2[3 * i + 1]); tot += G2[3 * i + 1]; }
            if (getenv("RAD_TEST_VERBOSE")) printf("    refresh from another solution: mean |error| %.4f of the mean texel, %llu entries\n", err / tot, (unsigned long long)entries);
            CHECK(err < 0.05 * tot);
        }
        rad_lightmap_weights_destroy(wt);
        free(R); free(R2); free(E2); free(B2); free(Hp2); free(Hp3); free(G2);
    }
    /* the factored rows without detail factors against the public interpolation: each valid
       sample's value is rad_patches_vertex_values interpolated with rad_patches_locate's
       weights (barycentrics from the triangle's corners here), a texel the mean of its
       samples */
    {
        rad_lightmap_weights *w0 = NULL;
        float *R = (float *)calloc(3 * (size_t)o.width * o.height, sizeof(float));
        float *Vv = (float *)malloc(sizeof(float) * 3 * (P->vertex_count + 1));
        double worst_rel = 0.0;
        uint32_t compared = 0;
        CHECK_OK(rad_lightmap_weights_create(lm, P, NULL, NULL, NULL, &w0));
        if (w0 && R && Vv) {
            CHECK(w0->row_count == lm->valid_texels);
            CHECK_OK(rad_patches_vertex_values(P, Hp, 3, Vv));
            CHECK_OK(rad_lightmap_refresh(w0, Hp, R, NULL));
            for (i = 0; i < o.width * o.height; ++i) {
                double ref[3] = { 0.0, 0.0, 0.0 };
                uint32_t s, nv = 0, k;
                if (!(lm->flags[i] & RAD_TEXEL_VALID)) continue;
                for (s = lm->sample_first[i]; s < lm->sample_first[i + 1]; ++s) {
                    const float *v = S->positions + 9 * (size_t)lm->sample_triangles[s], *x = lm->sample_positions + 3 * (size_t)s;
                    double e1[3], e2[3], d[3], a00 = 0, a01 = 0, a11 = 0, b0 = 0, b1 = 0, det;
                    float wv[3];
                    uint32_t p;
                    if (!lm->sample_valid[s]) continue;
                    for (k = 0; k < 3; ++k) {
                        e1[k] = v[3 + k] - v[k]; e2[k] = v[6 + k] - v[k]; d[k] = x[k] - v[k];
                        a00 += e1[k] * e1[k]; a01 += e1[k] * e2[k]; a11 += e2[k] * e2[k]; b0 += d[k] * e1[k]; b1 += d[k] * e2[k];
                    }
                    det = a00 * a11 - a01 * a01;
                    p = rad_patches_locate(P, lm->sample_triangles[s], (float)((a11 * b0 - a01 * b1) / det),
                                           (float)((a00 * b1 - a01 * b0) / det), wv);
                    ++nv;
                    for (k = 0; k < 3; ++k) {
                        uint32_t vx = P->patches[p].vertices[k], ch;
                        for (ch = 0; ch < 3; ++ch) ref[ch] += (double)wv[k] * Vv[3 * (size_t)vx + ch];
                    }
                }
                for (k = 0; k < 3; ++k) {
                    double rel = fabs(R[3 * i + k] - ref[k] / nv) / (ref[k] / nv + 1e-6);
                    if (rel > worst_rel) worst_rel = rel;
                }
                ++compared;
            }
            CHECK(compared == lm->valid_texels);
            CHECK(worst_rel < 1e-4); /* float rounding, and barycentrics clamped at triangle borders */
            if (getenv("RAD_TEST_VERBOSE")) printf("    factored refresh against interpolated vertex values: %.2e relative\n", worst_rel);
        }
        rad_lightmap_weights_destroy(w0);
        free(R); free(Vv);
    }
    /* direct light adds rad_direct_irradiance's mean */
    CHECK_OK(rad_lightmap_direct(lm, &rc, NULL, 0, NULL, Hd, NULL));
    for (i = 0; i < o.width * o.height; ++i)
        if (lm->flags[i] & RAD_TEXEL_VALID) CHECK(Hd[3 * i] >= 0.0f);
        else CHECK(Hd[3 * i] == 0.0f);
    /* dilation fills every texel; per-triangle charts have no seam across a shared edge of
       the same plane except the quads' diagonals, which stitching closes */
    CHECK_OK(rad_lightmap_dilate(lm, 3, H, 0, NULL));
    for (i = 0; i < 3 * o.width * o.height; ++i) CHECK(H[i] > 0.0f || H[i] == 0.0f);
    CHECK_OK(rad_lightmap_stitch(lm, 3, H, 0, &st, NULL));
    CHECK(st.seams >= 14); /* at least the diagonals of the 5 walls and the blocks' sides */
    CHECK(st.max_jump_after < 0.1f * st.max_jump_before);
out:
    free(Hp); free(H); free(Hd); free(sum); free(cnt); free(hp); free(ap);
    rad_lightmap_destroy(lm);
    lm_cornell_free(&cb);
}

/* A floor of two triangles in two charts far apart in the atlas (the second mirrored), under
   a lamp: after dilation and stitching the largest jump across the seam is below 1% of the
   irradiance there, and the values away from the seam barely move */
static void lm_test_seam(void)
{
    float pos[12] = { 0, 0, 0, 0, 0, 1, 1, 0, 1, 1, 0, 0 }; /* floor y = 0, up: (0,0,0) (0,0,1) (1,0,1) (1,0,0) */
    /* unindexed: triangle A = 0 1 2 in the left half, triangle B = 0 2 3 in the right half */
    float P6[18], luv[12];
    const float lp[12] = { 0.3f, 0.9f, 0.3f, 0.7f, 0.9f, 0.3f, 0.7f, 0.9f, 0.7f, 0.3f, 0.9f, 0.7f };
    const uint32_t lidx[6] = { 0, 1, 2, 0, 2, 3 };
    rad_mesh_desc m[2];
    rad_scene_desc d;
    rad_material mats[2] = { { { 0.5f, 0.5f, 0.5f }, { 0, 0, 0 }, 0, 0, 0, 0, 0.0f }, { { 0.5f, 0.5f, 0.5f }, { 5, 5, 5 }, 0, 0, 0, 0, 0.0f } };
    rad_scene *S = NULL;
    rad_bvh *b = NULL;
    rad_raycaster rc;
    rad_patches *P = NULL;
    rad_patch_options po;
    rad_lightmap *lm = NULL;
    rad_lightmap_options o;
    rad_lightmap_gather_options go;
    rad_lightmap_seam_stats st;
    float *B = NULL, *H = NULL, *H0 = NULL;
    uint32_t i, k;
    int v;
    for (v = 0; v < 3; ++v) {
        memcpy(P6 + 3 * v, pos + 3 * (v == 0 ? 0 : v == 1 ? 1 : 2), 3 * sizeof(float));
        memcpy(P6 + 9 + 3 * v, pos + 3 * (v == 0 ? 0 : v == 1 ? 2 : 3), 3 * sizeof(float));
    }
    /* A: (x, z) -> (0.05 + 0.4 z, 0.05 + 0.8 x); B: mirrored into the right half at half the
       texel density, so the two sides' bilinear reconstructions differ */
    for (v = 0; v < 6; ++v) {
        const float *p = P6 + 3 * v;
        if (v < 3) { luv[2 * v] = 0.05f + 0.4f * p[2]; luv[2 * v + 1] = 0.05f + 0.8f * p[0]; }
        else { luv[2 * v] = 0.95f - 0.2f * p[0]; luv[2 * v + 1] = 0.05f + 0.4f * p[2]; }
    }
    memset(m, 0, sizeof(m));
    m[0].positions = P6; m[0].vertex_count = 6; m[0].triangle_count = 2; m[0].lightmap_uvs = luv;
    m[1].positions = lp; m[1].vertex_count = 4; m[1].indices = lidx; m[1].triangle_count = 2; m[1].material = 1;
    memset(&d, 0, sizeof(d));
    d.meshes = m; d.mesh_count = 2; d.materials = mats; d.material_count = 2;
    CHECK_OK(rad_scene_create(&d, NULL, &S));
    if (!S) return;
    CHECK_OK(rad_bvh_create(S, NULL, &b));
    rad_bvh_raycaster(b, &rc);
    rad_patch_options_default(&po);
    po.max_edge = 0.2f;
    CHECK_OK(rad_patches_create(S, &po, NULL, &P));
    rad_lightmap_options_default(&o);
    o.width = o.height = 40;
    CHECK_OK(rad_lightmap_create(S, &rc, &o, NULL, &lm));
    if (!P || !lm) goto out;
    B = (float *)malloc(sizeof(float) * 3 * P->count);
    for (i = 0; i < P->count; ++i)
        for (k = 0; k < 3; ++k) B[3 * i + k] = (float)LM_PI * P->patches[i].emission[k];
    H = (float *)malloc(sizeof(float) * 3 * 40 * 40);
    H0 = (float *)malloc(sizeof(float) * 3 * 40 * 40);
    rad_lightmap_gather_options_default(&go);
    CHECK_OK(rad_lightmap_gather(lm, P, B, &rc, &go, H, NULL));
    /* +-5% texel noise, as a Monte Carlo baker would leave: the seam must close anyway */
    for (i = 0; i < 40 * 40; ++i)
        for (k = 0; k < 3; ++k) H[3 * i + k] *= 1.0f + 0.025f * (float)((int)((i % 40) * 7 + (i / 40) * 13) % 5 - 2);
    CHECK_OK(rad_lightmap_dilate(lm, 3, H, 3, NULL));
    memcpy(H0, H, sizeof(float) * 3 * 40 * 40);
    CHECK_OK(rad_lightmap_stitch(lm, 3, H, 0, &st, NULL));
    CHECK(st.seams == 1);
    CHECK(st.sample_pairs >= 40);
    /* the irradiance along the diagonal is about 1 (lamp 5 x pi exitance, 0.6 m above) */
    {
        float a[3], c[3], ref = H0[3 * (20 * 40 + 10)];
        if (getenv("RAD_TEST_VERBOSE")) printf("    seam jump %g before, %g after, irradiance %g\n", st.max_jump_before, st.max_jump_after, ref);
        CHECK(ref > 0.5f);
        CHECK(st.max_jump_before > 0.03f * ref); /* the seam was visible */
        if (rad_test_failures) printf("    seam jump %g before, %g after, irradiance %g\n", st.max_jump_before, st.max_jump_after, ref);
        CHECK(st.max_jump_after < 0.01f * ref);
        for (i = 0; i <= 20; ++i) {
            float s = (float)i / 20.0f;
            /* diagonal (0,0,0)-(1,0,1): A's uv (0.05 + 0.4 s, 0.05 + 0.8 s), B's (0.95 - 0.2 s, 0.05 + 0.4 s) */
            rad_lightmap_sample(lm, 3, H, 0.05f + 0.4f * s, 0.05f + 0.8f * s, a);
            rad_lightmap_sample(lm, 3, H, 0.95f - 0.2f * s, 0.05f + 0.4f * s, c);
            CHECK_NEAR(a[0], c[0], 0.01f * ref);
        }
        /* texels away from the seam keep their values */
        CHECK_NEAR(H[3 * (30 * 40 + 5)], H0[3 * (30 * 40 + 5)], 1e-6f);
    }
out:
    free(B); free(H); free(H0);
    rad_lightmap_destroy(lm);
    rad_patches_destroy(P);
    rad_bvh_destroy(b);
    rad_scene_destroy(S);
}

/* The hemisphere gather against the exact one on the Cornell box: the same sum estimated by
   rays, so the texels agree within its noise (a few % at 1024 rays a texel) and the totals
   within 1%; with every patch bright it is the exact gather bit for bit; the bits do not
   depend on the task count; bad options are refused */
static void lm_test_hemisphere(void)
{
    lm_cornell cb;
    rad_raycaster rc;
    rad_patches *P;
    float *B;
    rad_lightmap *lm = NULL;
    rad_lightmap_options o;
    rad_lightmap_gather_options go;
    rad_context ctx;
    float *X = NULL, *H = NULL, *H2 = NULL, *XS = NULL, *HS = NULL;
    double ym = 0.0, err = 0.0, sx = 0.0, sh = 0.0, s0x = 0.0, s0h = 0.0;
    uint32_t i, n = 0, texels;
    if (lm_cornell_make(&cb, 8, 150, 0)) goto out;
    rc = cb.rc, P = cb.P, B = cb.B;
    rad_lightmap_options_default(&o);
    o.width = o.height = cb.g.cells * cb.g.cell;
    CHECK_OK(rad_lightmap_create(cb.S, &rc, &o, NULL, &lm));
    if (!lm) goto out;
    texels = o.width * o.height;
    X = (float *)calloc(3 * (size_t)texels, sizeof(float));
    H = (float *)calloc(3 * (size_t)texels, sizeof(float));
    H2 = (float *)calloc(3 * (size_t)texels, sizeof(float));
    XS = (float *)calloc(12 * (size_t)texels, sizeof(float));
    HS = (float *)calloc(12 * (size_t)texels, sizeof(float));
    rad_lightmap_gather_options_default(&go);
    CHECK(go.method == RAD_LIGHTMAP_GATHER_EXACT && go.hemisphere_rays == 256 && go.exact_ratio == 16.0f);
    CHECK_OK(rad_lightmap_gather(lm, P, B, &rc, &go, X, NULL));
    go.method = RAD_LIGHTMAP_GATHER_HEMISPHERE;
    go.hemisphere_rays = 1024;
    CHECK_OK(rad_lightmap_gather(lm, P, B, &rc, &go, H, NULL));
    for (i = 0; i < texels; ++i)
        if (lm->flags[i] & RAD_TEXEL_VALID) { ym += X[3 * i + 1]; ++n; }
    CHECK(n > 100);
    ym /= n ? n : 1u;
    n = 0;
    for (i = 0; i < texels; ++i) {
        if (!(lm->flags[i] & RAD_TEXEL_VALID)) { CHECK(H[3 * i] == 0.0f); continue; }
        sx += X[3 * i + 1];
        sh += H[3 * i + 1];
        if (X[3 * i + 1] < 0.01 * ym) continue;
        err += fabs((double)H[3 * i + 1] - X[3 * i + 1]) / X[3 * i + 1];
        ++n;
    }
    err /= n ? n : 1u;
    if (rad_test_failures || getenv("RAD_TEST_VERBOSE"))
        printf("    hemisphere vs exact: mean |relative difference| %.4f over %u texels, totals %.5g %.5g\n", err, n, sh, sx);
    CHECK(err < 0.02);
    CHECK_REL(sh, sx, 0.01);
    /* SH: the same for L_0,0 */
    go.encoding = RAD_LIGHTMAP_SH_L1;
    go.method = RAD_LIGHTMAP_GATHER_EXACT;
    CHECK_OK(rad_lightmap_gather(lm, P, B, &rc, &go, XS, NULL));
    go.method = RAD_LIGHTMAP_GATHER_HEMISPHERE;
    CHECK_OK(rad_lightmap_gather(lm, P, B, &rc, &go, HS, NULL));
    for (i = 0; i < texels; ++i) { s0x += XS[12 * i + 1]; s0h += HS[12 * i + 1]; }
    CHECK_REL(s0h, s0x, 0.02);
    /* the same bits with one task and with seven */
    go.encoding = RAD_LIGHTMAP_IRRADIANCE;
    go.hemisphere_rays = 64;
    memset(&ctx, 0, sizeof ctx);
    ctx.task_count = 1;
    CHECK_OK(rad_lightmap_gather(lm, P, B, &rc, &go, H, &ctx));
    ctx.task_count = 7;
    CHECK_OK(rad_lightmap_gather(lm, P, B, &rc, &go, H2, &ctx));
    CHECK(memcmp(H, H2, 3 * sizeof(float) * texels) == 0);
    /* every lit patch bright: the exact gather, bit for bit */
    go.exact_ratio = 1e-20f;
    CHECK_OK(rad_lightmap_gather(lm, P, B, &rc, &go, H, NULL));
    CHECK(memcmp(H, X, 3 * sizeof(float) * texels) == 0);
    /* bad options */
    go.exact_ratio = -1.0f;
    CHECK_RESULT(rad_lightmap_gather(lm, P, B, &rc, &go, H, NULL), RAD_ERROR_INVALID_ARGUMENT);
    go.exact_ratio = 0.0f;
    go.hemisphere_rays = 65537;
    CHECK_RESULT(rad_lightmap_gather(lm, P, B, &rc, &go, H, NULL), RAD_ERROR_INVALID_ARGUMENT);
    go.hemisphere_rays = 0;
    go.method = (rad_lightmap_gather_method)2;
    CHECK_RESULT(rad_lightmap_gather(lm, P, B, &rc, &go, H, NULL), RAD_ERROR_INVALID_ARGUMENT);
    go.method = RAD_LIGHTMAP_GATHER_HEMISPHERE;
    rc.intersect = NULL;
    CHECK_RESULT(rad_lightmap_gather(lm, P, B, &rc, &go, H, NULL), RAD_ERROR_INVALID_ARGUMENT);
out:
    free(X); free(H); free(H2); free(XS); free(HS);
    rad_lightmap_destroy(lm);
    lm_cornell_free(&cb);
}

/* E = rho D for the hierarchical solve (the source rad render --method hierarchical uses) */
typedef struct lm_hr_src { const rad_scene *S; const rad_raycaster *rc; } lm_hr_src;
static rad_result lm_hr_source(void *user, const float *points, const float *normals, const uint32_t *triangles,
                               const float *albedos, uint32_t count, float *out_E)
{
    const lm_hr_src *d = (const lm_hr_src *)user;
    rad_direct_options dopt;
    rad_result r;
    uint32_t i;
    (void)triangles;
    rad_direct_options_default(&dopt);
    dopt.exclude_emitters = 0;
    r = rad_direct_irradiance(d->S, d->rc, NULL, 0, &dopt, points, normals, count, out_E, NULL);
    for (i = 0; r == RAD_SUCCESS && i < 3 * count; ++i) out_E[i] *= albedos[i];
    return r;
}

/* Lightmaps from virtual patches and from the hierarchical solution, on the Cornell box lit
   by its lamp as a light (the lightmap then holds the indirect irradiance): per triangle, the
   mean over its valid samples against the lightmap of the classic solution of the same scene
   (a second method: the bounds are the proxies' coarseness, measured in the comments); the
   refresh weights of the virtual-patch gather against a fresh gather of another solution (a
   point light), which must agree to float rounding; bad input refused */
static void lm_test_other_sources(void)
{
    lm_cornell cb;
    rad_lightmap *lm = NULL;
    rad_lightmap_options o;
    rad_lightmap_gather_options go;
    rad_virtual_patches *vp = NULL;
    rad_vp_options vo;
    rad_direct_options dopt;
    rad_system sys;
    rad_solve_options so;
    rad_lightmap_weights *wt = NULL;
    rad_hierarchical *hr = NULL;
    rad_hierarchical_options ho;
    rad_light pl;
    lm_hr_src hsrc;
    float *Hc = NULL, *Hv = NULL, *Hh = NULL, *R = NULL, *Ev = NULL, *Bv = NULL, *Pv = NULL;
    double *sc = NULL, *sv = NULL, *sh = NULL, *cnt = NULL, vmean = 0.0, vworst = 0.0, hmean = 0.0, hworst = 0.0;
    double worst_rel = 0.0;
    uint32_t i, t, k, texels, checked = 0, rows = 0;
    if (lm_cornell_make(&cb, 8, rad_test_quick() ? 150 : 300, 1)) goto out;
    rad_lightmap_options_default(&o);
    o.width = o.height = cb.g.cells * cb.g.cell;
    CHECK_OK(rad_lightmap_create(cb.S, &cb.rc, &o, NULL, &lm));
    if (!lm) goto out;
    texels = o.width * o.height;
    Hc = (float *)calloc(3 * (size_t)texels, sizeof(float));
    Hv = (float *)calloc(3 * (size_t)texels, sizeof(float));
    Hh = (float *)calloc(3 * (size_t)texels, sizeof(float));
    R = (float *)calloc(3 * (size_t)texels, sizeof(float));
    rad_lightmap_gather_options_default(&go);
    go.visibility_rays = 2;
    CHECK_OK(rad_lightmap_gather(lm, cb.P, cb.B, &cb.rc, &go, Hc, NULL));
    /* the virtual-patch solution as rad render --method aavp: E = rho D, L by Gauss-Seidel,
       H = F (E + L) gathered */
    rad_vp_options_default(&vo);
    vo.resolution = rad_test_quick() ? 8 : 12;
    CHECK_OK(rad_vp_create(cb.S, &cb.rc, &vo, NULL, &vp));
    if (!vp) goto out;
    Ev = (float *)malloc(sizeof(float) * 3 * vp->count);
    Bv = (float *)malloc(sizeof(float) * 3 * vp->count);
    Pv = (float *)malloc(sizeof(float) * 3 * vp->count);
    rad_direct_options_default(&dopt);
    dopt.exclude_emitters = 0;
    CHECK_OK(rad_vp_sources(vp, &cb.rc, NULL, 0, &dopt, RAD_SOURCE_DIRECT, Ev, NULL));
    rad_vp_system(&sys, vp, Ev);
    rad_solve_options_default(&so);
    so.output = RAD_OUTPUT_TOTAL;
    CHECK_OK(rad_solve_gauss_seidel(&sys, &so, Bv, NULL, NULL));
    CHECK_OK(rad_matrix_multiply(&vp->matrix, Bv, Pv, NULL));
    CHECK_OK(rad_lightmap_gather_vp(lm, vp, Pv, Hv, NULL));
    /* the hierarchical solution with the same source (its lookup of H) */
    rad_hierarchical_options_default(&ho);
    hsrc.S = cb.S;
    hsrc.rc = &cb.rc;
    ho.source = lm_hr_source;
    ho.source_user = &hsrc;
    ho.tolerance = 1e-4;
    CHECK_OK(rad_hierarchical_create(cb.S, &cb.rc, &ho, NULL, &hr));
    if (hr) CHECK_OK(rad_hierarchical_solve(hr, NULL));
    if (hr) CHECK_OK(rad_lightmap_gather_hierarchical(lm, hr, RAD_HIERARCHICAL_GATHERED, Hh, NULL));
    sc = (double *)calloc(cb.S->triangle_count, sizeof(double));
    sv = (double *)calloc(cb.S->triangle_count, sizeof(double));
    sh = (double *)calloc(cb.S->triangle_count, sizeof(double));
    cnt = (double *)calloc(cb.S->triangle_count, sizeof(double));
    for (i = 0; i < texels; ++i) {
        uint32_t s;
        if (!(lm->flags[i] & RAD_TEXEL_VALID)) { CHECK(Hv[3 * i] == 0.0f && Hh[3 * i] == 0.0f); continue; }
        for (s = lm->sample_first[i]; s < lm->sample_first[i + 1]; ++s) {
            if (!lm->sample_valid[s]) continue;
            t = lm->sample_triangles[s];
            for (k = 0; k < 3; ++k) { sc[t] += Hc[3 * i + k]; sv[t] += Hv[3 * i + k]; sh[t] += Hh[3 * i + k]; }
            cnt[t] += 1.0;
        }
    }
    for (t = 0; t < cb.S->triangle_count; ++t) {
        double dv, dh;
        if (!(cnt[t] > 0.0) || !(sc[t] > 0.0) || strcmp(cb.S0->mesh_names[cb.S0->meshes[t]], "light") == 0) continue;
        dv = fabs(sv[t] - sc[t]) / sc[t];
        dh = fabs(sh[t] - sc[t]) / sc[t];
        if (getenv("RAD_TEST_VERBOSE"))
            printf("    triangle %u of '%s': classic %g, vp %g, hierarchical %g\n", t, cb.S0->mesh_names[cb.S0->meshes[t]],
                   sc[t] / cnt[t], sv[t] / cnt[t], sh[t] / cnt[t]);
        vmean += dv; hmean += dh;
        if (dv > vworst) vworst = dv;
        if (dh > hworst) hworst = dh;
        ++checked;
    }
    CHECK(checked >= 28);
    vmean /= checked ? checked : 1u;
    hmean /= checked ? checked : 1u;
    if (rad_test_failures || getenv("RAD_TEST_VERBOSE"))
        printf("    per-triangle |relative difference| to classic: vp mean %.4f worst %.4f, hierarchical mean %.4f worst %.4f\n",
               vmean, vworst, hmean, hworst);
    /* virtual patches at 8 voxels a side: 6% on average, the worst a dark block face lit
       mostly from the floor beside it (32%), where the trilinear filter blends voxels that see
       the floor differently; the hierarchical solution at tolerance 1e-4: 8%, worst 45% on
       the same faces (the classic patches are themselves a few % off there) */
    CHECK(vmean < 0.08);
    CHECK(vworst < 0.40);
    CHECK(hmean < 0.11);
    CHECK(hworst < 0.55);
    /* refresh weights: the same solution gives the gather back, another (a point light) its
       fresh gather; texels without a row keep their value */
    CHECK_OK(rad_lightmap_weights_create_vp(lm, vp, NULL, &wt));
    if (wt) {
        memset(&pl, 0, sizeof pl);
        pl.type = RAD_LIGHT_POINT;
        pl.position[0] = 0.15f; pl.position[1] = 0.3f; pl.position[2] = 0.3f;
        pl.color[0] = 0.02f; pl.color[1] = 0.01f; pl.color[2] = 0.005f;
        CHECK(wt->patch_count == vp->count && wt->vertex_count == vp->count);
        for (i = 0; i < texels; ++i) R[3 * i] = -1.0f;
        CHECK_OK(rad_lightmap_refresh(wt, Pv, R, NULL));
        for (i = 0; i < 2; ++i) {
            uint32_t j;
            if (i == 1) { /* the new solution */
                CHECK_OK(rad_vp_sources(vp, &cb.rc, &pl, 1, &dopt, RAD_SOURCE_DIRECT, Ev, NULL));
                rad_vp_system(&sys, vp, Ev);
                CHECK_OK(rad_solve_gauss_seidel(&sys, &so, Bv, NULL, NULL));
                CHECK_OK(rad_matrix_multiply(&vp->matrix, Bv, Pv, NULL));
                CHECK_OK(rad_lightmap_gather_vp(lm, vp, Pv, Hv, NULL));
                CHECK_OK(rad_lightmap_refresh(wt, Pv, R, NULL));
            }
            for (j = 0; j < texels; ++j) {
                if (R[3 * j] == -1.0f) { CHECK(Hv[3 * j] == 0.0f); continue; } /* no row: no sample reached */
                if (i == 0) ++rows;
                for (k = 0; k < 3; ++k) {
                    double rel = fabs((double)R[3 * j + k] - Hv[3 * j + k]) / (fabs(Hv[3 * j + k]) + 1e-6);
                    if (rel > worst_rel) worst_rel = rel;
                }
            }
        }
        CHECK(rows == wt->row_count && rows + 8 >= lm->valid_texels);
        if (getenv("RAD_TEST_VERBOSE"))
            printf("    vp refresh against fresh gathers: %.2e relative, %u rows, %u entries\n", worst_rel, wt->row_count,
                   wt->row_first[wt->row_count]);
        CHECK(worst_rel < 1e-5);
        CHECK(wt->row_first[wt->row_count] <= 48u * wt->row_count);
    }
    rad_lightmap_weights_destroy(wt);
    wt = NULL;
    /* bad input */
    CHECK_RESULT(rad_lightmap_gather_vp(NULL, vp, Pv, Hv, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_lightmap_gather_vp(lm, vp, NULL, Hv, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_lightmap_gather_vp(lm, vp, Pv, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    Pv[4] = (float)(1.0 / sqrt(-1.0 + 0.0 * vmean));
    CHECK_RESULT(rad_lightmap_gather_vp(lm, vp, Pv, Hv, NULL), RAD_ERROR_NON_FINITE);
    CHECK_RESULT(rad_lightmap_weights_create_vp(lm, NULL, NULL, &wt), RAD_ERROR_INVALID_ARGUMENT);
    CHECK(wt == NULL);
    CHECK_RESULT(rad_lightmap_weights_create_vp(lm, vp, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_lightmap_gather_hierarchical(lm, hr, (rad_hierarchical_value)7, Hh, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_lightmap_gather_hierarchical(lm, NULL, RAD_HIERARCHICAL_GATHERED, Hh, NULL), RAD_ERROR_INVALID_ARGUMENT);
    {
        /* a set and a solution of another scene (the box without per-triangle charts) */
        rad_virtual_patches *v0 = NULL;
        rad_hierarchical *h0 = NULL;
        rad_bvh *b0 = NULL;
        rad_raycaster r0;
        CHECK_OK(rad_bvh_create(cb.S0, NULL, &b0));
        if (b0) {
            rad_bvh_raycaster(b0, &r0);
            vo.resolution = 4;
            CHECK_OK(rad_vp_create(cb.S0, &r0, &vo, NULL, &v0));
            CHECK_RESULT(rad_lightmap_gather_vp(lm, v0, Pv, Hv, NULL), RAD_ERROR_INVALID_ARGUMENT);
            CHECK_RESULT(rad_lightmap_weights_create_vp(lm, v0, NULL, &wt), RAD_ERROR_INVALID_ARGUMENT);
            CHECK_OK(rad_hierarchical_create(cb.S0, &r0, &ho, NULL, &h0));
            /* not solved, then of another scene */
            CHECK_RESULT(rad_lightmap_gather_hierarchical(lm, h0, RAD_HIERARCHICAL_GATHERED, Hh, NULL), RAD_ERROR_INVALID_ARGUMENT);
            if (h0) CHECK_OK(rad_hierarchical_solve(h0, NULL));
            CHECK_RESULT(rad_lightmap_gather_hierarchical(lm, h0, RAD_HIERARCHICAL_GATHERED, Hh, NULL), RAD_ERROR_INVALID_ARGUMENT);
        }
        rad_hierarchical_destroy(h0);
        rad_vp_destroy(v0);
        rad_bvh_destroy(b0);
    }
out:
    free(Hc); free(Hv); free(Hh); free(R); free(Ev); free(Bv); free(Pv);
    free(sc); free(sv); free(sh); free(cnt);
    rad_lightmap_weights_destroy(wt);
    rad_hierarchical_destroy(hr);
    rad_vp_destroy(vp);
    rad_lightmap_destroy(lm);
    lm_cornell_free(&cb);
}

static const rad_test_case tests_lightmap[] = {
    { "lightmap_polygon_projection", lm_test_polygon },
    { "lightmap_coverage", lm_test_coverage },
    { "lightmap_sh_uniform", lm_test_sh_uniform },
    { "lightmap_no_leak", lm_test_no_leak },
    { "lightmap_cornell", lm_test_cornell },
    { "lightmap_seam", lm_test_seam },
    { "lightmap_hemisphere", lm_test_hemisphere },
    { "lightmap_other_sources", lm_test_other_sources },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_lightmap)

/* test_formfactor.c - form factors (SPEC §2) against the closed forms of REFERENCE.md §1, the
   enclosure properties, the row/sparse/dense storage, determinism, and the built-in BVH
   against a brute-force ray caster. Included by test_main.c after the implementation: every
   name is static and prefixed ff_. */

#ifndef FF_PI
#define FF_PI 3.14159265358979323846
#endif

/* ---------------------------------------------------------------------------------------- */
/* helpers                                                                                  */
/* ---------------------------------------------------------------------------------------- */

/* A planar quad o, o+u, o+u+v, o+v: counter-clockwise seen from the side u x v points to, so
   that side is its front. Two triangles (0 1 2) (0 2 3). */
typedef struct ff_quad {
    float pos[12];
} ff_quad;

static const uint32_t ff_quad_indices[6] = { 0, 1, 2, 0, 2, 3 };

static void ff_quad_set(ff_quad *q, float ox, float oy, float oz, float ux, float uy, float uz, float vx, float vy,
                        float vz)
{
    float o[3], u[3], v[3];
    int k;
    o[0] = ox; o[1] = oy; o[2] = oz;
    u[0] = ux; u[1] = uy; u[2] = uz;
    v[0] = vx; v[1] = vy; v[2] = vz;
    for (k = 0; k < 3; ++k) {
        q->pos[k] = o[k];
        q->pos[3 + k] = o[k] + u[k];
        q->pos[6 + k] = o[k] + u[k] + v[k];
        q->pos[9 + k] = o[k] + v[k];
    }
}

static void ff_mesh_quad(rad_mesh_desc *m, const ff_quad *q)
{
    memset(m, 0, sizeof(*m));
    m->positions = q->pos;
    m->vertex_count = 4;
    m->indices = ff_quad_indices;
    m->triangle_count = 2;
    m->material = 0;
}

/* A scene, its patches, its BVH and a raycaster over it. */
typedef struct ff_world {
    rad_scene *scene;
    rad_patches *patches;
    rad_bvh *bvh;
    rad_raycaster rc;
} ff_world;

static void ff_world_free(ff_world *w)
{
    rad_bvh_destroy(w->bvh);
    rad_patches_destroy(w->patches);
    rad_scene_destroy(w->scene);
    memset(w, 0, sizeof(*w));
}

/* Builds scene + patches (max_edge and/or target_count) + BVH. Returns 1 on success. */
static int ff_world_make(const rad_scene_desc *desc, float max_edge, uint32_t target_count, ff_world *w)
{
    rad_patch_options popt;
    rad_result r;
    memset(w, 0, sizeof(*w));
    r = rad_scene_create(desc, NULL, &w->scene);
    CHECK_OK(r);
    if (r != RAD_SUCCESS) return 0;
    rad_patch_options_default(&popt);
    popt.max_edge = max_edge;
    popt.target_count = target_count;
    r = rad_patches_create(w->scene, &popt, NULL, &w->patches);
    CHECK_OK(r);
    if (r != RAD_SUCCESS) { ff_world_free(w); return 0; }
    r = rad_bvh_create(w->scene, NULL, &w->bvh);
    CHECK_OK(r);
    if (r != RAD_SUCCESS) { ff_world_free(w); return 0; }
    rad_bvh_raycaster(w->bvh, &w->rc);
    return 1;
}

static const rad_material ff_grey = { { 0.5f, 0.5f, 0.5f }, { 0.0f, 0.0f, 0.0f }, 0 };

static void ff_desc(rad_scene_desc *d, const rad_mesh_desc *meshes, uint32_t count)
{
    memset(d, 0, sizeof(*d));
    d->meshes = meshes;
    d->mesh_count = count;
    d->materials = &ff_grey;
    d->material_count = 1;
}

/* Area-weighted group form factor F_GH = sum_{i in G} A_i sum_{j in H} F_ij / sum_{i in G} A_i,
   groups by the scene mesh of each patch's triangle. */
static double ff_group(const rad_patches *P, const float *F, uint32_t g, uint32_t h, double *area_g)
{
    const rad_scene *s = P->scene;
    double num = 0.0, den = 0.0;
    uint32_t i, j, N = P->count;
    for (i = 0; i < N; ++i) {
        double row = 0.0;
        if (s->meshes[P->patches[i].triangle] != g) continue;
        for (j = 0; j < N; ++j)
            if (s->meshes[P->patches[j].triangle] == h) row += (double)F[(size_t)i * N + j];
        num += (double)P->patches[i].area * row;
        den += (double)P->patches[i].area;
    }
    if (area_g) *area_g = den;
    return den > 0.0 ? num / den : 0.0;
}

/* Howell C-11: identical parallel opposed rectangles a x b at gap c */
static double ff_c11(double a, double b, double c)
{
    double X = a / c, Y = b / c;
    return 2.0 / (FF_PI * X * Y) *
           (log(sqrt((1 + X * X) * (1 + Y * Y) / (1 + X * X + Y * Y))) + X * sqrt(1 + Y * Y) * atan(X / sqrt(1 + Y * Y)) +
            Y * sqrt(1 + X * X) * atan(Y / sqrt(1 + X * X)) - X * atan(X) - Y * atan(Y));
}

/* Howell C-14: A1 = l x w, A2 = l x h, common edge l; F_12 */
static double ff_c14(double l, double w, double h)
{
    double H = h / l, W = w / l, H2 = H * H, W2 = W * W, S = sqrt(H2 + W2);
    double t1 = (1 + W2) * (1 + H2) / (1 + W2 + H2);
    double t2 = pow(W2 * (1 + W2 + H2) / ((1 + W2) * (W2 + H2)), W2);
    double t3 = pow(H2 * (1 + W2 + H2) / ((1 + H2) * (W2 + H2)), H2);
    return 1.0 / (FF_PI * W) * (W * atan(1 / W) + H * atan(1 / H) - S * atan(1 / S) + 0.25 * log(t1 * t2 * t3));
}

/* Howell C-41: coaxial parallel disks r1 (emitter), r2, gap h */
static double ff_c41(double r1, double r2, double h)
{
    double R1 = r1 / h, R2 = r2 / h, X = 1 + (1 + R2 * R2) / (R1 * R1);
    return 0.5 * (X - sqrt(X * X - 4 * (R2 / R1) * (R2 / R1)));
}

/* radius of the disk with the area of a regular n-gon of circumradius r */
static double ff_equal_area_radius(double r, int n)
{
    double area = 0.5 * n * r * r * sin(2.0 * FF_PI / n);
    return sqrt(area / FF_PI);
}

/* Lambert's contour integral in double, unclipped, for a polygon entirely in front of p:
   an independent reference for rad_ff_point_polygon. */
static double ff_ref_contour(const double *p, const double *n, const double *v, int count)
{
    double sum = 0.0;
    int i, k;
    for (i = 0; i < count; ++i) {
        double a[3], b[3], c[3], la = 0, lb = 0, cl, d;
        for (k = 0; k < 3; ++k) {
            a[k] = v[3 * i + k] - p[k];
            b[k] = v[3 * ((i + 1) % count) + k] - p[k];
            la += a[k] * a[k];
            lb += b[k] * b[k];
        }
        la = sqrt(la);
        lb = sqrt(lb);
        for (k = 0; k < 3; ++k) { a[k] /= la; b[k] /= lb; }
        c[0] = a[1] * b[2] - a[2] * b[1];
        c[1] = a[2] * b[0] - a[0] * b[2];
        c[2] = a[0] * b[1] - a[1] * b[0];
        cl = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        sum += atan2(cl, d) * (n[0] * c[0] + n[1] * c[1] + n[2] * c[2]) / cl;
    }
    return fabs(sum) / (2.0 * FF_PI);
}

/* ---------------------------------------------------------------------------------------- */
/* 1. rad_ff_point_polygon                                                                  */
/* ---------------------------------------------------------------------------------------- */

static void ff_test_point_polygon_square(void)
{
    /* unit square in z = 0, counter-clockwise seen from +z: its front faces +z */
    static const float sq[12] = { 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0 };
    static const float sq_cw[12] = { 0, 0, 0, 0, 1, 0, 1, 1, 0, 1, 0, 0 };
    const float down[3] = { 0, 0, -1 }, up[3] = { 0, 0, 1 };
    const float centre[3] = { 0.5f, 0.5f, 1.0f }, corner[3] = { 0.0f, 0.0f, 1.0f };
    const float below[3] = { 0.5f, 0.5f, -1.0f };
    /* the kernel runs in double and returns a float: 1e-6 relative is a few float ulps */
    CHECK_REL(rad_ff_point_polygon(centre, down, sq, 4), 0.23945647, 1e-6);
    CHECK_REL(rad_ff_point_polygon(corner, down, sq, 4), 0.13853161, 1e-6);
    /* winding: the same square clockwise seen from the point has its front facing away from
       the point, so the point is behind it: exactly 0 */
    CHECK(rad_ff_point_polygon(centre, down, sq_cw, 4) == 0.0f);
    CHECK(rad_ff_point_polygon(corner, down, sq_cw, 4) == 0.0f);
    /* behind the polygon's plane (its front faces +z, the point is at z = -1 looking up) */
    CHECK(rad_ff_point_polygon(below, up, sq, 4) == 0.0f);
    /* in front of the polygon but facing away: the whole polygon is below the tangent plane */
    CHECK(rad_ff_point_polygon(centre, up, sq, 4) == 0.0f);
    /* a non-unit normal is normalised (doc: "unit normal"; a scaled one must not scale F) */
    {
        const float down3[3] = { 0, 0, -3 };
        CHECK_REL(rad_ff_point_polygon(centre, down3, sq, 4), 0.23945647, 1e-6);
    }
}

static void ff_test_point_polygon_disk(void)
{
    enum { NG = 256 };
    static float poly[3 * NG];
    const float p[3] = { 0, 0, 1 }, n[3] = { 0, 0, -1 };
    double reff, expect, got;
    int i;
    /* coaxial disk r = h = 1 as a regular 256-gon (CCW seen from +z, the point's side) */
    for (i = 0; i < NG; ++i) {
        double a = 2.0 * FF_PI * i / NG;
        poly[3 * i] = (float)cos(a);
        poly[3 * i + 1] = (float)sin(a);
        poly[3 * i + 2] = 0.0f;
    }
    reff = ff_equal_area_radius(1.0, NG);
    expect = reff * reff / (reff * reff + 1.0);
    got = rad_ff_point_polygon(p, n, poly, NG);
    /* the 256-gon and the disk of equal area differ by O((pi/256)^2 / 12 ~ 1e-5) in radius
       moments; 1e-4 relative covers the shape difference, the float vertices and the return */
    CHECK_REL(got, expect, 1e-4);
    CHECK_NEAR(got, 0.5, 2e-4); /* the disk itself, REFERENCE.md table */

    /* off-axis: disk of radius 0.5 centred at (0.7, 0.2, 0); point at (0,0,1)... use an
       offset a = |(0.7, 0.2)| in the formula */
    {
        const double cx = 0.7, cy = 0.2, r = 0.5, h = 1.0;
        double a = sqrt(cx * cx + cy * cy), A, R;
        for (i = 0; i < NG; ++i) {
            double t = 2.0 * FF_PI * i / NG;
            poly[3 * i] = (float)(cx + r * cos(t));
            poly[3 * i + 1] = (float)(cy + r * sin(t));
            poly[3 * i + 2] = 0.0f;
        }
        reff = ff_equal_area_radius(r, NG);
        A = a / h;
        R = reff / h;
        expect = 0.5 * (1.0 - (1.0 + A * A - R * R) / sqrt((1 + A * A + R * R) * (1 + A * A + R * R) - 4 * A * A * R * R));
        got = rad_ff_point_polygon(p, n, poly, NG);
        /* same reasoning as above: equal-area 256-gon vs disk, float vertices */
        CHECK_REL(got, expect, 1e-4);
    }
    /* against an independent double-precision contour sum: a convex pentagon in a tilted
       plane (e1 x e2 points towards the receiver), receiver point off-centre, tilted normal */
    {
        static const double loc[10] = { 0.0, 0.0, 1.0, -0.1, 1.4, 0.7, 0.6, 1.2, -0.3, 0.6 };
        const double e1[3] = { 0.8, 0.0, 0.6 }, e2[3] = { 0.0, 1.0, 0.0 }; /* e1 x e2 = (-0.6, 0, 0.8) */
        double pd[3] = { 0.1, 0.5, 2.0 }, nd[3] = { 0.1, -0.2, -1.0 }, pdv[15], nl, ref;
        float pf[15], pp[3], nn[3];
        int k;
        nl = sqrt(nd[0] * nd[0] + nd[1] * nd[1] + nd[2] * nd[2]);
        for (k = 0; k < 3; ++k) { nn[k] = (float)(nd[k] / nl); pp[k] = (float)pd[k]; nd[k] = nn[k]; pd[k] = pp[k]; }
        for (i = 0; i < 5; ++i)
            for (k = 0; k < 3; ++k) {
                pf[3 * i + k] = (float)(loc[2 * i] * e1[k] + loc[2 * i + 1] * e2[k]);
                pdv[3 * i + k] = pf[3 * i + k];
            }
        ref = ff_ref_contour(pd, nd, pdv, 5);
        CHECK(ref > 0.05);
        /* same float inputs on both sides, both sums in double: 1e-6 is float rounding of the
           returned value */
        CHECK_REL(rad_ff_point_polygon(pp, nn, pf, 5), ref, 1e-6);
    }
}

static void ff_test_point_polygon_clip(void)
{
    /* point at the origin, normal +z; unit square in the plane x = 1 facing -x (towards the
       point), y in [-0.5, 0.5], z in [-0.5, 0.5]: half above, half below the tangent plane */
    static const float full[12] = { 1, -0.5f, -0.5f, 1, -0.5f, 0.5f, 1, 0.5f, 0.5f, 1, 0.5f, -0.5f };
    static const float upper[12] = { 1, -0.5f, 0.0f, 1, -0.5f, 0.5f, 1, 0.5f, 0.5f, 1, 0.5f, 0.0f };
    static const double upper_d[12] = { 1, -0.5, 0.0, 1, -0.5, 0.5, 1, 0.5, 0.5, 1, 0.5, 0.0 };
    const float p[3] = { 0, 0, 0 }, n[3] = { 0, 0, 1 };
    const double pd[3] = { 0, 0, 0 }, nd[3] = { 0, 0, 1 };
    double f_full = rad_ff_point_polygon(p, n, full, 4), f_up = rad_ff_point_polygon(p, n, upper, 4);
    double ref = ff_ref_contour(pd, nd, upper_d, 4);
    CHECK(f_up > 0.0);
    /* clipping at z = 0 must give the upper half exactly up to float rounding of the result */
    CHECK_REL(f_full, f_up, 1e-6);
    CHECK_REL(f_up, ref, 1e-6);
    /* the lower half alone is entirely below the tangent plane */
    {
        static const float lower[12] = { 1, -0.5f, -0.5f, 1, -0.5f, 0.0f, 1, 0.5f, 0.0f, 1, 0.5f, -0.5f };
        CHECK(rad_ff_point_polygon(p, n, lower, 4) == 0.0f);
    }
}

/* ---------------------------------------------------------------------------------------- */
/* 2. rad_ff_point_point                                                                    */
/* ---------------------------------------------------------------------------------------- */

static void ff_test_point_point(void)
{
    const float pi_[3] = { 0.1f, -0.2f, 0.3f }, pj[3] = { 0.4f, 0.2f, 2.3f };
    float ni[3] = { 0.1f, 0.05f, 1.0f }, nj[3] = { -0.1f, 0.2f, -1.0f };
    double r[3], d2, ci, cj, expect, l;
    int k;
    const float sj = 0.05f;
    l = sqrt((double)ni[0] * ni[0] + (double)ni[1] * ni[1] + (double)ni[2] * ni[2]);
    for (k = 0; k < 3; ++k) ni[k] = (float)(ni[k] / l);
    l = sqrt((double)nj[0] * nj[0] + (double)nj[1] * nj[1] + (double)nj[2] * nj[2]);
    for (k = 0; k < 3; ++k) nj[k] = (float)(nj[k] / l);
    for (k = 0; k < 3; ++k) r[k] = (double)pj[k] - pi_[k];
    d2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    ci = (r[0] * ni[0] + r[1] * ni[1] + r[2] * ni[2]) / sqrt(d2);
    cj = -(r[0] * nj[0] + r[1] * nj[1] + r[2] * nj[2]) / sqrt(d2);
    expect = sj * ci * cj / (FF_PI * d2);
    /* float arithmetic in the library: 1e-5 relative is ~100 ulps */
    CHECK_REL(rad_ff_point_point(pi_, ni, pj, nj, sj), expect, 1e-5);
    /* symmetric form: swapping the roles with s_i = s_j gives the same kernel */
    CHECK_REL(rad_ff_point_point(pj, nj, pi_, ni, sj), expect, 1e-5);

    /* the clamp: facing points at tiny distances never exceed 1 (|r|^2 >= s_j / pi) */
    {
        const float a[3] = { 0, 0, 0 }, up[3] = { 0, 0, 1 }, down[3] = { 0, 0, -1 };
        const float dists[5] = { 1e-2f, 1e-4f, 1e-8f, 1e-15f, 1e-19f };
        for (k = 0; k < 5; ++k) {
            float b[3] = { 0, 0, 0 }, v;
            b[2] = dists[k];
            v = rad_ff_point_point(a, up, b, down, 0.01f);
            /* 1 up to float rounding of s_j / (pi * (s_j / pi)) */
            CHECK(v <= 1.0f + 4.0f * FLT_EPSILON);
            CHECK(v >= 0.0f);
            if (k >= 1) CHECK_NEAR(v, 1.0, 1e-5); /* saturated: cos = 1 both sides, r^2 clamped */
        }
        /* above the clamp distance the unclamped formula applies: d = 1, s = 0.01 */
        {
            float b[3] = { 0, 0, 1 };
            CHECK_REL(rad_ff_point_point(a, up, b, down, 0.01f), 0.01 / FF_PI, 1e-6);
        }
    }
    /* zero when either cosine <= 0 */
    {
        const float a[3] = { 0, 0, 0 }, b[3] = { 0, 0, 1 }, side[3] = { 1, 0, 0 };
        const float up[3] = { 0, 0, 1 }, down[3] = { 0, 0, -1 }, px[3] = { 1, 0, 0 };
        CHECK(rad_ff_point_point(a, up, b, up, 0.1f) == 0.0f);     /* receiver faces away */
        CHECK(rad_ff_point_point(a, down, b, down, 0.1f) == 0.0f); /* sender faces away */
        CHECK(rad_ff_point_point(a, down, b, up, 0.1f) == 0.0f);   /* back to back */
        CHECK(rad_ff_point_point(a, up, side, px, 0.1f) == 0.0f);  /* grazing: cos_i == 0 */
        CHECK(rad_ff_point_point(a, px, b, down, 0.1f) == 0.0f);   /* cos_i == 0 */
        CHECK(rad_ff_point_point(a, up, b, down, 0.1f) > 0.0f);    /* control: facing */
    }
}

/* ---------------------------------------------------------------------------------------- */
/* 3. closed forms through patches                                                          */
/* ---------------------------------------------------------------------------------------- */

/* Two-quad scene, dense form factors; returns F_12 and F_21 through ff_group. */
static int ff_two_quads(const ff_quad *q1, const ff_quad *q2, float max_edge, const rad_form_factor_options *fo,
                        double *f12, double *f21, double *a1, double *a2)
{
    rad_mesh_desc meshes[2];
    rad_scene_desc d;
    ff_world w;
    rad_form_factors *ff = NULL;
    rad_result r;
    rad_form_factor_options def;
    ff_mesh_quad(&meshes[0], q1);
    ff_mesh_quad(&meshes[1], q2);
    ff_desc(&d, meshes, 2);
    if (!ff_world_make(&d, max_edge, 0, &w)) return 0;
    if (!fo) { rad_form_factor_options_default(&def); fo = &def; }
    r = rad_form_factors_dense(w.patches, &w.rc, fo, NULL, &ff);
    CHECK_OK(r);
    if (r != RAD_SUCCESS) { ff_world_free(&w); return 0; }
    *f12 = ff_group(w.patches, ff->matrix.dense, 0, 1, a1);
    *f21 = ff_group(w.patches, ff->matrix.dense, 1, 0, a2);
    rad_form_factors_destroy(ff);
    ff_world_free(&w);
    return 1;
}

static void ff_report(const char *what, double got, double expect)
{
    printf("    %-34s F = %.9f  reference %.9f  rel.err %.2e\n", what, got, expect, fabs(got - expect) / expect);
}

static void ff_test_c11_parallel(void)
{
    static const struct { float a, b, c; double ref; const char *name; } cases[4] = {
        { 1, 1, 1, 0.19982489569838746, "C-11 1x1 gap 1" },
        { 1, 1, 2, 0.06858959, "C-11 1x1 gap 2" },
        { 1, 1, 0.5f, 0.41525328, "C-11 1x1 gap 0.5" },
        { 2, 1, 1, 0.28587538, "C-11 2x1 gap 1" },
    };
    float edge = rad_test_quick() ? 0.25f : 0.1f;
    int c;
    for (c = 0; c < 4; ++c) {
        ff_quad q1, q2;
        double f12 = 0, f21 = 0, a1 = 0, a2 = 0;
        float a = cases[c].a, b = cases[c].b, g = cases[c].c;
        /* bottom faces +z, top faces -z: each front faces the other */
        ff_quad_set(&q1, 0, 0, 0, a, 0, 0, 0, b, 0);
        ff_quad_set(&q2, 0, 0, g, 0, b, 0, a, 0, 0);
        /* our own C-11 formula reproduces the table (guards the table and the formula) */
        CHECK_REL(ff_c11(a, b, g), cases[c].ref, 1e-7);
        if (!ff_two_quads(&q1, &q2, edge, NULL, &f12, &f21, &a1, &a2)) continue;
        ff_report(cases[c].name, f12, cases[c].ref);
        /* the accuracy target at default quality (16 analytic samples per patch) */
        CHECK_REL(f12, cases[c].ref, 1e-3);
        CHECK_REL(f21, cases[c].ref, 1e-3); /* identical rectangles: F_21 = F_12 */
        /* reciprocity holds by construction (one pair computed, the other mirrored); 1e-6
           covers float rounding of the mirrored entries and of the areas */
        CHECK_REL(a1 * f12, a2 * f21, 1e-6);
        CHECK_REL(a1, (double)a * b, 1e-6);
    }
}

static void ff_test_c14_perpendicular(void)
{
    static const struct { float l, w, h; double ref; const char *name; } cases[3] = {
        { 1, 1, 1, 0.20004377607540316, "C-14 unit squares" },
        { 1, 1, 2, 0.23285260, "C-14 l=1 w=1 h=2" },
        { 1, 2, 1, 0.11642630, "C-14 l=1 w=2 h=1" },
    };
    float edge = rad_test_quick() ? 0.25f : 0.1f;
    int c;
    for (c = 0; c < 3; ++c) {
        ff_quad q1, q2;
        double f12 = 0, f21 = 0, a1 = 0, a2 = 0;
        float l = cases[c].l, w = cases[c].w, h = cases[c].h;
        /* A1 = l x w in z = 0 facing +z; A2 = l x h in y = 0 facing +y; common edge on x */
        ff_quad_set(&q1, 0, 0, 0, l, 0, 0, 0, w, 0);
        ff_quad_set(&q2, 0, 0, 0, 0, 0, h, l, 0, 0);
        CHECK_REL(ff_c14(l, w, h), cases[c].ref, 1e-7);
        if (!ff_two_quads(&q1, &q2, edge, NULL, &f12, &f21, &a1, &a2)) continue;
        ff_report(cases[c].name, f12, cases[c].ref);
        /* the accuracy target at default quality */
        CHECK_REL(f12, cases[c].ref, 1e-3);
        /* the other direction from the closed form by reciprocity */
        CHECK_REL(f21, cases[c].ref * (double)l * w / ((double)l * h), 1e-3);
        /* reciprocity of the group values: by construction, up to float rounding */
        CHECK_REL(a1 * f12, a2 * f21, 1e-6);
    }
}

/* A regular n-gon of circumradius r centred at (0, 0, z) as a fan of triangles around its
   centre, front facing +z (up != 0) or -z. pos: 3 (n + 1) floats, idx: 3 n. */
static void ff_fan(float *pos, uint32_t *idx, int n, double r, float z, int up)
{
    int i;
    pos[0] = 0.0f; pos[1] = 0.0f; pos[2] = z;
    for (i = 0; i < n; ++i) {
        double a = 2.0 * FF_PI * i / n;
        pos[3 * (i + 1)] = (float)(r * cos(a));
        pos[3 * (i + 1) + 1] = (float)(r * sin(a));
        pos[3 * (i + 1) + 2] = z;
    }
    for (i = 0; i < n; ++i) {
        uint32_t a = (uint32_t)i + 1, b = (uint32_t)((i + 1) % n) + 1;
        idx[3 * i] = 0;
        idx[3 * i + 1] = up ? a : b; /* counter-clockwise seen from +z when up */
        idx[3 * i + 2] = up ? b : a;
    }
}

static void ff_test_c41_disks(void)
{
    enum { NG = 64 };
    static float pos1[3 * (NG + 1)], pos2[3 * (NG + 1)];
    static uint32_t idx1[3 * NG], idx2[3 * NG];
    rad_mesh_desc meshes[2];
    rad_scene_desc d;
    rad_form_factor_options fo;
    rad_form_factors *ff = NULL;
    ff_world w;
    double reff = ff_equal_area_radius(1.0, NG), ref, f12, f21, a1, a2;
    /* r1 = r2 = 1, h = 1 as 64-gons. Reference: C-41 for the disks of equal area to the
       polygons, r_eff = sqrt(64/2 sin(2 pi/64) / pi) = 0.99839 (the circle itself gives
       0.381966; the polygons are ~0.3% smaller in area) */
    ff_fan(pos1, idx1, NG, 1.0, 0.0f, 1);
    ff_fan(pos2, idx2, NG, 1.0, 1.0f, 0);
    memset(meshes, 0, sizeof(meshes));
    meshes[0].positions = pos1;
    meshes[0].vertex_count = NG + 1;
    meshes[0].indices = idx1;
    meshes[0].triangle_count = NG;
    meshes[1] = meshes[0];
    meshes[1].positions = pos2;
    meshes[1].indices = idx2;
    ff_desc(&d, meshes, 2);
    ref = ff_c41(reff, reff, 1.0);
    CHECK_REL(ff_c41(1.0, 1.0, 1.0), 0.3819660112501051, 1e-12);
    CHECK_REL(ff_c41(1.0, 2.0, 1.0), 0.76393202, 1e-7);
    if (!ff_world_make(&d, rad_test_quick() ? 0.5f : 0.25f, 0, &w)) return;
    rad_form_factor_options_default(&fo);
    CHECK_OK(rad_form_factors_dense(w.patches, &w.rc, &fo, NULL, &ff));
    if (ff) {
        f12 = ff_group(w.patches, ff->matrix.dense, 0, 1, &a1);
        f21 = ff_group(w.patches, ff->matrix.dense, 1, 0, &a2);
        ff_report("C-41 64-gons r=1 h=1", f12, ref);
        /* the target at default quality */
        CHECK_REL(f12, ref, 1e-3);
        CHECK_REL(f21, ref, 1e-3);
        CHECK_REL(a1 * f12, a2 * f21, 1e-6); /* reciprocity, float rounding */
        CHECK_REL(a1, FF_PI * reff * reff, 1e-5);
    }
    rad_form_factors_destroy(ff);
    ff_world_free(&w);
}

/* ---------------------------------------------------------------------------------------- */
/* the test table                                                                           */
/* ---------------------------------------------------------------------------------------- */

static const rad_test_case tests_formfactor[] = {
    { "formfactor_point_polygon_square", ff_test_point_polygon_square },
    { "formfactor_point_polygon_disk", ff_test_point_polygon_disk },
    { "formfactor_point_polygon_clip", ff_test_point_polygon_clip },
    { "formfactor_point_point", ff_test_point_point },
    { "formfactor_c11_parallel", ff_test_c11_parallel },
    { "formfactor_c14_perpendicular", ff_test_c14_perpendicular },
    { "formfactor_c41_disks", ff_test_c41_disks },
    { NULL, NULL }
};

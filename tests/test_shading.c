/* test_shading.c - lighting models and BRDFs (docs/methods/shading.md): NDF normalization, the weak white
   furnace for Smith G1, reciprocity, energy, Beckmann's rational Lambda against the exact
   erf form, hand-computed values, API errors. Integrals are midpoint sums in closed-form
   changes of variables; each tolerance below is the quadrature error measured at the
   coarse (RAD_TEST_QUICK) grid with a margin, far below the errors the tests look for
   (a missing 1/pi, a wrong Lambda, a lobe normalized for the wrong exponent). */
#include "fixtures.h"


#define SH_PI 3.14159265358979323846

static float sh_ndf(int ggx, float nm, float tm, float bm, float ax, float ay)
{
    if (ax == ay) return ggx ? rad_ndf_ggx(nm, ax) : rad_ndf_beckmann(nm, ax);
    return ggx ? rad_ndf_ggx_aniso(nm, tm, bm, ax, ay) : rad_ndf_beckmann_aniso(nm, tm, bm, ax, ay);
}

/* Integral over the hemisphere of D(m) w(m) dm, n = z, t = x, b = y, written in slope space
   (D(m) (n.m) dm = P22 dx dy with P22 = D cos^4) with slopes (ax r cos phi, ay r sin phi),
   r = tan(u), u in (0, pi/2). w = 1 (n.m) when v is NULL, else (v.m)+. */
static double sh_ndf_integral(int ggx, float ax, float ay, const double *v, int nt, int np)
{
    double sum = 0.0;
    int i, j;
    for (i = 0; i < nt; ++i) {
        double u = (i + 0.5) / nt * (SH_PI / 2), r = tan(u), dr = (SH_PI / 2) / nt / (cos(u) * cos(u));
        for (j = 0; j < np; ++j) {
            double phi = (j + 0.5) / np * 2.0 * SH_PI, x = ax * r * cos(phi), y = ay * r * sin(phi);
            double c = 1.0 / sqrt(1.0 + x * x + y * y), m[3], D, w;
            m[0] = -x * c; m[1] = -y * c; m[2] = c;
            D = sh_ndf(ggx, (float)m[2], (float)m[0], (float)m[1], ax, ay);
            w = 1.0;
            if (v) {
                double vm = v[0] * m[0] + v[1] * m[1] + v[2] * m[2];
                w = vm > 0.0 ? vm / c : 0.0;
            }
            sum += D * c * c * c * c * w * (double)ax * ay * r * dr * (2.0 * SH_PI / np);
        }
    }
    return sum;
}

static void sh_test_ndf_normalization(void)
{
    static const float alphas[][2] = { {0.05f, 0.05f}, {0.2f, 0.2f}, {0.5f, 0.5f}, {1.0f, 1.0f}, {0.1f, 0.6f}, {0.8f, 0.25f} };
    int quick = rad_test_quick(), nt = quick ? 64 : 256, np = quick ? 16 : 64, g, a;
    for (g = 0; g < 2; ++g)
        for (a = 0; a < 6; ++a) {
            double I = sh_ndf_integral(g, alphas[a][0], alphas[a][1], NULL, nt, a < 4 ? 1 : np);
            CHECK_NEAR(I, 1.0, quick ? 5e-4 : 1e-4);
        }
    /* a wrong normalization constant (no 1/pi) would fail: the integral sees it */
    CHECK_NEAR(sh_ndf_integral(1, 0.3f, 0.3f, NULL, nt, 1) * SH_PI, SH_PI, 1e-3);
}

/* weak white furnace: Integral G1(v,m) D(m) (v.m)+ dm = n.v, with G1 = 1/(1 + Lambda(v)) */
static void sh_test_g1_furnace(void)
{
    static const float alphas[][2] = { {0.1f, 0.1f}, {0.4f, 0.4f}, {1.0f, 1.0f}, {0.15f, 0.7f} };
    static const double thetas[] = { 0.0, 0.5, 1.0, 1.4 };
    int quick = rad_test_quick(), nt = quick ? 96 : 256, np = quick ? 48 : 128, g, a, k, exact;
    for (g = 0; g < 2; ++g)
        for (a = 0; a < 4; ++a)
            for (k = 0; k < 4; ++k)
                for (exact = 0; exact < (g ? 1 : 2); ++exact) {
                    float ax = alphas[a][0], ay = alphas[a][1], A, lambda;
                    double v[3], I, phi = 0.7;
                    v[0] = sin(thetas[k]) * cos(phi); v[1] = sin(thetas[k]) * sin(phi); v[2] = cos(thetas[k]);
                    A = rad_smith_a((float)v[2], (float)v[0], (float)v[1], ax, ay);
                    lambda = g ? rad_lambda_ggx(A) : (exact ? rad_lambda_beckmann_exact(A) : rad_lambda_beckmann(A));
                    I = sh_ndf_integral(g, ax, ay, v, nt, np) * rad_smith_g1(1.0f, lambda);
                    /* quadrature: measured <= 7e-6 (4.5e-5 quick); the rational Beckmann Lambda
                       adds its own error, G1 within 0.35 % (see below): measured 1.7e-3 */
                    CHECK_NEAR(I, v[2], (!g && !exact ? 0.0035 * v[2] : 0.0) + 2e-4);
                }
}

/* Beckmann: the rational approximation of Lambda against the exact erf form. The bound is
   the 0.35 % relative error on G1 = 1/(1 + Lambda) quoted for Walter et al. 2007's rational
   G1 (docs/references.md; quoted from memory, not checked against the paper); measured here:
   0.313 % at a = 1.336, on a grid of a in (0, 6]. (Lambda itself differs by up to 0.76 as
   a -> 0, where both forms go to infinity: G1 is the fair measure.) */
static void sh_test_beckmann_lambda(void)
{
    double worst = 0.0;
    int i, n = rad_test_quick() ? 2000 : 20000;
    for (i = 1; i <= n; ++i) {
        float a = 6.0f * (float)i / (float)n;
        double ge = 1.0 / (1.0 + rad_lambda_beckmann_exact(a)), ga = 1.0 / (1.0 + rad_lambda_beckmann(a));
        double rel = fabs(ga - ge) / ge;
        if (rel > worst) worst = rel;
    }
    CHECK(worst < 0.0035);
    CHECK(worst > 0.002); /* the approximation really is an approximation: the check compares two forms */
    /* exact form spot values: Lambda(1) = (erf(1) - 1)/2 + e^-1 / (2 sqrt(pi)) */
    CHECK_REL(rad_lambda_beckmann_exact(1.0f), 0.5 * (0.8427007929497149 - 1.0) + exp(-1.0) / (2.0 * sqrt(SH_PI)), 1e-6);
    CHECK_NEAR(rad_lambda_beckmann(1.6f), 0.0, 0.0);
    CHECK_NEAR(rad_lambda_beckmann_exact(HUGE_VALF), 0.0, 0.0);
    /* GGX Lambda at a = 1: (sqrt(2) - 1) / 2 */
    CHECK_REL(rad_lambda_ggx(1.0f), (sqrt(2.0) - 1.0) / 2.0, 1e-6);
    CHECK_NEAR(rad_lambda_ggx(HUGE_VALF), 0.0, 0.0);
}

static void sh_dir(double theta, double phi, float *out)
{
    out[0] = (float)(sin(theta) * cos(phi));
    out[1] = (float)(sin(theta) * sin(phi));
    out[2] = (float)cos(theta);
}

static const float sh_n[3] = { 0.0f, 0.0f, 1.0f }, sh_t[3] = { 1.0f, 0.0f, 0.0f }, sh_b[3] = { 0.0f, 1.0f, 0.0f };

/* the materials the reciprocity and energy tests go through (albedos at 1: the worst case) */
static int sh_material(int index, rad_shading *s)
{
    int k;
    switch (index) {
    case 0: rad_shading_default(s, RAD_SHADING_LAMBERT); for (k = 0; k < 3; ++k) s->lambert.albedo[k] = 1.0f; return 1;
    case 1: case 2:
        rad_shading_default(s, index == 1 ? RAD_SHADING_PHONG : RAD_SHADING_BLINN_PHONG);
        for (k = 0; k < 3; ++k) { s->phong.diffuse[k] = 0.4f; s->phong.specular[k] = 0.6f; }
        s->phong.shininess = 20.0f;
        return 1;
    case 3: rad_shading_default(s, RAD_SHADING_MINNAERT); s->minnaert.k = 1.5f; for (k = 0; k < 3; ++k) s->minnaert.albedo[k] = 1.0f; return 1;
    case 4: rad_shading_default(s, RAD_SHADING_OREN_NAYAR); s->oren_nayar.sigma = 1.0f; for (k = 0; k < 3; ++k) s->oren_nayar.albedo[k] = 1.0f; return 1;
    case 5: case 6: case 7: case 8: case 9: case 10:
        rad_shading_default(s, RAD_SHADING_MICROFACET);
        s->microfacet.ndf = (index & 1) ? RAD_NDF_GGX : RAD_NDF_BECKMANN;
        s->microfacet.masking = index < 8 ? RAD_MASKING_HEIGHT_CORRELATED : RAD_MASKING_SEPARABLE;
        s->microfacet.diffuse = index < 9 ? RAD_DIFFUSE_SHIRLEY : RAD_DIFFUSE_NONE;
        s->microfacet.alpha_x = index < 7 ? 0.3f : 0.6f;
        s->microfacet.alpha_y = index < 9 ? 0.3f : 0.2f;
        for (k = 0; k < 3; ++k) { s->microfacet.f0[k] = index < 9 ? 0.04f : 1.0f; s->microfacet.albedo[k] = 1.0f; }
        return 1;
    default: return 0;
    }
}

static void sh_test_reciprocity(void)
{
    rad_shading s;
    int m, i;
    uint32_t seed = 12345u;
    for (m = 0; sh_material(m, &s); ++m)
        for (i = 0; i < 200; ++i) {
            float l[3], v[3], a[3], b[3];
            double u[4];
            int k;
            for (k = 0; k < 4; ++k) { seed = seed * 1664525u + 1013904223u; u[k] = (seed >> 8) / 16777216.0; }
            sh_dir(acos(0.02 + 0.98 * u[0]), 2.0 * SH_PI * u[1], l);
            sh_dir(acos(0.02 + 0.98 * u[2]), 2.0 * SH_PI * u[3], v);
            CHECK_OK(rad_shading_brdf(&s, l, v, sh_n, sh_t, sh_b, a, NULL));
            CHECK_OK(rad_shading_brdf(&s, v, l, sh_n, sh_t, sh_b, b, NULL));
            for (k = 0; k < 3; ++k) CHECK_NEAR(a[k], b[k], 2e-5 * (fabs(b[k]) + 1.0));
        }
    /* the Lambert diffuse term (1 - F(n,l)) rho / pi is not reciprocal: the test can tell */
    rad_shading_default(&s, RAD_SHADING_MICROFACET);
    {
        float l[3], v[3], a[3], b[3];
        sh_dir(0.2, 0.0, l); sh_dir(1.3, 2.0, v);
        CHECK_OK(rad_shading_brdf(&s, l, v, sh_n, NULL, NULL, a, NULL));
        CHECK_OK(rad_shading_brdf(&s, v, l, sh_n, NULL, NULL, b, NULL));
        CHECK(fabs(a[0] - b[0]) > 1e-3 * b[0]);
    }
}

/* directional albedo Integral f(l, v) (n.l) dl on a cosine-weighted midpoint grid */
static double sh_albedo(const rad_shading *s, const float *v, int n)
{
    double sum = 0.0;
    int i, j;
    for (i = 0; i < n; ++i)
        for (j = 0; j < n; ++j) {
            double u = (i + 0.5) / n, w = (j + 0.5) / n, st = sqrt(u);
            float l[3], f[3];
            l[0] = (float)(st * cos(2.0 * SH_PI * w)); l[1] = (float)(st * sin(2.0 * SH_PI * w)); l[2] = (float)sqrt(1.0 - u);
            if (rad_shading_brdf(s, l, v, sh_n, sh_t, sh_b, f, NULL) != RAD_SUCCESS) return -1.0;
            sum += f[0];
        }
    return sum * SH_PI / ((double)n * n);
}

static void sh_test_energy(void)
{
    static const double thetas[] = { 0.0, 0.7, 1.2, 1.5 };
    rad_shading s;
    int m, k, n = rad_test_quick() ? 64 : 256;
    float v[3];
    for (m = 0; sh_material(m, &s); ++m)
        for (k = 0; k < 4; ++k) {
            double a;
            sh_dir(thetas[k], 0.3, v);
            a = sh_albedo(&s, v, n);
            CHECK(a > 0.0);
            /* quadrature error about 1e-4; the Shirley diffuse term paired with GGX exceeds 1
               by 0.15 % at albedo 1 and grazing view (measured 1.0015 on a 400^2 grid) */
            if (!(a <= 1.0 + 2.5e-3)) printf("    material %d theta %.2f: albedo %.5f\n", m, thetas[k], a);
            CHECK(a <= 1.0 + 2.5e-3);
        }
    /* Oren-Nayar's qualitative model slightly exceeds 1 at grazing view for small sigma
       (measured 1.0105 at sigma 0.25, theta_v 1.55, albedo 1): bounded, as documented */
    rad_shading_default(&s, RAD_SHADING_OREN_NAYAR);
    s.oren_nayar.sigma = 0.25f;
    for (k = 0; k < 3; ++k) s.oren_nayar.albedo[k] = 1.0f;
    sh_dir(1.55, 0.3, v);
    {
        double a = sh_albedo(&s, v, n);
        CHECK(a > 1.0 && a < 1.015);
    }
    /* the test can tell: the default Lambert diffuse term (1 - F(n,l)) rho / pi (Korobeinikov 2022) is
       not energy-conserving with the specular term at albedo 1 (measured 1.072) */
    rad_shading_default(&s, RAD_SHADING_MICROFACET);
    for (k = 0; k < 3; ++k) s.microfacet.albedo[k] = 1.0f;
    {
        double worst = 0.0, a;
        for (k = 0; k < 4; ++k) {
            sh_dir(thetas[k], 0.3, v);
            a = sh_albedo(&s, v, n);
            if (a > worst) worst = a;
        }
        CHECK(worst > 1.03);
    }
    /* closed forms: Lambert's albedo is rho; normalized Phong's at v = n is kd + ks */
    rad_shading_default(&s, RAD_SHADING_LAMBERT);
    sh_dir(0.9, 0.0, v);
    CHECK_NEAR(sh_albedo(&s, v, n), 0.5, 1e-3);
    rad_shading_default(&s, RAD_SHADING_PHONG);
    sh_dir(0.0, 0.0, v);
    CHECK_NEAR(sh_albedo(&s, v, n), 0.8, 0.01);
    rad_shading_default(&s, RAD_SHADING_BLINN_PHONG);
    CHECK_NEAR(sh_albedo(&s, v, n), 0.8, 0.01);
    /* the specular term alone at F = 1 loses energy to single scattering, more when rough.
       Closed form for GGX, alpha = 1, v = n (D = 1/pi, Lambda(l) = (1/cos - 1)/2, height-
       correlated G2 = 2 cos / (1 + cos)): albedo = 1 - ln 2 */
    rad_shading_default(&s, RAD_SHADING_MICROFACET);
    s.microfacet.diffuse = RAD_DIFFUSE_NONE;
    for (k = 0; k < 3; ++k) s.microfacet.f0[k] = 1.0f;
    s.microfacet.alpha_x = s.microfacet.alpha_y = 1.0f;
    sh_dir(0.0, 0.0, v);
    CHECK_NEAR(sh_albedo(&s, v, n), 1.0 - log(2.0), 2e-3);
    sh_dir(0.5, 0.0, v);
    {
        double rough = sh_albedo(&s, v, n), smooth;
        s.microfacet.alpha_x = s.microfacet.alpha_y = 0.2f;
        smooth = sh_albedo(&s, v, n);
        CHECK(smooth > 0.9 && smooth <= 1.0 + 5e-3);
        CHECK(rough < 0.5 * smooth);
    }
}

/* values computed by hand */
static void sh_test_values(void)
{
    rad_shading s;
    float f[3], l[3], v[3];
    const float z[3] = { 0.0f, 0.0f, 1.0f };
    CHECK_REL(rad_ndf_ggx(1.0f, 0.5f), 1.0 / (SH_PI * 0.25), 1e-6);
    CHECK_REL(rad_ndf_beckmann(1.0f, 0.5f), 1.0 / (SH_PI * 0.25), 1e-6);
    /* Beckmann at n.m = cos 30 deg, alpha 0.5: exp(-tan^2 / a^2) / (pi a^2 cos^4) */
    CHECK_REL(rad_ndf_beckmann(0.8660254f, 0.5f), exp(-(1.0 / 3.0) / 0.25) / (SH_PI * 0.25 * 0.5625), 1e-5);
    CHECK_REL(rad_ndf_ggx_aniso(1.0f, 0.0f, 0.0f, 0.2f, 0.8f), 1.0 / (SH_PI * 0.16), 1e-6);
    CHECK_NEAR(rad_ndf_ggx(-0.1f, 0.5f), 0.0, 0.0);
    CHECK_REL(rad_fresnel_schlick(0.04f, 0.5f), 0.04 + 0.96 / 32.0, 1e-6);
    CHECK_REL(rad_fresnel_schlick_f90(0.04f, 0.5f, 5.0f, 0.5f), 0.04 + 0.46 / 32.0, 1e-5);
    CHECK_REL(rad_smith_g2_height_correlated(0.5f, 0.5f, 0.25f, 0.5f), 1.0 / 1.75, 1e-6);
    CHECK_REL(rad_smith_g2_separable(0.5f, 0.5f, 0.25f, 0.5f), 1.0 / (1.25 * 1.5), 1e-6);
    CHECK_NEAR(rad_smith_g2_separable(-0.5f, 0.5f, 0.25f, 0.5f), 0.0, 0.0);
    /* microfacet at l = v = n: D = 1/(pi a^2), Lambda = 0, F = F0; Lambert diffuse (1-F0) rho/pi */
    rad_shading_default(&s, RAD_SHADING_MICROFACET);
    CHECK_OK(rad_shading_brdf(&s, z, z, z, NULL, NULL, f, NULL));
    CHECK_REL(f[1], 0.04 / (4.0 * SH_PI * 0.09) + 0.96 * 0.5 / SH_PI, 1e-5);
    /* Shirley at normal incidence: (1 - F0) 21 rho / (20 pi) */
    s.microfacet.diffuse = RAD_DIFFUSE_SHIRLEY;
    CHECK_OK(rad_shading_brdf(&s, z, z, z, NULL, NULL, f, NULL));
    CHECK_REL(f[1], 0.04 / (4.0 * SH_PI * 0.09) + 0.96 * 21.0 * 0.5 / (20.0 * SH_PI), 1e-5);
    /* Oren-Nayar at l = v = n: A rho / pi, A = 1 - 0.5 s^2 / (s^2 + 0.33) */
    rad_shading_default(&s, RAD_SHADING_OREN_NAYAR);
    CHECK_OK(rad_shading_brdf(&s, z, z, z, NULL, NULL, f, NULL));
    CHECK_REL(f[0], (1.0 - 0.5 * 0.25 / 0.58) * 0.5 / SH_PI, 1e-5);
    /* Oren-Nayar, l at 60 deg, v at 30 deg in the same plane: cos(dphi) = 1,
       sin(60) tan(30) = 0.5; B = 0.45 * 0.25 / 0.34 */
    sh_dir(SH_PI / 3, 0.0, l); sh_dir(SH_PI / 6, 0.0, v);
    CHECK_OK(rad_shading_brdf(&s, l, v, z, NULL, NULL, f, NULL));
    CHECK_REL(f[0], (1.0 - 0.5 * 0.25 / 0.58 + 0.45 * 0.25 / 0.34 * 0.5) * 0.5 / SH_PI, 1e-5);
    /* half-Lambert at n.l = 0 (w = 1, p = 2): R = rho/pi / 4; behind (n.l = -1): 0 */
    rad_shading_default(&s, RAD_SHADING_HALF_LAMBERT);
    sh_dir(SH_PI / 2, 0.0, l);
    CHECK_OK(rad_shading_eval(&s, l, z, z, NULL, NULL, f, NULL));
    CHECK_REL(f[2], 0.25 * 0.5 / SH_PI, 1e-5);
    /* banded, 4 bands, n.l = 0.3: ceil(1.2) / 4 = 0.5 */
    rad_shading_default(&s, RAD_SHADING_BANDED);
    l[0] = (float)sqrt(1.0 - 0.09); l[1] = 0.0f; l[2] = 0.3f;
    CHECK_OK(rad_shading_eval(&s, l, z, z, NULL, NULL, f, NULL));
    CHECK_REL(f[0], 0.5 * 0.5 / SH_PI, 1e-5);
    /* Blinn-Phong, l = v = n: kd/pi + ks (s + 8) / (8 pi) */
    rad_shading_default(&s, RAD_SHADING_BLINN_PHONG);
    CHECK_OK(rad_shading_brdf(&s, z, z, z, NULL, NULL, f, NULL));
    CHECK_REL(f[0], 0.5 / SH_PI + 0.3 * 34.0 * 36.0 / (8.0 * SH_PI * (1.0 / 65536.0 + 32.0)), 1e-5);
    /* Minnaert k = 0.8, n.l = n.v = 0.5: rho 1.8 / (2 pi) 0.25^-0.2 */
    rad_shading_default(&s, RAD_SHADING_MINNAERT);
    sh_dir(SH_PI / 3, 0.0, l); sh_dir(SH_PI / 3, 1.0, v);
    CHECK_OK(rad_shading_brdf(&s, l, v, z, NULL, NULL, f, NULL));
    CHECK_REL(f[0], 0.5 * 1.8 / (2.0 * SH_PI) * pow(0.25, -0.2), 1e-5);
    /* eval = brdf * n.l, and the vectors are normalized: scaled inputs give the same */
    {
        float l2[3] = { 0.0f, 3.0f, 3.0f }, v2[3] = { 1.0f, 0.0f, 5.0f }, n2[3] = { 0.0f, 0.0f, 7.0f }, fe[3], fb[3];
        rad_shading_default(&s, RAD_SHADING_MICROFACET);
        CHECK_OK(rad_shading_eval(&s, l2, v2, n2, NULL, NULL, fe, NULL));
        CHECK_OK(rad_shading_brdf(&s, l2, v2, n2, NULL, NULL, fb, NULL));
        CHECK_REL(fe[0], fb[0] * sqrt(0.5), 1e-6);
        /* seen from behind: 0 */
        v2[2] = -5.0f;
        CHECK_OK(rad_shading_eval(&s, l2, v2, n2, NULL, NULL, fe, NULL));
        CHECK_NEAR(fe[0], 0.0, 0.0);
    }
    /* anisotropic with alpha_x = alpha_y equals isotropic */
    {
        float a[3], b[3], t2[3] = { 0.3f, 0.9f, 0.1f };
        rad_shading_default(&s, RAD_SHADING_MICROFACET);
        sh_dir(0.6, 0.4, l); sh_dir(0.9, 2.5, v);
        CHECK_OK(rad_shading_brdf(&s, l, v, z, NULL, NULL, a, NULL));
        s.microfacet.alpha_y = 0.30001f;
        CHECK_OK(rad_shading_brdf(&s, l, v, z, t2, NULL, b, NULL));
        CHECK_REL(b[0], a[0], 1e-3);
    }
}

/* rad_shade on a packed material is what both entries evaluate */
static void sh_test_packed(void)
{
    rad_shading s;
    rad_shading_gpu g;
    float l[3], v[3], f1[3], r1[3], f2[3], r2[3];
    int m, k;
    sh_dir(0.7, 0.2, l);
    sh_dir(0.4, 2.9, v);
    for (m = 0; m < (int)RAD_SHADING_MODEL_COUNT; ++m) {
        rad_shading_default(&s, (rad_shading_model)m);
        if (m == RAD_SHADING_MICROFACET) s.microfacet.alpha_y = 0.1f;
        CHECK_OK(rad_shading_pack(&s, &g, NULL));
        rad_shade(&g, l, v, sh_n, sh_t, sh_b, f1, r1);
        if (m != RAD_SHADING_HALF_LAMBERT) CHECK_OK(rad_shading_brdf(&s, l, v, sh_n, sh_t, sh_b, f2, NULL));
        CHECK_OK(rad_shading_eval(&s, l, v, sh_n, sh_t, sh_b, r2, NULL));
        for (k = 0; k < 3; ++k) {
            if (m != RAD_SHADING_HALF_LAMBERT) CHECK_NEAR(f1[k], f2[k], 1e-6 * fabs(f2[k]));
            CHECK_NEAR(r1[k], r2[k], 1e-6 * fabs(r2[k]));
            CHECK(r1[k] > 0.0f);
        }
    }
}

static void sh_test_errors(void)
{
    rad_shading s;
    rad_shading_model m = RAD_SHADING_LAMBERT;
    rad_shading_gpu g;
    float f[3], l[3] = { 0.0f, 0.0f, 1.0f }, zero[3] = { 0.0f, 0.0f, 0.0f }, bad[3] = { 0.0f, 0.0f, 0.0f };
    int i;
    bad[1] = (float)NAN;
    rad_shading_default(&s, RAD_SHADING_LAMBERT);
    CHECK_RESULT(rad_shading_eval(NULL, l, l, l, NULL, NULL, f, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_shading_eval(&s, NULL, l, l, NULL, NULL, f, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_shading_eval(&s, l, l, l, NULL, NULL, NULL, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_shading_eval(&s, zero, l, l, NULL, NULL, f, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_shading_eval(&s, l, bad, l, NULL, NULL, f, NULL), RAD_ERROR_NON_FINITE);
    s.model = (rad_shading_model)99;
    CHECK_RESULT(rad_shading_eval(&s, l, l, l, NULL, NULL, f, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_shading_validate(&s, NULL), RAD_ERROR_INVALID_ARGUMENT);
    rad_shading_default(&s, RAD_SHADING_LAMBERT);
    s.lambert.albedo[1] = 1.5f;
    CHECK_RESULT(rad_shading_eval(&s, l, l, l, NULL, NULL, f, NULL), RAD_ERROR_INVALID_ARGUMENT);
    s.lambert.albedo[1] = (float)NAN;
    CHECK_RESULT(rad_shading_eval(&s, l, l, l, NULL, NULL, f, NULL), RAD_ERROR_NON_FINITE);
    rad_shading_default(&s, RAD_SHADING_BANDED);
    s.banded.bands = 0;
    CHECK_RESULT(rad_shading_validate(&s, NULL), RAD_ERROR_INVALID_ARGUMENT);
    rad_shading_default(&s, RAD_SHADING_HALF_LAMBERT);
    CHECK_RESULT(rad_shading_brdf(&s, l, l, l, NULL, NULL, f, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_OK(rad_shading_eval(&s, l, l, l, NULL, NULL, f, NULL));
    rad_shading_default(&s, RAD_SHADING_MICROFACET);
    s.microfacet.alpha_x = 0.0f;
    CHECK_RESULT(rad_shading_validate(&s, NULL), RAD_ERROR_INVALID_ARGUMENT);
    s.microfacet.alpha_x = 0.1f;
    CHECK_RESULT(rad_shading_eval(&s, l, l, l, NULL, NULL, f, NULL), RAD_ERROR_INVALID_ARGUMENT); /* no t */
    CHECK_RESULT(rad_shading_eval(&s, l, l, l, l, NULL, f, NULL), RAD_ERROR_INVALID_ARGUMENT);    /* t parallel to n */
    CHECK_RESULT(rad_shading_eval(&s, l, l, l, bad, NULL, f, NULL), RAD_ERROR_NON_FINITE);
    s.microfacet.ndf = (rad_ndf)7;
    CHECK_RESULT(rad_shading_validate(&s, NULL), RAD_ERROR_INVALID_ARGUMENT);
    CHECK_RESULT(rad_shading_pack(&s, &g, NULL), RAD_ERROR_INVALID_ARGUMENT);
    rad_shading_default(&s, RAD_SHADING_PHONG);
    s.phong.shininess = 0.5f;
    CHECK_RESULT(rad_shading_validate(&s, NULL), RAD_ERROR_INVALID_ARGUMENT);
    /* names */
    for (i = 0; i < (int)RAD_SHADING_MODEL_COUNT; ++i) {
        CHECK_OK(rad_shading_model_from_name(rad_shading_model_name((rad_shading_model)i), &m));
        CHECK(m == (rad_shading_model)i);
    }
    CHECK(rad_shading_model_name(RAD_SHADING_MODEL_COUNT) == NULL);
    CHECK_RESULT(rad_shading_model_from_name("gouraud", &m), RAD_ERROR_INVALID_ARGUMENT);
    /* every default validates */
    for (i = 0; i < (int)RAD_SHADING_MODEL_COUNT; ++i) {
        rad_shading_default(&s, (rad_shading_model)i);
        CHECK_OK(rad_shading_validate(&s, NULL));
        CHECK_OK(rad_shading_pack(&s, &g, NULL));
        CHECK(g.mode[0] == i);
    }
}

static const rad_test_case tests_shading[] = {
    { "shading_ndf_normalization", sh_test_ndf_normalization },
    { "shading_g1_weak_white_furnace", sh_test_g1_furnace },
    { "shading_beckmann_lambda_approximation", sh_test_beckmann_lambda },
    { "shading_reciprocity", sh_test_reciprocity },
    { "shading_energy", sh_test_energy },
    { "shading_values", sh_test_values },
    { "shading_packed", sh_test_packed },
    { "shading_errors", sh_test_errors },
    { NULL, NULL }
};

RAD_TEST_MAIN(tests_shading)

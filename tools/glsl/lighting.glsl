// lighting.glsl - the lighting models and BRDF terms of radiosity.h (docs/methods/shading.md, >>shading),
// GLSL 450. An include: no #version; it defines only functions and one struct, all named
// as their C counterparts (rad_ndf_ggx ...). The arithmetic is written in the same order as
// the C code so the results agree to float rounding (tests/test_shading_vulkan.c checks
// 1e-5 relative). Conventions (l, v, n unit; f the BRDF; R = f * max(n.l, 0) the response)
// are those of the >>api_shading comment in radiosity.h.
//
// Including it: either with GL_GOOGLE_include_directive (as tools/glsl/lighting_eval.comp does:
// glslangValidator resolves it relative to the including file), or by pasting this file's
// text after your #version line.
#ifndef RAD_LIGHTING_GLSL
#define RAD_LIGHTING_GLSL

#define RAD_SHADING_LAMBERT 0
#define RAD_SHADING_HALF_LAMBERT 1
#define RAD_SHADING_BANDED 2
#define RAD_SHADING_PHONG 3
#define RAD_SHADING_BLINN_PHONG 4
#define RAD_SHADING_MINNAERT 5
#define RAD_SHADING_OREN_NAYAR 6
#define RAD_SHADING_MICROFACET 7
#define RAD_NDF_BECKMANN 0
#define RAD_NDF_GGX 1
#define RAD_MASKING_SEPARABLE 0
#define RAD_MASKING_HEIGHT_CORRELATED 1
#define RAD_DIFFUSE_NONE 0
#define RAD_DIFFUSE_LAMBERT 1
#define RAD_DIFFUSE_SHIRLEY 2

const float RAD_PI = 3.14159265358979323846;
const float RAD_INV_PI = 0.318309886183790671537767526745;

// The std430 mirror of rad_shading_gpu (96 bytes), filled by rad_shading_pack():
// albedo (or kd), specular (ks), f0, f90, p = (alpha_x, alpha_y, wrap / shininess / k / sigma,
// half-Lambert exponent / bands / Fresnel exponent), mode = (model, ndf, masking, diffuse).
struct RadShadingParams {
    vec4 albedo;
    vec4 specular;
    vec4 f0;
    vec4 f90;
    vec4 p;
    ivec4 mode;
};

// Beckmann NDF
float rad_ndf_beckmann(float nm, float alpha)
{
    float a2 = alpha * alpha, c2 = nm * nm;
    if (!(nm > 0.0)) return 0.0;
    return exp((c2 - 1.0) / (a2 * c2)) / (RAD_PI * a2 * c2 * c2);
}

// Beckmann NDF, anisotropic
float rad_ndf_beckmann_aniso(float nm, float tm, float bm, float alpha_x, float alpha_y)
{
    float c2 = nm * nm;
    if (!(nm > 0.0)) return 0.0;
    float e = (tm * tm / (alpha_x * alpha_x) + bm * bm / (alpha_y * alpha_y)) / c2;
    return exp(-e) / (RAD_PI * alpha_x * alpha_y * c2 * c2);
}

// GGX NDF (Walter et al. 2007)
float rad_ndf_ggx(float nm, float alpha)
{
    float a2 = alpha * alpha;
    if (!(nm > 0.0)) return 0.0;
    float d = 1.0 + nm * nm * (a2 - 1.0);
    return a2 / (RAD_PI * d * d);
}

// GGX NDF, anisotropic
float rad_ndf_ggx_aniso(float nm, float tm, float bm, float alpha_x, float alpha_y)
{
    if (!(nm > 0.0)) return 0.0;
    float d = tm * tm / (alpha_x * alpha_x) + bm * bm / (alpha_y * alpha_y) + nm * nm;
    return 1.0 / (RAD_PI * alpha_x * alpha_y * d * d);
}

// the Smith variable a (anisotropic; the isotropic form when alpha_x = alpha_y); the largest float for
// s = n (C returns +inf there; both give Lambda = 0)
float rad_smith_a(float ns, float ts, float bs, float alpha_x, float alpha_y)
{
    float d2 = alpha_x * alpha_x * ts * ts + alpha_y * alpha_y * bs * bs;
    if (!(d2 > 0.0)) return 3.402823466e38;
    return ns / sqrt(d2);
}

// Lambda of GGX (exact), for a > 0
// (Beckmann's exact Lambda needs erf, which GLSL lacks: it is C only.)
float rad_lambda_ggx(float a)
{
    return 0.5 * (-1.0 + sqrt(1.0 + 1.0 / (a * a)));
}

// Lambda of Beckmann, rational approximation (Walter et al. 2007)
float rad_lambda_beckmann(float a)
{
    if (!(a < 1.6)) return 0.0;
    return (1.0 - 1.259 * a + 0.396 * a * a) / (3.535 * a + 2.181 * a * a);
}

// Smith G1 (Heitz 2014)
float rad_smith_g1(float ms, float lambda_s) { return ms > 0.0 ? 1.0 / (1.0 + lambda_s) : 0.0; }

// Smith G2, separable and height-correlated (Heitz 2014)
float rad_smith_g2_separable(float mv, float ml, float lambda_v, float lambda_l)
{
    return (mv > 0.0 && ml > 0.0) ? 1.0 / ((1.0 + lambda_v) * (1.0 + lambda_l)) : 0.0;
}

float rad_smith_g2_height_correlated(float mv, float ml, float lambda_v, float lambda_l)
{
    return (mv > 0.0 && ml > 0.0) ? 1.0 / (1.0 + lambda_v + lambda_l) : 0.0;
}

// Schlick's Fresnel and its generalized F90 form (one channel)
float rad_fresnel_schlick(float f0, float c)
{
    float x = 1.0 - (c > 0.0 ? c : 0.0), x2 = x * x;
    return f0 + (1.0 - f0) * (x2 * x2 * x);
}

float rad_fresnel_schlick_f90(float f0, float f90, float exponent, float c)
{
    return f0 + (f90 - f0) * pow(1.0 - (c > 0.0 ? c : 0.0), exponent);
}

// diffuse terms: Lambert (1 - F) and Shirley et al. 1997 (one channel)
float rad_diffuse_lambert(float albedo, float F) { return (1.0 - F) * albedo * RAD_INV_PI; }

float rad_diffuse_shirley(float albedo, float f0, float nl, float nv)
{
    float a = 1.0 - (nl > 0.0 ? nl : 0.0), b = 1.0 - (nv > 0.0 ? nv : 0.0);
    float a5 = a * a * a * a * a, b5 = b * b * b * b * b;
    return (1.0 - f0) * (21.0 / 20.0) * albedo * RAD_INV_PI * (1.0 - a5) * (1.0 - b5);
}

// Lambda from n.s, t.s, b.s without forming a (no division by zero at s = n)
float rad_shading_lambda(int ndf, bool iso, float ns, float ts, float bs, float ax, float ay)
{
    float d2 = iso ? ax * ax * (1.0 - ns * ns) : ax * ax * ts * ts + ay * ay * bs * bs;
    if (!(d2 > 0.0)) return 0.0;
    if (ndf == RAD_NDF_GGX) return 0.5 * (-1.0 + sqrt(1.0 + d2 / (ns * ns)));
    return rad_lambda_beckmann(ns / sqrt(d2));
}

// f (out_f) and R (return value) for unit l, v, n and an orthonormal t, b (anything when the
// model is isotropic). f is 0 for half-Lambert, which has no BRDF.
vec3 rad_shade(RadShadingParams g, vec3 l, vec3 v, vec3 n, vec3 t, vec3 b, out vec3 out_f)
{
    float nl = dot(n, l), nv = dot(n, v);
    vec3 f = vec3(0.0), rr = vec3(0.0);
    int model = g.mode.x;
    if (nv > 0.0) {
        if (model == RAD_SHADING_HALF_LAMBERT) {
            float x = (nl + g.p.z) / (1.0 + g.p.z);
            float q = pow(x > 0.0 ? x : 0.0, g.p.w);
            rr = g.albedo.xyz * RAD_INV_PI * q;
        } else if (nl > 0.0) {
            if (model == RAD_SHADING_LAMBERT) {
                f = g.albedo.xyz * RAD_INV_PI;
            } else if (model == RAD_SHADING_BANDED) {
                float q = ceil(g.p.w * nl) / g.p.w / nl;
                f = g.albedo.xyz * RAD_INV_PI * q;
            } else if (model == RAD_SHADING_PHONG) {
                vec3 r = 2.0 * nl * n - l;
                float rv = dot(r, v), s = g.p.z;
                float q = (s + 2.0) * (0.5 * RAD_INV_PI) * pow(rv > 0.0 ? rv : 0.0, s);
                f = g.albedo.xyz * RAD_INV_PI + g.specular.xyz * q;
            } else if (model == RAD_SHADING_BLINN_PHONG) {
                vec3 h = l + v;
                float len = sqrt(dot(h, h)), nh = 0.0, s = g.p.z;
                if (len > 0.0) nh = dot(n, h) / len;
                float q = (s + 2.0) * (s + 4.0) * (0.125 * RAD_INV_PI) / (exp2(-0.5 * s) + s) * pow(nh > 0.0 ? nh : 0.0, s);
                f = g.albedo.xyz * RAD_INV_PI + g.specular.xyz * q;
            } else if (model == RAD_SHADING_MINNAERT) {
                float kk = g.p.z, c = nl * nv;
                float q = (kk + 1.0) * (0.5 * RAD_INV_PI) * pow(c > 1e-6 ? c : 1e-6, kk - 1.0);
                f = g.albedo.xyz * q;
            } else if (model == RAD_SHADING_OREN_NAYAR) {
                float s2 = g.p.z * g.p.z, A = 1.0 - 0.5 * s2 / (s2 + 0.33), B = 0.45 * s2 / (s2 + 0.09);
                float s = dot(l, v) - nl * nv, q = s > 0.0 ? s / (nl > nv ? nl : nv) : 0.0;
                f = g.albedo.xyz * RAD_INV_PI * (A + B * q);
            } else if (model == RAD_SHADING_MICROFACET) {
                float ax = g.p.x, ay = g.p.y;
                bool iso = ax == ay;
                int ndf = g.mode.y;
                vec3 h = l + v;
                float len = sqrt(dot(h, h));
                if (len > 0.0) {
                    h /= len;
                    float nh = dot(n, h), lh = dot(l, h), vh = dot(v, h), D;
                    if (iso) {
                        D = ndf == RAD_NDF_GGX ? rad_ndf_ggx(nh, ax) : rad_ndf_beckmann(nh, ax);
                    } else {
                        float th = dot(t, h), bh = dot(b, h);
                        D = ndf == RAD_NDF_GGX ? rad_ndf_ggx_aniso(nh, th, bh, ax, ay)
                                               : rad_ndf_beckmann_aniso(nh, th, bh, ax, ay);
                    }
                    float lv = rad_shading_lambda(ndf, iso, nv, iso ? 0.0 : dot(t, v), iso ? 0.0 : dot(b, v), ax, ay);
                    float ll = rad_shading_lambda(ndf, iso, nl, iso ? 0.0 : dot(t, l), iso ? 0.0 : dot(b, l), ax, ay);
                    float G = g.mode.z == RAD_MASKING_SEPARABLE ? rad_smith_g2_separable(vh, lh, lv, ll)
                                                               : rad_smith_g2_height_correlated(vh, lh, lv, ll);
                    float sp = G * D / (4.0 * nl * nv);
                    for (int k = 0; k < 3; ++k) f[k] = rad_fresnel_schlick_f90(g.f0[k], g.f90[k], g.p.w, lh) * sp;
                }
                for (int k = 0; k < 3; ++k) {
                    if (g.mode.w == RAD_DIFFUSE_LAMBERT)
                        f[k] += rad_diffuse_lambert(g.albedo[k], rad_fresnel_schlick_f90(g.f0[k], g.f90[k], g.p.w, nl));
                    else if (g.mode.w == RAD_DIFFUSE_SHIRLEY)
                        f[k] += rad_diffuse_shirley(g.albedo[k], g.f0[k], nl, nv);
                }
            }
            rr = f * nl;
        }
    }
    out_f = f;
    return rr;
}

#endif

#version 450
// lighting_eval.comp - evaluates rad_shade() of lighting.glsl for an array of configurations
// so a host can compare with rad_shading_brdf / rad_shading_eval (tests/test_shading_vulkan.c).
// Bindings: set 0, binding 0 the inputs (std430 RadShadingCase[]), binding 1 the outputs,
// 6 vec4 per case: f, R, then the individual terms (see rad_terms below; the C harness
// computes the same list). Push constant: the number of cases. Workgroup size: specialization
// constant 0 (default 64). The include is resolved by glslangValidator
// (GL_GOOGLE_include_directive, path relative to this file); a host compiling from memory
// (an embedded string, shaderc without an includer) replaces the #include line with the
// text of lighting.glsl and drops the #extension line: the result is the same shader.
#extension GL_GOOGLE_include_directive : require
#include "lighting.glsl"

layout(local_size_x_id = 0) in;

// 176 bytes: the packed material, then unit l, v, n, t, b in .xyz (w unused)
struct RadShadingCase {
    RadShadingParams params;
    vec4 l;
    vec4 v;
    vec4 n;
    vec4 t;
    vec4 b;
};

layout(std430, set = 0, binding = 0) readonly buffer Cases { RadShadingCase cases[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Results { vec4 results[]; };
layout(push_constant) uniform Push { uint count; } pc;

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) return;
    RadShadingCase c = cases[i];
    vec3 f;
    vec3 r = rad_shade(c.params, c.l.xyz, c.v.xyz, c.n.xyz, c.t.xyz, c.b.xyz, f);
    results[6u * i] = vec4(f, 0.0);
    results[6u * i + 1u] = vec4(r, 0.0);
    // every term function on this case's vectors; roughness 0.3 for the non-microfacet models
    vec3 l = c.l.xyz, v = c.v.xyz, n = c.n.xyz, t = c.t.xyz, b = c.b.xyz;
    float ax = c.params.p.x > 0.0 ? c.params.p.x : 0.3, ay = c.params.p.y > 0.0 ? c.params.p.y : 0.3;
    vec3 h = l + v;
    float len = sqrt(dot(h, h));
    h = len > 0.0 ? h / len : n;
    float nh = dot(n, h), th = dot(t, h), bh = dot(b, h), lh = dot(l, h), vh = dot(v, h);
    float nl = dot(n, l), nv = dot(n, v);
    float av = rad_smith_a(nv, dot(t, v), dot(b, v), ax, ay), al = rad_smith_a(nl, dot(t, l), dot(b, l), ax, ay);
    float lv = rad_lambda_ggx(av), ll = rad_lambda_ggx(al);
    float F = rad_fresnel_schlick_f90(c.params.f0.x, c.params.f90.x, 5.0, nl);
    results[6u * i + 2u] = vec4(av, lv, rad_lambda_beckmann(av), rad_smith_g1(vh, lv));
    results[6u * i + 3u] = vec4(rad_ndf_beckmann(nh, ax), rad_ndf_ggx(nh, ax), rad_ndf_beckmann_aniso(nh, th, bh, ax, ay),
                                rad_ndf_ggx_aniso(nh, th, bh, ax, ay));
    results[6u * i + 4u] = vec4(rad_fresnel_schlick(c.params.f0.x, lh), F, rad_diffuse_lambert(c.params.albedo.x, F),
                                rad_diffuse_shirley(c.params.albedo.x, c.params.f0.x, nl, nv));
    results[6u * i + 5u] = vec4(rad_smith_g2_separable(vh, lh, lv, ll), rad_smith_g2_height_correlated(vh, lh, lv, ll),
                                rad_lambda_beckmann(al), 0.0);
}

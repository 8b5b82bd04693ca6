#version 450
// lighting_eval.comp - evaluates rad_shade() of lighting.glsl for an array of configurations
// so a host can compare with rad_shading_brdf / rad_shading_eval (tests/test_shading_vulkan.c).
// Bindings: set 0, binding 0 the inputs (std430 RadShadingCase[]), binding 1 the outputs
// (vec4 pairs: f, R). Push constant: the number of cases. Workgroup size: specialization
// constant 0 (default 64). The include is resolved by glslangValidator
// (GL_GOOGLE_include_directive, path relative to this file).
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
    results[2u * i] = vec4(f, 0.0);
    results[2u * i + 1u] = vec4(r, 0.0);
}

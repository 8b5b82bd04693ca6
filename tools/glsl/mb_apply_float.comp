#version 450
#extension GL_GOOGLE_include_directive : require   // reduce.glsl; `make glsl` inlines it
// radiosity.h kernel RAD_GLSL_MB_APPLY_FLOAT: the multi-bounce apply L = F_mb E with float planes
// (rad_multibounce with precision RAD_MB_FLOAT). Plane row i' (permuted order) is original row
// row_perm[i'], plane column j' is original column col_perm[j'] (identity when flags bit 1 is clear):
//   out[row_perm[i']] = sum_j' plane_c[i'][j'] * E[col_perm[j']]  (+ E[row_perm[i']] when flags bit 0)
// for plane rows i' = row_offset .. row_offset + row_count - 1, channels c = R, G, B.
// ONE WORKGROUP PER ROW: dispatch row_count groups; the group strides over the columns.
// Chunking: bindings 0..2 may hold only this chunk's rows; entry (i', j') of plane c is element
// base + (i' - row_offset) * n + j' of binding c.
layout(local_size_x_id = 0) in;
layout(std430, set = 0, binding = 0) readonly buffer PlaneR { float R[]; };
layout(std430, set = 0, binding = 1) readonly buffer PlaneG { float G[]; };
layout(std430, set = 0, binding = 2) readonly buffer PlaneB { float B[]; };
layout(std430, set = 0, binding = 3) readonly buffer VectorE { float E[]; };       // 3 N, original order
layout(std430, set = 0, binding = 4) readonly buffer ColPerm { uint col_perm[]; }; // N (unused without bit 1)
layout(std430, set = 0, binding = 5) readonly buffer RowPerm { uint row_perm[]; }; // N (unused without bit 1)
layout(std430, set = 0, binding = 6) buffer Output { float outv[]; };              // 3 N, original order
layout(push_constant) uniform Push {
    uint n;           // N
    uint row_offset;  // first plane row of this dispatch
    uint row_count;   // rows in this dispatch (= workgroups)
    uint base;        // element of bindings 0..2 that holds plane row row_offset, column 0
    uint flags;       // bit 0: add E (total); bit 1: row_perm / col_perm are bound
} pc;

#include "reduce.glsl"                              // rad_group_sum

void main()
{
    uint r = gl_WorkGroupID.x, lid = gl_LocalInvocationID.x;
    if (r >= pc.row_count) return;
    bool perm = (pc.flags & 2u) != 0u;
    uint ip = pc.row_offset + r;
    uint at = pc.base + r * pc.n;
    precise vec3 acc = vec3(0.0);
    for (uint j = lid; j < pc.n; j += gl_WorkGroupSize.x) {
        uint e = 3u * (perm ? col_perm[j] : j);
        acc += vec3(R[at + j], G[at + j], B[at + j]) * vec3(E[e], E[e + 1u], E[e + 2u]);
    }
    vec3 sum = rad_group_sum(acc);
    if (lid != 0u) return;
    uint o = 3u * (perm ? row_perm[ip] : ip);
    precise vec3 s = sum;
    if ((pc.flags & 1u) != 0u) s += vec3(E[o], E[o + 1u], E[o + 2u]);
    outv[o] = s.x;
    outv[o + 1u] = s.y;
    outv[o + 2u] = s.z;
}

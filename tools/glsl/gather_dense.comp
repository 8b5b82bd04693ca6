#version 450
#extension GL_GOOGLE_include_directive : require   // reduce.glsl; `make glsl` inlines it
// radiosity.h kernel RAD_GLSL_GATHER_DENSE: one classic bounce with a dense form-factor matrix,
//   out_i = rho_i * sum_j F_ij E_j            (flags bit 0 clear: RAD_OUTPUT_INDIRECT)
//   out_i = E_i + rho_i * sum_j F_ij E_j      (flags bit 0 set:   RAD_OUTPUT_TOTAL)
// for rows i = row_offset .. row_offset + row_count - 1. ONE WORKGROUP PER ROW: dispatch
// row_count groups; the invocations of a group read the row with a stride of the group size
// (consecutive invocations read consecutive columns) and sum in shared memory.
// Chunking: binding 0 holds the rows of this chunk only; F_ij is F[f_base + (i - row_offset) * cols + j],
// so a matrix larger than one storage-buffer range runs as several dispatches.
layout(local_size_x_id = 0) in;
layout(std430, set = 0, binding = 0) readonly buffer MatrixF { float F[]; };
layout(std430, set = 0, binding = 1) readonly buffer VectorE { float E[]; };      // 3 N, RGB interleaved
layout(std430, set = 0, binding = 2) readonly buffer Albedo { float rho[]; };     // 3 N
layout(std430, set = 0, binding = 3) buffer Output { float outv[]; };             // 3 N
layout(push_constant) uniform Push {
    uint row_offset;  // first row of this dispatch (global index)
    uint row_count;   // rows in this dispatch (= workgroups)
    uint cols;        // N
    uint f_base;      // element of binding 0 that holds F[row_offset][0]
    uint flags;       // bit 0: add E (total)
} pc;

#include "reduce.glsl"                              // rad_group_sum

void main()
{
    uint r = gl_WorkGroupID.x, lid = gl_LocalInvocationID.x;
    if (r >= pc.row_count) return;               // the whole group: barriers stay uniform
    uint i = pc.row_offset + r;
    uint at = pc.f_base + r * pc.cols;
    precise vec3 acc = vec3(0.0);
    for (uint j = lid; j < pc.cols; j += gl_WorkGroupSize.x) {
        float f = F[at + j];
        acc += f * vec3(E[3u * j], E[3u * j + 1u], E[3u * j + 2u]);
    }
    vec3 sum = rad_group_sum(acc);
    if (lid != 0u) return;
    precise vec3 o = sum * vec3(rho[3u * i], rho[3u * i + 1u], rho[3u * i + 2u]);
    if ((pc.flags & 1u) != 0u) o += vec3(E[3u * i], E[3u * i + 1u], E[3u * i + 2u]);
    outv[3u * i] = o.x;
    outv[3u * i + 1u] = o.y;
    outv[3u * i + 2u] = o.z;
}

#version 450
#extension GL_GOOGLE_include_directive : require   // reduce.glsl; `make glsl` inlines it
// radiosity.h kernel RAD_GLSL_GATHER_CSR: one classic bounce with a CSR (sparse) form-factor matrix,
//   out_i = rho_i * sum_k values[k] E_columns[k]  (+ E_i when flags bit 0 is set)
// for rows i = row_offset .. row_offset + row_count - 1, ONE WORKGROUP PER ROW (dispatch
// row_count groups; the group strides over the row's entries and sums in shared memory).
// Binding 0 holds all N + 1 row offsets as uint64 (two uint words each, low word first, as
// rad_matrix.row_offsets stores them). Chunking: bindings 1 and 2 may hold only the entries of
// this chunk's rows; entry k of the matrix is element k - entry_base of them (entry_base = the
// low 32 bits of the first entry index the bound ranges start at; a chunk spans < 2^32 entries).
layout(local_size_x_id = 0) in;
layout(std430, set = 0, binding = 0) readonly buffer RowOffsets { uvec2 row_offsets[]; };
layout(std430, set = 0, binding = 1) readonly buffer Columns { uint columns[]; };
layout(std430, set = 0, binding = 2) readonly buffer Values { float values[]; };
layout(std430, set = 0, binding = 3) readonly buffer VectorE { float E[]; };      // 3 N
layout(std430, set = 0, binding = 4) readonly buffer Albedo { float rho[]; };     // 3 N
layout(std430, set = 0, binding = 5) buffer Output { float outv[]; };             // 3 N
layout(push_constant) uniform Push {
    uint row_offset;  // first row of this dispatch (global index)
    uint row_count;   // rows in this dispatch (= workgroups)
    uint entry_base;  // low 32 bits of the entry index at element 0 of bindings 1 and 2
    uint flags;       // bit 0: add E (total)
} pc;

#include "reduce.glsl"                              // rad_group_sum

void main()
{
    uint r = gl_WorkGroupID.x, lid = gl_LocalInvocationID.x;
    if (r >= pc.row_count) return;
    uint i = pc.row_offset + r;
    uint k0 = row_offsets[i].x - pc.entry_base;       // wraps correctly: only the difference matters
    uint count = row_offsets[i + 1u].x - row_offsets[i].x;
    precise vec3 acc = vec3(0.0);
    for (uint e = lid; e < count; e += gl_WorkGroupSize.x) {
        uint j = columns[k0 + e];
        acc += values[k0 + e] * vec3(E[3u * j], E[3u * j + 1u], E[3u * j + 2u]);
    }
    vec3 sum = rad_group_sum(acc);
    if (lid != 0u) return;
    precise vec3 o = sum * vec3(rho[3u * i], rho[3u * i + 1u], rho[3u * i + 2u]);
    if ((pc.flags & 1u) != 0u) o += vec3(E[3u * i], E[3u * i + 1u], E[3u * i + 2u]);
    outv[3u * i] = o.x;
    outv[3u * i + 1u] = o.y;
    outv[3u * i + 2u] = o.z;
}

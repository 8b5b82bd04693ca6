#version 450
#extension GL_GOOGLE_include_directive : require   // reduce.glsl; `make glsl` inlines it
// radiosity.h kernel RAD_GLSL_MB_APPLY_HALF: the multi-bounce apply L = F_mb E with IEEE binary16
// planes (rad_multibounce with precision RAD_MB_HALF), uploaded unchanged: two values per uint
// word, the lower-addressed value in the low 16 bits (little-endian), so no 16-bit storage
// feature is needed. Same bindings, push constants, permutations, dispatch (one workgroup per
// row) and chunking as RAD_GLSL_MB_APPLY_FLOAT, with 'base' counted in binary16 values (it may
// be odd). Buffers and bound ranges must cover whole 32-bit words: round a range's end up to a
// multiple of 4 bytes, or the word holding the last value reads as zero.
layout(local_size_x_id = 0) in;
layout(std430, set = 0, binding = 0) readonly buffer PlaneR { uint R[]; };
layout(std430, set = 0, binding = 1) readonly buffer PlaneG { uint G[]; };
layout(std430, set = 0, binding = 2) readonly buffer PlaneB { uint B[]; };
layout(std430, set = 0, binding = 3) readonly buffer VectorE { float E[]; };
layout(std430, set = 0, binding = 4) readonly buffer ColPerm { uint col_perm[]; };
layout(std430, set = 0, binding = 5) readonly buffer RowPerm { uint row_perm[]; };
layout(std430, set = 0, binding = 6) buffer Output { float outv[]; };
layout(push_constant) uniform Push {
    uint n;
    uint row_offset;
    uint row_count;
    uint base;        // binary16 value of bindings 0..2 that holds plane row row_offset, column 0
    uint flags;       // bit 0: add E (total); bit 1: row_perm / col_perm are bound
} pc;

#include "reduce.glsl"                              // rad_group_sum

float half_at(uint word, uint h) { vec2 v = unpackHalf2x16(word); return (h & 1u) != 0u ? v.y : v.x; }

void main()
{
    uint r = gl_WorkGroupID.x, lid = gl_LocalInvocationID.x;
    if (r >= pc.row_count) return;
    bool perm = (pc.flags & 2u) != 0u;
    uint ip = pc.row_offset + r;
    uint at = pc.base + r * pc.n;
    precise vec3 acc = vec3(0.0);
    for (uint j = lid; j < pc.n; j += gl_WorkGroupSize.x) {
        uint e = 3u * (perm ? col_perm[j] : j), h = at + j;
        vec3 f = vec3(half_at(R[h >> 1u], h), half_at(G[h >> 1u], h), half_at(B[h >> 1u], h));
        acc += f * vec3(E[e], E[e + 1u], E[e + 2u]);
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

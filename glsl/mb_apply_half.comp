#version 450
// radiosity.h kernel RAD_GLSL_MB_APPLY_HALF: the multi-bounce apply L = F_mb E with IEEE binary16
// planes (rad_multibounce with precision RAD_MB_HALF), uploaded unchanged: two values per uint
// word, the lower-addressed value in the low 16 bits (little-endian), so no 16-bit storage
// feature is needed. Same bindings, push constants, permutations and chunking as
// RAD_GLSL_MB_APPLY_FLOAT, with 'base' counted in binary16 values (it may be odd).
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

float half_at(uint word, uint h) { vec2 v = unpackHalf2x16(word); return (h & 1u) != 0u ? v.y : v.x; }

void main()
{
    uint r = gl_GlobalInvocationID.x;
    if (r >= pc.row_count) return;
    bool perm = (pc.flags & 2u) != 0u;
    uint ip = pc.row_offset + r;
    uint at = pc.base + r * pc.n;
    precise float sr = 0.0, sg = 0.0, sb = 0.0;
    for (uint j = 0u; j < pc.n; ++j) {
        uint e = 3u * (perm ? col_perm[j] : j), h = at + j;
        sr += half_at(R[h >> 1u], h) * E[e];
        sg += half_at(G[h >> 1u], h) * E[e + 1u];
        sb += half_at(B[h >> 1u], h) * E[e + 2u];
    }
    uint o = 3u * (perm ? row_perm[ip] : ip);
    if ((pc.flags & 1u) != 0u) { sr += E[o]; sg += E[o + 1u]; sb += E[o + 2u]; }
    outv[o] = sr;
    outv[o + 1u] = sg;
    outv[o + 2u] = sb;
}

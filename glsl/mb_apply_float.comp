#version 450
// radiosity.h kernel RAD_GLSL_MB_APPLY_FLOAT: the multi-bounce apply L = F_mb E with float planes
// (rad_multibounce with precision RAD_MB_FLOAT). Plane row i' (permuted order) is original row
// row_perm[i'], plane column j' is original column col_perm[j'] (identity when flags bit 1 is clear):
//   out[row_perm[i']] = sum_j' plane_c[i'][j'] * E[col_perm[j']]  (+ E[row_perm[i']] when flags bit 0)
// for plane rows i' = row_offset .. row_offset + row_count - 1, one invocation per row, channels c = R, G, B.
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
    uint row_count;   // rows in this dispatch
    uint base;        // element of bindings 0..2 that holds plane row row_offset, column 0
    uint flags;       // bit 0: add E (total); bit 1: row_perm / col_perm are bound
} pc;

void main()
{
    uint r = gl_GlobalInvocationID.x;
    if (r >= pc.row_count) return;
    bool perm = (pc.flags & 2u) != 0u;
    uint ip = pc.row_offset + r;
    uint at = pc.base + r * pc.n;
    precise float sr = 0.0, sg = 0.0, sb = 0.0;
    for (uint j = 0u; j < pc.n; ++j) {
        uint e = 3u * (perm ? col_perm[j] : j);
        sr += R[at + j] * E[e];
        sg += G[at + j] * E[e + 1u];
        sb += B[at + j] * E[e + 2u];
    }
    uint o = 3u * (perm ? row_perm[ip] : ip);
    if ((pc.flags & 1u) != 0u) { sr += E[o]; sg += E[o + 1u]; sb += E[o + 2u]; }
    outv[o] = sr;
    outv[o + 1u] = sg;
    outv[o + 2u] = sb;
}

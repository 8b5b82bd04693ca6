#version 450
// radiosity.h kernel RAD_GLSL_LOCAL_UPDATE: the O(M^2) pass of a local-matrix add
// (rad_local_add, docs/methods/local.md) on T resident on the GPU, after RAD_GLSL_LOCAL_VECTORS filled the work
// buffer (its comment has the layout: u, v, c, r per channel and the scalars s, cuv, coef, tnn).
// For plane rows i = row_offset .. row_offset + row_count - 1 (all < end), channels R, G, B:
//   i == k (the new patch's slot):  T[k][j] = coef v[j] (j != k), T[k][k] = tnn
//   else: T[i][j] += cuv u[i] v[j] - c[i] r[j] / g   (j < end, j != k; the second term only when
//         an add evicts slot ev = k, g = 1 + r[ev]: the exact downdate fused into a rank-2 pass)
//         T[i][k] = coef u[i]
// which is rad_local_add's update, new row and new column; with the factors of the first-order
// form when RAD_GLSL_LOCAL_VECTORS ran with it. Nothing is written when some channel has
// s <= 1e-12 (the CPU returns RAD_ERROR_SINGULAR and leaves T unchanged). Rows and columns >= end
// are not touched. ONE WORKGROUP PER ROW: dispatch row_count groups; the group strides over j.
// Chunking: bindings 0..2 may hold only this chunk's rows, row i at element base + (i - row_offset) * m.
layout(local_size_x_id = 0) in;
layout(std430, set = 0, binding = 0) buffer PlaneR { float R[]; };
layout(std430, set = 0, binding = 1) buffer PlaneG { float G[]; };
layout(std430, set = 0, binding = 2) buffer PlaneB { float B[]; };
layout(std430, set = 0, binding = 3) readonly buffer Work { float w[]; }; // 12 m + 12, from LOCAL_VECTORS
layout(push_constant) uniform Push {
    uint m;            // M: rad_local.capacity, the plane stride
    uint end;          // slots in use after the add (as given to RAD_GLSL_LOCAL_VECTORS)
    uint row_offset;   // first plane row of this dispatch
    uint row_count;    // rows in this dispatch (= workgroups)
    uint base;         // element of bindings 0..2 that holds plane row row_offset, column 0
    uint k;            // the new patch's slot
    uint ev;           // the slot evicted by this add (then ev == k), or 0xFFFFFFFF
} pc;

void update(uint c, uint at, uint i)
{
    uint m = pc.m, o = c * 4u * m, s = 12u * m, lid = gl_LocalInvocationID.x;
    float cuv = w[s + 3u + c], coef = w[s + 6u + c];
    if (i == pc.k) {
        for (uint j = lid; j < pc.end; j += gl_WorkGroupSize.x) {
            precise float t = j == pc.k ? w[s + 9u + c] : coef * w[o + m + j];
            if (c == 0u) R[at + j] = t; else if (c == 1u) G[at + j] = t; else B[at + j] = t;
        }
        return;
    }
    precise float ui = cuv * w[o + i];
    precise float ci = pc.ev != 0xFFFFFFFFu ? -w[o + 2u * m + i] / (1.0 + w[o + 3u * m + pc.ev]) : 0.0;
    for (uint j = lid; j < pc.end; j += gl_WorkGroupSize.x) {
        precise float t;
        if (j == pc.k) t = coef * w[o + i];
        else {
            t = c == 0u ? R[at + j] : c == 1u ? G[at + j] : B[at + j];
            if (ui != 0.0 || ci != 0.0) t += ci * w[o + 3u * m + j] + ui * w[o + m + j];
        }
        if (c == 0u) R[at + j] = t; else if (c == 1u) G[at + j] = t; else B[at + j] = t;
    }
}

void main()
{
    uint r = gl_WorkGroupID.x;
    if (r >= pc.row_count) return;
    uint s = 12u * pc.m;
    for (uint c = 0u; c < 3u; ++c)
        if (!(w[s + c] > 1e-12)) return; // singular: T stays as it was
    uint at = pc.base + r * pc.m, i = pc.row_offset + r;
    for (uint c = 0u; c < 3u; ++c) update(c, at, i);
}

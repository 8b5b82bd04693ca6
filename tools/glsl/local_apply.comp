#version 450
#extension GL_GOOGLE_include_directive : require   // reduce.glsl; `make glsl` inlines it
// radiosity.h kernel RAD_GLSL_LOCAL_APPLY: the local multi-bounce apply of rad_local_apply
// (docs/methods/local.md): for every visible entry r = row_offset .. row_offset + row_count - 1,
// with slot i = vis_slot[r] and world patch p = vis_patch[r],
//   out[p] = sum_{j < end, lit_patch[j] != NONE} T_c[i][j] * E[lit_patch[j]]   (+ E[p] when flags bit 0)
// for channels c = R, G, B. T is rad_local.planes: three M x M planes, row = receiving slot,
// stride m. ONE WORKGROUP PER VISIBLE ENTRY: dispatch row_count groups; the group strides over
// the columns j < end and sums in shared memory.
// Chunking: bindings 0..2 may hold only plane rows slot_offset .. slot_offset + slot_count - 1
// (row i at element base + (i - slot_offset) * m); an entry whose slot lies outside them is
// skipped, so one dispatch per chunk over the whole visible list (or over the part of a list
// sorted by slot that falls in the chunk) covers every row.
layout(local_size_x_id = 0) in;
layout(std430, set = 0, binding = 0) readonly buffer PlaneR { float R[]; };
layout(std430, set = 0, binding = 1) readonly buffer PlaneG { float G[]; };
layout(std430, set = 0, binding = 2) readonly buffer PlaneB { float B[]; };
layout(std430, set = 0, binding = 3) readonly buffer VectorE { float E[]; };        // 3 n, world order
layout(std430, set = 0, binding = 4) readonly buffer LitPatch { uint lit_patch[]; }; // end: patch of slot j, or ~0u
layout(std430, set = 0, binding = 5) readonly buffer VisSlot { uint vis_slot[]; };   // visible entries: slots
layout(std430, set = 0, binding = 6) readonly buffer VisPatch { uint vis_patch[]; }; // visible entries: patches
layout(std430, set = 0, binding = 7) buffer Output { float outv[]; };               // 3 n, world order
layout(push_constant) uniform Push {
    uint m;            // M: rad_local.capacity, the plane stride
    uint end;          // rad_local.slot_end: columns j < end
    uint row_offset;   // first visible entry of this dispatch
    uint row_count;    // visible entries in this dispatch (= workgroups)
    uint slot_offset;  // first plane row held by bindings 0..2
    uint slot_count;   // plane rows held by bindings 0..2
    uint base;         // element of bindings 0..2 that holds plane row slot_offset, column 0
    uint flags;        // bit 0: add E (RAD_OUTPUT_TOTAL)
} pc;

#include "reduce.glsl"                              // rad_group_sum

void main()
{
    uint r = gl_WorkGroupID.x, lid = gl_LocalInvocationID.x;
    if (r >= pc.row_count) return;                    // the whole group: barriers stay uniform
    uint i = vis_slot[pc.row_offset + r];
    if (i < pc.slot_offset || i - pc.slot_offset >= pc.slot_count) return; // another chunk's row
    uint at = pc.base + (i - pc.slot_offset) * pc.m;
    precise vec3 acc = vec3(0.0);
    for (uint j = lid; j < pc.end; j += gl_WorkGroupSize.x) {
        uint p = lit_patch[j];
        if (p == 0xFFFFFFFFu) continue;
        acc += vec3(R[at + j], G[at + j], B[at + j]) * vec3(E[3u * p], E[3u * p + 1u], E[3u * p + 2u]);
    }
    vec3 sum = rad_group_sum(acc);
    if (lid != 0u) return;
    uint o = 3u * vis_patch[pc.row_offset + r];
    precise vec3 s = sum;
    if ((pc.flags & 1u) != 0u) s += vec3(E[o], E[o + 1u], E[o + 2u]);
    outv[o] = s.x;
    outv[o + 1u] = s.y;
    outv[o + 2u] = s.z;
}

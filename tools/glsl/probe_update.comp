#version 450
// radiosity.h kernel RAD_GLSL_PROBE_UPDATE: irradiance probes from a new patch solution, as
// rad_probes_update (docs/methods/probes.md):
//   E_i(probe) = D_i(probe) + sum over the probe's entries e of W_e,i B_patch(e)
// 27 coefficients per probe (coefficient-major, RGB interleaved: [27 p + 3 i + c]) for probes
// p = row_offset .. row_offset + row_count - 1, ONE INVOCATION PER PROBE. Binding 0 holds all
// probe count + 1 entry offsets as uint64 (two uint words each, low word first: rad_probes_weights'
// first array uploaded unchanged). Chunking: bindings 1 and 2 may hold only this chunk's entries:
// entry k is element k - entry_base of binding 1 and elements 9 k - weight_base .. + 8 of binding 2
// (both bases in 32 bits: a chunk spans < 2^32 / 9 entries). Band 4 (RAD_PROBES_BAND4) is the
// same sum: bind rad_probes_weights_band4's weights and direct at bindings 2 and 3, and binding 5
// receives the band-4 block (27 floats per probe, the layout of rad_probes_band4).
layout(local_size_x_id = 0) in;
layout(std430, set = 0, binding = 0) readonly buffer First { uvec2 first[]; };
layout(std430, set = 0, binding = 1) readonly buffer Patch { uint patch_index[]; };
layout(std430, set = 0, binding = 2) readonly buffer Weights { float weights[]; };   // 9 per entry
layout(std430, set = 0, binding = 3) readonly buffer Direct { float direct[]; };     // 27 per probe
layout(std430, set = 0, binding = 4) readonly buffer Radiosity { float B[]; };       // 3 N
layout(std430, set = 0, binding = 5) buffer Output { float coefficients[]; };        // 27 per probe
layout(push_constant) uniform Push {
    uint row_offset;  // first probe of this dispatch
    uint row_count;   // probes in this dispatch
    uint entry_base;  // low 32 bits of the entry index at element 0 of binding 1
    uint weight_base; // low 32 bits of the float index (9 k) at element 0 of binding 2
} pc;

void main()
{
    uint r = gl_GlobalInvocationID.x;
    if (r >= pc.row_count) return;
    uint p = pc.row_offset + r;
    uint k0 = first[p].x - pc.entry_base;             // wraps correctly: only the difference matters
    uint w0 = 9u * first[p].x - pc.weight_base;
    uint count = first[p + 1u].x - first[p].x;
    precise vec3 acc[9];
    for (uint i = 0u; i < 9u; ++i) {
        uint d = 27u * p + 3u * i;
        acc[i] = vec3(direct[d], direct[d + 1u], direct[d + 2u]);
    }
    for (uint e = 0u; e < count; ++e) {
        uint j = patch_index[k0 + e];
        vec3 b = vec3(B[3u * j], B[3u * j + 1u], B[3u * j + 2u]);
        for (uint i = 0u; i < 9u; ++i) acc[i] += weights[w0 + 9u * e + i] * b;
    }
    for (uint i = 0u; i < 9u; ++i) {
        coefficients[27u * p + 3u * i] = acc[i].x;
        coefficients[27u * p + 3u * i + 1u] = acc[i].y;
        coefficients[27u * p + 3u * i + 2u] = acc[i].z;
    }
}

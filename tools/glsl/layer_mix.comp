#version 450
// radiosity.h kernel RAD_GLSL_LAYER_MIX: the baker's light layers mixed, as rad_baker_mix_layers
// (docs/methods/bake.md, "light layers"):
//   out[i] = sum over planes g of scale[3 g + i mod 3] layer_g[i]
// on planar float layers (plane g holds stride floats, RGB interleaved: rad_baker_result's
// vertex_layers, lightmap_layers or probe_layers uploaded unchanged). The sky layers of
// rad_baker_mix_sky are more planes after the groups' (their scales: the sky's coefficients).
// ONE INVOCATION PER FLOAT: floats i = row_offset .. row_offset + row_count - 1 of planes
// g = plane_offset .. plane_offset + plane_count - 1. A plane whose three scales are 0 is
// skipped, and the planes are added in increasing order to a float sum that starts at 0 (or, with
// RAD_GLSL_LAYER_ACCUMULATE, at out[i]): the CPU's order, so a dispatch per few planes
// (layers larger than one storage-buffer range) adds up to what one dispatch over all gives.
// Binding 0 holds the float g * stride + i (an index over all planes) at element
// (g * stride + i) - base, with base the low 32 bits of that index at its element 0 (uint
// arithmetic wraps: only the difference matters, and a bound range is < 2^32 floats).
layout(local_size_x_id = 0) in;
layout(std430, set = 0, binding = 0) readonly buffer Layers { float layers[]; };
layout(std430, set = 0, binding = 1) readonly buffer Scales { float scales[]; };  // 3 per plane
layout(std430, set = 0, binding = 2) buffer Output { float mixed[]; };            // stride floats
layout(push_constant) uniform Push {
    uint row_offset;   // first float of this dispatch (an index into a plane)
    uint row_count;    // floats in this dispatch
    uint stride;       // floats per plane (3 x vertices, texels or 9 x probes)
    uint plane_offset; // first plane mixed by this dispatch (scales[3 plane_offset] is its scale)
    uint plane_count;  // planes mixed by this dispatch
    uint base;         // low 32 bits of the index g * stride + i at element 0 of binding 0
    uint flags;        // RAD_GLSL_LAYER_ACCUMULATE (1): add to out instead of overwriting it
} pc;

void main()
{
    uint r = gl_GlobalInvocationID.x;
    if (r >= pc.row_count) return;
    uint i = pc.row_offset + r, c = i % 3u;
    // precise: no fused multiply-add, each product rounded as the CPU's is
    precise float acc = (pc.flags & 1u) != 0u ? mixed[i] : 0.0;
    for (uint q = 0u; q < pc.plane_count; ++q) {
        uint g = pc.plane_offset + q;
        if (scales[3u * g] == 0.0 && scales[3u * g + 1u] == 0.0 && scales[3u * g + 2u] == 0.0) continue;
        acc += layers[g * pc.stride + i - pc.base] * scales[3u * g + c];
    }
    mixed[i] = acc;
}

#version 450
// radiosity.h kernel RAD_GLSL_LAYER_MIX_RGB9E5: the baker's light layers mixed from packed
// RGB9E5 planes, as rad_baker_mix_layers_rgb9e5 (docs/methods/bake.md, "light layers"):
//   out[3 t + c] = sum over planes g of scale[3 g + c] unpack(layer_g[t])_c
// on planar RGB9E5 layers (plane g holds stride words, one per texel: rad_baker_result's
// lightmap_rgb9e5 uploaded unchanged), written as float RGB (3 per texel), the output of
// RAD_GLSL_LAYER_MIX on the unpacked layers.
// ONE INVOCATION PER TEXEL: texels t = row_offset .. row_offset + row_count - 1 of planes
// g = plane_offset .. plane_offset + plane_count - 1; each word is read once for its three
// channels. A plane whose three scales are 0 is skipped, and the planes are added in increasing
// order to a float sum that starts at 0 (or, with RAD_GLSL_LAYER_ACCUMULATE, at out): the CPU's
// order, so a dispatch per few planes adds up to what one dispatch over all gives.
// Binding 0 holds the word g * stride + t (an index over all planes) at element
// (g * stride + t) - base, with base the low 32 bits of that index at its element 0 (uint
// arithmetic wraps: only the difference matters, and a bound range is < 2^32 words).
layout(local_size_x_id = 0) in;
layout(std430, set = 0, binding = 0) readonly buffer Layers { uint layers[]; };   // RGB9E5 words
layout(std430, set = 0, binding = 1) readonly buffer Scales { float scales[]; };  // 3 per plane
layout(std430, set = 0, binding = 2) buffer Output { float mixed[]; };            // 3 x stride floats
layout(push_constant) uniform Push {
    uint row_offset;   // first texel of this dispatch (an index into a plane)
    uint row_count;    // texels in this dispatch
    uint stride;       // texels (words) per plane: rad_baker_mix_layers_rgb9e5's texel_count
    uint plane_offset; // first plane mixed by this dispatch (scales[3 plane_offset] is its scale)
    uint plane_count;  // planes mixed by this dispatch
    uint base;         // low 32 bits of the index g * stride + t at element 0 of binding 0
    uint flags;        // RAD_GLSL_LAYER_ACCUMULATE (1): add to out instead of overwriting it
} pc;

// One channel as rad_rgb9e5_unpack computes it: the 9-bit mantissa field left in place (mask),
// converted to float, times the power of two 2^(e - 24 - shift) built from the exponent bits
// (bits 27-31 moved to the float's exponent field plus 127 - 24 - shift). Both factors and
// their product are exact floats (no denormals, no rounding), so any device gets the CPU's bits.
float rgb9e5_channel(uint u, uint mask, uint bias)
{
    return float(u & mask) * uintBitsToFloat(((u >> 4u) & 0x0F800000u) + (bias << 23u));
}

void main()
{
    uint r = gl_GlobalInvocationID.x;
    if (r >= pc.row_count) return;
    uint t = pc.row_offset + r;
    // precise: no fused multiply-add and no dropped "0 +", each product and sum rounded as the CPU's
    precise float ar = 0.0, ag = 0.0, ab = 0.0;
    if ((pc.flags & 1u) != 0u) {
        ar = mixed[3u * t];
        ag = mixed[3u * t + 1u];
        ab = mixed[3u * t + 2u];
    }
    for (uint q = 0u; q < pc.plane_count; ++q) {
        uint g = pc.plane_offset + q;
        float sr = scales[3u * g], sg = scales[3u * g + 1u], sb = scales[3u * g + 2u];
        if (sr == 0.0 && sg == 0.0 && sb == 0.0) continue;
        uint u = layers[g * pc.stride + t - pc.base];
        ar += rgb9e5_channel(u, 0x1FFu, 103u) * sr;     // red: bits 0-8, 2^(e - 24)
        ag += rgb9e5_channel(u, 0x3FE00u, 94u) * sg;    // green: bits 9-17, 2^(e - 33)
        ab += rgb9e5_channel(u, 0x7FC0000u, 85u) * sb;  // blue: bits 18-26, 2^(e - 42)
    }
    mixed[3u * t] = ar;
    mixed[3u * t + 1u] = ag;
    mixed[3u * t + 2u] = ab;
}

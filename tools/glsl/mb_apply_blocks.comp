#version 450
#extension GL_GOOGLE_include_directive : require   // reduce.glsl; `make glsl` inlines it
// radiosity.h kernel RAD_GLSL_MB_APPLY_BLOCKS: the multi-bounce apply from the block-compressed
// matrix (rad_multibounce_blocks), as rad_multibounce_blocks_apply: the texture unit decodes the
// blocks (texelFetch), each texel is multiplied by its tile's scale, the outliers are added
// exactly and the permutations are applied:
//   out[row_perm[y]] = sum_x decoded(x, y) * scale(tile of x, y) * E[col_perm[x]]
//                      + sum over the outliers of original row row_perm[y] of value * E[column]
//                      (+ E[row_perm[y]] when flags bit 0 is set)
// for texel rows y = row_offset .. row_offset + row_count - 1 (<= N), RGB. ONE WORKGROUP PER ROW:
// dispatch row_count groups; the group strides over the columns (neighbouring invocations fetch
// neighbouring texels) and sums in shared memory.
// Formats: RAD_BLOCK_BC1 (flags bit 2): one VK_FORMAT_BC1_RGB_UNORM_BLOCK image bound to
// bindings 0, 1 and 2 (its .rgb is read from binding 0); RAD_BLOCK_BC4X3: three
// VK_FORMAT_BC4_UNORM_BLOCK images (R, G, B planes) at bindings 0, 1, 2 (.r of each). The images
// are blocks_per_row * 4 texels square; texel (x, y) is entry (row y, column x).
// The outlier arrays are bound whole (they are indexed by original row, which a chunk of
// permuted rows does not keep contiguous): with the default 5% of N^2 they fit 128 MiB up to
// N of about 14 000.
layout(local_size_x_id = 0) in;
layout(set = 0, binding = 0) uniform sampler2D texR;   // BC1: the RGB texture; BC4X3: R plane
layout(set = 0, binding = 1) uniform sampler2D texG;   // BC4X3: G plane (BC1: any, unused)
layout(set = 0, binding = 2) uniform sampler2D texB;   // BC4X3: B plane (BC1: any, unused)
layout(std430, set = 0, binding = 3) readonly buffer Scales { float scales[]; };          // 3 per tile
layout(std430, set = 0, binding = 4) readonly buffer VectorE { float E[]; };              // 3 N
layout(std430, set = 0, binding = 5) readonly buffer ColPerm { uint col_perm[]; };        // N (flags bit 1)
layout(std430, set = 0, binding = 6) readonly buffer RowPerm { uint row_perm[]; };        // N (flags bit 1)
layout(std430, set = 0, binding = 7) readonly buffer OutlierOffsets { uvec2 out_off[]; }; // N + 1 uint64 (bit 3)
layout(std430, set = 0, binding = 8) readonly buffer OutlierColumns { uint out_col[]; };  // (bit 3)
layout(std430, set = 0, binding = 9) readonly buffer OutlierValues { float out_val[]; };  // 3 per outlier (bit 3)
layout(std430, set = 0, binding = 10) buffer Output { float outv[]; };                    // 3 N
layout(push_constant) uniform Push {
    uint n;             // N
    uint row_offset;    // first texel row of this dispatch
    uint row_count;     // rows in this dispatch
    uint tile;          // scale tile in texels (0: one scale per channel)
    uint tiles_per_row; // ceil(N / tile), 1 when tile is 0
    uint flags;         // bit 0: add E; bit 1: permuted; bit 2: BC1 (else BC4X3); bit 3: outliers bound
} pc;

#include "reduce.glsl"                              // rad_group_sum

void main()
{
    uint r = gl_WorkGroupID.x, lid = gl_LocalInvocationID.x;
    if (r >= pc.row_count) return;
    bool perm = (pc.flags & 2u) != 0u, bc1 = (pc.flags & 4u) != 0u;
    uint y = pc.row_offset + r;
    uint trow = pc.tile != 0u ? (y / pc.tile) * pc.tiles_per_row : 0u;
    precise vec3 acc = vec3(0.0);
    for (uint x = lid; x < pc.n; x += gl_WorkGroupSize.x) {
        ivec2 p = ivec2(int(x), int(y));
        vec3 d = bc1 ? texelFetch(texR, p, 0).rgb
                     : vec3(texelFetch(texR, p, 0).r, texelFetch(texG, p, 0).r, texelFetch(texB, p, 0).r);
        uint t = 3u * (trow + (pc.tile != 0u ? x / pc.tile : 0u));
        uint e = 3u * (perm ? col_perm[x] : x);
        acc += (d * vec3(scales[t], scales[t + 1u], scales[t + 2u])) * vec3(E[e], E[e + 1u], E[e + 2u]);
    }
    uint i = perm ? row_perm[y] : y;
    precise vec3 s = vec3(0.0);
    if ((pc.flags & 8u) != 0u) {
        uint k0 = out_off[i].x, count = out_off[i + 1u].x - k0;
        for (uint k = k0 + lid; k < k0 + count; k += gl_WorkGroupSize.x) {
            uint j = 3u * out_col[k];
            s += vec3(out_val[3u * k], out_val[3u * k + 1u], out_val[3u * k + 2u]) * vec3(E[j], E[j + 1u], E[j + 2u]);
        }
    }
    vec3 sum = rad_group_sum(acc + s);
    if (lid != 0u) return;
    precise vec3 o = sum;
    if ((pc.flags & 1u) != 0u) o += vec3(E[3u * i], E[3u * i + 1u], E[3u * i + 2u]);
    outv[3u * i] = o.x;
    outv[3u * i + 1u] = o.y;
    outv[3u * i + 2u] = o.z;
}

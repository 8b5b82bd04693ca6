#version 450
// radiosity.h kernel RAD_GLSL_LIGHTMAP_REFRESH: a lightmap refreshed from a new patch
// irradiance H, as rad_lightmap_refresh (docs/methods/lightmap.md), in its two stages:
//   pass 0 (RAD_GLSL_LIGHTMAP_PASS_VERTICES), one invocation per patch vertex v:
//     V[v] = sum over k in [vertex_first[v], vertex_first[v + 1]) of vertex_weights[k] H[vertex_patches[k]]
//   pass 1 (RAD_GLSL_LIGHTMAP_PASS_TEXELS), one invocation per row r (a texel with a row):
//     out[row_texels[r]] = sum over e in [row_first[r], row_first[r + 1]) of entry_weights[e] V[entry_vertices[e]]
// rows (vertices or texel rows) row_offset .. row_offset + row_count - 1. RGB vectors are
// interleaved (3 floats each). Pass 1 reads what pass 0 wrote into binding 4: put a
// compute-to-compute barrier between them. Texels without a row are not written.
// Chunking: the entry arrays of the pass (bindings 1 and 2, or 7 and 8) may hold only this
// chunk's entries: entry k is element k - entry_base. The offsets (0, 6), vectors (3, 4) and
// out (9) are bound whole. A pass reads none of the other pass's bindings (bind any buffer).
layout(local_size_x_id = 0) in;
layout(std430, set = 0, binding = 0) readonly buffer VertexFirst { uint vertex_first[]; };   // vertices + 1
layout(std430, set = 0, binding = 1) readonly buffer VertexPatches { uint vertex_patches[]; };
layout(std430, set = 0, binding = 2) readonly buffer VertexWeights { float vertex_weights[]; };
layout(std430, set = 0, binding = 3) readonly buffer Irradiance { float H[]; };              // 3 N
layout(std430, set = 0, binding = 4) buffer VertexValues { float V[]; };                      // 3 per vertex
layout(std430, set = 0, binding = 5) readonly buffer RowTexels { uint row_texels[]; };
layout(std430, set = 0, binding = 6) readonly buffer RowFirst { uint row_first[]; };         // rows + 1
layout(std430, set = 0, binding = 7) readonly buffer EntryVertices { uint entry_vertices[]; };
layout(std430, set = 0, binding = 8) readonly buffer EntryWeights { float entry_weights[]; };
layout(std430, set = 0, binding = 9) buffer Output { float lightmap[]; };                    // 3 per texel
layout(push_constant) uniform Push {
    uint pass;        // 0: vertices, 1: texel rows
    uint row_offset;  // first vertex or row of this dispatch
    uint row_count;   // vertices or rows in this dispatch
    uint entry_base;  // the entry index at element 0 of the pass's entry bindings
} pc;

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.row_count) return;
    uint r = pc.row_offset + i;
    precise vec3 acc = vec3(0.0);
    if (pc.pass == 0u) {
        uint a = vertex_first[r] - pc.entry_base, b = vertex_first[r + 1u] - pc.entry_base;
        for (uint k = a; k < b; ++k) {
            uint j = 3u * vertex_patches[k];
            acc += vertex_weights[k] * vec3(H[j], H[j + 1u], H[j + 2u]);
        }
        V[3u * r] = acc.x;
        V[3u * r + 1u] = acc.y;
        V[3u * r + 2u] = acc.z;
    } else {
        uint a = row_first[r] - pc.entry_base, b = row_first[r + 1u] - pc.entry_base;
        for (uint e = a; e < b; ++e) {
            uint j = 3u * entry_vertices[e];
            acc += entry_weights[e] * vec3(V[j], V[j + 1u], V[j + 2u]);
        }
        uint t = 3u * row_texels[r];
        lightmap[t] = acc.x;
        lightmap[t + 1u] = acc.y;
        lightmap[t + 2u] = acc.z;
    }
}

#version 450
// radiosity.h kernel RAD_GLSL_VP_GATHER: virtual-patch gathering at surface points, as
// rad_vp_gather / rad_vp_gather_point (docs/methods/virtual-patches.md). For point i with unit
// normal n: in each voxel v of the 2x2x2 block around p (by voxel centres; the grid coordinate
// x = (p - origin) / voxel_size - 1/2 clamped to [-2, dims + 1], base = floor(x), g = x - base),
//   L(v) = sum_a w_a x_a / sum_a w_a over v's patches a with w_a > 0
// (axis-aligned: w_a the split weights of n, max(0, +-n_k)^2 or max(0, +-n_k) normalized to
// sum 1 (flags bit 0: cosine); clustered, flags bit 1: w_a = (A_a N_a) . n, binding 5 holding
// each patch's normal times its area); voxels outside the grid,
// empty or with no patch facing n are skipped, and
//   out_i = sum_v t_v L(v) / sum_v t_v       (t_v the trilinear weights; 0 when no voxel is used;
//   the plain mean of the used L(v) when their t_v sum to 0)
// ONE INVOCATION PER POINT: dispatch ceil(row_count / size) groups for the points
// row_offset .. row_offset + row_count - 1. Chunking: bindings 0, 1 and 6 may hold only this
// chunk's points, point i at elements base + 3 (i - row_offset) .. + 2 of each (bind the three at
// the same element offset). Voxel keys are the uint64 rad_virtual_patches.voxel_keys (ascending,
// ix + dims0 (iy + dims1 iz)), read as uvec2 (low word first) and found by binary search.
layout(local_size_x_id = 0) in;
layout(std430, set = 0, binding = 0) readonly buffer Points { float P[]; };       // 3 per point
layout(std430, set = 0, binding = 1) readonly buffer Normals { float Nrm[]; };    // 3 per point, unit
layout(std430, set = 0, binding = 2) readonly buffer Values { float X[]; };       // 3 N, per patch
layout(std430, set = 0, binding = 3) readonly buffer VoxelKeys { uvec2 keys[]; }; // voxel_count uint64
layout(std430, set = 0, binding = 4) readonly buffer VoxelPatch { uint vpatch[]; }; // 6 per voxel, or ~0u
layout(std430, set = 0, binding = 5) readonly buffer PatchNormals { float PN[]; }; // 3 N: A_a N_a (clustered only)
layout(std430, set = 0, binding = 6) buffer Output { float outv[]; };             // 3 per point
layout(push_constant) uniform Push {
    float origin_x, origin_y, origin_z;   // rad_virtual_patches.origin
    float size_x, size_y, size_z;         // .voxel_size
    uint dims_x, dims_y, dims_z;          // .dims
    uint voxel_count;                     // .voxel_count
    uint row_offset;                      // first point of this dispatch
    uint row_count;                       // points in this dispatch
    uint base;                            // element of bindings 0, 1, 6 holding point row_offset
    uint flags;                           // bit 0: cosine split weights; bit 1: clustered
} pc;

uvec2 mul64(uint a, uvec2 b) { uint hi, lo; umulExtended(a, b.x, hi, lo); return uvec2(lo, hi + a * b.y); }
uvec2 add64(uvec2 a, uint b) { uint c; uint lo = uaddCarry(a.x, b, c); return uvec2(lo, a.y + c); }
bool less64(uvec2 a, uvec2 b) { return a.y < b.y || (a.y == b.y && a.x < b.x); }

uint find_voxel(uvec2 key)
{
    uint lo = 0u, hi = pc.voxel_count;
    while (lo < hi) {
        uint mid = lo + (hi - lo) / 2u;
        if (less64(keys[mid], key)) lo = mid + 1u; else hi = mid;
    }
    return lo < pc.voxel_count && keys[lo] == key ? lo : 0xFFFFFFFFu;
}

// a + b exactly, as the pair (sum, error) (Knuth's TwoSum)
vec2 two_sum(float a, float b)
{
    precise float s = a + b;
    precise float bb = s - a;
    precise float e = (a - (s - bb)) + (b - bb);
    return vec2(s, e);
}
// a * b exactly, as the pair (product, error) (Dekker, Veltkamp's split; no fma needed)
vec2 two_prod(float a, float b)
{
    precise float ca = 4097.0 * a, cb = 4097.0 * b;
    precise float ah = ca - (ca - a), bh = cb - (cb - b);
    precise float al = a - ah, bl = b - bh;
    precise float q = a * b;
    precise float e = ((ah * bh - q) + ah * bl + al * bh) + al * bl;
    return vec2(q, e);
}
// (p - o) / s - 1/2 as an unevaluated float pair (hi, lo), to about 1e-14 relative
vec2 grid_coordinate(float p, float o, float s)
{
    vec2 d = two_sum(p, -o);                      // p - o exactly
    precise float q = d.x / s;
    vec2 qs = two_prod(q, s);
    precise float r = ((d.x - qs.x) - qs.y) + d.y; // the remainder d - q s
    precise float ql = r / s;
    vec2 x = two_sum(q, -0.5);
    precise float lo = x.y + ql;
    return vec2(x.x, lo);
}

void main()
{
    uint r = gl_GlobalInvocationID.x;
    if (r >= pc.row_count) return;
    uint at = pc.base + 3u * r;
    vec3 p = vec3(P[at], P[at + 1u], P[at + 2u]), n = vec3(Nrm[at], Nrm[at + 1u], Nrm[at + 2u]);
    vec3 origin = vec3(pc.origin_x, pc.origin_y, pc.origin_z), size = vec3(pc.size_x, pc.size_y, pc.size_z);
    uvec3 dims = uvec3(pc.dims_x, pc.dims_y, pc.dims_z);
    bool clustered = (pc.flags & 2u) != 0u;
    // the split weights of n (+x, -x, +y, -y, +z, -z)
    vec3 wp = max(n, vec3(0.0)), wm = max(-n, vec3(0.0));
    if ((pc.flags & 1u) == 0u) { wp *= wp; wm *= wm; }
    float wsum = wp.x + wm.x + wp.y + wm.y + wp.z + wm.z;
    float w[6] = float[6](wp.x, wm.x, wp.y, wm.y, wp.z, wm.z);
    if (wsum > 0.0) for (int a = 0; a < 6; ++a) w[a] /= wsum;
    // the grid coordinate as a float pair (the CPU computes it in double: a float x would carry
    // an absolute error of about 1e-7 dims, large against the small trilinear weights)
    ivec3 b;
    vec3 g0, g1;
    for (int k = 0; k < 3; ++k) {
        vec2 x = grid_coordinate(p[k], origin[k], size[k]);
        float top = float(dims[k]) + 1.0;
        if (x.x < -2.0 || (x.x == -2.0 && x.y < 0.0)) x = vec2(-2.0, 0.0);
        if (x.x > top || (x.x == top && x.y > 0.0)) x = vec2(top, 0.0);
        float fb = floor(x.x);
        precise float f = x.x - fb;             // exact
        if (f + x.y < 0.0) fb -= 1.0; else if (f + x.y >= 1.0) fb += 1.0;
        f = x.x - fb;
        b[k] = int(fb);
        g1[k] = f + x.y;                        // the weight of the upper cell, g
        g0[k] = (1.0 - f) - x.y;                // 1 - g, from the pair: no cancellation near g = 1
    }
    precise vec3 acc = vec3(0.0), facc = vec3(0.0);
    precise float tsum = 0.0;
    uint used = 0u;
    for (uint corner = 0u; corner < 8u; ++corner) {
        ivec3 bit = ivec3(int(corner & 1u), int((corner >> 1) & 1u), int((corner >> 2) & 1u));
        ivec3 cell = b + bit;
        if (any(lessThan(cell, ivec3(0))) || any(greaterThanEqual(uvec3(cell), dims))) continue;
        vec3 tt = mix(g0, g1, vec3(bit));
        float t = tt.x * tt.y * tt.z;
        uvec2 key = add64(mul64(dims.x, add64(mul64(dims.y, uvec2(uint(cell.z), 0u)), uint(cell.y))), uint(cell.x));
        uint v = find_voxel(key);
        if (v == 0xFFFFFFFFu) continue;
        precise vec3 L = vec3(0.0);
        precise float ws = 0.0;
        for (uint a = 0u; a < 6u; ++a) {
            uint q = vpatch[6u * v + a];
            if (q == 0xFFFFFFFFu) continue;
            float wa = clustered ? dot(vec3(PN[3u * q], PN[3u * q + 1u], PN[3u * q + 2u]), n) : w[a];
            if (!(wa > 0.0)) continue;
            ws += wa;
            L += wa * vec3(X[3u * q], X[3u * q + 1u], X[3u * q + 2u]);
        }
        if (!(ws > 0.0)) continue; // nothing in this voxel faces n
        used++;
        acc += t * L / ws;
        facc += L / ws;
        tsum += t;
    }
    vec3 o = used == 0u ? vec3(0.0) : (tsum > 0.0 ? acc / tsum : facc / float(used));
    outv[at] = o.x;
    outv[at + 1u] = o.y;
    outv[at + 2u] = o.z;
}

#version 450
// radiosity.h kernel RAD_GLSL_LOCAL_VECTORS: the small pre-pass of a local-matrix add
// (rad_local_add, docs/methods/local.md) computed from T resident on the GPU: the vectors u, v and the scalar
// s of the Sherman-Morrison update (fused with the exact downdate of slot ev when an add evicts),
// which RAD_GLSL_LOCAL_UPDATE then applies. T is rad_local.planes (three M x M planes, stride m,
// row = receiving slot). The host streams only the new patch's row and column over the slots:
//   a_c[j] = rho_c[patch(j)] * A_n F_nj / A_j (column by reciprocity), b_c[j] = rho_c[n] * F_nj
// for member slots j != ev (zero elsewhere; channel-major, a[c * m + j]), nz = the slots with a
// non-zero F_nj (any order), ann_c = rho_c[n] F_nn. Work buffer (binding 6), channel c at c * 4m:
//   u[j] at +j, v[j] at +m + j, c[j] = T[j][ev] at +2m + j, r[j] = T[ev][j] at +3m + j;
//   then 12 scalars at 12m: s[3], cuv[3] (rank-1 factor), coef[3] (new row/column factor), tnn[3].
// Passes (push 'pass'), run in this order, each one dispatch (or one per row chunk for pass 0):
//   0  GATHER, row-chunked: ONE INVOCATION PER ITEM, max(row_count, end) invocations.
//      Invocation x as row i = row_offset + x: u[i] = a[i] + sum_p T[i][nz_p] a[nz_p], c[i] = T[i][ev];
//      as column j = x < end: v[j] (=, flags bit 0 on the first chunk; else +=) b[j] +
//      sum over nz_p in the chunk of b[nz_p] T[nz_p][j]; r[j] = T[ev][j] when ev is in the chunk.
//   1  EVICT (only when ev != ~0u), end invocations, reads no plane: with g = 1 + r[ev],
//      u[i] -= c[i] (r.a) / g, v[i] -= (b.c) r[i] / g, u[ev] = v[ev] = 0.
//   2  SCALARS, 3 invocations (one per channel): s = 1 - ann - b.u, and the factors:
//      exact (flags bit 1 clear): cuv = coef = 1/s, tnn = 1/s - 1 (as (ann + b.u) / s); first order (bit 1 set,
//      RAD_LOCAL_FIRST_ORDER): d = ann + b.a, coef = 1 + d, cuv = (1 + d)^2, tnn = d.
// Float arithmetic (the CPU accumulates u, v, s in double): within 1e-5 relative of rad_local_add
// for the tested sets. A kernel cannot fail: s <= 1e-12 (rows that break energy conservation)
// makes RAD_GLSL_LOCAL_UPDATE leave T unchanged; read s back to detect it.
layout(local_size_x_id = 0) in;
layout(std430, set = 0, binding = 0) readonly buffer PlaneR { float R[]; };
layout(std430, set = 0, binding = 1) readonly buffer PlaneG { float G[]; };
layout(std430, set = 0, binding = 2) readonly buffer PlaneB { float B[]; };
layout(std430, set = 0, binding = 3) readonly buffer VecA { float a[]; };   // 3 m, channel-major
layout(std430, set = 0, binding = 4) readonly buffer VecB { float b[]; };   // 3 m, channel-major
layout(std430, set = 0, binding = 5) readonly buffer NonZero { uint nz[]; }; // nnz slots
layout(std430, set = 0, binding = 6) buffer Work { float w[]; };            // 12 m + 12
layout(push_constant) uniform Push {
    uint m;            // M: rad_local.capacity, the plane stride
    uint end;          // slots in use after the add: max(new slot + 1, rad_local.slot_end)
    uint row_offset;   // pass 0: first plane row held by bindings 0..2
    uint row_count;    // pass 0: plane rows held by bindings 0..2 (row_offset + row_count <= end)
    uint base;         // pass 0: element of bindings 0..2 that holds plane row row_offset, column 0
    uint nnz;          // entries of nz
    uint ev;           // the slot evicted by this add, or 0xFFFFFFFF
    uint pass;         // 0, 1, 2 (see above)
    uint flags;        // bit 0: first chunk of pass 0 (v = b + ...); bit 1: first-order update
    float ann_r, ann_g, ann_b; // rho_n F_nn per channel
} pc;

float plane(uint c, uint e) { return c == 0u ? R[e] : c == 1u ? G[e] : B[e]; }

void main()
{
    uint x = gl_GlobalInvocationID.x, m = pc.m, c;
    bool evict = pc.ev != 0xFFFFFFFFu;
    if (pc.pass == 0u) {
        if (x < pc.row_count) { // row i of the chunk
            uint i = pc.row_offset + x, at = pc.base + x * m;
            for (c = 0u; c < 3u; ++c) {
                precise float acc = a[c * m + i];
                for (uint p = 0u; p < pc.nnz; ++p) acc += plane(c, at + nz[p]) * a[c * m + nz[p]];
                w[c * 4u * m + i] = acc;
                w[c * 4u * m + 2u * m + i] = (evict && i != pc.ev) ? plane(c, at + pc.ev) : 0.0;
            }
        }
        if (x < pc.end) { // column j
            uint j = x;
            bool ev_here = evict && pc.ev >= pc.row_offset && pc.ev - pc.row_offset < pc.row_count;
            for (c = 0u; c < 3u; ++c) {
                precise float acc = (pc.flags & 1u) != 0u ? b[c * m + j] : w[c * 4u * m + m + j];
                for (uint p = 0u; p < pc.nnz; ++p) {
                    uint r = nz[p];
                    if (r >= pc.row_offset && r - pc.row_offset < pc.row_count)
                        acc += b[c * m + r] * plane(c, pc.base + (r - pc.row_offset) * m + j);
                }
                w[c * 4u * m + m + j] = acc;
                if (ev_here) w[c * 4u * m + 3u * m + j] = plane(c, pc.base + (pc.ev - pc.row_offset) * m + j);
            }
        }
    } else if (pc.pass == 1u) {
        if (x >= pc.end || !evict) return;
        for (c = 0u; c < 3u; ++c) {
            uint o = c * 4u * m;
            float g = 1.0 + w[o + 3u * m + pc.ev];
            precise float ra = 0.0, bc = 0.0;  // r.a and b.c (a and b are zero at ev)
            for (uint p = 0u; p < pc.nnz; ++p) {
                uint j = nz[p];
                ra += w[o + 3u * m + j] * a[c * m + j];
                bc += b[c * m + j] * w[o + 2u * m + j];
            }
            if (x == pc.ev) {
                w[o + x] = 0.0;
                w[o + m + x] = 0.0;
            } else {
                w[o + x] -= w[o + 2u * m + x] * (ra / g);
                w[o + m + x] -= (bc / g) * w[o + 3u * m + x];
            }
        }
    } else if (pc.pass == 2u) {
        if (x >= 3u) return;
        c = x;
        precise float bu = 0.0, ba = 0.0;
        for (uint p = 0u; p < pc.nnz; ++p) {
            uint j = nz[p];
            bu += b[c * m + j] * w[c * 4u * m + j];
            ba += b[c * m + j] * a[c * m + j];
        }
        float ann = c == 0u ? pc.ann_r : c == 1u ? pc.ann_g : pc.ann_b;
        precise float q = ann + bu, s = 1.0 - q; // q: no cancellation
        uint o = 12u * m;
        w[o + c] = s;
        if ((pc.flags & 2u) == 0u) {
            w[o + 3u + c] = 1.0 / s;
            w[o + 6u + c] = 1.0 / s;
            w[o + 9u + c] = q / s;                 // 1/s - 1 without its cancellation
        } else {
            precise float d = ann + ba;
            w[o + 3u + c] = (1.0 + d) * (1.0 + d);
            w[o + 6u + c] = 1.0 + d;
            w[o + 9u + c] = d;
        }
    }
}

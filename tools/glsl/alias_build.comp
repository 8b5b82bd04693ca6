#version 450
// radiosity.h kernel RAD_GLSL_ALIAS_BUILD: alias tables of streamed rows built on the GPU
// (docs/methods/temporal.md), the same bins as rad_alias_build_row (Vose's robust variant in double, the
// order of operations of the >>api_temporal doc block; bit-identical where double arithmetic is
// IEEE, as on lavapipe), one invocation per row.
// Input rows in CSR form: row i's entries are k = in_off[i] .. in_off[i+1]-1 (uint64, global), at
// element k - entry_base of bindings 1 and 2; flags bit 0 (DENSE): no columns bound, the column
// of entry k is k - in_off[i]. Entries <= 0 are skipped; a negative or non-finite entry or a
// column >= cols makes the row's bin count 0 (the CPU builder returns INVALID_ARGUMENT).
// Output, padded layout: row i gets room for (its entry count + 1) bins starting at bin
// in_off[i] + i (bin b at word (b - out_base) * words of binding 3); counts[i] receives the bins
// written and totals[i] T_i. Binding 4 (double) and 5 (uint) are scratch of one element per
// output bin at the same positions. Needs the shaderFloat64 feature.
// RAD_GLSL_TEMPORAL_STEP samples this layout directly (its PADDED flag).
layout(local_size_x_id = 0) in;
layout(std430, set = 0, binding = 0) readonly buffer RowOffsets { uvec2 in_off[]; }; // rows + 1 uint64
layout(std430, set = 0, binding = 1) readonly buffer Columns { uint columns[]; };    // (not DENSE)
layout(std430, set = 0, binding = 2) readonly buffer Values { float values[]; };
layout(std430, set = 0, binding = 3) buffer Bins { uint bins[]; };                   // 2 or 3 words per bin
layout(std430, set = 0, binding = 4) buffer ScratchQ { double q[]; };
layout(std430, set = 0, binding = 5) buffer ScratchStack { uint stack[]; };
layout(std430, set = 0, binding = 6) buffer Counts { uint counts[]; };               // per row (global index)
layout(std430, set = 0, binding = 7) buffer Totals { float totals[]; };              // per row (global index)
layout(push_constant) uniform Push {
    uint row_offset;  // first row of this dispatch
    uint row_count;   // rows in this dispatch
    uint cols;        // N: the environment's column (COMPACT needs cols <= 65535)
    uint words;       // 2 (RAD_ALIAS_COMPACT) or 3 (RAD_ALIAS_WIDE)
    uint entry_base;  // low 32 bits of the entry index at element 0 of bindings 1 and 2
    uint out_base;    // low 32 bits of the bin index at element 0 of bindings 3, 4 and 5
    uint flags;       // bit 0: DENSE rows (no column array)
} pc;

void set_bin(uint b, uint threshold, uint col, uint alias_col)
{
    uint w = b * pc.words;
    bins[w] = threshold;
    if (pc.words == 2u) bins[w + 1u] = col | (alias_col << 16u);
    else { bins[w + 1u] = col; bins[w + 2u] = alias_col; }
}

uint col_of(uint b) { return pc.words == 2u ? (bins[b * 2u + 1u] & 0xFFFFu) : bins[b * 3u + 1u]; }

void main()
{
    uint r = gl_GlobalInvocationID.x;
    if (r >= pc.row_count) return;
    uint i = pc.row_offset + r;
    uint k0 = in_off[i].x, count = in_off[i + 1u].x - k0;
    uint b0 = k0 + i - pc.out_base;          // this row's first bin (local)
    bool dense = (pc.flags & 1u) != 0u;
    precise double W = 0.0;
    uint n = 0u;
    for (uint e = 0u; e < count; ++e) {
        float v = values[k0 - pc.entry_base + e];
        uint col = dense ? e : columns[k0 - pc.entry_base + e];
        if (isnan(v) || isinf(v) || v < 0.0 || col >= pc.cols) { counts[i] = 0u; totals[i] = 0.0; return; }
        if (v > 0.0) {
            q[b0 + n] = double(v);
            set_bin(b0 + n, 0xFFFFFFFFu, col, col);
            W += double(v);
            ++n;
        }
    }
    precise double env = 1.0 - W;
    double total = W;
    if (env > 0.0) {
        q[b0 + n] = env;
        set_bin(b0 + n, 0xFFFFFFFFu, pc.cols, pc.cols);
        ++n;
        total = 1.0;
    }
    W += env > 0.0 ? env : 0.0;
    // Vose, robust variant: Small grows up from stack[0], Large down from stack[n-1]
    uint small_top = 0u, large_bottom = n;
    for (uint b = 0u; b < n; ++b) {
        precise double qb = double(n) * q[b0 + b] / W;
        q[b0 + b] = qb;
        if (qb < 1.0) stack[b0 + small_top++] = b;
        else stack[b0 + --large_bottom] = b;
    }
    while (small_top > 0u && large_bottom < n) {
        uint l = stack[b0 + --small_top], g = stack[b0 + large_bottom++];
        precise double p = q[b0 + l] * 4294967296.0 + 0.5;
        set_bin(b0 + l, p >= 4294967295.0 ? 0xFFFFFFFFu : uint(p), col_of(b0 + l), col_of(b0 + g));
        precise double qg = (q[b0 + g] + q[b0 + l]) - 1.0;
        q[b0 + g] = qg;
        if (qg < 1.0) stack[b0 + small_top++] = g;
        else stack[b0 + --large_bottom] = g;
    }
    counts[i] = n;
    totals[i] = float(total);
}

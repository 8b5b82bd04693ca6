#version 450
// radiosity.h kernel RAD_GLSL_TEMPORAL_STEP: one frame of temporal radiosity (rad_temporal_step
// with a fixed weight), drawing exactly the indices the CPU draws: the counter-based generator
// and the alias draw of the >>api_temporal doc block, in 32-bit integer arithmetic. One invocation per row i
// (dispatch ceil(row_count / group size) groups):
//   acc = 0; for s = 0..k-1: J = draw(sample = sample_base + s); acc += V_J
//   X = acc * (T_i / k); X *= rho_i (flags bit 0); B_i = w B_i^prev + (1 - w) X
// V_j = E_j, or E_j + B_j^prev (flags bit 1: FEEDBACK); V_N = env (the sky E_0).
// channel = 3: one table set serves R, G and B. channel = c < 3: this dispatch uses table set c
// (MULTIBOUNCE with three tables, sample_base = c k) and reads and writes component c only.
// Chunking: binding 1 may hold only this chunk's bins: word w of the tables (bin b starts at word
// b * words) is element w - word_base of it (word_base: low 32 bits; a chunk spans < 2^32 words).
// PADDED tables (flags bit 2), as RAD_GLSL_ALIAS_BUILD writes them for streamed rows: row i's
// bins start at bin row_offsets[i] + i (binding 0 = the input entry offsets) and counts[i]
// (binding 7) says how many there are, so the build's output is sampled without compaction.
layout(local_size_x_id = 0) in;
layout(std430, set = 0, binding = 0) readonly buffer RowOffsets { uvec2 row_offsets[]; }; // rows + 1 uint64, in bins
layout(std430, set = 0, binding = 1) readonly buffer Bins { uint bins[]; };              // 2 or 3 words per bin
layout(std430, set = 0, binding = 2) readonly buffer Totals { float totals[]; };         // T_i per row
layout(std430, set = 0, binding = 3) readonly buffer VectorE { float E[]; };             // 3 N
layout(std430, set = 0, binding = 4) readonly buffer Albedo { float rho[]; };            // 3 N (flags bit 0)
layout(std430, set = 0, binding = 5) readonly buffer Previous { float Bprev[]; };        // 3 N
layout(std430, set = 0, binding = 6) buffer Next { float Bnext[]; };                     // 3 N
layout(std430, set = 0, binding = 7) readonly buffer Counts { uint counts[]; };          // bins per row (bit 2)
layout(push_constant) uniform Push {
    uint seed;        // rad_temporal_options.seed
    uint frame;       // rad_temporal_frame() before the step
    uint row_offset;  // first row of this dispatch
    uint row_count;   // rows in this dispatch
    uint n;           // N: the environment's column index
    uint samples;     // k
    uint words;       // 2 (RAD_ALIAS_COMPACT) or 3 (RAD_ALIAS_WIDE)
    uint flags;       // bit 0: multiply by rho (SINGLE, FEEDBACK); bit 1: V = E + B^prev (FEEDBACK); bit 2: PADDED
    uint channel;     // 3: RGB from one table set; 0..2: this channel only
    uint sample_base; // channel * k with three table sets, else 0
    uint word_base;   // low 32 bits of the tables' word index at element 0 of binding 1
    float weight;     // w in [0, 1)
    float env_r, env_g, env_b; // E_0
} pc;

uint rad_pcg(uint v)
{
    uint s = v * 747796405u + 2891336453u;
    uint t = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return (t >> 22u) ^ t;
}

float value_at(uint j, uint c)
{
    if (j >= pc.n) return c == 0u ? pc.env_r : (c == 1u ? pc.env_g : pc.env_b);
    float v = E[3u * j + c];
    if ((pc.flags & 2u) != 0u) v += Bprev[3u * j + c];
    return v;
}

void main()
{
    uint r = gl_GlobalInvocationID.x;
    if (r >= pc.row_count) return;
    uint i = pc.row_offset + r;
    uint key = rad_pcg(rad_pcg(rad_pcg(pc.seed) ^ pc.frame) ^ i);
    bool padded = (pc.flags & 4u) != 0u;
    uint first = row_offsets[i].x + (padded ? i : 0u);
    uint nb = padded ? counts[i] : row_offsets[i + 1u].x - row_offsets[i].x;
    uint c0 = pc.channel < 3u ? pc.channel : 0u, c1 = pc.channel < 3u ? pc.channel : 2u;
    precise float acc[3] = float[3](0.0, 0.0, 0.0);
    for (uint s = 0u; s < pc.samples; ++s) {
        uint u1 = rad_pcg(key ^ ((pc.sample_base + s) * 0x9E3779B9u));
        uint u2 = rad_pcg(u1 ^ 0x68E31DA4u);
        uint hi, lo;
        umulExtended(u1, nb, hi, lo);
        uint w = (first + hi) * pc.words - pc.word_base, j;   // wraps correctly: only the difference matters
        if (pc.words == 2u) j = u2 < bins[w] ? (bins[w + 1u] & 0xFFFFu) : (bins[w + 1u] >> 16u);
        else j = u2 < bins[w] ? bins[w + 1u] : bins[w + 2u];
        for (uint c = c0; c <= c1; ++c) acc[c] += value_at(j, c);
    }
    precise float scale = totals[i] / float(pc.samples);
    for (uint c = c0; c <= c1; ++c) {
        precise float x = acc[c] * scale;
        if ((pc.flags & 1u) != 0u) x *= rho[3u * i + c];
        precise float b = pc.weight * Bprev[3u * i + c] + (1.0 - pc.weight) * x;
        Bnext[3u * i + c] = b;
    }
}

/* test_vulkan_layers.h - RAD_GLSL_LAYER_MIX against rad_baker_mix_layers, part of
   tests/test_vulkan.c (included there, before its table of tests; it uses that file's helpers:
   g_vk, frand, compare, chunks, T_CHECK). */

/* The GPU's mix of 'groups' planes of 'stride' words (kernel RAD_GLSL_LAYER_MIX: floats;
   RAD_GLSL_LAYER_MIX_RGB9E5: packed texels; a dispatch row per word) in three row chunks
   times two plane chunks, the second with RAD_GLSL_LAYER_ACCUMULATE unless the first is empty,
   each bound at an offset; the output of out_floats floats starts as NaN, so every float must
   be written, and is copied into gpu. 1 on success. */
static int layer_mix_gpu(uint32_t kernel, const void *layers, size_t stride, uint32_t groups, const float *scales,
                         size_t out_floats, uint32_t local_size, float *gpu)
{
    uint32_t q, s, cut[4], pcut[3];
    vk_kernel k;
    vk_buf bL, bS, bO;
    int ok = 1;
    chunks((uint32_t)stride, cut);
    pcut[0] = 0;
    pcut[1] = groups / 2;
    pcut[2] = groups;
    if (!vk_kernel_create(&g_vk, &k, kernel, 0, 3, (uint32_t)sizeof(rad_glsl_layer_mix_push), local_size)) return 0;
    memset(&bL, 0, sizeof(bL));
    memset(&bS, 0, sizeof(bS));
    memset(&bO, 0, sizeof(bO));
    ok &= vk_buffer(&g_vk, &bL, stride * groups * 4, layers);
    ok &= vk_buffer(&g_vk, &bS, 3 * (VkDeviceSize)groups * 4, scales);
    ok &= vk_buffer(&g_vk, &bO, out_floats * 4, NULL);
    if (ok) memset(bO.map, 0xFF, out_floats * 4);
    for (s = 0; s < 2 && ok; ++s)
        for (q = 0; q < 3 && ok; ++q) {
            rad_glsl_layer_mix_push p;
            vk_range r[3];
            uint32_t at;
            VkDeviceSize first = (VkDeviceSize)pcut[s] * stride + cut[q];
            if (cut[q + 1] == cut[q] || pcut[s + 1] == pcut[s]) continue;
            p.row_offset = cut[q];
            p.row_count = cut[q + 1] - cut[q];
            p.stride = (uint32_t)stride;
            p.plane_offset = pcut[s];
            p.plane_count = pcut[s + 1] - pcut[s];
            p.flags = pcut[s] > 0 ? RAD_GLSL_LAYER_ACCUMULATE : 0u;
            r[0] = vk_chunk(&g_vk, &bL, 4, first, (VkDeviceSize)(p.plane_count - 1) * stride + p.row_count, &at);
            p.base = (uint32_t)first - at;
            r[1] = vk_whole(&bS);
            r[2] = vk_whole(&bO);
            ok &= vk_dispatch(&g_vk, &k, r, &p, p.row_count);
        }
    if (ok) memcpy(gpu, bO.map, out_floats * 4);
    vk_buffer_free(&g_vk, &bL); vk_buffer_free(&g_vk, &bS); vk_buffer_free(&g_vk, &bO);
    vk_kernel_destroy(&g_vk, &k);
    return ok;
}

/* Random planar layers of 'texels' RGB texels, 'groups' planes: a plane with scale 0 0 0 (skipped
   by both: NaNs in it must not reach the output), one with a single zero channel, negative and large scales, layers with zeros and a
   wide range of magnitudes, mixed by layer_mix_gpu. Both sum in the same order without fused products: the test asks
   for 1e-6 relative (float rounding of one product and sum) and reports the bit-equal fraction. */
static void layer_mix_case(uint32_t groups, uint32_t texels, uint32_t local_size, uint32_t *bit_equal, size_t *total)
{
    size_t stride = 3 * (size_t)texels, i;
    float *layers = (float *)malloc(stride * groups * sizeof(float));
    float *cpu = (float *)malloc(stride * sizeof(float)), *gpu = (float *)malloc(stride * sizeof(float));
    float scales[3 * 8];
    uint32_t g;
    int ok;
    if (!layers || !cpu || !gpu || groups > 8) { T_CHECK(0); free(layers); free(cpu); free(gpu); return; }
    for (i = 0; i < stride * groups; ++i) {
        float u = frand();
        layers[i] = u < 0.2f ? 0.0f : frand() * (u < 0.9f ? 4.0f : 3000.0f);
    }
    for (g = 0; g < groups; ++g)
        for (i = 0; i < 3; ++i) scales[3 * g + i] = 2.0f * frand() - 0.4f;
    scales[3] = scales[4] = scales[5] = 0.0f;   /* group 1: skipped, so its NaN below is never read */
    layers[stride + 7] = layers[stride + stride - 1] = (float)NAN;
    scales[3 * 2 + 1] = 0.0f;                   /* group 2: only its green off */
    scales[0] *= 250.0f;                        /* group 0: a bright light */
    T_CHECK(rad_baker_mix_layers(layers, groups, stride, scales, cpu, NULL) == RAD_SUCCESS);
    ok = layer_mix_gpu(RAD_GLSL_LAYER_MIX, layers, stride, groups, scales, stride, local_size, gpu);
    T_CHECK(ok);
    if (ok) {
        char what[80];
        snprintf(what, sizeof(what), "layer mix, %u groups, %u texels", groups, texels);
        compare(what, gpu, cpu, stride, 1e-6);
        for (i = 0; i < stride; ++i) *bit_equal += memcmp(gpu + i, cpu + i, 4) == 0;
        *total += stride;
    }
    free(layers);
    free(cpu);
    free(gpu);
}

static void test_layer_mix(void)
{
    static const uint32_t groups[3] = { 3, 5, 8 }, texels[3] = { 2731, 4096, 1500 };
    uint32_t c, equal = 0;
    size_t total = 0;
    g_worst_what = "relative difference from rad_baker_mix_layers";
    for (c = 0; c < 3; ++c) layer_mix_case(groups[c], texels[c], g_local_sizes[c & 1], &equal, &total);
    printf("    %u of %lu floats equal to the CPU's bit for bit\n", equal, (unsigned long)total);
}

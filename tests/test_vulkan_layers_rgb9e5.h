/* test_vulkan_layers_rgb9e5.h - RAD_GLSL_LAYER_MIX_RGB9E5 against rad_baker_mix_layers_rgb9e5,
   part of tests/test_vulkan.c (included there, before its table of tests; it uses that file's
   helpers: g_vk, frand, compare, chunks, T_CHECK). */

/* Packed planar layers of 'texels' texels, 'groups' planes: half the words packed by
   rad_rgb9e5_pack from floats over a wide range (zeros, tiny values at the smallest exponent,
   values clamped at RAD_RGB9E5_MAX), half raw random words (every word decodes; these reach
   mantissa and exponent fields the packer never writes). Scales: group 0 bright with a negative
   green (0 times it is -0, which the sum from +0 must turn into +0 as the CPU's does), group 1
   skipped (0 0 0), group 2 with only its green off, the others random in [-0.4, 1.6). The GPU
   mixes them in three texel chunks times two plane chunks (the second with
   RAD_GLSL_LAYER_ACCUMULATE unless the first is empty), each bound at an offset; the output
   starts as NaN, so every float must be written. The kernel decodes exactly and adds in the
   CPU's order without fused products, so the test asks for the CPU's bits in every float. */
static void layer_mix_rgb9e5_case(uint32_t groups, uint32_t texels, uint32_t local_size, uint32_t *bit_equal, size_t *total)
{
    size_t stride = texels, n3 = 3 * (size_t)texels, i, first_diff = (size_t)-1;
    uint32_t *layers = (uint32_t *)malloc(stride * groups * sizeof(uint32_t) + 4);
    float *rgb = (float *)calloc(3 * stride * groups + 1, sizeof(float)), *cpu = (float *)malloc(n3 * sizeof(float) + 4);
    float scales[3 * 8];
    uint32_t g, q, s, cut[4], pcut[3], equal = 0;
    vk_kernel k;
    vk_buf bL, bS, bO;
    int ok = 1;
    if (!layers || !rgb || !cpu || groups > 8 || groups == 0) { T_CHECK(0); free(layers); free(rgb); free(cpu); return; }
    for (i = 0; i < 3 * stride * groups; ++i) {
        float u = frand(), v = frand();
        rgb[i] = u < 0.15f ? 0.0f : u < 0.25f ? v * 1e-6f : u < 0.3f ? 70000.0f : v * (u < 0.85f ? 4.0f : 3000.0f);
    }
    T_CHECK(rad_rgb9e5_pack(rgb, stride * groups, layers, NULL) == RAD_SUCCESS);
    for (i = 0; i < stride * groups; ++i)
        if (frand() < 0.5f) layers[i] = (uint32_t)(frand() * 65536.0f) << 16 | (uint32_t)(frand() * 65536.0f);
    for (g = 0; g < groups; ++g)
        for (i = 0; i < 3; ++i) scales[3 * g + i] = 2.0f * frand() - 0.4f;
    scales[0] = 250.0f * (0.5f + frand()); /* group 0: a bright light, its green negative */
    scales[1] = -0.75f;
    if (groups > 1) scales[3] = scales[4] = scales[5] = 0.0f; /* group 1: skipped */
    if (groups > 2) scales[3 * 2 + 1] = 0.0f;                 /* group 2: only its green off */
    T_CHECK(rad_baker_mix_layers_rgb9e5(layers, groups, stride, scales, cpu, NULL) == RAD_SUCCESS);
    chunks(texels, cut);
    pcut[0] = 0;
    pcut[1] = groups / 2;
    pcut[2] = groups;
    if (!vk_kernel_create(&g_vk, &k, RAD_GLSL_LAYER_MIX_RGB9E5, 0, 3, (uint32_t)sizeof(rad_glsl_layer_mix_push), local_size)) {
        T_CHECK(0);
        free(layers); free(rgb); free(cpu);
        return;
    }
    ok &= vk_buffer(&g_vk, &bL, stride * groups * 4, layers);
    ok &= vk_buffer(&g_vk, &bS, 3 * (VkDeviceSize)groups * 4, scales);
    ok &= vk_buffer(&g_vk, &bO, n3 * 4, NULL);
    if (ok) memset(bO.map, 0xFF, n3 * 4);
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
            p.flags = pcut[s] > 0 ? RAD_GLSL_LAYER_ACCUMULATE : 0u; /* one group: the only chunk writes */
            r[0] = vk_chunk(&g_vk, &bL, 4, first, (VkDeviceSize)(p.plane_count - 1) * stride + p.row_count, &at);
            p.base = (uint32_t)first - at;
            r[1] = vk_whole(&bS);
            r[2] = vk_whole(&bO);
            ok &= vk_dispatch(&g_vk, &k, r, &p, p.row_count);
        }
    T_CHECK(ok);
    if (ok) {
        char what[80];
        const float *gpu = (const float *)bO.map;
        snprintf(what, sizeof(what), "rgb9e5 layer mix, %u groups, %u texels", groups, texels);
        compare(what, gpu, cpu, n3, 1e-6);
        for (i = 0; i < n3; ++i) {
            if (memcmp(gpu + i, cpu + i, 4) == 0) ++equal;
            else if (first_diff == (size_t)-1) first_diff = i;
        }
        if (equal != n3) {
            printf("    FAIL %s: %lu of %lu floats differ from the CPU's bits, first at %lu (gpu %.9g, cpu %.9g)\n", what,
                   (unsigned long)(n3 - equal), (unsigned long)n3, (unsigned long)first_diff, (double)gpu[first_diff],
                   (double)cpu[first_diff]);
            g_checks_failed++;
        }
        *bit_equal += equal;
        *total += n3;
    }
    vk_buffer_free(&g_vk, &bL); vk_buffer_free(&g_vk, &bS); vk_buffer_free(&g_vk, &bO);
    vk_kernel_destroy(&g_vk, &k);
    free(layers);
    free(rgb);
    free(cpu);
}

static void test_layer_mix_rgb9e5(void)
{
    /* 1 group (one plane chunk), 3 (an uneven split), 8 (two chunks of four), 5 on a single
       texel; odd texel counts; both workgroup sizes */
    static const uint32_t groups[4] = { 1, 3, 8, 5 }, texels[4] = { 1031, 2731, 1499, 1 };
    uint32_t c, equal = 0;
    size_t total = 0;
    g_worst_what = "relative difference from rad_baker_mix_layers_rgb9e5";
    for (c = 0; c < 4; ++c) layer_mix_rgb9e5_case(groups[c], texels[c], g_local_sizes[c & 1], &equal, &total);
    printf("    %u of %lu floats equal to the CPU's bit for bit\n", equal, (unsigned long)total);
}

/* test_vulkan_layers_rgb9e5.h - RAD_GLSL_LAYER_MIX_RGB9E5 against rad_baker_mix_layers_rgb9e5,
   part of tests/test_vulkan.c (included there, before its table of tests; it uses that file's
   helpers: g_vk, frand, compare, chunks, T_CHECK). */

/* Packed planar layers of 'texels' texels, 'groups' planes: half the words packed by
   rad_rgb9e5_pack from floats over a wide range (zeros, tiny values at the smallest exponent,
   values clamped at RAD_RGB9E5_MAX), half raw random words (every word decodes; these reach
   mantissa and exponent fields the packer never writes). Scales: group 0 bright with a negative
   green (0 times it is -0, which the sum from +0 must turn into +0 as the CPU's does), group 1
   skipped (0 0 0), group 2 with only its green off, the others random in [-0.4, 1.6). Mixed by
   layer_mix_gpu (test_vulkan_layers.h). The kernel decodes exactly and adds in the
   CPU's order without fused products, so the test asks for the CPU's bits in every float. */
static void layer_mix_rgb9e5_case(uint32_t groups, uint32_t texels, uint32_t local_size, uint32_t *bit_equal, size_t *total)
{
    size_t stride = texels, n3 = 3 * (size_t)texels, i, first_diff = (size_t)-1;
    uint32_t *layers = (uint32_t *)malloc(stride * groups * sizeof(uint32_t) + 4);
    float *rgb = (float *)calloc(3 * stride * groups + 1, sizeof(float)), *cpu = (float *)malloc(n3 * sizeof(float) + 4);
    float *gpu = (float *)malloc(n3 * sizeof(float) + 4), scales[3 * 8];
    uint32_t g, equal = 0;
    int ok;
    if (!layers || !rgb || !cpu || !gpu || groups > 8 || groups == 0) {
        T_CHECK(0);
        free(layers); free(rgb); free(cpu); free(gpu);
        return;
    }
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
    ok = layer_mix_gpu(RAD_GLSL_LAYER_MIX_RGB9E5, layers, stride, groups, scales, n3, local_size, gpu);
    T_CHECK(ok);
    if (ok) {
        char what[80];
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
    free(layers);
    free(rgb);
    free(cpu);
    free(gpu);
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

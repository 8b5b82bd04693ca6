/* test_shading_vulkan.c - the GLSL lighting models (tools/glsl/lighting.glsl) against the C ones
   (radiosity.h >>shading) on a Vulkan 1.1 compute device (Mesa's lavapipe is enough).
   Builds a few thousand cases (every model, both NDFs, both G2 forms, every diffuse term,
   isotropic and anisotropic, random directions including back-facing ones), compiles
   tools/glsl/lighting_eval.comp with glslangValidator at run time, runs it, and compares f, R and
   every term function (sv_terms) value by value: |gpu - c| <= 1e-5 |c| + 1e-6 max|c of that case| + 1e-12. The second
   part matters only where a term cancels to nearly 0 inside a larger value; the third only
   far outside a specular lobe, where values below 1e-12 sr^-1 come from exp() of a large
   negative argument (whose relative error grows with the argument) or are denormals, which
   the GPU flushes to 0. The largest relative difference is reported for values >= 1e-6.
   Usage: test_shading_vulkan [repository root] (default "."). Exit 0: pass, 1: fail,
   77: skipped (no glslangValidator, no Vulkan loader or no device), with a line saying why.
   Build: cc -std=c99 -I. tests/test_shading_vulkan.c -o build/tsv -lvulkan -lm */
#define RADIOSITY_IMPLEMENTATION
#include "../radiosity.h"
#include <vulkan/vulkan.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>

typedef struct sv_case {
    rad_shading_gpu params;
    float l[4], v[4], n[4], t[4], b[4];
} sv_case;
typedef char sv_check_case_size[(sizeof(sv_case) == 176) ? 1 : -1];

static uint32_t sv_seed = 2024u;
static double sv_rand(void)
{
    sv_seed = sv_seed * 1664525u + 1013904223u;
    return (sv_seed >> 8) / 16777216.0;
}

static void sv_unit(double *d)
{
    double len;
    do {
        d[0] = 2.0 * sv_rand() - 1.0; d[1] = 2.0 * sv_rand() - 1.0; d[2] = 2.0 * sv_rand() - 1.0;
        len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    } while (len < 0.1 || len > 1.0);
    d[0] /= len; d[1] /= len; d[2] /= len;
}

#define SV_OUT 24 /* floats per case: f, R and four vec4 of terms */

/* the terms the kernel writes after f and R, in the same order and the same float math */
static void sv_terms(const sv_case *c, float *o)
{
    const float *l = c->l, *v = c->v, *n = c->n, *t = c->t, *b = c->b;
    float ax = c->params.p[0] > 0.0f ? c->params.p[0] : 0.3f, ay = c->params.p[1] > 0.0f ? c->params.p[1] : 0.3f;
    float h[3], len, nh, th, bh, lh, vh, nl, nv, av, al, lv, ll, F;
    int k;
    for (k = 0; k < 3; ++k) h[k] = l[k] + v[k];
    len = sqrtf(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
    for (k = 0; k < 3; ++k) h[k] = len > 0.0f ? h[k] / len : n[k];
#define SV_DOT(a, b) ((a)[0] * (b)[0] + (a)[1] * (b)[1] + (a)[2] * (b)[2])
    nh = SV_DOT(n, h); th = SV_DOT(t, h); bh = SV_DOT(b, h); lh = SV_DOT(l, h); vh = SV_DOT(v, h);
    nl = SV_DOT(n, l); nv = SV_DOT(n, v);
    av = rad_smith_a(nv, SV_DOT(t, v), SV_DOT(b, v), ax, ay);
    al = rad_smith_a(nl, SV_DOT(t, l), SV_DOT(b, l), ax, ay);
#undef SV_DOT
    lv = rad_lambda_ggx(av);
    ll = rad_lambda_ggx(al);
    F = rad_fresnel_schlick_f90(c->params.f0[0], c->params.f90[0], 5.0f, nl);
    o[0] = av < HUGE_VALF ? av : 3.402823466e38f; o[1] = lv; o[2] = rad_lambda_beckmann(av); o[3] = rad_smith_g1(vh, lv);
    o[4] = rad_ndf_beckmann(nh, ax); o[5] = rad_ndf_ggx(nh, ax);
    o[6] = rad_ndf_beckmann_aniso(nh, th, bh, ax, ay); o[7] = rad_ndf_ggx_aniso(nh, th, bh, ax, ay);
    o[8] = rad_fresnel_schlick(c->params.f0[0], lh); o[9] = F;
    o[10] = rad_diffuse_lambert(c->params.albedo[0], F);
    o[11] = rad_diffuse_shirley(c->params.albedo[0], c->params.f0[0], nl, nv);
    o[12] = rad_smith_g2_separable(vh, lh, lv, ll); o[13] = rad_smith_g2_height_correlated(vh, lh, lv, ll);
    o[14] = rad_lambda_beckmann(al); o[15] = 0.0f;
}

/* material number m (of sv_material_count) */
static int sv_material(int m, rad_shading *s)
{
    int k;
    if (m < 7) {
        rad_shading_default(s, (rad_shading_model)m);
        if (m == RAD_SHADING_MINNAERT && (m & 1)) s->minnaert.k = 0.6f;
        return 1;
    }
    m -= 7;
    if (m >= 2 * 2 * 3 * 2) {
        m -= 24; /* extra variants of the simple models */
        if (m >= 4) return 0;
        rad_shading_default(s, m < 2 ? RAD_SHADING_PHONG : RAD_SHADING_BLINN_PHONG);
        s->phong.shininess = (m & 1) ? 500.0f : 3.0f;
        return 1;
    }
    rad_shading_default(s, RAD_SHADING_MICROFACET);
    s->microfacet.ndf = (m & 1) ? RAD_NDF_GGX : RAD_NDF_BECKMANN;
    s->microfacet.masking = (m & 2) ? RAD_MASKING_HEIGHT_CORRELATED : RAD_MASKING_SEPARABLE;
    s->microfacet.diffuse = (rad_diffuse_term)((m >> 2) % 3);
    s->microfacet.alpha_x = (m / 12) ? 0.6f : 0.15f;
    s->microfacet.alpha_y = (m / 12) ? 0.1f : 0.15f;
    for (k = 0; k < 3; ++k) {
        s->microfacet.f0[k] = 0.04f + 0.3f * (float)k;
        s->microfacet.f90[k] = 1.0f - 0.1f * (float)k;
        s->microfacet.albedo[k] = 0.8f - 0.2f * (float)k;
    }
    s->microfacet.fresnel_exponent = (m / 12) ? 5.0f : 4.0f;
    return 1;
}

#define SV_CHECK(call, what)                                                                      \
    do {                                                                                          \
        VkResult r_ = (call);                                                                     \
        if (r_ != VK_SUCCESS) {                                                                   \
            printf("vulkan: %s failed (%d)\n", what, (int)r_);                                   \
            goto fail;                                                                            \
        }                                                                                         \
    } while (0)

static int sv_memory_type(VkPhysicalDevice pd, uint32_t bits)
{
    VkPhysicalDeviceMemoryProperties mp;
    uint32_t i, want = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    vkGetPhysicalDeviceMemoryProperties(pd, &mp);
    for (i = 0; i < mp.memoryTypeCount; ++i)
        if ((bits & (1u << i)) && (mp.memoryTypes[i].propertyFlags & want) == want) return (int)i;
    return -1;
}

int main(int argc, char **argv)
{
    const char *root = argc > 1 ? argv[1] : ".";
    char cmd[2048], spv_path[1024];
    int per_material = 160, materials = 0, status = 1, m, i, k, skipped = 0;
    rad_shading s;
    sv_case *cases = NULL;
    float *expect = NULL;
    unsigned char *spv = NULL;
    long spv_size = 0;
    uint32_t count = 0;
    FILE *fp;
    VkInstance inst = VK_NULL_HANDLE;
    VkDevice dev = VK_NULL_HANDLE;
    VkBuffer buf[2] = { VK_NULL_HANDLE, VK_NULL_HANDLE };
    VkDeviceMemory mem[2] = { VK_NULL_HANDLE, VK_NULL_HANDLE };
    VkShaderModule shader = VK_NULL_HANDLE;
    VkDescriptorSetLayout dsl = VK_NULL_HANDLE;
    VkPipelineLayout pl = VK_NULL_HANDLE;
    VkPipeline pipe = VK_NULL_HANDLE;
    VkDescriptorPool pool = VK_NULL_HANDLE;
    VkCommandPool cpool = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;

    /* ---- the cases and the C answers ---- */
    while (sv_material(materials, &s)) ++materials;
    cases = (sv_case *)calloc((size_t)materials * per_material, sizeof(sv_case));
    expect = (float *)calloc((size_t)materials * per_material * SV_OUT, sizeof(float));
    if (!cases || !expect) goto fail;
    for (m = 0; m < materials; ++m) {
        sv_material(m, &s);
        for (i = 0; i < per_material; ++i) {
            double l[3], v[3], n[3], t[3], b[3], d;
            sv_case *c = &cases[count];
            float *e = &expect[SV_OUT * count];
            sv_unit(n); sv_unit(l); sv_unit(v); sv_unit(t);
            /* most cases in front (n.l, n.v > 0), some behind */
            if (i % 8 != 0) {
                if (l[0] * n[0] + l[1] * n[1] + l[2] * n[2] < 0.0) for (k = 0; k < 3; ++k) l[k] = -l[k];
                if (v[0] * n[0] + v[1] * n[1] + v[2] * n[2] < 0.0) for (k = 0; k < 3; ++k) v[k] = -v[k];
            }
            d = t[0] * n[0] + t[1] * n[1] + t[2] * n[2];
            for (k = 0; k < 3; ++k) t[k] -= d * n[k];
            d = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
            if (d < 1e-3) { --i; continue; }
            for (k = 0; k < 3; ++k) t[k] /= d;
            b[0] = n[1] * t[2] - n[2] * t[1]; b[1] = n[2] * t[0] - n[0] * t[2]; b[2] = n[0] * t[1] - n[1] * t[0];
            for (k = 0; k < 3; ++k) {
                c->l[k] = (float)l[k]; c->v[k] = (float)v[k]; c->n[k] = (float)n[k];
                c->t[k] = (float)t[k]; c->b[k] = (float)b[k];
            }
            if (rad_shading_pack(&s, &c->params, NULL) != RAD_SUCCESS) goto fail;
            if (s.model == RAD_SHADING_HALF_LAMBERT) {
                e[0] = e[1] = e[2] = 0.0f;
            } else if (rad_shading_brdf(&s, c->l, c->v, c->n, c->t, c->b, e, NULL) != RAD_SUCCESS) {
                printf("C brdf failed for material %d\n", m);
                goto fail;
            }
            if (rad_shading_eval(&s, c->l, c->v, c->n, c->t, c->b, e + 4, NULL) != RAD_SUCCESS) goto fail;
            sv_terms(c, e + 8);
            ++count;
        }
    }

    /* ---- SPIR-V ---- */
    snprintf(spv_path, sizeof(spv_path), "%s/build/lighting_eval.spv", root);
    snprintf(cmd, sizeof(cmd), "mkdir -p '%s/build' && glslangValidator -V '%s/tools/glsl/lighting_eval.comp' -o '%s' >/dev/null",
             root, root, spv_path);
    if (system("glslangValidator --version >/dev/null 2>&1") != 0) {
        printf("skip: glslangValidator not found (package glslang-tools)\n");
        skipped = 1;
        goto fail;
    }
    if (system(cmd) != 0) {
        printf("glslangValidator failed on %s/tools/glsl/lighting_eval.comp\n", root);
        goto fail;
    }
    fp = fopen(spv_path, "rb");
    if (!fp) goto fail;
    fseek(fp, 0, SEEK_END);
    spv_size = ftell(fp);
    fseek(fp, 0, SEEK_SET);
    spv = (unsigned char *)malloc((size_t)spv_size);
    if (!spv || fread(spv, 1, (size_t)spv_size, fp) != (size_t)spv_size) { fclose(fp); goto fail; }
    fclose(fp);

    /* ---- Vulkan ---- */
    {
        VkApplicationInfo app;
        VkInstanceCreateInfo ici;
        VkPhysicalDevice pds[16], pd;
        VkPhysicalDeviceProperties props;
        uint32_t npd = 16, nqf = 0, qf = UINT32_MAX;
        VkQueueFamilyProperties qfp[16];
        float prio = 1.0f;
        VkDeviceQueueCreateInfo dqci;
        VkDeviceCreateInfo dci;
        VkQueue queue;
        VkBufferCreateInfo bci;
        VkDeviceSize sizes[2];
        VkShaderModuleCreateInfo smci;
        VkDescriptorSetLayoutBinding bind[2];
        VkDescriptorSetLayoutCreateInfo dslci;
        VkPushConstantRange pcr;
        VkPipelineLayoutCreateInfo plci;
        VkSpecializationMapEntry sme;
        uint32_t wg = 64;
        VkSpecializationInfo si;
        VkComputePipelineCreateInfo cpci;
        VkDescriptorPoolSize ps;
        VkDescriptorPoolCreateInfo dpci;
        VkDescriptorSetAllocateInfo dsai;
        VkDescriptorSet set;
        VkDescriptorBufferInfo dbi[2];
        VkWriteDescriptorSet wds[2];
        VkCommandPoolCreateInfo cpoolci;
        VkCommandBufferAllocateInfo cbai;
        VkCommandBuffer cb;
        VkCommandBufferBeginInfo cbbi;
        VkSubmitInfo sub;
        VkFenceCreateInfo fci;
        void *map;
        float *got;
        double worst = 0.0, worst_big = 0.0, worst_terms = 0.0;
        int bad = 0, worst_case = -1;

        memset(&app, 0, sizeof(app));
        app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
        app.pApplicationName = "test_shading_vulkan";
        app.apiVersion = VK_API_VERSION_1_1;
        memset(&ici, 0, sizeof(ici));
        ici.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
        ici.pApplicationInfo = &app;
        if (vkCreateInstance(&ici, NULL, &inst) != VK_SUCCESS) {
            printf("skip: no Vulkan 1.1 instance (loader or driver missing: packages libvulkan1 mesa-vulkan-drivers)\n");
            inst = VK_NULL_HANDLE;
            skipped = 1;
            goto fail;
        }
        if (vkEnumeratePhysicalDevices(inst, &npd, pds) < 0 || npd == 0) {
            printf("skip: no Vulkan device\n");
            skipped = 1;
            goto fail;
        }
        pd = pds[0];
        vkGetPhysicalDeviceProperties(pd, &props);
        vkGetPhysicalDeviceQueueFamilyProperties(pd, &nqf, NULL);
        if (nqf > 16) nqf = 16;
        vkGetPhysicalDeviceQueueFamilyProperties(pd, &nqf, qfp);
        for (k = 0; k < (int)nqf; ++k)
            if (qfp[k].queueFlags & VK_QUEUE_COMPUTE_BIT) { qf = (uint32_t)k; break; }
        if (qf == UINT32_MAX) { printf("skip: no compute queue\n"); skipped = 1; goto fail; }
        printf("device: %s\n", props.deviceName);
        memset(&dqci, 0, sizeof(dqci));
        dqci.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
        dqci.queueFamilyIndex = qf;
        dqci.queueCount = 1;
        dqci.pQueuePriorities = &prio;
        memset(&dci, 0, sizeof(dci));
        dci.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
        dci.queueCreateInfoCount = 1;
        dci.pQueueCreateInfos = &dqci;
        SV_CHECK(vkCreateDevice(pd, &dci, NULL, &dev), "vkCreateDevice");
        vkGetDeviceQueue(dev, qf, 0, &queue);

        sizes[0] = (VkDeviceSize)count * sizeof(sv_case);
        sizes[1] = (VkDeviceSize)count * SV_OUT * sizeof(float);
        for (k = 0; k < 2; ++k) {
            VkMemoryRequirements mr;
            VkMemoryAllocateInfo mai;
            int type;
            memset(&bci, 0, sizeof(bci));
            bci.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
            bci.size = sizes[k];
            bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
            bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
            SV_CHECK(vkCreateBuffer(dev, &bci, NULL, &buf[k]), "vkCreateBuffer");
            vkGetBufferMemoryRequirements(dev, buf[k], &mr);
            type = sv_memory_type(pd, mr.memoryTypeBits);
            if (type < 0) { printf("no host-visible coherent memory\n"); goto fail; }
            memset(&mai, 0, sizeof(mai));
            mai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
            mai.allocationSize = mr.size;
            mai.memoryTypeIndex = (uint32_t)type;
            SV_CHECK(vkAllocateMemory(dev, &mai, NULL, &mem[k]), "vkAllocateMemory");
            SV_CHECK(vkBindBufferMemory(dev, buf[k], mem[k], 0), "vkBindBufferMemory");
        }
        SV_CHECK(vkMapMemory(dev, mem[0], 0, sizes[0], 0, &map), "vkMapMemory");
        memcpy(map, cases, (size_t)sizes[0]);
        vkUnmapMemory(dev, mem[0]);
        SV_CHECK(vkMapMemory(dev, mem[1], 0, sizes[1], 0, &map), "vkMapMemory");
        memset(map, 0xFF, (size_t)sizes[1]); /* NaN: an unwritten result fails */
        vkUnmapMemory(dev, mem[1]);

        memset(&smci, 0, sizeof(smci));
        smci.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
        smci.codeSize = (size_t)spv_size;
        smci.pCode = (const uint32_t *)(const void *)spv;
        SV_CHECK(vkCreateShaderModule(dev, &smci, NULL, &shader), "vkCreateShaderModule");
        memset(bind, 0, sizeof(bind));
        for (k = 0; k < 2; ++k) {
            bind[k].binding = (uint32_t)k;
            bind[k].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
            bind[k].descriptorCount = 1;
            bind[k].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
        }
        memset(&dslci, 0, sizeof(dslci));
        dslci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
        dslci.bindingCount = 2;
        dslci.pBindings = bind;
        SV_CHECK(vkCreateDescriptorSetLayout(dev, &dslci, NULL, &dsl), "vkCreateDescriptorSetLayout");
        pcr.stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
        pcr.offset = 0;
        pcr.size = 4;
        memset(&plci, 0, sizeof(plci));
        plci.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
        plci.setLayoutCount = 1;
        plci.pSetLayouts = &dsl;
        plci.pushConstantRangeCount = 1;
        plci.pPushConstantRanges = &pcr;
        SV_CHECK(vkCreatePipelineLayout(dev, &plci, NULL, &pl), "vkCreatePipelineLayout");
        sme.constantID = 0;
        sme.offset = 0;
        sme.size = sizeof(uint32_t);
        si.mapEntryCount = 1;
        si.pMapEntries = &sme;
        si.dataSize = sizeof(wg);
        si.pData = &wg;
        memset(&cpci, 0, sizeof(cpci));
        cpci.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
        cpci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
        cpci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
        cpci.stage.module = shader;
        cpci.stage.pName = "main";
        cpci.stage.pSpecializationInfo = &si;
        cpci.layout = pl;
        SV_CHECK(vkCreateComputePipelines(dev, VK_NULL_HANDLE, 1, &cpci, NULL, &pipe), "vkCreateComputePipelines");
        ps.type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        ps.descriptorCount = 2;
        memset(&dpci, 0, sizeof(dpci));
        dpci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
        dpci.maxSets = 1;
        dpci.poolSizeCount = 1;
        dpci.pPoolSizes = &ps;
        SV_CHECK(vkCreateDescriptorPool(dev, &dpci, NULL, &pool), "vkCreateDescriptorPool");
        memset(&dsai, 0, sizeof(dsai));
        dsai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
        dsai.descriptorPool = pool;
        dsai.descriptorSetCount = 1;
        dsai.pSetLayouts = &dsl;
        SV_CHECK(vkAllocateDescriptorSets(dev, &dsai, &set), "vkAllocateDescriptorSets");
        memset(wds, 0, sizeof(wds));
        for (k = 0; k < 2; ++k) {
            dbi[k].buffer = buf[k];
            dbi[k].offset = 0;
            dbi[k].range = VK_WHOLE_SIZE;
            wds[k].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
            wds[k].dstSet = set;
            wds[k].dstBinding = (uint32_t)k;
            wds[k].descriptorCount = 1;
            wds[k].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
            wds[k].pBufferInfo = &dbi[k];
        }
        vkUpdateDescriptorSets(dev, 2, wds, 0, NULL);
        memset(&cpoolci, 0, sizeof(cpoolci));
        cpoolci.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
        cpoolci.queueFamilyIndex = qf;
        SV_CHECK(vkCreateCommandPool(dev, &cpoolci, NULL, &cpool), "vkCreateCommandPool");
        memset(&cbai, 0, sizeof(cbai));
        cbai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
        cbai.commandPool = cpool;
        cbai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
        cbai.commandBufferCount = 1;
        SV_CHECK(vkAllocateCommandBuffers(dev, &cbai, &cb), "vkAllocateCommandBuffers");
        memset(&cbbi, 0, sizeof(cbbi));
        cbbi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
        cbbi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        SV_CHECK(vkBeginCommandBuffer(cb, &cbbi), "vkBeginCommandBuffer");
        vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipe);
        vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pl, 0, 1, &set, 0, NULL);
        vkCmdPushConstants(cb, pl, VK_SHADER_STAGE_COMPUTE_BIT, 0, 4, &count);
        vkCmdDispatch(cb, (count + wg - 1) / wg, 1, 1);
        SV_CHECK(vkEndCommandBuffer(cb), "vkEndCommandBuffer");
        memset(&fci, 0, sizeof(fci));
        fci.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
        SV_CHECK(vkCreateFence(dev, &fci, NULL, &fence), "vkCreateFence");
        memset(&sub, 0, sizeof(sub));
        sub.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
        sub.commandBufferCount = 1;
        sub.pCommandBuffers = &cb;
        SV_CHECK(vkQueueSubmit(queue, 1, &sub, fence), "vkQueueSubmit");
        SV_CHECK(vkWaitForFences(dev, 1, &fence, VK_TRUE, 60ull * 1000000000ull), "vkWaitForFences");
        SV_CHECK(vkMapMemory(dev, mem[1], 0, sizes[1], 0, &map), "vkMapMemory");
        got = (float *)map;
        for (i = 0; i < (int)count; ++i) {
            double scale = 0.0;
            for (k = 0; k < 8; ++k) if (k % 4 != 3 && fabs(expect[SV_OUT * i + k]) > scale) scale = fabs(expect[SV_OUT * i + k]);
            for (k = 0; k < SV_OUT; ++k) {
                double c, g, err;
                if (k < 8 && k % 4 == 3) continue;
                c = expect[SV_OUT * i + k];
                g = got[SV_OUT * i + k];
                /* terms: relative only (plus the 1e-12 floor), except the Lambert diffuse term
                   (1 - F) albedo / pi, which cancels as F -> 1: its scale is albedo / pi */
                if (k >= 8) scale = k == 18 ? cases[i].params.albedo[0] / 3.14159265358979 : 0.0;
                err = fabs(g - c);
                if (!(err <= 1e-5 * fabs(c) + 1e-6 * scale + 1e-12)) {
                    if (bad < 10) printf("FAIL case %d (model %d, ndf %d, masking %d, diffuse %d) %s[%d]: C %.9g GLSL %.9g\n", i,
                                         cases[i].params.mode[0], cases[i].params.mode[1], cases[i].params.mode[2],
                                         cases[i].params.mode[3], k < 4 ? "f" : k < 8 ? "R" : "term", k < 8 ? k % 4 : k - 8, c, g);
                    ++bad;
                }
                if (k >= 8) {
                    if (k != 18 && fabs(c) >= 1e-6 && err / fabs(c) > worst_terms) worst_terms = err / fabs(c);
                    continue;
                }
                if (fabs(c) >= 1e-2 && err / fabs(c) > worst_big) { worst_big = err / fabs(c); if (getenv("SV_DEBUG")) printf("  worst >= 1e-2: case %d model %d ndf %d C %.9g GLSL %.9g\n", i, cases[i].params.mode[0], cases[i].params.mode[1], c, g); }
                if (fabs(c) >= 1e-6 && err / fabs(c) > worst) { worst = err / fabs(c); worst_case = i; if (getenv("SV_DEBUG")) printf("  worst so far: case %d %s[%d] C %.9g GLSL %.9g (case max %.3g)\n", i, k < 4 ? "f" : "R", k % 4, c, g, scale); }
            }
        }
        vkUnmapMemory(dev, mem[1]);
        printf("%u cases, %d materials: %d mismatches; largest relative difference of f and R %.3g for values >= 1e-2, %.3g for values >= 1e-6 (case %d, model %d); of the terms (but the Lambert diffuse one) %.3g\n",
               count, materials, bad, worst_big, worst, worst_case, worst_case >= 0 ? cases[worst_case].params.mode[0] : -1, worst_terms);
        status = bad ? 1 : 0;
    }
fail:
    if (dev) {
        vkDeviceWaitIdle(dev);
        if (fence) vkDestroyFence(dev, fence, NULL);
        if (cpool) vkDestroyCommandPool(dev, cpool, NULL);
        if (pool) vkDestroyDescriptorPool(dev, pool, NULL);
        if (pipe) vkDestroyPipeline(dev, pipe, NULL);
        if (pl) vkDestroyPipelineLayout(dev, pl, NULL);
        if (dsl) vkDestroyDescriptorSetLayout(dev, dsl, NULL);
        if (shader) vkDestroyShaderModule(dev, shader, NULL);
        for (k = 0; k < 2; ++k) {
            if (buf[k]) vkDestroyBuffer(dev, buf[k], NULL);
            if (mem[k]) vkFreeMemory(dev, mem[k], NULL);
        }
        vkDestroyDevice(dev, NULL);
    }
    if (inst) vkDestroyInstance(inst, NULL);
    free(spv);
    free(cases);
    free(expect);
    if (skipped) return 77;
    printf("%s\n", status == 0 ? "pass" : "FAIL");
    return status;
}

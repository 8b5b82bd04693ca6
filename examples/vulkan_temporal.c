/* vulkan_temporal.c - radiosity.h's GLSL kernels in a user program: temporal radiosity on the GPU.

   1. Bake (or load with --load FILE): the built-in Cornell box, form factors, the source E, the
      albedo, alias tables of F and the infinite-bounce matrix F_mb, all in ONE container.
   2. Open the container in place and take views of what it holds (rad_alias_tables_view,
      rad_multibounce_load): this is what a game loads from disk.
   3. Create a Vulkan device (compute only, headless, any device), compile the kernels from the
      header's embedded GLSL (glslangValidator here; ship SPIR-V in a real application) and upload
      the baked arrays unchanged.
   4. Every frame: one RAD_GLSL_TEMPORAL_STEP dispatch (FEEDBACK mode: converges to the
      infinite-bounce solution, a few thousand random reads per frame) and one
      RAD_GLSL_MB_APPLY_FLOAT dispatch (the exact L_inf = F_mb E by one matrix-vector product),
      then read back both and print how far the temporal estimate is from L_inf.
   5. Check the GPU frames against rad_temporal_step on the CPU (same draws: same numbers).

       vulkan_temporal [--patches N] [--frames N] [--samples K] [--save FILE] [--load FILE] [--tmp DIR]

   Build: cc -std=c99 -O2 -I. examples/vulkan_temporal.c -o vulkan_temporal -lvulkan -lm
   Needs a Vulkan 1.1 driver (Mesa's lavapipe is enough) and glslangValidator on the PATH.
   Exit code 0 when the GPU agrees with the CPU. */
#define RADIOSITY_IMPLEMENTATION
#include "radiosity.h"
#include <vulkan/vulkan.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>

#define CHECK_VK(x) do { VkResult r_ = (x); if (r_ != VK_SUCCESS) { fprintf(stderr, "%s failed (%d)\n", #x, (int)r_); exit(1); } } while (0)
#define CHECK_RAD(x) do { rad_result r_ = (x); if (r_ != RAD_SUCCESS) { fprintf(stderr, "%s: %s\n", #x, rad_result_string(r_)); exit(1); } } while (0)

/* ---- step 1: the bake, into one container -------------------------------------------------- */

static void *bake(uint32_t patch_target, size_t *out_size)
{
    rad_scene_desc desc;
    rad_camera cam;
    rad_scene *scene = NULL;
    rad_patches *patches = NULL;
    rad_bvh *bvh = NULL;
    rad_form_factors *ff = NULL;
    rad_patch_options popt;
    rad_form_factor_options fopt;
    rad_multibounce_options mopt;
    rad_multibounce *mb = NULL;
    rad_alias_tables *tables = NULL;
    rad_raycaster rc;
    rad_section s[4 + RAD_MB_MAX_SECTIONS];
    uint32_t count = 0, mb_count = 0;
    float *E;
    void *bytes;
    rad_cornell_box(&desc, &cam);
    CHECK_RAD(rad_scene_create(&desc, NULL, &scene));
    rad_patch_options_default(&popt);
    popt.target_count = patch_target;
    CHECK_RAD(rad_patches_create(scene, &popt, NULL, &patches));
    CHECK_RAD(rad_bvh_create(scene, NULL, &bvh));
    rad_bvh_raycaster(bvh, &rc);
    rad_form_factor_options_default(&fopt);
    CHECK_RAD(rad_form_factors_dense(patches, &rc, &fopt, NULL, &ff));
    E = (float *)malloc(3 * sizeof(float) * patches->count);
    if (!E) exit(1);
    CHECK_RAD(rad_sources(patches, RAD_SOURCE_EMISSION, NULL, E));
    CHECK_RAD(rad_alias_tables_create(&ff->matrix, RAD_ALIAS_AUTO, NULL, &tables));
    rad_multibounce_options_default(&mopt);
    mopt.bounces = RAD_MB_INFINITE;
    CHECK_RAD(rad_multibounce_create(&ff->matrix, patches->albedo, &mopt, NULL, &mb));
    /* the sections: E and the albedo as named vectors, the tables, the matrix */
    memset(s, 0, sizeof(s));
    s[0].type = RAD_SECTION_VECTOR; s[0].elem_size = 12; s[0].count = patches->count; s[0].data = E; strcpy(s[0].name, "E");
    s[1].type = RAD_SECTION_VECTOR; s[1].elem_size = 12; s[1].count = patches->count; s[1].data = patches->albedo; strcpy(s[1].name, "albedo");
    rad_alias_tables_sections(tables, "F", s + 2, NULL);
    CHECK_RAD(rad_multibounce_sections(mb, "F_mb", s + 5, &mb_count));
    count = 5 + mb_count;
    CHECK_RAD(rad_container_size(s, count, out_size));
    bytes = malloc(*out_size);
    if (!bytes) exit(1);
    CHECK_RAD(rad_container_write(s, count, bytes, *out_size));
    printf("baked %u patches: %.2f MB container (alias tables %.2f MB, F_mb %.2f MB)\n", patches->count, *out_size / 1e6,
           rad_alias_tables_memory(tables) / 1e6, 12.0 * patches->count * patches->count / 1e6);
    free(E);
    rad_multibounce_destroy(mb);
    rad_alias_tables_destroy(tables);
    rad_form_factors_destroy(ff);
    rad_bvh_destroy(bvh);
    rad_patches_destroy(patches);
    rad_scene_destroy(scene);
    return bytes;
}

/* ---- step 3: a minimal compute-only Vulkan layer --------------------------------------------- */

typedef struct gpu {
    VkInstance instance;
    VkPhysicalDevice phys;
    VkDevice device;
    VkQueue queue;
    VkCommandPool pool;
    VkPhysicalDeviceMemoryProperties mem;
    char tmp[400];
} gpu;

typedef struct buffer { VkBuffer buffer; VkDeviceMemory memory; void *map; VkDeviceSize size; } buffer;

typedef struct kernel {
    VkDescriptorSetLayout set_layout;
    VkPipelineLayout layout;
    VkPipeline pipeline;
    VkDescriptorPool pool;
    VkDescriptorSet set;
    uint32_t bindings, push_size;
} kernel;

static void gpu_init(gpu *g)
{
    VkApplicationInfo app;
    VkInstanceCreateInfo ici;
    VkPhysicalDevice devs[8];
    VkPhysicalDeviceProperties props;
    VkQueueFamilyProperties fam[16];
    uint32_t ndev = 8, nf = 16, f, family = 0xFFFFFFFFu;
    float prio = 1.0f;
    VkDeviceQueueCreateInfo qci;
    VkDeviceCreateInfo dci;
    VkCommandPoolCreateInfo pci;
    memset(&app, 0, sizeof(app));
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.pApplicationName = "vulkan_temporal";
    app.apiVersion = VK_API_VERSION_1_1;
    memset(&ici, 0, sizeof(ici));
    ici.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    ici.pApplicationInfo = &app;
    CHECK_VK(vkCreateInstance(&ici, NULL, &g->instance));
    CHECK_VK(vkEnumeratePhysicalDevices(g->instance, &ndev, devs));
    if (ndev == 0) { fprintf(stderr, "no Vulkan device\n"); exit(1); }
    g->phys = devs[0];
    vkGetPhysicalDeviceProperties(g->phys, &props);
    vkGetPhysicalDeviceMemoryProperties(g->phys, &g->mem);
    vkGetPhysicalDeviceQueueFamilyProperties(g->phys, &nf, fam);
    for (f = 0; f < nf && family == 0xFFFFFFFFu; ++f)
        if (fam[f].queueFlags & VK_QUEUE_COMPUTE_BIT) family = f;
    if (family == 0xFFFFFFFFu) { fprintf(stderr, "no compute queue\n"); exit(1); }
    printf("device: %s\n", props.deviceName);
    memset(&qci, 0, sizeof(qci));
    qci.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    qci.queueFamilyIndex = family;
    qci.queueCount = 1;
    qci.pQueuePriorities = &prio;
    memset(&dci, 0, sizeof(dci));
    dci.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    CHECK_VK(vkCreateDevice(g->phys, &dci, NULL, &g->device));
    vkGetDeviceQueue(g->device, family, 0, &g->queue);
    memset(&pci, 0, sizeof(pci));
    pci.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pci.queueFamilyIndex = family;
    CHECK_VK(vkCreateCommandPool(g->device, &pci, NULL, &g->pool));
}

/* host-visible storage buffer (lavapipe and integrated GPUs: device-local too; on a discrete GPU
   upload the big arrays through a staging copy into device-local memory instead) */
static buffer buffer_create(gpu *g, VkDeviceSize size, const void *data)
{
    buffer b;
    VkBufferCreateInfo bci;
    VkMemoryRequirements req;
    VkMemoryAllocateInfo mai;
    uint32_t t;
    const VkMemoryPropertyFlags want = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    memset(&b, 0, sizeof(b));
    b.size = size ? size : 4;
    memset(&bci, 0, sizeof(bci));
    bci.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    bci.size = b.size;
    bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    CHECK_VK(vkCreateBuffer(g->device, &bci, NULL, &b.buffer));
    vkGetBufferMemoryRequirements(g->device, b.buffer, &req);
    memset(&mai, 0, sizeof(mai));
    mai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    mai.allocationSize = req.size;
    for (t = 0; t < g->mem.memoryTypeCount; ++t)
        if ((req.memoryTypeBits & (1u << t)) && (g->mem.memoryTypes[t].propertyFlags & want) == want) break;
    if (t == g->mem.memoryTypeCount) { fprintf(stderr, "no host-visible memory\n"); exit(1); }
    mai.memoryTypeIndex = t;
    CHECK_VK(vkAllocateMemory(g->device, &mai, NULL, &b.memory));
    CHECK_VK(vkBindBufferMemory(g->device, b.buffer, b.memory, 0));
    CHECK_VK(vkMapMemory(g->device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.map));
    if (data) memcpy(b.map, data, (size_t)size);
    else memset(b.map, 0, (size_t)b.size);
    return b;
}

static void buffer_destroy(gpu *g, buffer *b)
{
    vkDestroyBuffer(g->device, b->buffer, NULL);
    vkFreeMemory(g->device, b->memory, NULL);
}

/* SPIR-V from the header's GLSL: write the source, run glslangValidator, read the result */
static uint32_t *compile(const gpu *g, rad_glsl_id id, size_t *bytes)
{
    char src_path[512], spv_path[520], cmd[1200];
    size_t len = 0;
    char *src;
    FILE *f;
    uint32_t *code;
    long n;
    CHECK_RAD(rad_glsl_source(id, NULL, 0, &len));
    src = (char *)malloc(len + 1);
    if (!src) exit(1);
    CHECK_RAD(rad_glsl_source(id, src, len + 1, NULL));
    snprintf(src_path, sizeof(src_path), "%s/%s", g->tmp, rad_glsl_name(id));
    snprintf(spv_path, sizeof(spv_path), "%s.spv", src_path);
    f = fopen(src_path, "wb");
    if (!f || fwrite(src, 1, len, f) != len) { fprintf(stderr, "cannot write %s\n", src_path); exit(1); }
    fclose(f);
    free(src);
    snprintf(cmd, sizeof(cmd), "glslangValidator -V --target-env vulkan1.1 -o '%s' '%s' >/dev/null", spv_path, src_path);
    if (system(cmd) != 0) { fprintf(stderr, "glslangValidator failed on %s\n", src_path); exit(1); }
    f = fopen(spv_path, "rb");
    if (!f) exit(1);
    fseek(f, 0, SEEK_END);
    n = ftell(f);
    fseek(f, 0, SEEK_SET);
    code = (uint32_t *)malloc((size_t)n);
    if (!code || fread(code, 1, (size_t)n, f) != (size_t)n) exit(1);
    fclose(f);
    *bytes = (size_t)n;
    return code;
}

/* a pipeline with 'bindings' storage buffers bound once (the kernels take all changing values
   through push constants, so one descriptor set per kernel serves every frame) */
static kernel kernel_create(gpu *g, rad_glsl_id id, uint32_t push_size, uint32_t local_size, const buffer *const *bufs,
                            uint32_t bindings)
{
    kernel k;
    size_t bytes = 0;
    uint32_t *code = compile(g, id, &bytes), b;
    VkShaderModule module;
    VkShaderModuleCreateInfo smci;
    VkDescriptorSetLayoutBinding lb[16];
    VkDescriptorSetLayoutCreateInfo dlci;
    VkPushConstantRange pcr;
    VkPipelineLayoutCreateInfo plci;
    VkSpecializationMapEntry me;
    VkSpecializationInfo si;
    VkComputePipelineCreateInfo cpci;
    VkDescriptorPoolSize ps;
    VkDescriptorPoolCreateInfo dpci;
    VkDescriptorSetAllocateInfo dsai;
    VkDescriptorBufferInfo bi[16];
    VkWriteDescriptorSet w[16];
    memset(&k, 0, sizeof(k));
    memset(&smci, 0, sizeof(smci));
    smci.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    smci.codeSize = bytes;
    smci.pCode = code;
    CHECK_VK(vkCreateShaderModule(g->device, &smci, NULL, &module));
    free(code);
    memset(lb, 0, sizeof(lb));
    memset(w, 0, sizeof(w));
    for (b = 0; b < bindings; ++b) {
        lb[b].binding = b;
        lb[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        lb[b].descriptorCount = 1;
        lb[b].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    }
    memset(&dlci, 0, sizeof(dlci));
    dlci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    dlci.bindingCount = bindings;
    dlci.pBindings = lb;
    CHECK_VK(vkCreateDescriptorSetLayout(g->device, &dlci, NULL, &k.set_layout));
    pcr.stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    pcr.offset = 0;
    pcr.size = push_size;
    memset(&plci, 0, sizeof(plci));
    plci.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    plci.setLayoutCount = 1;
    plci.pSetLayouts = &k.set_layout;
    plci.pushConstantRangeCount = 1;
    plci.pPushConstantRanges = &pcr;
    CHECK_VK(vkCreatePipelineLayout(g->device, &plci, NULL, &k.layout));
    me.constantID = RAD_GLSL_SPEC_LOCAL_SIZE;   /* the workgroup size */
    me.offset = 0;
    me.size = sizeof(uint32_t);
    si.mapEntryCount = 1;
    si.pMapEntries = &me;
    si.dataSize = sizeof(uint32_t);
    si.pData = &local_size;
    memset(&cpci, 0, sizeof(cpci));
    cpci.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
    cpci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    cpci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    cpci.stage.module = module;
    cpci.stage.pName = "main";
    cpci.stage.pSpecializationInfo = &si;
    cpci.layout = k.layout;
    CHECK_VK(vkCreateComputePipelines(g->device, VK_NULL_HANDLE, 1, &cpci, NULL, &k.pipeline));
    vkDestroyShaderModule(g->device, module, NULL);
    ps.type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    ps.descriptorCount = bindings;
    memset(&dpci, 0, sizeof(dpci));
    dpci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
    dpci.maxSets = 1;
    dpci.poolSizeCount = 1;
    dpci.pPoolSizes = &ps;
    CHECK_VK(vkCreateDescriptorPool(g->device, &dpci, NULL, &k.pool));
    memset(&dsai, 0, sizeof(dsai));
    dsai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
    dsai.descriptorPool = k.pool;
    dsai.descriptorSetCount = 1;
    dsai.pSetLayouts = &k.set_layout;
    CHECK_VK(vkAllocateDescriptorSets(g->device, &dsai, &k.set));
    for (b = 0; b < bindings; ++b) {
        bi[b].buffer = bufs[b]->buffer;
        bi[b].offset = 0;
        bi[b].range = VK_WHOLE_SIZE;
        w[b].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        w[b].dstSet = k.set;
        w[b].dstBinding = b;
        w[b].descriptorCount = 1;
        w[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        w[b].pBufferInfo = &bi[b];
    }
    vkUpdateDescriptorSets(g->device, bindings, w, 0, NULL);
    k.bindings = bindings;
    k.push_size = push_size;
    return k;
}

static void kernel_destroy(gpu *g, kernel *k)
{
    vkDestroyDescriptorPool(g->device, k->pool, NULL);
    vkDestroyPipeline(g->device, k->pipeline, NULL);
    vkDestroyPipelineLayout(g->device, k->layout, NULL);
    vkDestroyDescriptorSetLayout(g->device, k->set_layout, NULL);
}

/* groups: the temporal step runs one invocation per row (ceil(rows / local_size) groups), the
   gathers and applies one workgroup per row (rows groups) */
static void record(VkCommandBuffer cb, const kernel *k, const void *push, uint32_t groups)
{
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, k->pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, k->layout, 0, 1, &k->set, 0, NULL);
    vkCmdPushConstants(cb, k->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, k->push_size, push);
    vkCmdDispatch(cb, groups, 1, 1);
}

/* ---- the program ------------------------------------------------------------------------------ */

int main(int argc, char **argv)
{
    uint32_t patch_target = 400, frames = 300, samples = 16, local_size = 64, n, f, i;
    const char *save = NULL, *load = NULL;
    void *bytes;
    size_t size = 0;
    rad_container *ct = NULL;
    const rad_section *sE, *sA;
    rad_alias_tables tables;
    const rad_alias_tables *tp[1];
    rad_multibounce *mb = NULL;
    rad_temporal *cpu = NULL;
    rad_temporal_options topt;
    gpu g;
    buffer bOff, bBins, bTot, bE, bAlb, bB[2], bPlanes[3], bPerm, bL;
    kernel kt[2], km;
    VkCommandBuffer cb;
    VkCommandBufferAllocateInfo cbai;
    float *L_cpu, *B_cpu;
    double worst_gpu_cpu = 0.0;
    int a;
    memset(&g, 0, sizeof(g));
    strcpy(g.tmp, ".");
    for (a = 1; a < argc; ++a) {
        if (!strcmp(argv[a], "--patches") && a + 1 < argc) patch_target = (uint32_t)atoi(argv[++a]);
        else if (!strcmp(argv[a], "--frames") && a + 1 < argc) frames = (uint32_t)atoi(argv[++a]);
        else if (!strcmp(argv[a], "--samples") && a + 1 < argc) samples = (uint32_t)atoi(argv[++a]);
        else if (!strcmp(argv[a], "--save") && a + 1 < argc) save = argv[++a];
        else if (!strcmp(argv[a], "--load") && a + 1 < argc) load = argv[++a];
        else if (!strcmp(argv[a], "--tmp") && a + 1 < argc) snprintf(g.tmp, sizeof(g.tmp), "%s", argv[++a]);
        else { fprintf(stderr, "usage: %s [--patches N] [--frames N] [--samples K] [--save FILE] [--load FILE] [--tmp DIR]\n", argv[0]); return 2; }
    }
    if (samples == 0) samples = 1;

    /* 1. bake or load */
    if (load) {
        FILE *fl = fopen(load, "rb");
        long len;
        if (!fl) { fprintf(stderr, "cannot open %s\n", load); return 1; }
        fseek(fl, 0, SEEK_END);
        len = ftell(fl);
        fseek(fl, 0, SEEK_SET);
        bytes = malloc(len > 0 ? (size_t)len : 1);
        if (!bytes || len <= 0 || fread(bytes, 1, (size_t)len, fl) != (size_t)len) { fprintf(stderr, "cannot read %s\n", load); return 1; }
        fclose(fl);
        size = (size_t)len;
    } else {
        bytes = bake(patch_target, &size);
        if (save) {
            FILE *fs = fopen(save, "wb");
            if (!fs || fwrite(bytes, 1, size, fs) != size || fclose(fs) != 0) { fprintf(stderr, "cannot write %s\n", save); return 1; }
        }
    }

    /* 2. views into the container: nothing is copied */
    CHECK_RAD(rad_container_create(bytes, size, NULL, &ct));
    sE = rad_container_find(ct, RAD_SECTION_VECTOR, "E");
    sA = rad_container_find(ct, RAD_SECTION_VECTOR, "albedo");
    if (!sE || !sA) { fprintf(stderr, "the container has no E or albedo vector\n"); return 1; }
    CHECK_RAD(rad_alias_tables_view(ct, "F", NULL, &tables));
    CHECK_RAD(rad_multibounce_load(ct, "F_mb", NULL, &mb));
    n = tables.rows;
    if (sE->count != n || sA->count != n || mb->n != n || mb->precision != RAD_MB_FLOAT) {
        fprintf(stderr, "the container's parts do not match (need float F_mb)\n");
        return 1;
    }

    /* 3. the device, the buffers (uploaded as stored), the kernels */
    gpu_init(&g);
    bOff = buffer_create(&g, ((VkDeviceSize)n + 1) * 8, tables.row_offsets);
    bBins = buffer_create(&g, tables.row_offsets[n] * (VkDeviceSize)tables.format * 4, tables.bins);
    bTot = buffer_create(&g, (VkDeviceSize)n * 4, tables.totals);
    bE = buffer_create(&g, (VkDeviceSize)n * 12, sE->data);
    bAlb = buffer_create(&g, (VkDeviceSize)n * 12, sA->data);
    bB[0] = buffer_create(&g, (VkDeviceSize)n * 12, NULL);
    bB[1] = buffer_create(&g, (VkDeviceSize)n * 12, NULL);
    for (i = 0; i < 3; ++i) bPlanes[i] = buffer_create(&g, (VkDeviceSize)n * n * 4, mb->planes + (size_t)i * n * n);
    bPerm = buffer_create(&g, 4, NULL); /* unpermuted F_mb: bound but unused */
    bL = buffer_create(&g, (VkDeviceSize)n * 12, NULL);
    {
        /* two descriptor sets for the temporal kernel: B ping-pongs between frames */
        const buffer *t0[8], *t1[8], *m[7];
        t0[0] = t1[0] = &bOff; t0[1] = t1[1] = &bBins; t0[2] = t1[2] = &bTot; t0[3] = t1[3] = &bE; t0[4] = t1[4] = &bAlb;
        t0[5] = &bB[0]; t0[6] = &bB[1];
        t1[5] = &bB[1]; t1[6] = &bB[0];
        t0[7] = t1[7] = &bPerm; /* bins per row: only for padded tables (RAD_GLSL_TEMPORAL_PADDED) */
        kt[0] = kernel_create(&g, RAD_GLSL_TEMPORAL_STEP, sizeof(rad_glsl_temporal_push), local_size, t0, 8);
        kt[1] = kernel_create(&g, RAD_GLSL_TEMPORAL_STEP, sizeof(rad_glsl_temporal_push), local_size, t1, 8);
        m[0] = &bPlanes[0]; m[1] = &bPlanes[1]; m[2] = &bPlanes[2]; m[3] = &bE; m[4] = &bPerm; m[5] = &bPerm; m[6] = &bL;
        km = kernel_create(&g, RAD_GLSL_MB_APPLY_FLOAT, sizeof(rad_glsl_mb_apply_push), local_size, m, 7);
    }
    memset(&cbai, 0, sizeof(cbai));
    cbai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    cbai.commandPool = g.pool;
    cbai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cbai.commandBufferCount = 1;
    CHECK_VK(vkAllocateCommandBuffers(g.device, &cbai, &cb));

    /* the CPU twin, for the check of step 5 */
    rad_temporal_options_default(&topt);
    topt.mode = RAD_TEMPORAL_FEEDBACK;
    topt.samples = samples;
    topt.weight = 0.98f;
    topt.seed = 2026u;
    tp[0] = &tables;
    CHECK_RAD(rad_temporal_create(tp, 1, (const float *)sA->data, &topt, NULL, &cpu));
    L_cpu = (float *)malloc((size_t)n * 12);
    B_cpu = (float *)malloc((size_t)n * 12);
    if (!L_cpu || !B_cpu) return 1;

    /* 4. the frames */
    printf("%u patches, %u draws per patch and frame, w = %.2f, FEEDBACK mode\n", n, samples, (double)topt.weight);
    for (f = 0; f < frames; ++f) {
        VkCommandBufferBeginInfo bi;
        VkSubmitInfo sub;
        VkMemoryBarrier bar;
        rad_glsl_temporal_push tpc;
        rad_glsl_mb_apply_push mpc;
        const float *B_gpu = (const float *)bB[(f + 1) & 1u].map, *L_gpu = (const float *)bL.map;
        memset(&tpc, 0, sizeof(tpc));
        tpc.seed = topt.seed;
        tpc.frame = f;
        tpc.row_offset = 0;
        tpc.row_count = n;
        tpc.n = n;
        tpc.samples = samples;
        tpc.words = (uint32_t)tables.format;
        tpc.flags = RAD_GLSL_TEMPORAL_ALBEDO | RAD_GLSL_TEMPORAL_FEEDBACK;
        tpc.channel = 3;
        tpc.weight = topt.weight;
        memset(&mpc, 0, sizeof(mpc));
        mpc.n = n;
        mpc.row_count = n;
        memset(&bi, 0, sizeof(bi));
        bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
        bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        CHECK_VK(vkBeginCommandBuffer(cb, &bi));
        /* the previous frame's B (and the host's writes of E) visible to this frame: needed as
           soon as frames are not waited on one by one as they are here */
        memset(&bar, 0, sizeof(bar));
        bar.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
        bar.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_HOST_WRITE_BIT;
        bar.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
        vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_HOST_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                             0, 1, &bar, 0, NULL, 0, NULL);
        record(cb, &kt[f & 1u], &tpc, (n + local_size - 1) / local_size); /* reads B[f & 1], writes B[(f + 1) & 1] */
        record(cb, &km, &mpc, n);                  /* L_inf = F_mb E (E could change every frame) */
        memset(&bar, 0, sizeof(bar));
        bar.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
        bar.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
        bar.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
        vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &bar, 0, NULL, 0, NULL);
        CHECK_VK(vkEndCommandBuffer(cb));
        memset(&sub, 0, sizeof(sub));
        sub.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
        sub.commandBufferCount = 1;
        sub.pCommandBuffers = &cb;
        CHECK_VK(vkQueueSubmit(g.queue, 1, &sub, VK_NULL_HANDLE));
        CHECK_VK(vkQueueWaitIdle(g.queue));
        /* 5. the same frame on the CPU: the same draws, so the same numbers to float rounding */
        CHECK_RAD(rad_temporal_step(cpu, (const float *)sE->data, NULL, B_cpu));
        for (i = 0; i < 3 * n; ++i) {
            double d = fabs((double)B_gpu[i] - B_cpu[i]) / (fabs(B_cpu[i]) > 1e-6 ? fabs(B_cpu[i]) : 1e-6);
            if (d > worst_gpu_cpu) worst_gpu_cpu = d;
        }
        if (f == 0 || (f + 1) % 50 == 0 || f + 1 == frames) {
            double num = 0.0, den = 0.0;
            for (i = 0; i < 3 * n; ++i) { num += fabs((double)B_gpu[i] - L_gpu[i]); den += fabs((double)L_gpu[i]); }
            printf("frame %4u: temporal estimate vs L_inf = F_mb E: mean relative difference %.4f\n", f + 1, den > 0 ? num / den : 0.0);
        }
    }
    CHECK_RAD(rad_multibounce_apply(mb, (const float *)sE->data, L_cpu, RAD_OUTPUT_INDIRECT, NULL));
    {
        double worst_l = 0.0;
        for (i = 0; i < 3 * n; ++i) {
            double d = fabs((double)((const float *)bL.map)[i] - L_cpu[i]) / (fabs(L_cpu[i]) > 1e-6 ? fabs(L_cpu[i]) : 1e-6);
            if (d > worst_l) worst_l = d;
        }
        printf("GPU vs CPU: temporal frames %.2g, multi-bounce apply %.2g (largest relative difference)\n", worst_gpu_cpu, worst_l);
        if (worst_l > 1e-5) worst_gpu_cpu = worst_l > worst_gpu_cpu ? worst_l : worst_gpu_cpu;
    }

    vkFreeCommandBuffers(g.device, g.pool, 1, &cb);
    kernel_destroy(&g, &kt[0]); kernel_destroy(&g, &kt[1]); kernel_destroy(&g, &km);
    buffer_destroy(&g, &bOff); buffer_destroy(&g, &bBins); buffer_destroy(&g, &bTot); buffer_destroy(&g, &bE);
    buffer_destroy(&g, &bAlb); buffer_destroy(&g, &bB[0]); buffer_destroy(&g, &bB[1]); buffer_destroy(&g, &bPerm);
    buffer_destroy(&g, &bL);
    for (i = 0; i < 3; ++i) buffer_destroy(&g, &bPlanes[i]);
    vkDestroyCommandPool(g.device, g.pool, NULL);
    vkDestroyDevice(g.device, NULL);
    vkDestroyInstance(g.instance, NULL);
    rad_temporal_destroy(cpu);
    rad_multibounce_destroy(mb);
    rad_container_destroy(ct);
    free(bytes); free(L_cpu); free(B_cpu);
    return worst_gpu_cpu <= 1e-5 ? 0 : 1;
}

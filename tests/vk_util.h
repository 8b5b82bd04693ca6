/* vk_util.h - the small headless Vulkan compute layer of tests/test_vulkan.c: instance, device,
   host-visible buffers, kernels compiled from the HEADER's GLSL (rad_glsl_source, so the tests
   check what users get) by glslangValidator, dispatch and wait. Compute only, Vulkan 1.1.
   Include after radiosity.h. Every failure prints what failed and returns 0 / NULL. */
#ifndef RAD_VK_UTIL_H
#define RAD_VK_UTIL_H
#include <vulkan/vulkan.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* pipelines created per kernel id (test_vulkan checks that every kernel ran) */
static unsigned vk_created[64];

/* messages of the Khronos validation layer (enabled when installed: vulkan-validationlayers) */
static unsigned vk_validation_errors;

static VKAPI_ATTR VkBool32 VKAPI_CALL vk_on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT type,
                                                   const VkDebugUtilsMessengerCallbackDataEXT *data, void *user)
{
    (void)type;
    (void)user;
    if (severity & (VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT)) {
        printf("    vulkan validation %s: %s\n", (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) ? "error" : "warning",
               data && data->pMessage ? data->pMessage : "?");
        vk_validation_errors++;
    }
    return VK_FALSE;
}

typedef struct vk_ctx {
    int validation;      /* the Khronos validation layer is on */
    VkDebugUtilsMessengerEXT messenger;
    VkInstance instance;
    VkPhysicalDevice phys;
    VkDevice device;
    VkQueue queue;
    uint32_t family;
    VkCommandPool pool;
    VkPhysicalDeviceProperties props;
    VkPhysicalDeviceMemoryProperties mem;
    int bc;              /* textureCompressionBC enabled */
    int fp64;            /* shaderFloat64 enabled */
    VkSampler sampler;   /* nearest, for texelFetch */
    char workdir[512];   /* where .comp and .spv files go */
} vk_ctx;

typedef struct vk_buf {
    VkBuffer buffer;
    VkDeviceMemory memory;
    VkDeviceSize size;
    void *map;
} vk_buf;

typedef struct vk_kernel {
    VkShaderModule module;
    VkDescriptorSetLayout set_layout;
    VkPipelineLayout layout;
    VkPipeline pipeline;
    uint32_t images, bindings, push_size, local_size; /* bindings 0..images-1 are combined image samplers */
    int group_per_row;   /* gathers and applies: one workgroup per row; else one invocation per row */
} vk_kernel;

typedef struct vk_image {
    VkImage image;
    VkDeviceMemory memory;
    VkImageView view;
} vk_image;

/* one binding: a buffer range */
typedef struct vk_range { const vk_buf *buf; VkDeviceSize offset, range; } vk_range;

#define VK_TRY(expr)                                                                                 \
    do {                                                                                             \
        VkResult vr_ = (expr);                                                                       \
        if (vr_ != VK_SUCCESS) { printf("    vulkan: %s failed (%d) at %s:%d\n", #expr, (int)vr_, __FILE__, __LINE__); return 0; } \
    } while (0)

static int vk_init(vk_ctx *v, const char *workdir)
{
    VkApplicationInfo app;
    VkInstanceCreateInfo ici;
    VkPhysicalDevice devs[16];
    uint32_t ndev = 16, d;
    float prio = 1.0f;
    VkDeviceQueueCreateInfo qci;
    VkDeviceCreateInfo dci;
    VkCommandPoolCreateInfo pci;
    VkPhysicalDeviceFeatures have, want;
    VkSamplerCreateInfo sci;
    memset(v, 0, sizeof(*v));
    snprintf(v->workdir, sizeof(v->workdir), "%s", workdir);
    memset(&app, 0, sizeof(app));
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.pApplicationName = "radiosity.h tests";
    app.apiVersion = VK_API_VERSION_1_1;
    memset(&ici, 0, sizeof(ici));
    ici.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    ici.pApplicationInfo = &app;
    {
        /* the validation layer when it is installed (RAD_VK_VALIDATION=0 turns it off) */
        VkLayerProperties layers[64];
        uint32_t nl = 64, l;
        const char *env = getenv("RAD_VK_VALIDATION");
        static const char *const layer_name[1] = { "VK_LAYER_KHRONOS_validation" };
        static const char *const ext_name[1] = { VK_EXT_DEBUG_UTILS_EXTENSION_NAME };
        if (!(env && env[0] == '0') && vkEnumerateInstanceLayerProperties(&nl, layers) >= 0)
            for (l = 0; l < nl; ++l)
                if (!strcmp(layers[l].layerName, layer_name[0])) v->validation = 1;
        if (v->validation) {
            ici.enabledLayerCount = 1;
            ici.ppEnabledLayerNames = layer_name;
            ici.enabledExtensionCount = 1;
            ici.ppEnabledExtensionNames = ext_name;
        }
    }
    VK_TRY(vkCreateInstance(&ici, NULL, &v->instance));
    if (v->validation) {
        VkDebugUtilsMessengerCreateInfoEXT mci;
        PFN_vkCreateDebugUtilsMessengerEXT create =
            (PFN_vkCreateDebugUtilsMessengerEXT)vkGetInstanceProcAddr(v->instance, "vkCreateDebugUtilsMessengerEXT");
        memset(&mci, 0, sizeof(mci));
        mci.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
        mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT;
        mci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                          VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
        mci.pfnUserCallback = vk_on_message;
        if (!create) { printf("    vulkan: no vkCreateDebugUtilsMessengerEXT\n"); return 0; }
        VK_TRY(create(v->instance, &mci, NULL, &v->messenger));
    }
    if (vkEnumeratePhysicalDevices(v->instance, &ndev, devs) < 0 || ndev == 0) { printf("    vulkan: no physical device\n"); return 0; }
    v->family = 0xFFFFFFFFu;
    for (d = 0; d < ndev && v->family == 0xFFFFFFFFu; ++d) {
        VkQueueFamilyProperties fam[16];
        uint32_t nf = 16, f;
        vkGetPhysicalDeviceQueueFamilyProperties(devs[d], &nf, fam);
        for (f = 0; f < nf; ++f)
            if (fam[f].queueFlags & VK_QUEUE_COMPUTE_BIT) { v->phys = devs[d]; v->family = f; break; }
    }
    if (v->family == 0xFFFFFFFFu) { printf("    vulkan: no compute queue\n"); return 0; }
    vkGetPhysicalDeviceProperties(v->phys, &v->props);
    vkGetPhysicalDeviceMemoryProperties(v->phys, &v->mem);
    memset(&qci, 0, sizeof(qci));
    qci.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    qci.queueFamilyIndex = v->family;
    qci.queueCount = 1;
    qci.pQueuePriorities = &prio;
    vkGetPhysicalDeviceFeatures(v->phys, &have);
    memset(&want, 0, sizeof(want));
    want.textureCompressionBC = have.textureCompressionBC;
    want.shaderFloat64 = have.shaderFloat64;
    v->bc = have.textureCompressionBC == VK_TRUE;
    v->fp64 = have.shaderFloat64 == VK_TRUE;
    memset(&dci, 0, sizeof(dci));
    dci.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    dci.pEnabledFeatures = &want;
    VK_TRY(vkCreateDevice(v->phys, &dci, NULL, &v->device));
    memset(&sci, 0, sizeof(sci));
    sci.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO;
    sci.magFilter = VK_FILTER_NEAREST;
    sci.minFilter = VK_FILTER_NEAREST;
    sci.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
    sci.addressModeU = sci.addressModeV = sci.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    VK_TRY(vkCreateSampler(v->device, &sci, NULL, &v->sampler));
    vkGetDeviceQueue(v->device, v->family, 0, &v->queue);
    memset(&pci, 0, sizeof(pci));
    pci.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pci.queueFamilyIndex = v->family;
    VK_TRY(vkCreateCommandPool(v->device, &pci, NULL, &v->pool));
    return 1;
}

static void vk_shutdown(vk_ctx *v)
{
    if (v->device) {
        if (v->sampler) vkDestroySampler(v->device, v->sampler, NULL);
        vkDestroyCommandPool(v->device, v->pool, NULL);
        vkDestroyDevice(v->device, NULL);
    }
    if (v->messenger) {
        PFN_vkDestroyDebugUtilsMessengerEXT destroy =
            (PFN_vkDestroyDebugUtilsMessengerEXT)vkGetInstanceProcAddr(v->instance, "vkDestroyDebugUtilsMessengerEXT");
        if (destroy) destroy(v->instance, v->messenger, NULL);
    }
    if (v->instance) vkDestroyInstance(v->instance, NULL);
}

/* a host-visible, coherent storage buffer of 'size' bytes, mapped; 'data' (optional) copied in */
static int vk_buffer(vk_ctx *v, vk_buf *b, VkDeviceSize size, const void *data)
{
    VkBufferCreateInfo bci;
    VkMemoryRequirements req;
    VkMemoryAllocateInfo mai;
    uint32_t t;
    VkMemoryPropertyFlags want = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    VkDeviceSize alloc = (size + 3) / 4 * 4; /* whole 32-bit words: the kernels read uint words */
    memset(b, 0, sizeof(*b));
    if (alloc == 0) alloc = 4;
    memset(&bci, 0, sizeof(bci));
    bci.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    bci.size = alloc;
    bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    VK_TRY(vkCreateBuffer(v->device, &bci, NULL, &b->buffer));
    vkGetBufferMemoryRequirements(v->device, b->buffer, &req);
    memset(&mai, 0, sizeof(mai));
    mai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = 0xFFFFFFFFu;
    for (t = 0; t < v->mem.memoryTypeCount; ++t)
        if ((req.memoryTypeBits & (1u << t)) && (v->mem.memoryTypes[t].propertyFlags & want) == want) { mai.memoryTypeIndex = t; break; }
    if (mai.memoryTypeIndex == 0xFFFFFFFFu) { printf("    vulkan: no host-visible coherent memory\n"); return 0; }
    VK_TRY(vkAllocateMemory(v->device, &mai, NULL, &b->memory));
    VK_TRY(vkBindBufferMemory(v->device, b->buffer, b->memory, 0));
    VK_TRY(vkMapMemory(v->device, b->memory, 0, VK_WHOLE_SIZE, 0, &b->map));
    b->size = alloc;
    memset(b->map, 0, (size_t)alloc);
    if (data) memcpy(b->map, data, (size_t)size);
    return 1;
}

static void vk_buffer_free(vk_ctx *v, vk_buf *b)
{
    if (b->buffer) vkDestroyBuffer(v->device, b->buffer, NULL);
    if (b->memory) vkFreeMemory(v->device, b->memory, NULL);
    memset(b, 0, sizeof(*b));
}

/* SPIR-V of kernel 'id' of the header, compiled by glslangValidator; *words receives the size in words */
static uint32_t *vk_compile(vk_ctx *v, rad_glsl_id id, size_t *words)
{
    char comp[600], spv[700], cmd[2400];
    size_t len = 0, got;
    char *src;
    FILE *f;
    uint32_t *code;
    long n;
    if (rad_glsl_source(id, NULL, 0, &len) != RAD_SUCCESS) return NULL;
    src = (char *)malloc(len + 1);
    if (!src || rad_glsl_source(id, src, len + 1, NULL) != RAD_SUCCESS) { free(src); return NULL; }
    snprintf(comp, sizeof(comp), "%s/%s", v->workdir, rad_glsl_name(id));
    snprintf(spv, sizeof(spv), "%s.spv", comp);
    f = fopen(comp, "wb");
    if (!f) { printf("    cannot write %s\n", comp); free(src); return NULL; }
    got = fwrite(src, 1, len, f);
    fclose(f);
    free(src);
    if (got != len) return NULL;
    snprintf(cmd, sizeof(cmd), "glslangValidator -V --target-env vulkan1.1 -o '%s' '%s' > '%s.log' 2>&1", spv, comp, comp);
    if (system(cmd) != 0) {
        printf("    glslangValidator failed on the embedded %s (see %s.log)\n", rad_glsl_name(id), comp);
        return NULL;
    }
    f = fopen(spv, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    n = ftell(f);
    fseek(f, 0, SEEK_SET);
    code = (uint32_t *)malloc((size_t)n + 4);
    if (!code || n <= 0 || n % 4 || fread(code, 1, (size_t)n, f) != (size_t)n) { fclose(f); free(code); return NULL; }
    fclose(f);
    *words = (size_t)n / 4;
    return code;
}

/* a compute pipeline for kernel 'id' with 'bindings' storage buffers (0..bindings-1), a push
   block of push_size bytes and the workgroup size given by specialization constant 0 */
static int vk_kernel_create(vk_ctx *v, vk_kernel *k, rad_glsl_id id, uint32_t images, uint32_t bindings, uint32_t push_size,
                            uint32_t local_size)
{
    size_t words = 0;
    uint32_t *code = vk_compile(v, id, &words), b;
    VkShaderModuleCreateInfo smci;
    VkDescriptorSetLayoutBinding lb[16];
    VkDescriptorSetLayoutCreateInfo dlci;
    VkPushConstantRange pcr;
    VkPipelineLayoutCreateInfo plci;
    VkSpecializationMapEntry me;
    VkSpecializationInfo si;
    VkComputePipelineCreateInfo cpci;
    VkResult r;
    memset(k, 0, sizeof(*k));
    if (!code) return 0;
    memset(&smci, 0, sizeof(smci));
    smci.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    smci.codeSize = words * 4;
    smci.pCode = code;
    r = vkCreateShaderModule(v->device, &smci, NULL, &k->module);
    free(code);
    VK_TRY(r);
    memset(lb, 0, sizeof(lb));
    for (b = 0; b < bindings; ++b) {
        lb[b].binding = b;
        lb[b].descriptorType = b < images ? VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        lb[b].descriptorCount = 1;
        lb[b].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    }
    memset(&dlci, 0, sizeof(dlci));
    dlci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    dlci.bindingCount = bindings;
    dlci.pBindings = lb;
    VK_TRY(vkCreateDescriptorSetLayout(v->device, &dlci, NULL, &k->set_layout));
    pcr.stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    pcr.offset = 0;
    pcr.size = push_size;
    memset(&plci, 0, sizeof(plci));
    plci.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    plci.setLayoutCount = 1;
    plci.pSetLayouts = &k->set_layout;
    plci.pushConstantRangeCount = 1;
    plci.pPushConstantRanges = &pcr;
    VK_TRY(vkCreatePipelineLayout(v->device, &plci, NULL, &k->layout));
    me.constantID = RAD_GLSL_SPEC_LOCAL_SIZE;
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
    cpci.stage.module = k->module;
    cpci.stage.pName = "main";
    cpci.stage.pSpecializationInfo = &si;
    cpci.layout = k->layout;
    VK_TRY(vkCreateComputePipelines(v->device, VK_NULL_HANDLE, 1, &cpci, NULL, &k->pipeline));
    if ((unsigned)id < 64u) vk_created[id]++;
    k->images = images;
    k->group_per_row = id == RAD_GLSL_GATHER_DENSE || id == RAD_GLSL_GATHER_CSR || id == RAD_GLSL_MB_APPLY_FLOAT ||
                       id == RAD_GLSL_MB_APPLY_HALF || id == RAD_GLSL_MB_APPLY_BLOCKS || id == RAD_GLSL_LOCAL_APPLY ||
                       id == RAD_GLSL_LOCAL_UPDATE;
    k->bindings = bindings;
    k->push_size = push_size;
    k->local_size = local_size;
    return 1;
}

static void vk_kernel_destroy(vk_ctx *v, vk_kernel *k)
{
    if (k->pipeline) vkDestroyPipeline(v->device, k->pipeline, NULL);
    if (k->layout) vkDestroyPipelineLayout(v->device, k->layout, NULL);
    if (k->set_layout) vkDestroyDescriptorSetLayout(v->device, k->set_layout, NULL);
    if (k->module) vkDestroyShaderModule(v->device, k->module, NULL);
    memset(k, 0, sizeof(*k));
}

/* runs k over 'rows' invocations with the given bindings and push data, and waits */
static int vk_dispatch_images(vk_ctx *v, const vk_kernel *k, const VkImageView *views, const vk_range *ranges, const void *push,
                              uint32_t rows)
{
    VkDescriptorPoolSize ps[2];
    VkDescriptorImageInfo ii[16];
    VkDescriptorPoolCreateInfo dpci;
    VkDescriptorPool dpool;
    VkDescriptorSetAllocateInfo dsai;
    VkDescriptorSet set;
    VkDescriptorBufferInfo bi[16];
    VkWriteDescriptorSet w[16];
    VkCommandBufferAllocateInfo cbai;
    VkCommandBuffer cb;
    VkCommandBufferBeginInfo cbbi;
    VkSubmitInfo sub;
    VkFenceCreateInfo fci;
    VkFence fence;
    uint32_t b;
    ps[0].type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    ps[0].descriptorCount = k->bindings;
    ps[1].type = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    ps[1].descriptorCount = k->images ? k->images : 1;
    memset(&dpci, 0, sizeof(dpci));
    dpci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
    dpci.maxSets = 1;
    dpci.poolSizeCount = 2;
    dpci.pPoolSizes = ps;
    VK_TRY(vkCreateDescriptorPool(v->device, &dpci, NULL, &dpool));
    memset(&dsai, 0, sizeof(dsai));
    dsai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
    dsai.descriptorPool = dpool;
    dsai.descriptorSetCount = 1;
    dsai.pSetLayouts = &k->set_layout;
    VK_TRY(vkAllocateDescriptorSets(v->device, &dsai, &set));
    memset(w, 0, sizeof(w));
    for (b = 0; b < k->bindings; ++b) {
        w[b].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        w[b].dstSet = set;
        w[b].dstBinding = b;
        w[b].descriptorCount = 1;
        if (b < k->images) {
            ii[b].sampler = v->sampler;
            ii[b].imageView = views[b];
            ii[b].imageLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
            w[b].descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
            w[b].pImageInfo = &ii[b];
            continue;
        }
        bi[b].buffer = ranges[b].buf->buffer;
        bi[b].offset = ranges[b].offset;
        bi[b].range = ranges[b].range ? ranges[b].range : VK_WHOLE_SIZE;
        w[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        w[b].pBufferInfo = &bi[b];
    }
    vkUpdateDescriptorSets(v->device, k->bindings, w, 0, NULL);
    memset(&cbai, 0, sizeof(cbai));
    cbai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    cbai.commandPool = v->pool;
    cbai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cbai.commandBufferCount = 1;
    VK_TRY(vkAllocateCommandBuffers(v->device, &cbai, &cb));
    memset(&cbbi, 0, sizeof(cbbi));
    cbbi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    cbbi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VK_TRY(vkBeginCommandBuffer(cb, &cbbi));
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, k->pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, k->layout, 0, 1, &set, 0, NULL);
    vkCmdPushConstants(cb, k->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, k->push_size, push);
    vkCmdDispatch(cb, k->group_per_row ? rows : (rows + k->local_size - 1) / k->local_size, 1, 1);
    VK_TRY(vkEndCommandBuffer(cb));
    memset(&fci, 0, sizeof(fci));
    fci.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    VK_TRY(vkCreateFence(v->device, &fci, NULL, &fence));
    memset(&sub, 0, sizeof(sub));
    sub.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    sub.commandBufferCount = 1;
    sub.pCommandBuffers = &cb;
    VK_TRY(vkQueueSubmit(v->queue, 1, &sub, fence));
    VK_TRY(vkWaitForFences(v->device, 1, &fence, VK_TRUE, UINT64_MAX));
    vkDestroyFence(v->device, fence, NULL);
    vkFreeCommandBuffers(v->device, v->pool, 1, &cb);
    vkDestroyDescriptorPool(v->device, dpool, NULL);
    return 1;
}

static int vk_dispatch(vk_ctx *v, const vk_kernel *k, const vk_range *ranges, const void *push, uint32_t rows)
{
    return vk_dispatch_images(v, k, NULL, ranges, push, rows);
}

/* one-time command buffer: begin / submit and wait */
static VkCommandBuffer vk_begin(vk_ctx *v)
{
    VkCommandBufferAllocateInfo cbai;
    VkCommandBufferBeginInfo cbbi;
    VkCommandBuffer cb = VK_NULL_HANDLE;
    memset(&cbai, 0, sizeof(cbai));
    cbai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    cbai.commandPool = v->pool;
    cbai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cbai.commandBufferCount = 1;
    if (vkAllocateCommandBuffers(v->device, &cbai, &cb) != VK_SUCCESS) return VK_NULL_HANDLE;
    memset(&cbbi, 0, sizeof(cbbi));
    cbbi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    cbbi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    vkBeginCommandBuffer(cb, &cbbi);
    return cb;
}

static int vk_submit(vk_ctx *v, VkCommandBuffer cb)
{
    VkSubmitInfo sub;
    VK_TRY(vkEndCommandBuffer(cb));
    memset(&sub, 0, sizeof(sub));
    sub.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    sub.commandBufferCount = 1;
    sub.pCommandBuffers = &cb;
    VK_TRY(vkQueueSubmit(v->queue, 1, &sub, VK_NULL_HANDLE));
    VK_TRY(vkQueueWaitIdle(v->queue));
    vkFreeCommandBuffers(v->device, v->pool, 1, &cb);
    return 1;
}

/* a size x size sampled image of a block-compressed 'format' filled with 'bytes' (the blocks,
   row-major, as the header stores them), in SHADER_READ_ONLY_OPTIMAL layout */
static int vk_image_blocks(vk_ctx *v, vk_image *im, VkFormat format, uint32_t size, const void *bytes, size_t nbytes)
{
    VkImageCreateInfo ici;
    VkMemoryRequirements req;
    VkMemoryAllocateInfo mai;
    VkImageViewCreateInfo vci;
    VkImageMemoryBarrier bar;
    VkBufferImageCopy cp;
    VkCommandBuffer cb;
    vk_buf staging;
    uint32_t t;
    memset(im, 0, sizeof(*im));
    memset(&ici, 0, sizeof(ici));
    ici.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
    ici.imageType = VK_IMAGE_TYPE_2D;
    ici.format = format;
    ici.extent.width = size;
    ici.extent.height = size;
    ici.extent.depth = 1;
    ici.mipLevels = 1;
    ici.arrayLayers = 1;
    ici.samples = VK_SAMPLE_COUNT_1_BIT;
    ici.tiling = VK_IMAGE_TILING_OPTIMAL;
    ici.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    ici.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    VK_TRY(vkCreateImage(v->device, &ici, NULL, &im->image));
    vkGetImageMemoryRequirements(v->device, im->image, &req);
    memset(&mai, 0, sizeof(mai));
    mai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = 0xFFFFFFFFu;
    for (t = 0; t < v->mem.memoryTypeCount; ++t)
        if (req.memoryTypeBits & (1u << t)) { mai.memoryTypeIndex = t; break; }
    if (mai.memoryTypeIndex == 0xFFFFFFFFu) return 0;
    VK_TRY(vkAllocateMemory(v->device, &mai, NULL, &im->memory));
    VK_TRY(vkBindImageMemory(v->device, im->image, im->memory, 0));
    if (!vk_buffer(v, &staging, nbytes, bytes)) return 0;
    cb = vk_begin(v);
    if (!cb) { vk_buffer_free(v, &staging); return 0; }
    memset(&bar, 0, sizeof(bar));
    bar.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
    bar.srcQueueFamilyIndex = bar.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    bar.image = im->image;
    bar.subresourceRange.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
    bar.subresourceRange.levelCount = 1;
    bar.subresourceRange.layerCount = 1;
    bar.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    bar.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    bar.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, NULL, 0, NULL, 1, &bar);
    memset(&cp, 0, sizeof(cp));
    cp.imageSubresource.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
    cp.imageSubresource.layerCount = 1;
    cp.imageExtent = ici.extent;
    vkCmdCopyBufferToImage(cb, staging.buffer, im->image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &cp);
    bar.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    bar.newLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    bar.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    bar.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 0, NULL, 0, NULL, 1, &bar);
    t = (uint32_t)vk_submit(v, cb);
    vk_buffer_free(v, &staging);
    if (!t) return 0;
    memset(&vci, 0, sizeof(vci));
    vci.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
    vci.image = im->image;
    vci.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vci.format = format;
    vci.subresourceRange = bar.subresourceRange;
    VK_TRY(vkCreateImageView(v->device, &vci, NULL, &im->view));
    return 1;
}

static void vk_image_free(vk_ctx *v, vk_image *im)
{
    if (im->view) vkDestroyImageView(v->device, im->view, NULL);
    if (im->image) vkDestroyImage(v->device, im->image, NULL);
    if (im->memory) vkFreeMemory(v->device, im->memory, NULL);
    memset(im, 0, sizeof(*im));
}

/* a range of 'count' elements of 'elem' bytes starting at element 'first' of b, bound from an
   offset rounded down to minStorageBufferOffsetAlignment and ending on a whole 32-bit word (a
   range ending inside a word would make the word it shares with the last binary16 value read as
   zero under robust buffer access); *base receives the element the range starts with (what the
   kernels call base) */
static vk_range vk_chunk(const vk_ctx *v, const vk_buf *b, VkDeviceSize elem, VkDeviceSize first, VkDeviceSize count,
                         uint32_t *base)
{
    vk_range r;
    VkDeviceSize align = v->props.limits.minStorageBufferOffsetAlignment, byte = first * elem, off;
    if (align == 0) align = 1;
    off = byte / align * align;
    r.buf = b;
    r.offset = off;
    r.range = (byte + count * elem - off + 3) / 4 * 4; /* whole words: binary16 pairs share one */
    if (r.range == 0) r.range = elem;
    if (r.offset + r.range > b->size) r.range = b->size - r.offset;
    *base = (uint32_t)((byte - off) / elem);
    return r;
}

static vk_range vk_whole(const vk_buf *b)
{
    vk_range r;
    r.buf = b;
    r.offset = 0;
    r.range = 0;
    return r;
}
#endif

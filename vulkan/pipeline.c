#include "pipeline.h"

#include <assert.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <xxhash.h>

#include "array.h"
#include "log.h"

/* ---- The context's layouts and pipelines ------------------------------------------ */

/* Each keyed by an XXH3-128 of what defines it (the hash functions below):
 * a collision would need 2^64 kernels. Linear searches: a renderer makes
 * about a hundred, and a lookup costs nothing beside a compile. */
struct sb_vk_cached_layout {
    XXH128_hash_t key;
    VkDescriptorSetLayout set_layout;
    VkPipelineLayout layout;
};

struct sb_vk_cached_pipeline {
    XXH128_hash_t key;
    VkPipeline pipeline;
    bool ahead; /* compiled by sb_compute_pipelines_prepare */
    bool named; /* asked for, named (and its statistics logged) by its first caller */
};

struct sb_vk_cache {
    struct sb_vk_cached_layout *layouts;
    uint32_t layout_count, layout_capacity;
    struct sb_vk_cached_pipeline *pipelines;
    uint32_t pipeline_count, pipeline_capacity;
};

static struct sb_vk_cache *cache(struct sb_vk *vk)
{
    if (!vk->cache)
        vk->cache = calloc(1, sizeof(*vk->cache));
    return vk->cache;
}

static void hash_u64(XXH3_state_t *st, uint64_t v)
{
    XXH3_128bits_update(st, &v, sizeof(v));
}

static void hash_bytes(XXH3_state_t *st, const void *data, size_t size)
{
    hash_u64(st, size);
    if (size)
        XXH3_128bits_update(st, data, size);
}

static void hash_specialization(XXH3_state_t *st, const VkSpecializationInfo *s)
{
    uint32_t n = s ? s->mapEntryCount : 0;
    hash_u64(st, n);
    for (uint32_t i = 0; i < n; i++) {
        const VkSpecializationMapEntry *e = &s->pMapEntries[i];
        hash_u64(st, e->constantID);
        hash_u64(st, e->offset);
        hash_u64(st, e->size);
    }
    if (n)
        hash_bytes(st, s->pData, s->dataSize);
}

/* 'C' compute, 'G' graphics, 'L' layouts: no two kinds share a key. */
static XXH3_state_t *key_begin(char kind)
{
    XXH3_state_t *st = XXH3_createState();
    if (st) {
        XXH3_128bits_reset(st);
        hash_u64(st, (uint64_t)kind);
    }
    return st;
}

static XXH128_hash_t key_end(XXH3_state_t *st)
{
    XXH128_hash_t key = XXH3_128bits_digest(st);
    XXH3_freeState(st);
    return key;
}

/* The compute pipeline's key; false without the memory to hash. */
static bool compute_key(VkPipelineLayout layout, const uint32_t *spirv, size_t spirv_size,
                        const VkSpecializationInfo *specialization, XXH128_hash_t *key)
{
    XXH3_state_t *st = key_begin('C');
    if (!st)
        return false;
    /* a layout is the context's (sb_vk_layout), never destroyed: its handle names its definition */
    hash_u64(st, (uint64_t)layout);
    hash_bytes(st, spirv, spirv_size);
    hash_specialization(st, specialization);
    *key = key_end(st);
    return true;
}

static struct sb_vk_cached_pipeline *find_pipeline(struct sb_vk *vk, XXH128_hash_t key)
{
    struct sb_vk_cache *c = vk->cache;
    for (uint32_t i = 0; c && i < c->pipeline_count; i++)
        if (XXH128_isEqual(c->pipelines[i].key, key))
            return &c->pipelines[i];
    return NULL;
}

/* Keep `pipeline` under `key`; without the memory to, destroy it (NULL). */
static struct sb_vk_cached_pipeline *keep_pipeline(struct sb_vk *vk, XXH128_hash_t key, VkPipeline pipeline)
{
    struct sb_vk_cache *c = cache(vk);
    if (!c || !sb_array_grow((void **)&c->pipelines, c->pipeline_count, &c->pipeline_capacity, sizeof(*c->pipelines))) {
        vkDestroyPipeline(vk->device, pipeline, NULL);
        return NULL;
    }
    struct sb_vk_cached_pipeline *kept = &c->pipelines[c->pipeline_count++];
    *kept = (struct sb_vk_cached_pipeline){.key = key, .pipeline = pipeline};
    return kept;
}

enum sb_result sb_vk_layout(struct sb_vk *vk, const VkDescriptorSetLayoutBinding *bindings, uint32_t binding_count,
                            VkShaderStageFlags push_stages, uint32_t push_size, VkDescriptorSetLayout *set_layout,
                            VkPipelineLayout *layout)
{
    enum sb_result res = SB_OK;
    XXH3_state_t *st = key_begin('L');
    if (!st)
        return SB_ERR_NOMEM;
    hash_u64(st, binding_count);
    for (uint32_t i = 0; i < binding_count; i++) {
        const VkDescriptorSetLayoutBinding *b = &bindings[i];
        assert(!b->pImmutableSamplers && "handles, which a key of definitions cannot hold");
        hash_u64(st, b->binding);
        hash_u64(st, b->descriptorType);
        hash_u64(st, b->descriptorCount);
        hash_u64(st, b->stageFlags);
    }
    hash_u64(st, push_size ? push_stages : 0);
    hash_u64(st, push_size);
    XXH128_hash_t key = key_end(st);
    struct sb_vk_cache *c = cache(vk);
    if (!c)
        return SB_ERR_NOMEM;
    for (uint32_t i = 0; i < c->layout_count; i++)
        if (XXH128_isEqual(c->layouts[i].key, key)) {
            *set_layout = c->layouts[i].set_layout;
            *layout = c->layouts[i].layout;
            return SB_OK;
        }
    if (!sb_array_grow((void **)&c->layouts, c->layout_count, &c->layout_capacity, sizeof(*c->layouts)))
        return SB_ERR_NOMEM;
    struct sb_vk_cached_layout *kept = &c->layouts[c->layout_count];
    *kept = (struct sb_vk_cached_layout){.key = key};
    VkDescriptorSetLayoutCreateInfo set_info = {
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO,
        .bindingCount = binding_count,
        .pBindings = bindings,
    };
    VK(vkCreateDescriptorSetLayout(vk->device, &set_info, NULL, &kept->set_layout));
    VkPushConstantRange range = {.stageFlags = push_stages, .size = push_size};
    VkPipelineLayoutCreateInfo layout_info = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO,
        .setLayoutCount = 1,
        .pSetLayouts = &kept->set_layout,
        .pushConstantRangeCount = push_size ? 1 : 0,
        .pPushConstantRanges = &range,
    };
    VK(vkCreatePipelineLayout(vk->device, &layout_info, NULL, &kept->layout));
    c->layout_count++;
    *set_layout = kept->set_layout;
    *layout = kept->layout;
    return SB_OK;

cleanup:
    if (kept->set_layout)
        vkDestroyDescriptorSetLayout(vk->device, kept->set_layout, NULL);
    return res;
}

uint32_t sb_vk_pipeline_count(const struct sb_vk *vk)
{
    return vk->cache ? vk->cache->pipeline_count : 0;
}

void sb_vk_pipelines_finish(struct sb_vk *vk)
{
    struct sb_vk_cache *c = vk->cache;
    if (!c)
        return;
    for (uint32_t i = 0; i < c->pipeline_count; i++)
        vkDestroyPipeline(vk->device, c->pipelines[i].pipeline, NULL);
    for (uint32_t i = 0; i < c->layout_count; i++) {
        vkDestroyPipelineLayout(vk->device, c->layouts[i].layout, NULL);
        vkDestroyDescriptorSetLayout(vk->device, c->layouts[i].set_layout, NULL);
    }
    free(c->pipelines);
    free(c->layouts);
    free(c);
    vk->cache = NULL;
}

/* ---- Compiles --------------------------------------------------------------------- */

static enum sb_result shader_module(struct sb_vk *vk, const uint32_t *spirv, size_t size, VkShaderModule *module)
{
    enum sb_result res = SB_OK;
    VkShaderModuleCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO,
        .codeSize = size,
        .pCode = spirv,
    };
    VK(vkCreateShaderModule(vk->device, &info, NULL, module));
cleanup:
    return res;
}

/* Log what the driver says of the pipeline's code, one line per executable:
 * "NAME (EXECUTABLE): Register Count 64, ..." as it names them. */
static void log_statistics(struct sb_vk *vk, VkPipeline pipeline, const char *name)
{
    PFN_vkGetPipelineExecutablePropertiesKHR get_properties =
        (PFN_vkGetPipelineExecutablePropertiesKHR)vkGetDeviceProcAddr(vk->device,
                                                                      "vkGetPipelineExecutablePropertiesKHR");
    PFN_vkGetPipelineExecutableStatisticsKHR get_statistics =
        (PFN_vkGetPipelineExecutableStatisticsKHR)vkGetDeviceProcAddr(vk->device,
                                                                      "vkGetPipelineExecutableStatisticsKHR");
    if (!get_properties || !get_statistics)
        return;
    VkPipelineInfoKHR info = {.sType = VK_STRUCTURE_TYPE_PIPELINE_INFO_KHR, .pipeline = pipeline};
    VkPipelineExecutablePropertiesKHR executables[4];
    uint32_t n = 4;
    for (uint32_t i = 0; i < n; i++)
        executables[i] =
            (VkPipelineExecutablePropertiesKHR){.sType = VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_PROPERTIES_KHR};
    if (get_properties(vk->device, &info, &n, executables) < 0)
        return;
    for (uint32_t e = 0; e < n; e++) {
        VkPipelineExecutableInfoKHR which = {
            .sType = VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_INFO_KHR,
            .pipeline = pipeline,
            .executableIndex = e,
        };
        VkPipelineExecutableStatisticKHR stats[32];
        uint32_t count = 32;
        for (uint32_t i = 0; i < count; i++)
            stats[i] = (VkPipelineExecutableStatisticKHR){.sType = VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_STATISTIC_KHR};
        if (get_statistics(vk->device, &which, &count, stats) < 0)
            continue;
        char line[1024];
        int len = snprintf(line, sizeof(line), "%s (%s):", name, executables[e].name);
        for (uint32_t i = 0; i < count && len > 0 && (size_t)len < sizeof(line); i++) {
            const VkPipelineExecutableStatisticKHR *st = &stats[i];
            const char *sep = i ? "," : "";
            size_t room = sizeof(line) - (size_t)len;
            if (st->format == VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_BOOL32_KHR)
                len += snprintf(line + len, room, "%s %s %s", sep, st->name, st->value.b32 ? "yes" : "no");
            else if (st->format == VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_INT64_KHR)
                len += snprintf(line + len, room, "%s %s %lld", sep, st->name, (long long)st->value.i64);
            else if (st->format == VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_UINT64_KHR)
                len += snprintf(line + len, room, "%s %s %llu", sep, st->name, (unsigned long long)st->value.u64);
            else
                len += snprintf(line + len, room, "%s %s %g", sep, st->name, st->value.f64);
        }
        sb_info("%s", line);
    }
}

/* The compile alone: safe on any thread. */
static enum sb_result compile_compute(struct sb_vk *vk, VkPipelineLayout layout, const uint32_t *spirv,
                                      size_t spirv_size, const VkSpecializationInfo *specialization,
                                      VkPipeline *pipeline)
{
    VkShaderModule module = VK_NULL_HANDLE;
    *pipeline = VK_NULL_HANDLE;
    enum sb_result res = shader_module(vk, spirv, spirv_size, &module);
    if (res)
        return res;
    VkComputePipelineCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO,
        .stage =
            {
                .sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
                .stage = VK_SHADER_STAGE_COMPUTE_BIT,
                .module = module,
                .pName = "main",
                .pSpecializationInfo = specialization,
            },
        .layout = layout,
        .flags =
            VK_PIPELINE_CREATE_DISPATCH_BASE_BIT | (vk->statistics ? VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR : 0),
    };
    VK(vkCreateComputePipelines(vk->device, VK_NULL_HANDLE, 1, &info, NULL, pipeline));
cleanup:
    vkDestroyShaderModule(vk->device, module, NULL);
    return res;
}

/* Name it for its first caller; a compute pipeline's statistics logged then
 * too (only those capture them: VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR). */
static void name_pipeline(struct sb_vk *vk, struct sb_vk_cached_pipeline *kept, const char *name, bool compute)
{
    if (kept->named)
        return;
    kept->named = true;
    sb_vk_name(vk, VK_OBJECT_TYPE_PIPELINE, (uint64_t)kept->pipeline, name);
    if (compute && vk->statistics)
        log_statistics(vk, kept->pipeline, name);
}

enum sb_result sb_compute_pipeline_create(struct sb_vk *vk, VkPipelineLayout layout, const uint32_t *spirv,
                                          size_t spirv_size, const VkSpecializationInfo *specialization,
                                          const char *name, VkPipeline *pipeline)
{
    XXH128_hash_t key;
    *pipeline = VK_NULL_HANDLE;
    if (!compute_key(layout, spirv, spirv_size, specialization, &key))
        return SB_ERR_NOMEM;
    struct sb_vk_cached_pipeline *kept = find_pipeline(vk, key);
    if (!kept) {
        double t0 = sb_now_s();
        VkPipeline compiled;
        enum sb_result res = compile_compute(vk, layout, spirv, spirv_size, specialization, &compiled);
        if (res)
            return res;
        sb_debug("pipeline %s: compiled in %.1f ms", name, 1e3 * (sb_now_s() - t0));
        if (!(kept = keep_pipeline(vk, key, compiled)))
            return SB_ERR_NOMEM;
    } else if (kept->ahead && !kept->named) {
        sb_debug("pipeline %s: compiled ahead", name);
    }
    name_pipeline(vk, kept, name, true);
    *pipeline = kept->pipeline;
    return SB_OK;
}

uint32_t sb_compute_pipelines_unused(const struct sb_vk *vk)
{
    uint32_t n = 0;
    for (uint32_t i = 0; vk->cache && i < vk->cache->pipeline_count; i++)
        n += vk->cache->pipelines[i].ahead && !vk->cache->pipelines[i].named;
    return n;
}

/* Compile threads at most (a driver's compiler seldom scales further). */
#define SB_PREPARE_THREADS_MAX 32

struct prepared {
    const struct sb_compute_kernel *kernel;
    XXH128_hash_t key;
    VkPipeline pipeline;
};

struct prepare_job {
    struct sb_vk *vk;
    struct prepared *kernels;
    uint32_t count;
    atomic_uint next;
};

static void *prepare_thread(void *user)
{
    struct prepare_job *job = user;
    for (uint32_t i; (i = atomic_fetch_add(&job->next, 1)) < job->count;) {
        struct prepared *k = &job->kernels[i];
        if (compile_compute(job->vk, k->kernel->layout, k->kernel->spirv, k->kernel->spirv_size,
                            k->kernel->specialization, &k->pipeline))
            k->pipeline = VK_NULL_HANDLE; /* sb_compute_pipeline_create compiles it again */
    }
    return NULL;
}

void sb_compute_pipelines_prepare(struct sb_vk *vk, const struct sb_compute_kernel *kernels, uint32_t count,
                                  int threads)
{
    struct prepare_job job = {.vk = vk, .kernels = calloc(count ? count : 1, sizeof(*job.kernels))};
    if (!job.kernels)
        return; /* each compiles when created */
    for (uint32_t i = 0; i < count; i++) {
        XXH128_hash_t key;
        bool listed =
            !compute_key(kernels[i].layout, kernels[i].spirv, kernels[i].spirv_size, kernels[i].specialization, &key) ||
            find_pipeline(vk, key);
        for (uint32_t j = 0; j < job.count && !listed; j++)
            listed = XXH128_isEqual(job.kernels[j].key, key);
        if (!listed)
            job.kernels[job.count++] = (struct prepared){.kernel = &kernels[i], .key = key};
    }
    double t0 = sb_now_s();
    pthread_t pool[SB_PREPARE_THREADS_MAX];
    int started = 0;
    threads = threads < 1 ? 1 : threads > SB_PREPARE_THREADS_MAX ? SB_PREPARE_THREADS_MAX : threads;
    for (int t = 1; t < threads && (uint32_t)t < job.count; t++)
        if (!pthread_create(&pool[started], NULL, prepare_thread, &job))
            started++;
    prepare_thread(&job);
    for (int t = 0; t < started; t++)
        pthread_join(pool[t], NULL);
    for (uint32_t i = 0; i < job.count; i++) {
        struct sb_vk_cached_pipeline *kept =
            job.kernels[i].pipeline ? keep_pipeline(vk, job.kernels[i].key, job.kernels[i].pipeline) : NULL;
        if (kept)
            kept->ahead = true;
    }
    sb_debug("pipelines: %u kernels compiled ahead on %d threads in %.1f ms", job.count, started + 1,
             1e3 * (sb_now_s() - t0));
    free(job.kernels);
}

/* The graphics pipeline's key: every field of `p` that its create info reads. */
static bool graphics_key(const struct sb_vk *vk, const struct sb_graphics_pipeline_params *p, XXH128_hash_t *key)
{
    XXH3_state_t *st = key_begin('G');
    if (!st)
        return false;
    hash_u64(st, (uint64_t)p->layout);
    hash_bytes(st, p->vertex_spirv, p->vertex_size);
    hash_bytes(st, p->fragment_spirv, p->fragment_spirv ? p->fragment_size : 0);
    hash_specialization(st, p->fragment_spirv ? p->fragment_specialization : NULL);
    const uint64_t state[] = {
        p->color_format,  p->color_format2, p->depth_format,
        p->depth_compare, p->cull_mode,     p->depth_clamp && vk->depth_clamp,
    };
    XXH3_128bits_update(st, state, sizeof(state));
    XXH3_128bits_update(st, &p->depth_bias_constant, sizeof(p->depth_bias_constant));
    XXH3_128bits_update(st, &p->depth_bias_slope, sizeof(p->depth_bias_slope));
    *key = key_end(st);
    return true;
}

static enum sb_result compile_graphics(struct sb_vk *vk, const struct sb_graphics_pipeline_params *p,
                                       VkPipeline *pipeline)
{
    VkShaderModule modules[2] = {VK_NULL_HANDLE, VK_NULL_HANDLE};
    *pipeline = VK_NULL_HANDLE;
    enum sb_result res = shader_module(vk, p->vertex_spirv, p->vertex_size, &modules[0]);
    if (!res && p->fragment_spirv)
        res = shader_module(vk, p->fragment_spirv, p->fragment_size, &modules[1]);
    if (res)
        goto cleanup;
    VkPipelineShaderStageCreateInfo stages[2] = {
        {
            .sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
            .stage = VK_SHADER_STAGE_VERTEX_BIT,
            .module = modules[0],
            .pName = "main",
        },
        {
            .sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
            .stage = VK_SHADER_STAGE_FRAGMENT_BIT,
            .module = modules[1],
            .pName = "main",
            .pSpecializationInfo = p->fragment_specialization,
        },
    };
    VkPipelineVertexInputStateCreateInfo vertex_input = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO,
    };
    VkPipelineInputAssemblyStateCreateInfo assembly = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO,
        .topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST,
    };
    VkPipelineViewportStateCreateInfo viewport = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO,
        .viewportCount = 1,
        .scissorCount = 1,
    };
    bool bias = p->depth_bias_constant != 0.0f || p->depth_bias_slope != 0.0f;
    VkPipelineRasterizationStateCreateInfo raster = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO,
        .depthClampEnable = p->depth_clamp && vk->depth_clamp,
        .polygonMode = VK_POLYGON_MODE_FILL,
        .cullMode = p->cull_mode,
        .frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE,
        .depthBiasEnable = bias,
        .depthBiasConstantFactor = p->depth_bias_constant,
        .depthBiasSlopeFactor = p->depth_bias_slope,
        .lineWidth = 1.0f,
    };
    VkPipelineMultisampleStateCreateInfo multisample = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO,
        .rasterizationSamples = VK_SAMPLE_COUNT_1_BIT,
    };
    VkPipelineDepthStencilStateCreateInfo depth = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO,
        .depthTestEnable = VK_TRUE,
        .depthWriteEnable = VK_TRUE,
        .depthCompareOp = p->depth_compare,
    };
    const VkColorComponentFlags rgba =
        VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
    const VkPipelineColorBlendAttachmentState blend_attachments[2] = {{.colorWriteMask = rgba},
                                                                      {.colorWriteMask = rgba}};
    const VkFormat color_formats[2] = {p->color_format, p->color_format2};
    uint32_t colors = p->color_format == VK_FORMAT_UNDEFINED ? 0 : p->color_format2 == VK_FORMAT_UNDEFINED ? 1 : 2;
    VkPipelineColorBlendStateCreateInfo blend = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO,
        .attachmentCount = colors,
        .pAttachments = blend_attachments,
    };
    const VkDynamicState dynamic_states[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    VkPipelineDynamicStateCreateInfo dynamic = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO,
        .dynamicStateCount = 2,
        .pDynamicStates = dynamic_states,
    };
    VkPipelineRenderingCreateInfo rendering = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO,
        .colorAttachmentCount = colors,
        .pColorAttachmentFormats = color_formats,
        .depthAttachmentFormat = p->depth_format,
    };
    VkGraphicsPipelineCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO,
        .pNext = &rendering,
        .stageCount = p->fragment_spirv ? 2 : 1,
        .pStages = stages,
        .pVertexInputState = &vertex_input,
        .pInputAssemblyState = &assembly,
        .pViewportState = &viewport,
        .pRasterizationState = &raster,
        .pMultisampleState = &multisample,
        .pDepthStencilState = &depth,
        .pColorBlendState = &blend,
        .pDynamicState = &dynamic,
        .layout = p->layout,
    };
    VK(vkCreateGraphicsPipelines(vk->device, VK_NULL_HANDLE, 1, &info, NULL, pipeline));
cleanup:
    for (int i = 0; i < 2; i++)
        if (modules[i])
            vkDestroyShaderModule(vk->device, modules[i], NULL);
    return res;
}

enum sb_result sb_graphics_pipeline_create(struct sb_vk *vk, const struct sb_graphics_pipeline_params *params,
                                           VkPipeline *pipeline)
{
    XXH128_hash_t key;
    *pipeline = VK_NULL_HANDLE;
    if (!graphics_key(vk, params, &key))
        return SB_ERR_NOMEM;
    struct sb_vk_cached_pipeline *kept = find_pipeline(vk, key);
    if (!kept) {
        VkPipeline compiled;
        enum sb_result res = compile_graphics(vk, params, &compiled);
        if (res)
            return res;
        if (!(kept = keep_pipeline(vk, key, compiled)))
            return SB_ERR_NOMEM;
    }
    name_pipeline(vk, kept, params->name, false);
    *pipeline = kept->pipeline;
    return SB_OK;
}

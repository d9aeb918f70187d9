#include "compute.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"
#include "pipeline.h"
#include "warm_up.spv.h"

static enum sb_result buffer_create(struct sb_vk *vk, VkDeviceSize size, const char *name, bool texels,
                                    struct sb_buffer *b)
{
    enum sb_result res = SB_OK;
    memset(b, 0, sizeof(*b));
    VkBufferCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO,
        .size = size,
        .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                 VK_BUFFER_USAGE_TRANSFER_DST_BIT | (texels ? VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT : 0),
        .sharingMode = VK_SHARING_MODE_EXCLUSIVE,
    };
    if (texels && size / 16 > vk->properties.limits.maxTexelBufferElements) {
        sb_error("%s: %llu texels, over the device's %u in a texel buffer", name, (unsigned long long)(size / 16),
                 vk->properties.limits.maxTexelBufferElements);
        return SB_ERR_DEVICE_LIMIT;
    }
    VK(vkCreateBuffer(vk->device, &info, NULL, &b->buffer));
    sb_vk_name(vk, VK_OBJECT_TYPE_BUFFER, (uint64_t)b->buffer, name);
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(vk->device, b->buffer, &req);
    const VkMemoryPropertyFlags host = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    VkMemoryPropertyFlags flags = 0;
    if ((res = sb_vk_allocate(vk, &req, host, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, name, &b->memory, &flags)))
        goto cleanup;
    b->host_cached = flags & VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
    VK(vkBindBufferMemory(vk->device, b->buffer, b->memory, 0));
    VK(vkMapMemory(vk->device, b->memory, 0, VK_WHOLE_SIZE, 0, &b->mapped));
    memset(b->mapped, 0, size);
    b->size = size;
    if (texels) {
        VkBufferViewCreateInfo view = {
            .sType = VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO,
            .buffer = b->buffer,
            .format = VK_FORMAT_R32G32B32A32_SFLOAT,
            .range = size / 16 * 16,
        };
        VK(vkCreateBufferView(vk->device, &view, NULL, &b->texels));
    }
    return SB_OK;

cleanup:
    sb_buffer_destroy(vk, b);
    return res;
}

enum sb_result sb_buffer_create(struct sb_vk *vk, VkDeviceSize size, const char *name, struct sb_buffer *b)
{
    return buffer_create(vk, size, name, false, b);
}

enum sb_result sb_buffer_create_texels(struct sb_vk *vk, VkDeviceSize size, const char *name, struct sb_buffer *b)
{
    return buffer_create(vk, size, name, true, b);
}

enum sb_result sb_buffer_read(struct sb_vk *vk, const struct sb_buffer *b, void *out)
{
    return sb_buffers_read(vk, 1, &b, &out);
}

/* Where a buffer's bytes start after those before it in a staging copy. */
static VkDeviceSize staged(VkDeviceSize size)
{
    return (size + 255) & ~(VkDeviceSize)255;
}

/* Straight from the buffers' own mapping (cached, or no cached type to
 * stage through). */
static void copy_mapped(int count, const struct sb_buffer *const *buffers, void *const *outs)
{
    for (int i = 0; i < count; i++)
        memcpy(outs[i], buffers[i]->mapped, buffers[i]->size);
}

enum sb_result sb_buffers_read(struct sb_vk *vk, int count, const struct sb_buffer *const *buffers, void *const *outs)
{
    VkDeviceSize size = 0;
    bool cached = true;
    for (int i = 0; i < count; i++) {
        size += staged(buffers[i]->size);
        cached = cached && buffers[i]->host_cached;
    }
    if (cached || !size) {
        copy_mapped(count, buffers, outs);
        return SB_OK;
    }
    enum sb_result res = SB_OK;
    VkBuffer staging = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    void *mapped = NULL;
    VkBufferCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO,
        .size = size,
        .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT,
        .sharingMode = VK_SHARING_MODE_EXCLUSIVE,
    };
    VK(vkCreateBuffer(vk->device, &info, NULL, &staging));
    sb_vk_name(vk, VK_OBJECT_TYPE_BUFFER, (uint64_t)staging, "readback");
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(vk->device, staging, &req);
    VkMemoryPropertyFlags flags = 0;
    if ((res = sb_vk_allocate(vk, &req, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
                              VK_MEMORY_PROPERTY_HOST_CACHED_BIT, "readback", &memory, &flags)))
        goto cleanup;
    if (!(flags & VK_MEMORY_PROPERTY_HOST_CACHED_BIT)) {
        /* No cached type: the staging copy would be as slow to read. */
        copy_mapped(count, buffers, outs);
        goto cleanup;
    }
    VK(vkBindBufferMemory(vk->device, staging, memory, 0));
    VK(vkMapMemory(vk->device, memory, 0, VK_WHOLE_SIZE, 0, &mapped));
    if ((res = sb_vk_begin_once(vk, &cmd)))
        goto cleanup;
    VkMemoryBarrier before = {
        .sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER,
        .srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_HOST_WRITE_BIT,
        .dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT,
    };
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_HOST_BIT,
                         VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &before, 0, NULL, 0, NULL);
    VkDeviceSize at = 0;
    for (int i = 0; i < count; i++) {
        vkCmdCopyBuffer(cmd, buffers[i]->buffer, staging, 1,
                        &(VkBufferCopy){.dstOffset = at, .size = buffers[i]->size});
        at += staged(buffers[i]->size);
    }
    VkMemoryBarrier after = {
        .sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER,
        .srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT,
        .dstAccessMask = VK_ACCESS_HOST_READ_BIT,
    };
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &after, 0, NULL, 0,
                         NULL);
    if ((res = sb_vk_end_once(vk, cmd)))
        goto cleanup;
    at = 0;
    for (int i = 0; i < count; i++) {
        memcpy(outs[i], (const char *)mapped + at, buffers[i]->size);
        at += staged(buffers[i]->size);
    }

cleanup:
    if (staging)
        vkDestroyBuffer(vk->device, staging, NULL);
    if (memory)
        vkFreeMemory(vk->device, memory, NULL);
    return res;
}

void sb_buffer_destroy(struct sb_vk *vk, struct sb_buffer *b)
{
    if (b->texels)
        vkDestroyBufferView(vk->device, b->texels, NULL);
    if (b->buffer)
        vkDestroyBuffer(vk->device, b->buffer, NULL);
    if (b->memory)
        vkFreeMemory(vk->device, b->memory, NULL); /* unmaps */
    memset(b, 0, sizeof(*b));
}

static VkDescriptorType binding_type(const struct sb_pipeline_params *params, uint32_t i)
{
    return params->texel_bindings >> i & 1u ? VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER
                                            : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
}

/* A kernel's layouts: storage (or texel) buffers at bindings
 * 0..binding_count-1 and push_size bytes of push constants, the context's. */
static enum sb_result kernel_layout(struct sb_vk *vk, const struct sb_pipeline_params *params,
                                    VkDescriptorSetLayout *set_layout, VkPipelineLayout *layout)
{
    VkDescriptorSetLayoutBinding bindings[16];
    if (params->binding_count > 16)
        return SB_ERR_OUT_OF_RANGE;
    for (uint32_t i = 0; i < params->binding_count; i++)
        bindings[i] = (VkDescriptorSetLayoutBinding){
            .binding = i,
            .descriptorType = binding_type(params, i),
            .descriptorCount = 1,
            .stageFlags = VK_SHADER_STAGE_COMPUTE_BIT,
        };
    return sb_vk_layout(vk, bindings, params->binding_count, VK_SHADER_STAGE_COMPUTE_BIT, params->push_size, set_layout,
                        layout);
}

void sb_pipelines_prepare(struct sb_vk *vk, const struct sb_pipeline_params *params, uint32_t count, int threads)
{
    struct sb_compute_kernel *kernels = calloc(count ? count : 1, sizeof(*kernels));
    if (!kernels)
        return; /* each compiles when created */
    uint32_t n = 0;
    for (uint32_t i = 0; i < count; i++) {
        VkDescriptorSetLayout set_layout;
        struct sb_compute_kernel *k = &kernels[n];
        if (!kernel_layout(vk, &params[i], &set_layout, &k->layout)) {
            k->spirv = params[i].spirv;
            k->spirv_size = params[i].spirv_size;
            n++;
        }
    }
    sb_compute_pipelines_prepare(vk, kernels, n, threads);
    free(kernels);
}

enum sb_result sb_pipeline_create(struct sb_vk *vk, const struct sb_pipeline_params *params, struct sb_pipeline *p)
{
    enum sb_result res = SB_OK;
    memset(p, 0, sizeof(*p));
    p->binding_count = params->binding_count;
    p->texel_bindings = params->texel_bindings;
    p->push_size = params->push_size;
    if ((res = kernel_layout(vk, params, &p->set_layout, &p->layout)) ||
        (res = sb_compute_pipeline_create(vk, p->layout, params->spirv, params->spirv_size, NULL, params->name,
                                          &p->pipeline)))
        goto cleanup;

    VkDescriptorPoolSize pool_sizes[2] = {
        {.type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, .descriptorCount = 1},
        {.type = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, .descriptorCount = 1},
    };
    for (uint32_t i = 0; i < params->binding_count; i++)
        pool_sizes[binding_type(params, i) == VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER].descriptorCount++;
    VkDescriptorPoolCreateInfo pool_info = {
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO,
        .maxSets = 1,
        .poolSizeCount = 2,
        .pPoolSizes = pool_sizes,
    };
    VK(vkCreateDescriptorPool(vk->device, &pool_info, NULL, &p->descriptor_pool));
    VkDescriptorSetAllocateInfo set_alloc = {
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO,
        .descriptorPool = p->descriptor_pool,
        .descriptorSetCount = 1,
        .pSetLayouts = &p->set_layout,
    };
    VK(vkAllocateDescriptorSets(vk->device, &set_alloc, &p->set));
    return SB_OK;

cleanup:
    sb_pipeline_destroy(vk, p);
    return res;
}

void sb_pipeline_destroy(struct sb_vk *vk, struct sb_pipeline *p)
{
    if (p->descriptor_pool)
        vkDestroyDescriptorPool(vk->device, p->descriptor_pool, NULL);
    memset(p, 0, sizeof(*p)); /* its layouts and pipeline are the context's */
}

void sb_pipeline_bind(struct sb_vk *vk, struct sb_pipeline *p, const struct sb_buffer *const *buffers)
{
    VkDescriptorBufferInfo infos[16];
    VkWriteDescriptorSet writes[16];
    for (uint32_t i = 0; i < p->binding_count; i++) {
        bool texels = p->texel_bindings >> i & 1u;
        infos[i] = (VkDescriptorBufferInfo){.buffer = buffers[i]->buffer, .range = VK_WHOLE_SIZE};
        writes[i] = (VkWriteDescriptorSet){
            .sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
            .dstSet = p->set,
            .dstBinding = i,
            .descriptorCount = 1,
            .descriptorType = texels ? VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
            .pBufferInfo = texels ? NULL : &infos[i],
            .pTexelBufferView = texels ? &buffers[i]->texels : NULL,
        };
    }
    vkUpdateDescriptorSets(vk->device, p->binding_count, writes, 0, NULL);
}

enum sb_result sb_dispatch(struct sb_vk *vk, struct sb_pipeline *p, const void *push, uint32_t gx, uint32_t gy,
                           uint32_t gz, double *gpu_ms)
{
    static const uint32_t none[3] = {0, 0, 0};
    return sb_dispatch_base(vk, p, push, none, gx, gy, gz, gpu_ms);
}

enum sb_result sb_dispatch_base(struct sb_vk *vk, struct sb_pipeline *p, const void *push, const uint32_t base[3],
                                uint32_t gx, uint32_t gy, uint32_t gz, double *gpu_ms)
{
    enum sb_result res = SB_OK;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    VkQueryPool queries = VK_NULL_HANDLE;
    *gpu_ms = 0.0;

    if (vk->has_timestamps) {
        VkQueryPoolCreateInfo qinfo = {
            .sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO,
            .queryType = VK_QUERY_TYPE_TIMESTAMP,
            .queryCount = 2,
        };
        VK(vkCreateQueryPool(vk->device, &qinfo, NULL, &queries));
        vkResetQueryPool(vk->device, queries, 0, 2);
    }
    if ((res = sb_vk_begin_once(vk, &cmd)))
        goto cleanup;
    /* Host writes to the inputs are visible through the submission itself. */
    if (queries)
        vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, queries, 0);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p->pipeline);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p->layout, 0, 1, &p->set, 0, NULL);
    if (push && p->push_size)
        vkCmdPushConstants(cmd, p->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, p->push_size, push);
    if (base[0] || base[1] || base[2])
        vkCmdDispatchBase(cmd, base[0], base[1], base[2], gx, gy, gz);
    else
        vkCmdDispatch(cmd, gx, gy, gz);
    if (queries)
        vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries, 1);
    /* Make the shader's writes visible to the host once the fence signals. */
    VkMemoryBarrier barrier = {
        .sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER,
        .srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT,
        .dstAccessMask = VK_ACCESS_HOST_READ_BIT,
    };
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier, 0, NULL,
                         0, NULL);
    if ((res = sb_vk_end_once(vk, cmd)))
        goto cleanup;
    if (queries) {
        uint64_t ts[2];
        VK(vkGetQueryPoolResults(vk->device, queries, 0, 2, sizeof(ts), ts, sizeof(uint64_t),
                                 VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
        *gpu_ms = (double)(ts[1] - ts[0]) * vk->timestamp_period_ns * 1e-6;
    }

cleanup:
    if (queries)
        vkDestroyQueryPool(vk->device, queries, NULL);
    return res;
}

enum sb_result sb_warm_up(struct sb_vk *vk, double warm_ms)
{
    if (vk->properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU || !vk->has_timestamps)
        return SB_OK;
    enum { GROUPS = 4096 };
    struct sb_buffer out = {0};
    struct sb_pipeline pipeline = {0};
    struct sb_pipeline_params pp = {
        .spirv = sb_spv_warm_up,
        .spirv_size = sizeof(sb_spv_warm_up),
        .binding_count = 1,
        .push_size = sizeof(uint32_t),
        .name = "warm up",
    };
    enum sb_result res = sb_buffer_create(vk, GROUPS * 64 * sizeof(float), "warm up", &out);
    if (!res)
        res = sb_pipeline_create(vk, &pp, &pipeline);
    if (!res) {
        const struct sb_buffer *bindings[1] = {&out};
        sb_pipeline_bind(vk, &pipeline, bindings);
    }
    /* Dispatches of about 10 ms, their length scaled from the last one. */
    uint32_t rounds = 1024;
    double busy = 0;
    for (int n = 0; !res && busy < warm_ms && n < 256; n++) {
        double ms = 0;
        res = sb_dispatch(vk, &pipeline, &rounds, GROUPS, 1, 1, &ms);
        busy += ms;
        double scale = ms > 0 ? 10.0 / ms : 16.0;
        rounds = (uint32_t)fmin(fmax(rounds * fmin(scale, 16.0), 1.0), 1e7);
    }
    sb_pipeline_destroy(vk, &pipeline);
    sb_buffer_destroy(vk, &out);
    return res;
}

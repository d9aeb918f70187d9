/*
 * What a pass may call (renderer_internal.h): uploads, textures, kernels,
 * dispatches and draws on the pass's own set, its declarations' helpers.
 * The renderer calls the passes; the passes call this file and the graph,
 * never the renderer's frame loop.
 */
#include <assert.h>
#include <stdlib.h>
#include <string.h>

#include "image.h"
#include "log.h"
#include "pipeline.h"
#include "renderer_internal.h"

void *sb_pass_data(struct sb_renderer *r)
{
    return r->pass_data[r->pass];
}

void sb_pass_set_data(struct sb_renderer *r, void *data)
{
    r->pass_data[r->pass] = data;
}

sb_resource sb_pass_find(struct sb_renderer *r, const char *name)
{
    sb_resource id = sb_graph_find(r, name);
    if (!id)
        sb_error("the %s pass uses \"%s\", which no earlier pass made", r->pass_name, name);
    assert(id);
    return id;
}

void sb_pass_read_atmosphere(struct sb_renderer *r)
{
    sb_pass_use(r, SB_BINDING_ATMOSPHERE, sb_pass_find(r, "atmosphere"), SB_USE_LOAD);
    /* read by texelFetch (atmosphere.glsl, SB_ATMOSPHERE_TEXTURES) */
    sb_pass_sample(r, SB_BINDING_TRANSMITTANCE, sb_pass_find(r, "transmittance"), r->nearest);
    sb_pass_sample(r, SB_BINDING_MULTISCATTERING, sb_pass_find(r, "multiscattering"), r->nearest);
    sb_pass_sample(r, SB_BINDING_IRRADIANCE_GROUND, sb_pass_find(r, "irradiance ground"), r->nearest);
    /* bilinear in mu and nu by the sampler (view.glsl's orders_sky) */
    sb_pass_sample(r, SB_VIEW_BINDING_ORDERS, sb_pass_find(r, "orders"), r->linear);
    sb_pass_use(r, SB_VIEW_BINDING_FRAME, sb_pass_find(r, "frame"), SB_USE_LOAD);
}

enum sb_result sb_renderer_upload(struct sb_renderer *r, const void *data, size_t bytes, const char *name,
                                  struct sb_buffer *buffer)
{
    enum sb_result res = sb_buffer_create(r->vk, bytes, name, buffer);
    if (!res && data)
        memcpy(buffer->mapped, data, bytes);
    return res;
}

enum sb_result sb_renderer_texture(struct sb_renderer *r, struct sb_texture *t, const uint32_t size[3], uint32_t layers,
                                   uint32_t mips, VkFormat format, VkImageUsageFlags usage, const char *name)
{
    struct sb_texture_params p = {
        .width = size[0],
        .height = size[1],
        .depth = size[2],
        .layers = layers,
        .mips = mips,
        .format = format,
        .usage = usage,
        .name = name,
    };
    return sb_texture_create(r->vk, &p, t);
}

enum sb_result sb_renderer_upload_image(struct sb_renderer *r, const struct sb_image *image, bool volume, float fill,
                                        const char *name, struct sb_texture *texture)
{
    uint32_t size[3] = {1, 1, volume ? 2 : 1}; /* a depth of 2 keeps a stand-in 3D */
    if (image) {
        size[0] = image->width;
        size[1] = image->height;
        size[2] = image->depth ? image->depth : 1;
    }
    size_t texels = (size_t)size[0] * size[1] * size[2];
    uint16_t *data = malloc(texels * 4 * sizeof(uint16_t));
    if (!data)
        return SB_ERR_NOMEM;
    for (size_t i = 0; i < texels; i++)
        for (uint32_t c = 0; c < 4; c++) {
            float v = image && c < image->channel_count ? image->data[i * image->channel_count + c] : fill;
            data[4 * i + c] = sb_half_from_float(v);
        }
    enum sb_result res = sb_renderer_texture(r, texture, size, 1, 1, VK_FORMAT_R16G16B16A16_SFLOAT,
                                             VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, name);
    if (!res)
        res = sb_texture_upload(r->vk, texture, data, texels * 4 * sizeof(uint16_t), 4 * sizeof(uint16_t));
    free(data);
    return res;
}

enum sb_result sb_renderer_kernel(struct sb_renderer *r, const uint32_t *spirv, size_t spirv_size, const char *name,
                                  VkPipeline *pipeline)
{
    VkPipelineLayout layout;
    enum sb_result res = sb_pass_layout(r, &layout);
    return res ? res : sb_compute_pipeline_create(r->vk, layout, spirv, spirv_size, &r->specialization, name, pipeline);
}

void sb_renderer_release(struct sb_renderer *r, struct sb_texture *const *textures, size_t texture_count)
{
    for (size_t i = 0; i < texture_count; i++)
        sb_texture_destroy(r->vk, textures[i]);
}

void sb_renderer_dispatch_set(struct sb_renderer *r, uint32_t set, VkPipeline pipeline, const struct sb_view_push *push,
                              const uint32_t size[3], const uint32_t group[3])
{
    const struct sb_graph_pass *p = &r->graph.passes[r->pass];
    struct sb_view_push none = {0};
    assert(set < p->set_count);
    vkCmdBindPipeline(r->cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
    vkCmdBindDescriptorSets(r->cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p->layout, 0, 1, &p->sets[set], 0, NULL);
    vkCmdPushConstants(r->cmd, p->layout, VK_SHADER_STAGE_ALL, 0, sizeof(none), push ? push : &none);
    vkCmdDispatch(r->cmd, (size[0] + group[0] - 1) / group[0], (size[1] + group[1] - 1) / group[1],
                  (size[2] + group[2] - 1) / group[2]);
}

void sb_renderer_dispatch(struct sb_renderer *r, VkPipeline pipeline, const struct sb_view_push *push,
                          const uint32_t size[3], const uint32_t group[3])
{
    sb_renderer_dispatch_set(r, 0, pipeline, push, size, group);
}

void sb_renderer_dispatch_frame(struct sb_renderer *r, VkPipeline pipeline)
{
    sb_renderer_dispatch(r, pipeline, NULL, (const uint32_t[3]){r->width, r->height, 1},
                         (const uint32_t[3]){SB_WORKGROUP_X, SB_WORKGROUP_Y, 1});
}

void sb_renderer_bind_graphics(struct sb_renderer *r, VkPipeline pipeline, const struct sb_view_push *push)
{
    const struct sb_graph_pass *p = &r->graph.passes[r->pass];
    struct sb_view_push none = {0};
    vkCmdBindPipeline(r->cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
    vkCmdBindDescriptorSets(r->cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, p->layout, 0, 1, &p->sets[0], 0, NULL);
    vkCmdPushConstants(r->cmd, p->layout, VK_SHADER_STAGE_ALL, 0, sizeof(none), push ? push : &none);
}

void sb_renderer_viewport(struct sb_renderer *r, uint32_t width, uint32_t height)
{
    VkViewport viewport = {0.0f, 0.0f, (float)width, (float)height, 0.0f, 1.0f};
    VkRect2D scissor = {{0, 0}, {width, height}};
    vkCmdSetViewport(r->cmd, 0, 1, &viewport);
    vkCmdSetScissor(r->cmd, 0, 1, &scissor);
}

enum sb_result sb_pass_frame_kernel(struct sb_renderer *r, const uint32_t *spirv, size_t spirv_size, const char *name)
{
    VkPipeline *kernel = calloc(1, sizeof(*kernel));
    if (!kernel)
        return SB_ERR_NOMEM;
    sb_pass_set_data(r, kernel);
    return sb_renderer_kernel(r, spirv, spirv_size, name, kernel);
}

void sb_pass_frame_kernel_destroy(struct sb_renderer *r)
{
    free(sb_pass_data(r)); /* its kernel is the context's */
}

void sb_pass_frame_kernel_record(struct sb_renderer *r)
{
    VkPipeline *kernel = sb_pass_data(r);
    if (kernel)
        sb_renderer_dispatch_frame(r, *kernel);
}

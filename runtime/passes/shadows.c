/*
 * The sun's cascaded shadow maps (runtime/shadows.h has their fitting): the
 * casters drawn into SB_CASCADES layers of depth, each cleared and drawn
 * only where casters project (and a margin that covers what the lookups
 * read), then the far map past the last cascade, every caster over the
 * world, into one more layer; which the scene and the fog sample; "shadow
 * cascades" in the graph's table. A traced scene casts shadow rays instead, and this pass
 * has nothing to do.
 */
#include <stdlib.h>

#include "pipeline.h"
#include "renderer_internal.h"

#include "shadow_vert.spv.h"
#include "shadow_vert_instanced.spv.h"

/* The cascades' depth: 16 bits resolve 1 cm over the largest cascade's
 * depth range (two radii of 238 m and the 200 m caster margin), far under
 * its 23 cm texels, and halve what the H100's 8 ROPs clear and write
 * (0.61 ms to 0.37 at 1080p, the test world). */
#define SHADOW_FORMAT VK_FORMAT_D16_UNORM

struct shadows {
    struct sb_texture maps;
    VkPipeline pipeline;
};

static enum sb_result shadows_create(struct sb_renderer *r)
{
    if (r->scene_traced) /* shadow rays instead */
        return SB_OK;
    struct shadows *s = calloc(1, sizeof(*s));
    if (!s)
        return SB_ERR_NOMEM;
    sb_pass_set_data(r, s);
    uint32_t n = r->params.shadow_size;
    enum sb_result res = sb_renderer_texture(
        r, &s->maps, (const uint32_t[3]){n, n, 1}, SB_CASCADES + 1, 1, SHADOW_FORMAT,
        VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT, "shadow cascades");
    if (res)
        return res;
    sb_pass_use(r, SB_VIEW_BINDING_FRAME, sb_pass_find(r, "frame"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_VERTICES, sb_pass_find(r, "vertices"), SB_USE_LOAD);
    if (r->draw_group_count) {
        sb_pass_use(r, SB_VIEW_BINDING_INSTANCES, sb_pass_find(r, "instances"), SB_USE_LOAD);
        sb_pass_use(r, SB_VIEW_BINDING_VISIBLE, sb_pass_find(r, "visible instances"), SB_USE_LOAD);
    }
    sb_pass_use(r, SB_NO_BINDING, sb_graph_image(r, "shadow cascades", &s->maps), SB_USE_DEPTH_TARGET);
    struct sb_graphics_pipeline_params params = {
        .vertex_spirv = r->draw_group_count ? sb_spv_shadow_vert_instanced : sb_spv_shadow_vert,
        .vertex_size = r->draw_group_count ? sizeof(sb_spv_shadow_vert_instanced) : sizeof(sb_spv_shadow_vert),
        .depth_format = SHADOW_FORMAT,
        .depth_compare = VK_COMPARE_OP_LESS,
        .depth_clamp = true, /* casters behind the near plane still cast ("pancaking") */
        .depth_bias_constant = 1.0f,
        .depth_bias_slope = 1.5f,
        .name = "shadow cascades",
    };
    res = sb_pass_layout(r, &params.layout);
    return res ? res : sb_graphics_pipeline_create(r->vk, &params, &s->pipeline);
}

static void shadows_destroy(struct sb_renderer *r)
{
    struct shadows *s = sb_pass_data(r);
    if (!s)
        return;
    struct sb_texture *maps = &s->maps;
    sb_renderer_release(r, &maps, 1);
    free(s);
}

static void shadows_record(struct sb_renderer *r)
{
    struct shadows *s = sb_pass_data(r);
    if (!s)
        return;
    uint32_t n = r->params.shadow_size;
    sb_renderer_bind_graphics(r, s->pipeline, NULL);
    const VkPipelineLayout layout = r->graph.passes[r->pass].layout;
    for (uint32_t c = 0; c <= SB_CASCADES; c++) { /* the cascades, then the far map */
        const int32_t *clear = r->cascade_clear[c];
        if (clear[0] >= clear[2] || clear[1] >= clear[3])
            continue;
        VkRect2D area = {{clear[0], clear[1]}, {(uint32_t)(clear[2] - clear[0]), (uint32_t)(clear[3] - clear[1])}};
        VkRenderingAttachmentInfo depth = {
            .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
            .imageView = s->maps.subviews[c],
            .imageLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
            .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
            .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
            .clearValue = {.depthStencil = {1.0f, 0}},
        };
        VkRenderingInfo info = {
            .sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
            .renderArea = area,
            .layerCount = 1,
            .pDepthAttachment = &depth,
        };
        vkCmdBeginRendering(r->cmd, &info);
        sb_renderer_viewport(r, n, n);
        vkCmdSetScissor(r->cmd, 0, 1, &area);
        struct sb_view_push push = {.cascade = c};
        vkCmdPushConstants(r->cmd, layout, VK_SHADER_STAGE_ALL, 0, sizeof(push), &push);
        if (!r->draw_group_count)
            vkCmdDraw(r->cmd, r->vertex_count - r->caster_first_vertex, 1, r->caster_first_vertex, 0);
        for (uint32_t g = 0; g < r->draw_group_count; g++) { /* a mesh's casters, every instance on the map */
            const struct sb_draw_group *d = &r->draw_groups[g];
            const struct sb_visible_range *v = &r->visible_ranges[(1 + c) * r->draw_group_count + g];
            if (d->end_vertex > d->caster_first_vertex && v->count)
                vkCmdDraw(r->cmd, d->end_vertex - d->caster_first_vertex, v->count, d->caster_first_vertex, v->first);
        }
        vkCmdEndRendering(r->cmd);
    }
}

const struct sb_pass_class sb_pass_shadows = {
    .name = "shadows",
    .create = shadows_create,
    .destroy = shadows_destroy,
    .record = shadows_record,
};

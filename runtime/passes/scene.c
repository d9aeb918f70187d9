/*
 * The scene: the world lit by the sun (its shadows), the sky (the probes'
 * irradiance, or the sky's on open ground), the reflection probes and the
 * aerial perspective, into the HDR frame and its depth. Rasterised (the
 * shadows from the cascades), or traced (sb_renderer_params.scene): a ray a
 * pixel through the world's BVH (renderer.c builds it, geometry/bvh.h), the
 * hit lit as a fragment is (scene_shading.glsl), the sun's visibility from
 * a shadow ray, so the shadow pass has nothing to draw; the fog traces its
 * shadow rays too (fog_inject_traced).
 *
 * Why trace: a data-centre GPU's rasteriser is its weak part. On the H100
 * the raster scene pass took 1.98 ms at 1080p, 0.71 ms of it to rasterise
 * with a one-line fragment shader, and the cascades 0.37 ms
 * (docs/skyview.md). llvmpipe rasterises well and traces slowly, so a CPU
 * device rasterises. The traced frame differs from the raster one only in
 * its shadows (exact at every distance, the penumbra the mean of a ray a
 * frame over the light's disk, kept in the "sun visibility" history, where
 * the maps' penumbrae are estimated and end at shadow_distance_m) and in the
 * last bits of each point's position; test_runtime holds the two together
 * and the shadows to Embree.
 *
 * The reflection probes are the reflections pass's (passes/reflections.c).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "clouds_gpu.h"
#include "history.h"
#include "image.h"
#include "log.h"
#include "physics.h"
#include "pipeline.h"
#include "probes_gpu.h"
#include "reflections_gpu.h"
#include "renderer_internal.h"
#include "scene.h"
#include "sh.h"

#include "scene_frag.spv.h"
#include "scene_frag_key.spv.h"
#include "scene_frag_volume.spv.h"
#include "scene_frag_volume_key.spv.h"
#include "scene_trace.spv.h"
#include "scene_trace_instanced.spv.h"
#include "scene_trace_volume.spv.h"
#include "scene_trace_volume_instanced.spv.h"
#include "scene_vert.spv.h"
#include "scene_vert_instanced.spv.h"

struct scene {
    /* Traced: the key light's visibility over the frames (its penumbrae), and what reprojects it. */
    struct sb_texture sun_history[2];
    /* Rasterised: the key light's direct share of each pixel (scene.frag),
     * which the contact shadows take back where they find a caster. */
    struct sb_texture key_light;
    struct sb_buffer history; /* sb_scene_history_gpu */
    struct sb_history history_state;
    /* Generic, and with aerial perspective from its volume alone (aerial.glsl). */
    VkPipeline raster[2], traced[2];
};

/* The traced scene writes every pixel of the frame and its depth. */
static enum sb_result create_traced(struct sb_renderer *r, struct scene *s)
{
    enum sb_result made = SB_OK;
    for (int i = 0; i < 2 && !made; i++)
        made = sb_renderer_texture(r, &s->sun_history[i], (const uint32_t[3]){r->width, r->height, 1}, 1, 1,
                                   SB_HDR_FORMAT, VK_IMAGE_USAGE_STORAGE_BIT, "sun visibility");
    if (!made)
        made = sb_renderer_upload(r, NULL, sizeof(struct sb_scene_history_gpu), "scene history", &s->history);
    if (made)
        return made;
    sb_resource sun = sb_graph_history(r, "sun visibility", s->sun_history);
    sb_pass_use(r, SB_VIEW_BINDING_SUN_HISTORY_OUT, sun, SB_USE_OVERWRITE);
    sb_pass_use(r, SB_VIEW_BINDING_SUN_HISTORY, SB_PREVIOUS(sun), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_SCENE_HISTORY, sb_graph_buffer(r, "scene history", &s->history), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_HDR, sb_pass_find(r, "hdr"), SB_USE_OVERWRITE);
    sb_pass_use(r, SB_VIEW_BINDING_DEPTH_OUT, sb_pass_find(r, "depth"), SB_USE_OVERWRITE);
    sb_pass_use(r, SB_VIEW_BINDING_BVH_NODES, sb_pass_find(r, "bvh nodes"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_BVH_TRIANGLES, sb_pass_find(r, "bvh triangles"), SB_USE_LOAD);
    if (r->draw_group_count) { /* an instanced world: its BVH's two levels, its vertices placed */
        enum sb_result res = sb_renderer_kernel(r, sb_spv_scene_trace_instanced, sizeof(sb_spv_scene_trace_instanced),
                                                "scene traced (instances)", &s->traced[0]);
        if (!res)
            res =
                sb_renderer_kernel(r, sb_spv_scene_trace_volume_instanced, sizeof(sb_spv_scene_trace_volume_instanced),
                                   "scene traced (instances, aerial volume only)", &s->traced[1]);
        return res;
    }
    enum sb_result res =
        sb_renderer_kernel(r, sb_spv_scene_trace, sizeof(sb_spv_scene_trace), "scene traced", &s->traced[0]);
    if (!res)
        res = sb_renderer_kernel(r, sb_spv_scene_trace_volume, sizeof(sb_spv_scene_trace_volume),
                                 "scene traced (aerial volume only)", &s->traced[1]);
    return res;
}

static enum sb_result create_raster(struct sb_renderer *r, struct scene *s)
{
    /* the key light's share for the contact shadows: a second target, which
     * cost llvmpipe a fifth of the pass, so only when they are on */
    bool key = !r->params.no_contact_shadows;
    enum sb_result made =
        key ? sb_renderer_texture(r, &s->key_light, (const uint32_t[3]){r->width, r->height, 1}, 1, 1, SB_HDR_FORMAT,
                                  VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_STORAGE_BIT, "key light")
            : SB_OK;
    if (made)
        return made;
    sb_pass_sample(r, SB_VIEW_BINDING_SHADOW, sb_pass_find(r, "shadow cascades"), r->shadow_compare);
    sb_pass_sample(r, SB_VIEW_BINDING_SHADOW_DEPTH, sb_pass_find(r, "shadow cascades"), r->nearest);
    sb_pass_use(r, SB_NO_BINDING, sb_pass_find(r, "hdr"), SB_USE_COLOR_TARGET);
    if (key)
        sb_pass_use(r, SB_NO_BINDING, sb_graph_image(r, "key light", &s->key_light), SB_USE_COLOR_TARGET);
    sb_pass_use(r, SB_NO_BINDING, sb_pass_find(r, "depth"), SB_USE_DEPTH_TARGET);
    /* scene.frag's specialization: what the pack and the world hold */
    bool generic = r->params.generic_shaders;
    const VkBool32 has[6] = {generic || r->probe_count > 0,
                             generic || r->reflection_count > 0,
                             generic || r->textures.count > 0,
                             generic || r->emissive_count > 0,
                             r->constants.orders,
                             r->constants.bands};
    VkSpecializationMapEntry entries[6];
    for (uint32_t i = 0; i < 6; i++) /* the last two, every view kernel's: the orders, the bands (pass.c) */
        entries[i] = (VkSpecializationMapEntry){.constantID = i < 4    ? i
                                                              : i == 4 ? SB_VIEW_CONSTANT_ORDERS
                                                                       : SB_VIEW_CONSTANT_BANDS,
                                                .offset = i * sizeof(VkBool32),
                                                .size = sizeof(VkBool32)};
    const VkSpecializationInfo specialization = {
        .mapEntryCount = 6, .pMapEntries = entries, .dataSize = sizeof(has), .pData = has};
    struct sb_graphics_pipeline_params params = {
        .fragment_specialization = &specialization,
        .vertex_spirv = r->draw_group_count ? sb_spv_scene_vert_instanced : sb_spv_scene_vert,
        .vertex_size = r->draw_group_count ? sizeof(sb_spv_scene_vert_instanced) : sizeof(sb_spv_scene_vert),
        .fragment_spirv = key ? sb_spv_scene_frag_key : sb_spv_scene_frag,
        .fragment_size = key ? sizeof(sb_spv_scene_frag_key) : sizeof(sb_spv_scene_frag),
        .color_format = SB_HDR_FORMAT,
        .color_format2 = key ? SB_HDR_FORMAT : VK_FORMAT_UNDEFINED,
        .depth_format = SB_DEPTH_FORMAT,
        .depth_compare = VK_COMPARE_OP_GREATER, /* reverse Z */
        .name = "scene",
    };
    enum sb_result res = sb_pass_layout(r, &params.layout);
    if (!res)
        res = sb_graphics_pipeline_create(r->vk, &params, &s->raster[0]);
    params.fragment_spirv = key ? sb_spv_scene_frag_volume_key : sb_spv_scene_frag_volume;
    params.fragment_size = key ? sizeof(sb_spv_scene_frag_volume_key) : sizeof(sb_spv_scene_frag_volume);
    params.name = "scene (aerial volume only)";
    if (!res)
        res = sb_graphics_pipeline_create(r->vk, &params, &s->raster[1]);
    return res;
}

static enum sb_result scene_create(struct sb_renderer *r)
{
    struct scene *s = calloc(1, sizeof(*s));
    if (!s)
        return SB_ERR_NOMEM;
    sb_pass_set_data(r, s);
    sb_pass_read_atmosphere(r);
    sb_pass_use(r, SB_VIEW_BINDING_VERTICES, sb_pass_find(r, "vertices"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_TEXTURES, sb_pass_find(r, "texture records"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_TEXELS, sb_pass_find(r, "texels"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_EMISSIVE, sb_pass_find(r, "emissive"), SB_USE_LOAD);
    if (r->draw_group_count) {
        sb_pass_use(r, SB_VIEW_BINDING_INSTANCES, sb_pass_find(r, "instances"), SB_USE_LOAD);
        if (!r->scene_traced)
            sb_pass_use(r, SB_VIEW_BINDING_VISIBLE, sb_pass_find(r, "visible instances"), SB_USE_LOAD);
    }
    sb_pass_sample(r, SB_VIEW_BINDING_AERIAL, sb_pass_find(r, "aerial"), NULL);
    sb_pass_sample(r, SB_VIEW_BINDING_AERIAL_T, sb_pass_find(r, "aerial transmittance"), NULL);
    sb_pass_read_probes(r);
    sb_pass_use(r, SB_VIEW_BINDING_REFLECTIONS, sb_pass_find(r, "reflections"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_REFLECTION_CUBES, sb_pass_find(r, "reflection cubes"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_CLOUDS, sb_pass_find(r, "clouds"), SB_USE_LOAD);
    sb_pass_sample(r, SB_VIEW_BINDING_CLOUD_SHADOW, sb_pass_find(r, "cloud shadow"), NULL);
    return r->scene_traced ? create_traced(r, s) : create_raster(r, s);
}

static void scene_destroy(struct sb_renderer *r)
{
    struct scene *s = sb_pass_data(r);
    if (!s)
        return;
    struct sb_texture *textures[3] = {&s->sun_history[0], &s->sun_history[1], &s->key_light};
    sb_renderer_release(r, textures, 3);
    sb_buffer_destroy(r->vk, &s->history);
    free(s);
}

static void scene_record(struct sb_renderer *r)
{
    struct scene *s = sb_pass_data(r);
    if (r->scene_traced) {
        struct sb_history_step step;
        sb_history_advance(&s->history_state, r, &step);
        struct sb_scene_history_gpu *g = s->history.mapped;
        sb_mat4_store(&step.previous_view_proj, g->previous_view_proj);
        for (int k = 0; k < 3; k++)
            g->camera_motion_m[k] = (float)step.camera_motion_m[k];
        g->camera_motion_m[3] = step.keep ? 1.0f : 0.0f;
        g->frame[0] = (uint32_t)r->frame_index;
        sb_renderer_dispatch_frame(r, s->traced[r->aerial_volume_only ? 1 : 0]);
        return;
    }
    VkRenderingAttachmentInfo color[2] = {
        {
            .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
            .imageView = r->hdr.view,
            .imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
            .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
            .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
        },
        {
            .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
            .imageView = s->key_light.view,
            .imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
            .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
            .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
        },
    };
    VkRenderingAttachmentInfo depth = {
        .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
        .imageView = r->depth.view,
        .imageLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
        .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
        .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
        .clearValue = {.depthStencil = {0.0f, 0}}, /* reverse Z: 0 is infinitely far */
    };
    VkRenderingInfo info = {
        .sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
        .renderArea = {{0, 0}, {r->width, r->height}},
        .layerCount = 1,
        .colorAttachmentCount = s->key_light.image ? 2 : 1,
        .pColorAttachments = color,
        .pDepthAttachment = &depth,
    };
    vkCmdBeginRendering(r->cmd, &info);
    sb_renderer_viewport(r, r->width, r->height);
    sb_renderer_bind_graphics(r, s->raster[r->aerial_volume_only ? 1 : 0], NULL);
    if (!r->draw_group_count)
        vkCmdDraw(r->cmd, r->vertex_count, 1, 0, 0);
    for (uint32_t g = 0; g < r->draw_group_count; g++) { /* a mesh, every instance of it the frame sees */
        const struct sb_draw_group *d = &r->draw_groups[g];
        const struct sb_visible_range *v = &r->visible_ranges[g];
        if (v->count)
            vkCmdDraw(r->cmd, d->end_vertex - d->first_vertex, v->count, d->first_vertex, v->first);
    }
    vkCmdEndRendering(r->cmd);
}

const struct sb_pass_class sb_pass_scene = {
    .name = "scene",
    .create = scene_create,
    .destroy = scene_destroy,
    .record = scene_record,
};

/*
 * Volumetric clouds (docs/clouds.md, "In skyview"): the scene's cloud_layer
 * shaped by the pack's baked noise, marched at one pixel of each
 * scale x scale block a frame (cloud_trace), rebuilt at full resolution
 * with the last frame's result and composited (cloud_resolve); and their
 * shadow map, which the scene and the fog read (cloud_shadow). Two passes
 * of the renderer's table, "cloud shadow" after the cascades and "clouds"
 * after the sky, in one file: they share the layer's state (its
 * parameters, filled once a frame, and its history).
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "clouds_gpu.h"
#include "history.h"
#include "image.h"
#include "log.h"
#include "renderer_internal.h"
#include "scene.h"

#include "cloud_resolve.spv.h"
#include "cloud_shadow.spv.h"
#include "cloud_trace.spv.h"
#include "cloud_trace_moon.spv.h"

#define CLOUD_FORMAT VK_FORMAT_R16G16B16A16_SFLOAT
#define HISTORY_WEIGHT 0.8         /* the last frame's share where a pixel is traced again */
#define SHADOW_WIDTH_M 16000.0     /* the shadow map's square, about the camera */
#define SHADOW_STEPS 32            /* pieces of a shadow texel's crossing of the layer */
#define GOLDEN 0.61803398874989485 /* the jitter's step from frame to frame */

struct sb_clouds {
    bool enabled;
    struct sb_cloud_layer_params layer;
    uint32_t scale, steps, light_steps, shadow_size;
    uint32_t trace_size[2];
    struct sb_buffer params;
    struct sb_texture shape, detail, curl, weather;
    struct sb_texture shadow, trace, depth;
    struct sb_texture out[2]; /* a history: this frame's clouds at full resolution, and the last frame's */
    VkPipeline shadow_kernel, trace_kernel[2], resolve_kernel; /* the trace's by day, and with the moon */
    struct sb_history history_state; /* the last frame, for reprojection */
    uint64_t history_frames;         /* frames since the history began */
};

static const enum sb_product_id noise_products[4] = {SB_PRODUCT_CLOUD_SHAPE, SB_PRODUCT_CLOUD_DETAIL,
                                                     SB_PRODUCT_CLOUD_CURL, SB_PRODUCT_WEATHER};
/* The layer's state, which both passes read: the cloud shadow pass's. */
static struct sb_clouds *layer(struct sb_renderer *r)
{
    return r->pass_data[SB_PASS_CLOUD_SHADOW];
}

static const char *const noise_names[4] = {"cloud shape", "cloud detail", "cloud curl", "cloud weather"};

static enum sb_result target(struct sb_renderer *r, struct sb_texture *t, uint32_t width, uint32_t height,
                             VkFormat format, VkImageUsageFlags usage, const char *name)
{
    struct sb_texture_params p = {.width = width, .height = height, .format = format, .usage = usage, .name = name};
    return sb_texture_create(r->vk, &p, t);
}

/* Whether the layer is drawn: the pack's noise is there, skyview was not
 * told otherwise, and the layer has clouds to draw. Says why not. */
static bool wanted(struct sb_renderer *r, const struct sb_clouds *c)
{
    const struct sb_scene *scene = r->pack->scene;
    if (r->params.no_clouds)
        return false;
    for (int i = 0; i < 4; i++)
        if (!r->pack->present[noise_products[i]]) {
            sb_info("clouds: the pack has no %s (bake a scene that asks for the cloud noise): no clouds",
                    sb_product_name(noise_products[i]));
            return false;
        }
    if (c->layer.coverage <= 0.0 || c->layer.extinction_per_m <= 0.0) {
        sb_info("clouds: the scene's cloud_layer has no %s: no clouds",
                c->layer.coverage <= 0.0 ? "coverage" : "extinction");
        return false;
    }
    if (!scene->has_cloud_layer)
        sb_info("clouds: the scene has no cloud_layer: the default layer (docs/scene.md)");
    return true;
}

/* The layer's parameters and noise, which its kernels read. */
static void declare_noise(struct sb_renderer *r)
{
    sb_pass_use(r, SB_VIEW_BINDING_CLOUDS, sb_pass_find(r, "clouds"), SB_USE_LOAD);
    for (uint32_t i = 0; i < 4; i++)
        sb_pass_sample(r, SB_VIEW_BINDING_CLOUD_SHAPE + i, sb_pass_find(r, noise_names[i]), r->repeat);
}

static enum sb_result clouds_create(struct sb_renderer *r)
{
    struct sb_clouds *c = calloc(1, sizeof(*c));
    if (!c)
        return SB_ERR_NOMEM;
    sb_pass_set_data(r, c);
    const struct sb_scene *scene = r->pack->scene;
    if (scene->has_cloud_layer)
        c->layer = scene->cloud_layer;
    else
        sb_cloud_layer_params_default(&c->layer);
    c->enabled = wanted(r, c);
    c->scale = r->params.cloud_scale ? r->params.cloud_scale : 2;
    c->steps = r->params.cloud_steps ? r->params.cloud_steps : 128;
    c->light_steps = r->params.cloud_light_steps ? r->params.cloud_light_steps : 6;
    c->shadow_size = r->params.cloud_shadow_size ? r->params.cloud_shadow_size : 512;
    if ((c->scale != 1 && c->scale != 2 && c->scale != 4) || c->steps < 8 || c->steps > 1024 ||
        c->light_steps > SB_CLOUD_MAX_LIGHT_STEPS || c->shadow_size < 16 || c->shadow_size > 4096) {
        sb_error("clouds: scale %u (1, 2 or 4), steps %u ([8, 1024]), light steps %u ([1, %d]) or shadow map %u "
                 "([16, 4096]) out of range",
                 c->scale, c->steps, c->light_steps, SB_CLOUD_MAX_LIGHT_STEPS, c->shadow_size);
        return SB_ERR_USAGE;
    }
    uint32_t tw = c->enabled ? (r->width + c->scale - 1) / c->scale : 1;
    uint32_t th = c->enabled ? (r->height + c->scale - 1) / c->scale : 1;
    uint32_t fw = c->enabled ? r->width : 1, fh = c->enabled ? r->height : 1, ss = c->enabled ? c->shadow_size : 1;
    c->trace_size[0] = tw;
    c->trace_size[1] = th;

    const VkImageUsageFlags storage_sampled = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    struct sb_texture *noise[4] = {&c->shape, &c->detail, &c->curl, &c->weather};
    enum sb_result res = sb_renderer_upload(r, NULL, sizeof(struct sb_clouds_gpu), "cloud parameters", &c->params);
    for (int i = 0; i < 4 && !res; i++)
        res = sb_renderer_upload_image(r, c->enabled ? &r->pack->images[noise_products[i]] : NULL, i < 2, 0.0f,
                                       noise_names[i], noise[i]);
    if (!res)
        res = target(r, &c->shadow, ss, ss, CLOUD_FORMAT, storage_sampled, "cloud shadow map");
    if (!res)
        res = target(r, &c->trace, tw, th, CLOUD_FORMAT, storage_sampled, "clouds traced");
    if (!res)
        res = target(r, &c->depth, tw, th, VK_FORMAT_R32_SFLOAT, storage_sampled, "clouds traced distance");
    for (int i = 0; i < 2 && !res; i++)
        res = target(r, &c->out[i], fw, fh, CLOUD_FORMAT, storage_sampled,
                     i ? "clouds resolved (history)" : "clouds resolved");
    if (res)
        return res;
    /* The scene and the fog read the layer and its shadow, drawn or not
     * (a shadow map of one texel, never written, when not). */
    sb_graph_buffer(r, "clouds", &c->params);
    sb_resource shadow = sb_graph_image(r, "cloud shadow", &c->shadow);
    sb_graph_image(r, "clouds traced", &c->trace);
    sb_graph_image(r, "clouds traced distance", &c->depth);
    sb_graph_history(r, "clouds resolved", c->out);
    for (int i = 0; i < 4; i++)
        sb_graph_image(r, noise_names[i], noise[i]);
    if (!c->enabled)
        return SB_OK;
    sb_pass_read_atmosphere(r);
    declare_noise(r);
    sb_pass_use(r, SB_VIEW_BINDING_CLOUD_SHADOW_OUT, shadow, SB_USE_STORE);
    res = sb_renderer_kernel(r, sb_spv_cloud_shadow, sizeof(sb_spv_cloud_shadow), "cloud shadow", &c->shadow_kernel);
    if (!res)
        sb_info("clouds: %g to %g m, coverage %g; traced at 1 pixel in %u x %u (%u x %u), %u steps, %u light steps; "
                "shadow map %u^2 over %g km",
                c->layer.base_altitude_m, c->layer.top_altitude_m, c->layer.coverage, c->scale, c->scale, tw, th,
                c->steps, c->light_steps, c->shadow_size, SHADOW_WIDTH_M * 1e-3);
    return SB_OK;
}

static void clouds_destroy(struct sb_renderer *r)
{
    struct sb_clouds *c = layer(r);
    if (!c)
        return;
    struct sb_texture *const textures[] = {&c->shape, &c->detail, &c->curl,   &c->weather, &c->shadow,
                                           &c->trace, &c->depth,  &c->out[0], &c->out[1]};
    sb_renderer_release(r, textures, sizeof(textures) / sizeof(textures[0]));
    sb_buffer_destroy(r->vk, &c->params);
    free(c);
}

/* x - tile floor(x / tile): a drift kept within one tile, so fp32 holds it exactly over hours. */
static double wrap(double x, double tile)
{
    return x - tile * floor(x / tile);
}

/* Which pixel of a scale x scale block frame i traces (y scale + x): an
 * ordered-dither (Bayer) order, so that consecutive frames fill the block
 * evenly. */
static uint32_t block_pixel(uint64_t i, uint32_t scale)
{
    static const uint8_t bayer2[4] = {0, 3, 1, 2};
    static const uint8_t bayer4[16] = {0, 10, 2, 8, 5, 15, 7, 13, 1, 11, 3, 9, 4, 14, 6, 12};
    return scale == 1 ? 0 : scale == 2 ? bayer2[i % 4] : bayer4[i % 16];
}

static void fill_params(struct sb_renderer *r, struct sb_clouds *c, struct sb_clouds_gpu *g)
{
    const struct sb_view *v = r->view;
    const struct sb_cloud_layer_params *m = &c->layer;
    struct sb_history_step step;
    sb_history_advance(&c->history_state, r, &step);
    memset(g, 0, sizeof(*g));
    sb_mat4_store(&step.previous_view_proj, g->previous_view_proj);
    double thickness = m->top_altitude_m - m->base_altitude_m;
    g->layer[0] = (float)m->base_altitude_m;
    g->layer[1] = (float)m->top_altitude_m;
    g->layer[2] = (float)(1.0 / thickness);
    g->layer[3] = (float)m->extinction_per_m;
    for (int k = 0; k < 3; k++)
        g->albedo[k] = (float)m->albedo[k];
    g->albedo[3] = (float)m->coverage;
    g->scales[0] = (float)(1.0 / m->weather_scale_m);
    g->scales[1] = (float)(1.0 / m->shape_scale_m);
    g->scales[2] = (float)(1.0 / m->detail_scale_m);
    g->scales[3] = (float)(1.0 / m->curl_scale_m);
    g->erosion[0] = (float)m->erosion;
    g->erosion[1] = (float)m->curl_m;
    g->erosion[2] = 1.0f;
    /* The clouds drift with the wind: the field at q now is the field at
     * q - wind t at time 0. */
    for (int k = 0; k < 3; k++) {
        double drift = -m->wind_m_s[k] * v->time_s;
        g->weather_offset[k] = k == 1 ? 0.0f : (float)wrap(drift, m->weather_scale_m);
        g->shape_offset[k] = (float)wrap(drift, m->shape_scale_m);
        g->detail_offset[k] = (float)wrap(drift, m->detail_scale_m);
        g->camera_motion_m[k] = (float)step.camera_motion_m[k];
    }
    g->phase[0] = (float)m->phase_forward_g;
    g->phase[1] = (float)m->phase_backward_g;
    g->phase[2] = (float)m->phase_forward_weight;
    g->phase[3] = (float)m->scattering_octaves;
    g->march[0] = (float)c->steps;
    g->march[1] = (float)c->light_steps;
    g->march[2] = (float)SB_CLOUD_REACH_M;
    g->march[3] = (float)(thickness / c->steps); /* an upright crossing takes every step */
    /* The shadow map follows the camera in whole texels, so its texels stay put on the ground. */
    double texel = SHADOW_WIDTH_M / c->shadow_size;
    g->shadow[0] = (float)(texel * floor(v->camera_m[0] / texel + 0.5));
    g->shadow[1] = (float)(texel * floor(v->camera_m[2] / texel + 0.5));
    g->shadow[2] = (float)SHADOW_WIDTH_M;
    g->shadow[3] = (float)SHADOW_STEPS;
    g->temporal[0] = (float)wrap(GOLDEN * (double)r->frame_index, 1.0);
    c->history_frames = step.keep ? c->history_frames + 1 : 0;
    g->temporal[1] = step.keep ? (float)HISTORY_WEIGHT : 0.0f;
    g->temporal[2] = (float)(c->history_frames < (1u << 20) ? c->history_frames : (1u << 20)); /* exact in fp32 */
    g->temporal[3] = (float)step.scale_ratio; /* the history's scale to this frame's */
    g->trace[0] = c->trace_size[0];
    g->trace[1] = c->trace_size[1];
    g->trace[2] = c->scale;
    g->trace[3] = block_pixel(r->frame_index, c->scale);
}

static void cloud_shadow_record(struct sb_renderer *r)
{
    struct sb_clouds *c = layer(r);
    if (!c->enabled)
        return;
    fill_params(r, c, c->params.mapped);
    sb_renderer_dispatch(r, c->shadow_kernel, NULL, (const uint32_t[3]){c->shadow_size, c->shadow_size, 1},
                         (const uint32_t[3]){SB_WORKGROUP_X, SB_WORKGROUP_Y, 1});
}

static void clouds_record(struct sb_renderer *r)
{
    struct sb_clouds *c = layer(r);
    if (!c->enabled)
        return;
    const uint32_t group[3] = {SB_WORKGROUP_X, SB_WORKGROUP_Y, 1};
    sb_renderer_dispatch(r, c->trace_kernel[r->frame_lights > 1], NULL, (const uint32_t[3]){c->trace_size[0], c->trace_size[1], 1}, group);
    sb_renderer_barrier(r->cmd);
    sb_renderer_dispatch_frame(r, c->resolve_kernel);
}

/* Traced, then resolved with the last frame's clouds and composited. */
static enum sb_result clouds_pass_create(struct sb_renderer *r)
{
    struct sb_clouds *c = layer(r);
    if (!c->enabled)
        return SB_OK;
    sb_resource trace = sb_pass_find(r, "clouds traced"), distance = sb_pass_find(r, "clouds traced distance");
    sb_resource resolved = sb_pass_find(r, "clouds resolved");
    sb_pass_read_atmosphere(r);
    declare_noise(r);
    sb_pass_sample(r, SB_VIEW_BINDING_AERIAL, sb_pass_find(r, "aerial"), NULL);
    sb_pass_sample(r, SB_VIEW_BINDING_AERIAL_T, sb_pass_find(r, "aerial transmittance"), NULL);
    sb_pass_sample(r, SB_VIEW_BINDING_DEPTH, sb_pass_find(r, "depth"), r->nearest);
    sb_pass_use(r, SB_VIEW_BINDING_HDR, sb_pass_find(r, "hdr"), SB_USE_LOAD_STORE);
    sb_pass_use(r, SB_VIEW_BINDING_CLOUD_TRACE_OUT, trace, SB_USE_STORE);
    sb_pass_sample(r, SB_VIEW_BINDING_CLOUD_TRACE, trace, NULL);
    sb_pass_use(r, SB_VIEW_BINDING_CLOUD_DEPTH_OUT, distance, SB_USE_STORE);
    sb_pass_sample(r, SB_VIEW_BINDING_CLOUD_DEPTH, distance, r->nearest); /* r32f need not filter */
    sb_pass_use(r, SB_VIEW_BINDING_CLOUD_OUT, resolved, SB_USE_STORE);
    sb_pass_sample(r, SB_VIEW_BINDING_CLOUD_HISTORY, SB_PREVIOUS(resolved), NULL);
    enum sb_result res =
        sb_renderer_kernel(r, sb_spv_cloud_trace, sizeof(sb_spv_cloud_trace), "cloud trace", &c->trace_kernel[0]);
    if (!res)
        res = sb_renderer_kernel(r, sb_spv_cloud_trace_moon, sizeof(sb_spv_cloud_trace_moon), "cloud trace (the moon)",
                                 &c->trace_kernel[1]);
    if (!res)
        res = sb_renderer_kernel(r, sb_spv_cloud_resolve, sizeof(sb_spv_cloud_resolve), "cloud resolve",
                                 &c->resolve_kernel);
    return res;
}

const struct sb_pass_class sb_pass_cloud_shadow = {
    .name = "cloud shadow",
    .create = clouds_create,
    .destroy = clouds_destroy,
    .record = cloud_shadow_record,
};

/* Left out of a frame, the clouds' history goes stale: the next frame starts
 * anew. (Their shadow map is another pass, which stays.) */
static void clouds_skipped(struct sb_renderer *r)
{
    if (layer(r))
        sb_history_drop(&layer(r)->history_state);
}

const struct sb_pass_class sb_pass_clouds = {
    .name = "clouds",
    .create = clouds_pass_create,
    .record = clouds_record,
    .optional = true,
    .skipped = clouds_skipped,
};

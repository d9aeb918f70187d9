/*
 * Froxel fog (docs/fog.md): the scene's "fog" in a camera-aligned volume of
 * froxels, lit each frame and blended with the last frame's (fog_inject),
 * integrated front to back (fog_integrate): "froxels" in the graph's
 * table, which the fog apply pass (fog_apply.c) applies to the frame.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "clouds_gpu.h"
#include "fog_gpu.h"
#include "history.h"
#include "image.h"
#include "log.h"
#include "probes_gpu.h"
#include "renderer_internal.h"
#include "scene.h"

#include "fog_inject.spv.h"
#include "fog_inject_traced.spv.h"
#include "fog_inject_traced_instanced.spv.h"
#include "fog_integrate.spv.h"

#define FROXEL_FORMAT VK_FORMAT_R16G16B16A16_SFLOAT
#define SLICE_SCALE_M 1.0  /* c in distance(w) = c ((1 + far / c)^w - 1) */
#define HISTORY_WEIGHT 0.9 /* the last frame's share in a froxel (10 frames to settle) */

_Static_assert(SB_FOG_VOLUMES == SB_FOG_MAX_VOLUMES, "fog_gpu.h and scene.h agree on the fog's boxes");

struct sb_fog {
    bool enabled;
    struct sb_fog_params medium;
    uint32_t grid[3];
    double far_m;
    struct sb_buffer params;
    struct sb_texture light[2]; /* a history: this frame's froxel light, and the last frame's */
    struct sb_texture integrated, noise;
    VkPipeline inject, integrate;
    struct sb_history history_state; /* the last frame, for reprojection */
};

static enum sb_result volume(struct sb_renderer *r, struct sb_texture *t, const uint32_t size[3],
                             VkImageUsageFlags usage, const char *name)
{
    struct sb_texture_params p = {
        .width = size[0],
        .height = size[1],
        .depth = size[2],
        .format = FROXEL_FORMAT,
        .usage = usage,
        .name = name,
    };
    return sb_texture_create(r->vk, &p, t);
}

/* The pack's cloud_detail as an rgba16f volume (its half values exactly),
 * or one texel of 1 (no modulation) where the fog asks for none or the pack has none. */
static enum sb_result upload_noise(struct sb_renderer *r, struct sb_fog *f)
{
    bool use = f->enabled && f->medium.noise_amount > 0.0;
    if (use && !r->pack->present[SB_PRODUCT_CLOUD_DETAIL]) {
        sb_warn("fog.noise: the pack has no cloud_detail to modulate the fog with; the fog is not modulated");
        f->medium.noise_amount = 0.0;
        use = false;
    }
    return sb_renderer_upload_image(r, use ? &r->pack->images[SB_PRODUCT_CLOUD_DETAIL] : NULL, true, 1.0f, "fog noise",
                                    &f->noise);
}

static enum sb_result fog_create(struct sb_renderer *r)
{
    struct sb_fog *f = calloc(1, sizeof(*f));
    if (!f)
        return SB_ERR_NOMEM;
    sb_pass_set_data(r, f);
    const struct sb_scene *scene = r->pack->scene;
    f->medium = scene->fog;
    f->enabled =
        scene->has_fog && !r->params.no_fog && (f->medium.extinction_per_m > 0.0 || f->medium.volume_count > 0);
    if (!f->enabled)
        return SB_OK;
    uint32_t tile = r->params.fog_tile_px ? r->params.fog_tile_px : 8;
    f->grid[0] = (r->width + tile - 1) / tile;
    f->grid[1] = (r->height + tile - 1) / tile;
    f->grid[2] = r->params.fog_slices ? r->params.fog_slices : 64;
    f->far_m = r->params.fog_far_m > 0.0 ? r->params.fog_far_m : 256.0;

    const VkImageUsageFlags storage_sampled = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    enum sb_result res = sb_renderer_upload(r, NULL, sizeof(struct sb_fog_gpu), "fog parameters", &f->params);
    for (int i = 0; i < 2 && !res; i++)
        res = volume(r, &f->light[i], f->grid, storage_sampled, i ? "froxel light (history)" : "froxel light");
    if (!res)
        res = volume(r, &f->integrated, f->grid, storage_sampled, "froxels integrated");
    if (!res)
        res = upload_noise(r, f);
    if (res)
        return res;
    sb_resource params = sb_graph_buffer(r, "fog", &f->params);
    sb_resource light = sb_graph_history(r, "froxel light", f->light);
    sb_resource froxels = sb_graph_image(r, "froxels", &f->integrated);
    sb_pass_read_atmosphere(r);
    sb_pass_use(r, SB_VIEW_BINDING_FOG, params, SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_FROXEL_LIGHT_OUT, light, SB_USE_LOAD_STORE);
    sb_pass_sample(r, SB_VIEW_BINDING_FROXEL_HISTORY, SB_PREVIOUS(light), NULL);
    sb_pass_use(r, SB_VIEW_BINDING_FROXEL_OUT, froxels, SB_USE_STORE);
    sb_pass_sample(r, SB_VIEW_BINDING_FOG_NOISE, sb_graph_image(r, "fog noise", &f->noise), r->repeat);
    sb_pass_read_probes(r);
    sb_pass_use(r, SB_VIEW_BINDING_CLOUDS, sb_pass_find(r, "clouds"), SB_USE_LOAD);
    sb_pass_sample(r, SB_VIEW_BINDING_CLOUD_SHADOW, sb_pass_find(r, "cloud shadow"), NULL);
    if (r->scene_traced) {
        sb_pass_use(r, SB_VIEW_BINDING_BVH_NODES, sb_pass_find(r, "bvh nodes"), SB_USE_LOAD);
        sb_pass_use(r, SB_VIEW_BINDING_BVH_TRIANGLES, sb_pass_find(r, "bvh triangles"), SB_USE_LOAD);
        if (r->draw_group_count) /* an instanced world: its BVH's two levels */
            res = sb_renderer_kernel(r, sb_spv_fog_inject_traced_instanced, sizeof(sb_spv_fog_inject_traced_instanced),
                                     "fog inject (shadow rays, instances)", &f->inject);
        else
            res = sb_renderer_kernel(r, sb_spv_fog_inject_traced, sizeof(sb_spv_fog_inject_traced),
                                     "fog inject (shadow rays)", &f->inject);
    } else {
        sb_pass_sample(r, SB_VIEW_BINDING_SHADOW, sb_pass_find(r, "shadow cascades"), r->shadow_compare);
        res = sb_renderer_kernel(r, sb_spv_fog_inject, sizeof(sb_spv_fog_inject), "fog inject", &f->inject);
    }
    if (!res)
        res = sb_renderer_kernel(r, sb_spv_fog_integrate, sizeof(sb_spv_fog_integrate), "fog integrate", &f->integrate);
    if (!res)
        sb_info("fog: %u x %u x %u froxels to %g m%s, %d boxes", f->grid[0], f->grid[1], f->grid[2], f->far_m,
                f->medium.noise_amount > 0.0 ? ", noise" : "", f->medium.volume_count);
    return res;
}

static void fog_destroy(struct sb_renderer *r)
{
    struct sb_fog *f = sb_pass_data(r);
    if (!f)
        return;
    struct sb_texture *const textures[] = {&f->light[0], &f->light[1], &f->integrated, &f->noise};
    sb_renderer_release(r, textures, sizeof(textures) / sizeof(textures[0]));
    sb_buffer_destroy(r->vk, &f->params);
    free(f);
}

/* The radical inverse of i in `base`: Halton's sequence, for the jitter. */
static double halton(uint64_t i, unsigned base)
{
    double f = 1.0, x = 0.0;
    for (; i > 0; i /= base) {
        f /= base;
        x += f * (double)(i % base);
    }
    return x;
}

static void fill_params(struct sb_renderer *r, struct sb_fog *f, struct sb_fog_gpu *g)
{
    const struct sb_view *v = r->view;
    const struct sb_fog_params *m = &f->medium;
    struct sb_history_step step;
    sb_history_advance(&f->history_state, r, &step);
    memset(g, 0, sizeof(*g));
    sb_mat4_store(&step.previous_view_proj, g->previous_view_proj);
    g->grid[0] = f->grid[0];
    g->grid[1] = f->grid[1];
    g->grid[2] = f->grid[2];
    g->grid[3] = (uint32_t)m->volume_count;
    g->slices[0] = (float)f->far_m;
    g->slices[1] = (float)SLICE_SCALE_M;
    g->slices[2] = (float)log2(1.0 + f->far_m / SLICE_SCALE_M);
    g->slices[3] = step.keep ? (float)HISTORY_WEIGHT : 0.0f;
    g->medium[0] = (float)m->extinction_per_m;
    g->medium[1] = (float)m->base_altitude_m;
    g->medium[2] = (float)(1.0 / m->falloff_height_m);
    g->medium[3] = (float)m->anisotropy;
    for (int k = 0; k < 3; k++) {
        g->albedo[k] = (float)m->albedo[k];
        /* The drift wrapped to the noise's tile, so fp32 keeps it exact over hours. */
        double drift = -m->noise_wind_m_s[k] * v->time_s;
        g->noise[k] = (float)(drift - m->noise_scale_m * floor(drift / m->noise_scale_m));
        g->camera_motion_m[k] = (float)step.camera_motion_m[k];
    }
    /* The history was stored at the last frame's scale (pre-exposure). */
    g->camera_motion_m[3] = (float)step.scale_ratio;
    g->albedo[3] = (float)m->noise_amount;
    g->noise[3] = (float)(1.0 / m->noise_scale_m);
    /* Halton (2, 3, 5), a new point each frame; the first frame samples centres. */
    uint64_t i = r->frame_index;
    g->jitter[0] = i ? (float)halton(i, 2) : 0.5f;
    g->jitter[1] = i ? (float)halton(i, 3) : 0.5f;
    g->jitter[2] = i ? (float)halton(i, 5) : 0.5f;
    g->jitter[3] = m->extinction_per_m > 0.0 ? 1.0f : 0.0f;
    for (int b = 0; b < m->volume_count; b++) {
        for (int k = 0; k < 3; k++) {
            g->volume_min[b][k] = (float)m->volumes[b].box_m[0][k];
            g->volume_max[b][k] = (float)m->volumes[b].box_m[1][k];
        }
        g->volume_min[b][3] = (float)m->volumes[b].extinction_per_m;
        g->volume_max[b][3] = (float)m->volumes[b].edge_m;
    }
}

static void fog_record(struct sb_renderer *r)
{
    struct sb_fog *f = sb_pass_data(r);
    if (!f->enabled)
        return;
    fill_params(r, f, f->params.mapped);
    sb_renderer_dispatch(r, f->inject, NULL, f->grid, (const uint32_t[3]){SB_FOG_GROUP, SB_FOG_GROUP, SB_FOG_GROUP});
    sb_renderer_barrier(r->cmd);
    sb_renderer_dispatch(r, f->integrate, NULL, (const uint32_t[3]){f->grid[0], f->grid[1], 1},
                         (const uint32_t[3]){SB_WORKGROUP_X, SB_WORKGROUP_Y, 1});
}

/* Left out of a frame, the froxels' history goes stale: the next frame starts anew. */
static void fog_skipped(struct sb_renderer *r)
{
    struct sb_fog *f = sb_pass_data(r);
    if (f)
        sb_history_drop(&f->history_state);
}

const struct sb_pass_class sb_pass_fog = {
    .name = "fog",
    .create = fog_create,
    .destroy = fog_destroy,
    .record = fog_record,
    .optional = true,
    .skipped = fog_skipped,
};

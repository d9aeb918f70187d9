/*
 * skyview's renderer: the frame loop. It uploads the atmosphere and the
 * world, makes the frame's targets, creates the passes (passes/passes.c)
 * and, each frame, fills the frame constants, records the passes with the
 * render graph's barriers (graph.h), reads back and meters the exposure.
 */
#include "renderer_internal.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "image.h"
#include "log.h"
#include "moon.h"
#include "physics.h"
#include "scene.h"
#include "shadows.h"
#include "texture.h"
#include "transform.h"

/* In integers (2 x far >= 7 x extent): a floating comparison is no C
 * constant expression, and clang refuses it. */
_Static_assert(2 * (long)SB_TRACE_FAR_M >= 7 * (long)SB_MESH_MAX_EXTENT_M, "a shadow ray crosses any world");

/* ---- Creation ------------------------------------------------------------------ */

/* The renderer's own resources in the graph's table. */
static void add_resources(struct sb_renderer *r)
{
    const struct {
        const char *name;
        const struct sb_buffer *buffer;
    } buffers[] = {
        {"atmosphere", &r->atmosphere},
        {"frame", &r->frame},
        {"vertices", &r->vertices},
        {"exposure", &r->exposure},
        {"texture records", &r->textures.records},
        {"texels", &r->textures.texels},
        {"instances", &r->instances},
        {"emissive", &r->emissive},
        {"visible instances", &r->visible},
    };
    for (size_t i = 0; i < sizeof(buffers) / sizeof(buffers[0]); i++)
        sb_graph_buffer(r, buffers[i].name, buffers[i].buffer);
    if (r->world_bvh) {
        sb_graph_buffer(r, "bvh nodes", &r->bvh_nodes);
        sb_graph_buffer(r, "bvh triangles", &r->bvh_triangles);
    }
    sb_graph_image(r, "transmittance", &r->transmittance);
    sb_graph_image(r, "multiscattering", &r->multiscattering);
    sb_graph_image(r, "irradiance ground", &r->irradiance_ground);
    sb_graph_image(r, "orders", &r->orders);
    sb_graph_image(r, "depth", &r->depth);
    r->hdr_id = sb_graph_image(r, "hdr", &r->hdr);
    r->ldr_id = sb_graph_image(r, "ldr", &r->ldr);
}

/* Whether the scene pass traces (passes/scene.c): on a GPU by default. */
static bool scene_traced(const struct sb_renderer_params *params, const struct sb_vk *vk, uint32_t vertex_count)
{
    if (vertex_count < 3) /* nothing to trace: the raster pass draws nothing cheaply */
        return false;
    if (params->scene == SB_SCENE_AUTO)
        return vk->properties.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU;
    return params->scene == SB_SCENE_TRACED;
}

/* The frame's targets and the samplers. */
static enum sb_result create_images(struct sb_renderer *r)
{
    const VkImageUsageFlags storage_sampled = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    const VkImageUsageFlags copy = VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    const uint32_t size[3] = {r->width, r->height, 1};
    enum sb_result res = sb_renderer_texture(
        r, &r->hdr, size, 1, 1, SB_HDR_FORMAT,
        storage_sampled | copy | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT, "HDR frame");
    /* the traced scene writes its depth from a kernel, which a depth format cannot take */
    if (!res && r->scene_traced)
        res = sb_renderer_texture(r, &r->depth, size, 1, 1, VK_FORMAT_R32_SFLOAT, storage_sampled,
                                  "scene depth (traced)");
    if (!res && !r->scene_traced)
        res = sb_renderer_texture(r, &r->depth, size, 1, 1, SB_DEPTH_FORMAT,
                                  VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT,
                                  "scene depth");
    if (!res)
        res = sb_renderer_texture(r, &r->ldr, size, 1, 1, VK_FORMAT_R8G8B8A8_UNORM, VK_IMAGE_USAGE_STORAGE_BIT | copy,
                                  "LDR frame");
    if (res)
        return res;

    struct sb_vk *vk = r->vk;
    VkSamplerCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO,
        .magFilter = VK_FILTER_LINEAR,
        .minFilter = VK_FILTER_LINEAR,
        .mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST,
        .addressModeU = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
        .addressModeV = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
        .addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
        .maxLod = VK_LOD_CLAMP_NONE,
    };
    VK(vkCreateSampler(vk->device, &info, NULL, &r->linear));
    info.magFilter = info.minFilter = VK_FILTER_NEAREST;
    VK(vkCreateSampler(vk->device, &info, NULL, &r->nearest));
    info.magFilter = info.minFilter = VK_FILTER_LINEAR;
    info.compareEnable = VK_TRUE;
    info.compareOp = VK_COMPARE_OP_LESS_OR_EQUAL;
    VK(vkCreateSampler(vk->device, &info, NULL, &r->shadow_compare));
    info.compareEnable = VK_FALSE;
    info.addressModeU = info.addressModeV = info.addressModeW = VK_SAMPLER_ADDRESS_MODE_REPEAT;
    VK(vkCreateSampler(vk->device, &info, NULL, &r->repeat));
cleanup:
    return res;
}

enum sb_result sb_renderer_create(struct sb_vk *vk, const struct sb_pack *pack, const struct sb_world *world,
                                  const struct sb_renderer_params *params, struct sb_renderer **out)
{
    enum sb_result res = SB_OK;
    *out = NULL;
    if (!vk->graphics) {
        sb_error("skyview needs a Vulkan context created for graphics");
        return SB_ERR_USAGE;
    }
    if (!pack->scene) {
        sb_error("the pack has no scene");
        return SB_ERR_USAGE;
    }
    struct sb_renderer *r = calloc(1, sizeof(*r));
    if (!r)
        return SB_ERR_NOMEM;
    r->vk = vk;
    r->params = *params;
    r->width = params->width ? params->width : 1280;
    r->height = params->height ? params->height : 720;
    if (!r->params.shadow_size)
        r->params.shadow_size = 2048;
    if (r->params.shadow_distance_m <= 0.0)
        r->params.shadow_distance_m = 250.0;
    if (r->params.bloom_strength == 0.0)
        r->params.bloom_strength = 0.15;
    uint32_t shorter = r->width < r->height ? r->width : r->height;
    r->bloom_levels = 0;
    if (r->params.bloom_strength > 0.0)
        while (r->bloom_levels < SB_BLOOM_MAX_LEVELS && (shorter >> (r->bloom_levels + 1)) >= 4)
            r->bloom_levels++;
    r->scene_traced = scene_traced(&r->params, vk, world->vertex_count);
    r->world_bvh = r->scene_traced || sb_reflections_relightable(pack, &r->params, world);
    if ((res = sb_atmosphere_upload(r, pack)))
        goto cleanup;
    res = sb_world_upload(r, world);
    if (!res)
        res = sb_renderer_upload(r, NULL, sizeof(struct sb_frame_gpu), "frame constants", &r->frame);
    if (!res)
        res = sb_renderer_upload(r, NULL, SB_HISTOGRAM_BINS * sizeof(uint32_t) + sizeof(struct sb_exposure_gpu),
                                 "exposure", &r->exposure);
    if (!res)
        res = sb_renderer_upload(r, NULL, (size_t)r->width * r->height * 4, "LDR readback", &r->read_ldr);
    if (!res)
        res = sb_renderer_upload(r, NULL, (size_t)r->width * r->height * 8, "HDR readback", &r->read_hdr);
    if (!res && params->post_input) {
        res = sb_renderer_upload(r, NULL, (size_t)r->width * r->height * 8, "post-processing input", &r->post_input);
        uint16_t *dst = res ? NULL : r->post_input.mapped;
        for (size_t i = 0; dst && i < (size_t)r->width * r->height; i++)
            for (int c = 0; c < 4; c++) {
                float v = c < 3 ? params->post_input[3 * i + c] : 1.0f;
                double stored = isfinite(v) ? v * r->radiance_scale : 0.0; /* within a half's range */
                dst[4 * i + c] = sb_half_from_float((float)fmin(fmax(stored, -65504.0), 65504.0));
            }
    }
    if (!res)
        res = sb_renderer_upload(r, NULL, (size_t)SB_SKY_VIEW_WIDTH * SB_SKY_VIEW_HEIGHT * 8, "sky-view readback",
                                 &r->read_sky_view);
    if (!res)
        res = sb_renderer_upload(r, NULL, (size_t)SB_AERIAL_SIZE * SB_AERIAL_SIZE * SB_AERIAL_SIZE * 8,
                                 "aerial readback", &r->read_aerial);
    if (!res)
        res = create_images(r);
    r->graph.passes = calloc(SB_PASS_COUNT, sizeof(*r->graph.passes));
    if (!res && !r->graph.passes)
        res = SB_ERR_NOMEM;
    if (!res)
        add_resources(r);
    r->pack = pack;
    r->world = world;
    for (r->pass = 0; r->pass < SB_PASS_COUNT && !res; r->pass++) {
        r->pass_name = sb_pass_classes[r->pass]->name;
        if (sb_pass_classes[r->pass]->create)
            res = sb_pass_classes[r->pass]->create(r);
    }
    r->pack = NULL;
    r->world = NULL;
    /* The lit frame is whole before the first post-processing pass; when
     * one of them writes it, what they made is read back too. */
    r->first_post = SB_PASS_COUNT;
    for (int p = SB_PASS_COUNT; p-- > 0;)
        if (sb_pass_classes[p]->post)
            r->first_post = p;
    for (int p = r->first_post; !res && p < SB_PASS_COUNT; p++)
        for (uint32_t u = 0; u < r->graph.passes[p].use_count; u++) {
            const struct sb_graph_use *use = &r->graph.passes[p].uses[u];
            r->post_in_place |= use->resource == r->hdr_id && use->use != SB_USE_SAMPLED && use->use != SB_USE_LOAD;
        }
    if (!res && r->post_in_place)
        res =
            sb_renderer_upload(r, NULL, (size_t)r->width * r->height * 8, "post-processed HDR readback", &r->read_post);
    r->sky_view_id = sb_graph_find(r, "sky-view");
    r->aerial_id = sb_graph_find(r, "aerial");
    if (!res)
        res = sb_graph_write_sets(r);
    if (res)
        goto cleanup;

    if (vk->has_timestamps) {
        VkQueryPoolCreateInfo qinfo = {
            .sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO,
            .queryType = VK_QUERY_TYPE_TIMESTAMP,
            .queryCount = 2 * SB_PASS_COUNT,
        };
        VK(vkCreateQueryPool(vk->device, &qinfo, NULL, &r->queries));
    }
    VkCommandBufferAllocateInfo alloc = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
        .commandPool = vk->command_pool,
        .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY,
        .commandBufferCount = 1,
    };
    VK(vkAllocateCommandBuffers(vk->device, &alloc, &r->cmd));
    VkFenceCreateInfo finfo = {.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VK(vkCreateFence(vk->device, &finfo, NULL, &r->fence));
    *out = r;
    return SB_OK;

cleanup:
    sb_renderer_destroy(&r);
    return res;
}

void sb_renderer_destroy(struct sb_renderer **pr)
{
    struct sb_renderer *r = *pr;
    if (!r)
        return;
    struct sb_vk *vk = r->vk;
    VkDevice d = vk->device;
    vkDeviceWaitIdle(d);
    if (r->fence)
        vkDestroyFence(d, r->fence, NULL);
    if (r->cmd)
        vkFreeCommandBuffers(d, vk->command_pool, 1, &r->cmd);
    if (r->queries)
        vkDestroyQueryPool(d, r->queries, NULL);
    for (r->pass = SB_PASS_COUNT; r->pass-- > 0;)
        if (sb_pass_classes[r->pass]->destroy)
            sb_pass_classes[r->pass]->destroy(r);
    sb_graph_destroy(r);
    if (r->linear)
        vkDestroySampler(d, r->linear, NULL);
    if (r->nearest)
        vkDestroySampler(d, r->nearest, NULL);
    if (r->shadow_compare)
        vkDestroySampler(d, r->shadow_compare, NULL);
    if (r->repeat)
        vkDestroySampler(d, r->repeat, NULL);
    struct sb_texture *const textures[] = {
        &r->transmittance, &r->multiscattering, &r->irradiance_ground, &r->orders, &r->hdr, &r->depth, &r->ldr};
    sb_renderer_release(r, textures, sizeof(textures) / sizeof(textures[0]));
    struct sb_buffer *buffers[] = {&r->atmosphere, &r->frame,      &r->exposure,      &r->read_ldr,   &r->read_hdr,
                                   &r->read_post,  &r->post_input, &r->read_sky_view, &r->read_aerial};
    for (size_t i = 0; i < sizeof(buffers) / sizeof(buffers[0]); i++)
        sb_buffer_destroy(vk, buffers[i]);
    sb_world_release(r);
    free(r);
    *pr = NULL;
}

/* ---- A frame ------------------------------------------------------------------- */

static void store4(float dst[4], double x, double y, double z, double w)
{
    dst[0] = (float)x;
    dst[1] = (float)y;
    dst[2] = (float)z;
    dst[3] = (float)w;
}

/*
 * The solid-angle integral of the moon's disk's shading, a Lommel-Seeliger
 * surface, mu0 / (mu0 + mu) where the sun lights it (mu0: the cosine to the
 * sun, mu: to the viewer), which view.glsl's moon_disk divides by so that
 * the disk delivers the moon's irradiance whatever its phase. The law of the
 * dusty regolith: a full moon is a flat disk, without a Lambert sphere's
 * dark limb. Over the visible hemisphere by the angle theta from the disk's
 * centre (a disk radius sin theta, its area element sin theta cos theta
 * dtheta dphi, smooth to the limb) and the angle phi around it: midpoints,
 * 64 x 128, within 1e-3 of the integral at any phase (the sun-moon-viewer
 * angle, radians; 0: full).
 */
static double moon_disk_integral(double phase, double radius)
{
    /* The shading is symmetric about the line to the moon: the sun is taken
     * in the plane of the disk's first axis, at the phase angle from the
     * viewer (s3 its cosine toward the viewer, s1 its sine across). */
    double s1 = sin(phase), s3 = cos(phase);
    enum { THETA = 64, PHI = 128 };
    double sum = 0.0;
    for (int j = 0; j < THETA; j++) {
        double theta = (j + 0.5) * (0.5 * M_PI / THETA), r = sin(theta), mu = cos(theta);
        for (int i = 0; i < PHI; i++) {
            double phi = (i + 0.5) * (2.0 * M_PI / PHI);
            double mu0 = r * cos(phi) * s1 + mu * s3;
            if (mu0 > 0.0)
                sum += mu0 / (mu0 + mu) * r * mu;
        }
    }
    return sum * (0.5 * M_PI / THETA) * (2.0 * M_PI / PHI) * radius * radius;
}

double sb_renderer_ev100(const struct sb_renderer *r, double log2_luminance)
{
    return log2_luminance + log2(r->cd_m2_per_unit * 100.0 / 12.5); /* log2(L S / K) */
}

static void fill_frame(struct sb_renderer *r, const struct sb_view *v, struct sb_frame_gpu *f)
{
    memset(f, 0, sizeof(*f));
    double fov = v->fov_y > 0.0 ? v->fov_y : 50.0 * M_PI / 180.0;
    double aspect = (double)r->width / r->height;
    double forward[3], sun[3];
    sb_direction(v->yaw, v->pitch, forward);
    sb_direction(v->sun_azimuth, v->sun_elevation, sun);
    double up[3] = {0.0, 1.0, 0.0};
    if (fabs(forward[1]) > 0.999) { /* looking straight up or down: yaw decides what is up */
        sb_direction(v->yaw, 0.0, up);
        if (forward[1] > 0.0)
            for (int i = 0; i < 3; i++)
                up[i] = -up[i];
    }
    struct sb_mat4 view = sb_mat4_look(forward, up);
    struct sb_mat4 proj = sb_mat4_perspective(fov, aspect, SB_NEAR_M);
    r->view_proj = sb_mat4_mul(&proj, &view);
    memcpy(r->camera_m, v->camera_m, sizeof(r->camera_m));
    struct sb_mat4 inv = sb_mat4_inverse(&r->view_proj);
    sb_mat4_store(&r->view_proj, f->view_proj);
    sb_mat4_store(&inv, f->inv_view_proj);

    struct sb_cascade_params cp = {
        .near_m = SB_NEAR_M,
        .distance_m = r->params.shadow_distance_m,
        .lambda = 0.75,
        .fov_y = fov,
        .aspect = aspect,
        .map_size = r->params.shadow_size,
        .caster_margin_m = 200.0,
    };
    /* The moon: where it is, how bright its phase is, and whether it is the
     * key light (the sun wholly under the horizon). */
    const double sun_radius = 0.2666 * M_PI / 180.0; /* the sun's mean angular radius */
    double moon[3] = {0.0, -1.0, 0.0};
    bool moon_key = false;
    if (v->moon) {
        sb_direction(v->moon_azimuth, v->moon_elevation, moon);
        double distance = v->moon_distance_km > 0.0 ? v->moon_distance_km : 384400.0;
        double radius = asin(fmin(SB_MOON_RADIUS_KM / distance, 1.0));
        double phase = acos(fmin(fmax(-(sun[0] * moon[0] + sun[1] * moon[1] + sun[2] * moon[2]), -1.0), 1.0));
        double ratio = sb_moon_irradiance_ratio(phase, distance);
        double shading = moon_disk_integral(phase, radius);
        store4(f->moon_direction, moon[0], moon[1], moon[2], radius);
        store4(f->moon_light, ratio * SB_MOON_COLOR_R, ratio * SB_MOON_COLOR_G, ratio * SB_MOON_COLOR_B,
               shading > 0.0 ? 1.0 / shading : 0.0);
        moon_key = v->sun_elevation < -sun_radius;
    }
    r->frame_lights = moon_key ? 2 : 1;
    store4(f->lights, r->frame_lights, moon_key ? 1.0 : 0.0, 0.0, 0.0);
    memcpy(r->key_direction, moon_key ? moon : sun, sizeof(r->key_direction));

    struct sb_cascades cascades;
    sb_cascades_compute(&cp, v->camera_m, forward, r->key_direction, &cascades);
    /* The far map past the last cascade (raster): the casters over the
     * world, along the key light; drawn whole, or not at all. */
    struct sb_mat4 far;
    double far_texel = 0.0, far_depth = 0.0;
    bool far_drawn =
        !r->scene_traced && !r->params.no_far_shadows &&
        sb_far_shadow_compute(v->camera_m, r->key_direction, r->caster_boxes, r->caster_box_count, r->world_min_m,
                              r->world_max_m, r->params.shadow_size, &far, &far_texel, &far_depth);
    int32_t *far_clear = r->cascade_clear[SB_CASCADES];
    far_clear[0] = far_clear[1] = 0;
    far_clear[2] = far_clear[3] = far_drawn ? (int32_t)r->params.shadow_size : 0;
    if (!far_drawn)
        memset(&far, 0, sizeof(far));
    sb_mat4_store(&far, f->far_view_proj);
    store4(f->far_shadow, far_texel, far_depth, 0.0, far_drawn ? 1.0 : 0.0);
    if (r->draw_group_count)
        sb_world_cull(r, &cascades, far_drawn ? &far : NULL);
    for (int c = 0; c < SB_CASCADES; c++) {
        sb_mat4_store(&cascades.view_proj[c], f->shadow_view_proj[c]);
        f->cascade_ends[c] = (float)cascades.ends_m[c];
        f->cascade_texel[c] = (float)cascades.texel_m[c];
        f->cascade_depth_m[c] = (float)(2.0 * cascades.radius_m[c] + cp.caster_margin_m);
        /* Texels to clear and draw: the casters' box and a margin each side
         * that covers what the lookups read (view_gpu.h); they see the sun
         * outside, exactly as if the whole map were cleared and drawn. */
        int32_t box[4], size = (int32_t)r->params.shadow_size;
        int32_t *clear = r->cascade_clear[c];
        if (r->params.whole_shadow_maps) {
            box[0] = box[1] = 0;
            box[2] = box[3] = size;
        } else {
            sb_cascade_caster_rect(&cascades.view_proj[c], v->camera_m, r->caster_boxes, r->caster_box_count,
                                   r->params.shadow_size, box);
        }
        for (int k = 0; k < 2; k++) {
            clear[k] = box[k] - SB_SHADOW_CLEAR_MARGIN_TEXELS > 0 ? box[k] - SB_SHADOW_CLEAR_MARGIN_TEXELS : 0;
            clear[k + 2] =
                box[k + 2] + SB_SHADOW_CLEAR_MARGIN_TEXELS < size ? box[k + 2] + SB_SHADOW_CLEAR_MARGIN_TEXELS : size;
        }
        if (box[0] >= box[2]) { /* no casters: nothing to draw, every lookup lit */
            clear[0] = clear[1] = clear[2] = clear[3] = 0;
            store4(f->cascade_rect[c], 2.0, 2.0, -1.0, -1.0);
        } else {
            const double m = SB_SHADOW_RECT_MARGIN_TEXELS;
            store4(f->cascade_rect[c], (box[0] - m) / size, (box[1] - m) / size, (box[2] + m) / size,
                   (box[3] + m) / size);
        }
    }

    /* the atmosphere's camera stays over the planet's ground, as the LUTs
     * were made: a camera in a world's valley under y 0 sees the sky from
     * the ground (its world still from where it is) */
    const double R = r->ground_radius_km;
    double km[3] = {v->camera_m[0] * 1e-3, R + fmax(v->camera_m[1], SB_CAMERA_LOWEST_ATMOSPHERE_M) * 1e-3,
                    v->camera_m[2] * 1e-3};
    double altitude = sqrt(km[0] * km[0] + km[1] * km[1] + km[2] * km[2]) - R;
    store4(f->camera_m, v->camera_m[0], v->camera_m[1], v->camera_m[2], SB_NEAR_M);
    store4(f->camera_km, km[0], km[1], km[2], altitude);
    /* the shaders' test, on the same fp32 values */
    r->camera_in_atmosphere = (float)altitude < r->thickness_km;
    /* Every fragment lies in the world's box: when its farthest corner is
     * inside the aerial-perspective volume's range (1% to spare for fp32),
     * no fragment needs the ray's integral (aerial.glsl). */
    double reach2 = 0.0;
    for (int i = 0; i < 3; i++) {
        double d = fmax(fabs(r->world_min_m[i] - v->camera_m[i]), fabs(r->world_max_m[i] - v->camera_m[i]));
        reach2 += d * d;
    }
    r->aerial_volume_only =
        !r->params.generic_shaders && r->camera_in_atmosphere && sqrt(reach2) <= 0.99e3 * SB_AERIAL_FAR_KM;
    store4(f->camera_forward, forward[0], forward[1], forward[2], cos(sun_radius));
    store4(f->sun_direction, sun[0], sun[1], sun[2], sun_radius);
    store4(f->shadow, 0.1, 1.5, r->params.shadow_size, 1.0);
    store4(f->aerial, SB_AERIAL_FAR_KM, r->frame_scale, 0.0, 0.0);
    /* Bins 1 to 255 span 2^-34 to 2^12 of the solar irradiance's units
     * (0.18 stops a bin): from a moonless night's sky to beyond the sun-lit
     * snow. The meter adapts within the EV range (renderer.h). */
    double log_sun = log2(1.0 / r->radiance_scale);
    store4(f->exposure, log_sun - 34.0, 46.0, 0.10, 0.90);
    const struct sb_renderer_params *p = &r->params;
    bool ev_given = p->exposure_min_ev100 != 0.0 || p->exposure_max_ev100 != 0.0;
    double ev_lo = ev_given ? p->exposure_min_ev100 : SB_EXPOSURE_MIN_EV100;
    double ev_hi = ev_given ? p->exposure_max_ev100 : SB_EXPOSURE_MAX_EV100;
    double dim = p->dim_compensation > 0.0   ? p->dim_compensation
                 : p->dim_compensation < 0.0 ? 0.0
                                             : SB_EXPOSURE_DIM_STOPS;
    double to_log_units = -sb_renderer_ev100(r, 0.0);
    store4(f->meter, ev_lo + to_log_units, ev_hi + to_log_units, dim, SB_EXPOSURE_DIM_EV100 + to_log_units);
    store4(f->adaptation, 3.0, 1.0, v->dt_s > 0.0 ? v->dt_s : 1.0 / 60.0, v->snap_exposure ? 1.0 : 0.0);
    bool bloom = r->params.bloom_strength > 0.0 && !(v->disabled_passes >> SB_PASS_BLOOM & 1);
    store4(f->post, 1.0, bloom ? r->params.bloom_strength : 0.0, r->params.exposure_compensation_ev, 0.0);
    f->size[0] = r->width;
    f->size[1] = r->height;
    f->size[2] = bloom ? r->bloom_levels : 0; /* none: the tone curve reads no bloom (never written this frame) */
    f->size[3] = (uint32_t)r->params.debug;
    memcpy(f->orders_size, r->orders_grid.size, sizeof(f->orders_size));
    memcpy(f->orders_heights, r->orders_grid.heights, sizeof(f->orders_heights));
    memcpy(f->orders_mu_s, r->orders_grid.mu_s, sizeof(f->orders_mu_s));
    memcpy(f->spectral_rgb, r->spectral_rgb, sizeof(f->spectral_rgb));
}

/* A readback: the whole of an image into a host-visible buffer. */
static void copy_image(struct sb_renderer *r, sb_resource image, const struct sb_buffer *b)
{
    const struct sb_texture *t = sb_graph_texture(r, image);
    VkBufferImageCopy region = {
        .imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
        .imageExtent = {t->width, t->height, t->depth ? t->depth : 1},
    };
    sb_graph_access(r, image, SB_USE_COPY_SRC);
    vkCmdCopyImageToBuffer(r->cmd, t->image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, b->buffer, 1, &region);
}

/* The lit frame replaced by params.post_input's (its halves, uploaded once). */
static void copy_input(struct sb_renderer *r)
{
    VkBufferImageCopy region = {
        .imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
        .imageExtent = {r->width, r->height, 1},
    };
    sb_graph_access(r, r->hdr_id, SB_USE_COPY_DST);
    vkCmdCopyBufferToImage(r->cmd, r->post_input.buffer, r->hdr.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                           &region);
}

/*
 * Pre-exposure: the frame is stored in halves as radiance times a scale that
 * follows the exposure, so whatever the light, mid grey is stored within
 * half a stop of 2^-PRE_EXPOSURE_EV (0.011; exposed, 0.18): 13 stops above the
 * halves' subnormals and 20 below their largest (the sun's disk at noon
 * fits). A fixed scale put twilight among the subnormals and night below
 * them. The scale is the radiance scale times a power of two, so a frame
 * reads back the same, bit for bit, whichever it was stored at, away from
 * the halves' limits (a value subnormal at one scale and not at the other
 * differs by its rounding). The next frame's comes from this frame's
 * adapted exposure (a cut's from its metered one), so a frame's scale
 * depends on the frame before alone; the fog's and clouds' histories are
 * rescaled by the ratio as they are read. A post_input is stored at the
 * radiance scale, so with one the scale stays that.
 */
#define PRE_EXPOSURE_EV 4
/* A cut whose metered scale is more than this many stops from the one it
 * was drawn with is drawn again with the metered one (once). */
#define PRE_EXPOSURE_REDRAW_EV 3
#define PRE_EXPOSURE_MIN_EV (-16)
#define PRE_EXPOSURE_MAX_EV 24

static double metered_frame_scale(const struct sb_renderer *r)
{
    if (r->params.post_input)
        return r->radiance_scale;
    float state[4];
    sb_renderer_exposure(r, state);
    double stops = log2((double)state[1] / r->radiance_scale) - PRE_EXPOSURE_EV;
    if (!isfinite(stops))
        return r->frame_scale;
    stops = fmin(fmax(round(stops), PRE_EXPOSURE_MIN_EV), PRE_EXPOSURE_MAX_EV);
    return r->radiance_scale * exp2(stops);
}

static enum sb_result render_once(struct sb_renderer *r, const struct sb_view *view, bool readback,
                                  struct sb_frame_timings *timings);

enum sb_result sb_renderer_render(struct sb_renderer *r, const struct sb_view *view, bool readback,
                                  struct sb_frame_timings *timings)
{
    r->previous_frame_scale = r->frame_scale;
    r->frame_scale = r->next_frame_scale;
    if (view->fixed_pre_exposure && !r->params.post_input)
        r->frame_scale =
            r->radiance_scale * exp2(fmin(fmax(view->pre_exposure_stops, PRE_EXPOSURE_MIN_EV), PRE_EXPOSURE_MAX_EV));
    enum sb_result res = render_once(r, view, readback, timings);
    if (res)
        return res;
    r->next_frame_scale = metered_frame_scale(r);
    if (view->snap_exposure && !view->fixed_pre_exposure &&
        fabs(log2(r->next_frame_scale / r->frame_scale)) > PRE_EXPOSURE_REDRAW_EV) {
        /* A cut keeps no history, so drawing it again gives the frame it
         * would have been with the right scale; the same jitter too. */
        r->frame_scale = r->next_frame_scale;
        r->frame_index--;
        if ((res = render_once(r, view, readback, timings)))
            return res;
        r->next_frame_scale = metered_frame_scale(r);
    }
    if (readback)
        r->readback_scale = r->frame_scale;
    return SB_OK;
}

/* A pass's start or end. Isolated, every command before the start is done
 * first, and the end's before any command after it. llvmpipe takes a
 * timestamp when its rasteriser threads next run, which a barrier makes
 * them do at once: there both sides of each timestamp get one. */
static void timestamp(struct sb_renderer *r, const struct sb_view *view, uint32_t query, bool start)
{
    bool cpu = r->vk->properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
    if (view->isolate_passes && (start || cpu))
        sb_renderer_barrier(r->cmd);
    if (r->queries)
        vkCmdWriteTimestamp(r->cmd,
                            start && !cpu ? VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT : VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT,
                            r->queries, query);
    if (view->isolate_passes && (!start || cpu))
        sb_renderer_barrier(r->cmd);
}

static enum sb_result render_once(struct sb_renderer *r, const struct sb_view *view, bool readback,
                                  struct sb_frame_timings *timings)
{
    enum sb_result res = SB_OK;
    struct sb_vk *vk = r->vk;
    fill_frame(r, view, r->frame.mapped);
    r->view = view;

    VK(vkResetCommandBuffer(r->cmd, 0));
    VkCommandBufferBeginInfo begin = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
        .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT,
    };
    VK(vkBeginCommandBuffer(r->cmd, &begin));
    sb_graph_begin_frame(r);
    if (r->queries)
        vkCmdResetQueryPool(r->cmd, r->queries, 0, 2 * SB_PASS_COUNT);

    /* A pass whose input was left out is left out too (its `needs`); the
     * passes come in order, so one sweep settles it. */
    uint32_t disabled = 0;
    for (int p = 0; p < SB_PASS_COUNT; p++)
        if (sb_pass_classes[p]->optional &&
            (view->disabled_passes >> p & 1 || (disabled & sb_pass_classes[p]->needs) != 0))
            disabled |= 1u << p;
    for (r->pass = 0; r->pass < SB_PASS_COUNT; r->pass++) {
        int p = r->pass;
        if (p == r->first_post) { /* the lit frame is whole: post-processing takes it from here */
            if (r->params.post_input)
                copy_input(r);
            if (readback)
                copy_image(r, r->hdr_id, &r->read_hdr);
        }
        bool skip = disabled >> p & 1;
        if (!skip)
            sb_graph_before_pass(r, p);
        timestamp(r, view, 2 * p, true);
        if (skip && sb_pass_classes[p]->skipped)
            sb_pass_classes[p]->skipped(r);
        else if (!skip)
            sb_pass_classes[p]->record(r);
        timestamp(r, view, 2 * p + 1, false);
    }

    if (readback) {
        copy_image(r, r->ldr_id, &r->read_ldr);
        if (r->post_in_place)
            copy_image(r, r->hdr_id, &r->read_post);
        copy_image(r, r->sky_view_id, &r->read_sky_view);
        if (r->aerial_id)
            copy_image(r, r->aerial_id, &r->read_aerial);
    }
    sb_graph_end_frame(r);
    VkMemoryBarrier to_host = {
        .sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER,
        .srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT,
        .dstAccessMask = VK_ACCESS_HOST_READ_BIT,
    };
    vkCmdPipelineBarrier(r->cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &to_host, 0,
                         NULL, 0, NULL);
    VK(vkEndCommandBuffer(r->cmd));
    VK(vkResetFences(vk->device, 1, &r->fence));
    VkSubmitInfo submit = {
        .sType = VK_STRUCTURE_TYPE_SUBMIT_INFO,
        .commandBufferCount = 1,
        .pCommandBuffers = &r->cmd,
    };
    VK(vkQueueSubmit(vk->queue, 1, &submit, r->fence));
    VK(vkWaitForFences(vk->device, 1, &r->fence, VK_TRUE, UINT64_MAX));
    r->view = NULL;
    r->frame_index++;

    if (timings) {
        memset(timings, 0, sizeof(*timings));
        if (r->queries) {
            uint64_t ts[2 * SB_PASS_COUNT];
            VK(vkGetQueryPoolResults(vk->device, r->queries, 0, 2 * SB_PASS_COUNT, sizeof(ts), ts, sizeof(uint64_t),
                                     VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
            double to_ms = vk->timestamp_period_ns * 1e-6;
            for (int p = 0; p < SB_PASS_COUNT; p++)
                timings->ms[p] = (double)(ts[2 * p + 1] - ts[2 * p]) * to_ms;
            timings->total_ms = (double)(ts[2 * SB_PASS_COUNT - 1] - ts[0]) * to_ms;
            timings->valid = true;
        }
    }
cleanup:
    return res;
}

/* ---- Reading back ---------------------------------------------------------------- */

void sb_renderer_size(const struct sb_renderer *r, uint32_t *width, uint32_t *height)
{
    *width = r->width;
    *height = r->height;
}

const uint8_t *sb_renderer_ldr(const struct sb_renderer *r)
{
    return r->read_ldr.mapped;
}

static void halves_to_rgb(const uint16_t *src, size_t pixels, double scale, float *rgb)
{
    for (size_t i = 0; i < pixels; i++)
        for (int c = 0; c < 3; c++)
            rgb[i * 3 + c] = (float)(sb_half_to_float(src[i * 4 + c]) / scale);
}

double sb_renderer_stored_scale(const struct sb_renderer *r)
{
    return r->readback_scale;
}

void sb_renderer_hdr(const struct sb_renderer *r, float *rgb)
{
    halves_to_rgb(r->read_hdr.mapped, (size_t)r->width * r->height, r->readback_scale, rgb);
}

void sb_renderer_post_hdr(const struct sb_renderer *r, float *rgb)
{
    const struct sb_buffer *b = r->post_in_place ? &r->read_post : &r->read_hdr;
    halves_to_rgb(b->mapped, (size_t)r->width * r->height, r->readback_scale, rgb);
}

void sb_renderer_sky_view(const struct sb_renderer *r, float *rgb)
{
    halves_to_rgb(r->read_sky_view.mapped, (size_t)SB_SKY_VIEW_WIDTH * SB_SKY_VIEW_HEIGHT, r->readback_scale, rgb);
}

void sb_renderer_aerial(const struct sb_renderer *r, float *rgb)
{
    size_t texels = (size_t)SB_AERIAL_SIZE * SB_AERIAL_SIZE * SB_AERIAL_SIZE;
    halves_to_rgb(r->read_aerial.mapped, texels, r->readback_scale, rgb);
}

void sb_renderer_exposure(const struct sb_renderer *r, float state[4])
{
    const struct sb_exposure_gpu *e =
        (const struct sb_exposure_gpu *)((const uint32_t *)r->exposure.mapped + SB_HISTOGRAM_BINS);
    memcpy(state, e->state, 4 * sizeof(float));
}

bool sb_renderer_project(const struct sb_renderer *r, const double world_m[3], double pixel[2])
{
    double rel[3] = {world_m[0] - r->camera_m[0], world_m[1] - r->camera_m[1], world_m[2] - r->camera_m[2]};
    const double *m = r->view_proj.m;
    double w = m[3] * rel[0] + m[7] * rel[1] + m[11] * rel[2] + m[15];
    if (w <= 0.0)
        return false;
    double ndc[3];
    sb_mat4_project(&r->view_proj, rel, ndc);
    pixel[0] = (ndc[0] * 0.5 + 0.5) * r->width;
    pixel[1] = (ndc[1] * 0.5 + 0.5) * r->height;
    return true;
}

void sb_renderer_pixel_ray(const struct sb_renderer *r, const double pixel[2], double direction[3])
{
    struct sb_mat4 inv = sb_mat4_inverse(&r->view_proj);
    double ndc[3] = {pixel[0] / r->width * 2.0 - 1.0, pixel[1] / r->height * 2.0 - 1.0, 0.5}, p[3];
    sb_mat4_project(&inv, ndc, p);
    double len = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    for (int i = 0; i < 3; i++)
        direction[i] = p[i] / len;
}

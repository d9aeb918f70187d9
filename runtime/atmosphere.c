/*
 * The pack's atmosphere as skyview's passes read it (atmosphere.glsl,
 * SB_ATMOSPHERE_TEXTURES): its parameters, and its transmittance,
 * multiple-scattering and ground-irradiance LUTs as RGBA32F textures in
 * the forms the shaders look up (physics.h); and the radiance scale that
 * makes the sun's largest channel 1.
 */
#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"
#include "physics.h"
#include "renderer_internal.h"
#include "scene.h"

/* A sampled RGBA32F texture of width x height texels from `data`, `channels`
 * floats (3 or more) a texel: the first three, alpha 0. */
static enum sb_result upload_rgba32f(struct sb_renderer *r, const float *data, uint32_t channels, uint32_t width,
                                     uint32_t height, const char *name, struct sb_texture *texture)
{
    size_t texels = (size_t)width * height;
    float *rgba = channels == 4 ? NULL : malloc(texels * 4 * sizeof(float));
    if (channels != 4 && !rgba)
        return SB_ERR_NOMEM;
    for (size_t i = 0; rgba && i < texels; i++)
        for (uint32_t c = 0; c < 4; c++)
            rgba[4 * i + c] = c < 3 ? data[i * channels + c] : 0.0f;
    struct sb_texture_params p = {
        .width = width,
        .height = height,
        .format = VK_FORMAT_R32G32B32A32_SFLOAT,
        .usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
        .name = name,
    };
    enum sb_result res = sb_texture_create(r->vk, &p, texture);
    if (!res)
        res = sb_texture_upload(r->vk, texture, rgba ? rgba : data, texels * 4 * sizeof(float), 4 * sizeof(float));
    free(rgba);
    return res;
}

enum sb_result sb_atmosphere_upload(struct sb_renderer *r, const struct sb_pack *pack)
{
    static const enum sb_product_id needed[] = {SB_PRODUCT_TRANSMITTANCE, SB_PRODUCT_MULTISCATTERING,
                                                SB_PRODUCT_IRRADIANCE_GROUND};
    for (size_t i = 0; i < sizeof(needed) / sizeof(needed[0]); i++)
        if (!pack->present[needed[i]]) {
            sb_error("the pack has no %s, which skyview needs: bake a scene that asks for it",
                     sb_product_name(needed[i]));
            return SB_ERR_USAGE;
        }
    const struct sb_atmosphere_params *atm = &pack->scene->atmosphere;
    struct sb_atmosphere_gpu gpu;
    sb_atmosphere_gpu_pack(atm, &gpu);
    double sun_max = fmax(atm->solar_irradiance[0], fmax(atm->solar_irradiance[1], atm->solar_irradiance[2]));
    r->radiance_scale = sun_max > 0.0 ? 1.0 / sun_max : 1.0;
    /* The pack's radiance is relative to its solar irradiance; the sun's
     * illuminance above the atmosphere makes it absolute. */
    static const double weights[3] = {SB_LUMINANCE_RGB};
    double sun_y = weights[0] * atm->solar_irradiance[0] + weights[1] * atm->solar_irradiance[1] +
                   weights[2] * atm->solar_irradiance[2];
    double lux = r->params.sun_illuminance_lux > 0.0 ? r->params.sun_illuminance_lux : SB_EARTH_SUN_LUX;
    r->cd_m2_per_unit = sun_y > 0.0 ? lux / sun_y : lux;
    r->frame_scale = r->previous_frame_scale = r->next_frame_scale = r->readback_scale = r->radiance_scale;
    r->ground_radius_km = atm->ground_radius_km;
    r->thickness_km = gpu.radii[3];

    const struct sb_image *t = &pack->images[SB_PRODUCT_TRANSMITTANCE];
    enum sb_result res = sb_renderer_upload(r, &gpu, sizeof(gpu), "atmosphere parameters", &r->atmosphere);
    /* Each as RGBA32F (atmosphere.glsl, SB_ATMOSPHERE_TEXTURES): the
     * transmittance LUT's and the ground irradiance's lookup forms; psi_ms
     * refined. */
    float *depth = res ? NULL : malloc(sb_lookup_float_count(SB_PRODUCT_TRANSMITTANCE) * sizeof(float));
    if (!res && !depth)
        res = SB_ERR_NOMEM;
    if (!res) {
        sb_lookup_fill(SB_PRODUCT_TRANSMITTANCE, t, depth);
        res = upload_rgba32f(r, depth, 3, t->width, t->height, "transmittance (optical depth)", &r->transmittance);
    }
    free(depth);
    float *refined = res ? NULL : malloc(sb_multiscattering_refined_float_count() * sizeof(float));
    if (!res && !refined)
        res = SB_ERR_NOMEM;
    if (!res) {
        sb_multiscattering_refined_fill(&pack->images[SB_PRODUCT_MULTISCATTERING], refined);
        res = upload_rgba32f(r, refined, 4, SB_MULTISCATTERING_REFINED_SIZE, SB_MULTISCATTERING_REFINED_SIZE,
                             "multiscattering (refined)", &r->multiscattering);
    }
    free(refined);
    /* The orders product, where the pack has it (every view kernel is
     * specialized on it: pass.c), else a 1 x 1 stand-in nothing reads. */
    const struct sb_image *orders = &pack->images[SB_PRODUCT_ORDERS];
    r->has_orders = !res && pack->present[SB_PRODUCT_ORDERS];
    VkFormatProperties rgba32f;
    vkGetPhysicalDeviceFormatProperties(r->vk->physical_device, VK_FORMAT_R32G32B32A32_SFLOAT, &rgba32f);
    if (r->has_orders && !(rgba32f.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT)) {
        /* optional in Vulkan; the shaders read the orders bilinearly (view.glsl) */
        sb_warn("skyview: this device cannot filter RGBA32F textures: the pack's orders are not used (Hillaire's "
                "multiple scattering instead)");
        r->has_orders = false;
    }
    memset(&r->orders_grid, 0, sizeof(r->orders_grid));
    if (r->has_orders) {
        sb_orders_grid_pack(atm, SB_ORDERS_R, SB_ORDERS_MU, SB_ORDERS_MU_S, SB_ORDERS_NU, &r->orders_grid);
        res = upload_rgba32f(r, orders->data, 3, orders->width, orders->height, "orders", &r->orders);
    } else if (!res) {
        const float none[3] = {0, 0, 0};
        res = upload_rgba32f(r, none, 3, 1, 1, "orders (none)", &r->orders);
    }
    r->specialization_entry =
        (VkSpecializationMapEntry){.constantID = SB_VIEW_CONSTANT_ORDERS, .offset = 0, .size = sizeof(VkBool32)};
    r->specialization = (VkSpecializationInfo){.mapEntryCount = 1,
                                               .pMapEntries = &r->specialization_entry,
                                               .dataSize = sizeof(VkBool32),
                                               .pData = &r->has_orders};
    float ground[SB_IRRADIANCE_WIDTH * 2 * 3]; /* two rows (physics.h) */
    assert(sb_lookup_float_count(SB_PRODUCT_IRRADIANCE_GROUND) == sizeof(ground) / sizeof(ground[0]));
    if (!res) {
        sb_lookup_fill(SB_PRODUCT_IRRADIANCE_GROUND, &pack->images[SB_PRODUCT_IRRADIANCE_GROUND], ground);
        res = upload_rgba32f(r, ground, 3, SB_IRRADIANCE_WIDTH, 2, "irradiance_ground (lookup)", &r->irradiance_ground);
    }
    return res;
}

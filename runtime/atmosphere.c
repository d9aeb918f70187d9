/*
 * The pack's atmosphere as skyview's passes read it (atmosphere.glsl,
 * SB_ATMOSPHERE_TEXTURES): its parameters, and its transmittance,
 * multiple-scattering and ground-irradiance LUTs as RGBA32F textures in
 * the forms the shaders look up (physics.h); and the radiance scale that
 * makes the sun's largest channel 1.
 */
#include <assert.h>
#include <cJSON.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"
#include "physics.h"
#include "renderer_internal.h"
#include "scene.h"
#include "spectrum.h"

/* A sampled RGBA32F texture of width x height texels in `layers` layers
 * (a 2D array when `array`) from data[layer]: `channels` floats (3 or
 * more) a texel, the first three its rgb (alpha 0). */
static enum sb_result upload_rgba32f(struct sb_renderer *r, const float *const *data, uint32_t layers, bool array,
                                     uint32_t channels, uint32_t width, uint32_t height, const char *name,
                                     struct sb_texture *texture)
{
    size_t texels = (size_t)width * height;
    float *rgba = malloc(texels * layers * 4 * sizeof(float));
    if (!rgba)
        return SB_ERR_NOMEM;
    for (uint32_t l = 0; l < layers; l++)
        for (size_t i = 0; i < texels; i++)
            for (uint32_t c = 0; c < 4; c++)
                rgba[4 * (l * texels + i) + c] = c < 3 ? data[l][i * channels + c] : 0.0f;
    struct sb_texture_params p = {
        .width = width,
        .height = height,
        .layers = layers,
        .array = array,
        .format = VK_FORMAT_R32G32B32A32_SFLOAT,
        .usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
        .name = name,
    };
    enum sb_result res = sb_texture_create(r->vk, &p, texture);
    if (!res)
        res = sb_texture_upload(r->vk, texture, rgba, texels * layers * 4 * sizeof(float), 4 * sizeof(float));
    free(rgba);
    return res;
}

/* Product `id`'s lookup form (physics.h), `rows` rows, for layer 0 and,
 * with the bands, each band's from spectral product `spectral` in layer
 * 1 + b, uploaded as a 2D array. */
static enum sb_result upload_layers(struct sb_renderer *r, const struct sb_pack *pack, enum sb_product_id id,
                                    enum sb_product_id spectral, uint32_t rows, const char *name,
                                    struct sb_texture *texture)
{
    uint32_t layers = r->constants.bands ? 1 + SB_SPECTRAL_BANDS : 1;
    size_t floats = sb_lookup_float_count(id);
    float *lookup = malloc(floats * layers * sizeof(float));
    const float *data[1 + SB_SPECTRAL_BANDS];
    if (!lookup)
        return SB_ERR_NOMEM;
    enum sb_result res = SB_OK;
    for (uint32_t l = 0; l < layers && !res; l++) {
        struct sb_image band = {0};
        data[l] = lookup + l * floats;
        if (l > 0)
            res = sb_spectral_band_image(&pack->images[spectral], id, (int)l - 1, &band);
        if (!res)
            sb_lookup_fill(id, l > 0 ? &band : &pack->images[id], lookup + l * floats);
        sb_image_finish(&band);
    }
    if (!res)
        res = upload_rgba32f(r, data, layers, true, 3, pack->images[id].width, rows, name, texture);
    free(lookup);
    return res;
}

/* The orders' grid an artifact was baked on, as its settings record it,
 * against the one this build reads (sb_orders_grid_pack): its top and its
 * azimuth nodes' power. A pack of another grid, same in shape, would be
 * read between the wrong nodes without a word. A field a build before it
 * did not write stands for the grid that build had: the atmosphere's top,
 * uniform azimuths. */
static enum sb_result orders_grid_check(const struct sb_artifact *a, const struct sb_atmosphere_params *atm)
{
    struct {
        const char *field, *what, *unit;
        double before, now;
    } grid[] = {
        {"top_km", "ending at radius", " km", atm->top_radius_km, sb_orders_top_km(atm)},
        {"nu_power", "with azimuth nodes at the power", "", 1.0, sb_orders_azimuth_power(atm)},
    };
    cJSON *settings = cJSON_Parse(a->settings_json[0] ? a->settings_json : "{}");
    enum sb_result res = SB_OK;
    for (size_t i = 0; i < sizeof(grid) / sizeof(grid[0]) && !res; i++) {
        const cJSON *v = cJSON_GetObjectItemCaseSensitive(settings, grid[i].field);
        double baked = cJSON_IsNumber(v) ? v->valuedouble : grid[i].before;
        if (fabs(baked - grid[i].now) > 1e-9 * fabs(grid[i].now)) {
            sb_error(
                "%s: baked on a grid of the orders %s %.9g%s (settings.%s), where this build reads them %s %.9g%s: "
                "rebake needed",
                a->file, grid[i].what, baked, grid[i].unit, grid[i].field, grid[i].what, grid[i].now, grid[i].unit);
            res = SB_ERR_VERSION;
        }
    }
    cJSON_Delete(settings);
    return res;
}

enum sb_result sb_renderer_check_pack(const struct sb_pack *pack)
{
    static const enum sb_product_id tables[] = {SB_PRODUCT_ORDERS, SB_PRODUCT_SPECTRAL_ORDERS};
    for (size_t i = 0; i < sizeof(tables) / sizeof(tables[0]); i++) {
        enum sb_result res =
            pack->present[tables[i]] ? orders_grid_check(&pack->artifacts[tables[i]], &pack->scene->atmosphere) : SB_OK;
        if (res)
            return res;
    }
    return SB_OK;
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
    enum sb_result grid = sb_renderer_check_pack(pack);
    if (grid)
        return grid;
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

    /* The spectral products, where the pack has all three and the orders:
     * the sky at 12 wavelengths in four bands of three (view.glsl). */
    bool spectral = pack->present[SB_PRODUCT_SPECTRAL_TRANSMITTANCE] &&
                    pack->present[SB_PRODUCT_SPECTRAL_IRRADIANCE_GROUND] && pack->present[SB_PRODUCT_SPECTRAL_ORDERS];
    r->constants.orders = pack->present[SB_PRODUCT_ORDERS];
    VkFormatProperties rgba32f;
    vkGetPhysicalDeviceFormatProperties(r->vk->physical_device, VK_FORMAT_R32G32B32A32_SFLOAT, &rgba32f);
    if ((r->constants.orders || spectral) &&
        !(rgba32f.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT)) {
        /* optional in Vulkan; the shaders read the orders bilinearly (view.glsl) */
        sb_warn("this device cannot filter RGBA32F textures: the pack's orders%s are not used (Hillaire's "
                "multiple scattering, in three channels, instead)",
                spectral ? " and spectral products" : "");
        r->constants.orders = false;
        spectral = false;
    }
    if (spectral && !r->constants.orders)
        sb_warn("the pack has the spectral products but not the orders: its sky is drawn in three channels");
    r->constants.bands = spectral && r->constants.orders;
    r->constants.band_lanes = r->constants.bands ? SB_SPECTRAL_BANDS : 1;
    struct sb_atmosphere_gpu layers[1 + SB_SPECTRAL_BANDS];
    layers[0] = gpu;
    for (int b = 0; r->constants.bands && b < SB_SPECTRAL_BANDS; b++) {
        struct sb_atmosphere_params band;
        sb_spectral_band(atm, b, &band);
        sb_atmosphere_gpu_pack(&band, &layers[1 + b]);
    }
    double k[SB_SPECTRAL_WAVELENGTHS][3];
    sb_spectral_to_rec709(atm->solar_irradiance, k);
    for (int i = 0; i < SB_SPECTRAL_WAVELENGTHS; i++)
        for (int c = 0; c < 4; c++)
            r->spectral_rgb[i][c] = c < 3 && r->constants.bands ? (float)k[i][c] : 0.0f;

    enum sb_result res = sb_renderer_upload(r, layers, (r->constants.bands ? 1 + SB_SPECTRAL_BANDS : 1) * sizeof(gpu),
                                            "atmosphere parameters", &r->atmosphere);
    /* Each as RGBA32F (atmosphere.glsl, SB_ATMOSPHERE_TEXTURES): the
     * transmittance LUT's and the ground irradiance's lookup forms; psi_ms
     * refined. */
    if (!res)
        res = upload_layers(r, pack, SB_PRODUCT_TRANSMITTANCE, SB_PRODUCT_SPECTRAL_TRANSMITTANCE,
                            pack->images[SB_PRODUCT_TRANSMITTANCE].height, "transmittance (optical depth)",
                            &r->transmittance);
    float *refined = res ? NULL : malloc(sb_multiscattering_refined_float_count() * sizeof(float));
    if (!res && !refined)
        res = SB_ERR_NOMEM;
    if (!res) {
        sb_multiscattering_refined_fill(&pack->images[SB_PRODUCT_MULTISCATTERING], refined);
        res = upload_rgba32f(r, (const float *const[1]){refined}, 1, false, 4, SB_MULTISCATTERING_REFINED_SIZE,
                             SB_MULTISCATTERING_REFINED_SIZE, "multiscattering (refined)", &r->multiscattering);
    }
    free(refined);
    /* The orders product, where the pack has it (every view kernel is
     * specialized on it: pass.c), else a 1 x 1 stand-in nothing reads; with
     * the bands, each band's in a layer of its own. */
    memset(&r->orders_grid, 0, sizeof(r->orders_grid));
    if (!res && r->constants.orders) {
        sb_orders_grid_pack(atm, SB_ORDERS_R, sb_orders_mu_nodes(atm), sb_orders_mu_s_nodes(atm),
                            sb_orders_nu_nodes(atm), &r->orders_grid);
        const struct sb_image *orders = &pack->images[SB_PRODUCT_ORDERS];
        struct sb_image bands[SB_SPECTRAL_BANDS] = {{0}};
        const float *data[1 + SB_SPECTRAL_BANDS] = {orders->data};
        uint32_t orders_layers = r->constants.bands ? 1 + SB_SPECTRAL_BANDS : 1;
        for (uint32_t l = 1; l < orders_layers && !res; l++) {
            res = sb_spectral_band_image(&pack->images[SB_PRODUCT_SPECTRAL_ORDERS], SB_PRODUCT_ORDERS, (int)l - 1,
                                         &bands[l - 1]);
            data[l] = bands[l - 1].data;
        }
        if (!res)
            res = upload_rgba32f(r, data, orders_layers, true, 3, orders->width, orders->height, "orders", &r->orders);
        for (int b = 0; b < SB_SPECTRAL_BANDS; b++)
            sb_image_finish(&bands[b]);
    } else if (!res) {
        const float none[3] = {0, 0, 0};
        res = upload_rgba32f(r, (const float *const[1]){none}, 1, true, 3, 1, 1, "orders (none)", &r->orders);
    }
    r->specialization_entries[0] =
        (VkSpecializationMapEntry){.constantID = SB_VIEW_CONSTANT_ORDERS, .offset = 0, .size = sizeof(VkBool32)};
    r->specialization_entries[1] = (VkSpecializationMapEntry){
        .constantID = SB_VIEW_CONSTANT_BANDS, .offset = sizeof(VkBool32), .size = sizeof(VkBool32)};
    r->specialization_entries[2] = (VkSpecializationMapEntry){
        .constantID = SB_VIEW_CONSTANT_BAND_LANES, .offset = 2 * sizeof(VkBool32), .size = sizeof(uint32_t)};
    r->specialization = (VkSpecializationInfo){.mapEntryCount = 3,
                                               .pMapEntries = r->specialization_entries,
                                               .dataSize = sizeof(r->constants),
                                               .pData = &r->constants};
    assert(sb_lookup_float_count(SB_PRODUCT_IRRADIANCE_GROUND) == SB_IRRADIANCE_WIDTH * 2 * 3); /* two rows */
    if (!res)
        res = upload_layers(r, pack, SB_PRODUCT_IRRADIANCE_GROUND, SB_PRODUCT_SPECTRAL_IRRADIANCE_GROUND, 2,
                            "irradiance_ground (lookup)", &r->irradiance_ground);
    return res;
}

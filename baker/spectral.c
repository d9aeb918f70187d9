#include "spectral.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"
#include "spectrum.h"

struct sb_spectral {
    struct sb_vk *vk;
    struct sb_orders_settings orders_grid; /* the scene's (sb_orders_product_grid), every band's */
    struct sb_atmosphere_params bands[SB_SPECTRAL_BANDS];
    struct sb_atmosphere_baker *bakers[SB_SPECTRAL_BANDS];
    struct sb_image luts[SB_SPECTRAL_BANDS][SB_PRODUCT_COUNT]; /* by three-channel id; empty until baked */
    struct sb_orders_result orders[SB_SPECTRAL_BANDS];
};

enum sb_result sb_spectral_create(struct sb_vk *vk, const struct sb_atmosphere_params *p, struct sb_spectral **out)
{
    *out = NULL;
    struct sb_spectral *s = calloc(1, sizeof(*s));
    if (!s)
        return SB_ERR_NOMEM;
    s->vk = vk;
    s->orders_grid = sb_orders_product_grid(p);
    enum sb_result res = SB_OK;
    for (int b = 0; b < SB_SPECTRAL_BANDS && !res; b++) {
        sb_spectral_band(p, b, &s->bands[b]);
        res = sb_atmosphere_baker_create(vk, &s->bands[b], &s->bakers[b]);
    }
    if (res) {
        sb_spectral_destroy(&s);
        return res;
    }
    *out = s;
    return SB_OK;
}

void sb_spectral_destroy(struct sb_spectral **s)
{
    if (!*s)
        return;
    for (int b = 0; b < SB_SPECTRAL_BANDS; b++) {
        sb_atmosphere_baker_destroy(&(*s)->bakers[b]);
        for (int i = 0; i < SB_PRODUCT_COUNT; i++)
            sb_image_finish(&(*s)->luts[b][i]);
    }
    free(*s);
    *s = NULL;
}

enum sb_product_id sb_spectral_base(enum sb_product_id id)
{
    switch (id) {
    case SB_PRODUCT_SPECTRAL_TRANSMITTANCE:
        return SB_PRODUCT_TRANSMITTANCE;
    case SB_PRODUCT_SPECTRAL_IRRADIANCE_GROUND:
        return SB_PRODUCT_IRRADIANCE_GROUND;
    case SB_PRODUCT_SPECTRAL_ORDERS:
        return SB_PRODUCT_ORDERS;
    default:
        return SB_PRODUCT_COUNT;
    }
}

const struct sb_atmosphere_params *sb_spectral_band_params(const struct sb_spectral *s, int band)
{
    return &s->bands[band];
}

enum sb_result sb_spectral_band_lut(struct sb_spectral *s, int band, enum sb_product_id id, const struct sb_image **out,
                                    double *gpu_ms)
{
    struct sb_image *image = &s->luts[band][id];
    enum sb_result res = SB_OK;
    if (!image->data) {
        /* what the product reads first: the orders read all three LUTs */
        static const enum sb_product_id reads[] = {SB_PRODUCT_TRANSMITTANCE, SB_PRODUCT_MULTISCATTERING,
                                                   SB_PRODUCT_IRRADIANCE_GROUND};
        for (size_t i = 0; i < sizeof(reads) / sizeof(reads[0]) && reads[i] < id && !res; i++) {
            const struct sb_image *unused;
            res = sb_spectral_band_lut(s, band, reads[i], &unused, gpu_ms);
        }
        if (res)
            return res;
        double ms = 0;
        if (id == SB_PRODUCT_ORDERS) {
            res = sb_orders_bake(s->vk, s->bakers[band], &s->bands[band], &s->orders_grid, image, &s->orders[band]);
            ms = s->orders[band].gpu_ms;
        } else {
            res = sb_atmosphere_bake(s->bakers[band], id, NULL, image, NULL, &ms);
        }
        if (res) {
            sb_image_finish(image);
            return res;
        }
        if (gpu_ms)
            *gpu_ms += ms;
    }
    *out = image;
    return SB_OK;
}

enum sb_result sb_spectral_bake(struct sb_spectral *s, enum sb_product_id id, struct sb_image *image, double *gpu_ms,
                                struct sb_orders_result *orders)
{
    enum sb_product_id base = sb_spectral_base(id);
    if (base == SB_PRODUCT_COUNT)
        return SB_ERR_USAGE;
    const struct sb_product_format *f = sb_product_format(id);
    double ms = 0;
    enum sb_result res = SB_OK;
    const struct sb_image *bands[SB_SPECTRAL_BANDS];
    for (int b = 0; b < SB_SPECTRAL_BANDS && !res; b++)
        res = sb_spectral_band_lut(s, b, base, &bands[b], &ms);
    /* the bands' shape: products.def's, or the scene's where the atmosphere
     * family sets it (the orders of a dust: sb_orders_nu_nodes, _mu_nodes) */
    for (int b = 0; b < SB_SPECTRAL_BANDS && !res; b++)
        if (bands[b]->width != bands[0]->width || bands[b]->height != bands[0]->height ||
            bands[b]->channel_count * SB_SPECTRAL_BANDS != f->channel_count)
            res = SB_ERR_USAGE; /* products.def's channels and the three-channel bakes disagree */
    if (!res)
        res = sb_image_init(image, bands[0]->width, bands[0]->height, f->channel_count);
    if (res)
        return res;
    sb_image_set_channel_names(image, f->channel_names);
    uint32_t base_channels = bands[0]->channel_count, texels = image->width * image->height;
    for (int b = 0; b < SB_SPECTRAL_BANDS; b++)
        for (uint32_t i = 0; i < texels; i++)
            for (uint32_t ch = 0; ch < base_channels; ch++)
                image->data[(size_t)i * f->channel_count + sb_spectral_channel(ch, (int)b)] =
                    bands[b]->data[(size_t)i * base_channels + ch];
    if (gpu_ms)
        *gpu_ms = ms;
    if (orders) {
        *orders = (struct sb_orders_result){0};
        for (int b = 0; b < SB_SPECTRAL_BANDS; b++) {
            if (s->orders[b].orders > orders->orders)
                orders->orders = s->orders[b].orders;
            if (s->orders[b].last_share > orders->last_share)
                orders->last_share = s->orders[b].last_share;
            for (int c = 0; c < 3; c++)
                orders->tail[c] = fmax(orders->tail[c], s->orders[b].tail[c]);
            orders->gpu_ms += s->orders[b].gpu_ms;
        }
    }
    return SB_OK;
}

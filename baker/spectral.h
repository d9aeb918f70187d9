/*
 * The sky at 12 wavelengths (physics/spectrum.h; format version 15): the
 * atmosphere's transmittance, irradiance_ground and orders baked for each
 * band of three wavelengths by the three-channel kernels, one baker a band,
 * and interleaved into the spectral products: base channel g * 3 + c of
 * band b is the spectral product's channel g * 12 + 3 b + c (the
 * transmittance's and the orders' 12 wavelengths; the ground irradiance's
 * 12 direct, then 12 from the sky). A band's products are baked when first
 * needed, with the products they read, and kept.
 */
#ifndef SB_BAKER_SPECTRAL_H
#define SB_BAKER_SPECTRAL_H

#include "atmosphere.h"
#include "compute.h"
#include "image.h"
#include "orders.h"

struct sb_spectral;

enum sb_result sb_spectral_create(struct sb_vk *vk, const struct sb_atmosphere_params *p, struct sb_spectral **out);
void sb_spectral_destroy(struct sb_spectral **s); /* accepts a pointer to NULL */

/* The three-channel product a spectral product holds at 12 wavelengths
 * (SB_PRODUCT_COUNT for any other). */
enum sb_product_id sb_spectral_base(enum sb_product_id id);

/* Band `band`'s scene (sb_spectral_band) and its three-channel product
 * `id` (transmittance, multiscattering, irradiance_ground or orders),
 * baked on first use; *gpu_ms (may be NULL) gets what baking it took. */
const struct sb_atmosphere_params *sb_spectral_band_params(const struct sb_spectral *s, int band);
enum sb_result sb_spectral_band_lut(struct sb_spectral *s, int band, enum sb_product_id id, const struct sb_image **out,
                                    double *gpu_ms);

/* Spectral product `id` into `image` (initialised here); the orders'
 * result (the most orders over the bands, their GPU time summed) to
 * *orders where not NULL. */
enum sb_result sb_spectral_bake(struct sb_spectral *s, enum sb_product_id id, struct sb_image *image, double *gpu_ms,
                                struct sb_orders_result *orders);

#endif

/*
 * The orders product: multiple scattering by orders (Bruneton and Neyret
 * 2008, Bruneton 2017) on the GPU, orders 2 and up summed on the grid of
 * orders_ref.h (its fp64 reference), which states the grid. Three kernels
 * (shaders/bake/orders.comp): single scattering at the nodes once, then per
 * order the scattering density (the previous order's radiance over the
 * sphere, against the phase functions) and its integral along each node's
 * view; orders are added until one adds less than the settings' tolerance
 * of the sum's largest value, and the orders after the last as its tail
 * (sb_orders_tail_factor, on the host: the sums of the last two orders).
 * The ground's irradiance of each order lights the next but one. Where
 * Mie's phase is a narrow peak (sb_orders_medium) the orders are computed
 * in its delta-M medium, with a transmittance LUT of the medium's own, and
 * the table adds the light the peak carries forward that the air then
 * scatters once (docs/pack.md).
 *
 * The image: rgb radiance (solar_irradiance's unit per steradian) of
 * orders 2 and up, node (ir, imu, imus, inu) at texel
 * x = imus * nu + inu, y = ir * mu + imu (width mu_s * nu, height
 * r * mu + 1); the last row holds the ground's irradiance from the sky
 * (orders 1 and up, solar_irradiance's unit) at mu_s node imus, at every x
 * = imus * nu + inu alike.
 */
#ifndef SB_BAKER_ORDERS_H
#define SB_BAKER_ORDERS_H

#include "atmosphere.h"
#include "compute.h"
#include "image.h"
#include "orders_ref.h"

/* The product's grid for an atmosphere (config.h's SB_ORDERS_*, format
 * version 14; a dust's nodes: sb_orders_mu_nodes, _mu_s_nodes, _nu_nodes). A
 * spectral band's is its scene's. */
struct sb_orders_settings sb_orders_product_grid(const struct sb_atmosphere_params *scene_atmosphere);

struct sb_orders_result {
    int orders;        /* the last order computed */
    double last_share; /* its largest value over the sum's */
    double tail[3];    /* the factor of its radiance added for the orders after it (orders_ref.h) */
    double gpu_ms;
};

/* Bake with `baker`'s parameters and transmittance LUT (baked or adopted
 * before): SB_ERR_USAGE for a grid outside 2 to SB_ORDERS_MAX_NODES a
 * dimension (mu at least 4) or orders outside 2 to SB_ORDERS_MAX_ORDER. */
enum sb_result sb_orders_bake(struct sb_vk *vk, struct sb_atmosphere_baker *baker, const struct sb_atmosphere_params *p,
                              const struct sb_orders_settings *settings, struct sb_image *image,
                              struct sb_orders_result *result);

/* The sky skybake shows with the orders product: single scattering with
 * the transmittance LUT (sb_ref_sky_radiance), orders 2 and up from the
 * table, and where the view ends on the ground, the ground lit by the sun
 * and by the table's irradiance. `grid`: sb_orders_grid_create's of the
 * product's grid. */
void sb_orders_product_sky(const struct sb_atmosphere_params *p, const struct sb_orders_ref *grid,
                           const struct sb_image *orders, const struct sb_image *transmittance, double h, double mu,
                           double mu_s, double nu, double out[3]);

/*
 * How far Hillaire's multiple scattering (the baked multiscattering and
 * irradiance_ground LUTs with transmittance, baked[]) leaves the sky from
 * the one the orders give (`orders`, this product's image; its grid the
 * format's), seen from altitude_km at sky-error's views and the suns
 * given (elevations in degrees): the rms and the largest of the relative
 * differences over views and channels, each relative to the orders' sky
 * floored at 1e-3 of its brightest value in that channel and sun.
 */
void sb_orders_hillaire_error(const struct sb_atmosphere_params *p, const struct sb_image baked[SB_PRODUCT_COUNT],
                              const struct sb_image *orders, double altitude_km, const double *suns_deg, int sun_count,
                              double *rms, double *worst);

/* The kernels sb_orders_bake makes (its stages, orders.comp); returns their count. */
#define SB_ORDERS_KERNEL_COUNT 5
uint32_t sb_orders_kernels(struct sb_pipeline_params out[SB_ORDERS_KERNEL_COUNT]);

/* XXH3-128 of the kernels' SPIR-V, for the product's bake key. */
void sb_orders_code_hash(char out[SB_HASH_HEX_SIZE]);

#endif

/*
 * Multiple scattering by orders in fp64 (Bruneton and Neyret 2008, as
 * Bruneton 2017 restates it): the reference of issue 50's orders product,
 * written from the definitions, not from the GPU kernels.
 *
 * The table holds, on a grid of (r, mu, mu_s, nu), the radiance reaching r
 * along the view (cosine mu to the vertical) from light scattered two times
 * or more in the air on its way there, summed over orders 2 to N; ground
 * bounces count as orders too (a ground bounce then a scattering is
 * order 2). Order k at a point is the integral along the view ray of the
 * transmittance times the scattering density J_k, the phase-weighted
 * integral over the sphere of order k - 1's radiance at that point (the
 * ground's, where a direction ends on it: albedo / pi times its irradiance
 * of order k - 2, the direct sun being order 0). Orders are added until
 * an order's largest value on the grid is under `tolerance` of the sum's
 * largest, or `max_order` is reached; the orders after the last, K, are
 * added as its tail: once light has spread, each order is the last times
 * a ratio rho, and orders K + 1 on sum to order K times rho / (1 - rho)
 * (sb_orders_tail_factor), the ground's orders K on likewise from its
 * order K - 1. The ground's irradiance of every order is kept
 * too, so that a view that ends on the ground can be lit by all of it.
 *
 * The grid (all nodes on the edges of their ranges) ends at its top,
 * sb_orders_top_km: the atmosphere's, or lower where the air above it holds
 * under 1e-6 of its column (the thick atmosphere's grid ends 110 km up);
 * its nodes' rays run on through the air to the atmosphere's top, reading
 * the table above the grid at its top, and a view from above the grid
 * reads it where it enters it:
 * - r: altitudes in a geometric progression from the ground to the top, the
 *   first step a quarter of the smaller scale height (the nodes follow the
 *   air however thick the atmosphere);
 * - mu: two halves, rays that end on the ground and rays that leave the
 *   grid, each uniform in the ray's length to the ground or the grid's top
 *   between its extremes (straight down or up, and the horizon), as
 *   Bruneton's mapping;
 * - mu_s: half the nodes uniform from -H / top (H = sqrt(top^2 - R^2):
 *   below it no point of the grid sees the sun) to 0.1, the rest on
 *   to 1; read linearly, but geometrically between two nodes below the
 *   horizon, where twilight falls exponentially;
 * - nu: the sun's azimuth about the vertical from the view's, over [0, pi]
 *   (every node a real direction) at pi x^p, x uniform, p the
 *   atmosphere's (sb_orders_azimuth_power: 2 for the air, its nodes close
 *   about the sun where twilight's light is; 1 for a dust), read linearly
 *   in x.
 * Between nodes, multilinear otherwise. A view's read of the sum (the
 * sky's, and sb_orders_table_read's), where Mie outscatters Rayleigh at
 * the ground with a peaked phase (sb_orders_log_azimuth: a peaked dust's
 * forward peak, the haze), takes the
 * azimuth by day log-trigonometrically through every azimuth node instead,
 * kept between the two about it (the orders' own reads stay linear). The density's integral over the
 * sphere takes Rayleigh's part on Gauss-Legendre nodes on either side of
 * the horizon, and Mie's at quantiles of Henyey-Greenstein's scattering
 * angle about the view (weighted by Cornette-Shanks over it), so that a
 * narrow forward peak (g = 0.99) is resolved. The sun's transmittance and
 * the views' come from an fp64 table of the optical depth to the top
 * (1024 x 1024, the transmittance LUT's mapping, bilinear in depth): T
 * within 1.3e-4 of exact for the earth, 5e-6 for mars and 3.3e-3 for the
 * thick atmosphere (the worst of 2e5 random rays; 256 rows gave 6.7e-4,
 * 1.8e-5 and 2.2e-2).
 * The sun is a point: its light stops where the planet hides its centre,
 * as in the path tracer.
 *
 * Where Mie's phase is a narrow forward peak (sb_orders_medium: g at least
 * SB_ORDERS_DELTA_M_G) the orders are computed in its delta-M medium on
 * the medium's grid, and the table adds the light the peak carries forward
 * that the air then scatters once (single scattering in the medium less
 * the same smooth scattering in the atmosphere's transmittance), the
 * ground's row the sun the peak carries to the ground; the sky
 * (sb_orders_ref_sky) draws single scattering in the atmosphere itself.
 */
#ifndef SB_BAKER_ORDERS_REF_H
#define SB_BAKER_ORDERS_REF_H

#include <stdbool.h>

#include "scene.h"

struct sb_orders_settings {
    int r, mu, mu_s, nu; /* nodes; 0: 16, 64, 24, 8 (mu even) */
    int max_order;       /* 0: 16 */
    double tolerance;    /* 0: 1e-3 */
};

/* The settings with their defaults filled in (mu even). */
struct sb_orders_settings sb_orders_settings_resolve(const struct sb_orders_settings *s);

struct sb_orders_ref; /* opaque */

/* The grid alone, to read a table of it (sb_orders_table_read): what the
 * orders product's image holds; destroyed as a reference is. NULL on
 * failure (memory). */
struct sb_orders_ref *sb_orders_grid_create(const struct sb_atmosphere_params *p, const struct sb_orders_settings *s);

/* Node `index`'s view, in the table's node order (ir, imu, imus, inu,
 * the last fastest): its altitude (km) and cosines; and the sun cosine of
 * mu_s node imus (the ground row's). */
void sb_orders_grid_node(const struct sb_orders_ref *grid, size_t index, double *h, double *mu, double *mu_s,
                         double *nu);
double sb_orders_grid_mu_s(const struct sb_orders_ref *grid, int imus);

/* Orders 2 and up seen from altitude h along (mu, mu_s, nu), read from
 * `table` (rgb a node, the product's texel order) as the reference reads
 * its own. */
void sb_orders_table_read(const struct sb_orders_ref *grid, const float *table, double h, double mu, double mu_s,
                          double nu, double out[3]);

/* The ground's irradiance from the sky at sun cosine mu_s, read from the
 * row after the table's nodes (the orders product's last row). */
void sb_orders_table_ground(const struct sb_orders_ref *grid, const float *table, double mu_s, double out[3]);

/* The factor rho / (1 - rho) of the last order's radiance that stands for
 * every order after it, of one channel: rho the ratio of the last order's
 * sum over the grid's nodes to the order's before (the earth's red, green
 * and blue fall by 0.17, 0.26 and 0.41 an order from order 6 on, mars's
 * dust by 0.51, 0.47 and 0.38 from order 8), at most
 * SB_ORDERS_TAIL_MAX_RATIO; 0 where either sum is 0 (order 2, the first
 * the table holds, has none before it). */
double sb_orders_tail_factor(double last, double before);

/* Compute the orders; NULL on failure (memory). Uses every core. */
struct sb_orders_ref *sb_orders_ref_create(const struct sb_atmosphere_params *p, const struct sb_orders_settings *s);
void sb_orders_ref_destroy(struct sb_orders_ref **ref);

/* The orders computed, and the largest share of the last one (what it
 * added over what was there, at the node where that was largest). */
int sb_orders_ref_orders(const struct sb_orders_ref *ref);
double sb_orders_ref_last_share(const struct sb_orders_ref *ref);

/* Orders 2 and up at node (ir, imu, imus, inu), the table itself. */
void sb_orders_ref_node(const struct sb_orders_ref *ref, int ir, int imu, int imus, int inu, double out[3]);

/* The ground's irradiance from the sky, orders 1 to N - 1, at mu_s node imus. */
void sb_orders_ref_ground(const struct sb_orders_ref *ref, int imus, double out[3]);

/* The sky's radiance seen from altitude h (km) along (mu, mu_s, nu), in
 * solar_irradiance's unit per steradian: single scattering integrated
 * exactly, orders 2 and up from the table, and where the view ends on the
 * ground the ground lit by the sun and every order of the sky. Above the
 * atmosphere the view starts where it enters it. `multiple`, when not
 * NULL, receives the orders' share alone. */
void sb_orders_ref_sky(const struct sb_orders_ref *ref, double h, double mu, double mu_s, double nu, double out[3],
                       double multiple[3]);

#endif

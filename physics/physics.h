/*
 * The C half of the shared physics (atmosphere.glsl): the GPU image of the
 * atmosphere parameters and the lookup forms in which shaders read baked
 * LUTs. Used by the baker, whose later products read earlier ones, and by
 * the runtime, which reads a pack. No Vulkan here; all functions are pure
 * and thread safe.
 */
#ifndef SB_PHYSICS_PHYSICS_H
#define SB_PHYSICS_PHYSICS_H

#include <stdbool.h>
#include <stddef.h>

#include "config.h"
#include "image.h"
#include "pack.h"
#include "scene.h"

/* Gauss-Legendre node k of n on [a, b], ascending, fp64, for any n (<= 256):
 * the quadrature the fp64 references and sb_sh9_tensor share. */
void sb_gauss_legendre_node(int k, int n, double a, double b, double *x, double *w);

/* Fill the std430 image of the parameters (config.h) from validated ones. */
void sb_atmosphere_gpu_pack(const struct sb_atmosphere_params *params, struct sb_atmosphere_gpu *gpu);

/* The radius (km) at which the orders' grid ends: the atmosphere's top, or
 * lower where above it every species holds under 1e-6 of its vertical
 * column (Rayleigh and Mie from 13.8 scale heights, ozone above its tent).
 * Its nodes in r, in the rays' lengths and in mu_s (whose lowest is the
 * sun's last light on that top) then lie where the air is: an atmosphere
 * as thick as its planet's radius took them thousands of kilometres up,
 * and read twilight 4 times coarser in mu_s and the horizon 6 times
 * coarser in mu than the earth's grid (docs/accuracy.md). Its nodes' rays
 * still run through all of the air to the top. */
double sb_orders_top_km(const struct sb_atmosphere_params *params);

/* The orders' grid (baker/orders_ref.h states it): the ratio q of its
 * altitudes' geometric progression, h_i = Z (q^i - 1) / (q^n - 1) over its
 * thickness Z (sb_orders_top_km's, less the ground's radius) with n = nr -
 * 1, the first step a quarter of the smaller scale height (q = 1: uniform,
 * where that would be coarser). */
double sb_orders_height_ratio(const struct sb_atmosphere_params *params, int nr);

/* Whether a view reads the orders' table across the sun's azimuth
 * log-trigonometrically (through all n azimuth nodes, exact for the
 * exponential of any sum of cos(k phi), k < n) rather than linearly between the
 * two nodes about it: where Mie scatters more than Rayleigh at the ground
 * in every channel and its phase is peaked (sb_atmosphere_peaked_dust: the
 * haze). A dust's orders 2 and up peak toward the sun like exp(k cos phi),
 * which a line between nodes 60 degrees apart lifts across the sun (mars
 * read 17 to 38% high there); where Rayleigh's smooth light dominates, the
 * line is the better read (docs/accuracy.md, "The orders' azimuths by the
 * medium"), and so it is for a broad dust (mars) on the air's 8 nodes
 * close about the sun, which its twilight needs ("Mars's twilight"). */
bool sb_orders_log_azimuth(const struct sb_atmosphere_params *params);
/* The power p of the orders' azimuth nodes, phi_j = pi (j / (n - 1))^p: 1
 * (uniform) where views read them log-trigonometrically, which needs
 * uniform nodes, else SB_ORDERS_NU_POWER. */
double sb_orders_azimuth_power(const struct sb_atmosphere_params *params);

/* The grid of nr x nmu x nmus x nnu nodes as the orders' kernels and
 * skyview's passes take it (config.h's sb_orders_push; order 0), of the
 * scene's atmosphere (a spectral band's grid is its scene's). */
void sb_orders_grid_pack(const struct sb_atmosphere_params *params, int nr, int nmu, int nmus, int nnu,
                         struct sb_orders_push *out);

/* The altitude levels (km, ascending) that cut rays into segments: geometric
 * by sqrt(2) from half the smallest scale height, below the top. Returns
 * their number, at most SB_MAX_LEVELS. */
int sb_atmosphere_levels(const struct sb_atmosphere_params *params, double levels[SB_MAX_LEVELS]);

/*
 * The lookup form of a baked product (config.h), which shaders read:
 * - transmittance: its optical depth, -ln(max(T, 1e-30)) per texel and
 *   channel, in the LUT's layout (transmittance_lut_sample interpolates it
 *   and takes one exponential);
 * - multiscattering: ln(max(psi, 1e-30)) per texel and channel, padded to
 *   four floats a texel (the fourth 0), with a ghost texel on every side
 *   repeating the edge (SB_MULTISCATTERING_LOOKUP_TEXELS texels, rows of
 *   SB_MULTISCATTERING_SIZE + 2 from mu_s = -1 and h = 0);
 * - irradiance_ground: two rows of SB_IRRADIANCE_WIDTH x 3 floats taken from
 *   the ground row (h = 0), ln(max(direct + sky, 1e-30)) then
 *   ln(max(sky, 1e-30));
 * other products are read as baked and have no lookup form (0 floats).
 * `image` must have the product's format (sb_product_format).
 */
size_t sb_lookup_float_count(enum sb_product_id id);
void sb_lookup_fill(enum sb_product_id id, const struct sb_image *image, float *dst);

/* Catmull-Rom's weights at t in [0, 1] for the four texels around it; the
 * same as atmosphere.glsl's catmull_rom and cubic_taps, which
 * test_atmosphere holds to these (through the multiscattering lookup). */
void sb_catmull_rom(double t, double w[4]);
/* The first of the four texels around continuous texel coordinate f on n
 * texels (clamped to [0, n - 1]; texel i at i), and their weights: what the
 * shaders' cubic_taps computes. The first may be -1 and the last n: the
 * caller repeats the edges. */
int sb_cubic_taps(double f, int n, double w[4]);

/*
 * skyview's form of the multiscattering LUT (config.h): at each node of a
 * grid SB_MULTISCATTERING_REFINE times finer (SB_MULTISCATTERING_REFINED_SIZE
 * nodes a side, rows from h = 0, from mu_s = -1), the lookup form's
 * Catmull-Rom of ln(max(psi, 1e-30)), as the bakes read it
 * (multiscattering_lut_sample, atmosphere.glsl), four floats a node (the
 * fourth 0). `image` must have multiscattering's format.
 */
size_t sb_multiscattering_refined_float_count(void);
void sb_multiscattering_refined_fill(const struct sb_image *image, float *dst);

/* Reflection cubes (docs/reflections.md), prefiltered by the bake and by
 * skyview's relight alike (prefilter.glsl). The perceptual roughness mip
 * `level` of `levels` holds: Filament's mapping, level / (levels - 1) =
 * r (2 - r), which spends more levels on smooth surfaces (a runtime's lod
 * = (levels - 1) r (2 - r)). */
double sb_reflection_level_roughness(uint32_t level, uint32_t levels);

/* The GGX samples a texel of `level` gets from the scene's `samples`: the
 * level above 0's, doubling with each level (rough levels are cheap, their
 * texels few, and their lobes wide), at most SB_REFLECTION_MAX_SAMPLES.
 * Costs about twice level 1's. */
#define SB_REFLECTION_MAX_SAMPLES 16384
uint32_t sb_reflection_level_samples(uint32_t samples, uint32_t level);

/* A prefilter dispatch's layout for `texels` texels of `samples` samples:
 * about 16 samples an invocation (a power of two of them a texel, at most
 * `threads` a workgroup: the wide levels' few samples would otherwise
 * leave most of a workgroup idle), and the workgroups as x by y. */
void sb_prefilter_layout(uint32_t samples, uint64_t texels, uint32_t threads, uint32_t *threads_per_texel,
                         uint32_t groups[2]);

#endif

/*
 * Cloud noise (Schneider 2015, "The real-time volumetric cloudscapes of
 * Horizon Zero Dawn"; Nubis): tileable textures baked with Vulkan compute
 * (shaders/noise.glsl, clouds.comp), and their CPU reference
 * (clouds_ref.c), which the GPU output matches bit for bit.
 *
 * Definitions. A texel (i, j, k) of an N_x x N_y x N_z texture sits at
 * p = ((i, j, k) + 0.5) * r, r = 1 / N per axis rounded to fp32 on the host;
 * 2D textures are the slice p_z = 0.3. Each noise tiles [0, 1)^3 exactly:
 * its lattice has an integer period P per axis and lattice points wrap
 * modulo P before they are hashed.
 * - hash: pcg3d (Jarzynski and Olano 2020) of the wrapped lattice point,
 *   its z offset by seed * 0x9E3779B9; unit(h) = (h >> 8) * 2^-24 in [0, 1).
 * - perlin(p, P, seed): x = p P, c = floor(x), f = x - c; gradient of corner
 *   c + o is the cube edge direction (+-1, +-1, 0), (+-1, 0, +-1) or
 *   (0, +-1, +-1) chosen by ((hash.x >> 8) 12) >> 24, in [0, 12) (12 (h mod 2^24) / 2^24:
 *   no integer division, which llvmpipe cannot vectorise); the corners' g . (f - o) are
 *   blended with the fade u = f^3 (f (6 f - 15) + 10), x then y then z.
 * - perlin_fbm(p, P, n, seed) = clamp(1/2 + 1/2 norm_n
 *   sum_{k<n} 2^-k perlin(p, P 2^k, seed + k), 0, 1), norm_n = 1 / sum 2^-k.
 * - worley(p, C, seed) = 1 - sqrt(min(1, F1^2)), F1 the distance from x = p C
 *   to the nearest feature point, one per cell at cell + unit(hash(cell)),
 *   over the 27 cells around x, computed within x's cell (f - o - unit with
 *   f = x - floor(x)), so that one period on gives the same bits.
 * - worley_fbm(p, C, seed) = 0.625 worley(p, C, seed) + 0.25 worley(p, 2C,
 *   seed + 1) + 0.125 worley(p, 4C, seed + 2).
 * Only integer operations and fp32 add, subtract, multiply and compare are
 * used (Vulkan rounds those correctly everywhere); sqrt is 4 Newton steps
 * for 1/sqrt from an integer first guess, then x * y; every expression is
 * evaluated in the same order, unfused, on both sides.
 *
 * The products' channels (defaults; sizes, periods, Worley cell counts,
 * octaves and the seed are scene parameters, struct sb_cloud_params in
 * formats/scene.h; each channel's seed is the scene's plus the constant
 * sb_cloud_recipe adds, so that channels differ):
 * - cloud_shape 128^3: r = Perlin-Worley, remap(perlin_fbm(P 4, 4
 *   octaves), 0, 1, worley_fbm(C 4), 1) = w + v (1 - w); g, b, a =
 *   worley_fbm with C = 4, 8, 16. (TileableVolumeNoise, which Schneider's
 *   chapter points to, builds its Worley fBm over 2, 8 and 14 cells and its
 *   Perlin at frequency 8 with 3 octaves; we keep doubling periods, which
 *   tile at every octave.)
 * - cloud_detail 32^3: r, g, b = worley_fbm with C = 2, 4, 8.
 * - cloud_curl 128^2, 3 channels, 2D as in Nubis (the curl distorts the
 *   sample position in the horizontal plane and across height; a 2D texture
 *   costs 1/128 of a 128^3 volume): the curl of a potential whose three
 *   components are perlin_fbm(P 4, 3 octaves, seed + 16 i), by central
 *   differences with step 2^-12, mapped to 1/2 + curl / 16 and clamped.
 * - weather 512^2: r coverage = perlin_fbm(P 4, 5 octaves) stretched by 2
 *   about 1/2 and clamped; g precipitation = perlin_fbm(P 8, 4 octaves,
 *   seed + 32) stretched by 2 about 1/2, clamped; b cloud type =
 *   perlin_fbm(P 2, 3 octaves, seed + 64).
 */
#ifndef SB_BAKER_CLOUDS_H
#define SB_BAKER_CLOUDS_H

#include <stdint.h>

#include "compute.h"
#include "config.h"
#include "context.h"
#include "image.h"
#include "pack.h"
#include "scene.h"

/* The channel recipes of a cloud product (config.h's sb_noise_push, filled
 * for it from the scene's parameters). */
void sb_cloud_recipe(enum sb_product_id product, const struct sb_cloud_params *params, struct sb_noise_push *push);

/* The recipe as a JSON object (the manifest's settings): each channel's
 * noise, periods or cells, octaves and seed. */
void sb_cloud_recipe_json(const struct sb_noise_push *push, char *out, size_t size);

/* The CPU reference: texels [first, first + count) of the product, in
 * x-fastest order, their channels interleaved, into out. Thread-safe. */
void sb_cloud_ref(const struct sb_noise_push *push, uint64_t first, uint64_t count, float *out);

/* The kernel sb_cloud_bake makes for `product`. */
struct sb_pipeline_params sb_cloud_kernel(enum sb_product_id product);

/* Bake a cloud product on the device into *image (fp32, as computed; 2D
 * products have depth 1), named as the pack names its channels. */
enum sb_result sb_cloud_bake(struct sb_vk *vk, enum sb_product_id product, const struct sb_cloud_params *params,
                             struct sb_image *image, double *gpu_ms);

/* XXH3-128 of what a cloud product's values depend on besides its recipe:
 * the kernel's SPIR-V (for the bake keys). */
void sb_cloud_code_hash(char out[SB_HASH_HEX_SIZE]);

#endif

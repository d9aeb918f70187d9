/*
 * The atmosphere LUT products (transmittance, multiscattering,
 * irradiance_ground, irradiance_sky) baked with Vulkan compute. Each product
 * is one compute dispatch over its texels; its inputs are the products it
 * depends on, kept on the GPU between dispatches.
 */
#ifndef SB_BAKER_ATMOSPHERE_H
#define SB_BAKER_ATMOSPHERE_H

#include <stdbool.h>
#include <stdint.h>

#include "compute.h"
#include "config.h"
#include "image.h"
#include "pack.h"
#include "physics.h"
#include "scene.h"

/* Settings of one product's bake. Zero fields take the product's defaults;
 * fields a product does not use stay zero. */
struct sb_atmosphere_settings {
    uint32_t directions_mu;  /* scattering products: Gauss-Legendre nodes in cos(zenith) per piece */
    uint32_t directions_phi; /* scattering products: azimuth nodes over [0, pi] */
    uint32_t quadrature;     /* transmittance: SB_QUADRATURE_* (config.h) */
    uint32_t samples;        /* transmittance: Gauss-Legendre order, or steps of a uniform rule */
    uint32_t subdivisions;   /* transmittance, Gauss-Legendre: sub-pieces per piece */
    uint32_t width, height;  /* transmittance: a resolution other than the format's, for
                                measurements only (a pack holds the format's) */
};

/* Density samples a texel of the transmittance LUT takes at most, or the
 * directions a texel of a scattering product integrates: the work a setting
 * costs, independent of the device. */
uint64_t sb_atmosphere_settings_cost(enum sb_product_id id, const struct sb_atmosphere_settings *settings);

/* A short label of a setting, e.g. "gl8x1", "uniform0.3-40", "16x12". */
void sb_atmosphere_settings_label(enum sb_product_id id, const struct sb_atmosphere_settings *settings, char *out,
                                  size_t size);

/* A setting a product's bake may choose and bench sweeps
 * (atmosphere_candidates.c). */
struct sb_atmosphere_candidate {
    struct sb_atmosphere_settings settings;
    const char *anchor; /* the published method this setting reproduces, or NULL */
    bool quick;         /* part of `skybake bench --quick` */
};

/* The sweeps: a product's candidates, or (lookup) the resolutions whose
 * bilinear lookups bench measures. */
enum sb_atmosphere_sweep_id {
    SB_ATMOSPHERE_SWEEP_TRANSMITTANCE,
    SB_ATMOSPHERE_SWEEP_TRANSMITTANCE_RESOLUTION,
    SB_ATMOSPHERE_SWEEP_MULTISCATTERING,
    SB_ATMOSPHERE_SWEEP_IRRADIANCE_GROUND,
    SB_ATMOSPHERE_SWEEP_IRRADIANCE_SKY,
    SB_ATMOSPHERE_SWEEP_COUNT,
};

struct sb_atmosphere_sweep {
    const char *name; /* bench's --product */
    enum sb_product_id product;
    bool lookup; /* resolutions, measured through lookups: not bake candidates */
    const struct sb_atmosphere_candidate *entries;
    int count;
    const char *error_name;
};

/* The sweeps, indexed by enum sb_atmosphere_sweep_id. */
extern const struct sb_atmosphere_sweep sb_atmosphere_sweeps[SB_ATMOSPHERE_SWEEP_COUNT];

#define SB_ATMOSPHERE_MAX_CANDIDATES 32

/* The settings a bake under a tolerance tries for `id`, cheapest first
 * (stable: ties keep the table's order), into out; returns their number.
 * Thread-safe. */
int sb_atmosphere_candidates(enum sb_product_id id, struct sb_atmosphere_settings out[SB_ATMOSPHERE_MAX_CANDIDATES]);

struct sb_atmosphere_product {
    enum sb_product_id id;
    uint32_t depends_on;      /* bit mask of sb_product_id */
    bool workgroup_per_texel; /* sphere.glsl's layout, else 8x8 texels a workgroup */
    bool rings;               /* the azimuth integrated first, in the ring table (sun_rings.glsl) */
    struct sb_atmosphere_settings defaults;
};

/* The descriptor of a product. */
const struct sb_atmosphere_product *sb_atmosphere_product(enum sb_product_id id);

/* Baking state: the device, the parameters and every product baked so far. */
struct sb_atmosphere_baker;

enum sb_result sb_atmosphere_baker_create(struct sb_vk *vk, const struct sb_atmosphere_params *params,
                                          struct sb_atmosphere_baker **baker);
void sb_atmosphere_baker_destroy(struct sb_atmosphere_baker **baker);

/* The scattering bakes' kernels as laid out for either kind of device
 * (config.h, SB_SPHERE_THREADS_*): the same sums in another order. */
enum sb_atmosphere_kernels {
    SB_ATMOSPHERE_KERNELS_GPU,
    SB_ATMOSPHERE_KERNELS_CPU, /* narrower; the irradiance bakes copy the multiscattering LUT to workgroup memory */
};

/* Bake with the other kind's kernels from now on (tests compare the two on
 * one device); a baker starts with its device's. A CPU device's kernels
 * need SB_SPHERE_SHARED_BYTES of workgroup memory: SB_ERR_DEVICE_LIMIT
 * where the device has less. */
enum sb_result sb_atmosphere_baker_set_kernels(struct sb_atmosphere_baker *baker, enum sb_atmosphere_kernels kernels);

/* Whether the GPU layout of scattering product `id` computes its sums in
 * the CPU layout's order (one direction an invocation, summed by a second
 * kernel: sphere.glsl), so that the two differ only where a compiler
 * contracts their arithmetic differently. */
bool sb_atmosphere_kernels_same_order(enum sb_product_id id);

/*
 * Bake one product into `image` (initialised here; the caller finishes it).
 * Its dependencies must have been baked by this baker first. `settings` may
 * be NULL for the defaults; the settings used are written to *used (may be
 * NULL) and the GPU time to *gpu_ms.
 */
enum sb_result sb_atmosphere_bake(struct sb_atmosphere_baker *baker, enum sb_product_id id,
                                  const struct sb_atmosphere_settings *settings, struct sb_image *image,
                                  struct sb_atmosphere_settings *used, double *gpu_ms);

/* The kernels sb_atmosphere_bake makes for `id` with `settings` (NULL:
 * the defaults), the sun's tables' included; returns their count. */
#define SB_ATMOSPHERE_KERNELS_MAX 4
uint32_t sb_atmosphere_kernels(const struct sb_atmosphere_baker *baker, enum sb_product_id id,
                               const struct sb_atmosphere_settings *settings,
                               struct sb_pipeline_params out[SB_ATMOSPHERE_KERNELS_MAX]);

/* The buffers a kernel including atmosphere.glsl reads at bindings 0 to
 * 3 (config.h, SB_BINDING_*): the parameters and the LUTs this baker has
 * baked or adopted (a 16-byte unused buffer in the slot of each it has
 * not), for kernels of other families (the reflection capture).
 * bindings[] must have room for 4. */
void sb_atmosphere_bind_inputs(struct sb_atmosphere_baker *baker, const struct sb_buffer **bindings);

/*
 * Evaluate the shared GLSL model directly, for tests and tools: run a
 * kernel with the baker's parameters and products bound as in a bake, over
 * `record_count` records of `record_floats` floats each, read and written in
 * place at SB_BINDING_OUTPUT. The kernel gets an sb_bake_push whose
 * directions_mu is the record count and directions_phi the record size, and
 * runs over a (width, height) grid of 8x8 workgroups with
 * record index = y * width + x, width = pc.width.
 */
enum sb_result sb_atmosphere_run_kernel(struct sb_atmosphere_baker *baker, const uint32_t *spirv, size_t spirv_size,
                                        float *records, uint32_t record_count, uint32_t record_floats);

/*
 * Give the baker a product baked before (read back from a pack whose key
 * says it is what this bake would make), for the products that read it.
 */
enum sb_result sb_atmosphere_adopt(struct sb_atmosphere_baker *baker, enum sb_product_id id,
                                   const struct sb_image *image);

/*
 * What a product's bake runs, for its bake key: XXH3-128 of the SPIR-V of
 * every kernel the product may use, of the host-side choices that shape a
 * bake (config.h's cap constants), and of SB_ATMOSPHERE_RECIPE.
 */
void sb_atmosphere_code_hash(enum sb_product_id id, char out[SB_HASH_HEX_SIZE]);

/* Bumped by hand whenever host code changes what a product's values are
 * without changing its kernel's SPIR-V (atmosphere.c, physics.c's lookups). */
#define SB_ATMOSPHERE_RECIPE 1

/* The manifest's settings object for a product baked with `settings`. */
void sb_atmosphere_settings_json(enum sb_product_id id, const struct sb_atmosphere_settings *settings, char *out,
                                 size_t size);

#endif

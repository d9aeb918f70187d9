#include "atmosphere.h"

#include <assert.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "irradiance_ground_bruneton.spv.h"
#include "irradiance_ground_gpu.spv.h"
#include "irradiance_ground_shared.spv.h"
#include "irradiance_sky_gpu.spv.h"
#include "irradiance_sky_shared.spv.h"
#include "log.h"
#include "multiscattering.spv.h"
#include "multiscattering_rays.spv.h"
#include "multiscattering_hillaire.spv.h"
#include "physics.h"
#include "sun_columns.spv.h"
#include "sun_columns_ghosts.spv.h"
#include "sun_rings.spv.h"
#include "transmittance_gl0.spv.h"
#include "transmittance_gl1.spv.h"
#include "transmittance_gl2.spv.h"
#include "transmittance_gl3.spv.h"
#include "transmittance_gl4.spv.h"
#include "transmittance_gl5.spv.h"
#include "transmittance_gl6.spv.h"
#include "transmittance_gl7.spv.h"
#include "transmittance_gl8.spv.h"

#define BIT(p) (1u << (p))

static const struct sb_atmosphere_product products[SB_ATMOSPHERE_PRODUCT_COUNT] = {
    [SB_PRODUCT_TRANSMITTANCE] =
        {
            .id = SB_PRODUCT_TRANSMITTANCE,
            .defaults = {.quadrature = SB_QUADRATURE_GAUSS_LEGENDRE, .samples = 8, .subdivisions = 1},
        },
    [SB_PRODUCT_MULTISCATTERING] =
        {
            .id = SB_PRODUCT_MULTISCATTERING,
            .depends_on = BIT(SB_PRODUCT_TRANSMITTANCE),
            .defaults = {.directions_mu = 16, .directions_phi = 6},
            .workgroup_per_texel = true,
            .rings = true,
        },
    [SB_PRODUCT_IRRADIANCE_GROUND] =
        {
            .id = SB_PRODUCT_IRRADIANCE_GROUND,
            .depends_on = BIT(SB_PRODUCT_TRANSMITTANCE) | BIT(SB_PRODUCT_MULTISCATTERING),
            .defaults = {.directions_mu = 8, .directions_phi = 8},
            .workgroup_per_texel = true,
        },
    [SB_PRODUCT_IRRADIANCE_SKY] =
        {
            .id = SB_PRODUCT_IRRADIANCE_SKY,
            .depends_on =
                BIT(SB_PRODUCT_TRANSMITTANCE) | BIT(SB_PRODUCT_MULTISCATTERING) | BIT(SB_PRODUCT_IRRADIANCE_GROUND),
            .defaults = {.directions_mu = 16, .directions_phi = 16},
            .workgroup_per_texel = true,
        },
};

struct spirv {
    const uint32_t *words;
    size_t size;
    uint32_t threads; /* a sphere.glsl kernel's workgroup size */
    /* A kernel that integrates one direction an invocation (sphere.glsl's
     * SB_SPHERE_RAYS), workgroups of `threads` dispatched along z. */
    bool rays;
};

#define SPIRV(name) {.words = sb_spv_##name, .size = sizeof(sb_spv_##name), .threads = SB_SPHERE_THREADS_CPU}
#define SPIRV_GPU(name) {.words = sb_spv_##name, .size = sizeof(sb_spv_##name), .threads = SB_SPHERE_THREADS_GPU}
#define SPIRV_RAYS(name)                                                                                               \
    {                                                                                                                  \
        .words = sb_spv_##name##_rays, .size = sizeof(sb_spv_##name##_rays), .threads = SB_SPHERE_RAY_GROUP,           \
        .rays = true,                                                                                                  \
    }
/* Transmittance: one shader per Gauss-Legendre order, 0 for the uniform rules (config.h). */
static const struct spirv transmittance_shaders[SB_GL_MAX_ORDER + 1] = {
    SPIRV(transmittance_gl0), SPIRV(transmittance_gl1), SPIRV(transmittance_gl2),
    SPIRV(transmittance_gl3), SPIRV(transmittance_gl4), SPIRV(transmittance_gl5),
    SPIRV(transmittance_gl6), SPIRV(transmittance_gl7), SPIRV(transmittance_gl8),
};
/* The scattering products as a GPU runs them [SB_ATMOSPHERE_KERNELS_GPU],
 * SB_SPHERE_THREADS_GPU invocations a texel (config.h), and as a CPU device
 * does [SB_ATMOSPHERE_KERNELS_CPU], with the irradiance bakes reading the
 * multiscattering LUT from workgroup memory (atmosphere.glsl). Both compute
 * the same sums in another order. On the H100, workgroup memory took
 * irradiance_sky from 6.1 to 8.5 ms (irradiance_ground 1.13 -> 1.05 ms); on
 * llvmpipe, from 10.7 to 8.2 s (1.46 -> 1.25 s).
 *
 * A GPU runs multiscattering one ray an invocation, the last workgroup of
 * a texel summing its rays (sphere.glsl's SB_SPHERE_RAYS) in the CPU
 * layout's order, so the two give the same bits where the compilers
 * contract alike: on an H200 the default bake took 0.447 ms instead of
 * 0.505 (12x4 0.351 instead of 0.458, 4x3 0.276 instead of 0.418; two
 * alternating runs of skybake bench), its content hash unchanged. The
 * irradiance bakes were slower so on an H100: irradiance_ground 0.368 ms
 * against 0.314, irradiance_sky 5.13 against 4.17 (240 registers an
 * invocation instead of 168), and keep a workgroup a texel. */
static const struct spirv scattering_shaders[2][SB_ATMOSPHERE_PRODUCT_COUNT] = {
    [SB_ATMOSPHERE_KERNELS_GPU] =
        {
            [SB_PRODUCT_MULTISCATTERING] = SPIRV_RAYS(multiscattering),
            [SB_PRODUCT_IRRADIANCE_GROUND] = SPIRV_GPU(irradiance_ground_gpu),
            [SB_PRODUCT_IRRADIANCE_SKY] = SPIRV_GPU(irradiance_sky_gpu),
        },
    [SB_ATMOSPHERE_KERNELS_CPU] =
        {
            [SB_PRODUCT_MULTISCATTERING] = SPIRV(multiscattering),
            [SB_PRODUCT_IRRADIANCE_GROUND] = SPIRV(irradiance_ground_shared),
            [SB_PRODUCT_IRRADIANCE_SKY] = SPIRV(irradiance_sky_shared),
        },
};
/* skybake bench's anchors: Hillaire 2020's multiple-scattering LUT and
 * Bruneton 2017's ground irradiance (config.h), by product. */
static const struct spirv anchor_shaders[SB_ATMOSPHERE_PRODUCT_COUNT] = {
    [SB_PRODUCT_MULTISCATTERING] = SPIRV(multiscattering_hillaire),
    [SB_PRODUCT_IRRADIANCE_GROUND] = SPIRV(irradiance_ground_bruneton),
};
/* The scattering bakes' sun table (atmosphere.glsl): its nodes, then its ghosts. */
static const struct spirv sun_columns_shader = SPIRV(sun_columns);
static const struct spirv sun_columns_ghosts_shader = SPIRV(sun_columns_ghosts);
/* Multiscattering's ring table (sun_rings.glsl). */
static const struct spirv sun_rings_shader = SPIRV(sun_rings);
#undef SPIRV

bool sb_atmosphere_kernels_same_order(enum sb_product_id id)
{
    return id < SB_ATMOSPHERE_PRODUCT_COUNT && scattering_shaders[SB_ATMOSPHERE_KERNELS_GPU][id].rays;
}

/* The kernels a device runs: a CPU device's where it offers their
 * workgroup memory. */
static enum sb_atmosphere_kernels device_kernels(const struct sb_vk *vk)
{
    return vk->properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU &&
                   vk->properties.limits.maxComputeSharedMemorySize >= SB_SPHERE_SHARED_BYTES
               ? SB_ATMOSPHERE_KERNELS_CPU
               : SB_ATMOSPHERE_KERNELS_GPU;
}

/* A scattering product's setting of the published methods (bench anchors). */
static bool is_anchor(enum sb_product_id id, const struct sb_atmosphere_settings *s)
{
    return id != SB_PRODUCT_TRANSMITTANCE && s->quadrature != SB_QUADRATURE_GAUSS_LEGENDRE;
}

const struct sb_atmosphere_product *sb_atmosphere_product(enum sb_product_id id)
{
    assert((unsigned)id < SB_ATMOSPHERE_PRODUCT_COUNT);
    return &products[id];
}

/* `settings` over the product's defaults, with the fields it does not use zeroed. */
static struct sb_atmosphere_settings resolve_settings(enum sb_product_id id,
                                                      const struct sb_atmosphere_settings *settings)
{
    struct sb_atmosphere_settings s = products[id].defaults,
                                  in = settings ? *settings : (struct sb_atmosphere_settings){0};
    if (id == SB_PRODUCT_TRANSMITTANCE) {
        if (in.quadrature || in.samples) {
            s.quadrature = in.quadrature;
            s.samples = in.samples;
            s.subdivisions = in.quadrature == SB_QUADRATURE_GAUSS_LEGENDRE ? 1 : 0;
        }
        if (in.subdivisions && s.quadrature == SB_QUADRATURE_GAUSS_LEGENDRE)
            s.subdivisions = in.subdivisions;
        s.width = in.width;
        s.height = in.height;
        return s;
    }
    if (in.directions_mu)
        s.directions_mu = in.directions_mu;
    if (in.directions_phi)
        s.directions_phi = in.directions_phi;
    if (in.quadrature) {
        s.quadrature = in.quadrature;
        s.samples = in.samples;
    }
    return s;
}

static enum sb_result check_settings(enum sb_product_id id, const struct sb_atmosphere_settings *s)
{
    const char *name = sb_product_name(id);
    if (is_anchor(id, s)) {
        uint64_t directions = (uint64_t)s->directions_mu * s->directions_phi;
        bool hillaire = id == SB_PRODUCT_MULTISCATTERING && s->quadrature == SB_QUADRATURE_UNIFORM_0_3 &&
                        directions >= 1 && directions <= SB_ANCHOR_MAX_DIRECTIONS && s->samples >= 1 &&
                        s->samples <= SB_UNIFORM_MAX_STEPS &&
                        SB_ANCHOR_ITERATIONS(directions, s->samples) <= SB_ANCHOR_MAX_ITERATIONS;
        bool bruneton = id == SB_PRODUCT_IRRADIANCE_GROUND && s->quadrature == SB_QUADRATURE_TRAPEZOID &&
                        directions >= 1 && directions <= SB_BRUNETON_MAX_DIRECTIONS && s->samples >= 1 &&
                        s->samples <= SB_BRUNETON_MAX_STEPS;
        if (!hillaire && !bruneton) {
            sb_error("%s: the published rules are Hillaire 2020's multiscattering (uniform, 1 to %d directions, 1 to "
                     "%d steps, and steps times directions / %d rounded up at most %d) and Bruneton 2017's "
                     "irradiance_ground (trapezoid, 1 to %d directions, 1 to %d steps); got quadrature %u, %ux%u, %u",
                     name, SB_ANCHOR_MAX_DIRECTIONS, SB_UNIFORM_MAX_STEPS, SB_ANCHOR_THREADS, SB_ANCHOR_MAX_ITERATIONS,
                     SB_BRUNETON_MAX_DIRECTIONS, SB_BRUNETON_MAX_STEPS, s->quadrature, s->directions_mu,
                     s->directions_phi, s->samples);
            return SB_ERR_USAGE;
        }
        return SB_OK;
    }
    if (id != SB_PRODUCT_TRANSMITTANCE) {
        if (s->directions_mu < 1 || s->directions_mu > SB_MAX_DIRECTIONS_MU || s->directions_phi < 1 ||
            s->directions_phi > SB_MAX_DIRECTIONS_PHI) {
            sb_error("%s: directions_mu must be 1 to %d and directions_phi 1 to %d (got %u, %u)", name,
                     SB_MAX_DIRECTIONS_MU, SB_MAX_DIRECTIONS_PHI, s->directions_mu, s->directions_phi);
            return SB_ERR_USAGE;
        }
        return SB_OK;
    }
    if (s->quadrature >= SB_QUADRATURE_COUNT) {
        sb_error("%s: unknown quadrature %u", name, s->quadrature);
        return SB_ERR_USAGE;
    }
    if (s->quadrature == SB_QUADRATURE_GAUSS_LEGENDRE &&
        (s->samples < 1 || s->samples > SB_GL_MAX_ORDER || s->subdivisions < 1 ||
         s->subdivisions > SB_GL_MAX_SUBDIVISIONS)) {
        sb_error("%s: Gauss-Legendre order must be 1 to %d and subdivisions 1 to %d (got %u, %u)", name,
                 SB_GL_MAX_ORDER, SB_GL_MAX_SUBDIVISIONS, s->samples, s->subdivisions);
        return SB_ERR_USAGE;
    }
    if (s->quadrature != SB_QUADRATURE_GAUSS_LEGENDRE && (s->samples < 1 || s->samples > SB_UNIFORM_MAX_STEPS)) {
        sb_error("%s: a uniform rule takes 1 to %d steps (got %u)", name, SB_UNIFORM_MAX_STEPS, s->samples);
        return SB_ERR_USAGE;
    }
    if ((s->width || s->height) && (s->width < 2 || s->height < 2 || s->width > 4096 || s->height > 4096)) {
        sb_error("%s: resolution %ux%u is outside 2 to 4096 a side", name, s->width, s->height);
        return SB_ERR_USAGE;
    }
    return SB_OK;
}

/* The most directions a texel of sphere.glsl's integrals has: the zenith
 * grid's pieces, and with `cap` those of the cap around Mie's peak; with
 * `rings` (the azimuth integrated in the ring table), one per zenith node. */
static uint64_t sphere_directions(const struct sb_atmosphere_settings *s, bool cap, bool rings)
{
    return (uint64_t)(SB_SPHERE_MAX_PIECES + (cap ? SB_SPHERE_CAP_PIECES : 0)) * s->directions_mu *
           (rings ? 1 : s->directions_phi);
}

uint64_t sb_atmosphere_settings_cost(enum sb_product_id id, const struct sb_atmosphere_settings *settings)
{
    struct sb_atmosphere_settings s = resolve_settings(id, settings);
    if (is_anchor(id, &s))
        return (uint64_t)s.directions_mu * s.directions_phi;
    if (id != SB_PRODUCT_TRANSMITTANCE)
        return sphere_directions(&s, id != SB_PRODUCT_MULTISCATTERING, false); /* rings: phi prices the table */
    if (s.quadrature == SB_QUADRATURE_GAUSS_LEGENDRE)
        return 5ull * s.samples * s.subdivisions; /* five pieces, as on the earth */
    return s.quadrature == SB_QUADRATURE_TRAPEZOID ? s.samples + 1ull : s.samples;
}

void sb_atmosphere_settings_label(enum sb_product_id id, const struct sb_atmosphere_settings *settings, char *out,
                                  size_t size)
{
    struct sb_atmosphere_settings s = resolve_settings(id, settings);
    if (is_anchor(id, &s)) {
        snprintf(out, size, "%s%ux%u-%u", id == SB_PRODUCT_MULTISCATTERING ? "hillaire" : "bruneton", s.directions_mu,
                 s.directions_phi, s.samples);
        return;
    }
    if (id != SB_PRODUCT_TRANSMITTANCE) {
        snprintf(out, size, "%ux%u", s.directions_mu, s.directions_phi);
        return;
    }
    static const char *rules[SB_QUADRATURE_COUNT] = {"gl", "uniform0.3-", "midpoint-", "trapezoid-"};
    int n;
    if (s.quadrature == SB_QUADRATURE_GAUSS_LEGENDRE)
        n = snprintf(out, size, "gl%ux%u", s.samples, s.subdivisions);
    else
        n = snprintf(out, size, "%s%u", s.quadrature < SB_QUADRATURE_COUNT ? rules[s.quadrature] : "?", s.samples);
    if (s.width && n > 0 && (size_t)n < size)
        snprintf(out + n, size - (size_t)n, "@%ux%u", s.width, s.height);
}

struct sb_atmosphere_baker {
    struct sb_vk *vk;
    struct sb_buffer params;
    struct sb_buffer dummy;
    struct sb_buffer scratch;     /* sphere.glsl's sums between passes */
    struct sb_buffer sun_columns; /* the scattering bakes' sun table */
    struct sb_buffer sun_rings;   /* multiscattering's ring table, while it bakes */
    struct sb_buffer outputs[SB_ATMOSPHERE_PRODUCT_COUNT];
    struct sb_buffer lookups[SB_ATMOSPHERE_PRODUCT_COUNT]; /* the form later bakes read (config.h) */
    bool sky_cap; /* irradiance_sky integrates Mie's peak on a cap (sphere.glsl) */
    enum sb_atmosphere_kernels kernels;
};

enum sb_result sb_atmosphere_baker_create(struct sb_vk *vk, const struct sb_atmosphere_params *params,
                                          struct sb_atmosphere_baker **out)
{
    *out = NULL;
    struct sb_atmosphere_baker *b = calloc(1, sizeof(*b));
    if (!b)
        return SB_ERR_NOMEM;
    b->vk = vk;
    b->sky_cap = fabs(params->mie_g) >= SB_CAP_MIN_G;
    b->kernels = device_kernels(vk);
    struct sb_atmosphere_gpu gpu;
    sb_atmosphere_gpu_pack(params, &gpu);
    enum sb_result res = sb_buffer_create(vk, sizeof(gpu), "atmosphere parameters", &b->params);
    if (!res)
        res = sb_buffer_create(vk, 16, "unused input", &b->dummy);
    if (res) {
        sb_atmosphere_baker_destroy(&b);
        return res;
    }
    memcpy(b->params.mapped, &gpu, sizeof(gpu));
    *out = b;
    return SB_OK;
}

enum sb_result sb_atmosphere_baker_set_kernels(struct sb_atmosphere_baker *b, enum sb_atmosphere_kernels kernels)
{
    if (kernels == SB_ATMOSPHERE_KERNELS_CPU &&
        b->vk->properties.limits.maxComputeSharedMemorySize < SB_SPHERE_SHARED_BYTES)
        return SB_ERR_DEVICE_LIMIT;
    b->kernels = kernels;
    return SB_OK;
}

void sb_atmosphere_baker_destroy(struct sb_atmosphere_baker **pb)
{
    struct sb_atmosphere_baker *b = *pb;
    if (!b)
        return;
    for (int p = 0; p < SB_ATMOSPHERE_PRODUCT_COUNT; p++) {
        sb_buffer_destroy(b->vk, &b->outputs[p]);
        sb_buffer_destroy(b->vk, &b->lookups[p]);
    }
    sb_buffer_destroy(b->vk, &b->params);
    sb_buffer_destroy(b->vk, &b->dummy);
    sb_buffer_destroy(b->vk, &b->scratch);
    sb_buffer_destroy(b->vk, &b->sun_columns);
    sb_buffer_destroy(b->vk, &b->sun_rings);
    free(b);
    *pb = NULL;
}

/*
 * Run a kernel with the parameters and every product baked so far bound (a
 * product is never bound as its own input), writing `output`. The kernel
 * runs SB_WORKGROUP_X x SB_WORKGROUP_Y texels a workgroup in one dispatch,
 * or, for sphere.glsl's integrals over at most `directions` directions
 * (else 0), one workgroup per texel in passes of
 * SB_SPHERE_STEPS_PER_PASS directions per invocation on a CPU device (one
 * pass on a GPU), the partial sums kept
 * in the scratch buffer; *gpu_ms sums the passes.
 */
static struct sb_pipeline_params kernel_params(const struct spirv *kernel, const char *name)
{
    return (struct sb_pipeline_params){
        .spirv = kernel->words,
        .spirv_size = kernel->size,
        .binding_count = SB_BINDING_COUNT,
        .push_size = sizeof(struct sb_bake_push),
        .name = name,
    };
}

/* The kernel that bakes product `id` with settings `s` (resolved). */
static const struct spirv *product_kernel(const struct sb_atmosphere_baker *b, enum sb_product_id id,
                                          const struct sb_atmosphere_settings *s)
{
    if (id == SB_PRODUCT_TRANSMITTANCE)
        return &transmittance_shaders[s->quadrature == SB_QUADRATURE_GAUSS_LEGENDRE ? s->samples : 0];
    return is_anchor(id, s) ? &anchor_shaders[id] : &scattering_shaders[b->kernels][id];
}

static enum sb_result run(struct sb_atmosphere_baker *b, const struct spirv *kernel, const char *name,
                          struct sb_buffer *output, uint32_t width, uint32_t height, uint64_t directions,
                          bool group_per_texel, const struct sb_atmosphere_settings *s, double *gpu_ms)
{
    uint32_t directions_mu = s->directions_mu, directions_phi = s->directions_phi;
    struct sb_bake_push push = {
        .width = width,
        .height = height,
        .directions_mu = directions_mu,
        .directions_phi = directions_phi,
        .step_count = 1,
        .quadrature = s->quadrature,
        .samples = s->samples,
        .subdivisions = s->subdivisions,
    };
    enum sb_result res = SB_OK;
    bool workgroup_per_texel = directions > 0;
    /* One direction an invocation (sphere.glsl). */
    bool rays = workgroup_per_texel && kernel->rays;
    uint32_t ray_groups = 0;
    if (rays) {
        ray_groups = (uint32_t)((directions + kernel->threads - 1) / kernel->threads);
        push.direction_slots = ray_groups * kernel->threads;
    }
    if (workgroup_per_texel) {
        push.step_count = rays ? 1 : (uint32_t)((directions + kernel->threads - 1) / kernel->threads);
        size_t per_texel = rays ? push.direction_slots : kernel->threads;
        size_t sums = SB_SPHERE_COUNTERS((size_t)width * height, per_texel);
        size_t counters = rays ? (size_t)width * height : 0; /* a texel's workgroups done */
        size_t bytes = 16 + (sums + counters) * sizeof(float);
        if (b->scratch.size < bytes) {
            sb_buffer_destroy(b->vk, &b->scratch);
            if ((res = sb_buffer_create(b->vk, bytes, "sphere scratch", &b->scratch)))
                return res;
        }
        const uint32_t header[4] = {0, 1, 1, 0}; /* truncated flag, sentinel */
        memcpy(b->scratch.mapped, header, sizeof(header));
        memset((uint32_t *)b->scratch.mapped + 4 + sums, 0, counters * sizeof(uint32_t));
    }

    struct sb_pipeline pipeline = {0};
    struct sb_pipeline_params pp = kernel_params(kernel, name);
    if ((res = sb_pipeline_create(b->vk, &pp, &pipeline)))
        return res;
    const struct sb_buffer *bindings[SB_BINDING_COUNT] = {
        [SB_BINDING_OUTPUT] = output,
        [SB_BINDING_SCRATCH] = workgroup_per_texel ? &b->scratch : &b->dummy,
        [SB_BINDING_SUN_COLUMNS] = b->sun_columns.buffer && output != &b->sun_columns ? &b->sun_columns : &b->dummy,
        [SB_BINDING_SUN_RINGS] = b->sun_rings.buffer && output != &b->sun_rings ? &b->sun_rings : &b->dummy,
    };
    sb_atmosphere_bind_inputs(b, bindings);
    for (int i = SB_BINDING_TRANSMITTANCE; i <= SB_BINDING_IRRADIANCE_GROUND; i++)
        if (bindings[i] == output) /* a product is never its own input */
            bindings[i] = &b->dummy;
    sb_pipeline_bind(b->vk, &pipeline, bindings);
    group_per_texel = group_per_texel || workgroup_per_texel;
    uint32_t groups_x = group_per_texel ? width : (width + SB_WORKGROUP_X - 1) / SB_WORKGROUP_X;
    uint32_t groups_y = group_per_texel ? height : (height + SB_WORKGROUP_Y - 1) / SB_WORKGROUP_Y;
    double total_ms = 0;
    /* Passes exist for llvmpipe's loop limiter; a GPU takes all the steps
     * in one dispatch (the sums are the same: sphere.glsl). */
    uint32_t per_pass =
        b->vk->properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU ? SB_SPHERE_STEPS_PER_PASS : push.step_count;
    for (uint32_t step = 0; step < push.step_count && !res; step += per_pass) {
        push.step_begin = step;
        push.step_end = workgroup_per_texel && push.step_count - step > per_pass ? step + per_pass : push.step_count;
        double ms = 0;
        res = sb_dispatch(b->vk, &pipeline, &push, groups_x, groups_y, rays ? ray_groups : 1, &ms);
        total_ms += ms;
    }
    if (!res && workgroup_per_texel && *(const uint32_t *)b->scratch.mapped) {
        sb_error("%s: the device ended the shader's loops early (llvmpipe allows 65535 loop iterations per "
                 "invocation); the sums would be short, so nothing was baked",
                 name);
        res = SB_ERR_DEVICE_LIMIT;
    }
    if (gpu_ms)
        *gpu_ms = total_ms;
    sb_pipeline_destroy(b->vk, &pipeline);
    return res;
}

/* The scattering bakes' sun table (atmosphere.glsl), built before the first
 * of them reads it; *gpu_ms adds its time. */
static enum sb_result build_sun_columns(struct sb_atmosphere_baker *b, double *gpu_ms)
{
    enum sb_result res = SB_OK;
    if (!b->sun_columns.buffer &&
        (res = sb_buffer_create(b->vk, SB_SUN_COLUMNS_FLOATS * sizeof(float), "sun columns", &b->sun_columns)))
        return res;
    const struct sb_atmosphere_settings none = {0};
    double ms = 0, ghosts_ms = 0;
    res = run(b, &sun_columns_shader, "sun columns", &b->sun_columns, SB_SUN_COLUMNS_X + 2, 2 * (SB_SUN_COLUMNS_U + 2),
              0, false, &none, &ms);
    if (!res)
        res = run(b, &sun_columns_ghosts_shader, "sun columns' ghosts", &b->sun_columns, SB_SUN_COLUMNS_X + 2,
                  2 * (SB_SUN_COLUMNS_U + 2), 0, false, &none, &ghosts_ms);
    ms += ghosts_ms;
    if (res)
        sb_buffer_destroy(b->vk, &b->sun_columns);
    *gpu_ms += ms;
    return res;
}

/* Multiscattering's ring table (sun_rings.glsl) for a LUT `width` columns
 * wide, with the ring quadrature of `s`; *gpu_ms adds its time. */
static enum sb_result build_sun_rings(struct sb_atmosphere_baker *b, uint32_t width,
                                      const struct sb_atmosphere_settings *s, double *gpu_ms)
{
    sb_buffer_destroy(b->vk, &b->sun_rings);
    enum sb_result res =
        sb_buffer_create(b->vk, (size_t)width * SB_RINGS_COLUMN * 4 * sizeof(float), "sun rings", &b->sun_rings);
    if (res)
        return res;
    double ms = 0;
    res = run(b, &sun_rings_shader, "sun rings", &b->sun_rings, SB_RINGS_COLUMN, width, 0, false, s, &ms);
    if (res)
        sb_buffer_destroy(b->vk, &b->sun_rings);
    *gpu_ms += ms;
    return res;
}

/* The form in which later bakes read a product (physics.h). */
static enum sb_result make_lookup(struct sb_atmosphere_baker *b, enum sb_product_id id, const struct sb_image *image)
{
    size_t n = sb_lookup_float_count(id);
    if (!n)
        return SB_OK;
    enum sb_result res = sb_buffer_create(b->vk, n * sizeof(float), "lookup", &b->lookups[id]);
    if (!res)
        sb_lookup_fill(id, image, b->lookups[id].mapped);
    return res;
}

uint32_t sb_atmosphere_kernels(const struct sb_atmosphere_baker *b, enum sb_product_id id,
                               const struct sb_atmosphere_settings *settings,
                               struct sb_pipeline_params out[SB_ATMOSPHERE_KERNELS_MAX])
{
    const struct sb_atmosphere_product *prod = sb_atmosphere_product(id);
    struct sb_atmosphere_settings s = resolve_settings(id, settings);
    uint32_t n = 0;
    out[n++] = kernel_params(product_kernel(b, id, &s), sb_product_name(id));
    if (prod->workgroup_per_texel && !is_anchor(id, &s)) {
        out[n++] = kernel_params(&sun_columns_shader, "sun columns");
        out[n++] = kernel_params(&sun_columns_ghosts_shader, "sun columns' ghosts");
        if (prod->rings)
            out[n++] = kernel_params(&sun_rings_shader, "sun rings");
    }
    return n;
}

enum sb_result sb_atmosphere_bake(struct sb_atmosphere_baker *b, enum sb_product_id id,
                                  const struct sb_atmosphere_settings *settings, struct sb_image *image,
                                  struct sb_atmosphere_settings *used, double *gpu_ms)
{
    const struct sb_atmosphere_product *prod = sb_atmosphere_product(id);
    struct sb_atmosphere_settings s = resolve_settings(id, settings);
    if (used)
        *used = s;
    enum sb_result res = check_settings(id, &s);
    if (res)
        return res;
    for (int dep = 0; dep < SB_ATMOSPHERE_PRODUCT_COUNT; dep++)
        if ((prod->depends_on & BIT(dep)) && !b->outputs[dep].buffer) {
            sb_error("%s: needs %s, which has not been baked", sb_product_name(id),
                     sb_product_name((enum sb_product_id)dep));
            return SB_ERR_USAGE;
        }

    const struct sb_product_format *format = sb_product_format(id);
    uint32_t width = s.width ? s.width : format->width, height = s.height ? s.height : format->height;
    if ((res = sb_image_init(image, width, height, format->channel_count)))
        return res;
    sb_image_set_channel_names(image, format->channel_names);
    sb_buffer_destroy(b->vk, &b->outputs[id]);
    sb_buffer_destroy(b->vk, &b->lookups[id]);
    size_t bytes = sb_image_float_count(image) * sizeof(float);
    if ((res = sb_buffer_create(b->vk, bytes, sb_product_name(id), &b->outputs[id])))
        goto cleanup;

    bool anchor = is_anchor(id, &s);
    const struct spirv *shader = product_kernel(b, id, &s);
    bool cap = id == SB_PRODUCT_IRRADIANCE_GROUND || (id == SB_PRODUCT_IRRADIANCE_SKY && b->sky_cap);
    uint64_t directions = prod->workgroup_per_texel && !anchor ? sphere_directions(&s, cap, prod->rings) : 0;
    /* The sun table is built afresh by every multiscattering bake, the
     * first of the scattering products, so that its time counts there. */
    double table_ms = 0, rings_ms = 0, product_ms = 0;
    if (directions && (id == SB_PRODUCT_MULTISCATTERING || !b->sun_columns.buffer) &&
        (res = build_sun_columns(b, &table_ms)))
        goto cleanup;
    if (directions && prod->rings && (res = build_sun_rings(b, width, &s, &rings_ms)))
        goto cleanup;
    res = run(b, shader, sb_product_name(id), &b->outputs[id], width, height, directions, anchor, &s, &product_ms);
    sb_buffer_destroy(b->vk, &b->sun_rings);
    sb_log(SB_LOG_DEBUG, "%s: sun table %.3f ms, ring table %.3f ms, the product's kernel %.3f ms", sb_product_name(id),
           table_ms, rings_ms, product_ms);
    if (gpu_ms)
        *gpu_ms = table_ms + rings_ms + product_ms;
    if (res)
        goto cleanup;
    memcpy(image->data, b->outputs[id].mapped, bytes);
    /* A resolution other than the format's, or an anchor, is a measurement:
     * later bakes must not read it. */
    if (anchor || width != format->width || height != format->height)
        sb_buffer_destroy(b->vk, &b->outputs[id]);
    else
        res = make_lookup(b, id, image);

cleanup:
    if (res)
        sb_image_finish(image);
    return res;
}

enum sb_result sb_atmosphere_adopt(struct sb_atmosphere_baker *b, enum sb_product_id id, const struct sb_image *image)
{
    const struct sb_product_format *format = sb_product_format(id);
    if (image->width != format->width || image->height != format->height ||
        image->channel_count != format->channel_count)
        return SB_ERR_BAD_IMAGE;
    sb_buffer_destroy(b->vk, &b->outputs[id]);
    sb_buffer_destroy(b->vk, &b->lookups[id]);
    size_t bytes = sb_image_float_count(image) * sizeof(float);
    enum sb_result res = sb_buffer_create(b->vk, bytes, sb_product_name(id), &b->outputs[id]);
    if (res)
        return res;
    memcpy(b->outputs[id].mapped, image->data, bytes);
    return make_lookup(b, id, image);
}

void sb_atmosphere_code_hash(enum sb_product_id id, char out[SB_HASH_HEX_SIZE])
{
    /* The hashes of each kernel, then the constants, as one text. */
    char text[(SB_GL_MAX_ORDER + 1) * SB_HASH_HEX_SIZE + 256];
    size_t n = 0;
    /* Every shader that may bake the product, whatever the device. */
    const struct spirv *shaders[SB_GL_MAX_ORDER + 1];
    int count = 0;
    if (id == SB_PRODUCT_TRANSMITTANCE)
        for (int i = 0; i <= SB_GL_MAX_ORDER; i++)
            shaders[count++] = &transmittance_shaders[i];
    else
        for (int k = 0; k < 2; k++)
            shaders[count++] = &scattering_shaders[k][id];
    for (int i = 0; i < count; i++) {
        sb_hash_bytes(shaders[i]->words, shaders[i]->size, text + n);
        n += SB_HASH_HEX_SIZE - 1;
    }
    if (id != SB_PRODUCT_TRANSMITTANCE) /* they read the sun table */
        for (int k = 0; k < 2; k++) {
            const struct spirv *table = k ? &sun_columns_ghosts_shader : &sun_columns_shader;
            sb_hash_bytes(table->words, table->size, text + n);
            n += SB_HASH_HEX_SIZE - 1;
        }
    if (products[id].rings) {
        sb_hash_bytes(sun_rings_shader.words, sun_rings_shader.size, text + n);
        n += SB_HASH_HEX_SIZE - 1;
    }
    snprintf(text + n, sizeof(text) - n, " recipe %d cap %a %a %d", SB_ATMOSPHERE_RECIPE, (double)SB_CAP_MIN_G,
             (double)SB_CAP_THETA, SB_SPHERE_CAP_PIECES);
    sb_hash_bytes(text, strlen(text), out);
}

void sb_atmosphere_bind_inputs(struct sb_atmosphere_baker *b, const struct sb_buffer **bindings)
{
    static const int inputs[][2] = {
        {SB_BINDING_TRANSMITTANCE, SB_PRODUCT_TRANSMITTANCE},
        {SB_BINDING_MULTISCATTERING, SB_PRODUCT_MULTISCATTERING},
        {SB_BINDING_IRRADIANCE_GROUND, SB_PRODUCT_IRRADIANCE_GROUND},
    };
    bindings[SB_BINDING_ATMOSPHERE] = &b->params;
    for (size_t i = 0; i < sizeof(inputs) / sizeof(inputs[0]); i++) {
        const struct sb_buffer *in = &b->lookups[inputs[i][1]];
        if (!in->buffer)
            in = &b->outputs[inputs[i][1]];
        bindings[inputs[i][0]] = in->buffer ? in : &b->dummy;
    }
}

enum sb_result sb_atmosphere_run_kernel(struct sb_atmosphere_baker *b, const uint32_t *spirv, size_t spirv_size,
                                        float *records, uint32_t record_count, uint32_t record_floats)
{
    if (!record_count || !record_floats)
        return SB_ERR_USAGE;
    struct sb_buffer io = {0};
    size_t bytes = (size_t)record_count * record_floats * sizeof(float);
    enum sb_result res = sb_buffer_create(b->vk, bytes, "kernel records", &io);
    if (res)
        return res;
    memcpy(io.mapped, records, bytes);
    uint32_t per_row = SB_WORKGROUP_X * 32;
    uint32_t width = record_count < per_row ? record_count : per_row;
    uint32_t height = (record_count + per_row - 1) / per_row;
    struct sb_atmosphere_settings s = {.directions_mu = record_count, .directions_phi = record_floats};
    const struct spirv kernel = {.words = spirv, .size = spirv_size};
    res = run(b, &kernel, "kernel", &io, width, height, 0, false, &s, NULL);
    if (!res)
        memcpy(records, io.mapped, bytes);
    sb_buffer_destroy(b->vk, &io);
    return res;
}

void sb_atmosphere_settings_json(enum sb_product_id id, const struct sb_atmosphere_settings *s, char *out, size_t size)
{
    if (id == SB_PRODUCT_TRANSMITTANCE) {
        struct sb_atmosphere_settings t = resolve_settings(id, s);
        if (t.quadrature == SB_QUADRATURE_GAUSS_LEGENDRE)
            snprintf(out, size,
                     "{\"quadrature\":\"gauss-legendre\",\"order\":%u,\"subdivisions\":%u,"
                     "\"pieces\":\"cut at the ozone corners and the tangent fold\",\"max_samples\":%llu}",
                     t.samples, t.subdivisions, (unsigned long long)sb_atmosphere_settings_cost(id, &t));
        else
            snprintf(out, size, "{\"quadrature\":\"%s\",\"steps\":%u,\"max_samples\":%llu}",
                     t.quadrature == SB_QUADRATURE_TRAPEZOID  ? "trapezoid"
                     : t.quadrature == SB_QUADRATURE_MIDPOINT ? "midpoint"
                                                              : "uniform, offset 0.3",
                     t.samples, (unsigned long long)sb_atmosphere_settings_cost(id, &t));
        return;
    }
    if (products[id].rings) {
        snprintf(out, size,
                 "{\"directions_mu\":%u,\"directions_phi\":%u,"
                 "\"zenith\":\"gauss-legendre per piece, cut at the horizon, two ground depths, the ozone corners, "
                 "25 scale heights of tangent altitude and the sun's mirror\","
                 "\"azimuth\":\"integrated first: the ring table, %d rows (split where the sun sets) x (%d + %d) "
                 "angles (split at the shadow's tangency) a column, %d on the ground, Catmull-Rom; each ring "
                 "gauss-legendre-%u a piece, cut at the shadow and the ozone tangencies\","
                 "\"ray_segments\":\"altitude levels, geometric from half the smallest scale height, the ozone "
                 "corners, the closest point, and where a ring touches the shadow or an ozone tangency\","
                 "\"segment_quadrature\":\"gauss-legendre-%d\",\"sun_transmittance\":\"the sun table: "
                 "Catmull-Rom of Rayleigh and Mie airmasses on %dx%d nodes a region, ozone integrated\"}",
                 s->directions_mu, s->directions_phi, SB_RINGS_ROWS, SB_RINGS_INNER, SB_RINGS_OUTER, SB_RINGS_GROUND,
                 s->directions_phi, SB_RAY_GL_ORDER, SB_SUN_COLUMNS_X, SB_SUN_COLUMNS_U);
        return;
    }
    const char *zenith_cuts = id == SB_PRODUCT_IRRADIANCE_GROUND
                                  ? "the sun's mirror and the sun (upper hemisphere)"
                                  : "the horizon, two ground depths, the ozone corners, 25 scale heights of "
                                    "tangent altitude, the sun's mirror and the sun";
    char day_azimuths[256];
    snprintf(day_azimuths, sizeof(day_azimuths),
             "\"azimuth_by_day\":\"where the sun is %g rad above every seen point's horizontal: %u even nodes, "
             "the phase functions by product integration, %d nodes\",",
             SB_AZIMUTH_DAY_MARGIN, (s->directions_phi + 3) / 4, SB_AZIMUTH_DENSE);
    snprintf(
        out, size,
        "{\"directions_mu\":%u,\"directions_phi\":%u,"
        "\"zenith\":\"gauss-legendre per piece, cut at %s\","
        "\"azimuth\":\"midpoint over [0, pi]%s\","
        "%s"
        "\"ray_segments\":\"altitude levels, geometric from half the smallest scale height,%s the shadow "
        "boundary and the sun grazing the ozone corners\",\"segment_quadrature\":\"gauss-legendre-%d\","
        "\"sun_transmittance\":\"the sun table: Catmull-Rom of Rayleigh and Mie airmasses on %dx%d nodes a region, "
        "ozone integrated\"%s}",
        s->directions_mu, s->directions_phi, zenith_cuts, ", crowded toward the sun",
        id == SB_PRODUCT_IRRADIANCE_SKY ? day_azimuths : "",
        id == SB_PRODUCT_IRRADIANCE_SKY ? "" : " the ozone corners,", SB_RAY_GL_ORDER, SB_SUN_COLUMNS_X,
        SB_SUN_COLUMNS_U, ",\"lut_lookup\":\"catmull-rom of the logarithm\"");
}

#include "atmosphere.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "irradiance_ground.spv.h"
#include "irradiance_sky.spv.h"
#include "log.h"
#include "multiscattering.spv.h"
#include "physics.h"
#include "transmittance.spv.h"

#define BIT(p) (1u << (p))

static const struct sb_atmosphere_product products[SB_PRODUCT_COUNT] = {
    [SB_PRODUCT_TRANSMITTANCE] =
        {
            .id = SB_PRODUCT_TRANSMITTANCE,
        },
    [SB_PRODUCT_MULTISCATTERING] =
        {
            .id = SB_PRODUCT_MULTISCATTERING,
            .depends_on = BIT(SB_PRODUCT_TRANSMITTANCE),
            .defaults = {.directions_mu = 16, .directions_phi = 12},
            .workgroup_per_texel = true,
        },
    [SB_PRODUCT_IRRADIANCE_GROUND] =
        {
            .id = SB_PRODUCT_IRRADIANCE_GROUND,
            .depends_on = BIT(SB_PRODUCT_TRANSMITTANCE) | BIT(SB_PRODUCT_MULTISCATTERING),
            .defaults = {.directions_mu = 12, .directions_phi = 12},
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

static const struct {
    const uint32_t *words;
    size_t size;
} shaders[SB_PRODUCT_COUNT] = {
    [SB_PRODUCT_TRANSMITTANCE] = {sb_spv_transmittance, sizeof(sb_spv_transmittance)},
    [SB_PRODUCT_MULTISCATTERING] = {sb_spv_multiscattering, sizeof(sb_spv_multiscattering)},
    [SB_PRODUCT_IRRADIANCE_GROUND] = {sb_spv_irradiance_ground, sizeof(sb_spv_irradiance_ground)},
    [SB_PRODUCT_IRRADIANCE_SKY] = {sb_spv_irradiance_sky, sizeof(sb_spv_irradiance_sky)},
};

const struct sb_atmosphere_product *sb_atmosphere_product(enum sb_product_id id)
{
    return &products[id];
}

struct sb_atmosphere_baker {
    struct sb_vk *vk;
    struct sb_buffer params;
    struct sb_buffer dummy;
    struct sb_buffer scratch; /* sphere.glsl's sums between passes */
    struct sb_buffer outputs[SB_PRODUCT_COUNT];
    struct sb_buffer lookups[SB_PRODUCT_COUNT]; /* the form later bakes read (config.h) */
};

enum sb_result sb_atmosphere_baker_create(struct sb_vk *vk, const struct sb_atmosphere_params *params,
                                          struct sb_atmosphere_baker **out)
{
    *out = NULL;
    struct sb_atmosphere_baker *b = calloc(1, sizeof(*b));
    if (!b)
        return SB_ERR_NOMEM;
    b->vk = vk;
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

void sb_atmosphere_baker_destroy(struct sb_atmosphere_baker **pb)
{
    struct sb_atmosphere_baker *b = *pb;
    if (!b)
        return;
    for (int p = 0; p < SB_PRODUCT_COUNT; p++) {
        sb_buffer_destroy(b->vk, &b->outputs[p]);
        sb_buffer_destroy(b->vk, &b->lookups[p]);
    }
    sb_buffer_destroy(b->vk, &b->params);
    sb_buffer_destroy(b->vk, &b->dummy);
    sb_buffer_destroy(b->vk, &b->scratch);
    free(b);
    *pb = NULL;
}

/*
 * Run a kernel with the parameters and every product baked so far bound (a
 * product is never bound as its own input), writing `output`. The kernel
 * runs SB_WORKGROUP_X x SB_WORKGROUP_Y texels a workgroup in one dispatch,
 * or, for sphere.glsl's integrals, one workgroup per texel in passes of
 * SB_SPHERE_STEPS_PER_PASS directions per invocation, the partial sums kept
 * in the scratch buffer; *gpu_ms sums the passes.
 */
static enum sb_result run(struct sb_atmosphere_baker *b, const uint32_t *spirv, size_t spirv_size, const char *name,
                          struct sb_buffer *output, uint32_t width, uint32_t height, bool workgroup_per_texel,
                          uint32_t directions_mu, uint32_t directions_phi, double *gpu_ms)
{
    struct sb_bake_push push = {
        .width = width,
        .height = height,
        .directions_mu = directions_mu,
        .directions_phi = directions_phi,
        .step_count = 1,
    };
    enum sb_result res = SB_OK;
    if (workgroup_per_texel) {
        uint64_t directions = (uint64_t)SB_SPHERE_MAX_PIECES * directions_mu * directions_phi;
        push.step_count = (uint32_t)((directions + SB_SPHERE_THREADS - 1) / SB_SPHERE_THREADS);
        size_t bytes = 16 + (size_t)width * height * SB_SPHERE_THREADS * SB_SPHERE_MAX_SUMS * sizeof(float);
        if (b->scratch.size < bytes) {
            sb_buffer_destroy(b->vk, &b->scratch);
            if ((res = sb_buffer_create(b->vk, bytes, "sphere scratch", &b->scratch)))
                return res;
        }
        const uint32_t header[4] = {0, 1, 1, 0}; /* truncated flag, sentinel */
        memcpy(b->scratch.mapped, header, sizeof(header));
    }

    struct sb_pipeline pipeline = {0};
    struct sb_pipeline_params pp = {
        .spirv = spirv,
        .spirv_size = spirv_size,
        .binding_count = SB_BINDING_COUNT,
        .push_size = sizeof(struct sb_bake_push),
        .name = name,
    };
    if ((res = sb_pipeline_create(b->vk, &pp, &pipeline)))
        return res;
    const struct sb_buffer *bindings[SB_BINDING_COUNT] = {
        [SB_BINDING_ATMOSPHERE] = &b->params,
        [SB_BINDING_OUTPUT] = output,
        [SB_BINDING_SCRATCH] = workgroup_per_texel ? &b->scratch : &b->dummy,
    };
    static const int inputs[][2] = {
        {SB_BINDING_TRANSMITTANCE, SB_PRODUCT_TRANSMITTANCE},
        {SB_BINDING_MULTISCATTERING, SB_PRODUCT_MULTISCATTERING},
        {SB_BINDING_IRRADIANCE_GROUND, SB_PRODUCT_IRRADIANCE_GROUND},
    };
    for (size_t i = 0; i < sizeof(inputs) / sizeof(inputs[0]); i++) {
        const struct sb_buffer *in = &b->lookups[inputs[i][1]];
        if (!in->buffer)
            in = &b->outputs[inputs[i][1]];
        bindings[inputs[i][0]] = in->buffer && in != output ? in : &b->dummy;
    }
    sb_pipeline_bind(b->vk, &pipeline, bindings);
    uint32_t groups_x = workgroup_per_texel ? width : (width + SB_WORKGROUP_X - 1) / SB_WORKGROUP_X;
    uint32_t groups_y = workgroup_per_texel ? height : (height + SB_WORKGROUP_Y - 1) / SB_WORKGROUP_Y;
    double total_ms = 0;
    for (uint32_t step = 0; step < push.step_count && !res; step += SB_SPHERE_STEPS_PER_PASS) {
        push.step_begin = step;
        push.step_end = workgroup_per_texel && push.step_count - step > SB_SPHERE_STEPS_PER_PASS
                            ? step + SB_SPHERE_STEPS_PER_PASS
                            : push.step_count;
        double ms = 0;
        res = sb_dispatch(b->vk, &pipeline, &push, groups_x, groups_y, 1, &ms);
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

enum sb_result sb_atmosphere_bake(struct sb_atmosphere_baker *b, enum sb_product_id id,
                                  const struct sb_atmosphere_settings *settings, struct sb_image *image,
                                  struct sb_atmosphere_settings *used, double *gpu_ms)
{
    const struct sb_atmosphere_product *prod = &products[id];
    struct sb_atmosphere_settings s = prod->defaults;
    if (settings && settings->directions_mu)
        s.directions_mu = settings->directions_mu;
    if (settings && settings->directions_phi)
        s.directions_phi = settings->directions_phi;
    if (used)
        *used = s;
    if (prod->workgroup_per_texel &&
        (s.directions_mu < 1 || s.directions_mu > SB_MAX_DIRECTIONS_MU || s.directions_phi < 1)) {
        sb_error("%s: directions_mu must be 1 to %d and directions_phi at least 1 (got %u, %u)", sb_product_name(id),
                 SB_MAX_DIRECTIONS_MU, s.directions_mu, s.directions_phi);
        return SB_ERR_USAGE;
    }
    for (int dep = 0; dep < SB_PRODUCT_COUNT; dep++)
        if ((prod->depends_on & BIT(dep)) && !b->outputs[dep].buffer) {
            sb_error("%s: needs %s, which has not been baked", sb_product_name(id),
                     sb_product_name((enum sb_product_id)dep));
            return SB_ERR_USAGE;
        }

    const struct sb_product_format *format = sb_product_format(id);
    enum sb_result res = sb_image_init(image, format->width, format->height, format->channel_count);
    if (res)
        return res;
    sb_image_set_channel_names(image, format->channel_names);
    sb_buffer_destroy(b->vk, &b->outputs[id]);
    sb_buffer_destroy(b->vk, &b->lookups[id]);
    size_t bytes = sb_image_float_count(image) * sizeof(float);
    if ((res = sb_buffer_create(b->vk, bytes, sb_product_name(id), &b->outputs[id])))
        goto cleanup;

    if ((res = run(b, shaders[id].words, shaders[id].size, sb_product_name(id), &b->outputs[id], format->width,
                   format->height, prod->workgroup_per_texel, s.directions_mu, s.directions_phi, gpu_ms)))
        goto cleanup;
    memcpy(image->data, b->outputs[id].mapped, bytes);
    res = make_lookup(b, id, image);

cleanup:
    if (res)
        sb_image_finish(image);
    return res;
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
    res = run(b, spirv, spirv_size, "kernel", &io, width, height, false, record_count, record_floats, NULL);
    if (!res)
        memcpy(records, io.mapped, bytes);
    sb_buffer_destroy(b->vk, &io);
    return res;
}

void sb_atmosphere_settings_json(enum sb_product_id id, const struct sb_atmosphere_settings *s, char *out, size_t size)
{
    if (id == SB_PRODUCT_TRANSMITTANCE) {
        snprintf(out, size,
                 "{\"quadrature\":\"gauss-legendre-8, pieces cut at the ozone corners and the tangent fold\","
                 "\"max_samples\":40}");
        return;
    }
    const char *zenith_cuts = id == SB_PRODUCT_IRRADIANCE_GROUND ? "the sun's mirror and the sun (upper hemisphere)"
                              : id == SB_PRODUCT_MULTISCATTERING
                                  ? "the horizon, two ground depths, the ozone corners and the sun's mirror"
                                  : "the horizon, two ground depths, the ozone corners, the sun's mirror and "
                                    "the sun";
    snprintf(out, size,
             "{\"directions_mu\":%u,\"directions_phi\":%u,"
             "\"zenith\":\"gauss-legendre per piece, cut at %s\","
             "\"azimuth\":\"midpoint over [0, pi]%s\","
             "\"ray_segments\":\"altitude levels, geometric from half the smallest scale height, the shadow "
             "boundary and the sun grazing the ozone corners\",\"segment_quadrature\":\"gauss-legendre-%d\","
             "\"sun_transmittance\":\"integrated, at most 40 samples\"%s}",
             s->directions_mu, s->directions_phi, zenith_cuts,
             id == SB_PRODUCT_MULTISCATTERING ? "" : ", crowded toward the sun", SB_RAY_GL_ORDER,
             id == SB_PRODUCT_MULTISCATTERING ? "" : ",\"lut_lookup\":\"catmull-rom of the logarithm\"");
}

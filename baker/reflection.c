#include "reflection.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "config.h"
#include "cube.h"
#include "exr.h"
#include "log.h"
#include "physics.h"
#include "reflection_capture.spv.h"
#include "reflection_prefilter.spv.h"
#include "sh.h"

void sb_reflection_kernels_destroy(struct sb_vk *vk, struct sb_reflection_kernels *k)
{
    sb_pipeline_destroy(vk, &k->capture);
    sb_pipeline_destroy(vk, &k->prefilter);
}

struct sb_pipeline_params sb_reflection_capture_kernel(void)
{
    return (struct sb_pipeline_params){
        .spirv = sb_spv_reflection_capture,
        .spirv_size = sizeof(sb_spv_reflection_capture),
        .binding_count = SB_CAPTURE_BINDING_COUNT,
        .push_size = sizeof(struct sb_capture_push),
        .name = "reflection capture",
    };
}

struct sb_pipeline_params sb_reflection_prefilter_kernel(void)
{
    return (struct sb_pipeline_params){
        .spirv = sb_spv_reflection_prefilter,
        .spirv_size = sizeof(sb_spv_reflection_prefilter),
        .binding_count = SB_PREFILTER_BINDING_COUNT,
        .push_size = sizeof(struct sb_prefilter_push),
        .name = "reflection prefilter",
    };
}

/* The cached pipeline (made on first use) or, without a cache, `temp`. */
static enum sb_result pipeline_for(struct sb_vk *vk, struct sb_pipeline *cached, const struct sb_pipeline_params *pp,
                                   struct sb_pipeline *temp, struct sb_pipeline **use)
{
    struct sb_pipeline *p = cached ? cached : temp;
    *use = p;
    return p->pipeline ? SB_OK : sb_pipeline_create(vk, pp, p);
}

enum sb_result sb_reflection_capture(struct sb_vk *vk, const struct sb_capture_inputs *in,
                                     const struct sb_capture_params *p, float *out, float *surfaces, double *gpu_ms)
{
    uint32_t n = p->face_size;
    struct sb_capture_push pc = {
        .origin_m = {p->origin_m[0], p->origin_m[1], p->origin_m[2], (float)p->altitude_km},
        .sun_direction = {(float)p->sun[0], (float)p->sun[1], (float)p->sun[2], 0},
        .face_size = n,
        .has_world = in->rc != NULL,
        .ambient_rays = p->ambient_rays,
        .tmin_m = 1e-4f,
    };
    struct sb_buffer result = {0}, sky = {0}, dummy = {0}, relight = {0};
    struct sb_pipeline temp = {0}, *pipeline = NULL;
    const struct sb_pipeline_params pp = sb_reflection_capture_kernel();
    enum sb_result res;
    if ((res = sb_buffer_create(vk, (VkDeviceSize)6 * n * n * 4 * sizeof(float), "reflection capture", &result)) ||
        (res = sb_buffer_create(vk, SB_PROBE_SH * 4 * sizeof(float), "sky sh", &sky)) ||
        (res = sb_buffer_create(vk, 64, "no world", &dummy)) ||
        (res = sb_buffer_create(vk, (VkDeviceSize)6 * n * n * SB_RELIGHT_VEC4S * 4 * sizeof(float), "relight surfaces",
                                &relight)) ||
        (res = pipeline_for(vk, in->kernels ? &in->kernels->capture : NULL, &pp, &temp, &pipeline)))
        goto done;
    float *s = sky.mapped;
    for (int k = 0; k < SB_PROBE_SH; k++)
        for (int c = 0; c < 3; c++)
            s[4 * k + c] = (float)p->sky_sh[k][c];
    const struct sb_buffer *bindings[SB_CAPTURE_BINDING_COUNT] = {
        [SB_CAPTURE_BINDING_OUT] = &result,
        [SB_CAPTURE_BINDING_NODES] = in->rc ? &in->rc->nodes : &dummy,
        [SB_CAPTURE_BINDING_TRIANGLES] = in->rc ? &in->rc->triangles : &dummy,
        [SB_CAPTURE_BINDING_SKY_SH] = &sky,
        [SB_CAPTURE_BINDING_SURFACES_OUT] = &relight,
    };
    if (in->rc)
        sb_surfaces_bindings(in->surfaces, &bindings[SB_CAPTURE_BINDING_SURFACE]);
    else
        for (int b = 0; b < SB_SURFACE_BINDING_COUNT; b++)
            bindings[SB_CAPTURE_BINDING_SURFACE + b] = &dummy;
    sb_atmosphere_bind_inputs(in->atmosphere, bindings);
    sb_pipeline_bind(vk, pipeline, bindings);
    /* the passes (config.h, SB_CAPTURE_PASS_DIRECTIONS), in a fixed order;
     * one without a world */
    double total = 0;
    uint32_t directions = in->rc ? 2 * p->ambient_rays : 1;
    for (uint32_t first = 0; first < directions && !res; first += SB_CAPTURE_PASS_DIRECTIONS) {
        double ms = 0;
        pc.first_direction = first;
        pc.accumulate = first > 0;
        res = sb_dispatch(vk, pipeline, &pc, (n + SB_WORKGROUP_X - 1) / SB_WORKGROUP_X,
                          (6 * n + SB_WORKGROUP_Y - 1) / SB_WORKGROUP_Y, 1, &ms);
        total += ms;
    }
    if (!res)
        res = sb_buffer_read(vk, &result, out);
    if (!res && surfaces)
        res = sb_buffer_read(vk, &relight, surfaces);
    if (gpu_ms)
        *gpu_ms = total;
done:
    sb_pipeline_destroy(vk, &temp);
    sb_buffer_destroy(vk, &result);
    sb_buffer_destroy(vk, &sky);
    sb_buffer_destroy(vk, &dummy);
    sb_buffer_destroy(vk, &relight);
    return res;
}

enum sb_result sb_reflection_prefilter(struct sb_vk *vk, const float *level0, uint32_t n,
                                       const struct sb_prefilter_params *params, float *out, double *gpu_ms)
{
    uint32_t samples = params->samples;
    uint32_t levels = sb_cube_levels(n);
    if (levels > SB_PREFILTER_MAX_LEVELS || !samples) {
        sb_error("reflection prefilter: %u levels (at most %d) or no samples", levels, SB_PREFILTER_MAX_LEVELS);
        return SB_ERR_OUT_OF_RANGE;
    }
    uint64_t texels = sb_cube_level_offset(n, levels);
    struct sb_buffer source = {0}, result = {0};
    struct sb_pipeline temp = {0}, *pipeline = NULL;
    const struct sb_pipeline_params pp = sb_reflection_prefilter_kernel();
    enum sb_result res;
    if ((res = sb_buffer_create(vk, texels * 4 * sizeof(float), "prefilter source", &source)) ||
        (res = sb_buffer_create(vk, texels * 4 * sizeof(float), "prefiltered", &result)) ||
        (res = pipeline_for(vk, params->kernels ? &params->kernels->prefilter : NULL, &pp, &temp, &pipeline)))
        goto done;
    /* Built in host memory: a device's mapped memory may be uncached, and
     * each level reads the one before (seconds on an H100 otherwise). */
    float *chain = malloc(texels * 4 * sizeof(float));
    if (!chain) {
        res = SB_ERR_NOMEM;
        goto done;
    }
    memcpy(chain, level0, (size_t)6 * n * n * 4 * sizeof(float));
    sb_cube_build_mips(chain, n, levels);
    memcpy(source.mapped, chain, texels * 4 * sizeof(float));
    free(chain);
    const struct sb_buffer *bindings[SB_PREFILTER_BINDING_COUNT] = {
        [SB_PREFILTER_BINDING_SOURCE] = &source, [SB_PREFILTER_BINDING_OUT] = &result};
    sb_pipeline_bind(vk, pipeline, bindings);
    /* skybake's: no bias on Colbert and Krivanek's lod (their +1 blurs: 2
     * to 4 times the error against the reference), and no source level of
     * faces under 4 texels (a rough lobe read from 1 x 1 faces is six flat
     * patches). */
    struct sb_prefilter_push pc = {
        .face_size = n,
        .levels = levels,
        .lod_bias = params->lod_bias,
        .max_lod = params->unfiltered ? 0.0f
                   : levels > 3       ? (float)(levels - 3)
                                      : 0.0f,
    };
    for (uint32_t l = 0; l < levels; l++)
        pc.source_offsets[l / 4][l % 4] = (uint32_t)sb_cube_level_offset(n, l);
    double total = 0;
    for (uint32_t l = 1; l < levels && !res; l++) {
        uint32_t m = n >> l;
        double ms = 0;
        pc.level = l;
        pc.samples = params->constant_samples ? samples : sb_reflection_level_samples(samples, l);
        uint32_t groups[2];
        sb_prefilter_layout(pc.samples, 6ull * m * m, SB_PREFILTER_THREADS, &pc.threads_per_texel, groups);
        pc.groups_x = groups[0];
        pc.roughness = (float)sb_reflection_level_roughness(l, levels);
        pc.out_offset = (uint32_t)sb_cube_level_offset(n, l);
        res = sb_dispatch(vk, pipeline, &pc, groups[0], groups[1], 1, &ms);
        total += ms;
    }
    if (!res)
        res = sb_buffer_read(vk, &result, out);
    if (!res) /* level 0: the mirror */
        memcpy(out, level0, (size_t)6 * n * n * 4 * sizeof(float));
    if (gpu_ms)
        *gpu_ms = total;
done:
    sb_pipeline_destroy(vk, &temp);
    sb_buffer_destroy(vk, &source);
    sb_buffer_destroy(vk, &result);
    return res;
}

void sb_reflection_sh(const float *level0, uint32_t n, int irradiance, double sh[9][3])
{
    memset(sh, 0, 9 * 3 * sizeof(double));
    for (int f = 0; f < 6; f++)
        for (uint32_t y = 0; y < n; y++)
            for (uint32_t x = 0; x < n; x++) {
                double d[3], basis[SB_PROBE_SH];
                sb_cube_texel_direction(f, n, x, y, d);
                sb_sh9_basis(d, basis);
                double u0 = 2.0 * x / n - 1, v0 = 2.0 * y / n - 1, step = 2.0 / n;
                double w = sb_cube_solid_angle(u0, v0, u0 + step, v0 + step);
                const float *L = &level0[4 * ((size_t)f * n * n + (size_t)y * n + x)];
                for (int k = 0; k < SB_PROBE_SH; k++)
                    for (int c = 0; c < 3; c++)
                        sh[k][c] += w * basis[k] * L[c];
            }
    if (irradiance) { /* the clamped cosine's factor of each band (config.h) */
        static const double cosine[3] = {SB_SH_COSINE_FACTORS};
        static const int band[SB_PROBE_SH] = {SB_SH_BANDS};
        for (int k = 0; k < SB_PROBE_SH; k++)
            for (int c = 0; c < 3; c++)
                sh[k][c] *= cosine[band[k]];
    }
}

void sb_reflection_code_hash(char out[33])
{
    char text[3 * 33 + 16];
    sb_hash_bytes(sb_spv_reflection_capture, sizeof(sb_spv_reflection_capture), text);
    sb_hash_bytes(sb_spv_reflection_prefilter, sizeof(sb_spv_reflection_prefilter), text + 32);
    sb_surfaces_code_hash(text + 64);
    sb_hash_bytes(text, 96, out);
}

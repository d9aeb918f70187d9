#include "sky_bounce.h"

#include <string.h>

#include "log.h"
#include "probe_bounce.spv.h"
#include "probe_bounce_instanced.spv.h"

struct sb_pipeline_params sb_sky_bounce_kernel(bool instanced)
{
    return (struct sb_pipeline_params){
        .spirv = instanced ? sb_spv_probe_bounce_instanced : sb_spv_probe_bounce,
        .spirv_size = instanced ? sizeof(sb_spv_probe_bounce_instanced) : sizeof(sb_spv_probe_bounce),
        .binding_count = SB_BOUNCE_BINDING_COUNT,
        .push_size = sizeof(struct sb_bounce_push),
        .name = "sky bounce",
    };
}

enum sb_result sb_sky_bounce_bake(struct sb_raycaster *rc, const struct sb_surfaces *surfaces, const float *positions,
                                  const float *valid, uint32_t probe_count, const struct sb_sky_bounce_params *params,
                                  float *out, double *gpu_ms)
{
    static const struct sb_sky_bounce_params defaults = {0};
    params = params ? params : &defaults;
    struct sb_bounce_push pc = {
        .probe_count = probe_count,
        .ray_count = params->ray_count ? params->ray_count : 256,
        .secondary = params->secondary ? params->secondary : 64,
        .tmin_m = params->tmin_m > 0 ? params->tmin_m : 1e-4f,
    };
    if (gpu_ms)
        *gpu_ms = 0;
    if (pc.ray_count % SB_PROBE_THREADS || pc.ray_count > SB_PROBE_MAX_RAYS || pc.secondary > SB_PROBE_MAX_RAYS / 2 ||
        !probe_count || !surfaces->material_count) {
        sb_error("sky bounce: %u rays and %u from each hit for %u probes (rays: a multiple of %u up to %u)",
                 pc.ray_count, pc.secondary, probe_count, SB_PROBE_THREADS, SB_PROBE_MAX_RAYS);
        return SB_ERR_OUT_OF_RANGE;
    }
    struct sb_vk *vk = rc->vk;
    struct sb_buffer probes = {0}, results = {0};
    struct sb_pipeline pipeline = {0};
    const struct sb_pipeline_params pp = sb_sky_bounce_kernel(rc->instanced);
    enum sb_result res;
    if ((res = sb_probe_buffers_create(vk, positions, valid, probe_count, SB_BOUNCE_FLOATS, &probes, &results)) ||
        (res = sb_pipeline_create(vk, &pp, &pipeline)))
        goto done;
    const struct sb_buffer *bindings[SB_BOUNCE_BINDING_COUNT] = {
        [SB_RAYCAST_BINDING_NODES] = &rc->nodes,
        [SB_RAYCAST_BINDING_TRIANGLES] = &rc->triangles,
        [SB_RAYCAST_BINDING_RAYS] = &probes,
        [SB_RAYCAST_BINDING_HITS] = &results,
    };
    sb_surfaces_bindings(surfaces, &bindings[SB_BOUNCE_BINDING_SURFACE]);
    sb_pipeline_bind(vk, &pipeline, bindings);
    res = sb_probe_kernel_run(vk, &pipeline, &pc, probe_count, &results, out, gpu_ms);
done:
    sb_pipeline_destroy(vk, &pipeline);
    sb_buffer_destroy(vk, &results);
    sb_buffer_destroy(vk, &probes);
    return res;
}

void sb_sky_bounce_code_hash(char out[33])
{
    char both[2 * 33];
    sb_kernel_code_hash(sb_spv_probe_bounce, sizeof(sb_spv_probe_bounce), sb_spv_probe_bounce_instanced,
                        sizeof(sb_spv_probe_bounce_instanced), both);
    sb_surfaces_code_hash(both + 32);
    sb_hash_bytes(both, 64, out);
}

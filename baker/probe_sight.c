#include "probe_sight.h"

#include <string.h>

#include "log.h"
#include "probe_sight.spv.h"
#include "probe_sight_instanced.spv.h"

struct sb_pipeline_params sb_probe_sight_kernel(bool instanced)
{
    return (struct sb_pipeline_params){
        .spirv = instanced ? sb_spv_probe_sight_instanced : sb_spv_probe_sight,
        .spirv_size = instanced ? sizeof(sb_spv_probe_sight_instanced) : sizeof(sb_spv_probe_sight),
        .binding_count = SB_PROBE_SIGHT_BINDING_COUNT,
        .push_size = sizeof(struct sb_probe_sight_push),
        .name = "probe sight",
    };
}

enum sb_result sb_probe_sight_bake(struct sb_raycaster *rc, const float *positions, const float *lattice,
                                   uint32_t probe_count, float spacing_m, uint32_t *out, double *gpu_ms)
{
    struct sb_probe_sight_push pc = {.probe_count = probe_count, .tmin_m = 1e-4f, .spacing_m = spacing_m};
    if (gpu_ms)
        *gpu_ms = 0;
    if (!probe_count || !(spacing_m > 0)) {
        sb_error("probe sight: %u probes %g m apart", probe_count, (double)spacing_m);
        return SB_ERR_OUT_OF_RANGE;
    }
    struct sb_vk *vk = rc->vk;
    struct sb_buffer probes = {0}, results = {0};
    struct sb_pipeline pipeline = {0};
    const struct sb_pipeline_params pp = sb_probe_sight_kernel(rc->instanced);
    enum sb_result res;
    if ((res = sb_buffer_create(vk, (VkDeviceSize)probe_count * 8 * sizeof(float), "probes", &probes)) ||
        (res = sb_buffer_create(vk, (VkDeviceSize)probe_count * SB_PROBE_SIGHT_WORDS * sizeof(uint32_t),
                                "probe sight", &results)) ||
        (res = sb_pipeline_create(vk, &pp, &pipeline)))
        goto done;
    float *p = probes.mapped;
    for (uint32_t i = 0; i < probe_count; i++) {
        memcpy(&p[8 * (size_t)i], &positions[3 * (size_t)i], 3 * sizeof(float));
        memcpy(&p[8 * (size_t)i + 4], &lattice[3 * (size_t)i], 3 * sizeof(float));
        p[8 * (size_t)i + 3] = p[8 * (size_t)i + 7] = 0.0f;
    }
    const struct sb_buffer *bindings[SB_PROBE_SIGHT_BINDING_COUNT] = {
        [SB_RAYCAST_BINDING_NODES] = &rc->nodes,
        [SB_RAYCAST_BINDING_TRIANGLES] = &rc->triangles,
        [SB_RAYCAST_BINDING_RAYS] = &probes,
        [SB_RAYCAST_BINDING_HITS] = &results,
    };
    sb_pipeline_bind(vk, &pipeline, bindings);
    double t0 = sb_now_s();
    res = sb_probe_kernel_run(vk, &pipeline, &pc, probe_count, &results, out, gpu_ms);
    sb_debug("probe sight: %u probes x %u segments in %.1f ms", probe_count, SB_PROBE_SIGHT_SAMPLES,
             1e3 * (sb_now_s() - t0));
done:
    sb_pipeline_destroy(vk, &pipeline);
    sb_buffer_destroy(vk, &results);
    sb_buffer_destroy(vk, &probes);
    return res;
}

void sb_probe_sight_code_hash(char out[33])
{
    sb_kernel_code_hash(sb_spv_probe_sight, sizeof(sb_spv_probe_sight), sb_spv_probe_sight_instanced,
                        sizeof(sb_spv_probe_sight_instanced), out);
}

void sb_probe_sight_point(const double lattice[3], double spacing_m, uint32_t b, double out[3])
{
    const uint32_t ijk[3] = {b % SB_PROBE_SIGHT_SIDE, b / SB_PROBE_SIGHT_SIDE % SB_PROBE_SIGHT_SIDE,
                             b / (SB_PROBE_SIGHT_SIDE * SB_PROBE_SIGHT_SIDE)};
    for (int k = 0; k < 3; k++)
        out[k] = lattice[k] + ((ijk[k] + 0.5) * (2.0 / SB_PROBE_SIGHT_SIDE) - 1.0) * spacing_m;
}

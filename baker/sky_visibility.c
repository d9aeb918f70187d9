#include "sky_visibility.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"
#include "sh.h"
#include "sky_visibility.spv.h"
#include "sky_visibility_instanced.spv.h"

/* Morton code of two 16-bit coordinates. */
static uint32_t morton2(uint32_t x, uint32_t y)
{
    uint32_t code = 0;
    for (int b = 0; b < 16; b++)
        code |= ((x >> b) & 1u) << (2 * b) | ((y >> b) & 1u) << (2 * b + 1);
    return code;
}

struct keyed {
    uint32_t key, index;
};

static int compare_keyed(const void *a, const void *b)
{
    const struct keyed *x = a, *y = b;
    return x->key != y->key ? (x->key < y->key ? -1 : 1) : (x->index < y->index ? -1 : x->index > y->index);
}

void sb_probe_ray_order(uint32_t n, uint32_t *order)
{
    struct keyed *k = malloc(n * sizeof(*k));
    for (uint32_t i = 0; i < n; i++) {
        double d[3];
        sb_probe_direction(i, n, d);
        /* octahedral map of the direction to [0, 1]^2 */
        double l1 = fabs(d[0]) + fabs(d[1]) + fabs(d[2]), u = d[0] / l1, v = d[2] / l1;
        if (d[1] < 0) {
            double u2 = (1 - fabs(v)) * (u >= 0 ? 1 : -1), v2 = (1 - fabs(u)) * (v >= 0 ? 1 : -1);
            u = u2;
            v = v2;
        }
        uint32_t x = (uint32_t)fmin(65535.0, (u * 0.5 + 0.5) * 65536.0),
                 y = (uint32_t)fmin(65535.0, (v * 0.5 + 0.5) * 65536.0);
        if (k)
            k[i] = (struct keyed){morton2(x, y), i};
        else
            order[i] = i;
    }
    if (!k)
        return; /* the identity: slower, never wrong */
    qsort(k, n, sizeof(*k), compare_keyed);
    for (uint32_t i = 0; i < n; i++)
        order[i] = k[i].index;
    free(k);
}

struct sb_pipeline_params sb_sky_visibility_kernel(bool instanced)
{
    return (struct sb_pipeline_params){
        .spirv = instanced ? sb_spv_sky_visibility_instanced : sb_spv_sky_visibility,
        .spirv_size = instanced ? sizeof(sb_spv_sky_visibility_instanced) : sizeof(sb_spv_sky_visibility),
        .binding_count = SB_PROBE_BINDING_COUNT,
        .push_size = sizeof(struct sb_probe_push),
        .name = "sky visibility",
    };
}

enum sb_result sb_sky_visibility_bake(struct sb_raycaster *rc, const float *positions, uint32_t probe_count,
                                      const struct sb_sky_visibility_params *params, float *out, double *gpu_ms)
{
    static const struct sb_sky_visibility_params defaults = {0};
    params = params ? params : &defaults;
    struct sb_probe_push pc = {
        .probe_count = probe_count,
        .ray_count = params->ray_count ? params->ray_count : 2048,
        .tmin_m = params->tmin_m > 0 ? params->tmin_m : 1e-4f,
        .tmax_m = params->tmax_m > 0 ? params->tmax_m : 1e30f,
    };
    if (gpu_ms)
        *gpu_ms = 0;
    if (pc.ray_count % SB_PROBE_THREADS || pc.ray_count > SB_PROBE_MAX_RAYS || !probe_count) {
        sb_error("sky visibility: %u rays for %u probes (rays: a multiple of %u up to %u)", pc.ray_count, probe_count,
                 SB_PROBE_THREADS, SB_PROBE_MAX_RAYS);
        return SB_ERR_OUT_OF_RANGE;
    }
    struct sb_vk *vk = rc->vk;
    double start = sb_now_s();
    struct sb_buffer probes = {0}, results = {0}, order = {0};
    struct sb_pipeline pipeline = {0};
    const struct sb_pipeline_params pp = sb_sky_visibility_kernel(rc->instanced);
    enum sb_result res;
    if ((res = sb_probe_buffers_create(vk, positions, NULL, probe_count, SB_VISIBILITY_FLOATS, &probes, &results)) ||
        (res = sb_buffer_create(vk, (VkDeviceSize)pc.ray_count * sizeof(uint32_t), "probe ray order", &order)) ||
        (res = sb_pipeline_create(vk, &pp, &pipeline)))
        goto done;
    sb_probe_ray_order(pc.ray_count, order.mapped);
    const struct sb_buffer *bindings[SB_PROBE_BINDING_COUNT] = {
        [SB_PROBE_BINDING_ORDER] = &order,
        [SB_RAYCAST_BINDING_NODES] = &rc->nodes,
        [SB_RAYCAST_BINDING_TRIANGLES] = &rc->triangles,
        [SB_RAYCAST_BINDING_RAYS] = &probes,
        [SB_RAYCAST_BINDING_HITS] = &results,
    };
    sb_pipeline_bind(vk, &pipeline, bindings);
    double t0 = sb_now_s();
    /* the passes (config.h, SB_VISIBILITY_PASS_RAYS), in a fixed order */
    struct sb_probe_work work;
    sb_probe_work_begin(&work, params->what ? params->what : "sky visibility: probes' rays",
                        (pc.ray_count + SB_VISIBILITY_PASS_RAYS - 1) / SB_VISIBILITY_PASS_RAYS, probe_count);
    for (uint32_t first = 0; first < pc.ray_count && !res; first += SB_VISIBILITY_PASS_RAYS) {
        pc.first_ray = first;
        pc.accumulate = first > 0;
        pc.last = first + SB_VISIBILITY_PASS_RAYS >= pc.ray_count;
        res = sb_probe_kernel_pass(vk, &pipeline, &pc, probe_count, &work, gpu_ms);
    }
    if (!res)
        res = sb_buffer_read(vk, &results, out);
    sb_debug("sky visibility: %u probes x %u rays: buffers %.1f ms, run and read back %.1f ms", probe_count,
             pc.ray_count, 1e3 * (t0 - start), 1e3 * (sb_now_s() - t0));
done:
    sb_pipeline_destroy(vk, &pipeline);
    sb_buffer_destroy(vk, &results);
    sb_buffer_destroy(vk, &probes);
    sb_buffer_destroy(vk, &order);
    return res;
}

void sb_sky_visibility_code_hash(char out[33])
{
    sb_kernel_code_hash(sb_spv_sky_visibility, sizeof(sb_spv_sky_visibility), sb_spv_sky_visibility_instanced,
                        sizeof(sb_spv_sky_visibility_instanced), out);
}

void sb_probe_rays(const float position[3], uint32_t n, float tmin, float *rays)
{
    for (uint32_t r = 0; r < n; r++) {
        double d[3];
        sb_probe_direction(r, n, d);
        float *ray = &rays[8 * (size_t)r];
        memcpy(ray, position, 3 * sizeof(float));
        ray[3] = tmin;
        for (int k = 0; k < 3; k++)
            ray[4 + k] = (float)d[k];
        ray[7] = 1e30f;
    }
}

#include "raycast.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"
#include "raycast.spv.h"
#include "raycast_instanced.spv.h"

struct sb_pipeline_params sb_raycast_kernel(bool instanced)
{
    return (struct sb_pipeline_params){
        .spirv = instanced ? sb_spv_raycast_instanced : sb_spv_raycast,
        .spirv_size = instanced ? sizeof(sb_spv_raycast_instanced) : sizeof(sb_spv_raycast),
        .binding_count = SB_RAYCAST_BINDING_COUNT,
        .push_size = sizeof(struct sb_raycast_push),
        .name = "raycast",
    };
}

enum sb_result sb_raycaster_create(struct sb_vk *vk, const struct sb_bvh *bvh, struct sb_raycaster **out)
{
    *out = NULL;
    struct sb_raycaster *rc = calloc(1, sizeof(*rc));
    if (!rc)
        return SB_ERR_NOMEM;
    rc->vk = vk;
    enum sb_result res;
    VkDeviceSize node_bytes = (VkDeviceSize)bvh->node_count * sizeof(*bvh->nodes);
    VkDeviceSize triangle_bytes = (VkDeviceSize)bvh->triangle_count * sizeof(*bvh->triangles);
    if ((res = sb_buffer_create(vk, node_bytes, "bvh nodes", &rc->nodes)) ||
        (res = sb_buffer_create(vk, triangle_bytes, "bvh triangles", &rc->triangles)))
        goto fail;
    memcpy(rc->nodes.mapped, bvh->nodes, node_bytes);
    memcpy(rc->triangles.mapped, bvh->triangles, triangle_bytes);
    rc->instanced = bvh->instance_count > 0;
    const struct sb_pipeline_params params = sb_raycast_kernel(rc->instanced);
    if ((res = sb_pipeline_create(vk, &params, &rc->pipeline)))
        goto fail;
    *out = rc;
    return SB_OK;
fail:
    sb_raycaster_destroy(&rc);
    return res;
}

void sb_raycaster_destroy(struct sb_raycaster **raycaster)
{
    struct sb_raycaster *rc = *raycaster;
    if (!rc)
        return;
    sb_pipeline_destroy(rc->vk, &rc->pipeline);
    sb_buffer_destroy(rc->vk, &rc->rays);
    sb_buffer_destroy(rc->vk, &rc->hits);
    sb_buffer_destroy(rc->vk, &rc->nodes);
    sb_buffer_destroy(rc->vk, &rc->triangles);
    free(rc);
    *raycaster = NULL;
}

enum sb_result sb_raycaster_cast(struct sb_raycaster *rc, const float *rays, uint32_t count, bool any, float *hits,
                                 double *gpu_ms)
{
    if (gpu_ms)
        *gpu_ms = 0;
    if (!count)
        return SB_OK;
    enum sb_result res;
    if (count != rc->capacity) { /* sb_buffer_read reads whole buffers */
        sb_buffer_destroy(rc->vk, &rc->rays);
        sb_buffer_destroy(rc->vk, &rc->hits);
        rc->capacity = 0;
        if ((res = sb_buffer_create(rc->vk, (VkDeviceSize)count * 8 * sizeof(float), "rays", &rc->rays)) ||
            (res = sb_buffer_create(rc->vk, (VkDeviceSize)count * 4 * sizeof(float), "hits", &rc->hits)))
            return res;
        rc->capacity = count;
    }
    memcpy(rc->rays.mapped, rays, (size_t)count * 8 * sizeof(float));
    const struct sb_buffer *bindings[SB_RAYCAST_BINDING_COUNT] = {
        [SB_RAYCAST_BINDING_NODES] = &rc->nodes,
        [SB_RAYCAST_BINDING_TRIANGLES] = &rc->triangles,
        [SB_RAYCAST_BINDING_RAYS] = &rc->rays,
        [SB_RAYCAST_BINDING_HITS] = &rc->hits,
    };
    sb_pipeline_bind(rc->vk, &rc->pipeline, bindings);
    const uint32_t per_dispatch = 65535u * SB_RAYCAST_WORKGROUP;
    for (uint32_t first = 0; first < count; first += per_dispatch) {
        uint32_t n = count - first < per_dispatch ? count - first : per_dispatch;
        struct sb_raycast_push pc = {.ray_count = count, .any_hit = any, .first = first};
        double ms = 0;
        if ((res = sb_dispatch(rc->vk, &rc->pipeline, &pc, (n + SB_RAYCAST_WORKGROUP - 1) / SB_RAYCAST_WORKGROUP, 1, 1,
                               &ms)))
            return res;
        if (gpu_ms)
            *gpu_ms += ms;
    }
    return sb_buffer_read(rc->vk, &rc->hits, hits);
}

void sb_probe_work_begin(struct sb_probe_work *work, const char *what, uint32_t passes, uint32_t probe_count)
{
    *work = (struct sb_probe_work){.what = what, .total = (uint64_t)passes * probe_count};
    sb_progress(what, 0, (unsigned)work->total);
}

enum sb_result sb_probe_kernel_pass(struct sb_vk *vk, struct sb_pipeline *pipeline, const void *push,
                                    uint32_t probe_count, struct sb_probe_work *work, double *gpu_ms)
{
    double ms = 0;
    enum sb_result res = SB_OK;
    if (!work) {
        uint32_t gx = probe_count < 65535 ? probe_count : 65535, gy = (probe_count + gx - 1) / gx;
        res = sb_dispatch(vk, pipeline, push, gx, gy, 1, &ms);
        if (gpu_ms)
            *gpu_ms += ms;
        return res;
    }
    /* rows of SB_PROBE_ROW workgroups, some rows a dispatch (their ids
     * from the first row on: the same probes as one dispatch) */
    uint32_t gx = probe_count < SB_PROBE_ROW ? probe_count : SB_PROBE_ROW, gy = (probe_count + gx - 1) / gx;
    for (uint32_t row = 0; row < gy && !res;) {
        uint32_t rows = work->rows ? work->rows : 8;
        rows = rows < gy - row ? rows : gy - row;
        double t0 = sb_now_s();
        res = sb_dispatch_base(vk, pipeline, push, (const uint32_t[3]){0, row, 0}, gx, rows, 1, &ms);
        double s = sb_now_s() - t0;
        if (gpu_ms)
            *gpu_ms += ms;
        uint64_t first = (uint64_t)row * gx, last = (uint64_t)(row + rows) * gx;
        work->done += (last < probe_count ? last : probe_count) - first;
        sb_progress(work->what, (unsigned)(work->done < work->total ? work->done : work->total), (unsigned)work->total);
        row += rows;
        /* about half a second a dispatch, from this one's time */
        double next = s > 0 ? rows * 0.5 / s : 1e9;
        work->rows = (uint32_t)fmin(fmax(next, 1.0), 65535.0);
    }
    return res;
}

enum sb_result sb_probe_kernel_run(struct sb_vk *vk, struct sb_pipeline *pipeline, const void *push,
                                   uint32_t probe_count, struct sb_buffer *results, void *out, double *gpu_ms)
{
    if (gpu_ms)
        *gpu_ms = 0;
    enum sb_result res = sb_probe_kernel_pass(vk, pipeline, push, probe_count, NULL, gpu_ms);
    return res ? res : sb_buffer_read(vk, results, out);
}

enum sb_result sb_probe_buffers_create(struct sb_vk *vk, const float *positions, const float *valid,
                                       uint32_t probe_count, uint32_t floats, struct sb_buffer *probes,
                                       struct sb_buffer *results)
{
    enum sb_result res = sb_buffer_create(vk, (VkDeviceSize)probe_count * 4 * sizeof(float), "probes", probes);
    if (!res)
        res = sb_buffer_create(vk, (VkDeviceSize)probe_count * floats * sizeof(float), "probe results", results);
    if (res)
        return res;
    float *p = probes->mapped;
    for (uint32_t i = 0; i < probe_count; i++) {
        memcpy(&p[4 * (size_t)i], &positions[3 * (size_t)i], 3 * sizeof(float));
        p[4 * (size_t)i + 3] = valid ? valid[i] : 1.0f;
    }
    return SB_OK;
}

void sb_kernel_code_hash(const void *one_level, size_t one_size, const void *instanced, size_t instanced_size,
                         char out[33])
{
    char both[2 * 33];
    sb_hash_bytes(one_level, one_size, both);
    sb_hash_bytes(instanced, instanced_size, both + 32);
    sb_hash_bytes(both, 64, out);
}

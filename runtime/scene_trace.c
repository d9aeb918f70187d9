/*
 * The scene pass traced instead of rasterised (sb_renderer_params.scene):
 * shaders/scene_trace.comp casts a ray a pixel through a BVH of the world
 * (geometry/bvh.h, built here once) and lights the hit as scene.frag lights
 * a fragment (scene_shading.glsl), the sun's visibility from a shadow ray
 * instead of the cascades, so the shadow pass has nothing to draw; the fog
 * traces its shadow rays too (fog_inject_traced).
 *
 * Why: a data-centre GPU's rasteriser is its weak part. On the H100 the
 * raster scene pass took 1.98 ms at 1080p, 0.71 ms of it to rasterise with
 * a one-line fragment shader, and the cascades 0.37 ms (docs/skyview.md).
 * llvmpipe rasterises well and traces slowly, so a CPU device rasterises.
 *
 * The traced frame differs from the raster one only in its shadows (hard
 * and exact at every distance, where the maps are filtered and end at
 * shadow_distance_m) and in the last bits of each point's position;
 * test_runtime holds the two together and the shadows to Embree.
 */

#include "bvh.h"
#include "log.h"
#include "renderer_internal.h"
#include "scene_trace.spv.h"
#include "scene_trace_volume.spv.h"

_Static_assert(SB_TRACE_FAR_M >= 3.5 * SB_MESH_MAX_EXTENT_M, "a shadow ray crosses any world");

bool sb_scene_trace_wanted(const struct sb_renderer_params *params, const struct sb_vk *vk, uint32_t vertex_count)
{
    if (vertex_count < 3) /* nothing to trace: the raster pass draws nothing cheaply */
        return false;
    if (params->scene == SB_SCENE_AUTO)
        return vk->properties.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU;
    return params->scene == SB_SCENE_TRACED;
}

enum sb_result sb_scene_trace_create(struct sb_renderer *r, const struct sb_world *world)
{
    enum sb_result res = SB_OK;
    if (!r->scene_traced)
        return SB_OK;
    struct sb_mesh mesh;
    struct sb_bvh bvh = {0};
    if ((res = sb_world_mesh(world, false, &mesh)))
        return res;
    res = sb_bvh_build(&mesh, &bvh);
    sb_mesh_finish(&mesh);
    if (!res)
        res = sb_renderer_upload(r, bvh.nodes, bvh.node_count * sizeof(*bvh.nodes), "world BVH nodes", &r->bvh_nodes);
    if (!res)
        res = sb_renderer_upload(r, bvh.triangles, bvh.triangle_count * sizeof(*bvh.triangles), "world BVH triangles",
                                 &r->bvh_triangles);
    if (!res)
        sb_info("scene traced: %u triangles, a BVH of %u nodes, %u deep", bvh.triangle_count, bvh.node_count,
                bvh.depth);
    sb_bvh_finish(&bvh);
    return res;
}

enum sb_result sb_scene_trace_create_pass(struct sb_renderer *r)
{
    sb_pass_use(r, SB_VIEW_BINDING_HDR, r->hdr_id, SB_USE_OVERWRITE);
    sb_pass_use(r, SB_VIEW_BINDING_DEPTH_OUT, sb_pass_find(r, "depth"), SB_USE_OVERWRITE);
    sb_pass_use(r, SB_VIEW_BINDING_BVH_NODES, sb_pass_find(r, "bvh nodes"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_BVH_TRIANGLES, sb_pass_find(r, "bvh triangles"), SB_USE_LOAD);
    enum sb_result res =
        sb_renderer_kernel(r, sb_spv_scene_trace, sizeof(sb_spv_scene_trace), "scene traced", &r->scene_trace[0]);
    if (!res)
        res = sb_renderer_kernel(r, sb_spv_scene_trace_volume, sizeof(sb_spv_scene_trace_volume),
                                 "scene traced (aerial volume only)", &r->scene_trace[1]);
    return res;
}

void sb_scene_trace_destroy(struct sb_renderer *r)
{
    sb_renderer_release(r, r->scene_trace, 2, NULL, 0);
    sb_buffer_destroy(r->vk, &r->bvh_nodes);
    sb_buffer_destroy(r->vk, &r->bvh_triangles);
}

void sb_scene_trace_record(struct sb_renderer *r)
{
    VkPipeline pipeline = r->scene_trace[r->aerial_volume_only ? 1 : 0];
    sb_renderer_dispatch(r, pipeline, NULL, (const uint32_t[3]){r->width, r->height, 1},
                         (const uint32_t[3]){SB_WORKGROUP_X, SB_WORKGROUP_Y, 1});
}

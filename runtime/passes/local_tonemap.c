/*
 * Local tone mapping (shaders/local_tonemap_*.comp): one pass of the
 * renderer's table, "local tonemap", in place on the exposed frame after the
 * meter and before grading, bloom and the tone curve. It is Durand and
 * Dorsey's base and detail split (2002) on a bilateral grid (Chen, Paris
 * and Durand 2007), as Unreal's local exposure ships it: the frame's log2
 * luminance, splatted into a grid of SB_LTM_GRID_X cells across by
 * SB_LTM_BINS bins of 0.75 EV and blurred, is the base; the base's distance
 * from the frame's pivot (the mean of the cells' mean log2 luminance) is
 * scaled by params.local_contrast and the detail kept. A sunset's sky and its
 * shadowed foreground, 8 EV apart, end 5.6 EV apart at 0.7 (the CLI's
 * default), their texture as it was. Contrast 1 records nothing.
 */
#include <stddef.h>
#include <stdlib.h>

#include "local_tonemap_gpu.h"
#include "log.h"
#include "renderer_internal.h"

#include "local_tonemap_apply.spv.h"
#include "local_tonemap_blur.spv.h"
#include "local_tonemap_grid.spv.h"
#include "local_tonemap_grid_subgroups.spv.h"
#include "local_tonemap_pivot.spv.h"

struct sb_local_tonemap {
    bool enabled;
    struct sb_buffer params; /* sb_local_tonemap_gpu */
    struct sb_buffer grid;   /* the sums and counts, then the blurred grid */
    VkDeviceSize sums_size;  /* the sums and counts' bytes, cleared each frame */
    VkPipeline grid_kernel, pivot_kernel, blur_kernel, apply_kernel;
};

static enum sb_result local_tonemap_create(struct sb_renderer *r)
{
    struct sb_local_tonemap *t = calloc(1, sizeof(*t));
    if (!t)
        return SB_ERR_NOMEM;
    sb_pass_set_data(r, t);
    double contrast = r->params.local_contrast;
    t->enabled = contrast > 0.0 && contrast != 1.0;
    if (!t->enabled)
        return SB_OK;
    uint32_t side = (r->width + SB_LTM_GRID_X - 1) / SB_LTM_GRID_X;
    uint32_t gx = (r->width + side - 1) / side, gy = (r->height + side - 1) / side;
    size_t cells = (size_t)gx * gy * SB_LTM_BINS;
    enum sb_result res =
        sb_renderer_upload(r, NULL, sizeof(struct sb_local_tonemap_gpu), "local tone mapping", &t->params);
    if (!res)
        res = sb_renderer_upload(r, NULL, cells * 16, "local tone mapping grid", &t->grid);
    t->sums_size = cells * 8;
    if (res)
        return res;
    struct sb_local_tonemap_gpu *gpu = t->params.mapped;
    gpu->grid[0] = gx;
    gpu->grid[1] = gy;
    gpu->grid[2] = SB_LTM_BINS;
    gpu->grid[3] = side;
    gpu->params[0] = (float)contrast;
    sb_pass_use(r, SB_VIEW_BINDING_FRAME, sb_pass_find(r, "frame"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_EXPOSURE, sb_pass_find(r, "exposure"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_HDR, sb_pass_find(r, "hdr"), SB_USE_LOAD_STORE);
    sb_pass_use(r, SB_VIEW_BINDING_LOCAL_TONEMAP, sb_graph_buffer(r, "local tonemap", &t->params), SB_USE_LOAD_STORE);
    sb_pass_use(r, SB_VIEW_BINDING_LOCAL_TONEMAP_GRID, sb_graph_buffer(r, "local tonemap grid", &t->grid),
                SB_USE_LOAD_STORE);
    /* the grid's subgroups add before their atomics where they can (local_tonemap_grid.comp) */
    const VkSubgroupFeatureFlags adds =
        VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_BALLOT_BIT | VK_SUBGROUP_FEATURE_ARITHMETIC_BIT;
    bool subgroups = (r->vk->compute_subgroup_ops & adds) == adds;
    sb_debug("local tone mapping: the grid's atomics %s", subgroups ? "added up by subgroup first" : "a pixel each");
    if (subgroups)
        res = sb_renderer_kernel(r, sb_spv_local_tonemap_grid_subgroups, sizeof(sb_spv_local_tonemap_grid_subgroups),
                                 "local tonemap grid (subgroups)", &t->grid_kernel);
    else
        res = sb_renderer_kernel(r, sb_spv_local_tonemap_grid, sizeof(sb_spv_local_tonemap_grid), "local tonemap grid",
                                 &t->grid_kernel);
    if (!res)
        res = sb_renderer_kernel(r, sb_spv_local_tonemap_pivot, sizeof(sb_spv_local_tonemap_pivot),
                                 "local tonemap pivot", &t->pivot_kernel);
    if (!res)
        res = sb_renderer_kernel(r, sb_spv_local_tonemap_blur, sizeof(sb_spv_local_tonemap_blur), "local tonemap blur",
                                 &t->blur_kernel);
    if (!res)
        res = sb_renderer_kernel(r, sb_spv_local_tonemap_apply, sizeof(sb_spv_local_tonemap_apply),
                                 "local tonemap apply", &t->apply_kernel);
    return res;
}

static void local_tonemap_destroy(struct sb_renderer *r)
{
    struct sb_local_tonemap *t = sb_pass_data(r);
    if (!t)
        return;
    sb_buffer_destroy(r->vk, &t->params);
    sb_buffer_destroy(r->vk, &t->grid);
    free(t);
}

static void local_tonemap_record(struct sb_renderer *r)
{
    struct sb_local_tonemap *t = sb_pass_data(r);
    if (!t->enabled)
        return;
    const struct sb_local_tonemap_gpu *gpu = t->params.mapped;
    vkCmdFillBuffer(r->cmd, t->params.buffer, offsetof(struct sb_local_tonemap_gpu, pivot), sizeof(gpu->pivot), 0);
    vkCmdFillBuffer(r->cmd, t->grid.buffer, 0, t->sums_size, 0);
    sb_renderer_barrier(r->cmd);
    sb_renderer_dispatch(r, t->grid_kernel, NULL, (const uint32_t[3]){r->width, r->height, 1},
                         (const uint32_t[3]){SB_WORKGROUP_X, SB_WORKGROUP_Y, 1});
    sb_renderer_barrier(r->cmd);
    sb_renderer_dispatch(r, t->pivot_kernel, NULL, (const uint32_t[3]){gpu->grid[0] * gpu->grid[1], 1, 1},
                         (const uint32_t[3]){64, 1, 1});
    sb_renderer_barrier(r->cmd);
    sb_renderer_dispatch(r, t->blur_kernel, NULL, (const uint32_t[3]){gpu->grid[0], gpu->grid[1], gpu->grid[2]},
                         (const uint32_t[3]){4, 4, 4});
    sb_renderer_barrier(r->cmd);
    sb_renderer_dispatch(r, t->apply_kernel, NULL, (const uint32_t[3]){r->width, r->height, 1},
                         (const uint32_t[3]){SB_WORKGROUP_X, SB_WORKGROUP_Y, 1});
}

const struct sb_pass_class sb_pass_local_tonemap = {
    .name = "local tonemap",
    .post = true,
    .create = local_tonemap_create,
    .destroy = local_tonemap_destroy,
    .record = local_tonemap_record,
    .optional = true,
};

#include "dfg.h"

#include "compute.h"
#include "config.h"
#include "dfg.spv.h"
#include "log.h"

struct sb_pipeline_params sb_dfg_kernel(void)
{
    return (struct sb_pipeline_params){
        .spirv = sb_spv_dfg,
        .spirv_size = sizeof(sb_spv_dfg),
        .binding_count = SB_DFG_BINDING_COUNT,
        .push_size = sizeof(struct sb_dfg_push),
        .name = "dfg",
    };
}

enum sb_result sb_dfg_bake(struct sb_vk *vk, struct sb_image *image, double *gpu_ms)
{
    struct sb_dfg_push pc = {.size = SB_DFG_SIZE, .samples_side = SB_DFG_SAMPLES_SIDE};
    struct sb_buffer out = {0};
    struct sb_pipeline pipeline = {0};
    const struct sb_pipeline_params pp = sb_dfg_kernel();
    double ms = 0;
    enum sb_result res;
    if ((res = sb_image_init(image, SB_DFG_SIZE, SB_DFG_SIZE, 2)) ||
        (res = sb_buffer_create(vk, (VkDeviceSize)SB_DFG_SIZE * SB_DFG_SIZE * 2 * sizeof(float), "dfg", &out)) ||
        (res = sb_pipeline_create(vk, &pp, &pipeline)))
        goto done;
    sb_image_set_channel_names(image, "dfg.x,dfg.y");
    const struct sb_buffer *bindings[SB_DFG_BINDING_COUNT] = {[SB_DFG_BINDING_OUT] = &out};
    sb_pipeline_bind(vk, &pipeline, bindings);
    uint32_t groups = (SB_DFG_SIZE + SB_WORKGROUP_X - 1) / SB_WORKGROUP_X;
    if (!(res = sb_dispatch(vk, &pipeline, &pc, groups, groups, 1, &ms)))
        res = sb_buffer_read(vk, &out, image->data);
done:
    if (gpu_ms)
        *gpu_ms = ms;
    if (res)
        sb_image_finish(image);
    sb_pipeline_destroy(vk, &pipeline);
    sb_buffer_destroy(vk, &out);
    return res;
}

void sb_dfg_code_hash(char out[33])
{
    sb_hash_bytes(sb_spv_dfg, sizeof(sb_spv_dfg), out);
}

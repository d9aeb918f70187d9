#include "clouds.h"

#include <stdlib.h>
#include <string.h>

#include "clouds.spv.h"
#include "compute.h"
#include "log.h"

static const char *const product_names[SB_CLOUD_COUNT] = {"cloud_shape", "cloud_detail", "cloud_curl", "weather"};

const char *sb_cloud_product_name(enum sb_cloud_product product)
{
    return (unsigned)product < SB_CLOUD_COUNT ? product_names[product] : "unknown";
}

void sb_volume_finish(struct sb_volume *volume)
{
    free(volume->data);
    memset(volume, 0, sizeof(*volume));
}

void sb_cloud_params_default(struct sb_cloud_params *params)
{
    *params = (struct sb_cloud_params){.size = {128, 32, 128, 512}, .seed = 0};
}

static void channel(struct sb_noise_push *pc, uint32_t kind, uint32_t a, uint32_t b, uint32_t c, uint32_t seed)
{
    uint32_t i = pc->channel_count++;
    pc->kind[i] = kind;
    pc->a[i] = a;
    pc->b[i] = b;
    pc->c[i] = c;
    pc->seed[i] = seed;
}

void sb_cloud_recipe(enum sb_cloud_product product, const struct sb_cloud_params *params, struct sb_noise_push *pc)
{
    memset(pc, 0, sizeof(*pc));
    uint32_t n = params->size[product], seed = params->seed;
    bool volume = product == SB_CLOUD_SHAPE || product == SB_CLOUD_DETAIL;
    pc->size_x = pc->size_y = n;
    pc->size_z = volume ? n : 1;
    pc->inv_x = pc->inv_y = 1.0f / (float)n;
    pc->inv_z = 1.0f / (float)pc->size_z;
    pc->slice_z = 0.3f;
    switch (product) {
    case SB_CLOUD_SHAPE:
        channel(pc, SB_NOISE_PERLIN_WORLEY, 4, 4, 4, seed);
        channel(pc, SB_NOISE_WORLEY_FBM, 4, 0, 0, seed + 1000u);
        channel(pc, SB_NOISE_WORLEY_FBM, 8, 0, 0, seed + 2000u);
        channel(pc, SB_NOISE_WORLEY_FBM, 16, 0, 0, seed + 3000u);
        break;
    case SB_CLOUD_DETAIL:
        channel(pc, SB_NOISE_WORLEY_FBM, 2, 0, 0, seed + 4000u);
        channel(pc, SB_NOISE_WORLEY_FBM, 4, 0, 0, seed + 5000u);
        channel(pc, SB_NOISE_WORLEY_FBM, 8, 0, 0, seed + 6000u);
        break;
    case SB_CLOUD_CURL:
        for (uint32_t axis = 0; axis < 3; axis++)
            channel(pc, SB_NOISE_CURL, 4, 3, axis, seed + 7000u);
        break;
    default:
        channel(pc, SB_NOISE_PERLIN_FBM, 4, 5, 1, seed + 8000u);
        channel(pc, SB_NOISE_PERLIN_FBM, 8, 4, 1, seed + 8032u);
        channel(pc, SB_NOISE_PERLIN_FBM, 2, 3, 0, seed + 8064u);
        break;
    }
}

enum sb_result sb_cloud_bake(struct sb_vk *vk, enum sb_cloud_product product, const struct sb_cloud_params *params,
                             struct sb_volume *volume, double *gpu_ms)
{
    memset(volume, 0, sizeof(*volume));
    struct sb_noise_push pc;
    sb_cloud_recipe(product, params, &pc);
    uint64_t values = (uint64_t)pc.size_x * pc.size_y * pc.size_z * pc.channel_count;
    struct sb_buffer out = {0};
    struct sb_pipeline pipeline = {0};
    enum sb_result res = sb_buffer_create(vk, values * sizeof(float), sb_cloud_product_name(product), &out);
    if (!res)
        res = sb_pipeline_create(vk,
                                 &(struct sb_pipeline_params){.spirv = sb_spv_clouds,
                                                              .spirv_size = sizeof(sb_spv_clouds),
                                                              .binding_count = 1,
                                                              .push_size = sizeof(pc),
                                                              .name = sb_cloud_product_name(product)},
                                 &pipeline);
    if (!res) {
        const struct sb_buffer *bindings[1] = {&out};
        sb_pipeline_bind(vk, &pipeline, bindings);
        res = sb_dispatch(vk, &pipeline, &pc, (pc.size_x + SB_WORKGROUP_X - 1) / SB_WORKGROUP_X,
                          (pc.size_y + SB_WORKGROUP_Y - 1) / SB_WORKGROUP_Y, pc.size_z, gpu_ms);
    }
    if (!res) {
        volume->data = malloc(values * sizeof(float));
        if (!volume->data) {
            res = SB_ERR_NOMEM;
        } else {
            memcpy(volume->data, out.mapped, values * sizeof(float));
            volume->width = pc.size_x;
            volume->height = pc.size_y;
            volume->depth = pc.size_z;
            volume->channel_count = pc.channel_count;
        }
    }
    sb_pipeline_destroy(vk, &pipeline);
    sb_buffer_destroy(vk, &out);
    return res;
}

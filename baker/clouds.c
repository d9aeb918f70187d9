#include "clouds.h"

#include <assert.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "clouds.spv.h"
#include "compute.h"
#include "log.h"

/* The channel recipes and the seeds' offsets (documented in clouds.h). */
static void channel(struct sb_noise_push *pc, uint32_t kind, uint32_t a, uint32_t b, uint32_t c, uint32_t seed)
{
    uint32_t i = pc->channel_count++;
    pc->kind[i] = kind;
    pc->a[i] = a;
    pc->b[i] = b;
    pc->c[i] = c;
    pc->seed[i] = seed;
}

static uint32_t product_size(enum sb_product_id product, const struct sb_cloud_params *params)
{
    switch (product) {
    case SB_PRODUCT_CLOUD_SHAPE:
        return params->shape_size;
    case SB_PRODUCT_CLOUD_DETAIL:
        return params->detail_size;
    case SB_PRODUCT_CLOUD_CURL:
        return params->curl_size;
    default:
        return params->weather_size;
    }
}

void sb_cloud_recipe(enum sb_product_id product, const struct sb_cloud_params *params, struct sb_noise_push *pc)
{
    assert(sb_product_is_cloud(product));
    memset(pc, 0, sizeof(*pc));
    uint32_t n = product_size(product, params), seed = params->seed;
    bool volume = product == SB_PRODUCT_CLOUD_SHAPE || product == SB_PRODUCT_CLOUD_DETAIL;
    pc->size_x = pc->size_y = n;
    pc->size_z = volume ? n : 1;
    pc->inv_x = pc->inv_y = 1.0f / (float)n;
    pc->inv_z = 1.0f / (float)pc->size_z;
    pc->slice_z = 0.3f;
    const uint32_t *cells;
    switch (product) {
    case SB_PRODUCT_CLOUD_SHAPE:
        cells = params->shape_worley_cells;
        channel(pc, SB_NOISE_PERLIN_WORLEY, params->shape_perlin.period, params->shape_perlin.octaves, cells[0], seed);
        channel(pc, SB_NOISE_WORLEY_FBM, cells[0], 0, 0, seed + 1000u);
        channel(pc, SB_NOISE_WORLEY_FBM, cells[1], 0, 0, seed + 2000u);
        channel(pc, SB_NOISE_WORLEY_FBM, cells[2], 0, 0, seed + 3000u);
        break;
    case SB_PRODUCT_CLOUD_DETAIL:
        cells = params->detail_worley_cells;
        channel(pc, SB_NOISE_WORLEY_FBM, cells[0], 0, 0, seed + 4000u);
        channel(pc, SB_NOISE_WORLEY_FBM, cells[1], 0, 0, seed + 5000u);
        channel(pc, SB_NOISE_WORLEY_FBM, cells[2], 0, 0, seed + 6000u);
        break;
    case SB_PRODUCT_CLOUD_CURL:
        for (uint32_t axis = 0; axis < 3; axis++)
            channel(pc, SB_NOISE_CURL, params->curl.period, params->curl.octaves, axis, seed + 7000u);
        break;
    default:
        channel(pc, SB_NOISE_PERLIN_FBM, params->coverage.period, params->coverage.octaves, 1, seed + 8000u);
        channel(pc, SB_NOISE_PERLIN_FBM, params->precipitation.period, params->precipitation.octaves, 1, seed + 8032u);
        channel(pc, SB_NOISE_PERLIN_FBM, params->cloud_type.period, params->cloud_type.octaves, 0, seed + 8064u);
        break;
    }
}

void sb_cloud_recipe_json(const struct sb_noise_push *pc, char *out, size_t size)
{
    static const char *const kinds[] = {"perlin_worley", "worley_fbm", "perlin_fbm", "curl"};
    size_t n = (size_t)snprintf(out, size, "{\"channels\":[");
    for (uint32_t i = 0; i < pc->channel_count && n < size; i++) {
        const char *sep = i ? "," : "";
        switch (pc->kind[i]) {
        case SB_NOISE_PERLIN_WORLEY:
            n += (size_t)snprintf(out + n, size - n,
                                  "%s{\"noise\":\"%s\",\"perlin_period\":%u,\"perlin_octaves\":%u,\"worley_cells\":%u,"
                                  "\"seed\":%u}",
                                  sep, kinds[pc->kind[i]], pc->a[i], pc->b[i], pc->c[i], pc->seed[i]);
            break;
        case SB_NOISE_WORLEY_FBM:
            n += (size_t)snprintf(out + n, size - n, "%s{\"noise\":\"%s\",\"cells\":%u,\"octaves\":3,\"seed\":%u}", sep,
                                  kinds[pc->kind[i]], pc->a[i], pc->seed[i]);
            break;
        case SB_NOISE_CURL:
            n += (size_t)snprintf(out + n, size - n,
                                  "%s{\"noise\":\"%s\",\"period\":%u,\"octaves\":%u,\"axis\":%u,\"seed\":%u}", sep,
                                  kinds[pc->kind[i]], pc->a[i], pc->b[i], pc->c[i], pc->seed[i]);
            break;
        default:
            n += (size_t)snprintf(out + n, size - n,
                                  "%s{\"noise\":\"%s\",\"period\":%u,\"octaves\":%u,\"stretched\":%s,\"seed\":%u}", sep,
                                  kinds[pc->kind[i] & 3], pc->a[i], pc->b[i], pc->c[i] ? "true" : "false", pc->seed[i]);
            break;
        }
    }
    if (n < size)
        snprintf(out + n, size - n, "],\"slice_z\":%.9g}", (double)pc->slice_z);
}

void sb_cloud_code_hash(char out[SB_HASH_HEX_SIZE])
{
    sb_hash_bytes(sb_spv_clouds, sizeof(sb_spv_clouds), out);
}

struct sb_pipeline_params sb_cloud_kernel(enum sb_product_id product)
{
    return (struct sb_pipeline_params){
        .spirv = sb_spv_clouds,
        .spirv_size = sizeof(sb_spv_clouds),
        .binding_count = 1,
        .push_size = sizeof(struct sb_noise_push),
        .name = sb_product_name(product),
    };
}

enum sb_result sb_cloud_bake(struct sb_vk *vk, enum sb_product_id product, const struct sb_cloud_params *params,
                             struct sb_image *image, double *gpu_ms)
{
    memset(image, 0, sizeof(*image));
    struct sb_noise_push pc;
    sb_cloud_recipe(product, params, &pc);
    uint64_t values = (uint64_t)pc.size_x * pc.size_y * pc.size_z * pc.channel_count;
    struct sb_buffer out = {0};
    struct sb_pipeline pipeline = {0};
    const struct sb_pipeline_params pp = sb_cloud_kernel(product);
    enum sb_result res = sb_buffer_create(vk, values * sizeof(float), sb_product_name(product), &out);
    if (!res)
        res = sb_pipeline_create(vk, &pp, &pipeline);
    if (!res) {
        const struct sb_buffer *bindings[1] = {&out};
        sb_pipeline_bind(vk, &pipeline, bindings);
        res = sb_dispatch(vk, &pipeline, &pc, (pc.size_x + SB_WORKGROUP_X - 1) / SB_WORKGROUP_X,
                          (pc.size_y + SB_WORKGROUP_Y - 1) / SB_WORKGROUP_Y, pc.size_z, gpu_ms);
    }
    if (!res && !(res = sb_image_init_volume(image, pc.size_x, pc.size_y, pc.size_z, pc.channel_count))) {
        sb_image_set_channel_names(image, sb_product_format(product)->channel_names);
        if ((res = sb_buffer_read(vk, &out, image->data)))
            sb_image_finish(image);
    }
    sb_pipeline_destroy(vk, &pipeline);
    sb_buffer_destroy(vk, &out);
    return res;
}

/*
 * The cloud noise family (clouds.h): keys from each product's recipe and
 * kernel, bakes rounded as the files store them (family.h). The noise reads
 * no other product.
 */
#include <stdio.h>

#include "clouds.h"
#include "family.h"

/* A cloud product's recipe, every field of its push constants, and its kernel. */
static void clouds_key(void *state, const struct sb_scene *scene, enum sb_product_id id, struct sb_key_text *key)
{
    struct sb_noise_push pc;
    sb_cloud_recipe(id, &scene->clouds, &pc);
    sb_key_add(key, " size=%u,%u,%u inv=%a,%a,%a slice_z=%a", pc.size_x, pc.size_y, pc.size_z, (double)pc.inv_x,
               (double)pc.inv_y, (double)pc.inv_z, (double)pc.slice_z);
    for (uint32_t c = 0; c < pc.channel_count; c++)
        sb_key_add(key, " channel%u=%u,%u,%u,%u,%u", c, pc.kind[c], pc.a[c], pc.b[c], pc.c[c], pc.seed[c]);
    char code[SB_HASH_HEX_SIZE];
    sb_cloud_code_hash(code);
    sb_key_add(key, " code %s", code);
}

/* Bake one cloud product into *image, rounded as its file stores it. */
static enum sb_result clouds_bake(void *state, struct sb_vk *vk, const struct sb_scene *scene, enum sb_product_id id,
                                  const struct sb_image baked[SB_PRODUCT_COUNT], struct sb_image *image,
                                  struct sb_artifact *a)
{
    enum sb_result res = sb_cloud_bake(vk, id, &scene->clouds, image, &a->gpu_ms);
    if (res)
        return res;
    struct sb_noise_push pc;
    sb_cloud_recipe(id, &scene->clouds, &pc);
    sb_cloud_recipe_json(&pc, a->settings_json, sizeof(a->settings_json));
    /* The noise lies in [0, 1]: binary16 cannot overflow. */
    if (sb_product_format(id)->storage == SB_STORAGE_VDB_HALF)
        res = sb_image_round_to_half(image, NULL);
    return res;
}

static uint32_t clouds_kernels(void *state, const struct sb_scene *scene, enum sb_product_id id,
                               struct sb_pipeline_params out[SB_FAMILY_KERNELS_MAX])
{
    out[0] = sb_cloud_kernel(id);
    return 1;
}

const struct sb_family_baker sb_clouds_family = {
    .key = clouds_key,
    .bake = clouds_bake,
    .kernels = clouds_kernels,
};

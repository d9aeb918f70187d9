/*
 * The reflection family (issue 18): so far the DFG (split-sum) LUT
 * (dfg.h), which depends on nothing but its kernel: baked once, reused by
 * every later bake whose key matches (docs/reflections.md).
 */
#include <stdio.h>

#include "dfg.h"
#include "family.h"

#define DFG_RECIPE 1

static void reflection_key(void *state, const struct sb_scene *scene, enum sb_product_id id, struct sb_key_text *key)
{
    char code[SB_HASH_HEX_SIZE];
    sb_dfg_code_hash(code);
    sb_key_add(key, " recipe %d size %d samples %dx%d code %s", DFG_RECIPE, SB_DFG_SIZE, SB_DFG_SAMPLES_SIDE,
               SB_DFG_SAMPLES_SIDE, code);
}

static enum sb_result reflection_bake(void *state, struct sb_vk *vk, const struct sb_scene *scene,
                                      enum sb_product_id id, const struct sb_image baked[SB_PRODUCT_COUNT],
                                      struct sb_image *image, struct sb_artifact *a)
{
    enum sb_result res = sb_dfg_bake(vk, image, &a->gpu_ms);
    if (!res)
        snprintf(a->settings_json, sizeof(a->settings_json),
                 "{\"brdf\":\"GGX, height-correlated Smith, Schlick\",\"x\":\"Fresnel-weighted\",\"y\":\"whole\","
                 "\"samples\":[%d,%d],\"sampling\":\"midpoint grid of the inverse CDF of D(h) (n.h)\"}",
                 SB_DFG_SAMPLES_SIDE, SB_DFG_SAMPLES_SIDE);
    return res;
}

const struct sb_family_baker sb_reflection_family = {
    .key = reflection_key,
    .bake = reflection_bake,
};

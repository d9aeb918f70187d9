/*
 * Bloom: the exposed frame filtered down a chain of r->bloom_levels mip
 * levels at half resolution (bloom_down), then back up, each level adding
 * the one below (bloom_up); the tone curve adds level 0 ("bloom" in the
 * graph's table). Left out (or with no levels), the tone curve adds none
 * (the frame constants say so, renderer.c).
 */
#include <stdlib.h>

#include "renderer_internal.h"

#include "bloom_down.spv.h"
#include "bloom_up.spv.h"

#define BLOOM_SETS (2 * SB_BLOOM_MAX_LEVELS) /* a set a step: down steps 0..L-1, then up steps */
_Static_assert(BLOOM_SETS <= SB_GRAPH_MAX_SETS, "a bloom step a set");

struct bloom {
    struct sb_texture chain;
    VkPipeline down, up;
};

/* The chain (made whatever the levels: the tone curve's binding reads it),
 * and the steps' sets: down step i reads level i - 1 (the frame for
 * i = 0) and writes level i; up step i reads level i + 1 and adds into
 * level i. */
static enum sb_result bloom_create(struct sb_renderer *r)
{
    struct bloom *b = calloc(1, sizeof(*b));
    if (!b)
        return SB_ERR_NOMEM;
    sb_pass_set_data(r, b);
    const uint32_t size[3] = {r->width / 2 ? r->width / 2 : 1, r->height / 2 ? r->height / 2 : 1, 1};
    enum sb_result res =
        sb_renderer_texture(r, &b->chain, size, 1, r->bloom_levels > 1 ? r->bloom_levels : 2, SB_HDR_FORMAT,
                            VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT, "bloom chain");
    if (res)
        return res;
    sb_resource chain = sb_graph_image(r, "bloom", &b->chain);
    if (!r->bloom_levels)
        return SB_OK;
    sb_pass_use(r, SB_VIEW_BINDING_FRAME, sb_pass_find(r, "frame"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_EXPOSURE, sb_pass_find(r, "exposure"), SB_USE_LOAD);
    sb_pass_sample(r, SB_VIEW_BINDING_BLOOM_SRC, sb_pass_find(r, "hdr"), NULL);
    sb_pass_use(r, SB_VIEW_BINDING_BLOOM_DST, chain, SB_USE_LOAD_STORE);
    sb_pass_sets(r, BLOOM_SETS);
    VkImageView mip[SB_BLOOM_MAX_LEVELS];
    for (uint32_t i = 0; i < SB_BLOOM_MAX_LEVELS; i++)
        mip[i] = b->chain.subview_count ? b->chain.subviews[i < r->bloom_levels ? i : 0] : b->chain.view;
    for (uint32_t i = 0; i < SB_BLOOM_MAX_LEVELS; i++) {
        if (i > 0)
            sb_pass_set_view(r, i, SB_VIEW_BINDING_BLOOM_SRC, mip[i - 1]);
        sb_pass_set_view(r, i, SB_VIEW_BINDING_BLOOM_DST, mip[i]);
        sb_pass_set_view(r, SB_BLOOM_MAX_LEVELS + i, SB_VIEW_BINDING_BLOOM_SRC,
                         mip[i + 1 < SB_BLOOM_MAX_LEVELS ? i + 1 : i]);
        sb_pass_set_view(r, SB_BLOOM_MAX_LEVELS + i, SB_VIEW_BINDING_BLOOM_DST, mip[i]);
    }
    res = sb_renderer_kernel(r, sb_spv_bloom_down, sizeof(sb_spv_bloom_down), "bloom down", &b->down);
    if (!res)
        res = sb_renderer_kernel(r, sb_spv_bloom_up, sizeof(sb_spv_bloom_up), "bloom up", &b->up);
    return res;
}

static void bloom_destroy(struct sb_renderer *r)
{
    struct bloom *b = sb_pass_data(r);
    if (!b)
        return;
    struct sb_texture *chain = &b->chain;
    sb_renderer_release(r, &chain, 1);
    free(b);
}

static void bloom_record(struct sb_renderer *r)
{
    struct bloom *b = sb_pass_data(r);
    if (!r->bloom_levels)
        return;
    uint32_t w = b->chain.width, h = b->chain.height;
    const uint32_t group[3] = {SB_WORKGROUP_X, SB_WORKGROUP_Y, 1};
    for (uint32_t i = 0; i < r->bloom_levels; i++) {
        struct sb_view_push push = {.level = i, .first_level = i == 0};
        sb_renderer_dispatch_set(r, i, b->down, &push, (const uint32_t[3]){w >> i ? w >> i : 1, h >> i ? h >> i : 1, 1},
                                 group);
        if (r->bloom_levels > 1) /* the next step reads it */
            sb_renderer_barrier(r->cmd);
    }
    for (uint32_t i = r->bloom_levels - 1; i-- > 0;) {
        struct sb_view_push push = {.level = i};
        sb_renderer_dispatch_set(r, SB_BLOOM_MAX_LEVELS + i, b->up, &push,
                                 (const uint32_t[3]){w >> i ? w >> i : 1, h >> i ? h >> i : 1, 1}, group);
        if (i > 0)
            sb_renderer_barrier(r->cmd);
    }
}

/* Left out, the tone curve adds no bloom (renderer.c's frame constants). */
const struct sb_pass_class sb_pass_bloom = {
    .name = "bloom",
    .post = true,
    .create = bloom_create,
    .destroy = bloom_destroy,
    .record = bloom_record,
    .optional = true,
};

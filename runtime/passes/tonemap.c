/*
 * The tone curve (AgX, ACES or GT, sb_renderer_params.tonemap): the exposed
 * frame and its bloom to sRGB-encoded 8-bit, into the renderer's "ldr".
 */
#include "renderer_internal.h"

#include "tonemap.spv.h"
#include "tonemap_aces.spv.h"
#include "tonemap_gt.spv.h"

static enum sb_result tonemap_create(struct sb_renderer *r)
{
    sb_resource bloom = sb_pass_find(r, "bloom");
    const struct sb_texture *chain = sb_graph_texture(r, bloom);
    sb_pass_use(r, SB_VIEW_BINDING_FRAME, sb_pass_find(r, "frame"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_EXPOSURE, sb_pass_find(r, "exposure"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_HDR, sb_pass_find(r, "hdr"), SB_USE_LOAD);
    sb_pass_sample(r, SB_VIEW_BINDING_BLOOM, bloom, NULL);
    sb_pass_set_view(r, 0, SB_VIEW_BINDING_BLOOM, chain->subview_count ? chain->subviews[0] : chain->view);
    sb_pass_use(r, SB_VIEW_BINDING_LDR, sb_pass_find(r, "ldr"), SB_USE_STORE);
    /* the renderer's curve, built alone (tonemap.comp) */
    if (r->params.tonemap == SB_TONEMAP_ACES)
        return sb_pass_frame_kernel(r, sb_spv_tonemap_aces, sizeof(sb_spv_tonemap_aces), "tonemap (ACES)");
    if (r->params.tonemap == SB_TONEMAP_GT)
        return sb_pass_frame_kernel(r, sb_spv_tonemap_gt, sizeof(sb_spv_tonemap_gt), "tonemap (GT)");
    return sb_pass_frame_kernel(r, sb_spv_tonemap, sizeof(sb_spv_tonemap), "tonemap (AgX)");
}

const struct sb_pass_class sb_pass_tonemap = {
    .name = "tonemap",
    .post = true,
    .create = tonemap_create,
    .destroy = sb_pass_frame_kernel_destroy,
    .record = sb_pass_frame_kernel_record,
};

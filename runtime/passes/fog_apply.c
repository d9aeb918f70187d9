/*
 * The froxel fog applied to the frame (fog_apply.comp, docs/fog.md): each
 * pixel's in-scattering and transmittance to its depth from the fog pass's
 * volume ("froxels"), the height fog beyond it in closed form. Without fog
 * (no "froxels" in the graph's table) it declares and records nothing.
 */
#include "clouds_gpu.h"
#include "fog_gpu.h"
#include "probes_gpu.h"
#include "renderer_internal.h"

#include "fog_apply.spv.h"

static enum sb_result fog_apply_create(struct sb_renderer *r)
{
    sb_resource froxels = sb_graph_find(r, "froxels");
    if (!froxels)
        return SB_OK;
    sb_pass_read_atmosphere(r);
    sb_pass_use(r, SB_VIEW_BINDING_HDR, sb_pass_find(r, "hdr"), SB_USE_LOAD_STORE);
    sb_pass_sample(r, SB_VIEW_BINDING_DEPTH, sb_pass_find(r, "depth"), r->nearest);
    sb_pass_use(r, SB_VIEW_BINDING_FOG, sb_pass_find(r, "fog"), SB_USE_LOAD);
    sb_pass_sample(r, SB_VIEW_BINDING_FROXEL, froxels, NULL);
    sb_pass_read_probes(r);
    sb_pass_use(r, SB_VIEW_BINDING_CLOUDS, sb_pass_find(r, "clouds"), SB_USE_LOAD);
    sb_pass_sample(r, SB_VIEW_BINDING_CLOUD_SHADOW, sb_pass_find(r, "cloud shadow"), NULL);
    return sb_pass_frame_kernel(r, sb_spv_fog_apply, sizeof(sb_spv_fog_apply), "fog apply");
}

/* It reads the froxels: the fog left out, it is too. */
const struct sb_pass_class sb_pass_fog_apply = {
    .name = "fog apply",
    .create = fog_apply_create,
    .destroy = sb_pass_frame_kernel_destroy,
    .record = sb_pass_frame_kernel_record,
    .optional = true,
    .needs = 1u << SB_PASS_FOG,
};

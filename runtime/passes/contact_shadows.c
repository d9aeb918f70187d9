/*
 * Screen-space contact shadows (contact_shadows.comp, docs/skyview.md,
 * "Soft shadows"): on the raster path, the key light's direct share of
 * each pixel, which the scene pass writes beside the frame ("key light"),
 * taken back where a short march toward the light through the depth
 * buffer meets a caster the cascades miss. The traced scene's shadow rays
 * are exact, so it has no "key light" and this pass declares and records
 * nothing; left out (sb_view.disabled_passes), the frame keeps the
 * cascades' shadows alone.
 */
#include "renderer_internal.h"

#include "contact_shadows.spv.h"

static enum sb_result contact_shadows_create(struct sb_renderer *r)
{
    sb_resource key = sb_graph_find(r, "key light");
    if (!key || r->params.no_contact_shadows)
        return SB_OK;
    sb_pass_read_atmosphere(r);
    sb_pass_use(r, SB_VIEW_BINDING_HDR, sb_pass_find(r, "hdr"), SB_USE_LOAD_STORE);
    sb_pass_sample(r, SB_VIEW_BINDING_DEPTH, sb_pass_find(r, "depth"), r->nearest);
    sb_pass_use(r, SB_VIEW_BINDING_KEY_LIGHT, key, SB_USE_LOAD);
    return sb_pass_frame_kernel(r, sb_spv_contact_shadows, sizeof(sb_spv_contact_shadows), "contact shadows");
}

const struct sb_pass_class sb_pass_contact_shadows = {
    .name = "contact shadows",
    .create = contact_shadows_create,
    .destroy = sb_pass_frame_kernel_destroy,
    .record = sb_pass_frame_kernel_record,
    .optional = true,
};

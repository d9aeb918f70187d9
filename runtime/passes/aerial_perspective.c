/*
 * Aerial perspective (Hillaire 2020): the in-scattered radiance and the
 * transmittance between the camera and each froxel of an SB_AERIAL_SIZE^3
 * volume out to SB_AERIAL_FAR_KM, which the scene and the clouds sample;
 * "aerial" and "aerial transmittance" in the graph's table.
 */
#include <stdlib.h>

#include "log.h"
#include "renderer_internal.h"

#include "aerial_perspective.spv.h"
#include "aerial_perspective_moon.spv.h"
#include "aerial_perspective_moon_quads.spv.h"
#include "aerial_perspective_quads.spv.h"

struct aerial {
    struct sb_texture scattering, transmittance;
    VkPipeline kernel[2]; /* by day, and with the moon in the sky */
};

static enum sb_result aerial_create(struct sb_renderer *r)
{
    struct aerial *a = calloc(1, sizeof(*a));
    if (!a)
        return SB_ERR_NOMEM;
    sb_pass_set_data(r, a);
    const uint32_t size[3] = {SB_AERIAL_SIZE, SB_AERIAL_SIZE, SB_AERIAL_SIZE};
    const VkImageUsageFlags usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    /* the in-scattering is read back with the frame (sb_renderer_aerial) */
    enum sb_result res =
        sb_renderer_texture(r, &a->scattering, size, 1, 1, SB_HDR_FORMAT, usage | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                            "aerial perspective in-scattering");
    if (!res)
        res = sb_renderer_texture(r, &a->transmittance, size, 1, 1, SB_HDR_FORMAT, usage,
                                  "aerial perspective transmittance");
    if (res)
        return res;
    sb_pass_read_atmosphere(r);
    sb_pass_use(r, SB_VIEW_BINDING_AERIAL_OUT, sb_graph_image(r, "aerial", &a->scattering), SB_USE_STORE);
    sb_pass_use(r, SB_VIEW_BINDING_AERIAL_T_OUT, sb_graph_image(r, "aerial transmittance", &a->transmittance),
                SB_USE_STORE);
    /* with the spectral products a column's four bands share their light
     * within a quad where a compute shader's subgroups can (else at a
     * barrier a slice: aerial_perspective.comp) */
    bool quads = r->constants.bands && (r->vk->compute_subgroup_ops & VK_SUBGROUP_FEATURE_QUAD_BIT);
    sb_debug("aerial perspective: %s", !r->constants.bands ? "a column an invocation"
                                       : quads             ? "a band an invocation, summed by quads"
                                                           : "a band an invocation, summed in workgroup memory");
    if (quads) {
        res = sb_renderer_kernel(r, sb_spv_aerial_perspective_quads, sizeof(sb_spv_aerial_perspective_quads),
                                 "aerial perspective (quads)", &a->kernel[0]);
        if (!res)
            res = sb_renderer_kernel(r, sb_spv_aerial_perspective_moon_quads,
                                     sizeof(sb_spv_aerial_perspective_moon_quads),
                                     "aerial perspective (the moon, quads)", &a->kernel[1]);
        return res;
    }
    res = sb_renderer_kernel(r, sb_spv_aerial_perspective, sizeof(sb_spv_aerial_perspective), "aerial perspective",
                             &a->kernel[0]);
    if (!res)
        res = sb_renderer_kernel(r, sb_spv_aerial_perspective_moon, sizeof(sb_spv_aerial_perspective_moon),
                                 "aerial perspective (the moon)", &a->kernel[1]);
    return res;
}

static void aerial_destroy(struct sb_renderer *r)
{
    struct aerial *a = sb_pass_data(r);
    if (!a)
        return;
    struct sb_texture *const textures[] = {&a->scattering, &a->transmittance};
    sb_renderer_release(r, textures, 2);
    free(a);
}

static void aerial_record(struct sb_renderer *r)
{
    struct aerial *a = sb_pass_data(r);
    sb_renderer_dispatch(r, a->kernel[r->frame_lights > 1], NULL,
                         (const uint32_t[3]){SB_AERIAL_SIZE, SB_AERIAL_SIZE, 1},
                         (const uint32_t[3]){SB_WORKGROUP_X, SB_WORKGROUP_Y, 1});
}

const struct sb_pass_class sb_pass_aerial_perspective = {
    .name = "aerial perspective",
    .create = aerial_create,
    .destroy = aerial_destroy,
    .record = aerial_record,
};

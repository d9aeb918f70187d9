/*
 * The sky-view LUT (Hillaire 2020): the sky's radiance around the camera on
 * a latitude-longitude grid, SB_SKY_VIEW_WIDTH x SB_SKY_VIEW_HEIGHT, a layer
 * for each light in the sky (the sun's, and at night the moon's, written
 * only then), which the probes and the sky pass sample; "sky-view" in the
 * graph's table.
 */
#include <stdlib.h>

#include "renderer_internal.h"

#include "sky_view.spv.h"

struct sky_view {
    struct sb_texture lut;
    VkPipeline kernel;
};

static enum sb_result sky_view_create(struct sb_renderer *r)
{
    struct sky_view *s = calloc(1, sizeof(*s));
    if (!s)
        return SB_ERR_NOMEM;
    sb_pass_set_data(r, s);
    enum sb_result res = sb_renderer_texture(
        r, &s->lut, (const uint32_t[3]){SB_SKY_VIEW_WIDTH, SB_SKY_VIEW_HEIGHT, 1}, SB_SKY_LIGHTS, 1, SB_HDR_FORMAT,
        VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, "sky-view LUT");
    if (res)
        return res;
    sb_pass_read_atmosphere(r);
    sb_pass_use(r, SB_VIEW_BINDING_SKY_VIEW_OUT, sb_graph_image(r, "sky-view", &s->lut), SB_USE_STORE);
    return sb_renderer_kernel(r, sb_spv_sky_view, sizeof(sb_spv_sky_view), "sky-view", &s->kernel);
}

static void sky_view_destroy(struct sb_renderer *r)
{
    struct sky_view *s = sb_pass_data(r);
    if (!s)
        return;
    struct sb_texture *lut = &s->lut;
    sb_renderer_release(r, &lut, 1);
    free(s);
}

static void sky_view_record(struct sb_renderer *r)
{
    struct sky_view *s = sb_pass_data(r);
    uint32_t lights = r->frame_lights;
    sb_renderer_dispatch(r, s->kernel, NULL, (const uint32_t[3]){SB_SKY_VIEW_WIDTH, SB_SKY_VIEW_HEIGHT, lights},
                         (const uint32_t[3]){SB_WORKGROUP_X, SB_WORKGROUP_Y, 1});
}

const struct sb_pass_class sb_pass_sky_view = {
    .name = "sky-view",
    .create = sky_view_create,
    .destroy = sky_view_destroy,
    .record = sky_view_record,
};

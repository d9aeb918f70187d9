/*
 * The sky: every pixel the scene left empty (depth 0) gets the sky's
 * radiance, from the sky-view LUT with the camera inside the atmosphere,
 * or by integrating along the ray from above it (sky_from_space).
 */
#include <stdlib.h>

#include "renderer_internal.h"

#include "sky.spv.h"
#include "sky_from_space.spv.h"
#include "sky_from_space_moon.spv.h"
#include "sky_moon.spv.h"

struct sky {
    VkPipeline inside[2], from_space[2]; /* by day, and with the moon in the sky */
};

static enum sb_result sky_create(struct sb_renderer *r)
{
    struct sky *s = calloc(1, sizeof(*s));
    if (!s)
        return SB_ERR_NOMEM;
    sb_pass_set_data(r, s);
    sb_pass_read_atmosphere(r);
    sb_pass_sample(r, SB_VIEW_BINDING_SKY_VIEW, sb_pass_find(r, "sky-view"), NULL);
    sb_pass_use(r, SB_VIEW_BINDING_HDR, sb_pass_find(r, "hdr"), SB_USE_LOAD_STORE);
    sb_pass_sample(r, SB_VIEW_BINDING_DEPTH, sb_pass_find(r, "depth"), r->nearest);
    enum sb_result res = sb_renderer_kernel(r, sb_spv_sky, sizeof(sb_spv_sky), "sky", &s->inside[0]);
    if (!res)
        res = sb_renderer_kernel(r, sb_spv_sky_from_space, sizeof(sb_spv_sky_from_space), "sky from space",
                                 &s->from_space[0]);
    if (!res)
        res = sb_renderer_kernel(r, sb_spv_sky_moon, sizeof(sb_spv_sky_moon), "sky (the moon)", &s->inside[1]);
    if (!res)
        res = sb_renderer_kernel(r, sb_spv_sky_from_space_moon, sizeof(sb_spv_sky_from_space_moon),
                                 "sky from space (the moon)", &s->from_space[1]);
    return res;
}

static void sky_destroy(struct sb_renderer *r)
{
    struct sky *s = sb_pass_data(r);
    if (!s)
        return;
    free(s);
}

static void sky_record(struct sb_renderer *r)
{
    struct sky *s = sb_pass_data(r);
    bool moon = r->frame_lights > 1;
    sb_renderer_dispatch_frame(r, r->camera_in_atmosphere ? s->inside[moon] : s->from_space[moon]);
}

const struct sb_pass_class sb_pass_sky = {
    .name = "sky",
    .create = sky_create,
    .destroy = sky_destroy,
    .record = sky_record,
};

/*
 * Automatic exposure: a histogram of the lit frame's log luminance
 * (histogram), then the metered exposure and its adaptation over time
 * (exposure), kept in the renderer's "exposure" buffer, which the post
 * passes read and the renderer reads back (pre-exposure, renderer.c).
 */
#include <stdlib.h>

#include "renderer_internal.h"

#include "exposure.spv.h"
#include "histogram.spv.h"

struct exposure {
    VkPipeline histogram, exposure;
};

static enum sb_result exposure_create(struct sb_renderer *r)
{
    struct exposure *e = calloc(1, sizeof(*e));
    if (!e)
        return SB_ERR_NOMEM;
    sb_pass_set_data(r, e);
    sb_pass_read_atmosphere(r); /* the frame, and the atmosphere's top: histogram.comp leaves space out */
    sb_pass_use(r, SB_VIEW_BINDING_EXPOSURE, sb_pass_find(r, "exposure"), SB_USE_LOAD_STORE);
    sb_pass_use(r, SB_VIEW_BINDING_HDR, sb_pass_find(r, "hdr"), SB_USE_LOAD);
    enum sb_result res = sb_renderer_kernel(r, sb_spv_histogram, sizeof(sb_spv_histogram), "histogram", &e->histogram);
    if (!res)
        res = sb_renderer_kernel(r, sb_spv_exposure, sizeof(sb_spv_exposure), "exposure", &e->exposure);
    return res;
}

static void exposure_destroy(struct sb_renderer *r)
{
    struct exposure *e = sb_pass_data(r);
    if (!e)
        return;
    free(e);
}

static void exposure_record(struct sb_renderer *r)
{
    struct exposure *e = sb_pass_data(r);
    sb_renderer_dispatch(r, e->histogram, NULL, (const uint32_t[3]){r->width, r->height, 1},
                         (const uint32_t[3]){16, 16, 1});
    sb_renderer_barrier(r->cmd);
    sb_renderer_dispatch(r, e->exposure, NULL, (const uint32_t[3]){1, 1, 1}, (const uint32_t[3]){1, 1, 1});
}

const struct sb_pass_class sb_pass_exposure = {
    .name = "exposure",
    .post = true,
    .create = exposure_create,
    .destroy = exposure_destroy,
    .record = exposure_record,
};

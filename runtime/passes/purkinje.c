/*
 * The Purkinje shift (shaders/purkinje.comp): one pass of the renderer's
 * table, "purkinje", on the lit frame before exposure, so that the meter
 * and every later pass see what the eye would. It needs the frame's
 * radiance in cd/m^2: the pack's is relative to its solar irradiance, and
 * the sun's illuminance above the atmosphere (params.sun_illuminance_lux)
 * makes it absolute. Off, it records nothing.
 */
#include <stdlib.h>

#include "purkinje_gpu.h"
#include "renderer_internal.h"
#include "scene.h"

#include "purkinje.spv.h"

/* CIE 191:2010's mesopic range: the cones alone at and above 5 cd/m^2, the
 * rods alone at and below 0.005 cd/m^2. */
#define PHOTOPIC_CD_M2 5.0
#define SCOTOPIC_CD_M2 0.005

struct sb_purkinje {
    bool enabled;
    struct sb_buffer params; /* sb_purkinje_gpu */
    VkPipeline kernel;
};

static enum sb_result purkinje_create(struct sb_renderer *r)
{
    struct sb_purkinje *p = calloc(1, sizeof(*p));
    if (!p)
        return SB_ERR_NOMEM;
    sb_pass_set_data(r, p);
    p->enabled = r->params.purkinje;
    if (!p->enabled)
        return SB_OK;
    enum sb_result res = sb_renderer_upload(r, NULL, sizeof(struct sb_purkinje_gpu), "Purkinje shift", &p->params);
    if (res)
        return res;
    struct sb_purkinje_gpu *gpu = p->params.mapped;
    gpu->scale[2] = (float)PHOTOPIC_CD_M2;
    gpu->scale[3] = (float)SCOTOPIC_CD_M2;
    sb_pass_use(r, SB_VIEW_BINDING_FRAME, sb_pass_find(r, "frame"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_HDR, sb_pass_find(r, "hdr"), SB_USE_LOAD_STORE);
    sb_pass_use(r, SB_VIEW_BINDING_PURKINJE, sb_graph_buffer(r, "purkinje", &p->params), SB_USE_LOAD);
    return sb_renderer_kernel(r, sb_spv_purkinje, sizeof(sb_spv_purkinje), "purkinje", &p->kernel);
}

static void purkinje_destroy(struct sb_renderer *r)
{
    struct sb_purkinje *p = sb_pass_data(r);
    if (!p)
        return;
    sb_buffer_destroy(r->vk, &p->params);
    free(p);
}

static void purkinje_record(struct sb_renderer *r)
{
    struct sb_purkinje *p = sb_pass_data(r);
    if (!p->enabled)
        return;
    /* The stored frame to cd/m^2 follows the frame's scale (pre-exposure). */
    struct sb_purkinje_gpu *gpu = p->params.mapped;
    double scale = r->cd_m2_per_unit / r->frame_scale;
    gpu->scale[0] = (float)scale;
    gpu->scale[1] = (float)(1.0 / scale);
    sb_renderer_dispatch_frame(r, p->kernel);
}

const struct sb_pass_class sb_pass_purkinje = {
    .name = "purkinje",
    .post = true,
    .create = purkinje_create,
    .destroy = purkinje_destroy,
    .record = purkinje_record,
    .optional = true,
};

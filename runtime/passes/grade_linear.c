/*
 * Scene-linear grading (grade_linear.comp, the science in grading.c), in
 * place on the exposed frame before bloom and the tone curve: white
 * balance, saturation, contrast, and a .cube LUT when it is made in
 * ACEScct. Neutral settings and no such LUT declare and record nothing, so
 * the frame is the tone mapper's bit for bit.
 */
#include <stdlib.h>

#include "grading_gpu.h"
#include "renderer_internal.h"

#include "grade_linear.spv.h"
#include "grade_linear_lut.spv.h"

struct grade_linear {
    struct sb_buffer lut;     /* lut3d.glsl's GradeLut (a stand-in without a LUT in ACEScct) */
    struct sb_buffer grading; /* sb_grading_gpu */
    VkPipeline kernel;
};

static enum sb_result grade_linear_create(struct sb_renderer *r)
{
    bool log_lut = r->params.grade && r->params.grade_log;
    if (!log_lut && sb_grading_is_neutral(&r->params.grading))
        return SB_OK;
    struct grade_linear *g = calloc(1, sizeof(*g));
    if (!g)
        return SB_ERR_NOMEM;
    sb_pass_set_data(r, g);
    enum sb_result res = sb_grade_lut_upload(r, log_lut ? r->params.grade : NULL, &g->lut);
    if (!res)
        res = sb_renderer_upload(r, NULL, sizeof(struct sb_grading_gpu), "grading", &g->grading);
    if (res)
        return res;
    sb_grading_gpu_fill(&r->params.grading, g->grading.mapped);
    sb_pass_use(r, SB_VIEW_BINDING_FRAME, sb_pass_find(r, "frame"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_EXPOSURE, sb_pass_find(r, "exposure"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_HDR, sb_pass_find(r, "hdr"), SB_USE_LOAD_STORE);
    sb_pass_use(r, SB_VIEW_BINDING_GRADE_LUT, sb_graph_buffer(r, "grade linear lut", &g->lut), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_GRADING, sb_graph_buffer(r, "grading", &g->grading), SB_USE_LOAD);
    return log_lut
               ? sb_renderer_kernel(r, sb_spv_grade_linear_lut, sizeof(sb_spv_grade_linear_lut), "grade linear",
                                    &g->kernel)
               : sb_renderer_kernel(r, sb_spv_grade_linear, sizeof(sb_spv_grade_linear), "grade linear", &g->kernel);
}

static void grade_linear_destroy(struct sb_renderer *r)
{
    struct grade_linear *g = sb_pass_data(r);
    if (!g)
        return;
    sb_buffer_destroy(r->vk, &g->lut);
    sb_buffer_destroy(r->vk, &g->grading);
    free(g);
}

static void grade_linear_record(struct sb_renderer *r)
{
    struct grade_linear *g = sb_pass_data(r);
    if (g)
        sb_renderer_dispatch_frame(r, g->kernel);
}

const struct sb_pass_class sb_pass_grade_linear = {
    .name = "grade linear",
    .post = true,
    .create = grade_linear_create,
    .destroy = grade_linear_destroy,
    .record = grade_linear_record,
    .optional = true,
};

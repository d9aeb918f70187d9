/*
 * A .cube LUT on the display-referred 8-bit frame (grade.comp), after the
 * tone curve, unless the LUT is made in ACEScct (then grade_linear.c
 * applies it). Without a LUT it declares and records nothing.
 */
#include <stdlib.h>

#include "grading_gpu.h"
#include "renderer_internal.h"

#include "grade.spv.h"

struct grade {
    struct sb_buffer lut; /* lut3d.glsl's GradeLut */
    VkPipeline kernel;
};

static enum sb_result grade_create(struct sb_renderer *r)
{
    if (!r->params.grade || r->params.grade_log)
        return SB_OK;
    struct grade *g = calloc(1, sizeof(*g));
    if (!g)
        return SB_ERR_NOMEM;
    sb_pass_set_data(r, g);
    enum sb_result res = sb_grade_lut_upload(r, r->params.grade, &g->lut);
    if (res)
        return res;
    sb_pass_use(r, SB_VIEW_BINDING_FRAME, sb_pass_find(r, "frame"), SB_USE_LOAD);
    sb_pass_use(r, SB_VIEW_BINDING_LDR, sb_pass_find(r, "ldr"), SB_USE_LOAD_STORE);
    sb_pass_use(r, SB_VIEW_BINDING_GRADE_LUT, sb_graph_buffer(r, "grade lut", &g->lut), SB_USE_LOAD);
    return sb_renderer_kernel(r, sb_spv_grade, sizeof(sb_spv_grade), "grade", &g->kernel);
}

static void grade_destroy(struct sb_renderer *r)
{
    struct grade *g = sb_pass_data(r);
    if (!g)
        return;
    sb_buffer_destroy(r->vk, &g->lut);
    free(g);
}

static void grade_record(struct sb_renderer *r)
{
    struct grade *g = sb_pass_data(r);
    if (g)
        sb_renderer_dispatch_frame(r, g->kernel);
}

const struct sb_pass_class sb_pass_grade = {
    .name = "grade",
    .post = true,
    .create = grade_create,
    .destroy = grade_destroy,
    .record = grade_record,
    .optional = true,
};

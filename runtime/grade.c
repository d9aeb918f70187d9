/*
 * Colour grading: a .cube LUT (formats/lut3d.h) applied to the
 * display-referred frame after tone mapping (shaders/grade.comp). One pass
 * of the renderer's table, "grade", after "tonemap"; without a LUT it
 * records nothing and the frame is the tone mapper's.
 */
#include <stdlib.h>
#include <string.h>

#include "lut3d.h"
#include "renderer_internal.h"

#include "grade.spv.h"

struct sb_grade {
    bool enabled;
    struct sb_buffer lut; /* grade.comp's GradeLut: domain and size, then the entries */
    VkPipeline kernel;
};

static enum sb_result grade_create(struct sb_renderer *r)
{
    struct sb_grade *g = calloc(1, sizeof(*g));
    if (!g)
        return SB_ERR_NOMEM;
    r->grade = g;
    const struct sb_lut3d *lut = r->params.grade;
    g->enabled = lut != NULL;
    size_t entries = g->enabled ? (size_t)lut->size * lut->size * lut->size * 3 : 0;
    size_t bytes = 8 * sizeof(float) + (entries ? entries : 3) * sizeof(float);
    enum sb_result res = sb_renderer_upload(r, NULL, bytes, "grading LUT", &g->lut);
    if (res)
        return res;
    if (g->enabled) {
        float *dst = g->lut.mapped;
        for (int c = 0; c < 3; c++) {
            dst[c] = lut->domain_min[c];
            dst[4 + c] = lut->domain_max[c];
        }
        dst[3] = (float)lut->size;
        memcpy(dst + 8, lut->rgb, entries * sizeof(float));
        res = sb_renderer_kernel(r, sb_spv_grade, sizeof(sb_spv_grade), "grade", &g->kernel);
    }
    sb_renderer_bind_buffer(r, SB_VIEW_BINDING_GRADE_LUT, &g->lut);
    return res;
}

static void grade_destroy(struct sb_renderer *r)
{
    struct sb_grade *g = r->grade;
    if (!g)
        return;
    sb_renderer_release(r, &g->kernel, 1, NULL, 0);
    sb_buffer_destroy(r->vk, &g->lut);
    free(g);
    r->grade = NULL;
}

static void grade_record(struct sb_renderer *r)
{
    if (!r->grade->enabled)
        return;
    sb_renderer_dispatch(r, r->grade->kernel, NULL, (const uint32_t[3]){r->width, r->height, 1},
                         (const uint32_t[3]){SB_WORKGROUP_X, SB_WORKGROUP_Y, 1});
}

const struct sb_pass_class sb_pass_grade = {
    .name = "grade",
    .create = grade_create,
    .destroy = grade_destroy,
    .record = grade_record,
};

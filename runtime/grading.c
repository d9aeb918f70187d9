/*
 * Colour grading's science, for two passes (passes/grade_linear.c on the
 * exposed scene-linear frame, passes/grade.c on the display-referred one):
 * white balance along the Planckian locus, saturation, contrast, the
 * matrices to and from ACES AP1 (physics/colour.h), in double precision;
 * and the LUT as the shaders read it (lut3d.glsl).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "colour.h"
#include "grading_gpu.h"
#include "lut3d.h"
#include "renderer_internal.h"

typedef double mat3[3][3];

static const double rec709[4][2] = {SB_REC709_PRIMARIES};

/* The Planckian locus in CIE 1960 uv (Krystek 1985, 1000 to 15000 K). */
static void planck_uv(double t, double uv[2])
{
    uv[0] =
        (0.860117757 + 1.54118254e-4 * t + 1.28641212e-7 * t * t) / (1.0 + 8.42420235e-4 * t + 7.08145163e-7 * t * t);
    uv[1] =
        (0.317398726 + 4.22806245e-5 * t + 4.20481691e-8 * t * t) / (1.0 - 2.89741816e-5 * t + 1.61456053e-7 * t * t);
}

/* The locus's unit normal at t, toward +v (greener). */
static void planck_normal(double t, double n[2])
{
    double a[2], b[2];
    planck_uv(t * 0.999, a);
    planck_uv(t * 1.001, b);
    double du = b[0] - a[0], dv = b[1] - a[1], len = hypot(du, dv);
    /* du < 0 as t grows: (-dv, du) points to +v */
    n[0] = dv / len;
    n[1] = -du / len;
    if (n[1] < 0.0) {
        n[0] = -n[0];
        n[1] = -n[1];
    }
}

static void planck_point(double t, double duv, double xy[2])
{
    double uv[2], n[2];
    planck_uv(t, uv);
    planck_normal(t, n);
    double u = uv[0] + duv * n[0], v = uv[1] + duv * n[1];
    double d = 2.0 * u - 8.0 * v + 4.0;
    xy[0] = 3.0 * u / d;
    xy[1] = 2.0 * v / d;
}

void sb_planckian_xy(double kelvin, double xy[2])
{
    planck_point(kelvin, 0.0, xy);
}

void sb_grading_white(double kelvin, double tint, double xy[2])
{
    /* D65 lies 0.0032 above the locus at 6504 K: the same offset at every
     * temperature makes 6504 K with no tint D65 itself. */
    double p[2], n[2], d65 = 4.0 * rec709[3][0] / (-2.0 * rec709[3][0] + 12.0 * rec709[3][1] + 3.0),
                       v65 = 6.0 * rec709[3][1] / (-2.0 * rec709[3][0] + 12.0 * rec709[3][1] + 3.0);
    planck_uv(SB_GRADING_NEUTRAL_K, p);
    planck_normal(SB_GRADING_NEUTRAL_K, n);
    double offset = (d65 - p[0]) * n[0] + (v65 - p[1]) * n[1];
    planck_point(kelvin, offset - tint * 1e-3, xy);
}

void sb_grading_matrix(const struct sb_grading *g, double m[3][3])
{
    mat3 to_xyz, from_xyz, cat, wb;
    double white[2];
    sb_grading_white(g->white_balance_k, g->tint, white);
    sb_primaries_to_xyz(rec709, to_xyz);
    sb_mat3_invert(to_xyz, from_xyz);
    sb_bradford(white, rec709[3], cat);
    sb_mat3_mul(cat, to_xyz, wb);
    sb_mat3_mul(from_xyz, wb, wb);
    /* saturation about Y: s I + (1 - s) 1 w^T, w the luminance row */
    mat3 sat;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            sat[i][j] = (1.0 - g->saturation) * to_xyz[1][j] + (i == j ? g->saturation : 0.0);
    sb_mat3_mul(sat, wb, m);
}

bool sb_grading_is_neutral(const struct sb_grading *g)
{
    return !g->enabled ||
           (g->white_balance_k == SB_GRADING_NEUTRAL_K && g->tint == 0.0 && g->saturation == 1.0 && g->contrast == 1.0);
}

static void store_rows(const mat3 m, float (*rows)[4])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++)
            rows[i][j] = j < 3 ? (float)m[i][j] : 0.0f;
}

void sb_grading_gpu_fill(const struct sb_grading *grading, struct sb_grading_gpu *gpu)
{
    bool neutral = sb_grading_is_neutral(grading);
    mat3 m = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, inv; /* neutral: exactly the identity */
    if (!neutral)
        sb_grading_matrix(grading, m);
    store_rows(m, gpu->matrix);
    gpu->tone[0] = neutral ? 1.0f : (float)grading->contrast;
    gpu->tone[1] = 0.18f;
    sb_rec709_to_ap1(m);
    sb_mat3_invert(m, inv);
    store_rows(m, gpu->to_ap1);
    store_rows(inv, gpu->from_ap1);
}

enum sb_result sb_grade_lut_upload(struct sb_renderer *r, const struct sb_lut3d *lut, struct sb_buffer *buffer)
{
    size_t entries = lut ? (size_t)lut->size * lut->size * lut->size * 3 : 0;
    size_t bytes = 8 * sizeof(float) + (entries ? entries : 3) * sizeof(float);
    enum sb_result res = sb_renderer_upload(r, NULL, bytes, "grading LUT", buffer);
    if (res || !lut)
        return res;
    float *dst = buffer->mapped;
    for (int c = 0; c < 3; c++) {
        dst[c] = lut->domain_min[c];
        dst[4 + c] = lut->domain_max[c];
    }
    dst[3] = (float)lut->size;
    memcpy(dst + 8, lut->rgb, entries * sizeof(float));
    return SB_OK;
}

/*
 * Colour grading's science, for two passes (passes/grade_linear.c on the
 * exposed scene-linear frame, passes/grade.c on the display-referred one):
 * white balance along the Planckian locus, saturation, contrast, the
 * matrices to and from ACES AP1, made here in double precision; and the
 * LUT as the shaders read it (lut3d.glsl).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grading_gpu.h"
#include "lut3d.h"
#include "renderer_internal.h"

typedef double mat3[3][3];

static void mul3(const mat3 a, const mat3 b, mat3 out)
{
    mat3 t;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            t[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
    memcpy(out, t, sizeof(t));
}

static void apply3(const mat3 m, const double v[3], double out[3])
{
    double t[3];
    for (int i = 0; i < 3; i++)
        t[i] = m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2];
    memcpy(out, t, sizeof(t));
}

static void invert3(const mat3 m, mat3 out)
{
    double c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1], c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2],
           c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
    double det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
    mat3 t = {
        {c00 / det, (m[0][2] * m[2][1] - m[0][1] * m[2][2]) / det, (m[0][1] * m[1][2] - m[0][2] * m[1][1]) / det},
        {c01 / det, (m[0][0] * m[2][2] - m[0][2] * m[2][0]) / det, (m[0][2] * m[1][0] - m[0][0] * m[1][2]) / det},
        {c02 / det, (m[0][1] * m[2][0] - m[0][0] * m[2][1]) / det, (m[0][0] * m[1][1] - m[0][1] * m[1][0]) / det},
    };
    memcpy(out, t, sizeof(t));
}

static void xy_to_xyz(const double xy[2], double xyz[3])
{
    xyz[0] = xy[0] / xy[1];
    xyz[1] = 1.0;
    xyz[2] = (1.0 - xy[0] - xy[1]) / xy[1];
}

/* RGB to XYZ for primaries r, g, b and white w (CIE 1931 xy): the
 * primaries' XYZ columns, each scaled so that RGB (1, 1, 1) is w at Y = 1. */
static void rgb_to_xyz(const double p[4][2], mat3 out)
{
    mat3 m;
    for (int j = 0; j < 3; j++) {
        double c[3];
        xy_to_xyz(p[j], c);
        for (int i = 0; i < 3; i++)
            m[i][j] = c[i];
    }
    mat3 inv;
    invert3(m, inv);
    double w[3], s[3];
    xy_to_xyz(p[3], w);
    apply3(inv, w, s);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            out[i][j] = m[i][j] * s[j];
}

static const double rec709[4][2] = {{0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06}, {0.3127, 0.3290}};
static const double ap1[4][2] = {{0.713, 0.293}, {0.165, 0.830}, {0.128, 0.044}, {0.32168, 0.33767}};

/* Bradford's von Kries adaptation of XYZ from white `from` to `to` (xy). */
static void bradford(const double from[2], const double to[2], mat3 out)
{
    static const mat3 b = {{0.8951, 0.2664, -0.1614}, {-0.7502, 1.7135, 0.0367}, {0.0389, -0.0685, 1.0296}};
    double wf[3], wt[3], lf[3], lt[3];
    xy_to_xyz(from, wf);
    xy_to_xyz(to, wt);
    apply3(b, wf, lf);
    apply3(b, wt, lt);
    mat3 d = {{lt[0] / lf[0], 0, 0}, {0, lt[1] / lf[1], 0}, {0, 0, lt[2] / lf[2]}}, inv;
    invert3(b, inv);
    mul3(d, b, out);
    mul3(inv, out, out);
}

void sb_rec709_to_xyz(double m[3][3])
{
    rgb_to_xyz(rec709, m);
}

void sb_rec709_to_ap1(double m[3][3])
{
    mat3 to_xyz, ap1_to_xyz, from_xyz, cat;
    rgb_to_xyz(rec709, to_xyz);
    rgb_to_xyz(ap1, ap1_to_xyz);
    invert3(ap1_to_xyz, from_xyz);
    bradford(rec709[3], ap1[3], cat);
    mul3(cat, to_xyz, m);
    mul3(from_xyz, m, m);
}

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
    rgb_to_xyz(rec709, to_xyz);
    invert3(to_xyz, from_xyz);
    bradford(white, rec709[3], cat);
    mul3(cat, to_xyz, wb);
    mul3(from_xyz, wb, wb);
    /* saturation about Y: s I + (1 - s) 1 w^T, w the luminance row */
    mat3 sat;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            sat[i][j] = (1.0 - g->saturation) * to_xyz[1][j] + (i == j ? g->saturation : 0.0);
    mul3(sat, wb, m);
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
    invert3(m, inv);
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

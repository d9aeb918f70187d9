#include "colour.h"

#include <math.h>
#include <string.h>

typedef double mat3[3][3];

void sb_mat3_mul(const mat3 a, const mat3 b, mat3 out)
{
    mat3 t;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            t[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
    memcpy(out, t, sizeof(t));
}

void sb_mat3_apply(const mat3 m, const double v[3], double out[3])
{
    double t[3];
    for (int i = 0; i < 3; i++)
        t[i] = m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2];
    memcpy(out, t, sizeof(t));
}

void sb_mat3_invert(const mat3 m, mat3 out)
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

void sb_xy_to_xyz(const double xy[2], double xyz[3])
{
    xyz[0] = xy[0] / xy[1];
    xyz[1] = 1.0;
    xyz[2] = (1.0 - xy[0] - xy[1]) / xy[1];
}

/* The primaries' XYZ columns, each scaled so that RGB (1, 1, 1) is w. */
void sb_primaries_to_xyz(const double p[4][2], mat3 out)
{
    mat3 m;
    for (int j = 0; j < 3; j++) {
        double c[3];
        sb_xy_to_xyz(p[j], c);
        for (int i = 0; i < 3; i++)
            m[i][j] = c[i];
    }
    mat3 inv;
    sb_mat3_invert(m, inv);
    double w[3], s[3];
    sb_xy_to_xyz(p[3], w);
    sb_mat3_apply(inv, w, s);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            out[i][j] = m[i][j] * s[j];
}

void sb_bradford(const double from[2], const double to[2], mat3 out)
{
    static const mat3 b = {{0.8951, 0.2664, -0.1614}, {-0.7502, 1.7135, 0.0367}, {0.0389, -0.0685, 1.0296}};
    double wf[3], wt[3], lf[3], lt[3];
    sb_xy_to_xyz(from, wf);
    sb_xy_to_xyz(to, wt);
    sb_mat3_apply(b, wf, lf);
    sb_mat3_apply(b, wt, lt);
    mat3 d = {{lt[0] / lf[0], 0, 0}, {0, lt[1] / lf[1], 0}, {0, 0, lt[2] / lf[2]}}, inv;
    sb_mat3_invert(b, inv);
    sb_mat3_mul(d, b, out);
    sb_mat3_mul(inv, out, out);
}

static const double rec709[4][2] = {SB_REC709_PRIMARIES};
static const double ap1[4][2] = {{0.713, 0.293}, {0.165, 0.830}, {0.128, 0.044}, {0.32168, 0.33767}};

void sb_rec709_to_xyz(mat3 m)
{
    sb_primaries_to_xyz(rec709, m);
}

void sb_rec709_to_ap1(mat3 m)
{
    mat3 to_xyz, ap1_to_xyz, from_xyz, cat;
    sb_primaries_to_xyz(rec709, to_xyz);
    sb_primaries_to_xyz(ap1, ap1_to_xyz);
    sb_mat3_invert(ap1_to_xyz, from_xyz);
    sb_bradford(rec709[3], ap1[3], cat);
    sb_mat3_mul(cat, to_xyz, m);
    sb_mat3_mul(from_xyz, m, m);
}

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

/* CIELAB's f: a cube root above (6/29)^3, a line below. */
static double lab_f(double t)
{
    const double d = 6.0 / 29.0;
    return t > d * d * d ? cbrt(t) : t / (3.0 * d * d) + 4.0 / 29.0;
}

void sb_xyz_to_lab(const double xyz[3], const double white[3], double lab[3])
{
    double fx = lab_f(xyz[0] / white[0]), fy = lab_f(xyz[1] / white[1]), fz = lab_f(xyz[2] / white[2]);
    lab[0] = 116.0 * fy - 16.0;
    lab[1] = 500.0 * (fx - fy);
    lab[2] = 200.0 * (fy - fz);
}

/* A hue angle in degrees, [0, 360); 0 for a neutral colour. */
static double hue_deg(double b, double a)
{
    if (a == 0.0 && b == 0.0)
        return 0.0;
    double h = atan2(b, a) * (180.0 / M_PI);
    return h < 0.0 ? h + 360.0 : h;
}

double sb_ciede2000(const double lab1[3], const double lab2[3])
{
    const double deg = M_PI / 180.0, pow25_7 = 6103515625.0; /* 25^7 */
    double c1 = hypot(lab1[1], lab1[2]), c2 = hypot(lab2[1], lab2[2]);
    double c_mean = 0.5 * (c1 + c2), c7 = pow(c_mean, 7.0);
    double g = 0.5 * (1.0 - sqrt(c7 / (c7 + pow25_7)));
    double a1 = (1.0 + g) * lab1[1], a2 = (1.0 + g) * lab2[1];
    double cp1 = hypot(a1, lab1[2]), cp2 = hypot(a2, lab2[2]);
    double hp1 = hue_deg(lab1[2], a1), hp2 = hue_deg(lab2[2], a2);

    double dl = lab2[0] - lab1[0], dc = cp2 - cp1, dh = 0.0;
    if (cp1 * cp2 != 0.0) {
        dh = hp2 - hp1;
        if (dh > 180.0)
            dh -= 360.0;
        else if (dh < -180.0)
            dh += 360.0;
    }
    double dH = 2.0 * sqrt(cp1 * cp2) * sin(0.5 * dh * deg);

    double l_mean = 0.5 * (lab1[0] + lab2[0]), cp_mean = 0.5 * (cp1 + cp2), hp_mean = hp1 + hp2;
    if (cp1 * cp2 != 0.0) {
        if (fabs(hp1 - hp2) <= 180.0)
            hp_mean *= 0.5;
        else
            hp_mean = hp_mean < 360.0 ? 0.5 * (hp_mean + 360.0) : 0.5 * (hp_mean - 360.0);
    }
    double t = 1.0 - 0.17 * cos((hp_mean - 30.0) * deg) + 0.24 * cos(2.0 * hp_mean * deg) +
               0.32 * cos((3.0 * hp_mean + 6.0) * deg) - 0.20 * cos((4.0 * hp_mean - 63.0) * deg);
    double d_theta = 30.0 * exp(-((hp_mean - 275.0) / 25.0) * ((hp_mean - 275.0) / 25.0));
    double cp7 = pow(cp_mean, 7.0);
    double r_c = 2.0 * sqrt(cp7 / (cp7 + pow25_7));
    double l50 = (l_mean - 50.0) * (l_mean - 50.0);
    double s_l = 1.0 + 0.015 * l50 / sqrt(20.0 + l50), s_c = 1.0 + 0.045 * cp_mean, s_h = 1.0 + 0.015 * cp_mean * t;
    double r_t = -sin(2.0 * d_theta * deg) * r_c;
    double tl = dl / s_l, tc = dc / s_c, th = dH / s_h;
    return sqrt(tl * tl + tc * tc + th * th + r_t * tc * th);
}

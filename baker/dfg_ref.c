/*
 * The DFG LUT's fp64 reference (dfg.h): two routes to the same integrals,
 * neither shared with the kernel's midpoint grid.
 */
#include <math.h>

#include "dfg.h"
#include "physics.h"

static double visibility(double n_v, double n_l, double a2)
{
    double gv = n_l * sqrt(n_v * n_v * (1 - a2) + a2), gl = n_v * sqrt(n_l * n_l * (1 - a2) + a2);
    return 0.5 / (gv + gl);
}

/* Composite Gauss-Legendre nodes and weights on [0, 1]: 8 a panel. */
static void node(int k, int panels, double *x, double *w)
{
    int p = k / 8;
    sb_gauss_legendre_node(k % 8, 8, (double)p / panels, (double)(p + 1) / panels, x, w);
}

/* The azimuth interval |phi| < phi_max where n.l > 0 and v.h > 0. */
static double phi_max(double sin_v, double n_v, double sin_h, double n_h)
{
    double den = sin_v * sin_h;
    if (den <= 1e-300)
        return n_v * (2 * n_h * n_h - 1) > 0 ? M_PI : 0;
    double c = fmax(n_v * (1 - 2 * n_h * n_h) / (2 * n_h * den), -n_v * n_h / den);
    return c >= 1 ? 0 : acos(fmax(c, -1.0));
}

void sb_dfg_reference(double n_v, double r, int panels, double out[2])
{
    double a2 = r * r * r * r, v[3] = {sqrt(1 - n_v * n_v), 0, n_v}, x = 0, y = 0;
    /* the polar angle of h by its inverse CDF; its azimuth over the
     * interval that reaches the light's hemisphere, phi = phi_max (1 - s^2),
     * graded toward its end (n.l = 0); both signs of phi */
    /* past xi_max l is below the horizon at every azimuth; in q = 1 - xi */
    double c_max = cos(0.5 * acos(n_v) + 0.25 * M_PI), c2 = c_max * c_max;
    double den_max = 1 - c2 + c2 * a2, xi_max = (1 - c2) / den_max, q_min = c2 * a2 / den_max;
    for (int i = 0; i < 8 * panels; i++) {
        double t, wi;
        node(i, panels, &t, &wi);
        double q = q_min + xi_max * t * t * t * t, den = a2 + q * (1 - a2);
        wi *= 4 * xi_max * t * t * t;
        double n_h = sqrt(q / den), sin_h = sqrt(a2 * fmax(1 - q, 0) / den);
        double pm = phi_max(v[0], n_v, sin_h, n_h);
        for (int j = 0; j < 8 * panels && pm > 0; j++) {
            double s, wj;
            node(j, panels, &s, &wj);
            double phi = pm * (1 - s * s), h[3] = {sin_h * cos(phi), sin_h * sin(phi), n_h};
            double v_h = v[0] * h[0] + v[2] * h[2], n_l = 2 * v_h * n_h - n_v;
            if (n_l <= 0 || v_h <= 0)
                continue;
            double g = visibility(n_v, n_l, a2) * 4 * n_l * v_h / n_h, f = pow(fmax(1 - v_h, 0.0), 5);
            double w = wi * wj * 2 * pm * s * 2 / (2 * M_PI);
            x += w * f * g;
            y += w * g;
        }
    }
    out[0] = x;
    out[1] = y;
}

void sb_dfg_reference_direct(double n_v, double r, int panels, double out[2])
{
    double a2 = r * r * r * r, v[3] = {sqrt(1 - n_v * n_v), 0, n_v}, x = 0, y = 0;
    for (int i = 0; i < 8 * panels; i++) {
        double t, wi;
        node(i, panels, &t, &wi);
        double theta = 0.5 * M_PI * t, n_l = cos(theta), s = sin(theta);
        for (int j = 0; j < 8 * panels; j++) {
            double u, wj;
            node(j, panels, &u, &wj);
            double phi = M_PI * u, l[3] = {s * cos(phi), s * sin(phi), n_l};
            double h[3] = {v[0] + l[0], v[1] + l[1], v[2] + l[2]};
            double len = sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
            if (len < 1e-300)
                continue;
            double n_h = h[2] / len, v_h = (v[0] * h[0] + v[2] * h[2]) / len;
            double dd = n_h * n_h * (a2 - 1) + 1, d = a2 / (M_PI * dd * dd);
            double g = d * visibility(n_v, n_l, a2) * n_l, f = pow(fmax(1 - v_h, 0.0), 5);
            /* dw = sin(theta) dtheta dphi over [0, pi/2] x [0, pi], doubled */
            double w = wi * wj * (0.5 * M_PI) * M_PI * s * 2;
            x += w * f * g;
            y += w * g;
        }
    }
    out[0] = x;
    out[1] = y;
}

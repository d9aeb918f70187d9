#include "sh.h"
#include "physics.h"

#include <math.h>
#include <stdbool.h>
#include <pthread.h>
#include <string.h>

void sb_sh9_basis(const double d[3], double y[SB_PROBE_SH])
{
    double x = d[0], yy = d[1], z = d[2];
    y[0] = 0.28209479177387814;
    y[1] = 0.4886025119029199 * yy;
    y[2] = 0.4886025119029199 * z;
    y[3] = 0.4886025119029199 * x;
    y[4] = 1.0925484305920792 * x * yy;
    y[5] = 1.0925484305920792 * yy * z;
    y[6] = 0.31539156525252005 * (3.0 * z * z - 1.0);
    y[7] = 1.0925484305920792 * x * z;
    y[8] = 0.5462742152960396 * (x * x - yy * yy);
}

void sb_probe_direction(uint32_t i, uint32_t n, double d[3])
{
    double y = 1.0 - (2.0 * i + 1.0) / n;
    double phi = 2.0 * M_PI * ((double)(uint32_t)(i * 0x9E3779B9u) * 0x1p-32);
    double r = sqrt(fmax(0.0, 1.0 - y * y));
    d[0] = r * cos(phi);
    d[1] = y;
    d[2] = r * sin(phi);
}

/* The unit direction at (u, v) of the upper hemisphere's octahedral map. */
static void sun_map_direction(double u, double v, double d[3])
{
    double x = 0.5 * (u + v), z = 0.5 * (u - v), y = fmax(1.0 - fabs(x) - fabs(z), 0.0);
    double len = sqrt(x * x + y * y + z * z);
    d[0] = x / len;
    d[1] = y / len;
    d[2] = z / len;
}

void sb_sun_table_direction(uint32_t j, double d[3])
{
    double step = 2.0 / (SB_SUN_SIDE - 1);
    sun_map_direction(-1.0 + step * (j % SB_SUN_SIDE), -1.0 + step * (j / SB_SUN_SIDE), d);
}

static uint32_t sun_hash(uint32_t x)
{
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

void sb_sun_table_sample(uint32_t j, uint32_t seed, double d[3])
{
    uint32_t h0 = sun_hash(seed), h1 = sun_hash(h0), h2 = sun_hash(h1), h3 = sun_hash(h2);
    double step = 2.0 / (SB_SUN_SIDE - 1), unit = 0x1p-24;
    double u = -1.0 + step * (j % SB_SUN_SIDE) + step * ((double)(h0 >> 8) - (double)(h1 >> 8)) * unit;
    double v = -1.0 + step * (j / SB_SUN_SIDE) + step * ((double)(h2 >> 8) - (double)(h3 >> 8)) * unit;
    u = u > 1.0 ? 2.0 - u : (u < -1.0 ? -2.0 - u : u);
    v = v > 1.0 ? 2.0 - v : (v < -1.0 ? -2.0 - v : v);
    sun_map_direction(u, v, d);
}

void sb_sun_table_weights(const double s[3], uint32_t at[4], double w[4])
{
    double d[3] = {s[0], fmax(s[1], 0.0), s[2]};
    double a = fabs(d[0]) + d[1] + fabs(d[2]);
    if (a > 0) {
        for (int k = 0; k < 3; k++)
            d[k] /= a;
    } else {
        d[0] = d[2] = 0;
        d[1] = 1;
    }
    double side = SB_SUN_SIDE - 1, t[2] = {d[0] + d[2], d[0] - d[2]}, f[2];
    uint32_t b[2];
    for (int k = 0; k < 2; k++) {
        t[k] = fmin(fmax((t[k] + 1.0) * 0.5 * side, 0.0), side);
        double base = fmin(floor(t[k]), side - 1.0);
        f[k] = t[k] - base;
        b[k] = (uint32_t)base;
    }
    uint32_t i = b[0] + b[1] * SB_SUN_SIDE;
    at[0] = i;
    at[1] = i + 1;
    at[2] = i + SB_SUN_SIDE;
    at[3] = i + SB_SUN_SIDE + 1;
    w[0] = (1 - f[0]) * (1 - f[1]);
    w[1] = f[0] * (1 - f[1]);
    w[2] = (1 - f[0]) * f[1];
    w[3] = f[0] * f[1];
}

double sb_sh9_eval(const double c[SB_PROBE_SH], const double d[3])
{
    double y[SB_PROBE_SH], sum = 0;
    sb_sh9_basis(d, y);
    for (int k = 0; k < SB_PROBE_SH; k++)
        sum += c[k] * y[k];
    return sum;
}

void sb_sh9_tensor(double t[SB_PROBE_SH][SB_PROBE_SH][SB_PROBE_SH])
{
    /* the products are polynomials of degree 6: 4 nodes in z and 7 in azimuth would do */
    enum { NZ = 8, NPHI = 16 };
    double zx[NZ], zw[NZ];
    for (int k = 0; k < NZ; k++)
        sb_gauss_legendre_node(k, NZ, -1.0, 1.0, &zx[k], &zw[k]);
    memset(t, 0, sizeof(double) * SB_PROBE_SH * SB_PROBE_SH * SB_PROBE_SH);
    for (int a = 0; a < NZ; a++)
        for (int b = 0; b < NPHI; b++) {
            double phi = 2 * M_PI * b / NPHI, r = sqrt(fmax(0.0, 1 - zx[a] * zx[a]));
            double d[3] = {r * cos(phi), r * sin(phi), zx[a]}, y[SB_PROBE_SH];
            sb_sh9_basis(d, y);
            double w = zw[a] * 2 * M_PI / NPHI;
            for (int i = 0; i < SB_PROBE_SH; i++)
                for (int j = 0; j < SB_PROBE_SH; j++)
                    for (int k = 0; k < SB_PROBE_SH; k++)
                        t[i][j][k] += w * y[i] * y[j] * y[k];
        }
    for (int i = 0; i < SB_PROBE_SH; i++) /* the zeros are zeros */
        for (int j = 0; j < SB_PROBE_SH; j++)
            for (int k = 0; k < SB_PROBE_SH; k++)
                if (fabs(t[i][j][k]) < 1e-12)
                    t[i][j][k] = 0;
}

void sb_sh9_from_zonal(const double z[3], const double axis[3], double c[SB_PROBE_SH])
{
    double y[SB_PROBE_SH];
    sb_sh9_basis(axis, y);
    static const int band[SB_PROBE_SH] = {SB_SH_BANDS};
    for (int k = 0; k < SB_PROBE_SH; k++)
        c[k] = sqrt(4.0 * M_PI / (2 * band[k] + 1)) * z[band[k]] * y[k];
}

/* The test directions and their basis, made once (deringing evaluates
 * them some twenty times a probe). */
static double test_direction[SB_SH_TEST_DIRECTIONS][3], test_basis[SB_SH_TEST_DIRECTIONS][SB_PROBE_SH];
static pthread_once_t test_once = PTHREAD_ONCE_INIT;

static void make_test_directions(void)
{
    for (uint32_t i = 0; i < SB_SH_TEST_DIRECTIONS; i++) {
        sb_probe_direction(i, SB_SH_TEST_DIRECTIONS, test_direction[i]);
        sb_sh9_basis(test_direction[i], test_basis[i]);
    }
}

/* The reconstruction at test direction i: sb_sh9_eval's sum, in its order. */
static inline double test_value(const double c[SB_PROBE_SH], uint32_t i)
{
    double v = 0;
    for (int k = 0; k < SB_PROBE_SH; k++)
        v += c[k] * test_basis[i][k];
    return v;
}

/* Whether the reconstruction is negative at a test direction: the same
 * answer as sb_sh9_min(c) < 0, found from *hint on (the direction where the
 * last call found one, which mostly still is), stopping at the first. */
static bool has_negative(const double c[SB_PROBE_SH], uint32_t *hint)
{
    for (uint32_t n = 0, i = *hint; n < SB_SH_TEST_DIRECTIONS; n++, i = i + 1 < SB_SH_TEST_DIRECTIONS ? i + 1 : 0)
        if (test_value(c, i) < 0.0) {
            *hint = i;
            return true;
        }
    return false;
}

double sb_sh9_min(const double c[SB_PROBE_SH], double where[3])
{
    pthread_once(&test_once, make_test_directions);
    double lowest = INFINITY;
    for (uint32_t i = 0; i < SB_SH_TEST_DIRECTIONS; i++) {
        double v = test_value(c, i);
        if (v < lowest) {
            lowest = v;
            if (where)
                memcpy(where, test_direction[i], sizeof(test_direction[i]));
        }
    }
    return lowest;
}

void sb_sh9_window_factors(double h, double w[3])
{
    /* Hann for order 2 (bands 1, 3/4, 1/4), then towards the constant band alone */
    static const double hann[3] = {1.0, 0.75, 0.25};
    for (int l = 0; l < 3; l++)
        w[l] = h <= 1.0 ? 1.0 - h * (1.0 - hann[l]) : (l ? hann[l] * (2.0 - h) : 1.0);
}

static void window(const double c[SB_PROBE_SH], double h, double out[SB_PROBE_SH])
{
    static const int band[SB_PROBE_SH] = {SB_SH_BANDS};
    double w[3];
    sb_sh9_window_factors(h, w);
    for (int k = 0; k < SB_PROBE_SH; k++)
        out[k] = c[k] * w[band[k]];
}

/*
 * The reconstruction at a test direction is linear in h on each half of
 * the window's range (sb_sh9_window_factors): with the direction's band
 * sums s0, s1, s2, it is s0 + (1 - h / 4) s1 + (1 - 3 h / 4) s2 on [0, 1]
 * and s0 + (2 - h) (3 s1 / 4 + s2 / 4) on [1, 2], s0 >= 0 at h = 2. So
 * each direction's smallest h from which it stays non-negative is exact,
 * and the window is their largest: one pass over the directions, not a
 * bisection's twenty.
 */
double sb_sh9_dering(double c[SB_PROBE_SH], double *min_before)
{
    pthread_once(&test_once, make_test_directions);
    double lowest = INFINITY, h = 0.0;
    /* comparisons rather than fmin and fmax (library calls, for NaN's
     * sake: every value here is finite), the bands' sums written out: the
     * same values, five times as fast */
    for (uint32_t i = 0; i < SB_SH_TEST_DIRECTIONS; i++) {
        const double *y = test_basis[i];
        double s[3] = {c[0] * y[0], c[1] * y[1] + c[2] * y[2] + c[3] * y[3],
                       c[4] * y[4] + c[5] * y[5] + c[6] * y[6] + c[7] * y[7] + c[8] * y[8]};
        double v = test_value(c, i);
        lowest = v < lowest ? v : lowest;
        double at1 = s[0] + 0.75 * s[1] + 0.25 * s[2], slope = 0.75 * s[1] + 0.25 * s[2];
        double from; /* where this direction turns non-negative for good */
        if (at1 < 0.0)
            from = slope < 0.0 ? 2.0 - s[0] / -slope : 2.0; /* on [1, 2], rising to s0 >= 0 */
        else if (s[0] + s[1] + s[2] < 0.0)
            from = (s[0] + s[1] + s[2]) / (0.25 * s[1] + 0.75 * s[2]); /* on [0, 1], rising to at1 */
        else
            from = 0.0;
        from = from < 2.0 ? from : 2.0;
        h = from > h ? from : h;
    }
    *min_before = lowest;
    if (lowest >= 0.0)
        return 0.0;
    /* the exact h may leave a rounding's worth below zero: step up by
     * ulps until no test direction is negative (a few at most) */
    double w[SB_PROBE_SH];
    uint32_t hint = 0;
    for (int step = 0; step < 64; step++) {
        window(c, h, w);
        if (!has_negative(w, &hint) || h >= 2.0)
            break;
        h = fmin(2.0, h + fmax(h, 1.0) * 0x1p-40);
    }
    memcpy(c, w, sizeof(w));
    return h;
}

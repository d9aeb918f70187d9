/*
 * The records atmosphere_probe.comp reads and writes, and the check of the
 * bakes' sun table against fp64 built on them, which test_atmosphere (the
 * earth, at the table's design bound) and test_hard_cases (every atmosphere
 * of data/scenes) share.
 */
#ifndef SB_TEST_ATMOSPHERE_PROBE_H
#define SB_TEST_ATMOSPHERE_PROBE_H

#include <math.h>
#include <stdint.h>

#include "atmosphere_ref.h"

#define PROBE_FLOATS 24 /* atmosphere_probe.comp's SB_PROBE_FLOATS */
#define PROBE_SUN 16    /* in: h, mu of a ray toward the sun; out: its transmittance, RGB */

static inline double rel_err(double gpu, double ref)
{
    return fabs(gpu / ref - 1.0);
}

/* The k-th ray toward the sun on which the bakes' sun table is checked:
 * altitudes crowded toward the ground, cosines over the whole range and,
 * for every other ray, within 0.2 of the horizon, crowded toward it, in
 * [-1, 1] whatever the planet (on a small one the horizon sits near
 * mu = -1 high up). */
static inline void sun_table_ray(const struct sb_atmosphere_params *p, int k, float *h, float *mu)
{
    uint64_t state = 0x9e3779b97f4a7c15ull * (uint64_t)(k + 1);
    double v[3];
    for (int i = 0; i < 3; i++) {
        state ^= state >> 31;
        state *= 0xbf58476d1ce4e5b9ull;
        state ^= state >> 29;
        v[i] = (double)(state >> 11) / 9007199254740992.0;
    }
    double R = p->ground_radius_km, hh = (p->top_radius_km - R) * v[0] * v[0];
    double mu_h = -sqrt(hh * (2 * R + hh)) / (R + hh);
    double m = k % 2 ? mu_h + 0.2 * v[1] * v[1] * v[1] * (v[2] < 0.5 ? -1 : 1) : -1 + 2 * v[1];
    m = m < mu_h + 1e-6 ? fabs(m) : m; /* the bakes never look up a ray that hits the ground */
    *h = (float)hh;
    *mu = (float)fmin(fmax(m, -1.0), 1.0);
}

/* The worst sun-table record so far: how far beyond its bound, the error
 * in optical depth there, and the ray. */
struct sun_table_worst {
    double excess, tau;
    float h, mu;
    int count; /* records where the sun's light counts */
};

/*
 * One record: the table's transmittance `got` at the ray (h, mu) against
 * fp64, wherever T > 0.05 (tau < 3; beyond, the sun's light no longer
 * counts). The input itself is fp32, and near the horizon one ulp of mu
 * moves the sun's ray through much air, so the allowance is `bound` of T
 * plus what 4 ulp of mu change.
 */
static inline void sun_table_record(const struct sb_atmosphere_params *p, float h, float mu, const float got[3],
                                    double bound, struct sun_table_worst *w)
{
    double ref[3], next[3], ulp = nextafterf(mu, 2.0f) - mu;
    sb_ref_transmittance(p, p->ground_radius_km + h, mu, 8, ref);
    sb_ref_transmittance(p, p->ground_radius_km + h, mu + 4 * ulp, 8, next);
    for (int c = 0; c < 3; c++) {
        if (!(ref[c] > 0.05))
            continue;
        w->count++;
        double excess = rel_err(got[c], ref[c]) - bound - rel_err(next[c], ref[c]);
        if (!isfinite(excess))
            excess = INFINITY;
        if (w->count == 1 || excess > w->excess) {
            w->excess = excess;
            w->tau = fabs(log(got[c] / ref[c]));
            w->h = h;
            w->mu = mu;
        }
    }
}

#endif

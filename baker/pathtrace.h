/*
 * fp64 Monte Carlo path tracer of the atmosphere: the reference for sky
 * radiance, with every scattering order and ground bounce, written
 * independently of the LUT model and of the shaders.
 *
 * The model is the products' (scene.h): a spherical planet with a
 * Lambertian ground, exponential Rayleigh and Mie layers, the ozone tent,
 * the Rayleigh and Cornette-Shanks phase functions, and the sun as a
 * directional source of irradiance solar_irradiance (no disk: the sun
 * itself is never seen, as in skybake's sky). Each channel is traced on its
 * own (the media's coefficients differ per channel).
 *
 * The estimator of one path:
 * - the view ray: its first collision is sampled in proportion to the
 *   ray's optical depth, tabulated in fp64, and stratified: the paths
 *   form 16 batches, and path j of a batch of n takes its quantile in
 *   [j / n, (j + 1) / n); where the
 *   ray ends on the ground, the ground's branch is added with the ray's
 *   exact transmittance;
 * - after that, free paths by delta tracking against a majorant per piece
 *   of the ray (the density at the piece's lowest point);
 * - at every vertex, next-event estimation toward the sun, with the sun's
 *   transmittance integrated exactly (sb_ref_transmittance); where Mie's
 *   peak is strong (|g| >= 0.5) the next vertex's sunlight is also drawn
 *   from a direction about the sun, both draws weighed by the balance
 *   heuristic: the peak's light no longer rests on the rare paths that
 *   happen to travel along it;
 * - scattering directions from the phase functions: Rayleigh exactly,
 *   Cornette-Shanks from Henyey-Greenstein of the same g, weighted by the
 *   ratio of the two (at most 3 / (2 + g^2)); the ground cosine-weighted;
 * - Russian roulette once a path's throughput falls below a fifth of its
 *   first vertex's, so that every order is counted and none biased.
 *
 * Random numbers come from one stream per (seed, view, channel, path):
 * results depend on nothing else (no thread count, no call order) and are
 * reproducible bit for bit on one build.
 */
#ifndef SB_BAKER_PATHTRACE_H
#define SB_BAKER_PATHTRACE_H

#include <stdbool.h>
#include <stdint.h>

#include "scene.h"

/* Where the sky is looked at from, and where. */
struct sb_pathtrace_view {
    double altitude_km; /* the camera above the ground; above the top, rays start where they enter */
    double mu;          /* cos(view zenith angle) */
    double mu_s;        /* cos(sun zenith angle) */
    double nu;          /* cos(view-sun angle); clamped to what mu and mu_s allow */
};

struct sb_pathtrace_params {
    uint64_t seed;
    int paths;     /* per view and channel; 0: 4096 */
    int max_order; /* vertices (scattering events and ground bounces) per path; 0: all */
    bool unguided; /* no directions drawn about the sun (the same mean, noisier; for tests) */
};

struct sb_pathtrace_result {
    double radiance;  /* the mean over the paths, in solar_irradiance's unit per steradian */
    double std_error; /* its standard error, from the spread of 16 independent batches of
                         the paths (infinite for fewer than 32 paths) */
};

/* The radiance reaching the camera along the view, in one channel (0 to 2).
 * Thread safe; the parameters must be valid (sb_atmosphere_validate). */
struct sb_pathtrace_result sb_pathtrace_radiance(const struct sb_atmosphere_params *atmosphere,
                                                 const struct sb_pathtrace_view *view, int channel,
                                                 const struct sb_pathtrace_params *params);

#endif

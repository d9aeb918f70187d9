/*
 * fp64 CPU reference of the atmosphere products, written independently of
 * the shaders: geometry in plain double precision, transmittance by composite
 * 16-point Gauss-Legendre, scattering along rays with segments cut at
 * denser altitude levels, at the tangent point and where the planet's shadow
 * begins, and with exact (not tabulated) transmittance toward the sun.
 * Where a product's definition reads another product (the multiple-
 * scattering LUT for irradiance), the reference reads the same baked LUT with
 * its own fp64 interpolation (the shaders' lookup, see lut_log_cubic). All functions are thread safe.
 */
#ifndef SB_BAKER_ATMOSPHERE_REF_H
#define SB_BAKER_ATMOSPHERE_REF_H

#include <stdint.h>

#include "image.h"
#include "scene.h"

struct sb_ref_quality {
    int directions_mu;              /* Gauss-Legendre nodes in cos(zenith) per piece; 0: 32 */
    int directions_phi;             /* midpoint nodes in azimuth over [0, pi]; 0: 16 */
    int level_steps;                /* altitude levels per factor 2 of altitude; 0: 2 */
    int transmittance_subdivisions; /* GL-16 sub-pieces per piece of a sun ray; 0: 2 */
};

/* Transmittance from radius r (km) with cosine mu to the top; the ray must not
 * hit the ground. subdivisions: GL-16 sub-pieces per piece (8 is converged to
 * fp64 rounding). */
void sb_ref_transmittance(const struct sb_atmosphere_params *p, double r, double mu, int subdivisions, double out[3]);

/* The media at altitude h (km), per km: Rayleigh's and Mie's scattering,
 * and the extinction with Mie's and ozone's absorption. */
struct sb_ref_medium {
    double rayleigh[3], mie[3], extinction[3];
};
void sb_ref_medium(const struct sb_atmosphere_params *p, double h, struct sb_ref_medium *m);

/* The phase functions at the cosine nu of the scattering angle: Rayleigh's,
 * and Cornette-Shanks's with asymmetry g. */
double sb_ref_phase_rayleigh(double nu);
double sb_ref_phase_mie(double g, double nu);

/* The n-point Gauss-Legendre rule on [a, b]: nodes x[n] ascending, weights w[n]. */
void sb_ref_gauss_legendre(int n, double a, double b, double *x, double *w);

/* Optical depth along the ray from radius r (km) with cosine mu, between
 * the distances t_from <= t_to (km) on it, at the same precision; the
 * segment must stay in the atmosphere. */
void sb_ref_optical_depth(const struct sb_atmosphere_params *p, double r, double mu, double t_from, double t_to,
                          int subdivisions, double out[3]);

/* (r, mu) at unit coordinates (x_mu, x_r) of the transmittance LUT
 * (transmittance-subtexel-horizon-v2, docs/pack.md: texel (x, y) of W x H
 * is at (x / (W - 1), y / (H - 1))). */
void sb_ref_transmittance_geometry(const struct sb_atmosphere_params *p, double x_mu, double x_r, double *r,
                                   double *mu);

/* The inverse: unit coordinates of (r, mu), for a ray that does not hit the ground. */
void sb_ref_transmittance_coords(const struct sb_atmosphere_params *p, double r, double mu, double *x_mu, double *x_r);

/* A baked transmittance LUT (any size) read at (r, mu) as the runtime reads
 * it: its optical depth (-ln T, T floored at 1e-30) bilinear between texels,
 * clamped at the edges, then exp; in fp64. */
void sb_ref_transmittance_lookup(const struct sb_atmosphere_params *p, const struct sb_image *lut, double r, double mu,
                                 double out[3]);

/* The shaders' lookup of a multiscattering LUT at altitude h (km) with sun
 * cosine mu_s: Catmull-Rom of its logarithm, the edges repeated. */
void sb_ref_multiscattering_lookup(const struct sb_atmosphere_params *p, const struct sb_image *lut, double h,
                                   double mu_s, double out[3]);

/* Hillaire's psi_ms at altitude h (km) with sun cosine mu_s (see multiscattering.comp). */
void sb_ref_multiscattering(const struct sb_atmosphere_params *p, double h, double mu_s, const struct sb_ref_quality *q,
                            double out[3]);

/* Ground irradiance (see irradiance_ground.comp); `multiscattering` is the
 * baked LUT the product reads. */
void sb_ref_irradiance_ground(const struct sb_atmosphere_params *p, double h, double mu_s,
                              const struct sb_image *multiscattering, const struct sb_ref_quality *q, double direct[3],
                              double sky[3]);

/* Sky irradiance split rayleigh.rgb, mie.rgb, ground.rgb (see irradiance_sky.comp);
 * with irradiance_ground NULL, no light from the ground. */
void sb_ref_irradiance_sky(const struct sb_atmosphere_params *p, double h, double mu_s,
                           const struct sb_image *multiscattering, const struct sb_image *irradiance_ground,
                           const struct sb_ref_quality *q, double out[9]);

/* Sky radiance seen from altitude h (km) along view cosine mu, with sun cosine
 * mu_s and view-sun cosine nu: single scattering, multiple scattering from
 * the baked psi_ms, and the lit ground (baked irradiance_ground) where the
 * ray ends on it; no sun disk. What skyview's sky-view LUT holds. The sun's
 * transmittance is integrated exactly when `transmittance` is NULL, else
 * read from that baked LUT bilinearly, as the runtime reads it. From above
 * the atmosphere the ray starts where it enters it (0 where it misses).
 * With multiscattering NULL, only single scattering; with irradiance_ground
 * NULL, no light from the ground. */
void sb_ref_sky_radiance(const struct sb_atmosphere_params *p, double h, double mu, double mu_s, double nu,
                         const struct sb_image *transmittance, const struct sb_image *multiscattering,
                         const struct sb_image *irradiance_ground, const struct sb_ref_quality *q, double out[3]);

#endif

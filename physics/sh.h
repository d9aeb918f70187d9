/*
 * The C half of sh.glsl: the order-2 real SH basis (Sloan 2008), the probe
 * rays' directions, and deringing. Pure, thread safe, fp64.
 */
#ifndef SB_PHYSICS_SH_H
#define SB_PHYSICS_SH_H

#include <stdint.h>

#include "config.h"

/* The 9 basis functions at unit direction d (world axes). */
void sb_sh9_basis(const double d[3], double y[SB_PROBE_SH]);

/* Ray i of n of a probe (config.h: spherical Fibonacci, y up), in fp64. */
void sb_probe_direction(uint32_t i, uint32_t n, double d[3]);

/* The sun table's direction j (config.h, SB_SUN_SIDE; sh.glsl): the
 * corner (j % side, j / side) of a grid over the upper hemisphere's
 * octahedral map (u = (x + z) / a, v = (x - z) / a, a = |x| + |y| + |z|,
 * each from -1 to 1), unit, y up. */
void sb_sun_table_direction(uint32_t j, double d[3]);

/* A direction about the table's direction j drawn with the density of its
 * bilinear weight over the map (sh.glsl's sun_table_sample, from the same
 * hash of seed): the kernel casts one a hit and direction, seed = the
 * probe's ray x SB_SUN_DIRECTIONS + j. */
void sb_sun_table_sample(uint32_t j, uint32_t seed, double d[3]);

/* The 4 table directions around the sun s (unit or not) and their
 * bilinear weights, summing to 1; a sun below the horizon is read at the
 * horizon under it. */
void sb_sun_table_weights(const double s[3], uint32_t at[4], double w[4]);

/* The SH reconstruction sum_k c[k] Y_k(d). */
double sb_sh9_eval(const double c[SB_PROBE_SH], const double d[3]);

/* The triple-product tensor t[i][j][k] = the integral of Y_i Y_j Y_k over
 * the sphere, exact to rounding (Gauss-Legendre in the polar cosine times
 * a uniform rule in azimuth, exact for these polynomials): the SH of a
 * product fg, truncated to order 2, is sum_ij t[i][j][k] f_i g_j. */
void sb_sh9_tensor(double t[SB_PROBE_SH][SB_PROBE_SH][SB_PROBE_SH]);

/* A zonal function about unit axis a with zonal coefficients z[l] (l = 0..2)
 * in the basis: c_lm = sqrt(4 pi / (2 l + 1)) z_l Y_lm(a). */
void sb_sh9_from_zonal(const double z[3], const double axis[3], double c[SB_PROBE_SH]);

/* The smallest reconstruction over SB_SH_TEST_DIRECTIONS directions (a
 * spherical Fibonacci set), and where. */
#define SB_SH_TEST_DIRECTIONS 2048
double sb_sh9_min(const double c[SB_PROBE_SH], double where[3]);

/*
 * Dering: window the bands so that the reconstruction is never negative
 * (on the test directions). The window is h in [0, 2]: from 0 (none)
 * through 1 (Hann: bands scaled 1, 3/4, 1/4) to 2 (the constant band
 * alone, which is never negative for a non-negative function's
 * projection); the smallest h that works, exactly (the reconstruction is
 * linear in h on [0, 1] and on [1, 2]), stepped up by a few ulps where
 * rounding leaves a test direction below zero.
 * Returns h; *min_before gets the smallest value before (>= 0: nothing done).
 */
double sb_sh9_dering(double c[SB_PROBE_SH], double *min_before);

/* The window h's factor for each band l (0 to 2): what sb_sh9_dering
 * scaled the band's coefficients by. */
void sb_sh9_window_factors(double h, double w[3]);

#endif

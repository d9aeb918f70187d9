/*
 * Spectra, for the spectral reference of the sky (sky-error) and for the
 * runtime's colour: the CIE 1931 2-degree observer, the sun's spectral
 * irradiance above the atmosphere, ozone's absorption cross-section, a
 * scene's atmosphere at any wavelength, and what skybake's three channels
 * stand for. fp64; pure functions, thread safe.
 *
 * A scene gives its media at three channels. They stand for the
 * wavelengths sb_channel_nm (680, 550 and 440 nm: Bruneton 2017's and
 * Hillaire 2020's, whose earth values the earth preset holds). The spectral
 * model of a scene reads them as samples of spectra:
 * - Rayleigh's and Mie's coefficients: a power law in wavelength through
 *   each pair of neighbouring channels (Rayleigh's lambda^-4 and
 *   Angstrom's law for aerosols reproduced exactly), the end pairs' law
 *   beyond 440 and 680 nm;
 * - ozone: the measured cross-section times one number density, the least
 *   squares fit to the three channels (exact for the earth preset);
 * - the ground's albedo: linear in wavelength between the channels, flat
 *   beyond;
 * - the sun: the measured spectrum (its colour is then adapted to the
 *   scene's solar_irradiance, taken as linear Rec.709: sb_sun_xyz_to_rec709).
 */
#ifndef SB_PHYSICS_SPECTRUM_H
#define SB_PHYSICS_SPECTRUM_H

#include "config.h"
#include "image.h"
#include "product.h"
#include "scene.h"

#define SB_SPECTRUM_FIRST_NM 360.0
#define SB_SPECTRUM_STEP_NM 10.0
#define SB_SPECTRUM_COUNT 48 /* 360, 370, ..., 830 nm */

/* The wavelength each channel stands for, nm: red, green, blue. */
extern const double sb_channel_nm[3];

/* Wavelength k of the spectral grid, nm. */
double sb_spectrum_nm(int k);

/* The CIE 1931 2-degree colour matching functions at nm (linear between the
 * 5 nm table's rows; 0 outside 360 to 830 nm). */
void sb_cie1931_xyz(double nm, double xyz[3]);

/* The sun's spectral irradiance above the atmosphere, W m^-2 nm^-1, and
 * ozone's absorption cross-section, m^2 (10 nm bins, linear between them;
 * 0 outside 360 to 830 nm). */
double sb_solar_spectrum(double nm);
double sb_ozone_cross_section(double nm);

/* CIE XYZ of a spectrum sampled on the grid (10 nm a sample). */
void sb_spectrum_to_xyz(const double spectrum[SB_SPECTRUM_COUNT], double xyz[3]);

/* The ozone number density (per km per m^2 of cross-section) that fits the
 * scene's three channels best (least squares). */
double sb_ozone_density_fit(const struct sb_atmosphere_params *p);

/* Channel c of *out made the scene's media, ground and sun at wavelength nm
 * (the rules above); the geometry and the rest of *out are left alone. */
void sb_atmosphere_at_wavelength(const struct sb_atmosphere_params *p, double nm, int c,
                                 struct sb_atmosphere_params *out);

/* XYZ of the sun's spectrum above the atmosphere (sb_spectrum_to_xyz). */
void sb_sun_white(double xyz[3]);

/* XYZ under the measured sun to the runtime's linear Rec.709: Bradford's
 * adaptation from the sun's white to D65, then each channel scaled so that
 * the sun above the atmosphere comes out as the scene's solar_irradiance. */
void sb_sun_xyz_to_rec709(const double solar_rgb[3], double m[3][3]);

/*
 * The three-channel colour scheme: the matrix that takes skybake's three
 * channels of a radiance (the transfer at 680, 550 and 440 nm times the
 * scene's solar_irradiance) to the linear Rec.709 that its spectrum shows,
 * the transfer read linearly in wavelength between the channels (flat
 * beyond) under the measured sun, through the CIE observer and
 * sb_sun_xyz_to_rec709. The sun itself, and any grey transfer, is left as
 * it is: m (solar_rgb) = solar_rgb.
 */
void sb_channels_to_rec709(const double solar_rgb[3], double m[3][3]);

/*
 * The sky at 12 wavelengths (the spectral products, docs/pack.md): 400,
 * 430, 460, then every 20 nm to 600, 630 and 670 nm, in SB_SPECTRAL_BANDS
 * bands of three, band b's channel c wavelength 3 b + c; each band a scene
 * of its own (the rules above), so every three-channel kernel bakes and
 * draws it unchanged.
 */
#define SB_SPECTRAL_WAVELENGTHS (3 * SB_SPECTRAL_BANDS)

/* Wavelength i of the 12, nm (ascending, on the spectral grid). */
double sb_spectral_nm(int i);

/* The scene's atmosphere at band b's three wavelengths. */
void sb_spectral_band(const struct sb_atmosphere_params *p, int band, struct sb_atmosphere_params *out);

/* XYZ of radiances sampled at n ascending wavelengths nm[] (on the spectral
 * grid): the transfer (radiance over the sun's spectrum) linear between
 * them, flat beyond, times the sun's spectrum, through the observer. */
void sb_samples_to_xyz(const double *radiance, const double *nm, int n, double xyz[3]);

/* The 12 wavelengths' radiances (each band's sun the measured spectrum) to
 * the runtime's linear Rec.709 under the scene's sun: rgb = sum over i of
 * k[i] L_i (sb_samples_to_xyz, then sb_sun_xyz_to_rec709). */
void sb_spectral_to_rec709(const double solar_rgb[3], double k[SB_SPECTRAL_WAVELENGTHS][3]);

/* The spectral product's channel that holds channel `base_channel` of its
 * three-channel product for band b (docs/pack.md): g * 12 + 3 b + c for
 * base channel g * 3 + c. */
static inline uint32_t sb_spectral_channel(uint32_t base_channel, int b)
{
    return base_channel / 3 * (3 * SB_SPECTRAL_BANDS) + 3 * (uint32_t)b + base_channel % 3;
}

/* Band b's three wavelengths of a spectral product's image as its
 * three-channel product `base` holds a scene's channels (base channel
 * g * 3 + c from the spectral product's g * 12 + 3 b + c: docs/pack.md),
 * into *band (initialised here; the caller finishes it). */
enum sb_result sb_spectral_band_image(const struct sb_image *spectral, enum sb_product_id base, int b,
                                      struct sb_image *band);

#endif

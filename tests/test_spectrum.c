/*
 * physics/spectrum.c against independent values: the CIE 1931 observer's
 * tabulated integrals and illuminant A's published chromaticity; the ozone
 * table against Hillaire 2020's earth channels at 300 Dobson units; the
 * spectral Rayleigh coefficient against Bruneton 2017's closed form; every
 * scene's channels reproduced at their wavelengths; the three-channel
 * colour scheme's white and its exactness on the spectra it assumes. No
 * Vulkan.
 */
#include <math.h>
#include <stdio.h>

#include "colour.h"
#include "harness.h"
#include "spectrum.h"

/* A spectrum's chromaticity, sampled every `step` nm from 360 to 830. */
static void chromaticity(double (*spectrum)(double), double step, double xy[2], double *y_integral)
{
    double xyz[3] = {0, 0, 0};
    for (double nm = 360.0; nm <= 830.0 + 1e-9; nm += step) {
        double cmf[3], s = spectrum(nm);
        sb_cie1931_xyz(nm, cmf);
        for (int c = 0; c < 3; c++)
            xyz[c] += step * cmf[c] * s;
    }
    xy[0] = xyz[0] / (xyz[0] + xyz[1] + xyz[2]);
    xy[1] = xyz[1] / (xyz[0] + xyz[1] + xyz[2]);
    if (y_integral)
        *y_integral = xyz[1];
}

static double equal_energy(double nm)
{
    (void)nm;
    return 1.0;
}

/* CIE illuminant A (CIE 015:2004, eq. 3.1: Planck's law with the c2 of its
 * definition), relative. */
static double illuminant_a(double nm)
{
    return 100.0 * pow(560.0 / nm, 5.0) * expm1(1.435e7 / (2848.0 * 560.0)) / expm1(1.435e7 / (2848.0 * nm));
}

static void test_observer(void)
{
    double xy[2], y_integral;
    chromaticity(equal_energy, 5.0, xy, &y_integral);
    /* CIE 015: the integral of y-bar over 360 to 830 nm is 106.857; the equal-
     * energy illuminant is at x = y = 1/3 (the functions have equal areas) */
    printf("observer: integral of y %.6f, E at (%.6f, %.6f)\n", y_integral, xy[0], xy[1]);
    /* the published value's 3 decimals */
    CHECK(fabs(y_integral - 106.857) < 5e-4, "the integral of y-bar: %.6f, published 106.857", y_integral);
    CHECK(fabs(xy[0] - 1.0 / 3) < 1e-4 && fabs(xy[1] - 1.0 / 3) < 1e-4, "E at (%.6f, %.6f)", xy[0], xy[1]);
    /* illuminant A: (0.44757, 0.40745), CIE 015:2004 table T.3 */
    chromaticity(illuminant_a, 5.0, xy, NULL);
    printf("illuminant A, 5 nm: (%.5f, %.5f), published (0.44757, 0.40745)\n", xy[0], xy[1]);
    CHECK(fabs(xy[0] - 0.44757) < 5e-5 && fabs(xy[1] - 0.40745) < 5e-5, "illuminant A at 5 nm: (%.5f, %.5f)", xy[0],
          xy[1]);
    /* the grid the spectral reference integrates on (10 nm) */
    double s[SB_SPECTRUM_COUNT], xyz[3];
    for (int k = 0; k < SB_SPECTRUM_COUNT; k++)
        s[k] = illuminant_a(sb_spectrum_nm(k));
    sb_spectrum_to_xyz(s, xyz);
    double x = xyz[0] / (xyz[0] + xyz[1] + xyz[2]), y = xyz[1] / (xyz[0] + xyz[1] + xyz[2]);
    printf("illuminant A, the 10 nm grid: (%.5f, %.5f)\n", x, y);
    CHECK(fabs(x - 0.44757) < 2e-4 && fabs(y - 0.40745) < 2e-4, "illuminant A on the grid: (%.5f, %.5f)", x, y);
    CHECK(sb_spectrum_nm(0) == 360.0 && sb_spectrum_nm(SB_SPECTRUM_COUNT - 1) == 830.0, "the grid spans 360 to 830 nm");
}

static void test_media(void)
{
    struct sb_atmosphere_params earth, mars, at;
    sb_atmosphere_preset_earth(&earth);
    sb_atmosphere_preset_mars(&mars);
    /* 300 DU over the tent's 15 km: 300 x 2.687e20 / 15000 molecules per m^3,
     * per km of path: x 1000 */
    double density = sb_ozone_density_fit(&earth), expected = 300.0 * 2.687e20 / 15000.0 * 1000.0;
    printf("ozone: the earth preset fits %.4e molecules a m^3 (300 DU: %.4e)\n", density / 1000, expected / 1000);
    CHECK(fabs(density / expected - 1) < 5e-3, "earth's ozone: %.4e, 300 DU %.4e", density, expected);
    double worst_rayleigh = 0.0, worst_channel = 0.0;
    for (int k = 0; k < SB_SPECTRUM_COUNT; k++) {
        double nm = sb_spectrum_nm(k), um = nm / 1000;
        sb_atmosphere_at_wavelength(&earth, nm, 0, &at);
        /* Bruneton 2017's demo: 1.24062e-6 / lambda^4 per m, lambda in um */
        double closed = 1.24062e-6 / (um * um * um * um) * 1000;
        worst_rayleigh = fmax(worst_rayleigh, fabs(at.rayleigh_scattering_per_km[0] / closed - 1));
        CHECK(at.solar_irradiance[0] > 0.9 && at.ozone_absorption_per_km[0] >= 0, "the sun and ozone at %g nm", nm);
    }
    printf("Rayleigh: earth's within %.2g of lambda^-4 over 360 to 830 nm\n", worst_rayleigh);
    CHECK(worst_rayleigh < 1e-3, "Rayleigh against Bruneton's closed form: %.3g", worst_rayleigh);
    /* every channel at its own wavelength, the ozone's where it fits */
    struct sb_atmosphere_params zero_blue = earth;
    zero_blue.mie_scattering_per_km[2] = 0.0;
    zero_blue.ground_albedo[0] = 0.9;
    const struct sb_atmosphere_params *scenes[] = {&earth, &mars, &zero_blue};
    for (int i = 0; i < 3; i++)
        for (int c = 0; c < 3; c++) {
            const struct sb_atmosphere_params *p = scenes[i];
            sb_atmosphere_at_wavelength(p, sb_channel_nm[c], c, &at);
            const double pairs[4][2] = {
                {at.rayleigh_scattering_per_km[c], p->rayleigh_scattering_per_km[c]},
                {at.mie_scattering_per_km[c], p->mie_scattering_per_km[c]},
                {at.mie_absorption_per_km[c], p->mie_absorption_per_km[c]},
                {at.ground_albedo[c], p->ground_albedo[c]},
            };
            for (int j = 0; j < 4; j++)
                worst_channel = fmax(worst_channel, fabs(pairs[j][0] - pairs[j][1]) / fmax(pairs[j][1], 1e-30));
            if (i == 0)
                CHECK(fabs(at.ozone_absorption_per_km[c] / p->ozone_absorption_per_km[c] - 1) < 5e-3,
                      "earth's ozone at %g nm: %.4e, preset %.4e", sb_channel_nm[c], at.ozone_absorption_per_km[c],
                      p->ozone_absorption_per_km[c]);
        }
    printf("the scenes' channels at their wavelengths: within %.2g\n", worst_channel);
    CHECK(worst_channel < 1e-12, "channels reproduced: %.3g", worst_channel);
    sb_atmosphere_at_wavelength(&zero_blue, 360.0, 1, &at);
    CHECK(at.mie_scattering_per_km[1] >= 0 && at.ground_albedo[1] <= 1.0, "a zero channel: no negative medium");
}

static void test_channels(void)
{
    const double suns[2][3] = {{1, 1, 1}, {1.474, 1.8504, 1.91198}};
    for (int i = 0; i < 2; i++) {
        double m[3][3], out[3];
        sb_channels_to_rec709(suns[i], m);
        sb_mat3_apply(m, suns[i], out);
        double e = fmax(fmax(fabs(out[0] - suns[i][0]), fabs(out[1] - suns[i][1])), fabs(out[2] - suns[i][2]));
        CHECK(e < 1e-12, "the sun (%g, %g, %g) is left as it is: %.3g", suns[i][0], suns[i][1], suns[i][2], e);
        /* the sun's own spectrum through sb_sun_xyz_to_rec709 is the same */
        double white[3], to_rgb[3][3];
        sb_sun_white(white);
        sb_sun_xyz_to_rec709(suns[i], to_rgb);
        sb_mat3_apply(to_rgb, white, out);
        e = fmax(fmax(fabs(out[0] - suns[i][0]), fabs(out[1] - suns[i][1])), fabs(out[2] - suns[i][2]));
        CHECK(e < 1e-12, "the measured sun is the scene's: %.3g", e);
    }
    /* exact on what it assumes: a transfer linear in wavelength between the
     * channels, flat beyond, under the measured sun */
    const double transfer[3] = {0.2, 0.5, 0.9};
    double m[3][3], to_rgb[3][3], s[SB_SPECTRUM_COUNT], xyz[3], direct[3], through[3];
    sb_channels_to_rec709((const double[3]){1, 1, 1}, m);
    sb_sun_xyz_to_rec709((const double[3]){1, 1, 1}, to_rgb);
    for (int k = 0; k < SB_SPECTRUM_COUNT; k++) {
        double nm = sb_spectrum_nm(k), t;
        if (nm <= 440)
            t = transfer[2];
        else if (nm <= 550)
            t = transfer[2] + (nm - 440) / 110 * (transfer[1] - transfer[2]);
        else if (nm <= 680)
            t = transfer[1] + (nm - 550) / 130 * (transfer[0] - transfer[1]);
        else
            t = transfer[0];
        s[k] = sb_solar_spectrum(nm) * t;
    }
    sb_spectrum_to_xyz(s, xyz);
    sb_mat3_apply(to_rgb, xyz, direct);
    sb_mat3_apply(m, transfer, through);
    double e = fmax(fmax(fabs(direct[0] - through[0]), fabs(direct[1] - through[1])), fabs(direct[2] - through[2]));
    printf("three channels to Rec.709: (%.4f %.4f %.4f) (%.4f %.4f %.4f) (%.4f %.4f %.4f); exact on its spectra "
           "within %.2g\n",
           m[0][0], m[0][1], m[0][2], m[1][0], m[1][1], m[1][2], m[2][0], m[2][1], m[2][2], e);
    CHECK(e < 1e-12, "a piecewise linear transfer: %.3g", e);
}

/* The 12 wavelengths' reading (the spectral products' colour): the sun
 * itself, a grey transfer, comes out as the scene's sun; any transfer
 * linear between the 12 and flat beyond comes out as its spectrum shows
 * through the observer, built here on the 10 nm grid directly. */
static void test_twelve(void)
{
    const double sun[3] = {1.474, 1.8504, 1.91198};
    double k[SB_SPECTRAL_WAVELENGTHS][3], L[SB_SPECTRAL_WAVELENGTHS], transfer[SB_SPECTRAL_WAVELENGTHS];
    sb_spectral_to_rec709(sun, k);
    for (int i = 0; i < SB_SPECTRAL_WAVELENGTHS; i++) {
        CHECK(i == 0 || sb_spectral_nm(i) > sb_spectral_nm(i - 1), "the wavelengths ascend");
        transfer[i] = 0.3 + 0.25 * sin(0.9 * i) + 0.02 * i;
    }
    for (int grey = 1; grey >= 0; grey--) {
        double rgb[3] = {0, 0, 0}, want[3], xyz[3], to_rgb[3][3], s[SB_SPECTRUM_COUNT];
        for (int i = 0; i < SB_SPECTRAL_WAVELENGTHS; i++)
            L[i] = sb_solar_spectrum(sb_spectral_nm(i)) * (grey ? 0.7 : transfer[i]);
        for (int i = 0; i < SB_SPECTRAL_WAVELENGTHS; i++)
            for (int c = 0; c < 3; c++)
                rgb[c] += k[i][c] * L[i];
        for (int j = 0; j < SB_SPECTRUM_COUNT; j++) {
            double nm = sb_spectrum_nm(j), t = grey ? 0.7 : transfer[0];
            for (int i = 0; !grey && i < SB_SPECTRAL_WAVELENGTHS; i++)
                if (nm >= sb_spectral_nm(i))
                    t = i + 1 < SB_SPECTRAL_WAVELENGTHS && nm < sb_spectral_nm(i + 1)
                            ? transfer[i] + (nm - sb_spectral_nm(i)) / (sb_spectral_nm(i + 1) - sb_spectral_nm(i)) *
                                                (transfer[i + 1] - transfer[i])
                            : transfer[i];
            s[j] = sb_solar_spectrum(nm) * t;
        }
        sb_spectrum_to_xyz(s, xyz);
        sb_sun_xyz_to_rec709(sun, to_rgb);
        sb_mat3_apply(to_rgb, xyz, want);
        if (grey)
            for (int c = 0; c < 3; c++)
                CHECK(fabs(want[c] - 0.7 * sun[c]) < 1e-12, "a grey transfer on the grid is the sun");
        double e = fmax(fmax(fabs(rgb[0] - want[0]), fabs(rgb[1] - want[1])), fabs(rgb[2] - want[2]));
        printf("12 wavelengths to Rec.709, %s transfer: (%.5f %.5f %.5f), exact within %.2g\n",
               grey ? "a grey" : "a varying", rgb[0], rgb[1], rgb[2], e);
        CHECK(e < 1e-12, "%s transfer through the 12 wavelengths' reading: %.3g", grey ? "a grey" : "a varying", e);
    }
}

int main(void)
{
    test_observer();
    test_media();
    test_channels();
    test_twelve();
    return test_finish("spectrum");
}

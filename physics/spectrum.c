#include "spectrum.h"

#include <math.h>

#include "colour.h"

const double sb_channel_nm[3] = {680.0, 550.0, 440.0};

/*
 * The CIE 1931 2-degree colour matching functions x, y, z at 5 nm from 360
 * to 830 nm (CIE 015:2004, table T.4; transcribed from the Colour & Vision
 * Research Laboratory's ciexyz31.txt, as in Bruneton 2017's constants.h).
 */
static const double cie1931[95][3] = {
    {0.0001299, 3.917e-06, 0.0006061},   /* 360 */
    {0.0002321, 6.965e-06, 0.001086},    /* 365 */
    {0.0004149, 1.239e-05, 0.001946},    /* 370 */
    {0.0007416, 2.202e-05, 0.003486},    /* 375 */
    {0.001368, 3.9e-05, 0.006450001},    /* 380 */
    {0.002236, 6.4e-05, 0.01054999},     /* 385 */
    {0.004243, 0.00012, 0.02005001},     /* 390 */
    {0.00765, 0.000217, 0.03621},        /* 395 */
    {0.01431, 0.000396, 0.06785001},     /* 400 */
    {0.02319, 0.00064, 0.1102},          /* 405 */
    {0.04351, 0.00121, 0.2074},          /* 410 */
    {0.07763, 0.00218, 0.3713},          /* 415 */
    {0.13438, 0.004, 0.6456},            /* 420 */
    {0.21477, 0.0073, 1.0390501},        /* 425 */
    {0.2839, 0.0116, 1.3856},            /* 430 */
    {0.3285, 0.01684, 1.62296},          /* 435 */
    {0.34828, 0.023, 1.74706},           /* 440 */
    {0.34806, 0.0298, 1.7826},           /* 445 */
    {0.3362, 0.038, 1.77211},            /* 450 */
    {0.3187, 0.048, 1.7441},             /* 455 */
    {0.2908, 0.06, 1.6692},              /* 460 */
    {0.2511, 0.0739, 1.5281},            /* 465 */
    {0.19536, 0.09098, 1.28764},         /* 470 */
    {0.1421, 0.1126, 1.0419},            /* 475 */
    {0.09564, 0.13902, 0.8129501},       /* 480 */
    {0.05795001, 0.1693, 0.6162},        /* 485 */
    {0.03201, 0.20802, 0.46518},         /* 490 */
    {0.0147, 0.2586, 0.3533},            /* 495 */
    {0.0049, 0.323, 0.272},              /* 500 */
    {0.0024, 0.4073, 0.2123},            /* 505 */
    {0.0093, 0.503, 0.1582},             /* 510 */
    {0.0291, 0.6082, 0.1117},            /* 515 */
    {0.06327, 0.71, 0.07824999},         /* 520 */
    {0.1096, 0.7932, 0.05725001},        /* 525 */
    {0.1655, 0.862, 0.04216},            /* 530 */
    {0.2257499, 0.9148501, 0.02984},     /* 535 */
    {0.2904, 0.954, 0.0203},             /* 540 */
    {0.3597, 0.9803, 0.0134},            /* 545 */
    {0.4334499, 0.9949501, 0.008749999}, /* 550 */
    {0.5120501, 1, 0.005749999},         /* 555 */
    {0.5945, 0.995, 0.0039},             /* 560 */
    {0.6784, 0.9786, 0.002749999},       /* 565 */
    {0.7621, 0.952, 0.0021},             /* 570 */
    {0.8425, 0.9154, 0.0018},            /* 575 */
    {0.9163, 0.87, 0.001650001},         /* 580 */
    {0.9786, 0.8163, 0.0014},            /* 585 */
    {1.0263, 0.757, 0.0011},             /* 590 */
    {1.0567, 0.6949, 0.001},             /* 595 */
    {1.0622, 0.631, 0.0008},             /* 600 */
    {1.0456, 0.5668, 0.0006},            /* 605 */
    {1.0026, 0.503, 0.00034},            /* 610 */
    {0.9384, 0.4412, 0.00024},           /* 615 */
    {0.8544499, 0.381, 0.00019},         /* 620 */
    {0.7514, 0.321, 0.0001},             /* 625 */
    {0.6424, 0.265, 4.999999e-05},       /* 630 */
    {0.5419, 0.217, 3e-05},              /* 635 */
    {0.4479, 0.175, 2e-05},              /* 640 */
    {0.3608, 0.1382, 1e-05},             /* 645 */
    {0.2835, 0.107, 0},                  /* 650 */
    {0.2187, 0.0816, 0},                 /* 655 */
    {0.1649, 0.061, 0},                  /* 660 */
    {0.1212, 0.04458, 0},                /* 665 */
    {0.0874, 0.032, 0},                  /* 670 */
    {0.0636, 0.0232, 0},                 /* 675 */
    {0.04677, 0.017, 0},                 /* 680 */
    {0.0329, 0.01192, 0},                /* 685 */
    {0.0227, 0.00821, 0},                /* 690 */
    {0.01584, 0.005723, 0},              /* 695 */
    {0.01135916, 0.004102, 0},           /* 700 */
    {0.008110916, 0.002929, 0},          /* 705 */
    {0.005790346, 0.002091, 0},          /* 710 */
    {0.004109457, 0.001484, 0},          /* 715 */
    {0.002899327, 0.001047, 0},          /* 720 */
    {0.00204919, 0.00074, 0},            /* 725 */
    {0.001439971, 0.00052, 0},           /* 730 */
    {0.0009999493, 0.0003611, 0},        /* 735 */
    {0.0006900786, 0.0002492, 0},        /* 740 */
    {0.0004760213, 0.0001719, 0},        /* 745 */
    {0.0003323011, 0.00012, 0},          /* 750 */
    {0.0002348261, 8.48e-05, 0},         /* 755 */
    {0.0001661505, 6e-05, 0},            /* 760 */
    {0.000117413, 4.24e-05, 0},          /* 765 */
    {8.307527e-05, 3e-05, 0},            /* 770 */
    {5.870652e-05, 2.12e-05, 0},         /* 775 */
    {4.150994e-05, 1.499e-05, 0},        /* 780 */
    {2.935326e-05, 1.06e-05, 0},         /* 785 */
    {2.067383e-05, 7.4657e-06, 0},       /* 790 */
    {1.455977e-05, 5.2578e-06, 0},       /* 795 */
    {1.025398e-05, 3.7029e-06, 0},       /* 800 */
    {7.221456e-06, 2.6078e-06, 0},       /* 805 */
    {5.085868e-06, 1.8366e-06, 0},       /* 810 */
    {3.581652e-06, 1.2934e-06, 0},       /* 815 */
    {2.522525e-06, 9.1093e-07, 0},       /* 820 */
    {1.776509e-06, 6.4153e-07, 0},       /* 825 */
    {1.251141e-06, 4.5181e-07, 0},       /* 830 */
};

/*
 * The sun's spectral irradiance above the atmosphere, W m^-2 nm^-1: ASTM
 * G-173-03's extraterrestrial column averaged over each 10 nm bin from the
 * wavelength named (Bruneton 2017's demo.cc, kSolarIrradiance).
 */
static const double solar[SB_SPECTRUM_COUNT] = {
    1.11776, 1.14259, 1.01249, 1.14716, 1.72765, 1.73054, 1.6887,  1.61253, 1.91198, 2.03474, 2.02042, 2.02212,
    1.93377, 1.95809, 1.91686, 1.8298,  1.8685,  1.8931,  1.85149, 1.8504,  1.8341,  1.8345,  1.8147,  1.78158,
    1.7533,  1.6965,  1.68194, 1.64654, 1.6048,  1.52143, 1.55622, 1.5113,  1.474,   1.4482,  1.41018, 1.36775,
    1.34188, 1.31429, 1.28303, 1.26758, 1.2367,  1.2082,  1.18737, 1.14683, 1.12362, 1.1058,  1.07124, 1.04992,
};

/*
 * Ozone's absorption cross-section, m^2 a molecule, at 233 K (Serdyuchenko,
 * Gorshelev, Weber, Chehade and Burrows 2014, the University of Bremen's
 * o3spectra2011), averaged over each 10 nm bin from the wavelength named
 * (Bruneton 2017's demo.cc, kOzoneCrossSection). Times 300 Dobson units
 * over the tent's 15 km it gives the earth preset's three channels.
 */
static const double ozone[SB_SPECTRUM_COUNT] = {
    1.18e-27,  2.182e-28, 2.818e-28, 6.636e-28, 1.527e-27, 2.763e-27, 5.52e-27,  8.451e-27, 1.582e-26, 2.316e-26,
    3.669e-26, 4.924e-26, 7.752e-26, 9.016e-26, 1.48e-25,  1.602e-25, 2.139e-25, 2.755e-25, 3.091e-25, 3.5e-25,
    4.266e-25, 4.672e-25, 4.398e-25, 4.701e-25, 5.019e-25, 4.305e-25, 3.74e-25,  3.215e-25, 2.662e-25, 2.238e-25,
    1.852e-25, 1.473e-25, 1.209e-25, 9.423e-26, 7.455e-26, 6.566e-26, 5.105e-26, 4.15e-26,  4.228e-26, 3.237e-26,
    2.451e-26, 2.801e-26, 2.534e-26, 1.624e-26, 1.465e-26, 2.078e-26, 1.383e-26, 7.105e-27,
};

double sb_spectrum_nm(int k)
{
    return SB_SPECTRUM_FIRST_NM + SB_SPECTRUM_STEP_NM * k;
}

/* A table of `count` rows `step` nm apart from `first`, linear between
 * rows, 0 outside. */
static double table_at(const double *table, int stride, int count, double first, double step, double nm)
{
    double u = (nm - first) / step;
    if (!(u >= 0.0) || u > count - 1)
        return 0.0;
    int i = u >= count - 1 ? count - 2 : (int)u;
    double f = u - i;
    return table[i * stride] * (1.0 - f) + table[(i + 1) * stride] * f;
}

void sb_cie1931_xyz(double nm, double xyz[3])
{
    for (int c = 0; c < 3; c++)
        xyz[c] = table_at(&cie1931[0][c], 3, 95, 360.0, 5.0, nm);
}

double sb_solar_spectrum(double nm)
{
    return table_at(solar, 1, SB_SPECTRUM_COUNT, SB_SPECTRUM_FIRST_NM, SB_SPECTRUM_STEP_NM, nm);
}

double sb_ozone_cross_section(double nm)
{
    return table_at(ozone, 1, SB_SPECTRUM_COUNT, SB_SPECTRUM_FIRST_NM, SB_SPECTRUM_STEP_NM, nm);
}

void sb_spectrum_to_xyz(const double spectrum[SB_SPECTRUM_COUNT], double xyz[3])
{
    xyz[0] = xyz[1] = xyz[2] = 0.0;
    for (int k = 0; k < SB_SPECTRUM_COUNT; k++) {
        double cmf[3];
        sb_cie1931_xyz(sb_spectrum_nm(k), cmf);
        for (int c = 0; c < 3; c++)
            xyz[c] += SB_SPECTRUM_STEP_NM * cmf[c] * spectrum[k];
    }
}

/* The channels by wavelength: blue (440 nm), green (550), red (680). */
static const int by_nm[3] = {2, 1, 0};

/* Channel values at their wavelengths, ascending; the segment nm falls in
 * (the first below the middle, the second above, each extended). */
static int channel_samples(const double v[3], double nm, double x[3], double y[3])
{
    for (int i = 0; i < 3; i++) {
        x[i] = sb_channel_nm[by_nm[i]];
        y[i] = v[by_nm[i]];
    }
    return nm < x[1] ? 0 : 1;
}

/* Linear in wavelength between the three channels, flat beyond them. */
static double linear_at(const double v[3], double nm)
{
    double x[3], y[3];
    int s = channel_samples(v, nm, x, y);
    double f = fmin(fmax((nm - x[s]) / (x[s + 1] - x[s]), 0.0), 1.0);
    return y[s] + f * (y[s + 1] - y[s]);
}

/* A power law in wavelength through each pair of neighbouring channels (log
 * against log), the end pairs' beyond them: Rayleigh's lambda^-4 and
 * Angstrom's law for aerosols come out exactly. Linear where a channel is 0. */
static double power_law_at(const double v[3], double nm)
{
    double x[3], y[3];
    int s = channel_samples(v, nm, x, y);
    if (!(y[0] > 0.0 && y[1] > 0.0 && y[2] > 0.0))
        return fmax(linear_at(v, nm), 0.0);
    double slope = log(y[s + 1] / y[s]) / log(x[s + 1] / x[s]);
    return y[s] * pow(nm / x[s], slope);
}

double sb_ozone_density_fit(const struct sb_atmosphere_params *p)
{
    double num = 0.0, den = 0.0;
    for (int c = 0; c < 3; c++) {
        double sigma = sb_ozone_cross_section(sb_channel_nm[c]);
        num += p->ozone_absorption_per_km[c] * sigma;
        den += sigma * sigma;
    }
    return den > 0.0 ? num / den : 0.0;
}

void sb_atmosphere_at_wavelength(const struct sb_atmosphere_params *p, double nm, int c,
                                 struct sb_atmosphere_params *out)
{
    out->rayleigh_scattering_per_km[c] = power_law_at(p->rayleigh_scattering_per_km, nm);
    out->mie_scattering_per_km[c] = power_law_at(p->mie_scattering_per_km, nm);
    out->mie_absorption_per_km[c] = power_law_at(p->mie_absorption_per_km, nm);
    out->ozone_absorption_per_km[c] = sb_ozone_density_fit(p) * sb_ozone_cross_section(nm);
    out->ground_albedo[c] = fmin(fmax(linear_at(p->ground_albedo, nm), 0.0), 1.0);
    out->solar_irradiance[c] = sb_solar_spectrum(nm);
}

void sb_sun_white(double xyz[3])
{
    double s[SB_SPECTRUM_COUNT];
    for (int k = 0; k < SB_SPECTRUM_COUNT; k++)
        s[k] = sb_solar_spectrum(sb_spectrum_nm(k));
    sb_spectrum_to_xyz(s, xyz);
}

void sb_sun_xyz_to_rec709(const double solar_rgb[3], double m[3][3])
{
    static const double rec709[4][2] = {SB_REC709_PRIMARIES};
    double white[3], xy[2], cat[3][3], to_xyz[3][3], from_xyz[3][3];
    sb_sun_white(white);
    double sum = white[0] + white[1] + white[2];
    xy[0] = white[0] / sum;
    xy[1] = white[1] / sum;
    sb_bradford(xy, rec709[3], cat);
    sb_rec709_to_xyz(to_xyz);
    sb_mat3_invert(to_xyz, from_xyz);
    sb_mat3_mul(from_xyz, cat, m);
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            m[r][c] *= solar_rgb[r] / white[1];
}

void sb_channels_to_rec709(const double solar_rgb[3], double m[3][3])
{
    /* XYZ of each channel's hat function under the sun: the spectrum that
     * linear_at makes of the three channels, integrated channel by channel */
    double hats[3][3] = {{0}};
    for (int k = 0; k < SB_SPECTRUM_COUNT; k++) {
        double nm = sb_spectrum_nm(k), cmf[3];
        sb_cie1931_xyz(nm, cmf);
        for (int c = 0; c < 3; c++) {
            double unit[3] = {0, 0, 0};
            unit[c] = 1.0;
            double w = SB_SPECTRUM_STEP_NM * sb_solar_spectrum(nm) * linear_at(unit, nm);
            for (int r = 0; r < 3; r++)
                hats[r][c] += cmf[r] * w;
        }
    }
    double to_rgb[3][3];
    sb_sun_xyz_to_rec709((const double[3]){1, 1, 1}, to_rgb);
    sb_mat3_mul(to_rgb, hats, m);
    /* the scene's sun: its channel c carries solar_rgb[c] times the transfer */
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            m[r][c] *= solar_rgb[c] > 0.0 ? solar_rgb[r] / solar_rgb[c] : 0.0;
}

/* Dense (20 nm) where the observer's functions and the twilight's spectrum
 * (ozone's Chappuis band) change most, 30 to 40 nm at the ends: chosen by
 * measurement (tests/test_wavelengths.c). */
static const double spectral_nm[SB_SPECTRAL_WAVELENGTHS] = {400, 430, 460, 480, 500, 520, 540, 560, 580, 600, 630, 670};

double sb_spectral_nm(int i)
{
    return spectral_nm[i];
}

void sb_spectral_band(const struct sb_atmosphere_params *p, int band, struct sb_atmosphere_params *out)
{
    *out = *p;
    for (int c = 0; c < 3; c++)
        sb_atmosphere_at_wavelength(p, sb_spectral_nm(3 * band + c), c, out);
}

void sb_samples_to_xyz(const double *radiance, const double *nm, int n, double xyz[3])
{
    double spectrum[SB_SPECTRUM_COUNT];
    for (int k = 0, j = 0; k < SB_SPECTRUM_COUNT; k++) {
        double at = sb_spectrum_nm(k);
        while (j + 2 < n && nm[j + 1] <= at)
            j++;
        double f = fmin(fmax((at - nm[j]) / (nm[j + 1] - nm[j]), 0.0), 1.0);
        double lo = radiance[j] / sb_solar_spectrum(nm[j]), hi = radiance[j + 1] / sb_solar_spectrum(nm[j + 1]);
        spectrum[k] = (lo + f * (hi - lo)) * sb_solar_spectrum(at);
    }
    sb_spectrum_to_xyz(spectrum, xyz);
}

void sb_spectral_to_rec709(const double solar_rgb[3], double k[SB_SPECTRAL_WAVELENGTHS][3])
{
    double nm[SB_SPECTRAL_WAVELENGTHS], to_rgb[3][3];
    for (int i = 0; i < SB_SPECTRAL_WAVELENGTHS; i++)
        nm[i] = sb_spectral_nm(i);
    sb_sun_xyz_to_rec709(solar_rgb, to_rgb);
    for (int i = 0; i < SB_SPECTRAL_WAVELENGTHS; i++) {
        double unit[SB_SPECTRAL_WAVELENGTHS] = {0}, xyz[3];
        unit[i] = 1.0;
        sb_samples_to_xyz(unit, nm, SB_SPECTRAL_WAVELENGTHS, xyz);
        sb_mat3_apply(to_rgb, xyz, k[i]);
    }
}

enum sb_result sb_spectral_band_image(const struct sb_image *spectral, enum sb_product_id base, int b,
                                      struct sb_image *band)
{
    uint32_t channels = sb_product_format(base)->channel_count, texels = spectral->width * spectral->height;
    if (spectral->channel_count != channels * SB_SPECTRAL_BANDS || b < 0 || b >= SB_SPECTRAL_BANDS)
        return SB_ERR_USAGE;
    enum sb_result res = sb_image_init(band, spectral->width, spectral->height, channels);
    if (res)
        return res;
    sb_image_set_channel_names(band, sb_product_format(base)->channel_names);
    for (uint32_t t = 0; t < texels; t++)
        for (uint32_t ch = 0; ch < channels; ch++)
            band->data[(size_t)t * channels + ch] =
                spectral->data[(size_t)t * spectral->channel_count + sb_spectral_channel(ch, b)];
    return SB_OK;
}

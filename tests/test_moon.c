/*
 * The moon of skyview's nights (runtime/moon.c) against published values:
 * Meeus's worked examples 47.a (the moon's apparent place), 48.a (its
 * illuminated fraction) and 12.a/12.b (sidereal time); the topocentric
 * place against two total solar eclipses, where the moon covers the sun
 * (the sun from runtime/sun_path.c, an independent series): seen from the
 * earth's centre the two are a degree apart there, so the parallax is what
 * the test checks; the magnitude law's full and quarter moons. No Vulkan.
 */
#include <math.h>

#include "harness.h"
#include "moon.h"
#include "sun_path.h"

#define DEG (M_PI / 180.0)

/* The bound for the moon's place against a published ephemeris. */
#define MOON_TOLERANCE_DEG 0.1

static double angle_diff_deg(double a, double b)
{
    double d = fmod(fabs(a - b), 2.0 * M_PI);
    return fmin(d, 2.0 * M_PI - d) / DEG;
}

static void direction(double elevation, double azimuth, double out[3])
{
    out[0] = cos(elevation) * sin(azimuth);
    out[1] = sin(elevation);
    out[2] = -cos(elevation) * cos(azimuth);
}

static double separation_deg(const double a[3], const double b[3])
{
    double c = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    double x[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    return atan2(sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]), c) / DEG;
}

static void test_meeus(void)
{
    /* 47.a: 1992 April 12, 0h TD. Apparent longitude 133.167265, latitude
     * -3.229126, distance 368409.7 km, right ascension 134.688470,
     * declination 13.768368 degrees. The series is Meeus's own; what
     * differs is the nutation's shorter series (0.5" at most). */
    struct sb_moon_position m;
    sb_moon_geocentric(2448724.5, &m);
    printf("47.a: longitude %.6f (133.167265), latitude %.6f (-3.229126), distance %.1f km (368409.7), "
           "right ascension %.6f (134.688470), declination %.6f (13.768368)\n",
           m.longitude / DEG, m.latitude / DEG, m.distance_km, m.right_ascension / DEG, m.declination / DEG);
    const double tight = 2.0 / 3600.0; /* 2": the short nutation's bound, with room for rounding */
    CHECK(angle_diff_deg(m.longitude, 133.167265 * DEG) < tight, "longitude %.6f", m.longitude / DEG);
    CHECK(fabs(m.latitude / DEG + 3.229126) < tight, "latitude %.6f", m.latitude / DEG);
    CHECK(fabs(m.distance_km - 368409.7) < 0.1, "distance %.2f km", m.distance_km);
    CHECK(angle_diff_deg(m.right_ascension, 134.688470 * DEG) < tight, "right ascension %.6f", m.right_ascension / DEG);
    CHECK(fabs(m.declination / DEG - 13.768368) < tight, "declination %.6f", m.declination / DEG);
    CHECK(tight < MOON_TOLERANCE_DEG, "the issue's bound is the looser");

    /* 12.a and 12.b: 1987 April 10 at 0h UT, 13h10m46.3668s; at 19h21m00s
     * UT, 8h34m57.0896s (mean sidereal time at Greenwich). */
    double s0 = sb_sidereal_time(sb_julian_day(1987, 4, 10, 0.0)) / DEG;
    double s1 = sb_sidereal_time(sb_julian_day(1987, 4, 10, 19.35)) / DEG;
    double e0 = (13.0 + 10.0 / 60.0 + 46.3668 / 3600.0) * 15.0, e1 = (8.0 + 34.0 / 60.0 + 57.0896 / 3600.0) * 15.0;
    printf("12.a/b: sidereal time %.6f (%.6f), %.6f (%.6f) degrees\n", s0, e0, s1, e1);
    /* 1e-4 degrees is 0.024 s of time: Meeus's values are to 1e-4 s, the
     * rest is the double's rounding of a Julian day (4e-5 s). */
    CHECK(fabs(s0 - e0) < 1e-4 && fabs(s1 - e1) < 1e-4, "sidereal times %.6f, %.6f", s0, s1);

    /* 48.a: the same instant, illuminated fraction 0.6786 (phase angle
     * 69.0756 degrees). sb_moon_position takes UT: 0h TD less delta T. */
    sb_moon_position(0.0, 0.0, 1992, 4, 12, -69.0 / 3600.0, &m);
    printf("48.a: illuminated fraction %.4f (0.6786), phase angle %.4f (69.0756)\n", m.illuminated_fraction,
           m.phase_angle / DEG);
    CHECK(fabs(m.illuminated_fraction - 0.6786) < 5e-4, "fraction %.5f", m.illuminated_fraction);
    CHECK(fabs(m.phase_angle / DEG - 69.0756) < 0.02, "phase angle %.4f", m.phase_angle / DEG);
}

static void test_eclipses(void)
{
    /* Greatest eclipse, where the axis of the moon's shadow meets the
     * earth: the centres of the sun and the moon line up there (NASA's
     * eclipse bulletins, Espenak). 2017 August 21, 18:25:32 TD at
     * 36 58.0' N, 87 40.3' W; 2024 April 8, 18:17:16 TD at 25 17.4' N,
     * 104 08.3' W. TD - UT was 69 s. */
    static const struct {
        int year, month, day;
        double hours, latitude, longitude;
    } eclipses[2] = {
        {2017, 8, 21, 18.0 + 25.0 / 60.0 + (32.0 - 69.0) / 3600.0, 36.0 + 58.0 / 60.0, -(87.0 + 40.3 / 60.0)},
        {2024, 4, 8, 18.0 + 17.0 / 60.0 + (16.0 - 69.0) / 3600.0, 25.0 + 17.4 / 60.0, -(104.0 + 8.3 / 60.0)},
    };
    for (int i = 0; i < 2; i++) {
        struct sb_moon_position m;
        struct sb_sun_position s;
        sb_moon_position(eclipses[i].latitude, eclipses[i].longitude, eclipses[i].year, eclipses[i].month,
                         eclipses[i].day, eclipses[i].hours, &m);
        sb_sun_position(eclipses[i].latitude, eclipses[i].longitude, eclipses[i].year, eclipses[i].month,
                        eclipses[i].day, eclipses[i].hours, &s);
        double dm[3], ds[3];
        direction(m.elevation, m.azimuth, dm);
        direction(s.elevation, s.azimuth, ds);
        double apart = separation_deg(dm, ds);
        printf("%d-%02d-%02d: the moon %.4f degrees from the sun (radii %.4f and 0.267), phase angle %.2f, "
               "moon elevation %.3f\n",
               eclipses[i].year, eclipses[i].month, eclipses[i].day, apart, m.angular_radius / DEG, m.phase_angle / DEG,
               m.elevation / DEG);
        /* Totality: the moon's disk covers the sun's (its radius is the larger by 0.01 degrees). */
        CHECK(apart < 0.05, "%d: the centres %.4f degrees apart", eclipses[i].year, apart);
        CHECK(m.angular_radius / DEG > 0.267, "%d: the moon's radius %.4f does not cover the sun's", eclipses[i].year,
              m.angular_radius / DEG);
        CHECK(m.illuminated_fraction < 1e-3, "%d: fraction %.5f at a new moon", eclipses[i].year,
              m.illuminated_fraction);
    }
}

static void test_brightness(void)
{
    /* Full moon: -12.73 against -26.74, 2.5e-6; about 0.3 lux under the
     * earth's 128 klx sun. Quarter: 2.6 magnitudes fainter, a tenth. */
    double full = sb_moon_irradiance_ratio(0.0, 384400.0), quarter = sb_moon_irradiance_ratio(M_PI / 2.0, 384400.0);
    printf("irradiance over the sun's: full %.3e (%.3f lux), quarter %.3e (%.3f of full)\n", full, full * 128000.0,
           quarter, quarter / full);
    CHECK(fabs(full / pow(10.0, -0.4 * 14.01) - 1.0) < 1e-12, "full moon %.4e", full);
    CHECK(fabs(quarter / full - pow(10.0, -0.4 * (0.026 * 90.0 + 4e-9 * pow(90.0, 4.0)))) < 1e-12, "quarter %.4e",
          quarter / full);
    /* Nearer, brighter by the square of the distance. */
    double near = sb_moon_irradiance_ratio(0.0, 356500.0);
    CHECK(fabs(near / full - pow(384400.0 / 356500.0, 2.0)) < 1e-12, "perigee %.4f", near / full);
    /* The colour's luminance is 1 (the magnitudes are visual). */
    double y = 0.2126 * SB_MOON_COLOR_R + 0.7152 * SB_MOON_COLOR_G + 0.0722 * SB_MOON_COLOR_B;
    CHECK(fabs(y - 1.0) < 2e-3, "moonlight's colour has luminance %.4f", y);
}

int main(void)
{
    test_meeus();
    test_eclipses();
    test_brightness();
    return test_finish("moon");
}

#include "moon.h"

#include <math.h>
#include <stdlib.h>

#include "sun_path.h"

#define DEG (M_PI / 180.0)
#define ARCSEC (DEG / 3600.0)

/* The terms of Meeus's tables 47.A (longitude, 1e-6 degrees, and distance,
 * 1e-3 km: sine and cosine of the argument) and 47.B (latitude, 1e-6
 * degrees), by the multiples of D, M, M' and F in their argument. */
struct lunar_term {
    signed char d, m, mp, f;
    int a, b;
};

static const struct lunar_term longitude_distance[60] = {
    {0, 0, 1, 0, 6288774, -20905355},
    {2, 0, -1, 0, 1274027, -3699111},
    {2, 0, 0, 0, 658314, -2955968},
    {0, 0, 2, 0, 213618, -569925},
    {0, 1, 0, 0, -185116, 48888},
    {0, 0, 0, 2, -114332, -3149},
    {2, 0, -2, 0, 58793, 246158},
    {2, -1, -1, 0, 57066, -152138},
    {2, 0, 1, 0, 53322, -170733},
    {2, -1, 0, 0, 45758, -204586},
    {0, 1, -1, 0, -40923, -129620},
    {1, 0, 0, 0, -34720, 108743},
    {0, 1, 1, 0, -30383, 104755},
    {2, 0, 0, -2, 15327, 10321},
    {0, 0, 1, 2, -12528, 0},
    {0, 0, 1, -2, 10980, 79661},
    {4, 0, -1, 0, 10675, -34782},
    {0, 0, 3, 0, 10034, -23210},
    {4, 0, -2, 0, 8548, -21636},
    {2, 1, -1, 0, -7888, 24208},
    {2, 1, 0, 0, -6766, 30824},
    {1, 0, -1, 0, -5163, -8379},
    {1, 1, 0, 0, 4987, -16675},
    {2, -1, 1, 0, 4036, -12831},
    {2, 0, 2, 0, 3994, -10445},
    {4, 0, 0, 0, 3861, -11650},
    {2, 0, -3, 0, 3665, 14403},
    {0, 1, -2, 0, -2689, -7003},
    {2, 0, -1, 2, -2602, 0},
    {2, -1, -2, 0, 2390, 10056},
    {1, 0, 1, 0, -2348, 6322},
    {2, -2, 0, 0, 2236, -9884},
    {0, 1, 2, 0, -2120, 5751},
    {0, 2, 0, 0, -2069, 0},
    {2, -2, -1, 0, 2048, -4950},
    {2, 0, 1, -2, -1773, 4130},
    {2, 0, 0, 2, -1595, 0},
    {4, -1, -1, 0, 1215, -3958},
    {0, 0, 2, 2, -1110, 0},
    {3, 0, -1, 0, -892, 3258},
    {2, 1, 1, 0, -810, 2616},
    {4, -1, -2, 0, 759, -1897},
    {0, 2, -1, 0, -713, -2117},
    {2, 2, -1, 0, -700, 2354},
    {2, 1, -2, 0, 691, 0},
    {2, -1, 0, -2, 596, 0},
    {4, 0, 1, 0, 549, -1423},
    {0, 0, 4, 0, 537, -1117},
    {4, -1, 0, 0, 520, -1571},
    {1, 0, -2, 0, -487, -1739},
    {2, 1, 0, -2, -399, 0},
    {0, 0, 2, -2, -381, -4421},
    {1, 1, 1, 0, 351, 0},
    {3, 0, -2, 0, -340, 0},
    {4, 0, -3, 0, 330, 0},
    {2, -1, 2, 0, 327, 0},
    {0, 2, 1, 0, -323, 1165},
    {1, 1, -1, 0, 299, 0},
    {2, 0, 3, 0, 294, 0},
    {2, 0, -1, -2, 0, 8752},
};

static const struct lunar_term latitude[60] = {
    {0, 0, 0, 1, 5128122, 0}, {0, 0, 1, 1, 280602, 0},  {0, 0, 1, -1, 277693, 0}, {2, 0, 0, -1, 173237, 0},
    {2, 0, -1, 1, 55413, 0},  {2, 0, -1, -1, 46271, 0}, {2, 0, 0, 1, 32573, 0},   {0, 0, 2, 1, 17198, 0},
    {2, 0, 1, -1, 9266, 0},   {0, 0, 2, -1, 8822, 0},   {2, -1, 0, -1, 8216, 0},  {2, 0, -2, -1, 4324, 0},
    {2, 0, 1, 1, 4200, 0},    {2, 1, 0, -1, -3359, 0},  {2, -1, -1, 1, 2463, 0},  {2, -1, 0, 1, 2211, 0},
    {2, -1, -1, -1, 2065, 0}, {0, 1, -1, -1, -1870, 0}, {4, 0, -1, -1, 1828, 0},  {0, 1, 0, 1, -1794, 0},
    {0, 0, 0, 3, -1749, 0},   {0, 1, -1, 1, -1565, 0},  {1, 0, 0, 1, -1491, 0},   {0, 1, 1, 1, -1475, 0},
    {0, 1, 1, -1, -1410, 0},  {0, 1, 0, -1, -1344, 0},  {1, 0, 0, -1, -1335, 0},  {0, 0, 3, 1, 1107, 0},
    {4, 0, 0, -1, 1021, 0},   {4, 0, -1, 1, 833, 0},    {0, 0, 1, -3, 777, 0},    {4, 0, -2, 1, 671, 0},
    {2, 0, 0, -3, 607, 0},    {2, 0, 2, -1, 596, 0},    {2, -1, 1, -1, 491, 0},   {2, 0, -2, 1, -451, 0},
    {0, 0, 3, -1, 439, 0},    {2, 0, 2, 1, 422, 0},     {2, 0, -3, -1, 421, 0},   {2, 1, -1, 1, -366, 0},
    {2, 1, 0, 1, -351, 0},    {4, 0, 0, 1, 331, 0},     {2, -1, 1, 1, 315, 0},    {2, -2, 0, -1, 302, 0},
    {0, 0, 1, 3, -283, 0},    {2, 1, 1, -1, -229, 0},   {1, 1, 0, -1, 223, 0},    {1, 1, 0, 1, 223, 0},
    {0, 1, -2, -1, -220, 0},  {2, 1, -1, -1, -220, 0},  {1, 0, 1, 1, -185, 0},    {2, -1, -2, -1, 181, 0},
    {0, 1, 2, 1, -177, 0},    {4, 0, -2, -1, 176, 0},   {4, -1, -1, -1, 166, 0},  {1, 0, 1, -1, -164, 0},
    {4, 0, 1, -1, 132, 0},    {1, 0, -1, -1, -119, 0},  {4, -1, 0, -1, 115, 0},   {2, -2, 0, 1, 107, 0},
};

static double wrap(double x)
{
    return x - 2.0 * M_PI * floor(x / (2.0 * M_PI));
}

/* Nutation in longitude and obliquity's (radians) and the mean obliquity
 * (Meeus, ch. 22: the terms above 0.05", within 0.5" of the full series). */
static void nutation(double t, double *dpsi, double *deps, double *eps0)
{
    double omega = (125.04452 - 1934.136261 * t) * DEG;
    double l = (280.4665 + 36000.7698 * t) * DEG, lp = (218.3165 + 481267.8813 * t) * DEG;
    *dpsi = (-17.20 * sin(omega) - 1.32 * sin(2.0 * l) - 0.23 * sin(2.0 * lp) + 0.21 * sin(2.0 * omega)) * ARCSEC;
    *deps = (9.20 * cos(omega) + 0.57 * cos(2.0 * l) + 0.10 * cos(2.0 * lp) - 0.09 * cos(2.0 * omega)) * ARCSEC;
    *eps0 = 23.0 * DEG + 26.0 * DEG / 60.0 + (21.448 - t * (46.8150 + t * (0.00059 - t * 0.001813))) * ARCSEC;
}

void sb_moon_geocentric(double jde, struct sb_moon_position *out)
{
    double t = (jde - 2451545.0) / 36525.0;
    /* The mean elements (Meeus, 47.1 to 47.5), degrees. */
    double lp = 218.3164477 + t * (481267.88123421 + t * (-0.0015786 + t * (1.0 / 538841.0 - t / 65194000.0)));
    double d = 297.8501921 + t * (445267.1114034 + t * (-0.0018819 + t * (1.0 / 545868.0 - t / 113065000.0)));
    double m = 357.5291092 + t * (35999.0502909 + t * (-0.0001536 + t / 24490000.0));
    double mp = 134.9633964 + t * (477198.8675055 + t * (0.0087414 + t * (1.0 / 69699.0 - t / 14712000.0)));
    double f = 93.2720950 + t * (483202.0175233 + t * (-0.0036539 + t * (-1.0 / 3526000.0 + t / 863310000.0)));
    double a1 = (119.75 + 131.849 * t) * DEG, a2 = (53.09 + 479264.290 * t) * DEG, a3 = (313.45 + 481266.484 * t) * DEG;
    /* The earth's orbit's eccentricity shrinks the terms in M. */
    double e = 1.0 - t * (0.002516 + t * 0.0000074);
    double scale[3] = {1.0, e, e * e};
    lp *= DEG;
    d *= DEG;
    m *= DEG;
    mp *= DEG;
    f *= DEG;

    double sl = 0.0, sr = 0.0, sb = 0.0;
    for (int i = 0; i < 60; i++) {
        const struct lunar_term *k = &longitude_distance[i];
        double arg = k->d * d + k->m * m + k->mp * mp + k->f * f, s = scale[abs(k->m)];
        sl += s * k->a * sin(arg);
        sr += s * k->b * cos(arg);
        k = &latitude[i];
        arg = k->d * d + k->m * m + k->mp * mp + k->f * f;
        sb += scale[abs(k->m)] * k->a * sin(arg);
    }
    /* Venus's and Jupiter's actions and the earth's flattening. */
    sl += 3958.0 * sin(a1) + 1962.0 * sin(lp - f) + 318.0 * sin(a2);
    sb += -2235.0 * sin(lp) + 382.0 * sin(a3) + 175.0 * sin(a1 - f) + 175.0 * sin(a1 + f) + 127.0 * sin(lp - mp) -
          115.0 * sin(lp + mp);

    double dpsi, deps, eps0;
    nutation(t, &dpsi, &deps, &eps0);
    double lambda = wrap(lp + sl * 1e-6 * DEG + dpsi), beta = sb * 1e-6 * DEG, eps = eps0 + deps;
    out->longitude = lambda;
    out->latitude = beta;
    out->distance_km = 385000.56 + sr * 1e-3;
    out->right_ascension = wrap(atan2(sin(lambda) * cos(eps) - tan(beta) * sin(eps), cos(lambda)));
    out->declination = asin(sin(beta) * cos(eps) + cos(beta) * sin(eps) * sin(lambda));
}

bool sb_moon_path_at(const struct sb_sun_path *path, double hour, struct sb_moon_position *out)
{
    if (path->key_count >= 2)
        return false;
    int year, month, day;
    double offset;
    sb_sun_path_date(path, &year, &month, &day, &offset);
    sb_moon_position(path->latitude_deg, path->longitude_deg, year, month, day, hour - offset, out);
    return true;
}

double sb_sidereal_time(double jd)
{
    double t = (jd - 2451545.0) / 36525.0;
    return wrap((280.46061837 + 360.98564736629 * (jd - 2451545.0) + t * t * (0.000387933 - t / 38710000.0)) * DEG);
}

double sb_moon_irradiance_ratio(double phase_angle, double distance_km)
{
    double a = fabs(phase_angle) / DEG;
    double magnitude = -12.73 + 0.026 * a + 4e-9 * a * a * a * a;
    double mean = 384400.0 / distance_km;
    return pow(10.0, -0.4 * (magnitude + 26.74)) * mean * mean;
}

/* Terrestrial time runs ahead of UT by delta T: 69 s in the 2020s, 14 s
 * in 1800, near 200 s by 2100 as extrapolated. The constant is within two
 * minutes of it from 1800 to 2100: 0.02 degrees of the moon's motion. */
#define DELTA_T_S 69.0
#define EARTH_RADIUS_KM 6378.14

void sb_moon_position(double latitude_deg, double longitude_deg, int year, int month, int day, double utc_hours,
                      struct sb_moon_position *out)
{
    double jd = sb_julian_day(year, month, day, utc_hours);
    sb_moon_geocentric(jd + DELTA_T_S / 86400.0, out);

    /* The local hour angle from apparent sidereal time. */
    double t = (jd - 2451545.0) / 36525.0, dpsi, deps, eps0;
    nutation(t, &dpsi, &deps, &eps0);
    double hour_angle = sb_sidereal_time(jd) + dpsi * cos(eps0 + deps) + longitude_deg * DEG - out->right_ascension;
    /* The geocentric moon in the place's horizon frame (east, north, up),
     * less the place's own offset from the centre (a spherical earth: the
     * flattening moves the moon by under 0.01 degrees). */
    double phi = latitude_deg * DEG, dec = out->declination, dist = out->distance_km;
    double east = -dist * cos(dec) * sin(hour_angle);
    double north = dist * (sin(dec) * cos(phi) - cos(dec) * cos(hour_angle) * sin(phi));
    double up = dist * (sin(phi) * sin(dec) + cos(phi) * cos(dec) * cos(hour_angle)) - EARTH_RADIUS_KM;
    double topocentric = sqrt(east * east + north * north + up * up);
    out->elevation = atan2(up, hypot(east, north));
    out->azimuth = wrap(atan2(east, north));
    out->angular_radius = asin(SB_MOON_RADIUS_KM / topocentric);

    /* The phase from the elongation of the moon from the sun (Meeus, 48.2
     * and 48.3; the sun's latitude is below 1.2"). */
    struct sb_sun_position sun;
    sb_sun_position(latitude_deg, longitude_deg, year, month, day, utc_hours, &sun);
    double r = sun.distance_au * 149597870.7;
    double psi = acos(cos(out->latitude) * cos(out->longitude - sun.apparent_longitude));
    out->phase_angle = atan2(r * sin(psi), dist - r * cos(psi));
    out->illuminated_fraction = 0.5 * (1.0 + cos(out->phase_angle));
    out->irradiance_ratio = sb_moon_irradiance_ratio(out->phase_angle, dist);
}

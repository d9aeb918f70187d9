#include "sun_path.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define DEG (M_PI / 180.0)

double sb_julian_day(int year, int month, int day, double utc_hours)
{
    /* Meeus, ch. 7, for the Gregorian calendar. */
    if (month <= 2) {
        year -= 1;
        month += 12;
    }
    double a = floor(year / 100.0);
    double b = 2.0 - a + floor(a / 4.0);
    return floor(365.25 * (year + 4716)) + floor(30.6001 * (month + 1)) + day + b - 1524.5 + utc_hours / 24.0;
}

static double wrap_degrees(double x)
{
    return x - 360.0 * floor(x / 360.0);
}

void sb_sun_position(double latitude_deg, double longitude_deg, int year, int month, int day, double utc_hours,
                     struct sb_sun_position *out)
{
    /* Julian centuries from J2000.0. The series take terrestrial time;
     * UT differs by about a minute (delta T), 0.0007 degrees of the sun's
     * longitude, far below the series' own 0.01. */
    double t = (sb_julian_day(year, month, day, utc_hours) - 2451545.0) / 36525.0;
    double mean_longitude = wrap_degrees(280.46646 + t * (36000.76983 + t * 0.0003032));
    double mean_anomaly = (357.52911 + t * (35999.05029 - t * 0.0001537)) * DEG;
    double eccentricity = 0.016708634 - t * (0.000042037 + t * 0.0000001267);
    double centre = sin(mean_anomaly) * (1.914602 - t * (0.004817 + t * 0.000014)) +
                    sin(2.0 * mean_anomaly) * (0.019993 - t * 0.000101) + sin(3.0 * mean_anomaly) * 0.000289;
    /* Apparent longitude: the true one less aberration, plus nutation's main term. */
    double node = (125.04 - 1934.136 * t) * DEG;
    double longitude = (mean_longitude + centre - 0.00569 - 0.00478 * sin(node)) * DEG;
    double mean_obliquity = 23.0 + (26.0 + (21.448 - t * (46.815 + t * (0.00059 - t * 0.001813))) / 60.0) / 60.0;
    double obliquity = (mean_obliquity + 0.00256 * cos(node)) * DEG;
    double declination = asin(sin(obliquity) * sin(longitude));

    /* The equation of time (Meeus, ch. 28, Smart's series). */
    double y = tan(0.5 * obliquity);
    y *= y;
    double l0 = mean_longitude * DEG;
    double eot = y * sin(2.0 * l0) - 2.0 * eccentricity * sin(mean_anomaly) +
                 4.0 * eccentricity * y * sin(mean_anomaly) * cos(2.0 * l0) - 0.5 * y * y * sin(4.0 * l0) -
                 1.25 * eccentricity * eccentricity * sin(2.0 * mean_anomaly);
    double eot_min = 4.0 * eot / DEG;

    /* The hour angle from the apparent solar time; then the horizon frame.
     * atan2 keeps the azimuth finite at the poles (it follows the hour angle). */
    double solar_min = utc_hours * 60.0 + eot_min + 4.0 * longitude_deg;
    double hour_angle = (solar_min / 4.0 - 180.0) * DEG;
    double phi = latitude_deg * DEG;
    double sin_e = sin(phi) * sin(declination) + cos(phi) * cos(declination) * cos(hour_angle);
    double east = -cos(declination) * sin(hour_angle);
    double north = sin(declination) * cos(phi) - cos(declination) * cos(hour_angle) * sin(phi);
    out->elevation = asin(fmax(-1.0, fmin(1.0, sin_e)));
    out->azimuth = wrap_degrees(atan2(east, north) / DEG) * DEG;
    out->declination = declination;
    out->equation_of_time_min = eot_min;
    out->apparent_longitude = wrap_degrees(longitude / DEG) * DEG;
    /* The radius vector (Meeus, 25.5). */
    double true_anomaly = mean_anomaly + centre * DEG;
    out->distance_au = 1.000001018 * (1.0 - eccentricity * eccentricity) / (1.0 + eccentricity * cos(true_anomaly));
}

/*
 * Fritsch and Carlson's tangents for a monotone cubic through (x, y): the
 * weighted harmonic mean of the secants (Fritsch and Butland), zero at a
 * local extremum, so a value held by two keys stays flat between them.
 * Interior tangents stay within three times either secant and the ends take
 * their secant: the bounds under which each interval is monotone.
 */
static void monotone_tangents(const double *x, const double *y, int n, double *m)
{
    for (int i = 0; i < n; i++) {
        double left = i > 0 ? (y[i] - y[i - 1]) / (x[i] - x[i - 1]) : 0.0;
        double right = i < n - 1 ? (y[i + 1] - y[i]) / (x[i + 1] - x[i]) : 0.0;
        if (i == 0)
            m[i] = right;
        else if (i == n - 1)
            m[i] = left;
        else if (left * right <= 0.0)
            m[i] = 0.0;
        else {
            double h0 = x[i] - x[i - 1], h1 = x[i + 1] - x[i];
            double w0 = 2.0 * h1 + h0, w1 = h1 + 2.0 * h0;
            m[i] = (w0 + w1) / (w0 / left + w1 / right);
        }
    }
}

static double hermite(const double *x, const double *y, const double *m, int n, double at)
{
    if (at <= x[0])
        return y[0];
    if (at >= x[n - 1])
        return y[n - 1];
    int i = 0;
    while (at > x[i + 1])
        i++;
    double h = x[i + 1] - x[i], s = (at - x[i]) / h;
    double s2 = s * s, s3 = s2 * s;
    return (2.0 * s3 - 3.0 * s2 + 1.0) * y[i] + (s3 - 2.0 * s2 + s) * h * m[i] + (-2.0 * s3 + 3.0 * s2) * y[i + 1] +
           (s3 - s2) * h * m[i + 1];
}

void sb_sun_path_date(const struct sb_sun_path *path, int *year, int *month, int *day, double *utc_offset_h)
{
    *year = path->year ? path->year : 2026;
    *month = path->year ? path->month : 6;
    *day = path->year ? path->day : 21;
    *utc_offset_h = path->has_utc_offset ? path->utc_offset_h : path->longitude_deg / 15.0;
}

void sb_sun_path_at(const struct sb_sun_path *path, double hour, double *elevation, double *azimuth)
{
    if (path->key_count >= 2) {
        int n = path->key_count;
        double x[SB_SUN_PATH_MAX_KEYS], e[SB_SUN_PATH_MAX_KEYS], a[SB_SUN_PATH_MAX_KEYS], m[SB_SUN_PATH_MAX_KEYS];
        for (int i = 0; i < n; i++) {
            x[i] = path->keys[i].hour;
            e[i] = path->keys[i].elevation;
            a[i] = path->keys[i].azimuth;
            /* Unwrap: each azimuth within half a turn of the one before. */
            if (i > 0)
                a[i] -= 2.0 * M_PI * round((a[i] - a[i - 1]) / (2.0 * M_PI));
        }
        monotone_tangents(x, e, n, m);
        *elevation = hermite(x, e, m, n, hour);
        monotone_tangents(x, a, n, m);
        double az = hermite(x, a, m, n, hour);
        *azimuth = az - 2.0 * M_PI * floor(az / (2.0 * M_PI));
        return;
    }
    int year, month, day;
    double offset;
    sb_sun_path_date(path, &year, &month, &day, &offset);
    struct sb_sun_position p;
    sb_sun_position(path->latitude_deg, path->longitude_deg, year, month, day, hour - offset, &p);
    *elevation = p.elevation;
    *azimuth = p.azimuth;
}

static bool parse_real(const char **s, double lo, double hi, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(*s, &end);
    if (end == *s || errno || !isfinite(v) || v < lo || v > hi)
        return false;
    *s = end;
    *out = v;
    return true;
}

bool sb_sun_path_parse_keys(const char *text, struct sb_sun_path *path, char *why, size_t why_size)
{
    const char *s = text;
    int n = 0;
    while (*s) {
        if (n == SB_SUN_PATH_MAX_KEYS) {
            snprintf(why, why_size, "more than %d keys", SB_SUN_PATH_MAX_KEYS);
            return false;
        }
        double h, e, a;
        if (!parse_real(&s, 0.0, 48.0, &h) || *s++ != ':' || !parse_real(&s, -90.0, 90.0, &e) || *s++ != ':' ||
            !parse_real(&s, -360.0, 720.0, &a) || (*s && *s != ',')) {
            snprintf(why, why_size,
                     "key %d is not HOUR:ELEVATION:AZIMUTH (hours in [0, 48], elevation in [-90, 90] and "
                     "azimuth in [-360, 720] degrees)",
                     n + 1);
            return false;
        }
        if (n > 0 && h <= path->keys[n - 1].hour) {
            snprintf(why, why_size, "key %d's hour %g does not follow key %d's %g", n + 1, h, n,
                     path->keys[n - 1].hour);
            return false;
        }
        path->keys[n++] = (struct sb_sun_key){h, e * DEG, a * DEG};
        if (*s == ',' && !*++s) {
            snprintf(why, why_size, "a comma ends the list");
            return false;
        }
    }
    if (n < 2) {
        snprintf(why, why_size, "a path needs 2 keys or more, not %d", n);
        return false;
    }
    path->key_count = n;
    return true;
}

bool sb_parse_date(const char *text, int *year, int *month, int *day, char *why, size_t why_size)
{
    int y, m, d, used = 0;
    if (sscanf(text, "%4d-%2d-%2d%n", &y, &m, &d, &used) != 3 || text[used] || used != 10) {
        snprintf(why, why_size, "'%s' is not a date YYYY-MM-DD", text);
        return false;
    }
    static const int days[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    bool leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
    if (y < 1800 || y > 2100) {
        snprintf(why, why_size, "the year %d is outside 1800 to 2100, where the solar coordinates hold", y);
        return false;
    }
    if (m < 1 || m > 12 || d < 1 || d > days[m - 1] + (m == 2 && leap)) {
        snprintf(why, why_size, "%s is not a day of the calendar", text);
        return false;
    }
    *year = y;
    *month = m;
    *day = d;
    return true;
}

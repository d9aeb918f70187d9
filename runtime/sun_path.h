/*
 * Where the sun is over a day, for skyview's time-of-day sweeps: from a
 * place and a date (the sun's apparent position by the low-precision
 * solar coordinates of Meeus, "Astronomical Algorithms", ch. 25, as NOAA's
 * solar calculator uses them: within 0.01 degrees from 1800 to 2100), or
 * from keyframes an artist sets. No Vulkan; thread safe (no state).
 *
 * Angles follow struct sb_view: elevation above the horizon, azimuth
 * clockwise from north toward east, both in radians. The world's north is
 * its -z axis. Elevations are geometric: the atmosphere skyview draws does
 * not refract, so the sun is drawn where straight paths reach it (half a
 * degree lower at the horizon than a refracting sky shows it).
 */
#ifndef SB_RUNTIME_SUN_PATH_H
#define SB_RUNTIME_SUN_PATH_H

#include <stdbool.h>
#include <stddef.h>

/* The sun seen from a place on the earth at an instant. */
struct sb_sun_position {
    double elevation, azimuth;   /* radians, as above */
    double declination;          /* radians */
    double equation_of_time_min; /* apparent minus mean solar time, minutes */
    double apparent_longitude;   /* the sun's ecliptic longitude, radians in [0, 2 pi) */
    double distance_au;          /* from the earth */
};

/* The Julian day (UT) of a Gregorian date at `utc_hours` (any real; it may
 * run past 24 or below 0). */
double sb_julian_day(int year, int month, int day, double utc_hours);

/* The sun from latitude and longitude (degrees, north and east positive;
 * the poles included) at `utc_hours` of a Gregorian date. */
void sb_sun_position(double latitude_deg, double longitude_deg, int year, int month, int day, double utc_hours,
                     struct sb_sun_position *out);

#define SB_SUN_PATH_MAX_KEYS 64

/* One keyframe: the sun at a time of day (hours), angles in radians. */
struct sb_sun_key {
    double hour, elevation, azimuth;
};

/*
 * A sun path over the hours of a day. Zeroed, it is the place's: latitude
 * and longitude 0 (set them), the date year/month/day (0: the June solstice
 * of 2026, 2026-06-21), hours in local clock time utc_offset_h ahead of UTC
 * (without has_utc_offset: the longitude's mean solar time, longitude / 15
 * hours ahead). With keys, the
 * sun follows them instead: a monotone cubic (Fritsch and Carlson) through
 * each of elevation and azimuth, so it passes every key, never overshoots
 * between two and turns smoothly (azimuths are taken the short way round,
 * 350 to 10 degrees through north); before the first key and after the last
 * it stays at that key.
 */
struct sb_sun_path {
    double latitude_deg, longitude_deg;
    int year, month, day;
    bool has_utc_offset;
    double utc_offset_h;
    struct sb_sun_key keys[SB_SUN_PATH_MAX_KEYS]; /* hours strictly increasing */
    int key_count;                                /* 0: the place's sun; otherwise 2 or more */
};

/* The date of a path of a place (its zeroed date: 2026-06-21) and its
 * clock's offset from UTC (hours). */
void sb_sun_path_date(const struct sb_sun_path *path, int *year, int *month, int *day, double *utc_offset_h);

/* The sun at `hour` (local clock time) on the path. */
void sb_sun_path_at(const struct sb_sun_path *path, double hour, double *elevation, double *azimuth);

/*
 * Parsers for skyview's options; on failure they return false and write
 * why into `why` (a sentence without the option's name):
 * - keys: "HOUR:ELEVATION:AZIMUTH,..." in hours and degrees, 2 to
 *   SB_SUN_PATH_MAX_KEYS of them, hours strictly increasing in [0, 48],
 *   elevations in [-90, 90], azimuths in [-360, 720];
 * - a date: "YYYY-MM-DD", a real Gregorian date from 1800 to 2100 (where
 *   the solar coordinates hold).
 */
bool sb_sun_path_parse_keys(const char *text, struct sb_sun_path *path, char *why, size_t why_size);
bool sb_parse_date(const char *text, int *year, int *month, int *day, char *why, size_t why_size);

#endif

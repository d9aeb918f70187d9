/*
 * Where the moon is and how much light it gives, for skyview's nights: its
 * position by Meeus's lunar coordinates ("Astronomical Algorithms", ch. 47:
 * the main terms of ELP-2000/82, about 10" in longitude and 4" in latitude),
 * seen from a place on the earth (parallax included: the moon is up to a
 * degree lower at the horizon than from the earth's centre), its phase
 * (ch. 48) and its irradiance from its phase by the moon's magnitude law.
 * Earthshine, lunar eclipses and refraction are left out. No Vulkan; thread
 * safe. Angles follow runtime/sun_path.h (elevation; azimuth clockwise from
 * north; radians).
 */
#ifndef SB_RUNTIME_MOON_H
#define SB_RUNTIME_MOON_H

#include <stdbool.h>

struct sb_moon_position {
    /* From the earth's centre, apparent (nutation in longitude included). */
    double longitude, latitude;          /* ecliptic of date, radians; longitude in [0, 2 pi) */
    double right_ascension, declination; /* radians; right ascension in [0, 2 pi) */
    double distance_km;                  /* between the centres */
    /* From the place (only sb_moon_position fills these). */
    double elevation, azimuth;   /* radians */
    double angular_radius;       /* the disk's, radians */
    double phase_angle;          /* the sun-moon-observer angle, radians: 0 full, pi new */
    double illuminated_fraction; /* of the disk, (1 + cos phase_angle) / 2 */
    double irradiance_ratio;     /* its irradiance over the sun's, above the atmosphere, visual band */
};

/* The moon from the earth's centre at Julian ephemeris day `jde`
 * (terrestrial time); fills the first block. */
void sb_moon_geocentric(double jde, struct sb_moon_position *out);

/* The moon from latitude and longitude (degrees, north and east positive)
 * at `utc_hours` of a Gregorian date (1800 to 2100); fills everything. */
void sb_moon_position(double latitude_deg, double longitude_deg, int year, int month, int day, double utc_hours,
                      struct sb_moon_position *out);

struct sb_sun_path;

/* The moon at `hour` of a sun path's date and place (as sb_sun_path_at
 * reads them); false, with *out untouched, for a path of keys, which has no
 * place. */
bool sb_moon_path_at(const struct sb_sun_path *path, double hour, struct sb_moon_position *out);

/* Greenwich mean sidereal time at Julian day `jd` (UT), radians in [0, 2 pi)
 * (Meeus, eq. 12.4). */
double sb_sidereal_time(double jd);

/*
 * The moon's irradiance over the sun's, above the atmosphere, in the visual
 * band, at phase angle `phase_angle` (radians) and distance `distance_km`:
 * its magnitude at the mean distance, -12.73 + 0.026 |a| + 4e-9 a^4 (a in
 * degrees; Allen 1976, as Krisciunas and Schaefer 1991 use it; the opposition
 * surge included), against the sun's -26.74, both at the sun's distance:
 * 2.5e-6 at full moon, a tenth of that at quarter.
 */
double sb_moon_irradiance_ratio(double phase_angle, double distance_km);

/* Moonlight's colour against sunlight's, per linear Rec.709 channel, with
 * luminance 1: the lunar soil reflects more red than blue (its B - V is
 * 0.92 against the sun's 0.65, 0.78 times the blue), taken as a
 * reflectance rising linearly with wavelength at the primaries'. */
#define SB_MOON_COLOR_R 1.105
#define SB_MOON_COLOR_G 0.987
#define SB_MOON_COLOR_B 0.819

#define SB_MOON_RADIUS_KM 1737.4

#endif

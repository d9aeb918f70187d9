/*
 * The sun path of skyview's time-of-day sweeps (runtime/sun_path.c) against
 * published references: NREL's SPA worked example (Reda and Andreas 2004,
 * table A5.1), the 2026 equinoxes and solstices, Meeus's Julian-day
 * examples; its horizon frame against a rotation built another way; the
 * keyframe curve's promises (through every key, monotone, smooth, the short
 * way round); the option parsers on good and bad text. No Vulkan.
 */
#include <math.h>
#include <string.h>

#include "harness.h"
#include "sun_path.h"

#define DEG (M_PI / 180.0)

/* Meeus's stated accuracy of the low-precision solar coordinates, 0.01
 * degrees: the bound for every angle compared with a published value. */
#define SOLAR_TOLERANCE_DEG 0.01

static double angle_diff_deg(double a, double b)
{
    double d = fmod(fabs(a - b), 2.0 * M_PI);
    return fmin(d, 2.0 * M_PI - d) / DEG;
}

static void test_published(void)
{
    /* Meeus, examples 7.a and J2000.0. */
    CHECK(sb_julian_day(2000, 1, 1, 12.0) == 2451545.0, "J2000.0 is %.3f", sb_julian_day(2000, 1, 1, 12.0));
    double jd = sb_julian_day(1957, 10, 4, 0.81 * 24.0);
    CHECK(fabs(jd - 2436116.31) < 1e-6, "1957-10-04.81 is JD %.6f, not 2436116.31", jd);
    CHECK(sb_julian_day(1600, 1, 1, 0.0) == 2305447.5, "1600-01-01 is JD %.1f", sb_julian_day(1600, 1, 1, 0.0));

    /* SPA's example: Golden, Colorado, 2003-10-17 12:30:30 at UTC-7. Its
     * topocentric elevation before refraction is 39.872046 degrees (the
     * parallax, 0.0024 degrees here, is below our tolerance), its azimuth
     * 194.340241, declination -9.31434, equation of time 14.641503 min. */
    struct sb_sun_position p;
    sb_sun_position(39.742476, -105.1786, 2003, 10, 17, 19.0 + 30.5 / 60.0, &p);
    printf("SPA example: elevation %.6f (39.872046), azimuth %.6f (194.340241), declination %.6f (-9.31434), "
           "equation of time %.4f min (14.6415)\n",
           p.elevation / DEG, p.azimuth / DEG, p.declination / DEG, p.equation_of_time_min);
    CHECK(fabs(p.elevation / DEG - 39.872046) < SOLAR_TOLERANCE_DEG, "elevation %.6f", p.elevation / DEG);
    CHECK(angle_diff_deg(p.azimuth, 194.340241 * DEG) < SOLAR_TOLERANCE_DEG, "azimuth %.6f", p.azimuth / DEG);
    CHECK(fabs(p.declination / DEG + 9.31434) < SOLAR_TOLERANCE_DEG, "declination %.6f", p.declination / DEG);
    /* 0.01 degrees of hour angle is 0.04 minutes of time. */
    CHECK(fabs(p.equation_of_time_min - 14.641503) < 4.0 * SOLAR_TOLERANCE_DEG, "equation of time %.5f",
          p.equation_of_time_min);

    /* The 2026 equinoxes and solstices (UTC, to the minute: the sun moves
     * 0.0007 degrees of longitude a minute): the apparent longitude is 0, 90,
     * 180 and 270 degrees there. */
    static const struct {
        int month, day, hour, minute;
    } events[4] = {{3, 20, 14, 46}, {6, 21, 8, 24}, {9, 23, 0, 5}, {12, 21, 20, 50}};
    for (int i = 0; i < 4; i++) {
        sb_sun_position(0.0, 0.0, 2026, events[i].month, events[i].day, events[i].hour + events[i].minute / 60.0, &p);
        double err = angle_diff_deg(p.apparent_longitude, i * 90.0 * DEG);
        CHECK(err < SOLAR_TOLERANCE_DEG + 0.0007, "2026-%02d-%02d: longitude %.5f, %.5f degrees off", events[i].month,
              events[i].day, p.apparent_longitude / DEG, err);
        /* Declination reaches the obliquity (23.436 degrees in 2026) at a solstice. */
        if (i % 2)
            CHECK(fabs(fabs(p.declination / DEG) - 23.4362) < SOLAR_TOLERANCE_DEG, "solstice declination %.5f",
                  p.declination / DEG);
        else
            CHECK(fabs(p.declination / DEG) < SOLAR_TOLERANCE_DEG, "equinox declination %.5f", p.declination / DEG);
    }
}

/*
 * The horizon frame built by rotations: the sun's equatorial unit vector
 * (x toward the meridian's equator point, y west, z the pole) turned about
 * the west axis by the colatitude gives (south, west, up).
 */
static void horizon_by_rotation(double latitude, double declination, double hour_angle, double *elevation,
                                double *azimuth)
{
    double eq[3] = {cos(declination) * cos(hour_angle), cos(declination) * sin(hour_angle), sin(declination)};
    double c = M_PI / 2.0 - latitude;
    double south = eq[0] * cos(c) - eq[2] * sin(c);
    double west = eq[1];
    double up = eq[0] * sin(c) + eq[2] * cos(c);
    *elevation = asin(fmax(-1.0, fmin(1.0, up)));
    *azimuth = atan2(-west, -south);
}

static void test_geometry(void)
{
    int bad = 0, nonfinite = 0;
    double worst = 0.0;
    static const double latitudes[] = {-90.0, -66.5, -35.0, -0.3, 0.0, 23.4, 45.0, 78.2, 89.999, 90.0};
    static const double longitudes[] = {-180.0, -105.2, 0.0, 13.4, 179.9};
    for (int la = 0; la < 10; la++)
        for (int lo = 0; lo < 5; lo++)
            for (int month = 1; month <= 12; month += 1)
                for (double h = -6.0; h <= 30.0; h += 0.75) {
                    struct sb_sun_position p;
                    sb_sun_position(latitudes[la], longitudes[lo], 2026, month, 15, h, &p);
                    if (!isfinite(p.elevation) || !isfinite(p.azimuth) || !isfinite(p.declination) ||
                        !isfinite(p.equation_of_time_min) || p.azimuth < 0.0 || p.azimuth >= 2.0 * M_PI) {
                        nonfinite++;
                        continue;
                    }
                    double hour_angle =
                        ((h * 60.0 + p.equation_of_time_min + 4.0 * longitudes[lo]) / 4.0 - 180.0) * DEG;
                    double e, a;
                    horizon_by_rotation(latitudes[la] * DEG, p.declination, hour_angle, &e, &a);
                    double de = fabs(e - p.elevation) / DEG;
                    /* The azimuth is undefined with the sun at the zenith or at a pole. */
                    double da = fabs(latitudes[la]) < 90.0 && fabs(e) < 89.9 * DEG ? angle_diff_deg(a, p.azimuth) : 0.0;
                    worst = fmax(worst, fmax(de, da));
                    bad += de > 1e-9 || da > 1e-9;
                }
    CHECK(nonfinite == 0, "%d positions not finite or azimuth outside [0, 360)", nonfinite);
    CHECK(bad == 0, "%d positions differ from the rotation (worst %.3g degrees)", bad, worst);

    /* At a pole the sun's elevation is its declination all day; at 80 N on
     * the June solstice it never sets: at local midnight it is the
     * declination less 10 degrees. */
    struct sb_sun_position p;
    for (double h = 0.0; h < 24.0; h += 3.0) {
        sb_sun_position(90.0, 0.0, 2026, 6, 21, h, &p);
        CHECK(fabs(p.elevation - p.declination) < 1e-12, "north pole at %g h: elevation %.9f, declination %.9f", h,
              p.elevation / DEG, p.declination / DEG);
    }
    /* Sampled each minute about midnight, the lowest point is within 30 s
     * of the lower culmination, where the elevation moves by 2e-5 degrees:
     * 1e-4. */
    double lowest = 90.0, declination = 0.0;
    for (double h = -1.0; h <= 1.0; h += 1.0 / 60.0) { /* about local midnight */
        sb_sun_position(80.0, 0.0, 2026, 6, 21, h, &p);
        if (p.elevation / DEG < lowest) {
            lowest = p.elevation / DEG;
            declination = p.declination / DEG;
        }
    }
    printf("80 N on the June solstice: lowest %.5f degrees, declination %.5f less 10\n", lowest, declination);
    CHECK(lowest > 0.0 && fabs(lowest - (declination - 10.0)) < 1e-4,
          "80 N at midnight sun: lowest %.6f degrees, not the declination %.6f less 10", lowest, declination);
}

static void test_keys(void)
{
    char why[256];
    struct sb_sun_path path = {0};
    CHECK(sb_sun_path_parse_keys("6:-4:70,9:20:100,12:60:180,12.5:60:190,18:10:280,20:-6:350", &path, why, sizeof(why)),
          "%s", why);
    CHECK(path.key_count == 6, "%d keys", path.key_count);
    int misses = 0, overshoots = 0, kinks = 0;
    for (int i = 0; i < path.key_count; i++) {
        double e, a;
        sb_sun_path_at(&path, path.keys[i].hour, &e, &a);
        misses += fabs(e - path.keys[i].elevation) > 1e-12 || angle_diff_deg(a, path.keys[i].azimuth) > 1e-9;
    }
    for (int i = 0; i + 1 < path.key_count; i++) {
        const struct sb_sun_key *k0 = &path.keys[i], *k1 = &path.keys[i + 1];
        double lo = fmin(k0->elevation, k1->elevation), hi = fmax(k0->elevation, k1->elevation);
        for (int s = 1; s < 100; s++) {
            double e, a;
            sb_sun_path_at(&path, k0->hour + (k1->hour - k0->hour) * s / 100.0, &e, &a);
            overshoots += e < lo - 1e-12 || e > hi + 1e-12;
        }
        /* C1: the slope from the left and from the right agree at an interior key. */
        if (i > 0) {
            double h = 1e-5, e0, e1, e2, a;
            sb_sun_path_at(&path, k0->hour - h, &e0, &a);
            sb_sun_path_at(&path, k0->hour, &e1, &a);
            sb_sun_path_at(&path, k0->hour + h, &e2, &a);
            double left = (e1 - e0) / h, right = (e2 - e1) / h;
            kinks += fabs(left - right) > 1e-3 * fmax(1.0, fabs(left));
        }
    }
    CHECK(misses == 0, "%d keys missed", misses);
    CHECK(overshoots == 0, "%d samples overshoot their keys' elevations", overshoots);
    CHECK(kinks == 0, "%d kinks at interior keys", kinks);
    /* Held value: 12 and 12.5 both at 60 degrees: flat between. */
    double e, a;
    sb_sun_path_at(&path, 12.25, &e, &a);
    CHECK(fabs(e - 60.0 * DEG) < 1e-12, "held key: %.9f degrees", e / DEG);
    /* Outside the keys the sun stays at the end keys. */
    sb_sun_path_at(&path, 3.0, &e, &a);
    CHECK(e == path.keys[0].elevation && angle_diff_deg(a, 70.0 * DEG) < 1e-9, "before the first key");
    sb_sun_path_at(&path, 23.0, &e, &a);
    CHECK(e == path.keys[5].elevation && angle_diff_deg(a, 350.0 * DEG) < 1e-9, "after the last key");

    /* The short way round: 350 to 10 degrees passes north, never south. */
    struct sb_sun_path wrap = {0};
    CHECK(sb_sun_path_parse_keys("0:10:350,1:10:10", &wrap, why, sizeof(why)), "%s", why);
    double farthest = 0.0;
    for (int s = 0; s <= 100; s++) {
        sb_sun_path_at(&wrap, s / 100.0, &e, &a);
        farthest = fmax(farthest, angle_diff_deg(a, 0.0));
        CHECK(a >= 0.0 && a < 2.0 * M_PI, "azimuth %.6f outside [0, 360)", a / DEG);
    }
    CHECK(fabs(farthest - 10.0) < 1e-9, "350 -> 10 strays %.6f degrees from north", farthest);

    /* Bad keys: each refused with a reason. */
    static const char *const bad[] = {"",
                                      "6:10:90",
                                      "6:10:90,6:20:100",
                                      "6:10:90,5:20:100",
                                      "6:10:90,7:91:100",
                                      "6:10:90,7:20",
                                      "6:10:90,7:20:100,",
                                      "6:10:90;7:20:100",
                                      "a:b:c,1:2:3",
                                      "6:10:90,49:0:0",
                                      "6:10:nan,7:1:1",
                                      "6:10:90,7:20:100x"};
    for (size_t i = 0; i < sizeof(bad) / sizeof(bad[0]); i++) {
        struct sb_sun_path p = {0};
        why[0] = '\0';
        CHECK(!sb_sun_path_parse_keys(bad[i], &p, why, sizeof(why)) && why[0] && p.key_count == 0, "'%s' accepted",
              bad[i]);
    }
    char many[4096] = "";
    for (int i = 0; i <= SB_SUN_PATH_MAX_KEYS; i++)
        snprintf(many + strlen(many), sizeof(many) - strlen(many), "%s%d.%d:0:0", i ? "," : "", i / 3, i % 3 * 3);
    struct sb_sun_path p = {0};
    CHECK(!sb_sun_path_parse_keys(many, &p, why, sizeof(why)), "%d keys accepted", SB_SUN_PATH_MAX_KEYS + 1);
}

static void test_dates_and_place(void)
{
    char why[256];
    int y, m, d;
    CHECK(sb_parse_date("2024-02-29", &y, &m, &d, why, sizeof(why)) && y == 2024 && m == 2 && d == 29, "%s", why);
    CHECK(sb_parse_date("2000-02-29", &y, &m, &d, why, sizeof(why)), "%s", why);
    static const char *const bad[] = {"2026-02-29",  "1900-02-29", "2026-13-01", "2026-04-31", "2026-6-21",
                                      "2026-06-21x", "1799-12-31", "2101-01-01", "21-06-2026", "",
                                      "2026-00-10"};
    for (size_t i = 0; i < sizeof(bad) / sizeof(bad[0]); i++) {
        why[0] = '\0';
        CHECK(!sb_parse_date(bad[i], &y, &m, &d, why, sizeof(why)) && why[0], "'%s' accepted", bad[i]);
    }

    /* A zeroed path is the June solstice of 2026 in mean solar time: at the
     * equator the sun crosses the meridian in the north, 90 - 23.44 degrees
     * up, at 12:00 less the equation of time. Sampled each second: the
     * highest point is within 0.5 s of the crossing (bound 1 s, 1/60 min),
     * where the azimuth turns 35 degrees an hour (0.005 in 0.5 s; bound 0.05). */
    struct sb_sun_path path = {.longitude_deg = 30.0};
    double best = -1.0, best_hour = 0.0, e, a;
    for (double h = 11.0; h <= 13.0; h += 1.0 / 3600.0) {
        sb_sun_path_at(&path, h, &e, &a);
        if (e > best) {
            best = e;
            best_hour = h;
        }
    }
    sb_sun_path_at(&path, best_hour, &e, &a);
    CHECK(fabs(best / DEG - (90.0 - 23.4362)) < SOLAR_TOLERANCE_DEG, "noon elevation %.5f", best / DEG);
    struct sb_sun_position at_noon;
    sb_sun_position(0.0, 30.0, 2026, 6, 21, best_hour - 2.0, &at_noon);
    double noon_min = 720.0 - at_noon.equation_of_time_min;
    printf("the equator at 30 E on the June solstice: noon at %.3f min (12:00 less the equation of time, %.3f), "
           "azimuth %.4f\n",
           best_hour * 60.0, noon_min, a / DEG);
    CHECK(angle_diff_deg(a, 0.0) < 0.05, "noon azimuth %.4f", a / DEG);
    CHECK(fabs(best_hour * 60.0 - noon_min) < 1.0 / 60.0, "noon at %.3f min, not 12:00 less the equation of time %.3f",
          best_hour * 60.0, noon_min);
    /* The same instant with a UTC offset: 14:00 at UTC+2 is 12:00 UTC. */
    struct sb_sun_path utc = {.longitude_deg = 30.0, .has_utc_offset = true, .utc_offset_h = 2.0};
    double e2, a2;
    sb_sun_path_at(&utc, 14.0, &e2, &a2);
    sb_sun_path_at(&path, 14.0, &e, &a); /* mean solar time at 30 E is also UTC + 2 */
    CHECK(e2 == e && a2 == a, "UTC offset: %.9f vs %.9f", e2, e);
}

int main(void)
{
    test_published();
    test_geometry();
    test_keys();
    test_dates_and_place();
    return test_finish("sun path");
}

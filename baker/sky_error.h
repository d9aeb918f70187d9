/*
 * skybake sky-error: how good the sky is, not only the LUTs. The scene's
 * atmosphere is baked with the default settings on the device; its sky
 * radiance is then evaluated as the runtime computes it from those LUTs
 * (single scattering, Hillaire's multiple scattering from the
 * multiscattering LUT, the lit ground from irradiance_ground; in fp64 by
 * sb_ref_sky_radiance, which skyview's sky-view LUT matches to 1e-3) and
 * compared with the fp64 path tracer (pathtrace.h), every order counted,
 * over a fixed set of view directions from the scene's camera altitude, for
 * each of a list of sun elevations. What it measures is the multiple-
 * scattering approximation itself: the LUTs' own errors against fp64 are
 * bench's business and 1e-3 or less. Its colour too: CIEDE2000 between the
 * two skies, each rgb as the runtime shows it (linear Rec.709), against
 * the same three-wavelength path tracer (the model's colour error alone),
 * and against the spectral truth: the path tracer at the 48 wavelengths
 * of physics/spectrum.h, 360 to 830 nm, the scene read at each by
 * spectrum.h's rules, integrated against the CIE 1931 observer and taken
 * to Rec.709 under the measured sun adapted to the scene's
 * (sb_sun_xyz_to_rec709). Each three-channel sky is measured against it
 * read two ways: as Rec.709 primaries (the runtime today) and through
 * sb_channels_to_rec709 (the three channels as samples of a spectrum).
 */
#ifndef SB_BAKER_SKY_ERROR_H
#define SB_BAKER_SKY_ERROR_H

#include <stdbool.h>
#include <stdint.h>

#include "context.h"
#include "orders_ref.h"
#include "scene.h"
#include "spectrum.h"

#define SB_SKY_ERROR_MAX_SUNS 16
#define SB_SKY_ERROR_DIRECTIONS 16

/* View i (< SB_SKY_ERROR_DIRECTIONS) of the tables from altitude_km: its
 * zenith angle and its azimuth from the sun's, in degrees. */
void sb_sky_error_view(const struct sb_atmosphere_params *p, double altitude_km, int i, double *zenith_deg,
                       double *azimuth_deg);

/* A view's cosines from its zenith angle, its azimuth from the sun's and the
 * sun's elevation (degrees): mu (view), mu_s (sun), nu (view-sun). */
void sb_sky_error_cosines(double zenith_deg, double azimuth_deg, double elevation_deg, double *mu, double *mu_s,
                          double *nu);

struct sb_sky_error_params {
    int paths;                             /* per direction and channel; 0: 16384 */
    int spectral_paths;                    /* per direction and wavelength; 0: paths / 16 (the same work as the
                                              three channels' trace), at least 32 */
    uint64_t seed;                         /* the path tracer's */
    bool orders;                           /* also the sky with multiple scattering by orders (orders_ref.h), */
    struct sb_orders_settings orders_grid; /* on this grid (zeros: the default) */
    int sun_count;                         /* 0: 90, 30, 10, 2 and -4 degrees */
    double sun_elevation_deg[SB_SKY_ERROR_MAX_SUNS];
};

/* One view direction: zenith angle and azimuth from the sun, in degrees. */
struct sb_sky_error_direction {
    double zenith_deg, azimuth_deg;
    bool ground;                              /* the view ends on the ground */
    double skybake[3];                        /* the runtime's model on the baked LUTs */
    double single[3];                         /* its single scattering alone (no ground light) */
    double path_traced[3];                    /* the reference */
    double std_error[3];                      /* the reference's standard error */
    double orders[3];                         /* the sky with orders 2 and up from orders_ref.h */
    double product[3];                        /* skybake's sky with the orders product (orders.h) */
    double skybake_12[12];                    /* skybake's model at the 12 wavelengths (sb_spectral_nm) */
    double product_12[12];                    /* its sky with the spectral orders, as skyview draws it */
    double spectral[SB_SPECTRUM_COUNT];       /* the spectral path tracer, per wavelength */
    double spectral_error[SB_SPECTRUM_COUNT]; /* its standard error */
};

/* How the three-channel skies are read as colour against the spectral one. */
enum sb_sky_error_scheme {
    SB_SKY_ERROR_PRIMARIES,        /* skybake's sky, its channels as Rec.709 primaries */
    SB_SKY_ERROR_CONVERTED,        /* skybake's sky through sb_channels_to_rec709 */
    SB_SKY_ERROR_TRACED_PRIMARIES, /* the three-channel path tracer's, as primaries */
    SB_SKY_ERROR_TRACED_CONVERTED, /* the three-channel path tracer's, converted */
    /* The spectral trace itself read at 6 of its wavelengths (evenly spread
     * from 380 to 810 nm) or at the spectral products' 12 (400 to 670 nm,
     * sb_spectral_nm), linear between them and flat beyond: the error of a
     * runtime of that many wavelengths whose light were exact */
    SB_SKY_ERROR_WAVELENGTHS_6,
    SB_SKY_ERROR_WAVELENGTHS_12,
    /* skybake's model (its LUTs baked for each wavelength, read as the
     * runtime reads them) at those 12 wavelengths, linear between them */
    SB_SKY_ERROR_SKYBAKE_12,
    /* the sky with the orders product, as primaries (skyview's colour with
     * three-channel products), and at 12 wavelengths from the spectral
     * products (skyview's with them: spectral_orders) */
    SB_SKY_ERROR_PRODUCT_PRIMARIES,
    SB_SKY_ERROR_PRODUCT_12,
    SB_SKY_ERROR_SCHEME_COUNT,
};

struct sb_sky_error_colour {
    double mean, max; /* CIEDE2000 over the views of the sky */
    int worst_direction;
};

struct sb_sky_error_sun {
    double elevation_deg;
    struct sb_sky_error_direction directions[SB_SKY_ERROR_DIRECTIONS];
    /* Over directions and channels, relative to the path tracer (floored at
     * 1e-3 of the sun's brightest value in that channel, of the views at
     * least 5 degrees from the sun): */
    double max_rel, rms_rel, mean_rel; /* mean_rel is signed: skybake above the reference > 0 */
    int worst_direction, worst_channel;
    double noise;                                              /* the largest 2 standard errors, relative */
    double orders_max_rel, orders_rms_rel, orders_mean_rel;    /* the same for the orders' sky */
    struct sb_sky_error_colour orders_colour;                  /* its CIEDE2000 against the path tracer, as de_* */
    double product_max_rel, product_rms_rel, product_mean_rel; /* the same for the orders product's sky */
    struct sb_sky_error_colour product_colour;
    /* Colour: CIEDE2000 between the two skies over the views of the sky (not
     * the ground), each rgb taken as linear Rec.709 as the runtime shows
     * it, in CIELAB against D65 at the luminance of the path tracer's
     * brightest view of that sun (an exposure for the sky): */
    double de_mean, de_max;
    int de_worst_direction;
    double de_noise;       /* the largest CIEDE2000 that 2 standard errors of one channel make */
    double multiple_share; /* mean of 1 - single / path traced over the views of the sky (not
                              the ground): how much light the higher orders bring */
    /* Against the spectral path tracer (CIELAB against D65 at its brightest
     * view of the sky): */
    struct sb_sky_error_colour spectral[SB_SKY_ERROR_SCHEME_COUNT];
    double spectral_noise; /* the largest CIEDE2000 that 2 standard errors of X, Y or Z make */
};

struct sb_sky_error_report {
    char scene[256];
    double altitude_km;
    int paths;
    int spectral_paths;
    int sun_count;
    struct sb_sky_error_sun suns[SB_SKY_ERROR_MAX_SUNS];
    double path_trace_s; /* wall time of the path tracer, three channels and spectral */
    int orders;          /* with params.orders: the orders the reference summed, */
    double orders_s;     /* and its wall time */
    int product_orders;  /* the orders product's orders */
    /* on the scene's grid (sb_orders_product_grid) */
    struct sb_orders_settings product_grid;
    double product_gpu_ms;
};

/* Bake and compare; the report is the caller's (no resources to free). */
enum sb_result sb_sky_error_run(struct sb_vk *vk, const char *scene_name, const struct sb_scene *scene,
                                const struct sb_sky_error_params *params, struct sb_sky_error_report *report);

/* A table per report, or all reports as one JSON array, on stdout. */
void sb_sky_error_print(const struct sb_sky_error_report *reports, int count, bool json);

#endif

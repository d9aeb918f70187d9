#include "sky_error.h"

#include <cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "atmosphere.h"
#include "atmosphere_ref.h"
#include "colour.h"
#include "json.h"
#include "log.h"
#include "orders.h"
#include "orders_ref.h"
#include "parallel.h"
#include "pathtrace.h"
#include "spectral.h"

#define SKY_PI 3.14159265358979323846

/* Zenith angles from straight up to below the horizon (the ground, for a
 * camera in the air), each at the sun's azimuth, across and opposite; the
 * zenith once. A camera above the atmosphere looks down instead: the
 * nadir, three rings on the ground (0.5, 0.9 and 0.99 of the angle to its
 * edge) and two through the limb (grazing 5 and 30 km up). */
static const double zenith_deg[] = {30, 60, 80, 87, 120};
static const double azimuth_deg[] = {0, 90, 180};
static const double default_suns[] = {90, 30, 10, 2, -4};

void sb_sky_error_view(const struct sb_atmosphere_params *p, double altitude_km, int i, double *zenith, double *azimuth)
{
    double R = p->ground_radius_km, r = R + altitude_km;
    bool space = r > p->top_radius_km;
    if (i == 0) {
        *zenith = space ? 180 : 0;
        *azimuth = 0;
        return;
    }
    int ring = (i - 1) / 3;
    *azimuth = azimuth_deg[(i - 1) % 3];
    if (!space) {
        *zenith = zenith_deg[ring];
        return;
    }
    /* angles from the nadir */
    double edge = asin(R / r) * 180 / SKY_PI;
    const double ground[3] = {0.5, 0.9, 0.99}, limb_km[2] = {5, 30};
    double from_nadir = ring < 3 ? ground[ring] * edge : asin((R + limb_km[ring - 3]) / r) * 180 / SKY_PI;
    *zenith = 180 - from_nadir;
}

#define TRIPLES (SB_SPECTRUM_COUNT / 3) /* the spectral trace's wavelengths, three a medium */

struct job {
    const struct sb_atmosphere_params *params;
    const struct sb_image *luts;
    const struct sb_sky_error_params *settings;
    struct sb_sky_error_report *report;
    /* the scene at wavelengths 3 t, 3 t + 1 and 3 t + 2 of the grid, as channels */
    struct sb_atmosphere_params spectral[TRIPLES];
    /* the scene at the 12 wavelengths, a band of three at a time, and each
     * band's LUTs: transmittance, multiscattering, irradiance_ground, orders */
    const struct sb_atmosphere_params *band[SB_SPECTRAL_BANDS];
    const struct sb_image *band_luts[SB_SPECTRAL_BANDS][4];
    const struct sb_orders_ref *orders; /* NULL unless asked */
    const struct sb_orders_ref *grid;   /* the orders product's grid */
    int sun;                            /* the sun being traced */
};

#define JOBS_PER_SUN (SB_SKY_ERROR_DIRECTIONS * (3 + TRIPLES))

/* Of the job's sun: one (direction, channel), then one (direction,
 * wavelength triple) of the spectral trace. */
void sb_sky_error_cosines(double zenith_angle_deg, double azimuth_from_sun_deg, double elevation_deg, double *mu,
                          double *mu_s, double *nu)
{
    double zenith = zenith_angle_deg * SKY_PI / 180, azimuth = azimuth_from_sun_deg * SKY_PI / 180;
    double elevation = elevation_deg * SKY_PI / 180;
    *mu = cos(zenith);
    *mu_s = sin(elevation);
    *nu = fmax(-1.0, fmin(1.0, sin(zenith) * cos(elevation) * cos(azimuth) + *mu * *mu_s));
}

static void run_one(void *user, int index)
{
    struct job *job = user;
    int rgb_jobs = SB_SKY_ERROR_DIRECTIONS * 3;
    bool spectral = index >= rgb_jobs;
    int per_view = spectral ? TRIPLES : 3, i = spectral ? index - rgb_jobs : index;
    int channel = i % per_view, d = i / per_view;
    struct sb_sky_error_sun *sun = &job->report->suns[job->sun];
    struct sb_sky_error_direction *dir = &sun->directions[d];
    double mu, mu_s, nu;
    sb_sky_error_cosines(dir->zenith_deg, dir->azimuth_deg, sun->elevation_deg, &mu, &mu_s, &nu);
    double h = job->report->altitude_km, R = job->params->ground_radius_km, r = R + h;
    struct sb_pathtrace_view view = {h, mu, mu_s, nu};
    if (spectral) {
        /* seeds apart from the three channels' streams */
        struct sb_pathtrace_params params = {.seed = job->settings->seed ^ 0x5bd1e9955bd1e995ull,
                                             .paths = job->report->spectral_paths};
        for (int c = 0; c < 3; c++) {
            struct sb_pathtrace_result traced = sb_pathtrace_radiance(&job->spectral[channel], &view, c, &params);
            dir->spectral[3 * channel + c] = traced.radiance;
            dir->spectral_error[3 * channel + c] = traced.std_error;
        }
        return;
    }
    if (channel == 0) {
        dir->ground = mu < 0 && r * r * (mu * mu - 1) + R * R >= 0;
        sb_ref_sky_radiance(job->params, h, mu, mu_s, nu, &job->luts[SB_PRODUCT_TRANSMITTANCE],
                            &job->luts[SB_PRODUCT_MULTISCATTERING], &job->luts[SB_PRODUCT_IRRADIANCE_GROUND], NULL,
                            dir->skybake);
        sb_ref_sky_radiance(job->params, h, mu, mu_s, nu, &job->luts[SB_PRODUCT_TRANSMITTANCE], NULL, NULL, NULL,
                            dir->single);
        sb_orders_product_sky(job->params, job->grid, &job->luts[SB_PRODUCT_ORDERS],
                              &job->luts[SB_PRODUCT_TRANSMITTANCE], h, mu, mu_s, nu, dir->product);
        if (job->orders)
            sb_orders_ref_sky(job->orders, h, mu, mu_s, nu, dir->orders, NULL);
        for (int b = 0; b < SB_SPECTRAL_BANDS; b++) {
            const struct sb_image *const *l = job->band_luts[b];
            double rgb[3], product[3];
            sb_ref_sky_radiance(job->band[b], h, mu, mu_s, nu, l[0], l[1], l[2], NULL, rgb);
            sb_orders_product_sky(job->band[b], job->grid, l[3], l[0], h, mu, mu_s, nu, product);
            for (int c = 0; c < 3; c++) {
                dir->skybake_12[3 * b + c] = rgb[c];
                dir->product_12[3 * b + c] = product[c];
            }
        }
    }
    struct sb_pathtrace_params params = {.seed = job->settings->seed, .paths = job->report->paths};
    struct sb_pathtrace_result traced = sb_pathtrace_radiance(job->params, &view, channel, &params);
    dir->path_traced[channel] = traced.radiance;
    dir->std_error[channel] = traced.std_error;
}

/* A view's rgb as CIELAB (sb_sky_error_sun's colour fields). */
static void view_lab(const double m[3][3], const double white[3], const double rgb[3], double lab[3])
{
    double xyz[3];
    sb_mat3_apply(m, rgb, xyz);
    sb_xyz_to_lab(xyz, white, lab);
}

/* The colour statistics: a view's difference added (view n of those counted). */
static void colour_add(struct sb_sky_error_colour *stats, double de, int direction, int n)
{
    stats->mean += de;
    if (de > stats->max || n == 0) {
        stats->max = de;
        stats->worst_direction = direction;
    }
}

/* The largest CIEDE2000 from the reference's `ref` (Lab) that moving one
 * component of `base` by 2 `sigma` makes, base taken to linear Rec.709 by
 * `to_rgb` (NULL: it is). */
static double colour_noise(const double base[3], const double sigma[3], const double to_rgb[3][3],
                           const double to_xyz[3][3], const double white[3], const double ref[3])
{
    double worst = 0.0;
    for (int c = 0; c < 3; c++)
        for (int sign = -1; sign <= 1; sign += 2) {
            double moved[3] = {base[0], base[1], base[2]}, rgb[3], lab[3];
            moved[c] = fmax(moved[c] + sign * 2 * sigma[c], 0.0);
            if (to_rgb)
                sb_mat3_apply(to_rgb, moved, rgb);
            else
                memcpy(rgb, moved, sizeof(rgb));
            view_lab(to_xyz, white, rgb, lab);
            worst = fmax(worst, sb_ciede2000(lab, ref));
        }
    return worst;
}

static void summarise_colour(struct sb_sky_error_sun *sun)
{
    double m[3][3], white[3], y_max = 0;
    sb_rec709_to_xyz(m);
    for (int d = 0; d < SB_SKY_ERROR_DIRECTIONS; d++) {
        const double *pt = sun->directions[d].path_traced;
        if (!sun->directions[d].ground)
            y_max = fmax(y_max, m[1][0] * pt[0] + m[1][1] * pt[1] + m[1][2] * pt[2]);
    }
    sb_mat3_apply(m, (const double[3]){y_max, y_max, y_max}, white);
    struct sb_sky_error_colour stats = {0};
    sun->orders_colour = sun->product_colour = stats;
    sun->de_noise = 0;
    int n = 0;
    for (int d = 0; y_max > 0 && d < SB_SKY_ERROR_DIRECTIONS; d++) {
        const struct sb_sky_error_direction *dir = &sun->directions[d];
        if (dir->ground)
            continue;
        double ours[3], ref[3], orders[3], product[3];
        view_lab(m, white, dir->skybake, ours);
        view_lab(m, white, dir->path_traced, ref);
        view_lab(m, white, dir->orders, orders);
        view_lab(m, white, dir->product, product);
        colour_add(&sun->orders_colour, sb_ciede2000(orders, ref), d, n);
        colour_add(&sun->product_colour, sb_ciede2000(product, ref), d, n);
        colour_add(&stats, sb_ciede2000(ours, ref), d, n++);
        sun->de_noise = fmax(sun->de_noise, colour_noise(dir->path_traced, dir->std_error, NULL, m, white, ref));
    }
    sun->de_mean = n ? stats.mean / n : 0;
    sun->orders_colour.mean = n ? sun->orders_colour.mean / n : 0;
    sun->product_colour.mean = n ? sun->product_colour.mean / n : 0;
    sun->de_max = stats.max;
    sun->de_worst_direction = stats.worst_direction;
}

/* Wavelength i of n spread evenly over the grid from 380 to 810 nm (an
 * index of the grid). */
static int subset_index(int i, int n)
{
    return (int)lround(i * 43.0 / (n - 1)) + 2;
}

/* Each view's rgb in a scheme. */
static void scheme_rgb(const struct sb_sky_error_direction *dir, int scheme, const double convert[3][3],
                       const double sun_to_rgb[3][3], double rgb[3])
{
    double picked[SB_SPECTRAL_WAVELENGTHS], nm[SB_SPECTRAL_WAVELENGTHS], xyz[3];
    int n = 0;
    switch (scheme) {
    case SB_SKY_ERROR_WAVELENGTHS_6:
        for (; n < 6; n++) {
            nm[n] = sb_spectrum_nm(subset_index(n, 6));
            picked[n] = dir->spectral[subset_index(n, 6)];
        }
        break;
    case SB_SKY_ERROR_WAVELENGTHS_12:
    case SB_SKY_ERROR_SKYBAKE_12:
    case SB_SKY_ERROR_PRODUCT_12:
        for (; n < SB_SPECTRAL_WAVELENGTHS; n++) {
            nm[n] = sb_spectral_nm(n);
            int k = (int)lround((nm[n] - SB_SPECTRUM_FIRST_NM) / SB_SPECTRUM_STEP_NM);
            picked[n] = scheme == SB_SKY_ERROR_SKYBAKE_12   ? dir->skybake_12[n]
                        : scheme == SB_SKY_ERROR_PRODUCT_12 ? dir->product_12[n]
                                                            : dir->spectral[k];
        }
        break;
    }
    if (n) {
        sb_samples_to_xyz(picked, nm, n, xyz);
        sb_mat3_apply(sun_to_rgb, xyz, rgb);
        return;
    }
    bool traced = scheme == SB_SKY_ERROR_TRACED_PRIMARIES || scheme == SB_SKY_ERROR_TRACED_CONVERTED;
    const double *v = traced                                     ? dir->path_traced
                      : scheme == SB_SKY_ERROR_PRODUCT_PRIMARIES ? dir->product
                                                                 : dir->skybake;
    if (scheme == SB_SKY_ERROR_CONVERTED || scheme == SB_SKY_ERROR_TRACED_CONVERTED)
        sb_mat3_apply(convert, v, rgb);
    else
        memcpy(rgb, v, 3 * sizeof(double));
}

static void summarise_spectral(struct sb_sky_error_sun *sun, const double solar[3])
{
    double to_xyz[3][3], sun_to_rgb[3][3], convert[3][3], white[3], ref_rgb[SB_SKY_ERROR_DIRECTIONS][3];
    double sigma[SB_SKY_ERROR_DIRECTIONS][3], y_max = 0;
    sb_rec709_to_xyz(to_xyz);
    sb_sun_xyz_to_rec709(solar, sun_to_rgb);
    sb_channels_to_rec709(solar, convert);
    for (int d = 0; d < SB_SKY_ERROR_DIRECTIONS; d++) {
        const struct sb_sky_error_direction *dir = &sun->directions[d];
        double xyz[3], var[3] = {0, 0, 0};
        sb_spectrum_to_xyz(dir->spectral, xyz);
        for (int k = 0; k < SB_SPECTRUM_COUNT; k++) {
            double cmf[3];
            sb_cie1931_xyz(sb_spectrum_nm(k), cmf);
            for (int c = 0; c < 3; c++)
                var[c] += pow(SB_SPECTRUM_STEP_NM * cmf[c] * dir->spectral_error[k], 2);
        }
        for (int c = 0; c < 3; c++)
            sigma[d][c] = sqrt(var[c]);
        sb_mat3_apply(sun_to_rgb, xyz, ref_rgb[d]);
        if (!dir->ground)
            y_max =
                fmax(y_max, to_xyz[1][0] * ref_rgb[d][0] + to_xyz[1][1] * ref_rgb[d][1] + to_xyz[1][2] * ref_rgb[d][2]);
    }
    sb_mat3_apply(to_xyz, (const double[3]){y_max, y_max, y_max}, white);
    memset(sun->spectral, 0, sizeof(sun->spectral));
    sun->spectral_noise = 0;
    int n = 0;
    for (int d = 0; y_max > 0 && d < SB_SKY_ERROR_DIRECTIONS; d++) {
        const struct sb_sky_error_direction *dir = &sun->directions[d];
        if (dir->ground)
            continue;
        double ref[3], lab[3], rgb[3];
        view_lab(to_xyz, white, ref_rgb[d], ref);
        for (int scheme = 0; scheme < SB_SKY_ERROR_SCHEME_COUNT; scheme++) {
            scheme_rgb(dir, scheme, convert, sun_to_rgb, rgb);
            view_lab(to_xyz, white, rgb, lab);
            colour_add(&sun->spectral[scheme], sb_ciede2000(lab, ref), d, n);
        }
        n++;
        double xyz[3];
        sb_spectrum_to_xyz(dir->spectral, xyz);
        sun->spectral_noise = fmax(sun->spectral_noise, colour_noise(xyz, sigma[d], sun_to_rgb, to_xyz, white, ref));
    }
    for (int scheme = 0; n && scheme < SB_SKY_ERROR_SCHEME_COUNT; scheme++)
        sun->spectral[scheme].mean /= n;
}

/* The relative error over directions and channels of skybake's sky, or of
 * the orders' (`orders`), against the path tracer (floored at `floor`). */
enum sky { SKY_SKYBAKE, SKY_ORDERS, SKY_PRODUCT };

static const double *sky_of(const struct sb_sky_error_direction *dir, enum sky which)
{
    return which == SKY_ORDERS ? dir->orders : which == SKY_PRODUCT ? dir->product : dir->skybake;
}

static void radiance_error(const struct sb_sky_error_sun *sun, const double floor[3], enum sky which, double *max_rel,
                           double *rms_rel, double *mean_rel, int *worst_direction, int *worst_channel)
{
    double sum = 0, sum2 = 0;
    int n = 0;
    *max_rel = 0;
    for (int d = 0; d < SB_SKY_ERROR_DIRECTIONS; d++)
        for (int c = 0; c < 3; c++) {
            const struct sb_sky_error_direction *dir = &sun->directions[d];
            double ref = fmax(dir->path_traced[c], floor[c]);
            if (!(ref > 0))
                continue;
            double rel = (sky_of(dir, which)[c] - dir->path_traced[c]) / ref;
            if (fabs(rel) > *max_rel || n == 0) {
                *max_rel = fabs(rel);
                *worst_direction = d;
                *worst_channel = c;
            }
            sum += rel;
            sum2 += rel * rel;
            n++;
        }
    *rms_rel = n ? sqrt(sum2 / n) : 0;
    *mean_rel = n ? sum / n : 0;
}

/* The floor of the relative errors: 1e-3 of the brightest view in the
 * channel, of those at least 5 degrees from the sun. A view at the sun
 * looks into Mie's forward peak (at g = 0.99 thousands of times the sky
 * about it), which as the brightest raised the floor above the rest of
 * the sky and hid the haze's errors (12.7% rms at 30 degrees read 5.4%). */
static void error_floor(const struct sb_sky_error_sun *sun, double floor[3])
{
    floor[0] = floor[1] = floor[2] = 0;
    for (int d = 0; d < SB_SKY_ERROR_DIRECTIONS; d++) {
        const struct sb_sky_error_direction *dir = &sun->directions[d];
        double mu, mu_s, nu;
        sb_sky_error_cosines(dir->zenith_deg, dir->azimuth_deg, sun->elevation_deg, &mu, &mu_s, &nu);
        if (nu > cos(5.0 * SKY_PI / 180))
            continue;
        for (int c = 0; c < 3; c++)
            floor[c] = fmax(floor[c], 1e-3 * dir->path_traced[c]);
    }
}

static void summarise(struct sb_sky_error_sun *sun, const double solar[3])
{
    double floor[3], share = 0;
    error_floor(sun, floor);
    int lit = 0, unused_d, unused_c;
    sun->noise = 0;
    for (int d = 0; d < SB_SKY_ERROR_DIRECTIONS; d++)
        for (int c = 0; c < 3; c++) {
            const struct sb_sky_error_direction *dir = &sun->directions[d];
            double ref = fmax(dir->path_traced[c], floor[c]);
            if (!(ref > 0))
                continue;
            sun->noise = fmax(sun->noise, 2 * dir->std_error[c] / ref);
            if (!dir->ground && dir->path_traced[c] > 0) {
                share += 1 - dir->single[c] / dir->path_traced[c];
                lit++;
            }
        }
    radiance_error(sun, floor, SKY_SKYBAKE, &sun->max_rel, &sun->rms_rel, &sun->mean_rel, &sun->worst_direction,
                   &sun->worst_channel);
    radiance_error(sun, floor, SKY_ORDERS, &sun->orders_max_rel, &sun->orders_rms_rel, &sun->orders_mean_rel, &unused_d,
                   &unused_c);
    radiance_error(sun, floor, SKY_PRODUCT, &sun->product_max_rel, &sun->product_rms_rel, &sun->product_mean_rel,
                   &unused_d, &unused_c);
    sun->multiple_share = lit ? share / lit : 0;
    summarise_colour(sun);
    summarise_spectral(sun, solar);
}

enum sb_result sb_sky_error_run(struct sb_vk *vk, const char *scene_name, const struct sb_scene *scene,
                                const struct sb_sky_error_params *params, struct sb_sky_error_report *report)
{
    memset(report, 0, sizeof(*report));
    snprintf(report->scene, sizeof(report->scene), "%s", scene_name);
    report->altitude_km = scene->view.altitude_km;
    report->paths = params->paths > 0 ? params->paths : 16384;
    report->spectral_paths = params->spectral_paths > 0 ? params->spectral_paths : report->paths / 16;
    if (report->spectral_paths < 32)
        report->spectral_paths = 32;
    report->sun_count = params->sun_count > 0 ? params->sun_count : (int)(sizeof(default_suns) / sizeof(double));
    if (report->sun_count > SB_SKY_ERROR_MAX_SUNS)
        report->sun_count = SB_SKY_ERROR_MAX_SUNS;
    for (int s = 0; s < report->sun_count; s++) {
        struct sb_sky_error_sun *sun = &report->suns[s];
        sun->elevation_deg = params->sun_count > 0 ? params->sun_elevation_deg[s] : default_suns[s];
        for (int d = 0; d < SB_SKY_ERROR_DIRECTIONS; d++)
            sb_sky_error_view(&scene->atmosphere, report->altitude_km, d, &sun->directions[d].zenith_deg,
                              &sun->directions[d].azimuth_deg);
    }

    /* The products the sky reads, baked as a default bake bakes them: for
     * the scene's three channels, and for the 12 wavelengths as the
     * spectral products bake them, a band of three at a time. */
    struct job job = {0};
    struct sb_image luts[SB_PRODUCT_COUNT] = {0};
    struct sb_spectral *spectral = NULL;
    struct sb_atmosphere_baker *baker = NULL;
    struct sb_orders_settings product_grid = sb_orders_product_grid(&scene->atmosphere);
    struct sb_orders_ref *grid = sb_orders_grid_create(&scene->atmosphere, &product_grid);
    enum sb_result res = grid ? SB_OK : SB_ERR_NOMEM;
    job.grid = grid;
    if (!res)
        res = sb_atmosphere_baker_create(vk, &scene->atmosphere, &baker);
    const enum sb_product_id needed[] = {SB_PRODUCT_TRANSMITTANCE, SB_PRODUCT_MULTISCATTERING,
                                         SB_PRODUCT_IRRADIANCE_GROUND};
    for (size_t i = 0; i < sizeof(needed) / sizeof(needed[0]) && !res; i++)
        res = sb_atmosphere_bake(baker, needed[i], NULL, &luts[needed[i]], NULL, NULL);
    if (!res) { /* the orders product, as a bake makes it */
        struct sb_orders_result orders_result;
        res = sb_orders_bake(vk, baker, &scene->atmosphere, &product_grid, &luts[SB_PRODUCT_ORDERS], &orders_result);
        report->product_orders = orders_result.orders;
        report->product_grid = product_grid;
        report->product_gpu_ms = orders_result.gpu_ms;
    }
    sb_atmosphere_baker_destroy(&baker);
    if (!res)
        res = sb_spectral_create(vk, &scene->atmosphere, &spectral);
    static const enum sb_product_id band_needed[4] = {SB_PRODUCT_TRANSMITTANCE, SB_PRODUCT_MULTISCATTERING,
                                                      SB_PRODUCT_IRRADIANCE_GROUND, SB_PRODUCT_ORDERS};
    for (int b = 0; b < SB_SPECTRAL_BANDS && !res; b++) {
        job.band[b] = sb_spectral_band_params(spectral, b);
        for (int i = 0; i < 4 && !res; i++)
            res = sb_spectral_band_lut(spectral, b, band_needed[i], &job.band_luts[b][i], NULL);
    }
    if (res) {
        sb_error("%s: baking the sky's LUTs failed (%s)", scene_name, sb_result_name(res));
        goto done;
    }

    sb_info("%s: path tracing %d suns x %d directions x 3 channels, %d paths each, and x %d wavelengths, %d paths "
            "each",
            scene_name, report->sun_count, SB_SKY_ERROR_DIRECTIONS, report->paths, SB_SPECTRUM_COUNT,
            report->spectral_paths);
    struct sb_orders_ref *orders = NULL;
    if (params->orders) {
        double t_orders = sb_now_s();
        orders = sb_orders_ref_create(&scene->atmosphere, &params->orders_grid);
        if (!orders) {
            res = SB_ERR_NOMEM;
            sb_error("%s: the orders' reference: out of memory", scene_name);
            goto done;
        }
        report->orders = sb_orders_ref_orders(orders);
        report->orders_s = sb_now_s() - t_orders;
        job.orders = orders;
    }
    job.params = &scene->atmosphere;
    job.luts = luts;
    job.settings = params;
    job.report = report;
    for (int t = 0; t < TRIPLES; t++) {
        job.spectral[t] = scene->atmosphere;
        for (int c = 0; c < 3; c++)
            sb_atmosphere_at_wavelength(&scene->atmosphere, sb_spectrum_nm(3 * t + c), c, &job.spectral[t]);
    }
    double t0 = sb_now_s();
    sb_progress("sky-error: suns path traced", 0, (unsigned)report->sun_count);
    for (job.sun = 0; job.sun < report->sun_count; job.sun++) {
        sb_parallel_for(JOBS_PER_SUN, run_one, &job);
        sb_progress("sky-error: suns path traced", (unsigned)job.sun + 1, (unsigned)report->sun_count);
    }
    report->path_trace_s = sb_now_s() - t0;
    for (int s = 0; s < report->sun_count; s++)
        summarise(&report->suns[s], scene->atmosphere.solar_irradiance);

done:
    sb_orders_ref_destroy(&orders);
    sb_orders_ref_destroy(&grid);
    sb_spectral_destroy(&spectral);
    for (int i = 0; i < SB_PRODUCT_COUNT; i++)
        sb_image_finish(&luts[i]);
    return res;
}

static const char *channel_name(int c)
{
    return c == 0 ? "red" : c == 1 ? "green" : "blue";
}

static const char *const scheme_names[SB_SKY_ERROR_SCHEME_COUNT] = {
    "primaries",      "converted",  "traced_primaries",  "traced_converted", "wavelengths_6",
    "wavelengths_12", "skybake_12", "product_primaries", "product_12"};

static cJSON *triple(const double v[3])
{
    return cJSON_CreateDoubleArray(v, 3);
}

void sb_sky_error_print(const struct sb_sky_error_report *reports, int count, bool json)
{
    if (json) {
        cJSON *root = cJSON_CreateArray();
        for (int i = 0; i < count; i++) {
            const struct sb_sky_error_report *r = &reports[i];
            cJSON *o = cJSON_CreateObject();
            cJSON_AddStringToObject(o, "scene", r->scene);
            cJSON_AddNumberToObject(o, "altitude_km", r->altitude_km);
            cJSON_AddNumberToObject(o, "paths", r->paths);
            cJSON_AddNumberToObject(o, "spectral_paths", r->spectral_paths);
            cJSON_AddNumberToObject(o, "path_trace_s", r->path_trace_s);
            cJSON_AddNumberToObject(o, "product_orders", r->product_orders);
            const int grid[4] = {r->product_grid.r, r->product_grid.mu, r->product_grid.mu_s, r->product_grid.nu};
            cJSON_AddItemToObject(o, "product_grid", cJSON_CreateIntArray(grid, 4));
            cJSON *suns = cJSON_AddArrayToObject(o, "suns");
            for (int s = 0; s < r->sun_count; s++) {
                const struct sb_sky_error_sun *sun = &r->suns[s];
                cJSON *so = cJSON_CreateObject();
                cJSON_AddNumberToObject(so, "elevation_deg", sun->elevation_deg);
                cJSON_AddNumberToObject(so, "max_rel", sun->max_rel);
                cJSON_AddNumberToObject(so, "rms_rel", sun->rms_rel);
                cJSON_AddNumberToObject(so, "mean_rel", sun->mean_rel);
                cJSON_AddNumberToObject(so, "noise", sun->noise);
                cJSON_AddNumberToObject(so, "multiple_share", sun->multiple_share);
                if (r->orders) {
                    cJSON_AddNumberToObject(so, "orders_max_rel", sun->orders_max_rel);
                    cJSON_AddNumberToObject(so, "orders_rms_rel", sun->orders_rms_rel);
                    cJSON_AddNumberToObject(so, "orders_mean_rel", sun->orders_mean_rel);
                    cJSON_AddNumberToObject(so, "orders_ciede2000_mean", sun->orders_colour.mean);
                    cJSON_AddNumberToObject(so, "orders_ciede2000_max", sun->orders_colour.max);
                }
                cJSON_AddNumberToObject(so, "product_max_rel", sun->product_max_rel);
                cJSON_AddNumberToObject(so, "product_rms_rel", sun->product_rms_rel);
                cJSON_AddNumberToObject(so, "product_mean_rel", sun->product_mean_rel);
                cJSON_AddNumberToObject(so, "product_ciede2000_mean", sun->product_colour.mean);
                cJSON_AddNumberToObject(so, "product_ciede2000_max", sun->product_colour.max);
                cJSON_AddNumberToObject(so, "ciede2000_mean", sun->de_mean);
                cJSON_AddNumberToObject(so, "ciede2000_max", sun->de_max);
                cJSON_AddNumberToObject(so, "ciede2000_noise", sun->de_noise);
                cJSON *spectral = cJSON_AddObjectToObject(so, "spectral");
                for (int k = 0; k < SB_SKY_ERROR_SCHEME_COUNT; k++) {
                    cJSON *scheme = cJSON_AddObjectToObject(spectral, scheme_names[k]);
                    cJSON_AddNumberToObject(scheme, "ciede2000_mean", sun->spectral[k].mean);
                    cJSON_AddNumberToObject(scheme, "ciede2000_max", sun->spectral[k].max);
                }
                cJSON_AddNumberToObject(spectral, "ciede2000_noise", sun->spectral_noise);
                cJSON *dirs = cJSON_AddArrayToObject(so, "directions");
                for (int d = 0; d < SB_SKY_ERROR_DIRECTIONS; d++) {
                    const struct sb_sky_error_direction *dir = &sun->directions[d];
                    cJSON *dobj = cJSON_CreateObject();
                    cJSON_AddNumberToObject(dobj, "zenith_deg", dir->zenith_deg);
                    cJSON_AddNumberToObject(dobj, "azimuth_deg", dir->azimuth_deg);
                    cJSON_AddItemToObject(dobj, "skybake", triple(dir->skybake));
                    cJSON_AddItemToObject(dobj, "single", triple(dir->single));
                    cJSON_AddItemToObject(dobj, "path_traced", triple(dir->path_traced));
                    cJSON_AddItemToObject(dobj, "std_error", triple(dir->std_error));
                    if (r->orders)
                        cJSON_AddItemToObject(dobj, "orders", triple(dir->orders));
                    cJSON_AddItemToObject(dobj, "product", triple(dir->product));
                    cJSON_AddItemToObject(dobj, "spectral", cJSON_CreateDoubleArray(dir->spectral, SB_SPECTRUM_COUNT));
                    cJSON_AddItemToObject(dobj, "spectral_std_error",
                                          cJSON_CreateDoubleArray(dir->spectral_error, SB_SPECTRUM_COUNT));
                    cJSON_AddItemToArray(dirs, dobj);
                }
                cJSON_AddItemToArray(suns, so);
            }
            cJSON_AddItemToArray(root, o);
        }
        sb_json_emit(stdout, root);
        return;
    }
    for (int i = 0; i < count; i++) {
        const struct sb_sky_error_report *r = &reports[i];
        printf("%s: sky from %.6g km against the path tracer (%d paths per direction and channel, %.1f s)\n", r->scene,
               r->altitude_km, r->paths, r->path_trace_s);
        printf("  %8s %9s %9s %9s %9s %9s  %s\n", "sun deg", "max rel", "rms rel", "mean rel", "noise", "multiple",
               "worst at (zenith, azimuth from the sun)");
        for (int s = 0; s < r->sun_count; s++) {
            const struct sb_sky_error_sun *sun = &r->suns[s];
            const struct sb_sky_error_direction *w = &sun->directions[sun->worst_direction];
            printf("  %8.4g %9.3g %9.3g %+9.2g %9.2g %8.1f%%  %g, %g deg, %s\n", sun->elevation_deg, sun->max_rel,
                   sun->rms_rel, sun->mean_rel, sun->noise, 100 * sun->multiple_share, w->zenith_deg, w->azimuth_deg,
                   channel_name(sun->worst_channel));
        }
        printf("  with the orders product (%d orders; %dx%dx%dx%d nodes), as skybake shows it:\n", r->product_orders,
               r->product_grid.r, r->product_grid.mu, r->product_grid.mu_s, r->product_grid.nu);
        printf("  %8s %9s %9s %9s %15s\n", "sun deg", "max rel", "rms rel", "mean rel", "CIEDE2000");
        for (int s = 0; s < r->sun_count; s++) {
            const struct sb_sky_error_sun *sun = &r->suns[s];
            printf("  %8.4g %9.3g %9.3g %+9.2g %7.2f / %5.2f\n", sun->elevation_deg, sun->product_max_rel,
                   sun->product_rms_rel, sun->product_mean_rel, sun->product_colour.mean, sun->product_colour.max);
        }
        if (r->orders) {
            printf("  with multiple scattering by orders (fp64 reference, %d orders, %.1f s):\n", r->orders,
                   r->orders_s);
            printf("  %8s %9s %9s %9s %15s\n", "sun deg", "max rel", "rms rel", "mean rel", "CIEDE2000");
            for (int s = 0; s < r->sun_count; s++) {
                const struct sb_sky_error_sun *sun = &r->suns[s];
                printf("  %8.4g %9.3g %9.3g %+9.2g %7.2f / %5.2f\n", sun->elevation_deg, sun->orders_max_rel,
                       sun->orders_rms_rel, sun->orders_mean_rel, sun->orders_colour.mean, sun->orders_colour.max);
            }
        }
        printf(
            "  colour, CIEDE2000 over the views of the sky (linear Rec.709, D65 at the brightest view's luminance):\n");
        printf("  %8s %9s %9s %9s  %s\n", "sun deg", "mean", "max", "noise", "worst at (zenith, azimuth from the sun)");
        for (int s = 0; s < r->sun_count; s++) {
            const struct sb_sky_error_sun *sun = &r->suns[s];
            const struct sb_sky_error_direction *w = &sun->directions[sun->de_worst_direction];
            printf("  %8.4g %9.3g %9.3g %9.2g  %g, %g deg\n", sun->elevation_deg, sun->de_mean, sun->de_max,
                   sun->de_noise, w->zenith_deg, w->azimuth_deg);
        }
        printf("  colour against the spectral path tracer (%d wavelengths, 360 to 830 nm, %d paths each; CIEDE2000 "
               "mean / max):\n  skybake's sky and the three-channel path tracer's, each read as Rec.709 primaries or\n"
               "  converted (sb_channels_to_rec709); the spectral trace itself read at 6 and 12 wavelengths;\n"
               "  skybake's model at 12 wavelengths; the sky with the orders product as primaries and at 12\n"
               "  wavelengths (the spectral products, as skyview draws them):\n",
               SB_SPECTRUM_COUNT, r->spectral_paths);
        printf("  %8s %15s %15s %15s %15s %15s %15s %15s %15s %15s %9s\n", "sun deg", "primaries", "converted",
               "traced prim.", "traced conv.", "6 wavelengths", "12 wavelengths", "skybake at 12", "orders prim.",
               "orders at 12", "noise");
        for (int s = 0; s < r->sun_count; s++) {
            const struct sb_sky_error_sun *sun = &r->suns[s];
            printf("  %8.4g", sun->elevation_deg);
            for (int k = 0; k < SB_SKY_ERROR_SCHEME_COUNT; k++)
                printf(" %7.2f / %5.2f", sun->spectral[k].mean, sun->spectral[k].max);
            printf(" %9.2g\n", sun->spectral_noise);
        }
    }
}

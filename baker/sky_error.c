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
#include "parallel.h"
#include "pathtrace.h"

#define SKY_PI 3.14159265358979323846

/* Zenith angles from straight up to below the horizon (the ground, for a
 * camera in the air), each at the sun's azimuth, across and opposite; the
 * zenith once. A camera above the atmosphere looks down instead: the
 * nadir, three rings on the ground (0.5, 0.9 and 0.99 of the angle to its
 * edge) and two through the limb (grazing 5 and 30 km up). */
static const double zenith_deg[] = {30, 60, 80, 87, 120};
static const double azimuth_deg[] = {0, 90, 180};
static const double default_suns[] = {90, 30, 10, 2, -4};

static void direction_angles(const struct sb_atmosphere_params *p, double altitude_km, int i, double *zenith,
                             double *azimuth)
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

struct job {
    const struct sb_atmosphere_params *params;
    const struct sb_image *luts;
    const struct sb_sky_error_params *settings;
    struct sb_sky_error_report *report;
};

/* One (sun, direction, channel). */
static void run_one(void *user, int index)
{
    struct job *job = user;
    int channel = index % 3, d = index / 3 % SB_SKY_ERROR_DIRECTIONS, s = index / 3 / SB_SKY_ERROR_DIRECTIONS;
    struct sb_sky_error_sun *sun = &job->report->suns[s];
    struct sb_sky_error_direction *dir = &sun->directions[d];
    double zenith = dir->zenith_deg * SKY_PI / 180, azimuth = dir->azimuth_deg * SKY_PI / 180;
    double elevation = sun->elevation_deg * SKY_PI / 180;
    double mu = cos(zenith), mu_s = sin(elevation);
    double nu = fmax(-1.0, fmin(1.0, sin(zenith) * cos(elevation) * cos(azimuth) + mu * mu_s));
    double h = job->report->altitude_km, R = job->params->ground_radius_km, r = R + h;
    if (channel == 0) {
        dir->ground = mu < 0 && r * r * (mu * mu - 1) + R * R >= 0;
        sb_ref_sky_radiance(job->params, h, mu, mu_s, nu, &job->luts[SB_PRODUCT_TRANSMITTANCE],
                            &job->luts[SB_PRODUCT_MULTISCATTERING], &job->luts[SB_PRODUCT_IRRADIANCE_GROUND], NULL,
                            dir->skybake);
        sb_ref_sky_radiance(job->params, h, mu, mu_s, nu, &job->luts[SB_PRODUCT_TRANSMITTANCE], NULL, NULL, NULL,
                            dir->single);
    }
    struct sb_pathtrace_view view = {h, mu, mu_s, nu};
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
    sun->de_mean = sun->de_max = sun->de_noise = 0;
    sun->de_worst_direction = 0;
    int n = 0;
    for (int d = 0; y_max > 0 && d < SB_SKY_ERROR_DIRECTIONS; d++) {
        const struct sb_sky_error_direction *dir = &sun->directions[d];
        if (dir->ground)
            continue;
        double ours[3], ref[3];
        view_lab(m, white, dir->skybake, ours);
        view_lab(m, white, dir->path_traced, ref);
        double de = sb_ciede2000(ours, ref);
        sun->de_mean += de;
        if (de > sun->de_max || n == 0) {
            sun->de_max = de;
            sun->de_worst_direction = d;
        }
        n++;
        for (int c = 0; c < 3; c++)
            for (int sign = -1; sign <= 1; sign += 2) {
                double moved[3] = {dir->path_traced[0], dir->path_traced[1], dir->path_traced[2]}, lab[3];
                moved[c] = fmax(moved[c] + sign * 2 * dir->std_error[c], 0.0);
                view_lab(m, white, moved, lab);
                sun->de_noise = fmax(sun->de_noise, sb_ciede2000(lab, ref));
            }
    }
    sun->de_mean = n ? sun->de_mean / n : 0;
}

static void summarise(struct sb_sky_error_sun *sun)
{
    double floor[3] = {0, 0, 0};
    for (int d = 0; d < SB_SKY_ERROR_DIRECTIONS; d++)
        for (int c = 0; c < 3; c++)
            floor[c] = fmax(floor[c], 1e-3 * sun->directions[d].path_traced[c]);
    double sum2 = 0, sum = 0, share = 0;
    int n = 0, lit = 0;
    sun->max_rel = sun->noise = 0;
    for (int d = 0; d < SB_SKY_ERROR_DIRECTIONS; d++)
        for (int c = 0; c < 3; c++) {
            const struct sb_sky_error_direction *dir = &sun->directions[d];
            double ref = fmax(dir->path_traced[c], floor[c]);
            if (!(ref > 0))
                continue;
            double rel = (dir->skybake[c] - dir->path_traced[c]) / ref;
            if (fabs(rel) > sun->max_rel || n == 0) {
                sun->max_rel = fabs(rel);
                sun->worst_direction = d;
                sun->worst_channel = c;
            }
            sum += rel;
            sum2 += rel * rel;
            sun->noise = fmax(sun->noise, 2 * dir->std_error[c] / ref);
            n++;
            if (!dir->ground && dir->path_traced[c] > 0) {
                share += 1 - dir->single[c] / dir->path_traced[c];
                lit++;
            }
        }
    sun->rms_rel = n ? sqrt(sum2 / n) : 0;
    sun->mean_rel = n ? sum / n : 0;
    sun->multiple_share = lit ? share / lit : 0;
    summarise_colour(sun);
}

enum sb_result sb_sky_error_run(struct sb_vk *vk, const char *scene_name, const struct sb_scene *scene,
                                const struct sb_sky_error_params *params, struct sb_sky_error_report *report)
{
    memset(report, 0, sizeof(*report));
    snprintf(report->scene, sizeof(report->scene), "%s", scene_name);
    report->altitude_km = scene->view.altitude_km;
    report->paths = params->paths > 0 ? params->paths : 16384;
    report->sun_count = params->sun_count > 0 ? params->sun_count : (int)(sizeof(default_suns) / sizeof(double));
    if (report->sun_count > SB_SKY_ERROR_MAX_SUNS)
        report->sun_count = SB_SKY_ERROR_MAX_SUNS;
    for (int s = 0; s < report->sun_count; s++) {
        struct sb_sky_error_sun *sun = &report->suns[s];
        sun->elevation_deg = params->sun_count > 0 ? params->sun_elevation_deg[s] : default_suns[s];
        for (int d = 0; d < SB_SKY_ERROR_DIRECTIONS; d++)
            direction_angles(&scene->atmosphere, report->altitude_km, d, &sun->directions[d].zenith_deg,
                             &sun->directions[d].azimuth_deg);
    }

    /* The products the sky reads, baked as a default bake bakes them. */
    struct sb_image luts[SB_PRODUCT_COUNT] = {0};
    struct sb_atmosphere_baker *baker = NULL;
    enum sb_result res = sb_atmosphere_baker_create(vk, &scene->atmosphere, &baker);
    const enum sb_product_id needed[] = {SB_PRODUCT_TRANSMITTANCE, SB_PRODUCT_MULTISCATTERING,
                                         SB_PRODUCT_IRRADIANCE_GROUND};
    for (size_t i = 0; i < sizeof(needed) / sizeof(needed[0]) && !res; i++)
        res = sb_atmosphere_bake(baker, needed[i], NULL, &luts[needed[i]], NULL, NULL);
    sb_atmosphere_baker_destroy(&baker);
    if (res) {
        sb_error("%s: baking the sky's LUTs failed (%s)", scene_name, sb_result_name(res));
        goto done;
    }

    sb_info("%s: path tracing %d suns x %d directions x 3 channels, %d paths each", scene_name, report->sun_count,
            SB_SKY_ERROR_DIRECTIONS, report->paths);
    struct job job = {&scene->atmosphere, luts, params, report};
    double t0 = sb_now_s();
    sb_parallel_for(report->sun_count * SB_SKY_ERROR_DIRECTIONS * 3, run_one, &job);
    report->path_trace_s = sb_now_s() - t0;
    for (int s = 0; s < report->sun_count; s++)
        summarise(&report->suns[s]);

done:
    for (int i = 0; i < SB_ATMOSPHERE_PRODUCT_COUNT; i++)
        sb_image_finish(&luts[i]);
    return res;
}

static const char *channel_name(int c)
{
    return c == 0 ? "red" : c == 1 ? "green" : "blue";
}

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
            cJSON_AddNumberToObject(o, "path_trace_s", r->path_trace_s);
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
                cJSON_AddNumberToObject(so, "ciede2000_mean", sun->de_mean);
                cJSON_AddNumberToObject(so, "ciede2000_max", sun->de_max);
                cJSON_AddNumberToObject(so, "ciede2000_noise", sun->de_noise);
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
        printf(
            "  colour, CIEDE2000 over the views of the sky (linear Rec.709, D65 at the brightest view's luminance):\n");
        printf("  %8s %9s %9s %9s  %s\n", "sun deg", "mean", "max", "noise", "worst at (zenith, azimuth from the sun)");
        for (int s = 0; s < r->sun_count; s++) {
            const struct sb_sky_error_sun *sun = &r->suns[s];
            const struct sb_sky_error_direction *w = &sun->directions[sun->de_worst_direction];
            printf("  %8.4g %9.3g %9.3g %9.2g  %g, %g deg\n", sun->elevation_deg, sun->de_mean, sun->de_max,
                   sun->de_noise, w->zenith_deg, w->azimuth_deg);
        }
    }
}

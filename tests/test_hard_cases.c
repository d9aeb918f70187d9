/*
 * Every scene in data/scenes (the hard cases of docs/accuracy.md among
 * them) baked on the device with validation on, and checked:
 * - no NaN or Inf in any product;
 * - transmittance in [0, 1], and non-increasing as its ray lengthens: along
 *   each row of the LUT (one altitude) the ray from the point grows with
 *   x_mu, and for any density >= 0 the optical depth grows with it (each
 *   spherical shell is crossed more obliquely, and a downward ray goes
 *   deeper); and along rays, read as the runtime reads the LUT;
 * - multiple scattering and irradiances >= 0;
 * - agreement with the fp64 reference (accuracy.h): transmittance 1e-5 at
 *   every texel with T > 1e-6, the scattering products 1e-3 at the sparse
 *   probe texels;
 * - the bakes' sun table against fp64 at 1024 rays (5e-5 of T,
 *   check_sun_table);
 * - the sky from the scene's view (sb_ref_sky_radiance reading the baked
 *   LUTs, as the runtime does) finite and >= 0 over a fan of directions.
 * Scenes that share an atmosphere (the camera presets) share its bake.
 * Usage: test_hard_cases [SCENES_DIR]
 */
#include <dirent.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "accuracy.h"
#include "atmosphere.h"
#include "atmosphere_probe.h"
#include "atmosphere_probe.spv.h"
#include "atmosphere_ref.h"
#include "context.h"
#include "harness_vk.h"
#include "log.h"
#include "parallel.h"
#include "scene.h"

#ifndef SCENES_DIR
#define SCENES_DIR "data/scenes"
#endif

#define MAX_SCENES 64

struct baked {
    struct sb_atmosphere_params params;
    struct sb_image luts[SB_PRODUCT_COUNT];
};

static int compare_names(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* T along each row must not increase with x_mu. The slack is the bake's
 * accuracy (1e-5 relative, checked below) on both texels. */
static void check_transmittance_shape(const char *name, const struct sb_image *t)
{
    double low = 0, high = 0, rise = 0;
    int at_x = 0, at_y = 0;
    for (uint32_t y = 0; y < t->height; y++)
        for (uint32_t x = 0; x < t->width; x++)
            for (int c = 0; c < 3; c++) {
                double v = t->data[(y * t->width + x) * 3 + c];
                low = fmin(low, v);
                high = fmax(high, v);
                if (x + 1 < t->width) {
                    double next = t->data[(y * t->width + x + 1) * 3 + c];
                    double excess = next - v * (1 + 2e-5);
                    if (excess > rise) {
                        rise = excess;
                        at_x = (int)x;
                        at_y = (int)y;
                    }
                }
            }
    CHECK(low >= 0 && high <= 1, "%s: transmittance outside [0, 1]: %.9g to %.9g", name, low, high);
    CHECK(rise <= 0, "%s: transmittance rises by %.3g as its ray lengthens, texel (%d, %d)", name, rise, at_x, at_y);
}

/* Along rays from a fan of points and directions that leave the atmosphere,
 * T(x -> top) read from the LUT must not decrease with the distance walked
 * (T(x -> y) = T(x) / T(y) <= 1), up to the lookup's own error against
 * fp64 at those points plus the bake's 1e-5. */
static void check_transmittance_rays(const char *name, const struct sb_atmosphere_params *p, const struct sb_image *t)
{
    double R = p->ground_radius_km, top = p->top_radius_km, worst = 0;
    int rays = 0;
    for (int i = 0; i < 8; i++) {
        double r0 = R + (top - R) * i / 8.0;
        for (int j = 0; j <= 16; j++) {
            double mu = -1.0 + 2.0 * j / 16.0;
            if (mu < 0 && r0 * r0 * (1 - mu * mu) <= R * R * (1 + 1e-9))
                continue; /* hits the ground */
            double d = -r0 * mu + sqrt(top * top - r0 * r0 * (1 - mu * mu));
            double prev[3] = {-1, -1, -1}, prev_exact[3] = {-1, -1, -1};
            rays++;
            for (int k = 0; k <= 32; k++) {
                double s = d * k / 33.0;
                double r = sqrt(r0 * r0 + s * s + 2 * r0 * mu * s), m = (r0 * mu + s) / r, v[3], exact[3];
                sb_ref_transmittance_lookup(p, t, r, m, v);
                sb_ref_transmittance(p, r, m, 4, exact);
                for (int c = 0; c < 3; c++) {
                    if (prev[c] >= 0) {
                        /* a drop beyond what the two lookups' errors explain */
                        double err = fabs(v[c] - exact[c]) + fabs(prev[c] - prev_exact[c]) + 1e-5 * (v[c] + prev[c]);
                        worst = fmax(worst, (prev[c] - v[c]) - err);
                    }
                    prev[c] = v[c];
                    prev_exact[c] = exact[c];
                }
            }
        }
    }
    CHECK(worst <= 0, "%s: transmittance read along a ray falls by %.3g beyond the lookup error", name, worst);
    printf("%s: transmittance along %d rays: monotone within the lookup error\n", name, rays);
}

static void check_non_negative(const char *name, enum sb_product_id id, const struct sb_image *image)
{
    size_t n = sb_image_float_count(image);
    double low = 0;
    for (size_t i = 0; i < n; i++)
        low = fmin(low, image->data[i]);
    CHECK(low >= 0, "%s: %s has a negative value %.3g", name, sb_product_name(id), low);
}

/*
 * Known limits: where the default direction counts do not reach 1e-3
 * against fp64 (measured on lavapipe, 2026-11), each held to its measured
 * value plus a tenth so that it cannot grow unnoticed, each with its cause.
 * In the atmosphere as thick as its planet, high up, the planet's shadow
 * and the terminator on the ground cross the azimuth grid along curves, where
 * the azimuthal integrands kink; the midpoint rule converges as n^-2 across
 * a kink. At its top with the sun 5.6 deg above the horizontal,
 * multiscattering moves by 1.1e-3 from 12 to 16 azimuth nodes and by 4e-5
 * from 16 to 64; irradiance_sky's Mie at 3816 km, the sun 29.5 deg below
 * the horizontal, moves by 2e-3 between 16 and 32 (fp64 reference,
 * docs/accuracy.md; the reference shares that azimuth grid, so over the
 * bench's full probe set the atmosphere's scattering products are good to
 * about 1e-2). The fix would cut the azimuth at those crossings. (The limb's
 * light fading above the ozone, a 1.4e-2 / 6.6e-3 limit here, went with the
 * cut at 25 scale heights of tangent altitude in sphere.glsl; peaked phase
 * functions, |g| >= 0.99, with Mie's own grid around the peak,
 * cap_directions in baker/atmosphere_ref.c.)
 */
static const struct {
    const char *scene;
    enum sb_product_id product;
    double measured;
} known_limits[] = {
    /* with rings (sun_rings.glsl), which cut each ring at the shadow, 7.4e-4
     * at its top, texel (14, 31): what remains is the reference's azimuths */
    {"thick-atmosphere.json", SB_PRODUCT_MULTISCATTERING, 7.4e-4},
    {"thick-atmosphere.json", SB_PRODUCT_IRRADIANCE_SKY, 1.33e-3},
};

static double known_limit(const char *scene, enum sb_product_id id)
{
    for (size_t i = 0; i < sizeof(known_limits) / sizeof(known_limits[0]); i++)
        if (!strcmp(known_limits[i].scene, scene) && known_limits[i].product == id)
            return known_limits[i].measured;
    return 0;
}

static void check_reference(const char *name, const struct baked *b)
{
    for (int p = 0; p < SB_ATMOSPHERE_PRODUCT_COUNT; p++) {
        enum sb_product_id id = (enum sb_product_id)p;
        struct sb_accuracy_ref *ref = NULL;
        enum sb_result res = sb_accuracy_ref_create(&b->params, id, SB_ACCURACY_SPARSE, 0, 0, b->luts, &ref);
        CHECK(res == SB_OK, "%s: reference of %s", name, sb_product_name(id));
        if (res)
            continue;
        struct sb_error e;
        sb_accuracy_measure(ref, &b->luts[p], false, &e);
        double tolerance = id == SB_PRODUCT_TRANSMITTANCE ? 1e-5 : 1e-3, known = known_limit(name, id);
        printf("%s: %-17s max rel error %.3g (texel %u, %u channel %u), rms %.3g over %u values (%s)%s\n", name,
               sb_product_name(id), e.max_rel, e.worst_x, e.worst_y, e.worst_channel, e.rms_rel, e.count,
               sb_accuracy_ref_probe(ref), known ? "; a known limit, see known_limits" : "");
        if (known) /* the measured value plus a tenth, so that any growth fails */
            tolerance = 1.1 * known;
        CHECK(e.max_rel <= tolerance, "%s: %s is %.3g from fp64 (tolerance %g) at texel (%u, %u) channel %u", name,
              sb_product_name(id), e.max_rel, tolerance, e.worst_x, e.worst_y, e.worst_channel);
        sb_accuracy_ref_destroy(&ref);
    }
}

struct sky_job {
    const struct sb_scene *scene;
    const struct baked *b;
    double values[64][3];
};

static void sky_direction(void *user, int i)
{
    struct sky_job *job = user;
    const struct sb_scene *s = job->scene;
    /* 16 zenith angles from up to down, 4 azimuths from the sun's to its opposite */
    double zenith = M_PI * (i % 16) / 15.0, phi = M_PI * (i / 16) / 3.0;
    double elev = s->view.sun_elevation_deg * M_PI / 180.0;
    double mu = cos(zenith), mu_s = sin(elev);
    double nu = sin(zenith) * cos(elev) * cos(phi) + mu * mu_s;
    sb_ref_sky_radiance(&job->b->params, s->view.altitude_km, mu, mu_s, nu, &job->b->luts[SB_PRODUCT_TRANSMITTANCE],
                        &job->b->luts[SB_PRODUCT_MULTISCATTERING], &job->b->luts[SB_PRODUCT_IRRADIANCE_GROUND], NULL,
                        job->values[i]);
}

static void check_sky(const char *name, const struct sb_scene *scene, const struct baked *b)
{
    struct sky_job *job = calloc(1, sizeof(*job));
    job->scene = scene;
    job->b = b;
    sb_parallel_for(64, sky_direction, job);
    double low = INFINITY, high = 0;
    bool finite = true;
    for (int i = 0; i < 64; i++)
        for (int c = 0; c < 3; c++) {
            finite = finite && isfinite(job->values[i][c]);
            low = fmin(low, job->values[i][c]);
            high = fmax(high, job->values[i][c]);
        }
    printf("%s: sky from %.6g km, sun at %g deg: radiance %.3g to %.3g over 64 directions\n", name,
           scene->view.altitude_km, scene->view.sun_elevation_deg, low, high);
    CHECK(finite && low >= 0, "%s: sky radiance not finite or negative (min %.3g)", name, low);
    CHECK(high > 0, "%s: the sky is black from its view", name);
    free(job);
}

/*
 * The bakes' sun table off the earth: its transmittance at 1024 rays from
 * the ground to the top against fp64 (atmosphere_probe.h). Its nodes are
 * laid out by the atmosphere's scale heights and thickness, so its error
 * moves with their ratios: 1.2e-5 in optical depth on the earth (whose
 * design bound, 2e-5, test_atmosphere holds), 2.2e-5 on mars, 2.6e-5 in
 * the thick atmosphere, 1.1e-6 on the tiny planet (lavapipe, 2026-11-24).
 * The bound, 5e-5 of T, keeps the table's share a twentieth of the 1e-3
 * the scattering products are held to here, which the sun's transmittance
 * enters linearly. At half the table's nodes each way the error grows six-
 * to sevenfold, and all three fail (8.3e-5, 1.6e-4, 1.6e-4).
 */
static void check_sun_table(const char *name, struct sb_atmosphere_baker *baker,
                            const struct sb_atmosphere_params *params)
{
    enum { RECORDS = 1024 };
    const double bound = 5e-5;
    float *rec = calloc((size_t)RECORDS * PROBE_FLOATS, sizeof(float));
    float(*rays)[2] = calloc(RECORDS, sizeof(*rays));
    for (int k = 0; k < RECORDS; k++) {
        float *in = rec + k * PROBE_FLOATS;
        in[1] = 1.0f; /* the probe's other inputs: the zenith from the ground, the LUTs' corners */
        sun_table_ray(params, k, &rays[k][0], &rays[k][1]);
        in[PROBE_SUN] = rays[k][0];
        in[PROBE_SUN + 1] = rays[k][1];
    }
    enum sb_result res = sb_atmosphere_run_kernel(baker, sb_spv_atmosphere_probe, sizeof(sb_spv_atmosphere_probe), rec,
                                                  RECORDS, PROBE_FLOATS);
    CHECK(res == SB_OK, "%s: probe kernel: %s", name, sb_result_name(res));
    struct sun_table_worst w = {0};
    for (int k = 0; !res && k < RECORDS; k++)
        sun_table_record(params, rays[k][0], rays[k][1], rec + k * PROBE_FLOATS + PROBE_SUN, bound, &w);
    printf("%s: sun table: worst error minus (%.3g + 4-ulp sensitivity) %.3g over %d values (h %.4g mu %.6g: %.3g "
           "in optical depth)\n",
           name, bound, w.excess, w.count, w.h, w.mu, w.tau);
    CHECK(!res && w.count > RECORDS && w.excess <= 0, "%s: sun table: %.3g beyond its bound over %d values", name,
          w.excess, w.count);
    free(rays);
    free(rec);
}

static bool bake_all(struct sb_vk *vk, const char *name, struct baked *b)
{
    struct sb_atmosphere_baker *baker = NULL;
    bool ok = sb_atmosphere_baker_create(vk, &b->params, &baker) == SB_OK;
    for (int p = 0; p < SB_ATMOSPHERE_PRODUCT_COUNT && ok; p++) {
        enum sb_product_id id = (enum sb_product_id)p;
        ok = sb_atmosphere_bake(baker, id, NULL, &b->luts[p], NULL, NULL) == SB_OK;
        CHECK(ok, "%s: baking %s", name, sb_product_name(id));
        if (ok)
            CHECK(sb_image_find_nonfinite(&b->luts[p]) < 0, "%s: %s holds NaN or Inf", name, sb_product_name(id));
    }
    if (ok)
        check_sun_table(name, baker, &b->params);
    sb_atmosphere_baker_destroy(&baker);
    return ok;
}

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : SCENES_DIR;
    char *names[MAX_SCENES];
    int count = 0;
    DIR *d = opendir(dir);
    CHECK(d != NULL, "cannot list %s", dir);
    if (!d)
        return test_finish("hard cases");
    for (struct dirent *e; (e = readdir(d)) && count < MAX_SCENES;) {
        size_t len = strlen(e->d_name);
        if (len > 5 && !strcmp(e->d_name + len - 5, ".json"))
            names[count++] = strdup(e->d_name);
    }
    closedir(d);
    qsort(names, (size_t)count, sizeof(names[0]), compare_names);
    CHECK(count >= 14, "%d scenes in %s, expected the 14 presets at least", count, dir);

    struct sb_vk *vk;
    enum sb_result res = test_vulkan(false, &vk);
    if (res == SB_ERR_NO_DEVICE)
        return test_no_device();

    static struct baked baked[MAX_SCENES];
    int baked_count = 0;
    for (int i = 0; i < count && !res; i++) {
        char path[4096];
        snprintf(path, sizeof(path), "%s/%s", dir, names[i]);
        struct sb_scene scene;
        res = sb_scene_load(path, &scene);
        CHECK(res == SB_OK, "%s: %s", path, sb_result_name(res));
        if (res)
            break;
        struct baked *b = NULL;
        for (int k = 0; k < baked_count && !b; k++)
            if (!memcmp(&baked[k].params, &scene.atmosphere, sizeof(scene.atmosphere)))
                b = &baked[k];
        if (!b) {
            b = &baked[baked_count++];
            b->params = scene.atmosphere;
            if (!bake_all(vk, names[i], b))
                continue;
            check_transmittance_shape(names[i], &b->luts[SB_PRODUCT_TRANSMITTANCE]);
            check_transmittance_rays(names[i], &b->params, &b->luts[SB_PRODUCT_TRANSMITTANCE]);
            for (int p = SB_PRODUCT_MULTISCATTERING; p < SB_ATMOSPHERE_PRODUCT_COUNT; p++)
                check_non_negative(names[i], (enum sb_product_id)p, &b->luts[p]);
            check_reference(names[i], b);
        }
        check_sky(names[i], &scene, b);
    }
    for (int k = 0; k < baked_count; k++)
        for (int p = 0; p < SB_PRODUCT_COUNT; p++)
            sb_image_finish(&baked[k].luts[p]);
    for (int i = 0; i < count; i++)
        free(names[i]);
    CHECK(sb_vk_validation_messages(vk) == 0, "%u validation messages", sb_vk_validation_messages(vk));
    sb_vk_destroy(&vk);
    return test_finish("hard cases");
}

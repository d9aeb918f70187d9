/*
 * The atmosphere family (Hillaire 2020's LUTs, Bruneton 2017's irradiance):
 * keys, bakes at the default settings or the cheapest within a scene's
 * tolerance, and adoption of reused products (family.h).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accuracy.h"
#include "atmosphere.h"
#include "family.h"
#include "log.h"
#include "orders.h"
#include "spectral.h"
#include "spectrum.h"

/* The family's state: the scene's baker, and its bands' for the spectral
 * products (made when the first is baked). */
struct atmosphere_state {
    struct sb_atmosphere_baker *baker;
    struct sb_spectral *spectral;
};

/*
 * Bake product `id` with the cheapest setting (device-independent cost,
 * sb_atmosphere_settings_cost) whose max relative error against the fp64
 * reference, at the probe points accuracy.h names, is within `tolerance`.
 * Candidates are baked cheapest first until one is; *image holds it and the
 * baker keeps it for the products that read it.
 */
static enum sb_result bake_to_tolerance(struct sb_atmosphere_baker *baker, const struct sb_atmosphere_params *params,
                                        enum sb_product_id id, double tolerance,
                                        const struct sb_image baked[SB_PRODUCT_COUNT], struct sb_image *image,
                                        struct sb_atmosphere_settings *used, struct sb_error *error, char *probe,
                                        size_t probe_size, double *gpu_ms)
{
    const char *name = sb_product_name(id);
    struct sb_accuracy_ref *ref = NULL;
    enum sb_result res = sb_accuracy_ref_create(params, id, false, 0, 0, baked, &ref);
    if (res)
        return res;
    snprintf(probe, probe_size, "%s", sb_accuracy_ref_probe(ref));
    struct sb_atmosphere_settings candidates[SB_ATMOSPHERE_MAX_CANDIDATES];
    int count = sb_atmosphere_candidates(id, candidates);
    double best = INFINITY;
    char best_label[48] = "", label[48];
    double total_ms = 0;
    res = SB_ERR_TOLERANCE;
    for (int i = 0; i < count; i++) {
        double ms = 0;
        sb_image_finish(image);
        enum sb_result r = sb_atmosphere_bake(baker, id, &candidates[i], image, used, &ms);
        if (r) {
            res = r;
            break;
        }
        total_ms += ms;
        sb_accuracy_measure(ref, image, false, error);
        sb_atmosphere_settings_label(id, used, label, sizeof(label));
        sb_debug("%s: %s: max rel error %.3g (tolerance %g)", name, label, error->max_rel, tolerance);
        if (error->max_rel < best) {
            best = error->max_rel;
            snprintf(best_label, sizeof(best_label), "%s", label);
        }
        if (error->max_rel <= tolerance) {
            sb_info("%s: %s is the cheapest setting within tolerance %g (max rel error %.3g at %s)", name, label,
                    tolerance, error->max_rel, probe);
            res = SB_OK;
            break;
        }
    }
    if (res == SB_ERR_TOLERANCE)
        sb_error("%s: no setting reaches tolerance %g; the best reachable is %.3g (%s), at %s", name, tolerance, best,
                 best_label, probe);
    if (res)
        sb_image_finish(image);
    *gpu_ms = total_ms;
    sb_accuracy_ref_destroy(&ref);
    return res;
}

/* The settings' JSON object with the tolerance and the measured error added. */
static void add_error_json(char *json, size_t size, double tolerance, const struct sb_error *e, const char *probe)
{
    sb_settings_json_add(json, size,
                         ",\"tolerance\":%.17g,\"error\":{\"max_rel\":%.6g,\"rms_rel\":%.6g,\"values\":%u,"
                         "\"against\":\"fp64 reference\",\"at\":\"%s\"}",
                         tolerance, e->max_rel, e->rms_rel, e->count, probe);
}

/* The parameters a product's kernels read: the medium for all; the ground's
 * albedo and the sun's irradiance for the scattering products; Mie's g for
 * those whose phase functions are not isotropic (multiscattering's is). */
static void key_params(enum sb_product_id id, const struct sb_atmosphere_params *p, struct sb_key_text *key)
{
    sb_key_add(key, " ground_radius_km=%a top_radius_km=%a rayleigh_scale_height_km=%a mie_scale_height_km=%a",
               p->ground_radius_km, p->top_radius_km, p->rayleigh_scale_height_km, p->mie_scale_height_km);
    sb_key_add3(key, "rayleigh_scattering_per_km", p->rayleigh_scattering_per_km);
    sb_key_add3(key, "mie_scattering_per_km", p->mie_scattering_per_km);
    sb_key_add3(key, "mie_absorption_per_km", p->mie_absorption_per_km);
    sb_key_add3(key, "ozone_absorption_per_km", p->ozone_absorption_per_km);
    sb_key_add(key, " ozone_center_km=%a ozone_half_width_km=%a", p->ozone_center_km, p->ozone_half_width_km);
    if (id == SB_PRODUCT_TRANSMITTANCE)
        return;
    sb_key_add3(key, "ground_albedo", p->ground_albedo);
    sb_key_add3(key, "solar_irradiance", p->solar_irradiance);
    if (id != SB_PRODUCT_MULTISCATTERING)
        sb_key_add(key, " mie_g=%a", p->mie_g);
}

#define BIT(p) (1u << (p))

/* The orders read transmittance; under a tolerance, they are measured
 * against Hillaire's LUTs, which they read too. */
static uint32_t atmosphere_depends_on(enum sb_product_id id)
{
    switch (id) {
    case SB_PRODUCT_ORDERS:
        return BIT(SB_PRODUCT_TRANSMITTANCE) | BIT(SB_PRODUCT_MULTISCATTERING) | BIT(SB_PRODUCT_IRRADIANCE_GROUND);
    /* The spectral products bake what they read for themselves
     * (spectral.h); a runtime draws the three together, and with the
     * orders (and what they read): naming spectral_orders brings them all. */
    case SB_PRODUCT_SPECTRAL_TRANSMITTANCE:
        return 0;
    case SB_PRODUCT_SPECTRAL_IRRADIANCE_GROUND:
        return BIT(SB_PRODUCT_SPECTRAL_TRANSMITTANCE);
    case SB_PRODUCT_SPECTRAL_ORDERS:
        return BIT(SB_PRODUCT_ORDERS) | BIT(SB_PRODUCT_SPECTRAL_TRANSMITTANCE) |
               BIT(SB_PRODUCT_SPECTRAL_IRRADIANCE_GROUND);
    default:
        return sb_atmosphere_product(id)->depends_on;
    }
}

/* The suns a tolerance is measured at: the scene's, or the day's when it
 * gives no view (sky-error's from noon to a low sun). */
static int orders_suns(const struct sb_scene *scene, double suns[4])
{
    static const double day[4] = {90, 30, 10, 2};
    if (scene->has_view) {
        suns[0] = scene->view.sun_elevation_deg;
        return 1;
    }
    memcpy(suns, day, sizeof(day));
    return 4;
}

/* The orders' grid and their stopping rule, for a key. */
static void orders_grid_key(const struct sb_scene *scene, struct sb_key_text *key)
{
    struct sb_orders_settings grid = sb_orders_product_grid(&scene->atmosphere);
    struct sb_orders_settings s = sb_orders_settings_resolve(&grid);
    struct sb_atmosphere_params medium;
    sb_key_add(key, " grid %dx%dx%dx%d nu power %a top %a orders %d until %a delta-M %a", s.r, s.mu, s.mu_s, s.nu,
               sb_orders_azimuth_power(&scene->atmosphere), sb_orders_top_km(&scene->atmosphere), s.max_order,
               s.tolerance, sb_orders_medium(&scene->atmosphere, &medium));
}

static void orders_code_key(struct sb_key_text *key)
{
    char code[SB_HASH_HEX_SIZE];
    sb_orders_code_hash(code);
    sb_key_add(key, " code %s", code);
}

/* What the artifact's settings say of an orders bake of `p`, after `first`
 * (the object's opening fields, "{" for none); the grid's altitude ratio
 * where it is not NAN. */
static void orders_settings(struct sb_artifact *a, const char *first, const struct sb_atmosphere_params *p,
                            const struct sb_orders_settings *grid, const struct sb_orders_result *r,
                            double height_ratio)
{
    struct sb_orders_settings s = sb_orders_settings_resolve(grid);
    struct sb_atmosphere_params medium;
    int n = snprintf(a->settings_json, sizeof(a->settings_json),
                     "%s\"r\":%d,\"mu\":%d,\"mu_s\":%d,\"nu\":%d,\"nu_power\":%.17g,\"top_km\":%.17g,\"delta_m\":%.17g",
                     first, s.r, s.mu, s.mu_s, s.nu, sb_orders_azimuth_power(p), sb_orders_top_km(p),
                     sb_orders_medium(p, &medium));
    if (!isnan(height_ratio) && n > 0 && (size_t)n < sizeof(a->settings_json))
        n += snprintf(a->settings_json + n, sizeof(a->settings_json) - (size_t)n, ",\"height_ratio\":%.17g",
                      height_ratio);
    if (n > 0 && (size_t)n < sizeof(a->settings_json))
        snprintf(a->settings_json + n, sizeof(a->settings_json) - (size_t)n,
                 ",\"orders\":%d,\"last_share\":%.6g,\"until\":%.17g,\"tail\":[%.6g,%.6g,%.6g]}", r->orders,
                 r->last_share, s.tolerance, r->tail[0], r->tail[1], r->tail[2]);
}

static void orders_key(const struct sb_scene *scene, struct sb_key_text *key)
{
    orders_grid_key(scene, key);
    if (scene->tolerance[SB_PRODUCT_ORDERS] > 0) {
        double suns[4];
        int n = orders_suns(scene, suns);
        sb_key_add(key, " tolerance %a at altitude %a", scene->tolerance[SB_PRODUCT_ORDERS], scene->view.altitude_km);
        for (int i = 0; i < n; i++)
            sb_key_add(key, " sun %a", suns[i]);
    }
    orders_code_key(key);
}

/*
 * Bake the orders; under a tolerance, decline them (an empty image) where
 * Hillaire's multiple scattering is within it of them, rms over
 * sky-error's views at the scene's suns.
 */
static enum sb_result orders_bake(struct sb_atmosphere_baker *baker, struct sb_vk *vk, const struct sb_scene *scene,
                                  const struct sb_image baked[SB_PRODUCT_COUNT], struct sb_image *image,
                                  struct sb_artifact *a)
{
    struct sb_orders_result r;
    struct sb_orders_settings grid = sb_orders_product_grid(&scene->atmosphere);
    enum sb_result res = sb_orders_bake(vk, baker, &scene->atmosphere, &grid, image, &r);
    if (res)
        return res;
    a->gpu_ms = r.gpu_ms;
    struct sb_orders_settings s = sb_orders_settings_resolve(&grid);
    orders_settings(a, "{", &scene->atmosphere, &grid, &r, sb_orders_height_ratio(&scene->atmosphere, s.r));
    double tolerance = scene->tolerance[SB_PRODUCT_ORDERS];
    if (tolerance <= 0)
        return SB_OK;
    double suns[4], rms, worst;
    int n = orders_suns(scene, suns);
    sb_orders_hillaire_error(&scene->atmosphere, baked, image, scene->view.altitude_km, suns, n, &rms, &worst);
    sb_settings_json_add(a->settings_json, sizeof(a->settings_json),
                         ",\"tolerance\":%.17g,\"hillaire\":{\"rms_rel\":%.6g,\"max_rel\":%.6g,\"suns\":%d}", tolerance,
                         rms, worst, n);
    if (rms <= tolerance) {
        sb_info("orders: Hillaire's multiple scattering is within tolerance %g of them (rms %.3g, worst %.3g over "
                "%d sun%s): not needed",
                tolerance, rms, worst, n, n > 1 ? "s" : "");
        sb_image_finish(image);
    } else {
        sb_info("orders: Hillaire's multiple scattering is %.3g rms off them (worst %.3g), beyond tolerance %g: "
                "baked",
                rms, worst, tolerance);
    }
    return SB_OK;
}

/* A spectral product's: each band's scene (what the spectrum's tables
 * made of the scene's), and the three-channel bake's settings and kernels. */
static void spectral_key(const struct sb_scene *scene, enum sb_product_id id, struct sb_key_text *key)
{
    enum sb_product_id base = sb_spectral_base(id);
    for (int b = 0; b < SB_SPECTRAL_BANDS; b++) {
        struct sb_atmosphere_params band;
        sb_spectral_band(&scene->atmosphere, b, &band);
        sb_key_add(key, " band %d at %a %a %a nm", b, sb_spectral_nm(3 * b), sb_spectral_nm(3 * b + 1),
                   sb_spectral_nm(3 * b + 2));
        key_params(base, &band, key);
    }
    char settings[1024], code[SB_HASH_HEX_SIZE];
    if (base == SB_PRODUCT_ORDERS) {
        orders_grid_key(scene, key);
        orders_code_key(key);
    }
    /* the LUTs each band's bake of `base` reads, and its own */
    for (enum sb_product_id p = SB_PRODUCT_TRANSMITTANCE; p <= SB_PRODUCT_IRRADIANCE_GROUND && p <= base; p++) {
        sb_atmosphere_settings_json(p, &sb_atmosphere_product(p)->defaults, settings, sizeof(settings));
        sb_atmosphere_code_hash(p, code);
        sb_key_add(key, " %s defaults %s code %s", sb_product_name(p), settings, code);
    }
}

static void atmosphere_key(void *state, const struct sb_scene *scene, enum sb_product_id id, struct sb_key_text *key)
{
    char settings[1024], code[SB_HASH_HEX_SIZE];
    if (sb_spectral_base(id) != SB_PRODUCT_COUNT) {
        spectral_key(scene, id, key);
        return;
    }
    key_params(id, &scene->atmosphere, key);
    if (id == SB_PRODUCT_ORDERS) {
        orders_key(scene, key);
        return;
    }
    if (scene->tolerance[id] > 0) {
        sb_key_add(key, " tolerance=%a candidates", scene->tolerance[id]);
        struct sb_atmosphere_settings candidates[SB_ATMOSPHERE_MAX_CANDIDATES];
        int count = sb_atmosphere_candidates(id, candidates);
        for (int i = 0; i < count; i++) {
            sb_atmosphere_settings_json(id, &candidates[i], settings, sizeof(settings));
            sb_key_add(key, " %s", settings);
        }
    } else {
        sb_atmosphere_settings_json(id, &sb_atmosphere_product(id)->defaults, settings, sizeof(settings));
        sb_key_add(key, " defaults %s", settings);
    }
    sb_atmosphere_code_hash(id, code);
    sb_key_add(key, " code %s", code);
}

static enum sb_result atmosphere_create(struct sb_vk *vk, const struct sb_scene *scene, void **state)
{
    struct atmosphere_state *s = calloc(1, sizeof(*s));
    *state = s;
    if (!s)
        return SB_ERR_NOMEM;
    return sb_atmosphere_baker_create(vk, &scene->atmosphere, &s->baker);
}

static void atmosphere_destroy(void **state)
{
    struct atmosphere_state *s = *state;
    if (s) {
        sb_atmosphere_baker_destroy(&s->baker);
        sb_spectral_destroy(&s->spectral);
        free(s);
    }
    *state = NULL;
}

static enum sb_result spectral_bake(struct atmosphere_state *state, struct sb_vk *vk, const struct sb_scene *scene,
                                    enum sb_product_id id, struct sb_image *image, struct sb_artifact *a)
{
    enum sb_result res = SB_OK;
    if (!state->spectral && (res = sb_spectral_create(vk, &scene->atmosphere, &state->spectral)))
        return res;
    struct sb_orders_result orders;
    if ((res = sb_spectral_bake(state->spectral, id, image, &a->gpu_ms, &orders)))
        return res;
    char head[160];
    int n = snprintf(head, sizeof(head), "{\"bands\":%d,\"nm\":[", SB_SPECTRAL_BANDS);
    for (int i = 0; i < SB_SPECTRAL_WAVELENGTHS; i++)
        n += snprintf(head + n, sizeof(head) - (size_t)n, "%s%g", i ? "," : "", sb_spectral_nm(i));
    snprintf(head + n, sizeof(head) - (size_t)n, "]");
    if (sb_spectral_base(id) == SB_PRODUCT_ORDERS) {
        strncat(head, ",", sizeof(head) - strlen(head) - 1);
        struct sb_orders_settings grid = sb_orders_product_grid(&scene->atmosphere);
        orders_settings(a, head, &scene->atmosphere, &grid, &orders, NAN);
    } else {
        snprintf(a->settings_json, sizeof(a->settings_json), "%s}", head);
    }
    return SB_OK;
}

static enum sb_result atmosphere_bake(void *state, struct sb_vk *vk, const struct sb_scene *scene,
                                      enum sb_product_id id, const struct sb_image baked[SB_PRODUCT_COUNT],
                                      struct sb_image *image, struct sb_artifact *a)
{
    struct atmosphere_state *st = state;
    struct sb_atmosphere_baker *baker = st->baker;
    if (sb_spectral_base(id) != SB_PRODUCT_COUNT)
        return spectral_bake(st, vk, scene, id, image, a);
    if (id == SB_PRODUCT_ORDERS)
        return orders_bake(baker, vk, scene, baked, image, a);
    struct sb_atmosphere_settings used;
    struct sb_error error;
    char probe[96];
    double tolerance = scene->tolerance[id];
    enum sb_result res;
    if (tolerance > 0)
        res = bake_to_tolerance(baker, &scene->atmosphere, id, tolerance, baked, image, &used, &error, probe,
                                sizeof(probe), &a->gpu_ms);
    else
        res = sb_atmosphere_bake(baker, id, NULL, image, &used, &a->gpu_ms);
    if (res)
        return res;
    sb_atmosphere_settings_json(id, &used, a->settings_json, sizeof(a->settings_json));
    if (tolerance > 0)
        add_error_json(a->settings_json, sizeof(a->settings_json), tolerance, &error, probe);
    return SB_OK;
}

static enum sb_result atmosphere_adopt(void *state, enum sb_product_id id, const struct sb_image *image)
{
    /* no product reads the orders; the spectral products bake what they read */
    if (id == SB_PRODUCT_ORDERS || sb_spectral_base(id) != SB_PRODUCT_COUNT)
        return SB_OK;
    return sb_atmosphere_adopt(((struct atmosphere_state *)state)->baker, id, image);
}

static uint32_t atmosphere_kernels(void *state, const struct sb_scene *scene, enum sb_product_id id,
                                   struct sb_pipeline_params out[SB_FAMILY_KERNELS_MAX])
{
    _Static_assert(SB_ATMOSPHERE_KERNELS_MAX <= SB_FAMILY_KERNELS_MAX, "room for the atmosphere's kernels");
    _Static_assert(SB_ORDERS_KERNEL_COUNT <= SB_FAMILY_KERNELS_MAX, "room for the orders' kernels");
    struct atmosphere_state *st = state;
    enum sb_product_id base = sb_spectral_base(id);
    if (base != SB_PRODUCT_COUNT) /* the three-channel kernels, for each band */
        return base == SB_PRODUCT_ORDERS ? sb_orders_kernels(out) : sb_atmosphere_kernels(st->baker, base, NULL, out);
    if (id == SB_PRODUCT_ORDERS)
        return sb_orders_kernels(out);
    /* to a tolerance, the candidates bake cheapest first: the first's */
    struct sb_atmosphere_settings candidates[SB_ATMOSPHERE_MAX_CANDIDATES];
    bool first = scene->tolerance[id] > 0 && sb_atmosphere_candidates(id, candidates) > 0;
    return sb_atmosphere_kernels(st->baker, id, first ? &candidates[0] : NULL, out);
}

const struct sb_family_baker sb_atmosphere_family = {
    .depends_on = atmosphere_depends_on,
    .key = atmosphere_key,
    .create = atmosphere_create,
    .destroy = atmosphere_destroy,
    .bake = atmosphere_bake,
    .adopt = atmosphere_adopt,
    .kernels = atmosphere_kernels,
};

/*
 * The scene's "atmosphere" section, the scene's core (every scene has one):
 * the presets, one table row a key with its range, parsing, validation and
 * the normalised form (docs/scene.md). scene.c reads the rest of the scene.
 */
#include <cJSON.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "config.h"
#include "family.h"
#include "json.h"
#include "log.h"
#include "scene.h"

void sb_atmosphere_preset_earth(struct sb_atmosphere_params *p)
{
    *p = (struct sb_atmosphere_params){
        .ground_radius_km = 6360.0,
        .top_radius_km = 6460.0,
        .rayleigh_scattering_per_km = {5.802e-3, 13.558e-3, 33.1e-3},
        .rayleigh_scale_height_km = 8.0,
        .mie_scattering_per_km = {3.996e-3, 3.996e-3, 3.996e-3},
        .mie_absorption_per_km = {0.444e-3, 0.444e-3, 0.444e-3},
        .mie_scale_height_km = 1.2,
        .mie_g = 0.8,
        .ozone_absorption_per_km = {0.650e-3, 1.881e-3, 0.085e-3},
        .ozone_center_km = 25.0,
        .ozone_half_width_km = 15.0,
        .ground_albedo = {0.3, 0.3, 0.3},
        .solar_irradiance = {1.0, 1.0, 1.0},
    };
}

void sb_atmosphere_preset_mars(struct sb_atmosphere_params *p)
{
    /* Illustrative, not a validated model of Mars: CO2 at ~0.8% of Earth's
     * surface number density with 2.5x air's cross-section; dust of visible
     * optical depth 0.5 over an 11 km scale height, single-scattering albedo
     * 0.97 / 0.93 / 0.76 and asymmetry 0.65 (Wolff et al.'s order of
     * magnitude); no ozone; a reddish ground. */
    *p = (struct sb_atmosphere_params){
        .ground_radius_km = 3389.5,
        .top_radius_km = 3389.5 + 80.0,
        .rayleigh_scattering_per_km = {1.16e-4, 2.71e-4, 6.62e-4},
        .rayleigh_scale_height_km = 11.1,
        .mie_scattering_per_km = {0.0437, 0.0419, 0.0342},
        .mie_absorption_per_km = {0.0013, 0.0032, 0.0108},
        .mie_scale_height_km = 11.0,
        .mie_g = 0.65,
        .ozone_absorption_per_km = {0.0, 0.0, 0.0},
        .ozone_center_km = 25.0,
        .ozone_half_width_km = 15.0,
        .ground_albedo = {0.35, 0.22, 0.13},
        .solar_irradiance = {1.0, 1.0, 1.0},
    };
}

static const struct {
    const char *name;
    void (*fill)(struct sb_atmosphere_params *p);
} presets[] = {
    {"earth", sb_atmosphere_preset_earth},
    {"mars", sb_atmosphere_preset_mars},
};

/* ---- Field table: one row per atmosphere key ------------------------------------- */

enum field_kind { FIELD_SCALAR, FIELD_RGB };

struct field {
    const char *key;
    enum field_kind kind;
    size_t offset;
    double min, max;    /* allowed range */
    bool min_exclusive; /* value must be > min */
    const char *unit;
};

#define F(key, kind, lo, hi, excl, unit)                                                                               \
    {                                                                                                                  \
#key, kind, offsetof(struct sb_atmosphere_params, key), lo, hi, excl, unit                                     \
    }
static const struct field atmosphere_fields[] = {
    F(ground_radius_km, FIELD_SCALAR, 0.0, 1e6, true, "km"),
    F(top_radius_km, FIELD_SCALAR, 0.0, 2e6, true, "km"),
    F(rayleigh_scattering_per_km, FIELD_RGB, 0.0, 1e3, false, "1/km"),
    F(rayleigh_scale_height_km, FIELD_SCALAR, 1e-3, 1e5, false, "km"),
    F(mie_scattering_per_km, FIELD_RGB, 0.0, 1e3, false, "1/km"),
    F(mie_absorption_per_km, FIELD_RGB, 0.0, 1e3, false, "1/km"),
    F(mie_scale_height_km, FIELD_SCALAR, 1e-3, 1e5, false, "km"),
    F(mie_g, FIELD_SCALAR, -0.999, 0.999, false, ""),
    F(ozone_absorption_per_km, FIELD_RGB, 0.0, 1e3, false, "1/km"),
    F(ozone_center_km, FIELD_SCALAR, 0.0, 1e6, false, "km"),
    F(ozone_half_width_km, FIELD_SCALAR, 0.0, 1e6, true, "km"),
    F(ground_albedo, FIELD_RGB, 0.0, 1.0, false, ""),
    F(solar_irradiance, FIELD_RGB, 0.0, 1e6, false, ""),
};
#undef F
#define FIELD_COUNT (sizeof(atmosphere_fields) / sizeof(atmosphere_fields[0]))

static double *field_ptr(struct sb_atmosphere_params *p, const struct field *f)
{
    return (double *)((char *)p + f->offset);
}

static const double *field_cptr(const struct sb_atmosphere_params *p, const struct field *f)
{
    return (const double *)((const char *)p + f->offset);
}

static enum sb_result check_range(const struct field *f, double v, const char *source, const char *path)
{
    if (!isfinite(v)) {
        sb_error("%s: %s: must be a finite number", source, path);
        return SB_ERR_OUT_OF_RANGE;
    }
    bool low = f->min_exclusive ? v <= f->min : v < f->min;
    if (low || v > f->max) {
        sb_error("%s: %s: %.17g is out of range, expected %s%g%s and <= %g%s%s", source, path, v,
                 f->min_exclusive ? "> " : ">= ", f->min, "", f->max, *f->unit ? " " : "", f->unit);
        return SB_ERR_OUT_OF_RANGE;
    }
    return SB_OK;
}

enum sb_result sb_atmosphere_validate(const struct sb_atmosphere_params *p, const char *source)
{
    char path[96];
    for (size_t i = 0; i < FIELD_COUNT; i++) {
        const struct field *f = &atmosphere_fields[i];
        const double *v = field_cptr(p, f);
        int n = f->kind == FIELD_RGB ? 3 : 1;
        for (int c = 0; c < n; c++) {
            if (n == 3)
                snprintf(path, sizeof(path), "atmosphere.%s[%d]", f->key, c);
            else
                snprintf(path, sizeof(path), "atmosphere.%s", f->key);
            enum sb_result res = check_range(f, v[c], source, path);
            if (res)
                return res;
        }
    }
    if (!(p->top_radius_km > p->ground_radius_km)) {
        sb_error("%s: atmosphere.top_radius_km: %.17g must exceed ground_radius_km (%.17g)", source, p->top_radius_km,
                 p->ground_radius_km);
        return SB_ERR_OUT_OF_RANGE;
    }
    if (p->top_radius_km - p->ground_radius_km < 1e-3 * p->ground_radius_km * 1e-3) {
        sb_error("%s: atmosphere.top_radius_km: the atmosphere is thinner than fp32 can resolve on this planet",
                 source);
        return SB_ERR_OUT_OF_RANGE;
    }
    return SB_OK;
}

/* ---- JSON walking -------------------------------------------------------------- */

static enum sb_result read_number(const cJSON *item, double *out, const char *source, const char *path)
{
    if (!cJSON_IsNumber(item)) {
        sb_error("%s: %s: expected a number", source, path);
        return SB_ERR_WRONG_TYPE;
    }
    *out = item->valuedouble;
    return SB_OK;
}

static enum sb_result parse_field(const struct field *f, const cJSON *item, struct sb_atmosphere_params *p,
                                  const char *source)
{
    char path[96];
    snprintf(path, sizeof(path), "atmosphere.%s", f->key);
    double *dst = field_ptr(p, f);
    if (f->kind == FIELD_SCALAR)
        return read_number(item, dst, source, path);
    if (cJSON_IsNumber(item)) {
        dst[0] = dst[1] = dst[2] = item->valuedouble;
        return SB_OK;
    }
    if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != 3) {
        sb_error("%s: %s: expected a number or an array of 3 numbers (r, g, b)", source, path);
        return SB_ERR_WRONG_TYPE;
    }
    for (int c = 0; c < 3; c++) {
        char elem[112];
        snprintf(elem, sizeof(elem), "%s[%d]", path, c);
        enum sb_result res = read_number(cJSON_GetArrayItem(item, c), &dst[c], source, elem);
        if (res)
            return res;
    }
    return SB_OK;
}

enum sb_result sb_atmosphere_section_parse(const cJSON *obj, struct sb_scene *scene, const char *source)
{
    if (!cJSON_IsObject(obj)) {
        sb_error("%s: atmosphere: expected an object", source);
        return SB_ERR_WRONG_TYPE;
    }
    enum sb_result res = sb_json_check_duplicates(obj, source, "atmosphere");
    if (res)
        return res;
    const cJSON *preset = cJSON_GetObjectItemCaseSensitive(obj, "preset");
    if (!preset) {
        sb_error("%s: atmosphere.preset: missing (known presets: \"earth\", \"mars\")", source);
        return SB_ERR_MISSING_FIELD;
    }
    if (!cJSON_IsString(preset)) {
        sb_error("%s: atmosphere.preset: expected a string", source);
        return SB_ERR_WRONG_TYPE;
    }
    size_t known = 0;
    while (known < sizeof(presets) / sizeof(presets[0]) && strcmp(preset->valuestring, presets[known].name))
        known++;
    if (known == sizeof(presets) / sizeof(presets[0])) {
        sb_error("%s: atmosphere.preset: unknown preset \"%s\" (known presets: \"earth\", \"mars\")", source,
                 preset->valuestring);
        return SB_ERR_UNKNOWN_PRESET;
    }
    snprintf(scene->preset, sizeof(scene->preset), "%s", preset->valuestring);
    presets[known].fill(&scene->atmosphere);

    for (const cJSON *item = obj->child; item; item = item->next) {
        if (strcmp(item->string, "preset") == 0)
            continue;
        const struct field *f = NULL;
        for (size_t i = 0; i < FIELD_COUNT; i++)
            if (strcmp(item->string, atmosphere_fields[i].key) == 0)
                f = &atmosphere_fields[i];
        if (!f) {
            sb_error("%s: atmosphere.%s: unknown key (see docs/scene.md for the schema)", source, item->string);
            return SB_ERR_UNKNOWN_KEY;
        }
        res = parse_field(f, item, &scene->atmosphere, source);
        if (res)
            return res;
    }
    return sb_atmosphere_validate(&scene->atmosphere, source);
}

cJSON *sb_atmosphere_section_json(const struct sb_scene *scene)
{
    cJSON *atm = cJSON_CreateObject();
    if (!atm)
        return NULL;
    cJSON_AddStringToObject(atm, "preset", scene->preset);
    for (size_t i = 0; i < FIELD_COUNT; i++) {
        const struct field *f = &atmosphere_fields[i];
        const double *v = field_cptr(&scene->atmosphere, f);
        if (f->kind == FIELD_RGB)
            cJSON_AddItemToObject(atm, f->key, cJSON_CreateDoubleArray(v, 3));
        else
            cJSON_AddNumberToObject(atm, f->key, v[0]);
    }
    return atm;
}

bool sb_atmosphere_dusty(const struct sb_atmosphere_params *p)
{
    for (int c = 0; c < 3; c++)
        if (!(p->mie_scattering_per_km[c] > p->rayleigh_scattering_per_km[c]))
            return false;
    return true;
}

bool sb_atmosphere_peaked_dust(const struct sb_atmosphere_params *p)
{
    return sb_atmosphere_dusty(p) && fabs(p->mie_g) >= SB_ORDERS_DUST_MAX_G;
}

double sb_orders_medium(const struct sb_atmosphere_params *p, struct sb_atmosphere_params *medium)
{
    *medium = *p;
    if (!(p->mie_g >= SB_ORDERS_DELTA_M_G))
        return 0.0;
    double f = p->mie_g * p->mie_g;
    for (int c = 0; c < 3; c++)
        medium->mie_scattering_per_km[c] = p->mie_scattering_per_km[c] * (1.0 - f);
    medium->mie_g = p->mie_g / (1.0 + p->mie_g);
    return f;
}

int sb_orders_mu_nodes(const struct sb_atmosphere_params *p)
{
    struct sb_atmosphere_params m;
    sb_orders_medium(p, &m);
    return sb_atmosphere_dusty(&m) && !sb_atmosphere_peaked_dust(&m) ? SB_ORDERS_MU_DUST : SB_ORDERS_MU;
}

int sb_orders_mu_s_nodes(const struct sb_atmosphere_params *p)
{
    struct sb_atmosphere_params m;
    sb_orders_medium(p, &m);
    return sb_atmosphere_dusty(&m) ? SB_ORDERS_MU_S_DUST : SB_ORDERS_MU_S;
}

int sb_orders_nu_nodes(const struct sb_atmosphere_params *p)
{
    struct sb_atmosphere_params m;
    sb_orders_medium(p, &m);
    return sb_atmosphere_peaked_dust(&m) ? SB_ORDERS_NU_DUST : SB_ORDERS_NU;
}

/* The orders' rows follow the atmosphere's mu nodes (a dust's zenith), its
 * columns its sun cosine and azimuth nodes. */
static void atmosphere_product_shape(const struct sb_scene *scene, enum sb_product_id id, uint32_t shape[3])
{
    if (id == SB_PRODUCT_ORDERS || id == SB_PRODUCT_SPECTRAL_ORDERS) {
        shape[0] = (uint32_t)(sb_orders_mu_s_nodes(&scene->atmosphere) * sb_orders_nu_nodes(&scene->atmosphere));
        shape[1] = (uint32_t)(SB_ORDERS_R * sb_orders_mu_nodes(&scene->atmosphere) + 1);
    }
}

/* The scene's core: scene.c reads and writes the section itself, first. */
const struct sb_family_format sb_atmosphere_family_format = {
    .name = "atmosphere",
    .default_products = true,
    .product_shape = atmosphere_product_shape,
};

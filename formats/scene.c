#include "scene.h"

#include <cJSON.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "family.h"
#include "json.h"
#include "log.h"

#define SCENE_MAX_BYTES (1u << 20)

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

static enum sb_result parse_atmosphere(const cJSON *obj, struct sb_scene *scene, const char *source)
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

static enum sb_result parse_products(const cJSON *arr, struct sb_scene *scene, const char *source)
{
    if (!cJSON_IsArray(arr)) {
        sb_error("%s: products: expected an array of product names", source);
        return SB_ERR_WRONG_TYPE;
    }
    int i = 0;
    for (const cJSON *item = arr->child; item; item = item->next, i++) {
        if (!cJSON_IsString(item)) {
            sb_error("%s: products[%d]: expected a product name string", source, i);
            return SB_ERR_WRONG_TYPE;
        }
        enum sb_product_id id;
        if (!sb_product_from_name(item->valuestring, &id)) {
            sb_error("%s: products[%d]: unknown product \"%s\"", source, i, item->valuestring);
            return SB_ERR_UNKNOWN_PRODUCT;
        }
        if (scene->wants[id]) {
            sb_error("%s: products[%d]: \"%s\" is listed twice", source, i, item->valuestring);
            return SB_ERR_DUPLICATE_KEY;
        }
        scene->wants[id] = true;
    }
    if (i == 0) {
        sb_error("%s: products: empty; leave the key out to bake the atmosphere's products", source);
        return SB_ERR_OUT_OF_RANGE;
    }
    return SB_OK;
}

static enum sb_result tolerance_value(const cJSON *item, const char *source, const char *path, double *out)
{
    if (!cJSON_IsNumber(item)) {
        sb_error("%s: %s: expected a number (a relative error)", source, path);
        return SB_ERR_WRONG_TYPE;
    }
    double v = item->valuedouble;
    if (!isfinite(v) || v < SB_TOLERANCE_MIN || v > SB_TOLERANCE_MAX) {
        sb_error("%s: %s: %.17g is out of range, expected a relative error in [%g, %g] (fp32 cannot do better "
                 "than the first)",
                 source, path, v, SB_TOLERANCE_MIN, SB_TOLERANCE_MAX);
        return SB_ERR_OUT_OF_RANGE;
    }
    *out = v;
    return SB_OK;
}

/* "tolerance": a number for every product, or an object of product names. */
static enum sb_result parse_tolerance(const cJSON *item, struct sb_scene *scene, const char *source)
{
    if (cJSON_IsNumber(item)) {
        double v;
        enum sb_result res = tolerance_value(item, source, "tolerance", &v);
        for (int p = 0; p < SB_PRODUCT_COUNT && !res; p++)
            if (!sb_family_format(sb_product_format((enum sb_product_id)p)->family)->no_tolerance)
                scene->tolerance[p] = v;
        return res;
    }
    if (!cJSON_IsObject(item)) {
        sb_error("%s: tolerance: expected a number or an object of product names", source);
        return SB_ERR_WRONG_TYPE;
    }
    enum sb_result res = sb_json_check_duplicates(item, source, "tolerance");
    if (res)
        return res;
    for (const cJSON *t = item->child; t; t = t->next) {
        enum sb_product_id id;
        char path[96];
        snprintf(path, sizeof(path), "tolerance.%s", t->string);
        if (!sb_product_from_name(t->string, &id)) {
            sb_error("%s: %s: unknown product", source, path);
            return SB_ERR_UNKNOWN_PRODUCT;
        }
        const char *why = sb_family_format(sb_product_format(id)->family)->no_tolerance;
        if (why) {
            sb_error("%s: %s: %s", source, path, why);
            return SB_ERR_OUT_OF_RANGE;
        }
        if ((res = tolerance_value(t, source, path, &scene->tolerance[id])))
            return res;
    }
    if (!item->child) {
        sb_error("%s: tolerance: empty; leave the key out for the default settings", source);
        return SB_ERR_OUT_OF_RANGE;
    }
    return SB_OK;
}

static enum sb_result view_number(const cJSON *obj, const char *key, double lo, double hi, const char *source,
                                  double *out)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    char path[64];
    snprintf(path, sizeof(path), "view.%s", key);
    return item ? sb_json_number(item, source, path, lo, hi, out) : SB_OK;
}

static enum sb_result parse_view(const cJSON *obj, struct sb_scene *scene, const char *source)
{
    if (!cJSON_IsObject(obj)) {
        sb_error("%s: view: expected an object", source);
        return SB_ERR_WRONG_TYPE;
    }
    enum sb_result res = sb_json_check_duplicates(obj, source, "view");
    for (const cJSON *item = obj->child; item && !res; item = item->next)
        if (strcmp(item->string, "altitude_km") && strcmp(item->string, "sun_elevation_deg") &&
            strcmp(item->string, "sun_azimuth_deg")) {
            sb_error("%s: view.%s: unknown key (altitude_km, sun_elevation_deg, sun_azimuth_deg)", source,
                     item->string);
            res = SB_ERR_UNKNOWN_KEY;
        }
    if (!res)
        res = view_number(obj, "altitude_km", 0.0, 1e6, source, &scene->view.altitude_km);
    if (!res)
        res = view_number(obj, "sun_elevation_deg", -90.0, 90.0, source, &scene->view.sun_elevation_deg);
    if (!res)
        res = view_number(obj, "sun_azimuth_deg", -360.0, 360.0, source, &scene->view.sun_azimuth_deg);
    scene->has_view = true;
    return res;
}

/* Sections that belong to no product family: what the bakes place
 * (the world) and what only skyview reads (the fog, the cloud layer), in normalised order. */
static const struct other_section {
    const char *key;
    enum sb_result (*parse)(const cJSON *section, struct sb_scene *scene, const char *source);
    cJSON *(*json)(const struct sb_scene *scene);
} other_sections[] = {
    {"world", sb_world_section_parse, sb_world_section_json},
    {"fog", sb_fog_section_parse, sb_fog_section_json},
    {"cloud_layer", sb_cloud_layer_section_parse, sb_cloud_layer_section_json},
};

static const struct other_section *other_section(const char *key)
{
    for (size_t i = 0; i < sizeof(other_sections) / sizeof(other_sections[0]); i++)
        if (!strcmp(other_sections[i].key, key))
            return &other_sections[i];
    return NULL;
}

/* The family whose scene section `key` is, or NULL. */
static const struct sb_family_format *family_section(const char *key)
{
    for (int f = 0; f < SB_FAMILY_COUNT; f++) {
        const struct sb_family_format *family = sb_family_format((enum sb_family)f);
        if (family->section && !strcmp(family->section, key))
            return family;
    }
    return NULL;
}

static enum sb_result parse_root(const cJSON *root, struct sb_scene *scene, const char *source)
{
    if (!cJSON_IsObject(root)) {
        sb_error("%s: the scene must be a JSON object", source);
        return SB_ERR_WRONG_TYPE;
    }
    enum sb_result res = sb_json_check_duplicates(root, source, "");
    if (res)
        return res;
    bool have_atmosphere = false, have_products = false;
    scene->view = (struct sb_scene_view){.altitude_km = 0.002, .sun_elevation_deg = 30.0, .sun_azimuth_deg = 150.0};
    for (int f = 0; f < SB_FAMILY_COUNT; f++)
        if (sb_family_format((enum sb_family)f)->set_defaults)
            sb_family_format((enum sb_family)f)->set_defaults(scene);
    sb_cloud_layer_params_default(&scene->cloud_layer);
    for (const cJSON *item = root->child; item; item = item->next) {
        if (strcmp(item->string, "version") == 0) {
            if (!cJSON_IsNumber(item)) {
                sb_error("%s: version: expected a number", source);
                return SB_ERR_WRONG_TYPE;
            }
            if (item->valuedouble != 1.0) {
                sb_error("%s: version: %g is not a scene version this skybake reads (1)", source, item->valuedouble);
                return SB_ERR_OUT_OF_RANGE;
            }
        } else if (strcmp(item->string, "name") == 0) {
            if (!cJSON_IsString(item)) {
                sb_error("%s: name: expected a string", source);
                return SB_ERR_WRONG_TYPE;
            }
            if (strlen(item->valuestring) >= sizeof(scene->name)) {
                sb_error("%s: name: longer than %zu bytes", source, sizeof(scene->name) - 1);
                return SB_ERR_OUT_OF_RANGE;
            }
            snprintf(scene->name, sizeof(scene->name), "%s", item->valuestring);
        } else if (strcmp(item->string, "atmosphere") == 0) {
            if ((res = parse_atmosphere(item, scene, source)))
                return res;
            have_atmosphere = true;
        } else if (strcmp(item->string, "products") == 0) {
            if ((res = parse_products(item, scene, source)))
                return res;
            have_products = true;
        } else if (strcmp(item->string, "view") == 0) {
            if ((res = parse_view(item, scene, source)))
                return res;
        } else if (other_section(item->string)) {
            if ((res = other_section(item->string)->parse(item, scene, source)))
                return res;
        } else if (strcmp(item->string, "tolerance") == 0) {
            if ((res = parse_tolerance(item, scene, source)))
                return res;
        } else if (family_section(item->string)) {
            if ((res = family_section(item->string)->parse_section(item, scene, source)))
                return res;
        } else {
            sb_error("%s: %s: unknown key (see docs/scene.md for the schema)", source, item->string);
            return SB_ERR_UNKNOWN_KEY;
        }
    }
    if (!have_atmosphere) {
        sb_error("%s: atmosphere: missing", source);
        return SB_ERR_MISSING_FIELD;
    }
    if (!have_products)
        for (int p = 0; p < SB_PRODUCT_COUNT; p++)
            scene->wants[p] = sb_family_format(sb_product_format((enum sb_product_id)p)->family)->default_products;
    for (int f = 0; f < SB_FAMILY_COUNT; f++) {
        const struct sb_family_format *family = sb_family_format((enum sb_family)f);
        if (family->validate && (res = family->validate(scene, source)))
            return res;
    }
    return SB_OK;
}

/* The scene from a parsed root (deleted here); *scene is left empty on error. */
static enum sb_result scene_from_root(cJSON *root, const char *source, struct sb_scene *scene)
{
    enum sb_result res = parse_root(root, scene, source);
    cJSON_Delete(root);
    if (res)
        memset(scene, 0, sizeof(*scene));
    return res;
}

enum sb_result sb_scene_parse(const char *json, size_t size, const char *source, struct sb_scene *scene)
{
    memset(scene, 0, sizeof(*scene));
    cJSON *root;
    enum sb_result res = sb_json_parse(json, size, source, &root);
    return res ? res : scene_from_root(root, source, scene);
}

enum sb_result sb_scene_load(const char *path, struct sb_scene *scene)
{
    memset(scene, 0, sizeof(*scene));
    cJSON *root;
    enum sb_result res = sb_json_load(AT_FDCWD, path, path, SCENE_MAX_BYTES, true, &root);
    res = res ? res : scene_from_root(root, path, scene);
    if (!res) { /* the world's file is found beside the scene's */
        const char *slash = strrchr(path, '/');
        size_t length = slash ? (slash == path ? 1 : (size_t)(slash - path)) : 0;
        if (length >= sizeof(scene->directory)) {
            sb_error("%s: the scene's directory is longer than %zu bytes", path, sizeof(scene->directory) - 1);
            memset(scene, 0, sizeof(*scene));
            return SB_ERR_OUT_OF_RANGE;
        }
        snprintf(scene->directory, sizeof(scene->directory), "%.*s", (int)length, path);
    }
    return res;
}

char *sb_scene_normalized_json(const struct sb_scene *scene)
{
    cJSON *root = cJSON_CreateObject();
    cJSON *atm = cJSON_CreateObject();
    cJSON *products = cJSON_CreateArray();
    char *out = NULL;
    if (!root || !atm || !products) {
        cJSON_Delete(atm);
        cJSON_Delete(products);
        goto done;
    }
    cJSON_AddNumberToObject(root, "version", 1);
    cJSON_AddStringToObject(root, "name", scene->name);
    cJSON_AddItemToObject(root, "atmosphere", atm);
    cJSON_AddStringToObject(atm, "preset", scene->preset);
    for (size_t i = 0; i < FIELD_COUNT; i++) {
        const struct field *f = &atmosphere_fields[i];
        const double *v = field_cptr(&scene->atmosphere, f);
        if (f->kind == FIELD_RGB)
            cJSON_AddItemToObject(atm, f->key, cJSON_CreateDoubleArray(v, 3));
        else
            cJSON_AddNumberToObject(atm, f->key, v[0]);
    }
    cJSON_AddItemToObject(root, "products", products);
    for (int p = 0; p < SB_PRODUCT_COUNT; p++)
        if (scene->wants[p])
            cJSON_AddItemToArray(products, cJSON_CreateString(sb_product_name((enum sb_product_id)p)));
    /* Only when given, so that scenes without them keep their hashes. */
    if (scene->has_view) {
        cJSON *view = cJSON_AddObjectToObject(root, "view");
        cJSON_AddNumberToObject(view, "altitude_km", scene->view.altitude_km);
        cJSON_AddNumberToObject(view, "sun_elevation_deg", scene->view.sun_elevation_deg);
        if (scene->view.sun_azimuth_deg != 150.0) /* the default's absence keeps older scenes' hashes */
            cJSON_AddNumberToObject(view, "sun_azimuth_deg", scene->view.sun_azimuth_deg);
    }
    for (int f = 0; f < SB_FAMILY_COUNT; f++) {
        const struct sb_family_format *family = sb_family_format((enum sb_family)f);
        cJSON *section = family->section_json ? family->section_json(scene) : NULL;
        if (section)
            cJSON_AddItemToObject(root, family->section, section);
    }
    for (size_t i = 0; i < sizeof(other_sections) / sizeof(other_sections[0]); i++) {
        cJSON *section = other_sections[i].json(scene);
        if (section)
            cJSON_AddItemToObject(root, other_sections[i].key, section);
    }
    cJSON *tolerance = NULL;
    for (int p = 0; p < SB_PRODUCT_COUNT; p++) {
        if (scene->tolerance[p] <= 0)
            continue;
        if (!tolerance)
            tolerance = cJSON_AddObjectToObject(root, "tolerance");
        cJSON_AddNumberToObject(tolerance, sb_product_name((enum sb_product_id)p), scene->tolerance[p]);
    }
    out = cJSON_PrintUnformatted(root);
done:
    cJSON_Delete(root);
    return out;
}

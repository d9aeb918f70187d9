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

/* Why a tolerance does not apply to product `id`, NULL where it does. */
static const char *no_tolerance(enum sb_product_id id)
{
    const char *why = sb_product_format(id)->no_tolerance;
    return why ? why : sb_family_format(sb_product_format(id)->family)->no_tolerance;
}

/* "tolerance": a number for every product, or an object of product names. */
static enum sb_result parse_tolerance(const cJSON *item, struct sb_scene *scene, const char *source)
{
    if (cJSON_IsNumber(item)) {
        double v;
        enum sb_result res = tolerance_value(item, source, "tolerance", &v);
        for (int p = 0; p < SB_PRODUCT_COUNT && !res; p++)
            if (!no_tolerance((enum sb_product_id)p))
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
        const char *why = no_tolerance(id);
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
            if ((res = sb_atmosphere_section_parse(item, scene, source)))
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
            scene->wants[p] = sb_family_format(sb_product_format((enum sb_product_id)p)->family)->default_products &&
                              !sb_product_format((enum sb_product_id)p)->named_only;
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
    cJSON *atm = sb_atmosphere_section_json(scene);
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

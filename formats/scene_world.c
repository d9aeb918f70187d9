/*
 * The scene's "world" (the mesh file the probes bake against and how it is
 * placed) and "probes" (where the sky-visibility probes go) sections:
 * parsing with every key and range checked, defaults, normalised forms
 * (docs/scene.md).
 */
#include <cJSON.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "family.h"
#include "json.h"
#include "log.h"
#include "scene.h"

enum sb_result sb_world_section_parse(const cJSON *obj, struct sb_scene *scene, const char *source)
{
    static const char *const keys[] = {"file", "units_m", "scale", "up", "rotate_deg", "translate_m", "albedo", NULL};
    struct sb_world_params *w = &scene->world;
    *w = (struct sb_world_params){.units_m = 1, .scale = 1};
    scene->has_world = true;
    enum sb_result res = sb_json_only_keys(obj, source, "world", keys);
    if (res)
        return res;
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, "file");
    if (!cJSON_IsString(item) || !item->valuestring[0] || strlen(item->valuestring) >= sizeof(w->file)) {
        sb_error("%s: world.file: expected the mesh file's path (1 to %zu bytes)", source, sizeof(w->file) - 1);
        return item ? SB_ERR_WRONG_TYPE : SB_ERR_MISSING_FIELD;
    }
    snprintf(w->file, sizeof(w->file), "%s", item->valuestring);
    if ((item = cJSON_GetObjectItemCaseSensitive(obj, "units_m")) &&
        (res = sb_json_number(item, source, "world.units_m", 1e-6, 1e3, &w->units_m)))
        return res;
    if ((item = cJSON_GetObjectItemCaseSensitive(obj, "scale")) &&
        (res = sb_json_number(item, source, "world.scale", 1e-6, 1e3, &w->scale)))
        return res;
    if ((item = cJSON_GetObjectItemCaseSensitive(obj, "up"))) {
        if (!cJSON_IsString(item) || (strcmp(item->valuestring, "y") && strcmp(item->valuestring, "z"))) {
            sb_error("%s: world.up: expected \"y\" or \"z\"", source);
            return SB_ERR_OUT_OF_RANGE;
        }
        w->up_z = !strcmp(item->valuestring, "z");
    }
    if ((item = cJSON_GetObjectItemCaseSensitive(obj, "rotate_deg")) &&
        (res = sb_json_vec3(item, source, "world.rotate_deg", -360, 360, w->rotate_deg)))
        return res;
    if ((item = cJSON_GetObjectItemCaseSensitive(obj, "translate_m")) &&
        (res = sb_json_vec3(item, source, "world.translate_m", -1e4, 1e4, w->translate_m)))
        return res;
    if ((item = cJSON_GetObjectItemCaseSensitive(obj, "albedo"))) {
        if (!cJSON_IsObject(item) || !item->child) {
            sb_error("%s: world.albedo: expected an object of material names (or \"*\") to [r, g, b]", source);
            return SB_ERR_WRONG_TYPE;
        }
        if ((res = sb_json_check_duplicates(item, source, "world.albedo")))
            return res;
        for (const cJSON *o = item->child; o; o = o->next) {
            char path[128];
            snprintf(path, sizeof(path), "world.albedo.%.64s", o->string);
            if (w->override_count >= SB_WORLD_MAX_OVERRIDES || strlen(o->string) >= sizeof(w->overrides[0].material) ||
                !o->string[0]) {
                sb_error("%s: %s: at most %d names of 1 to 63 bytes", source, path, SB_WORLD_MAX_OVERRIDES);
                return SB_ERR_OUT_OF_RANGE;
            }
            snprintf(w->overrides[w->override_count].material, sizeof(w->overrides[0].material), "%s", o->string);
            if ((res = sb_json_vec3(o, source, path, 0, 1, w->overrides[w->override_count].albedo)))
                return res;
            w->override_count++;
        }
    }
    return SB_OK;
}

cJSON *sb_world_section_json(const struct sb_scene *scene)
{
    if (!scene->has_world)
        return NULL;
    const struct sb_world_params *w = &scene->world;
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "file", w->file);
    cJSON_AddNumberToObject(o, "units_m", w->units_m);
    cJSON_AddNumberToObject(o, "scale", w->scale);
    cJSON_AddStringToObject(o, "up", w->up_z ? "z" : "y");
    cJSON_AddItemToObject(o, "rotate_deg", cJSON_CreateDoubleArray(w->rotate_deg, 3));
    cJSON_AddItemToObject(o, "translate_m", cJSON_CreateDoubleArray(w->translate_m, 3));
    if (w->override_count) {
        cJSON *albedo = cJSON_AddObjectToObject(o, "albedo");
        for (int i = 0; i < w->override_count; i++)
            cJSON_AddItemToObject(albedo, w->overrides[i].material, cJSON_CreateDoubleArray(w->overrides[i].albedo, 3));
    }
    return o;
}

void sb_probe_params_default(struct sb_probe_params *p)
{
    *p = (struct sb_probe_params){
        .spacing_m = 2.0, .rays = 2048, .inside_fraction = 0.25, .bounce_rays = 256, .bounce_secondary = 64};
}

void sb_probes_set_defaults(struct sb_scene *scene)
{
    sb_probe_params_default(&scene->probes);
}

enum sb_result sb_probes_validate(const struct sb_scene *scene, const char *source)
{
    if ((scene->wants[SB_PRODUCT_SKY_VISIBILITY] || scene->wants[SB_PRODUCT_SKY_BOUNCE]) && !scene->has_world) {
        sb_error("%s: products: %s needs a \"world\" (the geometry the probes see)", source,
                 scene->wants[SB_PRODUCT_SKY_VISIBILITY] ? "sky_visibility" : "sky_bounce");
        return SB_ERR_MISSING_FIELD;
    }
    return SB_OK;
}

enum sb_result sb_probes_section_parse(const cJSON *obj, struct sb_scene *scene, const char *source)
{
    static const char *const keys[] = {"spacing_m",   "margin_m",    "bounds_m",         "rays", "inside_fraction",
                                       "positions_m", "bounce_rays", "bounce_secondary", NULL};
    struct sb_probe_params *p = &scene->probes;
    sb_probe_params_default(p);
    scene->has_probes = true;
    enum sb_result res = sb_json_only_keys(obj, source, "probes", keys);
    const cJSON *item;
    if (!res && (item = cJSON_GetObjectItemCaseSensitive(obj, "spacing_m")) &&
        (res = sb_json_number(item, source, "probes.spacing_m", 0, 1000, &p->spacing_m)))
        return res;
    if (!res && p->spacing_m > 0 && p->spacing_m < 0.01) {
        sb_error("%s: probes.spacing_m: %g; 0 (no grid) or at least 0.01 m", source, p->spacing_m);
        return SB_ERR_OUT_OF_RANGE;
    }
    if (!res && (item = cJSON_GetObjectItemCaseSensitive(obj, "margin_m")))
        res = sb_json_number(item, source, "probes.margin_m", 0, 1000, &p->margin_m);
    if (!res && (item = cJSON_GetObjectItemCaseSensitive(obj, "bounds_m"))) {
        if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != 2) {
            sb_error("%s: probes.bounds_m: expected [[min x, y, z], [max x, y, z]]", source);
            return SB_ERR_WRONG_TYPE;
        }
        res = sb_json_vec3(item->child, source, "probes.bounds_m[0]", -1e4, 1e4, p->bounds_m[0]);
        if (!res)
            res = sb_json_vec3(item->child->next, source, "probes.bounds_m[1]", -1e4, 1e4, p->bounds_m[1]);
        for (int k = 0; k < 3 && !res; k++)
            if (!(p->bounds_m[1][k] >= p->bounds_m[0][k])) {
                sb_error("%s: probes.bounds_m: the max corner's %c (%g) is below the min's (%g)", source, "xyz"[k],
                         p -> bounds_m[1][k], p -> bounds_m[0][k]);
                res = SB_ERR_OUT_OF_RANGE;
            }
        p->has_bounds = !res;
    }
    if (!res && (item = cJSON_GetObjectItemCaseSensitive(obj, "inside_fraction")))
        res = sb_json_number(item, source, "probes.inside_fraction", 0, 1, &p->inside_fraction);
    if (!res && (item = cJSON_GetObjectItemCaseSensitive(obj, "rays"))) {
        double rays;
        if (!(res = sb_json_number(item, source, "probes.rays", 64, 65536, &rays))) {
            if (rays != floor(rays) || (uint32_t)rays % 64) {
                sb_error("%s: probes.rays: %g is not a multiple of 64", source, rays);
                return SB_ERR_OUT_OF_RANGE;
            }
            p->rays = (uint32_t)rays;
        }
    }
    const struct {
        const char *key;
        double lo, hi, multiple;
        uint32_t *out;
    } counts[] = {{"bounce_rays", 64, 4096, 64, &p->bounce_rays},
                  {"bounce_secondary", 8, 1024, 8, &p->bounce_secondary}};
    for (size_t i = 0; i < sizeof(counts) / sizeof(counts[0]) && !res; i++) {
        if (!(item = cJSON_GetObjectItemCaseSensitive(obj, counts[i].key)))
            continue;
        char where[64];
        double v;
        snprintf(where, sizeof(where), "probes.%s", counts[i].key);
        if ((res = sb_json_number(item, source, where, counts[i].lo, counts[i].hi, &v)))
            break;
        if (v != floor(v) || fmod(v, counts[i].multiple) != 0) {
            sb_error("%s: %s: %g is not a multiple of %g", source, where, v, counts[i].multiple);
            return SB_ERR_OUT_OF_RANGE;
        }
        *counts[i].out = (uint32_t)v;
    }
    if (!res && (item = cJSON_GetObjectItemCaseSensitive(obj, "positions_m"))) {
        if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) > SB_PROBES_MAX_EXPLICIT) {
            sb_error("%s: probes.positions_m: expected an array of at most %d [x, y, z]", source,
                     SB_PROBES_MAX_EXPLICIT);
            return cJSON_IsArray(item) ? SB_ERR_OUT_OF_RANGE : SB_ERR_WRONG_TYPE;
        }
        for (const cJSON *e = item->child; e && !res; e = e->next) {
            char path[64];
            snprintf(path, sizeof(path), "probes.positions_m[%d]", p->explicit_count);
            res = sb_json_vec3(e, source, path, -1e4, 1e4, p->positions_m[p->explicit_count++]);
        }
    }
    if (!res && p->spacing_m == 0 && !p->explicit_count) {
        sb_error("%s: probes: no grid (spacing_m 0) and no positions_m: no probe at all", source);
        return SB_ERR_OUT_OF_RANGE;
    }
    return res;
}

cJSON *sb_probes_section_json(const struct sb_scene *scene)
{
    bool used = scene->has_probes || scene->wants[SB_PRODUCT_SKY_VISIBILITY] || scene->wants[SB_PRODUCT_SKY_BOUNCE];
    if (!used)
        return NULL;
    const struct sb_probe_params *p = &scene->probes;
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "spacing_m", p->spacing_m);
    cJSON_AddNumberToObject(o, "margin_m", p->margin_m);
    if (p->has_bounds) { /* only when given: scenes without keep their hash */
        cJSON *b = cJSON_AddArrayToObject(o, "bounds_m");
        cJSON_AddItemToArray(b, cJSON_CreateDoubleArray(p->bounds_m[0], 3));
        cJSON_AddItemToArray(b, cJSON_CreateDoubleArray(p->bounds_m[1], 3));
    }
    cJSON_AddNumberToObject(o, "rays", p->rays);
    cJSON_AddNumberToObject(o, "inside_fraction", p->inside_fraction);
    if (scene->wants[SB_PRODUCT_SKY_BOUNCE]) { /* only then: scenes without keep their hash */
        cJSON_AddNumberToObject(o, "bounce_rays", p->bounce_rays);
        cJSON_AddNumberToObject(o, "bounce_secondary", p->bounce_secondary);
    }
    cJSON *list = cJSON_AddArrayToObject(o, "positions_m");
    for (int i = 0; i < p->explicit_count; i++)
        cJSON_AddItemToArray(list, cJSON_CreateDoubleArray(p->positions_m[i], 3));
    return o;
}

/*
 * The scene's "world" section: the mesh file the probes and the reflection
 * captures bake against, and how it is placed; parsing with every key and
 * range checked, the normalised form (docs/scene.md). Read by no family of
 * its own: the families that need a world check for it.
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

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

/* "ground": true (the default's), false, or {"height_m", "size_m", "albedo"};
 * a mesh file's alone (a world file states its own). */
static enum sb_result parse_ground(const cJSON *item, struct sb_world_params *w, const char *source)
{
    size_t length = strlen(w->file);
    if (length > 5 && !strcmp(w->file + length - 5, ".json")) {
        sb_error("%s: world.ground: %s is a skybake world file, which states its own ground", source, w->file);
        return SB_ERR_OUT_OF_RANGE;
    }
    w->ground.given = true;
    if (cJSON_IsBool(item)) {
        w->ground.none = cJSON_IsFalse(item);
        return SB_OK;
    }
    static const char *const keys[] = {"height_m", "size_m", "albedo", NULL};
    if (!cJSON_IsObject(item)) {
        sb_error("%s: world.ground: expected true, false or an object (height_m, size_m, albedo)", source);
        return SB_ERR_WRONG_TYPE;
    }
    w->ground.object = true;
    enum sb_result res = sb_json_only_keys(item, source, "world.ground", keys);
    const cJSON *v;
    if (!res && (v = cJSON_GetObjectItemCaseSensitive(item, "height_m"))) {
        w->ground.has_height = true;
        res = sb_json_number(v, source, "world.ground.height_m", -1e4, 1e4, &w->ground.height_m);
    }
    if (!res && (v = cJSON_GetObjectItemCaseSensitive(item, "size_m")))
        res = sb_json_number(v, source, "world.ground.size_m", 1, 2e4, &w->ground.size_m);
    if (!res && (v = cJSON_GetObjectItemCaseSensitive(item, "albedo")))
        res = sb_json_vec3(v, source, "world.ground.albedo", 0, 1, w->ground.albedo);
    return res;
}

enum sb_result sb_world_section_parse(const cJSON *obj, struct sb_scene *scene, const char *source)
{
    static const char *const keys[] = {"file",        "units_m", "scale",  "up", "rotate_deg",
                                       "translate_m", "albedo",  "ground", NULL};
    struct sb_world_params *w = &scene->world;
    *w = (struct sb_world_params){.units_m = 1, .scale = 1, .ground.albedo = {0.18, 0.18, 0.18}};
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
    if ((item = cJSON_GetObjectItemCaseSensitive(obj, "ground")))
        return parse_ground(item, w, source);
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
    /* only when given, so that older scenes keep their hashes */
    if (w->ground.none) {
        cJSON_AddFalseToObject(o, "ground");
    } else if (w->ground.object) {
        cJSON *g = cJSON_AddObjectToObject(o, "ground");
        if (w->ground.has_height)
            cJSON_AddNumberToObject(g, "height_m", w->ground.height_m);
        if (w->ground.size_m > 0)
            cJSON_AddNumberToObject(g, "size_m", w->ground.size_m);
        cJSON_AddItemToObject(g, "albedo", cJSON_CreateDoubleArray(w->ground.albedo, 3));
    }
    return o;
}

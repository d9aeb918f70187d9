/*
 * The scene's "fog" section: the participating media near the ground that
 * skyview renders in its froxel volume (docs/fog.md): exponential height
 * fog, a modulation by the baked cloud noise, and local boxes. Every key and
 * range is checked; the normalised form is written only when the scene gives
 * the section, so scenes without fog keep their hashes. The bakes do not
 * read it.
 */
#include <cJSON.h>
#include <stdio.h>
#include <string.h>

#include "family.h"
#include "json.h"
#include "log.h"
#include "scene.h"

void sb_fog_params_default(struct sb_fog_params *p)
{
    *p = (struct sb_fog_params){
        .extinction_per_m = 0.01,
        .falloff_height_m = 50.0,
        .albedo = {0.9, 0.9, 0.9},
        .anisotropy = 0.6,
        .noise_scale_m = 40.0,
        .noise_wind_m_s = {2.0, 0.0, 0.0},
    };
}

static enum sb_result parse_noise(const cJSON *obj, struct sb_fog_params *p, const char *source)
{
    static const char *const keys[] = {"amount", "scale_m", "wind_m_s", NULL};
    enum sb_result res = sb_json_only_keys(obj, source, "fog.noise", keys);
    p->noise_amount = 0.6;
    if (!res)
        res = sb_json_member_number(obj, "fog.noise", "amount", 0.0, 1.0, source, &p->noise_amount);
    if (!res)
        res = sb_json_member_number(obj, "fog.noise", "scale_m", 0.1, 1e4, source, &p->noise_scale_m);
    if (!res)
        res = sb_json_member_vec3(obj, "fog.noise", "wind_m_s", -200.0, 200.0, source, p->noise_wind_m_s);
    return res;
}

static enum sb_result parse_volume(const cJSON *e, int i, struct sb_fog_params *p, const char *source)
{
    static const char *const keys[] = {"box_m", "extinction_per_m", "edge_m", NULL};
    char where[64], path[96];
    snprintf(where, sizeof(where), "fog.volumes[%d]", i);
    enum sb_result res = sb_json_only_keys(e, source, where, keys);
    if (res)
        return res;
    const cJSON *box = cJSON_GetObjectItemCaseSensitive(e, "box_m");
    if (!box || !cJSON_GetObjectItemCaseSensitive(e, "extinction_per_m")) {
        sb_error("%s: %s: needs box_m and extinction_per_m", source, where);
        return SB_ERR_MISSING_FIELD;
    }
    snprintf(path, sizeof(path), "%s.box_m", where);
    if ((res = sb_json_box(box, source, path, -1e5, 1e5, p->volumes[i].box_m)))
        return res;
    p->volumes[i].edge_m = 1.0;
    if (!res)
        res = sb_json_member_number(e, where, "extinction_per_m", 0.0, 10.0, source, &p->volumes[i].extinction_per_m);
    if (!res)
        res = sb_json_member_number(e, where, "edge_m", 0.0, 1e3, source, &p->volumes[i].edge_m);
    return res;
}

enum sb_result sb_fog_section_parse(const cJSON *obj, struct sb_scene *scene, const char *source)
{
    static const char *const keys[] = {"extinction_per_m", "base_altitude_m", "falloff_height_m", "albedo",
                                       "anisotropy",       "noise",           "volumes",          NULL};
    struct sb_fog_params *p = &scene->fog;
    sb_fog_params_default(p);
    scene->has_fog = true;
    enum sb_result res = sb_json_only_keys(obj, source, "fog", keys);
    if (!res)
        res = sb_json_member_number(obj, "fog", "extinction_per_m", 0.0, 10.0, source, &p->extinction_per_m);
    if (!res)
        res = sb_json_member_number(obj, "fog", "base_altitude_m", -1e4, 1e5, source, &p->base_altitude_m);
    if (!res)
        res = sb_json_member_number(obj, "fog", "falloff_height_m", 1.0, 1e4, source, &p->falloff_height_m);
    if (!res)
        res = sb_json_member_vec3(obj, "fog", "albedo", 0.0, 1.0, source, p->albedo);
    if (!res)
        res = sb_json_member_number(obj, "fog", "anisotropy", -0.95, 0.95, source, &p->anisotropy);
    const cJSON *noise = cJSON_GetObjectItemCaseSensitive(obj, "noise");
    if (!res && noise)
        res = parse_noise(noise, p, source);
    const cJSON *list = cJSON_GetObjectItemCaseSensitive(obj, "volumes");
    if (!res && list) {
        if (!cJSON_IsArray(list) || cJSON_GetArraySize(list) > SB_FOG_MAX_VOLUMES) {
            sb_error("%s: fog.volumes: expected an array of at most %d boxes (%d given)", source, SB_FOG_MAX_VOLUMES,
                     cJSON_IsArray(list) ? cJSON_GetArraySize(list) : 0);
            return cJSON_IsArray(list) ? SB_ERR_OUT_OF_RANGE : SB_ERR_WRONG_TYPE;
        }
        for (const cJSON *e = list->child; e && !res; e = e->next)
            res = parse_volume(e, p->volume_count++, p, source);
    }
    return res;
}

cJSON *sb_fog_section_json(const struct sb_scene *scene)
{
    if (!scene->has_fog)
        return NULL;
    const struct sb_fog_params *p = &scene->fog;
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "extinction_per_m", p->extinction_per_m);
    cJSON_AddNumberToObject(o, "base_altitude_m", p->base_altitude_m);
    cJSON_AddNumberToObject(o, "falloff_height_m", p->falloff_height_m);
    cJSON_AddItemToObject(o, "albedo", cJSON_CreateDoubleArray(p->albedo, 3));
    cJSON_AddNumberToObject(o, "anisotropy", p->anisotropy);
    cJSON *noise = cJSON_AddObjectToObject(o, "noise");
    cJSON_AddNumberToObject(noise, "amount", p->noise_amount);
    cJSON_AddNumberToObject(noise, "scale_m", p->noise_scale_m);
    cJSON_AddItemToObject(noise, "wind_m_s", cJSON_CreateDoubleArray(p->noise_wind_m_s, 3));
    cJSON *list = cJSON_AddArrayToObject(o, "volumes");
    for (int i = 0; i < p->volume_count; i++) {
        cJSON *e = cJSON_CreateObject();
        cJSON *box = cJSON_AddArrayToObject(e, "box_m");
        cJSON_AddItemToArray(box, cJSON_CreateDoubleArray(p->volumes[i].box_m[0], 3));
        cJSON_AddItemToArray(box, cJSON_CreateDoubleArray(p->volumes[i].box_m[1], 3));
        cJSON_AddNumberToObject(e, "extinction_per_m", p->volumes[i].extinction_per_m);
        cJSON_AddNumberToObject(e, "edge_m", p->volumes[i].edge_m);
        cJSON_AddItemToArray(list, e);
    }
    return o;
}

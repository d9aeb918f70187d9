/*
 * The probes family's scene section, "probes": where the sky-visibility
 * probes go, with every key and range checked, defaults, the normalised
 * form (docs/scene.md), and the family's row.
 */
#include <cJSON.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "family.h"
#include "json.h"
#include "log.h"
#include "scene.h"

void sb_probe_params_default(struct sb_probe_params *p)
{
    *p = (struct sb_probe_params){
        .spacing_m = 2.0,      .rays = 2048,          .inside_fraction = 0.25,
        .bounce_rays = 256,    .bounce_secondary = 64, .sun_rays = 1024};
}

static void probes_set_defaults(struct sb_scene *scene)
{
    sb_probe_params_default(&scene->probes);
}

static enum sb_result probes_validate(const struct sb_scene *scene, const char *source)
{
    static const enum sb_product_id probes[] = {SB_PRODUCT_SKY_VISIBILITY, SB_PRODUCT_SKY_BOUNCE,
                                                SB_PRODUCT_SUN_BOUNCE};
    for (size_t i = 0; i < sizeof(probes) / sizeof(probes[0]); i++)
        if (scene->wants[probes[i]] && !scene->has_world) {
            sb_error("%s: products: %s needs a \"world\" (the geometry the probes see)", source,
                     sb_product_name(probes[i]));
            return SB_ERR_MISSING_FIELD;
        }
    return SB_OK;
}

/* "detail_volumes": [{"min_m": [x, y, z], "max_m": [x, y, z], "detail": true}, ...] */
static enum sb_result parse_volumes(const cJSON *list, const char *source, struct sb_probe_params *p)
{
    static const char *const keys[] = {"min_m", "max_m", "detail", NULL};
    if (!cJSON_IsArray(list) || cJSON_GetArraySize(list) > SB_PROBES_MAX_VOLUMES) {
        sb_error("%s: probes.detail_volumes: expected an array of at most %d {\"min_m\", \"max_m\", \"detail\"}",
                 source, SB_PROBES_MAX_VOLUMES);
        return cJSON_IsArray(list) ? SB_ERR_OUT_OF_RANGE : SB_ERR_WRONG_TYPE;
    }
    if (p->detail_spacing_m == 0 && cJSON_GetArraySize(list)) {
        sb_error("%s: probes.detail_volumes: volumes need detail (probes.detail_spacing_m above 0)", source);
        return SB_ERR_OUT_OF_RANGE;
    }
    enum sb_result res = SB_OK;
    for (const cJSON *e = list->child; e && !res; e = e->next, p->detail_volume_count++) {
        struct sb_probe_volume *v = &p->detail_volumes[p->detail_volume_count];
        char path[96];
        snprintf(path, sizeof(path), "probes.detail_volumes[%d]", p->detail_volume_count);
        if (!cJSON_IsObject(e)) {
            sb_error("%s: %s: expected an object", source, path);
            return SB_ERR_WRONG_TYPE;
        }
        if ((res = sb_json_only_keys(e, source, path, keys)))
            return res;
        const cJSON *min = cJSON_GetObjectItemCaseSensitive(e, "min_m"),
                    *max = cJSON_GetObjectItemCaseSensitive(e, "max_m"),
                    *detail = cJSON_GetObjectItemCaseSensitive(e, "detail");
        if (!min || !max || !detail) {
            sb_error("%s: %s: needs \"min_m\", \"max_m\" and \"detail\"", source, path);
            return SB_ERR_MISSING_FIELD;
        }
        if (!cJSON_IsBool(detail)) {
            sb_error("%s: %s.detail: expected true (force detail) or false (forbid it)", source, path);
            return SB_ERR_WRONG_TYPE;
        }
        v->detail = cJSON_IsTrue(detail);
        char at[112];
        snprintf(at, sizeof(at), "%s.min_m", path);
        res = sb_json_vec3(min, source, at, -1e4, 1e4, v->min_m);
        snprintf(at, sizeof(at), "%s.max_m", path);
        if (!res)
            res = sb_json_vec3(max, source, at, -1e4, 1e4, v->max_m);
        for (int k = 0; k < 3 && !res; k++)
            if (!(v->max_m[k] > v->min_m[k])) {
                sb_error("%s: %s: the max corner's %c (%g) is not above the min's (%g)", source, path, "xyz"[k],
                         v -> max_m[k], v -> min_m[k]);
                res = SB_ERR_OUT_OF_RANGE;
            }
    }
    return res;
}

static enum sb_result probes_section_parse(const cJSON *obj, struct sb_scene *scene, const char *source)
{
    static const char *const keys[] = {
        "spacing_m",   "margin_m",         "bounds_m", "rays",      "inside_fraction",  "positions_m",
        "bounce_rays", "bounce_secondary", "bounces",  "layers_m",  "budget_mb",        "detail_spacing_m",
        "detail_volumes", "tile_m",        "reach_m",  "sun_rays", NULL};
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
    if (!res && (item = cJSON_GetObjectItemCaseSensitive(obj, "budget_mb")))
        res = sb_json_number(item, source, "probes.budget_mb", 0.001, 1e5, &p->budget_mb);
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
                  {"bounce_secondary", 8, 1024, 8, &p->bounce_secondary},
                  {"bounces", 0, SB_PROBES_MAX_BOUNCES, 1, &p->bounces},
                  {"sun_rays", 64, 4096, 64, &p->sun_rays}};
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
    if (!res && (item = cJSON_GetObjectItemCaseSensitive(obj, "layers_m"))) {
        int n = cJSON_IsArray(item) ? cJSON_GetArraySize(item) : 0;
        if (n < 1 || n > SB_PROBES_MAX_LAYERS) {
            sb_error("%s: probes.layers_m: expected an array of 1 to %d heights above the surface (m)", source,
                     SB_PROBES_MAX_LAYERS);
            return cJSON_IsArray(item) ? SB_ERR_OUT_OF_RANGE : SB_ERR_WRONG_TYPE;
        }
        for (const cJSON *e = item->child; e && !res; e = e->next, p->layer_count++) {
            char path[64];
            snprintf(path, sizeof(path), "probes.layers_m[%d]", p->layer_count);
            double *h = &p->layers_m[p->layer_count];
            if (!(res = sb_json_number(e, source, path, 0.01, 1000, h)) && p->layer_count && !(*h > h[-1])) {
                sb_error("%s: %s: %g is not above the layer before it (%g)", source, path, *h, h[-1]);
                res = SB_ERR_OUT_OF_RANGE;
            }
        }
        if (!res && p->spacing_m == 0) {
            sb_error("%s: probes.layers_m: the layers need a grid (probes.spacing_m above 0)", source);
            return SB_ERR_OUT_OF_RANGE;
        }
    }
    if (!res && (item = cJSON_GetObjectItemCaseSensitive(obj, "detail_spacing_m")) &&
        !(res = sb_json_number(item, source, "probes.detail_spacing_m", 0, 1000, &p->detail_spacing_m)) &&
        p->detail_spacing_m > 0 && p->detail_spacing_m < 0.05) {
        sb_error("%s: probes.detail_spacing_m: %g; 0 (no detail) or at least 0.05 m", source, p->detail_spacing_m);
        return SB_ERR_OUT_OF_RANGE;
    }
    if (!res && (item = cJSON_GetObjectItemCaseSensitive(obj, "detail_volumes")))
        res = parse_volumes(item, source, p);
    if (!res && (item = cJSON_GetObjectItemCaseSensitive(obj, "reach_m")))
        res = sb_json_number(item, source, "probes.reach_m", 0, 1e5, &p->reach_m);
    if (!res && (item = cJSON_GetObjectItemCaseSensitive(obj, "tile_m")) &&
        !(res = sb_json_number(item, source, "probes.tile_m", 0, 1e4, &p->tile_m)) && p->tile_m > 0) {
        if (p->tile_m < 1) {
            sb_error("%s: probes.tile_m: %g; 0 (no tiles) or at least 1 m", source, p->tile_m);
            return SB_ERR_OUT_OF_RANGE;
        }
        if (p->explicit_count) { /* they stand nowhere in particular: every tile would own them */
            sb_error("%s: probes.tile_m: tiles hold a grid and its detail, not probes.positions_m (%d given): bake "
                     "those in a scene of their own",
                     source, p->explicit_count);
            return SB_ERR_OUT_OF_RANGE;
        }
    }
    if (!res && p->spacing_m == 0 && !p->explicit_count && p->detail_spacing_m == 0) {
        sb_error("%s: probes: no grid (spacing_m 0), no detail and no positions_m: no probe at all", source);
        return SB_ERR_OUT_OF_RANGE;
    }
    return res;
}

static cJSON *probes_section_json(const struct sb_scene *scene)
{
    bool used = scene->has_probes || scene->wants[SB_PRODUCT_SKY_VISIBILITY] || scene->wants[SB_PRODUCT_SKY_BOUNCE] ||
                scene->wants[SB_PRODUCT_SUN_BOUNCE];
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
    if (p->bounces && (scene->wants[SB_PRODUCT_SKY_BOUNCE] || scene->wants[SB_PRODUCT_SUN_BOUNCE]))
        cJSON_AddNumberToObject(o, "bounces", p->bounces); /* only when given: 0 is every bounce */
    if (scene->wants[SB_PRODUCT_SUN_BOUNCE]) /* only then: scenes without keep their hash */
        cJSON_AddNumberToObject(o, "sun_rays", p->sun_rays);
    if (p->budget_mb > 0) /* only when given: scenes without keep their hash */
        cJSON_AddNumberToObject(o, "budget_mb", p->budget_mb);
    if (p->tile_m > 0) /* likewise */
        cJSON_AddNumberToObject(o, "tile_m", p->tile_m);
    if (p->reach_m > 0)
        cJSON_AddNumberToObject(o, "reach_m", p->reach_m);
    if (p->layer_count) /* only when given: scenes without keep their hash */
        cJSON_AddItemToObject(o, "layers_m", cJSON_CreateDoubleArray(p->layers_m, p->layer_count));
    if (p->detail_spacing_m > 0) { /* likewise */
        cJSON_AddNumberToObject(o, "detail_spacing_m", p->detail_spacing_m);
        cJSON *list = cJSON_AddArrayToObject(o, "detail_volumes");
        for (int i = 0; i < p->detail_volume_count; i++) {
            cJSON *v = cJSON_CreateObject();
            cJSON_AddItemToObject(v, "min_m", cJSON_CreateDoubleArray(p->detail_volumes[i].min_m, 3));
            cJSON_AddItemToObject(v, "max_m", cJSON_CreateDoubleArray(p->detail_volumes[i].max_m, 3));
            cJSON_AddBoolToObject(v, "detail", p->detail_volumes[i].detail);
            cJSON_AddItemToArray(list, v);
        }
    }
    cJSON *list = cJSON_AddArrayToObject(o, "positions_m");
    for (int i = 0; i < p->explicit_count; i++)
        cJSON_AddItemToArray(list, cJSON_CreateDoubleArray(p->positions_m[i], 3));
    return o;
}

const struct sb_family_format sb_probes_family_format = {
    .name = "probes",
    .section = "probes",
    .set_defaults = probes_set_defaults,
    .parse_section = probes_section_parse,
    .section_json = probes_section_json,
    .validate = probes_validate,
    .no_tolerance = "the probes' error is set by their ray count (probes.rays), not by a tolerance",
};

/*
 * The scene's "reflections" section: the reflection probes' cube size,
 * sample counts and explicit probes with their boxes, every key and range
 * checked before anything is allocated; defaults; the normalised form
 * (docs/scene.md, docs/reflections.md).
 */
#include <cJSON.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "exr.h"
#include "family.h"
#include "json.h"
#include "log.h"
#include "scene.h"

void sb_reflection_params_default(struct sb_reflection_params *p)
{
    *p = (struct sb_reflection_params){.face_size = 128, .samples = 512, .ambient_rays = 64};
}

static void reflections_set_defaults(struct sb_scene *scene)
{
    sb_reflection_params_default(&scene->reflections);
}

/* A count in [lo, hi], a multiple of `multiple` (a power of two when
 * multiple is 0). */
static enum sb_result count(const cJSON *obj, const char *key, double lo, double hi, uint32_t multiple,
                            const char *source, uint32_t *out)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!item)
        return SB_OK;
    char where[64];
    double v;
    snprintf(where, sizeof(where), "reflections.%s", key);
    enum sb_result res = sb_json_number(item, source, where, lo, hi, &v);
    if (res)
        return res;
    uint32_t n = (uint32_t)v;
    if (v != floor(v) || (multiple ? n % multiple != 0 : (n & (n - 1)) != 0)) {
        if (multiple)
            sb_error("%s: %s: %g is not a multiple of %u", source, where, v, multiple);
        else
            sb_error("%s: %s: %g is not a power of two", source, where, v);
        return SB_ERR_OUT_OF_RANGE;
    }
    *out = n;
    return SB_OK;
}

static enum sb_result parse_probe(const cJSON *e, int i, struct sb_reflection_params *p, const char *source)
{
    static const char *const keys[] = {"position_m", "box_m", NULL};
    char where[64];
    snprintf(where, sizeof(where), "reflections.probes[%d]", i);
    enum sb_result res = sb_json_only_keys(e, source, where, keys);
    if (res)
        return res;
    const cJSON *position = cJSON_GetObjectItemCaseSensitive(e, "position_m");
    const cJSON *box = cJSON_GetObjectItemCaseSensitive(e, "box_m");
    if (!position || !box) {
        sb_error("%s: %s: needs position_m and box_m", source, where);
        return SB_ERR_MISSING_FIELD;
    }
    char path[96];
    snprintf(path, sizeof(path), "%s.position_m", where);
    if ((res = sb_json_vec3(position, source, path, -1e4, 1e4, p->probes[i].position_m)))
        return res;
    snprintf(path, sizeof(path), "%s.box_m", where);
    if ((res = sb_json_box(box, source, path, -1e4, 1e4, p->probes[i].box_m)))
        return res;
    for (int k = 0; k < 3 && !res; k++) {
        double lo = p->probes[i].box_m[0][k], hi = p->probes[i].box_m[1][k], at = p->probes[i].position_m[k];
        if (at < lo || at > hi) {
            sb_error("%s: %s.position_m: %c = %g lies outside the probe's box [%g, %g]", source, where, "xyz"[k], at,
                     lo, hi);
            res = SB_ERR_OUT_OF_RANGE;
        }
    }
    return res;
}

static enum sb_result reflections_section_parse(const cJSON *obj, struct sb_scene *scene, const char *source)
{
    static const char *const keys[] = {"face_size", "samples", "ambient_rays", "probes", NULL};
    struct sb_reflection_params *p = &scene->reflections;
    sb_reflection_params_default(p);
    scene->has_reflections = true;
    enum sb_result res = sb_json_only_keys(obj, source, "reflections", keys);
    if (!res)
        res = count(obj, "face_size", 16, 1024, 0, source, &p->face_size);
    if (!res)
        res = count(obj, "samples", 16, 16384, 16, source, &p->samples);
    if (!res)
        res = count(obj, "ambient_rays", 8, 1024, 8, source, &p->ambient_rays);
    const cJSON *list = cJSON_GetObjectItemCaseSensitive(obj, "probes");
    if (!res && list) {
        if (!cJSON_IsArray(list) || cJSON_GetArraySize(list) > SB_REFLECTION_MAX_PROBES) {
            sb_error("%s: reflections.probes: expected an array of at most %d probes (%d given)", source,
                     SB_REFLECTION_MAX_PROBES, cJSON_IsArray(list) ? cJSON_GetArraySize(list) : 0);
            return cJSON_IsArray(list) ? SB_ERR_OUT_OF_RANGE : SB_ERR_WRONG_TYPE;
        }
        for (const cJSON *e = list->child; e && !res; e = e->next)
            res = parse_probe(e, p->probe_count++, p, source);
    }
    return res;
}

static cJSON *reflections_section_json(const struct sb_scene *scene)
{
    bool used = scene->has_reflections;
    for (int id = 0; id < SB_PRODUCT_COUNT; id++)
        used |= scene->wants[id] && sb_product_format((enum sb_product_id)id)->family == SB_FAMILY_REFLECTIONS &&
                id != SB_PRODUCT_DFG;
    if (!used) /* the DFG alone reads none of it: its scenes keep their hashes */
        return NULL;
    const struct sb_reflection_params *p = &scene->reflections;
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "face_size", p->face_size);
    cJSON_AddNumberToObject(o, "samples", p->samples);
    cJSON_AddNumberToObject(o, "ambient_rays", p->ambient_rays);
    cJSON *list = cJSON_AddArrayToObject(o, "probes");
    for (int i = 0; i < p->probe_count; i++) {
        cJSON *e = cJSON_CreateObject();
        cJSON_AddItemToObject(e, "position_m", cJSON_CreateDoubleArray(p->probes[i].position_m, 3));
        cJSON *box = cJSON_AddArrayToObject(e, "box_m");
        cJSON_AddItemToArray(box, cJSON_CreateDoubleArray(p->probes[i].box_m[0], 3));
        cJSON_AddItemToArray(box, cJSON_CreateDoubleArray(p->probes[i].box_m[1], 3));
        cJSON_AddItemToArray(list, e);
    }
    return o;
}

static void reflections_product_shape(const struct sb_scene *scene, enum sb_product_id id, uint32_t shape[3])
{
    uint32_t n = scene->reflections.face_size, cubes = 1 + (uint32_t)scene->reflections.probe_count;
    if (id == SB_PRODUCT_REFLECTION_CUBES || id == SB_PRODUCT_REFLECTION_SURFACES) {
        shape[0] = n;
        shape[1] = 6 * n;
        shape[2] = cubes;
    } else if (id == SB_PRODUCT_REFLECTION_PROBES) {
        shape[0] = cubes;
    }
}

const struct sb_family_format sb_reflections_family_format = {
    .name = "reflections",
    .section = "reflections",
    .set_defaults = reflections_set_defaults,
    .parse_section = reflections_section_parse,
    .section_json = reflections_section_json,
    .product_shape = reflections_product_shape,
    .no_tolerance = "the reflections' accuracy is set by their sample counts (reflections.samples; the DFG LUT's is "
                    "fixed, within 1e-3 of its fp64 reference)",
};

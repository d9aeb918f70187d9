/*
 * The scene's "cloud_layer" section: the volumetric cloud layer skyview
 * renders from the baked cloud noise (docs/clouds.md, "In skyview"). Every
 * key and range is checked; the normalised form is written only when the
 * scene gives the section, so scenes without it keep their hashes. The
 * bakes do not read it.
 */
#include <cJSON.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "family.h"
#include "json.h"
#include "log.h"
#include "scene.h"

void sb_cloud_layer_params_default(struct sb_cloud_layer_params *p)
{
    *p = (struct sb_cloud_layer_params){
        .base_altitude_m = 1500.0,
        .top_altitude_m = 4000.0,
        .coverage = 0.4,
        .extinction_per_m = 0.08,
        .albedo = {0.99, 0.99, 0.99},
        .weather_scale_m = 40000.0,
        .shape_scale_m = 8000.0,
        .detail_scale_m = 700.0,
        .erosion = 0.4,
        .curl_scale_m = 5000.0,
        .curl_m = 200.0,
        .wind_m_s = {10.0, 0.0, 0.0},
        .phase_forward_g = 0.8,
        .phase_backward_g = -0.3,
        .phase_forward_weight = 0.7,
        .scattering_octaves = 4,
    };
}

/* One row per number of the section: its key, where it goes, its range. */
struct layer_field {
    const char *key;
    size_t offset;
    double lo, hi;
};

#define F(key, member, lo, hi)                                                                                         \
    {                                                                                                                  \
        key, offsetof(struct sb_cloud_layer_params, member), lo, hi                                                    \
    }
static const struct layer_field layer_fields[] = {
    F("base_altitude_m", base_altitude_m, 0.0, 3e4),
    F("top_altitude_m", top_altitude_m, 100.0, 3e4),
    F("coverage", coverage, 0.0, 1.0),
    F("extinction_per_m", extinction_per_m, 0.0, 1.0),
    F("weather_scale_m", weather_scale_m, 100.0, 1e7),
    F("shape_scale_m", shape_scale_m, 10.0, 1e6),
    F("detail_scale_m", detail_scale_m, 1.0, 1e5),
    F("erosion", erosion, 0.0, 1.0),
    F("curl_scale_m", curl_scale_m, 1.0, 1e6),
    F("curl_m", curl_m, 0.0, 1e4),
};
#undef F
#define LAYER_FIELD_COUNT (sizeof(layer_fields) / sizeof(layer_fields[0]))

static double *field_ptr(struct sb_cloud_layer_params *p, const struct layer_field *f)
{
    return (double *)((char *)p + f->offset);
}

static enum sb_result parse_phase(const cJSON *obj, struct sb_cloud_layer_params *p, const char *source)
{
    static const char *const keys[] = {"forward_g", "backward_g", "forward_weight", NULL};
    enum sb_result res = sb_json_only_keys(obj, source, "cloud_layer.phase", keys);
    if (!res)
        res = sb_json_member_number(obj, "cloud_layer.phase", "forward_g", -0.95, 0.95, source, &p->phase_forward_g);
    if (!res)
        res = sb_json_member_number(obj, "cloud_layer.phase", "backward_g", -0.95, 0.95, source, &p->phase_backward_g);
    if (!res)
        res = sb_json_member_number(obj, "cloud_layer.phase", "forward_weight", 0.0, 1.0, source,
                                    &p->phase_forward_weight);
    return res;
}

enum sb_result sb_cloud_layer_section_parse(const cJSON *obj, struct sb_scene *scene, const char *source)
{
    static const char *const keys[] = {
        "base_altitude_m", "top_altitude_m",     "coverage", "extinction_per_m", "albedo", "weather_scale_m",
        "shape_scale_m",   "detail_scale_m",     "erosion",  "curl_scale_m",     "curl_m", "wind_m_s",
        "phase",           "scattering_octaves", NULL};
    struct sb_cloud_layer_params *p = &scene->cloud_layer;
    sb_cloud_layer_params_default(p);
    scene->has_cloud_layer = true;
    enum sb_result res = sb_json_only_keys(obj, source, "cloud_layer", keys);
    for (size_t i = 0; i < LAYER_FIELD_COUNT && !res; i++)
        res = sb_json_member_number(obj, "cloud_layer", layer_fields[i].key, layer_fields[i].lo, layer_fields[i].hi,
                                    source, field_ptr(p, &layer_fields[i]));
    if (!res)
        res = sb_json_member_vec3(obj, "cloud_layer", "albedo", 0.0, 1.0, source, p->albedo);
    if (!res)
        res = sb_json_member_vec3(obj, "cloud_layer", "wind_m_s", -200.0, 200.0, source, p->wind_m_s);
    const cJSON *phase = cJSON_GetObjectItemCaseSensitive(obj, "phase");
    if (!res && phase)
        res = parse_phase(phase, p, source);
    double octaves = p->scattering_octaves;
    if (!res)
        res = sb_json_member_number(obj, "cloud_layer", "scattering_octaves", 1.0, 8.0, source, &octaves);
    if (!res && octaves != floor(octaves)) {
        sb_error("%s: cloud_layer.scattering_octaves: %g is not an integer", source, octaves);
        res = SB_ERR_OUT_OF_RANGE;
    }
    p->scattering_octaves = (uint32_t)octaves;
    if (!res && p->top_altitude_m < p->base_altitude_m + 100.0) {
        sb_error("%s: cloud_layer.top_altitude_m: %g m is not at least 100 m above base_altitude_m (%g m)", source,
                 p->top_altitude_m, p->base_altitude_m);
        res = SB_ERR_OUT_OF_RANGE;
    }
    return res;
}

cJSON *sb_cloud_layer_section_json(const struct sb_scene *scene)
{
    if (!scene->has_cloud_layer)
        return NULL;
    const struct sb_cloud_layer_params *p = &scene->cloud_layer;
    struct sb_cloud_layer_params copy = *p;
    cJSON *o = cJSON_CreateObject();
    for (size_t i = 0; i < LAYER_FIELD_COUNT; i++)
        cJSON_AddNumberToObject(o, layer_fields[i].key, *field_ptr(&copy, &layer_fields[i]));
    cJSON_AddItemToObject(o, "albedo", cJSON_CreateDoubleArray(p->albedo, 3));
    cJSON_AddItemToObject(o, "wind_m_s", cJSON_CreateDoubleArray(p->wind_m_s, 3));
    cJSON *phase = cJSON_AddObjectToObject(o, "phase");
    cJSON_AddNumberToObject(phase, "forward_g", p->phase_forward_g);
    cJSON_AddNumberToObject(phase, "backward_g", p->phase_backward_g);
    cJSON_AddNumberToObject(phase, "forward_weight", p->phase_forward_weight);
    cJSON_AddNumberToObject(o, "scattering_octaves", p->scattering_octaves);
    return o;
}

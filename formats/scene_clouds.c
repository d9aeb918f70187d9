/*
 * The scene's "clouds" section: the cloud noise's parameters, their
 * defaults, caps and normalised form (docs/scene.md).
 */
#include <cJSON.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "family.h"
#include "json.h"
#include "log.h"
#include "scene.h"

void sb_cloud_params_default(struct sb_cloud_params *p)
{
    *p = (struct sb_cloud_params){
        .seed = 0,
        .shape_size = 128,
        .shape_perlin = {4, 4},
        .shape_worley_cells = {4, 8, 16},
        .detail_size = 32,
        .detail_worley_cells = {2, 4, 8},
        .curl_size = 128,
        .curl = {4, 3},
        .weather_size = 512,
        .coverage = {4, 5},
        .precipitation = {8, 4},
        .cloud_type = {2, 3},
    };
}

static void clouds_set_defaults(struct sb_scene *scene)
{
    sb_cloud_params_default(&scene->clouds);
}

/* One row per key of "clouds" (object NULL) or of one of its products'
 * objects: count integers (an array when 3) at offset, each in [min, max]. */
struct cloud_field {
    const char *object, *key;
    size_t offset;
    int count;
    uint32_t min, max;
};

#define C(object, key, member, count, lo, hi)                                                                          \
    {                                                                                                                  \
        object, key, offsetof(struct sb_cloud_params, member), count, lo, hi                                           \
    }
static const struct cloud_field cloud_fields[] = {
    C(NULL, "seed", seed, 1, 0, UINT32_MAX),
    C("cloud_shape", "size", shape_size, 1, 8, 256),
    C("cloud_shape", "perlin_period", shape_perlin.period, 1, 1, 256),
    C("cloud_shape", "perlin_octaves", shape_perlin.octaves, 1, 1, 8),
    C("cloud_shape", "worley_cells", shape_worley_cells, 3, 1, 64),
    C("cloud_detail", "size", detail_size, 1, 8, 128),
    C("cloud_detail", "worley_cells", detail_worley_cells, 3, 1, 32),
    C("cloud_curl", "size", curl_size, 1, 8, 1024),
    C("cloud_curl", "period", curl.period, 1, 1, 1024),
    C("cloud_curl", "octaves", curl.octaves, 1, 1, 8),
    C("weather", "size", weather_size, 1, 8, 1024),
    C("weather", "coverage_period", coverage.period, 1, 1, 1024),
    C("weather", "coverage_octaves", coverage.octaves, 1, 1, 8),
    C("weather", "precipitation_period", precipitation.period, 1, 1, 1024),
    C("weather", "precipitation_octaves", precipitation.octaves, 1, 1, 8),
    C("weather", "type_period", cloud_type.period, 1, 1, 1024),
    C("weather", "type_octaves", cloud_type.octaves, 1, 1, 8),
};
#undef C
#define CLOUD_FIELD_COUNT (sizeof(cloud_fields) / sizeof(cloud_fields[0]))
static const char *const cloud_objects[] = {"cloud_shape", "cloud_detail", "cloud_curl", "weather"};

static uint32_t *cloud_ptr(struct sb_cloud_params *p, const struct cloud_field *f)
{
    return (uint32_t *)((char *)p + f->offset);
}

static const uint32_t *cloud_cptr(const struct sb_cloud_params *p, const struct cloud_field *f)
{
    return (const uint32_t *)((const char *)p + f->offset);
}

static void cloud_path(const struct cloud_field *f, int index, char *out, size_t size)
{
    int n = snprintf(out, size, "clouds.%s%s%s", f->object ? f->object : "", f->object ? "." : "", f->key);
    if (f->count > 1 && n > 0 && (size_t)n < size)
        snprintf(out + n, size - (size_t)n, "[%d]", index);
}

/* The finest octave of a noise must have at least one texel per cell. */
static enum sb_result check_finest(uint32_t cells, uint32_t octaves, uint32_t size, const char *source,
                                   const char *path, const char *size_path)
{
    uint64_t finest = (uint64_t)cells << (octaves - 1);
    if (finest > size) {
        sb_error("%s: %s: %u cells over %u octaves make %llu cells in the finest, more than the %u texels of %s: "
                 "at least one texel per cell",
                 source, path, cells, octaves, (unsigned long long)finest, size, size_path);
        return SB_ERR_OUT_OF_RANGE;
    }
    return SB_OK;
}

enum sb_result sb_cloud_params_validate(const struct sb_cloud_params *p, const char *source)
{
    char path[96];
    for (size_t i = 0; i < CLOUD_FIELD_COUNT; i++) {
        const struct cloud_field *f = &cloud_fields[i];
        const uint32_t *v = cloud_cptr(p, f);
        for (int c = 0; c < f->count; c++)
            if (v[c] < f->min || v[c] > f->max) {
                cloud_path(f, c, path, sizeof(path));
                sb_error("%s: %s: %u is out of range, expected an integer in [%u, %u]", source, path, v[c], f->min,
                         f->max);
                return SB_ERR_OUT_OF_RANGE;
            }
    }
    /* Worley fBm has 3 octaves (cells, 2 cells, 4 cells). */
    enum sb_result res = SB_OK;
    for (int c = 0; c < 3 && !res; c++) {
        snprintf(path, sizeof(path), "clouds.cloud_shape.worley_cells[%d]", c);
        res = check_finest(p->shape_worley_cells[c], 3, p->shape_size, source, path, "clouds.cloud_shape.size");
        snprintf(path, sizeof(path), "clouds.cloud_detail.worley_cells[%d]", c);
        if (!res)
            res = check_finest(p->detail_worley_cells[c], 3, p->detail_size, source, path, "clouds.cloud_detail.size");
    }
    const struct {
        const struct sb_noise_octaves *noise;
        uint32_t size;
        const char *path, *size_path;
    } perlins[] = {
        {&p->shape_perlin, p->shape_size, "clouds.cloud_shape.perlin_period", "clouds.cloud_shape.size"},
        {&p->curl, p->curl_size, "clouds.cloud_curl.period", "clouds.cloud_curl.size"},
        {&p->coverage, p->weather_size, "clouds.weather.coverage_period", "clouds.weather.size"},
        {&p->precipitation, p->weather_size, "clouds.weather.precipitation_period", "clouds.weather.size"},
        {&p->cloud_type, p->weather_size, "clouds.weather.type_period", "clouds.weather.size"},
    };
    for (size_t i = 0; i < sizeof(perlins) / sizeof(perlins[0]) && !res; i++)
        res = check_finest(perlins[i].noise->period, perlins[i].noise->octaves, perlins[i].size, source,
                           perlins[i].path, perlins[i].size_path);
    return res;
}

static enum sb_result cloud_integer(const cJSON *item, const char *source, const char *path, uint32_t *out)
{
    if (!cJSON_IsNumber(item)) {
        sb_error("%s: %s: expected an integer", source, path);
        return SB_ERR_WRONG_TYPE;
    }
    double v = item->valuedouble;
    if (!(v >= 0 && v <= 4294967295.0) || v != floor(v)) {
        sb_error("%s: %s: %.17g is not an integer in [0, 2^32)", source, path, v);
        return SB_ERR_OUT_OF_RANGE;
    }
    *out = (uint32_t)v;
    return SB_OK;
}

static enum sb_result parse_cloud_field(const struct cloud_field *f, const cJSON *item, struct sb_cloud_params *p,
                                        const char *source)
{
    char path[96];
    cloud_path(f, 0, path, sizeof(path));
    uint32_t *dst = cloud_ptr(p, f);
    if (f->count == 1)
        return cloud_integer(item, source, path, dst);
    if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != f->count) {
        path[strcspn(path, "[")] = '\0';
        sb_error("%s: %s: expected an array of %d integers", source, path, f->count);
        return SB_ERR_WRONG_TYPE;
    }
    for (int c = 0; c < f->count; c++) {
        cloud_path(f, c, path, sizeof(path));
        enum sb_result res = cloud_integer(cJSON_GetArrayItem(item, c), source, path, &dst[c]);
        if (res)
            return res;
    }
    return SB_OK;
}

/* The keys of one object of "clouds" (object NULL: "clouds" itself). */
static enum sb_result parse_cloud_object(const cJSON *obj, const char *object, struct sb_cloud_params *p,
                                         const char *source)
{
    char where[64];
    snprintf(where, sizeof(where), "clouds%s%s", object ? "." : "", object ? object : "");
    if (!cJSON_IsObject(obj)) {
        sb_error("%s: %s: expected an object", source, where);
        return SB_ERR_WRONG_TYPE;
    }
    enum sb_result res = sb_json_check_duplicates(obj, source, where);
    for (const cJSON *item = obj->child; item && !res; item = item->next) {
        if (!object) {
            size_t o = 0;
            while (o < 4 && strcmp(item->string, cloud_objects[o]))
                o++;
            if (o < 4) {
                res = parse_cloud_object(item, cloud_objects[o], p, source);
                continue;
            }
        }
        const struct cloud_field *f = NULL;
        for (size_t i = 0; i < CLOUD_FIELD_COUNT && !f; i++)
            if ((object ? cloud_fields[i].object && !strcmp(cloud_fields[i].object, object)
                        : !cloud_fields[i].object) &&
                !strcmp(cloud_fields[i].key, item->string))
                f = &cloud_fields[i];
        if (!f) {
            sb_error("%s: %s.%s: unknown key (see docs/scene.md for the schema)", source, where, item->string);
            return SB_ERR_UNKNOWN_KEY;
        }
        res = parse_cloud_field(f, item, p, source);
    }
    return res;
}

static enum sb_result clouds_section_parse(const cJSON *obj, struct sb_scene *scene, const char *source)
{
    enum sb_result res = parse_cloud_object(obj, NULL, &scene->clouds, source);
    scene->has_clouds = true;
    return res ? res : sb_cloud_params_validate(&scene->clouds, source);
}

static cJSON *clouds_section_json(const struct sb_scene *scene)
{
    /* Only when given or used, so that scenes without clouds keep the hashes
     * they had in format version 1. */
    bool used = scene->has_clouds;
    for (int p = 0; p < SB_PRODUCT_COUNT; p++)
        used |= scene->wants[p] && sb_product_format((enum sb_product_id)p)->family == SB_FAMILY_CLOUDS;
    if (!used)
        return NULL;
    const struct sb_cloud_params *p = &scene->clouds;
    cJSON *clouds = cJSON_CreateObject();
    cJSON *objects[4];
    for (int o = 0; o < 4; o++)
        objects[o] = cJSON_AddObjectToObject(clouds, cloud_objects[o]);
    for (size_t i = 0; i < CLOUD_FIELD_COUNT; i++) {
        const struct cloud_field *f = &cloud_fields[i];
        const uint32_t *v = cloud_cptr(p, f);
        cJSON *parent = clouds;
        for (int o = 0; o < 4; o++)
            if (f->object && !strcmp(f->object, cloud_objects[o]))
                parent = objects[o];
        if (f->count == 1) {
            cJSON_AddNumberToObject(parent, f->key, v[0]);
        } else {
            cJSON *arr = cJSON_AddArrayToObject(parent, f->key);
            for (int c = 0; c < f->count; c++)
                cJSON_AddItemToArray(arr, cJSON_CreateNumber(v[c]));
        }
    }
    return clouds;
}

static void clouds_product_shape(const struct sb_scene *scene, enum sb_product_id id, uint32_t shape[3])
{
    const struct sb_cloud_params *c = &scene->clouds;
    uint32_t n = id == SB_PRODUCT_CLOUD_SHAPE    ? c->shape_size
                 : id == SB_PRODUCT_CLOUD_DETAIL ? c->detail_size
                 : id == SB_PRODUCT_CLOUD_CURL   ? c->curl_size
                 : id == SB_PRODUCT_WEATHER      ? c->weather_size
                                                 : 0;
    for (int k = 0; k < 3; k++)
        shape[k] = shape[k] ? shape[k] : n;
}

const struct sb_family_format sb_clouds_family_format = {
    .name = "clouds",
    .section = "clouds",
    .set_defaults = clouds_set_defaults,
    .parse_section = clouds_section_parse,
    .section_json = clouds_section_json,
    .product_shape = clouds_product_shape,
    .no_tolerance = "the cloud noise is baked exactly (bit for bit with its CPU reference) and takes no tolerance",
};

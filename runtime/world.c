#include "world.h"

#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json.h"
#include "log.h"

#define WORLD_MAX_BYTES (1 << 20)

struct reader {
    const char *source;
    char path[128];
};

static enum sb_result number(const struct reader *rd, const cJSON *obj, const char *key, double lo, double hi,
                             double fallback, double *out)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!item) {
        if (isnan(fallback)) {
            sb_error("%s: %s%s: missing", rd->source, rd->path, key);
            return SB_ERR_MISSING_FIELD;
        }
        *out = fallback;
        return SB_OK;
    }
    if (!cJSON_IsNumber(item)) {
        sb_error("%s: %s%s: expected a number", rd->source, rd->path, key);
        return SB_ERR_WRONG_TYPE;
    }
    if (!(item->valuedouble >= lo && item->valuedouble <= hi)) {
        sb_error("%s: %s%s: %g is outside [%g, %g]", rd->source, rd->path, key, item->valuedouble, lo, hi);
        return SB_ERR_OUT_OF_RANGE;
    }
    *out = item->valuedouble;
    return SB_OK;
}

static enum sb_result vec3(const struct reader *rd, const cJSON *obj, const char *key, double lo, double hi,
                           const double *fallback, double out[3])
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!item && fallback) {
        memcpy(out, fallback, 3 * sizeof(double));
        return SB_OK;
    }
    if (!item) {
        sb_error("%s: %s%s: missing", rd->source, rd->path, key);
        return SB_ERR_MISSING_FIELD;
    }
    if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != 3) {
        sb_error("%s: %s%s: expected an array of 3 numbers", rd->source, rd->path, key);
        return SB_ERR_WRONG_TYPE;
    }
    for (int i = 0; i < 3; i++) {
        const cJSON *v = cJSON_GetArrayItem(item, i);
        if (!cJSON_IsNumber(v)) {
            sb_error("%s: %s%s[%d]: expected a number", rd->source, rd->path, key, i);
            return SB_ERR_WRONG_TYPE;
        }
        if (!(v->valuedouble >= lo && v->valuedouble <= hi)) {
            sb_error("%s: %s%s[%d]: %g is outside [%g, %g]", rd->source, rd->path, key, i, v->valuedouble, lo, hi);
            return SB_ERR_OUT_OF_RANGE;
        }
        out[i] = v->valuedouble;
    }
    return SB_OK;
}

/* Every key of `obj` must be one of `keys` (NULL-terminated). */
static enum sb_result known_keys(const struct reader *rd, const cJSON *obj, const char *const *keys)
{
    if (!cJSON_IsObject(obj)) {
        sb_error("%s: %s: expected an object", rd->source, rd->path[0] ? rd->path : "(root)");
        return SB_ERR_WRONG_TYPE;
    }
    enum sb_result res = sb_json_check_duplicates(obj, rd->source, rd->path);
    if (res)
        return res;
    const cJSON *item;
    cJSON_ArrayForEach(item, obj)
    {
        bool found = false;
        for (int i = 0; keys[i] && !found; i++)
            found = strcmp(item->string, keys[i]) == 0;
        if (!found) {
            sb_error("%s: %s%s: unknown key", rd->source, rd->path, item->string);
            return SB_ERR_UNKNOWN_KEY;
        }
    }
    return SB_OK;
}

#define MATERIAL_KEYS "albedo", "roughness", "metallic"

static enum sb_result material(const struct reader *rd, const cJSON *obj, struct sb_material *m)
{
    static const double grey[3] = {0.5, 0.5, 0.5};
    enum sb_result res = vec3(rd, obj, "albedo", 0.0, 1.0, grey, m->albedo);
    if (!res)
        res = number(rd, obj, "roughness", 0.0, 1.0, 0.5, &m->roughness);
    if (!res)
        res = number(rd, obj, "metallic", 0.0, 1.0, 0.0, &m->metallic);
    return res;
}

static enum sb_result array(const struct reader *rd, const cJSON *root, const char *key, const cJSON **out, int *count)
{
    *out = cJSON_GetObjectItemCaseSensitive(root, key);
    *count = 0;
    if (!*out)
        return SB_OK;
    if (!cJSON_IsArray(*out)) {
        sb_error("%s: %s: expected an array", rd->source, key);
        return SB_ERR_WRONG_TYPE;
    }
    *count = cJSON_GetArraySize(*out);
    if (*count > SB_WORLD_MAX_OBJECTS) {
        sb_error("%s: %s: %d entries; at most %d", rd->source, key, *count, SB_WORLD_MAX_OBJECTS);
        return SB_ERR_OUT_OF_RANGE;
    }
    return SB_OK;
}

static enum sb_result parse(const cJSON *root, const char *source, struct sb_world *w)
{
    struct reader rd = {.source = source};
    static const char *const root_keys[] = {"version", "ground", "boxes", "pillars", NULL};
    enum sb_result res = known_keys(&rd, root, root_keys);
    double version = 0;
    if (!res)
        res = number(&rd, root, "version", 1, 1, NAN, &version);
    const cJSON *ground = res ? NULL : cJSON_GetObjectItemCaseSensitive(root, "ground");
    if (!res && ground) {
        static const char *const keys[] = {"size_m", MATERIAL_KEYS, NULL};
        snprintf(rd.path, sizeof(rd.path), "ground.");
        res = known_keys(&rd, ground, keys);
        if (!res)
            res = number(&rd, ground, "size_m", 1.0, 200000.0, 40000.0, &w->ground_size_m);
        if (!res)
            res = material(&rd, ground, &w->ground);
    } else if (!res) {
        w->ground_size_m = 40000.0;
        res = material(&rd, root, &w->ground); /* defaults */
    }
    const cJSON *list, *item;
    int n = 0;
    if (!res)
        res = array(&rd, root, "boxes", &list, &n);
    w->box_count = res ? 0 : n;
    for (int i = 0; i < w->box_count && !res; i++) {
        static const char *const keys[] = {"center_m", "size_m", MATERIAL_KEYS, NULL};
        struct sb_world_box *b = &w->boxes[i];
        item = cJSON_GetArrayItem(list, i);
        snprintf(rd.path, sizeof(rd.path), "boxes[%d].", i);
        res = known_keys(&rd, item, keys);
        if (!res)
            res = vec3(&rd, item, "center_m", -1e5, 1e5, NULL, b->center_m);
        if (!res)
            res = vec3(&rd, item, "size_m", 1e-3, 1e4, NULL, b->size_m);
        if (!res)
            res = material(&rd, item, &b->material);
    }
    if (!res)
        res = array(&rd, root, "pillars", &list, &n);
    w->pillar_count = res ? 0 : n;
    for (int i = 0; i < w->pillar_count && !res; i++) {
        static const char *const keys[] = {"base_m", "radius_m", "height_m", "sides", MATERIAL_KEYS, NULL};
        struct sb_world_pillar *p = &w->pillars[i];
        item = cJSON_GetArrayItem(list, i);
        snprintf(rd.path, sizeof(rd.path), "pillars[%d].", i);
        double sides = 0;
        res = known_keys(&rd, item, keys);
        if (!res)
            res = vec3(&rd, item, "base_m", -1e5, 1e5, NULL, p->base_m);
        if (!res)
            res = number(&rd, item, "radius_m", 1e-3, 1e4, NAN, &p->radius_m);
        if (!res)
            res = number(&rd, item, "height_m", 1e-3, 1e4, NAN, &p->height_m);
        if (!res)
            res = number(&rd, item, "sides", 3, 64, 16, &sides);
        if (!res && sides != floor(sides)) {
            sb_error("%s: %ssides: expected a whole number", source, rd.path);
            res = SB_ERR_OUT_OF_RANGE;
        }
        p->sides = (int)sides;
        if (!res)
            res = material(&rd, item, &p->material);
    }
    return res;
}

/* ---- Triangles ----------------------------------------------------------------- */

struct builder {
    struct sb_vertex_gpu *v;
    uint32_t count;
};

static void put(struct builder *b, const double p[3], const double n[3], const struct sb_material *m)
{
    struct sb_vertex_gpu *v = &b->v[b->count++];
    for (int i = 0; i < 3; i++) {
        v->position[i] = (float)p[i];
        v->normal[i] = (float)n[i];
        v->albedo[i] = (float)m->albedo[i];
    }
    v->position[3] = (float)m->metallic;
    v->normal[3] = (float)m->roughness;
    v->albedo[3] = 1.0f;
}

/* A quad a, b, c, d (counter-clockwise seen from where n points). */
static void quad(struct builder *b, const double a[3], const double bb[3], const double c[3], const double d[3],
                 const double n[3], const struct sb_material *m)
{
    put(b, a, n, m);
    put(b, bb, n, m);
    put(b, c, n, m);
    put(b, a, n, m);
    put(b, c, n, m);
    put(b, d, n, m);
}

static void box(struct builder *b, const struct sb_world_box *x)
{
    /* Each face: its normal axis and sign, and two tangent axes forming a right-handed frame. */
    for (int axis = 0; axis < 3; axis++)
        for (int sign = -1; sign <= 1; sign += 2) {
            int u = (axis + 1) % 3, v = (axis + 2) % 3;
            double n[3] = {0, 0, 0};
            n[axis] = sign;
            double corner[4][3];
            static const double su[4] = {-1, 1, 1, -1}, sv[4] = {-1, -1, 1, 1};
            for (int k = 0; k < 4; k++) {
                corner[k][axis] = x->center_m[axis] + sign * 0.5 * x->size_m[axis];
                corner[k][u] = x->center_m[u] + su[k] * 0.5 * x->size_m[u] * sign;
                corner[k][v] = x->center_m[v] + sv[k] * 0.5 * x->size_m[v];
            }
            quad(b, corner[0], corner[1], corner[2], corner[3], n, &x->material);
        }
}

static void pillar(struct builder *b, const struct sb_world_pillar *x)
{
    double top = x->base_m[1] + x->height_m;
    const double up[3] = {0, 1, 0}, down[3] = {0, -1, 0};
    double centre_top[3] = {x->base_m[0], top, x->base_m[2]};
    double centre_bottom[3] = {x->base_m[0], x->base_m[1], x->base_m[2]};
    for (int i = 0; i < x->sides; i++) {
        double a0 = 2.0 * M_PI * i / x->sides, a1 = 2.0 * M_PI * (i + 1) / x->sides, am = 0.5 * (a0 + a1);
        double c0 = cos(a0), s0 = sin(a0), c1 = cos(a1), s1 = sin(a1);
        double p0b[3] = {x->base_m[0] + x->radius_m * c0, x->base_m[1], x->base_m[2] - x->radius_m * s0};
        double p1b[3] = {x->base_m[0] + x->radius_m * c1, x->base_m[1], x->base_m[2] - x->radius_m * s1};
        double p0t[3] = {p0b[0], top, p0b[2]}, p1t[3] = {p1b[0], top, p1b[2]};
        double n[3] = {cos(am), 0, -sin(am)}; /* flat sides: the shadow test knows the exact outline */
        quad(b, p0b, p1b, p1t, p0t, n, &x->material);
        put(b, centre_top, up, &x->material);
        put(b, p0t, up, &x->material);
        put(b, p1t, up, &x->material);
        put(b, centre_bottom, down, &x->material);
        put(b, p1b, down, &x->material);
        put(b, p0b, down, &x->material);
    }
}

static enum sb_result build(struct sb_world *w)
{
    uint32_t count = 6 + (uint32_t)w->box_count * 36;
    for (int i = 0; i < w->pillar_count; i++)
        count += (uint32_t)w->pillars[i].sides * 12;
    struct builder b = {.v = calloc(count, sizeof(struct sb_vertex_gpu))};
    if (!b.v)
        return SB_ERR_NOMEM;
    double h = 0.5 * w->ground_size_m;
    const double up[3] = {0, 1, 0};
    double g[4][3] = {{-h, 0, h}, {h, 0, h}, {h, 0, -h}, {-h, 0, -h}};
    quad(&b, g[0], g[1], g[2], g[3], up, &w->ground);
    w->caster_first_vertex = b.count;
    for (int i = 0; i < w->box_count; i++)
        box(&b, &w->boxes[i]);
    for (int i = 0; i < w->pillar_count; i++)
        pillar(&b, &w->pillars[i]);
    w->vertices = b.v;
    w->vertex_count = b.count;
    return SB_OK;
}

/* A parsed root (deleted here) to a world. */
static enum sb_result world_from_root(enum sb_result res, cJSON *root, const char *source, struct sb_world *w)
{
    if (!res)
        res = parse(root, source, w);
    cJSON_Delete(root);
    if (!res)
        res = build(w);
    if (res)
        sb_world_finish(w);
    return res;
}

enum sb_result sb_world_load(const char *path, struct sb_world *w)
{
    memset(w, 0, sizeof(*w));
    cJSON *root = NULL;
    enum sb_result res = sb_json_load(AT_FDCWD, path, path, WORLD_MAX_BYTES, true, &root);
    return world_from_root(res, root, path, w);
}

enum sb_result sb_world_parse(const char *json, size_t size, const char *source, struct sb_world *w)
{
    memset(w, 0, sizeof(*w));
    cJSON *root = NULL;
    enum sb_result res = size > WORLD_MAX_BYTES ? SB_ERR_OUT_OF_RANGE : sb_json_parse(json, size, source, &root);
    return world_from_root(res, root, source, w);
}

void sb_world_finish(struct sb_world *w)
{
    free(w->vertices);
    memset(w, 0, sizeof(*w));
}

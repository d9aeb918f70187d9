#include "world_file.h"

#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json.h"
#include "log.h"

struct material {
    double albedo[3]; /* linear base colour, [0, 1] */
    double roughness; /* perceptual, [0, 1] */
    double metallic;  /* [0, 1] */
};

struct box {
    double center_m[3];
    double size_m[3];
    struct material material;
};

struct pillar {
    double base_m[3]; /* centre of the bottom face */
    double radius_m;
    double height_m;
    int sides; /* 3 to 64 */
    struct material material;
};

/* Rolling hills: a square heightfield of cells x cells quads centred on
 * the origin, heights from seeded value noise (4 octaves). */
struct terrain {
    double size_m, height_m;
    int cells;
    uint32_t seed;
    struct material material;
};

struct world {
    bool no_ground;       /* "ground": false */
    bool has_terrain;
    struct terrain terrain;
    double ground_size_m; /* the ground plane is this wide, centred on the origin */
    struct material ground;
    int box_count, pillar_count;
    struct box boxes[SB_WORLD_FILE_MAX_OBJECTS];
    struct pillar pillars[SB_WORLD_FILE_MAX_OBJECTS];
    struct sb_world_file_refs refs;
};

/* ---- Parsing ------------------------------------------------------------------- */

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

/* An array of n numbers in [lo, hi]. */
static enum sb_result numbers(const struct reader *rd, const cJSON *obj, const char *key, int n, double lo, double hi,
                              const double *fallback, double *out)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!item && fallback) {
        memcpy(out, fallback, (size_t)n * sizeof(double));
        return SB_OK;
    }
    if (!item || !cJSON_IsArray(item) || cJSON_GetArraySize(item) != n) {
        sb_error("%s: %s%s: %s an array of %d numbers", rd->source, rd->path, key, item ? "expected" : "missing:", n);
        return item ? SB_ERR_WRONG_TYPE : SB_ERR_MISSING_FIELD;
    }
    for (int i = 0; i < n; i++) {
        const cJSON *v = cJSON_GetArrayItem(item, i);
        if (!cJSON_IsNumber(v) || !(v->valuedouble >= lo && v->valuedouble <= hi)) {
            sb_error("%s: %s%s[%d]: expected a number in [%g, %g]", rd->source, rd->path, key, i, lo, hi);
            return cJSON_IsNumber(v) ? SB_ERR_OUT_OF_RANGE : SB_ERR_WRONG_TYPE;
        }
        out[i] = v->valuedouble;
    }
    return SB_OK;
}

static enum sb_result boolean(const struct reader *rd, const cJSON *obj, const char *key, bool *out)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!item)
        return SB_OK;
    if (!cJSON_IsBool(item)) {
        sb_error("%s: %s%s: expected true or false", rd->source, rd->path, key);
        return SB_ERR_WRONG_TYPE;
    }
    *out = cJSON_IsTrue(item);
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

static enum sb_result material(const struct reader *rd, const cJSON *obj, struct material *m)
{
    static const double grey[3] = {0.5, 0.5, 0.5};
    enum sb_result res = vec3(rd, obj, "albedo", 0.0, 1.0, grey, m->albedo);
    if (!res)
        res = number(rd, obj, "roughness", 0.0, 1.0, 0.5, &m->roughness);
    if (!res)
        res = number(rd, obj, "metallic", 0.0, 1.0, 0.0, &m->metallic);
    return res;
}

static enum sb_result array(const struct reader *rd, const cJSON *root, const char *key, int max, const cJSON **out,
                            int *count)
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
    if (*count > max) {
        sb_error("%s: %s: %d entries; at most %d", rd->source, key, *count, max);
        return SB_ERR_OUT_OF_RANGE;
    }
    return SB_OK;
}

static enum sb_result parse(const cJSON *root, const char *source, struct world *w)
{
    struct reader rd = {.source = source};
    static const char *const root_keys[] = {"version", "ground", "terrain", "boxes", "pillars", "instances", "scatter",
                                            NULL};
    enum sb_result res = known_keys(&rd, root, root_keys);
    double version = 0;
    if (!res)
        res = number(&rd, root, "version", 1, 1, NAN, &version);
    const cJSON *ground = res ? NULL : cJSON_GetObjectItemCaseSensitive(root, "ground");
    if (!res && cJSON_IsFalse(ground)) {
        w->no_ground = true;
    } else if (!res && ground) {
        static const char *const keys[] = {"size_m", MATERIAL_KEYS, NULL};
        snprintf(rd.path, sizeof(rd.path), "ground.");
        res = known_keys(&rd, ground, keys);
        if (!res)
            res = number(&rd, ground, "size_m", 1.0, 2.0 * SB_MESH_MAX_EXTENT_M, 2.0 * SB_MESH_MAX_EXTENT_M,
                         &w->ground_size_m);
        if (!res)
            res = material(&rd, ground, &w->ground);
    } else if (!res) {
        w->ground_size_m = 2.0 * SB_MESH_MAX_EXTENT_M;
        res = material(&rd, root, &w->ground); /* defaults */
    }
    const cJSON *terrain = res ? NULL : cJSON_GetObjectItemCaseSensitive(root, "terrain");
    if (!res && terrain) {
        static const char *const keys[] = {"size_m", "cells", "height_m", "seed", MATERIAL_KEYS, NULL};
        struct terrain *t = &w->terrain;
        double cells = 0, seed = 0;
        snprintf(rd.path, sizeof(rd.path), "terrain.");
        w->has_terrain = true;
        res = known_keys(&rd, terrain, keys);
        if (!res)
            res = number(&rd, terrain, "size_m", 1.0, 2.0 * SB_MESH_MAX_EXTENT_M, NAN, &t->size_m);
        if (!res)
            res = number(&rd, terrain, "cells", 1, SB_WORLD_FILE_MAX_TERRAIN_CELLS, NAN, &cells);
        if (!res)
            res = number(&rd, terrain, "height_m", 0.0, 1e3, 10.0, &t->height_m);
        if (!res)
            res = number(&rd, terrain, "seed", 0, 4294967295.0, 1, &seed);
        if (!res && (cells != floor(cells) || seed != floor(seed))) {
            sb_error("%s: terrain: cells and seed are whole numbers", source);
            res = SB_ERR_OUT_OF_RANGE;
        }
        if (!res)
            res = material(&rd, terrain, &t->material);
        t->cells = (int)cells;
        t->seed = (uint32_t)seed;
    }
    const cJSON *list, *item;
    int n = 0;
    if (!res)
        res = array(&rd, root, "boxes", SB_WORLD_FILE_MAX_OBJECTS, &list, &n);
    w->box_count = res ? 0 : n;
    for (int i = 0; i < w->box_count && !res; i++) {
        static const char *const keys[] = {"center_m", "size_m", MATERIAL_KEYS, NULL};
        struct box *b = &w->boxes[i];
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
        res = array(&rd, root, "pillars", SB_WORLD_FILE_MAX_OBJECTS, &list, &n);
    w->pillar_count = res ? 0 : n;
    for (int i = 0; i < w->pillar_count && !res; i++) {
        static const char *const keys[] = {"base_m", "radius_m", "height_m", "sides", MATERIAL_KEYS, NULL};
        struct pillar *p = &w->pillars[i];
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
    int instance_count = 0, scatter_count = 0;
    const cJSON *instances = NULL, *scatters = NULL;
    if (!res)
        res = array(&rd, root, "instances", SB_WORLD_FILE_MAX_REFS, &instances, &instance_count);
    if (!res)
        res = array(&rd, root, "scatter", SB_WORLD_FILE_MAX_REFS, &scatters, &scatter_count);
    if (!res && instance_count + scatter_count > SB_WORLD_FILE_MAX_REFS) {
        sb_error("%s: instances and scatter: %d entries; at most %d", source, instance_count + scatter_count,
                 SB_WORLD_FILE_MAX_REFS);
        res = SB_ERR_OUT_OF_RANGE;
    }
    if (!res && instance_count + scatter_count) {
        w->refs.refs = calloc((size_t)(instance_count + scatter_count), sizeof(*w->refs.refs));
        if (!w->refs.refs)
            res = SB_ERR_NOMEM;
    }
    for (int i = 0; i < instance_count + scatter_count && !res; i++) {
        bool scatter = i >= instance_count;
        struct sb_world_file_ref *r = &w->refs.refs[w->refs.count++];
        item = cJSON_GetArrayItem(scatter ? scatters : instances, scatter ? i - instance_count : i);
        snprintf(rd.path, sizeof(rd.path), "%s[%d].", scatter ? "scatter" : "instances", scatter ? i - instance_count : i);
        static const char *const instance_keys[] = {"file", "translate_m", "rotate_deg", "scale", "units_m", "up_z", NULL};
        static const char *const scatter_keys[] = {"file", "count", "seed", "area_m", "scale", "units_m", "up_z", NULL};
        res = known_keys(&rd, item, scatter ? scatter_keys : instance_keys);
        const cJSON *file = res ? NULL : cJSON_GetObjectItemCaseSensitive(item, "file");
        if (!res && (!cJSON_IsString(file) || !file->valuestring[0] || strlen(file->valuestring) >= sizeof(r->file))) {
            sb_error("%s: %sfile: %s", source, rd.path,
                     file ? "expected a path of 1 to 1023 bytes" : "missing: the mesh or world file to place");
            res = file ? SB_ERR_WRONG_TYPE : SB_ERR_MISSING_FIELD;
        }
        if (!res)
            snprintf(r->file, sizeof(r->file), "%s", file->valuestring);
        static const double zero[3] = {0, 0, 0};
        r->scatter = scatter;
        if (!res)
            res = number(&rd, item, "units_m", 1e-6, 1e6, 1.0, &r->transform.units_m);
        if (!res)
            res = boolean(&rd, item, "up_z", &r->transform.up_z);
        if (!res && !scatter) {
            res = vec3(&rd, item, "translate_m", -SB_MESH_MAX_EXTENT_M, SB_MESH_MAX_EXTENT_M, zero,
                       r->transform.translate_m);
            if (!res)
                res = vec3(&rd, item, "rotate_deg", -360, 360, zero, r->transform.rotate_deg);
            if (!res)
                res = number(&rd, item, "scale", 1e-6, 1e6, 1.0, &r->transform.scale);
        } else if (!res) {
            double count = 0, seed = 0;
            static const double one[2] = {1, 1};
            res = number(&rd, item, "count", 1, SB_WORLD_FILE_MAX_SCATTER, NAN, &count);
            if (!res && count != floor(count)) {
                sb_error("%s: %scount: expected a whole number", source, rd.path);
                res = SB_ERR_OUT_OF_RANGE;
            }
            if (!res)
                res = number(&rd, item, "seed", 0, 4294967295.0, 1, &seed);
            if (!res && seed != floor(seed)) {
                sb_error("%s: %sseed: expected a whole number", source, rd.path);
                res = SB_ERR_OUT_OF_RANGE;
            }
            if (!res)
                res = numbers(&rd, item, "area_m", 4, -SB_MESH_MAX_EXTENT_M, SB_MESH_MAX_EXTENT_M, NULL, r->area_m);
            if (!res && !(r->area_m[2] > r->area_m[0] && r->area_m[3] > r->area_m[1])) {
                sb_error("%s: %sarea_m: expected [x0, z0, x1, z1] with x1 > x0 and z1 > z0", source, rd.path);
                res = SB_ERR_OUT_OF_RANGE;
            }
            if (!res)
                res = numbers(&rd, item, "scale", 2, 1e-6, 1e6, one, r->scale_range);
            if (!res && r->scale_range[1] < r->scale_range[0]) {
                sb_error("%s: %sscale: expected [smallest, largest]", source, rd.path);
                res = SB_ERR_OUT_OF_RANGE;
            }
            r->count = (uint32_t)count;
            r->seed = (uint64_t)seed;
        }
    }
    return res;
}

/* ---- Triangles ----------------------------------------------------------------- */

struct builder {
    struct sb_mesh *mesh;
    const struct sb_mesh_load_params *params;
    double to_world[3][4]; /* params' transform, made once */
    const char *source;
    uint32_t material;
    enum sb_result res;
};

/* A material named `name`, with the scene's override where one names it. */
static void begin(struct builder *b, const char *name, const struct material *m, bool casts_shadows)
{
    if (b->res)
        return;
    double albedo[3];
    memcpy(albedo, m->albedo, sizeof(albedo));
    for (int o = 0; o < b->params->override_count; o++) {
        const struct sb_mesh_albedo_override *ov = &b->params->overrides[o];
        if (!strcmp(ov->material, "*") || !strcmp(ov->material, name))
            memcpy(albedo, ov->albedo, sizeof(albedo));
    }
    if ((b->res = sb_mesh_add_material(b->mesh, name, albedo, &b->material)))
        return;
    struct sb_mesh_material *out = &b->mesh->material_list[b->material];
    out->roughness = (float)m->roughness;
    out->metallic = (float)m->metallic;
    out->casts_shadows = casts_shadows;
}

static void triangle(struct builder *b, const double p0[3], const double p1[3], const double p2[3])
{
    if (b->res)
        return;
    double q[3][3];
    const double *p[3] = {p0, p1, p2};
    const double(*m)[4] = b->to_world;
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < 3; i++)
            q[k][i] = m[i][0] * p[k][0] + m[i][1] * p[k][1] + m[i][2] * p[k][2] + m[i][3];
    b->res = sb_mesh_add_triangle(b->mesh, q[0], q[1], q[2], b->material, b->source);
}

/* A quad a, b, c, d (counter-clockwise seen from outside). */
static void quad(struct builder *b, const double a[3], const double bb[3], const double c[3], const double d[3])
{
    triangle(b, a, bb, c);
    triangle(b, a, c, d);
}

static void box(struct builder *b, const struct box *x)
{
    /* Each face: its normal axis and sign, and two tangent axes forming a right-handed frame. */
    for (int axis = 0; axis < 3; axis++)
        for (int sign = -1; sign <= 1; sign += 2) {
            int u = (axis + 1) % 3, v = (axis + 2) % 3;
            double corner[4][3];
            static const double su[4] = {-1, 1, 1, -1}, sv[4] = {-1, -1, 1, 1};
            for (int k = 0; k < 4; k++) {
                corner[k][axis] = x->center_m[axis] + sign * 0.5 * x->size_m[axis];
                corner[k][u] = x->center_m[u] + su[k] * 0.5 * x->size_m[u] * sign;
                corner[k][v] = x->center_m[v] + sv[k] * 0.5 * x->size_m[v];
            }
            quad(b, corner[0], corner[1], corner[2], corner[3]);
        }
}

/* Flat sides: the shadow test knows the exact outline. */
static void pillar(struct builder *b, const struct pillar *x)
{
    double top = x->base_m[1] + x->height_m;
    double centre_top[3] = {x->base_m[0], top, x->base_m[2]};
    double centre_bottom[3] = {x->base_m[0], x->base_m[1], x->base_m[2]};
    for (int i = 0; i < x->sides; i++) {
        double a0 = 2.0 * M_PI * i / x->sides, a1 = 2.0 * M_PI * (i + 1) / x->sides;
        double c0 = cos(a0), s0 = sin(a0), c1 = cos(a1), s1 = sin(a1);
        double p0b[3] = {x->base_m[0] + x->radius_m * c0, x->base_m[1], x->base_m[2] - x->radius_m * s0};
        double p1b[3] = {x->base_m[0] + x->radius_m * c1, x->base_m[1], x->base_m[2] - x->radius_m * s1};
        double p0t[3] = {p0b[0], top, p0b[2]}, p1t[3] = {p1b[0], top, p1b[2]};
        quad(b, p0b, p1b, p1t, p0t);
        triangle(b, centre_top, p0t, p1t);
        triangle(b, centre_bottom, p1b, p0b);
    }
}

static double lattice(uint32_t seed, int64_t i, int64_t j)
{
    uint64_t h = seed * 0x9e3779b97f4a7c15ull ^ (uint64_t)i * 0xbf58476d1ce4e5b9ull ^ (uint64_t)j * 0x94d049bb133111ebull;
    h ^= h >> 31;
    h *= 0xd6e8feb86659fd93ull;
    h ^= h >> 32;
    return (double)(h >> 11) * 0x1.0p-52 - 1.0; /* [-1, 1) */
}

/* Value noise, smoothly interpolated, four octaves: in about [-1, 1]. */
static double hills(uint32_t seed, double x, double z)
{
    double sum = 0, amplitude = 0.5333;
    for (int o = 0; o < 4; o++, x *= 2, z *= 2, amplitude *= 0.5) {
        double fx = floor(x), fz = floor(z), u = x - fx, v = z - fz;
        u = u * u * (3 - 2 * u);
        v = v * v * (3 - 2 * v);
        int64_t i = (int64_t)fx, j = (int64_t)fz;
        double a = lattice(seed + (uint32_t)o, i, j), b = lattice(seed + (uint32_t)o, i + 1, j);
        double c = lattice(seed + (uint32_t)o, i, j + 1), d = lattice(seed + (uint32_t)o, i + 1, j + 1);
        sum += amplitude * ((a + (b - a) * u) * (1 - v) + (c + (d - c) * u) * v);
    }
    return sum;
}

static void terrain(struct builder *b, const struct terrain *t)
{
    int n = t->cells;
    double step = t->size_m / n, half = 0.5 * t->size_m, scale = 4.0 / t->size_m; /* four hills across */
    for (int j = 0; j < n && !b->res; j++)
        for (int i = 0; i < n && !b->res; i++) {
            double p[4][3];
            for (int k = 0; k < 4; k++) {
                double x = -half + (i + (k & 1)) * step, z = -half + (j + (k >> 1)) * step;
                p[k][0] = x;
                p[k][1] = t->height_m * hills(t->seed, (x + half) * scale, (z + half) * scale);
                p[k][2] = z;
            }
            /* counter-clockwise seen from above */
            triangle(b, p[0], p[2], p[1]);
            triangle(b, p[1], p[2], p[3]);
        }
}

static enum sb_result build(const struct world *w, const char *source, const struct sb_mesh_load_params *params,
                            struct sb_mesh *mesh)
{
    struct builder b = {.mesh = mesh, .params = params, .source = source};
    sb_mesh_transform_matrix(&params->transform, b.to_world);
    double h = 0.5 * w->ground_size_m;
    double g[4][3] = {{-h, 0, h}, {h, 0, h}, {h, 0, -h}, {-h, 0, -h}};
    if (!w->no_ground) {
        begin(&b, "ground", &w->ground, false);
        quad(&b, g[0], g[1], g[2], g[3]);
    }
    if (w->has_terrain) {
        begin(&b, "terrain", &w->terrain.material, true);
        terrain(&b, &w->terrain);
    }
    char name[32];
    for (int i = 0; i < w->box_count; i++) {
        snprintf(name, sizeof(name), "boxes[%d]", i);
        begin(&b, name, &w->boxes[i].material, true);
        box(&b, &w->boxes[i]);
    }
    for (int i = 0; i < w->pillar_count; i++) {
        snprintf(name, sizeof(name), "pillars[%d]", i);
        begin(&b, name, &w->pillars[i].material, true);
        pillar(&b, &w->pillars[i]);
    }
    return b.res;
}

/* A parsed root (deleted here) to triangles and places; *mesh as it was
 * and *refs empty on failure. */
static enum sb_result from_root(enum sb_result res, cJSON *root, const char *source,
                                const struct sb_mesh_load_params *params, struct sb_mesh *mesh,
                                struct sb_world_file_refs *refs)
{
    static const struct sb_mesh_load_params defaults = {0};
    params = params ? params : &defaults;
    if (refs)
        memset(refs, 0, sizeof(*refs));
    struct world *w = res ? NULL : calloc(1, sizeof(*w));
    if (!res && !w)
        res = SB_ERR_NOMEM;
    if (!res)
        res = parse(root, source, w);
    cJSON_Delete(root);
    if (!res && w->refs.count && !refs) {
        sb_error("%s: places other files (instances, scatter): read it as a scene's world, not as one mesh", source);
        res = SB_ERR_MESH;
    }
    struct sb_mesh before = *mesh;
    if (!res)
        res = build(w, source, params, mesh);
    if (res) {
        mesh->vertex_count = before.vertex_count;
        mesh->triangle_count = before.triangle_count;
        mesh->material_count = before.material_count;
        mesh->dropped_degenerate = before.dropped_degenerate;
    }
    if (w && !res && refs)
        *refs = w->refs;
    else if (w)
        free(w->refs.refs);
    free(w);
    return res;
}

enum sb_result sb_world_file_load(const char *path, const struct sb_mesh_load_params *params, struct sb_mesh *mesh,
                                  struct sb_world_file_refs *refs)
{
    cJSON *root = NULL;
    enum sb_result res = sb_json_load(AT_FDCWD, path, path, SB_WORLD_FILE_MAX_BYTES, true, &root);
    return from_root(res, root, path, params, mesh, refs);
}

enum sb_result sb_world_file_parse(const char *json, size_t size, const char *source,
                                   const struct sb_mesh_load_params *params, struct sb_mesh *mesh,
                                   struct sb_world_file_refs *refs)
{
    cJSON *root = NULL;
    enum sb_result res = SB_OK;
    if (size > SB_WORLD_FILE_MAX_BYTES) {
        sb_error("%s: %zu bytes; world files are read up to %d", source, size, SB_WORLD_FILE_MAX_BYTES);
        res = SB_ERR_TOO_LARGE;
    }
    if (!res)
        res = sb_json_parse(json, size, source, &root);
    return from_root(res, root, source, params, mesh, refs);
}

#include "pack_tools.h"

#include <cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "json.h"
#include "log.h"
#include "pngfile.h"
#include "scene.h"

static long long file_bytes(const char *dir, const char *file)
{
    char path[4096];
    struct stat st;
    snprintf(path, sizeof(path), "%s/%s", dir, file);
    return stat(path, &st) == 0 ? (long long)st.st_size : -1;
}

/* The channels' names, comma-separated; a list that does not fit in size
 * ends with ",... (N channels)". */
static void channel_list(const struct sb_image *image, char *out, size_t size)
{
    size_t n = 0;
    out[0] = '\0';
    for (uint32_t c = 0; c < image->channel_count; c++) {
        size_t need = strlen(image->channel_names[c]) + (c ? 1 : 0);
        if (n + need + 24 >= size) {
            snprintf(out + n, size - n, ",... (%u channels)", image->channel_count);
            return;
        }
        n += (size_t)snprintf(out + n, size - n, "%s%s", c ? "," : "", image->channel_names[c]);
    }
}

static cJSON *info_json(const struct sb_pack *pack, const char *dir)
{
    cJSON *root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "pack", dir);
    cJSON_AddNumberToObject(root, "format_version", pack->format_version);
    cJSON_AddStringToObject(root, "skybake_version", pack->skybake_version);
    cJSON_AddStringToObject(root, "scene", pack->scene ? pack->scene->name : "");
    cJSON_AddStringToObject(root, "scene_hash", pack->scene_hash);
    cJSON *device = cJSON_AddObjectToObject(root, "device");
    cJSON_AddStringToObject(device, "name", pack->device.name);
    cJSON_AddStringToObject(device, "driver", pack->device.driver);
    cJSON_AddStringToObject(device, "api_version", pack->device.api_version);
    cJSON_AddNumberToObject(device, "vendor_id", pack->device.vendor_id);
    cJSON_AddNumberToObject(device, "device_id", pack->device.device_id);
    cJSON *artifacts = cJSON_AddArrayToObject(root, "artifacts");
    for (int p = 0; p < SB_PRODUCT_COUNT; p++) {
        if (!pack->present[p])
            continue;
        const struct sb_artifact *a = &pack->artifacts[p];
        const struct sb_image *image = &pack->images[p];
        char channels[SB_IMAGE_MAX_CHANNELS * SB_CHANNEL_NAME_MAX];
        channel_list(image, channels, sizeof(channels));
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", sb_product_name((enum sb_product_id)p));
        cJSON_AddStringToObject(o, "file", a->file);
        cJSON_AddNumberToObject(o, "bytes", (double)file_bytes(dir, a->file));
        cJSON_AddNumberToObject(o, "width", image->width);
        cJSON_AddNumberToObject(o, "height", image->height);
        cJSON_AddNumberToObject(o, "depth", image->depth);
        cJSON_AddStringToObject(o, "channels", channels);
        cJSON_AddStringToObject(o, "parameterization", a->parameterization);
        cJSON_AddNumberToObject(o, "gpu_ms", a->gpu_ms);
        cJSON_AddNumberToObject(o, "bake_ms", a->bake_ms);
        cJSON *settings = cJSON_Parse(a->settings_json[0] ? a->settings_json : "{}");
        cJSON_AddItemToObject(o, "settings", settings ? settings : cJSON_CreateObject());
        cJSON_AddStringToObject(o, "content_hash", a->content_hash);
        if (a->world_hash[0]) {
            cJSON_AddStringToObject(o, "world_hash", a->world_hash);
            cJSON_AddStringToObject(o, "world_path", a->world_path);
        }
        if (a->probes.tile_count) { /* each tile, for a farm that splits a level */
            cJSON *tiles = cJSON_AddArrayToObject(o, "tiles");
            for (uint32_t t = 0; t < a->probes.tile_count; t++) {
                const struct sb_probe_tile *tile = &a->probes.tiles[t];
                cJSON *e = cJSON_CreateObject();
                char content[17];
                snprintf(content, sizeof(content), "%016llx", (unsigned long long)tile->content);
                cJSON_AddNumberToObject(e, "x", tile->x);
                cJSON_AddNumberToObject(e, "z", tile->z);
                cJSON_AddNumberToObject(e, "probes", tile->probes);
                cJSON_AddBoolToObject(e, "baked", tile->flags & SB_PROBES_TILE_BAKED);
                cJSON_AddStringToObject(e, "key", tile->key);
                cJSON_AddStringToObject(e, "content", content);
                cJSON_AddItemToArray(tiles, e);
            }
        }
        cJSON_AddItemToArray(artifacts, o);
    }
    return root;
}

void sb_pack_info_print(const struct sb_pack *pack, const char *dir, bool json)
{
    if (json) {
        sb_json_emit(stdout, info_json(pack, dir));
        return;
    }
    printf("pack %s: format version %d, baked by skybake %s\n", dir, pack->format_version, pack->skybake_version);
    printf("scene: %s (hash %s)\n", pack->scene && pack->scene->name[0] ? pack->scene->name : "(unnamed)",
           pack->scene_hash);
    printf("device: %s (%s, Vulkan %s)\n", pack->device.name, pack->device.driver, pack->device.api_version);
    printf("%-18s %-11s %-28s %10s %9s  %-32s  %s\n", "product", "size", "channels", "bytes", "gpu ms", "content hash",
           "settings");
    for (int p = 0; p < SB_PRODUCT_COUNT; p++) {
        if (!pack->present[p])
            continue;
        const struct sb_artifact *a = &pack->artifacts[p];
        const struct sb_image *image = &pack->images[p];
        char size[32], channels[256];
        if (image->depth > 1)
            snprintf(size, sizeof(size), "%ux%ux%u", image->width, image->height, image->depth);
        else
            snprintf(size, sizeof(size), "%ux%u", image->width, image->height);
        channel_list(image, channels, sizeof(channels));
        printf("%-18s %-11s %-28s %10lld %9.3f  %-32s  %s\n", sb_product_name((enum sb_product_id)p), size, channels,
               file_bytes(dir, a->file), a->gpu_ms, a->content_hash, a->settings_json);
        if (a->world_hash[0])
            printf("%-18s baked against the world %s (%s)\n", "", a->world_path[0] ? a->world_path : "(path unknown)",
                   a->world_hash);
        if (a->probes.tile_count) {
            uint32_t baked = 0;
            for (uint32_t t = 0; t < a->probes.tile_count; t++)
                baked += a->probes.tiles[t].flags & SB_PROBES_TILE_BAKED;
            printf("%-18s %u tiles of %g m (%u baked, %u left for another bake), rays reaching %g m; --json lists "
                   "them\n",
                   "", a->probes.tile_count, (double)a->probes.tile_m, baked, a->probes.tile_count - baked,
                   (double)a->probes.reach_m);
        }
    }
}

/* verify --json: every problem's message, as logged. */
static void collect_problem(void *user, enum sb_log_level level, const char *message)
{
    if (level <= SB_LOG_WARN)
        cJSON_AddItemToArray(user, cJSON_CreateString(message));
}

enum sb_result sb_pack_verify_print(const char *dir, bool json)
{
    cJSON *problems = json ? cJSON_CreateArray() : NULL;
    if (json)
        sb_log_set_sink(collect_problem, problems);
    unsigned count = 0;
    enum sb_result res = sb_pack_verify(dir, &count);
    if (json) {
        sb_log_set_sink(NULL, NULL);
        cJSON *root = cJSON_CreateObject();
        cJSON_AddStringToObject(root, "pack", dir);
        cJSON_AddBoolToObject(root, "ok", res == SB_OK);
        cJSON_AddStringToObject(root, "first_problem", sb_result_name(res));
        cJSON_AddNumberToObject(root, "problem_count", count);
        cJSON_AddItemToObject(root, "problems", problems);
        sb_json_emit(stdout, root);
    } else if (res) {
        printf("%s: %u problem%s (the first: %s)\n", dir, count, count == 1 ? "" : "s", sb_result_name(res));
    } else {
        printf("%s: verified\n", dir);
    }
    return res;
}

const char *sb_diff_outcome_name(enum sb_diff_outcome outcome)
{
    static const char *const names[] = {"identical", "within-tolerance", "different", "missing"};
    return (unsigned)outcome <= SB_DIFF_MISSING ? names[outcome] : "unknown";
}

double sb_diff_relative(double a, double b, double peak, double floor)
{
    double scale = fmax(fmax(fabs(a), fabs(b)), floor * peak);
    return scale > 0 ? fabs(a - b) / scale : 0.0;
}

static void diff_images(const struct sb_image *a, const struct sb_image *b, double tolerance, double floor,
                        struct sb_artifact_diff *d)
{
    if (a->width != b->width || a->height != b->height || a->depth != b->depth ||
        a->channel_count != b->channel_count) {
        d->outcome = SB_DIFF_DIFFERENT;
        return;
    }
    uint32_t nc = a->channel_count;
    uint64_t pixels = (uint64_t)a->width * a->height * a->depth;
    double peak[SB_IMAGE_MAX_CHANNELS] = {0};
    for (uint64_t i = 0; i < pixels; i++)
        for (uint32_t c = 0; c < nc; c++)
            peak[c] = fmax(peak[c], fmax(fabs(a->data[i * nc + c]), fabs(b->data[i * nc + c])));
    d->values = pixels * nc;
    for (uint64_t i = 0; i < pixels; i++) {
        for (uint32_t c = 0; c < nc; c++) {
            float va = a->data[i * nc + c], vb = b->data[i * nc + c];
            if (memcmp(&va, &vb, sizeof(va)) == 0)
                continue;
            d->differing++;
            struct sb_value_place at = {(uint32_t)(i % a->width), (uint32_t)(i / a->width % a->height),
                                        (uint32_t)(i / a->width / a->height), c};
            double abs_diff = fabs((double)va - (double)vb), rel = sb_diff_relative(va, vb, peak[c], floor);
            if (abs_diff > d->max_abs) {
                d->max_abs = abs_diff;
                d->max_abs_at = at;
            }
            if (rel > d->max_rel) {
                d->max_rel = rel;
                d->max_rel_at = at;
            }
            if (!(rel <= tolerance))
                d->beyond++;
        }
    }
    d->outcome = !d->differing ? SB_DIFF_IDENTICAL : d->beyond ? SB_DIFF_DIFFERENT : SB_DIFF_WITHIN;
}

enum sb_diff_outcome sb_pack_diff(const struct sb_pack *a, const struct sb_pack *b, double tolerance, double floor,
                                  struct sb_artifact_diff out[SB_PRODUCT_COUNT])
{
    enum sb_diff_outcome worst = SB_DIFF_IDENTICAL;
    for (int p = 0; p < SB_PRODUCT_COUNT; p++) {
        struct sb_artifact_diff *d = &out[p];
        memset(d, 0, sizeof(*d));
        d->product = (enum sb_product_id)p;
        d->in_a = a->present[p];
        d->in_b = b->present[p];
        if (d->in_a != d->in_b)
            d->outcome = SB_DIFF_MISSING;
        else if (d->in_a)
            diff_images(&a->images[p], &b->images[p], tolerance, floor, d);
        if (d->outcome > worst)
            worst = d->outcome;
    }
    return worst;
}

static void place_text(const struct sb_image *image, struct sb_value_place at, char *out, size_t size)
{
    if (image->depth > 1)
        snprintf(out, size, "(%u, %u, %u) %s", at.x, at.y, at.z, image->channel_names[at.channel]);
    else
        snprintf(out, size, "(%u, %u) %s", at.x, at.y, image->channel_names[at.channel]);
}

void sb_pack_diff_print(const struct sb_pack *a, const char *dir_a, const struct sb_pack *b, const char *dir_b,
                        double tolerance, double floor, const struct sb_artifact_diff diffs[SB_PRODUCT_COUNT],
                        bool json)
{
    bool same_scene = !strcmp(a->scene_hash, b->scene_hash);
    enum sb_diff_outcome worst = SB_DIFF_IDENTICAL;
    for (int p = 0; p < SB_PRODUCT_COUNT; p++)
        if (diffs[p].outcome > worst)
            worst = diffs[p].outcome;
    cJSON *root = json ? cJSON_CreateObject() : NULL, *arr = NULL;
    if (json) {
        cJSON_AddStringToObject(root, "a", dir_a);
        cJSON_AddStringToObject(root, "b", dir_b);
        cJSON_AddNumberToObject(root, "tolerance", tolerance);
        cJSON_AddNumberToObject(root, "floor", floor);
        cJSON_AddBoolToObject(root, "same_scene", same_scene);
        cJSON_AddStringToObject(root, "device_a", a->device.name);
        cJSON_AddStringToObject(root, "device_b", b->device.name);
        cJSON_AddStringToObject(root, "outcome", sb_diff_outcome_name(worst));
        arr = cJSON_AddArrayToObject(root, "artifacts");
    } else {
        printf("A %s: %s, on %s\nB %s: %s, on %s\n", dir_a, a->scene_hash, a->device.name, dir_b, b->scene_hash,
               b->device.name);
        if (!same_scene)
            printf("the packs were baked from different scenes\n");
        printf("relative difference: |a - b| / max(|a|, |b|, %g x the channel's largest value); tolerance %g\n", floor,
               tolerance);
    }
    for (int p = 0; p < SB_PRODUCT_COUNT; p++) {
        const struct sb_artifact_diff *d = &diffs[p];
        if (!d->in_a && !d->in_b)
            continue;
        const char *name = sb_product_name(d->product);
        const struct sb_image *image = d->in_a ? &a->images[p] : &b->images[p];
        char abs_at[80] = "", rel_at[80] = "";
        if (d->differing) {
            place_text(image, d->max_abs_at, abs_at, sizeof(abs_at));
            place_text(image, d->max_rel_at, rel_at, sizeof(rel_at));
        }
        if (json) {
            cJSON *o = cJSON_CreateObject();
            cJSON_AddStringToObject(o, "name", name);
            cJSON_AddStringToObject(o, "outcome", sb_diff_outcome_name(d->outcome));
            if (d->outcome == SB_DIFF_MISSING)
                cJSON_AddStringToObject(o, "missing_from", d->in_a ? "b" : "a");
            if (d->differing) {
                cJSON_AddNumberToObject(o, "values", (double)d->values);
                cJSON_AddNumberToObject(o, "differing", (double)d->differing);
                cJSON_AddNumberToObject(o, "beyond_tolerance", (double)d->beyond);
                cJSON_AddNumberToObject(o, "max_abs", d->max_abs);
                cJSON_AddStringToObject(o, "max_abs_at", abs_at);
                cJSON_AddNumberToObject(o, "max_rel", d->max_rel);
                cJSON_AddStringToObject(o, "max_rel_at", rel_at);
            }
            cJSON_AddItemToArray(arr, o);
            continue;
        }
        if (d->outcome == SB_DIFF_MISSING)
            printf("%-18s missing from %s\n", name, d->in_a ? "B" : "A");
        else if (d->outcome == SB_DIFF_IDENTICAL)
            printf("%-18s identical\n", name);
        else if (!d->differing)
            printf("%-18s different shapes\n", name);
        else
            printf("%-18s %s: %llu of %llu values differ, %llu beyond the tolerance; max abs %.3g at %s, max rel "
                   "%.3g at %s\n",
                   name, sb_diff_outcome_name(d->outcome), (unsigned long long)d->differing,
                   (unsigned long long)d->values, (unsigned long long)d->beyond, d->max_abs, abs_at, d->max_rel,
                   rel_at);
    }
    if (json)
        sb_json_emit(stdout, root);
    else
        printf("outcome: %s\n", sb_diff_outcome_name(worst));
}

#define SHEET_FACE 48
#define SHEET_GAP 2

static uint8_t srgb8(double linear)
{
    double v = linear <= 0.0031308 ? 12.92 * linear : 1.055 * pow(linear, 1 / 2.4) - 0.055;
    return (uint8_t)lrint(fmin(fmax(v, 0.0), 1.0) * 255.0);
}

enum sb_result sb_pack_contact_sheet(const struct sb_pack *pack, const char *png_path)
{
    if (!pack->present[SB_PRODUCT_REFLECTION_CUBES]) {
        sb_error("%s: the pack has no reflection_cubes to draw", png_path);
        return SB_ERR_USAGE;
    }
    const struct sb_image *cubes = &pack->images[SB_PRODUCT_REFLECTION_CUBES];
    uint32_t n = cubes->width, levels = cubes->levels ? cubes->levels : 1, count = cubes->depth;
    uint32_t cell = SHEET_FACE + SHEET_GAP;
    uint32_t width = 6 * cell + SHEET_GAP, height = count * (levels * cell + 3 * SHEET_GAP) + SHEET_GAP;
    double log_sum = 0;
    for (size_t t = 0; t < (size_t)6 * n * n; t++) {
        const float *c = cubes->data + 3 * t;
        log_sum += log(fmax(0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2], 1e-9));
    }
    double exposure = 0.18 / exp(log_sum / (6.0 * n * n));
    uint8_t *rgba = malloc((size_t)width * height * 4);
    if (!rgba)
        return SB_ERR_NOMEM;
    for (size_t i = 0; i < (size_t)width * height; i++) { /* a dark grey ground */
        rgba[4 * i] = rgba[4 * i + 1] = rgba[4 * i + 2] = 32;
        rgba[4 * i + 3] = 255;
    }
    for (uint32_t i = 0; i < count; i++)
        for (uint32_t l = 0; l < levels; l++) {
            uint32_t m = sb_image_level_size(n, l);
            const float *level = cubes->data + sb_image_level_offset(cubes, l) + (size_t)i * 6 * m * m * 3;
            uint32_t y0 = SHEET_GAP + i * (levels * cell + 3 * SHEET_GAP) + l * cell;
            for (uint32_t f = 0; f < 6; f++)
                for (uint32_t y = 0; y < SHEET_FACE; y++)
                    for (uint32_t x = 0; x < SHEET_FACE; x++) {
                        const float *c = level + 3 * (((size_t)f * m + y * m / SHEET_FACE) * m + x * m / SHEET_FACE);
                        uint8_t *o = rgba + 4 * ((size_t)(y0 + y) * width + SHEET_GAP + f * cell + x);
                        for (int k = 0; k < 3; k++) {
                            double v = c[k] * exposure;
                            o[k] = srgb8(v / (1 + v));
                        }
                    }
        }
    enum sb_result res = sb_png_write(png_path, width, height, rgba);
    free(rgba);
    return res;
}

/* The probe map's canvas: the probes' footprint in x and z, MAP_SIDE
 * pixels along its longer side, north (-z) up. */
#define MAP_SIDE 1024
struct map {
    uint32_t width, height;
    double x0, z0, scale; /* pixels per m */
    uint8_t *rgba;
};

static void map_put(struct map *m, double x, double z, int radius, const uint8_t colour[3])
{
    int64_t cx = (int64_t)floor((x - m->x0) * m->scale), cy = (int64_t)floor((z - m->z0) * m->scale);
    for (int64_t y = cy - radius; y <= cy + radius; y++)
        for (int64_t px = cx - radius; px <= cx + radius; px++)
            if (px >= 0 && y >= 0 && px < m->width && y < m->height)
                memcpy(&m->rgba[4 * ((size_t)y * m->width + (size_t)px)], colour, 3);
}

/* A probe's colour: its kind's, as bright as the sky it sees (the constant
 * band over its largest, 2 sqrt(pi)); red when invalid. */
static void probe_colour(const float *record, const uint8_t tint[3], uint8_t out[3])
{
    static const uint8_t invalid[3] = {230, 40, 40};
    if (record[SB_SKY_VISIBILITY_VALID] == 0) {
        memcpy(out, invalid, 3);
        return;
    }
    double open = record[SB_SKY_VISIBILITY_SH] / (2 * sqrt(M_PI));
    open = open < 0 ? 0 : open > 1 ? 1 : open;
    for (int k = 0; k < 3; k++)
        out[k] = (uint8_t)(tint[k] * (0.3 + 0.7 * open));
}

enum sb_result sb_pack_probe_map(const struct sb_pack *pack, const char *png_path)
{
    if (!pack->present[SB_PRODUCT_SKY_VISIBILITY] || !pack->images[SB_PRODUCT_SKY_VISIBILITY].width) {
        sb_error("%s: the pack has no sky_visibility probes to draw", png_path);
        return SB_ERR_USAGE;
    }
    const struct sb_image *img = &pack->images[SB_PRODUCT_SKY_VISIBILITY];
    const struct sb_probe_layout *l = &pack->artifacts[SB_PRODUCT_SKY_VISIBILITY].probes;
    uint64_t count = img->width, grid = (uint64_t)l->grid[0] * l->grid[1] * l->grid[2];
    const size_t stride = SB_SKY_VISIBILITY_CHANNEL_COUNT;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (uint64_t i = 0; i < count; i++) {
        const float *r = &img->data[i * stride + SB_SKY_VISIBILITY_POSITION];
        lo[0] = fmin(lo[0], r[0]), hi[0] = fmax(hi[0], r[0]);
        lo[1] = fmin(lo[1], r[2]), hi[1] = fmax(hi[1], r[2]);
    }
    double pad = 0.02 * fmax(fmax(hi[0] - lo[0], hi[1] - lo[1]), 1.0), w = hi[0] - lo[0] + 2 * pad,
           h = hi[1] - lo[1] + 2 * pad;
    struct map m = {.x0 = lo[0] - pad, .z0 = lo[1] - pad, .scale = MAP_SIDE / fmax(w, h)};
    m.width = (uint32_t)fmax(64, ceil(w * m.scale));
    m.height = (uint32_t)fmax(64, ceil(h * m.scale));
    m.rgba = malloc((size_t)m.width * m.height * 4);
    if (!m.rgba)
        return SB_ERR_NOMEM;
    for (size_t i = 0; i < (size_t)m.width * m.height; i++) {
        m.rgba[4 * i] = m.rgba[4 * i + 1] = m.rgba[4 * i + 2] = 24;
        m.rgba[4 * i + 3] = 255;
    }
    /* the detail's brick columns, a dark blue ground under their probes */
    static const uint8_t column[3] = {24, 44, 84}, white[3] = {255, 255, 255}, amber[3] = {255, 176, 48},
                         green[3] = {60, 220, 90};
    double brick = l->detail_spacing_m * SB_PROBES_BRICK;
    for (uint32_t c = 0; c < l->column_count && l->detail_count; c++) {
        double x = l->detail_origin_m[0] + l->columns[c].x * brick, z = l->detail_origin_m[2] + l->columns[c].z * brick;
        int64_t px0 = (int64_t)ceil((x - m.x0) * m.scale), px1 = (int64_t)ceil((x + brick - m.x0) * m.scale);
        int64_t py0 = (int64_t)ceil((z - m.z0) * m.scale), py1 = (int64_t)ceil((z + brick - m.z0) * m.scale);
        for (int64_t py = py0 < 0 ? 0 : py0; py < py1 && py < m.height; py++)
            for (int64_t px = px0 < 0 ? 0 : px0; px < px1 && px < m.width; px++)
                memcpy(&m.rgba[4 * ((size_t)py * m.width + (size_t)px)], column, 3);
    }
    /* the grid's probes, the detail's over them, the explicit ones on top;
     * a dot a twelfth of the spacing across, 1 to 7 pixels */
    double grid_px = fmin(l->spacing_m[0], l->spacing_m[2]) * m.scale, detail_px = l->detail_spacing_m * m.scale;
    int grid_radius = (int)fmin(3, grid_px / 12), detail_radius = (int)fmin(3, detail_px / 12);
    uint64_t first[3] = {0, grid, grid + l->detail_count}, end[3] = {grid, grid + l->detail_count, count};
    const uint8_t *tint[3] = {white, amber, green};
    const int radius[3] = {grid_radius, detail_radius, 2};
    for (int kind = 0; kind < 3; kind++)
        for (uint64_t i = first[kind]; i < end[kind] && i < count; i++) {
            const float *r = &img->data[i * stride];
            uint8_t c[3];
            probe_colour(r, tint[kind], c);
            map_put(&m, r[SB_SKY_VISIBILITY_POSITION], r[SB_SKY_VISIBILITY_POSITION + 2], radius[kind], c);
        }
    enum sb_result res = sb_png_write(png_path, m.width, m.height, m.rgba);
    free(m.rgba);
    return res;
}

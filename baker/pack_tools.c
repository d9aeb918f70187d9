#include "pack_info.h"

#include <cJSON.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>

#include "json.h"
#include "scene.h"

static long long file_bytes(const char *dir, const char *file)
{
    char path[4096];
    struct stat st;
    snprintf(path, sizeof(path), "%s/%s", dir, file);
    return stat(path, &st) == 0 ? (long long)st.st_size : -1;
}

static void channel_list(const struct sb_image *image, char *out, size_t size)
{
    size_t n = 0;
    out[0] = '\0';
    for (uint32_t c = 0; c < image->channel_count && n < size; c++)
        n += (size_t)snprintf(out + n, size - n, "%s%s", c ? "," : "", image->channel_names[c]);
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
        char channels[256];
        channel_list(image, channels, sizeof(channels));
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", sb_product_name((enum sb_product_id)p));
        cJSON_AddStringToObject(o, "file", a->file);
        cJSON_AddNumberToObject(o, "bytes", (double)file_bytes(dir, a->file));
        cJSON_AddNumberToObject(o, "width", image->width);
        cJSON_AddNumberToObject(o, "height", image->height);
        cJSON_AddStringToObject(o, "channels", channels);
        cJSON_AddStringToObject(o, "parameterization", a->parameterization);
        cJSON_AddNumberToObject(o, "gpu_ms", a->gpu_ms);
        cJSON_AddNumberToObject(o, "bake_ms", a->bake_ms);
        cJSON *settings = cJSON_Parse(a->settings_json[0] ? a->settings_json : "{}");
        cJSON_AddItemToObject(o, "settings", settings ? settings : cJSON_CreateObject());
        cJSON_AddStringToObject(o, "content_hash", a->content_hash);
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
    printf("%-18s %-9s %-28s %10s %9s  %-32s  %s\n", "product", "size", "channels", "bytes", "gpu ms", "content hash",
           "settings");
    for (int p = 0; p < SB_PRODUCT_COUNT; p++) {
        if (!pack->present[p])
            continue;
        const struct sb_artifact *a = &pack->artifacts[p];
        const struct sb_image *image = &pack->images[p];
        char size[32], channels[256];
        snprintf(size, sizeof(size), "%ux%u", image->width, image->height);
        channel_list(image, channels, sizeof(channels));
        printf("%-18s %-9s %-28s %10lld %9.3f  %-32s  %s\n", sb_product_name((enum sb_product_id)p), size, channels,
               file_bytes(dir, a->file), a->gpu_ms, a->content_hash, a->settings_json);
    }
}

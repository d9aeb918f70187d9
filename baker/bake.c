#include "bake.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "atmosphere.h"
#include "log.h"

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

uint32_t sb_bake_closure(const struct sb_scene *scene)
{
    uint32_t mask = 0;
    for (int p = 0; p < SB_PRODUCT_COUNT; p++)
        if (scene->wants[p])
            mask |= 1u << p;
    /* Dependencies point to lower ids, so one pass from the top closes the set. */
    for (int p = SB_PRODUCT_COUNT - 1; p >= 0; p--)
        if (mask & (1u << p))
            mask |= sb_atmosphere_product((enum sb_product_id)p)->depends_on;
    return mask;
}

enum sb_result sb_bake_scene(struct sb_vk *vk, const struct sb_scene *scene, const char *out_dir,
                             struct sb_bake_report *report)
{
    struct sb_pack_writer *writer = NULL;
    struct sb_atmosphere_baker *baker = NULL;
    struct sb_image image = {0};
    char *scene_json = NULL;
    memset(report, 0, sizeof(*report));

    enum sb_result res = sb_pack_writer_create(out_dir, &writer);
    if (res)
        goto cleanup;
    if ((res = sb_atmosphere_baker_create(vk, &scene->atmosphere, &baker)))
        goto cleanup;

    uint32_t mask = sb_bake_closure(scene);
    for (int p = 0; p < SB_PRODUCT_COUNT; p++) {
        if (!(mask & (1u << p)))
            continue;
        enum sb_product_id id = (enum sb_product_id)p;
        struct sb_artifact *a = &report->artifacts[report->artifact_count];
        struct sb_atmosphere_settings used;
        memset(a, 0, sizeof(*a));
        a->product = id;
        snprintf(a->file, sizeof(a->file), "%s.exr", sb_product_name(id));
        snprintf(a->parameterization, sizeof(a->parameterization), "%s", sb_product_format(id)->parameterization);

        double t0 = now_ms();
        if ((res = sb_atmosphere_bake(baker, id, NULL, &image, &used, &a->gpu_ms)))
            goto cleanup;
        a->bake_ms = now_ms() - t0;
        sb_atmosphere_settings_json(id, &used, a->settings_json, sizeof(a->settings_json));
        if ((res = sb_pack_writer_add_image(writer, a, &image)))
            goto cleanup;
        report->shapes[report->artifact_count][0] = image.width;
        report->shapes[report->artifact_count][1] = image.height;
        report->shapes[report->artifact_count][2] = image.channel_count;
        report->artifact_count++;
        sb_info("%-18s %4ux%-3u x%u  gpu %9.3f ms  bake %9.3f ms  %s", sb_product_name(id), image.width,
                image.height, image.channel_count, a->gpu_ms, a->bake_ms, a->content_hash);
        sb_image_finish(&image);
    }

    scene_json = sb_scene_normalized_json(scene);
    if (!scene_json) {
        res = SB_ERR_NOMEM;
        goto cleanup;
    }
    struct sb_device_info device;
    sb_vk_device_info(vk, &device);
    res = sb_pack_writer_commit(&writer, scene_json, &device);

cleanup:
    free(scene_json);
    sb_image_finish(&image);
    sb_atmosphere_baker_destroy(&baker);
    sb_pack_writer_destroy(&writer);
    return res;
}

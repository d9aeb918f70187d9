/*
 * A pack of every product with synthetic, finite content, written through
 * the pack writer: what the pack reader's tests and the manifest fuzzer
 * open. The cloud products are small (the scene's sizes: 16^3, 8^3, 8^2,
 * 8^2); the probes are 5 explicit ones over a world "world.obj" that the
 * pack does not need; the reflection cubes 2 of 16^2 a face. `images` (may be NULL) receives each product's image,
 * which the caller finishes; `name` is the scene's and the device's.
 */
#ifndef SB_TEST_SYNTHETIC_PACK_H
#define SB_TEST_SYNTHETIC_PACK_H

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>

#include "family.h"
#include "pack.h"
#include "scene.h"

/* The world its probe and reflection products record. */
#define SYNTHETIC_WORLD_HASH "0123456789abcdef0123456789abcdef"
#define SYNTHETIC_WORLD_PATH "/worlds/caf\xc3\xa9 \"quoted\"/world.obj"

static inline enum sb_result write_synthetic_pack(const char *dir, const char *name,
                                                  struct sb_image images[SB_PRODUCT_COUNT])
{
    struct sb_scene scene = {.preset = "earth"};
    snprintf(scene.name, sizeof(scene.name), "%s", name);
    sb_atmosphere_preset_earth(&scene.atmosphere);
    for (int p = 0; p < SB_PRODUCT_COUNT; p++)
        scene.wants[p] = true;
    scene.clouds = (struct sb_cloud_params){
        .seed = 7,
        .shape_size = 16,
        .shape_perlin = {2, 2},
        .shape_worley_cells = {1, 2, 4},
        .detail_size = 8,
        .detail_worley_cells = {1, 1, 2},
        .curl_size = 8,
        .curl = {2, 2},
        .weather_size = 8,
        .coverage = {2, 2},
        .precipitation = {4, 1},
        .cloud_type = {1, 3},
    };
    scene.has_world = true;
    scene.world = (struct sb_world_params){.file = "world.obj", .units_m = 1, .scale = 1};
    sb_probe_params_default(&scene.probes);
    sb_reflection_params_default(&scene.reflections);
    scene.has_reflections = true;
    scene.reflections.face_size = 16;
    scene.reflections.probe_count = 1;
    scene.reflections.probes[0].position_m[1] = 1;
    scene.reflections.probes[0].box_m[0][1] = -1;
    for (int k = 0; k < 3; k++)
        scene.reflections.probes[0].box_m[1][k] = 2;
    struct sb_pack_writer *w = NULL;
    enum sb_result res = sb_pack_writer_create(dir, &w);
    for (int p = 0; p < SB_PRODUCT_COUNT && !res; p++) {
        const struct sb_product_format *f = sb_product_format((enum sb_product_id)p);
        uint32_t shape[3];
        sb_product_shape(&scene, (enum sb_product_id)p, shape);
        bool probes = f->storage == SB_STORAGE_PROBES;
        if (probes && !shape[0])
            shape[0] = 5;
        struct sb_image image;
        uint32_t levels = f->storage == SB_STORAGE_EXR_CUBE ? sb_cube_levels(shape[0]) : 1;
        if ((res = sb_image_init_levels(&image, shape[0], shape[1], shape[2], f->channel_count, levels)))
            break;
        sb_image_set_channel_names(&image, f->channel_names);
        for (uint64_t i = 0; i < sb_image_float_count(&image); i++)
            image.data[i] = probes ? (i % f->channel_count == 6 ? 1.0f : (float)(i * 2654435761u % 1000u) * 1e-3f)
                                   : (float)((double)(i * 2654435761u % 1000003u) * 1e-6 + p);
        if (!strcmp(f->pixel_type, "float16"))
            sb_image_round_to_half(&image, NULL);
        struct sb_artifact a = {.product = (enum sb_product_id)p,
                                .probes = {.explicit_count = probes ? shape[0] : 0, .ray_count = 64}};
        snprintf(a.file, sizeof(a.file), "%s.%s", f->name, f->extension);
        snprintf(a.parameterization, sizeof(a.parameterization), "%s", f->parameterization);
        if (f->family == SB_FAMILY_PROBES || p == SB_PRODUCT_REFLECTION_CUBES || p == SB_PRODUCT_REFLECTION_SURFACES)
            sb_artifact_set_world(&a, SYNTHETIC_WORLD_HASH, SYNTHETIC_WORLD_PATH);
        res = sb_pack_writer_add_image(w, &a, &image);
        if (images)
            images[p] = image;
        else
            sb_image_finish(&image);
    }
    struct sb_device_info device = {.driver = "none"};
    snprintf(device.name, sizeof(device.name), "%s device", name);
    char *scene_json = res ? NULL : sb_scene_normalized_json(&scene);
    if (!res)
        res = scene_json ? sb_pack_writer_commit(&w, scene_json, &device) : SB_ERR_NOMEM;
    free(scene_json);
    sb_pack_writer_destroy(&w);
    return res;
}

#endif

/*
 * libFuzzer entry point: the pack reader, manifest first. A pack of every
 * product with synthetic content is written once; each input replaces its
 * manifest.json and the pack is opened. Any manifest is refused with a
 * code of the closed set, or opens with every artifact present and
 * verified; never a crash, never a read outside the pack (its file names
 * are checked before any file is opened).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "fuzz.h"
#include "log.h"
#include "pack.h"
#include "scene.h"

static char pack_dir[64];

/* The synthetic pack the seed manifest (corpus/manifest/) describes. */
static void write_pack(void)
{
    struct sb_pack_writer *w = NULL;
    if (sb_pack_writer_create(pack_dir, &w))
        abort();
    for (int p = 0; p < SB_PRODUCT_COUNT; p++) {
        const struct sb_product_format *f = sb_product_format((enum sb_product_id)p);
        struct sb_image image;
        if (sb_image_init(&image, f->width, f->height, f->channel_count))
            abort();
        sb_image_set_channel_names(&image, f->channel_names);
        for (uint64_t i = 0; i < sb_image_float_count(&image); i++)
            image.data[i] = (float)((double)(i * 2654435761u % 1000003u) * 1e-6 + p);
        struct sb_artifact a = {.product = (enum sb_product_id)p};
        snprintf(a.file, sizeof(a.file), "%s.exr", f->name);
        snprintf(a.parameterization, sizeof(a.parameterization), "%s", f->parameterization);
        if (sb_pack_writer_add_image(w, &a, &image))
            abort();
        sb_image_finish(&image);
    }
    struct sb_device_info device = {.name = "fuzz device", .driver = "none"};
    struct sb_scene scene = {.name = "fuzz", .preset = "earth"};
    sb_atmosphere_preset_earth(&scene.atmosphere);
    for (int p = 0; p < SB_PRODUCT_COUNT; p++)
        scene.wants[p] = true;
    char *scene_json = sb_scene_normalized_json(&scene);
    if (!scene_json || sb_pack_writer_commit(&w, scene_json, &device))
        abort();
    free(scene_json);
}

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    if (!pack_dir[0]) {
        sb_log_set_sink(fuzz_quiet, NULL);
        snprintf(pack_dir, sizeof(pack_dir), "/tmp/skybake-fuzz-pack-%ld", (long)getpid());
        write_pack();
        const char *seed = getenv("SKYBAKE_FUZZ_WRITE_SEED"); /* regenerate the seed manifest */
        if (seed) {
            char cmd[256];
            snprintf(cmd, sizeof(cmd), "cp '%s/manifest.json' '%s'", pack_dir, seed);
            if (system(cmd) != 0)
                abort();
        }
    }
    char path[128];
    snprintf(path, sizeof(path), "%s/manifest.json", pack_dir);
    fuzz_write(path, data, size);
    struct sb_pack pack;
    enum sb_result res = sb_pack_open(pack_dir, &pack);
    if ((unsigned)res >= SB_RESULT_COUNT)
        abort();
    for (int p = 0; p < SB_PRODUCT_COUNT; p++)
        if (res == SB_OK && pack.present[p] && !pack.images[p].data)
            abort();
    sb_pack_close(&pack);
    return 0;
}

/*
 * Bake a scene into a pack: resolve which products the scene needs (its
 * requests plus their dependencies), bake them in dependency order on one
 * device, check every value is finite, and publish the pack atomically.
 */
#ifndef SB_BAKER_BAKE_H
#define SB_BAKER_BAKE_H

#include "context.h"
#include "pack.h"
#include "scene.h"

struct sb_bake_report {
    int artifact_count;
    struct sb_artifact artifacts[SB_PRODUCT_COUNT];
    uint32_t shapes[SB_PRODUCT_COUNT][3]; /* width, height, channels */
};

/* Products to bake: the scene's requests closed over dependencies (bit mask). */
uint32_t sb_bake_closure(const struct sb_scene *scene);

/* Bake `scene` on `vk` into a pack at out_dir. On failure the previous pack at
 * out_dir (if any) is untouched and no temporary files remain. */
enum sb_result sb_bake_scene(struct sb_vk *vk, const struct sb_scene *scene, const char *out_dir,
                             struct sb_bake_report *report);

#endif

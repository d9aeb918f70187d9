/*
 * Bake a scene into a pack: resolve which products the scene needs (its
 * requests plus their dependencies), bake them in dependency order on one
 * device, check every value is finite, and publish the pack atomically.
 *
 * The bake graph: each product has a key, XXH3-128 of everything its values
 * depend on: the format version, the skybake version, the parameters its
 * kernels read (normalised: each as a hexadecimal float; for the cloud
 * noise, its channel recipes), what the scene asks of it (a tolerance and
 * the candidate settings, or the default settings), its kernels' SPIR-V and
 * the host-side recipe (sb_atmosphere_code_hash, sb_cloud_code_hash), how
 * its file stores it, and the keys of the products it reads. Baking into an existing pack reuses
 * every artifact whose key is unchanged, baked on the same device, after the
 * pack verified (content hashes recomputed); the rest is baked.
 */
#ifndef SB_BAKER_BAKE_H
#define SB_BAKER_BAKE_H

#include "context.h"
#include "pack.h"
#include "scene.h"

#define SB_BAKE_MAX_FROM 16                        /* --from packs */
#define SB_BAKE_MAX_SOURCES (1 + SB_BAKE_MAX_FROM) /* the pack there, then those */

struct sb_bake_options {
    bool force; /* bake every product, reusing nothing */
    /* more packs (baked on this device) whose parts a family may keep,
     * after the pack there: the probes' tiles of a farm's machines */
    const char *from[SB_BAKE_MAX_FROM];
    int from_count;
};

struct sb_bake_report {
    int artifact_count;
    struct sb_artifact artifacts[SB_PRODUCT_COUNT];
    uint32_t shapes[SB_PRODUCT_COUNT][4]; /* width, height, depth, channels */
    bool reused[SB_PRODUCT_COUNT];        /* per artifact: taken from the pack there before */
    uint32_t declined; /* products the scene's tolerance made unneeded, left out of the pack (bit mask) */
};

/* Products to bake: the scene's requests closed over dependencies (bit mask). */
uint32_t sb_bake_closure(const struct sb_scene *scene);

/* The bake key of every product in `mask` (see above), in out[id]. */
/* `states`: each family's state (family.h), or NULL for families without. */
void sb_bake_keys(const struct sb_scene *scene, uint32_t mask, void *const states[SB_FAMILY_COUNT],
                  char out[SB_PRODUCT_COUNT][SB_HASH_HEX_SIZE]);

/* Bake `scene` on `vk` into a pack at out_dir. On failure the previous pack at
 * out_dir (if any) is untouched and no temporary files remain. `options`
 * may be NULL. */
enum sb_result sb_bake_scene(struct sb_vk *vk, const struct sb_scene *scene, const char *out_dir,
                             const struct sb_bake_options *options, struct sb_bake_report *report);

#endif

/*
 * The baker's half of a product family (the formats' half is
 * formats/family.h): how its products' bake keys are written, how they are
 * baked, and how a product reused from an older pack is handed back to the
 * family for the products that read it. bake.c drives every family through
 * this table alone; a new family is one file (atmosphere_family.c,
 * clouds_family.c) and its rows in formats/products.def.
 */
#ifndef SB_BAKER_FAMILY_H
#define SB_BAKER_FAMILY_H

#include <stddef.h>
#include <stdint.h>

#include "compute.h"
#include "context.h"
#include "image.h"
#include "key.h"
#include "pack.h"
#include "scene.h"

/* The most kernels a product's bake makes (sb_family_baker.kernels). */
#define SB_FAMILY_KERNELS_MAX 8

struct sb_family_baker {
    /* The products `id` reads (bit mask of sb_product_id, all of lower ids
     * than id); NULL when the family's products read none. */
    uint32_t (*depends_on)(enum sb_product_id id);
    /* Append everything the product's values depend on but its inputs'
     * keys (bake.c adds those): parameters, settings, kernels, and for a
     * family with inputs of its own (the probes' world) what was read.
     * `state` is the family's (NULL when it has no create). */
    void (*key)(void *state, const struct sb_scene *scene, enum sb_product_id id, struct sb_key_text *key);
    /* The family's state for one bake (NULL create: none), created before
     * the keys when the bake needs any of its products: what the keys and
     * the bakes read (the atmosphere's baker, the probes' world). destroy
     * accepts a pointer to NULL. */
    enum sb_result (*create)(struct sb_vk *vk, const struct sb_scene *scene, void **state);
    void (*destroy)(void **state);
    /* Bake `id` into *image (values as the pack's file stores them) and
     * fill the artifact's settings_json and gpu_ms (and, for a product
     * baked against the world, sb_artifact_set_world). baked[] holds every
     * product of lower id that this bake made or reused. A product that a
     * scene's tolerance makes unneeded (the orders, where Hillaire's LUT
     * is within it) returns SB_OK with *image left empty: the pack goes
     * without it, and no product may read it. */
    enum sb_result (*bake)(void *state, struct sb_vk *vk, const struct sb_scene *scene, enum sb_product_id id,
                           const struct sb_image baked[SB_PRODUCT_COUNT], struct sb_image *image,
                           struct sb_artifact *artifact);
    /* A product reused from an older pack, for the family's later bakes
     * that read it; NULL when they read baked[] only. */
    enum sb_result (*adopt)(void *state, enum sb_product_id id, const struct sb_image *image);
    /* A product of the older pack there (verified, baked on this device)
     * whose key changed, offered before bake(): a family that can keep
     * parts of it (the probes' tiles) takes what it needs, moving *image
     * out; NULL: none kept. */
    void (*previous)(void *state, enum sb_product_id id, struct sb_artifact *was, struct sb_image *image);
    /* The kernels bake() makes for `id`, at most SB_FAMILY_KERNELS_MAX;
     * returns their count. bake.c compiles every product's at once, on
     * every core, before the first bake (sb_pipelines_prepare): a driver's
     * first compile of a kernel takes up to a second. NULL: none listed
     * (each compiles when made); one left out compiles when made. */
    uint32_t (*kernels)(void *state, const struct sb_scene *scene, enum sb_product_id id,
                        struct sb_pipeline_params out[SB_FAMILY_KERNELS_MAX]);
};

/* Add fields (printf's `fmt`, starting with a comma) to the end of the JSON
 * object in json[size] (an artifact's settings_json): nothing when it is
 * not one, or when they would not fit. */
void sb_settings_json_add(char *json, size_t size, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

/* The baker of `family` (< SB_FAMILY_COUNT). */
const struct sb_family_baker *sb_family_baker(enum sb_family family);

/* The family baker of product `id`. */
const struct sb_family_baker *sb_product_baker(enum sb_product_id id);

/* The rows, each in its family's file (<name>_family.c, products.def). */
#define SB_FAMILY(id, name) extern const struct sb_family_baker sb_##name##_family;
#include "products.def"

#endif
